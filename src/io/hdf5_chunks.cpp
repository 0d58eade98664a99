// Direct chunk writes of a netCDF-4 file's compressed variables: see hdf5_chunks.hpp.
#include "hdf5_chunks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <new>
#include <type_traits>

#include <libdeflate.h>

#include "globemesh/output_file.hpp"
#include "netcdf_handle.hpp"

namespace globemesh::io {

namespace fs = std::filesystem;

namespace {

/// HDF5's shuffle of m elements of `size` bytes from `in` into `size` planes of n bytes at
/// `out`; `size` a std::integral_constant for the common sizes (its loops unrolled).
template <class Size>
void shuffle(const unsigned char *in, std::size_t m, std::size_t n, Size size, unsigned char *out) {
    for (std::size_t i = 0; i < m; ++i)
        for (std::size_t j = 0; j < size; ++j)
            out[j * n + i] = in[i * size + j];
}

/// A plane is noise when its bytes' entropy is at least noise_bits (Huffman codes could save
/// under 0.4% of it) and deflate saves under probe_saving of its first probe_bytes (no repeats
/// for the matches to find either: a counter's low byte has all the entropy but repeats).
constexpr double noise_bits = 7.97;
constexpr std::size_t probe_bytes = 8192;
constexpr double probe_saving = 0.01;

/// Appends `bytes` bytes at `in` as stored deflate blocks (RFC 1951, 3.2.4: a header byte,
/// LEN and its complement, the bytes), the last one final when `final`. The stream is byte
/// aligned before and after each.
void append_stored(const unsigned char *in, std::size_t bytes, bool final,
                   std::vector<unsigned char> &out) {
    constexpr std::size_t most = 65535;
    for (std::size_t done = 0; done < bytes;) {
        const std::size_t len = std::min(most, bytes - done);
        done += len;
        const auto byte = [](std::size_t v) { return static_cast<unsigned char>(v & 0xff); };
        // BFINAL, BTYPE 00 and the padding to the byte; LEN and NLEN little-endian.
        const unsigned char header[] = {byte(final && done == bytes), byte(len), byte(len >> 8),
                                        byte(~len), byte(~len >> 8)};
        out.insert(out.end(), header, header + sizeof header);
        out.insert(out.end(), in + done - len, in + done);
    }
}

} // namespace

bool ChunkEncoder::noise(const unsigned char *plane, std::size_t bytes) {
    std::array<std::size_t, 256> count{};
    for (std::size_t i = 0; i < bytes; ++i)
        ++count[plane[i]];
    double bits = 0;
    for (const std::size_t c : count)
        if (c)
            bits -= double(c) * std::log2(double(c) / double(bytes));
    if (bits < noise_bits * double(bytes))
        return false;
    const std::size_t n = std::min(bytes, probe_bytes);
    probe_.resize(libdeflate_deflate_compress_bound(compressor_, n));
    const std::size_t packed =
        libdeflate_deflate_compress(compressor_, plane, n, probe_.data(), probe_.size());
    return packed == 0 || double(packed) >= double(n) * (1 - probe_saving);
}

ChunkEncoder::ChunkEncoder() : compressor_(libdeflate_alloc_compressor(1)) {
    if (!compressor_)
        throw std::bad_alloc();
}

ChunkEncoder::~ChunkEncoder() {
    libdeflate_free_compressor(compressor_);
}

void ChunkEncoder::encode(const void *data, std::size_t rows, std::size_t chunk_rows,
                          std::size_t row_bytes, std::size_t element_size,
                          std::vector<unsigned char> &out) {
    const std::size_t bytes = chunk_rows * row_bytes, used = rows * row_bytes,
                      n = bytes / element_size;
    // HDF5's shuffle: byte j of element i goes to j * n + i (n elements in the chunk); the
    // elements past `used` (a last chunk's) are zeros. Not zero-filled first: every byte is set.
    shuffled_.resize(bytes);
    const auto *in = static_cast<const unsigned char *>(data);
    const std::size_t m = used / element_size;
    if (element_size == 8)
        shuffle(in, m, n, std::integral_constant<std::size_t, 8>{}, shuffled_.data());
    else if (element_size == 4)
        shuffle(in, m, n, std::integral_constant<std::size_t, 4>{}, shuffled_.data());
    else
        shuffle(in, m, n, element_size, shuffled_.data());
    for (std::size_t j = 0; j < element_size; ++j)
        std::fill(shuffled_.begin() + std::ptrdiff_t(j * n + m),
                  shuffled_.begin() + std::ptrdiff_t((j + 1) * n), 0);
    // A double's leading planes that are noise (its low mantissa bytes) are stored, not
    // deflated: deflate spent most of its time on them to save 0-3% of them. The rest follows
    // deflated in the same stream, which any zlib inflates. Not for integers: the
    // connectivity's low bytes look like noise but repeat far apart (deflate saves 20-55%).
    std::size_t stored = 0;
    while (element_size == 8 && stored < element_size && noise(shuffled_.data() + stored * n, n))
        ++stored;
    if (stored == 0) {
        out.resize(libdeflate_zlib_compress_bound(compressor_, bytes));
        out.resize(
            libdeflate_zlib_compress(compressor_, shuffled_.data(), bytes, out.data(), out.size()));
        return;
    }
    const std::size_t head = stored * n;
    out.assign({0x78, 0x01}); // zlib header: deflate, 32 KiB window, the fastest level
    append_stored(shuffled_.data(), head, head == bytes, out);
    if (head < bytes) {
        const std::size_t at = out.size();
        out.resize(at + libdeflate_deflate_compress_bound(compressor_, bytes - head));
        out.resize(at + libdeflate_deflate_compress(compressor_, shuffled_.data() + head,
                                                    bytes - head, out.data() + at,
                                                    out.size() - at));
    }
    const std::uint32_t adler = libdeflate_adler32(1, shuffled_.data(), bytes);
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<unsigned char>(adler >> shift));
}

