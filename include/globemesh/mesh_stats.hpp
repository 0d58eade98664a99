// globemesh/mesh_stats.hpp: what a mesh is like (MeshStats) and whether it is sound (check_mesh).
//
// compute_stats measures a Mesh as `globemesh info`, the run summary, --report and the files'
// metadata print it: counts, extent, face quality, edge lengths, area and, with a node field
// "target_size", the edge lengths against it. check_mesh lists the invariants of mesh.hpp that
// a mesh breaks (the command line's --check). Neither throws.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "globemesh/mesh.hpp"

namespace globemesh {

/// Summary statistics of a mesh.
struct MeshStats {
    std::size_t nodes = 0, faces = 0, edges = 0, boundary_edges = 0, boundary_loops = 0;
    double lon_min = 0, lon_max = 0, lat_min = 0, lat_max = 0; ///< extent, degrees
    /// Face quality q (1 equilateral, 0 degenerate): smallest, mean, fraction of faces above 0.8
    double quality_min = 0, quality_mean = 0, quality_above_0_8 = 0;
    std::array<std::size_t, 10> quality_histogram{}; ///< counts of q in [0,0.1), ..., [0.9,1]
    double edge_km_min = 0, edge_km_mean = 0, edge_km_max = 0; ///< great-circle edge lengths, km
    double area_km2 = 0;   ///< sum of spherical face areas on the sphere of earth_radius_km
    bool has_size = false; ///< true when a node field "target_size" exists
    /// Edge length / mean target_size of its ends: median, and fraction in [0.7, 1.4]
    double size_ratio_median = 0, size_ratio_in_range = 0;
};

/// The statistics of `mesh` (every face and edge visited; an empty mesh gives zeros).
MeshStats compute_stats(const Mesh &mesh);

/// The invariants of mesh.hpp that fail (empty when the mesh is sound): indices in range,
/// three distinct corners, counter-clockwise faces (sign of det[a,b,c] in floating point), unit
/// nodes (|1-|v|| < 1e-12), every edge shared by at most two faces with opposite directions,
/// boundary list equal to the edges used by one face, field sizes. At most `limit` messages.
std::vector<std::string> check_mesh(const Mesh &mesh, std::size_t limit = 20);

} // namespace globemesh
