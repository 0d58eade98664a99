// Coast module on real Natural Earth fixtures: ring invariants (checked by an independent brute
// force), ocean area against GeographicLib on the source's own ocean layer, Antarctica around
// the South Pole, shapefile = GeoPackage, projected copy within 1 m, shaping at 100 and 10 km,
// regions across +-180 and at a pole, a region with islands inside against the source clipped.
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <thread>

#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "support.hpp"
#include "unit/coast_support.hpp"

using namespace globemesh;
using globemesh::test::count_violations;
using globemesh::test::fixture;
using globemesh::test::layer_area_km2;

namespace {

MeshOptions coast_options(const std::string &rel, const std::string &layer = "land") {
    MeshOptions o;
    o.coast = fixture(rel).string();
    o.coast_layer = layer;
    return o;
}

/// Options reading layer `land` of the file at `path`.
MeshOptions coast_options_at(const std::string &path) {
    MeshOptions o;
    o.coast = path;
    o.coast_layer = "land";
    return o;
}

const CoastData &ne110() {
    static const CoastData data = load_coast(coast_options("coast/ne_110m_land.gpkg"));
    return data;
}
const CoastData &ne50() {
    static const CoastData data = load_coast(coast_options("coast/ne_50m_land.gpkg"));
    return data;
}

std::size_t node_count(const Boundary &b) {
    std::size_t n = 0;
    for (const auto &r : b.rings)
        n += r.nodes.size();
    return n;
}

/// Sum of longitude steps along a ring, degrees: +-360 for a ring around a pole, 0 otherwise.
double winding_deg(const Ring &r) {
    double sum = 0;
    for (std::size_t i = 0; i < r.nodes.size(); ++i) {
        double a = vec_to_lonlat(r.nodes[i]).lon,
               b = vec_to_lonlat(r.nodes[(i + 1) % r.nodes.size()]).lon;
        sum += std::remainder(b - a, 360.0);
    }
    return sum;
}

SizeFn uniform(double h) {
    return [h](const Vec3 &) { return h; };
}

void expect_valid(const Boundary &b) {
    auto issues = check_boundary(b);
    EXPECT_TRUE(issues.empty()) << issues.front().what << " ring " << issues.front().ring << " seg "
                                << issues.front().segment;
}

} // namespace

TEST(Coast, natural_earth_110m_gives_simple_non_crossing_rings) {
    const auto &d = ne110();
    ASSERT_GT(d.rings.rings.size(), 100u);
    EXPECT_EQ(count_violations(d.rings), 0u);
    expect_valid(d.rings);
    for (const auto &r : d.rings.rings) {
        ASSERT_EQ(r.kinds.size(), r.nodes.size());
        for (auto k : r.kinds)
            EXPECT_EQ(k, SegmentKind::coast);
    }
}

TEST(Coast, ocean_area_110m_matches_the_source_ocean_layer) {
    // Default: the Caspian (an inland sea, the smaller polygon of the ocean layer) is dropped.
    double oracle = layer_area_km2(fixture("coast/ne_110m_land.gpkg").string(), "ocean", true);
    EXPECT_NEAR(ne110().ocean_area_km2, oracle, 0.005 * oracle);
    EXPECT_EQ(ne110().lakes_removed, 1u);
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.keep_inland_seas = true;
    CoastData with_caspian = load_coast(o);
    double all = layer_area_km2(fixture("coast/ne_110m_land.gpkg").string(), "ocean");
    EXPECT_NEAR(with_caspian.ocean_area_km2, all, 0.005 * all);
    EXPECT_NEAR(with_caspian.ocean_area_km2 - ne110().ocean_area_km2, all - oracle,
                0.01 * (all - oracle));
}

TEST(Coast, antarctica_is_one_ring_around_the_south_pole_without_cut_nodes) {
    for (const CoastData *d : {&ne110(), &ne50()}) {
        int around_south = 0;
        for (const auto &r : d->rings.rings) {
            double w = winding_deg(r);
            if (std::abs(std::abs(w) - 360.0) > 1e-6) {
                EXPECT_NEAR(w, 0.0, 1e-6);
                continue;
            }
            ++around_south;
            for (const auto &v : r.nodes) {
                LonLat p = vec_to_lonlat(v);
                EXPECT_LT(p.lat, -60.0);
                EXPECT_GT(p.lat, -86.0) << "node on the artificial closure near the pole";
                // The data's cut runs down lon +-180 below the coast at about -84.4 (50m) / -84.7.
                if (std::abs(std::abs(p.lon) - 180.0) < 1e-9) {
                    EXPECT_GT(p.lat, -84.8);
                }
            }
            // Ocean on the left: walking east along the coast (positive winding) keeps the sea
            // north.
            EXPECT_GT(w, 0.0);
        }
        EXPECT_EQ(around_south, 1);
    }
}

TEST(Coast, shapefile_and_geopackage_give_the_same_rings) {
    CoastData shp = load_coast(coast_options("coast/ne_110m_land_shp/ne_110m_land.shp", ""));
    ASSERT_EQ(shp.rings.rings.size(), ne110().rings.rings.size());
    for (std::size_t r = 0; r < shp.rings.rings.size(); ++r)
        EXPECT_EQ(shp.rings.rings[r].nodes, ne110().rings.rings[r].nodes) << "ring " << r;
}

// The same land with its features in another order (ogr2ogr to FlatGeobuf sorts them along its
// spatial index) gave other rings in another order, and the mesher, following it, another mesh:
// Natural Earth 110m at --hmax 500 closed the Strait of Gibraltar from the .fgb, not from the
// .gpkg (2047 against 2052 nodes). The rings now come in one order of their own.
TEST(Coast, the_order_of_the_features_does_not_change_the_rings) {
    globemesh::test::TempDir dir;
    const std::string sorted = (dir / "land.fgb").string();
    ASSERT_TRUE(test::ogr2ogr(fixture("coast/ne_110m_land.gpkg").string(), sorted, {"land"}));
    const CoastData r = load_coast(coast_options_at(sorted));
    ASSERT_EQ(r.rings.rings.size(), ne110().rings.rings.size());
    for (std::size_t k = 0; k < r.rings.rings.size(); ++k)
        EXPECT_EQ(r.rings.rings[k].nodes, ne110().rings.rings[k].nodes) << "ring " << k;
}

