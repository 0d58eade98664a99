// Tests of the spherical Delaunay core. Oracles are independent of the implementation:
// Euler's formula, spherical areas adding up to 4 pi, a brute-force empty-circumcircle check
// in plain long double on small sets, and invariance of the triangle set under input shuffling
// (the Delaunay triangulation of a perturbed point set is unique).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

using namespace globemesh;

namespace {

std::vector<Vec3> random_points(std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> z(-1, 1), lon(-180, 180);
    std::vector<Vec3> p(n);
    for (auto &v : p)
        v = lonlat_to_vec(lon(rng), std::asin(z(rng)) * rad_to_deg);
    return p;
}

std::vector<Vec3> grid_points(double step_deg) {
    std::vector<Vec3> p;
    for (double lat = -90; lat <= 90; lat += step_deg)
        for (double lon = -180; lon < 180; lon += step_deg)
            p.push_back(lonlat_to_vec(lon, lat));
    return p; // the poles appear once per longitude: duplicates the core must merge
}

using Tri = std::array<std::array<double, 3>, 3>;

// Triangles as coordinate triples, rotated to start at the lexicographically smallest corner,
// sorted: two triangulations of the same points are equal iff these lists are.
std::vector<Tri> canonical(const SphericalDelaunay &dt, bool solid_only) {
    std::vector<Tri> out;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || (solid_only && !dt.is_solid(t)))
            continue;
        Tri tri;
        for (int i = 0; i < 3; ++i) {
            const Vec3 &p = dt.point(dt.vertex(t, i));
            tri[i] = {p.x, p.y, p.z};
        }
        auto m = std::min_element(tri.begin(), tri.end()) - tri.begin();
        std::rotate(tri.begin(), tri.begin() + m, tri.end());
        out.push_back(tri);
    }
    std::sort(out.begin(), out.end());
    return out;
}

double solid_area(const SphericalDelaunay &dt) {
    double a = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.is_solid(t))
            a += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                         dt.point(dt.vertex(t, 2)));
    return a;
}

// Brute force, independent of the predicates: no vertex strictly inside any solid triangle's
// circumcircle by more than `slack` in the plane-distance sense (long double).
// Vertices marked in `skip` (removed ones) are not tested.
std::size_t brute_force_violations(const SphericalDelaunay &dt, long double slack,
                                   const std::vector<std::uint8_t> &skip = {}) {
    std::size_t bad = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || !dt.is_solid(t))
            continue;
        const Vec3 &a = dt.point(dt.vertex(t, 0)), &b = dt.point(dt.vertex(t, 1)),
                   &c = dt.point(dt.vertex(t, 2));
        long double nx =
            (long double)(b.y - a.y) * (c.z - a.z) - (long double)(b.z - a.z) * (c.y - a.y);
        long double ny =
            (long double)(b.z - a.z) * (c.x - a.x) - (long double)(b.x - a.x) * (c.z - a.z);
        long double nz =
            (long double)(b.x - a.x) * (c.y - a.y) - (long double)(b.y - a.y) * (c.x - a.x);
        long double len = std::sqrt(nx * nx + ny * ny + nz * nz);
        for (VertexId v = 0; v < dt.vertex_count(); ++v) {
            if (v < skip.size() && skip[v])
                continue;
            const Vec3 &d = dt.point(v);
            long double h = ((d.x - a.x) * nx + (d.y - a.y) * ny + (d.z - a.z) * nz) / len;
            if (h > slack)
                ++bad;
        }
    }
    return bad;
}

std::size_t euler(const SphericalDelaunay &dt) {
    std::set<VertexId> used;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t))
            for (int i = 0; i < 3; ++i)
                used.insert(dt.vertex(t, i));
    std::size_t f = dt.triangle_count();
    return used.size() - 3 * f / 2 + f;
}

void expect_valid_closed(const SphericalDelaunay &dt) {
    auto problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    EXPECT_EQ(euler(dt), 2u);
}

} // namespace

TEST(Delaunay, octahedron_vertices_give_eight_triangles) {
    std::vector<Vec3> p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.triangle_count(), 8u);
    EXPECT_NEAR(solid_area(dt), 4 * pi, 1e-12);
    // Every quadruple of octahedron vertices around a face pair is cocircular: any order gives
    // the same triangulation through the perturbation.
    std::vector<Vec3> q(p.rbegin(), p.rend());
    SphericalDelaunay dt2;
    dt2.insert_points(q);
    EXPECT_EQ(canonical(dt, false), canonical(dt2, false));
}

TEST(Delaunay, release_points_hands_over_the_vertices_and_empties_the_triangulation) {
    std::vector<Vec3> p = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    SphericalDelaunay dt;
    const std::vector<VertexId> ids = dt.insert_points(p);
    const std::vector<Vec3> released = dt.release_points();
    ASSERT_EQ(released.size(), p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        EXPECT_EQ(released[ids[i]], p[i]);
    EXPECT_EQ(dt.vertex_count(), 0u);
    EXPECT_EQ(dt.triangle_slots(), 0u);
    // Empty, not broken: it triangulates again.
    dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.triangle_count(), 8u);
}

TEST(Delaunay, random_points_1e5_are_valid_and_cover_the_sphere) {
    auto p = random_points(100000, 1);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.vertex_count(), 100000u);
    EXPECT_EQ(dt.triangle_count(), 2 * 100000u - 4);
    EXPECT_NEAR(solid_area(dt), 4 * pi, 1e-9);
    for (std::size_t i = 0; i < p.size(); ++i)
        ASSERT_EQ(dt.point(ids[i]), p[i]);
}

TEST(Delaunay, brute_force_empty_circumcircles_on_2000_random_points) {
    auto p = random_points(2000, 7);
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(brute_force_violations(dt, 1e-15L), 0u);
}

TEST(Delaunay, shuffled_input_gives_the_same_triangulation) {
    auto p = random_points(20000, 3);
    SphericalDelaunay a;
    a.insert_points(p);
    std::mt19937_64 rng(99);
    std::shuffle(p.begin(), p.end(), rng);
    SphericalDelaunay b(SphericalDelaunay::Options{1e-12, 12345});
    b.insert_points(p);
    EXPECT_EQ(canonical(a, false), canonical(b, false));
}

TEST(Delaunay, reserved_room_holds_the_points_added_one_by_one_without_moving_them) {
    // The mesher reserves for the nodes it expects before the refinement adds them one at a
    // time: the points must stay where they are (no regrowth) and the triangulation be the one
    // made without the reservation.
    const auto p = random_points(5000, 11);
    const std::span<const Vec3> first(p.data(), 100);
    SphericalDelaunay plain, reserved;
    plain.insert_points(first);
    reserved.insert_points(first);
    reserved.reserve(p.size());
    const Vec3 *storage = reserved.points().data();
    for (std::size_t i = first.size(); i < p.size(); ++i) {
        plain.insert(p[i], plain.last_triangle());
        reserved.insert(p[i], reserved.last_triangle());
    }
    EXPECT_EQ(reserved.points().data(), storage);
    EXPECT_EQ(reserved.vertex_count(), p.size());
    expect_valid_closed(reserved);
    EXPECT_EQ(canonical(plain, false), canonical(reserved, false));
}

