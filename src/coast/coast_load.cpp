// Stage 1 of the coast: OGR reading, reprojection, GEOS cleaning and clipping, and the ocean's
// rings on the sphere (antimeridian stitching, pole closures), at full resolution.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <array>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <geos_c.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "coast_internal.hpp"
#include "gdal_handles.hpp"
#include "geos_interrupt.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"

namespace globemesh {
namespace {

using coast_detail::find_conflicts;

// ----------------------------------------------------------------------------- RAII owners

using gdal::DatasetPtr;
using gdal::FeaturePtr;
using gdal::SrsPtr;
using gdal::TransformPtr;
using OgrGeometryPtr = gdal::GeometryPtr; // GeomPtr below is the GEOS owner

/// A GEOS context whose error handler keeps the last message.
class Geos {
public:
    Geos() : h_(GEOS_init_r()) {
        GEOSContext_setErrorMessageHandler_r(h_, &Geos::on_error, this);
    }
    ~Geos() { GEOS_finish_r(h_); }
    Geos(const Geos&) = delete;
    Geos& operator=(const Geos&) = delete;
    GEOSContextHandle_t get() const { return h_; }
    const std::string& message() const { return message_; }

private:
    static void on_error(const char* message, void* self) {
        static_cast<Geos*>(self)->message_ = message ? message : "";
    }
    GEOSContextHandle_t h_;
    std::string message_;
};

struct GeomDeleter {
    GEOSContextHandle_t ctx;
    void operator()(GEOSGeometry* g) const {
        if (g) GEOSGeom_destroy_r(ctx, g);
    }
};
using GeomPtr = std::unique_ptr<GEOSGeometry, GeomDeleter>;

struct PreparedDeleter {
    GEOSContextHandle_t ctx;
    void operator()(const GEOSPreparedGeometry* g) const {
        if (g) GEOSPreparedGeom_destroy_r(ctx, g);
    }
};
using PreparedPtr = std::unique_ptr<const GEOSPreparedGeometry, PreparedDeleter>;

GeomPtr own(Geos& geos, GEOSGeometry* g, const char* what) {
    GeomPtr owned(g, GeomDeleter{geos.get()});
    coast::GeosInterrupt::poll(); // Cancelled once the run is (then g may be null: GEOS was interrupted)
    if (!g) throw DataError(std::string("coast: GEOS failed to ") + what + ": " + geos.message());
    return owned;
}

// ----------------------------------------------------------------------------- reading

using PointList = std::vector<LonLat>;

/// One polygon in lon/lat: shell first, then holes (each ring closed, first == last).
using PolygonRings = std::vector<PointList>;

struct Source {
    std::vector<PolygonRings> polygons;
    std::vector<PointList> lines;
    std::size_t points = 0;   ///< point geometries seen (ignored)
    std::size_t features = 0; ///< features read
    std::string layer;
};

constexpr double seam_snap_deg = 1e-9;
/// A vertex this close to +-180 (11 m at the equator) next to a vertex on it goes onto it too.
/// Natural Earth stores coordinates on a grid of 1/20480 degree, and a corner of a polygon cut
/// at the antimeridian can sit one step off it: Chukotka's western half at 1:50m ends at
/// -179.999951, leaving a 27 km wedge of "ocean" 2 m wide between the two halves (a face of
/// quality 1e-4 at 20 km).
constexpr double seam_notch_deg = 1e-4;
constexpr double pole_snap_deg = 2e-3;
constexpr double line_end_snap_deg = 1e-3;
constexpr double max_line_gap_deg = 0.5;
/// Rings enclosing less than this (planar lon/lat, 1e-14 deg2, about 1e-4 m2) are slivers.
constexpr double min_ring_area_deg2 = 1e-14;
/// The land is snap-rounded to a lon/lat grid of 2^-20 degree (0.11 m at the equator): near-
/// touches closer than about half a cell (an islet's vertex 5 cm from the mainland's edge)
/// become touches, spikes narrower collapse, and what stays apart is at least half a cell
/// apart. A power of two, so that +-180, +-90 and grid multiples are exact in binary.
constexpr double snap_grid_deg = 1.0 / (1 << 20);
/// A region's outline takes the land's vertices within 2^-16 degree (1.7 m), so that the same
/// coast reprojected or clipped in another CRS (a few micro-degrees off) leaves no slivers.
constexpr double outline_snap_deg = 1.0 / (1 << 16);

/// Moves onto the seam each vertex within seam_notch_deg of it whose neighbour along the ring
/// lies on it, on the same side (neighbours judged as they were before this pass).
void close_seam_notches(PointList& pts) {
    std::size_t n = pts.size();
    const bool closed = n > 1 && pts.front().lon == pts.back().lon && pts.front().lat == pts.back().lat;
    if (closed) --n;
    if (n < 3) return;
    const PointList was(pts.begin(), pts.begin() + static_cast<std::ptrdiff_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
        const double lon = was[i].lon;
        const double seam = lon > 0 ? 180.0 : -180.0;
        if (std::abs(lon) == 180.0 || std::abs(lon) <= 180.0 - seam_notch_deg) continue;
        const bool has_prev = closed || i > 0, has_next = closed || i + 1 < n;
        if ((has_prev && was[(i + n - 1) % n].lon == seam) || (has_next && was[(i + 1) % n].lon == seam))
            pts[i].lon = seam;
    }
    if (closed) pts.back() = pts.front();
}

/// Longitudes beyond this (degrees) are refused: no ring needs more than one wrap.
constexpr double max_abs_lon_deg = 540.0;

/// Snaps coordinates of one ring or line to the +-180 seam and the poles (see coast.hpp).
void snap_coordinates(PointList& pts, bool transformed) {
    for (auto& p : pts) {
        if (p.lat > 90.0 - pole_snap_deg) p.lat = 90.0;
        if (p.lat < -90.0 + pole_snap_deg) p.lat = -90.0;
    }
    if (!transformed) {
        for (auto& p : pts) {
            if (std::abs(p.lon - 180.0) < seam_snap_deg) p.lon = 180.0;
            if (std::abs(p.lon + 180.0) < seam_snap_deg) p.lon = -180.0;
        }
        close_seam_notches(pts);
        return;
    }
    // A projection's inverse may return either +180 or -180 on the seam: a run of vertices on
    // the seam takes the side of the vertex before it, up to a pole vertex (where a closure
    // such as Antarctica's crosses to the other side), and the side of the vertex after it
    // from there on.
    auto on_seam = [](const LonLat& p) { return std::abs(p.lon) > 180.0 - seam_snap_deg; };
    std::size_t n = pts.size();
    if (n && pts.front().lon == pts.back().lon && pts.front().lat == pts.back().lat) --n; // closed ring
    std::size_t anchor = n;
    for (std::size_t i = 0; i < n; ++i)
        if (!on_seam(pts[i])) anchor = i;
    if (anchor == n) {
        for (auto& p : pts) p.lon = p.lon > 0 ? 180.0 : -180.0;
        return;
    }
    auto side_of = [](const LonLat& p) { return p.lon >= 0 ? 180.0 : -180.0; };
    for (std::size_t k = 1; k <= n; ++k) {
        std::size_t i = (anchor + k) % n;
        if (!on_seam(pts[i])) continue;
        std::size_t end = k; // the run is k .. end-1 (offsets from anchor)
        while (end <= n && on_seam(pts[(anchor + end) % n])) ++end;
        double before = side_of(pts[(anchor + k - 1) % n]);
        double after = side_of(pts[(anchor + end) % n]);
        bool past_pole = false;
        for (std::size_t m = k; m < end; ++m) {
            auto& p = pts[(anchor + m) % n];
            p.lon = past_pole ? after : before;
            if (std::abs(p.lat) == 90.0) past_pole = true;
        }
        k = end;
    }
    if (n < pts.size()) pts.back() = pts.front();
    close_seam_notches(pts);
}

PointList read_points(OGRGeometryH g, bool transformed) {
    int n = OGR_G_GetPointCount(g);
    PointList pts(static_cast<std::size_t>(std::max(n, 0)));
    for (int i = 0; i < n; ++i) pts[i] = {OGR_G_GetX(g, i), OGR_G_GetY(g, i)};
    for (const auto& p : pts) {
        if (!std::isfinite(p.lon) || !std::isfinite(p.lat))
            throw DataError("coast: a vertex has a non-finite coordinate (failed reprojection?)");
        // A ring drawn across the antimeridian may reach past +-180 (lon 190, or [0, 360)), and
        // add_wrapped cuts it back once per 360 degrees: further out, the layer is not in degrees.
        if (std::abs(p.lon) > max_abs_lon_deg) {
            char text[160];
            std::snprintf(text, sizeof text, "coast: a vertex has longitude %.6g, beyond +-%.0f degrees: is the layer in "
                          "lon/lat? (--coast-srs names its CRS)", p.lon, max_abs_lon_deg);
            throw DataError(text);
        }
    }
    snap_coordinates(pts, transformed);
    return pts;
}

void collect_geometry(OGRGeometryH g, bool transformed, Source& out) {
    if (!g || OGR_G_IsEmpty(g)) return;
    OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
    if (OGR_GT_IsNonLinear(t)) {
        OgrGeometryPtr linear(OGR_G_GetLinearGeometry(g, 0, nullptr));
        collect_geometry(linear.get(), transformed, out);
        return;
    }
    switch (t) {
    case wkbPolygon: {
        PolygonRings poly;
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i) {
            PointList ring = read_points(OGR_G_GetGeometryRef(g, i), transformed);
            if (!ring.empty() && (ring.front().lon != ring.back().lon || ring.front().lat != ring.back().lat))
                ring.push_back(ring.front());
            if (ring.size() < 4) {
                if (i == 0) return; // degenerate shell: no polygon
                continue;
            }
            poly.push_back(std::move(ring));
        }
        if (!poly.empty()) out.polygons.push_back(std::move(poly));
        return;
    }
    case wkbLineString:
    case wkbLinearRing: {
        PointList line = read_points(g, transformed);
        if (line.size() >= 2) out.lines.push_back(std::move(line));
        return;
    }
    case wkbPoint:
    case wkbMultiPoint: ++out.points; return;
    default:
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
            collect_geometry(OGR_G_GetGeometryRef(g, i), transformed, out);
    }
}

/// Vertices of a geometry (all its parts and rings), as OGR holds them; curves count their
/// control points (a linearized curve has more, but curves are rare in coastlines).
std::uint64_t vertex_count(OGRGeometryH g) {
    if (!g) return 0;
    const int parts = OGR_G_GetGeometryCount(g);
    if (parts == 0) return static_cast<std::uint64_t>(std::max(OGR_G_GetPointCount(g), 0));
    std::uint64_t n = 0;
    for (int i = 0; i < parts; ++i) n += vertex_count(OGR_G_GetGeometryRef(g, i));
    return n;
}

/// Peak bytes per input vertex of load_coast: the lon/lat copy (16), GEOS's coordinate
/// sequences of the polygon, its valid and dissolved copies (3 x 24), the rings on the sphere
/// (24 + tags) and the containers' slack. Measured on ne_10m_land (0.41 M vertices): peak RSS
/// 129 MB for a whole 100 km run against 60 MB for a run refused before reading, 170 B/vertex
/// with the mesh included; rounded up.
constexpr std::uint64_t coast_bytes_per_vertex = 200;

bool is_polygon_type(OGRwkbGeometryType t) {
    t = wkbFlatten(t);
    return OGR_GT_IsSubClassOf(t, wkbCurvePolygon) || OGR_GT_IsSubClassOf(t, wkbMultiSurface);
}

bool is_area_or_line(OGRwkbGeometryType t) {
    t = wkbFlatten(t);
    return is_polygon_type(t) || OGR_GT_IsSubClassOf(t, wkbCurve) || OGR_GT_IsSubClassOf(t, wkbMultiCurve);
}

std::string layer_list(GDALDatasetH ds) {
    std::string list;
    for (int i = 0; i < GDALDatasetGetLayerCount(ds); ++i) {
        OGRLayerH l = GDALDatasetGetLayer(ds, i);
        if (!list.empty()) list += ", ";
        list += std::string(OGR_L_GetName(l)) + " (" + OGRGeometryTypeToName(OGR_L_GetGeomType(l)) + ")";
    }
    return list.empty() ? "none" : list;
}

/// Reads every polygon and line of a layer of `path` in lon/lat (WGS84, GIS axis order).
/// `what` names the option for messages (--coast or --region-file). With `near` (a --region
/// W,S,E,N) a polygon layer is read through OGR's spatial filter: only the features whose
/// envelope meets the box widened by 1% of its larger side (its latitude band when it crosses
/// +-180), in the layer's CRS; the land elsewhere plays no part in a region (region_rings cuts
/// it off), and a layer with an index (GeoPackage, a shapefile's .qix) is then not read whole.
/// A filter that leaves no feature is dropped (the errors below stay those of the whole layer).
/// Line layers are read whole: their lines close into land only together.
/// max_bytes (0: no limit): the layer's vertices are counted while they are read; once they
/// pass max_bytes / coast_bytes_per_vertex nothing more is kept (memory stays bounded by one
/// feature), the rest is only counted, and a DataError names the layer, the count and
/// --max-memory.
Source read_source(const std::string& path, const std::string& layer_name, const std::string& where,
                   const std::string& srs_override, const char* what, std::uint64_t max_bytes = 0,
                   const std::optional<std::array<double, 4>>& near = std::nullopt) {
    GDALAllRegister();
    gdal::QuietErrors quiet;
    DatasetPtr ds(GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
    if (!ds) {
        std::string msg = CPLGetLastErrorMsg();
        throw IoError(std::string(what) + " " + path + ": cannot open as a vector data set" +
                      (msg.empty() ? "" : " (" + msg + ")") + "; check the path and format");
    }
    GDALDatasetH h = ds.get();
    OGRLayerH layer = nullptr;
    if (!layer_name.empty()) {
        layer = GDALDatasetGetLayerByName(h, layer_name.c_str());
        if (!layer)
            throw DataError(std::string(what) + " " + path + ": no layer named '" + layer_name +
                            "'; layers: " + layer_list(h));
    } else {
        std::vector<OGRLayerH> candidates, unknown;
        for (int i = 0; i < GDALDatasetGetLayerCount(h); ++i) {
            OGRLayerH l = GDALDatasetGetLayer(h, i);
            OGRwkbGeometryType t = OGR_L_GetGeomType(l);
            if (is_area_or_line(t)) candidates.push_back(l);
            else if (wkbFlatten(t) == wkbUnknown || wkbFlatten(t) == wkbGeometryCollection) unknown.push_back(l);
        }
        if (candidates.empty()) candidates = unknown;
        if (candidates.size() != 1)
            throw DataError(std::string(what) + " " + path + ": " +
                            (candidates.empty() ? "no polygon or line layer"
                                                : std::string("several polygon or line layers, choose one with ") +
                                                      (std::string(what) == "--region-file" ? "--region-layer"
                                                                                            : "--coast-layer")) +
                            "; layers: " + layer_list(h));
        layer = candidates.front();
    }
    Source src;
    src.layer = OGR_L_GetName(layer);
    std::string where_msg = std::string(what) + " " + path + " layer '" + src.layer + "'";
    if (!where.empty() && OGR_L_SetAttributeFilter(layer, where.c_str()) != OGRERR_NONE)
        throw UsageError("--coast-where '" + where + "' is not a valid filter for " + where_msg + ": " +
                         CPLGetLastErrorMsg());

    // Coordinate reference system: the layer's, or the override; lon/lat WGS84 as target. A
    // local (engineering) CRS of unknown units, as a .prj with LOCAL_CS, counts as none.
    OGRSpatialReferenceH declared = OGR_L_GetSpatialRef(layer);
    if (declared && OSRIsLocal(declared)) declared = nullptr;
    SrsPtr source_srs;
    if (!srs_override.empty()) {
        source_srs.reset(OSRNewSpatialReference(nullptr));
        if (OSRSetFromUserInput(source_srs.get(), srs_override.c_str()) != OGRERR_NONE)
            throw UsageError("--coast-srs '" + srs_override + "' is not a CRS GDAL/PROJ understands");
        // A layer's own CRS is not overridden: degrees read as EPSG:3857 metres put the whole
        // coast within a kilometre of 0,0, and the mesh is silently an aqua-planet.
        if (declared) {
            // Both are read lon, lat (traditional order, below): only the CRS themselves are
            // compared, not their data axis mappings.
            const char* same_options[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", nullptr};
            if (!OSRIsSameEx(declared, source_srs.get(), same_options)) {
                const char* name = OSRGetName(declared);
                const char* auth = OSRGetAuthorityName(declared, nullptr);
                const char* code = OSRGetAuthorityCode(declared, nullptr);
                const std::string declared_name = std::string(name ? name : "a CRS") +
                                                  (auth && code ? std::string(" (") + auth + ":" + code + ")" : "");
                throw DataError(where_msg + " declares " + declared_name + ", not --coast-srs " + srs_override +
                                "; --coast-srs is for a layer that declares none (leave it out, or replace a "
                                "wrong CRS with ogr2ogr -a_srs)");
            }
        }
    } else if (declared) {
        source_srs.reset(OSRClone(declared));
    } else {
        throw DataError(where_msg + " declares no coordinate reference system" +
                        (OGR_L_GetSpatialRef(layer) ? " (only a local one, of unknown units)" : "") +
                        (std::string(what) == "--coast" ? "; give it with --coast-srs (e.g. EPSG:4326)"
                                                        : "; assign one, e.g. ogr2ogr -a_srs EPSG:4326"));
    }
    OSRSetAxisMappingStrategy(source_srs.get(), OAMS_TRADITIONAL_GIS_ORDER);
    SrsPtr wgs84(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
    TransformPtr transform;
    if (!OSRIsSame(source_srs.get(), wgs84.get())) {
        transform.reset(OCTNewCoordinateTransformation(source_srs.get(), wgs84.get()));
        if (!transform)
            throw DataError(where_msg + ": no transformation from its CRS to WGS84 lon/lat (" +
                            CPLGetLastErrorMsg() + ")");
    }

    bool filtered = false;
    if (near && is_polygon_type(OGR_L_GetGeomType(layer))) {
        auto [w, s, e, n] = *near;
        if (e <= w) w = -180, e = 180;
        const double pad = 0.01 * std::max(e - w, n - s);
        w = std::max(-180.0, w - pad), e = std::min(180.0, e + pad);
        s = std::max(-90.0, s - pad), n = std::min(90.0, n + pad);
        double x0 = w, y0 = s, x1 = e, y1 = n;
        bool ok = true;
        if (transform) {
            // The box in the layer's CRS (densified edges); a CRS that cannot take it: no filter.
            TransformPtr to_layer(OCTNewCoordinateTransformation(wgs84.get(), source_srs.get()));
            ok = to_layer && OCTTransformBounds(to_layer.get(), w, s, e, n, &x0, &y0, &x1, &y1, 21) && x0 < x1 &&
                 y0 < y1 && std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1);
        }
        if (ok) {
            OGR_L_SetSpatialFilterRect(layer, x0, y0, x1, y1);
            filtered = true;
        }
    }

    OGR_L_ResetReading(layer);
    CPLErrorReset();
    const std::uint64_t max_vertices = max_bytes / coast_bytes_per_vertex;
    std::uint64_t vertices = 0;
    bool too_many = false;
    for (;;) {
        FeaturePtr f(OGR_L_GetNextFeature(layer));
        if (!f && filtered && src.features == 0) {
            // Nothing near the region: read the whole layer, as without a region.
            OGR_L_SetSpatialFilter(layer, nullptr);
            OGR_L_ResetReading(layer);
            filtered = false;
            continue;
        }
        if (!f) break;
        ++src.features;
        OGRGeometryH g = OGR_F_GetGeometryRef(f.get());
        if (!g) continue;
        vertices += vertex_count(g);
        if (max_bytes > 0 && vertices > max_vertices && !too_many) {
            too_many = true; // from here on only count, to name the total
            src.polygons = {};
            src.lines = {};
        }
        if (too_many) continue;
        if (transform) {
            OgrGeometryPtr copy(OGR_G_Clone(g));
            if (OGR_G_Transform(copy.get(), transform.get()) != OGRERR_NONE)
                throw DataError(where_msg + ": feature " + std::to_string(OGR_F_GetFID(f.get())) +
                                " cannot be reprojected to lon/lat (" + CPLGetLastErrorMsg() + ")");
            collect_geometry(copy.get(), true, src);
        } else {
            collect_geometry(g, false, src);
        }
    }
    if (too_many)
        throw DataError(where_msg + " has " + std::to_string(vertices) + " vertices, more than the " +
                        std::to_string(max_vertices) + " that --max-memory " + memory_text(static_cast<double>(max_bytes)) +
                        " allows (about " + std::to_string(coast_bytes_per_vertex) +
                        " bytes each); raise --max-memory, or simplify the layer first (e.g. ogr2ogr -simplify 0.001)");
    if (src.features == 0 && !where.empty() && CPLGetLastErrorType() >= CE_Failure)
        throw UsageError("--coast-where '" + where + "' failed on " + where_msg + ": " + CPLGetLastErrorMsg());
    if (src.features == 0)
        throw DataError(where_msg + " has no features" + (where.empty() ? "" : " matching --coast-where") +
                        "; give a layer of land polygons or coastlines");
    if (src.polygons.empty() && src.lines.empty())
        throw DataError(where_msg + " holds no polygons or lines" +
                        (src.points ? " (only points)" : "") + "; give land polygons or coastlines");
    return src;
}

// ----------------------------------------------------------------------------- GEOS building

GeomPtr make_ring(Geos& geos, const PointList& pts) {
    std::vector<double> xy;
    xy.reserve(pts.size() * 2);
    for (const auto& p : pts) {
        xy.push_back(p.lon);
        xy.push_back(p.lat);
    }
    GEOSCoordSequence* seq = GEOSCoordSeq_copyFromBuffer_r(geos.get(), xy.data(), pts.size(), 0, 0);
    if (!seq) throw DataError("coast: GEOS cannot build a coordinate sequence: " + geos.message());
    return own(geos, GEOSGeom_createLinearRing_r(geos.get(), seq), "build a ring");
}

GeomPtr make_polygon(Geos& geos, const PolygonRings& rings) {
    GeomPtr shell = make_ring(geos, rings[0]);
    std::vector<GEOSGeometry*> holes;
    for (std::size_t i = 1; i < rings.size(); ++i) holes.push_back(make_ring(geos, rings[i]).release());
    return own(geos,
               GEOSGeom_createPolygon_r(geos.get(), shell.release(), holes.data(),
                                        static_cast<unsigned>(holes.size())),
               "build a polygon");
}

GeomPtr make_collection(Geos& geos, std::vector<GeomPtr>& parts) {
    std::vector<GEOSGeometry*> raw;
    for (auto& p : parts) raw.push_back(p.release());
    parts.clear();
    return own(geos,
               GEOSGeom_createCollection_r(geos.get(), GEOS_GEOMETRYCOLLECTION, raw.data(),
                                           static_cast<unsigned>(raw.size())),
               "build a collection");
}

/// MakeValid (STRUCTURE method, collapsed parts dropped): polygonal output only.
GeomPtr make_valid(Geos& geos, const GEOSGeometry* g) {
    GEOSMakeValidParams* params = GEOSMakeValidParams_create_r(geos.get());
    GEOSMakeValidParams_setMethod_r(geos.get(), params, GEOS_MAKE_VALID_STRUCTURE);
    GEOSMakeValidParams_setKeepCollapsed_r(geos.get(), params, 0);
    GEOSGeometry* out = GEOSMakeValidWithParams_r(geos.get(), g, params);
    GEOSMakeValidParams_destroy_r(geos.get(), params);
    return own(geos, out, "make a polygon valid");
}

void polygons_of(Geos& geos, const GEOSGeometry* g, std::vector<const GEOSGeometry*>& out) {
    int type = GEOSGeomTypeId_r(geos.get(), g);
    if (type == GEOS_POLYGON) {
        if (!GEOSisEmpty_r(geos.get(), g)) out.push_back(g);
    } else if (type == GEOS_MULTIPOLYGON || type == GEOS_GEOMETRYCOLLECTION) {
        for (int i = 0; i < GEOSGetNumGeometries_r(geos.get(), g); ++i)
            polygons_of(geos, GEOSGetGeometryN_r(geos.get(), g, i), out);
    }
}

PointList ring_points(Geos& geos, const GEOSGeometry* ring) {
    const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(geos.get(), ring);
    unsigned n = 0;
    GEOSCoordSeq_getSize_r(geos.get(), seq, &n);
    std::vector<double> xy(2 * n);
    if (n) GEOSCoordSeq_copyToBuffer_r(geos.get(), seq, xy.data(), 0, 0);
    PointList pts(n);
    for (unsigned i = 0; i < n; ++i) pts[i] = {xy[2 * i], xy[2 * i + 1]};
    return pts;
}

/// XOR of many polygonal geometries by pairwise reduction (even-odd fill of nested rings).
GeomPtr symmetric_difference_all(Geos& geos, std::vector<GeomPtr> parts) {
    if (parts.empty()) return own(geos, GEOSGeom_createEmptyPolygon_r(geos.get()), "build");
    while (parts.size() > 1) {
        std::vector<GeomPtr> next;
        for (std::size_t i = 0; i + 1 < parts.size(); i += 2)
            next.push_back(own(geos, GEOSSymDifference_r(geos.get(), parts[i].get(), parts[i + 1].get()),
                               "combine coastline rings"));
        if (parts.size() % 2) next.push_back(std::move(parts.back()));
        parts = std::move(next);
    }
    return std::move(parts.front());
}

/// Polygonizes closed coastline lines (GSHHG / OSM style). Lines are first merged at shared
/// ends; a line whose ends lie on the +-180 seam is closed along it (same side) or through the
/// nearer pole (opposite sides, as Antarctica). Land is the even-odd fill of all rings, so the
/// orientation of the lines does not matter and islands in lakes come out right.
GeomPtr polygonize_lines(Geos& geos, const std::vector<PointList>& lines, const std::string& where) {
    std::vector<GeomPtr> linestrings;
    for (const auto& l : lines) {
        std::vector<double> xy;
        for (const auto& p : l) {
            xy.push_back(p.lon);
            xy.push_back(p.lat);
        }
        GEOSCoordSequence* seq = GEOSCoordSeq_copyFromBuffer_r(geos.get(), xy.data(), l.size(), 0, 0);
        linestrings.push_back(own(geos, GEOSGeom_createLineString_r(geos.get(), seq), "build a line"));
    }
    GeomPtr all = make_collection(geos, linestrings);
    GeomPtr merged = own(geos, GEOSLineMerge_r(geos.get(), all.get()), "merge coastline lines");
    std::vector<GeomPtr> faces;
    int n = GEOSGetNumGeometries_r(geos.get(), merged.get());
    for (int i = 0; i < n; ++i) {
        PointList pts = ring_points(geos, GEOSGetGeometryN_r(geos.get(), merged.get(), i));
        if (pts.size() < 2) continue;
        LonLat a = pts.front(), b = pts.back();
        if (a.lon != b.lon || a.lat != b.lat) {
            // Open ends within 0.001 degree (110 m) of the seam, on either side, were cut there
            // (an end far beyond it, lon 199 of a line drawn in [0, 360), is not).
            for (LonLat* e : {&pts.front(), &pts.back()})
                if (std::abs(std::abs(e->lon) - 180.0) <= line_end_snap_deg) e->lon = e->lon > 0 ? 180.0 : -180.0;
            a = pts.front(), b = pts.back();
            bool a_seam = std::abs(a.lon) == 180.0, b_seam = std::abs(b.lon) == 180.0;
            double gap = std::hypot(a.lon - b.lon, a.lat - b.lat);
            if ((!a_seam || !b_seam) && gap <= max_line_gap_deg) {
                // a small gap in the data: close it straight
                a_seam = b_seam = true;
                b = a;
            }
            if (!a_seam || !b_seam)
                throw DataError(where + ": a coastline line from (" + std::to_string(a.lon) + ", " +
                                std::to_string(a.lat) + ") to (" + std::to_string(b.lon) + ", " +
                                std::to_string(b.lat) +
                                ") is not closed and does not end on the +-180 meridian; give "
                                "closed coastlines or land polygons");
            if (a.lon != b.lon) {
                double mean = 0;
                for (const auto& p : pts) mean += p.lat;
                double pole = mean < 0 ? -90.0 : 90.0;
                pts.push_back({b.lon, pole});
                pts.push_back({a.lon, pole});
            }
            pts.push_back(a);
        }
        if (pts.size() < 4) continue;
        GeomPtr ring = make_ring(geos, pts);
        GeomPtr poly = own(geos, GEOSGeom_createPolygon_r(geos.get(), ring.release(), nullptr, 0), "build");
        if (GEOSisValid_r(geos.get(), poly.get()) == 1) {
            faces.push_back(std::move(poly));
            continue;
        }
        // A self-intersecting line: node it and polygonize its faces.
        GeomPtr line = own(geos, GEOSBoundary_r(geos.get(), poly.get()), "take a boundary");
        GeomPtr noded = own(geos, GEOSUnaryUnion_r(geos.get(), line.get()), "node a line");
        const GEOSGeometry* input[] = {noded.get()};
        GeomPtr pieces = own(geos, GEOSPolygonize_r(geos.get(), input, 1), "polygonize a line");
        faces.push_back(own(geos, GEOSUnaryUnion_r(geos.get(), pieces.get()), "union faces"));
    }
    return symmetric_difference_all(geos, std::move(faces));
}


struct TreeDeleter {
    GEOSContextHandle_t ctx;
    void operator()(GEOSSTRtree* t) const {
        if (t) GEOSSTRtree_destroy_r(ctx, t);
    }
};

/// What snap rounding did to the land (CoastData reports it).
struct SnapCount {
    std::size_t joined = 0;  ///< polygons joined to another that they only came within 2 cells of
    std::size_t changed = 0; ///< rings gained or lost by dissolving and snap rounding, per batch
};

/// Dissolves valid polygonal parts into non-overlapping polygons, snap-rounded to a lon/lat
/// grid of `grid` degrees (GEOS's snap-rounding noder, OverlayNG): every vertex on the grid, and
/// every edge that passes through a vertex's grid cell noded at that vertex, so two rings that
/// came within about half a cell of each other touch there, and no vertex lies closer than half
/// a cell to an edge it is not on. Polygons that intersect (an STR tree's candidates confirmed by
/// GEOS's prepared test) or come within 2 cells of each other (near_pairs) are snap-rounded
/// together (one union), every other one alone: most coastline polygons are disjoint, and a
/// union of all of them costs seconds at 1:10m. Output order: each group where its first polygon
/// stands, the lone polygons with the batch they were rounded in (deterministic).
std::vector<GeomPtr> dissolve(Geos& geos, const std::vector<GeomPtr>& parts, double grid, SnapCount& count) {
    std::vector<GeomPtr> polys;
    for (const auto& part : parts) {
        std::vector<const GEOSGeometry*> ps;
        polygons_of(geos, part.get(), ps);
        for (const auto* p : ps) polys.push_back(own(geos, GEOSGeom_clone_r(geos.get(), p), "copy a polygon"));
    }
    std::size_t n = polys.size();
    std::vector<std::size_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](std::size_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    std::vector<char> near_only(n, 0); // joined by distance alone, not by intersection
    std::vector<int> vertices(n);
    for (std::size_t i = 0; i < n; ++i) vertices[i] = GEOSGetNumCoordinates_r(geos.get(), polys[i].get());
    {
        std::unique_ptr<GEOSSTRtree, TreeDeleter> tree(GEOSSTRtree_create_r(geos.get(), 10), TreeDeleter{geos.get()});
        for (std::size_t i = 0; i < n; ++i)
            GEOSSTRtree_insert_r(geos.get(), tree.get(), polys[i].get(), reinterpret_cast<void*>(i));
        std::vector<std::size_t> hits;
        auto collect = [](void* item, void* user) {
            static_cast<std::vector<std::size_t>*>(user)->push_back(reinterpret_cast<std::size_t>(item));
        };
        // Of each pair, the polygon with more vertices is the prepared one, kept for its other
        // pairs: a continent meets hundreds of islands' boxes, and GEOS builds the index of
        // the geometry tested against a prepared one anew on every call. Intersection is
        // symmetric: the groups are the same.
        std::vector<PreparedPtr> prepared;
        for (std::size_t i = 0; i < n; ++i) prepared.emplace_back(nullptr, PreparedDeleter{geos.get()});
        auto prepared_of = [&](std::size_t i) {
            if (!prepared[i]) prepared[i].reset(GEOSPrepare_r(geos.get(), polys[i].get()));
            return prepared[i].get();
        };
        for (std::size_t i = 0; i < n; ++i) {
            coast::GeosInterrupt::poll(); // a long run of short GEOS calls, none of which reports
            hits.clear();
            GEOSSTRtree_query_r(geos.get(), tree.get(), polys[i].get(), collect, &hits);
            std::sort(hits.begin(), hits.end());
            for (std::size_t j : hits) {
                if (j <= i || find(i) == find(j)) continue;
                const auto [big, small] = vertices[j] > vertices[i] ? std::pair{j, i} : std::pair{i, j};
                if (GEOSPreparedIntersects_r(geos.get(), prepared_of(big), polys[small].get()) == 1)
                    parent[find(j)] = find(i);
            }
            prepared[i].reset(); // its pairs are all done: later ones have both indices above i
        }
    }
    // Outlines within 2 cells of each other (near-touches) are snap-rounded together too.
    {
        std::vector<PolygonRings> outlines(n);
        for (std::size_t i = 0; i < n; ++i) {
            outlines[i].push_back(ring_points(geos, GEOSGetExteriorRing_r(geos.get(), polys[i].get())));
            for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), polys[i].get()); ++h)
                outlines[i].push_back(ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), polys[i].get(), h)));
        }
        for (auto [i, j] : coast_detail::near_pairs(outlines, 2 * grid)) {
            if (find(i) == find(j)) continue;
            near_only[j] = 1;
            parent[find(j)] = find(i);
        }
    }
    // Each group goes to GEOS as one collection: a polygon alone through GEOS's precision
    // reducer, several through a snap-rounding union. Lone polygons go in batches of about
    // batch_vertices (a valid MultiPolygon, as they are at least 2 cells apart): each GEOS snap
    // rounding seeds a random generator through CPUID, which a virtual machine traps. Groups are
    // far enough apart (2 cells: rounding moves a vertex at most 0.71 cell) that rounding them
    // apart cannot make them meet.
    constexpr std::size_t batch_vertices = 100'000;
    std::vector<std::vector<std::size_t>> groups(n);
    for (std::size_t i = 0; i < n; ++i) groups[find(i)].push_back(i);
    std::vector<GeomPtr> out;
    auto rings_of = [&](const GEOSGeometry* p) { return std::size_t(1 + GEOSGetNumInteriorRings_r(geos.get(), p)); };
    auto add_snapped = [&](GeomPtr snapped, std::size_t rings_in) {
        std::vector<const GEOSGeometry*> ps;
        polygons_of(geos, snapped.get(), ps);
        std::size_t rings_out = 0;
        for (const auto* p : ps) {
            rings_out += rings_of(p);
            out.push_back(own(geos, GEOSGeom_clone_r(geos.get(), p), "copy a polygon"));
        }
        count.changed += rings_out > rings_in ? rings_out - rings_in : rings_in - rings_out;
    };
    std::vector<GEOSGeometry*> lone;
    std::size_t lone_vertices = 0, lone_rings = 0;
    auto flush_lone = [&] {
        if (lone.empty()) return;
        GeomPtr multi = own(geos, GEOSGeom_createCollection_r(geos.get(), GEOS_MULTIPOLYGON, lone.data(),
                                                               static_cast<unsigned>(lone.size())), "collect polygons");
        add_snapped(own(geos, GEOSGeom_setPrecision_r(geos.get(), multi.get(), grid, 0), "snap-round the land"), lone_rings);
        lone.clear();
        lone_vertices = lone_rings = 0;
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (groups[i].empty()) continue;
        if (groups[i].size() == 1) {
            lone_rings += rings_of(polys[i].get());
            lone_vertices += static_cast<std::size_t>(vertices[i]);
            lone.push_back(polys[i].release());
            if (lone_vertices >= batch_vertices) flush_lone();
            continue;
        }
        std::vector<GeomPtr> members;
        std::size_t rings_in = 0;
        for (std::size_t j : groups[i]) {
            count.joined += near_only[j];
            rings_in += rings_of(polys[j].get());
            members.push_back(std::move(polys[j]));
        }
        GeomPtr all = make_collection(geos, members);
        add_snapped(own(geos, GEOSUnaryUnionPrec_r(geos.get(), all.get(), grid), "dissolve the land polygons"), rings_in);
    }
    flush_lone();
    return out;
}


