// TELEMAC SELAFIN writer (the SELAFIN row of writers.cpp): the geometry file NAME.slf and its
// boundary conditions file NAME.cli, written beside it.
//
// .slf (single precision SELAFIN, "SERAFIN " in the title's last 8 characters; with --co
// PRECISION=DOUBLE double precision, "SERAFIND", every real record in float64): big-endian
// Fortran sequential records, each framed by its byte length before and after. Records: the
// title (80 characters); NBV1 NBV2 (1 0); the variable name and unit (32 characters: BOTTOM, M);
// IPARAM (10 integers, IPARAM(1) = 1, IPARAM(10) = 0: no date record); NELEM NPOIN NDP(3) 1;
// IKLE (1-based nodes of each triangle, counter-clockwise); IPOBO (0 for an interior node, k for
// the k-th boundary node); X; Y (float32 lon/lat degrees, for TELEMAC's SPATIAL PROJECTION TYPE
// 3; or, with an --output-srs, x y in that CRS less the origin IPARAM(3), IPARAM(4), which
// TELEMAC and MDAL add back: the centre of the mesh's extent, so that float32 keeps about 3 cm
// over 1000 km; SELAFIN has no place for the CRS); then one time step: the time (0) and BOTTOM at
// every node, the bottom elevation (metres, positive up: minus the depth; 0 without a depth field).
//
// .cli: one line per boundary node in the boundary numbering, "LIHBOR LIUBOR LIVBOR HBOR UBOR
// VBOR AUBOR LITBOR TBOR ATBOR BTBOR N K": solid (coast) 2 2 2 ... 2, open (prescribed elevation,
// free velocity and tracer) 5 4 4 ... 4, the values 0, N the node and K its boundary number. The
// boundary numbering follows the boundary loops with the mesh on their left (TELEMAC's order:
// outer boundary counter-clockwise, islands clockwise), the loops with open edges first. A node
// takes the open codes when one of its two boundary edges is open.
#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "buffered_file.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "model_coordinates.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;

constexpr std::size_t report_every = 1 << 16;

/// Big-endian Fortran records, through a buffer.
class RecordOut {
public:
    RecordOut(const fs::path &temp, const fs::path &target)
        : file_(temp, target, "SELAFIN output") {}
    /// The length marker that opens and closes a record of `bytes` bytes.
    void marker(std::size_t bytes) { word(std::uint32_t(bytes)); }
    void integer(std::int64_t v) { word(std::uint32_t(std::int32_t(v))); }
    /// A real as float32, or float64 in a double precision (SERAFIND) file.
    void real(double v) {
        if (double_) {
            std::uint64_t u;
            std::memcpy(&u, &v, 8);
            word(std::uint32_t(u >> 32));
            word(std::uint32_t(u));
            return;
        }
        const float f = float(v);
        std::uint32_t u;
        std::memcpy(&u, &f, 4);
        word(u);
    }
    std::size_t real_bytes() const { return double_ ? 8 : 4; }
    void set_double(bool on) { double_ = on; }
    void text(const std::string &s, std::size_t width) {
        std::string padded = s.substr(0, width);
        padded.resize(width, ' ');
        file_.put(padded);
    }
    /// One record of whole text.
    void text_record(const std::string &s, std::size_t width) {
        marker(width);
        text(s, width);
        marker(width);
    }
    void integer_record(const std::vector<std::int64_t> &values) {
        marker(4 * values.size());
        for (auto v : values)
            integer(v);
        marker(4 * values.size());
    }
    void close() { file_.close(); }

private:
    void word(std::uint32_t u) {
        const char b[4] = {char(u >> 24), char(u >> 16), char(u >> 8), char(u)};
        file_.put({b, 4});
    }
    io::BufferedFile file_;
    bool double_ = false;
};

/// A boundary node in the boundary numbering: its 0-based node and whether it is open.
struct BoundaryNode {
    std::uint32_t node;
    bool open;
};

