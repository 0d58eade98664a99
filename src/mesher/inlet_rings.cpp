// The rings with the inlets close_inlets closed cut out (mesher_state.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// Each ring as a list linked by `next`, each chord that crosses relinking it past the inlet's
// nodes.
InletCut rings_with_inlets_closed(const Mesher &m, const Boundary &boundary,
                                  const std::vector<VertexId> &ids, std::size_t first,
                                  const std::function<bool(const Vec3 &, const Vec3 &)> &crosses) {
    constexpr std::uint32_t none = 0xffffffffu;
    InletCut out;
    std::vector<std::uint32_t> ring_of(m.dt.vertex_count(), none), pos_of(m.dt.vertex_count());
    std::vector<std::vector<std::uint32_t>> next(boundary.rings.size());
    std::vector<std::vector<SegmentKind>> kinds(boundary.rings.size());
    std::size_t offset = 0;
    for (std::uint32_t r = 0; r < boundary.rings.size(); ++r) {
        const std::size_t n = boundary.rings[r].nodes.size();
        kinds[r] = boundary.rings[r].kinds;
        for (std::uint32_t i = 0; i < n; ++i) {
            next[r].push_back(static_cast<std::uint32_t>((i + 1) % n));
            const VertexId v = ids[offset + i];
            ring_of[v] = ring_of[v] == none ? r : none - 1; // none - 1: merged, left out
            pos_of[v] = i;
        }
        offset += n;
    }
    std::vector<std::vector<char>> cut(boundary.rings.size());
    for (std::uint32_t r = 0; r < boundary.rings.size(); ++r)
        cut[r].assign(boundary.rings[r].nodes.size(), 0);
    for (std::size_t k = first; k < m.directed.size(); ++k) {
        const auto [u, v] = m.directed[k];
        const std::uint32_t r = ring_of[u];
        if (r >= none - 1 || ring_of[v] != r)
            continue;
        const std::uint32_t pu = pos_of[u], pv = pos_of[v];
        std::size_t steps = 0;
        for (std::uint32_t p = next[r][pu]; p != pv && steps <= next[r].size(); p = next[r][p])
            ++steps;
        if (steps > next[r].size())
            continue; // v not ahead of u: not this ring's arc
        // The inlet as the source ring had it (closings inside it included), and its chord.
        const std::vector<Vec3> &nodes = boundary.rings[r].nodes;
        bool crossed = crosses(nodes[pv], nodes[pu]);
        for (std::uint32_t p = pu; p != pv && !crossed; p = (p + 1) % nodes.size())
            crossed = crosses(nodes[p], nodes[(p + 1) % nodes.size()]);
        if (!crossed)
            continue;
        for (const Vec3 &c : {nodes[pu], nodes[pv]})
            out.mouths.push_back({c.x, c.y, c.z});
        // The water cut: the fan from u over the arc left (closings before it already cut).
        double area = 0;
        for (std::uint32_t p = next[r][pu]; p != pv; p = next[r][p]) {
            cut[r][p] = 1;
            const Vec3 &a = nodes[pu], &b = nodes[p], &c = nodes[next[r][p]];
            const double t = spherical_triangle_area(a, b, c);
            area += dot(cross(b - a, c - a), a) > 0 ? t : -t;
        }
        ++out.closed;
        out.area_km2 += std::abs(area) * earth_radius_km * earth_radius_km;
        next[r][pu] = pv;
        kinds[r][pu] = SegmentKind::coast;
    }
    std::sort(out.mouths.begin(), out.mouths.end());
    for (std::uint32_t r = 0; r < boundary.rings.size(); ++r) {
        const auto start = std::find(cut[r].begin(), cut[r].end(), 0);
        Ring ring;
        if (start != cut[r].end()) {
            const auto s = static_cast<std::uint32_t>(start - cut[r].begin());
            std::uint32_t p = s;
            do {
                ring.nodes.push_back(boundary.rings[r].nodes[p]);
                ring.kinds.push_back(kinds[r][p]);
                p = next[r][p];
            } while (p != s);
        }
        out.rings.push_back(ring.nodes.size() >= 3 ? std::move(ring) : boundary.rings[r]);
    }
    return out;
}

} // namespace globemesh::mesher_internal
