// End to end through the globemesh executable (and run_cli with the real library): the runs a
// user makes, judged by independent readers (python3 netCDF4 and json, mesh-verify) rather than
// by globemesh's own output.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "globemesh/cli.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::run_command;
using globemesh::test::TempDir;

namespace {

const std::string exe = GLOBEMESH_EXE;
const std::string land110 = fixture("coast/ne_110m_land.gpkg").string();
const std::string land50 = fixture("coast/ne_50m_land.gpkg").string();
const std::string shelf_dem = fixture("bathy/etopo5_nwshelf_5min.tif").string();

std::string quote(const std::string& s) { return "'" + s + "'"; }

/// Runs the executable; `out` gets stdout only, `err` stderr only.
int run_exe(const std::vector<std::string>& args, std::string& out, std::string& err, const fs::path& dir) {
    std::string command = quote(exe);
    for (const auto& a : args) command += " " + quote(a);
    const fs::path err_file = dir / ".stderr";
    const int status = run_command("( " + command + " 2>" + quote(err_file.string()) + " )", out);
    std::ifstream e(err_file);
    std::stringstream s;
    s << e.rdbuf();
    err = s.str();
    fs::remove(err_file);
    return status;
}

/// Runs a python3 script (independent reader) and returns its stdout; fails the test on error.
std::string python(const std::string& script, const fs::path& dir) {
    const fs::path file = dir / ".check.py";
    std::ofstream(file) << script;
    std::string out;
    const int status = run_command("/usr/bin/python3 " + quote(file.string()), out);
    fs::remove(file);
    EXPECT_EQ(status, 0) << out;
    return out;
}

std::set<std::string> files_in(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
}

int count_lines(const std::string& s) {
    int n = 0;
    for (char c : s) n += c == '\n';
    return n;
}

} // namespace

TEST(CliE2e, global_mesh_writes_every_output_and_the_report_matches_the_file) {
    TempDir dir;
    std::string out, err;
    const int status = run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "400km",
                                "-o", (dir / "g.nc").string(), "--gpkg", (dir / "g.gpkg").string(),
                                "--preview", (dir / "g.png").string(), "--report", (dir / "r.json").string(),
                                "--timings", (dir / "t.json").string(), "--check"},
                               out, err, dir.path());
    ASSERT_EQ(status, 0) << err;
    EXPECT_NE(out.find("nodes"), std::string::npos) << out;
    EXPECT_NE(out.find("peak memory"), std::string::npos) << out;
    EXPECT_NE(err.find("100 - done."), std::string::npos) << err;
    // Exactly the outputs asked for: no temporary file left beside them.
    EXPECT_EQ(files_in(dir.path()), (std::set<std::string>{"g.nc", "g.gpkg", "g.png", "r.json", "t.json"}));
    expect_mesh_verify(dir / "g.nc");
    // The report and timings against the NetCDF file, read by netCDF4 and json.
    const std::string verdict = python(R"(
import json, netCDF4, numpy as np
r = json.load(open(')" + (dir / "r.json").string() + R"('))
t = json.load(open(')" + (dir / "t.json").string() + R"('))
ds = netCDF4.Dataset(')" + (dir / "g.nc").string() + R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
lon = ds.variables[mesh.node_coordinates.split()[0]]
faces = ds.variables[mesh.face_node_connectivity]
assert r['mesh']['nodes'] == lon.shape[0], (r['mesh']['nodes'], lon.shape)
assert r['mesh']['faces'] == faces.shape[0], (r['mesh']['faces'], faces.shape)
assert sum(r['mesh']['quality']['histogram']) == faces.shape[0]
assert 0 < r['mesh']['quality']['min'] <= r['mesh']['quality']['mean'] <= 1
assert r['peak_memory_bytes'] > 1e6
for k in ('mesh', 'write'):
    assert k in t['stages'], t
assert all(v >= 0 for v in t['stages'].values())
assert 0.6 * 400 < r['mesh']['edge_km']['mean'] < 1.3 * 400, r['mesh']['edge_km']
print('OK', lon.shape[0])
)",
                                       dir.path());
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
    // info reads back the same counts.
    std::string info_out, info_err;
    ASSERT_EQ(run_exe({"info", (dir / "g.nc").string(), "--json"}, info_out, info_err, dir.path()), 0) << info_err;
    fs::path info_json = dir / "info.json";
    std::ofstream(info_json) << info_out;
    const std::string same = python(R"(
import json
a = json.load(open(')" + info_json.string() + R"('))
b = json.load(open(')" + (dir / "r.json").string() + R"('))['mesh']
for k in ('nodes', 'faces', 'edges', 'boundary_edges', 'boundary_loops'):
    assert a[k] == b[k], (k, a[k], b[k])
assert abs(a['quality']['mean'] - b['quality']['mean']) < 1e-9
print('OK')
)",
                                    dir.path());
    EXPECT_EQ(same, "OK\n");
}

