// The improve stage's searches for where one node should go. The node's star (its triangles
// v, b, c) is held as the far edges b -> c; a candidate centre p is scored on the triangles
// p, b, c (its worst quality, or the quality rounds' count), and a pattern search scores eight
// candidates at a time, lane by lane, so that the compiler vectorizes them (the file that
// includes this is built with -fno-math-errno for the square roots). Internal to mesher/.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::detail {

/// A far edge b -> c of a star (its triangle v, b, c for the centre v), with what the tests of
/// many candidate centres p share: the minors of orient(p, b, c) and |b - c|.
struct FarEdge : predicates::OrientEdge {
    double length;
    FarEdge(const Vec3 &b_, const Vec3 &c_) : OrientEdge(b_, c_), length(norm(b_ - c_)) {}
};

/// The worst quality of the star triangles p, b, c for the star's far edges b -> c (counter-
/// clockwise around the star's centre), or -1 when p would fold one of them (move_vertex's test).
/// With `floor`, stops at the first triangle at or below it and returns that triangle's
/// quality: a value at or below floor, no smaller than the worst (for callers that only ask
/// whether the worst beats floor; the moves of the improve stage evaluate candidates so).
inline double star_worst_quality(const Vec3 &p, const std::vector<FarEdge> &far,
                                 double floor = -2.0) {
    double worst = 1;
    for (const FarEdge &e : far) {
        if (predicates::orient(p, e) <= 0)
            return -1.0;
        worst = std::min(worst, triangle_quality(p, e.b, e.c, e.length));
        if (worst <= floor)
            return worst;
    }
    return worst;
}

/// What the quality rounds' score counts (star_count_score); the mesher's constants.
struct CountRule {
    double worst_goal;    // the worst quality counts up to this
    double count_quality; // a triangle above this quality counts 1
    double count_cap;     // and its quality, capped at this
    double worst_weight;  // the weight of the worst (count_worst_weight)
};

/// The rule of the mesher's quality rounds (quality.cpp, which says how each value was chosen);
/// the join of parts (parts_smooth.cpp) scores its nodes by it too.
inline constexpr CountRule quality_count_rule{0.6, 0.8, 0.82, 1000};

/// The quality rounds' score of the star triangles p, b, c (far edges b -> c): count_worst_weight
/// times the worst quality up to worst_goal, plus 1 for each triangle above count_quality and its
/// quality capped at count_cap. A higher score first has a better worst below worst_goal, then more
/// triangles above count_quality or, as many, closer to it. -1 when p would fold a triangle or
/// bring one below `floor`. With `beat`, returns as soon as the score can no longer exceed it
/// (a value at or below beat).
inline double star_count_score(const Vec3 &p, const std::vector<FarEdge> &far,
                               const CountRule &rule, double floor, double beat = -2.0) {
    const double worst_goal = rule.worst_goal, count_quality = rule.count_quality,
                 count_cap = rule.count_cap, count_worst_weight = rule.worst_weight;
    double score = 0, worst = worst_goal, left = static_cast<double>(far.size());
    for (const FarEdge &e : far) {
        if (predicates::orient(p, e) <= 0)
            return -1.0;
        const double q = triangle_quality(p, e.b, e.c, e.length);
        if (q < floor)
            return -1.0;
        worst = std::min(worst, q);
        score += (q > count_quality ? 1.0 : 0.0) + std::min(q, count_cap);
        left -= 1;
        // What the triangles left could add at most.
        if (count_worst_weight * worst + score + left * (1 + count_cap) <= beat)
            return beat;
    }
    return count_worst_weight * worst + score;
}

/// The highest star_count_score of a star of n triangles: all above count_cap.
inline double star_count_best(std::size_t n, const CountRule &rule) {
    return rule.worst_weight * rule.worst_goal + double(n) * (1 + rule.count_cap);
}

// The two eight-lane scorers below are built three times on x86-64, for AVX-512, AVX2 and the
// baseline (SSE2, two lanes an instruction), and the widest the processor has runs
// (star_scorer_in_use). None of the three enables FMA, so every lane does the same IEEE
// operations in each: the same values, the same mesh on any machine (tests/unit/
// star_search_test.cpp meshes with each build the processor runs and compares the bytes).
// Measured on 1:50m land (AVX-512 machine), improve at 64 km 0.190 -> 0.147 s, at 20 km 0.806 ->
// 0.736 s (medians of alternated runs); the 64 and 20 km files identical.
#if defined(__x86_64__) && defined(__ELF__)
#define GLOBEMESH_LANES_TARGET(isa) __attribute__((target(isa)))
#else
#define GLOBEMESH_LANES_TARGET(isa)
#endif

