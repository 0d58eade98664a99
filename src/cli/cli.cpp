// run_cli(): parsing (CLI11 and config files), validation, progress, outputs, summaries and the
// mapping of errors to exit statuses. One CLI11 App per subcommand, so that `--config` reads a
// flat file whose keys are the long option names (CLI11 reads config files for its top App only).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <cpl_error.h>
#include <gdal.h>

#include "cli_support.hpp"
#include "globemesh/bathymetry.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/error.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/options.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;
using namespace globemesh::cli;

int report_error(std::ostream& err, const std::string& command);

std::string version_text() {
    return std::string("globemesh ") + GLOBEMESH_VERSION + " (GDAL " + GDALVersionInfo("RELEASE_NAME") + ")";
}

/// Shortest text that reads back as the same double.
std::string exact_text(double v) {
    char buffer[32];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, end);
}

/// A CLI11 transform that turns "20km" into "20" (the field's unit), so the bound field, the
/// --help default and --print-config all speak the field's unit.
CLI::Validator unit_transform(double (*parse)(std::string_view), const std::string& name) {
    return CLI::Validator(
        [parse](std::string& value) -> std::string {
            try {
                value = exact_text(parse(value));
                return {};
            } catch (const UsageError& e) {
                return e.what();
            }
        },
        name);
}

/// A CLI11 transform for a count: a whole number, also written as 2e7 (CLI11 alone refuses that
/// with "Could not convert").
CLI::Validator count_transform() {
    return CLI::Validator(
        [](std::string& value) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0' || !(v >= 0 && v <= 9.007199254740992e15) || v != std::floor(v))
                return "'" + value + "' is not a whole number, e.g. 20000000 or 2e7";
            value = std::to_string(static_cast<std::uint64_t>(v));
            return {};
        },
        "");
}

/// CLI11 wants the arguments in reverse order.
std::vector<std::string> reversed(std::span<const std::string> args) {
    return std::vector<std::string>(args.rbegin(), args.rend());
}

/// One line: newlines of multi-line messages (CLI11's) become "; ".
std::string one_line(std::string message) {
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    std::string r;
    for (char c : message) {
        if (c == '\n')
            r += "; ";
        else
            r += c;
    }
    return r;
}

/// CLI11's parse errors in the words of the rest of globemesh's messages, for `command` (mesh,
/// info, triangulate; empty at the top level): an option given twice, an option without its
/// value, an unknown option, a stray argument.
std::string usage_text(const CLI::ParseError& e, const std::string& command) {
    const std::string what = one_line(e.what());
    const std::string help = command.empty() ? "globemesh --help" : "globemesh " + command + " --help";
    const std::size_t colon = what.find(": ");
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&e) && colon != std::string::npos) {
        // "NAME: At Most N required but received M", "NAME: At least N required but received
        // M", "NAME: N required TYPE missing" (CLI11 2.3's words).
        const std::string name = what.substr(0, colon);
        std::istringstream rest(what.substr(colon + 2));
        std::vector<std::string> w;
        for (std::string x; rest >> x;) w.push_back(x);
        if (w.size() == 7 && w[0] == "At" && w[1] == "Most" && w[3] == "required" && w[5] == "received")
            return name + " is given " + w[6] + " times; give it " + (w[2] == "1" ? std::string("once") : "at most " + w[2] + " times");
        if (w.size() == 7 && w[0] == "At" && w[1] == "least" && w[3] == "required" && w[5] == "received")
            return name + " needs " + w[2] + " values, got " + w[6];
        if (w.size() == 4 && w[1] == "required" && w[3] == "missing") return name + " needs a value (" + w[2] + ")";
    }
    if (dynamic_cast<const CLI::ExtrasError*>(&e)) {
        // "The following argument(s) was/were not expected: A B": options first.
        std::istringstream words(colon == std::string::npos ? std::string() : what.substr(colon + 2));
        std::vector<std::string> options, others;
        for (std::string w; words >> w;) (w.size() > 1 && w[0] == '-' ? options : others).push_back(w);
        std::string list;
        for (const auto& w : options.empty() ? others : options) list += (list.empty() ? "" : ", ") + w;
        const std::string where = command.empty() ? "" : " for globemesh " + command;
        if (!options.empty())
            return std::string(options.size() > 1 ? "unknown options " : "unknown option ") + list + where +
                   " (" + help + " lists them)";
        return std::string(others.size() > 1 ? "unexpected arguments " : "unexpected argument ") + list + where +
               " (a value goes after its option's name, e.g. --coast land.shp; " + help + ")";
    }
    if (dynamic_cast<const CLI::RequiredError*>(&e)) return what + " (" + help + ")";
    return what;
}

/// The command line for the `history` attribute, with the date (UTC).
std::string history_text(const std::string& sub, std::span<const std::string> args) {
    std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
    std::string command = "globemesh " + sub;
    for (const auto& a : args) {
        const bool plain = !a.empty() && a.find_first_of(" \t'\"\\$`") == std::string::npos;
        if (plain) {
            command += " " + a;
            continue;
        }
        std::string quoted = "'"; // POSIX shell quoting: ' becomes '\''
        for (char c : a) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
        command += " " + quoted + "'";
    }
    return std::string(date) + ": " + command;
}

