// The mesher's internal state, shared by its stages (mesher.cpp runs them in sequence; each
// stage is a file of src/mesher/), and the constants more than one stage uses.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "disjoint_sets.hpp"
#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/predicates.hpp"
#include "lonlat_box.hpp"
#include "star_search.hpp"

namespace globemesh::mesher_internal {

// Tuned constants shared by stages (bench/RESULTS-mesher.md has the measurements behind them).

// Triangles with two or three boundary corners, which smoothing cannot move, are refined until
// their quality q (sphere.hpp) reaches this.
constexpr double quality_goal = 0.6;
// Shape stops counting below this fraction of the target circumradius, and boundary segments
// shorter than twice this fraction of h are not split: narrow rivers and the pinch points of
// the coast (rings moved 0.64 m apart where they touched) would otherwise be refined down to
// their own width.
constexpr double refine_floor = 0.05;
// A boundary node may slide (the quality rounds, nudge_off_land) to points within this times h
// of the source coast: the issue asks for h/4 at the 95th percentile.
constexpr double slide_reach = 0.2;
// No removal or slide of faces centred on land leaves on the boundary a node farther than this
// times h from the source coast: the 95th percentile then stays under the h/4.
constexpr double land_exposed_reach = 0.5;
// Water behind a narrow mouth (close_inlets) larger than inlet_area h^2 closes too when it is
// narrow on average (a river, a chain of narrow lakes) and holds at most this many h^2.
constexpr double inlet_narrow_area = 25;

constexpr std::uint8_t land = 0;
constexpr std::uint8_t ocean = 1;

/// close_inlets' rule: water behind a narrow mouth, of `area` (square radians) and `perimeter`
/// (radians, the mouth included), where the size is h (radians), closes when it holds at most
/// inlet_area h^2, or is narrower on average (twice its area over its perimeter) than
/// inlet_width h and holds at most inlet_narrow_area h^2.
inline bool inlet_closes(double area, double perimeter, double h, const MesherOptions &options) {
    return area <= options.inlet_area * h * h ||
           (area <= inlet_narrow_area * h * h && 2 * area < options.inlet_width * h * perimeter);
}
constexpr int next3(int i) {
    return i == 2 ? 0 : i + 1;
}
constexpr int prev3(int i) {
    return i == 0 ? 2 : i - 1;
}

using detail::FarEdge;
using detail::pattern_search;
using detail::Points8;
using detail::star_count_accepts;
using detail::star_count_best;
using detail::star_count_score;
using detail::star_worst_accepts;
using detail::star_worst_quality;

/// Whether p lies in the region's box (MesherOptions::region; true without one): where a
/// boundary node may slide to.
inline bool in_region(const MesherOptions &options, const Vec3 &p) {
    return !options.region || in_lonlat_box(*options.region, vec_to_lonlat(p));
}

/// How many of the star triangles p, b, c (far edges b -> c) have their centroid on land.
inline int star_faces_on_land(const LandTest &land, const Vec3 &p,
                              const std::vector<FarEdge> &far) {
    int n = 0;
    for (const FarEdge &e : far)
        n += land.contains(normalized(p + e.b + e.c));
    return n;
}

/// True when moving the star's centre from `at` to `to` (far: its far edges) would bring the
/// star's worst triangle below `floor` and below where it was: the smoothing moves' refusal
/// test. The whole worst after the move is computed only when it falls below floor.
inline bool lowers_worst_below(const Vec3 &to, const Vec3 &at, const std::vector<FarEdge> &far,
                               double floor) {
    if (star_worst_quality(to, far, std::nextafter(floor, 0.0)) >= floor)
        return false;
    return star_worst_quality(to, far) < star_worst_quality(at, far);
}

using Clock = std::chrono::steady_clock;
inline double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

using EdgeKey = std::pair<VertexId, VertexId>;
inline EdgeKey key(VertexId a, VertexId b) {
    return a < b ? EdgeKey{a, b} : EdgeKey{b, a};
}

// Moves per_vertex[v] to new_of_old[v] (SphericalDelaunay::renumber's numbering); vertices past
// its end take `absent`.
template <class T>
void renumber_per_vertex(std::vector<T> &per_vertex, const std::vector<VertexId> &new_of_old,
                         T absent) {
    std::vector<T> out(new_of_old.size(), absent);
    for (std::size_t v = 0; v < per_vertex.size(); ++v)
        out[new_of_old[v]] = per_vertex[v];
    per_vertex.swap(out);
}

using DisjointSets = globemesh::DisjointSets<>;

// The state shared by the steps: the triangulation, the boundary segments with their kinds,
// the size field.
struct Mesher {
    SphericalDelaunay dt;
    const std::function<double(const Vec3 &)> &size_km;
    std::map<EdgeKey, SegmentKind> segments; // constrained boundary edges (ordered: deterministic)
    std::vector<std::pair<VertexId, VertexId>> directed; // each segment a->b with ocean on the left
    MesherReport &report;
    std::vector<char> sharp; // per vertex: a boundary corner with an ocean angle below 60 degrees
    std::vector<VertexId> pinched; // boundary vertices a closed strait left between fans of ocean
    std::vector<TriangleId> cut_sides; // ocean faces beside closings that cut the mesh in two
    // Ocean faces beside every strait closing (cut, join or pinch), until close_dead_ends.
    std::vector<TriangleId> strait_sides;