TEST(Coast, projected_copy_gives_the_same_rings_within_one_metre) {
    CoastData proj = load_coast(coast_options("coast/ne_110m_land_equal_earth.gpkg"));
    const auto &ref = ne110().rings.rings;
    ASSERT_EQ(proj.rings.rings.size(), ref.size());
    double worst_km = 0;
    for (std::size_t r = 0; r < ref.size(); ++r) {
        ASSERT_EQ(proj.rings.rings[r].nodes.size(), ref[r].nodes.size()) << "ring " << r;
        for (std::size_t i = 0; i < ref[r].nodes.size(); ++i)
            worst_km = std::max(worst_km, arc_km(proj.rings.rings[r].nodes[i], ref[r].nodes[i]));
    }
    EXPECT_LT(worst_km, 1e-3);
    EXPECT_NEAR(proj.ocean_area_km2, ne110().ocean_area_km2, 1.0);
}

TEST(Coast, natural_earth_50m_rings_are_valid_and_enclose_the_ocean_area) {
    const auto &d = ne50();
    expect_valid(d.rings);
    double oracle = layer_area_km2(fixture("coast/ne_50m_land.gpkg").string(), "ocean", true);
    EXPECT_NEAR(d.ocean_area_km2, oracle, 0.005 * oracle);
}

TEST(Coast, coastline_lines_are_polygonized_like_the_land_polygons) {
    CoastData lines = load_coast(coast_options("coast/ne_50m_coastline.gpkg", ""));
    EXPECT_EQ(lines.layer, "coastline");
    expect_valid(lines.rings);
    EXPECT_NEAR(lines.ocean_area_km2, ne50().ocean_area_km2, 0.005 * ne50().ocean_area_km2);
    EXPECT_NEAR(static_cast<double>(lines.rings.rings.size()),
                static_cast<double>(ne50().rings.rings.size()), 10.0);
}

TEST(Coast, shaping_at_100_and_10_km_keeps_every_invariant) {
    for (const CoastData *d : {&ne110(), &ne50()}) {
        for (double h : {100.0, 10.0}) {
            CoastReport rep;
            MeshOptions o;
            Boundary b = shape_boundary(*d, uniform(h), o, &rep);
            expect_valid(b);
            if (d == &ne110()) {
                EXPECT_EQ(count_violations(b), 0u) << "h " << h;
            }
            EXPECT_EQ(rep.rings, b.rings.size());
            EXPECT_EQ(rep.nodes, node_count(b));
            // Consecutive nodes are at most about h apart (arcs are split to round(L/h) pieces).
            double longest = 0;
            for (const auto &r : b.rings)
                for (std::size_t i = 0; i < r.nodes.size(); ++i)
                    longest =
                        std::max(longest, arc_km(r.nodes[i], r.nodes[(i + 1) % r.nodes.size()]));
            EXPECT_LT(longest, 1.5 * h) << "h " << h;
            // Small islands go, the ocean area hardly changes.
            EXPECT_NEAR(rep.ocean_area_km2, d->ocean_area_km2, 0.01 * d->ocean_area_km2)
                << "h " << h;
            EXPECT_NEAR(boundary_area_km2(b), rep.ocean_area_km2, 1.0);
            // Islands (land area < a quarter of the Earth) survive iff their full-resolution
            // area reaches 4 equilateral triangles of side h (1 % margin: spherical vs WGS84).
            double earth = GeographicLib::Geodesic::WGS84().EllipsoidArea() * 1e-6;
            double min_island = 4 * std::sqrt(3.0) / 4 * h * h;
            std::size_t surely_kept = 0, maybe_kept = 0;
            for (const auto &r : d->rings.rings) {
                Boundary one;
                one.rings.push_back(r);
                double land = earth - boundary_area_km2(one);
                bool island = land < 0.25 * earth;
                if (!island || land > 1.01 * min_island)
                    ++surely_kept;
                if (!island || land > 0.99 * min_island)
                    ++maybe_kept;
            }
            EXPECT_GE(b.rings.size(), surely_kept) << "h " << h;
            EXPECT_LE(b.rings.size(), maybe_kept) << "h " << h;
        }
    }
}

// The issue's fidelity target: boundary nodes within h/4 of the source coast (95th percentile),
// measured by brute force against every source arc; and coast segments near h, so that the
// mesher's triangles on them can be near equilateral (runs between corners are cut evenly).
TEST(Coast, shaped_nodes_stay_near_the_source_and_segments_near_the_size) {
    const double h = 200;
    MeshOptions o;
    Boundary b = shape_boundary(ne110(), uniform(h), o);
    std::vector<double> distance, length;
    for (const auto &r : b.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            const Vec3 &p = r.nodes[i];
            double nearest = pi;
            for (const auto &s : ne110().rings.rings)
                for (std::size_t k = 0; k < s.nodes.size(); ++k)
                    nearest = std::min(
                        nearest, arc_distance(s.nodes[k], s.nodes[(k + 1) % s.nodes.size()], p));
            distance.push_back(nearest * earth_radius_km);
            length.push_back(arc_km(p, r.nodes[(i + 1) % r.nodes.size()]));
        }
    std::sort(distance.begin(), distance.end());
    EXPECT_LT(distance[distance.size() * 95 / 100], h / 4);
    EXPECT_LT(distance.back(), h / 2);
    const auto near_h = std::count_if(length.begin(), length.end(),
                                      [&](double l) { return l >= 0.7 * h && l <= 1.4 * h; });
    std::printf("nodes %zu: distance p95 %.1f km, max %.1f km; segments in [0.7, 1.4] h: %.1f%%\n",
                distance.size(), distance[distance.size() * 95 / 100], distance.back(),
                100.0 * near_h / length.size());
    EXPECT_GT(double(near_h), 0.8 * length.size());
}

