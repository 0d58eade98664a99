// The GeoPackage writer's bulk steps in SQLite: see gpkg_rtree.hpp.
#include "gpkg_rtree.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <deque>
#include <limits>
#include <numeric>
#include <utility>

#include <sqlite3.h>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"

namespace globemesh::io {

RtreeBox rtree_box(double min_x, double max_x, double min_y, double max_y) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    auto down = [](double d) {
        const float f = static_cast<float>(d);
        return static_cast<double>(f) > d ? std::nextafter(f, -inf) : f;
    };
    auto up = [](double d) {
        const float f = static_cast<float>(d);
        return static_cast<double>(f) < d ? std::nextafter(f, inf) : f;
    };
    return {down(min_x), up(max_x), down(min_y), up(max_y)};
}

namespace {

/// Sort-Tile-Recursive packing (Leutenegger, Lopez & Edgington 1997) of the boxes into nodes of
/// at most `capacity`: sorted by the x of their centres into vertical slices of about
/// sqrt(nodes) nodes each, each slice sorted by y and cut into nodes. Returns the boxes' order
/// in `order` and where each node starts in it, with boxes.size() last. Ties go by index: the
/// same tree run after run.
std::vector<std::size_t> pack(const std::vector<RtreeBox> &boxes, std::size_t capacity,
                              std::vector<std::uint32_t> &order) {
    const std::size_t n = boxes.size();
    const std::size_t nodes = (n + capacity - 1) / capacity;
    const auto slices = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(nodes))));
    const std::size_t per_slice = ((nodes + slices - 1) / slices) * capacity;
    // Sorted as (centre, index) pairs: an index sort that reads the boxes misses the cache
    // (2.1M faces: 0.4 s).
    std::vector<std::pair<float, std::uint32_t>> keyed(n);
    auto sort_by = [&](std::size_t lo, std::size_t from, std::size_t to) {
        for (std::size_t i = from; i < to; ++i)
            keyed[i] = {boxes[order[i]][lo] + boxes[order[i]][lo + 1], order[i]};
        std::sort(keyed.begin() + std::ptrdiff_t(from), keyed.begin() + std::ptrdiff_t(to));
        for (std::size_t i = from; i < to; ++i)
            order[i] = keyed[i].second;
    };
    order.resize(n);
    std::iota(order.begin(), order.end(), 0u);
    sort_by(0, 0, n);
    std::vector<std::size_t> starts;
    for (std::size_t s = 0; s < n; s += per_slice) {
        const std::size_t end = std::min(n, s + per_slice);
        sort_by(2, s, end);
        for (std::size_t k = s; k < end; k += capacity)
            starts.push_back(k);
    }
    starts.push_back(n);
    return starts;
}

void put16(unsigned char *p, std::uint32_t v) {
    p[0] = static_cast<unsigned char>(v >> 8);
    p[1] = static_cast<unsigned char>(v);
}

void put64(unsigned char *p, std::uint64_t v) {
    for (int i = 7; i >= 0; --i, v >>= 8)
        p[i] = static_cast<unsigned char>(v);
}

void put_float(unsigned char *p, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, sizeof v);
    for (int i = 3; i >= 0; --i, v >>= 8)
        p[i] = static_cast<unsigned char>(v);
}

/// "name" as an SQL identifier.
std::string quoted(const std::string &name) {
    std::string q = "\"";
    for (char c : name)
        q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}

/// 'text' as an SQL string literal.
std::string literal(const std::string &text) {
    std::string q = "'";
    for (char c : text)
        q += c == '\'' ? std::string("''") : std::string(1, c);
    return q + "'";
}