/// GDAL messages go through our stream: warnings only with --verbose (errors become exceptions
/// at the library's call sites, which read CPLGetLastErrorMsg).
class GdalMessages {
public:
    GdalMessages(std::ostream& err, bool verbose) : err_(err), verbose_(verbose) {
        CPLPushErrorHandlerEx(&GdalMessages::handler, this);
    }
    ~GdalMessages() { CPLPopErrorHandler(); }
    GdalMessages(const GdalMessages&) = delete;
    GdalMessages& operator=(const GdalMessages&) = delete;

private:
    static void CPL_STDCALL handler(CPLErr level, CPLErrorNum, const char* message) {
        auto* self = static_cast<GdalMessages*>(CPLGetErrorHandlerUserData());
        if (self && self->verbose_ && level == CE_Warning)
            self->err_ << "\nwarning (GDAL): " << message << "\n";
    }
    std::ostream& err_;
    bool verbose_;
};

// --------------------------------------------------------------------------------------------
// globemesh mesh

/// The `mesh` subcommand: its CLI11 App bound to a CliOptions, plus the fields that need a
/// conversion after parsing (optional values).
struct MeshCommand {
    CliOptions o;
    std::vector<double> region;
    double bathy_fill_m = 0;
    double min_depth_m = 0;
    std::string max_memory_text = "auto";
    CLI::App app{"Mesh the ocean between the coastlines, graded by the size options.", "globemesh mesh"};
    CLI::Option* region_opt = nullptr;
    CLI::Option* bathy_fill_opt = nullptr;
    CLI::Option* min_depth_opt = nullptr;

