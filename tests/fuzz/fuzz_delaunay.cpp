// libFuzzer target: the spherical Delaunay core (include/globemesh/delaunay.hpp) on point sets
// decoded from the input (at most 48 points).
//
// Each point comes from a mode byte: a lon/lat, a copy of an earlier point (duplicate), an
// earlier point moved a few ulps, a point 1e-13..1e-6 rad from an earlier one (around both merge
// tolerances), a point on a small circle shared by a group (co-circular), a point on a great
// circle (co-planar with the origin: hemisphere hulls with ghost triangles), a pole or axis
// point, an exactly cospherical lattice point (scaled (5,0,0)/(3,4,0) permutations). Checks:
//   * insert_points either succeeds or throws DataError only when every point lies on one plane
//     (checked in floating point with a wide margin);
//   * validate() is empty; every input point maps to a vertex within 1e-7 rad of it; the
//     vertices used by triangles are exactly the distinct vertices of the map, and with V of
//     them there are 2V - 4 triangles
//     (V - E + F = 2, E = 3F/2);
//   * when no two distinct points are within 1e-7 rad (closer ones merge order-dependently),
//     the triangle set does not depend on the insertion order: BRIO with another seed, and
//     one-by-one insert() in input order, give the same triangles;
//   * after a few insert_constraint and move_vertex calls validate() is still empty; a refused
//     constraint changed no triangle and no flag, an accepted one is a constrained edge (or a
//     chain of them through vertices on its arc); each moved vertex is at its target (or where
//     it was, when move_vertex refused).
// A failure prints the points as hex floats and aborts (a libFuzzer crash); with
// GLOBEMESH_FUZZ_PRINT set, each input's points and calls are printed as they are made (to
// replay a hang).
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"

using namespace globemesh;

namespace {

std::vector<Vec3> g_points; // for failure messages
std::string g_ops;          // the constraint and move calls made, for failure messages

[[noreturn]] void fail(const std::string &what) {
    std::fprintf(stderr, "fuzz_delaunay: %s\npoints (%zu):\n", what.c_str(), g_points.size());
    for (const Vec3 &p : g_points)
        std::fprintf(stderr, "  {%a, %a, %a},\n", p.x, p.y, p.z);
    std::fprintf(stderr, "calls after insert_points:\n%s", g_ops.c_str());
    std::abort();
}

/// Fails on any problem validate() reports.
void expect_valid(const SphericalDelaunay &d, const char *stage) {
    const auto problems = d.validate();
    if (problems.empty())
        return;
    std::fprintf(stderr, "triangles:\n");
    for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
        if (!d.is_live(t))
            continue;
        for (int k = 0; k < 3; ++k) {
            const Vec3 &p = d.point(d.vertex(t, k));
            std::fprintf(stderr, "%s{%a, %a, %a}", k ? " " : "  ", p.x, p.y, p.z);
        }
        std::fprintf(stderr, "\n");
    }
    fail(std::string(stage) + ": validate(): " + problems.front());
}

double nudge(double x, int k) {
    for (; k > 0; --k)
        x = std::nextafter(x, INFINITY);
    for (; k < 0; ++k)
        x = std::nextafter(x, -INFINITY);
    return x;
}

Vec3 rotate(const Vec3 &v, const Vec3 &axis, double angle) { // Rodrigues, axis a unit vector
    const double c = std::cos(angle), s = std::sin(angle);
    return c * v + s * cross(axis, v) + ((1 - c) * dot(axis, v)) * axis;
}

// Longitude, then latitude, in that order: as two arguments of one call their order of
// evaluation is unspecified (g++ on x86-64 goes right to left, clang++ left to right), and the
// same input decoded to other points under each compiler.
Vec3 consume_lonlat(FuzzedDataProvider &in) {
    const double lon = in.ConsumeFloatingPointInRange<double>(-180, 180);
    const double lat = in.ConsumeFloatingPointInRange<double>(-90, 90);
    return lonlat_to_vec(lon, lat);
}

