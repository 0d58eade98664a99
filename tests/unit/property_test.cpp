// Property tests (issue 8): generated inputs, fixed seeds, invariants as the oracle.
//   * the spherical Delaunay core: for thousands of point sets with duplicates, clusters a few
//     ulps or 1e-10 rad apart, co-circular and co-planar subsets and both poles, validate() is
//     empty, V - E + F = 2, and shuffling the input (or changing the BRIO seed) gives the same
//     triangle set (the perturbed predicates make the triangulation unique);
//   * the coast pipeline: for hundreds of small hostile GeoJSON coasts (temporary files)
//   (self-intersecting rings,
//     rings across +-180 and round the poles, duplicate and near-duplicate vertices), load_coast ->
//     shape_boundary -> mesh_boundary gives a valid mesh (3 distinct nodes per face, CCW by the
//     exact orient predicate, every edge shared by two faces or tagged boundary) or a DataError /
//     UsageError;
//   * removing land never removes ocean: with islands L and a subset L', the ocean area of L'
//     (sum of spherical face areas) is at least that of L, and every ocean face centroid of L's
//     mesh lies in a face of L''s mesh;
//   * regression tests for what tests/fuzz found (see each test's comment).
#include <gtest/gtest.h>

#include <csignal>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "globemesh/coast.hpp"
#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/options.hpp"
#include "globemesh/predicates.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"
#include "support.hpp"

using namespace globemesh;

namespace {

// --- the core -----------------------------------------------------------------------------------

Vec3 rotate(const Vec3 &v, const Vec3 &axis, double angle) { // Rodrigues, axis a unit vector
    const double c = std::cos(angle), s = std::sin(angle);
    return c * v + s * cross(axis, v) + ((1 - c) * dot(axis, v)) * axis;
}

double nudge(double x, int k) {
    for (; k > 0; --k)
        x = std::nextafter(x, INFINITY);
    for (; k < 0; ++k)
        x = std::nextafter(x, -INFINITY);
    return x;
}

struct PointGen {
    std::mt19937_64 rng;
    explicit PointGen(std::uint64_t seed) : rng(seed) {}
    double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
    int pick(int n) { return static_cast<int>(rng() % static_cast<std::uint64_t>(n)); }
    Vec3 random_unit() {
        std::normal_distribution<double> g;
        return normalized(Vec3{g(rng), g(rng), g(rng)});
    }

    /// 4..64 points: random, a shared small circle, a great circle, poles and axes, a line of
    /// latitude on a 15-degree grid; when clustered also duplicates, ulp nudges and 1e-13..1e-6
    /// rad neighbours.
    std::vector<Vec3> points(bool clustered) {
        const int n = 4 + pick(61);
        const Vec3 axis = random_unit();
        const double radius = std::pow(10.0, uniform(-6, 0.2));
        const Vec3 start = normalized(cross(axis, random_unit()));
        const Vec3 on_circle = rotate(axis, start, radius);
        const Vec3 normal = random_unit();
        const Vec3 gc = normalized(cross(normal, random_unit()));
        const int quantum = 3 + pick(20);
        std::vector<Vec3> pts;
        while (static_cast<int>(pts.size()) < n) {
            int mode = pts.empty() ? 0 : pick(9);
            if (!clustered && mode >= 1 && mode <= 3)
                mode = 0;
            const Vec3 e = pts.empty()
                               ? Vec3{}
                               : pts[static_cast<std::size_t>(pick(static_cast<int>(pts.size())))];
            switch (mode) {
            case 0:
                pts.push_back(random_unit());
                break;
            case 1:
                pts.push_back(e);
                break;
            case 2:
                pts.push_back(
                    {nudge(e.x, pick(7) - 3), nudge(e.y, pick(7) - 3), nudge(e.z, pick(7) - 3)});
                break;
            case 3: {
                const Vec3 perp = cross(e, random_unit());
                if (norm(perp) > 1e-6)
                    pts.push_back(
                        normalized(rotate(e, normalized(perp), std::pow(10.0, uniform(-13, -6)))));
                break;
            }
            case 4:
                pts.push_back(rotate(on_circle, axis, 2 * pi * pick(quantum) / quantum));
                break;
            case 5:
                pts.push_back(rotate(gc, normal, 2 * pi * pick(4 * quantum) / (4 * quantum)));
                break;
            case 6: {
                static const Vec3 axes[6] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                             {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
                pts.push_back(axes[pick(6)]);
                break;
            }
            case 7:
                pts.push_back(lonlat_to_vec(15.0 * (pick(25) - 12), 15.0 * (pick(13) - 6)));
                break;
            default:
                pts.push_back(random_unit());
            }
        }
        // The predicates' contract: no non-zero coordinate below ~1e-182 (a nudged 0 is subnormal).
        for (Vec3 &p : pts)
            for (double *c : {&p.x, &p.y, &p.z})
                if (std::fabs(*c) < 1e-170)
                    *c = 0;
        return pts;
    }
};

using TriangleKey = std::array<double, 9>;

/// The live triangles as coordinates, rotated to start at the lexicographically smallest vertex.
std::set<TriangleKey> triangle_set(const SphericalDelaunay &d) {
    std::set<TriangleKey> out;
    auto less = [](const Vec3 &a, const Vec3 &b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
        if (!d.is_live(t))
            continue;
        std::array<Vec3, 3> v{d.point(d.vertex(t, 0)), d.point(d.vertex(t, 1)),
                              d.point(d.vertex(t, 2))};
        std::rotate(v.begin(), std::min_element(v.begin(), v.end(), less), v.end());
        out.insert({v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z});
    }
    return out;
}

std::string describe(const std::vector<Vec3> &pts) {
    std::string s;
    char buf[128];
    for (const Vec3 &p : pts) {
        std::snprintf(buf, sizeof buf, "{%a, %a, %a},\n", p.x, p.y, p.z);
        s += buf;
    }
    return s;
}

/// True when insert_points may refuse the set: fewer than 3 points more than the merge tolerance
/// (1e-12 rad) apart, or all of those exactly on one plane (a point within the tolerance of
/// another is merged into it, whatever side of the plane it lies on).
bool spans_no_tetrahedron(const std::vector<Vec3> &pts) {
    std::vector<Vec3> reps;
    for (const Vec3 &p : pts) {
        bool near = false;
        for (const Vec3 &r : reps)
            near = near || arc_angle(p, r) <= 1e-12;
        if (!near)
            reps.push_back(p);
    }
    for (std::size_t i = 0; i < reps.size(); ++i)
        for (std::size_t j = i + 1; j < reps.size(); ++j)
            for (std::size_t k = j + 1; k < reps.size(); ++k) {
                if (norm(cross(reps[j] - reps[i], reps[k] - reps[i])) < 1e-9)
                    continue;
                for (const Vec3 &p : reps)
                    if (predicates::orient3d(reps[i], reps[j], reps[k], p) != 0)
                        return false;
                return true;
            }
    return true;
}

/// Every invariant the fuzz target checks, as a GoogleTest failure.
void expect_valid_triangulation(const std::vector<Vec3> &pts, std::uint64_t seed,
                                int &order_checked) {
    SphericalDelaunay d;
    std::vector<VertexId> map;
    try {
        map = d.insert_points(std::span<const Vec3>(pts));
    } catch (const DataError &) {
        // Allowed only when the points span no tetrahedron.
        ASSERT_TRUE(spans_no_tetrahedron(pts)) << "seed " << seed << "\n" << describe(pts);
        return;
    }
    const auto problems = d.validate();
    ASSERT_TRUE(problems.empty()) << "seed " << seed << ": " << problems.front() << "\n"
                                  << describe(pts);
    std::set<VertexId> used;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t)
        if (d.is_live(t))
            for (int k = 0; k < 3; ++k)
                used.insert(d.vertex(t, k));
    for (std::size_t i = 0; i < pts.size(); ++i) {
        ASSERT_LE(arc_angle(d.point(map[i]), pts[i]), 1e-7)
            << "seed " << seed << ": point " << i << "\n"
            << describe(pts);
        ASSERT_TRUE(used.count(map[i]))
            << "seed " << seed << ": point " << i << " is in no triangle\n"
            << describe(pts);
    }
    ASSERT_EQ(d.triangle_count(), 2 * used.size() - 4) << "seed " << seed << "\n" << describe(pts);
    // Which of two close points survives (merged within 1e-12 rad, or within ~1e-8 rad when one
    // falls inside the hull of the other and its neighbours) depends on the order: compare orders
    // only without them.
    for (std::size_t i = 0; i < pts.size(); ++i)
        for (std::size_t j = i + 1; j < pts.size(); ++j)
            if (!(pts[i] == pts[j]) && arc_angle(pts[i], pts[j]) < 1e-7)
                return;
    ++order_checked;

