// libFuzzer target: predicates::orient, orient3d and in_circle (include/globemesh/predicates.hpp)
// on four points decoded from the input, against GMP rationals.
//
// Points are built one by one, each from a mode byte: a unit vector from lon/lat, a copy of an
// earlier point, an earlier point moved a few ulps, a point near the great circle through two
// earlier points, a point near the circle through three earlier points (rotated about the
// circle's axis), an antipode or pole, small integers (exact co-planar and co-circular sets), an
// exactly cospherical lattice point, or raw coordinates with exponents in [-300, 300] (inside
// the exact stage's precision contract). Checks:
//   * orient and orient3d equal the sign of the exact rational determinant;
//   * in_circle equals orient3d's exact sign when that is non-zero; otherwise, for four distinct
//     points, it is non-zero, antisymmetric under every permutation of its arguments, and equal to
//     the sign of the determinant of concretely perturbed points (the oracle of
//     tests/unit/predicates_test.cpp: radial factors 1 + 2^-(A k) by lexicographic rank, plus
//     coordinate offsets when the four points lie on one plane through the origin; that case is
//     only computed when the integers are short, else only antisymmetry is checked).
// A mismatch prints the points as hex floats and aborts (a libFuzzer crash).
#include <fuzzer/FuzzedDataProvider.h>
#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <tuple>
#include <vector>

#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

using namespace globemesh;

namespace {

template <class T> struct V3 { T x, y, z; };

template <class T> int orient3d_of(const V3<T> &a, const V3<T> &b, const V3<T> &c, const V3<T> &d) {
    T bx = b.x - a.x, by = b.y - a.y, bz = b.z - a.z;
    T cx = c.x - a.x, cy = c.y - a.y, cz = c.z - a.z;
    T dx = d.x - a.x, dy = d.y - a.y, dz = d.z - a.z;
    T det = dx * (by * cz - bz * cy) + dy * (bz * cx - bx * cz) + dz * (bx * cy - by * cx);
    return sgn(det);
}

V3<mpq_class> q3(const Vec3 &p) {
    return {mpq_class(p.x), mpq_class(p.y), mpq_class(p.z)};
}

int gmp_orient(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    const auto A = q3(a), B = q3(b), C = q3(c);
    mpq_class det = A.x * (B.y * C.z - B.z * C.y) + A.y * (B.z * C.x - B.x * C.z) +
                    A.z * (B.x * C.y - B.y * C.x);
    return sgn(det);
}

int gmp_orient3d(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    return orient3d_of(q3(a), q3(b), q3(c), q3(d));
}

/// Exact integers proportional (one common power of two) to the coordinates; bits = longest.
std::vector<std::array<mpz_class, 3>> to_integers(const std::array<Vec3, 4> &pts, long &bits) {
    long emin = 1L << 20;
    for (const Vec3 &p : pts)
        for (double v : {p.x, p.y, p.z})
            if (v != 0) {
                int e;
                const auto m = static_cast<std::int64_t>(std::ldexp(std::frexp(v, &e), 53));
                emin =
                    std::min<long>(emin, e - 53 + std::countr_zero(static_cast<std::uint64_t>(m)));
            }
    std::vector<std::array<mpz_class, 3>> out;
    bits = 1;
    for (const Vec3 &p : pts) {
        std::array<mpz_class, 3> row;
        int k = 0;
        for (double v : {p.x, p.y, p.z}) {
            mpz_class z = 0;
            if (v != 0) {
                int e;
                auto m = static_cast<std::int64_t>(std::ldexp(std::frexp(v, &e), 53));
                const int tz = std::countr_zero(static_cast<std::uint64_t>(m));
                m /= std::int64_t{1} << tz;
                z = mpz_class(static_cast<long>(m));
                z <<= static_cast<mp_bitcnt_t>(e - 53 + tz - emin);
            }
            bits = std::max<long>(bits, static_cast<long>(mpz_sizeinbase(z.get_mpz_t(), 2)));
            row[k++] = z;
        }
        out.push_back(row);
    }
    return out;
}

bool lex_less(const Vec3 &p, const Vec3 &q) {
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
}

/// Sign of orient3d of concretely perturbed points (see the header comment); -2 when the
/// integers are too long for the offset variant to be computed quickly.
int perturbed_oracle(const std::array<Vec3, 4> &pts, bool with_eta) {
    long L;
    auto X = to_integers(pts, L);
    if (with_eta && L > 48)
        return -2;
    std::array<int, 4> rank{1, 1, 1, 1};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (lex_less(pts[j], pts[i]))
                ++rank[i];
    const long A = 3 * L + 24 + 8;
    const long B = 4 * A + 3 * L + 32;
    const long W = with_eta ? B * (1L << 11) : 0;
    const long top = A * 4;
    std::array<V3<mpz_class>, 4> P;
    for (int i = 0; i < 4; ++i) {
        const long g = rank[i];
        mpz_class radial = (mpz_class(1) << static_cast<mp_bitcnt_t>(A * g)) + 1;
        radial <<= static_cast<mp_bitcnt_t>(top - A * g);
        mpz_class c[3];
        for (int k = 0; k < 3; ++k) {
            c[k] = X[i][k] << static_cast<mp_bitcnt_t>(W);
            if (with_eta)
                c[k] += mpz_class(1) << static_cast<mp_bitcnt_t>(W - B * (1L << (3 * (g - 1) + k)));
            c[k] *= radial;
        }
        P[i] = {c[0], c[1], c[2]};
    }
    return orient3d_of(P[0], P[1], P[2], P[3]);
}

[[noreturn]] void fail(const char *what, const std::array<Vec3, 4> &q, int got, int want) {
    std::fprintf(stderr, "fuzz_predicates: %s: got %d, want %d for", what, got, want);
    for (const Vec3 &p : q)
        std::fprintf(stderr, " {%a, %a, %a}", p.x, p.y, p.z);
    std::fprintf(stderr, "\n");
    std::abort();
}

double nudge(double x, int k) {
    for (; k > 0; --k)
        x = std::nextafter(x, INFINITY);
    for (; k < 0; ++k)
        x = std::nextafter(x, -INFINITY);
    return x;
}

Vec3 nudge(FuzzedDataProvider &in, const Vec3 &v) {
    auto k = [&] { return in.ConsumeIntegralInRange<int>(-4, 4); };
    return {nudge(v.x, k()), nudge(v.y, k()), nudge(v.z, k())};
}

bool finite_nonzero(const Vec3 &v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) &&
           (v.x != 0 || v.y != 0 || v.z != 0);
}

