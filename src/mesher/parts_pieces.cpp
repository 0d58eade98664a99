// The joined mesh's pieces apart (mesh_parts): closed by the inlet rule as one part closes its
// own (pieces.cpp), and the basins the closed straits cut off told.
#include <algorithm>
#include <map>

#include "globemesh/passages.hpp"
#include "mesher_state.hpp"
#include "parts_smooth.hpp"

namespace globemesh::mesher_internal {

namespace {

struct Piece {
    std::size_t first_face = 0, faces = 0;
    double area = 0, perimeter = 0; // radians
    bool open = false;              // touches an open (sea) boundary
    bool closes = false;
};

bool on_a_passage(const Mesh &mesh, const std::vector<NodeIndex> &root, NodeIndex piece,
                  const MesherOptions &options) {
    if (options.passages.empty())
        return false;
    for (const auto &t : mesh.faces)
        if (root[t[0]] == piece)
            for (const std::vector<Vec3> &line : options.passages)
                if (line_meets_triangle(line, mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]))
                    return true;
    return false;
}

/// Removes the faces of the closing pieces, their boundary edges and nodes.
void remove_pieces(Mesh &mesh, const std::vector<NodeIndex> &root,
                   const std::map<NodeIndex, Piece> &pieces) {
    std::vector<char> dead_node(mesh.nodes.size(), 0), dead_face(mesh.faces.size(), 0);
    for (const auto &[r, p] : pieces)
        dead_node[r] = p.closes;
    for (NodeIndex v = 0; v < mesh.nodes.size(); ++v)
        dead_node[v] = dead_node[root[v]];
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        dead_face[f] = dead_node[mesh.faces[f][0]];
    std::erase_if(mesh.boundary, [&](const BoundaryEdge &e) { return dead_node[e.a] != 0; });
    parts_detail::compact_mesh(mesh, dead_node, dead_face);
}

} // namespace

void close_joined_pieces(Mesh &mesh, const std::vector<NodeIndex> &cut_nodes, const SizeFn &size_km,
                         const MesherOptions &options, MesherReport &report) {
    if (mesh.boundary.empty())
        return; // no coast: one piece
    const auto [root, largest] = mesh_pieces(mesh);
    std::map<NodeIndex, Piece> pieces; // but the largest, by root
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &t = mesh.faces[f];
        if (root[t[0]] == largest)
            continue;
        const auto [it, added] = pieces.try_emplace(root[t[0]], Piece{f});
        ++it->second.faces;
        it->second.area +=
            spherical_triangle_area(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]);
    }
    for (const BoundaryEdge &e : mesh.boundary)
        if (const auto it = pieces.find(root[e.a]); it != pieces.end()) {
            it->second.perimeter += arc_angle(mesh.nodes[e.a], mesh.nodes[e.b]);
            it->second.open = it->second.open || e.tag == EdgeTag::open;
        }
    const bool may_close =
        !options.keep_inland_seas && options.close_pieces_apart && options.inlet_width > 0;
    std::size_t faces_closed = 0;
    for (auto &[r, p] : pieces) {
        const auto &t = mesh.faces[p.first_face];
        const double h =
            km_to_rad(size_km(normalized(mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]])));
        p.closes = may_close && !p.open && inlet_closes(p.area, p.perimeter, h, options) &&
                   !on_a_passage(mesh, root, r, options);
        if (p.closes) {
            report.straits_water_km2 += p.area * earth_radius_km * earth_radius_km;
            faces_closed += p.faces;
        }
    }
    // The pieces left: each cut off by a closing in some part (a part may take water for a
    // pocket at its border with no cut of its own), but a lake kept with keep_inland_seas,
    // where only those beside a cut are.
    std::map<NodeIndex, double> basins;
    for (const auto &[r, p] : pieces)
        if (!options.keep_inland_seas && !p.closes)
            basins.emplace(r, p.area);
    for (const NodeIndex n : cut_nodes)
        if (const auto it = pieces.find(root[n]); it != pieces.end() && !it->second.closes)
            basins.emplace(root[n], it->second.area);
    for (const auto &[r, area] : basins)
        report.seas_cut_off.push_back(area * earth_radius_km * earth_radius_km);
    std::sort(report.seas_cut_off.rbegin(), report.seas_cut_off.rend());
    report.water_faces_removed += faces_closed;
    if (faces_closed > 0)
        remove_pieces(mesh, root, pieces);
}

} // namespace globemesh::mesher_internal