    MeshCommand() {
        app.option_defaults()->always_capture_default();
        app.set_version_flag("--version", version_text(), "Print the version and exit");
        app.get_formatter()->column_width(36);
        app.footer("Lengths: 20km, 5000m or 20 (km). Areas: 1000km2, 1e6m2 or 1000 (km2). Durations: 12.42h,\n"
                   "745min, 44712s or 12.42 (h). Depths: 50m, 0.05km or 50 (m). See globemesh(1).\n");
        MeshOptions& m = o.mesh;
        const std::string coast = "Coastline", bathy = "Bathymetry", size = "Size field",
                          mesher = "Mesher", output = "Output", run = "Run";

        app.add_option("--coast", m.coast, "Land polygons or coast lines: any OGR vector source (required)")
            ->group(coast)->type_name("SOURCE");
        app.add_option("--coast-layer", m.coast_layer, "Layer of --coast; default the only polygon or line layer")
            ->group(coast)->type_name("NAME");
        app.add_option("--coast-where", m.coast_where, "OGR SQL attribute filter on --coast; default none")
            ->group(coast)->type_name("SQL");
        app.add_option("--coast-srs", m.coast_srs, "CRS of a --coast layer that declares none, e.g. EPSG:4326 (a declared one is not overridden)")
            ->group(coast)->type_name("SRS");
        region_opt = app.add_option("--region", region,
                                    "Region W,S,E,N in degrees (W > E crosses 180); default the whole globe")
                         ->group(coast)->type_name("W,S,E,N")->delimiter(',')->expected(4);
        region_opt->always_capture_default(false)->default_str("")->run_callback_for_default(false); // no region: the globe
        app.add_option("--region-file", m.region_file, "Polygons (any OGR source, any CRS) bounding the ocean")
            ->group(coast)->type_name("SOURCE");
        app.add_option("--region-layer", m.region_layer, "Layer of --region-file; default the only polygon or line layer")
            ->group(coast)->type_name("NAME");
        app.add_option("--min-island-area", m.min_island_area_km2,
                       "Drop islands and lakes smaller than AREA (km2 or m2; bare number: km2)")
            ->group(coast)->type_name("AREA")->transform(unit_transform(parse_area_km2, ""));
        app.add_flag("--keep-inland-seas", m.keep_inland_seas, "Keep water bodies not connected to the ocean")
            ->group(coast);
        app.add_flag("--keep-straits", m.keep_straits,
                     "Keep straits narrower than a triangle open, their triangles centred on land")
            ->group(coast);

        app.add_option("--bathy", m.bathy, "Elevation (or depth) raster: any GDAL raster; default none")
            ->group(bathy)->type_name("RASTER");
        app.add_option("--bathy-band", m.bathy_band, "1-based band of --bathy")->group(bathy)->type_name("N");
        app.add_option("--bathy-srs", m.bathy_srs, "CRS of --bathy, replacing the file's (e.g. EPSG:4326); default the file's")
            ->group(bathy)->type_name("SRS")
            ->check(CLI::Validator(
                [](std::string& value) -> std::string {
                    try {
                        validate_bathy_srs(value);
                        return {};
                    } catch (const UsageError& e) { // CLI11 puts the option's name in front
                        const std::string what = e.what(), name = "--bathy-srs ";
                        return what.rfind(name, 0) == 0 ? what.substr(name.size()) : what;
                    }
                },
                ""));
        app.add_flag("--depth-positive", m.depth_positive, "The raster stores depth, positive down")
            ->group(bathy);
        bathy_fill_opt = app.add_option("--bathy-fill", bathy_fill_m,
                                        "Depth where the raster has no data (m or km; bare number: m); default none")
                             ->group(bathy)->type_name("DEPTH")->transform(unit_transform(parse_depth_m, ""));
        bathy_fill_opt->always_capture_default(false)->default_str("")->run_callback_for_default(false); // unset: no fill
        min_depth_opt = app.add_option("--min-depth", min_depth_m,
                                       "Raise nodes shallower than DEPTH to DEPTH (m or km, positive down); default none")
                            ->group(bathy)->type_name("DEPTH")->transform(unit_transform(parse_depth_m, ""));
        min_depth_opt->always_capture_default(false)->default_str("")->run_callback_for_default(false); // unset: as sampled

        app.add_option("--hmax", m.hmax_km, "Largest edge length (km or m; bare number: km); alone gives a uniform mesh")
            ->group(size)->type_name("LENGTH")->transform(unit_transform(parse_length_km, ""));
        app.add_option("--hmin", m.hmin_km, "Smallest edge length (km or m); 0: a floor of max(hmax/1000, 10 m)")
            ->group(size)->type_name("LENGTH")->transform(unit_transform(parse_length_km, ""));
        app.add_option("--coast-size", m.coast_size_km, "Edge length at the coast (km or m); 0: off")
            ->group(size)->type_name("LENGTH")->transform(unit_transform(parse_length_km, ""));
        app.add_option("--coast-rate", m.coast_rate, "Growth of the edge length with distance from the coast (km/km)")
            ->group(size)->type_name("RATE");
        app.add_option("--wavelength", m.wavelength, "Points per wavelength of the tide; 0: off")
            ->group(size)->type_name("N");
        app.add_option("--wave-period", m.wave_period_h, "Period of that wave (h, min or s; bare number: h; M2)")
            ->group(size)->type_name("DURATION")->transform(unit_transform(parse_duration_h, ""));
        app.add_option("--slope", m.slope, "Points per topographic length scale; 0: off")
            ->group(size)->type_name("N");
        app.add_option("--size-regions", m.size_regions, "Polygons with a size_km attribute: edge length inside")
            ->group(size)->type_name("SOURCE");
        app.add_option("--size-regions-layer", m.size_regions_layer,
                       "Layer of --size-regions; default every layer with a size_km field")
            ->group(size)->type_name("NAME");
        app.add_option("--grade", m.grade, "Largest |grad h|, the gradation of edge lengths (km/km)")
            ->group(size)->type_name("G");

        app.add_option("--max-nodes", m.max_nodes, "Refuse runs estimated to give more nodes")
            ->group(mesher)->type_name("N")->transform(count_transform());
        // Kept as text ("auto", "4GB") so that --print-config and the mesh's configuration say
        // what was asked, not this machine's memory; converted in parse(). "auto" is 3/4 of the
        // physical memory, read here: the library reads no system state.
        app.add_option("--max-memory", max_memory_text,
                       "Refuse runs estimated to need more memory (B, kB, MB, GB or KiB..TiB; bare: "
                       "bytes; 0: no limit; auto: 3/4 of the physical memory)")
            ->group(mesher)->type_name("SIZE")
            ->check(CLI::Validator(
                [](std::string& value) -> std::string {
                    try {
                        if (value != "auto") parse_memory_bytes(value);
                        return {};
                    } catch (const UsageError& e) {
                        return e.what();
                    }
                },
                ""));
        app.add_option("--inlet-width", m.inlet_width,
                       "Close inlets narrower than F times the edge length at their mouth (0: none)")
            ->group(mesher)->type_name("F");
        app.add_option("--smooth", m.smooth_iterations, "Smoothing/relaxation sweeps")->group(mesher)->type_name("N");
        app.add_option("--seed", m.seed, "Seed of every pseudo-random choice")->group(mesher)->type_name("N");

        app.add_option("-o,--output", o.output, "UGRID NetCDF file to write (required)")
            ->group(output)->type_name("OUT.nc");
        app.add_option("--gpkg", o.gpkg, "Also write a GeoPackage (faces, nodes, boundary, mesh_info)")
            ->group(output)->type_name("OUT.gpkg");
        app.add_option("--preview", o.preview, "Also draw the mesh over the land as a PNG")
            ->group(output)->type_name("OUT.png");
        app.add_option("--format", o.format, "NetCDF flavour: netcdf4 (deflate) or classic")
            ->group(output)->type_name("FORMAT")->check(CLI::IsMember({"netcdf4", "classic"}));
        app.add_option("--timings", o.timings, "Write the seconds per stage as JSON")
            ->group(output)->type_name("FILE.json");
        app.add_option("--report", o.report, "Write the run summary and quality histogram as JSON")
            ->group(output)->type_name("FILE.json");
        app.add_flag("--overwrite", o.overwrite, "Replace existing output files")->group(output);

        app.set_config("--config", "", "Read options from a TOML or INI file (keys: the long option names)")
            ->group(run)->type_name("FILE");
        app.add_flag("--print-config", o.print_config, "Print the effective configuration (for --config) and stop")
            ->group(run)->configurable(false);
        // Not CLI11's excludes(): --print-config writes both as false, and must read back.
        app.add_flag("-q,--quiet", o.quiet, "No progress or warnings on stderr (not with --verbose)")->group(run);
        app.add_flag("-v,--verbose", o.verbose, "Show stage names with the progress, and GDAL warnings")
            ->group(run);
        app.add_flag("--check", o.check, "Check the mesh invariants before writing (exit 1 if one fails)")
            ->group(run);
    }
    MeshCommand(const MeshCommand&) = delete;
    MeshCommand& operator=(const MeshCommand&) = delete;

