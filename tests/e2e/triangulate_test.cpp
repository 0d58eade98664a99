// End to end: `globemesh triangulate` through run_cli with the real library. Oracles: the
// independent checker mesh-verify (Delaunay check on), Euler's formula on the read-back mesh
// (closed: F = 2V - 4; one hemisphere: F = 2V - B - 2 with B boundary edges), ogr2ogr's own
// reprojection to EPSG:3857 giving the same triangles, and the CLI's exit-status contract.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "globemesh/cli.hpp"
#include "globemesh/ugrid.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::fixture;
using globemesh::test::TempDir;

namespace {

struct CliRun {
    int status;
    std::string out, err;
};

CliRun triangulate(std::vector<std::string> args) {
    args.insert(args.begin(), "triangulate");
    std::ostringstream out, err;
    int status = globemesh::run_cli(args, out, err);
    return {status, out.str(), err.str()};
}

void write_csv(const fs::path &path, const std::vector<std::array<double, 2>> &lonlat) {
    std::ofstream f(path);
    f.precision(17);
    f << "id,lon,lat\n";
    for (std::size_t i = 0; i < lonlat.size(); ++i)
        f << i << "," << lonlat[i][0] << "," << lonlat[i][1] << "\n";
}

std::vector<std::array<double, 2>> random_lonlat(std::size_t n, double lat_min, double lat_max,
                                                 unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> lon(-180, 180),
        z(std::sin(lat_min * M_PI / 180), std::sin(lat_max * M_PI / 180));
    std::vector<std::array<double, 2>> p(n);
    for (auto &q : p)
        q = {lon(rng), std::asin(z(rng)) * 180 / M_PI};
    return p;
}

// Faces as a set of vertex triples, each rotated to start at its smallest index (keeps
// orientation).
std::set<std::array<globemesh::NodeIndex, 3>> face_set(const globemesh::Mesh &m) {
    std::set<std::array<globemesh::NodeIndex, 3>> s;
    for (auto f : m.faces) {
        std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
        s.insert(f);
    }
    return s;
}

int line_count(const std::string &s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

} // namespace

TEST(Triangulate, stations_csv_gives_a_closed_delaunay_mesh_in_netcdf_and_geopackage) {
    TempDir dir;
    CliRun r = triangulate({fixture("points/stations.csv").string(), "-o", (dir / "s.nc").string(),
                            "--gpkg", (dir / "s.gpkg").string(), "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_TRUE(fs::exists(dir / "s.gpkg"));
    globemesh::Mesh m = globemesh::read_ugrid(dir / "s.nc");
    EXPECT_EQ(m.nodes.size(), 2000u); // the 2000 distinct stations of the fixture
    EXPECT_EQ(m.faces.size(), 2 * m.nodes.size() - 4);
    globemesh::test::expect_mesh_verify(dir / "s.nc");
}

TEST(Triangulate, random_points_csv_gives_a_closed_mesh_with_every_point) {
    TempDir dir;
    write_csv(dir / "random.csv", random_lonlat(20000, -90, 90, 7));
    CliRun r = triangulate({(dir / "random.csv").string(), "-o", (dir / "r.nc").string(), "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
    globemesh::Mesh m = globemesh::read_ugrid(dir / "r.nc");
    EXPECT_EQ(m.nodes.size(), 20000u);
    EXPECT_EQ(m.faces.size(), 2 * m.nodes.size() - 4);
    EXPECT_TRUE(m.boundary.empty());
    globemesh::test::expect_mesh_verify(dir / "r.nc");
}

TEST(Triangulate, geopackage_in_web_mercator_gives_the_same_triangles_as_the_lonlat_csv) {
    std::string out;
    if (globemesh::test::run_command("ogr2ogr --version", out) != 0)
        GTEST_SKIP() << "ogr2ogr not found";
    TempDir dir;
    write_csv(dir / "p.csv", random_lonlat(3000, -80, 80, 11));
    // ogr2ogr (GDAL's own tool, not our reader) writes the same points in EPSG:3857.
    ASSERT_EQ(globemesh::test::run_command("ogr2ogr -f GPKG " + (dir / "p3857.gpkg").string() +
                                               " " + (dir / "p.csv").string() +
                                               " -oo X_POSSIBLE_NAMES=lon -oo Y_POSSIBLE_NAMES=lat "
                                               "-s_srs EPSG:4326 -t_srs EPSG:3857 -nln merc",
                                           out),
              0)
        << out;
    CliRun a = triangulate({(dir / "p.csv").string(), "-o", (dir / "a.nc").string(), "-q"});
    CliRun b = triangulate(
        {(dir / "p3857.gpkg").string(), "--layer", "merc", "-o", (dir / "b.nc").string(), "-q"});
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    globemesh::Mesh ma = globemesh::read_ugrid(dir / "a.nc"),
                    mb = globemesh::read_ugrid(dir / "b.nc");
    ASSERT_EQ(ma.nodes.size(), mb.nodes.size());
    for (std::size_t i = 0; i < ma.nodes.size();
         ++i) // same node order (the input's), nearly same place
        ASSERT_LT(globemesh::arc_angle(ma.nodes[i], mb.nodes[i]), 1e-9) << "node " << i;
    EXPECT_EQ(face_set(ma), face_set(mb));
}

TEST(Triangulate, one_degree_grid_with_both_poles_merges_the_pole_rows) {
    TempDir dir;
    std::vector<std::array<double, 2>> grid;
    for (int lat = -90; lat <= 90; ++lat)
        for (int lon = -180; lon < 180; ++lon)
            grid.push_back({double(lon), double(lat)});
    write_csv(dir / "grid.csv", grid);
    CliRun r = triangulate({(dir / "grid.csv").string(), "-o", (dir / "g.nc").string(), "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
    globemesh::Mesh m = globemesh::read_ugrid(dir / "g.nc");
    EXPECT_EQ(m.nodes.size(), 360u * 179u + 2u); // each pole row is one point
    EXPECT_EQ(m.faces.size(), 2 * m.nodes.size() - 4);
    globemesh::test::expect_mesh_verify(dir / "g.nc");
}

TEST(Triangulate, points_in_one_hemisphere_give_a_disk_with_an_open_boundary) {
    TempDir dir;
    write_csv(dir / "north.csv", random_lonlat(5000, 10, 90, 3));
    CliRun r = triangulate({(dir / "north.csv").string(), "-o", (dir / "n.nc").string(), "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
    globemesh::Mesh m = globemesh::read_ugrid(dir / "n.nc");
    EXPECT_EQ(m.nodes.size(), 5000u);
    ASSERT_FALSE(m.boundary.empty());
    // A triangulated disk: F = 2V - B - 2, with B boundary edges (= boundary vertices).
    EXPECT_EQ(m.faces.size(), 2 * m.nodes.size() - m.boundary.size() - 2);
    for (const auto &e : m.boundary)
        EXPECT_EQ(e.tag, globemesh::EdgeTag::open);
    globemesh::test::expect_mesh_verify(dir / "n.nc");
}

TEST(Triangulate, timings_json_has_read_sort_triangulate_each_writer_and_the_total) {
    TempDir dir;
    CliRun r = triangulate({fixture("points/stations.csv").string(), "-o", (dir / "s.nc").string(),
                            "--timings", (dir / "t.json").string(), "-q"});
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream f(dir / "t.json");
    std::string json((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_EQ(json.rfind("{\"stages\": {", 0), 0u) << json;
    for (const char *key : {"\"read\": ", "\"sort\": ", "\"triangulate\": ", "\"write_ugrid\": ",
                            "\"write\": ", "\"total\": "})
        EXPECT_NE(json.find(key), std::string::npos) << key << " missing in " << json;
}

struct BadInput {
    const char *name;
    const char *csv;     // file content; nullptr: the file does not exist
    const char *message; // a word the error line must hold
};

class TriangulateBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(TriangulateBadInput, fails_with_one_line_and_leaves_no_output) {
    const BadInput &bad = GetParam();
    TempDir dir;
    const fs::path in = dir / "in.csv";
    if (bad.csv) {
        std::ofstream f(in);
        f << bad.csv;
    }
    CliRun r =
        triangulate({in.string(), "-o", (dir / "out.nc").string(), "--gpkg",
                     (dir / "out.gpkg").string(), "--timings", (dir / "t.json").string(), "-q"});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("globemesh: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(bad.message), std::string::npos) << r.err;
    for (const auto &e : fs::directory_iterator(dir.path()))
        EXPECT_EQ(e.path().filename(), "in.csv") << "left behind: " << e.path();
}

INSTANTIATE_TEST_SUITE_P(
    Triangulate, TriangulateBadInput,
    ::testing::Values(
        BadInput{"missing_file", nullptr, "in.csv"},
        BadInput{"empty_layer", "id,lon,lat\n", "no points"},
        BadInput{"two_points", "id,lon,lat\n1,0,0\n2,10,10\n", "fewer than 3 distinct points"},
        BadInput{"all_on_the_equator", "id,lon,lat\n1,0,0\n2,10,0\n3,50,0\n4,120,0\n5,-100,0\n",
                 "one circle"},
        BadInput{"non_numeric_longitude", "id,lon,lat\n1,0,0\n2,abc,10\n3,50,5\n4,20,-3\n",
                 "feature 2"},
        BadInput{"latitude_95", "id,lon,lat\n1,0,0\n2,10,95\n3,50,5\n4,20,-3\n", "feature 2"}),
    [](const ::testing::TestParamInfo<BadInput> &info) { return std::string(info.param.name); });
