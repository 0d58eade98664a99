// --parts and --threads (issue 41, docs/parallel.md): the sphere meshed in lunes and joined. The
// joined mesh is one valid mesh (mesh-verify), the same bytes whatever the thread count, and
// close to the single-part mesh of the same input; borders cut by the coast (Natural Earth)
// and an aqua-planet (no ring crosses a border).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/parts.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"
#include "ring_through.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using namespace globemesh;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::TempDir;

namespace {

std::string bytes_of(const fs::path &p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

/// The run meshed and written to dir/name with a fixed history line (the CLI's holds the date).
Mesh mesh_and_write(MeshOptions o, int parts, int threads, const fs::path &path) {
    o.parts = parts;
    o.threads = threads;
    OceanMesh run = mesh_ocean(o);
    UgridOptions w;
    w.history = "parts_test";
    w.overwrite = true;
    write_ugrid(run.mesh, path, w);
    return std::move(run.mesh);
}

/// Natural Earth land from the fixtures (`scale` "110m" or "50m"), uniform at hmax_km.
MeshOptions natural_earth(const std::string &scale, double hmax_km) {
    MeshOptions o;
    o.coast = fixture("coast/ne_" + scale + "_land.gpkg").string();
    o.coast_layer = "land";
    o.hmax_km = hmax_km;
    return o;
}

/// An aqua-planet with one 10 x 8 degree island, written into dir: its path.
std::string island(const fs::path &dir) {
    std::ofstream(dir / "island.geojson")
        << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
           R"("geometry":{"type":"Polygon","coordinates":[[[-150,0],[-140,0],[-140,8],)"
           R"([-150,8],[-150,0]]]}}]})";
    return (dir / "island.geojson").string();
}

/// Every edge between two faces once each way, every other edge a boundary edge (not open on a
/// global run): the parts are one mesh with no border left.
void expect_joined(const Mesh &mesh) {
    std::set<std::pair<NodeIndex, NodeIndex>> edges;
    for (const auto &f : mesh.faces)
        for (int i = 0; i < 3; ++i)
            EXPECT_TRUE(edges.insert({f[i], f[(i + 1) % 3]}).second) << "an edge twice";
    std::size_t boundary = 0;
    for (const auto &[a, b] : edges)
        boundary += edges.count({b, a}) == 0;
    EXPECT_EQ(boundary, mesh.boundary.size());
    for (const BoundaryEdge &e : mesh.boundary)
        EXPECT_NE(e.tag, EdgeTag::open) << "a border left as open boundary";
}

TEST(Parts, aqua_planet_outlines_share_their_border_nodes) {
    const SizeFn h = [](const Vec3 &) { return 500.0; };
    for (int parts : {2, 3, 6}) {
        const auto split = split_boundary(Boundary{}, h, Lunes{parts}, nullptr);
        ASSERT_EQ(split.size(), std::size_t(parts));
        std::multiset<std::tuple<double, double, double>> nodes;
        for (const auto &p : split) {
            EXPECT_TRUE(p.has_ocean);
            ASSERT_EQ(p.boundary.rings.size(), 1u);
            for (const Vec3 &v : p.boundary.rings[0].nodes)
                nodes.insert({v.x, v.y, v.z});
        }
        // Each border node (20000 km / 500 km: 40 pieces) in two outlines, the poles in all.
        for (const auto &v : nodes) {
            const bool pole = std::abs(std::get<2>(v)) == 1.0;
            EXPECT_EQ(nodes.count(v), pole ? std::size_t(parts) : 2u);
        }
        EXPECT_EQ(nodes.size(), std::size_t(parts) * (2 * 39 + 2)) << parts;
    }
}

/// A coast ring through `corners` (lon/lat, the ocean on the left).
Ring coast_ring(const std::vector<LonLat> &corners) {
    return globemesh::test::ring_of_points(corners);
}

/// An island from 5W to 5E, 0 to 3N, across the border at 0E, the ocean on the left: its south
/// coast's nodes at `south` (west from 5E), one node of its north coast at `north` (between
/// 0.63W and 1.17E).
std::vector<LonLat> island_across_0e(const std::vector<double> &south, LonLat north) {
    std::vector<LonLat> ring;
    for (double lon : south)
        ring.push_back({lon, 0});
    for (double lat : {0.0, 0.9, 1.8, 2.7})
        ring.push_back({-5, lat});
    for (double lon : {-5.0, -4.1, -3.2, -2.3, -1.4, -0.63})
        ring.push_back({lon, 3});
    ring.push_back(north);
    for (double lon : {1.17, 2.07, 3.2, 4.1, 5.0})
        ring.push_back({lon, 3});
    for (double lat : {2.1, 1.2, 0.3})
        ring.push_back({5, lat});
    return ring;
}

/// Whether a part of `split` has a ring node at lon, lat.
bool split_has(const std::vector<PartBoundary> &split, double lon, double lat) {
    const Vec3 p = lonlat_to_vec(lon, lat);
    for (const auto &part : split)
        for (const Ring &x : part.boundary.rings)
            for (const Vec3 &v : x.nodes)
                if (norm(v - p) < 1e-12)
                    return true;
    return false;
}

TEST(Parts, a_coast_node_near_a_crossing_goes_where_the_coast_is_straight) {
    // An island across the border at 0E (h 100 km): on its straight south coast (the equator) a
    // node 30 km east of the crossing made a 30 km segment there, and faces as short (GSHHG low
    // at 20 km, the Benin coast at 2.01E: q 0.54). It goes; on the north coast a cape as near
    // the crossing, 33 km off the coast's line, stays.
    const SizeFn h = [](const Vec3 &) { return 100.0; };
    Boundary b;
    b.rings.push_back(coast_ring(island_across_0e(
        {5.0, 4.1, 3.2, 2.07, 1.17, 0.27, -0.63, -1.53, -2.43, -3.33, -4.23}, {0.27, 3.3})));
    const auto split = split_boundary(b, h, Lunes{2, 0.0}, nullptr);
    auto has = [&](double lon, double lat) { return split_has(split, lon, lat); };
    ASSERT_TRUE(has(1.17, 0)) << "the island is not where the test thinks";
    EXPECT_FALSE(has(0.27, 0)) << "the straight coast's node 30 km from the crossing";
    EXPECT_TRUE(has(-0.63, 0));
    EXPECT_TRUE(has(0.27, 3.3)) << "the cape";
}

TEST(Parts, a_coast_node_near_a_crossing_stays_where_another_coast_lies_behind_it) {
    // A shallow bay 30 km east of the crossing at 0E (h 100 km), 4.1 km off the arc from the
    // crossing to the node after it: the node goes, as on a straight coast. With an islet in
    // the bay that arc would cross the islet's coast (a ring no part could recover): the node
    // stays. So for a node within snap_fraction h of a crossing, which goes however far it
    // lies off that arc.
    const SizeFn h = [](const Vec3 &) { return 100.0; };
    const std::vector<LonLat> coast = island_across_0e(
        {5.0, 4.1, 3.2, 2.3, 1.4, 0.5, -0.4, -1.3, -2.2, -3.1, -4.0}, {0.27, 2.92});
    for (const bool islet : {false, true}) {
        Boundary b;
        b.rings.push_back(coast_ring(coast));
        if (islet)
            b.rings.push_back(coast_ring({{0.19, 2.935}, {0.21, 2.945}, {0.23, 2.935}}));
        EXPECT_EQ(split_has(split_boundary(b, h, Lunes{2, 0.0}, nullptr), 0.27, 2.92), islet)
            << (islet ? "with" : "without") << " the islet";
    }
}

TEST(Parts, a_border_side_split_many_times_on_one_side_gets_a_node_on_the_other) {
    // The east part's face A-P-B lies on the border at 0E (A to B 15 km, P a coast node 12 km
    // east); the west part split A-B at M, 1.9 km from B, and M is a coast node there (an
    // archipelago at the border: GSHHG high's Arctic at 15 km in 2 parts). A fan from P made a
    // face M-B-P of q 0.21 that no smoothing mends (P, M and B are fixed); the join adds a node
    // inside A-P-B and smooths it.
    const Vec3 a = lonlat_to_vec(0, 0), b = lonlat_to_vec(0, 0.135), m = lonlat_to_vec(0, 0.118);
    const Vec3 p = lonlat_to_vec(0.108, 0.07), q = lonlat_to_vec(-0.1, 0.07),
               w = lonlat_to_vec(-0.02, 0.128);
    auto part = [](std::vector<Vec3> nodes, std::vector<std::array<NodeIndex, 3>> faces,
                   std::vector<BoundaryEdge> boundary) {
        Mesh mesh;
        mesh.nodes = std::move(nodes);
        mesh.faces = std::move(faces);
        mesh.boundary = std::move(boundary);
        mesh.node_fields.push_back({"target_size", "target edge length", "km", "", {}});
        mesh.node_fields[0].values.assign(mesh.nodes.size(), 15.0);
        return mesh;
    };
    using T = EdgeTag;
    std::vector<Mesh> meshes;
    meshes.push_back(
        part({a, p, b}, {{0, 1, 2}}, {{0, 1, T::coast}, {1, 2, T::coast}, {2, 0, T::open}}));
    meshes.push_back(part({a, m, b, q, w}, {{0, 1, 3}, {1, 2, 4}},
                          {{0, 1, T::open},
                           {1, 3, T::coast},
                           {3, 0, T::coast},
                           {1, 2, T::open},
                           {2, 4, T::coast},
                           {4, 1, T::coast}}));
    const SizeFn h = [](const Vec3 &) { return 15.0; };
    const Mesh joined = join_parts(meshes, Lunes{2, 0.0}, h);
    EXPECT_EQ(joined.nodes.size(), 7u) << "a node added inside A-P-B";
    double worst = 1;
    for (const auto &f : joined.faces)
        worst = std::min(
            worst, triangle_quality(joined.nodes[f[0]], joined.nodes[f[1]], joined.nodes[f[2]]));
    EXPECT_GE(worst, 0.3) << "a fan from P has a face of q 0.21";
}

TEST(Parts, threads_give_the_same_bytes_aqua_planet) {
    TempDir dir;
    MeshOptions o;
    o.coast = island(dir.path());
    o.hmax_km = 250;
    const Mesh one = mesh_and_write(o, 1, 1, dir / "one.nc");
    const Mesh a = mesh_and_write(o, 2, 1, dir / "a.nc");
    mesh_and_write(o, 2, 2, dir / "b.nc");
    EXPECT_EQ(bytes_of(dir / "a.nc"), bytes_of(dir / "b.nc"));
    expect_mesh_verify(dir / "a.nc");
    expect_joined(a);
    EXPECT_NEAR(double(a.nodes.size()), double(one.nodes.size()), 0.03 * double(one.nodes.size()));
}

/// The faces below quality q.
std::size_t faces_below(const Mesh &mesh, double q) {
    return static_cast<std::size_t>(
        std::count_if(mesh.faces.begin(), mesh.faces.end(), [&](const auto &f) {
            return triangle_quality(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]) < q;
        }));
}

TEST(Parts, the_band_along_the_borders_is_the_lattice_again) {
    // Each part keeps its lattice 1.5 spacings off its borders and refines the band between:
    // joined, that band held the mesh's worst faces (q 0.60 in 3 parts, 300 faces below q 0.85
    // in 2, against 30 in one part). The join puts the lattice back there: the open ocean's
    // faces are the lattice's (q above 0.88), as in one part. The borders from 89.99W, off the
    // island: chosen, one cuts it (its coast holds 7% of the work, and no other position
    // balances 3 parts within 3%), and the band beside the cut is the parts' (q min 0.787).
    TempDir dir;
    MeshOptions o;
    o.coast = island(dir.path());
    o.hmax_km = 150;
    o.parts_border_lon = default_border_lon;
    o.parts = 1;
    const Mesh one = mesh_ocean(o).mesh;
    for (int parts : {2, 3}) {
        o.parts = parts;
        const Mesh joined = mesh_ocean(o).mesh;
        EXPECT_LE(faces_below(joined, 0.85), faces_below(one, 0.85) + 3) << parts;
        EXPECT_EQ(faces_below(joined, 0.8), faces_below(one, 0.8)) << parts;
        expect_joined(joined);
    }
}

TEST(Parts, an_inlet_a_border_runs_through_closes_as_in_one_part) {
    // A channel 11 km wide and 555 km long into a 10 x 10 degree island, at 50 km: one part
    // closes it by the inlet rule (narrower than inlet_width h). The border at 89.99W runs up
    // its middle: each part saw half a channel on its border, open water the inlet rule keeps,
    // and meshed it with 268 faces. The inlets a border crosses are now closed on the whole
    // boundary before the split.
    TempDir dir;
    std::ofstream(dir / "inlet.geojson")
        << R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{},)"
           R"("geometry":{"type":"Polygon","coordinates":[[[-95,0],[-90.05,0],[-90.05,5],)"
           R"([-89.95,5],[-89.95,0],[-85,0],[-85,10],[-95,10],[-95,0]]]}}]})";
    MeshOptions o;
    o.coast = (dir / "inlet.geojson").string();
    o.hmax_km = 50;
    o.parts_border_lon = default_border_lon; // chosen, the border keeps off the channel
    for (int parts : {1, 2}) {
        o.parts = parts;
        const Mesh mesh = mesh_ocean(o).mesh;
        std::size_t in_channel = 0; // faces whose centroid lies more than 1 degree up it
        for (const auto &f : mesh.faces) {
            const LonLat c =
                vec_to_lonlat(normalized(mesh.nodes[f[0]] + mesh.nodes[f[1]] + mesh.nodes[f[2]]));
            in_channel += c.lon > -90.05 && c.lon < -89.95 && c.lat > 1 && c.lat < 5;
        }
        EXPECT_EQ(in_channel, 0u) << parts << " parts";
    }
}