/// The boundary nodes in TELEMAC's numbering: each loop walked with the mesh on its left, from
/// its edge's start node; the loops with open edges first. At a node where two loops touch,
/// either continuation closes a loop.
std::vector<BoundaryNode> boundary_numbering(const io::MeshTopology &topo, std::size_t nodes) {
    const auto &edges = topo.boundary_edges;
    const auto start = [&](std::size_t i) { return topo.edge_nodes(std::size_t(edges[i]))[0]; };
    std::vector<std::uint32_t> by_start(edges.size()), first(nodes + 1, 0);
    for (std::size_t i = 0; i < edges.size(); ++i)
        ++first[std::size_t(start(i)) + 1];
    for (std::size_t v = 0; v < nodes; ++v)
        first[v + 1] += first[v];
    std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
    for (std::size_t i = 0; i < edges.size(); ++i)
        by_start[fill[std::size_t(start(i))]++] = std::uint32_t(i);
    std::vector<bool> used(edges.size(), false);
    std::vector<std::vector<BoundaryNode>> open_loops, closed_loops;
    for (std::size_t s = 0; s < edges.size(); ++s) {
        if (used[s])
            continue;
        std::vector<BoundaryNode> loop;
        bool any_open = false;
        for (std::size_t e = s, previous = s; e < edges.size();) {
            used[e] = true;
            const bool open = topo.boundary_tags[e] == int(EdgeTag::open);
            const bool open_before =
                loop.empty() ? false : topo.boundary_tags[previous] == int(EdgeTag::open);
            any_open = any_open || open;
            loop.push_back({std::uint32_t(start(e)), open || open_before});
            const auto b = std::size_t(topo.edge_nodes(std::size_t(edges[e]))[1]);
            previous = e;
            e = edges.size();
            for (auto k = first[b]; k < first[b + 1] && e == edges.size(); ++k)
                if (!used[by_start[k]])
                    e = by_start[k];
            if (e == edges.size() && topo.boundary_tags[previous] == int(EdgeTag::open))
                loop.front().open = true; // the closing edge ends at the first node
        }
        (any_open ? open_loops : closed_loops).push_back(std::move(loop));
    }
    std::vector<BoundaryNode> numbering;
    for (const auto *group : {&open_loops, &closed_loops})
        for (const auto &loop : *group)
            numbering.insert(numbering.end(), loop.begin(), loop.end());
    return numbering;
}

/// Refuses what SELAFIN cannot hold: nodes without a depth, counts past its 32-bit records.
void check_mesh(const Mesh &mesh, const Field *depth, const fs::path &path) {
    if (3 * mesh.faces.size() * 4 >= std::size_t(INT32_MAX) ||
        8 * mesh.nodes.size() >= std::size_t(INT32_MAX))
        throw DataError("SELAFIN output " + path.string() + ": " +
                        std::to_string(mesh.faces.size()) +
                        " triangles are more than a SELAFIN record holds (about 1.8e8)");
    if (depth)
        io::require_depths(*depth, "SELAFIN output " + path.string());
}

/// The integer origin SELAFIN's IPARAM(3) and IPARAM(4) give planar coordinates (the centre of
/// their extent), so that the float32 X and Y keep centimetres; 0 for lon/lat.
std::array<double, 2> origin(const io::ModelCoordinates &xy) {
    if (!xy.crs || !xy.crs->projected || xy.x.empty())
        return {0, 0};
    const auto [x0, x1] = std::minmax_element(xy.x.begin(), xy.x.end());
    const auto [y0, y1] = std::minmax_element(xy.y.begin(), xy.y.end());
    return {std::round((*x0 + *x1) / 2), std::round((*y0 + *y1) / 2)};
}

