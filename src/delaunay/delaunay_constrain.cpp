// SphericalDelaunay: constrained edges, recovered by flips along the arc (Sloan 1993).
#include "globemesh/delaunay.hpp"

#include <utility>
#include <vector>

#include "delaunay_internal.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

// ---------------------------------------------------------------------------------------------
// Constraints (segment recovery)
// ---------------------------------------------------------------------------------------------

bool SphericalDelaunay::insert_constraint(VertexId a, VertexId b) {
    // Journaled, so that a failure changes nothing: flips that cannot finish the edge (another
    // constraint crosses it, or the rounded points near it are not in convex position) would
    // otherwise leave edges that are not locally Delaunay.
    std::vector<HalfEdge> created;
    std::vector<FlipRecord> journal;
    std::vector<std::pair<VertexId, VertexId>> constrained;
    if (recover_segment(a, b, created, journal, constrained) &&
        legalize_from(created, &journal, false, nullptr))
        return true;
    undo_flips(journal);
    // An edge constrained here that no undone flip restored lies between two triangles the
    // flips never touched: it was an edge before, unconstrained.
    for (auto [u, v] : constrained) {
        const HalfEdge from = leaving(u);
        const HalfEdge e = from == no_half_edge ? no_half_edge : find_edge(from, v);
        if (e != no_half_edge)
            set_constrained(e, false);
    }
    return false;
}

// True when the minor arcs a-b and c-d cross at a point interior to both (exact; the sign
// pattern of S2's CrossingSign: the endpoints of each arc straddle the other's great circle,
// and on the same hemisphere, which rules out the antipodal intersection).
static bool arcs_cross(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    int acb = -orient(a, b, c);
    int bda = orient(a, b, d);
    if (acb == 0 || acb != bda)
        return false;
    int cbd = -orient(c, d, b);
    if (cbd != acb)
        return false;
    return orient(c, d, a) == acb;
}

// True when vertex d lies on the minor arc a-b strictly between a and b.
static bool on_arc(const Vec3 &a, const Vec3 &b, const Vec3 &d) {
    return orient(a, b, d) == 0 && arc_angle(a, d) < arc_angle(a, b) &&
           arc_angle(d, b) < arc_angle(a, b);
}

bool SphericalDelaunay::recover_segment(VertexId a, VertexId b, std::vector<HalfEdge> &created,
                                        std::vector<FlipRecord> &journal,
                                        std::vector<std::pair<VertexId, VertexId>> &constrained) {
    if (a == b)
        return true;
    const Vec3 &pa = points_[a];
    const Vec3 &pb = points_[b];
    for (int round = 0; round < 64; ++round) {
        // From the last edge recovered or flipped: the previous segment of a ring ends at a,
        // and the flips below go along the arc, so the lookup stays local
        // (bench/RESULTS-core-coast.md).
        const HalfEdge from = leaving(a, recover_hint_);
        if (from == no_half_edge)
            return false;
        HalfEdge e = find_edge(from, b);
        if (e != no_half_edge) {
            recover_hint_ = triangle_of(e);
            if (!is_constrained(e)) {
                set_constrained(e, true);
                constrained.emplace_back(a, b);
            }
            return true;
        }
        // Rotate around a to the triangle (a, d, third) the arc a->b leaves through its edge
        // d->third; a vertex exactly on the arc splits the constraint.
        HalfEdge exit = no_half_edge;
        HalfEdge h = from;
        do {
            TriangleId s = triangle_of(h);
            int i = edge_of(h);
            VertexId d = destination(h), third = vertex(s, i);
            if (on_arc(pa, pb, points_[d]))
                return recover_segment(a, d, created, journal, constrained) &&
                       recover_segment(d, b, created, journal, constrained);
            if (orient(pa, points_[d], pb) > 0 && orient(pa, points_[third], pb) < 0) {
                exit = half_edge(s, next3(i)); // d -> third, opposite a
                break;
            }
            h = next_around_origin(h);
        } while (h != from);
        if (exit == no_half_edge)
            return false;

        // Walk along the arc, collecting the edges it crosses.
        std::vector<HalfEdge> crossing;
        HalfEdge c = exit;
        for (;;) {
            if (is_constrained(c))
                return false; // another constraint crosses a-b
            crossing.push_back(c);
            HalfEdge o = twin(c);
            TriangleId r = triangle_of(o);
            int k = edge_of(o);
            VertexId apex = vertex(r, k);
            if (apex == b)
                break;
            int side = orient(pa, pb, points_[apex]);
            if (side == 0) {
                if (!on_arc(pa, pb, points_[apex]))
                    return false;
                return recover_segment(a, apex, created, journal, constrained) &&
                       recover_segment(apex, b, created, journal, constrained);
            }
            // r = (apex, third, d): d is right of a->b, third left; leave through the edge whose
            // endpoints are on opposite sides.
            c = side > 0 ? half_edge(r, next3(k)) /* d -> apex */
                         : half_edge(r, prev3(k)) /* apex -> third */;
            if (crossing.size() > 4 * triangle_slots())
                return false;
        }
        // Flip crossing edges until none crosses (Sloan 1993); a non-convex quadrilateral is
        // retried later, after its neighbours have moved. Half-edge ids change under flips, so
        // the queue holds vertex pairs and each is looked up again before it is flipped.
        std::vector<std::pair<VertexId, VertexId>> queue;
        queue.reserve(crossing.size());
        for (HalfEdge e : crossing)
            queue.emplace_back(origin(e), destination(e));
        // In the plane these flips end (Sloan), after O(k^2) of them for k crossings at worst;
        // where rounded points are not in convex position (see insert_constraint) they can
        // cycle, so their number is bounded.
        const std::size_t max_flips = 4 * crossing.size() * crossing.size() + 64;
        std::size_t stall = 0, flips = 0;
        std::size_t head = 0;
        while (head < queue.size()) {
            if (flips > max_flips)
                return false;
            auto [qu, qw] = queue[head++];
            HalfEdge e2 = find_edge(leaving(qu, recover_hint_), qw);
            if (e2 == no_half_edge)
                continue; // already flipped away
            TriangleId s = triangle_of(e2);
            recover_hint_ = s;
            int i = edge_of(e2);
            HalfEdge g = twin(e2);
            const Vec3 &x = points_[vertex(s, i)];
            const Vec3 &u = points_[vertex(s, next3(i))];
            const Vec3 &w = points_[vertex(s, prev3(i))];
            const Vec3 &y = points_[vertex(triangle_of(g), edge_of(g))];
            if (orient(x, u, y) <= 0 || orient(y, w, x) <= 0) {
                queue.emplace_back(qu, qw);
                if (++stall > 2 * (queue.size() - head) + 8)
                    return false;
                continue;
            }
            stall = 0;
            ++flips;
            flip_recorded(e2, &journal);
            // The quadrilateral's outer edges border changed triangles: recheck them afterwards.
            TriangleId r = triangle_of(g);
            created.push_back(half_edge(s, i));
            created.push_back(half_edge(s, prev3(i)));
            created.push_back(half_edge(r, edge_of(g)));
            created.push_back(half_edge(r, prev3(edge_of(g))));
            HalfEdge diag = half_edge(s, next3(i)); // the new diagonal y -> x
            VertexId d0 = origin(diag), d1 = destination(diag);
            bool touches = d0 == a || d0 == b || d1 == a || d1 == b;
            if (!touches && arcs_cross(pa, pb, points_[d0], points_[d1]))
                queue.emplace_back(d0, d1);
            else
                created.push_back(diag);
        }
    }
    return false;
}

} // namespace globemesh
