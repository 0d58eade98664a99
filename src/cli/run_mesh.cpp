// `globemesh mesh`: checks before anything is opened, the run, its outputs and its summary.
#include <algorithm>
#include <chrono>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/error.hpp"
#include "globemesh/options.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "mesh_summary.hpp"
#include "mesh_topology.hpp"

namespace globemesh::cli {

namespace {

/// The checks run_cli makes before anything is opened: library validation, then the outputs'
/// formats and paths. Returns the outputs to write.
std::vector<PlannedOutput> check_mesh_run(const CliOptions &o, std::span<const Writer> table) {
    validate(o.mesh);
    if (o.mesh.coast.empty())
        throw UsageError(
            "--coast is required: land polygons or coast lines, e.g. --coast land.gpkg");
    if (o.output.empty())
        throw UsageError("-o/--output is required: the UGRID file to write, e.g. -o ocean.nc");
    const OutputChoices choices{o.output,
                                o.output_format,
                                o.creation_options,
                                {{"--gpkg", "GPKG", o.gpkg}, {"--preview", "PNG", o.preview}}};
    auto extra_creation = msh_version_creation(o.msh_version, o.creation_options);
    if (o.format == "classic")
        extra_creation.emplace_back("--format classic", "FORMAT=NC2");
    const auto planned = plan_outputs(choices, table, extra_creation, !o.mesh.bathy.empty());
    check_output_srs(o.output_srs, requests(planned));
    if (o.preview_region && std::none_of(planned.begin(), planned.end(), [](const auto &p) {
            return p.request.writer->name == "PNG";
        }))
        throw UsageError("--preview-region zooms the PNG picture: give --preview OUT.png too");
    const auto files = output_files(planned, o.timings, o.report, table);
    const auto inputs = mesh_input_files(o);
    for (const auto &[name, path] : inputs)
        check_input_path(path, name); // (--config was read)
    check_output_files(files, inputs, o.overwrite);
    return planned;
}

/// Adds the `mesh` key of issue 4 (everything from rings and size field to the final mesh,
/// I/O excluded) when the pipeline did not report it: the stages that read no input.
void add_mesh_total(StageTimings &timings) {
    for (const auto &[name, s] : timings.stages)
        if (name == "mesh")
            return;
    timings.add("mesh", timings.compute_seconds());
}

} // namespace

int run_mesh(std::span<const std::string> args, std::ostream &out, std::ostream &err,
             TerminalProgress &terminal, const CliLibrary &lib) {
    auto command = std::make_unique<MeshCommand>(lib.writers);
    if (printed_help(command->app, out, [&] { command->parse(args); }))
        return 0;
    if (command->o.mesh.passages == "default")
        command->o.mesh.passages = default_passages_path();
    const CliOptions &o = command->o;
    if (o.print_config) {
        validate(o.mesh);
        out << command->app.config_to_str(true, true);
        return 0;
    }
    const std::vector<PlannedOutput> planned = check_mesh_run(o, lib.writers);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, o.verbose);
    const auto t0 = std::chrono::steady_clock::now();
    StageTimings timings;
    terminal.configure(o.quiet, o.verbose);
    OceanMesh run =
        lib.mesh_ocean(o.mesh, sub_progress(terminal.callback(), 0, mesh_share(planned)), &timings);
    Mesh &mesh = run.mesh;
    throw_if_interrupted();
    add_mesh_total(timings);
    // The effective configuration travels with the mesh, so the file itself says how to remake it.
    mesh.attributes.emplace_back("globemesh_configuration",
                                 file_configuration(command->app.config_to_str(true, false)));

    if (o.check) {
        auto problems = check_mesh(mesh);
        if (!problems.empty())
            throw DataError("--check: the mesh breaks " + std::to_string(problems.size()) +
                            (problems.size() >= 20 ? "+" : "") + " invariants, first: " +
                            problems.front() + "; please report this with the command line");
    }

    // Computed once for the report and the writers (each would otherwise build the topology
    // again for it), on the topology the writers then share.
    const io::SharedTopology shared(mesh);
    const auto stats_start = std::chrono::steady_clock::now();
    const MeshStats stats = lib.compute_stats(mesh);
    timings.add("statistics", seconds_since(stats_start));
    // Every output of the run waits under its temporary name until all are complete.
    OutputBatch batch;
    WriteOptions write;
    write.overwrite = o.overwrite;
    write.history = history_text("mesh", args);
    write.stats = &stats;
    write.land = o.mesh.coast;
    write.extent_deg = o.preview_region ? o.preview_region : o.mesh.region;
    write.output_srs = o.output_srs;
    write_run_outputs(mesh, planned, write, terminal, &timings);
    terminal.finish(); // close the progress line if a stage stopped short of its share's end
    timings.add("total", seconds_since(t0)); // read to write, what the user waits for

    MeshRunSummary summary{o, planned, stats, run, timings, write.history};
    summary.total_s = timings.stages.back().second;
    summary.peak = peak_memory_bytes();
    if (!o.timings.empty()) {
        OutputFile::write_text(o.timings, timings_json(timings), o.overwrite, "--timings");
    }
    if (!o.report.empty())
        OutputFile::write_text(o.report, report_json(summary), o.overwrite, "--report");
    InterruptGuard::completing();
    batch.commit(InterruptGuard::interrupted);
    print_mesh_summary(out, err, summary);
    return 0;
}

} // namespace globemesh::cli
