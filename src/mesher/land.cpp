// Land clean-up: faces centred on land removed, or nudged off it.
#include <unordered_set>

#include "globemesh/parts.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// Removing the faces centred on land (remove_land_faces): a face that would pinch the mesh at
// a corner may take along at most this many water faces of that corner's fan (or the water it
// cuts off, up to inlet_area h^2; 3 removes no more than 2); no removal leaves on the boundary
// a node farther than land_exposed_reach times h from the source coast (0.5: the 95th
// percentile stays under the h/4).
constexpr std::size_t land_fan_faces = 2;
// The faces left on land then get a corner moved (nudge_off_land) towards the water nearest
// the centroid (the nudge_water nearest points of a grid of nudge_grid rows on the face), each
// of nudge_reaches times the way from the centroid (the centroid moves a third as far), where
// no triangle falls below min(its star's worst, nudge_floor): the fewest faces left on land
// for the quality kept (a finer grid, a longer reach or a second pass leave as many).
constexpr double nudge_reaches[3] = {2.0, 3.1, 4.0};
constexpr int nudge_grid = 12;
constexpr double nudge_floor = 0.6;
constexpr std::size_t nudge_water = 8;
// With `straits` (close_straits), a node a removal puts on the boundary may lie up to this times h
// from the coast, which lets the last straits beside islands the shaping dropped close too.
constexpr double strait_exposed_reach = 0.75;
// A face centred on land whose removal would join two boundary loops goes only when at least
// this many of its 6 halfway points (remove_land_faces, land_points) are on land too.
constexpr int join_land_points = 3;

namespace {

// remove_land_faces' state (its lambdas, as members): the boundary loops, the faces of the
// removal being tried and its counts.
class LandRemoval {
public:
    LandRemoval(Mesher &m, const LandTest &land_test, const MesherOptions &options,
                MesherReport &report, BoundaryLoops &loops_state, bool straits)
        : m(m), dt(m.dt), land_test(land_test), pocket_area(options.inlet_area),
          borders(options.lattice_within), close_straits(options.close_straits), report(report),
          loops_state(loops_state), straits(straits),
          side_faces(m.cut_sides.begin(), m.cut_sides.end()) {}
    std::size_t run(std::vector<TriangleId> island_faces, std::vector<TriangleId> &left_faces);

private:
    Mesher &m;
    SphericalDelaunay &dt;
    const LandTest &land_test;
    const double pocket_area;
    const std::vector<Vec3> &borders; // a part's (MesherOptions::lattice_within)
    const bool close_straits;
    MesherReport &report;
    BoundaryLoops &loops_state;
    const bool straits;
    std::unordered_set<TriangleId> side_faces; // Mesher::cut_sides, to find one a removal takes
    // The boundary: each boundary half-edge's origin -> destination (one per boundary vertex in
    // a manifold), and its half-edges with the ocean on the left.
    std::unordered_map<VertexId, VertexId> next_on_boundary;
    std::vector<HalfEdge> boundary_edges;
    // try_remove's: the faces tried, their corners (each with a half-edge leaving it), a
    // union-find over the corners' indices, the corners left between two fans of water.
    std::vector<TriangleId> members;
    std::vector<std::pair<VertexId, HalfEdge>> corners;
    std::vector<VertexId> arc_parent;
    std::vector<VertexId> pinches;
    std::size_t holes = 0, joins = 0, removed_faces = 0;
    bool pocket_at_border = false; // the removal tried is a pocket reaching a part's border
    // remove_face's: the group tried, the flood's stack and its marks.
    std::vector<TriangleId> group, stack;
    std::vector<std::uint32_t> seen_at;
    std::uint32_t stamp = 0;

