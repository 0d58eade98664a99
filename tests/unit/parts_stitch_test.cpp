// The icosahedral lattice's points (src/mesher/lattice_points.hpp) and the join's stitch of the
// band along the borders back into the lattice (src/mesher/parts_stitch.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "globemesh/delaunay.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/predicates.hpp"
#include "globemesh/sphere.hpp"
#include "lattice_points.hpp"
#include "parts_smooth.hpp"

namespace globemesh {
namespace {

using mesher_internal::LatticePoints;

constexpr double spacing_km = 500;

/// Every lattice point once (each by the face that owns it).
std::vector<Vec3> all_points(const LatticePoints &lattice) {
    std::vector<Vec3> points;
    const int n = lattice.rows();
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i <= n; ++i)
            for (int j = 0; j <= n - i; ++j)
                if (mesher_internal::owns_node(f, i, j, n - i - j))
                    points.push_back(lattice.point(f, i, j));
    return points;
}

/// The Delaunay triangulation of `points` as a mesh of the whole sphere.
Mesh delaunay_mesh(const std::vector<Vec3> &points) {
    SphericalDelaunay dt;
    dt.insert_points(points);
    Mesh mesh;
    mesh.nodes = dt.points();
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t))
            mesh.faces.push_back({dt.vertex(t, 0), dt.vertex(t, 1), dt.vertex(t, 2)});
    return mesh;
}

/// The faces as sets of their corners' coordinates, each rotated to start at its least corner.
std::set<std::array<double, 9>> faces_by_points(const Mesh &mesh) {
    std::set<std::array<double, 9>> out;
    for (auto f : mesh.faces) {
        std::rotate(f.begin(),
                    std::min_element(f.begin(), f.end(),
                                     [&](NodeIndex a, NodeIndex b) {
                                         const Vec3 &p = mesh.nodes[a], &q = mesh.nodes[b];
                                         return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
                                     }),
                    f.end());
        std::array<double, 9> key{};
        for (int k = 0; k < 3; ++k) {
            const Vec3 &p = mesh.nodes[f[k]];
            key[3 * k] = p.x, key[3 * k + 1] = p.y, key[3 * k + 2] = p.z;
        }
        out.insert(key);
    }
    return out;
}

TEST(LatticePoints, each_point_is_one_index_and_known_to_the_bit) {
    const LatticePoints lattice(spacing_km);
    const int n = lattice.rows();
    ASSERT_EQ(n, 16); // 1.2185 / (500 km in radians)
    const std::vector<Vec3> points = all_points(lattice);
    EXPECT_EQ(points.size(), std::size_t(10 * n * n + 2)); // a geodesic grid's count
    for (const Vec3 &p : points) {
        std::vector<LatticePoints::Index> nearest;
        lattice.near(p, 0, nearest);
        ASSERT_EQ(nearest.size(), 1u); // a corner's or an edge's point too: its owner's alone
        EXPECT_TRUE(lattice.is_point(p));
        // Moved by a millionth of the spacing (the jitter's size), it is none.
        EXPECT_FALSE(lattice.is_point(normalized(p + Vec3{1e-6 * lattice.spacing(), 0, 0})));
    }
}

