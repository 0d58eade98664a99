// The GeoPackage writer's bulk steps in SQLite (gpkg_write.cpp): the rows of its large layers
// and their spatial indexes (extension gpkg_rtree_index).
//
// GDAL creates the file, its tables and metadata, and closes it; this opens the closed file
// with SQLite and, in one transaction, inserts the rows through one prepared statement per
// table (GDAL's per-feature path cost more than SQLite itself), then packs each spatial index.
// SQLite's journal and syncs are off while it writes: the file is a temporary one, deleted when
// the write fails, and whole once the transaction commits.
//
// GDAL 3.6 (Debian 12) fills a GeoPackage's RTree at close with one SQLite R*Tree insertion a
// row, about 9 us each: two thirds of writing a GeoPackage. GDAL 3.7 and later pack the tree
// themselves; this does the same for every version. The layers are written without an index
// (SPATIAL_INDEX=NO), then this creates each index's virtual table as GDAL does, and writes the
// tree's shadow tables directly: nodes packed by Sort-Tile-Recursive, in SQLite's node format
// (the layout SQLite's rtree module documents in its source: a 2-byte depth in the root, a
// 2-byte cell count, then per cell a 64-bit id and four 32-bit floats, all big-endian). The
// triggers and the gpkg_extensions row are GDAL's own (GeoPackage 1.2's), so that editing the
// layer later in QGIS or GDAL keeps the index.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "globemesh/progress.hpp"

struct sqlite3;
struct sqlite3_stmt;

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

/// Rows inserted into one table of `db`, 64 to a statement (SQLite updates an AUTOINCREMENT
/// table's sequence once a statement: one a row cost half the insert), `columns` in the order
/// the values are set.
class RowInserter {
public:
    RowInserter(GpkgSqlite &db, const std::string &table, const std::vector<std::string> &columns);
    ~RowInserter();
    RowInserter(const RowInserter &) = delete;
    RowInserter &operator=(const RowInserter &) = delete;

    /// Sets column i (0-based in `columns`) of the next row; a blob must live until flush().
    void bind(int i, std::int64_t v);
    void bind(int i, double v);
    void bind_blob(int i, const unsigned char *data, std::size_t bytes);
    /// Queues the row set (every column must be), inserting a full statement's rows.
    void insert();
    /// Inserts the rows queued.
    void flush();
    /// The rows queued or inserted.
    std::int64_t rows() const { return rows_; }

protected:
    GpkgSqlite &db_;
    std::string table_;

private:
    static constexpr std::size_t rows_per_statement = 64;
    struct Value {
        enum { integer, real, blob } kind = integer;
        std::int64_t i = 0;
        double d = 0;
        const unsigned char *data = nullptr;
        std::size_t bytes = 0;
    };
    void bind_row(sqlite3_stmt *s, std::size_t row, int first);
    void step(sqlite3_stmt *s);

    std::size_t columns_;
    sqlite3_stmt *full_ = nullptr; ///< rows_per_statement rows
    sqlite3_stmt *one_ = nullptr;  ///< one row, for the last of a flush
    std::vector<Value> queued_;    ///< the rows queued, then the row being set
    std::size_t queued_rows_ = 0;
    std::int64_t rows_ = 0;
};

/// The bulk rows of one feature table that GDAL created empty (a row's fid among `columns`).
/// GDAL's feature-count trigger is dropped while the rows go in and put back by finish(), which
/// writes the table's row count to gpkg_ogr_contents and its features' extent to gpkg_contents,
/// as GDAL does at close.
class BulkRows : public RowInserter {
public:
    BulkRows(GpkgSqlite &db, const std::string &table, const std::vector<std::string> &columns);
    /// Widens the layer's extent by a feature's envelope.
    void extend(double min_x, double max_x, double min_y, double max_y);
    /// Flushes, then the count, the extent (none: left as GDAL wrote it) and the trigger.
    void finish();

private:
    std::vector<std::string> triggers_; ///< the SQL of the triggers dropped
    std::array<double, 4> extent_;      ///< min x, max x, min y, max y
};

/// Adds the spatial index of each layer (written by GDAL with SPATIAL_INDEX=NO) to the file.
/// Reports to `progress` under the stage "write_gpkg" (and stops with Cancelled when asked).
void add_rtree_indexes(GpkgSqlite &db, const std::vector<RtreeLayer> &layers,
                       const Progress &progress = {});

} // namespace globemesh::io
