// Edges and neighbours from the faces: see mesh_topology.hpp.
#include "mesh_topology.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <string>

#include "disjoint_sets.hpp"
#include "fresh_memory.hpp"
#include "globemesh/error.hpp"
#include "ordered_blocks.hpp"

namespace globemesh::io {

namespace {
// Below this many half-edges the buckets are sorted on the calling thread alone.
constexpr std::size_t sort_alone = std::size_t(1) << 16;

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
    if (a > b)
        std::swap(a, b);
    return (std::uint64_t(a) << 32) | b;
}

// The one topology a SharedTopology scope shares: its mesh, the topology kept (or, after
// let_go, only watched).
struct TopologySlot {
    std::mutex mutex;
    const Mesh *mesh = nullptr;
    std::shared_ptr<const MeshTopology> kept;
    std::weak_ptr<const MeshTopology> watched;
    bool holding = true;
};
TopologySlot &slot() {
    static TopologySlot s;
    return s;
}
} // namespace

std::shared_ptr<const MeshTopology> topology_of(const Mesh &mesh) {
    TopologySlot &s = slot();
    std::unique_lock<std::mutex> lock(s.mutex);
    if (s.mesh != &mesh) {
        lock.unlock(); // not the shared mesh: built apart, another mesh's build not waited for
        return std::make_shared<const MeshTopology>(build_topology(mesh));
    }
    if (auto alive = s.watched.lock()) {
        if (!s.holding)
            s.kept.reset(); // let go: this caller holds it alone now
        return alive;
    }
    auto built = std::make_shared<const MeshTopology>(build_topology(mesh));
    s.watched = built;
    if (s.holding)
        s.kept = built;
    return built;
}

SharedTopology::SharedTopology(const Mesh &mesh) {
    TopologySlot &s = slot();
    const std::lock_guard<std::mutex> lock(s.mutex);
    if (s.mesh)
        return; // an outer scope (of this mesh or another) has the slot
    s.mesh = &mesh;
    s.holding = true;
    owner_ = true;
}

SharedTopology::~SharedTopology() {
    if (!owner_)
        return;
    TopologySlot &s = slot();
    const std::lock_guard<std::mutex> lock(s.mutex);
    s.mesh = nullptr;
    s.kept.reset();
    s.watched.reset();
}

void SharedTopology::let_go(const Mesh &mesh) {
    TopologySlot &s = slot();
    const std::lock_guard<std::mutex> lock(s.mutex);
    if (s.mesh != &mesh)
        return;
    s.holding = false; // the next topology_of takes the slot's pointer over
}

