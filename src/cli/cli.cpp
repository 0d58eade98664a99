// run_cli(): parsing (CLI11 and config files), validation, progress, outputs, summaries and the
// mapping of errors to exit statuses. One CLI11 App per subcommand, so that `--config` reads a
// flat file whose keys are the long option names (CLI11 reads config files for its top App only).
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
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

#include "cli_outputs.hpp"
#include "cli_support.hpp"
#include "globemesh/bathymetry.hpp"
#include "globemesh/cli.hpp"
#include "globemesh/error.hpp"
#include "globemesh/options.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "option_flags.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;
using namespace globemesh::cli;

int report_error(std::ostream &err, const std::string &command);

std::string version_text() {
    return std::string("globemesh ") + GLOBEMESH_VERSION + " (GDAL " +
           GDALVersionInfo("RELEASE_NAME") + ")";
}

/// Shortest text that reads back as the same double.
std::string exact_text(double v) {
    char buffer[32];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, end);
}

/// A CLI11 transform that turns "20km" into "20" (the field's unit), so the bound field, the
/// --help default and --print-config all speak the field's unit.
CLI::Validator unit_transform(double (*parse)(std::string_view), const std::string &name) {
    return CLI::Validator(
        [parse](std::string &value) -> std::string {
            try {
                value = exact_text(parse(value));
                return {};
            } catch (const UsageError &e) {
                return e.what();
            }
        },
        name);
}

