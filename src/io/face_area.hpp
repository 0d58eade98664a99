// Internal to io/: the geodesic areas of a mesh's faces on the WGS84 ellipsoid, for both writers.
//
// GeographicLib's PolygonArea solves one inverse problem per side of a polygon and sums the
// sides' S12 terms (the area between the geodesic and the equator). A mesh edge is a side of
// two faces, so the inverse problem of each edge is solved here once (on every core) and its
// S12 enters one face with its sign and the other with the opposite sign: half the geodesic
// work of PolygonArea face by face, the same areas (to rounding), and areas that tile the
// ellipsoid exactly, each edge's term cancelling between its faces. Each face's sum is then
// reduced as PolygonArea::Compute does it: modulo the ellipsoid's area, and by half of it when
// the face goes round a pole (an odd number of crossings of the prime meridian).
//
// Memory: one double per edge (about 24 bytes per node) while the object lives. The corners'
// lon/lat are converted where needed rather than held: a table of them (16 bytes per node) made
// the writer the process's peak at 20 km (204.3 MiB instead of the mesher's 194.5).
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"

namespace globemesh::io {

class GeodesicFaceAreas {
public:
    /// Solves every edge's inverse problem, on every core. When `stop` turns true meanwhile,
    /// returns early with the areas unfinished (for a writer that failed or was cancelled).
    explicit GeodesicFaceAreas(const MeshTopology &topo, const std::atomic<bool> *stop = nullptr);

    /// The area of face f (m2), whose edges edges_of_f are those face_edges gives.
    double face_m2(std::size_t f, const std::int32_t *edges_of_f) const;

private:
    const MeshTopology &topo_;
    std::vector<double> s12_; ///< per edge, from its first node to its second (edge_nodes)
};

} // namespace globemesh::io
