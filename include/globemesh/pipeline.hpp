// globemesh/pipeline.hpp: the library's top-level jobs, one call each (GDAL's *_lib pattern).
//
// mesh_ocean() runs the whole flow of DESIGN.md: read and shape the coastline, read the
// bathymetry, build the size field, mesh, attach depth and size. triangulate_file() is the
// scattered-points job. Both fill a StageTimings with the seconds each stage took.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/options.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

/// Meshes the ocean as the options say. Throws UsageError, DataError, IoError or Cancelled.
Mesh mesh_ocean(const MeshOptions& options, const Progress& progress = {},
                StageTimings* timings = nullptr);

struct TriangulateOptions {
    std::string points;       ///< any OGR point source (CSV with lon/lat columns, GPKG, SHP)
    std::string layer;        ///< layer name; default the first layer
    double merge_tolerance_rad = 1e-12; ///< points closer than this are merged
    std::uint64_t seed = 1;
};

/// Spherical Delaunay triangulation of the points of an OGR source (reprojected to lon/lat).
/// Keeps solid triangles only (see delaunay.hpp). Stages "read", "sort"+"triangulate" (timed
/// together as "triangulate" when not separable), "write" is the caller's.
Mesh triangulate_file(const TriangulateOptions& options, const Progress& progress = {},
                      StageTimings* timings = nullptr);

} // namespace globemesh
