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
/// says, mesh-verify VALID with no face below quality 0.3.
void expect_passages_open(const std::string &coast) {
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
    expect_passages_open(land10.string());
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
    EXPECT_EQ(run_exe(base + "--passages " + quote(land50), out), 1);
    EXPECT_TRUE(
        regex_search(out, R"(^globemesh: --passages .*Polygon.*lines drawn across straits)"))
        << out;
    EXPECT_EQ(run_exe(base + "--passages default --passage-cells 0", out), 2);
    EXPECT_TRUE(regex_search(out, R"(^globemesh: --passage-cells must be in 1\.\.100)")) << out;
    EXPECT_EQ(run_exe(base + "--passages-layer x", out), 2);
    EXPECT_TRUE(regex_search(out, R"(--passages-layer names a layer of --passages)")) << out;
    EXPECT_FALSE(fs::exists(dir.path() / "m.nc"));
}

} // namespace
