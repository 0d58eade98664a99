// GeoPackage writer and PNG preview, read back with OGR/GDAL. Oracles: counts from the mesh, the
// plate carree rectangle (360 x 180 square degrees) that a closed mesh's faces must tile exactly,
// part widths, and pixel colours at places known to be face, land or background.
#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include <sqlite3.h>

#include "face_geometry.hpp"
#include "globemesh/error.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/preview.hpp"
#include "globemesh/ugrid.hpp"
#include "io_test_meshes.hpp"
#include "support.hpp"
#include "write_hooks.hpp"

using namespace globemesh;
using namespace globemesh::test;
namespace fs = std::filesystem;

namespace {

struct Dataset {
    explicit Dataset(const fs::path &p, unsigned flags = GDAL_OF_VECTOR) {
        GDALAllRegister();
        ds.reset(GDALDataset::Open(p.c_str(), flags | GDAL_OF_READONLY));
    }
    struct Close {
        void operator()(GDALDataset *d) const { GDALClose(d); }
    };
    std::unique_ptr<GDALDataset, Close> ds;
};

std::vector<std::string> folder_listing(const fs::path &dir) {
    std::vector<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

/// Sum of planar lon/lat areas of all features, and the widest polygon part, degrees.
std::pair<double, double> faces_area_and_widest_part(OGRLayer *layer) {
    double area = 0, widest = 0;
    layer->ResetReading();
    for (auto &f : *layer) {
        const auto *multi = f->GetGeometryRef()->toMultiPolygon();
        for (const auto *part : multi) {
            OGREnvelope env;
            part->getEnvelope(&env);
            widest = std::max(widest, env.MaxX - env.MinX);
            EXPECT_GE(env.MinX, -180.0);
            EXPECT_LE(env.MaxX, 180.0);
            area += part->get_Area();
        }
    }
    return {area, widest};
}

std::array<int, 4> pixel(GDALDataset *ds, double lon, double lat,
                         const std::array<double, 4> &extent) {
    int x = int((lon - extent[0]) / (extent[2] - extent[0]) * ds->GetRasterXSize());
    int y = int((extent[3] - lat) / (extent[3] - extent[1]) * ds->GetRasterYSize());
    std::array<int, 4> c{};
    for (int b = 0; b < std::min(4, ds->GetRasterCount()); ++b) {
        GByte v = 0;
        EXPECT_EQ(ds->GetRasterBand(b + 1)->RasterIO(GF_Read, x, y, 1, 1, &v, 1, 1, GDT_Byte, 0, 0),
                  CE_None);
        c[b] = v;
    }
    return c;
}

/// The file as SQLite itself reads it (not through GDAL): each query's rows, as text.
class Sqlite {
public:
    explicit Sqlite(const fs::path &p) {
        EXPECT_EQ(sqlite3_open_v2(p.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    }
    ~Sqlite() { sqlite3_close(db_); }
    Sqlite(const Sqlite &) = delete;
    Sqlite &operator=(const Sqlite &) = delete;
    std::vector<std::vector<std::string>> rows(const std::string &sql) const {
        std::vector<std::vector<std::string>> out;
        sqlite3_stmt *s = nullptr;
        EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr), SQLITE_OK)
            << sql << ": " << sqlite3_errmsg(db_);
        while (s && sqlite3_step(s) == SQLITE_ROW) {
            out.emplace_back();
            for (int c = 0; c < sqlite3_column_count(s); ++c) {
                const auto *text = sqlite3_column_text(s, c);
                out.back().push_back(text ? reinterpret_cast<const char *>(text) : "");
            }
        }
        sqlite3_finalize(s);
        return out;
    }
    std::string one(const std::string &sql) const {
        const auto r = rows(sql);
        return r.empty() || r[0].empty() ? "" : r[0][0];
    }
    /// The RTree's box of each feature id, read as doubles (the floats it stores, exactly).
    std::map<GIntBig, std::array<double, 4>> boxes(const std::string &rtree) const {
        std::map<GIntBig, std::array<double, 4>> out;
        sqlite3_stmt *s = nullptr;
        EXPECT_EQ(sqlite3_prepare_v2(db_,
                                     ("SELECT id, minx, maxx, miny, maxy FROM " + rtree).c_str(),
                                     -1, &s, nullptr),
                  SQLITE_OK);
        while (s && sqlite3_step(s) == SQLITE_ROW)
            out[sqlite3_column_int64(s, 0)] = {
                sqlite3_column_double(s, 1), sqlite3_column_double(s, 2),
                sqlite3_column_double(s, 3), sqlite3_column_double(s, 4)};
        sqlite3_finalize(s);
        return out;
    }

private:
    sqlite3 *db_ = nullptr;
};

/// Each feature's envelope as OGR reads its geometry back, by fid.
std::map<GIntBig, OGREnvelope> envelopes(OGRLayer *layer) {
    std::map<GIntBig, OGREnvelope> out;
    layer->ResetReading();
    for (auto &f : *layer)
        f->GetGeometryRef()->getEnvelope(&out[f->GetFID()]);
    return out;
}

} // namespace

TEST(Gpkg, layers_hold_one_feature_per_face_and_node_with_their_fields) {
    TempDir dir;
    Mesh m =
        icosphere_with_holes(5); // the faces' features are made in blocks of 4,096 on every core
    m.attributes = {{"coast", "land.gpkg"}};
    write_gpkg(m, dir / "m.gpkg");
    Dataset d(dir / "m.gpkg");
    ASSERT_TRUE(d.ds);
    OGRLayer *faces = d.ds->GetLayerByName("faces");
    OGRLayer *nodes = d.ds->GetLayerByName("nodes");
    OGRLayer *boundary = d.ds->GetLayerByName("boundary");
    OGRLayer *info = d.ds->GetLayerByName("mesh_info");
    ASSERT_TRUE(faces && nodes && boundary && info);
    EXPECT_EQ(faces->GetFeatureCount(), GIntBig(m.faces.size()));
    EXPECT_EQ(nodes->GetFeatureCount(), GIntBig(m.nodes.size()));
    EXPECT_EQ(wkbFlatten(faces->GetGeomType()), wkbMultiPolygon);
    EXPECT_TRUE(faces->GetSpatialRef() && faces->GetSpatialRef()->GetEPSGGeogCS() == 4326);
    for (const char *field : {"quality", "area_km2", "depth", "target_size"})
        EXPECT_GE(faces->GetLayerDefn()->GetFieldIndex(field), 0) << field;
    for (const char *field : {"depth", "target_size"})
        EXPECT_GE(nodes->GetLayerDefn()->GetFieldIndex(field), 0) << field;

    // Face 7: mean depth of its nodes, quality as the sphere module computes it.
    std::unique_ptr<OGRFeature> f7(faces->GetFeature(8));
    ASSERT_TRUE(f7);
    const auto &t = m.faces[7];
    const auto &depth = m.node_field("depth")->values;
    EXPECT_NEAR(f7->GetFieldAsDouble("depth"), (depth[t[0]] + depth[t[1]] + depth[t[2]]) / 3, 1e-9);
    EXPECT_NEAR(f7->GetFieldAsDouble("quality"),
                triangle_quality(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]]), 1e-12);
    // Every face's number, quality and area_km2, the area GeographicLib's PolygonArea of its
    // corners (the writer's own computation, face_area.hpp, agrees to 1e-9 relative).
    GIntBig fid = 0;
    std::size_t parts = 0;
    for (auto &f : *faces) {
        EXPECT_EQ(f->GetFID(), ++fid);
        EXPECT_EQ(f->GetFieldAsInteger("face"), fid - 1);
        const auto &c = m.faces[std::size_t(f->GetFID() - 1)];
        EXPECT_EQ(f->GetFieldAsDouble("quality"),
                  triangle_quality(m.nodes[c[0]], m.nodes[c[1]], m.nodes[c[2]]));
        GeographicLib::PolygonArea poly(GeographicLib::Geodesic::WGS84());
        for (NodeIndex k : c)
            poly.AddPoint(vec_to_lonlat(m.nodes[k]).lat, vec_to_lonlat(m.nodes[k]).lon);
        double perimeter, area_m2;
        poly.Compute(false, true, perimeter, area_m2);
        EXPECT_NEAR(f->GetFieldAsDouble("area_km2"), std::fabs(area_m2) * 1e-6, 1e-7)
            << "face " << f->GetFID() - 1;
        // Its polygon holds each of its corners away from the cuts (the writer refills the
        // features and polygons of a block for later blocks: none keeps another face's). The
        // longitudes are unwrapped from the previous corner's, to rounding.
        const OGRMultiPolygon *multi = f->GetGeometryRef()->toMultiPolygon();
        parts += multi->getNumGeometries();
        for (NodeIndex k : c) {
            const LonLat ll = vec_to_lonlat(m.nodes[k]);
            if (std::fabs(ll.lon) > 179.9 || std::fabs(ll.lat) > 89.9)
                continue;
            bool found = false;
            for (const OGRPolygon *polygon : *multi)
                for (const OGRPoint &point : *polygon->getExteriorRing())
                    found = found ||
                            (std::fabs(point.getX() - ll.lon) < 1e-9 && point.getY() == ll.lat);
            EXPECT_TRUE(found) << "face " << f->GetFID() - 1 << " lacks its corner " << ll.lon
                               << " " << ll.lat;
        }
    }
    // Faces cut at +-180 (two parts) among the others: both kinds follow each other in a slot.
    EXPECT_GT(parts, m.faces.size());
    // Every node: its number, its fields and its point (one feature refilled for each).
    fid = 0;
    for (auto &f : *nodes) {
        EXPECT_EQ(f->GetFID(), ++fid);
        const auto i = std::size_t(fid - 1);
        EXPECT_EQ(f->GetFieldAsInteger("node"), int(i));
        EXPECT_EQ(f->GetFieldAsDouble("depth"), m.node_field("depth")->values[i]);
        EXPECT_EQ(f->GetFieldAsDouble("target_size"), m.node_field("target_size")->values[i]);
        const OGRPoint *point = f->GetGeometryRef()->toPoint();
        EXPECT_EQ(point->getX(), vec_to_lonlat(m.nodes[i]).lon);
        EXPECT_EQ(point->getY(), vec_to_lonlat(m.nodes[i]).lat);
    }
    EXPECT_EQ(std::size_t(fid), m.nodes.size());

    // Boundary runs: every boundary edge once, tags coast and open both present.
    int edges = 0, coast = 0, open = 0;
    for (auto &f : *boundary) {
        edges += f->GetFieldAsInteger("edges");
        std::string tag = f->GetFieldAsString("tag");
        coast += tag == "coast", open += tag == "open";
    }
    EXPECT_EQ(std::size_t(edges), m.boundary.size());
    EXPECT_GT(coast, 0);
    EXPECT_GT(open, 0);
    bool found = false;
    for (auto &f : *info)
        found |= std::string(f->GetFieldAsString("key")) == "coast";
    EXPECT_TRUE(found);
}