    bool is_ocean(TriangleId t) const { return dt.is_live(t) && dt.label(t) == ocean; }
    // The next half-edge leaving origin(h) clockwise around it (next_around_origin's reverse):
    // the edge after h's twin in the twin's triangle.
    HalfEdge clockwise_around_origin(HalfEdge h) const {
        const HalfEdge back = dt.twin(h);
        return half_edge(triangle_of(back), next3(edge_of(back)));
    }
    std::uint32_t loop_root(std::uint32_t l) const {
        while (loops_state.parent[l] != l)
            l = loops_state.parent[l];
        return l;
    }
    VertexId index_of(VertexId v) const {
        return static_cast<VertexId>(
            std::lower_bound(corners.begin(), corners.end(), v,
                             [](const auto &c, VertexId x) { return c.first < x; }) -
            corners.begin());
    }
    VertexId arc_root(VertexId i) const {
        while (arc_parent[i] != i)
            i = arc_parent[i];
        return i;
    }
    void trace_loops();
    std::vector<TriangleId> faces_on_land(std::vector<TriangleId> island_faces);
    int land_points(TriangleId t) const;
    void gather(const std::vector<TriangleId> &group);
    bool contact_loops(std::vector<std::uint32_t> &arc_loops, bool &cuts) const;
    bool corners_allowed();
    void commit(const std::vector<std::uint32_t> &arc_loops, bool cuts, TriangleId needed);
    bool try_remove(const std::vector<TriangleId> &group, TriangleId needed);
    bool corners_on_boundary(TriangleId t) const;
    bool on_border(VertexId a, VertexId b) const;
    bool remove_with_pocket(TriangleId t);
    bool remove_with_fan(TriangleId t);
    bool remove_face(TriangleId t);
};

// The loop of each boundary vertex (an id: only equality counts, through loop_root: loops that a
// removal joins share their root). Every edge between ocean and land is a segment: each loop is
// found from its first segment not yet seen and traced around its vertices, so that the step
// costs what the coast has, not what the ocean has.
void LandRemoval::trace_loops() {
    // The boundary half-edge after h (ocean on the left of both): clockwise around h's
    // destination, through the ocean, from the edge of h's triangle that leaves it.
    auto next_on_loop = [&](HalfEdge h) {
        HalfEdge g = half_edge(triangle_of(h), next3(edge_of(h)));
        for (int turns = 0; is_ocean(triangle_of(dt.twin(g))) && turns < 1000; ++turns)
            g = clockwise_around_origin(g);
        return g;
    };
    auto seen = [&](VertexId a, VertexId b) {
        auto it = next_on_boundary.find(a);
        return it != next_on_boundary.end() && it->second == b;
    };
    std::uint32_t &loops = loops_state.count;
    std::vector<std::size_t> starts; // of each loop in boundary_edges
    TriangleId hint = no_triangle;
    for (const auto &[segment, kind] : m.segments) {
        const auto [a, b] = segment;
        if (seen(a, b) || seen(b, a))
            continue;
        const HalfEdge from = dt.leaving(a, hint);
        const HalfEdge e = from == no_half_edge ? no_half_edge : dt.find_edge(from, b);
        if (e == no_half_edge)
            continue;
        hint = triangle_of(e);
        for (const HalfEdge start : {e, dt.twin(e)}) {
            if (!is_ocean(triangle_of(start)) || is_ocean(triangle_of(dt.twin(start))))
                continue;
            HalfEdge h = start;
            starts.push_back(boundary_edges.size());
            do {
                next_on_boundary.emplace(dt.origin(h), dt.destination(h));
                loops_state.of.emplace(dt.origin(h), loops);
                boundary_edges.push_back(h);
                h = next_on_loop(h);
            } while (h != start && boundary_edges.size() <= m.segments.size());
            loops_state.parent.push_back(loops++);
        }
    }
    loops_as_whole(m, boundary_edges, starts, loops_state);
}

// The faces centred on land looked at, sorted: without `straits`, the ocean faces around the
// corners of the faces on the boundary (near 1) and around those corners' neighbours (near 2);
// and those of `island_faces`.
std::vector<TriangleId> LandRemoval::faces_on_land(std::vector<TriangleId> island_faces) {
    std::vector<char> near(dt.vertex_count(), 0);
    std::vector<std::pair<VertexId, HalfEdge>> near_list; // each once, with a half-edge leaving it
    auto mark = [&](TriangleId t, char bit) {
        for (int k = 0; k < 3; ++k) {
            const VertexId v = dt.vertex(t, k);
            if (!near[v])
                near_list.emplace_back(v, half_edge(t, prev3(k)));
            near[v] |= bit;
        }
    };
    auto for_star = [&](HalfEdge from, auto &&visit) {
        HalfEdge h = from;
        do {
            if (is_ocean(triangle_of(h)))
                visit(triangle_of(h));
            h = dt.next_around_origin(h);
        } while (h != from);
    };
    std::vector<TriangleId> faces, candidates;
    if (!straits) {
        for (const HalfEdge h : boundary_edges)
            mark(triangle_of(h), 1);
        const std::size_t first_ring = near_list.size();
        for (std::size_t i = 0; i < first_ring; ++i)
            for_star(near_list[i].second, [&](TriangleId t) { mark(t, 2); });
        for (const auto &[v, from] : near_list)
            for_star(from, [&](TriangleId t) { candidates.push_back(t); });
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    for (TriangleId t : candidates)
        if (land_test.contains(m.centroid(t)))
            faces.push_back(t);
    std::vector<char>().swap(near);
    // The faces around dropped islands not tested already (the islands' lists overlap).
    std::sort(island_faces.begin(), island_faces.end());
    island_faces.erase(std::unique(island_faces.begin(), island_faces.end()), island_faces.end());
    for (TriangleId t : island_faces)
        if (is_ocean(t) && !std::binary_search(candidates.begin(), candidates.end(), t) &&
            land_test.contains(m.centroid(t)))
            faces.push_back(t);
    std::sort(faces.begin(), faces.end());
    faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
    return faces;
}

// Land under the face at the points halfway from its centroid to its corners and to its
// sides' midpoints (of 6).
int LandRemoval::land_points(TriangleId t) const {
    const Vec3 c = m.centroid(t);
    int on_land = 0;
    for (int k = 0; k < 3; ++k) {
        const Vec3 &a = dt.point(dt.vertex(t, k));
        const Vec3 &b = dt.point(dt.vertex(t, next3(k)));
        on_land += land_test.contains(normalized(c + a));
        on_land += land_test.contains(normalized(c + normalized(a + b)));
    }
    return on_land;
}

// Whether every corner of face t is on the boundary: no move of a corner into the water can
// take its centroid off land.
bool LandRemoval::corners_on_boundary(TriangleId t) const {
    for (int k = 0; k < 3; ++k)
        if (loops_state.of.count(dt.vertex(t, k)) == 0)
            return false;
    return true;
}

// The faces of `group` still in the ocean (members), their corners, and the contact arcs: the
// corners on the boundary, joined (arc_parent) by the members' boundary edges.
void LandRemoval::gather(const std::vector<TriangleId> &group) {
    members.clear();
    for (TriangleId t : group)
        if (is_ocean(t))
            members.push_back(t);
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    corners.clear();
    for (TriangleId t : members)
        for (int k = 0; k < 3; ++k)
            corners.emplace_back(dt.vertex(t, k), half_edge(t, prev3(k)));
    std::sort(corners.begin(), corners.end(),
              [](const auto &a, const auto &b) { return a.first < b.first; });
    corners.erase(std::unique(corners.begin(), corners.end(),
                              [](const auto &a, const auto &b) { return a.first == b.first; }),
                  corners.end());
    arc_parent.resize(corners.size());
    for (VertexId i = 0; i < corners.size(); ++i)
        arc_parent[i] = i;
    for (TriangleId t : members)
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            if (!is_ocean(triangle_of(dt.twin(h))))
                arc_parent[arc_root(index_of(dt.origin(h)))] =
                    arc_root(index_of(dt.destination(h)));
        }
}

// The loops the contact arcs lie on, one each (arc_loops), and whether two arcs lie on one loop
// (cuts); false when they do without `straits` (the removal would cut the mesh).
bool LandRemoval::contact_loops(std::vector<std::uint32_t> &arc_loops, bool &cuts) const {
    for (VertexId i = 0; i < corners.size(); ++i) {
        auto it = loops_state.of.find(corners[i].first);
        if (it == loops_state.of.end() || arc_root(i) != i)
            continue;
        const std::uint32_t root = loop_root(it->second);
        if (std::find(arc_loops.begin(), arc_loops.end(), root) != arc_loops.end()) {
            if (!straits)
                return false; // would cut the mesh
            cuts = true;
            continue;
        }
        arc_loops.push_back(root);
    }
    return true;
}

// With the members labelled land: whether every corner keeps at most one fan of water (or, with
// `straits`, a boundary corner more), an interior corner keeps one, and each corner that comes
// onto the boundary lies within reach of the coast. Fills `pinches`.
bool LandRemoval::corners_allowed() {
    const double reach = straits ? strait_exposed_reach : land_exposed_reach;
    pinches.clear();
    for (const auto &[v, from] : corners) {
        const int fans = m.ocean_fans(from, [](TriangleId, int) {});
        const bool was_on_boundary = loops_state.of.count(v) > 0;
        if (fans > 1)
            pinches.push_back(v);
        if ((fans > 1 && !(straits && was_on_boundary)) || (!was_on_boundary && fans == 0))
            return false;
        if (!was_on_boundary &&
            !land_test.coast_within(dt.point(v), reach * km_to_rad(m.size_km(dt.point(v)))))
            return false;
    }
    return true;
}

// Records a removal made: the loops it opened or joined, the strait it closed, the cut's sides.
void LandRemoval::commit(const std::vector<std::uint32_t> &arc_loops, bool cuts,
                         TriangleId needed) {
    std::uint32_t loop;
    if (arc_loops.empty()) {
        loop = loops_state.count++;
        loops_state.parent.push_back(loop);
        ++holes;
    } else {
        loop = arc_loops[0];
        for (std::size_t i = 1; i < arc_loops.size(); ++i)
            loops_state.parent[arc_loops[i]] = loop;
        joins += arc_loops.size() - 1;
    }
    for (const auto &c : corners)
        loops_state.of.emplace(c.first, loop);
    auto add_beside = [&](std::vector<TriangleId> &out) { // the ocean faces beside the members
        for (TriangleId t : members)
            for (int i = 0; i < 3; ++i)
                if (is_ocean(dt.neighbour(t, i)))
                    out.push_back(dt.neighbour(t, i));
    };
    // A strait closed: with `straits`, the removal cut the mesh, joined loops or pinched it at
    // a node (not an island coming back as a hole, or a bite into one coast); or a pocket
    // reaching a part's border went, which may cut the joined mesh.
    if (straits)
        m.pinched.insert(m.pinched.end(), pinches.begin(), pinches.end());
    if (pocket_at_border || (straits && (cuts || !pinches.empty() || arc_loops.size() > 1))) {
        ++report.straits_closed;
        report.straits_closed_at.push_back(m.centroid(needed));
        add_beside(m.strait_sides);
    }
    // A cut or a pinch (the output splits the node) may leave a piece apart, found from the
    // faces beside it (Mesher::cut_sides); a removal that takes one of those faces hands that
    // on to the faces beside it, so every piece apart keeps one.
    const bool takes_side = std::any_of(members.begin(), members.end(),
                                        [&](TriangleId t) { return side_faces.count(t); });
    if (pocket_at_border || (straits && (cuts || !pinches.empty() || takes_side))) {
        const std::size_t from = m.cut_sides.size();
        add_beside(m.cut_sides);
        side_faces.insert(m.cut_sides.begin() + std::ptrdiff_t(from), m.cut_sides.end());
    }
    removed_faces += members.size();
}

// Removes the faces of `group` still in the ocean, which hold `needed`, all or none. They may
// go when the mesh stays a manifold and none of it is cut off: at each of their corners the
// faces left form at most one fan (an interior corner keeps one), and the arcs along which
// they touch the boundary lie on different loops. By Euler's formula, removing a disc that
// touches the boundary in c arcs on c different loops joins those loops into one (c = 0
// opens a hole: a dropped island comes back; c = 1 bites into the coast) and never
// disconnects the mesh; two arcs on one loop would cut it in two. A removal that joins loops
// closes narrow water between two rings: only where most of `needed` is land
// (join_land_points), not because an islet lies under its centroid in open water; with
// `straits`, also where every corner of `needed` is on the boundary, since no nudge can take
// such a face off the land (it would stay centred on it). Every corner that comes onto the
// boundary must lie within land_exposed_reach h of the coast.
bool LandRemoval::try_remove(const std::vector<TriangleId> &group, TriangleId needed) {
    if (!is_ocean(needed))
        return false;
    gather(group);
    std::vector<std::uint32_t> arc_loops; // one per loop touched
    bool cuts = false;                    // two contact arcs on one loop
    if (!contact_loops(arc_loops, cuts))
        return false;
    if ((arc_loops.size() > 1 || cuts) && land_points(needed) < join_land_points &&
        !(straits && corners_on_boundary(needed)))
        return false;
    for (TriangleId t : members)
        dt.set_label(t, land);
    if (!corners_allowed()) {
        for (TriangleId t : members)
            dt.set_label(t, ocean);
        return false;
    }
    commit(arc_loops, cuts, needed);
    return true;
}

// Whether a-b lies on one of a part's borders.
bool LandRemoval::on_border(VertexId a, VertexId b) const {
    return std::any_of(borders.begin(), borders.end(), [&](const Vec3 &n) {
        return std::abs(dot(dt.point(a), n)) < on_border_tolerance &&
               std::abs(dot(dt.point(b), n)) < on_border_tolerance;
    });
}

// Face t with the pocket of ocean it cuts off beyond one of its sides (a bay behind it, whose
// mouth is mostly land), when the pocket's faces centred off land hold at most pocket_area
// h^2 (the inlet rule of close_inlets): a river narrower than its faces goes, a sea behind a
// strait stays. A pocket that reaches a part's border may go on beyond it, unseen (alone, a
// part takes its half of the Sea of Marmara for a pocket; one part keeps it with the Black
// Sea): it goes only where straits close, and as a strait closed (commit).
bool LandRemoval::remove_with_pocket(TriangleId t) {
    const double h = km_to_rad(m.size_km(m.centroid(t)));
    for (int i = 0; i < 3; ++i) {
        const TriangleId n = dt.neighbour(t, i);
        if (!is_ocean(n))
            continue;
        group.assign(1, t);
        stack.assign(1, n);
        seen_at[t] = seen_at[n] = ++stamp;
        double area = 0;
        bool closed = true;
        pocket_at_border = false;
        while (!stack.empty() && closed) {
            const TriangleId u = stack.back();
            stack.pop_back();
            group.push_back(u);
            if (!land_test.contains(m.centroid(u)))
                area +=
                    spherical_triangle_area(dt.point(dt.vertex(u, 0)), dt.point(dt.vertex(u, 1)),
                                            dt.point(dt.vertex(u, 2)));
            for (int j = 0; j < 3; ++j) {
                const TriangleId w = dt.neighbour(u, j);
                const VertexId a = dt.vertex(u, next3(j)), b = dt.vertex(u, prev3(j));
                if (!is_ocean(w) && m.is_open(a, b) && on_border(a, b))
                    pocket_at_border = true;
                if (is_ocean(w) && seen_at[w] != stamp) {
                    seen_at[w] = stamp;
                    stack.push_back(w);
                }
            }
            if (area > pocket_area * h * h || (pocket_at_border && !close_straits))
                closed = false;
        }
        const bool removed = closed && try_remove(group, t);
        pocket_at_border = false;
        if (removed)
            return true;
    }
    return false;
}

// Face t with the fan of water faces between it and the boundary on the shorter side of one of
// its corners, when at most land_fan_faces.
bool LandRemoval::remove_with_fan(TriangleId t) {
    for (int k = 0; k < 3; ++k) {
        // The faces around corner k from t each way to the first face not in the ocean.
        std::vector<TriangleId> sides[2];
        for (int side = 0; side < 2; ++side) {
            const HalfEdge from = half_edge(t, prev3(k)); // leaves vertex k
            HalfEdge h2 = from;
            while (sides[side].size() <= land_fan_faces) {
                h2 = side == 0 ? dt.next_around_origin(h2) : clockwise_around_origin(h2);
                if (!is_ocean(triangle_of(h2)) || triangle_of(h2) == t)
                    break;
                sides[side].push_back(triangle_of(h2));
            }
        }
        auto &fan = sides[0].size() <= sides[1].size() ? sides[0] : sides[1];
        if (fan.empty() || fan.size() > land_fan_faces)
            continue;
        group.assign(1, t);
        group.insert(group.end(), fan.begin(), fan.end());
        if (try_remove(group, t))
            return true;
    }
    return false;
}

// A face alone, else with water faces beside it, where alone it would pinch the mesh at a
// corner or join two loops only through a corner: a pocket, else a fan.
bool LandRemoval::remove_face(TriangleId t) {
    group.assign(1, t);
    if (try_remove(group, t))
        return true;
    return remove_with_pocket(t) || remove_with_fan(t);
}

std::size_t LandRemoval::run(std::vector<TriangleId> island_faces,
                             std::vector<TriangleId> &left_faces) {
    if (!loops_state.traced) {
        loops_state.traced = true;
        trace_loops();
    }
    const std::vector<TriangleId> faces = faces_on_land(std::move(island_faces));
    if (faces.empty())
        return 0;
    seen_at.assign(dt.triangle_slots(), 0);
    // Passes until none goes: one face gone may free the next.
    for (bool removed = true; removed;) {
        removed = false;
        for (TriangleId t : faces)
            if (is_ocean(t) && remove_face(t))
                removed = true;
    }
    std::size_t left = 0;
    left_faces.clear();
    for (TriangleId t : faces)
        if (is_ocean(t)) {
            ++left;
            left_faces.push_back(t);
        }
    report.land_holes += holes;
    report.land_loops_joined += joins;
    report.land_faces_removed += faces.size() - left;
    report.water_faces_removed += removed_faces - (faces.size() - left);
    return left;
}

} // namespace