    const auto reference = triangle_set(d);
    std::vector<Vec3> shuffled = pts;
    std::mt19937_64 rng(seed ^ 0x5eed);
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    SphericalDelaunay::Options o;
    o.seed = seed + 17;
    SphericalDelaunay d2(o);
    d2.insert_points(std::span<const Vec3>(shuffled));
    ASSERT_TRUE(d2.validate().empty()) << "seed " << seed;
    ASSERT_EQ(triangle_set(d2), reference)
        << "seed " << seed << ": shuffling changed the triangles\n"
        << describe(pts);
}

} // namespace

TEST(DelaunayProperty, generated_point_sets_triangulate_validly_and_independently_of_order) {
    int order_checked = 0;
    for (std::uint64_t seed = 1; seed <= 3000; ++seed) {
        PointGen g(seed);
        const auto pts = g.points(seed % 2 == 1);
        expect_valid_triangulation(pts, seed, order_checked);
        if (HasFatalFailure())
            return;
    }
    // The order check must actually have run on most unclustered sets.
    EXPECT_GT(order_checked, 1200);
}

// Found by tests/fuzz/fuzz_delaunay: the north pole, two points 1e-9 rad from the south pole and
// (1,0,0). The hull is a tetrahedron; the triangle (N, S1, S2) is a lune of angle = the longitude
// difference of S1 and S2 (2.73 sr), but spherical_triangle_area's det/(1 + a.b + b.c + c.a)
// form lost every digit (both ~1e-18), so validate() reported "areas add up to 12.98 sr: folded
// triangles". Fixed in src/sphere/sphere.cpp (angle sum for near-antipodal vertices).
TEST(SphereProperty, triangle_with_nearly_antipodal_vertices_has_the_area_of_its_lune) {
    const Vec3 s1{-0x1.d7696690d15fep-31, -0x1.1ad8d723b0d32p-31, -0x1p+0};
    const Vec3 n{0, 0, 1};
    const Vec3 s2{-0x1.74d7b336f0708p-31, 0x1.9401399eb21eap-31, -0x1p+0};
    const Vec3 x{1, 0, 0};
    // Closed form: the lune between the meridians of s1 and s2, less a triangle of ~1e-18 sr.
    double dlon = std::atan2(s2.y, s2.x) - std::atan2(s1.y, s1.x);
    if (dlon < 0)
        dlon += 2 * pi;
    const double lune = 2 * std::min(dlon, 2 * pi - dlon);
    EXPECT_NEAR(std::fabs(spherical_triangle_area(s1, n, s2)), lune, 1e-9);
    EXPECT_NEAR(spherical_triangle_area(s1, n, s2) + spherical_triangle_area(s2, n, s1), 0.0,
                1e-12);

    SphericalDelaunay d;
    const std::vector<Vec3> pts{s1, n, s2, x};
    d.insert_points(std::span<const Vec3>(pts));
    const auto problems = d.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    double total = 0;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t)
        if (d.is_live(t))
            total += spherical_triangle_area(d.point(d.vertex(t, 0)), d.point(d.vertex(t, 1)),
                                             d.point(d.vertex(t, 2)));
    EXPECT_NEAR(total, 4 * pi, 1e-9); // the hull contains the origin
}

// Found by tests/fuzz/fuzz_delaunay: four points within 1e-17 of one great circle whose hull
// does not contain the origin (exact dets of the outward faces: -1.7e-18, 3.5e-17, 8.2e-17,
// 4.6e-17, checked with rationals). Two faces have areas near +-2 pi, and the rounded det gave
// the ghost face +2 pi, so validate() reported a clockwise triangle in a hull around the origin.
// Fixed in src/sphere/sphere.cpp: below 1e-14 the area takes the sign of the exact orient.
TEST(SphereProperty, triangle_area_sign_follows_the_exact_orientation_near_a_great_circle) {
    const std::vector<Vec3> pts{
        {0x1.01792d6bc79d6p-3, -0x1.e6831bc4032b4p-1, -0x1.23ef9ba1c7466p-2},
        {-0x1.062a60c54698dp-2, 0x1.de69cdf1936cdp-1, 0x1.fb427994a5adap-3},
        {0x1.86b5f41403eb2p-2, -0x1.cd670b94037cfp-1, -0x1.a532b75ea815bp-3},
        {-0x1.e75cb85d96405p-1, 0x1.14792521be96cp-2, -0x1.28fdc101a4ca8p-3}};
    SphericalDelaunay d;
    d.insert_points(std::span<const Vec3>(pts));
    const auto problems = d.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    double total = 0;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
        if (!d.is_live(t))
            continue;
        const Vec3 &a = d.point(d.vertex(t, 0)), &b = d.point(d.vertex(t, 1)),
                   &c = d.point(d.vertex(t, 2));
        const double area = spherical_triangle_area(a, b, c);
        const int o = predicates::orient(a, b, c);
        EXPECT_TRUE(o == 0 || area == 0 || (area > 0) == (o > 0))
            << "area " << area << " orient " << o;
        total += area;
    }
    EXPECT_NEAR(total, 0.0, 1e-9); // the hull does not contain the origin
    // Random near-flat triples: the sign of the area is the sign of the exact determinant.
    PointGen g(7);
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a = g.random_unit(), b = g.random_unit();
        const Vec3 nrm = normalized(cross(a, b));
        const Vec3 c = normalized(rotate(a, nrm, g.uniform(0, 2 * pi)) +
                                  std::ldexp(g.uniform(-1, 1), -g.pick(60) - 40) * nrm);
        const double area = spherical_triangle_area(a, b, c);
        const int o = predicates::orient(a, b, c);
        ASSERT_TRUE(o == 0 || area == 0 || (area > 0) == (o > 0)) << describe({a, b, c});
    }
}

// Found by tests/fuzz/fuzz_delaunay (after a move_vertex): the triangle a, b, c with b and c
// nearly antipodal and the minor arc b-c passing by -a, so that its three minor arcs run round
// one great circle: a hemisphere, area 2 pi (det 2.2e-27, den -3.5e-11 in exact arithmetic).
// The signed-angle fallback lost the sign of the angles near pi. Fixed in src/sphere/sphere.cpp
// (unsigned angles, the exact orientation's sign).
TEST(SphereProperty, triangle_whose_arcs_run_round_a_great_circle_has_the_area_of_a_hemisphere) {
    const Vec3 a{-0x1.3333333333334p-1, 0x1.19799812deaf1p-40, -0x1.999999999999ap-1};
    const Vec3 b{0, -1, 0};
    const Vec3 c{0x1.6df2b3e614e8p-36, 0x1p+0, 0x1.e7ee4532c68abp-36};
    ASSERT_EQ(predicates::orient(a, b, c), 1);
    EXPECT_NEAR(spherical_triangle_area(a, b, c), 2 * pi, 1e-9);
    EXPECT_NEAR(spherical_triangle_area(a, c, b), -2 * pi, 1e-9);
}

