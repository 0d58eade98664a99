// UGRID 1.0 NetCDF writer: see globemesh/ugrid.hpp.
//
// Layout (names are fixed so tools and tests can rely on them): dimensions nMesh_node,
// nMesh_face, nMesh_edge, nMesh_boundary (only when the mesh has a boundary), Two, Three; the
// topology variable "mesh"; coordinates mesh_{node,face,edge}_{lon,lat}; connectivities
// mesh_face_nodes, mesh_edge_nodes, mesh_face_edges, mesh_face_links, mesh_edge_face_links,
// mesh_boundary_nodes, all 0-based with start_index written; "crs" for CF and MDAL. Nothing in
// the file depends on the clock: the only date is the caller's history string.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "face_area.hpp"
#include "face_geometry.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "nc_block_writer.hpp"
#include "netcdf_handle.hpp"
#include "ordered_blocks.hpp"
#include "qgis_style.hpp"
#include "write_hooks.hpp"

#ifndef GLOBEMESH_VERSION
#define GLOBEMESH_VERSION "unknown"
#endif

namespace globemesh {

namespace {

using io::NcBlockWriter;
using io::wgs84_wkt;

/// A netCDF attribute name from a free-form key (letters, digits, underscore).
std::string attribute_name(const std::string &key) {
    std::string s;
    for (char c : key)
        s += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0])))
        s.insert(0, "a_");
    return s;
}

void field_attributes(NcBlockWriter &w, int v, const Field &f, const char *location,
                      const char *coords) {
    w.text(v, "mesh", "mesh");
    w.text(v, "location", location);
    w.text(v, "coordinates", coords);
    w.text(v, "grid_mapping", "crs");
    std::string standard = f.standard_name;
    std::string units = f.units;
    if (f.name == "depth") {
        if (standard.empty())
            standard = "sea_floor_depth_below_geoid";
        if (units.empty())
            units = std::string(1, 'm');
        w.text(v, "positive", "down");
    }
    if (f.name == "target_size" && units.empty())
        units = "km";
    w.text(v, "long_name", f.long_name.empty() ? f.name : f.long_name);
    if (!standard.empty())
        w.text(v, "standard_name", standard);
    if (!units.empty())
        w.text(v, "units", units);
}

/// Refuses a mesh whose fields do not match its nodes or faces, or that has no faces.
void check_fields(const Mesh &mesh, const std::filesystem::path &path) {
    for (const auto &f : mesh.node_fields)
        if (f.values.size() != mesh.nodes.size())
            throw DataError("mesh: node field " + f.name + " has " +
                            std::to_string(f.values.size()) + " values for " +
                            std::to_string(mesh.nodes.size()) + " nodes");
    for (const auto &f : mesh.face_fields)
        if (f.values.size() != mesh.faces.size())
            throw DataError("mesh: face field " + f.name + " has " +
                            std::to_string(f.values.size()) + " values for " +
                            std::to_string(mesh.faces.size()) + " faces");
    if (mesh.faces.empty())
        throw DataError("mesh: no faces to write to " + path.string());
}

/// How many nodes, faces, edges and boundary edges the file holds.
struct Counts {
    std::size_t nn, nf, ne, nb;
};

/// The file's dimensions; bnd is -1 when the mesh has no boundary.
struct Dims {
    int node, face, edge, two, three, bnd;
};

Dims define_dimensions(NcBlockWriter &w, const Counts &c) {
    Dims d;
    d.node = w.dim("nMesh_node", c.nn);
    d.face = w.dim("nMesh_face", c.nf);
    d.edge = w.dim("nMesh_edge", c.ne);
    d.two = w.dim("Two", 2);
    d.three = w.dim("Three", 3);
    d.bnd = c.nb ? w.dim("nMesh_boundary", c.nb) : -1;
    return d;
}

/// The variables of the mesh itself: the containers crs and mesh, the coordinates (node, face
/// centre, edge midpoint; lon then lat) and the connectivities (bnd: -1 without a boundary).
struct TopologyVars {
    int crs = -1, mesh = -1;
    int coords[6] = {};
    int face_nodes = -1, edge_nodes = -1, face_edges = -1, face_links = -1, edge_faces = -1,
        bnd = -1;
};

