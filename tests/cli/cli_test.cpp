// The command line in-process through run_cli (PROJ's test_projinfo_lib style). These tests pass
// their own CliLibrary: a bad command must stop before any library call, so the library here
// fails the test if it is reached. The runs through the real library are in tests/e2e.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <cpl_string.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <netcdf.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "globemesh/cli.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::fixture;
using globemesh::test::regex_all;
using globemesh::test::regex_match;
using globemesh::test::regex_replace;
using globemesh::test::regex_search;
using globemesh::test::TempDir;

namespace {

struct Result {
    int status = -1;
    std::string out, err;
};

/// A library whose every call is counted and refused: reaching it is a test failure.
struct RefusingLibrary {
    int calls = 0;
    globemesh::CliLibrary lib() {
        globemesh::CliLibrary l;
        auto refuse = [this] {
            ++calls;
            throw std::logic_error("the library was reached");
        };
        l.mesh_ocean = [refuse](auto &&...) -> globemesh::OceanMesh {
            refuse();
            return {};
        };
        l.triangulate_file = [refuse](auto &&...) -> globemesh::Mesh {
            refuse();
            return {};
        };
        l.writers = globemesh::writers();
        for (auto &w : l.writers)
            w.write = [refuse](auto &&...) { refuse(); };
        l.read_ugrid = [refuse](auto &&...) -> globemesh::Mesh {
            refuse();
            return {};
        };
        l.compute_stats = [refuse](auto &&...) -> globemesh::MeshStats {
            refuse();
            return {};
        };
        return l;
    }
};

/// The row of `lib`'s writers table named `name` (the test replaces its write function).
globemesh::Writer &row(globemesh::CliLibrary &lib, const std::string &name) {
    for (auto &w : lib.writers)
        if (w.name == name)
            return w;
    throw std::logic_error("no writer " + name);
}

Result run(const std::vector<std::string> &args, const globemesh::CliLibrary &lib) {
    std::ostringstream out, err;
    Result r;
    r.status = globemesh::run_cli(args, out, err, lib);
    r.out = out.str();
    r.err = err.str();
    return r;
}

/// Runs with a refusing library and checks the library was not reached.
Result run_refused(const std::vector<std::string> &args) {
    RefusingLibrary refusing;
    Result r = run(args, refusing.lib());
    EXPECT_EQ(refusing.calls, 0) << "the library was called for a command that should stop first";
    return r;
}

int count_lines(const std::string &s) {
    int n = 0;
    for (char c : s)
        n += c == '\n';
    return n;
}

const std::string coast = fixture("coast/ne_110m_land.gpkg").string();

std::string read_text(const fs::path &p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

void write_text(const fs::path &p, const std::string &text) {
    std::ofstream f(p);
    f << text;
}

/// Field by field comparison of two MeshOptions.
void expect_same_options(const globemesh::MeshOptions &a, const globemesh::MeshOptions &b) {
    EXPECT_EQ(a.coast, b.coast);
    EXPECT_EQ(a.coast_layer, b.coast_layer);
    EXPECT_EQ(a.coast_where, b.coast_where);
    EXPECT_EQ(a.coast_srs, b.coast_srs);
    EXPECT_EQ(a.region, b.region);
    EXPECT_EQ(a.region_file, b.region_file);
    EXPECT_EQ(a.region_layer, b.region_layer);
    EXPECT_EQ(a.min_island_area_km2, b.min_island_area_km2);
    EXPECT_EQ(a.min_island_triangles, b.min_island_triangles);
    EXPECT_EQ(a.keep_inland_seas, b.keep_inland_seas);
    EXPECT_EQ(a.keep_straits, b.keep_straits);
    EXPECT_EQ(a.bathy, b.bathy);
    EXPECT_EQ(a.bathy_band, b.bathy_band);
    EXPECT_EQ(a.depth_positive, b.depth_positive);
    EXPECT_EQ(a.bathy_fill_m, b.bathy_fill_m);
    EXPECT_EQ(a.min_depth_m, b.min_depth_m);
    EXPECT_EQ(a.bathy_srs, b.bathy_srs);
    EXPECT_EQ(a.hmax_km, b.hmax_km);
    EXPECT_EQ(a.hmin_km, b.hmin_km);
    EXPECT_EQ(a.coast_size_km, b.coast_size_km);
    EXPECT_EQ(a.coast_rate, b.coast_rate);
    EXPECT_EQ(a.wavelength, b.wavelength);
    EXPECT_EQ(a.wave_period_h, b.wave_period_h);
    EXPECT_EQ(a.slope, b.slope);
    EXPECT_EQ(a.feature_size, b.feature_size);
    EXPECT_EQ(a.size_regions, b.size_regions);
    EXPECT_EQ(a.size_regions_layer, b.size_regions_layer);
    EXPECT_EQ(a.grade, b.grade);
    EXPECT_EQ(a.max_nodes, b.max_nodes);
    EXPECT_EQ(a.max_memory_bytes, b.max_memory_bytes);
    EXPECT_EQ(a.smooth_iterations, b.smooth_iterations);
    EXPECT_EQ(a.inlet_width, b.inlet_width);
    EXPECT_EQ(a.seed, b.seed);
}

void expect_same_cli(const globemesh::CliOptions &a, const globemesh::CliOptions &b) {
    expect_same_options(a.mesh, b.mesh);
    EXPECT_EQ(a.output, b.output);
    EXPECT_EQ(a.gpkg, b.gpkg);
    EXPECT_EQ(a.preview, b.preview);
    EXPECT_EQ(a.preview_region, b.preview_region);
    EXPECT_EQ(a.format, b.format);
    EXPECT_EQ(a.timings, b.timings);
    EXPECT_EQ(a.report, b.report);
    EXPECT_EQ(a.overwrite, b.overwrite);
    EXPECT_EQ(a.quiet, b.quiet);
    EXPECT_EQ(a.verbose, b.verbose);
    EXPECT_EQ(a.check, b.check);
}

/// Every option except the program-only ones, each away from its default, in all unit styles.
std::vector<std::string> every_option(const std::string &out_dir) {
    return {"--coast",
            coast,
            "--coast-layer",
            "ne_110m_land",
            "--coast-where",
            "featurecla = 'Land'",
            "--coast-srs",
            "EPSG:4326",
            "--region",
            "-20.5,40,10.25,65",
            "--min-island-area",
            "2.5e7m2",
            "--keep-inland-seas",
            "--keep-straits",
            "--bathy",
            fixture("bathy/etopo5_nwshelf_5min.tif").string(),
            "--bathy-band",
            "1",
            "--bathy-srs",
            "EPSG:4326",
            "--depth-positive",
            "--bathy-fill",
            "0.05km",
            "--min-depth",
            "-2.5m",
            "--hmax",
            "45000m",
            "--hmin",
            "3.3",
            "--coast-size",
            "7.5km",
            "--coast-rate",
            "0.123456789012345",
            "--wavelength",
            "30",
            "--wave-period",
            "745.2min",
            "--slope",
            "12",
            "--feature-size",
            "2.5",
            "--size-regions",
            out_dir + "/sizes.gpkg",
            "--size-regions-layer",
            "fine",
            "--grade",
            "0.2",
            "--max-nodes",
            "123456",
            "--max-memory",
            "3.5GiB",
            "--smooth",
            "7",
            "--inlet-width",
            "0.25",
            "--seed",
            "42",
            "-o",
            out_dir + "/o.nc",
            "--gpkg",
            out_dir + "/o.gpkg",
            "--preview",
            out_dir + "/o.png",
            "--preview-region",
            "170,-50,-170,-10",
            "--format",
            "classic",
            "--timings",
            out_dir + "/t.json",
            "--report",
            out_dir + "/r.json",
            "--overwrite",
            "--verbose",
            "--check"};
}

/// Three quarters of the physical memory (the documented default of --max-memory), from sysconf.
std::uint64_t three_quarters_of_ram() {
    const auto pages = static_cast<std::uint64_t>(sysconf(_SC_PHYS_PAGES));
    const auto page = static_cast<std::uint64_t>(sysconf(_SC_PAGE_SIZE));
    return pages / 4 * 3 * page;
}

/// MeshOptions{} as the CLI fills it when no option is given.
globemesh::MeshOptions cli_default_options() {
    globemesh::MeshOptions o;
    o.max_memory_bytes = three_quarters_of_ram();
    return o;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Units

TEST(Cli, lengths_convert_from_metres_and_kilometres) {
    EXPECT_DOUBLE_EQ(globemesh::parse_length_km("5000m"), 5.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_length_km("20km"), 20.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_length_km("20"), 20.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_length_km(" 2.5e3 m "), 2.5);
    EXPECT_DOUBLE_EQ(globemesh::parse_length_km("+7 km"), 7.0);
}

TEST(Cli, areas_convert_from_square_metres_and_square_kilometres) {
    EXPECT_DOUBLE_EQ(globemesh::parse_area_km2("1e6m2"), 1.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_area_km2("1000km2"), 1000.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_area_km2("1000"), 1000.0);
}

TEST(Cli, durations_and_depths_convert) {
    EXPECT_DOUBLE_EQ(globemesh::parse_duration_h("90min"), 1.5);
    EXPECT_DOUBLE_EQ(globemesh::parse_duration_h("3600s"), 1.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_duration_h("12.42"), 12.42);
    EXPECT_DOUBLE_EQ(globemesh::parse_depth_m("0.05km"), 50.0);
    EXPECT_DOUBLE_EQ(globemesh::parse_depth_m("50"), 50.0);
}

TEST(Cli, unknown_units_and_non_numbers_are_usage_errors) {
    EXPECT_THROW(globemesh::parse_length_km("20parsecs"), globemesh::UsageError);
    EXPECT_THROW(globemesh::parse_length_km("km"), globemesh::UsageError);
    EXPECT_THROW(globemesh::parse_length_km(""), globemesh::UsageError);
    EXPECT_THROW(globemesh::parse_length_km("inf"), globemesh::UsageError);
    EXPECT_THROW(globemesh::parse_area_km2("10km"), globemesh::UsageError);
    EXPECT_THROW(globemesh::parse_length_km("10km2"), globemesh::UsageError);
}

TEST(Cli, memory_sizes_take_si_and_binary_units_and_auto) {
    auto bytes = [](const std::string &text) {
        return globemesh::parse_mesh_args(std::vector<std::string>{"--max-memory", text})
            .mesh.max_memory_bytes;
    };
    EXPECT_EQ(bytes("4GB"), 4'000'000'000u);
    EXPECT_EQ(bytes("500MB"), 500'000'000u);
    EXPECT_EQ(bytes("2.5 kB"), 2500u);
    EXPECT_EQ(bytes("2GiB"), std::uint64_t{2} << 30);
    EXPECT_EQ(bytes("3MiB"), std::uint64_t{3} << 20);
    EXPECT_EQ(bytes("123456"), 123456u); // bare: bytes
    EXPECT_EQ(bytes("0"), 0u);           // no limit
    EXPECT_EQ(bytes("auto"), three_quarters_of_ram());
    for (const char *bad : {"4G", "4gb", "-1GB", "lots", "1e30TB"})
        EXPECT_THROW(bytes(bad), globemesh::UsageError) << bad;
    // The configuration says what was asked ("auto", "4GB"), not this machine's memory.
    const Result asked = run_refused({"mesh", "--max-memory", "4GB", "--print-config"});
    EXPECT_NE(asked.out.find("max-memory=\"4GB\""), std::string::npos) << asked.out;
    const Result by_default = run_refused({"mesh", "--print-config"});
    EXPECT_NE(by_default.out.find("max-memory=\"auto\""), std::string::npos) << by_default.out;
    // Values below 1MB (other than 0) cannot hold any run: refused before reading anything.
    const Result r = run_refused({"mesh", "--coast", coast, "-o", "x.nc", "--max-memory", "1kB"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("--max-memory"), std::string::npos) << r.err;
}

TEST(Cli, flags_with_units_fill_the_fields_in_their_units) {
    const auto a = globemesh::parse_mesh_args(std::vector<std::string>{
        "--hmax", "5000m", "--hmin", "0.5", "--min-island-area", "1e6m2", "--coast-size", "2km",
        "--wave-period", "30min", "--bathy-fill", "1km", "--min-depth", "0.005km"});
    EXPECT_DOUBLE_EQ(a.mesh.hmax_km, 5.0);
    EXPECT_DOUBLE_EQ(a.mesh.hmin_km, 0.5);
    EXPECT_DOUBLE_EQ(a.mesh.min_island_area_km2, 1.0);
    EXPECT_DOUBLE_EQ(a.mesh.coast_size_km, 2.0);
    EXPECT_DOUBLE_EQ(a.mesh.wave_period_h, 0.5);
    ASSERT_TRUE(a.mesh.bathy_fill_m.has_value());
    EXPECT_DOUBLE_EQ(*a.mesh.bathy_fill_m, 1000.0);
    ASSERT_TRUE(a.mesh.min_depth_m.has_value());
    EXPECT_DOUBLE_EQ(*a.mesh.min_depth_m, 5.0);
    const auto b = globemesh::parse_mesh_args(std::vector<std::string>{"--hmax", "5"});
    EXPECT_EQ(a.mesh.hmax_km, b.mesh.hmax_km);
}

TEST(Cli, max_nodes_takes_a_whole_number_also_as_a_power_of_ten) {
    EXPECT_EQ(
        globemesh::parse_mesh_args(std::vector<std::string>{"--max-nodes", "2e7"}).mesh.max_nodes,
        20'000'000u);
    EXPECT_EQ(globemesh::parse_mesh_args(std::vector<std::string>{"--max-nodes", "123456789"})
                  .mesh.max_nodes,
              123'456'789u);
}

TEST(Cli, defaults_are_those_of_mesh_options) {
    const auto a = globemesh::parse_mesh_args(std::vector<std::string>{});
    // All but --max-memory, which the library leaves off and the CLI sets from the machine.
    expect_same_options(a.mesh, cli_default_options());
    EXPECT_EQ(globemesh::MeshOptions{}.max_memory_bytes, 0u);
    EXPECT_GT(a.mesh.max_memory_bytes, 0u);
    EXPECT_FALSE(a.mesh.region.has_value());
    EXPECT_FALSE(a.mesh.bathy_fill_m.has_value());
    EXPECT_FALSE(a.mesh.min_depth_m.has_value());
    EXPECT_EQ(a.format, "netcdf4");
}

TEST(Cli, region_takes_four_comma_separated_degrees) {
    const auto a = globemesh::parse_mesh_args(std::vector<std::string>{"--region", "-20,40,10,65"});
    ASSERT_TRUE(a.mesh.region.has_value());
    EXPECT_EQ(*a.mesh.region, (std::array<double, 4>{-20, 40, 10, 65}));
    EXPECT_THROW(globemesh::parse_mesh_args(std::vector<std::string>{"--region", "1,2,3"}),
                 globemesh::UsageError);
}

// ---------------------------------------------------------------------------------------------
// Config files and --print-config

TEST(Cli, config_file_equals_the_same_options_given_as_flags) {
    TempDir dir;
    const fs::path toml = dir / "run.toml";
    write_text(
        toml,
        "# a run\ncoast = \"" + coast +
            "\"\nhmax = \"45km\"\nhmin = \"2000m\"\n"
            "region = [-20, 40, 10, 65]\nkeep-inland-seas = true\nmin-island-area = \"1e8m2\"\n"
            "seed = 9\nformat = \"classic\"\noutput = \"x.nc\"\n");
    const fs::path ini = dir / "run.ini";
    write_text(
        ini,
        "; a run\ncoast=" + coast +
            "\nhmax=45km\nhmin=2000m\nregion=-20,40,10,65\n"
            "keep-inland-seas=true\nmin-island-area=1e8m2\nseed=9\nformat=classic\noutput=x.nc\n");
    const auto flags = globemesh::parse_mesh_args(
        std::vector<std::string>{"--coast", coast, "--hmax", "45", "--hmin", "2", "--region",
                                 "-20,40,10,65", "--keep-inland-seas", "--min-island-area", "100",
                                 "--seed", "9", "--format", "classic", "-o", "x.nc"});
    const auto from_toml =
        globemesh::parse_mesh_args(std::vector<std::string>{"--config", toml.string()});
    const auto from_ini =
        globemesh::parse_mesh_args(std::vector<std::string>{"--config", ini.string()});
    expect_same_cli(from_toml, flags);
    expect_same_cli(from_ini, flags);
    EXPECT_DOUBLE_EQ(flags.mesh.hmax_km, 45.0); // and not the default
}

TEST(Cli, flags_override_the_config_file) {
    TempDir dir;
    write_text(dir / "run.toml", "hmax = \"45km\"\nseed = 9\n");
    const auto a = globemesh::parse_mesh_args(
        std::vector<std::string>{"--config", (dir / "run.toml").string(), "--hmax", "30km"});
    EXPECT_DOUBLE_EQ(a.mesh.hmax_km, 30.0);
    EXPECT_EQ(a.mesh.seed, 9u);
}

TEST(Cli, print_config_round_trips_every_option) {
    TempDir dir;
    const auto args = every_option(dir.path().string());
    const auto original = globemesh::parse_mesh_args(args);
    auto print_args = args;
    print_args.insert(print_args.begin(), "mesh");
    print_args.push_back("--print-config");
    const Result printed = run_refused(print_args);
    ASSERT_EQ(printed.status, 0) << printed.err;
    EXPECT_EQ(printed.err, "");
    write_text(dir / "printed.toml", printed.out);
    const auto again = globemesh::parse_mesh_args(
        std::vector<std::string>{"--config", (dir / "printed.toml").string()});
    expect_same_cli(again, original);
    // Not vacuous: the values differ from the defaults.
    EXPECT_DOUBLE_EQ(original.mesh.hmax_km, 45.0);
    EXPECT_EQ(original.preview_region, (std::array<double, 4>{170, -50, -170, -10}));
    EXPECT_DOUBLE_EQ(original.mesh.wave_period_h, 12.42);
    EXPECT_DOUBLE_EQ(original.mesh.min_island_area_km2, 25.0);
    EXPECT_EQ(original.mesh.coast_rate, 0.123456789012345);
    EXPECT_NE(original.mesh.seed, globemesh::MeshOptions{}.seed);
    EXPECT_TRUE(original.mesh.keep_straits);
    EXPECT_EQ(original.mesh.min_depth_m, -2.5);
    EXPECT_EQ(original.mesh.size_regions_layer, "fine");
    // And printing the re-read configuration gives the same text.
    const Result printed_again =
        run_refused({"mesh", "--config", (dir / "printed.toml").string(), "--print-config"});
    EXPECT_EQ(printed_again.out, printed.out);
}

// --region-layer goes with --region-file, which every_option leaves out (it has --region).
TEST(Cli, print_config_round_trips_the_region_layer) {
    TempDir dir;
    const std::vector<std::string> args = {
        "--coast",   coast, "--region-file",        (dir / "r.gpkg").string(), "--region-layer",
        "north sea", "-o",  (dir / "o.nc").string()};
    std::vector<std::string> print_args = args;
    print_args.insert(print_args.begin(), "mesh");
    print_args.push_back("--print-config");
    const Result printed = run_refused(print_args);
    ASSERT_EQ(printed.status, 0) << printed.err;
    write_text(dir / "printed.toml", printed.out);
    const auto again = globemesh::parse_mesh_args(
        std::vector<std::string>{"--config", (dir / "printed.toml").string()});
    EXPECT_EQ(again.mesh.region_layer, "north sea");
    expect_same_cli(again, globemesh::parse_mesh_args(args));
}

TEST(Cli, print_config_of_defaults_reads_back_as_the_defaults) {
    TempDir dir;
    const Result printed = run_refused({"mesh", "--print-config"});
    ASSERT_EQ(printed.status, 0) << printed.err;
    write_text(dir / "d.toml", printed.out);
    SCOPED_TRACE(printed.out);
    const auto again =
        globemesh::parse_mesh_args(std::vector<std::string>{"--config", (dir / "d.toml").string()});
    globemesh::CliOptions defaults;
    defaults.mesh = cli_default_options();
    expect_same_cli(again, defaults);
}

TEST(Cli, a_missing_config_file_is_an_error_naming_it) {
    const Result r = run_refused({"mesh", "--config", "/nonexistent/run.toml"});
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("/nonexistent/run.toml"), std::string::npos) << r.err;
}

// A key that names no option would otherwise be dropped without a word: the run would mesh at
// the default size for a misspelt hmax, or for any key under a [section].
TEST(Cli, an_unknown_config_key_is_a_usage_error_naming_it) {
    TempDir dir;
    struct Case {
        std::string text, named;
    };
    for (const Case &c :
         {Case{"hmax = \"50km\"\nhmaxx = \"20km\"\n",
               "unknown key hmaxx; the keys are the long option names"},
          Case{"coast_layer = \"land\"\n", "unknown key coast_layer; did you mean coast-layer?"},
          Case{"[mesh]\nhmax = \"50km\"\n", "[mesh]: the file takes no sections"}}) {
        SCOPED_TRACE(c.text);
        write_text(dir / "run.toml", c.text);
        const Result r = run_refused({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(),
                                      "--config", (dir / "run.toml").string()});
        EXPECT_EQ(r.status, 2);
        EXPECT_EQ(count_lines(r.err), 1) << r.err;
        EXPECT_NE(r.err.find("--config " + (dir / "run.toml").string() + ": " + c.named),
                  std::string::npos)
            << r.err;
    }
}

TEST(Cli, seed_takes_every_unsigned_64_bit_number) {
    for (const std::uint64_t seed : {std::uint64_t(0), std::uint64_t(18446744073709551615u)})
        EXPECT_EQ(
            globemesh::parse_mesh_args(std::vector<std::string>{"--seed", std::to_string(seed)})
                .mesh.seed,
            seed);
}

// A file system of no blocks (proc) has 0 blocks free without being full: a failed write there
// said "(the disk is full)".
TEST(Cli, a_file_system_without_blocks_is_not_called_full) {
    EXPECT_EQ(globemesh::OutputFile::full_disk_note("/proc/o.nc"), "");
}

// ---------------------------------------------------------------------------------------------
// Errors: status, one line naming the option or file, no output, no library call

struct ErrorCase {
    std::string name;
    std::vector<std::string> args; // "{dir}" is replaced by a fresh temporary folder
    int status;
    std::string named; // text the one line must contain
};

class CliErrors : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(CliErrors, one_line_naming_the_culprit_and_no_output) {
    const ErrorCase &c = GetParam();
    TempDir dir;
    std::vector<std::string> args;
    for (auto a : c.args) {
        for (auto p = a.find("{dir}"); p != std::string::npos; p = a.find("{dir}"))
            a.replace(p, 5, dir.path().string());
        args.push_back(a);
    }
    write_text(dir / "existing.nc", "keep me");
    write_text(dir / "existing.gpkg", "keep me too");
    const Result r = run_refused(args);
    EXPECT_EQ(r.status, c.status) << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("globemesh: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.named), std::string::npos)
        << "expected '" << c.named << "' in: " << r.err;
    EXPECT_EQ(r.out, "");
    // Nothing but the files the test made is in the folder, and they are untouched.
    std::vector<std::string> files;
    for (const auto &e : fs::directory_iterator(dir.path()))
        files.push_back(e.path().filename().string());
    std::sort(files.begin(), files.end());
    EXPECT_EQ(files, (std::vector<std::string>{"existing.gpkg", "existing.nc"}));
    EXPECT_EQ(read_text(dir / "existing.nc"), "keep me");
    EXPECT_EQ(read_text(dir / "existing.gpkg"), "keep me too");
}

INSTANTIATE_TEST_SUITE_P(
    Cli, CliErrors,
    ::testing::Values(
        ErrorCase{"unknown_unit",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax", "20parsecs"},
                  2,
                  "--hmax"},
        ErrorCase{"not_a_number",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmin", "small"},
                  2,
                  "--hmin"},
        ErrorCase{"negative_size",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax", "-5km"},
                  2,
                  "--hmax"},
        ErrorCase{"hmax_beyond_an_eighth_of_the_globe",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax", "5001km"},
                  2,
                  "--hmax must be at most 5000km"},
        ErrorCase{"max_nodes_not_whole",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--max-nodes", "2.5e-1"},
                  2,
                  "--max-nodes: '2.5e-1' is not a whole number"},
        ErrorCase{
            "gpkg_to_a_device",
            {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "/dev/null", "--overwrite"},
            1,
            "/dev/null is not a regular file"},
        ErrorCase{
            "hmin_above_hmax",
            {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax", "10km", "--hmin", "20.5km"},
            2,
            "--hmin (20.5km) must not be larger than --hmax (10km)"},
        ErrorCase{"area_with_length_unit",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--min-island-area", "10km"},
                  2,
                  "--min-island-area"},
        ErrorCase{"bad_region",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--region", "0,80,10,60"},
                  2,
                  "--region"},
        ErrorCase{"region_layer_without_region_file",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--region-layer", "a"},
                  2,
                  "--region-layer names a layer of --region-file, which is not given"},
        ErrorCase{"size_regions_layer_without_file",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--size-regions-layer", "a"},
                  2,
                  "--size-regions-layer"},
        ErrorCase{"min_depth_without_bathy",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--min-depth", "5"},
                  2,
                  "--min-depth needs --bathy"},
        // The raster's other options without the raster: ignored before, without a word.
        ErrorCase{"bathy_fill_without_bathy",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--bathy-fill", "20m"},
                  2,
                  "--bathy-fill needs --bathy: it is the depth where the raster has no data"},
        ErrorCase{"depth_positive_without_bathy",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--depth-positive"},
                  2,
                  "--depth-positive needs --bathy: it says the raster stores depth"},
        ErrorCase{"bathy_srs_without_bathy",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--bathy-srs", "EPSG:4326"},
                  2,
                  "--bathy-srs needs --bathy: it is the raster's CRS"},
        ErrorCase{"bathy_band_without_bathy",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--bathy-band", "2"},
                  2,
                  "--bathy-band 2 needs --bathy: it picks a band of the raster"},
        ErrorCase{"min_depth_with_area_unit",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--min-depth", "5m2"},
                  2,
                  "--min-depth"},
        ErrorCase{"bad_format",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--format", "hdf5"},
                  2,
                  "--format"},
        ErrorCase{"bad_bathy_srs",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--bathy-srs", "EPSG:99999"},
                  2,
                  "--bathy-srs: 'EPSG:99999' is not a CRS"},
        ErrorCase{"unknown_option",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmaxx", "3"},
                  2,
                  "unknown option --hmaxx for globemesh mesh"},
        // CLI11's own words ("At Most 1 required but received 2") in globemesh's.
        ErrorCase{"option_given_twice",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax", "5km", "--hmax", "6km"},
                  2,
                  "--hmax is given 2 times; give it once"},
        ErrorCase{"option_without_value",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--hmax"},
                  2,
                  "--hmax needs a value (LENGTH)"},
        // Five values are too many values, not an option given five times.
        ErrorCase{"region_of_five_numbers",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--region", "1,2,3,4,5"},
                  2,
                  "--region takes 4 values, got 5"},
        // Given twice, its values add up: said as too many values, and to give it once.
        ErrorCase{"region_given_twice",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--region", "1,2,3,4", "--region",
                   "5,6,7,8"},
                  2,
                  "--region takes 4 values, got 8; give it once, with 4"},
        // The seed is an unsigned 64-bit number: CLI11 alone wrapped -1 and saturated 2^70.
        ErrorCase{"negative_seed",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--seed", "-1"},
                  2,
                  "--seed: '-1' is not a whole number in 0..18446744073709551615"},
        ErrorCase{
            "seed_beyond_64_bits",
            {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--seed", "18446744073709551616"},
            2,
            "--seed: '18446744073709551616' is not a whole number in 0..18446744073709551615"},
        // CLI11's "Could not convert: --smooth = abc" in globemesh's words.
        ErrorCase{"a_word_for_a_count",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--smooth", "abc"},
                  2,
                  "--smooth: 'abc' is not a value it takes (globemesh mesh --help"},
        ErrorCase{
            "a_count_past_its_range",
            {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--smooth", "1180591620717411303424"},
            2,
            "--smooth: '1180591620717411303424' is out of its range"},
        // /proc looks writable to root but takes no file: said before the run, not "disk full".
        ErrorCase{"output_in_a_folder_that_takes_no_file",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "/proc/o.gpkg"},
                  1,
                  "--gpkg: /proc/o.gpkg: the folder /proc takes no new file"},
        ErrorCase{"region_of_three_numbers",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--region", "1,2,3"},
                  2,
                  "--region needs 4 values, got 3"},
        ErrorCase{"coast_without_its_option",
                  {"mesh", coast, "-o", "{dir}/o.nc"},
                  2,
                  "unexpected argument " + coast + " for globemesh mesh (a value goes after"},
        ErrorCase{"info_unknown_option",
                  {"info", "-q", "{dir}/existing.nc"},
                  2,
                  "unknown option -q for globemesh info"},
        ErrorCase{"quiet_and_verbose",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "-q", "-v"},
                  2,
                  "--quiet"},
        ErrorCase{"no_coast", {"mesh", "-o", "{dir}/o.nc"}, 2, "--coast"},
        ErrorCase{"no_output", {"mesh", "--coast", coast}, 2, "--output"},
        ErrorCase{"same_output_twice",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "{dir}/o.nc"},
                  2,
                  "--gpkg"},
        ErrorCase{"unknown_subcommand", {"meshh", "--coast", coast}, 2, "meshh"},
        ErrorCase{"no_subcommand", {}, 2, "subcommand"},
        ErrorCase{"unknown_top_level_option", {"--hmax", "3"}, 2, "--hmax"},
        ErrorCase{"help_on_unknown_subcommand", {"help", "bogus"}, 2, "bogus"},
        ErrorCase{"missing_coast_file",
                  {"mesh", "--coast", "{dir}/nowhere.gpkg", "-o", "{dir}/o.nc"},
                  1,
                  "nowhere.gpkg"},
        ErrorCase{"missing_bathy_file",
                  {"mesh", "--coast", coast, "--bathy", "{dir}/nodem.tif", "-o", "{dir}/o.nc"},
                  1,
                  "nodem.tif"},
        ErrorCase{"output_in_missing_folder",
                  {"mesh", "--coast", coast, "-o", "{dir}/no/such/o.nc"},
                  1,
                  "--output"},
        ErrorCase{"existing_output",
                  {"mesh", "--coast", coast, "-o", "{dir}/existing.nc"},
                  1,
                  "--overwrite"},
        // Said at once, not "exists; use --overwrite" first (which would not help).
        ErrorCase{"output_is_a_folder",
                  {"mesh", "--coast", coast, "-o", "{dir}"},
                  1,
                  "is a folder; give a file name"},
        ErrorCase{"gpkg_is_a_folder",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "{dir}/"},
                  1,
                  "/ is a folder; give a file name"},
        // An output that is an input, even with --overwrite (and through another spelling):
        // the run would replace the data it reads.
        ErrorCase{"gpkg_is_the_coast",
                  {"mesh", "--coast", "{dir}/existing.gpkg", "-o", "{dir}/o.nc", "--gpkg",
                   "{dir}/./existing.gpkg", "--overwrite"},
                  2,
                  "existing.gpkg is the --coast file: the run would replace what it reads"},
        ErrorCase{"output_is_the_bathy",
                  {"mesh", "--coast", coast, "--bathy", "{dir}/existing.nc", "-o",
                   "{dir}/existing.nc", "--overwrite"},
                  2,
                  "--output"},
        ErrorCase{"triangulate_output_is_its_points",
                  {"triangulate", "{dir}/existing.nc", "-o", "{dir}/existing.nc", "--overwrite"},
                  2,
                  "is the POINTS file"},
        ErrorCase{"existing_gpkg_output",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "{dir}/existing.gpkg"},
                  1,
                  "existing.gpkg"},
        // An output named for another output's format: NetCDF under a GeoPackage's name would
        // not open in QGIS as one.
        ErrorCase{"output_named_json",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.json"},
                  2,
                  "use --report "},
        ErrorCase{"gpkg_named_nc",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--gpkg", "{dir}/p.NC"},
                  2,
                  "--output"},
        ErrorCase{"preview_named_json",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview", "{dir}/p.json"},
                  2,
                  "--preview"},
        // --preview-region is checked as --region is, and zooms only a picture.
        ErrorCase{"preview_region_south_above_north",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview", "{dir}/p.png",
                   "--preview-region=-8,56,2,49"},
                  2,
                  "--preview-region: needs -90 <= S < N"},
        ErrorCase{"preview_region_longitude_out_of_range",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview", "{dir}/p.png",
                   "--preview-region=170,-10,190,10"},
                  2,
                  "--preview-region: longitudes"},
        ErrorCase{"preview_region_of_width_zero",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview", "{dir}/p.png",
                   "--preview-region=5,40,5,50"},
                  2,
                  "--preview-region: W and E must differ"},
        ErrorCase{"preview_region_of_three_values",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview", "{dir}/p.png",
                   "--preview-region=5,40,6"},
                  2,
                  "--preview-region"},
        ErrorCase{"preview_region_without_a_picture",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--preview-region=-8,49,2,56"},
                  2,
                  "give --preview"},
        // convert takes --preview-region as mesh does (checked before IN is read).
        ErrorCase{"convert_preview_region_of_width_zero",
                  {"convert", fixture("bathy/etopo5_global_10min.nc").string(), "{dir}/p.png",
                   "--preview-region=5,40,5,50"},
                  2,
                  "--preview-region: W and E must differ"},
        ErrorCase{"convert_preview_region_without_a_picture",
                  {"convert", fixture("bathy/etopo5_global_10min.nc").string(), "{dir}/o.nc",
                   "--preview-region=-8,49,2,56"},
                  2,
                  "--preview-region zooms the PNG picture: give an OUT.png too"},
        ErrorCase{"report_named_png",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--report", "{dir}/r.png"},
                  2,
                  "--report"},
        // -o's format is its extension's or -f's: an unknown one lists the formats, and their
        // creation options are checked, all before the run.
        ErrorCase{"output_of_unknown_extension",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.dat"},
                  2,
                  "no format has the extension .dat; the formats are UGRID (.nc, .nc4), GPKG "
                  "(.gpkg), PNG (.png)"},
        ErrorCase{"triangulate_output_of_unknown_extension",
                  {"triangulate", fixture("points/stations.csv").string(), "-o", "{dir}/t.dat"},
                  2,
                  "the formats are UGRID"},
        // triangulate has no --bathy: the message says what gives depths instead.
        ErrorCase{"triangulate_to_a_format_that_needs_depths",
                  {"triangulate", fixture("points/stations.csv").string(), "-f", "fesom2", "-o",
                   "{dir}/fesom"},
                  2,
                  "FESOM2 needs depths; points have none: mesh with a bathymetry (globemesh mesh "
                  "--bathy) for it"},
        ErrorCase{"unknown_output_format",
                  {"mesh", "--coast", coast, "-f", "NOSUCH", "-o", "{dir}/o.dat"},
                  2,
                  "-f/--output-format NOSUCH: no such format; the formats are UGRID"},
        ErrorCase{"output_format_for_two_outputs",
                  {"mesh", "--coast", coast, "-f", "GPKG", "-o", "{dir}/a", "-o", "{dir}/b"},
                  2,
                  "-f/--output-format names the format of one -o file"},
        ErrorCase{"same_file_by_output_and_gpkg",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.gpkg", "--gpkg", "{dir}/o.gpkg"},
                  2,
                  "name the same file"},
        ErrorCase{"creation_option_no_output_takes",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.gpkg", "--co", "FORMAT=NC2"},
                  2,
                  "--co FORMAT=NC2: none of the outputs takes the creation option FORMAT (UGRID"},
        ErrorCase{"creation_option_value",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--co", "format=nc3"},
                  2,
                  "UGRID creation option FORMAT=nc3: use FORMAT=NC4 or NC2"},
        ErrorCase{"creation_option_without_value",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--co", "FORMAT"},
                  2,
                  "--co FORMAT: give KEY=VALUE"},
        ErrorCase{"classic_without_a_ugrid_output",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.gpkg", "--format", "classic"},
                  2,
                  "--format classic (FORMAT=NC2): none of the outputs"},
        ErrorCase{"report_in_missing_folder",
                  {"mesh", "--coast", coast, "-o", "{dir}/o.nc", "--report", "{dir}/x/r.json"},
                  1,
                  "--report"},
        ErrorCase{"triangulate_missing_points",
                  {"triangulate", "{dir}/none.csv", "-o", "{dir}/t.nc"},
                  1,
                  "none.csv"},
        ErrorCase{"triangulate_without_output",
                  {"triangulate", fixture("points/stations.csv").string()},
                  2,
                  "--output"},
        ErrorCase{
            "triangulate_existing_output",
            {"triangulate", fixture("points/stations.csv").string(), "-o", "{dir}/existing.nc"},
            1,
            "existing.nc"},
        ErrorCase{"info_missing_file", {"info", "{dir}/none.nc"}, 1, "none.nc"},
        ErrorCase{"info_without_file", {"info"}, 2, "MESH"}),
    [](const auto &info) { return info.param.name; });

