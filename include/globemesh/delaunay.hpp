// globemesh/delaunay.hpp: the (constrained) Delaunay triangulation of points on the sphere.
//
// What it is. The Delaunay triangulation of points on the unit sphere is the 3-D convex hull of
// the points (CGAL manual, "2D Triangulations on the Sphere"). SphericalDelaunay keeps that hull
// as a closed triangle surface: arrays of vertex and neighbour indices per triangle, no
// allocation per triangle. Insertion is Bowyer-Watson: the triangles whose circumcircle holds the
// new point (in hull terms: whose plane it lies beyond) are replaced by a fan around it.
//
// Solid and ghost triangles. A triangle abc is "solid" when det[a,b,c] > 0 (the origin is below
// its plane, so it is a proper spherical triangle). When every point lies in one closed
// hemisphere, the hull does not contain the origin and the triangles that close it on the far
// side have det <= 0: these are "ghost" triangles (CGAL's ghost faces). Solid triangles cover the
// spherical convex hull of the points; ghost triangles close the surface. Callers that want a
// mesh of the sphere keep only solid triangles (triangulate) or label ghosts as outside (mesher).
//
// Invariants (validate() checks them all): every live triangle lists three distinct vertices,
// counter-clockwise seen from outside the hull; neighbour links are symmetric; V - E + F = 2;
// every unconstrained edge is locally Delaunay under predicates::in_circle; a constrained edge is
// never flipped. The perturbed predicates make the triangulation unique for a point set without
// constraints, whatever the insertion order.
//
// Precision contract. Predicates are exact on the stored doubles. Points closer than the merge
// tolerance (default 1e-12 rad, 6 micrometres on the Earth) are merged and reported. Rounded unit
// vectors lie up to ~1e-16 off the sphere, so a point within ~1e-8 rad of existing ones can fall
// inside the hull of its neighbours; such a point is merged into its nearest vertex too (reported
// the same way) rather than breaking the structure. Conversely a new point can put an existing
// vertex inside the hull (its whole star in the new point's cavity): the nearer of the two
// survives and the other is merged into its nearest vertex, so every point maps to a vertex of
// the triangulation within ~1e-8 rad of it.
//
// Edge convention: edge i of triangle t joins vertex(t, i+1) to vertex(t, i+2) (indices mod 3),
// opposite vertex(t, i). A half-edge is encoded as 3*t + i. Standard library only.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "globemesh/sphere.hpp"

namespace globemesh {

using VertexId = std::uint32_t;
using TriangleId = std::uint32_t;
using HalfEdge = std::uint32_t;
inline constexpr VertexId no_vertex = 0xffffffffu;
inline constexpr TriangleId no_triangle = 0xffffffffu;
inline constexpr HalfEdge no_half_edge = 0xffffffffu;

inline constexpr TriangleId triangle_of(HalfEdge h) {
    return h / 3;
}
inline constexpr int edge_of(HalfEdge h) {
    return static_cast<int>(h % 3);
}
inline constexpr HalfEdge half_edge(TriangleId t, int i) {
    return 3 * t + static_cast<HalfEdge>(i);
}

class SphericalDelaunay {
public:
    struct Options {
        double merge_tolerance_rad = 1e-12; ///< points closer than this are merged
        std::uint64_t seed = 1;             ///< seed of the BRIO rounds (insertion order only)
    };

    SphericalDelaunay() = default;
    explicit SphericalDelaunay(Options options) : options_(options) {}

    /// Inserts points in a cache-friendly order (BRIO rounds, each sorted along a Hilbert curve
    /// on the cube faces). Returns, for each input point, the vertex it became or was merged into.
    /// On an empty triangulation, needs four points not on one plane: throws DataError
    /// ("fewer than 3 distinct points", "all points on one circle") otherwise.
    std::vector<VertexId> insert_points(std::span<const Vec3> points);

    /// The insertion order insert_points uses: a permutation of [0, n) in BRIO rounds drawn
    /// from `seed`, each round sorted along the Hilbert curve on the cube faces. Exposed so a
    /// caller can time the ordering apart from the insertions. Needs n < 2^31.
    static std::vector<std::uint32_t> insertion_order(std::span<const Vec3> points,
                                                      std::uint64_t seed);

