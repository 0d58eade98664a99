// Boundary rings drawn through lon/lat corners, for the tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::test {

/// A ring through lon/lat corners, land on its right (ocean on the left), each side cut into
/// pieces of at most `step` degrees.
inline Ring ring_through(const std::vector<LonLat> &corners, double step = 0.8) {
    Ring r;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        const LonLat a = corners[i], b = corners[(i + 1) % corners.size()];
        const int n = std::max(1, int(std::ceil(std::hypot(b.lon - a.lon, b.lat - a.lat) / step)));
        for (int k = 0; k < n; ++k)
            r.nodes.push_back(
                lonlat_to_vec(a.lon + (b.lon - a.lon) * k / n, a.lat + (b.lat - a.lat) * k / n));
    }
    r.kinds.assign(r.nodes.size(), SegmentKind::coast);
    return r;
}

/// A ring through the lon/lat points as they are (no node added between them), every segment
/// of `kind`.
inline Ring ring_of_points(const std::vector<LonLat> &points,
                           SegmentKind kind = SegmentKind::coast) {
    Ring r;
    for (const LonLat &p : points)
        r.nodes.push_back(lonlat_to_vec(p));
    r.kinds.assign(r.nodes.size(), kind);
    return r;
}

} // namespace globemesh::test
