// Internal to io/ (and the bathymetry read): the one lock on netCDF-C and HDF5 in this process.
// netCDF-C is not thread-safe (Debian's HDF5 is built thread-safe, netCDF-C's own state is not
// guarded), and GDAL guards its netCDF driver with a mutex of its own: two runs at once (two Python
// threads, two QGIS Processing tasks) crashed in nc_enddef, one writing its UGRID file while the
// other read a NetCDF raster through GDAL. Every netCDF or HDF5 file this process opens is held
// under it from open to close, and so is a raster GDAL reads.
#pragma once

#include <mutex>

namespace globemesh {

/// The process's netCDF/HDF5 lock (recursive: one thread may hold two files, as convert does).
inline std::recursive_mutex &netcdf_mutex() {
    static std::recursive_mutex mutex;
    return mutex;
}

/// Holds netcdf_mutex() for its lifetime.
using NetcdfLock = std::unique_lock<std::recursive_mutex>;

/// Turns off HDF5's printing of its error stack for the calling thread: netCDF-C turns it off
/// for the thread that first uses it, and HDF5 printed HDF5-DIAG blocks on stderr for a file
/// opened in another (a Python thread, a QGIS task). Its errors still come back as statuses.
void quiet_hdf5_errors();

} // namespace globemesh
