// lon/lat of many points with SLEEF: see lonlat_batch.hpp.
#include "lonlat_batch.hpp"

#include <algorithm>
#include <cmath>

#include <sleef.h>

namespace globemesh::io {

namespace detail {

bool has_avx() {
#if defined(__x86_64__)
    static const bool avx = __builtin_cpu_supports("avx");
    return avx;
#else
    return false;
#endif
}

void atan2_batch(Atan2Path path, const double *y, const double *x, double *out, std::size_t n) {
    std::size_t i = 0;
#if defined(__x86_64__)
    if (path == Atan2Path::avx && has_avx())
        return atan2_avx(y, x, out, n);
    if (path != Atan2Path::plain)
        for (; i + 2 <= n; i += 2)
            _mm_storeu_pd(out + i,
                          Sleef_cinz_atan2d2_u10sse2(_mm_loadu_pd(y + i), _mm_loadu_pd(x + i)));
#endif
    for (; i < n; ++i)
        out[i] = Sleef_cinz_atan2d1_u10purec(y[i], x[i]);
}

} // namespace detail

void lonlat_batch(const Vec3 *p, std::size_t n, double *lon, double *lat) {
    constexpr std::size_t step = 256; // columns on the stack, a few kB
    double x[step], y[step], z[step], h[step];
    for (std::size_t first = 0; first < n; first += step) {
        const std::size_t m = std::min(step, n - first);
        for (std::size_t i = 0; i < m; ++i) {
            const Vec3 &v = p[first + i];
            x[i] = v.x, y[i] = v.y, z[i] = v.z, h[i] = std::sqrt(v.x * v.x + v.y * v.y);
        }
        detail::atan2_batch(detail::Atan2Path::avx, z, h, lat + first, m);
        detail::atan2_batch(detail::Atan2Path::avx, y, x, lon + first, m);
        for (std::size_t i = 0; i < m; ++i) {
            double &a = lon[first + i];
            a = h[i] == 0 ? 0.0 : a * rad_to_deg;
            if (a >= 180.0)
                a -= 360.0;
            lat[first + i] *= rad_to_deg;
        }
    }
}

} // namespace globemesh::io
