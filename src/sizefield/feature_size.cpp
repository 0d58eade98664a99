// The feature-size component: coast samples, their spherical Delaunay triangulation (our core),
// the triangles spanning channels of water, rasterised onto the background grid.
#include "feature_size.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"

namespace globemesh::detail {

namespace {

/// A coast sample: its point and where it lies along its piece of coast (a maximal run of coast
/// segments of one ring; a ring without open segments is one closed piece).
struct Sample {
    Vec3 p;
    std::uint32_t piece = 0;
    double along_km = 0;
};

struct Piece {
    double length_km = 0;
    bool closed = false;
    std::size_t first = 0, count = 0; ///< its samples
};

/// The runs of coast segments of ring r: each a list of node indices (closed: the first node is
/// not repeated at the end).
std::vector<std::vector<std::size_t>> coast_runs(const Ring &r, bool &closed) {
    const std::size_t n = r.nodes.size();
    std::size_t start = n;
    for (std::size_t i = 0; i < n && start == n; ++i)
        if (r.kinds[i] != SegmentKind::coast)
            start = (i + 1) % n; // a run starts after an open segment
    closed = start == n;
    std::vector<std::vector<std::size_t>> runs;
    if (closed) {
        runs.emplace_back(n);
        for (std::size_t i = 0; i < n; ++i)
            runs.back()[i] = i;
        return runs;
    }
    std::vector<std::size_t> run;
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = (start + k) % n;
        if (r.kinds[i] == SegmentKind::coast) {
            if (run.empty())
                run.push_back(i);
            run.push_back((i + 1) % n);
        } else if (!run.empty()) {
            runs.push_back(std::move(run));
            run.clear();
        }
    }
    if (!run.empty())
        runs.push_back(std::move(run));
    return runs;
}

double coast_length_km(const Boundary &b) {
    double km = 0;
    for (const Ring &r : b.rings)
        for (std::size_t i = 0; i < r.nodes.size(); ++i)
            if (r.kinds[i] == SegmentKind::coast)
                km += arc_km(r.nodes[i], r.nodes[(i + 1) % r.nodes.size()]);
    return km;
}

/// Samples a polyline (closed: back to its first node) every spacing_km or closer, evenly.
void sample_piece(const Ring &r, const std::vector<std::size_t> &run, bool closed,
                  double spacing_km, std::vector<Sample> &out, std::vector<Piece> &pieces) {
    Piece piece;
    piece.closed = closed;
    piece.first = out.size();
    const std::size_t segments = closed ? run.size() : run.size() - 1;
    for (std::size_t k = 0; k < segments; ++k)
        piece.length_km += arc_km(r.nodes[run[k]], r.nodes[run[(k + 1) % run.size()]]);
    const double min_count = closed ? 3 : 1;
    const auto count =
        static_cast<std::size_t>(std::max(min_count, std::ceil(piece.length_km / spacing_km)));
    const double step = piece.length_km / static_cast<double>(count);
    const auto id = static_cast<std::uint32_t>(pieces.size());
    double done = 0; // length of the segments before segment k
    std::size_t k = 0;
    for (std::size_t s = 0; s < count + (closed ? 0 : 1); ++s) {
        const double at = std::min(static_cast<double>(s) * step, piece.length_km);
        const Vec3 *a = &r.nodes[run[k]], *c = &r.nodes[run[(k + 1) % run.size()]];
        double len = arc_km(*a, *c);
        while (at > done + len && k + 1 < segments) {
            done += len, ++k;
            a = &r.nodes[run[k]], c = &r.nodes[run[(k + 1) % run.size()]];
            len = arc_km(*a, *c);
        }
        const double t = len > 0 ? std::clamp((at - done) / len, 0.0, 1.0) : 0.0;
        out.push_back({arc_interpolate(*a, *c, t), id, at});
    }
    piece.count = out.size() - piece.first;
    pieces.push_back(piece);
}

/// Distance along the coast between two samples (infinite on different pieces).
double along_km(const Sample &a, const Sample &b, const std::vector<Piece> &pieces) {
    if (a.piece != b.piece)
        return std::numeric_limits<double>::infinity();
    const double d = std::abs(a.along_km - b.along_km);
    const Piece &p = pieces[a.piece];
    return p.closed ? std::min(d, p.length_km - d) : d;
}

/// The direction of the coast at sample i (from its previous to its next sample on the piece).
Vec3 tangent(std::size_t i, const std::vector<Sample> &s, const std::vector<Piece> &pieces) {
    const Piece &p = pieces[s[i].piece];
    const std::size_t k = i - p.first;
    std::size_t prev = k, next = k;
    if (p.closed)
        prev = (k + p.count - 1) % p.count, next = (k + 1) % p.count;
    else
        prev = k > 0 ? k - 1 : k, next = k + 1 < p.count ? k + 1 : k;
    return s[p.first + next].p - s[p.first + prev].p;
}

/// True when the centroid of corners i, j, k lies left of the coast (the ocean) at two of them.
bool in_water(const std::size_t (&corner)[3], const std::vector<Sample> &s,
              const std::vector<Piece> &pieces) {
    const Vec3 g = s[corner[0]].p + s[corner[1]].p + s[corner[2]].p;
    int votes = 0;
    for (std::size_t i : corner) {
        const Vec3 left = cross(s[i].p, tangent(i, s, pieces));
        votes += dot(g - 3.0 * s[i].p, left) > 0;
    }
    return votes >= 2;
}

} // namespace

