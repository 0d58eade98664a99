// Insertion order for the spherical Delaunay core: BRIO rounds (Amenta, Choi & Rote 2003), each
// round sorted along a Hilbert curve on the six faces of the cube around the sphere. Points
// that are close in the order are close on the sphere, so the point-location walk is short and
// memory access stays local. Internal to delaunay/. Standard library only.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "globemesh/sphere.hpp"

namespace globemesh::detail {

/// Hilbert key of a point: cube face in the top 3 bits, then the top 29 bits of the Hilbert
/// index of its cell in a 2^15 x 2^15 grid on that face (cells of ~300 m on the Earth; points
/// closer than that keep their input order, which only matters for speed).
std::uint32_t hilbert_key(const Vec3 &p);

/// A permutation of [0, n): BRIO rounds (each point lands in round r with probability 2^-r,
/// drawn from `seed`), every round sorted by hilbert_key. Rounds smaller than 64 points are merged.
std::vector<std::uint32_t> brio_order(std::span<const Vec3> points, std::uint64_t seed);

} // namespace globemesh::detail