/// The part of a valid polygonal geometry inside a lon/lat box: a copy when it lies inside,
/// else GEOS's overlay intersection with the box (valid output). Not GEOSClipByRect: its
/// polygon reconnection leaks memory and can build wrong polygons when edges run along the box
/// (GEOS 3.11; libgeos/geos#605), as edges on a +-180 cut do (found by fuzz_coast: a leak).
GeomPtr clip_to_box(Geos& geos, const GEOSGeometry* g, double x0, double y0, double x1, double y1, const char* what) {
    double a0, b0, a1, b1;
    if (GEOSGeom_getExtent_r(geos.get(), g, &a0, &b0, &a1, &b1) != 0 && a0 >= x0 && a1 <= x1 && b0 >= y0 && b1 <= y1)
        return own(geos, GEOSGeom_clone_r(geos.get(), g), what);
    GeomPtr box = own(geos, GEOSGeom_createRectangle_r(geos.get(), x0, y0, x1, y1), what);
    GeomPtr out = own(geos, GEOSIntersection_r(geos.get(), g, box.get()), what);
    const int type = GEOSGeomTypeId_r(geos.get(), out.get());
    if (type == GEOS_POLYGON || type == GEOS_MULTIPOLYGON) return out;
    // A part touching the box along an edge comes back as a line too: keep the polygons.
    std::vector<const GEOSGeometry*> polys;
    polygons_of(geos, out.get(), polys);
    std::vector<GeomPtr> parts;
    for (const auto* q : polys) parts.push_back(own(geos, GEOSGeom_clone_r(geos.get(), q), what));
    return make_collection(geos, parts);
}

