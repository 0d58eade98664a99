// GeoPackage writer: see globemesh/gpkg.hpp. GDAL's GPKG driver creates the file, its layers
// and small tables; the faces' and nodes' rows are written as SQLite pages (sqlite_pages.hpp,
// gpkg_rtree.hpp).
//
// Layers: faces (MultiPolygon, one feature per face, FID = face index + 1, cut at +-180 and with
// pole corners split, see face_geometry.hpp), nodes (Point, every node field), boundary (runs of
// equally tagged boundary edges as MultiLineString), mesh_info (key/value attributes), and
// layer_styles (QGIS's own table) holding a graduated-by-quality default style for faces.
// No polygon or line part is wider than 180 degrees of longitude (gpkg_geometry.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include <ogrsf_frmts.h>

#include "face_area.hpp"
#include "face_geometry.hpp"
#include "gdal_util.hpp"
#include "globemesh/error.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "gpkg_geometry.hpp"
#include "gpkg_rtree.hpp"
#include "mesh_topology.hpp"
#include "ordered_blocks.hpp"
#include "sqlite_pages.hpp"
#include "write_hooks.hpp"

#ifndef GLOBEMESH_VERSION
#define GLOBEMESH_VERSION "unknown"
#endif

namespace globemesh {

namespace {

struct QualityClass {
    double lower, upper;
    const char *colour; ///< "r,g,b,a" as QGIS writes colours
    const char *label;
};
constexpr QualityClass quality_classes[] = {
    {0.0, 0.3, "215,25,28,255", "poor (below 0.3)"},
    {0.3, 0.5, "253,174,97,255", "0.3 - 0.5"},
    {0.5, 0.7, "255,255,191,255", "0.5 - 0.7"},
    {0.7, 0.9, "166,217,106,255", "0.7 - 0.9"},
    {0.9, 1.000001, "26,150,65,255", "good (0.9 and above)"}};

/// A QGIS 3 graduated renderer on "quality" (the style QGIS itself writes, trimmed to symbology).
std::string faces_style_qml() {
    std::ostringstream q;
    q << "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n"
      << "<qgis version=\"3.22.16-Białowieża\" styleCategories=\"Symbology\">\n"
      << " <renderer-v2 type=\"graduatedSymbol\" attr=\"quality\" "
         "graduatedMethod=\"GraduatedColor\" "
         "symbollevels=\"0\" enableorderby=\"0\" forceraster=\"0\">\n  <ranges>\n";
    int i = 0;
    for (const auto &c : quality_classes)
        q << "   <range render=\"true\" symbol=\"" << i++ << "\" lower=\"" << c.lower
          << "\" upper=\"" << c.upper << "\" label=\"" << c.label << "\"/>\n";
    q << "  </ranges>\n  <symbols>\n";
    i = 0;
    for (const auto &c : quality_classes)
        q << "   <symbol type=\"fill\" name=\"" << i++
          << "\" alpha=\"1\" clip_to_extent=\"1\" force_rhr=\"0\">\n"
          << "    <layer class=\"SimpleFill\" enabled=\"1\" pass=\"0\" locked=\"0\">\n"
          << "     <Option type=\"Map\">\n"
          << "      <Option type=\"QString\" name=\"color\" value=\"" << c.colour << "\"/>\n"
          << "      <Option type=\"QString\" name=\"joinstyle\" value=\"bevel\"/>\n"
          << "      <Option type=\"QString\" name=\"outline_color\" value=\"60,60,60,255\"/>\n"
          << "      <Option type=\"QString\" name=\"outline_style\" value=\"solid\"/>\n"
          << "      <Option type=\"QString\" name=\"outline_width\" value=\"0.06\"/>\n"
          << "      <Option type=\"QString\" name=\"outline_width_unit\" value=\"MM\"/>\n"
          << "      <Option type=\"QString\" name=\"style\" value=\"solid\"/>\n"
          << "     </Option>\n    </layer>\n   </symbol>\n";
    q << "  </symbols>\n  <classificationMethod id=\"Pretty\">\n   <symmetricMode enabled=\"0\" "
         "symmetrypoint=\"0\" astride=\"0\"/>\n   <labelFormat format=\"%1 - %2\" "
         "trimtrailingzeroes=\"1\" "
         "labelprecision=\"2\"/>\n  </classificationMethod>\n  <rotation/>\n  <sizescale/>\n"
      << " </renderer-v2>\n <blendMode>0</blendMode>\n <featureBlendMode>0</featureBlendMode>\n"
      << " <layerGeometryType>2</layerGeometryType>\n</qgis>\n";
    return q.str();
}

class GpkgWriter {
public:
    GpkgWriter(GDALDataset *ds, const std::filesystem::path &path) : ds_(ds), path_(path) {
        srs_.importFromEPSG(4326);
        srs_.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    }
    [[noreturn]] void fail(const std::string &step) const {
        throw IoError("GeoPackage output " + path_.string() + ": " + step + ": " +
                      io::last_gdal_error() + OutputFile::full_disk_note(path_));
    }
    /// A layer; a spatial one without GDAL's spatial index (gpkg_rtree.hpp adds it in bulk).
    OGRLayer *layer(const char *name, OGRwkbGeometryType type, const char *description,
                    const char *fid = "FID=fid") {
        const std::string desc = std::string("DESCRIPTION=") + description;
        const char *options[] = {fid, desc.c_str(), "SPATIAL_INDEX=NO", nullptr};
        OGRLayer *l = ds_->CreateLayer(name, type == wkbNone ? nullptr : &srs_, type,
                                       const_cast<char **>(options));
        if (!l)
            fail(std::string("creating layer ") + name);
        return l;
    }
    void field(OGRLayer *l, const char *name, OGRFieldType type,
               const char *default_value = nullptr) {
        OGRFieldDefn f(name, type);
        if (default_value)
            f.SetDefault(default_value);
        if (l->CreateField(&f) != OGRERR_NONE)
            fail(std::string("creating field ") + name);
    }
    void add(OGRLayer *l, OGRFeature &f) {
        if (l->CreateFeature(&f) != OGRERR_NONE)
            fail(std::string("writing a feature of ") + l->GetName());
    }
    /// The named layer's table and metadata rows, created now (GDAL creates them at the first
    /// feature or at close).
    void create_tables(const char *name) {
        OGRLayer *l = ds_->GetLayerByName(name);
        if (!l || l->SyncToDisk() != OGRERR_NONE)
            fail(std::string("creating layer ") + name);
    }
    void begin() {
        if (ds_->StartTransaction() != OGRERR_NONE)
            fail("starting a transaction");
        in_transaction_ = true;
    }
    void commit() {
        if (ds_->CommitTransaction() != OGRERR_NONE)
            fail("committing");
        in_transaction_ = false;
    }
    /// A transaction still open (the write failed or was cancelled) is rolled back before the
    /// dataset closes as it unwinds: GDAL would otherwise commit the rows written so far, to a
    /// file about to be deleted.
    ~GpkgWriter() {
        if (in_transaction_)
            ds_->RollbackTransaction();
    }
    GpkgWriter(const GpkgWriter &) = delete;
    GpkgWriter &operator=(const GpkgWriter &) = delete;

private:
    GDALDataset *ds_;
    bool in_transaction_ = false;
    const std::filesystem::path &path_;
    OGRSpatialReference srs_;
};

/// Boundary edges chained into loops, each loop split into runs of one tag.
struct BoundaryRun {
    std::vector<NodeIndex> nodes;
    int tag = 1;
    int loop = 0;
};

std::vector<BoundaryRun> boundary_runs(const io::MeshTopology &topo) {
    // Boundary edges are named here by their position b in topo.boundary_edges (ascending edge
    // index), the index of their tag in topo.boundary_tags.
    const std::size_t nb = topo.boundary_edges.size();
    auto nodes = [&](std::size_t b) {
        return topo.edge_nodes(std::size_t(topo.boundary_edges[b]));
    };
    std::map<std::int32_t, std::vector<std::size_t>> outgoing; // node -> boundary edges leaving it
    for (std::size_t b = 0; b < nb; ++b)
        outgoing[nodes(b)[0]].push_back(b);
    std::vector<char> used(nb, 0);
    std::vector<BoundaryRun> runs;
    int loop = 0;
    for (std::size_t start = 0; start < nb; ++start) {
        if (used[start])
            continue;
        std::vector<std::size_t> edges;
        for (std::size_t b = start; b < nb && !used[b];) {
            used[b] = 1;
            edges.push_back(b);
            std::size_t next = nb;
            for (auto cand : outgoing[nodes(b)[1]])
                if (!used[cand]) {
                    next = cand;
                    break;
                }
            b = next;
        }
        // Start at a change of tag, so a run never wraps round the start of the loop.
        const auto &tags = topo.boundary_tags;
        std::size_t first = 0;
        for (std::size_t i = 0; i < edges.size(); ++i)
            if (tags[edges[i]] != tags[edges[(i + edges.size() - 1) % edges.size()]]) {
                first = i;
                break;
            }
        std::rotate(edges.begin(), edges.begin() + std::ptrdiff_t(first), edges.end());
        for (std::size_t i = 0; i < edges.size(); ++i) {
            int tag = tags[edges[i]];
            if (i == 0 || tag != runs.back().tag || runs.back().loop != loop) {
                runs.push_back({{NodeIndex(nodes(edges[i])[0])}, tag, loop});
            }
            runs.back().nodes.push_back(NodeIndex(nodes(edges[i])[1]));
        }
        ++loop;
    }
    return runs;
}

/// Shares of the progress, as the writer's time splits at 1e6 nodes: the faces' rows, the
/// nodes', and the rest (the spatial indexes).
constexpr double face_share = 0.55, node_share = 0.1;

/// A geometry's box, for its layer's spatial index (gpkg_rtree.hpp).
io::RtreeBox box_of(const OGRGeometry &g) {
    OGREnvelope e;
    g.getEnvelope(&e);
    return io::rtree_box(e.MinX, e.MaxX, e.MinY, e.MaxY);
}

/// The faces layer and the node and face fields its features carry.
struct FacesLayer {
    const Field *depth = nullptr; ///< the nodes' depth, as the mean of each face's corners
    const Field *size = nullptr;  ///< the nodes' target_size, likewise
    std::vector<const Field *> face_fields; ///< the mesh's other face fields, as they are
    std::vector<std::string> columns;       ///< the table's, in order
};

FacesLayer define_faces_layer(GpkgWriter &w, const Mesh &mesh) {
    FacesLayer l;
    OGRLayer *faces =
        w.layer("faces", wkbMultiPolygon, "mesh triangles, cut at +-180 (one feature per face)");
    l.columns = {"fid", "geom", "face"};
    w.field(faces, "face", OFTInteger);
    auto real = [&](const std::string &name) {
        w.field(faces, name.c_str(), OFTReal);
        l.columns.push_back(name);
    };
    real("quality");
    real("area_km2");
    const Field *depth = l.depth = mesh.node_field("depth");
    const Field *size = l.size = mesh.node_field("target_size");
    if (depth)
        real("depth");
    if (size)
        real("target_size");
    for (const auto &f : mesh.face_fields)
        if (f.name != "quality" && f.name != "area" && f.name != "area_km2" && f.name != "face" &&
            !(depth && f.name == "depth") && !(size && f.name == "target_size") &&
            f.values.size() == mesh.faces.size()) {
            real(f.name);
            l.face_fields.push_back(&f);
        }
    return l;
}

/// The columns of a bulk layer: fid, geom, the integer `number`, then `reals`.
std::vector<std::string> bulk_columns(const char *number, const std::vector<std::string> &reals) {
    std::vector<std::string> columns = {"fid", "geom", number};
    columns.insert(columns.end(), reals.begin(), reals.end());
    return columns;
}

/// A block of rows made on any core (ordered_blocks.hpp): each row's record (sqlite_pages.hpp)
/// in `bytes` up to ends[r], its envelope and index box.
struct RowBlock {
    std::vector<unsigned char> bytes;
    std::vector<std::size_t> ends;
    std::vector<io::Envelope> envelopes;
    std::vector<io::RtreeBox> boxes;
    void clear() { bytes.clear(), ends.clear(), envelopes.clear(), boxes.clear(); }
};

/// What a worker reuses from row to row.
struct RowScratch {
    std::vector<unsigned char> blob;
    io::SqliteRecord record;
    std::vector<std::int32_t> edges;
};

/// A row of a bulk layer appended to `b`: fid (the rowid), the geometry blob in scratch.blob,
/// the feature's `number`, then `reals`.
void append_row(RowBlock &b, RowScratch &scratch, std::size_t number,
                const std::vector<double> &reals) {
    io::SqliteRecord &r = scratch.record;
    r.null(); // fid, the INTEGER PRIMARY KEY: the rowid itself
    r.blob(scratch.blob.data(), scratch.blob.size());
    r.integer(std::int64_t(number));
    for (double v : reals)
        r.real(v);
    r.append_to(b.bytes);
    b.ends.push_back(b.bytes.size());
    scratch.blob.clear();
}

/// A bulk layer's rows as they go into its table: their count and extent, and their boxes for
/// its index.
struct BulkLayer {
    io::TableLoader rows;
    std::vector<io::RtreeBox> &boxes;
    std::array<double, 4> extent = {
        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
        std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    std::int64_t count = 0;

    /// Adds a block's rows, the first with fid first + 1.
    void add(const RowBlock &b, std::size_t first) {
        std::size_t start = 0;
        for (std::size_t r = 0; r < b.ends.size(); ++r) {
            rows.add(std::int64_t(first + r) + 1, b.bytes.data() + start, b.ends[r] - start);
            const io::Envelope &e = b.envelopes[r];
            extent = {std::min(extent[0], e[0]), std::max(extent[1], e[1]),
                      std::min(extent[2], e[2]), std::max(extent[3], e[3])};
            start = b.ends[r];
        }
        count += std::int64_t(b.ends.size());
        boxes.insert(boxes.end(), b.boxes.begin(), b.boxes.end());
    }
};

/// The faces' rows into `layer`.
void write_faces(BulkLayer &layer, const FacesLayer &l, const Mesh &mesh,
                 const std::vector<LonLat> &lonlat, const io::MeshTopology &topo,
                 const GpkgOptions &options) {
    const Field *depth = l.depth, *size = l.size;
    const std::vector<const Field *> &face_fields = l.face_fields;
    // The face areas as the UGRID file has them: those write_ugrid gave, else computed face by
    // face as it does (face_area.hpp: the authalic sphere and a term per side).
    const std::vector<double> *given = options.face_areas_m2;
    if (given && given->size() != mesh.faces.size())
        given = nullptr;
    std::optional<io::GeodesicFaceAreas> areas;
    if (!given)
        areas.emplace(topo);
    layer.boxes.reserve(mesh.faces.size());
    // The rows (fields, geometry cut at +-180, box) are made a block at a time on every core,
    // and added in order from this thread (ordered_blocks.hpp).
    struct Scratch {
        RowScratch row;
        std::vector<double> reals;
    };
    constexpr std::size_t block_faces = 4096;
    io::compute_in_order<RowBlock, Scratch>(
        (mesh.faces.size() + block_faces - 1) / block_faces,
        [&](std::size_t k, RowBlock &b, Scratch &scratch) {
            const std::size_t first = k * block_faces,
                              last = std::min(mesh.faces.size(), first + block_faces);
            b.clear();
            std::vector<double> &reals = scratch.reals;
            for (std::size_t i = first; i < last; ++i) {
                const auto &t = mesh.faces[i];
                reals.clear();
                reals.push_back(
                    triangle_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]));
                double area_m2;
                if (given) {
                    area_m2 = (*given)[i];
                } else {
                    io::face_edges(topo, i, 1, scratch.row.edges);
                    area_m2 = areas->face_m2(i, scratch.row.edges.data());
                }
                reals.push_back(area_m2 * 1e-6);
                auto mean = [&](const Field *f) {
                    return (f->values[t[0]] + f->values[t[1]] + f->values[t[2]]) / 3.0;
                };
                if (depth)
                    reals.push_back(mean(depth));
                if (size)
                    reals.push_back(mean(size));
                for (const Field *f : face_fields)
                    reals.push_back(f->values[i]);
                const Vec3 v[3] = {mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]};
                const LonLat ll[3] = {lonlat[t[0]], lonlat[t[1]], lonlat[t[2]]};
                bool empty = false;
                const io::Envelope e = io::append_face(scratch.row.blob, v, ll, empty);
                append_row(b, scratch.row, i, reals);
                b.envelopes.push_back(e);
                // An empty geometry's box is OGR's envelope of it, all 0.
                b.boxes.push_back(empty ? io::rtree_box(0, 0, 0, 0)
                                        : io::rtree_box(e[0], e[1], e[2], e[3]));
            }
        },
        [&](std::size_t k, RowBlock &b) {
            if (k % 4 == 0)
                report(options.progress,
                       face_share * double(k * block_faces) / double(mesh.faces.size()),
                       "write_gpkg");
            layer.add(b, k * block_faces);
        });
    layer.rows.finish();
}

