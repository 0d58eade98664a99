// The background grid, distance to the coast (nearest-point propagation) and gradient limiting
// (fast marching of the upwind eikonal scheme, Persson 2006) on it.
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "grid.hpp"

namespace globemesh::detail {

namespace {

constexpr float float_inf = std::numeric_limits<float>::infinity();

struct HeapEntry {
    float key;
    std::uint32_t node;
    bool operator>(const HeapEntry& o) const { return key > o.key || (key == o.key && node > o.node); }
};
using MinHeap = std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<HeapEntry>>;

double chord2(const Vec3& a, const Vec3& b) {
    Vec3 d = a - b;
    return dot(d, d);
}

/// Largest float not above x (so a stored size never exceeds the solver's value).
float float_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x) f = std::nextafter(f, -float_inf);
    return f;
}

} // namespace

BackgroundGrid::BackgroundGrid(double lon0_deg, double lat0_deg, double dlon_deg, double dlat_deg,
                               std::size_t nlon_, std::size_t nlat_, bool global_)
    : lon0(lon0_deg), lat0(lat0_deg), dlon(dlon_deg), dlat(dlat_deg), nlon(nlon_), nlat(nlat_),
      global(global_) {
    sin_lon.resize(nlon);
    cos_lon.resize(nlon);
    for (std::size_t i = 0; i < nlon; ++i) sincosd(lon(i), sin_lon[i], cos_lon[i]);
    sin_lat.resize(nlat);
    cos_lat.resize(nlat);
    dx_km.resize(nlat);
    for (std::size_t j = 0; j < nlat; ++j) {
        sincosd(lat(j), sin_lat[j], cos_lat[j]);
        dx_km[j] = nlon > 1 ? arc_km(node(0, j), node(1, j)) : 0.0;
    }
    dy_km = dlat * deg_to_rad * earth_radius_km;
}

void BackgroundGrid::row_neighbours(std::size_t n, std::size_t out[2]) const {
    std::size_t i = n % nlon, row = n - i;
    out[0] = i > 0 ? n - 1 : (global ? row + nlon - 1 : npos);
    out[1] = i + 1 < nlon ? n + 1 : (global ? row : npos);
}

void BackgroundGrid::column_neighbours(std::size_t n, std::size_t out[2]) const {
    std::size_t i = n % nlon, j = n / nlon;
    std::size_t across = (i + nlon / 2) % nlon; // the node 180 degrees away, across the pole
    out[0] = j > 0 ? n - nlon : (global ? across : npos);
    out[1] = j + 1 < nlat ? n + nlon : (global ? (nlat - 1) * nlon + across : npos);
}

BackgroundGrid make_background_grid(const MeshOptions& o, double hfloor_km, std::size_t max_nodes) {
    max_nodes = std::max<std::size_t>(max_nodes, 64);
    const double spacing = std::max(1e-6, 0.5 * hfloor_km / earth_radius_km * rad_to_deg);
    double w = -180, s = -90, e = 180, n = 90;
    bool global = true;
    if (o.region) {
        w = (*o.region)[0];
        e = (*o.region)[2];
        if (e <= w) e += 360;
        // One cell of margin, within the poles.
        s = std::max(-90.0, (*o.region)[1] - spacing);
        n = std::min(90.0, (*o.region)[3] + spacing);
        global = e - w >= 360 - 2 * spacing;
        if (global) {
            w = -180;
            e = 180;
        } else {
            w -= spacing;
            e += spacing;
        }
    }
    double nx = std::ceil((e - w) / spacing), ny = std::ceil((n - s) / spacing);
    if (nx * ny > static_cast<double>(max_nodes)) {
        double f = std::sqrt(nx * ny / static_cast<double>(max_nodes));
        nx = std::floor(nx / f);
        ny = std::floor(ny / f);
    }
    std::size_t nlon = std::max<std::size_t>(2, static_cast<std::size_t>(nx));
    std::size_t nlat = std::max<std::size_t>(2, static_cast<std::size_t>(ny));
    if (global && nlon % 2) --nlon;
    nlon = std::max<std::size_t>(nlon, 2);
    double dlon = (e - w) / static_cast<double>(nlon), dlat = (n - s) / static_cast<double>(nlat);
    return BackgroundGrid(w + 0.5 * dlon, s + 0.5 * dlat, dlon, dlat, nlon, nlat, global);
}

