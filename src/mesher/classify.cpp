// Classification: the ocean told from the land, narrow inlets closed, the node estimate.
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// The node estimate (add_node_estimate) splits a triangle larger than estimate_area times the
// square of the smallest size at its corners and centroid while those sizes differ by more than
// estimate_ratio or a side exceeds estimate_reach times the smallest: within about 15% of the
// nodes made, in a fraction of a second (without the area bound the boundary's slivers split
// into ever more slivers).
constexpr double estimate_area = 8;
constexpr double estimate_ratio = 1.25;
constexpr double estimate_reach = 32;

/// Adds to `sum` the nodes (nodes_for_area) the size field asks for over the spherical triangle
/// a, b, c: on pieces split in four at the arcs' midpoints until the size varies little over
/// each (estimate_ratio, estimate_reach), with each piece's 1/h^2 the mean of its corners' and
/// centroid's. A size of metres at the coast and hundreds of km offshore is counted as it grows,
/// not at its smallest over the whole triangle. Stops once `sum` passes `stop`. `each` (may be
/// empty) is told each piece's corners and nodes.
void add_node_estimate(const std::function<double(const Vec3 &)> &size_km, const Vec3 &a,
                       const Vec3 &b, const Vec3 &c, double stop, double &sum,
                       const NodesAt &each) {
    struct Piece {
        Vec3 p[3];
        double h[3]; // radians
    };
    auto h_at = [&](const Vec3 &p) { return km_to_rad(size_km(p)); };
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
        if (area > estimate_area * lo * lo &&
            (hi > estimate_ratio * lo || side > estimate_reach * lo)) {
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
        if (area > 0) {
            const double nodes = nodes_for_area(area, 1 / std::sqrt(inverse / 4));
            sum += nodes;
            if (each)
                each(q.p[0], q.p[1], q.p[2], nodes);
        }
    }
}

// Closes the inlets narrower than options.inlet_width times h, on the triangulation of the
// boundary nodes alone (before refinement, which would otherwise fill them with slivers). An
// unconstrained ocean edge a-b between two nodes of one ring cuts the ocean in two: the ring's
// arc from a to b and the edge close a curve. When a-b is shorter than inlet_width * h at its
// midpoint and one side holds at most inlet_area * h^2 of ocean, with no open (sea) boundary,
// no other ring (every ring stays a boundary loop) and no passage line, that side becomes land and
// a-b a coast segment. A dead-end channel narrower than the bound closes whole, a bit at a time;
// water behind a narrow mouth closes when it is small (a lagoon) or narrow on average too (twice
// its area over its perimeter under inlet_width * h: a river with lakes along it, up to
// inlet_narrow_area h^2), and stays when it is large and wide (the Black Sea behind the
// Bosphorus).
void close_inlets(Mesher &m, const MesherOptions &options, MesherReport &report) {
    SphericalDelaunay &dt = m.dt;
    struct Chord {
        double length;
        double h; // the size at its midpoint, radians
        HalfEdge edge;
        VertexId a, b;
    };
    auto ring = [&](VertexId v) { return v < m.ring_of.size() ? m.ring_of[v] : Mesher::no_ring; };
    std::vector<Chord> chords;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            const VertexId a = dt.origin(h), b = dt.destination(h);
            // Each edge once (both its triangles are ocean: the flood fill crossed it).
            if (a > b || dt.is_constrained(h) || ring(a) >= Mesher::shared_ring ||
                ring(a) != ring(b))
                continue;
            const double length = arc_angle(dt.point(a), dt.point(b));
            const double size = km_to_rad(m.size_km(arc_midpoint(dt.point(a), dt.point(b))));
            if (length < options.inlet_width * size)
                chords.push_back({length, size, h, a, b});
        }
    }
    std::sort(chords.begin(), chords.end(), [](const Chord &x, const Chord &y) {
        if (x.length != y.length)
            return x.length > y.length;
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    std::vector<std::uint32_t> mark(dt.triangle_slots(), 0);
    std::uint32_t stamp = 0;
    // The ocean on one side of `cut` from `seed` (square radians), where the size is h, or -1
    // when the inlet rule keeps it (inlet_closes, its perimeter the cut included), it touches an
    // open boundary or another ring than `own`, or it reaches `other` (the cut does not separate).
    auto flood = [&](TriangleId seed, HalfEdge cut, TriangleId other, std::uint32_t own, double h,
                     std::vector<TriangleId> &out) {
        const double narrow_cap = inlet_narrow_area * h * h;
        ++stamp;
        out.assign(1, seed);
        mark[seed] = stamp;
        double area = 0;
        double perimeter = arc_angle(dt.point(dt.origin(cut)), dt.point(dt.destination(cut)));
        for (std::size_t k = 0; k < out.size(); ++k) {
            const TriangleId t = out[k];
            area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                            dt.point(dt.vertex(t, 2)));
            if (area > narrow_cap || (!options.passages.empty() && on_passage(m, options, t)))
                return -1.0; // too large, or a passage runs through it (it stays open)
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(t, i);
                if (e == cut || e == dt.twin(cut))
                    continue;
                if (dt.is_constrained(e)) {
                    perimeter += arc_angle(dt.point(dt.origin(e)), dt.point(dt.destination(e)));
                    // Another ring inside (an island) would vanish with the inlet: keep it open.
                    if (ring(dt.origin(e)) != own || ring(dt.destination(e)) != own)
                        return -1.0;
                    if (m.is_open(dt.origin(e), dt.destination(e)))
                        return -1.0;
                    continue;
                }
                const TriangleId nb = triangle_of(dt.twin(e));
                if (nb == other)
                    return -1.0;
                if (mark[nb] == stamp || dt.label(nb) != ocean)
                    continue;
                mark[nb] = stamp;
                out.push_back(nb);
            }
        }
        return inlet_closes(area, perimeter, h, options) ? area : -1.0;
    };
    // Passes until nothing closes: a closed tip makes the water behind the next edge out small
    // enough, so a dead-end channel narrower than the bound closes whole, whatever the order.
    std::vector<TriangleId> side[2];
    for (bool closed = true; closed;) {
        closed = false;
        for (const Chord &c : chords) {
            const TriangleId left = triangle_of(c.edge), right = triangle_of(dt.twin(c.edge));
            if (dt.label(left) != ocean || dt.label(right) != ocean)
                continue; // closed already
            const double area_left = flood(left, c.edge, right, ring(c.a), c.h, side[0]);
            const double area_right = flood(right, c.edge, left, ring(c.a), c.h, side[1]);
            if (area_left < 0 && area_right < 0)
                continue;
            const int s = area_right < 0 || (area_left >= 0 && area_left <= area_right) ? 0 : 1;
            for (TriangleId t : side[s])
                dt.set_label(t, land);
            dt.set_constrained(c.edge, true);
            m.current_ring = m.ring_of[c.a];
            // The ocean stays on the segment's left.
            if (s == 0)
                m.add_segment(c.b, c.a, SegmentKind::coast);
            else
                m.add_segment(c.a, c.b, SegmentKind::coast);
            ++report.inlets_closed;
            report.inlet_area_km2 +=
                (s == 0 ? area_left : area_right) * earth_radius_km * earth_radius_km;
            closed = true;
        }
    }
}

