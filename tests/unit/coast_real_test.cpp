// Hostile cases cut from real public coastlines (fixtures/coast/hostile/, sources in
// fixtures/README.md): each failed before issue 37 and must now mesh validly, with no face
// below quality 0.3 (issue 37's floor, by mesh-verify's own measure).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "globemesh/coast.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/mesh_stats.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/sphere.hpp"
#include "globemesh/ugrid.hpp"
#include "support.hpp"

namespace globemesh {
namespace {

MeshOptions region_run(const std::string &coast, std::array<double, 4> region, double h_km) {
    MeshOptions o;
    o.coast = test::fixture(coast).string();
    o.region = region;
    o.hmax_km = h_km;
    return o;
}

void expect_valid_mesh(const Mesh &mesh, const MeshOptions &o, const std::string &name) {
    test::TempDir dir;
    write_ugrid(mesh, dir / name);
    test::expect_mesh_verify(dir / name,
                             "--coast " + o.coast + " --max-land-faces 0 --min-quality 0.3");
}

std::size_t count_attribute(const Mesh &mesh, const std::string &name) {
    for (const auto &[key, value] : mesh.attributes)
        if (key == name)
            return std::stoul(value);
    ADD_FAILURE() << "no " << name << " attribute";
    return 0;
}

std::size_t corners_blunted(const Mesh &mesh) {
    return count_attribute(mesh, "corners_blunted");
}

double worst_quality(const Mesh &mesh) {
    double worst = 1;
    for (const auto &f : mesh.faces)
        worst =
            std::min(worst, triangle_quality(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]));
    return worst;
}

// GSHHG intermediate around the Great Sandy Strait (Queensland): an islet's vertex 0.4 m from
// the mainland's 5 km edge, which as a great-circle arc passes on the islet's other side. The
// check on the cleaned coast refused the whole run ("arcs touch or cross near lon 152.6166,
// lat -25.1746"); snap rounding and the split of straying arcs now resolve it. The land is
// also clipped to the region's own box.
TEST(CoastReal, an_islet_a_fraction_of_a_metre_off_the_mainland_meshes) {
    const MeshOptions o = region_run("coast/hostile/gshhg_i_great_sandy_strait.geojson",
                                     {152.3, -25.5, 153.3, -24.8}, 5);
    const CoastData d = load_coast(o);
    EXPECT_TRUE(check_boundary(d.rings).empty());
    // The near-touch is resolved, and said so: split arcs or joined polygons are counted.
    EXPECT_GT(d.arcs_split + d.polygons_joined, 0u);
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GT(mesh.faces.size(), 100u);
    expect_valid_mesh(mesh, o, "strait.nc");
}

/// Whether a face of the mesh holds the point (on its edges counts).
bool covered(const Mesh &mesh, const Vec3 &p) {
    return std::any_of(mesh.faces.begin(), mesh.faces.end(), [&](const auto &f) {
        const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
        const double s[3] = {dot(cross(a, b), p), dot(cross(b, c), p), dot(cross(c, a), p)};
        return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
    });
}

/// Whether a boundary edge of the mesh has an end in the lon/lat box W, S, E, N.
bool boundary_in(const Mesh &mesh, const std::array<double, 4> &box) {
    auto inside = [&](NodeIndex n) {
        const LonLat p = vec_to_lonlat(mesh.nodes[n]);
        return p.lon > box[0] && p.lat > box[1] && p.lon < box[2] && p.lat < box[3];
    };
    return std::any_of(mesh.boundary.begin(), mesh.boundary.end(),
                       [&](const BoundaryEdge &e) { return inside(e.a) || inside(e.b); });
}

// DCW's Denmark buffered 0.02 degrees as the region, GSHHG intermediate as the coast, at 5 km:
// the region has a hole of 1.8 km2 in the water off Helnaes, a thin crescent. Unlike an island
// that small, a hole in a region's outline was kept; resampled to three nodes it came out the
// other way round, and the mesher stopped ("a boundary ring has the ocean on its right near lon
// 10.1083, lat 55.1651"; at 8, 10 and 15 km elsewhere on Denmark's outline, after f4707a6 kept
// more of the open rings' nodes). Smaller than a few triangles, it is meshed over as such an
// island is: no boundary is left in it.
TEST(CoastReal, a_region_hole_smaller_than_a_few_triangles_is_meshed_over_as_an_island_is) {
    MeshOptions o;
    o.coast = test::fixture("coast/hostile/gshhg_i_south_funen.geojson").string();
    o.region_file = test::fixture("regions/dcw_denmark_buffer_0.02_south_funen.geojson").string();
    o.hmax_km = 5;
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_FALSE(boundary_in(mesh, {10.0487, 55.1495, 10.1158, 55.1652})); // the hole's box
    EXPECT_TRUE(covered(mesh, lonlat_to_vec({10.1035, 55.1573})));         // inside the hole
    EXPECT_FALSE(covered(mesh, lonlat_to_vec({9.92, 55.1})));              // water off the region
    expect_valid_mesh(mesh, o, "south_funen.nc");
}

// GSHHG full resolution of the Sogn coast (western Norway), clipped to a lon/lat box and stored
// in UTM 32N (EPSG:25832) as a shapefile, meshed with that box as --region: the land runs
// along the region's outline, an island closes a notch of water against it, and every size
// from 10 km to 0.5 km was refused, by the outline check or by the mesher's ring orientation.
TEST(CoastReal, a_fjord_coast_clipped_to_its_region_meshes_at_every_size) {
    for (double h : {10.0, 5.0, 4.0, 2.5, 2.2, 1.8, 1.5, 1.0, 0.75, 0.5}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        const MeshOptions o =
            region_run("coast/hostile/gshhg_f_sogn_25832.shp", {4.8, 61.3, 5.3, 61.6}, h);
        const Mesh mesh = mesh_ocean(o).mesh;
        EXPECT_GT(mesh.faces.size(), 10u);
        if (h == 10.0 || h == 1.5 || h == 0.5)
            expect_valid_mesh(mesh, o, "fjord.nc");
    }
}

// GSHHG intermediate around Lake Maracaibo at 100 km, the region its own box: the lake's
// mouth, closed as an inlet, leaves an ear of the coast (two coast sides meeting at a corner
// too sharp for a face of 100 km) that was the run's worst face (q 0.110). The ear goes last,
// its third side becoming coast.
TEST(CoastReal, a_coast_corner_sharper_than_the_mesh_can_hold_is_blunted) {
    const MeshOptions o =
        region_run("coast/hostile/gshhg_i_maracaibo.geojson", {-73, 9, -70, 12}, 100);
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GE(corners_blunted(mesh), 1u);
    expect_valid_mesh(mesh, o, "maracaibo.nc");
}

// GSHHG intermediate around the Danube delta at 25 km, the region its own box: two faces of q
// 0.217 at 29.0E 44.68N without a coast side, each with one corner on the coast (an interior
// node 0.3 km from a coast node beside a sharp corner). The faces between them and the coast
// at that corner go first, then the faces themselves.
// (With the coast's close nodes kept: merged, as by default, the mouth of the Sulina arm behind
// that corner is one node once its inlet closes, and the faces are not made.)
TEST(CoastReal, a_face_below_the_floor_with_one_coast_corner_goes_with_the_faces_beside_it) {
    MeshOptions o = region_run("coast/hostile/gshhg_i_danube.geojson", {28, 43.5, 30.5, 46}, 25);
    o.close_node_gap = 0;
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GE(corners_blunted(mesh), 2u);
    expect_valid_mesh(mesh, o, "danube.nc");
}

// The same coast at 20 and 25 km: the inlet closed at the Sulina arm left its mouth, between the
// banks' own vertices 0.23 km apart, as a coast segment of h/100, meshed with faces as small (q
// 0.40 at 20 km; at 25 km the faces of the test above). The coast shaping merges nodes closer
// than close_node_gap h (1/32), but there the banks were apart. Once the inlets close, such a
// segment loses an end too: no coast edge is left shorter than h/32.
TEST(CoastReal, no_coast_edge_is_left_shorter_than_the_close_node_gap_once_the_inlets_close) {
    for (double h : {20.0, 25.0}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        const MeshOptions o =
            region_run("coast/hostile/gshhg_i_danube.geojson", {28, 43.5, 30.5, 46}, h);
        const Mesh mesh = mesh_ocean(o).mesh;
        EXPECT_GE(count_attribute(mesh, "coast_nodes_merged"), 1u);
        double shortest_km = 1e300;
        for (const BoundaryEdge &b : mesh.boundary)
            if (b.tag == EdgeTag::coast)
                shortest_km = std::min(shortest_km, arc_angle(mesh.nodes[b.a], mesh.nodes[b.b]) *
                                                        earth_radius_km);
        EXPECT_GE(shortest_km, h / 32);
        expect_valid_mesh(mesh, o, "danube.nc");
    }
}

// A face below the floor on a short coast side beside nodes of a much coarser spacing, which no
// move and no removal of a node mends, gets a node at the apex of the equilateral triangle on
// that side (quality.cpp). The cases found: GSHHG high around the Yangtze mouth at 50 km, a face
// of q 0.202 between a free node and two coast nodes 0.6 km apart (the last face below the floor
// of the global GSHHG h run at 50 km), and GSHHG full around the Suez Canal at 2.9-3.1 km and
// 4.9-5.2 km, with the coast's close nodes kept. Since the coast's conflicts get their corners
// under the arc in conflict, neither coast makes such a side: no run of the hostile fixtures
// and of eight GSHHG full regions at sizes 1.5-7% apart adds the node (bench/RESULTS-coast.md).
// The cases stay, above the floor.
TEST(CoastReal, a_short_coast_side_among_coarse_nodes_leaves_no_face_below_the_floor) {
    MeshOptions o = region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, 3);
    o.close_node_gap = 0;
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GE(worst_quality(mesh), 0.3);
    expect_valid_mesh(mesh, o, "suez_3km.nc");
    o = region_run("coast/hostile/gshhg_h_yangtze.geojson", {119, 29, 125, 34}, 50);
    o.close_node_gap = 0;
    const Mesh yangtze = mesh_ocean(o).mesh;
    EXPECT_GE(worst_quality(yangtze), 0.3);
    expect_valid_mesh(yangtze, o, "yangtze.nc");
}

