// Geodesic face areas with each edge's inverse problem solved once: see face_area.hpp.
#include "face_area.hpp"

#include <algorithm>
#include <cmath>
#include <system_error>
#include <thread>
#include <vector>

#include <GeographicLib/Accumulator.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/Math.hpp>

namespace globemesh::io {

namespace {

/// +1 or -1 when the shorter way from lon1 to lon2 crosses the prime meridian eastwards or
/// westwards (longitude 0 counts as east of it), else 0: PolygonArea's rule for the crossings
/// whose parity tells a polygon round a pole.
int prime_meridian_transit(double lon1, double lon2) {
    using GeographicLib::Math;
    // Longitudes in [-180, 180] (vec_to_lonlat's) on one side of the meridian: no crossing, as
    // the rule below gives for them, without its angle reductions.
    if ((lon1 < 0) == (lon2 < 0) && !(lon1 > 0 && lon2 == 0))
        return 0;
    const double d = Math::AngDiff(lon1, lon2);
    lon1 = Math::AngNormalize(lon1);
    lon2 = Math::AngNormalize(lon2);
    if (d > 0 && ((lon1 < 0 && lon2 >= 0) || (lon1 > 0 && lon2 == 0)))
        return 1;
    if (d < 0 && lon1 >= 0 && lon2 < 0)
        return -1;
    return 0;
}

/// +1 or -1 when vec_to_lonlat(v).lon is surely in (0, 180) or in (-180, 0), from the sign of
/// v.y alone (a margin keeps lon off 0 and off the 180 that rounding could give), else 0.
int hemisphere_of_lon(const Vec3 &v) {
    const double margin = 1e-12 * std::fabs(v.x);
    return v.y > margin ? 1 : v.y < -margin ? -1 : 0;
}

/// Runs slice(k, threads) for k = 0 .. threads - 1, one per core (at most 16), slice 0 on the
/// calling thread; when the process may start no more threads, the caller runs the rest.
/// slice must be safe to run concurrently with the others.
template <class Slice> void on_every_core(const Slice &slice) {
    const std::size_t threads = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
    std::vector<std::thread> pool;
    std::size_t k = 1;
    try {
        for (; k < threads; ++k)
            pool.emplace_back(slice, k, threads);
    } catch (const std::system_error &) {
        // No more threads (a process limit): this thread runs the slices left.
    }
    for (; k < threads; ++k)
        slice(k, threads);
    slice(0, threads);
    for (auto &t : pool)
        t.join();
}

} // namespace

GeodesicFaceAreas::GeodesicFaceAreas(const MeshTopology &topo, const std::atomic<bool> *stop)
    : topo_(topo), s12_(topo.edge_count()) {
    const auto &wgs84 = GeographicLib::Geodesic::WGS84();
    const auto &nodes = topo.mesh->nodes;
    const std::size_t n = nodes.size();
    // Node by node, each edge among those of its smaller node (node_edges): that node's lon/lat
    // is converted once for its edges rather than once per edge.
    on_every_core([&](std::size_t k, std::size_t threads) {
        double t;
        for (std::size_t v = n * k / threads; v < n * (k + 1) / threads; ++v) {
            if (stop && v % 4096 == 0 && stop->load(std::memory_order_relaxed))
                return;
            const LonLat own = vec_to_lonlat(nodes[v]);
            for (std::size_t e = topo.node_edges[v]; e < topo.node_edges[v + 1]; ++e) {
                const auto ends = topo.edge_nodes(e);
                const bool first = std::size_t(ends[0]) == v;
                const LonLat other = vec_to_lonlat(nodes[std::size_t(ends[first ? 1 : 0])]);
                const LonLat &a = first ? own : other, &b = first ? other : own;
                wgs84.GenInverse(a.lat, a.lon, b.lat, b.lon, GeographicLib::Geodesic::AREA, t, t, t,
                                 t, t, t, s12_[e]);
            }
        }
    });
}

double GeodesicFaceAreas::face_m2(std::size_t f, const std::int32_t *edges_of_f) const {
    const auto &face = topo_.mesh->faces[f];
    const auto &nodes = topo_.mesh->nodes;
    // Corners all east or all west of the prime meridian (and off the antimeridian's 180) cross
    // neither: their longitudes are not needed.
    const int side = hemisphere_of_lon(nodes[face[0]]);
    const bool one_side = side != 0 && hemisphere_of_lon(nodes[face[1]]) == side &&
                          hemisphere_of_lon(nodes[face[2]]) == side;
    double lon[3] = {};
    for (int k = 0; k < 3 && !one_side; ++k)
        lon[k] = vec_to_lonlat(nodes[face[std::size_t(k)]]).lon;
    GeographicLib::Accumulator<> sum;
    int crossings = 0;
    for (int k = 0; k < 3; ++k) {
        const auto e = std::size_t(edges_of_f[k]);
        // Side k runs from corner k to corner k + 1: the edge's own direction when the face is
        // the edge's first (edge_nodes), the opposite one on its second.
        const bool forward = topo_.edge_halves[e][0] == 3 * f + std::size_t(k);
        sum += forward ? s12_[e] : -s12_[e];
        if (!one_side)
            crossings += prime_meridian_transit(lon[k], lon[(k + 1) % 3]);
    }
    // PolygonArea::Compute's reduction: into (-area0/2, area0/2], then half the ellipsoid off a
    // face that goes round a pole.
    const double area0 = GeographicLib::Geodesic::WGS84().EllipsoidArea();
    sum.remainder(area0);
    if (crossings & 1)
        sum += (sum() < 0 ? 0.5 : -0.5) * area0;
    double area = sum();
    if (area > area0 / 2)
        area -= area0;
    else if (area <= -area0 / 2)
        area += area0;
    return std::fabs(area);
}

} // namespace globemesh::io
