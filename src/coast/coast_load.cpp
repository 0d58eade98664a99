// Stage 1 of the coast, its sequence: the OGR source read (coast_source.cpp), the land cleaned
// with GEOS (coast_geos.cpp), small islands and lakes dropped, the ocean's rings built on the
// sphere (coast_rings.cpp) and checked, at full resolution.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <geos_c.h>

#include "coast_internal.hpp"
#include "coast_load_internal.hpp"
#include "coast_parallel.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "lonlat_box.hpp"

namespace globemesh {
namespace {

using namespace coast_detail;

double geodesic_area_km2(const PointList &ring) {
    GeographicLib::PolygonArea poly(GeographicLib::Geodesic::WGS84(), false);
    for (std::size_t i = 0; i + 1 < ring.size(); ++i)
        poly.AddPoint(ring[i].lat, ring[i].lon);
    double perimeter, area;
    poly.Compute(false, true, perimeter, area);
    return std::abs(area) * 1e-6;
}

bool touches_pole(const PointList &ring) {
    return std::any_of(ring.begin(), ring.end(),
                       [](const LonLat &p) { return std::abs(p.lat) == 90.0; });
}

/// `p` within the boxes: whole when one holds it, else its clips by the boxes it meets (GEOS's
/// rectangle clip, which takes invalid input; its output is made valid after). Null when none
/// meets it. The land beyond a region plays no part in it (region_rings cuts it off); a
/// continent read whole for a region of its coast cost 90% of the run (GSHHG f, Norway).
GeomPtr within_boxes(Geos &geos, GeomPtr p, const std::vector<Box> &boxes) {
    // Small polygons stay whole: a clip bends a segment across the clip line where the union's
    // snap rounding moves the new vertex (by up to 2^-20 degree), and the region's own cut of
    // that segment then moves too; worth it only for the continents.
    constexpr int clip_min_vertices = 4096;
    double x0, y0, x1, y1;
    if (boxes.empty() || GEOSGetNumCoordinates_r(geos.get(), p.get()) < clip_min_vertices ||
        GEOSGeom_getExtent_r(geos.get(), p.get(), &x0, &y0, &x1, &y1) == 0)
        return p;
    std::vector<GeomPtr> pieces;
    for (const Box &b : boxes) {
        if (b[0] <= x0 && x1 <= b[2] && b[1] <= y0 && y1 <= b[3])
            return p;
        if (x1 < b[0] || b[2] < x0 || y1 < b[1] || b[3] < y0)
            continue;
        GeomPtr clip = own(geos, GEOSClipByRect_r(geos.get(), p.get(), b[0], b[1], b[2], b[3]),
                           "clip the land to the region");
        std::vector<const GEOSGeometry *> polys;
        polygons_of(geos, clip.get(), polys);
        for (const auto *q : polys)
            pieces.push_back(clone(geos, q));
    }
    return pieces.empty() ? nullptr : make_collection(geos, pieces);
}

/// The source's polygons (clipped to `boxes`, when given) made valid and wrapped into +-180
/// (add_wrapped), on every core, in their order.
std::vector<GeomPtr> valid_parts(Geos &geos, const std::vector<PolygonRings> &polygons,
                                 const std::vector<Box> &boxes) {
    std::vector<std::vector<GeomPtr>> parts_of(polygons.size());
    std::vector<std::size_t> sizes;
    for (const auto &p : polygons)
        sizes.push_back(p.front().size());
    const std::vector<std::size_t> first = largest_first(sizes);
    parallel_for_each_geos(
        geos, polygons.size(),
        [&](Geos &g, std::size_t i) {
            GeomPtr p = within_boxes(g, make_polygon(g, polygons[i]), boxes);
            if (!p)
                return;
            if (GEOSisValid_r(g.get(), p.get()) != 1)
                p = make_valid(g, p.get());
            std::vector<GeomPtr> pieces;
            add_wrapped(g, std::move(p), pieces);
            for (auto &piece : pieces)
                parts_of[i].emplace_back(piece.release(), GeosDeleter{geos.get()});
        },
        &first);
    std::vector<GeomPtr> parts;
    for (auto &pieces : parts_of)
        for (auto &piece : pieces)
            parts.push_back(std::move(piece));
    return parts;
}

/// The shortest arc of longitudes (west, east; degrees, east - west < 360, west in [-180, 180))
/// that holds every span [w, e] of `spans` (each e - w < 360): the circle less the widest gap
/// between them. None when they leave no gap.
std::optional<std::array<double, 2>> covering_arc(std::vector<std::array<double, 2>> spans) {
    for (auto &[w, e] : spans) {
        const double shift = w - wrap_lon(w);
        w -= shift, e -= shift;
    }
    std::sort(spans.begin(), spans.end());
    double reach = spans.front()[1], gap = 0, west = 0, east = 0;
    auto gap_to = [&](double next_west) {
        if (next_west - reach > gap)
            gap = next_west - reach, west = next_west, east = reach;
    };
    for (const auto &[w, e] : spans) {
        gap_to(w);
        reach = std::max(reach, e);
    }
    gap_to(spans.front()[0] + 360); // round the circle, back to the first
    if (!(gap > 0))
        return std::nullopt;
    if (west >= 180)
        west -= 360;
    return std::array<double, 2>{west, east < west ? east + 360 : east};
}

/// The lon/lat box a --region-file's polygons (`region`) lie in, half a degree wider (W > E
/// across 180), for the coast's read to take only the land near it as a --region box does: its
/// longitudes the shortest arc holding every polygon (pieces either side of 180 stored apart lie
/// in one box across it); none where they go round the globe (a cap about a pole).
std::optional<std::array<double, 4>> region_file_box(const Source &region) {
    std::vector<std::array<double, 2>> spans;
    double s = 90, n = -90;
    for (const PolygonRings &poly : region.polygons) {
        double w = 1e300, e = -1e300;
        for (const PointList &ring : poly)
            for (const LonLat &p : ring) {
                w = std::min(w, p.lon), e = std::max(e, p.lon);
                s = std::min(s, p.lat), n = std::max(n, p.lat);
            }
        if (!(e - w < 360))
            return std::nullopt;
        spans.push_back({w, e});
    }
    constexpr double margin = 0.5;
    const std::optional<std::array<double, 2>> arc =
        spans.empty() ? std::nullopt : covering_arc(spans);
    if (!arc || !((*arc)[1] - (*arc)[0] < 360 - 2 * margin - 10))
        return std::nullopt;
    return std::array<double, 4>{wrap_lon((*arc)[0] - margin), std::max(-90.0, s - margin),
                                 wrap_lon((*arc)[1] + margin), std::min(90.0, n + margin)};
}

} // namespace

CoastData load_coast(const CoastOptions &options, std::uint64_t max_memory_bytes,
                     const Progress &progress) {
    if (options.coast.empty())
        throw UsageError(option("coast") +
                         " is required: give a coastline file (land polygons or coastlines, "
                         "any OGR format)");
    report(progress, 0.0, "reading coast");
    CoastData out;
    // A --region-file, read once, reads the coast near its polygons' box alone (GSHHG f about
    // the Oresund: 13.8 s and 2.0 GB for the whole layer, 0.27 s as the same --region box).
    std::optional<Source> region_file;
    if (!options.region && !options.region_file.empty())
        region_file = read_source(options.region_file, options.region_layer, "", "", "region_file",
                                  max_memory_bytes);
    const std::optional<std::array<double, 4>> near =
        region_file ? region_file_box(*region_file) : options.region;
    Source src = read_source(options.coast, options.coast_layer, options.coast_where,
                             options.coast_srs, "coast", max_memory_bytes, near);
    out.layer = src.layer;
    const ErrorText where = option("coast") + " " + options.coast + " layer '" + src.layer + "'";
    report(progress, 0.25, "cleaning coast");

    Geos geos;
    // Land: valid polygons, dissolved.
    // Cut to the region first, unless --min-island-area weighs each island whole.
    const bool clip = near && !(options.min_island_area_km2 > 0);
    const std::vector<Box> clip_boxes = clip ? near_boxes(*near) : std::vector<Box>{};
    // A region's outline may cut a lake the clipping then opens: its holes, read first, tell
    // (not needed where every inland sea is kept).
    const std::vector<GeomPtr> holes = near && !options.keep_inland_seas
                                           ? source_holes(geos, src.polygons)
                                           : std::vector<GeomPtr>{};
    std::vector<GeomPtr> parts = valid_parts(geos, src.polygons, clip_boxes);
    if (!src.lines.empty()) {
        // each polygon wrapped alone: only those past +-180 are cut, not all the land at once
        GeomPtr from_lines = polygonize_lines(geos, src.lines, where, clip_boxes);
        std::vector<const GEOSGeometry *> polys;
        polygons_of(geos, from_lines.get(), polys);
        for (const GEOSGeometry *p : polys)
            add_wrapped(geos, clone(geos, p), parts);
    }
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
        for (const auto &g : land) {
            const GEOSGeometry *p = g.get();
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
        rings = region_rings(geos, land, holes, options, region_file ? &*region_file : nullptr,
                             where, out);
    }
    report(progress, 0.85, "checking rings");
    {
        std::vector<PolygonRings> polygons;
        for (const auto &g : land)
            polygons.push_back(polygon_rings(geos, g.get()));
        out.land = std::make_shared<const LandMask>(polygons);
    }

    for (const auto &c : rings) {
        Ring r = to_sphere(c);
        if (r.nodes.size() >= 3)
            out.rings.rings.push_back(std::move(r));
    }
    // The rings come out of GEOS (a region's overlay, the global dissolve) in an order and from
    // starts of its own, which follow the source's (its rings' starts, directions, features), and
    // the shaping and the mesher's choices follow them: put them in one of ours, so that the same
    // ocean makes the same mesh however it was stored or computed.
    canonical_order(out.rings);
    separate_pinches(out.rings);
    // 30 rounds shorten an arc 2^30 times: far past any bulge that snap rounding leaves room for.
    bool clear = false;
    out.arcs_split = coast_detail::split_conflicting_arcs(out.rings, 30, &clear);
    auto issues = clear ? check_boundary_clear(out.rings, 5) : check_boundary(out.rings, 5);
    if (!issues.empty()) {
        const auto &is = issues.front();
        LonLat at = vec_to_lonlat(out.rings.rings[is.ring].nodes[std::max(is.segment, 0L)]);
        const std::string near =
            " near lon " + std::to_string(at.lon) + ", lat " + std::to_string(at.lat);
        // A region outline drawn along the coast (an ocean polygon as --region-file) leaves
        // slivers between the two: the data is not at fault, the outline's course is.
        auto open = [&](long ring, long segment) {
            const auto &kinds = ring >= 0 && segment >= 0 ? out.rings.rings[ring].kinds
                                                          : std::vector<SegmentKind>{};
            return std::size_t(segment) < kinds.size() && kinds[segment] == SegmentKind::open;
        };
        if (open(is.ring, is.segment) || open(is.other_ring, is.other_segment))
            throw DataError((options.region ? option("region")
                                            : option("region_file") + " " + options.region_file) +
                            ": its outline runs along the coast of " + where + near +
                            ", leaving slivers of ocean between them (" + is.what +
                            "); draw the outline across open water, clear of the coast");
        throw DataError(where + ": in the cleaned coast " + is.what + near +
                        "; repair the data there");
    }
    out.ocean_area_km2 = boundary_area_km2(out.rings);
    report(progress, 1.0, "coast loaded");
    return out;
}

} // namespace globemesh
