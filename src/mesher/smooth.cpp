// Improvement: smoothing sweeps and relaxation towards valence 6.
#include "mesher_state.hpp"

#include <limits>

#include "../delaunay/hilbert.hpp"

namespace globemesh::mesher_internal {

// A smoothing move shorter than this fraction of h is not made, and the node is left out of the
// next sweep unless a neighbour moves: most of the sweeps' time saved, the quality the same.
constexpr double settle_fraction = 0.01;

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
// flipping there too made more coast faces below q 0.8 than it mended. Their neighbours on the
// coast take part in the flips (their valence defects had left most of the faces below q 0.8
// with no corner on the coast: NE 1:10m at 100 km, 172 of 177) but are not among the free
// neighbours moved with the flipped corners. The neighbours of an open boundary (a region's
// edge, a part's border) keep the lattice's connectivity: flipping them too left the joined
// aqua-planet's worst faces at its borders at q 0.673 (0.800 without). Returns the flips made;
// the nodes moved get their bit in `active` and lose `as_made`.
std::size_t relax_valence(Mesher &m, std::vector<char> &as_made,
                          std::vector<std::uint8_t> &active) {
    SphericalDelaunay &dt = m.dt;
    const std::size_t nv = dt.vertex_count();
    std::vector<int> defect(nv, -6);
    std::vector<char> coastal(nv, 0);                    // a boundary node or its neighbour
    std::vector<char> open_end(nv, 0), near_open(nv, 0); // an open segment's node, its neighbour
    for (const auto &[e, kind] : m.segments)
        if (kind == SegmentKind::open)
            open_end[e.first] = open_end[e.second] = 1;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        ++defect[a], ++defect[b], ++defect[c];
        if (m.is_fixed(a) || m.is_fixed(b) || m.is_fixed(c))
            coastal[a] = coastal[b] = coastal[c] = 1;
        if (open_end[a] || open_end[b] || open_end[c])
            near_open[a] = near_open[b] = near_open[c] = 1;
    }
    auto flips_at = [&](VertexId v) { return !m.is_fixed(v) && !near_open[v]; };
    // A flip needs a corner of positive defect at one end of its edge, or one of valence 4
    // opposite it: only the triangles with one are tried (few where the lattice or smoothing
    // left valence 6).
    std::vector<TriangleId> tried;
    auto wants = [&](VertexId v) { return flips_at(v) && (defect[v] > 0 || defect[v] <= -2); };
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        if (wants(dt.vertex(t, 0)) || wants(dt.vertex(t, 1)) || wants(dt.vertex(t, 2)))
            tried.push_back(t);
    }
    std::vector<VertexId> move;
    std::size_t flips = 0;
    for (int pass = 0; pass < relax_passes; ++pass) {
        std::size_t made = 0;
        for (TriangleId t : tried) {
            if (!dt.is_live(t) || dt.label(t) != ocean)
                continue;
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                const HalfEdge g = dt.twin(h);
                if (dt.is_constrained(h) || dt.label(triangle_of(g)) != ocean)
                    continue;
                const VertexId a = dt.origin(h), b = dt.destination(h);
                const VertexId c = dt.vertex(t, i), d = dt.vertex(triangle_of(g), edge_of(g));
                // The sum of squares drops by 2 (gain - 2). At a gain of 2 it stays, and the flip
                // is made when it brings every corner of valence 4 or 8 (or less, or more) among
                // the four to 5, 6 or 7: a 4 among 6s is mended only so. (Each flip lowers the
                // sum, or keeps it and lowers the count of such corners: the passes end.)
                const int gain = defect[a] + defect[b] - defect[c] - defect[d];
                if (gain < 2)
                    continue;
                if (gain == 2 &&
                    (std::max({std::abs(defect[a]), std::abs(defect[b]), std::abs(defect[c]),
                               std::abs(defect[d])}) < 2 ||
                     std::max({std::abs(defect[a] - 1), std::abs(defect[b] - 1),
                               std::abs(defect[c] + 1), std::abs(defect[d] + 1)}) >= 2))
                    continue;
                if (!flips_at(a) || !flips_at(b) || !flips_at(c) || !flips_at(d))
                    continue;
                const Vec3 &pa = dt.point(a), &pb = dt.point(b), &pc = dt.point(c),
                           &pd = dt.point(d);
                if (predicates::orient(pa, pd, pc) <= 0 || predicates::orient(pd, pb, pc) <= 0)
                    continue;
                if (std::min(triangle_quality(pa, pd, pc), triangle_quality(pd, pb, pc)) <
                    relax_floor)
                    continue;
                dt.flip(h);
                --defect[a], --defect[b], ++defect[c], ++defect[d];
                move.insert(move.end(), {a, b, c, d});
                ++made;
                break; // t is another triangle now
            }
        }
        flips += made;
        if (made == 0)
            break;
    }
    if (flips == 0)
        return 0;
    // The flipped corners' free neighbours move too, each from a half-edge leaving it (the moves
    // below change no connectivity, so one lookup serves every round).
    const std::vector<HalfEdge> star = dt.vertex_half_edges();
    for (std::size_t k = 0, n = move.size(); k < n; ++k) {
        const HalfEdge from = star[move[k]];
        HalfEdge h = from;
        do {
            if (!coastal[dt.destination(h)])
                move.push_back(dt.destination(h));
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
            if (!m.ocean_star(from, far))
                continue;
            Vec3 sum{0, 0, 0};
            for (const FarEdge &e : far)
                sum = sum + e.b;
            const Vec3 to = normalized(sum);
            if (lowers_worst_below(to, dt.point(v), far, relax_move_floor))
                continue;
            if (dt.place_vertex_from(from, to))
                as_made[v] = 0, active[v] = 1;
        }
    // Only the triangles around the moved nodes changed (the flipped corners are among them).
    std::vector<HalfEdge> edges;
    for (VertexId v : move) {
        const HalfEdge from = star[v];
        HalfEdge h = from;
        do {
            edges.push_back(h);
            edges.push_back(
                half_edge(triangle_of(h), next3(edge_of(h)))); // the link edge opposite v
            h = dt.next_around_origin(h);
        } while (h != from);
    }
    dt.make_delaunay(edges);
    return flips;
}