MeshTopology build_topology(const Mesh &mesh) {
    const std::size_t nf = mesh.faces.size(), nn = mesh.nodes.size();
    if (nf * 3 >= std::size_t(INT32_MAX))
        throw DataError("mesh: too many faces for 32-bit indices");
    for (std::size_t f = 0; f < nf; ++f) {
        const auto &t = mesh.faces[f];
        for (auto v : t)
            if (v >= nn)
                throw DataError("mesh: face " + std::to_string(f) + " uses node " +
                                std::to_string(v) + " but the mesh has " + std::to_string(nn) +
                                " nodes");
        if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
            throw DataError("mesh: face " + std::to_string(f) + " repeats a node");
    }
    // Half-edges in the order of (smaller node, larger node, half-edge index): equal edges are
    // adjacent, first face first. Bucketed by the smaller node (a counting sort), then each
    // bucket (a node's few half-edges) sorted by the larger node, which is looked up again in
    // the face rather than stored: 4 bytes per half-edge, 28 to 32 bytes per node of scratch.
    const std::size_t nh = 3 * nf;
    auto ends = [&](std::uint32_t h) {
        const auto &face = mesh.faces[h / 3];
        std::uint32_t a = face[h % 3], b = face[(h % 3 + 1) % 3];
        return a < b ? std::pair{a, b} : std::pair{b, a};
    };
    // The scratch and the edges are fresh memory (fresh_memory.hpp), at 1.7e7 nodes over a GB.
    auto start = fresh_array<std::uint32_t>(nn + 1);
    std::fill(start.get(), start.get() + nn + 1, 0);
    for (std::uint32_t h = 0; h < nh; ++h)
        ++start[ends(h).first + 1];
    std::partial_sum(start.get(), start.get() + nn + 1, start.get());
    auto bucket = fresh_array<std::uint32_t>(nh);
    {
        auto fill = fresh_array<std::uint32_t>(nn);
        std::copy(start.get(), start.get() + nn, fill.get());
        for (std::uint32_t h = 0; h < nh; ++h)
            bucket[fill[ends(h).first]++] = h;
    }
    auto by_larger_node = [&](std::uint32_t a, std::uint32_t b) {
        return std::pair{ends(a).second, a} < std::pair{ends(b).second, b};
    };
    // The buckets sorted on every core, each thread a range of nodes with about an equal share
    // of the half-edges (the keys are distinct: the same order on any number of threads).
    auto sort_nodes = [&](std::size_t v0, std::size_t v1) {
        for (std::size_t v = v0; v < v1; ++v)
            std::sort(bucket.get() + start[v], bucket.get() + start[v + 1], by_larger_node);
    };
    const std::size_t parts = nh < sort_alone ? 1 : block_threads();
    std::vector<std::size_t> cut{0};
    for (std::size_t k = 1; k < parts; ++k)
        cut.push_back(std::size_t(
            std::upper_bound(start.get(), start.get() + nn, std::uint32_t(nh * k / parts)) -
            start.get()));
    cut.push_back(nn);
    for_each_part(parts, [&](std::size_t k) { sort_nodes(cut[k], cut[k + 1]); });

    // Calls edge(i, j, v) for each edge in order: its half-edges are bucket[i..j), one or two,
    // and v is its smaller node.
    auto for_each_edge = [&](const auto &edge) {
        for (std::size_t v = 0; v < nn; ++v) {
            for (std::size_t i = start[v], end = start[v + 1]; i < end;) {
                const std::uint32_t larger = ends(bucket[i]).second;
                std::size_t j = i + 1;
                while (j < end && ends(bucket[j]).second == larger)
                    ++j;
                if (j - i > 2)
                    throw DataError("mesh: edge " + std::to_string(v) + "-" +
                                    std::to_string(larger) + " is shared by " +
                                    std::to_string(j - i) + " faces (non-manifold)");
                edge(i, j, v);
                i = j;
            }
        }
    };
    std::size_t ne = 0;
    for_each_edge([&](std::size_t, std::size_t, std::size_t) { ++ne; });
    MeshTopology t;
    t.mesh = &mesh;
    fresh_resize(t.edge_halves, ne);
    fresh_resize(t.node_edges, nn + 1);
    std::fill(t.node_edges.begin(), t.node_edges.end(), 0);
    std::size_t e = 0;
    for_each_edge([&](std::size_t i, std::size_t j, std::size_t v) {
        if (j - i == 1)
            t.boundary_edges.push_back(std::int32_t(e));
        t.edge_halves[e++] = {bucket[i], j - i == 2 ? bucket[i + 1] : MeshTopology::no_half_edge};
        t.node_edges[v + 1] = std::uint32_t(e);
    });
    for (std::size_t v = 0; v < nn; ++v)
        t.node_edges[v + 1] = std::max(t.node_edges[v + 1], t.node_edges[v]);
    start.reset();
    bucket.reset();

    // Tags: boundary edges from mesh.boundary by node pair (binary search on sorted keys).
    std::vector<std::pair<std::uint64_t, int>> tagged;
    tagged.reserve(mesh.boundary.size());
    for (const auto &b : mesh.boundary)
        tagged.emplace_back(edge_key(b.a, b.b), int(b.tag));
    std::sort(tagged.begin(), tagged.end());
    t.boundary_tags.reserve(t.boundary_edges.size());
    for (auto e : t.boundary_edges) {
        const auto nodes = t.edge_nodes(std::size_t(e));
        std::uint64_t key = edge_key(std::uint32_t(nodes[0]), std::uint32_t(nodes[1]));
        auto it = std::lower_bound(tagged.begin(), tagged.end(), std::make_pair(key, -1));
        t.boundary_tags.push_back((it != tagged.end() && it->first == key && it->second != 0)
                                      ? it->second
                                      : int(EdgeTag::coast));
    }
    return t;
}

