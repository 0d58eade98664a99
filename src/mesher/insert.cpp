// Boundary insertion and recovery: the rings' nodes triangulated, then their segments made edges.
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

namespace {

// True when a ghost triangle (delaunay.hpp) is left: the boundary nodes lie in one hemisphere.
bool has_ghost(const SphericalDelaunay &dt) {
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && !dt.is_solid(t))
            return true;
    return false;
}

// When every boundary node lies in one hemisphere, ghost triangles close the far side, and the
// far side may be ocean: adds fixed far points until every triangle is solid. A candidate closer
// than 1e-4 rad to a boundary arc is skipped, so none lies on a segment; the flood fill of
// classify_ocean classifies them like any vertex.
void close_far_side(SphericalDelaunay &dt, const Boundary &boundary) {
    if (!has_ghost(dt))
        return;
    std::vector<Vec3> far;
    for (double x : {-1.0, 1.0}) {
        far.push_back({x, 0, 0});
        far.push_back({0, x, 0});
        far.push_back({0, 0, x});
    }
    for (double x : {-1.0, 1.0})
        for (double y : {-1.0, 1.0})
            for (double z : {-1.0, 1.0})
                far.push_back(normalized(Vec3{x, y, z}));
    for (const Vec3 &p : far) {
        bool clear = true;
        for (std::size_t r = 0; r < boundary.rings.size() && clear; ++r) {
            const auto &rn = boundary.rings[r].nodes;
            for (std::size_t i = 0; i < rn.size() && clear; ++i)
                clear = arc_distance(rn[i], rn[(i + 1) % rn.size()], p) > 1e-4;
        }
        if (clear)
            dt.insert(p);
        if (!has_ghost(dt))
            break;
    }
}

} // namespace

std::vector<VertexId> insert_boundary(Mesher &m, const Boundary &boundary) {
    SphericalDelaunay &dt = m.dt;
    std::vector<Vec3> nodes;
    for (const Ring &r : boundary.rings)
        nodes.insert(nodes.end(), r.nodes.begin(), r.nodes.end());
    m.report.boundary_nodes = nodes.size();
    std::vector<VertexId> ids;
    if (boundary.empty()) {
        // An aqua-planet: start from the octahedron and let refinement do the rest.
        std::vector<Vec3> seed = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        dt.insert_points(seed);
        return ids;
    }
    if (nodes.size() < 4)
        throw DataError("the boundary has fewer than 4 nodes: no ocean to mesh");
    ids = dt.insert_points(nodes);
    close_far_side(dt, boundary);
    return ids;
}

void recover_segments(Mesher &m, const Boundary &boundary, const std::vector<VertexId> &ids) {
    std::size_t offset = 0; // of the ring's first node in ids
    for (std::size_t r = 0; r < boundary.rings.size(); ++r) {
        const Ring &ring = boundary.rings[r];
        const std::size_t n = ring.nodes.size();
        m.current_ring = static_cast<std::uint32_t>(r);
        for (std::size_t i = 0; i < n; ++i) {
            VertexId a = ids[offset + i], b = ids[offset + (i + 1) % n];
            SegmentKind kind = i < ring.kinds.size() ? ring.kinds[i] : SegmentKind::coast;
            m.recover(a, b, kind, 0);
        }
        offset += n;
    }
}

} // namespace globemesh::mesher_internal
