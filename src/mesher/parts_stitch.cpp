// The lattice put back across the borders after the join (docs/parallel.md, section 6). Each
// part fills its open ocean with the same icosahedral lattice (lattice_points.hpp), but keeps it
// lattice_clearance spacings off its borders and refines the band between against the border's
// nodes: after the join that band, two or three faces wide along every border, is the only
// place where the open ocean is not the lattice, and its faces were the joined mesh's worst
// (q 0.80 at 1e6 nodes, 0.73 at 4e6, against 0.82 in one part). Where the band is open ocean at
// the lattice's size, its nodes that are not lattice points are removed and the lattice points
// there inserted instead: the faces become the lattice's own, as in one part.
#include "parts_smooth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "globemesh/delaunay.hpp"
#include "globemesh/predicates.hpp"
#include "lattice_points.hpp"

namespace globemesh::parts_detail {

namespace {

using mesher_internal::lattice_level;
using mesher_internal::LatticePoints;

/// How many rings of faces from a border the band's nodes may be removed from (the border's own
/// ring is 1): the parts' lattice ends about two spacings off a border, and its last nodes were
/// smoothed off their lattice points.
constexpr char removed_rings = 6;
/// How many rings around the band are looked at: a node there blocks the removals within
/// blocked_rings of it when it is on the boundary or where the size field is below the lattice's.
constexpr char looked_rings = removed_rings + 2;
constexpr char blocked_rings = 2;
/// A lattice point is not inserted this close to a node kept (spacings): that node stands for it.
constexpr double kept_clearance = 0.5;

constexpr std::uint8_t inside_band = 1;

/// The band to re-mesh: its faces and the removed nodes.
struct Band {
    std::vector<char> removed;         // per node
    std::vector<std::uint32_t> faces;  // of the mesh, ascending
    std::vector<NodeIndex> kept_nodes; // the band faces' other corners
    std::vector<char> kept_lattice;    // per kept node: a lattice point
    std::size_t removed_count = 0;
};

/// The nodes on the boundary or where the size field is below the lattice's (1), and those within
/// blocked_rings rings of one (2, 3, ...), among the nodes near a border.
std::vector<char> blocked_nodes(const Mesh &mesh, const std::vector<char> &ring,
                                const std::vector<std::uint32_t> &near_faces, const SizeFn &size_km,
                                double lattice_km) {
    std::vector<char> blocked(mesh.nodes.size(), 0);
    for (const BoundaryEdge &e : mesh.boundary)
        blocked[e.a] = blocked[e.b] = 1;
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (ring[v] && !blocked[v] && size_km(mesh.nodes[v]) < lattice_level * lattice_km)
            blocked[v] = 1;
    grow_rings(mesh, &near_faces, blocked, blocked_rings + 1);
    return blocked;
}

/// The nodes near a border that are not lattice points, off the boundary and where the size
/// field reaches the lattice's size, at least blocked_rings rings from any that is not.
Band find_band(const Mesh &mesh, const std::vector<char> &ring, const NearBorders &near,
               const LatticePoints &lattice, const SizeFn &size_km, double lattice_km) {
    const std::vector<std::uint32_t> &near_faces = near.faces;
    const std::size_t n = mesh.nodes.size();
    const std::vector<char> blocked = blocked_nodes(mesh, ring, near_faces, size_km, lattice_km);
    Band band;
    band.removed.assign(n, 0);
    for (std::size_t v = 0; v < n; ++v)
        if (near.node[v] && ring[v] && ring[v] <= removed_rings && !blocked[v] &&
            !lattice.is_point(mesh.nodes[v])) {
            band.removed[v] = 1;
            ++band.removed_count;
        }
    // The band: the faces of the removed nodes and of their neighbours, so that its outline
    // runs one ring off the removed nodes, between nodes the parts' lattices left as they made
    // them (their edges are the lattice's; an edge next to a removed node need not be).
    std::vector<char> mark(n, 0); // 1 removed, 2 a neighbour of one
    for (std::size_t v = 0; v < n; ++v)
        mark[v] = band.removed[v];
    auto touches = [&](const std::array<NodeIndex, 3> &t, char m) {
        return mark[t[0]] == m || mark[t[1]] == m || mark[t[2]] == m;
    };
    for (std::uint32_t f : near_faces)
        if (touches(mesh.faces[f], 1))
            for (NodeIndex v : mesh.faces[f])
                if (!mark[v])
                    mark[v] = 2;
    std::vector<char> kept(n, 0);
    for (std::uint32_t f : near_faces) {
        const auto &t = mesh.faces[f];
        if (!touches(t, 1) && !touches(t, 2))
            continue;
        band.faces.push_back(f);
        for (NodeIndex v : t)
            if (!band.removed[v] && !kept[v]) {
                kept[v] = 1;
                band.kept_nodes.push_back(v);
                band.kept_lattice.push_back(lattice.is_point(mesh.nodes[v]));
            }
    }
    return band;
}

/// The band's outline: each edge of a band face whose other side is not a band face, the band on
/// its left.
std::vector<std::pair<NodeIndex, NodeIndex>> band_outline(const Mesh &mesh, const Band &band) {
    FaceOfEdge face_of = faces_of_edges(mesh, band.faces);
    std::vector<std::pair<NodeIndex, NodeIndex>> outline;
    for (std::uint32_t f : band.faces) {
        const auto &t = mesh.faces[f];
        for (int i = 0; i < 3; ++i) {
            const NodeIndex a = t[i], b = t[(i + 1) % 3];
            if (!face_of.find(edge_key(b, a)))
                outline.push_back({a, b});
        }
    }
    return outline;
}

/// The band's new triangulation: its kept nodes and the lattice points inserted, its outline
/// constrained, the triangles inside it labelled inside_band.
class BandTriangulation {
public:
    /// False when the outline cannot be constrained as it is or does not close the band in.
    bool build(const Mesh &mesh, const Band &band,
               const std::vector<std::pair<NodeIndex, NodeIndex>> &outline);
    /// Inserts lattice point p where it lies inside the band, clear of the nodes and the outline.
    bool add(const Vec3 &p, double spacing);
    std::size_t inside_count() const;
    SphericalDelaunay dt;
    std::vector<VertexId> vertex_of; // per kept node (band.kept_nodes order)

private:
    TriangleId hint_ = no_triangle;
};

bool BandTriangulation::build(const Mesh &mesh, const Band &band,
                              const std::vector<std::pair<NodeIndex, NodeIndex>> &outline) {
    std::vector<Vec3> points;
    points.reserve(band.kept_nodes.size());
    for (NodeIndex v : band.kept_nodes)
        points.push_back(mesh.nodes[v]);
    if (points.size() < 4)
        return false;
    vertex_of = dt.insert_points(points);
    if (dt.merged_count() != 0)
        return false;
    std::vector<VertexId> local(mesh.nodes.size(), no_vertex);
    for (std::size_t k = 0; k < band.kept_nodes.size(); ++k)
        local[band.kept_nodes[k]] = vertex_of[k];
    // Most of the outline's edges are edges already (the kept nodes' own Delaunay edges): those
    // are only marked; the others are recovered by flips.
    std::vector<HalfEdge> leaving = dt.vertex_half_edges();
    std::vector<std::pair<VertexId, VertexId>> missing;
    for (const auto &[a, b] : outline) {
        const HalfEdge h = dt.find_edge(leaving[local[a]], local[b]);
        if (h != no_half_edge)
            dt.set_constrained(h, true);
        else
            missing.push_back({local[a], local[b]});
    }
    for (const auto &[a, b] : missing)
        if (!dt.insert_constraint(a, b))
            return false;
    if (!missing.empty())
        leaving = dt.vertex_half_edges();
    std::vector<TriangleId> stack;
    for (const auto &[a, b] : outline) {
        const HalfEdge h = dt.find_edge(leaving[local[a]], local[b]);
        if (h == no_half_edge) // split where a node lies on it: not the band's outline
            return false;
        stack.push_back(triangle_of(h)); // the triangle on its left
    }
    while (!stack.empty()) {
        const TriangleId t = stack.back();
        stack.pop_back();
        if (dt.label(t) == inside_band)
            continue;
        if (!dt.is_solid(t))
            return false; // the outline leaks
        dt.set_label(t, inside_band);
        for (int i = 0; i < 3; ++i)
            if (!dt.is_constrained(half_edge(t, i)))
                stack.push_back(dt.neighbour(t, i));
    }
    return true;
}

bool BandTriangulation::add(const Vec3 &p, double spacing) {
    const TriangleId t = dt.locate(p, hint_);
    hint_ = t;
    if (t == no_triangle || dt.label(t) != inside_band)
        return false;
    // Outside the points' hull (a region's band), the walk ends at a triangle p is beyond.
    for (int i = 0; i < 3; ++i)
        if (predicates::orient(dt.point(dt.vertex(t, (i + 1) % 3)),
                               dt.point(dt.vertex(t, (i + 2) % 3)), p) < 0)
            return false;
    // The nodes near p are those of t and its neighbours.
    const double node_chord = 2 * std::sin(0.5 * kept_clearance * spacing);
    for (int i = 0; i < 3; ++i) {
        const TriangleId u = dt.neighbour(t, i);
        for (const TriangleId x : {t, u})
            for (int k = 0; k < 3; ++k)
                if (norm(dt.point(dt.vertex(x, k)) - p) < node_chord)
                    return false;
    }
    const std::size_t before = dt.vertex_count();
    dt.insert_in_triangle(p, t);
    return dt.vertex_count() > before;
}

std::size_t BandTriangulation::inside_count() const {
    std::size_t count = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        count += dt.is_live(t) && dt.label(t) == inside_band;
    return count;
}

/// Removes the entries of `holes` (ascending) from v, each filled by the last entry.
template <class T> void remove_holes(std::vector<T> &v, const std::vector<std::size_t> &holes) {
    for (auto h = holes.rbegin(); h != holes.rend(); ++h) {
        if (*h + 1 != v.size())
            v[*h] = v.back();
        v.pop_back();
    }
}

/// The band's faces replaced by the triangulation's inside triangles, its removed nodes by the
/// lattice points added: each takes a removed one's slot, the rest are appended, and a slot left
/// over takes the last node (the faces then renumbered). Only the new nodes next to a node kept
/// that is not a lattice point stay in the zone (2): the others are the lattice's, as made.
void replace_band(Mesh &mesh, std::vector<char> &zone, const Band &band,
                  const BandTriangulation &bt, const SizeFn &size_km) {
    const SphericalDelaunay &dt = bt.dt;
    std::vector<NodeIndex> node_of_vertex(dt.vertex_count());
    std::vector<char> off_lattice(dt.vertex_count(), 0); // kept, not a lattice point
    for (std::size_t k = 0; k < band.kept_nodes.size(); ++k) {
        node_of_vertex[bt.vertex_of[k]] = band.kept_nodes[k];
        off_lattice[bt.vertex_of[k]] = !band.kept_lattice[k];
        if (band.kept_lattice[k])
            zone[band.kept_nodes[k]] = 0;
    }
    std::vector<std::size_t> free_slots;
    for (std::size_t v = 0; v < band.removed.size(); ++v)
        if (band.removed[v])
            free_slots.push_back(v);
    std::size_t next_slot = 0;
    for (VertexId v = static_cast<VertexId>(band.kept_nodes.size()); v < dt.vertex_count(); ++v) {
        const Vec3 &p = dt.point(v);
        const double size = size_km(p); // target_size, the only node field
        if (next_slot < free_slots.size()) {
            const std::size_t slot = free_slots[next_slot++];
            mesh.nodes[slot] = p, zone[slot] = 0;
            for (Field &field : mesh.node_fields)
                field.values[slot] = size;
            node_of_vertex[v] = static_cast<NodeIndex>(slot);
        } else {
            node_of_vertex[v] = static_cast<NodeIndex>(mesh.nodes.size());
            mesh.nodes.push_back(p), zone.push_back(0);
            for (Field &field : mesh.node_fields)
                field.values.push_back(size);
        }
    }
    std::vector<std::array<NodeIndex, 3>> triangles;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != inside_band)
            continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        triangles.push_back({node_of_vertex[a], node_of_vertex[b], node_of_vertex[c]});
        if (off_lattice[a] || off_lattice[b] || off_lattice[c])
            for (NodeIndex u : triangles.back())
                zone[u] = std::max<char>(zone[u], 2);
    }
    std::size_t k = 0;
    for (; k < triangles.size() && k < band.faces.size(); ++k)
        mesh.faces[band.faces[k]] = triangles[k];
    mesh.faces.insert(mesh.faces.end(), triangles.begin() + std::ptrdiff_t(k), triangles.end());
    remove_holes(mesh.faces, {band.faces.begin() + std::ptrdiff_t(k), band.faces.end()});
    if (next_slot == free_slots.size())
        return;
    // Fewer points than nodes removed: the last nodes fill the slots left, and are renumbered.
    const std::vector<std::size_t> holes(free_slots.begin() + std::ptrdiff_t(next_slot),
                                         free_slots.end());
    std::vector<NodeIndex> was(mesh.nodes.size()), moved_to(mesh.nodes.size());
    for (std::size_t v = 0; v < was.size(); ++v)
        was[v] = static_cast<NodeIndex>(v);
    remove_holes(was, holes);
    for (std::size_t v = 0; v < was.size(); ++v)
        moved_to[was[v]] = static_cast<NodeIndex>(v);
    remove_holes(mesh.nodes, holes);
    remove_holes(zone, holes);
    for (Field &field : mesh.node_fields)
        remove_holes(field.values, holes);
    for (auto &t : mesh.faces)
        for (NodeIndex &u : t)
            u = moved_to[u];
    for (BoundaryEdge &e : mesh.boundary)
        e.a = moved_to[e.a], e.b = moved_to[e.b];
}

} // namespace