std::vector<Vec3> decode(FuzzedDataProvider &in) {
    std::vector<Vec3> pts;
    const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, 48);
    // A shared small circle (axis, radius) and great circle (normal) for co-circular groups.
    const Vec3 axis = consume_lonlat(in);
    const double radius = in.ConsumeFloatingPointInRange<double>(1e-9, pi / 2);
    Vec3 start = cross(axis, Vec3{0.3, -0.5, 0.8});
    start = norm(start) > 1e-6 ? normalized(start) : Vec3{1, 0, 0};
    const Vec3 on_circle = rotate(axis, normalized(cross(axis, start)), radius);
    const int quantum =
        in.ConsumeIntegralInRange<int>(1, 24); // angles on the circle: 2 pi k / quantum
    for (std::size_t i = 0; i < n && in.remaining_bytes() > 0; ++i) {
        const int mode = in.ConsumeIntegralInRange<int>(0, 8);
        const auto earlier = [&] {
            return pts[in.ConsumeIntegralInRange<std::size_t>(0, pts.size() - 1)];
        };
        if (pts.empty() && (mode >= 1 && mode <= 3)) {
            pts.push_back(consume_lonlat(in));
            continue;
        }
        switch (mode) {
        case 0:
            pts.push_back(consume_lonlat(in));
            break;
        case 1:
            pts.push_back(earlier());
            break;
        case 2: {
            const Vec3 a = earlier();
            auto k = [&] { return in.ConsumeIntegralInRange<int>(-3, 3); };
            pts.push_back({nudge(a.x, k()), nudge(a.y, k()), nudge(a.z, k())});
            break;
        }
        case 3: { // near an earlier point: 1e-13 .. 1e-6 rad
            const Vec3 a = earlier();
            const double angle = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-13, -6));
            Vec3 perp =
                cross(a, lonlat_to_vec(in.ConsumeFloatingPointInRange<double>(-180, 180), 10));
            if (!(norm(perp) > 1e-9))
                perp = cross(a, Vec3{0, 0, 1});
            if (!(norm(perp) > 1e-9))
                perp = Vec3{1, 0, 0};
            pts.push_back(normalized(rotate(a, normalized(perp), angle)));
            break;
        }
        case 4: { // co-circular: on the shared small circle
            const int k = in.ConsumeIntegralInRange<int>(0, quantum - 1);
            pts.push_back(rotate(on_circle, axis, 2 * pi * k / quantum));
            break;
        }
        case 5: { // co-planar with the origin: on the equator or on the meridian plane lon 0/180
            const double t =
                2 * pi * in.ConsumeIntegralInRange<int>(0, 4 * quantum - 1) / (4 * quantum);
            const double c = std::cos(t), s = std::sin(t);
            pts.push_back(in.ConsumeBool() ? Vec3{c, s, 0} : Vec3{c, 0, s});
            break;
        }
        case 6: {
            static const Vec3 axes[6] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},
                                         {-1, 0, 0}, {0, 1, 0},  {0, -1, 0}};
            pts.push_back(axes[in.ConsumeIntegralInRange<int>(0, 5)]);
            break;
        }
        case 7: { // exactly cospherical lattice points on the sphere of radius 5/8
            const double b[2][3] = {{5, 0, 0}, {3, 4, 0}};
            const int base = in.ConsumeIntegralInRange<int>(0, 1);
            int perm[3] = {0, 1, 2};
            for (int k = in.ConsumeIntegralInRange<int>(0, 5); k > 0; --k)
                std::next_permutation(perm, perm + 3);
            const int s = in.ConsumeIntegralInRange<int>(0, 7);
            double v[3];
            for (int k = 0; k < 3; ++k)
                v[k] = b[base][perm[k]] * ((s >> k & 1) ? -1 : 1) / 8.0 + 0.0;
            pts.push_back(normalized(Vec3{v[0], v[1], v[2]}));
            break;
        }
        default: { // on a line of latitude (co-circular about the pole), longitudes on a grid
            const double lat = in.ConsumeIntegralInRange<int>(-6, 6) * 15.0;
            const double lon = in.ConsumeIntegralInRange<int>(-12, 12) * 15.0;
            pts.push_back(lonlat_to_vec(lon, lat));
        }
        }
    }
    // The predicates' precision contract (predicates.hpp): no non-zero coordinate below ~1e-182
    // of the largest. A few ulps off 0 is a subnormal, so such coordinates become 0.
    for (Vec3 &p : pts)
        for (double *c : {&p.x, &p.y, &p.z})
            if (std::fabs(*c) < 1e-170)
                *c = 0;
    return pts;
}