Vec3 decode_point(FuzzedDataProvider &in, const std::array<Vec3, 4> &q, int i) {
    const int mode = in.ConsumeIntegralInRange<int>(0, 9);
    const auto earlier = [&] { return q[in.ConsumeIntegralInRange<int>(0, std::max(0, i - 1))]; };
    const auto lonlat = [&] {
        const double lon = in.ConsumeFloatingPointInRange<double>(-180, 180);
        const double lat = in.ConsumeFloatingPointInRange<double>(-90, 90);
        return lonlat_to_vec(lon, lat);
    };
    if (i == 0 && (mode >= 1 && mode <= 5))
        return lonlat();
    switch (mode) {
    case 0:
        return lonlat();
    case 1:
        return earlier();
    case 2:
        return nudge(in, earlier());
    case 3: { // near the great circle through two earlier points
        const Vec3 a = earlier(), b = earlier();
        const double s = in.ConsumeFloatingPointInRange<double>(-1, 1);
        const double t = in.ConsumeFloatingPointInRange<double>(-1, 1);
        const Vec3 v = s * a + t * b;
        return norm(v) > 1e-300 ? nudge(in, normalized(v)) : a;
    }
    case 4: { // near the circle through three earlier points (or tiny triangles' circles)
        const Vec3 a = earlier(), b = earlier(), c = earlier();
        const Vec3 nn = cross(b - a, c - a);
        if (!(norm(nn) > 1e-300))
            return nudge(in, a);
        const Vec3 n = normalized(nn);
        const Vec3 axis_point = dot(n, a) * n;
        const Vec3 r = a - axis_point, s = cross(n, r);
        const double t = in.ConsumeFloatingPointInRange<double>(0, 2 * pi);
        return nudge(in, axis_point + std::cos(t) * r + std::sin(t) * s);
    }
    case 5: { // antipode, or a point very close to an earlier one
        const Vec3 a = earlier();
        if (in.ConsumeBool())
            return nudge(in, -a);
        const double eps = std::ldexp(1.0, -in.ConsumeIntegralInRange<int>(10, 50));
        const Vec3 v = normalized(a + eps * lonlat());
        return v;
    }
    case 6: { // poles and axis points
        static const Vec3 axes[6] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                     {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
        return axes[in.ConsumeIntegralInRange<int>(0, 5)];
    }
    case 7: { // small integers, scaled: exact co-planar / co-circular configurations
        const int e = in.ConsumeIntegralInRange<int>(-8, 8);
        auto c = [&] { return std::ldexp(in.ConsumeIntegralInRange<int>(-6, 6), e); };
        const Vec3 v{c(), c(), c()};
        return finite_nonzero(v) ? v : Vec3{1, 0, 0};
    }
    case 8: { // exactly cospherical lattice points: permutations and signs of (5,0,0), (3,4,0)
        const int base = in.ConsumeIntegralInRange<int>(0, 1);
        const double b[2][3] = {{5, 0, 0}, {3, 4, 0}};
        int perm[3] = {0, 1, 2};
        for (int k = in.ConsumeIntegralInRange<int>(0, 5); k > 0; --k)
            std::next_permutation(perm, perm + 3);
        const int s = in.ConsumeIntegralInRange<int>(0, 7);
        double v[3];
        for (int k = 0; k < 3; ++k)
            v[k] = b[base][perm[k]] * ((s >> k & 1) ? -1 : 1) / 8.0 + 0.0;
        return {v[0], v[1], v[2]};
    }
    default: { // raw coordinates, exponents within the exact stage's contract
        const int e0 = in.ConsumeIntegralInRange<int>(-300, 300);
        auto c = [&] {
            if (in.ConsumeIntegralInRange<int>(0, 7) == 0)
                return 0.0;
            const double m = in.ConsumeFloatingPointInRange<double>(-1, 1);
            return std::ldexp(m, e0 + in.ConsumeIntegralInRange<int>(-3, 3));
        };
        Vec3 v{c(), c(), c()};
        if (!finite_nonzero(v))
            return {std::ldexp(1.0, e0), 0, 0};
        // keep every non-zero coordinate within 2^-600 of the largest (the exact stage's contract)
        const double mx = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
        for (double *x : {&v.x, &v.y, &v.z})
            if (*x != 0 && std::fabs(*x) < std::ldexp(mx, -600))
                *x = 0;
        return v;
    }
    }
}

int permutation_sign(const std::array<int, 4> &p) {
    int s = 1;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            if (p[i] > p[j])
                s = -s;
    return s;
}

/// The exact stage's contract: every non-zero coordinate within 2^-605 of the largest of the call.
bool within_contract(const std::array<Vec3, 4> &q) {
    double mx = 0, mn = INFINITY;
    for (const Vec3 &p : q)
        for (double v : {p.x, p.y, p.z}) {
            if (!std::isfinite(v))
                return false;
            if (v != 0)
                mn = std::min(mn, std::fabs(v)), mx = std::max(mx, std::fabs(v));
        }
    return mx == 0 || mn >= std::ldexp(mx, -605);
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    std::array<Vec3, 4> q{};
    for (int i = 0; i < 4; ++i)
        q[i] = decode_point(in, q, i);
    if (!within_contract(q))
        return 0;
    using namespace globemesh::predicates;

    // orient on every triple
    static constexpr int triples[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
    for (const auto &t : triples) {
        const int want = gmp_orient(q[t[0]], q[t[1]], q[t[2]]);
        const int got = orient(q[t[0]], q[t[1]], q[t[2]]);
        if (got != want)
            fail("orient", q, got, want);
    }
    const int exact = gmp_orient3d(q[0], q[1], q[2], q[3]);
    const int o3 = orient3d(q[0], q[1], q[2], q[3]);
    if (o3 != exact)
        fail("orient3d", q, o3, exact);

    const int s = in_circle(q[0], q[1], q[2], q[3]);
    if (exact != 0) {
        if (s != exact)
            fail("in_circle (non-degenerate)", q, s, exact);
        return 0;
    }
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            if (q[i] == q[j])
                return 0; // equal points: the caller merges them first
    if (s == 0)
        fail("in_circle returned 0 for distinct points", q, s, 1);
    std::array<int, 4> p{0, 1, 2, 3};
    do {
        const int got = in_circle(q[p[0]], q[p[1]], q[p[2]], q[p[3]]);
        if (got != permutation_sign(p) * s)
            fail("in_circle not antisymmetric", q, got, permutation_sign(p) * s);
    } while (std::next_permutation(p.begin(), p.end()));
    const bool flat = gmp_orient(q[0], q[1], q[2]) == 0 && gmp_orient(q[0], q[1], q[3]) == 0 &&
                      gmp_orient(q[0], q[2], q[3]) == 0 && gmp_orient(q[1], q[2], q[3]) == 0;
    const int want = perturbed_oracle(q, flat);
    if (want != -2 && s != want)
        fail("in_circle (perturbed oracle)", q, s, want);
    return 0;
}
