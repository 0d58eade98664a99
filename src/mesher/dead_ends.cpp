// Dead ends the strait closings leave, closed by the inlet rule.
#include <algorithm>

#include "corners.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

namespace {

// A chord under short_chord inlet_width h (mesher_state.hpp) closes by the inlet rule wherever
// it is, not only beside a closing: the mouth of a stub the refinement and the land removals
// left, meshed with faces hundreds of metres across at a size of kilometres.

struct Chord {
    double length;
    double h; // the size at its midpoint, radians
    HalfEdge edge;
    bool short_; // shorter than short_chord inlet_width h
};

class DeadEnds {
public:
    DeadEnds(Mesher &m, const MesherOptions &options)
        : m(m), dt(m.dt), options(options), mark(dt.triangle_slots(), 0),
          beside(dt.triangle_slots(), 0), cut_side(dt.triangle_slots(), 0) {}

    void run(MesherReport &report) {
        for (const TriangleId t : m.strait_sides)
            if (is_ocean(t))
                beside[t] = 1;
        for (const TriangleId t : m.cut_sides)
            cut_side[t] = 1;
        std::vector<Chord> chords = find_chords();
        add_short_chords(chords);
        // Each edge once (both searches may find it), then the longest first.
        std::sort(chords.begin(), chords.end(),
                  [](const Chord &x, const Chord &y) { return x.edge < y.edge; });
        chords.erase(std::unique(chords.begin(), chords.end(),
                                 [](const Chord &x, const Chord &y) { return x.edge == y.edge; }),
                     chords.end());
        std::sort(chords.begin(), chords.end(), [](const Chord &x, const Chord &y) {
            if (x.length != y.length)
                return x.length > y.length;
            return x.edge < y.edge;
        });
        std::vector<TriangleId> side[2];
        for (bool closed = true; closed;) {
            closed = false;
            for (const Chord &c : chords) {
                const TriangleId left = triangle_of(c.edge), right = triangle_of(dt.twin(c.edge));
                if (!is_ocean(left) || !is_ocean(right))
                    continue; // closed already
                const double area[2] = {flood(left, c, right, side[0]),
                                        flood(right, c, left, side[1])};
                if (area[0] < 0 && area[1] < 0)
                    continue;
                const int s = area[1] < 0 || (area[0] >= 0 && area[0] <= area[1]) ? 0 : 1;
                bool cut = false;
                for (const TriangleId t : side[s]) {
                    dt.set_label(t, land);
                    cut = cut || cut_side[t];
                }
                // A basin a closing cut off is found from the faces beside it: the face beside
                // this closing stands for those it closed.
                if (const TriangleId kept = s == 0 ? right : left; cut && !cut_side[kept]) {
                    cut_side[kept] = 1;
                    m.cut_sides.push_back(kept);
                }
                ++report.inlets_closed;
                report.inlet_area_km2 += area[s] * earth_radius_km * earth_radius_km;
                closed = true;
            }
        }
    }

private:
    bool is_ocean(TriangleId t) const { return dt.is_live(t) && dt.label(t) == ocean; }

    // The ocean edges between two boundary nodes, shorter than inlet_width h, among the faces
    // a flood from each face beside a closing reaches within inlet_narrow_area h^2 (an edge
    // may come twice, from two floods).
    std::vector<Chord> find_chords() {
        std::vector<Chord> chords;
        std::vector<TriangleId> reached;
        ++stamp;
        for (const TriangleId seed : m.strait_sides) {
            if (!is_ocean(seed) || mark[seed] == stamp)
                continue;
            const double h = km_to_rad(m.size_km(m.centroid(seed)));
            double area = 0;
            reached.assign(1, seed);
            mark[seed] = stamp;
            for (std::size_t k = 0; k < reached.size() && area <= inlet_narrow_area * h * h; ++k) {
                const TriangleId t = reached[k];
                area += triangle_area(t);
                for (int i = 0; i < 3; ++i) {
                    const TriangleId n = dt.neighbour(t, i);
                    if (!is_ocean(n))
                        continue;
                    const HalfEdge e = half_edge(t, i);
                    if (dt.origin(e) < dt.destination(e))
                        add_chord(e, t, chords);
                    if (mark[n] != stamp) {
                        mark[n] = stamp;
                        reached.push_back(n);
                    }
                }
            }
        }
        return chords;
    }

