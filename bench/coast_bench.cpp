// Coast speed: read, clean, simplify to a uniform size and resample a coastline file (issue 3
// asks for Natural Earth 1:10m land at 10 km in under 5 s).
//
//   coast_bench PATH [LAYER] [SIZE_KM] [google-benchmark flags...]
//   e.g. coast_bench ../shared/data/ne_10m_land.gpkg land 10
//
// Prints "SKIPPED" and exits 0 when PATH does not exist (the 1:10m file is not a fixture).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "globemesh/coast.hpp"

namespace {

globemesh::CoastOptions options;
const std::uint64_t max_nodes = globemesh::MeshingOptions{}.max_nodes;
double size_km = 10;

void load(benchmark::State &state) {
    std::size_t nodes = 0;
    for (auto _ : state) {
        globemesh::CoastData d = globemesh::load_coast(options);
        nodes = 0;
        for (const auto &r : d.rings.rings)
            nodes += r.nodes.size();
        benchmark::DoNotOptimize(d);
    }
    state.counters["nodes"] = static_cast<double>(nodes);
}

void shape(benchmark::State &state) {
    globemesh::CoastData d = globemesh::load_coast(options);
    globemesh::CoastReport report;
    for (auto _ : state) {
        auto b = globemesh::shape_boundary(
            d, [](const globemesh::Vec3 &) { return size_km; }, options, max_nodes, &report);
        benchmark::DoNotOptimize(b);
    }
    state.counters["rings"] = static_cast<double>(report.rings);
    state.counters["nodes"] = static_cast<double>(report.nodes);
}

void load_and_shape(benchmark::State &state) {
    for (auto _ : state) {
        globemesh::CoastData d = globemesh::load_coast(options);
        auto b = globemesh::shape_boundary(
            d, [](const globemesh::Vec3 &) { return size_km; }, options, max_nodes);
        benchmark::DoNotOptimize(b);
    }
}

} // namespace

int main(int argc, char **argv) {
    std::vector<char *> rest{argv[0]};
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        if (std::string(argv[i]).rfind("--", 0) == 0)
            rest.push_back(argv[i]);
        else
            positional.push_back(argv[i]);
    }
    if (positional.empty()) {
        std::cerr << "usage: coast_bench PATH [LAYER] [SIZE_KM] [benchmark flags]\n";
        return 2;
    }
    options.coast = positional[0];
    if (positional.size() > 1)
        options.coast_layer = positional[1];
    if (positional.size() > 2)
        size_km = std::atof(positional[2].c_str());
    if (!std::filesystem::exists(options.coast)) {
        std::cout << "coast_bench SKIPPED: " << options.coast << " not found\n";
        return 0;
    }
    benchmark::RegisterBenchmark("coast/load", load)->Unit(benchmark::kMillisecond)->Iterations(3);
    benchmark::RegisterBenchmark("coast/shape", shape)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(3);
    benchmark::RegisterBenchmark("coast/load_and_shape", load_and_shape)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(3);
    int n = static_cast<int>(rest.size());
    benchmark::Initialize(&n, rest.data());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
