// The coast's snap rounding of the land (coast_detail::dissolve), which rounds the polygons in
// batches and groups on every core: each polygon must come out as GEOS rounds it alone, and the
// lone ones in their input order, however the batches fall.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include <geos_c.h>

#include "coast_load_internal.hpp"

using namespace globemesh;
using namespace globemesh::coast_detail;

namespace {

/// A star-shaped island of n vertices off the snap grid, about r degrees across, around (x, y).
PolygonRings island(double x, double y, double r, int n, std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> wiggle(0.5, 1.0);
    PointList ring;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * std::acos(-1.0) * i / n, d = r * wiggle(rng);
        ring.push_back({x + d * std::cos(a), y + d * std::sin(a)});
    }
    ring.push_back(ring.front());
    return {ring};
}

/// Islands on a lattice of 1-degree cells (disjoint), 5 to 40 vertices each.
std::vector<PolygonRings> archipelago(int count, std::mt19937_64 &rng) {
    std::uniform_int_distribution<int> vertices(5, 40);
    std::vector<PolygonRings> out;
    for (int k = 0; k < count; ++k)
        out.push_back(island(-170.3 + (k % 300), -60.7 + k / 300, 0.4, vertices(rng), rng));
    return out;
}

std::vector<GeomPtr> geometries(Geos &geos, const std::vector<PolygonRings> &polygons) {
    std::vector<GeomPtr> out;
    for (const auto &p : polygons)
        out.push_back(make_polygon(geos, p));
    return out;
}

/// GEOS's own snap rounding of one geometry.
GeomPtr rounded(Geos &geos, const GEOSGeometry *g) {
    return own(geos, GEOSGeom_setPrecision_r(geos.get(), g, snap_grid_deg, 0), "round");
}

} // namespace

TEST(CoastDissolve, lone_polygons_come_out_as_geos_rounds_each_alone_in_their_order) {
    std::mt19937_64 rng(41);
    Geos geos;
    const auto polygons = archipelago(6000, rng); // several batches, on every core
    const auto parts = geometries(geos, polygons);
    SnapCount count;
    const auto out = dissolve(geos, parts, snap_grid_deg, count);
    ASSERT_EQ(out.size(), polygons.size());
    EXPECT_EQ(count.joined, 0u);
    EXPECT_EQ(count.changed, 0u);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const GeomPtr alone = rounded(geos, parts[i].get());
        ASSERT_EQ(GEOSEqualsExact_r(geos.get(), out[i].get(), alone.get(), 0.0), 1)
            << "polygon " << i;
    }
}

TEST(CoastDissolve, overlapping_polygons_are_dissolved_together_and_every_other_one_alone) {
    std::mt19937_64 rng(42);
    Geos geos;
    auto polygons = archipelago(300, rng);
    // Polygon 150 overlaps 151's cell; 200 and 201 are one island drawn twice, slightly shifted.
    polygons[150] = island(-170.3 + 150.5, -60.7, 0.4, 12, rng);
    polygons[201] = polygons[200];
    for (auto &p : polygons[201][0])
        p.lon += 0.01;
    const auto parts = geometries(geos, polygons);
    SnapCount count;
    const auto out = dissolve(geos, parts, snap_grid_deg, count);
    std::vector<GeomPtr> expected;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        if (i == 151 || i == 201)
            continue;
        if (i == 150 || i == 200) {
            std::vector<GeomPtr> pair;
            pair.push_back(own(geos, GEOSGeom_clone_r(geos.get(), parts[i].get()), "copy"));
            pair.push_back(own(geos, GEOSGeom_clone_r(geos.get(), parts[i + 1].get()), "copy"));
            GeomPtr both = make_collection(geos, pair);
            expected.push_back(
                own(geos, GEOSUnaryUnionPrec_r(geos.get(), both.get(), snap_grid_deg), "union"));
        } else {
            expected.push_back(rounded(geos, parts[i].get()));
        }
    }
    // Each output polygon is one expected polygon (the groups' results join where their batch
    // does), each expected once.
    ASSERT_EQ(out.size(), expected.size());
    std::vector<char> used(expected.size(), 0);
    for (const auto &g : out) {
        std::size_t hits = 0;
        for (std::size_t e = 0; e < expected.size(); ++e)
            if (!used[e] && GEOSEqualsExact_r(geos.get(), g.get(), expected[e].get(), 0.0) == 1) {
                used[e] = 1;
                ++hits;
                break;
            }
        EXPECT_EQ(hits, 1u);
    }
}
