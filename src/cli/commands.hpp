// Private to src/cli: the subcommands `mesh`, `triangulate`, `convert` and `info`, each a CLI11 App
// bound to its options, and the functions that run them (run_cli's dispatch calls these).
#pragma once

#include <array>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_support.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/options.hpp"
#include "globemesh/writers.hpp"

namespace globemesh::cli {

/// The `mesh` subcommand: its CLI11 App bound to a CliOptions, plus the fields that need a
/// conversion after parsing (optional values).
struct MeshCommand {
    CliOptions o;
    std::vector<double> region;
    std::vector<double> preview_region;
    double bathy_fill_m = 0;
    double min_depth_m = 0;
    std::string max_memory_text = "auto";
    CLI::App app{"Mesh the ocean between the coastlines, graded by the size options.",
                 "globemesh mesh"};
    CLI::Option *region_opt = nullptr;
    CLI::Option *preview_region_opt = nullptr;
    CLI::Option *bathy_fill_opt = nullptr;
    CLI::Option *min_depth_opt = nullptr;

    /// `table`: the output formats the help lists.
    explicit MeshCommand(std::span<const Writer> table = writers());
    MeshCommand(const MeshCommand &) = delete;
    MeshCommand &operator=(const MeshCommand &) = delete;

    /// Parses; CLI11 errors (including help and version) propagate.
    void parse(std::span<const std::string> args);

private:
    // The option groups of --help, added in this order (the order --help lists them in).
    void add_coast_options(const std::string &group);
    void add_bathy_options(const std::string &group);
    void add_size_options(const std::string &group);
    void add_mesher_options(const std::string &group);
    void add_output_options(std::span<const Writer> table, const std::string &group);
    void add_run_options(const std::string &group);
};

/// The `triangulate` subcommand's CLI11 App and options.
struct TriangulateCommand {
    TriangulateOptions t;
    std::vector<std::string> output, creation;
    std::string format, gpkg, timings;
    bool overwrite = false, quiet = false, verbose = false;
    CLI::App app{"Spherical Delaunay triangulation of scattered points (any OGR point source).",
                 "globemesh triangulate"};

    explicit TriangulateCommand(std::span<const Writer> table = writers());
};

/// The `info` subcommand's CLI11 App and options.
struct InfoCommand {
    std::string path;
    bool json = false;
    CLI::App app{"Counts, extent, edge lengths and quality of a UGRID mesh file.",
                 "globemesh info"};
    InfoCommand();
};

/// --preview-region's W,S,E,N, checked as --region is (W > E crosses +-180); one-line
/// UsageError otherwise (mesh and convert).
std::array<double, 4> checked_preview_region(const std::vector<double> &r);

/// The input files of a `mesh` run, (option, path), unset ones empty: each must exist before
/// the run (check_input_path) and none may be an output (check_not_an_input).
std::vector<std::pair<std::string, std::string>> mesh_input_files(const CliOptions &o);

/// The `convert` subcommand's CLI11 App and options.
struct ConvertCommand {
    std::string input;
    std::vector<std::string> positional, output, creation;
    std::string format, output_srs, msh_version;
    std::vector<double> preview_region;
    CLI::Option *preview_region_opt = nullptr;
    bool overwrite = false, quiet = false;
    CLI::App app{"Convert a UGRID mesh to the output formats, keeping boundary tags and depths.",
                 "globemesh convert"};

    explicit ConvertCommand(std::span<const Writer> table = writers());
};

/// `globemesh mesh ARGS`: returns the exit status; errors propagate to run_cli.
int run_mesh(std::span<const std::string> args, std::ostream &out, std::ostream &err,
             TerminalProgress &terminal, const CliLibrary &lib);
/// `globemesh triangulate ARGS`, likewise.
int run_triangulate(std::span<const std::string> args, std::ostream &out, std::ostream &err,
                    TerminalProgress &terminal, const CliLibrary &lib);
/// `globemesh convert ARGS`, likewise.
int run_convert(std::span<const std::string> args, std::ostream &out, std::ostream &err,
                TerminalProgress &terminal, const CliLibrary &lib);
/// `globemesh info ARGS`, likewise.
int run_info(std::span<const std::string> args, std::ostream &out, const CliLibrary &lib);

} // namespace globemesh::cli
