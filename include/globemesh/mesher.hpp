// globemesh/mesher.hpp: the ocean mesher (Legrand, Legat & Deleersnijder 2000, sections 3-4).
//
// From closed boundary rings (boundary.hpp: ocean on the left) and a size field h(x) in km, it
//   1. inserts every boundary node into the spherical Delaunay core;
//   2. recovers every boundary segment by edge flips, splitting a segment at its midpoint only
//      where flips cannot recover it; recovered segments are constrained for good;
//   3. classifies triangles by flood fill across unconstrained edges, seeded on the left of every
//      segment, drops land and the ocean components apart from the largest one that reach no
//      open (region) segment (inland seas) unless keep_inland_seas, and reports each component
//      by area; then closes the
//      inlets narrower than inlet_width * h (an edge between two nodes of one ring, shorter than
//      that, becomes coast when the water behind it is under inlet_area * h^2, or narrower on
//      average than inlet_width * h and under 25 h^2; repeated, so a dead-end channel closes
//      whole), which no triangle of size h could fill but slivers; then a coast segment shorter
//      than close_node_gap * h (a closed mouth between the source's own vertices) loses one end
//      where the segment joining its neighbours crosses nothing, and one shorter than
//      inlet_width * h / 2 where that end then lies within close_node_gap * h of the new
//      segment, is no corner of a closed inlet's mouth and begins no ocean chord as short;
//   4. refines by Delaunay refinement: the triangle whose circumradius is largest against the
//      local target (an equilateral triangle of side h has circumradius h/sqrt(3)) or whose
//      radius-edge ratio is worst gets a new node at its circumcentre; a circumcentre beyond a
//      boundary segment splits that segment at its midpoint instead (Ruppert). Each triangle's
//      badness is computed once, when the core creates it; candidates wait in a 4-ary heap of
//      16-byte entries stamped with their slot's generation (a stale entry is skipped), ordered
//      by badness in steps of 2^(1/8) and, within a step, along the Hilbert curve (locality);
//   5. improves: sweeps of optimal-Delaunay smoothing of the interior nodes (each moved to the
//      area-weighted mean of its triangles' circumcentres, refused where a triangle would fold),
//      with Delaunay flips after each move; boundary nodes stay put. A node whose move would
//      be under 1% of h stays, and sits out the next sweep unless a neighbour moved. Nodes are
//      visited along the Hilbert curve (src/delaunay/hilbert.hpp), so consecutive stars share
//      cache lines.
//      After the last sweep, relaxation towards valence 6 (Frey & Field): edges whose four
//      corners are away from the boundary (not on it nor next to it) are flipped where that
//      lowers the corners' sum of squared valence defects, the nodes around move to the mean of
//      their neighbours without flips, and Lawson flips make the mesh Delaunay again there.
//      Then six rounds over the nodes of triangles below q 0.82: each interior node moves where
//      its star has the best worst triangle up to 0.6, then the most triangles above q 0.8,
//      then the highest sum of qualities capped at 0.82 (a pattern search from the best of a
//      few candidates: the mean of the apexes that would make each star triangle equilateral,
//      the mean of its neighbours, halfway to either). With MesherOptions::land, each boundary
//      node between two coast segments of one ring slides the same way, within 0.2 h of the
//      source coast (LandTest::coast_within), where no coast corner becomes sharper than 60
//      degrees and no more of its faces are centred on land. Every move is checked on the
//      triangles its flips leave (none below the star's worst or 0.6, none of two or three
//      boundary corners below 0.6) and undone otherwise.
//      Last, two rounds of a pattern search over the nodes of triangles still below q 0.6,
//      and triangles with two or three boundary corners still below 0.6 get a node (their
//      circumcentre, or the midpoint of the segment in its way);
//   6. keeps face centroids off the islands the coast shaping dropped (Boundary::
//      dropped_islands): a face centred on one gets a free corner moved so that its centroid
//      leaves the island, where no triangle of the corner's star falls below min(0.8, its
//      quality); the faces left are reported;
//   7. with MesherOptions::land, removes the faces whose centroid lies on the source land (under
//      capes the shaped coast cuts across, on dropped islands, spanning water narrower than a
//      face), alone or in small groups, all of a group or none, where the mesh stays a
//      manifold and in one piece: at each corner the faces left form at most one fan, and the
//      arcs along which a group touches the boundary lie on different loops. A group touching
//      no loop opens a hole (a dropped island comes back); one touching two or more joins them
//      (narrow water between two rings closes), only where most of the face is land; two arcs
//      on one loop would cut the mesh, so a face across the mouth of a basin goes only with
//      the water behind it, when that holds at most inlet_area * h^2 (a bay, or a river
//      narrower than its faces); a sea behind a strait stays connected (Gibraltar, the
//      Bosphorus at 100 km). Water behind the mouth that reaches a part's border (lattice_within)
//      goes on unseen in the other part: it goes only with close_straits, as a strait closed
//      (reported), else stays. Otherwise a face goes with the one or two water faces between it
//      and the boundary at a corner. A node it leaves on the boundary lies within h/2 of the
//      coast (LandTest::coast_within). Removing faces keeps every other
//      face and edge, so the mesh stays constrained Delaunay. A face left on land then gets one
//      corner moved (a boundary corner slides as in step 5; one the removals put on the
//      boundary stays within h/2 of the coast) so that its centroid goes to the water near it,
//      where no triangle falls below min(its star's worst, 0.6) and fewer faces are centred on
//      land; the edges between ocean and land are constrained first, so no flip crosses the
//      boundary. The faces still on land lie across straits narrower than a face, or where a
//      removal would leave a node too far from the coast. With MesherOptions::close_straits
//      (the default) they go as above but may also cut the mesh in two, the sea behind
//      becoming a basin of its own (the Black Sea behind the Dardanelles at 100 km; reported;
//      a piece that close_inlets' rule would close goes too), or close the strait at a node
//      between two fans of water (the output gives each fan after the first a node of its
//      own, 0.64 m into it or less, so the mesh stays a manifold), and the nodes they put on
//      the boundary may lie up to 0.75 h from the coast. The faces left on land are reported
//      with their centroids. Last (after the corners are blunted), the pieces beside the
//      closings and the fans at split nodes go under the same rule: no piece the output
//      makes apart from the largest is one close_inlets would close, and each is reported.
// The result is constrained Delaunay, every face counter-clockwise, and deterministic: the same
// input and options give the same mesh. Standard library only (sphere, delaunay).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/size_fn.hpp"

