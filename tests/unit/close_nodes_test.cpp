// The merge of close coast nodes after the inlets close (src/mesher/close_nodes.cpp), checked on
// the mesher's own state right after it: the triangulation valid, every segment constrained with
// the ocean on one side only, every unconstrained edge between two triangles of one label.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "globemesh/boundary.hpp"
#include "globemesh/sphere.hpp"
#include "globemesh/ugrid.hpp"
#include "mesher_state.hpp"
#include "ring_through.hpp"
#include "support.hpp"

namespace globemesh::mesher_internal {
namespace {

using test::ring_through;

// What is wrong with the mesher's state, in words (empty: nothing).
std::vector<std::string> problems(const Mesher &m) {
    const SphericalDelaunay &dt = m.dt;
    std::vector<std::string> out = dt.validate();
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t))
            continue;
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            if (!dt.is_constrained(h) && dt.label(t) != dt.label(triangle_of(dt.twin(h))))
                out.push_back("labels differ across a free edge at " +
                              Mesher::describe(dt.point(dt.origin(h))));
        }
    }
    for (const auto &[e, kind] : m.segments) {
        const HalfEdge h = dt.find_edge(dt.leaving(e.first), e.second);
        if (h == no_half_edge || !dt.is_constrained(h))
            out.push_back("a segment is not a constrained edge at " +
                          Mesher::describe(dt.point(e.first)));
    }
    return out;
}

// A 4 x 4 degree sea at h = 20 km, with a lake 11 km inland of its west coast; at the head of a
// bay there, a coast node 55 m off the line of its neighbours 0.56 km either side: a notch into
// the land (its ocean fan is the notch's one triangle, whose far side then becomes the coast) or
// a cape into the sea (its land fan is one triangle). Both segments are under h/32.
Boundary sea_with(double off) {
    Boundary b;
    b.rings.push_back(ring_through({{0, 2},
                                    {0.3, 0.3},
                                    {0, 0.005},
                                    {off, 0},
                                    {0, -0.005},
                                    {0.3, -0.3},
                                    {0, -2},
                                    {4, -2},
                                    {4, 2}}));
    b.rings.push_back(ring_through({{-0.3, 0.1}, {-0.3, -0.1}, {-0.1, -0.1}, {-0.1, 0.1}}));
    return b;
}

TEST(CloseNodes, a_node_of_segments_under_h_over_32_goes_and_the_labels_follow_the_coast) {
    for (const double off : {-0.0005, 0.0005}) {
        SCOPED_TRACE(off < 0 ? "notch" : "cape");
        const Boundary b = sea_with(off);
        const std::function<double(const Vec3 &)> size = [](const Vec3 &) { return 20.0; };
        MesherReport report;
        MesherOptions options;
        options.inlet_width = 0; // else the notch's 0.03 km2 of water closes as an inlet first
        Mesher m(SphericalDelaunay::Options{1e-12, 1}, size, report);
        const std::vector<VertexId> ids = insert_boundary(m, b);
        recover_segments(m, b, ids);
        classify_ocean(m, b, options);
        ASSERT_TRUE(problems(m).empty()) << problems(m).front();
        auto vertex_at = [&](double lon, double lat) {
            const Vec3 p = lonlat_to_vec(lon, lat);
            for (VertexId k = 0; k < m.dt.vertex_count(); ++k)
                if (m.dt.point(k) == p)
                    return k;
            return no_vertex;
        };
        const VertexId v = vertex_at(off, 0), p = vertex_at(0, 0.005), n = vertex_at(0, -0.005);
        ASSERT_NE(v, no_vertex);
        ASSERT_NE(p, no_vertex);
        ASSERT_NE(n, no_vertex);

        EXPECT_EQ(merge_close_coast_nodes(m, options), 1u);
        const std::vector<std::string> after = problems(m);
        EXPECT_TRUE(after.empty()) << after.size() << " problems, first: " << after.front();
        EXPECT_EQ(m.dt.vertex_half_edges()[v], no_half_edge) << "the node is still there";
        // Its neighbours are joined by a segment with the sea on its left.
        const HalfEdge h = m.dt.find_edge(m.dt.leaving(p), n);
        ASSERT_NE(h, no_half_edge);
        EXPECT_TRUE(m.dt.is_constrained(h));
        EXPECT_EQ(m.dt.label(triangle_of(h)), ocean);
        EXPECT_EQ(m.dt.label(triangle_of(m.dt.twin(h))), land);
    }
}