TEST(Gpkg, face_areas_from_the_ugrid_writer_are_taken_as_given_and_freed_after_the_faces) {
    TempDir dir;
    const Mesh m = icosphere_with_holes(4);
    std::vector<double> areas;
    UgridOptions u;
    u.face_areas_m2 = &areas;
    write_ugrid(m, dir / "m.nc", u);
    ASSERT_EQ(areas.size(), m.faces.size());
    write_gpkg(m, dir / "own.gpkg"); // computed by the writer
    // Doubled, so that the file shows they were taken as given, not computed again.
    std::vector<double> doubled = areas;
    for (double &a : doubled)
        a *= 2;
    GpkgOptions g;
    g.face_areas_m2 = &doubled;
    write_gpkg(m, dir / "given.gpkg", g);
    EXPECT_TRUE(doubled.empty() && doubled.capacity() == 0);
    // One area too few: computed by the writer, as without.
    std::vector<double> short_by_one(areas.begin(), areas.end() - 1);
    g.face_areas_m2 = &short_by_one;
    write_gpkg(m, dir / "short.gpkg", g);
    Dataset own(dir / "own.gpkg"), given(dir / "given.gpkg"), fallback(dir / "short.gpkg");
    ASSERT_TRUE(own.ds && given.ds && fallback.ds);
    OGRLayer *a = own.ds->GetLayerByName("faces");
    OGRLayer *b = given.ds->GetLayerByName("faces");
    OGRLayer *c = fallback.ds->GetLayerByName("faces");
    ASSERT_TRUE(a && b && c);
    std::size_t n = 0;
    for (auto &fa : *a) {
        std::unique_ptr<OGRFeature> fb(b->GetNextFeature()), fc(c->GetNextFeature());
        ASSERT_TRUE(fb && fc);
        const double km2 = fa->GetFieldAsDouble("area_km2");
        EXPECT_EQ(km2, areas[n] * 1e-6) << "face " << n; // the UGRID file's areas
        EXPECT_EQ(fb->GetFieldAsDouble("area_km2"), 2 * areas[n] * 1e-6) << "face " << n;
        EXPECT_EQ(fc->GetFieldAsDouble("area_km2"), km2) << "face " << n;
        ++n;
    }
    EXPECT_EQ(n, m.faces.size());
}

