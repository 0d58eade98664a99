// The land test of the coast at full resolution (coast.hpp, LandMask): GEOS point-in-polygon in
// planar lon/lat, the way GIS software and mesh-verify read land polygons, and the distance to
// the outlines on the sphere.
#include <cmath>
#include <string>
#include <vector>

#include <geos_c.h>

#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"

namespace globemesh {

/// Vertices per piece of the coast in the distance index: short enough that a query's box
/// meets few of them, long enough that the tree stays small.
constexpr std::size_t piece_vertices = 16;

struct LandMask::Impl {
    GEOSContextHandle_t ctx = GEOS_init_r();
    std::vector<GEOSGeometry*> polygons;
    std::vector<const GEOSPreparedGeometry*> prepared;
    GEOSSTRtree* tree = nullptr;
    // The outlines (shells and holes) as unit vectors, cut into pieces of piece_vertices
    // vertices (the last one shared with the next piece), under an STR tree of their lon/lat
    // envelopes: the coast distance is measured on the sphere, segment by segment.
    std::vector<Vec3> outline;            // every piece's vertices, one piece after another
    std::vector<std::size_t> piece_start; // piece i is outline[piece_start[i], piece_start[i + 1])
    std::vector<GEOSGeometry*> envelopes;
    GEOSSTRtree* pieces = nullptr;

    ~Impl() {
        if (tree) GEOSSTRtree_destroy_r(ctx, tree);
        if (pieces) GEOSSTRtree_destroy_r(ctx, pieces);
        for (const auto* p : prepared)
            if (p) GEOSPreparedGeom_destroy_r(ctx, p);
        for (auto* g : envelopes) GEOSGeom_destroy_r(ctx, g);
        for (auto* g : polygons) GEOSGeom_destroy_r(ctx, g);
        GEOS_finish_r(ctx);
    }

    void add_outline(const std::vector<LonLat>& pts) {
        for (std::size_t first = 0; first + 1 < pts.size(); first += piece_vertices - 1) {
            const std::size_t last = std::min(first + piece_vertices, pts.size());
            double x0 = pts[first].lon, x1 = x0, y0 = pts[first].lat, y1 = y0;
            piece_start.push_back(outline.size());
            for (std::size_t k = first; k < last; ++k) {
                x0 = std::min(x0, pts[k].lon), x1 = std::max(x1, pts[k].lon);
                y0 = std::min(y0, pts[k].lat), y1 = std::max(y1, pts[k].lat);
                outline.push_back(lonlat_to_vec(pts[k].lon, pts[k].lat));
            }
            GEOSGeometry* box = GEOSGeom_createRectangle_r(ctx, x0, y0, x1, y1);
            if (!box) throw DataError("coast: GEOS failed to build an envelope for the land test");
            envelopes.push_back(box);
        }
    }

    GEOSGeometry* ring(const std::vector<LonLat>& pts) const {
        std::vector<double> xy;
        xy.reserve(2 * pts.size());
        for (const auto& p : pts) {
            xy.push_back(p.lon);
            xy.push_back(p.lat);
        }
        GEOSCoordSequence* seq = GEOSCoordSeq_copyFromBuffer_r(ctx, xy.data(), pts.size(), 0, 0);
        GEOSGeometry* r = seq ? GEOSGeom_createLinearRing_r(ctx, seq) : nullptr;
        if (!r) throw DataError("coast: GEOS failed to build a land ring for the land test");
        return r;
    }
};

LandMask::LandMask(const std::vector<std::vector<std::vector<LonLat>>>& polygons) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    std::vector<LonLat> probes; // a point of each polygon's shell
    for (const auto& rings : polygons) {
        if (rings.empty() || rings[0].size() < 4) continue;
        GEOSGeometry* shell = m.ring(rings[0]);
        std::vector<GEOSGeometry*> holes;
        for (std::size_t i = 1; i < rings.size(); ++i)
            if (rings[i].size() >= 4) holes.push_back(m.ring(rings[i]));
        GEOSGeometry* poly = GEOSGeom_createPolygon_r(m.ctx, shell, holes.data(), static_cast<unsigned>(holes.size()));
        if (!poly) throw DataError("coast: GEOS failed to build a land polygon for the land test");
        m.polygons.push_back(poly);
        probes.push_back(rings[0][0]);
        for (const auto& r : rings) {
            if (r.size() >= 4) m.add_outline(r);
            vertices_ += r.size();
        }
    }
    m.piece_start.push_back(m.outline.size());
    // Every polygon prepared now, its point locator built by a first test (GEOS builds it
    // lazily): the index belongs to loading the coast, not to the meshing that asks it.
    m.prepared.assign(m.polygons.size(), nullptr);
    for (std::size_t i = 0; i < m.polygons.size(); ++i) {
        m.prepared[i] = GEOSPrepare_r(m.ctx, m.polygons[i]);
        if (!m.prepared[i]) throw DataError("coast: GEOS failed to prepare a land polygon for the land test");
        GEOSGeometry* probe = GEOSGeom_createPointFromXY_r(m.ctx, probes[i].lon, probes[i].lat);
        if (probe) {
            GEOSPreparedContains_r(m.ctx, m.prepared[i], probe);
            GEOSGeom_destroy_r(m.ctx, probe);
        }
    }
    m.tree = GEOSSTRtree_create_r(m.ctx, 10);
    for (std::size_t i = 0; i < m.polygons.size(); ++i)
        GEOSSTRtree_insert_r(m.ctx, m.tree, m.polygons[i], reinterpret_cast<void*>(i));
    m.pieces = GEOSSTRtree_create_r(m.ctx, 10);
    for (std::size_t i = 0; i < m.envelopes.size(); ++i)
        GEOSSTRtree_insert_r(m.ctx, m.pieces, m.envelopes[i], reinterpret_cast<void*>(i));
}

