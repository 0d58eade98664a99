// Rowid tables filled by writing their pages: see sqlite_pages.hpp.
#include "sqlite_pages.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"

namespace globemesh::io {

namespace {

/// SQLite's variable-length integer (fileformat2 1.6): 7 bits a byte, high first, and the ninth
/// byte's 8 bits.
std::size_t varint_bytes(std::uint64_t v) {
    std::size_t n = 1;
    while (n < 9 && (v >> (7 * n)) != 0)
        ++n;
    return n;
}

std::size_t put_varint(unsigned char *p, std::uint64_t v) {
    const std::size_t n = varint_bytes(v);
    if (n == 9) {
        p[8] = static_cast<unsigned char>(v);
        v >>= 8;
        for (int i = 7; i >= 0; --i, v >>= 7)
            p[i] = static_cast<unsigned char>((v & 0x7f) | 0x80);
        return 9;
    }
    for (std::size_t i = n; i-- > 0; v >>= 7)
        p[i] = static_cast<unsigned char>((v & 0x7f) | (i + 1 < n ? 0x80 : 0));
    return n;
}

std::uint32_t get_be(const unsigned char *p, int bytes) {
    std::uint32_t v = 0;
    for (int i = 0; i < bytes; ++i)
        v = v << 8 | p[i];
    return v;
}

constexpr unsigned char table_leaf = 0x0d, table_interior = 0x05;
constexpr std::size_t header_bytes = 100; // the database header, at the start of page 1
constexpr std::size_t flush_bytes = 1 << 20;

} // namespace

void put_big_endian(unsigned char *p, std::uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i, v >>= 8)
        p[i] = static_cast<unsigned char>(v);
}

unsigned sqlite_integer_type(std::int64_t v) {
    if (v == 0 || v == 1)
        return 8 + unsigned(v);
    const std::uint64_t u = v < 0 ? ~std::uint64_t(v) : std::uint64_t(v);
    constexpr std::uint64_t limits[] = {0x7f, 0x7fff, 0x7fffff, 0x7fffffff, 0x7fffffffffff};
    unsigned type = 1;
    while (type < 6 && u > limits[type - 1])
        ++type;
    return type;
}

std::size_t sqlite_integer_bytes(unsigned type) {
    constexpr std::size_t sizes[] = {0, 1, 2, 3, 4, 6, 8, 8, 0, 0};
    return sizes[type];
}

std::size_t null_and_integer_record(std::int64_t v, unsigned char (&out)[11]) {
    const unsigned type = sqlite_integer_type(v);
    out[0] = 3, out[1] = 0, out[2] = static_cast<unsigned char>(type); // header size, NULL, v
    const std::size_t bytes = sqlite_integer_bytes(type);
    put_big_endian(out + 3, std::uint64_t(v), int(bytes));
    return 3 + bytes;
}

void SqliteRecord::integer(std::int64_t v) {
    const unsigned type = sqlite_integer_type(v);
    types_.push_back(type);
    const std::size_t at = body_.size(), bytes = sqlite_integer_bytes(type);
    body_.resize(at + bytes);
    if (bytes)
        put_big_endian(&body_[at], std::uint64_t(v), int(bytes));
}

void SqliteRecord::real(double v) {
    if (std::isnan(v)) { // as sqlite3_bind_double stores a NaN
        null();
        return;
    }
    // SQLite stores a whole value of a REAL column as an integer of at most 6 bytes (read back
    // as a real): sqlite3VdbeIntegerAffinity, then OP_MakeRecord. Done alike, the file is as
    // SQLite would write it.
    if (v > -9.2e18 && v < 9.2e18) {
        const auto i = static_cast<std::int64_t>(v);
        if (static_cast<double>(i) == v && sqlite_integer_type(i) != 6) { // not 8 bytes
            integer(i);
            return;
        }
    }
    types_.push_back(7);
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    const std::size_t at = body_.size();
    body_.resize(at + 8);
    put_big_endian(&body_[at], bits, 8);
}

void SqliteRecord::blob(const unsigned char *data, std::size_t bytes) {
    types_.push_back(12 + 2 * std::uint64_t(bytes));
    body_.insert(body_.end(), data, data + bytes);
}

void SqliteRecord::append_to(std::vector<unsigned char> &out) {
    std::size_t types = 0;
    for (std::uint64_t t : types_)
        types += varint_bytes(t);
    std::size_t header = types + 1; // the header's size counts its own varint
    while (varint_bytes(header) + types != header)
        header = types + varint_bytes(header);
    std::size_t at = out.size();
    out.resize(at + header + body_.size());
    at += put_varint(&out[at], header);
    for (std::uint64_t t : types_)
        at += put_varint(&out[at], t);
    std::copy(body_.begin(), body_.end(), out.begin() + std::ptrdiff_t(at));
    types_.clear(), body_.clear();
}