// A size of metres asks the global coast for hundreds of millions of nodes: refused before the
// resampling makes them, by --max-nodes (the coast alone is a lower bound of the mesh's nodes).
// The 1:110m coast is about 2.6e5 km long (the sum of its arcs, measured below), so 1 m asks
// for over 1e8 nodes and 100 km for a few thousand.
TEST(Coast, a_coast_that_alone_exceeds_max_nodes_is_refused_before_it_is_resampled) {
    double length_km = 0;
    for (const auto &r : ne110().rings.rings)
        for (std::size_t k = 0; k < r.nodes.size(); ++k)
            length_km += arc_km(r.nodes[k], r.nodes[(k + 1) % r.nodes.size()]);
    ASSERT_GT(length_km / 0.001, 1e8);
    MeshOptions o;
    o.max_nodes = 20'000'000;
    const std::string m = test::thrown_message<DataError>(
        [&] { shape_boundary(ne110(), uniform(0.001), o); }, "a 1 m coast");
    EXPECT_NE(m.find("more than max_nodes 20000000: raise hmin_km/hmax_km or max_nodes"),
              std::string::npos)
        << m;
    // At 100 km the same bound lets it through, with nodes to spare.
    o.max_nodes = static_cast<std::uint64_t>(length_km / 100 * 2);
    CoastReport rep;
    shape_boundary(ne110(), uniform(100), o, &rep);
    EXPECT_GT(rep.nodes, 1000u);
}

TEST(Coast, shaping_follows_a_varying_size) {
    // h = 20 km north of the equator, 200 km south of it.
    auto size = [](const Vec3 &v) { return v.z > 0 ? 20.0 : 200.0; };
    MeshOptions o;
    Boundary b = shape_boundary(ne110(), size, o);
    expect_valid(b);
    double north = 0, south = 0;
    std::size_t nn = 0, ns = 0;
    for (const auto &r : b.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            double d = arc_km(r.nodes[i], r.nodes[(i + 1) % r.nodes.size()]);
            if (r.nodes[i].z > 0.1)
                north += d, ++nn;
            if (r.nodes[i].z < -0.1)
                south += d, ++ns;
        }
    ASSERT_GT(nn, 0u);
    ASSERT_GT(ns, 0u);
    EXPECT_LT(north / nn, 25.0);
    EXPECT_GT(south / ns, 60.0);
}

/// The source's ocean layer clipped to a lon/lat box: its area (km2, on WGS84, GeographicLib) and
/// its islands (the holes of the clipped polygons).
struct ClippedOcean {
    double area_km2 = 0;
    std::size_t islands = 0;
};
ClippedOcean clipped_ocean(const std::string &path, const std::array<double, 4> &box) {
    GDALAllRegister();
    GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    EXPECT_NE(ds, nullptr) << path;
    ClippedOcean out;
    if (!ds)
        return out;
    OGRGeometryH rect = OGR_G_CreateGeometry(wkbPolygon),
                 ring = OGR_G_CreateGeometry(wkbLinearRing);
    for (auto [x, y] : {std::pair{box[0], box[1]},
                        {box[2], box[1]},
                        {box[2], box[3]},
                        {box[0], box[3]},
                        {box[0], box[1]}})
        OGR_G_AddPoint_2D(ring, x, y);
    OGR_G_AddGeometryDirectly(rect, ring);
    const auto &wgs = GeographicLib::Geodesic::WGS84();
    auto ring_area = [&](OGRGeometryH r) {
        GeographicLib::PolygonArea poly(wgs);
        for (int i = 0; i + 1 < OGR_G_GetPointCount(r); ++i)
            poly.AddPoint(OGR_G_GetY(r, i), OGR_G_GetX(r, i));
        double perimeter, area;
        poly.Compute(false, false, perimeter, area); // either way round: the smaller side
        return std::min(area, wgs.EllipsoidArea() - area) * 1e-6;
    };
    OGRLayerH layer = GDALDatasetGetLayerByName(ds, "ocean");
    OGR_L_ResetReading(layer);
    while (OGRFeatureH f = OGR_L_GetNextFeature(layer)) {
        OGRGeometryH cut = OGR_G_Intersection(OGR_F_GetGeometryRef(f), rect);
        const bool multi = wkbFlatten(OGR_G_GetGeometryType(cut)) == wkbMultiPolygon;
        for (int p = 0; p < (multi ? OGR_G_GetGeometryCount(cut) : 1); ++p) {
            OGRGeometryH poly = multi ? OGR_G_GetGeometryRef(cut, p) : cut;
            if (OGR_G_IsEmpty(poly) || OGR_G_GetGeometryCount(poly) == 0)
                continue;
            out.area_km2 += ring_area(OGR_G_GetGeometryRef(poly, 0));
            for (int h = 1; h < OGR_G_GetGeometryCount(poly); ++h, ++out.islands)
                out.area_km2 -= ring_area(OGR_G_GetGeometryRef(poly, h));
        }
        OGR_G_DestroyGeometry(cut);
        OGR_F_Destroy(f);
    }
    OGR_G_DestroyGeometry(rect);
    GDALClose(ds);
    return out;
}

TEST(Coast, a_region_with_islands_inside_holds_the_source_ocean_clipped_to_it) {
    // Celebes Sea to the Moluccas: 13 islands lie wholly inside the box, which the coast stage
    // keeps out of the overlay (each becomes a hole of the ocean polygon holding it); Sulawesi and
    // Halmahera cross its edges. 8 degrees at 6S..2N: the box's great-circle edges lie within
    // 0.012 degrees of the parallels.
    const std::array<double, 4> box{119, -6, 127, 2};
    MeshOptions o = coast_options("coast/ne_50m_land.gpkg");
    o.region = box;
    const CoastData d = load_coast(o);
    expect_valid(d.rings);
    const ClippedOcean oracle = clipped_ocean(fixture("coast/ne_50m_land.gpkg").string(), box);
    std::size_t islands = 0; // rings with no open segment: the coast all round
    for (const auto &r : d.rings.rings)
        islands += std::none_of(r.kinds.begin(), r.kinds.end(),
                                [](SegmentKind k) { return k == SegmentKind::open; });
    EXPECT_NEAR(d.ocean_area_km2, oracle.area_km2, 0.003 * oracle.area_km2);
    EXPECT_EQ(islands, oracle.islands);
}

