// Geodesic face areas on the authalic sphere with a term per side: see face_area.hpp.
#include "face_area.hpp"

#include <array>
#include <cmath>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

namespace globemesh::io {

namespace {

/// WGS84 (a, e^2) and its authalic sphere: q at the pole and the radius R_q (and its square).
struct Ellipsoid {
    double a, e2, qp, rq, rq2;
};

/// atanh(e x) / e for |x| <= 1 and e^2 = WGS84's (0.0067): its series to x^17, whose next
/// term is below 1e-19 relative.
double atanh_e_over_e(double e2, double x) {
    const double t = e2 * x * x;
    double sum = 1.0 / 17;
    for (int k = 15; k >= 1; k -= 2)
        sum = 1.0 / k + t * sum;
    return x * sum;
}

/// q(phi) of the authalic latitude (sin xi = q(phi) / q(pole)), from s = sin(phi).
double authalic_q(const Ellipsoid &w, double s) {
    return (1 - w.e2) * (s / (1 - w.e2 * s * s) + atanh_e_over_e(w.e2, s));
}

const Ellipsoid &wgs84() {
    static const Ellipsoid w = [] {
        const auto &g = GeographicLib::Geodesic::WGS84();
        Ellipsoid e{g.EquatorialRadius(), 0, 0, 0, 0};
        const double f = g.Flattening();
        e.e2 = f * (2 - f);
        e.qp = authalic_q(e, 1);
        e.rq2 = e.a * e.a * e.qp / 2;
        e.rq = std::sqrt(e.rq2);
        return e;
    }();
    return w;
}

/// sin and cos of the authalic latitude of the point at geodetic latitude phi, from sin(phi) (z)
/// and cos(phi) (h >= 0). q(pole) - q(phi) is taken from 1 - |sin phi| = cos^2 / (1 + |sin|) to
/// keep the digits of cos xi near the poles.
std::array<double, 2> authalic_sin_cos(const Ellipsoid &w, double z, double h) {
    const double s = std::fabs(z), one_minus = h * h / (1 + s);
    const double q = authalic_q(w, s);
    const double to_pole = one_minus * (1 + w.e2 * s) / (1 - w.e2 * s * s) +
                           (1 - w.e2) * atanh_e_over_e(w.e2, one_minus / (1 - w.e2 * s));
    return {std::copysign(q / w.qp, z), std::sqrt(to_pole * (w.qp + q)) / w.qp};
}

/// The point of the authalic sphere (unit vector) where the equal-area map takes the point v
/// (a unit vector of geodetic latitude atan2(v.z, hypot(v.x, v.y))): its authalic latitude.
Vec3 to_authalic(const Ellipsoid &w, const Vec3 &v) {
    const double h = std::sqrt(v.x * v.x + v.y * v.y), r = std::sqrt(h * h + v.z * v.z);
    if (h == 0)
        return {0, 0, v.z > 0 ? 1.0 : -1.0};
    const auto [sx, cx] = authalic_sin_cos(w, v.z / r, h / r);
    return {v.x * (cx / h), v.y * (cx / h), sx};
}

/// The geodesic curvature (1/m, positive turning left) on the authalic sphere of the image of
/// the ellipsoid's geodesic through m (unit vector, geodetic) heading along d (a chord).
/// With k = P / p the map's scale along parallels (1 / k along meridians: equal area), the
/// image's azimuth is atan(k^2 tan alpha); its rate of turn along the image, less that of the
/// sphere's great circle of the same azimuth (Clairaut), is the curvature.
double image_curvature(const Ellipsoid &w, const Vec3 &m, const Vec3 &d) {
    const double z = m.z, h = std::sqrt(m.x * m.x + m.y * m.y);
    const Vec3 east{-m.y / h, m.x / h, 0}, north{-z * m.x / h, -z * m.y / h, h};
    // The ellipsoid's azimuth: tan alpha = (N / M) tan(azimuth on the unit sphere).
    const double w2 = 1 - w.e2 * z * z;
    double sa = w2 / (1 - w.e2) * dot(d, east), ca = dot(d, north);
    const double r = std::sqrt(sa * sa + ca * ca);
    sa /= r;
    ca /= r;
    const double wr = std::sqrt(w2), n = w.a / wr, mr = w.a * (1 - w.e2) / (wr * w2), p = n * h;
    const auto [sx, cx] = authalic_sin_cos(w, z, h);
    const double big_p = w.rq * cx;
    const double k = big_p / p, k2 = k * k;
    const double k_lat = mr * (big_p * z / (p * p) - sx / big_p); // dk / dphi
    const double turn = sa * z / p;                               // dalpha / ds (geodesic)
    const double k2_s = 2 * k * k_lat * ca / mr;                  // d(k^2) / ds
    const double den = ca * ca + k2 * k2 * sa * sa;
    const double image_turn = (k2_s * sa * ca + k2 * turn) / den;  // dalpha' / ds
    const double stretch = std::sqrt(ca * ca / k2 + k2 * sa * sa); // ds' / ds
    const double sin_image = k2 * sa / std::sqrt(den);
    return image_turn / stretch - sx * sin_image / big_p;
}

/// The area (m2) between the image of the geodesic from a to b and the authalic sphere's great
/// circle between their images wa and wb, positive on the left of a -> b.
double side_term(const Ellipsoid &w, const Vec3 &a, const Vec3 &b, const Vec3 &wa, const Vec3 &wb) {
    // The arc from its chord c: 2 asin(c / 2) = c + c^3 / 24 + 3 c^5 / 640 + (below 1e-15 of it
    // for sides under 100 km).
    const Vec3 d = wb - wa;
    const double c2 = dot(d, d), l = w.rq * std::sqrt(c2) * (1 + c2 / 24 + 3 * c2 * c2 / 640);
    return -image_curvature(w, normalized(a + b), b - a) * l * l * l / 12;
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

GeodesicFaceAreas::GeodesicFaceAreas(const MeshTopology &topo, const std::atomic<bool> *)
    : topo_(topo) {}

double GeodesicFaceAreas::face_m2(std::size_t f, const std::int32_t *edges_of_f) const {
    const auto &face = topo_.mesh->faces[f];
    const auto &nodes = topo_.mesh->nodes;
    const Vec3 v[3] = {nodes[face[0]], nodes[face[1]], nodes[face[2]]};
    constexpr double longest_chord = short_side_km / 6371.0;
    for (int k = 0; k < 3; ++k)
        if (const Vec3 d = v[(k + 1) % 3] - v[k]; dot(d, d) > longest_chord * longest_chord)
            return polygon_area_m2(v[0], v[1], v[2]);
    const Ellipsoid &w = wgs84();
    const Vec3 s[3] = {to_authalic(w, v[0]), to_authalic(w, v[1]), to_authalic(w, v[2])};
    // The spherical triangle's excess, tan(E / 2) = det / (1 + a.b + b.c + c.a), the determinant
    // from the sides (b - a, c - a) to keep its digits on small faces.
    const double det = dot(s[0], cross(s[1] - s[0], s[2] - s[0]));
    double area =
        w.rq2 * 2 * std::atan2(det, 1 + dot(s[0], s[1]) + dot(s[1], s[2]) + dot(s[2], s[0]));
    for (int k = 0; k < 3; ++k) {
        const int j = (k + 1) % 3;
        const auto e = std::size_t(edges_of_f[k]);
        // Side k runs from corner k to corner j: the edge's own direction when the face is the
        // edge's first (edge_nodes), the opposite one on its second; the term is computed in the
        // edge's direction so that both faces get the same value.
        const bool forward = topo_.edge_halves[e][0] == 3 * f + std::size_t(k);
        area +=
            forward ? side_term(w, v[k], v[j], s[k], s[j]) : -side_term(w, v[j], v[k], s[j], s[k]);
    }
    return std::fabs(area);
}

} // namespace globemesh::io
