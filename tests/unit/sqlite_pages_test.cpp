// Rows written as SQLite pages (sqlite_pages.hpp), judged by SQLite itself: its integrity check
// (every page used once, the lock-byte page by none, keys in order, cell and overflow
// accounting), and every value read back equal to the same row inserted through SQL.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <sqlite3.h>

#include "globemesh/error.hpp"
#include "sqlite_pages.hpp"
#include "support.hpp"

using namespace globemesh;
using namespace globemesh::test;
namespace fs = std::filesystem;

namespace {

class Db {
public:
    explicit Db(const fs::path &p) { EXPECT_EQ(sqlite3_open(p.c_str(), &db_), SQLITE_OK); }
    ~Db() { sqlite3_close(db_); }
    void exec(const std::string &sql) {
        EXPECT_EQ(sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK)
            << sql << ": " << sqlite3_errmsg(db_);
    }
    std::string one(const std::string &sql) {
        sqlite3_stmt *s = nullptr;
        std::string out;
        EXPECT_EQ(sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr), SQLITE_OK)
            << sql << ": " << sqlite3_errmsg(db_);
        if (s && sqlite3_step(s) == SQLITE_ROW && sqlite3_column_text(s, 0))
            out = reinterpret_cast<const char *>(sqlite3_column_text(s, 0));
        sqlite3_finalize(s);
        return out;
    }
    sqlite3 *get() { return db_; }

private:
    sqlite3 *db_ = nullptr;
};

/// A row of the test tables: t(id INTEGER PRIMARY KEY, i INTEGER, r REAL, b BLOB).
struct Row {
    std::int64_t id, i;
    double r;
    std::vector<unsigned char> b;
};

/// Integers at the edges of each of SQLite's sizes (1, 2, 3, 4, 6 and 8 bytes, 0 and 1 kept in
/// the type), on both signs.
const std::int64_t integer_edges[] = {0,
                                      1,
                                      -1,
                                      2,
                                      127,
                                      128,
                                      -128,
                                      -129,
                                      32767,
                                      32768,
                                      -32768,
                                      -32769,
                                      8388607,
                                      8388608,
                                      2147483647,
                                      -2147483649LL,
                                      140737488355327LL,
                                      140737488355328LL,
                                      std::numeric_limits<std::int64_t>::max(),
                                      std::numeric_limits<std::int64_t>::min()};

/// Rows with every integer size and sign, reals whole (stored as integers) and not, -0, NaN
/// (NULL), blobs from empty to several overflow pages, and gaps in the rowids.
std::vector<Row> test_rows(std::size_t n) {
    const auto &ints = integer_edges;
    const double reals[] = {
        0.1,         -0.0, 3.0, -7.0, 1e300, 1125899906842624.0, -2.5, 1e-300, 140737488355327.0,
        std::nan("")};
    std::mt19937_64 random(7);
    std::vector<Row> rows;
    std::int64_t id = 0;
    for (std::size_t k = 0; k < n; ++k) {
        id += 1 + std::int64_t(random() % 3);
        Row row{id, ints[k % std::size(ints)], reals[k % std::size(reals)], {}};
        // Mostly short; every 97th long enough for a chain of overflow pages.
        row.b.resize(k % 97 == 0 ? 2000 + k % 1500 : random() % 60);
        for (auto &c : row.b)
            c = static_cast<unsigned char>(random());
        rows.push_back(std::move(row));
    }
    rows.back().id = std::int64_t(1) << 40; // a rowid of six bytes
    return rows;
}

/// Creates `file` with page size `page` and two empty tables: pages (to be written as pages) and
/// sql (to be filled through SQL, the oracle); returns pages' root.
std::uint32_t create(const fs::path &file, int page) {
    Db db(file);
    db.exec("PRAGMA page_size = " + std::to_string(page));
    db.exec("CREATE TABLE pages (id INTEGER PRIMARY KEY, i INTEGER, r REAL, b BLOB)");
    db.exec("CREATE TABLE sql (id INTEGER PRIMARY KEY, i INTEGER, r REAL, b BLOB)");
    return std::uint32_t(std::stoul(db.one("SELECT rootpage FROM sqlite_master WHERE name = "
                                           "'pages'")));
}

