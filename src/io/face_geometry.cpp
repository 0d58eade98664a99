// Lon/lat geometry of faces and lines: see face_geometry.hpp.
#include "face_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace globemesh::io {

namespace {

bool is_pole(const Vec3 &v) {
    return v.x == 0 && v.y == 0;
}

/// d reduced to (-180, 180].
double wrap_delta(double d) {
    while (d > 180)
        d -= 360;
    while (d <= -180)
        d += 360;
    return d;
}

/// Sutherland-Hodgman clip of a ring against lon <= x (keep_below) or lon >= x.
LonLatPart clip_ring(const LonLatPart &ring, double x, bool keep_below) {
    LonLatPart out;
    const std::size_t n = ring.size();
    auto inside = [&](const LonLatPoint &p) { return keep_below ? p[0] <= x : p[0] >= x; };
    for (std::size_t i = 0; i < n; ++i) {
        const LonLatPoint &p = ring[i], &q = ring[(i + 1) % n];
        bool pin = inside(p), qin = inside(q);
        if (pin)
            out.push_back(p);
        if (pin != qin) {
            double t = (x - p[0]) / (q[0] - p[0]);
            out.push_back({x, p[1] + t * (q[1] - p[1])});
        }
    }
    return out;
}

} // namespace

std::vector<LonLatPart> face_polygons(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 v[3] = {a, b, c};
    LonLat ll[3];
    for (int i = 0; i < 3; ++i)
        ll[i] = vec_to_lonlat(v[i]);
    LonLatPart ring;
    for (int i = 0; i < 3; ++i) {
        if (!is_pole(v[i])) {
            ring.push_back({ll[i].lon, ll[i].lat});
            continue;
        }
        const int prev = (i + 2) % 3, next = (i + 1) % 3;
        const double lat = v[i].z > 0 ? 90.0 : -90.0;
        ring.push_back({ll[prev].lon, lat});
        ring.push_back({ll[next].lon, lat});
    }
    // Unwrap so consecutive longitudes differ by less than 180 degrees.
    for (std::size_t i = 1; i < ring.size(); ++i)
        ring[i][0] = ring[i - 1][0] + wrap_delta(ring[i][0] - ring[i - 1][0]);
    const double winding =
        ring.back()[0] + wrap_delta(ring.front()[0] - ring.back()[0]) - ring.front()[0];
    if (std::fabs(winding) > 180) {
        // The face goes round a pole: close it along that pole's line (north when
        // counter-clockwise), its last side ending at the first corner a full turn on.
        const double lat = winding > 0 ? 90.0 : -90.0;
        ring.push_back({ring.front()[0] + winding, ring.front()[1]});
        ring.push_back({ring.front()[0] + winding, lat});
        ring.push_back({ring.front()[0], lat});
    }
    // A piece of under 1e-9 of the face is a sliver along a cut meridian the face only touches
    // (a corner at -180 and the others near 180: its clip's corners within rounding of -180).
    const double floor = std::max(1e-18, 1e-9 * std::fabs(ring_area(ring)));
    std::vector<LonLatPart> parts;
    for (double shift : {-360.0, 0.0, 360.0}) {
        LonLatPart r = ring;
        for (auto &p : r)
            p[0] += shift;
        r = clip_ring(clip_ring(r, 180.0, true), -180.0, false);
        if (r.size() >= 3 && std::fabs(ring_area(r)) > floor)
            parts.push_back(std::move(r));
    }
    return parts;
}

bool simple_face_ring(const Vec3 v[3], const LonLat ll[3], std::array<LonLatPoint, 3> &ring) {
    // face_polygons' steps on three corners, with the cases that change the ring left to it.
    for (int i = 0; i < 3; ++i) {
        if (is_pole(v[i]))
            return false;
        ring[std::size_t(i)] = {ll[i].lon, ll[i].lat};
    }
    for (std::size_t i = 1; i < 3; ++i)
        ring[i][0] = ring[i - 1][0] + wrap_delta(ring[i][0] - ring[i - 1][0]);
    const double winding = ring[2][0] + wrap_delta(ring[0][0] - ring[2][0]) - ring[0][0];
    if (std::fabs(winding) > 180)
        return false;
    // Strictly inside: a corner at +-180 would leave a sliver in the ring shifted by 360.
    for (const auto &p : ring)
        if (!(p[0] > -180 && p[0] < 180))
            return false;
    return std::fabs(ring_area(ring)) > 1e-18;
}

std::vector<LonLatPart> polyline_parts(const std::vector<Vec3> &nodes) {
    LonLatPart line;
    for (const auto &v : nodes) {
        LonLat p = vec_to_lonlat(v);
        if (!line.empty())
            p.lon = line.back()[0] + wrap_delta(p.lon - line.back()[0]);
        line.push_back({p.lon, p.lat});
    }
    std::vector<LonLatPart> parts;
    for (double shift : {-360.0, 0.0, 360.0}) {
        LonLatPart current;
        auto flush = [&] {
            if (current.size() >= 2)
                parts.push_back(current);
            current.clear();
        };
        for (std::size_t i = 0; i + 1 < line.size(); ++i) {
            LonLatPoint p = {line[i][0] + shift, line[i][1]},
                        q = {line[i + 1][0] + shift, line[i + 1][1]};
            // Clip segment p-q to -180 <= lon <= 180 (Liang-Barsky on lon only).
            double t0 = 0, t1 = 1, dx = q[0] - p[0];
            if (dx == 0) {
                // A segment along the antimeridian is kept at 180 only: at -180 too, it was drawn
                // twice (a region ending at 180: its open edge's every segment).
                if (p[0] <= -180 || p[0] > 180) {
                    flush();
                    continue;
                }
            } else {
                double ta = (-180 - p[0]) / dx, tb = (180 - p[0]) / dx;
                t0 = std::max(t0, std::min(ta, tb));
                t1 = std::min(t1, std::max(ta, tb));
                if (t0 >= t1) {
                    flush();
                    continue;
                }
            }
            LonLatPoint s = {p[0] + t0 * dx, p[1] + t0 * (q[1] - p[1])},
                        e = {p[0] + t1 * dx, p[1] + t1 * (q[1] - p[1])};
            if (current.empty() || t0 > 0) {
                flush();
                current.push_back(s);
            }
            current.push_back(e);
            if (t1 < 1)
                flush();
        }
        flush();
    }
    return parts;
}

} // namespace globemesh::io