// The spatial indexes are written in bulk into SQLite's RTree tables (gpkg_rtree.hpp). Oracles:
// SQLite's own rtreecheck() of the tree's structure, OGR's envelope of each feature read back
// (the float box must hold it and be the tightest that does), and brute force over those
// envelopes for window queries, which SQLite answers by walking the tree.
TEST(Gpkg, spatial_indexes_are_rtrees_holding_each_features_tightest_float_box) {
    TempDir dir;
    const Mesh m = icosphere_with_holes(4); // 4,9xx faces: leaves, a level of nodes and the root
    write_gpkg(m, dir / "m.gpkg");
    Dataset d(dir / "m.gpkg");
    ASSERT_TRUE(d.ds);
    const Sqlite db(dir / "m.gpkg");
    for (const std::string table : {"faces", "nodes", "boundary"}) {
        SCOPED_TRACE(table);
        const std::string rtree = "rtree_" + table + "_geom";
        OGRLayer *layer = d.ds->GetLayerByName(table.c_str());
        ASSERT_TRUE(layer);
        EXPECT_EQ(db.one("SELECT rtreecheck('" + rtree + "')"), "ok");
        EXPECT_EQ(db.one("PRAGMA integrity_check"), "ok"); // the pages written without SQLite
        EXPECT_EQ(db.one("SELECT scope FROM gpkg_extensions WHERE table_name = '" + table +
                         "' AND column_name = 'geom' AND extension_name = 'gpkg_rtree_index'"),
                  "write-only");
        EXPECT_EQ(
            db.one("SELECT count(*) FROM sqlite_master WHERE type = 'trigger' AND name LIKE '" +
                   rtree + "_%'"),
            "6");
        const auto boxes = db.boxes(rtree);
        const auto env = envelopes(layer);
        ASSERT_EQ(boxes.size(), env.size());
        if (table == "faces") {
            EXPECT_EQ(env.size(), m.faces.size());
            // More than one leaf below the root: the tree has inner levels to get right.
            EXPECT_GT(std::stoi(db.one("SELECT count(*) FROM " + rtree + "_parent")), 51);
        }
        for (const auto &[fid, e] : env) {
            ASSERT_TRUE(boxes.count(fid)) << fid;
            const auto &b = boxes.at(fid);
            const double bound[4] = {e.MinX, e.MaxX, e.MinY, e.MaxY};
            for (int k = 0; k < 4; ++k) {
                const float f = static_cast<float>(b[std::size_t(k)]);
                const bool low = k % 2 == 0;
                // Holds the envelope, and the next float inwards would not.
                EXPECT_TRUE(low ? b[std::size_t(k)] <= bound[k] : b[std::size_t(k)] >= bound[k])
                    << fid << " side " << k;
                const float inwards = std::nextafter(f, low ? INFINITY : -INFINITY);
                EXPECT_TRUE(low ? double(inwards) > bound[k] : double(inwards) < bound[k])
                    << fid << " side " << k;
            }
        }
        // Windows: every feature whose envelope meets one is found through the tree; any other
        // found meets it within a float's rounding.
        for (const std::array<double, 4> w : {std::array<double, 4>{-10.3, 10.7, -12.1, 9.9},
                                              {150.5, 180, -90, 90},
                                              {-180, -172.2, 55.5, 90},
                                              {100.1, 141.3, -51.7, -19.2}}) {
            std::set<GIntBig> brute, tree;
            for (const auto &[fid, e] : env)
                if (e.MaxX >= w[0] && e.MinX <= w[1] && e.MaxY >= w[2] && e.MinY <= w[3])
                    brute.insert(fid);
            for (const auto &row :
                 db.rows("SELECT id FROM " + rtree + " WHERE maxx >= " + std::to_string(w[0]) +
                         " AND minx <= " + std::to_string(w[1]) + " AND maxy >= " +
                         std::to_string(w[2]) + " AND miny <= " + std::to_string(w[3])))
                tree.insert(std::stoll(row[0]));
            if (table != "boundary") {
                EXPECT_GT(brute.size(), 0u) << w[0];
            }
            for (GIntBig fid : brute)
                EXPECT_TRUE(tree.count(fid))
                    << "window " << w[0] << ": feature " << fid << " missed";
            for (GIntBig fid : tree) {
                if (brute.count(fid))
                    continue;
                const OGREnvelope &e = env.at(fid);
                EXPECT_TRUE(e.MaxX >= w[0] - 1e-4 && e.MinX <= w[1] + 1e-4 &&
                            e.MaxY >= w[2] - 1e-4 && e.MinY <= w[3] + 1e-4)
                    << "window " << w[0] << ": feature " << fid << " found far from it";
            }
        }
    }
}

// The triggers written with the index are GDAL's: a feature deleted or added later through
// GDAL (as QGIS edits a layer) leaves a consistent index that holds the new feature.
TEST(Gpkg, spatial_index_follows_features_edited_later_through_gdal) {
    TempDir dir;
    write_gpkg(icosphere(3), dir / "m.gpkg");
    GIntBig added = 0;
    {
        Dataset d(dir / "m.gpkg", GDAL_OF_VECTOR | GDAL_OF_UPDATE);
        ASSERT_TRUE(d.ds);
        OGRLayer *faces = d.ds->GetLayerByName("faces");
        ASSERT_TRUE(faces);
        EXPECT_EQ(faces->DeleteFeature(5), OGRERR_NONE);
        OGRFeature f(faces->GetLayerDefn());
        OGRPolygon poly;
        OGRLinearRing ring;
        for (const auto &[x, y] : {std::pair{10.0, 80.0}, {11.0, 80.0}, {11.0, 81.0}, {10.0, 80.0}})
            ring.addPoint(x, y);
        poly.addRing(&ring);
        OGRMultiPolygon multi;
        multi.addGeometry(&poly);
        f.SetGeometry(&multi);
        ASSERT_EQ(faces->CreateFeature(&f), OGRERR_NONE);
        added = f.GetFID();
    }
    const Sqlite db(dir / "m.gpkg");
    EXPECT_EQ(db.one("SELECT rtreecheck('rtree_faces_geom')"), "ok");
    EXPECT_EQ(db.one("SELECT count(*) FROM rtree_faces_geom"),
              db.one("SELECT count(*) FROM faces"));
    EXPECT_EQ(db.one("SELECT count(*) FROM rtree_faces_geom WHERE id = 5"), "0");
    const auto box = db.rows("SELECT minx, maxx, miny, maxy FROM rtree_faces_geom WHERE id = " +
                             std::to_string(added));
    ASSERT_EQ(box.size(), 1u);
    EXPECT_EQ(box[0], (std::vector<std::string>{"10.0", "11.0", "80.0", "81.0"}));
}