TEST(Parts, an_excursion_is_kept_where_its_shortcut_would_cross_the_coast) {
    // Mindanao in GSHHG low at 150 km (Davao Gulf closed), moved 36 degrees west so that its
    // east coast lies 18-21 km past the border at 90.01E of 2 parts, within the 0.2 h (30 km)
    // of an excursion. Dropped, its shortcut from the north-east cape (89.44E 9.83N) to the
    // gulf's west corner (89.73E 6.32N) passed west of the north coast's node at 89.54E 8.96N:
    // the west part's ring crossed itself and could not be recovered (GSHHG low 150 km in 5
    // parts failed so). It is kept where the shortcut would cross the ring.
    const std::vector<LonLat> mindanao = {
        {124.9992, 5.8596}, {124.0543, 6.4791}, {124.0116, 7.6480}, {122.8231, 7.7590},
        {122.1517, 6.9096}, {122.0838, 7.7383}, {123.2977, 8.6680}, {124.1905, 8.2381},
        {125.5399, 8.9645}, {125.4392, 9.8279}, {126.1713, 8.7901}, {126.2017, 7.5381},
        {126.1917, 6.2737}, {125.7281, 6.3237}};
    Boundary b;
    Ring r;
    for (const LonLat &c : mindanao)
        r.nodes.push_back(lonlat_to_vec(c.lon - 36, c.lat));
    r.kinds.assign(r.nodes.size(), SegmentKind::coast);
    b.rings.push_back(r);
    const SizeFn h = [](const Vec3 &) { return 150.0; };
    MesherOptions o;
    o.lattice_km = 150;
    o.parts_border_lon = default_border_lon;
    const Mesh mesh = mesh_parts(b, h, o, 2, 1);
    expect_joined(mesh);
    EXPECT_GT(mesh.faces.size(), 1000u);
}

