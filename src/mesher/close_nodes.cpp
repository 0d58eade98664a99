// Coast nodes far closer than the size, merged once the inlets have closed.
#include <algorithm>

#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

namespace {

// The points a merge flips among stay this far (radians, 6 m) from the new segment's ends and
// great circle: closer, the stored points' rounding off the sphere can outweigh its curvature
// and the segment's recovery could fail (SphericalDelaunay::insert_constraint).
constexpr double merge_clearance = 1e-6;

// A boundary node with its star: the previous and next node along the coast (ocean on the
// left of prev -> v -> next), the other neighbours on the ocean and the land side, and the
// constrained spokes (the two coast segments and any closed inlet's, land on both sides).
struct Star {
    VertexId v = no_vertex, prev = no_vertex, next = no_vertex;
    std::vector<HalfEdge> spokes;
    std::vector<VertexId> ocean_side, land_side;
    std::vector<HalfEdge> constrained;
};

class CloseNodes {
public:
    CloseNodes(Mesher &m, const MesherOptions &options)
        : m(m), dt(m.dt), options(options), gone(dt.vertex_count(), 0) {}

    // Passes until no merge is left: a merge can make the next segment along short too. After
    // the first pass over every segment, only the segments a merge made and the short ones
    // left are looked at again: no other segment changed.
    std::size_t run() {
        std::vector<std::pair<VertexId, VertexId>> look_at = m.directed;
        std::size_t merged = 0;
        for (std::size_t pass = merged_in_pass(look_at); pass > 0; pass = merged_in_pass(look_at))
            merged += pass;
        auto involves_gone = [&](const std::pair<VertexId, VertexId> &d) {
            return gone[d.first] || gone[d.second];
        };
        m.directed.erase(std::remove_if(m.directed.begin(), m.directed.end(), involves_gone),
                         m.directed.end());
        return merged;
    }

private:
    struct Short {
        double length;
        VertexId a, b; // the coast segment a -> b, ocean on its left
        bool tiny;     // under close_node_gap h
    };

    // Merges along the short live segments of `look_at`, shortest first; leaves in it the
    // segments to look at in the next pass.
    std::size_t merged_in_pass(std::vector<std::pair<VertexId, VertexId>> &look_at) {
        std::vector<Short> shorts;
        TriangleId hint = no_triangle;
        for (const auto &[a, b] : look_at) {
            if (gone[a] || gone[b])
                continue;
            const HalfEdge h = dt.find_edge(dt.leaving(a, hint), b);
            if (h == no_half_edge)
                continue;
            hint = triangle_of(h);
            if (dt.label(triangle_of(h)) != ocean || dt.label(triangle_of(dt.twin(h))) == ocean)
                continue; // a closed inlet's segment, land on both sides
            const Vec3 &p = dt.point(a), &q = dt.point(b);
            const double length = arc_angle(p, q);
            const double size = km_to_rad(m.size_km(arc_midpoint(p, q)));
            if (length < trigger() * size)
                shorts.push_back({length, a, b, length < options.close_node_gap * size});
        }
        std::sort(shorts.begin(), shorts.end(), [](const Short &x, const Short &y) {
            if (x.length != y.length)
                return x.length < y.length;
            return x.a != y.a ? x.a < y.a : x.b < y.b;
        });
        const std::size_t made_from = m.directed.size(); // the segments merges add follow
        std::size_t merged = 0;
        for (const Short &s : shorts) {
            if (gone[s.a] || gone[s.b])
                continue;
            // Of the two ends, the one nearer the segment that replaces it goes; else the other.
            Star at_a, at_b;
            const bool a_can = star_of(s.a, at_a) && (s.tiny || may_go(at_a)),
                       b_can = star_of(s.b, at_b) && (s.tiny || may_go(at_b));
            const double move_a = a_can ? distance_to_new(at_a) : 1e300;
            const double move_b = b_can ? distance_to_new(at_b) : 1e300;
            const bool a_first = move_a <= move_b;
            if ((a_first ? a_can && drop(at_a) : b_can && drop(at_b)) ||
                (a_first ? b_can && drop(at_b) : a_can && drop(at_a)))
                ++merged;
        }
        look_at.assign(m.directed.begin() + std::ptrdiff_t(made_from), m.directed.end());
        for (const Short &s : shorts)
            if (!gone[s.a] && !gone[s.b])
                look_at.emplace_back(s.a, s.b);
        return merged;
    }

