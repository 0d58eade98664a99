// A projected world map's +-180 edge, where PROJ's inverse rejects points that rounding put just
// outside its domain: the points reprojected one by one, those pulled inside. Shared by the
// coast's and the size regions' readers.
#pragma once

#include <cmath>
#include <string>

#include <cpl_error.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "gdal_handles.hpp"

namespace globemesh {

/// Largest pull toward the central meridian that transform_on_edge tries, relative to a point's
/// offset from it: 2^-20 (16 m at 1.7e7 m, the edge of a Robinson world map), past the 2.4e-7
/// that Robinson's inverse needs on its edge at latitude 60 (its table's nodes, every 5 degrees).
constexpr double edge_pull_max = 0x1p-20;

/// A world map's edge in x: its false easting, and the central meridian (degrees) whose
/// antimeridian the edge draws.
struct MapEdge {
    double x_centre = 0;
    double lon_0 = 0;
};

/// The edge of a projected CRS's world map.
inline MapEdge map_edge(OGRSpatialReferenceH srs) {
    return {OSRGetProjParm(srs, SRS_PP_FALSE_EASTING, 0.0, nullptr),
            OSRGetProjParm(srs, SRS_PP_CENTRAL_MERIDIAN, 0.0, nullptr)};
}

/// Reprojects one point of a projected world map in place. A point the inverse rejects is pulled
/// toward the centre by the least of 2^-52 .. edge_pull_max of its offset that the inverse
/// accepts: PROJ's Robinson and Mollweide inverses reject points of their +-180 edge that
/// rounding put just outside. Such a point lies on the edge, so it takes the edge's longitude,
/// lon_0 +- 180, exactly (the pulled inverse is up to 2e-5 degrees off it). False if none works.
inline bool transform_on_edge(OGRCoordinateTransformationH ct, const MapEdge &edge, double &x,
                              double &y) {
    for (double pull = 0; pull <= edge_pull_max; pull = pull == 0 ? 0x1p-52 : 2 * pull) {
        double px = edge.x_centre + (x - edge.x_centre) * (1 - pull), py = y, pz = 0;
        int ok = FALSE;
        if (OCTTransformEx(ct, 1, &px, &py, &pz, &ok) && ok && std::isfinite(px) &&
            std::isfinite(py)) {
            if (pull > 0)
                px = std::remainder(edge.lon_0 + (x > edge.x_centre ? 180.0 : -180.0), 360.0);
            x = px;
            y = py;
            return true;
        }
    }
    return false;
}

/// Reprojects every point of `g` (each part, ring and line) in place, a point at a time through
/// transform_on_edge; keeps Z and M. False if a point cannot be reprojected.
inline bool transform_points_on_edge(OGRGeometryH g, OGRCoordinateTransformationH ct,
                                     const MapEdge &edge) {
    const int parts = OGR_G_GetGeometryCount(g);
    for (int i = 0; i < parts; ++i)
        if (!transform_points_on_edge(OGR_G_GetGeometryRef(g, i), ct, edge))
            return false;
    for (int i = 0; i < OGR_G_GetPointCount(g); ++i) {
        double x = 0, y = 0, z = 0, m = 0;
        OGR_G_GetPointZM(g, i, &x, &y, &z, &m);
        if (!transform_on_edge(ct, edge, x, y))
            return false;
        OGR_G_SetPointZM(g, i, x, y, z, m);
    }
    return true;
}

/// A clone of `g` reprojected by `ct`. In a projected CRS, when the whole transform fails (a
/// world map's +-180 edge), another clone point by point (transform_points_on_edge), the retry's
/// GDAL messages silenced and, once it succeeds, the failure cleared unless an error was pending
/// before (a failure recovered from is no read error). Null when it cannot be reprojected, `why`
/// then the first attempt's message.
inline gdal::GeometryPtr reprojected(OGRGeometryH g, OGRCoordinateTransformationH ct,
                                     bool projected, const MapEdge &edge, std::string &why) {
    const bool had_error = CPLGetLastErrorType() >= CE_Failure;
    gdal::GeometryPtr copy(OGR_G_Clone(g));
    if (OGR_G_Transform(copy.get(), ct) == OGRERR_NONE)
        return copy;
    why = gdal::last_error("a point outside the projection's domain");
    if (!projected)
        return nullptr;
    copy.reset(OGR_G_Clone(g));
    CPLPushErrorHandler(CPLQuietErrorHandler);
    const bool ok = transform_points_on_edge(copy.get(), ct, edge);
    CPLPopErrorHandler();
    if (!ok)
        return nullptr;
    if (!had_error)
        CPLErrorReset();
    return copy;
}

} // namespace globemesh