TEST(Parts, an_excursion_is_kept_where_its_shortcut_would_cut_a_cape) {
    // NE 1:50m at 150 km in 4 parts, the border the parts chose at 67.74W: the cape south of
    // George VI Sound (67.68W 72.84S) lies 2 km past it, within the 0.2 h of an excursion.
    // Dropped, its shortcut from 68.15W 71.45S to 72.20W 73.38S passed 60 km off the cape and
    // across Alexander Island's coast, and the run failed ("a boundary segment cannot be
    // recovered"). The shortcut may stray from the nodes it replaces by 0.2 h at most, and
    // pass over no node of any ring.
    const TempDir dir;
    MeshOptions o = natural_earth("50m", 150);
    o.parts_border_lon = -67.737654321099996;
    const Mesh mesh = mesh_and_write(o, 4, 2, dir / "a.nc");
    expect_joined(mesh);
    expect_mesh_verify(dir / "a.nc");
}

TEST(Parts, part_count_zero_follows_the_node_estimate) {
    // --parts 0: one part below auto_parts_nodes (2e6) estimated nodes, the single-part mesh
    // itself; two parts from them on a global mesh. An open ocean of 5.1e8 km2: at 18 km about
    // 1.8e6 nodes (the field's bound alone, a quarter more, does not decide: the whole-ocean pass
    // counts), at 16 km about 2.3e6. It is the default.
    TempDir dir;
    MeshOptions o;
    o.coast = island(dir.path());
    ASSERT_EQ(o.parts, 0);
    o.hmax_km = 18;
    const OceanMesh small = mesh_ocean(o);
    EXPECT_EQ(small.mesher.parts, 1);
    EXPECT_GT(small.mesher.estimated_nodes, 1'600'000u);
    EXPECT_LT(small.mesher.estimated_nodes, auto_parts_nodes);
    o.parts = 1;
    const OceanMesh one = mesh_ocean(o);
    EXPECT_TRUE(small.mesh.nodes == one.mesh.nodes && small.mesh.faces == one.mesh.faces);
    o.parts = 0;
    o.hmax_km = 16;
    const OceanMesh big = mesh_ocean(o);
    EXPECT_EQ(big.mesher.parts, 2);
    EXPECT_GE(big.mesher.estimated_nodes, auto_parts_nodes);
    EXPECT_NE(std::find(big.mesh.attributes.begin(), big.mesh.attributes.end(),
                        std::pair<std::string, std::string>{"parts", "2"}),
              big.mesh.attributes.end());
    // A region is one part however large: 30 x 30 degrees at 2.2 km, 2.4e6 nodes.
    o.region = std::array<double, 4>{-160, -10, -130, 20};
    o.hmax_km = 2.2;
    const OceanMesh region = mesh_ocean(o);
    EXPECT_EQ(region.mesher.parts, 1);
    EXPECT_GE(region.mesh.nodes.size(), auto_parts_nodes);
}

