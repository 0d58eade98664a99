// Private to src/cli: what the subcommands share around CLI11 (version, unit transforms, the
// wording of CLI11's errors, the history line) and around a run (GDAL's messages, interruption,
// elapsed time).
#pragma once

#include <chrono>
#include <ostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <cpl_error.h>

namespace globemesh::cli {

/// "globemesh VERSION (GDAL RELEASE)": --version's line.
std::string version_text();

/// Shortest text that reads back as the same double.
std::string exact_text(double v);

/// A CLI11 transform that turns "20km" into "20" (the field's unit), so the bound field, the
/// --help default and --print-config all speak the field's unit.
CLI::Validator unit_transform(double (*parse)(std::string_view), const std::string &name);

/// A CLI11 transform for a count: a whole number, also written as 2e7 (CLI11 alone refuses that
/// with "Could not convert").
CLI::Validator count_transform();

/// CLI11 wants the arguments in reverse order.
std::vector<std::string> reversed(std::span<const std::string> args);

/// Calls parse() for a subcommand's `app`; when it asks for --help (or --help-all) or --version,
/// prints that on `out` and returns true: the command is done, with status 0.
template <class Parse> bool printed_help(CLI::App &app, std::ostream &out, Parse &&parse) {
    try {
        parse();
    } catch (const CLI::CallForHelp &) {
        out << app.help();
        return true;
    } catch (const CLI::CallForAllHelp &) {
        out << app.help();
        return true;
    } catch (const CLI::CallForVersion &) {
        out << version_text() << "\n";
        return true;
    }
    return false;
}

/// One line: newlines of multi-line messages (CLI11's) become "; ".
std::string one_line(std::string message);

/// CLI11's parse errors in the words of the rest of globemesh's messages, for `command` (mesh,
/// info, triangulate; empty at the top level): an option given twice, an option without its
/// value, an unknown option, a stray argument.
std::string usage_text(const CLI::ParseError &e, const std::string &command);

/// The command line for the `history` attribute, with the date (UTC).
std::string history_text(const std::string &sub, std::span<const std::string> args);

/// The configuration (config_to_str) as an output file keeps it: without the thread count,
/// which never changes the mesh (the same bytes on any machine), and without the default part
/// count (0, chosen from the mesh size: a file of one part is that of before --parts).
std::string file_configuration(const std::string &config);

/// Throws Cancelled once a cancelling signal arrived (InterruptGuard).
void throw_if_interrupted();

/// Seconds elapsed since `t0`.
double seconds_since(std::chrono::steady_clock::time_point t0);

/// GDAL messages go through our stream: warnings only with --verbose (errors become exceptions
/// at the library's call sites, which read CPLGetLastErrorMsg).
class GdalMessages {
public:
    GdalMessages(std::ostream &err, bool verbose) : err_(err), verbose_(verbose) {
        CPLPushErrorHandlerEx(&GdalMessages::handler, this);
    }
    ~GdalMessages() { CPLPopErrorHandler(); }
    GdalMessages(const GdalMessages &) = delete;
    GdalMessages &operator=(const GdalMessages &) = delete;

private:
    static void CPL_STDCALL handler(CPLErr level, CPLErrorNum, const char *message) {
        auto *self = static_cast<GdalMessages *>(CPLGetErrorHandlerUserData());
        if (self && self->verbose_ && level == CE_Warning)
            self->err_ << "\nwarning (GDAL): " << message << "\n";
    }
    std::ostream &err_;
    bool verbose_;
};

} // namespace globemesh::cli