TEST(Cli, the_config_file_is_not_an_output) {
    TempDir dir;
    write_text(dir / "run.toml", "hmax = \"500km\"\n");
    const Result r = run_refused({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(),
                                  "--config", (dir / "run.toml").string(), "--report",
                                  (dir / "run.toml").string(), "--overwrite"});
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("run.toml is the --config file"), std::string::npos) << r.err;
    EXPECT_EQ(read_text(dir / "run.toml"), "hmax = \"500km\"\n");
    EXPECT_FALSE(fs::exists(dir / "o.nc"));
}

TEST(Cli, the_folder_named_in_a_missing_folder_error_is_the_real_one) {
    TempDir dir;
    const Result r = run_refused({"mesh", "--coast", coast, "-o", (dir / "no/such/o.nc").string()});
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find((dir / "no/such").string()), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "no"));
}

TEST(Cli, errors_of_the_library_map_to_their_exit_status) {
    TempDir dir;
    const std::vector<std::string> args = {"mesh", "--coast", coast, "-o", (dir / "o.nc").string(),
                                           "-q"};
    auto with_error = [&](std::function<void()> thrower) {
        RefusingLibrary refusing;
        auto lib = refusing.lib();
        lib.mesh_ocean = [thrower](auto &&...) -> globemesh::OceanMesh {
            thrower();
            return {};
        };
        return run(args, lib);
    };
    const Result usage =
        with_error([] { throw globemesh::UsageError("--coast-layer: no layer 'x'"); });
    EXPECT_EQ(usage.status, 2);
    EXPECT_EQ(usage.err, "globemesh: --coast-layer: no layer 'x'\n");
    const Result data =
        with_error([] { throw globemesh::DataError("--region: no ocean in the region"); });
    EXPECT_EQ(data.status, 1);
    EXPECT_EQ(data.err, "globemesh: --region: no ocean in the region\n");
    // The library names options by their MeshOptions field; the command line says its flags.
    using globemesh::option;
    const Result named = with_error([] {
        throw globemesh::DataError("at " + option("hmax_km") + " 1 km: raise " + option("hmax_km") +
                                   " or " + option("max_memory_bytes"));
    });
    EXPECT_EQ(named.status, 1);
    EXPECT_EQ(named.err, "globemesh: at --hmax 1 km: raise --hmax or --max-memory\n");
    const Result io = with_error([] { throw globemesh::IoError("cannot read x.gpkg"); });
    EXPECT_EQ(io.status, 1);
    const Result internal = with_error([] { throw std::out_of_range("vector::at\nsecond line"); });
    EXPECT_EQ(internal.status, 1);
    EXPECT_EQ(internal.err, "globemesh: internal error: vector::at; second line\n");
    for (const auto *r : {&usage, &data, &io, &internal})
        EXPECT_EQ(r->out, "");
    EXPECT_FALSE(fs::exists(dir / "o.nc"));
}

