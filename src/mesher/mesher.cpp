#include "globemesh/mesher.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "../delaunay/hilbert.hpp"
#include "corners.hpp"
#include "star_search.hpp"

namespace globemesh {

namespace {

// Refinement stops when every circumradius is below this factor times that of an equilateral
// triangle of side h: Delaunay refinement leaves most triangles well inside the bound, so a
// factor above 1 centres the edge lengths on h after smoothing (measured: see tests).
constexpr double circumradius_factor = 1.35;
// Frontal points make triangles of circumradius this factor times the refinement bound. It sets
// the median edge against h: on 1:50m land at 100 km, 0.8 gave 1.073 (edges 7% long), 0.75
// gives 1.012 (10% more nodes; q > 0.8 97.27 -> 97.58%), 0.7 gives 0.945. At an equal node
// count the quality is the same (circumradius_factor 1.5 with 0.7: 97.08%).
constexpr double frontal_radius_factor = 0.75;
// Largest circumradius of a frontal triangle relative to its front edge's length.
constexpr double front_growth = 1.0;
// Refinement splits triangles whose circumradius exceeds this factor times their shortest edge
// (sqrt(2): smallest angle 20.7 degrees, the bound for which Ruppert's algorithm terminates).
constexpr double shape_bound = 1.4142135623730951;
// Triangles with a boundary corner are split above this ratio instead (smallest angle 25.8
// degrees): smoothing moves at most two of their corners, and the coast's crowded places
// (straits, island groups) leave it little room. Measured on 1:50m land, faces below q 0.6
// away from sharp corners at 100 km / Gulf Stream field: sqrt(2) 9 / 12, 1.3 6 / 13, 1.2 2 / 2,
// 1.15 1 / 2, 1.1 4 / 2, 1.0 1 / 6 (with 2% more centroids on land and size fit 97.2%); q > 0.8
// 97.61 / 97.28% -> 97.62 / 97.34% at 1.15, 0.1% more nodes. (Below Ruppert's sqrt(2) the
// refinement still ends: shape stops counting below refine_floor.)
constexpr double coast_shape_bound = 1.15;
// Triangles with two or three boundary corners, which smoothing cannot move, are refined until
// their quality q (sphere.hpp) reaches this.
constexpr double quality_goal = 0.6;
// Shape stops counting below this fraction of the target circumradius, and boundary segments
// shorter than twice this fraction of h are not split: narrow rivers and the pinch points of
// the coast (rings moved 0.64 m apart where they touched) would otherwise be refined down to
// their own width. Measured on 1:50m land at 100 km: 0.5 leaves 247 faces below q 0.6 away
// from sharp corners, 0.05 leaves 84 for 1.8% more nodes.
constexpr double refine_floor = 0.05;
// The refinement pops the worst triangles first, their badness coarsened to this many levels per
// doubling; within a level, along the Hilbert curve. Consecutive insertions are then neighbours
// on the sphere and so are the new vertices' numbers, which keeps the refinement and the
// smoothing in cache. Measured on 1:50m land (mesh_boundary, bench/mesher_memory), exact order
// -> this: 20 km 8.0 -> 6.1 s, 10 km 37.3 -> 26.6 s (us/node x1.65 -> x1.20 from 64 to 10 km);
// at 100 km q > 0.8 97.29% -> 97.36%, mean q 0.9534 -> 0.9541 (4 levels: 0.9517, 16: 0.9536).
constexpr double badness_levels_per_doubling = 8;
// A smoothing move shorter than this fraction of h is not made, and the node is left out of the
// next sweep unless a neighbour moves. Measured on 1:50m land: at 20 km improve 2.93 -> 1.92 s
// (bench/mesher_memory); at 100 km q > 0.8 97.36 -> 97.34%, mean q 0.9541 -> 0.9538; Gulf
// Stream field 96.93 -> 96.93%, mean 0.9535 -> 0.9533 (0.02: improve 1.73 s, q > 0.8 97.33%).
constexpr double settle_fraction = 0.01;
// Then the nodes of triangles below this quality (away from sharp corners) get a pattern search
// for their star's best worst triangle, for this many rounds. Measured on 1:50m land at 100 km:
// faces below 0.6 away from sharp corners 38 -> 9, the worst 0.445 -> 0.535, faces below 0.8
// 2,070 -> 2,086; Gulf Stream field 46 -> 15, 0.469 -> 0.525 (4 rounds: the same).
constexpr double worst_goal = 0.6;
constexpr int search_rounds = 2;
constexpr int mend_passes = 3;
// Rounds of the last, quality-driven smoothing of the nodes of triangles below q count_cap.
// Measured on 1:50m land at 100 km, q > 0.8 with the count and the slides below: 99.61% after
// 4 rounds, 99.63% after 6 (with the star's worst as the goal and no slides, 3 rounds took the
// faces below q 0.8 away from the coast from 0.89% to 0.12%; 6 gained 0.02%).
constexpr int improve_rounds = 6;
// Those rounds move each node where its star has the most triangles above count_quality (the
// issue's q 0.8), ties broken by the sum of the qualities capped at count_cap, with no triangle
// below min(the star's worst, worst_goal) (star_count_score). Measured on 1:50m land at 100 km,
// q > 0.8 after 3 rounds without slides: the star's worst as the goal (before) 97.93%; the
// capped sum alone, cap 0.8 98.41%, 0.82 98.71%, 0.85 98.50%; the count and the capped sum,
// cap 0.82 98.85%, 0.85 98.81%, 0.9 98.71%.
// The nodes are those of the triangles below count_cap: a node whose triangles are all above it
// has the best score already and stays. Collected below q 0.9 before (session 28), 12,988 of
// the 22,111 visits at 64 km on 1:50m ended at once; below count_cap the improve stage took
// 0.95 -> 0.82 us per node there, and on 1:50m land at 100 km / the Gulf Stream field q > 0.8
// 99.54 / 99.53 -> 99.52 / 99.50%, mean q 0.9558 / 0.9590 -> 0.9559 / 0.9591, the worst away
// from sharp corners 0.600 both (collected below 0.8: 99.50 / 99.48%; below 0.7: 98.41 /
// 98.24%, with two faces below 0.6; no rounds at all: 97.24 / 97.11%).
constexpr double count_quality = 0.8;
constexpr double count_cap = 0.82;
constexpr double count_worst_weight = 1000; // the worst up to worst_goal comes first
constexpr detail::CountRule count_rule{worst_goal, count_quality, count_cap, count_worst_weight};
// In the same rounds a boundary node (not at a sharp corner, between two coast segments of one
// ring) slides where its ocean star scores best, to points within slide_reach times h of the
// source coast (LandTest::coast_within; the issue asks for h/4 at the 95th percentile), where
// no corner of the coast becomes sharper than 60 degrees and no more of its star's faces have
// their centroid on land. Measured on 1:50m land, 100 km / Gulf Stream field: q > 0.8
// 98.90 / 98.87% without slides, 99.61 / 99.57% with; boundary node to coast p95 0.233 / 0.223 h
// -> 0.227 / 0.212 h; face centroids on land 52 / 47 -> 48 / 39 (66 / 45 when slides may put
// more centroids on land). The coast and land rules checked only on the points the search
// improved through, from the best back, instead of on each: mesh_boundary at 64 km 2,339 ->
// 2,204 million instructions; after the nudge below, faces on land 19 / 14 -> 18 / 15, p95
// 0.227 / 0.212 -> 0.228 / 0.218 h, q > 0.8 99.54 / 99.49 -> 99.54 / 99.50%.
constexpr double slide_reach = 0.2;
// Relaxation towards valence 6 (relax_valence): passes of flips over the candidate triangles, a
// flip refused where either new triangle would be below q relax_floor; then rounds of moves to
// the mean of the neighbours, a move refused where the star's worst triangle would fall below
// min(relax_move_floor, where it was). Measured on 1:50m land at 100 km, the floor 0.6 instead
// of 0.8 for the moves: faces below 0.6 away from sharp corners 11 instead of 6 (the moves
// then still reached the coast's neighbours).
constexpr int relax_passes = 4;
constexpr int relax_rounds = 6;
constexpr double relax_floor = 0.3;
constexpr double relax_move_floor = 0.8;
// The icosahedral lattice (fill_lattice): n subdivisions of an icosahedron's edge give a median
// chord of lattice_edge_scale / n (its chords lie within [0.74, 1.09] of the median, its
// triangles' q above 0.88). A lattice node is kept where the size field reaches lattice_level
// times the lattice's size, and no boundary segment or other node lies within lattice_clearance
// times that size.
constexpr double lattice_edge_scale = 1.2185;
constexpr double lattice_level = 0.99;
constexpr double lattice_clearance = 1.5;
constexpr double lattice_jitter = 1e-6;
// Moving a free node to take a face's centroid off a dropped island (clear_dropped_islands):
// no face of its star may fall below min(its quality, this); the ways out tried are towards
// the nearest points of this many sides of the outline. Measured on 1:50m land at 100 km, faces
// moved / left on dropped islands: floor 0.8 with 1 way 110 / 251, 4 ways 116 / 244, 16 the
// same; floor 0.6 226 / 135 (q > 0.8 97.62 -> 97.40%), none 297 / 60 (97.13%, worst 0.04).
constexpr double island_quality_floor = 0.8;
constexpr std::size_t island_exits = 4;
// Removing the faces centred on land (remove_land_faces): a face that would pinch the mesh at
// a corner may take along at most this many water faces of that corner's fan (or the water it
// cuts off, up to inlet_area h^2); no removal leaves on the boundary a node farther than
// land_exposed_reach times h from the source coast. Measured on 1:50m land (faces centred on
// land / boundary node to coast p95 over h), 100 km, Gulf Stream field, 50 km: no removal
// 577 / 0.175, 521 / 0.181, 1,149 / 0.186; one face at a time, the loops kept apart and the
// coast distance from the nearest lon/lat point: reach 0.25: 263 / 0.183, 273 / 0.183,
// 592 / 0.191; 0.35: 191 / 0.200, 227 / 0.197, 457 / 0.206; 0.5: 129 / 0.221, 171 / 0.219,
// 275 / 0.232; no bound: 93 / 0.239, 145 / 0.229, 173 / 0.252 (over the issue's h/4). Fans of 1
// face instead of 2 (no bound): 98 and 146 left; of 3: the same as 2. With groups removed
// whole, loops joined and the coast distance on the sphere, reach 0.5: 50 / 0.228,
// 109 / 0.223, 124 / 0.240; a last round at 0.6: 35 / 0.237, 95 / 0.232, 72 / 0.250; at
// 0.75: 30 / 0.239, 91 / 0.234, 56 / 0.254.
constexpr std::size_t land_fan_faces = 2;
// The faces left on land then get a corner moved (nudge_off_land) towards the water nearest
// the centroid (the nudge_water nearest points of a grid of nudge_grid rows on the face), each
// of nudge_reaches times the way from the centroid (the centroid moves a third as far), where
// no triangle falls below min(its star's worst, nudge_floor). Measured on 1:50m land, faces
// left on land at 100 km / Gulf Stream field: no nudge 48 / 39; interior corners only, the 3
// nearest points at 3.3: 26 / 24 (q > 0.8 99.61 -> 99.53%), floor 0.7 35 / 32, 4 times 31 / 27,
// 5 times 34 / 29; boundary corners sliding too (slide_reach), 3.1: 21 / 15; the 8 nearest at
// 2, 3.1 and 4: 19 / 14 (q > 0.8 99.54 / 99.49%); a second pass: the same. (18 / 15 with the
// slides' lazy checks.) Nodes that the removals put on the boundary sliding too, within the
// land_exposed_reach that admitted them: 12 / 13 (99.52 / 99.50%); a grid of 24 rows or a
// reach of 1.5 as well: 12 / 12-13.
constexpr double nudge_reaches[3] = {2.0, 3.1, 4.0};
constexpr int nudge_grid = 12;
constexpr double nudge_floor = 0.6;
constexpr std::size_t nudge_water = 8;
constexpr double land_exposed_reach = 0.5;
// The faces still centred on land after the nudge lie across straits narrower than a face
// (close_straits). Closing one may cut the mesh in two (the sea behind becomes a basin of its
// own: the Black Sea behind the Dardanelles at 100 km; a piece under close_inlets' rule goes
// too: the rest of the strait, or a narrow sound behind it) or leave a node between two fans
// of water (the strait closed at a point: the output splits the node, pinch_apart radians
// into each fan); a node it puts on the boundary may lie up to strait_exposed_reach h from the
// coast. Measured on 1:50m land, faces left centred on land at 100 km: 12 before; cuts allowed
// 6; nodes between two fans too 2; the last two (Roosevelt Island and Kolguyev, dropped by the
// shaping, where a corner would come onto the boundary 0.5-0.75 h from their coast) with the
// reach 0.75: 0. Gulf Stream field 13 -> 0, 20 km 29 -> 0; boundary node to coast p95 at 100 km
// 0.228 -> 0.230 h.
constexpr double strait_exposed_reach = 0.75;
constexpr double pinch_apart = 1e-7; // 0.64 m
// A face centred on land whose removal would join two boundary loops goes only when at least
// this many of its 6 halfway points (remove_land_faces, land_points) are on land too.
constexpr int join_land_points = 3;
// Water behind a narrow mouth (close_inlets) larger than inlet_area h^2 closes too when it is
// narrow on average (a river, a chain of narrow lakes) and holds at most this many h^2.
constexpr double inlet_narrow_area = 25;
// The node estimate (add_node_estimate) splits a triangle larger than estimate_area times the
// square of the smallest size at its corners and centroid while those sizes differ by more than
// estimate_ratio or a side exceeds estimate_reach times the smallest. Measured on 1:50m land at
// --hmax 100km, estimate / nodes and the estimate's seconds: --coast-size 5km 1.113M / 0.958M,
// 0.2 s (area 2: 1.048M, 0.35 s; 16 with ratio 1.5: 1.174M, 0.16 s), 20km 217k / 193k; a
// refusal (10m) after 3.7 s (area 2: 8.1 s). Without the area bound the boundary's slivers split
// into ever more slivers (8.8M pieces for 1M nodes). The smallest size at the corners and
// centroid of each whole triangle, before: 80.7M for 2.6M nodes at --coast-size 2km, refused.
// A reach of 32 instead of 8 changes the estimates on bathymetry fields by under 0.5% (--slope
// 20: 6.17M for 5.52M nodes in 0.9 s) and costs a uniform 20 km field 3 ms instead of 16.
constexpr double estimate_area = 8;
constexpr double estimate_ratio = 1.25;
constexpr double estimate_reach = 32;
constexpr std::uint8_t land = 0;
constexpr std::uint8_t ocean = 1;
constexpr int next3(int i) { return i == 2 ? 0 : i + 1; }
constexpr int prev3(int i) { return i == 0 ? 2 : i - 1; }

using detail::FarEdge;
using detail::pattern_search;
using detail::Points8;
using detail::star_count_accepts;
using detail::star_count_best;
using detail::star_count_score;
using detail::star_worst_accepts;
using detail::star_worst_quality;

/// How many of the star triangles p, b, c (far edges b -> c) have their centroid on land.
int star_faces_on_land(const LandTest& land, const Vec3& p, const std::vector<FarEdge>& far) {
    int n = 0;
    for (const FarEdge& e : far) n += land.contains(normalized(p + e.b + e.c));
    return n;
}

/// True when moving the star's centre from `at` to `to` (far: its far edges) would bring the
/// star's worst triangle below `floor` and below where it was: the smoothing moves' refusal
/// test. The whole worst after the move is computed only when it falls below floor.
bool lowers_worst_below(const Vec3& to, const Vec3& at, const std::vector<FarEdge>& far, double floor) {
    if (star_worst_quality(to, far, std::nextafter(floor, 0.0)) >= floor) return false;
    return star_worst_quality(to, far) < star_worst_quality(at, far);
}

/// Adds to `sum` the nodes (nodes_for_area) the size field asks for over the spherical triangle
/// a, b, c: on pieces split in four at the arcs' midpoints until the size varies little over
/// each (estimate_ratio, estimate_reach), with each piece's 1/h^2 the mean of its corners' and
/// centroid's. A size of metres at the coast and hundreds of km offshore is counted as it grows,
/// not at its smallest over the whole triangle. Stops once `sum` passes `stop`.
void add_node_estimate(const std::function<double(const Vec3&)>& size_km, const Vec3& a, const Vec3& b,
                       const Vec3& c, double stop, double& sum) {
    struct Piece {
        Vec3 p[3];
        double h[3]; // radians
    };
    auto h_at = [&](const Vec3& p) { return km_to_rad(size_km(p)); };
    std::vector<Piece> stack{{{a, b, c}, {h_at(a), h_at(b), h_at(c)}}};
    while (!stack.empty() && sum <= stop) {
        const Piece q = stack.back();
        stack.pop_back();
        const double hc = h_at(normalized(q.p[0] + q.p[1] + q.p[2]));
        double lo = hc, hi = hc, inverse = 1 / (hc * hc), side = 0;
        for (int i = 0; i < 3; ++i) {
            lo = std::min(lo, q.h[i]);
            hi = std::max(hi, q.h[i]);
            inverse += 1 / (q.h[i] * q.h[i]);
            side = std::max(side, norm(q.p[next3(i)] - q.p[i]));
        }
        const double area = spherical_triangle_area(q.p[0], q.p[1], q.p[2]);
        if (area > estimate_area * lo * lo && (hi > estimate_ratio * lo || side > estimate_reach * lo)) {
            Vec3 mid[3];
            double hm[3];
            for (int i = 0; i < 3; ++i) {
                mid[i] = normalized(q.p[i] + q.p[next3(i)]); // on the side opposite corner prev3(i)
                hm[i] = h_at(mid[i]);
            }
            stack.push_back({{q.p[0], mid[0], mid[2]}, {q.h[0], hm[0], hm[2]}});
            stack.push_back({{mid[0], q.p[1], mid[1]}, {hm[0], q.h[1], hm[1]}});
            stack.push_back({{mid[2], mid[1], q.p[2]}, {hm[2], hm[1], q.h[2]}});
            stack.push_back({{mid[0], mid[1], mid[2]}, {hm[0], hm[1], hm[2]}});
            continue;
        }
        if (area > 0) sum += nodes_for_area(area, 1 / std::sqrt(inverse / 4));
    }
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

using EdgeKey = std::pair<VertexId, VertexId>;
EdgeKey key(VertexId a, VertexId b) { return a < b ? EdgeKey{a, b} : EdgeKey{b, a}; }

// Moves per_vertex[v] to new_of_old[v] (SphericalDelaunay::renumber's numbering); vertices past
// its end take `absent`.
template <class T>
void renumber_per_vertex(std::vector<T>& per_vertex, const std::vector<VertexId>& new_of_old, T absent) {
    std::vector<T> out(new_of_old.size(), absent);
    for (std::size_t v = 0; v < per_vertex.size(); ++v) out[new_of_old[v]] = per_vertex[v];
    per_vertex.swap(out);
}

// The state shared by the steps: the triangulation, the boundary segments with their kinds,
// the size field.
struct Mesher {
    SphericalDelaunay dt;
    const std::function<double(const Vec3&)>& size_km;
    std::map<EdgeKey, SegmentKind> segments; // constrained boundary edges (ordered: deterministic)
    std::vector<std::pair<VertexId, VertexId>> directed; // each segment a->b with ocean on the left
    MesherReport& report;
    std::vector<char> sharp; // per vertex: a boundary corner with an ocean angle below 60 degrees
    std::vector<VertexId> pinched; // boundary vertices a closed strait left between fans of ocean
    std::vector<TriangleId> cut_sides; // ocean faces beside closings that cut the mesh in two

    bool is_sharp(VertexId v) const { return v < sharp.size() && sharp[v]; }
    std::vector<char> fixed; // per vertex: on a boundary segment (moved only by the slides)
    // Per vertex: the ring whose segments end there (no_ring: none; shared_ring: several).
    static constexpr std::uint32_t no_ring = 0xffffffffu, shared_ring = 0xfffffffeu;
    std::vector<std::uint32_t> ring_of;
    std::uint32_t current_ring = no_ring; // the ring recover() is working on
    void set_ring(VertexId v) {
        if (v >= ring_of.size()) ring_of.resize(v + 1, no_ring);
        ring_of[v] = ring_of[v] == no_ring || ring_of[v] == current_ring ? current_ring : shared_ring;
    }
    bool is_fixed(VertexId v) const { return v < fixed.size() && fixed[v]; }
    void mark_fixed(VertexId v) {
        if (v >= fixed.size()) fixed.resize(v + 1, 0);
        fixed[v] = 1;
    }

    Mesher(SphericalDelaunay::Options o, const std::function<double(const Vec3&)>& h, MesherReport& r)
        : dt(o), size_km(h), report(r) {}

    // Renumbers the triangulation (SphericalDelaunay::renumber) and everything here that names
    // its vertices or triangles; returns each old slot's new triangle.
    std::vector<TriangleId> renumber(const std::vector<VertexId>& new_of_old) {
        std::vector<TriangleId> new_of_slot = dt.renumber(new_of_old);
        renumber_per_vertex(sharp, new_of_old, char{0});
        renumber_per_vertex(fixed, new_of_old, char{0});
        renumber_per_vertex(ring_of, new_of_old, no_ring);
        std::map<EdgeKey, SegmentKind> renamed;
        for (const auto& [e, kind] : segments) renamed.emplace(key(new_of_old[e.first], new_of_old[e.second]), kind);
        segments.swap(renamed);
        for (auto& [a, b] : directed) a = new_of_old[a], b = new_of_old[b];
        for (VertexId& v : pinched) v = new_of_old[v];
        for (TriangleId& t : cut_sides) t = new_of_slot[t];
        return new_of_slot;
    }

    Vec3 centroid(TriangleId t) const {
        return normalized(dt.point(dt.vertex(t, 0)) + dt.point(dt.vertex(t, 1)) + dt.point(dt.vertex(t, 2)));
    }

    // Recovers segment a->b, splitting it at its midpoint where flips cannot.
    void recover(VertexId a, VertexId b, SegmentKind kind, int depth) {
        if (a == b) return;
        if (dt.insert_constraint(a, b)) {
            add_segment(a, b, kind);
            return;
        }
        if (depth > 30)
            throw DataError("a boundary segment cannot be recovered: coastline rings cross or touch near " +
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
        if (arc_angle(dt.point(a), dt.point(b)) < 2 * refine_floor * km_to_rad(size_km(mid))) return no_vertex;
        auto it = segments.find(key(a, b));
        const SegmentKind kind = it != segments.end() ? it->second : SegmentKind::coast;
        const std::size_t before = dt.vertex_count();
        const VertexId v = dt.split_edge(h, mid);
        if (v == a || v == b || dt.vertex_count() == before) return no_vertex;
        segments.erase(key(a, b));
        segments[key(a, v)] = kind;
        segments[key(v, b)] = kind;
        mark_fixed(v);
        return v;
    }

    void add_segment(VertexId a, VertexId b, SegmentKind kind) {
        segments[key(a, b)] = kind;
        directed.emplace_back(a, b);
        mark_fixed(a);
        mark_fixed(b);
        set_ring(a);
        set_ring(b);
    }

    static std::string describe(const Vec3& p) {
        LonLat ll = vec_to_lonlat(p);
        char buf[64];
        std::snprintf(buf, sizeof buf, "lon %.4f, lat %.4f", ll.lon, ll.lat);
        return buf;
    }

    // Walks from triangle t towards p. Returns the triangle holding p, or the last one before
    // the first constrained edge in the way; `blocked` is that edge or, when p lands in an ocean
    // triangle inside the diametral circle of one of its boundary segments (p encroaches on it,
    // Ruppert's rule), that segment; else no_half_edge.
    TriangleId walk_towards(TriangleId t, const Vec3& p, HalfEdge& blocked) const {
        blocked = no_half_edge;
        for (std::size_t step = 0; step < 100000; ++step) {
            bool moved = false;
            for (int k = 0; k < 3; ++k) {
                const int i = (k + static_cast<int>(step % 3)) % 3;
                const Vec3& u = dt.point(dt.vertex(t, next3(i)));
                const Vec3& w = dt.point(dt.vertex(t, prev3(i)));
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
            if (!moved) break;
        }
        if (blocked == no_half_edge && dt.label(t) == ocean) {
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                if (!dt.is_constrained(h)) continue;
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
    bool slide_star(HalfEdge from, std::vector<FarEdge>& far, std::vector<FarEdge>& land_far,
                    VertexId ends[2], bool exposed = false) const {
        const VertexId v = dt.origin(from);
        if (is_sharp(v)) return false;
        if (!exposed && (v >= ring_of.size() || ring_of[v] >= shared_ring)) return false;
        far.clear();
        land_far.clear();
        int constrained = 0;
        HalfEdge h = from;
        do {
            const TriangleId t = triangle_of(h);
            (dt.label(t) == ocean ? far : land_far).emplace_back(dt.point(dt.destination(h)), dt.point(dt.vertex(t, edge_of(h))));
            if (dt.is_constrained(h)) {
                if (constrained < 2) ends[constrained] = dt.destination(h);
                ++constrained;
            }
            h = dt.next_around_origin(h);
        } while (h != from && far.size() + land_far.size() < 64);
        if (h != from || constrained != 2 || far.empty()) return false;
        for (int k = 0; k < 2; ++k) {
            auto it = segments.find(key(v, ends[k]));
            if (is_sharp(ends[k])) return false;
            if (it == segments.end() ? !exposed : it->second != SegmentKind::coast) return false;
        }
        if (exposed)
            for (VertexId u : {v, ends[0], ends[1]})
                if (ocean_angle(u, triangle_of(from)) < 60.0 * deg_to_rad) return false;
        return true;
    }

    // The fans of ocean triangles around the origin of `from`: the runs of ocean triangles
    // between the others, counter-clockwise. visit(t, k) for each ocean triangle t of fan k
    // (from 0, in order around the vertex). Returns how many: 1 for an interior vertex (all its
    // triangles ocean), more where a removal left it between two fans of water.
    template <class Visit>
    int ocean_fans(HalfEdge from, Visit&& visit) const {
        auto in_ocean = [&](HalfEdge h) { return dt.label(triangle_of(h)) == ocean; };
        HalfEdge start = from;
        while (in_ocean(start)) {
            start = dt.next_around_origin(start);
            if (start != from) continue;
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
            if (in && !before) ++fans;
            if (in) visit(triangle_of(h), fans - 1);
            before = in;
            h = dt.next_around_origin(h);
        } while (h != start);
        return fans;
    }

    // The ocean angle at u (the sum of its ocean triangles' angles), from a triangle near it.
    double ocean_angle(VertexId u, TriangleId hint) const {
        const HalfEdge from = dt.leaving(u, hint);
        const Vec3& p = dt.point(u);
        double angle = 0;
        HalfEdge h = from;
        do {
            const TriangleId t = triangle_of(h);
            if (dt.label(t) == ocean) {
                const Vec3 x = dt.point(dt.destination(h)) - p, y = dt.point(dt.vertex(t, edge_of(h))) - p;
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
    bool move_if(HalfEdge from, const Vec3& to, const VertexId* ends, std::vector<VertexId>& touched, Holds&& holds,
                 Finally&& finally) {
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
            for (int k = 0; k < 3; ++k) angle_before[k] = ocean_angle(corners[k], triangle_of(from));
        auto accept = [&] {
            // from's slot: next to v before the move, and near it after (flips reuse slots).
            const TriangleId near = triangle_of(from);
            seen_.clear();
            auto around = [&](VertexId u) {
                const HalfEdge first = dt.leaving(u, near);
                HalfEdge g = first;
                do {
                    const TriangleId t = triangle_of(g);
                    if (dt.label(t) == ocean && std::find(seen_.begin(), seen_.end(), t) == seen_.end()) {
                        seen_.push_back(t);
                        if (!holds(t)) return false;
                    }
                    g = dt.next_around_origin(g);
                } while (g != first);
                return true;
            };
            if (!around(v)) return false;
            for (std::size_t i = neighbours; i < touched.size(); ++i)
                if (!around(touched[i])) return false;
            if (ends)
                for (int k = 0; k < 3; ++k) {
                    const double after = ocean_angle(corners[k], near);
                    if (after < 60.0 * deg_to_rad && after < angle_before[k]) return false;
                }
            return finally();
        };
        return dt.move_vertex_from(from, to, &touched, accept);
    }
    std::vector<TriangleId> seen_; // move_if's scratch

    // The far edges b -> c of the star of from's origin (counter-clockwise around it, as
    // star_worst_quality takes them), into `far`; false when a triangle of the star is not
    // ocean or the star has more than 64.
    bool ocean_star(HalfEdge from, std::vector<FarEdge>& far) const {
        far.clear();
        HalfEdge h = from;
        do {
            if (dt.label(triangle_of(h)) != ocean) return false;
            far.emplace_back(dt.point(dt.destination(h)), dt.point(dt.vertex(triangle_of(h), edge_of(h))));
            h = dt.next_around_origin(h);
        } while (h != from && far.size() < 64);
        return h == from;
    }

    // Circumcentre (unit vector) of a solid triangle.
    Vec3 circumcentre(TriangleId t) const {
        const Vec3& a = dt.point(dt.vertex(t, 0));
        const Vec3& b = dt.point(dt.vertex(t, 1));
        const Vec3& c = dt.point(dt.vertex(t, 2));
        return normalized(cross(b - a, c - a));
    }

    // How much the triangle wants refining: > 1 means too large for the size field or too
    // skinny (radius-edge ratio above sqrt(2), i.e. a smallest angle below about 20.7 degrees).
    // Lengths are chords, not arcs: below 0.1 rad (637 km) they differ by under 0.05%, and a
    // chord needs no atan2 (this runs for every triangle the refinement creates).
    double badness(TriangleId t) const {
        const Vec3& a = dt.point(dt.vertex(t, 0));
        const Vec3& b = dt.point(dt.vertex(t, 1));
        const Vec3& d = dt.point(dt.vertex(t, 2));
        const double r = norm(circumcentre(t) - a);
        double h = km_to_rad(size_km(centroid(t)));
        double size_ratio = r / (circumradius_factor * h / std::sqrt(3.0));
        // A triangle at a sharp coast corner keeps the corner's small angle whatever is inserted:
        // only its size counts (Ruppert's algorithm needs input angles of 60 degrees or more).
        if (is_sharp(dt.vertex(t, 0)) || is_sharp(dt.vertex(t, 1)) || is_sharp(dt.vertex(t, 2)))
            return size_ratio;
        const Vec3 ab = b - a, bd = d - b, da = a - d;
        const double shortest = std::sqrt(std::min({dot(ab, ab), dot(bd, bd), dot(da, da)}));
        // Below a floor, shape does not count: pinch points of the coast (rings moved 0.64 m
        // apart where they touched) would otherwise be refined down to their own scale.
        // A triangle with a boundary corner is held to a tighter shape; one with two or three,
        // which smoothing cannot mend, is refined until its quality reaches quality_goal.
        const int corners = is_fixed(dt.vertex(t, 0)) + is_fixed(dt.vertex(t, 1)) + is_fixed(dt.vertex(t, 2));
        double shape_ratio = r / shortest / (corners > 0 ? coast_shape_bound : shape_bound);
        if (corners >= 2) shape_ratio = std::max(shape_ratio, quality_goal / std::max(1e-3, triangle_quality(a, b, d)));
        if (size_ratio < refine_floor) shape_ratio = 0;
        return std::max(size_ratio, shape_ratio);
    }
};

// A refinement candidate: 16 bytes. `order` is the badness level (badness_levels_per_doubling)
// above the Hilbert key of the triangle's centroid. `stamp` is the generation of slot t when it
// was queued (twice, plus 1 when the triangle was on the front); a slot's generation (24 bits)
// grows each time the core puts a new triangle in it, so an entry whose stamp no longer matches
// is stale.
struct Candidate {
    std::uint64_t order;
    TriangleId t;
    std::uint32_t stamp;
    bool active() const { return (stamp & 1u) != 0; } // next to an accepted triangle or the boundary
    bool operator<(const Candidate& o) const {
        if (active() != o.active()) return !active();
        if (order != o.order) return order < o.order;
        return t > o.t; // deterministic ties
    }
};

// Cache-line aligned storage for the heap below.
template <class T>
struct LineAllocator {
    using value_type = T;
    LineAllocator() = default;
    template <class U>
    LineAllocator(const LineAllocator<U>&) {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{64})); }
    void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t{64}); }
    template <class U>
    bool operator==(const LineAllocator<U>&) const { return true; }
};

// A max-heap of candidates with four children per node: half the depth of a binary heap, and
// the four children of a node (16 bytes each) fill one 64-byte cache line, so a sift-down
// touches one line per level. Node i lives at index i + 3, which puts the children 4i+1..4i+4
// at indices 4(i+1)..4(i+1)+3 of a 64-byte aligned array. Pops come in the order of
// Candidate::operator< (entries that compare equal are interchangeable: the same triangle,
// badness and front flag, so either identical or stale).
class CandidateHeap {
public:
    bool empty() const { return size() == 0; }
    std::size_t size() const { return a_.size() - pad; }
    void push(const Candidate& c) {
        a_.push_back(c);
        std::size_t i = size() - 1;
        while (i > 0) {
            const std::size_t parent = (i - 1) / 4;
            if (!(at(parent) < c)) break;
            at(i) = at(parent);
            i = parent;
        }
        at(i) = c;
    }
    Candidate pop() {
        const Candidate top = at(0);
        const Candidate last = a_.back();
        a_.pop_back();
        if (!empty()) sift_down(0, last);
        return top;
    }
    /// Drops the entries for which `drop` holds and restores the heap.
    template <class F>
    void remove_if(F drop) {
        std::erase_if(a_, [&](const Candidate& c) { return &c >= a_.data() + pad && drop(c); });
        for (std::size_t i = size() / 4 + 1; i-- > 0;)
            if (i < size()) sift_down(i, at(i));
    }
    void release() { std::vector<Candidate, LineAllocator<Candidate>>().swap(a_); }

private:
    static constexpr std::size_t pad = 3;
    Candidate& at(std::size_t i) { return a_[i + pad]; }
    void sift_down(std::size_t i, const Candidate c) { // c by value: it may be at(i)
        const std::size_t n = size();
        for (;;) {
            const std::size_t first = 4 * i + 1;
            if (first >= n) break;
            std::size_t best = first;
            const std::size_t end = std::min(first + 4, n);
            for (std::size_t k = first + 1; k < end; ++k)
                if (at(best) < at(k)) best = k;
            if (!(c < at(best))) break;
            at(i) = at(best);
            i = best;
        }
        at(i) = c;
    }
    std::vector<Candidate, LineAllocator<Candidate>> a_ = std::vector<Candidate, LineAllocator<Candidate>>(pad);
};

// Closes the inlets narrower than options.inlet_width times h, on the triangulation of the
// boundary nodes alone (before refinement, which would otherwise fill them with slivers). An
// unconstrained ocean edge a-b between two nodes of one ring cuts the ocean in two: the ring's
// arc from a to b and the edge close a curve. When a-b is shorter than inlet_width * h at its
// midpoint and one side holds at most inlet_area * h^2 of ocean, with no open (sea) boundary
// and no other ring (every ring stays a boundary loop), that side becomes land and a-b a coast
// segment. A dead-end channel narrower than the bound closes whole, a bit at a time; water
// behind a narrow mouth closes when it is small (a lagoon) or narrow on average too (twice its
// area over its perimeter under inlet_width * h: a river with lakes along it, up to
// inlet_narrow_area h^2), and stays when it is large and wide (the Black Sea behind the
// Bosphorus). Measured on 1:50m land, faces centred on land / q > 0.8, area alone -> with the
// mean width: 100 km 50 / 97.91% -> 48 / 97.92% (Maracaibo, Chesapeake Bay, the Gulf of Ob and
// the Lagoa dos Patos close); Gulf Stream field 109 / 97.79% -> 44 / 97.94% (the St. Lawrence
// above Quebec, 7.3 h^2, the White Sea, the Gulf of Finland, the Sea of Azov, Lake Melville).
void close_inlets(Mesher& m, const MesherOptions& options, MesherReport& report) {
    SphericalDelaunay& dt = m.dt;
    struct Chord {
        double length;
        double h; // the size at its midpoint, radians
        HalfEdge edge;
        VertexId a, b;
    };
    auto ring = [&](VertexId v) { return v < m.ring_of.size() ? m.ring_of[v] : Mesher::no_ring; };
    std::vector<Chord> chords;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            const VertexId a = dt.origin(h), b = dt.destination(h);
            // Each edge once (both its triangles are ocean: the flood fill crossed it).
            if (a > b || dt.is_constrained(h) || ring(a) >= Mesher::shared_ring || ring(a) != ring(b)) continue;
            const double length = arc_angle(dt.point(a), dt.point(b));
            const double size = km_to_rad(m.size_km(arc_midpoint(dt.point(a), dt.point(b))));
            if (length < options.inlet_width * size) chords.push_back({length, size, h, a, b});
        }
    }
    std::sort(chords.begin(), chords.end(), [](const Chord& x, const Chord& y) {
        if (x.length != y.length) return x.length > y.length;
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    std::vector<std::uint32_t> mark(dt.triangle_slots(), 0);
    std::uint32_t stamp = 0;
    // The ocean on one side of `cut` from `seed` (square radians), or -1 when it holds more than
    // `cap` and is wider on average than `width` (twice its area over its perimeter, cut
    // included, in radians), or holds more than `narrow_cap`, touches an open boundary or
    // another ring than `own`, or reaches `other` (the cut does not separate).
    auto flood = [&](TriangleId seed, HalfEdge cut, TriangleId other, std::uint32_t own, double cap,
                     double width, double narrow_cap, std::vector<TriangleId>& out) {
        ++stamp;
        out.assign(1, seed);
        mark[seed] = stamp;
        double area = 0;
        double perimeter = arc_angle(dt.point(dt.origin(cut)), dt.point(dt.destination(cut)));
        for (std::size_t k = 0; k < out.size(); ++k) {
            const TriangleId t = out[k];
            area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                            dt.point(dt.vertex(t, 2)));
            if (area > narrow_cap) return -1.0;
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(t, i);
                if (e == cut || e == dt.twin(cut)) continue;
                if (dt.is_constrained(e)) {
                    perimeter += arc_angle(dt.point(dt.origin(e)), dt.point(dt.destination(e)));
                    // Another ring inside (an island) would vanish with the inlet: keep it open.
                    if (ring(dt.origin(e)) != own || ring(dt.destination(e)) != own) return -1.0;
                    auto it = m.segments.find(key(dt.origin(e), dt.destination(e)));
                    if (it != m.segments.end() && it->second == SegmentKind::open) return -1.0;
                    continue;
                }
                const TriangleId nb = triangle_of(dt.twin(e));
                if (nb == other) return -1.0;
                if (mark[nb] == stamp || dt.label(nb) != ocean) continue;
                mark[nb] = stamp;
                out.push_back(nb);
            }
        }
        return area <= cap || 2 * area < width * perimeter ? area : -1.0;
    };
    // Passes until nothing closes: a closed tip makes the water behind the next edge out small
    // enough, so a dead-end channel narrower than the bound closes whole, whatever the order.
    std::vector<TriangleId> side[2];
    for (bool closed = true; closed;) {
        closed = false;
        for (const Chord& c : chords) {
            const TriangleId left = triangle_of(c.edge), right = triangle_of(dt.twin(c.edge));
            if (dt.label(left) != ocean || dt.label(right) != ocean) continue; // closed already
            const double cap = options.inlet_area * c.h * c.h, width = options.inlet_width * c.h;
            const double narrow_cap = inlet_narrow_area * c.h * c.h;
            const double area_left = flood(left, c.edge, right, ring(c.a), cap, width, narrow_cap, side[0]);
            const double area_right = flood(right, c.edge, left, ring(c.a), cap, width, narrow_cap, side[1]);
            if (area_left < 0 && area_right < 0) continue;
            const int s = area_right < 0 || (area_left >= 0 && area_left <= area_right) ? 0 : 1;
            for (TriangleId t : side[s]) dt.set_label(t, land);
            dt.set_constrained(c.edge, true);
            m.current_ring = m.ring_of[c.a];
            // The ocean stays on the segment's left.
            if (s == 0) m.add_segment(c.b, c.a, SegmentKind::coast);
            else m.add_segment(c.a, c.b, SegmentKind::coast);
            ++report.inlets_closed;
            report.inlet_area_km2 += (s == 0 ? area_left : area_right) * earth_radius_km * earth_radius_km;
            closed = true;
        }
    }
}

// Keeps face centroids off the islands the coast shaping dropped: a model that samples depth
// at face centres would otherwise put those faces on land. Each island is projected
// gnomonically from its centre (great-circle arcs become straight lines, so the inside test is
// exact for its arcs); a face whose centroid lies inside gets one free corner moved three times
// the way out of the centroid past the nearest point of the island's outline (the centroid
// moves a third as far), the corner whose star stays best, when no face of the star falls
// below min(its quality, 0.8) or gets its centroid onto the island. Returns the faces left
// with their centroid on a dropped island; the faces around each island (whose centroid is
// within its radius plus two edges) go to `nearby`.
std::size_t clear_dropped_islands(Mesher& m, const Boundary& boundary, MesherReport& report,
                                  std::vector<TriangleId>& nearby) {
    SphericalDelaunay& dt = m.dt;
    std::size_t left = 0;
    std::vector<double> px, py;
    std::vector<TriangleId> near, around, stack;
    std::vector<FarEdge> far;
    std::vector<std::array<double, 3>> exits; // distance, unit direction in the projection
    std::vector<Vec3> shifts;                 // the centroid's move for each way out
    std::vector<std::uint32_t> seen(dt.triangle_slots(), 0);
    std::uint32_t stamp = 0;
    TriangleId hint = no_triangle;
    for (const auto& island : boundary.dropped_islands) {
        Vec3 sum{0, 0, 0};
        for (const auto& v : island) sum = sum + v;
        if (norm(sum) == 0 || island.size() < 3) continue;
        const Vec3 c = normalized(sum);
        const Vec3 e1 = normalized(cross(c, std::abs(c.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 e2 = cross(c, e1);
        double radius = 0;
        for (const auto& v : island) radius = std::max(radius, arc_angle(c, v));
        if (radius > 0.5) continue; // not small: the projection would distort it
        auto project = [&](const Vec3& p, double& x, double& y) {
            const double w = dot(p, c);
            x = dot(p, e1) / w;
            y = dot(p, e2) / w;
        };
        px.resize(island.size());
        py.resize(island.size());
        for (std::size_t i = 0; i < island.size(); ++i) project(island[i], px[i], py[i]);
        auto inside = [&](const Vec3& p) {
            if (arc_angle(p, c) > radius) return false;
            double x, y;
            project(p, x, y);
            bool in = false;
            for (std::size_t i = 0, j = island.size() - 1; i < island.size(); j = i++)
                if ((py[i] > y) != (py[j] > y) && x < px[j] + (y - py[j]) * (px[i] - px[j]) / (py[i] - py[j])) in = !in;
            return in;
        };
        // The ocean faces near the island: from the one holding its centre, out to the faces
        // whose centroid is within `radius` plus two edges of the centre.
        const double reach = radius + 2 * km_to_rad(m.size_km(c));
        auto gather = [&] {
            near.clear();
            around.clear();
            hint = dt.locate(c, hint);
            if (hint == no_triangle || !dt.is_live(hint)) return;
            stack.assign(1, hint);
            seen[hint] = ++stamp;
            while (!stack.empty()) {
                const TriangleId t = stack.back();
                stack.pop_back();
                if (dt.label(t) == ocean) {
                    around.push_back(t);
                    if (inside(m.centroid(t))) near.push_back(t);
                }
                for (int i = 0; i < 3; ++i) {
                    const TriangleId nb = dt.neighbour(t, i);
                    if (nb == no_triangle || seen[nb] == stamp) continue;
                    seen[nb] = stamp;
                    if (arc_angle(m.centroid(nb), c) < reach) stack.push_back(nb);
                }
            }
        };
        gather();
        bool moved = false;
        for (const TriangleId t : near) {
            if (!dt.is_live(t) || dt.label(t) != ocean || !inside(m.centroid(t))) continue; // moved already
            // The ways out: from the centroid to the nearest point of each side of the outline,
            // and a little beyond (1% of h, which covers the checker's own outline between the
            // nodes); the nearest first, so that of equal stars the shortest move wins.
            const Vec3 g = m.centroid(t);
            double gx, gy;
            project(g, gx, gy);
            exits.clear();
            for (std::size_t i = 0, j = island.size() - 1; i < island.size(); j = i++) {
                const double dx = px[i] - px[j], dy = py[i] - py[j];
                const double l2 = dx * dx + dy * dy;
                const double f = l2 > 0 ? std::clamp(((gx - px[j]) * dx + (gy - py[j]) * dy) / l2, 0.0, 1.0) : 0.0;
                const double qx = px[j] + f * dx - gx, qy = py[j] + f * dy - gy;
                const double d = std::hypot(qx, qy);
                if (d > 0) exits.push_back({d, qx / d, qy / d});
            }
            std::sort(exits.begin(), exits.end(), [](const auto& a, const auto& b) { return a[0] < b[0]; });
            if (exits.size() > island_exits) exits.resize(island_exits);
            const double margin = 0.01 * km_to_rad(m.size_km(g));
            double best = -1;
            HalfEdge best_from = no_half_edge;
            Vec3 best_to{};
            shifts.clear();
            for (const auto& [d, ux, uy] : exits)
                shifts.push_back(normalized(c + (gx + (d + margin) * ux) * e1 + (gy + (d + margin) * uy) * e2) - g);
            for (int k = 0; k < 3; ++k) {
                const VertexId v = dt.vertex(t, k);
                if (m.is_fixed(v)) continue;
                const HalfEdge from = dt.leaving(v, t);
                if (from == no_half_edge || dt.origin(from) != v || !m.ocean_star(from, far)) continue;
                const Vec3& p0 = dt.point(v);
                for (const Vec3& shift : shifts) {
                    const Vec3 to = normalized(p0 + 3.0 * shift);
                    double worst = 1;
                    for (const FarEdge& e : far) {
                        const double q = triangle_quality(to, e.b, e.c, e.length);
                        if (predicates::orient(to, e) <= 0 || inside(normalized(to + e.b + e.c)) ||
                            q < std::min(island_quality_floor, triangle_quality(p0, e.b, e.c, e.length))) {
                            worst = -1;
                            break;
                        }
                        worst = std::min(worst, q);
                    }
                    if (worst > best) {
                        best = worst;
                        best_from = from;
                        best_to = to;
                    }
                }
            }
            if (best_from != no_half_edge && dt.move_vertex_from(best_from, best_to)) {
                ++report.island_centroids_moved;
                moved = true;
            }
        }
        // What is left (the flips after a move may make another such face): counted, not chased.
        // The faces around go to the land test, which reads the island at full resolution. With
        // no move the first gathering still holds.
        if (moved) gather();
        left += near.size();
        nearby.insert(nearby.end(), around.begin(), around.end());
    }
    return left;
}

// Removes the faces whose centroid lies on the source land (MesherOptions::land): under the
// capes the shaped coast cuts across, on the islands it dropped, and across water narrower than
// a face. A model that samples depth at face centres then meets no land there (ocean models
// cull such cells the same way). The faces looked at: those around the corners of the faces
// on the boundary and around those corners' neighbours, and `island_faces`. Each goes alone or
// in a small group, all or none, where the mesh stays one manifold (try_remove below): a hole
// opens where it touches no loop, loops join where it touches several, a group that would cut
// the mesh in two is refused, so a sea behind a strait stays connected. Passes repeat while
// faces go, since one gone may free the next. Returns the faces left on land (listed in
// `left_faces`); the faces removed, the holes opened and the loops joined go to `report`.
//
// With `straits` (close_straits), the faces looked at are `island_faces` alone, and a removal
// may also cut the mesh in two or leave a node between two fans of water (in Mesher::pinched;
// the output splits it); nodes it puts on the boundary may lie up to strait_exposed_reach h
// from the coast. The ocean faces beside each removal that cut the mesh go to `cut_sides`,
// and each removal that closed a strait (cut, joined or pinched) to report.straits_closed.
//
// `loops`: the boundary loops, traced by the first call and kept up to date by its removals
// (the nudge between the calls moves nodes but changes no boundary edge), so that the second
// call takes them as they are.
struct BoundaryLoops {
    std::unordered_map<VertexId, std::uint32_t> of; // the loop of each boundary vertex (an id)
    std::vector<std::uint32_t> parent;              // loops a removal joined share their root
    std::uint32_t count = 0;
    bool traced = false;
};
std::size_t remove_land_faces(Mesher& m, const LandTest& land_test, std::vector<TriangleId> island_faces,
                              double pocket_area, MesherReport& report, std::vector<TriangleId>& left_faces,
                              BoundaryLoops& loops_state, bool straits = false,
                              std::vector<TriangleId>* cut_sides = nullptr) {
    SphericalDelaunay& dt = m.dt;
    auto is_ocean = [&](TriangleId t) { return dt.is_live(t) && dt.label(t) == ocean; };
    // The next half-edge leaving origin(h) clockwise around it (next_around_origin's reverse):
    // the edge after h's twin in the twin's triangle.
    auto clockwise_around_origin = [&](HalfEdge h) {
        const HalfEdge back = dt.twin(h);
        return half_edge(triangle_of(back), next3(edge_of(back)));
    };
    // The boundary: each boundary half-edge's origin -> destination (one per boundary vertex in
    // a manifold), and the loop of each boundary vertex (an id: only equality counts, through
    // loop_root: loops that a removal joins share their root). Every edge between ocean and
    // land is a segment: each loop is found from its first segment not yet seen and traced
    // around its vertices, so that the step costs what the coast has, not what the ocean has.
    std::unordered_map<VertexId, VertexId> next_on_boundary;
    auto& loop_of = loops_state.of;
    auto& loop_parent = loops_state.parent;
    std::uint32_t& loops = loops_state.count;
    std::vector<HalfEdge> boundary_edges; // ocean on the left
    if (!loops_state.traced) {
        loops_state.traced = true;
        // The boundary half-edge after h (ocean on the left of both): clockwise around h's
        // destination, through the ocean, from the edge of h's triangle that leaves it.
        auto next_on_loop = [&](HalfEdge h) {
            HalfEdge g = half_edge(triangle_of(h), next3(edge_of(h)));
            for (int turns = 0; is_ocean(triangle_of(dt.twin(g))) && turns < 1000; ++turns) g = clockwise_around_origin(g);
            return g;
        };
        auto seen = [&](VertexId a, VertexId b) {
            auto it = next_on_boundary.find(a);
            return it != next_on_boundary.end() && it->second == b;
        };
        TriangleId hint = no_triangle;
        for (const auto& [segment, kind] : m.segments) {
            const auto [a, b] = segment;
            if (seen(a, b) || seen(b, a)) continue;
            const HalfEdge from = dt.leaving(a, hint);
            const HalfEdge e = from == no_half_edge ? no_half_edge : dt.find_edge(from, b);
            if (e == no_half_edge) continue;
            hint = triangle_of(e);
            for (const HalfEdge start : {e, dt.twin(e)}) {
                if (!is_ocean(triangle_of(start)) || is_ocean(triangle_of(dt.twin(start)))) continue;
                HalfEdge h = start;
                do {
                    next_on_boundary.emplace(dt.origin(h), dt.destination(h));
                    loop_of.emplace(dt.origin(h), loops);
                    boundary_edges.push_back(h);
                    h = next_on_loop(h);
                } while (h != start && boundary_edges.size() <= m.segments.size());
                loop_parent.push_back(loops++);
            }
        }
    }
    // The faces looked at: the ocean faces around the corners of the faces on the boundary
    // (near 1) and around those corners' neighbours (near 2).
    std::vector<char> near(dt.vertex_count(), 0);
    std::vector<std::pair<VertexId, HalfEdge>> near_list; // each once, with a half-edge leaving it
    auto mark = [&](TriangleId t, char bit) {
        for (int k = 0; k < 3; ++k) {
            const VertexId v = dt.vertex(t, k);
            if (!near[v]) near_list.emplace_back(v, half_edge(t, prev3(k)));
            near[v] |= bit;
        }
    };
    auto for_star = [&](HalfEdge from, auto&& visit) {
        HalfEdge h = from;
        do {
            if (is_ocean(triangle_of(h))) visit(triangle_of(h));
            h = dt.next_around_origin(h);
        } while (h != from);
    };
    std::vector<TriangleId> faces, candidates;
    if (!straits) {
        for (const HalfEdge h : boundary_edges) mark(triangle_of(h), 1);
        const std::size_t first_ring = near_list.size();
        for (std::size_t i = 0; i < first_ring; ++i) for_star(near_list[i].second, [&](TriangleId t) { mark(t, 2); });
        for (const auto& [v, from] : near_list) for_star(from, [&](TriangleId t) { candidates.push_back(t); });
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    for (TriangleId t : candidates)
        if (land_test.contains(m.centroid(t))) faces.push_back(t);
    std::vector<char>().swap(near);
    // The faces around dropped islands not tested already (the islands' lists overlap).
    std::sort(island_faces.begin(), island_faces.end());
    island_faces.erase(std::unique(island_faces.begin(), island_faces.end()), island_faces.end());
    for (TriangleId t : island_faces)
        if (is_ocean(t) && !std::binary_search(candidates.begin(), candidates.end(), t) && land_test.contains(m.centroid(t)))
            faces.push_back(t);
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    if (faces.empty()) return 0;

    auto loop_root = [&](std::uint32_t l) {
        while (loop_parent[l] != l) l = loop_parent[l];
        return l;
    };
    // The fans of ocean faces that meet at the origin of `from` (an interior vertex has one).
    auto fans_at = [&](HalfEdge from) { return m.ocean_fans(from, [](TriangleId, int) {}); };
    // Land under the face at the points halfway from its centroid to its corners and to its
    // sides' midpoints (of 6).
    auto land_points = [&](TriangleId t) {
        const Vec3 c = m.centroid(t);
        int on_land = 0;
        for (int k = 0; k < 3; ++k) {
            const Vec3& a = dt.point(dt.vertex(t, k));
            const Vec3& b = dt.point(dt.vertex(t, next3(k)));
            on_land += land_test.contains(normalized(c + a));
            on_land += land_test.contains(normalized(c + normalized(a + b)));
        }
        return on_land;
    };
    // Removes the faces of `group` still in the ocean, which hold `needed`, all or none. They may
    // go when the mesh stays a manifold and none of it is cut off: at each of their corners the
    // faces left form at most one fan (an interior corner keeps one), and the arcs along which
    // they touch the boundary lie on different loops. By Euler's formula, removing a disc that
    // touches the boundary in c arcs on c different loops joins those loops into one (c = 0
    // opens a hole: a dropped island comes back; c = 1 bites into the coast) and never
    // disconnects the mesh; two arcs on one loop would cut it in two. A removal that joins loops
    // closes narrow water between two rings: only where most of `needed` is land
    // (join_land_points), not because an islet lies under its centroid in open water. Every
    // corner that comes onto the boundary must lie within land_exposed_reach h of the coast.
    std::vector<TriangleId> members;
    std::vector<std::pair<VertexId, HalfEdge>> corners; // each corner with a half-edge leaving it
    std::vector<VertexId> arc_parent;                     // union-find over corner indices
    std::vector<VertexId> pinches;                        // corners left between two fans of water
    std::size_t holes = 0, joins = 0, removed_faces = 0;
    auto try_remove = [&](const std::vector<TriangleId>& group, TriangleId needed) {
        if (!is_ocean(needed)) return false;
        members.clear();
        for (TriangleId t : group)
            if (is_ocean(t)) members.push_back(t);
        std::sort(members.begin(), members.end());
        members.erase(std::unique(members.begin(), members.end()), members.end());
        corners.clear();
        for (TriangleId t : members)
            for (int k = 0; k < 3; ++k) corners.emplace_back(dt.vertex(t, k), half_edge(t, prev3(k)));
        std::sort(corners.begin(), corners.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        corners.erase(std::unique(corners.begin(), corners.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
                      corners.end());
        auto index_of = [&](VertexId v) {
            return static_cast<VertexId>(
                std::lower_bound(corners.begin(), corners.end(), v, [](const auto& c, VertexId x) { return c.first < x; }) - corners.begin());
        };
        auto arc_root = [&](VertexId i) {
            while (arc_parent[i] != i) i = arc_parent[i];
            return i;
        };
        // The contact arcs: the corners on the boundary, joined by the members' boundary edges.
        arc_parent.resize(corners.size());
        for (VertexId i = 0; i < corners.size(); ++i) arc_parent[i] = i;
        for (TriangleId t : members)
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                if (!is_ocean(triangle_of(dt.twin(h)))) arc_parent[arc_root(index_of(dt.origin(h)))] = arc_root(index_of(dt.destination(h)));
            }
        std::vector<std::uint32_t> arc_loops; // one per loop touched
        bool cuts = false;                    // two contact arcs on one loop
        for (VertexId i = 0; i < corners.size(); ++i) {
            auto it = loop_of.find(corners[i].first);
            if (it == loop_of.end() || arc_root(i) != i) continue;
            const std::uint32_t root = loop_root(it->second);
            if (std::find(arc_loops.begin(), arc_loops.end(), root) != arc_loops.end()) {
                if (!straits) return false; // would cut the mesh
                cuts = true;
                continue;
            }
            arc_loops.push_back(root);
        }
        if ((arc_loops.size() > 1 || cuts) && land_points(needed) < join_land_points) return false;
        for (TriangleId t : members) dt.set_label(t, land);
        bool ok = true;
        const double reach = straits ? strait_exposed_reach : land_exposed_reach;
        pinches.clear();
        for (const auto& [v, from] : corners) {
            const int fans = fans_at(from);
            const bool was_on_boundary = loop_of.count(v) > 0;
            if (fans > 1) pinches.push_back(v);
            if ((fans > 1 && !(straits && was_on_boundary)) || (!was_on_boundary && fans == 0)) ok = false;
            else if (!was_on_boundary && !land_test.coast_within(dt.point(v), reach * km_to_rad(m.size_km(dt.point(v)))))
                ok = false;
            if (!ok) break;
        }
        if (!ok) {
            for (TriangleId t : members) dt.set_label(t, ocean);
            return false;
        }
        std::uint32_t loop;
        if (arc_loops.empty()) {
            loop = loops++;
            loop_parent.push_back(loop);
            ++holes;
        } else {
            loop = arc_loops[0];
            for (std::size_t i = 1; i < arc_loops.size(); ++i) loop_parent[arc_loops[i]] = loop;
            joins += arc_loops.size() - 1;
        }
        for (const auto& c : corners) loop_of.emplace(c.first, loop);
        if (straits) {
            // A strait closed: the removal cut the mesh, joined loops or pinched it at a node
            // (not an island coming back as a hole, or a bite into one coast).
            m.pinched.insert(m.pinched.end(), pinches.begin(), pinches.end());
            if (cuts || !pinches.empty() || arc_loops.size() > 1) {
                ++report.straits_closed;
                report.straits_closed_at.push_back(m.centroid(needed));
            }
        }
        if (cuts && cut_sides)
            for (TriangleId t : members)
                for (int i = 0; i < 3; ++i)
                    if (is_ocean(dt.neighbour(t, i))) cut_sides->push_back(dt.neighbour(t, i));
        removed_faces += members.size();
        return true;
    };
    // A face alone, else with water faces beside it, where alone it would pinch the mesh at a
    // corner or join two loops only through a corner:
    // - a pocket: the ocean the face cuts off (a bay behind it, whose mouth is mostly land),
    //   when its faces centred off land hold at most inlet_area h^2 (the inlet rule of
    //   close_inlets): a river narrower than its faces goes, a sea behind a strait stays;
    // - else the fan of water faces between it and the boundary on the shorter side of a
    //   corner, when at most land_fan_faces.
    std::vector<TriangleId> group, stack;
    std::vector<std::uint32_t> seen_at(dt.triangle_slots(), 0);
    std::uint32_t stamp = 0;
    auto remove_face = [&](TriangleId t) {
        group.assign(1, t);
        if (try_remove(group, t)) return true;
        const double h = km_to_rad(m.size_km(m.centroid(t)));
        bool done = false;
        for (int i = 0; i < 3 && !done; ++i) {
            const TriangleId n = dt.neighbour(t, i);
            if (!is_ocean(n)) continue;
            group.assign(1, t);
            stack.assign(1, n);
            seen_at[t] = seen_at[n] = ++stamp;
            double area = 0;
            bool closed = true;
            while (!stack.empty() && closed) {
                const TriangleId u = stack.back();
                stack.pop_back();
                group.push_back(u);
                if (!land_test.contains(m.centroid(u)))
                    area += spherical_triangle_area(dt.point(dt.vertex(u, 0)), dt.point(dt.vertex(u, 1)), dt.point(dt.vertex(u, 2)));
                if (area > pocket_area * h * h) closed = false;
                for (int j = 0; j < 3; ++j) {
                    const TriangleId w = dt.neighbour(u, j);
                    if (is_ocean(w) && seen_at[w] != stamp) {
                        seen_at[w] = stamp;
                        stack.push_back(w);
                    }
                }
            }
            if (closed) done = try_remove(group, t);
        }
        for (int k = 0; k < 3 && !done; ++k) {
            // The faces around corner k from t each way to the first face not in the ocean.
            std::vector<TriangleId> sides[2];
            for (int side = 0; side < 2; ++side) {
                const HalfEdge from = half_edge(t, prev3(k)); // leaves vertex k
                HalfEdge h2 = from;
                while (sides[side].size() <= land_fan_faces) {
                    h2 = side == 0 ? dt.next_around_origin(h2) : clockwise_around_origin(h2);
                    if (!is_ocean(triangle_of(h2)) || triangle_of(h2) == t) break;
                    sides[side].push_back(triangle_of(h2));
                }
            }
            auto& fan = sides[0].size() <= sides[1].size() ? sides[0] : sides[1];
            if (fan.empty() || fan.size() > land_fan_faces) continue;
            group.assign(1, t);
            group.insert(group.end(), fan.begin(), fan.end());
            done = try_remove(group, t);
        }
        return done;
    };
    // Passes until none goes: one face gone may free the next.
    for (bool removed = true; removed;) {
        removed = false;
        for (TriangleId t : faces)
            if (is_ocean(t) && remove_face(t)) removed = true;
    }
    std::size_t left = 0;
    left_faces.clear();
    for (TriangleId t : faces)
        if (is_ocean(t)) {
            ++left;
            left_faces.push_back(t);
        }
    report.land_holes += holes;
    report.land_loops_joined += joins;
    report.land_faces_removed += faces.size() - left;
    report.water_faces_removed += removed_faces - (faces.size() - left);
    return left;
}

// Moves the faces still centred on land (`faces`, from remove_land_faces: in straits kept
// open, or where a removal would pinch the mesh or leave a node far from the coast) off it
// where one corner can take them: an interior corner, or a boundary corner that may slide
// (Mesher::slide_star, within slide_reach h of the coast), goes nudge_reaches times the way
// from the centroid to one of the nudge_water points of the face nearest it that lie in the
// water (a triangular grid of nudge_grid rows), the first that works. A move is kept when,
// on the triangles around the corner and its flips' corners (Mesher::move_if), no triangle
// falls below min(the star's worst, nudge_floor) and fewer faces are centred on land than in
// the corner's star before. The edges between ocean and land are constrained first, so that
// no flip crosses the boundary the removals made. Returns how many fewer faces are centred
// on land; `left` and `left_at` get those still on land and their centroids.
std::size_t nudge_off_land(Mesher& m, const LandTest& land_test, const std::vector<TriangleId>& faces,
                           std::vector<TriangleId>& left, std::vector<Vec3>& left_at) {
    SphericalDelaunay& dt = m.dt;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        for (int i = 0; i < 3; ++i)
            if (dt.label(dt.neighbour(t, i)) != ocean) dt.set_constrained(half_edge(t, i), true);
    }
    auto quality_of = [&](TriangleId t) {
        return triangle_quality(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)), dt.point(dt.vertex(t, 2)));
    };
    std::vector<FarEdge> far, land_far;
    std::vector<VertexId> touched;
    std::vector<std::pair<double, Vec3>> water;
    // The corners of the faces and every vertex a move changed the star of: the faces centred
    // on land at the end all lie around them.
    std::vector<std::pair<VertexId, TriangleId>> around; // each with a triangle near it
    for (const TriangleId t : faces)
        if (dt.is_live(t))
            for (int k = 0; k < 3; ++k) around.emplace_back(dt.vertex(t, k), t);
    std::size_t fewer = 0;
    for (const TriangleId t : faces) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        const Vec3 c = m.centroid(t);
        if (!land_test.contains(c)) continue; // an earlier move took it off
        // The water of the face, nearest the centroid first.
        const Vec3 a = dt.point(dt.vertex(t, 0)), b = dt.point(dt.vertex(t, 1)), d = dt.point(dt.vertex(t, 2));
        water.clear();
        for (int i = 0; i <= nudge_grid; ++i)
            for (int j = 0; i + j <= nudge_grid; ++j) {
                const Vec3 p = normalized(double(i) * a + double(j) * b + double(nudge_grid - i - j) * d);
                if (!land_test.contains(p)) water.emplace_back(norm(p - c), p);
            }
        std::sort(water.begin(), water.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        if (water.size() > nudge_water) water.resize(nudge_water);
        bool done = false;
        for (int k = 0; k < 3 && !done; ++k) {
            const VertexId v = dt.vertex(t, k);
            const HalfEdge from = half_edge(t, prev3(k)); // leaves v
            // A boundary node slides as in the quality rounds (Mesher::slide_star, slide_reach);
            // one the removals put on the boundary within the reach they allowed it.
            VertexId ends[2];
            const bool slide = !m.ocean_star(from, far);
            if (slide && !m.slide_star(from, far, land_far, ends, true)) continue;
            const Vec3 p0 = dt.point(v);
            const double reach = (m.is_fixed(v) ? slide_reach : land_exposed_reach) * km_to_rad(m.size_km(p0));
            const int land_before = star_faces_on_land(land_test, p0, far);
            const double floor = std::min(star_worst_quality(p0, far), nudge_floor);
            auto try_move = [&](const Vec3& to) {
                if (star_worst_quality(to, far, floor) < floor) return false;
                if (slide) {
                    for (const FarEdge& e : land_far)
                        if (predicates::orient(to, e) <= 0) return false;
                    if (!land_test.coast_within(to, reach)) return false;
                }
                // The ocean triangles near v after the move: each at or above floor, fewer centred
                // on land than v's star before.
                int land_after = 0;
                auto holds = [&](TriangleId s) {
                    land_after += land_test.contains(m.centroid(s));
                    return quality_of(s) >= floor;
                };
                if (!m.move_if(from, to, slide ? ends : nullptr, touched, holds, [&] { return land_after < land_before; }))
                    return false;
                fewer += static_cast<std::size_t>(land_before - land_after);
                for (const VertexId u : touched) around.emplace_back(u, triangle_of(from));
                return true;
            };
            for (const auto& [dist, w] : water)
                for (const double reach_factor : nudge_reaches)
                    if (!done) done = try_move(normalized(p0 + reach_factor * (w - c)));
        }
    }
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                 around.end());
    std::vector<TriangleId> on;
    for (const auto& [u, near] : around) {
        const HalfEdge first = dt.leaving(u, near);
        HalfEdge h = first;
        do {
            const TriangleId t = triangle_of(h);
            if (dt.label(t) == ocean && land_test.contains(m.centroid(t))) on.push_back(t);
            h = dt.next_around_origin(h);
        } while (h != first);
    }
    std::sort(on.begin(), on.end());
    on.erase(std::unique(on.begin(), on.end()), on.end());
    left_at.clear();
    for (const TriangleId t : on) left_at.push_back(m.centroid(t));
    left = std::move(on);
    return fewer;
}

// Closes the straits narrower than a face that `faces` (those still centred on land after the
// nudge) lie across (MesherOptions::close_straits): remove_land_faces with `straits`. Of the
// pieces a closing cut the mesh into, the largest stays; the others go under close_inlets'
// rule (at most inlet_area h^2 of water, or narrow on average and at most inlet_narrow_area
// h^2: the rest of the strait, a narrow sound behind it) unless they touch an open boundary,
// and stay otherwise as basins of their own (report.seas_cut_off). Leaves in `faces` those
// still on land.
void close_straits(Mesher& m, const LandTest& land_test, std::vector<TriangleId>& faces, const MesherOptions& options,
                   BoundaryLoops& loops, MesherReport& report) {
    SphericalDelaunay& dt = m.dt;
    auto is_ocean = [&](TriangleId t) { return dt.is_live(t) && dt.label(t) == ocean; };
    std::vector<TriangleId> sides, left;
    remove_land_faces(m, land_test, faces, options.inlet_area, report, left, loops, true, &sides);
    // The pieces beside the cuts, each flooded until whole or over inlet_narrow_area h^2 (then
    // it stays whatever it is: the ocean, or a sea cut off). Floods that meet are one piece
    // (union-find over the floods).
    struct Flood {
        std::vector<TriangleId> faces; // visited; those before `next` counted in the root's sums
        std::size_t next = 0;
        std::uint32_t parent;
        double area = 0, perimeter = 0; // the piece's, at its root (radians)
        bool open = false;              // the piece touches an open (sea) boundary
    };
    std::vector<Flood> floods;
    std::unordered_map<TriangleId, std::uint32_t> piece;
    auto root = [&](std::uint32_t f) {
        while (floods[f].parent != f) f = floods[f].parent = floods[floods[f].parent].parent;
        return f;
    };
    for (const TriangleId t : sides)
        if (is_ocean(t) && piece.emplace(t, static_cast<std::uint32_t>(floods.size())).second)
            floods.push_back({{t}, 0, static_cast<std::uint32_t>(floods.size())});
    for (std::uint32_t f = 0; f < floods.size(); ++f) {
        const double h = km_to_rad(m.size_km(m.centroid(floods[f].faces[0])));
        const double cap = inlet_narrow_area * h * h;
        while (floods[f].next < floods[f].faces.size() && floods[root(f)].area <= cap) {
            const TriangleId t = floods[f].faces[floods[f].next++];
            Flood& r = floods[root(f)];
            r.area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)), dt.point(dt.vertex(t, 2)));
            for (int i = 0; i < 3; ++i) {
                const TriangleId n = dt.neighbour(t, i);
                if (!is_ocean(n)) {
                    const VertexId x = dt.vertex(t, next3(i)), y = dt.vertex(t, prev3(i));
                    r.perimeter += arc_angle(dt.point(x), dt.point(y));
                    const auto it = m.segments.find(key(x, y));
                    r.open = r.open || (it != m.segments.end() && it->second == SegmentKind::open);
                    continue;
                }
                const auto [it, added] = piece.emplace(n, f);
                if (added) {
                    floods[f].faces.push_back(n);
                } else if (const std::uint32_t g = root(it->second), rf = root(f); g != rf) {
                    floods[g].parent = rf; // the same piece: its sums go to one root
                    floods[rf].area += floods[g].area;
                    floods[rf].perimeter += floods[g].perimeter;
                    floods[rf].open = floods[rf].open || floods[g].open;
                }
            }
        }
    }
    // A piece is whole when none of its floods has faces left to count. The whole ones go
    // under the inlet rule, but for the largest when no piece is left growing (every piece
    // beside the cuts small: one of them stays).
    std::vector<std::uint32_t> whole;
    std::vector<char> growing(floods.size(), 0);
    for (std::uint32_t f = 0; f < floods.size(); ++f)
        if (floods[f].next < floods[f].faces.size()) growing[root(f)] = 1;
    for (std::uint32_t f = 0; f < floods.size(); ++f)
        if (root(f) == f && !growing[f]) whole.push_back(f);
    if (std::find(growing.begin(), growing.end(), 1) == growing.end() && !whole.empty())
        whole.erase(std::max_element(whole.begin(), whole.end(),
                                     [&](std::uint32_t x, std::uint32_t y) { return floods[x].area < floods[y].area; }));
    for (const std::uint32_t k : whole) {
        const Flood& p = floods[k];
        const double h = km_to_rad(m.size_km(m.centroid(p.faces[0])));
        const bool small = p.area <= options.inlet_area * h * h ||
                           (p.area <= inlet_narrow_area * h * h && 2 * p.area < options.inlet_width * h * p.perimeter);
        if (p.open || !small) continue;
        report.straits_water_km2 += p.area * earth_radius_km * earth_radius_km;
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == k)
                for (const TriangleId t : floods[f].faces) {
                    dt.set_label(t, land);
                    ++(land_test.contains(m.centroid(t)) ? report.land_faces_removed : report.water_faces_removed);
                }
    }
    // Where the cuts are, for the count of basins they made (mesh_boundary's output).
    for (const TriangleId t : sides)
        if (is_ocean(t)) m.cut_sides.push_back(t);
    faces.clear();
    for (const TriangleId t : left)
        if (is_ocean(t)) faces.push_back(t);
}

// Relaxation by flips towards valence 6 (Frey & Field): an unconstrained edge between two ocean
// triangles with four free corners is flipped when that lowers the sum of squared valence
// defects (valence - 6) of those corners. The flipped corners and their free neighbours then
// move, without flips, to the mean of their neighbours for a few rounds, so that the new
// connectivity can become the Delaunay one; last, Lawson flips restore the constrained-Delaunay
// property (undoing the few flips the moves could not make Delaunay). Boundary nodes take no
// part: counting their ideal valence from their ocean angle (one triangle per 60 degrees) and
// flipping there too made more coast faces below q 0.8 than it mended. Returns the flips made;
// the nodes moved get their bit in `active` and lose `as_made`.
std::size_t relax_valence(Mesher& m, std::vector<char>& as_made, std::vector<std::uint8_t>& active) {
    SphericalDelaunay& dt = m.dt;
    const std::size_t nv = dt.vertex_count();
    std::vector<int> defect(nv, -6);
    std::vector<char> coastal(nv, 0); // a boundary node or its neighbour
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        ++defect[a], ++defect[b], ++defect[c];
        if (m.is_fixed(a) || m.is_fixed(b) || m.is_fixed(c)) coastal[a] = coastal[b] = coastal[c] = 1;
    }
    // A flip needs a corner of positive defect at one end of its edge, or one of valence 4
    // opposite it: only the triangles with one are tried (few where the lattice or smoothing
    // left valence 6).
    std::vector<TriangleId> tried;
    auto wants = [&](VertexId v) { return !coastal[v] && (defect[v] > 0 || defect[v] <= -2); };
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        if (wants(dt.vertex(t, 0)) || wants(dt.vertex(t, 1)) || wants(dt.vertex(t, 2))) tried.push_back(t);
    }
    std::vector<VertexId> move;
    std::size_t flips = 0;
    for (int pass = 0; pass < relax_passes; ++pass) {
        std::size_t made = 0;
        for (TriangleId t : tried) {
            if (!dt.is_live(t) || dt.label(t) != ocean) continue;
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                const HalfEdge g = dt.twin(h);
                if (dt.is_constrained(h) || dt.label(triangle_of(g)) != ocean) continue;
                const VertexId a = dt.origin(h), b = dt.destination(h);
                const VertexId c = dt.vertex(t, i), d = dt.vertex(triangle_of(g), edge_of(g));
                // The sum of squares drops by 2 (gain - 2). At a gain of 2 it stays, and the flip
                // is made when it brings every corner of valence 4 or 8 (or less, or more) among
                // the four to 5, 6 or 7: a 4 among 6s is mended only so. (Each flip lowers the
                // sum, or keeps it and lowers the count of such corners: the passes end.)
                const int gain = defect[a] + defect[b] - defect[c] - defect[d];
                if (gain < 2) continue;
                if (gain == 2 && (std::max({std::abs(defect[a]), std::abs(defect[b]), std::abs(defect[c]), std::abs(defect[d])}) < 2 ||
                                  std::max({std::abs(defect[a] - 1), std::abs(defect[b] - 1), std::abs(defect[c] + 1), std::abs(defect[d] + 1)}) >= 2))
                    continue;
                if (coastal[a] || coastal[b] || coastal[c] || coastal[d]) continue;
                const Vec3 &pa = dt.point(a), &pb = dt.point(b), &pc = dt.point(c), &pd = dt.point(d);
                if (predicates::orient(pa, pd, pc) <= 0 || predicates::orient(pd, pb, pc) <= 0) continue;
                if (std::min(triangle_quality(pa, pd, pc), triangle_quality(pd, pb, pc)) < relax_floor) continue;
                dt.flip(h);
                --defect[a], --defect[b], ++defect[c], ++defect[d];
                move.insert(move.end(), {a, b, c, d});
                ++made;
                break; // t is another triangle now
            }
        }
        flips += made;
        if (made == 0) break;
    }
    if (flips == 0) return 0;
    // The flipped corners' free neighbours move too, each from a half-edge leaving it (the moves
    // below change no connectivity, so one lookup serves every round).
    const std::vector<HalfEdge> star = dt.vertex_half_edges();
    for (std::size_t k = 0, n = move.size(); k < n; ++k) {
        const HalfEdge from = star[move[k]];
        HalfEdge h = from;
        do {
            if (!coastal[dt.destination(h)]) move.push_back(dt.destination(h));
            h = dt.next_around_origin(h);
        } while (h != from);
    }
    std::sort(move.begin(), move.end());
    move.erase(std::unique(move.begin(), move.end()), move.end());
    // A move that would bring the star's worst triangle below relax_move_floor, and below where
    // it was, is refused.
    std::vector<FarEdge> far;
    for (int round = 0; round < relax_rounds; ++round)
        for (VertexId v : move) {
            const HalfEdge from = star[v];
            if (!m.ocean_star(from, far)) continue;
            Vec3 sum{0, 0, 0};
            for (const FarEdge& e : far) sum = sum + e.b;
            const Vec3 to = normalized(sum);
            if (lowers_worst_below(to, dt.point(v), far, relax_move_floor)) continue;
            if (dt.place_vertex_from(from, to)) as_made[v] = 0, active[v] = 1;
        }
    // Only the triangles around the moved nodes changed (the flipped corners are among them).
    std::vector<HalfEdge> edges;
    for (VertexId v : move) {
        const HalfEdge from = star[v];
        HalfEdge h = from;
        do {
            edges.push_back(h);
            edges.push_back(half_edge(triangle_of(h), next3(edge_of(h)))); // the link edge opposite v
            h = dt.next_around_origin(h);
        } while (h != from);
    }
    dt.make_delaunay(edges);
    return flips;
}