/// Adds a valid polygonal geometry to `parts`, cutting what lies beyond +-180 (a ring drawn
/// across the antimeridian with longitudes such as 190) and wrapping it back by 360 degrees.
void add_wrapped(Geos& geos, GeomPtr g, std::vector<GeomPtr>& parts) {
    double x0, y0, x1, y1;
    if (GEOSisEmpty_r(geos.get(), g.get()) || GEOSGeom_getExtent_r(geos.get(), g.get(), &x0, &y0, &x1, &y1) == 0 ||
        (x0 >= -180.0 && x1 <= 180.0)) {
        parts.push_back(std::move(g));
        return;
    }
    for (int k = static_cast<int>(std::floor((x0 + 180.0) / 360.0)); k * 360.0 - 180.0 < x1; ++k) {
        double shift = -360.0 * k;
        GeomPtr piece = clip_to_box(geos, g.get(), -180.0 - shift, -90.0, 180.0 - shift, 90.0, "cut at the antimeridian");
        if (GEOSisEmpty_r(geos.get(), piece.get())) continue;
        auto move = [](double* x, double*, void* user) {
            *x += *static_cast<double*>(user);
            return 1;
        };
        GeomPtr moved = own(geos, GEOSGeom_transformXY_r(geos.get(), piece.get(), move, &shift), "wrap longitudes");
        if (GEOSisValid_r(geos.get(), moved.get()) != 1) moved = make_valid(geos, moved.get());
        parts.push_back(std::move(moved));
    }
}