int define_crs(NcBlockWriter &w) {
    // CRS, read by CF tools (grid_mapping_name, crs_wkt) and by MDAL (EPSG_code, epsg).
    int crs = w.var("crs", NC_INT, {});
    io::wgs84_grid_mapping(w, crs);
    w.text(crs, "wkt", wgs84_wkt);
    w.ints(crs, "epsg", {4326});
    w.text(crs, "EPSG_code", "EPSG:4326");
    return crs;
}

int define_topology(NcBlockWriter &w, bool has_boundary) {
    int topo_var = w.var("mesh", NC_INT, {});
    w.text(topo_var, "cf_role", "mesh_topology");
    w.text(topo_var, "long_name", "Topology of the 2-D unstructured ocean mesh");
    w.ints(topo_var, "topology_dimension", {2});
    w.text(topo_var, "node_coordinates", "mesh_node_lon mesh_node_lat");
    w.text(topo_var, "face_coordinates", "mesh_face_lon mesh_face_lat");
    w.text(topo_var, "edge_coordinates", "mesh_edge_lon mesh_edge_lat");
    w.text(topo_var, "face_node_connectivity", "mesh_face_nodes");
    w.text(topo_var, "edge_node_connectivity", "mesh_edge_nodes");
    w.text(topo_var, "face_edge_connectivity", "mesh_face_edges");
    w.text(topo_var, "face_face_connectivity", "mesh_face_links");
    w.text(topo_var, "edge_face_connectivity", "mesh_edge_face_links");
    if (has_boundary)
        w.text(topo_var, "boundary_node_connectivity", "mesh_boundary_nodes");
    w.text(topo_var, "face_dimension", "nMesh_face");
    w.text(topo_var, "edge_dimension", "nMesh_edge");
    return topo_var;
}

void define_coordinates(NcBlockWriter &w, const Dims &d, TopologyVars &t) {
    struct Coord {
        const char *name;
        int dim;
        bool lon;
        const char *what;
    };
    const Coord coords[] = {{"mesh_node_lon", d.node, true, "node"},
                            {"mesh_node_lat", d.node, false, "node"},
                            {"mesh_face_lon", d.face, true, "face centre"},
                            {"mesh_face_lat", d.face, false, "face centre"},
                            {"mesh_edge_lon", d.edge, true, "edge midpoint"},
                            {"mesh_edge_lat", d.edge, false, "edge midpoint"}};
    for (int i = 0; i < 6; ++i) {
        const Coord &c = coords[i];
        int v = t.coords[i] = w.var(c.name, NC_DOUBLE, {c.dim});
        w.text(v, "standard_name", c.lon ? "longitude" : "latitude");
        w.text(v, "long_name", std::string(c.lon ? "longitude of " : "latitude of ") + c.what);
        w.text(v, "units", c.lon ? "degrees_east" : "degrees_north");
        w.text(v, "grid_mapping", "crs");
    }
}

void define_connectivity(NcBlockWriter &w, const Dims &d, TopologyVars &t) {
    auto connectivity = [&](const char *name, const char *role, int d_elem, int d_cols,
                            const char *long_name, bool fill) {
        int v = w.var(name, NC_INT, {d_elem, d_cols});
        w.text(v, "cf_role", role);
        w.text(v, "long_name", long_name);
        w.ints(v, "start_index", {0});
        if (fill)
            w.ints(v, "_FillValue", {-1});
        return v;
    };
    t.face_nodes = connectivity("mesh_face_nodes", "face_node_connectivity", d.face, d.three,
                                "nodes of each face, counter-clockwise", false);
    t.edge_nodes = connectivity("mesh_edge_nodes", "edge_node_connectivity", d.edge, d.two,
                                "nodes of each edge", false);
    t.face_edges = connectivity("mesh_face_edges", "face_edge_connectivity", d.face, d.three,
                                "edges of each face (edge k joins nodes k and k+1)", false);
    t.face_links = connectivity("mesh_face_links", "face_face_connectivity", d.face, d.three,
                                "neighbour faces of each face", true);
    t.edge_faces = connectivity("mesh_edge_face_links", "edge_face_connectivity", d.edge, d.two,
                                "faces on each side of each edge", true);
    t.bnd = d.bnd >= 0 ? connectivity("mesh_boundary_nodes", "boundary_node_connectivity", d.bnd,
                                      d.two, "nodes of each boundary edge, mesh on the left", false)
                       : -1;
}

