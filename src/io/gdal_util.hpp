// Internal to io/: GDAL helpers for the GeoPackage and PNG writers (the GDAL C++ dataset owner
// and close_dataset); the general owners come from gdal_handles.hpp.
#pragma once

#include <memory>
#include <string>

#include <cpl_error.h>
#include <gdal_priv.h>

#include "gdal_handles.hpp"

namespace globemesh::io {

// The shared owners live in gdal_handles.hpp; these names keep io/'s call sites unchanged.
using QuietGdalErrors = gdal::QuietErrors;
using ScopedGdalConfig = gdal::ScopedConfig;

inline std::string last_gdal_error() {
    return gdal::last_error();
}

/// Owns a GDALDataset through GDAL's C++ API (the writers use it); closes it with GDALClose.
struct GdalDatasetCloser {
    void operator()(GDALDataset *ds) const {
        if (ds)
            GDALClose(GDALDataset::ToHandle(ds));
    }
};
using GdalDatasetPtr = std::unique_ptr<GDALDataset, GdalDatasetCloser>;

/// Closes the dataset now and reports whether GDAL signalled a failure while flushing it.
inline bool close_dataset(GdalDatasetPtr &ds) {
    CPLErrorReset();
    ds.reset();
    return CPLGetLastErrorType() != CE_Failure && CPLGetLastErrorType() != CE_Fatal;
}

} // namespace globemesh::io