double geodesic_area_km2(const PointList& ring) {
    GeographicLib::PolygonArea poly(GeographicLib::Geodesic::WGS84(), false);
    for (std::size_t i = 0; i + 1 < ring.size(); ++i) poly.AddPoint(ring[i].lat, ring[i].lon);
    double perimeter, area;
    poly.Compute(false, true, perimeter, area);
    return std::abs(area) * 1e-6;
}

bool touches_pole(const PointList& ring) {
    return std::any_of(ring.begin(), ring.end(), [](const LonLat& p) { return std::abs(p.lat) == 90.0; });
}

// ----------------------------------------------------------------------------- ocean rings

enum class EdgeKind { coast, open, seam, pole };

struct Clip {
    bool box = false;
    double w = -180, s = -90, e = 180, n = 90;
    bool seam_glued = true;
    const GEOSPreparedGeometry* boundary = nullptr; // region file: its outline (prepared)
};

struct Chain {
    PointList pts;
    std::vector<SegmentKind> kinds; // kinds[i]: pts[i] -> pts[i+1]
};

using NodeKey = std::pair<double, double>;
NodeKey node_key(const LonLat& p) {
    if (std::abs(p.lat) == 90.0) return {0.0, p.lat};
    return {std::abs(p.lon) == 180.0 ? 180.0 : p.lon, p.lat};
}