std::vector<ChannelTriangle> channel_triangles(const Boundary &b, double spacing_km,
                                               double max_lfs_km, std::size_t max_samples) {
    const double length = coast_length_km(b);
    spacing_km =
        std::max(spacing_km, length / static_cast<double>(std::max<std::size_t>(max_samples, 4)));
    std::vector<Sample> samples;
    std::vector<Piece> pieces;
    for (const Ring &r : b.rings) {
        bool closed = false;
        for (const auto &run : coast_runs(r, closed))
            sample_piece(r, run, closed, spacing_km, samples, pieces);
    }
    std::vector<ChannelTriangle> out;
    if (samples.size() < 4)
        return out;
    std::vector<Vec3> points(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i)
        points[i] = samples[i].p;
    SphericalDelaunay dt;
    std::vector<VertexId> vertex;
    try {
        vertex = dt.insert_points(std::move(points));
    } catch (const DataError &) {
        return out; // the samples lie on one circle: no triangle spans water
    }
    // The first sample of each vertex (samples closer than rounding merge).
    std::vector<std::size_t> sample_of(dt.vertex_count(), samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i)
        if (sample_of[vertex[i]] == samples.size())
            sample_of[vertex[i]] = i;
    const double max_angle = std::min(km_to_rad(max_lfs_km), 0.5 * pi);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || !dt.is_solid(t))
            continue;
        const std::size_t corner[3] = {sample_of[dt.vertex(t, 0)], sample_of[dt.vertex(t, 1)],
                                       sample_of[dt.vertex(t, 2)]};
        const Vec3 &a = dt.point(dt.vertex(t, 0)), &bb = dt.point(dt.vertex(t, 1)),
                   &c = dt.point(dt.vertex(t, 2));
        const Vec3 centre = normalized(cross(bb - a, c - a)); // outward for a solid triangle
        const double angle = arc_angle(centre, a);
        if (!(angle <= max_angle) || !in_water(corner, samples, pieces))
            continue;
        const double radius_km = rad_to_km(angle);
        bool spans = false;
        for (int e = 0; e < 3 && !spans; ++e)
            spans =
                along_km(samples[corner[e]], samples[corner[(e + 1) % 3]], pieces) > 4 * radius_km;
        if (spans)
            out.push_back({a, bb, c, radius_km});
    }
    return out;
}