    // A corner of an inlet's mouth closed before a part's split (MesherOptions::mouth_corners).
    bool is_mouth_corner(const Vec3 &p) const {
        return std::binary_search(options.mouth_corners.begin(), options.mouth_corners.end(),
                                  std::array<double, 3>{p.x, p.y, p.z});
    }
    // The segments looked at: under close_node_gap h, or under the dead ends' short chord.
    double trigger() const {
        return std::max(options.close_node_gap, short_chord * options.inlet_width);
    }

    // An end of a segment no shorter than close_node_gap h goes only where the coast moves by
    // less (the new segment passes within close_node_gap h of it), where it is no corner of a
    // closed inlet's mouth (a segment with land on both sides at it: the mouth would move and
    // the inlet's bank come out, its source vertices metres apart), and where it begins no
    // ocean chord under the short chord to another coast node (a mouth the dead ends close by).
    bool may_go(const Star &s) const {
        const double h = km_to_rad(m.size_km(dt.point(s.v)));
        if (distance_to_new(s) >= options.close_node_gap * h || s.constrained.size() > 2 ||
            is_mouth_corner(dt.point(s.v)))
            return false;
        // Every node of the triangulation is a boundary node yet (the lattice and the
        // refinement come later): a spoke to the ocean side is a chord between two of them.
        return std::none_of(s.ocean_side.begin(), s.ocean_side.end(), [&](VertexId w) {
            return arc_angle(dt.point(w), dt.point(s.v)) < short_chord * options.inlet_width * h;
        });
    }

    double distance_to_new(const Star &s) const {
        return arc_distance(dt.point(s.prev), dt.point(s.next), dt.point(s.v));
    }

    // v's star, when v is a node of one coast ring with exactly one coast segment in and one out,
    // every triangle solid, ocean between its next and previous node and land on the other side.
    bool star_of(VertexId v, Star &s) const {
        s = Star{};
        s.v = v;
        if (v < m.ring_of.size() && m.ring_of[v] >= Mesher::shared_ring)
            return false;
        const HalfEdge first = dt.leaving(v);
        if (first == no_half_edge || dt.origin(first) != v)
            return false;
        std::size_t out = 0, in = 0, outs = 0, ins = 0;
        HalfEdge h = first;
        do {
            if (!dt.is_solid(triangle_of(h)))
                return false;
            if (dt.is_constrained(h)) {
                const bool left = dt.label(triangle_of(h)) == ocean;
                const bool right = dt.label(triangle_of(dt.twin(h))) == ocean;
                if (left && right)
                    return false;
                if (left)
                    out = s.spokes.size(), ++outs;
                else if (right)
                    in = s.spokes.size(), ++ins;
                s.constrained.push_back(h);
            }
            s.spokes.push_back(h);
            h = dt.next_around_origin(h);
        } while (h != first);
        if (outs != 1 || ins != 1)
            return false;
        s.next = dt.destination(s.spokes[out]);
        s.prev = dt.destination(s.spokes[in]);
        // Counter-clockwise from the outgoing segment to the incoming one: the ocean's fan.
        const std::size_t n = s.spokes.size();
        for (std::size_t k = out; k != in; k = (k + 1) % n) {
            if (dt.label(triangle_of(s.spokes[k])) != ocean)
                return false;
            if (k != out)
                s.ocean_side.push_back(dt.destination(s.spokes[k]));
        }
        for (std::size_t k = in; k != out; k = (k + 1) % n) {
            if (dt.label(triangle_of(s.spokes[k])) == ocean)
                return false;
            if (k != in)
                s.land_side.push_back(dt.destination(s.spokes[k]));
        }
        // prev-next may already be an edge only as a side of the star's rim (no neighbour
        // between them on one side): elsewhere the hole would be cut by a second edge prev-next.
        const bool joined = dt.find_edge(dt.leaving(s.prev), s.next) != no_half_edge;
        return s.prev != s.next && is_coast(s.prev, v) && is_coast(v, s.next) &&
               (!joined || s.ocean_side.empty() || s.land_side.empty()) &&
               m.segments.count(key(s.prev, s.next)) == 0 && off_borders(dt.point(v)) &&
               segment_fits(s);
    }

