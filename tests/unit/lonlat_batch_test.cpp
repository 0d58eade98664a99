// The UGRID writer's lon/lat of face centres and edge midpoints (src/io/lonlat_batch.hpp): the
// same bits on SLEEF's AVX, SSE2 and plain-C paths (the file must not depend on the machine),
// within 2 ulp of vec_to_lonlat, and its conventions at the poles and the antimeridian.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <random>
#include <vector>

#include "globemesh/sphere.hpp"
#include "lonlat_batch.hpp"

namespace {

using globemesh::Vec3;
namespace io = globemesh::io;

/// Distance in units in the last place between two doubles of the same sign.
std::int64_t ulps(double a, double b) {
    std::int64_t x, y;
    std::memcpy(&x, &a, sizeof x);
    std::memcpy(&y, &b, sizeof y);
    return x > y ? x - y : y - x;
}

/// Random unit vectors, then the awkward ones: poles, the antimeridian from both sides, axes.
std::vector<Vec3> test_points() {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> g;
    std::vector<Vec3> p;
    for (int i = 0; i < 200000; ++i)
        p.push_back(globemesh::normalized(Vec3{g(rng), g(rng), g(rng)}));
    for (double y : {0.0, -0.0, 1e-300, -1e-300, 1e-17, -1e-17})
        p.push_back(globemesh::normalized(Vec3{-1, y, 0.3}));
    p.push_back({0, 0, 1}), p.push_back({0, 0, -1});
    p.push_back({1, 0, 0}), p.push_back({0, 1, 0}), p.push_back({0, -1, 0});
    return p;
}

TEST(LonLatBatch, avx_sse2_and_plain_paths_give_the_same_bits) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-2, 2);
    const std::size_t n = 100003; // not a multiple of the vector widths
    std::vector<double> y(n), x(n), a(n), b(n), c(n);
    for (std::size_t i = 0; i < n; ++i)
        y[i] = u(rng), x[i] = u(rng);
    y[0] = 0, x[0] = -1, y[1] = -0.0, x[1] = -1, y[2] = 1, x[2] = 0, y[3] = 0, x[3] = 0;
    using io::detail::Atan2Path;
    io::detail::atan2_batch(Atan2Path::avx, y.data(), x.data(), a.data(), n);
    io::detail::atan2_batch(Atan2Path::sse2, y.data(), x.data(), b.data(), n);
    io::detail::atan2_batch(Atan2Path::plain, y.data(), x.data(), c.data(), n);
    if (!io::detail::has_avx())
        std::cout << "this CPU has no AVX: the avx path ran as sse2\n";
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(std::memcmp(&a[i], &b[i], sizeof a[i]), 0) << i << ": " << a[i] << " " << b[i];
        ASSERT_EQ(std::memcmp(&a[i], &c[i], sizeof a[i]), 0) << i << ": " << a[i] << " " << c[i];
        ASSERT_LE(ulps(a[i], std::atan2(y[i], x[i])), 1) << y[i] << " " << x[i];
    }
}

TEST(LonLatBatch, within_two_ulp_of_vec_to_lonlat_with_its_conventions) {
    const std::vector<Vec3> p = test_points();
    std::vector<double> lon(p.size()), lat(p.size());
    io::lonlat_batch(p.data(), p.size(), lon.data(), lat.data());
    for (std::size_t i = 0; i < p.size(); ++i) {
        const globemesh::LonLat want = globemesh::vec_to_lonlat(p[i]);
        EXPECT_GE(lon[i], -180.0) << i;
        EXPECT_LT(lon[i], 180.0) << i;
        // Near +-180 the two may sit on either side of the cut: compare modulo 360.
        const double dlon = std::remainder(lon[i] - want.lon, 360.0);
        EXPECT_LE(std::fabs(dlon), 2 * std::ldexp(std::numeric_limits<double>::epsilon(), 7))
            << i << ": " << lon[i] << " " << want.lon;
        if (std::fabs(want.lon) < 179) {
            EXPECT_LE(ulps(lon[i], want.lon), 2) << i << ": " << lon[i] << " " << want.lon;
        }
        EXPECT_LE(ulps(lat[i], want.lat), 2) << i << ": " << lat[i] << " " << want.lat;
    }
    // The poles: lat +-90 exactly and lon 0, as vec_to_lonlat gives them.
    const std::size_t north = p.size() - 5, south = p.size() - 4;
    EXPECT_EQ(lat[north], 90.0);
    EXPECT_EQ(lat[south], -90.0);
    EXPECT_EQ(lon[north], 0.0);
    EXPECT_EQ(lon[south], 0.0);
    EXPECT_EQ(lon[p.size() - 3], 0.0);
    EXPECT_EQ(lon[p.size() - 2], 90.0);
    EXPECT_EQ(lon[p.size() - 1], -90.0);
}

} // namespace