NearBorders near_borders(const Mesh &mesh, const std::vector<Vec3> &normals, double reach) {
    const double limit = std::sin(reach);
    NearBorders near;
    near.node.assign(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        for (const Vec3 &n : normals)
            near.node[v] |= std::abs(dot(mesh.nodes[v], n)) < limit;
    for (std::uint32_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &t = mesh.faces[f];
        if (near.node[t[0]] || near.node[t[1]] || near.node[t[2]])
            near.faces.push_back(f);
    }
    return near;
}

// The rings' faces at the lattice's size are at most 1.4 spacings across (the size fit).
double stitch_reach(double lattice_km) {
    return 1.4 * looked_rings * LatticePoints(lattice_km).spacing();
}

std::size_t stitch_lattice(Mesh &mesh, std::vector<char> &zone, const std::vector<Vec3> &normals,
                           const SizeFn &size_km, double lattice_km, const NearBorders *near) {
    // The joined mesh's only node field is the target size; a face field would need values for
    // the new faces.
    if (lattice_km <= 0 || !size_km || !mesh.face_fields.empty() ||
        std::any_of(mesh.node_fields.begin(), mesh.node_fields.end(),
                    [](const Field &f) { return f.name != "target_size"; }))
        return 0;
    const LatticePoints lattice(lattice_km);
    NearBorders own;
    if (!near)
        own = near_borders(mesh, normals, stitch_reach(lattice_km));
    const NearBorders &near_nodes = near ? *near : own;
    std::vector<char> ring(mesh.nodes.size(), 0); // rings of faces from the border nodes
    for (std::size_t v = 0; v < zone.size(); ++v)
        ring[v] = zone[v] == 1;
    grow_rings(mesh, &near_nodes.faces, ring, looked_rings);
    const Band band = find_band(mesh, ring, near_nodes, lattice, size_km, lattice_km);
    if (band.removed_count == 0)
        return 0;
    BandTriangulation bt;
    if (!bt.build(mesh, band, band_outline(mesh, band)) ||
        bt.inside_count() + 2 * band.removed_count != band.faces.size())
        return 0;
    // The lattice points near the removed nodes, then near each point added (the band may be
    // wider than the removed nodes' neighbourhoods), each tried once, in the order they are met.
    std::vector<LatticePoints::Index> candidates;
    std::vector<bool> met(lattice.index_count(), false); // 48e6 indices at 5 km: bits
    auto meet_near = [&](const Vec3 &p) {
        const std::size_t from = candidates.size();
        lattice.near(p, 1, candidates);
        candidates.erase(std::remove_if(candidates.begin() + std::ptrdiff_t(from), candidates.end(),
                                        [&](const auto &x) {
                                            auto bit = met[lattice.index_of(x)];
                                            const bool seen = bit;
                                            bit = true;
                                            return seen;
                                        }),
                         candidates.end());
    };
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (band.removed[v])
            meet_near(mesh.nodes[v]);
    std::size_t added = 0;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
        const auto x = candidates[k];
        const Vec3 p = lattice.point(x.f, x.i, x.j);
        if (size_km(p) >= lattice_level * lattice_km && bt.add(p, lattice.spacing())) {
            ++added;
            meet_near(p);
        }
    }
    // The band's triangles: two per node it holds inside, less two per node removed.
    if (bt.inside_count() + 2 * band.removed_count != band.faces.size() + 2 * added)
        return 0;
    replace_band(mesh, zone, band, bt, size_km);
    return added;
}

} // namespace globemesh::parts_detail