// ---------------------------------------------------------------------------------------------
// Signals

// Ctrl-C, `kill` (and a batch scheduler's time limit: SIGTERM) and a closed terminal (SIGHUP)
// each cancel the run the same way; any but Ctrl-C is named in the message.
TEST(Cli, each_cancelling_signal_stops_the_run_leaves_no_output_and_restores_the_handler) {
    for (const auto &[signal, message] :
         {std::pair{SIGINT, "globemesh: cancelled, no output written\n"},
          std::pair{SIGTERM, "globemesh: cancelled by SIGTERM, no output written\n"},
          std::pair{SIGHUP, "globemesh: cancelled by SIGHUP, no output written\n"}}) {
        SCOPED_TRACE(signal);
        TempDir dir;
        struct sigaction before {};
        sigaction(signal, nullptr, &before);
        RefusingLibrary refusing;
        auto lib = refusing.lib();
        bool handled_inside = false;
        lib.mesh_ocean = [&, signal = signal](const globemesh::MeshOptions &,
                                              const globemesh::Progress &progress,
                                              globemesh::StageTimings *) -> globemesh::OceanMesh {
            globemesh::report(progress, 0.1, "refine");
            std::raise(signal); // our handler only records it, so the test process survives
            handled_inside = true;
            globemesh::report(progress, 0.2, "refine"); // throws Cancelled
            ADD_FAILURE() << "the progress callback did not cancel the run";
            return {};
        };
        const Result r = run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "-q"}, lib);
        EXPECT_TRUE(handled_inside);
        EXPECT_EQ(r.status, 1);
        EXPECT_EQ(r.err, message);
        EXPECT_EQ(r.out, "");
        EXPECT_TRUE(fs::is_empty(dir.path()));
        struct sigaction after {};
        sigaction(signal, nullptr, &after);
        EXPECT_EQ(after.sa_handler, before.sa_handler);
    }
}

