// The coast's snap rounding of the land (coast_detail::dissolve), which rounds the polygons in
// batches and groups on every core: each polygon must come out as GEOS rounds it alone (the same
// rings and vertices, GEOSNormalize putting both in one order), and the lone ones in their input
// order, however the batches fall; the polygons rounded without GEOS (rounded_if_clear) too.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include <geos_c.h>

#include "coast_load_internal.hpp"
#include "support.hpp"

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

/// Whether a and b hold the same rings with the same vertices (in any start and direction).
bool same_polygons(Geos &geos, const GEOSGeometry *a, const GEOSGeometry *b) {
    GeomPtr x = own(geos, GEOSGeom_clone_r(geos.get(), a), "copy"),
            y = own(geos, GEOSGeom_clone_r(geos.get(), b), "copy");
    GEOSNormalize_r(geos.get(), x.get());
    GEOSNormalize_r(geos.get(), y.get());
    return GEOSEqualsExact_r(geos.get(), x.get(), y.get(), 0.0) == 1;
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
        ASSERT_TRUE(same_polygons(geos, out[i].get(), alone.get())) << "polygon " << i;
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
            if (!used[e] && same_polygons(geos, g.get(), expected[e].get())) {
                used[e] = 1;
                ++hits;
                break;
            }
        EXPECT_EQ(hits, 1u);
    }
}

// Real coastlines: every polygon that rounded_if_clear takes comes out as GEOS's snap rounding
// gives it, and it takes most of them (else the test would pass by refusing all).
TEST(CoastDissolve, real_polygons_rounded_without_geos_are_those_geos_gives) {
    struct Source {
        const char *file, *layer;
    };
    for (const Source src : {Source{"coast/ne_50m_land.gpkg", "land"},
                             Source{"coast/ne_110m_land_equal_earth.gpkg", "land"},
                             Source{"coast/hostile/gshhg_f_suez.geojson", ""},
                             Source{"coast/hostile/gshhg_f_sogn_25832.shp", ""},
                             Source{"coast/hostile/gshhg_h_yangtze.geojson", ""},
                             Source{"coast/hostile/gshhg_i_seram.geojson", ""}}) {
        SCOPED_TRACE(src.file);
        Geos geos;
        const auto source =
            read_source(test::fixture(src.file).string(), src.layer, "", "", "coast");
        std::size_t taken = 0, polygons = 0;
        for (const PolygonRings &rings : source.polygons) {
            const GeomPtr valid = make_valid(geos, make_polygon(geos, rings).get());
            std::vector<const GEOSGeometry *> parts;
            polygons_of(geos, valid.get(), parts);
            for (const GEOSGeometry *p : parts) {
                ++polygons;
                const auto ours = rounded_if_clear(polygon_rings(geos, p), snap_grid_deg);
                if (!ours)
                    continue;
                ++taken;
                const GeomPtr theirs = rounded(geos, p);
                ASSERT_EQ(GEOSEqualsExact_r(geos.get(), make_polygon(geos, *ours).get(),
                                            theirs.get(), 0.0),
                          1)
                    << "polygon " << polygons - 1;
            }
        }
        EXPECT_GT(taken, polygons * 9 / 10) << taken << " of " << polygons;
    }
}

// A polygon whose arms come within a cell of each other (a near-touch of its own) or whose hole
// touches its shell is left to GEOS; a vertex 3 cells from an edge is not.
TEST(CoastDissolve, a_polygon_that_rounding_would_change_is_left_to_geos) {
    const double c = snap_grid_deg;
    auto u_shape = [&](double gap_cells) {
        // A U whose inner sides are gap_cells apart: x = 1 and x = 1 + gap.
        const double g = gap_cells * c;
        return PolygonRings{{{0, 0},
                             {2 + g, 0},
                             {2 + g, 3},
                             {1 + g, 3},
                             {1 + g, 1},
                             {1, 1},
                             {1, 3},
                             {0, 3},
                             {0, 0}}};
    };
    EXPECT_FALSE(rounded_if_clear(u_shape(1.0), c));
    EXPECT_FALSE(rounded_if_clear(u_shape(2.0), c));
    EXPECT_TRUE(rounded_if_clear(u_shape(3.0), c));
    const PolygonRings touching{{{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 0}},
                                {{0, 1}, {1, 2}, {1, 1}, {0, 1}}};
    EXPECT_FALSE(rounded_if_clear(touching, c));
    // dissolve still gives GEOS's rounding of the near-touching one.
    Geos geos;
    std::vector<GeomPtr> parts;
    parts.push_back(make_polygon(geos, u_shape(0.4)));
    SnapCount count;
    const auto out = dissolve(geos, parts, snap_grid_deg, count);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_TRUE(same_polygons(geos, out[0].get(), rounded(geos, parts[0].get()).get()));
}
