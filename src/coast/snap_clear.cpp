// A lone polygon rounded to the snap grid without GEOS's snap-rounding noder, when rounding
// cannot change it (see coast_load_internal.hpp, rounded_if_clear).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

#include "coast_internal.hpp"
#include "coast_load_internal.hpp"

namespace globemesh::coast_detail {

namespace {

/// A vertex this many cells or more from every edge it is not on stays more than half a cell
/// from it after rounding (each end moves at most 0.71 cell): 2, and a margin for the
/// arithmetic of the test.
constexpr double clear_cells = 2.5;

/// Past this many (cell, edge) entries per edge (long edges over fine cells) the test gives up.
constexpr std::size_t max_entries_per_edge = 16;

/// GEOS's rounding of a coordinate to the grid (PrecisionModel::makePrecise: half up).
double round_to(double v, double grid) {
    return std::floor(v / grid + 0.5) * grid;
}

/// A rounded ring laid out as GEOS's precision reducer lays out its output (checked vertex by
/// vertex in coast_dissolve_test): clockwise for a shell, counter-clockwise for a hole, starting
/// at what was the ring's second vertex once so oriented.
void lay_out_as_geos(PointList &r, bool clockwise) {
    orient(r, !clockwise);
    r.pop_back();
    std::rotate(r.begin(), r.begin() + 1, r.end());
    r.push_back(r.front());
}

} // namespace

std::optional<PolygonRings> rounded_if_clear(const PolygonRings &rings, double grid) {
    // Edges (ring, i): rings[ring][i] -> rings[ring][i + 1]; first[ring] numbers them.
    std::vector<std::size_t> first{0};
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300, length = 0;
    for (const PointList &r : rings) {
        if (r.size() < 4 || r.front().lon != r.back().lon || r.front().lat != r.back().lat)
            return std::nullopt;
        first.push_back(first.back() + r.size() - 1);
        for (std::size_t i = 0; i + 1 < r.size(); ++i) {
            x0 = std::min(x0, r[i].lon), x1 = std::max(x1, r[i].lon);
            y0 = std::min(y0, r[i].lat), y1 = std::max(y1, r[i].lat);
            length += std::hypot(r[i + 1].lon - r[i].lon, r[i + 1].lat - r[i].lat);
        }
    }
    const std::size_t edges = first.back();
    const double reach = clear_cells * grid;
    // Cells about an edge long, and every edge listed in the cells its box, widened by the
    // reach, covers: a vertex then meets every edge within reach in its own cell.
    const double cell = std::max(length / double(edges), 4 * reach);
    const auto nx = std::uint64_t((x1 - x0 + 2 * reach) / cell) + 1;
    auto cell_of = [&](double x, double y) {
        return std::uint64_t((y - y0 + reach) / cell) * nx + std::uint64_t((x - x0 + reach) / cell);
    };
    std::vector<std::pair<std::uint64_t, std::uint32_t>> entries;
    entries.reserve(4 * edges);
    for (std::size_t k = 0; k < rings.size(); ++k)
        for (std::size_t i = 0; i + 1 < rings[k].size(); ++i) {
            const LonLat &a = rings[k][i], &b = rings[k][i + 1];
            const auto cx0 = std::uint64_t((std::min(a.lon, b.lon) - x0) / cell),
                       cx1 = std::uint64_t((std::max(a.lon, b.lon) - x0 + 2 * reach) / cell),
                       cy0 = std::uint64_t((std::min(a.lat, b.lat) - y0) / cell),
                       cy1 = std::uint64_t((std::max(a.lat, b.lat) - y0 + 2 * reach) / cell);
            if ((cx1 - cx0 + 1) * (cy1 - cy0 + 1) + entries.size() > max_entries_per_edge * edges)
                return std::nullopt;
            for (std::uint64_t cy = cy0; cy <= cy1; ++cy)
                for (std::uint64_t cx = cx0; cx <= cx1; ++cx)
                    entries.emplace_back(cy * nx + cx, std::uint32_t(first[k] + i));
        }
    std::sort(entries.begin(), entries.end());
    // Every vertex against the edges of its cell that it is not an end of.
    auto edge_ends = [&](std::uint32_t e) {
        const auto k =
            std::size_t(std::upper_bound(first.begin(), first.end(), e) - first.begin()) - 1;
        const std::size_t i = e - first[k];
        return std::pair<const LonLat &, const LonLat &>{rings[k][i], rings[k][i + 1]};
    };
    for (std::size_t k = 0; k < rings.size(); ++k) {
        const std::size_t m = rings[k].size() - 1; // distinct vertices
        for (std::size_t i = 0; i < m; ++i) {
            const LonLat &p = rings[k][i];
            const auto own = std::uint32_t(first[k] + i),
                       before = std::uint32_t(first[k] + (i + m - 1) % m);
            const std::uint64_t c = cell_of(p.lon, p.lat);
            auto it = std::lower_bound(entries.begin(), entries.end(),
                                       std::pair<std::uint64_t, std::uint32_t>{c, 0});
            for (; it != entries.end() && it->first == c; ++it) {
                if (it->second == own || it->second == before)
                    continue;
                const auto [a, b] = edge_ends(it->second);
                if (planar_distance2(p.lon, p.lat, a.lon, a.lat, b.lon, b.lat) < reach * reach)
                    return std::nullopt;
            }
        }
    }
    PolygonRings out = rings;
    for (std::size_t k = 0; k < out.size(); ++k) {
        for (LonLat &p : out[k])
            p = {round_to(p.lon, grid), round_to(p.lat, grid)};
        lay_out_as_geos(out[k], k == 0);
    }
    return out;
}

} // namespace globemesh::coast_detail