// ---------------------------------------------------------------------------------------------
// Progress

TEST(Cli, progress_is_gdal_style_on_stderr_and_silent_with_quiet) {
    TempDir dir;
    auto lib_with_progress = [](RefusingLibrary &refusing) {
        auto lib = refusing.lib();
        lib.mesh_ocean = [](const globemesh::MeshOptions &, const globemesh::Progress &progress,
                            globemesh::StageTimings *) -> globemesh::OceanMesh {
            for (int i = 0; i <= 10; ++i)
                globemesh::report(progress, i / 10.0, i < 5 ? "size_field" : "refine");
            throw globemesh::DataError("stop here");
        };
        return lib;
    };
    RefusingLibrary r1, r2, r3;
    // The mesh has a share of the run's one progress line; the line ends before the error.
    const Result normal =
        run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string()}, lib_with_progress(r1));
    EXPECT_TRUE(regex_search(normal.err, R"(^0(\.\.\.[1-9]0)+\.*\nglobemesh: stop here\n$)"))
        << normal.err;
    EXPECT_EQ(normal.err.find("100"), std::string::npos) << normal.err;
    EXPECT_EQ(normal.out, "");
    // An error before the run made any progress stands alone: no "0" before it.
    RefusingLibrary r0;
    auto early = r0.lib();
    early.mesh_ocean = [](const globemesh::MeshOptions &, const globemesh::Progress &progress,
                          globemesh::StageTimings *) -> globemesh::OceanMesh {
        globemesh::report(progress, 0.0, "reading coast");
        globemesh::report(progress, 0.001, "reading coast");
        throw globemesh::DataError("--coast x.gpkg: several layers");
    };
    EXPECT_EQ(run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string()}, early).err,
              "globemesh: --coast x.gpkg: several layers\n");
    const Result quiet = run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "--quiet"},
                             lib_with_progress(r2));
    EXPECT_EQ(quiet.err, "globemesh: stop here\n");
    const Result verbose =
        run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "--verbose"},
            lib_with_progress(r3));
    EXPECT_NE(verbose.err.find("[size_field] 0"), std::string::npos) << verbose.err;
    EXPECT_NE(verbose.err.find("\n[refine] "), std::string::npos) << verbose.err;
}

// One progress line for the whole run: the mesh and each output report into their share of it,
// and it reaches "100 - done." once, when the last output is written.
TEST(Cli, the_mesh_and_its_outputs_share_one_progress_line) {
    TempDir dir;
    RefusingLibrary refusing;
    auto lib = refusing.lib();
    std::vector<std::string> order;
    auto report_all = [&](const globemesh::Progress &p, const char *stage) {
        order.push_back(stage);
        for (int i = 0; i <= 20; ++i)
            globemesh::report(p, i / 20.0, stage);
    };
    lib.mesh_ocean = [&](const globemesh::MeshOptions &, const globemesh::Progress &p,
                         globemesh::StageTimings *) {
        report_all(p, "refine");
        return globemesh::OceanMesh{};
    };
    lib.compute_stats = [](const globemesh::Mesh &) { return globemesh::MeshStats{}; };
    row(lib, "UGRID").write = [&](const globemesh::Mesh &, const fs::path &path,
                                  const globemesh::WriteOptions &o) {
        report_all(o.progress, "write_ugrid");
        write_text(path, "ugrid");
    };
    row(lib, "GPKG").write = [&](const globemesh::Mesh &, const fs::path &path,
                                 const globemesh::WriteOptions &o) {
        report_all(o.progress, "write_gpkg");
        write_text(path, "gpkg");
    };
    const Result r = run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "--gpkg",
                          (dir / "o.gpkg").string()},
                         lib);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(order, (std::vector<std::string>{"refine", "write_ugrid", "write_gpkg"}));
    EXPECT_EQ(r.err, "0...10...20...30...40...50...60...70...80...90...100 - done.\n");
    // Cancelled from the terminal while an output is written: no file left.
    row(lib, "UGRID").write = [&](const globemesh::Mesh &, const fs::path &,
                                  const globemesh::WriteOptions &o) {
        globemesh::report(o.progress, 0.1, "write_ugrid");
        std::raise(SIGINT);
        globemesh::report(o.progress, 0.2, "write_ugrid"); // throws Cancelled
    };
    const Result cancelled =
        run({"mesh", "--coast", coast, "-o", (dir / "p.nc").string(), "-q"}, lib);
    EXPECT_EQ(cancelled.status, 1);
    EXPECT_EQ(cancelled.err, "globemesh: cancelled, no output written\n");
    EXPECT_FALSE(fs::exists(dir / "p.nc"));
}

// ---------------------------------------------------------------------------------------------
// Help and version

TEST(Cli, version_prints_the_project_version) {
    // The version in the top CMakeLists.txt, read independently of the build's definition.
    const std::string cmake = read_text(fs::path(GLOBEMESH_FIXTURES_DIR) / ".." / "CMakeLists.txt");
    std::vector<std::string> m;
    ASSERT_TRUE(regex_search(cmake, R"(project\(globemesh VERSION ([0-9.]+))", &m));
    for (const auto &args :
         {std::vector<std::string>{"--version"}, std::vector<std::string>{"mesh", "--version"}}) {
        const Result r = run_refused(args);
        EXPECT_EQ(r.status, 0);
        EXPECT_EQ(r.out.rfind("globemesh " + m[1] + " ", 0), 0u) << r.out;
        EXPECT_EQ(count_lines(r.out), 1);
        EXPECT_EQ(r.err, "");
    }
}

TEST(Cli, help_lists_the_subcommands) {
    for (const auto &args :
         {std::vector<std::string>{"help"}, std::vector<std::string>{"--help"}}) {
        const Result r = run_refused(args);
        EXPECT_EQ(r.status, 0);
        EXPECT_EQ(r.err, "");
        for (const char *sub : {"mesh", "triangulate", "convert", "info", "help"})
            EXPECT_TRUE(regex_search(r.out, std::string("\\n\\s+") + sub + "\\s")) << sub << " in\n"
                                                                                   << r.out;
    }
}