// GSHHG full around the Suez Canal at 5.2 km, the region the fixture's own box: a stub of the
// canal (300 m wide, left open where straits closed north of it) held nodes 12 m to 100 m
// apart. The floor's searches raised an interior face there from q 0.24 to 0.284, a sliver on a
// coast side of 100 m whose third corner lay 24 m off it; blunting had run before and removed
// such slivers only before the floor's moves (the global GSHHG full run at 5 km had this face
// as its worst, q 0.2852 at 32.354E 30.427N, in one part and in two). Blunting and the floor
// run once more when a face is left below it. (With the coast's close nodes kept and the stub
// left open. Since the coast's conflicts get their corners under the arc in conflict, the
// stub's nodes are no longer crowded and the second run is not needed here, nor in any run
// swept; the case stays, above the floor.)
TEST(CoastReal, a_canal_stub_with_its_close_nodes_kept_leaves_no_sliver_below_the_floor) {
    MeshOptions o = region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, 5.2);
    o.close_node_gap = 0;
    o.close_dead_ends = false;
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GE(worst_quality(mesh), 0.3); // 0.284 once
    expect_valid_mesh(mesh, o, "suez.nc");
}

TEST(CoastReal, a_conflict_gets_its_corners_under_the_arc_in_conflict) {
    // The Digital Chart of the World's Mexico and Guatemala at the Suchiate's mouth at 5 km. A
    // resampled arc touching another gets a corner at the source node farthest from it, each
    // round, up to the kept node after its end: also when its end lay on a kept node, so that
    // the nodes past the end, which are not under the arc, got the corners and left the arc as
    // it was, round after round. 506 rounds put 451 corners on this coast (crowding its faces
    // down to 0.2 km sides) that the close nodes' merge took off again; global DCW at 50 km
    // spent 13.8 s in 8,171 such rounds. A coast shaped at h merges few of its nodes: fewer
    // than it keeps.
    const MeshOptions o =
        region_run("coast/hostile/dcw_suchiate.geojson", {-92.6, 14.3, -91.8, 15.1}, 5);
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_LT(count_attribute(mesh, "coast_nodes_merged"), mesh.boundary.size());
    expect_valid_mesh(mesh, o, "suchiate.nc");
}

