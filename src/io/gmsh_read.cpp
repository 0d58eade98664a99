// gmsh MSH reader (4.1 and 2.2, ASCII and binary): see globemesh/mesh_read.hpp.
//
// Sections read, as gmsh's file format documentation lays them out: $MeshFormat (version, file
// type 0 = ASCII or 1 = binary, data size: that of size_t), $PhysicalNames ("dim tag "name""),
// $Entities (4.1: each curve's physical tags), $Nodes (4.1: blocks of tags then coordinates; 2.2:
// "id x y z"), $Elements (4.1: blocks of one entity and type; 2.2: "id type ntags tags... nodes"),
// $NodeData "depth". Other sections are skipped; $Projection (a projected mesh, as globemesh and
// seamsh write it) is refused. Triangles (type 2) are the faces; lines (type 1) tag the boundary
// edges: those in a physical group named "open" or "open_<k>" are open, the rest coast; points
// (type 15) are ignored. Coordinates are lon/lat degrees when every z is 0, else points in 3-D on a
// sphere (any radius). A binary file has the same sections with their numbers as the machine's int,
// size_t and double (little-endian here, checked by the int 1 after $MeshFormat's line), its text
// lines as in ASCII.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/mesh_read.hpp"
#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"
#include "text_lines.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;
using io::Lines;

constexpr int line_type = 1, triangle_type = 2, point_type = 15;

struct MshContent {
    bool v4 = true;
    bool binary = false;
    std::size_t size_bytes = 8;                      ///< a binary file's size_t
    std::map<int, std::string> line_groups;          ///< physical tag of dimension 1 -> name
    std::map<int, std::vector<int>> curve_groups;    ///< 4.1: curve entity -> physical tags
    std::vector<long long> node_tags;                ///< in the order read
    std::vector<std::array<double, 3>> xyz;          ///< per node read
    std::vector<std::array<long long, 3>> triangles; ///< node tags
    std::vector<std::pair<std::array<long long, 2>, int>> lines; ///< node tags, physical (0)
    std::map<long long, double> depth;                           ///< node tag -> $NodeData "depth"
};

std::string unquoted(std::string_view w) {
    if (w.size() >= 2 && w.front() == '"' && w.back() == '"')
        w = w.substr(1, w.size() - 2);
    return std::string(w);
}

void read_format(Lines &in, MshContent &c) {
    const auto &w = in.need(3, "version file-type data-size");
    const std::string version(w[0]);
    if (version.rfind("4", 0) == 0)
        c.v4 = true;
    else if (version.rfind("2", 0) == 0)
        c.v4 = false;
    else
        in.fail("MSH version " + version + " is not read (4.1 or 2.2)");
    if (w[1] != "0" && w[1] != "1")
        in.fail("file type " + std::string(w[1]) + " is neither ASCII (0) nor binary (1)");
    c.binary = w[1] == "1";
    if (!c.binary)
        return;
    c.size_bytes = in.count(w[2], "data size");
    if (c.size_bytes != 4 && c.size_bytes != 8)
        in.fail("data size " + std::string(w[2]) + " is not that of a size_t (4 or 8)");
    std::int32_t one = 0;
    in.bytes(&one, sizeof one, "the binary format's int 1");
    if (one == 0x01000000)
        in.fail("a binary file written with the other byte order is not read; save it as ASCII "
                "(gmsh: -bin 0)");
    if (one != 1)
        in.fail("a binary file's int 1 does not follow its format line (the file is cut, or "
                "not binary)");
}

/// A binary file's numbers, read where its last text line ended.
struct Binary {
    Lines &in;
    std::size_t size_bytes;
    int i32(const char *what) {
        std::int32_t v;
        in.bytes(&v, sizeof v, what);
        return v;
    }
    double f64(const char *what) {
        double v;
        in.bytes(&v, sizeof v, what);
        return v;
    }
    /// A size_t (a count or a tag) of at most `max`.
    std::size_t size(const char *what, std::uint64_t max = std::uint64_t(1) << 40) {
        std::uint64_t v = 0;
        if (size_bytes == 8) {
            in.bytes(&v, 8, what);
        } else {
            std::uint32_t v32;
            in.bytes(&v32, 4, what);
            v = v32;
        }
        if (v > max)
            in.fail(std::string(what) + " " + std::to_string(v) + " is out of range");
        return std::size_t(v);
    }
};

constexpr std::uint64_t max_count = std::uint64_t(1) << 31;