// The lattice points walked, per face of the icosahedron and row: row i of face f walks j in
// [lo, hi] (weights i, j, rows - i - j on the face's corners), its cells at cell[start + j -
// lo], each the index of its point or `none` (not kept).
struct LatticeCells {
    static constexpr std::uint32_t none = 0xffffffffu;
    struct Row {
        int lo = 1, hi = 0;
        std::size_t start = 0;
    };
    int rows = 0;
    std::vector<Row> row_of; // 20 * (rows + 1)
    std::vector<std::uint32_t> cell;

    const Row& row(int f, int i) const { return row_of[static_cast<std::size_t>(f) * (rows + 1) + i]; }
    /// The cell of (i, j) in face f, or SIZE_MAX outside the face or the rows walked.
    std::size_t index(int f, int i, int j) const {
        if (i < 0 || i > rows || j < 0 || j > rows - i) return SIZE_MAX;
        const Row& r = row(f, i);
        return j < r.lo || j > r.hi ? SIZE_MAX : r.start + static_cast<std::size_t>(j - r.lo);
    }
    /// The entry of (i, j) of face f in `of` (an array over the cells), or none outside.
    std::uint32_t at(const std::vector<std::uint32_t>& of, int f, int i, int j) const {
        const std::size_t c = index(f, i, j);
        return c == SIZE_MAX ? none : of[c];
    }
    /// The point at (i, j) of face f, or none.
    std::uint32_t kept(int f, int i, int j) const { return at(cell, f, i, j); }
};

