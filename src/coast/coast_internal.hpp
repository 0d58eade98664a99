// Internal pieces of the coast module shared by its source files (not installed).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::coast_detail {

/// Two arcs (ring_a, seg_a) and (ring_b, seg_b) that touch or cross.
struct ArcPair {
    std::uint32_t ring_a, seg_a, ring_b, seg_b;
};

/// True when the great-circle arcs a-b and c-d (each shorter than pi/2) touch or cross.
bool arcs_conflict(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Every pair of arcs of the closed rings that touch or cross (consecutive arcs of one ring only
/// when they fold back), found through a uniform 3-D grid; sorted, at most max_pairs.
std::vector<ArcPair> find_conflicts(const std::vector<const std::vector<Vec3>*>& rings,
                                    std::size_t max_pairs = static_cast<std::size_t>(-1));

/// Geodesic area (WGS84) to the left of all the closed lon/lat rings, km2 (sum of signed
/// GeographicLib areas modulo the Earth's area); the whole Earth when there is no ring.
double rings_area_km2(const std::vector<std::vector<LonLat>>& rings);

} // namespace globemesh::coast_detail