// Found by tests/fuzz/fuzz_delaunay: points 2 and 3 are antipodal to within 4 ulps, so the
// hull does not contain the origin (signed areas must add up to 0: checked in 50-digit
// arithmetic, as are the two faces through both points, of -5.047 and -0.192 sr). With plain
// cross products the direction of their arc is rounding noise and validate() reported a sum of
// -5.8e-5 sr. Fixed in src/sphere/sphere.cpp (FMA-accurate cross products in the angle form).
TEST(SphereProperty, areas_of_a_hull_with_points_ulps_from_antipodal_add_up_to_zero) {
    const std::vector<Vec3> pts{
        {0x0p+0, 0x0p+0, 0x1p+0},
        {0x1.9dcbe81f787aep-21, -0x1.55e1762f3851dp-21, 0x1.fffffffffee6cp-1},
        {-0x1.419ed152373f1p-3, 0x1.e35c5c2ddae82p-1, 0x1.28ed40471db1p-2},
        {0x1.419ed152373f5p-3, -0x1.e35c5c2ddae82p-1, -0x1.28ed40471db13p-2},
        {0x1.ffffffffffffep-3, 0x1.bb67ae8584caap-2, 0x1.bb67ae8584cabp-1},
        {0x1.e7ef630589655p-2, -0x1.cfcf337476a3p-5, -0x1.c134059943a1ep-1}};
    SphericalDelaunay d;
    d.insert_points(std::span<const Vec3>(pts));
    const auto problems = d.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    double total = 0;
    std::vector<double> through_both; // faces through points 2 and 3
    for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
        if (!d.is_live(t))
            continue;
        const Vec3 &a = d.point(d.vertex(t, 0)), &b = d.point(d.vertex(t, 1)),
                   &c = d.point(d.vertex(t, 2));
        const double area = spherical_triangle_area(a, b, c);
        total += area;
        int both = 0;
        for (const Vec3 *p : {&a, &b, &c})
            both += (*p == pts[2]) + (*p == pts[3]);
        if (both == 2)
            through_both.push_back(area);
    }
    EXPECT_NEAR(total, 0.0, 1e-9);
    std::sort(through_both.begin(), through_both.end());
    ASSERT_EQ(through_both.size(), 2u);
    EXPECT_NEAR(through_both[0], -5.047431234780856, 1e-9);
    EXPECT_NEAR(through_both[1], -0.19152962558708048, 1e-9);
}

// Found by tests/fuzz/fuzz_delaunay: points 0 and 1 are 2 ulps apart (1e-16 rad, far below the
// 1e-12 rad merge tolerance). insert_points mapped point 1 to its own vertex, but no triangle
// used it and merged_count() was 0: inserting point 0 afterwards, its cavity held the whole star
// of point 1's vertex (a point 2 ulps off puts its twin inside the hull), so the fan over the
// cavity's rim dropped that vertex silently. Fixed in src/delaunay: a swallowed vertex either
// takes the new point (the nearer one, as here) or is merged into its nearest rim vertex.
TEST(DelaunayProperty, point_ulps_from_another_maps_to_a_vertex_of_the_triangulation) {
    const std::vector<Vec3> pts{
        {-0x1.09684c36307edp-13, 0x1.ce03f13427331p-14, -0x1.ffffff8718964p-1},
        {-0x1.09684c36307ebp-13, 0x1.ce03f1342732ep-14, -0x1.ffffff8718962p-1},
        {0x1.2cf2304755a5cp-1, 0x0p+0, -0x1.9e3779b97f4a9p-1},
        {0x0p+0, 0x1p+0, 0x0p+0},
        {-0x1.2db80c41452b8p-13, -0x1.6a10c8054e5d4p-14, -0x1.ffffff8718344p-1}};
    SphericalDelaunay d;
    const auto map = d.insert_points(std::span<const Vec3>(pts));
    std::set<VertexId> used;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t)
        if (d.is_live(t))
            for (int k = 0; k < 3; ++k)
                used.insert(d.vertex(t, k));
    for (std::size_t i = 0; i < pts.size(); ++i)
        EXPECT_TRUE(used.count(map[i])) << "point " << i << " -> vertex " << map[i];
    EXPECT_EQ(d.merged_count(), 1u);
}

// --- the coast pipeline -----------------------------------------------------------------------

namespace {

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string feature_collection(const std::vector<std::string> &geometries) {
    std::string s = "{\"type\":\"FeatureCollection\",\"features\":[";
    for (std::size_t i = 0; i < geometries.size(); ++i)
        s += (i ? "," : "") + std::string("{\"type\":\"Feature\",\"properties\":{},\"geometry\":") +
             geometries[i] + "}";
    return s + "]}";
}

std::string ring_json(const std::vector<LonLat> &r, bool close = true) {
    std::string s = "[";
    for (std::size_t i = 0; i < r.size(); ++i)
        s += (i ? ",[" : "[") + num(r[i].lon) + "," + num(r[i].lat) + "]";
    if (close && !r.empty())
        s += ",[" + num(r[0].lon) + "," + num(r[0].lat) + "]";
    return s + "]";
}

/// A GeoJSON string written to a file of a temporary directory (removed with it).
class MemFile {
public:
    MemFile(const std::string &name, const std::string &text) : path_((dir_ / name).string()) {
        std::ofstream(path_) << text;
    }
    const std::string &path() const { return path_; }

private:
    test::TempDir dir_;
    std::string path_;
};

/// Mesh validity as mesh.hpp states it; returns the first problem, empty when valid.
std::string mesh_problem(const Mesh &m) {
    std::set<std::pair<NodeIndex, NodeIndex>> directed;
    for (const auto &f : m.faces) {
        for (NodeIndex v : f)
            if (v >= m.nodes.size())
                return "node index out of range";
        if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
            return "a face repeats a node";
        if (const int o = predicates::orient(m.nodes[f[0]], m.nodes[f[1]], m.nodes[f[2]]); o <= 0) {
            const LonLat ll = vec_to_lonlat(m.nodes[f[0]]);
            return std::string(o == 0 ? "a face is flat (its nodes on one great circle)"
                                      : "a face is clockwise") +
                   " near lon " + num(ll.lon) + " lat " + num(ll.lat) + ", area " +
                   num(spherical_triangle_area(m.nodes[f[0]], m.nodes[f[1]], m.nodes[f[2]])) +
                   " sr";
        }
        for (int k = 0; k < 3; ++k)
            if (!directed.insert({f[k], f[(k + 1) % 3]}).second)
                return "a directed edge is in two faces";
    }
    std::set<std::pair<NodeIndex, NodeIndex>> boundary;
    for (const BoundaryEdge &e : m.boundary) {
        if (!directed.count({e.a, e.b}))
            return "a boundary edge is not a face edge oriented like it";
        if (directed.count({e.b, e.a}))
            return "a boundary edge has faces on both sides";
        boundary.insert({e.a, e.b});
    }
    for (const auto &[a, b] : directed)
        if (!directed.count({b, a}) && !boundary.count({a, b}))
            return "an edge with one face is not tagged boundary";
    return {};
}

// Mesher bug, fixed (MesherProperty.nine_node_island_across_180_meshes_counter_clockwise: ghost
// triangles were labelled ocean): mesh_boundary (src/mesher, owned by the lead) sometimes returns a
// clockwise face. While this is true the batteries below count such meshes apart instead of
// failing; every other problem fails. Set it to false once the mesher is fixed.
constexpr bool known_clockwise_faces = false;

bool known_mesher_issue(const std::string &problem) {
    return known_clockwise_faces && problem.rfind("a face is clockwise", 0) == 0;
}

// Mesher bug, fixed (MesherProperty.nine_node_island_rotated_7_degrees_meshes_in_bounded_memory:
// ghost triangles were labelled ocean): refinement sometimes runs away. Refinement reports progress
// every 16384 insertions; with at most 20000 nodes asked for, a 5th report means a runaway: the run
// is cancelled there and counted apart while this is true (a failure otherwise).
constexpr bool known_runaway = false;

struct RunawayGuard {
    std::size_t reports = 0;
    bool tripped = false;
    Progress progress() {
        return [this](double, std::string_view stage) {
            if (stage == "refine" && ++reports >= 5)
                tripped = true;
            return !tripped;
        };
    }
};

struct CoastGen {
    std::mt19937_64 rng;
    explicit CoastGen(std::uint64_t seed) : rng(seed) {}
    double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
    int pick(int n) { return static_cast<int>(rng() % static_cast<std::uint64_t>(n)); }