    /// Parses; CLI11 errors (including help and version) propagate.
    void parse(std::span<const std::string> args) {
        // A key of the config file that names no option is an error, not ignored: a typo
        // (hmaxx) or a [section] would otherwise mesh at the defaults without a word.
        app.allow_config_extras(CLI::config_extras_mode::error);
        try {
            app.parse(reversed(args));
        } catch (const CLI::ConfigError& e) {
            const std::string what = e.what(), prefix = "INI was not able to parse "; // CLI11's ConfigError::Extras
            if (what.rfind(prefix, 0) != 0) throw;
            const std::string key = what.substr(prefix.size()), file = app.get_config_ptr()->as<std::string>();
            if (const auto dot = key.find('.'); dot != std::string::npos)
                throw UsageError("--config " + file + ": [" + key.substr(0, dot) +
                                 "]: the file takes no sections, only option = value lines");
            std::string dashed = key;
            std::replace(dashed.begin(), dashed.end(), '_', '-');
            const std::string hint = dashed != key && app.get_option_no_throw("--" + dashed) != nullptr
                                         ? "; did you mean " + dashed + "?"
                                         : "; the keys are the long option names, as --print-config writes them";
            throw UsageError("--config " + file + ": unknown key " + key + hint);
        }
        if (const CLI::Option* config = app.get_config_ptr(); config != nullptr && config->count() > 0)
            o.config = config->as<std::string>();
        if (region_opt->count() > 0 && region.size() == 4)
            o.mesh.region = std::array<double, 4>{region[0], region[1], region[2], region[3]};
        if (bathy_fill_opt->count() > 0) o.mesh.bathy_fill_m = bathy_fill_m;
        if (min_depth_opt->count() > 0) o.mesh.min_depth_m = min_depth_m;
        o.mesh.max_memory_bytes =
            max_memory_text == "auto" ? default_memory_budget_bytes() : parse_memory_bytes(max_memory_text);
        if (o.quiet && o.verbose) throw UsageError("--quiet and --verbose exclude each other");
    }
};

/// The checks run_cli makes before anything is opened: library validation, then the paths.
void check_mesh_run(const CliOptions& o) {
    validate(o.mesh);
    if (o.mesh.coast.empty())
        throw UsageError("--coast is required: land polygons or coast lines, e.g. --coast land.gpkg");
    if (o.output.empty()) throw UsageError("-o/--output is required: the UGRID file to write, e.g. -o ocean.nc");
    const std::vector<std::pair<std::string, std::string>> outputs = {
        {"--output", o.output}, {"--gpkg", o.gpkg}, {"--preview", o.preview},
        {"--timings", o.timings}, {"--report", o.report}};
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_output_kind(path, name);
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        for (std::size_t j = i + 1; j < outputs.size(); ++j) {
            if (!outputs[i].second.empty() && !outputs[j].second.empty() &&
                fs::absolute(outputs[i].second).lexically_normal() ==
                    fs::absolute(outputs[j].second).lexically_normal())
                throw UsageError(outputs[i].first + " and " + outputs[j].first + " name the same file " +
                                 outputs[i].second);
        }
    }
    const std::pair<std::string, std::string> inputs[] = {{"--coast", o.mesh.coast},
                                                          {"--bathy", o.mesh.bathy},
                                                          {"--region-file", o.mesh.region_file},
                                                          {"--size-regions", o.mesh.size_regions},
                                                          {"--config", o.config}};
    for (const auto& [name, path] : inputs) check_input_path(path, name); // (--config was read)
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_not_an_input(path, name, inputs);
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_output_path(path, name, o.overwrite);
}

/// One progress line for a run: the mesh (or triangulation) and each output get a share of it
/// as their times compare, asked for in the order they run. Measured at 20 km on 1:50m land
/// (1.08e6 nodes), seconds for reading and meshing / the UGRID file / the GeoPackage / the PNG:
/// 1.7 / 2.6 / 7.9 / 1.8.
class RunShares {
public:
    RunShares(TerminalProgress& terminal, bool gpkg, bool preview)
        : terminal_(terminal), total_(1 + ugrid_weight + (gpkg ? gpkg_weight : 0) + (preview ? preview_weight : 0)) {}
    Progress mesh() { return next(1); }
    Progress ugrid() { return next(ugrid_weight); }
    Progress gpkg() { return next(gpkg_weight); }
    Progress preview() { return next(preview_weight); }

private:
    static constexpr double ugrid_weight = 1.5, gpkg_weight = 4.6, preview_weight = 1.1;
    Progress next(double weight) {
        const Progress p = sub_progress(terminal_.callback(), at_ / total_, (at_ + weight) / total_);
        at_ += weight;
        return p;
    }
    TerminalProgress& terminal_;
    double total_, at_ = 0;
};