// The faces' and nodes' rows are written as SQLite pages, not through GDAL: the layer's count
// and extent are still those GDAL keeps (gpkg_ogr_contents, gpkg_contents: the union of the
// features' envelopes as OGR reads them, written by GDAL with 16 significant digits and read
// here as SQLite's text, 15), and a row added later still counts (GDAL's trigger is in place).
TEST(Gpkg, bulk_layers_keep_gdal_counts_extents_and_count_triggers) {
    TempDir dir;
    const Mesh m = icosphere_with_holes(3);
    write_gpkg(m, dir / "m.gpkg");
    {
        Dataset d(dir / "m.gpkg");
        ASSERT_TRUE(d.ds);
        const Sqlite db(dir / "m.gpkg");
        for (const char *name : {"faces", "nodes"}) {
            SCOPED_TRACE(name);
            OGRLayer *layer = d.ds->GetLayerByName(name);
            ASSERT_TRUE(layer);
            OGREnvelope all;
            for (const auto &[fid, e] : envelopes(layer))
                all.Merge(e);
            const auto row = db.rows(std::string("SELECT min_x, max_x, min_y, max_y FROM "
                                                 "gpkg_contents WHERE table_name = '") +
                                     name + "'");
            ASSERT_EQ(row.size(), 1u);
            const double expected[] = {all.MinX, all.MaxX, all.MinY, all.MaxY};
            for (int i = 0; i < 4; ++i)
                EXPECT_NEAR(std::stod(row[0][std::size_t(i)]), expected[i],
                            1e-14 * std::max(1.0, std::fabs(expected[i])))
                    << i;
            EXPECT_EQ(
                db.one(std::string("SELECT feature_count FROM gpkg_ogr_contents WHERE "
                                   "table_name = '") +
                       name + "'"),
                std::to_string(name == std::string("faces") ? m.faces.size() : m.nodes.size()));
        }
    }
    sqlite3 *db = nullptr;
    ASSERT_EQ(sqlite3_open_v2((dir / "m.gpkg").c_str(), &db, SQLITE_OPEN_READWRITE, nullptr),
              SQLITE_OK);
    // The index's triggers name GDAL's SQL functions: stand-ins, not called for a row with no
    // geometry.
    for (const char *f : {"ST_IsEmpty", "ST_MinX", "ST_MaxX", "ST_MinY", "ST_MaxY"})
        sqlite3_create_function(
            db, f, 1, SQLITE_UTF8, nullptr,
            [](sqlite3_context *c, int, sqlite3_value **) { sqlite3_result_null(c); }, nullptr,
            nullptr);
    EXPECT_EQ(sqlite3_exec(db, "INSERT INTO nodes (node) VALUES (-1)", nullptr, nullptr, nullptr),
              SQLITE_OK)
        << sqlite3_errmsg(db);
    sqlite3_close(db);
    EXPECT_EQ(Sqlite(dir / "m.gpkg")
                  .one("SELECT feature_count FROM gpkg_ogr_contents WHERE table_name = 'nodes'"),
              std::to_string(m.nodes.size() + 1));
}

// GDAL's own GeoPackage validator (validate_gpkg.py, with python3-gdal) finds nothing to say.
TEST(Gpkg, gdal_validator_accepts_the_file) {
    std::string out;
    if (run_command("/usr/bin/python3 -c 'import osgeo_utils.samples.validate_gpkg'", out) != 0) {
        std::cout << "[  NOTE    ] validate_gpkg SKIPPED: python3-gdal's osgeo_utils absent\n";
        GTEST_SKIP() << "python3-gdal absent";
    }
    TempDir dir;
    write_gpkg(icosphere_with_holes(3), dir / "m.gpkg");
    EXPECT_EQ(run_command("/usr/bin/python3 -m osgeo_utils.samples.validate_gpkg " +
                              (dir / "m.gpkg").string(),
                          out),
              0)
        << out;
    EXPECT_EQ(out, "");
}

// `globemesh info ocean.gpkg`: netCDF-C says "Unknown file format"; the reader names what
// the file is instead.
TEST(Gpkg, reading_a_geopackage_as_ugrid_says_it_is_one) {
    TempDir dir;
    write_gpkg(icosphere(1), dir / "m.gpkg");
    const std::string m = test::thrown_message<IoError>([&] { read_ugrid(dir / "m.gpkg"); });
    EXPECT_NE(m.find("is a GeoPackage (SQLite), not NetCDF"), std::string::npos) << m;
}

TEST(Gpkg, closed_mesh_faces_tile_the_lonlat_rectangle_with_no_part_wider_than_180) {
    TempDir dir;
    write_gpkg(icosphere(3), dir / "ico.gpkg");
    Dataset d(dir / "ico.gpkg");
    ASSERT_TRUE(d.ds);
    auto [area, widest] = faces_area_and_widest_part(d.ds->GetLayerByName("faces"));
    EXPECT_NEAR(area, 360.0 * 180.0, 1e-6); // no gap and no overlap, poles and seam included
    EXPECT_LT(widest, 180.0);
}