    bool is_sharp(VertexId v) const { return v < sharp.size() && sharp[v]; }
    std::vector<char> fixed; // per vertex: on a boundary segment (moved only by the slides)
    // Per vertex: the ring whose segments end there (no_ring: none; shared_ring: several).
    static constexpr std::uint32_t no_ring = 0xffffffffu, shared_ring = 0xfffffffeu;
    std::vector<std::uint32_t> ring_of;
    std::uint32_t current_ring = no_ring; // the ring recover() is working on
    // A part's (MesherOptions::whole_rings): per vertex, the whole boundary's ring of the
    // segment leaving it in the part's rings (no_whole_ring: a border's; not_given: a vertex the
    // rings did not give); empty for a whole boundary.
    static constexpr std::uint32_t not_given = 0xfffffffeu;
    std::vector<std::uint32_t> whole_ring_from;
    void set_ring(VertexId v) {
        if (v >= ring_of.size())
            ring_of.resize(v + 1, no_ring);
        ring_of[v] =
            ring_of[v] == no_ring || ring_of[v] == current_ring ? current_ring : shared_ring;
    }
    bool is_fixed(VertexId v) const { return v < fixed.size() && fixed[v]; }
    void mark_fixed(VertexId v) {
        if (v >= fixed.size())
            fixed.resize(v + 1, 0);
        fixed[v] = 1;
    }

    Mesher(SphericalDelaunay::Options o, const std::function<double(const Vec3 &)> &h,
           MesherReport &r)
        : dt(o), size_km(h), report(r) {}

    // Renumbers the triangulation (SphericalDelaunay::renumber) and everything here that names
    // its vertices or triangles; returns each old slot's new triangle.
    std::vector<TriangleId> renumber(const std::vector<VertexId> &new_of_old) {
        std::vector<TriangleId> new_of_slot = dt.renumber(new_of_old);
        renumber_per_vertex(sharp, new_of_old, char{0});
        renumber_per_vertex(fixed, new_of_old, char{0});
        renumber_per_vertex(ring_of, new_of_old, no_ring);
        if (!whole_ring_from.empty())
            renumber_per_vertex(whole_ring_from, new_of_old, not_given);
        std::map<EdgeKey, SegmentKind> renamed;
        for (const auto &[e, kind] : segments)
            renamed.emplace(key(new_of_old[e.first], new_of_old[e.second]), kind);
        segments.swap(renamed);
        for (auto &[a, b] : directed)
            a = new_of_old[a], b = new_of_old[b];
        for (VertexId &v : pinched)
            v = new_of_old[v];
        for (TriangleId &t : cut_sides)
            t = new_of_slot[t];
        for (TriangleId &t : strait_sides)
            t = new_of_slot[t];
        return new_of_slot;
    }

    Vec3 centroid(TriangleId t) const {
        return normalized(dt.point(dt.vertex(t, 0)) + dt.point(dt.vertex(t, 1)) +
                          dt.point(dt.vertex(t, 2)));
    }