// Adds the lattice's points (those `grid` names) to the triangulation. A node inside its face
// whose six neighbours are kept too is "inner": its whole star is the lattice's six
// triangles. The others (on the lattice's rim, or on the icosahedron's edges) are inserted as
// any points; their triangulation with the boundary's then holds every edge of a lattice
// triangle whose corners are all kept (its circumcircle holds no other lattice node, and no
// boundary node or segment, which are lattice_clearance away), so the region of each face's
// whole lattice triangles is bounded by such edges, and the lattice's triangles replace
// whatever triangles the rim nodes made there (replace_region). Lawson flips then mend any
// lattice edge the rounding or the icosahedron's distortion left non-Delaunay: the result is
// the triangulation point insertion would give, without locating each point and testing its
// cavity. Returns the number of nodes added.
std::size_t place_lattice(Mesher& m, LatticeCells& grid, std::vector<Vec3>& points) {
    SphericalDelaunay& dt = m.dt;
    constexpr std::uint32_t none = LatticeCells::none;
    const int rows = grid.rows;
    const std::vector<std::uint32_t>& cell = grid.cell;
    auto kept = [&](int f, int i, int j) { return grid.kept(f, i, j); };
    const std::size_t before = dt.vertex_count();
    std::vector<char> inner(points.size(), 0);
    for (int f = 0; f < 20; ++f)
        for (int i = 1; i < rows; ++i) {
            const LatticeCells::Row& row = grid.row(f, i);
            for (int j = std::max(row.lo, 1); j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::uint32_t id = cell[row.start + static_cast<std::size_t>(j - row.lo)];
                if (id == none) continue;
                inner[id] = kept(f, i + 1, j) != none && kept(f, i - 1, j) != none && kept(f, i, j + 1) != none &&
                            kept(f, i, j - 1) != none && kept(f, i + 1, j - 1) != none && kept(f, i - 1, j + 1) != none;
            }
        }
    std::vector<Vec3> rim, inside;
    // Each to its size first: growing by doubling would copy and touch about twice the points.
    const auto inner_count = static_cast<std::size_t>(std::count(inner.begin(), inner.end(), 1));
    inside.reserve(inner_count);
    rim.reserve(points.size() - inner_count);
    std::vector<VertexId> vertex_of(points.size(), no_vertex); // point -> vertex (inner: filled below)
    for (std::size_t q = 0; q < points.size(); ++q) (inner[q] ? inside : rim).push_back(points[q]);
    if (!rim.empty()) {
        const std::vector<VertexId> ids = dt.insert_points(rim);
        for (std::size_t q = 0, r = 0; q < points.size(); ++q)
            if (!inner[q]) vertex_of[q] = ids[r++];
    }
    points.clear();
    points.shrink_to_fit();
    for (std::size_t q = 0, r = 0; q < vertex_of.size(); ++q)
        if (inner[q]) vertex_of[q] = static_cast<VertexId>(dt.vertex_count() + r++);
    inner.clear();
    inner.shrink_to_fit();
    // The lattice triangles whose corners are all kept: up (i, j), (i + 1, j), (i, j + 1) at
    // the cell of (i, j), and down (i + 1, j - 1), (i + 1, j), (i, j) at the cell of (i, j),
    // numbered first so that each can name its neighbours; counter-clockwise as the faces are
    // (replace_region checks).
    std::vector<std::uint32_t> up(cell.size(), none), down(cell.size(), none);
    std::uint32_t count = 0;
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i < rows; ++i) {
            const LatticeCells::Row& row = grid.row(f, i);
            for (int j = row.lo; j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::size_t c = row.start + static_cast<std::size_t>(j - row.lo);
                if (cell[c] == none || kept(f, i + 1, j) == none) continue;
                if (kept(f, i, j + 1) != none) up[c] = count++;
                if (kept(f, i + 1, j - 1) != none) down[c] = count++;
            }
        }
    std::vector<VertexId> triangles(3 * static_cast<std::size_t>(count));
    std::vector<std::uint32_t> adjacent(3 * static_cast<std::size_t>(count));
    std::vector<HalfEdge> border;
    const std::vector<HalfEdge> star = dt.vertex_half_edges();
    bool fits = true;
    // Links half-edge e of new triangle r (corners v) to edge e2 of new triangle t on its other
    // side or, when t is none, to the edge of the rim nodes' triangulation that it replaces
    // (a border edge; `fits` turns false when that edge is missing).
    auto set_edge = [&](std::uint32_t r, int e, const VertexId* v, std::uint32_t t, int e2) {
        if (t != none) {
            adjacent[3 * r + e] = 3 * t + e2;
            return;
        }
        const VertexId from = v[next3(e)], to = v[prev3(e)];
        const HalfEdge h = from < star.size() ? dt.find_edge(star[from], to) : no_half_edge;
        fits = fits && h != no_half_edge;
        adjacent[3 * r + e] = SphericalDelaunay::patch_border | static_cast<std::uint32_t>(border.size());
        border.push_back(h);
    };
    for (int f = 0; f < 20 && fits; ++f)
        for (int i = 0; i < rows && fits; ++i) {
            const LatticeCells::Row& row = grid.row(f, i);
            for (int j = row.lo; j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::size_t c = row.start + static_cast<std::size_t>(j - row.lo);
                if (const std::uint32_t r = up[c]; r != none) {
                    VertexId* v = &triangles[3 * r];
                    v[0] = vertex_of[cell[c]], v[1] = vertex_of[kept(f, i + 1, j)], v[2] = vertex_of[kept(f, i, j + 1)];
                    // Edge 0, (i + 1, j) -> (i, j + 1), is the down triangle's at (i, j + 1)
                    // edge 1; edge 1, (i, j + 1) -> (i, j), that at (i - 1, j + 1) edge 2;
                    // edge 2, (i, j) -> (i + 1, j), that at (i, j) edge 0.
                    set_edge(r, 0, v, grid.at(down, f, i, j + 1), 1);
                    set_edge(r, 1, v, grid.at(down, f, i - 1, j + 1), 2);
                    set_edge(r, 2, v, down[c], 0);
                }
                if (const std::uint32_t r = down[c]; r != none) {
                    VertexId* w = &triangles[3 * r];
                    w[0] = vertex_of[kept(f, i + 1, j - 1)], w[1] = vertex_of[kept(f, i + 1, j)], w[2] = vertex_of[cell[c]];
                    // Edge 0, (i + 1, j) -> (i, j), is the up triangle's at (i, j) edge 2; edge
                    // 1, (i, j) -> (i + 1, j - 1), that at (i, j - 1) edge 0; edge 2,
                    // (i + 1, j - 1) -> (i + 1, j), that at (i + 1, j - 1) edge 1.
                    set_edge(r, 0, w, up[c], 2);
                    set_edge(r, 1, w, grid.at(up, f, i, j - 1), 0);
                    set_edge(r, 2, w, grid.at(up, f, i + 1, j - 1), 1);
                }
            }
        }
    up.clear(), up.shrink_to_fit(), down.clear(), down.shrink_to_fit();
    grid.cell.clear(), grid.cell.shrink_to_fit();
    std::vector<TriangleId> slots;
    vertex_of.clear();
    vertex_of.shrink_to_fit();
    const std::size_t n_inside = inside.size();
    if (!fits || !dt.replace_region(border, inside, triangles, adjacent, ocean, &slots)) {
        // Only if rounding kept an edge of the lattice's rim out of the rim nodes' triangulation
        // (not seen; replace_region's checks are the guard): insert the inner nodes as points.
        dt.insert_points(inside);
        return dt.vertex_count() - before;
    }
    // Every new edge once (an edge between two new triangles from its smaller half-edge).
    std::vector<char> is_new(dt.triangle_slots(), 0);
    for (TriangleId t : slots) is_new[t] = 1;
    std::vector<HalfEdge> to_check;
    to_check.reserve(3 * slots.size() / 2 + border.size());
    for (TriangleId t : slots)
        for (int e = 0; e < 3; ++e) {
            const HalfEdge h = half_edge(t, e), o = dt.twin(h);
            if (h < o || !is_new[triangle_of(o)]) to_check.push_back(h);
        }
    dt.make_delaunay(to_check);
    m.report.lattice_patched = n_inside;
    return dt.vertex_count() - before;
}