    /// Inserts points into an empty triangulation, taking over `points`: they are gathered into
    /// the order of `order` (a permutation from insertion_order), so vertex v is the point at
    /// position v of that order (points() keeps every input point; a point merged into another
    /// keeps its slot as an unused vertex, with no triangle). Returns, for each input point, the
    /// vertex it became or was merged into. Peak memory is the points (24 B each), the result
    /// (4 B) and the triangles (2 per point, 25 B each); the gathered copy of the points and the
    /// order are released before the first triangle (56 B/point at most then). Throws DataError
    /// as insert_points, and std::invalid_argument when the triangulation is not empty or
    /// `order` is not a permutation of [0, points.size()).
    std::vector<VertexId> insert_points(std::vector<Vec3> &&points,
                                        std::vector<std::uint32_t> &&order);
    /// The same with insertion_order(points, options.seed).
    std::vector<VertexId> insert_points(std::vector<Vec3> &&points);

    /// Inserts one point, starting the walk at `hint` (any live triangle, or no_triangle).
    /// Returns its vertex, or the vertex it was merged into (then merged_count() grows).
    /// An unconstrained vertex whose whole star p's cavity takes (it lies within rounding of
    /// the hull of p and its neighbours) either takes p (p merges into it, when p is nearer to it
    /// than any vertex of the cavity's rim) or leaves the triangulation, merged into its nearest
    /// rim vertex (merged_count() grows; insert_points maps its points there).
    /// The cavity never crosses a constrained edge. Triangles created inherit the cavity's label.
    VertexId insert(const Vec3 &p, TriangleId hint = no_triangle);

    /// Inserts p, which the caller knows lies in the solid triangle t, into a constrained
    /// triangulation: t is replaced even when constraints make it non-Delaunay, and the cavity
    /// grows from it to the triangles whose circumcircle holds p, never across a constraint.
    VertexId insert_in_triangle(const Vec3 &p, TriangleId t);

    /// Inserts p into the edge h (constrained or not) and keeps both halves constrained when h
    /// was. p should lie on or very near the edge's arc (e.g. its midpoint). Returns the vertex,
    /// or the existing vertex p merged into (an end of h, or, as for insert(), a vertex within
    /// rounding of p: then vertex_count() does not grow).
    VertexId split_edge(HalfEdge h, const Vec3 &p);

    /// Makes a-b an edge of the triangulation and constrains it, by flipping the edges that cross
    /// the arc a-b (never inserting points). When a vertex lies exactly on the arc, the
    /// constraint is split there. Returns false and changes nothing when an existing constrained
    /// edge crosses the arc, or when flips cannot make the edge Delaunay-constrained: near
    /// vertices closer than about 1e-7 rad, whose rounding off the unit sphere outweighs its
    /// curvature, the points need not be in convex position (split the arc there instead).
    bool insert_constraint(VertexId a, VertexId b);

    /// Marks an entry of replace_region's `adjacent` as a border edge: patch_border | k is
    /// border[k].
    static constexpr std::uint32_t patch_border = 0x80000000u;

    /// Replaces a region by a triangulation the caller already knows (e.g. a lattice patch),
    /// without locating or testing its points one by one. `border` lists the half-edges of the
    /// region's boundary, each with the region on its left; the region is every triangle reached
    /// from them without crossing one. `points` become new vertices, numbered from
    /// vertex_count(), each inside the region. `triangles` holds three vertex ids per new
    /// triangle (existing vertices of the border, or new ones), counter-clockwise, and `adjacent`
    /// per new half-edge 3r + i (the edge convention above) either the new half-edge on its other
    /// side or patch_border | k when it takes border[k]'s place, with border[k]'s ends and
    /// constrained flag. New triangles get `label`; with `slots`, new triangle r is put in
    /// (*slots)[r]. The three vectors are emptied (each released once copied, so the peak stays
    /// near the grown triangulation's) when it returns true, left as they were when it returns
    /// false and changes nothing: when the pieces do not fit (a new triangle not
    /// counter-clockwise under predicates::orient, links not symmetric, a border edge missing or
    /// taken twice, a region holding a constrained edge or a vertex off the border, or a region
    /// whose triangle count is not the patch's less twice its new points: the patch and the
    /// region must tile the same surface). The Delaunay property is not restored:
    /// make_delaunay(edges) from the new half-edges does that.
    bool replace_region(std::span<const HalfEdge> border, std::vector<Vec3> &points,
                        std::vector<VertexId> &triangles, std::vector<std::uint32_t> &adjacent,
                        std::uint8_t label, std::vector<TriangleId> *slots = nullptr);