namespace {

// Flood fills from triangle `seed` across unconstrained edges, marking component[t] = id;
// returns the area (steradians) of the triangles reached.
double flood_component(const SphericalDelaunay &dt, TriangleId seed, std::uint32_t id,
                       std::vector<std::uint32_t> &component, std::vector<TriangleId> &stack) {
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
            if (dt.is_constrained(h))
                continue;
            TriangleId nb = triangle_of(dt.twin(h));
            if (component[nb] != 0xffffffffu)
                continue;
            component[nb] = id;
            stack.push_back(nb);
        }
    }
    return area;
}

// Floods the components on the left of the boundary segments (their areas into
// component_area, 1 in reaches_open for those beside a region's open segment), then checks that
// every segment has land (or the outside of the region) on its right.
void flood_left_of_segments(const Mesher &m, std::vector<std::uint32_t> &component,
                            std::vector<double> &component_area, std::vector<char> &reaches_open,
                            std::vector<TriangleId> &stack) {
    const SphericalDelaunay &dt = m.dt;
    // Consecutive segments of a ring share a node: each edge's triangle is the next one's
    // hint, which saves a walk from the last triangle across the whole triangulation.
    TriangleId hint = no_triangle;
    for (auto [a, b] : m.directed) {
        HalfEdge h = dt.find_edge(dt.leaving(a, hint), b);
        if (h == no_half_edge)
            throw DataError("internal: a recovered boundary segment is missing");
        hint = triangle_of(h);
        TriangleId left = triangle_of(h);
        if (component[left] == 0xffffffffu) {
            component_area.push_back(flood_component(
                dt, left, static_cast<std::uint32_t>(component_area.size()), component, stack));
            reaches_open.push_back(0);
        }
        if (m.is_open(a, b))
            reaches_open[component[left]] = 1;
    }
    hint = no_triangle;
    for (auto [a, b] : m.directed) {
        HalfEdge h = dt.find_edge(dt.leaving(a, hint), b);
        hint = triangle_of(h);
        TriangleId right = triangle_of(dt.twin(h));
        if (component[right] != 0xffffffffu && component[right] == component[triangle_of(h)])
            throw DataError("the boundary rings do not close the ocean: ocean on both sides of the "
                            "boundary near " +
                            Mesher::describe(dt.point(a)));
        if (component[right] != 0xffffffffu) {
            // Ocean on the right of a segment: two rings of opposite orientation face each other
            // (e.g. an island drawn the wrong way round).
            throw DataError("a boundary ring has the ocean on its right near " +
                            Mesher::describe(dt.point(a)) +
                            ": rings must keep the ocean on their left");
        }
    }
}

} // namespace