// The same seas meshed whole: no coast edge under h/32 is left, and the sea's area is the ring's
// without the node, within the notch or cape's 0.03 km2 (the triangles of the hole labelled
// by side, and nothing beyond it).
TEST(CloseNodes, the_seas_meshed_whole_keep_their_area_without_the_node) {
    for (const double off : {-0.0005, 0.0005}) {
        SCOPED_TRACE(off < 0 ? "notch" : "cape");
        MesherOptions options;
        if (off < 0)
            options.inlet_width = 0;
        MesherReport report;
        const Mesh mesh = mesh_boundary(
            sea_with(off), [](const Vec3 &) { return 20.0; }, options, &report);
        EXPECT_EQ(report.coast_nodes_merged, 1u);
        double shortest_km = 1e300, area_km2 = 0;
        for (const BoundaryEdge &e : mesh.boundary)
            shortest_km = std::min(shortest_km,
                                   arc_angle(mesh.nodes[e.a], mesh.nodes[e.b]) * earth_radius_km);
        EXPECT_GE(shortest_km, 20.0 / 32);
        for (const auto &f : mesh.faces)
            area_km2 +=
                spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]);
        // The sea ring's own area without the node (a fan from its centre: its sides are arcs).
        const Ring ring = sea_with(off).rings[0];
        std::vector<Vec3> nodes;
        for (const Vec3 &p : ring.nodes)
            if (p != lonlat_to_vec(off, 0))
                nodes.push_back(p);
        Vec3 centre{0, 0, 0};
        for (const Vec3 &p : nodes)
            centre = centre + p;
        centre = normalized(centre);
        double ring_area = 0;
        for (std::size_t k = 0; k < nodes.size(); ++k)
            ring_area += spherical_triangle_area(centre, nodes[k], nodes[(k + 1) % nodes.size()]);
        const double km2 = earth_radius_km * earth_radius_km;
        EXPECT_NEAR(area_km2 * km2, std::abs(ring_area) * km2, 0.1);
        test::TempDir dir;
        write_ugrid(mesh, dir / "merged.nc");
        test::expect_mesh_verify(dir / "merged.nc");
    }
}

// sea_with's cape with an islet 6 km east of it and a small lake 17 km inland: the hole the
// cape node leaves has triangles whose circumcircles hold points beyond its rim, so flips would
// leave it; held constrained, the rim keeps them in (without that, the merge stops with its
// internal error: its floods reach past the hole).
TEST(CloseNodes, the_rim_held_keeps_the_flips_in_the_hole) {
    Boundary b = sea_with(0.0005);
    b.rings.pop_back(); // sea_with's lake
    b.rings.push_back(
        ring_through({{0.055, 0.045}, {0.066, 0.045}, {0.066, 0.034}, {0.055, 0.034}}));
    b.rings.push_back(
        ring_through({{-0.16, -0.037}, {-0.16, -0.0395}, {-0.1575, -0.0395}, {-0.1575, -0.037}}));
    const std::function<double(const Vec3 &)> size = [](const Vec3 &) { return 20.0; };
    MesherReport report;
    MesherOptions options;
    options.inlet_width = 0;
    Mesher m(SphericalDelaunay::Options{1e-12, 1}, size, report);
    const std::vector<VertexId> ids = insert_boundary(m, b);
    recover_segments(m, b, ids);
    classify_ocean(m, b, options);
    EXPECT_EQ(merge_close_coast_nodes(m, options), 1u);
    const std::vector<std::string> after = problems(m);
    EXPECT_TRUE(after.empty()) << after.size() << " problems, first: " << after.front();
}

// A sea like sea_with's whose cape node has its neighbours 2.5 km either side (h/8 at 20 km),
// `off` degrees into the sea; with `islet`, a 2.2 km square island whose west corners lie 2.4 km
// from the cape (ocean chords under h/4: the mouth between them would close as a dead end).
Boundary cape_with(double off, bool islet) {
    Boundary b;
    b.rings.push_back(ring_through({{0, 2},
                                    {0.3, 0.3},
                                    {0, 0.0225},
                                    {off, 0},
                                    {0, -0.0225},
                                    {0.3, -0.3},
                                    {0, -2},
                                    {4, -2},
                                    {4, 2}}));
    if (islet)
        b.rings.push_back(ring_through({{0.02, 0.01}, {0.04, 0.01}, {0.04, -0.01}, {0.02, -0.01}}));
    return b;
}

