// Private to src/cli: the output flags of `mesh` and `triangulate` (-o, -f/--output-format, --co,
// and the older --gpkg and --preview), turned into the writers table's OutputRequests, and the
// summary's and the report's lists of the outputs. Nothing here names a format: the table does.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_support.hpp"
#include "globemesh/writers.hpp"

namespace globemesh::cli {

/// The outputs asked for on one command line.
struct OutputChoices {
    std::vector<std::string>
        output;         ///< -o (repeatable): each in the format of its extension, or -f's
    std::string format; ///< -f/--output-format NAME: the format of -o's file
    std::vector<std::string> creation; ///< --co KEY=VALUE, for every output whose format takes KEY
    /// Options that always write one format (--gpkg, --preview): option, format name, path.
    struct Fixed {
        std::string option, format, path;
    };
    std::vector<Fixed> fixed;
};

/// Adds -o/--output, -f/--output-format and --co to `app` in `group`, bound to the fields of
/// OutputChoices' first three members; the help lists the formats of `table`.
void add_output_flags(CLI::App &app, std::vector<std::string> &output, std::string &format,
                      std::vector<std::string> &creation, std::span<const Writer> table,
                      const std::string &group);

/// Adds --output-srs and --msh-version to `app` in `group` (mesh and convert).
void add_model_flags(CLI::App &app, std::string &output_srs, std::string &msh_version,
                     std::span<const Writer> table, const std::string &group);

/// The creation option --msh-version stands for, as plan_outputs' extra_creation ("--msh-version",
/// "MSH_VERSION=2.2"); none when not given. UsageError when a --co MSH_VERSION of `creation`
/// says otherwise.
std::vector<std::pair<std::string, std::string>>
msh_version_creation(const std::string &msh_version, const std::vector<std::string> &creation);

/// One output of the run with the option that named it (for messages).
struct PlannedOutput {
    std::string option;
    OutputRequest request;
};

/// The outputs of `c` in the table's order (the order they are written), their formats chosen
/// and their creation options checked. `extra_creation` (option, KEY=VALUE) are creation
/// options given by other flags (--format classic). `has_depth`: the mesh will have depths;
/// `no_depth`: how the message about a format that needs them goes on (what gives them).
/// Throws UsageError (one line naming the option and listing the formats) before anything runs.
std::vector<PlannedOutput>
plan_outputs(const OutputChoices &c, std::span<const Writer> table,
             std::span<const std::pair<std::string, std::string>> extra_creation, bool has_depth,
             const std::string &no_depth = "give a bathymetry (--bathy)");

/// Throws UsageError when JSON output `option` (--report, --timings) is named for a mesh format.
void check_json_output(const std::string &path, const std::string &option,
                       std::span<const Writer> table);

/// The mesh files and the JSON files (--timings, --report; checked by check_json_output) of a
/// run, as (option, path).
std::vector<std::pair<std::string, std::string>>
output_files(std::span<const PlannedOutput> planned, const std::string &timings,
             const std::string &report, std::span<const Writer> table);

/// Checks that the output files can be written: distinct (UsageError), none of `inputs`
/// (option, path; UsageError), their folders there and no file in the way unless `overwrite`
/// (IoError).
void check_output_files(std::span<const std::pair<std::string, std::string>> outputs,
                        std::span<const std::pair<std::string, std::string>> inputs,
                        bool overwrite);

/// The share of a run's one progress line the mesh (or triangulation) gets, before its outputs:
/// each output's progress_weight is its writing time relative to the mesh's.
double mesh_share(std::span<const PlannedOutput> planned);

/// Writes the outputs of `mesh` (mesh and triangulate alike) into the caller's OutputBatch, on
/// the rest of `terminal`'s line after the mesh's share; a signal stops it (Cancelled). With
/// `timings`, adds each format's seconds (write_ugrid, write_gpkg...) and all of them (write) to
/// `timings`.
void write_run_outputs(const Mesh &mesh, std::span<const PlannedOutput> planned,
                       WriteOptions options, TerminalProgress &terminal,
                       StageTimings *timings = nullptr);

/// The requests of `planned`, in order.
std::vector<OutputRequest> requests(std::span<const PlannedOutput> planned);

/// {"netcdf": "o.nc", "gpkg": "o.gpkg"}: each output under its format's report key (a list
/// when a format is written twice).
std::string outputs_json(std::span<const PlannedOutput> planned);

/// "o.nc, o.qml, o.gpkg": the outputs in the order written, with the QGIS style NAME.qml that a
/// UGRID output of `mesh` gets when it has depths (ugrid_write.cpp).
std::string outputs_text(std::span<const PlannedOutput> planned, const Mesh *mesh = nullptr);

} // namespace globemesh::cli