/// The variables of the fields: one per node field (in order), quality and area, one per other
/// face field (extra_face_fields, in order), and the edges' boundary tags.
struct FieldVars {
    std::vector<int> node, face;
    std::vector<const Field *> extra_face_fields;
    int quality = -1, area = -1, tag = -1;
};

FieldVars define_fields(NcBlockWriter &w, const Mesh &mesh, const Dims &d) {
    FieldVars v;
    const char *node_coords = "mesh_node_lon mesh_node_lat";
    const char *face_coords = "mesh_face_lon mesh_face_lat";
    // Variable and dimension names in use; a field whose name is taken gets a "_node"/"_face"
    // suffix. (netCDF-4 stores a variable named as a dimension under another name in HDF5,
    // where the chunks are written by name.)
    std::set<std::string> used = {"crs",
                                  "mesh",
                                  "quality",
                                  "area",
                                  "boundary_tag",
                                  "mesh_node_lon",
                                  "mesh_node_lat",
                                  "mesh_face_lon",
                                  "mesh_face_lat",
                                  "mesh_edge_lon",
                                  "mesh_edge_lat",
                                  "mesh_face_nodes",
                                  "mesh_edge_nodes",
                                  "mesh_face_edges",
                                  "mesh_face_links",
                                  "mesh_edge_face_links",
                                  "mesh_boundary_nodes",
                                  "nMesh_node",
                                  "nMesh_face",
                                  "nMesh_edge",
                                  "nMesh_boundary",
                                  "Two",
                                  "Three"};
    auto var_name = [&used](const std::string &name, const char *suffix) {
        std::string n = attribute_name(name);
        while (used.count(n))
            n += suffix;
        used.insert(n);
        return n;
    };
    for (const auto &f : mesh.node_fields) {
        v.node.push_back(w.var(var_name(f.name, "_node").c_str(), NC_DOUBLE, {d.node}));
        field_attributes(w, v.node.back(), f, "node", node_coords);
    }
    Field q_field{"quality", "quality (2*sqrt(3)*inradius/longest edge)", "1", "", {}};
    Field a_field{"area", "face area (geodesic, WGS84)", "m2", "cell_area", {}};
    v.quality = w.var("quality", NC_DOUBLE, {d.face});
    field_attributes(w, v.quality, q_field, "face", face_coords);
    w.text(v.quality, "comment",
           "shape quality of the chordal triangle: 1 equilateral, 0 degenerate");
    v.area = w.var("area", NC_DOUBLE, {d.face});
    field_attributes(w, v.area, a_field, "face", face_coords);
    for (const auto &f : mesh.face_fields) {
        if (f.name == "quality" || f.name == "area")
            continue; // recomputed above
        v.extra_face_fields.push_back(&f);
        v.face.push_back(w.var(var_name(f.name, "_face").c_str(), NC_DOUBLE, {d.face}));
        field_attributes(w, v.face.back(), f, "face", face_coords);
    }
    v.tag = w.var("boundary_tag", NC_INT, {d.edge});
    w.text(v.tag, "mesh", "mesh");
    w.text(v.tag, "location", "edge");
    w.text(v.tag, "coordinates", "mesh_edge_lon mesh_edge_lat");
    w.text(v.tag, "long_name", "boundary tag of each edge");
    w.ints(v.tag, "flag_values", {0, 1, 2});
    w.text(v.tag, "flag_meanings", "interior coast open");
    return v;
}

