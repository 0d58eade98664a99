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
#include "hdf5_chunks.hpp"
#include "mesh_topology.hpp"
#include "netcdf_handle.hpp"
#include "ordered_blocks.hpp"
#include "write_hooks.hpp"

#ifndef GLOBEMESH_VERSION
#define GLOBEMESH_VERSION "unknown"
#endif

namespace globemesh {

namespace {

constexpr const char *wgs84_wkt =
    "GEOGCRS[\"WGS 84\",DATUM[\"World Geodetic System 1984\",ELLIPSOID[\"WGS "
    "84\",6378137,298.257223563,"
    "LENGTHUNIT[\"metre\",1]]],PRIMEM[\"Greenwich\",0,ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "CS[ellipsoidal,2],AXIS[\"geodetic latitude "
    "(Lat)\",north,ORDER[1],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "AXIS[\"geodetic longitude (Lon)\",east,ORDER[2],ANGLEUNIT[\"degree\",0.0174532925199433]],"
    "ID[\"EPSG\",4326]]";

/// Writes the variables of one file; every call checks its status.
///
/// The variables' data are computed and written a block of block_rows rows (one chunk) at a
/// time (in_blocks), on every core (ordered_blocks.hpp). A netCDF-4 file is defined and closed
/// in netCDF-C first (start_data), then each block's rows are shuffled and deflated on the
/// thread that computed them and stored from this one as whole chunks (hdf5_chunks.hpp); a
/// classic file's rows go through netCDF-C as they are.
class UgridWriter {
public:
    UgridWriter(io::NcHandle &nc, const std::filesystem::path &temp,
                const std::filesystem::path &file, bool compress, const Progress &progress)
        : nc_(nc), temp_(temp), file_(file), compress_(compress), progress_(progress) {}

    int dim(const char *name, std::size_t len) {
        int d;
        io::nc_check(nc_def_dim(nc_.id(), name, len, &d), file_,
                     std::string("defining dimension ") + name);
        return d;
    }
    int var(const char *name, nc_type type, std::vector<int> dims) {
        int v;
        io::nc_check(nc_def_var(nc_.id(), name, type, int(dims.size()), dims.data(), &v), file_,
                     std::string("defining variable ") + name);
        if (dims.empty())
            return v;
        Shape shape{name, 0, 1, 0};
        std::vector<std::size_t> lengths(dims.size());
        for (std::size_t k = 0; k < dims.size(); ++k) {
            io::nc_check(nc_inq_dimlen(nc_.id(), dims[k], &lengths[k]), file_,
                         std::string("sizing ") + name);
            if (k > 0)
                shape.row_values *= lengths[k];
        }
        shape.rows = lengths[0];
        rows_total_ += shape.rows; // every variable with dimensions is written whole, once
        if (compress_) {
            // Chunks of at most block_rows rows, whole rows each: the blocks in_blocks computes.
            // (netCDF's default chunking makes one chunk of a whole variable.)
            shape.chunk_rows = std::max<std::size_t>(1, std::min(shape.rows, block_rows));
            std::vector<std::size_t> chunk = lengths;
            chunk[0] = shape.chunk_rows;
            io::nc_check(nc_def_var_chunking(nc_.id(), v, NC_CHUNKED, chunk.data()), file_,
                         std::string("chunking ") + name);
            io::nc_check(nc_def_var_deflate(nc_.id(), v, 1, 1, 1), file_,
                         std::string("compressing ") + name);
        }
        if (shapes_.size() <= std::size_t(v))
            shapes_.resize(std::size_t(v) + 1);
        shapes_[std::size_t(v)] = shape;
        return v;
    }
    void text(int v, const char *name, const std::string &value) {
        io::nc_check(nc_put_att_text(nc_.id(), v, name, value.size(), value.c_str()), file_,
                     std::string("writing attribute ") + name);
    }
    void ints(int v, const char *name, std::vector<int> values) {
        io::nc_check(nc_put_att_int(nc_.id(), v, name, NC_INT, values.size(), values.data()), file_,
                     std::string("writing attribute ") + name);
    }
    void dbl(int v, const char *name, double value) {
        io::nc_check(nc_put_att_double(nc_.id(), v, name, NC_DOUBLE, 1, &value), file_,
                     std::string("writing attribute ") + name);
    }
    bool has_att(int v, const char *name) const {
        return nc_inq_attid(nc_.id(), v, name, nullptr) == NC_NOERR;
    }

    /// After the definitions and the variables without dimensions: a netCDF-4 file is closed
    /// and reopened for its chunks.
    void start_data() {
        if (!compress_)
            return;
        nc_.close(file_, "UGRID output");
        chunks_.emplace(temp_, file_, "UGRID output");
    }
    /// After the last block: closes the file (throws IoError).
    void finish() {
        if (chunks_)
            chunks_->close();
        else
            nc_.close(file_, "UGRID output");
    }

    /// One block's rows of each variable it holds, as compute gives them (in_blocks).
    class Block {
    public:
        /// Rows `first` .. `first + count - 1` (the block's) of variable v, row_values values of
        /// type T (double or int, as the variable) a row; `data` must live until the block is
        /// stored (it is the caller's Buffers).
        template <class T> void put(int v, const T *data, std::size_t count) {
            static_assert(std::is_same_v<T, double> || std::is_same_v<T, int>);
            if (used_ == pieces_.size())
                pieces_.emplace_back();
            Piece &p = pieces_[used_++];
            p.var = v;
            p.rows = count;
            p.is_double = std::is_same_v<T, double>;
            p.data = data;
            if (encoder_) {
                const Shape &s = writer_->shapes_[std::size_t(v)];
                encoder_->encode(data, count, s.chunk_rows, s.row_values * sizeof(T), sizeof(T),
                                 p.chunk);
            }
        }

    private:
        friend class UgridWriter;
        struct Piece {
            int var = -1;
            std::size_t rows = 0;
            bool is_double = false;
            const void *data = nullptr;
            std::vector<unsigned char> chunk; ///< encoded (netCDF-4)
        };
        const UgridWriter *writer_ = nullptr;
        io::ChunkEncoder *encoder_ = nullptr;
        std::vector<Piece>
            pieces_; ///< the first used_ are this block's (the rest: buffers to reuse)
        std::size_t used_ = 0;
    };

    /// Computes and stores the blocks of block_rows rows of n (compute_in_order). compute(first,
    /// count, buffers, block) fills `buffers` (its scratch, a Buffers kept from block to block)
    /// and puts each variable's rows into `block`; it runs on every core, for several blocks at
    /// once in any order, so it must only read shared data. The blocks are stored in order.
    template <class Buffers, class Compute> void in_blocks(std::size_t n, const Compute &compute) {
        struct Slot {
            Buffers buffers{};
            Block block;
        };
        io::compute_in_order<Slot, std::optional<io::ChunkEncoder>>(
            (n + block_rows - 1) / block_rows,
            [&](std::size_t k, Slot &slot, std::optional<io::ChunkEncoder> &encoder) {
                if (compress_ && !encoder)
                    encoder.emplace();
                slot.block.writer_ = this;
                slot.block.encoder_ = encoder ? &*encoder : nullptr;
                slot.block.used_ = 0;
                const std::size_t first = k * block_rows;
                compute(first, std::min(block_rows, n - first), slot.buffers, slot.block);
            },
            [&](std::size_t k, const Slot &slot) { store(k * block_rows, slot.block); });
    }

    /// in_blocks for one variable of N values of type T (double or int, as the variable) a row:
    /// row(i) returns row i as std::array<T, N>.
    template <class T, std::size_t N, class Row>
    void put_rows(int v, std::size_t n, const Row &row) {
        in_blocks<std::vector<T>>(
            n, [&](std::size_t first, std::size_t count, std::vector<T> &rows, Block &block) {
                rows.resize(count * N);
                for (std::size_t i = 0; i < count; ++i) {
                    const std::array<T, N> r = row(first + i);
                    std::copy(r.begin(), r.end(), rows.begin() + std::ptrdiff_t(i * N));
                }
                block.put(v, rows.data(), count);
            });
    }
    /// put_rows for a variable of one value per row: value(i) returns row i's value.
    template <class T, class Value> void put_values(int v, std::size_t n, const Value &value) {
        put_rows<T, 1>(v, n, [&](std::size_t i) { return std::array<T, 1>{value(i)}; });
    }

    /// Writes the lon and lat of n points to variables v_lon and v_lat, point(i) giving point i
    /// (a unit vector), each converted once.
    template <class Point>
    void put_lonlat(int v_lon, int v_lat, std::size_t n, const Point &point) {
        using LonLats = std::array<std::vector<double>, 2>;
        in_blocks<LonLats>(n, [&](std::size_t first, std::size_t count, LonLats &b, Block &block) {
            b[0].resize(count);
            b[1].resize(count);
            for (std::size_t i = 0; i < count; ++i) {
                const LonLat p = vec_to_lonlat(point(first + i));
                b[0][i] = p.lon;
                b[1][i] = p.lat;
            }
            block.put(v_lon, b[0].data(), count);
            block.put(v_lat, b[1].data(), count);
        });
    }

    static constexpr std::size_t block_rows = 65536; ///< rows a block, as the chunks

private:
    struct Shape {
        std::string name;
        std::size_t rows = 0, row_values = 1, chunk_rows = 0;
    };

    /// Stores a computed block whose rows start at `first`, and reports the progress.
    void store(std::size_t first, const Block &block) {
        for (std::size_t i = 0; i < block.used_; ++i) {
            const Block::Piece &p = block.pieces_[i];
            const Shape &s = shapes_[std::size_t(p.var)];
            if (chunks_) {
                chunks_->write(s.name, first, p.chunk);
            } else {
                const std::size_t start[2] = {first, 0}, count[2] = {p.rows, s.row_values};
                const int status = p.is_double
                                       ? nc_put_vara_double(nc_.id(), p.var, start, count,
                                                            static_cast<const double *>(p.data))
                                       : nc_put_vara_int(nc_.id(), p.var, start, count,
                                                         static_cast<const int *>(p.data));
                io::nc_check(status, file_, "writing " + s.name);
            }
            rows_done_ += p.rows;
            report(progress_, double(rows_done_) / double(std::max<std::size_t>(rows_total_, 1)),
                   "write_ugrid");
        }
    }

    io::NcHandle &nc_;
    const std::filesystem::path &temp_;
    const std::filesystem::path &file_;
    bool compress_;
    const Progress &progress_;
    std::vector<Shape> shapes_;                  ///< by variable id (those with dimensions)
    std::optional<io::Hdf5ChunkFile> chunks_;    ///< a netCDF-4 file's, from start_data
    std::size_t rows_total_ = 0, rows_done_ = 0; ///< rows of all the variables, and written
};

/// A netCDF attribute name from a free-form key (letters, digits, underscore).
std::string attribute_name(const std::string &key) {
    std::string s;
    for (char c : key)
        s += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0])))
        s.insert(0, "a_");
    return s;
}

