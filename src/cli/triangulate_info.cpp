// `globemesh triangulate` and `globemesh info`: their options and their runs.
#include <chrono>
#include <memory>
#include <span>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"

namespace globemesh::cli {

// --------------------------------------------------------------------------------------------
// globemesh triangulate

TriangulateCommand::TriangulateCommand(std::span<const Writer> table) {
    app.option_defaults()->always_capture_default();
    app.set_version_flag("--version", version_text(), "Print the version and exit");
    app.get_formatter()->column_width(36);
    app.add_option("POINTS", t.points,
                   "Points: CSV with lon/lat columns, GeoPackage, shapefile, ...")
        ->required()
        ->type_name("SOURCE");
    add_output_flags(app, output, format, creation, table, "Options");
    app.add_option("--gpkg", gpkg, "Also write a GeoPackage")->type_name("OUT.gpkg");
    app.add_option("--layer", t.layer, "Layer of POINTS; default the first layer")
        ->type_name("NAME");
    app.add_option("--timings", timings, "Write the seconds per stage as JSON")
        ->type_name("FILE.json");
    app.add_flag("--overwrite", overwrite, "Replace existing output files");
    app.add_flag("-q,--quiet", quiet, "No progress on stderr (not with --verbose)");
    app.add_flag("-v,--verbose", verbose, "Show stage names with the progress");
}

int run_triangulate(std::span<const std::string> args, std::ostream &out, std::ostream &err,
                    TerminalProgress &terminal, const CliLibrary &lib) {
    auto command = std::make_unique<TriangulateCommand>(lib.writers);
    if (printed_help(command->app, out, [&] { command->app.parse(reversed(args)); }))
        return 0;
    const auto &c = *command;
    if (c.quiet && c.verbose)
        throw UsageError("--quiet and --verbose exclude each other");
    if (c.output.empty())
        throw UsageError("-o/--output is required: the UGRID file to write, e.g. -o out.nc");
    check_input_path(c.t.points, "POINTS");
    const OutputChoices choices{c.output, c.format, c.creation, {{"--gpkg", "GPKG", c.gpkg}}};
    const auto planned = plan_outputs(choices, lib.writers, {}, false,
                                      "points have none: mesh with a bathymetry (globemesh mesh "
                                      "--bathy) for it");
    const std::pair<std::string, std::string> inputs[] = {{"POINTS", c.t.points}};
    check_output_files(output_files(planned, c.timings, "", lib.writers), inputs, c.overwrite);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, c.verbose);
    const auto t0 = std::chrono::steady_clock::now();
    StageTimings timings;
    terminal.configure(c.quiet, c.verbose);
    Mesh mesh = lib.triangulate_file(c.t, sub_progress(terminal.callback(), 0, mesh_share(planned)),
                                     &timings);
    throw_if_interrupted();
    OutputBatch batch; // every output waits under its temporary name until all are complete
    WriteOptions write;
    write.overwrite = c.overwrite;
    write.title = "globemesh spherical Delaunay triangulation";
    write.history = history_text("triangulate", args);
    write_run_outputs(mesh, planned, write, terminal, &timings);
    terminal.finish();
    timings.add("total", seconds_since(t0));
    if (!c.timings.empty()) {
        OutputFile::write_text(c.timings, timings_json(timings), c.overwrite, "--timings");
    }
    InterruptGuard::completing();
    batch.commit(InterruptGuard::interrupted);
    out << "nodes             " << mesh.nodes.size() << "\n"
        << "faces             " << mesh.faces.size() << "\n";
    print_timings(out, timings);
    return 0;
}

// --------------------------------------------------------------------------------------------
// globemesh info

InfoCommand::InfoCommand() {
    app.set_version_flag("--version", version_text(), "Print the version and exit");
    app.get_formatter()->column_width(36);
    app.add_option("MESH", path, "UGRID NetCDF file (ours or another tool's)")
        ->required()
        ->type_name("MESH.nc");
    app.add_flag("--json", json, "Print JSON for machines");
}

int run_info(std::span<const std::string> args, std::ostream &out, const CliLibrary &lib) {
    InfoCommand command;
    if (printed_help(command.app, out, [&] { command.app.parse(reversed(args)); }))
        return 0;
    check_input_path(command.path, "MESH");
    const MeshStats stats = lib.compute_stats(lib.read_ugrid(command.path));
    if (command.json)
        out << stats_json(stats, "") << "\n";
    else
        print_stats(out, stats, true);
    return 0;
}

} // namespace globemesh::cli
