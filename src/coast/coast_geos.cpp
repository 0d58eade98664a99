// The GEOS operations of the coast: building GEOS geometries from lon/lat rings and reading them
// back, making them valid, polygonizing coastline lines, dissolving and snap-rounding the land,
// clipping to a box and wrapping across +-180.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <geos_c.h>

#include "coast_internal.hpp"
#include "coast_load_internal.hpp"
#include "coast_parallel.hpp"
#include "disjoint_sets.hpp"
#include "globemesh/error.hpp"
#include "pole_rings.hpp"

namespace globemesh::coast_detail {
namespace {

constexpr double line_end_snap_deg = 1e-3;
constexpr double max_line_gap_deg = 0.5;
/// dissolve's groups of this many polygons or more (countries side by side: GSHHG's and Natural
/// Earth's largest have tens), with more than four tiles' vertices, are unioned by tiles of
/// about tile_vertices vertices (tiled_union).
constexpr std::size_t tiled_polygons = 256;
constexpr std::size_t tile_vertices = 16'384;

} // namespace

void join_meeting(Geos &geos, const std::vector<GeomPtr> &polys, const std::vector<int> &vertices,
                  Groups &groups, const MeetTest &meet_test) {
    const std::size_t n = polys.size();
    auto find = [&](std::size_t i) { return groups.find(i); };
    TreePtr tree(GEOSSTRtree_create_r(geos.get(), 10), GeosDeleter{geos.get()});
    for (std::size_t i = 0; i < n; ++i)
        GEOSSTRtree_insert_r(geos.get(), tree.get(), polys[i].get(), reinterpret_cast<void *>(i));
    std::vector<std::size_t> hits;
    auto collect = [](void *item, void *user) {
        static_cast<std::vector<std::size_t> *>(user)->push_back(
            reinterpret_cast<std::size_t>(item));
    };
    // The pairs whose boxes meet, i < j, in the order the joins are made.
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t i = 0; i < n; ++i) {
        coast::GeosInterrupt::poll(); // a long run of short GEOS calls, none of which reports
        hits.clear();
        GEOSSTRtree_query_r(geos.get(), tree.get(), polys[i].get(), collect, &hits);
        std::sort(hits.begin(), hits.end());
        for (std::size_t j : hits)
            if (j > i)
                pairs.emplace_back(i, j);
    }
    // Each pair tested against its polygon with more vertices (see the header).
    std::vector<std::vector<std::size_t>> pairs_of(n);
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto [i, j] = pairs[k];
        pairs_of[vertices[j] > vertices[i] ? j : i].push_back(k);
    }
    std::vector<std::size_t> sizes(n);
    for (std::size_t i = 0; i < n; ++i)
        sizes[i] = pairs_of[i].empty() ? 0 : std::size_t(vertices[i]);
    const std::vector<std::size_t> first = largest_first(sizes);
    std::vector<char> meet(pairs.size(), 0);
    parallel_for_each_geos(
        geos, n,
        [&](Geos &g, std::size_t big) {
            if (pairs_of[big].empty())
                return;
            coast::GeosInterrupt::poll();
            const PreparedPtr prepared(GEOSPrepare_r(g.get(), polys[big].get()),
                                       GeosDeleter{g.get()});
            for (std::size_t k : pairs_of[big]) {
                const std::size_t small = pairs[k].first == big ? pairs[k].second : pairs[k].first;
                meet[k] = meet_test(g, prepared.get(), big, small);
            }
        },
        &first);
    // The joins in pair order, as one thread made them (the same groups, the same roots).
    for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto [i, j] = pairs[k];
        if (meet[k] && find(i) != find(j))
            groups.join(i, j);
    }
}