/// The nodes layer with every node field (the rows are write_nodes').
void define_nodes_layer(GpkgWriter &w, const Mesh &mesh) {
    OGRLayer *nodes = w.layer("nodes", wkbPoint, "mesh nodes with their fields");
    w.field(nodes, "node", OFTInteger);
    for (const auto &f : mesh.node_fields)
        if (f.name != "node")
            w.field(nodes, f.name.c_str(), OFTReal);
}

/// The node fields of the nodes layer (define_nodes_layer's).
std::vector<const Field *> node_fields(const Mesh &mesh) {
    std::vector<const Field *> fields;
    for (const auto &f : mesh.node_fields)
        if (f.name != "node")
            fields.push_back(&f);
    return fields;
}

/// The nodes table's columns.
std::vector<std::string> node_columns(const Mesh &mesh) {
    std::vector<std::string> reals;
    for (const Field *f : node_fields(mesh))
        reals.push_back(f->name);
    return bulk_columns("node", reals);
}

/// The nodes' rows into `layer`.
void write_nodes(BulkLayer &layer, const Mesh &mesh, const std::vector<LonLat> &lonlat,
                 const GpkgOptions &options) {
    const std::vector<const Field *> fields = node_fields(mesh);
    layer.boxes.reserve(mesh.nodes.size());
    struct Scratch {
        RowScratch row;
        std::vector<double> reals;
    };
    constexpr std::size_t block_nodes = 16384;
    io::compute_in_order<RowBlock, Scratch>(
        (mesh.nodes.size() + block_nodes - 1) / block_nodes,
        [&](std::size_t k, RowBlock &b, Scratch &scratch) {
            const std::size_t first = k * block_nodes,
                              last = std::min(mesh.nodes.size(), first + block_nodes);
            b.clear();
            for (std::size_t i = first; i < last; ++i) {
                scratch.reals.clear();
                for (const Field *f : fields) // NULL (as NaN) where a field has no value
                    scratch.reals.push_back(f->values.size() == mesh.nodes.size()
                                                ? f->values[i]
                                                : std::numeric_limits<double>::quiet_NaN());
                const LonLat p = lonlat[i];
                io::append_point(scratch.row.blob, p.lon, p.lat);
                append_row(b, scratch.row, i, scratch.reals);
                b.envelopes.push_back({p.lon, p.lon, p.lat, p.lat});
                b.boxes.push_back(io::rtree_box(p.lon, p.lon, p.lat, p.lat));
            }
        },
        [&](std::size_t k, RowBlock &b) {
            report(options.progress,
                   face_share + node_share * double(k * block_nodes) / double(mesh.nodes.size()),
                   "write_gpkg");
            layer.add(b, k * block_nodes);
        });
    layer.rows.finish();
}

