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
#pragma once

#include "globemesh/sphere.hpp"

namespace globemesh::predicates {

/// Exact sign of det[a, b, c] = a . (b x c): +1 when c is strictly left of the great circle
/// through a then b (seen from outside), -1 when right, 0 when the three vectors are coplanar
/// with the origin. No perturbation.
int orient(const Vec3& a, const Vec3& b, const Vec3& c);

/// Exact sign of (d - a) . ((b - a) x (c - a)), no perturbation: +1 when d lies on the side of
/// the plane through a, b, c that (b - a) x (c - a) points to.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// orient3d with the symbolic perturbation above. For unit vectors with a, b, c counter-clockwise
/// seen from outside, +1 means d lies strictly inside the circumcircle of abc on the sphere
/// (d is beyond the face's plane, "visible" from it as in a 3-D convex hull). Returns 0 only when
/// two arguments are equal points (the caller must merge duplicates first).
int in_circle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

} // namespace globemesh::predicates
