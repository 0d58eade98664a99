// Internal to io/: small RAII owners for GDAL state used by the GeoPackage and PNG writers.
#pragma once

#include <memory>
#include <string>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>

namespace globemesh::io {

/// Keeps GDAL from printing (the library never prints): errors are read with last_gdal_error().
class QuietGdalErrors {
public:
    QuietGdalErrors() {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        CPLErrorReset();
    }
    ~QuietGdalErrors() { CPLPopErrorHandler(); }
    QuietGdalErrors(const QuietGdalErrors&) = delete;
    QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
};

inline std::string last_gdal_error() {
    const char* m = CPLGetLastErrorMsg();
    return m && *m ? m : "unknown GDAL error";
}

/// Sets a GDAL configuration option for this thread and restores the old value.
class ScopedGdalConfig {
public:
    ScopedGdalConfig(const char* key, const char* value) : key_(key) {
        if (const char* old = CPLGetThreadLocalConfigOption(key, nullptr)) old_ = old, had_ = true;
        CPLSetThreadLocalConfigOption(key, value);
    }
    ~ScopedGdalConfig() { CPLSetThreadLocalConfigOption(key_.c_str(), had_ ? old_.c_str() : nullptr); }
    ScopedGdalConfig(const ScopedGdalConfig&) = delete;
    ScopedGdalConfig& operator=(const ScopedGdalConfig&) = delete;

private:
    std::string key_, old_;
    bool had_ = false;
};

struct GdalDatasetCloser {
    void operator()(GDALDataset* ds) const {
        if (ds) GDALClose(GDALDataset::ToHandle(ds));
    }
};
using GdalDatasetPtr = std::unique_ptr<GDALDataset, GdalDatasetCloser>;

/// Closes the dataset now and reports whether GDAL signalled a failure while flushing it.
inline bool close_dataset(GdalDatasetPtr& ds) {
    CPLErrorReset();
    ds.reset();
    return CPLGetLastErrorType() != CE_Failure && CPLGetLastErrorType() != CE_Fatal;
}

} // namespace globemesh::io