// The shortest side of the mesh's faces, and of its boundary (the sides of one face), km.
struct Shortest {
    double side = 1e9, boundary = 1e9;
};
Shortest shortest_sides(const Mesh &mesh) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
    for (const auto &f : mesh.faces)
        for (int i = 0; i < 3; ++i)
            ++uses[std::minmax(f[i], f[(i + 1) % 3])];
    Shortest s;
    for (const auto &[e, n] : uses) {
        const double km = arc_angle(mesh.nodes[e.first], mesh.nodes[e.second]) * earth_radius_km;
        s.side = std::min(s.side, km);
        if (n == 1)
            s.boundary = std::min(s.boundary, km);
    }
    return s;
}

// The Yangtze mouth as above, with the coast's close nodes merged (the default): the two coast
// nodes 0.6 km apart are one, and no coast side is shorter than h/32.
TEST(CoastReal, coast_nodes_far_closer_than_h_among_coarse_ones_are_merged) {
    const MeshOptions o =
        region_run("coast/hostile/gshhg_h_yangtze.geojson", {119, 29, 125, 34}, 50);
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GE(shortest_sides(mesh).boundary, 50.0 / 32); // 0.60 km before
    expect_valid_mesh(mesh, o, "yangtze.nc");
}

// The Suez Canal as above at 5 km. The topology repair put its corners at the source's own
// vertices along the canal's stub (a jetty's tip among them): with the coast's close nodes kept
// they were 4 m to 100 m apart and the faces there had sides of 7 m, and only the close nodes'
// merge (the default) took them off. Since the conflicts get their corners under the arc in
// conflict, the repair puts none there: with the close nodes merged or kept, no coast side is
// under h/32 and no side under 0.1 km (the canal is 0.3 km wide; an explicit model's time step
// there is some 30 times longer than at 7 m).
TEST(CoastReal, a_canal_narrower_than_h_keeps_no_side_far_shorter_than_its_width) {
    for (double gap : {1.0 / 32, 0.0}) {
        SCOPED_TRACE("close_node_gap " + std::to_string(gap));
        MeshOptions o =
            region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, 5);
        o.close_node_gap = gap;
        const Mesh mesh = mesh_ocean(o).mesh;
        EXPECT_GE(worst_quality(mesh), 0.3);
        const Shortest s = shortest_sides(mesh);
        EXPECT_GE(s.boundary, 5.0 / 32); // 0.007 km, kept, before
        EXPECT_GE(s.side, 0.1);
        expect_valid_mesh(mesh, o, "suez.nc");
    }
}

