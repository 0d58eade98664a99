// choose_lunes (src/mesher/parts_lunes.cpp): where the parts' borders go, on work and coasts
// laid out by hand.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "globemesh/parts.hpp"
#include "globemesh/sphere.hpp"
#include "parts_lunes.hpp"

namespace globemesh::parts_detail {
namespace {

/// Degrees from longitude a to b, the short way round.
double lon_gap(double a, double b) {
    const double d = std::fmod(std::abs(a - b), 360.0);
    return std::min(d, 360 - d);
}

/// An island 0.05 degrees wide from 60S to 60N with its west coast at `lon`, nodes every
/// 0.25 degrees of latitude (ocean on the left: anticlockwise seen from outside).
Ring long_island(double lon) {
    Ring r;
    for (double lat = -60; lat <= 60; lat += 0.25)
        r.nodes.push_back(lonlat_to_vec(lon + 0.05, lat));
    for (double lat = 60; lat >= -60; lat -= 0.25)
        r.nodes.push_back(lonlat_to_vec(lon, lat));
    r.kinds.assign(r.nodes.size(), SegmentKind::coast);
    return r;
}

const SizeFn size_50km = [](const Vec3 &) { return 50.0; };

TEST(PartsLunes, the_first_border_splits_the_work_in_two) {
    // All the work lies in the 180 degrees east of default_border_lon: two parts share it
    // where a border runs through its middle, 90 degrees east.
    std::vector<double> nodes(lon_bins, 0.0);
    for (int i = 0; i < lon_bins / 2; ++i)
        nodes[static_cast<std::size_t>(i)] = 1000;
    const Lunes lunes = choose_lunes(2, nodes, {}, {}, size_50km);
    EXPECT_EQ(lunes.count, 2);
    EXPECT_NEAR(lunes.first_lon, default_border_lon + 90, 1e-9);
}

TEST(PartsLunes, with_the_work_even_the_first_position_is_kept) {
    const std::vector<double> nodes(lon_bins, 1000.0);
    EXPECT_EQ(choose_lunes(3, nodes, {}, {}, size_50km).first_lon, default_border_lon);
}

TEST(PartsLunes, the_borders_keep_off_a_coast_along_a_meridian) {
    // With the work even, every position balances it; the island's coast runs along the
    // meridian 0.1 degrees (11 km) east of the first position. Kept off by more than its size
    // (50 km, 0.45 degrees at the equator), each border.
    const std::vector<double> nodes(lon_bins, 1000.0);
    const double island = default_border_lon + 0.1;
    for (int count : {2, 3}) {
        const Lunes lunes = choose_lunes(count, nodes, {long_island(island)}, {1}, size_50km);
        for (int k = 0; k < count; ++k)
            EXPECT_GT(lon_gap(lunes.border_lon(k), island + 0.025), 0.5) << count << " " << k;
    }
    // Not kept (a lake), the ring does not move the borders.
    const Lunes lunes = choose_lunes(2, nodes, {long_island(island)}, {0}, size_50km);
    EXPECT_EQ(lunes.first_lon, default_border_lon);
}

} // namespace
} // namespace globemesh::parts_detail