void throw_if_interrupted() {
    if (InterruptGuard::interrupted()) throw Cancelled();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Adds the `mesh` key of issue 4 (everything from rings and size field to the final mesh,
/// I/O excluded) when the pipeline did not report it: the sum of the stages not named read*.
void add_mesh_total(StageTimings& timings) {
    for (const auto& [name, s] : timings.stages)
        if (name == "mesh") return;
    double total = 0;
    for (const auto& [name, s] : timings.stages)
        if (name.rfind("read", 0) != 0) total += s;
    timings.add("mesh", total);
}

/// The value of the mesh's attribute `key`, or nullopt.
std::optional<std::string> find_attribute(const Mesh& mesh, std::string_view key) {
    for (const auto& [k, v] : mesh.attributes)
        if (k == key) return v;
    return std::nullopt;
}

/// A whole number with thousands separators: 33251 -> "33,251", -2505 -> "-2,505".
std::string grouped(long long v) {
    std::string digits = std::to_string(v < 0 ? -v : v), r;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0) r += ',';
        r += digits[i];
    }
    return (v < 0 ? "-" : "") + r;
}

/// The depth counts of the pipeline's attributes (nodes above sea level as sampled, those
/// --min-depth raised) as a JSON object, or "" when the mesh has no depth.
std::string depth_json(const Mesh& mesh) {
    const auto above = find_attribute(mesh, "nodes_above_sea_level");
    if (!above) return "";
    const auto shallowest = find_attribute(mesh, "min_sampled_depth_m");
    const auto floor = find_attribute(mesh, "min_depth_m");
    const auto raised = find_attribute(mesh, "nodes_raised_to_min_depth");
    return "{\"nodes_above_sea_level\": " + *above + ", \"min_sampled_depth_m\": " + shallowest.value_or("null") +
           ", \"min_depth_m\": " + floor.value_or("null") + ", \"nodes_raised_to_min_depth\": " + raised.value_or("0") +
           "}";
}

/// The summary's depth line, and unless `quiet` the warning on `err` when nodes above sea level
/// are written with negative depth (no --min-depth).
void print_depth(std::ostream& out, std::ostream& err, const Mesh& mesh, bool quiet) {
    const auto above = find_attribute(mesh, "nodes_above_sea_level");
    if (!above) return;
    const long long count = std::stoll(*above);
    const auto floor = find_attribute(mesh, "min_depth_m");
    std::string down_to;
    if (const auto shallowest = find_attribute(mesh, "min_sampled_depth_m"))
        down_to = " (down to " + grouped(std::llround(std::stod(*shallowest))) + " m)";
    out << "depth             " << count << " nodes above sea level" << down_to;
    if (floor)
        out << ", " << find_attribute(mesh, "nodes_raised_to_min_depth").value_or("0") << " raised to --min-depth "
            << *floor << " m";
    out << "\n";
    if (count > 0 && !floor && !quiet)
        err << "globemesh: warning: " << grouped(count) << (count == 1 ? " node lies" : " nodes lie")
            << " above sea level" << down_to << (count == 1 ? " and is" : " and are")
            << " written with negative depth; --min-depth 5 would raise them to 5 m\n";
}

