// Size field: time to build the global field from the ETOPO5 fixture with the issue-5 options
// (--hmin 10 --hmax 150 --wavelength 40 --slope 20 --grade 0.15) and with the demo's (--hmin 40
// --hmax 300 --wavelength 30 --grade 0.2) on 1 and 2 threads, and the cost of one evaluation.
// Run: build/<dir>/bench/sizefield_bench
#include <benchmark/benchmark.h>

#include <optional>
#include <random>
#include <vector>

#include "globemesh/sizefield.hpp"

using namespace globemesh;

namespace {

SizeFieldOptions issue5_options() {
    SizeFieldOptions o;
    o.hmin_km = 10;
    o.hmax_km = 150;
    o.wavelength = 40;
    o.slope = 20;
    o.grade = 0.15;
    return o;
}

const Raster &etopo5() {
    static const Raster r = read_raster(GLOBEMESH_FIXTURES_DIR "/bathy/etopo5_global_10min.nc");
    return r;
}

void BM_read_etopo5_global(benchmark::State &state) {
    for (auto _ : state)
        benchmark::DoNotOptimize(
            read_raster(GLOBEMESH_FIXTURES_DIR "/bathy/etopo5_global_10min.nc"));
}
BENCHMARK(BM_read_etopo5_global)->Unit(benchmark::kMillisecond);

void BM_build_global_size_field(benchmark::State &state) {
    const Raster &r = etopo5();
    for (auto _ : state) {
        SizeField f = build_size_field(issue5_options(), std::nullopt, &r, nullptr);
        state.counters["grid_nodes"] = static_cast<double>(f.grid().values().size());
        benchmark::DoNotOptimize(f);
    }
}
BENCHMARK(BM_build_global_size_field)->Unit(benchmark::kMillisecond)->Iterations(1);

SizeFieldOptions demo_options() {
    SizeFieldOptions o;
    o.hmin_km = 40;
    o.hmax_km = 300;
    o.wavelength = 30;
    o.grade = 0.2;
    return o;
}

// The demo's field (tools/demo) with the per-node terms on state.range(0) threads.
void BM_build_demo_size_field(benchmark::State &state) {
    const Raster &r = etopo5();
    const auto threads = static_cast<std::size_t>(state.range(0));
    for (auto _ : state) {
        SizeField f = build_size_field(demo_options(), std::nullopt, &r, nullptr, {},
                                       std::size_t{1} << 22, {}, {}, threads);
        state.counters["grid_nodes"] = static_cast<double>(f.grid().values().size());
        benchmark::DoNotOptimize(f);
    }
}
BENCHMARK(BM_build_demo_size_field)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

// The field of the 1e6-node run with bathymetry (--hmax 20km --wavelength 30 --grade 0.2, no
// --hmin): the pipeline's largest grid, 2^22 nodes.
void BM_build_hmax20_size_field(benchmark::State &state) {
    SizeFieldOptions o;
    o.hmax_km = 20;
    o.wavelength = 30;
    o.grade = 0.2;
    const Raster &r = etopo5();
    const auto threads = static_cast<std::size_t>(state.range(0));
    for (auto _ : state) {
        SizeField f = build_size_field(o, std::nullopt, &r, nullptr, {}, std::size_t{1} << 22, {},
                                       {}, threads);
        state.counters["grid_nodes"] = static_cast<double>(f.grid().values().size());
        benchmark::DoNotOptimize(f);
    }
}
BENCHMARK(BM_build_hmax20_size_field)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

void BM_size_km(benchmark::State &state) {
    static const SizeField f = build_size_field(issue5_options(), std::nullopt, &etopo5(), nullptr);
    std::mt19937 rng(1);
    std::normal_distribution<double> n;
    std::vector<Vec3> points(1 << 16);
    for (Vec3 &p : points)
        p = normalized({n(rng), n(rng), n(rng)});
    std::size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(f.size_km(points[k]));
        k = (k + 1) & (points.size() - 1);
    }
}
BENCHMARK(BM_size_km);

void BM_elevation_m(benchmark::State &state) {
    const Raster &r = etopo5();
    std::mt19937 rng(2);
    std::normal_distribution<double> n;
    std::vector<Vec3> points(1 << 16);
    for (Vec3 &p : points)
        p = normalized({n(rng), n(rng), n(rng)});
    std::size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(r.elevation_m(points[k]));
        k = (k + 1) & (points.size() - 1);
    }
}
BENCHMARK(BM_elevation_m);

} // namespace

BENCHMARK_MAIN();