// The Suez Canal as above: the straits closed north of 30.51N leave the canal's stub above the
// Bitter Lakes (0.3 km wide) a dead end, narrower than inlet_width h (2.5 km), which the inlet
// rule closes. Its closing comes after the straits', so the stub's northern part goes and no
// face is left there; the Bitter Lakes stay, a basin cut off.
TEST(CoastReal, a_canal_stub_the_strait_closings_leave_as_a_dead_end_closes) {
    const MeshOptions o =
        region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, 5);
    const OceanMesh run = mesh_ocean(o);
    std::size_t in_stub = 0;
    for (const auto &f : run.mesh.faces) {
        const LonLat c = vec_to_lonlat(
            normalized(run.mesh.nodes[f[0]] + run.mesh.nodes[f[1]] + run.mesh.nodes[f[2]]));
        in_stub += c.lon > 32.3 && c.lon < 32.4 && c.lat > 30.45 && c.lat < 30.55;
    }
    EXPECT_EQ(in_stub, 0u); // 43 faces before
    // The Gulf of Suez's end of the region (1,167 km2: the closings cut the canal south of the
    // Bitter Lakes too), then the Bitter Lakes (177 km2).
    ASSERT_EQ(run.mesher.seas_cut_off.size(), 2u);
    EXPECT_GT(run.mesher.seas_cut_off[0], 1000.0);
    EXPECT_GT(run.mesher.seas_cut_off[1], 150.0);
    expect_valid_mesh(run.mesh, o, "suez.nc");
}