    std::vector<LonLat> ring() {
        const int n = 3 + pick(8);
        const int turns = 1 + pick(3); // 2, 3: a self-intersecting star
        const double cx = uniform(-200, 200), cy = uniform(-85, 85);
        const double r = std::pow(10.0, uniform(-3, 1.6));
        std::vector<LonLat> out;
        for (int i = 0; i < n; ++i) {
            const double t = 2 * pi * turns * i / n;
            LonLat p{cx + r * std::cos(t) * uniform(0.5, 1),
                     std::clamp(cy + r * std::sin(t) * uniform(0.5, 1), -90.0, 90.0)};
            switch (pick(10)) {
            case 0:
                p.lon = pick(2) ? 180.0 : -180.0;
                break;
            case 1:
                p.lon = pick(2) ? 180.00000000000014 : -180.00000000000014;
                break;
            case 2:
                p.lat = pick(2) ? 90.0 : -90.0;
                break;
            case 3:
                if (!out.empty())
                    p = out.back();
                break;
            case 4:
                if (!out.empty())
                    p = {out.back().lon + 1e-9, out.back().lat};
                break;
            default:
                break;
            }
            out.push_back(p);
        }
        return out;
    }

    std::string geometry() {
        const int kind = pick(6);
        if (kind <= 2) {
            std::string s = "{\"type\":\"Polygon\",\"coordinates\":[" + ring_json(ring());
            if (pick(3) == 0)
                s += "," + ring_json(ring());
            return s + "]}";
        }
        if (kind ==
            3) // a polar cap drawn as Antarctica is: along a latitude, closed through the pole
        {
            const double lat = pick(2) ? uniform(-89, -50) : uniform(50, 89);
            const double pole = lat < 0 ? -90 : 90;
            std::vector<LonLat> r{
                {-180, pole}, {-180, lat}, {-60, lat + uniform(-3, 3)}, {60, lat + uniform(-3, 3)},
                {180, lat},   {180, pole}};
            return "{\"type\":\"Polygon\",\"coordinates\":[" + ring_json(r) + "]}";
        }
        // One draw after another, in the order g++ evaluated them when they were arguments and
        // operands (unsequenced there: clang's order made other cases of the same seeds).
        if (kind == 4) {
            const std::string second = ring_json(ring()), first = ring_json(ring());
            return "{\"type\":\"MultiPolygon\",\"coordinates\":[[" + first + "],[" + second + "]]}";
        }
        const bool closed = pick(2) == 0;
        return "{\"type\":\"LineString\",\"coordinates\":" + ring_json(ring(), closed) + "}";
    }
};

} // namespace

namespace {

struct CoastCase {
    std::string json;
    MeshOptions options; ///< all but the coast path
    double h = 0;        ///< uniform size, km
};

/// 1-3 hostile geometries, options and a coarse size, all from `seed`.
CoastCase coast_case(std::uint64_t seed) {
    CoastGen g(seed);
    std::vector<std::string> geometries;
    for (int k = 1 + g.pick(3); k > 0; --k)
        geometries.push_back(g.geometry());
    CoastCase c;
    c.json = feature_collection(geometries);
    c.options.keep_inland_seas = g.pick(2) == 0;
    c.options.min_island_triangles = g.pick(3);
    if (g.pick(5) == 0)
        c.options.region = std::array<double, 4>{g.uniform(-180, 0), -60, g.uniform(-180, 180), 60};
    c.h = g.uniform(800, 2000);
    c.options.keep_straits = g.pick(4) == 0;
    return c;
}

} // namespace

namespace {

// Outcomes of one coast case, as the exit status of the child process that runs it.
enum Outcome : int {
    meshed_ok = 0,
    refused_cleanly = 1,
    known_bug = 2,
    bad_boundary = 10,
    bad_mesh = 11,
    unexpected = 12
};

/// Runs load_coast -> shape_boundary -> mesh_boundary on one case in a child process (so that a
/// mesher hang, which reports no progress and cannot be cancelled, only costs `limit_s`).
/// Returns the Outcome, or -1 when the child ran out of time (killed) or crashed (-2).
int run_case_isolated(const CoastCase &c, const std::string &path, int limit_s) {
    std::fflush(nullptr);
    const pid_t pid = fork();
    if (pid == 0) {
        int code = unexpected;
        try {
            MeshOptions options = c.options;
            options.coast = path;
            const SizeFn size = [h = c.h](const Vec3 &) { return h; };
            const CoastData coast = load_coast(options);
            const Boundary boundary = shape_boundary(coast, size, options);
            const auto issues = check_boundary(boundary);
            if (!issues.empty()) {
                std::fprintf(stderr, "shaped boundary invalid: %s\n", issues.front().what.c_str());
                std::_Exit(bad_boundary);
            }
            MesherOptions mo;
            mo.keep_inland_seas = options.keep_inland_seas;
            mo.land = coast.land; // as the pipeline: faces centred on land removed, straits closed
            mo.close_straits = !options.keep_straits;
            mo.max_nodes = 20000;
            mo.lattice_km = c.h; // as the pipeline: the lattice where the field is at its largest
            RunawayGuard guard;
            try {
                const Mesh mesh = mesh_boundary(boundary, size, mo, nullptr, guard.progress());
                const std::string problem = mesh_problem(mesh);
                if (known_mesher_issue(problem))
                    code = known_bug;
                else if (!problem.empty() || mesh.faces.empty()) {
                    std::fprintf(stderr, "mesh invalid: %s\n",
                                 problem.empty() ? "no faces" : problem.c_str());
                    code = bad_mesh;
                } else {
                    code = meshed_ok;
                }
            } catch (const Cancelled &) {
                code = known_runaway && guard.tripped ? known_bug : unexpected;
            }
        } catch (const DataError &) {
            code = refused_cleanly;
        } catch (const UsageError &) {
            code = refused_cleanly;
        } catch (const std::exception &e) {
            std::fprintf(stderr, "unexpected exception: %s\n", e.what());
            code = unexpected;
        }
        std::fflush(nullptr);
        std::_Exit(code);
    }
    if (pid < 0)
        return -2;
    int status = 0;
    for (int waited_ms = 0;; ++waited_ms) {
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid)
            break;
        if (waited_ms >= 1000 * limit_s) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            return -1;
        }
        usleep(1000);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -2;
}

} // namespace

// Each case's time limit: a hang detector, not a timing. Sanitizer builds run the mesher 5 to 10
// times slower (seed 180, a polar coast at h ~1000 km: 0.5 s in Release, 3.5 s under ASan, most
// of it measuring its closed straits' widths).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr int case_limit_s = 15;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr int case_limit_s = 15;
#else
constexpr int case_limit_s = 2;
#endif
#else
constexpr int case_limit_s = 2;
#endif

TEST(CoastProperty, hundreds_of_hostile_small_coasts_mesh_validly_or_raise_a_clean_error) {
    int meshed = 0, refused = 0, known = 0;
    for (std::uint64_t seed = 1; seed <= 200; ++seed) {
        const CoastCase c = coast_case(seed);
        MemFile file("property_coast_" + std::to_string(seed) + ".geojson", c.json);
        int outcome = run_case_isolated(c, file.path(), case_limit_s);
        // Mesher hang, fixed (MesherProperty.hostile_coast_seed_32_meshes_in_bounded_time):
        // refinement loops without reporting progress; counted apart while known_runaway.
        if (outcome == -1 && known_runaway)
            outcome = known_bug;
        ASSERT_GE(outcome, 0) << "seed " << seed << ": "
                              << (outcome == -1
                                      ? "no result in " + std::to_string(case_limit_s) + " s"
                                      : std::string("crashed"))
                              << "\n"
                              << c.json;
        ASSERT_LE(outcome, int(known_bug))
            << "seed " << seed << " (outcome " << outcome << ", message above)\n"
            << c.json;
        meshed += outcome == meshed_ok;
        refused += outcome == refused_cleanly;
        known += outcome == known_bug;
    }
    // Most inputs must actually reach the mesher and give a valid mesh.
    EXPECT_GT(meshed, 100) << refused << " refused, " << known << " with the known mesher bugs";
    std::printf("%d meshed, %d refused cleanly, %d with the known mesher bugs\n", meshed, refused,
                known);
}

