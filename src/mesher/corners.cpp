#include "corners.hpp"

#include "mesher_state.hpp"

#include <algorithm>

namespace globemesh::detail {

namespace {

constexpr int next3(int i) {
    return i == 2 ? 0 : i + 1;
}
constexpr int prev3(int i) {
    return i == 0 ? 2 : i - 1;
}
// The most faces of a coast node's fan that go to give a face below the floor a coast side.
constexpr std::size_t fan_reach = 2;

// The removal of ocean faces below the floor, one at a time, the faces behind looked at again.
// A face below the floor with two boundary sides is an ear of the coast at a corner too sharp
// for the faces its segments allow (a narrow inlet's mouth closed beside a long segment, a spike
// of water thinner than a face): it goes when its corner lies within blunt_reach h of its third
// side, which becomes coast; a longer ear first gets its longer boundary side split. A sliver
// with one boundary side goes when its third corner, off the coast, is within reach. A face
// below the floor whose corners are on the boundary across water (one boundary side and the
// corner opposite on the boundary, or no boundary side and two corners on it) spans water
// narrower than itself: with close_straits, it goes as a closing at those corners. A face with
// one corner on the coast and no boundary side first loses the faces between it and the coast
// at that corner (at most fan_reach, within reach of it). Removing a face keeps every other
// face and edge, so the mesh stays constrained Delaunay; each of its corners that it leaves
// between two fans of ocean is pinched (split apart on output).
class Blunter {
public:
    Blunter(CornerMesh &m, bool straits) : m_(m), dt_(m.dt), straits_(straits) {}

    CornerReport run() {
        for (TriangleId t = 0; t < dt_.triangle_slots(); ++t)
            if (is_ocean(t) && quality(t) < blunt_floor)
                todo_.push_back(t);
        std::reverse(todo_.begin(), todo_.end()); // taken from the back: in slot order
        while (!todo_.empty()) {
            const TriangleId t = todo_.back();
            todo_.pop_back();
            if (is_ocean(t) && quality(t) < blunt_floor)
                look_at(t);
        }
        return std::move(report_);
    }

private:
    bool is_ocean(TriangleId t) const { return dt_.is_live(t) && dt_.label(t) == m_.ocean; }
    Vec3 point(VertexId v) const { return dt_.point(v); }
    double quality(TriangleId t) const {
        return triangle_quality(point(dt_.vertex(t, 0)), point(dt_.vertex(t, 1)),
                                point(dt_.vertex(t, 2)));
    }
    // The fans of ocean faces around v (t one of its triangles): 1 inside the ocean or on one
    // stretch of boundary, more where v sits between fans of water.
    int fans(VertexId v, TriangleId t) const {
        // From just after a triangle that is not ocean, so that no fan is counted twice.
        const HalfEdge from = dt_.leaving(v, t);
        HalfEdge start = from;
        while (is_ocean(triangle_of(start)))
            if ((start = dt_.next_around_origin(start)) == from)
                return 1;
        int count = 0;
        bool before = false;
        HalfEdge h = start;
        do {
            const bool in = is_ocean(triangle_of(h));
            count += in && !before;
            before = in;
            h = dt_.next_around_origin(h);
        } while (h != start);
        return count;
    }
    // The half-edge leaving origin(h) before h, clockwise around it (next_around_origin's inverse).
    HalfEdge previous_around_origin(HalfEdge h) const {
        const HalfEdge back = dt_.twin(h);
        return half_edge(triangle_of(back), next3(edge_of(back)));
    }
    bool on_boundary(VertexId v, TriangleId t) const {
        return detail::on_boundary(dt_, m_.ocean, v, t);
    }
    // Whether corner i of t lies within blunt_reach h of its opposite side.
    bool within_reach(TriangleId t, int i) const {
        const HalfEdge across = half_edge(t, i);
        const Vec3 p = point(dt_.vertex(t, i));
        return arc_distance(point(dt_.origin(across)), point(dt_.destination(across)), p) <=
               blunt_reach * km_to_rad(m_.size_km(p));
    }

