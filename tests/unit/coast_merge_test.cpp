// The coast's close nodes merged (coast_detail::merge_close_samples): arcs far shorter than the
// size lose an end, unless the arc that replaces them would touch or cross another.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "coast_internal.hpp"

using namespace globemesh;
using coast_detail::ArcGrid;

namespace {

constexpr double km_per_degree = 6371.0 * pi / 180;
constexpr double h_km = 10, gap = 1.0 / 32; // arcs under 312.5 m merge

Vec3 at_km(double x, double y) {
    return lonlat_to_vec(x / km_per_degree, y / km_per_degree);
}

struct Merged {
    std::vector<std::vector<std::uint32_t>> kept;
    std::size_t dropped = 0;
    std::vector<std::vector<Vec3>> rings;
};

Merged merge(const std::vector<std::vector<Vec3>> &samples) {
    std::vector<std::vector<double>> h;
    std::vector<std::vector<char>> movable;
    for (const auto &r : samples) {
        h.emplace_back(r.size(), h_km / 6371.0);
        movable.emplace_back(r.size(), 1);
    }
    Merged out;
    out.rings = samples;
    std::vector<const std::vector<Vec3> *> ptrs;
    for (const auto &r : out.rings)
        ptrs.push_back(&r);
    ArcGrid grid(ptrs);
    EXPECT_TRUE(grid.conflicts().empty());
    out.dropped =
        coast_detail::merge_close_samples(samples, h, movable, gap, out.rings, grid, out.kept);
    return out;
}

double shortest_arc_km(const std::vector<Vec3> &ring) {
    double shortest = 1e9;
    for (std::size_t i = 0; i < ring.size(); ++i)
        shortest = std::min(shortest, arc_angle(ring[i], ring[(i + 1) % ring.size()]) * 6371.0);
    return shortest;
}

} // namespace

// A square of 40 km with nodes 5 km apart and, on one side, a jetty's three extra nodes 4 m
// apart: three go, and every arc left is at least gap h long.
TEST(CoastMerge, nodes_metres_apart_merge_into_one) {
    std::vector<Vec3> ring;
    for (int side = 0; side < 4; ++side)
        for (int k = 0; k < 8; ++k) {
            const double s = 5.0 * k;
            const double x[4] = {s, 40, 40 - s, 0}, y[4] = {0, s, 40, 40 - s};
            ring.push_back(at_km(x[side], y[side]));
            if (side == 0 && k == 2)
                for (int j = 1; j <= 3; ++j)
                    ring.push_back(at_km(s + 0.004 * j, 0.002 * (j % 2)));
        }
    const Merged m = merge({ring});
    EXPECT_EQ(m.dropped, 3u);
    EXPECT_EQ(m.kept[0].size(), 32u);
    EXPECT_GE(shortest_arc_km(m.rings[0]), gap * h_km);
    EXPECT_TRUE(coast_detail::find_conflicts({&m.rings[0]}).empty());
}

// Ring A's node a1 dips 80 m below the line from a0 to a2, around the tip of ring B, which
// comes down to 10 m below that line: dropping a1 (the end of the 128 m arc a0-a1 nearer the
// arc between its neighbours) would cross B, so a1 comes back and stays, and a0 goes instead.
TEST(CoastMerge, a_node_whose_arc_would_cross_another_ring_stays) {
    const std::vector<Vec3> a = {at_km(0, 0), at_km(0.1, -0.08), at_km(2, 0), at_km(2, -2),
                                 at_km(0, -2)};
    const std::vector<Vec3> b = {at_km(0.05, -0.01), at_km(0.07, 1), at_km(0.03, 1)};
    const Merged m = merge({a, b});
    EXPECT_EQ(m.dropped, 1u);
    EXPECT_EQ(m.kept[0], (std::vector<std::uint32_t>{1, 2, 3, 4}));
    EXPECT_EQ(m.kept[1].size(), 3u);
    EXPECT_TRUE(coast_detail::find_conflicts({&m.rings[0], &m.rings[1]}).empty());
}

// A ring keeps four nodes whatever their spacing, and an unmovable node stays.
TEST(CoastMerge, a_ring_keeps_four_nodes_and_its_fixed_ones) {
    const std::vector<Vec3> ring = {at_km(0, 0),     at_km(0.1, 0),   at_km(0.2, 0),
                                    at_km(0.2, 0.1), at_km(0.2, 0.2), at_km(0, 0.2)};
    std::vector<std::vector<Vec3>> rings{ring};
    std::vector<const std::vector<Vec3> *> ptrs{&rings[0]};
    ArcGrid grid(ptrs);
    std::vector<std::vector<std::uint32_t>> kept;
    const std::vector<std::vector<char>> movable{{0, 1, 1, 1, 1, 1}};
    const std::size_t dropped = coast_detail::merge_close_samples(
        {ring}, {std::vector<double>(6, h_km / 6371.0)}, movable, gap, rings, grid, kept);
    EXPECT_EQ(dropped, 2u);
    ASSERT_EQ(kept[0].size(), 4u);
    EXPECT_EQ(kept[0][0], 0u);
}
