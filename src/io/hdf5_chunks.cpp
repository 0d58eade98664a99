// Direct chunk writes of a netCDF-4 file's compressed variables: see hdf5_chunks.hpp.
#include "hdf5_chunks.hpp"

#include <algorithm>
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

} // namespace

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
    out.resize(libdeflate_zlib_compress_bound(compressor_, bytes));
    out.resize(
        libdeflate_zlib_compress(compressor_, shuffled_.data(), bytes, out.data(), out.size()));
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
