// Private to src/cli: what a `mesh` run tells its user: the summary on stdout (with the warning
// about nodes above sea level on stderr) and the --report JSON, both from the typed reports.
#pragma once

#include <ostream>
#include <span>
#include <string>

#include "cli_outputs.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/pipeline.hpp"

namespace globemesh::cli {

/// What a finished `mesh` run reports: its command, outputs, mesh and times.
struct MeshRunSummary {
    const CliOptions &options;
    std::span<const PlannedOutput> planned;
    const MeshStats &stats;
    const OceanMesh &run;
    const StageTimings &timings;
    std::string history; ///< the command line with its date, as in the files' `history`
    double total_s = 0;  ///< the run's wall-clock seconds
    long long peak = 0;  ///< peak resident memory in bytes
};

/// The --report file's JSON: summary, quality histogram, the mesh's attributes, times.
std::string report_json(const MeshRunSummary &s);

/// The summary lines on `out`; unless --quiet, the warning about nodes above sea level on `err`.
void print_mesh_summary(std::ostream &out, std::ostream &err, const MeshRunSummary &s);

/// The file --passages default names: the installed passages.geojson, else the source tree's.
/// Throws IoError when neither is there.
std::string default_passages_path();

/// The passages' report: {"cells_needed": N, "list": [{name, width_km, size_km, cells, lon, lat}]}.
std::string passages_json(const OceanMesh &run);

/// The summary's passages line on `out`; unless `quiet`, a warning on `err` for each passage
/// with fewer cells across than --passage-cells.
void print_passages(std::ostream &out, std::ostream &err, const OceanMesh &run, bool quiet);

} // namespace globemesh::cli