TEST(Delaunay, one_degree_grid_with_both_poles_is_valid_and_order_independent) {
    auto p = grid_points(1.0);
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    // 360 x 179 distinct points plus 2 poles; the 718 other pole copies are merged.
    EXPECT_EQ(dt.vertex_count(), 360u * 179u + 2u);
    EXPECT_EQ(dt.merged_count(), 2u * 359u);
    EXPECT_NEAR(solid_area(dt), 4 * pi, 1e-9);
    std::reverse(p.begin(), p.end());
    SphericalDelaunay dt2(SphericalDelaunay::Options{1e-12, 77});
    dt2.insert_points(p);
    EXPECT_EQ(canonical(dt, false), canonical(dt2, false));
}

TEST(Delaunay, great_circle_plus_two_poles) {
    std::vector<Vec3> p;
    for (int i = 0; i < 360; ++i)
        p.push_back(lonlat_to_vec(i, 0));
    p.push_back({0, 0, 1});
    p.push_back({0, 0, -1});
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.triangle_count(), 720u); // a fan from each pole to every equator edge
    EXPECT_NEAR(solid_area(dt), 4 * pi, 1e-9);
    std::vector<Vec3> q(p.rbegin(), p.rend());
    SphericalDelaunay dt2;
    dt2.insert_points(q);
    EXPECT_EQ(canonical(dt, false), canonical(dt2, false));
}

TEST(Delaunay, clustered_points_ninety_percent_in_a_one_degree_cap) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    auto p = random_points(5000, 11);
    Vec3 c = lonlat_to_vec(-30, 45);
    for (int i = 0; i < 45000; ++i) {
        double r = 0.5 * std::sqrt(u(rng)), az = 360 * u(rng);
        p.push_back(lonlat_to_vec(-30 + r * std::cos(az * deg_to_rad) / std::cos(45 * deg_to_rad),
                                  45 + r * std::sin(az * deg_to_rad)));
    }
    (void)c;
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.vertex_count() + dt.merged_count(), p.size());
    EXPECT_NEAR(solid_area(dt), 4 * pi, 1e-9);
}

TEST(Delaunay, duplicates_are_merged_and_reported) {
    auto p = random_points(1000, 2);
    std::vector<Vec3> q = p;
    q.insert(q.end(), p.begin(), p.begin() + 100); // exact duplicates
    Vec3 near =
        lonlat_to_vec(vec_to_lonlat(p[500]).lon + 1e-13 * rad_to_deg, vec_to_lonlat(p[500]).lat);
    q.push_back(near); // within the default 1e-12 rad
    SphericalDelaunay dt;
    auto ids = dt.insert_points(q);
    expect_valid_closed(dt);
    EXPECT_EQ(dt.vertex_count(), 1000u);
    EXPECT_EQ(dt.merged_count(), 101u);
    for (int i = 0; i < 100; ++i)
        EXPECT_EQ(ids[1000 + i], ids[i]);
    EXPECT_EQ(ids.back(), ids[500]);
}

TEST(Delaunay, points_in_one_hemisphere_give_ghost_triangles_closing_the_hull) {
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> lon(-40, 40), lat(10, 60);
    std::vector<Vec3> p(3000);
    for (auto &v : p)
        v = lonlat_to_vec(lon(rng), lat(rng));
    SphericalDelaunay dt;
    dt.insert_points(p);
    expect_valid_closed(dt);
    std::size_t ghosts = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && !dt.is_solid(t))
            ++ghosts;
    EXPECT_GT(ghosts, 0u);
    EXPECT_EQ(brute_force_violations(dt, 1e-15L), 0u);
    // Solid triangles tile the spherical convex hull: their area is below a hemisphere.
    EXPECT_GT(solid_area(dt), 0.0);
    EXPECT_LT(solid_area(dt), 2 * pi);
}

TEST(Delaunay, too_few_or_circular_points_are_refused) {
    SphericalDelaunay a;
    std::vector<Vec3> two = {{1, 0, 0}, {0, 1, 0}, {1, 0, 0}};
    EXPECT_THROW(a.insert_points(two), DataError);
    std::vector<Vec3> circle;
    for (int i = 0; i < 50; ++i)
        circle.push_back(lonlat_to_vec(i * 7.0, 0));
    SphericalDelaunay b;
    EXPECT_THROW(b.insert_points(circle), DataError);
    std::vector<Vec3> small_circle;
    for (int i = 0; i < 50; ++i)
        small_circle.push_back(lonlat_to_vec(i * 7.0, 30));
    SphericalDelaunay c;
    EXPECT_THROW(c.insert_points(small_circle), DataError);
}

TEST(Delaunay, constraints_are_recovered_by_flips_and_never_flipped_again) {
    auto p = random_points(3000, 21);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    // A closed polygon of 40 vertices around a small circle, its sides long enough to cross
    // many Delaunay edges.
    std::vector<VertexId> ring;
    for (int k = 0; k < 40; ++k)
        ring.push_back(dt.insert(lonlat_to_vec(10 + 25 * std::cos(k * 2 * pi / 40),
                                               20 + 15 * std::sin(k * 2 * pi / 40))));
    for (int k = 0; k < 40; ++k)
        ASSERT_TRUE(dt.insert_constraint(ring[k], ring[(k + 1) % 40]));
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    auto star = dt.vertex_half_edges();
    for (int k = 0; k < 40; ++k) {
        HalfEdge h = dt.find_edge(star[ring[k]], ring[(k + 1) % 40]);
        ASSERT_NE(h, no_half_edge);
        EXPECT_TRUE(dt.is_constrained(h));
    }
    // Inserting more points keeps every constraint and the constrained Delaunay property.
    auto more = random_points(2000, 22);
    for (const Vec3 &q : more)
        dt.insert(q);
    problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    star = dt.vertex_half_edges();
    for (int k = 0; k < 40; ++k)
        EXPECT_NE(dt.find_edge(star[ring[k]], ring[(k + 1) % 40]), no_half_edge);
    (void)ids;
}