TEST(Parts, threads_give_the_same_bytes_natural_earth) {
    TempDir dir;
    // 2 parts: a border node in the Canadian Arctic with land on both sides; 5 parts: nodes
    // with four faces near the borders, removed by the join (both with the borders from -89.99).
    MeshOptions o = natural_earth("110m", 150);
    o.parts_border_lon = default_border_lon;
    const Mesh one = mesh_and_write(o, 1, 1, dir / "one.nc");
    for (int parts : {2, 5}) {
        const Mesh a = mesh_and_write(o, parts, 1, dir / "a.nc");
        mesh_and_write(o, parts, 3, dir / "b.nc");
        EXPECT_EQ(bytes_of(dir / "a.nc"), bytes_of(dir / "b.nc")) << parts;
        expect_mesh_verify(dir / "a.nc");
        expect_joined(a);
        EXPECT_NEAR(double(a.nodes.size()), double(one.nodes.size()),
                    0.05 * double(one.nodes.size()))
            << parts;
    }
}

/// No slit: no two boundary edges run between the same places (within 1e-6 radians, 6 m) in
/// opposite directions, water on both sides of a wall mesh-verify passes. (Parts whose land
/// steps split or dropped a border node on one side only left one.)
void expect_no_slit(const Mesh &mesh) {
    constexpr double near = 1e-6;
    std::vector<std::pair<double, std::size_t>> by_z; // boundary edges by their midpoint's z
    for (std::size_t i = 0; i < mesh.boundary.size(); ++i) {
        const BoundaryEdge &e = mesh.boundary[i];
        by_z.push_back({0.5 * (mesh.nodes[e.a].z + mesh.nodes[e.b].z), i});
    }
    std::sort(by_z.begin(), by_z.end());
    auto close = [&](NodeIndex u, NodeIndex v) {
        return norm(mesh.nodes[u] - mesh.nodes[v]) < near;
    };
    for (std::size_t i = 0; i < by_z.size(); ++i)
        for (std::size_t j = i + 1; j < by_z.size() && by_z[j].first - by_z[i].first < near; ++j) {
            const BoundaryEdge &e = mesh.boundary[by_z[i].second],
                               &f = mesh.boundary[by_z[j].second];
            EXPECT_FALSE(close(e.a, f.b) && close(e.b, f.a))
                << "slit at " << vec_to_lonlat(mesh.nodes[e.a]).lon << ","
                << vec_to_lonlat(mesh.nodes[e.a]).lat;
        }
}

