// globemesh/ugrid.hpp: UGRID 1.0 NetCDF writer and reader (netCDF-C).
//
// write_ugrid writes a CF-1.8 / UGRID-1.0 file that MDAL (QGIS), xarray tools and ocean models
// read as it is (see issue "Outputs"): every connectivity with cf_role and start_index, the CRS
// where both CF and MDAL read it, data on nodes/faces/edges, run metadata as global attributes.
// It writes to a temporary name beside the target and renames at the end: a failure leaves no
// file. read_ugrid reads any UGRID 2-D triangle mesh (0- or 1-based, with or without fill values).
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/mesh_stats.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

struct UgridOptions {
    bool classic = false; ///< --format classic: netCDF-3 classic model instead of NetCDF-4+deflate
    bool overwrite =
        false; ///< replace an existing file; otherwise an existing output is an IoError
    std::string title = "globemesh ocean mesh";
    std::string history; ///< the full command line and date (the CLI fills it)
    /// compute_stats of this same mesh when the caller has it (the global attributes take it
    /// as it is); null: the writer computes it.
    const MeshStats *stats = nullptr;
    /// When given, receives each face's geodesic area (m2), as the file's face area variable
    /// holds it: write_gpkg takes it (GpkgOptions::face_areas_m2) instead of solving every
    /// edge's geodesic problem again.
    std::vector<double> *face_areas_m2 = nullptr;
    /// Reports the share of the rows written (stage "write_ugrid"); returning false cancels
    /// (Cancelled, no file left).
    Progress progress;
};

/// Writes the mesh as UGRID NetCDF. Throws IoError (unwritable folder, existing output, disk
/// full) and leaves no partial or temporary file.
void write_ugrid(const Mesh &mesh, const std::filesystem::path &path,
                 const UgridOptions &options = {});

/// Reads a UGRID 2-D triangle mesh (first mesh_topology variable). Throws IoError (not readable)
/// or DataError (not UGRID, not triangles, out-of-range indices).
Mesh read_ugrid(const std::filesystem::path &path);

} // namespace globemesh