TEST(Delaunay, renumbering_keeps_every_triangle_constraint_and_label_and_lays_them_out_as_asked) {
    // Insertions after the batch, constraints and labels.
    SphericalDelaunay dt;
    auto ids = dt.insert_points(random_points(3000, 31));
    std::vector<VertexId> ring;
    for (int k = 0; k < 30; ++k)
        ring.push_back(dt.insert(lonlat_to_vec(-40 + 20 * std::cos(k * 2 * pi / 30),
                                               10 + 20 * std::sin(k * 2 * pi / 30))));
    for (int k = 0; k < 30; ++k)
        ASSERT_TRUE(dt.insert_constraint(ring[k], ring[(k + 1) % 30]));
    for (const Vec3 &q : random_points(1000, 32))
        dt.insert(q);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t))
            dt.set_label(t, static_cast<std::uint8_t>(t % 3));
    // Each triangle as its corners' points, rotated to start at the smallest, with its label and
    // which of its edges are constrained: the triangulation whatever the numbering.
    using Described = std::tuple<Tri, std::uint8_t, std::array<bool, 3>>;
    auto describe = [](const SphericalDelaunay &d) {
        std::vector<Described> out;
        for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
            if (!d.is_live(t))
                continue;
            Tri tri;
            std::array<bool, 3> constrained;
            for (int i = 0; i < 3; ++i) {
                const Vec3 &p = d.point(d.vertex(t, i));
                tri[i] = {p.x, p.y, p.z};
                constrained[i] = d.is_constrained(half_edge(t, i));
            }
            const auto m = std::min_element(tri.begin(), tri.end()) - tri.begin();
            std::rotate(tri.begin(), tri.begin() + m, tri.end());
            std::rotate(constrained.begin(), constrained.begin() + m, constrained.end());
            out.emplace_back(tri, d.label(t), constrained);
        }
        std::sort(out.begin(), out.end());
        return out;
    };
    const auto before = describe(dt);
    const std::size_t live = dt.triangle_count(), slots = dt.triangle_slots();
    // A random permutation of the vertices.
    std::vector<VertexId> new_of_old(dt.vertex_count());
    std::iota(new_of_old.begin(), new_of_old.end(), VertexId{0});
    std::shuffle(new_of_old.begin(), new_of_old.end(), std::mt19937_64(33));
    std::vector<Vec3> old_points(dt.points());
    const auto new_of_slot = dt.renumber(new_of_old);
    ASSERT_EQ(new_of_slot.size(), slots);
    EXPECT_EQ(
        static_cast<std::size_t>(std::count(new_of_slot.begin(), new_of_slot.end(), no_triangle)),
        slots - live);
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    for (VertexId v = 0; v < old_points.size(); ++v)
        ASSERT_EQ(dt.point(new_of_old[v]), old_points[v]);
    EXPECT_EQ(dt.triangle_slots(), live);
    EXPECT_EQ(describe(dt), before);
    // Laid out by their smallest corner, in increasing order.
    auto smallest = [&](TriangleId t) {
        return std::min({dt.vertex(t, 0), dt.vertex(t, 1), dt.vertex(t, 2)});
    };
    for (TriangleId t = 1; t < dt.triangle_slots(); ++t)
        ASSERT_LE(smallest(t - 1), smallest(t));
    // The constraints are still found from their new ends, and insertion goes on from here.
    auto star = dt.vertex_half_edges();
    for (int k = 0; k < 30; ++k) {
        const HalfEdge h = dt.find_edge(star[new_of_old[ring[k]]], new_of_old[ring[(k + 1) % 30]]);
        ASSERT_NE(h, no_half_edge);
        EXPECT_TRUE(dt.is_constrained(h));
    }
    for (const Vec3 &q : random_points(500, 34))
        dt.insert(q);
    problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    (void)ids;
}

TEST(Delaunay, crossing_constraint_is_refused) {
    std::vector<Vec3> p = {
        lonlat_to_vec(0, 0), lonlat_to_vec(10, 0), lonlat_to_vec(5, -5), lonlat_to_vec(5, 5),
        {0, 0, 1},           {0, 0, -1},           lonlat_to_vec(180, 0)};
    SphericalDelaunay dt;
    auto id = dt.insert_points(p);
    ASSERT_TRUE(dt.insert_constraint(id[0], id[1]));
    EXPECT_FALSE(dt.insert_constraint(id[2], id[3]));
    auto problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
}

TEST(Delaunay, split_edge_keeps_both_halves_constrained) {
    auto p = random_points(500, 4);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    ASSERT_TRUE(dt.insert_constraint(ids[0], ids[1]));
    auto star = dt.vertex_half_edges();
    HalfEdge h = dt.find_edge(star[ids[0]], ids[1]);
    ASSERT_NE(h, no_half_edge);
    VertexId m = dt.split_edge(h, arc_midpoint(p[0], p[1]));
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    star = dt.vertex_half_edges();
    HalfEdge h1 = dt.find_edge(star[ids[0]], m), h2 = dt.find_edge(star[m], ids[1]);
    ASSERT_NE(h1, no_half_edge);
    ASSERT_NE(h2, no_half_edge);
    EXPECT_TRUE(dt.is_constrained(h1));
    EXPECT_TRUE(dt.is_constrained(h2));
}

TEST(Delaunay, moving_a_vertex_restores_delaunay_and_refuses_folds) {
    auto p = random_points(2000, 6);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    VertexId v = ids[10];
    Vec3 target = normalized(dt.point(v) + 1e-3 * Vec3{1, 1, 1});
    dt.move_vertex(v, target);
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    // Moving a vertex across the sphere would fold its star: refused, nothing changes.
    Vec3 before = dt.point(ids[20]);
    EXPECT_FALSE(dt.move_vertex(ids[20], -before));
    EXPECT_EQ(dt.point(ids[20]), before);
    EXPECT_TRUE(dt.validate().empty());
}

namespace {

// A move's target that usually needs flips: 55% of the way from the origin of `from` to its
// destination.
Vec3 past_halfway(const SphericalDelaunay &dt, HalfEdge from) {
    return normalized(0.45 * dt.point(dt.origin(from)) + 0.55 * dt.point(dt.destination(from)));
}

} // namespace

TEST(Delaunay, a_move_names_the_corners_of_its_flips_and_they_cover_every_changed_star) {
    // Each vertex's neighbours before and after moves that need flips: every vertex whose
    // neighbours changed is the moved one, one of its neighbours before, or a corner
    // move_vertex_from reports.
    auto p = random_points(2000, 9);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    auto neighbours = [&] {
        std::vector<std::set<VertexId>> n(dt.vertex_count());
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
            if (dt.is_live(t))
                for (int i = 0; i < 3; ++i)
                    n[dt.vertex(t, i)].insert(dt.vertex(t, (i + 1) % 3));
        return n;
    };
    std::size_t with_flips = 0;
    for (std::size_t k = 0; k < 200 && with_flips < 20; ++k) {
        const VertexId v = ids[k];
        const HalfEdge from = dt.leaving(v);
        const Vec3 to = past_halfway(dt, from);
        const auto before = neighbours();
        std::vector<VertexId> flipped;
        if (!dt.move_vertex_from(from, to, &flipped))
            continue;
        ASSERT_TRUE(dt.validate().empty());
        const auto after = neighbours();
        std::set<VertexId> covered(flipped.begin(), flipped.end());
        covered.insert(v);
        covered.insert(before[v].begin(), before[v].end());
        for (VertexId u = 0; u < dt.vertex_count(); ++u)
            if (before[u] != after[u]) {
                EXPECT_TRUE(covered.count(u)) << "vertex " << u << " after moving " << v;
            }
        with_flips += !flipped.empty();
        if (flipped.empty()) {
            EXPECT_EQ(before, after);
        }
    }
    EXPECT_GE(with_flips, 20u);
}

