// Rings read as great-circle arcs where the data drew straight lon/lat edges: an arc bulges
// away from its lon/lat edge (by L^2 tan(lat) / 8R for an edge of length L, 28 m for a 0.5
// degree edge at 25 degrees), so an arc can touch or cross a neighbour that the edge keeps
// clear of. Those arcs are split at their lon/lat midpoints until none does: the polyline then
// follows the lon/lat edge closer at each round (the bulge falls fourfold), and snap rounding
// has left every edge at least half a grid cell from what it does not touch.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "coast_internal.hpp"

namespace globemesh::coast_detail {

namespace {

/// The midpoint of the lon/lat edge a-b (shorter way round; a node on a pole takes the other
/// end's longitude, as the meridian to the pole does).
Vec3 lonlat_midpoint(const Vec3 &a, const Vec3 &b) {
    LonLat p = vec_to_lonlat(a), q = vec_to_lonlat(b);
    constexpr double polar = 90.0 - 1e-9;
    if (std::abs(p.lat) >= polar)
        p.lon = q.lon;
    if (std::abs(q.lat) >= polar)
        q.lon = p.lon;
    if (q.lon - p.lon > 180.0)
        q.lon -= 360.0;
    if (q.lon - p.lon < -180.0)
        q.lon += 360.0;
    double lon = 0.5 * (p.lon + q.lon);
    if (lon < -180.0)
        lon += 360.0;
    if (lon > 180.0)
        lon -= 360.0;
    return lonlat_to_vec(lon, 0.5 * (p.lat + q.lat));
}

} // namespace

std::size_t split_conflicting_arcs(Boundary &boundary, int max_rounds, bool *clear) {
    std::vector<const std::vector<Vec3> *> rings;
    for (const auto &r : boundary.rings)
        rings.push_back(&r.nodes);
    ArcGrid grid(rings);
    // Splitting converges when arcs stray by their bulge; arcs that fold back on each other
    // (a spike of zero width) conflict at every split and would double each round: the nodes
    // added are bounded by the ring nodes (at least 1000), and what is left is refused later.
    std::size_t budget = 1000;
    for (const auto &r : boundary.rings)
        budget += r.nodes.size();
    std::size_t added = 0;
    if (clear)
        *clear = false;
    for (int round = 0; round <= max_rounds; ++round) {
        const std::vector<ArcPair> pairs = grid.conflicts();
        if (clear)
            *clear = pairs.empty();
        if (pairs.empty() || round == max_rounds)
            break;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> arcs; // (ring, arc) to split
        for (const auto &p : pairs) {
            arcs.push_back({p.ring_a, p.seg_a});
            arcs.push_back({p.ring_b, p.seg_b});
        }
        std::sort(arcs.begin(), arcs.end());
        arcs.erase(std::unique(arcs.begin(), arcs.end()), arcs.end());
        if (added + arcs.size() > budget)
            break;
        for (std::size_t k = 0; k < arcs.size();) {
            const std::uint32_t r = arcs[k].first;
            Ring &ring = boundary.rings[r];
            const std::size_t n = ring.nodes.size();
            std::vector<Vec3> nodes;
            std::vector<SegmentKind> kinds;
            std::vector<std::uint32_t> old_of;
            for (std::uint32_t i = 0; i < n; ++i) {
                nodes.push_back(ring.nodes[i]);
                kinds.push_back(ring.kinds[i]);
                const bool split = k < arcs.size() && arcs[k].first == r && arcs[k].second == i;
                old_of.push_back(split ? ArcGrid::none : i);
                if (!split)
                    continue;
                ++k;
                nodes.push_back(lonlat_midpoint(ring.nodes[i], ring.nodes[(i + 1) % n]));
                kinds.push_back(ring.kinds[i]);
                old_of.push_back(ArcGrid::none);
                ++added;
            }
            ring.nodes = std::move(nodes);
            ring.kinds = std::move(kinds);
            grid.replace(r, old_of);
        }
        grid.update();
    }
    return added;
}

} // namespace globemesh::coast_detail
