// Internal to globemesh_lib: the RAII owners for GDAL/OGR C handles and GDAL's error state,
// shared by every reader and writer that calls GDAL (the library never prints, so GDAL's errors
// are silenced and read back with last_error() to become exceptions at the call site).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <type_traits>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "globemesh/progress.hpp"

namespace globemesh::gdal {

/// Routes GDAL's error messages to a quiet handler for its lifetime and clears the last error;
/// the last message stays readable through last_error().
class QuietErrors {
public:
    QuietErrors() {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        CPLErrorReset();
    }
    ~QuietErrors() { CPLPopErrorHandler(); }
    QuietErrors(const QuietErrors &) = delete;
    QuietErrors &operator=(const QuietErrors &) = delete;
};

/// GDAL's last error message, or `fallback` when there is none.
inline std::string last_error(const char *fallback = "unknown GDAL error") {
    const char *m = CPLGetLastErrorMsg();
    return m && *m ? m : fallback;
}

/// For a path to an archive or compressed file that GDAL opens only through its virtual file
/// systems (.zip, .tar, .tgz, .tar.gz, .gz, case-insensitive), how to name it: "a zip archive
/// opens as /vsizip/PATH ...". Empty for any other path, or one already under /vsi.
inline std::string archive_hint(const std::string &path) {
    if (path.rfind("/vsi", 0) == 0)
        return {};
    auto ends = [&](std::string_view ext) {
        return path.size() > ext.size() &&
               EQUAL(path.c_str() + path.size() - ext.size(), std::string(ext).c_str());
    };
    if (ends(".zip"))
        return "a zip archive opens as /vsizip/" + path + " (or /vsizip/" + path +
               "/FILE for one file in it)";
    if (ends(".tar") || ends(".tgz") || ends(".tar.gz"))
        return "a tar archive opens as /vsitar/" + path + "/FILE";
    if (ends(".gz"))
        return "a gzip file opens as /vsigzip/" + path;
    return {};
}

/// What to do about a path GDAL could not open: archive_hint's prefix for an archive, else to
/// check the path and format.
inline std::string open_advice(const std::string &path) {
    const std::string hint = archive_hint(path);
    return hint.empty() ? "check the path and format" : hint;
}

/// GDAL's `reason` an open failed, and for an archive archive_hint's prefix after it (the
/// reason's closing '.' dropped before the "; ").
inline std::string with_archive_hint(std::string reason, const std::string &path) {
    const std::string hint = archive_hint(path);
    if (hint.empty())
        return reason;
    if (!reason.empty() && reason.back() == '.')
        reason.pop_back();
    return reason + "; " + hint;
}

/// Sets a GDAL configuration option for this thread and restores the old value on scope exit.
class ScopedConfig {
public:
    ScopedConfig(const char *key, const char *value) : key_(key) {
        if (const char *old = CPLGetThreadLocalConfigOption(key, nullptr))
            old_ = old, had_ = true;
        CPLSetThreadLocalConfigOption(key, value);
    }
    ~ScopedConfig() { CPLSetThreadLocalConfigOption(key_.c_str(), had_ ? old_.c_str() : nullptr); }
    ScopedConfig(const ScopedConfig &) = delete;
    ScopedConfig &operator=(const ScopedConfig &) = delete;

private:
    std::string key_, old_;
    bool had_ = false;
};

/// Calls `Free` on a non-null handle (std::unique_ptr never passes null to its deleter).
template <auto Free> struct Deleter {
    template <class T> void operator()(T *h) const { Free(h); }
};

template <class Handle, auto Free>
using HandlePtr = std::unique_ptr<std::remove_pointer_t<Handle>, Deleter<Free>>;

using DatasetPtr = HandlePtr<GDALDatasetH, GDALClose>;
using FeaturePtr = HandlePtr<OGRFeatureH, OGR_F_Destroy>;
using GeometryPtr = HandlePtr<OGRGeometryH, OGR_G_DestroyGeometry>;
/// Deletes the spatial reference outright (OSRDestroySpatialReference).
using SrsPtr = HandlePtr<OGRSpatialReferenceH, OSRDestroySpatialReference>;
/// Drops one reference (OSRRelease), deleting the spatial reference when it was the last.
using SrsRefPtr = HandlePtr<OGRSpatialReferenceH, OSRRelease>;
using TransformPtr = HandlePtr<OGRCoordinateTransformationH, OCTDestroyCoordinateTransformation>;

/// Opens `path` read-only as vector data. Throws IoError "WHERE: cannot open as vector data:
/// REASON", GDAL's reason (no such file, a format it does not read) by GDAL_OF_VERBOSE_ERROR,
/// and for an archive the /vsi prefix that opens it (archive_hint).
inline DatasetPtr open_vector(const std::string &path, const ErrorText &where) {
    const QuietErrors quiet;
    DatasetPtr ds(GDALOpenEx(path.c_str(),
                             GDAL_OF_VECTOR | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, nullptr,
                             nullptr, nullptr));
    if (!ds)
        throw IoError(where + ": cannot open as vector data: " +
                      with_archive_hint(last_error("not a vector format GDAL reads"), path));
    return ds;
}

/// A Progress as GDAL's GDALProgressFunc, on [lo, hi] of it under the name `stage`: pass
/// &ProgressBridge::call and the bridge's address. When the callback asks to stop, GDAL's call
/// fails and `cancelled` tells the caller to throw Cancelled rather than an error.
struct ProgressBridge {
    const Progress *progress;
    double lo, hi;
    std::string_view stage;
    bool cancelled = false;
    static int CPL_STDCALL call(double f, const char *, void *data) {
        auto *b = static_cast<ProgressBridge *>(data);
        if (*b->progress && !(*b->progress)(b->lo + (b->hi - b->lo) * f, b->stage)) {
            b->cancelled = true;
            return FALSE;
        }
        return TRUE;
    }
};

} // namespace globemesh::gdal