    // Recovers segment a->b, splitting it at its midpoint where flips cannot.
    void recover(VertexId a, VertexId b, SegmentKind kind, int depth) {
        if (a == b)
            return;
        if (dt.insert_constraint(a, b)) {
            add_segment(a, b, kind);
            return;
        }
        if (depth > 30)
            throw DataError(
                "a boundary segment cannot be recovered: coastline rings cross or touch near " +
                describe(dt.point(a)));
        VertexId m = dt.insert(arc_midpoint(dt.point(a), dt.point(b)));
        ++report.segments_split;
        recover(a, m, kind, depth + 1);
        recover(m, b, kind, depth + 1);
    }

    // Splits the boundary segment `h` at its midpoint; returns the new vertex, or no_vertex when
    // the segment is shorter than twice refine_floor times h or the midpoint merged with an
    // existing vertex (the segment is then left whole).
    VertexId split_segment(HalfEdge h) {
        const VertexId a = dt.origin(h), b = dt.destination(h);
        const Vec3 mid = arc_midpoint(dt.point(a), dt.point(b));
        if (arc_angle(dt.point(a), dt.point(b)) < 2 * refine_floor * km_to_rad(size_km(mid)))
            return no_vertex;
        auto it = segments.find(key(a, b));
        const SegmentKind kind = it != segments.end() ? it->second : SegmentKind::coast;
        const std::size_t before = dt.vertex_count();
        const VertexId v = dt.split_edge(h, mid);
        if (v == a || v == b || dt.vertex_count() == before)
            return no_vertex;
        segments.erase(key(a, b));
        segments[key(a, v)] = kind;
        segments[key(v, b)] = kind;
        mark_fixed(v);
        return v;
    }

    /// Whether a-b (either way) is a segment of an open (region) boundary.
    bool is_open(VertexId a, VertexId b) const {
        const auto it = segments.find(key(a, b));
        return it != segments.end() && it->second == SegmentKind::open;
    }

    void add_segment(VertexId a, VertexId b, SegmentKind kind) {
        segments[key(a, b)] = kind;
        directed.emplace_back(a, b);
        mark_fixed(a);
        mark_fixed(b);
        set_ring(a);
        set_ring(b);
    }

    static std::string describe(const Vec3 &p) {
        LonLat ll = vec_to_lonlat(p);
        char buf[64];
        std::snprintf(buf, sizeof buf, "lon %.4f, lat %.4f", ll.lon, ll.lat);
        return buf;
    }

    // Walks from triangle t towards p. Returns the triangle holding p, or the last one before
    // the first constrained edge in the way; `blocked` is that edge or, when p lands in an ocean
    // triangle inside the diametral circle of one of its boundary segments (p encroaches on it,
    // Ruppert's rule), that segment; else no_half_edge.
    TriangleId walk_towards(TriangleId t, const Vec3 &p, HalfEdge &blocked) const {
        blocked = no_half_edge;
        for (std::size_t step = 0; step < 100000; ++step) {
            bool moved = false;
            for (int k = 0; k < 3; ++k) {
                const int i = (k + static_cast<int>(step % 3)) % 3;
                const Vec3 &u = dt.point(dt.vertex(t, next3(i)));
                const Vec3 &w = dt.point(dt.vertex(t, prev3(i)));
                if (predicates::orient(u, w, p) < 0) {
                    const HalfEdge h = half_edge(t, i);
                    if (dt.is_constrained(h)) {
                        blocked = h;
                    } else {
                        t = triangle_of(dt.twin(h));
                        moved = true;
                    }
                    break;
                }
            }
            if (!moved)
                break;
        }
        if (blocked == no_half_edge && dt.label(t) == ocean) {
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                if (!dt.is_constrained(h))
                    continue;
                if (dot(dt.point(dt.origin(h)) - p, dt.point(dt.destination(h)) - p) < 0) {
                    blocked = h;
                    break;
                }
            }
        }
        return t;
    }