// A face with a side along the antimeridian, its two corners within rounding of -180 (a
// region's east edge at 180, as the nodes come out: -179.99999999999997 and -180), and its third
// just west of 180, only touches it: one polygon, without the sliver along -180 its clip left
// beside it (GSHHG low 170,-50,180,-30 at 50 km: 12 faces written as two parts, the second of
// area 1.4e-14 square degrees; globally at 100 km 73). A face across 180 still gives two parts.
TEST(Gpkg, a_face_touching_the_antimeridian_is_one_polygon) {
    const double deg = std::acos(-1.0) / 180;
    auto near_180 = [&](double lat, double y) {
        return normalized(Vec3{-std::cos(lat * deg), y, std::sin(lat * deg)});
    };
    int slivers = 0;
    for (const double y0 : {-0.0, -1e-15, -3e-15, 1e-15})
        for (const double y1 : {-0.0, -2e-15, 2e-15}) {
            const Vec3 a = near_180(-37.73, y0), b = near_180(-37.27, y1),
                       c = lonlat_to_vec(179.64, -37.56);
            const auto parts = io::face_polygons(a, c, b);
            slivers += parts.size() != 1;
            for (const auto &p : parts)
                EXPECT_GT(std::fabs(io::ring_area(p)), 0.01);
        }
    EXPECT_EQ(slivers, 0);
    const auto across = io::face_polygons(lonlat_to_vec(179.5, -37.7), lonlat_to_vec(-179.6, -37.6),
                                          lonlat_to_vec(179.7, -37.2));
    ASSERT_EQ(across.size(), 2u);
    for (const auto &p : across)
        EXPECT_GT(std::fabs(io::ring_area(p)), 0.001);
}

// A line along the antimeridian (a region's open edge at 180) is drawn once, at 180: each of its
// segments came out at -180 too (GSHHG low 170,-50,180,-30 at 10 km: 805 segments for 583
// open edges). A line across 180 is cut there into two.
TEST(Gpkg, a_line_along_the_antimeridian_is_drawn_once) {
    std::vector<Vec3> along;
    for (double lat = -10; lat <= 10; lat += 5)
        along.push_back(lonlat_to_vec(180, lat));
    const auto parts = io::polyline_parts(along);
    std::size_t segments = 0;
    for (const auto &p : parts) {
        segments += p.size() - 1;
        for (const auto &q : p)
            EXPECT_EQ(std::fabs(q[0]), 180.0);
    }
    EXPECT_EQ(segments, along.size() - 1);
    const auto across = io::polyline_parts({lonlat_to_vec(179, 0), lonlat_to_vec(-179, 1)});
    EXPECT_EQ(across.size(), 2u);
}

// The writer's shortcut for the common face (face_geometry.hpp, simple_face_ring) gives what
// face_polygons gives, value for value, on faces anywhere: across +-180, at and round the poles,
// with corners on +-180, tiny and degenerate.
TEST(Gpkg, simple_face_ring_is_face_polygons_one_ring_wherever_it_applies) {
    std::mt19937_64 random(11);
    std::uniform_real_distribution<double> unit(-1, 1);
    auto jitter = [&](const Vec3 &c, double size) {
        const Vec3 v{c.x + size * unit(random), c.y + size * unit(random),
                     c.z + size * unit(random)};
        const double n = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
        return Vec3{v.x / n, v.y / n, v.z / n};
    };
    const std::vector<Vec3> centres = {lonlat_to_vec(180, 0),  lonlat_to_vec(-180, 60),
                                       lonlat_to_vec(0, 89.9), lonlat_to_vec(40, -89.99),
                                       lonlat_to_vec(100, 10), lonlat_to_vec(179.99, -30)};
    int simple = 0, general = 0;
    for (int k = 0; k < 60000; ++k) {
        const Vec3 &c = centres[std::size_t(k) % centres.size()];
        const double size = std::pow(10.0, -6 + 6 * (unit(random) + 1) / 2); // 1e-6 .. 1
        Vec3 v[3] = {jitter(c, size), jitter(c, size), jitter(c, size)};
        if (k % 50 == 0)
            v[k % 3] = {0, 0, k % 100 ? 1.0 : -1.0}; // a corner at a pole
        if (k % 70 == 0)
            v[1] = lonlat_to_vec(180, 10 * unit(random)); // a corner on the antimeridian
        if (k % 110 == 0)
            v[2] = lonlat_to_vec(-180, 10 * unit(random)); // and a side along it
        if (k % 90 == 0)
            v[2] = v[0]; // degenerate
        const LonLat ll[3] = {vec_to_lonlat(v[0]), vec_to_lonlat(v[1]), vec_to_lonlat(v[2])};
        std::array<io::LonLatPoint, 3> ring;
        const auto parts = io::face_polygons(v[0], v[1], v[2]);
        if (!io::simple_face_ring(v, ll, ring)) {
            ++general;
            continue;
        }
        ++simple;
        ASSERT_EQ(parts.size(), 1u) << k;
        ASSERT_EQ(parts[0].size(), 3u) << k;
        for (std::size_t i = 0; i < 3; ++i)
            ASSERT_TRUE(parts[0][i] == ring[i]) << k << " corner " << i;
    }
    EXPECT_GT(simple, 10000); // both ways are taken often
    EXPECT_GT(general, 10000);
}

// A face round a pole whose corners have different latitudes (an Arctic mesh's polar face: NE
// 10m, 20-80 km, corners at 89.63, 89.63 and 89.41 N) covers, in lon/lat, what lies between its
// three straight sides and the pole line, no more: the sum of the sides' trapezoids up to the
// pole. Its closing side came back at the last corner's latitude, adding a triangle under the
// side to the first corner that belongs to the neighbouring face.
TEST(Gpkg, a_face_round_a_pole_covers_only_up_to_its_sides) {
    struct Case {
        std::array<LonLat, 3> corners; // counter-clockwise seen from outside the sphere
        double pole;
    };
    const Case cases[] = {{{{{90, 89.6349}, {-90, 89.6349}, {0, 89.407}}}, 90},
                          {{{{90.0001, 89.0921}, {-91.5451, 89.0721}, {1.4437, 88.5221}}}, 90},
                          {{{{10, -88.2}, {-110, -89.1}, {130, -88.9}}}, -90}};
    for (const Case &c : cases) {
        const auto parts = io::face_polygons(lonlat_to_vec(c.corners[0].lon, c.corners[0].lat),
                                             lonlat_to_vec(c.corners[1].lon, c.corners[1].lat),
                                             lonlat_to_vec(c.corners[2].lon, c.corners[2].lat));
        double area = 0, want = 0;
        for (const auto &part : parts)
            area += std::fabs(io::ring_area(part));
        for (int i = 0; i < 3; ++i) { // each side's trapezoid to the pole, the longitude step
            const LonLat &p = c.corners[i], &q = c.corners[(i + 1) % 3]; // taken the short way
            const double step = std::remainder(q.lon - p.lon, 360.0);
            want += std::fabs(step) * std::fabs(c.pole - (p.lat + q.lat) / 2);
        }
        EXPECT_NEAR(area, want, 1e-9 * want) << c.corners[2].lat;
    }
}

