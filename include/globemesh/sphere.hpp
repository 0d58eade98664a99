// globemesh/sphere.hpp: points on the unit sphere and the few constructions the mesher needs.
//
// Every geometric computation in globemesh happens on unit vectors (Vec3), never on lon/lat.
// Conversions to and from degrees live here, with one Earth radius (mean radius of WGS84,
// 6371.0088 km) used to turn kilometres into radians and back.
//
// Accuracy: lonlat_to_vec is degree-exact at multiples of 90 degrees (the poles are exactly
// (0,0,+-1), the equator has z == 0), otherwise within 1 ulp per component. Constructions
// (midpoints, normalisation, arc lengths) are inexact: their results are rounded to double and
// they never feed a predicate's sign decision except as new input points.
// Standard library only.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace globemesh {

/// Mean Earth radius (IUGG R1 of WGS84), km. The only Earth radius used in globemesh.
inline constexpr double earth_radius_km = 6371.0088;
inline constexpr double pi = 3.14159265358979323846;
inline constexpr double deg_to_rad = pi / 180.0;
inline constexpr double rad_to_deg = 180.0 / pi;

/// A 3-D vector; points on the sphere are unit vectors (x towards lon 0, z towards the north pole).
struct Vec3 {
    double x = 0, y = 0, z = 0;

    friend constexpr Vec3 operator+(const Vec3 &a, const Vec3 &b) {
        return {a.x + b.x, a.y + b.y, a.z + b.z};
    }
    friend constexpr Vec3 operator-(const Vec3 &a, const Vec3 &b) {
        return {a.x - b.x, a.y - b.y, a.z - b.z};
    }
    friend constexpr Vec3 operator-(const Vec3 &a) { return {-a.x, -a.y, -a.z}; }
    friend constexpr Vec3 operator*(double s, const Vec3 &a) { return {s * a.x, s * a.y, s * a.z}; }
    friend constexpr bool operator==(const Vec3 &, const Vec3 &) = default;
};

constexpr double dot(const Vec3 &a, const Vec3 &b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3 cross(const Vec3 &a, const Vec3 &b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(const Vec3 &a) {
    return std::sqrt(dot(a, a));
}
/// a / |a|; a must not be the zero vector.
inline Vec3 normalized(const Vec3 &a) {
    return (1.0 / norm(a)) * a;
}

/// Longitude and latitude in degrees.
struct LonLat {
    double lon = 0, lat = 0;
};

/// sin and cos of an angle in degrees, exact at multiples of 90 (GeographicLib's sincosd idea).
void sincosd(double deg, double &s, double &c);

/// Unit vector of a lon/lat in degrees (any longitude; latitude in [-90, 90]).
Vec3 lonlat_to_vec(double lon_deg, double lat_deg);
inline Vec3 lonlat_to_vec(const LonLat &p) {
    return lonlat_to_vec(p.lon, p.lat);
}

/// Lon/lat in degrees of a non-zero vector; longitude in [-180, 180), latitude in [-90, 90].
/// At the poles the longitude is 0.
LonLat vec_to_lonlat(const Vec3 &v);

/// Great-circle angle between two unit vectors, radians in [0, pi] (atan2 form, accurate for
/// tiny and near-antipodal angles).
double arc_angle(const Vec3 &a, const Vec3 &b);

/// Great-circle distance between two unit vectors on the Earth, km.
inline double arc_km(const Vec3 &a, const Vec3 &b) {
    return arc_angle(a, b) * earth_radius_km;
}

/// Midpoint of the shorter great-circle arc a-b (a and b not antipodal), a unit vector.
Vec3 arc_midpoint(const Vec3 &a, const Vec3 &b);

/// The point at fraction t in [0, 1] along the shorter great-circle arc a-b (slerp), unit vector.
Vec3 arc_interpolate(const Vec3 &a, const Vec3 &b, double t);

/// Angular distance (radians) from the unit vector p to the shorter great-circle arc a-b: to the
/// arc's great circle when p lies between the planes through a and b normal to it, else to the
/// nearer end.
double arc_distance(const Vec3 &a, const Vec3 &b, const Vec3 &p);

/// How much the line a, b, c turns at b: the angle (radians, in [0, pi]) between the great
/// circles a-b and b-c; 0 when a = b or b = c.
double turn_angle(const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// Area of the spherical triangle abc on the unit sphere, steradians, signed: positive when abc
/// is counter-clockwise seen from outside (Van Oosterom-Strackee formula).
double spherical_triangle_area(const Vec3 &a, const Vec3 &b, const Vec3 &c);

inline constexpr double km_to_rad(double km) {
    return km / earth_radius_km;
}
inline constexpr double rad_to_km(double rad) {
    return rad * earth_radius_km;
}

} // namespace globemesh

namespace globemesh {

/// triangle_quality below with la = |b - c| already known: the improve stage's searches try
/// many a against one b, c, some 1e6 times per 1e5 nodes (hence inline).
inline double triangle_quality(const Vec3 &a, const Vec3 &b, const Vec3 &c, double la) {
    const double lb = norm(c - a), lc = norm(a - b);
    const double area = 0.5 * norm(cross(b - a, c - a));
    const double perimeter = la + lb + lc;
    const double lmax = std::max({la, lb, lc});
    if (perimeter == 0 || lmax == 0)
        return 0.0;
    const double inradius = 2.0 * area / perimeter;
    return 2.0 * std::sqrt(3.0) * inradius / lmax;
}

/// Shape quality of the chordal (flat) triangle through three unit vectors:
/// q = 2*sqrt(3)*inradius/longest edge, 1 for equilateral, 0 for degenerate (mesh-verify's q).
inline double triangle_quality(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    return triangle_quality(a, b, c, norm(b - c));
}

} // namespace globemesh