namespace {

// The nodes to smooth, along the Hilbert curve, boundary nodes (fixed) left out. When the
// refinement made most of them, they are renumbered in that order first, and the triangles
// after them (SphericalDelaunay::renumber), so that neighbours lie near each other in memory:
// the refinement numbers nodes in the order it makes them, all over the sphere level after
// level, where the lattice's come in Hilbert order already. The stages after and the output's
// numbering follow. `lattice` (per vertex: a lattice node) is renumbered with them.
std::vector<VertexId> visit_in_hilbert_order(Mesher &m, std::vector<char> &lattice) {
    const SphericalDelaunay &dt = m.dt;
    std::vector<VertexId> visit;
    using Key = decltype(detail::hilbert_key(Vec3{}));
    std::vector<std::pair<Key, VertexId>> keyed;
    keyed.reserve(dt.vertex_count());
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        keyed.emplace_back(detail::hilbert_key(dt.point(v)), v);
    std::sort(keyed.begin(), keyed.end());
    if (2 * m.report.lattice_nodes < dt.vertex_count()) {
        std::vector<VertexId> new_of_old(keyed.size());
        for (std::size_t k = 0; k < keyed.size(); ++k)
            new_of_old[keyed[k].second] = static_cast<VertexId>(k);
        for (std::size_t k = 0; k < keyed.size(); ++k)
            keyed[k].second = static_cast<VertexId>(k);
        m.renumber(new_of_old);
        renumber_per_vertex(lattice, new_of_old, char{0});
    }
    for (const auto &kv : keyed)
        if (!m.is_fixed(kv.second))
            visit.push_back(kv.second);
    return visit;
}

// Per vertex: a lattice node among lattice nodes only that has not moved ("as made"). Such a
// node is about where smoothing would leave it (inside a face of the icosahedron, the move is
// under 0.3% of the spacing, below settle_fraction), so it starts settled (its bit in `active`
// cleared) and moves only when a neighbour does; and a triangle of three is the lattice's own
// (q above 0.88), which the quality rounds leave as it is.
std::vector<char> lattice_as_made(const Mesher &m, const std::vector<char> &lattice,
                                  std::vector<std::uint8_t> &active) {
    const SphericalDelaunay &dt = m.dt;
    std::vector<char> as_made(dt.vertex_count(), 0);
    if (m.report.lattice_nodes == 0)
        return as_made;
    as_made = lattice; // then those with every neighbour a lattice node too
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t))
            continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        if (!lattice[a] || !lattice[b] || !lattice[c])
            as_made[a] = as_made[b] = as_made[c] = 0;
    }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (as_made[v])
            active[v] = 0;
    return as_made;
}

// The smoothing sweeps: each node moves to the area / h^2 weighted mean of its star's
// circumcentres (optimal Delaunay triangulation, Chen & Xu), flips following.
class Sweeps {
public:
    Sweeps(Mesher &m, std::vector<char> &as_made, std::vector<std::uint8_t> &active)
        : m(m), dt(m.dt), as_made(as_made), active(active) {}
    void sweep(const std::vector<VertexId> &visit);
    void release_sizes() { std::vector<float>().swap(vertex_size); }

private:
    Mesher &m;
    SphericalDelaunay &dt;
    std::vector<char> &as_made;
    // Per vertex, bit 0: visit in this sweep, bit 1: in the next. A node whose move would be
    // shorter than settle_fraction of h stays and stays off the next sweep, unless a neighbour
    // moves.
    std::vector<std::uint8_t> &active;
    std::vector<FarEdge> far;   // a star's far edges b -> c (triangles v, b, c)
    std::vector<VertexId> ring; // the star's outer vertices
    // Per vertex, the size there (km; NaN: not asked yet): a triangle's size is the mean of its
    // corners' (the size at its centroid where the field is linear over it; the grid's cells
    // are about hfloor / 2), each evaluated when first asked and again when its node moves,
    // instead of once per star triangle visited (the refinement's badness keeps the size at the
    // centroid: from the corners it cost graded fields quality). No node is added while it is
    // in use.
    std::vector<float> vertex_size =
        std::vector<float>(dt.vertex_count(), std::numeric_limits<float>::quiet_NaN());

