// Conversion to Mesh: the ocean triangles become the faces, their vertices the nodes (pinched
// nodes split), with the boundary edges, the seas closed straits cut off, the sharp corners and
// the target size per node.
#include "mesher_state.hpp"

#include "globemesh/parts.hpp"

#include <map>
#include <tuple>

namespace globemesh::mesher_internal {

namespace {

// The output splits a node between two fans of ocean (close_straits) this far into each fan.
constexpr double pinch_apart = 1e-7; // 0.64 m

// A vertex between two or more fans of ocean (close_straits closed a strait there at a point):
// each fan after the first gets a node of its own, pinch_apart into the fan, so that the mesh
// is a manifold.
struct PinchSplit {
    std::vector<std::pair<TriangleId, VertexId>>
        fan_corner;                        // the corners of those fans' faces, sorted
    std::vector<NodeIndex> fan_node;       // and their nodes
    std::vector<Vec3> fan_point;           // the new nodes' points, numbered from node_count
    const std::vector<NodeIndex> &node_of; // every other vertex's node

    // The node of corner v of face t.
    NodeIndex node_at(TriangleId t, VertexId v) const {
        if (!fan_corner.empty()) {
            const auto it = std::lower_bound(fan_corner.begin(), fan_corner.end(), std::pair{t, v});
            if (it != fan_corner.end() && *it == std::pair{t, v})
                return fan_node[std::size_t(it - fan_corner.begin())];
        }
        return node_of[v];
    }
};

// Where the corners of faces already split sit: a face may have two or three pinched corners
// (a coast through a pole), each moved into its own fan.
using MovedCorners = std::map<std::pair<TriangleId, VertexId>, Vec3>;

// The point pinch_apart or less from vertex v towards the centroid of the fan's middle face
// (inside the fan's angle): every face of the fan must stay counter-clockwise (a sliver of the
// fan may be thinner than pinch_apart), with its corners split before this one where they went.
Vec3 into_fan(const Mesher &m, VertexId v, const std::vector<TriangleId> &fan,
              const MovedCorners &moved) {
    const SphericalDelaunay &dt = m.dt;
    const Vec3 &p = dt.point(v);
    const Vec3 into = m.centroid(fan[fan.size() / 2]) - p;
    const Vec3 dir = normalized(into - dot(into, p) * p);
    auto at = [&](TriangleId t, VertexId u) {
        const auto it = moved.find({t, u});
        return it != moved.end() ? it->second : dt.point(u);
    };
    auto far_edge = [&](TriangleId t) {
        int i = 0;
        while (dt.vertex(t, i) != v)
            ++i;
        return std::pair{at(t, dt.vertex(t, next3(i))), at(t, dt.vertex(t, prev3(i)))};
    };
    for (double d = pinch_apart; d > 1e-15; d *= 0.5) {
        const Vec3 moved_p = normalized(p + d * dir);
        bool ccw = true;
        for (const TriangleId t : fan) {
            const auto [a, b] = far_edge(t);
            ccw = ccw && predicates::orient(moved_p, a, b) > 0;
        }
        if (ccw)
            return moved_p;
    }
    return p;
}

// Splits the nodes of Mesher::pinched, numbering the new ones from node_count.
void split_pinched(Mesher &m, std::size_t node_count, PinchSplit &split) {
    const SphericalDelaunay &dt = m.dt;
    std::sort(m.pinched.begin(), m.pinched.end());
    m.pinched.erase(std::unique(m.pinched.begin(), m.pinched.end()), m.pinched.end());
    std::vector<std::tuple<TriangleId, VertexId, NodeIndex>> corners;
    std::vector<std::vector<TriangleId>> fans;
    MovedCorners moved;
    for (const VertexId v : m.pinched) {
        fans.clear();
        const int n = m.ocean_fans(dt.leaving(v, no_triangle), [&](TriangleId t, int k) {
            if (k == int(fans.size()))
                fans.emplace_back();
            fans[std::size_t(k)].push_back(t);
        });
        for (int k = 1; k < n; ++k) {
            const std::vector<TriangleId> &fan = fans[std::size_t(k)];
            split.fan_point.push_back(into_fan(m, v, fan, moved));
            const auto node = static_cast<NodeIndex>(node_count + split.fan_point.size() - 1);
            for (const TriangleId t : fan) {
                corners.emplace_back(t, v, node);
                moved[{t, v}] = split.fan_point.back();
            }
        }
    }
    std::sort(corners.begin(), corners.end());
    for (const auto &[t, v, node] : corners) {
        split.fan_corner.emplace_back(t, v);
        split.fan_node.push_back(node);
    }
    m.report.nodes_split = split.fan_point.size();
}

// Counts the boundary nodes whose ocean angle is below 60 degrees, and the faces at them.
void count_sharp_corners(const Mesh &mesh, MesherReport &report) {
    std::vector<double> ocean_angle(mesh.nodes.size(), 0.0);
    std::vector<char> on_boundary(mesh.nodes.size(), 0);
    for (const auto &e : mesh.boundary)
        on_boundary[e.a] = on_boundary[e.b] = 1;
    for (const auto &f : mesh.faces)
        for (int i = 0; i < 3; ++i) {
            if (!on_boundary[f[i]])
                continue;
            const Vec3 &p = mesh.nodes[f[i]];
            const Vec3 &q = mesh.nodes[f[next3(i)]];
            const Vec3 &r = mesh.nodes[f[prev3(i)]];
            ocean_angle[f[i]] += std::atan2(norm(cross(q - p, r - p)), dot(q - p, r - p));
        }
    std::vector<char> sharp(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (on_boundary[v] && ocean_angle[v] < 60.0 * deg_to_rad) {
            sharp[v] = 1;
            ++report.sharp_corners;
        }
    for (const auto &f : mesh.faces)
        if (sharp[f[0]] || sharp[f[1]] || sharp[f[2]])
            ++report.sharp_corner_faces;
}

// The ocean faces and the boundary edges (tagged open or coast); returns a node of each face
// beside a cut (Mesher::cut_sides).
std::vector<NodeIndex> write_faces(const Mesher &m, const PinchSplit &split, std::size_t face_count,
                                   Mesh &mesh) {
    const SphericalDelaunay &dt = m.dt;
    mesh.faces.reserve(face_count); // sized once: no doubling, no copy while growing
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        mesh.faces.push_back({split.node_at(t, dt.vertex(t, 0)), split.node_at(t, dt.vertex(t, 1)),
                              split.node_at(t, dt.vertex(t, 2))});
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            TriangleId other = triangle_of(dt.twin(h));
            if (dt.label(other) == ocean)
                continue;
            VertexId a = dt.origin(h), b = dt.destination(h);
            const EdgeTag tag = m.is_open(a, b) ? EdgeTag::open : EdgeTag::coast;
            mesh.boundary.push_back({split.node_at(t, a), split.node_at(t, b), tag});
        }
    }
    std::vector<NodeIndex> cut_nodes; // a node of each face beside a cut
    for (const TriangleId t : m.cut_sides)
        if (dt.is_live(t) && dt.label(t) == ocean)
            cut_nodes.push_back(split.node_at(t, dt.vertex(t, 0)));
    return cut_nodes;
}

} // namespace