/// The boundary layer, one feature per run, and its boxes into `run_boxes`; runs is not empty.
void write_boundary(GpkgWriter &w, const Mesh &mesh, const std::vector<BoundaryRun> &runs,
                    std::vector<io::RtreeBox> &run_boxes) {
    OGRLayer *boundary =
        w.layer("boundary", wkbMultiLineString, "mesh boundary, runs of coast or open edges");
    w.field(boundary, "tag", OFTString);
    w.field(boundary, "tag_code", OFTInteger);
    w.field(boundary, "loop", OFTInteger);
    w.field(boundary, "edges", OFTInteger);
    w.field(boundary, "length_km", OFTReal);
    for (const auto &run : runs) {
        OGRFeature feature(boundary->GetLayerDefn());
        feature.SetFID(GIntBig(run_boxes.size()) + 1);
        feature.SetField("tag", run.tag == int(EdgeTag::open) ? "open" : "coast");
        feature.SetField("tag_code", run.tag);
        feature.SetField("loop", run.loop);
        feature.SetField("edges", int(run.nodes.size() - 1));
        double km = 0;
        std::vector<Vec3> points;
        for (std::size_t i = 0; i < run.nodes.size(); ++i) {
            points.push_back(mesh.nodes[run.nodes[i]]);
            if (i)
                km += arc_km(points[i - 1], points[i]);
        }
        feature.SetField("length_km", km);
        auto *multi = new OGRMultiLineString();
        for (const auto &cut : io::polyline_parts(points))
            for (const auto &part : io::narrow_lines(cut)) {
                auto *line = new OGRLineString();
                for (const auto &p : part)
                    line->addPoint(p[0], p[1]);
                multi->addGeometryDirectly(line);
            }
        run_boxes.push_back(box_of(*multi));
        feature.SetGeometryDirectly(multi);
        w.add(boundary, feature);
    }
}

