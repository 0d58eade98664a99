// The land test of the coast at full resolution (coast.hpp, LandMask): GEOS point-in-polygon in
// planar lon/lat, the way GIS software and mesh-verify read land polygons, and the distance to
// the outlines on the sphere.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <geos_c.h>

#include "coast_load_internal.hpp"
#include "coast_parallel.hpp"
#include "geos_handles.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"

namespace globemesh {

/// Vertices per piece of the coast in the distance index: short enough that a query's box
/// meets few of them, long enough that the tree stays small.
constexpr std::size_t piece_vertices = 16;

// The cells in front of the point-in-polygon test: lon/lat cells of 1/cells_per_degree degree
// (7 km at the equator), in blocks of block_side x block_side (one degree). A cell that no
// segment's box touches holds no outline, and neither does the side two such cells share: the
// cells of one component (such cells joined through their sides) lie all on land or all in the
// water, and GEOS is asked once per component, at the first point that falls in it, and at
// every point of a touched cell. The cell of a coordinate is floor((x + 180 or 90) *
// cells_per_degree), clamped to the grid: monotone in x in floating point too, so a segment lies
// in the cells between its ends' cells. A block's cells are numbered by the piece of the block
// they lie in (runs of each row joined with the row below), and the pieces joined across the
// blocks' sides into components (union-find). 1/16 degree: finer cells send few fewer tests to
// GEOS and take longer to build (bench/RESULTS-core-coast.md).
constexpr int cells_per_degree = 16;
constexpr int block_side = 16; // a block's row is 16 bits of a 64-bit word of `touched`
constexpr int cells_x = 360 * cells_per_degree, cells_y = 180 * cells_per_degree;
constexpr int blocks_x = cells_x / block_side, blocks_y = cells_y / block_side;
constexpr int block_cells = block_side * block_side;

int cell_of(double x, double origin, int cells) {
    const double c = std::floor((x + origin) * cells_per_degree);
    return c <= 0 ? 0 : c >= cells - 1 ? cells - 1 : static_cast<int>(c);
}

using coast_detail::GeomPtr;
using coast_detail::GeosDeleter;
using coast_detail::PreparedPtr;
using coast_detail::TreePtr;

// Members are destroyed in reverse order: each tree before the geometries it indexes, the
// prepared polygons before the polygons, the context last.
struct LandMask::Impl {
    coast_detail::Geos geos;
    GEOSContextHandle_t ctx = geos.get();
    std::vector<GeomPtr> polygons;
    std::vector<PreparedPtr> prepared;
    TreePtr tree;
    // The outlines (shells and holes) as unit vectors, cut into pieces of piece_vertices
    // vertices (the last one shared with the next piece), under an STR tree of their lon/lat
    // envelopes: the coast distance is measured on the sphere, segment by segment.
    std::vector<Vec3> outline;            // every piece's vertices, one piece after another
    std::vector<std::size_t> piece_start; // piece i is outline[piece_start[i], piece_start[i + 1])
    std::vector<GeomPtr> envelopes;
    TreePtr pieces;
    // The cells (see cells_per_degree): per cell, set when a segment's box touches it (built by
    // add_segments, then read by label_pieces); per block, the offset of its cells' piece
    // numbers in `piece` (0: a segment touches the cell, else 1 + the piece within the block)
    // or -1 when no segment touches the block (one piece), and the number of its first piece
    // among all; per piece, its component; per component, GEOS's answer (-1 not asked yet, 0
    // water, 1 land).
    std::vector<std::uint64_t> touched =
        std::vector<std::uint64_t>((std::size_t(cells_x) * cells_y + 63) / 64, 0);
    std::vector<std::int32_t> block_piece;
    std::vector<std::uint8_t> piece;
    std::vector<std::uint32_t> block_first;  // the number of the block's first piece among all
    std::vector<std::uint32_t> component;    // per piece, the component's first piece
    mutable std::vector<std::int8_t> answer; // per piece: used at the components' first pieces