/// No boundary node lies inside another boundary edge (on its arc between its ends): the
/// joined parts split an edge wherever the other side's boundary meets it.
void expect_no_node_inside_a_boundary_edge(const Mesh &mesh) {
    std::set<NodeIndex> on;
    for (const BoundaryEdge &e : mesh.boundary)
        on.insert(e.a), on.insert(e.b);
    for (const BoundaryEdge &e : mesh.boundary) {
        const Vec3 &a = mesh.nodes[e.a], &b = mesh.nodes[e.b];
        const Vec3 normal = normalized(cross(a, b));
        for (NodeIndex v : on) {
            const Vec3 &p = mesh.nodes[v];
            if (v == e.a || v == e.b || std::abs(dot(p, normal)) > 1e-12)
                continue;
            EXPECT_FALSE(dot(cross(a, p), normal) > 0 && dot(cross(p, b), normal) > 0)
                << "node " << v << " inside boundary edge " << e.a << "-" << e.b;
        }
    }
}

/// GSHHG low east of New Guinea (the fixture) in the box 146-154E, 13-6S, at 30 km.
MeshOptions new_guinea_east() {
    MeshOptions o;
    o.coast = fixture("coast/hostile/gshhg_l_new_guinea_east.geojson").string();
    o.region = std::array<double, 4>{146, -13, 154, -6};
    o.hmax_km = 30;
    o.parts_border_lon = default_border_lon; // a border at 150.0123E in 3 parts
    return o;
}

TEST(Parts, a_coast_vertex_metres_past_a_border_leaves_no_sliver_at_it) {
    // GSHHG low east of New Guinea, 3 parts at 30 km, the border at 150.0123E: a coast vertex at
    // 150.0125E made a piece of one node in the east part between two crossings 30 m apart.
    // Its faces had q 0.086 (one part: 0.600); global GSHHG low in 3 parts at 25 and 30 km had
    // its coast meet the border inside the other part's unsplit border edge (mesh-verify:
    // boundary edges crossing; b58aa0a splits such edges). The excursion is now dropped.
    TempDir dir;
    const MeshOptions o = new_guinea_east();
    const double one = compute_stats(mesh_ocean(o).mesh).quality_min;
    const Mesh a = mesh_and_write(o, 3, 2, dir / "a.nc");
    EXPECT_GE(compute_stats(a).quality_min, one - 0.05);
    expect_no_node_inside_a_boundary_edge(a);
    expect_no_slit(a);
    expect_mesh_verify(dir / "a.nc");
}

