// Faces off the islands the coast shaping dropped.
#include "mesher_state.hpp"

#include <array>

namespace globemesh::mesher_internal {

namespace {

// Moving a free node to take a face's centroid off a dropped island (clear_dropped_islands):
// no face of its star may fall below min(its quality, this), which keeps q > 0.8 where a lower
// floor trades it for fewer faces left; the ways out tried are towards the nearest points of
// this many sides of the outline (more change nothing).
constexpr double island_quality_floor = 0.8;
constexpr std::size_t island_exits = 4;

// A dropped island projected gnomonically from its centre c (great-circle arcs become straight
// lines, so the inside test is exact for its arcs) onto the plane of e1, e2.
struct Island {
    const std::vector<Vec3> &outline;
    Vec3 c, e1, e2;
    double radius = 0;          // of the cap around c that holds it
    std::vector<double> px, py; // its outline, projected

    void project(const Vec3 &p, double &x, double &y) const {
        const double w = dot(p, c);
        x = dot(p, e1) / w;
        y = dot(p, e2) / w;
    }
    bool inside(const Vec3 &p) const {
        if (arc_angle(p, c) > radius)
            return false;
        double x, y;
        project(p, x, y);
        bool in = false;
        for (std::size_t i = 0, j = outline.size() - 1; i < outline.size(); j = i++)
            if ((py[i] > y) != (py[j] > y) &&
                x < px[j] + (y - py[j]) * (px[i] - px[j]) / (py[i] - py[j]))
                in = !in;
        return in;
    }
};

// The island's projection; false for an island too large for it (or degenerate).
bool project_island(Island &island) {
    const std::vector<Vec3> &outline = island.outline;
    Vec3 sum{0, 0, 0};
    for (const auto &v : outline)
        sum = sum + v;
    if (norm(sum) == 0 || outline.size() < 3)
        return false;
    const Vec3 c = normalized(sum);
    island.c = c;
    island.e1 = normalized(cross(c, std::abs(c.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    island.e2 = cross(c, island.e1);
    for (const auto &v : outline)
        island.radius = std::max(island.radius, arc_angle(c, v));
    if (island.radius > 0.5)
        return false; // not small: the projection would distort it
    island.px.resize(outline.size());
    island.py.resize(outline.size());
    for (std::size_t i = 0; i < outline.size(); ++i)
        island.project(outline[i], island.px[i], island.py[i]);
    return true;
}

// The moves of a face's centroid g out of the island: to the nearest point of each side of the
// outline, and a little beyond (margin: 1% of h, which covers the checker's own outline between
// the nodes); the nearest first, so that of equal stars the shortest move wins.
void ways_out(const Island &island, const Vec3 &g, double margin,
              std::vector<std::array<double, 3>> &exits, std::vector<Vec3> &shifts) {
    const std::vector<double> &px = island.px, &py = island.py;
    double gx, gy;
    island.project(g, gx, gy);
    exits.clear();
    for (std::size_t i = 0, j = island.outline.size() - 1; i < island.outline.size(); j = i++) {
        const double dx = px[i] - px[j], dy = py[i] - py[j];
        const double l2 = dx * dx + dy * dy;
        const double f =
            l2 > 0 ? std::clamp(((gx - px[j]) * dx + (gy - py[j]) * dy) / l2, 0.0, 1.0) : 0.0;
        const double qx = px[j] + f * dx - gx, qy = py[j] + f * dy - gy;
        const double d = std::hypot(qx, qy);
        if (d > 0)
            exits.push_back({d, qx / d, qy / d});
    }
    std::sort(exits.begin(), exits.end(), [](const auto &a, const auto &b) { return a[0] < b[0]; });
    if (exits.size() > island_exits)
        exits.resize(island_exits);
    shifts.clear();
    for (const auto &[d, ux, uy] : exits)
        shifts.push_back(normalized(island.c + (gx + (d + margin) * ux) * island.e1 +
                                    (gy + (d + margin) * uy) * island.e2) -
                         g);
}

// clear_dropped_islands' state: the faces near the island at hand and the scratch of the moves.
class IslandClearing {
public:
    IslandClearing(Mesher &m) : m(m), dt(m.dt), seen(dt.triangle_slots(), 0) {}
    // The faces left with their centroid on the island; the faces around it go to `nearby`.
    std::size_t clear(const Island &island, MesherReport &report, std::vector<TriangleId> &nearby);

private:
    Mesher &m;
    SphericalDelaunay &dt;
    std::vector<TriangleId> near, around, stack;
    std::vector<FarEdge> far;
    std::vector<std::array<double, 3>> exits; // distance, unit direction in the projection
    std::vector<Vec3> shifts;                 // the centroid's move for each way out
    std::vector<std::uint32_t> seen;
    std::uint32_t stamp = 0;
    TriangleId hint = no_triangle;

    void gather(const Island &island, double reach);
    bool move_off(const Island &island, TriangleId t);
};

// The ocean faces near the island (`around`) and those of them centred on it (`near`): from the
// one holding its centre, out to the faces whose centroid is within `reach` of the centre.
void IslandClearing::gather(const Island &island, double reach) {
    near.clear();
    around.clear();
    hint = dt.locate(island.c, hint);
    if (hint == no_triangle || !dt.is_live(hint))
        return;
    stack.assign(1, hint);
    seen[hint] = ++stamp;
    while (!stack.empty()) {
        const TriangleId t = stack.back();
        stack.pop_back();
        if (dt.label(t) == ocean) {
            around.push_back(t);
            if (island.inside(m.centroid(t)))
                near.push_back(t);
        }
        for (int i = 0; i < 3; ++i) {
            const TriangleId nb = dt.neighbour(t, i);
            if (nb == no_triangle || seen[nb] == stamp)
                continue;
            seen[nb] = stamp;
            if (arc_angle(m.centroid(nb), island.c) < reach)
                stack.push_back(nb);
        }
    }
}

// Moves the free corner of face t whose star stays best three times the way out of the
// centroid (which moves a third as far), when no face of the star falls below min(its quality,
// island_quality_floor) or gets its centroid onto the island.
bool IslandClearing::move_off(const Island &island, TriangleId t) {
    const Vec3 g = m.centroid(t);
    ways_out(island, g, 0.01 * km_to_rad(m.size_km(g)), exits, shifts);
    double best = -1;
    HalfEdge best_from = no_half_edge;
    Vec3 best_to{};
    for (int k = 0; k < 3; ++k) {
        const VertexId v = dt.vertex(t, k);
        if (m.is_fixed(v))
            continue;
        const HalfEdge from = dt.leaving(v, t);
        if (from == no_half_edge || dt.origin(from) != v || !m.ocean_star(from, far))
            continue;
        const Vec3 &p0 = dt.point(v);
        for (const Vec3 &shift : shifts) {
            const Vec3 to = normalized(p0 + 3.0 * shift);
            double worst = 1;
            for (const FarEdge &e : far) {
                const double q = triangle_quality(to, e.b, e.c, e.length);
                if (predicates::orient(to, e) <= 0 || island.inside(normalized(to + e.b + e.c)) ||
                    q < std::min(island_quality_floor, triangle_quality(p0, e.b, e.c, e.length))) {
                    worst = -1;
                    break;
                }
                worst = std::min(worst, q);
            }
            if (worst > best) {
                best = worst;
                best_from = from;
                best_to = to;
            }
        }
    }
    return best_from != no_half_edge && dt.move_vertex_from(best_from, best_to);
}

std::size_t IslandClearing::clear(const Island &island, MesherReport &report,
                                  std::vector<TriangleId> &nearby) {
    // Within the island's radius plus two edges of its centre.
    const double reach = island.radius + 2 * km_to_rad(m.size_km(island.c));
    gather(island, reach);
    bool moved = false;
    for (const TriangleId t : near) {
        if (!dt.is_live(t) || dt.label(t) != ocean || !island.inside(m.centroid(t)))
            continue; // moved already
        if (move_off(island, t)) {
            ++report.island_centroids_moved;
            moved = true;
        }
    }
    // What is left (the flips after a move may make another such face): counted, not chased.
    // The faces around go to the land test, which reads the island at full resolution. With
    // no move the first gathering still holds.
    if (moved)
        gather(island, reach);
    nearby.insert(nearby.end(), around.begin(), around.end());
    return near.size();
}

} // namespace

// Keeps face centroids off the islands the coast shaping dropped: a model that samples depth
// at face centres would otherwise put those faces on land. Each island is projected
// gnomonically from its centre; a face whose centroid lies inside gets one free corner moved
// three times the way out of the centroid past the nearest point of the island's outline (the
// centroid moves a third as far), the corner whose star stays best, when no face of the star
// falls below min(its quality, 0.8) or gets its centroid onto the island. Returns the faces
// left with their centroid on a dropped island; the faces around each island (whose centroid is
// within its radius plus two edges) go to `nearby`.
std::size_t clear_dropped_islands(Mesher &m, const Boundary &boundary, MesherReport &report,
                                  std::vector<TriangleId> &nearby) {
    std::size_t left = 0;
    IslandClearing clearing(m);
    for (const auto &outline : boundary.dropped_islands) {
        Island island{outline, {}, {}, {}, 0, {}, {}};
        if (!project_island(island))
            continue;
        left += clearing.clear(island, report, nearby);
    }
    return left;
}

} // namespace globemesh::mesher_internal