/// True when some four points are clearly not on one plane (floating point, wide margins).
bool clearly_not_coplanar(const std::vector<Vec3> &pts) {
    std::vector<Vec3> reps;
    for (const Vec3 &p : pts) {
        bool near = false;
        for (const Vec3 &r : reps)
            near = near || arc_angle(p, r) < 1e-6;
        if (!near)
            reps.push_back(p);
    }
    for (std::size_t i = 0; i < reps.size(); ++i)
        for (std::size_t j = i + 1; j < reps.size(); ++j)
            for (std::size_t k = j + 1; k < reps.size(); ++k) {
                const Vec3 n = cross(reps[j] - reps[i], reps[k] - reps[i]);
                if (norm(n) < 1e-5)
                    continue;
                const Vec3 u = normalized(n);
                for (const Vec3 &p : reps)
                    if (std::fabs(dot(u, p - reps[i])) > 1e-5)
                        return true;
                return false; // one well-spanned plane holds every representative
            }
    return false;
}

using Key = std::array<double, 9>;

/// The triangles as point coordinates, each rotated to start at its lexicographically smallest
/// vertex (orientation kept), as a sorted set.
// Constrained edges as (smaller, larger) vertex pairs.
std::set<std::pair<VertexId, VertexId>> constrained_edges(const SphericalDelaunay &d) {
    std::set<std::pair<VertexId, VertexId>> out;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t)
        for (int i = 0; i < 3 && d.is_live(t); ++i) {
            const HalfEdge h = half_edge(t, i);
            if (d.is_constrained(h))
                out.emplace(std::min(d.origin(h), d.destination(h)),
                            std::max(d.origin(h), d.destination(h)));
        }
    return out;
}