SqlitePages::SqlitePages(const std::filesystem::path &file, std::string label,
                         std::filesystem::path output)
    : label_(std::move(label)), output_(std::move(output)) {
    fd_ = ::open(file.c_str(), O_RDWR | O_CLOEXEC);
    if (fd_ < 0)
        fail("opening it", errno);
    unsigned char h[header_bytes];
    struct stat st {};
    if (::pread(fd_, h, sizeof h, 0) != std::ptrdiff_t(sizeof h) || ::fstat(fd_, &st) != 0)
        fail("reading its header", errno ? errno : EIO);
    const std::uint32_t size = get_be(h + 16, 2);
    page_size_ = size == 1 ? 65536 : size;
    usable_ = page_size_ - h[20];
    // A rollback-journal file (version 1: the file is the whole database) without auto-vacuum
    // (no pointer-map pages to keep). GDAL makes one unless told otherwise.
    if (std::memcmp(h, "SQLite format 3", 16) != 0 || page_size_ < 512 ||
        st.st_size % page_size_ != 0)
        throw IoError(label_ + ": not a SQLite file");
    if (h[18] != 1 || h[19] != 1)
        throw IoError(label_ + ": the SQLite file is in WAL mode (is OGR_SQLITE_JOURNAL set?), "
                               "which the writer cannot fill");
    if (get_be(h + 52, 4) != 0)
        throw IoError(label_ + ": the SQLite file has auto-vacuum (is OGR_SQLITE_PRAGMA set?), "
                               "which the writer cannot fill");
    pages_ = std::uint32_t(st.st_size / page_size_);
    // The page holding the pending byte is never used (fileformat2 1.3); SQLite's own value.
    const int pending = sqlite3_test_control(SQLITE_TESTCTRL_PENDING_BYTE, 0u);
    lock_page_ = std::uint32_t((pending > 0 ? pending : 0x40000000) / page_size_ + 1);
    buffer_first_ = pages_ + 1;
    buffer_.reserve(flush_bytes + page_size_);
}

SqlitePages::~SqlitePages() {
    if (fd_ >= 0)
        ::close(fd_);
}

void SqlitePages::fail(const std::string &step, int error) const {
    throw IoError(label_ + ": " + step + ": " + std::strerror(error) +
                  OutputFile::full_disk_note(output_));
}

std::uint32_t SqlitePages::append(const unsigned char *page) {
    if (pages_ + 1 == lock_page_) {
        buffer_.resize(buffer_.size() + page_size_, 0);
        ++pages_;
    }
    buffer_.insert(buffer_.end(), page, page + page_size_);
    const std::uint32_t number = ++pages_;
    if (buffer_.size() >= flush_bytes)
        flush();
    return number;
}

void SqlitePages::write(std::uint32_t number, const unsigned char *page) {
    if (number >= buffer_first_) {
        std::copy(page, page + page_size_,
                  buffer_.begin() +
                      std::ptrdiff_t(std::size_t(number - buffer_first_) * page_size_));
        return;
    }
    write_at(page, page_size_, off_t(number - 1) * page_size_, "writing");
}

void SqlitePages::write_at(const unsigned char *data, std::size_t bytes, off_t offset,
                           const std::string &step) {
    for (std::size_t done = 0; done < bytes;) {
        const ssize_t n = ::pwrite(fd_, data + done, bytes - done, offset + off_t(done));
        if (n <= 0)
            fail(step, n < 0 ? errno : ENOSPC);
        done += std::size_t(n);
    }
}

void SqlitePages::flush() {
    write_at(buffer_.data(), buffer_.size(), off_t(buffer_first_ - 1) * page_size_, "writing");
    buffer_.clear();
    buffer_first_ = pages_ + 1;
}

void SqlitePages::finish() {
    flush();
    unsigned char h[header_bytes];
    if (::pread(fd_, h, sizeof h, 0) != std::ptrdiff_t(sizeof h))
        fail("reading its header", errno ? errno : EIO);
    // The page count is valid when the version-valid-for number is the change counter.
    const std::uint32_t counter = get_be(h + 24, 4) + 1;
    put_big_endian(h + 24, counter, 4);
    put_big_endian(h + 28, pages_, 4);
    put_big_endian(h + 92, counter, 4);
    put_big_endian(h + 96, std::uint32_t(sqlite3_libversion_number()), 4);
    write_at(h, sizeof h, 0, "writing its header");
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0)
        fail("closing", errno);
}

TableLoader::TableLoader(SqlitePages &file, std::uint32_t root) : file_(file), root_(root) {}