TEST(Cli, help_of_a_subcommand_shows_its_options_and_defaults) {
    const Result a = run_refused({"help", "mesh"});
    const Result b = run_refused({"mesh", "--help"});
    EXPECT_EQ(a.status, 0);
    EXPECT_EQ(b.status, 0);
    EXPECT_EQ(a.out, b.out);
    EXPECT_TRUE(regex_search(a.out, R"(--hmax LENGTH=100\s)")) << a.out;
    EXPECT_TRUE(regex_search(a.out, R"(--grade G=0\.15\s)")) << a.out;
    const Result t = run_refused({"triangulate", "--help"});
    EXPECT_NE(t.out.find("POINTS"), std::string::npos);
    const Result i = run_refused({"info", "--help"});
    EXPECT_NE(i.out.find("--json"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The man page documents exactly the options --help lists

namespace {

const fs::path man_page = fs::path(GLOBEMESH_FIXTURES_DIR) / ".." / "man" / "globemesh.1";

std::set<std::string> long_options(const std::string &text) {
    const auto names =
        globemesh::test::regex_all(text, R"((^|[^A-Za-z0-9-])(--[a-z][a-z0-9-]*))", 2);
    return {names.begin(), names.end()};
}

std::string man_text_plain() {
    // man(7) writes a minus as "\-": turn it back into "-" before looking for options.
    return regex_replace(read_text(man_page), R"(\\-)", "-");
}

} // namespace

TEST(Cli, every_option_in_help_is_in_the_man_page) {
    ASSERT_TRUE(fs::exists(man_page)) << man_page;
    const auto documented = long_options(man_text_plain());
    for (const char *sub : {"mesh", "triangulate", "convert", "info"}) {
        const Result r = run_refused({sub, "--help"});
        const auto listed = long_options(r.out);
        EXPECT_GT(listed.size(), 2u) << sub;
        for (const auto &o : listed)
            EXPECT_TRUE(documented.count(o)) << o << " of " << sub << " is not in " << man_page;
    }
}

TEST(Cli, every_option_in_the_man_page_is_in_help) {
    std::set<std::string> listed = long_options(run_refused({"--help"}).out);
    for (const char *sub : {"mesh", "triangulate", "convert", "info"})
        for (const auto &o : long_options(run_refused({sub, "--help"}).out))
            listed.insert(o);
    const auto documented = long_options(man_text_plain());
    EXPECT_GT(documented.size(), 30u);
    for (const auto &o : documented)
        EXPECT_TRUE(listed.count(o)) << o << " is in the man page but in no --help";
}

// ---------------------------------------------------------------------------------------------
// check_mesh

TEST(Cli, check_mesh_accepts_the_octahedron_and_names_broken_faces) {
    globemesh::Mesh m;
    m.nodes = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.faces = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4},
               {1, 0, 5}, {2, 1, 5}, {3, 2, 5}, {0, 3, 5}};
    EXPECT_TRUE(globemesh::check_mesh(m).empty());
    auto flipped = m;
    std::swap(flipped.faces[2][0], flipped.faces[2][1]);
    const auto problems = globemesh::check_mesh(flipped);
    ASSERT_FALSE(problems.empty());
    EXPECT_NE(problems.front().find("face 2"), std::string::npos) << problems.front();
    auto open = m; // drop the south half: 4 boundary edges, which must be listed
    open.faces.resize(4);
    EXPECT_FALSE(globemesh::check_mesh(open).empty());
    for (int k = 0; k < 4; ++k)
        open.boundary.push_back(
            {globemesh::NodeIndex((k + 1) % 4), globemesh::NodeIndex(k), globemesh::EdgeTag::open});
    // Faces (k, k+1, 4) leave the edge k -> k+1 open; the list above has them reversed.
    EXPECT_FALSE(globemesh::check_mesh(open).empty());
    for (auto &e : open.boundary)
        std::swap(e.a, e.b);
    EXPECT_TRUE(globemesh::check_mesh(open).empty());
}

// ---------------------------------------------------------------------------------------------
// What run_cli does with a finished mesh: outputs, timings, report, and clean-up on failure.
// The library is replaced by fakes that write small files, so these test the CLI's own logic.

namespace {

struct FakeRun {
    std::vector<std::string> written; // paths the fake writers were asked for, in order
    std::string configuration;        // the globemesh_configuration attribute given to write_ugrid
    bool fail_gpkg = false;
    int ugrid_ms = 0, gpkg_ms = 0; // how long the fake writers take
    globemesh::CliLibrary lib() {
        globemesh::CliLibrary l;
        l.mesh_ocean = [](const globemesh::MeshOptions &, const globemesh::Progress &p,
                          globemesh::StageTimings *t) {
            globemesh::report(p, 0.5, "refine");
            t->add_input("read_coast", 0.5); // a stage that reads an input
            t->add("refine", 1.25);
            t->add("improve", 0.25);
            globemesh::Mesh m;
            m.nodes = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
            m.faces = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4},
                       {1, 0, 5}, {2, 1, 5}, {3, 2, 5}, {0, 3, 5}};
            globemesh::OceanMesh run;
            run.mesh = std::move(m);
            return run;
        };
        l.triangulate_file = [](auto &&...) -> globemesh::Mesh {
            throw std::logic_error("not here");
        };
        l.writers = globemesh::writers();
        row(l, "UGRID").write = [this](const globemesh::Mesh &m, const fs::path &p,
                                       const globemesh::WriteOptions &o) {
            EXPECT_NE(o.history.find("globemesh mesh --coast"), std::string::npos) << o.history;
            for (const auto &[key, value] : m.attributes)
                if (key == "globemesh_configuration")
                    configuration = value;
            globemesh::OutputFile::write_text(p, "nc", o.overwrite); // as the real writers do
            std::this_thread::sleep_for(std::chrono::milliseconds(ugrid_ms));
            written.push_back(p.string());
        };
        row(l, "GPKG").write = [this](const globemesh::Mesh &, const fs::path &p,
                                      const globemesh::WriteOptions &o) {
            if (fail_gpkg)
                throw globemesh::IoError("cannot write " + p.string() + " (disk full)");
            globemesh::OutputFile::write_text(p, "gpkg", o.overwrite);
            std::this_thread::sleep_for(std::chrono::milliseconds(gpkg_ms));
            written.push_back(p.string());
        };
        row(l, "PNG").write = [this](const globemesh::Mesh &, const fs::path &p,
                                     const globemesh::WriteOptions &o) {
            globemesh::OutputFile::write_text(p, "png", o.overwrite);
            written.push_back(p.string());
        };
        l.read_ugrid = [](auto &&...) -> globemesh::Mesh { throw std::logic_error("not here"); };
        l.compute_stats = [](const globemesh::Mesh &m) {
            globemesh::MeshStats s;
            s.nodes = m.nodes.size();
            s.faces = m.faces.size();
            s.quality_histogram[9] = m.faces.size();
            return s;
        };
        return l;
    }
};

} // namespace

TEST(Cli, timings_and_report_hold_the_stages_and_the_mesh_total) {
    TempDir dir;
    FakeRun fake;
    const Result r =
        run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "--timings",
             (dir / "t.json").string(), "--report", (dir / "r.json").string(), "-q", "--check"},
            fake.lib());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const std::string t = read_text(dir / "t.json");
    // Issue 4's "mesh" key: every stage but the reading, 1.25 + 0.25 s here.
    EXPECT_TRUE(regex_search(
        t,
        R"(^\{"stages": \{"read_coast": 0\.5, "refine": 1\.25, "improve": 0\.25, "mesh": 1\.5, "statistics": [0-9.e-]+, "write_ugrid": [0-9.e-]+, "write": [0-9.e-]+, "total": [0-9.e-]+\}\}\n$)"))
        << t;
    const std::string report = read_text(dir / "r.json");
    EXPECT_NE(report.find("\"nodes\": 6"), std::string::npos) << report;
    EXPECT_NE(report.find("\"histogram\": [0, 0, 0, 0, 0, 0, 0, 0, 0, 8]"), std::string::npos)
        << report;
    EXPECT_TRUE(regex_search(report, R"("peak_memory_bytes": [1-9][0-9]{5,})")) << report;
    EXPECT_TRUE(regex_search(r.out, R"(nodes\s+6\n)")) << r.out;
    EXPECT_TRUE(regex_search(r.out, R"(faces\s+8\n)")) << r.out;
    std::set<std::string> names;
    for (const auto &e : fs::directory_iterator(dir.path()))
        names.insert(e.path().filename().string());
    EXPECT_EQ(names, (std::set<std::string>{"o.nc", "t.json", "r.json"})); // no temporary files
}

TEST(Cli, timings_name_each_format_as_a_stage_and_add_the_total) {
    TempDir dir;
    FakeRun fake;
    fake.ugrid_ms = 30;
    fake.gpkg_ms = 80;
    const Result r =
        run({"mesh", "--coast", coast, "-o", (dir / "a.nc").string(), "-o", (dir / "b.nc").string(),
             "--gpkg", (dir / "o.gpkg").string(), "--timings", (dir / "t.json").string(), "-q"},
            fake.lib());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string t = read_text(dir / "t.json");
    EXPECT_EQ(
        regex_all(t, R"x("([a-z_]+)": )x", 1),
        (std::vector<std::string>{"stages", "read_coast", "refine", "improve", "mesh", "statistics",
                                  "write_ugrid", "write_gpkg", "write", "total"}))
        << t;
    auto seconds = [&t](const std::string &stage) {
        const auto v = regex_all(t, "\"" + stage + R"(": ([0-9.e-]+))", 1);
        return v.size() == 1 ? std::stod(v[0]) : -1.0;
    };
    // Two UGRID outputs of 30 ms add up in one stage; the GeoPackage's 80 ms are its own.
    EXPECT_GE(seconds("write_ugrid"), 0.06) << t;
    EXPECT_GE(seconds("write_gpkg"), 0.08) << t;
    EXPECT_GE(seconds("write"), seconds("write_ugrid") + seconds("write_gpkg")) << t;
    // The total is measured (the fake mesher's 2 s are only reported): at least the writing.
    EXPECT_GE(seconds("total"), seconds("write")) << t;
    EXPECT_LT(seconds("total"), 1.5) << t;
    EXPECT_TRUE(regex_search(r.out, R"(\n\s+write_ugrid [0-9.]+\n\s+write_gpkg [0-9.]+\n)"))
        << r.out;
    EXPECT_TRUE(regex_search(r.out, R"(\n\s+total [0-9.]+\npeak memory )")) << r.out;
}

TEST(Cli, a_failing_writer_leaves_none_of_the_run_outputs) {
    TempDir dir;
    FakeRun fake;
    fake.fail_gpkg = true;
    const Result r = run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "--gpkg",
                          (dir / "o.gpkg").string(), "--report", (dir / "r.json").string(), "-q"},
                         fake.lib());
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "globemesh: cannot write " + (dir / "o.gpkg").string() + " (disk full)\n");
    EXPECT_EQ(fake.written, std::vector<std::string>{(dir / "o.nc").string()}); // it was written...
    EXPECT_TRUE(fs::is_empty(dir.path()));                                      // ...and removed
    EXPECT_EQ(r.out, "");
}

// The outputs appear together: none under its own name while another is still being written,
// all of them once the run succeeds, and a stale file of one kept out by the final check.
TEST(Cli, the_outputs_appear_together_at_the_end_of_the_run) {
    TempDir dir;
    FakeRun fake;
    std::vector<std::set<std::string>> seen; // the folder as each later writer starts
    auto lib = fake.lib();
    const auto gpkg = row(lib, "GPKG").write;
    const auto preview = row(lib, "PNG").write;
    auto names = [&] {
        std::set<std::string> n;
        for (const auto &e : fs::directory_iterator(dir.path()))
            n.insert(e.path().filename().string());
        return n;
    };
    row(lib, "GPKG").write = [&](const globemesh::Mesh &m, const fs::path &p,
                                 const globemesh::WriteOptions &o) {
        seen.push_back(names());
        gpkg(m, p, o);
    };
    row(lib, "PNG").write = [&](const globemesh::Mesh &m, const fs::path &p,
                                const globemesh::WriteOptions &o) {
        seen.push_back(names());
        preview(m, p, o);
    };
    const std::vector<std::string> args = {"mesh",
                                           "--coast",
                                           coast,
                                           "-o",
                                           (dir / "o.nc").string(),
                                           "--gpkg",
                                           (dir / "o.gpkg").string(),
                                           "--preview",
                                           (dir / "o.png").string(),
                                           "--report",
                                           (dir / "r.json").string(),
                                           "-q"};
    const Result r = run(args, lib);
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_EQ(seen.size(), 2u);
    for (const auto &before : seen) {
        EXPECT_EQ(before.count("o.nc"), 0u); // waiting under a hidden temporary name
        EXPECT_EQ(before.size(), &before == &seen[0] ? 1u : 2u);
        for (const auto &name : before)
            EXPECT_EQ(name[0], '.') << name;
    }
    EXPECT_EQ(names(), (std::set<std::string>{"o.nc", "o.gpkg", "o.png", "r.json"}));
    EXPECT_EQ(read_text(dir / "o.png"), "png");
    // A file that appears under one of the names during the run stops it before any is placed.
    for (const char *name : {"o.nc", "o.gpkg", "o.png", "r.json"})
        fs::remove(dir / name);
    row(lib, "PNG").write = [&](const globemesh::Mesh &m, const fs::path &p,
                                const globemesh::WriteOptions &o) {
        write_text(dir / "o.gpkg", "someone else's");
        preview(m, p, o);
    };
    const Result clash = run(args, lib);
    EXPECT_EQ(clash.status, 1);
    EXPECT_NE(clash.err.find("o.gpkg already exists"), std::string::npos) << clash.err;
    EXPECT_EQ(names(), (std::set<std::string>{"o.gpkg"}));
    EXPECT_EQ(read_text(dir / "o.gpkg"), "someone else's");
}

