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

/// The face abc (unit vectors, counter-clockwise) as one or more polygon rings within [-180, 180].
std::vector<LonLatPart> face_polygons(const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// A polyline of unit vectors (straight in lon/lat between nodes) cut at +-180 into parts.
std::vector<LonLatPart> polyline_parts(const std::vector<Vec3> &nodes);

} // namespace globemesh::io