/// The nodes of an element of `type` that the reader takes (3-node triangles, 2-node lines,
/// points), else a failure naming it.
std::size_t nodes_of_type(Lines &in, long long type) {
    if (type == triangle_type || type == line_type || type == point_type)
        return type == triangle_type ? 3 : type == line_type ? 2 : 1;
    in.fail("element type " + std::to_string(type) +
            " is not read (3-node triangles, 2-node lines and points only)");
}

void read_physical_names(Lines &in, MshContent &c) {
    const std::size_t n = in.count(in.need(1, "the number of physical names")[0], "count");
    for (std::size_t i = 0; i < n; ++i) {
        const auto &w = in.need(3, "a physical name: dim tag \"name\"");
        if (in.integer(w[0], "dimension") == 1)
            c.line_groups[int(in.integer(w[1], "physical tag"))] = unquoted(w[2]);
    }
}

/// 4.1's binary $Entities: per entity its tag, its box, its physical tags and (but points) its
/// bounding entities.
void read_entities_binary(Lines &in, MshContent &c) {
    Binary b{in, c.size_bytes};
    std::size_t counts[4];
    for (std::size_t &n : counts)
        n = b.size("an entity count", max_count);
    for (int dim = 0; dim < 4; ++dim)
        for (std::size_t i = 0; i < counts[dim]; ++i) {
            const int tag = b.i32("an entity tag");
            for (int k = 0; k < (dim == 0 ? 3 : 6); ++k)
                b.f64("an entity's box");
            const std::size_t n = b.size("a number of physical tags", max_count);
            std::vector<int> physical;
            for (std::size_t k = 0; k < n; ++k)
                physical.push_back(std::abs(b.i32("a physical tag")));
            if (dim == 1)
                c.curve_groups[tag] = std::move(physical);
            if (dim > 0)
                for (std::size_t k = 0, m = b.size("a number of bounding entities", max_count);
                     k < m; ++k)
                    b.i32("a bounding entity");
        }
}

/// 4.1's $Entities: the physical tags of each curve (points, surfaces, volumes skipped).
void read_entities(Lines &in, MshContent &c) {
    if (c.binary)
        return read_entities_binary(in, c);
    const auto &counts = in.need(4, "numPoints numCurves numSurfaces numVolumes");
    const std::size_t points = in.count(counts[0], "count"), curves = in.count(counts[1], "count"),
                      others = in.count(counts[2], "count") + in.count(counts[3], "count");
    for (std::size_t i = 0; i < points; ++i)
        in.need(5, "a point entity");
    for (std::size_t i = 0; i < curves; ++i) {
        const auto &w = in.need(8, "a curve entity");
        const std::size_t n = in.count(w[7], "number of physical tags");
        if (w.size() < 8 + n)
            in.fail("a curve entity lists fewer physical tags than it says");
        auto &tags = c.curve_groups[int(in.integer(w[0], "entity tag"))];
        for (std::size_t k = 0; k < n; ++k)
            tags.push_back(int(std::abs(in.integer(w[8 + k], "physical tag"))));
    }
    for (std::size_t i = 0; i < others; ++i)
        in.need(8, "a surface or volume entity");
}

void add_node(Lines &in, MshContent &c, long long tag, const std::vector<std::string_view> &w,
              std::size_t first) {
    c.node_tags.push_back(tag);
    c.xyz.push_back(
        {in.number(w[first], "x"), in.number(w[first + 1], "y"), in.number(w[first + 2], "z")});
}

/// Binary $Nodes: 2.2's "int id, 3 doubles" per node after the count's line; 4.1's blocks (a
/// header of 3 ints and a size_t, the node tags, then each node's x y z and parameters).
void read_nodes_binary(Lines &in, MshContent &c) {
    Binary b{in, c.size_bytes};
    auto coordinates = [&](long long tag, int params) {
        c.node_tags.push_back(tag);
        c.xyz.push_back({b.f64("a node's x"), b.f64("a node's y"), b.f64("a node's z")});
        for (int k = 0; k < params; ++k)
            b.f64("a node's parametric coordinate");
    };
    if (!c.v4) {
        const std::size_t n = in.count(in.need(1, "the number of nodes")[0], "node count");
        for (std::size_t i = 0; i < n; ++i)
            coordinates(b.i32("a node id"), 0);
        return;
    }
    const std::size_t blocks = b.size("the number of node blocks", max_count);
    for (int k = 0; k < 3; ++k)
        b.size("the node count or tag range");
    std::vector<long long> tags;
    for (std::size_t block = 0; block < blocks; ++block) {
        const int dim = b.i32("a node block's dimension");
        b.i32("a node block's entity");
        const bool parametric = b.i32("a node block's parametric flag") != 0;
        const std::size_t n = b.size("a node block's count", max_count);
        tags.clear();
        for (std::size_t i = 0; i < n; ++i)
            tags.push_back(static_cast<long long>(b.size("a node tag")));
        for (std::size_t i = 0; i < n; ++i)
            coordinates(tags[i], parametric ? dim : 0);
    }
}