    // For a boundary node that may slide along the coast (from: a half-edge leaving it): one
    // ring's node between two coast segments, neither it nor their other ends a sharp corner.
    // Fills `far` with its ocean triangles' far edges, `land_far` with its other triangles',
    // and `ends` with the segments' other ends; false (and nothing to rely on) otherwise.
    // With `exposed`, also a node that the removal of faces centred on land put on the boundary
    // (remove_land_faces; those edges constrained by then): an edge that is no segment counts
    // as coast, and a corner below 60 degrees as sharp.
    bool slide_star(HalfEdge from, std::vector<FarEdge> &far, std::vector<FarEdge> &land_far,
                    VertexId ends[2], bool exposed = false) const {
        const VertexId v = dt.origin(from);
        if (is_sharp(v))
            return false;
        if (!exposed && (v >= ring_of.size() || ring_of[v] >= shared_ring))
            return false;
        far.clear();
        land_far.clear();
        int constrained = 0;
        HalfEdge h = from;
        do {
            const TriangleId t = triangle_of(h);
            (dt.label(t) == ocean ? far : land_far)
                .emplace_back(dt.point(dt.destination(h)), dt.point(dt.vertex(t, edge_of(h))));
            if (dt.is_constrained(h)) {
                if (constrained < 2)
                    ends[constrained] = dt.destination(h);
                ++constrained;
            }
            h = dt.next_around_origin(h);
        } while (h != from && far.size() + land_far.size() < 64);
        if (h != from || constrained != 2 || far.empty())
            return false;
        for (int k = 0; k < 2; ++k) {
            auto it = segments.find(key(v, ends[k]));
            if (is_sharp(ends[k]))
                return false;
            if (it == segments.end() ? !exposed : it->second != SegmentKind::coast)
                return false;
        }
        if (exposed)
            for (VertexId u : {v, ends[0], ends[1]})
                if (ocean_angle(u, triangle_of(from)) < 60.0 * deg_to_rad)
                    return false;
        return true;
    }

    // The fans of ocean triangles around the origin of `from`: the runs of ocean triangles
    // between the others, counter-clockwise. visit(t, k) for each ocean triangle t of fan k
    // (from 0, in order around the vertex). Returns how many: 1 for an interior vertex (all its
    // triangles ocean), more where a removal left it between two fans of water.
    template <class Visit> int ocean_fans(HalfEdge from, Visit &&visit) const {
        auto in_ocean = [&](HalfEdge h) { return dt.label(triangle_of(h)) == ocean; };
        HalfEdge start = from;
        while (in_ocean(start)) {
            start = dt.next_around_origin(start);
            if (start != from)
                continue;
            do {
                visit(triangle_of(start), 0);
                start = dt.next_around_origin(start);
            } while (start != from);
            return 1;
        }
        int fans = 0;
        bool before = false;
        HalfEdge h = start;
        do {
            const bool in = in_ocean(h);
            if (in && !before)
                ++fans;
            if (in)
                visit(triangle_of(h), fans - 1);
            before = in;
            h = dt.next_around_origin(h);
        } while (h != start);
        return fans;
    }

    // The ocean angle at u (the sum of its ocean triangles' angles), from a triangle near it.
    double ocean_angle(VertexId u, TriangleId hint) const {
        const HalfEdge from = dt.leaving(u, hint);
        const Vec3 &p = dt.point(u);
        double angle = 0;
        HalfEdge h = from;
        do {
            const TriangleId t = triangle_of(h);
            if (dt.label(t) == ocean) {
                const Vec3 x = dt.point(dt.destination(h)) - p,
                           y = dt.point(dt.vertex(t, edge_of(h))) - p;
                angle += std::atan2(norm(cross(x, y)), dot(x, y));
            }
            h = dt.next_around_origin(h);
        } while (h != from);
        return angle;
    }

    // Moves the origin v of `from` to `to` when holds(t) is true of every ocean triangle t the
    // move and its flips leave around v and around the flips' corners (each once), then
    // finally() is true, and, with `ends` (a sliding boundary node's two coast neighbours), no
    // corner among v and the ends becomes sharper than 60 degrees. Otherwise nothing changes
    // (the core undoes the move). The stars scored before a move do not hold the triangles its
    // flips make: this looks at them. `touched` gets v's neighbours before the move, then the
    // flips' corners: every vertex whose star the move changed.
    template <class Holds, class Finally>
    bool move_if(HalfEdge from, const Vec3 &to, const VertexId *ends,
                 std::vector<VertexId> &touched, Holds &&holds, Finally &&finally) {
        const VertexId v = dt.origin(from);
        touched.clear();
        HalfEdge h = from;
        do {
            touched.push_back(dt.destination(h));
            h = dt.next_around_origin(h);
        } while (h != from);
        const std::size_t neighbours = touched.size();
        double angle_before[3] = {0, 0, 0};
        const VertexId corners[3] = {v, ends ? ends[0] : v, ends ? ends[1] : v};
        if (ends)
            for (int k = 0; k < 3; ++k)
                angle_before[k] = ocean_angle(corners[k], triangle_of(from));
        auto accept = [&] {
            // from's slot: next to v before the move, and near it after (flips reuse slots).
            const TriangleId near = triangle_of(from);
            seen_.clear();
            auto around = [&](VertexId u) {
                const HalfEdge first = dt.leaving(u, near);
                HalfEdge g = first;
                do {
                    const TriangleId t = triangle_of(g);
                    if (dt.label(t) == ocean &&
                        std::find(seen_.begin(), seen_.end(), t) == seen_.end()) {
                        seen_.push_back(t);
                        if (!holds(t))
                            return false;
                    }
                    g = dt.next_around_origin(g);
                } while (g != first);
                return true;
            };
            if (!around(v))
                return false;
            for (std::size_t i = neighbours; i < touched.size(); ++i)
                if (!around(touched[i]))
                    return false;
            if (ends)
                for (int k = 0; k < 3; ++k) {
                    const double after = ocean_angle(corners[k], near);
                    if (after < 60.0 * deg_to_rad && after < angle_before[k])
                        return false;
                }
            return finally();
        };
        return dt.move_vertex_from(from, to, &touched, accept);
    }
    std::vector<TriangleId> seen_; // move_if's scratch

