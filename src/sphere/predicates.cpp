// Exact stages of the predicates in globemesh/predicates.hpp: expansion arithmetic after
// Shewchuk (1997), and the symbolic perturbation of in_circle.
//
// Expansions. A number is kept as an unevaluated sum of doubles, non-overlapping, sorted by
// increasing magnitude, zero components removed (Shewchuk's "zeroelim" routines). Its sign is the
// sign of its last (largest) component. two_product uses std::fma, which is exact for the error
// term of a product as long as nothing underflows; the scaling in scale_points() and the input
// contract in the header guarantee that (every partial product lies on the 2^-1074 lattice).
//
// Every product is written through two_product()/std::fma: a contracted a*b+c would change the
// rounding the error-free transformations rely on, so no such expression appears here.
#include "globemesh/predicates.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>

namespace globemesh::predicates::detail {
namespace {

// --- error-free transformations -----------------------------------------------------------

/// x + y == a + b exactly, x = fl(a + b) (Knuth's TwoSum, no branch on magnitudes).
inline void two_sum(double a, double b, double &x, double &y) {
    x = a + b;
    const double bv = x - a;
    const double av = x - bv;
    y = (a - av) + (b - bv);
}

/// x + y == a + b exactly when |a| >= |b| or a == 0 (Dekker's FastTwoSum).
inline void fast_two_sum(double a, double b, double &x, double &y) {
    x = a + b;
    y = b - (x - a);
}

/// x + y == a * b exactly, x = fl(a * b), provided the error term does not underflow.
inline void two_product(double a, double b, double &x, double &y) {
    x = a * b;
    y = std::fma(a, b, -x);
}

// --- expansions -------------------------------------------------------------------------------

/// h = e + f (Shewchuk's FAST-EXPANSION-SUM-ZEROELIM): the components of e and f merged by
/// increasing magnitude, then one pass of TwoSum carrying the running sum upwards. elen, flen
/// >= 1; h holds elen + flen components and aliases neither input. Returns the length of h
/// (>= 1; a zero sum is the single component 0). The merge and the zero elimination are
/// branch-free: their branches would be unpredictable and this loop is most of the exact stage.
int expansion_sum(const double *e, int elen, const double *f, int flen, double *h) {
    int i = 0, j = 0, k = 0;
    while (i < elen && j < flen) {
        const bool take_e = std::fabs(e[i]) < std::fabs(f[j]);
        h[k++] = take_e ? e[i] : f[j];
        i += take_e;
        j += !take_e;
    }
    while (i < elen)
        h[k++] = e[i++];
    while (j < flen)
        h[k++] = f[j++];
    // In place: step m reads h[m] before writing h[hn], hn < m.
    double q = h[0];
    int hn = 0;
    double x, y;
    if (k > 1) {
        fast_two_sum(h[1], q, x, y);
        q = x;
        h[hn] = y;
        hn += y != 0;
    }
    for (int m = 2; m < k; ++m) {
        two_sum(q, h[m], x, y);
        q = x;
        h[hn] = y;
        hn += y != 0;
    }
    if (q != 0 || hn == 0)
        h[hn++] = q;
    return hn;
}

/// h = b * e (Shewchuk's SCALE-EXPANSION-ZEROELIM). h holds 2 * elen components.
int scale_expansion(const double *e, int elen, double b, double *h) {
    int hn = 0;
    double q, hh;
    two_product(e[0], b, q, hh);
    if (hh != 0)
        h[hn++] = hh;
    for (int i = 1; i < elen; ++i) {
        double p1, p0, sum;
        two_product(e[i], b, p1, p0);
        two_sum(q, p0, sum, hh);
        if (hh != 0)
            h[hn++] = hh;
        fast_two_sum(p1, sum, q, hh);
        if (hh != 0)
            h[hn++] = hh;
    }
    if (q != 0 || hn == 0)
        h[hn++] = q;
    return hn;
}

inline int expansion_sign(const double *e, int elen) {
    const double top = e[elen - 1];
    return (top > 0) - (top < 0);
}

inline void negate(double *e, int elen) {
    for (int i = 0; i < elen; ++i)
        e[i] = -e[i];
}

/// h = a * b - c * d exactly, at most 4 components.
int minor2(double a, double b, double c, double d, double *h) {
    double p[2], q[2];
    two_product(a, b, p[1], p[0]);
    two_product(c, d, q[1], q[0]);
    q[0] = -q[0];
    q[1] = -q[1];
    return expansion_sum(p, 2, q, 2, h);
}

/// h = det[p, q, r] = p . (q x r) exactly, at most 24 components.
int det3(const Vec3 &p, const Vec3 &q, const Vec3 &r, double *h) {
    double m[4], t0[8], t1[8], t2[8], s[16];
    int n = minor2(q.y, r.z, q.z, r.y, m);
    const int n0 = scale_expansion(m, n, p.x, t0);
    n = minor2(q.z, r.x, q.x, r.z, m);
    const int n1 = scale_expansion(m, n, p.y, t1);
    n = minor2(q.x, r.y, q.y, r.x, m);
    const int n2 = scale_expansion(m, n, p.z, t2);
    const int ns = expansion_sum(t0, n0, t1, n1, s);
    return expansion_sum(s, ns, t2, n2, h);
}

// --- input scaling ------------------------------------------------------------------------------

/// Multiplies every coordinate by one power of two so that the largest magnitude lands in
/// [2^299, 2^300). Scaling all points by 2^k > 0 multiplies each 3x3 determinant by 2^(3k), so
/// no sign changes, and the lexicographic order is kept. Returns false when all are zero.
template <std::size_t N> bool scale_points(std::array<Vec3, N> &p) {
    double largest = 0;
    for (const Vec3 &v : p)
        largest = std::max({largest, std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
    if (largest == 0)
        return false;
    const int k = 299 - std::ilogb(largest);
    for (Vec3 &v : p)
        v = {std::ldexp(v.x, k), std::ldexp(v.y, k), std::ldexp(v.z, k)};
    return true;
}

/// The four cofactor determinants of the 4x4 matrix [[p_i, 1]]: t[i] = det of the three points
/// other than p_i, in argument order. Each holds up to 24 components.
struct FourDets {
    double t[4][24];
    int n[4];
};

void four_dets(const std::array<Vec3, 4> &p, FourDets &f) {
    f.n[0] = det3(p[1], p[2], p[3], f.t[0]);
    f.n[1] = det3(p[0], p[2], p[3], f.t[1]);
    f.n[2] = det3(p[0], p[1], p[3], f.t[2]);
    f.n[3] = det3(p[0], p[1], p[2], f.t[3]);
}

/// Sign of (d - a) . ((b - a) x (c - a)) = det[b,c,d] - det[a,c,d] + det[a,b,d] - det[a,b,c].
/// (With D4 = det[[a,1],[b,1],[c,1],[d,1]], subtracting row a gives D4 = -det[b-a, c-a, d-a],
/// and expanding D4 along its column of ones gives -t0 + t1 - t2 + t3; orient3d is -D4.)
int orient3d_from(FourDets &f) {
    double u[48], v[48], w[96];
    double t1[24], t3[24];
    for (int i = 0; i < f.n[1]; ++i)
        t1[i] = -f.t[1][i];
    for (int i = 0; i < f.n[3]; ++i)
        t3[i] = -f.t[3][i];
    const int nu = expansion_sum(f.t[0], f.n[0], t1, f.n[1], u);
    const int nv = expansion_sum(f.t[2], f.n[2], t3, f.n[3], v);
    const int nw = expansion_sum(u, nu, v, nv, w);
    return expansion_sign(w, nw);
}

inline bool lex_less(const Vec3 &p, const Vec3 &q) {
    if (p.x != q.x)
        return p.x < q.x;
    if (p.y != q.y)
        return p.y < q.y;
    return p.z < q.z;
}

inline double coordinate(const Vec3 &p, int c) {
    return c == 0 ? p.x : c == 1 ? p.y : p.z;
}

/// h = sign * (product of the n doubles in f), exactly; n <= 3, at most 4 components.
int signed_product(const double *f, int n, int sign, double *h) {
    if (n == 0) {
        h[0] = sign;
        return 1;
    }
    if (n == 1) {
        h[0] = sign * f[0];
        return 1;
    }
    double p[2];
    two_product(f[0], f[1], p[1], p[0]);
    int len = 2;
    if (n == 3) {
        len = scale_expansion(p, 2, f[2], h);
    } else {
        h[0] = p[0];
        h[1] = p[1];
    }
    if (sign < 0)
        negate(h, len);
    return len;
}

/// Level 2 of the perturbation: Simulation of Simplicity for four points that span only a plane
/// through the origin (every 3x3 cofactor is zero). p holds the (scaled) points in rank order;
/// parity is the sign of the permutation that sorted them. See in_circle_exact for the scheme.
int great_circle_sign(const std::array<Vec3, 4> &p, int parity) {
    static constexpr int perms[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                        {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    static constexpr int perm_sign[6] = {1, 1, 1, -1, -1, -1};
    // Monomials of the coordinate perturbation, largest first: eta_{r,c} = eta^(2^(3r+c)) for the
    // point of rank r and coordinate c, so the monomial with bit set M is eta^M and a smaller
    // mask value is a larger monomial. A monomial of a determinant uses each row (point) and each
    // column (coordinate) at most once, so at most 3 bits.
    for (unsigned mask = 1; mask < 4096; ++mask) {
        if (std::popcount(mask) > 3)
            continue;
        int fixed[4] = {-1, -1, -1, -1}; // coordinate perturbed in row r, or -1
        unsigned cols = 0;
        bool valid = true;
        for (int bit = 0; bit < 12 && valid; ++bit) {
            if (!(mask >> bit & 1u))
                continue;
            const int r = bit / 3, c = bit % 3;
            if (fixed[r] != -1 || (cols >> c & 1u))
                valid = false;
            fixed[r] = c;
            cols |= 1u << c;
        }
        if (!valid)
            continue;

        // gamma[r]: coefficient of eta^mask in the cofactor C_r(q) = (-1)^(r+1) det[q_i, i != r]
        // of the perturbed points q; alpha = sum of gamma[r] = coefficient in D4(q).
        double gamma[4][32];
        int glen[4];
        double alpha[128], scratch[128];
        int alen = 1;
        alpha[0] = 0;
        for (int r = 0; r < 4; ++r) {
            glen[r] = 1;
            gamma[r][0] = 0;
            if (fixed[r] != -1)
                continue; // C_r does not contain row r
            int rows[3], k = 0;
            for (int i = 0; i < 4; ++i)
                if (i != r)
                    rows[k++] = i;
            for (int s = 0; s < 6; ++s) {
                double factors[3];
                int nf = 0;
                bool consistent = true;
                for (int i = 0; i < 3; ++i) {
                    const int fc = fixed[rows[i]];
                    if (fc == -1)
                        factors[nf++] = coordinate(p[rows[i]], perms[s][i]);
                    else if (fc != perms[s][i])
                        consistent = false;
                }
                if (!consistent)
                    continue;
                double term[4], sum[32];
                const int sign = perm_sign[s] * (r % 2 == 0 ? -1 : 1);
                const int nt = signed_product(factors, nf, sign, term);
                const int ns = expansion_sum(gamma[r], glen[r], term, nt, sum);
                std::copy(sum, sum + ns, gamma[r]);
                glen[r] = ns;
            }
            const int na = expansion_sum(alpha, alen, gamma[r], glen[r], scratch);
            std::copy(scratch, scratch + na, alpha);
            alen = na;
        }
        // The coefficient of eta^mask in -D4'/prod(1 + eps_i) is -alpha + sum_r delta_r gamma[r].
        if (const int s = expansion_sign(alpha, alen); s != 0)
            return -s * parity;
        for (int r = 0; r < 4; ++r)
            if (const int s = expansion_sign(gamma[r], glen[r]); s != 0)
                return s * parity;
    }
    return 0; // not reached for distinct points: a 3-bit monomial has alpha = +-1
}

} // namespace

int orient_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    std::array<Vec3, 3> p{a, b, c};
    if (!scale_points(p))
        return 0;
    double h[24];
    const int n = det3(p[0], p[1], p[2], h);
    return expansion_sign(h, n);
}

int orient3d_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    std::array<Vec3, 4> p{a, b, c, d};
    if (!scale_points(p))
        return 0;
    FourDets f;
    four_dets(p, f);
    return orient3d_from(f);
}

// The symbolic perturbation.
//
// Let D4 = det[[a,1],[b,1],[c,1],[d,1]] (rows p_1..p_4), so that orient3d = -D4, and let
// C_i = (-1)^(i+4) det[p_j, p_k, p_l] be the cofactor of the entry 1 in row i ({j,k,l} the other
// rows in order), so D4 = sum_i C_i. Level 1 moves p_i to (1 + e_i) p_i with e_i = eps^k(i),
// k(i) in 1..4 the lexicographic rank of p_i (smallest point, k = 1, largest move). Factoring
// (1 + e_i) out of row i leaves the row [p_i, 1/(1 + e_i)] = [p_i, 1 - delta_i] with
// delta_i = e_i / (1 + e_i), and the determinant is linear in that column:
//     D4' = prod_i (1 + e_i) * (D4 - sum_i delta_i C_i).
// delta_i is a series in eps^k(i) alone whose leading term is eps^k(i), so when D4 == 0 the sign
// of -D4' (the perturbed orient3d) is the sign of C_i for the first point i in rank order with
// C_i != 0: C_a = -det[b,c,d], C_b = +det[a,c,d], C_c = -det[a,b,d], C_d = +det[a,b,c]. For a
// point d of rank 1 on the circle of a counter-clockwise abc this gives +1: moved outwards, d is
// beyond the plane of abc, i.e. inside its circle, as the header says.
//
// Level 2: all four C_i are 0 exactly when the four points lie in one plane through the origin
// (on one great circle). Then each point p_i of rank r also gets a coordinate perturbation before
// the radial one: p_i -> (1 + e_i)(p_i + (eta_{r,0}, eta_{r,1}, eta_{r,2})), eta_{r,c} =
// eta^(2^(3r+c)), with eta infinitesimal even with respect to every power of eps. Writing q_i for
// the coordinate-perturbed points, D4' = prod(1 + e_i) (D4(q) - sum_i delta_i C_i(q)). Expanded
// in eta, each monomial eta^M (M a set of (row, coordinate) pairs with distinct rows and columns,
// ordered by the integer sum of 2^(3r+c), smaller first = larger) has the coefficient
// alpha_M - sum_i delta_i gamma_{i,M}, with gamma_{i,M} its coefficient in C_i(q) (a signed
// complementary minor: a product of at most two coordinates, or +-1) and alpha_M = sum_i
// gamma_{i,M} its coefficient in D4(q). The sign is decided by the first monomial whose coefficient
// is not zero, and within it by alpha_M when non-zero, else by the first non-zero gamma_{i,M} in
// rank order (delta_i's leading term). A monomial of three pairs in three distinct rows has alpha_M
// = +-1, so this always ends for distinct points: Edelsbrunner and Muecke's argument that SoS
// decides every orientation test. M = {} is exactly level 1 (alpha = D4, gamma = C_i).
//
// Why this is one fixed perturbed point set. The perturbation of a point is a function of its
// rank in the lexicographic order of ALL points the triangulation ever compares (e_i = eps^g,
// eta exponents 2^(3g+c), g the global rank). Only the relative order of the four ranks matters
// above (which delta dominates, which eta monomial is larger: comparing two masks is decided by
// their highest differing bit, unchanged by an order-preserving relabelling of bits), and the
// relative order of global ranks is the lexicographic order of the four points. So every call
// returns the exact sign of orient3d on one fixed set of perturbed points, a function of the
// coordinates alone: permuting the arguments permutes rows of one determinant (odd
// permutations flip the sign, cyclic shifts of a, b, c keep it), and neither argument order,
// vertex indices nor insertion order can change the answer. Equal points have equal rank and
// equal perturbation, so they keep the determinant 0; that is the only 0.
int in_circle_exact(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    const std::array<Vec3, 4> original{a, b, c, d};
    std::array<Vec3, 4> p = original;
    if (!scale_points(p))
        return 0; // four copies of the origin
    FourDets f;
    four_dets(p, f);
    if (const int s = orient3d_from(f); s != 0)
        return s;

    for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
            if (original[i] == original[j])
                return 0;

    // Rank order (insertion sort, counting swaps for the permutation's parity).
    int order[4] = {0, 1, 2, 3};
    int parity = 1;
    for (int i = 1; i < 4; ++i)
        for (int j = i; j > 0 && lex_less(original[order[j]], original[order[j - 1]]); --j) {
            std::swap(order[j], order[j - 1]);
            parity = -parity;
        }

    // Level 1: C_i = (-1)^(i+1) t[i] for 0-based i.
    for (int r = 0; r < 4; ++r) {
        const int i = order[r];
        if (const int s = expansion_sign(f.t[i], f.n[i]); s != 0)
            return i % 2 == 0 ? -s : s;
    }

    // Level 2, on the points in rank order: det(sorted rows) = parity * det(argument rows).
    std::array<Vec3, 4> sorted;
    for (int r = 0; r < 4; ++r)
        sorted[r] = p[order[r]];
    return great_circle_sign(sorted, parity);
}

} // namespace globemesh::predicates::detail
