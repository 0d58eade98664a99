// Point sets shared by the core benchmarks: uniform on the sphere, and clustered (90% in a
// 1-degree cap), generated from a fixed seed so every run measures the same input.
#pragma once

#include <algorithm>
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
    for (auto &v : p)
        v = lonlat_to_vec(lon(rng), std::asin(z(rng)) * rad_to_deg);
    return p;
}

inline std::vector<Vec3> clustered_points(std::size_t n, std::uint64_t seed = 2) {
    std::vector<Vec3> p = uniform_points(n / 10, seed);
    p.reserve(n); // exactly n: the capacity is what the triangulation adopts and memory counts
    std::mt19937_64 rng(seed + 1);
    std::uniform_real_distribution<double> u(0, 1);
    while (p.size() < n) {
        double r = 0.5 * std::sqrt(u(rng)), az = 2 * pi * u(rng);
        p.push_back(lonlat_to_vec(-30 + r * std::cos(az) / std::cos(45 * deg_to_rad),
                                  45 + r * std::sin(az)));
    }
    return p;
}

/// Closed rings like a shaped coast, about n nodes in all: 100 wiggly loops around the points
/// of a Fibonacci lattice, apart from one another, each a polygon of 24 corners whose
/// great-circle arcs are cut evenly (so most nodes lie on a great circle with their
/// neighbours, as a resampled coast's do). Counter-clockwise around their centres.
inline std::vector<std::vector<Vec3>> coast_like_rings(std::size_t n, std::uint64_t seed = 3) {
    constexpr int loops = 100, corners = 24;
    const std::size_t per_arc = std::max<std::size_t>(1, n / (loops * corners));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.6, 1.0);
    std::vector<std::vector<Vec3>> rings;
    for (int k = 0; k < loops; ++k) {
        // Lattice point k; loops of radius up to 0.15 rad stay apart (neighbours are ~0.35 apart).
        const double z = 1 - (2 * k + 1) / double(loops), lon = k * pi * (3 - std::sqrt(5.0));
        const Vec3 c{std::sqrt(1 - z * z) * std::cos(lon), std::sqrt(1 - z * z) * std::sin(lon), z};
        const Vec3 e1 = normalized(cross(c, std::abs(c.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 e2 = cross(c, e1);
        std::vector<Vec3> poly;
        for (int i = 0; i < corners; ++i) {
            const double a = 2 * pi * i / corners, r = 0.15 * u(rng);
            poly.push_back(normalized(c + r * (std::cos(a) * e1 + std::sin(a) * e2)));
        }
        std::vector<Vec3> ring;
        for (int i = 0; i < corners; ++i)
            for (std::size_t j = 0; j < per_arc; ++j)
                ring.push_back(
                    arc_interpolate(poly[i], poly[(i + 1) % corners], double(j) / double(per_arc)));
        rings.push_back(std::move(ring));
    }
    return rings;
}

inline std::vector<Vec3> points_of_kind(const std::string &kind, std::size_t n) {
    return kind == "clustered" ? clustered_points(n) : uniform_points(n);
}

} // namespace globemesh::bench
