// Private to src/cli: terminal progress, the Ctrl-C guard, JSON output written safely, and the
// run summary shared by `mesh`, `triangulate` and `info`.
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "globemesh/pipeline.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/ugrid.hpp"

namespace globemesh::cli {

/// Installs handlers for SIGINT, SIGTERM and SIGHUP for its lifetime (restoring the previous
/// ones after). The first signal is only recorded (interrupted() reads it; the run stops at its
/// next progress report and removes its files). A second one removes the temporary output files
/// (OutputFile::remove_temporaries), says "cancelled" on stderr and ends the process by that
/// signal, unless the run is moving its outputs in place (completing()). A run still going
/// stop_grace after the first signal (in a long call that does not report) gets it again from a
/// watchdog thread, and so ends as on a second one. One guard at a time, on the thread that runs
/// (run_cli is not re-entrant); a signal delivered to another thread is passed to it.
class InterruptGuard {
public:
    InterruptGuard();
    ~InterruptGuard();
    InterruptGuard(const InterruptGuard &) = delete;
    InterruptGuard &operator=(const InterruptGuard &) = delete;
    static bool interrupted();
    /// The signal that cancelled the last run (kept after the guard is gone), or 0.
    static int signal();
    /// Clears signal() before a new run.
    static void forget();
    /// The run is about to move its outputs in place (OutputBatch::commit, which still stops on
    /// a signal that came before): from now on every signal is ignored, also after the guard
    /// ends (it then leaves them ignored rather than restoring the earlier handlers), so that the
    /// process ends either with all its outputs and status 0 or, when the commit fails, with none.
    static void completing();
    /// The signals that cancel a run: Ctrl-C, `kill` and batch schedulers at their time limit
    /// (SIGTERM), and a closed terminal (SIGHUP). Each would otherwise end the process at once
    /// and leave the temporary output files behind.
    static constexpr int cancelling[3] = {SIGINT, SIGTERM, SIGHUP};
    /// How long a run has to stop cleanly (status 1) after a signal before it is ended by it.
    static constexpr std::chrono::milliseconds stop_grace{1000};

private:
    struct sigaction previous_[std::size(cancelling)]{};
    bool installed_[std::size(cancelling)] = {};
    std::thread watchdog_;
};

/// GDAL's terminal progress ("0...10...20...30...40...50...60...70...80...90...100 - done."),
/// drawn on `err` rather than stdout (where GDALTermProgress writes) so that stdout carries
/// results only. With `verbose`, each new stage starts a line "[stage] ". The callback returns
/// false once a cancelling signal arrived (InterruptGuard), which cancels the run. run_cli owns
/// one, so that an error line never lands in the middle of a progress line. Without `verbose`
/// the line starts at the first tick after 0, so an early error is not preceded by a lone "0".
class TerminalProgress {
public:
    explicit TerminalProgress(std::ostream &err) : err_(err) {}
    void configure(bool quiet, bool verbose) { quiet_ = quiet, verbose_ = verbose; }
    bool update(double fraction, std::string_view stage);
    Progress callback() {
        return [this](double f, std::string_view stage) { return update(f, stage); };
    }
    /// Ends a progress line left open (before an error message).
    void end_line();
    /// Draws the ticks up to 100 when the library stopped reporting short of 1.
    void finish() { update(1.0, stage_); }

private:
    std::ostream &err_;
    bool quiet_ = false, verbose_ = false, mid_line_ = false;
    int last_tick_ = -1;
    std::string stage_;
};

/// A JSON number (shortest round-trip form) or null when not finite.
std::string json_number(double v);
/// A JSON string literal with escapes.
std::string json_string(const std::string &s);

/// {name: seconds, ...} in run order.
std::string stages_json(const StageTimings &timings);
/// {"stages": {name: seconds, ...}} and a newline: the --timings file.
inline std::string timings_json(const StageTimings &timings) {
    return "{\"stages\": " + stages_json(timings) + "}\n";
}

/// The statistics of compute_stats as a JSON object (no trailing newline), indented by `indent`.
std::string stats_json(const MeshStats &stats, const std::string &indent);

/// Human-readable statistics (counts, extent, quality, edge lengths, size ratio, histogram).
void print_stats(std::ostream &out, const MeshStats &stats, bool histogram);

/// Seconds per stage on one line per stage.
void print_timings(std::ostream &out, const StageTimings &timings);

/// Peak resident memory of this process in bytes (getrusage ru_maxrss).
long long peak_memory_bytes();

/// "4GB", "500MB", "2GiB", "123" (bytes) -> bytes: SI units B, kB, MB, GB, TB (powers of 1000)
/// and binary KiB, MiB, GiB, TiB (powers of 1024). Throws UsageError for a non-number, a
/// negative value or an unknown unit.
std::uint64_t parse_memory_bytes(std::string_view text);

/// The default of --max-memory: 3/4 of the physical memory (sysconf), leaving room for the
/// system and other programs; 0 (no limit) when the system does not say.
std::uint64_t default_memory_budget_bytes();

/// Throws IoError when `path`'s folder does not exist, or when `path` exists and !overwrite.
/// `what` names the option, e.g. "--gpkg".
void check_output_path(const std::string &path, const std::string &what, bool overwrite);

/// Throws IoError when a local input file is missing; GDAL virtual paths (/vsi...) and
/// connection strings (PG:..., https://...) are left to GDAL.
void check_input_path(const std::string &path, const std::string &what);

/// Throws UsageError when output `path` (option `what`) is the very file of one of `inputs`
/// (option, path; through links and other spellings): --overwrite would replace the data the run
/// reads (gdal_translate refuses the same).
void check_not_an_input(const std::string &path, const std::string &what,
                        std::span<const std::pair<std::string, std::string>> inputs);

} // namespace globemesh::cli