// GSHHG intermediate around Seram and Misool (128.5..131.5E, 4.5..1.5S): in the global run at
// 100 km a face there below 0.3 had no coast side (its corners on the coast across water), and
// the first blunting step read its corner index as -1, pinched a node of another triangle and
// left 130.05E 2.97S between two fans of water (mesh-verify: non-manifold). Every size, with
// and without the region box, must stay a manifold above the floor.
TEST(CoastReal, islands_near_130E_3S_mesh_as_a_manifold_above_the_floor_at_every_size) {
    for (double h : {100.0, 50.0, 25.0}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        MeshOptions o =
            region_run("coast/hostile/gshhg_i_seram.geojson", {128.5, -4.5, 131.5, -1.5}, h);
        expect_valid_mesh(mesh_ocean(o).mesh, o, "seram_region.nc");
        if (h < 100)
            continue; // the global ocean below 100 km takes seconds
        o.region.reset();
        expect_valid_mesh(mesh_ocean(o).mesh, o, "seram_global.nc");
    }
}

// An edge of a mesh by its two nodes, smaller first, and the faces on each edge of `mesh`.
using MeshEdge = std::pair<NodeIndex, NodeIndex>;
MeshEdge edge_of(NodeIndex a, NodeIndex b) {
    return {std::min(a, b), std::max(a, b)};
}
std::map<MeshEdge, std::vector<std::size_t>> faces_of_edges(const Mesh &mesh) {
    std::map<MeshEdge, std::vector<std::size_t>> out;
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        for (int i = 0; i < 3; ++i)
            out[edge_of(mesh.faces[f][i], mesh.faces[f][(i + 1) % 3])].push_back(f);
    return out;
}

// The mesh's pieces over shared edges (the output splits a node between two fans of water, so a
// piece hanging at one stands apart): each piece's area and perimeter (km2, km), and whether it
// reaches an open (region) boundary.
struct Piece {
    double area_km2 = 0, perimeter_km = 0;
    bool open = false;
};
std::vector<Piece> pieces_of(const Mesh &mesh) {
    std::vector<std::size_t> parent(mesh.faces.size());
    for (std::size_t i = 0; i < parent.size(); ++i)
        parent[i] = i;
    auto root = [&](std::size_t i) {
        while (parent[i] != i)
            i = parent[i] = parent[parent[i]];
        return i;
    };
    const auto faces_of_edge = faces_of_edges(mesh);
    for (const auto &[edge, faces] : faces_of_edge)
        for (std::size_t k = 1; k < faces.size(); ++k)
            parent[root(faces[k])] = root(faces[0]);
    std::map<std::size_t, Piece> by_root;
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &n = mesh.faces[f];
        by_root[root(f)].area_km2 +=
            spherical_triangle_area(mesh.nodes[n[0]], mesh.nodes[n[1]], mesh.nodes[n[2]]) *
            earth_radius_km * earth_radius_km;
    }
    for (const auto &[edge, faces] : faces_of_edge)
        if (faces.size() == 1)
            by_root[root(faces[0])].perimeter_km +=
                arc_angle(mesh.nodes[edge.first], mesh.nodes[edge.second]) * earth_radius_km;
    for (const BoundaryEdge &b : mesh.boundary)
        if (b.tag == EdgeTag::open)
            by_root[root(faces_of_edge.at(edge_of(b.a, b.b)).front())].open = true;
    std::vector<Piece> out;
    for (const auto &[r, p] : by_root)
        out.push_back(p);
    std::sort(out.begin(), out.end(),
              [](const Piece &x, const Piece &y) { return x.area_km2 > y.area_km2; });
    return out;
}