// A format is a row of the writers table: with one more row, -o picks it by its extension and -f
// by its name, --co reaches it, it has its share of the progress line, and the help, the summary
// and the report list it, with nothing else of the command line changed.
TEST(Cli, a_row_added_to_the_writers_table_is_an_output_format_of_the_command_line) {
    TempDir dir;
    FakeRun fake;
    auto lib = fake.lib();
    std::vector<std::pair<std::string, std::string>> wrote; // file, its FLAVOUR creation option
    bool stop_halfway = false;
    globemesh::Writer toy;
    toy.name = "TOY";
    toy.long_name = "toy mesh";
    toy.extensions = {".toy"};
    toy.report_key = "toy";
    toy.progress_weight = 2;
    toy.creation_options = {{"FLAVOUR", {"SWEET", "SOUR"}, "the taste"}};
    toy.write = [&](const globemesh::Mesh &m, const fs::path &p, const globemesh::WriteOptions &o) {
        globemesh::report(o.progress, 0.5, "write_toy");
        if (stop_halfway)
            throw globemesh::IoError("the toy stops here");
        globemesh::OutputFile::write_text(p, std::to_string(m.faces.size()) + " faces\n",
                                          o.overwrite);
        wrote.emplace_back(p.filename().string(),
                           globemesh::creation_option(o.creation_options, "FLAVOUR", "-"));
    };
    lib.writers.push_back(toy);
    const std::string a = (dir / "a.nc").string(), b = (dir / "b.toy").string(),
                      c = (dir / "c.dat").string(), report = (dir / "r.json").string();
    const Result r = run({"mesh", "--coast", coast, "-o", a, "-o", b, "--co", "flavour=sour",
                          "--report", report, "-q"},
                         lib);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_text(dir / "b.toy"), "8 faces\n");
    EXPECT_NE(r.out.find("wrote             " + a + ", " + b + ", " + report + "\n"),
              std::string::npos)
        << r.out;
    EXPECT_NE(
        read_text(report).find("\"outputs\": {\"netcdf\": \"" + a + "\", \"toy\": \"" + b + "\"}"),
        std::string::npos)
        << read_text(report);
    const Result f = run({"mesh", "--coast", coast, "-f", "toy", "-o", c, "-q"}, lib);
    ASSERT_EQ(f.status, 0) << f.err;
    EXPECT_EQ(wrote, (std::vector<std::pair<std::string, std::string>>{{"b.toy", "SOUR"},
                                                                       {"c.dat", "-"}}));
    EXPECT_EQ(fake.written, (std::vector<std::string>{a})); // UGRID for a.nc only
    // Its share of the line: the mesh 1, UGRID 1.5, the toy 2; half of the toy is at 7/9 of the
    // line, tick 31 of 40 ("70..."), where its error ends the line.
    stop_halfway = true;
    const Result half = run(
        {"mesh", "--coast", coast, "-o", (dir / "d.nc").string(), "-o", (dir / "d.toy").string()},
        lib);
    EXPECT_EQ(half.status, 1);
    EXPECT_TRUE(regex_search(
        half.err, R"(^0\.\.\.10(\.\.\.[2-7]0)+\.\.\.\nglobemesh: the toy stops here\n$)"))
        << half.err;
    EXPECT_FALSE(fs::exists(dir / "d.nc"));
    const Result help = run({"mesh", "--help"}, lib);
    EXPECT_NE(help.out.find(", TOY; default: from its extension"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find(", .toy TOY)"), std::string::npos) << help.out;
    // What a format needs is checked before the run: a toy that needs depths, and no --bathy.
    RefusingLibrary refusing;
    auto refused = refusing.lib();
    toy.needs = globemesh::needs_depth;
    refused.writers.push_back(toy);
    const Result depth = run({"mesh", "--coast", coast, "-o", (dir / "e.toy").string()}, refused);
    EXPECT_EQ(depth.status, 2);
    EXPECT_EQ(depth.err, "globemesh: --output " + (dir / "e.toy").string() +
                             ": TOY needs depths; give a bathymetry (--bathy)\n");
    EXPECT_EQ(refusing.calls, 0);
}

// A failure of the library after a cancelling signal is the run stopping (an interrupted GEOS or
// GDAL call fails in its own words): reported as the cancellation.
TEST(Cli, an_error_after_a_signal_is_reported_as_the_cancellation) {
    TempDir dir;
    FakeRun fake;
    auto lib = fake.lib();
    lib.mesh_ocean = [](const globemesh::MeshOptions &, const globemesh::Progress &,
                        globemesh::StageTimings *) -> globemesh::OceanMesh {
        std::raise(SIGTERM);
        throw globemesh::DataError(
            "coast: GEOS failed to dissolve the land polygons: Interrupted!");
    };
    const Result r = run({"mesh", "--coast", coast, "-o", (dir / "o.nc").string(), "-q"}, lib);
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "globemesh: cancelled by SIGTERM, no output written\n");
    // The next run in the process starts afresh: its own error is its own.
    const Result next =
        run({"mesh", "--coast", coast, "-o", (dir / "x" / "o.nc").string(), "-q"}, lib);
    EXPECT_EQ(next.status, 1);
    EXPECT_NE(next.err.find("does not exist"), std::string::npos) << next.err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Cli, the_mesh_carries_a_configuration_that_remakes_the_run) {
    TempDir dir;
    FakeRun fake;
    const std::vector<std::string> args = {"--coast", coast,   "-o",       (dir / "o.nc").string(),
                                           "--hmax",  "3500m", "--region", "170,-50,-170,-30",
                                           "--seed",  "77",    "-q"};
    std::vector<std::string> with_sub = args;
    with_sub.insert(with_sub.begin(), "mesh");
    const Result r = run(with_sub, fake.lib());
    ASSERT_EQ(r.status, 0) << r.err;
    ASSERT_FALSE(fake.configuration.empty());
    write_text(dir / "from_file.toml", fake.configuration);
    expect_same_cli(globemesh::parse_mesh_args(
                        std::vector<std::string>{"--config", (dir / "from_file.toml").string()}),
                    globemesh::parse_mesh_args(args));
}

TEST(Cli, info_reads_back_a_written_octahedron) {
    TempDir dir;
    globemesh::Mesh m;
    m.nodes = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    m.faces = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4},
               {1, 0, 5}, {2, 1, 5}, {3, 2, 5}, {0, 3, 5}};
    globemesh::write_ugrid(m, dir / "octa.nc");
    RefusingLibrary refusing;
    auto lib = refusing.lib();
    lib.read_ugrid = [](const fs::path &p) { return globemesh::read_ugrid(p); };
    lib.compute_stats = [](const globemesh::Mesh &mesh) { return globemesh::compute_stats(mesh); };
    const Result json = run({"info", (dir / "octa.nc").string(), "--json"}, lib);
    ASSERT_EQ(json.status, 0) << json.err;
    EXPECT_EQ(json.err, "");
    // Closed form: V - E + F = 6 - 12 + 8 = 2; the faces tile the sphere, area 4 pi R^2.
    EXPECT_NE(json.out.find("\"nodes\": 6,"), std::string::npos) << json.out;
    EXPECT_NE(json.out.find("\"faces\": 8,"), std::string::npos) << json.out;
    EXPECT_NE(json.out.find("\"edges\": 12,"), std::string::npos) << json.out;
    EXPECT_NE(json.out.find("\"histogram\": [0, 0, 0, 0, 0, 0, 0, 0, 0, 8]"), std::string::npos)
        << json.out;
    std::vector<std::string> area;
    ASSERT_TRUE(regex_search(json.out, R"("area_km2": ([0-9.e+]+))", &area));
    const double r = globemesh::earth_radius_km;
    EXPECT_NEAR(std::stod(area[1]), 4 * M_PI * r * r, 1e-6 * 4 * M_PI * r * r);
    // Every edge is a quarter great circle: pi/2 R.
    std::vector<std::string> edge;
    ASSERT_TRUE(regex_search(json.out, R"("edge_km": \{"min": ([0-9.e+]+))", &edge));
    EXPECT_NEAR(std::stod(edge[1]), M_PI / 2 * r, 1e-6 * r);
    const Result text = run({"info", (dir / "octa.nc").string()}, lib);
    ASSERT_EQ(text.status, 0) << text.err;
    EXPECT_TRUE(regex_search(text.out, R"(faces\s+8\n)")) << text.out;
    EXPECT_TRUE(regex_search(text.out, R"(\[0\.9, 1\.0\]\s+8 100\.0% #+\n)")) << text.out;
}

// ---------------------------------------------------------------------------------------------
// Options whose effect only the data shows, through the real library on real data (ETOPO5 and
// Natural Earth), each run in well under a second; the files are read back with netCDF-C, not
// with globemesh's reader.

namespace {

/// A variable of a NetCDF file as doubles, read with netCDF-C; empty (and a test failure) when
/// it is not there.
std::vector<double> nc_doubles(const fs::path &file, const char *name) {
    int nc = -1, var = -1, ndims = 0, dim = -1;
    std::size_t n = 0;
    if (nc_open(file.c_str(), NC_NOWRITE, &nc) != NC_NOERR) {
        ADD_FAILURE() << "netCDF cannot open " << file;
        return {};
    }
    std::vector<double> values;
    if (nc_inq_varid(nc, name, &var) == NC_NOERR && nc_inq_varndims(nc, var, &ndims) == NC_NOERR &&
        ndims == 1 && nc_inq_vardimid(nc, var, &dim) == NC_NOERR &&
        nc_inq_dimlen(nc, dim, &n) == NC_NOERR) {
        values.resize(n);
        if (nc_get_var_double(nc, var, values.data()) != NC_NOERR)
            values.clear();
    }
    if (values.empty())
        ADD_FAILURE() << "no 1-D variable " << name << " in " << file;
    nc_close(nc);
    return values;
}

/// A text attribute of a variable, read with netCDF-C ("" when missing).
std::string nc_text(const fs::path &file, const char *var_name, const char *attribute) {
    int nc = -1, var = -1;
    std::size_t n = 0;
    std::string text;
    if (nc_open(file.c_str(), NC_NOWRITE, &nc) != NC_NOERR)
        return text;
    if (nc_inq_varid(nc, var_name, &var) == NC_NOERR &&
        nc_inq_attlen(nc, var, attribute, &n) == NC_NOERR) {
        text.resize(n);
        if (nc_get_att_text(nc, var, attribute, text.data()) != NC_NOERR)
            text.clear();
    }
    nc_close(nc);
    return text;
}

/// The --report's "depth" object: above sea level, shallowest, --min-depth (text), raised.
struct ReportedDepth {
    long long above = -1, raised = -1;
    double shallowest = NAN;
    std::string floor;
};

ReportedDepth reported_depth(const std::string &report) {
    std::vector<std::string> g;
    ReportedDepth d;
    if (!regex_search(
            report,
            R"re("depth": \{"nodes_above_sea_level": ([0-9]+), "min_sampled_depth_m": ([-0-9.e+]+|null), )re"
            R"re("min_depth_m": ([-0-9.e+]+|null), "nodes_raised_to_min_depth": ([0-9]+)\})re",
            &g)) {
        ADD_FAILURE() << "no depth object in the report:\n" << report;
        return d;
    }
    d.above = std::stoll(g[1]);
    d.shallowest = g[2] == "null" ? NAN : std::stod(g[2]);
    d.floor = g[3];
    d.raised = std::stoll(g[4]);
    return d;
}

} // namespace