/// Point at fraction t of the planar lon/lat segment p-q, densifying long edges.
void append_densified(PointList& out, std::vector<SegmentKind>& kinds, const LonLat& p, const LonLat& q,
                      SegmentKind kind) {
    constexpr double max_step_deg = 0.5;
    double dx = q.lon - p.lon, dy = q.lat - p.lat;
    int pieces = dx * dx + dy * dy <= max_step_deg * max_step_deg
                     ? 1
                     : static_cast<int>(std::ceil(std::sqrt(dx * dx + dy * dy) / max_step_deg));
    for (int k = 1; k < pieces; ++k) {
        double t = double(k) / pieces;
        kinds.push_back(kind);
        out.push_back({p.lon + t * (q.lon - p.lon), p.lat + t * (q.lat - p.lat)});
    }
    kinds.push_back(kind);
    out.push_back(q);
}

class RingBuilder {
public:
    RingBuilder(Geos& geos, const Clip& clip) : geos_(geos), clip_(clip) {}

    EdgeKind classify(const LonLat& p, const LonLat& q) const {
        if (p.lat == q.lat && std::abs(p.lat) == 90.0) return EdgeKind::pole;
        if (p.lon == q.lon && std::abs(p.lon) == 180.0)
            return clip_.seam_glued ? EdgeKind::seam : EdgeKind::open;
        if (clip_.box) {
            if (p.lon == q.lon && (p.lon == clip_.w || p.lon == clip_.e)) return EdgeKind::open;
            if (p.lat == q.lat && (p.lat == clip_.s || p.lat == clip_.n)) return EdgeKind::open;
        } else if (clip_.boundary) {
            for (const LonLat& m : {p, q, LonLat{0.5 * (p.lon + q.lon), 0.5 * (p.lat + q.lat)}}) {
                GEOSCoordSequence* seq = GEOSCoordSeq_create_r(geos_.get(), 1, 2);
                GEOSCoordSeq_setXY_r(geos_.get(), seq, 0, m.lon, m.lat);
                GeomPtr pt = own(geos_, GEOSGeom_createPoint_r(geos_.get(), seq), "build a point");
                double d = 1;
                GEOSPreparedDistance_r(geos_.get(), clip_.boundary, pt.get(), &d);
                if (d > snap_grid_deg) return EdgeKind::coast; // noded at a hot pixel: still the outline
            }
            return EdgeKind::open;
        }
        return EdgeKind::coast;
    }

