// Internal to io/: a netCDF-4 file's compressed variables written chunk by chunk, each chunk
// shuffled and deflated by the caller, on any thread, for the UGRID writer.
//
// netCDF-C hands every chunk to HDF5's filter pipeline (byte shuffle, then zlib's deflate) on
// the thread that writes: at 4e6 nodes that was half of the writer's CPU time, on one core. The
// writer defines its file with netCDF-C as before (each variable chunked, shuffled, deflated),
// closes it, and reopens it here with HDF5 to store each chunk whole (H5Dwrite_chunk, HDF5's
// direct chunk write, meant for callers that compress on their own). ChunkEncoder encodes a
// chunk exactly as those two filters define it, with libdeflate instead of zlib for the deflate:
// the same zlib stream format, which every HDF5 reads, 1.8 times as fast at level 1 and a little
// smaller; a double's byte planes that are noise go into the stream as stored blocks, not
// deflated. The file is the same netCDF-4 file, chunk for chunk; only the deflate streams differ.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <hdf5.h>

#include "globemesh/error.hpp"
#include "netcdf_lock.hpp"

struct libdeflate_compressor;

namespace globemesh::io {

/// Shuffles and deflates chunks (HDF5 filters 2 and 1, in that order, as netCDF-C's
/// nc_def_var_deflate with shuffle sets them). One per thread.
class ChunkEncoder {
public:
    ChunkEncoder();
    ~ChunkEncoder();
    ChunkEncoder(const ChunkEncoder &) = delete;
    ChunkEncoder &operator=(const ChunkEncoder &) = delete;

    /// Encodes `rows` rows of `row_bytes` bytes each (elements of element_size bytes) as one
    /// chunk of chunk_rows rows into `out`. HDF5 stores a variable's last chunk whole: the rows
    /// past `rows` are zeros (a reader never sees them).
    void encode(const void *data, std::size_t rows, std::size_t chunk_rows, std::size_t row_bytes,
                std::size_t element_size, std::vector<unsigned char> &out);

private:
    /// Whether a plane of `bytes` bytes is noise, not worth deflating (hdf5_chunks.cpp).
    bool noise(const unsigned char *plane, std::size_t bytes);

    libdeflate_compressor *compressor_;
    std::vector<unsigned char> shuffled_, probe_;
};

/// A closed netCDF-4 file reopened for direct chunk writes. Messages name `target` (the file the
/// temporary one becomes). A file not closed explicitly is abandoned as NcHandle abandons one:
/// HDF5's descriptors of it are first pointed at memory, so that no failed flush (a full disk)
/// leaves HDF5 holding it.
class Hdf5ChunkFile {
public:
    Hdf5ChunkFile(const std::filesystem::path &temp, const std::filesystem::path &target,
                  const char *what);
    ~Hdf5ChunkFile();
    Hdf5ChunkFile(const Hdf5ChunkFile &) = delete;
    Hdf5ChunkFile &operator=(const Hdf5ChunkFile &) = delete;

    /// Stores an encoded chunk (ChunkEncoder) of variable `name`, the one whose first row is
    /// first_row (a multiple of the variable's chunk rows). Throws IoError.
    void write(const std::string &name, std::size_t first_row,
               const std::vector<unsigned char> &chunk);
    /// Flushes and closes the file; throws IoError (the file is then abandoned as above).
    void close();

private:
    void close_datasets();
    /// The IoError of a failed HDF5 call at `step`.
    IoError failure(const std::string &step) const;

    NetcdfLock lock_{netcdf_mutex()}; // HDF5 as netCDF-C: one thread at a time (netcdf_lock.hpp)
    std::filesystem::path temp_, target_;
    const char *what_;
    hid_t file_ = H5I_INVALID_HID;
    std::map<std::string, hid_t> datasets_;
};

} // namespace globemesh::io