namespace {

/// An island: a jittered regular n-gon (n = 3..6) of circumradius r km about a centre, as a
/// lon/lat ring written with continuous longitudes (so one across +-180 goes beyond 180).
std::vector<LonLat> island(CoastGen &g, const Vec3 &centre, double r_km) {
    const int n = 3 + g.pick(4);
    Vec3 east = cross(Vec3{0, 0, 1}, centre);
    east = norm(east) > 1e-6 ? normalized(east) : Vec3{0, 1, 0};
    const Vec3 start = rotate(centre, east, km_to_rad(r_km));
    const double phase = g.uniform(0, 2 * pi);
    const LonLat c = vec_to_lonlat(centre);
    std::vector<LonLat> out;
    for (int i = 0; i < n; ++i) {
        const double t = phase + 2 * pi * i / n + g.uniform(-0.2, 0.2) * 2 * pi / n;
        LonLat p = vec_to_lonlat(
            rotate(start, centre, -t)); // clockwise: GeoJSON outer rings are CCW, either works
        while (p.lon - c.lon > 180)
            p.lon -= 360;
        while (p.lon - c.lon < -180)
            p.lon += 360;
        out.push_back(p);
    }
    return out;
}

/// Face areas (steradians) and a point-in-mesh test by brute force over the faces.
double mesh_area(const Mesh &m) {
    double a = 0;
    for (const auto &f : m.faces)
        a += spherical_triangle_area(m.nodes[f[0]], m.nodes[f[1]], m.nodes[f[2]]);
    return a;
}

bool in_mesh(const Mesh &m, const Vec3 &p) {
    for (const auto &f : m.faces) {
        const Vec3 &a = m.nodes[f[0]], &b = m.nodes[f[1]], &c = m.nodes[f[2]];
        if (predicates::orient(a, b, p) >= 0 && predicates::orient(b, c, p) >= 0 &&
            predicates::orient(c, a, p) >= 0)
            return true;
    }
    return false;
}

Mesh mesh_islands(const std::vector<std::vector<LonLat>> &islands, const std::string &name,
                  double h) {
    std::vector<std::string> geometries;
    for (const auto &r : islands)
        geometries.push_back("{\"type\":\"Polygon\",\"coordinates\":[" + ring_json(r) + "]}");
    MemFile file(name, feature_collection(geometries));
    MeshOptions options;
    options.coast = file.path();
    options.keep_inland_seas = true;
    options.min_island_triangles = 0;
    const SizeFn size = [h](const Vec3 &) { return h; };
    const CoastData coast = load_coast(options);
    const Boundary boundary = shape_boundary(coast, size, options);
    MesherOptions mo;
    mo.keep_inland_seas = true;
    mo.max_nodes = 20000;
    mo.lattice_km = h;
    RunawayGuard guard;
    try {
        return mesh_boundary(boundary, size, mo, nullptr, guard.progress());
    } catch (const Cancelled &) {
        if (!known_runaway || !guard.tripped)
            throw;
        return Mesh{}; // known runaway: an empty mesh, skipped by the caller
    } catch (const DataError &e) {
        // Known mesher bug: a node estimate near 2^64 (a negative or NaN area cast to an
        // unsigned count) on some of these well-formed inputs; skipped while known_runaway.
        if (!known_runaway ||
            std::string(e.what()).find("asks for about 1844674407370955161") == std::string::npos)
            throw;
        return Mesh{};
    }
}

} // namespace

// Islands are well separated (no two shaped rings interact) and coarse (every corner deviates from
// its neighbours' arc by more than the simplification tolerance h/2), so each island is shaped
// the same whether or not the others are present: the property then holds exactly.
TEST(CoastProperty, removing_land_never_removes_ocean) {
    const double h = 800;
    int compared = 0;
    for (std::uint64_t seed = 1; seed <= 12; ++seed) {
        CoastGen g(seed * 7919);
        std::vector<Vec3> centres;
        std::vector<double> radii;
        const int want = 2 + g.pick(4);
        for (int tries = 0; tries < 200 && static_cast<int>(centres.size()) < want; ++tries) {
            Vec3 c = normalized(Vec3{g.uniform(-1, 1), g.uniform(-1, 1), g.uniform(-1, 1)});
            if (tries % 4 == 0)
                c = lonlat_to_vec(180 + g.uniform(-5, 5), g.uniform(-60, 60)); // across +-180
            if (std::fabs(vec_to_lonlat(c).lat) > 70)
                continue; // keep rings off the poles
            const double r = g.uniform(1200, 2000);
            bool apart = true;
            for (std::size_t i = 0; i < centres.size(); ++i)
                apart = apart && arc_km(c, centres[i]) > r + radii[i] + 3 * h;
            if (!apart)
                continue;
            centres.push_back(c);
            radii.push_back(r);
        }
        ASSERT_GE(centres.size(), 2u);
        std::vector<std::vector<LonLat>> all, subset;
        for (std::size_t i = 0; i < centres.size(); ++i) {
            all.push_back(island(g, centres[i], radii[i]));
            if (i % 2 == 0)
                subset.push_back(all.back()); // drop every other island
        }
        const Mesh with_all = mesh_islands(all, "land_all.geojson", h);
        const Mesh with_subset = mesh_islands(subset, "land_subset.geojson", h);
        if (with_all.faces.empty() || with_subset.faces.empty())
            continue; // the known runaway
        if (known_mesher_issue(mesh_problem(with_all)) ||
            known_mesher_issue(mesh_problem(with_subset)))
            continue;
        ASSERT_TRUE(mesh_problem(with_all).empty()) << mesh_problem(with_all);
        ASSERT_TRUE(mesh_problem(with_subset).empty()) << mesh_problem(with_subset);
        const double ocean_all = mesh_area(with_all), ocean_subset = mesh_area(with_subset);
        EXPECT_GT(ocean_subset, ocean_all + 1e-3)
            << "seed " << seed << ": dropping islands must add their area";
        for (const auto &f : with_all.faces) {
            const Vec3 centroid =
                normalized(with_all.nodes[f[0]] + with_all.nodes[f[1]] + with_all.nodes[f[2]]);
            ASSERT_TRUE(in_mesh(with_subset, centroid))
                << "seed " << seed << ": an ocean point of L is land for L'";
        }
        ++compared;
    }
    EXPECT_EQ(compared, 12);
}

// Found by tests/fuzz/fuzz_coast: an open coastline LineString drawn in [0, 360) longitudes
// (ends at lon 199.42 and 199.02, 0.28 degree apart) had both ends "snapped to the seam" because
// the test was |lon| > 180 - 0.001 rather than within 0.001 of 180, which made a 19-degree sliver
// from lon 180 instead of closing the 0.5-degree gap. Fixed in src/coast/coast_load.cpp. Oracle:
// the land is the small triangle of the three vertices wrapped by -360 degrees.
TEST(CoastProperty, open_line_beyond_180_is_closed_straight_and_wrapped_not_snapped_to_the_seam) {
    MemFile file(
        "line_beyond_180.geojson",
        feature_collection(
            {"{\"type\":\"LineString\",\"coordinates\":[[199.42414141170187,-61.174619759458437],"
             "[199.01804536377966,-61.03394396190761],[199.01804536377966,-61.315295557009264]]"
             "}"}));
    MeshOptions options;
    options.coast = file.path();
    const CoastData coast = load_coast(options);
    ASSERT_EQ(coast.rings.rings.size(), 1u);
    for (const Vec3 &p : coast.rings.rings[0].nodes) {
        const LonLat ll = vec_to_lonlat(p);
        EXPECT_GE(ll.lon, 199.018 - 360 - 1e-6);
        EXPECT_LE(ll.lon, 199.425 - 360 + 1e-6);
        EXPECT_GE(ll.lat, -61.3153 - 1e-6);
        EXPECT_LE(ll.lat, -61.0339 + 1e-6);
    }
}