/// The builds of the eight-lane scorers.
enum class StarScorer { avx512f, avx2, baseline };

/// Whether this processor can run build `s` (elsewhere than x86-64, only the baseline).
inline bool star_scorer_supported(StarScorer s) {
#if defined(__x86_64__) && defined(__ELF__)
    if (s == StarScorer::avx512f)
        return __builtin_cpu_supports("avx512f");
    if (s == StarScorer::avx2)
        return __builtin_cpu_supports("avx2");
    return true;
#else
    return s == StarScorer::baseline;
#endif
}

/// The build that runs: GLOBEMESH_STAR_SCORER's (avx512f, avx2 or default) when the processor
/// runs it, else the widest it runs. Assignable through force_star_scorer.
inline StarScorer &star_scorer_in_use() {
    static StarScorer in_use = [] {
        const char *forced = std::getenv("GLOBEMESH_STAR_SCORER");
        const std::string name = forced ? forced : "";
        const StarScorer named = name == "avx512f" ? StarScorer::avx512f
                                 : name == "avx2"  ? StarScorer::avx2
                                                   : StarScorer::baseline;
        if ((name == "avx512f" || name == "avx2" || name == "default") &&
            star_scorer_supported(named))
            return named;
        for (StarScorer s : {StarScorer::avx512f, StarScorer::avx2})
            if (star_scorer_supported(s))
                return s;
        return StarScorer::baseline;
    }();
    return in_use;
}

/// Runs build `s` from now on (the tests compare the builds); false, and nothing changed, when
/// the processor cannot run it.
inline bool force_star_scorer(StarScorer s) {
    if (!star_scorer_supported(s))
        return false;
    star_scorer_in_use() = s;
    return true;
}

/// The eight points of one step of pattern_search, coordinate by coordinate: the searches score
/// them together (star_count_accepts, star_worst_accepts), eight lanes the compiler vectorizes.
struct Points8 {
    double x[8], y[8], z[8];
    Vec3 operator[](int k) const { return {x[k], y[k], z[k]}; }
};

/// The quality of the triangles p[k], e.b, e.c for the eight points, as triangle_quality(p[k],
/// e.b, e.c, e.length) computes it (the same operations in the same order: the same values),
/// into q; and whether orient(p[k], e) is positive, into `certain` (bit k) where the filter
/// certifies it, certainly not into `folded`. The caller decides the other lanes exactly.
inline void star_triangle8(const Points8 &p, const FarEdge &e, double (&q)[8], unsigned &certain,
                           unsigned &folded) {
    using predicates::detail::filter_max, predicates::detail::filter_min,
        predicates::detail::orient_bound;
    certain = folded = 0;
    // The points are unit vectors: only the edge's extents can leave the filter's range, and
    // only a zero-length edge can leave triangle_quality's perimeter or longest edge zero.
    // Then lane by lane as the scalar code does.
    const double low = std::min(std::min(e.extent.x, e.extent.y), e.extent.z);
    const double high = std::max(std::max(e.extent.x, e.extent.y), e.extent.z);
    if (!(e.length > 0 && low >= filter_min && high <= filter_max)) {
        for (int k = 0; k < 8; ++k) {
            const int s = predicates::orient(p[k], e);
            certain |= unsigned(s > 0) << k;
            folded |= unsigned(s <= 0) << k;
            q[k] = triangle_quality(p[k], e.b, e.c, e.length);
        }
        return;
    }
    // Without branches, the flags as doubles: the loop vectorizes.
    double pos[8], neg[8];
    for (int k = 0; k < 8; ++k) {
        const double ax = p.x[k], ay = p.y[k], az = p.z[k];
        // predicates::orient(a, e)'s filter.
        const double det = ax * e.minors.x + ay * e.minors.y + az * e.minors.z;
        const double bound = orient_bound * std::max(std::fabs(ax), e.extent.x) *
                             std::max(std::fabs(ay), e.extent.y) *
                             std::max(std::fabs(az), e.extent.z);
        pos[k] = det > bound ? 1.0 : 0.0;
        neg[k] = det < -bound ? 1.0 : 0.0;
        // triangle_quality(a, e.b, e.c, e.length).
        const double cax = e.c.x - ax, cay = e.c.y - ay, caz = e.c.z - az;
        const double abx = ax - e.b.x, aby = ay - e.b.y, abz = az - e.b.z;
        const double bax = e.b.x - ax, bay = e.b.y - ay, baz = e.b.z - az;
        const double lb = std::sqrt(cax * cax + cay * cay + caz * caz);
        const double lc = std::sqrt(abx * abx + aby * aby + abz * abz);
        const double nx = bay * caz - baz * cay, ny = baz * cax - bax * caz,
                     nz = bax * cay - bay * cax;
        const double area = 0.5 * std::sqrt(nx * nx + ny * ny + nz * nz);
        const double perimeter = e.length + lb + lc;
        const double lmax = std::max(std::max(e.length, lb), lc);
        const double inradius = 2.0 * area / perimeter;
        q[k] = 2.0 * std::sqrt(3.0) * inradius / lmax;
    }
    for (int k = 0; k < 8; ++k) {
        certain |= unsigned(pos[k] != 0) << k;
        folded |= unsigned(neg[k] != 0) << k;
    }
}

