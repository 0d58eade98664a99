// Internal to globemesh_lib: lon/lat rings closed through a pole, or joined across +-180, for the
// coast (coastline lines ending on the +-180 seam, polygons reprojected from a polar CRS), a
// --region-file and --size-regions. In a CRS where a pole is a point (polar stereographic:
// EPSG:3413, 3031) a polygon may hold it. Reprojected, its ring either goes round the pole
// without reaching it, which in lon/lat bounds nothing, or passes through it at whatever
// longitude the inverse projection gives the pole (EPSG:3413: -45), which leaves a spike. Closed
// through the pole along lat +-90 it bounds the cap it held, as Antarctica's polygon is drawn.
#pragma once

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <ogr_srs_api.h>

#include "gdal_handles.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::detail {

/// Whether the CRS `srs` holds a pole as one point (polar stereographic, transverse Mercator),
/// where a polygon may go round or through it: the pole reached from three meridians lands on
/// one point. Not in lon/lat, nor where a pole is a line (Equal Earth, whose polygons may run
/// from -180 to 180 along it) or out of reach (Mercator).
inline bool holds_a_pole_as_a_point(OGRSpatialReferenceH srs) {
    gdal::SrsPtr wgs84(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
    gdal::TransformPtr to_srs(OCTNewCoordinateTransformation(wgs84.get(), srs));
    for (const double pole : {90.0, -90.0}) {
        double x[3] = {-135.0, 0.0, 90.0}, y[3] = {pole, pole, pole};
        int ok[3] = {0, 0, 0};
        if (!to_srs || !OCTTransformEx(to_srs.get(), 3, x, y, nullptr, ok) || !ok[0] || !ok[1] ||
            !ok[2])
            continue;
        const double tolerance = 1e-9 * (1 + std::abs(x[0]) + std::abs(y[0]));
        bool point = std::isfinite(tolerance);
        for (int i = 1; i < 3; ++i)
            point = point && std::abs(x[i] - x[0]) + std::abs(y[i] - y[0]) <= tolerance;
        if (point)
            return true;
    }
    return false;
}

/// The pole nearer a path's mean latitude: -90 or 90.
inline double nearer_pole(const std::vector<LonLat> &path) {
    double mean = 0;
    for (const LonLat &p : path)
        mean += p.lat;
    return mean < 0 ? -90.0 : 90.0;
}

/// Closes a path whose ends lie 360 degrees of longitude apart, or on either side of the seam,
/// through the pole at latitude `pole`: appends (back.lon, pole), (front.lon, pole) and front.
inline void close_through_pole(std::vector<LonLat> &path, double pole) {
    const LonLat front = path.front();
    path.push_back({path.back().lon, pole});
    path.push_back({front.lon, pole});
    path.push_back(front);
}

/// The longitude step from a to b the shorter way round, degrees in [-180, 180].
inline double lon_step(double a, double b) {
    return std::remainder(b - a, 360.0);
}

/// Appends `v` to `path` with its longitude moved by the multiple of 360 degrees that puts it
/// next to the last one's (unless it repeats the last point).
inline void append_continuous(std::vector<LonLat> &path, const LonLat &v) {
    const double turns = std::round((path.back().lon - v.lon) / 360.0);
    const LonLat w{v.lon + 360.0 * turns, v.lat};
    if (w.lon != path.back().lon || w.lat != path.back().lat)
        path.push_back(w);
}

/// The ring's vertices from `from` on, `count` of them round the ring (n vertices, not closed),
/// with continuous longitudes after `start`.
inline std::vector<LonLat> continuous_run(const std::vector<LonLat> &ring, std::size_t n,
                                          LonLat start, std::size_t from, std::size_t count) {
    std::vector<LonLat> path{start};
    for (std::size_t j = 0; j < count; ++j)
        append_continuous(path, ring[(from + j) % n]);
    return path;
}

/// A ring round a pole without reaching it (n vertices, `winding` +-360 degrees of longitude),
/// cut where it crosses the seam the way it winds and closed through the nearer pole. False when
/// no step crosses the seam that way.
inline bool close_round_pole(std::vector<LonLat> &ring, std::size_t n, double winding) {
    std::size_t k = 0;
    while (k < n && !(std::abs(ring[k + 1].lon - ring[k].lon) > 180.0 &&
                      (lon_step(ring[k].lon, ring[k + 1].lon) < 0) == (winding < 0)))
        ++k;
    if (k == n)
        return false;
    const LonLat p = ring[k], q = ring[k + 1];
    const double step = lon_step(p.lon, q.lon);
    const double seam = p.lon + 0.5 * step > 0 ? 180.0 : -180.0; // crossed there, from p's side
    const double lat = p.lat + (step == 0 ? 0.0 : (seam - p.lon) / step) * (q.lat - p.lat);
    // From the crossing on q's side round to it on p's side: 360 degrees on, the way it winds.
    std::vector<LonLat> path = continuous_run(ring, n, {-seam, lat}, k + 1, n);
    append_continuous(path, {seam, lat});
    path.back().lon = -seam + (winding < 0 ? -360.0 : 360.0);
    close_through_pole(path, nearer_pole(path));
    ring = std::move(path);
    return true;
}

/// A closed ring (first == last) reprojected from a CRS where a pole is a point, made to bound in
/// lon/lat what it bounded there (true; false: left as it was). One that goes round a pole is
/// closed through it (close_round_pole); in one through a pole (a single run of vertices on it)
/// the run becomes the pole's edge from the meridian it arrives on to the one it leaves on, as far
/// as the rest of the ring winds (Antarctica's -180 to 180). Longitudes are continuous along the
/// ring and may pass +-180: the caller wraps that part back by 360 degrees.
inline bool close_at_pole(std::vector<LonLat> &ring) {
    const std::size_t n = ring.size() > 0 ? ring.size() - 1 : 0;
    if (n < 3)
        return false;
    std::size_t on_pole = 0, runs = 0, run_end = 0;
    double winding = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const bool here = std::abs(ring[i].lat) == 90.0, next = std::abs(ring[i + 1].lat) == 90.0;
        on_pole += here;
        if (here && !next)
            ++runs, run_end = i; // the run's last vertex
        winding += lon_step(ring[i].lon, ring[i + 1].lon);
    }
    if (runs == 0)
        return std::abs(winding) > 180.0 && close_round_pole(ring, n, winding);
    if (runs > 1 || n - on_pole < 2)
        return false; // through a pole twice (which way each time?), or nothing but the pole
    const double pole = ring[run_end].lat;
    const std::size_t first = (run_end + 1) % n;
    std::vector<LonLat> path = continuous_run(ring, n, ring[first], first + 1, n - on_pole - 1);
    close_through_pole(path, pole);
    ring = std::move(path);
    return true;
}

/// A closed ring (first == last) reprojected to lon/lat that jumps across +-180 but goes round
/// no pole (a UTM zone 1 or 60 polygon across the antimeridian: the inverse projection returns
/// 179 then -179, and the ring read as drawn spans every longitude but the ones it holds), with
/// its longitudes made continuous from its first vertex (true; false: left as it was). They then
/// pass +-180 on one side: the caller wraps that part back by 360 degrees.
inline bool join_across_seam(std::vector<LonLat> &ring) {
    const std::size_t n = ring.size() > 0 ? ring.size() - 1 : 0;
    if (n < 3)
        return false;
    double winding = 0;
    bool jumps = false;
    for (std::size_t i = 0; i < n; ++i) {
        winding += lon_step(ring[i].lon, ring[i + 1].lon);
        jumps = jumps || std::abs(ring[i + 1].lon - ring[i].lon) > 180.0;
    }
    if (!jumps || std::abs(winding) > 180.0)
        return false;
    std::vector<LonLat> path = continuous_run(ring, n, ring[0], 1, n - 1);
    path.push_back(ring[0]);
    ring = std::move(path);
    return true;
}

} // namespace globemesh::detail
