// The background grid, distance to the coast (nearest-point propagation) and gradient limiting
// on it (ordered like fast marching, Persson 2006, with the corner conditions of the evaluated
// piecewise-linear field in place of the upwind eikonal update).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <queue>
#include <system_error>
#include <thread>

#include <sys/mman.h>

#include "grid.hpp"

namespace globemesh::detail {

namespace {

constexpr float float_inf = std::numeric_limits<float>::infinity();
constexpr double float_max = std::numeric_limits<float>::max(); // finite bounds stay finite

struct HeapEntry {
    float key;
    std::uint32_t node;
    bool operator>(const HeapEntry &o) const {
        return key > o.key || (key == o.key && node > o.node);
    }
};
using MinHeap = std::priority_queue<HeapEntry, std::vector<HeapEntry>, std::greater<HeapEntry>>;

constexpr std::size_t huge_page = std::size_t{2} << 20;

/// Puts blocks of 2 MiB and more on 2 MiB boundaries, advised to huge pages: the coast distance and
/// the gradation read their arrays in the order of the values, all over the grid, where 4 KiB
/// pages make most reads a TLB miss. Where the kernel has none the advice is ignored.
template <class T> struct HugePages {
    using value_type = T;
    HugePages() = default;
    template <class U> HugePages(const HugePages<U> &) {}
    T *allocate(std::size_t n) {
        const std::size_t bytes = n * sizeof(T);
        if (bytes < huge_page)
            return std::allocator<T>{}.allocate(n);
        const std::size_t rounded = (bytes + huge_page - 1) / huge_page * huge_page;
        void *p = std::aligned_alloc(huge_page, rounded);
        if (!p)
            throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
        madvise(p, rounded, MADV_HUGEPAGE);
#endif
        return static_cast<T *>(p);
    }
    void deallocate(T *p, std::size_t n) {
        if (n * sizeof(T) < huge_page)
            std::allocator<T>{}.deallocate(p, n);
        else
            std::free(p);
    }
    friend bool operator==(const HugePages &, const HugePages &) {
        return true;
    }
};
template <class T> using HugeVector = std::vector<T, HugePages<T>>;

double chord2(const Vec3 &a, const Vec3 &b) {
    Vec3 d = a - b;
    return dot(d, d);
}

/// Largest float not above x (so a stored size never exceeds the solver's value).
float float_down(double x) {
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x)
        f = std::nextafter(f, -float_inf);
    return f;
}

/// Sorts entries made in increasing node order by (key, node), as the heap pops them: a stable
/// radix sort on the key's bits (positive floats order as their bit patterns); std::sort where a
/// key is not a positive finite float.
void sort_seeds(std::vector<HeapEntry> &seeds) {
    auto bits = [](float key) {
        std::uint32_t b;
        std::memcpy(&b, &key, sizeof b);
        return b;
    };
    if (!std::all_of(seeds.begin(), seeds.end(),
                     [](const HeapEntry &e) { return e.key > 0 && e.key < float_inf; })) {
        std::sort(seeds.begin(), seeds.end(),
                  [](const HeapEntry &a, const HeapEntry &b) { return b > a; });
        return;
    }
    std::vector<HeapEntry> sorted(seeds.size());
    for (int shift = 0; shift < 32; shift += 8) {
        std::array<std::size_t, 257> start{};
        for (const HeapEntry &e : seeds)
            ++start[((bits(e.key) >> shift) & 255u) + 1];
        if (std::find(start.begin(), start.end(), seeds.size()) != start.end())
            continue; // one digit for all: this pass would not move anything
        for (std::size_t d = 1; d < start.size(); ++d)
            start[d] += start[d - 1];
        for (const HeapEntry &e : seeds)
            sorted[start[(bits(e.key) >> shift) & 255u]++] = e;
        seeds.swap(sorted);
    }
}

} // namespace

std::size_t field_threads(std::size_t threads) {
    return threads > 0 ? threads
                       : std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
}