namespace {

/// Joins the polygons whose outlines come within 2 cells of each other (near-touches), marking
/// in near_only those joined by distance alone.
void join_near(Geos &geos, const std::vector<GeomPtr> &polys, double grid, Groups &groups,
               std::vector<char> &near_only) {
    const std::size_t n = polys.size();
    auto find = [&](std::size_t i) { return groups.find(i); };
    std::vector<PolygonRings> outlines(n);
    for (std::size_t i = 0; i < n; ++i)
        outlines[i] = polygon_rings(geos, polys[i].get());
    for (auto [i, j] : coast_detail::near_pairs(outlines, 2 * grid)) {
        if (find(i) == find(j))
            continue;
        near_only[j] = 1;
        groups.join(i, j);
    }
}

std::size_t rings_of(Geos &geos, const GEOSGeometry *polygon) {
    return std::size_t(1 + GEOSGetNumInteriorRings_r(geos.get(), polygon));
}

/// Polygons snap-rounded together: a group (one snap-rounding union) or a batch of lone ones
/// (no union: see snap_job).
struct SnapJob {
    bool group = false;
    std::vector<GeomPtr> polygons; ///< taken by snap_job
    std::size_t vertices = 0, rings_in = 0, rings_out = 0;
    std::vector<GeomPtr> out; ///< the polygons it gave, owned in the caller's context
};

/// Adds the polygons of `snapped` to job.out, owned in the caller's context `owner`.
void add_output(Geos &geos, SnapJob &job, const GEOSGeometry *snapped, GEOSContextHandle_t owner) {
    std::vector<const GEOSGeometry *> ps;
    polygons_of(geos, snapped, ps);
    for (const auto *p : ps) {
        job.rings_out += rings_of(geos, p);
        GeomPtr copy = clone(geos, p);
        job.out.emplace_back(copy.release(), GeosDeleter{owner});
    }
}

/// Runs a job in `geos` (a worker's context, or the caller's `owner`). A batch's lone polygons
/// come out in order, each as GEOS's precision reducer rounds it alone: rounded here when
/// rounding cannot change it (rounded_if_clear: GEOS's vertices in GEOS's order), else by GEOS
/// (15 us a call beside the rounding: each seeds a random generator). A group goes through
/// GEOS's snap-rounding union.
void snap_job(Geos &geos, SnapJob &job, double grid, GEOSContextHandle_t owner) {
    if (!job.group) {
        for (const auto &p : job.polygons)
            if (auto rounded = rounded_if_clear(polygon_rings(geos, p.get()), grid)) {
                job.rings_out += rounded->size();
                job.out.emplace_back(make_polygon(geos, *rounded).release(), GeosDeleter{owner});
            } else {
                const GeomPtr snapped =
                    own(geos, GEOSGeom_setPrecision_r(geos.get(), p.get(), grid, 0),
                        "snap-round the land");
                add_output(geos, job, snapped.get(), owner);
            }
        job.polygons.clear();
        return;
    }
    std::vector<GeomPtr> tiled;
    if (job.polygons.size() >= tiled_polygons && job.vertices > 4 * tile_vertices)
        tiled = tiled_union(geos, job.polygons, grid, tile_vertices);
    if (!tiled.empty()) {
        job.polygons.clear();
        for (auto &p : tiled) {
            job.rings_out += rings_of(geos, p.get());
            job.out.emplace_back(p.release(), GeosDeleter{owner});
        }
        return;
    }
    std::vector<GEOSGeometry *> raw;
    for (auto &p : job.polygons)
        raw.push_back(p.release());
    job.polygons.clear();
    GeomPtr all = own(geos,
                      GEOSGeom_createCollection_r(geos.get(), GEOS_GEOMETRYCOLLECTION, raw.data(),
                                                  static_cast<unsigned>(raw.size())),
                      "collect polygons");
    const GeomPtr snapped =
        own(geos, GEOSUnaryUnionPrec_r(geos.get(), all.get(), grid), "dissolve the land polygons");
    add_output(geos, job, snapped.get(), owner);
}

} // namespace

GeomPtr make_ring(Geos &geos, const PointList &pts) {
    std::vector<double> xy;
    xy.reserve(pts.size() * 2);
    for (const auto &p : pts) {
        xy.push_back(p.lon);
        xy.push_back(p.lat);
    }
    GEOSCoordSequence *seq = GEOSCoordSeq_copyFromBuffer_r(geos.get(), xy.data(), pts.size(), 0, 0);
    if (!seq)
        throw DataError("coast: GEOS cannot build a coordinate sequence: " + geos.message());
    return own(geos, GEOSGeom_createLinearRing_r(geos.get(), seq), "build a ring");
}

GeomPtr make_polygon(Geos &geos, const PolygonRings &rings) {
    GeomPtr shell = make_ring(geos, rings[0]);
    std::vector<GEOSGeometry *> holes;
    for (std::size_t i = 1; i < rings.size(); ++i)
        holes.push_back(make_ring(geos, rings[i]).release());
    return own(geos,
               GEOSGeom_createPolygon_r(geos.get(), shell.release(), holes.data(),
                                        static_cast<unsigned>(holes.size())),
               "build a polygon");
}