/// The mesh_info table: provenance and summary statistics, then the mesh's run metadata.
void write_mesh_info(GpkgWriter &w, const Mesh &mesh, const MeshStats &stats) {
    OGRLayer *info = w.layer("mesh_info", wkbNone, "run metadata and summary statistics");
    w.field(info, "key", OFTString);
    w.field(info, "value", OFTString);
    std::vector<std::pair<std::string, std::string>> rows = {
        {"source", std::string("globemesh ") + GLOBEMESH_VERSION},
        {"node_count", std::to_string(stats.nodes)},
        {"face_count", std::to_string(stats.faces)},
        {"edge_count", std::to_string(stats.edges)},
        {"boundary_edge_count", std::to_string(stats.boundary_edges)},
        {"boundary_loop_count", std::to_string(stats.boundary_loops)},
        {"quality_min", std::to_string(stats.quality_min)},
        {"quality_mean", std::to_string(stats.quality_mean)},
        {"quality_fraction_above_0_8", std::to_string(stats.quality_above_0_8)},
        {"edge_length_km_min", std::to_string(stats.edge_km_min)},
        {"edge_length_km_mean", std::to_string(stats.edge_km_mean)},
        {"edge_length_km_max", std::to_string(stats.edge_km_max)}};
    rows.insert(rows.end(), mesh.attributes.begin(), mesh.attributes.end());
    for (const auto &[key, value] : rows) {
        OGRFeature feature(info->GetLayerDefn());
        feature.SetField("key", key.c_str());
        feature.SetField("value", value.c_str());
        w.add(info, feature);
    }
}