void field_attributes(UgridWriter &w, int v, const Field &f, const char *location,
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

Dims define_dimensions(UgridWriter &w, const Counts &c) {
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

int define_crs(UgridWriter &w) {
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
    return crs;
}

int define_topology(UgridWriter &w, bool has_boundary) {
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

void define_coordinates(UgridWriter &w, const Dims &d, TopologyVars &t) {
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

void define_connectivity(UgridWriter &w, const Dims &d, TopologyVars &t) {
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

FieldVars define_fields(UgridWriter &w, const Mesh &mesh, const Dims &d) {
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
void define_global_attributes(UgridWriter &w, const Mesh &mesh, const UgridOptions &options,
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
void write_data(UgridWriter &w, const Mesh &mesh, const io::MeshTopology &topo, const Counts &c,
                const TopologyVars &t, const FieldVars &fv, const UgridOptions &options) {
    const std::size_t nn = c.nn, nf = c.nf, ne = c.ne, nb = c.nb;
    // Every variable is computed block by block while it is written (UgridWriter::in_blocks):
    // no table of the file is ever whole in memory. Beside the mesh and its topology, one helper
    // table: the edges' area terms (GeodesicFaceAreas, 24 bytes a node).
    auto centre = [&](std::size_t f) {
        return normalized(mesh.nodes[mesh.faces[f][0]] + mesh.nodes[mesh.faces[f][1]] +
                          mesh.nodes[mesh.faces[f][2]]);
    };
    auto midpoint = [&](std::size_t e) {
        const auto ends = topo.edge_nodes(e);
        return arc_midpoint(mesh.nodes[ends[0]], mesh.nodes[ends[1]]);
    };
    // The edges' geodesic problems (GeodesicFaceAreas), the writer's largest computation, run in
    // the background from here, while the variables before the face areas are computed and
    // compressed.
    std::atomic<bool> stop_solving{false};
    auto solve_edges = [&topo, &stop_solving] {
        return io::GeodesicFaceAreas(topo, &stop_solving);
    };
    std::future<io::GeodesicFaceAreas> areas_ahead = io::start_task(solve_edges);
    // A failure or a cancel before the areas are taken stops their computation: the future's
    // destructor waits for it (at 1e7 nodes, a minute).
    struct StopOnExit {
        std::atomic<bool> &stop;
        ~StopOnExit() { stop = true; }
    } stop_on_exit{stop_solving};
    w.put_rows<int, 3>(t.face_nodes, nf, [&](std::size_t f) {
        const auto &tri = mesh.faces[f];
        return std::array<int, 3>{int(tri[0]), int(tri[1]), int(tri[2])};
    });
    if (detail::after_partial_write)
        detail::after_partial_write(); // tests only (write_hooks.hpp)
    w.put_lonlat(t.coords[2], t.coords[3], nf, centre);
    w.put_lonlat(t.coords[4], t.coords[5], ne, midpoint);
    w.put_rows<int, 2>(t.edge_nodes, ne, [&](std::size_t e) { return topo.edge_nodes(e); });
    {
        w.put_lonlat(t.coords[0], t.coords[1], nn, [&](std::size_t i) { return mesh.nodes[i]; });
        const io::GeodesicFaceAreas areas = areas_ahead.get();
        if (options.face_areas_m2)
            options.face_areas_m2->assign(nf, 0.0);
        // Face edges, face neighbours and face areas a block of faces at a time (face_edges): no
        // face-to-edge table of the whole mesh (12 bytes a face) at the writer's peak.
        struct FaceRows {
            std::vector<std::int32_t> edges;
            std::vector<int> links;
            std::vector<double> area;
        };
        w.in_blocks<FaceRows>(
            nf, [&](std::size_t first, std::size_t count, FaceRows &b, UgridWriter::Block &block) {
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
                                          std::vector<int> &tags, UgridWriter::Block &block) {
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
    const io::MeshTopology topo = io::build_topology(mesh);
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
    UgridWriter w(nc, out.temp_path(), path, !options.classic, options.progress);

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

/// The UGRID row of the writers table (writers.cpp).
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
    write_ugrid(mesh, path, ugrid);
}

} // namespace globemesh