TEST(Delaunay, a_move_its_caller_refuses_leaves_every_triangle_as_it_was) {
    // Moves that need flips, refused by `accept` after seeing the moved state: the point and
    // every slot's corners and links come back exactly; accepted, the same move stays.
    auto p = random_points(2000, 11);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    auto snapshot = [&] {
        std::vector<std::array<VertexId, 6>> s(dt.triangle_slots());
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
            for (int i = 0; i < 3; ++i) {
                s[t][i] = dt.vertex(t, i);
                s[t][3 + i] = dt.is_live(t) ? dt.twin(half_edge(t, i)) : no_half_edge;
            }
        return s;
    };
    std::size_t refused = 0;
    for (std::size_t k = 0; k < 200 && refused < 20; ++k) {
        const VertexId v = ids[k];
        const HalfEdge from = dt.leaving(v);
        const Vec3 to = past_halfway(dt, from);
        const Vec3 was = dt.point(v);
        const auto before = snapshot();
        std::vector<VertexId> flipped;
        bool seen_moved = false;
        const bool moved = dt.move_vertex_from(from, to, &flipped, [&] {
            seen_moved = dt.point(v) == to && dt.validate().empty();
            return false;
        });
        EXPECT_FALSE(moved);
        if (!seen_moved)
            continue; // refused by the fold test: accept never ran
        EXPECT_EQ(dt.point(v), was);
        EXPECT_EQ(snapshot(), before) << "after refusing the move of " << v;
        ASSERT_TRUE(dt.validate().empty());
        refused += !flipped.empty();
        EXPECT_TRUE(dt.move_vertex_from(dt.leaving(v), to, nullptr, [] { return true; }));
        EXPECT_EQ(dt.point(v), to);
        ASSERT_TRUE(dt.validate().empty());
    }
    EXPECT_GE(refused, 20u);
}

TEST(Delaunay,
     placing_a_vertex_keeps_the_links_and_make_delaunay_from_its_star_restores_the_property) {
    auto p = random_points(2000, 7);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    const VertexId v = ids[10];
    const HalfEdge from = dt.leaving(v);
    // Across the sphere would fold the star: refused, nothing changes.
    const Vec3 before = dt.point(v);
    EXPECT_FALSE(dt.place_vertex_from(from, -before));
    EXPECT_EQ(dt.point(v), before);
    // Most of the way to a neighbour: no fold, but circumcircles now hold points.
    for (HalfEdge h = from; !dt.place_vertex_from(
             from, normalized(0.3 * before + 0.7 * dt.point(dt.destination(h))));) {
        h = dt.next_around_origin(h);
        ASSERT_NE(h, from) << "no neighbour could be approached";
    }
    EXPECT_NE(dt.point(v), before);
    EXPECT_GT(brute_force_violations(dt, 1e-15L), 0u);
    // The links are intact: the same triangle count, every triangle counter-clockwise.
    EXPECT_EQ(euler(dt), 2u);
    std::vector<HalfEdge> edges;
    for (HalfEdge h = dt.leaving(v);;) {
        edges.push_back(h);
        edges.push_back(half_edge(triangle_of(h), (edge_of(h) + 1) % 3));
        h = dt.next_around_origin(h);
        if (h == edges.front())
            break;
    }
    EXPECT_GT(dt.make_delaunay(edges), 0u);
    EXPECT_EQ(brute_force_violations(dt, 1e-15L), 0u);
    EXPECT_TRUE(dt.validate().empty());
}

TEST(Delaunay, insert_in_triangle_of_a_constrained_triangulation) {
    auto p = random_points(400, 31);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    for (int k = 0; k + 1 < 20; k += 2)
        dt.insert_constraint(ids[k], ids[k + 1]);
    // Insert the centroid of every 7th solid triangle through insert_in_triangle.
    std::vector<std::pair<TriangleId, Vec3>> todo;
    for (TriangleId t = 0; t < dt.triangle_slots(); t += 7)
        if (dt.is_live(t) && dt.is_solid(t))
            todo.emplace_back(t, normalized(dt.point(dt.vertex(t, 0)) + dt.point(dt.vertex(t, 1)) +
                                            dt.point(dt.vertex(t, 2))));
    std::size_t before = dt.vertex_count();
    for (auto &[t, c] : todo) {
        TriangleId where = dt.locate(c, t);
        dt.insert_in_triangle(c, where);
    }
    EXPECT_EQ(dt.vertex_count(), before + todo.size());
    auto problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
}

TEST(Delaunay, adopted_points_in_brio_order_give_the_same_triangulation_as_the_span_insert) {
    auto p = random_points(20000, 41);
    SphericalDelaunay by_span;
    auto ids_span = by_span.insert_points(std::span<const Vec3>(p));
    SphericalDelaunay adopted;
    auto order = SphericalDelaunay::insertion_order(p, 1);
    auto ids = adopted.insert_points(std::vector<Vec3>(p), std::move(order));
    expect_valid_closed(adopted);
    EXPECT_EQ(canonical(adopted, false), canonical(by_span, false));
    ASSERT_EQ(ids.size(), p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        EXPECT_EQ(adopted.point(ids[i]), p[i]);
        EXPECT_EQ(by_span.point(ids_span[i]), p[i]);
    }
}

TEST(Delaunay, adopting_insert_refuses_an_order_that_is_not_a_permutation) {
    auto p = random_points(100, 42);
    std::vector<std::uint32_t> repeated(100);
    for (std::uint32_t i = 0; i < 100; ++i)
        repeated[i] = i;
    repeated[7] = 3;
    SphericalDelaunay dt;
    EXPECT_THROW(dt.insert_points(std::vector<Vec3>(p), std::move(repeated)),
                 std::invalid_argument);
    std::vector<std::uint32_t> out_of_range(100);
    for (std::uint32_t i = 0; i < 100; ++i)
        out_of_range[i] = i;
    out_of_range[99] = 100;
    SphericalDelaunay dt2;
    EXPECT_THROW(dt2.insert_points(std::vector<Vec3>(p), std::move(out_of_range)),
                 std::invalid_argument);
    EXPECT_EQ(dt2.triangle_count(), 0u);
}

