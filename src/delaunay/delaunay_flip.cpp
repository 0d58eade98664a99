// SphericalDelaunay: edge flips, Lawson legalization with an undo journal, and vertex moves.
#include "globemesh/delaunay.hpp"

#include <functional>
#include <vector>

#include "delaunay_internal.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

// ---------------------------------------------------------------------------------------------
// Flips and moves
// ---------------------------------------------------------------------------------------------

void SphericalDelaunay::flip(HalfEdge h) {
    const TriangleId t = triangle_of(h);
    const int i = edge_of(h);
    const HalfEdge g = twin(h);
    const TriangleId s = triangle_of(g);
    const int j = edge_of(g);
    const VertexId x = vertex(t, i);
    const VertexId y = vertex(s, j);
    // Outer half-edges (with their flags): A across w->x, B across x->u, C across u->y, D across
    // y->w.
    const std::uint32_t A = links_[half_edge(t, next3(i))];
    const std::uint32_t C = links_[half_edge(s, next3(j))];
    // t becomes (x, u, y): edge i = u->y (C), edge i+1 = y->x (diagonal), edge i+2 = x->u (B,
    // unchanged). s becomes (y, w, x): edge j = w->x (A), edge j+1 = x->y (diagonal), edge j+2 =
    // y->w (D, unchanged).
    tri_vertices_[3 * t + prev3(i)] = y;
    tri_vertices_[3 * s + prev3(j)] = x;
    auto attach = [&](HalfEdge mine, std::uint32_t outer) {
        links_[mine] = outer;
        links_[outer & link_mask] = mine | (outer & constrained_bit);
    };
    attach(half_edge(t, i), C);
    attach(half_edge(s, j), A);
    links_[half_edge(t, next3(i))] = half_edge(s, next3(j));
    links_[half_edge(s, next3(j))] = half_edge(t, next3(i));
    last_ = t;
}

void SphericalDelaunay::flip_recorded(HalfEdge h, std::vector<FlipRecord> *journal) {
    if (journal) {
        const TriangleId t = triangle_of(h), s = triangle_of(twin(h));
        FlipRecord rec{t, s, {}, {}, {}, {}};
        for (int k = 0; k < 3; ++k) {
            rec.tv[k] = tri_vertices_[3 * t + k];
            rec.sv[k] = tri_vertices_[3 * s + k];
            rec.tl[k] = links_[3 * t + k];
            rec.sl[k] = links_[3 * s + k];
        }
        journal->push_back(rec);
    }
    flip(h);
}

void SphericalDelaunay::undo_flips(std::vector<FlipRecord> &journal) {
    // Newest first: restore both triangles, then the outer half-edges' links to them.
    for (auto r = journal.rbegin(); r != journal.rend(); ++r) {
        for (int k = 0; k < 3; ++k) {
            tri_vertices_[3 * r->t + k] = r->tv[k];
            tri_vertices_[3 * r->s + k] = r->sv[k];
            links_[3 * r->t + k] = r->tl[k];
            links_[3 * r->s + k] = r->sl[k];
        }
        for (int k = 0; k < 3; ++k) {
            const HalfEdge ht = half_edge(r->t, k), hs = half_edge(r->s, k);
            links_[twin(ht)] = ht | (links_[ht] & constrained_bit);
            links_[twin(hs)] = hs | (links_[hs] & constrained_bit);
        }
    }
    if (!journal.empty())
        last_ = journal.front().t;
    journal.clear();
}