// Fills the open ocean where the size field reaches s_km, its largest value, with the nodes of
// an icosahedral lattice of that spacing: each of the icosahedron's 20 faces cut into n^2
// triangles and projected onto the sphere from its centre. Its triangles are close to
// equilateral and the right size, so the refinement then only fills the band between the
// lattice and the coast (or smaller sizes), growing fronts from both. The points are chosen on
// the triangulation of the boundary alone, whose triangles are large (walked face by face, row
// by row, each row the other way than the last, so each walk is a step). Those on the rim of
// the kept lattice and on the icosahedron's edges are then inserted as any point set; the
// others come with their six lattice triangles, put in place by replace_region (see below).
// Only the lattice's points in a cap around the ocean are walked (a region's), and none when
// those are more than `max_points` (about 10 n^2 times the cap's share of the sphere). Returns
// the number of nodes added.
std::size_t fill_lattice(Mesher& m, double s_km, double max_points) {
    SphericalDelaunay& dt = m.dt;
    const double s = km_to_rad(s_km);
    const double n = std::max(1.0, std::round(lattice_edge_scale / s));
    // The cap: around the mean of the ocean triangles' corners, out to the farthest corner. A
    // cap narrower than a hemisphere holds each triangle whose corners it holds; a wider one
    // is taken as the whole sphere (cos_r -1).
    Vec3 centre{0, 0, 0};
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean)
            for (int i = 0; i < 3; ++i) centre = centre + dt.point(dt.vertex(t, i));
    double cos_r = -1;
    if (norm(centre) > 0) {
        centre = normalized(centre);
        cos_r = 1;
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
            if (dt.is_live(t) && dt.label(t) == ocean)
                for (int i = 0; i < 3; ++i) cos_r = std::min(cos_r, dot(dt.point(dt.vertex(t, i)), centre));
        const double r = std::acos(cos_r) + 2 * s; // a margin for the jitter
        cos_r = r < 1.5 ? std::cos(r) : -1;
    }
    const double cap_points = (10 * n * n + 2) * 0.5 * (1 - cos_r); // the lattice's points in the cap, about
    if (cap_points > max_points) return 0;
    auto in_cap = [&](const Vec3& p) { return dot(p, centre) >= cos_r * norm(p); }; // p need not be unit
    const double g = 0.5 * (1.0 + std::sqrt(5.0));
    const std::array<Vec3, 12> corner = {
        normalized(Vec3{-1, g, 0}), normalized(Vec3{1, g, 0}),  normalized(Vec3{-1, -g, 0}),
        normalized(Vec3{1, -g, 0}), normalized(Vec3{0, -1, g}), normalized(Vec3{0, 1, g}),
        normalized(Vec3{0, -1, -g}), normalized(Vec3{0, 1, -g}), normalized(Vec3{g, 0, -1}),
        normalized(Vec3{g, 0, 1}),  normalized(Vec3{-g, 0, -1}), normalized(Vec3{-g, 0, 1})};
    static constexpr int face[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                        {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                        {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                        {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    // A node shared by faces (on an edge or a corner) is made by the first face that has it.
    auto owner = [](int a, int b) { // the first face with the edge a-b, or with the corner a when b < 0
        for (int f = 0; f < 20; ++f) {
            const int* v = face[f];
            const bool has_a = v[0] == a || v[1] == a || v[2] == a;
            const bool has_b = b < 0 || v[0] == b || v[1] == b || v[2] == b;
            if (has_a && has_b) return f;
        }
        return -1;
    };
    const double clearance = lattice_clearance * s;
    const double sin2 = std::pow(std::sin(clearance), 2);
    const double chord2 = std::pow(2.0 * std::sin(0.5 * clearance), 2);
    std::vector<TriangleId> seen;
    // Whether p, in the ocean triangle t, has no boundary segment and no node within the
    // clearance: the triangles whose edges come that close, from t.
    auto clear = [&](const Vec3& p, TriangleId t) {
        seen.assign(1, t);
        for (std::size_t k = 0; k < seen.size(); ++k) {
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(seen[k], i);
                const Vec3& u = dt.point(dt.origin(e));
                const Vec3& w = dt.point(dt.destination(e));
                if (dot(u - p, u - p) < chord2) return false;
                const Vec3 c = cross(u, w);
                const double d = dot(p, c);
                if (d * d >= sin2 * dot(c, c) || arc_distance(u, w, p) >= clearance) continue; // far from the arc's circle, or its ends
                if (dt.is_constrained(e)) return false;
                const TriangleId nb = triangle_of(dt.twin(e));
                if (std::find(seen.begin(), seen.end(), nb) != seen.end()) continue;
                if (seen.size() == 64) return false; // a fan of long edges: leave it to the refinement
                seen.push_back(nb);
            }
        }
        return true;
    };
    // The points walked (a node of an edge or corner that another face owns is filled in
    // after the walk).
    constexpr std::uint32_t none = LatticeCells::none;
    const int rows = static_cast<int>(n);
    LatticeCells grid;
    grid.rows = rows;
    grid.row_of.resize(20 * static_cast<std::size_t>(rows + 1));
    std::vector<std::uint32_t>& cell = grid.cell;
    // The nodes on the icosahedron's 30 edges (by their smaller corner and the steps from it)
    // and at its 12 corners, shared by the faces that have them.
    std::array<std::array<int, 12>, 12> edge_id{};
    for (auto& e : edge_id) e.fill(-1);
    int edges = 0;
    for (const auto& v : face)
        for (int q = 0; q < 3; ++q) {
            const int u = std::min(v[q], v[(q + 1) % 3]), w = std::max(v[q], v[(q + 1) % 3]);
            if (edge_id[u][w] < 0) edge_id[u][w] = edges++;
        }
    std::vector<std::uint32_t> edge_node(30 * static_cast<std::size_t>(rows + 1), none);
    std::array<std::uint32_t, 12> corner_node;
    corner_node.fill(none);
    // The shared entry of node (i, j, k) of face f (weights on its corners a, b, c), or null
    // inside the face.
    auto shared_node = [&](int f, int i, int j, int k) -> std::uint32_t* {
        const int zeros = (i == 0) + (j == 0) + (k == 0);
        if (zeros == 0) return nullptr;
        const int* v = face[f];
        if (zeros == 2) return &corner_node[i > 0 ? v[0] : j > 0 ? v[1] : v[2]];
        int u = v[0], w = v[1], wu = i, ww = j; // k == 0: the edge a-b
        if (i == 0) u = v[1], w = v[2], wu = j, ww = k;
        else if (j == 0) u = v[0], w = v[2], wu = i, ww = k;
        if (u > w) std::swap(u, w), std::swap(wu, ww);
        return &edge_node[static_cast<std::size_t>(edge_id[u][w]) * (rows + 1) + ww];
    };
    std::vector<Vec3> points;
    // Room for every lattice point of the cap (those on land or too near the coast are never
    // written, so never touched): growing by doubling would copy and touch about twice the points.
    points.reserve(static_cast<std::size_t>(cap_points) + 1);
    TriangleId hint = no_triangle;
    for (int f = 0; f < 20; ++f) {
        const int ia = face[f][0], ib = face[f][1], ic = face[f][2];
        const Vec3 &a = corner[ia], &b = corner[ib], &c = corner[ic];
        // Skip a face whose cap (from its centre out to its corners) misses the ocean's.
        const Vec3 face_centre = normalized(a + b + c);
        if (cos_r > -1 && arc_angle(face_centre, centre) > arc_angle(face_centre, a) + std::acos(cos_r)) continue;
        for (int i = 0; i <= rows; ++i) {
            const int len = rows - i;
            // Row i is an arc of a great circle (weights j on b, len - j on c): its points in the
            // cap are an interval of j around the point nearest the cap's centre, found by a
            // ternary search (the cosine to the centre is unimodal along an arc under pi), and
            // its ends by bisection.
            int lo = 0, hi = len;
            if (cos_r > -1) {
                auto at = [&](int j) { return double(i) * a + double(j) * b + double(len - j) * c; };
                auto closeness = [&](int j) { const Vec3 q = at(j); return dot(q, centre) / norm(q); };
                int x0 = 0, x1 = len;
                while (x1 - x0 > 2) {
                    const int m1 = x0 + (x1 - x0) / 3, m2 = x1 - (x1 - x0) / 3;
                    if (closeness(m1) < closeness(m2)) x0 = m1 + 1;
                    else x1 = m2;
                }
                int best = x0;
                for (int j = x0 + 1; j <= x1; ++j)
                    if (closeness(j) > closeness(best)) best = j;
                if (!in_cap(at(best))) continue;
                int l = 0, r = best; // the first j in the cap
                while (l < r) {
                    const int mid = l + (r - l) / 2;
                    if (in_cap(at(mid))) r = mid;
                    else l = mid + 1;
                }
                lo = l;
                l = best, r = len; // the last
                while (l < r) {
                    const int mid = l + (r - l + 1) / 2;
                    if (in_cap(at(mid))) l = mid;
                    else r = mid - 1;
                }
                hi = l;
            }
            LatticeCells::Row& row = grid.row_of[static_cast<std::size_t>(f) * (rows + 1) + i];
            row = {lo, hi, cell.size()};
            cell.resize(cell.size() + static_cast<std::size_t>(hi - lo + 1), none);
            for (int step = 0; step <= hi - lo; ++step) {
                const int j = i % 2 == 0 ? lo + step : hi - step;
                const int k = rows - i - j;
                // Weights i, j, k on corners a, b, c: a node on the edge opposite a corner (its
                // weight 0) or at a corner belongs to the first face that has it.
                const int zeros = (i == 0) + (j == 0) + (k == 0);
                if (zeros == 2) {
                    const int v = i > 0 ? ia : j > 0 ? ib : ic;
                    if (owner(v, -1) != f) continue;
                } else if (zeros == 1) {
                    const int u = i == 0 ? ib : ia, w = k == 0 ? ib : ic;
                    if (owner(u, w) != f) continue;
                }
                // Each point moved by a pseudo-random 1e-6 of the spacing (its index hashed,
                // splitmix64): the lattice's mirror symmetries make many four points exactly
                // cocircular, each an in-circle test that only exact arithmetic decides.
                std::uint64_t x = (static_cast<std::uint64_t>(f) << 42) ^ (static_cast<std::uint64_t>(i) << 21) ^
                                  static_cast<std::uint64_t>(j);
                Vec3 shift;
                for (double* e : {&shift.x, &shift.y, &shift.z}) {
                    x += 0x9e3779b97f4a7c15ull;
                    std::uint64_t z = x;
                    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
                    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
                    *e = double((z ^ (z >> 31)) >> 11) * 0x1p-53 - 0.5;
                }
                const Vec3 p = normalized(normalized(double(i) * a + double(j) * b + double(k) * c) +
                                          (lattice_jitter * s) * shift);
                if (m.size_km(p) < lattice_level * s_km) continue;
                hint = dt.locate(p, hint);
                if (dt.label(hint) != ocean || !clear(p, hint)) continue;
                const auto id = static_cast<std::uint32_t>(points.size());
                cell[row.start + static_cast<std::size_t>(j - lo)] = id;
                if (std::uint32_t* shared = shared_node(f, i, j, k)) *shared = id;
                points.push_back(p);
            }
        }
    }
    if (points.empty()) return 0;
    // Every face's edge and corner cells from their owners.
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i <= rows; ++i) {
            const LatticeCells::Row& row = grid.row(f, i);
            for (int j = row.lo; j <= row.hi; ++j)
                if (const std::uint32_t* shared = shared_node(f, i, j, rows - i - j))
                    cell[row.start + static_cast<std::size_t>(j - row.lo)] = *shared;
        }
    edge_node.clear(), edge_node.shrink_to_fit();
    return place_lattice(m, grid, points);
}

} // namespace