namespace {

/// Lowers h to v on the nodes within margin_km of the spherical triangle t.
void lower_over(const BackgroundGrid &g, const ChannelTriangle &t, double margin_km, float v,
                std::vector<float> &h) {
    const LonLat p[3] = {vec_to_lonlat(t.a), vec_to_lonlat(t.b), vec_to_lonlat(t.c)};
    const double margin_deg = margin_km / earth_radius_km * rad_to_deg;
    double lat_lo = 90, lat_hi = -90, lon_lo = 0, lon_hi = 0;
    for (const LonLat &q : p) {
        lat_lo = std::min(lat_lo, q.lat), lat_hi = std::max(lat_hi, q.lat);
        const double dl = std::remainder(q.lon - p[0].lon, 360.0);
        lon_lo = std::min(lon_lo, dl), lon_hi = std::max(lon_hi, dl);
    }
    lat_lo -= margin_deg, lat_hi += margin_deg;
    const double cos_lat = std::cos(std::min(89.9, std::max(-lat_lo, lat_hi)) * deg_to_rad);
    const bool all_lons = lat_hi >= 89.5 || lat_lo <= -89.5 || lon_hi - lon_lo > 90;
    double west = p[0].lon + lon_lo - margin_deg / cos_lat,
           east = p[0].lon + lon_hi + margin_deg / cos_lat;
    if (!g.global) { // into the grid's own longitudes (a regional grid may pass +-180)
        const double centre = g.lon0 + 0.5 * static_cast<double>(g.nlon - 1) * g.dlon;
        const double shift = std::remainder(p[0].lon - centre, 360.0) + centre - p[0].lon;
        west += shift, east += shift;
    }
    const auto index = [](double x) { return static_cast<std::ptrdiff_t>(std::floor(x)); };
    const std::ptrdiff_t nlon = static_cast<std::ptrdiff_t>(g.nlon),
                         nlat = static_cast<std::ptrdiff_t>(g.nlat);
    std::ptrdiff_t i0 = all_lons ? 0 : index((west - g.lon0) / g.dlon);
    std::ptrdiff_t i1 = all_lons ? nlon - 1 : index((east - g.lon0) / g.dlon) + 1;
    if (!g.global)
        i0 = std::max<std::ptrdiff_t>(i0, 0), i1 = std::min(i1, nlon - 1);
    else if (i1 - i0 >= nlon)
        i0 = 0, i1 = nlon - 1;
    const std::ptrdiff_t j0 = std::max<std::ptrdiff_t>(index((lat_lo - g.lat0) / g.dlat), 0);
    const std::ptrdiff_t j1 = std::min(index((lat_hi - g.lat0) / g.dlat) + 1, nlat - 1);
    // Inside (or within the margin of) the triangle: on the inner side of its three great circles.
    const Vec3 side[3] = {normalized(cross(t.a, t.b)), normalized(cross(t.b, t.c)),
                          normalized(cross(t.c, t.a))};
    const double slack = -std::sin(km_to_rad(margin_km));
    for (std::ptrdiff_t j = j0; j <= j1; ++j)
        for (std::ptrdiff_t i = i0; i <= i1; ++i) {
            const auto col = static_cast<std::size_t>(((i % nlon) + nlon) % nlon);
            const Vec3 q = g.node(col, static_cast<std::size_t>(j));
            if (dot(side[0], q) >= slack && dot(side[1], q) >= slack && dot(side[2], q) >= slack) {
                float &x = h[static_cast<std::size_t>(j) * g.nlon + col];
                x = std::min(x, v);
            }
        }
}

} // namespace

void apply_feature_size(const BackgroundGrid &g, const Boundary &b, double elements, double hmax_km,
                        std::vector<float> &h, const Progress &progress) {
    // A channel lowers h only where 2 lfs / elements < hmax.
    const std::vector<ChannelTriangle> channels =
        channel_triangles(b, g.dy_km, 0.5 * elements * hmax_km);
    report(progress, 0.5, "size field");
    for (const ChannelTriangle &t : channels)
        lower_over(g, t, 1.5 * g.dy_km, static_cast<float>(2 * t.lfs_km / elements), h);
    report(progress, 1.0, "size field");
}

} // namespace globemesh::detail
