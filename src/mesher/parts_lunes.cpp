// choose_lunes (docs/parallel.md, section 1): the lunes' first border placed where the parts'
// work is balanced and the borders pass the coast least closely.
#include "parts_lunes.hpp"

#include <algorithm>
#include <cmath>

#include "globemesh/sphere.hpp"

namespace globemesh::parts_detail {

namespace {

/// A coast node costs the mesher about as much as this many nodes of open ocean (segment
/// recovery, encroachment, the land tests): the time of 24 parts of GSHHG low at 20 km, fitted
/// to their nodes and coast nodes (bench/RESULTS-parallel.md).
constexpr double coast_node_work = 65;

/// A position whose busiest part has up to this much more work than the best one's may be
/// chosen for borders passing the coast less closely: the fit predicts a part's time to about
/// 6%.
constexpr double balance_slack = 0.03;

constexpr double bin_degrees = 360.0 / lon_bins;

/// A coast nearer a border than h / max_passed is as bad as any nearer (coast_passed_by).
constexpr double max_passed = 50;

/// Degrees east of default_border_lon, in [0, 360).
double east_of_default(const Vec3 &p) {
    return Lunes{}.east_of_first(p);
}

/// The bin of position u, any number of turns away.
std::size_t bin_at(long u) {
    return static_cast<std::size_t>((u % lon_bins + lon_bins) % lon_bins);
}

/// The normal of the meridian plane at border position u (a bin's start).
Vec3 position_normal(long u) {
    return Lunes{1, default_border_lon + double(u) * bin_degrees}.border_normal(0);
}

/// How closely the border at position u passes segment a-b by (h its size, radians): the
/// integral over the segment of 1/d - 1/h where d < h, d its distance from the meridian plane
/// (at least h / max_passed), in sizes; where it crosses the border, 2 (1 / sin t - 1) for an
/// angle t between them (a crossing at right angles costs nothing, a shallow one leaves a
/// wedge of water as narrow as the angle).
double passed_by(const Vec3 &a, const Vec3 &b, double h, long u) {
    const Vec3 normal = position_normal(u);
    const double da = dot(a, normal), db = dot(b, normal);
    if ((da > 0) != (db > 0)) {
        const double sine = std::abs(dot(normalized(b - a), normal));
        return std::min(max_passed, 2 * (1 / std::max(sine, 1e-300) - 1));
    }
    constexpr int samples = 8;
    const double step = std::acos(std::clamp(dot(a, b), -1.0, 1.0)) / samples;
    double sum = 0;
    for (int i = 0; i < samples; ++i) {
        const double d = std::abs(dot(normalized(a + ((i + 0.5) / samples) * (b - a)), normal));
        sum += step * std::max(0.0, 1 / std::max(d, h / max_passed) - 1 / h);
    }
    return sum;
}

/// Per border position (the start of each bin), how closely it passes the kept rings' segments
/// by (passed_by), summed. A coast running along a border counts along its length, a cape
/// pointing at it by its nearness, a coast crossing it at right angles not at all. Segments
/// nearer a pole than their size reach every meridian and are left out.
std::vector<double> coast_passed_by(const std::vector<Ring> &rings, const std::vector<char> &kept,
                                    const SizeFn &size_km) {
    std::vector<double> passed(lon_bins, 0.0);
    for (std::size_t k = 0; k < rings.size(); ++k) {
        const std::vector<Vec3> &nodes = rings[k].nodes;
        const std::size_t n = nodes.size();
        if (!kept[k] || n < 2)
            continue;
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3 &a = nodes[i], &b = nodes[(i + 1) % n];
            const double h = km_to_rad(size_km(arc_midpoint(a, b)));
            const double reach = std::sin(h);
            const double cos_lat = std::min(std::hypot(a.x, a.y), std::hypot(b.x, b.y));
            if (reach >= cos_lat)
                continue;
            const double half = std::asin(reach / cos_lat) * rad_to_deg;
            const double ea = east_of_default(a);
            double eb = east_of_default(b) - ea;
            eb = ea + eb - 360 * std::round(eb / 360);
            const long from = static_cast<long>(std::ceil((std::min(ea, eb) - half) / bin_degrees));
            const long to =
                std::min(static_cast<long>(std::floor((std::max(ea, eb) + half) / bin_degrees)),
                         from + lon_bins - 1);
            for (long u = from; u <= to; ++u)
                passed[bin_at(u)] += passed_by(a, b, h, u);
        }
    }
    return passed;
}

} // namespace