void read_nodes(Lines &in, MshContent &c) {
    if (c.binary)
        return read_nodes_binary(in, c);
    if (!c.v4) {
        const std::size_t n = in.count(in.need(1, "the number of nodes")[0], "node count");
        for (std::size_t i = 0; i < n; ++i) {
            const auto &w = in.need(4, "a node: id x y z");
            add_node(in, c, in.integer(w[0], "node id"), w, 1);
        }
        return;
    }
    const auto &head = in.need(4, "numEntityBlocks numNodes minNodeTag maxNodeTag");
    const std::size_t blocks = in.count(head[0], "block count");
    std::vector<long long> tags;
    for (std::size_t b = 0; b < blocks; ++b) {
        const auto &w = in.need(4, "a node block: entityDim entityTag parametric numNodes");
        const bool parametric = in.integer(w[2], "parametric") != 0;
        const std::size_t n = in.count(w[3], "node count");
        tags.clear();
        for (std::size_t i = 0; i < n; ++i)
            tags.push_back(in.integer(in.need(1, "a node tag")[0], "node tag"));
        for (std::size_t i = 0; i < n; ++i)
            add_node(in, c, tags[i], in.need(parametric ? 4 : 3, "node coordinates x y z"), 0);
    }
}

/// One element of `type` with node tags `nodes` (as many as nodes_of_type) and group `physical`.
void add_element_tags(MshContent &c, long long type, const long long *nodes, int physical) {
    if (type == triangle_type)
        c.triangles.push_back({nodes[0], nodes[1], nodes[2]});
    else if (type == line_type)
        c.lines.push_back({{nodes[0], nodes[1]}, physical});
}

/// One element of `type` with its node tags the words of `w` from `first`, and physical group
/// `physical` (0: none).
void add_element(Lines &in, MshContent &c, long long type, const std::vector<std::string_view> &w,
                 std::size_t first, int physical) {
    const std::size_t n = nodes_of_type(in, type);
    if (type == point_type)
        return;
    if (first + n > w.size())
        in.fail("an element has fewer nodes than its type");
    long long nodes[3];
    for (std::size_t k = 0; k < n; ++k)
        nodes[k] = in.integer(w[first + k], "node tag");
    add_element_tags(c, type, nodes, physical);
}

/// The physical group of a 4.1 element block's entity: a curve's first, else none (0).
int block_group(const MshContent &c, int dim, int entity) {
    const auto groups = c.curve_groups.find(entity);
    return dim == 1 && groups != c.curve_groups.end() && !groups->second.empty()
               ? groups->second.front()
               : 0;
}

/// Binary $Elements: 2.2's headers (type, count, number of tags as ints) each followed by its
/// elements (id, tags, nodes as ints); 4.1's blocks (3 ints and a size_t, then per element its
/// tag and nodes as size_t).
void read_elements_binary(Lines &in, MshContent &c) {
    Binary b{in, c.size_bytes};
    long long nodes[3];
    if (!c.v4) {
        const std::size_t total =
            in.count(in.need(1, "the number of elements")[0], "element count");
        for (std::size_t done = 0; done < total;) {
            const long long type = b.i32("an element header's type");
            const int count = b.i32("an element header's count"), tags = b.i32("a tag count");
            if (count <= 0 || std::size_t(count) > total - done || tags < 0 || tags > 1000)
                in.fail("an element header's counts do not add up to the elements");
            const std::size_t n = nodes_of_type(in, type);
            for (int i = 0; i < count; ++i, ++done) {
                b.i32("an element id");
                int physical = 0;
                for (int k = 0; k < tags; ++k) {
                    const int t = b.i32("an element tag");
                    physical = k == 0 ? t : physical;
                }
                for (std::size_t k = 0; k < n; ++k)
                    nodes[k] = b.i32("an element's node");
                add_element_tags(c, type, nodes, physical);
            }
        }
        return;
    }
    const std::size_t blocks = b.size("the number of element blocks", max_count);
    for (int k = 0; k < 3; ++k)
        b.size("the element count or tag range");
    for (std::size_t block = 0; block < blocks; ++block) {
        const int dim = b.i32("an element block's dimension"),
                  entity = b.i32("an element block's entity");
        const long long type = b.i32("an element block's type");
        const std::size_t count = b.size("an element block's count", max_count);
        const std::size_t n = nodes_of_type(in, type);
        const int physical = block_group(c, dim, entity);
        for (std::size_t i = 0; i < count; ++i) {
            b.size("an element tag");
            for (std::size_t k = 0; k < n; ++k)
                nodes[k] = static_cast<long long>(b.size("an element's node"));
            add_element_tags(c, type, nodes, physical);
        }
    }
}