TEST(Coast, region_across_the_antimeridian_gets_open_edges_on_the_box) {
    MeshOptions o = coast_options("coast/ne_50m_land.gpkg");
    o.region = std::array<double, 4>{170, -25, -170, -10}; // around Fiji
    CoastData d = load_coast(o);
    expect_valid(d.rings);
    EXPECT_EQ(count_violations(d.rings), 0u);
    std::size_t open = 0, coast = 0;
    for (const auto &r : d.rings.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            LonLat p = vec_to_lonlat(r.nodes[i]);
            EXPECT_TRUE(p.lon >= 170 - 1e-9 || p.lon <= -170 + 1e-9) << p.lon;
            EXPECT_GE(p.lat, -25 - 1e-9);
            EXPECT_LE(p.lat, -10 + 1e-9);
            if (r.kinds[i] == SegmentKind::open) {
                ++open;
                LonLat q = vec_to_lonlat(r.nodes[(i + 1) % r.nodes.size()]);
                bool on_box = (std::abs(p.lat - q.lat) < 1e-9 &&
                               (std::abs(p.lat + 25) < 1e-9 || std::abs(p.lat + 10) < 1e-9)) ||
                              (std::abs(p.lon - q.lon) < 1e-9 &&
                               (std::abs(p.lon - 170) < 1e-9 || std::abs(p.lon + 170) < 1e-9));
                EXPECT_TRUE(on_box) << p.lon << " " << p.lat << " -> " << q.lon << " " << q.lat;
                // No open edge along the glued +-180 seam.
                EXPECT_FALSE(std::abs(std::abs(p.lon) - 180) < 1e-9 &&
                             std::abs(std::abs(q.lon) - 180) < 1e-9);
            } else {
                ++coast;
            }
        }
    EXPECT_GT(open, 0u);
    EXPECT_GT(coast, 0u);
    // Ocean area: the box (20 x 15 degrees) less a little land; the box's geodesic area bounds it.
    GeographicLib::PolygonArea box(GeographicLib::Geodesic::WGS84());
    for (double lon = 170; lon < 190; lon += 0.5)
        box.AddPoint(-25, lon);
    for (double lat = -25; lat < -10; lat += 0.5)
        box.AddPoint(lat, 190);
    for (double lon = 190; lon > 170; lon -= 0.5)
        box.AddPoint(-10, lon);
    for (double lat = -10; lat > -25; lat -= 0.5)
        box.AddPoint(lat, 170);
    double perimeter, area;
    box.Compute(false, true, perimeter, area);
    area *= 1e-6;
    EXPECT_LT(d.ocean_area_km2, area);
    EXPECT_GT(d.ocean_area_km2, 0.97 * area);
    Boundary b = shape_boundary(d, uniform(20), o);
    expect_valid(b);
}

TEST(Coast, region_reaching_the_north_pole_has_no_pole_node) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.region = std::array<double, 4>{-180, 65, 180, 90}; // the Arctic cap
    CoastData d = load_coast(o);
    expect_valid(d.rings);
    EXPECT_EQ(count_violations(d.rings), 0u);
    std::size_t open = 0;
    for (const auto &r : d.rings.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            LonLat p = vec_to_lonlat(r.nodes[i]);
            EXPECT_LT(p.lat, 89.0);
            EXPECT_GE(p.lat, 65 - 1e-9);
            if (r.kinds[i] == SegmentKind::open) {
                ++open;
                EXPECT_NEAR(p.lat, 65.0, 1e-9);
            }
        }
    EXPECT_GT(open, 0u);
    // Less than the cap north of 65 N, more than half of it (the Arctic Ocean dominates).
    double cap = 2 * pi * earth_radius_km * earth_radius_km * (1 - std::sin(65 * deg_to_rad));
    EXPECT_LT(d.ocean_area_km2, cap);
    EXPECT_GT(d.ocean_area_km2, 0.5 * cap);
    expect_valid(shape_boundary(d, uniform(50), o));
}

TEST(Coast, open_region_box_in_the_open_sea_is_all_open_boundary) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.region = std::array<double, 4>{-150, -30, -130, -10};
    CoastData d = load_coast(o);
    ASSERT_EQ(d.rings.rings.size(), 1u);
    for (auto k : d.rings.rings[0].kinds)
        EXPECT_EQ(k, SegmentKind::open);
    // Oracle: the box's geodesic area with edges densified as the rings are (0.5 degree).
    GeographicLib::PolygonArea box(GeographicLib::Geodesic::WGS84());
    for (double lon = -150; lon < -130; lon += 0.5)
        box.AddPoint(-30, lon);
    for (double lat = -30; lat < -10; lat += 0.5)
        box.AddPoint(lat, -130);
    for (double lon = -130; lon > -150; lon -= 0.5)
        box.AddPoint(-10, lon);
    for (double lat = -10; lat > -30; lat -= 0.5)
        box.AddPoint(lat, -150);
    double perimeter, area;
    box.Compute(false, true, perimeter, area);
    EXPECT_NEAR(d.ocean_area_km2, area * 1e-6, 1e-6 * area * 1e-6);
}