TEST(Delaunay, locate_from_any_hint_finds_a_triangle_containing_the_point) {
    auto p = random_points(5000, 43);
    SphericalDelaunay dt;
    dt.insert_points(p);
    auto q = random_points(500, 44);
    std::size_t k = 0;
    for (const Vec3 &x : q) {
        // Hints: none, a far live slot, and an out-of-range id.
        const TriangleId hints[] = {
            no_triangle, static_cast<TriangleId>((k * 7919) % dt.triangle_slots()), 0xfffffff0u};
        for (TriangleId h : hints) {
            TriangleId t = dt.locate(x, h);
            ASSERT_NE(t, no_triangle);
            ASSERT_TRUE(dt.is_live(t));
            const Vec3 &a = dt.point(dt.vertex(t, 0)), &b = dt.point(dt.vertex(t, 1)),
                       &c = dt.point(dt.vertex(t, 2));
            EXPECT_GE(predicates::orient(a, b, x), 0);
            EXPECT_GE(predicates::orient(b, c, x), 0);
            EXPECT_GE(predicates::orient(c, a, x), 0);
        }
        ++k;
    }
}

// fuzz_delaunay finding 1b15f159 (insert_constraint), minimized. Points 0..3 are rounded unit
// vectors ~2.5e-12 rad apart on one great circle, and point 1 is bit-exactly the midpoint of
// the chord 0-2 (collinear in space, impossible for points exactly on the sphere). Points 4, 5
// lie about 2 rad away, so all six are in a closed hemisphere: flat and ghost triangles close
// the hull. Recovering the edge 2-4 leaves the edge from point 1 to a far point needing a flip
// whose new triangle (0, 1, 2) is flat (orient() == 0); in_circle()'s radial perturbation keeps
// that zero, so the flip is legal there, but legalize_from refused it as if it folded and left
// an edge that is not locally Delaunay. Reproduces with g++ and clang++ (the input is hex).
TEST(Delaunay, constraint_recovery_flips_to_a_flat_triangle_on_three_collinear_rounded_points) {
    const std::vector<Vec3> p = {
        {-0x1.b602699904241p-4, -0x1.4626cbb5399d1p-1, -0x1.86dc23c464258p-1},
        {-0x1.b60269990c4d2p-4, -0x1.4626cbb53fb0ap-1, -0x1.86dc23c45eeeep-1},
        {-0x1.b602699914763p-4, -0x1.4626cbb545c43p-1, -0x1.86dc23c459b84p-1},
        {-0x1.b60269991c9f4p-4, -0x1.4626cbb54bd7cp-1, -0x1.86dc23c45481ap-1},
        {-0x1.c11dd5c05fb99p-2, -0x1.c46ad831d8a59p-10, 0x1.cc207f367f37fp-1},
        {-0x1.c11dd5bd6382ep-2, -0x1.c46ad8d4e110ep-10, 0x1.cc207f37398b5p-1},
    };
    // The premise, checked exactly: p1 = (p0 + p2) / 2 with no rounding (halving and adding
    // these doubles is exact here), so p0, p1, p2 lie on one line and on one great circle.
    EXPECT_EQ(p[1], 0.5 * (p[0] + p[2]));
    EXPECT_EQ(predicates::orient(p[0], p[1], p[2]), 0);
    EXPECT_EQ(predicates::orient(p[0], p[1], p[3]), 0);

    SphericalDelaunay dt;
    const auto id = dt.insert_points(p);
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    ASSERT_EQ(std::set<VertexId>(id.begin(), id.end()).size(), p.size()); // nothing merged
    ASSERT_TRUE(dt.insert_constraint(id[2], id[4]));
    problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();

    const HalfEdge h = dt.find_edge(dt.vertex_half_edges()[id[2]], id[4]);
    ASSERT_NE(h, no_half_edge);
    EXPECT_TRUE(dt.is_constrained(h));
    // Independently of validate(): every unconstrained edge is locally Delaunay (the opposite
    // vertex is not inside the circumcircle).
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t))
            continue;
        for (int i = 0; i < 3; ++i) {
            const HalfEdge e = half_edge(t, i);
            if (dt.is_constrained(e))
                continue;
            const HalfEdge g = dt.twin(e);
            const Vec3 &opposite = dt.point(dt.vertex(triangle_of(g), edge_of(g)));
            EXPECT_LE(predicates::in_circle(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                            dt.point(dt.vertex(t, 2)), opposite),
                      0)
                << "edge " << dt.origin(e) << "-" << dt.destination(e);
        }
    }
}

// Every ordered pair of vertices of p, as a constraint on a copy of its triangulation:
// validate() stays empty, a refused pair leaves the same triangles and no constrained edge, a
// recovered pair is a constrained edge. Returns how many were refused.
static int check_every_constraint(const std::vector<Vec3> &p) {
    SphericalDelaunay dt;
    const auto id = dt.insert_points(p);
    EXPECT_TRUE(dt.validate().empty());
    const auto before = canonical(dt, false);
    std::set<VertexId> used(id.begin(), id.end());
    int refused = 0;
    for (VertexId a : used)
        for (VertexId b : used) {
            if (a == b)
                continue;
            SphericalDelaunay d = dt;
            const bool ok = d.insert_constraint(a, b);
            const auto problems = d.validate();
            EXPECT_TRUE(problems.empty()) << a << "-" << b << ": " << problems.front();
            if (ok) {
                const HalfEdge e = d.find_edge(d.vertex_half_edges()[a], b);
                EXPECT_NE(e, no_half_edge) << a << "-" << b; // no vertex lies on these arcs
                if (e != no_half_edge) {
                    EXPECT_TRUE(d.is_constrained(e));
                }
            } else {
                ++refused;
                EXPECT_EQ(canonical(d, false), before) << a << "-" << b;
                for (TriangleId t = 0; t < d.triangle_slots(); ++t)
                    for (int i = 0; i < 3 && d.is_live(t); ++i)
                        EXPECT_FALSE(d.is_constrained(half_edge(t, i)));
            }
        }
    return refused;
}

