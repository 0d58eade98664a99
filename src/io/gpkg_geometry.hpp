// Internal to io/: the GeoPackage writer's geometry (gpkg_write.cpp). Faces and lines as GIS
// software draws them right (face_geometry.hpp), no part wider than 180 degrees of longitude
// (QGIS draws straight lines in lon/lat, so a wider part, a face round a pole or a coastline
// loop, is smeared across the map: a face round a pole is also cut at lon 0, and a line wherever
// its lon extent would pass 180), and faces and points as GeoPackage geometry blobs.
#pragma once

#include <array>
#include <vector>

#include "face_geometry.hpp"
#include "globemesh/mesh.hpp"

namespace globemesh::io {

/// Widest part the writer emits, degrees of longitude.
constexpr double max_part_width_deg = 180.0;

/// min x, max x, min y, max y, the order of a GeoPackage geometry's envelope.
using Envelope = std::array<double, 4>;

/// The ring itself if it is at most 180 degrees wide, else its pieces between the meridians at
/// multiples of 180, each at most 180 wide.
std::vector<LonLatPart> narrow_rings(LonLatPart ring);

/// A line cut into pieces at most 180 degrees wide, each starting where the last one ended.
std::vector<LonLatPart> narrow_lines(const LonLatPart &line);

/// The face with corners v (lon/lat ll: vec_to_lonlat of v) appended to `out` as a GeoPackage
/// MultiPolygon blob: its rings as face_polygons and narrow_rings cut them (`empty` when it
/// has none); returns its envelope.
Envelope append_face(std::vector<unsigned char> &out, const Vec3 v[3], const LonLat ll[3],
                     bool &empty);

/// A point appended to `out` as a GeoPackage blob (no envelope, as GDAL writes points).
void append_point(std::vector<unsigned char> &out, double x, double y);

} // namespace globemesh::io