Mesh mesh_boundary(const Boundary& boundary, const std::function<double(const Vec3&)>& size_km,
                   const MesherOptions& options, MesherReport* report_out, const Progress& progress,
                   StageTimings* timings) {
    MesherReport local_report;
    MesherReport& report = report_out ? *report_out : local_report;
    report = MesherReport{};
    Mesher m(SphericalDelaunay::Options{1e-12, options.seed}, size_km, report);
    SphericalDelaunay& dt = m.dt;

    // ---- 1. boundary nodes -------------------------------------------------------------------
    auto t0 = Clock::now();
    std::vector<Vec3> nodes;
    std::vector<std::size_t> offsets;
    for (const Ring& r : boundary.rings) {
        offsets.push_back(nodes.size());
        nodes.insert(nodes.end(), r.nodes.begin(), r.nodes.end());
    }
    report.boundary_nodes = nodes.size();
    std::vector<VertexId> ids;
    if (boundary.empty()) {
        // An aqua-planet: start from the octahedron and let refinement do the rest.
        std::vector<Vec3> seed = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        dt.insert_points(seed);
    } else {
        if (nodes.size() < 4) throw DataError("the boundary has fewer than 4 nodes: no ocean to mesh");
        ids = dt.insert_points(nodes);
        // When every boundary node lies in one hemisphere, ghost triangles (delaunay.hpp) close
        // the far side, and the far side may be ocean: add fixed far points until every triangle
        // is solid. A candidate closer than 1e-4 rad to a boundary arc is skipped, so none lies
        // on a segment; the flood fill below classifies them like any vertex.
        auto has_ghost = [&] {
            for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
                if (dt.is_live(t) && !dt.is_solid(t)) return true;
            return false;
        };
        if (has_ghost()) {
            std::vector<Vec3> far;
            for (double x : {-1.0, 1.0}) {
                far.push_back({x, 0, 0});
                far.push_back({0, x, 0});
                far.push_back({0, 0, x});
            }
            for (double x : {-1.0, 1.0})
                for (double y : {-1.0, 1.0})
                    for (double z : {-1.0, 1.0}) far.push_back(normalized(Vec3{x, y, z}));
            for (const Vec3& p : far) {
                bool clear = true;
                for (std::size_t r = 0; r < boundary.rings.size() && clear; ++r) {
                    const auto& rn = boundary.rings[r].nodes;
                    for (std::size_t i = 0; i < rn.size() && clear; ++i)
                        clear = arc_distance(rn[i], rn[(i + 1) % rn.size()], p) > 1e-4;
                }
                if (clear) dt.insert(p);
                if (!has_ghost()) break;
            }
        }
    }
    globemesh::report(progress, 0.05, "insert_boundary");
    if (timings) timings->add("insert_boundary", seconds_since(t0));

    // ---- 2. recover segments -----------------------------------------------------------------
    t0 = Clock::now();
    for (std::size_t r = 0; r < boundary.rings.size(); ++r) {
        const Ring& ring = boundary.rings[r];
        const std::size_t n = ring.nodes.size();
        m.current_ring = static_cast<std::uint32_t>(r);
        for (std::size_t i = 0; i < n; ++i) {
            VertexId a = ids[offsets[r] + i], b = ids[offsets[r] + (i + 1) % n];
            SegmentKind kind = i < ring.kinds.size() ? ring.kinds[i] : SegmentKind::coast;
            m.recover(a, b, kind, 0);
        }
    }
    globemesh::report(progress, 0.1, "recover");
    if (timings) timings->add("recover", seconds_since(t0));

    // ---- 3. classify -------------------------------------------------------------------------
    t0 = Clock::now();
    const std::size_t slots = dt.triangle_slots();
    std::vector<std::uint32_t> component(slots, 0xffffffffu);
    std::vector<double> component_area;
    std::vector<TriangleId> stack;
    auto flood = [&](TriangleId seed, std::uint32_t id) {
        double area = 0;
        stack.assign(1, seed);
        component[seed] = id;
        while (!stack.empty()) {
            TriangleId t = stack.back();
            stack.pop_back();
            area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                            dt.point(dt.vertex(t, 2)));
            for (int i = 0; i < 3; ++i) {
                HalfEdge h = half_edge(t, i);
                if (dt.is_constrained(h)) continue;
                TriangleId nb = triangle_of(dt.twin(h));
                if (component[nb] != 0xffffffffu) continue;
                component[nb] = id;
                stack.push_back(nb);
            }
        }
        return area;
    };
    if (boundary.empty()) {
        component_area.push_back(flood(dt.last_triangle(), 0));
    } else {
        // Consecutive segments of a ring share a node: each edge's triangle is the next one's
        // hint, which saves a walk from the last triangle across the whole triangulation.
        TriangleId hint = no_triangle;
        for (auto [a, b] : m.directed) {
            HalfEdge h = dt.find_edge(dt.leaving(a, hint), b);
            if (h == no_half_edge) throw DataError("internal: a recovered boundary segment is missing");
            hint = triangle_of(h);
            TriangleId left = triangle_of(h);
            if (component[left] == 0xffffffffu)
                component_area.push_back(flood(left, static_cast<std::uint32_t>(component_area.size())));
        }
        // Every segment must have land (or the outside of the region) on its right.
        hint = no_triangle;
        for (auto [a, b] : m.directed) {
            HalfEdge h = dt.find_edge(dt.leaving(a, hint), b);
            hint = triangle_of(h);
            TriangleId right = triangle_of(dt.twin(h));
            if (component[right] != 0xffffffffu && component[right] == component[triangle_of(h)])
                throw DataError("the boundary rings do not close the ocean: ocean on both sides of the "
                                "boundary near " + Mesher::describe(dt.point(a)));
            if (component[right] != 0xffffffffu) {
                // Ocean on the right of a segment: two rings of opposite orientation face each other
                // (e.g. an island drawn the wrong way round).
                throw DataError("a boundary ring has the ocean on its right near " +
                                Mesher::describe(dt.point(a)) + ": rings must keep the ocean on their left");
            }
        }
    }
    std::size_t largest = 0;
    for (std::size_t c = 0; c < component_area.size(); ++c)
        if (component_area[c] > component_area[largest]) largest = c;
    std::vector<char> kept(component_area.size(), 0);
    for (std::size_t c = 0; c < component_area.size(); ++c) {
        kept[c] = c == largest || options.keep_inland_seas;
        report.components.push_back({component_area[c] * earth_radius_km * earth_radius_km, kept[c] != 0});
    }
    if (component_area.empty()) throw DataError("no ocean is left inside the boundary");
    for (TriangleId t = 0; t < slots; ++t)
        if (dt.is_live(t))
            dt.set_label(t, component[t] != 0xffffffffu && kept[component[t]] ? ocean : land);
    if (options.inlet_width > 0 && !boundary.empty()) close_inlets(m, options, report);
    globemesh::report(progress, 0.15, "classify");

    // Sharp corners: boundary vertices whose ocean angle (the sum of their ocean triangles'
    // angles) is below 60 degrees. Later splits never change it: segments stay on their arcs.
    {
        std::vector<double> angle(dt.vertex_count(), 0.0);
        for (TriangleId t = 0; t < slots; ++t) {
            if (!dt.is_live(t) || dt.label(t) != ocean) continue;
            for (int i = 0; i < 3; ++i) {
                const Vec3& p = dt.point(dt.vertex(t, i));
                const Vec3 u = dt.point(dt.vertex(t, next3(i))) - p;
                const Vec3 w = dt.point(dt.vertex(t, prev3(i))) - p;
                angle[dt.vertex(t, i)] += std::atan2(norm(cross(u, w)), dot(u, w));
            }
        }
        m.sharp.assign(dt.vertex_count(), 0);
        for (auto [a, b] : m.directed) {
            if (angle[a] > 0 && angle[a] < 60.0 * deg_to_rad) m.sharp[a] = 1;
            if (angle[b] > 0 && angle[b] < 60.0 * deg_to_rad) m.sharp[b] = 1;
        }
    }

    // Node estimate over the ocean's triangles (add_node_estimate), which stops once past the
    // limits: the refusal then says "more than".
    std::size_t limit = options.max_nodes;
    if (options.max_memory != 0) limit = std::min<std::size_t>(limit, options.max_memory / mesher_bytes_per_node);
    const double stop = double(limit) - double(dt.vertex_count());
    double estimate = 0;
    for (TriangleId t = 0; t < slots && estimate <= stop; ++t)
        if (dt.is_live(t) && dt.label(t) == ocean)
            add_node_estimate(size_km, dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)), dt.point(dt.vertex(t, 2)),
                              stop, estimate);
    report.estimated_nodes = static_cast<std::size_t>(estimate) + dt.vertex_count();
    if (estimate > stop) {
        const std::string nodes = "more than " + std::to_string(limit) + " nodes";
        if (limit == options.max_nodes)
            throw DataError("the size field asks for " + nodes + " (--max-nodes): raise --hmin/--hmax or --max-nodes");
        throw DataError("the size field asks for " + nodes + ", which need more than --max-memory " +
                        std::to_string(options.max_memory >> 20) + " MiB: raise --hmin/--hmax or --max-memory");
    }
    // The triangulation's arrays sized once for the nodes to come (the estimate is within a few
    // per cent of the nodes made on 1:50m land at 64, 20 and 10 km), instead of doubling through
    // the lattice and the refinement: each doubling copied them into new blocks and touched
    // their pages again. Measured (alternated runs): refine at 64 km 0.113 -> 0.094 s, at 20 km
    // 0.622 -> 0.565 s; the peak at 20 km 193.9 -> 190.9 MiB.
    dt.reserve(report.estimated_nodes + report.estimated_nodes / 4);
    if (timings) timings->add("classify", seconds_since(t0));

    // ---- 4. refine ---------------------------------------------------------------------------
    t0 = Clock::now();
    const auto lattice_first = static_cast<VertexId>(dt.vertex_count()); // the lattice nodes follow
    // The lattice's points over the whole sphere may be a few times the nodes asked for (the
    // global ocean: 1.5 times), not more.
    if (options.lattice_km > 0)
        report.lattice_nodes = fill_lattice(m, options.lattice_km, 4.0 * double(report.estimated_nodes) + 1000);
    // Badness per triangle slot, computed once when the core creates the triangle: a triangle
    // never changes while it lives (its corners, their fixed/sharp flags and the size field are
    // all fixed), and every triangle an insertion creates has the new vertex as a corner.
    std::vector<double> bad(dt.triangle_slots(), 0.0);
    // Per slot: the generation of its triangle (bits 8-31, grows each time the core puts a new
    // triangle in the slot) and how many copies of its candidate, off the front (bits 0-3) and
    // on it (bits 4-7), are queued. Copies of one candidate are identical, so the heap holds one
    // entry for them and puts it back after each pop while copies remain: the same pops as one
    // entry per copy, with a smaller heap and fewer stale pops.
    std::vector<std::uint32_t> slot_state(dt.triangle_slots(), 0);
    CandidateHeap queue;
    auto refresh = [&](TriangleId t) {
        if (t >= bad.size()) {
            bad.resize(dt.triangle_slots(), 0.0);
            slot_state.resize(dt.triangle_slots(), 0);
        }
        slot_state[t] = ((slot_state[t] >> 8) + 1) << 8;
        bad[t] = dt.label(t) == ocean ? m.badness(t) : 0.0;
    };
    auto order_of = [&](double b, TriangleId t) -> std::uint64_t {
        const auto level = static_cast<std::uint64_t>(std::log2(b) * badness_levels_per_doubling); // b > 1
        return level << 32 | detail::hilbert_key(m.centroid(t));
    };
    auto push = [&](double b, TriangleId t, bool active) {
        const int shift = active ? 4 : 0;
        const std::uint32_t copies = (slot_state[t] >> shift) & 15u;
        if (copies == 0) queue.push({order_of(b, t), t, (slot_state[t] >> 8) << 1 | (active ? 1u : 0u)});
        if (copies < 15) slot_state[t] += 1u << shift; // (more than 15 copies: counted as 15)
    };
    auto stale = [&](const Candidate& c) {
        return !dt.is_live(c.t) || slot_state[c.t] >> 8 != c.stamp >> 1 || dt.label(c.t) != ocean;
    };
    // Frontal order (Rebay 1993): a bad triangle whose edge borders an accepted triangle or the
    // boundary is on the front and goes first; its new node is placed off that edge.
    auto front_edge = [&](TriangleId t) -> int {
        int best = -1;
        double best_len = 0;
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            TriangleId nb = triangle_of(dt.twin(h));
            bool accepted = dt.is_constrained(h) || dt.label(nb) != ocean || bad[nb] <= 1.0;
            if (!accepted) continue;
            const Vec3 d = dt.point(dt.destination(h)) - dt.point(dt.origin(h));
            const double len = dot(d, d); // the shortest chord is the shortest arc
            if (best < 0 || len < best_len) {
                best = i;
                best_len = len;
            }
        }
        return best;
    };
    auto consider = [&](TriangleId t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) return;
        double b = bad[t];
        if (b > 1.0) {
            push(b, t, front_edge(t) >= 0);
        } else {
            // An accepted triangle puts its bad neighbours on the front.
            for (int i = 0; i < 3; ++i) {
                TriangleId nb = triangle_of(dt.twin(half_edge(t, i)));
                if (dt.label(nb) == ocean && !dt.is_constrained(half_edge(t, i))) {
                    double bn = bad[nb];
                    if (bn > 1.0) push(bn, nb, true);
                }
            }
        }
    };
    std::vector<TriangleId> star_triangles;
    auto consider_star = [&](VertexId v) {
        // Every triangle created by the last insertion has v as a corner: rotate around v, give
        // each its badness first (front_edge reads the neighbours'), then consider each.
        TriangleId last = dt.last_triangle();
        int k = 0;
        while (k < 3 && dt.vertex(last, k) != v) ++k;
        if (k == 3) return;
        HalfEdge from = half_edge(last, prev3(k)); // leaves v
        HalfEdge h = from;
        star_triangles.clear();
        do {
            star_triangles.push_back(triangle_of(h));
            refresh(triangle_of(h));
            h = dt.next_around_origin(h);
        } while (h != from);
        for (TriangleId t : star_triangles) consider(t);
    };
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean) bad[t] = m.badness(t);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) consider(t);
    const std::size_t node_limit = 4 * report.estimated_nodes + 1000;
    std::size_t inserted = 0;
    // Stale entries are dropped whenever the heap doubles since the last sweep (this keeps the
    // pop order: only entries that would be skipped go).
    std::size_t compact_at = std::max<std::size_t>(2 * queue.size(), 1 << 16);
    while (!queue.empty()) {
        if (queue.size() >= compact_at) {
            queue.remove_if(stale);
            compact_at = std::max<std::size_t>(2 * queue.size(), 1 << 16);
        }
        const Candidate c = queue.pop();
        const TriangleId t = c.t;
        if (stale(c)) continue;
        const int shift = c.active() ? 4 : 0;
        slot_state[t] -= 1u << shift;
        if ((slot_state[t] >> shift & 15u) != 0) queue.push(c); // the next copy
        if (dt.vertex_count() > node_limit)
            throw DataError("refinement does not converge (over " + std::to_string(node_limit) +
                            " nodes): the size field may be too small for the boundary");
        Vec3 centre = m.circumcentre(t);
        if (int e = front_edge(t); e >= 0) {
            // Off the front edge u->w (t on its left): the apex of an isosceles triangle whose
            // circumradius is the target's, kept inside t's circumcircle (Rebay's point).
            const Vec3& u = dt.point(dt.vertex(t, next3(e)));
            const Vec3& w = dt.point(dt.vertex(t, prev3(e)));
            Vec3 mid = arc_midpoint(u, w);
            Vec3 left = normalized(cross(u, w));
            double half = 0.5 * arc_angle(u, w);
            // Grow from short front edges (e.g. short coast segments) at most by the edge's own
            // length, so the mesh grades away from them instead of leaving slivers.
            double target = circumradius_factor * km_to_rad(size_km(mid)) / std::sqrt(3.0) * frontal_radius_factor;
            double rho = std::max(half, std::min(target, 2.0 * half * front_growth));
            double height = rho + std::sqrt(std::max(0.0, rho * rho - half * half));
            double to_centre = std::atan2(dot(centre, left), dot(centre, mid)); // signed, along the bisector
            if (to_centre > 0) {
                double d = std::min(height, to_centre);
                centre = normalized(std::cos(d) * mid + std::sin(d) * left);
            }
        }
        // Walk from t to the circumcentre; stop at the first constrained edge in the way, or at
        // one whose diametral circle it lands in (Ruppert's rule): split that segment instead.
        HalfEdge blocked = no_half_edge;
        const TriangleId cur = m.walk_towards(t, centre, blocked);
        VertexId v;
        if (blocked != no_half_edge) {
            // The circumcentre lies beyond a boundary segment: split the segment, if it is
            // not already short against the size field.
            v = m.split_segment(blocked);
            if (v == no_vertex) continue;
            ++report.encroached_splits;
            consider_star(v);
            // The triangle itself may survive the split: look at it again.
            consider(t);
        } else {
            if (dt.label(cur) != ocean) continue;
            std::size_t before = dt.vertex_count();
            v = dt.insert_in_triangle(centre, cur);
            if (dt.vertex_count() == before) continue; // merged with a close vertex
            consider_star(v);
        }
        if ((++inserted & 0x3fff) == 0)
            globemesh::report(progress, 0.15 + 0.6 * std::min(1.0, double(dt.vertex_count()) / double(report.estimated_nodes + 1)),
                   "refine");
    }
    if (timings) timings->add("refine", seconds_since(t0));

    // ---- 5. improve --------------------------------------------------------------------------
    t0 = Clock::now();
    // The refinement's memory goes before the smoothing's: the heap and the per-slot arrays.
    queue.release();
    std::vector<double>().swap(bad);
    std::vector<std::uint32_t>().swap(slot_state);
    // Nodes are visited along the Hilbert curve, boundary nodes (fixed) left out. When the
    // refinement made most of them, they are renumbered in that order first, and the triangles
    // after them (SphericalDelaunay::renumber), so that neighbours lie near each other in memory:
    // the refinement numbers nodes in the order it makes them, all over the sphere level after
    // level (1:50m land at --hmax 100km --coast-size 5km: 88% of the triangles joined vertices
    // over 4,096 ids apart), where the lattice's come in Hilbert order already (20 km: 9%). The
    // stages below and the output's numbering follow. Measured there: improve 5.0 -> 3.6 s, land
    // 0.7 -> 0.4 s, UGRID write 5.0 -> 3.6 s; renumbering a uniform 20 km mesh would take 0.17 s
    // (its new arrays' first touch, mostly) for nothing.
    std::vector<char> lattice(dt.vertex_count(), 0); // the lattice's nodes
    std::fill_n(lattice.begin() + lattice_first, report.lattice_nodes, 1);
    std::vector<VertexId> visit;
    {
        using Key = decltype(detail::hilbert_key(Vec3{}));
        std::vector<std::pair<Key, VertexId>> keyed;
        keyed.reserve(dt.vertex_count());
        for (VertexId v = 0; v < dt.vertex_count(); ++v) keyed.emplace_back(detail::hilbert_key(dt.point(v)), v);
        std::sort(keyed.begin(), keyed.end());
        if (2 * report.lattice_nodes < dt.vertex_count()) {
            std::vector<VertexId> new_of_old(keyed.size());
            for (std::size_t k = 0; k < keyed.size(); ++k) new_of_old[keyed[k].second] = static_cast<VertexId>(k);
            for (std::size_t k = 0; k < keyed.size(); ++k) keyed[k].second = static_cast<VertexId>(k);
            m.renumber(new_of_old);
            renumber_per_vertex(lattice, new_of_old, char{0});
        }
        for (const auto& kv : keyed)
            if (!m.is_fixed(kv.second)) visit.push_back(kv.second);
    }
    std::vector<FarEdge> far; // a star's far edges b -> c (triangles v, b, c)
    std::vector<VertexId> ring;             // the star's outer vertices
    // Per vertex, bit 0: visit in this sweep, bit 1: in the next. A node whose move would be
    // shorter than settle_fraction of h stays and stays off the next sweep, unless a neighbour
    // moves.
    std::vector<std::uint8_t> active(dt.vertex_count(), 1);
    // Per vertex: a lattice node among lattice nodes only that has not moved. Such a node is
    // about where smoothing would leave it (inside a face of the icosahedron, the move is under
    // 0.3% of the spacing, below settle_fraction), so it starts settled and moves only when a
    // neighbour does; and a triangle of three is the lattice's own (q above 0.88), which the
    // quality rounds below leave as it is.
    std::vector<char> as_made(dt.vertex_count(), 0);
    if (report.lattice_nodes > 0) {
        as_made = lattice; // then those with every neighbour a lattice node too
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
            if (!dt.is_live(t)) continue;
            const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
            if (!lattice[a] || !lattice[b] || !lattice[c]) as_made[a] = as_made[b] = as_made[c] = 0;
        }
        for (VertexId v = 0; v < dt.vertex_count(); ++v)
            if (as_made[v]) active[v] = 0;
    }
    std::vector<char>().swap(lattice);
    // Per vertex, the size there (km; NaN: not asked yet), for the sweeps: a triangle's size is
    // the mean of its corners' (the size at its centroid where the field is linear over it; the
    // grid's cells are about hfloor / 2), each evaluated when first asked and again when its
    // node moves, instead of once per star triangle visited. On 1:50m land at --hmax 100km
    // --coast-size 5km: 5.1 instead of 20 million evaluations, the sweeps 3.1 -> 1.8 s, the
    // quality the same (mean 0.9231, above 0.9 69.95 against 69.92%). (The refinement's badness
    // from them too saved another 0.44 s, but cost the Gulf Stream field 0.0012 of its mean q:
    // it keeps the size at the centroid.) No node is added while it is in use.
    std::vector<float> vertex_size(dt.vertex_count(), std::numeric_limits<float>::quiet_NaN());
    auto corner_size_km = [&](TriangleId t) {
        double sum = 0;
        for (int i = 0; i < 3; ++i) {
            float& h = vertex_size[dt.vertex(t, i)];
            if (std::isnan(h)) h = static_cast<float>(size_km(dt.point(dt.vertex(t, i))));
            sum += h;
        }
        return sum / 3;
    };
    for (int sweep = 0; sweep < options.smooth_iterations; ++sweep) {
        // One vertex map per sweep; flips make entries stale, so each serves as a walk hint
        // (a triangle next to v) rather than an answer: the walk from it is a step or two.
        const std::vector<HalfEdge> star = dt.vertex_half_edges();
        for (std::size_t k = 0; k < visit.size(); ++k) {
            const VertexId v = visit[k];
            if (!(active[v] & 1)) continue;
            // The next stars' entries are far apart in memory: ask for them ahead.
            if (k + 16 < visit.size()) __builtin_prefetch(&star[visit[k + 16]]);
            if (k + 8 < visit.size() && star[visit[k + 8]] != no_half_edge)
                __builtin_prefetch(&dt.point(dt.destination(star[visit[k + 8]])));
            if (star[v] == no_half_edge) continue;
            HalfEdge from = star[v];
            if (dt.origin(from) != v || !dt.is_live(triangle_of(from))) from = dt.leaving(v, triangle_of(from));
            if (from == no_half_edge || dt.origin(from) != v) continue;
            // Only nodes inside the kept ocean move.
            Vec3 sum{0, 0, 0};
            bool inside = true;
            HalfEdge h = from;
            std::size_t guard = 0;
            far.clear();
            ring.clear();
            double hk = 0;
            do {
                TriangleId t = triangle_of(h);
                if (dt.label(t) != ocean) {
                    inside = false;
                    break;
                }
                far.emplace_back(dt.point(dt.destination(h)), dt.point(dt.vertex(t, edge_of(h))));
                ring.push_back(dt.destination(h));
                const Vec3& a = dt.point(dt.vertex(t, 0));
                const Vec3& b = dt.point(dt.vertex(t, 1));
                const Vec3& c = dt.point(dt.vertex(t, 2));
                Vec3 n = cross(b - a, c - a); // |n| = twice the chordal area
                double area = 0.5 * norm(n);
                // Optimal Delaunay triangulation update (Chen & Xu): weight the circumcentres by
                // area / h^2 so that graded meshes keep their grading.
                hk = corner_size_km(t);
                sum = sum + (area / (hk * hk)) * normalized(n);
                h = dt.next_around_origin(h);
            } while (h != from && ++guard < 64);
            if (!inside || norm(sum) == 0) continue;
            // Refuse a move that would bring the worst triangle of the star below 0.6 and
            // below where it was (smoothing must not flatten triangles against the coast).
            const Vec3 target = normalized(sum);
            // The quality before the move is needed only when the move would go below 0.6. (A
            // move that would fold the star counts as -1: move_vertex_from refuses it anyway.)
            if (norm(target - dt.point(v)) < settle_fraction * km_to_rad(hk)) continue;
            if (lowers_worst_below(target, dt.point(v), far, 0.6)) continue;
            if (!dt.move_vertex_from(from, target)) continue;
            vertex_size[v] = static_cast<float>(size_km(target));
            active[v] |= 2;
            as_made[v] = 0;
            for (VertexId u : ring) active[u] |= 2;
        }
        for (auto& a : active) a >>= 1;
        if (sweep == options.smooth_iterations - 1) {
            std::vector<float>().swap(vertex_size); // the relaxation moves nodes without it
            report.valence_flips = relax_valence(m, as_made, active);
        }
        globemesh::report(progress, 0.75 + 0.2 * (sweep + 1) / std::max(1, options.smooth_iterations), "improve");
    }
    std::vector<float>().swap(vertex_size); // (with no sweeps)
    // Then the nodes of the triangles still below q count_cap (next to the coast, or at valence
    // defects), a few rounds: each interior node goes where its star has the most triangles
    // above count_quality (star_count_score), searched from the best of a few candidates (the
    // mean of the apexes that would make each star triangle equilateral on its far edge, the
    // mean of its neighbours, halfway to either); each boundary node slides near the coast the
    // same way (slide_reach).
    {
        // The nodes of the ocean triangles below `below` (those at a sharp corner left out when
        // `skip_sharp`), each with a triangle next to it: the hint that finds its star in a step
        // or two. Interior nodes go to `todo`; boundary nodes to `*fixed_todo` when given.
        std::vector<std::pair<VertexId, TriangleId>> todo, slide_todo;
        // With `near`, only the triangles with a corner marked there. Every corner of the
        // triangles collected is marked in `dirty`.
        std::vector<char> dirty(dt.vertex_count(), 0);
        auto collect = [&](double below, bool skip_sharp, std::vector<std::pair<VertexId, TriangleId>>* fixed_todo = nullptr,
                           const std::vector<char>* near = nullptr) {
            todo.clear();
            if (fixed_todo) fixed_todo->clear();
            for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
                if (!dt.is_live(t) || dt.label(t) != ocean) continue;
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                if (near && !(*near)[a] && !(*near)[b] && !(*near)[c]) continue;
                if (skip_sharp && (m.is_sharp(a) || m.is_sharp(b) || m.is_sharp(c))) continue;
                if (as_made[a] && as_made[b] && as_made[c]) continue;
                if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) >= below) continue;
                for (VertexId u : {a, b, c}) {
                    dirty[u] = 1;
                    if (!m.is_fixed(u)) todo.emplace_back(u, t);
                    else if (fixed_todo) fixed_todo->emplace_back(u, t);
                }
            }
            for (auto* list : {&todo, fixed_todo}) {
                if (!list) continue;
                std::sort(list->begin(), list->end());
                list->erase(std::unique(list->begin(), list->end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                            list->end());
            }
        };
        std::vector<Vec3> candidates;
        std::vector<VertexId> touched;                 // move_checked's scratch
        std::vector<FarEdge> land_far;   // slide_node's: the star's far edges on land
        std::vector<Vec3> chain;                       // slide_node's: the points its search improved through
        // Moves v (`from` leaves it) to `to` (Mesher::move_if) when the ocean triangles the move
        // and its flips leave near it all keep q >= floor and none with two or three boundary
        // corners falls below quality_goal (the mending would have to split it); `ends` as in
        // move_if. With `changed`, a move marks every vertex whose star it changed.
        auto move_checked = [&](VertexId v, HalfEdge from, const Vec3& to, double floor, std::vector<char>* changed,
                                const VertexId* ends = nullptr) {
            auto holds = [&](TriangleId t) {
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                const double q = triangle_quality(dt.point(a), dt.point(b), dt.point(c));
                return q >= floor && (q >= quality_goal || m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2);
            };
            if (!m.move_if(from, to, ends, touched, holds, [] { return true; })) return false;
            as_made[v] = 0;
            // Every star the move changed: where the search rounds look for what is left.
            if (dirty.size() < dt.vertex_count()) dirty.resize(dt.vertex_count(), 0);
            dirty[v] = 1;
            for (VertexId u : touched) dirty[u] = 1;
            if (changed) {
                (*changed)[v] = 1;
                for (VertexId u : touched) (*changed)[u] = 1;
            }
            return true;
        };
        // A half-edge leaving v, found from `hint` (a triangle next to v when it was collected,
        // updated to one next to it now), or no_half_edge.
        auto leaving = [&](VertexId v, TriangleId& hint) {
            const HalfEdge from = dt.leaving(v, dt.is_live(hint) ? hint : no_triangle);
            if (from == no_half_edge || dt.origin(from) != v) return no_half_edge;
            hint = triangle_of(from);
            return from;
        };
        // The candidates for interior node v (p0, its star's far edges `far`) and the pattern
        // search's first step, 0.2 of its mean equilateral apex height.
        auto star_candidates = [&](const Vec3& p0) {
            Vec3 apex{0, 0, 0}, mean{0, 0, 0};
            double step = 0;
            for (const FarEdge& e : far) {
                const double d = 0.5 * std::sqrt(3.0) * arc_angle(e.b, e.c);
                apex = apex + (std::cos(d) * arc_midpoint(e.b, e.c) + std::sin(d) * normalized(cross(e.b, e.c)));
                mean = mean + e.b;
                step += d;
            }
            candidates.clear();
            for (const Vec3& p : {normalized(apex), normalized(mean)}) {
                candidates.push_back(p);
                candidates.push_back(normalized(p0 + p));
            }
            return step * 0.2 / double(far.size());
        };
        // The quality rounds' move of interior node v: the candidates, then a pattern search,
        // for the best star_count_score.
        auto count_node = [&](VertexId v, TriangleId& hint, std::vector<char>* changed) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            if (!m.ocean_star(from, far)) return;
            const Vec3 p0 = dt.point(v);
            const double floor = std::min(star_worst_quality(p0, far), worst_goal);
            double best = star_count_score(p0, far, count_rule, floor);
            if (best >= star_count_best(far.size(), count_rule)) return; // every triangle above count_cap
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
                if (score <= best + 1e-12) return false;
                best = score;
                to = p;
                return true;
            };
            // Half the search rounds' first step, and 4 halvings instead of 6.
            const double step = 0.5 * star_candidates(p0);
            for (const Vec3& p : candidates) consider(p);
            if (best < star_count_best(far.size(), count_rule))
                to = pattern_search(to, step, step / 16, [&](const Points8& p) { return star_count_accepts(p, far, count_rule, floor, best); });
            if (to != p0) move_checked(v, from, to, floor, changed);
        };
        // The same for boundary node v, between two coast segments of one ring, neither end a
        // sharp corner: its star's land triangles must stay counter-clockwise too, and it stays
        // within slide_reach h of the source coast; the candidates lie along its two segments.
        auto slide_node = [&](VertexId v, TriangleId& hint, std::vector<char>* changed) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            VertexId ends[2];
            if (!m.slide_star(from, far, land_far, ends)) return;
            const Vec3 p0 = dt.point(v);
            const double reach = slide_reach * km_to_rad(size_km(p0));
            const double floor = std::min(star_worst_quality(p0, far), worst_goal);
            double best = star_count_score(p0, far, count_rule, floor);
            if (best >= star_count_best(far.size(), count_rule)) return; // every triangle above count_cap
            // The search scores the star alone; the coast and land rules are checked on the points
            // it improved through, from the best back.
            chain.clear();
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                for (const FarEdge& e : land_far)
                    if (predicates::orient(p, e) <= 0) return false;
                const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
                if (score <= best + 1e-12) return false;
                best = score;
                to = p;
                chain.push_back(p);
                return true;
            };
            for (VertexId e : ends)
                for (double f : {0.1, 0.2, 0.3}) consider(normalized((1 - f) * p0 + f * dt.point(e)));
            const double step = 0.5 * reach;
            if (best < star_count_best(far.size(), count_rule))
                pattern_search(to, step, step / 8, [&](const Points8& p) {
                    const unsigned accepted = star_count_accepts(p, far, count_rule, floor, best, &land_far);
                    for (int k = 0; k < 8; ++k)
                        if (accepted >> k & 1u) chain.push_back(p[k]);
                    return accepted;
                });
            // The star's faces centred on land where it is now are counted only when a point
            // has some (rarely: most stars have none either way).
            int land0 = -1;
            for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
                if (!options.land->coast_within(*it, reach)) continue;
                if (const int land = star_faces_on_land(*options.land, *it, far); land > 0) {
                    if (land0 < 0) land0 = star_faces_on_land(*options.land, p0, far);
                    if (land > land0) continue;
                }
                move_checked(v, from, *it, floor, changed, ends);
                return;
            }
        };
        // The search rounds' move: to the candidate, then, when the star is still below
        // worst_goal, the point of a pattern search, that best raises the star's worst.
        auto improve_node = [&](VertexId v, TriangleId& hint) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            if (!m.ocean_star(from, far)) return;
            const Vec3 p0 = dt.point(v);
            const double before = star_worst_quality(p0, far);
            double best = before;
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                const double w = star_worst_quality(p, far, best + 1e-9);
                if (w <= best + 1e-9) return false;
                best = w;
                to = p;
                return true;
            };
            const double step = star_candidates(p0);
            for (const Vec3& p : candidates) consider(p);
            if (best < worst_goal)
                to = pattern_search(to, step, step / 64, [&](const Points8& p) { return star_worst_accepts(p, far, best); });
            if (to != p0) move_checked(v, from, to, std::min(before, worst_goal), nullptr);
        };
        collect(count_cap, false, options.land ? &slide_todo : nullptr);
        {
            // A node's move depends on its star's points alone: a node whose star has not
            // changed since it last stayed would stay again, and is skipped (the same mesh,
            // fewer evaluations). A move changes the stars of the node, its neighbours and,
            // when it needs flips, the corners of the flipped edges' quadrilaterals.
            std::vector<char> changed(dt.vertex_count(), 1);
            for (int round = 0; round < improve_rounds; ++round) {
                for (auto& [v, hint] : todo)
                    if (changed[v]) {
                        changed[v] = 0;
                        count_node(v, hint, &changed);
                    }
                for (auto& [v, hint] : slide_todo)
                    if (changed[v]) {
                        changed[v] = 0;
                        slide_node(v, hint, &changed);
                    }
            }
        }
        // Last, search_rounds rounds over the nodes of the triangles still below worst_goal
        // (away from sharp corners), collected again each round. Such a triangle was below
        // count_cap before the quality rounds, or a move changed it: only the triangles with a corner
        // marked in `dirty` are looked at.
        for (int round = 0; round < search_rounds; ++round) {
            collect(worst_goal, true, nullptr, &dirty);
            if (todo.empty()) break;
            for (auto& [v, hint] : todo) improve_node(v, hint);
        }
        // Last, a triangle with two or three boundary corners left below quality_goal (away
        // from sharp corners) has one node or none to move, and the flips of smoothing may have
        // made it after the refinement (an ear of the coast: two segments and the edge across
        // their corner). It gets its circumcentre when that lies in the ocean without
        // encroaching on a segment, else the segment in the way is split at its midpoint (as the
        // refinement does), and the new node and its free neighbours get their search, twice; a
        // few passes, as a search may leave another such triangle. (The split mends the last
        // face below 0.6 away from sharp corners on the Gulf Stream field, 0.5996 at the tip of
        // Sakhalin, and changes nothing at 100 km.)
        std::vector<TriangleId> mend;
        std::vector<std::pair<VertexId, TriangleId>> around;
        for (int pass = 0; pass < mend_passes; ++pass) {
            mend.clear();
            for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
                if (!dt.is_live(t) || dt.label(t) != ocean) continue;
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                if (m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2 || m.is_sharp(a) || m.is_sharp(b) || m.is_sharp(c)) continue;
                if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) < quality_goal) mend.push_back(t);
            }
            if (mend.empty()) break;
            for (TriangleId t : mend) {
                if (!dt.is_live(t)) continue; // gone with an earlier one's cavity
                HalfEdge blocked;
                const Vec3 centre = m.circumcentre(t);
                const TriangleId in = m.walk_towards(t, centre, blocked);
                VertexId v = no_vertex;
                if (blocked != no_half_edge) {
                    v = m.split_segment(blocked);
                    if (v != no_vertex) ++report.encroached_splits;
                } else if (dt.label(in) == ocean) {
                    const std::size_t before = dt.vertex_count();
                    v = dt.insert_in_triangle(centre, in);
                    if (dt.vertex_count() == before) v = no_vertex;
                }
                if (v == no_vertex) continue;
                as_made.resize(dt.vertex_count(), 0);
                around.assign(m.is_fixed(v) ? 0 : 1, {v, dt.last_triangle()});
                const HalfEdge from = dt.leaving(v, dt.last_triangle());
                HalfEdge h = from;
                do {
                    if (!m.is_fixed(dt.destination(h))) around.emplace_back(dt.destination(h), triangle_of(h));
                    h = dt.next_around_origin(h);
                } while (h != from);
                for (int round = 0; round < 2; ++round)
                    for (auto& [u, hint] : around) improve_node(u, hint);
                ++report.corners_mended;
            }
        }
    }
    std::vector<TriangleId> island_faces;
    report.island_centroids_left = clear_dropped_islands(m, boundary, report, island_faces);
    if (timings) timings->add("improve", seconds_since(t0));
    if (options.land) {
        t0 = Clock::now();
        std::vector<TriangleId> left;
        BoundaryLoops loops;
        remove_land_faces(m, *options.land, std::move(island_faces), options.inlet_area, report, left, loops);
        report.land_faces_nudged = nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        if (options.close_straits && !left.empty()) {
            close_straits(m, *options.land, left, options, loops, report);
            report.land_faces_at.clear();
            if (!left.empty()) report.land_faces_nudged += nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        }
        report.land_faces_left = report.land_faces_at.size();
        if (timings) timings->add("land", seconds_since(t0));
    }
    {
        // Last, the coast's corners too sharp for the faces there (corners.cpp).
        detail::CornerMesh cm{dt, ocean, land, size_km,
                              [&](VertexId a, VertexId b) {
                                  const auto it = m.segments.find(key(a, b));
                                  return it != m.segments.end() ? it->second : SegmentKind::coast;
                              },
                              [&](VertexId a, VertexId b, SegmentKind k) { m.add_segment(a, b, k); },
                              [&](HalfEdge h) { return m.split_segment(h); }, m.pinched, m.cut_sides};
        detail::CornerReport corners = detail::blunt_corners(cm, options.close_straits);
        report.corners_blunted = corners.blunted;
        report.encroached_splits += corners.splits;
        report.straits_closed += corners.straits_at.size();
        for (const Vec3& p : corners.straits_at) report.straits_closed_at.push_back(p);
    }

    // ---- output ------------------------------------------------------------------------------
    // The faces first, then the triangulation goes and its points become the nodes in place: the
    // triangulation and the output nodes never coexist (this is the mesher's peak).
    Mesh mesh;
    std::vector<NodeIndex> node_of(dt.vertex_count(), 0xffffffffu);
    std::size_t face_count = 0, node_count = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean) {
            ++face_count;
            for (int i = 0; i < 3; ++i) node_of[dt.vertex(t, i)] = 0;
        }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (node_of[v] == 0) node_of[v] = static_cast<NodeIndex>(node_count++);
    if (node_count == 0) throw DataError("no ocean is left to mesh at this size: the water was closed as inlets or straits, or removed as land; a smaller size keeps it");
    // A vertex between two or more fans of ocean (close_straits closed a strait there at a
    // point): each fan after the first gets a node of its own, pinch_apart into the fan, so
    // that the mesh is a manifold. (fan_corner, fan_node): the corners of those fans' faces and
    // their nodes, sorted; fan_point: the new nodes' points, numbered from node_count.
    std::vector<std::pair<TriangleId, VertexId>> fan_corner;
    std::vector<NodeIndex> fan_node;
    std::vector<Vec3> fan_point;
    {
        std::sort(m.pinched.begin(), m.pinched.end());
        m.pinched.erase(std::unique(m.pinched.begin(), m.pinched.end()), m.pinched.end());
        std::vector<std::tuple<TriangleId, VertexId, NodeIndex>> corners;
        std::vector<std::vector<TriangleId>> fans;
        for (const VertexId v : m.pinched) {
            fans.clear();
            const int n = m.ocean_fans(dt.leaving(v, no_triangle), [&](TriangleId t, int k) {
                if (k == int(fans.size())) fans.emplace_back();
                fans[std::size_t(k)].push_back(t);
            });
            const Vec3& p = dt.point(v);
            for (int k = 1; k < n; ++k) {
                const std::vector<TriangleId>& fan = fans[std::size_t(k)];
                // Towards the centroid of the fan's middle face (inside the fan's angle),
                // pinch_apart or less: every face of the fan must stay counter-clockwise (a
                // sliver of the fan may be thinner than pinch_apart).
                const Vec3 into = m.centroid(fan[fan.size() / 2]) - p;
                const Vec3 dir = normalized(into - dot(into, p) * p);
                auto far_edge = [&](TriangleId t) {
                    int i = 0;
                    while (dt.vertex(t, i) != v) ++i;
                    return std::pair{dt.point(dt.vertex(t, next3(i))), dt.point(dt.vertex(t, prev3(i)))};
                };
                Vec3 q = p;
                for (double d = pinch_apart; d > 1e-15; d *= 0.5) {
                    const Vec3 moved = normalized(p + d * dir);
                    bool ccw = true;
                    for (const TriangleId t : fan) {
                        const auto [a, b] = far_edge(t);
                        ccw = ccw && predicates::orient(moved, a, b) > 0;
                    }
                    if (ccw) {
                        q = moved;
                        break;
                    }
                }
                fan_point.push_back(q);
                const auto node = static_cast<NodeIndex>(node_count + fan_point.size() - 1);
                for (const TriangleId t : fan) corners.emplace_back(t, v, node);
            }
        }
        std::sort(corners.begin(), corners.end());
        for (const auto& [t, v, node] : corners) {
            fan_corner.emplace_back(t, v);
            fan_node.push_back(node);
        }
        report.nodes_split = fan_point.size();
    }
    auto node_at = [&](TriangleId t, VertexId v) {
        if (!fan_corner.empty()) {
            const auto it = std::lower_bound(fan_corner.begin(), fan_corner.end(), std::pair{t, v});
            if (it != fan_corner.end() && *it == std::pair{t, v}) return fan_node[std::size_t(it - fan_corner.begin())];
        }
        return node_of[v];
    };
    mesh.faces.reserve(face_count); // sized once: no doubling, no copy while growing
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        mesh.faces.push_back({node_at(t, dt.vertex(t, 0)), node_at(t, dt.vertex(t, 1)), node_at(t, dt.vertex(t, 2))});
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            TriangleId other = triangle_of(dt.twin(h));
            if (dt.label(other) == ocean) continue;
            VertexId a = dt.origin(h), b = dt.destination(h);
            auto it = m.segments.find(key(a, b));
            EdgeTag tag = it != m.segments.end() && it->second == SegmentKind::open ? EdgeTag::open : EdgeTag::coast;
            mesh.boundary.push_back({node_at(t, a), node_at(t, b), tag});
        }
    }
    std::vector<NodeIndex> cut_nodes; // a node of each face beside a cut
    for (const TriangleId t : m.cut_sides)
        if (dt.is_live(t) && dt.label(t) == ocean) cut_nodes.push_back(node_at(t, dt.vertex(t, 0)));
    // Node k is the k-th vertex used by a face, so moving each down to its index is in place.
    mesh.nodes = m.dt.release_points();
    for (VertexId v = 0; v < node_of.size(); ++v)
        if (node_of[v] != 0xffffffffu) mesh.nodes[node_of[v]] = mesh.nodes[v];
    mesh.nodes.resize(node_count);
    mesh.nodes.insert(mesh.nodes.end(), fan_point.begin(), fan_point.end());
    mesh.nodes.shrink_to_fit(); // the triangulation is gone: the copy is not the peak
    std::vector<NodeIndex>().swap(node_of);
    if (!cut_nodes.empty()) {
        // The basins the closed straits cut off: the mesh's pieces (union-find over the nodes
        // through the faces) beside a cut, but for the largest.
        std::vector<NodeIndex> parent(mesh.nodes.size());
        for (NodeIndex i = 0; i < parent.size(); ++i) parent[i] = i;
        auto find = [&](NodeIndex i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        for (const auto& f : mesh.faces) {
            const NodeIndex r = find(f[0]);
            for (int k = 1; k < 3; ++k) parent[find(f[k])] = r;
        }
        std::unordered_map<NodeIndex, double> area; // steradians per piece beside a cut
        for (const NodeIndex n : cut_nodes) area.emplace(find(n), 0.0);
        std::vector<std::uint32_t> faces_of(mesh.nodes.size(), 0);
        for (const auto& f : mesh.faces) ++faces_of[find(f[0])];
        const NodeIndex largest = static_cast<NodeIndex>(std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
        area.erase(largest);
        for (const auto& f : mesh.faces)
            if (auto it = area.find(find(f[0])); it != area.end())
                it->second += spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]);
        for (const auto& [r, a] : area) report.seas_cut_off.push_back(a * earth_radius_km * earth_radius_km);
        std::sort(report.seas_cut_off.rbegin(), report.seas_cut_off.rend());
    }
    std::vector<double> ocean_angle(mesh.nodes.size(), 0.0);
    std::vector<char> on_boundary(mesh.nodes.size(), 0);
    for (const auto& e : mesh.boundary) on_boundary[e.a] = on_boundary[e.b] = 1;
    for (const auto& f : mesh.faces)
        for (int i = 0; i < 3; ++i) {
            if (!on_boundary[f[i]]) continue;
            const Vec3& p = mesh.nodes[f[i]];
            const Vec3& q = mesh.nodes[f[next3(i)]];
            const Vec3& r = mesh.nodes[f[prev3(i)]];
            ocean_angle[f[i]] += std::atan2(norm(cross(q - p, r - p)), dot(q - p, r - p));
        }
    std::vector<char> sharp(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (on_boundary[v] && ocean_angle[v] < 60.0 * deg_to_rad) {
            sharp[v] = 1;
            ++report.sharp_corners;
        }
    for (const auto& f : mesh.faces)
        if (sharp[f[0]] || sharp[f[1]] || sharp[f[2]]) ++report.sharp_corner_faces;
    Field target{"target_size", "target edge length", "km", "", {}};
    target.values.reserve(mesh.nodes.size());
    for (const Vec3& p : mesh.nodes) target.values.push_back(size_km(p));
    mesh.node_fields.push_back(std::move(target));
    globemesh::report(progress, 1.0, "improve");
    return mesh;
}

} // namespace globemesh

