// Internal to io/: edges, neighbours and boundary of a triangle mesh, derived from its faces.
//
// Half-edge h = 3 * f + k runs from node k to node k+1 of face f. Edges are numbered in the order
// of their sorted node pair (min, max), so the numbering depends only on the faces. An edge is
// oriented as its first half-edge (lowest face index), so a boundary edge has the mesh on its
// left. Fill (-1) entries come last in a row.
//
// Memory: the edges are stored as their two half-edges, 8 bytes an edge (about 24 bytes per
// node), and where each node's edges start (4 bytes a node); edge nodes, edge faces and face
// neighbours are computed from them and the mesh when asked for. The face-to-edge table is built
// a block of faces at a time (face_edges), by the writer that needs it. Building the edges takes
// 28 to 32 bytes per node of scratch, freed before it returns.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fresh_memory.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/sphere.hpp"
#include "globemesh/ugrid.hpp"

namespace globemesh::io {

struct MeshTopology {
    static constexpr std::uint32_t no_half_edge = UINT32_MAX;

    const Mesh *mesh = nullptr; ///< the mesh it was built from, which must outlive it
    using HalfPair = std::array<std::uint32_t, 2>;
    /// Second is no_half_edge on the boundary.
    std::vector<HalfPair, FreshAllocator<HalfPair>> edge_halves;
    /// The edges whose smaller node is v are node_edges[v] .. node_edges[v + 1] - 1 (nodes + 1
    /// entries).
    std::vector<std::uint32_t, FreshAllocator<std::uint32_t>> node_edges;
    std::vector<std::int32_t> boundary_edges; ///< edge indices with one face, ascending
    std::vector<int> boundary_tags;           ///< EdgeTag of each of boundary_edges

    std::size_t edge_count() const { return edge_halves.size(); }
    /// Nodes of edge e, oriented as its first face.
    std::array<std::int32_t, 2> edge_nodes(std::size_t e) const {
        const std::uint32_t h = edge_halves[e][0];
        const auto &face = mesh->faces[h / 3];
        return {std::int32_t(face[h % 3]), std::int32_t(face[(h % 3 + 1) % 3])};
    }
    /// Faces on each side of edge e; the second is -1 on the boundary.
    std::array<std::int32_t, 2> edge_faces(std::size_t e) const {
        const auto &h = edge_halves[e];
        return {std::int32_t(h[0] / 3), h[1] == no_half_edge ? -1 : std::int32_t(h[1] / 3)};
    }
};

/// Builds the edges. Throws DataError on a face with an out-of-range or repeated node, or an
/// edge shared by more than two faces. Boundary edges take their tag from mesh.boundary (matched
/// by node pair); untagged boundary edges are coast.
MeshTopology build_topology(const Mesh &mesh);

/// The topology of `mesh` for a writer or the statistics: while a SharedTopology of this same
/// mesh is alive, the one it keeps (built at the first call), otherwise built anew. The caller
/// may drop its pointer early to free the memory when nothing else holds it.
std::shared_ptr<const MeshTopology> topology_of(const Mesh &mesh);

/// While alive, every topology_of(mesh) of the mesh it names returns one topology, built once:
/// the CLI's statistics and each writer of a run share it (one at a time per process; an inner
/// scope of the same mesh joins the outer one). The mesh must not change while it lives.
class SharedTopology {
public:
    explicit SharedTopology(const Mesh &mesh);
    ~SharedTopology();
    SharedTopology(const SharedTopology &) = delete;
    SharedTopology &operator=(const SharedTopology &) = delete;
    /// Keeps the topology of `mesh` (when a scope shares it) only until the next topology_of,
    /// whose caller then holds it alone (called before the last writer, which can then free it
    /// early).
    static void let_go(const Mesh &mesh);

private:
    bool owner_ = false; // this scope made the process's slot (an inner one did not)
};

/// The edges of faces first .. first + count - 1: out[3 * i + k] is the edge joining nodes k and
/// k+1 of face first + i, found among the edges of the side's smaller node.
void face_edges(const MeshTopology &topo, std::size_t first, std::size_t count,
                std::vector<std::int32_t> &out);

/// Neighbours of face f across its edges k = 0, 1, 2 (-1 entries last), from its three edges.
std::array<std::int32_t, 3> face_faces(const MeshTopology &topo, const std::int32_t *edges_of_f,
                                       std::size_t f);

/// Replaces mesh.boundary by every boundary edge of the faces, oriented with the mesh on its
/// left, each tagged from the edges read into mesh.boundary (any orientation; coast when not
/// there). Throws DataError beginning with `what` when the faces do not make a mesh (an index out
/// of range, an edge of more than two faces).
void tag_boundary_edges(Mesh &mesh, const std::string &what);

/// Number of boundary loops: connected groups of boundary edges (joined at shared nodes).
std::size_t count_boundary_loops(const MeshTopology &topo, std::size_t node_count);

/// The boundary loops as lists of indices into topo.boundary_edges, each walked with the mesh on
/// its left from its lowest index; at a node where two loops touch, either continuation closes a
/// loop. The ADCIRC/SCHISM boundary strings and the gmsh open groups follow this order.
std::vector<std::vector<std::size_t>> boundary_loops(const MeshTopology &topo,
                                                     std::size_t node_count);

/// A run of boundary edges of one tag along a loop: loop[(first + k) % size], k < count.
struct BoundaryRun {
    std::size_t first = 0, count = 0;
    int tag = 0;
};

/// The runs of a loop, in its order from the start of a run (a loop of one tag is one run from its
/// first edge).
std::vector<BoundaryRun> loop_runs(const MeshTopology &topo, const std::vector<std::size_t> &loop);

/// compute_stats on an already built topology (the writer has one).
MeshStats compute_stats(const Mesh &mesh, const MeshTopology &topo);

/// Whether the mesh's longitudes go in [0, 360) rather than [-180, 180): when that spares every
/// face a cut at the seam (a region across 180, or up to it), which nothing spares a global mesh.
bool east_longitudes(const Mesh &mesh);

/// The nodes in lon/lat for the formats that store degrees (UGRID, ADCIRC, SCHISM, SELAFIN,
/// gmsh, D-Flow FM, FESOM2): longitudes in [-180, 180), or in [0, 360) by east_longitudes.
std::vector<LonLat> node_lonlats(const Mesh &mesh);

} // namespace globemesh::io
