// The GeoPackage spatial index (extension gpkg_rtree_index) built in bulk, for gpkg_write.cpp.
//
// GDAL 3.6 (Debian 12) fills a GeoPackage's RTree at close with one SQLite R*Tree insertion a
// row, about 9 us each: two thirds of writing a GeoPackage. GDAL 3.7 and later pack the tree
// themselves; this does the same for every version. The layers are written without an index
// (SPATIAL_INDEX=NO), then this opens the closed file with SQLite, creates each index's virtual
// table as GDAL does, and writes the tree's shadow tables directly: nodes packed by
// Sort-Tile-Recursive, in SQLite's node format (the layout SQLite's rtree module documents in
// its source: a 2-byte depth in the root, a 2-byte cell count, then per cell a 64-bit id and
// four 32-bit floats, all big-endian). The triggers and the gpkg_extensions row are GDAL's own
// (GeoPackage 1.2's), so that editing the layer later in QGIS or GDAL keeps the index.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "globemesh/progress.hpp"

namespace globemesh::io {

/// A feature's envelope as the RTree keeps it: min x, max x, min y, max y in 32-bit floats,
/// rounded outwards from the geometry's (double) envelope.
using RtreeBox = std::array<float, 4>;

/// The envelope [min_x, max_x] x [min_y, max_y] rounded outwards to floats, as SQLite's rtree
/// stores a box.
RtreeBox rtree_box(double min_x, double max_x, double min_y, double max_y);

/// One spatial layer's index: its table and geometry column, and each feature's box, the
/// feature with id (fid) i + 1 at boxes[i].
struct RtreeLayer {
    std::string table;
    std::string column;
    std::vector<RtreeBox> boxes;
};

/// Adds the spatial index of each layer to the closed GeoPackage `file` (written by GDAL with
/// SPATIAL_INDEX=NO), in one transaction: all of them, or none and an IoError that names
/// `output` (the path the user gave; `file` is its temporary name) and SQLite's reason. Reports
/// to `progress` under the stage "write_gpkg" (and stops with Cancelled, none written, when
/// asked).
void add_rtree_indexes(const std::filesystem::path &file, const std::vector<RtreeLayer> &layers,
                       const std::filesystem::path &output, const Progress &progress = {});

} // namespace globemesh::io