void TableLoader::add(std::int64_t rowid, const unsigned char *record, std::size_t bytes) {
    // How much of the payload stays in the cell (fileformat2 1.6, table leaf cells).
    const std::size_t u = file_.usable(), max_local = u - 35, min_local = (u - 12) * 32 / 255 - 23;
    std::size_t local = bytes;
    if (bytes > max_local) {
        const std::size_t k = min_local + (bytes - min_local) % (u - 4);
        local = k <= max_local ? k : min_local;
    }
    const std::size_t cell =
        varint_bytes(bytes) + varint_bytes(std::uint64_t(rowid)) + local + (local < bytes ? 4 : 0);
    if (cells_ > 0 && 8 + 2 * (cells_ + 1) + content_ + cell > u)
        close_leaf();
    if (page_.empty())
        page_.assign(file_.page_size(), 0); // the reserved bytes past `u` stay zero
    const std::uint32_t chain = local < bytes ? overflow(record + local, bytes - local) : 0;
    content_ += cell;
    unsigned char *p = &page_[u - content_];
    p += put_varint(p, bytes);
    p += put_varint(p, std::uint64_t(rowid));
    std::memcpy(p, record, local);
    if (chain)
        put_big_endian(p + local, chain, 4);
    put_big_endian(&page_[8 + 2 * cells_], u - content_, 2);
    ++cells_;
    last_rowid_ = rowid;
}

std::uint32_t TableLoader::overflow(const unsigned char *rest, std::size_t bytes) {
    // Each overflow page: the next one's number (0 for the last), then usable - 4 bytes. Written
    // last to first, so that each knows its successor.
    const std::size_t u = file_.usable(), per_page = u - 4;
    const std::size_t count = (bytes + per_page - 1) / per_page;
    std::vector<unsigned char> page(file_.page_size(), 0);
    std::uint32_t next = 0;
    for (std::size_t i = count; i-- > 0;) {
        std::fill(page.begin(), page.end(), 0);
        put_big_endian(&page[0], next, 4);
        const std::size_t from = i * per_page, n = std::min(per_page, bytes - from);
        std::memcpy(&page[4], rest + from, n);
        next = file_.append(page.data());
    }
    return next;
}

void TableLoader::close_leaf() {
    const std::size_t u = file_.usable();
    if (page_.empty())
        page_.assign(file_.page_size(), 0);
    page_[0] = table_leaf;
    put_big_endian(&page_[3], cells_, 2);
    put_big_endian(&page_[5], (u - content_) & 0xffff, 2); // 65536 is written 0
    store(last_rowid_);
    page_.clear();
    cells_ = 0, content_ = 0;
}

void TableLoader::store(std::int64_t max_rowid) {
    if (leaves_.empty() && !held_) {
        first_ = page_, first_max_ = max_rowid, held_ = true;
        return;
    }
    if (held_) {
        leaves_.push_back({file_.append(first_.data()), first_max_});
        held_ = false;
        first_.clear();
    }
    leaves_.push_back({file_.append(page_.data()), max_rowid});
}

void TableLoader::finish() {
    const std::size_t u = file_.usable();
    if (cells_ > 0 || (leaves_.empty() && !held_))
        close_leaf(); // the last leaf, or the empty root of an empty table
    if (held_) {      // one leaf: it is the root
        file_.write(root_, first_.data());
        return;
    }
    std::vector<Child> level = std::move(leaves_);
    for (;;) {
        // Interior pages: cells (left child, its largest rowid) and the right-most child. The
        // last page keeps at least two children, so that none has no cell.
        std::vector<std::vector<unsigned char>> pages;
        std::vector<Child> up;
        for (std::size_t i = 0; i < level.size();) {
            std::size_t j = i, used = 12;
            while (j + 1 < level.size()) {
                const std::size_t c = 2 + 4 + varint_bytes(std::uint64_t(level[j].max_rowid));
                if (used + c > u)
                    break;
                used += c, ++j;
            }
            if (level.size() - (j + 1) == 1)
                --j;
            std::vector<unsigned char> &page = pages.emplace_back(file_.page_size(), 0);
            page[0] = table_interior;
            put_big_endian(&page[3], j - i, 2);
            put_big_endian(&page[8], level[j].page, 4);
            std::size_t content = 0;
            for (std::size_t k = i; k < j; ++k) {
                unsigned char cell[13];
                put_big_endian(cell, level[k].page, 4);
                const std::size_t n = 4 + put_varint(cell + 4, std::uint64_t(level[k].max_rowid));
                content += n;
                std::memcpy(&page[u - content], cell, n);
                put_big_endian(&page[12 + 2 * (k - i)], u - content, 2);
            }
            put_big_endian(&page[5], (u - content) & 0xffff, 2);
            up.push_back({0, level[j].max_rowid});
            i = j + 1;
        }
        if (pages.size() == 1) {
            file_.write(root_, pages[0].data());
            return;
        }
        for (std::size_t k = 0; k < pages.size(); ++k)
            up[k].page = file_.append(pages[k].data());
        level = std::move(up);
    }
}

} // namespace globemesh::io
