// D-Flow FM (Delft3D FM) network file writer: the writers table's row DFLOWFM, for names ending
// "_net.nc".
//
// Layout: the UGRID 1.0 flavour D-Flow FM reads and writes itself (Deltares' io_ugrid library;
// HYDROLIB-core's net writer writes the same), netCDF classic (64-bit offset) as those files are.
// Dimensions mesh2d_nNodes, mesh2d_nEdges, mesh2d_nFaces, mesh2d_nMax_face_nodes (3), Two; the
// topology variable mesh2d; mesh2d_node_x/y; mesh2d_node_z, the bed level (metres, positive up:
// minus the depth; -999, D-Flow FM's missing value, where the mesh has none); mesh2d_edge_x/y
// (midpoints), mesh2d_edge_nodes (D-Flow FM needs the edges), mesh2d_face_nodes (both 1-based;
// faces counter-clockwise, _FillValue -999 as D-Flow FM's), mesh2d_face_x/y (centres);
// mesh2d_edge_type with the codes of D-Flow FM's map files (1 internal, 2 open boundary, 3 closed
// boundary: the coast); the CRS variable wgs84 (epsg 4326) and Conventions "CF-1.8 UGRID-1.0
// Deltares-0.10". D-Flow FM itself takes its open boundaries from .pli files, not from the net
// file: the edge types say where they are.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "model_coordinates.hpp"
#include "nc_block_writer.hpp"
#include "netcdf_handle.hpp"

#ifndef GLOBEMESH_VERSION
#define GLOBEMESH_VERSION "unknown"
#endif

namespace globemesh {

namespace {

namespace fs = std::filesystem;

constexpr const char *what = "D-Flow FM output";
constexpr int fill_index = -999;
constexpr double missing_z = -999.0; ///< D-Flow FM's dmiss

/// The file's x/y: lon/lat degrees as io::node_lonlats places the nodes, with the CRS variable
/// wgs84; or, with an --output-srs, the nodes in that CRS (io::model_coordinates), the edge
/// midpoints and face centres the means of their nodes in the plane, with the CRS variable
/// projected_coordinate_system.
struct Placement {
    std::vector<LonLat> nodes;        ///< x in lon, y in lat
    std::optional<io::OutputCrs> crs; ///< set when projected
    bool east = false; ///< lon/lat: longitudes in [0, 360), as node_lonlats chose for this mesh