    bool is_coast(VertexId a, VertexId b) const {
        const auto it = m.segments.find(key(a, b));
        return it != m.segments.end() && it->second == SegmentKind::coast;
    }

    // A part's border nodes stay where both parts have them (MesherOptions::lattice_within).
    bool off_borders(const Vec3 &p) const {
        return std::none_of(options.lattice_within.begin(), options.lattice_within.end(),
                            [&](const Vec3 &n) { return dot(p, n) == 0; });
    }

    // The segment prev-next lies inside v's star, so that it splits the hole v leaves in two
    // and crosses no other segment (the coast then moves by less than the short segment). The
    // triangle prev, v, next lies on the fan whose side of the segment is not v's (the ocean's at
    // a notch into the land, the land's at a cape): it is inside that fan when the fan's other
    // neighbours lie strictly beyond the segment's great circle (exact orientations), and every
    // side between them too (minor arcs in that open hemisphere). The fan on v's side is apart
    // from that triangle whatever its neighbours. Every neighbour keeps merge_clearance from the
    // segment's ends, and those beyond the segment from its great circle.
    bool segment_fits(const Star &s) const {
        const Vec3 &p = dt.point(s.prev), &q = dt.point(s.next), &v = dt.point(s.v);
        if (dot(p, v) <= 0 || dot(q, v) <= 0 || arc_angle(p, q) < merge_clearance)
            return false;
        const Vec3 pole = normalized(cross(p, q));
        const int v_side = predicates::orient(p, q, v);
        auto clear = [&](VertexId x, int side) {
            const Vec3 &w = dt.point(x);
            if (arc_angle(w, p) < merge_clearance || arc_angle(w, q) < merge_clearance)
                return false;
            return side == v_side || (dot(w, v) > 0 && predicates::orient(p, q, w) == side &&
                                      std::abs(dot(w, pole)) >= merge_clearance);
        };
        return std::all_of(s.ocean_side.begin(), s.ocean_side.end(),
                           [&](VertexId x) { return clear(x, 1); }) &&
               std::all_of(s.land_side.begin(), s.land_side.end(),
                           [&](VertexId x) { return clear(x, -1); });
    }