TEST(Gpkg, pole_corner_is_written_as_two_points_at_the_neighbouring_longitudes) {
    TempDir dir;
    Mesh m = icosphere(0); // node 0 is the north pole; face 0 is (pole, u, un)
    write_gpkg(m, dir / "ico.gpkg");
    Dataset d(dir / "ico.gpkg");
    std::unique_ptr<OGRFeature> f(d.ds->GetLayerByName("faces")->GetFeature(1));
    const auto *ring = f->GetGeometryRef()->toMultiPolygon()->getGeometryRef(0)->getExteriorRing();
    std::vector<double> pole_lons;
    for (int i = 0; i + 1 < ring->getNumPoints(); ++i)
        if (ring->getY(i) == 90.0)
            pole_lons.push_back(ring->getX(i));
    ASSERT_EQ(pole_lons.size(), 2u);
    std::sort(pole_lons.begin(), pole_lons.end());
    EXPECT_NEAR(pole_lons[0], -180.0, 1e-9); // the corners of face 0 are at lon -180 and -108
    EXPECT_NEAR(pole_lons[1], -108.0, 1e-9);
}

TEST(Gpkg, faces_crossing_the_antimeridian_are_cut_into_two_parts) {
    TempDir dir;
    Mesh m = icosphere_cap(4, 180, 0, 30);
    write_gpkg(m, dir / "pacific.gpkg");
    Dataset d(dir / "pacific.gpkg");
    OGRLayer *faces = d.ds->GetLayerByName("faces");
    EXPECT_EQ(faces->GetFeatureCount(), GIntBig(m.faces.size()));
    auto [area, widest] = faces_area_and_widest_part(faces);
    EXPECT_LT(widest, 30.0);
    int cut = 0;
    faces->ResetReading();
    for (auto &f : *faces)
        cut += f->GetGeometryRef()->toMultiPolygon()->getNumGeometries() == 2;
    EXPECT_GT(cut, 5);
    // Boundary lines are cut too: no segment jumps across the map.
    for (auto &f : *d.ds->GetLayerByName("boundary")) {
        OGREnvelope env;
        for (const auto *line : f->GetGeometryRef()->toMultiLineString()) {
            line->getEnvelope(&env);
            EXPECT_LT(env.MaxX - env.MinX, 90.0);
        }
    }
}

TEST(Gpkg, face_round_a_pole_is_cut_into_parts_no_wider_than_180) {
    TempDir dir;
    Mesh m = icosphere_without_pole_nodes(3);
    write_gpkg(m, dir / "nopole.gpkg");
    Dataset d(dir / "nopole.gpkg");
    ASSERT_TRUE(d.ds);
    OGRLayer *faces = d.ds->GetLayerByName("faces");
    EXPECT_EQ(faces->GetFeatureCount(), GIntBig(m.faces.size())); // still one feature per face
    auto [area, widest] = faces_area_and_widest_part(faces);
    EXPECT_NEAR(area, 360.0 * 180.0, 1e-6); // the polar faces still reach the pole lines
    EXPECT_LE(widest, 180.0);
    // With no pole nodes, only the two faces round the poles reach lat +-90: each is closed along
    // the pole line over every longitude, in parts (uncut, it is one part 360 degrees wide).
    int round_pole = 0;
    faces->ResetReading();
    for (auto &f : *faces) {
        OGREnvelope env;
        f->GetGeometryRef()->getEnvelope(&env);
        if (env.MaxY != 90.0 && env.MinY != -90.0)
            continue;
        ++round_pole;
        EXPECT_EQ(env.MinX, -180.0);
        EXPECT_EQ(env.MaxX, 180.0);
        EXPECT_GE(f->GetGeometryRef()->toMultiPolygon()->getNumGeometries(), 2);
    }
    EXPECT_EQ(round_pole, 2);
}

TEST(Gpkg, boundary_loops_wider_than_180_are_split_into_joined_parts) {
    TempDir dir;
    // Holes: a band round the globe (two loops crossing +-180) and a wide hole lon -120..120 at
    // lat 30..50 (one loop 240 degrees wide, like the Afro-Eurasian coast), round-the-pole faces.
    Mesh full = icosphere_without_pole_nodes(3);
    add_fields(full);
    Mesh m = keep_faces(
        full,
        [&](std::size_t f) {
            const auto &t = full.faces[f];
            LonLat c =
                vec_to_lonlat(normalized(full.nodes[t[0]] + full.nodes[t[1]] + full.nodes[t[2]]));
            return !(c.lat > -20 && c.lat < -10) &&
                   !(c.lat > 30 && c.lat < 50 && std::fabs(c.lon) < 120);
        },
        [](const Vec3 &, const Vec3 &) { return EdgeTag::coast; });
    write_gpkg(m, dir / "holes.gpkg");
    Dataset d(dir / "holes.gpkg");
    ASSERT_TRUE(d.ds);
    OGRLayer *faces = d.ds->GetLayerByName("faces");
    EXPECT_EQ(faces->GetFeatureCount(), GIntBig(m.faces.size()));
    EXPECT_LE(faces_area_and_widest_part(faces).second, 180.0);
    OGRLayer *boundary = d.ds->GetLayerByName("boundary");
    EXPECT_EQ(boundary->GetFeatureCount(), 3); // one feature per loop (all coast), as before
    int edges = 0, split = 0;
    double widest_feature = 0;
    boundary->ResetReading();
    for (auto &f : *boundary) {
        edges += f->GetFieldAsInteger("edges");
        OGREnvelope all;
        f->GetGeometryRef()->getEnvelope(&all);
        widest_feature = std::max(widest_feature, all.MaxX - all.MinX);
        const auto *multi = f->GetGeometryRef()->toMultiLineString();
        split += multi->getNumGeometries() > 1;
        const OGRLineString *previous = nullptr;
        for (const auto *line : multi) {
            OGREnvelope env;
            line->getEnvelope(&env);
            EXPECT_LE(env.MaxX - env.MinX, 180.0);
            if (previous) { // a loop's parts chain: each starts where the last ended, or across
                            // +-180
                OGRPoint end, start;
                previous->EndPoint(&end);
                line->StartPoint(&start);
                const double jump = std::fabs(start.getX() - end.getX());
                EXPECT_NEAR(start.getY(), end.getY(), 1e-9);
                EXPECT_TRUE(jump < 1e-9 || std::fabs(jump - 360.0) < 1e-9)
                    << end.getX() << " -> " << start.getX();
            }
            previous = line;
        }
    }
    EXPECT_EQ(std::size_t(edges), m.boundary.size()); // every boundary edge once
    EXPECT_GT(widest_feature, 300.0);                 // the loops really were wide ...
    EXPECT_EQ(split, 3);                              // ... and every one was split
}

