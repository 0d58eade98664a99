// --check: the invariants of mesh.hpp, checked independently of how the mesh was built
// (Triangle's -C, geogram's check_consistency).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "globemesh/mesh_stats.hpp"

namespace globemesh {

std::vector<std::string> check_mesh(const Mesh &mesh, std::size_t limit) {
    std::vector<std::string> problems;
    auto fail = [&](std::string message) {
        if (problems.size() < limit)
            problems.push_back(std::move(message));
    };
    const std::size_t n = mesh.nodes.size();
    for (std::size_t i = 0; i < n; ++i) {
        const double r = norm(mesh.nodes[i]);
        if (!(std::abs(r - 1.0) < 1e-12))
            fail("node " + std::to_string(i) + " is not a unit vector");
    }
    // Directed edge (a, b) -> count; key a * n + b (n < 2^32, fits in 64 bits).
    std::unordered_map<std::uint64_t, int> directed;
    directed.reserve(mesh.faces.size() * 3);
    auto key = [n](NodeIndex a, NodeIndex b) { return std::uint64_t(a) * n + b; };
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &t = mesh.faces[f];
        const std::string name = "face " + std::to_string(f);
        if (t[0] >= n || t[1] >= n || t[2] >= n) {
            fail(name + " has a node index out of range");
            continue;
        }
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            fail(name + " repeats a node");
            continue;
        }
        // A floating-point sign is enough here: a face too thin for it to be certain is itself
        // a defect worth reporting.
        if (!(dot(mesh.nodes[t[0]], cross(mesh.nodes[t[1]], mesh.nodes[t[2]])) > 0))
            fail(name + " is not counter-clockwise seen from outside");
        for (int k = 0; k < 3; ++k) {
            if (++directed[key(t[k], t[(k + 1) % 3])] == 2)
                fail("edge " + std::to_string(t[k]) + "-" + std::to_string(t[(k + 1) % 3]) +
                     " is used twice in the same direction (faces not consistently oriented)");
        }
    }
    // Edges with no face on the other side are the boundary, oriented as their face.
    std::vector<std::uint64_t> open_edges;
    for (const auto &[k, count] : directed) {
        const auto a = static_cast<NodeIndex>(k / n), b = static_cast<NodeIndex>(k % n);
        if (!directed.count(key(b, a)))
            open_edges.push_back(k);
    }
    std::vector<std::uint64_t> listed;
    for (const auto &e : mesh.boundary) {
        if (e.a >= n || e.b >= n) {
            fail("boundary edge with a node index out of range");
            continue;
        }
        listed.push_back(key(e.a, e.b));
    }
    std::sort(open_edges.begin(), open_edges.end());
    std::sort(listed.begin(), listed.end());
    if (open_edges != listed)
        fail("the boundary list (" + std::to_string(listed.size()) +
             " edges) differs from the edges with a face on one side only (" +
             std::to_string(open_edges.size()) + ")");
    for (const auto &f : mesh.node_fields)
        if (f.values.size() != n)
            fail("node field '" + f.name + "' has the wrong size");
    for (const auto &f : mesh.face_fields)
        if (f.values.size() != mesh.faces.size())
            fail("face field '" + f.name + "' has the wrong size");
    return problems;
}

} // namespace globemesh