// The Suez fixture at sizes where the strait closings cut the canal into pieces, some hanging
// from the rest at a pinched node only (a face or two, 0.05-25 km2), which stood apart in the
// output, unreported, until the faces beside a closing were kept when a later one took them and
// the pieces at pinched nodes were looked at. Every piece but the largest is now a basin the
// report lists, and none is one the inlet rule (MesherOptions: at most h^2 of water, or at most
// 25 h^2 and narrower on average than h/2) would close.
TEST(CoastReal, every_piece_the_closings_leave_apart_is_a_reported_basin_the_inlet_rule_keeps) {
    for (double h : {3.0, 6.0, 8.0, 20.0}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        const MeshOptions o =
            region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, h);
        const OceanMesh run = mesh_ocean(o);
        const std::vector<Piece> pieces = pieces_of(run.mesh);
        ASSERT_FALSE(pieces.empty());
        // The pieces apart: the ocean components kept (the Gulf of Suez reaches the box's
        // south edge, apart from the Mediterranean side) and the basins the closings cut off.
        const auto kept = std::count_if(run.mesher.components.begin(), run.mesher.components.end(),
                                        [](const OceanComponent &c) { return c.kept; });
        EXPECT_EQ(pieces.size(), kept + run.mesher.seas_cut_off.size());
        for (std::size_t k = 1; k < pieces.size(); ++k) {
            const Piece &p = pieces[k];
            if (p.open)
                continue; // ocean reaching the region's edge: no inlet to close
            EXPECT_GT(p.area_km2, h * h);
            EXPECT_FALSE(p.area_km2 <= 25 * h * h && 2 * p.area_km2 < 0.5 * h * p.perimeter_km)
                << p.area_km2 << " km2, " << p.perimeter_km << " km around";
        }
    }
}

// The water behind each short chord of `mesh` (an edge between two boundary nodes across water,
// shorter than h/4 at a uniform size h): for each side that the chord cuts off from the other,
// its area and perimeter (km2, km), and whether it touches an open (region) boundary.
struct Behind {
    double area_km2 = 0, perimeter_km = 0;
    bool open = false;
};
std::vector<Behind> water_behind_short_chords(const Mesh &mesh, double h) {
    const auto faces_of = faces_of_edges(mesh);
    std::map<MeshEdge, EdgeTag> tag;
    std::vector<char> on_boundary(mesh.nodes.size(), 0);
    for (const BoundaryEdge &b : mesh.boundary) {
        tag[edge_of(b.a, b.b)] = b.tag;
        on_boundary[b.a] = on_boundary[b.b] = 1;
    }
    auto km = [&](NodeIndex a, NodeIndex b) {
        return arc_angle(mesh.nodes[a], mesh.nodes[b]) * earth_radius_km;
    };
    std::vector<Behind> out;
    std::vector<std::size_t> seen(mesh.faces.size(), 0); // the flood's number where it went
    std::size_t flood = 0;
    for (const auto &[chord, faces] : faces_of) {
        if (faces.size() != 2 || !on_boundary[chord.first] || !on_boundary[chord.second] ||
            km(chord.first, chord.second) >= h / 4)
            continue;
        for (int side = 0; side < 2; ++side) {
            // Flood from one face without crossing the chord, up to 25 h^2.
            std::vector<std::size_t> stack{faces[side]};
            seen[faces[side]] = ++flood;
            Behind w;
            bool reached_other = false;
            while (!stack.empty() && !reached_other && w.area_km2 <= 25 * h * h) {
                const auto &n = mesh.faces[stack.back()];
                stack.pop_back();
                w.area_km2 +=
                    spherical_triangle_area(mesh.nodes[n[0]], mesh.nodes[n[1]], mesh.nodes[n[2]]) *
                    earth_radius_km * earth_radius_km;
                for (int i = 0; i < 3; ++i) {
                    const MeshEdge e = edge_of(n[i], n[(i + 1) % 3]);
                    if (e == chord)
                        continue;
                    const std::vector<std::size_t> &across = faces_of.at(e);
                    if (across.size() == 1) {
                        w.perimeter_km += km(e.first, e.second);
                        w.open = w.open || tag[e] == EdgeTag::open;
                    }
                    for (const std::size_t g : across)
                        if (g == faces[1 - side])
                            reached_other = true;
                        else if (seen[g] != flood) {
                            seen[g] = flood;
                            stack.push_back(g);
                        }
                }
            }
            if (!reached_other && stack.empty())
                out.push_back(w);
        }
    }
    return out;
}

