// globemesh/passages.hpp: critical passages, lines drawn across straits that must stay open.
//
// A passage is a polyline of great-circle arcs drawn across a strait from land to land
// (--passages SOURCE, any OGR source of LineString/MultiLineString in any CRS). Its width is
// the length of its part in water: the line is sampled every width / 4000 (at most 25 m) against
// the source land (LandTest), or, without a land test, its whole length. The size field is
// lowered to width / passage_cells on the background grid's cells the line runs through
// (sizefield.hpp), below hmin where that needs it; the mesher never closes a strait across a
// passage (mesher.hpp, step 7); the run reports each passage with the ocean faces it crosses.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

/// One passage: its name (the "name" attribute, else "passage FID"), its line (unit vectors,
/// at least two points) and, once measured, its width in water (km).
struct Passage {
    std::string name;
    std::vector<Vec3> line;
    double width_km = 0;
};

/// A passage in the final mesh: its width, the size the field asked there and the ocean faces
/// its line crosses.
struct PassageReport {
    std::string name;
    double width_km = 0;
    double size_km = 0;
    std::size_t cells = 0;
    Vec3 at; ///< the line's middle point
};

/// The lines of an OGR source (layer `layer`, else every layer), transformed to lon/lat.
/// Throws IoError (unreadable), DataError (no such layer, no CRS, a polygon or point layer,
/// no line at all), naming the option --passages.
std::vector<Passage> read_passages(const std::string &path, const std::string &layer);

/// Sets each passage's width_km: the length of its part in water (land->contains false), or
/// its whole length when land is null.
void measure_passages(std::vector<Passage> &passages, const LandTest *land);

/// True when the polyline `line` (great-circle arcs) meets the spherical triangle a, b, c
/// (counter-clockwise): an arc crosses an edge, or a point of the line lies inside.
bool line_meets_triangle(std::span<const Vec3> line, const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// True when the polyline `line` reaches the ocean of `ocean` (left of its rings): an arc
/// crosses or touches a ring's segment, or the line lies in the ocean. A line across a strait
/// (land to land) reaches a region's ocean exactly when the strait's water lies in the region.
/// O(line arcs x ring segments).
bool line_meets_ocean(std::span<const Vec3> line, const Boundary &ocean);

/// The faces of `mesh` (all ocean) that `line` meets.
std::size_t faces_crossed(const Mesh &mesh, std::span<const Vec3> line);

} // namespace globemesh