// The merges of the mesher's stages up to them, and whether the node at (off, 0) is gone.
std::pair<std::size_t, bool> merged_at(const Boundary &b, double off) {
    const std::function<double(const Vec3 &)> size = [](const Vec3 &) { return 20.0; };
    MesherReport report;
    const MesherOptions options; // inlet_width 0.5: the short chord h/4
    Mesher m(SphericalDelaunay::Options{1e-12, 1}, size, report);
    const std::vector<VertexId> ids = insert_boundary(m, b);
    recover_segments(m, b, ids);
    classify_ocean(m, b, options);
    const std::size_t merged = merge_close_coast_nodes(m, options);
    const std::vector<std::string> after = problems(m);
    EXPECT_TRUE(after.empty()) << after.size() << " problems, first: " << after.front();
    const Vec3 p = lonlat_to_vec(off, 0);
    for (VertexId k = 0; k < m.dt.vertex_count(); ++k)
        if (m.dt.point(k) == p)
            return {merged, m.dt.vertex_half_edges()[k] == no_half_edge};
    ADD_FAILURE() << "no node at the cape";
    return {merged, false};
}

TEST(CloseNodes, a_segment_under_h_over_4_loses_an_end_where_the_coast_moves_under_h_over_32) {
    // 55 m off its neighbours' line (under h/32 = 625 m): it goes, though its segments are
    // 2.5 km long (four times h/32).
    EXPECT_EQ(merged_at(cape_with(0.0005, false), 0.0005), std::make_pair(std::size_t(1), true));
    // 890 m off: the coast would move by more than h/32; no end of either segment goes.
    EXPECT_EQ(merged_at(cape_with(0.008, false), 0.008), std::make_pair(std::size_t(0), false));
    // 55 m off, but beginning 2.4 km chords to the islet: kept for the dead ends to close.
    EXPECT_EQ(merged_at(cape_with(0.0005, true), 0.0005), std::make_pair(std::size_t(0), false));
}

// A sea at h = 20 km whose coast at x = 0 has an inlet 3 km wide and 10 km long (it closes: under
// h/2 wide, under h^2 of water); its mouth's corners lie 20 m off the line of their neighbours
// along the closed coast (those 5.2 km away, over h/4), the mouth 3 km long (under h/4). With
// `cut`, the inlet's nodes are left out: its mouth is a coast segment.
Boundary sea_with_inlet(bool cut) {
    std::vector<LonLat> coast = {{0, 2},           {0.0005, 0.06}, {0, 0.0135},     {-0.09, 0.0135},
                                 {-0.09, -0.0135}, {0, -0.0135},   {0.0005, -0.06}, {0, -2},
                                 {4, -2},          {4, 2}};
    if (cut)
        coast.erase(coast.begin() + 3, coast.begin() + 5);
    Boundary b;
    b.rings.push_back(ring_through(coast));
    return b;
}

TEST(CloseNodes, a_closed_inlets_mouth_keeps_its_corners) {
    const Boundary b = sea_with_inlet(false);
    const std::function<double(const Vec3 &)> size = [](const Vec3 &) { return 20.0; };
    MesherReport report;
    const MesherOptions options;
    Mesher m(SphericalDelaunay::Options{1e-12, 1}, size, report);
    const std::vector<VertexId> ids = insert_boundary(m, b);
    recover_segments(m, b, ids);
    classify_ocean(m, b, options);
    close_inlets(m, options, report);
    ASSERT_EQ(report.inlets_closed, 1u);
    // Moving a corner would move the mouth and bring the inlet's bank out as coast.
    EXPECT_EQ(merge_close_coast_nodes(m, options), 0u);
    const std::vector<std::string> after = problems(m);
    EXPECT_TRUE(after.empty()) << after.size() << " problems, first: " << after.front();
}

TEST(CloseNodes, the_mouth_corners_given_stay_where_the_inlet_was_cut_before) {
    // mesh_parts closes the inlets a border crosses on the whole boundary and cuts their nodes
    // from the rings before the split: a part sees the mouth's corners as plain coast nodes,
    // which the merge took (every inlet cut, GSHHG low at 20 km in 2 parts: 162 merged against
    // 45 in one part). It keeps those it is given, as one part keeps a mouth's corners.
    const Boundary b = sea_with_inlet(true);
    const std::function<double(const Vec3 &)> size = [](const Vec3 &) { return 20.0; };
    auto merged = [&](const MesherOptions &options) {
        MesherReport report;
        Mesher m(SphericalDelaunay::Options{1e-12, 1}, size, report);
        const std::vector<VertexId> ids = insert_boundary(m, b);
        recover_segments(m, b, ids);
        classify_ocean(m, b, options);
        return merge_close_coast_nodes(m, options);
    };
    MesherOptions options;
    EXPECT_GT(merged(options), 0u); // a corner goes, as a plain coast node
    for (const Vec3 &p : {lonlat_to_vec(0, 0.0135), lonlat_to_vec(0, -0.0135)})
        options.mouth_corners.push_back({p.x, p.y, p.z});
    std::sort(options.mouth_corners.begin(), options.mouth_corners.end());
    EXPECT_EQ(merged(options), 0u);
}

} // namespace
} // namespace globemesh::mesher_internal
