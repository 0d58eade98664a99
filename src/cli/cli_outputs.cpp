// The output flags and the writers table: see cli_outputs.hpp.
#include "cli_outputs.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <map>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "globemesh/error.hpp"

namespace globemesh::cli {

namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

/// ", or -f FESOM2 to write a FESOM2 mesh folder into it": the formats that write folders.
std::string folder_formats(std::span<const Writer> table) {
    std::string r;
    for (const Writer &w : table)
        if (!w.folder_files.empty())
            r += ", or -f " + w.name + " to write a " + w.long_name + " into it";
    return r;
}

/// The format of -o `path`: -f's when given, else its extension's; the table's first row for a
/// name without extension (as before the table, when -o wrote UGRID only).
const Writer &output_format(const std::string &path, const std::string &format,
                            std::span<const Writer> table) {
    const std::string formats = "; the formats are " + formats_text(table);
    if (!format.empty()) {
        const Writer *w = find_writer(table, format);
        if (w == nullptr)
            throw UsageError("-f/--output-format " + format + ": no such format" + formats);
        return *w;
    }
    if (const Writer *w = writer_for_extension(table, path))
        return *w;
    const std::string extension = fs::path(path).extension().string();
    std::error_code ec;
    if (extension.empty() && fs::is_directory(path, ec)) // as check_output_path says it
        throw IoError("--output " + path + " is a folder; give a file name" +
                      folder_formats(table));
    if (extension.empty())
        return table.front();
    if (lower(extension) == ".json")
        throw UsageError("--output " + path + " is named for JSON: use --report " + path +
                         " for the run summary; --output writes a mesh" + formats);
    throw UsageError("--output " + path + ": no format has the extension " + extension + formats +
                     "; name the file so, or choose the format with -f NAME");
}

/// The format of a --gpkg or --preview file, refusing a name made for another output.
const Writer &fixed_format(const OutputChoices::Fixed &f, std::span<const Writer> table) {
    const Writer *w = find_writer(table, f.format);
    if (w == nullptr)
        throw std::logic_error(f.option + ": no format " + f.format + " in the writers table");
    const Writer *named = writer_for_extension(table, f.path);
    const bool json = lower(fs::path(f.path).extension().string()) == ".json";
    if (json)
        throw UsageError(f.option + " writes " + w->long_name + ", but " + f.path +
                         " is named for JSON: use --report " + f.path + " for that");
    if (named != nullptr && named != w)
        throw UsageError(f.option + " writes " + w->long_name + ", but " + f.path +
                         " is named for " + named->long_name + ": use --output " + f.path +
                         " for that");
    return *w;
}

/// Gives each creation option (option, KEY=VALUE) to every output whose format takes KEY.
void assign_creation_options(std::vector<PlannedOutput> &planned, std::span<const Writer> table,
                             std::span<const std::pair<std::string, std::string>> creation) {
    for (const auto &[option, text] : creation) {
        const auto eq = text.find('=');
        if (eq == std::string::npos || eq == 0)
            throw UsageError(option + " " + text + ": give KEY=VALUE, e.g. --co FORMAT=NC2");
        std::string key = text.substr(0, eq);
        std::transform(key.begin(), key.end(), key.begin(),
                       [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
        bool taken = false;
        for (auto &p : planned) {
            const auto &known = p.request.writer->creation_options;
            if (std::none_of(known.begin(), known.end(),
                             [&](const CreationOption &c) { return c.name == key; }))
                continue;
            p.request.creation_options.emplace_back(key, text.substr(eq + 1));
            taken = true;
        }
        const std::string label =
            option == "--co" ? option + " " + text : option + " (" + text + ")";
        if (taken)
            continue;
        std::string takers;
        for (const Writer &w : table)
            if (std::any_of(w.creation_options.begin(), w.creation_options.end(),
                            [&](const CreationOption &c) { return c.name == key; }))
                takers += (takers.empty() ? "" : ", ") + w.name;
        throw UsageError(
            label + ": none of the outputs takes the creation option " + key +
            (takers.empty()
                 ? " (no format does)"
                 : " (" + takers + (takers.find(',') == std::string::npos ? " does)" : " do)")));
    }
    for (auto &p : planned)
        check_creation_options(*p.request.writer, p.request.creation_options,
                               p.option + " " + p.request.path.string());
}

/// True when `folder` exists as a folder; false when it is missing and its parent is there (the
/// writer makes it). Throws IoError for a file in its place or a missing parent.
bool check_output_folder(const fs::path &folder, const std::string &what) {
    std::error_code ec;
    if (fs::is_directory(folder, ec))
        return true;
    if (fs::exists(folder, ec))
        throw IoError(what + " is a file, and this format writes a folder of files: give a folder "
                             "name");
    const fs::path named = folder.has_filename() ? folder : folder.parent_path(); // "dir/"
    const fs::path parent = named.parent_path().empty() ? fs::path(".") : named.parent_path();
    if (!fs::is_directory(parent, ec))
        throw IoError(what + ": the folder " + parent.string() +
                      " does not exist; create it first");
    return false;
}

} // namespace

void add_output_flags(CLI::App &app, std::vector<std::string> &output, std::string &format,
                      std::vector<std::string> &creation, std::span<const Writer> table,
                      const std::string &group) {
    std::string names, extensions;
    for (const Writer &w : table) {
        names += (names.empty() ? "" : ", ") + w.name;
        if (!w.extensions.empty())
            extensions += (extensions.empty() ? "" : ", ") + w.extensions.front() + " " + w.name;
        else
            extensions +=
                (extensions.empty() ? "" : ", ") + std::string("a folder with -f ") + w.name;
    }
    // One value per -o (it may be repeated). Not given, --print-config shows -o as "" and leaves
    // out -f and --co, so a run's configuration reads as it did before they existed.
    app.add_option(
           "-o,--output", output,
           "Mesh file to write (required; may be repeated): its extension picks the format (" +
               extensions + "), or -f")
        ->group(group)
        ->type_name("OUT.nc")
        ->allow_extra_args(false)
        ->always_capture_default(false)
        ->default_str("")
        ->run_callback_for_default();
    app.add_option("-f,--output-format", format,
                   "Format of the -o file (with several, of the one without an extension), as "
                   "GDAL names it: " +
                       names + "; default: from its extension")
        ->group(group)
        ->type_name("NAME")
        ->always_capture_default(false)
        ->default_str("")
        ->run_callback_for_default(false);
    app.add_option(
           "--co,--creation-option", creation,
           "KEY=VALUE creation option, given to every output whose format takes KEY (GDAL's -co)")
        ->group(group)
        ->type_name("KEY=VALUE")
        ->allow_extra_args(false)
        ->always_capture_default(false)
        ->default_str("")
        ->run_callback_for_default(false);
}

void add_model_flags(CLI::App &app, std::string &output_srs, std::string &msh_version,
                     std::span<const Writer> table, const std::string &group) {
    std::string planar;
    for (const Writer &w : table)
        for (const auto &e : w.extensions)
            if (w.takes_output_srs &&
                std::find(w.lonlat_extensions.begin(), w.lonlat_extensions.end(), e) ==
                    w.lonlat_extensions.end())
                planar += (planar.empty() ? "" : ", ") + e;
    // Not given, --print-config leaves them out, as -f and --co.
    app.add_option("--output-srs", output_srs,
                   "CRS of the node coordinates of " + planar +
                       " outputs (EPSG:32631, a PROJ string, WKT); the others, and by default "
                       "all, hold lon/lat")
        ->group(group)
        ->type_name("CRS")
        ->always_capture_default(false)
        ->default_str("")
        ->run_callback_for_default(false);
    app.add_option("--msh-version", msh_version,
                   "MSH version of .msh outputs: 4.1 (default) or 2.2 (= --co MSH_VERSION=...)")
        ->group(group)
        ->type_name("VERSION")
        ->always_capture_default(false)
        ->default_str("")
        ->run_callback_for_default(false);
}

std::vector<std::pair<std::string, std::string>>
msh_version_creation(const std::string &msh_version, const std::vector<std::string> &creation) {
    if (msh_version.empty())
        return {};
    if (msh_version != "4.1" && msh_version != "2.2")
        throw UsageError("--msh-version " + msh_version + ": use 4.1 or 2.2");
    for (const auto &text : creation) {
        const auto eq = text.find('=');
        std::string key = text.substr(0, eq);
        std::transform(key.begin(), key.end(), key.begin(),
                       [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
        if (key == "MSH_VERSION" && text.substr(eq + 1) != msh_version)
            throw UsageError("--msh-version " + msh_version + " and --co " + text +
                             " ask for two MSH versions: give one");
    }
    return {{"--msh-version", "MSH_VERSION=" + msh_version}};
}

std::vector<PlannedOutput>
plan_outputs(const OutputChoices &c, std::span<const Writer> table,
             std::span<const std::pair<std::string, std::string>> extra_creation, bool has_depth,
             const std::string &no_depth) {
    // -f names the format of the one -o, or, with several, of the one without an extension (a
    // FESOM2 folder beside the UGRID file); the others take theirs from their extensions.
    const auto bare = [](const std::string &path) { return fs::path(path).extension().empty(); };
    if (!c.format.empty() && c.output.size() > 1 &&
        std::count_if(c.output.begin(), c.output.end(), bare) != 1)
        throw UsageError(
            "-f/--output-format names the format of one -o file; with several, of the one "
            "without an extension, each other taking its format from its extension");
    std::vector<PlannedOutput> planned;
    for (const auto &path : c.output) {
        const std::string format = c.output.size() == 1 || bare(path) ? c.format : "";
        planned.push_back({"--output", {&output_format(path, format, table), path, {}}});
    }
    for (const auto &f : c.fixed)
        if (!f.path.empty())
            planned.push_back({f.option, {&fixed_format(f, table), f.path, {}}});
    std::vector<std::pair<std::string, std::string>> creation(extra_creation.begin(),
                                                              extra_creation.end());
    for (const auto &text : c.creation)
        creation.emplace_back("--co", text);
    assign_creation_options(planned, table, creation);
    for (const auto &p : planned)
        if ((p.request.writer->needs & needs_depth) && !has_depth)
            throw UsageError(p.option + " " + p.request.path.string() + ": " +
                             p.request.writer->name + " needs depths; " + no_depth);
    // The table's order is the order of writing (a writer that computes the face areas first).
    auto row = [&](const PlannedOutput &p) { return p.request.writer - table.data(); };
    std::stable_sort(planned.begin(), planned.end(),
                     [&](const auto &a, const auto &b) { return row(a) < row(b); });
    return planned;
}

void check_json_output(const std::string &path, const std::string &option,
                       std::span<const Writer> table) {
    if (const Writer *w = writer_for_extension(table, path))
        throw UsageError(option + " writes JSON, but " + path + " is named for " + w->long_name +
                         ": use --output " + path + " for that");
}

std::vector<std::pair<std::string, std::string>>
output_files(std::span<const PlannedOutput> planned, const std::string &timings,
             const std::string &report, std::span<const Writer> table) {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto &p : planned) {
        const auto &inside = p.request.writer->folder_files;
        if (inside.empty()) {
            files.emplace_back(p.option, p.request.path.string());
            continue;
        }
        // A folder format: its files, checked as files when the folder exists (else it makes it).
        if (check_output_folder(p.request.path, p.option + " " + p.request.path.string()))
            for (const auto &name : inside)
                files.emplace_back(p.option, (p.request.path / name).string());
    }
    for (const auto &[name, path] :
         {std::pair<std::string, std::string>{"--timings", timings}, {"--report", report}}) {
        if (path.empty())
            continue;
        check_json_output(path, name, table);
        files.emplace_back(name, path);
    }
    return files;
}

void check_output_files(std::span<const std::pair<std::string, std::string>> outputs,
                        std::span<const std::pair<std::string, std::string>> inputs,
                        bool overwrite) {
    for (std::size_t i = 0; i < outputs.size(); ++i)
        for (std::size_t j = i + 1; j < outputs.size(); ++j)
            if (fs::absolute(outputs[i].second).lexically_normal() ==
                fs::absolute(outputs[j].second).lexically_normal())
                throw UsageError(outputs[i].first + " and " + outputs[j].first +
                                 " name the same file " + outputs[i].second);
    for (const auto &[name, path] : outputs)
        check_not_an_input(path, name, inputs);
    for (const auto &[name, path] : outputs)
        check_output_path(path, name, overwrite);
}

double mesh_share(std::span<const PlannedOutput> planned) {
    double total = 1;
    for (const auto &p : planned)
        total += p.request.writer->progress_weight;
    return 1 / total;
}

void write_run_outputs(const Mesh &mesh, std::span<const PlannedOutput> planned,
                       WriteOptions options, TerminalProgress &terminal, StageTimings *timings) {
    options.progress = sub_progress(terminal.callback(), mesh_share(planned), 1);
    const auto t0 = std::chrono::steady_clock::now();
    write_outputs(mesh, requests(planned), options, InterruptGuard::interrupted, timings);
    if (timings)
        timings->add("write", seconds_since(t0));
}

std::vector<OutputRequest> requests(std::span<const PlannedOutput> planned) {
    std::vector<OutputRequest> r;
    for (const auto &p : planned)
        r.push_back(p.request);
    return r;
}

std::string outputs_json(std::span<const PlannedOutput> planned) {
    std::vector<std::string> keys; // in the order written
    std::map<std::string, std::vector<std::string>> paths;
    for (const auto &p : planned) {
        const std::string &key = p.request.writer->report_key;
        if (paths[key].empty())
            keys.push_back(key);
        paths[key].push_back(json_string(p.request.path.string()));
    }
    std::string r = "{";
    for (const auto &key : keys) {
        const auto &list = paths[key];
        std::string value = list.front();
        if (list.size() > 1) {
            value = "[";
            for (std::size_t i = 0; i < list.size(); ++i)
                value += (i ? ", " : "") + list[i];
            value += "]";
        }
        r += (r.size() > 1 ? ", " : "") + json_string(key) + ": " + value;
    }
    return r + "}";
}

std::string outputs_text(std::span<const PlannedOutput> planned, const Mesh *mesh) {
    const bool styled = mesh != nullptr && mesh->node_field("depth") != nullptr;
    std::string r;
    for (const auto &p : planned) {
        r += (r.empty() ? "" : ", ") + p.request.path.string();
        if (styled && p.request.writer->name == "UGRID" && p.request.path.extension() != ".qml")
            r += ", " + fs::path(p.request.path).replace_extension(".qml").string();
    }
    return r;
}

} // namespace globemesh::cli
