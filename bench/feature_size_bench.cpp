// Feature size (--feature-size): what the term adds to the size-field stage it joins. The field
// of a fjord coast is built with --coast-size alone, with --coast-size and --feature-size 3, and
// with --feature-size 3 alone (the same background grid and gradation each time); CPU time, as
// the machine is shared.
// Run: build/<dir>/bench/feature_size_bench COAST LAYER W,S,E,N HMIN_KM HMAX_KM
//   e.g. ../shared/data/ne_10m_land.gpkg land 4,58,16,66 1 20
#include <benchmark/benchmark.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "globemesh/coast.hpp"
#include "globemesh/sizefield.hpp"

using namespace globemesh;

namespace {

CoastOptions coast_options_;
SizeFieldOptions field_options_;

const CoastData &coast() {
    static const CoastData c = load_coast(coast_options_);
    return c;
}

void build(benchmark::State &state, double coast_size_km, double feature_size) {
    SizeFieldOptions o = field_options_;
    o.coast_size_km = coast_size_km;
    o.feature_size = feature_size;
    for (auto _ : state) {
        SizeField f = build_size_field(o, coast_options_.region, nullptr, &coast().rings, {},
                                       std::size_t{1} << 22); // the pipeline's grid cap
        state.counters["grid_nodes"] = static_cast<double>(f.grid().values().size());
        benchmark::DoNotOptimize(f);
    }
}

} // namespace

int main(int argc, char **argv) {
    benchmark::Initialize(&argc, argv);
    if (argc != 6) {
        std::fprintf(stderr, "usage: feature_size_bench COAST LAYER W,S,E,N HMIN_KM HMAX_KM\n");
        return 2;
    }
    coast_options_.coast = argv[1];
    coast_options_.coast_layer = argv[2];
    std::array<double, 4> r{};
    if (std::sscanf(argv[3], "%lf,%lf,%lf,%lf", &r[0], &r[1], &r[2], &r[3]) != 4)
        return 2;
    coast_options_.region = r;
    field_options_.hmin_km = std::atof(argv[4]);
    field_options_.hmax_km = std::atof(argv[5]);
    coast();
    for (int round = 0; round < 3; ++round) { // alternated rounds: the machine's speed drifts
        benchmark::RegisterBenchmark("coast_size_2km", build, 2.0, 0.0)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark("coast_size_2km+feature_size_3", build, 2.0, 3.0)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark("feature_size_3", build, 0.0, 3.0)
            ->Iterations(1)
            ->Unit(benchmark::kMillisecond);
    }
    benchmark::RunSpecifiedBenchmarks();
    return 0;
}