int run_mesh(std::span<const std::string> args, std::ostream& out, std::ostream& err,
             TerminalProgress& terminal, const CliLibrary& lib) {
    auto command = std::make_unique<MeshCommand>();
    try {
        command->parse(args);
    } catch (const CLI::CallForHelp&) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForAllHelp&) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForVersion&) {
        out << version_text() << "\n";
        return 0;
    }
    const CliOptions& o = command->o;
    if (o.print_config) {
        validate(o.mesh);
        out << command->app.config_to_str(true, true);
        return 0;
    }
    check_mesh_run(o);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, o.verbose);
    const auto t0 = std::chrono::steady_clock::now();
    StageTimings timings;
    terminal.configure(o.quiet, o.verbose);
    RunShares share(terminal, !o.gpkg.empty(), !o.preview.empty());
    Mesh mesh = lib.mesh_ocean(o.mesh, share.mesh(), &timings);
    throw_if_interrupted();
    add_mesh_total(timings);
    // The effective configuration travels with the mesh, so the file itself says how to remake it.
    mesh.attributes.emplace_back("globemesh_configuration", command->app.config_to_str(true, false));

    if (o.check) {
        auto problems = check_mesh(mesh);
        if (!problems.empty())
            throw DataError("--check: the mesh breaks " + std::to_string(problems.size()) +
                            (problems.size() >= 20 ? "+" : "") + " invariants, first: " + problems.front() +
                            "; please report this with the command line");
    }

    // Computed once for the report and both writers (each would otherwise build the topology
    // again for it).
    const MeshStats stats = lib.compute_stats(mesh);
    // Every output of the run waits under its temporary name until all are complete.
    OutputBatch batch;
    const auto tw = std::chrono::steady_clock::now();
    UgridOptions ugrid;
    ugrid.classic = o.format == "classic";
    ugrid.overwrite = o.overwrite;
    ugrid.history = history_text("mesh", args);
    ugrid.stats = &stats;
    ugrid.progress = share.ugrid();
    // The face areas pass from one writer to the other (8 bytes a face, held while the
    // GeoPackage is written instead of its 8 bytes an edge of geodesic terms).
    std::vector<double> face_areas;
    if (!o.gpkg.empty()) ugrid.face_areas_m2 = &face_areas;
    lib.write_ugrid(mesh, o.output, ugrid);
    throw_if_interrupted();
    if (!o.gpkg.empty()) {
        GpkgOptions gpkg;
        gpkg.overwrite = o.overwrite;
        gpkg.stats = &stats;
        gpkg.face_areas_m2 = &face_areas;
        gpkg.progress = share.gpkg();
        lib.write_gpkg(mesh, o.gpkg, gpkg);
        throw_if_interrupted();
    }
    if (!o.preview.empty()) {
        PreviewOptions preview;
        preview.land = o.mesh.coast;
        preview.colour_by = mesh.node_field("depth") ? "depth" : "quality";
        preview.extent_deg = o.mesh.region;
        preview.overwrite = o.overwrite;
        preview.progress = share.preview();
        lib.write_preview_png(mesh, o.preview, preview);
        throw_if_interrupted();
    }
    timings.add("write", seconds_since(tw));
    terminal.finish(); // close the progress line if a stage stopped short of its share's end

    const double total_s = seconds_since(t0);
    const long long peak = peak_memory_bytes();
    if (!o.timings.empty()) {
        OutputFile::write_text(o.timings, timings_json(timings), o.overwrite, "--timings");
    }
    if (!o.report.empty()) {
        std::ostringstream r;
        r << "{\n  \"globemesh\": " << json_string(GLOBEMESH_VERSION) << ",\n"
          << "  \"history\": " << json_string(ugrid.history) << ",\n"
          << "  \"outputs\": {\"netcdf\": " << json_string(o.output);
        if (!o.gpkg.empty()) r << ", \"gpkg\": " << json_string(o.gpkg);
        if (!o.preview.empty()) r << ", \"preview\": " << json_string(o.preview);
        r << "},\n  \"mesh\": " << stats_json(stats, "  ") << ",\n";
        if (const std::string depth = depth_json(mesh); !depth.empty()) r << "  \"depth\": " << depth << ",\n";
        // What the run did to the coast and the land, as the NetCDF file's global attributes say.
        r << "  \"attributes\": {";
        for (std::size_t i = 0; i < mesh.attributes.size(); ++i)
            r << (i ? ", " : "") << json_string(mesh.attributes[i].first) << ": " << json_string(mesh.attributes[i].second);
        r << "},\n"
          << "  \"stages\": " << stages_json(timings) << ",\n"
          << "  \"total_seconds\": " << json_number(total_s) << ",\n"
          << "  \"peak_memory_bytes\": " << peak << "\n}\n";
        OutputFile::write_text(o.report, r.str(), o.overwrite, "--report");
    }
    batch.commit(InterruptGuard::interrupted);
    InterruptGuard::finished();

    print_stats(out, stats, false);
    // What the run changed of the coast, from the pipeline's attributes.
    auto attribute = [&](const char* key) {
        for (const auto& [k, v] : mesh.attributes)
            if (k == key) return v;
        return std::string("?");
    };
    out << "coast             " << attribute("boundary_rings") << " rings kept, islands dropped "
        << attribute("islands_removed") << ", lakes dropped " << attribute("lakes_removed")
        << ", inlets closed " << attribute("inlets_closed") << ", corners blunted " << attribute("corners_blunted")
        << "\n"
        << "coast repairs     " << attribute("coast_repairs") << "\n"
        << "faces on land     " << attribute("faces_on_land") << "\n";
    // The first six places (lon lat) of a list attribute; all of them, up to 50, are the attribute.
    auto places = [&](const char* key) {
        std::string at = attribute(key);
        if (at == "?") return;
        std::size_t cut = 0;
        for (int i = 0; i < 6 && cut != std::string::npos; ++i) cut = at.find(", ", cut + (i > 0 ? 2 : 0));
        if (cut != std::string::npos) at = at.substr(0, cut) + ", ... (" + key + ")";
        out << "                  at " << at << "\n";
    };
    places("faces_on_land_at");
    if (std::string closed = attribute("straits_closed"); closed != "?" && closed.rfind("0 ", 0) != 0) {
        out << "straits closed    " << closed << "\n";
        places("straits_closed_at");
    }
    out << "ocean components  " << attribute("ocean_components") << "\n";
    print_depth(out, err, mesh, o.quiet);
    print_timings(out, timings);
    out << "total time        " << exact_text(std::round(total_s * 1000) / 1000) << " s\n"
        << "peak memory       " << exact_text(std::round(peak / 1048576.0 * 10) / 10) << " MiB\n"
        << "wrote             " << o.output;
    for (const auto* p : {&o.gpkg, &o.preview, &o.timings, &o.report})
        if (!p->empty()) out << ", " << *p;
    out << "\n";
    return 0;
}

// --------------------------------------------------------------------------------------------
// globemesh triangulate

struct TriangulateCommand {
    TriangulateOptions t;
    std::string output, gpkg, timings;
    bool overwrite = false, quiet = false, verbose = false;
    CLI::App app{"Spherical Delaunay triangulation of scattered points (any OGR point source).",
                 "globemesh triangulate"};

