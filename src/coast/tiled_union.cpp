// A snap-rounding union of a large group of polygons by tiles (dissolve's groups of countries
// side by side). GEOS 3.11's overlay places each hole of a union by scanning the coordinates of
// the shells whose envelopes cover it (OverlayEdgeRing::findEdgeRingContaining), at every level
// of its cascaded union: the gaps between a continent's countries in the Digital Chart of the
// World (10^4 holes beside a shell of 10^6 vertices) took a minute a continent
// (bench/RESULTS-coast.md). Here the group is cut in halves until each tile holds a few thousand
// vertices, each tile's pieces are snap-rounded together, and the tiles' shells (holes set
// aside) are joined by a union without rounding; the holes then go back into the polygon around
// them.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <unordered_set>
#include <vector>

#include <geos_c.h>

#include "coast_load_internal.hpp"

namespace globemesh::coast_detail {
namespace {

struct Extent {
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    bool overlaps(const Extent &o) const {
        return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1;
    }
    bool holds(const Extent &o) const {
        return x0 <= o.x0 && o.x1 <= x1 && y0 <= o.y0 && o.y1 <= y1;
    }
};

Extent extent_of(Geos &geos, const GEOSGeometry *g) {
    Extent e;
    if (GEOSGeom_getExtent_r(geos.get(), g, &e.x0, &e.y0, &e.x1, &e.y1) == 0)
        throw DataError("coast: GEOS cannot give a polygon's extent: " + geos.message());
    return e;
}

/// The polygon of a ring: a shell, or a hole as the water it holds.
GeomPtr polygon_of_ring(Geos &geos, const GEOSGeometry *ring) {
    GeomPtr shell = clone(geos, ring);
    return own(geos, GEOSGeom_createPolygon_r(geos.get(), shell.release(), nullptr, 0),
               "build a polygon");
}

GeomPtr point_inside(Geos &geos, const GEOSGeometry *polygon) {
    return own(geos, GEOSPointOnSurface_r(geos.get(), polygon), "find a point inside a polygon");
}

struct Piece {
    GeomPtr g;
    Extent e;
    std::size_t vertices = 0;
};

Piece piece_of(Geos &geos, GeomPtr g) {
    Piece p{std::move(g), {}, 0};
    p.e = extent_of(geos, p.g.get());
    p.vertices = static_cast<std::size_t>(GEOSGetNumCoordinates_r(geos.get(), p.g.get()));
    return p;
}

/// Whether every vertex of a polygonal geometry lies on the grid.
bool on_grid(Geos &geos, const GEOSGeometry *g, double grid) {
    std::vector<const GEOSGeometry *> ps;
    polygons_of(geos, g, ps);
    for (const auto *p : ps)
        for (const PointList &ring : polygon_rings(geos, p))
            for (const LonLat &q : ring)
                if (std::round(q.lon / grid) * grid != q.lon ||
                    std::round(q.lat / grid) * grid != q.lat)
                    return false;
    return true;
}

/// The tiles' union, as it is built: the shells to join, the holes set aside (as polygons), and
/// the polygons that lie in another's hole (an island in a lake), kept whole.
class Tiles {
public:
    Tiles(Geos &geos, double grid, std::size_t tile_vertices)
        : geos_(geos), grid_(grid), tile_vertices_(tile_vertices) {}
    /// Cuts `pieces` (inside `box`) in halves until a tile holds at most tile_vertices, or is a
    /// few cells wide; the halves' line on the grid, where snap rounding keeps the edges the
    /// cut put on it.
    void cut(std::vector<Piece> pieces, const Extent &box);
    std::vector<GeomPtr> shells, holes, nested;

private:
    void add_tile(std::vector<Piece> pieces);
    Geos &geos_;
    double grid_;
    std::size_t tile_vertices_;
};

void Tiles::cut(std::vector<Piece> pieces, const Extent &box) {
    std::size_t vertices = 0;
    for (const Piece &p : pieces)
        vertices += p.vertices;
    const bool along_x = box.x1 - box.x0 >= box.y1 - box.y0;
    const double lo = along_x ? box.x0 : box.y0, hi = along_x ? box.x1 : box.y1;
    const double mid = lo + std::floor((hi - lo) / 2 / grid_) * grid_;
    if (vertices <= tile_vertices_ || mid - lo < 4 * grid_)
        return add_tile(std::move(pieces));
    Extent half[2] = {box, box};
    (along_x ? half[0].x1 : half[0].y1) = mid;
    (along_x ? half[1].x0 : half[1].y0) = mid;
    std::vector<Piece> in[2];
    for (Piece &p : pieces)
        for (int h = 0; h < 2; ++h) {
            if (!p.g || !half[h].overlaps(p.e))
                continue;
            if (half[h].holds(p.e)) {
                in[h].push_back(std::move(p));
                continue;
            }
            GeomPtr part = clip_to_box(geos_, p.g.get(), half[h].x0, half[h].y0, half[h].x1,
                                       half[h].y1, "cut the land into tiles");
            if (GEOSisEmpty_r(geos_.get(), part.get()) == 0)
                in[h].push_back(piece_of(geos_, std::move(part)));
        }
    pieces.clear();
    for (int h = 0; h < 2; ++h)
        cut(std::move(in[h]), half[h]);
}

/// One tile: its pieces snap-rounded together; each polygon's shell and holes set aside, or the
/// polygon kept whole where it lies in a hole of another.
void Tiles::add_tile(std::vector<Piece> pieces) {
    if (pieces.empty())
        return;
    std::vector<GeomPtr> parts;
    for (Piece &p : pieces)
        parts.push_back(std::move(p.g));
    const GeomPtr all = make_collection(geos_, parts);
    GeomPtr snapped = own(geos_, GEOSUnaryUnionPrec_r(geos_.get(), all.get(), grid_),
                          "dissolve the land polygons of a tile");
    // GEOS returns a piece that meets no other as it came (a tile of one piece: unrounded).
    if (!on_grid(geos_, snapped.get(), grid_))
        snapped = own(geos_, GEOSGeom_setPrecision_r(geos_.get(), snapped.get(), grid_, 0),
                      "snap-round the land of a tile");
    std::vector<const GEOSGeometry *> tile;
    polygons_of(geos_, snapped.get(), tile);
    std::vector<GeomPtr> tile_holes;
    std::vector<std::size_t> hole_of;
    std::vector<Extent> hole_extents;
    for (std::size_t i = 0; i < tile.size(); ++i)
        for (int h = 0; h < GEOSGetNumInteriorRings_r(geos_.get(), tile[i]); ++h) {
            tile_holes.push_back(
                polygon_of_ring(geos_, GEOSGetInteriorRingN_r(geos_.get(), tile[i], h)));
            hole_of.push_back(i);
            hole_extents.push_back(extent_of(geos_, tile_holes.back().get()));
        }
    std::vector<char> in_hole(tile.size(), 0);
    for (std::size_t i = 0; i < tile.size() && !tile_holes.empty(); ++i) {
        const GeomPtr at = point_inside(geos_, tile[i]);
        const Extent e = extent_of(geos_, at.get());
        for (std::size_t k = 0; k < tile_holes.size() && !in_hole[i]; ++k)
            in_hole[i] = hole_of[k] != i && hole_extents[k].holds(e) &&
                         GEOSContains_r(geos_.get(), tile_holes[k].get(), at.get()) == 1;
    }
    for (std::size_t i = 0; i < tile.size(); ++i) {
        if (in_hole[i]) {
            nested.push_back(clone(geos_, tile[i]));
            continue;
        }
        shells.push_back(polygon_of_ring(geos_, GEOSGetExteriorRing_r(geos_.get(), tile[i])));
        for (std::size_t k = 0; k < tile_holes.size(); ++k)
            if (hole_of[k] == i)
                holes.push_back(std::move(tile_holes[k]));
    }
}

/// A vertex's coordinates as bit patterns, hashed: the join's vertices looked up among the
/// shells'.
struct XY {
    std::uint64_t x, y;
    explicit XY(const LonLat &p) { std::memcpy(&x, &p.lon, 8), std::memcpy(&y, &p.lat, 8); }
    bool operator==(const XY &o) const { return x == o.x && y == o.y; }
};
struct XYHash {
    std::size_t operator()(const XY &p) const {
        return std::size_t(p.x * 0x9e3779b97f4a7c15ull ^ (p.y + 0x632be59bd9b4e019ull));
    }
};

/// The polygon `p` with the rings of `holes` added to its own.
GeomPtr with_holes(Geos &geos, const GEOSGeometry *p,
                   const std::vector<const GEOSGeometry *> &holes) {
    GeomPtr shell = clone(geos, GEOSGetExteriorRing_r(geos.get(), p));
    std::vector<GeomPtr> rings;
    for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), p); ++h)
        rings.push_back(clone(geos, GEOSGetInteriorRingN_r(geos.get(), p, h)));
    for (const auto *hole : holes)
        rings.push_back(clone(geos, GEOSGetExteriorRing_r(geos.get(), hole)));
    std::vector<GEOSGeometry *> raw;
    for (auto &r : rings)
        raw.push_back(r.release());
    return own(geos,
               GEOSGeom_createPolygon_r(geos.get(), shell.release(), raw.data(),
                                        static_cast<unsigned>(raw.size())),
               "build a polygon");
}

} // namespace