TEST(Coast, region_boxes_reaching_the_south_pole_or_the_seam_keep_the_invariants) {
    for (std::array<double, 4> box :
         {std::array<double, 4>{-180, -90, 180, -60}, std::array<double, 4>{-180, -50, 100, 10},
          std::array<double, 4>{0, 70, 90, 90}, std::array<double, 4>{150, -60, -120, 60}}) {
        MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
        o.region = box;
        CoastData d = load_coast(o);
        expect_valid(d.rings);
        EXPECT_EQ(count_violations(d.rings), 0u) << box[0] << " " << box[1];
        std::size_t open = 0;
        for (const auto &r : d.rings.rings)
            for (std::size_t i = 0; i < r.nodes.size(); ++i) {
                LonLat p = vec_to_lonlat(r.nodes[i]);
                EXPECT_GE(p.lat, box[1] - 1e-9);
                EXPECT_LE(p.lat, box[3] + 1e-9);
                if (r.kinds[i] == SegmentKind::open)
                    ++open;
            }
        EXPECT_GT(open, 0u);
        expect_valid(shape_boundary(d, uniform(100), o));
    }
}

TEST(Coast, region_file_in_a_projected_crs_bounds_the_ocean_with_open_edges) {
    globemesh::test::TempDir dir;
    // A 2000 km square in the North Atlantic, in Web Mercator metres.
    auto path = (dir / "region.geojson").string();
    std::ofstream(path) << "{\"type\":\"FeatureCollection\",\"crs\":{\"type\":\"name\","
                           "\"properties\":{\"name\":\"EPSG:3857\"}},"
                           "\"features\":[{\"type\":\"Feature\",\"properties\":{},\"geometry\":{"
                           "\"type\":\"Polygon\","
                           "\"coordinates\":[[[-4000000,4000000],[-2000000,4000000],[-2000000,"
                           "7000000],[-4000000,7000000],[-4000000,4000000]]]}}]}";
    MeshOptions o = coast_options("coast/ne_50m_land.gpkg");
    o.region_file = path;
    CoastData d = load_coast(o);
    expect_valid(d.rings);
    EXPECT_EQ(count_violations(d.rings), 0u);
    std::size_t open = 0;
    for (const auto &r : d.rings.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            LonLat p = vec_to_lonlat(r.nodes[i]);
            // -4e6 m and -2e6 m are lon -35.93 and -17.97 degrees in Web Mercator.
            EXPECT_GE(p.lon, -35.94);
            EXPECT_LE(p.lon, -17.96);
            if (r.kinds[i] == SegmentKind::open)
                ++open;
        }
    EXPECT_GT(open, 0u);
    expect_valid(shape_boundary(d, uniform(30), o));
}

/// A GeoJSON file in `dir` holding one feature of `geometry` (lon/lat, or `crs` when given).
std::string geojson_file(const globemesh::test::TempDir &dir, const std::string &name,
                         const std::string &geometry, const std::string &crs = "") {
    const std::string path = (dir / name).string();
    std::ofstream(path) << "{\"type\":\"FeatureCollection\","
                        << (crs.empty() ? ""
                                        : "\"crs\":{\"type\":\"name\",\"properties\":{\"name\":\"" +
                                              crs + "\"}},")
                        << "\"features\":[{\"type\":\"Feature\",\"properties\":{},"
                        << "\"geometry\":" << geometry << "}]}";
    return path;
}

/// Segments of `b` of kind `kind` that run along the +-180 meridian.
std::size_t seam_segments(const Boundary &b, SegmentKind kind) {
    std::size_t n = 0;
    for (const auto &r : b.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            const LonLat p = vec_to_lonlat(r.nodes[i]),
                         q = vec_to_lonlat(r.nodes[(i + 1) % r.nodes.size()]);
            n += r.kinds[i] == kind && std::abs(std::abs(p.lon) - 180) < 1e-9 &&
                 std::abs(std::abs(q.lon) - 180) < 1e-9;
        }
    return n;
}

// A --region-file polygon across +-180 (lon 170 to 190, or two polygons split at 180), or round
// the North Pole in lon/lat (north of 65N, two of its sides on the seam), bounds the ocean of the
// same --region box: its pieces either side of the seam join there, as the box's do. The seam's
// two sides were open edges on one meridian: refused as an outline along the coast (the cap,
// the split polygons) or the part past 180 dropped (found by a sweep). A region that ends at 180
// keeps its side there open.
TEST(Coast, a_region_file_across_the_antimeridian_or_round_a_pole_bounds_the_box_ocean) {
    globemesh::test::TempDir dir;
    const std::string fiji_box = "[[170,-25],[180,-25],[180,-10],[170,-10],[170,-25]]";
    const std::string tonga_box = "[[-180,-25],[-170,-25],[-170,-10],[-180,-10],[-180,-25]]";
    struct Case {
        std::string name, geometry;
        std::array<double, 4> box;
    };
    for (
        const Case &c :
        {Case{
             "past_180.geojson",
             R"({"type":"Polygon","coordinates":[[[170,-25],[190,-25],[190,-10],[170,-10],[170,-25]]]})",
             {170, -25, -170, -10}},
         Case{"split.geojson",
              R"({"type":"MultiPolygon","coordinates":[[)" + fiji_box + "],[" + tonga_box + "]]}",
              {170, -25, -170, -10}},
         Case{
             "cap.geojson",
             R"({"type":"Polygon","coordinates":[[[-180,65],[180,65],[180,90],[-180,90],[-180,65]]]})",
             {-180, 65, 180, 90}},
         Case{"to_180.geojson",
              R"({"type":"Polygon","coordinates":[)" + fiji_box + "]}",
              {170, -25, 180, -10}}}) {
        SCOPED_TRACE(c.name);
        MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
        o.region = c.box;
        const CoastData box = load_coast(o);
        o.region.reset();
        o.region_file = geojson_file(dir, c.name, c.geometry);
        const CoastData file = load_coast(o);
        expect_valid(file.rings);
        EXPECT_NEAR(file.ocean_area_km2, box.ocean_area_km2, 1e-6 * box.ocean_area_km2);
        EXPECT_EQ(file.rings.rings.size(), box.rings.rings.size());
        EXPECT_EQ(seam_segments(file.rings, SegmentKind::open),
                  seam_segments(box.rings, SegmentKind::open));
        expect_valid(shape_boundary(file, uniform(50), o));
    }
}