TEST(CliE2e, regional_run_has_coast_and_open_boundaries_inside_the_region) {
    TempDir dir;
    std::string out, err;
    const int status = run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-12,46,13,62",
                                "--bathy", shelf_dem, "--hmax", "60km", "--hmin", "10km", "--coast-size", "15km",
                                "-o", (dir / "r.nc").string(), "--quiet"},
                               out, err, dir.path());
    ASSERT_EQ(status, 0) << err;
    EXPECT_EQ(err, ""); // --quiet
    expect_mesh_verify(dir / "r.nc");
    const std::string verdict = python(R"(
import netCDF4, numpy as np
ds = netCDF4.Dataset(')" + (dir / "r.nc").string() + R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
lon = ds.variables[mesh.node_coordinates.split()[0]][:]
lat = ds.variables[mesh.node_coordinates.split()[1]][:]
# The region's edges may be great-circle arcs between its corners: the northern one bulges
# poleward up to atan(tan(N) / cos((E - W) / 2)), the southern one never below S.
north = np.degrees(np.arctan(np.tan(np.radians(62)) / np.cos(np.radians(25 / 2))))
assert lon.min() >= -12 - 1e-6 and lon.max() <= 13 + 1e-6, (lon.min(), lon.max())
assert lat.min() >= 46 - 1e-6 and lat.max() <= north + 1e-6, (lat.min(), lat.max(), north)
tag = ds.variables['boundary_tag'][:]
assert (tag == 1).any() and (tag == 2).any(), np.unique(tag)
assert 'depth' in ds.variables
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
}

TEST(CliE2e, a_config_file_run_equals_the_same_run_by_options) {
    TempDir dir;
    std::string out, err;
    ASSERT_EQ(run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "600km", "--seed", "3",
                       "--smooth", "2", "-o", (dir / "a.nc").string(), "-q"},
                      out, err, dir.path()),
              0)
        << err;
    std::ofstream(dir / "run.toml") << "coast = \"" << land110 << "\"\ncoast-layer = \"land\"\nhmax = \"600000m\"\n"
                                    << "seed = 3\nsmooth = 2\nquiet = true\n";
    ASSERT_EQ(run_exe({"mesh", "--config", (dir / "run.toml").string(), "-o", (dir / "b.nc").string()}, out, err,
                      dir.path()),
              0)
        << err;
    const std::string verdict = python(R"(
import netCDF4, numpy as np
a = netCDF4.Dataset(')" + (dir / "a.nc").string() + R"(')
b = netCDF4.Dataset(')" + (dir / "b.nc").string() + R"(')
assert set(a.variables) == set(b.variables)
for name in a.variables:
    if a.variables[name].shape == ():
        continue  # attribute containers (mesh, crs): their value carries no data
    assert np.array_equal(np.ma.filled(a.variables[name][:], -1), np.ma.filled(b.variables[name][:], -1)), name
print('OK', len(a.variables))
)",
                                       dir.path());
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
}

TEST(CliE2e, print_config_output_reads_back_to_the_same_configuration) {
    TempDir dir;
    std::string first, second, err;
    ASSERT_EQ(run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-12,46,13,62",
                       "--bathy", shelf_dem, "--hmax", "20km", "--min-island-area", "5e7m2", "--wave-period", "25h",
                       "-o", (dir / "x.nc").string(), "--print-config"},
                      first, err, dir.path()),
              0)
        << err;
    std::ofstream(dir / "p.toml") << first;
    ASSERT_EQ(run_exe({"mesh", "--config", (dir / "p.toml").string(), "--print-config"}, second, err, dir.path()), 0)
        << err;
    EXPECT_EQ(first, second);
    EXPECT_NE(first.find("hmax=20"), std::string::npos) << first;
    EXPECT_NE(first.find("min-island-area=50"), std::string::npos) << first;
    EXPECT_FALSE(fs::exists(dir / "x.nc"));
}