    void add_chord(HalfEdge e, TriangleId t, std::vector<Chord> &chords) const {
        const VertexId a = dt.origin(e), b = dt.destination(e);
        const double length = arc_angle(dt.point(a), dt.point(b));
        const double h = km_to_rad(m.size_km(arc_midpoint(dt.point(a), dt.point(b))));
        if (length < options.inlet_width * h && detail::on_boundary(dt, ocean, a, t) &&
            detail::on_boundary(dt, ocean, b, t))
            chords.push_back({length, h, e, length < short_chord * options.inlet_width * h});
    }

    // The ocean edges anywhere between two boundary nodes shorter than short_chord inlet_width
    // h (the boundary nodes found from the faces beside land), added to `chords`.
    void add_short_chords(std::vector<Chord> &chords) {
        std::vector<char> on_boundary(dt.vertex_count(), 0);
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
            if (is_ocean(t))
                for (int i = 0; i < 3; ++i)
                    if (!is_ocean(dt.neighbour(t, i)))
                        on_boundary[dt.vertex(t, next3(i))] = on_boundary[dt.vertex(t, prev3(i))] =
                            1;
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
            if (!is_ocean(t))
                continue;
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(t, i);
                const VertexId a = dt.origin(e), b = dt.destination(e);
                if (a > b || !on_boundary[a] || !on_boundary[b] || !is_ocean(dt.neighbour(t, i)))
                    continue;
                const double length = arc_angle(dt.point(a), dt.point(b));
                const double h = km_to_rad(m.size_km(arc_midpoint(dt.point(a), dt.point(b))));
                if (length < short_chord * options.inlet_width * h)
                    chords.push_back({length, h, e, true});
            }
        }
    }

    double triangle_area(TriangleId t) const {
        return spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                       dt.point(dt.vertex(t, 2)));
    }

    // The ocean on one side of chord c from `seed` (square radians), or -1 when it reaches
    // `other` (the chord does not cut it off), touches an open boundary or a passage line, holds
    // no face beside a closing (not a dead end the closings made) unless c is short, or is too
    // large for the inlet rule.
    double flood(TriangleId seed, const Chord &c, TriangleId other, std::vector<TriangleId> &out) {
        ++stamp;
        out.assign(1, seed);
        mark[seed] = stamp;
        const double narrow_cap = inlet_narrow_area * c.h * c.h;
        double area = 0, perimeter = c.length;
        bool at_closing = false;
        for (std::size_t k = 0; k < out.size(); ++k) {
            const TriangleId t = out[k];
            area += triangle_area(t);
            at_closing = at_closing || beside[t];
            if (area > narrow_cap || (!options.passages.empty() && on_passage(m, options, t)))
                return -1.0; // too large, or a passage runs through it (it stays open)
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(t, i);
                if (e == c.edge || e == dt.twin(c.edge))
                    continue;
                const TriangleId n = triangle_of(dt.twin(e));
                if (n == other)
                    return -1.0;
                if (!is_ocean(n)) {
                    const VertexId x = dt.origin(e), y = dt.destination(e);
                    perimeter += arc_angle(dt.point(x), dt.point(y));
                    if (m.is_open(x, y))
                        return -1.0;
                    continue;
                }
                if (mark[n] != stamp) {
                    mark[n] = stamp;
                    out.push_back(n);
                }
            }
        }
        return (at_closing || c.short_) && inlet_closes(area, perimeter, c.h, options) ? area
                                                                                       : -1.0;
    }

    Mesher &m;
    SphericalDelaunay &dt;
    const MesherOptions &options;
    std::vector<std::uint32_t> mark;
    std::uint32_t stamp = 0;
    std::vector<char> beside;   // faces beside a closing (Mesher::strait_sides)
    std::vector<char> cut_side; // faces in Mesher::cut_sides
};

} // namespace

// After the straits close, a channel a closing left as a dead end (the stub of a canal closed
// further along, a creek whose mouth closed) is meshed with faces as narrow as it is, far below
// h. It closes by close_inlets' rule on the mesh as it is: an ocean edge between two boundary
// nodes, shorter than inlet_width h, with at most inlet_area h^2 of water behind it (or narrow
// on average and at most inlet_narrow_area h^2), water that holds a face beside a closing
// (Mesher::strait_sides) and touches no open boundary; or, for an edge shorter than short_chord
// inlet_width h, any water behind it the rule closes. The longest such edge first, so a stub
// closes whole at its mouth. Counted with the inlets closed.
void close_dead_ends(Mesher &m, const MesherOptions &options, MesherReport &report) {
    if (options.close_dead_ends && options.inlet_width > 0)
        DeadEnds(m, options).run(report);
    m.strait_sides.clear();
}

} // namespace globemesh::mesher_internal