std::vector<float> coast_distance_km(const BackgroundGrid& g, const Boundary& b, double max_km,
                                     const Progress& progress) {
    // Sources: the rings densified to a quarter of the smallest grid spacing.
    const double step = 0.25 * std::min(g.dlat, g.dlon) * deg_to_rad;
    std::vector<Vec3> sources;
    for (const Ring& ring : b.rings) {
        const std::size_t m = ring.nodes.size();
        for (std::size_t k = 0; k < m; ++k) {
            const Vec3& a = ring.nodes[k];
            const Vec3& c = ring.nodes[(k + 1) % m];
            double angle = arc_angle(a, c);
            std::size_t pieces = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(angle / step)));
            for (std::size_t p = 0; p < pieces; ++p)
                sources.push_back(p == 0 ? a : arc_interpolate(a, c, static_cast<double>(p) / static_cast<double>(pieces)));
        }
    }
    std::vector<float> key(g.size(), float_inf); // chord^2 to the nearest source found
    std::vector<std::uint32_t> nearest(g.size(), 0);
    MinHeap heap;
    auto offer = [&](std::size_t node, std::uint32_t src) {
        float k = static_cast<float>(chord2(g.node(node), sources[src]));
        if (k < key[node]) {
            key[node] = k;
            nearest[node] = src;
            heap.push({k, static_cast<std::uint32_t>(node)});
        }
    };
    // Seed the four nodes around each source.
    for (std::size_t s = 0; s < sources.size(); ++s) {
        LonLat ll = vec_to_lonlat(sources[s]);
        double u = (ll.lon - g.lon0) / g.dlon, v = (ll.lat - g.lat0) / g.dlat;
        if (g.global) u = u - std::floor(u / static_cast<double>(g.nlon)) * static_cast<double>(g.nlon);
        else if (u < -1 || u > static_cast<double>(g.nlon)) {
            double u2 = (ll.lon + 360.0 - g.lon0) / g.dlon;
            if (u2 >= -1 && u2 <= static_cast<double>(g.nlon)) u = u2;
            else continue;
        }
        if (v < -1 || v > static_cast<double>(g.nlat)) continue;
        long i0 = static_cast<long>(std::floor(u)), j0 = static_cast<long>(std::floor(v));
        for (long dj = 0; dj <= 1; ++dj)
            for (long di = 0; di <= 1; ++di) {
                long i = i0 + di, j = std::clamp(j0 + dj, 0L, static_cast<long>(g.nlat) - 1);
                if (g.global) i = (i % static_cast<long>(g.nlon) + static_cast<long>(g.nlon)) % static_cast<long>(g.nlon);
                else if (i < 0 || i >= static_cast<long>(g.nlon)) continue;
                offer(static_cast<std::size_t>(j) * g.nlon + static_cast<std::size_t>(i), static_cast<std::uint32_t>(s));
            }
    }
    // Dijkstra over the 8-neighbourhood, each node carrying its nearest source.
    const double max_angle = std::min(pi, max_km / earth_radius_km);
    const float max_key = static_cast<float>(4.0 * std::pow(std::sin(0.5 * max_angle), 2)) * 1.0001f;
    std::vector<std::uint8_t> done(g.size(), 0);
    std::size_t popped = 0;
    while (!heap.empty()) {
        HeapEntry top = heap.top();
        heap.pop();
        if (top.key > max_key) break;
        if (done[top.node] || top.key > key[top.node]) continue;
        done[top.node] = 1;
        if (++popped % (1u << 20) == 0)
            report(progress, std::min(0.99, static_cast<double>(popped) / static_cast<double>(g.size())), "coast distance");
        std::size_t r[2], c[2];
        g.row_neighbours(top.node, r);
        g.column_neighbours(top.node, c);
        std::size_t around[8] = {r[0], r[1], c[0], c[1], BackgroundGrid::npos, BackgroundGrid::npos,
                                 BackgroundGrid::npos, BackgroundGrid::npos};
        for (int k = 0; k < 2; ++k)
            if (c[k] != BackgroundGrid::npos) {
                std::size_t cr[2];
                g.row_neighbours(c[k], cr);
                around[4 + 2 * k] = cr[0];
                around[5 + 2 * k] = cr[1];
            }
        for (std::size_t m : around)
            if (m != BackgroundGrid::npos && !done[m]) offer(m, nearest[top.node]);
    }
    std::vector<float> d(g.size(), float_inf);
    for (std::size_t n = 0; n < g.size(); ++n)
        if (done[n]) d[n] = static_cast<float>(2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(static_cast<double>(key[n])))) * earth_radius_km);
    return d;
}