    /// Moves vertex v to p (a unit vector) and restores the Delaunay property around it by flips.
    /// Returns false and leaves v and every triangle as they were when the move would fold a
    /// triangle of its star, when its star holds a ghost triangle, or when flips cannot restore
    /// the property (v at p inside the hull of its neighbours: closer than rounding resolves).
    bool move_vertex(VertexId v, const Vec3 &p);
    /// The same with a half-edge leaving v (origin == v), which avoids a search for the star.
    /// With `flipped`, a successful move appends the corners of every quadrilateral whose
    /// diagonal it flipped (with repeats; nothing when no flip was needed): with v and its
    /// neighbours before the move, every vertex whose star the move changed.
    /// With `accept`, called once v is at p and its flips are made (after `flipped` is filled):
    /// when it returns false, the flips are undone and v goes back, so that every triangle is
    /// exactly as before the call, which then returns false. It must not change the triangulation.
    bool move_vertex_from(HalfEdge leaving_v, const Vec3 &p,
                          std::vector<VertexId> *flipped = nullptr,
                          const std::function<bool()> &accept = {});

    /// Moves the origin of leaving_v to p without flips, so the triangulation may stop being
    /// Delaunay until make_delaunay(). Returns false and changes nothing when a triangle of its
    /// star would not stay counter-clockwise with v at p.
    bool place_vertex_from(HalfEdge leaving_v, const Vec3 &p);

    /// Removes vertex v from the triangulation: its star becomes the Delaunay triangulation of
    /// its former neighbours' polygon, so a Delaunay triangulation stays Delaunay (and equals
    /// the one of the remaining points, without constraints). The polygon is cut into ears (each
    /// strictly counter-clockwise under predicates::orient, no other polygon vertex in it or on
    /// its sides), then Lawson flips from the edges of the hole restore the Delaunay property. v
    /// keeps its point and id as an unused vertex with no triangle (as a merged point does:
    /// vertex_count() does not fall), two triangle slots are freed, and the triangles left take the
    /// labels of the slots they occupy (triangles of a star with one label keep it). Returns false
    /// and changes nothing when a spoke of v is constrained, a triangle of its star is a ghost (not
    /// solid), no ear is found (polygon vertices on one great circle), or a Lawson flip would fold
    /// or flatten a triangle (points closer than rounding resolves).
    bool remove_vertex(VertexId v);
    /// The same with a half-edge leaving v (origin == v). With `changed`, a successful removal
    /// fills it with every triangle created or changed (sorted, live), before `accept` is called;
    /// when `accept` returns false, everything is undone exactly (the same triangles in the same
    /// slots, the free slots as before) and the call returns false. `accept` must not change the
    /// triangulation.
    bool remove_vertex_from(HalfEdge leaving_v, std::vector<TriangleId> *changed = nullptr,
                            const std::function<bool()> &accept = {});

    /// Flips the unconstrained edge h; the quadrilateral around it must be strictly convex.
    void flip(HalfEdge h);

    /// Renumbers the vertices, vertex v becoming new_of_old[v] (a permutation of every vertex),
    /// and the triangles in the order of their smallest new corner, free slots dropped: the same
    /// triangulation, laid out in memory as new_of_old orders it (for locality, a space-filling
    /// curve's order). Returns each old slot's new triangle (no_triangle for a free slot).
    std::vector<TriangleId> renumber(std::span<const VertexId> new_of_old);

    /// Flips unconstrained non-Delaunay edges until none remains (Lawson). Returns the flips made.
    std::size_t make_delaunay();
    /// The same from the half-edges in `edges` only (consumed): enough after changes confined
    /// to the triangles those edges bound.
    std::size_t make_delaunay(std::vector<HalfEdge> &edges);

    /// A live triangle whose spherical cone contains p, or that p is beyond (for points outside
    /// the solid region). Walks from `hint`.
    TriangleId locate(const Vec3 &p, TriangleId hint = no_triangle) const;

