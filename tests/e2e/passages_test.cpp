// --passages: global meshes with the default list of critical passages keep each open with at
// least --passage-cells triangles across, counted by an independent reader (python: netCDF4 for
// the mesh, OGR for the lines), and the errors of the options.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "globemesh/passages.hpp"
#include "globemesh/sizefield.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::regex_all;
using globemesh::test::regex_search;
using globemesh::test::run_command;
using globemesh::test::TempDir;

namespace {

const std::string exe = GLOBEMESH_EXE;
const std::string land50 = fixture("coast/ne_50m_land.gpkg").string();
const std::string passages = fixture("passages/passages.geojson").string();

std::string quote(const std::string &s) {
    return "'" + s + "'";
}

/// Runs the executable with `args`; stdout and stderr together in `out`.
int run_exe(const std::string &args, std::string &out) {
    return run_command(quote(exe) + " " + args + " 2>&1", out);
}

// Samples each passage line every 20 m along its great-circle arcs and counts the mesh's faces
// that hold a sample (a face the line only grazes at a corner may be missed: a lower bound).
const char *count_script = R"PY(
import sys, json, numpy as np, netCDF4
from osgeo import ogr
ds = netCDF4.Dataset(sys.argv[1])
lon, lat = np.radians(ds["mesh_node_lon"][:]), np.radians(ds["mesh_node_lat"][:])
xyz = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=1)
fn = np.asarray(ds["mesh_face_nodes"][:], dtype=np.int64) - int(ds["mesh_face_nodes"].start_index)
def unit(p):
    lo, la = np.radians(p[0]), np.radians(p[1])
    return np.array([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)])
src = ogr.Open(sys.argv[2])
for f in src.GetLayer(0):
    g = f.GetGeometryRef()
    pts = [unit(g.GetPoint_2D(i)) for i in range(g.GetPointCount())]
    samples = []
    for a, b in zip(pts, pts[1:]):
        w = np.arccos(np.clip(a @ b, -1, 1)); n = max(100, int(w * 6371.0 / 0.02))
        t = np.linspace(0, 1, n + 1)[:, None]
        samples.append((np.sin((1 - t) * w) * a + np.sin(t * w) * b) / np.sin(w))
    s = np.concatenate(samples)
    centre = s.mean(axis=0); centre /= np.linalg.norm(centre)
    reach = np.arccos(np.clip(s @ centre, -1, 1)).max() + np.radians(3)
    near = np.where((np.arccos(np.clip(xyz[fn] @ centre, -1, 1)) < reach).any(axis=1))[0]
    crossed = 0
    for k in near:
        a, b, c = xyz[fn[k]]
        d = np.stack([np.cross(a, b) @ s.T, np.cross(b, c) @ s.T, np.cross(c, a) @ s.T])
        inside = ((d >= 0).all(axis=0) | (d <= 0).all(axis=0)) & (s @ (a + b + c) > 0)
        crossed += bool(inside.any())
    print(f"{f.GetField('name')}={crossed}")
)PY";

/// Each passage of `lines` with the faces of `mesh` it crosses, counted by count_script.
std::map<std::string, int> cells_across(const fs::path &mesh, const std::string &lines,
                                        const fs::path &dir) {
    const fs::path script = dir / "count.py";
    std::ofstream(script) << count_script;
    std::string out;
    EXPECT_EQ(run_command("/usr/bin/python3 " + quote(script.string()) + " " +
                              quote(mesh.string()) + " " + quote(lines) + " 2>&1",
                          out),
              0)
        << out;
    std::map<std::string, int> cells;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
        if (const auto eq = line.find('='); eq != std::string::npos)
            cells[line.substr(0, eq)] = std::stoi(line.substr(eq + 1));
    return cells;
}

