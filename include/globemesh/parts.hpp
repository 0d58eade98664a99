// Parallel meshing (docs/parallel.md): the sphere split into `parts` lunes between meridians,
// each border discretised first from the size field (the same nodes for both sides), every part
// meshed by mesh_boundary on a thread of its own, and the parts joined in part order. The result
// depends on the part count and the inputs, never on the thread count. One part is mesh_boundary
// itself. Standard library only.
#pragma once

#include <vector>

#include "globemesh/mesher.hpp"

namespace globemesh {

/// Most parts: the lunes meet at the poles at 360 / parts degrees, 60 (an equilateral
/// triangle's corner) at 6.
inline constexpr int max_parts = 6;

/// The part count mesh_parts chooses when asked for 0 parts: one part below this many nodes
/// (the whole ocean's node estimate), auto_parts from it. Measured on 2 cores
/// (bench/RESULTS-parallel.md): at 1e6 nodes two parts are as fast as one on a real coast and
/// slower on an open ocean; from 4e6 they are 1.4-1.5 times faster. Fixed, never the core
/// count, so that the mesh depends on the inputs alone; more parts pay only with more cores
/// (--parts).
inline constexpr std::size_t auto_parts_nodes = 2'000'000;
inline constexpr int auto_parts = 2;

/// The part count for a run of `estimated_nodes` nodes (auto_parts_nodes).
inline int parts_for_nodes(std::size_t estimated_nodes) {
    return estimated_nodes < auto_parts_nodes ? 1 : auto_parts;
}

/// The first border's longitude (degrees) where none is asked for and none chosen: off the
/// meridians where source data has vertices by construction (0, +-90, +-180).
inline constexpr double default_border_lon = -90 + 0.0123456789;

/// A node this close to a border's plane (radians) lies on the border: border nodes are on it
/// to rounding (1e-16, as split_boundary puts them), every other node a segment's length away.
inline constexpr double on_border_tolerance = 1e-12;

/// The sphere cut into `count` lunes: border k is the meridian at first_lon + 360 k / count
/// degrees, and part k lies east of border k and west of border k + 1.
struct Lunes {
    int count = 1;
    double first_lon = default_border_lon;

    /// The longitude (degrees) of border k.
    double border_lon(int k) const { return first_lon + 360.0 * k / count; }
    /// The normal of border k's meridian plane: dot(p, normal) > 0 east of the border.
    Vec3 border_normal(int k) const;
    /// Where border k's meridian meets the equator: dot(p, direction) > 0 on its half of the
    /// plane.
    Vec3 border_direction(int k) const;
    /// Degrees from the first border east to p's meridian, in [0, 360).
    double east_of_first(const Vec3 &p) const;
    /// The lune (0 .. count - 1) holding p.
    int part_of(const Vec3 &p) const;
};

/// `boundary` cut into the rings of each part: each ring piece inside a part, joined along the
/// part's borders by nodes spaced by size_km (open segments), a deterministic function of the
/// border, the coast crossing it and the size field. An empty boundary (aqua-planet) gives each
/// part its outline. A border no ring crosses is ocean as the south pole is, which the crossed
/// borders tell; with no crossing at all, not for a region's outline (rings with open segments)
/// and else where `land` (may be null) has no land. A part without ocean gets no rings and
/// `has_ocean` false. Throws DataError when the rings do not alternate along a border (they do
/// not close the ocean).
struct PartBoundary {
    Boundary boundary;
    /// Per ring of `boundary`, per segment: the ring of the whole boundary it lies on, or
    /// no_whole_ring along a border (MesherOptions::whole_rings).
    std::vector<std::vector<std::uint32_t>> whole_rings;
    bool has_ocean = false;
};
std::vector<PartBoundary> split_boundary(const Boundary &boundary, const SizeFn &size_km,
                                         const Lunes &lunes, const LandTest *land);

/// The part meshes joined: nodes equal on a border are one node, a border segment one side
/// split is split on the other (a fan, or a star around a node of its own where a fan face
/// would fall below q 0.3), boundary edges with their reverse become interior.
/// With the parts' lattice size (MesherOptions::lattice_km) and size field, the band along the
/// borders is made the lattice again where it is open ocean at that size.
Mesh join_parts(std::vector<Mesh> &parts_meshes, const Lunes &lunes, const SizeFn &size_km = {},
                double lattice_km = 0);

/// mesh_boundary over `parts` parts, meshed on up to `threads` threads (0: one) and joined;
/// the inland seas are told on the whole boundary first (MesherOptions::keep_inland_seas), the
/// rest per part. `parts` 0: parts_for_nodes of that pass's node estimate (one part is then
/// mesh_boundary on `boundary`, as `parts` 1). report->parts says how many. Reports and stage times
/// are summed over the parts. Throws what mesh_boundary throws, the first in part order.
Mesh mesh_parts(const Boundary &boundary, const SizeFn &size_km, const MesherOptions &options,
                int parts, unsigned threads, MesherReport *report = nullptr,
                const Progress &progress = {}, StageTimings *timings = nullptr);

} // namespace globemesh