/// Global attributes: conventions, provenance, the mesh's run metadata, summary statistics.
void define_global_attributes(NcBlockWriter &w, const Mesh &mesh, const UgridOptions &options,
                              const MeshStats &stats, const Counts &c) {
    w.text(NC_GLOBAL, "Conventions", "CF-1.8 UGRID-1.0");
    w.text(NC_GLOBAL, "title", options.title);
    w.text(NC_GLOBAL, "source", std::string("globemesh ") + GLOBEMESH_VERSION);
    if (!options.history.empty())
        w.text(NC_GLOBAL, "history", options.history);
    for (const auto &[key, value] : mesh.attributes) {
        std::string name = attribute_name(key);
        if (!w.has_att(NC_GLOBAL, name.c_str()))
            w.text(NC_GLOBAL, name.c_str(), value);
    }
    w.ints(NC_GLOBAL, "node_count", {int(c.nn)});
    w.ints(NC_GLOBAL, "face_count", {int(c.nf)});
    w.ints(NC_GLOBAL, "edge_count", {int(c.ne)});
    w.ints(NC_GLOBAL, "boundary_edge_count", {int(c.nb)});
    w.ints(NC_GLOBAL, "boundary_loop_count", {int(stats.boundary_loops)});
    w.dbl(NC_GLOBAL, "quality_min", stats.quality_min);
    w.dbl(NC_GLOBAL, "quality_mean", stats.quality_mean);
    w.dbl(NC_GLOBAL, "quality_fraction_above_0_8", stats.quality_above_0_8);
    w.dbl(NC_GLOBAL, "edge_length_km_min", stats.edge_km_min);
    w.dbl(NC_GLOBAL, "edge_length_km_mean", stats.edge_km_mean);
    w.dbl(NC_GLOBAL, "edge_length_km_max", stats.edge_km_max);
    w.dbl(NC_GLOBAL, "area_km2", stats.area_km2);
}

