// Internal to io/: a small RAII owner for a netCDF-C file id and the status check that turns a
// netCDF error into an IoError naming the file.
#pragma once

#include <filesystem>
#include <string>

#include <netcdf.h>

#include "globemesh/error.hpp"
#include "netcdf_lock.hpp"

namespace globemesh::io {

/// Throws IoError("<what> <file>: <step>: <nc_strerror>") when status is not NC_NOERR, with a
/// note when the file's disk is full (HDF5 reports that as a bare "HDF error").
void nc_check(int status, const std::filesystem::path &file, const std::string &step,
              const char *what = "UGRID file");

/// Points every descriptor this process holds on `file` at one new empty memory file, so that
/// whatever is written through them from now on lands in memory (a temporary file being
/// abandoned, whose last flush must not fail). Returns how many it moved.
int divert_to_memory(const std::filesystem::path &file);

/// Owns an open netCDF id, under the process's netCDF lock (netcdf_lock.hpp) from construction to
/// destruction; abandons (nc_abort) a file that was not closed explicitly.
///
/// HDF5 flushes a netCDF-4 file as it closes it, abandoned or not. When that flush fails (a full
/// disk), HDF5 keeps the file open, netCDF-C 4.9.0 crashes listing its open objects, and HDF5
/// 1.10.8 crashes closing it again at the process's exit. So a file this handle created is
/// never closed on a failed flush: before it is abandoned, HDF5's descriptors of it are pointed
/// at an empty memory file (it is a temporary file, deleted next), where the flush succeeds.
class NcHandle {
public:
    NcHandle();
    ~NcHandle();
    NcHandle(const NcHandle &) = delete;
    NcHandle &operator=(const NcHandle &) = delete;
    int *out() { return &id_; }
    int id() const { return id_; }
    /// nc_create of `temp`, the temporary file through which `target` is written (messages
    /// name target); throws IoError.
    void create(const std::filesystem::path &temp, int mode, const std::filesystem::path &target,
                const char *what);
    /// Closes the file, flushing it first on its own (when that fails, the file is still open and
    /// the destructor abandons it as above); throws IoError on failure (e.g. a full disk).
    void close(const std::filesystem::path &file, const char *what = "UGRID file");

private:
    NetcdfLock lock_{netcdf_mutex()}; // first: released after the destructor's abandon
    int id_ = -1;
    std::filesystem::path created_;
};

} // namespace globemesh::io
