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

namespace {

/// The polygons as one MULTIPOLYGON (copies), for GEOS's overlay and point tests.
GeomPtr multipolygon(Geos &geos, const std::vector<GeomPtr> &polygons) {
    std::vector<GEOSGeometry *> raw;
    for (const auto &p : polygons) {
        std::vector<const GEOSGeometry *> ps;
        polygons_of(geos, p.get(), ps);
        for (const auto *q : ps)
            raw.push_back(GEOSGeom_clone_r(geos.get(), q));
    }
    return own(geos,
               GEOSGeom_createCollection_r(geos.get(), GEOS_MULTIPOLYGON, raw.data(),
                                           static_cast<unsigned>(raw.size())),
               "collect");
}

/// One snap-rounding union of all the polygons, as dissolve made it for every group.
GeomPtr one_union(Geos &geos, const std::vector<GeomPtr> &polygons) {
    std::vector<GeomPtr> copies;
    for (const auto &p : polygons)
        copies.push_back(own(geos, GEOSGeom_clone_r(geos.get(), p.get()), "copy"));
    const GeomPtr all = make_collection(geos, copies);
    return own(geos, GEOSUnaryUnionPrec_r(geos.get(), all.get(), snap_grid_deg), "union");
}

double area(Geos &geos, const GEOSGeometry *g) {
    double a = 0;
    GEOSArea_r(geos.get(), g, &a);
    return a;
}

std::size_t holes(Geos &geos, const GEOSGeometry *g) {
    std::vector<const GEOSGeometry *> ps;
    polygons_of(geos, g, ps);
    std::size_t n = 0;
    for (const auto *p : ps)
        n += std::size_t(GEOSGetNumInteriorRings_r(geos.get(), p));
    return n;
}

/// Every polygon valid and every vertex on the snap grid.
void expect_valid_on_grid(Geos &geos, const std::vector<GeomPtr> &polygons) {
    for (const auto &p : polygons) {
        EXPECT_EQ(GEOSisValid_r(geos.get(), p.get()), 1);
        for (const PointList &ring : polygon_rings(geos, p.get()))
            for (const LonLat &q : ring) {
                ASSERT_EQ(q.lon / snap_grid_deg, std::round(q.lon / snap_grid_deg));
                ASSERT_EQ(q.lat / snap_grid_deg, std::round(q.lat / snap_grid_deg));
            }
    }
}

/// How far apart two snap roundings of the polygons may lie (square degrees): each moves the
/// boundary by at most 0.71 cell, so they differ within 1.42 cells of it.
double rounding_apart(Geos &geos, const std::vector<GeomPtr> &polygons) {
    double length = 0;
    for (const auto &p : polygons) {
        double l = 0;
        GEOSLength_r(geos.get(), p.get(), &l);
        length += l;
    }
    return 1.42 * snap_grid_deg * length;
}

bool land_at(Geos &geos, const GEOSGeometry *land, double x, double y) {
    const GeomPtr p = own(geos, GEOSGeom_createPointFromXY_r(geos.get(), x, y), "point");
    return GEOSContains_r(geos.get(), land, p.get()) == 1;
}

} // namespace

// Countries side by side whose borders do not match (the Digital Chart of the World, five
// countries round Belgium: 210 gaps in their union), unioned by tiles of 256 vertices: valid
// polygons on the grid, the land and the gaps of one snap-rounding union.
TEST(CoastDissolve, countries_unioned_by_tiles_are_the_land_of_one_union) {
    Geos geos;
    const auto source = read_source(test::fixture("coast/hostile/dcw_benelux.geojson").string(), "",
                                    "", "", "coast");
    std::vector<GeomPtr> parts;
    for (const PolygonRings &rings : source.polygons) {
        const GeomPtr valid = make_valid(geos, make_polygon(geos, rings).get());
        std::vector<const GEOSGeometry *> ps;
        polygons_of(geos, valid.get(), ps);
        for (const auto *p : ps)
            parts.push_back(own(geos, GEOSGeom_clone_r(geos.get(), p), "copy"));
    }
    const GeomPtr reference = one_union(geos, parts);
    const std::vector<GeomPtr> tiled = tiled_union(geos, parts, snap_grid_deg, 256);
    ASSERT_FALSE(tiled.empty()) << "the tiles' union gave up";
    expect_valid_on_grid(geos, tiled);
    const GeomPtr land = multipolygon(geos, tiled);
    const GeomPtr apart =
        own(geos, GEOSSymDifference_r(geos.get(), land.get(), reference.get()), "difference");
    EXPECT_LT(area(geos, apart.get()), rounding_apart(geos, parts));
    EXPECT_GT(holes(geos, reference.get()), 150u);
    EXPECT_EQ(holes(geos, land.get()), holes(geos, reference.get()));
}

// A lake inside a tile with an island in it (tiles of 600 vertices leave the corner country's
// tile whole), and a lake the tile lines cross with an island they cross too: each island stays
// land in its lake, as in one union.
TEST(CoastDissolve, islands_in_lakes_unioned_by_tiles_stay_in_their_lakes) {
    auto square = [](double x0, double y0, double x1, double y1) {
        PointList ring; // 40 vertices a side: the tiles cut it
        const double corners[5][2] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
        for (int s = 0; s < 4; ++s)
            for (int k = 0; k < 40; ++k) {
                const double t = k / 40.0;
                ring.push_back({corners[s][0] + t * (corners[s + 1][0] - corners[s][0]),
                                corners[s][1] + t * (corners[s + 1][1] - corners[s][1])});
            }
        ring.push_back(ring.front());
        return ring;
    };
    // A 4 x 4 map of unit countries without its middle 2 x 2 (a lake, an island across its
    // centre); the corner country holds a lake with an island of its own.
    Geos geos;
    std::vector<GeomPtr> parts;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            if ((i == 1 || i == 2) && (j == 1 || j == 2))
                continue;
            PolygonRings country{square(i, j, i + 1, j + 1)};
            if (i == 0 && j == 0)
                country.push_back(square(0.1, 0.1, 0.4, 0.4));
            parts.push_back(make_polygon(geos, country));
        }
    parts.push_back(make_polygon(geos, {square(1.8, 1.8, 2.2, 2.2)}));
    parts.push_back(make_polygon(geos, {square(0.2, 0.2, 0.3, 0.3)}));
    const std::vector<GeomPtr> tiled = tiled_union(geos, parts, snap_grid_deg, 600);
    ASSERT_FALSE(tiled.empty()) << "the tiles' union gave up";
    expect_valid_on_grid(geos, tiled);
    const GeomPtr land = multipolygon(geos, tiled);
    EXPECT_NEAR(area(geos, land.get()), 12 - 0.09 + 0.01 + 0.16, rounding_apart(geos, parts));
    EXPECT_NEAR(area(geos, land.get()), area(geos, one_union(geos, parts).get()),
                rounding_apart(geos, parts));
    EXPECT_TRUE(land_at(geos, land.get(), 2.0, 2.0)) << "the island across the middle";
    EXPECT_FALSE(land_at(geos, land.get(), 1.5, 1.5)) << "the middle lake";
    EXPECT_TRUE(land_at(geos, land.get(), 0.25, 0.25)) << "the corner lake's island";
    EXPECT_FALSE(land_at(geos, land.get(), 0.15, 0.15)) << "the corner lake";
    EXPECT_TRUE(land_at(geos, land.get(), 0.5, 0.5));
}
