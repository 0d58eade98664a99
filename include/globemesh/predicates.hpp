// globemesh/predicates.hpp: exact geometric predicates on points of the unit sphere.
//
// Both predicates are signs of determinants of the input doubles, taken as exact numbers:
// a floating-point filter with a certified error bound answers almost every call, and an exact
// expansion-arithmetic evaluation (Shewchuk 1997) answers the rest. No epsilon anywhere.
//
// in_circle() is the only predicate the triangulation's combinatorics depend on; it is made
// total by symbolic perturbation so that it never returns 0 for distinct points:
//   level 1: each point p is moved radially to (1 + eps^k) p, where k is its rank in the
//            lexicographic (x, y, z) order of the four points (smallest point, largest move).
//            This decides every co-circular quadruple that does not lie on one great circle.
//   level 2: four points on one great circle (a flat face of the hull, which only appears when
//            the points lie in a closed hemisphere) are decided by Simulation of Simplicity on
//            the coordinates, in the same lexicographic rank order.
// The perturbation depends only on the coordinates, never on indices or insertion order, so the
// perturbed point set, and hence its Delaunay triangulation, is unique: insertion order cannot
// change the result. Standard library only.
//
// Input range (the precision contract, in numbers).
//   * The filters below are certified for any finite doubles: they answer only when every
//     coordinate difference (orient3d, in_circle) or coordinate (orient) column has a largest
//     magnitude in [2^-300, 2^300] (about [5e-91, 2e90]) and the rounded determinant exceeds
//     the error bound; every other call goes to the exact evaluation.
//   * The exact evaluation first scales all the coordinates of a call by one power of two
//     (which changes no sign) so that the largest magnitude is in [2^299, 2^300). It is then
//     exact whenever every non-zero coordinate of the call is at least 2^-605 (about 1e-182)
//     times the largest one: every partial product is then a multiple of 2^-1074 below 2^920,
//     so no step of the expansion arithmetic underflows or overflows. Unit vectors qualify as
//     long as no coordinate is non-zero and below 1e-182 (lon/lat within 1e-180 degrees of a
//     coordinate plane, but not on it). Outside that ratio the result is still -1, 0 or +1 and
//     deterministic, but a sign decided by the exact stage may be wrong. Infinities and NaNs
//     are not supported (unspecified sign).
//   * Assumes IEEE-754 binary64 arithmetic rounding to nearest-even (x86-64 SSE2, AArch64),
//     as every C++20 compiler provides by default; do not build with -ffast-math.
//
// Cost (bench/predicates_bench.cpp): the filtered paths take a few ns; the exact stage a few
// hundred ns. References: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and
// Fast Robust Geometric Predicates", Discrete Comput. Geom. 18 (1997); H. Edelsbrunner and
// E. P. Muecke, "Simulation of Simplicity", ACM Trans. Graphics 9 (1990).
#pragma once

#include <algorithm>
#include <cmath>

#include "globemesh/sphere.hpp"

namespace globemesh::predicates {

/// Exact sign of det[a, b, c] = a . (b x c): +1 when c is strictly left of the great circle
/// through a then b (seen from outside), -1 when right, 0 when the three vectors are coplanar
/// with the origin. No perturbation.
inline int orient(const Vec3 &a, const Vec3 &b, const Vec3 &c);

/// Exact sign of (d - a) . ((b - a) x (c - a)), no perturbation: +1 when d lies on the side of
/// the plane through a, b, c that (b - a) x (c - a) points to.
inline int orient3d(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d);

/// orient3d with the symbolic perturbation above. For unit vectors with a, b, c counter-clockwise
/// seen from outside, +1 means d lies strictly inside the circumcircle of abc on the sphere
/// (d is beyond the face's plane, "visible" from it as in a 3-D convex hull). Returns 0 only when
/// two arguments are equal points (the caller must merge duplicates first).
inline int in_circle(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d);

namespace detail {

// Exact stages (src/sphere/predicates.cpp), called when the filter cannot decide.
int orient_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c);
int orient3d_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d);
int in_circle_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d);

// Semi-static filters (the bound scales with the largest magnitude in each coordinate column,
// as in CGAL's generated static filters). Derivation, with u = 2^-53:
//   orient: each of the 6 monomials a_i b_j c_k passes through 5 roundings (product, minor
//   difference, product, two additions), so the error is at most gamma_5 * sum |monomials|
//   <= 5u/(1-5u) * 6 * X*Y*Z (Higham, Accuracy and Stability, lemma 3.1), below 30.0001u XYZ.
//   orient3d: 3 more roundings, one per coordinate difference, so gamma_8 * 6 * XYZ / (1-u)^3
//   for X, Y, Z the largest *rounded* differences, below 48.001u XYZ.
// The constants 32u and 50u leave room for the 3 roundings of the bound itself and for
// underflow. Every column maximum is >= 2^-300, so the bound is >= 2^-947 and never underflows
// itself; an underflowed operation errs by <= 2^-1075 and is multiplied afterwards by at most
// one factor <= H = max(X, Y, Z), and a dozen of those stay below 2^-400 * u * XYZ since
// XYZ >= H * 2^-600. The column maxima are <= 2^300 so nothing overflows (6 * 2^900).
inline constexpr double filter_min = 0x1p-300;
inline constexpr double filter_max = 0x1p300;
inline constexpr double orient_bound = 32 * 0x1p-53;
inline constexpr double orient3d_bound = 50 * 0x1p-53;

