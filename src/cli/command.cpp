// globemesh/command.hpp: the `mesh` and `triangulate` runs and the outputs of the command line
// for bindings, by the command line's own parser, checks, reports and writers.
#include "globemesh/command.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <utility>

#include "cli_common.hpp"
#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "face_area.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/writers.hpp"
#include "mesh_summary.hpp"
#include "mesh_topology.hpp"
#include "option_flags.hpp"

namespace globemesh::command {

namespace fs = std::filesystem;

namespace {

/// Whether mesh() takes this option of `globemesh mesh`: all but the outputs (those are
/// write()'s) and the terminal's.
bool binding_takes(const CLI::Option &option) {
    const std::string name = option.get_lnames().empty() ? "" : option.get_lnames().front();
    return option.get_group() != "Output" && !name.empty() && name != "help" && name != "version" &&
           name != "quiet" && name != "verbose" && name != "print-config";
}

/// The inputs that must be readable files, as `globemesh mesh` checks them before any run.
void check_inputs(const CliOptions &o) {
    if (o.mesh.coast.empty())
        throw UsageError(
            "--coast is required: land polygons or coast lines, e.g. --coast land.gpkg");
    for (const auto &[name, path] : cli::mesh_input_files(o))
        cli::check_input_path(path, name);
}

/// The run's mesh, checked when --check asks, with its statistics in `stats`.
OceanMesh mesh_and_check(const CliOptions &o, const Progress &progress, StageTimings &timings,
                         MeshStats &stats) {
    OceanMesh run = mesh_ocean(o.mesh, progress, &timings);
    if (o.check) {
        const auto problems = check_mesh(run.mesh);
        if (!problems.empty())
            throw DataError("--check: the mesh breaks " + std::to_string(problems.size()) +
                            (problems.size() >= 20 ? "+" : "") + " invariants, first: " +
                            problems.front() + "; please report this with the command line");
    }
    stats = compute_stats(run.mesh);
    return run;
}

/// Each face's geodesic area (m2) as the UGRID writer computes it.
std::vector<double> face_areas(const io::MeshTopology &topo, std::size_t faces) {
    const io::GeodesicFaceAreas areas(topo);
    std::vector<std::int32_t> edges;
    io::face_edges(topo, 0, faces, edges);
    std::vector<double> m2(faces);
    for (std::size_t f = 0; f < faces; ++f)
        m2[f] = areas.face_m2(f, &edges[3 * f]);
    return m2;
}

/// The edges, their tags and the boundary as the UGRID file numbers them.
void edge_arrays(const io::MeshTopology &topo, Arrays &a) {
    a.edges.resize(topo.edge_count());
    for (std::size_t e = 0; e < topo.edge_count(); ++e)
        a.edges[e] = topo.edge_nodes(e);
    a.edge_tags.assign(topo.edge_count(), std::int32_t(EdgeTag::interior));
    for (std::size_t i = 0; i < topo.boundary_edges.size(); ++i) {
        const auto e = std::size_t(topo.boundary_edges[i]);
        a.edge_tags[e] = topo.boundary_tags[i];
        a.boundary.push_back(topo.edge_nodes(e));
        a.boundary_tags.push_back(topo.boundary_tags[i]);
    }
}

} // namespace

std::vector<Keyword> mesh_keywords() {
    cli::MeshCommand command;
    std::vector<Keyword> keywords;
    for (const CLI::Option *option : command.app.get_options()) {
        if (!binding_takes(*option))
            continue;
        std::string name = option->get_lnames().front();
        std::replace(name.begin(), name.end(), '-', '_');
        keywords.push_back({name, option->get_expected_max() == 0, option->get_expected_max()});
    }
    return keywords;
}

Run mesh(std::span<const std::string> args, const Progress &progress) {
    cli::MeshCommand command;
    try {
        command.parse(args);
    } catch (const CLI::ParseError &e) {
        throw UsageError(cli::usage_text(e, "mesh"));
    }
    if (command.o.mesh.passages == "default") // as `globemesh mesh` resolves it
        command.o.mesh.passages = cli::default_passages_path();
    const CliOptions &o = command.o;
    validate(o.mesh);
    check_inputs(o);
    Run result;
    // Outputs only a --config file can name here: mesh() writes none, which is said.
    std::string outputs;
    for (const CLI::Option *option : command.app.get_options())
        if (option->get_group() == "Output" && option->count() > 0)
            outputs += (outputs.empty() ? "" : ", ") + option->get_name();
    if (!outputs.empty())
        result.warnings.push_back("--config " + o.config + " names outputs (" + outputs +
                                  ") that mesh_ocean() does not write: "
                                  "write them with its result's write()");
    StageTimings timings;
    const auto t0 = std::chrono::steady_clock::now();
    // The check and the statistics after the run take the last hundredth of the progress.
    OceanMesh run = mesh_and_check(o, sub_progress(progress, 0, 0.99), timings, result.stats);
    // The effective configuration travels with the mesh, as the command line's files carry it.
    run.mesh.attributes.emplace_back(
        "globemesh_configuration", cli::file_configuration(command.app.config_to_str(true, false)));
    result.history = cli::history_text("mesh", args);
    cli::MeshRunSummary summary{o, {}, result.stats, run, timings, result.history};
    summary.total_s = cli::seconds_since(t0);
    summary.peak = cli::peak_memory_bytes();
    result.report_json = cli::report_json(summary);
    // The summary's warnings, as the command line prints them on stderr.
    std::ostringstream summary_out, summary_err;
    cli::print_mesh_summary(summary_out, summary_err, summary);
    const std::string prefix = "globemesh: warning: ";
    std::istringstream lines(summary_err.str());
    for (std::string line; std::getline(lines, line);)
        if (line.rfind(prefix, 0) == 0)
            result.warnings.push_back(line.substr(prefix.size()));
    // Inputs named by files absolute, as a later chdir would otherwise move them (a data set
    // GDAL opens by another name, e.g. PG:..., stays as given).
    auto absolute = [](const std::string &path) {
        std::error_code ec;
        return !path.empty() && fs::exists(path, ec) ? fs::absolute(path).string() : path;
    };
    result.land = absolute(o.mesh.coast);
    result.extent_deg = o.mesh.region;
    for (const auto &[name, path] :
         {std::pair<const char *, const std::string &>{"coast", o.mesh.coast},
          {"bathy", o.mesh.bathy},
          {"region_file", o.mesh.region_file},
          {"size_regions", o.mesh.size_regions},
          {"passages", o.mesh.passages}})
        if (!path.empty())
            result.inputs.emplace_back(name, absolute(path));
    result.mesh = std::move(run.mesh);
    report(progress, 1.0, "statistics");
    return result;
}

Run triangulate(std::vector<Vec3> points, const Progress &progress) {
    Run result;
    result.mesh = triangulate_points(std::move(points), TriangulateOptions{}, progress);
    result.stats = compute_stats(result.mesh);
    result.history = cli::history_text("triangulate", std::vector<std::string>{"(Python)"});
    result.title = "globemesh spherical Delaunay triangulation"; // as `globemesh triangulate`
    result.report_json = "{\"mesh\": " + cli::stats_json(result.stats, "") + "}";
    return result;
}

void write(const Run &run, const Outputs &outputs, const Progress &progress) {
    const auto &table = writers();
    const cli::OutputChoices choices{outputs.paths, outputs.format, outputs.creation, {}};
    const auto planned =
        cli::plan_outputs(choices, table, {}, run.mesh.node_field("depth") != nullptr);
    const std::vector<OutputRequest> requests = cli::requests(planned);
    check_output_srs(outputs.output_srs, requests);
    cli::check_output_files(cli::output_files(planned, "", "", table), run.inputs,
                            outputs.overwrite);
    WriteOptions options;
    options.overwrite = outputs.overwrite;
    options.history = run.history;
    if (!run.title.empty())
        options.title = run.title;
    options.stats = &run.stats;
    options.land = run.land;
    options.extent_deg = run.extent_deg;
    options.output_srs = outputs.output_srs;
    options.progress = progress;
    write_outputs(run.mesh, requests, options);
}

std::string error_message(const Error &e) {
    return cli::one_line(e.message(cli::flag_of));
}

Arrays ugrid_arrays(const Mesh &mesh) {
    Arrays a;
    const io::MeshTopology topo = io::build_topology(mesh);
    for (const Vec3 &p : mesh.nodes) {
        const LonLat ll = vec_to_lonlat(p);
        a.lon.push_back(ll.lon);
        a.lat.push_back(ll.lat);
    }
    edge_arrays(topo, a);
    for (const auto &f : mesh.faces)
        a.quality.push_back(triangle_quality(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]));
    a.area_m2 = face_areas(topo, mesh.faces.size());
    return a;
}

} // namespace globemesh::command