void face_edges(const MeshTopology &topo, std::size_t first, std::size_t count,
                std::vector<std::int32_t> &out) {
    out.assign(3 * count, -1);
    const auto &faces = topo.mesh->faces;
    for (std::size_t i = 0; i < count; ++i) {
        const auto &face = faces[first + i];
        for (std::size_t k = 0; k < 3; ++k) {
            // Side k is a half-edge of one of the edges of its smaller node.
            const auto h = std::uint32_t(3 * (first + i) + k);
            const std::uint32_t v = std::min(face[k], face[(k + 1) % 3]);
            for (std::uint32_t e = topo.node_edges[v]; e < topo.node_edges[v + 1]; ++e)
                if (topo.edge_halves[e][0] == h || topo.edge_halves[e][1] == h) {
                    out[3 * i + k] = std::int32_t(e);
                    break;
                }
        }
    }
}

std::array<std::int32_t, 3> face_faces(const MeshTopology &topo, const std::int32_t *edges_of_f,
                                       std::size_t f) {
    std::array<std::int32_t, 3> neighbours = {-1, -1, -1};
    int n = 0;
    for (int k = 0; k < 3; ++k) {
        const auto ef = topo.edge_faces(std::size_t(edges_of_f[k]));
        const std::int32_t other = ef[0] == std::int32_t(f) ? ef[1] : ef[0];
        if (other >= 0)
            neighbours[n++] = other;
    }
    return neighbours;
}

std::size_t count_boundary_loops(const MeshTopology &topo, std::size_t node_count) {
    DisjointSets<> loops_of(node_count);
    std::vector<char> on_boundary(node_count, 0);
    for (auto e : topo.boundary_edges) {
        const auto nodes = topo.edge_nodes(std::size_t(e));
        const auto a = std::uint32_t(nodes[0]), b = std::uint32_t(nodes[1]);
        on_boundary[a] = on_boundary[b] = 1;
        loops_of.join(b, a);
    }
    std::size_t loops = 0;
    for (std::uint32_t v = 0; v < node_count; ++v)
        if (on_boundary[v] && loops_of.find(v) == v)
            ++loops;
    return loops;
}

std::vector<std::vector<std::size_t>> boundary_loops(const MeshTopology &topo,
                                                     std::size_t node_count) {
    const auto &edges = topo.boundary_edges;
    // Edges starting at each node: first[v] .. first[v + 1] - 1 of by_start.
    std::vector<std::uint32_t> first(node_count + 1, 0), by_start(edges.size());
    for (auto e : edges)
        ++first[topo.edge_nodes(std::size_t(e))[0] + 1];
    for (std::size_t v = 0; v < node_count; ++v)
        first[v + 1] += first[v];
    std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
    for (std::size_t i = 0; i < edges.size(); ++i)
        by_start[fill[topo.edge_nodes(std::size_t(edges[i]))[0]]++] = std::uint32_t(i);
    std::vector<bool> used(edges.size(), false);
    std::vector<std::vector<std::size_t>> loops;
    for (std::size_t start = 0; start < edges.size(); ++start) {
        if (used[start])
            continue;
        std::vector<std::size_t> loop;
        for (std::size_t e = start;;) {
            used[e] = true;
            loop.push_back(e);
            const auto b = topo.edge_nodes(std::size_t(edges[e]))[1];
            std::size_t next = edges.size();
            for (auto k = first[b]; k < first[b + 1] && next == edges.size(); ++k)
                if (!used[by_start[k]])
                    next = by_start[k];
            if (next == edges.size())
                break; // back at the start: every node has as many edges in as out
            e = next;
        }
        loops.push_back(std::move(loop));
    }
    return loops;
}

