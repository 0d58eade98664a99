// triangulate_file(): the scattered-points job. OGR reads any point source (CSV with lon/lat
// columns, GeoPackage, shapefile, ...) and reprojects it to lon/lat; SphericalDelaunay
// triangulates the points; the solid triangles become a Mesh. Stages: "read", "sort" (the
// BRIO/Hilbert insertion order), "triangulate" (the insertions and the mesh).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "gdal_handles.hpp"
#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/pipeline.hpp"

namespace globemesh {

namespace {

using gdal::DatasetPtr;
using gdal::FeaturePtr;
using gdal::SrsPtr;
using gdal::TransformPtr;

std::string gdal_message() {
    std::string m = CPLGetLastErrorMsg();
    return m.empty() ? "" : " (" + m + ")";
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

struct PointSource {
    std::vector<Vec3> points;
    std::string layer;
};

// Appends the point(s) of g (a point or a multipoint, possibly in a collection) in lon/lat,
// checking each coordinate. Throws DataError naming the file and the feature.
void collect_points(OGRGeometryH g, OGRCoordinateTransformationH to_lonlat,
                    const std::string &where, std::vector<Vec3> &out) {
    const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(g));
    if (type == wkbMultiPoint || type == wkbGeometryCollection) {
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
            collect_points(OGR_G_GetGeometryRef(g, i), to_lonlat, where, out);
        return;
    }
    if (type != wkbPoint)
        throw DataError(where + " is a " + OGRGeometryTypeToName(OGR_G_GetGeometryType(g)) +
                        ", not a point: give a layer of points");
    if (OGR_G_IsEmpty(g))
        throw DataError(where + " has an empty point: give every feature a lon/lat");
    double x = OGR_G_GetX(g, 0), y = OGR_G_GetY(g, 0), z = 0;
    if (!std::isfinite(x) || !std::isfinite(y))
        throw DataError(where + " has a non-finite coordinate: every point needs finite lon/lat");
    if (to_lonlat && !OCTTransform(to_lonlat, 1, &x, &y, &z))
        throw DataError(where + " cannot be transformed to lon/lat" + gdal_message());
    if (!std::isfinite(x) || !std::isfinite(y) || std::fabs(y) > 90.0)
        throw DataError(where + " has latitude " + std::to_string(y) + " (longitude " +
                        std::to_string(x) + "): latitudes lie in [-90, 90] degrees");
    out.push_back(lonlat_to_vec(x, y));
}

PointSource read_point_source(const TriangulateOptions &options, const Progress &progress) {
    const std::string &path = options.points;
    GDALAllRegister();
    gdal::QuietErrors quiet;
    // CSV: take lon/lat columns as the geometry and drop them from the attributes (other drivers
    // ignore these open options).
    const char *open_options[] = {"X_POSSIBLE_NAMES=lon*,long*,x", "Y_POSSIBLE_NAMES=lat*,y",
                                  "KEEP_GEOM_COLUMNS=NO", nullptr};
    const bool is_csv = path.size() >= 4 && CPLGetExtension(path.c_str()) != nullptr &&
                        EQUAL(CPLGetExtension(path.c_str()), "csv");
    DatasetPtr ds(GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr,
                             is_csv ? open_options : nullptr, nullptr));
    if (!ds)
        throw IoError("POINTS " + path + ": cannot open as a vector data set" + gdal_message() +
                      "; " + gdal::open_advice(path));
    OGRLayerH layer = nullptr;
    if (!options.layer.empty()) {
        layer = GDALDatasetGetLayerByName(ds.get(), options.layer.c_str());
        if (!layer)
            throw DataError("POINTS " + path + ": no layer named '" + options.layer +
                            "'; see ogrinfo " + path);
    } else {
        if (GDALDatasetGetLayerCount(ds.get()) == 0)
            throw DataError("POINTS " + path + ": has no layer");
        layer = GDALDatasetGetLayer(ds.get(), 0);
    }
    PointSource src;
    src.layer = OGR_L_GetName(layer);
    const std::string at = "POINTS " + path + " layer '" + src.layer + "'";

    TransformPtr to_lonlat;
    if (OGRSpatialReferenceH layer_srs = OGR_L_GetSpatialRef(layer)) {
        SrsPtr source(OSRClone(layer_srs));
        SrsPtr wgs84(OSRNewSpatialReference(nullptr));
        OSRImportFromEPSG(wgs84.get(), 4326);
        OSRSetAxisMappingStrategy(source.get(), OAMS_TRADITIONAL_GIS_ORDER);
        OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
        // A geographic CRS on the WGS84 datum (or close to it) needs no transformation.
        if (!(OSRIsGeographic(source.get()) && OSRIsSame(source.get(), wgs84.get()))) {
            to_lonlat.reset(OCTNewCoordinateTransformation(source.get(), wgs84.get()));
            if (!to_lonlat)
                throw DataError(at + ": its CRS cannot be transformed to lon/lat" + gdal_message());
        }
    } else if (!EQUAL(GDALGetDriverShortName(GDALGetDatasetDriver(ds.get())), "CSV")) {
        throw DataError(
            at +
            " declares no CRS: add one (e.g. ogr2ogr -a_srs EPSG:4326) or give a CSV of lon/lat");
    }

