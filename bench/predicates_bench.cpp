// Cost per call of the exact predicates (globemesh/predicates.hpp).
//
//   cmake --build build/<dir> --target predicates_bench && build/<dir>/bench/predicates_bench
//
// Cases: random unit vectors (the filter answers); nearby points as in a Delaunay insertion
// (a small triangle and a point a few edge lengths away); exactly co-circular quadruples from a
// regular lon/lat grid (isosceles trapezoids, which the filter cannot decide, so the exact
// stage and the level-1 perturbation run); four points on the equator (level 2). Inputs are
// precomputed in arrays walked in order, so the figures include one L1/L2 load per point.
#include <benchmark/benchmark.h>

#include <array>
#include <cstddef>
#include <random>
#include <vector>

#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

using namespace globemesh;
namespace pr = globemesh::predicates;

namespace {

using Quad = std::array<Vec3, 4>;

Vec3 random_unit(std::mt19937_64 &rng) {
    std::normal_distribution<double> n;
    return normalized(Vec3{n(rng), n(rng), n(rng)});
}

std::vector<Quad> random_quads(std::size_t count) {
    std::mt19937_64 rng(1);
    std::vector<Quad> q(count);
    for (Quad &x : q)
        x = {random_unit(rng), random_unit(rng), random_unit(rng), random_unit(rng)};
    return q;
}

/// A triangle with edges ~1e-3 rad (4e6 points on the sphere) and a fourth point nearby.
std::vector<Quad> local_quads(std::size_t count) {
    std::mt19937_64 rng(2);
    std::vector<Quad> q(count);
    const double h = 1e-3;
    for (Quad &x : q) {
        const Vec3 a = random_unit(rng);
        const Vec3 u = random_unit(rng), v = random_unit(rng), w = random_unit(rng);
        x = {a, normalized(a + h * u), normalized(a + h * v), normalized(a + 2 * h * w)};
    }
    return q;
}

/// (lon, lat), (lon + s, lat), (lon + s, lat + s), (lon, lat + s): co-circular on the sphere,
/// counter-clockwise seen from outside. Only the quadruples whose rounded vectors stay exactly
/// co-circular are kept, so every call takes the exact path and the perturbation.
std::vector<Quad> cocircular_grid_quads(std::size_t count) {
    std::vector<Quad> q;
    for (int step = 1; q.size() < count; ++step)
        for (double lon = -180; lon < 180 && q.size() < count; lon += 1)
            for (double lat = -85; lat < 85 && q.size() < count; lat += 1) {
                const double s = 0.25 * step;
                Quad x{lonlat_to_vec(lon, lat), lonlat_to_vec(lon + s, lat),
                       lonlat_to_vec(lon + s, lat + s), lonlat_to_vec(lon, lat + s)};
                if (pr::detail::orient3d_exact(x[0], x[1], x[2], x[3]) == 0)
                    q.push_back(x);
            }
    return q;
}

/// Rounded grid quadruples as the mesher meets them, co-circular or not after rounding:
/// nearly all of them fail the filter.
std::vector<Quad> grid_quads(std::size_t count) {
    std::vector<Quad> q;
    for (double lon = -180; lon < 180 && q.size() < count; lon += 1)
        for (double lat = -85; lat < 85 && q.size() < count; lat += 1)
            q.push_back({lonlat_to_vec(lon, lat), lonlat_to_vec(lon + 1, lat),
                         lonlat_to_vec(lon + 1, lat + 1), lonlat_to_vec(lon, lat + 1)});
    return q;
}

/// Four points on the equator: every 3x3 cofactor is zero, so level 2 decides.
std::vector<Quad> great_circle_quads(std::size_t count) {
    std::vector<Quad> q(count);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> lon(-180, 180);
    for (Quad &x : q)
        x = {lonlat_to_vec(lon(rng), 0), lonlat_to_vec(lon(rng), 0), lonlat_to_vec(lon(rng), 0),
             lonlat_to_vec(lon(rng), 0)};
    return q;
}

constexpr std::size_t n_quads = 4096; // a power of two: the loop wraps with a mask

template <class Make> void run_in_circle(benchmark::State &state, Make make) {
    const std::vector<Quad> q = make(n_quads);
    std::size_t i = 0;
    for (auto _ : state) {
        const Quad &x = q[i];
        benchmark::DoNotOptimize(pr::in_circle(x[0], x[1], x[2], x[3]));
        i = (i + 1) & (n_quads - 1);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void in_circle_random(benchmark::State &s) {
    run_in_circle(s, random_quads);
}
void in_circle_local(benchmark::State &s) {
    run_in_circle(s, local_quads);
}
void in_circle_grid_rounded(benchmark::State &s) {
    run_in_circle(s, grid_quads);
}
void in_circle_grid_cocircular(benchmark::State &s) {
    run_in_circle(s, cocircular_grid_quads);
}
void in_circle_great_circle(benchmark::State &s) {
    run_in_circle(s, great_circle_quads);
}

void orient_random(benchmark::State &state) {
    const std::vector<Quad> q = random_quads(n_quads);
    std::size_t i = 0;
    for (auto _ : state) {
        const Quad &x = q[i];
        benchmark::DoNotOptimize(pr::orient(x[0], x[1], x[2]));
        i = (i + 1) & (n_quads - 1);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void orient_local(benchmark::State &state) {
    const std::vector<Quad> q = local_quads(n_quads);
    std::size_t i = 0;
    for (auto _ : state) {
        const Quad &x = q[i];
        benchmark::DoNotOptimize(pr::orient(x[1], x[2], x[3]));
        i = (i + 1) & (n_quads - 1);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

void orient_exact_great_circle(benchmark::State &state) {
    const std::vector<Quad> q = great_circle_quads(n_quads);
    std::size_t i = 0;
    for (auto _ : state) {
        const Quad &x = q[i];
        benchmark::DoNotOptimize(pr::orient(x[0], x[1], x[2]));
        i = (i + 1) & (n_quads - 1);
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
}

} // namespace

BENCHMARK(in_circle_random);
BENCHMARK(in_circle_local);
BENCHMARK(in_circle_grid_rounded);
BENCHMARK(in_circle_grid_cocircular);
BENCHMARK(in_circle_great_circle);
BENCHMARK(orient_random);
BENCHMARK(orient_local);
BENCHMARK(orient_exact_great_circle);