std::set<Key> triangle_set(const SphericalDelaunay &d) {
    std::set<Key> out;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t) {
        if (!d.is_live(t))
            continue;
        std::array<Vec3, 3> v{d.point(d.vertex(t, 0)), d.point(d.vertex(t, 1)),
                              d.point(d.vertex(t, 2))};
        auto less = [](const Vec3 &a, const Vec3 &b) {
            return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
        };
        const int m = static_cast<int>(std::min_element(v.begin(), v.end(), less) - v.begin());
        std::rotate(v.begin(), v.begin() + m, v.end());
        out.insert({v[0].x, v[0].y, v[0].z, v[1].x, v[1].y, v[1].z, v[2].x, v[2].y, v[2].z});
    }
    return out;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    g_points = decode(in);
    g_ops.clear();
    static const bool print = std::getenv("GLOBEMESH_FUZZ_PRINT") != nullptr;
    if (print) { // replaying one input: show it as it goes (a hang never reaches fail())
        std::fprintf(stderr, "points (%zu):\n", g_points.size());
        for (const Vec3 &p : g_points)
            std::fprintf(stderr, "  {%a, %a, %a},\n", p.x, p.y, p.z);
    }
    const std::vector<Vec3> &pts = g_points;

    SphericalDelaunay d;
    std::vector<VertexId> map;
    try {
        map = d.insert_points(std::span<const Vec3>(pts));
    } catch (const DataError &e) {
        if (clearly_not_coplanar(pts))
            fail(std::string("DataError on points not on one plane: ") + e.what());
        return 0;
    }
    expect_valid(d, "insert_points");
    if (map.size() != pts.size())
        fail("insert_points returned a map of the wrong size");
    std::set<VertexId> distinct;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        if (map[i] >= d.vertex_count())
            fail("vertex index out of range");
        if (arc_angle(d.point(map[i]), pts[i]) > 1e-7)
            fail("point merged into a far vertex");
        distinct.insert(map[i]);
    }
    std::set<VertexId> used;
    for (TriangleId t = 0; t < d.triangle_slots(); ++t)
        if (d.is_live(t))
            for (int k = 0; k < 3; ++k)
                used.insert(d.vertex(t, k));
    for (VertexId v : used)
        if (!distinct.count(v))
            fail("a triangle uses a vertex no input point maps to");
    for (std::size_t i = 0; i < pts.size(); ++i)
        if (!used.count(map[i]))
            fail("input point " + std::to_string(i) + " maps to vertex " + std::to_string(map[i]) +
                 ", which no triangle uses");
    if (d.triangle_count() != 2 * used.size() - 4)
        fail("F = " + std::to_string(d.triangle_count()) +
             " triangles for V = " + std::to_string(used.size()) + " vertices, not 2V - 4");

    // Insertion order: another BRIO seed, and input order one point at a time.
    // Which of two close points survives (merged within 1e-12 rad, or within ~1e-8 rad when it
    // falls inside its neighbours' hull) depends on the order: compare orders only without them
    // (equal points are fine: whichever copy survives has the same coordinates).
    bool comparable = true;
    for (std::size_t i = 0; i < pts.size() && comparable; ++i)
        for (std::size_t j = i + 1; j < pts.size() && comparable; ++j)
            comparable = pts[i] == pts[j] || arc_angle(pts[i], pts[j]) >= 1e-7;
    if (comparable) {
        const auto reference = triangle_set(d);
        SphericalDelaunay::Options o;
        o.seed = 0x9e3779b97f4a7c15ull ^ size;
        SphericalDelaunay d2(o);
        d2.insert_points(std::span<const Vec3>(pts));
        expect_valid(d2, "insert_points, other seed");
        if (triangle_set(d2) != reference)
            fail("another BRIO seed gives other triangles");

        // One by one: start from the same four-point tetrahedron a fresh insert_points would
        // choose is not known here, so insert the first points with insert_points on a prefix
        // that spans space, then the rest with insert().
        std::size_t prefix = 4;
        while (prefix <= pts.size() &&
               !clearly_not_coplanar(std::vector<Vec3>(pts.begin(), pts.begin() + prefix)))
            ++prefix;
        if (prefix <= pts.size()) {
            SphericalDelaunay d3;
            bool ok = true;
            try {
                d3.insert_points(std::span<const Vec3>(pts.data(), prefix));
            } catch (const DataError &) {
                ok = false; // the prefix is only spanned within the wide margin of the check
            }
            if (ok) {
                for (std::size_t i = prefix; i < pts.size(); ++i)
                    d3.insert(pts[i], d3.last_triangle());
                expect_valid(d3, "insert one by one");
                if (triangle_set(d3) != reference)
                    fail("one-by-one insertion gives other triangles");
            }
        }
    }

    // Constraints between random vertex pairs (not equal, not near-antipodal), then moves.
    const std::vector<VertexId> verts(used.begin(), used.end());
    const int constraints = in.ConsumeIntegralInRange<int>(0, 4);
    for (int c = 0; c < constraints && verts.size() >= 2; ++c) {
        const VertexId a = verts[in.ConsumeIntegralInRange<std::size_t>(0, verts.size() - 1)];
        const VertexId b = verts[in.ConsumeIntegralInRange<std::size_t>(0, verts.size() - 1)];
        if (a == b || arc_angle(d.point(a), d.point(b)) > 0.9 * pi)
            continue;
        g_ops += "  insert_constraint(" + std::to_string(a) + ", " + std::to_string(b) + ")\n";
        if (print)
            std::fprintf(stderr, "  insert_constraint(%u, %u)\n", a, b);
        const auto triangles = triangle_set(d);
        const auto flags = constrained_edges(d);
        const bool ok = d.insert_constraint(a, b);
        expect_valid(d, "insert_constraint");
        if (!ok && (triangle_set(d) != triangles || constrained_edges(d) != flags))
            fail("insert_constraint returned false but changed the triangulation");
        if (ok) {
            // The edge is there and constrained, unless a vertex on the arc split it.
            const HalfEdge e = d.find_edge(d.vertex_half_edges()[a], b);
            bool split = false; // some vertex lies exactly on the arc a-b
            const Vec3 &pa = d.point(a), &pb = d.point(b);
            for (VertexId v : verts)
                split = split || (v != a && v != b && predicates::orient(pa, pb, d.point(v)) == 0 &&
                                  arc_angle(pa, d.point(v)) < arc_angle(pa, pb) &&
                                  arc_angle(d.point(v), pb) < arc_angle(pa, pb));
            if (e != no_half_edge ? !d.is_constrained(e) : !split)
                fail("insert_constraint returned true but a-b is not a constrained edge");
        }
    }
    const int moves = in.ConsumeIntegralInRange<int>(0, 3);
    for (int m = 0; m < moves && !verts.empty(); ++m) {
        const VertexId v = verts[in.ConsumeIntegralInRange<std::size_t>(0, verts.size() - 1)];
        const double angle = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-12, -1));
        Vec3 perp = cross(d.point(v), Vec3{0.6, 0.0, 0.8});
        if (!(norm(perp) > 1e-6))
            perp = cross(d.point(v), Vec3{0, 1, 0});
        const Vec3 to = normalized(rotate(d.point(v), normalized(perp), angle));
        char buf[160];
        std::snprintf(buf, sizeof buf, "  move_vertex(%u, {%a, %a, %a})\n", v, to.x, to.y, to.z);
        g_ops += buf;
        if (print)
            std::fputs(buf, stderr);
        const Vec3 before = d.point(v);
        const bool moved = d.move_vertex(v, to);
        if (!(d.point(v) == (moved ? to : before)))
            fail("move_vertex left the vertex elsewhere");
        expect_valid(d, "move_vertex");
    }
    return 0;
}