GeomPtr make_collection(Geos &geos, std::vector<GeomPtr> &parts) {
    std::vector<GEOSGeometry *> raw;
    for (auto &p : parts)
        raw.push_back(p.release());
    parts.clear();
    return own(geos,
               GEOSGeom_createCollection_r(geos.get(), GEOS_GEOMETRYCOLLECTION, raw.data(),
                                           static_cast<unsigned>(raw.size())),
               "build a collection");
}

/// MakeValid (STRUCTURE method, collapsed parts dropped): polygonal output only.
GeomPtr make_valid(Geos &geos, const GEOSGeometry *g) {
    GEOSMakeValidParams *params = GEOSMakeValidParams_create_r(geos.get());
    GEOSMakeValidParams_setMethod_r(geos.get(), params, GEOS_MAKE_VALID_STRUCTURE);
    GEOSMakeValidParams_setKeepCollapsed_r(geos.get(), params, 0);
    GEOSGeometry *out = GEOSMakeValidWithParams_r(geos.get(), g, params);
    GEOSMakeValidParams_destroy_r(geos.get(), params);
    return own(geos, out, "make a polygon valid");
}

void polygons_of(Geos &geos, const GEOSGeometry *g, std::vector<const GEOSGeometry *> &out) {
    int type = GEOSGeomTypeId_r(geos.get(), g);
    if (type == GEOS_POLYGON) {
        if (!GEOSisEmpty_r(geos.get(), g))
            out.push_back(g);
    } else if (type == GEOS_MULTIPOLYGON || type == GEOS_GEOMETRYCOLLECTION) {
        for (int i = 0; i < GEOSGetNumGeometries_r(geos.get(), g); ++i)
            polygons_of(geos, GEOSGetGeometryN_r(geos.get(), g, i), out);
    }
}

PointList ring_points(const Geos &geos, const GEOSGeometry *ring) {
    const GEOSCoordSequence *seq = ring ? GEOSGeom_getCoordSeq_r(geos.get(), ring) : nullptr;
    unsigned n = 0;
    if (!seq || !GEOSCoordSeq_getSize_r(geos.get(), seq, &n))
        throw DataError("coast: GEOS failed to read a ring: " + geos.message());
    std::vector<double> xy(2 * std::size_t(n));
    if (n && !GEOSCoordSeq_copyToBuffer_r(geos.get(), seq, xy.data(), 0, 0))
        throw DataError("coast: GEOS failed to read a ring: " + geos.message());
    PointList pts(n);
    for (unsigned i = 0; i < n; ++i)
        pts[i] = {xy[2 * i], xy[2 * i + 1]};
    return pts;
}

PolygonRings polygon_rings(const Geos &geos, const GEOSGeometry *polygon) {
    PolygonRings rings{ring_points(geos, GEOSGetExteriorRing_r(geos.get(), polygon))};
    for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), polygon); ++h)
        rings.push_back(ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), polygon, h)));
    return rings;
}

namespace {

/// Whether the lon/lat box of `pts` meets one of `boxes` (all of them when there are none).
bool meets_any(const PointList &pts, const std::vector<Box> &boxes) {
    if (boxes.empty())
        return true;
    double w = 1e300, e = -1e300, s = 1e300, n = -1e300;
    for (const LonLat &p : pts) {
        w = std::min(w, p.lon), e = std::max(e, p.lon);
        s = std::min(s, p.lat), n = std::max(n, p.lat);
    }
    return std::any_of(boxes.begin(), boxes.end(), [&](const Box &b) {
        return w <= b[2] && e >= b[0] && s <= b[3] && n >= b[1];
    });
}

} // namespace

