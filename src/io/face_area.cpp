// Geodesic face areas on the authalic sphere with a term per side: see face_area.hpp.
#include "face_area.hpp"

#include <array>
#include <cmath>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include "fresh_memory.hpp"
#include "ordered_blocks.hpp"

namespace globemesh::io {

namespace {

/// WGS84 (a, e^2) and its authalic sphere: q at the pole (and 1 / it), the radius R_q (and its
/// square).
struct Ellipsoid {
    double a, e2, qp, inv_qp, rq, rq2;
};

/// atanh(e x) / e for |x| <= 1 and e^2 = WGS84's (0.0067): its series to x^17, whose next
/// term is below 1e-19 relative.
double atanh_e_over_e(double e2, double x) {
    const double t = e2 * x * x;
    return x * (1 + t * (1.0 / 3 +
                         t * (1.0 / 5 +
                              t * (1.0 / 7 +
                                   t * (1.0 / 9 +
                                        t * (1.0 / 11 +
                                             t * (1.0 / 13 + t * (1.0 / 15 + t * (1.0 / 17)))))))));
}

/// q(phi) of the authalic latitude (sin xi = q(phi) / q(pole)), from s = sin(phi).
double authalic_q(const Ellipsoid &w, double s) {
    return (1 - w.e2) * (s / (1 - w.e2 * s * s) + atanh_e_over_e(w.e2, s));
}

const Ellipsoid &wgs84() {
    static const Ellipsoid w = [] {
        const auto &g = GeographicLib::Geodesic::WGS84();
        Ellipsoid e{g.EquatorialRadius(), 0, 0, 0, 0, 0};
        const double f = g.Flattening();
        e.e2 = f * (2 - f);
        e.qp = authalic_q(e, 1);
        e.inv_qp = 1 / e.qp;
        e.rq2 = e.a * e.a * e.qp / 2;
        e.rq = std::sqrt(e.rq2);
        return e;
    }();
    return w;
}

/// sin and cos of the authalic latitude xi at geodetic latitude phi, from sin(phi) (z) and
/// cos(phi) (h >= 0, z^2 + h^2 = 1). cos(xi) comes from q(pole) - q(phi), taken from
/// 1 - |sin phi| = cos^2 / (1 + |sin|), to keep its digits near the poles.
std::array<double, 2> authalic_sin_cos(const Ellipsoid &w, double z, double h) {
    const double s = std::fabs(z), one_minus = h * h / (1 + s);
    const double e2s = w.e2 * s, inv = 1 / (1 - e2s * s); // 1 / (1 - e^2 s^2)
    const double q = (1 - w.e2) * (s * inv + atanh_e_over_e(w.e2, s));
    // q(1) - q(s) = (1 - s) (1 + e^2 s) / (1 - e^2 s^2) + (1 - e^2) atanh(e x) / e with
    // x = (1 - s) / (1 - e^2 s) (atanh(e) - atanh(e s) = atanh(e x)).
    const double to_pole =
        one_minus * (1 + e2s) * inv + (1 - w.e2) * atanh_e_over_e(w.e2, one_minus / (1 - e2s));
    return {std::copysign(q * w.inv_qp, z), std::sqrt(to_pole * (w.qp + q)) * w.inv_qp};
}

/// The point of the authalic sphere (unit vector) where the equal-area map takes the point v
/// (a unit vector of geodetic latitude atan2(v.z, hypot(v.x, v.y))): its authalic latitude.
Vec3 to_authalic(const Ellipsoid &w, const Vec3 &v) {
    const double h = std::sqrt(v.x * v.x + v.y * v.y);
    if (h == 0)
        return {0, 0, v.z > 0 ? 1.0 : -1.0};
    const double to_unit = 1 / std::sqrt(h * h + v.z * v.z);
    const auto [sx, cx] = authalic_sin_cos(w, v.z * to_unit, h * to_unit);
    return {v.x * (cx / h), v.y * (cx / h), sx};
}

/// The geodesic curvature (1/m, positive turning clockwise) on the authalic sphere of the image
/// of the ellipsoid's geodesic through the midpoint of a and b (unit vectors, geodetic) heading
/// from a to b. With k = P / p the map's scale along parallels (1 / k along meridians: equal
/// area), the image's azimuth is atan(k^2 tan alpha); its rate of turn along the image less that
/// of the sphere's great circle of the same azimuth (Clairaut) is, with s = sin(alpha),
/// c = cos(alpha), D = c^2 + k^4 s^2 and xi the authalic latitude,
///   k s (k^2 sin(phi) (1 + 2 c^2) - sin(xi) (k^4 + (3 - k^4) c^2)) / (p D^(3/2)),
/// zero on a sphere (k = 1, xi = phi). Near a pole its terms cancel to O(cos^2 phi): xi's sine and
/// cosine are those of to_authalic.
double image_curvature(const Ellipsoid &w, const Vec3 &a, const Vec3 &b) {
    const Vec3 m = normalized(a + b), d = b - a;
    const double z = m.z, h2 = m.x * m.x + m.y * m.y, w2 = 1 - w.e2 * z * z;
    // The ellipsoid's azimuth, unnormalised: tan alpha = (N / M) tan(azimuth on the unit sphere).
    const double sa = w2 / (1 - w.e2) * (m.x * d.y - m.y * d.x),
                 ca = h2 * d.z - z * (m.x * d.x + m.y * d.y);
    const double sa2 = sa * sa, ca2 = ca * ca, r2 = sa2 + ca2;
    const auto [sx, cx] = authalic_sin_cos(w, z, std::sqrt(h2));
    const double p = w.a * std::sqrt(h2 / w2); // the parallel's radius
    const double k = w.rq * cx / p, k2 = k * k, k4 = k2 * k2, den = ca2 + k4 * sa2;
    const double turn = k2 * z * (r2 + 2 * ca2) - sx * (k4 * r2 + (3 - k4) * ca2);
    return k * sa * turn / (p * den * std::sqrt(den));
}

/// The area (m2) to add to the spherical triangle of a face whose side runs from a to b (unit
/// vectors, geodetic; wa and wb their images) for that side to follow the image of the
/// ellipsoid's geodesic: minus the area between that curve and the great circle, which bows to
/// the face's side (the left) when it turns clockwise.
double side_term(const Ellipsoid &w, const Vec3 &a, const Vec3 &b, const Vec3 &wa, const Vec3 &wb) {
    // The arc from its chord c: 2 asin(c / 2) = c + c^3 / 24 + 3 c^5 / 640 + (below 1e-15 of it
    // for sides under 100 km).
    const Vec3 d = wb - wa;
    const double c2 = dot(d, d), l = w.rq * std::sqrt(c2) * (1 + c2 / 24 + 3 * c2 * c2 / 640);
    return -image_curvature(w, a, b) * l * l * l / 12;
}

} // namespace

double polygon_area_m2(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    GeographicLib::PolygonArea polygon(GeographicLib::Geodesic::WGS84());
    for (const Vec3 *v : {&a, &b, &c}) {
        const LonLat p = vec_to_lonlat(*v);
        polygon.AddPoint(p.lat, p.lon);
    }
    double perimeter, area;
    polygon.Compute(false, true, perimeter, area);
    return std::fabs(area);
}

GeodesicFaceAreas::GeodesicFaceAreas(const MeshTopology &topo) : topo_(topo) {
    const Ellipsoid &w = wgs84();
    const auto &nodes = topo.mesh->nodes;
    authalic_ = fresh_array<Point>(nodes.size());
    for_each_range(nodes.size(), [&](std::size_t first, std::size_t last) {
        for (std::size_t i = first; i < last; ++i)
            authalic_[i] = Point(to_authalic(w, nodes[i]));
    });
    side_ = fresh_array<double>(topo.edge_count());
    for_each_range(topo.edge_count(), [&](std::size_t first, std::size_t last) {
        for (std::size_t e = first; e < last; ++e) {
            const auto [a, b] = topo.edge_nodes(e);
            side_[e] = side_term(w, nodes[std::size_t(a)], nodes[std::size_t(b)],
                                 authalic_[std::size_t(a)].vec(), authalic_[std::size_t(b)].vec());
        }
    });
}

double GeodesicFaceAreas::face_m2(std::size_t f, const std::int32_t *edges_of_f) const {
    const auto &face = topo_.mesh->faces[f];
    const auto &nodes = topo_.mesh->nodes;
    const Vec3 v[3] = {nodes[face[0]], nodes[face[1]], nodes[face[2]]};
    constexpr double longest_chord = short_side_km / 6371.0;
    for (int k = 0; k < 3; ++k)
        if (const Vec3 d = v[(k + 1) % 3] - v[k]; dot(d, d) > longest_chord * longest_chord)
            return polygon_area_m2(v[0], v[1], v[2]);
    const Ellipsoid &w = wgs84();
    const Vec3 s[3] = {authalic_[face[0]].vec(), authalic_[face[1]].vec(),
                       authalic_[face[2]].vec()};
    // The spherical triangle's excess, tan(E / 2) = det / (1 + a.b + b.c + c.a), the determinant
    // from the sides (b - a, c - a) to keep its digits on small faces.
    const double det = dot(s[0], cross(s[1] - s[0], s[2] - s[0]));
    double area =
        w.rq2 * 2 * std::atan2(det, 1 + dot(s[0], s[1]) + dot(s[1], s[2]) + dot(s[2], s[0]));
    for (int k = 0; k < 3; ++k) {
        const auto e = std::size_t(edges_of_f[k]);
        // Side k runs from corner k to corner k + 1: the edge's own direction when the face is
        // the edge's first (edge_nodes), the opposite one on its second; the term is the edge's,
        // so that both faces get the same value.
        const bool forward = topo_.edge_halves[e][0] == 3 * f + std::size_t(k);
        area += forward ? side_[e] : -side_[e];
    }
    return std::fabs(area);
}

} // namespace globemesh::io