// The Suez fixture: after the straits close and the land's faces go, the refinement and the
// removals leave stubs of water behind chords far shorter than h (hundreds of metres at 5 km),
// meshed with faces as small. The inlet rule (at most h^2 behind, or narrower than h/2 on average
// and at most 25 h^2) now closes them behind any chord shorter than h/4, not only beside a
// strait closing: none is left behind such a chord, by the rule measured here on the output.
TEST(CoastReal, no_water_the_inlet_rule_closes_is_left_behind_a_chord_shorter_than_h_over_4) {
    for (double h : {3.0, 5.0}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        const MeshOptions o =
            region_run("coast/hostile/gshhg_f_suez.geojson", {31.5, 29.5, 33.5, 31.5}, h);
        for (const Behind &w : water_behind_short_chords(mesh_ocean(o).mesh, h)) {
            if (w.open)
                continue;
            EXPECT_GT(w.area_km2, h * h);
            EXPECT_FALSE(w.area_km2 <= 25 * h * h && 2 * w.area_km2 < 0.5 * h * w.perimeter_km)
                << w.area_km2 << " km2, " << w.perimeter_km << " km around";
        }
    }
}

// GSHHG (as GMT ships it, bench/gshhg_land.py) stores Eurasia up to lon 190: Chukotka west of
// the Bering Strait lies at 180..190, Alaska at -170..-160. A region west of 180 met only
// Alaska through the spatial filter and meshed Chukotka as sea (GSHHG h, -180..-176, 64..68N:
// the whole box's 80,413 km2 as ocean). Its water must be about what Natural Earth's 1:50m
// land leaves in the same box (a source of its own: 1.4% apart; 47% before).
TEST(CoastReal, land_stored_past_180_is_found_by_a_region_west_of_180) {
    const std::array<double, 4> box{-180, 64, -160, 68};
    const MeshOptions o = region_run("coast/hostile/gshhg_i_chukotka_360.geojson", box, 10);
    const Mesh mesh = mesh_ocean(o).mesh;
    MeshOptions ne = region_run("coast/ne_50m_land.gpkg", box, 10);
    ne.coast_layer = "land";
    const double gshhg_km2 = compute_stats(mesh).area_km2,
                 ne_km2 = compute_stats(mesh_ocean(ne).mesh).area_km2;
    EXPECT_NEAR(gshhg_km2 / ne_km2, 1.0, 0.05) << gshhg_km2 << " km2 against " << ne_km2;
    expect_valid_mesh(mesh, o, "chukotka.nc");
}

