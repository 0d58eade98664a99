// Stage 2 of the coast: drop small rings, simplify to the local size with topology preserved,
// resample along great-circle arcs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "coast_internal.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"

namespace globemesh {
namespace {

/// Largest arc kept between two simplified nodes (radians): keeps arcs far below pi/2, where
/// the crossing test and "shorter arc" are unambiguous.
constexpr double max_simplified_arc = 0.25;

/// Area to the left of one closed ring on the unit sphere, steradians in [0, 4 pi).
double left_area_sr(const std::vector<Vec3>& nodes) {
    Vec3 sum{};
    for (const auto& v : nodes) sum = sum + v;
    Vec3 ref = norm(sum) > 1e-3 ? normalized(sum) : normalized(nodes[0] + Vec3{0.3, 0.5, 0.7});
    double s = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i)
        s += spherical_triangle_area(ref, nodes[i], nodes[(i + 1) % nodes.size()]);
    s = std::fmod(s, 4 * pi);
    if (s < 0) s += 4 * pi;
    return s;
}

struct ShapedRing {
    const Ring* ring;
    std::vector<double> h_rad;        // target size at every node, radians
    std::vector<std::uint32_t> kept;  // indices of kept nodes, increasing
    std::vector<bool> anchor;         // nodes that must stay
};

/// Douglas-Peucker between kept nodes i < j (indices modulo n): keeps the node farthest from the
/// arc while it is farther than half the local size, or while the arc is too long.
void simplify_span(const ShapedRing& s, std::uint32_t i, std::uint32_t j, std::vector<bool>& keep) {
    const auto& nodes = s.ring->nodes;
    std::uint32_t n = static_cast<std::uint32_t>(nodes.size());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{i, j}};
    while (!stack.empty()) {
        auto [a, b] = stack.back();
        stack.pop_back();
        if (b <= a + 1) continue;
        const Vec3& pa = nodes[a % n];
        const Vec3& pb = nodes[b % n];
        double worst = 0;
        std::uint32_t at = a + 1;
        for (std::uint32_t k = a + 1; k < b; ++k) {
            double r = arc_distance(pa, pb, nodes[k % n]) / (0.5 * s.h_rad[k % n]);
            if (r > worst) {
                worst = r;
                at = k;
            }
        }
        bool too_long = arc_angle(pa, pb) > max_simplified_arc || pa == pb || norm(pa + pb) < 1e-9;
        if (worst > 1.0 || too_long) {
            if (worst <= 1.0) at = a + (b - a) / 2;
            keep[at % n] = true;
            stack.push_back({a, at});
            stack.push_back({at, b});
        }
    }
}

std::vector<Vec3> kept_nodes(const ShapedRing& s) {
    std::vector<Vec3> out;
    out.reserve(s.kept.size());
    for (auto k : s.kept) out.push_back(s.ring->nodes[k]);
    return out;
}

} // namespace

