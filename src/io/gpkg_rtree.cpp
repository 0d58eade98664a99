// The GeoPackage writer's bulk steps in SQLite: see gpkg_rtree.hpp.
#include "gpkg_rtree.hpp"

#include <algorithm>
#include <array>
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
#include "ordered_blocks.hpp"
#include "sqlite_pages.hpp"

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

/// `words` sorted as std::sort sorts (key, index) pairs: by key, ties by index. Each pair is
/// one 64-bit word (keyed_word), the key's bits in an order that compares as the floats do (the
/// sign flipped, a negative's other bits inverted; -0 made +0 first), then the index, sorted by
/// least-significant-digit radix a byte at a time (a byte every word shares is skipped).
void sort_keyed(std::vector<std::uint64_t> &words, std::vector<std::uint64_t> &scratch) {
    const std::size_t n = words.size();
    std::vector<std::array<std::size_t, 256>> counts(8);
    for (auto &c : counts)
        c.fill(0);
    for (std::uint64_t w : words)
        for (std::size_t d = 0; d < 8; ++d)
            ++counts[d][(w >> (8 * d)) & 0xff];
    scratch.resize(n);
    for (std::size_t d = 0; d < 8; ++d) {
        auto &c = counts[d];
        if (std::find(c.begin(), c.end(), n) != c.end())
            continue; // every word has the same byte here
        std::size_t at = 0;
        for (auto &k : c)
            at += std::exchange(k, at);
        for (std::uint64_t w : words)
            scratch[c[(w >> (8 * d)) & 0xff]++] = w;
        words.swap(scratch);
    }
}