// Removes the faces whose centroid lies on the source land (MesherOptions::land): under the
// capes the shaped coast cuts across, on the islands it dropped, and across water narrower than
// a face. A model that samples depth at face centres then meets no land there (ocean models
// cull such cells the same way). The faces looked at: those around the corners of the faces
// on the boundary and around those corners' neighbours, and `island_faces`. Each goes alone or
// in a small group, all or none, where the mesh stays one manifold (LandRemoval::try_remove): a
// hole opens where it touches no loop, loops join where it touches several, a group that would cut
// the mesh in two is refused, so a sea behind a strait stays connected. Passes repeat while
// faces go, since one gone may free the next. Returns the faces left on land (listed in
// `left_faces`); the faces removed, the holes opened and the loops joined go to `report`.
//
// With `straits` (close_straits), the faces looked at are `island_faces` alone, and a removal
// may also cut the mesh in two or leave a node between two fans of water (in Mesher::pinched;
// the output splits it); nodes it puts on the boundary may lie up to strait_exposed_reach h
// from the coast. The ocean faces beside each removal that cut or pinched the mesh go to
// Mesher::cut_sides, and each removal that closed a strait (cut, joined or pinched) to
// report.straits_closed.
//
// `loops`: the boundary loops, traced by the first call and kept up to date by its removals
// (the nudge between the calls moves nodes but changes no boundary edge), so that the second
// call takes them as they are.
std::size_t remove_land_faces(Mesher &m, const LandTest &land_test,
                              std::vector<TriangleId> island_faces, const MesherOptions &options,
                              MesherReport &report, std::vector<TriangleId> &left_faces,
                              BoundaryLoops &loops_state, bool straits) {
    return LandRemoval(m, land_test, options, report, loops_state, straits)
        .run(std::move(island_faces), left_faces);
}

