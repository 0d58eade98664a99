// Peak memory of the spherical Delaunay core for one point set, one size per process so the
// high-water mark (VmHWM) belongs to this run alone. Prints bytes per point counting the input
// points and everything the triangulation allocates (the points are handed over, not copied:
// insert_points(std::vector<Vec3>&&), as `globemesh triangulate` does), over the process's
// baseline before the points existed, and the seconds of the ordering ("sort") and of the
// insertions ("triangulate"). Usage: delaunay_memory N uniform|clustered
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "allocation.hpp"
#include "bench_points.hpp"
#include "globemesh/delaunay.hpp"

static long vm_kib(const char *key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind(key, 0) == 0)
            return std::atol(line.c_str() + std::string(key).size());
    return -1;
}

int main(int argc, char **argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: delaunay_memory N uniform|clustered\n");
        return 2;
    }
    globemesh::configure_allocation(); // as the globemesh executable (src/cli/allocation.cpp)
    const std::size_t n = std::strtoull(argv[1], nullptr, 10);
    const std::string kind = argv[2];
    const long base = vm_kib("VmRSS:");
    auto points = globemesh::bench::points_of_kind(kind, n);
    auto t0 = std::chrono::steady_clock::now();
    globemesh::SphericalDelaunay dt;
    auto order = globemesh::SphericalDelaunay::insertion_order(points, 1);
    auto t1 = std::chrono::steady_clock::now();
    auto ids = dt.insert_points(std::move(points), std::move(order));
    auto t2 = std::chrono::steady_clock::now();
    const long peak = vm_kib("VmHWM:");
    const double sort_s = std::chrono::duration<double>(t1 - t0).count();
    const double tri_s = std::chrono::duration<double>(t2 - t1).count();
    const bool check = n <= 200000;
    const bool valid = !check || dt.validate().empty();
    std::printf("%s %zu points: %.3f s (sort %.3f + triangulate %.3f), %.1f ns/point, peak %.1f "
                "bytes/point "
                "(input points included), %zu triangles, %s\n",
                kind.c_str(), n, sort_s + tri_s, sort_s, tri_s, 1e9 * (sort_s + tri_s) / double(n),
                1024.0 * double(peak - base) / double(n), dt.triangle_count(),
                check ? (valid ? "valid" : "INVALID") : "validate skipped");
    return valid ? 0 : 1;
}