class Statement {
public:
    /// `what` names the step in the error of a failed insert.
    Statement(GpkgSqlite &db, const std::string &sql,
              std::string what = "spatial index: writing the tree")
        : db_(db), what_(std::move(what)) {
        if (sqlite3_prepare_v2(db.get(), sql.c_str(), -1, &s_, nullptr) != SQLITE_OK)
            db.fail("preparing " + sql);
    }
    ~Statement() { sqlite3_finalize(s_); }
    Statement(const Statement &) = delete;
    Statement &operator=(const Statement &) = delete;
    /// Binds two integers, steps and resets: an INSERT of one row.
    void insert(std::int64_t a, std::int64_t b) {
        sqlite3_bind_int64(s_, 1, a);
        sqlite3_bind_int64(s_, 2, b);
        step();
    }
    void insert(std::int64_t a, const std::vector<unsigned char> &blob) {
        sqlite3_bind_int64(s_, 1, a);
        sqlite3_bind_blob(s_, 2, blob.data(), static_cast<int>(blob.size()), SQLITE_STATIC);
        step();
    }
    void insert(std::int64_t a) {
        sqlite3_bind_int64(s_, 1, a);
        step();
    }
    /// The first column of the next row of a query as text, or "" past the last row.
    std::string text() {
        if (sqlite3_step(s_) != SQLITE_ROW)
            return "";
        const auto *t = sqlite3_column_text(s_, 0);
        return t ? reinterpret_cast<const char *>(t) : "";
    }
    /// The first column of the one row of a query, or -1 when it has none.
    std::int64_t single() {
        const std::int64_t v = sqlite3_step(s_) == SQLITE_ROW ? sqlite3_column_int64(s_, 0) : -1;
        sqlite3_reset(s_);
        return v;
    }

private:
    void step() {
        if (sqlite3_step(s_) != SQLITE_DONE)
            db_.fail(what_);
        sqlite3_reset(s_);
    }
    GpkgSqlite &db_;
    std::string what_;
    sqlite3_stmt *s_ = nullptr;
};

/// The triggers GDAL creates with an index (GeoPackage 1.2's gpkg_rtree_index, as GDAL 3.6
/// words them): they keep the index when features are added, moved or deleted later.
std::vector<std::string> triggers(const std::string &table, const std::string &column) {
    const std::string t = quoted(table), c = quoted(column),
                      rtree = "rtree_" + table + "_" + column;
    const std::string r = quoted(rtree);
    const std::string values = " VALUES (NEW.\"fid\",ST_MinX(NEW." + c + "), ST_MaxX(NEW." + c +
                               "),ST_MinY(NEW." + c + "), ST_MaxY(NEW." + c + ")); END";
    return {
        "CREATE TRIGGER " + quoted(rtree + "_insert") + " AFTER INSERT ON " + t + " WHEN (new." +
            c + " NOT NULL AND NOT ST_IsEmpty(NEW." + c + ")) BEGIN INSERT OR REPLACE INTO " + r +
            values,
        "CREATE TRIGGER " + quoted(rtree + "_update1") + " AFTER UPDATE OF " + c + " ON " + t +
            " WHEN OLD.\"fid\" = NEW.\"fid\" AND (NEW." + c + " NOTNULL AND NOT ST_IsEmpty(NEW." +
            c + ")) BEGIN INSERT OR REPLACE INTO " + r + values,
        "CREATE TRIGGER " + quoted(rtree + "_update2") + " AFTER UPDATE OF " + c + " ON " + t +
            " WHEN OLD.\"fid\" = NEW.\"fid\" AND (NEW." + c + " ISNULL OR ST_IsEmpty(NEW." + c +
            ")) BEGIN DELETE FROM " + r + " WHERE id = OLD.\"fid\"; END",
        "CREATE TRIGGER " + quoted(rtree + "_update3") + " AFTER UPDATE ON " + t +
            " WHEN OLD.\"fid\" != NEW.\"fid\" AND (NEW." + c + " NOTNULL AND NOT ST_IsEmpty(NEW." +
            c + ")) BEGIN DELETE FROM " + r + " WHERE id = OLD.\"fid\"; INSERT OR REPLACE INTO " +
            r + values,
        "CREATE TRIGGER " + quoted(rtree + "_update4") + " AFTER UPDATE ON " + t +
            " WHEN OLD.\"fid\" != NEW.\"fid\" AND (NEW." + c + " ISNULL OR ST_IsEmpty(NEW." + c +
            ")) BEGIN DELETE FROM " + r + " WHERE id IN (OLD.\"fid\", NEW.\"fid\"); END",
        "CREATE TRIGGER " + quoted(rtree + "_delete") + " AFTER DELETE ON " + t + " WHEN old." + c +
            " NOT NULL BEGIN DELETE FROM " + r + " WHERE id = OLD.\"fid\"; END",
    };
}

/// Progress over every layer's features, each counted twice (its leaf cell, its _rowid row).
struct Steps {
    const Progress &progress;
    double total = 0;
    double done = 0;
    /// Adds n steps; reports every 65,536 of them, or every 1/32 of a smaller total.
    void add(double n) {
        const double every = std::max(1.0, std::min(65536.0, total / 32));
        const bool due = std::floor(done / every) != std::floor((done + n) / every);
        done += n;
        if (due)
            report(progress, std::min(1.0, done / total), "write_gpkg");
    }
};

