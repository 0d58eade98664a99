// The improve stage's eight-lane scoring (mesher/star_search.hpp) against the one-point scores
// it replaces: for each step of a pattern search, the same points accepted and the same best as
// eight calls of star_count_score / star_worst_quality considered in turn, on random stars
// (folds, floors and early stops among them) and on the cases the lanes hand to exact
// arithmetic (points on an edge's great circle, coordinates exactly 0). Each test runs with each
// build of the lanes the processor can run (AVX-512, AVX2, baseline), and the mesher gives the
// same bytes with each.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "star_search.hpp"
#include "support.hpp"

namespace globemesh::detail {
namespace {

constexpr CountRule rule{0.6, 0.8, 0.82, 1000};

constexpr StarScorer builds[] = {StarScorer::avx512f, StarScorer::avx2, StarScorer::baseline};

std::string build_name(StarScorer s) {
    return s == StarScorer::avx512f ? "avx512f" : s == StarScorer::avx2 ? "avx2" : "baseline";
}

/// Runs the lanes' build `s` while it lives, then the host's pick again.
class ForcedBuild {
public:
    explicit ForcedBuild(StarScorer s) : ran_(force_star_scorer(s)) {}
    ~ForcedBuild() { star_scorer_in_use() = host_; }
    ForcedBuild(const ForcedBuild &) = delete;
    ForcedBuild &operator=(const ForcedBuild &) = delete;
    bool ran() const { return ran_; }

private:
    StarScorer host_ = star_scorer_in_use();
    bool ran_;
};

/// The tests of the lanes, once per build; a build this processor cannot run is skipped.
class StarSearch : public ::testing::TestWithParam<StarScorer> {
protected:
    void SetUp() override {
        if (!forced_.ran())
            GTEST_SKIP() << "this processor cannot run the " << build_name(GetParam()) << " build";
    }
    ForcedBuild forced_{GetParam()};
};

/// What the quality rounds accepted before the lanes: star_count_score of each point in turn,
/// against best + 1e-12, after the `left_of` orientations.
unsigned count_accepts_one_by_one(const Points8 &p, const std::vector<FarEdge> &far, double floor,
                                  double &best, const std::vector<FarEdge> *left_of = nullptr) {
    unsigned accepted = 0;
    for (int k = 0; k < 8; ++k) {
        bool left = true;
        if (left_of)
            for (const FarEdge &e : *left_of)
                left = left && predicates::orient(p[k], e) > 0;
        if (!left)
            continue;
        const double score = star_count_score(p[k], far, rule, floor, best + 1e-12);
        if (score <= best + 1e-12)
            continue;
        best = score;
        accepted |= 1u << k;
    }
    return accepted;
}

/// The search rounds' the same way: star_worst_quality against best + 1e-9.
unsigned worst_accepts_one_by_one(const Points8 &p, const std::vector<FarEdge> &far, double &best) {
    unsigned accepted = 0;
    for (int k = 0; k < 8; ++k) {
        const double w = star_worst_quality(p[k], far, best + 1e-9);
        if (w <= best + 1e-9)
            continue;
        best = w;
        accepted |= 1u << k;
    }
    return accepted;
}

/// A star around `centre`: n ring points at about `radius`, counter-clockwise, jittered.
std::vector<FarEdge> random_star(const Vec3 &centre, int n, double radius, std::mt19937_64 &rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    const Vec3 e1 =
        normalized(cross(centre, std::abs(centre.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
    const Vec3 e2 = cross(centre, e1);
    std::vector<Vec3> ring;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * M_PI * (i + 0.3 * u(rng)) / n;
        const double r = radius * (1 + 0.4 * u(rng));
        ring.push_back(normalized(centre + r * (std::cos(a) * e1 + std::sin(a) * e2)));
    }
    std::vector<FarEdge> far;
    for (int i = 0; i < n; ++i)
        far.emplace_back(ring[std::size_t(i)], ring[std::size_t((i + 1) % n)]);
    return far;
}

/// The eight points of a pattern-search step around `to` (pattern_search's own arithmetic).
Points8 step_points(const Vec3 &to, double step) {
    Points8 points{};
    Vec3 first = to;
    pattern_search(to, step, 0.75 * step, [&](const Points8 &p) {
        points = p;
        first = p[0];
        return 0u; // none accepted: the search halves the step and ends
    });
    EXPECT_NE(first, to);
    return points;
}

TEST_P(StarSearch, eight_lanes_accept_what_eight_calls_in_turn_accepted) {
    std::mt19937_64 rng(20261203);
    std::uniform_real_distribution<double> u(-1, 1);
    std::size_t trials = 0, accepted_any = 0, rejected_some = 0, with_floor = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const Vec3 centre = normalized(Vec3{u(rng), u(rng), u(rng)});
        const double radius = 1e-3 * (1 + u(rng) * 0.9);
        const std::vector<FarEdge> far = random_star(centre, 4 + trial % 6, radius, rng);
        // Off centre, so that the searches have somewhere to go; steps from a tenth of the
        // radius (small moves) to twice it (folds).
        const Vec3 p0 = normalized(centre + 0.3 * radius * Vec3{u(rng), u(rng), u(rng)});
        const double worst0 = star_worst_quality(p0, far);
        if (worst0 <= 0)
            continue; // p0 itself folds the star
        const double floor = std::min(worst0, rule.worst_goal);
        with_floor += floor < rule.worst_goal;
        const Points8 points = step_points(p0, radius * (0.1 + 1.9 * (trial % 16) / 15.0));
        const std::vector<FarEdge> land(far.begin(),
                                        far.begin() + 2); // stands for slide_node's land edges
        for (const std::vector<FarEdge> *left_of :
             {static_cast<const std::vector<FarEdge> *>(nullptr), &land}) {
            double best_one = star_count_score(p0, far, rule, floor), best_lanes = best_one;
            const unsigned one = count_accepts_one_by_one(points, far, floor, best_one, left_of);
            const unsigned lanes =
                star_count_accepts(points, far, rule, floor, best_lanes, left_of);
            ASSERT_EQ(lanes, one) << "trial " << trial;
            ASSERT_EQ(best_lanes, best_one) << "trial " << trial;
            accepted_any += one != 0;
            rejected_some += one != 0xffu;
        }
        double worst_one = worst0, worst_lanes = worst0;
        ASSERT_EQ(star_worst_accepts(points, far, worst_lanes),
                  worst_accepts_one_by_one(points, far, worst_one))
            << "trial " << trial;
        ASSERT_EQ(worst_lanes, worst_one);
        ++trials;
    }
    // The trials covered both outcomes and stars below the goal.
    EXPECT_GT(trials, 3000u);
    EXPECT_GT(accepted_any, 1000u);
    EXPECT_GT(rejected_some, 1000u);
    EXPECT_GT(with_floor, 100u);
}

TEST_P(StarSearch, points_on_an_edge_circle_and_zero_coordinates_are_decided_exactly) {
    // A star around the north pole's neighbourhood on the equator's plane: b and c on the
    // equator (z exactly 0, so the filter's range excludes the edge), candidates on it (orient
    // exactly 0: a fold) and just off it either way.
    const Vec3 b = normalized(Vec3{1, -0.01, 0}), c = normalized(Vec3{1, 0.01, 0});
    const std::vector<FarEdge> far = {FarEdge(b, c), FarEdge(c, normalized(Vec3{1, 0, 0.02})),
                                      FarEdge(normalized(Vec3{1, 0, 0.02}), b)};
    Points8 p{};
    const Vec3 points[8] = {normalized(Vec3{1, 0, 0}),        normalized(Vec3{1, 0.005, 0}),
                            normalized(Vec3{1, 0, 0.005}),    normalized(Vec3{1, 0, -0.005}),
                            normalized(Vec3{1, 0.001, 1e-9}), normalized(Vec3{1, -0.001, 1e-300}),
                            normalized(Vec3{1, 0, 0.01}),     normalized(Vec3{1, 0.002, 0.006})};
    for (int k = 0; k < 8; ++k)
        p.x[k] = points[k].x, p.y[k] = points[k].y, p.z[k] = points[k].z;
    for (double floor : {-2.0, 0.0, 0.3}) {
        double best_one = -0.5, best_lanes = -0.5;
        const unsigned one = count_accepts_one_by_one(p, far, floor, best_one);
        EXPECT_EQ(star_count_accepts(p, far, rule, floor, best_lanes), one);
        EXPECT_EQ(best_lanes, best_one);
        // Inside the star: z > 0 by a margin; on the equator or below it folds.
        EXPECT_EQ(one & 0b1011u, 0u) << "the points on or below the edge b -> c must fold";
        EXPECT_NE(one, 0u);
    }
    double worst_one = 0, worst_lanes = 0;
    EXPECT_EQ(star_worst_accepts(p, far, worst_lanes), worst_accepts_one_by_one(p, far, worst_one));
    EXPECT_EQ(worst_lanes, worst_one);
}

TEST_P(StarSearch, points_the_filter_cannot_decide_are_decided_exactly) {
    // The same star turned so that no coordinate is 0 (the lanes' filter applies), with
    // candidates on the great circle of b -> c up to rounding: the filter leaves them to exact
    // arithmetic, which folds some of them.
    auto turn = [](const Vec3 &v) {
        const Vec3 a = normalized(Vec3{0.3, -0.5, 0.8});
        const double t = 0.7; // about the axis a
        return normalized(std::cos(t) * v + std::sin(t) * cross(a, v) +
                          (1 - std::cos(t)) * dot(a, v) * a);
    };
    const Vec3 b = turn(normalized(Vec3{1, -0.01, 0})), c = turn(normalized(Vec3{1, 0.01, 0}));
    const Vec3 d = turn(normalized(Vec3{1, 0, 0.02}));
    const std::vector<FarEdge> far = {FarEdge(b, c), FarEdge(c, d), FarEdge(d, b)};
    Points8 p{};
    for (int k = 0; k < 8; ++k) {
        const Vec3 q =
            k < 7 ? normalized(b + (0.2 + 0.1 * k) * (c - b)) : turn(normalized(Vec3{1, 0, 0.005}));
        p.x[k] = q.x, p.y[k] = q.y, p.z[k] = q.z;
    }
    unsigned folded = 0;
    for (int k = 0; k < 7; ++k) {
        ASSERT_EQ(predicates::detail::orient_filter(p[k], b, c), 0)
            << "lane " << k << " is not a case for exact arithmetic";
        folded |= unsigned(predicates::orient(p[k], far[0]) <= 0) << k;
    }
    ASSERT_NE(folded, 0u) << "no lane on the circle folds: the exact stage is not exercised";
    double best_one = -0.5, best_lanes = -0.5;
    const unsigned one = count_accepts_one_by_one(p, far, -2.0, best_one);
    EXPECT_EQ(star_count_accepts(p, far, rule, -2.0, best_lanes), one);
    EXPECT_EQ(best_lanes, best_one);
    EXPECT_EQ(one & folded, 0u);
    double worst_one = -0.5, worst_lanes = -0.5;
    EXPECT_EQ(star_worst_accepts(p, far, worst_lanes), worst_accepts_one_by_one(p, far, worst_one));
    EXPECT_EQ(worst_lanes, worst_one);
}

INSTANTIATE_TEST_SUITE_P(Builds, StarSearch, ::testing::ValuesIn(builds),
                         [](const ::testing::TestParamInfo<StarScorer> &info) {
                             return build_name(info.param);
                         });

// The builds differ in vector width only (none uses FMA), so the improve stage must move every
// node to the same double in each. The program itself (not this file's copies of the inline
// scorers) meshes a graded 1:110m ocean with each build the processor runs
// (GLOBEMESH_STAR_SCORER), and ncdump prints every variable (node coordinates, faces, their
// quality and areas...) with 17 digits, which tell every double apart.
TEST(StarSearchBuilds, every_build_the_processor_runs_gives_the_same_mesh) {
    test::TempDir dir;
    std::vector<std::string> ran;
    std::string first;
    for (StarScorer s : builds) {
        if (!star_scorer_supported(s))
            continue;
        const std::string name = s == StarScorer::baseline ? "default" : build_name(s);
        const auto nc = dir / (name + ".nc");
        std::string out;
        ASSERT_EQ(test::run_command("GLOBEMESH_STAR_SCORER=" + name +
                                        " " GLOBEMESH_EXE " mesh -q --coast " +
                                        test::fixture("coast/ne_110m_land.gpkg").string() +
                                        " --coast-layer land --hmin 150km --hmax 400km --bathy " +
                                        test::fixture("bathy/etopo5_global_10min.nc").string() +
                                        " -o " + nc.string(),
                                    out),
                  0)
            << out;
        ASSERT_EQ(
            test::run_command("ncdump -p 17,17 " + nc.string() + " | sed -n '/^data:/,$p'", out), 0)
            << out;
        ASSERT_GT(out.size(), 100000u) << out.substr(0, 500);
        if (ran.empty())
            first = out;
        else
            EXPECT_TRUE(out == first) << name << " gives another mesh than " << ran.front();
        ran.push_back(name);
    }
    // The baseline runs everywhere; on x86-64, AVX2 too on any processor of the last decade.
    ASSERT_FALSE(ran.empty());
    if (ran.size() < 2)
        GTEST_SKIP() << "only the " << ran.front() << " build runs here: nothing to compare";
}

} // namespace
} // namespace globemesh::detail
