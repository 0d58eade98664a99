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
    // Half-edges in the order of (smaller node, larger node, half-edge index): equal edges are
    // adjacent, first face first. Bucketed by the smaller node (a counting sort), then each
    // bucket (a node's few edges) sorted by the larger node: no global sort, and 56 bytes per
    // node of scratch instead of 72 for sorting keys and indices.
    const std::size_t nh = 3 * nf;
    auto ends = [&](std::size_t h) {
        const auto& face = mesh.faces[h / 3];
        std::uint32_t a = face[h % 3], b = face[(h % 3 + 1) % 3];
        return a < b ? std::pair{a, b} : std::pair{b, a};
    };
    std::vector<std::uint32_t> start(nn + 1, 0);
    for (std::size_t h = 0; h < nh; ++h) ++start[ends(h).first + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::pair<std::uint32_t, std::uint32_t>> bucket(nh); // (larger node, half-edge)
    {
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (std::size_t h = 0; h < nh; ++h) {
            auto [lo, hi] = ends(h);
            bucket[fill[lo]++] = {hi, std::uint32_t(h)};
        }
    }
    for (std::size_t v = 0; v < nn; ++v) std::sort(bucket.begin() + start[v], bucket.begin() + start[v + 1]);

    MeshTopology t;
    t.face_edges.assign(nf, {-1, -1, -1});
    t.edge_nodes.reserve(nh / 2 + 16);
    t.edge_faces.reserve(nh / 2 + 16);
    for (std::size_t v = 0; v < nn; ++v) {
        for (std::size_t i = start[v], end = start[v + 1]; i < end;) {
            std::size_t j = i + 1;
            while (j < end && bucket[j].first == bucket[i].first) ++j;
            if (j - i > 2)
                throw DataError("mesh: edge " + std::to_string(v) + "-" + std::to_string(bucket[i].first) +
                                " is shared by " + std::to_string(j - i) + " faces (non-manifold)");
            auto e = std::int32_t(t.edge_nodes.size());
            std::uint32_t h0 = bucket[i].second;
            std::int32_t f0 = std::int32_t(h0 / 3);
            int k0 = int(h0 % 3);
            t.edge_nodes.push_back({std::int32_t(mesh.faces[f0][k0]), std::int32_t(mesh.faces[f0][(k0 + 1) % 3])});
            t.face_edges[f0][k0] = e;
            if (j - i == 2) {
                std::uint32_t h1 = bucket[i + 1].second;
                std::int32_t f1 = std::int32_t(h1 / 3);
                t.face_edges[f1][h1 % 3] = e;
                t.edge_faces.push_back({f0, f1});
            } else {
                t.edge_faces.push_back({f0, -1});
                t.boundary_edges.push_back(e);
            }
            i = j;
        }
    }
    std::vector<std::uint32_t>().swap(start);
    std::vector<std::pair<std::uint32_t, std::uint32_t>>().swap(bucket);
    t.face_faces.assign(nf, {-1, -1, -1}); // after the buckets are gone: the peak is lower
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