void for_row_blocks(std::size_t n, std::size_t block, std::size_t threads,
                    const std::function<void(std::size_t, std::size_t)> &rows,
                    const std::function<void(double)> &progress) {
    block = std::max<std::size_t>(block, 1);
    const std::size_t blocks = (n + block - 1) / block;
    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::exception_ptr error;
    // Takes blocks until none is left or one failed; the first failure is kept.
    auto work = [&](bool caller) {
        try {
            for (std::size_t b; !stop && (b = next++) < blocks;) {
                rows(b * block, std::min(n, (b + 1) * block));
                if (caller && progress)
                    progress(static_cast<double>(std::min(next.load(), blocks)) /
                             static_cast<double>(blocks));
            }
        } catch (...) {
            std::lock_guard lock(mutex);
            if (!error)
                error = std::current_exception();
            stop = true;
        }
    };
    std::vector<std::thread> pool;
    try {
        for (std::size_t t = 1; t < std::min(threads, blocks); ++t)
            pool.emplace_back(work, false);
    } catch (const std::system_error &) {
        // No more threads (a process limit): fewer share the blocks, this one among them.
    }
    work(true);
    for (std::thread &t : pool)
        t.join();
    if (error)
        std::rethrow_exception(error);
}

BackgroundGrid::BackgroundGrid(double lon0_deg, double lat0_deg, double dlon_deg, double dlat_deg,
                               std::size_t nlon_, std::size_t nlat_, bool global_)
    : lon0(lon0_deg), lat0(lat0_deg), dlon(dlon_deg), dlat(dlat_deg), nlon(nlon_), nlat(nlat_),
      global(global_) {
    sin_lon.resize(nlon);
    cos_lon.resize(nlon);
    for (std::size_t i = 0; i < nlon; ++i)
        sincosd(lon(i), sin_lon[i], cos_lon[i]);
    sin_lat.resize(nlat);
    cos_lat.resize(nlat);
    dx_km.resize(nlat);
    for (std::size_t j = 0; j < nlat; ++j) {
        sincosd(lat(j), sin_lat[j], cos_lat[j]);
        dx_km[j] = nlon > 1 ? arc_km(node(0, j), node(1, j)) : 0.0;
    }
    dy_km = dlat * deg_to_rad * earth_radius_km;
    if (global && nlat > 0) {
        south_cap = lat(0) > -90.0 && lat(0) - dlat <= -90.0 + 1e-9 * dlat;
        north_cap = lat(nlat - 1) < 90.0 && lat(nlat - 1) + dlat >= 90.0 - 1e-9 * dlat;
    }
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

BackgroundGrid make_background_grid(const std::optional<std::array<double, 4>> &region,
                                    double hfloor_km, std::size_t max_nodes) {
    max_nodes = std::max<std::size_t>(max_nodes, 64);
    const double spacing = std::max(1e-6, 0.5 * hfloor_km / earth_radius_km * rad_to_deg);
    double w = -180, s = -90, e = 180, n = 90;
    bool global = true;
    if (region) {
        w = (*region)[0];
        e = (*region)[2];
        if (e <= w)
            e += 360;
        // One cell of margin beyond the great circles through the region's corners (they bulge
        // poleward of the parallels, and the mesh's open boundary follows them), within the poles.
        const double half = 0.5 * (e - w);
        auto bulge = [&](double lat) {
            if (half >= 90.0 || lat == 0)
                return lat;
            return std::atan(std::tan(lat * deg_to_rad) / std::cos(half * deg_to_rad)) * rad_to_deg;
        };
        s = std::max(-90.0, std::min((*region)[1], bulge((*region)[1])) - spacing);
        n = std::min(90.0, std::max((*region)[3], bulge((*region)[3])) + spacing);
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
    if (global && nlon % 2)
        --nlon;
    nlon = std::max<std::size_t>(nlon, 2);
    double dlon = (e - w) / static_cast<double>(nlon), dlat = (n - s) / static_cast<double>(nlat);
    return BackgroundGrid(w + 0.5 * dlon, s + 0.5 * dlat, dlon, dlat, nlon, nlat, global);
}

std::vector<float> coast_distance_km(const BackgroundGrid &g, const Boundary &b, double max_km,
                                     const Progress &progress) {
    // Sources: the coast segments densified to a quarter of the smallest grid spacing; a
    // region's open edge is water on both sides, no coast.
    const double step = 0.25 * std::min(g.dlat, g.dlon) * deg_to_rad;
    std::vector<Vec3> sources;
    for (const Ring &ring : b.rings) {
        const std::size_t m = ring.nodes.size();
        // a ring without kinds (a caller's own boundary) is coast all round
        auto coast = [&](std::size_t k) {
            return k >= ring.kinds.size() || ring.kinds[k] == SegmentKind::coast;
        };
        for (std::size_t k = 0; k < m; ++k) {
            if (!coast(k))
                continue;
            const Vec3 &a = ring.nodes[k];
            const Vec3 &c = ring.nodes[(k + 1) % m];
            double angle = arc_angle(a, c);
            std::size_t pieces =
                std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(angle / step)));
            for (std::size_t p = 0; p < pieces; ++p)
                sources.push_back(
                    p == 0 ? a
                           : arc_interpolate(a, c,
                                             static_cast<double>(p) / static_cast<double>(pieces)));
            if (!coast((k + 1) % m))
                sources.push_back(c); // the coast's last node before an open edge
        }
    }
    HugeVector<float> key(g.size(), float_inf); // chord^2 to the nearest source found
    HugeVector<std::uint32_t> nearest(g.size(), 0);
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
        if (g.global)
            u = u - std::floor(u / static_cast<double>(g.nlon)) * static_cast<double>(g.nlon);
        else if (u < -1 || u > static_cast<double>(g.nlon)) {
            double u2 = (ll.lon + 360.0 - g.lon0) / g.dlon;
            if (u2 >= -1 && u2 <= static_cast<double>(g.nlon))
                u = u2;
            else
                continue;
        }
        if (v < -1 || v > static_cast<double>(g.nlat))
            continue;
        long i0 = static_cast<long>(std::floor(u)), j0 = static_cast<long>(std::floor(v));
        for (long dj = 0; dj <= 1; ++dj)
            for (long di = 0; di <= 1; ++di) {
                long i = i0 + di, j = std::clamp(j0 + dj, 0L, static_cast<long>(g.nlat) - 1);
                if (g.global)
                    i = (i % static_cast<long>(g.nlon) + static_cast<long>(g.nlon)) %
                        static_cast<long>(g.nlon);
                else if (i < 0 || i >= static_cast<long>(g.nlon))
                    continue;
                offer(static_cast<std::size_t>(j) * g.nlon + static_cast<std::size_t>(i),
                      static_cast<std::uint32_t>(s));
            }
    }
    // Dijkstra over the 8-neighbourhood, each node carrying its nearest source.
    const double max_angle = std::min(pi, max_km / earth_radius_km);
    const float max_key =
        static_cast<float>(4.0 * std::pow(std::sin(0.5 * max_angle), 2)) * 1.0001f;
    HugeVector<std::uint8_t> done(g.size(), 0);
    std::size_t popped = 0;
    while (!heap.empty()) {
        HeapEntry top = heap.top();
        heap.pop();
        if (top.key > max_key)
            break;
        if (done[top.node] || top.key > key[top.node])
            continue;
        done[top.node] = 1;
        if (++popped % (1u << 20) == 0)
            report(progress,
                   std::min(0.99, static_cast<double>(popped) / static_cast<double>(g.size())),
                   "coast distance");
        std::size_t r[2], c[2];
        g.row_neighbours(top.node, r);
        g.column_neighbours(top.node, c);
        std::size_t around[8] = {r[0],
                                 r[1],
                                 c[0],
                                 c[1],
                                 BackgroundGrid::npos,
                                 BackgroundGrid::npos,
                                 BackgroundGrid::npos,
                                 BackgroundGrid::npos};
        for (int k = 0; k < 2; ++k)
            if (c[k] != BackgroundGrid::npos) {
                std::size_t cr[2];
                g.row_neighbours(c[k], cr);
                around[4 + 2 * k] = cr[0];
                around[5 + 2 * k] = cr[1];
            }
        for (std::size_t m : around)
            if (m != BackgroundGrid::npos && !done[m])
                offer(m, nearest[top.node]);
    }
    std::vector<float> d(g.size(), float_inf);
    for (std::size_t n = 0; n < g.size(); ++n)
        if (done[n])
            d[n] = static_cast<float>(
                2.0 * std::asin(std::min(1.0, 0.5 * std::sqrt(static_cast<double>(key[n])))) *
                earth_radius_km);
    return d;
}