    // The far edges b -> c of the star of from's origin (counter-clockwise around it, as
    // star_worst_quality takes them), into `far`; false when a triangle of the star is not
    // ocean or the star has more than 64.
    bool ocean_star(HalfEdge from, std::vector<FarEdge> &far) const {
        far.clear();
        HalfEdge h = from;
        do {
            if (dt.label(triangle_of(h)) != ocean)
                return false;
            far.emplace_back(dt.point(dt.destination(h)),
                             dt.point(dt.vertex(triangle_of(h), edge_of(h))));
            h = dt.next_around_origin(h);
        } while (h != from && far.size() < 64);
        return h == from;
    }

    // Circumcentre (unit vector) of a solid triangle.
    Vec3 circumcentre(TriangleId t) const {
        const Vec3 &a = dt.point(dt.vertex(t, 0));
        const Vec3 &b = dt.point(dt.vertex(t, 1));
        const Vec3 &c = dt.point(dt.vertex(t, 2));
        return normalized(cross(b - a, c - a));
    }
};

// The boundary loops (remove_land_faces), traced by its first call and kept up to date by its
// removals, so that a second call (close_straits) takes them as they are.
struct BoundaryLoops {
    std::unordered_map<VertexId, std::uint32_t> of; // the loop of each boundary vertex (an id)
    std::vector<std::uint32_t> parent;              // loops a removal joined share their root
    std::uint32_t count = 0;
    bool traced = false;
};

// whole_loops.cpp, for a part (MesherOptions::whole_rings): its rings' vertices noted with
// their whole rings after insert_boundary; the loops remove_land_faces traced (`starts`: where
// each begins in `edges`, its boundary half-edges in order) renumbered as the whole's, each
// stretch between borders taking one loop for the whole rings it runs along. A part's borders
// join its coasts into loops the whole ocean does not have: a removal touching two coasts would
// look like a cut of the ocean where it joins two of the whole's rings.
void note_whole_rings(Mesher &m, const Boundary &boundary, const std::vector<VertexId> &ids,
                      const std::vector<std::vector<std::uint32_t>> &whole_rings);
void loops_as_whole(const Mesher &m, const std::vector<HalfEdge> &edges,
                    const std::vector<std::size_t> &starts, BoundaryLoops &loops);

// The stages' entry points, in the order mesh_boundary (mesher.cpp) runs them, each in the file
// named.

// insert.cpp: the boundary rings' nodes triangulated (returns their vertices, ring after ring;
// none for an empty boundary, which starts from an octahedron), then each segment made an edge.
std::vector<VertexId> insert_boundary(Mesher &m, const Boundary &boundary);
void recover_segments(Mesher &m, const Boundary &boundary, const std::vector<VertexId> &ids);