// The nodes of the coast sample the land side of the raster: the run counts them as written,
// warns without --min-depth, and with it raises exactly the nodes shallower than DEPTH.
TEST(Cli, min_depth_raises_the_shallow_nodes_and_the_counts_match_the_file) {
    TempDir dir;
    const std::vector<std::string> common = {"mesh",
                                             "--coast",
                                             coast,
                                             "--coast-layer",
                                             "land",
                                             "--bathy",
                                             fixture("bathy/etopo5_nwshelf_5min.tif").string(),
                                             "--region",
                                             "-10,48,10,60",
                                             "--hmax",
                                             "30km"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = common;
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const Result plain =
        with({"-o", (dir / "d0.nc").string(), "--report", (dir / "r0.json").string()});
    ASSERT_EQ(plain.status, 0) << plain.err;
    const Result floored = with({"-o", (dir / "d5.nc").string(), "--report",
                                 (dir / "r5.json").string(), "--min-depth", "5m", "-q"});
    ASSERT_EQ(floored.status, 0) << floored.err;

    const std::vector<double> d0 = nc_doubles(dir / "d0.nc", "depth"),
                              d5 = nc_doubles(dir / "d5.nc", "depth");
    EXPECT_EQ(nc_text(dir / "d0.nc", "depth", "positive"), "down");
    ASSERT_EQ(d0.size(), d5.size());
    // The same mesh: --min-depth changes the depths only.
    EXPECT_EQ(nc_doubles(dir / "d0.nc", "mesh_node_lon"),
              nc_doubles(dir / "d5.nc", "mesh_node_lon"));
    EXPECT_EQ(nc_doubles(dir / "d0.nc", "mesh_node_lat"),
              nc_doubles(dir / "d5.nc", "mesh_node_lat"));
    const long long above = std::count_if(d0.begin(), d0.end(), [](double d) { return d < 0; });
    const long long shallower = std::count_if(d0.begin(), d0.end(), [](double d) { return d < 5; });
    const double shallowest = *std::min_element(d0.begin(), d0.end());
    ASSERT_GT(above, 10); // not vacuous: coast nodes on land cells
    EXPECT_GT(shallower, above);
    EXPECT_GE(*std::min_element(d5.begin(), d5.end()), 5.0);
    for (std::size_t i = 0; i < d0.size(); ++i)
        ASSERT_EQ(d5[i], std::max(d0[i], 5.0)) << "node " << i;

    const ReportedDepth r0 = reported_depth(read_text(dir / "r0.json"));
    EXPECT_EQ(r0.above, above);
    EXPECT_NEAR(r0.shallowest, shallowest, 1e-5 * std::abs(shallowest));
    EXPECT_EQ(r0.floor, "null");
    EXPECT_EQ(r0.raised, 0);
    const ReportedDepth r5 = reported_depth(read_text(dir / "r5.json"));
    EXPECT_EQ(r5.above, above); // as sampled, before --min-depth
    EXPECT_EQ(r5.floor, "5");
    EXPECT_EQ(r5.raised, shallower);

    // The warning (one line after the progress, counts grouped by thousands) comes only without
    // --min-depth, and not with --quiet.
    std::vector<std::string> g;
    ASSERT_TRUE(
        regex_search(plain.err,
                     R"(done\.\nglobemesh: warning: ([0-9,]+) nodes lie above sea level \(down to )"
                     R"((-?[0-9,]+) m\) and are written with negative depth; --min-depth 5 would )"
                     R"(raise them to 5 m\n$)",
                     &g))
        << plain.err;
    EXPECT_EQ(with({"-o", (dir / "quiet.nc").string(), "-q"}).err, "");
    auto plain_number = [](std::string t) { return std::stoll(regex_replace(t, ",", "")); };
    EXPECT_EQ(plain_number(g[1]), above);
    EXPECT_EQ(plain_number(g[2]), std::llround(shallowest));
    EXPECT_EQ(floored.err, "");
    const std::string depth_line =
        "\ndepth +" + std::to_string(above) + " nodes above sea level \\(down to -[0-9,]+ m\\)";
    EXPECT_TRUE(regex_search(plain.out, depth_line + "\n")) << plain.out;
    EXPECT_TRUE(regex_search(floored.out, depth_line + ", " + std::to_string(shallower) +
                                              " raised to --min-depth 5 m\n"))
        << floored.out;
    globemesh::test::expect_mesh_verify(dir / "d5.nc");
}

// GDAL opens a .zip, .tar or .gz only through /vsizip/, /vsitar/ or /vsigzip/: the error for an
// archive given as it is ("cannot open as a vector data set; check the path and format") now
// names the path that opens it, for every option that reads a file.
TEST(Cli, an_archive_given_as_a_plain_path_is_told_its_vsi_prefix) {
    TempDir dir;
    const std::string island = R"({"type":"FeatureCollection","crs":{"type":"name","properties":)"
                               R"({"name":"EPSG:4326"}},"features":[{"type":"Feature",)"
                               R"("properties":{"size_km":50},"geometry":{"type":"Polygon",)"
                               R"("coordinates":[[[5,5],[10,5],[10,10],[5,10],[5,5]]]}}]})";
    const std::string zip = (dir / "land.zip").string(), gz = (dir / "land.geojson.gz").string();
    for (const std::string &vsi : {"/vsizip/" + zip + "/land.geojson", "/vsigzip/" + gz}) {
        VSILFILE *f = VSIFOpenL(vsi.c_str(), "wb");
        ASSERT_NE(f, nullptr) << vsi;
        ASSERT_EQ(VSIFWriteL(island.data(), 1, island.size(), f), island.size());
        VSIFCloseL(f);
    }
    auto mesh = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {
            "mesh", "--hmax", "200km", "-o", (dir / "m.nc").string(), "--overwrite", "-q"};
        if (std::find(extra.begin(), extra.end(), "--region-file") == extra.end())
            extra.insert(extra.end(), {"--region", "0,0,20,20"});
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const std::string zip_hint = "a zip archive opens as /vsizip/" + zip + " (or /vsizip/" + zip +
                                 "/FILE for one file in it)";
    for (const char *option : {"--coast", "--region-file", "--size-regions", "--passages"}) {
        std::vector<std::string> extra = {option, zip};
        if (std::string(option) != "--coast")
            extra.insert(extra.end(), {"--coast", "/vsigzip/" + gz});
        const Result r = mesh(extra);
        EXPECT_NE(r.status, 0) << option;
        EXPECT_NE(r.err.find(zip_hint), std::string::npos) << option << ": " << r.err;
    }
    const Result r = mesh({"--coast", gz});
    EXPECT_NE(r.err.find("a gzip file opens as /vsigzip/" + gz + "\n"), std::string::npos) << r.err;
    const Result b = mesh({"--coast", "/vsizip/" + zip, "--bathy", zip});
    EXPECT_NE(b.err.find(": cannot open as a raster: "), std::string::npos) << b.err;
    EXPECT_NE(b.err.find(zip_hint), std::string::npos) << b.err;
    // The prefixed paths the errors name open.
    const Result ok = mesh({"--coast", "/vsizip/" + zip, "--size-regions", "/vsigzip/" + gz});
    EXPECT_EQ(ok.status, 0) << ok.err;
}

// Natural Earth's GeoPackage holds layers 'land' and 'ocean'; --coast-layer ocean meshed the
// continents without a word. A whole-globe mesh covering less than half the sphere now warns.
TEST(Cli, a_whole_globe_mesh_of_more_land_than_ocean_warns_of_a_water_layer) {
    TempDir dir;
    auto mesh = [&](const std::string &layer, std::vector<std::string> extra) {
        std::vector<std::string> args = {
            "mesh",   "--coast", coast, "--coast-layer",         layer,
            "--hmax", "1000km",  "-o",  (dir / "m.nc").string(), "--overwrite"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const std::string warning = R"(globemesh: warning: the mesh covers [0-9]+% of the globe and )"
                                R"(the land [0-9]+%: --coast takes land polygons; is layer )"
                                R"('ocean' water\?\n)";
    const Result ocean = mesh("ocean", {});
    ASSERT_EQ(ocean.status, 0) << ocean.err;
    EXPECT_TRUE(regex_search(ocean.err, warning)) << ocean.err;
    EXPECT_EQ(mesh("ocean", {"-q"}).err, "");
    const Result land = mesh("land", {});
    ASSERT_EQ(land.status, 0) << land.err;
    EXPECT_EQ(land.err.find("of the globe and the land"), std::string::npos) << land.err;
    // A region is any share of the globe.
    const Result region = mesh("ocean", {"--region", "-20,-20,20,20"});
    EXPECT_EQ(region.err.find("of the globe and the land"), std::string::npos) << region.err;
}

// A raster of depth (positive down) read as height, or of height read as depth with
// --depth-positive, puts most of the ocean's nodes above sea level: the warning suggested
// --min-depth 5, which would flatten the whole ocean to 5 m. It now names the sign.
TEST(Cli, most_nodes_above_sea_level_warn_about_the_raster_sign) {
    TempDir dir;
    const fs::path depth = dir / "depth.tif";
    {
        GDALAllRegister();
        const std::string src = fixture("bathy/etopo5_nwshelf_5min.tif").string();
        const char *args[] = {"-scale", "-32768", "32767", "32768", "-32767", nullptr};
        GDALTranslateOptions *opts = GDALTranslateOptionsNew(const_cast<char **>(args), nullptr);
        GDALDatasetH in = GDALOpen(src.c_str(), GA_ReadOnly);
        ASSERT_NE(in, nullptr);
        GDALDatasetH out = GDALTranslate(depth.c_str(), in, opts, nullptr);
        GDALTranslateOptionsFree(opts);
        GDALClose(in);
        ASSERT_NE(out, nullptr);
        GDALClose(out);
    }
    auto mesh = [&](const fs::path &bathy, std::vector<std::string> extra) {
        std::vector<std::string> args = {"mesh",
                                         "--coast",
                                         coast,
                                         "--coast-layer",
                                         "land",
                                         "--bathy",
                                         bathy.string(),
                                         "--region",
                                         "-10,48,10,60",
                                         "--hmax",
                                         "30km",
                                         "-o",
                                         (dir / "m.nc").string(),
                                         "--overwrite"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const std::string shelf = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    const std::string sign = R"(globemesh: warning: [0-9,]+ of the [0-9,]+ nodes lie above sea )"
                             R"(level: does --bathy hold )";
    const Result as_height = mesh(depth, {});
    ASSERT_EQ(as_height.status, 0) << as_height.err;
    EXPECT_TRUE(regex_search(as_height.err, sign + R"(depths \(positive down\)\? then pass )"
                                                   R"(--depth-positive\n)"))
        << as_height.err;
    const Result floored = mesh(depth, {"--min-depth", "5m"});
    EXPECT_TRUE(regex_search(floored.err, sign + "depths")) << floored.err;
    const Result as_depth = mesh(shelf, {"--depth-positive"});
    EXPECT_TRUE(regex_search(as_depth.err, sign + R"(heights \(positive up\)\? then leave out )"
                                                  R"(--depth-positive\n)"))
        << as_depth.err;
    // The same data with its sign right: no such warning.
    EXPECT_FALSE(regex_search(mesh(depth, {"--depth-positive"}).err, sign));
    EXPECT_FALSE(regex_search(mesh(shelf, {}).err, sign));
}

namespace {

/// The ETOPO5 shelf fixture (301 x 193 cells of 5 minutes from 12 1/24 W, 62 1/24 N) copied to
/// `path` with nodata (-32768) in columns c0..c1 and rows r0..r1, as the sweep's shelf_hole.tif.
void shelf_with_hole(const fs::path &path, int c0, int c1, int r0, int r1) {
    GDALAllRegister();
    GDALDatasetH src = GDALOpen(fixture("bathy/etopo5_nwshelf_5min.tif").c_str(), GA_ReadOnly);
    ASSERT_NE(src, nullptr);
    GDALDatasetH ds = GDALCreateCopy(GDALGetDriverByName("GTiff"), path.c_str(), src, FALSE,
                                     nullptr, nullptr, nullptr);
    GDALClose(src);
    ASSERT_NE(ds, nullptr) << path;
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    EXPECT_EQ(GDALSetRasterNoDataValue(band, -32768), CE_None);
    std::vector<std::int16_t> hole(std::size_t(c1 - c0 + 1) * std::size_t(r1 - r0 + 1), -32768);
    EXPECT_EQ(GDALRasterIO(band, GF_Write, c0, r0, c1 - c0 + 1, r1 - r0 + 1, hole.data(),
                           c1 - c0 + 1, r1 - r0 + 1, GDT_Int16, 0, 0),
              CE_None);
    GDALClose(ds);
}

} // namespace

// A nodata hole in the raster under the region's ocean (the sweep's shelf_hole.tif: 37 x 37
// cells of the shelf fixture in the North Sea) used to leave its nodes with NaN depths and exit
// 0. Without --bathy-fill the run stops with one line naming how many nodes and the first, and
// writes nothing; with it those nodes, and only those, take the fill, the others the depths of
// the raster without the hole (a uniform size: the same mesh either way).
TEST(Cli, nodes_without_bathymetry_data_are_an_error_unless_bathy_fill_gives_them_a_depth) {
    TempDir dir;
    const fs::path hole = dir / "hole.tif";
    shelf_with_hole(hole, 169, 205, 60, 96);
    auto mesh = [&](const std::string &bathy, const fs::path &out, std::vector<std::string> extra) {
        std::vector<std::string> args = {
            "mesh",     "--coast",      coast,    "--coast-layer", "land", "--bathy",    bathy,
            "--region", "-10,47,11,60", "--hmax", "30km",          "-o",   out.string(), "-q"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const Result refused = mesh(hole.string(), dir / "m.nc", {});
    EXPECT_EQ(refused.status, 1) << refused.err;
    std::vector<std::string> g;
    ASSERT_TRUE(regex_match(
        refused.err,
        "globemesh: --bathy " + hole.string() +
            R"(: no data at ([0-9]+) of the mesh's ([0-9]+) nodes, the first at lon (-?[0-9.]+), )"
            R"(lat (-?[0-9.]+) \(0 past the raster's edges at lon [-0-9.]+\.\.[-0-9.]+, lat )"
            R"([-0-9.]+\.\.[-0-9.]+; ([0-9]+) on cells without data\); pass --bathy-fill DEPTH to )"
            R"(give them that depth\n)",
        &g))
        << refused.err;
    EXPECT_EQ(g[5], g[1]);
    EXPECT_FALSE(fs::exists(dir / "m.nc"));
    EXPECT_FALSE(fs::exists(dir / "m.qml"));

    const Result filled = mesh(hole.string(), dir / "f.nc", {"--bathy-fill", "12345.5m"});
    ASSERT_EQ(filled.status, 0) << filled.err;
    const Result plain = mesh(fixture("bathy/etopo5_nwshelf_5min.tif").string(), dir / "p.nc", {});
    ASSERT_EQ(plain.status, 0) << plain.err;
    const std::vector<double> lon = nc_doubles(dir / "f.nc", "mesh_node_lon"),
                              lat = nc_doubles(dir / "f.nc", "mesh_node_lat"),
                              depth = nc_doubles(dir / "f.nc", "depth"),
                              plain_depth = nc_doubles(dir / "p.nc", "depth");
    ASSERT_EQ(lon, nc_doubles(dir / "p.nc", "mesh_node_lon"));
    ASSERT_EQ(depth.size(), plain_depth.size());
    EXPECT_EQ(std::to_string(depth.size()), g[2]);
    std::size_t fills = 0, first = depth.size();
    for (std::size_t i = 0; i < depth.size(); ++i) {
        // A cell or more from the hole (2 1/24 .. 5 1/8 E, 53 23/24 .. 57 1/24 N) as without it.
        const bool near = lon[i] > 1.95 && lon[i] < 5.21 && lat[i] > 53.87 && lat[i] < 57.13;
        if (depth[i] != 12345.5) {
            EXPECT_TRUE(near || depth[i] == plain_depth[i]) << lon[i] << " " << lat[i];
            continue;
        }
        first = std::min(first, i);
        ++fills;
        // Within half a cell of the hole.
        EXPECT_TRUE(lon[i] > 2.0 && lon[i] < 5.17 && lat[i] > 53.9 && lat[i] < 57.09)
            << lon[i] << " " << lat[i];
    }
    EXPECT_GT(fills, 50u);
    EXPECT_EQ(std::to_string(fills), g[1]);
    ASSERT_LT(first, depth.size());
    EXPECT_NEAR(lon[first], std::stod(g[3]), 1e-5);
    EXPECT_NEAR(lat[first], std::stod(g[4]), 1e-5);
    globemesh::test::expect_mesh_verify(dir / "f.nc");
}

namespace {

/// Adds a layer `name` (EPSG:4326) holding the box W,S,E,N (degrees) to the GeoPackage `path`,
/// created when missing.
void add_box_layer(const std::string &path, const char *name, double w, double s, double e,
                   double n) {
    GDALAllRegister();
    GDALDatasetH ds =
        GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_UPDATE, nullptr, nullptr, nullptr);
    if (!ds)
        ds = GDALCreate(GDALGetDriverByName("GPKG"), path.c_str(), 0, 0, 0, GDT_Unknown, nullptr);
    ASSERT_NE(ds, nullptr) << path;
    OGRSpatialReferenceH wgs84 = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(wgs84, 4326);
    OGRLayerH layer = GDALDatasetCreateLayer(ds, name, wgs84, wkbPolygon, nullptr);
    OSRRelease(wgs84);
    ASSERT_NE(layer, nullptr);
    OGRFeatureH f = OGR_F_Create(OGR_L_GetLayerDefn(layer));
    OGRGeometryH ring = OGR_G_CreateGeometry(wkbLinearRing),
                 polygon = OGR_G_CreateGeometry(wkbPolygon);
    for (auto [x, y] : {std::pair{w, s}, {e, s}, {e, n}, {w, n}, {w, s}})
        OGR_G_AddPoint_2D(ring, x, y);
    OGR_G_AddGeometryDirectly(polygon, ring);
    OGR_F_SetGeometryDirectly(f, polygon);
    EXPECT_EQ(OGR_L_CreateFeature(layer, f), OGRERR_NONE);
    OGR_F_Destroy(f);
    GDALClose(ds);
}

} // namespace

// ETOPO5 cut to the region's box (gdal_translate -projwin -12 62 13 46, the sweep's g_regcut):
// the box's open edge along 62N is great-circle arcs between nodes on it, 0.0002-0.0008 degree
// past the raster's edge, and the run was refused ("the ocean of --region reaches lon 4.87, lat
// 62.00022"). A raster is read a quarter of a cell past its edges (Raster::edge_margin): the
// run meshes, every node with a depth, ADCIRC's fort.14 written.
TEST(Cli, a_raster_cut_to_the_region_box_covers_the_mesh) {
    TempDir dir;
    const fs::path cut = dir / "cut.tif";
    GDALAllRegister();
    char **argv = CSLAddString(nullptr, "-projwin");
    for (const char *a : {"-12", "62", "13", "46"})
        argv = CSLAddString(argv, a);
    GDALTranslateOptions *opts = GDALTranslateOptionsNew(argv, nullptr);
    CSLDestroy(argv);
    GDALDatasetH src = GDALOpen(fixture("bathy/etopo5_global_10min.nc").c_str(), GA_ReadOnly);
    ASSERT_NE(src, nullptr);
    GDALDatasetH out = GDALTranslate(cut.c_str(), src, opts, nullptr);
    GDALTranslateOptionsFree(opts);
    GDALClose(src);
    ASSERT_NE(out, nullptr);
    GDALClose(out);
    const Result r =
        run({"mesh", "--coast", coast, "--coast-layer", "land", "--bathy", cut.string(), "--region",
             "-12,46,13,62", "--hmax", "60km", "--hmin", "5km", "-o", (dir / "m.nc").string(), "-o",
             (dir / "fort.14").string(), "-q"},
            globemesh::library_calls());
    ASSERT_EQ(r.status, 0) << r.err;
    const std::vector<double> depth = nc_doubles(dir / "m.nc", "depth");
    ASSERT_FALSE(depth.empty());
    EXPECT_TRUE(std::all_of(depth.begin(), depth.end(), [](double d) { return std::isfinite(d); }));
    EXPECT_TRUE(fs::exists(dir / "fort.14"));
}

TEST(Cli, region_layer_picks_one_layer_of_a_region_file) {
    TempDir dir;
    const std::string regions = (dir / "regions.gpkg").string();
    add_box_layer(regions, "north_sea", -4, 51, 9, 59);
    add_box_layer(regions, "biscay", -10, 43.5, -1, 48);
    auto mesh = [&](const std::string &out, std::vector<std::string> extra) {
        std::vector<std::string> args = {"mesh",  "--coast",
                                         coast,   "--coast-layer",
                                         "land",  "--region-file",
                                         regions, "--hmax",
                                         "40km",  "-q",
                                         "-o",    (dir / out).string()};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const Result both = mesh("both.nc", {});
    EXPECT_EQ(both.status, 1);
    EXPECT_EQ(both.err,
              "globemesh: --region-file " + regions +
                  ": several polygon or line layers, choose one with --region-layer; layers: "
                  "north_sea (Polygon), biscay (Polygon)\n");
    EXPECT_FALSE(fs::exists(dir / "both.nc"));
    const Result missing = mesh("missing.nc", {"--region-layer", "baltic"});
    EXPECT_EQ(missing.status, 1);
    EXPECT_NE(missing.err.find("no layer named 'baltic'"), std::string::npos) << missing.err;

    // Each layer alone: the nodes lie in its box and reach across it.
    for (const auto &[layer, box] :
         {std::pair{"biscay", std::array<double, 4>{-10, 43.5, -1, 48}},
          std::pair{"north_sea", std::array<double, 4>{-4, 51, 9, 59}}}) {
        SCOPED_TRACE(layer);
        const std::string out = std::string(layer) + ".nc";
        const Result r = mesh(out, {"--region-layer", layer});
        ASSERT_EQ(r.status, 0) << r.err;
        const auto lon = nc_doubles(dir / out, "mesh_node_lon"),
                   lat = nc_doubles(dir / out, "mesh_node_lat");
        ASSERT_FALSE(lon.empty());
        const auto [lon_min, lon_max] = std::minmax_element(lon.begin(), lon.end());
        const auto [lat_min, lat_max] = std::minmax_element(lat.begin(), lat.end());
        EXPECT_GE(*lon_min, box[0] - 1e-9);
        EXPECT_LE(*lon_max, box[2] + 1e-9);
        EXPECT_GE(*lat_min, box[1] - 1e-9);
        // The outline's edges are great circles: the northern one bulges north of its parallel
        // to atan(tan(N) / cos(half its longitude span)) at its middle.
        const double half_span = 0.5 * (box[2] - box[0]) * M_PI / 180;
        EXPECT_LE(*lat_max,
                  std::atan(std::tan(box[3] * M_PI / 180) / std::cos(half_span)) * 180 / M_PI +
                      1e-9);
        EXPECT_GT(*lon_max - *lon_min, 0.8 * (box[2] - box[0]));
        EXPECT_GT(*lat_max - *lat_min, 0.8 * (box[3] - box[1]));
        globemesh::test::expect_mesh_verify(dir / out);
    }
}

// Straits narrower than a face: by default closed, with the warning that says how to keep one;
// with --keep-straits the faces across them stay, centred on land, and the warning says so, with
// the mesh's worst quality and how to resolve them. Neither with --quiet. (NE 1:50m, the Aegean
// and the Black Sea at 100 km: the Dardanelles and the Bosphorus are 1-6 km wide.)
TEST(Cli, straits_narrower_than_a_face_warn_when_closed_and_when_kept) {
    TempDir dir;
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {"mesh",
                                         "--coast",
                                         fixture("coast/ne_50m_land.gpkg").string(),
                                         "--coast-layer",
                                         "land",
                                         "--region",
                                         "20,35,45,48",
                                         "--hmax",
                                         "100km",
                                         "-o",
                                         (dir / "s.nc").string(),
                                         "--overwrite"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const Result closed = with({});
    ASSERT_EQ(closed.status, 0) << closed.err;
    EXPECT_TRUE(regex_search(closed.err, R"(globemesh: warning: [0-9]+ straits? narrower than )"))
        << closed.err;
    EXPECT_EQ(closed.err.find("--keep-straits kept"), std::string::npos) << closed.err;
    const Result kept = with({"--keep-straits"});
    ASSERT_EQ(kept.status, 0) << kept.err;
    std::vector<std::string> g;
    ASSERT_TRUE(regex_search(kept.err,
                             R"(globemesh: warning: --keep-straits kept ([0-9]+) faces? centred )"
                             R"(on land across straits narrower than a face \(listed in the )"
                             R"(summary under 'faces on land'; the mesh's worst face has q )"
                             R"(([0-9.]+)\); resolve a strait with --size-regions)",
                             &g))
        << kept.err;
    EXPECT_GE(std::stoi(g[1]), 1);
    // The summary's counts and quality are the warning's.
    EXPECT_TRUE(regex_search(kept.out, "faces on land     " + g[1] + " ")) << kept.out;
    EXPECT_TRUE(regex_search(kept.out, "quality           min " + g[2].substr(0, 4))) << kept.out;
    EXPECT_EQ(kept.err.find("were closed"), std::string::npos) << kept.err;
    EXPECT_EQ(with({"--keep-straits", "-q"}).err, "");
}

// GSHHG intermediate in the Sundarbans at 1.3 km: a tidal channel narrows to a point between two
// coasts. With --keep-straits its faces there are squeezed to q 0.11 (a side of 6 m) in water,
// with no face on land: the run said nothing of a face below the floor the mesher keeps (q 0.3)
// wherever straits close. It now warns, with the place.
TEST(Cli, keep_straits_warns_of_a_face_below_the_floor_in_a_channel_it_kept) {
    TempDir dir;
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> args = {
            "mesh",
            "--coast",
            fixture("coast/hostile/gshhg_i_sundarbans.geojson").string(),
            "--region",
            "88.1,21.55,88.35,21.8",
            "--hmax",
            "1.3km",
            "-o",
            (dir / "s.nc").string(),
            "--overwrite"};
        args.insert(args.end(), extra.begin(), extra.end());
        return run(args, globemesh::library_calls());
    };
    const Result kept = with({"--keep-straits"});
    ASSERT_EQ(kept.status, 0) << kept.err;
    std::vector<std::string> g;
    ASSERT_TRUE(regex_search(kept.err,
                             R"(globemesh: warning: --keep-straits kept channels narrower than a )"
                             R"(face open; the mesh's worst face has q ([0-9.]+) at lon )"
                             R"(([0-9.]+), lat ([0-9.]+); resolve a channel with --size-regions)",
                             &g))
        << kept.err;
    EXPECT_LT(std::stod(g[1]), 0.3);
    EXPECT_TRUE(regex_search(kept.out, "quality           min " + g[1].substr(0, 4))) << kept.out;
    EXPECT_NEAR(std::stod(g[2]), 88.225, 0.01);
    EXPECT_NEAR(std::stod(g[3]), 21.670, 0.01);
    EXPECT_TRUE(regex_search(kept.out, "faces on land     0 ")) << kept.out;
    // Where straits close (the default) the floor holds and nothing of the kind is said.
    const Result closed = with({});
    ASSERT_EQ(closed.status, 0) << closed.err;
    EXPECT_EQ(closed.err.find("channels narrower"), std::string::npos) << closed.err;
    EXPECT_TRUE(regex_search(closed.out, R"(quality           min 0\.[3-9])")) << closed.out;
    EXPECT_EQ(with({"--keep-straits", "-q"}).err, "");
}