    void add_outline(const std::vector<LonLat> &pts) {
        for (std::size_t first = 0; first + 1 < pts.size(); first += piece_vertices - 1) {
            const std::size_t last = std::min(first + piece_vertices, pts.size());
            double x0 = pts[first].lon, x1 = x0, y0 = pts[first].lat, y1 = y0;
            piece_start.push_back(outline.size());
            for (std::size_t k = first; k < last; ++k) {
                x0 = std::min(x0, pts[k].lon), x1 = std::max(x1, pts[k].lon);
                y0 = std::min(y0, pts[k].lat), y1 = std::max(y1, pts[k].lat);
                outline.push_back(lonlat_to_vec(pts[k].lon, pts[k].lat));
            }
            GeomPtr box(GEOSGeom_createRectangle_r(ctx, x0, y0, x1, y1), GeosDeleter{ctx});
            if (!box)
                throw DataError("coast: GEOS failed to build an envelope for the land test");
            envelopes.push_back(std::move(box));
        }
    }

    // Marks the cells of each segment's lon/lat box.
    void add_segments(const std::vector<LonLat> &pts) {
        for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
            const int x0 = cell_of(std::min(pts[k].lon, pts[k + 1].lon), 180, cells_x);
            const int x1 = cell_of(std::max(pts[k].lon, pts[k + 1].lon), 180, cells_x);
            const int y0 = cell_of(std::min(pts[k].lat, pts[k + 1].lat), 90, cells_y);
            const int y1 = cell_of(std::max(pts[k].lat, pts[k + 1].lat), 90, cells_y);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const std::size_t i = std::size_t(y) * cells_x + std::size_t(x);
                    touched[i / 64] |= std::uint64_t{1} << (i % 64);
                }
        }
    }

    // Numbers the pieces of every block that a segment touches (the runs of untouched cells of
    // its rows, joined with the row below), joins the pieces across the blocks' sides into
    // components, then lets the per-cell marks go.
    void label_pieces() {
        block_piece.assign(std::size_t(blocks_x) * blocks_y, -1);
        block_first.resize(block_piece.size());
        std::uint32_t pieces_in_all = 0;
        constexpr int words_x = cells_x / 64, blocks_per_word = 64 / block_side;
        std::vector<std::uint64_t> any_row(
            words_x); // the blocks of a row of blocks with a touched cell
        for (int by = 0; by < blocks_y; ++by) {
            std::fill(any_row.begin(), any_row.end(), 0);
            for (int y = 0; y < block_side; ++y)
                for (int w = 0; w < words_x; ++w)
                    any_row[w] |= touched[std::size_t(by * block_side + y) * words_x + w];
            for (int bx = 0; bx < blocks_x; ++bx) {
                const std::size_t b = std::size_t(by) * blocks_x + bx;
                const int shift = bx % blocks_per_word * block_side;
                block_first[b] = pieces_in_all;
                if (!static_cast<std::uint16_t>(any_row[bx / blocks_per_word] >> shift)) {
                    ++pieces_in_all;
                    continue;
                }
                std::uint16_t rows[block_side]; // a bit per touched cell
                for (int y = 0; y < block_side; ++y)
                    rows[y] = static_cast<std::uint16_t>(
                        touched[std::size_t(by * block_side + y) * words_x +
                                bx / blocks_per_word] >>
                        shift);
                const std::size_t first = piece.size();
                block_piece[b] = static_cast<std::int32_t>(first);
                piece.resize(first + block_cells, 0);
                std::uint8_t *cell = &piece[first];
                // The runs of untouched cells of each row, a label each (at most block_side / 2
                // a row), joined with the labels of the row below where they meet it.
                std::uint8_t parent[block_cells / 2 + 1];
                auto find = [&](std::uint8_t a) {
                    while (parent[a] != a)
                        a = parent[a] = parent[parent[a]];
                    return a;
                };
                std::uint8_t labels = 0;
                for (int y = 0; y < block_side; ++y) {
                    const unsigned free = ~unsigned{rows[y]} & 0xffffu;
                    for (int x = 0; x < block_side;) {
                        if (!(free >> x & 1u)) {
                            ++x;
                            continue;
                        }
                        const std::uint8_t label = ++labels;
                        parent[label] = label;
                        for (std::uint8_t last = 0; x < block_side && (free >> x & 1u); ++x) {
                            cell[y * block_side + x] = label;
                            const std::uint8_t below = y > 0 ? cell[(y - 1) * block_side + x] : 0;
                            if (below && below != last)
                                parent[find(below)] = find(label);
                            last = below;
                        }
                    }
                }
                // The pieces numbered 1, 2, ... in the order of their first labels.
                std::uint8_t number[block_cells / 2 + 1] = {}, of_label[block_cells / 2 + 1];
                std::uint8_t pieces = 0;
                for (std::uint8_t l = 1; l <= labels; ++l) {
                    std::uint8_t &n = number[find(l)];
                    if (!n)
                        n = ++pieces;
                    of_label[l] = n;
                }
                for (int c = 0; c < block_cells; ++c)
                    cell[c] = cell[c] ? of_label[cell[c]] : 0;
                pieces_in_all += pieces;
            }
        }
        // The components: pieces on both sides of a block side, each in a free cell, are one.
        component.resize(pieces_in_all);
        for (std::uint32_t k = 0; k < pieces_in_all; ++k)
            component[k] = k;
        auto root = [&](std::uint32_t k) {
            while (component[k] != k)
                k = component[k] = component[component[k]];
            return k;
        };
        auto join = [&](std::int64_t a, std::int64_t b) {
            if (a >= 0 && b >= 0)
                component[root(std::uint32_t(a))] = root(std::uint32_t(b));
        };
        for (int by = 0; by < blocks_y; ++by)
            for (int bx = 0; bx < blocks_x; ++bx) {
                const std::size_t b = std::size_t(by) * blocks_x + bx;
                const std::size_t right = b + 1,
                                  up = b + blocks_x; // the blocks beside it, when any
                if (bx + 1 < blocks_x) {
                    if (block_piece[b] < 0 && block_piece[right] < 0)
                        join(block_first[b], block_first[right]);
                    else
                        for (int y = 0; y < block_side; ++y)
                            join(piece_of(b, block_side - 1, y), piece_of(right, 0, y));
                }
                if (by + 1 < blocks_y) {
                    if (block_piece[b] < 0 && block_piece[up] < 0)
                        join(block_first[b], block_first[up]);
                    else
                        for (int x = 0; x < block_side; ++x)
                            join(piece_of(b, x, block_side - 1), piece_of(up, x, 0));
                }
            }
        for (std::uint32_t k = 0; k < pieces_in_all; ++k)
            component[k] = root(k);
        answer.assign(pieces_in_all, -1);
        piece.shrink_to_fit();
        std::vector<std::uint64_t>().swap(touched);
    }

    // The piece (among all) of cell (x, y) of block b, or -1 where a segment touches the cell.
    std::int64_t piece_of(std::size_t b, int x, int y) const {
        if (block_piece[b] < 0)
            return block_first[b];
        const std::uint8_t k =
            piece[std::size_t(block_piece[b]) + std::size_t(y) * block_side + std::size_t(x)];
        return k == 0 ? -1 : std::int64_t(block_first[b]) + k - 1;
    }

    // GEOS's answer: inside one of the polygons whose envelope holds the point.
    bool geos_contains(const LonLat &ll) const {
        const GeomPtr point(GEOSGeom_createPointFromXY_r(ctx, ll.lon, ll.lat), GeosDeleter{ctx});
        if (!point)
            throw DataError("coast: GEOS failed to build a point for the land test");
        struct Query {
            const Impl *m;
            const GEOSGeometry *point;
            bool inside = false;
        } q{this, point.get()};
        GEOSSTRtree_query_r(
            ctx, tree.get(), point.get(),
            [](void *item, void *data) {
                auto &q = *static_cast<Query *>(data);
                if (q.inside)
                    return;
                const auto i = reinterpret_cast<std::size_t>(item);
                q.inside = GEOSPreparedContains_r(q.m->ctx, q.m->prepared[i].get(), q.point) == 1;
            },
            &q);
        return q.inside;
    }

    GEOSGeometry *ring(const std::vector<LonLat> &pts) const {
        std::vector<double> xy;
        xy.reserve(2 * pts.size());
        for (const auto &p : pts) {
            xy.push_back(p.lon);
            xy.push_back(p.lat);
        }
        GEOSCoordSequence *seq = GEOSCoordSeq_copyFromBuffer_r(ctx, xy.data(), pts.size(), 0, 0);
        GEOSGeometry *r = seq ? GEOSGeom_createLinearRing_r(ctx, seq) : nullptr;
        if (!r)
            throw DataError("coast: GEOS failed to build a land ring for the land test");
        return r;
    }
};

