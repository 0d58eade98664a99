// The table of output formats and write_outputs(): see globemesh/writers.hpp.
#include "globemesh/writers.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <memory>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "mesh_topology.hpp"

namespace globemesh {

namespace fs = std::filesystem;

// Each format's file in src/io/ defines its write function.
void write_as_ugrid(const Mesh &mesh, const fs::path &path,
                    const WriteOptions &options); // ugrid_write.cpp
void write_as_gpkg(const Mesh &mesh, const fs::path &path,
                   const WriteOptions &options); // gpkg_write.cpp
void write_as_png(const Mesh &mesh, const fs::path &path,
                  const WriteOptions &options); // preview_png.cpp
void write_as_gmsh(const Mesh &mesh, const fs::path &path,
                   const WriteOptions &options); // gmsh_write.cpp
void write_as_adcirc(const Mesh &mesh, const fs::path &path,
                     const WriteOptions &options); // adcirc_write.cpp
void write_as_schism(const Mesh &mesh, const fs::path &path,
                     const WriteOptions &options); // adcirc_write.cpp
void write_as_selafin(const Mesh &mesh, const fs::path &path,
                      const WriteOptions &options); // selafin_write.cpp
void write_as_dflowfm(const Mesh &mesh, const fs::path &path,
                      const WriteOptions &options); // dflowfm_write.cpp
void write_as_fesom2(const Mesh &mesh, const fs::path &path,
                     const WriteOptions &options);            // fesom2_write.cpp
std::string fesom2_levels_problem(const std::string &levels); // fesom2_write.cpp

// The progress weights: seconds to write over seconds to read and mesh, at 20 km on 1:50m land
// (1.08e6 nodes): UGRID 2.6 s, GPKG 7.9 s, PNG 1.8 s, meshing 1.7 s.
const std::vector<Writer> &writers() {
    static const std::vector<Writer> table = {
        {.name = "UGRID",
         .long_name = "UGRID NetCDF",
         .extensions = {".nc", ".nc4"},
         .report_key = "netcdf",
         .shares_face_areas = true,
         .progress_weight = 1.5,
         .creation_options = {{"FORMAT",
                               {"NC4", "NC2"},
                               "NC4: NetCDF-4 with deflate; NC2: netCDF-3 64-bit offset"}},
         .write = write_as_ugrid},
        {.name = "GPKG",
         .long_name = "GeoPackage",
         .extensions = {".gpkg"},
         .report_key = "gpkg",
         .shares_face_areas = true,
         .progress_weight = 4.6,
         .write = write_as_gpkg},
        {.name = "PNG",
         .long_name = "PNG picture",
         .extensions = {".png"},
         .report_key = "preview",
         .progress_weight = 1.1,
         .write = write_as_png},
        {.name = "GMSH",
         .long_name = "gmsh MSH",
         .extensions = {".msh"},
         .report_key = "gmsh",
         .progress_weight = 1.5,
         .creation_options =
             {{"MSH_VERSION", {"4.1", "2.2"}, "4.1 (default) or 2.2 of the MSH format"},
              {"COORDS",
               {"LONLAT", "SPHERE"},
               "LONLAT: lon/lat degrees (default); SPHERE: x y z in metres on a sphere"},
              {"RADIUS", {}, "the sphere's radius in metres for COORDS=SPHERE (6371000)"},
              {"OPEN_GROUPS",
               {"NO", "YES"},
               "YES: each open boundary its own physical group open_1, open_2... (tags 4, 5...) "
               "instead of open"}},
         .takes_output_srs = true,
         .write = write_as_gmsh},
        {.name = "ADCIRC",
         .long_name = "ADCIRC fort.14",
         .extensions = {".14"},
         .report_key = "adcirc",
         .progress_weight = 0.4, // 0.6 to 0.9 s at 1.08e6 nodes, as above
         .takes_output_srs = true,
         .write = write_as_adcirc},
        {.name = "SCHISM",
         .long_name = "SCHISM hgrid.gr3",
         .extensions = {".gr3", ".ll"},
         .report_key = "schism",
         .progress_weight = 0.4, // 0.6 to 0.9 s at 1.08e6 nodes, as above
         .takes_output_srs = true,
         .lonlat_extensions = {".ll"},
         .write = write_as_schism},
        {.name = "SELAFIN",
         .long_name = "TELEMAC SELAFIN and its .cli",
         .extensions = {".slf"},
         .report_key = "selafin",
         .progress_weight = 0.25, // 0.6 s at 1.08e6 nodes, as above
         .creation_options = {{"PRECISION",
                               {"SINGLE", "DOUBLE"},
                               "SINGLE: SERAFIN, float32 reals; DOUBLE: SERAFIND, float64 (lon/lat "
                               "to the micrometre)"}},
         .takes_output_srs = true,
         .write = write_as_selafin},
        {.name = "DFLOWFM",
         .long_name = "D-Flow FM net file",
         .extensions = {"_net.nc"}, // before ".nc": the longest suffix a name ends with wins
         .report_key = "dflowfm",
         .progress_weight = 0.4, // 1.2 to 1.6 s at 1.08e6 nodes (bench/RESULTS-dflowfm.md)
         .takes_output_srs = true,
         .write = write_as_dflowfm},
        {.name = "FESOM2",
         .long_name = "FESOM2 mesh folder",
         .extensions = {},
         .folder_files = {"nod2d.out", "elem2d.out", "aux3d.out"},
         .report_key = "fesom2",
         .needs = needs_depth,
         .progress_weight = 0.4, // 1.4 s at 1.08e6 nodes, as ADCIRC (bench/RESULTS-fesom2.md)
         .creation_options = {{"LEVELS",
                               {},
                               "the model levels in metres, from 0 down, comma-separated "
                               "(default: the 48 of FESOM2's CORE2 mesh)",
                               fesom2_levels_problem}},
         .write = write_as_fesom2},
    };
    return table;
}

namespace {

std::string upper(std::string_view s) {
    std::string r(s);
    std::transform(r.begin(), r.end(), r.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return r;
}

std::string lower(std::string_view s) {
    std::string r(s);
    std::transform(r.begin(), r.end(), r.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return r;
}

std::string joined(const std::vector<std::string> &items) {
    std::string r;
    for (const auto &item : items)
        r += (r.empty() ? "" : ", ") + item;
    return r;
}

} // namespace

const Writer *find_writer(std::span<const Writer> table, std::string_view name) {
    for (const Writer &w : table)
        if (upper(w.name) == upper(name))
            return &w;
    return nullptr;
}

const Writer *writer_for_extension(std::span<const Writer> table, const fs::path &path) {
    // The longest suffix wins ("x_net.nc" is D-Flow FM, not UGRID); a name that is only the
    // suffix (".nc", a hidden file) has no extension.
    const std::string name = lower(path.filename().string());
    const Writer *found = nullptr;
    std::size_t longest = 0;
    for (const Writer &w : table)
        for (const std::string &suffix : w.extensions)
            if (suffix.size() > longest && name.size() > suffix.size() && name.ends_with(suffix)) {
                found = &w;
                longest = suffix.size();
            }
    return found;
}

std::string formats_text(std::span<const Writer> table) {
    std::string r;
    for (const Writer &w : table)
        r += (r.empty() ? "" : ", ") + w.name + " (" +
             (w.extensions.empty() ? std::string("a folder, with -f ") + w.name
                                   : joined(w.extensions)) +
             ")";
    return r;
}

void check_creation_options(const Writer &writer, CreationOptions &options,
                            const std::string &what) {
    for (auto &[key, value] : options) {
        key = upper(key);
        const std::string &name = key; // (clang 14 cannot capture a structured binding)
        auto known = std::find_if(writer.creation_options.begin(), writer.creation_options.end(),
                                  [&](const CreationOption &c) { return c.name == name; });
        if (known == writer.creation_options.end()) {
            std::vector<std::string> names;
            for (const auto &c : writer.creation_options)
                names.push_back(c.name);
            throw UsageError(
                what + ": " + writer.name + " takes no creation option " + key +
                (names.empty() ? " (it takes none)" : " (it takes " + joined(names) + ")"));
        }
        if (known->values.empty()) {
            const std::string problem = known->problem ? known->problem(value) : "";
            if (!problem.empty())
                throw UsageError(what + ": " + writer.name + " creation option " + key + "=" +
                                 value + ": " + problem);
            continue;
        }
        if (std::find(known->values.begin(), known->values.end(), upper(value)) ==
            known->values.end()) {
            std::string choices = known->values.front();
            for (std::size_t i = 1; i < known->values.size(); ++i)
                choices += (i + 1 == known->values.size() ? " or " : ", ") + known->values[i];
            throw UsageError(what + ": " + writer.name + " creation option " + key + "=" + value +
                             ": use " + key + "=" + choices);
        }
        value = upper(value);
    }
}

std::string creation_option(const CreationOptions &options, std::string_view key,
                            std::string fallback) {
    for (const auto &[k, v] : options)
        if (k == key)
            return v;
    return fallback;
}

bool takes_output_srs(const OutputRequest &output) {
    const auto &lonlat = output.writer->lonlat_extensions;
    return output.writer->takes_output_srs &&
           std::find(lonlat.begin(), lonlat.end(), lower(output.path.extension().string())) ==
               lonlat.end();
}

double progress_weight(std::span<const OutputRequest> outputs) {
    double total = 0;
    for (const auto &o : outputs)
        total += o.writer->progress_weight;
    return total;
}

std::string writer_stage_name(const Writer &writer) {
    return "write_" + lower(writer.name);
}

void write_outputs(const Mesh &mesh, std::span<const OutputRequest> outputs,
                   const WriteOptions &common, const std::function<bool()> &cancelled,
                   StageTimings *timings) {
    for (const auto &o : outputs)
        if ((o.writer->needs & needs_depth) && mesh.node_field("depth") == nullptr)
            throw DataError(o.writer->name + " output " + o.path.string() +
                            " needs depths, and the mesh has none (mesh with a bathymetry)");
    // The face areas pass from one writer to the next (8 bytes a face) only when two use them.
    const auto sharing = std::count_if(outputs.begin(), outputs.end(), [](const OutputRequest &o) {
        return o.writer->shares_face_areas;
    });
    std::vector<double> face_areas;
    // Joins the caller's batch when there is one (the CLI adds its reports to it).
    std::unique_ptr<OutputBatch> own =
        OutputBatch::active() ? nullptr : std::make_unique<OutputBatch>();
    const double total = progress_weight(outputs);
    double at = 0;
    std::vector<OutputRequest> checked(outputs.begin(), outputs.end());
    for (auto &o : checked)
        check_creation_options(*o.writer, o.creation_options, o.path.string());
    check_output_srs(common.output_srs, checked);
    // The writers share one topology (and the caller's statistics, when it made them in a scope
    // of its own); the last writer holds it alone, so it can free it early.
    const io::SharedTopology shared(mesh);
    for (const auto &o : checked) {
        if (&o == &checked.back())
            io::SharedTopology::let_go(mesh);
        WriteOptions options = common;
        options.creation_options = o.creation_options;
        if (!takes_output_srs(o))
            options.output_srs.clear();
        if (sharing > 1 && o.writer->shares_face_areas)
            options.face_areas_m2 = &face_areas;
        options.progress =
            sub_progress(common.progress, at / total, (at + o.writer->progress_weight) / total);
        at += o.writer->progress_weight;
        const auto t0 = std::chrono::steady_clock::now();
        o.writer->write(mesh, o.path, options);
        if (timings)
            timings->add_to(
                writer_stage_name(*o.writer),
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        if (cancelled && cancelled())
            throw Cancelled();
    }
    if (own)
        own->commit(cancelled);
}

} // namespace globemesh