GeomPtr polygonize_lines(Geos &geos, const std::vector<PointList> &lines, const ErrorText &where,
                         const std::vector<Box> &near) {
    std::vector<GeomPtr> linestrings;
    for (const auto &l : lines) {
        // A closed line off the region's boxes holds none of its land, nor any land of it.
        if (!l.empty() && l.front().lon == l.back().lon && l.front().lat == l.back().lat &&
            !meets_any(l, near))
            continue;
        std::vector<double> xy;
        for (const auto &p : l) {
            xy.push_back(p.lon);
            xy.push_back(p.lat);
        }
        GEOSCoordSequence *seq =
            GEOSCoordSeq_copyFromBuffer_r(geos.get(), xy.data(), l.size(), 0, 0);
        linestrings.push_back(
            own(geos, GEOSGeom_createLineString_r(geos.get(), seq), "build a line"));
    }
    GeomPtr all = make_collection(geos, linestrings);
    GeomPtr merged = own(geos, GEOSLineMerge_r(geos.get(), all.get()), "merge coastline lines");
    std::vector<GeomPtr> faces;
    int n = GEOSGetNumGeometries_r(geos.get(), merged.get());
    for (int i = 0; i < n; ++i) {
        PointList pts = ring_points(geos, GEOSGetGeometryN_r(geos.get(), merged.get(), i));
        if (pts.size() < 2)
            continue;
        LonLat a = pts.front(), b = pts.back();
        if (a.lon != b.lon || a.lat != b.lat) {
            // Open ends within 0.001 degree (110 m) of the seam, on either side, were cut there
            // (an end far beyond it, lon 199 of a line drawn in [0, 360), is not).
            for (LonLat *e : {&pts.front(), &pts.back()})
                if (std::abs(std::abs(e->lon) - 180.0) <= line_end_snap_deg)
                    e->lon = e->lon > 0 ? 180.0 : -180.0;
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
            if (a.lon != b.lon)
                detail::close_through_pole(pts, detail::nearer_pole(pts)); // as Antarctica
            else
                pts.push_back(a);
        }
        if (pts.size() < 4 || !meets_any(pts, near))
            continue;
        GeomPtr ring = make_ring(geos, pts);
        GeomPtr poly =
            own(geos, GEOSGeom_createPolygon_r(geos.get(), ring.release(), nullptr, 0), "build");
        if (GEOSisValid_r(geos.get(), poly.get()) == 1) {
            faces.push_back(std::move(poly));
            continue;
        }
        // A self-intersecting line: node it and polygonize its faces.
        GeomPtr line = own(geos, GEOSBoundary_r(geos.get(), poly.get()), "take a boundary");
        GeomPtr noded = own(geos, GEOSUnaryUnion_r(geos.get(), line.get()), "node a line");
        const GEOSGeometry *input[] = {noded.get()};
        GeomPtr pieces = own(geos, GEOSPolygonize_r(geos.get(), input, 1), "polygonize a line");
        faces.push_back(own(geos, GEOSUnaryUnion_r(geos.get(), pieces.get()), "union faces"));
    }
    return parity_fill(geos, std::move(faces));
}

std::vector<GeomPtr> dissolve(Geos &geos, const std::vector<GeomPtr> &parts, double grid,
                              SnapCount &count) {
    std::vector<GeomPtr> polys;
    for (const auto &part : parts) {
        std::vector<const GEOSGeometry *> ps;
        polygons_of(geos, part.get(), ps);
        for (const auto *p : ps)
            polys.push_back(clone(geos, p));
    }
    std::size_t n = polys.size();
    Groups joined(n);
    auto find = [&](std::size_t i) { return joined.find(i); };
    std::vector<char> near_only(n, 0); // joined by distance alone, not by intersection
    std::vector<int> vertices(n);
    for (std::size_t i = 0; i < n; ++i)
        vertices[i] = GEOSGetNumCoordinates_r(geos.get(), polys[i].get());
    join_meeting(geos, polys, vertices, joined,
                 [&](Geos &g, const GEOSPreparedGeometry *big, std::size_t, std::size_t small) {
                     return GEOSPreparedIntersects_r(g.get(), big, polys[small].get()) == 1;
                 });
    // Outlines within 2 cells of each other (near-touches) are snap-rounded together too.
    join_near(geos, polys, grid, joined, near_only);
    // A polygon alone is rounded alone (snap_job), a group of several through a snap-rounding
    // union; lone polygons go to the threads in batches of about batch_vertices. Groups are
    // far enough apart (2 cells: rounding moves a vertex at most 0.71 cell) that rounding them
    // apart cannot make them meet. The batches and groups are snap-rounded on every core, the
    // largest first, and join the output in a fixed order.
    constexpr std::size_t batch_vertices = 100'000;
    std::vector<std::vector<std::size_t>> groups(n);
    for (std::size_t i = 0; i < n; ++i)
        groups[find(i)].push_back(i);
    // Jobs in the order their results join the output: a group where it stands, a batch of lone
    // polygons where it fills up (and the last one at the end).
    std::vector<SnapJob> jobs;
    SnapJob lone;
    auto flush_lone = [&] {
        if (!lone.polygons.empty())
            jobs.push_back(std::move(lone));
        lone = SnapJob{};
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (groups[i].empty())
            continue;
        if (groups[i].size() == 1) {
            lone.rings_in += rings_of(geos, polys[i].get());
            lone.vertices += static_cast<std::size_t>(vertices[i]);
            lone.polygons.push_back(std::move(polys[i]));
            if (lone.vertices >= batch_vertices)
                flush_lone();
            continue;
        }
        SnapJob group;
        group.group = true;
        for (std::size_t j : groups[i]) {
            count.joined += near_only[j];
            group.rings_in += rings_of(geos, polys[j].get());
            group.vertices += static_cast<std::size_t>(vertices[j]);
            group.polygons.push_back(std::move(polys[j]));
        }
        jobs.push_back(std::move(group));
    }
    flush_lone();
    std::vector<std::size_t> sizes;
    for (const auto &job : jobs)
        sizes.push_back(job.vertices);
    const std::vector<std::size_t> first = largest_first(sizes);
    parallel_for_each_geos(
        geos, jobs.size(), [&](Geos &g, std::size_t k) { snap_job(g, jobs[k], grid, geos.get()); },
        &first);
    std::vector<GeomPtr> out;
    for (auto &job : jobs) {
        count.changed += job.rings_out > job.rings_in ? job.rings_out - job.rings_in
                                                      : job.rings_in - job.rings_out;
        for (auto &p : job.out)
            out.push_back(std::move(p));
    }
    return out;
}