    double corner_size_km(TriangleId t) {
        double sum = 0;
        for (int i = 0; i < 3; ++i) {
            float &h = vertex_size[dt.vertex(t, i)];
            if (std::isnan(h))
                h = static_cast<float>(m.size_km(dt.point(dt.vertex(t, i))));
            sum += h;
        }
        return sum / 3;
    }
    void smooth_node(VertexId v, HalfEdge from);
};

void Sweeps::sweep(const std::vector<VertexId> &visit) {
    // One vertex map per sweep; flips make entries stale, so each serves as a walk hint
    // (a triangle next to v) rather than an answer: the walk from it is a step or two.
    const std::vector<HalfEdge> star = dt.vertex_half_edges();
    for (std::size_t k = 0; k < visit.size(); ++k) {
        const VertexId v = visit[k];
        if (!(active[v] & 1))
            continue;
        // The next stars' entries are far apart in memory: ask for them ahead.
        if (k + 16 < visit.size())
            __builtin_prefetch(&star[visit[k + 16]]);
        if (k + 8 < visit.size() && star[visit[k + 8]] != no_half_edge)
            __builtin_prefetch(&dt.point(dt.destination(star[visit[k + 8]])));
        if (star[v] == no_half_edge)
            continue;
        HalfEdge from = star[v];
        if (dt.origin(from) != v || !dt.is_live(triangle_of(from)))
            from = dt.leaving(v, triangle_of(from));
        if (from == no_half_edge || dt.origin(from) != v)
            continue;
        smooth_node(v, from);
    }
    for (auto &a : active)
        a >>= 1;
}

// Moves v (`from` leaves it) to its star's weighted mean, when the star is all ocean.
void Sweeps::smooth_node(VertexId v, HalfEdge from) {
    // Only nodes inside the kept ocean move.
    Vec3 sum{0, 0, 0};
    HalfEdge h = from;
    std::size_t guard = 0;
    far.clear();
    ring.clear();
    double hk = 0;
    do {
        TriangleId t = triangle_of(h);
        if (dt.label(t) != ocean)
            return;
        far.emplace_back(dt.point(dt.destination(h)), dt.point(dt.vertex(t, edge_of(h))));
        ring.push_back(dt.destination(h));
        const Vec3 &a = dt.point(dt.vertex(t, 0));
        const Vec3 &b = dt.point(dt.vertex(t, 1));
        const Vec3 &c = dt.point(dt.vertex(t, 2));
        Vec3 n = cross(b - a, c - a); // |n| = twice the chordal area
        double area = 0.5 * norm(n);
        // Optimal Delaunay triangulation update (Chen & Xu): weight the circumcentres by
        // area / h^2 so that graded meshes keep their grading.
        hk = corner_size_km(t);
        sum = sum + (area / (hk * hk)) * normalized(n);
        h = dt.next_around_origin(h);
    } while (h != from && ++guard < 64);
    if (norm(sum) == 0)
        return;
    // Refuse a move that would bring the worst triangle of the star below 0.6 and
    // below where it was (smoothing must not flatten triangles against the coast).
    const Vec3 target = normalized(sum);
    // The quality before the move is needed only when the move would go below 0.6. (A
    // move that would fold the star counts as -1: move_vertex_from refuses it anyway.)
    if (norm(target - dt.point(v)) < settle_fraction * km_to_rad(hk))
        return;
    if (lowers_worst_below(target, dt.point(v), far, 0.6))
        return;
    if (!dt.move_vertex_from(from, target))
        return;
    vertex_size[v] = static_cast<float>(m.size_km(target));
    active[v] |= 2;
    as_made[v] = 0;
    for (VertexId u : ring)
        active[u] |= 2;
}

} // namespace

std::vector<char> smooth(Mesher &m, const MesherOptions &options, VertexId lattice_first,
                         const Progress &progress) {
    SphericalDelaunay &dt = m.dt;
    std::vector<char> lattice(dt.vertex_count(), 0); // the lattice's nodes
    std::fill_n(lattice.begin() + lattice_first, m.report.lattice_nodes, 1);
    const std::vector<VertexId> visit = visit_in_hilbert_order(m, lattice);
    std::vector<std::uint8_t> active(dt.vertex_count(), 1);
    std::vector<char> as_made = lattice_as_made(m, lattice, active);
    std::vector<char>().swap(lattice);
    Sweeps sweeps(m, as_made, active);
    for (int sweep = 0; sweep < options.smooth_iterations; ++sweep) {
        sweeps.sweep(visit);
        if (sweep == options.smooth_iterations - 1) {
            sweeps.release_sizes(); // the relaxation moves nodes without them
            m.report.valence_flips = relax_valence(m, as_made, active);
        }
        globemesh::report(
            progress, 0.75 + 0.2 * (sweep + 1) / std::max(1, options.smooth_iterations), "improve");
    }
    return as_made;
}

} // namespace globemesh::mesher_internal