TEST(Parts, a_channel_between_two_coasts_a_border_joins_closes_as_in_one_part) {
    // Natural Earth 1:50m around Greece at 25 km in 4 parts, a border at 20.7623E (the first at
    // -69.2377E) beside the channel between Lefkada and the mainland. In its part the border
    // joined the mainland's coast and the island's into one loop: a face across the channel,
    // centred on land, looked like a cut of the ocean and stayed, and the channel kept a fan of
    // 16 faces down to q 0.333 (one part: one face, q min 0.397 elsewhere). The land stage now
    // tells the loops by the whole coast's rings.
    TempDir dir;
    MeshOptions o = natural_earth("50m", 25);
    o.region = {15, 33, 28, 45};
    o.parts_border_lon = -69.2377;
    const double one = compute_stats(mesh_ocean(o).mesh).quality_min;
    const Mesh parts = mesh_and_write(o, 4, 2, dir / "p.nc");
    EXPECT_GE(compute_stats(parts).quality_min, one);
    expect_mesh_verify(dir / "p.nc");
}

TEST(Parts, a_region_in_parts_is_meshed_inside_its_box_alone) {
    // The box (146-154E) lies in one lune of 2 parts and across the border at 150.01E of 3. A
    // border no ring crosses had been taken for ocean where the coast has no land: 2 parts
    // refused the box ("a boundary ring has the ocean on its right"), 3 meshed two whole lunes.
    TempDir dir;
    const MeshOptions o = new_guinea_east();
    const std::size_t one = mesh_ocean(o).mesh.nodes.size();
    for (int parts : {2, 3}) {
        SCOPED_TRACE(parts);
        const fs::path path = dir / ("p" + std::to_string(parts) + ".nc");
        const Mesh m = mesh_and_write(o, parts, 2, path);
        EXPECT_GT(double(m.nodes.size()), 0.9 * double(one));
        EXPECT_LT(double(m.nodes.size()), 1.2 * double(one));
        for (const Vec3 &v : m.nodes) {
            const LonLat p = vec_to_lonlat(v);
            // The box's southern edge is a great circle between its corners: a little south.
            ASSERT_TRUE(p.lon >= 146 - 1e-9 && p.lon <= 154 + 1e-9 && p.lat >= -13.1 &&
                        p.lat <= -6 + 1e-9)
                << p.lon << " " << p.lat;
        }
        expect_no_slit(m);
        expect_mesh_verify(path);
    }
}

/// The edges shorter than `km` whose midpoint lies within 1 degree of a border of `lunes`.
std::size_t short_edges_near_borders(const Mesh &mesh, const Lunes &lunes, double km) {
    std::set<std::pair<NodeIndex, NodeIndex>> seen;
    std::size_t count = 0;
    const double near = std::sin(1.0 * pi / 180);
    for (const auto &f : mesh.faces)
        for (int i = 0; i < 3; ++i) {
            const NodeIndex a = std::min(f[i], f[(i + 1) % 3]), b = std::max(f[i], f[(i + 1) % 3]);
            if (!seen.insert({a, b}).second)
                continue;
            const Vec3 &p = mesh.nodes[a], &q = mesh.nodes[b];
            if (std::acos(std::clamp(dot(p, q), -1.0, 1.0)) * earth_radius_km >= km)
                continue;
            const Vec3 mid = normalized(p + q);
            for (int k = 0; k < lunes.count; ++k)
                if (std::abs(dot(mid, lunes.border_normal(k))) < near &&
                    dot(mid, lunes.border_direction(k)) > 0) {
                    ++count;
                    break;
                }
        }
    return count;
}

TEST(Parts, the_borders_are_chosen_off_the_coasts) {
    // Natural Earth 1:50m at 60 km in 2 parts. With the borders at 89.99W and 90.01E, the west
    // one runs less than a face off the coasts of Ellesmere, Devon and Boothia: the parts
    // meshed those slivers of water with 28 edges shorter than h / 4 within a degree of the
    // borders (one part: 3). Chosen (the parts' work balanced, the borders passing the coast
    // least closely), the borders at 2.26E and 177.74W have none, and the worst face is one
    // part's.
    MeshOptions o = natural_earth("50m", 60);
    o.parts = 1;
    const Mesh one = mesh_ocean(o).mesh;
    o.parts = 2;
    const OceanMesh chosen = mesh_ocean(o);
    o.parts_border_lon = default_border_lon;
    const OceanMesh fixed = mesh_ocean(o);
    const Lunes at{2, chosen.mesher.parts_border_lon}, from_default{2, default_border_lon};
    EXPECT_GT(std::abs(at.first_lon - default_border_lon), 1);
    const double km = o.hmax_km / 4;
    EXPECT_GT(short_edges_near_borders(fixed.mesh, from_default, km),
              short_edges_near_borders(one, from_default, km) + 15);
    EXPECT_LE(short_edges_near_borders(chosen.mesh, at, km),
              short_edges_near_borders(one, at, km) + 2);
    const double q_one = compute_stats(one).quality_min;
    EXPECT_GE(compute_stats(chosen.mesh).quality_min, q_one - 0.01);
    expect_joined(chosen.mesh);
}

