// Point sets shared by the core benchmarks: uniform on the sphere, and clustered (90% in a
// 1-degree cap), generated from a fixed seed so every run measures the same input.
#pragma once

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "globemesh/sphere.hpp"

namespace globemesh::bench {

inline std::vector<Vec3> uniform_points(std::size_t n, std::uint64_t seed = 1) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> z(-1, 1), lon(-180, 180);
    std::vector<Vec3> p(n);
    for (auto& v : p) v = lonlat_to_vec(lon(rng), std::asin(z(rng)) * rad_to_deg);
    return p;
}

inline std::vector<Vec3> clustered_points(std::size_t n, std::uint64_t seed = 2) {
    std::vector<Vec3> p = uniform_points(n / 10, seed);
    p.reserve(n); // exactly n: the capacity is what the triangulation adopts and memory counts
    std::mt19937_64 rng(seed + 1);
    std::uniform_real_distribution<double> u(0, 1);
    while (p.size() < n) {
        double r = 0.5 * std::sqrt(u(rng)), az = 2 * pi * u(rng);
        p.push_back(lonlat_to_vec(-30 + r * std::cos(az) / std::cos(45 * deg_to_rad), 45 + r * std::sin(az)));
    }
    return p;
}

inline std::vector<Vec3> points_of_kind(const std::string& kind, std::size_t n) {
    return kind == "clustered" ? clustered_points(n) : uniform_points(n);
}

} // namespace globemesh::bench