// fuzz_delaunay finding d3073a7a (insert_constraint), minimized to 7 points. Rounded unit
// vectors 1e-12..1e-10 rad apart: their distances from the sphere (~1e-16) outweigh its
// curvature over that span (~1e-21), so the points, as the 3D points the predicates see, are not
// in convex position: a vertex can lie inside the hull of its neighbours. Recovering an edge
// there by flips gets stuck, and the half-done flips left an edge that is not locally Delaunay
// and that no flip can mend (its quadrilateral is not convex). insert_constraint must then
// change nothing; where it succeeds, the edge is there and constrained.
TEST(Delaunay, constraint_that_flips_cannot_recover_leaves_the_triangulation_unchanged) {
    const std::vector<Vec3> p = {
        {-0x1.11e5d7e388a1dp-2, -0x1.74254068c618ep-2, -0x1.c8e8baafc9b31p-1},
        {-0x1.11e5d7e2af555p-2, -0x1.7425406971476p-2, -0x1.c8e8baafc768cp-1},
        {-0x1.11e5d7e1a7286p-2, -0x1.7425406980139p-2, -0x1.c8e8baafebfc9p-1},
        {-0x1.11e5d7e386007p-2, -0x1.74254068c24d5p-2, -0x1.c8e8baafcaddfp-1},
        {-0x1.11e5d7e418caap-2, -0x1.7425406989befp-2, -0x1.c8e8baaf8c41cp-1},
        {-0x1.11e5d7e41b6c2p-2, -0x1.742540698d8aap-2, -0x1.c8e8baaf8b172p-1},
        {-0x1.11e5d7e45a0a2p-2, -0x1.742540680f87ap-2, -0x1.c8e8baafcf7dep-1},
    };
    // The premise: all within 2e-10 rad, closer than rounding off the sphere resolves.
    for (const Vec3 &a : p)
        for (const Vec3 &b : p)
            EXPECT_LT(arc_angle(a, b), 2e-10);

    // The finding's pair is refused, and others are recovered: both branches are checked.
    const int refused = check_every_constraint(p);
    EXPECT_GT(refused, 0);
    EXPECT_LT(refused, 7 * 6);
}

// fuzz_delaunay timeout 60bf7b3f: in the same kind of cluster, flips recovering the constraint
// 4-16 cycled forever (Sloan's flips end in the plane, not where the points are not in convex
// position); their number is now bounded and the constraint refused. Here every pair must
// finish (a hang is a ctest timeout) with the same guarantees.
TEST(Delaunay, constraint_flips_that_would_cycle_end_and_change_nothing) {
    const std::vector<Vec3> p = {
        {-0x1.11e5d7e34c9a5p-2, -0x1.7425406816bc9p-2, -0x1.c8e8baaff6673p-1},
        {-0x1.11e5d7e27890ap-2, -0x1.74254068c9824p-2, -0x1.c8e8baaff1c74p-1},
        {-0x1.11e5d7e27890ap-2, -0x1.74254068c9824p-2, -0x1.c8e8baaff1c74p-1},
        {-0x1.11e5d7e27890ap-2, -0x1.74254068c9824p-2, -0x1.c8e8baaff1c74p-1},
        {-0x1.11e5d7e3833bfp-2, -0x1.74254068c00fbp-2, -0x1.c8e8baafcbbcep-1},
        {-0x1.11e5a49b3aa31p-2, -0x1.74256ba48e19bp-2, -0x1.c8e8b9919d75dp-1},
        {-0x1.11e5d7e34eebfp-2, -0x1.742540681a15p-2, -0x1.c8e8baaff55fdp-1},
        {-0x1.11e5d7e385dd6p-2, -0x1.74254068c3db5p-2, -0x1.c8e8baafca922p-1},
        {-0x1.11e5d7e3887edp-2, -0x1.74254068c7a6fp-2, -0x1.c8e8baafc9676p-1},
        {-0x1.11e5d7e27b321p-2, -0x1.74254068cd4dep-2, -0x1.c8e8baaff09c8p-1},
        {-0x1.11e5d7e27ed6fp-2, -0x1.74254068c9588p-2, -0x1.c8e8baaff0df1p-1},
        {-0x1.11e5d7e3518d6p-2, -0x1.742540681de0ap-2, -0x1.c8e8baaff4351p-1},
        {-0x1.11e5d7e27b321p-2, -0x1.74254068cd4dep-2, -0x1.c8e8baaff09c8p-1},
        {-0x1.11e5d7e348a67p-2, -0x1.742540681a11bp-2, -0x1.c8e8baaff6512p-1},
        {-0x1.11e5d7e2af324p-2, -0x1.7425406972d56p-2, -0x1.c8e8baafc71cfp-1},
        {-0x1.11e5d7e1a7286p-2, -0x1.7425406980139p-2, -0x1.c8e8baafebfc9p-1},
        {-0x1.11e5d7e459ba4p-2, -0x1.742540680f147p-2, -0x1.c8e8baafcfa14p-1},
        {-0x1.11e5d7e45768bp-2, -0x1.742540680bbcp-2, -0x1.c8e8baafd0a8ap-1},
        {-0x1.11e5d7e386007p-2, -0x1.74254068c24d5p-2, -0x1.c8e8baafcaddfp-1},
        {-0x1.11e5d7e418a7ap-2, -0x1.742540698b4dp-2, -0x1.c8e8baaf8bf61p-1},
        {-0x1.11e5d7e41b491p-2, -0x1.742540698f18ap-2, -0x1.c8e8baaf8acb5p-1},
        {-0x1.11e5d7e388a18p-2, -0x1.74254068c6187p-2, -0x1.c8e8baafc9b35p-1},
        {-0x1.11e5d7e45a0a2p-2, -0x1.742540680f87ap-2, -0x1.c8e8baafcf7dep-1},
    };
    SphericalDelaunay dt;
    dt.insert_points(p);
    ASSERT_GT(dt.vertex_count(), 16u); // the finding's vertex 16 exists
    EXPECT_FALSE(dt.insert_constraint(4, 16));
    EXPECT_TRUE(dt.validate().empty());
    check_every_constraint(p);
}

// fuzz_delaunay finding e2cdd810 (insert_points). Every point but p6 lies on the great circle
// y = 0 (the pole too), so the hull closes with flat triangles in that plane. p9 is an exact
// copy of p7 and came in after it; the walk stopped on a flat triangle of that great circle
// without p7's vertex, and the greedy descent to the nearest vertex, which holds for Delaunay
// triangulations, stalled at p4's vertex, 1e-6 rad away, which does not neighbour p7's: p9 was
// merged there. The nearest vertex is now sought over the flat region around the triangle.
TEST(Delaunay, duplicate_landing_on_a_flat_triangle_merges_into_its_twin) {
    const std::vector<Vec3> p = {
        {0x0p+0, 0x0p+0, 0x1p+0},
        {-0x1.c45bad246bb71p-44, 0x1.42f30c52d67f8p-58, 0x1p+0},
        {-0x1.c45bad246bb71p-44, 0x1.42f30c52d67f8p-58, 0x1p+0},
        {-0x1.999999999999ap-1, 0x0p+0, -0x1.3333333333334p-1},
        {-0x1.999999999af4ap-1, 0x0p+0, -0x1.3333333331649p-1},
        {0x1.1498b953a0096p-35, 0x1.7fe0bff3e70a7p-35, 0x1p+0},
        {0x1.2d6eae2110c18p-3, -0x1.fa6c843761f3dp-1, 0x1.1a62633145c06p-54},
        {-0x1.9999adbb8eac8p-1, 0x0p+0, -0x1.3333185b3fefap-1},
        {-0x1.9999c1dd81fdp-1, 0x0p+0, -0x1.3332fd834b5a4p-1},
        {-0x1.9999adbb8eac8p-1, 0x0p+0, -0x1.3333185b3fefap-1},
    };
    ASSERT_EQ(p[7], p[9]);
    SphericalDelaunay dt;
    const auto id = dt.insert_points(p);
    const auto problems = dt.validate();
    EXPECT_TRUE(problems.empty()) << problems.front();
    EXPECT_EQ(id[9], id[7]);
    // Every point maps to a vertex no farther than the merge distance of points the hull cannot
    // resolve (about 1e-8 rad; p4 is 1e-12 from p3, the near-pole points 1e-13 and 5e-11).
    for (std::size_t i = 0; i < p.size(); ++i)
        EXPECT_LT(arc_angle(dt.point(id[i]), p[i]), 1e-7) << "point " << i;
}