// A --region-file read the whole coast layer (GSHHG f about the Oresund: 16 s and 2.0 GB, where
// the same --region box took 0.27 s): the coast is now read near the region's polygons' box, as
// a box's is. NE 1:50m about the Oresund: the land kept for the mesher's land test is about the
// box's, not the world's, and the ocean the same.
TEST(Coast, a_region_file_reads_the_coast_near_its_polygons_alone) {
    const globemesh::test::TempDir dir;
    MeshOptions o = coast_options("coast/ne_50m_land.gpkg");
    const std::size_t whole = load_coast(o).land->vertices();
    o.region = std::array<double, 4>{12.3, 55.45, 13.0, 56.3};
    const CoastData box = load_coast(o);
    o.region.reset();
    o.region_file = geojson_file(
        dir, "oresund.geojson",
        R"({"type":"Polygon","coordinates":[[[12.3,55.45],[13,55.45],[13,56.3],[12.3,56.3],[12.3,55.45]]]})");
    const CoastData file = load_coast(o);
    EXPECT_LT(file.land->vertices(), whole / 20) << box.land->vertices();
    EXPECT_NEAR(file.ocean_area_km2, box.ocean_area_km2, 1e-6 * box.ocean_area_km2);
}

/// A circle of `radius_m` about the North Pole in polar stereographic EPSG:3413 (128 vertices),
/// as a GeoJSON polygon, and the latitude its vertices lie at.
std::pair<std::string, double> polar_circle(double radius_m) {
    std::string ring;
    for (int k = 0; k <= 128; ++k) {
        const double a = 2 * pi * (k % 128) / 128;
        ring += (k ? "," : "") + std::string("[") + std::to_string(radius_m * std::cos(a)) + "," +
                std::to_string(radius_m * std::sin(a)) + "]";
    }
    OGRSpatialReferenceH polar = OSRNewSpatialReference(nullptr),
                         wgs84 = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(polar, 3413);
    OSRImportFromEPSG(wgs84, 4326);
    OSRSetAxisMappingStrategy(wgs84, OAMS_TRADITIONAL_GIS_ORDER);
    OGRCoordinateTransformationH to_lonlat = OCTNewCoordinateTransformation(polar, wgs84);
    double x = radius_m, y = 0;
    OCTTransform(to_lonlat, 1, &x, &y, nullptr);
    OCTDestroyCoordinateTransformation(to_lonlat);
    OSRDestroySpatialReference(polar);
    OSRDestroySpatialReference(wgs84);
    return {R"({"type":"Polygon","coordinates":[[)" + ring + "]]}", y};
}

// A polygon about a pole in a polar CRS comes back to lon/lat as a ring round the pole, which
// bounds nothing there, or through it at the longitude the projection gives the pole: closed
// through the pole it is the cap it held. A 1500 km circle in EPSG:3413 as --region-file was
// refused ("GEOS failed to take the region outline: ... GeometryCollection", found by a sweep):
// now the ocean of the --region box north of the latitude it lies at. Natural Earth's land in
// EPSG:3031 (Antarctica through the South Pole, at the longitude 0 the projection gives it)
// lost the land round the pole: now the rings of the lon/lat source.
TEST(Coast, a_polygon_about_a_pole_in_a_polar_crs_closes_through_the_pole) {
    globemesh::test::TempDir dir;
    const auto [circle, lat] = polar_circle(1.5e6);
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.region = {-180, lat, 180, 90};
    const CoastData box = load_coast(o);
    o.region.reset();
    o.region_file = geojson_file(dir, "circle.geojson", circle, "EPSG:3413");
    const CoastData file = load_coast(o);
    expect_valid(file.rings);
    EXPECT_NEAR(file.ocean_area_km2, box.ocean_area_km2, 1e-5 * box.ocean_area_km2);
    EXPECT_EQ(file.rings.rings.size(), box.rings.rings.size());
    expect_valid(shape_boundary(file, uniform(50), o));

    const std::string south = (dir / "land_3031.gpkg").string();
    ASSERT_TRUE(test::ogr2ogr(fixture("coast/ne_110m_land.gpkg").string(), south,
                              {"-t_srs", "EPSG:3031", "land"}));
    const CoastData polar = load_coast(coast_options_at(south));
    EXPECT_EQ(polar.rings.rings.size(), ne110().rings.rings.size());
    EXPECT_NEAR(polar.ocean_area_km2, ne110().ocean_area_km2, 1.0);
}

