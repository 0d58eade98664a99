// Straits narrower than a face closed.
#include "globemesh/passages.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

namespace {

/// True when a passage line (MesherOptions::passages) meets face t: closing it would close
/// the passage.
bool on_passage(const Mesher &m, const MesherOptions &options, TriangleId t) {
    const SphericalDelaunay &dt = m.dt;
    const Vec3 &a = dt.point(dt.vertex(t, 0)), &b = dt.point(dt.vertex(t, 1)),
               &c = dt.point(dt.vertex(t, 2));
    for (const std::vector<Vec3> &line : options.passages)
        if (line_meets_triangle(line, a, b, c))
            return true;
    return false;
}

} // namespace

// Closes the straits narrower than a face that `faces` (those still centred on land after the
// nudge) lie across (MesherOptions::close_straits): remove_land_faces with `straits`. Of the
// pieces a closing cut the mesh into, the largest stays; the others go under close_inlets'
// rule (at most inlet_area h^2 of water, or narrow on average and at most inlet_narrow_area
// h^2: the rest of the strait, a narrow sound behind it) unless they touch an open boundary,
// and stay otherwise as basins of their own (report.seas_cut_off). Leaves in `faces` those
// still on land.
void close_straits(Mesher &m, const LandTest &land_test, std::vector<TriangleId> &faces,
                   const MesherOptions &options, BoundaryLoops &loops, MesherReport &report) {
    SphericalDelaunay &dt = m.dt;
    auto is_ocean = [&](TriangleId t) { return dt.is_live(t) && dt.label(t) == ocean; };
    std::vector<TriangleId> sides, left;
    // The faces across a passage stay (with those left on land).
    const auto kept = std::stable_partition(
        faces.begin(), faces.end(), [&](TriangleId t) { return !on_passage(m, options, t); });
    std::vector<TriangleId> passage_faces(kept, faces.end());
    faces.erase(kept, faces.end());
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
        while (floods[f].parent != f)
            f = floods[f].parent = floods[floods[f].parent].parent;
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
            Flood &r = floods[root(f)];
            r.area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                              dt.point(dt.vertex(t, 2)));
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
    // A piece a passage runs through stays.
    auto passes_through = [&](std::uint32_t k) {
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == k)
                for (const TriangleId t : floods[f].faces)
                    if (on_passage(m, options, t))
                        return true;
        return false;
    };
    // A piece is whole when none of its floods has faces left to count. The whole ones go
    // under the inlet rule, but for the largest when no piece is left growing (every piece
    // beside the cuts small: one of them stays).
    std::vector<std::uint32_t> whole;
    std::vector<char> growing(floods.size(), 0);
    for (std::uint32_t f = 0; f < floods.size(); ++f)
        if (floods[f].next < floods[f].faces.size())
            growing[root(f)] = 1;
    for (std::uint32_t f = 0; f < floods.size(); ++f)
        if (root(f) == f && !growing[f])
            whole.push_back(f);
    if (std::find(growing.begin(), growing.end(), 1) == growing.end() && !whole.empty())
        whole.erase(
            std::max_element(whole.begin(), whole.end(), [&](std::uint32_t x, std::uint32_t y) {
                return floods[x].area < floods[y].area;
            }));
    for (const std::uint32_t k : whole) {
        const Flood &p = floods[k];
        const double h = km_to_rad(m.size_km(m.centroid(p.faces[0])));
        const bool small = p.area <= options.inlet_area * h * h ||
                           (p.area <= inlet_narrow_area * h * h &&
                            2 * p.area < options.inlet_width * h * p.perimeter);
        if (p.open || !small || passes_through(k))
            continue;
        report.straits_water_km2 += p.area * earth_radius_km * earth_radius_km;
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == k)
                for (const TriangleId t : floods[f].faces) {
                    dt.set_label(t, land);
                    ++(land_test.contains(m.centroid(t)) ? report.land_faces_removed
                                                         : report.water_faces_removed);
                }
    }
    // Where the cuts are, for the count of basins they made (mesh_boundary's output).
    for (const TriangleId t : sides)
        if (is_ocean(t))
            m.cut_sides.push_back(t);
    faces.clear();
    for (const TriangleId t : left)
        if (is_ocean(t))
            faces.push_back(t);
    for (const TriangleId t : passage_faces)
        if (is_ocean(t))
            faces.push_back(t);
}

void clear_land(Mesher &m, const MesherOptions &options, std::vector<TriangleId> island_faces) {
    MesherReport &report = m.report;
    std::vector<TriangleId> left;
    BoundaryLoops loops;
    remove_land_faces(m, *options.land, std::move(island_faces), options.inlet_area, report, left,
                      loops);
    report.land_faces_nudged = nudge_off_land(m, *options.land, left, left, report.land_faces_at);
    if (options.close_straits && !left.empty()) {
        close_straits(m, *options.land, left, options, loops, report);
        report.land_faces_at.clear();
        if (!left.empty())
            report.land_faces_nudged +=
                nudge_off_land(m, *options.land, left, left, report.land_faces_at);
    }
    report.land_faces_left = report.land_faces_at.size();
}

} // namespace globemesh::mesher_internal
