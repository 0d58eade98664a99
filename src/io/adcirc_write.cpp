// ADCIRC fort.14 and SCHISM hgrid.gr3 / hgrid.ll writers (one layout, the writers table's rows
// ADCIRC and SCHISM).
//
// Layout (ADCIRC's "grid and boundary information file", which SCHISM's hgrid.gr3 follows): a
// title line; "NE NP"; NP lines "id lon lat depth" (1-based, depth positive down); NE lines
// "id 3 n1 n2 n3" (counter-clockwise); then NOPE, NETA and one node string per open run
// ("count 0", then a node a line); NBOU, NVEL and one string per land run ("count IBTYPE", then a
// node a line). Each line's counts come first; the rest after "!" is a comment.
//
// Boundary strings follow the boundary loops, walked with the mesh on their left (ADCIRC's order:
// outer boundaries counter-clockwise, islands clockwise). A loop with open edges splits into
// alternating open and land runs (IBTYPE 0), the node where two runs meet ending one and starting
// the next. A loop of coast edges only is one closed string, its first node repeated at its end:
// IBTYPE 0 (mainland) when it is an outer boundary, 1 (island) otherwise. Outer: never in a part
// of the mesh (faces joined by nodes) with open edges, whose loop is its outer one (the lon/lat
// area cannot tell a loop around a pole); else a loop whose area in the file's x y is positive:
// with an --output-srs (which keeps every face counter-clockwise) as ADCIRC sees the plane, and
// in lon/lat in a region; in a global lon/lat mesh the loop of most nodes, there being no
// outside.
//
// Coordinates are lon/lat degrees, in [-180, 180), or [0, 360) for a mesh that crosses the
// antimeridian and fits there without a face cut; or, with an --output-srs (WriteOptions), x y in
// that CRS (SCHISM's hgrid.ll excepted: write_outputs gives it none). The format has no place for
// the CRS. Without a depth field every depth is 0 (a grid
// for tools that interpolate the bathymetry afterwards); a node without a depth (NaN: the
// bathymetry does not cover it) is refused, as no model runs on it.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "disjoint_sets.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "model_coordinates.hpp"
#include "text_out.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;
using io::TextOut;

/// A node string of the boundary section: its 1-based nodes and its type.
struct NodeString {
    std::vector<std::uint32_t> nodes;
    int ibtype = 0;
    bool beside_open = false; ///< a closed string in a part of the mesh with open edges
};

struct BoundaryStrings {
    std::vector<NodeString> open, land;
    std::size_t open_nodes = 0, land_nodes = 0;
};

/// Whether the file's x y are planar (an --output-srs), not lon/lat degrees.
bool planar(const io::ModelCoordinates &xy) {
    return xy.crs && xy.crs->projected;
}

/// The signed area of a closed ring of 1-based nodes in the file's x y (positive
/// counter-clockwise), in lon/lat each longitude step taken the shorter way round.
double ring_area(const std::vector<std::uint32_t> &ring, const io::ModelCoordinates &xy) {
    double area = 0;
    for (std::size_t i = 0; i + 1 < ring.size(); ++i) {
        const std::size_t a = ring[i] - 1, b = ring[i + 1] - 1;
        double step = xy.x[b] - xy.x[a];
        if (!planar(xy))
            step -= 360 * std::round(step / 360);
        area -= step * (xy.y[a] + xy.y[b]) / 2; // the trapezoid under the step
    }
    return area;
}

/// The node strings of a loop with open edges: one per run of one tag, each ending on the node
/// that starts the next.
void split_loop(const io::MeshTopology &topo, const std::vector<std::size_t> &loop,
                BoundaryStrings &s) {
    const auto node = [&](std::size_t i) {
        return topo.edge_nodes(std::size_t(topo.boundary_edges[loop[i % loop.size()]]))[0] + 1;
    };
    for (const io::BoundaryRun &run : io::loop_runs(topo, loop)) {
        NodeString string;
        for (std::size_t k = 0; k <= run.count; ++k)
            string.nodes.push_back(node(run.first + k));
        (run.tag == int(EdgeTag::open) ? s.open : s.land).push_back(std::move(string));
    }
}

/// Each node's part of the mesh: the root of the nodes its faces join.
std::vector<std::uint32_t> node_parts(const Mesh &mesh) {
    DisjointSets<> parts(mesh.nodes.size());
    for (const auto &f : mesh.faces)
        parts.join(f[0], f[1]), parts.join(f[0], f[2]);
    return std::move(parts).roots();
}

/// IBTYPE of the closed coast strings: 0 for an outer boundary (see the top of the file), else 1.
void ring_types(std::vector<NodeString> &rings, bool regional, const io::ModelCoordinates &xy) {
    const bool by_area = regional || planar(xy);
    std::size_t longest = 0;
    for (std::size_t i = 0; i < rings.size(); ++i) {
        const bool outer = !rings[i].beside_open && ring_area(rings[i].nodes, xy) > 0;
        rings[i].ibtype = by_area && outer ? 0 : 1;
        if (rings[i].nodes.size() > rings[longest].nodes.size())
            longest = i;
    }
    if (!by_area && !rings.empty())
        rings[longest].ibtype = 0;
}

