// Improvement: smoothing sweeps and relaxation towards valence 6.
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// Relaxation towards valence 6 (relax_valence): passes of flips over the candidate triangles, a
// flip refused where either new triangle would be below q relax_floor; then rounds of moves to
// the mean of the neighbours, a move refused where the star's worst triangle would fall below
// min(relax_move_floor, where it was): a lower floor let the moves flatten the coast's
// neighbours.
constexpr int relax_passes = 4;
constexpr int relax_rounds = 6;
constexpr double relax_floor = 0.3;
constexpr double relax_move_floor = 0.8;

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

} // namespace globemesh::mesher_internal