void limit_gradient(const BackgroundGrid& g, std::vector<float>& h, double grade, const Progress& progress) {
    float top_value = 0;
    for (float v : h) top_value = std::max(top_value, v);
    MinHeap heap;
    // Nodes at the largest value never lower a neighbour: they enter only when lowered.
    for (std::size_t n = 0; n < g.size(); ++n)
        if (h[n] < top_value) heap.push({h[n], static_cast<std::uint32_t>(n)});
    std::vector<std::uint8_t> accepted(g.size(), 0);
    const double inf = std::numeric_limits<double>::infinity();
    const double dy = g.dy_km;
    auto axis_min = [&](const std::size_t nb[2]) {
        double a = inf;
        for (int k = 0; k < 2; ++k)
            if (nb[k] != BackgroundGrid::npos && accepted[nb[k]]) a = std::min(a, static_cast<double>(h[nb[k]]));
        return a;
    };
    // The upwind eikonal value at node m from its accepted neighbours.
    auto solve = [&](std::size_t m) {
        std::size_t r[2], c[2];
        g.row_neighbours(m, r);
        g.column_neighbours(m, c);
        const double a = axis_min(r), b = axis_min(c);
        const double dx = g.dx_km[m / g.nlon];
        const double ta = a + grade * dx, tb = b + grade * dy;
        double t = std::min(ta, tb);
        if (a < inf && b < inf && t > std::max(a, b)) {
            // (t - a)^2 / dx^2 + (t - b)^2 / dy^2 = grade^2, the larger root.
            const double ix = 1.0 / (dx * dx), iy = 1.0 / (dy * dy);
            const double qa = ix + iy, qb = -2.0 * (a * ix + b * iy);
            const double qc = a * a * ix + b * b * iy - grade * grade;
            const double disc = qb * qb - 4.0 * qa * qc;
            if (disc >= 0) {
                double root = (-qb + std::sqrt(disc)) / (2.0 * qa);
                if (root >= std::max(a, b)) t = std::min(t, root);
            }
        }
        return t;
    };
    std::size_t popped = 0;
    while (!heap.empty()) {
        HeapEntry top = heap.top();
        heap.pop();
        if (accepted[top.node] || top.key > h[top.node]) continue;
        accepted[top.node] = 1;
        if (++popped % (1u << 20) == 0)
            report(progress, std::min(0.99, static_cast<double>(popped) / static_cast<double>(g.size())), "gradation");
        std::size_t r[2], c[2];
        g.row_neighbours(top.node, r);
        g.column_neighbours(top.node, c);
        for (std::size_t m : {r[0], r[1], c[0], c[1]}) {
            if (m == BackgroundGrid::npos || accepted[m]) continue;
            double t = solve(m);
            if (t < h[m]) {
                h[m] = std::max(top.key, float_down(t));
                heap.push({h[m], static_cast<std::uint32_t>(m)});
            }
        }
    }
}

} // namespace globemesh::detail