/// Bit k set for each point p[k] that would fold a star triangle: orient(p[k], e) <= 0 for an e
/// of `far`, decided exactly for the lanes in `undecided` (the filter decided the others).
inline unsigned folds_exactly(const Points8 &p, const std::vector<FarEdge> &far,
                              unsigned undecided) {
    unsigned folded = 0;
    for (int k = 0; k < 8; ++k)
        if (undecided >> k & 1u)
            for (const FarEdge &e : far)
                if (predicates::orient(p[k], e) <= 0) {
                    folded |= 1u << k;
                    break;
                }
    return folded;
}

/// Which of p[0..7], considered in turn, the quality rounds' search accepts: star_count_score(
/// p[k], far, floor, best + 1e-12) above best + 1e-12, with best raised to each accepted score,
/// and (with `left_of`: slide_node's land edges) orient(p[k], e) > 0 for each e there. Bit k set
/// for each accepted. The eight scores are computed to the end, with the least of the bounds
/// star_count_score stops at on the way: the same decisions as eight calls.
[[gnu::always_inline]] inline unsigned
star_count_lanes(const Points8 &p, const std::vector<FarEdge> &far, const CountRule &rule,
                 double floor, double &best, const std::vector<FarEdge> *left_of) {
    const double worst_goal = rule.worst_goal, count_quality = rule.count_quality,
                 count_cap = rule.count_cap, count_worst_weight = rule.worst_weight;
    double score[8], worst[8], least[8], q[8];
    double below[8] = {}; // 1 once a triangle is below floor
    for (int k = 0; k < 8; ++k) {
        score[k] = 0;
        worst[k] = worst_goal;
        least[k] = std::numeric_limits<double>::infinity();
    }
    unsigned out = 0, undecided = 0;
    double left = static_cast<double>(far.size());
    for (const FarEdge &e : far) {
        unsigned certain, folded;
        star_triangle8(p, e, q, certain, folded);
        out |= folded;
        undecided |= ~(certain | folded) & 0xffu;
        left -= 1;
        for (int k = 0; k < 8; ++k) {
            below[k] = q[k] < floor ? 1.0 : below[k];
            worst[k] = std::min(worst[k], q[k]);
            score[k] += (q[k] > count_quality ? 1.0 : 0.0) + std::min(q[k], count_cap);
            least[k] = std::min(least[k],
                                count_worst_weight * worst[k] + score[k] + left * (1 + count_cap));
        }
    }
    for (int k = 0; k < 8; ++k)
        out |= unsigned(below[k] != 0) << k;
    out |= folds_exactly(p, far, undecided & ~out);
    if (left_of)
        out |= folds_exactly(p, *left_of, 0xffu & ~out);
    unsigned accepted = 0;
    for (int k = 0; k < 8; ++k) {
        const double beat = best + 1e-12;
        const double total = count_worst_weight * worst[k] + score[k];
        if ((out >> k & 1u) || least[k] <= beat || total <= beat)
            continue;
        best = total;
        accepted |= 1u << k;
    }
    return accepted;
}