void write_slf(const Mesh &mesh, const std::vector<BoundaryNode> &boundary,
               const io::ModelCoordinates &xy, RecordOut &out, const WriteOptions &options) {
    const std::size_t np = mesh.nodes.size(), ne = mesh.faces.size();
    std::string title = options.title;
    std::replace_if(
        title.begin(), title.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
    title.resize(72, ' ');
    out.text_record(title + (out.real_bytes() == 8 ? "SERAFIND" : "SERAFIN "), 80);
    out.integer_record({1, 0});
    out.text_record("BOTTOM          M               ", 32);
    const auto at = origin(xy);
    out.integer_record({1, 0, std::int64_t(at[0]), std::int64_t(at[1]), 0, 0, 0, 0, 0, 0});
    out.integer_record({std::int64_t(ne), std::int64_t(np), 3, 1});
    const double total = double(ne + 4 * np) + 1;
    out.marker(12 * ne);
    for (std::size_t f = 0; f < ne; ++f) {
        if (f % report_every == 0)
            report(options.progress, double(f) / total, "write_selafin");
        for (NodeIndex n : mesh.faces[f])
            out.integer(std::int64_t(n) + 1);
    }
    out.marker(12 * ne);
    std::vector<std::int32_t> ipobo(np, 0);
    for (std::size_t k = 0; k < boundary.size(); ++k)
        ipobo[boundary[k].node] = std::int32_t(k + 1);
    out.marker(4 * np);
    for (auto k : ipobo)
        out.integer(k);
    out.marker(4 * np);
    const Field *depth = mesh.node_field("depth");
    for (int part = 0; part < 3; ++part) { // X, Y, BOTTOM
        report(options.progress, double(ne + (part + 1) * np) / total, "write_selafin");
        const std::size_t real = out.real_bytes();
        if (part == 2)
            out.marker(real), out.real(0), out.marker(real); // the time step's time: 0
        out.marker(real * np);
        for (std::size_t i = 0; i < np; ++i)
            out.real(part == 0   ? xy.x[i] - at[0]
                     : part == 1 ? xy.y[i] - at[1]
                     : depth     ? -depth->values[i]
                                 : 0.0);
        out.marker(real * np);
    }
}

void write_cli(const std::vector<BoundaryNode> &boundary, const fs::path &temp,
               const fs::path &target) {
    std::FILE *file = std::fopen(temp.c_str(), "wb");
    bool ok = file != nullptr;
    for (std::size_t k = 0; ok && k < boundary.size(); ++k)
        ok = std::fprintf(file, "%s 0.000 0.000 0.000 0.000 %d 0.000 0.000 0.000 %u %zu\n",
                          boundary[k].open ? "5 4 4" : "2 2 2", boundary[k].open ? 4 : 2,
                          unsigned(boundary[k].node + 1), k + 1) > 0;
    if (file && std::fclose(file) != 0)
        ok = false;
    if (!ok)
        throw IoError("SELAFIN boundary file " + target.string() + ": writing failed (" +
                      std::strerror(errno) + ")" + OutputFile::full_disk_note(temp));
}

} // namespace

/// The SELAFIN row of the writers table (writers.cpp): NAME.slf and NAME.cli beside it. Both
/// files join the run's OutputBatch (write_outputs always has one), so they appear together.
void write_as_selafin(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    const Field *depth = mesh.node_field("depth");
    check_mesh(mesh, depth, path);
    const io::ModelCoordinates xy =
        io::model_coordinates(mesh, options.output_srs, "SELAFIN output " + path.string());
    fs::path cli_path = path;
    cli_path.replace_extension(".cli");
    OutputFile slf(path, options.overwrite, "SELAFIN output");
    OutputFile cli(cli_path, options.overwrite, "SELAFIN boundary file");
    const std::vector<BoundaryNode> boundary =
        boundary_numbering(io::build_topology(mesh), mesh.nodes.size());
    RecordOut out(slf.temp_path(), path);
    out.set_double(creation_option(options.creation_options, "PRECISION", "SINGLE") == "DOUBLE");
    write_slf(mesh, boundary, xy, out, options);
    out.close();
    write_cli(boundary, cli.temp_path(), cli_path);
    report(options.progress, 1, "write_selafin");
    slf.commit();
    cli.commit();
}

} // namespace globemesh