/// A CLI11 transform for a count: a whole number, also written as 2e7 (CLI11 alone refuses that
/// with "Could not convert").
CLI::Validator count_transform() {
    return CLI::Validator(
        [](std::string &value) -> std::string {
            char *end = nullptr;
            const double v = std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0' || !(v >= 0 && v <= 9.007199254740992e15) ||
                v != std::floor(v))
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
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
        message.pop_back();
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
std::string usage_text(const CLI::ParseError &e, const std::string &command) {
    const std::string what = one_line(e.what());
    const std::string help =
        command.empty() ? "globemesh --help" : "globemesh " + command + " --help";
    const std::size_t colon = what.find(": ");
    if (dynamic_cast<const CLI::ArgumentMismatch *>(&e) && colon != std::string::npos) {
        // "NAME: At Most N required but received M", "NAME: At least N required but received
        // M", "NAME: N required TYPE missing" (CLI11 2.3's words).
        const std::string name = what.substr(0, colon);
        std::istringstream rest(what.substr(colon + 2));
        std::vector<std::string> w;
        for (std::string x; rest >> x;)
            w.push_back(x);
        if (w.size() == 7 && w[0] == "At" && w[1] == "Most" && w[3] == "required" &&
            w[5] == "received")
            return name + " is given " + w[6] + " times; give it " +
                   (w[2] == "1" ? std::string("once") : "at most " + w[2] + " times");
        if (w.size() == 7 && w[0] == "At" && w[1] == "least" && w[3] == "required" &&
            w[5] == "received")
            return name + " needs " + w[2] + " values, got " + w[6];
        if (w.size() == 4 && w[1] == "required" && w[3] == "missing")
            return name + " needs a value (" + w[2] + ")";
    }
    if (dynamic_cast<const CLI::ExtrasError *>(&e)) {
        // "The following argument(s) was/were not expected: A B": options first.
        std::istringstream words(colon == std::string::npos ? std::string()
                                                            : what.substr(colon + 2));
        std::vector<std::string> options, others;
        for (std::string w; words >> w;)
            (w.size() > 1 && w[0] == '-' ? options : others).push_back(w);
        std::string list;
        for (const auto &w : options.empty() ? others : options)
            list += (list.empty() ? "" : ", ") + w;
        const std::string where = command.empty() ? "" : " for globemesh " + command;
        if (!options.empty())
            return std::string(options.size() > 1 ? "unknown options " : "unknown option ") + list +
                   where + " (" + help + " lists them)";
        return std::string(others.size() > 1 ? "unexpected arguments " : "unexpected argument ") +
               list + where + " (a value goes after its option's name, e.g. --coast land.shp; " +
               help + ")";
    }
    if (dynamic_cast<const CLI::RequiredError *>(&e))
        return what + " (" + help + ")";
    return what;
}

/// The command line for the `history` attribute, with the date (UTC).
std::string history_text(const std::string &sub, std::span<const std::string> args) {
    std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &tm);
    std::string command = "globemesh " + sub;
    for (const auto &a : args) {
        const bool plain = !a.empty() && a.find_first_of(" \t'\"\\$`") == std::string::npos;
        if (plain) {
            command += " " + a;
            continue;
        }
        std::string quoted = "'"; // POSIX shell quoting: ' becomes '\''
        for (char c : a)
            quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
        command += " " + quoted + "'";
    }
    return std::string(date) + ": " + command;
}

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
    CLI::App app{"Mesh the ocean between the coastlines, graded by the size options.",
                 "globemesh mesh"};
    CLI::Option *region_opt = nullptr;
    CLI::Option *bathy_fill_opt = nullptr;
    CLI::Option *min_depth_opt = nullptr;

    /// `table`: the output formats the help lists.
    explicit MeshCommand(std::span<const Writer> table = writers()) {
        app.option_defaults()->always_capture_default();
        app.set_version_flag("--version", version_text(), "Print the version and exit");
        app.get_formatter()->column_width(36);
        app.footer(
            "Lengths: 20km, 5000m or 20 (km). Areas: 1000km2, 1e6m2 or 1000 (km2). Durations: "
            "12.42h,\n"
            "745min, 44712s or 12.42 (h). Depths: 50m, 0.05km or 50 (m). See globemesh(1).\n");
        MeshOptions &m = o.mesh;
        const std::string coast = "Coastline", bathy = "Bathymetry", size = "Size field",
                          mesher = "Mesher", output = "Output", run = "Run";

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
                       "Polygons (any OGR source, any CRS) bounding the ocean")
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

        app.add_option("--bathy", m.bathy,
                       "Elevation (or depth) raster: any GDAL raster; default none")
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
            app.add_option(
                   "--bathy-fill", bathy_fill_m,
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
        app.add_option("--coast-size", m.coast_size_km,
                       "Edge length at the coast (km or m); 0: off")
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
        app.add_option("--size-regions", m.size_regions,
                       "Polygons with a size_km attribute: edge length inside")
            ->group(size)
            ->type_name("SOURCE");
        app.add_option("--size-regions-layer", m.size_regions_layer,
                       "Layer of --size-regions; default every layer with a size_km field")
            ->group(size)
            ->type_name("NAME");
        app.add_option("--grade", m.grade,
                       "Largest |grad h|, the gradation of edge lengths (km/km)")
            ->group(size)
            ->type_name("G");

        app.add_option("--max-nodes", m.max_nodes, "Refuse runs estimated to give more nodes")
            ->group(mesher)
            ->type_name("N")
            ->transform(count_transform());
        // Kept as text ("auto", "4GB") so that --print-config and the mesh's configuration say
        // what was asked, not this machine's memory; converted in parse(). "auto" is 3/4 of the
        // physical memory, read here: the library reads no system state.
        app.add_option(
               "--max-memory", max_memory_text,
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
        app.add_option(
               "--inlet-width", m.inlet_width,
               "Close inlets narrower than F times the edge length at their mouth (0: none)")
            ->group(mesher)
            ->type_name("F");
        app.add_option("--smooth", m.smooth_iterations, "Smoothing/relaxation sweeps")
            ->group(mesher)
            ->type_name("N");
        app.add_option("--seed", m.seed, "Seed of every pseudo-random choice")
            ->group(mesher)
            ->type_name("N");

        add_output_flags(app, o.output, o.output_format, o.creation_options, table, output);
        app.add_option("--gpkg", o.gpkg,
                       "Also write a GeoPackage (faces, nodes, boundary, mesh_info)")
            ->group(output)
            ->type_name("OUT.gpkg");
        app.add_option("--preview", o.preview, "Also draw the mesh over the land as a PNG")
            ->group(output)
            ->type_name("OUT.png");
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

        app.set_config("--config", "",
                       "Read options from a TOML or INI file (keys: the long option names)")
            ->group(run)
            ->type_name("FILE");
        app.add_flag("--print-config", o.print_config,
                     "Print the effective configuration (for --config) and stop")
            ->group(run)
            ->configurable(false);
        // Not CLI11's excludes(): --print-config writes both as false, and must read back.
        app.add_flag("-q,--quiet", o.quiet,
                     "No progress or warnings on stderr (not with --verbose)")
            ->group(run);
        app.add_flag("-v,--verbose", o.verbose,
                     "Show stage names with the progress, and GDAL warnings")
            ->group(run);
        app.add_flag("--check", o.check,
                     "Check the mesh invariants before writing (exit 1 if one fails)")
            ->group(run);
    }
    MeshCommand(const MeshCommand &) = delete;
    MeshCommand &operator=(const MeshCommand &) = delete;

    /// Parses; CLI11 errors (including help and version) propagate.
    void parse(std::span<const std::string> args) {
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
        if (const CLI::Option *config = app.get_config_ptr();
            config != nullptr && config->count() > 0)
            o.config = config->as<std::string>();
        if (region_opt->count() > 0 && region.size() == 4)
            o.mesh.region = std::array<double, 4>{region[0], region[1], region[2], region[3]};
        if (bathy_fill_opt->count() > 0)
            o.mesh.bathy_fill_m = bathy_fill_m;
        if (min_depth_opt->count() > 0)
            o.mesh.min_depth_m = min_depth_m;
        o.mesh.max_memory_bytes = max_memory_text == "auto" ? default_memory_budget_bytes()
                                                            : parse_memory_bytes(max_memory_text);
        if (o.quiet && o.verbose)
            throw UsageError("--quiet and --verbose exclude each other");
    }
};

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
    std::vector<std::pair<std::string, std::string>> netcdf_format;
    if (o.format == "classic")
        netcdf_format.emplace_back("--format classic", "FORMAT=NC2");
    const auto planned = plan_outputs(choices, table, netcdf_format, !o.mesh.bathy.empty());
    const auto files = output_files(planned, o.timings, o.report, table);
    const std::pair<std::string, std::string> inputs[] = {{"--coast", o.mesh.coast},
                                                          {"--bathy", o.mesh.bathy},
                                                          {"--region-file", o.mesh.region_file},
                                                          {"--size-regions", o.mesh.size_regions},
                                                          {"--config", o.config}};
    for (const auto &[name, path] : inputs)
        check_input_path(path, name); // (--config was read)
    check_output_files(files, inputs, o.overwrite);
    return planned;
}