/// Writes every variable with dimensions, in the order of the file's layout.
void write_data(NcBlockWriter &w, const Mesh &mesh, const io::MeshTopology &topo, const Counts &c,
                const TopologyVars &t, const FieldVars &fv, const UgridOptions &options) {
    const std::size_t nn = c.nn, nf = c.nf, ne = c.ne, nb = c.nb;
    // Every variable is computed block by block while it is written (NcBlockWriter::in_blocks):
    // no table of the file is ever whole in memory, beside the mesh and its topology.
    auto centre = [&](std::size_t f) {
        return normalized(mesh.nodes[mesh.faces[f][0]] + mesh.nodes[mesh.faces[f][1]] +
                          mesh.nodes[mesh.faces[f][2]]);
    };
    auto midpoint = [&](std::size_t e) {
        const auto ends = topo.edge_nodes(e);
        return arc_midpoint(mesh.nodes[ends[0]], mesh.nodes[ends[1]]);
    };
    w.put_rows<int, 3>(t.face_nodes, nf, [&](std::size_t f) {
        const auto &tri = mesh.faces[f];
        return std::array<int, 3>{int(tri[0]), int(tri[1]), int(tri[2])};
    });
    if (detail::after_partial_write)
        detail::after_partial_write(); // tests only (write_hooks.hpp)
    // Longitudes in [0, 360) for a region across 180 (or up to it): no face cut at the seam,
    // which QGIS (MDAL) draws across the whole map; as the model formats write them.
    const bool east = io::east_longitudes(mesh);
    w.put_derived_lonlat(t.coords[2], t.coords[3], nf, centre, east);
    w.put_derived_lonlat(t.coords[4], t.coords[5], ne, midpoint, east);
    w.put_rows<int, 2>(t.edge_nodes, ne, [&](std::size_t e) { return topo.edge_nodes(e); });
    {
        w.put_lonlat(
            t.coords[0], t.coords[1], nn, [&](std::size_t i) { return mesh.nodes[i]; }, east);
        const io::GeodesicFaceAreas areas(topo);
        if (options.face_areas_m2)
            options.face_areas_m2->assign(nf, 0.0);
        // Face edges, face neighbours and face areas a block of faces at a time (face_edges): no
        // face-to-edge table of the whole mesh (12 bytes a face) at the writer's peak.
        struct FaceRows {
            std::vector<std::int32_t> edges;
            std::vector<int> links;
            std::vector<double> area;
        };
        w.in_blocks<FaceRows>(nf, [&](std::size_t first, std::size_t count, FaceRows &b,
                                      NcBlockWriter::Block &block) {
            io::face_edges(topo, first, count, b.edges);
            b.links.resize(3 * count);
            b.area.resize(count);
            for (std::size_t i = 0; i < count; ++i) {
                const auto nb = io::face_faces(topo, &b.edges[3 * i], first + i);
                std::copy(nb.begin(), nb.end(), b.links.begin() + std::ptrdiff_t(3 * i));
                b.area[i] = areas.face_m2(first + i, &b.edges[3 * i]);
            }
            block.put(t.face_edges, b.edges.data(), count);
            block.put(t.face_links, b.links.data(), count);
            block.put(fv.area, b.area.data(), count);
            if (options.face_areas_m2)
                std::copy(b.area.begin(), b.area.end(),
                          options.face_areas_m2->begin() + std::ptrdiff_t(first));
        });
    }
    w.put_rows<int, 2>(t.edge_faces, ne, [&](std::size_t e) { return topo.edge_faces(e); });
    if (nb)
        w.put_rows<int, 2>(t.bnd, nb, [&](std::size_t i) {
            return topo.edge_nodes(std::size_t(topo.boundary_edges[i]));
        });
    for (std::size_t i = 0; i < fv.node.size(); ++i) {
        const Field &f = mesh.node_fields[i];
        w.put_values<double>(fv.node[i], nn, [&](std::size_t k) { return f.values[k]; });
    }
    w.put_values<double>(fv.quality, nf, [&](std::size_t f) {
        const auto &tri = mesh.faces[f];
        return triangle_quality(mesh.nodes[tri[0]], mesh.nodes[tri[1]], mesh.nodes[tri[2]]);
    });
    for (std::size_t i = 0; i < fv.face.size(); ++i) {
        const Field &f = *fv.extra_face_fields[i];
        w.put_values<double>(fv.face[i], nf, [&](std::size_t k) { return f.values[k]; });
    }
    w.in_blocks<std::vector<int>>(ne, [&](std::size_t first, std::size_t count,
                                          std::vector<int> &tags, NcBlockWriter::Block &block) {
        tags.assign(count, int(EdgeTag::interior));
        // boundary_edges ascend: those of this block follow the first at or after `first`.
        auto b = std::lower_bound(topo.boundary_edges.begin(), topo.boundary_edges.end(),
                                  std::int32_t(first));
        for (; b != topo.boundary_edges.end() && std::size_t(*b) < first + count; ++b)
            tags[std::size_t(*b) - first] =
                topo.boundary_tags[std::size_t(b - topo.boundary_edges.begin())];
        block.put(fv.tag, tags.data(), count);
    });
}

} // namespace

void write_ugrid(const Mesh &mesh, const std::filesystem::path &path, const UgridOptions &options) {
    check_fields(mesh, path);
    OutputFile out(path, options.overwrite, "UGRID output");
    const auto topology = io::topology_of(mesh);
    const io::MeshTopology &topo = *topology;
    const MeshStats stats = options.stats ? *options.stats : io::compute_stats(mesh, topo);
    const Counts counts{mesh.nodes.size(), mesh.faces.size(), topo.edge_count(),
                        topo.boundary_edges.size()};

    // Coordinates, quality and area are computed one variable at a time while writing, each in
    // a buffer freed before the next: all of them at once were most of the writer's peak (about
    // 250 bytes per node). Nothing of that can fail; a failure of the file itself leaves only
    // the temporary output, which OutputFile removes.
    io::NcHandle nc;
    const int mode =
        options.classic ? (NC_NOCLOBBER | NC_64BIT_OFFSET) : (NC_NOCLOBBER | NC_NETCDF4);
    nc.create(out.temp_path(), mode, path, "UGRID output");
    int old_fill;
    nc_set_fill(nc.id(), NC_NOFILL, &old_fill);
    NcBlockWriter w(nc, out.temp_path(), path, !options.classic, options.progress);

    const Dims dims = define_dimensions(w, counts);
    TopologyVars t;
    t.crs = define_crs(w);
    t.mesh = define_topology(w, counts.nb != 0);
    define_coordinates(w, dims, t);
    define_connectivity(w, dims, t);
    const FieldVars fields = define_fields(w, mesh, dims);
    define_global_attributes(w, mesh, options, stats, counts);
    io::nc_check(nc_enddef(nc.id()), path, "leaving define mode", "UGRID output");

    // The container variables hold no data, but NC_NOFILL leaves their bytes undefined: write
    // them so the same mesh always gives the same file.
    const int zero = 0;
    io::nc_check(nc_put_var_int(nc.id(), t.crs, &zero), path, "writing crs", "UGRID output");
    io::nc_check(nc_put_var_int(nc.id(), t.mesh, &zero), path, "writing the mesh variable",
                 "UGRID output");
    w.start_data();
    write_data(w, mesh, topo, counts, t, fields, options);
    w.finish();
    out.commit();
}