// A box's parallel edge, held as the chord between the coasts it meets, bulged past the box:
// NE 1:50m, the north-west shelf to 62N at 60 km (the man page's shelf example) had nodes at
// 62.127N, past a raster cut there, from the chord between the Faroes and Norway (12 degrees
// of longitude). Nodes may lie past it by the bulge of a great-circle arc 1.5 h long between
// two points on it, where the refinement splits an open segment (62N at 60 km: 0.0027 degree).
TEST(CoastReal, a_region_box_holds_its_mesh_along_its_parallels) {
    for (const auto &[box, h] : {std::pair{std::array<double, 4>{-12, 46, 13, 62}, 60.0},
                                 std::pair{std::array<double, 4>{-20, 60, 60, 80}, 100.0}}) {
        MeshOptions o = region_run("coast/ne_50m_land.gpkg", box, h);
        o.coast_layer = "land";
        const Mesh mesh = mesh_ocean(o).mesh;
        double lat_max = -90, lat_min = 90;
        for (const Vec3 &p : mesh.nodes) {
            lat_max = std::max(lat_max, vec_to_lonlat(p).lat);
            lat_min = std::min(lat_min, vec_to_lonlat(p).lat);
        }
        const double bulge_deg =
            std::pow(1.5 * h / earth_radius_km, 2) / 8 * std::tan(box[3] * deg_to_rad) / deg_to_rad;
        EXPECT_LT(lat_max, box[3] + bulge_deg) << box[3];
        EXPECT_GT(lat_min, box[1] - 1e-9) << box[1];
    }
}

// Where the box's north edge at 41N meets the Thracian coast in short pieces (Porto Lagos, GSHHG
// i), the coast/box corners closer than h/2 went with the resampling, and the shaped segment
// from the box edge at 25.16E to the coast at 24.96E, 40.95N was tagged open for the box edge it
// started on: an open boundary (ADCIRC's forced elevations) leaving the box across 9 km of coast.
// A segment that leaves the outline is coast: every open edge lies on the box.
TEST(CoastReal, every_open_edge_lies_on_the_region_box) {
    const std::array<double, 4> box{24.3, 40.5, 25.8, 41};
    MeshOptions o = region_run("coast/hostile/gshhg_i_porto_lagos.geojson", box, 20);
    o.hmin_km = 3;
    const Mesh mesh = mesh_ocean(o).mesh;
    // a node on the box: on a meridian edge (the land's snap grid, 2^-20 degree, apart), or on a
    // parallel edge up to the sag of the arcs bisected along it (0.0002 degree here; the segment
    // from the box to the coast ended 0.048 degree south of it)
    const double sag = 0.002;
    auto on_box = [&](NodeIndex n) {
        const LonLat p = vec_to_lonlat(mesh.nodes[n]);
        return std::abs(p.lon - box[0]) < 1e-6 || std::abs(p.lon - box[2]) < 1e-6 ||
               std::abs(p.lat - box[1]) < sag || std::abs(p.lat - box[3]) < sag;
    };
    std::size_t open = 0;
    for (const auto &e : mesh.boundary) {
        if (e.tag != EdgeTag::open)
            continue;
        ++open;
        EXPECT_TRUE(on_box(e.a) && on_box(e.b))
            << vec_to_lonlat(mesh.nodes[e.a]).lon << " " << vec_to_lonlat(mesh.nodes[e.a]).lat
            << " - " << vec_to_lonlat(mesh.nodes[e.b]).lon << " "
            << vec_to_lonlat(mesh.nodes[e.b]).lat;
    }
    EXPECT_GE(open, 8u);
}

// The summary's and `info`'s extent of a region across 180 was lon -180 .. 180 (the whole
// band); it is the region's box, in [0, 360) as the writers put such a region, and a global
// mesh's stays -180 .. 180.
TEST(CoastReal, a_region_across_180_has_its_extent_east_of_180) {
    MeshOptions o = region_run("coast/ne_50m_land.gpkg", {170, -50, -170, -30}, 60);
    o.coast_layer = "land";
    const MeshStats across = compute_stats(mesh_ocean(o).mesh);
    EXPECT_NEAR(across.lon_min, 170, 1e-9);
    EXPECT_NEAR(across.lon_max, 190, 1e-9);
    o.region.reset();
    o.hmax_km = 500;
    const MeshStats global = compute_stats(mesh_ocean(o).mesh);
    EXPECT_NEAR(global.lon_min, -180, 1);
    EXPECT_NEAR(global.lon_max, 180, 1);
}

} // namespace
} // namespace globemesh