LandMask::LandMask(const std::vector<std::vector<std::vector<LonLat>>> &polygons, bool every_core)
    : impl_(std::make_unique<Impl>()) {
    Impl &m = *impl_;
    std::vector<LonLat> probes; // a point of each polygon's shell
    for (const auto &rings : polygons) {
        if (rings.empty() || rings[0].size() < 4)
            continue;
        GEOSGeometry *shell = m.ring(rings[0]);
        std::vector<GEOSGeometry *> holes;
        for (std::size_t i = 1; i < rings.size(); ++i)
            if (rings[i].size() >= 4)
                holes.push_back(m.ring(rings[i]));
        GEOSGeometry *poly = GEOSGeom_createPolygon_r(m.ctx, shell, holes.data(),
                                                      static_cast<unsigned>(holes.size()));
        if (!poly)
            throw DataError("coast: GEOS failed to build a land polygon for the land test");
        m.polygons.emplace_back(poly, GeosDeleter{m.ctx});
        probes.push_back(rings[0][0]);
        for (const auto &r : rings) {
            if (r.size() >= 4) {
                m.add_outline(r);
                m.add_segments(r);
            }
            vertices_ += r.size();
        }
    }
    m.piece_start.push_back(m.outline.size());
    m.label_pieces();
    // Every polygon prepared now, its point locator built by a first test (GEOS builds it
    // lazily): the index belongs to loading the coast, not to the meshing that asks it. On every
    // core (every_core), the largest polygons first; each polygon's index is its own.
    m.prepared.resize(m.polygons.size());
    auto prepare = [&](coast_detail::Geos &g, std::size_t i) {
        m.prepared[i] =
            PreparedPtr(GEOSPrepare_r(g.get(), m.polygons[i].get()), GeosDeleter{m.ctx});
        if (!m.prepared[i])
            throw DataError("coast: GEOS failed to prepare a land polygon for the land test");
        const GeomPtr probe(GEOSGeom_createPointFromXY_r(g.get(), probes[i].lon, probes[i].lat),
                            GeosDeleter{g.get()});
        if (probe)
            GEOSPreparedContains_r(g.get(), m.prepared[i].get(), probe.get());
    };
    if (every_core) {
        std::vector<std::size_t> sizes(m.polygons.size());
        for (std::size_t i = 0; i < sizes.size(); ++i)
            sizes[i] = std::size_t(GEOSGetNumCoordinates_r(m.ctx, m.polygons[i].get()));
        const std::vector<std::size_t> first = coast_detail::largest_first(sizes);
        coast_detail::parallel_for_each_geos(m.geos, m.polygons.size(), prepare, &first);
    } else {
        for (std::size_t i = 0; i < m.polygons.size(); ++i)
            prepare(m.geos, i);
    }
    m.tree = TreePtr(GEOSSTRtree_create_r(m.ctx, 10), GeosDeleter{m.ctx});
    for (std::size_t i = 0; i < m.polygons.size(); ++i)
        GEOSSTRtree_insert_r(m.ctx, m.tree.get(), m.polygons[i].get(), reinterpret_cast<void *>(i));
    m.pieces = TreePtr(GEOSSTRtree_create_r(m.ctx, 10), GeosDeleter{m.ctx});
    for (std::size_t i = 0; i < m.envelopes.size(); ++i)
        GEOSSTRtree_insert_r(m.ctx, m.pieces.get(), m.envelopes[i].get(),
                             reinterpret_cast<void *>(i));
}