namespace {

// The patch that puts a new point (index first + r) at the centroid of each triangle in `ts`:
// three triangles per point, the triangle's own half-edges as the border (adjacent triangles of
// `ts` share a border edge from both sides).
struct CentroidPatch {
    std::vector<HalfEdge> border;
    std::vector<Vec3> points;
    std::vector<VertexId> triangles;
    std::vector<std::uint32_t> adjacent;
};

CentroidPatch centroid_patch(const SphericalDelaunay &dt, const std::vector<TriangleId> &ts) {
    CentroidPatch p;
    for (TriangleId t : ts) {
        const VertexId v[3] = {dt.vertex(t, 0), dt.vertex(t, 1), dt.vertex(t, 2)};
        const auto c = static_cast<VertexId>(dt.vertex_count() + p.points.size());
        p.points.push_back(normalized(dt.point(v[0]) + dt.point(v[1]) + dt.point(v[2])));
        const auto r0 = static_cast<std::uint32_t>(p.triangles.size() / 3);
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t next = r0 + (i + 1) % 3, prev = r0 + (i + 2) % 3;
            p.triangles.insert(p.triangles.end(), {v[(i + 1) % 3], v[(i + 2) % 3], c});
            p.adjacent.insert(p.adjacent.end(), {3 * next + 1, 3 * prev + 0,
                                                 SphericalDelaunay::patch_border |
                                                     static_cast<std::uint32_t>(p.border.size())});
            p.border.push_back(half_edge(t, i));
        }
    }
    return p;
}

// replace_region on copies of the patch's vectors: it empties them when it succeeds, and leaves
// them as they were when it refuses.
bool replace(SphericalDelaunay &dt, const CentroidPatch &q, std::uint8_t label) {
    std::vector<Vec3> points = q.points;
    std::vector<VertexId> triangles = q.triangles;
    std::vector<std::uint32_t> adjacent = q.adjacent;
    const bool done = dt.replace_region(q.border, points, triangles, adjacent, label);
    EXPECT_EQ(points.empty() && triangles.empty() && adjacent.empty(), done);
    if (!done) {
        EXPECT_EQ(points, q.points);
        EXPECT_EQ(triangles, q.triangles);
        EXPECT_EQ(adjacent, q.adjacent);
    }
    return done;
}

std::vector<HalfEdge> all_half_edges(const SphericalDelaunay &dt) {
    std::vector<HalfEdge> h;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t))
            for (int i = 0; i < 3; ++i)
                h.push_back(half_edge(t, i));
    return h;
}

} // namespace

TEST(
    Delaunay,
    replacing_regions_by_known_patches_then_flipping_gives_the_delaunay_triangulation_of_all_points) {
    const auto p = random_points(3000, 17);
    SphericalDelaunay dt;
    dt.insert_points(p);
    // Every third triangle: many of them neighbours, so border edges are taken from both sides.
    std::vector<TriangleId> ts;
    for (TriangleId t = 0; t < dt.triangle_slots(); t += 3)
        if (dt.is_live(t))
            ts.push_back(t);
    const CentroidPatch patch = centroid_patch(dt, ts);
    std::size_t shared = 0;
    for (HalfEdge h : patch.border)
        shared +=
            std::find(patch.border.begin(), patch.border.end(), dt.twin(h)) != patch.border.end();
    ASSERT_GT(shared, 100u);
    const std::size_t before = dt.triangle_count();
    ASSERT_TRUE(replace(dt, patch, 7));
    EXPECT_EQ(dt.vertex_count(), p.size() + ts.size());
    EXPECT_EQ(dt.triangle_count(), before + 2 * ts.size());
    EXPECT_EQ(euler(dt), 2u);
    std::size_t labelled = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        labelled += dt.is_live(t) && dt.label(t) == 7;
    EXPECT_EQ(labelled, 3 * ts.size());
    // Centroids are not Delaunay where a neighbour's circumcircle holds them: the flips mend that,
    // and the result is the triangulation of all the points inserted one by one.
    auto edges = all_half_edges(dt);
    EXPECT_GT(dt.make_delaunay(edges), 0u);
    expect_valid_closed(dt);
    std::vector<Vec3> all = p;
    all.insert(all.end(), patch.points.begin(), patch.points.end());
    SphericalDelaunay ref;
    ref.insert_points(all);
    EXPECT_EQ(canonical(dt, false), canonical(ref, false));
}

TEST(Delaunay, a_patch_that_does_not_fit_its_region_is_refused_and_changes_nothing) {
    const auto p = random_points(500, 23);
    SphericalDelaunay dt;
    dt.insert_points(p);
    const auto before = canonical(dt, false);
    const std::vector<TriangleId> ts = {4, 5, 40};
    const CentroidPatch good = centroid_patch(dt, ts);
    auto refused = [&](const CentroidPatch &q) {
        EXPECT_FALSE(replace(dt, q, 1));
        EXPECT_EQ(dt.vertex_count(), p.size());
        EXPECT_EQ(canonical(dt, false), before);
        EXPECT_TRUE(dt.validate().empty());
    };
    // A border edge no new triangle takes.
    CentroidPatch q = good;
    q.border.push_back(dt.twin(q.border[0]) == q.border[1] ? q.border[2] : dt.twin(q.border[0]));
    refused(q);
    // A new triangle clockwise.
    q = good;
    std::swap(q.triangles[0], q.triangles[1]);
    refused(q);
    // One new point fewer than the region needs (its three triangles' corner an old vertex off
    // the border).
    q = good;
    q.points.pop_back();
    for (std::size_t i = q.triangles.size() - 9; i < q.triangles.size(); ++i)
        if (q.triangles[i] >= p.size())
            q.triangles[i] = dt.vertex(dt.triangle_slots() - 1, 0);
    refused(q);
    // The border turned round (the region's outside on its left): no new edge matches its ends.
    q = good;
    const TriangleId t = ts[0];
    for (int i = 0; i < 3; ++i)
        q.border[i] = dt.twin(half_edge(t, i)); // the region's outside
    refused(q);
    // The right patch still fits after all the refusals.
    ASSERT_TRUE(replace(dt, good, 1));
    auto edges = all_half_edges(dt);
    dt.make_delaunay(edges);
    expect_valid_closed(dt);
}

