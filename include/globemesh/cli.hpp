// globemesh/cli.hpp: the whole command line as a library function (PROJ's projinfo_lib split).
//
// run_cli parses the arguments (CLI11, config files), validates them, calls the library, shows
// GDAL-style progress on `err`, and maps errors to one line on `err` prefixed "globemesh:" and an
// exit status: 0 success, 1 data/IO error (and cancellation), 2 usage error. It never calls
// exit(). Nothing but results (help, version, the run summary, --print-config, info) goes to
// `out`.
//
// Units at the command line: lengths take km or m ("20km", "5000m"; a bare number is km),
// areas km2 or m2 ("1000km2", "1e6m2"; bare: km2), durations h, min or s ("12.42h"; bare: h).
// They are converted here, once, into the km / km2 / hour fields of MeshOptions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/mesh_read.hpp"
#include "globemesh/mesh_stats.hpp"
#include "globemesh/options.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/preview.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"

namespace globemesh {

/// Runs `globemesh ARGS...` (args exclude the program name). Returns the exit status.
int run_cli(std::span<const std::string> args, std::ostream &out, std::ostream &err);

/// The library calls run_cli makes. run_cli(args, out, err) uses library_calls(), the real
/// functions; tests pass their own to show that a bad command stops before any call is made,
/// or to interrupt a run at a chosen point (a seam like GDAL's test hooks). Each member must be
/// set.
struct CliLibrary {
    std::function<OceanMesh(const MeshOptions &, const Progress &, StageTimings *)> mesh_ocean;
    std::function<Mesh(const TriangulateOptions &, const Progress &, StageTimings *)>
        triangulate_file;
    /// The output formats (writers.hpp): -o, -f, --gpkg and --preview choose among them, and
    /// their rows' write functions write the files.
    std::vector<Writer> writers;
    std::function<Mesh(const std::filesystem::path &)> read_ugrid;
    /// fort.14 / hgrid.gr3 (mesh_read.hpp), an input of `convert`.
    std::function<Mesh(const std::filesystem::path &)> read_adcirc;
    /// gmsh .msh (mesh_read.hpp), an input of `convert`.
    std::function<Mesh(const std::filesystem::path &)> read_gmsh;
    std::function<MeshStats(const Mesh &)> compute_stats;
};

/// The real library functions (pipeline.hpp, ugrid.hpp, writers.hpp).
CliLibrary library_calls();

/// run_cli with the given library calls.
int run_cli(std::span<const std::string> args, std::ostream &out, std::ostream &err,
            const CliLibrary &library);

/// Program-only choices of `globemesh mesh`, kept apart from the library's MeshOptions (GDAL's
/// "OptionsForBinary" split). CLI11 binds the flags straight to these fields.
struct CliOptions {
    MeshOptions mesh;
    std::vector<std::string>
        output; ///< -o/--output: files to write, each in its extension's format (required)
    std::string output_format; ///< -f/--output-format: the writers table's name of -o's format
    std::vector<std::string> creation_options; ///< --co KEY=VALUE: creation options of the outputs
    std::string gpkg;                          ///< --gpkg: also write a GeoPackage
    std::string preview;                       ///< --preview: also draw a PNG picture of the mesh
    /// --preview-region: W,S,E,N in degrees the PNG pictures show (W > E crosses +-180); unset:
    /// the --region, else the mesh's extent.
    std::optional<std::array<double, 4>> preview_region;
    std::string
        output_srs; ///< --output-srs: CRS of the model formats' coordinates (empty: lon/lat)
    std::string msh_version; ///< --msh-version: MSH_VERSION of .msh outputs (empty: the default)
    std::string format =
        "netcdf4";          ///< --format: netcdf4 (deflate) or classic (netCDF-3), UGRID's FORMAT
    std::string timings;    ///< --timings: JSON file of seconds per stage
    std::string report;     ///< --report: JSON file of the run summary and histogram
    bool overwrite = false; ///< --overwrite: replace existing outputs
    bool quiet = false;     ///< --quiet: no progress on stderr
    bool verbose = false;   ///< --verbose: stage names with the progress
    bool check = false;     ///< --check: verify the mesh invariants before writing
    bool print_config = false; ///< --print-config: print the effective configuration, stop
    std::string config;        ///< --config: the file read (kept to refuse it as an output)
};

/// Parses the arguments of `globemesh mesh` (after the word "mesh"), including any --config
/// file, into CliOptions. Validates nothing beyond the syntax and units. Throws UsageError
/// naming the option (also for --help, which has nothing to return here).
CliOptions parse_mesh_args(std::span<const std::string> args);

/// "20km", "5000m", "20" (km) -> km. Throws UsageError for a non-number or an unknown unit.
double parse_length_km(std::string_view text);
/// "1000km2", "1e6m2", "1000" (km2) -> km2. Throws UsageError like parse_length_km.
double parse_area_km2(std::string_view text);
/// "12.42h", "745min", "44712s", "12.42" (h) -> hours. Throws UsageError like parse_length_km.
double parse_duration_h(std::string_view text);
/// "50m", "0.05km", "50" (m) -> metres (depths). Throws UsageError like parse_length_km.
double parse_depth_m(std::string_view text);

} // namespace globemesh
