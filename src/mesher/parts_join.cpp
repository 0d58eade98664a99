// join_parts (docs/parallel.md, section 5): the part meshes as one mesh, border nodes merged,
// border segments split on one side only split on the other, border edges made interior, then
// the faces near the borders smoothed and flipped (parts_smooth.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <ranges>
#include <set>
#include <unordered_map>

#include "disjoint_sets.hpp"
#include "globemesh/error.hpp"
#include "globemesh/parts.hpp"
#include "globemesh/predicates.hpp"
#include "parts_smooth.hpp"

namespace globemesh {

namespace {

using namespace parts_detail;

/// A node the parts' meshers split off a border node (0.64 m, a pinched strait) is this close
/// to the border (radians): 6 m.
constexpr double near_border_tolerance = 1e-6;

/// Rounds of smoothing and flips over the nodes near the borders after the join (the parts'
/// own improve stage runs four sweeps).
constexpr int smoothing_rounds = 4;

/// The rings of nodes around a border that the join smooths and flips (the border's own
/// included): the parts' faces against a border reach two rings in.
constexpr char zone_rings = 3;

/// How far a node is moved into the second fan of faces at a border node (radians; 0.64 m, the
/// mesher's own offset at a pinched strait): apart beyond mesh-verify's 1e-9 duplicates.
constexpr double pinch_offset = 1e-7;

using Edge = std::pair<NodeIndex, NodeIndex>;

/// The directed boundary edges of a mesh, sorted as 64-bit keys: a std::set of 1e5 coast edges
/// took the join longer than the rest of its scans together.
class DirectedEdges {
public:
    explicit DirectedEdges(const std::vector<BoundaryEdge> &boundary) {
        keys_.reserve(boundary.size());
        for (const BoundaryEdge &e : boundary)
            keys_.push_back(edge_key(e.a, e.b));
        std::sort(keys_.begin(), keys_.end());
    }
    bool has(NodeIndex a, NodeIndex b) const {
        return std::binary_search(keys_.begin(), keys_.end(), edge_key(a, b));
    }

private:
    std::vector<std::uint64_t> keys_;
};

/// The borders' planes and directions (Lunes::border_normal, border_direction), computed once.
struct Borders {
    std::vector<Vec3> normal, direction;
    explicit Borders(const Lunes &lunes) {
        for (int k = 0; k < lunes.count; ++k) {
            normal.push_back(lunes.border_normal(k));
            direction.push_back(lunes.border_direction(k));
        }
    }
    /// Whether p lies on border k, within `tolerance` of its plane (radians).
    bool on(const Vec3 &p, std::size_t k, double tolerance = on_border_tolerance) const {
        return std::abs(dot(p, normal[k])) < tolerance && dot(p, direction[k]) > -tolerance;
    }
    bool on_any(const Vec3 &p) const {
        for (std::size_t k = 0; k < normal.size(); ++k)
            if (on(p, k))
                return true;
        return false;
    }
};

/// The sizes of all parts' nodes, faces and boundary edges together (the join's at most).
struct Sizes {
    std::size_t n = 0, f = 0, b = 0;
};

/// Appends part `m` to `out`: its boundary nodes on a border equal to one already there are
/// that node (two parts share points on their borders alone). The first part is moved, not
/// copied; `total` sizes out's arrays for the others.
void append_part(Mesh &m, const Borders &borders, const Sizes &total,
                 std::map<std::array<double, 3>, NodeIndex> &border, Mesh &out) {
    std::vector<char> open(m.nodes.size(), 0); // on the boundary and a border
    for (const BoundaryEdge &e : m.boundary)
        for (NodeIndex v : {e.a, e.b})
            open[v] = borders.on_any(m.nodes[v]);
    if (out.nodes.empty()) {
        for (std::size_t v = 0; v < m.nodes.size(); ++v)
            if (open[v])
                border.emplace(std::array<double, 3>{m.nodes[v].x, m.nodes[v].y, m.nodes[v].z},
                               static_cast<NodeIndex>(v));
        out.nodes = std::move(m.nodes);
        out.faces = std::move(m.faces);
        out.boundary = std::move(m.boundary);
        for (std::size_t i = 0; i < out.node_fields.size(); ++i)
            out.node_fields[i].values = std::move(m.node_fields[i].values);
        for (std::size_t i = 0; i < out.face_fields.size(); ++i)
            out.face_fields[i].values = std::move(m.face_fields[i].values);
        m = Mesh{};
        return;
    }
    // Room for every part at once (`total`): growing by doubling copied the first part again and
    // again, most of the join's time.
    out.nodes.reserve(total.n);
    for (std::size_t i = 0; i < out.node_fields.size(); ++i)
        out.node_fields[i].values.reserve(total.n);
    out.faces.reserve(total.f);
    for (std::size_t i = 0; i < out.face_fields.size(); ++i)
        out.face_fields[i].values.reserve(total.f);
    out.boundary.reserve(total.b);
    std::vector<NodeIndex> global_of(m.nodes.size());
    for (std::size_t v = 0; v < m.nodes.size(); ++v) {
        const Vec3 &p = m.nodes[v];
        const auto index = static_cast<NodeIndex>(out.nodes.size());
        if (open[v]) {
            const auto [it, added] = border.emplace(std::array<double, 3>{p.x, p.y, p.z}, index);
            if (!added) {
                global_of[v] = it->second;
                continue;
            }
        }
        global_of[v] = index;
        out.nodes.push_back(p);
        for (std::size_t i = 0; i < out.node_fields.size(); ++i)
            out.node_fields[i].values.push_back(m.node_fields[i].values[v]);
    }
    for (const auto &f : m.faces)
        out.faces.push_back({global_of[f[0]], global_of[f[1]], global_of[f[2]]});
    for (std::size_t i = 0; i < out.face_fields.size(); ++i)
        out.face_fields[i].values.insert(out.face_fields[i].values.end(),
                                         m.face_fields[i].values.begin(),
                                         m.face_fields[i].values.end());
    for (const BoundaryEdge &e : m.boundary)
        out.boundary.push_back({global_of[e.a], global_of[e.b], e.tag});
    m = Mesh{}; // its memory back before the next part is copied
}

/// Which nodes border_nodes lists.
enum class Among { open_edges, boundary_edges };

/// The nodes on each border, by latitude (z): of the open boundary edges, or of all boundary
/// edges.
std::vector<std::vector<std::pair<double, NodeIndex>>>
border_nodes(const Mesh &mesh, const Borders &borders, Among among,
             double tolerance = on_border_tolerance) {
    std::vector<std::vector<std::pair<double, NodeIndex>>> on(borders.normal.size());
    std::vector<char> seen(mesh.nodes.size(), 0);
    auto add = [&](NodeIndex v) {
        if (seen[v])
            return;
        seen[v] = 1;
        const Vec3 &p = mesh.nodes[v];
        for (std::size_t k = 0; k < on.size(); ++k)
            if (borders.on(p, k, tolerance))
                on[k].push_back({p.z, v});
    };
    for (const BoundaryEdge &e : mesh.boundary)
        if (e.tag == EdgeTag::open || among == Among::boundary_edges)
            add(e.a), add(e.b);
    for (auto &list : on)
        std::sort(list.begin(), list.end());
    return on;
}

/// The nodes of the other side strictly inside each open edge on a border whose reverse is not
/// in the mesh, in order from its start: of its open edges, or of its coast where it removed
/// its faces on the border as land (the coast meets the border at that node).
std::map<Edge, std::vector<NodeIndex>> border_splits(const Mesh &mesh, const Borders &borders) {
    const DirectedEdges edges(mesh.boundary);
    const auto on = border_nodes(mesh, borders, Among::boundary_edges);
    std::map<Edge, std::vector<NodeIndex>> splits;
    for (const BoundaryEdge &e : mesh.boundary) {
        if (e.tag != EdgeTag::open || edges.has(e.b, e.a))
            continue;
        for (const auto &list : on) {
            auto has = [&](NodeIndex v) {
                return std::any_of(list.begin(), list.end(),
                                   [v](const auto &x) { return x.second == v; });
            };
            if (!has(e.a) || !has(e.b))
                continue;
            const double za = mesh.nodes[e.a].z, zb = mesh.nodes[e.b].z;
            std::vector<NodeIndex> inside;
            for (const auto &x : list)
                if (x.first > std::min(za, zb) && x.first < std::max(za, zb))
                    inside.push_back(x.second);
            if (za > zb)
                std::reverse(inside.begin(), inside.end());
            if (!inside.empty())
                splits[{e.a, e.b}] = inside;
            break;
        }
    }
    return splits;
}

/// The faces of face (a, b, apex) with the nodes `inside` on its side a-b: a fan from the apex,
/// or, where a fan face would fall below join_floor and the apex is on the boundary (`apex_fixed`:
/// no smoothing moves it to mend the fan), a star around a node added at the face's centroid
/// (index `centre`; `star` tells), which the join's smoothing then moves to its best place. A
/// side the other part's refinement split near its end (an archipelago at a border) left a fan
/// face of q 0.21 at a coast node (GSHHG high's Arctic at 15 km in 2 parts; one part 0.301).
std::vector<std::array<NodeIndex, 3>> fan_or_star(const Mesh &mesh, NodeIndex a, NodeIndex b,
                                                  NodeIndex apex, bool apex_fixed,
                                                  const std::vector<NodeIndex> &inside,
                                                  NodeIndex centre, bool &star) {
    std::vector<std::array<NodeIndex, 3>> faces;
    NodeIndex from = a;
    for (NodeIndex v : inside)
        faces.push_back({from, v, apex}), from = v;
    faces.push_back({from, b, apex});
    star = apex_fixed && lowest_quality(mesh.nodes, faces) < join_floor;
    if (!star)
        return faces;
    for (auto &t : faces)
        t[2] = centre; // the side's pieces, then the apex's two sides
    faces.push_back({b, apex, centre});
    faces.push_back({apex, a, centre});
    return faces;
}

/// Splits each face on an edge of `splits` into a fan at the edge's nodes (or a star:
/// fan_or_star), and the edge too.
void split_faces(Mesh &mesh, const std::map<Edge, std::vector<NodeIndex>> &splits,
                 const SizeFn &size_km) {
    if (splits.empty())
        return;
    std::vector<char> starts(mesh.nodes.size(), 0); // a split edge's first node: few
    for (const auto &s : splits)
        starts[s.first.first] = 1;
    std::vector<char> fixed(mesh.nodes.size(), 0); // on the boundary: the smoothing leaves it
    for (const BoundaryEdge &e : mesh.boundary)
        fixed[e.a] = fixed[e.b] = 1;
    const std::size_t faces = mesh.faces.size();
    for (std::size_t f = 0; f < faces; ++f)
        for (int i = 0; i < 3; ++i) {
            const auto face = mesh.faces[f];
            if (!starts[face[i]])
                continue;
            const auto it = splits.find({face[i], face[(i + 1) % 3]});
            if (it == splits.end())
                continue;
            const NodeIndex apex = face[(i + 2) % 3];
            const auto centre = static_cast<NodeIndex>(mesh.nodes.size());
            bool star = false;
            const auto fan = fan_or_star(mesh, face[i], face[(i + 1) % 3], apex, fixed[apex],
                                         it->second, centre, star);
            if (star) {
                const Vec3 x = normalized(mesh.nodes[face[i]] + mesh.nodes[face[(i + 1) % 3]] +
                                          mesh.nodes[apex]);
                mesh.nodes.push_back(x);
                for (Field &field : mesh.node_fields)
                    field.values.push_back(
                        field.name == "target_size" && size_km ? size_km(x) : field.values[apex]);
            }
            mesh.faces[f] = fan[0];
            for (std::size_t j = 1; j < fan.size(); ++j) {
                mesh.faces.push_back(fan[j]);
                for (Field &field : mesh.face_fields)
                    field.values.push_back(field.values[f]);
            }
            break;
        }
    std::vector<BoundaryEdge> boundary;
    for (const BoundaryEdge &e : mesh.boundary) {
        const auto it = splits.find({e.a, e.b});
        if (it == splits.end()) {
            boundary.push_back(e);
            continue;
        }
        NodeIndex from = e.a;
        for (NodeIndex v : it->second)
            boundary.push_back({from, v, e.tag}), from = v;
        boundary.push_back({from, e.b, e.tag});
    }
    mesh.boundary.swap(boundary);
}

/// Nodes near the borders: 1 on a border, k + 1 k rings of faces away (k < zone_rings), 0
/// elsewhere. With `near` (may be null), found among its nodes and grown over its faces alone:
/// exact where every node reached before the last ring is near (all its faces are there), else
/// found again over the whole mesh.
std::vector<char> border_zone(const Mesh &mesh, const Borders &borders, const NearBorders *near) {
    std::vector<char> zone(mesh.nodes.size(), 0);
    for (NodeIndex v = 0; v < mesh.nodes.size(); ++v)
        if ((!near || near->node[v]) && borders.on_any(mesh.nodes[v]))
            zone[v] = 1;
    grow_rings(mesh, near ? &near->faces : nullptr, zone, zone_rings);
    for (NodeIndex v = 0; near && v < mesh.nodes.size(); ++v)
        if (zone[v] && zone[v] < zone_rings && !near->node[v])
            return border_zone(mesh, borders, nullptr);
    return zone;
}

/// Gives each fan of faces at a border node after the first a node of its own, moved
/// pinch_offset into its fan (as the mesher's output does where a closed strait pinches the
/// water): where the parts removed land on both sides of a border node, its faces form two fans.
void split_pinched(Mesh &mesh, const std::vector<char> &zone) {
    std::map<NodeIndex, std::vector<std::uint32_t>> star;
    for (std::uint32_t f = 0; f < mesh.faces.size(); ++f)
        for (NodeIndex v : mesh.faces[f])
            if (zone[v] == 1)
                star[v].push_back(f);
    for (const auto &[v, faces] : star) {
        // Faces sharing an edge at v are one fan (union-find over the star).
        DisjointSets<std::size_t> fan(faces.size());
        std::map<NodeIndex, std::size_t> by_neighbour;
        for (std::size_t i = 0; i < faces.size(); ++i)
            for (NodeIndex u : mesh.faces[faces[i]])
                if (u != v) {
                    const auto [it, added] = by_neighbour.emplace(u, i);
                    if (!added)
                        fan.join(it->second, i);
                }
        std::map<std::size_t, std::vector<std::uint32_t>> fans;
        for (std::size_t i = 0; i < faces.size(); ++i)
            fans[fan.find(i)].push_back(faces[i]);
        if (fans.size() < 2)
            continue;
        for (auto it = std::next(fans.begin()); it != fans.end(); ++it) {
            Vec3 toward{0, 0, 0};
            for (std::uint32_t f : it->second)
                for (NodeIndex u : mesh.faces[f])
                    if (u != v)
                        toward = toward + mesh.nodes[u];
            const Vec3 &p = mesh.nodes[v];
            const Vec3 step = normalized(normalized(toward) - p);
            const auto copy = static_cast<NodeIndex>(mesh.nodes.size());
            mesh.nodes.push_back(normalized(p + pinch_offset * step));
            for (Field &field : mesh.node_fields)
                field.values.push_back(field.values[v]);
            std::set<Edge> fan_edges;
            for (std::uint32_t f : it->second)
                for (int i = 0; i < 3; ++i) {
                    auto &t = mesh.faces[f];
                    fan_edges.insert({t[i], t[(i + 1) % 3]});
                }
            for (BoundaryEdge &e : mesh.boundary)
                if ((e.a == v || e.b == v) && fan_edges.count({e.a, e.b}))
                    (e.a == v ? e.a : e.b) = copy;
            for (std::uint32_t f : it->second)
                for (NodeIndex &u : mesh.faces[f])
                    if (u == v)
                        u = copy;
        }
    }
}

/// The open edges left on a border (the other side's faces there were removed as land) are
/// coast; their nodes may lie up to near_border_tolerance off it (a node the mesher split).
void tag_border_coast(Mesh &mesh, const Borders &borders) {
    const auto on = border_nodes(mesh, borders, Among::open_edges, near_border_tolerance);
    std::vector<int> border_of(mesh.nodes.size(), -1);
    for (std::size_t k = 0; k < on.size(); ++k)
        for (const auto &x : on[k])
            border_of[x.second] = border_of[x.second] == -1 ? int(k) : -2; // -2: a pole
    for (BoundaryEdge &e : mesh.boundary) {
        const int ka = border_of[e.a], kb = border_of[e.b];
        if (e.tag == EdgeTag::open && ka != -1 && kb != -1 && (ka == kb || ka == -2 || kb == -2))
            e.tag = EdgeTag::coast;
    }
}

} // namespace

Mesh join_parts(std::vector<Mesh> &meshes, const Lunes &lunes, const SizeFn &size_km,
                double lattice_km) {
    Mesh out;
    const auto first =
        std::find_if(meshes.begin(), meshes.end(), [](const Mesh &m) { return !m.faces.empty(); });
    if (first == meshes.end())
        throw DataError("no ocean is left to mesh in any part");
    for (const Field &f : first->node_fields)
        out.node_fields.push_back({f.name, f.long_name, f.units, f.standard_name, {}});
    for (const Field &f : first->face_fields)
        out.face_fields.push_back({f.name, f.long_name, f.units, f.standard_name, {}});
    out.attributes = first->attributes;
    const Borders borders(lunes);
    std::map<std::array<double, 3>, NodeIndex> border;
    Sizes total;
    for (const Mesh &m : meshes)
        total.n += m.nodes.size(), total.f += m.faces.size(), total.b += m.boundary.size();
    for (Mesh &m : meshes)
        if (!m.faces.empty())
            append_part(m, borders, total, border, out);
    split_faces(out, border_splits(out, borders), size_km);
    // A boundary edge whose reverse is there too lies between two parts: interior now.
    const DirectedEdges edges(out.boundary);
    std::vector<BoundaryEdge> boundary;
    for (const BoundaryEdge &e : out.boundary)
        if (!edges.has(e.b, e.a))
            boundary.push_back(e);
    out.boundary.swap(boundary);
    // The nodes near the borders, once for the zone and the stitch (where there is a lattice).
    NearBorders near;
    if (lattice_km > 0)
        near = near_borders(out, borders.normal, stitch_reach(lattice_km));
    const NearBorders *near_or_none = lattice_km > 0 ? &near : nullptr;
    std::vector<char> zone = border_zone(out, borders, near_or_none);
    stitch_lattice(out, zone, borders.normal, size_km, lattice_km, near_or_none);
    std::vector<std::uint32_t> faces = zone_faces(out, zone);
    FaceOfEdge face_of = faces_of_edges(out, faces);
    flip_near_borders(out, faces, face_of);
    for (int round = 0; round < smoothing_rounds; ++round) {
        smooth_near_borders(out, zone, faces, round + 1 == smoothing_rounds);
        flip_near_borders(out, faces, face_of);
    }
    // The valence defects the smoothing left: removed, then the flips and two more rounds.
    if (remove_valence_four(out, zone, faces) > 0) {
        faces = zone_faces(out, zone);
        face_of = faces_of_edges(out, faces);
        for (int round = 0; round < 2; ++round) {
            smooth_near_borders(out, zone, faces, true);
            flip_near_borders(out, faces, face_of);
        }
    }
    tag_border_coast(out, borders);
    split_pinched(out, zone);
    return out;
}

} // namespace globemesh