LandMask::~LandMask() = default;

bool LandMask::contains(const Vec3& p) const {
    const Impl& m = *impl_;
    if (m.polygons.empty()) return false;
    const LonLat ll = vec_to_lonlat(p);
    GEOSGeometry* point = GEOSGeom_createPointFromXY_r(m.ctx, ll.lon, ll.lat);
    if (!point) throw DataError("coast: GEOS failed to build a point for the land test");
    struct Query {
        const Impl* m;
        const GEOSGeometry* point;
        bool inside = false;
    } q{&m, point};
    GEOSSTRtree_query_r(
        m.ctx, m.tree, point,
        [](void* item, void* data) {
            auto& q = *static_cast<Query*>(data);
            if (q.inside) return;
            const auto i = reinterpret_cast<std::size_t>(item);
            q.inside = GEOSPreparedContains_r(q.m->ctx, q.m->prepared[i], q.point) == 1;
        },
        &q);
    GEOSGeom_destroy_r(m.ctx, point);
    return q.inside;
}

bool LandMask::coast_within(const Vec3& p, double angle) const {
    const Impl& m = *impl_;
    if (m.envelopes.empty()) return false;
    // The lon/lat box of the cap of that radius around p (the whole band of longitudes near a
    // pole), split in two where it crosses +-180.
    const LonLat ll = vec_to_lonlat(p);
    const double dlat = angle * rad_to_deg;
    const double c = std::cos(ll.lat * deg_to_rad);
    // The cap's widest reach in longitude; it holds a pole where sin(angle) >= cos(lat).
    const double dlon = std::sin(angle) < c ? std::asin(std::sin(angle) / c) * rad_to_deg : 180;
    const double y0 = std::max(-90.0, ll.lat - dlat), y1 = std::min(90.0, ll.lat + dlat);
    std::vector<std::pair<double, double>> spans{{ll.lon - dlon, ll.lon + dlon}};
    if (dlon >= 180) spans = {{-180, 180}};
    else if (spans[0].first < -180) spans = {{-180, spans[0].second}, {spans[0].first + 360, 180}};
    else if (spans[0].second > 180) spans = {{spans[0].first, 180}, {-180, spans[0].second - 360}};
    struct Query {
        const Impl* m;
        Vec3 p;
        double angle;
        bool near = false;
    } q{&m, p, angle};
    for (const auto& [x0, x1] : spans) {
        GEOSGeometry* box = GEOSGeom_createRectangle_r(m.ctx, x0, y0, x1, y1);
        if (!box) throw DataError("coast: GEOS failed to build a query for the coast distance");
        GEOSSTRtree_query_r(
            m.ctx, m.pieces, box,
            [](void* item, void* data) {
                auto& q = *static_cast<Query*>(data);
                if (q.near) return;
                const auto i = reinterpret_cast<std::size_t>(item);
                const std::vector<Vec3>& o = q.m->outline;
                for (std::size_t k = q.m->piece_start[i]; k + 1 < q.m->piece_start[i + 1] && !q.near; ++k)
                    q.near = arc_distance(o[k], o[k + 1], q.p) <= q.angle;
            },
            &q);
        GEOSGeom_destroy_r(m.ctx, box);
        if (q.near) break;
    }
    return q.near;
}

} // namespace globemesh