// classify.cpp: the triangles labelled ocean (the largest component left of the segments,
// those beside a region's open segment, or all with keep_inland_seas) or land; narrow inlets
// closed; corners below 60 degrees marked sharp; the nodes estimated (refused past max_nodes or
// max_memory) and the triangulation reserved for them.
void classify_ocean(Mesher &m, const Boundary &boundary, const MesherOptions &options);
void close_inlets(Mesher &m, const MesherOptions &options, MesherReport &report);
// A chord across water this short against the inlet width closes by the inlet rule wherever it
// is (dead_ends.cpp); a coast segment as short loses an end where the coast moves little
// (close_nodes.cpp).
constexpr double short_chord = 0.5;
std::size_t merge_close_coast_nodes(Mesher &m, const MesherOptions &options);
void mark_sharp_corners(Mesher &m);
// reserve: size the triangulation for them (not for a triangulation only counted, parts.cpp).
// each: told where the nodes are (a piece's corners and its nodes; parts.cpp spreads them over
// the longitudes).
using NodesAt = std::function<void(const Vec3 &, const Vec3 &, const Vec3 &, double)>;
void estimate_nodes(Mesher &m, const MesherOptions &options, bool reserve = true,
                    const NodesAt &each = {});
void add_node_estimate(const std::function<double(const Vec3 &)> &size_km, const Vec3 &a,
                       const Vec3 &b, const Vec3 &c, double stop, double &sum,
                       const NodesAt &each = {});

// lattice.cpp: the open ocean filled with an icosahedral lattice; returns the nodes added.
// within (MesherOptions::lattice_within): where the ocean may lie, covering `share` of the sphere.
std::size_t fill_lattice(Mesher &m, double s_km, double max_points,
                         const std::vector<Vec3> &within = {}, double share = 1);

// refine.cpp: refinement until every ocean triangle fits the size field and the shape bounds.
void refine(Mesher &m, const Progress &progress);

// smooth.cpp: the smoothing sweeps and the relaxation towards valence 6 (report.valence_flips);
// returns per vertex whether it is a lattice node that has not moved (the quality rounds leave
// triangles of three such alone). lattice_first: the first of the report.lattice_nodes.
std::vector<char> smooth(Mesher &m, const MesherOptions &options, VertexId lattice_first,
                         const Progress &progress);
std::size_t relax_valence(Mesher &m, std::vector<char> &as_made, std::vector<std::uint8_t> &active);

// quality.cpp: the quality rounds after the smoothing: the nodes of the triangles below q 0.82
// move where their star has the most triangles above q 0.8 (boundary nodes slide near the coast
// when options.land is given), pattern searches raise the worst triangles, and triangles with
// two or three boundary corners are mended.
void improve_quality(Mesher &m, const MesherOptions &options, std::vector<char> &as_made);
/// Fills report.straits_closed_width_km from report.straits_closed_at (straits.cpp).
void measure_closed_straits(const SizeFn &size_km, const LandTest &land, MesherReport &report);
/// Fills report.straits_closed_place(s) from report.straits_closed_at (straits.cpp).
void group_closed_straits(const SizeFn &size_km, MesherReport &report);

/// The rings after close_inlets, with the inlets `crosses` picks cut out: each closing's chord
/// u -> v (ocean on its left; the segments it added to m.directed from `first`) whose inlet
/// (the source ring from u to v, and the chord) has a segment that `crosses` (a border's plane,
/// for mesh_parts) replaces the ring's nodes from u forward to v (inlet_rings.cpp). `ids`: each
/// ring node's vertex (insert_boundary), rings in order; a chord at a vertex two ring nodes
/// merged into, or not on one ring, is left out. With the corners of the mouths cut, sorted
/// (MesherOptions::mouth_corners), and the inlets' count and water.
struct InletCut {
    std::vector<Ring> rings;
    std::vector<std::array<double, 3>> mouths;
    std::size_t closed = 0; ///< the inlets cut
    double area_km2 = 0;    ///< their water
};
InletCut rings_with_inlets_closed(const Mesher &m, const Boundary &boundary,
                                  const std::vector<VertexId> &ids, std::size_t first,
                                  const std::function<bool(const Vec3 &, const Vec3 &)> &crosses);
// The same search for the free nodes of the faces below q 0.3 that the land and corner stages
// leave (their nodes moved or their neighbours removed after improve_quality). Returns whether
// no ocean face is left below it.
bool raise_quality_floor(Mesher &m, const MesherOptions &options, std::vector<char> &as_made);

// islands.cpp: face centroids moved off the islands the coast shaping dropped.
std::size_t clear_dropped_islands(Mesher &m, const Boundary &boundary, MesherReport &report,
                                  std::vector<TriangleId> &nearby);