// Found by CoastProperty.removing_land_never_removes_ocean: a pentagon drawn across -180 with
// longitudes down to -187. Cut at the seam by GEOS twice (at -180, and at 180 after the shift by
// 360), the two copies of the crossing point differed in the last bit of the latitude, so the
// ring kept both: a zero-length arc, and load_coast threw "arcs touch or cross near lon -180".
// Fixed in src/coast/coast_load.cpp (nodes within 1e-14 rad are one node).
TEST(CoastProperty, polygon_drawn_beyond_minus_180_loads_as_one_valid_ring) {
    MemFile file(
        "across_minus_180.geojson",
        feature_collection(
            {"{\"type\":\"Polygon\",\"coordinates\":[[[-187.21262198602386,-29.016806345768277],"
             "[-184.14129885994811,-14.332982699626257],[-170.64670328804749,-13.633267588865795],"
             "[-165.2654724928764,-26.393610156719895],[-173.06917779321259,-33.552562075457594],"
             "[-187.21262198602386,-29.016806345768277]]]}"}));
    MeshOptions options;
    options.coast = file.path();
    const CoastData coast = load_coast(options);
    EXPECT_TRUE(check_boundary(coast.rings).empty());
    ASSERT_EQ(coast.rings.rings.size(), 1u);
    for (const Vec3 &p : coast.rings.rings[0].nodes) {
        const LonLat ll = vec_to_lonlat(p);
        EXPECT_TRUE(ll.lon >= -187.2127 + 360 - 1e-6 || ll.lon <= -165.2654) << ll.lon;
        EXPECT_GE(ll.lat, -33.5526);
        EXPECT_LE(ll.lat, -13.6332);
    }
}

// Found by tests/fuzz/fuzz_coast (before the coast fix of line ends beyond +-180 it built this
// boundary from an open LineString at lon 199): a valid 6-node ring (check_boundary is empty), a
// sliver 19 degrees long and 0.3 degree wide at lat -61 touching lon 180. mesh_boundary at a
// uniform 400 km returns a clockwise face with the mesher at 9bc775c, and did not return at all
// (refinement going round consider_star) with the lead's work in progress at the time
// (src/mesher/mesher.cpp). Fixed there; kept so that it stays fixed.
TEST(MesherProperty, sliver_ring_at_lat_minus_61_meshes_in_bounded_time) {
    Ring ring;
    ring.nodes = {{-0x1.edb694b4fe40bp-2, 0x0p+0, -0x1.c08f4971e5fb1p-1},
                  {-0x1.e91b104b07eaep-2, -0x1.b35b0396f29a5p-5, -0x1.c0ff02ca5174ep-1},
                  {-0x1.e31b49fa2efdp-2, -0x1.b2bc75f2a537ap-4, -0x1.c027b155317ap-1},
                  {-0x1.d4d86ac4eb47fp-2, -0x1.433404c380178p-3, -0x1.bff3c7c3781dbp-1},
                  {-0x1.e264093b3e16p-2, -0x1.b2178e47a9a38p-4, -0x1.c05b873ac2eecp-1},
                  {-0x1.e8bf02c9b15d4p-2, -0x1.b2b59c6f65187p-5, -0x1.c118b19e57a92p-1}};
    ring.kinds.assign(ring.nodes.size(), SegmentKind::coast);
    Boundary b;
    b.rings.push_back(ring);
    const auto issues = check_boundary(b);
    ASSERT_TRUE(issues.empty()) << issues.front().what << " ring " << issues.front().ring
                                << " segment " << issues.front().segment;
    MesherOptions mo;
    mo.max_nodes = 20000;
    const Mesh mesh = mesh_boundary(
        b, [](const Vec3 &) { return 400.0; }, mo);
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
}

// Found by CoastProperty.removing_land_never_removes_ocean: the shaped ring of a hexagon drawn
// across -180 (9 nodes, one on the seam), meshed at a uniform 800 km with keep_inland_seas.
// mesh_boundary at 9bc775c returns one clockwise face near lon -170, lat 5 (area -0.0013 sr);
// the same ring rotated 7 degrees about the polar axis makes refinement run away (2.1 GB in 47 s,
// then std::bad_alloc). Both fixed in src/mesher; kept so that they stay fixed.
namespace {
Boundary nine_node_island(double rotate_deg) {
    Ring ring;
    ring.nodes = {{-0x1.fccd3da46bdf6p-1, 0x0p+0, -0x1.c91ba4648188ap-4},
                  {-0x1.fc9594f6b41bdp-1, 0x1.bb7ac8a60740ep-4, -0x1.4525adcfd9dfcp-5},
                  {-0x1.f50f4b0c4e3efp-1, 0x1.7a2c6f295bbc5p-3, 0x1.727c66f336258p-4},
                  {-0x1.f497cf806cd7ep-1, 0x1.0abd535d8cb75p-3, 0x1.5122a4629d889p-3},
                  {-0x1.ee7071000a706p-1, 0x1.0f89c0ae0aa69p-4, 0x1.0112f9d32b7eep-2},
                  {-0x1.f0ae85da0a446p-1, -0x1.28ecd5dc59167p-4, 0x1.da87c233207e2p-3},
                  {-0x1.f1cdd7cca0b3dp-1, -0x1.6203d8ded32e9p-3, 0x1.428b6b207baa7p-3},
                  {-0x1.f83933abddd62p-1, -0x1.5f7513e59f37fp-3, 0x1.b06312ea8a853p-6},
                  {-0x1.fab400d5826a6p-1, -0x1.73084911f76c4p-4, -0x1.c7b6941807dap-4}};
    const double t = rotate_deg * deg_to_rad;
    for (Vec3 &p : ring.nodes)
        p = Vec3{std::cos(t) * p.x - std::sin(t) * p.y, std::sin(t) * p.x + std::cos(t) * p.y, p.z};
    ring.kinds.assign(ring.nodes.size(), SegmentKind::coast);
    Boundary b;
    b.rings.push_back(ring);
    return b;
}
} // namespace

TEST(MesherProperty, nine_node_island_across_180_meshes_counter_clockwise) {
    const Boundary b = nine_node_island(0);
    ASSERT_TRUE(check_boundary(b).empty());
    MesherOptions mo;
    mo.keep_inland_seas = true;
    const Mesh mesh = mesh_boundary(
        b, [](const Vec3 &) { return 800.0; }, mo);
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
}

TEST(MesherProperty, nine_node_island_rotated_7_degrees_meshes_in_bounded_memory) {
    const Boundary b = nine_node_island(7);
    ASSERT_TRUE(check_boundary(b).empty());
    MesherOptions mo;
    mo.keep_inland_seas = true;
    mo.max_nodes = 20000;
    std::size_t calls = 0;
    // Refinement reports progress every 16384 insertions: 40 reports are 650000 nodes, 30 times
    // the estimate for this boundary. Cancel there rather than exhaust the machine's memory.
    const Progress stop = [&calls](double, std::string_view stage) {
        return stage != "refine" || ++calls < 40;
    };
    Mesh mesh;
    ASSERT_NO_THROW(mesh = mesh_boundary(
                        b, [](const Vec3 &) { return 800.0; }, mo, nullptr, stop));
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
    EXPECT_LT(mesh.nodes.size(), 2000u);
}

