// A program outside globemesh linked to globemesh::core alone (standard library only): the
// spherical Delaunay triangulation of Fibonacci points and the mesher on the whole sphere.
// Exit 0 when both meshes are what a closed triangulated sphere must be.
#include <globemesh/delaunay.hpp>
#include <globemesh/mesher.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

namespace {

int failures = 0;
void check(bool ok, const char *what) {
    if (!ok)
        std::fprintf(stderr, "core_consumer: FAILED: %s\n", what);
    failures += !ok;
}

std::vector<globemesh::Vec3> fibonacci_points(int n) {
    std::vector<globemesh::Vec3> points;
    const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double z = 1 - (2 * i + 1) / static_cast<double>(n), r = std::sqrt(1 - z * z);
        points.push_back({r * std::cos(golden * i), r * std::sin(golden * i), z});
    }
    return points;
}

} // namespace

int main() {
    constexpr int n = 5000;
    globemesh::SphericalDelaunay dt;
    dt.insert_points(fibonacci_points(n));
    // Euler on a closed sphere: V - E + F = 2 with 3F = 2E, so F = 2V - 4.
    check(dt.triangle_count() == 2 * n - 4,
          "Delaunay of n points on the sphere has 2n - 4 triangles");
    check(dt.validate().empty(), "the triangulation validates");

    // No rings: the whole sphere is ocean (an aqua-planet), meshed at a uniform 1000 km.
    const globemesh::Mesh mesh =
        globemesh::mesh_boundary({}, [](const globemesh::Vec3 &) { return 1000.0; });
    std::set<std::pair<globemesh::NodeIndex, globemesh::NodeIndex>> edges;
    for (const auto &f : mesh.faces)
        for (int i = 0; i < 3; ++i)
            edges.insert(std::minmax(f[i], f[(i + 1) % 3]));
    const long euler = static_cast<long>(mesh.nodes.size()) - static_cast<long>(edges.size()) +
                       static_cast<long>(mesh.faces.size());
    std::printf("core_consumer: Delaunay %zu triangles; mesher %zu nodes, %zu faces\n",
                dt.triangle_count(), mesh.nodes.size(), mesh.faces.size());
    check(mesh.boundary.empty(), "the aqua-planet mesh has no boundary");
    check(euler == 2, "the aqua-planet mesh is a closed sphere (V - E + F = 2)");
    // Equilateral faces of side h = 1000 km: 4 pi R^2 / (sqrt(3)/4 h^2) = 1,178 faces, half as many
    // nodes (589); a mesh of near-equilateral faces lands well within a third of that.
    check(mesh.nodes.size() > 400 && mesh.nodes.size() < 800, "the node count of a 1000 km mesh");
    return failures == 0 ? 0 : 1;
}