/// The areas (km2, largest first) of the mesh's pieces over shared nodes (union-find), but the
/// largest (the ocean).
std::vector<double> pieces_but_the_ocean(const Mesh &mesh) {
    std::vector<NodeIndex> up(mesh.nodes.size());
    for (NodeIndex i = 0; i < up.size(); ++i)
        up[i] = i;
    auto root = [&](NodeIndex i) {
        while (up[i] != i)
            i = up[i] = up[up[i]];
        return i;
    };
    for (const auto &f : mesh.faces)
        up[root(f[1])] = up[root(f[2])] = root(f[0]);
    std::map<NodeIndex, double> area;
    for (const auto &f : mesh.faces)
        area[root(f[0])] +=
            spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]) *
            earth_radius_km * earth_radius_km;
    std::vector<double> pieces;
    for (const auto &[r, a] : area)
        pieces.push_back(a);
    std::sort(pieces.rbegin(), pieces.rend());
    pieces.erase(pieces.begin());
    return pieces;
}

TEST(Parts, the_basins_cut_off_are_pieces_of_the_joined_mesh) {
    // Each part had reported its own pieces beside a closed strait, though they reach the ocean
    // through another part: NE 1:110m at 150 km in 5 parts listed 6 basins, two of 2.6e6 and
    // 2.9e6 km2, where the joined mesh has one piece besides the ocean's.
    MeshOptions o = natural_earth("110m", 150);
    for (int parts : {3, 5}) {
        SCOPED_TRACE(parts);
        o.parts = parts;
        const OceanMesh run = mesh_ocean(o);
        const std::vector<double> pieces = pieces_but_the_ocean(run.mesh);
        ASSERT_LE(run.mesher.seas_cut_off.size(), pieces.size());
        for (const double a : run.mesher.seas_cut_off)
            EXPECT_TRUE(std::any_of(pieces.begin(), pieces.end(),
                                    [a](double p) { return std::fabs(p - a) <= 1e-6 * p; }))
                << a << " km2 is no piece of the joined mesh";
    }
}

TEST(Parts, a_face_a_border_leaves_apart_closes_and_every_piece_left_is_a_basin) {
    // NE 1:110m at 80 km: in 3 parts the joined mesh kept a face of 230 km2 apart north of
    // Greenland (-30E 82N), water a part kept against its border where the next part closed its
    // side; in 2 parts the Black Sea stood apart, cut off with no basin listed. One part leaves
    // no piece the inlet rule closes (under h^2 here) and lists every basin.
    MeshOptions o = natural_earth("110m", 80);
    for (int parts : {2, 3, 4, 5}) {
        SCOPED_TRACE(parts);
        o.parts = parts;
        const OceanMesh run = mesh_ocean(o);
        const std::vector<double> pieces = pieces_but_the_ocean(run.mesh);
        EXPECT_EQ(pieces.size(), run.mesher.seas_cut_off.size());
        for (const double a : pieces)
            EXPECT_GT(a, 80.0 * 80.0) << "a piece the inlet rule closes";
    }
}

TEST(Parts, the_straits_closed_are_measured_as_in_one_part) {
    // mesh_parts measures its parts' closings after them, beside the join (on a thread of its
    // own when there are two): a closing at the same place as one part's has its width, and
    // the thread count changes none. NE 1:50m, the Aegean and the Black Sea at 100 km (one
    // part closes the Ionian Sea at 20.42E 38.25N, 12.6 km wide; a border runs at 28.5E).
    MeshOptions o = natural_earth("50m", 100);
    o.region = std::array<double, 4>{20, 35, 45, 48};
    const MesherReport one = mesh_ocean(o).mesher;
    ASSERT_EQ(one.straits_closed_width_km.size(), one.straits_closed_at.size());
    o.parts = 2;
    std::vector<double> widths[2];
    for (int threads : {1, 2}) {
        o.threads = threads;
        const MesherReport r = mesh_ocean(o).mesher;
        ASSERT_EQ(r.parts, 2);
        ASSERT_EQ(r.straits_closed_width_km.size(), r.straits_closed_at.size());
        ASSERT_EQ(r.straits_closed_width_below_km.size(), r.straits_closed_at.size());
        std::size_t same_place = 0;
        for (std::size_t i = 0; i < r.straits_closed_at.size(); ++i) {
            EXPECT_GT(r.straits_closed_width_km[i] + r.straits_closed_width_below_km[i], 0);
            for (std::size_t j = 0; j < one.straits_closed_at.size(); ++j)
                if (norm(one.straits_closed_at[j] - r.straits_closed_at[i]) < 1e-12) {
                    // The same place to 1e-12 (its face's nodes rounded apart in the parts):
                    // the same width to as little.
                    ++same_place;
                    EXPECT_NEAR(r.straits_closed_width_km[i], one.straits_closed_width_km[j], 1e-9);
                }
        }
        EXPECT_GE(same_place, 1u) << "the Ionian Sea's closing, as in one part";
        widths[threads - 1] = r.straits_closed_width_km;
    }
    EXPECT_EQ(widths[0], widths[1]);
}