// The pieces are found by union-find over the nodes through the faces.
MeshPieces mesh_pieces(const Mesh &mesh) {
    DisjointSets pieces(mesh.nodes.size());
    for (const auto &f : mesh.faces)
        for (int k = 1; k < 3; ++k)
            pieces.join(f[0], f[k]);
    MeshPieces out{std::move(pieces).roots(), 0};
    std::vector<std::uint32_t> faces_of(mesh.nodes.size(), 0);
    for (const auto &f : mesh.faces)
        ++faces_of[out.root[f[0]]];
    out.largest = static_cast<NodeIndex>(std::max_element(faces_of.begin(), faces_of.end()) -
                                         faces_of.begin());
    return out;
}

void seas_cut_off(const Mesh &mesh, const std::vector<NodeIndex> &cut_nodes, MesherReport &report) {
    const auto [parent, largest] = mesh_pieces(mesh);
    std::unordered_map<NodeIndex, double> area; // steradians per piece beside a cut
    std::vector<char> beside_cut(mesh.nodes.size(), 0);
    for (const NodeIndex n : cut_nodes)
        if (parent[n] != largest)
            area.emplace(parent[n], 0.0), beside_cut[parent[n]] = 1;
    for (const auto &f : mesh.faces)
        if (beside_cut[parent[f[0]]])
            area[parent[f[0]]] +=
                spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]);
    for (const auto &[r, a] : area)
        report.seas_cut_off.push_back(a * earth_radius_km * earth_radius_km);
    std::sort(report.seas_cut_off.rbegin(), report.seas_cut_off.rend());
}

void keep_border_nodes_whole(Mesher &m, const std::vector<Vec3> &borders) {
    std::erase_if(m.pinched, [&](VertexId v) {
        const Vec3 &p = m.dt.point(v);
        return std::any_of(borders.begin(), borders.end(), [&](const Vec3 &n) {
            return std::abs(dot(p, n)) < on_border_tolerance;
        });
    });
}

Mesh to_mesh(Mesher &m, const std::vector<Vec3> &borders) {
    SphericalDelaunay &dt = m.dt;
    // The faces first, then the triangulation goes and its points become the nodes in place: the
    // triangulation and the output nodes never coexist (this is the mesher's peak).
    Mesh mesh;
    std::vector<NodeIndex> node_of(dt.vertex_count(), 0xffffffffu);
    std::size_t face_count = 0, node_count = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean) {
            ++face_count;
            for (int i = 0; i < 3; ++i)
                node_of[dt.vertex(t, i)] = 0;
        }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (node_of[v] == 0)
            node_of[v] = static_cast<NodeIndex>(node_count++);
    if (node_count == 0)
        throw DataError("no ocean is left to mesh at this size: the water was closed as inlets or "
                        "straits, or removed "
                        "as land; a smaller size keeps it");
    PinchSplit split{{}, {}, {}, node_of};
    split_pinched(m, node_count, split);
    const std::vector<NodeIndex> cut_nodes = write_faces(m, split, face_count, mesh);
    // Node k is the k-th vertex used by a face, so moving each down to its index is in place.
    mesh.nodes = m.dt.release_points();
    for (VertexId v = 0; v < node_of.size(); ++v)
        if (node_of[v] != 0xffffffffu)
            mesh.nodes[node_of[v]] = mesh.nodes[v];
    mesh.nodes.resize(node_count);
    mesh.nodes.insert(mesh.nodes.end(), split.fan_point.begin(), split.fan_point.end());
    mesh.nodes.shrink_to_fit(); // the triangulation is gone: the copy is not the peak
    std::vector<NodeIndex>().swap(node_of);
    if (!cut_nodes.empty() && borders.empty())
        seas_cut_off(mesh, cut_nodes, m.report);
    for (const NodeIndex n : cut_nodes)
        m.report.cut_points.push_back(mesh.nodes[n]);
    count_sharp_corners(mesh, m.report);
    Field target{"target_size", "target edge length", "km", "", {}};
    target.values.reserve(mesh.nodes.size());
    for (const Vec3 &p : mesh.nodes)
        target.values.push_back(m.size_km(p));
    mesh.node_fields.push_back(std::move(target));
    return mesh;
}

} // namespace globemesh::mesher_internal