TEST(Gpkg, default_qgis_style_colours_faces_by_quality) {
    TempDir dir;
    write_gpkg(icosphere(1), dir / "s.gpkg");
    Dataset d(dir / "s.gpkg");
    OGRLayer *styles = d.ds->GetLayerByName("layer_styles");
    ASSERT_TRUE(styles);
    for (const char *field :
         {"f_table_catalog", "f_table_schema", "f_table_name", "f_geometry_column", "styleName",
          "styleQML", "styleSLD", "useAsDefault", "description", "owner", "ui", "update_time"})
        EXPECT_GE(styles->GetLayerDefn()->GetFieldIndex(field), 0) << field;
    ASSERT_EQ(styles->GetFeatureCount(), 1);
    std::unique_ptr<OGRFeature> s(styles->GetNextFeature());
    EXPECT_STREQ(s->GetFieldAsString("f_table_name"), "faces");
    EXPECT_STREQ(s->GetFieldAsString("f_geometry_column"),
                 d.ds->GetLayerByName("faces")->GetGeometryColumn());
    EXPECT_EQ(s->GetFieldAsInteger("useAsDefault"), 1);
    std::string qml = s->GetFieldAsString("styleQML");
    EXPECT_NE(qml.find("type=\"graduatedSymbol\" attr=\"quality\""), std::string::npos);
}

TEST(Gpkg, existing_output_refused_and_failures_leave_no_file) {
    TempDir dir;
    std::ofstream(dir / "o.gpkg") << "keep";
    EXPECT_THROW(write_gpkg(icosphere(1), dir / "o.gpkg"), IoError);
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"o.gpkg"});
    fs::remove(dir / "o.gpkg");
    EXPECT_THROW(write_gpkg(icosphere(1), dir / "missing/o.gpkg"), IoError);
    {
        const detail::PartialWriteHook hook([&] { throw Cancelled(); });
        EXPECT_THROW(write_gpkg(icosphere(2), dir / "o.gpkg"), Cancelled);
        EXPECT_TRUE(folder_listing(dir.path()).empty());
    }
    const detail::PartialWriteHook hook([&] { throw std::runtime_error("simulated failure"); });
    EXPECT_THROW(write_gpkg(icosphere(2), dir / "o.gpkg"), std::runtime_error);
    EXPECT_TRUE(folder_listing(dir.path()).empty());
}

// Both writers report their progress under their stage, from 0 up to 1, and stop when the
// callback says so: Cancelled (also from inside GDAL's rasterizer and the GeoPackage's spatial
// indexes), no file left.
TEST(Gpkg, gpkg_and_preview_report_progress_and_stop_when_asked) {
    TempDir dir;
    const Mesh m = icosphere(5); // 20,480 faces: a few reports
    struct Writer {
        const char *stage;
        std::function<void(const Progress &)> write;
    };
    const std::vector<Writer> writers = {{"write_gpkg",
                                          [&](const Progress &p) {
                                              GpkgOptions o;
                                              o.progress = p;
                                              write_gpkg(m, dir / "o.gpkg", o);
                                          }},
                                         {"write_preview", [&](const Progress &p) {
                                              PreviewOptions o;
                                              o.progress = p;
                                              write_preview_png(m, dir / "o.png", o);
                                          }}};
    for (const Writer &w : writers) {
        SCOPED_TRACE(w.stage);
        std::vector<double> seen;
        w.write([&](double f, std::string_view stage) {
            EXPECT_EQ(stage, w.stage);
            seen.push_back(f);
            return true;
        });
        ASSERT_GE(seen.size(), 4u);
        EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
        EXPECT_EQ(seen.back(), 1.0);
        // The GeoPackage's last part, its spatial indexes, reports as it goes too: the stop past
        // 0.8 below comes inside them, and leaves no file either.
        if (std::string(w.stage) == "write_gpkg") {
            EXPECT_GE(
                std::count_if(seen.begin(), seen.end(), [](double f) { return f > 0.8 && f < 1; }),
                8);
        }
        for (const auto &e : fs::directory_iterator(dir.path()))
            fs::remove(e.path());
        // Stop at the first report, and at the first past 0.8 (the preview: inside GDAL's
        // rasterizer, whose progress the writer passes on).
        for (const double stop_at : {0.0, 0.8}) {
            EXPECT_THROW(w.write([&](double f, std::string_view) { return f < stop_at; }),
                         Cancelled)
                << stop_at;
            EXPECT_TRUE(folder_listing(dir.path()).empty()) << stop_at;
        }
    }
}

TEST(Preview, draws_faces_over_land_without_smearing_across_the_map) {
    TempDir dir;
    Mesh m = icosphere_cap(4, 180, 0, 30);
    PreviewOptions o;
    o.land = fixture("coast/ne_110m_land.gpkg").string();
    o.width_px = 720;
    o.extent_deg = std::array<double, 4>{-180, -90, 180, 90};
    write_preview_png(m, dir / "globe.png", o);
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"globe.png"}); // no .aux.xml
    Dataset d(dir / "globe.png", GDAL_OF_RASTER);
    ASSERT_TRUE(d.ds);
    EXPECT_STREQ(d.ds->GetDriver()->GetDescription(), "PNG");
    EXPECT_EQ(d.ds->GetRasterXSize(), 720);
    EXPECT_EQ(d.ds->GetRasterYSize(), 360);
    const auto extent = *o.extent_deg;
    const std::array<int, 4> background = {236, 242, 248, 255}, land = {205, 195, 170, 255};
    EXPECT_EQ(pixel(d.ds.get(), 20, 5, extent), land);          // central Africa
    EXPECT_EQ(pixel(d.ds.get(), -30, -40, extent), background); // South Atlantic, no mesh
    EXPECT_EQ(pixel(d.ds.get(), 0, 1, extent), background);     // a smeared face would cover this
    // Face centres (not edges, where outlines are drawn) east and west of the antimeridian.
    LonLat east{0, 0}, west{0, 0};
    for (const auto &t : m.faces) {
        LonLat c = vec_to_lonlat(normalized(m.nodes[t[0]] + m.nodes[t[1]] + m.nodes[t[2]]));
        if (c.lon > 170 && std::fabs(c.lat) < 10)
            east = c;
        if (c.lon < -170 && std::fabs(c.lat) < 10)
            west = c;
    }
    auto at_cap_east = pixel(d.ds.get(), east.lon, east.lat, extent),
         at_cap_west = pixel(d.ds.get(), west.lon, west.lat, extent);
    EXPECT_NE(at_cap_east, background);
    EXPECT_NE(at_cap_west, background);
    EXPECT_GT(at_cap_east[1], at_cap_east[0]); // quality ~0.9: green over red
}

