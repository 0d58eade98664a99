// The `mesh` subcommand's options, one function per group of --help, and their parsing.
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include <CLI/CLI.hpp>

#include "cli_common.hpp"
#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/bathymetry.hpp"
#include "globemesh/error.hpp"
#include "globemesh/options.hpp"
#include "option_flags.hpp"

namespace globemesh::cli {

/// --preview-region's W,S,E,N, checked as --region is (W > E crosses +-180); one-line
/// UsageError otherwise.
std::array<double, 4> checked_preview_region(const std::vector<double> &r) {
    const std::string flag = "--preview-region: ";
    if (!std::all_of(r.begin(), r.end(), [](double v) { return std::isfinite(v); }))
        throw UsageError(flag + "values must be numbers: W,S,E,N in degrees");
    if (r[0] < -180 || r[0] > 180 || r[2] < -180 || r[2] > 180)
        throw UsageError(flag + "longitudes W and E must be in [-180, 180]");
    if (!(r[1] >= -90 && r[3] <= 90 && r[1] < r[3]))
        throw UsageError(flag + "needs -90 <= S < N <= 90 (W,S,E,N in degrees)");
    if (r[0] == r[2])
        throw UsageError(flag + "W and E must differ (W > E crosses +-180)");
    return {r[0], r[1], r[2], r[3]};
}

namespace {

/// --seed's check: CLI11 alone wraps -1 and saturates 2^70 into the unsigned 64-bit field.
CLI::Validator seed_check() {
    return CLI::Validator(
        [](std::string &value) -> std::string {
            std::uint64_t seed = 0;
            const char *end = value.data() + value.size();
            const auto [last, ec] = std::from_chars(value.data(), end, seed);
            if (value.empty() || ec != std::errc() || last != end)
                return "'" + value + "' is not a whole number in 0.." +
                       std::to_string(std::numeric_limits<std::uint64_t>::max());
            return {};
        },
        "");
}

} // namespace

std::vector<std::pair<std::string, std::string>> mesh_input_files(const CliOptions &o) {
    return {{"--coast", o.mesh.coast},
            {"--bathy", o.mesh.bathy},
            {"--region-file", o.mesh.region_file},
            {"--size-regions", o.mesh.size_regions},
            {"--passages", o.mesh.passages},
            {"--config", o.config}};
}

MeshCommand::MeshCommand(std::span<const Writer> table) {
    app.option_defaults()->always_capture_default();
    app.set_version_flag("--version", version_text(), "Print the version and exit");
    app.get_formatter()->column_width(36);
    app.footer("Lengths: 20km, 5000m or 20 (km). Areas: 1000km2, 1e6m2 or 1000 (km2). Durations: "
               "12.42h,\n"
               "745min, 44712s or 12.42 (h). Depths: 50m, 0.05km or 50 (m). See globemesh(1).\n");
    add_coast_options("Coastline");
    add_bathy_options("Bathymetry");
    add_size_options("Size field");
    add_mesher_options("Mesher");
    add_output_options(table, "Output");
    add_run_options("Run");
}

void MeshCommand::add_coast_options(const std::string &coast) {
    MeshOptions &m = o.mesh;
    app.add_option("--coast", m.coast,
                   "Land polygons or coast lines: any OGR vector source (required)")
        ->group(coast)
        ->type_name("SOURCE");
    app.add_option("--coast-layer", m.coast_layer,
                   "Layer of --coast; default the only polygon or line layer")
        ->group(coast)
        ->type_name("NAME");
    app.add_option("--coast-where", m.coast_where,
                   "OGR SQL attribute filter on --coast; default none")
        ->group(coast)
        ->type_name("SQL");
    app.add_option("--coast-srs", m.coast_srs,
                   "CRS of a --coast layer that declares none, e.g. EPSG:4326 (a declared one "
                   "is not overridden)")
        ->group(coast)
        ->type_name("SRS");
    region_opt =
        app.add_option("--region", region,
                       "Region W,S,E,N in degrees (W > E crosses 180); default the whole globe")
            ->group(coast)
            ->type_name("W,S,E,N")
            ->delimiter(',')
            ->expected(4);
    region_opt->always_capture_default(false)->default_str("")->run_callback_for_default(
        false); // no region: the globe
    app.add_option("--region-file", m.region_file,
                   "Polygons or closed lines (any OGR source, any CRS) bounding the ocean")
        ->group(coast)
        ->type_name("SOURCE");
    app.add_option("--region-layer", m.region_layer,
                   "Layer of --region-file; default the only polygon or line layer")
        ->group(coast)
        ->type_name("NAME");
    app.add_option("--min-island-area", m.min_island_area_km2,
                   "Drop islands and lakes smaller than AREA (km2 or m2; bare number: km2)")
        ->group(coast)
        ->type_name("AREA")
        ->transform(unit_transform(parse_area_km2, ""));
    app.add_flag("--keep-inland-seas", m.keep_inland_seas,
                 "Keep water bodies not connected to the ocean")
        ->group(coast);
    app.add_flag("--keep-straits", m.keep_straits,
                 "Keep straits narrower than a triangle open, their triangles centred on land")
        ->group(coast);
}

void MeshCommand::add_bathy_options(const std::string &bathy) {
    MeshOptions &m = o.mesh;
    app.add_option("--bathy", m.bathy, "Elevation (or depth) raster: any GDAL raster; default none")
        ->group(bathy)
        ->type_name("RASTER");
    app.add_option("--bathy-band", m.bathy_band, "1-based band of --bathy")
        ->group(bathy)
        ->type_name("N");
    app.add_option("--bathy-srs", m.bathy_srs,
                   "CRS of --bathy, replacing the file's (e.g. EPSG:4326); default the file's")
        ->group(bathy)
        ->type_name("SRS")
        ->check(CLI::Validator(
            [](std::string &value) -> std::string {
                try {
                    validate_bathy_srs(value);
                    return {};
                } catch (const UsageError &e) { // CLI11 puts the option's name in front
                    return e.text().after_leading_option().str(flag_of);
                }
            },
            ""));
    app.add_flag("--depth-positive", m.depth_positive, "The raster stores depth, positive down")
        ->group(bathy);
    bathy_fill_opt =
        app.add_option("--bathy-fill", bathy_fill_m,
                       "Depth where the raster has no data (m or km; bare number: m); default none")
            ->group(bathy)
            ->type_name("DEPTH")
            ->transform(unit_transform(parse_depth_m, ""));
    bathy_fill_opt->always_capture_default(false)->default_str("")->run_callback_for_default(
        false); // unset: no fill
    min_depth_opt = app.add_option("--min-depth", min_depth_m,
                                   "Raise nodes shallower than DEPTH to DEPTH (m or km, "
                                   "positive down); default none")
                        ->group(bathy)
                        ->type_name("DEPTH")
                        ->transform(unit_transform(parse_depth_m, ""));
    min_depth_opt->always_capture_default(false)->default_str("")->run_callback_for_default(
        false); // unset: as sampled
}

void MeshCommand::add_size_options(const std::string &size) {
    MeshOptions &m = o.mesh;
    app.add_option("--hmax", m.hmax_km,
                   "Largest edge length (km or m; bare number: km); alone gives a uniform mesh")
        ->group(size)
        ->type_name("LENGTH")
        ->transform(unit_transform(parse_length_km, ""));
    app.add_option("--hmin", m.hmin_km,
                   "Smallest edge length (km or m); 0: a floor of max(hmax/1000, 10 m)")
        ->group(size)
        ->type_name("LENGTH")
        ->transform(unit_transform(parse_length_km, ""));
    app.add_option("--coast-size", m.coast_size_km, "Edge length at the coast (km or m); 0: off")
        ->group(size)
        ->type_name("LENGTH")
        ->transform(unit_transform(parse_length_km, ""));
    app.add_option("--coast-rate", m.coast_rate,
                   "Growth of the edge length with distance from the coast (km/km)")
        ->group(size)
        ->type_name("RATE");
    app.add_option("--wavelength", m.wavelength, "Points per wavelength of the tide; 0: off")
        ->group(size)
        ->type_name("N");
    app.add_option("--wave-period", m.wave_period_h,
                   "Period of that wave (h, min or s; bare number: h; M2)")
        ->group(size)
        ->type_name("DURATION")
        ->transform(unit_transform(parse_duration_h, ""));
    app.add_option("--slope", m.slope, "Points per topographic length scale; 0: off")
        ->group(size)
        ->type_name("N");
    app.add_option(
           "--feature-size", m.feature_size,
           "Elements across every channel, from the coast's medial axis (3 as OceanMesh2D); 0: off")
        ->group(size)
        ->type_name("N");
    app.add_option("--size-regions", m.size_regions,
                   "Polygons with a size_km attribute: edge length inside")
        ->group(size)
        ->type_name("SOURCE");
    app.add_option("--size-regions-layer", m.size_regions_layer,
                   "Layer of --size-regions; default every layer with a size_km field")
        ->group(size)
        ->type_name("NAME");
    app.add_option("--passages", m.passages,
                   "Lines across straits kept open (any OGR source), or 'default': the world's "
                   "critical passages")
        ->group(size)
        ->type_name("SOURCE");
    app.add_option("--passages-layer", m.passages_layer, "Layer of --passages; default every layer")
        ->group(size)
        ->type_name("NAME");
    app.add_option("--passage-cells", m.passage_cells,
                   "Edges across each passage's water (its width / N there, even below --hmin)")
        ->group(size)
        ->type_name("N");
    app.add_option("--grade", m.grade, "Largest |grad h|, the gradation of edge lengths (km/km)")
        ->group(size)
        ->type_name("G");
}

void MeshCommand::add_mesher_options(const std::string &mesher) {
    MeshOptions &m = o.mesh;
    app.add_option("--max-nodes", m.max_nodes, "Refuse runs estimated to give more nodes")
        ->group(mesher)
        ->type_name("N")
        ->transform(count_transform());
    // Kept as text ("auto", "4GB") so that --print-config and the mesh's configuration say
    // what was asked, not this machine's memory; converted in parse(). "auto" is 3/4 of the
    // physical memory, read here: the library reads no system state.
    app.add_option("--max-memory", max_memory_text,
                   "Refuse runs estimated to need more memory (B, kB, MB, GB or KiB..TiB; bare: "
                   "bytes; 0: no limit; auto: 3/4 of the physical memory)")
        ->group(mesher)
        ->type_name("SIZE")
        ->check(CLI::Validator(
            [](std::string &value) -> std::string {
                try {
                    if (value != "auto")
                        parse_memory_bytes(value);
                    return {};
                } catch (const UsageError &e) {
                    return e.what();
                }
            },
            ""));
    app.add_option("--inlet-width", m.inlet_width,
                   "Close inlets narrower than F times the edge length at their mouth (0: none)")
        ->group(mesher)
        ->type_name("F");
    app.add_option("--smooth", m.smooth_iterations, "Smoothing/relaxation sweeps")
        ->group(mesher)
        ->type_name("N");
    app.add_option("--seed", m.seed, "Seed of every pseudo-random choice")
        ->group(mesher)
        ->type_name("N")
        ->check(seed_check());
    app.add_option("--parts", m.parts,
                   "Mesh N lunes apart and join them (1..6; the mesh depends on N; 0, the default: "
                   "2 for a global mesh of 2e6 nodes or more, else 1)")
        ->group(mesher)
        ->type_name("N");
    app.add_option("--parts-border", m.parts_border_lon,
                   "Longitude of the parts' first border, degrees (default: chosen from the "
                   "inputs, where the parts' work balances and the borders pass the coast least "
                   "closely)")
        ->group(mesher)
        ->type_name("LON");
    app.add_option("--threads", m.threads,
                   "Threads meshing the parts (0: one per core; never changes the mesh)")
        ->group(mesher)
        ->type_name("N");
}

void MeshCommand::add_output_options(std::span<const Writer> table, const std::string &output) {
    add_output_flags(app, o.output, o.output_format, o.creation_options, table, output);
    add_model_flags(app, o.output_srs, o.msh_version, table, output);
    app.add_option("--gpkg", o.gpkg, "Also write a GeoPackage (faces, nodes, boundary, mesh_info)")
        ->group(output)
        ->type_name("OUT.gpkg");
    app.add_option("--preview", o.preview,
                   "Also draw the mesh over the land as a PNG (its edges when 4+ pixels long)")
        ->group(output)
        ->type_name("OUT.png");
    preview_region_opt = app.add_option("--preview-region", preview_region,
                                        "Region W,S,E,N in degrees the PNG shows (W > E crosses "
                                        "180); default the --region, else the mesh's extent")
                             ->group(output)
                             ->type_name("W,S,E,N")
                             ->delimiter(',')
                             ->expected(4);
    preview_region_opt->always_capture_default(false)->default_str("")->run_callback_for_default(
        false); // no region: the mesh's extent
    app.add_option(
           "--format", o.format,
           "NetCDF flavour of UGRID outputs: netcdf4 (deflate) or classic (= --co FORMAT=NC2)")
        ->group(output)
        ->type_name("FORMAT")
        ->check(CLI::IsMember({"netcdf4", "classic"}));
    app.add_option("--timings", o.timings, "Write the seconds per stage as JSON")
        ->group(output)
        ->type_name("FILE.json");
    app.add_option("--report", o.report, "Write the run summary and quality histogram as JSON")
        ->group(output)
        ->type_name("FILE.json");
    app.add_flag("--overwrite", o.overwrite, "Replace existing output files")->group(output);
}

void MeshCommand::add_run_options(const std::string &run) {
    app.set_config("--config", "",
                   "Read options from a TOML or INI file (keys: the long option names)")
        ->group(run)
        ->type_name("FILE");
    app.add_flag("--print-config", o.print_config,
                 "Print the effective configuration (for --config) and stop")
        ->group(run)
        ->configurable(false);
    // Not CLI11's excludes(): --print-config writes both as false, and must read back.
    app.add_flag("-q,--quiet", o.quiet, "No progress or warnings on stderr (not with --verbose)")
        ->group(run);
    app.add_flag("-v,--verbose", o.verbose, "Show stage names with the progress, and GDAL warnings")
        ->group(run);
    app.add_flag("--check", o.check,
                 "Check the mesh invariants before writing (exit 1 if one fails)")
        ->group(run);
}

void MeshCommand::parse(std::span<const std::string> args) {
    // A key of the config file that names no option is an error, not ignored: a typo
    // (hmaxx) or a [section] would otherwise mesh at the defaults without a word.
    app.allow_config_extras(CLI::config_extras_mode::error);
    try {
        app.parse(reversed(args));
    } catch (const CLI::ConfigError &e) {
        const std::string what = e.what(),
                          prefix = "INI was not able to parse "; // CLI11's ConfigError::Extras
        if (what.rfind(prefix, 0) != 0)
            throw;
        const std::string key = what.substr(prefix.size()),
                          file = app.get_config_ptr()->as<std::string>();
        if (const auto dot = key.find('.'); dot != std::string::npos)
            throw UsageError("--config " + file + ": [" + key.substr(0, dot) +
                             "]: the file takes no sections, only option = value lines");
        std::string dashed = key;
        std::replace(dashed.begin(), dashed.end(), '_', '-');
        const std::string hint =
            dashed != key && app.get_option_no_throw("--" + dashed) != nullptr
                ? "; did you mean " + dashed + "?"
                : "; the keys are the long option names, as --print-config writes them";
        throw UsageError("--config " + file + ": unknown key " + key + hint);
    }
    std::erase(o.output, std::string()); // output = "" (as --print-config shows none) is none
    if (const CLI::Option *config = app.get_config_ptr(); config != nullptr && config->count() > 0)
        o.config = config->as<std::string>();
    if (region_opt->count() > 0 && region.size() == 4)
        o.mesh.region = std::array<double, 4>{region[0], region[1], region[2], region[3]};
    if (preview_region_opt->count() > 0 && preview_region.size() == 4)
        o.preview_region = checked_preview_region(preview_region);
    if (bathy_fill_opt->count() > 0)
        o.mesh.bathy_fill_m = bathy_fill_m;
    if (min_depth_opt->count() > 0)
        o.mesh.min_depth_m = min_depth_m;
    o.mesh.max_memory_bytes = max_memory_text == "auto" ? default_memory_budget_bytes()
                                                        : parse_memory_bytes(max_memory_text);
    if (o.quiet && o.verbose)
        throw UsageError("--quiet and --verbose exclude each other");
}

} // namespace globemesh::cli
