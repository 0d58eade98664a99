// Internal pieces of SphericalDelaunay shared by its source files (not installed).
#pragma once

namespace globemesh::delaunay_detail {

// Edge i of a triangle joins corners next3(i) and prev3(i) (indices mod 3).
constexpr int next3(int i) {
    return i == 2 ? 0 : i + 1;
}
constexpr int prev3(int i) {
    return i == 0 ? 2 : i - 1;
}

} // namespace globemesh::delaunay_detail