// Gradient limiting with a guarantee for the evaluated field, not only on the grid edges.
//
// How SizeField evaluates the grid (sizefield.cpp): each cell, corners 00, 10, 01, 11 (rows j and
// j+1), is split along its 10-01 diagonal into two triangles, linear in (lon, lat): h00 + u a + v c
// (u + v <= 1) and h11 - (1-u) b - (1-v) d, with the row differences a = h10 - h00, b = h11 - h01
// and the column differences c = h01 - h00, d = h11 - h10. The Riemannian gradient of the first
// has east component a / (R dlon cos(lat)) and north component c / (R dlat), so
//   |grad h|^2 <= a^2 / dx^2 + c^2 / dy^2,   and   b^2 / dx^2 + d^2 / dy^2 for the second,     (*)
// with dx = R dlon cos(lat) at the cell's poleward row (the smallest cos in the cell) and
// dy = R dlat. Holding both corner conditions (*) <= grade^2 in every cell bounds |grad h| by grade
// everywhere, and since the field is continuous (across cells, the +-180 seam and the poles),
// |h(p) - h(q)| <= grade * arc(p, q) for every pair of points. (A node-wise upwind eikonal
// condition, what fast marching holds, does not: the interpolant of a cone's node values has a
// gradient of sqrt(2) * grade in the cells at the apex.) Bilinear interpolation would need all four
// corner conditions, max(a^2, b^2) / dx^2 + max(c^2, d^2) / dy^2 <= grade^2, which forbids a row
// difference of grade * dx beside any column difference: the field would grow at about
// 0.75 * grade along the grid axes away from a point source.
// A polar cap (global grids) is the strip between the last row and the pole, evaluated linearly
// in latitude between the row's linear interpolant and the pole value P: its east component is
// (1-t) a / (R dlon cos(lat)) with cos(lat) = sin((1-t) theta) >= (1-t) sin(theta), theta the
// cap's angular width, and its north component lies between c = P - h0 and d = P - h1 over R theta,
// so the two corner conditions (a, c) and (a, d) with dx = R dlon cos(lat of the row) and
// dy = R theta bound the gradient there.
//
// Solver: nodes are accepted in increasing order of value, as in fast marching. A node's tentative
// value is the smallest of its initial value and, for each corner condition it takes part in, the
// largest v for which the condition holds when it and the condition's other nodes not yet
// accepted take the value v (the best completion: the accepted ones are all <= v). It is
// recomputed for the unaccepted nodes of a node's conditions each time the node is accepted (it can
// rise: a node assumed to rise with it may be accepted lower); it is never below the value just
// accepted (the condition held with its unknown nodes at that value), so values are accepted in
// increasing order, and when the last node of a condition is accepted the condition holds with
// the final values. Values are stored rounded down to float, so (*) holds on the stored floats up
// to double rounding.
namespace {

/// One corner condition: ((h[row] - h[k]) / dx)^2 + ((h[col] - h[k]) / dy)^2 <= grade^2.
struct Corner {
    std::size_t k, row, col;
    double dx, dy;
    bool involves(std::size_t n) const { return n == k || n == row || n == col; }
};

/// Largest v >= the accepted nodes for which the condition holds when its unaccepted nodes take
/// the value v; +inf when no edge ties an unknown node to an accepted one.
double corner_bound(const Corner &c, const HugeVector<float> &h,
                    const HugeVector<std::uint8_t> &accepted, double grade) {
    const double inf = std::numeric_limits<double>::infinity();
    double fixed[2] = {0, 0}, partner[2] = {inf, inf};
    const std::size_t ends[2] = {c.row, c.col};
    for (int dir = 0; dir < 2; ++dir) {
        const std::size_t p = c.k, q = ends[dir];
        if (p == q)
            continue;
        const bool pa = accepted[p] != 0, qa = accepted[q] != 0;
        if (pa && qa) {
            const double diff = static_cast<double>(h[p]) - h[q];
            fixed[dir] = diff * diff;
        } else if (pa) {
            partner[dir] = h[p];
        } else if (qa) {
            partner[dir] = h[q];
        }
    }
    const double g2 = grade * grade, ix = 1.0 / (c.dx * c.dx), iy = 1.0 / (c.dy * c.dy);
    const bool var_x = partner[0] < inf, var_y = partner[1] < inf;
    if (var_x && var_y) {
        // (v - sx)^2 / dx^2 + (v - sy)^2 / dy^2 = grade^2, the larger root.
        const double sx = partner[0], sy = partner[1];
        const double disc = (ix + iy) * g2 - ix * iy * (sx - sy) * (sx - sy);
        return (ix * sx + iy * sy + std::sqrt(std::max(0.0, disc))) / (ix + iy);
    }
    if (var_x)
        return partner[0] + c.dx * std::sqrt(std::max(0.0, g2 - fixed[1] * iy));
    if (var_y)
        return partner[1] + c.dy * std::sqrt(std::max(0.0, g2 - fixed[0] * ix));
    return inf;
}

} // namespace

