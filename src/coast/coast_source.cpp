// The OGR source of the coast: a layer read into lon/lat polygons and lines (WGS84, GIS axis
// order), reprojected from its CRS, snapped to the +-180 seam and the poles.
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "coast_load_internal.hpp"
#include "gdal_handles.hpp"
#include "globemesh/error.hpp"
#include "map_edge.hpp"
#include "pole_rings.hpp"

namespace globemesh::coast_detail {
namespace {

using gdal::DatasetPtr;
using gdal::FeaturePtr;
using gdal::SrsPtr;
using gdal::TransformPtr;
using OgrGeometryPtr = gdal::GeometryPtr; // GeomPtr is the GEOS owner

constexpr double seam_snap_deg = 1e-9;
/// A vertex this close to +-180 (11 m at the equator) next to a vertex on it goes onto it too.
/// Natural Earth stores coordinates on a grid of 1/20480 degree, and a corner of a polygon cut
/// at the antimeridian can sit one step off it: Chukotka's western half at 1:50m ends at
/// -179.999951, leaving a 27 km wedge of "ocean" 2 m wide between the two halves (a face of
/// quality 1e-4 at 20 km).
constexpr double seam_notch_deg = 1e-4;
constexpr double pole_snap_deg = 2e-3;

/// Moves onto the seam each vertex within seam_notch_deg of it whose neighbour along the ring
/// lies on it, on the same side (neighbours judged as they were before this pass).
void close_seam_notches(PointList &pts) {
    std::size_t n = pts.size();
    const bool closed =
        n > 1 && pts.front().lon == pts.back().lon && pts.front().lat == pts.back().lat;
    if (closed)
        --n;
    if (n < 3)
        return;
    const PointList was(pts.begin(), pts.begin() + static_cast<std::ptrdiff_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
        const double lon = was[i].lon;
        const double seam = lon > 0 ? 180.0 : -180.0;
        if (std::abs(lon) == 180.0 || std::abs(lon) <= 180.0 - seam_notch_deg)
            continue;
        const bool has_prev = closed || i > 0, has_next = closed || i + 1 < n;
        if ((has_prev && was[(i + n - 1) % n].lon == seam) ||
            (has_next && was[(i + 1) % n].lon == seam))
            pts[i].lon = seam;
    }
    if (closed)
        pts.back() = pts.front();
}

/// Longitudes beyond this (degrees) are refused: no ring needs more than one wrap.
constexpr double max_abs_lon_deg = 540.0;

/// Snaps coordinates of one ring or line to the +-180 seam and the poles (see coast.hpp).
void snap_coordinates(PointList &pts, bool transformed) {
    for (auto &p : pts) {
        if (p.lat > 90.0 - pole_snap_deg)
            p.lat = 90.0;
        if (p.lat < -90.0 + pole_snap_deg)
            p.lat = -90.0;
    }
    if (!transformed) {
        for (auto &p : pts) {
            if (std::abs(p.lon - 180.0) < seam_snap_deg)
                p.lon = 180.0;
            if (std::abs(p.lon + 180.0) < seam_snap_deg)
                p.lon = -180.0;
        }
        close_seam_notches(pts);
        return;
    }
    // A projection's inverse may return either +180 or -180 on the seam: a run of vertices on
    // the seam takes the side of the vertex before it, up to a pole vertex (where a closure
    // such as Antarctica's crosses to the other side), and the side of the vertex after it
    // from there on.
    auto on_seam = [](const LonLat &p) { return std::abs(p.lon) > 180.0 - seam_snap_deg; };
    std::size_t n = pts.size();
    if (n && pts.front().lon == pts.back().lon && pts.front().lat == pts.back().lat)
        --n; // closed ring
    std::size_t anchor = n;
    for (std::size_t i = 0; i < n; ++i)
        if (!on_seam(pts[i]))
            anchor = i;
    if (anchor == n) {
        for (auto &p : pts)
            p.lon = p.lon > 0 ? 180.0 : -180.0;
        return;
    }
    auto side_of = [](const LonLat &p) { return p.lon >= 0 ? 180.0 : -180.0; };
    for (std::size_t k = 1; k <= n; ++k) {
        std::size_t i = (anchor + k) % n;
        if (!on_seam(pts[i]))
            continue;
        std::size_t end = k; // the run is k .. end-1 (offsets from anchor)
        while (end <= n && on_seam(pts[(anchor + end) % n]))
            ++end;
        double before = side_of(pts[(anchor + k - 1) % n]);
        double after = side_of(pts[(anchor + end) % n]);
        bool past_pole = false;
        for (std::size_t m = k; m < end; ++m) {
            auto &p = pts[(anchor + m) % n];
            p.lon = past_pole ? after : before;
            if (std::abs(p.lat) == 90.0)
                past_pole = true;
        }
        k = end;
    }
    if (n < pts.size())
        pts.back() = pts.front();
    close_seam_notches(pts);
}

PointList read_points(OGRGeometryH g, bool transformed) {
    int n = OGR_G_GetPointCount(g);
    PointList pts(static_cast<std::size_t>(std::max(n, 0)));
    for (int i = 0; i < n; ++i)
        pts[i] = {OGR_G_GetX(g, i), OGR_G_GetY(g, i)};
    for (const auto &p : pts) {
        if (!std::isfinite(p.lon) || !std::isfinite(p.lat))
            throw DataError("coast: a vertex has a non-finite coordinate (failed reprojection?)");
        // A ring drawn across the antimeridian may reach past +-180 (lon 190, or [0, 360)), and
        // add_wrapped cuts it back once per 360 degrees: further out, the layer is not in degrees.
        if (std::abs(p.lon) > max_abs_lon_deg) {
            char text[160];
            std::snprintf(
                text, sizeof text,
                "coast: a vertex has longitude %.6g, beyond +-%.0f degrees: is the layer in "
                "lon/lat? (",
                p.lon, max_abs_lon_deg);
            throw DataError(text + option("coast_srs") + " names its CRS)");
        }
    }
    snap_coordinates(pts, transformed);
    return pts;
}

/// How a geometry reached lon/lat: as stored, or reprojected from a geographic CRS, a projected
/// one (where a ring may cross +-180), or one that holds a pole as a point (where a ring may also
/// go round or through it: pole_rings.hpp).
enum class Reprojected { no, geographic, projected, from_pole_point };

void collect_geometry(OGRGeometryH g, Reprojected how, Source &out) {
    const bool transformed = how != Reprojected::no;
    if (!g || OGR_G_IsEmpty(g))
        return;
    OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
    if (OGR_GT_IsNonLinear(t)) {
        OgrGeometryPtr linear(OGR_G_GetLinearGeometry(g, 0, nullptr));
        collect_geometry(linear.get(), how, out);
        return;
    }
    switch (t) {
    case wkbPolygon: {
        PolygonRings poly;
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i) {
            PointList ring = read_points(OGR_G_GetGeometryRef(g, i), transformed);
            if (!ring.empty() &&
                (ring.front().lon != ring.back().lon || ring.front().lat != ring.back().lat))
                ring.push_back(ring.front());
            // Round or through a pole of a polar CRS: closed through it along lat +-90; else
            // across +-180 from a projected CRS, joined there (add_wrapped takes what passes
            // +-180).
            if (!(how == Reprojected::from_pole_point && detail::close_at_pole(ring)) &&
                (how == Reprojected::projected || how == Reprojected::from_pole_point))
                detail::join_across_seam(ring);
            if (ring.size() < 4) {
                if (i == 0)
                    return; // degenerate shell: no polygon
                continue;
            }
            poly.push_back(std::move(ring));
        }
        if (!poly.empty())
            out.polygons.push_back(std::move(poly));
        return;
    }
    case wkbLineString:
    case wkbLinearRing: {
        PointList line = read_points(g, transformed);
        if (line.size() >= 2)
            out.lines.push_back(std::move(line));
        return;
    }
    case wkbPoint:
    case wkbMultiPoint:
        ++out.points;
        return;
    default:
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
            collect_geometry(OGR_G_GetGeometryRef(g, i), how, out);
    }
}

/// A copy of `g` with each closed line string a polygon (a --region-file's outline drawn as a
/// line); its other parts as they are.
OgrGeometryPtr closed_lines_to_polygons(OGRGeometryH g) {
    const OGRwkbGeometryType t = wkbFlatten(OGR_G_GetGeometryType(g));
    if (t == wkbLineString)
        return OgrGeometryPtr(OGR_G_ForceToPolygon(OGR_G_Clone(g)));
    if (t != wkbMultiLineString && t != wkbGeometryCollection)
        return OgrGeometryPtr(OGR_G_Clone(g));
    OgrGeometryPtr out(OGR_G_CreateGeometry(wkbGeometryCollection));
    for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
        OGR_G_AddGeometryDirectly(out.get(),
                                  closed_lines_to_polygons(OGR_G_GetGeometryRef(g, i)).release());
    return out;
}

/// What a layer of the option `field` should hold, for messages.
std::string expected_geometry(const char *field) {
    return std::string_view(field) == "region_file"
               ? "polygons (or closed lines) bounding the ocean to mesh"
               : "land polygons or coastlines";
}

/// Vertices of a geometry (all its parts and rings), as OGR holds them; curves count their
/// control points (a linearized curve has more, but curves are rare in coastlines).
std::uint64_t vertex_count(OGRGeometryH g) {
    if (!g)
        return 0;
    const int parts = OGR_G_GetGeometryCount(g);
    if (parts == 0)
        return static_cast<std::uint64_t>(std::max(OGR_G_GetPointCount(g), 0));
    std::uint64_t n = 0;
    for (int i = 0; i < parts; ++i)
        n += vertex_count(OGR_G_GetGeometryRef(g, i));
    return n;
}

/// Peak bytes per input vertex of load_coast: the lon/lat copy (16), GEOS's coordinate
/// sequences of the polygon, its valid and dissolved copies (3 x 24), the rings on the sphere
/// (24 + tags) and the containers' slack: 170 B/vertex measured, rounded up
/// (bench/RESULTS-core-coast.md).
constexpr std::uint64_t coast_bytes_per_vertex = 200;

bool is_polygon_type(OGRwkbGeometryType t) {
    t = wkbFlatten(t);
    return OGR_GT_IsSubClassOf(t, wkbCurvePolygon) || OGR_GT_IsSubClassOf(t, wkbMultiSurface);
}

bool is_area_or_line(OGRwkbGeometryType t) {
    t = wkbFlatten(t);
    return is_polygon_type(t) || OGR_GT_IsSubClassOf(t, wkbCurve) ||
           OGR_GT_IsSubClassOf(t, wkbMultiCurve);
}

std::string layer_list(GDALDatasetH ds) {
    std::string list;
    for (int i = 0; i < GDALDatasetGetLayerCount(ds); ++i) {
        OGRLayerH l = GDALDatasetGetLayer(ds, i);
        if (!list.empty())
            list += ", ";
        list += std::string(OGR_L_GetName(l)) + " (" + OGRGeometryTypeToName(OGR_L_GetGeomType(l)) +
                ")";
    }
    return list.empty() ? "none" : list;
}

/// The layer named `layer_name`, or else the one polygon or line layer of the data set.
OGRLayerH choose_layer(GDALDatasetH h, const std::string &path, const std::string &layer_name,
                       const std::string &field) {
    OGRLayerH layer = nullptr;
    if (!layer_name.empty()) {
        layer = GDALDatasetGetLayerByName(h, layer_name.c_str());
        if (!layer)
            throw DataError(option(field) + " " + path + ": no layer named '" + layer_name +
                            "'; layers: " + layer_list(h));
    } else {
        std::vector<OGRLayerH> candidates, unknown;
        for (int i = 0; i < GDALDatasetGetLayerCount(h); ++i) {
            OGRLayerH l = GDALDatasetGetLayer(h, i);
            OGRwkbGeometryType t = OGR_L_GetGeomType(l);
            if (is_area_or_line(t))
                candidates.push_back(l);
            else if (wkbFlatten(t) == wkbUnknown || wkbFlatten(t) == wkbGeometryCollection)
                unknown.push_back(l);
        }
        if (candidates.empty())
            candidates = unknown;
        if (candidates.size() != 1)
            throw DataError(
                option(field) + " " + path + ": " +
                (candidates.empty()
                     ? ErrorText("no polygon or line layer")
                     : "several polygon or line layers, choose one with " +
                           option(field == "region_file" ? "region_layer" : "coast_layer")) +
                "; layers: " + layer_list(h));
        layer = candidates.front();
    }
    return layer;
}

/// The layer's CRS, or the override for a layer that declares none, in GIS axis order.
SrsPtr source_crs(OGRLayerH layer, const std::string &srs_override, const ErrorText &where_msg,
                  const std::string &field) {
    // Coordinate reference system: the layer's, or the override; lon/lat WGS84 as target. A
    // local (engineering) CRS of unknown units, as a .prj with LOCAL_CS, counts as none.
    OGRSpatialReferenceH declared = OGR_L_GetSpatialRef(layer);
    if (declared && OSRIsLocal(declared))
        declared = nullptr;
    SrsPtr source_srs;
    if (!srs_override.empty()) {
        source_srs.reset(OSRNewSpatialReference(nullptr));
        if (OSRSetFromUserInput(source_srs.get(), srs_override.c_str()) != OGRERR_NONE)
            throw UsageError(option("coast_srs") + " '" + srs_override +
                             "' is not a CRS GDAL/PROJ understands");
        // A layer's own CRS is not overridden: degrees read as EPSG:3857 metres put the whole
        // coast within a kilometre of 0,0, and the mesh is silently an aqua-planet.
        if (declared) {
            // Both are read lon, lat (traditional order, below): only the CRS themselves are
            // compared, not their data axis mappings.
            const char *same_options[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", nullptr};
            if (!OSRIsSameEx(declared, source_srs.get(), same_options)) {
                const char *name = OSRGetName(declared);
                const char *auth = OSRGetAuthorityName(declared, nullptr);
                const char *code = OSRGetAuthorityCode(declared, nullptr);
                const std::string declared_name =
                    std::string(name ? name : "a CRS") +
                    (auth && code ? std::string(" (") + auth + ":" + code + ")" : "");
                throw DataError(where_msg + " declares " + declared_name + ", not " +
                                option("coast_srs") + " " + srs_override + "; " +
                                option("coast_srs") +
                                " is for a layer that declares none (leave it out, or replace a "
                                "wrong CRS with ogr2ogr -a_srs)");
            }
        }
    } else if (declared) {
        source_srs.reset(OSRClone(declared));
    } else {
        throw DataError(
            where_msg + " declares no coordinate reference system" +
            (OGR_L_GetSpatialRef(layer) ? " (only a local one, of unknown units)" : "") +
            (field == "coast" ? "; give it with " + option("coast_srs") + " (e.g. EPSG:4326)"
                              : ErrorText("; assign one, e.g. ogr2ogr -a_srs EPSG:4326")));
    }
    OSRSetAxisMappingStrategy(source_srs.get(), OAMS_TRADITIONAL_GIS_ORDER);
    return source_srs;
}

/// The region W,S,E,N widened by 1% of its larger side, as lon/lat boxes within +-180: one, or
/// its two sides when it crosses +-180.
std::vector<Box> near_sides(const std::array<double, 4> &near) {
    auto [w, s, e, n] = near;
    const double width = e > w ? e - w : e + 360 - w;
    const double pad = 0.01 * std::max(width, n - s);
    s = std::max(-90.0, s - pad), n = std::min(90.0, n + pad);
    if (width >= 360 - 2 * pad)
        return {{-180, s, 180, n}};
    if (e > w)
        return {{std::max(-180.0, w - pad), s, std::min(180.0, e + pad), n}};
    return {{w - pad, s, 180, n}, {-180, s, e + pad, n}};
}

/// The boxes the layer is read through for the region `near` (see read_source): near_boxes
/// shifted where the layer's extent passes +-180 (GSHHG's Antarctica runs 0..360, Eurasia to
/// 190); in a projected CRS the bounds of its sides; none (read it whole) when the CRS cannot
/// take them.
std::vector<Box> filter_boxes(OGRLayerH layer, const std::array<double, 4> &near,
                              OGRCoordinateTransformationH transform, OGRSpatialReferenceH wgs84,
                              OGRSpatialReferenceH source_srs) {
    if (transform) {
        // The box in the layer's CRS (densified edges); a CRS that cannot take it: none.
        const std::vector<Box> sides = near_sides(near);
        TransformPtr to_layer(OCTNewCoordinateTransformation(wgs84, source_srs));
        const Box b = sides.size() == 1 ? sides.front() : Box{-180, sides[0][1], 180, sides[0][3]};
        Box t;
        const bool ok = to_layer &&
                        OCTTransformBounds(to_layer.get(), b[0], b[1], b[2], b[3], &t[0], &t[1],
                                           &t[2], &t[3], 21) &&
                        t[0] < t[2] && t[1] < t[3] && std::isfinite(t[0] + t[1] + t[2] + t[3]);
        return ok ? std::vector<Box>{t} : std::vector<Box>{};
    }
    OGREnvelope extent{};
    return OGR_L_GetExtent(layer, &extent, FALSE) == OGRERR_NONE
               ? near_boxes(near, extent.MinX, extent.MaxX)
               : near_boxes(near);
}

/// The layer's attribute fields, for a filter's error: "a, b, c" (at most 12, then "...").
std::string field_names(OGRLayerH layer) {
    OGRFeatureDefnH defn = OGR_L_GetLayerDefn(layer);
    const int n = OGR_FD_GetFieldCount(defn);
    std::string names;
    for (int i = 0; i < n && i < 12; ++i)
        names += (i ? ", " : "") + std::string(OGR_Fld_GetNameRef(OGR_FD_GetFieldDefn(defn, i)));
    return n == 0 ? "none" : n > 12 ? names + ", ..." : names;
}

/// A filter's error without OGR SQL's caret drawing ("... Occurred around :\n(x >)\n ^").
std::string filter_reason(std::string reason) {
    std::string::size_type at = reason.find("Occurred around");
    while (at != std::string::npos && at > 0 &&
           std::isspace(static_cast<unsigned char>(reason[at - 1])))
        --at;
    return at == std::string::npos ? reason : reason.substr(0, at);
}

/// What is wrong with the layer's attribute filter after a read failed on it. SQLite drivers
/// (GeoPackage) fail a read with their whole statement ("failed to prepare SQL: SELECT ..."),
/// and a count with SQLite's reason ("...) failed: no such column: x"): the count's is given.
std::string filter_error(OGRLayerH layer) {
    std::string reason = gdal::last_error();
    CPLErrorReset();
    OGR_L_SetSpatialFilter(layer, nullptr);
    OGR_L_GetFeatureCount(layer, TRUE);
    const std::string counted = CPLGetLastErrorMsg();
    const std::string::size_type at = counted.find(") failed: ");
    if (at != std::string::npos)
        reason = counted.substr(at + 10);
    else if (reason.starts_with("failed to prepare SQL"))
        reason = "the driver's SQL does not take it";
    return filter_reason(reason);
}

/// Throws when GDAL reported a failure since the last reset (a reading loop's end: its
/// GetNextFeature returned null on an error, not at the end of the layer, or skipped a feature),
/// naming the filter when there is one: the features read so far are not the layer's.
void throw_if_read_failed(OGRLayerH layer, const std::string &where, const ErrorText &where_msg) {
    if (CPLGetLastErrorType() < CE_Failure)
        return;
    if (!where.empty())
        throw UsageError(option("coast_where") + " '" + where + "' is not a valid filter for " +
                         where_msg + " (" + filter_error(layer) +
                         "); give one SQL expression on its fields (" + field_names(layer) +
                         "), without ';' or a comment");
    throw IoError(where_msg + ": reading failed (" + gdal::last_error() +
                  "); check the file, or convert it with ogr2ogr");
}

} // namespace

std::vector<Box> near_boxes(const std::array<double, 4> &near, double x_min, double x_max) {
    std::vector<Box> boxes;
    for (const Box &b : near_sides(near))
        for (const double shift : {0.0, 360.0, -360.0})
            if (shift == 0 || (shift > 0 ? x_max > 180 : x_min < -180))
                boxes.push_back({b[0] + shift, b[1], b[2] + shift, b[3]});
    return boxes;
}

Source read_source(const std::string &path, const std::string &layer_name, const std::string &where,
                   const std::string &srs_override, const char *field, std::uint64_t max_bytes,
                   const std::optional<std::array<double, 4>> &near) {
    GDALAllRegister();
    gdal::QuietErrors quiet;
    DatasetPtr ds(
        GDALOpenEx(path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
    if (!ds) {
        std::string msg = CPLGetLastErrorMsg();
        throw IoError(option(field) + " " + path + ": cannot open as a vector data set" +
                      (msg.empty() ? "" : " (" + msg + ")") + "; " + gdal::open_advice(path));
    }
    GDALDatasetH h = ds.get();
    OGRLayerH layer = choose_layer(h, path, layer_name, field);
    Source src;
    src.layer = OGR_L_GetName(layer);
    const ErrorText where_msg = option(field) + " " + path + " layer '" + src.layer + "'";
    // In parentheses: SQLite drivers (GeoPackage) paste the filter into their statement, which
    // ignored text after a ';' or in a '--' comment alone and failed on it with a region's
    // spatial filter; parenthesized it fails alike with or without one.
    if (!where.empty() &&
        OGR_L_SetAttributeFilter(layer, ("(" + where + ")").c_str()) != OGRERR_NONE)
        throw UsageError(option("coast_where") + " '" + where + "' is not a valid filter for " +
                         where_msg + " (" + filter_reason(gdal::last_error()) +
                         "); give one SQL expression on its fields (" + field_names(layer) + ")");

    SrsPtr source_srs = source_crs(layer, srs_override, where_msg, field);
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

    const std::vector<Box> boxes =
        near && is_polygon_type(OGR_L_GetGeomType(layer))
            ? filter_boxes(layer, *near, transform.get(), wgs84.get(), source_srs.get())
            : std::vector<Box>{};
    const Reprojected how = !transform ? Reprojected::no
                            : detail::holds_a_pole_as_a_point(source_srs.get())
                                ? Reprojected::from_pole_point
                            : OSRIsProjected(source_srs.get()) ? Reprojected::projected
                                                               : Reprojected::geographic;
    const MapEdge edge = map_edge(source_srs.get());
    CPLErrorReset();
    const std::uint64_t max_vertices = max_bytes / coast_bytes_per_vertex;
    std::uint64_t vertices = 0;
    bool too_many = false;
    const bool region = std::string_view(field) == "region_file";
    // One feature: counted, and its polygons and lines kept in lon/lat.
    auto take = [&](OGRFeatureH f) {
        ++src.features;
        OGRGeometryH g = OGR_F_GetGeometryRef(f);
        if (!g)
            return;
        vertices += vertex_count(g);
        if (max_bytes > 0 && vertices > max_vertices && !too_many) {
            too_many = true; // from here on only count, to name the total
            src.polygons = {};
            src.lines = {};
        }
        if (too_many)
            return;
        // A region's outline drawn as a closed line bounds what a polygon would.
        OgrGeometryPtr outline = region ? closed_lines_to_polygons(g) : nullptr;
        if (outline)
            g = outline.get();
        if (transform) {
            // A world map's points on its +-180 edge may fail the whole-geometry transform:
            // then point by point, those on the edge pulled inside (map_edge.hpp).
            std::string why;
            const OgrGeometryPtr copy =
                reprojected(g, transform.get(), how == Reprojected::projected, edge, why);
            if (!copy)
                throw DataError(where_msg + ": feature " + std::to_string(OGR_F_GetFID(f)) +
                                " cannot be reprojected to lon/lat (" + why + ")");
            collect_geometry(copy.get(), how, src);
        } else {
            collect_geometry(g, Reprojected::no, src);
        }
    };
    // Through each box, a feature met by two read once.
    std::unordered_set<GIntBig> seen;
    for (const Box &b : boxes) {
        OGR_L_SetSpatialFilterRect(layer, b[0], b[1], b[2], b[3]);
        OGR_L_ResetReading(layer);
        while (FeaturePtr f{OGR_L_GetNextFeature(layer)}) {
            const GIntBig fid = OGR_F_GetFID(f.get());
            if (fid == OGRNullFID || seen.insert(fid).second)
                take(f.get());
        }
        throw_if_read_failed(layer, where, where_msg);
    }
    // Whole, without a region or with nothing near it; then only up to a first polygon or
    // line (a region of open sea reads no more), for the errors below to be the whole layer's.
    if (src.features == 0) {
        OGR_L_SetSpatialFilter(layer, nullptr);
        OGR_L_ResetReading(layer);
        while (FeaturePtr f{OGR_L_GetNextFeature(layer)}) {
            take(f.get());
            if (!boxes.empty() && (!src.polygons.empty() || !src.lines.empty()))
                break;
        }
        throw_if_read_failed(layer, where, where_msg);
    }
    if (too_many)
        throw DataError(where_msg + " has " + std::to_string(vertices) +
                        " vertices, more than the " + std::to_string(max_vertices) + " that " +
                        option("max_memory_bytes") + " " +
                        memory_text(static_cast<double>(max_bytes)) + " allows (about " +
                        std::to_string(coast_bytes_per_vertex) + " bytes each); raise " +
                        option("max_memory_bytes") +
                        ", or simplify the layer first (e.g. "
                        "ogr2ogr -simplify 0.001)");
    if (src.features == 0)
        throw DataError(where_msg + " has no features" +
                        (where.empty() ? ErrorText("") : " matching " + option("coast_where")) +
                        "; give a layer of " + expected_geometry(field));
    if (src.polygons.empty() && src.lines.empty())
        throw DataError(where_msg + " holds no polygons or lines" +
                        (src.points ? " (only points)" : "") + "; give " +
                        expected_geometry(field));
    if (region && !src.lines.empty()) {
        const LonLat a = src.lines.front().front(), b = src.lines.front().back();
        throw DataError(where_msg + ": a line from (" + std::to_string(a.lon) + ", " +
                        std::to_string(a.lat) + ") to (" + std::to_string(b.lon) + ", " +
                        std::to_string(b.lat) + ") does not close; give " +
                        expected_geometry(field));
    }
    return src;
}

} // namespace globemesh::coast_detail