TEST(CliE2e, triangulate_stations_gives_a_closed_triangulation) {
    TempDir dir;
    std::string out, err;
    ASSERT_EQ(run_exe({"triangulate", fixture("points/stations.csv").string(), "-o", (dir / "s.nc").string(),
                       "--timings", (dir / "t.json").string(), "-q"},
                      out, err, dir.path()),
              0)
        << err;
    expect_mesh_verify(dir / "s.nc");
    // 2000 points in general position on the sphere: V - E + F = 2 and 3F = 2E give F = 2V - 4.
    const std::string verdict = python(R"(
import json, netCDF4
ds = netCDF4.Dataset(')" + (dir / "s.nc").string() + R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
n = ds.variables[mesh.node_coordinates.split()[0]].shape[0]
f = ds.variables[mesh.face_node_connectivity].shape[0]
assert n == 2000 and f == 2 * n - 4, (n, f)
t = json.load(open(')" + (dir / "t.json").string() + R"('))
assert 'read' in t['stages'] and 'write' in t['stages'], t
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
    EXPECT_NE(out.find("3996"), std::string::npos) << out;
}

struct ExeError {
    std::string name;
    std::vector<std::string> args; // "{dir}" is the test's folder
    std::set<int> statuses;
    std::string named;
};

class CliE2eErrors : public ::testing::TestWithParam<ExeError> {};

TEST_P(CliE2eErrors, exit_status_one_line_and_no_output) {
    const ExeError& c = GetParam();
    TempDir dir;
    std::ofstream(dir / "existing.nc") << "keep me";
    std::vector<std::string> args;
    for (auto a : c.args) {
        for (auto p = a.find("{dir}"); p != std::string::npos; p = a.find("{dir}")) a.replace(p, 5, dir.path().string());
        args.push_back(a);
    }
    std::string out, err;
    const int status = run_exe(args, out, err, dir.path());
    EXPECT_TRUE(c.statuses.count(status)) << "status " << status << ": " << err;
    EXPECT_EQ(out, "");
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_EQ(err.rfind("globemesh: ", 0), 0u) << err;
    EXPECT_NE(err.find(c.named), std::string::npos) << err;
    EXPECT_EQ(files_in(dir.path()), std::set<std::string>{"existing.nc"});
}

INSTANTIATE_TEST_SUITE_P(
    CliE2e, CliE2eErrors,
    ::testing::Values(
        ExeError{"unknown_unit", {"mesh", "--coast", land110, "--hmax", "20parsecs", "-o", "{dir}/o.nc"}, {2}, "--hmax"},
        ExeError{"negative_size", {"mesh", "--coast", land110, "--coast-size", "-3km", "-o", "{dir}/o.nc"}, {2}, "--coast-size"},
        ExeError{"hmin_above_hmax", {"mesh", "--coast", land110, "--hmin", "200km", "-o", "{dir}/o.nc"}, {2}, "--hmin"},
        // A layer that is not there: the option's value is wrong (2) or the data lacks it (1).
        ExeError{"unknown_layer", {"mesh", "--coast", land110, "--coast-layer", "nosuch", "-o", "{dir}/o.nc", "-q"}, {1, 2}, "nosuch"},
        ExeError{"missing_file", {"mesh", "--coast", "{dir}/land.gpkg", "-o", "{dir}/o.nc"}, {1}, "land.gpkg"},
        ExeError{"region_without_ocean", {"mesh", "--coast", land110, "--coast-layer", "land", "--region", "0,20,10,25", "-o", "{dir}/o.nc", "-q"}, {1}, "region"},
        ExeError{"output_in_missing_folder", {"mesh", "--coast", land110, "-o", "{dir}/none/o.nc"}, {1}, "none"},
        ExeError{"existing_output", {"mesh", "--coast", land110, "-o", "{dir}/existing.nc"}, {1}, "--overwrite"},
        ExeError{"unknown_subcommand", {"mesj"}, {2}, "mesj"},
        ExeError{"info_on_a_non_mesh", {"info", "{dir}/existing.nc"}, {1}, "existing.nc"}),
    [](const auto& info) { return info.param.name; });

TEST(CliE2e, sigint_stops_a_run_and_leaves_no_output) {
    TempDir dir;
    const std::string output = (dir / "big.nc").string();
    std::vector<std::string> args = {exe, "mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "8km",
                                     "--max-nodes", "100000000", "-o", output, "-q"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string err_path = (dir.path().parent_path() / (dir.path().filename().string() + ".err")).string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ASSERT_EQ(spawned, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    kill(pid, SIGINT); // the process this test started, by its id
    int wstatus = 0;
    ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
    ASSERT_TRUE(WIFEXITED(wstatus)) << "killed by the signal instead of stopping cleanly";
    std::stringstream err;
    err << std::ifstream(err_path).rdbuf();
    fs::remove(err_path);
    if (WEXITSTATUS(wstatus) == 0) GTEST_SKIP() << "the run finished before the signal arrived";
    EXPECT_EQ(WEXITSTATUS(wstatus), 1);
    EXPECT_NE(err.str().find("globemesh: cancelled"), std::string::npos) << err.str();
    EXPECT_TRUE(fs::is_empty(dir.path())) << "output or temporary files left behind";
}

TEST(CliE2e, run_cli_in_process_prints_the_summary_on_out_only) {
    TempDir dir;
    std::ostringstream out, err;
    const std::vector<std::string> args = {"mesh", "--coast", land110, "--coast-layer", "land",
                                           "--hmax", "800km", "-o", (dir / "p.nc").string(), "--quiet"};
    ASSERT_EQ(globemesh::run_cli(args, out, err), 0) << err.str();
    EXPECT_EQ(err.str(), "");
    EXPECT_NE(out.str().find("faces"), std::string::npos);
    expect_mesh_verify(dir / "p.nc");
}