PoleSizes limit_gradient(const BackgroundGrid &g, std::vector<float> &values, double grade,
                         const Progress &progress) {
    const std::size_t n_grid = g.size();
    const std::size_t south = n_grid, north = n_grid + 1; // the pole nodes, when capped
    float top_value = 0;
    for (float v : values)
        top_value = std::max(top_value, v);
    // The components' values, the ceiling of every node, and the values being solved for.
    HugeVector<float> initial(values.begin(), values.end());
    std::vector<float>().swap(values);
    initial.resize(n_grid + 2, top_value); // the poles start at the top: they are only lowered
    HugeVector<float> h(initial);

    const double rad_lon = g.dlon * deg_to_rad * earth_radius_km;
    auto row_dx = [&](long j) { return rad_lon * g.cos_lat[static_cast<std::size_t>(j)]; };
    const long nlat = static_cast<long>(g.nlat), nlon = static_cast<long>(g.nlon);
    const long j_first = g.south_cap ? -1 : 0, j_last = g.north_cap ? nlat - 1 : nlat - 2;
    const double cap_dy_south = (g.lat(0) + 90.0) * deg_to_rad * earth_radius_km;
    const double cap_dy_north = (90.0 - g.lat(g.nlat - 1)) * deg_to_rad * earth_radius_km;
    // Column i in [-1, nlon] (a cell's corners around a node), wrapped on global grids.
    auto node_id = [&](long i, long j) -> std::size_t {
        return static_cast<std::size_t>(j) * g.nlon + static_cast<std::size_t>(i < 0 ? i + nlon
                                                                               : i >= nlon
                                                                                   ? i - nlon
                                                                                   : i);
    };
    // The two corner conditions of the cell with lower-left corner (i, j); 0 where there is none.
    // Their slots in `bound` are 2 * cell and 2 * cell + 1.
    auto cell_index = [&](long i, long j) {
        return static_cast<std::size_t>(j - j_first) * g.nlon +
               static_cast<std::size_t>(i < 0       ? i + nlon
                                        : i >= nlon ? i - nlon
                                                    : i);
    };
    auto corners = [&](long i, long j, Corner out[2]) -> int {
        if (j < j_first || j > j_last)
            return 0;
        if (!g.global && (i < 0 || i > nlon - 2))
            return 0;
        if (j < 0) { // south cap: the pole below row 0
            const std::size_t c01 = node_id(i, 0), c11 = node_id(i + 1, 0);
            out[0] = {c01, c11, south, row_dx(0), cap_dy_south};
            out[1] = {c11, c01, south, row_dx(0), cap_dy_south};
            return 2;
        }
        if (j + 1 >= nlat) { // north cap
            const std::size_t c00 = node_id(i, j), c10 = node_id(i + 1, j);
            out[0] = {c00, c10, north, row_dx(j), cap_dy_north};
            out[1] = {c10, c00, north, row_dx(j), cap_dy_north};
            return 2;
        }
        const double dx = std::min(row_dx(j), row_dx(j + 1));
        const std::size_t c00 = node_id(i, j), c10 = node_id(i + 1, j), c01 = node_id(i, j + 1),
                          c11 = node_id(i + 1, j + 1);
        out[0] = {c00, c10, c01, dx, g.dy_km};
        out[1] = {c11, c01, c10, dx, g.dy_km};
        return 2;
    };
    // Every corner condition a node takes part in.
    auto for_each_corner = [&](std::size_t n, const auto &visit) {
        Corner c[2];
        auto cell = [&](long i, long j) {
            const int k = corners(i, j, c);
            for (int m = 0; m < k; ++m)
                if (c[m].involves(n))
                    visit(c[m], 2 * cell_index(i, j) + static_cast<std::size_t>(m));
        };
        if (n >= n_grid) {
            const long j = n == south ? -1 : nlat - 1;
            for (long i = 0; i < nlon; ++i)
                cell(i, j);
            return;
        }
        const long i = static_cast<long>(n % g.nlon), j = static_cast<long>(n / g.nlon);
        cell(i - 1, j - 1);
        cell(i, j - 1);
        cell(i - 1, j);
        cell(i, j);
    };

    // The queue: the nodes' initial values, sorted once, merged with a heap of the values the
    // solver lowers or raises them to (a band along the accepted front: small, where one heap of
    // every node takes a cache miss at each of its levels on every pop). The two pop in the one
    // order (value, node) a single heap of all the entries would: the same sizes. On 1:50m land
    // at --hmax 100km --coast-size 5km (4.2 million grid nodes, 3.2 million seeds, the band at
    // most 74,000): the size field 3.3 -> 2.5 s.
    // Nodes at the largest value never lower a neighbour: they enter only when lowered.
    std::vector<HeapEntry> seeds;
    for (std::size_t n = 0; n < n_grid; ++n)
        if (h[n] < top_value)
            seeds.push_back({h[n], static_cast<std::uint32_t>(n)});
    sort_seeds(seeds);
    std::size_t next_seed = 0;
    MinHeap heap;
    HugeVector<std::uint8_t> accepted(n_grid + 2, 0);
    std::size_t popped = 0;
    // Each condition's bound, rounded down to float (the same minimum: float_down is monotone),
    // changes only when one of its nodes is accepted, so it is kept, and a node's tentative value
    // is the minimum of its ceiling and its conditions' kept bounds. It can rise as well as fall
    // when another node of one of its conditions is accepted: no running minimum is kept.
    const long cell_rows = j_last - j_first + 1;
    HugeVector<float> bound(cell_rows > 0 ? 2 * static_cast<std::size_t>(cell_rows) * g.nlon : 0,
                            float_inf);
    auto tentative = [&](std::size_t m) {
        float t = initial[m];
        for_each_corner(m, [&](const Corner &, std::size_t slot) { t = std::min(t, bound[slot]); });
        return t;
    };
    std::vector<std::size_t> around;
    while (!heap.empty() || next_seed < seeds.size()) {
        HeapEntry top;
        if (heap.empty() || (next_seed < seeds.size() && heap.top() > seeds[next_seed])) {
            top = seeds[next_seed++];
        } else {
            top = heap.top();
            heap.pop();
        }
        if (accepted[top.node] || top.key != h[top.node])
            continue;
        accepted[top.node] = 1;
        if (++popped % (1u << 20) == 0)
            report(progress,
                   std::min(0.99, static_cast<double>(popped) / static_cast<double>(n_grid)),
                   "gradation");
        around.clear();
        for_each_corner(top.node, [&](const Corner &c, std::size_t slot) {
            bound[slot] = float_down(std::min(corner_bound(c, h, accepted, grade), float_max));
            for (std::size_t m : {c.k, c.row, c.col})
                if (!accepted[m] && std::find(around.begin(), around.end(), m) == around.end())
                    around.push_back(m);
        });
        for (std::size_t m : around) {
            // Never below the value just accepted (the conditions held with every unknown node
            // at that value); the max only absorbs rounding.
            const float t = std::max(top.key, tentative(m));
            if (t != h[m]) {
                h[m] = t;
                heap.push({t, static_cast<std::uint32_t>(m)});
            }
        }
    }
    PoleSizes poles;
    if (g.south_cap)
        poles.south = h[south];
    if (g.north_cap)
        poles.north = h[north];
    // The solver's arrays freed before the result is copied out: no higher peak than the solve.
    HugeVector<float>().swap(initial);
    HugeVector<float>().swap(bound);
    HugeVector<std::uint8_t>().swap(accepted);
    std::vector<HeapEntry>().swap(seeds);
    values.assign(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(n_grid));
    return poles;
}

} // namespace globemesh::detail