// Found by tests/fuzz/fuzz_delaunay: ten points in a cluster 1e-8 rad wide plus (0, 1, 0) (so a
// hull with ghost triangles); moving the vertex of point 0 by 2e-12 rad left 3 unconstrained
// edges not locally Delaunay although move_vertex promises to restore the property by flips:
// at the new position the vertex lies inside the hull of its neighbours (their spacing is
// below what rounding to the sphere resolves), and the flips it needs have non-convex
// quadrilaterals. Fixed in src/delaunay: such a move is undone (every flip) and refused.
TEST(DelaunayProperty, move_vertex_in_a_tiny_cluster_keeps_every_edge_delaunay) {
    const std::vector<Vec3> pts{
        {0x1.11fba5b721a52p-1, 0x1.7e082b3bf67fdp-1, -0x1.959afc23beadap-2},
        {0x1.11fba5b721a55p-1, 0x1.7e082b3bf67fdp-1, -0x1.959afc23bead8p-2},
        {0x1.11fba5c0d7b1fp-1, 0x1.7e082b3cf4ff4p-1, -0x1.959afc05c2a0cp-2},
        {0x1.11fba5b721a52p-1, 0x1.7e082b3bf67fdp-1, -0x1.959afc23beadap-2},
        {0x1.11fba59d7292bp-1, 0x1.7e082b4d16346p-1, -0x1.959afc28a096dp-2},
        {0x1.11fba5b721a52p-1, 0x1.7e082b3bf67ffp-1, -0x1.959afc23bead8p-2},
        {0x0p+0, 0x1p+0, 0x0p+0},
        {0x1.11fba5bed0265p-1, 0x1.7e082b36b66e2p-1, -0x1.959afc22c50f6p-2},
        {0x1.11fba5b5f87eep-1, 0x1.7e082b41e1185p-1, -0x1.959afc10974a3p-2},
        {0x1.11fba5b8ffb1dp-1, 0x1.7e082b41b5638p-1, -0x1.959afc090d64ep-2}};
    const Vec3 to{0x1.11fba5b722f5cp-1, 0x1.7e082b3bf67ep-1, -0x1.959afc23bb26cp-2};
    // Every insertion order (the failure did not depend on it), every vertex moved to `to`.
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        SphericalDelaunay::Options o;
        o.seed = seed;
        SphericalDelaunay d(o);
        const auto map = d.insert_points(std::span<const Vec3>(pts));
        ASSERT_TRUE(d.validate().empty());
        for (std::size_t i = 0; i < pts.size(); ++i) {
            SphericalDelaunay e = d;
            const VertexId v = map[i];
            const Vec3 before = e.point(v);
            const std::size_t triangles = e.triangle_count();
            const bool moved = e.move_vertex(v, to);
            EXPECT_TRUE(moved ? e.point(v) == to : e.point(v) == before)
                << "seed " << seed << " point " << i;
            EXPECT_EQ(e.triangle_count(), triangles);
            const auto problems = e.validate();
            EXPECT_TRUE(problems.empty())
                << "seed " << seed << " point " << i << ": " << problems.front();
            if (!moved) { // refused: every triangle as it was
                for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
                    ASSERT_EQ(e.is_live(t), d.is_live(t));
                    if (!d.is_live(t))
                        continue;
                    for (int k = 0; k < 3; ++k) {
                        ASSERT_EQ(e.vertex(t, k), d.vertex(t, k));
                        ASSERT_EQ(e.twin(half_edge(t, k)), d.twin(half_edge(t, k)));
                    }
                }
            }
        }
    }
}

// Found by tests/fuzz/fuzz_delaunay (finding 7ce1c8e5): five distinct points that lie in one
// hemisphere (the south pole S, and C, C' 1 ulp apart near the north pole), so the hull has ghost
// triangles, three of them around S. Moving S by 0.09 rad turned those three solid, so the hull
// now held the origin, but the ghost (C', C, A) away from S stayed: a clockwise triangle in a
// hull around the origin (and C' left with two triangles, a flat pillow). Flips around S cannot
// reach it. Fixed in src/delaunay: move_vertex refuses a move whose star holds a ghost triangle.
TEST(DelaunayProperty, move_vertex_out_of_ghost_triangles_never_folds_the_hull) {
    const std::vector<Vec3> pts{
        {0x1.5db3d742c2655p-1, 0x1.5db3d742c2656p-1, 0x1.0907dc193069p-2},
        {0x0p+0, 0x0p+0, -0x1p+0},
        {-0x1.e46cf4030bfdfp-2, -0x1.28d7fe19827b2p-8, 0x1.c31407c3ab563p-1},
        {-0x1.93916ca738b0dp-7, 0x1.3e44de35261afp-12, 0x1.fff60d8ed9a6cp-1},
        {-0x1.93916ca738b0ep-7, 0x1.3e44de35261aep-12, 0x1.fff60d8ed9a6bp-1}};
    const Vec3 to{0x1.725d42a841345p-4, 0x0p+0, -0x1.fde714c2de1a2p-1};
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        SphericalDelaunay::Options o;
        o.seed = seed;
        SphericalDelaunay d(o);
        const auto map = d.insert_points(std::span<const Vec3>(pts));
        ASSERT_TRUE(d.validate().empty());
        const bool moved = d.move_vertex(map[1], to);
        EXPECT_TRUE(moved ? d.point(map[1]) == to : d.point(map[1]) == pts[1]);
        const auto problems = d.validate();
        EXPECT_TRUE(problems.empty()) << "seed " << seed << ": " << problems.front();
    }
}

// Found by tests/fuzz/fuzz_delaunay (after 219000 executions): twelve points within 1e-5 rad of
// the south pole (several exactly on it or ulps from it, most on the meridian plane y = 0) and
// two near (0, 1, 0). An input point was mapped to a vertex 1e-6 rad away, beyond both merge
// distances the header states: an exact duplicate of an earlier point, whose walk stopped on a
// flat triangle of the meridian (every orientation 0) far from its twin; no face sees a duplicate,
// so it was merged into the nearest vertex of that flat triangle. Fixed in src/delaunay: merged
// into its nearest vertex, found by greedy descent from there. The insertion order of the
// failure changed with the BRIO keys of cd45ae4, so shuffled orders and one-by-one insert() too.
TEST(DelaunayProperty, points_near_the_south_pole_merge_only_into_near_vertices) {
    const std::vector<Vec3> pts{
        {-0x1.8bd7366f31c64p-39, 0x0p+0, -0x1p+0},
        {0x0p+0, 0x0p+0, -0x1p+0},
        {-0x1.f6a7a2f9da303p-20, 0x0p+0, -0x1.fffffffffc251p-1},
        {-0x1.0c6f9bad73b9ep-20, 0x1.70f33c4e64ad7p-30, -0x1.fffffffffee6ap-1},
        {-0x1.0c6f8adc689d3p-19, 0x1.70f3409fbd611p-30, -0x1.fffffffffb9a3p-1},
        {-0x1.0c5ec5635e0ep-20, 0x0p+0, -0x1.fffffffffee6bp-1},
        {-0x1.3a28c59d5433bp-34, 0x0p+0, -0x1p+0},
        {0x0p+0, 0x0p+0, -0x1p+0},
        {-0x1.6e6127ff9d971p-47, 0x0p+0, -0x1p+0},
        {-0x1.0c5ec5635e0ep-20, 0x0p+0, -0x1.fffffffffee6bp-1},
        {0x1.1a62633145c07p-54, 0x1p+0, 0x0p+0},
        {-0x1.bb3e01f5ad6d1p-44, 0x1p+0, 0x1.38d1165e73437p-46}};
    std::mt19937_64 rng(5);
    for (int run = 0; run < 400; ++run) {
        std::vector<Vec3> p = pts;
        std::shuffle(p.begin(), p.end(), rng);
        SphericalDelaunay d;
        std::vector<VertexId> map;
        if (run % 2 == 0) {
            map = d.insert_points(std::span<const Vec3>(p));
        } else {
            // The shortest prefix spanning a tetrahedron by insert_points, the rest one by one.
            std::size_t prefix = 4;
            for (; prefix <= p.size(); ++prefix) {
                SphericalDelaunay probe;
                try {
                    probe.insert_points(std::span<const Vec3>(p.data(), prefix));
                    break;
                } catch (const DataError &) {
                }
            }
            ASSERT_LE(prefix, p.size());
            map = d.insert_points(std::span<const Vec3>(p.data(), prefix));
            for (std::size_t i = prefix; i < p.size(); ++i)
                map.push_back(d.insert(p[i], d.last_triangle()));
        }
        const auto problems = d.validate();
        ASSERT_TRUE(problems.empty()) << "run " << run << ": " << problems.front();
        std::set<VertexId> used;
        for (TriangleId t = 0; t < d.triangle_slots(); ++t)
            if (d.is_live(t))
                for (int k = 0; k < 3; ++k)
                    used.insert(d.vertex(t, k));
        for (std::size_t i = 0; i < p.size(); ++i) {
            ASSERT_LE(arc_angle(d.point(map[i]), p[i]), 1e-7)
                << "run " << run << " point " << i << " -> vertex " << map[i];
            ASSERT_TRUE(used.count(map[i])) << "run " << run << " point " << i;
        }
    }
}