// A world map in Robinson or Mollweide (ogr2ogr -t_srs from lon/lat) holds the land's vertices
// on +-180 at the map's edge, where rounding puts some a few units in the last place outside the
// domain that PROJ's inverse accepts: the whole layer was refused ("feature 8 cannot be
// reprojected to lon/lat"). Now those vertices come back on the seam: Robinson gives the rings of
// the lon/lat source; Mollweide, which draws the pole as a 225 m line, the same ocean area.
TEST(Coast, a_world_map_in_robinson_or_mollweide_reads_its_edge_vertices) {
    globemesh::test::TempDir dir;
    const std::string robin = (dir / "land_robin.gpkg").string();
    ASSERT_TRUE(test::ogr2ogr(fixture("coast/ne_110m_land.gpkg").string(), robin,
                              {"-t_srs", "+proj=robin +datum=WGS84", "land"}));
    const CoastData r = load_coast(coast_options_at(robin));
    ASSERT_EQ(r.rings.rings.size(), ne110().rings.rings.size());
    double worst_km = 0;
    for (std::size_t k = 0; k < r.rings.rings.size(); ++k) {
        const auto &ref = ne110().rings.rings[k].nodes;
        ASSERT_EQ(r.rings.rings[k].nodes.size(), ref.size()) << "ring " << k;
        for (std::size_t i = 0; i < ref.size(); ++i)
            worst_km = std::max(worst_km, arc_km(r.rings.rings[k].nodes[i], ref[i]));
    }
    EXPECT_LT(worst_km, 1e-3);

    const std::string moll = (dir / "land_moll.gpkg").string();
    ASSERT_TRUE(test::ogr2ogr(fixture("coast/ne_110m_land.gpkg").string(), moll,
                              {"-t_srs", "+proj=moll +datum=WGS84", "land"}));
    const CoastData m = load_coast(coast_options_at(moll));
    expect_valid(m.rings);
    EXPECT_EQ(m.rings.rings.size(), ne110().rings.rings.size());
    EXPECT_NEAR(m.ocean_area_km2, ne110().ocean_area_km2, 1e-5 * ne110().ocean_area_km2);

    // A region round the globe between 60S and 30S: Robinson's inverse needs its edge points at
    // the latitudes of its table (every 5 degrees) pulled 2.4e-7 of the way in, and they come
    // back 2e-5 degrees off +-180: put on it, the outline closes across the seam as in lon/lat.
    const std::string band = (dir / "band.geojson").string(),
                      band_robin = (dir / "band_robin.gpkg").string();
    {
        std::ofstream f(band);
        f << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
             R"("geometry":{"type":"Polygon","coordinates":[[)";
        for (int lat = -60; lat < -30; lat += 5)
            f << "[180," << lat << "],";
        for (int lon = 180; lon > -180; lon -= 10)
            f << "[" << lon << ",-30],";
        for (int lat = -30; lat > -60; lat -= 5)
            f << "[-180," << lat << "],";
        for (int lon = -180; lon < 180; lon += 10)
            f << "[" << lon << ",-60],";
        f << "[180,-60]]]}}]}";
    }
    ASSERT_TRUE(test::ogr2ogr(band, band_robin, {"-t_srs", "+proj=robin +datum=WGS84"}));
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.region_file = band;
    const CoastData in_lonlat = load_coast(o);
    o.region_file = band_robin;
    const CoastData in_robin = load_coast(o);
    expect_valid(in_robin.rings);
    EXPECT_EQ(in_robin.rings.rings.size(), in_lonlat.rings.rings.size());
    EXPECT_NEAR(in_robin.ocean_area_km2, in_lonlat.ocean_area_km2, 1e-5 * in_lonlat.ocean_area_km2);
}

// The land itself, reprojected to Equal Earth and back, as the region: the region's outline runs
// along the coast everywhere, a few micro-degrees off it. An outline that follows the coast is
// land where it is on land (issue 37), so no sliver of ocean is left between them: the region is
// all land, and the error says so, not that the data or the outline is at fault.
TEST(Coast, a_region_outline_along_the_coast_is_land_there) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.region_file = fixture("coast/ne_110m_land_equal_earth.gpkg").string();
    const std::string m =
        test::thrown_message<DataError>([&] { load_coast(o); }, "a region that is all land");
    EXPECT_NE(m.find("no ocean is left in the region (it is all land)"), std::string::npos) << m;
}

TEST(Coast, attribute_filter_selects_features) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.coast_where = "scalerank = 0";
    CoastData d = load_coast(o);
    expect_valid(d.rings);
    EXPECT_LT(d.rings.rings.size(), ne110().rings.rings.size());
    EXPECT_GT(d.ocean_area_km2, ne110().ocean_area_km2);
}

TEST(Coast, min_island_area_drops_small_islands_by_geodesic_area) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg");
    o.min_island_area_km2 = 50000;
    CoastData d = load_coast(o);
    expect_valid(d.rings);
    EXPECT_GT(d.islands_removed, 10u);
    EXPECT_LT(d.rings.rings.size(), ne110().rings.rings.size());
    EXPECT_NEAR(d.ocean_area_km2 - ne110().ocean_area_km2,
                d.area_gained_km2 - d.area_lost_km2 + ne110().area_lost_km2,
                1e-6 * ne110().ocean_area_km2);
}