inline bool filter_range(double x, double y, double z) {
    // Written so that a NaN fails the test.
    return std::min(std::min(x, y), z) >= filter_min && std::max(std::max(x, y), z) <= filter_max;
}

/// +1 / -1 when the rounded determinant's sign is certified, 0 when undecided.
inline int orient_filter(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const double m1 = b.y * c.z - b.z * c.y;
    const double m2 = b.z * c.x - b.x * c.z;
    const double m3 = b.x * c.y - b.y * c.x;
    const double det = a.x * m1 + a.y * m2 + a.z * m3;
    const double mx = std::max(std::max(std::fabs(a.x), std::fabs(b.x)), std::fabs(c.x));
    const double my = std::max(std::max(std::fabs(a.y), std::fabs(b.y)), std::fabs(c.y));
    const double mz = std::max(std::max(std::fabs(a.z), std::fabs(b.z)), std::fabs(c.z));
    const double bound = orient_bound * mx * my * mz;
    if (filter_range(mx, my, mz)) {
        if (det > bound)
            return 1;
        if (det < -bound)
            return -1;
    }
    return 0;
}

/// The same for (d - a) . ((b - a) x (c - a)).
inline int orient3d_filter(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    const double bax = b.x - a.x, bay = b.y - a.y, baz = b.z - a.z;
    const double cax = c.x - a.x, cay = c.y - a.y, caz = c.z - a.z;
    const double dax = d.x - a.x, day = d.y - a.y, daz = d.z - a.z;
    const double m1 = bay * caz - baz * cay;
    const double m2 = baz * cax - bax * caz;
    const double m3 = bax * cay - bay * cax;
    const double det = dax * m1 + day * m2 + daz * m3;
    const double mx = std::max(std::max(std::fabs(bax), std::fabs(cax)), std::fabs(dax));
    const double my = std::max(std::max(std::fabs(bay), std::fabs(cay)), std::fabs(day));
    const double mz = std::max(std::max(std::fabs(baz), std::fabs(caz)), std::fabs(daz));
    const double bound = orient3d_bound * mx * my * mz;
    if (filter_range(mx, my, mz)) {
        if (det > bound)
            return 1;
        if (det < -bound)
            return -1;
    }
    return 0;
}

} // namespace detail

inline int orient(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const int s = detail::orient_filter(a, b, c);
    return s != 0 ? s : detail::orient_exact(a, b, c);
}

inline int orient3d(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    const int s = detail::orient3d_filter(a, b, c, d);
    return s != 0 ? s : detail::orient3d_exact(a, b, c, d);
}

inline int in_circle(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    // A certified non-zero sign of the unperturbed determinant is also the perturbed sign.
    const int s = detail::orient3d_filter(a, b, c, d);
    return s != 0 ? s : detail::in_circle_exact(a, b, c, d);
}

/// What orient(a, b, c) computes from b and c alone, kept for testing many a against one edge
/// b -> c (the far edges of a star, in the mesher's searches): the minors b x c and each
/// coordinate column's largest magnitude over b and c. orient(a, OrientEdge(b, c)) is
/// orient(a, b, c), the same rounded determinant and bound, with the exact stage behind.
struct OrientEdge {
    Vec3 b, c;
    Vec3 minors; // b x c, rounded as orient_filter rounds it
    Vec3 extent; // max(|b.x|, |c.x|), and the same for y and z
    OrientEdge(const Vec3 &b_, const Vec3 &c_)
        : b(b_), c(c_), minors{b_.y * c_.z - b_.z * c_.y, b_.z * c_.x - b_.x * c_.z,
                               b_.x * c_.y - b_.y * c_.x},
          extent{std::max(std::fabs(b_.x), std::fabs(c_.x)),
                 std::max(std::fabs(b_.y), std::fabs(c_.y)),
                 std::max(std::fabs(b_.z), std::fabs(c_.z))} {}
};

inline int orient(const Vec3 &a, const OrientEdge &e) {
    const double det = a.x * e.minors.x + a.y * e.minors.y + a.z * e.minors.z;
    const double mx = std::max(std::fabs(a.x), e.extent.x);
    const double my = std::max(std::fabs(a.y), e.extent.y);
    const double mz = std::max(std::fabs(a.z), e.extent.z);
    const double bound = detail::orient_bound * mx * my * mz;
    if (detail::filter_range(mx, my, mz)) {
        if (det > bound)
            return 1;
        if (det < -bound)
            return -1;
    }
    return detail::orient_exact(a, e.b, e.c);
}

} // namespace globemesh::predicates