/// Meshes `coast` globally at 100 km with --passages default and checks every passage of the
/// default list: at least 2 faces across by the independent count, no more than the report
/// says, mesh-verify VALID with no face below quality 0.3 and, by its count, at least
/// `pct_above_0_8` per cent of the faces above 0.8.
void expect_passages_open(const std::string &coast, double pct_above_0_8 = 0) {
    TempDir dir;
    const fs::path mesh = dir.path() / "ocean.nc", report = dir.path() / "report.json";
    std::string out;
    ASSERT_EQ(run_exe("mesh -q --coast " + quote(coast) +
                          " --coast-layer land --hmax 100km --passages default -o " +
                          quote(mesh.string()) + " --report " + quote(report.string()),
                      out),
              0)
        << out;
    std::ifstream r(report);
    std::stringstream json;
    json << r.rdbuf();
    const auto names = regex_all(json.str(), R"re("name": "([^"]+)")re", 1);
    const auto reported = regex_all(json.str(), R"re("cells": (\d+))re", 1);
    ASSERT_EQ(names.size(), 22u) << json.str();
    ASSERT_EQ(reported.size(), names.size());
    const auto cells = cells_across(mesh, passages, dir.path());
    ASSERT_EQ(cells.size(), 22u);
    for (std::size_t i = 0; i < names.size(); ++i) {
        ASSERT_TRUE(cells.count(names[i])) << names[i];
        EXPECT_GE(cells.at(names[i]), 2) << names[i] << " is not open with 2 cells across";
        EXPECT_LE(cells.at(names[i]), std::stoi(reported[i])) << names[i];
    }
    expect_mesh_verify(mesh, "--min-quality 0.3");
    std::string verdict;
    if (pct_above_0_8 > 0 && globemesh::test::mesh_verify_json(mesh, "", verdict) >= 0) {
        const auto pct = regex_all(verdict, R"re("pct_above_0.8": ([0-9.eE+-]+))re", 1);
        ASSERT_EQ(pct.size(), 1u) << verdict;
        EXPECT_GE(std::stod(pct[0]), pct_above_0_8);
    }
}

TEST(Passages, DefaultListStaysOpenOnNaturalEarth50m) {
    expect_passages_open(land50);
}

TEST(Passages, DefaultListStaysOpenOnNaturalEarth10m) {
    const fs::path land10 = fs::path(GLOBEMESH_SHARED_DIR) / "data" / "ne_10m_land.gpkg";
    if (!fs::exists(land10)) {
        globemesh::test::tool_missing("the Natural Earth 1:10m land (" + land10.string() + ")");
        return;
    }
    expect_passages_open(land10.string(), 99.0); // issue 40: >= 99% of the faces above q 0.8
}

// Without --passages the same run closes the narrow ones: the count sees a closed strait.
TEST(Passages, WithoutThemTheNarrowStraitsClose) {
    TempDir dir;
    const fs::path mesh = dir.path() / "ocean.nc";
    std::string out;
    ASSERT_EQ(run_exe("mesh -q --coast " + quote(land50) + " --coast-layer land --hmax 100km -o " +
                          quote(mesh.string()),
                      out),
              0)
        << out;
    const auto cells = cells_across(mesh, passages, dir.path());
    EXPECT_LT(cells.at("Bosphorus"), 2);
    EXPECT_LT(cells.at("Oresund"), 2);
}

/// Land west of 10.02 and east of 10.08 degrees east: water 0.06 degrees of longitude wide.
class Channel final : public globemesh::LandTest {
public:
    bool contains(const globemesh::Vec3 &p) const override {
        const double lon = globemesh::vec_to_lonlat(p).lon;
        return lon < 10.02 || lon > 10.08;
    }
    bool coast_within(const globemesh::Vec3 &, double) const override { return false; }
};

TEST(Passages, WidthIsTheLinesLengthInWater) {
    using namespace globemesh;
    std::vector<Passage> p{{"channel", {lonlat_to_vec(10, 0), lonlat_to_vec(10.1, 0)}, 0}};
    const double degree_km = earth_radius_km * pi / 180;
    measure_passages(p, nullptr);
    EXPECT_NEAR(p[0].width_km, 0.1 * degree_km, 1e-6);
    const Channel land;
    measure_passages(p, &land);
    EXPECT_NEAR(p[0].width_km, 0.06 * degree_km, 0.001 * degree_km);
}

// The field is width / cells along the line, below --hmin, and graded up to --hmax around it.
TEST(Passages, SizeFieldGoesBelowHminAlongTheLine) {
    using namespace globemesh;
    MeshOptions o;
    o.region = std::array<double, 4>{0, -10, 20, 10};
    o.hmin_km = 10;
    o.hmax_km = 100;
    o.passage_cells = 2;
    const std::vector<Passage> p{{"channel", {lonlat_to_vec(10, 0), lonlat_to_vec(10.1, 0)}, 1.0}};
    const SizeField f = build_size_field(o, nullptr, nullptr, {}, 1 << 18, {}, p);
    for (double lon : {10.0, 10.03, 10.05, 10.1})
        EXPECT_NEAR(f.size_km(lon, 0), 0.5, 1e-4) << lon;
    const double away = arc_km(lonlat_to_vec(10.05, 0), lonlat_to_vec(10.05, 1));
    EXPECT_LE(f.size_km(10.05, 1), 0.5 + o.grade * away + 1e-3);
    EXPECT_GE(f.size_km(10.05, 1), o.hmin_km);
    EXPECT_NEAR(f.size_km(1, 9), 100, 1e-4);
    // Without passages the same options give the uniform field.
    EXPECT_TRUE(build_size_field(o, nullptr, nullptr).is_uniform());
}

TEST(Passages, LineMeetsTriangle) {
    using namespace globemesh;
    const Vec3 a = lonlat_to_vec(-1, -1), b = lonlat_to_vec(1, -1), c = lonlat_to_vec(0, 1);
    auto meets = [&](std::vector<Vec3> line) { return line_meets_triangle(line, a, b, c); };
    EXPECT_TRUE(meets({lonlat_to_vec(-2, 0), lonlat_to_vec(2, 0)}));     // across
    EXPECT_TRUE(meets({lonlat_to_vec(-0.1, 0), lonlat_to_vec(0.1, 0)})); // inside
    EXPECT_TRUE(meets({lonlat_to_vec(0, -3), lonlat_to_vec(0, 0)}));     // into it
    EXPECT_FALSE(meets({lonlat_to_vec(5, 5), lonlat_to_vec(6, 6)}));
    EXPECT_FALSE(meets({lonlat_to_vec(179, 0), lonlat_to_vec(-179, 0)})); // the antipodes
    EXPECT_FALSE(meets({lonlat_to_vec(-2, 2), lonlat_to_vec(2, 2)}));     // above the apex
}

// Ring 0: the square of side 2 degrees around (0, 0), ocean inside (counter-clockwise); ring 1:
// an island at (0.5, 0.5), ocean outside (clockwise).
TEST(Passages, LineMeetsOcean) {
    using namespace globemesh;
    Boundary b;
    b.rings.push_back(
        {{lonlat_to_vec(-1, -1), lonlat_to_vec(1, -1), lonlat_to_vec(1, 1), lonlat_to_vec(-1, 1)},
         std::vector<SegmentKind>(4, SegmentKind::open)});
    b.rings.push_back({{lonlat_to_vec(0.4, 0.4), lonlat_to_vec(0.4, 0.6), lonlat_to_vec(0.6, 0.6),
                        lonlat_to_vec(0.6, 0.4)},
                       std::vector<SegmentKind>(4, SegmentKind::coast)});
    auto meets = [&](double x0, double y0, double x1, double y1) {
        const std::vector<Vec3> line{lonlat_to_vec(x0, y0), lonlat_to_vec(x1, y1)};
        return line_meets_ocean(line, b);
    };
    EXPECT_TRUE(meets(-0.5, -0.5, -0.2, 0.3));  // all in the ocean, no outline crossed
    EXPECT_TRUE(meets(-3, 0, 3, 0));            // across the region
    EXPECT_TRUE(meets(0.5, 0.5, 0.5, 0.9));     // from the island out
    EXPECT_FALSE(meets(0.45, 0.45, 0.55, 0.5)); // on the island
    EXPECT_FALSE(meets(2, 2, 3, -2));           // outside, within the box of the region
    EXPECT_FALSE(meets(178, 0, 179, 0));        // the far side
    EXPECT_FALSE(line_meets_ocean(std::vector<Vec3>{lonlat_to_vec(5, 5), lonlat_to_vec(6, 5)}, b));
    EXPECT_TRUE(line_meets_ocean(std::vector<Vec3>{lonlat_to_vec(5, 5), lonlat_to_vec(6, 5)},
                                 Boundary{})); // the whole sphere is ocean
}

// With --region-file, the passages whose line does not reach the polygon's ocean are dropped:
// Menorca's line lies inside the triangle's W,S,E,N box but outside the triangle, the
// Bosphorus's far from both.
TEST(Passages, RegionFileKeepsOnlyThePassagesInIt) {
    TempDir dir;
    const fs::path region = dir.path() / "triangle.geojson", lines = dir.path() / "lines.geojson";
    std::ofstream(region) << R"({"type": "FeatureCollection", "features": [{"type": "Feature",)"
                             R"( "properties": {}, "geometry": {"type": "Polygon", "coordinates":)"
                             R"( [[[-12, 33], [4, 33], [-12, 46], [-12, 33]]]}}]})";
    std::ofstream(lines)
        << R"({"type": "FeatureCollection", "features": [)"
           R"({"type": "Feature", "properties": {"name": "Gibraltar"}, "geometry": {"type":)"
           R"( "LineString", "coordinates": [[-5.61, 36.03], [-5.47, 35.9]]}},)"
           R"({"type": "Feature", "properties": {"name": "Menorca"}, "geometry": {"type":)"
           R"( "LineString", "coordinates": [[3.3, 39.7], [3.95, 40.0]]}},)"
           R"({"type": "Feature", "properties": {"name": "Bosphorus"}, "geometry": {"type":)"
           R"( "LineString", "coordinates": [[29.0, 41.1], [29.1, 41.05]]}}]})";
    std::string out;
    ASSERT_EQ(run_exe("mesh --coast " + quote(land50) + " --coast-layer land --hmax 50km" +
                          " --region-file " + quote(region.string()) + " --passages " +
                          quote(lines.string()) + " -o " + quote((dir.path() / "m.nc").string()),
                      out),
              0)
        << out;
    EXPECT_TRUE(
        regex_search(out, R"(passages +1, 1 with >= 2 cells across \(fewest [0-9]+: Gibraltar)"))
        << out;
    EXPECT_FALSE(regex_search(out, "warning: passage")) << out;
    expect_mesh_verify(dir.path() / "m.nc", "--min-quality 0.3");
}

// A region box across a strait with the passage's ends outside it: the box's region kept only a
// line with a point inside, and the Florida Straits' line (ends on the Keys and Cuba) was dropped:
// 8 nodes of 100 km across them. The line reaching the box's ocean is kept, as with a region file.
TEST(Passages, RegionBoxKeepsALineAcrossItWithItsEndsOutside) {
    TempDir dir;
    std::string out;
    ASSERT_EQ(run_exe("mesh --coast " + quote(land50) + " --coast-layer land --hmax 100km" +
                          " --region -82,23.3,-80,24.5 --passages default --passage-cells 8 -o " +
                          quote((dir.path() / "m.nc").string()),
                      out),
              0)
        << out;
    EXPECT_TRUE(regex_search(
        out, R"(passages +1, 1 with >= 8 cells across \(fewest [0-9]+: Florida Straits)"))
        << out;
    expect_mesh_verify(dir.path() / "m.nc", "--min-quality 0.3");
}

// --passage-cells 1 (the size across the passage its width): the inlet rule closed the Little
// Belt's water, which no strait closing may take (GSHHG i at 10 km: 0 cells, with a warning).
// A passage line keeps the inlet it runs through open too.
TEST(Passages, OneCellAcrossKeepsTheInletOpen) {
    TempDir dir;
    std::string out;
    ASSERT_EQ(run_exe("mesh --coast " +
                          quote(fixture("coast/hostile/gshhg_i_little_belt.geojson").string()) +
                          " --region 9.2,55.2,10.2,55.8 --hmax 10km --passages default"
                          " --passage-cells 1 -o " +
                          quote((dir.path() / "m.nc").string()),
                      out),
              0)
        << out;
    EXPECT_TRUE(regex_search(
        out, R"(passages +1, 1 with >= 1 cells across \(fewest [1-9][0-9]*: Little Belt)"))
        << out;
    EXPECT_FALSE(regex_search(out, "warning: passage")) << out;
}

// A line drawn on land (no water across) ends with no cell: a warning names it, never silent.
TEST(Passages, WarnsOfAPassageShortOfCells) {
    TempDir dir;
    const fs::path lines = dir.path() / "lines.geojson";
    std::ofstream(lines)
        << R"({"type": "FeatureCollection", "features": [)"
           R"({"type": "Feature", "properties": {"name": "Gibraltar"}, "geometry": {"type":)"
           R"( "LineString", "coordinates": [[-5.61, 36.03], [-5.47, 35.9]]}},)"
           R"({"type": "Feature", "properties": {"name": "Meseta"}, "geometry": {"type":)"
           R"( "LineString", "coordinates": [[-4, 40], [-3, 40]]}}]})";
    std::string out;
    ASSERT_EQ(run_exe("mesh --coast " + quote(land50) +
                          " --coast-layer land --hmax 50km --region -12,33,4,46 --passages " +
                          quote(lines.string()) + " -o " + quote((dir.path() / "m.nc").string()),
                      out),
              0)
        << out;
    EXPECT_TRUE(regex_search(out, R"(passages +2, 1 with >= 2 cells across \(fewest 0: Meseta)"))
        << out;
    EXPECT_TRUE(
        regex_search(out, R"(globemesh: warning: passage Meseta \(0 km of water.*has 0 cells)"))
        << out;
    EXPECT_FALSE(regex_search(out, "warning: passage Gibraltar")) << out;
}

TEST(Passages, Errors) {
    TempDir dir;
    const std::string base = "mesh -q --coast " + quote(land50) + " --coast-layer land -o " +
                             quote((dir.path() / "m.nc").string()) + " ";
    std::string out;
    EXPECT_EQ(run_exe(base + "--passages " + quote((dir.path() / "none.geojson").string()), out),
              1);
    EXPECT_TRUE(regex_search(out, R"(^globemesh: .*--passages.*none\.geojson)")) << out;
    // A file that holds no vector data (a raster): GDAL's reason, not "unknown error"; the
    // size regions are opened by the same code.
    const std::string raster = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    for (const std::string option : {"--passages ", "--size-regions "}) {
        EXPECT_EQ(run_exe(base + option + quote(raster), out), 1);
        EXPECT_TRUE(regex_search(out, "^globemesh: " + option +
                                          ".*etopo5_nwshelf_5min.tif: cannot open as vector data: "
                                          ".*not recognized as a supported file format"))
            << out;
        EXPECT_EQ(out.find("unknown error"), std::string::npos) << out;
    }
    EXPECT_EQ(run_exe(base + "--passages " + quote(land50), out), 1);
    EXPECT_TRUE(
        regex_search(out, R"(^globemesh: --passages .*Polygon.*lines drawn across straits)"))
        << out;
    EXPECT_EQ(run_exe(base + "--passages default --passage-cells 0", out), 2);
    EXPECT_TRUE(regex_search(out, R"(^globemesh: --passage-cells must be in 1\.\.100)")) << out;
    EXPECT_EQ(run_exe(base + "--passages-layer x", out), 2);
    EXPECT_TRUE(regex_search(out, R"(--passages-layer names a layer of --passages)")) << out;
    // The passages' sizes count against --max-nodes: the run is refused, not meshed.
    EXPECT_EQ(run_exe(base + "--hmax 100km --passages default --max-nodes 48000", out), 1);
    EXPECT_TRUE(regex_search(out, R"(more than 48000 nodes \(--max-nodes\))")) << out;
    // ... and says that the passages ask for them (raising --hmin does not help there).
    EXPECT_TRUE(regex_search(out, R"(ask less of the passages \(--passage-cells)")) << out;
    EXPECT_EQ(run_exe(base + "--hmax 100km --max-nodes 48000", out), 0) << out;
    fs::remove(dir.path() / "m.nc");
    EXPECT_FALSE(fs::exists(dir.path() / "m.nc"));
}

} // namespace