    /// Adds one ring of an ocean polygon (closed, oriented with the ocean on the left). Returns
    /// false when the ring has no edge on the clip outline (enclosed by coast).
    bool add_ring(PointList pts) {
        std::size_t n = pts.size() - 1; // closed: pts[n] == pts[0]
        std::vector<EdgeKind> kinds(n);
        bool touches_outline = false, cut = false;
        for (std::size_t i = 0; i < n; ++i) {
            kinds[i] = classify(pts[i], pts[i + 1]);
            if (kinds[i] != EdgeKind::coast) touches_outline = true;
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole) cut = true;
        }
        auto seg_kind = [](EdgeKind k) { return k == EdgeKind::open ? SegmentKind::open : SegmentKind::coast; };
        if (!cut) {
            Chain c;
            c.pts.push_back(pts[0]);
            for (std::size_t i = 0; i < n; ++i) append_densified(c.pts, c.kinds, pts[i], pts[i + 1], seg_kind(kinds[i]));
            c.pts.pop_back(); // closed ring: last == first
            whole_.push_back(std::move(c));
            return touches_outline;
        }
        // Start right after a removed edge and cut the ring into chains.
        std::size_t start = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole) start = (i + 1) % n;
        Chain current;
        for (std::size_t k = 0; k < n; ++k) {
            std::size_t i = (start + k) % n;
            const LonLat& p = pts[i];
            const LonLat& q = pts[i + 1];
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole) {
                if (kinds[i] == EdgeKind::seam) seam_.push_back({p.lat, q.lat});
                if (current.pts.size() >= 2) chains_.push_back(std::move(current));
                current = Chain{};
                continue;
            }
            if (current.pts.empty()) current.pts.push_back(p);
            append_densified(current.pts, current.kinds, p, q, seg_kind(kinds[i]));
        }
        if (current.pts.size() >= 2) chains_.push_back(std::move(current));
        return touches_outline;
    }

    /// Cancels seam edges that are glued to the opposite side, links the chains into closed
    /// rings and returns every ring (lon/lat, not closed, with segment kinds).
    std::vector<Chain> finish() {
        add_seam_leftovers();
        std::vector<Chain> rings = std::move(whole_);
        std::multimap<NodeKey, std::size_t> by_start;
        for (std::size_t i = 0; i < chains_.size(); ++i) by_start.insert({node_key(chains_[i].pts.front()), i});
        std::vector<bool> used(chains_.size(), false);
        for (std::size_t first = 0; first < chains_.size(); ++first) {
            if (used[first]) continue;
            Chain ring;
            std::size_t cur = first;
            NodeKey start_key = node_key(chains_[first].pts.front());
            bool closed = false;
            for (std::size_t guard = 0; guard <= chains_.size() && !closed; ++guard) {
                used[cur] = true;
                const Chain& c = chains_[cur];
                std::size_t skip = ring.pts.empty() ? 0 : 1;
                ring.pts.insert(ring.pts.end(), c.pts.begin() + static_cast<long>(skip), c.pts.end());
                ring.kinds.insert(ring.kinds.end(), c.kinds.begin(), c.kinds.end());
                NodeKey end_key = node_key(c.pts.back());
                std::size_t next = pick_next(c, end_key, by_start, used, end_key == start_key ? first : chains_.size());
                if (next == first) {
                    closed = true;
                    break;
                }
                if (next == chains_.size())
                    throw DataError("coast: the ocean outline does not close at lon " +
                                    std::to_string(c.pts.back().lon) + ", lat " +
                                    std::to_string(c.pts.back().lat) + " (inconsistent +-180 cut)");
                cur = next;
            }
            if (!closed) throw DataError("coast: the ocean outline does not close (inconsistent +-180 cut)");
            ring.pts.pop_back(); // the ring came back to its first node
            rings.push_back(std::move(ring));
        }
        return rings;
    }

private:
    void add_seam_leftovers() {
        if (seam_.empty()) return;
        std::vector<double> lats;
        for (auto [a, b] : seam_) {
            lats.push_back(a);
            lats.push_back(b);
        }
        std::sort(lats.begin(), lats.end());
        lats.erase(std::unique(lats.begin(), lats.end()), lats.end());
        std::vector<long> net(lats.size(), 0);
        auto index = [&](double v) { return static_cast<std::size_t>(std::lower_bound(lats.begin(), lats.end(), v) - lats.begin()); };
        for (auto [a, b] : seam_) {
            std::size_t i = index(a), j = index(b);
            if (i < j) { ++net[i]; --net[j]; }
            else if (j < i) { --net[j]; ++net[i]; }
        }
        long run = 0;
        for (std::size_t k = 0; k + 1 < lats.size(); ++k) {
            run += net[k];
            for (long c = 0; c < std::abs(run); ++c) {
                // Ocean on one side of the seam only: a (data) coast along the meridian.
                Chain ch;
                LonLat lo{180.0, lats[k]}, hi{180.0, lats[k + 1]};
                ch.pts.push_back(run > 0 ? lo : hi);
                append_densified(ch.pts, ch.kinds, run > 0 ? lo : hi, run > 0 ? hi : lo, SegmentKind::coast);
                chains_.push_back(std::move(ch));
            }
        }
    }

    /// The unused chain starting at `key` that keeps the same face on the left: the first
    /// outgoing direction clockwise from the incoming one (seen from outside the sphere).
    std::size_t pick_next(const Chain& in, const NodeKey& key, const std::multimap<NodeKey, std::size_t>& by_start,
                          const std::vector<bool>& used, std::size_t closing) const {
        auto [lo, hi] = by_start.equal_range(key);
        std::vector<std::size_t> options;
        if (closing != chains_.size()) options.push_back(closing);
        for (auto it = lo; it != hi; ++it)
            if (!used[it->second]) options.push_back(it->second);
        if (options.empty()) return chains_.size();
        if (options.size() == 1) return options[0];
        Vec3 p = lonlat_to_vec(in.pts.back());
        Vec3 a = lonlat_to_vec(in.pts[in.pts.size() - 2]);
        Vec3 ta = a - dot(p, a) * p;
        std::size_t best = options[0];
        double best_ccw = -1;
        for (std::size_t o : options) {
            Vec3 b = lonlat_to_vec(chains_[o].pts[1]);
            Vec3 tb = b - dot(p, b) * p;
            double ccw = std::atan2(dot(p, cross(ta, tb)), dot(ta, tb));
            if (ccw <= 0) ccw += 2 * pi;
            if (ccw > best_ccw) {
                best_ccw = ccw;
                best = o;
            }
        }
        return best;
    }

    Geos& geos_;
    const Clip& clip_;
    std::vector<Chain> whole_;
    std::vector<Chain> chains_;
    std::vector<std::pair<double, double>> seam_;
};

double signed_planar_area(const PointList& pts) {
    double a = 0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i) a += pts[i].lon * pts[i + 1].lat - pts[i + 1].lon * pts[i].lat;
    return 0.5 * a;
}

/// Converts a lon/lat ring to unit vectors, dropping nodes equal to the previous one.
Ring to_sphere(const Chain& c) {
    // Nodes closer than 1e-14 rad (check_boundary's touching distance) are one node: the two
    // copies of a point where a ring crosses the +-180 seam come from two GEOS cuts (at 180 and
    // at -180 shifted by 360) and may differ in the last bit of the latitude.
    auto same = [](const Vec3& a, const Vec3& b) { return norm(a - b) <= 1e-14; };
    Ring r;
    std::size_t n = c.pts.size();
    for (std::size_t i = 0; i < n; ++i) {
        Vec3 v = lonlat_to_vec(c.pts[i]);
        if (!r.nodes.empty() && same(r.nodes.back(), v)) {
            r.kinds.back() = c.kinds[i]; // keep the kind of the edge that leaves the merged node
            continue;
        }
        r.nodes.push_back(v);
        r.kinds.push_back(c.kinds[i]);
    }
    while (r.nodes.size() > 1 && same(r.nodes.back(), r.nodes.front())) {
        r.nodes.pop_back();
        r.kinds.pop_back();
    }
    return r;
}

/// Moves every copy of a node that several arcs share (rings meeting at one point, valid in
/// GEOS) by 1e-7 rad into the land on its right.
std::size_t separate_pinches(Boundary& b) {
    struct Occ {
        Vec3 v;
        std::uint32_t ring, index;
    };
    std::vector<Occ> occ;
    for (std::uint32_t r = 0; r < b.rings.size(); ++r)
        for (std::uint32_t i = 0; i < b.rings[r].nodes.size(); ++i) occ.push_back({b.rings[r].nodes[i], r, i});
    std::sort(occ.begin(), occ.end(), [](const Occ& a, const Occ& c) {
        return std::tie(a.v.x, a.v.y, a.v.z, a.ring, a.index) < std::tie(c.v.x, c.v.y, c.v.z, c.ring, c.index);
    });
    std::size_t moved = 0;
    constexpr double delta = 1e-7;
    for (std::size_t i = 0; i < occ.size();) {
        std::size_t j = i + 1;
        while (j < occ.size() && occ[j].v == occ[i].v) ++j;
        if (j - i > 1) {
            for (std::size_t k = i; k < j; ++k) {
                auto& nodes = b.rings[occ[k].ring].nodes;
                std::size_t n = nodes.size(), at = occ[k].index;
                const Vec3 p = occ[k].v;
                const Vec3& a = nodes[(at + n - 1) % n];
                const Vec3& c = nodes[(at + 1) % n];
                // The land is the sector swept counter-clockwise from the incoming arc (towards
                // a) to the outgoing one (towards c); move along its bisector.
                Vec3 ta = normalized(a - dot(p, a) * p), tc = normalized(c - dot(p, c) * p);
                double theta = std::atan2(dot(p, cross(ta, tc)), dot(ta, tc));
                if (theta <= 0) theta += 2 * pi;
                Vec3 u = std::cos(0.5 * theta) * ta + std::sin(0.5 * theta) * cross(p, ta);
                nodes[at] = normalized(p + delta * u);
                ++moved;
            }
        }
        i = j;
    }
    return moved;
}