namespace {

/// The QGIS style that shows depth first, or "" when the mesh has no depth. QGIS (MDAL) names a
/// dataset group by its variable's long_name and numbers the groups in the byte order of names.
std::string depth_style(const Mesh &mesh) {
    auto group_name = [](const Field &f) { return f.long_name.empty() ? f.name : f.long_name; };
    std::set<std::string> names = {"quality (2*sqrt(3)*inradius/longest edge)",
                                   "face area (geodesic, WGS84)"};
    const Field *depth = nullptr;
    for (const auto &f : mesh.node_fields) {
        names.insert(group_name(f));
        if (f.name == "depth" && !depth)
            depth = &f;
    }
    for (const auto &f : mesh.face_fields)
        names.insert(group_name(f));
    if (!depth)
        return "";
    double deepest = 0;
    for (double d : depth->values)
        if (std::isfinite(d))
            deepest = std::max(deepest, d);
    const auto group = std::distance(names.begin(), names.find(group_name(*depth)));
    return io::qgis_depth_style(int(group), deepest > 0 ? deepest : 1.0);
}

/// Writes `text` to the temporary file of `out`.
void write_style(const OutputFile &out, const std::string &text) {
    std::ofstream f(out.temp_path(), std::ios::binary);
    f << text;
    f.flush();
    if (!f)
        throw IoError("QGIS style " + out.target().string() + ": write failed" +
                      OutputFile::full_disk_note(out.target()));
}

/// Removes the style beside a UGRID file that an earlier run wrote (marked so) and this one,
/// without depth, does not replace: it would show another variable with the depth ramp.
void remove_our_style(const std::filesystem::path &qml) {
    std::ifstream f(qml, std::ios::binary);
    std::string doctype, mark;
    if (f && std::getline(f, doctype) && std::getline(f, mark) && mark == io::qgis_style_mark) {
        f.close();
        std::error_code ignored; // a style left behind is no failure of the run
        std::filesystem::remove(qml, ignored);
    }
}

} // namespace

/// The UGRID row of the writers table (writers.cpp); with depth, NAME.qml beside NAME.nc, the
/// style QGIS loads with the file (QgsMapLayer::loadDefaultStyle), so that it shows depth first.
void write_as_ugrid(const Mesh &mesh, const std::filesystem::path &path,
                    const WriteOptions &options) {
    UgridOptions ugrid;
    ugrid.classic = creation_option(options.creation_options, "FORMAT", "NC4") == "NC2";
    ugrid.overwrite = options.overwrite;
    ugrid.title = options.title;
    ugrid.history = options.history;
    ugrid.stats = options.stats;
    ugrid.face_areas_m2 = options.face_areas_m2;
    ugrid.progress = options.progress;
    const std::string style = depth_style(mesh);
    std::optional<OutputFile> qml;
    if (!style.empty() && path.extension() != ".qml") {
        qml.emplace(std::filesystem::path(path).replace_extension(".qml"), options.overwrite,
                    "QGIS style");
        write_style(*qml, style);
    }
    write_ugrid(mesh, path, ugrid);
    if (qml)
        qml->commit();
    else if (options.overwrite && path.extension() != ".qml")
        remove_our_style(std::filesystem::path(path).replace_extension(".qml"));
}

} // namespace globemesh