LandMask::~LandMask() = default;

std::function<std::shared_ptr<const LandTest>()> LandMask::copier() const {
    const Impl &m = *impl_;
    auto polygons = std::make_shared<std::vector<std::vector<std::vector<LonLat>>>>();
    polygons->reserve(m.polygons.size());
    for (const GeomPtr &polygon : m.polygons)
        polygons->push_back(coast_detail::polygon_rings(m.geos, polygon.get()));
    return [polygons]() -> std::shared_ptr<const LandTest> {
        return std::make_shared<LandMask>(*polygons, false);
    };
}

std::size_t LandMask::cell_bytes() const {
    const Impl &m = *impl_;
    return m.block_piece.capacity() * sizeof(std::int32_t) + m.piece.capacity() +
           m.block_first.capacity() * sizeof(std::uint32_t) +
           m.component.capacity() * sizeof(std::uint32_t) + m.answer.capacity();
}

bool LandMask::contains(const Vec3 &p) const {
    const Impl &m = *impl_;
    if (m.polygons.empty())
        return false;
    const LonLat ll = vec_to_lonlat(p);
    if (!std::isfinite(ll.lon) || !std::isfinite(ll.lat))
        return m.geos_contains(ll);
    const int x = cell_of(ll.lon, 180, cells_x), y = cell_of(ll.lat, 90, cells_y);
    const std::size_t b = std::size_t(y / block_side) * blocks_x + std::size_t(x / block_side);
    const std::int64_t k = m.piece_of(b, x % block_side, y % block_side);
    if (k < 0)
        return m.geos_contains(ll); // a cell the outline may cross
    std::int8_t &a = m.answer[m.component[std::size_t(k)]];
    if (a < 0)
        a = m.geos_contains(ll) ? 1 : 0;
    return a == 1;
}