    const char *crs_var() const { return crs ? "projected_coordinate_system" : "wgs84"; }
    /// The x/y of the point p, the mean of the n nodes `of`.
    template <std::size_t n>
    LonLat place(const Mesh &mesh, const std::array<NodeIndex, n> &of) const {
        if (crs) {
            LonLat q{0, 0};
            for (NodeIndex i : of)
                q.lon += nodes[i].lon / n, q.lat += nodes[i].lat / n;
            return q;
        }
        Vec3 p{0, 0, 0};
        for (NodeIndex i : of)
            p = p + mesh.nodes[i];
        LonLat q = vec_to_lonlat(normalized(p));
        if (east && q.lon < 0)
            q.lon += 360;
        return q;
    }
};

Placement place_nodes(const Mesh &mesh, const WriteOptions &options, const fs::path &path) {
    io::ModelCoordinates c =
        io::model_coordinates(mesh, options.output_srs, std::string(what) + " " + path.string());
    Placement p;
    p.nodes.resize(c.x.size());
    for (std::size_t i = 0; i < c.x.size(); ++i)
        p.nodes[i] = {c.x[i], c.y[i]};
    if (c.crs && c.crs->projected)
        p.crs = std::move(c.crs);
    else
        p.east = std::any_of(p.nodes.begin(), p.nodes.end(),
                             [](const LonLat &q) { return q.lon >= 180; });
    return p;
}

struct Dims {
    int node, edge, face, max_face_nodes, two;
};

struct Vars {
    int crs = -1, mesh = -1, node_z = -1, edge_nodes = -1, face_nodes = -1, edge_type = -1;
    std::array<int, 2> node_xy{}, edge_xy{}, face_xy{};
};

int define_crs(io::NcBlockWriter &w, const Placement &at) {
    // As D-Flow FM writes it: its reader takes the EPSG code from "epsg".
    if (at.crs) {
        const int v = w.var(at.crs_var(), NC_INT, {});
        w.text(v, "name", at.crs->name);
        w.ints(v, "epsg", {at.crs->epsg});
        w.text(v, "grid_mapping_name", "Unknown projected");
        if (at.crs->epsg > 0)
            w.text(v, "EPSG_code", "EPSG:" + std::to_string(at.crs->epsg));
        w.text(v, "crs_wkt", at.crs->wkt);
        w.text(v, "value", "value is equal to EPSG code");
        return v;
    }
    const int v = w.var("wgs84", NC_INT, {});
    w.text(v, "name", "WGS84");
    w.ints(v, "epsg", {4326});
    io::wgs84_grid_mapping(w, v);
    w.dbl(v, "semi_minor_axis", 6356752.314245);
    w.text(v, "EPSG_code", "EPSG:4326");
    w.text(v, "value", "value is equal to EPSG code");
    return v;
}

int define_topology(io::NcBlockWriter &w) {
    const int v = w.var("mesh2d", NC_INT, {});
    const std::pair<const char *, const char *> attributes[] = {
        {"cf_role", "mesh_topology"},
        {"long_name", "Topology data of 2D mesh"},
        {"node_coordinates", "mesh2d_node_x mesh2d_node_y"},
        {"node_dimension", "mesh2d_nNodes"},
        {"max_face_nodes_dimension", "mesh2d_nMax_face_nodes"},
        {"edge_node_connectivity", "mesh2d_edge_nodes"},
        {"edge_dimension", "mesh2d_nEdges"},
        {"edge_coordinates", "mesh2d_edge_x mesh2d_edge_y"},
        {"face_node_connectivity", "mesh2d_face_nodes"},
        {"face_dimension", "mesh2d_nFaces"},
        {"face_coordinates", "mesh2d_face_x mesh2d_face_y"}};
    for (const auto &[name, value] : attributes)
        w.text(v, name, value);
    w.ints(v, "topology_dimension", {2});
    return v;
}

/// A variable of the mesh at `location` (node, edge, face), with the attributes every one has.
int mesh_var(io::NcBlockWriter &w, const std::string &name, nc_type type, std::vector<int> dims,
             const char *location, const std::string &long_name) {
    const int v = w.var(name.c_str(), type, std::move(dims));
    w.text(v, "mesh", "mesh2d");
    w.text(v, "location", location);
    w.text(v, "long_name", long_name);
    return v;
}

/// mesh2d_<location>_x and _y, of dimension dim.
std::array<int, 2> define_xy(io::NcBlockWriter &w, const char *location, int dim, const char *of,
                             bool projected) {
    std::array<int, 2> v{};
    for (int k = 0; k < 2; ++k) {
        const std::string name = std::string("mesh2d_") + location + (k ? "_y" : "_x");
        if (projected) {
            v[k] = mesh_var(w, name, NC_DOUBLE, {dim}, location,
                            std::string(k ? "y-coordinate of " : "x-coordinate of ") + of);
            w.text(v[k], "standard_name",
                   k ? "projection_y_coordinate" : "projection_x_coordinate");
            w.text(v[k], "units", "m");
            continue;
        }
        v[k] = mesh_var(w, name, NC_DOUBLE, {dim}, location,
                        std::string(k ? "latitude of " : "longitude of ") + of);
        w.text(v[k], "standard_name", k ? "latitude" : "longitude");
        w.text(v[k], "units", k ? "degrees_north" : "degrees_east");
    }
    return v;
}

/// A 1-based connectivity; with a fill value when its rows may be shorter (faces: UGRID).
int define_connectivity(io::NcBlockWriter &w, const char *name, const char *role,
                        const char *location, std::vector<int> dims, const char *long_name) {
    const bool faces = std::string(location) == "face";
    const int v = mesh_var(w, name, NC_INT, std::move(dims), location, long_name);
    w.text(v, "cf_role", role);
    w.ints(v, "start_index", {1});
    if (faces)
        w.ints(v, "_FillValue", {fill_index});
    return v;
}

Vars define_variables(io::NcBlockWriter &w, const Dims &d, const Placement &at) {
    const bool projected = at.crs.has_value();
    Vars v;
    v.crs = define_crs(w, at);
    v.mesh = define_topology(w);
    v.node_xy = define_xy(w, "node", d.node, "mesh nodes", projected);
    v.node_z = mesh_var(w, "mesh2d_node_z", NC_DOUBLE, {d.node}, "node", "bed level at mesh nodes");
    w.text(v.node_z, "coordinates", "mesh2d_node_x mesh2d_node_y");
    w.text(v.node_z, "standard_name", "altitude");
    w.text(v.node_z, "units", "m");
    w.text(v.node_z, "positive", "up");
    w.text(v.node_z, "comment", "minus the depth below mean sea level");
    w.text(v.node_z, "grid_mapping", at.crs_var());
    w.dbl(v.node_z, "_FillValue", missing_z);
    v.edge_xy = define_xy(w, "edge", d.edge, "mesh edge midpoints", projected);
    v.edge_nodes = define_connectivity(w, "mesh2d_edge_nodes", "edge_node_connectivity", "edge",
                                       {d.edge, d.two}, "the two nodes of each edge");
    v.face_nodes = define_connectivity(w, "mesh2d_face_nodes", "face_node_connectivity", "face",
                                       {d.face, d.max_face_nodes},
                                       "the nodes of each face, counter-clockwise");
    v.face_xy = define_xy(w, "face", d.face, "mesh face centres", projected);
    v.edge_type = mesh_var(w, "mesh2d_edge_type", NC_INT, {d.edge}, "edge",
                           "edge type (relation between edge and flow geometry)");
    w.text(v.edge_type, "coordinates", "mesh2d_edge_x mesh2d_edge_y");
    w.ints(v.edge_type, "flag_values", {0, 1, 2, 3});
    w.text(v.edge_type, "flag_meanings", "internal_closed internal boundary boundary_closed");
    return v;
}

void define_global_attributes(io::NcBlockWriter &w, const WriteOptions &options) {
    w.text(NC_GLOBAL, "Conventions", "CF-1.8 UGRID-1.0 Deltares-0.10");
    w.text(NC_GLOBAL, "title", options.title);
    w.text(NC_GLOBAL, "source", std::string("globemesh ") + GLOBEMESH_VERSION);
    if (!options.history.empty())
        w.text(NC_GLOBAL, "history", options.history);
}

/// Each edge's mesh2d_edge_type: 1 internal, 2 open boundary, 3 coast (a closed boundary).
std::vector<int> edge_types(const io::MeshTopology &topo) {
    std::vector<int> types(topo.edge_count(), 1);
    for (std::size_t k = 0; k < topo.boundary_edges.size(); ++k)
        types[std::size_t(topo.boundary_edges[k])] =
            topo.boundary_tags[k] == int(EdgeTag::open) ? 2 : 3;
    return types;
}

void write_data(io::NcBlockWriter &w, const Mesh &mesh, const io::MeshTopology &topo, const Vars &v,
                const Placement &at) {
    const Field *depth = mesh.node_field("depth");
    const std::size_t nn = mesh.nodes.size(), nf = mesh.faces.size(), ne = topo.edge_count();
    w.put_xy(v.node_xy[0], v.node_xy[1], nn, [&](std::size_t i) { return at.nodes[i]; });
    w.put_values<double>(v.node_z, nn, [&](std::size_t i) {
        const double d = depth ? depth->values[i] : NAN;
        return std::isfinite(d) ? -d : missing_z;
    });
    w.put_xy(v.edge_xy[0], v.edge_xy[1], ne, [&](std::size_t e) {
        const auto ends = topo.edge_nodes(e);
        return at.place(mesh, std::array<NodeIndex, 2>{NodeIndex(ends[0]), NodeIndex(ends[1])});
    });
    w.put_rows<int, 2>(v.edge_nodes, ne, [&](std::size_t e) {
        const auto ends = topo.edge_nodes(e);
        return std::array<int, 2>{ends[0] + 1, ends[1] + 1};
    });
    w.put_rows<int, 3>(v.face_nodes, nf, [&](std::size_t f) {
        const auto &t = mesh.faces[f];
        return std::array<int, 3>{int(t[0]) + 1, int(t[1]) + 1, int(t[2]) + 1};
    });
    w.put_xy(v.face_xy[0], v.face_xy[1], nf,
             [&](std::size_t f) { return at.place(mesh, mesh.faces[f]); });
    const std::vector<int> types = edge_types(topo);
    w.put_values<int>(v.edge_type, ne, [&](std::size_t e) { return types[e]; });
}

} // namespace

/// The DFLOWFM row of the writers table (writers.cpp).
void write_as_dflowfm(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    if (mesh.faces.empty())
        throw DataError("mesh: no faces to write to " + path.string());
    const Placement at = place_nodes(mesh, options, path); // its refusals before any file
    OutputFile out(path, options.overwrite, what);
    const auto topology = io::topology_of(mesh);
    const io::MeshTopology &topo = *topology;
    io::NcHandle nc;
    nc.create(out.temp_path(), NC_NOCLOBBER | NC_64BIT_OFFSET, path, what);
    int old_fill;
    nc_set_fill(nc.id(), NC_NOFILL, &old_fill);
    io::NcBlockWriter w(nc, out.temp_path(), path, false, options.progress, what, "write_dflowfm");
    const Dims d{w.dim("mesh2d_nNodes", mesh.nodes.size()),
                 w.dim("mesh2d_nEdges", topo.edge_count()),
                 w.dim("mesh2d_nFaces", mesh.faces.size()), w.dim("mesh2d_nMax_face_nodes", 3),
                 w.dim("Two", 2)};
    const Vars v = define_variables(w, d, at);
    define_global_attributes(w, options);
    io::nc_check(nc_enddef(nc.id()), path, "leaving define mode", what);
    // The CRS variable holds its EPSG code, as D-Flow FM's do; NC_NOFILL leaves mesh2d's byte
    // undefined unless written.
    const int epsg = at.crs ? at.crs->epsg : 4326, zero = 0;
    io::nc_check(nc_put_var_int(nc.id(), v.crs, &epsg), path, "writing the CRS variable", what);
    io::nc_check(nc_put_var_int(nc.id(), v.mesh, &zero), path, "writing mesh2d", what);
    write_data(w, mesh, topo, v, at);
    w.finish();
    out.commit();
}

} // namespace globemesh
