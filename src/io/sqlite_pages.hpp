// Internal to io/: rowid tables of a closed SQLite file filled by writing their B-tree pages,
// for the GeoPackage writer's millions of rows (gpkg_write.cpp, gpkg_rtree.cpp).
//
// SQLite inserts a row in about 1 us on one core, whatever the batching (RESULTS-writers.md),
// and has no bulk load of rows already in key order. So this writes what its B-tree would
// hold, in the documented file format (https://www.sqlite.org/fileformat2.html): records (2.1),
// table leaf pages (0x0D) filled in rowid order, interior pages (0x05) built bottom-up, overflow
// chains for long payloads, the lock-byte page left unused, and the header's page count and
// change counter. The tables are created by SQLite (empty, so each is one leaf at its root
// page); their pages are appended to the file and the top page of each tree is written at its
// root. The file is a temporary one with no connection open on it; a failure leaves it for
// deletion.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <sys/types.h>

namespace globemesh::io {

/// v's low `bytes` bytes at p, big-endian (SQLite's order for its integers, page headers and
/// the RTree's nodes).
void put_big_endian(unsigned char *p, std::uint64_t v, int bytes);

/// The serial type SQLite stores the integer v as (1-6, or 8 and 9 for 0 and 1), and the bytes
/// of its value for such a type.
unsigned sqlite_integer_type(std::int64_t v);
std::size_t sqlite_integer_bytes(unsigned type);

/// The record of two columns, NULL (a rowid's alias) and the integer v, in `out`, as SqliteRecord
/// makes it, without its buffers (an RTree's _rowid and _parent rows: millions); returns its
/// size.
std::size_t null_and_integer_record(std::int64_t v, unsigned char (&out)[11]);

/// One row in SQLite's record format, appended to `out`: the header (its size and a serial type
/// per column), then the values. Columns are added in the table's order; a rowid table's
/// INTEGER PRIMARY KEY column is stored as NULL (its value is the rowid).
class SqliteRecord {
public:
    void null() { types_.push_back(0); }
    void integer(std::int64_t v);
    void real(double v);
    void blob(const unsigned char *data, std::size_t bytes);
    /// Appends the record to `out` and clears this one for the next row.
    void append_to(std::vector<unsigned char> &out);

private:
    std::vector<std::uint64_t> types_;
    std::vector<unsigned char> body_;
};

/// The closed SQLite file `file` opened for appending pages. `label` starts every error's
/// message ("GeoPackage output o.gpkg"), `output` is the path the user gave (for the full-disk
/// note).
class SqlitePages {
public:
    SqlitePages(const std::filesystem::path &file, std::string label, std::filesystem::path output);
    ~SqlitePages();
    SqlitePages(const SqlitePages &) = delete;
    SqlitePages &operator=(const SqlitePages &) = delete;

    /// Bytes of a page that hold content (the page size less the reserved bytes).
    std::uint32_t usable() const { return usable_; }
    std::uint32_t page_size() const { return page_size_; }
    /// Appends a page (page_size bytes) to the file; returns its number.
    std::uint32_t append(const unsigned char *page);
    /// Writes page `number` (one already in the file) in place.
    void write(std::uint32_t number, const unsigned char *page);
    /// Writes the pages still buffered and the header's page count and change counter.
    void finish();

private:
    [[noreturn]] void fail(const std::string &step, int error) const;
    /// Writes `bytes` bytes at `offset` of the file; fails naming `step`.
    void write_at(const unsigned char *data, std::size_t bytes, off_t offset,
                  const std::string &step);
    void flush();

    int fd_ = -1;
    std::string label_;
    std::filesystem::path output_;
    std::uint32_t page_size_ = 0, usable_ = 0;
    std::uint32_t pages_ = 0;     ///< pages in the file, those buffered included
    std::uint32_t lock_page_ = 0; ///< the page holding SQLite's pending byte: never used
    std::vector<unsigned char> buffer_;
    std::uint32_t buffer_first_ = 0; ///< the number of the first page in buffer_
};

/// The rows of one empty rowid table, added in ascending rowid order; finish() writes its tree.
class TableLoader {
public:
    /// The table whose root page is `root` (sqlite_master's rootpage).
    TableLoader(SqlitePages &file, std::uint32_t root);
    /// Adds a row: its rowid (above the last one's) and its record (SqliteRecord).
    void add(std::int64_t rowid, const unsigned char *record, std::size_t bytes);
    /// Writes the last leaf, the interior pages and the root.
    void finish();

private:
    struct Child {
        std::uint32_t page;
        std::int64_t max_rowid;
    };
    void close_leaf();
    /// Stores page_ as a page of the tree: appended, or held while it may be the root.
    void store(std::int64_t max_rowid);
    std::uint32_t overflow(const unsigned char *rest, std::size_t bytes);

    SqlitePages &file_;
    std::uint32_t root_;
    std::vector<unsigned char> page_;
    std::size_t cells_ = 0, content_ = 0; ///< cells in page_, bytes of their content
    std::int64_t last_rowid_ = 0;
    bool held_ = false; ///< the first page is held in first_ until a second one comes
    std::vector<unsigned char> first_;
    std::int64_t first_max_ = 0;
    std::vector<Child> leaves_;
};

} // namespace globemesh::io