void classify_ocean(Mesher &m, const Boundary &boundary, const MesherOptions &options) {
    SphericalDelaunay &dt = m.dt;
    const std::size_t slots = dt.triangle_slots();
    std::vector<std::uint32_t> component(slots, 0xffffffffu);
    std::vector<double> component_area;
    std::vector<char> reaches_open;
    std::vector<TriangleId> stack;
    if (boundary.empty())
        component_area.push_back(flood_component(dt, dt.last_triangle(), 0, component, stack));
    else
        flood_left_of_segments(m, component, component_area, reaches_open, stack);
    reaches_open.resize(component_area.size(), 0);
    std::size_t largest = 0;
    for (std::size_t c = 0; c < component_area.size(); ++c)
        if (component_area[c] > component_area[largest])
            largest = c;
    std::vector<char> kept(component_area.size(), 0);
    for (std::size_t c = 0; c < component_area.size(); ++c) {
        // Water at a region's open edge joins the ocean outside it: no inland sea.
        kept[c] = c == largest || options.keep_inland_seas || reaches_open[c];
        m.report.components.push_back(
            {component_area[c] * earth_radius_km * earth_radius_km, kept[c] != 0});
    }
    if (component_area.empty())
        throw DataError("no ocean is left inside the boundary");
    for (TriangleId t = 0; t < slots; ++t)
        if (dt.is_live(t))
            dt.set_label(t, component[t] != 0xffffffffu && kept[component[t]] ? ocean : land);
}

void mark_sharp_corners(Mesher &m) {
    const SphericalDelaunay &dt = m.dt;
    std::vector<double> angle(dt.vertex_count(), 0.0);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        for (int i = 0; i < 3; ++i) {
            const Vec3 &p = dt.point(dt.vertex(t, i));
            const Vec3 u = dt.point(dt.vertex(t, next3(i))) - p;
            const Vec3 w = dt.point(dt.vertex(t, prev3(i))) - p;
            angle[dt.vertex(t, i)] += std::atan2(norm(cross(u, w)), dot(u, w));
        }
    }
    m.sharp.assign(dt.vertex_count(), 0);
    for (auto [a, b] : m.directed) {
        if (angle[a] > 0 && angle[a] < 60.0 * deg_to_rad)
            m.sharp[a] = 1;
        if (angle[b] > 0 && angle[b] < 60.0 * deg_to_rad)
            m.sharp[b] = 1;
    }
}

void estimate_nodes(Mesher &m, const MesherOptions &options, bool reserve, const NodesAt &each) {
    SphericalDelaunay &dt = m.dt;
    MesherReport &report = m.report;
    std::size_t limit = options.max_nodes;
    if (options.max_memory != 0)
        limit = std::min<std::size_t>(limit, options.max_memory / mesher_bytes_per_node);
    const double stop = double(limit) - double(dt.vertex_count());
    double estimate = 0;
    for (TriangleId t = 0; t < dt.triangle_slots() && estimate <= stop; ++t)
        if (dt.is_live(t) && dt.label(t) == ocean)
            add_node_estimate(m.size_km, dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                              dt.point(dt.vertex(t, 2)), stop, estimate, each);
    report.estimated_nodes = static_cast<std::size_t>(estimate) + dt.vertex_count();
    if (estimate > stop) {
        const std::string nodes = "more than " + std::to_string(limit) + " nodes";
        // Passages refine below --hmin: raising it does not help them.
        const ErrorText passages =
            options.passages.empty()
                ? ErrorText("")
                : ", or ask less of the passages (" + option("passage_cells") + ", fewer lines)";
        if (limit == options.max_nodes)
            throw DataError("the size field asks for " + nodes + " (" + option("max_nodes") +
                            "): raise " + option("hmin_km") + "/" + option("hmax_km") + " or " +
                            option("max_nodes") + passages);
        throw DataError("the size field asks for " + nodes + ", which need more than " +
                        option("max_memory_bytes") + " " +
                        std::to_string(options.max_memory >> 20) + " MiB: raise " +
                        option("hmin_km") + "/" + option("hmax_km") + " or " +
                        option("max_memory_bytes") + passages);
    }
    // The triangulation's arrays sized once for the nodes to come (the estimate is within a few
    // per cent of the nodes made), instead of doubling through the lattice and the refinement:
    // each doubling copied them into new blocks and touched their pages again.
    if (reserve)
        dt.reserve(report.estimated_nodes + report.estimated_nodes / 4);
}

} // namespace globemesh::mesher_internal
