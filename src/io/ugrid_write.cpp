// UGRID 1.0 NetCDF writer: see globemesh/ugrid.hpp.
//
// Layout (names are fixed so tools and tests can rely on them): dimensions nMesh_node,
// nMesh_face, nMesh_edge, nMesh_boundary (only when the mesh has a boundary), Two, Three; the
// topology variable "mesh"; coordinates mesh_{node,face,edge}_{lon,lat}; connectivities
// mesh_face_nodes, mesh_edge_nodes, mesh_face_edges, mesh_face_links, mesh_edge_face_links,
// mesh_boundary_nodes, all 0-based with start_index written; "crs" for CF and MDAL. Nothing in
// the file depends on the clock: the only date is the caller's history string.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <future>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/ugrid.hpp"
#include "face_area.hpp"
#include "face_geometry.hpp"
#include "mesh_topology.hpp"
#include "netcdf_handle.hpp"

#ifndef GLOBEMESH_VERSION
#define GLOBEMESH_VERSION "unknown"
#endif

namespace globemesh {

namespace {

constexpr const char* wgs84_wkt =
    "GEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\",ELLIPSOID[\"WGS 84\",6378137,298.257223563,"
    "LENGTHUNIT[\"metre\",1]]],PRIMEM[\"Greenwich\",0,ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "CS[ellipsoidal,2],AXIS[\"geodetic latitude (Lat)\",north,ORDER[1],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "AXIS[\"geodetic longitude (Lon)\",east,ORDER[2],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "ID[\"EPSG\",4326]]";

/// Writes the variables of one file; every call checks its status.
class UgridWriter {
public:
    UgridWriter(int id, const std::filesystem::path& file, bool compress, const Progress& progress)
        : id_(id), file_(file), compress_(compress), progress_(progress) {}

    int dim(const char* name, std::size_t len) {
        int d;
        io::nc_check(nc_def_dim(id_, name, len, &d), file_, std::string("defining dimension ") + name);
        return d;
    }
    int var(const char* name, nc_type type, std::vector<int> dims) {
        int v;
        io::nc_check(nc_def_var(id_, name, type, int(dims.size()), dims.data(), &v), file_,
                     std::string("defining variable ") + name);
        if (!dims.empty()) {
            std::size_t rows = 0;
            io::nc_check(nc_inq_dimlen(id_, dims[0], &rows), file_, std::string("sizing ") + name);
            rows_total_ += rows; // every variable with dimensions is written whole, once
        }
        if (compress_ && !dims.empty()) {
            // Chunks of at most 65536 rows and a small chunk cache: netCDF's default chunking
            // makes one chunk of a whole variable, and HDF5 then keeps every variable written
            // in memory until the file closes (about half the process's peak at 1e6 nodes).
            std::vector<std::size_t> chunk(dims.size());
            for (std::size_t k = 0; k < dims.size(); ++k) {
                io::nc_check(nc_inq_dimlen(id_, dims[k], &chunk[k]), file_, std::string("sizing ") + name);
                chunk[k] = std::max<std::size_t>(1, k == 0 ? std::min(chunk[k], block_rows) : chunk[k]);
            }
            io::nc_check(nc_def_var_chunking(id_, v, NC_CHUNKED, chunk.data()), file_, std::string("chunking ") + name);
            io::nc_check(nc_set_var_chunk_cache(id_, v, 1u << 20, 7, 1.0f), file_, std::string("caching ") + name);
            io::nc_check(nc_def_var_deflate(id_, v, 1, 1, 1), file_, std::string("compressing ") + name);
        }
        return v;
    }
    void text(int v, const char* name, const std::string& value) {
        io::nc_check(nc_put_att_text(id_, v, name, value.size(), value.c_str()), file_,
                     std::string("writing attribute ") + name);
    }
    void ints(int v, const char* name, std::vector<int> values) {
        io::nc_check(nc_put_att_int(id_, v, name, NC_INT, values.size(), values.data()), file_,
                     std::string("writing attribute ") + name);
    }
    void dbl(int v, const char* name, double value) {
        io::nc_check(nc_put_att_double(id_, v, name, NC_DOUBLE, 1, &value), file_,
                     std::string("writing attribute ") + name);
    }
    bool has_att(int v, const char* name) const { return nc_inq_attid(id_, v, name, nullptr) == NC_NOERR; }
    /// Runs compute(first, count, buffers) and then write(first, count, buffers) for each block of
    /// block_rows rows of n, in order. The next block is computed on another thread while this
    /// one is written (netCDF-4's compression takes about as long as the computing); compute is
    /// called for one block at a time, in order, so the file is the same as without.
    template <class Buffers, class Compute, class Write>
    static void in_blocks(std::size_t n, const Compute& compute, const Write& write) {
        if (n == 0) return;
        auto count_at = [n](std::size_t first) { return std::min(block_rows, n - first); };
        Buffers current, next;
        compute(std::size_t(0), count_at(0), current);
        for (std::size_t first = 0; first < n; first += block_rows) {
            const std::size_t after = first + block_rows;
            std::future<void> ahead; // joined by its destructor should write throw
            if (after < n) {
                auto compute_next = [&] { compute(after, count_at(after), next); };
                try {
                    ahead = std::async(std::launch::async, compute_next);
                } catch (const std::system_error&) {
                    compute_next(); // no thread to be had (a process limit): in turn
                }
            }
            write(first, count_at(first), current);
            if (ahead.valid()) ahead.get();
            std::swap(current, next);
        }
    }
    /// Writes the n rows of variable v in blocks of block_rows (one chunk each), N values of
    /// type T (double or int, as the variable) a row: row(i) returns row i as std::array<T, N>.
    /// Rows are asked for in ascending order, from one thread at a time (in_blocks).
    template <class T, std::size_t N, class Row>
    void put_rows(int v, std::size_t n, const Row& row, const char* name) {
        in_blocks<std::vector<T>>(
            n,
            [&](std::size_t first, std::size_t count, std::vector<T>& block) {
                block.resize(count * N);
                for (std::size_t i = 0; i < count; ++i) {
                    const std::array<T, N> r = row(first + i);
                    std::copy(r.begin(), r.end(), block.begin() + std::ptrdiff_t(i * N));
                }
            },
            [&](std::size_t first, std::size_t count, const std::vector<T>& block) {
                put_block_rows(v, first, count, N, block.data(), name);
            });
    }
    /// put_rows for a variable of one value per row: value(i) returns row i's value.
    template <class T, class Value>
    void put_values(int v, std::size_t n, const Value& value, const char* name) {
        put_rows<T, 1>(v, n, [&](std::size_t i) { return std::array<T, 1>{value(i)}; }, name);
    }

    /// Writes the lon and lat of n points to variables v_lon and v_lat, point(i) giving point i
    /// (a unit vector), each converted once.
    template <class Point>
    void put_lonlat(int v_lon, int v_lat, std::size_t n, const Point& point, const char* what) {
        using LonLats = std::array<std::vector<double>, 2>;
        const std::string lons = std::string(what) + " longitudes", lats = std::string(what) + " latitudes";
        in_blocks<LonLats>(
            n,
            [&](std::size_t first, std::size_t count, LonLats& b) {
                b[0].resize(count);
                b[1].resize(count);
                for (std::size_t i = 0; i < count; ++i) {
                    const LonLat p = vec_to_lonlat(point(first + i));
                    b[0][i] = p.lon;
                    b[1][i] = p.lat;
                }
            },
            [&](std::size_t first, std::size_t count, const LonLats& b) {
                put_block_rows(v_lon, first, count, 1, b[0].data(), lons.c_str());
                put_block_rows(v_lat, first, count, 1, b[1].data(), lats.c_str());
            });
    }

    /// Writes rows first .. first + count - 1 of variable v (n_per_row values of type T, double or
    /// int as the variable, a row) from data.
    template <class T>
    void put_block_rows(int v, std::size_t first, std::size_t count, std::size_t n_per_row, const T* data,
                        const char* name) {
        const std::size_t start[2] = {first, 0}, counts[2] = {count, n_per_row};
        io::nc_check(put_block(v, start, counts, data), file_, std::string("writing ") + name);
        rows_done_ += count;
        report(progress_, double(rows_done_) / double(std::max<std::size_t>(rows_total_, 1)), "write_ugrid");
    }
    static constexpr std::size_t block_rows = 65536; ///< rows a block, as the chunks

private:
    int put_block(int v, const std::size_t* start, const std::size_t* count, const double* data) {
        return nc_put_vara_double(id_, v, start, count, data);
    }
    int put_block(int v, const std::size_t* start, const std::size_t* count, const int* data) {
        return nc_put_vara_int(id_, v, start, count, data);
    }

    int id_;
    const std::filesystem::path& file_;
    bool compress_;
    const Progress& progress_;
    std::size_t rows_total_ = 0, rows_done_ = 0; ///< rows of all the variables, and written
};

/// A netCDF attribute name from a free-form key (letters, digits, underscore).
std::string attribute_name(const std::string& key) {
    std::string s;
    for (char c : key) s += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) s.insert(0, "a_");
    return s;
}

void field_attributes(UgridWriter& w, int v, const Field& f, const char* location, const char* coords) {
    w.text(v, "mesh", "mesh");
    w.text(v, "location", location);
    w.text(v, "coordinates", coords);
    w.text(v, "grid_mapping", "crs");
    std::string standard = f.standard_name;
    std::string units = f.units;
    if (f.name == "depth") {
        if (standard.empty()) standard = "sea_floor_depth_below_geoid";
        if (units.empty()) units = std::string(1, 'm');
        w.text(v, "positive", "down");
    }
    if (f.name == "target_size" && units.empty()) units = "km";
    w.text(v, "long_name", f.long_name.empty() ? f.name : f.long_name);
    if (!standard.empty()) w.text(v, "standard_name", standard);
    if (!units.empty()) w.text(v, "units", units);
}

} // namespace

void write_ugrid(const Mesh& mesh, const std::filesystem::path& path, const UgridOptions& options) {
    for (const auto& f : mesh.node_fields)
        if (f.values.size() != mesh.nodes.size())
            throw DataError("mesh: node field " + f.name + " has " + std::to_string(f.values.size()) +
                            " values for " + std::to_string(mesh.nodes.size()) + " nodes");
    for (const auto& f : mesh.face_fields)
        if (f.values.size() != mesh.faces.size())
            throw DataError("mesh: face field " + f.name + " has " + std::to_string(f.values.size()) +
                            " values for " + std::to_string(mesh.faces.size()) + " faces");
    if (mesh.faces.empty()) throw DataError("mesh: no faces to write to " + path.string());

    OutputFile out(path, options.overwrite, "UGRID output");
    const io::MeshTopology topo = io::build_topology(mesh);
    const MeshStats stats = options.stats ? *options.stats : io::compute_stats(mesh, topo);
    const std::size_t nn = mesh.nodes.size(), nf = mesh.faces.size(), ne = topo.edge_count(),
                      nb = topo.boundary_edges.size();

    // Coordinates, quality and area are computed one variable at a time while writing, each in
    // a buffer freed before the next: all of them at once were most of the writer's peak (about
    // 250 bytes per node). Nothing of that can fail; a failure of the file itself leaves only
    // the temporary output, which OutputFile removes.
    io::NcHandle nc;
    const int mode = options.classic ? (NC_NOCLOBBER | NC_64BIT_OFFSET) : (NC_NOCLOBBER | NC_NETCDF4);
    nc.create(out.temp_path(), mode, path, "UGRID output");
    int old_fill;
    nc_set_fill(nc.id(), NC_NOFILL, &old_fill);
    UgridWriter w(nc.id(), path, !options.classic, options.progress);

    const int d_node = w.dim("nMesh_node", nn), d_face = w.dim("nMesh_face", nf), d_edge = w.dim("nMesh_edge", ne);
    const int d_two = w.dim("Two", 2), d_three = w.dim("Three", 3);
    const int d_bnd = nb ? w.dim("nMesh_boundary", nb) : -1;

    // CRS, read by CF tools (grid_mapping_name, crs_wkt) and by MDAL (EPSG_code, epsg).
    int crs = w.var("crs", NC_INT, {});
    w.text(crs, "grid_mapping_name", "latitude_longitude");
    w.dbl(crs, "longitude_of_prime_meridian", 0.0);
    w.dbl(crs, "semi_major_axis", 6378137.0);
    w.dbl(crs, "inverse_flattening", 298.257223563);
    w.text(crs, "crs_wkt", wgs84_wkt);
    w.text(crs, "wkt", wgs84_wkt);
    w.ints(crs, "epsg", {4326});
    w.text(crs, "EPSG_code", "EPSG:4326");

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
    if (nb) w.text(topo_var, "boundary_node_connectivity", "mesh_boundary_nodes");
    w.text(topo_var, "face_dimension", "nMesh_face");
    w.text(topo_var, "edge_dimension", "nMesh_edge");

    struct Coord { const char* name; int dim; bool lon; const char* what; };
    const Coord coords[] = {{"mesh_node_lon", d_node, true, "node"}, {"mesh_node_lat", d_node, false, "node"},
                            {"mesh_face_lon", d_face, true, "face centre"}, {"mesh_face_lat", d_face, false, "face centre"},
                            {"mesh_edge_lon", d_edge, true, "edge midpoint"}, {"mesh_edge_lat", d_edge, false, "edge midpoint"}};
    int coord_vars[6];
    for (int i = 0; i < 6; ++i) {
        const Coord& c = coords[i];
        int v = coord_vars[i] = w.var(c.name, NC_DOUBLE, {c.dim});
        w.text(v, "standard_name", c.lon ? "longitude" : "latitude");
        w.text(v, "long_name", std::string(c.lon ? "longitude of " : "latitude of ") + c.what);
        w.text(v, "units", c.lon ? "degrees_east" : "degrees_north");
        w.text(v, "grid_mapping", "crs");
    }

    auto connectivity = [&](const char* name, const char* role, int d_elem, int d_cols, const char* long_name, bool fill) {
        int v = w.var(name, NC_INT, {d_elem, d_cols});
        w.text(v, "cf_role", role);
        w.text(v, "long_name", long_name);
        w.ints(v, "start_index", {0});
        if (fill) w.ints(v, "_FillValue", {-1});
        return v;
    };
    int v_face_nodes = connectivity("mesh_face_nodes", "face_node_connectivity", d_face, d_three,
                                    "nodes of each face, counter-clockwise", false);
    int v_edge_nodes = connectivity("mesh_edge_nodes", "edge_node_connectivity", d_edge, d_two,
                                    "nodes of each edge", false);
    int v_face_edges = connectivity("mesh_face_edges", "face_edge_connectivity", d_face, d_three,
                                    "edges of each face (edge k joins nodes k and k+1)", false);
    int v_face_links = connectivity("mesh_face_links", "face_face_connectivity", d_face, d_three,
                                    "neighbour faces of each face", true);
    int v_edge_faces = connectivity("mesh_edge_face_links", "edge_face_connectivity", d_edge, d_two,
                                    "faces on each side of each edge", true);
    int v_bnd = nb ? connectivity("mesh_boundary_nodes", "boundary_node_connectivity", d_bnd, d_two,
                                  "nodes of each boundary edge, mesh on the left", false)
                   : -1;

    const char* node_coords = "mesh_node_lon mesh_node_lat";
    const char* face_coords = "mesh_face_lon mesh_face_lat";
    std::vector<int> node_vars, face_vars;
    // Variable names in use; a field whose name is taken gets a "_node"/"_face" suffix.
    std::set<std::string> used = {"crs", "mesh", "quality", "area", "boundary_tag", "mesh_node_lon",
                                  "mesh_node_lat", "mesh_face_lon", "mesh_face_lat", "mesh_edge_lon",
                                  "mesh_edge_lat", "mesh_face_nodes", "mesh_edge_nodes", "mesh_face_edges",
                                  "mesh_face_links", "mesh_edge_face_links", "mesh_boundary_nodes"};
    auto var_name = [&used](const std::string& name, const char* suffix) {
        std::string n = attribute_name(name);
        while (used.count(n)) n += suffix;
        used.insert(n);
        return n;
    };
    for (const auto& f : mesh.node_fields) {
        node_vars.push_back(w.var(var_name(f.name, "_node").c_str(), NC_DOUBLE, {d_node}));
        field_attributes(w, node_vars.back(), f, "node", node_coords);
    }
    Field q_field{"quality", "quality (2*sqrt(3)*inradius/longest edge)", "1", "", {}};
    Field a_field{"area", "face area (geodesic, WGS84)", "m2", "cell_area", {}};
    int v_quality = w.var("quality", NC_DOUBLE, {d_face});
    field_attributes(w, v_quality, q_field, "face", face_coords);
    w.text(v_quality, "comment", "shape quality of the chordal triangle: 1 equilateral, 0 degenerate");
    int v_area = w.var("area", NC_DOUBLE, {d_face});
    field_attributes(w, v_area, a_field, "face", face_coords);
    std::vector<const Field*> extra_face_fields;
    for (const auto& f : mesh.face_fields) {
        if (f.name == "quality" || f.name == "area") continue; // recomputed above
        extra_face_fields.push_back(&f);
        face_vars.push_back(w.var(var_name(f.name, "_face").c_str(), NC_DOUBLE, {d_face}));
        field_attributes(w, face_vars.back(), f, "face", face_coords);
    }
    int v_tag = w.var("boundary_tag", NC_INT, {d_edge});
    w.text(v_tag, "mesh", "mesh");
    w.text(v_tag, "location", "edge");
    w.text(v_tag, "coordinates", "mesh_edge_lon mesh_edge_lat");
    w.text(v_tag, "long_name", "boundary tag of each edge");
    w.ints(v_tag, "flag_values", {0, 1, 2});
    w.text(v_tag, "flag_meanings", "interior coast open");

    // Global attributes: conventions, provenance, the mesh's run metadata, summary statistics.
    w.text(NC_GLOBAL, "Conventions", "CF-1.8 UGRID-1.0");
    w.text(NC_GLOBAL, "title", options.title);
    w.text(NC_GLOBAL, "source", std::string("globemesh ") + GLOBEMESH_VERSION);
    if (!options.history.empty()) w.text(NC_GLOBAL, "history", options.history);
    for (const auto& [key, value] : mesh.attributes) {
        std::string name = attribute_name(key);
        if (!w.has_att(NC_GLOBAL, name.c_str())) w.text(NC_GLOBAL, name.c_str(), value);
    }
    w.ints(NC_GLOBAL, "node_count", {int(nn)});
    w.ints(NC_GLOBAL, "face_count", {int(nf)});
    w.ints(NC_GLOBAL, "edge_count", {int(ne)});
    w.ints(NC_GLOBAL, "boundary_edge_count", {int(nb)});
    w.ints(NC_GLOBAL, "boundary_loop_count", {int(stats.boundary_loops)});
    w.dbl(NC_GLOBAL, "quality_min", stats.quality_min);
    w.dbl(NC_GLOBAL, "quality_mean", stats.quality_mean);
    w.dbl(NC_GLOBAL, "quality_fraction_above_0_8", stats.quality_above_0_8);
    w.dbl(NC_GLOBAL, "edge_length_km_min", stats.edge_km_min);
    w.dbl(NC_GLOBAL, "edge_length_km_mean", stats.edge_km_mean);
    w.dbl(NC_GLOBAL, "edge_length_km_max", stats.edge_km_max);
    w.dbl(NC_GLOBAL, "area_km2", stats.area_km2);

    io::nc_check(nc_enddef(nc.id()), path, "leaving define mode", "UGRID output");

    // The container variables hold no data, but NC_NOFILL leaves their bytes undefined: write
    // them so the same mesh always gives the same file.
    const int zero = 0;
    io::nc_check(nc_put_var_int(nc.id(), crs, &zero), path, "writing crs", "UGRID output");
    io::nc_check(nc_put_var_int(nc.id(), topo_var, &zero), path, "writing the mesh variable", "UGRID output");

    // Every variable is computed block by block while it is written (UgridWriter::put_rows):
    // no table of the file is ever whole in memory. Beside the mesh and its topology, one helper
    // table: the edges' area terms (GeodesicFaceAreas, 24 bytes a node).
    auto centre = [&](std::size_t f) {
        return normalized(mesh.nodes[mesh.faces[f][0]] + mesh.nodes[mesh.faces[f][1]] + mesh.nodes[mesh.faces[f][2]]);
    };
    auto midpoint = [&](std::size_t e) {
        const auto ends = topo.edge_nodes(e);
        return arc_midpoint(mesh.nodes[ends[0]], mesh.nodes[ends[1]]);
    };
    // The edges' geodesic problems (GeodesicFaceAreas), the writer's largest computation, run in
    // the background from here, while the variables before the face areas are computed and
    // compressed (HDF5's deflate runs in this thread alone).
    std::atomic<bool> stop_solving{false};
    auto solve_edges = [&topo, &stop_solving] { return io::GeodesicFaceAreas(topo, &stop_solving); };
    std::future<io::GeodesicFaceAreas> areas_ahead;
    try {
        areas_ahead = std::async(std::launch::async, solve_edges);
    } catch (const std::system_error&) {
        areas_ahead = std::async(std::launch::deferred, solve_edges); // no thread to be had: when needed
    }
    // A failure or a cancel before the areas are taken stops their computation: the future's
    // destructor waits for it (at 1e7 nodes, a minute).
    struct StopOnExit {
        std::atomic<bool>& stop;
        ~StopOnExit() { stop = true; }
    } stop_on_exit{stop_solving};
    w.put_rows<int, 3>(v_face_nodes, nf, [&](std::size_t f) {
        const auto& t = mesh.faces[f];
        return std::array<int, 3>{int(t[0]), int(t[1]), int(t[2])};
    }, "face nodes");
    if (options.after_partial_write) options.after_partial_write();
    w.put_lonlat(coord_vars[2], coord_vars[3], nf, centre, "face");
    w.put_lonlat(coord_vars[4], coord_vars[5], ne, midpoint, "edge");
    w.put_rows<int, 2>(v_edge_nodes, ne, [&](std::size_t e) { return topo.edge_nodes(e); }, "edge nodes");
    {
        w.put_lonlat(coord_vars[0], coord_vars[1], nn, [&](std::size_t i) { return mesh.nodes[i]; }, "node");
        const io::GeodesicFaceAreas areas = areas_ahead.get();
        // Face edges, face neighbours and face areas a block of faces at a time (face_edges): no
        // face-to-edge table of the whole mesh (12 bytes a face) at the writer's peak.
        struct FaceRows {
            std::vector<std::int32_t> edges;
            std::vector<int> links;
            std::vector<double> area;
        };
        UgridWriter::in_blocks<FaceRows>(
            nf,
            [&](std::size_t first, std::size_t count, FaceRows& b) {
                io::face_edges(topo, first, count, b.edges);
                b.links.resize(3 * count);
                b.area.resize(count);
                for (std::size_t i = 0; i < count; ++i) {
                    const auto nb = io::face_faces(topo, &b.edges[3 * i], first + i);
                    std::copy(nb.begin(), nb.end(), b.links.begin() + std::ptrdiff_t(3 * i));
                    b.area[i] = areas.face_m2(first + i, &b.edges[3 * i]);
                }
            },
            [&](std::size_t first, std::size_t count, const FaceRows& b) {
                w.put_block_rows(v_face_edges, first, count, 3, b.edges.data(), "face edges");
                w.put_block_rows(v_face_links, first, count, 3, b.links.data(), "face neighbours");
                w.put_block_rows(v_area, first, count, 1, b.area.data(), "area");
            });
    }
    w.put_rows<int, 2>(v_edge_faces, ne, [&](std::size_t e) { return topo.edge_faces(e); }, "edge faces");
    if (nb)
        w.put_rows<int, 2>(v_bnd, nb, [&](std::size_t i) { return topo.edge_nodes(std::size_t(topo.boundary_edges[i])); },
                           "boundary nodes");
    for (std::size_t i = 0; i < node_vars.size(); ++i) {
        const Field& f = mesh.node_fields[i];
        w.put_values<double>(node_vars[i], nn, [&](std::size_t k) { return f.values[k]; }, f.name.c_str());
    }
    w.put_values<double>(v_quality, nf, [&](std::size_t f) {
        const auto& t = mesh.faces[f];
        return triangle_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]);
    }, "quality");
    for (std::size_t i = 0; i < face_vars.size(); ++i) {
        const Field& f = *extra_face_fields[i];
        w.put_values<double>(face_vars[i], nf, [&](std::size_t k) { return f.values[k]; }, f.name.c_str());
    }
    std::size_t next_boundary = 0; // rows come in ascending order, as boundary_edges
    w.put_values<int>(v_tag, ne, [&](std::size_t e) {
        if (next_boundary < nb && std::size_t(topo.boundary_edges[next_boundary]) == e)
            return topo.boundary_tags[next_boundary++];
        return int(EdgeTag::interior);
    }, "boundary tags");
    nc.close(path, "UGRID output");
    out.commit();
}

} // namespace globemesh