void read_elements(Lines &in, MshContent &c) {
    if (c.binary)
        return read_elements_binary(in, c);
    if (!c.v4) {
        const std::size_t n = in.count(in.need(1, "the number of elements")[0], "element count");
        for (std::size_t i = 0; i < n; ++i) {
            const auto &w = in.need(3, "an element: id type ntags ...");
            const std::size_t tags = in.count(w[2], "tag count");
            const int physical = tags > 0 && w.size() > 3 ? int(in.integer(w[3], "physical")) : 0;
            add_element(in, c, in.integer(w[1], "element type"), w, 3 + tags, physical);
        }
        return;
    }
    const auto &head = in.need(4, "numEntityBlocks numElements minTag maxTag");
    const std::size_t blocks = in.count(head[0], "block count");
    for (std::size_t b = 0; b < blocks; ++b) {
        const auto &w = in.need(4, "an element block: entityDim entityTag type numElements");
        const int dim = int(in.integer(w[0], "dimension")), entity = int(in.integer(w[1], "tag"));
        const long long type = in.integer(w[2], "element type");
        const std::size_t n = in.count(w[3], "element count");
        const int physical = block_group(c, dim, entity);
        for (std::size_t i = 0; i < n; ++i)
            add_element(in, c, type, in.need(2, "an element: tag nodes..."), 1, physical);
    }
}

/// $NodeData: kept when its name is "depth".
void read_node_data(Lines &in, MshContent &c) {
    std::string name;
    const std::size_t strings = in.count(in.need(1, "the number of string tags")[0], "count");
    for (std::size_t i = 0; i < strings; ++i)
        name = i == 0 ? unquoted(in.need(1, "a string tag")[0]) : name;
    const std::size_t reals = in.count(in.need(1, "the number of real tags")[0], "count");
    for (std::size_t i = 0; i < reals; ++i)
        in.need(1, "a real tag");
    const std::size_t ints = in.count(in.need(1, "the number of integer tags")[0], "count");
    std::size_t components = 1, values = 0;
    for (std::size_t i = 0; i < ints; ++i) {
        const std::size_t v = in.count(in.need(1, "an integer tag")[0], "integer tag");
        if (i == 1)
            components = v;
        if (i == 2)
            values = v;
    }
    if (c.binary) { // per value: the node tag (int), its components (doubles)
        Binary b{in, c.size_bytes};
        for (std::size_t i = 0; i < values; ++i) {
            const long long tag = b.i32("a node value's tag");
            double first = 0;
            for (std::size_t k = 0; k < components; ++k) {
                const double v = b.f64("a node value");
                first = k == 0 ? v : first;
            }
            if (name == "depth" && components == 1)
                c.depth[tag] = first;
        }
        return;
    }
    for (std::size_t i = 0; i < values; ++i) {
        const auto &w = in.need(1 + components, "a node value: tag value");
        // A node without a depth is NaN (written "nan" or "-nan", as gmsh reads it back).
        const bool nan = w[1].find("nan") != std::string_view::npos ||
                         w[1].find("NaN") != std::string_view::npos;
        if (name == "depth" && components == 1)
            c.depth[in.integer(w[0], "node tag")] = nan ? NAN : in.number(w[1], "depth");
    }
}

/// Skips to `$End<name>`.
void skip_section(Lines &in, const std::string &name) {
    std::vector<std::string_view> w;
    const std::string end = "$End" + name;
    while (in.next(w))
        if (!w.empty() && w[0] == end)
            return;
    in.fail("the file ends before " + end);
}

