// Time per point of the spherical Delaunay core (sort + triangulate, insert_points(vector&&)),
// against CGAL's Delaunay_triangulation_on_sphere_2 on the same points in the same run when CGAL is
// found. items_per_second is points per second; time per point = 1 / items_per_second. Also a
// coast's insertion and segment recovery (BM_globemesh_rings). Allocates as the globemesh
// executable.
#include <benchmark/benchmark.h>

#include "allocation.hpp"
#include "bench_points.hpp"
#include "globemesh/delaunay.hpp"

#ifdef GLOBEMESH_HAVE_CGAL
#include <CGAL/Delaunay_triangulation_on_sphere_2.h>
#include <CGAL/Delaunay_triangulation_on_sphere_traits_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#endif

using namespace globemesh;

static void run_globemesh(benchmark::State &state, const std::string &kind) {
    const auto points = bench::points_of_kind(kind, static_cast<std::size_t>(state.range(0)));
    for (auto _ : state) {
        // The caller's points are handed over (as `globemesh triangulate` does); the copy made
        // for the next iteration is not timed.
        state.PauseTiming();
        std::vector<Vec3> input = points;
        state.ResumeTiming();
        SphericalDelaunay dt;
        auto ids = dt.insert_points(std::move(input));
        benchmark::DoNotOptimize(ids.data());
        state.counters["triangles"] = static_cast<double>(dt.triangle_count());
    }
    state.SetItemsProcessed(state.iterations() * state.range(0));
}

static void BM_globemesh_uniform(benchmark::State &s) {
    run_globemesh(s, "uniform");
}
static void BM_globemesh_clustered(benchmark::State &s) {
    run_globemesh(s, "clustered");
}
BENCHMARK(BM_globemesh_uniform)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Arg(4000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_globemesh_clustered)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

// A coast's insertion and recovery, as the mesher's steps 1 and 2 do them: the rings' nodes
// inserted, then every segment recovered as a constraint (time per node).
static void BM_globemesh_rings(benchmark::State &state) {
    const auto rings = bench::coast_like_rings(static_cast<std::size_t>(state.range(0)));
    std::vector<Vec3> points;
    for (const auto &r : rings)
        points.insert(points.end(), r.begin(), r.end());
    for (auto _ : state) {
        SphericalDelaunay dt;
        const auto ids = dt.insert_points(points);
        std::size_t recovered = 0, offset = 0;
        for (const auto &r : rings) {
            for (std::size_t i = 0; i < r.size(); ++i)
                recovered +=
                    dt.insert_constraint(ids[offset + i], ids[offset + (i + 1) % r.size()]);
            offset += r.size();
        }
        if (recovered != points.size())
            state.SkipWithError("a segment was not recovered");
        state.counters["triangles"] = static_cast<double>(dt.triangle_count());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_globemesh_rings)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

#ifdef GLOBEMESH_HAVE_CGAL
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Delaunay_triangulation_on_sphere_traits_2<K>;
using DToS2 = CGAL::Delaunay_triangulation_on_sphere_2<Traits>;

static void run_cgal(benchmark::State &state, const std::string &kind) {
    const auto points = bench::points_of_kind(kind, static_cast<std::size_t>(state.range(0)));
    std::vector<K::Point_3> cp;
    cp.reserve(points.size());
    for (const auto &p : points)
        cp.emplace_back(p.x, p.y, p.z);
    for (auto _ : state) {
        DToS2 dt(cp.begin(), cp.end());
        benchmark::DoNotOptimize(dt.number_of_vertices());
        state.counters["triangles"] = static_cast<double>(dt.number_of_faces());
    }
    state.SetItemsProcessed(state.iterations() * state.range(0));
}

static void BM_cgal_uniform(benchmark::State &s) {
    run_cgal(s, "uniform");
}
static void BM_cgal_clustered(benchmark::State &s) {
    run_cgal(s, "clustered");
}
BENCHMARK(BM_cgal_uniform)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Arg(4000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_cgal_clustered)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
#endif

int main(int argc, char **argv) {
    globemesh::configure_allocation(); // as the globemesh executable (src/cli/allocation.cpp)
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
