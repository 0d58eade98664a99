// Peak memory of the spherical Delaunay core for one point set, one size per process so the
// high-water mark (VmHWM) belongs to this run alone. Prints bytes per point counting the input
// points and everything the triangulation allocates, over the process's baseline before the
// points existed. Usage: delaunay_memory N uniform|clustered
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "bench_points.hpp"
#include "globemesh/delaunay.hpp"

static long vm_kib(const char* key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::string(key).size());
    return -1;
}

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: delaunay_memory N uniform|clustered\n");
        return 2;
    }
    const std::size_t n = std::strtoull(argv[1], nullptr, 10);
    const std::string kind = argv[2];
    const long base = vm_kib("VmRSS:");
    auto points = globemesh::bench::points_of_kind(kind, n);
    auto t0 = std::chrono::steady_clock::now();
    globemesh::SphericalDelaunay dt;
    auto ids = dt.insert_points(points);
    auto t1 = std::chrono::steady_clock::now();
    const long peak = vm_kib("VmHWM:");
    double seconds = std::chrono::duration<double>(t1 - t0).count();
    bool valid = n > 200000 || dt.validate().empty();
    std::printf("%s %zu points: %.3f s, %.1f ns/point, peak %.1f bytes/point (input points included), "
                "%zu triangles, %s\n",
                kind.c_str(), n, seconds, 1e9 * seconds / double(n), 1024.0 * double(peak - base) / double(n),
                dt.triangle_count(), n > 200000 ? "validate skipped" : (valid ? "valid" : "INVALID"));
    return valid ? 0 : 1;
}
