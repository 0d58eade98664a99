// ADCIRC fort.14 / SCHISM hgrid.gr3 reader: see globemesh/mesh_read.hpp.
//
// Layout (ADCIRC's "grid and boundary information file"): a title line; "NE NP"; NP lines
// "id x y depth"; NE lines "id 3 n1 n2 n3"; then optionally NOPE, NETA and per open string
// "NVDLL [IBTYPEE]" and its nodes, then NBOU, NVEL and per land string "NVELL IBTYPE" and its
// nodes (a node line may carry more columns, e.g. a barrier's; only the first is read). Anything
// after "!" on a line is a comment. Node ids may be in any order; every index is checked.
#include "globemesh/mesh_read.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"
#include "text_lines.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;
using io::Lines;

/// Node index by the file's node id.
struct NodeIds {
    std::unordered_map<long long, NodeIndex> index;
    NodeIndex at(Lines &in, long long id) const {
        const auto it = index.find(id);
        if (it == index.end())
            in.fail("node " + std::to_string(id) + " is not among the nodes");
        return it->second;
    }
};

NodeIds read_nodes(Lines &in, std::size_t np, Mesh &mesh) {
    NodeIds ids;
    Field depth{"depth",
                "sea floor depth below mean sea level",
                "m",
                "sea_floor_depth_below_mean_sea_level",
                {}};
    for (std::size_t i = 0; i < np; ++i) {
        const auto &w = in.need(4, "a node line: id x y depth");
        const double x = in.number(w[1], "x"), y = in.number(w[2], "y");
        if (std::fabs(y) > 90 || std::fabs(x) > 540)
            in.fail("node coordinates (" + std::string(w[1]) + ", " + std::string(w[2]) +
                    ") are not longitude and latitude in degrees (a projected grid is not read)");
        if (!ids.index.emplace(in.integer(w[0], "node id"), NodeIndex(i)).second)
            in.fail("node id " + std::string(w[0]) + " is repeated");
        mesh.nodes.push_back(lonlat_to_vec(x, y));
        depth.values.push_back(in.number(w[3], "depth"));
    }
    mesh.node_fields.push_back(std::move(depth));
    return ids;
}

void read_elements(Lines &in, std::size_t ne, const NodeIds &ids, Mesh &mesh) {
    for (std::size_t i = 0; i < ne; ++i) {
        const auto &w = in.need(5, "an element line: id 3 n1 n2 n3");
        if (in.integer(w[1], "element node count") != 3)
            in.fail("element " + std::string(w[0]) +
                    " is not a triangle (only triangles are read)");
        mesh.faces.push_back({ids.at(in, in.integer(w[2], "node")),
                              ids.at(in, in.integer(w[3], "node")),
                              ids.at(in, in.integer(w[4], "node"))});
    }
}

/// One group of strings (open or land) of the boundary section into `tagged`; false when the
/// file ends before it.
bool read_strings(Lines &in, const NodeIds &ids, EdgeTag tag, std::vector<BoundaryEdge> &tagged) {
    std::vector<std::string_view> first;
    do {
        if (!in.next(first))
            return false;
    } while (first.empty());
    const std::size_t strings = in.count(first[0], "number of boundary strings");
    in.need(1, "the number of boundary nodes");
    for (std::size_t k = 0; k < strings; ++k) {
        const std::size_t n =
            in.count(in.need(1, "a boundary string's node count")[0], "boundary string node count");
        long long previous = -1;
        for (std::size_t j = 0; j < n; ++j) {
            const NodeIndex node = ids.at(in, in.integer(in.need(1, "a boundary node")[0], "node"));
            if (previous >= 0)
                tagged.push_back({NodeIndex(previous), node, tag});
            previous = node;
        }
    }
    return true;
}

} // namespace

bool is_adcirc_name(const fs::path &path) {
    const std::string ext = io::lower_extension(path);
    return ext == ".14" || ext == ".gr3" || ext == ".ll";
}

Mesh read_adcirc(const fs::path &path) {
    Lines in(path, "ADCIRC file", '!');
    Mesh mesh;
    in.need(0, "the title line");
    const auto &counts = in.need(2, "NE NP");
    const std::size_t ne = in.count(counts[0], "NE"), np = in.count(counts[1], "NP");
    const NodeIds ids = read_nodes(in, np, mesh);
    read_elements(in, ne, ids, mesh);
    // The strings' edges tag the boundary edges they lie on (build_topology matches them).
    if (read_strings(in, ids, EdgeTag::open, mesh.boundary))
        read_strings(in, ids, EdgeTag::coast, mesh.boundary);
    io::tag_boundary_edges(mesh, "ADCIRC file " + path.string());
    return mesh;
}

} // namespace globemesh