/// layer_styles, in the schema QGIS creates and reads (QgsOgrProviderUtils / saveStyle), with
/// the faces' default style.
void write_layer_styles(GpkgWriter &w) {
    OGRLayer *styles = w.layer("layer_styles", wkbNone, "QGIS layer styles", "FID=id");
    for (const char *name : {"f_table_catalog", "f_table_schema", "f_table_name",
                             "f_geometry_column", "styleName", "styleQML", "styleSLD"})
        w.field(styles, name, OFTString);
    {
        OGRFieldDefn f("useAsDefault", OFTInteger);
        f.SetSubType(OFSTBoolean);
        if (styles->CreateField(&f) != OGRERR_NONE)
            w.fail("creating field useAsDefault");
    }
    for (const char *name : {"description", "owner", "ui"})
        w.field(styles, name, OFTString);
    w.field(styles, "update_time", OFTDateTime, "CURRENT_TIMESTAMP");
    OGRFeature style(styles->GetLayerDefn());
    style.SetField("f_table_catalog", "");
    style.SetField("f_table_schema", "");
    style.SetField("f_table_name", "faces");
    style.SetField("f_geometry_column", "geom");
    style.SetField("styleName", "faces by quality");
    style.SetField("styleQML", faces_style_qml().c_str());
    style.SetField("styleSLD", "");
    style.SetField("useAsDefault", 1);
    style.SetField(
        "description",
        "globemesh default: faces coloured by quality (2*sqrt(3)*inradius/longest edge)");
    style.SetField("owner", "");
    style.SetField("ui", "");
    w.add(styles, style);
}

