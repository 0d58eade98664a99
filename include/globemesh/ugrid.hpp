// globemesh/ugrid.hpp: UGRID 1.0 NetCDF writer and reader (netCDF-C), and mesh statistics.
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
#include "globemesh/progress.hpp"

namespace globemesh {

struct MeshStats;

struct UgridOptions {
    bool classic = false;   ///< --format classic: netCDF-3 classic model instead of NetCDF-4+deflate
    bool overwrite = false; ///< replace an existing file; otherwise an existing output is an IoError
    std::string title = "globemesh ocean mesh";
    std::string history;    ///< the full command line and date (the CLI fills it)
    /// compute_stats of this same mesh when the caller has it (the global attributes take it
    /// as it is); null: the writer computes it.
    const MeshStats* stats = nullptr;
    /// When given, receives each face's geodesic area (m2), as the file's face area variable
    /// holds it: write_gpkg takes it (GpkgOptions::face_areas_m2) instead of solving every
    /// edge's geodesic problem again.
    std::vector<double>* face_areas_m2 = nullptr;
    /// Reports the share of the rows written (stage "write_ugrid"); returning false cancels
    /// (Cancelled, no file left).
    Progress progress;
    /// Test hook: called once after the data is partly written, before the rename.
    std::function<void()> after_partial_write;
};

/// Writes the mesh as UGRID NetCDF. Throws IoError (unwritable folder, existing output, disk
/// full) and leaves no partial or temporary file.
void write_ugrid(const Mesh& mesh, const std::filesystem::path& path, const UgridOptions& options = {});

/// Reads a UGRID 2-D triangle mesh (first mesh_topology variable). Throws IoError (not readable)
/// or DataError (not UGRID, not triangles, out-of-range indices).
Mesh read_ugrid(const std::filesystem::path& path);

/// Summary statistics of a mesh, as `globemesh info` and the run report print them.
struct MeshStats {
    std::size_t nodes = 0, faces = 0, edges = 0, boundary_edges = 0, boundary_loops = 0;
    double lon_min = 0, lon_max = 0, lat_min = 0, lat_max = 0; ///< extent, degrees
    double quality_min = 0, quality_mean = 0, quality_above_0_8 = 0; ///< fraction above 0.8
    std::array<std::size_t, 10> quality_histogram{}; ///< counts of q in [0,0.1), ..., [0.9,1]
    double edge_km_min = 0, edge_km_mean = 0, edge_km_max = 0;
    double area_km2 = 0; ///< sum of spherical face areas on the sphere of earth_radius_km
    bool has_size = false;  ///< true when a node field "target_size" exists
    double size_ratio_median = 0, size_ratio_in_range = 0; ///< edge length / target; fraction in [0.7, 1.4]
};

MeshStats compute_stats(const Mesh& mesh);

} // namespace globemesh