TEST(Parts, water_a_part_takes_for_a_pocket_closes_as_a_strait_or_stays_with_keep_straits) {
    // NE 1:50m, the Aegean and the Black Sea at 100 km in 2 parts, the border at 28.5123E
    // across the Sea of Marmara. Alone, each part took its half of Marmara for a pocket behind
    // a face centred on land (at the Dardanelles, at the Bosporus) and removed it: the Black
    // Sea was cut off from the Aegean with no closing listed there, and with --keep-straits too,
    // where one part keeps them one ocean (one boundary loop).
    MeshOptions o = natural_earth("50m", 100);
    o.region = std::array<double, 4>{20, 35, 45, 48};
    o.parts_border_lon = 28.5123;
    auto closings_at_the_straits = [](const MesherReport &r) {
        return std::count_if(
            r.straits_closed_at.begin(), r.straits_closed_at.end(), [](const Vec3 &p) {
                const LonLat ll = vec_to_lonlat(p);
                return ll.lon > 26 && ll.lon < 30 && ll.lat > 39.8 && ll.lat < 41.5;
            });
    };
    ASSERT_GE(closings_at_the_straits(mesh_ocean(o).mesher), 1) << "one part closes them";
    o.parts = 2;
    const OceanMesh parts = mesh_ocean(o);
    ASSERT_EQ(parts.mesher.parts, 2);
    EXPECT_GE(closings_at_the_straits(parts.mesher), 1);
    // The basin those closings cut off is the Black Sea's (436,000 km2 with the Sea of Azov), as
    // in one part.
    ASSERT_FALSE(parts.mesher.seas_cut_off.empty());
    const double largest =
        *std::max_element(parts.mesher.seas_cut_off.begin(), parts.mesher.seas_cut_off.end());
    EXPECT_GT(largest, 3.5e5);
    EXPECT_LT(largest, 5.0e5);

    o.keep_straits = true;
    o.parts = 1;
    ASSERT_EQ(compute_stats(mesh_ocean(o).mesh).boundary_loops, 1u);
    o.parts = 2;
    const OceanMesh kept = mesh_ocean(o);
    EXPECT_EQ(compute_stats(kept.mesh).boundary_loops, 1u) << "the Black Sea cut off";
    EXPECT_TRUE(kept.mesher.straits_closed_at.empty());
}

TEST(Parts, every_part_count_fills_its_lunes_with_the_lattice) {
    // Each part's lattice is its lune's share of the sphere's: with 3 or more parts it had been
    // weighed whole against one part's node estimate, and skipped.
    MeshOptions o = natural_earth("110m", 250);
    const std::size_t one = mesh_ocean(o).mesher.lattice_nodes;
    ASSERT_GT(one, 2000u);
    for (int parts = 2; parts <= 6; ++parts) {
        o.parts = parts;
        const OceanMesh run = mesh_ocean(o);
        // The bands along the borders (1.5 lattice spacings each side) are refined instead.
        EXPECT_GT(double(run.mesher.lattice_nodes), 0.6 * double(one)) << parts;
        EXPECT_LE(run.mesher.lattice_nodes, one) << parts;
    }
}

TEST(Parts, refuses_more_parts_than_the_poles_allow) {
    MeshOptions o;
    o.coast = fixture("coast/ne_110m_land.gpkg").string();
    o.parts = 7;
    EXPECT_THROW(validate(o), UsageError);
    o.parts = -1;
    EXPECT_THROW(validate(o), UsageError);
    o.parts = 2;
    o.threads = -1;
    EXPECT_THROW(validate(o), UsageError);
    o.threads = 0;
    o.parts_border_lon = 200;
    EXPECT_THROW(validate(o), UsageError);
    o.parts_border_lon = -180;
    EXPECT_NO_THROW(validate(o));
}

} // namespace
