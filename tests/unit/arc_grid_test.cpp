// The coast's conflict index kept across changes (coast_detail::ArcGrid): after each change its
// conflicts must be those found from scratch (find_conflicts), and those a test of every pair
// of arcs finds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <tuple>
#include <vector>

#include "coast_internal.hpp"

using namespace globemesh;
using coast_detail::ArcGrid;
using coast_detail::ArcPair;

namespace {

// A wiggly closed ring of n nodes around `centre`, radius about r (radians).
std::vector<Vec3> wiggly_ring(const Vec3 &centre, double r, int n, std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> wiggle(0.6, 1.4);
    const Vec3 e1 =
        normalized(cross(centre, std::abs(centre.z) < 0.9 ? Vec3{0, 0, 1} : Vec3{1, 0, 0}));
    const Vec3 e2 = cross(centre, e1);
    std::vector<Vec3> out;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * pi * i / n, d = r * wiggle(rng);
        out.push_back(normalized(centre + d * std::cos(a) * e1 + d * std::sin(a) * e2));
    }
    return out;
}

// Every pair of arcs that are not consecutive in one ring and that arcs_conflict says meet, in
// find_conflicts's order.
std::vector<ArcPair> every_pair(const std::vector<std::vector<Vec3>> &rings) {
    std::vector<ArcPair> out;
    for (std::uint32_t r = 0; r < rings.size(); ++r)
        for (std::uint32_t i = 0; i < rings[r].size(); ++i)
            for (std::uint32_t s = r; s < rings.size(); ++s)
                for (std::uint32_t j = s == r ? i + 1 : 0; j < rings[s].size(); ++j) {
                    const std::size_t n = rings[r].size();
                    if (s == r && ((i + 1) % n == j || (j + 1) % n == i))
                        continue;
                    const Vec3 &a = rings[r][i], &b = rings[r][(i + 1) % n];
                    const Vec3 &c = rings[s][j], &d = rings[s][(j + 1) % rings[s].size()];
                    if (coast_detail::arcs_conflict(a, b, c, d))
                        out.push_back({r, i, s, j});
                }
    return out;
}

bool consecutive(const std::vector<std::vector<Vec3>> &rings, const ArcPair &p) {
    const std::size_t n = rings[p.ring_a].size();
    return p.ring_a == p.ring_b && ((p.seg_a + 1) % n == p.seg_b || (p.seg_b + 1) % n == p.seg_a);
}

std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>>
tuples(const std::vector<ArcPair> &v) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>> out;
    for (const auto &p : v)
        out.emplace_back(p.ring_a, p.seg_a, p.ring_b, p.seg_b);
    return out;
}

} // namespace

TEST(ArcGrid, after_each_change_finds_what_a_search_from_scratch_finds) {
    std::mt19937_64 rng(20261203);
    std::uniform_real_distribution<double> unit(-1, 1);
    std::size_t conflicts_seen = 0, kept_seen = 0;
    for (int trial = 0; trial < 20; ++trial) {
        // Rings close together (some overlap, some cross themselves), in one region.
        const Vec3 region = normalized(Vec3{unit(rng), unit(rng), unit(rng)});
        std::vector<std::vector<Vec3>> rings;
        for (int r = 0; r < 6; ++r)
            rings.push_back(
                wiggly_ring(normalized(region + 0.08 * Vec3{unit(rng), unit(rng), unit(rng)}), 0.03,
                            12 + 4 * r, rng));
        std::vector<const std::vector<Vec3> *> ptrs;
        for (const auto &r : rings)
            ptrs.push_back(&r);
        ArcGrid grid(ptrs);
        for (int change = 0; change < 30; ++change) {
            // Some rings get a run of nodes replaced: nodes [a, b) by k new ones near them.
            for (std::uint32_t r = 0; r < rings.size(); ++r) {
                if (std::uniform_int_distribution<int>(0, 2)(rng) != 0)
                    continue;
                std::vector<Vec3> &ring = rings[r];
                const auto n = static_cast<std::uint32_t>(ring.size());
                const std::uint32_t a = std::uniform_int_distribution<std::uint32_t>(1, n - 2)(rng);
                const std::uint32_t b =
                    std::uniform_int_distribution<std::uint32_t>(a, std::min(a + 3, n - 1))(rng);
                const std::uint32_t k =
                    std::uniform_int_distribution<std::uint32_t>(b == a ? 1 : 0, 4)(rng);
                std::vector<Vec3> now(ring.begin(), ring.begin() + a);
                for (std::uint32_t q = 0; q < k; ++q)
                    now.push_back(
                        normalized(ring[a - 1] + 0.01 * Vec3{unit(rng), unit(rng), unit(rng)}));
                now.insert(now.end(), ring.begin() + b, ring.end());
                // Arc i (node i to i + 1) is the old arc with the same two nodes: before the
                // change, the arcs inside the prefix; after it, those inside the suffix, and the
                // closing arc when both ends stayed.
                const auto m = static_cast<std::uint32_t>(now.size());
                std::vector<std::uint32_t> old_of(m, ArcGrid::none);
                for (std::uint32_t i = 0; i + 1 < a; ++i)
                    old_of[i] = i;
                for (std::uint32_t i = a + k; i + 1 < m; ++i)
                    old_of[i] = i - (a + k) + b;
                if (b < n)
                    old_of[m - 1] = n - 1;
                ring = std::move(now);
                grid.replace(r, old_of);
            }
            grid.update();
            const std::vector<ArcPair> got = grid.conflicts();
            ASSERT_EQ(tuples(got), tuples(coast_detail::find_conflicts(ptrs)))
                << "trial " << trial << ", change " << change;
            std::vector<ArcPair> apart;
            for (const auto &p : got)
                if (!consecutive(rings, p))
                    apart.push_back(p);
            ASSERT_EQ(tuples(apart), tuples(every_pair(rings)))
                << "trial " << trial << ", change " << change;
            conflicts_seen += got.size();
        }
        kept_seen += grid.conflicts().size();
    }
    // The rings do meet: the comparison is not between empty lists.
    EXPECT_GT(conflicts_seen, 100u);
    EXPECT_GT(kept_seen, 0u);
}