BoundaryStrings boundary_strings(const Mesh &mesh, const io::ModelCoordinates &xy) {
    const auto topology = io::topology_of(mesh);
    const io::MeshTopology &topo = *topology;
    const auto is_open = [&](std::size_t e) { return topo.boundary_tags[e] == int(EdgeTag::open); };
    const std::vector<std::uint32_t> part = node_parts(mesh);
    std::vector<bool> part_open(mesh.nodes.size(), false);
    BoundaryStrings s;
    std::vector<NodeString> rings;
    bool regional = false;
    for (auto &loop : io::boundary_loops(topo, mesh.nodes.size())) {
        if (std::any_of(loop.begin(), loop.end(), is_open)) {
            regional = true;
            part_open[part[topo.edge_nodes(std::size_t(topo.boundary_edges[loop[0]]))[0]]] = true;
            split_loop(topo, loop, s);
            continue;
        }
        NodeString ring;
        for (auto e : loop)
            ring.nodes.push_back(topo.edge_nodes(std::size_t(topo.boundary_edges[e]))[0] + 1);
        ring.nodes.push_back(ring.nodes.front()); // a closed coast string ends where it starts
        rings.push_back(std::move(ring));
    }
    for (auto &ring : rings) // after every loop: an open one may come after a ring of its part
        ring.beside_open = part_open[part[ring.nodes.front() - 1]];
    ring_types(rings, regional, xy);
    s.land.insert(s.land.end(), std::make_move_iterator(rings.begin()),
                  std::make_move_iterator(rings.end()));
    for (const auto &r : s.open)
        s.open_nodes += r.nodes.size();
    for (const auto &r : s.land)
        s.land_nodes += r.nodes.size();
    return s;
}

/// The node strings of one kind: each "count IBTYPE ! comment", then its nodes, a line each.
void write_strings(TextOut &out, const std::vector<NodeString> &strings, const char *kind) {
    for (std::size_t k = 0; k < strings.size(); ++k) {
        out.integer(strings[k].nodes.size()).text(" ").integer(std::size_t(strings[k].ibtype));
        out.text(" ! nodes of ").text(kind).text(" boundary ").integer(k + 1).line();
        for (auto n : strings[k].nodes)
            out.integer(n).line();
    }
}

void write_grid(const Mesh &mesh, const fs::path &path, const WriteOptions &options,
                const std::string &what) {
    const Field *depth = mesh.node_field("depth");
    if (depth)
        io::require_depths(*depth, what + " " + path.string());
    const io::ModelCoordinates xy =
        io::model_coordinates(mesh, options.output_srs, what + " " + path.string());
    OutputFile file(path, options.overwrite, what);
    TextOut out(file.temp_path(), path, what);
    std::string title = options.title;
    std::replace_if(
        title.begin(), title.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    out.text(title).line();
    out.integer(mesh.faces.size()).text(" ").integer(mesh.nodes.size()).text(" ! NE NP").line();
    const double total = double(mesh.nodes.size() + mesh.faces.size()) + 1;
    constexpr std::size_t step = 1 << 16;
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
        if (i % step == 0)
            report(options.progress, double(i) / total, "write_model_grid");
        out.integer(i + 1).text(" ").real(xy.x[i]).text(" ").real(xy.y[i]).text(" ");
        out.real(depth ? depth->values[i] : 0.0).line();
    }
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        if (f % step == 0)
            report(options.progress, double(mesh.nodes.size() + f) / total, "write_model_grid");
        const auto &face = mesh.faces[f];
        out.integer(f + 1).text(" 3 ").integer(face[0] + 1).text(" ").integer(face[1] + 1);
        out.text(" ").integer(face[2] + 1).line();
    }
    const BoundaryStrings s = boundary_strings(mesh, xy);
    out.integer(s.open.size()).text(" ! NOPE: open boundaries").line();
    out.integer(s.open_nodes).text(" ! NETA: open boundary nodes").line();
    write_strings(out, s.open, "open");
    out.integer(s.land.size()).text(" ! NBOU: land boundaries").line();
    out.integer(s.land_nodes).text(" ! NVEL: land boundary nodes").line();
    write_strings(out, s.land, "land");
    out.close();
    report(options.progress, 1, "write_model_grid");
    file.commit();
}

} // namespace

/// The ADCIRC row of the writers table (writers.cpp).
void write_as_adcirc(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    write_grid(mesh, path, options, "ADCIRC output");
}

/// The SCHISM row of the writers table (writers.cpp): hgrid.gr3 and hgrid.ll (always lon/lat).
void write_as_schism(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    write_grid(mesh, path, options, "SCHISM output");
}

} // namespace globemesh