// near(p, reach_for(D)) is the fill's test of which lattice points may lie within D of a
// boundary node (lattice.cpp, near_boundary): a point it misses would be kept however close.
// Checked against every point of the lattice, around points near the icosahedron's corners and
// edges (where a point's neighbours belong to other faces) and elsewhere.
TEST(LatticePoints, near_at_reach_for_holds_every_point_within_the_chord) {
    for (const double km : {1500.0, 500.0, 90.0}) {
        const LatticePoints lattice(km);
        const double s = lattice.spacing();
        const std::vector<Vec3> points = all_points(lattice);
        std::vector<Vec3> around;
        const std::array<Vec3, 12> corners = mesher_internal::ico_corners();
        for (const Vec3 &c : corners) {
            around.push_back(normalized(c + Vec3{0.3 * s, -0.2 * s, 0.1 * s}));
            for (const Vec3 &d : corners)
                if (dot(c, d) > 0.4 && dot(c, d) < 0.99) // an edge's midpoint and a point past it
                    around.push_back(normalized(c + d)),
                        around.push_back(normalized(c + 0.8 * d + Vec3{0, 0.4 * s, 0}));
        }
        for (int k = 0; k < 40; ++k) { // a spiral over the sphere
            const double z = 1 - (k + 0.5) / 20.0, r = std::sqrt(1 - z * z), lon = 2.39996 * k;
            around.push_back({r * std::cos(lon), r * std::sin(lon), z});
        }
        for (const double chord_in_s : {0.3, 1.5, 2.2, 5.0}) {
            const double chord = chord_in_s * s;
            const int reach = lattice.reach_for(chord);
            if (km < 100) { // few to walk where the fill walks many
                EXPECT_LE(reach, static_cast<int>(2 * chord_in_s) + 3) << chord_in_s;
            }
            if (reach < 0) // none holds them: the fill tests every point
                continue;
            for (const Vec3 &p : around) {
                std::vector<LatticePoints::Index> near;
                lattice.near(p, reach, near);
                std::set<std::array<double, 3>> found;
                for (const auto &x : near) {
                    const Vec3 q = lattice.point(x.f, x.i, x.j);
                    found.insert({q.x, q.y, q.z});
                }
                for (const Vec3 &q : points) {
                    if (norm(q - p) < chord) {
                        ASSERT_TRUE(found.count({q.x, q.y, q.z}))
                            << km << " km, chord " << chord_in_s << " spacings, reach " << reach;
                    }
                }
            }
        }
    }
}

/// The lattice without its points within 1.5 spacings of the equator, and in their place
/// nodes of the parts' own along it: on the equator (the border) `per_spacing` to a spacing,
/// and as many on circles `rows` at 0.5 and 1 spacing north and south.
Mesh joined_at_the_equator(const LatticePoints &lattice, int per_spacing, int rows) {
    const double s = lattice.spacing();
    std::vector<Vec3> points;
    for (const Vec3 &p : all_points(lattice))
        if (std::abs(p.z) > std::sin(1.5 * s))
            points.push_back(p);
    const int around = static_cast<int>(std::round(2 * M_PI / s)) * per_spacing;
    for (int r = -rows; r <= rows; ++r)
        for (int k = 0; k < around; ++k) {
            const double lon = 2 * M_PI * (k + 0.37 * (r != 0)) / around, lat = 0.5 * r * s;
            points.push_back(
                {std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)});
        }
    return delaunay_mesh(points);
}

void expect_the_lattice_itself(int per_spacing, int rows) {
    const LatticePoints lattice(spacing_km);
    Mesh mesh = joined_at_the_equator(lattice, per_spacing, rows);
    const std::size_t before = mesh.nodes.size();
    std::vector<char> zone(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        zone[v] = mesh.nodes[v].z == 0; // the border's nodes
    const SizeFn h = [](const Vec3 &) { return spacing_km; };
    const std::size_t added =
        parts_detail::stitch_lattice(mesh, zone, {Vec3{0, 0, 1}}, h, spacing_km);
    EXPECT_GT(added, 0u);
    ASSERT_EQ(zone.size(), mesh.nodes.size());
    // Every node is a lattice point again, and every lattice point is there: the faces are the
    // Delaunay triangulation of the lattice's points (the core's, computed apart).
    const int n = lattice.rows();
    EXPECT_EQ(mesh.nodes.size(), std::size_t(10 * n * n + 2)) << "from " << before;
    for (const Vec3 &p : mesh.nodes)
        EXPECT_TRUE(lattice.is_point(p));
    for (const auto &f : mesh.faces)
        for (NodeIndex v : f)
            ASSERT_LT(v, mesh.nodes.size());
    EXPECT_EQ(faces_by_points(mesh), faces_by_points(delaunay_mesh(all_points(lattice))));
}

TEST(PartsStitch, more_nodes_removed_than_lattice_points_put_back) {
    expect_the_lattice_itself(3, 2); // the last nodes fill the slots left over
}

TEST(PartsStitch, fewer_nodes_removed_than_lattice_points_put_back) {
    expect_the_lattice_itself(1, 0); // the points left over are appended
}

} // namespace
} // namespace globemesh