Hdf5ChunkFile::Hdf5ChunkFile(const fs::path &temp, const fs::path &target, const char *what)
    : temp_(temp), target_(target), what_(what) {
    file_ = H5Fopen(temp.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    if (file_ < 0)
        throw failure("reopening the file for its data");
}

IoError Hdf5ChunkFile::failure(const std::string &step) const {
    return IoError(std::string(what_) + " " + target_.string() + ": " + step + ": HDF error" +
                   OutputFile::full_disk_note(target_));
}

Hdf5ChunkFile::~Hdf5ChunkFile() {
    if (file_ < 0)
        return;
    close_datasets();
    if (divert_to_memory(temp_) > 0) {
        // As NcHandle: the first flush may still fail (HDF5 finds the file shorter than it wrote
        // it), the next one does not; a file no flush went through is left open.
        bool flushed = false;
        for (int attempt = 0; attempt < 3 && !flushed; ++attempt)
            flushed = H5Fflush(file_, H5F_SCOPE_LOCAL) >= 0;
        if (!flushed)
            return;
    }
    H5Fclose(file_);
}

void Hdf5ChunkFile::close_datasets() {
    for (const auto &[name, id] : datasets_)
        H5Dclose(id);
    datasets_.clear();
}

void Hdf5ChunkFile::write(const std::string &name, std::size_t first_row,
                          const std::vector<unsigned char> &chunk) {
    auto it = datasets_.find(name);
    if (it == datasets_.end()) {
        const hid_t id = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
        if (id < 0)
            throw failure("opening " + name);
        it = datasets_.emplace(name, id).first;
    }
    const hsize_t offset[2] = {hsize_t(first_row), 0}; // rank 1 or 2: only the rows are chunked
    if (H5Dwrite_chunk(it->second, H5P_DEFAULT, 0, offset, chunk.size(), chunk.data()) < 0)
        throw failure("writing " + name);
}

void Hdf5ChunkFile::close() {
    close_datasets();
    if (H5Fflush(file_, H5F_SCOPE_LOCAL) < 0)
        throw failure("writing");
    const hid_t id = file_;
    file_ = H5I_INVALID_HID;
    if (H5Fclose(id) < 0)
        throw failure("closing");
}

} // namespace globemesh::io
