// run_cli(): the top level (help, version, dispatch to the subcommands of commands.hpp) and the
// mapping of errors to exit statuses. One CLI11 App per subcommand, so that `--config` reads a
// flat file whose keys are the long option names (CLI11 reads config files for its top App only).
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/error.hpp"
#include "option_flags.hpp"

namespace globemesh {

namespace {

using namespace globemesh::cli;

int report_error(std::ostream &err, const std::string &command);

// --------------------------------------------------------------------------------------------
// globemesh (top level), help

std::unique_ptr<CLI::App> make_top_app() {
    auto app = std::make_unique<CLI::App>(
        "Ocean meshes on the sphere from GIS data: coastlines from any OGR source, bathymetry from "
        "any GDAL raster, UGRID NetCDF and GeoPackage out. See globemesh(1).",
        "globemesh");
    app->set_version_flag("--version", version_text(), "Print the version and exit");
    app->add_subcommand("mesh",
                        "Mesh the ocean: globemesh mesh --coast LAND -o OCEAN.nc [options]");
    app->add_subcommand("triangulate",
                        "Delaunay triangulation of points: globemesh triangulate POINTS -o OUT.nc");
    app->add_subcommand(
        "convert", "Convert a UGRID mesh: globemesh convert IN.nc OUT.msh|fort.14|... [-o OUT]");
    app->add_subcommand("info", "Statistics of a UGRID mesh file: globemesh info MESH.nc [--json]");
    app->add_subcommand("help", "Help on globemesh or one subcommand: globemesh help [SUBCOMMAND]");
    app->require_subcommand(1);
    return app;
}

int run_help(std::span<const std::string> args, std::ostream &out) {
    if (args.empty()) {
        out << make_top_app()->help();
        return 0;
    }
    if (args.size() > 1)
        throw UsageError("help takes one subcommand name, e.g. globemesh help mesh");
    if (args[0] == "mesh") {
        MeshCommand c;
        out << c.app.help();
    } else if (args[0] == "triangulate") {
        TriangulateCommand c;
        out << c.app.help();
    } else if (args[0] == "convert") {
        ConvertCommand c;
        out << c.app.help();
    } else if (args[0] == "info") {
        InfoCommand c;
        out << c.app.help();
    } else if (args[0] == "help") {
        out << make_top_app()->help();
    } else {
        throw UsageError("help: unknown subcommand '" + args[0] +
                         "' (the subcommands are mesh, triangulate, convert, info, help)");
    }
    return 0;
}

int dispatch(std::span<const std::string> args, std::ostream &out, std::ostream &err,
             TerminalProgress &terminal, const CliLibrary &lib) {
    if (args.empty())
        throw UsageError("no subcommand given: run 'globemesh help' (e.g. globemesh mesh --coast "
                         "land.gpkg -o ocean.nc)");
    const std::string &name = args[0];
    const auto rest = args.subspan(1);
    if (name == "mesh")
        return run_mesh(rest, out, err, terminal, lib);
    if (name == "triangulate")
        return run_triangulate(rest, out, err, terminal, lib);
    if (name == "convert")
        return run_convert(rest, out, err, terminal, lib);
    if (name == "info")
        return run_info(rest, out, lib);
    if (name == "help")
        return run_help(rest, out);
    if (!name.empty() && name[0] != '-')
        throw UsageError("unknown subcommand '" + name +
                         "' (the subcommands are mesh, triangulate, convert, info, help)");
    auto top = make_top_app();
    try {
        top->parse(reversed(args));
    } catch (const CLI::CallForHelp &) {
        out << top->help();
        return 0;
    } catch (const CLI::CallForAllHelp &) {
        out << top->help();
        return 0;
    } catch (const CLI::CallForVersion &) {
        out << version_text() << "\n";
        return 0;
    } catch (const CLI::ParseError &) {
        throw UsageError("unknown option '" + name +
                         "' (globemesh takes --help, --version or a subcommand: mesh, triangulate, "
                         "convert, info, help)");
    }
    return 0; // unreachable: a subcommand name would have been dispatched above
}

} // namespace

CliOptions parse_mesh_args(std::span<const std::string> args) {
    auto command = std::make_unique<MeshCommand>();
    try {
        command->parse(args);
    } catch (const CLI::ParseError &e) {
        throw UsageError(usage_text(e, "mesh"));
    }
    return command->o;
}

int run_cli(std::span<const std::string> args, std::ostream &out, std::ostream &err,
            const CliLibrary &library) {
    TerminalProgress terminal(err);
    InterruptGuard::forget(); // a signal of an earlier run in this process
    try {
        return dispatch(args, out, err, terminal, library);
    } catch (...) {
        terminal.end_line();
        const bool sub = !args.empty() && (args[0] == "mesh" || args[0] == "info" ||
                                           args[0] == "triangulate" || args[0] == "convert");
        return report_error(err, sub ? args[0] : std::string());
    }
}

namespace {

/// Maps the exception in flight to one line on err and the exit status.
int report_error(std::ostream &err, const std::string &command) {
    bool usage = false;
    try {
        throw;
    } catch (const CLI::ParseError &) {
        usage = true;
    } catch (const UsageError &) {
        usage = true;
    } catch (...) {
    }
    // After a cancelling signal any other failure is the run stopping: a GEOS or GDAL call
    // interrupted fails in its own words.
    if (InterruptGuard::signal() != 0 && !usage) {
        // A signal other than Ctrl-C is named: it may come from a batch scheduler's time limit.
        const int signal = InterruptGuard::signal();
        const char *by = signal == SIGTERM ? " by SIGTERM" : signal == SIGHUP ? " by SIGHUP" : "";
        err << "globemesh: cancelled" << by << ", no output written\n";
        return 1;
    }
    try {
        throw;
    } catch (const CLI::ParseError &e) {
        err << "globemesh: " << usage_text(e, command) << "\n";
        return 2;
    } catch (const UsageError &e) {
        err << "globemesh: " << one_line(e.message(flag_of)) << "\n";
        return 2;
    } catch (const Cancelled &e) {
        err << "globemesh: cancelled, no output written\n"; // by the library's caller, not a signal
        return 1;
    } catch (const Error &e) {
        err << "globemesh: " << one_line(e.message(flag_of)) << "\n";
        return 1;
    } catch (const std::exception &e) {
        err << "globemesh: internal error: " << one_line(e.what()) << "\n";
        return 1;
    } catch (...) {
        err << "globemesh: internal error: unknown exception\n";
        return 1;
    }
}

} // namespace

} // namespace globemesh