namespace {

// Every slot's corners and twin links: equal snapshots mean the same triangles in the same slots.
std::vector<std::array<VertexId, 6>> slot_snapshot(const SphericalDelaunay &dt) {
    std::vector<std::array<VertexId, 6>> s(dt.triangle_slots());
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        for (int i = 0; i < 3; ++i) {
            s[t][i] = dt.vertex(t, i);
            s[t][3 + i] = dt.is_live(t) ? dt.twin(half_edge(t, i)) : no_half_edge;
        }
    return s;
}

// Removes every vertex listed, then compares with the triangulation built from the points left.
void expect_removal_gives_delaunay_of_the_rest(const std::vector<Vec3> &p, std::size_t step) {
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    std::vector<std::uint8_t> gone(dt.vertex_count(), 0);
    std::size_t removed = 0;
    for (std::size_t k = 0; k < p.size(); k += step) {
        const VertexId v = ids[k];
        if (gone[v])
            continue;
        ASSERT_TRUE(dt.remove_vertex(v)) << "vertex " << v;
        gone[v] = 1;
        ++removed;
        EXPECT_EQ(dt.vertex_half_edges()[v], no_half_edge);
    }
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    EXPECT_EQ(euler(dt), 2u);
    EXPECT_EQ(brute_force_violations(dt, 1e-15L, gone), 0u);
    std::vector<Vec3> rest;
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (!gone[v] && dt.vertex_half_edges()[v] != no_half_edge)
            rest.push_back(dt.point(v));
    SphericalDelaunay fresh;
    fresh.insert_points(rest);
    EXPECT_EQ(canonical(dt, false), canonical(fresh, false));
    EXPECT_GT(removed, p.size() / step / 2);
}

} // namespace

TEST(Delaunay, removing_half_of_2000_random_points_leaves_the_delaunay_triangulation_of_the_rest) {
    expect_removal_gives_delaunay_of_the_rest(random_points(2000, 31), 2);
}

TEST(Delaunay, removing_points_of_a_cocircular_grid_leaves_the_delaunay_triangulation_of_the_rest) {
    // Four points on a circle everywhere: only the perturbation decides the diagonals.
    expect_removal_gives_delaunay_of_the_rest(grid_points(6), 3);
}

TEST(Delaunay, removal_refuses_constrained_and_ghost_stars_and_keeps_constraints) {
    auto p = random_points(2000, 32);
    SphericalDelaunay dt;
    dt.insert_points(p);
    std::vector<VertexId> ring;
    for (int k = 0; k < 30; ++k)
        ring.push_back(dt.insert(lonlat_to_vec(10 + 20 * std::cos(k * 2 * pi / 30),
                                               20 + 12 * std::sin(k * 2 * pi / 30))));
    for (int k = 0; k < 30; ++k)
        ASSERT_TRUE(dt.insert_constraint(ring[k], ring[(k + 1) % 30]));
    for (VertexId v : ring) {
        const auto before = slot_snapshot(dt);
        EXPECT_FALSE(dt.remove_vertex(v));
        EXPECT_EQ(slot_snapshot(dt), before);
    }
    // Every other vertex goes; the constraints stay edges, still constrained.
    std::size_t removed = 0;
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (std::find(ring.begin(), ring.end(), v) == ring.end())
            removed += dt.remove_vertex(v);
    EXPECT_GT(removed, 1900u);
    auto problems = dt.validate();
    ASSERT_TRUE(problems.empty()) << problems.front();
    const auto star = dt.vertex_half_edges();
    for (int k = 0; k < 30; ++k) {
        const HalfEdge h = dt.find_edge(star[ring[k]], ring[(k + 1) % 30]);
        ASSERT_NE(h, no_half_edge);
        EXPECT_TRUE(dt.is_constrained(h));
    }
    // Points in one hemisphere: a vertex with a ghost in its star is refused.
    std::vector<Vec3> north;
    for (const Vec3 &q : random_points(400, 33))
        north.push_back({q.x, q.y, std::fabs(q.z)});
    SphericalDelaunay half;
    half.insert_points(north);
    std::size_t ghost_refusals = 0;
    const auto hs = half.vertex_half_edges();
    for (VertexId v = 0; v < half.vertex_count(); ++v) {
        if (hs[v] == no_half_edge)
            continue;
        bool ghost = false;
        HalfEdge h = hs[v];
        do {
            ghost = ghost || !half.is_solid(triangle_of(h));
            h = half.next_around_origin(h);
        } while (h != hs[v]);
        if (!ghost)
            continue;
        const auto before = slot_snapshot(half);
        EXPECT_FALSE(half.remove_vertex_from(hs[v]));
        EXPECT_EQ(slot_snapshot(half), before);
        ++ghost_refusals;
    }
    EXPECT_GE(ghost_refusals, 3u);
    EXPECT_TRUE(half.validate().empty());
}

TEST(Delaunay, a_removal_its_caller_refuses_leaves_every_triangle_as_it_was) {
    auto p = random_points(1000, 34);
    SphericalDelaunay dt;
    auto ids = dt.insert_points(p);
    for (std::size_t k = 0; k < 100; ++k) {
        const VertexId v = ids[k];
        const auto before = slot_snapshot(dt);
        const std::size_t count = dt.triangle_count();
        std::vector<TriangleId> changed;
        bool seen = false;
        EXPECT_FALSE(dt.remove_vertex_from(dt.leaving(v), &changed, [&] {
            seen = dt.validate().empty() && dt.triangle_count() == count - 2;
            for (TriangleId t : changed)
                for (int i = 0; i < 3; ++i)
                    seen = seen && dt.is_live(t) && dt.vertex(t, i) != v;
            return false;
        }));
        EXPECT_TRUE(seen);
        EXPECT_EQ(slot_snapshot(dt), before);
        EXPECT_EQ(dt.triangle_count(), count);
        ASSERT_TRUE(dt.validate().empty());
    }
    // The same removals accepted, then new points fill the freed slots.
    for (std::size_t k = 0; k < 100; ++k)
        ASSERT_TRUE(dt.remove_vertex_from(dt.leaving(ids[k]), nullptr, [] { return true; }));
    EXPECT_EQ(dt.triangle_count(), 2 * (1000 - 100) - 4);
    for (const Vec3 &q : random_points(50, 35))
        dt.insert(q);
    EXPECT_TRUE(dt.validate().empty());
    EXPECT_EQ(euler(dt), 2u);
}
