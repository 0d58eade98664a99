// Which polygons' outlines come within a distance of each other (planar lon/lat), through a
// uniform grid of the segments' boxes: GEOS 3.11's prepared distance test compares every
// segment of a continent with every segment of each nearby islet.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include "coast_internal.hpp"
#include "coast_parallel.hpp"

namespace globemesh::coast_detail {

namespace {

struct Seg {
    double ax, ay, bx, by;
};

double cross2(double ux, double uy, double vx, double vy) {
    return ux * vy - uy * vx;
}

double point_segment_distance2(double px, double py, const Seg &s) {
    return planar_distance2(px, py, s.ax, s.ay, s.bx, s.by);
}

/// True when segments s and t come within sqrt(d2): they cross, or an end of one is near the other.
bool segments_within(const Seg &s, const Seg &t, double d2) {
    const double d1 = cross2(s.bx - s.ax, s.by - s.ay, t.ax - s.ax, t.ay - s.ay);
    const double d2s = cross2(s.bx - s.ax, s.by - s.ay, t.bx - s.ax, t.by - s.ay);
    const double d3 = cross2(t.bx - t.ax, t.by - t.ay, s.ax - t.ax, s.ay - t.ay);
    const double d4 = cross2(t.bx - t.ax, t.by - t.ay, s.bx - t.ax, s.by - t.ay);
    if (((d1 > 0 && d2s < 0) || (d1 < 0 && d2s > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
        return true;
    return point_segment_distance2(t.ax, t.ay, s) <= d2 ||
           point_segment_distance2(t.bx, t.by, s) <= d2 ||
           point_segment_distance2(s.ax, s.ay, t) <= d2 ||
           point_segment_distance2(s.bx, s.by, t) <= d2;
}

} // namespace

std::vector<std::pair<std::uint32_t, std::uint32_t>>
near_pairs(const std::vector<std::vector<std::vector<LonLat>>> &polygons, double distance) {
    std::vector<Seg> segs;
    std::vector<std::uint32_t> owner;
    double total = 0;
    for (std::uint32_t p = 0; p < polygons.size(); ++p)
        for (const auto &ring : polygons[p])
            for (std::size_t i = 0; i + 1 < ring.size(); ++i) {
                segs.push_back({ring[i].lon, ring[i].lat, ring[i + 1].lon, ring[i + 1].lat});
                owner.push_back(p);
                total += std::hypot(ring[i + 1].lon - ring[i].lon, ring[i + 1].lat - ring[i].lat);
            }
    if (segs.empty())
        return {};
    // Cells of a few mean segment lengths hold a few segments each; long ones span several.
    const double cell = std::clamp(4.0 * total / static_cast<double>(segs.size()), 1e-4, 1.0);
    const auto columns = static_cast<std::uint64_t>(std::ceil(720.0 / cell)) + 2;
    auto index = [&](double v, double lo) {
        return static_cast<std::uint64_t>(std::floor((v - lo) / cell));
    };
    std::vector<std::pair<std::uint64_t, std::uint32_t>> entries; // (cell, segment)
    for (std::uint32_t k = 0; k < segs.size(); ++k) {
        const Seg &s = segs[k];
        const double x0 = std::min(s.ax, s.bx) - distance, x1 = std::max(s.ax, s.bx) + distance;
        const double y0 = std::min(s.ay, s.by) - distance, y1 = std::max(s.ay, s.by) + distance;
        for (std::uint64_t i = index(x0, -360.0); i <= index(x1, -360.0); ++i)
            for (std::uint64_t j = index(y0, -91.0); j <= index(y1, -91.0); ++j)
                entries.push_back({j * columns + i, k});
    }
    // Sorted by cell on every core: chunks sorted, then merged pairwise.
    const std::size_t chunks = 4 * coast_threads();
    std::vector<std::size_t> bound(chunks + 1);
    for (std::size_t c = 0; c <= chunks; ++c)
        bound[c] = entries.size() * c / chunks;
    parallel_for_each(chunks, [&](std::size_t c) {
        std::sort(entries.begin() + std::ptrdiff_t(bound[c]),
                  entries.begin() + std::ptrdiff_t(bound[c + 1]));
    });
    for (std::size_t width = 1; width < chunks; width *= 2)
        parallel_for_each((chunks + 2 * width - 1) / (2 * width), [&](std::size_t m) {
            const std::size_t lo = 2 * width * m, mid = std::min(chunks, lo + width),
                              hi = std::min(chunks, lo + 2 * width);
            std::inplace_merge(entries.begin() + std::ptrdiff_t(bound[lo]),
                               entries.begin() + std::ptrdiff_t(bound[mid]),
                               entries.begin() + std::ptrdiff_t(bound[hi]));
        });
    // The cells' pairs tested in chunks that end where a cell does, on every core; the pairs
    // come out sorted and unique, the same on any number of threads.
    for (std::size_t c = 1; c < chunks; ++c)
        for (bound[c] = std::max(bound[c], bound[c - 1]);
             bound[c] > 0 && bound[c] < entries.size() &&
             entries[bound[c]].first == entries[bound[c] - 1].first;)
            ++bound[c];
    const double d2 = distance * distance;
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(chunks);
    parallel_for_each(chunks, [&](std::size_t c) {
        for (std::size_t a = bound[c]; a < bound[c + 1];) {
            std::size_t b = a + 1;
            while (b < bound[c + 1] && entries[b].first == entries[a].first)
                ++b;
            for (std::size_t u = a; u < b; ++u)
                for (std::size_t v = u + 1; v < b; ++v) {
                    const std::uint32_t s = entries[u].second, t = entries[v].second;
                    if (owner[s] == owner[t] || !segments_within(segs[s], segs[t], d2))
                        continue;
                    found[c].push_back(std::minmax(owner[s], owner[t]));
                }
            a = b;
        }
    });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (const auto &f : found)
        out.insert(out.end(), f.begin(), f.end());
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

} // namespace globemesh::coast_detail
