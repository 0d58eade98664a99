// Internal to io/: lon/lat of many points at once, for the UGRID writer's face centres and edge
// midpoints (5 of every 6 coordinates it writes).
//
// glibc's atan2 and hypot took 15% of the writer's CPU. SLEEF's "cinz" functions (no FMA,
// within 1 ulp) give the same bits with SSE2, AVX and plain C (SLEEF's own promise, checked by
// tests/unit/lonlat_batch_test.cpp), so the file does not depend on the machine, and the AVX one
// takes a third of glibc's time. A point's lon/lat may differ from vec_to_lonlat's in the last
// bits (2 ulp at most: sqrt for hypot, then atan2); the nodes, which define the mesh, keep
// vec_to_lonlat's.
#pragma once

#include <cstddef>

#include "globemesh/sphere.hpp"

namespace globemesh::io {

/// lon[i], lat[i] (degrees, lon in [-180, 180), 0 at a pole) of the unit vectors p[0 .. n).
void lonlat_batch(const Vec3 *p, std::size_t n, double *lon, double *lat);

namespace detail {
/// The ways atan2_batch can take; avx falls back to sse2 on a CPU without AVX, and both to plain
/// off x86-64.
enum class Atan2Path { avx, sse2, plain };
/// out[i] = atan2(y[i], x[i]) (radians) for i < n by SLEEF's Sleef_cinz_atan2 (1 ulp) on `path`.
void atan2_batch(Atan2Path path, const double *y, const double *x, double *out, std::size_t n);
/// Whether this CPU runs AVX.
bool has_avx();
/// atan2_batch's AVX path (lonlat_batch_avx.cpp, x86-64 only): only where has_avx().
void atan2_avx(const double *y, const double *x, double *out, std::size_t n);
} // namespace detail

} // namespace globemesh::io
