// The netCDF handle: see netcdf_handle.hpp.
#include "netcdf_handle.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdlib>
#include <system_error>

#include <hdf5.h>

#include "globemesh/output_file.hpp"

namespace globemesh::io {

namespace fs = std::filesystem;

int divert_to_memory(const fs::path &file) {
    std::error_code ec;
    const fs::path target = fs::canonical(file, ec);
    if (ec)
        return 0;
    const int memory = ::memfd_create("globemesh-abandoned", MFD_CLOEXEC);
    if (memory < 0)
        return 0;
    int moved = 0;
    for (const auto &entry : fs::directory_iterator("/proc/self/fd", ec)) {
        std::error_code link_ec;
        if (fs::read_symlink(entry.path(), link_ec) != target || link_ec)
            continue;
        const int fd = std::atoi(entry.path().filename().c_str());
        if (fd != memory && ::dup2(memory, fd) == fd)
            ++moved;
    }
    ::close(memory);
    return moved;
}

void nc_check(int status, const fs::path &file, const std::string &step, const char *what) {
    if (status == NC_NOERR)
        return;
    throw IoError(std::string(what) + " " + file.string() + ": " + step + ": " +
                  nc_strerror(status) +
                  (status == NC_EHDFERR ? OutputFile::full_disk_note(file) : ""));
}

NcHandle::NcHandle() {
    quiet_hdf5_errors();
}

NcHandle::~NcHandle() {
    if (id_ < 0)
        return;
    if (!created_.empty() && divert_to_memory(created_) > 0) {
        // The first flush may still fail (HDF5 finds the file shorter than it wrote it); the next
        // one does not. A file no flush could go through is left open: nc_abort would crash.
        bool flushed = false;
        for (int attempt = 0; attempt < 3 && !flushed; ++attempt)
            flushed = nc_sync(id_) == NC_NOERR;
        if (!flushed)
            return;
    }
    nc_abort(id_);
}

void NcHandle::create(const fs::path &temp, int mode, const fs::path &target, const char *what) {
    nc_check(nc_create(temp.c_str(), mode, &id_), target, "creating the file", what);
    created_ = temp;
}

void NcHandle::close(const fs::path &file, const char *what) {
    nc_check(nc_sync(id_), file, "writing", what);
    const int id = id_;
    id_ = -1;
    nc_check(nc_close(id), file, "closing", what);
}

} // namespace globemesh::io

namespace globemesh {

void quiet_hdf5_errors() {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

} // namespace globemesh