MshContent read_content(const fs::path &path, Lines &in) {
    MshContent c;
    std::vector<std::string_view> w;
    bool format = false;
    while (in.next(w)) {
        if (w.empty())
            continue;
        if (!format && w[0] != "$MeshFormat")
            in.fail("not a gmsh MSH file (it does not begin with $MeshFormat)");
        if (w[0][0] != '$')
            in.fail("expected a section such as $Nodes, found '" + std::string(w[0]) + "'");
        const std::string name(w[0].substr(1));
        if (name == "MeshFormat")
            read_format(in, c), format = true;
        else if (name == "PhysicalNames")
            read_physical_names(in, c);
        else if (name == "Entities" && c.v4)
            read_entities(in, c);
        else if (name == "Nodes")
            read_nodes(in, c);
        else if (name == "Elements")
            read_elements(in, c);
        else if (name == "NodeData")
            read_node_data(in, c);
        else if (name == "Projection")
            throw DataError("gmsh file " + path.string() +
                            ": its nodes are in a projected CRS ($Projection); convert reads "
                            "lon/lat or points on a sphere");
        else {
            skip_section(in, name);
            continue;
        }
        skip_section(in, name);
    }
    if (!format)
        in.fail("not a gmsh MSH file (no $MeshFormat)");
    return c;
}

/// The nodes on the unit sphere: lon/lat degrees when every z is 0, else 3-D points.
std::vector<Vec3> unit_nodes(const fs::path &path, const MshContent &c) {
    const bool planar = std::all_of(c.xyz.begin(), c.xyz.end(),
                                    [](const std::array<double, 3> &p) { return p[2] == 0; });
    std::vector<Vec3> nodes;
    nodes.reserve(c.xyz.size());
    for (const auto &p : c.xyz) {
        if (planar && (std::fabs(p[1]) > 90 || std::fabs(p[0]) > 540))
            throw DataError("gmsh file " + path.string() + ": node (" + std::to_string(p[0]) +
                            ", " + std::to_string(p[1]) +
                            ") is not longitude and latitude in degrees (a projected mesh is not "
                            "read)");
        const Vec3 v{p[0], p[1], p[2]};
        if (!planar && norm(v) == 0)
            throw DataError("gmsh file " + path.string() +
                            ": a node lies at the centre of the sphere");
        nodes.push_back(planar ? lonlat_to_vec(p[0], p[1]) : normalized(v));
    }
    return nodes;
}

} // namespace

bool is_gmsh_name(const fs::path &path) {
    return io::lower_extension(path) == ".msh";
}

Mesh read_gmsh(const fs::path &path) {
    Lines in(path, "gmsh file", '\0');
    const MshContent c = read_content(path, in);
    Mesh mesh;
    mesh.nodes = unit_nodes(path, c);
    std::unordered_map<long long, NodeIndex> index;
    for (std::size_t i = 0; i < c.node_tags.size(); ++i)
        if (!index.emplace(c.node_tags[i], NodeIndex(i)).second)
            throw DataError("gmsh file " + path.string() + ": node tag " +
                            std::to_string(c.node_tags[i]) + " is repeated");
    auto node = [&](long long tag) {
        const auto it = index.find(tag);
        if (it == index.end())
            throw DataError("gmsh file " + path.string() + ": an element names node " +
                            std::to_string(tag) + ", which is not among the nodes");
        return it->second;
    };
    if (c.triangles.empty())
        throw DataError("gmsh file " + path.string() + ": no triangles to read");
    // Counter-clockwise seen from outside the sphere, as the writers want them.
    for (const auto &t : c.triangles) {
        std::array<NodeIndex, 3> f{node(t[0]), node(t[1]), node(t[2])};
        const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &d = mesh.nodes[f[2]];
        if (dot(cross(b - a, d - a), a) < 0)
            std::swap(f[1], f[2]);
        mesh.faces.push_back(f);
    }
    for (const auto &[ends, physical] : c.lines) {
        const auto group = c.line_groups.find(physical);
        const bool open = group != c.line_groups.end() && group->second.rfind("open", 0) == 0;
        mesh.boundary.push_back(
            {node(ends[0]), node(ends[1]), open ? EdgeTag::open : EdgeTag::coast});
    }
    if (!c.depth.empty()) {
        Field depth{"depth", "sea floor depth below mean sea level", "m",
                    "sea_floor_depth_below_mean_sea_level",
                    std::vector<double>(mesh.nodes.size(), NAN)};
        for (const auto &[tag, value] : c.depth)
            depth.values[node(tag)] = value;
        mesh.node_fields.push_back(std::move(depth));
    }
    io::tag_boundary_edges(mesh, "gmsh file " + path.string());
    return mesh;
}

} // namespace globemesh
