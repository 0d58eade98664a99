// Write speed and size of the io outputs on a 1,310,720-face icosphere (level 8) with depth and
// target_size fields: UGRID NetCDF-4 (deflate), UGRID classic, GeoPackage, preview PNG, gmsh MSH
// 4.1 and 2.2 and D-Flow FM _net.nc (through the writers table), read-back.
// Run: io_write_bench --benchmark_counters_tabular=true (file sizes are reported as counters).
#include <benchmark/benchmark.h>

#include <filesystem>

#include "../tests/unit/io_test_meshes.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/preview.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"

namespace {

const globemesh::Mesh &big_mesh() {
    static const globemesh::Mesh mesh = [] {
        globemesh::Mesh m = globemesh::test::icosphere(8);
        globemesh::test::add_fields(m);
        return m;
    }();
    return mesh;
}

std::filesystem::path out_path(const char *name) {
    return std::filesystem::temp_directory_path() / (std::string("globemesh-bench-") + name);
}

template <class Write> void run(benchmark::State &state, const char *name, Write write) {
    const auto &m = big_mesh();
    auto path = out_path(name);
    for (auto _ : state) {
        std::filesystem::remove(path);
        write(m, path);
    }
    state.counters["faces"] = double(m.faces.size());
    state.counters["MB"] = double(std::filesystem::file_size(path)) / 1e6;
    std::filesystem::remove(path);
}

void BM_write_ugrid_netcdf4(benchmark::State &s) {
    run(s, "n4.nc", [](const auto &m, const auto &p) { globemesh::write_ugrid(m, p); });
}
void BM_write_ugrid_classic(benchmark::State &s) {
    run(s, "c.nc", [](const auto &m, const auto &p) {
        globemesh::UgridOptions o;
        o.classic = true;
        globemesh::write_ugrid(m, p, o);
    });
}
void BM_write_gpkg(benchmark::State &s) {
    run(s, "m.gpkg", [](const auto &m, const auto &p) { globemesh::write_gpkg(m, p); });
}
void BM_write_preview_png(benchmark::State &s) {
    run(s, "p.png", [](const auto &m, const auto &p) { globemesh::write_preview_png(m, p); });
}
void write_gmsh(const globemesh::Mesh &m, const std::filesystem::path &p, const char *version) {
    globemesh::WriteOptions o;
    o.creation_options = {{"MSH_VERSION", version}};
    globemesh::find_writer(globemesh::writers(), "GMSH")->write(m, p, o);
}
void BM_write_gmsh_41(benchmark::State &s) {
    run(s, "m41.msh", [](const auto &m, const auto &p) { write_gmsh(m, p, "4.1"); });
}
void BM_write_gmsh_22(benchmark::State &s) {
    run(s, "m22.msh", [](const auto &m, const auto &p) { write_gmsh(m, p, "2.2"); });
}
void BM_write_dflowfm(benchmark::State &s) {
    run(s, "m_net.nc", [](const auto &m, const auto &p) {
        globemesh::find_writer(globemesh::writers(), "DFLOWFM")->write(m, p, {});
    });
}
void BM_read_ugrid_and_stats(benchmark::State &s) {
    auto path = out_path("r.nc");
    std::filesystem::remove(path);
    globemesh::write_ugrid(big_mesh(), path);
    for (auto _ : s)
        benchmark::DoNotOptimize(globemesh::compute_stats(globemesh::read_ugrid(path)));
    std::filesystem::remove(path);
}

} // namespace

BENCHMARK(BM_write_ugrid_netcdf4)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_ugrid_classic)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_gpkg)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_preview_png)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_gmsh_41)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_gmsh_22)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_write_dflowfm)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(BM_read_ugrid_and_stats)->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_MAIN();
