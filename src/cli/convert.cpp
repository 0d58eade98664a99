// `globemesh convert`: reads a UGRID mesh (ours or another tool's) or an ADCIRC/SCHISM grid
// (fort.14, .gr3, .ll, by its name) and writes it through the
// writers table, as `mesh` writes its outputs (-o, -f, --co, --overwrite, all or nothing).
#include <algorithm>
#include <array>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesh_read.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"

namespace globemesh::cli {

ConvertCommand::ConvertCommand(std::span<const Writer> table) {
    app.set_version_flag("--version", version_text(), "Print the version and exit");
    app.get_formatter()->column_width(36);
    app.add_option("IN", input,
                   "UGRID NetCDF mesh (ours or another tool's, 0- or 1-based), an ADCIRC/SCHISM "
                   "grid named fort.14, *.14, *.gr3 or *.ll, or a gmsh *.msh (ASCII 4.1 or 2.2)")
        ->required()
        ->type_name("IN.nc");
    app.add_option("OUT", positional, "Files to write, as -o gives them (either or both)")
        ->type_name("OUT");
    add_output_flags(app, output, format, creation, table, "Options");
    add_model_flags(app, output_srs, msh_version, table, "Options");
    preview_region_opt = app.add_option("--preview-region", preview_region,
                                        "Region W,S,E,N in degrees a .png output shows (W > E "
                                        "crosses 180); default the mesh's extent")
                             ->type_name("W,S,E,N")
                             ->delimiter(',')
                             ->expected(4);
    app.add_flag("--overwrite", overwrite, "Replace existing output files");
    app.add_flag("-q,--quiet", quiet, "No progress on stderr");
}

namespace {

/// A node field that another tool's file holds the depth in (positive down), named "depth" as
/// the writers look for it: CF's sea_floor_depth standard names, or an altitude (positive up)
/// negated. Our own files already name it "depth".
void name_depth(Mesh &mesh) {
    if (mesh.node_field("depth") != nullptr)
        return;
    const auto named = [&](auto &&test) -> const Field * {
        for (const Field &f : mesh.node_fields)
            if (test(f.standard_name))
                return &f;
        return nullptr;
    };
    const Field *depth =
        named([](const std::string &s) { return s.rfind("sea_floor_depth", 0) == 0; });
    const Field *altitude = named([](const std::string &s) { return s == "altitude"; });
    if (depth == nullptr && altitude == nullptr)
        return;
    Field d = depth != nullptr ? *depth : *altitude;
    d.name = "depth";
    d.standard_name = "sea_floor_depth_below_geoid";
    if (depth == nullptr)
        for (double &x : d.values)
            x = -x;
    mesh.node_fields.push_back(std::move(d));
}

/// --preview-region's W,S,E,N when given, checked, with a PNG output to zoom.
std::optional<std::array<double, 4>> preview_region(const ConvertCommand &c,
                                                    std::span<const PlannedOutput> planned) {
    if (c.preview_region_opt->count() == 0)
        return std::nullopt;
    const auto region = checked_preview_region(c.preview_region);
    if (std::none_of(planned.begin(), planned.end(),
                     [](const auto &p) { return p.request.writer->name == "PNG"; }))
        throw UsageError("--preview-region zooms the PNG picture: give an OUT.png too");
    return region;
}

} // namespace

int run_convert(std::span<const std::string> args, std::ostream &out, std::ostream &err,
                TerminalProgress &terminal, const CliLibrary &lib) {
    auto command = std::make_unique<ConvertCommand>(lib.writers);
    if (printed_help(command->app, out, [&] { command->app.parse(reversed(args)); }))
        return 0;
    auto &c = *command;
    c.output.insert(c.output.end(), c.positional.begin(), c.positional.end());
    if (c.output.empty())
        throw UsageError("convert: give the file to write, e.g. globemesh convert in.nc fort.14");
    check_input_path(c.input, "IN");
    const OutputChoices choices{c.output, c.format, c.creation, {}};
    // Whether IN holds depths is known once it is read: write_outputs refuses a format that
    // needs them then (DataError), before writing anything.
    const auto planned =
        plan_outputs(choices, lib.writers, msh_version_creation(c.msh_version, c.creation), true);
    check_output_srs(c.output_srs, requests(planned));
    const auto region = preview_region(c, planned);
    const std::pair<std::string, std::string> inputs[] = {{"IN", c.input}};
    check_output_files(output_files(planned, "", "", lib.writers), inputs, c.overwrite);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, false);
    terminal.configure(c.quiet, false);
    Mesh mesh = is_adcirc_name(c.input) ? lib.read_adcirc(c.input)
                : is_gmsh_name(c.input) ? lib.read_gmsh(c.input)
                                        : lib.read_ugrid(c.input);
    name_depth(mesh);
    throw_if_interrupted();
    OutputBatch batch; // every output waits under its temporary name until all are complete
    WriteOptions write;
    write.overwrite = c.overwrite;
    write.title =
        "globemesh mesh converted from " + std::filesystem::path(c.input).filename().string();
    write.history = history_text("convert", args);
    write.output_srs = c.output_srs;
    write.extent_deg = region;
    write_run_outputs(mesh, planned, write, terminal);
    terminal.finish();
    InterruptGuard::completing();
    batch.commit(InterruptGuard::interrupted);
    const auto coast = std::count_if(mesh.boundary.begin(), mesh.boundary.end(),
                                     [](const BoundaryEdge &e) { return e.tag == EdgeTag::coast; });
    out << "nodes             " << mesh.nodes.size() << "\n"
        << "faces             " << mesh.faces.size() << "\n"
        << "boundary edges    " << mesh.boundary.size() << " (" << coast << " coast, "
        << mesh.boundary.size() - std::size_t(coast) << " open)\n"
        << "written           " << outputs_text(planned, &mesh) << "\n";
    return 0;
}

} // namespace globemesh::cli