/// One layer's index: the virtual table (SQLite creates its shadow tables and an empty root),
/// then the packed tree written into them, then the triggers and the extension's row.
void add_index(GpkgSqlite &db, const RtreeLayer &layer, Steps &steps) {
    const std::string rtree = "rtree_" + layer.table + "_" + layer.column;
    db.exec("CREATE VIRTUAL TABLE " + quoted(rtree) + " USING rtree(id, minx, maxx, miny, maxy)");
    // The node size SQLite chose for this file's page size (its root is a node of that size).
    Statement size(db, "SELECT length(data) FROM " + quoted(rtree + "_node") + " WHERE nodeno = 1");
    const std::int64_t node_bytes = size.single();
    constexpr std::size_t cell_bytes = 8 + 4 * 4;
    if (node_bytes < std::int64_t(4 + 2 * cell_bytes))
        db.fail("spatial index: unexpected root node of " + rtree);
    const std::size_t capacity = (std::size_t(node_bytes) - 4) / cell_bytes;

    if (!layer.boxes.empty()) {
        // Level k holds the nodes at height k (0: the leaves): node j has the cells order[i]
        // for i in [starts[j], starts[j + 1]), each the index of a box in `boxes` (a feature's
        // at the leaves, fid = index + 1; a node's of the level below above them). The top
        // level has one node, the root.
        struct Level {
            const std::vector<RtreeBox> *boxes;
            std::vector<std::uint32_t> order;
            std::vector<std::size_t> starts;
        };
        std::deque<std::vector<RtreeBox>> node_boxes; // the boxes of the levels above the leaves
        std::vector<Level> levels;
        levels.push_back({&layer.boxes, {}, {}});
        for (;;) {
            Level &l = levels.back();
            l.starts = pack(*l.boxes, capacity, l.order);
            if (l.starts.size() == 2)
                break;
            std::vector<RtreeBox> &up = node_boxes.emplace_back();
            up.reserve(l.starts.size() - 1);
            for (std::size_t j = 0; j + 1 < l.starts.size(); ++j) {
                RtreeBox b = (*l.boxes)[l.order[l.starts[j]]];
                for (std::size_t i = l.starts[j] + 1; i < l.starts[j + 1]; ++i) {
                    const RtreeBox &c = (*l.boxes)[l.order[i]];
                    b = {std::min(b[0], c[0]), std::max(b[1], c[1]), std::min(b[2], c[2]),
                         std::max(b[3], c[3])};
                }
                up.push_back(b);
            }
            levels.push_back({&up, {}, {}});
        }
        // Node numbers: the root 1 (where SQLite looks for it), then level by level downwards.
        const std::size_t height = levels.size() - 1;
        std::vector<std::int64_t> first(levels.size());
        first[height] = 1;
        for (std::size_t k = height; k-- > 0;)
            first[k] = first[k + 1] + std::int64_t(levels[k + 1].starts.size() - 1);

        Statement node(db, "INSERT OR REPLACE INTO " + quoted(rtree + "_node") +
                               "(nodeno, data) VALUES (?, ?)");
        RowInserter rowid(db, rtree + "_rowid", {"rowid", "nodeno"});
        Statement parent(db, "INSERT INTO " + quoted(rtree + "_parent") +
                                 "(nodeno, parentnode) VALUES (?, ?)");
        std::vector<unsigned char> blob(static_cast<std::size_t>(node_bytes));
        // Each feature's leaf, written in fid order once the nodes are: SQLite appends rows
        // whose keys ascend (the index at 20 km 3.7 -> 2.6 s).
        std::vector<std::int64_t> leaf_of(layer.boxes.size());
        for (std::size_t k = levels.size(); k-- > 0;) {
            const Level &l = levels[k];
            for (std::size_t j = 0; j + 1 < l.starts.size(); ++j) {
                const std::int64_t number = first[k] + std::int64_t(j);
                std::fill(blob.begin(), blob.end(), 0);
                put16(&blob[0], k == height ? std::uint32_t(height) : 0);
                put16(&blob[2], std::uint32_t(l.starts[j + 1] - l.starts[j]));
                unsigned char *p = &blob[4];
                for (std::size_t i = l.starts[j]; i < l.starts[j + 1]; ++i, p += cell_bytes) {
                    const std::uint32_t c = l.order[i];
                    const std::int64_t id =
                        k == 0 ? std::int64_t(c) + 1 : first[k - 1] + std::int64_t(c);
                    put64(p, std::uint64_t(id));
                    for (std::size_t d = 0; d < 4; ++d)
                        put_float(p + 8 + 4 * d, (*l.boxes)[c][d]);
                    if (k == 0)
                        leaf_of[c] = number;
                    else
                        parent.insert(id, number);
                }
                node.insert(number, blob);
                if (k == 0)
                    steps.add(double(l.starts[j + 1] - l.starts[j]));
            }
        }
        for (std::size_t i = 0; i < leaf_of.size(); ++i) {
            rowid.bind(0, std::int64_t(i) + 1);
            rowid.bind(1, leaf_of[i]);
            rowid.insert();
            steps.add(1);
        }
        rowid.flush();
    }
    for (const std::string &sql : triggers(layer.table, layer.column))
        db.exec(sql);
    db.exec("INSERT INTO gpkg_extensions (table_name, column_name, extension_name, definition, "
            "scope) VALUES (" +
            literal(layer.table) + ", " + literal(layer.column) +
            ", 'gpkg_rtree_index', 'http://www.geopackage.org/spec120/#extension_rtree', "
            "'write-only')");
}

} // namespace