/// Calls visit(k) for each outline segment k (outline[k] to outline[k + 1]) whose piece's box
/// meets the lon/lat box of the cap of radius `angle` round p, until visit returns true.
template <class Visit>
void LandMask::visit_segments_near(const Vec3 &p, double angle, Visit &&visit) const {
    const Impl &m = *impl_;
    if (m.envelopes.empty())
        return;
    // The lon/lat box of the cap (the whole band of longitudes near a pole), split in two where
    // it crosses +-180.
    const LonLat ll = vec_to_lonlat(p);
    const double dlat = angle * rad_to_deg;
    const double c = std::cos(ll.lat * deg_to_rad);
    // The cap's widest reach in longitude; it holds a pole where sin(angle) >= cos(lat).
    const double dlon = std::sin(angle) < c ? std::asin(std::sin(angle) / c) * rad_to_deg : 180;
    const double y0 = std::max(-90.0, ll.lat - dlat), y1 = std::min(90.0, ll.lat + dlat);
    std::vector<std::pair<double, double>> spans{{ll.lon - dlon, ll.lon + dlon}};
    if (dlon >= 180)
        spans = {{-180, 180}};
    else if (spans[0].first < -180)
        spans = {{-180, spans[0].second}, {spans[0].first + 360, 180}};
    else if (spans[0].second > 180)
        spans = {{spans[0].first, 180}, {-180, spans[0].second - 360}};
    struct Query {
        const Impl *m;
        std::remove_reference_t<Visit> *visit;
        bool done = false;
    } q{&m, &visit};
    for (const auto &[x0, x1] : spans) {
        const GeomPtr box(GEOSGeom_createRectangle_r(m.ctx, x0, y0, x1, y1), GeosDeleter{m.ctx});
        if (!box)
            throw DataError("coast: GEOS failed to build a query for the coast distance");
        GEOSSTRtree_query_r(
            m.ctx, m.pieces.get(), box.get(),
            [](void *item, void *data) {
                auto &q = *static_cast<Query *>(data);
                const auto i = reinterpret_cast<std::size_t>(item);
                for (std::size_t k = q.m->piece_start[i];
                     k + 1 < q.m->piece_start[i + 1] && !q.done; ++k)
                    q.done = (*q.visit)(k);
            },
            &q);
        if (q.done)
            break;
    }
}

bool LandMask::coast_within(const Vec3 &p, double angle) const {
    const std::vector<Vec3> &o = impl_->outline;
    bool near = false;
    visit_segments_near(
        p, angle, [&](std::size_t k) { return near = arc_distance(o[k], o[k + 1], p) <= angle; });
    return near;
}

double LandMask::coast_distance(const Vec3 &p, double reach) const {
    const std::vector<Vec3> &o = impl_->outline;
    double nearest = reach;
    visit_segments_near(p, reach, [&](std::size_t k) {
        nearest = std::min(nearest, arc_distance(o[k], o[k + 1], p));
        return false;
    });
    return nearest;
}

} // namespace globemesh