/// GDAL's part of the file, created at `file` and closed: every layer and its fields, the faces
/// and nodes without rows (write_faces and write_nodes add them in bulk), the boundary (its
/// boxes into `run_boxes`; no layer for a closed mesh: QGIS treats an empty layer as a broken
/// one), mesh_info and layer_styles.
FacesLayer define_gdal_layers(const Mesh &mesh, const std::filesystem::path &path,
                              const std::filesystem::path &file,
                              const std::vector<BoundaryRun> &runs, const MeshStats &stats,
                              std::vector<io::RtreeBox> &run_boxes) {
    GDALAllRegister();
    io::QuietGdalErrors quiet;
    GDALDriver *driver = GetGDALDriverManager()->GetDriverByName("GPKG");
    if (!driver)
        throw IoError("GeoPackage output " + path.string() + ": GDAL has no GPKG driver");
    io::GdalDatasetPtr ds(driver->Create(file.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!ds)
        throw IoError("GeoPackage output " + path.string() + ": cannot create (" +
                      io::last_gdal_error() + ")" + OutputFile::full_disk_note(path));
    FacesLayer faces;
    {
        // Destroyed before the dataset closes: it rolls back a transaction left open.
        GpkgWriter w(ds.get(), path);
        w.begin();
        faces = define_faces_layer(w, mesh);
        define_nodes_layer(w, mesh);
        // Their tables now, not at close (GDAL defers an empty layer's): the layers' order.
        w.create_tables("faces"), w.create_tables("nodes");
        if (!runs.empty())
            write_boundary(w, mesh, runs, run_boxes);
        write_mesh_info(w, mesh, stats);
        write_layer_styles(w);
        w.commit();
    }
    if (!io::close_dataset(ds))
        throw IoError("GeoPackage output " + path.string() + ": closing failed: " +
                      io::last_gdal_error() + OutputFile::full_disk_note(path));
    return faces;
}

} // namespace