/// The rows inserted into table sql through SQL (after the pages: theirs come first in the file).
void insert_sql(const fs::path &file, const std::vector<Row> &rows) {
    Db db(file);
    db.exec("BEGIN");
    sqlite3_stmt *s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db.get(), "INSERT INTO sql VALUES (?, ?, ?, ?)", -1, &s, nullptr),
              SQLITE_OK);
    for (const Row &r : rows) {
        sqlite3_bind_int64(s, 1, r.id);
        sqlite3_bind_int64(s, 2, r.i);
        sqlite3_bind_double(s, 3, r.r);
        if (r.b.empty()) // an empty vector's data() may be null, which would bind NULL
            sqlite3_bind_zeroblob(s, 4, 0);
        else
            sqlite3_bind_blob(s, 4, r.b.data(), int(r.b.size()), SQLITE_STATIC);
        EXPECT_EQ(sqlite3_step(s), SQLITE_DONE);
        sqlite3_reset(s);
    }
    sqlite3_finalize(s);
    db.exec("COMMIT");
}

void write_pages(const fs::path &file, std::uint32_t root, const std::vector<Row> &rows) {
    io::SqlitePages pages(file, "test", file);
    io::TableLoader table(pages, root);
    io::SqliteRecord record;
    std::vector<unsigned char> bytes;
    for (const Row &r : rows) {
        bytes.clear();
        record.null();
        record.integer(r.i);
        record.real(r.r);
        record.blob(r.b.data(), r.b.size());
        record.append_to(bytes);
        table.add(r.id, bytes.data(), bytes.size());
    }
    table.finish();
    pages.finish();
    insert_sql(file, rows);
}

/// Rows where the two tables differ in value or type (none when the pages hold what SQL would).
std::string differences(Db &db) {
    return db.one("SELECT count(*) FROM pages p FULL JOIN sql s ON p.id = s.id WHERE p.id IS NULL "
                  "OR s.id IS NULL OR p.i IS NOT s.i OR typeof(p.i) != typeof(s.i) OR p.r IS NOT "
                  "s.r OR typeof(p.r) != typeof(s.r) OR p.b IS NOT s.b OR typeof(p.b) != "
                  "typeof(s.b)");
}

} // namespace

// 512-byte pages and 30,000 rows: a tree four levels deep, long blobs in overflow chains.
TEST(SqlitePages, rows_read_back_as_sql_wrote_them_through_a_deep_tree_and_overflow_chains) {
    TempDir dir;
    const fs::path file = dir / "t.sqlite";
    const auto rows = test_rows(30000);
    write_pages(file, create(file, 512), rows);
    Db db(file);
    EXPECT_EQ(db.one("PRAGMA integrity_check"), "ok");
    EXPECT_EQ(db.one("SELECT count(*) FROM pages"), std::to_string(rows.size()));
    EXPECT_EQ(differences(db), "0");
    // The tree is deep: its root is an interior page whose children are interior pages too.
    EXPECT_GE(std::stoi(db.one("SELECT max(depth) FROM (SELECT length(path) - "
                               "length(replace(path, '/', '')) AS depth FROM dbstat WHERE name "
                               "= 'pages')")),
              3)
        << "(dbstat missing?)";
    EXPECT_GT(std::stoi(db.one("SELECT count(*) FROM dbstat WHERE name = 'pages' AND pagetype = "
                               "'overflow'")),
              100);
    // Still an ordinary table: SQL adds, finds and deletes rows in it.
    db.exec("INSERT INTO pages (i, r, b) VALUES (5, 2.5, x'00')");
    db.exec("DELETE FROM pages WHERE id % 7 = 0");
    EXPECT_EQ(db.one("SELECT r FROM pages WHERE id = (SELECT max(id) FROM pages)"), "2.5");
    EXPECT_EQ(db.one("PRAGMA integrity_check"), "ok");
}

// Every table size over a range: somewhere a level's last page would be left one child (an
// interior page with no cell, which SQLite takes for corruption) unless the writer gives it two.
TEST(SqlitePages, every_table_size_makes_a_valid_tree) {
    TempDir dir;
    for (std::size_t n = 2600; n < 2800; n += 2) {
        const fs::path file = dir / ("t" + std::to_string(n) + ".sqlite");
        std::vector<Row> rows(n);
        for (std::size_t k = 0; k < n; ++k)
            rows[k] = {std::int64_t(k) + 1, std::int64_t(k), 0.5, {1, 2, 3}};
        write_pages(file, create(file, 512), rows);
        Db db(file);
        ASSERT_EQ(db.one("PRAGMA integrity_check"), "ok") << n;
        ASSERT_EQ(differences(db), "0") << n;
        ASSERT_EQ(db.one("SELECT sum(i) FROM pages WHERE id > 100"),
                  std::to_string(n * (n - 1) / 2 - 4950))
            << n;
    }
}

