// The places of the closed straits (group_closed_straits, src/mesher/straits.cpp): closings in a
// chain of steps shorter than the size are one place, numbered in the order of their first.
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "globemesh/sphere.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {
namespace {

// Closings along the equator at these longitudes (degrees; 0.01 degree is 1.11 km).
MesherReport closings_at(const std::vector<double> &lons) {
    MesherReport r;
    for (const double lon : lons)
        r.straits_closed_at.push_back(lonlat_to_vec(lon, 0));
    return r;
}

TEST(StraitsPlaces, closings_in_a_chain_of_steps_under_the_size_are_one_place) {
    const SizeFn five_km = [](const Vec3 &) { return 5.0; };
    // 0, 4.4 and 8.9 km along a channel (each step under 5 km, the ends 8.9 km apart), then one
    // 55 km away, then one 4.4 km from the first the other way: two places, numbered as they
    // first come.
    MesherReport r = closings_at({0, 0.04, 0.08, 0.5, -0.04});
    group_closed_straits(five_km, r);
    EXPECT_EQ(r.straits_closed_places, 2u);
    EXPECT_EQ(r.straits_closed_place, (std::vector<std::uint32_t>{0, 0, 0, 1, 0}));
    // A step of 6.7 km is over the size: two places.
    r = closings_at({0, 0.06});
    group_closed_straits(five_km, r);
    EXPECT_EQ(r.straits_closed_place, (std::vector<std::uint32_t>{0, 1}));
    // The larger size of a step's two ends decides (a closing in finer mesh beside a coarser one).
    const SizeFn graded = [](const Vec3 &p) { return p.y > 0.001 ? 8.0 : 2.0; };
    r = closings_at({0, 0.06});
    group_closed_straits(graded, r);
    EXPECT_EQ(r.straits_closed_places, 1u);
    // None closed: no place.
    r = closings_at({});
    group_closed_straits(five_km, r);
    EXPECT_EQ(r.straits_closed_places, 0u);
    EXPECT_TRUE(r.straits_closed_place.empty());
}

} // namespace
} // namespace globemesh::mesher_internal