    TriangulateCommand() {
        app.option_defaults()->always_capture_default();
        app.set_version_flag("--version", version_text(), "Print the version and exit");
        app.get_formatter()->column_width(36);
        app.add_option("POINTS", t.points, "Points: CSV with lon/lat columns, GeoPackage, shapefile, ...")
            ->required()->type_name("SOURCE");
        app.add_option("-o,--output", output, "UGRID NetCDF file to write (required)")->type_name("OUT.nc");
        app.add_option("--gpkg", gpkg, "Also write a GeoPackage")->type_name("OUT.gpkg");
        app.add_option("--layer", t.layer, "Layer of POINTS; default the first layer")->type_name("NAME");
        app.add_option("--timings", timings, "Write the seconds per stage as JSON")->type_name("FILE.json");
        app.add_flag("--overwrite", overwrite, "Replace existing output files");
        app.add_flag("-q,--quiet", quiet, "No progress on stderr (not with --verbose)");
        app.add_flag("-v,--verbose", verbose, "Show stage names with the progress");
    }
};

int run_triangulate(std::span<const std::string> args, std::ostream& out, std::ostream& err,
                    TerminalProgress& terminal, const CliLibrary& lib) {
    auto command = std::make_unique<TriangulateCommand>();
    try {
        command->app.parse(reversed(args));
    } catch (const CLI::CallForHelp&) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForVersion&) {
        out << version_text() << "\n";
        return 0;
    }
    const auto& c = *command;
    if (c.quiet && c.verbose) throw UsageError("--quiet and --verbose exclude each other");
    if (c.output.empty()) throw UsageError("-o/--output is required: the UGRID file to write, e.g. -o out.nc");
    check_input_path(c.t.points, "POINTS");
    const std::pair<const char*, const std::string&> outputs[] = {
        {"--output", c.output}, {"--gpkg", c.gpkg}, {"--timings", c.timings}};
    const std::pair<std::string, std::string> inputs[] = {{"POINTS", c.t.points}};
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_output_kind(path, name);
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_not_an_input(path, name, inputs);
    for (const auto& [name, path] : outputs)
        if (!path.empty()) check_output_path(path, name, c.overwrite);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, c.verbose);
    StageTimings timings;
    terminal.configure(c.quiet, c.verbose);
    RunShares share(terminal, !c.gpkg.empty(), false);
    Mesh mesh = lib.triangulate_file(c.t, share.mesh(), &timings);
    throw_if_interrupted();
    OutputBatch batch; // every output waits under its temporary name until all are complete
    const auto tw = std::chrono::steady_clock::now();
    UgridOptions ugrid;
    ugrid.overwrite = c.overwrite;
    ugrid.title = "globemesh spherical Delaunay triangulation";
    ugrid.history = history_text("triangulate", args);
    ugrid.progress = share.ugrid();
    std::vector<double> face_areas;
    if (!c.gpkg.empty()) ugrid.face_areas_m2 = &face_areas;
    lib.write_ugrid(mesh, c.output, ugrid);
    throw_if_interrupted();
    if (!c.gpkg.empty()) {
        GpkgOptions gpkg;
        gpkg.overwrite = c.overwrite;
        gpkg.face_areas_m2 = &face_areas;
        gpkg.progress = share.gpkg();
        lib.write_gpkg(mesh, c.gpkg, gpkg);
    }
    throw_if_interrupted();
    timings.add("write", seconds_since(tw));
    terminal.finish();
    if (!c.timings.empty()) {
        OutputFile::write_text(c.timings, timings_json(timings), c.overwrite, "--timings");
    }
    batch.commit(InterruptGuard::interrupted);
    InterruptGuard::finished();
    out << "nodes             " << mesh.nodes.size() << "\n"
        << "faces             " << mesh.faces.size() << "\n";
    print_timings(out, timings);
    return 0;
}

// --------------------------------------------------------------------------------------------
// globemesh info

struct InfoCommand {
    std::string path;
    bool json = false;
    CLI::App app{"Counts, extent, edge lengths and quality of a UGRID mesh file.", "globemesh info"};
    InfoCommand() {
        app.set_version_flag("--version", version_text(), "Print the version and exit");
        app.get_formatter()->column_width(36);
        app.add_option("MESH", path, "UGRID NetCDF file (ours or another tool's)")->required()->type_name("MESH.nc");
        app.add_flag("--json", json, "Print JSON for machines");
    }
};

int run_info(std::span<const std::string> args, std::ostream& out, const CliLibrary& lib) {
    InfoCommand command;
    try {
        command.app.parse(reversed(args));
    } catch (const CLI::CallForHelp&) {
        out << command.app.help();
        return 0;
    } catch (const CLI::CallForVersion&) {
        out << version_text() << "\n";
        return 0;
    }
    check_input_path(command.path, "MESH");
    const MeshStats stats = lib.compute_stats(lib.read_ugrid(command.path));
    if (command.json)
        out << stats_json(stats, "") << "\n";
    else
        print_stats(out, stats, true);
    return 0;
}

// --------------------------------------------------------------------------------------------
// globemesh (top level), help