    const GIntBig expected = OGR_L_GetFeatureCount(layer, FALSE);
    if (expected > 0)
        src.points.reserve(static_cast<std::size_t>(expected));
    OGR_L_ResetReading(layer);
    std::size_t features = 0;
    for (FeaturePtr f(OGR_L_GetNextFeature(layer)); f; f.reset(OGR_L_GetNextFeature(layer))) {
        const std::string where = at + " feature " + std::to_string(OGR_F_GetFID(f.get()));
        OGRGeometryH g = OGR_F_GetGeometryRef(f.get());
        if (!g)
            throw DataError(where + " has no point (a non-numeric, empty or non-finite lon/lat?)");
        collect_points(g, to_lonlat.get(), where, src.points);
        if (++features % 65536 == 0 && expected > 0)
            report(progress, std::min(1.0, double(features) / double(expected)), "read");
    }
    if (CPLGetLastErrorType() == CE_Failure)
        throw IoError("POINTS " + path + ": reading failed" + gdal_message());
    if (src.points.empty())
        throw DataError(at + " has no points");
    return src;
}

} // namespace

Mesh triangulate_points(std::vector<Vec3> points, const TriangulateOptions &options,
                        const Progress &progress, StageTimings *timings) {
    // The points' name in messages: the source file, or what the caller passed.
    const std::string what = options.points.empty() ? "the points" : "POINTS " + options.points;
    const std::size_t n = points.size();
    report(progress, 0.0, "sort");
    auto t0 = std::chrono::steady_clock::now();
    if (n >= 0x80000000u)
        throw DataError(what + ": more than 2^31 points");
    std::vector<std::uint32_t> order = SphericalDelaunay::insertion_order(points, options.seed);
    if (timings)
        timings->add("sort", seconds_since(t0));

    report(progress, 1.0 / 7, "triangulate");
    t0 = std::chrono::steady_clock::now();
    SphericalDelaunay dt({options.merge_tolerance_rad, options.seed});
    std::vector<VertexId> vertex_of;
    try {
        vertex_of = dt.insert_points(std::move(points), std::move(order));
    } catch (const DataError &e) {
        throw DataError(what + ": " + e.what());
    }
    report(progress, 6.0 / 7, "triangulate");

    // Nodes: the vertices of solid triangles, numbered in the order of the first input point that
    // became each (so node order follows the input, whatever the insertion order).
    std::vector<std::uint8_t> in_mesh(dt.vertex_count(), 0);
    std::size_t solid = 0;
    std::vector<std::uint8_t> is_solid(dt.triangle_slots(), 0);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.is_solid(t)) {
            is_solid[t] = 1;
            ++solid;
            for (int i = 0; i < 3; ++i)
                in_mesh[dt.vertex(t, i)] = 1;
        }
    Mesh mesh;
    std::vector<NodeIndex> node_of(dt.vertex_count(), 0xffffffffu);
    for (VertexId v : vertex_of)
        if (in_mesh[v] && node_of[v] == 0xffffffffu) {
            node_of[v] = static_cast<NodeIndex>(mesh.nodes.size());
            mesh.nodes.push_back(dt.point(v));
        }
    mesh.faces.reserve(solid);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!is_solid[t])
            continue;
        mesh.faces.push_back(
            {node_of[dt.vertex(t, 0)], node_of[dt.vertex(t, 1)], node_of[dt.vertex(t, 2)]});
        // An edge whose other side is a ghost triangle bounds the solid region (a hemisphere set).
        for (int i = 0; i < 3; ++i)
            if (!is_solid[dt.neighbour(t, i)]) {
                const HalfEdge h = half_edge(t, i);
                mesh.boundary.push_back(
                    {node_of[dt.origin(h)], node_of[dt.destination(h)], EdgeTag::open});
            }
    }
    if (mesh.faces.empty())
        throw DataError(what + ": the points give no triangle (all on one circle?)");
    mesh.attributes.emplace_back("input_point_count", std::to_string(n));
    mesh.attributes.emplace_back("merged_point_count", std::to_string(dt.merged_count()));
    if (timings)
        timings->add("triangulate", seconds_since(t0));
    report(progress, 1.0, "triangulate");
    return mesh;
}

Mesh triangulate_file(const TriangulateOptions &options, const Progress &progress,
                      StageTimings *timings) {
    auto t0 = std::chrono::steady_clock::now();
    report(progress, 0.0, "read");
    PointSource src = read_point_source(options, sub_progress(progress, 0.0, 0.3));
    if (timings)
        timings->add_input("read", seconds_since(t0));
    Mesh mesh = triangulate_points(std::move(src.points), options, sub_progress(progress, 0.3, 1.0),
                                   timings);
    const std::pair<std::string, std::string> source[] = {{"source_points", options.points},
                                                          {"source_layer", src.layer}};
    mesh.attributes.insert(mesh.attributes.begin(), std::begin(source), std::end(source));
    return mesh;
}

} // namespace globemesh