namespace globemesh {

/// MesherOptions::whole_rings of a segment along a border between parts.
inline constexpr std::uint32_t no_whole_ring = 0xffffffffu;

struct MesherOptions {
    std::uint64_t max_nodes = 20'000'000; ///< refuse when the size field asks for more nodes
    std::uint64_t max_memory = 0;  ///< bytes; refuse when the estimated peak exceeds it (0: no cap)
    int smooth_iterations = 4;     ///< smoothing sweeps
    bool keep_inland_seas = false; ///< keep ocean components apart from the largest (those
                                   ///< reaching an open segment are kept always)
    double inlet_width = 0.5;      ///< close inlets narrower than this times h (0: none)
    double inlet_area = 1.0; ///< ... holding at most this times h^2 of water (or narrow on average)
    /// Once the inlets have closed, a coast segment shorter than this times h (a closed mouth
    /// between the source's own vertices) loses one of its ends (CoastOptions::close_node_gap);
    /// one shorter than inlet_width h / 2 loses an end that moves the coast by less. 0: none.
    double close_node_gap = 1.0 / 32;
    std::uint64_t seed = 1; ///< seed of the core's insertion order
    /// The size field's largest value (km): where the field reaches it, away from the boundary,
    /// the ocean is first filled with a regular (icosahedral) lattice of that spacing, and the
    /// refinement fills the rest. 0: no lattice, every node from the refinement.
    double lattice_km = 0;
    /// Where the ocean may lie (a part's lune, parts.hpp): where dot(p, n) > 0 for each normal
    /// n. The lattice's points elsewhere are not looked for in the triangulation, and
    /// `lattice_share` (the share of the sphere that covers) scales the lattice's points
    /// against the node estimate. Empty: the whole sphere. A node on one of these planes (a
    /// part's border) is never split where a closed strait pinches it: the other part's faces
    /// may join its fans, and join_parts splits those still pinched.
    std::vector<Vec3> lattice_within;
    double lattice_share = 1;
    /// mesh_parts: the longitude (degrees) of the lunes' first border; NaN, the default: chosen
    /// from the inputs (docs/parallel.md, section 1).
    double parts_border_lon = std::numeric_limits<double>::quiet_NaN();
    /// Coast nodes the close-node merge keeps (sorted as x, y, z): the corners of the inlets'
    /// mouths mesh_parts closed on the whole boundary before the split (those a border crosses),
    /// which a part's rings hold as plain coast nodes (one part keeps such a corner: land on
    /// both sides of it).
    std::vector<std::array<double, 3>> mouth_corners;
    /// mesh_parts, for a part: per ring of the boundary, per segment, the ring of the whole
    /// boundary the segment lies on, or no_whole_ring along a border between parts. The land
    /// stage then tells a removal that would cut the ocean in two (two contacts with one ring)
    /// from one that joins two coasts by these rings: the part's borders join its coasts into
    /// loops the whole ocean does not have (the Suez canal, within a part whose Mediterranean
    /// reaches the border, was kept open as a cut). Empty: the boundary is the whole.
    std::vector<std::vector<std::uint32_t>> whole_rings;
    /// With `land`: measure the width of each strait closed (MesherReport::
    /// straits_closed_width_km). mesh_parts measures its parts' closings after the parts, beside
    /// their join, and turns this off in the parts.
    bool measure_straits = true;
    /// The source land at full resolution (e.g. coast.hpp's LandMask): boundary nodes slide near
    /// its coast (step 5 above), and faces whose centroid lies on it are removed at the end where
    /// the mesh stays one manifold and its new boundary nodes near the coast (step 7). Null:
    /// boundary nodes stay where the rings put them, and no face is removed.
    std::shared_ptr<const LandTest> land;
    /// With `land`: close the straits narrower than a face that faces centred on land are left
    /// across (step 7), rather than keep them open with those faces.
    bool close_straits = true;
    /// With inlet_width: a channel the strait closings leave as a dead end (the stub of a canal
    /// closed further along), and the water behind any edge between two boundary nodes shorter
    /// than inlet_width h / 2 (a stub the refinement left), close by the inlet rule too.
    bool close_dead_ends = true;
    /// With inlet_width: after the corners are blunted, the pieces the closings left apart (a
    /// face hanging at a split node) close by the inlet rule too.
    bool close_pieces_apart = true;
    /// Lines across straits (passages.hpp): no strait closing removes a face one of them meets.
    std::vector<std::vector<Vec3>> passages;
    /// The region's box W,S,E,N in degrees (W > E crosses 180), when there is one: a boundary
    /// node slides along the coast (the quality rounds, nudge_off_land) only to points inside
    /// it, as the source coast runs on past the region's edge.
    std::optional<std::array<double, 4>> region;
};

/// Peak bytes per output node allowed for meshing, used to turn the node estimate into a memory
/// estimate before refining: mesh_boundary's own peak (bench/mesher_memory measures it) with
/// room for the UGRID writer's tables that follow in the pipeline.
inline constexpr std::uint64_t mesher_bytes_per_node = 800;

/// The node estimate of an area meshed at size h (area in h's units squared): equilateral
/// triangles of side h cover sqrt(3)/4 h^2 each, and a large mesh has two triangles per node.
/// mesh_boundary sums it over the ocean's triangles before refining (the check against
/// max_nodes); the pipeline asks it first for the whole ocean at hmax_km.
inline double nodes_for_area(double area, double h) {
    return area / (0.4330127018922193 /* sqrt(3) / 4 */ * h * h) / 2.0;
}

struct OceanComponent {
    double area_km2 = 0;
    bool kept = false;
};

struct MesherReport {
    std::size_t boundary_nodes = 0;
    std::size_t segments_split = 0;    ///< segments split because flips could not recover them
    std::size_t encroached_splits = 0; ///< segments split during refinement and mending
    std::size_t estimated_nodes = 0; ///< the size field's node estimate, checked against max_nodes
    int parts = 1;                   ///< the parts meshed apart and joined (mesh_parts)
    double parts_border_lon = 0;     ///< their first border's longitude, degrees (parts > 1)
    std::size_t sharp_corners = 0;   ///< boundary nodes with an ocean angle below 60 degrees
    std::size_t sharp_corner_faces = 0; ///< faces touching such a corner (quality reported apart)
    std::size_t inlets_closed =
        0; ///< closings (MesherOptions::inlet_width; a long channel may take several)
    double inlet_area_km2 = 0;          ///< the water they held
    std::size_t coast_nodes_merged = 0; ///< ends of short coast segments (close_node_gap)
    std::size_t lattice_nodes = 0;      ///< nodes from the lattice (MesherOptions::lattice_km)
    std::size_t lattice_patched =
        0; ///< of which placed with their lattice triangles, not inserted one by one
    std::size_t island_centroids_moved = 0; ///< faces moved off islands the shaping dropped
    std::size_t island_centroids_left = 0;  ///< faces whose centroid is still on such an island
    std::size_t valence_flips = 0;          ///< flips towards valence 6 before the last restoration
    std::size_t corners_mended =
        0; ///< triangles of two or three boundary nodes split after smoothing
    std::size_t corners_blunted = 0;     ///< faces below q 0.3 at sharp coast corners removed last
    std::size_t floor_nodes_removed = 0; ///< free nodes of faces below q 0.3 removed to mend them
    std::size_t floor_nodes_added = 0;   ///< nodes added on the shortest side of faces below q 0.3
    std::size_t land_faces_removed = 0;  ///< faces removed because their centroid lies on land
    std::size_t land_faces_left =
        0; ///< faces centred on land that could not go (MesherOptions::land)
    std::size_t land_faces_nudged = 0; ///< faces that a corner's move took off land instead
    std::vector<Vec3> land_faces_at;   ///< the centroids of the land_faces_left
    std::size_t water_faces_removed =
        0;                      ///< faces removed with them so that the mesh stays a manifold
    std::size_t land_holes = 0; ///< boundary loops those removals opened (islands back)
    std::size_t land_loops_joined =
        0; ///< boundary loops those removals joined to another (narrow water closed)
    std::size_t straits_closed =
        0; ///< of the faces removed, those that closed a strait (MesherOptions::close_straits)
    std::vector<Vec3> straits_closed_at; ///< their centroids
    /// Each closed strait's water width (km) near its place in straits_closed_at: the narrowest
    /// passage joining two stretches of water within 0.6 h of it (0: narrower than the sampling).
    std::vector<double> straits_closed_width_km;
    /// Where the width is 0: the sampling's finest spacing (km), which the passage is narrower
    /// than.
    std::vector<double> straits_closed_width_below_km;
    /// The place of each closing: closings less than the size apart, in a chain, are one place
    /// (a channel narrower than its faces closes at many points along it). Numbered from 0 in
    /// the order of each place's first closing.
    std::vector<std::uint32_t> straits_closed_place;
    std::size_t straits_closed_places = 0;
    std::vector<double> seas_cut_off; ///< km2 of each basin those closings cut off (kept)
    /// The nodes beside those closings' cuts: mesh_parts tells the basins on the joined mesh, a
    /// part's own pieces reaching the ocean through another part.
    std::vector<Vec3> cut_points;
    double straits_water_km2 = 0; ///< water cut off with them and closed (inlet_area, inlet_width)
    std::size_t nodes_split =
        0; ///< nodes added where a strait closed at a node between two fans of water
    std::vector<OceanComponent> components;
};

/// Meshes the ocean bounded by `boundary` (empty: the whole sphere) with edges of about
/// size_km(x) km. Throws DataError when the rings do not close the ocean, when no ocean is left,
/// or when the estimated node count exceeds options.max_nodes (or the estimated memory,
/// estimated_nodes * mesher_bytes_per_node, exceeds options.max_memory); Cancelled through
/// progress. Stage times go to `timings` under insert_boundary, recover, classify, refine, improve.
/// Neighbouring nodes are mostly close in the numbering, and so are neighbouring faces (the
/// lattice's insertion order or, when the refinement made most nodes, a Hilbert curve's).
Mesh mesh_boundary(const Boundary &boundary, const SizeFn &size_km,
                   const MesherOptions &options = {}, MesherReport *report = nullptr,
                   const Progress &progress = {}, StageTimings *timings = nullptr);

} // namespace globemesh