    // --- access ---
    std::size_t vertex_count() const { return points_.size(); }
    std::size_t triangle_slots() const { return tri_vertices_.size() / 3; }
    std::size_t triangle_count() const { return triangle_slots() - free_.size(); }
    std::size_t merged_count() const { return merged_; }
    bool is_live(TriangleId t) const { return tri_vertices_[3 * t] != no_vertex; }
    const Vec3 &point(VertexId v) const { return points_[v]; }
    const std::vector<Vec3> &points() const { return points_; }
    /// Moves the points out (indexed by VertexId) and leaves an empty triangulation: for a caller
    /// done with the triangles, without a copy of the points.
    std::vector<Vec3> release_points() {
        std::vector<Vec3> p = std::move(points_);
        *this = SphericalDelaunay(options_);
        return p;
    }
    VertexId vertex(TriangleId t, int i) const { return tri_vertices_[3 * t + i]; }
    /// The half-edge on the other side of h.
    HalfEdge twin(HalfEdge h) const { return links_[h] & link_mask; }
    TriangleId neighbour(TriangleId t, int i) const { return triangle_of(twin(half_edge(t, i))); }
    bool is_constrained(HalfEdge h) const { return (links_[h] & constrained_bit) != 0; }
    void set_constrained(HalfEdge h, bool on);
    /// det[a,b,c] > 0 for the triangle's vertices (see "Solid and ghost triangles").
    bool is_solid(TriangleId t) const;
    /// A free byte per triangle for the caller (the mesher stores ocean/land in it).
    std::uint8_t label(TriangleId t) const { return labels_[t]; }
    void set_label(TriangleId t, std::uint8_t l) { labels_[t] = l; }
    /// The last triangle created (a good walk hint).
    TriangleId last_triangle() const { return last_; }
    /// Origin and destination of half-edge h.
    VertexId origin(HalfEdge h) const { return vertex(triangle_of(h), (edge_of(h) + 1) % 3); }
    VertexId destination(HalfEdge h) const { return vertex(triangle_of(h), (edge_of(h) + 2) % 3); }
    /// The next half-edge leaving origin(h), counter-clockwise around it: the twin of the edge
    /// of h's triangle that ends at origin(h).
    HalfEdge next_around_origin(HalfEdge h) const {
        const int before = edge_of(h) == 0 ? 2 : edge_of(h) - 1;
        return twin(half_edge(triangle_of(h), before));
    }
    /// A half-edge leaving v (origin(h) == v) for every vertex; no_half_edge for merged-away ones.
    std::vector<HalfEdge> vertex_half_edges() const;
    /// Room for `points` vertices in all and their triangles (2n - 4 on the sphere), so that a
    /// caller that knows how many it will add spares the arrays their growth by doubling: each
    /// doubling copies the arrays into new ones and touches their pages again. Untouched room
    /// costs address space only. Never shrinks.
    void reserve(std::size_t points);
    /// The half-edge from a to b, searching the star of a from `from` (a half-edge leaving a);
    /// no_half_edge when a-b is not an edge.
    HalfEdge find_edge(HalfEdge from, VertexId b) const;
    /// A half-edge leaving vertex a: from the hint when a is one of its corners, else found by
    /// walking to its point from the hint (or the last triangle).
    HalfEdge leaving(VertexId a, TriangleId hint = no_triangle) const;

    /// Every broken invariant, in words; empty when the triangulation is valid.
    std::vector<std::string> validate() const;

private:
    // A link word is the twin half-edge (below 2^30, so at most ~178 million points) with the
    // constrained flag on top; bit 30 of a triangle's first link word is a scratch mark
    // (cavity / search membership), always clear between calls.
    static constexpr std::uint32_t constrained_bit = 0x80000000u;
    static constexpr std::uint32_t mark_bit = 0x40000000u;
    static constexpr std::uint32_t link_mask = 0x3fffffffu;

    bool marked(TriangleId t) const { return (links_[3 * t] & mark_bit) != 0; }
    void set_mark(TriangleId t) { links_[3 * t] |= mark_bit; }
    void clear_mark(TriangleId t) { links_[3 * t] &= ~mark_bit; }
    void reserve_for(std::size_t points);
    // remove_vertex_from's steps: v's star (its triangles, in star) can go (no constrained spoke,
    // no ghost); an ear clipping of its ring (three ring positions per triangle, empty if none).
    bool star_removable(HalfEdge from, std::vector<TriangleId> &star) const;
    std::vector<int> clip_ears(const std::vector<VertexId> &ring) const;
    VertexId insert_vertex(const Vec3 &p, VertexId id, TriangleId hint);
    TriangleId start_triangle(TriangleId hint) const;
    TriangleId walk(const Vec3 &p, TriangleId start, bool &inside) const;
    bool insert_fan(const Vec3 &p, TriangleId seed, VertexId id, VertexId &result);
    TriangleId new_slot();
    // Every coordinate at most 2 in magnitude (false for NaN): unit vectors, with room to spare.
    static bool bounded(const Vec3 &p) {
        return std::fabs(p.x) <= 2 && std::fabs(p.y) <= 2 && std::fabs(p.z) <= 2;
    }