// land.cpp: faces centred on land removed, or nudged off it.
std::size_t remove_land_faces(Mesher &m, const LandTest &land_test,
                              std::vector<TriangleId> island_faces, const MesherOptions &options,
                              MesherReport &report, std::vector<TriangleId> &left_faces,
                              BoundaryLoops &loops_state, bool straits = false);
std::size_t nudge_off_land(Mesher &m, const LandTest &land_test, const MesherOptions &options,
                           const std::vector<TriangleId> &faces, std::vector<TriangleId> &left,
                           std::vector<Vec3> &left_at);

// straits.cpp: straits narrower than a face closed; clear_land runs the land clean-up (with
// options.land): remove_land_faces, nudge_off_land, then close_straits and a second nudge.
void clear_land(Mesher &m, const MesherOptions &options, std::vector<TriangleId> island_faces);
// clear_land_after_splits: the faces around the nodes the corners' splits added (from
// `first_new` on) that are centred on land, removed or nudged as clear_land's.
void clear_land_after_splits(Mesher &m, const MesherOptions &options, VertexId first_new);
void close_straits(Mesher &m, const LandTest &land_test, std::vector<TriangleId> &faces,
                   const MesherOptions &options, BoundaryLoops &loops, MesherReport &report);
// pieces.cpp: whether a passage line (MesherOptions::passages) meets face t, and the small
// pieces beside closings (`sides`: faces beside them) closed by the inlet rule. `land_test`
// (may be null) counts the faces closed as land or water.
bool on_passage(const Mesher &m, const MesherOptions &options, TriangleId t);
void close_small_pieces(Mesher &m, const std::vector<TriangleId> &sides,
                        const MesherOptions &options, const LandTest *land_test,
                        MesherReport &report);
// The last of them, after every closing: the pieces beside the cuts and pinches
// (Mesher::cut_sides), where the inlet rule would close them.
void close_cut_off_pieces(Mesher &m, const MesherOptions &options, MesherReport &report);
// dead_ends.cpp: the dead ends the closings left (Mesher::strait_sides), closed by the inlet rule.
void close_dead_ends(Mesher &m, const MesherOptions &options, MesherReport &report);

// corners.cpp: the last step, the ocean faces below q 0.3 that the coast's sharp corners leave
// removed (counted in report.corners_blunted; closings across narrow water with the straits).
void blunt_sharp_corners(Mesher &m, const MesherOptions &options);

// output.cpp: the ocean triangles as a Mesh (nodes a closed strait pinched split, the seas it cut
// off, sharp corners and the target size per node in the report and the mesh). A part (borders:
// MesherOptions::lattice_within) reports only its cuts' points: its seas are measured on the
// joined mesh (mesh_parts' basins_cut_off).
Mesh to_mesh(Mesher &m, const std::vector<Vec3> &borders);
/// Takes off Mesher::pinched the nodes on one of `borders`' planes (a part's borders,
/// MesherOptions::lattice_within): the other part's faces may join their fans, and join_parts
/// splits those still pinched on the joined mesh.
void keep_border_nodes_whole(Mesher &m, const std::vector<Vec3> &borders);
/// The mesh's pieces over shared nodes: each node's root, and the root of the piece with the
/// most faces.
struct MeshPieces {
    std::vector<NodeIndex> root;
    NodeIndex largest;
};
MeshPieces mesh_pieces(const Mesh &mesh);
/// Appends to report.seas_cut_off the areas (km2, then sorted largest first) of the mesh's
/// pieces beside a cut (cut_nodes) but the largest: the basins closed straits cut off.
void seas_cut_off(const Mesh &mesh, const std::vector<NodeIndex> &cut_nodes, MesherReport &report);
/// The joined mesh's pieces (over shared nodes) but the largest, told as one part's are: each
/// that the inlet rule closes goes unless it touches an open boundary or a passage runs through
/// it (none with keep_inland_seas; counted in report.water_faces_removed and
/// straits_water_km2), and those left beside a cut (cut_nodes) are the basins closed straits
/// cut off (report.seas_cut_off). A part keeps its water against its border, where the next
/// part may close its side, and a pocket removed at a border may leave a face apart.
void close_joined_pieces(Mesh &mesh, const std::vector<NodeIndex> &cut_nodes, const SizeFn &size_km,
                         const MesherOptions &options, MesherReport &report);

} // namespace globemesh::mesher_internal
