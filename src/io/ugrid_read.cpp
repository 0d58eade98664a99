// UGRID 2-D triangle mesh reader: see globemesh/ugrid.hpp.
//
// Reads the first variable with cf_role = "mesh_topology": node coordinates (longitude/latitude,
// in degrees), face_node_connectivity in either dimension order (face_dimension decides), any
// start_index (0 or 1) and _FillValue, node and face data variables as fields, and boundary tags
// from an edge variable "boundary_tag" or D-Flow FM's "<mesh>_edge_type" when present. Nothing is
// trusted: every index is checked.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/ugrid.hpp"
#include "mesh_topology.hpp"
#include "netcdf_handle.hpp"

namespace globemesh {

namespace {

class Reader {
public:
    Reader(int id, const std::filesystem::path &file) : id_(id), file_(file) {}

    [[noreturn]] void fail(const std::string &what) const {
        throw DataError("UGRID file " + file_.string() + ": " + what);
    }
    std::optional<std::string> text(int var, const char *name) const {
        nc_type type;
        std::size_t len;
        if (nc_inq_att(id_, var, name, &type, &len) != NC_NOERR)
            return std::nullopt;
        if (type == NC_STRING) {
            char *s = nullptr;
            if (len != 1 || nc_get_att_string(id_, var, name, &s) != NC_NOERR)
                return std::nullopt;
            std::string r = s ? s : "";
            nc_free_string(1, &s);
            return r;
        }
        if (type != NC_CHAR)
            return std::nullopt;
        std::string s(len, '\0');
        if (nc_get_att_text(id_, var, name, s.data()) != NC_NOERR)
            return std::nullopt;
        while (!s.empty() && s.back() == '\0')
            s.pop_back();
        return s;
    }
    std::optional<long long> integer(int var, const char *name) const {
        nc_type type;
        std::size_t len;
        if (nc_inq_att(id_, var, name, &type, &len) != NC_NOERR || len != 1 || type == NC_CHAR ||
            type == NC_STRING)
            return std::nullopt;
        long long v;
        if (nc_get_att_longlong(id_, var, name, &v) != NC_NOERR)
            return std::nullopt;
        return v;
    }
    int var_id(const std::string &name, const char *role) const {
        int v;
        if (nc_inq_varid(id_, name.c_str(), &v) != NC_NOERR)
            fail(std::string(role) + " names variable \"" + name + "\", which does not exist");
        return v;
    }
    std::vector<int> dims(int var) const {
        int n;
        io::nc_check(nc_inq_varndims(id_, var, &n), file_, "reading a variable");
        std::vector<int> d(static_cast<std::size_t>(n));
        io::nc_check(nc_inq_vardimid(id_, var, d.data()), file_, "reading a variable");
        return d;
    }
    std::size_t dim_len(int dim) const {
        std::size_t len;
        io::nc_check(nc_inq_dimlen(id_, dim, &len), file_, "reading a dimension");
        return len;
    }
    int dim_id(const std::string &name) const {
        int d;
        if (nc_inq_dimid(id_, name.c_str(), &d) != NC_NOERR)
            fail("dimension \"" + name + "\" does not exist");
        return d;
    }
    nc_type type(int var) const {
        nc_type t;
        io::nc_check(nc_inq_vartype(id_, var, &t), file_, "reading a variable");
        return t;
    }
    std::string name(int var) const {
        char n[NC_MAX_NAME + 1];
        io::nc_check(nc_inq_varname(id_, var, n), file_, "reading a variable");
        return n;
    }
    std::vector<double> doubles(int var, std::size_t n) const {
        std::vector<double> v(n);
        if (n)
            io::nc_check(nc_get_var_double(id_, var, v.data()), file_, "reading " + name(var));
        return v;
    }
    std::vector<long long> longs(int var, std::size_t n) const {
        std::vector<long long> v(n);
        if (n)
            io::nc_check(nc_get_var_longlong(id_, var, v.data()), file_, "reading " + name(var));
        return v;
    }
    int id() const { return id_; }

private:
    int id_;
    const std::filesystem::path &file_;
};

bool is_integer_type(nc_type t) {
    return t == NC_BYTE || t == NC_SHORT || t == NC_INT || t == NC_INT64 || t == NC_UBYTE ||
           t == NC_USHORT || t == NC_UINT || t == NC_UINT64;
}

/// A connectivity table read as rows of indices relative to start_index, fill entries as -1.
struct Table {
    std::size_t rows = 0, cols = 0;
    std::vector<long long> values; ///< row-major, 0-based, -1 = missing
};

Table read_connectivity(const Reader &r, const std::string &name, const char *role, int element_dim,
                        std::size_t target_count) {
    int v = r.var_id(name, role);
    if (!is_integer_type(r.type(v)))
        r.fail(std::string(role) + " " + name + " is not an integer variable");
    auto d = r.dims(v);
    if (d.size() != 2)
        r.fail(std::string(role) + " " + name + " is not 2-D");
    bool transposed = false;
    if (element_dim >= 0) {
        if (d[0] == element_dim)
            transposed = false;
        else if (d[1] == element_dim)
            transposed = true;
        else
            r.fail(std::string(role) + " " + name + " does not use the element dimension");
    }
    std::size_t n0 = r.dim_len(d[0]), n1 = r.dim_len(d[1]);
    Table t;
    t.rows = transposed ? n1 : n0;
    t.cols = transposed ? n0 : n1;
    auto raw = r.longs(v, n0 * n1);
    long long start = r.integer(v, "start_index").value_or(0);
    if (start != 0 && start != 1)
        r.fail(std::string(role) + " " + name + ": start_index must be 0 or 1");
    std::optional<long long> fill = r.integer(v, "_FillValue");
    t.values.resize(raw.size());
    for (std::size_t i = 0; i < t.rows; ++i)
        for (std::size_t k = 0; k < t.cols; ++k) {
            long long x = transposed ? raw[k * n1 + i] : raw[i * n1 + k];
            if (fill && x == *fill) {
                t.values[i * t.cols + k] = -1;
                continue;
            }
            long long idx = x - start;
            if (idx < 0 || std::size_t(idx) >= target_count)
                r.fail(std::string(role) + " " + name + ": row " + std::to_string(i) +
                       " has index " + std::to_string(x) + ", outside [" + std::to_string(start) +
                       ", " + std::to_string(start + (long long)target_count - 1) + "]" +
                       (fill ? "" : " (no _FillValue marks missing entries)"));
            t.values[i * t.cols + k] = idx;
        }
    return t;
}

std::vector<std::string> split_words(const std::string &s) {
    std::istringstream in(s);
    std::vector<std::string> words;
    for (std::string w; in >> w;)
        words.push_back(w);
    return words;
}

/// Opens `path` into `nc`; IoError when it is no NetCDF file (a GeoPackage named as such).
void open_ugrid(io::NcHandle &nc, const std::filesystem::path &path) {
    int status = nc_open(path.c_str(), NC_NOWRITE, nc.out());
    if (status != NC_NOERR) {
        // A GeoPackage (what --gpkg writes) starts with SQLite's header: say so rather than
        // netCDF-C's "Unknown file format".
        char head[16] = {};
        std::ifstream(path, std::ios::binary).read(head, sizeof head);
        if (status == NC_ENOTNC &&
            std::string(head, sizeof head) == std::string("SQLite format 3\0", 16))
            throw IoError("UGRID file " + path.string() +
                          ": is a GeoPackage (SQLite), not NetCDF; give the UGRID "
                          "file that -o wrote (ogrinfo reads the GeoPackage)");
        throw IoError("UGRID file " + path.string() + ": cannot open (" + nc_strerror(status) +
                      "); give an existing NetCDF file");
    }
}

/// The first variable with cf_role = "mesh_topology", which must be 2-D.
int find_topology(const Reader &r, int nvars) {
    int topo = -1;
    for (int v = 0; v < nvars && topo < 0; ++v)
        if (r.text(v, "cf_role") == std::optional<std::string>("mesh_topology"))
            topo = v;
    if (topo < 0)
        r.fail("no variable with cf_role = \"mesh_topology\": not a UGRID mesh");
    if (r.integer(topo, "topology_dimension").value_or(0) != 2)
        r.fail("mesh " + r.name(topo) + " has no topology_dimension = 2; only 2-D meshes are read");
    return topo;
}

/// Reads the nodes into mesh.nodes; returns their dimension.
int read_nodes(const Reader &r, int topo, Mesh &mesh) {
    // Longitude and latitude, told apart by standard_name or units, else in x y order.
    auto coord_names = split_words(r.text(topo, "node_coordinates").value_or(""));
    if (coord_names.size() != 2)
        r.fail("mesh " + r.name(topo) + ": node_coordinates must name two variables");
    int cx = r.var_id(coord_names[0], "node_coordinates"),
        cy = r.var_id(coord_names[1], "node_coordinates");
    auto is_lat = [&](int v) {
        auto sn = r.text(v, "standard_name").value_or(""), u = r.text(v, "units").value_or("");
        return sn == "latitude" || u.rfind("degrees_n", 0) == 0 || u.rfind("degree_n", 0) == 0 ||
               u == "degree_N";
    };
    if (is_lat(cx) && !is_lat(cy))
        std::swap(cx, cy);
    const std::string x_name = r.text(cx, "standard_name").value_or("");
    if (x_name == "projection_x_coordinate")
        r.fail("its nodes are in a projected CRS (" + r.name(cx) +
               " is projection_x_coordinate); globemesh reads longitude and latitude");
    auto node_dims = r.dims(cx);
    if (node_dims.size() != 1 || r.dims(cy) != node_dims)
        r.fail("node coordinates must be 1-D on one dimension");
    const int node_dim = node_dims[0];
    const std::size_t nn = r.dim_len(node_dim);
    auto lon = r.doubles(cx, nn), lat = r.doubles(cy, nn);
    mesh.nodes.resize(nn);
    for (std::size_t i = 0; i < nn; ++i) {
        if (!std::isfinite(lon[i]) || !std::isfinite(lat[i]) || std::fabs(lat[i]) > 90.0)
            r.fail("node " + std::to_string(i) + " has an invalid position (" +
                   std::to_string(lon[i]) + ", " + std::to_string(lat[i]) + ")");
        mesh.nodes[i] = lonlat_to_vec(lon[i], lat[i]);
    }
    return node_dim;
}

/// Reads the triangles into mesh.faces (after the nodes); returns their dimension.
int read_faces(const Reader &r, int topo, Mesh &mesh) {
    auto face_name = r.text(topo, "face_node_connectivity");
    if (!face_name)
        r.fail("mesh " + r.name(topo) + " has no face_node_connectivity");
    int face_dim = -1;
    if (auto fd = r.text(topo, "face_dimension"))
        face_dim = r.dim_id(*fd);
    else
        face_dim = r.dims(r.var_id(*face_name, "face_node_connectivity")).at(0);
    Table faces =
        read_connectivity(r, *face_name, "face_node_connectivity", face_dim, mesh.nodes.size());
    mesh.faces.resize(faces.rows);
    for (std::size_t f = 0; f < faces.rows; ++f) {
        std::size_t count = 0;
        bool gap = false;
        for (std::size_t k = 0; k < faces.cols; ++k) {
            long long x = faces.values[f * faces.cols + k];
            if (x < 0) {
                gap = true;
                continue;
            }
            if (gap)
                r.fail("face " + std::to_string(f) + " has a fill value before a node");
            if (count < 3)
                mesh.faces[f][count] = NodeIndex(x);
            ++count;
        }
        if (count != 3)
            r.fail("face " + std::to_string(f) + " has " + std::to_string(count) +
                   " nodes; only triangle meshes are read");
    }
    return face_dim;
}

/// Boundary tags (1 or 2) by edge key (smaller node << 32 | larger node), unsorted.
using EdgeTags = std::vector<std::pair<std::uint64_t, int>>;

/// The boundary tag (1 coast, 2 open; 0 none) of each value of an edge variable: ours
/// (boundary_tag: 1 coast, 2 open) or D-Flow FM's edge type (2 boundary, 3 boundary_closed).
int edge_tag_of(long long value, bool dflowfm) {
    if (dflowfm)
        return value == 2 ? 2 : value == 3 ? 1 : 0;
    return value == 1 || value == 2 ? int(value) : 0;
}

/// Adds the tags of the edge variable `v` (boundary_tag or D-Flow FM's <mesh>_edge_type, on
/// dimensions `d`) to `edge_tags`.
void read_edge_tags(const Reader &r, int v, const std::vector<int> &d, const std::string &edge_name,
                    int &edge_dim, std::size_t nn, EdgeTags &edge_tags, bool dflowfm) {
    int ev = r.var_id(edge_name, "edge_node_connectivity");
    if (edge_dim < 0)
        edge_dim = r.dims(ev).at(0);
    if (d[0] != edge_dim)
        return;
    Table edges = read_connectivity(r, edge_name, "edge_node_connectivity", edge_dim, nn);
    auto tags = r.longs(v, edges.rows);
    for (std::size_t e = 0; e < edges.rows; ++e) {
        long long a = edges.values[2 * e], b = edges.values[2 * e + 1];
        const int tag = edge_tag_of(tags[e], dflowfm);
        if (a < 0 || b < 0 || tag == 0)
            continue;
        if (a > b)
            std::swap(a, b);
        edge_tags.emplace_back((std::uint64_t(a) << 32) | std::uint64_t(b), tag);
    }
}

/// Data variables on nodes and faces into the mesh's fields; returns the boundary tags on edges.
EdgeTags read_variables(const Reader &r, int nvars, int topo, int node_dim, int face_dim,
                        Mesh &mesh) {
    const std::string topo_name = r.name(topo);
    const std::size_t nn = mesh.nodes.size(), nf = mesh.faces.size();
    int edge_dim = -1;
    if (auto ed = r.text(topo, "edge_dimension"))
        edge_dim = r.dim_id(*ed);
    auto edge_name = r.text(topo, "edge_node_connectivity");
    // The coordinates are no data, though some files (D-Flow FM's) give them a mesh and location.
    std::set<std::string> coordinates;
    for (const char *c : {"node_coordinates", "face_coordinates", "edge_coordinates"}) {
        std::istringstream names(r.text(topo, c).value_or(""));
        for (std::string name; names >> name;)
            coordinates.insert(name);
    }
    EdgeTags edge_tags;
    for (int v = 0; v < nvars; ++v) {
        if (r.text(v, "mesh") != std::optional<std::string>(topo_name) ||
            coordinates.count(r.name(v)))
            continue;
        auto location = r.text(v, "location").value_or("");
        auto d = r.dims(v);
        nc_type t = r.type(v);
        if (d.size() != 1 || t == NC_CHAR || t == NC_STRING)
            continue;
        const bool dflowfm = r.name(v) == topo_name + "_edge_type";
        if (location == "edge" && (r.name(v) == "boundary_tag" || dflowfm) && edge_name) {
            read_edge_tags(r, v, d, *edge_name, edge_dim, nn, edge_tags, dflowfm);
            continue;
        }
        bool on_nodes = location == "node" && d[0] == node_dim;
        bool on_faces = location == "face" && d[0] == face_dim;
        if (!on_nodes && !on_faces)
            continue;
        Field f;
        f.name = r.name(v);
        f.long_name = r.text(v, "long_name").value_or("");
        f.units = r.text(v, "units").value_or("");
        f.standard_name = r.text(v, "standard_name").value_or("");
        f.values = r.doubles(v, on_nodes ? nn : nf);
        double fill;
        if (nc_get_att_double(r.id(), v, "_FillValue", &fill) == NC_NOERR)
            for (auto &x : f.values)
                if (x == fill)
                    x = std::nan("");
        (on_nodes ? mesh.node_fields : mesh.face_fields).push_back(std::move(f));
    }
    return edge_tags;
}

/// Boundary edges from the faces (oriented with the mesh on the left), tagged from the file
/// (coast where it says nothing).
void add_boundary(const Reader &r, EdgeTags edge_tags, Mesh &mesh) {
    std::sort(edge_tags.begin(), edge_tags.end());
    const io::MeshTopology topology = [&] {
        try {
            return io::build_topology(mesh);
        } catch (const DataError &e) {
            r.fail(e.what());
        }
    }();
    for (auto e : topology.boundary_edges) {
        const auto nodes = topology.edge_nodes(std::size_t(e));
        auto a = std::uint32_t(nodes[0]), b = std::uint32_t(nodes[1]);
        std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
        auto it = std::lower_bound(edge_tags.begin(), edge_tags.end(), std::make_pair(key, 0));
        EdgeTag tag =
            (it != edge_tags.end() && it->first == key) ? EdgeTag(it->second) : EdgeTag::coast;
        mesh.boundary.push_back({a, b, tag});
    }
}

/// Text global attributes other than the ones a writer regenerates.
void read_global_attributes(const Reader &r, const std::filesystem::path &path, Mesh &mesh) {
    static const std::set<std::string> regenerated = {"Conventions", "title", "source", "history"};
    int natts;
    io::nc_check(nc_inq_natts(r.id(), &natts), path, "listing global attributes");
    for (int i = 0; i < natts; ++i) {
        char name[NC_MAX_NAME + 1];
        if (nc_inq_attname(r.id(), NC_GLOBAL, i, name) != NC_NOERR || regenerated.count(name))
            continue;
        if (auto value = r.text(NC_GLOBAL, name))
            mesh.attributes.emplace_back(name, *value);
    }
}

} // namespace

Mesh read_ugrid(const std::filesystem::path &path) {
    io::NcHandle nc;
    open_ugrid(nc, path);
    Reader r(nc.id(), path);
    int nvars;
    io::nc_check(nc_inq_nvars(nc.id(), &nvars), path, "listing variables");
    const int topo = find_topology(r, nvars);
    Mesh mesh;
    const int node_dim = read_nodes(r, topo, mesh);
    const int face_dim = read_faces(r, topo, mesh);
    add_boundary(r, read_variables(r, nvars, topo, node_dim, face_dim, mesh), mesh);
    read_global_attributes(r, path, mesh);
    return mesh;
}

} // namespace globemesh