    void look_at(TriangleId t) {
        // A side with ocean behind, one without, and how many are without.
        int inner = -1, outer = -1, sides = 0;
        for (int i = 0; i < 3; ++i) {
            if (is_ocean(triangle_of(dt_.twin(half_edge(t, i)))))
                inner = i;
            else
                outer = i, ++sides;
        }
        if (sides == 3) {
            remove(t, SegmentKind::coast);
            ++report_.blunted;
        } else if (sides == 2) {
            blunt_ear(t, inner);
        } else if (sides == 1 && !on_boundary(dt_.vertex(t, outer), t)) {
            // A sliver on the coast, its corner off the coast within reach: the coast is
            // drawn through that corner (no node is left between fans).
            if (!within_reach(t, outer))
                return;
            remove(t, SegmentKind::coast);
            ++report_.blunted;
        } else if (straits_ && spans_narrow_water(t, sides, outer)) {
            remove(t, SegmentKind::coast);
            report_.straits_at.push_back(centroid(t));
        } else if (sides == 0) {
            open_to_coast(t);
        }
    }

    // A face without a boundary side but with a corner b on the coast: the faces of b's fan
    // between it and the coast (on the side with fewer, at most fan_reach, each within reach of
    // b) go, so that t gets a boundary side and is looked at again.
    void open_to_coast(TriangleId t) {
        int corner = -1;
        for (int i = 0; i < 3; ++i)
            if (on_boundary(dt_.vertex(t, i), t))
                corner = corner < 0 ? i : 3;
        if (corner < 0 || corner == 3)
            return;
        const VertexId b = dt_.vertex(t, corner);
        const HalfEdge at = dt_.leaving(b, t);
        std::vector<TriangleId> runs[2];
        for (int way = 0; way < 2; ++way) {
            HalfEdge h = at;
            for (;;) {
                h = way == 0 ? dt_.next_around_origin(h) : previous_around_origin(h);
                if (!is_ocean(triangle_of(h)) || runs[way].size() > fan_reach)
                    break;
                runs[way].push_back(triangle_of(h));
            }
        }
        std::vector<TriangleId> &run = runs[0].size() <= runs[1].size() ? runs[0] : runs[1];
        if (run.size() > fan_reach)
            return;
        const double reach = blunt_reach * km_to_rad(m_.size_km(point(b)));
        for (const TriangleId f : run)
            for (int i = 0; i < 3; ++i)
                if (arc_angle(point(b), point(dt_.vertex(f, i))) > reach)
                    return;
        for (auto it = run.rbegin(); it != run.rend(); ++it) {
            remove(*it, SegmentKind::coast);
            ++report_.blunted;
        }
        todo_.push_back(t);
    }

    // An ear (two boundary sides meeting at corner c, ocean behind the third).
    void blunt_ear(TriangleId t, int c) {
        const VertexId apex = dt_.vertex(t, c);
        if (within_reach(t, c)) {
            // The new segment is open only where both sides it replaces were.
            const VertexId a = dt_.vertex(t, next3(c)), b = dt_.vertex(t, prev3(c));
            const bool open =
                m_.kind(a, apex) == SegmentKind::open && m_.kind(apex, b) == SegmentKind::open;
            remove(t, open ? SegmentKind::open : SegmentKind::coast);
            ++report_.blunted;
            return;
        }
        // A longer ear: its longer boundary side is split at its midpoint (as the refinement
        // does) and the faces at the new node are looked at again, until the tip is within
        // reach or the side is too short to split.
        const HalfEdge s1 = half_edge(t, next3(c)), s2 = half_edge(t, prev3(c));
        auto length = [&](HalfEdge e) {
            return arc_angle(point(dt_.origin(e)), point(dt_.destination(e)));
        };
        const VertexId v = m_.split_segment(length(s1) >= length(s2) ? s1 : s2);
        if (v == no_vertex)
            return;
        ++report_.splits;
        queue_around(v, dt_.last_triangle());
    }