// The land test the mesher uses to keep face centres off land, against OGR's own point-in-polygon
// on the source features (GIS semantics: a lake, a hole of the land, is not land), and its coast
// distance against a brute-force distance to the loaded rings on the sphere.
TEST(Coast, land_mask_agrees_with_ogr_on_the_source_polygons) {
    const CoastData &d = ne110();
    ASSERT_TRUE(d.land);
    GDALAllRegister();
    GDALDatasetH ds = GDALOpenEx(fixture("coast/ne_110m_land.gpkg").string().c_str(),
                                 GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    ASSERT_NE(ds, nullptr);
    OGRLayerH layer = GDALDatasetGetLayerByName(ds, "land");
    std::vector<OGRGeometryH> source;
    OGR_L_ResetReading(layer);
    while (OGRFeatureH f = OGR_L_GetNextFeature(layer)) {
        source.push_back(OGR_G_Clone(OGR_F_GetGeometryRef(f)));
        OGR_F_Destroy(f);
    }
    GDALClose(ds);
    auto ogr_land = [&](const LonLat &ll) {
        OGRGeometryH pt = OGR_G_CreateGeometry(wkbPoint);
        OGR_G_SetPoint_2D(pt, 0, ll.lon, ll.lat);
        bool in = false;
        for (auto g : source)
            in = in || OGR_G_Contains(g, pt);
        OGR_G_DestroyGeometry(pt);
        return in;
    };
    std::mt19937 rng(11);
    std::normal_distribution<double> gauss;
    std::size_t land = 0, disagree = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 p = normalized(Vec3{gauss(rng), gauss(rng), gauss(rng)});
        const bool in = d.land->contains(p);
        land += in;
        disagree += in != ogr_land(vec_to_lonlat(p));
    }
    EXPECT_EQ(disagree, 0u);
    EXPECT_NEAR(double(land) / 3000, 0.29, 0.03);            // land covers 29% of the Earth
    EXPECT_TRUE(d.land->contains(lonlat_to_vec(15, 25)));    // the Sahara
    EXPECT_FALSE(d.land->contains(lonlat_to_vec(-30, 30)));  // the Atlantic
    EXPECT_FALSE(d.land->contains(lonlat_to_vec(50.5, 42))); // the Caspian, a hole of the land
    // The source's rings (shells and holes: lake shores are coast too) as arcs on the sphere.
    std::vector<std::vector<Vec3>> outlines;
    std::function<void(OGRGeometryH)> collect = [&](OGRGeometryH g) {
        if (OGR_G_GetGeometryCount(g) > 0) {
            for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
                collect(OGR_G_GetGeometryRef(g, i));
            return;
        }
        std::vector<Vec3> ring;
        for (int i = 0; i < OGR_G_GetPointCount(g); ++i)
            ring.push_back(lonlat_to_vec(OGR_G_GetX(g, i), OGR_G_GetY(g, i)));
        outlines.push_back(std::move(ring));
    };
    for (auto g : source)
        collect(g);

    // Near the coast too, where the land test's cells (a cell no segment's box touches answers
    // from the first point asked in its component) meet the outline: points within a few cells
    // of the source's vertices, a third of them on cell sides and corners (multiples of 1/16
    // degree), each asked twice.
    std::uniform_int_distribution<std::size_t> pick(0, outlines.size() - 1);
    std::uniform_real_distribution<double> offset(-0.15, 0.15);
    std::size_t near_land = 0, near_disagree = 0;
    for (int i = 0; i < 3000; ++i) {
        const auto &r = outlines[pick(rng)];
        const LonLat v =
            vec_to_lonlat(r[std::uniform_int_distribution<std::size_t>(0, r.size() - 1)(rng)]);
        LonLat q{v.lon + offset(rng), std::clamp(v.lat + offset(rng), -90.0, 90.0)};
        if (i % 3 == 0)
            q = {std::round(q.lon * 16) / 16, std::round(q.lat * 16) / 16};
        const Vec3 p = lonlat_to_vec(q.lon, q.lat);
        const bool in = d.land->contains(p);
        EXPECT_EQ(d.land->contains(p), in);
        near_land += in;
        near_disagree += in != ogr_land(vec_to_lonlat(p));
    }
    EXPECT_EQ(near_disagree, 0u);
    EXPECT_GT(near_land, 600u);
    EXPECT_LT(near_land, 2400u);
    for (auto g : source)
        OGR_G_DestroyGeometry(g);

    // coast_within and coast_distance agree with the brute-force distance on the sphere, at every
    // latitude and across +-180 (the source splits land there; a cap that crosses it must find
    // both sides).
    std::uniform_real_distribution<double> lon(-180, 180), lat(-85, 85), reach(0.002, 0.1);
    int yes = 0, no = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3 p = i < 20 ? lonlat_to_vec(i % 2 ? 179.9 : -179.9, 66 + i * 0.3)
                              : lonlat_to_vec(lon(rng), lat(rng));
        const double a = reach(rng);
        double nearest = pi;
        for (const auto &r : outlines)
            for (std::size_t k = 0; k + 1 < r.size(); ++k)
                nearest = std::min(nearest, arc_distance(r[k], r[k + 1], p));
        if (std::abs(nearest - a) < 1e-9)
            continue; // a tie: either answer is right
        const bool within = d.land->coast_within(p, a);
        EXPECT_EQ(within, nearest <= a) << vec_to_lonlat(p).lon << " " << vec_to_lonlat(p).lat
                                        << " reach " << a << " nearest " << nearest;
        // coast_distance: the same nearest arc, or the reach beyond it (within 1e-9 rad, 6 mm,
        // as the ties above: near +-180 the mask's outline has vertices of its own).
        EXPECT_NEAR(d.land->coast_distance(p, a), std::min(nearest, a), 1e-8)
            << vec_to_lonlat(p).lon << " " << vec_to_lonlat(p).lat << " reach " << a;
        (within ? yes : no) += 1;
    }
    EXPECT_GT(yes, 30);
    EXPECT_GT(no, 30);
}

TEST(Coast, a_copy_of_the_land_test_built_on_another_thread_answers_as_the_original) {
    // The parts' threads each take a copy (mesh_parts): the same answers, or the mesh would
    // depend on the thread count.
    const CoastData &d = ne50();
    const auto copier = d.land->copier();
    ASSERT_TRUE(copier);
    std::shared_ptr<const LandTest> copy;
    std::thread([&] { copy = copier(); }).join();
    ASSERT_TRUE(copy);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> lon(-180, 180), z(-1, 1), reach(0.001, 0.05);
    int land = 0, near = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 p = lonlat_to_vec(lon(rng), std::asin(z(rng)) * 180 / pi);
        const bool in = d.land->contains(p);
        ASSERT_EQ(copy->contains(p), in) << vec_to_lonlat(p).lon << " " << vec_to_lonlat(p).lat;
        land += in;
        const double a = reach(rng);
        const bool within = d.land->coast_within(p, a);
        ASSERT_EQ(copy->coast_within(p, a), within);
        near += within;
    }
    EXPECT_GT(land, 4000); // about 29% of the sphere is land
    EXPECT_LT(land, 8000);
    EXPECT_GT(near, 500);
}

TEST(Coast, missing_coast_option_is_a_usage_error) {
    MeshOptions o;
    const std::string m = test::thrown_message<UsageError>([&] { load_coast(o); });
    EXPECT_EQ(m.rfind("coast is required", 0), 0u) << m; // the field a library user sets
}

TEST(Coast, two_polygon_layers_without_a_layer_name_list_the_layers) {
    MeshOptions o = coast_options("coast/ne_110m_land.gpkg", "");
    const std::string m = test::thrown_message<DataError>([&] { load_coast(o); });
    EXPECT_NE(m.find("land"), std::string::npos) << m;
    EXPECT_NE(m.find("ocean"), std::string::npos) << m;
}

TEST(Coast, progress_reaches_one_and_cancel_stops) {
    double last = -1;
    Progress p = [&](double f, std::string_view) {
        EXPECT_GE(f, last);
        last = f;
        return true;
    };
    load_coast(coast_options("coast/ne_110m_land.gpkg"), p);
    EXPECT_EQ(last, 1.0);
    Progress stop = [](double, std::string_view) { return false; };
    EXPECT_THROW(load_coast(coast_options("coast/ne_110m_land.gpkg"), stop), Cancelled);
}
