#include "globemesh/mesher.hpp"

#include "mesher_state.hpp"


#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "../delaunay/hilbert.hpp"
#include "star_search.hpp"

namespace globemesh {

namespace mesher_internal {
namespace {

// The tuned constants of the stages still here (bench/RESULTS-mesher.md has the measurements).
// The output splits a node between two fans of ocean (close_straits) this far into each fan.
constexpr double pinch_apart = 1e-7; // 0.64 m

} // namespace
} // namespace mesher_internal

using namespace mesher_internal;

Mesh mesh_boundary(const Boundary& boundary, const std::function<double(const Vec3&)>& size_km,
                   const MesherOptions& options, MesherReport* report_out, const Progress& progress,
                   StageTimings* timings) {
    MesherReport local_report;
    MesherReport& report = report_out ? *report_out : local_report;
    report = MesherReport{};
    Mesher m(SphericalDelaunay::Options{1e-12, options.seed}, size_km, report);
    SphericalDelaunay& dt = m.dt;

    // ---- 1. boundary nodes and segments --------------------------------------------------------
    auto t0 = Clock::now();
    const std::vector<VertexId> ids = insert_boundary(m, boundary);
    globemesh::report(progress, 0.05, "insert_boundary");
    if (timings) timings->add("insert_boundary", seconds_since(t0));
    t0 = Clock::now();
    recover_segments(m, boundary, ids);
    globemesh::report(progress, 0.1, "recover");
    if (timings) timings->add("recover", seconds_since(t0));

    // ---- 2. classify -------------------------------------------------------------------------
    t0 = Clock::now();
    classify_ocean(m, boundary, options);
    if (options.inlet_width > 0 && !boundary.empty()) close_inlets(m, options, report);
    globemesh::report(progress, 0.15, "classify");
    mark_sharp_corners(m);
    estimate_nodes(m, options);
    if (timings) timings->add("classify", seconds_since(t0));

    // ---- 3. lattice and refinement -----------------------------------------------------------
    t0 = Clock::now();
    const auto lattice_first = static_cast<VertexId>(dt.vertex_count()); // the lattice nodes follow
    // The lattice's points over the whole sphere may be a few times the nodes asked for (the
    // global ocean: 1.5 times), not more.
    if (options.lattice_km > 0)
        report.lattice_nodes = fill_lattice(m, options.lattice_km, 4.0 * double(report.estimated_nodes) + 1000);
    refine(m, progress);
    if (timings) timings->add("refine", seconds_since(t0));

    // ---- 5. improve --------------------------------------------------------------------------
    t0 = Clock::now();
    std::vector<char> as_made = smooth(m, options, lattice_first, progress);
    improve_quality(m, options, as_made);
    std::vector<TriangleId> island_faces;
    report.island_centroids_left = clear_dropped_islands(m, boundary, report, island_faces);
    if (timings) timings->add("improve", seconds_since(t0));
    if (options.land) {
        t0 = Clock::now();
        std::vector<TriangleId> left;
        BoundaryLoops loops;
        remove_land_faces(m, *options.land, std::move(island_faces), options.inlet_area, report, left, loops);
        report.land_faces_nudged = nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        if (options.close_straits && !left.empty()) {
            close_straits(m, *options.land, left, options, loops, report);
            report.land_faces_at.clear();
            if (!left.empty()) report.land_faces_nudged += nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        }
        report.land_faces_left = report.land_faces_at.size();
        if (timings) timings->add("land", seconds_since(t0));
    }

    // ---- output ------------------------------------------------------------------------------
    // The faces first, then the triangulation goes and its points become the nodes in place: the
    // triangulation and the output nodes never coexist (this is the mesher's peak).
    Mesh mesh;
    std::vector<NodeIndex> node_of(dt.vertex_count(), 0xffffffffu);
    std::size_t face_count = 0, node_count = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean) {
            ++face_count;
            for (int i = 0; i < 3; ++i) node_of[dt.vertex(t, i)] = 0;
        }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (node_of[v] == 0) node_of[v] = static_cast<NodeIndex>(node_count++);
    if (node_count == 0) throw DataError("no ocean is left to mesh at this size: the water was closed as inlets or straits, or removed as land; a smaller size keeps it");
    // A vertex between two or more fans of ocean (close_straits closed a strait there at a
    // point): each fan after the first gets a node of its own, pinch_apart into the fan, so
    // that the mesh is a manifold. (fan_corner, fan_node): the corners of those fans' faces and
    // their nodes, sorted; fan_point: the new nodes' points, numbered from node_count.
    std::vector<std::pair<TriangleId, VertexId>> fan_corner;
    std::vector<NodeIndex> fan_node;
    std::vector<Vec3> fan_point;
    {
        std::sort(m.pinched.begin(), m.pinched.end());
        m.pinched.erase(std::unique(m.pinched.begin(), m.pinched.end()), m.pinched.end());
        std::vector<std::tuple<TriangleId, VertexId, NodeIndex>> corners;
        std::vector<std::vector<TriangleId>> fans;
        for (const VertexId v : m.pinched) {
            fans.clear();
            const int n = m.ocean_fans(dt.leaving(v, no_triangle), [&](TriangleId t, int k) {
                if (k == int(fans.size())) fans.emplace_back();
                fans[std::size_t(k)].push_back(t);
            });
            const Vec3& p = dt.point(v);
            for (int k = 1; k < n; ++k) {
                const std::vector<TriangleId>& fan = fans[std::size_t(k)];
                // Towards the centroid of the fan's middle face (inside the fan's angle),
                // pinch_apart or less: every face of the fan must stay counter-clockwise (a
                // sliver of the fan may be thinner than pinch_apart).
                const Vec3 into = m.centroid(fan[fan.size() / 2]) - p;
                const Vec3 dir = normalized(into - dot(into, p) * p);
                auto far_edge = [&](TriangleId t) {
                    int i = 0;
                    while (dt.vertex(t, i) != v) ++i;
                    return std::pair{dt.point(dt.vertex(t, next3(i))), dt.point(dt.vertex(t, prev3(i)))};
                };
                Vec3 q = p;
                for (double d = pinch_apart; d > 1e-15; d *= 0.5) {
                    const Vec3 moved = normalized(p + d * dir);
                    bool ccw = true;
                    for (const TriangleId t : fan) {
                        const auto [a, b] = far_edge(t);
                        ccw = ccw && predicates::orient(moved, a, b) > 0;
                    }
                    if (ccw) {
                        q = moved;
                        break;
                    }
                }
                fan_point.push_back(q);
                const auto node = static_cast<NodeIndex>(node_count + fan_point.size() - 1);
                for (const TriangleId t : fan) corners.emplace_back(t, v, node);
            }
        }
        std::sort(corners.begin(), corners.end());
        for (const auto& [t, v, node] : corners) {
            fan_corner.emplace_back(t, v);
            fan_node.push_back(node);
        }
        report.nodes_split = fan_point.size();
    }
    auto node_at = [&](TriangleId t, VertexId v) {
        if (!fan_corner.empty()) {
            const auto it = std::lower_bound(fan_corner.begin(), fan_corner.end(), std::pair{t, v});
            if (it != fan_corner.end() && *it == std::pair{t, v}) return fan_node[std::size_t(it - fan_corner.begin())];
        }
        return node_of[v];
    };
    mesh.faces.reserve(face_count); // sized once: no doubling, no copy while growing
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        mesh.faces.push_back({node_at(t, dt.vertex(t, 0)), node_at(t, dt.vertex(t, 1)), node_at(t, dt.vertex(t, 2))});
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            TriangleId other = triangle_of(dt.twin(h));
            if (dt.label(other) == ocean) continue;
            VertexId a = dt.origin(h), b = dt.destination(h);
            auto it = m.segments.find(key(a, b));
            EdgeTag tag = it != m.segments.end() && it->second == SegmentKind::open ? EdgeTag::open : EdgeTag::coast;
            mesh.boundary.push_back({node_at(t, a), node_at(t, b), tag});
        }
    }
    std::vector<NodeIndex> cut_nodes; // a node of each face beside a cut
    for (const TriangleId t : m.cut_sides)
        if (dt.is_live(t) && dt.label(t) == ocean) cut_nodes.push_back(node_at(t, dt.vertex(t, 0)));
    // Node k is the k-th vertex used by a face, so moving each down to its index is in place.
    mesh.nodes = m.dt.release_points();
    for (VertexId v = 0; v < node_of.size(); ++v)
        if (node_of[v] != 0xffffffffu) mesh.nodes[node_of[v]] = mesh.nodes[v];
    mesh.nodes.resize(node_count);
    mesh.nodes.insert(mesh.nodes.end(), fan_point.begin(), fan_point.end());
    mesh.nodes.shrink_to_fit(); // the triangulation is gone: the copy is not the peak
    std::vector<NodeIndex>().swap(node_of);
    if (!cut_nodes.empty()) {
        // The basins the closed straits cut off: the mesh's pieces (union-find over the nodes
        // through the faces) beside a cut, but for the largest.
        std::vector<NodeIndex> parent(mesh.nodes.size());
        for (NodeIndex i = 0; i < parent.size(); ++i) parent[i] = i;
        auto find = [&](NodeIndex i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        for (const auto& f : mesh.faces) {
            const NodeIndex r = find(f[0]);
            for (int k = 1; k < 3; ++k) parent[find(f[k])] = r;
        }
        std::unordered_map<NodeIndex, double> area; // steradians per piece beside a cut
        for (const NodeIndex n : cut_nodes) area.emplace(find(n), 0.0);
        std::vector<std::uint32_t> faces_of(mesh.nodes.size(), 0);
        for (const auto& f : mesh.faces) ++faces_of[find(f[0])];
        const NodeIndex largest = static_cast<NodeIndex>(std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
        area.erase(largest);
        for (const auto& f : mesh.faces)
            if (auto it = area.find(find(f[0])); it != area.end())
                it->second += spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]);
        for (const auto& [r, a] : area) report.seas_cut_off.push_back(a * earth_radius_km * earth_radius_km);
        std::sort(report.seas_cut_off.rbegin(), report.seas_cut_off.rend());
    }
    std::vector<double> ocean_angle(mesh.nodes.size(), 0.0);
    std::vector<char> on_boundary(mesh.nodes.size(), 0);
    for (const auto& e : mesh.boundary) on_boundary[e.a] = on_boundary[e.b] = 1;
    for (const auto& f : mesh.faces)
        for (int i = 0; i < 3; ++i) {
            if (!on_boundary[f[i]]) continue;
            const Vec3& p = mesh.nodes[f[i]];
            const Vec3& q = mesh.nodes[f[next3(i)]];
            const Vec3& r = mesh.nodes[f[prev3(i)]];
            ocean_angle[f[i]] += std::atan2(norm(cross(q - p, r - p)), dot(q - p, r - p));
        }
    std::vector<char> sharp(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (on_boundary[v] && ocean_angle[v] < 60.0 * deg_to_rad) {
            sharp[v] = 1;
            ++report.sharp_corners;
        }
    for (const auto& f : mesh.faces)
        if (sharp[f[0]] || sharp[f[1]] || sharp[f[2]]) ++report.sharp_corner_faces;
    Field target{"target_size", "target edge length", "km", "", {}};
    target.values.reserve(mesh.nodes.size());
    for (const Vec3& p : mesh.nodes) target.values.push_back(size_km(p));
    mesh.node_fields.push_back(std::move(target));
    globemesh::report(progress, 1.0, "improve");
    return mesh;
}

} // namespace globemesh

