// The face areas of a UGRID file against GeographicLib's PolygonArea, face by face: reads the
// file's node lon/lat, face nodes and "area" with netCDF-C (nothing of globemesh), solves each
// face as PolygonArea does, and prints the largest absolute and relative differences, how many
// faces differ by more than 1e-9 relative, and how many by more than PolygonArea's own rounding
// allows (1e-9 area + 4 c^2 eps sum |dlon|, as tests/unit/face_area_test.cpp).
//   face_area_check FILE.nc
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <thread>
#include <type_traits>
#include <vector>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <netcdf.h>

namespace {

template <class T> std::vector<T> read_var(int nc, const char *name) {
    int v, dims[2], ndims;
    std::size_t n = 1, len;
    if (nc_inq_varid(nc, name, &v) || nc_inq_varndims(nc, v, &ndims) ||
        nc_inq_vardimid(nc, v, dims)) {
        std::fprintf(stderr, "face_area_check: no variable %s\n", name);
        std::exit(1);
    }
    for (int k = 0; k < ndims; ++k) {
        nc_inq_dimlen(nc, dims[k], &len);
        n *= len;
    }
    std::vector<T> out(n);
    const int status = std::is_same_v<T, double>
                           ? nc_get_var_double(nc, v, (double *)(void *)out.data())
                           : nc_get_var_int(nc, v, (int *)(void *)out.data());
    if (status) {
        std::fprintf(stderr, "face_area_check: reading %s: %s\n", name, nc_strerror(status));
        std::exit(1);
    }
    return out;
}

struct Worst {
    double abs = 0, rel = 0, ratio = 0;
    std::size_t over_1e9 = 0, over_bound = 0;
};

} // namespace

int main(int argc, char **argv) {
    int nc;
    if (argc != 2 || nc_open(argv[1], NC_NOWRITE, &nc)) {
        std::fprintf(stderr,
                     "usage: face_area_check FILE.nc (a UGRID file with an area variable)\n");
        return 2;
    }
    const auto lon = read_var<double>(nc, "mesh_node_lon"),
               lat = read_var<double>(nc, "mesh_node_lat");
    const auto faces = read_var<int>(nc, "mesh_face_nodes");
    const auto area = read_var<double>(nc, "area");
    nc_close(nc);
    const auto &g = GeographicLib::Geodesic::WGS84();
    const double c2 = g.EllipsoidArea() / (4 * M_PI), eps = std::numeric_limits<double>::epsilon();
    const std::size_t nf = area.size(), threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<Worst> worst(threads);
    std::vector<std::thread> pool;
    for (std::size_t t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (std::size_t f = nf * t / threads; f < nf * (t + 1) / threads; ++f) {
                GeographicLib::PolygonArea polygon(g);
                double span = 0;
                for (int k = 0; k < 3; ++k) {
                    const auto i = std::size_t(faces[3 * f + std::size_t(k)]),
                               j = std::size_t(faces[3 * f + std::size_t(k + 1) % 3]);
                    polygon.AddPoint(lat[i], lon[i]);
                    span += std::fabs(std::remainder(lon[j] - lon[i], 360.0)) * M_PI / 180;
                }
                double perimeter, ref;
                polygon.Compute(false, true, perimeter, ref);
                ref = std::fabs(ref);
                const double d = std::fabs(area[f] - ref), bound = 1e-9 * ref + 4 * c2 * eps * span;
                Worst &w = worst[t];
                w.abs = std::max(w.abs, d);
                w.rel = std::max(w.rel, d / ref);
                w.ratio = std::max(w.ratio, d / bound);
                w.over_1e9 += d > 1e-9 * ref;
                w.over_bound += d > bound;
            }
        });
    Worst all;
    for (std::size_t t = 0; t < threads; ++t) {
        pool[t].join();
        all.abs = std::max(all.abs, worst[t].abs);
        all.rel = std::max(all.rel, worst[t].rel);
        all.ratio = std::max(all.ratio, worst[t].ratio);
        all.over_1e9 += worst[t].over_1e9;
        all.over_bound += worst[t].over_bound;
    }
    std::printf(
        "%s: %zu faces; area - PolygonArea: max abs %.3g m2, max rel %.3g; over 1e-9 rel: %zu; "
        "over the rounding bound: %zu (max ratio %.3g)\n",
        argv[1], nf, all.abs, all.rel, all.over_1e9, all.over_bound, all.ratio);
    return all.over_bound ? 1 : 0;
}