std::vector<GeomPtr> tiled_union(Geos &geos, const std::vector<GeomPtr> &polygons, double grid,
                                 std::size_t tile_vertices) {
    std::vector<Piece> pieces;
    Extent all;
    for (const auto &p : polygons) {
        pieces.push_back(piece_of(geos, clone(geos, p.get())));
        const Extent &e = pieces.back().e;
        all = {std::min(all.x0, e.x0), std::min(all.y0, e.y0), std::max(all.x1, e.x1),
               std::max(all.y1, e.y1)};
    }
    all = {std::floor(all.x0 / grid) * grid, std::floor(all.y0 / grid) * grid,
           std::ceil(all.x1 / grid) * grid, std::ceil(all.y1 / grid) * grid};
    Tiles tiles(geos, grid, tile_vertices);
    tiles.cut(std::move(pieces), all);
    // The tiles' shells joined without rounding: each lies in its tile, on the grid, so two meet
    // only along a tile line, at vertices they have. A vertex the union made (GEOS's robust
    // overlay falling back to snapping) would break that: the group is then unioned whole.
    std::unordered_set<XY, XYHash> had;
    for (const auto &shell : tiles.shells)
        for (const PointList &ring : polygon_rings(geos, shell.get()))
            for (const LonLat &p : ring)
                had.insert(XY(p));
    const GeomPtr shells = make_collection(geos, tiles.shells);
    const GeomPtr joined =
        own(geos, GEOSUnaryUnion_r(geos.get(), shells.get()), "join the land's tiles");
    std::vector<const GEOSGeometry *> land;
    polygons_of(geos, joined.get(), land);
    for (const auto *p : land)
        for (const PointList &ring : polygon_rings(geos, p))
            for (const LonLat &q : ring)
                if (!had.count(XY(q)))
                    return {};
    // Each hole set aside goes back into the polygon around a point inside it.
    const std::vector<std::size_t> holder = polygons_holding(geos, land, tiles.holes);
    std::vector<std::vector<const GEOSGeometry *>> holes_of(land.size());
    for (std::size_t k = 0; k < tiles.holes.size(); ++k) {
        if (holder[k] == land.size())
            return {};
        holes_of[holder[k]].push_back(tiles.holes[k].get());
    }
    std::vector<GeomPtr> out;
    for (std::size_t r = 0; r < land.size(); ++r)
        out.push_back(with_holes(geos, land[r], holes_of[r]));
    for (auto &p : tiles.nested)
        out.push_back(std::move(p));
    return out;
}

} // namespace globemesh::coast_detail