GpkgSqlite::GpkgSqlite(const std::filesystem::path &file, const std::filesystem::path &output)
    : output_(output) {
    if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
        const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_); // the destructor does not run for a constructor that throws
        db_ = nullptr;
        fail("opening it with SQLite", why);
    }
    try {
        // No rollback journal and no syncs: a failed write's temporary file is deleted, not
        // rolled back (journal_mode is not stored in the file: the next reader has its own).
        exec("PRAGMA journal_mode = OFF");
        exec("PRAGMA synchronous = OFF");
        exec("BEGIN");
        in_transaction_ = true;
    } catch (...) {
        sqlite3_close(db_);
        throw;
    }
}

GpkgSqlite::~GpkgSqlite() {
    if (in_transaction_)
        sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    sqlite3_close(db_);
}

void GpkgSqlite::fail(const std::string &step, std::string why) const {
    if (why.empty())
        why = sqlite3_errmsg(db_);
    throw IoError("GeoPackage output " + output_.string() + ": " + step + ": " + why +
                  OutputFile::full_disk_note(output_));
}

void GpkgSqlite::exec(const std::string &sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK)
        fail(sql.substr(0, sql.find('(')));
}

void GpkgSqlite::commit() {
    exec("COMMIT");
    in_transaction_ = false;
}

RowInserter::RowInserter(GpkgSqlite &db, const std::string &table,
                         const std::vector<std::string> &columns)
    : db_(db), table_(table), columns_(columns.size()), queued_(columns.size()) {
    std::string names, row;
    for (const std::string &c : columns) {
        names += (names.empty() ? "" : ", ") + quoted(c);
        row += row.empty() ? "(?" : ", ?";
    }
    row += ")";
    const std::string insert = "INSERT INTO " + quoted(table) + " (" + names + ") VALUES ";
    std::string rows = row;
    for (std::size_t r = 1; r < rows_per_statement; ++r)
        rows += ", " + row;
    if (sqlite3_prepare_v2(db.get(), (insert + rows).c_str(), -1, &full_, nullptr) != SQLITE_OK ||
        sqlite3_prepare_v2(db.get(), (insert + row).c_str(), -1, &one_, nullptr) != SQLITE_OK) {
        const std::string why = sqlite3_errmsg(db.get());
        sqlite3_finalize(full_); // the destructor does not run for a constructor that throws
        db.fail("preparing the rows of " + table, why);
    }
}

BulkRows::BulkRows(GpkgSqlite &db, const std::string &table,
                   const std::vector<std::string> &columns)
    : RowInserter(db, table, columns) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    extent_ = {inf, -inf, inf, -inf};
    // GDAL's trigger that counts each row inserted into gpkg_ogr_contents (finish() writes the
    // count once, and puts the trigger back as it was).
    {
        Statement find(db, "SELECT sql FROM sqlite_master WHERE type = 'trigger' AND name = " +
                               literal("trigger_insert_feature_count_" + table));
        for (std::string sql; !(sql = find.text()).empty();)
            triggers_.push_back(sql);
    }
    if (!triggers_.empty())
        db.exec("DROP TRIGGER " + quoted("trigger_insert_feature_count_" + table));
}