/// Geodesic area to the left of densified chains (closed rings), km2.
double chains_area_km2(const std::vector<Chain>& chains) {
    std::vector<std::vector<LonLat>> ll;
    for (const auto& c : chains) ll.push_back(c.pts);
    return coast_detail::rings_area_km2(ll);
}

/// Orients a closed lon/lat ring: counter-clockwise in the plane when ccw, else clockwise.
void orient(PointList& pts, bool ccw) {
    if ((signed_planar_area(pts) > 0) != ccw) std::reverse(pts.begin(), pts.end());
}

struct Bbox {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    explicit Bbox(const PointList& pts) {
        for (const auto& p : pts) {
            x0 = std::min(x0, p.lon), y0 = std::min(y0, p.lat);
            x1 = std::max(x1, p.lon), y1 = std::max(y1, p.lat);
        }
    }
    bool inside(const Bbox& o) const { return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1; }
};

/// The ocean of the whole globe: the land's rings reversed (ocean on the left), cut at the
/// seam and the poles and stitched. Holes of the land are inland water bodies: kept with
/// keep_inland_seas, otherwise dropped with every land polygon inside them, unless nothing else
/// is ocean (then the largest stays).
std::vector<Chain> world_rings(Geos& geos, const std::vector<GeomPtr>& land, bool keep_inland_seas, CoastData& out) {
    struct Poly {
        PointList shell;
        std::vector<PointList> holes;
        const GEOSGeometry* geometry;
    };
    std::vector<Poly> polys;
    for (const auto& g : land) {
        Poly p;
        p.geometry = g.get();
        p.shell = ring_points(geos, GEOSGetExteriorRing_r(geos.get(), g.get()));
        if (std::abs(signed_planar_area(p.shell)) < min_ring_area_deg2) continue;
        orient(p.shell, false);
        for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), g.get()); ++h) {
            PointList hole = ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), g.get(), h));
            if (std::abs(signed_planar_area(hole)) < min_ring_area_deg2) continue; // zero-area sliver
            orient(hole, true);
            p.holes.push_back(std::move(hole));
        }
        polys.push_back(std::move(p));
    }
    Clip clip;
    RingBuilder main(geos, clip);
    struct Lake {
        std::vector<PointList> rings;
    };
    std::vector<Lake> lakes;
    std::vector<bool> in_lake(polys.size(), false);
    if (!keep_inland_seas) {
        std::vector<Bbox> boxes;
        for (const auto& p : polys) boxes.emplace_back(p.shell);
        for (std::size_t k = 0; k < polys.size(); ++k) {
            for (const auto& hole : polys[k].holes) {
                Lake lake;
                lake.rings.push_back(hole);
                Bbox hb(hole);
                GeomPtr ring = make_ring(geos, hole);
                GeomPtr poly = own(geos, GEOSGeom_createPolygon_r(geos.get(), ring.release(), nullptr, 0), "build a lake");
                PreparedPtr prepared(GEOSPrepare_r(geos.get(), poly.get()), PreparedDeleter{geos.get()});
                for (std::size_t j = 0; j < polys.size(); ++j) {
                    if (j == k || !boxes[j].inside(hb)) continue;
                    GeomPtr inner = own(geos, GEOSPointOnSurface_r(geos.get(), polys[j].geometry), "find an inner point");
                    if (GEOSPreparedContainsProperly_r(geos.get(), prepared.get(), inner.get()) != 1) continue;
                    in_lake[j] = true;
                    lake.rings.push_back(polys[j].shell);
                    for (const auto& h : polys[j].holes) lake.rings.push_back(h);
                }
                lakes.push_back(std::move(lake));
            }
        }
    }
    for (std::size_t k = 0; k < polys.size(); ++k) {
        if (in_lake[k]) continue;
        main.add_ring(polys[k].shell);
        if (keep_inland_seas)
            for (const auto& h : polys[k].holes) main.add_ring(h);
    }
    std::vector<Chain> rings = main.finish();
    std::vector<double> lake_area;
    std::vector<std::vector<Chain>> lake_chains;
    for (const auto& lake : lakes) {
        RingBuilder single(geos, clip);
        for (const auto& r : lake.rings) single.add_ring(r);
        lake_chains.push_back(single.finish());
        lake_area.push_back(chains_area_km2(lake_chains.back()));
    }
    std::size_t largest = lakes.size();
    if (rings.empty() && !lakes.empty())
        largest = static_cast<std::size_t>(std::max_element(lake_area.begin(), lake_area.end()) - lake_area.begin());
    for (std::size_t i = 0; i < lakes.size(); ++i) {
        if (i == largest) {
            for (auto& c : lake_chains[i]) rings.push_back(std::move(c));
            continue;
        }
        ++out.lakes_removed;
        out.area_lost_km2 += lake_area[i];
    }
    if (rings.empty() && !land.empty())
        throw DataError("coast: no ocean is left (the land covers the whole globe)");
    return rings;
}

