// The ocean mesher's own cost at one size: reads and shapes a coast, then runs mesh_boundary
// alone `repeats` times with a uniform size field and prints, per run, the nodes, the seconds
// (wall clock, and CPU time of the process, which a shared machine disturbs less) and us/node of
// the whole call, the wall-clock us/node of each stage (insert_boundary, recover, classify,
// refine, improve), and the peak bytes per node of the call itself: the process's high-water
// mark (VmHWM, reset through /proc/self/clear_refs just before the call) minus its resident size
// before the call, so the coast, the boundary and the writer are not counted; the returned Mesh
// is. Then one line of the process's peak in each step, bytes per output node: read_coast,
// boundary (shaping), each stage of mesh_boundary, and write (UGRID to OUT.nc, when given), the
// high-water mark reset at the start of each. Linux only.
// Usage: mesher_memory COAST LAYER HMAX_KM [REPEATS] [OUT.nc] [LATTICE]
// (LATTICE 0: no lattice, MesherOptions::lattice_km; by default HMAX_KM).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "../src/mesher/stage_hook.hpp"
#include "allocation.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/options.hpp"
#include "globemesh/sizefield.hpp"
#include "globemesh/ugrid.hpp"

namespace {

long vm_kib(const char *key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind(key, 0) == 0)
            return std::atol(line.c_str() + std::string(key).size());
    return -1;
}

bool reset_peak() {
    std::ofstream f("/proc/self/clear_refs");
    f << "5";
    return static_cast<bool>(f);
}

} // namespace

int main(int argc, char **argv) {
    if (argc < 4) {
        std::fprintf(stderr,
                     "usage: mesher_memory COAST LAYER HMAX_KM [REPEATS] [OUT.nc] [LATTICE]\n");
        return 2;
    }
    globemesh::MeshOptions o;
    o.coast = argv[1];
    o.coast_layer = argv[2];
    o.hmax_km = std::atof(argv[3]);
    globemesh::configure_allocation(); // as the globemesh executable (src/cli/allocation.cpp)
    const int repeats = argc > 4 ? std::atoi(argv[4]) : 1;
    const globemesh::SizeFn size = globemesh::uniform_size(o.hmax_km);
    globemesh::MesherOptions mo;
    mo.lattice_km = argc > 6 && std::atoi(argv[6]) == 0 ? 0.0 : o.hmax_km;
    // The process's peak in each step (kiB), the high-water mark reset as a step starts.
    std::vector<std::pair<std::string, long>> step_peaks;
    auto step_done = [&](const std::string &step) {
        step_peaks.emplace_back(step, vm_kib("VmHWM:"));
        reset_peak();
    };
    globemesh::Boundary boundary;
    reset_peak();
    {
        globemesh::CoastData coast = globemesh::load_coast(o);
        step_done("read_coast");
        boundary = globemesh::shape_boundary(coast, size, o);
        mo.land = coast.land;
    }
    step_done("boundary");
    globemesh::Mesh last;
    for (int r = 0; r < repeats; ++r) {
        const bool peak_ok = reset_peak();
        const long base = vm_kib("VmRSS:");
        globemesh::StageTimings timings;
        if (r == repeats - 1) // the process's peak in each stage of the last run
            globemesh::mesher_internal::after_stage = step_done;
        globemesh::MesherReport report;
        const std::clock_t c0 = std::clock();
        auto t0 = std::chrono::steady_clock::now();
        globemesh::Mesh mesh = globemesh::mesh_boundary(boundary, size, mo, &report, {}, &timings);
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
        const long peak = vm_kib("VmHWM:");
        const double n = static_cast<double>(mesh.nodes.size());
        std::printf("h %.0f km: %zu nodes, mesh %.3f s = %.2f us/node, CPU %.2f us/node (",
                    o.hmax_km, mesh.nodes.size(), s, 1e6 * s / n, 1e6 * cpu / n);
        for (const auto &[name, sec] : timings.stages)
            std::printf(" %s %.2f", name.c_str(), 1e6 * sec / n);
        std::printf(" ), peak %.0f B/node%s\n", peak_ok ? 1024.0 * double(peak - base) / n : -1.0,
                    peak_ok ? "" : " (clear_refs refused: not measured)");
        std::fflush(stdout);
        if (r == repeats - 1)
            last = std::move(mesh);
    }
    globemesh::mesher_internal::after_stage = nullptr;
    if (argc > 5 && argv[5][0] != '\0') {
        reset_peak();
        globemesh::UgridOptions u;
        u.overwrite = true;
        globemesh::write_ugrid(last, argv[5], u);
        step_done("write");
    }
    const double n = static_cast<double>(last.nodes.size());
    std::printf("h %.0f km: process peak per step, B/node:", o.hmax_km);
    for (const auto &[step, kib] : step_peaks)
        std::printf(" %s %.0f", step.c_str(), 1024.0 * double(kib) / n);
    std::printf("\n");
    return 0;
}