// Moves the faces still centred on land (`faces`, from remove_land_faces: in straits kept
// open, or where a removal would pinch the mesh or leave a node far from the coast) off it
// where one corner can take them: an interior corner, or a boundary corner that may slide
// (Mesher::slide_star, within slide_reach h of the coast), goes nudge_reaches times the way
// from the centroid to one of the nudge_water points of the face nearest it that lie in the
// water (a triangular grid of nudge_grid rows), the first that works. A move is kept when,
// on the triangles around the corner and its flips' corners (Mesher::move_if), no triangle
// falls below min(the star's worst, nudge_floor) and fewer faces are centred on land than in
// the corner's star before. The edges between ocean and land are constrained first, so that
// no flip crosses the boundary the removals made. Returns how many fewer faces are centred
// on land; `left` and `left_at` get those still on land and their centroids.
std::size_t nudge_off_land(Mesher &m, const LandTest &land_test, const MesherOptions &options,
                           const std::vector<TriangleId> &faces, std::vector<TriangleId> &left,
                           std::vector<Vec3> &left_at) {
    SphericalDelaunay &dt = m.dt;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        for (int i = 0; i < 3; ++i)
            if (dt.label(dt.neighbour(t, i)) != ocean)
                dt.set_constrained(half_edge(t, i), true);
    }
    auto quality_of = [&](TriangleId t) {
        return triangle_quality(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                dt.point(dt.vertex(t, 2)));
    };
    std::vector<FarEdge> far, land_far;
    std::vector<VertexId> touched;
    std::vector<std::pair<double, Vec3>> water;
    // The corners of the faces and every vertex a move changed the star of: the faces centred
    // on land at the end all lie around them.
    std::vector<std::pair<VertexId, TriangleId>> around; // each with a triangle near it
    for (const TriangleId t : faces)
        if (dt.is_live(t))
            for (int k = 0; k < 3; ++k)
                around.emplace_back(dt.vertex(t, k), t);
    std::size_t fewer = 0;
    for (const TriangleId t : faces) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        const Vec3 c = m.centroid(t);
        if (!land_test.contains(c))
            continue; // an earlier move took it off
        // The water of the face, nearest the centroid first.
        const Vec3 a = dt.point(dt.vertex(t, 0)), b = dt.point(dt.vertex(t, 1)),
                   d = dt.point(dt.vertex(t, 2));
        water.clear();
        for (int i = 0; i <= nudge_grid; ++i)
            for (int j = 0; i + j <= nudge_grid; ++j) {
                const Vec3 p =
                    normalized(double(i) * a + double(j) * b + double(nudge_grid - i - j) * d);
                if (!land_test.contains(p))
                    water.emplace_back(norm(p - c), p);
            }
        std::sort(water.begin(), water.end(),
                  [](const auto &x, const auto &y) { return x.first < y.first; });
        if (water.size() > nudge_water)
            water.resize(nudge_water);
        bool done = false;
        for (int k = 0; k < 3 && !done; ++k) {
            const VertexId v = dt.vertex(t, k);
            const HalfEdge from = half_edge(t, prev3(k)); // leaves v
            // A boundary node slides as in the quality rounds (Mesher::slide_star, slide_reach);
            // one the removals put on the boundary within the reach they allowed it.
            VertexId ends[2];
            const bool slide = !m.ocean_star(from, far);
            if (slide && !m.slide_star(from, far, land_far, ends, true))
                continue;
            const Vec3 p0 = dt.point(v);
            const double reach =
                (m.is_fixed(v) ? slide_reach : land_exposed_reach) * km_to_rad(m.size_km(p0));
            const int land_before = star_faces_on_land(land_test, p0, far);
            const double floor = std::min(star_worst_quality(p0, far), nudge_floor);
            auto try_move = [&](const Vec3 &to) {
                if (star_worst_quality(to, far, floor) < floor)
                    return false;
                if (slide) {
                    if (!in_region(options, to))
                        return false;
                    for (const FarEdge &e : land_far)
                        if (predicates::orient(to, e) <= 0)
                            return false;
                    if (!land_test.coast_within(to, reach))
                        return false;
                }
                // The ocean triangles near v after the move: each at or above floor, fewer centred
                // on land than v's star before.
                int land_after = 0;
                auto holds = [&](TriangleId s) {
                    land_after += land_test.contains(m.centroid(s));
                    return quality_of(s) >= floor;
                };
                if (!m.move_if(from, to, slide ? ends : nullptr, touched, holds,
                               [&] { return land_after < land_before; }))
                    return false;
                fewer += static_cast<std::size_t>(land_before - land_after);
                for (const VertexId u : touched)
                    around.emplace_back(u, triangle_of(from));
                return true;
            };
            for (const auto &[dist, w] : water)
                for (const double reach_factor : nudge_reaches)
                    if (!done)
                        done = try_move(normalized(p0 + reach_factor * (w - c)));
        }
    }
    std::sort(around.begin(), around.end());
    around.erase(std::unique(around.begin(), around.end(),
                             [](const auto &x, const auto &y) { return x.first == y.first; }),
                 around.end());
    std::vector<TriangleId> on;
    for (const auto &[u, near] : around) {
        const HalfEdge first = dt.leaving(u, near);
        HalfEdge h = first;
        do {
            const TriangleId t = triangle_of(h);
            if (dt.label(t) == ocean && land_test.contains(m.centroid(t)))
                on.push_back(t);
            h = dt.next_around_origin(h);
        } while (h != first);
    }
    std::sort(on.begin(), on.end());
    on.erase(std::unique(on.begin(), on.end()), on.end());
    left_at.clear();
    for (const TriangleId t : on)
        left_at.push_back(m.centroid(t));
    left = std::move(on);
    return fewer;
}

} // namespace globemesh::mesher_internal
