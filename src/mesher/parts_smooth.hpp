// Internal to the mesher's parts: the joined mesh made good near the borders (parts_smooth.cpp),
// over a zone of nodes join_parts marks (non-zero near a border) and the faces touching it.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/size_fn.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::parts_detail {

/// The directed edge a -> b as one 64-bit key (FaceOfEdge's, the join's boundary edges').
inline std::uint64_t edge_key(NodeIndex a, NodeIndex b) {
    return (std::uint64_t(a) << 32) | b;
}

/// Numbers the rings of faces around the nodes marked 1 in `ring`, over the faces listed in
/// `faces` (indices into mesh.faces; null: all of them): the nodes of a face with a corner at r,
/// not numbered yet, get r + 1, up to `last`.
void grow_rings(const Mesh &mesh, const std::vector<std::uint32_t> *faces, std::vector<char> &ring,
                char last);

/// The face of each directed edge (edge_key), of the zone's faces: the flips keep it. An open
/// addressing table (linear probes, erased slots marked): std::unordered_map's node per entry
/// made the flips and its building most of the join's smoothing time.
class FaceOfEdge {
public:
    /// Room for `edges` entries at a quarter of the slots (a flip erases two and adds two).
    explicit FaceOfEdge(std::size_t edges = 0);
    /// The face of `key`, or null.
    std::uint32_t *find(std::uint64_t key);
    /// Sets the face of `key` (added where absent).
    void set(std::uint64_t key, std::uint32_t face);
    void erase(std::uint64_t key);

private:
    static constexpr std::uint64_t empty = ~std::uint64_t(0), erased = empty - 1;
    std::size_t slot(std::uint64_t key) const;
    /// The live entries again, without the erased slots (when few empty ones are left).
    void rebuild();
    std::vector<std::uint64_t> keys_;
    std::vector<std::uint32_t> faces_;
    std::size_t mask_ = 0;
    std::size_t filled_ = 0; // slots not empty: entries and erased ones
};

/// The faces with a node in the zone: the only ones the flips and smoothing rewrite (a flip
/// turns two of them into two others of the same four nodes).
std::vector<std::uint32_t> zone_faces(const Mesh &mesh, const std::vector<char> &zone);

/// The face of each directed edge of `faces`.
FaceOfEdge faces_of_edges(const Mesh &mesh, const std::vector<std::uint32_t> &faces);

/// Lawson flips of the edges of `faces` whose opposite node lies inside the circumcircle: the
/// joined mesh Delaunay near the borders as inside.
void flip_near_borders(Mesh &mesh, const std::vector<std::uint32_t> &faces, FaceOfEdge &face_of);

/// One sweep over the free zone nodes: each to the mean of its neighbours where its star's worst
/// face rises, then, with `search`, where that face is still below q 0.8, pattern searches for the
/// most faces above q 0.8 and for the best worst face.
void smooth_near_borders(Mesh &mesh, const std::vector<char> &zone,
                         const std::vector<std::uint32_t> &zone_face_list, bool search);

/// The join makes no face below this quality that it can avoid (the mesher's floor,
/// blunt_floor): a fan split is made a star instead, and a node with four faces stays where its
/// two replacing faces would fall below it.
inline constexpr double join_floor = 0.3;

/// The lowest triangle_quality of `faces` (node triples of `nodes`; no fold test), 1 for none:
/// for faces the join weighs before they are in the mesh.
template <class Faces> double lowest_quality(const std::vector<Vec3> &nodes, const Faces &faces) {
    double q = 1;
    for (const auto &t : faces)
        q = std::min(q, triangle_quality(nodes[t[0]], nodes[t[1]], nodes[t[2]]));
    return q;
}

/// Drops the faces and nodes marked dead (no live face may use a dead node), keeping the
/// others' order, with their fields, `zone` (may be null) and the boundary edges' node indices.
void compact_mesh(Mesh &mesh, const std::vector<char> &dead_node,
                  const std::vector<char> &dead_face, std::vector<char> *zone = nullptr);

/// Removes the free zone nodes with four faces (their quadrilateral becomes two faces, unless one
/// would fall below join_floor and below the four) and compacts the nodes, the faces and `zone`.
/// Returns how many; the zone's faces must then be listed again.
std::size_t remove_valence_four(Mesh &mesh, std::vector<char> &zone,
                                const std::vector<std::uint32_t> &zone_face_list);

/// The nodes within `reach` (radians) of a border's plane, and the faces with such a corner:
/// every face of those nodes. One pass over the nodes and one over the faces.
struct NearBorders {
    std::vector<char> node;
    std::vector<std::uint32_t> faces;
};
NearBorders near_borders(const Mesh &mesh, const std::vector<Vec3> &normals, double reach);

/// How far from the borders' planes stitch_lattice looks (radians), at lattice_km.
double stitch_reach(double lattice_km);

/// Where the band along the borders (`normals`: their planes) is open ocean at the lattice's
/// size (lattice_km), its nodes that are not lattice points are removed and the lattice's points
/// there put in their place (parts_stitch.cpp): its faces become the lattice's, as inside a
/// part. The new nodes take the removed ones' slots (then are appended, or the last nodes fill
/// the slots left); only those next to a node kept off the lattice stay in `zone`. Changes
/// nothing when the band's new triangulation does not fit. Returns the lattice points added.
/// `near`: near_borders of the mesh at stitch_reach(lattice_km), or null (then computed here).
std::size_t stitch_lattice(Mesh &mesh, std::vector<char> &zone, const std::vector<Vec3> &normals,
                           const SizeFn &size_km, double lattice_km,
                           const NearBorders *near = nullptr);

} // namespace globemesh::parts_detail
