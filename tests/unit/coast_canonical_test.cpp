// The same land stored another way (its rings started elsewhere or reversed, its features in
// another order, its boundaries as lines) gives the same mesh, node for node.
#include <gtest/gtest.h>

#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <string>
#include <vector>

#include "coast_load_internal.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/pipeline.hpp"
#include "support.hpp"
#include "unit/coast_support.hpp"

namespace globemesh {
namespace {

/// How a copy of the land differs from it.
struct Variant {
    bool rotate = false;  // every ring starts a third of the way round
    bool reverse = false; // every ring runs the other way
    bool shuffle = false; // features and polygons in reverse order
};

/// A ring copied as `v` says (a closed OGR linear ring, its last point its first).
OGRGeometryH ring_copy(OGRGeometryH ring, const Variant &v) {
    const int n = OGR_G_GetPointCount(ring) - 1; // without the closing point
    std::vector<std::pair<double, double>> pts;
    for (int i = 0; i < n; ++i)
        pts.emplace_back(OGR_G_GetX(ring, i), OGR_G_GetY(ring, i));
    if (v.rotate)
        std::rotate(pts.begin(), pts.begin() + n / 3, pts.end());
    if (v.reverse)
        std::reverse(pts.begin(), pts.end());
    OGRGeometryH out = OGR_G_CreateGeometry(wkbLinearRing);
    for (const auto &[x, y] : pts)
        OGR_G_AddPoint_2D(out, x, y);
    OGR_G_AddPoint_2D(out, pts.front().first, pts.front().second);
    return out;
}

/// The polygons of a (multi)polygon, each copied as `v` says, as one multipolygon.
OGRGeometryH geometry_copy(OGRGeometryH g, const Variant &v) {
    std::vector<OGRGeometryH> polys;
    const bool single = wkbFlatten(OGR_G_GetGeometryType(g)) == wkbPolygon;
    for (int p = 0; p < (single ? 1 : OGR_G_GetGeometryCount(g)); ++p) {
        OGRGeometryH poly = single ? g : OGR_G_GetGeometryRef(g, p);
        OGRGeometryH out = OGR_G_CreateGeometry(wkbPolygon);
        for (int r = 0; r < OGR_G_GetGeometryCount(poly); ++r)
            OGR_G_AddGeometryDirectly(out, ring_copy(OGR_G_GetGeometryRef(poly, r), v));
        polys.push_back(out);
    }
    if (v.shuffle)
        std::reverse(polys.begin(), polys.end());
    OGRGeometryH multi = OGR_G_CreateGeometry(wkbMultiPolygon);
    for (OGRGeometryH p : polys)
        OGR_G_AddGeometryDirectly(multi, p);
    return multi;
}

/// Writes the land of layer `land` of `src` to `dst` (GeoPackage, layer `land`) as `v` says.
void write_variant(const std::string &src, const std::string &dst, const Variant &v) {
    GDALDatasetH in = GDALOpenEx(src.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    ASSERT_NE(in, nullptr) << src;
    OGRLayerH layer = GDALDatasetGetLayerByName(in, "land");
    std::vector<OGRGeometryH> geoms;
    OGR_L_ResetReading(layer);
    while (OGRFeatureH f = OGR_L_GetNextFeature(layer)) {
        if (OGRGeometryH g = OGR_F_GetGeometryRef(f))
            geoms.push_back(geometry_copy(g, v));
        OGR_F_Destroy(f);
    }
    GDALClose(in);
    if (v.shuffle)
        std::reverse(geoms.begin(), geoms.end());
    GDALDatasetH out =
        GDALCreate(GDALGetDriverByName("GPKG"), dst.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
    ASSERT_NE(out, nullptr) << dst;
    OGRSpatialReferenceH wgs = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(wgs, 4326);
    OGRLayerH ol = GDALDatasetCreateLayer(out, "land", wgs, wkbMultiPolygon, nullptr);
    for (OGRGeometryH g : geoms) {
        OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(ol));
        OGR_F_SetGeometryDirectly(f, g);
        EXPECT_EQ(OGR_L_CreateFeature(ol, f), OGRERR_NONE);
        OGR_F_Destroy(f);
    }
    OSRDestroySpatialReference(wgs);
    GDALClose(out);
}

Mesh global_mesh(const std::string &coast) {
    MeshOptions o;
    o.coast = coast;
    o.hmax_km = 50;
    return mesh_ocean(o).mesh;
}

// Natural Earth 1:50m's British Isles and the coast of France to Denmark, meshed globally at
// 50 km: the shaping kept each ring's first node and resampled from it, and the rings came in
// the source's order, so rotated rings, reordered features and the land given as lines (whose
// rings GEOS starts elsewhere) each made another mesh.
TEST(CoastCanonical, the_same_land_stored_another_way_gives_the_same_mesh) {
    test::TempDir dir;
    const std::string src = test::fixture("coast/ne_50m_land.gpkg").string();
    const std::string orig = (dir / "orig.gpkg").string();
    ASSERT_TRUE(test::ogr2ogr(src, orig,
                              {"-f", "GPKG", "-nln", "land", "-nlt", "MULTIPOLYGON", "-spat", "-11",
                               "49", "2", "61", "-clipsrc", "-11", "49", "2", "61", "land"}));
    const Mesh want = global_mesh(orig);
    ASSERT_GT(want.faces.size(), 1000u);
    std::vector<std::pair<std::string, std::string>> variants;
    auto add = [&](const std::string &name, const Variant &v) {
        const std::string path = (dir / (name + ".gpkg")).string();
        write_variant(orig, path, v);
        variants.emplace_back(name, path);
    };
    add("rotated", {true, false, false});
    add("reversed", {false, true, false});
    add("shuffled", {false, false, true});
    add("all three", {true, true, true});
    const std::string lines = (dir / "lines.gpkg").string();
    ASSERT_TRUE(
        test::ogr2ogr(orig, lines, {"-f", "GPKG", "-nln", "land", "-nlt", "MULTILINESTRING"}));
    variants.emplace_back("as lines", lines);
    for (const auto &[name, path] : variants) {
        const Mesh got = global_mesh(path);
        EXPECT_TRUE(got.nodes == want.nodes) << name << ": " << got.nodes.size() << " nodes, "
                                             << want.nodes.size() << " from the original";
        EXPECT_TRUE(got.faces == want.faces) << name;
    }
}

Ring ring_of(const std::vector<LonLat> &pts) {
    Ring r;
    for (const LonLat &p : pts) {
        r.nodes.push_back(lonlat_to_vec(p));
        r.kinds.push_back(SegmentKind::coast);
    }
    return r;
}

// Two rings meeting at their smallest node (lon 180 on the equator, x = -1) (valid in GEOS, as two
// islands touching at a point) tied in the sort by that node, and kept the order they came in.
TEST(CoastCanonical, rings_meeting_at_their_first_node_are_ordered_by_the_rest) {
    const Ring a = ring_of({{180, 0}, {179, 1}, {178, 0}});
    const Ring b = ring_of({{180, 0}, {178, -0.5}, {179, -1}});
    Boundary ab, ba;
    ab.rings = {a, b};
    ba.rings = {b, a};
    coast_detail::canonical_order(ab);
    coast_detail::canonical_order(ba);
    ASSERT_EQ(ab.rings.size(), 2u);
    for (std::size_t r = 0; r < 2; ++r)
        EXPECT_TRUE(ab.rings[r].nodes == ba.rings[r].nodes) << r;
}

// A ring that passes its smallest node twice (pinched there) started from its first pass, which
// depends on where the source started it.
TEST(CoastCanonical,
     a_ring_through_its_smallest_node_twice_starts_from_one_pass_whatever_its_start) {
    const std::vector<LonLat> pts{{180, 0}, {179, 1}, {178, 0}, {180, 0}, {178, -0.5}, {179, -1}};
    std::vector<LonLat> turned(pts.begin() + 3, pts.end());
    turned.insert(turned.end(), pts.begin(), pts.begin() + 3);
    Boundary one, two;
    one.rings = {ring_of(pts)};
    two.rings = {ring_of(turned)};
    coast_detail::canonical_order(one);
    coast_detail::canonical_order(two);
    EXPECT_TRUE(one.rings[0].nodes == two.rings[0].nodes);
}

} // namespace
} // namespace globemesh
