// Internal to io/: a small RAII owner for a netCDF-C file id and the status check that turns a
// netCDF error into an IoError naming the file.
#pragma once

#include <filesystem>
#include <string>

#include <netcdf.h>

#include "globemesh/error.hpp"

namespace globemesh::io {

/// Throws IoError("<what> <file>: <step>: <nc_strerror>") when status is not NC_NOERR.
inline void nc_check(int status, const std::filesystem::path& file, const std::string& step,
                     const char* what = "UGRID file") {
    if (status != NC_NOERR)
        throw IoError(std::string(what) + " " + file.string() + ": " + step + ": " + nc_strerror(status));
}

/// Owns an open netCDF id; abandons (nc_abort) a file that was not closed explicitly.
class NcHandle {
public:
    NcHandle() = default;
    ~NcHandle() {
        if (id_ >= 0) nc_abort(id_);
    }
    NcHandle(const NcHandle&) = delete;
    NcHandle& operator=(const NcHandle&) = delete;
    int* out() { return &id_; }
    int id() const { return id_; }
    /// Closes the file, flushing it; throws IoError on failure (e.g. disk full).
    void close(const std::filesystem::path& file, const char* what = "UGRID file") {
        int id = id_;
        id_ = -1;
        nc_check(nc_close(id), file, "closing (disk full?)", what);
    }

private:
    int id_ = -1;
};

} // namespace globemesh::io
