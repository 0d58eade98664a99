// The mesher's last step: the coast's corners sharper than the faces there can hold are blunted
// (issue 37's floor, OceanMesh2D's: no face below q 0.3). Internal to mesher/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/delaunay.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::detail {

/// What blunt_corners needs of the mesher's state: the triangulation with its ocean and land
/// labels, the size field, the boundary segments, and the lists the output reads.
struct CornerMesh {
    SphericalDelaunay &dt;
    std::uint8_t ocean, land; ///< the labels of dt's triangles
    const std::function<double(const Vec3 &)> &size_km;
    std::function<SegmentKind(VertexId, VertexId)> kind; ///< a boundary edge's kind
    std::function<void(VertexId, VertexId, SegmentKind)>
        add_segment; ///< a new segment a -> b, ocean on its left
    std::function<VertexId(HalfEdge)>
        split_segment;              ///< splits a segment at its midpoint (no_vertex: not split)
    std::vector<VertexId> &pinched; ///< nodes left between fans of ocean (split apart on output)
    std::vector<TriangleId>
        &cut_sides; ///< ocean faces beside a closing that may cut the mesh in two
};

struct CornerReport {
    std::size_t blunted = 0;      ///< ears of the coast removed (two or three boundary sides)
    std::size_t splits = 0;       ///< segments split to bring an ear's tip within reach
    std::vector<Vec3> straits_at; ///< faces removed where the water is narrower than them
};

/// Whether a triangle around v (near: one of them, or a hint) is not labelled `ocean`: v is a
/// node of the water's boundary.
inline bool on_boundary(const SphericalDelaunay &dt, std::uint8_t ocean, VertexId v,
                        TriangleId near) {
    const HalfEdge from = dt.leaving(v, near);
    HalfEdge h = from;
    do {
        if (dt.label(triangle_of(h)) != ocean)
            return true;
        h = dt.next_around_origin(h);
    } while (h != from);
    return false;
}

/// The floor and the reach: a face below `floor` goes when its corner lies within `reach` h
/// of its opposite side (see corners.cpp).
inline constexpr double blunt_floor = 0.3;
inline constexpr double blunt_reach = 1.0;

/// Removes the ocean faces below blunt_floor that the coast's corners leave (see corners.cpp).
/// Every node that a removal leaves between two fans of ocean goes to `pinched`, so the
/// output stays a manifold.
CornerReport blunt_corners(CornerMesh &m, bool close_straits);

} // namespace globemesh::detail