void throw_if_interrupted() {
    if (InterruptGuard::interrupted())
        throw Cancelled();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Adds the `mesh` key of issue 4 (everything from rings and size field to the final mesh,
/// I/O excluded) when the pipeline did not report it: the stages that read no input.
void add_mesh_total(StageTimings &timings) {
    for (const auto &[name, s] : timings.stages)
        if (name == "mesh")
            return;
    timings.add("mesh", timings.compute_seconds());
}

/// A whole number with thousands separators: 33251 -> "33,251", -2505 -> "-2,505".
std::string grouped(long long v) {
    std::string digits = std::to_string(v < 0 ? -v : v), r;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0)
            r += ',';
        r += digits[i];
    }
    return (v < 0 ? "-" : "") + r;
}

/// The depth counts (nodes above sea level as sampled, those --min-depth raised) as a JSON object.
std::string depth_json(const DepthReport &d) {
    auto number_or_null = [](bool set, double v) {
        return set ? report_number(v) : std::string("null");
    };
    return "{\"nodes_above_sea_level\": " + std::to_string(d.above_sea_level) +
           ", \"min_sampled_depth_m\": " + number_or_null(d.above_sea_level > 0, d.shallowest_m) +
           ", \"min_depth_m\": " +
           number_or_null(d.min_depth_m.has_value(), d.min_depth_m.value_or(0)) +
           ", \"nodes_raised_to_min_depth\": " + std::to_string(d.min_depth_m ? d.raised : 0) + "}";
}

/// The summary's depth line, and unless `quiet` the warning on `err` when nodes above sea level
/// are written with negative depth (no --min-depth).
void print_depth(std::ostream &out, std::ostream &err, const DepthReport &d, bool quiet) {
    const auto count = static_cast<long long>(d.above_sea_level);
    std::string down_to;
    if (d.above_sea_level > 0)
        down_to = " (down to " + grouped(std::llround(d.shallowest_m)) + " m)";
    out << "depth             " << count << " nodes above sea level" << down_to;
    if (d.min_depth_m)
        out << ", " << d.raised << " raised to --min-depth " << report_number(*d.min_depth_m)
            << " m";
    out << "\n";
    if (count > 0 && !d.min_depth_m && !quiet)
        err << "globemesh: warning: " << grouped(count)
            << (count == 1 ? " node lies" : " nodes lie") << " above sea level" << down_to
            << (count == 1 ? " and is" : " and are")
            << " written with negative depth; --min-depth 5 would raise them to 5 m\n";
}

