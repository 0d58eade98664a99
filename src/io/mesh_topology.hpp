// Internal to io/: edges, neighbours and boundary of a triangle mesh, derived from its faces.
//
// Edges are numbered in the order of their sorted node pair (min, max), so the numbering depends
// only on the faces. An edge is oriented as the first face (lowest face index) that uses it, so a
// boundary edge has the mesh on its left. Fill (-1) entries come last in a row.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/ugrid.hpp"

namespace globemesh::io {

struct MeshTopology {
    std::vector<std::array<std::int32_t, 2>> edge_nodes; ///< oriented as its first face
    std::vector<std::array<std::int32_t, 2>> edge_faces; ///< second is -1 on the boundary
    std::vector<std::array<std::int32_t, 3>> face_edges; ///< face_edges[f][k]: nodes k -> k+1
    std::vector<std::array<std::int32_t, 3>> face_faces; ///< neighbours, -1 entries last
    std::vector<std::int32_t> boundary_edges;            ///< edge indices with one face, ascending
    std::vector<int> edge_tags;                          ///< EdgeTag per edge
};

/// Builds the topology. Throws DataError on a face with an out-of-range or repeated node, or an
/// edge shared by more than two faces. Boundary edges take their tag from mesh.boundary (matched
/// by node pair); untagged boundary edges are coast.
MeshTopology build_topology(const Mesh& mesh);

/// Number of boundary loops: connected groups of boundary edges (joined at shared nodes).
std::size_t count_boundary_loops(const MeshTopology& topo, std::size_t node_count);

/// compute_stats on an already built topology (the writer has one).
MeshStats compute_stats(const Mesh& mesh, const MeshTopology& topo);

} // namespace globemesh::io