    void link(HalfEdge a, HalfEdge b);
    TriangleId new_triangle(VertexId a, VertexId b, VertexId c, std::uint8_t label);
    void free_triangle(TriangleId t);
    void initial_tetrahedron(std::span<const Vec3> points, std::span<const std::uint32_t> order,
                             std::vector<VertexId> &vertex_of);
    void make_tetrahedron(VertexId v[4]);
    bool visible(TriangleId t, const Vec3 &p) const;
    // id: the vertex p becomes (an adopted point's slot), or no_vertex to append p.
    VertexId insert_in_cavity(const Vec3 &p, TriangleId seed, HalfEdge split,
                              VertexId id = no_vertex);
    // insert_in_cavity's steps: the cavity (marked, in cavity_, its rim in cavity_boundary_), and
    // the vertex it swallows that p merges into, or no_vertex with the others' drops listed.
    void grow_cavity(const Vec3 &p, TriangleId seed, HalfEdge split);
    VertexId swallowed_vertex(const Vec3 &p, VertexId split_a, VertexId split_b,
                              std::size_t &drops);
    // Both triangles of a flip as they were (vertices and link words), to undo it exactly.
    struct FlipRecord {
        TriangleId t, s;
        VertexId tv[3], sv[3];
        std::uint32_t tl[3], sl[3];
    };
    // flip(h), first recording it in *journal when there is one.
    void flip_recorded(HalfEdge h, std::vector<FlipRecord> *journal);
    // Undoes the journal's flips, newest first, and clears it.
    void undo_flips(std::vector<FlipRecord> &journal);
    // Lawson flips from the half-edges on `stack` until each edge reached is locally Delaunay.
    // A non-Delaunay edge between solid triangles whose flip would fold one (or make it flat,
    // when flat_folds) cannot be mended: without a journal it is skipped; with one, every flip
    // is recorded and the run stops there, returning false. Counts flips in *flips if given.
    bool legalize_from(std::vector<HalfEdge> &stack, std::vector<FlipRecord> *journal,
                       bool flat_folds, std::size_t *flips);
    bool recover_segment(VertexId a, VertexId b, std::vector<HalfEdge> &created,
                         std::vector<FlipRecord> &journal,
                         std::vector<std::pair<VertexId, VertexId>> &constrained);
    VertexId nearest_vertex(const Vec3 &p, TriangleId t) const;
    // Maps each vertex left by a swallowing cavity (see insert) to the vertex it merged into.
    void resolve_dropped(std::vector<VertexId> &map) const;

    Options options_;
    std::vector<Vec3> points_;
    std::vector<VertexId> tri_vertices_; // 3 per triangle slot; no_vertex marks a free slot
    std::vector<std::uint32_t> links_;   // 3 per slot: twin half-edge | constrained_bit
    std::vector<std::uint8_t> labels_;
    std::vector<TriangleId> free_;
    std::size_t merged_ = 0;
    std::vector<std::pair<VertexId, VertexId>> dropped_; // (vertex left by a cavity, merged into)
    std::vector<VertexId> swallowed_, rim_vertices_;     // scratch of insert_in_cavity
    TriangleId last_ = no_triangle;
    TriangleId recover_hint_ =
        no_triangle;      // recover_segment's: where it last found or flipped an edge
    bool bounded_ = true; // every point ever stored is bounded(): the walk's static filter holds
    // scratch buffers reused across insertions (no allocation per insertion)
    struct Rim {
        VertexId u, w;
        std::uint32_t outside; // twin half-edge with its constrained flag
        std::uint8_t label;
    };
    std::vector<TriangleId> cavity_;
    std::vector<HalfEdge> cavity_boundary_;
    std::vector<TriangleId> search_;
    std::vector<HalfEdge> move_stack_;     // scratch of move_vertex_from
    std::vector<FlipRecord> move_journal_; // scratch of move_vertex_from
    std::vector<Rim> rim_;
    std::vector<std::pair<VertexId, TriangleId>> by_start_;
};

} // namespace globemesh
