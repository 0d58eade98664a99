// The AVX path of lonlat_batch.cpp's atan2_batch, alone in a file compiled with -mavx (where
// sleef.h declares SLEEF's AVX functions; src/io/CMakeLists.txt) and called only on a CPU with
// AVX. Nothing else lives here: an inline function emitted in this file could stand in for
// another file's copy and run AVX code on any CPU. (A function-level target("avx") declaration
// instead miscompiled with clang 14 under -fsanitize=null: both arguments became y.)
#include <cstddef>

#include <immintrin.h>
#include <sleef.h>

#include "lonlat_batch.hpp"

namespace globemesh::io::detail {

void atan2_avx(const double *y, const double *x, double *out, std::size_t n) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        _mm256_storeu_pd(out + i,
                         Sleef_cinz_atan2d4_u10avx(_mm256_loadu_pd(y + i), _mm256_loadu_pd(x + i)));
    for (; i < n; ++i)
        out[i] = Sleef_cinz_atan2d1_u10purec(y[i], x[i]);
}

} // namespace globemesh::io::detail