int lon_bin(const Vec3 &p) {
    return Lunes{lon_bins}.part_of(p); // the bins are lunes of bin_degrees from the default
}

void spread_over_longitudes(std::vector<double> &bins, const Vec3 &a, const Vec3 &b, const Vec3 &c,
                            double nodes) {
    // A pole lies inside where it is on the inner side of all three arcs.
    auto holds = [&](const Vec3 &pole) {
        return dot(cross(a, b), pole) > 0 && dot(cross(b, c), pole) > 0 &&
               dot(cross(c, a), pole) > 0;
    };
    double lo = 0, hi = 0; // degrees east of a's longitude, unwrapped
    for (const Vec3 *q : {&b, &c}) {
        double e = east_of_default(*q) - east_of_default(a);
        e -= 360 * std::round(e / 360);
        lo = std::min(lo, e);
        hi = std::max(hi, e);
    }
    long from = 0, to = lon_bins - 1;
    if (!holds({0, 0, 1}) && !holds({0, 0, -1}) && hi - lo < 360) {
        from = static_cast<long>(std::floor((east_of_default(a) + lo) / bin_degrees));
        to = std::min(static_cast<long>(std::floor((east_of_default(a) + hi) / bin_degrees)),
                      from + lon_bins - 1);
    }
    const double share = nodes / double(to - from + 1);
    for (long u = from; u <= to; ++u)
        bins[bin_at(u)] += share;
}

Lunes choose_lunes(int count, const std::vector<double> &nodes, const std::vector<Ring> &rings,
                   const std::vector<char> &kept, const SizeFn &size_km) {
    std::vector<double> work(nodes);
    work.resize(lon_bins, 0.0);
    for (std::size_t r = 0; r < rings.size(); ++r) {
        if (!kept[r])
            continue;
        for (const Vec3 &p : rings[r].nodes)
            work[static_cast<std::size_t>(lon_bin(p))] += coast_node_work;
    }
    // sums[i]: the work of bins 0 .. i - 1, over two turns so that a lune may wrap.
    std::vector<double> sums(2 * lon_bins + 1, 0.0);
    for (int i = 0; i < 2 * lon_bins; ++i)
        sums[static_cast<std::size_t>(i + 1)] =
            sums[static_cast<std::size_t>(i)] + work[static_cast<std::size_t>(i % lon_bins)];
    const std::vector<double> near = coast_passed_by(rings, kept, size_km);
    const int width = lon_bins / count;
    std::vector<double> busiest(static_cast<std::size_t>(width)), near_borders(busiest.size());
    for (int j = 0; j < width; ++j) {
        double most = 0, coast = 0;
        for (int k = 0; k < count; ++k) {
            const int start = j + k * width;
            most = std::max(most, sums[static_cast<std::size_t>(start + width)] -
                                      sums[static_cast<std::size_t>(start)]);
            coast += near[static_cast<std::size_t>(start)];
        }
        busiest[static_cast<std::size_t>(j)] = most;
        near_borders[static_cast<std::size_t>(j)] = coast;
    }
    const double bound = *std::min_element(busiest.begin(), busiest.end()) * (1 + balance_slack);
    int chosen = -1;
    for (int j = 0; j < width; ++j) {
        const auto u = static_cast<std::size_t>(j), c = static_cast<std::size_t>(chosen);
        if (busiest[u] <= bound &&
            (chosen < 0 || near_borders[u] < near_borders[c] ||
             (near_borders[u] == near_borders[c] && busiest[u] < busiest[c])))
            chosen = j;
    }
    return Lunes{count, default_border_lon + chosen * bin_degrees};
}

} // namespace globemesh::parts_detail
