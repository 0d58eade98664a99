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

} // namespace globemesh::cli