TEST(Preview, edges_are_drawn_across_180_without_a_line_along_the_cut) {
    // Faces about 3.8 degrees on a picture of 20 pixels a degree (W > E: across 180): their
    // edges are drawn, dark grey, but the cut of the faces across 180 is no edge of the mesh, so
    // the columns at 180 are dark only where edges cross them. Drawn, the cut would darken the
    // columns along the whole cap (about half of the picture's height).
    TempDir dir;
    const Mesh m = icosphere_cap(4, 180, 0, 30);
    PreviewOptions o;
    o.width_px = 400;
    o.extent_deg = std::array<double, 4>{170, -10, -170, 10};
    write_preview_png(m, dir / "seam.png", o);
    Dataset d(dir / "seam.png", GDAL_OF_RASTER);
    ASSERT_TRUE(d.ds);
    const int nx = d.ds->GetRasterXSize(), ny = d.ds->GetRasterYSize();
    ASSERT_EQ(nx, 400);
    ASSERT_EQ(ny, 400);
    std::vector<std::uint8_t> rgb(3 * std::size_t(nx) * std::size_t(ny));
    int bands[3] = {1, 2, 3};
    ASSERT_EQ(d.ds->RasterIO(GF_Read, 0, 0, nx, ny, rgb.data(), nx, ny, GDT_Byte, 3, bands, 3,
                             3 * nx, 1, nullptr),
              CE_None);
    auto dark = [&](int x, int y) {
        const std::size_t i = 3 * (std::size_t(y) * std::size_t(nx) + std::size_t(x));
        return rgb[i] == 40 && rgb[i + 1] == 40 && rgb[i + 2] == 40;
    };
    std::size_t all = 0;
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
            all += dark(x, y);
    EXPECT_GT(double(all) / double(nx * ny), 0.02); // the edges are drawn
    for (int x = 198; x <= 201; ++x) {              // lon 180 is between columns 199 and 200
        int column = 0;
        for (int y = 0; y < ny; ++y)
            column += dark(x, y);
        EXPECT_LT(column, ny / 5) << "column " << x;
    }
}

TEST(Preview, faces_smaller_than_a_pixel_leave_no_pixel_of_a_closed_sphere_unpainted) {
    // 327,680 faces, at 200 pixels about a quarter of a pixel wide: the writer skips those whose
    // box holds no pixel centre (they burn nothing); at 1,600 pixels about two pixels wide, and
    // burnt in batches of 262,144 as they are made. A face skipped wrongly, or a batch left out,
    // would leave pixels the background's.
    const Mesh m = icosphere(7);
    for (const int width : {200, 1600}) {
        TempDir dir;
        PreviewOptions o;
        o.width_px = width;
        o.extent_deg = std::array<double, 4>{-180, -90, 180, 90};
        write_preview_png(m, dir / "sphere.png", o);
        Dataset d(dir / "sphere.png", GDAL_OF_RASTER);
        ASSERT_TRUE(d.ds);
        const int nx = d.ds->GetRasterXSize(), ny = d.ds->GetRasterYSize();
        ASSERT_EQ(nx, width);
        std::vector<std::uint8_t> rgb(3 * std::size_t(nx) * std::size_t(ny));
        int bands[3] = {1, 2, 3};
        ASSERT_EQ(d.ds->RasterIO(GF_Read, 0, 0, nx, ny, rgb.data(), nx, ny, GDT_Byte, 3, bands, 3,
                                 3 * nx, 1, nullptr),
                  CE_None);
        std::size_t background = 0;
        for (std::size_t i = 0; i < rgb.size(); i += 3)
            background += rgb[i] == 236 && rgb[i + 1] == 242 && rgb[i + 2] == 248;
        EXPECT_EQ(background, 0u) << width << " pixels";
    }
}

TEST(Preview, default_extent_of_a_pacific_mesh_is_continuous_across_180_and_colours_by_depth) {
    TempDir dir;
    Mesh m = icosphere_cap(4, 180, 0, 30);
    PreviewOptions o;
    o.colour_by = "depth";
    o.width_px = 400;
    write_preview_png(m, dir / "pac.png", o);
    Dataset d(dir / "pac.png", GDAL_OF_RASTER);
    ASSERT_TRUE(d.ds);
    // The picture spans about 60 degrees round lon 180 (not the whole globe): centre is mesh.
    EXPECT_GT(d.ds->GetRasterYSize(), 300);
    EXPECT_LT(d.ds->GetRasterYSize(), 500);
    // Most of the picture is faces in blue depth colours: the cap is drawn in one piece.
    const int w = d.ds->GetRasterXSize(), h = d.ds->GetRasterYSize();
    std::vector<GByte> r(std::size_t(w) * h), b(std::size_t(w) * h);
    ASSERT_EQ(d.ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, w, h, r.data(), w, h, GDT_Byte, 0, 0),
              CE_None);
    ASSERT_EQ(d.ds->GetRasterBand(3)->RasterIO(GF_Read, 0, 0, w, h, b.data(), w, h, GDT_Byte, 0, 0),
              CE_None);
    std::size_t blue = 0;
    for (std::size_t i = 0; i < r.size(); ++i)
        blue += b[i] > r[i] + 50;
    EXPECT_GT(double(blue) / double(r.size()), 0.45);
    EXPECT_THROW(write_preview_png(m, dir / "pac.png", o), IoError); // exists, no overwrite
    o.overwrite = true;
    {
        const detail::PartialWriteHook hook([] { throw Cancelled(); });
        EXPECT_THROW(write_preview_png(m, dir / "pac.png", o), Cancelled);
        EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"pac.png"});
    }
    o.colour_by = "salinity";
    EXPECT_THROW(write_preview_png(m, dir / "x.png", o), UsageError);
}
