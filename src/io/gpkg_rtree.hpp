// The GeoPackage writer's bulk steps (gpkg_write.cpp): the metadata of its large layers and
// their spatial indexes (extension gpkg_rtree_index).
//
// GDAL creates the file, its tables and metadata, and closes it. Then this opens it with SQLite
// to create each spatial index's tables, empty, as GDAL does; the rows of the large layers and
// of the indexes are written as pages (sqlite_pages.hpp); then SQLite again writes each large
// layer's count, extent and sequence. SQLite's journal and syncs are off while it writes: the
// file is a temporary one, deleted when the write fails, and whole once the last step commits.
//
// GDAL 3.6 (Debian 12) fills a GeoPackage's RTree at close with one SQLite R*Tree insertion a
// row, about 9 us each: two thirds of writing a GeoPackage. GDAL 3.7 and later pack the tree
// themselves; this does the same for every version. The layers are written without an index
// (SPATIAL_INDEX=NO), then this creates each index's virtual table as GDAL does, and writes the
// tree's shadow tables: nodes packed by Sort-Tile-Recursive, in SQLite's node format (the
// layout SQLite's rtree module documents in its source: a 2-byte depth in the root, a 2-byte
// cell count, then per cell a 64-bit id and four 32-bit floats, all big-endian). The triggers
// and the gpkg_extensions row are GDAL's own (GeoPackage 1.2's), so that editing the layer
// later in QGIS or GDAL keeps the index.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "globemesh/progress.hpp"

struct sqlite3;

namespace globemesh::io {

class SqlitePages;

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

/// The closed GeoPackage `file` (written by GDAL) opened with SQLite, inside one transaction
/// that commit() ends; destroyed before, it rolls back (the file is then only fit for deletion).
/// Failures throw an IoError that names `output` (the path the user gave; `file` is its
/// temporary name) and SQLite's reason.
class GpkgSqlite {
public:
    GpkgSqlite(const std::filesystem::path &file, const std::filesystem::path &output);
    ~GpkgSqlite();
    GpkgSqlite(const GpkgSqlite &) = delete;
    GpkgSqlite &operator=(const GpkgSqlite &) = delete;

    /// Throws the IoError of `step`, for SQLite's last error or `why`.
    [[noreturn]] void fail(const std::string &step, std::string why = "") const;
    void exec(const std::string &sql);
    void commit();
    sqlite3 *get() const { return db_; }

private:
    sqlite3 *db_ = nullptr;
    std::filesystem::path output_;
    bool in_transaction_ = false;
};

/// The root page of `table` in sqlite_master, once its columns are checked to be `columns` in
/// order (the order of the records written into it).
std::uint32_t table_root(GpkgSqlite &db, const std::string &table,
                         const std::vector<std::string> &columns);

/// A spatial layer's index as create_rtree_index leaves it: empty, with the size of a node's
/// blob (SQLite's choice for the file's page size) and the root pages of its shadow tables.
struct RtreeTables {
    std::size_t node_bytes = 0;
    std::uint32_t node = 0, rowid = 0, parent = 0;
};

/// Creates the index of a layer written by GDAL with SPATIAL_INDEX=NO, as GDAL does: the virtual
/// table (empty), GDAL's triggers and the gpkg_extensions row (and that table when missing).
RtreeTables create_rtree_index(GpkgSqlite &db, const std::string &table, const std::string &column);

/// Writes each layer's packed tree into its index's tables, made by create_rtree_index (the
/// file closed by SQLite since). Reports to `progress` under the stage "write_gpkg" (and stops
/// with Cancelled when asked).
void write_rtree_indexes(SqlitePages &file, const std::vector<RtreeLayer> &layers,
                         const std::vector<RtreeTables> &tables, const Progress &progress = {});

/// A layer whose rows were written as pages gets what GDAL keeps of them: its row count
/// (gpkg_ogr_contents), its extent (gpkg_contents: min x, max x, min y, max y; none is left as
/// GDAL wrote it) and its AUTOINCREMENT sequence (sqlite_sequence: the last fid).
void finish_bulk_layer(GpkgSqlite &db, const std::string &table, std::int64_t rows,
                       const std::array<double, 4> &extent);

} // namespace globemesh::io
