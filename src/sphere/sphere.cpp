#include "globemesh/sphere.hpp"
#include "globemesh/predicates.hpp"

#include <algorithm>

namespace globemesh {

void sincosd(double deg, double &s, double &c) {
    // Reduce to [-45, 45] around a multiple of 90 so that quadrant values are exact.
    double r = std::remainder(deg, 360.0);
    double q = std::round(r / 90.0);
    double t = (r - 90.0 * q) * deg_to_rad;
    double st = std::sin(t), ct = std::cos(t);
    switch (static_cast<int>(q) & 3) {
    case 0:
        s = st;
        c = ct;
        break;
    case 1:
        s = ct;
        c = -st;
        break;
    case 2:
        s = -st;
        c = -ct;
        break;
    default:
        s = -ct;
        c = st;
        break;
    }
    s += 0.0; // turn -0 into +0
    c += 0.0;
}

Vec3 lonlat_to_vec(double lon_deg, double lat_deg) {
    double slon, clon, slat, clat;
    sincosd(lon_deg, slon, clon);
    sincosd(lat_deg, slat, clat);
    return {clat * clon, clat * slon, slat};
}

LonLat vec_to_lonlat(const Vec3 &v) {
    double h = std::hypot(v.x, v.y);
    double lat = std::atan2(v.z, h) * rad_to_deg;
    double lon = h == 0 ? 0.0 : std::atan2(v.y, v.x) * rad_to_deg;
    if (lon >= 180.0)
        lon -= 360.0;
    return {lon, lat};
}

double arc_angle(const Vec3 &a, const Vec3 &b) {
    return std::atan2(norm(cross(a, b)), dot(a, b));
}

Vec3 arc_midpoint(const Vec3 &a, const Vec3 &b) {
    return normalized(a + b);
}

double arc_distance(const Vec3 &a, const Vec3 &b, const Vec3 &p) {
    Vec3 n = cross(a, b);
    double ln = norm(n);
    if (ln > 1e-15) {
        n = (1.0 / ln) * n;
        if (dot(cross(a, p), n) >= 0 && dot(cross(p, b), n) >= 0)
            return std::asin(std::min(1.0, std::abs(dot(n, p))));
    }
    return std::min(arc_angle(a, p), arc_angle(p, b));
}

Vec3 arc_interpolate(const Vec3 &a, const Vec3 &b, double t) {
    double w = arc_angle(a, b);
    if (w < 1e-9)
        return normalized((1.0 - t) * a + t * b);
    double s = std::sin(w);
    return normalized((std::sin((1.0 - t) * w) / s) * a + (std::sin(t * w) / s) * b);
}

namespace {

// a*d - b*c to within ~1.5 ulp of the result, however much cancels (Kahan's algorithm with FMA;
// Jeannerod, Louvet, Muller, "Further analysis of Kahan's algorithm", Math. Comp. 82, 2013).
double diff_of_products(double a, double d, double b, double c) {
    const double w = b * c;
    const double e = std::fma(-b, c, w);
    const double f = std::fma(a, d, -w);
    return f + e;
}

// p x q, each component accurate to a few ulps of itself: the direction of the arc between
// nearly antipodal (or nearly equal) points survives.
Vec3 accurate_cross(const Vec3 &p, const Vec3 &q) {
    return {diff_of_products(p.y, q.z, p.z, q.y), diff_of_products(p.z, q.x, p.x, q.z),
            diff_of_products(p.x, q.y, p.y, q.x)};
}

} // namespace

double spherical_triangle_area(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const double det = dot(a, cross(b, c));
    const double den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
    // det^2 + den^2 = 2 (1 + a.b)(1 + b.c)(1 + c.a): both vanish when two vertices are nearly
    // antipodal, and the rounding of the dot products (~1e-16) then swamps them (a hull of a pole,
    // a point 1e-9 rad from the other pole and a third point is such a triangle, of area up to
    // 2 pi). There the angles give the area as alpha + beta + gamma - pi: from cross products
    // accurate to a few ulps of themselves (so even points a few ulps from antipodal keep the
    // direction of their arc), unsigned (each angle in [0, pi], so an angle near pi has no sign
    // to lose), with the sign of the exact orientation.
    if (det * det + den * den < 1e-6) {
        auto angle = [](const Vec3 &p, const Vec3 &q, const Vec3 &r) { // angle at p, q to r
            const Vec3 u = accurate_cross(p, q), v = accurate_cross(p, r);
            return std::atan2(norm(cross(u, v)), dot(u, v));
        };
        const double excess = angle(a, b, c) + angle(b, c, a) + angle(c, a, b) - pi;
        const double e = std::clamp(excess, 0.0, 2 * pi);
        return predicates::orient(a, b, c) < 0 ? -e : e;
    }
    double area = 2.0 * std::atan2(det, den);
    // Below ~1e-14 the rounded det may have the wrong sign; a triangle within rounding of a great
    // circle (area near 0 or +-2 pi) then takes the exact orientation's sign, so that the areas of
    // a closed hull of points near one great circle still add up to 0.
    if (std::fabs(det) < 1e-14) {
        const int s = predicates::orient(a, b, c);
        if ((s > 0 && area < 0) || (s < 0 && area > 0))
            area = -area;
    }
    return area;
}

} // namespace globemesh

namespace globemesh {

double turn_angle(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const Vec3 n1 = cross(a, b), n2 = cross(b, c);
    const double l1 = norm(n1), l2 = norm(n2);
    if (l1 == 0 || l2 == 0)
        return 0;
    return std::acos(std::clamp(dot(n1, n2) / (l1 * l2), -1.0, 1.0));
}

} // namespace globemesh