// Found by CoastProperty.hundreds_of_hostile_small_coasts_mesh_validly_or_raise_a_clean_error,
// seed 32: a polar cap closed through the north pole at lat 76-77, and a polygon at lat -70
// whose hole has a vertex at lon -180.00000000000014, keep_inland_seas, h = 1576 km. The coast
// stages pass (check_boundary is empty) but mesh_boundary at 9bc775c never returns, and its
// refinement loop reported no progress, so it could not be cancelled. Fixed in src/mesher; kept
// so that it stays fixed (a return of the hang shows as this test's ctest timeout).
TEST(MesherProperty, hostile_coast_seed_32_meshes_in_bounded_time) {
    CoastCase c = coast_case(32);
    MemFile file("seed32.geojson", c.json);
    c.options.coast = file.path();
    const SizeFn size = [h = c.h](const Vec3 &) { return h; };
    const Boundary boundary = shape_boundary(load_coast(c.options), size, c.options);
    ASSERT_TRUE(check_boundary(boundary).empty());
    MesherOptions mo;
    mo.keep_inland_seas = c.options.keep_inland_seas;
    mo.max_nodes = 20000;
    mo.lattice_km = c.h;
    const Mesh mesh = mesh_boundary(boundary, size, mo);
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
}

namespace {
/// Meshes case c from its GeoJSON (a file named `name`) with the coast's land, its straits
/// closed whatever the case asks; its shaped boundary must be valid. `as_made`: without the
/// closings that came after the case was made (dead ends, pieces apart), which close its water,
/// and without the merge of close coast nodes once the inlets close, which reshapes its coast.
void mesh_with_land(CoastCase c, const std::string &name, Mesh &mesh, MesherReport &report,
                    bool as_made = false) {
    MemFile file(name, c.json);
    c.options.coast = file.path();
    const SizeFn size = [h = c.h](const Vec3 &) { return h; };
    const CoastData coast = load_coast(c.options);
    const Boundary boundary = shape_boundary(coast, size, c.options);
    ASSERT_TRUE(check_boundary(boundary).empty());
    MesherOptions mo;
    mo.keep_inland_seas = c.options.keep_inland_seas;
    mo.land = coast.land;
    mo.max_nodes = 20000;
    mo.lattice_km = c.h;
    mo.close_dead_ends = !as_made;
    mo.close_pieces_apart = !as_made;
    if (as_made)
        mo.close_node_gap = 0;
    mesh = mesh_boundary(boundary, size, mo, &report);
}
} // namespace

// Found by CoastProperty.hundreds_of_hostile_small_coasts... once it closed straits (seed 192):
// a strait closed at a node next to the south pole whose fan held a sliver 0.04 m2 in area;
// moving the node's copy 0.64 m into its fan turned the sliver clockwise. The copy now moves
// at most as far as keeps every face of its fan counter-clockwise. (The closings of dead ends
// and of pieces apart close the water beside that node: it is meshed as it was made, without.)
// With the rings in their canonical order seed 192 splits no node: seeds 8, 10 and 11 do.
TEST(MesherProperty, a_node_split_at_a_closed_strait_keeps_its_fan_counter_clockwise) {
    std::size_t split = 0;
    for (const std::uint64_t seed : {192u, 8u, 10u, 11u}) {
        Mesh mesh;
        MesherReport report;
        ASSERT_NO_FATAL_FAILURE(
            mesh_with_land(coast_case(seed), "seed.geojson", mesh, report, true));
        split += report.nodes_split;
        EXPECT_TRUE(mesh_problem(mesh).empty()) << "seed " << seed << ": " << mesh_problem(mesh);
    }
    EXPECT_GE(split, 3u);
}

// Found by CoastProperty.hundreds_of_hostile_small_coasts... in the clang sanitizer build (its
// seed 41 then: clang drew the generator's unsequenced arguments in another order than g++): a
// coast through the north pole, straits closed at three nodes within 0.2 m of the pole, corners
// of one face; each copy moved into its fan as if the others stayed, and the face between the
// copies turned clockwise. A copy's fan is now checked with the corners already moved where they
// went. (Meshed as it was made: the closing of pieces apart closes the fans at those nodes.)
TEST(MesherProperty, nodes_split_side_by_side_at_a_pole_keep_their_faces_counter_clockwise) {
    CoastCase c;
    c.json =
        R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"t)"
        R"(ype":"LineString","coordinates":[[171.986078143957,-90],[171.98050870684705,90],[171.978)"
        R"(09419417982,56.027348029953473],[-180,56.025244341716281],[180,56.033175655641692],[-180)"
        R"(,56.03131364688933],[171.98031984724449,-90],[171.986078143957,-90]]}},{"type":"Feature")"
        R"(,"properties":{},"geometry":{"type":"MultiPolygon","coordinates":[[[[182.27090131584379,)"
        R"(-76.988311009098638],[174.71689608536525,-78.511685895720547],[180,-74.273213736334355],)"
        R"([179.14491813760446,-79.11787705904149],[175.37423738740338,90],[182.27090131584379,-76.)"
        R"(988311009098638]]],[[[-138.81643394813884,-66.766967505520313],[-139.27203578768194,-67.)"
        R"(108859853758887],[-139.27203578768194,-67.108859853758887],[-139.27203578768194,-66.4743)"
        R"(87925450415],[-138.81643394813884,-66.766967505520313]]]]}}]})";
    c.h = 829.1673975464621;
    c.options.keep_inland_seas = true;
    c.options.min_island_triangles = 2;
    Mesh mesh;
    MesherReport report;
    ASSERT_NO_FATAL_FAILURE(mesh_with_land(c, "pole_pinches.geojson", mesh, report, true));
    EXPECT_GE(report.nodes_split, 3u);
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
}

// Found by tests/fuzz/fuzz_coast (UBSan, 7 inputs in 10 minutes): a closed coastline LineString
// (60.98, -8.86) -> (-138.54, -90) -> (-88.66, 77.53), a land triangle larger than a hemisphere,
// at a uniform 400 km. The ocean triangles' areas add up to a negative node estimate (-431),
// which src/mesher/mesher.cpp (line 251 at 9bc775c) casts to std::size_t: undefined behaviour,
// and without UBSan "the size field asks for about 18446744073709551615 nodes". Fixed in
// src/mesher; kept so that it stays fixed.
TEST(MesherProperty, land_triangle_larger_than_a_hemisphere_meshes_or_is_refused_clearly) {
    MemFile file(
        "big_triangle.geojson",
        feature_collection(
            {"{\"type\":\"LineString\",\"coordinates\":[[60.983829486990587,-8.8619760051369667],"
             "[-138.53512844803578,-90],[-88.655388964279055,77.532267049028874],"
             "[60.983829486990587,-8.8619760051369667]]}"}));
    MeshOptions options;
    options.coast = file.path();
    options.min_island_triangles = 0;
    const SizeFn size = [](const Vec3 &) { return 400.0; };
    const Boundary boundary = shape_boundary(load_coast(options), size, options);
    ASSERT_TRUE(check_boundary(boundary).empty());
    MesherReport report;
    const Mesh mesh = mesh_boundary(boundary, size, {}, &report);
    EXPECT_LT(report.estimated_nodes, 10'000'000u);
    EXPECT_TRUE(mesh_problem(mesh).empty()) << mesh_problem(mesh);
}
