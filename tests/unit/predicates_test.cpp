// Tests of globemesh/predicates.hpp against an independent exact oracle: GMP rationals for the
// unperturbed signs, and for the perturbed in_circle the exact determinant of concretely
// perturbed points (radial factor 1 + 2^-(A k), coordinate offsets 2^-(B 2^(3r+c))), with A and B
// chosen so large that the concrete sign equals the symbolic one. The oracle never looks at the
// library's derivation (cofactor order, masks, parity); it only builds the perturbed points.
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

using namespace globemesh;
using globemesh::predicates::in_circle;
using globemesh::predicates::orient;
using globemesh::predicates::orient3d;

namespace {

// --- oracle -------------------------------------------------------------------------------------

struct Q3 {
    mpq_class x, y, z;
};
Q3 q3(const Vec3 &v) {
    return {mpq_class(v.x), mpq_class(v.y), mpq_class(v.z)};
}

int gmp_orient(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    Q3 A = q3(a), B = q3(b), C = q3(c);
    mpq_class det = A.x * (B.y * C.z - B.z * C.y) + A.y * (B.z * C.x - B.x * C.z) +
                    A.z * (B.x * C.y - B.y * C.x);
    return sgn(det);
}

template <class T> struct V3 { T x, y, z; };
template <class T> int orient3d_of(const V3<T> &a, const V3<T> &b, const V3<T> &c, const V3<T> &d) {
    T bx = b.x - a.x, by = b.y - a.y, bz = b.z - a.z;
    T cx = c.x - a.x, cy = c.y - a.y, cz = c.z - a.z;
    T dx = d.x - a.x, dy = d.y - a.y, dz = d.z - a.z;
    T det = dx * (by * cz - bz * cy) + dy * (bz * cx - bx * cz) + dz * (bx * cy - by * cx);
    return sgn(det);
}

int gmp_orient3d(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    auto v = [](const Vec3 &p) { return V3<mpq_class>{p.x, p.y, p.z}; };
    return orient3d_of(v(a), v(b), v(c), v(d));
}

bool lex_less(const Vec3 &p, const Vec3 &q) {
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
}

/// Exact integers proportional (by one common power of two) to the coordinates of the points.
std::vector<std::array<mpz_class, 3>> to_integers(const std::vector<Vec3> &pts, long &bits) {
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
                m /= std::int64_t{1} << tz; // exact: odd mantissa, v = m * 2^(e - 53 + tz)
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

/// Sign of orient3d of a concretely perturbed copy of `pts` (indices qa..qd into it). Point i
/// of rank g_i (lexicographic rank within `pts`, 1-based) becomes
///   (1 + eps^g_i) (p_i + (eta^(2^(3(g_i-1))), eta^(2^(3(g_i-1)+1)), eta^(2^(3(g_i-1)+2)))),
/// eps = 2^-A, eta = 2^-B, or without the eta term when with_eta is false. With `pts` larger
/// than the query this is one perturbation of the whole set (global ranks).
int perturbed_oracle(const std::vector<Vec3> &pts, int qa, int qb, int qc, int qd, bool with_eta) {
    const std::size_t n = pts.size();
    long L;
    auto X = to_integers(pts, L);
    std::vector<int> rank(n, 1);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j)
            if (lex_less(pts[j], pts[i]))
                ++rank[i];
    const long A = 3 * L + 24 + 8;
    const long B = static_cast<long>(n) * A + 3 * L + 32;
    const long W = with_eta ? B * (1L << (3 * n - 1)) : 0;
    const long top = A * static_cast<long>(n);
    std::vector<V3<mpz_class>> P(n);
    for (std::size_t i = 0; i < n; ++i) {
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
    return orient3d_of(P[qa], P[qb], P[qc], P[qd]);
}

bool on_one_plane_through_origin(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    return gmp_orient(a, b, c) == 0 && gmp_orient(a, b, d) == 0 && gmp_orient(a, c, d) == 0 &&
           gmp_orient(b, c, d) == 0;
}

/// The oracle's in_circle: exact sign if non-zero, 0 for equal points, else the perturbed sign
/// (eta only needed, and only used, when the four points span a plane through the origin).
int oracle_in_circle(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    if (int s = gmp_orient3d(a, b, c, d); s != 0)
        return s;
    const std::vector<Vec3> pts{a, b, c, d};
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            if (pts[i] == pts[j])
                return 0;
    return perturbed_oracle(pts, 0, 1, 2, 3, on_one_plane_through_origin(a, b, c, d));
}

// --- generators --------------------------------------------------------------------------------

struct Gen {
    std::mt19937_64 rng{20240611};
    std::normal_distribution<double> normal{0.0, 1.0};
    std::uniform_real_distribution<double> uniform{0.0, 1.0};

    Vec3 unit() {
        Vec3 v{normal(rng), normal(rng), normal(rng)};
        return normalized(v);
    }
    int pick(int n) { return static_cast<int>(rng() % static_cast<std::uint64_t>(n)); }
    /// x moved by k ulps (k in [-3, 3]).
    double nudge(double x) {
        int k = pick(7) - 3;
        for (; k > 0; --k)
            x = std::nextafter(x, INFINITY);
        for (; k < 0; ++k)
            x = std::nextafter(x, -INFINITY);
        return x;
    }
    Vec3 nudge(const Vec3 &v) { return {nudge(v.x), nudge(v.y), nudge(v.z)}; }
    /// A point on the rounded great circle through a and b, nudged by a few ulps.
    Vec3 near_great_circle(const Vec3 &a, const Vec3 &b) {
        const double s = normal(rng), t = normal(rng);
        return nudge(normalized(s * a + t * b));
    }
    /// A point near the rounded circle through a, b, c (on the sphere), nudged by a few ulps.
    Vec3 near_circle(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
        // centre direction n of the circle and its plane offset; rotate a about n.
        const Vec3 n = normalized(cross(b - a, c - a));
        const double h = dot(n, a);
        const Vec3 axis_point = h * n;
        const Vec3 r = a - axis_point;
        const Vec3 s = cross(n, r);
        const double t = 2 * pi * uniform(rng);
        return nudge(axis_point + std::cos(t) * r + std::sin(t) * s);
    }
};

/// The points as hexadecimal floats, for failure messages that reproduce the case exactly.
std::string describe(const std::array<Vec3, 4> &q) {
    std::string out;
    char buf[128];
    for (const Vec3 &p : q) {
        std::snprintf(buf, sizeof buf, "{%a, %a, %a} ", p.x, p.y, p.z);
        out += buf;
    }
    return out;
}

Vec3 scaled(const Vec3 &v, int e) {
    return {std::ldexp(v.x, e), std::ldexp(v.y, e), std::ldexp(v.z, e)};
}

/// Triples and quadruples that stress the filter: random, a few ulps apart, near one great
/// circle, nearly antipodal, scaled far from 1, with tiny coordinates.
std::vector<std::array<Vec3, 4>> adversarial_quadruples(Gen &g, int count) {
    std::vector<std::array<Vec3, 4>> out;
    for (int i = 0; i < count; ++i) {
        const Vec3 a = g.unit(), b = g.unit(), c = g.unit();
        switch (i % 9) {
        case 0:
            out.push_back({a, b, c, g.unit()});
            break;
        case 1:
            out.push_back({a, g.nudge(a), g.nudge(a), g.nudge(a)});
            break;
        case 2:
            out.push_back({a, b, g.near_great_circle(a, b), g.near_great_circle(a, b)});
            break;
        case 3:
            out.push_back({a, b, c, g.near_circle(a, b, c)});
            break;
        case 4:
            out.push_back({a, g.nudge(-a), b, g.nudge(-b)});
            break;
        case 5: {
            const int e = (i % 2 ? 1 : -1) * (200 + g.pick(400));
            out.push_back(
                {scaled(a, e), scaled(b, e), scaled(c, e), scaled(g.near_circle(a, b, c), e)});
            break;
        }
        case 6: {
            // tiny coordinates (still within 2^-605 of the largest): points a hair off the
            // x-y plane, and a few ulps-apart clusters of them.
            const int e = -(100 + g.pick(450));
            Vec3 p{a.x, a.y, std::ldexp(a.z, e)}, q{b.x, b.y, std::ldexp(b.z, e)};
            out.push_back({p, q, g.nudge(p), Vec3{c.x, c.y, std::ldexp(c.z, e)}});
            break;
        }
        case 7: {
            // small triangle (1e-9 rad) and a point near its circumcircle
            const Vec3 b2 = normalized(a + 1e-9 * b), c2 = normalized(a + 1e-9 * c);
            out.push_back({a, b2, c2, g.near_circle(a, b2, c2)});
            break;
        }
        default: {
            const Vec3 n = g.nudge(a);
            out.push_back({a, n, g.near_great_circle(a, n), g.nudge(b)});
            break;
        }
        }
    }
    return out;
}

// Exactly representable points on the sphere of radius 5 (all permutations and sign flips of
// (5,0,0) and (3,4,0)), scaled by 1/8 so they are not integers.
std::vector<Vec3> lattice_sphere_points() {
    std::vector<Vec3> out;
    const double base[2][3] = {{5, 0, 0}, {3, 4, 0}};
    for (const auto &b : base) {
        std::array<int, 3> perm{0, 1, 2};
        do {
            for (int s = 0; s < 8; ++s) {
                double v[3];
                for (int k = 0; k < 3; ++k)
                    v[k] = b[perm[k]] * ((s >> k & 1) ? -1 : 1) / 8.0;
                Vec3 p{v[0] + 0.0, v[1] + 0.0, v[2] + 0.0};
                if (std::find(out.begin(), out.end(), p) == out.end())
                    out.push_back(p);
            }
        } while (std::next_permutation(perm.begin(), perm.end()));
    }
    return out;
}

int permutation_sign(const std::array<int, 4> &p) {
    int s = 1;
    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            if (p[i] > p[j])
                s = -s;
    return s;
}

/// Every permutation of the arguments gives sign(permutation) * in_circle(a, b, c, d).
void expect_antisymmetric(const std::array<Vec3, 4> &q) {
    const int base = in_circle(q[0], q[1], q[2], q[3]);
    std::array<int, 4> p{0, 1, 2, 3};
    do {
        ASSERT_EQ(in_circle(q[p[0]], q[p[1]], q[p[2]], q[p[3]]), permutation_sign(p) * base)
            << describe(q) << " permutation " << p[0] << p[1] << p[2] << p[3];
    } while (std::next_permutation(p.begin(), p.end()));
}

} // namespace

// --- unperturbed signs --------------------------------------------------------------------------

TEST(Predicates, orient_matches_gmp_on_random_and_adversarial_triples) {
    Gen g;
    int zeros = 0;
    for (const auto &q : adversarial_quadruples(g, 36000)) {
        ASSERT_EQ(orient(q[0], q[1], q[2]), gmp_orient(q[0], q[1], q[2]));
        ASSERT_EQ(orient(q[0], q[1], q[3]), gmp_orient(q[0], q[1], q[3]));
        zeros += gmp_orient(q[0], q[1], q[3]) == 0;
    }
    // exactly coplanar with the origin
    EXPECT_EQ(orient({1, 0, 0}, {0, 1, 0}, {-1, 0, 0}), 0);
    EXPECT_EQ(orient(lonlat_to_vec(10, 0), lonlat_to_vec(75, 0), lonlat_to_vec(-130, 0)), 0);
    EXPECT_EQ(orient({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1);
    EXPECT_EQ(orient({0, 1, 0}, {1, 0, 0}, {0, 0, 1}), -1);
    EXPECT_EQ(orient({0.6, 0.8, 0}, {0.6, 0.8, 0}, {0, 0, 1}), 0);
    EXPECT_GT(zeros, 0); // the generators do reach exact degeneracy
}

TEST(Predicates, orient_against_a_kept_edge_matches_gmp) {
    // orient(a, OrientEdge(b, c)) keeps what orient(a, b, c) computes from b and c alone; its
    // signs must be the exact ones, through the filter and the exact stage alike.
    Gen g;
    int zeros = 0;
    for (const auto &q : adversarial_quadruples(g, 36000)) {
        const predicates::OrientEdge e(q[1], q[2]);
        ASSERT_EQ(orient(q[0], e), gmp_orient(q[0], q[1], q[2])) << describe(q);
        ASSERT_EQ(orient(q[3], e), gmp_orient(q[3], q[1], q[2])) << describe(q);
        zeros += gmp_orient(q[3], q[1], q[2]) == 0;
    }
    EXPECT_GT(zeros, 0);
    for (int i = 0; i < 3000; ++i) {
        const int x = g.pick(1200) - 600; // 2^-600 .. 2^600
        const Vec3 a = scaled(g.unit(), x), b = scaled(g.unit(), x), c = scaled(g.unit(), x);
        ASSERT_EQ(orient(a, predicates::OrientEdge(b, c)), gmp_orient(a, b, c)) << x;
    }
}

TEST(Predicates, orient3d_matches_gmp_on_random_and_adversarial_quadruples) {
    Gen g;
    int zeros = 0;
    for (const auto &q : adversarial_quadruples(g, 36000)) {
        const int expected = gmp_orient3d(q[0], q[1], q[2], q[3]);
        ASSERT_EQ(orient3d(q[0], q[1], q[2], q[3]), expected) << describe(q);
        zeros += expected == 0;
    }
    EXPECT_EQ(orient3d({1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0}), -1);
    EXPECT_EQ(orient3d({1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}), 1);
    EXPECT_EQ(orient3d({1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}), 0);
    EXPECT_GT(zeros, 0);
}

TEST(Predicates, orient_and_orient3d_exact_far_from_unit_scale) {
    Gen g;
    for (int i = 0; i < 3000; ++i) {
        const int e = g.pick(1200) - 600; // 2^-600 .. 2^600
        Vec3 a = scaled(g.unit(), e), b = scaled(g.unit(), e), c = scaled(g.unit(), e);
        Vec3 d = scaled(g.near_circle(g.unit(), g.unit(), g.unit()), e);
        ASSERT_EQ(orient(a, b, c), gmp_orient(a, b, c)) << e;
        ASSERT_EQ(orient3d(a, b, c, d), gmp_orient3d(a, b, c, d)) << e;
        // a few ulps apart at that scale
        Vec3 a1 = g.nudge(a), a2 = g.nudge(a), a3 = g.nudge(a);
        ASSERT_EQ(orient3d(a, a1, a2, a3), gmp_orient3d(a, a1, a2, a3)) << e;
    }
}

// --- in_circle ----------------------------------------------------------------------------------

TEST(Predicates, in_circle_equals_exact_sign_whenever_it_is_not_zero) {
    Gen g;
    int checked = 0;
    for (const auto &q : adversarial_quadruples(g, 36000)) {
        const int exact = gmp_orient3d(q[0], q[1], q[2], q[3]);
        const int s = in_circle(q[0], q[1], q[2], q[3]);
        if (exact != 0) {
            ASSERT_EQ(s, exact) << describe(q);
            ++checked;
        } else {
            ASSERT_EQ(s, oracle_in_circle(q[0], q[1], q[2], q[3]));
        }
    }
    EXPECT_GT(checked, 30000);
}

TEST(Predicates, in_circle_means_inside_the_circumcircle) {
    const Vec3 a{1, 0, 0}, b{0, 1, 0}, c{0, 0, 1}; // counter-clockwise seen from outside
    ASSERT_EQ(orient(a, b, c), 1);
    EXPECT_EQ(in_circle(a, b, c, normalized({1, 1, 1})), 1);
    EXPECT_EQ(in_circle(a, b, c, normalized({-1, -1, -1})), -1);
    EXPECT_EQ(in_circle(a, b, c, normalized({1, -0.5, -0.5})), -1);
    EXPECT_EQ(in_circle(b, a, c, normalized({1, 1, 1})), -1); // clockwise: the other cap
}

TEST(Predicates, in_circle_on_exact_lattice_circles_matches_one_global_perturbation) {
    // 30 exactly representable points on one sphere: many exactly co-circular quadruples (small
    // circles such as z = 3/8, and great circles such as z = 0). Level-1 cases are checked
    // against ONE perturbation of the whole set (global ranks), which shows the answers all come
    // from one fixed perturbed point set; level-2 cases against the four-point oracle.
    const std::vector<Vec3> pts = lattice_sphere_points();
    ASSERT_EQ(pts.size(), 30u);
    const int n = static_cast<int>(pts.size());
    int level1 = 0, level2 = 0;
    std::mt19937_64 rng(7);
    for (int i = 0; i < n; ++i)
        for (int j = i + 1; j < n; ++j)
            for (int k = j + 1; k < n; ++k)
                for (int l = k + 1; l < n; ++l) {
                    const Vec3 &a = pts[i], &b = pts[j], &c = pts[k], &d = pts[l];
                    const int s = in_circle(a, b, c, d);
                    ASSERT_NE(s, 0);
                    if (gmp_orient3d(a, b, c, d) != 0) {
                        ASSERT_EQ(s, gmp_orient3d(a, b, c, d));
                        continue;
                    }
                    if (!on_one_plane_through_origin(a, b, c, d)) {
                        ASSERT_EQ(s, perturbed_oracle(pts, i, j, k, l, false)) << i << j << k << l;
                        ++level1;
                    } else {
                        if (rng() % 64 == 0) { // the eta oracle is slow: a sample
                            ASSERT_EQ(s, oracle_in_circle(a, b, c, d)) << i << j << k << l;
                        }
                        ++level2;
                    }
                    expect_antisymmetric({a, b, c, d});
                }
    EXPECT_GT(level1, 100);
    EXPECT_GT(level2, 100);
}

TEST(Predicates, in_circle_on_cocircular_lonlat_grid_matches_oracle) {
    // (lon, lat) = (i, j), (i+s, j), (i+s, j+s), (i, j+s) form an isosceles trapezoid, so they
    // are co-circular on the sphere; the rounded vectors are co-circular only sometimes.
    // Whatever the rounding did, the answer must be the oracle's and antisymmetric.
    int exact_zero = 0;
    for (double s : {10.0, 1.0, 0.25})
        for (double lon = -180; lon < 180; lon += 37)
            for (double lat = -80; lat < 80; lat += 23) {
                const std::array<Vec3, 4> q{lonlat_to_vec(lon, lat), lonlat_to_vec(lon + s, lat),
                                            lonlat_to_vec(lon + s, lat + s),
                                            lonlat_to_vec(lon, lat + s)};
                const int expected = oracle_in_circle(q[0], q[1], q[2], q[3]);
                ASSERT_NE(expected, 0);
                ASSERT_EQ(in_circle(q[0], q[1], q[2], q[3]), expected)
                    << lon << " " << lat << " " << s;
                exact_zero += gmp_orient3d(q[0], q[1], q[2], q[3]) == 0;
                expect_antisymmetric(q);
            }
    // Exactly co-circular in floating point: the circle through the three axis points of an
    // octant (x + y + z = 3 on the sphere of radius 3), and the cyclic 0.6/0.8 points, whose
    // plane x + y + z = fl(0.6) + fl(0.8) holds exactly for the rounded values too.
    const std::array<Vec3, 4> octant{Vec3{3, 0, 0}, Vec3{0, 3, 0}, Vec3{0, 0, 3}, Vec3{-1, 2, 2}};
    const std::array<Vec3, 4> octant2{Vec3{3, 0, 0}, Vec3{2, -1, 2}, Vec3{0, 3, 0}, Vec3{2, 2, -1}};
    const std::array<Vec3, 4> small{Vec3{0.6, 0.8, 0}, Vec3{0, 0.6, 0.8}, Vec3{0.8, 0, 0.6},
                                    Vec3{0.8, 0.6, 0}};
    for (const auto &q : {octant, octant2, small}) {
        ASSERT_EQ(gmp_orient3d(q[0], q[1], q[2], q[3]), 0);
        ASSERT_EQ(in_circle(q[0], q[1], q[2], q[3]), oracle_in_circle(q[0], q[1], q[2], q[3]));
        expect_antisymmetric(q);
    }
    RecordProperty("exactly_cocircular_after_rounding", exact_zero);
}

TEST(Predicates, in_circle_on_one_great_circle_matches_oracle) {
    // Level 2: four distinct points in one plane through the origin. Exact small-integer points
    // p = i u + j v on planes spanned by integer vectors u, v (not unit vectors: the predicate
    // takes any doubles), plus rounded unit vectors on the equator and on meridians, which lie
    // exactly in the planes z = 0, y = 0 and x = 0.
    std::mt19937_64 rng(99);
    auto small = [&] { return static_cast<double>(static_cast<int>(rng() % 7) - 3); };
    int cases = 0;
    while (cases < 60) {
        const Vec3 u{small(), small(), small()}, v{small(), small(), small()};
        std::array<Vec3, 4> q;
        for (Vec3 &p : q) {
            const double i = small(), j = small();
            p = i * u + j * v; // exact: small integers
        }
        bool distinct = true;
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b)
                distinct = distinct && !(q[a] == q[b]);
        if (!distinct)
            continue;
        ASSERT_TRUE(on_one_plane_through_origin(q[0], q[1], q[2], q[3]));
        const int s = in_circle(q[0], q[1], q[2], q[3]);
        ASSERT_NE(s, 0);
        ASSERT_EQ(s, oracle_in_circle(q[0], q[1], q[2], q[3]))
            << q[0].x << "," << q[0].y << "," << q[0].z << " " << q[1].x << "," << q[1].y << ","
            << q[1].z << " " << q[2].x << "," << q[2].y << "," << q[2].z << " " << q[3].x << ","
            << q[3].y << "," << q[3].z;
        expect_antisymmetric(q);
        ++cases;
    }
    const std::array<std::array<Vec3, 4>, 4> circles{{
        {lonlat_to_vec(0, 0), lonlat_to_vec(10, 0), lonlat_to_vec(100, 0), lonlat_to_vec(-170, 0)},
        {lonlat_to_vec(0, 10), lonlat_to_vec(0, 20), lonlat_to_vec(0, 35), lonlat_to_vec(180, 40)},
        {lonlat_to_vec(90, -5), lonlat_to_vec(90, 5), lonlat_to_vec(-90, 60),
         lonlat_to_vec(90, 60)},
        {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{-1, 0, 0}, Vec3{0, -1, 0}},
    }};
    for (const auto &q : circles) {
        ASSERT_TRUE(on_one_plane_through_origin(q[0], q[1], q[2], q[3]));
        const int s = in_circle(q[0], q[1], q[2], q[3]);
        ASSERT_NE(s, 0);
        ASSERT_EQ(s, oracle_in_circle(q[0], q[1], q[2], q[3]));
        expect_antisymmetric(q);
    }
}

TEST(Predicates, in_circle_is_antisymmetric_under_all_24_permutations) {
    Gen g;
    for (const auto &q : adversarial_quadruples(g, 900))
        expect_antisymmetric(q);
    // points a few ulps apart with an exact degeneracy: three copies of one point nudged
    for (int i = 0; i < 200; ++i) {
        const Vec3 a = g.unit();
        expect_antisymmetric({a, g.nudge(a), g.nudge(a), g.nudge(a)});
    }
}

TEST(Predicates, in_circle_is_zero_only_for_equal_points) {
    Gen g;
    for (int i = 0; i < 500; ++i) {
        const Vec3 a = g.unit(), b = g.unit(), c = g.unit();
        EXPECT_EQ(in_circle(a, a, b, c), 0);
        EXPECT_EQ(in_circle(a, b, a, c), 0);
        EXPECT_EQ(in_circle(b, c, a, a), 0);
        EXPECT_EQ(in_circle(a, b, c, c), 0);
        // -0.0 and +0.0 are the same point
        EXPECT_EQ(in_circle(Vec3{0.0, 1, 0}, Vec3{-0.0, 1, 0}, a, b), 0);
        // distinct points, however close, never give 0
        const Vec3 a1 = g.nudge(a);
        if (!(a1 == a)) {
            EXPECT_NE(in_circle(a, a1, b, c), 0);
        }
    }
    // four points on a line through the origin (antipodes, both levels degenerate)
    const std::array<Vec3, 4> line{Vec3{1, 1, 1}, Vec3{-1, -1, -1}, Vec3{2, 2, 2},
                                   Vec3{0.5, 0.5, 0.5}};
    EXPECT_NE(in_circle(line[0], line[1], line[2], line[3]), 0);
    EXPECT_EQ(in_circle(line[0], line[1], line[2], line[3]),
              oracle_in_circle(line[0], line[1], line[2], line[3]));
    expect_antisymmetric(line);
}
