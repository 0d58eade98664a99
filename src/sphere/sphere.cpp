#include "globemesh/sphere.hpp"

#include <algorithm>

namespace globemesh {

void sincosd(double deg, double& s, double& c) {
    // Reduce to [-45, 45] around a multiple of 90 so that quadrant values are exact.
    double r = std::remainder(deg, 360.0);
    double q = std::round(r / 90.0);
    double t = (r - 90.0 * q) * deg_to_rad;
    double st = std::sin(t), ct = std::cos(t);
    switch (static_cast<int>(q) & 3) {
    case 0: s = st; c = ct; break;
    case 1: s = ct; c = -st; break;
    case 2: s = -st; c = -ct; break;
    default: s = -ct; c = st; break;
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

LonLat vec_to_lonlat(const Vec3& v) {
    double h = std::hypot(v.x, v.y);
    double lat = std::atan2(v.z, h) * rad_to_deg;
    double lon = h == 0 ? 0.0 : std::atan2(v.y, v.x) * rad_to_deg;
    if (lon >= 180.0) lon -= 360.0;
    return {lon, lat};
}

double arc_angle(const Vec3& a, const Vec3& b) { return std::atan2(norm(cross(a, b)), dot(a, b)); }

Vec3 arc_midpoint(const Vec3& a, const Vec3& b) { return normalized(a + b); }

Vec3 arc_interpolate(const Vec3& a, const Vec3& b, double t) {
    double w = arc_angle(a, b);
    if (w < 1e-9) return normalized((1.0 - t) * a + t * b);
    double s = std::sin(w);
    return normalized((std::sin((1.0 - t) * w) / s) * a + (std::sin(t * w) / s) * b);
}

double spherical_triangle_area(const Vec3& a, const Vec3& b, const Vec3& c) {
    double det = dot(a, cross(b, c));
    double den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
    return 2.0 * std::atan2(det, den);
}

} // namespace globemesh

namespace globemesh {

double triangle_quality(const Vec3& a, const Vec3& b, const Vec3& c) {
    double la = norm(b - c), lb = norm(c - a), lc = norm(a - b);
    double area = 0.5 * norm(cross(b - a, c - a));
    double perimeter = la + lb + lc;
    double lmax = std::max({la, lb, lc});
    if (perimeter == 0 || lmax == 0) return 0.0;
    double inradius = 2.0 * area / perimeter;
    return 2.0 * std::sqrt(3.0) * inradius / lmax;
}

} // namespace globemesh