std::vector<BoundaryRun> loop_runs(const MeshTopology &topo, const std::vector<std::size_t> &loop) {
    const std::size_t n = loop.size();
    const auto tag = [&](std::size_t i) { return topo.boundary_tags[loop[i % n]]; };
    std::size_t first = 0;
    while (first < n && tag(first) == tag(first + n - 1))
        ++first;
    first %= std::max<std::size_t>(n, 1);
    std::vector<BoundaryRun> runs;
    for (std::size_t i = 0; i < n;) {
        BoundaryRun run{first + i, 0, tag(first + i)};
        for (; i < n && (run.count == 0 || tag(first + i) == run.tag); ++i)
            ++run.count;
        runs.push_back(run);
    }
    return runs;
}

namespace {

/// east_longitudes with lon_of(n) giving node n's longitude in [-180, 180).
template <class Lon> bool east_of(const Mesh &mesh, const Lon &lon_of) {
    // A face is cut in [-180, 180) (or in [0, 360) with shift 360) when its longitudes span more
    // than 180 degrees; only a face with a corner beyond +-90 (x < 0) can be in [-180, 180), only
    // one with a corner within +-90 (x > 0) in [0, 360).
    const auto cuts = [&](double shift) {
        const double side = shift == 0 ? 1 : -1;
        for (const auto &f : mesh.faces) {
            if (side * mesh.nodes[f[0]].x >= 0 && side * mesh.nodes[f[1]].x >= 0 &&
                side * mesh.nodes[f[2]].x >= 0)
                continue;
            double lo = 1e9, hi = -1e9;
            for (NodeIndex n : f) {
                const double l = lon_of(n) < 0 ? lon_of(n) + shift : lon_of(n);
                lo = std::min(lo, l);
                hi = std::max(hi, l);
            }
            if (hi - lo > 180)
                return true;
        }
        return false;
    };
    return cuts(0) && !cuts(360);
}

} // namespace

bool east_longitudes(const Mesh &mesh) {
    // Each longitude computed when first asked: only the corners of faces that can be cut are.
    std::vector<double> lon(mesh.nodes.size(), std::nan(""));
    return east_of(mesh, [&](NodeIndex n) {
        if (std::isnan(lon[n]))
            lon[n] = vec_to_lonlat(mesh.nodes[n]).lon;
        return lon[n];
    });
}

std::vector<LonLat> node_lonlats(const Mesh &mesh) {
    std::vector<LonLat> p(mesh.nodes.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        p[i] = vec_to_lonlat(mesh.nodes[i]);
    if (east_of(mesh, [&](NodeIndex n) { return p[n].lon; }))
        for (auto &q : p)
            q.lon += q.lon < 0 ? 360 : 0;
    return p;
}

void tag_boundary_edges(Mesh &mesh, const std::string &what) {
    const MeshTopology topology = [&] {
        try {
            return build_topology(mesh);
        } catch (const DataError &e) {
            throw DataError(what + ": " + e.what());
        }
    }();
    std::vector<BoundaryEdge> boundary;
    for (std::size_t i = 0; i < topology.boundary_edges.size(); ++i) {
        const auto nodes = topology.edge_nodes(std::size_t(topology.boundary_edges[i]));
        boundary.push_back(
            {NodeIndex(nodes[0]), NodeIndex(nodes[1]), EdgeTag(topology.boundary_tags[i])});
    }
    mesh.boundary = std::move(boundary);
}

} // namespace globemesh::io
