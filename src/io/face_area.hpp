// Internal to io/: the geodesic areas of a mesh's faces on the WGS84 ellipsoid, for both writers.
//
// The area of a geodesic triangle is that of its image on the authalic sphere (the equal-area
// map of the ellipsoid, radius R_q, latitude -> authalic latitude): the spherical triangle of
// the three mapped corners, plus, for each side, the area between the image of the ellipsoid's
// geodesic and the sphere's great circle. That curve is nearly a great circle (its geodesic
// curvature on the sphere, kappa, is of the order of the flattening over R_q), so the area
// between them is kappa * L^3 / 12 with kappa taken at the side's midpoint (L its length on the
// sphere; the next terms are of relative order (L / R_q)^2). No geodesic problem is solved:
// on faces of sides up to short_side_km the areas agree with GeographicLib's PolygonArea to
// better than 1e-9 relative (tests/unit/face_area_test.cpp checks it face by face); a face with
// a longer side is given PolygonArea's area itself. Each side's term is computed from the
// edge's own direction (edge_nodes) and enters its two faces with opposite signs, so the
// areas still tile the ellipsoid.
//
// Memory: 48 bytes a node while it lives: each node's image on the authalic sphere and each
// edge's side term, computed once, on every core, when it is built (a node is a corner of about
// six faces, an edge a side of two).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"

namespace globemesh::io {

class GeodesicFaceAreas {
public:
    /// Faces with a side longer than this (chord, km on the unit sphere times 6371) are given
    /// GeographicLib's PolygonArea.
    static constexpr double short_side_km = 80;

    /// The areas of topo's mesh, face by face in face_m2 (safe from any thread); the nodes'
    /// images and the edges' side terms are computed here, on every core.
    explicit GeodesicFaceAreas(const MeshTopology &topo);

    /// The area of face f (m2), whose edges edges_of_f are those face_edges gives.
    double face_m2(std::size_t f, const std::int32_t *edges_of_f) const;

private:
    /// A Vec3 without default member initializers, which fresh_array can leave unwritten.
    struct Point {
        double x, y, z;
        Point() = default;
        explicit Point(const Vec3 &v) : x(v.x), y(v.y), z(v.z) {}
        Vec3 vec() const { return {x, y, z}; }
    };
    const MeshTopology &topo_;
    std::unique_ptr<Point[]> authalic_; ///< each node's image on the authalic sphere
    std::unique_ptr<double[]> side_;    ///< each edge's side term (m2), in its own direction
};

/// The area (m2) of the geodesic triangle abc (unit vectors of geodetic lon/lat, as
/// vec_to_lonlat reads them) on WGS84, as GeographicLib's PolygonArea gives it (its absolute
/// value): for tests and the writers' long sides.
double polygon_area_m2(const Vec3 &a, const Vec3 &b, const Vec3 &c);

} // namespace globemesh::io