/// The word of (key, index) for sort_keyed.
std::uint64_t keyed_word(float key, std::uint32_t index) {
    key += 0.0f; // -0 -> +0: the two compare equal
    std::uint32_t bits;
    std::memcpy(&bits, &key, sizeof bits);
    bits = bits & 0x80000000u ? ~bits : bits | 0x80000000u;
    return std::uint64_t(bits) << 32 | index;
}

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
    // Sorted as (centre, index) words: an index sort that reads the boxes misses the cache.
    std::vector<std::uint64_t> words, scratch;
    auto sort_by = [&](std::size_t lo, std::size_t from, std::size_t to) {
        words.resize(to - from);
        for (std::size_t i = from; i < to; ++i)
            words[i - from] = keyed_word(boxes[order[i]][lo] + boxes[order[i]][lo + 1], order[i]);
        sort_keyed(words, scratch);
        for (std::size_t i = from; i < to; ++i)
            order[i] = std::uint32_t(words[i - from]);
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

/// A float's bits at p, big-endian (an RTree node's coordinates).
void put_float(unsigned char *p, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, sizeof v);
    put_big_endian(p, v, 4);
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
    /// Binds an integer, steps and resets: an INSERT or UPDATE of one row.
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

/// A layer's packed tree: level k holds the nodes at height k (0: the leaves); node j of a level
/// has the cells order[i] for i in [starts[j], starts[j + 1]), each the index of a box in `boxes`
/// (a feature's at the leaves, fid = index + 1; a node's of the level below above them). The
/// top level has one node, the root.
struct PackedTree {
    struct Level {
        const std::vector<RtreeBox> *boxes;
        std::vector<std::uint32_t> order;
        std::vector<std::size_t> starts;
    };
    std::deque<std::vector<RtreeBox>> node_boxes; // the boxes of the levels above the leaves
    std::vector<Level> levels;
};

/// `layer`'s boxes packed into `tree`, nodes of at most `capacity` cells (no level for no box:
/// the index keeps the empty root SQLite made).
void pack_tree(const RtreeLayer &layer, std::size_t capacity, PackedTree &tree) {
    auto &levels = tree.levels;
    if (layer.boxes.empty())
        return;
    levels.push_back({&layer.boxes, {}, {}});
    for (;;) {
        PackedTree::Level &l = levels.back();
        l.starts = pack(*l.boxes, capacity, l.order);
        if (l.starts.size() == 2)
            break;
        std::vector<RtreeBox> &up = tree.node_boxes.emplace_back();
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
}

/// Writes a layer's packed tree into its index's empty tables.
void write_tree(SqlitePages &file, const RtreeLayer &layer, const PackedTree &tree,
                const RtreeTables &tables, Steps &steps) {
    constexpr std::size_t cell_bytes = 8 + 4 * 4;
    const auto &levels = tree.levels;
    if (levels.empty())
        return;
    // Node numbers: the root 1 (where SQLite looks for it), then level by level downwards, so
    // the nodes' rows are written in ascending order as they are made.
    const std::size_t height = levels.size() - 1;
    std::vector<std::int64_t> first(levels.size());
    first[height] = 1;
    for (std::size_t k = height; k-- > 0;)
        first[k] = first[k + 1] + std::int64_t(levels[k + 1].starts.size() - 1);
    const auto nodes = std::size_t(first[0]) + levels[0].starts.size() - 1; // 1 + the last

    TableLoader node_rows(file, tables.node);
    std::vector<unsigned char> blob(tables.node_bytes), record;
    SqliteRecord row;
    unsigned char small[11];                       // a _parent or _rowid record
    std::vector<std::int64_t> parent_of(nodes, 0); // of each node below the root
    std::vector<std::int64_t> leaf_of(layer.boxes.size());
    for (std::size_t k = levels.size(); k-- > 0;) {
        const PackedTree::Level &l = levels[k];
        for (std::size_t j = 0; j + 1 < l.starts.size(); ++j) {
            const std::int64_t number = first[k] + std::int64_t(j);
            std::fill(blob.begin(), blob.end(), 0);
            put_big_endian(&blob[0], k == height ? height : 0, 2);
            put_big_endian(&blob[2], l.starts[j + 1] - l.starts[j], 2);
            unsigned char *p = &blob[4];
            for (std::size_t i = l.starts[j]; i < l.starts[j + 1]; ++i, p += cell_bytes) {
                const std::uint32_t c = l.order[i];
                const std::int64_t id =
                    k == 0 ? std::int64_t(c) + 1 : first[k - 1] + std::int64_t(c);
                put_big_endian(p, std::uint64_t(id), 8);
                for (std::size_t d = 0; d < 4; ++d)
                    put_float(p + 8 + 4 * d, (*l.boxes)[c][d]);
                if (k == 0)
                    leaf_of[c] = number;
                else
                    parent_of[std::size_t(id)] = number;
            }
            record.clear();
            row.null(), row.blob(blob.data(), blob.size()), row.append_to(record);
            node_rows.add(number, record.data(), record.size());
            if (k == 0)
                steps.add(double(l.starts[j + 1] - l.starts[j]));
        }
    }
    node_rows.finish();
    TableLoader parent_rows(file, tables.parent);
    for (std::size_t n = 2; n < nodes; ++n)
        parent_rows.add(std::int64_t(n), small, null_and_integer_record(parent_of[n], small));
    parent_rows.finish();
    TableLoader rowid_rows(file, tables.rowid);
    for (std::size_t i = 0; i < leaf_of.size(); ++i) {
        rowid_rows.add(std::int64_t(i) + 1, small, null_and_integer_record(leaf_of[i], small));
        steps.add(1);
    }
    rowid_rows.finish();
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

std::uint32_t table_root(GpkgSqlite &db, const std::string &table,
                         const std::vector<std::string> &columns) {
    Statement info(db, "SELECT name FROM pragma_table_info(" + literal(table) + ")");
    std::vector<std::string> found;
    for (std::string name; !(name = info.text()).empty();)
        found.push_back(name);
    if (found != columns)
        db.fail("the columns of " + table, "not those the writer defined");
    Statement root(db, "SELECT rootpage FROM sqlite_master WHERE type = 'table' AND name = " +
                           literal(table));
    const std::int64_t page = root.single();
    if (page < 2)
        db.fail("the root page of " + table, "not found");
    return std::uint32_t(page);
}

RtreeTables create_rtree_index(GpkgSqlite &db, const std::string &table,
                               const std::string &column) {
    // The GeoPackage's table of extensions, in the words of the standard (GDAL creates it only
    // for a file that uses one).
    db.exec("CREATE TABLE IF NOT EXISTS gpkg_extensions (table_name TEXT,column_name "
            "TEXT,extension_name TEXT NOT NULL,"
            "definition TEXT NOT NULL,scope TEXT NOT NULL,CONSTRAINT ge_tce UNIQUE (table_name, "
            "column_name, extension_name))");
    const std::string rtree = "rtree_" + table + "_" + column;
    db.exec("CREATE VIRTUAL TABLE " + quoted(rtree) + " USING rtree(id, minx, maxx, miny, maxy)");
    RtreeTables t;
    // The node size SQLite chose for this file's page size (its root is a node of that size).
    Statement size(db, "SELECT length(data) FROM " + quoted(rtree + "_node") + " WHERE nodeno = 1");
    const std::int64_t node_bytes = size.single();
    if (node_bytes < std::int64_t(4 + 2 * (8 + 4 * 4)))
        db.fail("spatial index: unexpected root node of " + rtree);
    t.node_bytes = std::size_t(node_bytes);
    t.node = table_root(db, rtree + "_node", {"nodeno", "data"});
    t.rowid = table_root(db, rtree + "_rowid", {"rowid", "nodeno"});
    t.parent = table_root(db, rtree + "_parent", {"nodeno", "parentnode"});
    for (const std::string &sql : triggers(table, column))
        db.exec(sql);
    db.exec("INSERT INTO gpkg_extensions (table_name, column_name, extension_name, definition, "
            "scope) VALUES (" +
            literal(table) + ", " + literal(column) +
            ", 'gpkg_rtree_index', 'http://www.geopackage.org/spec120/#extension_rtree', "
            "'write-only')");
    return t;
}

void write_rtree_indexes(SqlitePages &file, const std::vector<RtreeLayer> &layers,
                         const std::vector<RtreeTables> &tables, const Progress &progress) {
    Steps steps{progress};
    for (const RtreeLayer &layer : layers)
        steps.total += 2.0 * double(layer.boxes.size());
    // Packed on every core, a layer to a thread, then written in turn.
    std::vector<PackedTree> trees(layers.size());
    for_each_part(layers.size(), [&](std::size_t i) {
        pack_tree(layers[i], (tables[i].node_bytes - 4) / (8 + 4 * 4), trees[i]);
    });
    for (std::size_t i = 0; i < layers.size(); ++i)
        write_tree(file, layers[i], trees[i], tables[i], steps);
}

void finish_bulk_layer(GpkgSqlite &db, const std::string &table, std::int64_t rows,
                       const std::array<double, 4> &extent) {
    Statement count(
        db, "UPDATE gpkg_ogr_contents SET feature_count = ? WHERE table_name = " + literal(table),
        "counting the rows of " + table);
    count.insert(rows);
    Statement sequence(db,
                       "INSERT INTO sqlite_sequence (name, seq) VALUES (" + literal(table) + ", ?)",
                       "the fid sequence of " + table);
    sequence.insert(rows);
    if (extent[0] <= extent[1]) {
        // As GDAL 3.6 writes it: through SQLite's printf, which keeps 16 significant digits.
        char *sql = sqlite3_mprintf("UPDATE gpkg_contents SET min_x = %.18g, min_y = %.18g, "
                                    "max_x = %.18g, max_y = %.18g WHERE table_name = %Q",
                                    extent[0], extent[2], extent[1], extent[3], table.c_str());
        if (!sql)
            db.fail("the extent of " + table, "out of memory");
        const std::string text = sql;
        sqlite3_free(sql);
        db.exec(text);
    }
}

} // namespace globemesh::io
