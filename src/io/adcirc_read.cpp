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

namespace globemesh {

namespace {

namespace fs = std::filesystem;

/// The file's lines as words, with the line number for messages.
class Lines {
public:
    explicit Lines(const fs::path &path) : path_(path), in_(path) {
        if (!in_)
            throw IoError("ADCIRC file " + path.string() + ": cannot open; give an existing file");
    }
    [[noreturn]] void fail(const std::string &what) const {
        throw DataError("ADCIRC file " + path_.string() + ": line " + std::to_string(line_) + ": " +
                        what);
    }
    /// The next line's words (before any "!"); false at the end of the file.
    bool next(std::vector<std::string_view> &words) {
        if (!std::getline(in_, text_))
            return false;
        ++line_;
        words.clear();
        const std::string_view s(text_.data(), std::min(text_.find('!'), text_.size()));
        for (std::size_t i = 0; i < s.size();) {
            while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i])))
                ++i;
            std::size_t j = i;
            while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j])))
                ++j;
            if (j > i)
                words.push_back(s.substr(i, j - i));
            i = j;
        }
        return true;
    }
    /// The next line's words; fails at the end of the file or when it has fewer than `n`.
    const std::vector<std::string_view> &need(std::size_t n, const char *what) {
        if (!next(words_))
            fail(std::string("the file ends where ") + what + " should be");
        if (words_.size() < n)
            fail(std::string("expected ") + what);
        return words_;
    }
    long long integer(std::string_view w, const char *what) const {
        long long v = 0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size())
            fail(std::string(what) + " '" + std::string(w) + "' is not an integer");
        return v;
    }
    double number(std::string_view w, const char *what) const {
        std::string s(w); // from_chars for double is missing from some standard libraries
        std::replace(s.begin(), s.end(), 'D', 'E');
        std::replace(s.begin(), s.end(), 'd', 'e');
        char *end = nullptr;
        const double v = std::strtod(s.c_str(), &end);
        if (end != s.c_str() + s.size() || !std::isfinite(v))
            fail(std::string(what) + " '" + s + "' is not a number");
        return v;
    }
    /// A count of at most `max`.
    std::size_t count(std::string_view w, const char *what, long long max = 1LL << 31) const {
        const long long v = integer(w, what);
        if (v < 0 || v > max)
            fail(std::string(what) + " " + std::to_string(v) + " is out of range");
        return std::size_t(v);
    }

private:
    const fs::path &path_;
    std::ifstream in_;
    std::string text_;
    std::vector<std::string_view> words_;
    std::size_t line_ = 0;
};

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
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".14" || ext == ".gr3" || ext == ".ll";
}

Mesh read_adcirc(const fs::path &path) {
    Lines in(path);
    Mesh mesh;
    in.need(0, "the title line");
    const auto &counts = in.need(2, "NE NP");
    const std::size_t ne = in.count(counts[0], "NE"), np = in.count(counts[1], "NP");
    const NodeIds ids = read_nodes(in, np, mesh);
    read_elements(in, ne, ids, mesh);
    // The strings' edges tag the boundary edges they lie on (build_topology matches them).
    if (read_strings(in, ids, EdgeTag::open, mesh.boundary))
        read_strings(in, ids, EdgeTag::coast, mesh.boundary);
    const io::MeshTopology topology = [&] {
        try {
            return io::build_topology(mesh);
        } catch (const DataError &e) {
            throw DataError("ADCIRC file " + path.string() + ": " + e.what());
        }
    }();
    std::vector<BoundaryEdge> boundary;
    for (std::size_t i = 0; i < topology.boundary_edges.size(); ++i) {
        const auto nodes = topology.edge_nodes(std::size_t(topology.boundary_edges[i]));
        boundary.push_back(
            {NodeIndex(nodes[0]), NodeIndex(nodes[1]), EdgeTag(topology.boundary_tags[i])});
    }
    mesh.boundary = std::move(boundary);
    return mesh;
}

} // namespace globemesh