GeomPtr clip_to_box(Geos &geos, const GEOSGeometry *g, double x0, double y0, double x1, double y1,
                    const char *what) {
    double a0, b0, a1, b1;
    if (GEOSGeom_getExtent_r(geos.get(), g, &a0, &b0, &a1, &b1) != 0 && a0 >= x0 && a1 <= x1 &&
        b0 >= y0 && b1 <= y1)
        return clone(geos, g, what);
    GeomPtr box = own(geos, GEOSGeom_createRectangle_r(geos.get(), x0, y0, x1, y1), what);
    GeomPtr out = own(geos, GEOSIntersection_r(geos.get(), g, box.get()), what);
    const int type = GEOSGeomTypeId_r(geos.get(), out.get());
    if (type == GEOS_POLYGON || type == GEOS_MULTIPOLYGON)
        return out;
    // A part touching the box along an edge comes back as a line too: keep the polygons.
    std::vector<const GEOSGeometry *> polys;
    polygons_of(geos, out.get(), polys);
    std::vector<GeomPtr> parts;
    for (const auto *q : polys)
        parts.push_back(clone(geos, q, what));
    return make_collection(geos, parts);
}

/// Adds a valid polygonal geometry to `parts`, cutting what lies beyond +-180 (a ring drawn
/// across the antimeridian with longitudes such as 190) and wrapping it back by 360 degrees.
void add_wrapped(Geos &geos, GeomPtr g, std::vector<GeomPtr> &parts) {
    double x0, y0, x1, y1;
    if (GEOSisEmpty_r(geos.get(), g.get()) ||
        GEOSGeom_getExtent_r(geos.get(), g.get(), &x0, &y0, &x1, &y1) == 0 ||
        (x0 >= -180.0 && x1 <= 180.0)) {
        parts.push_back(std::move(g));
        return;
    }
    for (int k = static_cast<int>(std::floor((x0 + 180.0) / 360.0)); k * 360.0 - 180.0 < x1; ++k) {
        double shift = -360.0 * k;
        GeomPtr piece = clip_to_box(geos, g.get(), -180.0 - shift, -90.0, 180.0 - shift, 90.0,
                                    "cut at the antimeridian");
        if (GEOSisEmpty_r(geos.get(), piece.get()))
            continue;
        auto move = [](double *x, double *, void *user) {
            *x += *static_cast<double *>(user);
            return 1;
        };
        GeomPtr moved = own(geos, GEOSGeom_transformXY_r(geos.get(), piece.get(), move, &shift),
                            "wrap longitudes");
        if (GEOSisValid_r(geos.get(), moved.get()) != 1)
            moved = make_valid(geos, moved.get());
        parts.push_back(std::move(moved));
    }
}

} // namespace globemesh::coast_detail
