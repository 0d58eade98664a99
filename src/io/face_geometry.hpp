// Internal to io/: faces and lines of the sphere as lon/lat geometry that GIS software draws
// right.
//
// GIS draws straight lines in lon/lat, so: a pole corner becomes two points at +-90 (at the
// longitudes of the neighbouring corners) and the polar fan draws as quads; a face around a pole
// (no corner at it) is closed along the pole line; anything crossing +-180 is cut there into
// parts that each lie in [-180, 180]. Coordinates are degrees, (lon, lat).
#pragma once

#include <array>
#include <vector>

#include "globemesh/mesh.hpp"

namespace globemesh::io {

using LonLatPoint = std::array<double, 2>;
using LonLatPart = std::vector<LonLatPoint>; ///< a ring (not repeated closing point) or a line

/// The signed area of a lon/lat ring (no repeated closing point), square degrees in the plane,
/// positive counter-clockwise: the shoelace sum over its sides in order. Any ring of points
/// that index as [0] lon, [1] lat (a LonLatPart, a std::array of them).
template <class Ring> double ring_area(const Ring &r) {
    double a = 0;
    for (std::size_t i = 0; i < r.size(); ++i) {
        const auto &p = r[i], &q = r[(i + 1) % r.size()];
        a += p[0] * q[1] - q[0] * p[1];
    }
    return 0.5 * a;
}

/// The face abc (unit vectors, counter-clockwise) as one or more polygon rings within [-180, 180].
std::vector<LonLatPart> face_polygons(const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// The one ring of face_polygons(v[0], v[1], v[2]) in its common case, from the corners' lon/lat
/// (vec_to_lonlat of v): no corner at a pole, the face not round a pole, every corner strictly
/// inside (-180, 180) once the ring is unwrapped, and not degenerate. Then face_polygons returns
/// exactly {ring} (the same values: its clipping keeps such a ring as it is), and this returns
/// true without allocating; else false.
bool simple_face_ring(const Vec3 v[3], const LonLat ll[3], std::array<LonLatPoint, 3> &ring);

/// A polyline of unit vectors (straight in lon/lat between nodes) cut at +-180 into parts.
std::vector<LonLatPart> polyline_parts(const std::vector<Vec3> &nodes);

} // namespace globemesh::io