/// What the run changed of the coast and the land: the summary's lines from the typed reports.
void print_coast(std::ostream &out, const OceanMesh &run) {
    const MesherReport &m = run.mesher;
    out << "coast             " << run.coast.rings << " rings kept, islands dropped "
        << run.coast.islands_removed << ", lakes dropped " << run.coast.lakes_removed
        << ", inlets closed " << inlets_closed_text(m) << ", corners blunted " << m.corners_blunted
        << "\n"
        << "coast repairs     " << coast_repairs_text(run.coast_repairs) << "\n"
        << "faces on land     " << land_faces_text(m) << "\n";
    // The first six places (lon lat); all of them, up to 50, are in the file's attribute `key`.
    auto places = [&](const std::vector<Vec3> &at, const char *key) {
        constexpr std::size_t shown = 6;
        if (at.empty())
            return;
        out << "                  at " << places_text(at, shown)
            << (at.size() > shown ? std::string(" (") + key + ")" : "") << "\n";
    };
    places(m.land_faces_at, "faces_on_land_at");
    if (run.straits_closing && m.straits_closed > 0) {
        out << "straits closed    " << straits_closed_text(m) << "\n";
        places(m.straits_closed_at, "straits_closed_at");
    }
    out << "ocean components  " << ocean_components_text(m) << "\n";
}

int run_mesh(std::span<const std::string> args, std::ostream &out, std::ostream &err,
             TerminalProgress &terminal, const CliLibrary &lib) {
    auto command = std::make_unique<MeshCommand>(lib.writers);
    try {
        command->parse(args);
    } catch (const CLI::CallForHelp &) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForAllHelp &) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForVersion &) {
        out << version_text() << "\n";
        return 0;
    }
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
                                 command->app.config_to_str(true, false));

    if (o.check) {
        auto problems = check_mesh(mesh);
        if (!problems.empty())
            throw DataError("--check: the mesh breaks " + std::to_string(problems.size()) +
                            (problems.size() >= 20 ? "+" : "") + " invariants, first: " +
                            problems.front() + "; please report this with the command line");
    }

    // Computed once for the report and the writers (each would otherwise build the topology
    // again for it).
    const MeshStats stats = lib.compute_stats(mesh);
    // Every output of the run waits under its temporary name until all are complete.
    OutputBatch batch;
    const auto tw = std::chrono::steady_clock::now();
    WriteOptions write;
    write.overwrite = o.overwrite;
    write.history = history_text("mesh", args);
    write.stats = &stats;
    write.land = o.mesh.coast;
    write.extent_deg = o.mesh.region;
    write_run_outputs(mesh, planned, write, terminal);
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
          << "  \"history\": " << json_string(write.history) << ",\n"
          << "  \"outputs\": " << outputs_json(planned);
        r << ",\n  \"mesh\": " << stats_json(stats, "  ") << ",\n";
        if (run.depth)
            r << "  \"depth\": " << depth_json(*run.depth) << ",\n";
        // What the run did to the coast and the land, as the NetCDF file's global attributes say.
        r << "  \"attributes\": {";
        for (std::size_t i = 0; i < mesh.attributes.size(); ++i)
            r << (i ? ", " : "") << json_string(mesh.attributes[i].first) << ": "
              << json_string(mesh.attributes[i].second);
        r << "},\n"
          << "  \"stages\": " << stages_json(timings) << ",\n"
          << "  \"total_seconds\": " << json_number(total_s) << ",\n"
          << "  \"peak_memory_bytes\": " << peak << "\n}\n";
        OutputFile::write_text(o.report, r.str(), o.overwrite, "--report");
    }
    batch.commit(InterruptGuard::interrupted);
    InterruptGuard::finished();

    print_stats(out, stats, false);
    print_coast(out, run);
    if (run.depth)
        print_depth(out, err, *run.depth, o.quiet);
    print_timings(out, timings);
    out << "total time        " << exact_text(std::round(total_s * 1000) / 1000) << " s\n"
        << "peak memory       " << exact_text(std::round(peak / 1048576.0 * 10) / 10) << " MiB\n"
        << "wrote             " << outputs_text(planned);
    for (const auto *p : {&o.timings, &o.report})
        if (!p->empty())
            out << ", " << *p;
    out << "\n";
    return 0;
}