Boundary shape_boundary(const CoastData& coast, const SizeFn& size_km, const MeshOptions& options,
                        CoastReport* report_out, const Progress& progress) {
    if (!size_km) throw UsageError("shape_boundary: no size function given");
    CoastReport rep;
    rep.islands_removed = coast.islands_removed;
    rep.lakes_removed = coast.lakes_removed;
    rep.area_gained_km2 = coast.area_gained_km2;
    rep.area_lost_km2 = coast.area_lost_km2;
    report(progress, 0.0, "shaping coast");

    const double r2 = earth_radius_km * earth_radius_km;
    auto h_at = [&](const Vec3& v) {
        double h = size_km(v);
        if (!(h > 0) || !std::isfinite(h))
            throw UsageError("the target size must be positive (got " + std::to_string(h) + " km)");
        return km_to_rad(h);
    };

    // 1. Small rings: islands (land on the right smaller than a few triangles) and enclosed
    //    water bodies (ocean on the left that small); rings with an open segment always stay.
    std::vector<ShapedRing> shaped;
    bool dropped_water = false;
    for (const Ring& ring : coast.rings.rings) {
        ShapedRing s{&ring, {}, {}, {}};
        s.h_rad.reserve(ring.nodes.size());
        for (const auto& v : ring.nodes) s.h_rad.push_back(h_at(v));
        bool has_open = std::any_of(ring.kinds.begin(), ring.kinds.end(), [](SegmentKind k) { return k == SegmentKind::open; });
        if (!has_open && options.min_island_triangles > 0) {
            double left = left_area_sr(ring.nodes);
            Vec3 sum{};
            for (const auto& v : ring.nodes) sum = sum + v;
            double hc = norm(sum) > 1e-9 ? h_at(normalized(sum)) : s.h_rad[0];
            double threshold = options.min_island_triangles * std::sqrt(3.0) / 4.0 * hc * hc;
            if (left < 2 * pi) { // a closed water body
                if (left < threshold) {
                    ++rep.lakes_removed;
                    rep.area_lost_km2 += left * r2;
                    dropped_water = true;
                    continue;
                }
            } else if (4 * pi - left < threshold) {
                ++rep.islands_removed;
                rep.area_gained_km2 += (4 * pi - left) * r2;
                continue;
            }
        }
        shaped.push_back(std::move(s));
    }
    if (shaped.empty() && dropped_water)
        throw DataError("the ocean of --coast " + options.coast +
                        " is smaller than a few triangles of the target size: lower the size or "
                        "--min-island-triangles");
    report(progress, 0.2, "simplifying coast");

    // 2. Douglas-Peucker on the sphere between anchors (kind changes, plus three spread nodes).
    for (auto& s : shaped) {
        const Ring& ring = *s.ring;
        std::uint32_t n = static_cast<std::uint32_t>(ring.nodes.size());
        std::vector<bool> keep(n, false);
        for (std::uint32_t i = 0; i < n; ++i)
            if (ring.kinds[i] != ring.kinds[(i + n - 1) % n]) keep[i] = true;
        keep[0] = keep[n / 3] = keep[(2 * n) / 3] = true;
        s.anchor = keep;
        std::vector<std::uint32_t> anchors;
        for (std::uint32_t i = 0; i < n; ++i)
            if (keep[i]) anchors.push_back(i);
        for (std::size_t a = 0; a < anchors.size(); ++a) {
            std::uint32_t i = anchors[a];
            std::uint32_t j = a + 1 < anchors.size() ? anchors[a + 1] : anchors[0] + n;
            simplify_span(s, i, j, keep);
        }
        // Thin nodes closer than half the local size to the previous kept node.
        std::uint32_t last = 0;
        for (std::uint32_t i = 1; i < n; ++i) {
            if (!keep[i]) continue;
            if (!s.anchor[i] && arc_angle(ring.nodes[last], ring.nodes[i]) < 0.5 * std::min(s.h_rad[last], s.h_rad[i])) {
                std::uint32_t next = i + 1;
                while (next < n && !keep[next]) ++next;
                std::uint32_t nn = next % n;
                // Only when the merged arc stays short and close to the dropped node.
                if (arc_angle(ring.nodes[last], ring.nodes[nn]) < max_simplified_arc &&
                    arc_distance(ring.nodes[last], ring.nodes[nn], ring.nodes[i]) < 0.5 * s.h_rad[i]) {
                    keep[i] = false;
                    continue;
                }
            }
            last = i;
        }
        for (std::uint32_t i = 0; i < n; ++i)
            if (keep[i]) s.kept.push_back(i);
    }
    report(progress, 0.5, "checking coast topology");

    // 3. Topology: re-insert original nodes into every simplified arc that touches or crosses
    //    another arc, until none does. The full-resolution rings do not conflict, so this ends.
    for (int round = 0;; ++round) {
        std::vector<std::vector<Vec3>> rings;
        rings.reserve(shaped.size());
        for (const auto& s : shaped) rings.push_back(kept_nodes(s));
        std::vector<const std::vector<Vec3>*> ptrs;
        for (const auto& r : rings) ptrs.push_back(&r);
        auto conflicts = coast_detail::find_conflicts(ptrs);
        if (conflicts.empty()) break;
        bool progress_made = false;
        std::vector<std::vector<std::uint32_t>> insert(shaped.size());
        auto refine = [&](std::uint32_t r, std::uint32_t seg) {
            const auto& s = shaped[r];
            std::uint32_t n = static_cast<std::uint32_t>(s.ring->nodes.size());
            std::uint32_t a = s.kept[seg];
            std::uint32_t b = seg + 1 < s.kept.size() ? s.kept[seg + 1] : s.kept[0] + n;
            if (b <= a + 1) return;
            const Vec3& pa = s.ring->nodes[a % n];
            const Vec3& pb = s.ring->nodes[b % n];
            double worst = -1;
            std::uint32_t at = a + 1;
            for (std::uint32_t k = a + 1; k < b; ++k) {
                double d = arc_distance(pa, pb, s.ring->nodes[k % n]);
                if (d > worst) {
                    worst = d;
                    at = k;
                }
            }
            insert[r].push_back(at % n);
            progress_made = true;
        };
        for (const auto& c : conflicts) {
            refine(c.ring_a, c.seg_a);
            refine(c.ring_b, c.seg_b);
        }
        if (!progress_made) {
            const auto& c = conflicts.front();
            LonLat at = vec_to_lonlat(rings[c.ring_a][c.seg_a]);
            throw DataError("coast: rings touch or cross near lon " + std::to_string(at.lon) + ", lat " +
                            std::to_string(at.lat) + " at full resolution; repair the coastline there");
        }
        for (std::size_t r = 0; r < shaped.size(); ++r) {
            if (insert[r].empty()) continue;
            auto& kept = shaped[r].kept;
            kept.insert(kept.end(), insert[r].begin(), insert[r].end());
            std::sort(kept.begin(), kept.end());
            kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
            rep.conflicts_repaired += insert[r].size();
        }
        report(progress, 0.5 + 0.3 * (1.0 - 1.0 / (round + 2)), "checking coast topology");
    }
    report(progress, 0.8, "resampling coast");

    // 4. Resample: split every kept arc into pieces of about the local size.
    Boundary out;
    for (const auto& s : shaped) {
        const Ring& ring = *s.ring;
        Ring r;
        std::size_t m = s.kept.size();
        for (std::size_t k = 0; k < m; ++k) {
            const Vec3& a = ring.nodes[s.kept[k]];
            const Vec3& b = ring.nodes[s.kept[(k + 1) % m]];
            SegmentKind kind = ring.kinds[s.kept[k]];
            double h = h_at(arc_midpoint(a, b));
            int pieces = std::max(1, static_cast<int>(std::lround(arc_angle(a, b) / h)));
            r.nodes.push_back(a);
            r.kinds.push_back(kind);
            for (int p = 1; p < pieces; ++p) {
                r.nodes.push_back(arc_interpolate(a, b, double(p) / pieces));
                r.kinds.push_back(kind);
            }
        }
        out.rings.push_back(std::move(r));
    }

    auto issues = check_boundary(out, 1);
    if (!issues.empty()) {
        const auto& is = issues.front();
        LonLat at = vec_to_lonlat(out.rings[is.ring].nodes[std::max(is.segment, 0L)]);
        throw DataError("coast: the shaped boundary has " + is.what + " near lon " + std::to_string(at.lon) +
                        ", lat " + std::to_string(at.lat));
    }
    rep.rings = out.rings.size();
    for (const auto& r : out.rings) rep.nodes += r.nodes.size();
    rep.ocean_area_km2 = boundary_area_km2(out);
    double dropped_net = rep.area_gained_km2 - coast.area_gained_km2 - (rep.area_lost_km2 - coast.area_lost_km2);
    double net = rep.ocean_area_km2 - (coast.ocean_area_km2 + dropped_net);
    if (net > 0) rep.area_gained_km2 += net;
    else rep.area_lost_km2 -= net;
    if (report_out) *report_out = rep;
    report(progress, 1.0, "coast shaped");
    return out;
}

} // namespace globemesh
