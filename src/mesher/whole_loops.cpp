// A part's boundary loops as the whole boundary's (MesherOptions::whole_rings,
// mesher_state.hpp).
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

void note_whole_rings(Mesher &m, const Boundary &boundary, const std::vector<VertexId> &ids,
                      const std::vector<std::vector<std::uint32_t>> &whole_rings) {
    if (whole_rings.empty() || ids.empty())
        return;
    m.whole_ring_from.assign(m.dt.vertex_count(), Mesher::not_given);
    std::size_t offset = 0; // of the ring's first node in ids
    for (std::size_t r = 0; r < boundary.rings.size(); ++r) {
        const std::size_t n = boundary.rings[r].nodes.size();
        for (std::size_t i = 0; r < whole_rings.size() && i < whole_rings[r].size(); ++i) {
            std::uint32_t &from = m.whole_ring_from[ids[offset + i]];
            if (from == Mesher::not_given) // a node two rings share keeps the first's
                from = whole_rings[r][i];
        }
        offset += n;
    }
}

void loops_as_whole(const Mesher &m, const std::vector<HalfEdge> &edges,
                    const std::vector<std::size_t> &starts, BoundaryLoops &loops) {
    if (m.whole_ring_from.empty())
        return;
    const SphericalDelaunay &dt = m.dt;
    auto from = [&](VertexId v) {
        return v < m.whole_ring_from.size() ? m.whole_ring_from[v] : Mesher::not_given;
    };
    // Each half-edge's whole ring: its origin's, or (a node added on a segment since) that of
    // the last of the rings' nodes before it on the loop.
    std::vector<std::uint32_t> ring(edges.size(), no_whole_ring);
    std::uint32_t rings = 0;
    for (std::size_t l = 0; l < starts.size(); ++l) {
        const std::size_t begin = starts[l];
        const std::size_t n = (l + 1 < starts.size() ? starts[l + 1] : edges.size()) - begin;
        std::size_t first = 0;
        while (first < n && from(dt.origin(edges[begin + first])) == Mesher::not_given)
            ++first;
        if (first == n)
            continue; // no node of the rings: the loop's own id stays
        std::uint32_t r = no_whole_ring;
        for (std::size_t s = 0; s < n; ++s) {
            const std::size_t j = begin + (first + s) % n;
            if (const std::uint32_t given = from(dt.origin(edges[j])); given != Mesher::not_given)
                r = given;
            ring[j] = r;
            if (r != no_whole_ring)
                rings = std::max(rings, r + 1);
        }
    }
    // The whole rings one stretch between borders runs along are one loop (an inlet's mouth
    // closed from one ring to another).
    DisjointSets joined(rings);
    for (std::size_t l = 0; l < starts.size(); ++l) {
        const std::size_t begin = starts[l];
        const std::size_t end = l + 1 < starts.size() ? starts[l + 1] : edges.size();
        for (std::size_t j = begin; j < end; ++j) {
            const std::size_t before = j == begin ? end - 1 : j - 1;
            if (ring[j] != no_whole_ring && ring[before] != no_whole_ring)
                joined.join(ring[before], ring[j]);
        }
    }
    std::vector<std::uint32_t> loop_of(rings, no_whole_ring);
    for (std::size_t j = 0; j < edges.size(); ++j) {
        if (ring[j] == no_whole_ring)
            continue; // a border's: the part's loop, as traced
        std::uint32_t &loop = loop_of[joined.find(ring[j])];
        if (loop == no_whole_ring) {
            loop = loops.count++;
            loops.parent.push_back(loop);
        }
        loops.of[dt.origin(edges[j])] = loop;
    }
}

} // namespace globemesh::mesher_internal