// The RTree's two-column rows are made without SqliteRecord's buffers: the same bytes.
TEST(SqlitePages, null_and_integer_record_is_the_records_bytes) {
    std::mt19937_64 random(3);
    std::vector<std::int64_t> values(std::begin(integer_edges), std::end(integer_edges));
    for (int k = 0; k < 1000; ++k)
        values.push_back(std::int64_t(random()) >> (random() % 64));
    io::SqliteRecord record;
    for (const std::int64_t v : values) {
        std::vector<unsigned char> expected;
        record.null();
        record.integer(v);
        record.append_to(expected);
        unsigned char bytes[11];
        const std::size_t n = io::null_and_integer_record(v, bytes);
        EXPECT_EQ(std::vector<unsigned char>(bytes, bytes + n), expected) << v;
    }
}

// A table of one row (its leaf is the root) and an empty one (the root stays an empty leaf).
TEST(SqlitePages, one_row_and_no_row_leave_the_root_a_leaf) {
    for (std::size_t n : {std::size_t(1), std::size_t(0)}) {
        SCOPED_TRACE(n);
        TempDir dir;
        const fs::path file = dir / "t.sqlite";
        auto rows = test_rows(1);
        rows.resize(n);
        write_pages(file, create(file, 4096), rows);
        Db db(file);
        EXPECT_EQ(db.one("PRAGMA integrity_check"), "ok");
        EXPECT_EQ(differences(db), "0");
        EXPECT_EQ(db.one("SELECT count(*) FROM pages"), std::to_string(n));
    }
}

// SQLite never uses the page holding its pending byte (at 1 GiB; moved here to 64 KiB, as
// SQLite's own tests do, to cross it with a small file): integrity_check counts that page as
// used, so a tree page there would be reported twice.
TEST(SqlitePages, the_lock_byte_page_is_skipped) {
    const int before = sqlite3_test_control(SQLITE_TESTCTRL_PENDING_BYTE, 0x10000u);
    if (before <= 0)
        GTEST_SKIP() << "this SQLite has no test controls";
    {
        TempDir dir;
        const fs::path file = dir / "t.sqlite";
        const auto rows = test_rows(3000);
        write_pages(file, create(file, 512), rows);
        EXPECT_GT(fs::file_size(file), 4 * 0x10000u);
        Db db(file);
        EXPECT_EQ(db.one("PRAGMA integrity_check"), "ok");
        EXPECT_EQ(differences(db), "0");
    }
    sqlite3_test_control(SQLITE_TESTCTRL_PENDING_BYTE, unsigned(before));
}

// A file that is not a plain rollback-journal SQLite database is refused, not written into,
// with what to look at (GDAL makes such a file only when its settings ask for it).
TEST(SqlitePages, a_file_in_wal_mode_with_auto_vacuum_or_not_sqlite_is_refused) {
    TempDir dir;
    {
        Db db(dir / "wal.sqlite");
        db.exec("PRAGMA journal_mode = WAL");
        db.exec("CREATE TABLE t (a)");
    }
    {
        Db db(dir / "vacuum.sqlite");
        db.exec("PRAGMA auto_vacuum = FULL");
        db.exec("CREATE TABLE t (a)");
    }
    std::ofstream(dir / "text.sqlite") << std::string(4096, 'x');
    for (const auto &[name, why] :
         {std::pair{"wal.sqlite", "the SQLite file is in WAL mode (is OGR_SQLITE_JOURNAL set?)"},
          std::pair{"vacuum.sqlite", "the SQLite file has auto-vacuum (is OGR_SQLITE_PRAGMA set?)"},
          std::pair{"text.sqlite", "not a SQLite file"}}) {
        const std::string m = thrown_message<IoError>(
            [&] { io::SqlitePages pages(dir / name, "output o.gpkg", dir / name); });
        EXPECT_EQ(m.find(std::string("output o.gpkg: ") + why), 0u) << m;
    }
}
