// Edges and neighbours from the faces: see mesh_topology.hpp.
#include "mesh_topology.hpp"

#include <algorithm>
#include <numeric>
#include <string>

#include "globemesh/error.hpp"

namespace globemesh::io {

namespace {
std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t(a) << 32) | b;
}
} // namespace

MeshTopology build_topology(const Mesh& mesh) {
    const std::size_t nf = mesh.faces.size(), nn = mesh.nodes.size();
    if (nf * 3 >= std::size_t(INT32_MAX)) throw DataError("mesh: too many faces for 32-bit indices");
    for (std::size_t f = 0; f < nf; ++f) {
        const auto& t = mesh.faces[f];
        for (auto v : t)
            if (v >= nn)
                throw DataError("mesh: face " + std::to_string(f) + " uses node " + std::to_string(v) +
                                " but the mesh has " + std::to_string(nn) + " nodes");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            throw DataError("mesh: face " + std::to_string(f) + " repeats a node");
    }
    // Half-edges sorted by (key, half-edge index): equal keys are adjacent, first face first.
    std::vector<std::uint64_t> keys(3 * nf);
    for (std::size_t f = 0; f < nf; ++f)
        for (int k = 0; k < 3; ++k) keys[3 * f + k] = edge_key(mesh.faces[f][k], mesh.faces[f][(k + 1) % 3]);
    std::vector<std::uint32_t> order(3 * nf);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
        return keys[x] != keys[y] ? keys[x] < keys[y] : x < y;
    });

    MeshTopology t;
    t.face_edges.assign(nf, {-1, -1, -1});
    t.face_faces.assign(nf, {-1, -1, -1});
    t.edge_nodes.reserve(3 * nf / 2 + 16);
    t.edge_faces.reserve(3 * nf / 2 + 16);
    for (std::size_t i = 0; i < order.size();) {
        std::size_t j = i + 1;
        while (j < order.size() && keys[order[j]] == keys[order[i]]) ++j;
        if (j - i > 2) {
            std::uint64_t key = keys[order[i]];
            throw DataError("mesh: edge " + std::to_string(key >> 32) + "-" + std::to_string(key & 0xffffffffu) +
                            " is shared by " + std::to_string(j - i) + " faces (non-manifold)");
        }
        auto e = std::int32_t(t.edge_nodes.size());
        std::uint32_t h0 = order[i];
        std::int32_t f0 = std::int32_t(h0 / 3);
        int k0 = int(h0 % 3);
        t.edge_nodes.push_back({std::int32_t(mesh.faces[f0][k0]), std::int32_t(mesh.faces[f0][(k0 + 1) % 3])});
        t.face_edges[f0][k0] = e;
        if (j - i == 2) {
            std::uint32_t h1 = order[i + 1];
            std::int32_t f1 = std::int32_t(h1 / 3);
            t.face_edges[f1][h1 % 3] = e;
            t.edge_faces.push_back({f0, f1});
        } else {
            t.edge_faces.push_back({f0, -1});
            t.boundary_edges.push_back(e);
        }
        i = j;
    }
    for (std::size_t f = 0; f < nf; ++f) {
        int n = 0;
        for (int k = 0; k < 3; ++k) {
            const auto& ef = t.edge_faces[t.face_edges[f][k]];
            std::int32_t other = ef[0] == std::int32_t(f) ? ef[1] : ef[0];
            if (other >= 0) t.face_faces[f][n++] = other;
        }
    }
    // Tags: boundary edges from mesh.boundary by node pair (binary search on sorted keys).
    t.edge_tags.assign(t.edge_nodes.size(), int(EdgeTag::interior));
    std::vector<std::pair<std::uint64_t, int>> tagged;
    tagged.reserve(mesh.boundary.size());
    for (const auto& b : mesh.boundary) tagged.emplace_back(edge_key(b.a, b.b), int(b.tag));
    std::sort(tagged.begin(), tagged.end());
    for (auto e : t.boundary_edges) {
        std::uint64_t key = edge_key(std::uint32_t(t.edge_nodes[e][0]), std::uint32_t(t.edge_nodes[e][1]));
        auto it = std::lower_bound(tagged.begin(), tagged.end(), std::make_pair(key, -1));
        t.edge_tags[e] = (it != tagged.end() && it->first == key && it->second != 0) ? it->second : int(EdgeTag::coast);
    }
    return t;
}

std::size_t count_boundary_loops(const MeshTopology& topo, std::size_t node_count) {
    std::vector<std::uint32_t> parent(node_count);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    std::vector<char> on_boundary(node_count, 0);
    for (auto e : topo.boundary_edges) {
        auto a = std::uint32_t(topo.edge_nodes[e][0]), b = std::uint32_t(topo.edge_nodes[e][1]);
        on_boundary[a] = on_boundary[b] = 1;
        a = find(a), b = find(b);
        if (a != b) parent[a] = b;
    }
    std::size_t loops = 0;
    for (std::uint32_t v = 0; v < node_count; ++v)
        if (on_boundary[v] && find(v) == v) ++loops;
    return loops;
}

} // namespace globemesh::io