bool SphericalDelaunay::legalize_from(std::vector<HalfEdge> &stack,
                                      std::vector<FlipRecord> *journal, bool flat_folds,
                                      std::size_t *flips) {
    while (!stack.empty()) {
        HalfEdge h = stack.back();
        stack.pop_back();
        TriangleId t = triangle_of(h);
        if (!is_live(t) || is_constrained(h))
            continue;
        HalfEdge g = twin(h);
        TriangleId s = triangle_of(g);
        int i = edge_of(h), j = edge_of(g);
        const Vec3 &x = points_[vertex(t, i)];
        const Vec3 &u = points_[vertex(t, next3(i))];
        const Vec3 &w = points_[vertex(t, prev3(i))];
        const Vec3 &y = points_[vertex(s, j)];
        if (in_circle(x, u, w, y) <= 0)
            continue;
        // A solid non-Delaunay edge bounds a convex quadrilateral when the points lie on the
        // sphere; with ghosts around, make sure the flip keeps both triangles oriented. Convex,
        // not strictly: in_circle's perturbation scales points radially, which keeps every
        // orient() sign, zeros included, so a new triangle with orient() == 0 is flat in the
        // perturbed set too (three vertices on one great circle, e.g. a rounded point exactly on
        // the chord of two others: a flat face of a hull in a closed hemisphere, as insertion
        // makes). Skipping that flip would leave the edge not locally Delaunay; only a clockwise
        // (folded) triangle is refused, and a flat one too when the caller asks.
        const int o1 = orient(x, u, y), o2 = orient(y, w, x);
        if ((o1 < 0 || o2 < 0 || (flat_folds && (o1 == 0 || o2 == 0))) && is_solid(t) &&
            is_solid(s)) {
            // Rounded points are not exactly on the sphere: within ~1e-7 rad of each other their
            // radial rounding outweighs the sphere's curvature, and a vertex can sit inside the
            // hull of its neighbours, where no flip mends the edge.
            if (journal)
                return false;
            continue;
        }
        flip_recorded(h, journal);
        if (flips)
            ++*flips;
        // The four outer edges of the new pair.
        stack.push_back(half_edge(t, i));
        stack.push_back(half_edge(t, prev3(i)));
        stack.push_back(half_edge(s, j));
        stack.push_back(half_edge(s, prev3(j)));
    }
    return true;
}

std::size_t SphericalDelaunay::make_delaunay() {
    std::vector<HalfEdge> stack;
    for (TriangleId t = 0; t < triangle_slots(); ++t)
        if (is_live(t))
            for (int i = 0; i < 3; ++i)
                stack.push_back(half_edge(t, i));
    return make_delaunay(stack);
}

std::size_t SphericalDelaunay::make_delaunay(std::vector<HalfEdge> &edges) {
    std::size_t flips = 0;
    legalize_from(edges, nullptr, false, &flips);
    return flips;
}

bool SphericalDelaunay::move_vertex(VertexId v, const Vec3 &p) {
    HalfEdge from = leaving(v);
    if (from == no_half_edge || origin(from) != v)
        return false;
    return move_vertex_from(from, p);
}

bool SphericalDelaunay::move_vertex_from(HalfEdge from, const Vec3 &p,
                                         std::vector<VertexId> *flipped,
                                         const std::function<bool()> &accept) {
    const VertexId v = origin(from);
    // Every triangle of the star must be solid before the move and stay counter-clockwise with v
    // at p. (Moving v out of a ghost triangle changes whether the hull holds the origin, which
    // can leave ghosts far from v that no flip around v reaches.)
    // The edges the move can make non-Delaunay: each spoke v->b once, and each link edge b->c
    // (opposite v). Scratch buffers: smoothing calls this for every node, sweep after sweep.
    std::vector<HalfEdge> &stack = move_stack_;
    stack.clear();
    HalfEdge h = from;
    do {
        TriangleId t = triangle_of(h);
        const Vec3 &b = points_[destination(h)];
        const Vec3 &c = points_[vertex(t, edge_of(h))];
        if (orient(p, b, c) <= 0 || orient(points_[v], b, c) <= 0)
            return false;
        stack.push_back(h);
        stack.push_back(half_edge(t, next3(edge_of(h))));
        h = next_around_origin(h);
    } while (h != from);
    const Vec3 was = points_[v];
    const bool was_bounded = bounded_;
    points_[v] = p;
    bounded_ = bounded_ && bounded(p);
    // Lawson flips, journaled: a non-Delaunay edge whose quadrilateral is not convex (or makes
    // a flat triangle, which has no place in a mesh) means v at p lies inside the hull of its
    // neighbours (closer than rounding resolves), which flips cannot mend; then every flip is
    // undone and v goes back.
    std::vector<FlipRecord> &journal = move_journal_;
    journal.clear();
    if (legalize_from(stack, &journal, true, nullptr)) {
        if (flipped)
            for (const FlipRecord &f : journal) {
                flipped->insert(flipped->end(), f.tv, f.tv + 3);
                flipped->insert(flipped->end(), f.sv, f.sv + 3);
            }
        if (!accept || accept())
            return true;
    }
    undo_flips(journal);
    points_[v] = was;
    bounded_ = was_bounded;
    last_ = triangle_of(from);
    return false;
}

bool SphericalDelaunay::place_vertex_from(HalfEdge from, const Vec3 &p) {
    const VertexId v = origin(from);
    HalfEdge h = from;
    do {
        const TriangleId t = triangle_of(h);
        if (orient(p, points_[destination(h)], points_[vertex(t, edge_of(h))]) <= 0)
            return false;
        h = next_around_origin(h);
    } while (h != from);
    points_[v] = p;
    bounded_ = bounded_ && bounded(p);
    return true;
}

} // namespace globemesh