// --------------------------------------------------------------------------------------------
// globemesh triangulate

struct TriangulateCommand {
    TriangulateOptions t;
    std::vector<std::string> output, creation;
    std::string format, gpkg, timings;
    bool overwrite = false, quiet = false, verbose = false;
    CLI::App app{"Spherical Delaunay triangulation of scattered points (any OGR point source).",
                 "globemesh triangulate"};

    explicit TriangulateCommand(std::span<const Writer> table = writers()) {
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
};

int run_triangulate(std::span<const std::string> args, std::ostream &out, std::ostream &err,
                    TerminalProgress &terminal, const CliLibrary &lib) {
    auto command = std::make_unique<TriangulateCommand>(lib.writers);
    try {
        command->app.parse(reversed(args));
    } catch (const CLI::CallForHelp &) {
        out << command->app.help();
        return 0;
    } catch (const CLI::CallForVersion &) {
        out << version_text() << "\n";
        return 0;
    }
    const auto &c = *command;
    if (c.quiet && c.verbose)
        throw UsageError("--quiet and --verbose exclude each other");
    if (c.output.empty())
        throw UsageError("-o/--output is required: the UGRID file to write, e.g. -o out.nc");
    check_input_path(c.t.points, "POINTS");
    const OutputChoices choices{c.output, c.format, c.creation, {{"--gpkg", "GPKG", c.gpkg}}};
    const auto planned = plan_outputs(choices, lib.writers, {}, false);
    const std::pair<std::string, std::string> inputs[] = {{"POINTS", c.t.points}};
    check_output_files(output_files(planned, c.timings, "", lib.writers), inputs, c.overwrite);

    InterruptGuard interrupt;
    GdalMessages gdal_messages(err, c.verbose);
    StageTimings timings;
    terminal.configure(c.quiet, c.verbose);
    Mesh mesh = lib.triangulate_file(c.t, sub_progress(terminal.callback(), 0, mesh_share(planned)),
                                     &timings);
    throw_if_interrupted();
    OutputBatch batch; // every output waits under its temporary name until all are complete
    const auto tw = std::chrono::steady_clock::now();
    WriteOptions write;
    write.overwrite = c.overwrite;
    write.title = "globemesh spherical Delaunay triangulation";
    write.history = history_text("triangulate", args);
    write_run_outputs(mesh, planned, write, terminal);
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
    CLI::App app{"Counts, extent, edge lengths and quality of a UGRID mesh file.",
                 "globemesh info"};
    InfoCommand() {
        app.set_version_flag("--version", version_text(), "Print the version and exit");
        app.get_formatter()->column_width(36);
        app.add_option("MESH", path, "UGRID NetCDF file (ours or another tool's)")
            ->required()
            ->type_name("MESH.nc");
        app.add_flag("--json", json, "Print JSON for machines");
    }
};

int run_info(std::span<const std::string> args, std::ostream &out, const CliLibrary &lib) {
    InfoCommand command;
    try {
        command.app.parse(reversed(args));
    } catch (const CLI::CallForHelp &) {
        out << command.app.help();
        return 0;
    } catch (const CLI::CallForVersion &) {
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
    app->add_subcommand("mesh",
                        "Mesh the ocean: globemesh mesh --coast LAND -o OCEAN.nc [options]");
    app->add_subcommand("triangulate",
                        "Delaunay triangulation of points: globemesh triangulate POINTS -o OUT.nc");
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
    } else if (args[0] == "info") {
        InfoCommand c;
        out << c.app.help();
    } else if (args[0] == "help") {
        out << make_top_app()->help();
    } else {
        throw UsageError("help: unknown subcommand '" + args[0] +
                         "' (the subcommands are mesh, triangulate, info, help)");
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
    if (name == "info")
        return run_info(rest, out, lib);
    if (name == "help")
        return run_help(rest, out);
    if (!name.empty() && name[0] != '-')
        throw UsageError("unknown subcommand '" + name +
                         "' (the subcommands are mesh, triangulate, info, help)");
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
        throw UsageError(
            "unknown option '" + name +
            "' (globemesh takes --help, --version or a subcommand: mesh, triangulate, info, help)");
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
        const bool sub =
            !args.empty() && (args[0] == "mesh" || args[0] == "info" || args[0] == "triangulate");
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