    // Water narrower than the face: with one boundary side, the corner opposite it is on the
    // boundary within reach of it; with none, two corners are on the boundary (the face joins
    // two stretches of coast) and one of them is within reach of its opposite side.
    bool spans_narrow_water(TriangleId t, int sides, int outer) const {
        if (sides == 1)
            return on_boundary(dt_.vertex(t, outer), t) && within_reach(t, outer);
        int on = 0;
        bool reach = false;
        for (int i = 0; i < 3; ++i)
            if (on_boundary(dt_.vertex(t, i), t)) {
                ++on;
                reach = reach || within_reach(t, i);
            }
        return on >= 2 && reach;
    }

    void queue_around(VertexId v, TriangleId t) {
        const HalfEdge from = dt_.leaving(v, t);
        HalfEdge h = from;
        do {
            if (is_ocean(triangle_of(h)))
                todo_.push_back(triangle_of(h));
            h = dt_.next_around_origin(h);
        } while (h != from);
    }

    Vec3 centroid(TriangleId t) const {
        return normalized(point(dt_.vertex(t, 0)) + point(dt_.vertex(t, 1)) +
                          point(dt_.vertex(t, 2)));
    }

    // t becomes land; each side with ocean behind becomes a segment of `kind` (ocean on its
    // left: the face behind), and each corner left between two fans of ocean is pinched.
    void remove(TriangleId t, SegmentKind kind) {
        dt_.set_label(t, m_.land);
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            const TriangleId behind = triangle_of(dt_.twin(h));
            if (!is_ocean(behind))
                continue;
            dt_.set_constrained(h, true);
            m_.add_segment(dt_.destination(h), dt_.origin(h), kind);
        }
        // A closing may cut the mesh in two: the faces beside it go to cut_sides, as do those
        // beside a removal of a face in cut_sides (it hands that on, so the piece keeps one).
        bool sides = std::find(m_.cut_sides.begin(), m_.cut_sides.end(), t) != m_.cut_sides.end();
        for (int i = 0; i < 3; ++i) {
            const VertexId v = dt_.vertex(t, i);
            queue_around(v, t); // their corners may now be on the boundary
            if (fans(v, t) < 2)
                continue;
            m_.pinched.push_back(v);
            sides = true;
        }
        if (sides)
            for (int k = 0; k < 3; ++k)
                if (const TriangleId behind = triangle_of(dt_.twin(half_edge(t, k)));
                    is_ocean(behind))
                    m_.cut_sides.push_back(behind);
    }

    CornerMesh &m_;
    SphericalDelaunay &dt_;
    bool straits_;
    std::vector<TriangleId> todo_;
    CornerReport report_;
};

} // namespace

CornerReport blunt_corners(CornerMesh &m, bool close_straits) {
    return Blunter(m, close_straits).run();
}

} // namespace globemesh::detail

namespace globemesh::mesher_internal {

void blunt_sharp_corners(Mesher &m, const MesherOptions &options) {
    detail::CornerMesh cm{m.dt,
                          ocean,
                          land,
                          m.size_km,
                          [&](VertexId a, VertexId b) {
                              const auto it = m.segments.find(key(a, b));
                              return it != m.segments.end() ? it->second : SegmentKind::coast;
                          },
                          [&](VertexId a, VertexId b, SegmentKind k) { m.add_segment(a, b, k); },
                          [&](HalfEdge h) { return m.split_segment(h); },
                          m.pinched,
                          m.cut_sides};
    const detail::CornerReport corners = detail::blunt_corners(cm, options.close_straits);
    MesherReport &report = m.report;
    report.corners_blunted += corners.blunted;
    report.encroached_splits += corners.splits;
    report.straits_closed += corners.straits_at.size();
    for (const Vec3 &p : corners.straits_at)
        report.straits_closed_at.push_back(p);
}

} // namespace globemesh::mesher_internal
