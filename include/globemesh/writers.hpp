// globemesh/writers.hpp: the table of output formats, and the writing of a run's outputs.
//
// Each output format is one row of writers(): the name GDAL/OGR users know (a driver name such
// as "UGRID", "GPKG", "PNG"), its file extensions, what it needs of the mesh, the creation
// options it takes (as GDAL's -co KEY=VALUE) and its write function. The command line takes its
// -o/-f choices, its progress shares, its summary and its report's list of outputs from this
// table, so a new format is one file in src/io/ and one row in src/io/writers.cpp.
//
// write_outputs() writes a list of outputs of one mesh so that they appear together or not at
// all (OutputBatch, output_file.hpp): on an error or a cancellation no file is left.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

struct MeshStats;

/// KEY=VALUE creation options of one output, keys upper case (GDAL's -co).
using CreationOptions = std::vector<std::pair<std::string, std::string>>;

/// What every writer takes; each writer reads the fields it has a use for.
struct WriteOptions {
    bool overwrite =
        false; ///< replace an existing file; otherwise an existing output is an IoError
    /// Reports the share written; returning false cancels (Cancelled, no file left).
    Progress progress;
    std::string title = "globemesh ocean mesh"; ///< what the file says it holds
    std::string history; ///< the full command line and date (the CLI fills it)
    /// compute_stats of this same mesh when the caller has it; null: the writer computes it.
    const MeshStats *stats = nullptr;
    /// Each face's geodesic area (m2), handed from a writer that computes them to one that
    /// needs them (write_outputs sets it when two outputs share it); null: computed anew.
    std::vector<double> *face_areas_m2 = nullptr;
    std::string land; ///< OGR land polygons a picture draws under the mesh; empty: none
    std::optional<std::array<double, 4>> extent_deg; ///< W,S,E,N of a picture; unset: the mesh's
    CreationOptions creation_options;                ///< this output's, checked against its row
    /// --output-srs: the CRS (as GDAL's SetFromUserInput takes it: EPSG:32631, a PROJ string,
    /// WKT) of the node coordinates of the formats that take planar ones; empty: lon/lat.
    /// write_outputs clears it for an output that does not take it (Writer::takes_output_srs).
    std::string output_srs;
};

/// What a format requires of the mesh (bits of Writer::needs).
enum WriterNeeds : unsigned {
    needs_mesh_only = 0,
    needs_depth = 1, ///< a node field "depth" (a run with a bathymetry)
};

/// A creation option a writer takes: its key, the values it accepts (upper case; empty: any
/// text) and what it does, for the messages and the manual.
struct CreationOption {
    std::string name;
    std::vector<std::string> values;
    std::string description;
    /// For a free value (no list): what is wrong with it, or "" (unset: any value).
    std::function<std::string(const std::string &value)> problem{};
};

/// One output format.
struct Writer {
    std::string name;                    ///< as GDAL/OGR name a driver: "UGRID", "GPKG", "PNG"
    std::string long_name;               ///< in messages: "UGRID NetCDF", "GeoPackage"
    std::vector<std::string> extensions; ///< name suffixes (".nc", "_net.nc"); first: usual
    /// The files it writes into the folder the output names (created when missing); empty for
    /// a format that writes the file the output names. A folder format has no extension.
    std::vector<std::string> folder_files{};
    std::string report_key;           ///< its key in the run report's "outputs"
    unsigned needs = needs_mesh_only; ///< WriterNeeds bits
    /// Computes or takes each face's geodesic area (WriteOptions::face_areas_m2).
    bool shares_face_areas = false;
    /// Its writing time relative to meshing the same mesh, for the shares of one progress line.
    double progress_weight = 1;
    std::vector<CreationOption> creation_options{};
    /// Writes its node coordinates in WriteOptions::output_srs, except in the files of
    /// lonlat_extensions (SCHISM's hgrid.ll), which hold lon/lat by definition.
    bool takes_output_srs = false;
    std::vector<std::string> lonlat_extensions{};
    std::function<void(const Mesh &, const std::filesystem::path &, const WriteOptions &)> write{};
};

/// The output formats, in the order a run writes them.
const std::vector<Writer> &writers();

/// The row named `name` (any case), or null.
const Writer *find_writer(std::span<const Writer> table, std::string_view name);
/// The row with the longest of the table's extensions (suffixes: ".nc", "_net.nc") that `path`'s
/// file name ends with (any case), or null (also for no extension).
const Writer *writer_for_extension(std::span<const Writer> table,
                                   const std::filesystem::path &path);
/// "UGRID (.nc, .nc4), GPKG (.gpkg), PNG (.png)": the formats, for messages.
std::string formats_text(std::span<const Writer> table);
/// Throws UsageError naming `what` (e.g. "-o x.nc") for a key the writer does not take, a
/// value outside its list or one its `problem` finds wrong; upper-cases keys and listed values
/// in place.
void check_creation_options(const Writer &writer, CreationOptions &options,
                            const std::string &what);

/// The value of creation option `key` (upper case, as check_creation_options leaves it), or
/// `fallback`.
std::string creation_option(const CreationOptions &options, std::string_view key,
                            std::string fallback = {});

/// One output of a run: the format, the file and its creation options.
struct OutputRequest {
    const Writer *writer = nullptr;
    std::filesystem::path path;
    CreationOptions creation_options;
};

/// Whether `output` writes its node coordinates in an --output-srs (see Writer).
bool takes_output_srs(const OutputRequest &output);

/// Checks --output-srs `srs` against the outputs before anything runs: UsageError (naming
/// `option`) for a CRS that does not parse, one that is neither projected nor geographic WGS 84,
/// no output that takes it, or an output whose creation options ask for other coordinates
/// (gmsh COORDS=SPHERE). Nothing for an empty `srs`.
void check_output_srs(const std::string &srs, std::span<const OutputRequest> outputs,
                      const std::string &option = "--output-srs");

/// Writes each output in the order given, each with `common` plus its own creation options and
/// its share of common.progress (by progress_weight). Throws what a writer throws (IoError,
/// DataError when the mesh lacks what a format needs, Cancelled when progress or `cancelled`
/// says so); then no output is left. Under a live OutputBatch the files join it; otherwise
/// they appear together at the end. With `timings`, each format's seconds are a stage of their
/// own (writer_stage_name; two outputs of one format add up).
void write_outputs(const Mesh &mesh, std::span<const OutputRequest> outputs,
                   const WriteOptions &common, const std::function<bool()> &cancelled = {},
                   StageTimings *timings = nullptr);

/// "write_" and the format's name in lower case: write_ugrid, write_gpkg, write_png...
std::string writer_stage_name(const Writer &writer);

/// The sum of the outputs' progress weights.
double progress_weight(std::span<const OutputRequest> outputs);

} // namespace globemesh
