// Faces off the islands the coast shaping dropped.
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// Moving a free node to take a face's centroid off a dropped island (clear_dropped_islands):
// no face of its star may fall below min(its quality, this), which keeps q > 0.8 where a lower
// floor trades it for fewer faces left; the ways out tried are towards the nearest points of
// this many sides of the outline (more change nothing).
constexpr double island_quality_floor = 0.8;
constexpr std::size_t island_exits = 4;

// Keeps face centroids off the islands the coast shaping dropped: a model that samples depth
// at face centres would otherwise put those faces on land. Each island is projected
// gnomonically from its centre (great-circle arcs become straight lines, so the inside test is
// exact for its arcs); a face whose centroid lies inside gets one free corner moved three times
// the way out of the centroid past the nearest point of the island's outline (the centroid
// moves a third as far), the corner whose star stays best, when no face of the star falls
// below min(its quality, 0.8) or gets its centroid onto the island. Returns the faces left
// with their centroid on a dropped island; the faces around each island (whose centroid is
// within its radius plus two edges) go to `nearby`.
std::size_t clear_dropped_islands(Mesher& m, const Boundary& boundary, MesherReport& report,
                                  std::vector<TriangleId>& nearby) {
    SphericalDelaunay& dt = m.dt;
    std::size_t left = 0;
    std::vector<double> px, py;
    std::vector<TriangleId> near, around, stack;
    std::vector<FarEdge> far;
    std::vector<std::array<double, 3>> exits; // distance, unit direction in the projection
    std::vector<Vec3> shifts;                 // the centroid's move for each way out
    std::vector<std::uint32_t> seen(dt.triangle_slots(), 0);
    std::uint32_t stamp = 0;
    TriangleId hint = no_triangle;
    for (const auto& island : boundary.dropped_islands) {
        Vec3 sum{0, 0, 0};
        for (const auto& v : island) sum = sum + v;
        if (norm(sum) == 0 || island.size() < 3) continue;
        const Vec3 c = normalized(sum);
        const Vec3 e1 = normalized(cross(c, std::abs(c.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 e2 = cross(c, e1);
        double radius = 0;
        for (const auto& v : island) radius = std::max(radius, arc_angle(c, v));
        if (radius > 0.5) continue; // not small: the projection would distort it
        auto project = [&](const Vec3& p, double& x, double& y) {
            const double w = dot(p, c);
            x = dot(p, e1) / w;
            y = dot(p, e2) / w;
        };
        px.resize(island.size());
        py.resize(island.size());
        for (std::size_t i = 0; i < island.size(); ++i) project(island[i], px[i], py[i]);
        auto inside = [&](const Vec3& p) {
            if (arc_angle(p, c) > radius) return false;
            double x, y;
            project(p, x, y);
            bool in = false;
            for (std::size_t i = 0, j = island.size() - 1; i < island.size(); j = i++)
                if ((py[i] > y) != (py[j] > y) && x < px[j] + (y - py[j]) * (px[i] - px[j]) / (py[i] - py[j])) in = !in;
            return in;
        };
        // The ocean faces near the island: from the one holding its centre, out to the faces
        // whose centroid is within `radius` plus two edges of the centre.
        const double reach = radius + 2 * km_to_rad(m.size_km(c));
        auto gather = [&] {
            near.clear();
            around.clear();
            hint = dt.locate(c, hint);
            if (hint == no_triangle || !dt.is_live(hint)) return;
            stack.assign(1, hint);
            seen[hint] = ++stamp;
            while (!stack.empty()) {
                const TriangleId t = stack.back();
                stack.pop_back();
                if (dt.label(t) == ocean) {
                    around.push_back(t);
                    if (inside(m.centroid(t))) near.push_back(t);
                }
                for (int i = 0; i < 3; ++i) {
                    const TriangleId nb = dt.neighbour(t, i);
                    if (nb == no_triangle || seen[nb] == stamp) continue;
                    seen[nb] = stamp;
                    if (arc_angle(m.centroid(nb), c) < reach) stack.push_back(nb);
                }
            }
        };
        gather();
        bool moved = false;
        for (const TriangleId t : near) {
            if (!dt.is_live(t) || dt.label(t) != ocean || !inside(m.centroid(t))) continue; // moved already
            // The ways out: from the centroid to the nearest point of each side of the outline,
            // and a little beyond (1% of h, which covers the checker's own outline between the
            // nodes); the nearest first, so that of equal stars the shortest move wins.
            const Vec3 g = m.centroid(t);
            double gx, gy;
            project(g, gx, gy);
            exits.clear();
            for (std::size_t i = 0, j = island.size() - 1; i < island.size(); j = i++) {
                const double dx = px[i] - px[j], dy = py[i] - py[j];
                const double l2 = dx * dx + dy * dy;
                const double f = l2 > 0 ? std::clamp(((gx - px[j]) * dx + (gy - py[j]) * dy) / l2, 0.0, 1.0) : 0.0;
                const double qx = px[j] + f * dx - gx, qy = py[j] + f * dy - gy;
                const double d = std::hypot(qx, qy);
                if (d > 0) exits.push_back({d, qx / d, qy / d});
            }
            std::sort(exits.begin(), exits.end(), [](const auto& a, const auto& b) { return a[0] < b[0]; });
            if (exits.size() > island_exits) exits.resize(island_exits);
            const double margin = 0.01 * km_to_rad(m.size_km(g));
            double best = -1;
            HalfEdge best_from = no_half_edge;
            Vec3 best_to{};
            shifts.clear();
            for (const auto& [d, ux, uy] : exits)
                shifts.push_back(normalized(c + (gx + (d + margin) * ux) * e1 + (gy + (d + margin) * uy) * e2) - g);
            for (int k = 0; k < 3; ++k) {
                const VertexId v = dt.vertex(t, k);
                if (m.is_fixed(v)) continue;
                const HalfEdge from = dt.leaving(v, t);
                if (from == no_half_edge || dt.origin(from) != v || !m.ocean_star(from, far)) continue;
                const Vec3& p0 = dt.point(v);
                for (const Vec3& shift : shifts) {
                    const Vec3 to = normalized(p0 + 3.0 * shift);
                    double worst = 1;
                    for (const FarEdge& e : far) {
                        const double q = triangle_quality(to, e.b, e.c, e.length);
                        if (predicates::orient(to, e) <= 0 || inside(normalized(to + e.b + e.c)) ||
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
            if (best_from != no_half_edge && dt.move_vertex_from(best_from, best_to)) {
                ++report.island_centroids_moved;
                moved = true;
            }
        }
        // What is left (the flips after a move may make another such face): counted, not chased.
        // The faces around go to the land test, which reads the island at full resolution. With
        // no move the first gathering still holds.
        if (moved) gather();
        left += near.size();
        nearby.insert(nearby.end(), around.begin(), around.end());
    }
    return left;
}

} // namespace globemesh::mesher_internal