RowInserter::~RowInserter() {
    sqlite3_finalize(full_);
    sqlite3_finalize(one_);
}

void RowInserter::bind(int i, std::int64_t v) {
    Value &x = queued_[queued_rows_ * columns_ + std::size_t(i)];
    x.kind = Value::integer, x.i = v;
}

void RowInserter::bind(int i, double v) {
    Value &x = queued_[queued_rows_ * columns_ + std::size_t(i)];
    x.kind = Value::real, x.d = v;
}

void RowInserter::bind_blob(int i, const unsigned char *data, std::size_t bytes) {
    Value &x = queued_[queued_rows_ * columns_ + std::size_t(i)];
    x.kind = Value::blob, x.data = data, x.bytes = bytes;
}

void RowInserter::insert() {
    ++queued_rows_;
    ++rows_;
    if (queued_rows_ < rows_per_statement) {
        queued_.resize((queued_rows_ + 1) * columns_);
        return;
    }
    for (std::size_t r = 0; r < queued_rows_; ++r)
        bind_row(full_, r, int(r * columns_) + 1);
    step(full_);
    queued_rows_ = 0;
}

void RowInserter::flush() {
    for (std::size_t r = 0; r < queued_rows_; ++r) {
        bind_row(one_, r, 1);
        step(one_);
    }
    queued_rows_ = 0;
}

/// Binds queued row `row` to the parameters of `s` from number `first` on.
void RowInserter::bind_row(sqlite3_stmt *s, std::size_t row, int first) {
    for (std::size_t c = 0; c < columns_; ++c) {
        const Value &x = queued_[row * columns_ + c];
        const int p = first + int(c);
        if (x.kind == Value::integer)
            sqlite3_bind_int64(s, p, x.i);
        else if (x.kind == Value::real)
            sqlite3_bind_double(s, p, x.d);
        else
            sqlite3_bind_blob(s, p, x.data, static_cast<int>(x.bytes), SQLITE_STATIC);
    }
}

void RowInserter::step(sqlite3_stmt *s) {
    if (sqlite3_step(s) != SQLITE_DONE)
        db_.fail("writing the rows of " + table_);
    sqlite3_reset(s);
}

void BulkRows::extend(double min_x, double max_x, double min_y, double max_y) {
    extent_ = {std::min(extent_[0], min_x), std::max(extent_[1], max_x),
               std::min(extent_[2], min_y), std::max(extent_[3], max_y)};
}

void BulkRows::finish() {
    flush();
    const std::string what = "counting the rows of " + table_;
    Statement count(db_,
                    "UPDATE gpkg_ogr_contents SET feature_count = ? WHERE "
                    "table_name = " +
                        literal(table_),
                    what);
    count.insert(rows());
    if (extent_[0] <= extent_[1]) {
        // As GDAL 3.6 writes it: through SQLite's printf, which keeps 16 significant digits.
        char *sql = sqlite3_mprintf("UPDATE gpkg_contents SET min_x = %.18g, min_y = %.18g, "
                                    "max_x = %.18g, max_y = %.18g WHERE table_name = %Q",
                                    extent_[0], extent_[2], extent_[1], extent_[3], table_.c_str());
        if (!sql)
            db_.fail("the extent of " + table_, "out of memory");
        const std::string text = sql;
        sqlite3_free(sql);
        db_.exec(text);
    }
    for (const std::string &sql : triggers_)
        db_.exec(sql);
    triggers_.clear();
}

void add_rtree_indexes(GpkgSqlite &db, const std::vector<RtreeLayer> &layers,
                       const Progress &progress) {
    Steps steps{progress};
    for (const RtreeLayer &layer : layers)
        steps.total += 2.0 * double(layer.boxes.size());
    // The GeoPackage's table of extensions, in the words of the standard (GDAL creates it only
    // for a file that uses one).
    db.exec("CREATE TABLE IF NOT EXISTS gpkg_extensions (table_name TEXT,column_name "
            "TEXT,extension_name TEXT NOT NULL,"
            "definition TEXT NOT NULL,scope TEXT NOT NULL,CONSTRAINT ge_tce UNIQUE (table_name, "
            "column_name, extension_name))");
    for (const RtreeLayer &layer : layers)
        add_index(db, layer, steps);
}

} // namespace globemesh::io