    // Removes s.v and joins its neighbours along the coast by one segment; the closed inlets'
    // segments at v go with it. False, with nothing changed, when the core cannot remove v.
    // While it works, the star's rim is held constrained: the flips stay in the hole v leaves
    // (a rim edge with a point hidden behind a segment in its new circle would otherwise flip
    // outwards), so the hole's triangles are the ones relabelled; afterwards the rim is freed
    // and made Delaunay again, each flip there between two triangles of one label.
    bool drop(const Star &s) {
        std::vector<EdgeKey> segments;
        for (const HalfEdge h : s.constrained) {
            segments.push_back(key(s.v, dt.destination(h)));
            dt.set_constrained(h, false);
        }
        std::vector<HalfEdge> rim; // the rim's free edges, from the triangles outside
        for (const HalfEdge spoke : s.spokes) {
            const TriangleId t = triangle_of(spoke);
            const HalfEdge inside = half_edge(t, (edge_of(spoke) + 1) % 3); // opposite v
            if (!dt.is_constrained(inside)) {
                rim.push_back(dt.twin(inside));
                dt.set_constrained(inside, true);
            }
        }
        auto free_rim = [&] {
            for (const HalfEdge h : rim)
                dt.set_constrained(h, false);
        };
        if (!dt.remove_vertex_from(s.spokes.front())) {
            free_rim();
            for (const HalfEdge h : s.constrained)
                dt.set_constrained(h, true);
            return false;
        }
        if (!dt.insert_constraint(s.prev, s.next))
            throw DataError("internal: a coast segment could not be recovered after merging "
                            "close coast nodes near " +
                            Mesher::describe(dt.point(s.v)) + "; please report this");
        for (const EdgeKey &e : segments)
            m.segments.erase(e);
        gone[s.v] = 1;
        m.current_ring = m.ring_of[s.prev];
        m.add_segment(s.prev, s.next, SegmentKind::coast);
        // The hole's triangles, closed in by the rim and the new segment: ocean on its left,
        // land on its right. (With no neighbour on a side, the segment was a side of the rim and
        // the triangle there lies outside.)
        const HalfEdge joined = dt.find_edge(dt.leaving(s.prev), s.next);
        // The hole holds two triangles fewer than v had spokes.
        const std::size_t hole = s.spokes.size() - 2;
        const std::size_t labelled =
            (s.ocean_side.empty() ? 0
                                  : label_within_constraints(triangle_of(joined), ocean, hole)) +
            (s.land_side.empty()
                 ? 0
                 : label_within_constraints(triangle_of(dt.twin(joined)), land, hole));
        if (labelled != hole)
            throw DataError("internal: merging close coast nodes near " +
                            Mesher::describe(dt.point(s.v)) +
                            " left a hole not closed in; please report this");
        free_rim();
        dt.set_constrained(joined, true); // when it was a side of the rim
        dt.make_delaunay(rim);
        return true;
    }

    // Labels `seed` and every triangle reached from it across unconstrained edges, up to `most`
    // of them (the hole's; more means it is not closed in); returns how many.
    std::size_t label_within_constraints(TriangleId seed, std::uint8_t label, std::size_t most) {
        std::vector<TriangleId> stack{seed};
        std::vector<TriangleId> seen{seed};
        while (!stack.empty() && seen.size() <= most) {
            const TriangleId t = stack.back();
            stack.pop_back();
            dt.set_label(t, label);
            for (int i = 0; i < 3; ++i) {
                const HalfEdge h = half_edge(t, i);
                const TriangleId nb = triangle_of(dt.twin(h));
                if (dt.is_constrained(h) || std::find(seen.begin(), seen.end(), nb) != seen.end())
                    continue;
                seen.push_back(nb);
                stack.push_back(nb);
            }
        }
        return seen.size();
    }

    Mesher &m;
    SphericalDelaunay &dt;
    const MesherOptions &options;
    std::vector<char> gone; // per vertex: merged away here
};

} // namespace

// Closing an inlet leaves its mouth as a segment, and the nodes either side of it are often the
// source's own vertices (the shaping keeps them where the river's banks would touch): a
// segment of metres to hundreds of metres at a size of kilometres, which the refinement then
// meshes with faces as small. Such a segment, shorter than close_node_gap times the size, loses
// one of its ends, as the coast shaping merges its nodes (CoastOptions::close_node_gap). So does
// one under the dead ends' short chord (a quarter of the size) where the coast moves by less
// than close_node_gap h: the source's vertices along a lagoon's spit or a river's bank.
std::size_t merge_close_coast_nodes(Mesher &m, const MesherOptions &options) {
    if (options.close_node_gap <= 0)
        return 0;
    return CloseNodes(m, options).run();
}

} // namespace globemesh::mesher_internal