/// The same for the search rounds: star_worst_quality(p[k], far, best + 1e-9) above best + 1e-9.
[[gnu::always_inline]] inline unsigned
star_worst_lanes(const Points8 &p, const std::vector<FarEdge> &far, double &best) {
    double worst[8], q[8];
    for (double &w : worst)
        w = 1;
    unsigned out = 0, undecided = 0;
    for (const FarEdge &e : far) {
        unsigned certain, folded;
        star_triangle8(p, e, q, certain, folded);
        out |= folded;
        undecided |= ~(certain | folded) & 0xffu;
        for (int k = 0; k < 8; ++k)
            worst[k] = std::min(worst[k], q[k]);
    }
    out |= folds_exactly(p, far, undecided & ~out);
    unsigned accepted = 0;
    for (int k = 0; k < 8; ++k) {
        if ((out >> k & 1u) || worst[k] <= best + 1e-9)
            continue;
        best = worst[k];
        accepted |= 1u << k;
    }
    return accepted;
}

// The builds of star_count_lanes and star_worst_lanes, and the calls that run the one in use.
GLOBEMESH_LANES_TARGET("avx512f")
inline unsigned star_count_avx512f(const Points8 &p, const std::vector<FarEdge> &far,
                                   const CountRule &rule, double floor, double &best,
                                   const std::vector<FarEdge> *left_of) {
    return star_count_lanes(p, far, rule, floor, best, left_of);
}
GLOBEMESH_LANES_TARGET("avx2")
inline unsigned star_count_avx2(const Points8 &p, const std::vector<FarEdge> &far,
                                const CountRule &rule, double floor, double &best,
                                const std::vector<FarEdge> *left_of) {
    return star_count_lanes(p, far, rule, floor, best, left_of);
}
inline unsigned star_count_baseline(const Points8 &p, const std::vector<FarEdge> &far,
                                    const CountRule &rule, double floor, double &best,
                                    const std::vector<FarEdge> *left_of) {
    return star_count_lanes(p, far, rule, floor, best, left_of);
}
GLOBEMESH_LANES_TARGET("avx512f")
inline unsigned star_worst_avx512f(const Points8 &p, const std::vector<FarEdge> &far,
                                   double &best) {
    return star_worst_lanes(p, far, best);
}
GLOBEMESH_LANES_TARGET("avx2")
inline unsigned star_worst_avx2(const Points8 &p, const std::vector<FarEdge> &far, double &best) {
    return star_worst_lanes(p, far, best);
}
inline unsigned star_worst_baseline(const Points8 &p, const std::vector<FarEdge> &far,
                                    double &best) {
    return star_worst_lanes(p, far, best);
}

inline unsigned star_count_accepts(const Points8 &p, const std::vector<FarEdge> &far,
                                   const CountRule &rule, double floor, double &best,
                                   const std::vector<FarEdge> *left_of = nullptr) {
    switch (star_scorer_in_use()) {
    case StarScorer::avx512f:
        return star_count_avx512f(p, far, rule, floor, best, left_of);
    case StarScorer::avx2:
        return star_count_avx2(p, far, rule, floor, best, left_of);
    default:
        return star_count_baseline(p, far, rule, floor, best, left_of);
    }
}

inline unsigned star_worst_accepts(const Points8 &p, const std::vector<FarEdge> &far,
                                   double &best) {
    switch (star_scorer_in_use()) {
    case StarScorer::avx512f:
        return star_worst_avx512f(p, far, best);
    case StarScorer::avx2:
        return star_worst_avx2(p, far, best);
    default:
        return star_worst_baseline(p, far, best);
    }
}

/// A pattern search on the sphere from `to`: the eight directions at `step` around it, moving
/// to the last that pick accepts (pick(points) returns a bit for each point accepted in turn and
/// keeps the best so far), the step halved when none is accepted, until it is no longer above
/// `stop`. Returns where it ends.
template <class Pick> Vec3 pattern_search(Vec3 to, double step, double stop, Pick &&pick) {
    // cos and sin of k pi / 4.
    constexpr double r = 0.70710678118654752440;
    constexpr double cosines[8] = {1, r, 0, -r, -1, -r, 0, r},
                     sines[8] = {0, r, 1, r, 0, -r, -1, -r};
    Points8 points;
    while (step > stop) {
        const Vec3 e1 = normalized(cross(to, std::abs(to.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 e2 = cross(to, e1);
        for (int k = 0; k < 8; ++k) {
            const Vec3 p = normalized(to + step * (cosines[k] * e1 + sines[k] * e2));
            points.x[k] = p.x;
            points.y[k] = p.y;
            points.z[k] = p.z;
        }
        const unsigned accepted = pick(points);
        const Vec3 next = accepted ? points[std::bit_width(accepted) - 1] : to;
        if (next == to)
            step *= 0.5;
        else
            to = next;
    }
    return to;
}

} // namespace globemesh::detail