/// The ocean of a region (--region box, two boxes across +-180, or --region-file polygons):
/// region minus land with GEOS, its rings with region edges tagged open.
std::vector<Chain> region_rings(Geos& geos, std::vector<GeomPtr>& land, const MeshOptions& options,
                                const std::string& where, CoastData& out) {
    Clip clip;
    GeomPtr domain;
    PreparedPtr prepared_outline(nullptr, PreparedDeleter{geos.get()});
    GeomPtr outline;
    if (options.region && !options.region_file.empty())
        throw UsageError("--region and --region-file exclude each other: give one");
    if (options.region) {
        auto [w, s, e, n] = *options.region;
        if (!(s < n) || s < -90 || n > 90 || w < -180 || w > 180 || e < -180 || e > 180 || w == e)
            throw UsageError("--region W,S,E,N: need -180 <= W, E <= 180, W != E, -90 <= S < N <= 90");
        // The box's sides on the land's snap grid, so that land clipped to the same box (data
        // downloaded for the area) meets them exactly instead of leaving slivers of ocean.
        auto on_grid = [](double v) { return std::nearbyint(v / snap_grid_deg) * snap_grid_deg; };
        w = on_grid(w), s = on_grid(s), e = on_grid(e), n = on_grid(n);
        clip.box = true;
        clip.w = w, clip.s = s, clip.e = e, clip.n = n;
        clip.seam_glued = w > e || (w == -180 && e == 180);
        std::vector<GeomPtr> boxes;
        if (w < e) {
            boxes.push_back(own(geos, GEOSGeom_createRectangle_r(geos.get(), w, s, e, n), "build the region"));
        } else {
            boxes.push_back(own(geos, GEOSGeom_createRectangle_r(geos.get(), w, s, 180, n), "build the region"));
            boxes.push_back(own(geos, GEOSGeom_createRectangle_r(geos.get(), -180, s, e, n), "build the region"));
        }
        domain = make_collection(geos, boxes);
        domain = own(geos, GEOSUnaryUnion_r(geos.get(), domain.get()), "build the region");
    } else {
        Source region = read_source(options.region_file, options.region_layer, "", "", "--region-file",
                                    options.max_memory_bytes);
        std::vector<GeomPtr> rparts;
        for (const auto& poly : region.polygons) rparts.push_back(make_valid(geos, make_polygon(geos, poly).get()));
        if (rparts.empty()) throw DataError("--region-file " + options.region_file + " holds no polygons");
        GeomPtr all = make_collection(geos, rparts);
        domain = own(geos, GEOSUnaryUnionPrec_r(geos.get(), all.get(), snap_grid_deg), "dissolve the region");
        GeomPtr world = own(geos, GEOSGeom_createRectangle_r(geos.get(), -180, -90, 180, 90), "build");
        domain = own(geos, GEOSIntersectionPrec_r(geos.get(), domain.get(), world.get(), snap_grid_deg), "clip the region");
        outline = own(geos, GEOSBoundary_r(geos.get(), domain.get()), "take the region outline");
        prepared_outline.reset(GEOSPrepare_r(geos.get(), outline.get()));
        clip.boundary = prepared_outline.get();
        clip.seam_glued = false; // the outline along +-180 is the user's region edge
    }
    // Only the land near the region matters: cut it to the region's extent first (fast).
    double x0, y0, x1, y1;
    GEOSGeom_getExtent_r(geos.get(), domain.get(), &x0, &y0, &x1, &y1);
    std::vector<GeomPtr> near;
    for (auto& g : land) {
        double a0, b0, a1, b1;
        GEOSGeom_getExtent_r(geos.get(), g.get(), &a0, &b0, &a1, &b1);
        if (a1 < x0 || a0 > x1 || b1 < y0 || b0 > y1) continue;
        near.push_back(clip_to_box(geos, g.get(), x0, y0, x1, y1, "clip the land"));
    }
    GeomPtr land_near = make_collection(geos, near);
    land_near = own(geos, GEOSUnaryUnionPrec_r(geos.get(), land_near.get(), snap_grid_deg), "dissolve the land");
    // An outline that runs along the coast (land clipped to the region, or the region drawn
    // from the same data in another CRS) follows the land there: it takes the land's vertices
    // within outline_snap_deg, so no sliver of water is left between the two.
    domain = own(geos, GEOSSnap_r(geos.get(), domain.get(), land_near.get(), outline_snap_deg), "snap the region to the coast");
    if (GEOSisValid_r(geos.get(), domain.get()) != 1) domain = make_valid(geos, domain.get());
    // On the land's snap grid: where the land runs along the outline (clipped to the same box or
    // polygon), the two meet exactly, and slivers narrower than half a cell collapse.
    GeomPtr ocean = own(geos, GEOSDifferencePrec_r(geos.get(), domain.get(), land_near.get(), snap_grid_deg),
                        "subtract the land");

    std::vector<const GEOSGeometry*> ocean_polys;
    polygons_of(geos, ocean.get(), ocean_polys);
    if (ocean_polys.empty()) throw DataError(where + ": no ocean is left in the region (it is all land); widen the region");
    std::vector<double> planar_area(ocean_polys.size());
    for (std::size_t i = 0; i < ocean_polys.size(); ++i) GEOSArea_r(geos.get(), ocean_polys[i], &planar_area[i]);

    RingBuilder builder(geos, clip);
    // Water bodies with no edge on the region outline are inland seas (dropped unless
    // keep_inland_seas, or unless nothing else is ocean: then the largest stays).
    std::vector<std::pair<std::size_t, std::vector<PointList>>> inland;
    for (std::size_t i = 0; i < ocean_polys.size(); ++i) {
        const GEOSGeometry* p = ocean_polys[i];
        std::vector<PointList> prings;
        prings.push_back(ring_points(geos, GEOSGetExteriorRing_r(geos.get(), p)));
        if (std::abs(signed_planar_area(prings.back())) < min_ring_area_deg2) continue;
        orient(prings.back(), true);
        for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), p); ++h) {
            PointList hole = ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), p, h));
            if (std::abs(signed_planar_area(hole)) < min_ring_area_deg2) continue; // zero-area sliver
            orient(hole, false);
            prings.push_back(std::move(hole));
        }
        bool outline_edge = false;
        for (const auto& r : prings)
            for (std::size_t j = 0; j + 1 < r.size() && !outline_edge; ++j)
                outline_edge = builder.classify(r[j], r[j + 1]) != EdgeKind::coast;
        if (outline_edge || options.keep_inland_seas) {
            for (auto& r : prings) builder.add_ring(std::move(r));
        } else {
            inland.push_back({i, std::move(prings)});
        }
    }
    std::vector<Chain> rings = builder.finish();
    std::size_t largest = inland.size();
    if (rings.empty())
        for (std::size_t k = 0; k < inland.size(); ++k)
            if (largest == inland.size() || planar_area[inland[k].first] > planar_area[inland[largest].first]) largest = k;
    for (std::size_t k = 0; k < inland.size(); ++k) {
        RingBuilder single(geos, clip);
        for (auto& r : inland[k].second) single.add_ring(r);
        std::vector<Chain> chains = single.finish();
        if (k == largest) {
            for (auto& c : chains) rings.push_back(std::move(c));
        } else {
            ++out.lakes_removed;
            out.area_lost_km2 += chains_area_km2(chains);
        }
    }
    return rings;
}

} // namespace

CoastData load_coast(const MeshOptions& options, const Progress& progress) {
    if (options.coast.empty())
        throw UsageError("--coast is required: give a coastline file (land polygons or coastlines, any OGR format)");
    report(progress, 0.0, "reading coast");
    CoastData out;
    Source src = read_source(options.coast, options.coast_layer, options.coast_where, options.coast_srs, "--coast",
                             options.max_memory_bytes, options.region);
    out.layer = src.layer;
    const std::string where = "--coast " + options.coast + " layer '" + src.layer + "'";
    report(progress, 0.25, "cleaning coast");

    Geos geos;
    // Land: valid polygons, dissolved.
    std::vector<GeomPtr> parts;
    for (const auto& poly : src.polygons) {
        GeomPtr g = make_polygon(geos, poly);
        if (GEOSisValid_r(geos.get(), g.get()) != 1) g = make_valid(geos, g.get());
        add_wrapped(geos, std::move(g), parts);
    }
    if (!src.lines.empty()) add_wrapped(geos, make_valid(geos, polygonize_lines(geos, src.lines, where).get()), parts);
    SnapCount snapped;
    std::vector<GeomPtr> land = dissolve(geos, parts, snap_grid_deg, snapped);
    out.polygons_joined = snapped.joined;
    out.rings_changed = snapped.changed;
    parts.clear();
    report(progress, 0.5, "cleaning coast");

    // Islands and lakes below --min-island-area (geodesic area); polygons closed through a pole
    // are never dropped.
    if (options.min_island_area_km2 > 0) {
        std::vector<GeomPtr> kept;
        for (const auto& g : land) {
            const GEOSGeometry* p = g.get();
            PointList shell = ring_points(geos, GEOSGetExteriorRing_r(geos.get(), p));
            double area = geodesic_area_km2(shell);
            PolygonRings keep_rings{shell};
            double holes = 0;
            for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), p); ++h) {
                PointList hole = ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), p, h));
                double ha = geodesic_area_km2(hole);
                holes += ha;
                if (ha < options.min_island_area_km2 && !touches_pole(hole)) {
                    ++out.lakes_removed;
                    out.area_lost_km2 += ha;
                } else {
                    keep_rings.push_back(std::move(hole));
                }
            }
            if (!touches_pole(shell) && area - holes < options.min_island_area_km2) {
                ++out.islands_removed;
                out.area_gained_km2 += area - holes;
                continue;
            }
            kept.push_back(make_polygon(geos, keep_rings));
        }
        land = std::move(kept);
    }

    std::vector<Chain> rings;
    if (!options.region && options.region_file.empty()) {
        rings = world_rings(geos, land, options.keep_inland_seas, out);
    } else {
        rings = region_rings(geos, land, options, where, out);
    }
    report(progress, 0.85, "checking rings");
    {
        std::vector<PolygonRings> polygons;
        for (const auto& g : land) {
            PolygonRings rings_of{ring_points(geos, GEOSGetExteriorRing_r(geos.get(), g.get()))};
            for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), g.get()); ++h)
                rings_of.push_back(ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), g.get(), h)));
            polygons.push_back(std::move(rings_of));
        }
        out.land = std::make_shared<const LandMask>(polygons);
    }

    for (const auto& c : rings) {
        Ring r = to_sphere(c);
        if (r.nodes.size() >= 3) out.rings.rings.push_back(std::move(r));
    }
    separate_pinches(out.rings);
    // 30 rounds shorten an arc 2^30 times: far past any bulge that snap rounding leaves room for.
    out.arcs_split = coast_detail::split_conflicting_arcs(out.rings, 30);
    auto issues = check_boundary(out.rings, 5);
    if (!issues.empty()) {
        const auto& is = issues.front();
        LonLat at = vec_to_lonlat(out.rings.rings[is.ring].nodes[std::max(is.segment, 0L)]);
        const std::string near = " near lon " + std::to_string(at.lon) + ", lat " + std::to_string(at.lat);
        // A region outline drawn along the coast (an ocean polygon as --region-file) leaves
        // slivers between the two: the data is not at fault, the outline's course is.
        auto open = [&](long ring, long segment) {
            const auto& kinds = ring >= 0 && segment >= 0 ? out.rings.rings[ring].kinds : std::vector<SegmentKind>{};
            return std::size_t(segment) < kinds.size() && kinds[segment] == SegmentKind::open;
        };
        if (open(is.ring, is.segment) || open(is.other_ring, is.other_segment))
            throw DataError(std::string(options.region ? "--region" : "--region-file " + options.region_file) +
                            ": its outline runs along the coast of " + where + near +
                            ", leaving slivers of ocean between them (" + is.what +
                            "); draw the outline across open water, clear of the coast");
        throw DataError(where + ": in the cleaned coast " + is.what + near + "; repair the data there");
    }
    out.ocean_area_km2 = boundary_area_km2(out.rings);
    report(progress, 1.0, "coast loaded");
    return out;
}

} // namespace globemesh