void write_gpkg(const Mesh &mesh, const std::filesystem::path &path, const GpkgOptions &options) {
    if (mesh.faces.empty())
        throw DataError("mesh: no faces to write to " + path.string());
    OutputFile out(path, options.overwrite, "GeoPackage output");
    // The topology (about 50 bytes a node) serves the statistics, the boundary's runs and the
    // faces' areas and edges, and goes once the faces are written (write_outputs lets the last
    // writer hold it alone): held to the end, it made the
    // spatial indexes' step the process's peak at 20 km (242.7 MiB, 218.5 without).
    std::shared_ptr<const io::MeshTopology> topo = io::topology_of(mesh);
    const MeshStats stats = options.stats ? *options.stats : io::compute_stats(mesh, *topo);
    const std::vector<BoundaryRun> runs = boundary_runs(*topo);

    // Each spatial layer's feature boxes, for its index (gpkg_rtree.hpp).
    std::vector<io::RtreeLayer> indexes = {
        {"faces", "geom", {}}, {"nodes", "geom", {}}, {"boundary", "geom", {}}};
    const FacesLayer faces =
        define_gdal_layers(mesh, path, out.temp_path(), runs, stats, indexes[2].boxes);
    if (runs.empty()) // no boundary layer (closed mesh)
        indexes.pop_back();
    // SQLite creates the indexes' tables and finds where each bulk table's pages go; then the
    // rows are written as pages (sqlite_pages.hpp), with no connection open; then SQLite writes
    // what GDAL keeps of the rows. A failure or a cancel anywhere before the last commit leaves
    // a file that OutputFile deletes.
    std::uint32_t face_root = 0, node_root = 0;
    std::vector<io::RtreeTables> tables;
    {
        io::GpkgSqlite db(out.temp_path(), path);
        face_root = io::table_root(db, "faces", faces.columns);
        node_root = io::table_root(db, "nodes", node_columns(mesh));
        for (const io::RtreeLayer &layer : indexes)
            tables.push_back(io::create_rtree_index(db, layer.table, layer.column));
        db.commit();
    }
    io::SqlitePages pages(out.temp_path(), "GeoPackage output " + path.string(), path);
    BulkLayer face_rows{io::TableLoader(pages, face_root), indexes[0].boxes};
    // Each node's lon/lat, once (a face's corners are shared by six faces).
    std::vector<LonLat> lonlat(mesh.nodes.size());
    io::for_each_range(mesh.nodes.size(), [&](std::size_t from, std::size_t to) {
        for (std::size_t i = from; i < to; ++i)
            lonlat[i] = vec_to_lonlat(mesh.nodes[i]);
    });
    write_faces(face_rows, faces, mesh, lonlat, *topo, options);
    if (options.face_areas_m2)
        std::vector<double>().swap(*options.face_areas_m2); // not needed any more
    topo.reset(); // freed here unless an earlier stage still shares it (SharedTopology)
    if (detail::after_partial_write)
        detail::after_partial_write(); // tests only (write_hooks.hpp)
    BulkLayer node_rows{io::TableLoader(pages, node_root), indexes[1].boxes};
    write_nodes(node_rows, mesh, lonlat, options);
    io::write_rtree_indexes(pages, indexes, tables,
                            sub_progress(options.progress, face_share + node_share, 1.0));
    pages.finish();
    io::GpkgSqlite db(out.temp_path(), path);
    io::finish_bulk_layer(db, "faces", face_rows.count, face_rows.extent);
    io::finish_bulk_layer(db, "nodes", node_rows.count, node_rows.extent);
    db.commit();
    report(options.progress, 1.0, "write_gpkg");
    out.commit();
}

/// The GPKG row of the writers table (writers.cpp).
void write_as_gpkg(const Mesh &mesh, const std::filesystem::path &path,
                   const WriteOptions &options) {
    GpkgOptions gpkg;
    gpkg.overwrite = options.overwrite;
    gpkg.stats = options.stats;
    gpkg.face_areas_m2 = options.face_areas_m2;
    gpkg.progress = options.progress;
    write_gpkg(mesh, path, gpkg);
}

} // namespace globemesh