std::unique_ptr<CLI::App> make_top_app() {
    auto app = std::make_unique<CLI::App>(
        "Ocean meshes on the sphere from GIS data: coastlines from any OGR source, bathymetry from "
        "any GDAL raster, UGRID NetCDF and GeoPackage out. See globemesh(1).",
        "globemesh");
    app->set_version_flag("--version", version_text(), "Print the version and exit");
    app->add_subcommand("mesh", "Mesh the ocean: globemesh mesh --coast LAND -o OCEAN.nc [options]");
    app->add_subcommand("triangulate", "Delaunay triangulation of points: globemesh triangulate POINTS -o OUT.nc");
    app->add_subcommand("info", "Statistics of a UGRID mesh file: globemesh info MESH.nc [--json]");
    app->add_subcommand("help", "Help on globemesh or one subcommand: globemesh help [SUBCOMMAND]");
    app->require_subcommand(1);
    return app;
}

int run_help(std::span<const std::string> args, std::ostream& out) {
    if (args.empty()) {
        out << make_top_app()->help();
        return 0;
    }
    if (args.size() > 1) throw UsageError("help takes one subcommand name, e.g. globemesh help mesh");
    if (args[0] == "mesh") {
        MeshCommand c;
        out << c.app.help();
    } else if (args[0] == "triangulate") {
        TriangulateCommand c;
        out << c.app.help();
    } else if (args[0] == "info") {
        InfoCommand c;
        out << c.app.help();
    } else if (args[0] == "help") {
        out << make_top_app()->help();
    } else {
        throw UsageError("help: unknown subcommand '" + args[0] + "' (the subcommands are mesh, triangulate, info, help)");
    }
    return 0;
}

int dispatch(std::span<const std::string> args, std::ostream& out, std::ostream& err,
             TerminalProgress& terminal, const CliLibrary& lib) {
    if (args.empty())
        throw UsageError("no subcommand given: run 'globemesh help' (e.g. globemesh mesh --coast land.gpkg -o ocean.nc)");
    const std::string& name = args[0];
    const auto rest = args.subspan(1);
    if (name == "mesh") return run_mesh(rest, out, err, terminal, lib);
    if (name == "triangulate") return run_triangulate(rest, out, err, terminal, lib);
    if (name == "info") return run_info(rest, out, lib);
    if (name == "help") return run_help(rest, out);
    if (!name.empty() && name[0] != '-')
        throw UsageError("unknown subcommand '" + name + "' (the subcommands are mesh, triangulate, info, help)");
    auto top = make_top_app();
    try {
        top->parse(reversed(args));
    } catch (const CLI::CallForHelp&) {
        out << top->help();
        return 0;
    } catch (const CLI::CallForAllHelp&) {
        out << top->help();
        return 0;
    } catch (const CLI::CallForVersion&) {
        out << version_text() << "\n";
        return 0;
    } catch (const CLI::ParseError&) {
        throw UsageError("unknown option '" + name +
                         "' (globemesh takes --help, --version or a subcommand: mesh, triangulate, info, help)");
    }
    return 0; // unreachable: a subcommand name would have been dispatched above
}

} // namespace

CliOptions parse_mesh_args(std::span<const std::string> args) {
    auto command = std::make_unique<MeshCommand>();
    try {
        command->parse(args);
    } catch (const CLI::ParseError& e) {
        throw UsageError(usage_text(e, "mesh"));
    }
    return command->o;
}

int run_cli(std::span<const std::string> args, std::ostream& out, std::ostream& err,
            const CliLibrary& library) {
    TerminalProgress terminal(err);
    InterruptGuard::forget(); // a signal of an earlier run in this process
    try {
        return dispatch(args, out, err, terminal, library);
    } catch (...) {
        terminal.end_line();
        const bool sub = !args.empty() && (args[0] == "mesh" || args[0] == "info" || args[0] == "triangulate");
        return report_error(err, sub ? args[0] : std::string());
    }
}

namespace {

/// Maps the exception in flight to one line on err and the exit status.
int report_error(std::ostream& err, const std::string& command) {
    bool usage = false;
    try {
        throw;
    } catch (const CLI::ParseError&) {
        usage = true;
    } catch (const UsageError&) {
        usage = true;
    } catch (...) {
    }
    // After a cancelling signal any other failure is the run stopping: a GEOS or GDAL call
    // interrupted fails in its own words.
    if (InterruptGuard::signal() != 0 && !usage) {
        // A signal other than Ctrl-C is named: it may come from a batch scheduler's time limit.
        const int signal = InterruptGuard::signal();
        const char* by = signal == SIGTERM ? " by SIGTERM" : signal == SIGHUP ? " by SIGHUP" : "";
        err << "globemesh: cancelled" << by << ", no output written\n";
        return 1;
    }
    try {
        throw;
    } catch (const CLI::ParseError& e) {
        err << "globemesh: " << usage_text(e, command) << "\n";
        return 2;
    } catch (const UsageError& e) {
        err << "globemesh: " << one_line(e.what()) << "\n";
        return 2;
    } catch (const Cancelled& e) {
        err << "globemesh: cancelled, no output written\n"; // by the library's caller, not a signal
        return 1;
    } catch (const Error& e) {
        err << "globemesh: " << one_line(e.what()) << "\n";
        return 1;
    } catch (const std::exception& e) {
        err << "globemesh: internal error: " << one_line(e.what()) << "\n";
        return 1;
    } catch (...) {
        err << "globemesh: internal error: unknown exception\n";
        return 1;
    }
}

} // namespace

} // namespace globemesh
