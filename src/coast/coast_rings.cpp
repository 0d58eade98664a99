// The ocean's rings on the sphere: the land's rings (the whole globe) or the region less the land,
// cut at the +-180 seam and the poles and stitched into closed rings with their segment kinds
// (coast or open), inland water dropped or kept, pinched nodes separated.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <geos_c.h>

#include "../delaunay/hilbert.hpp"
#include "coast_internal.hpp"
#include "coast_load_internal.hpp"
#include "globemesh/error.hpp"

namespace globemesh::coast_detail {
namespace {

/// Rings enclosing less than this (planar lon/lat, 1e-14 deg2, about 1e-4 m2) are slivers.
constexpr double min_ring_area_deg2 = 1e-14;
/// A region's outline takes the land's vertices within 2^-16 degree (1.7 m), so that the same
/// coast reprojected or clipped in another CRS (a few micro-degrees off) leaves no slivers.
constexpr double outline_snap_deg = 1.0 / (1 << 16);

enum class EdgeKind { coast, open, seam, pole };

struct Clip {
    bool box = false;
    double w = -180, s = -90, e = 180, n = 90;
    bool seam_glued = true;
    const GEOSPreparedGeometry *boundary = nullptr; // region file: its outline (prepared)
};

using NodeKey = std::pair<double, double>;
NodeKey node_key(const LonLat &p) {
    if (std::abs(p.lat) == 90.0)
        return {0.0, p.lat};
    return {std::abs(p.lon) == 180.0 ? 180.0 : p.lon, p.lat};
}

/// Point at fraction t of the planar lon/lat segment p-q, densifying long edges.
void append_densified(PointList &out, std::vector<SegmentKind> &kinds, const LonLat &p,
                      const LonLat &q, SegmentKind kind) {
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
    RingBuilder(Geos &geos, const Clip &clip) : geos_(geos), clip_(clip) {}

    EdgeKind classify(const LonLat &p, const LonLat &q) const {
        if (p.lat == q.lat && std::abs(p.lat) == 90.0)
            return EdgeKind::pole;
        if (p.lon == q.lon && std::abs(p.lon) == 180.0)
            return clip_.seam_glued ? EdgeKind::seam : EdgeKind::open;
        if (clip_.box) {
            if (p.lon == q.lon && (p.lon == clip_.w || p.lon == clip_.e))
                return EdgeKind::open;
            if (p.lat == q.lat && (p.lat == clip_.s || p.lat == clip_.n))
                return EdgeKind::open;
        } else if (clip_.boundary) {
            for (const LonLat &m : {p, q, LonLat{0.5 * (p.lon + q.lon), 0.5 * (p.lat + q.lat)}})
                if (!on_outline(m))
                    return EdgeKind::coast;
            return EdgeKind::open;
        }
        return EdgeKind::coast;
    }

    /// Whether a point lies on the region file's outline (within a snap cell: an edge noded at
    /// a hot pixel is still the outline).
    bool on_outline(const LonLat &m) const {
        GEOSCoordSequence *seq = GEOSCoordSeq_create_r(geos_.get(), 1, 2);
        GEOSCoordSeq_setXY_r(geos_.get(), seq, 0, m.lon, m.lat);
        GeomPtr pt = own(geos_, GEOSGeom_createPoint_r(geos_.get(), seq), "build a point");
        double d = 1;
        GEOSPreparedDistance_r(geos_.get(), clip_.boundary, pt.get(), &d);
        return d <= snap_grid_deg;
    }

    /// The kind of the seam from lat a to lat b with ocean on one side only (on its +180 side
    /// when `ocean_west`): coast, unless a region file ends at the seam there (its outline does
    /// not reach the other side).
    SegmentKind seam_kind(double a, double b, bool ocean_west) const {
        const LonLat other{ocean_west ? -180.0 : 180.0, 0.5 * (a + b)};
        return clip_.boundary && !on_outline(other) ? SegmentKind::open : SegmentKind::coast;
    }

    /// Adds one ring of an ocean polygon (closed, oriented with the ocean on the left). Returns
    /// false when the ring has no edge on the clip outline (enclosed by coast).
    bool add_ring(PointList pts) {
        std::size_t n = pts.size() - 1; // closed: pts[n] == pts[0]
        std::vector<EdgeKind> kinds(n);
        bool touches_outline = false, cut = false;
        for (std::size_t i = 0; i < n; ++i) {
            kinds[i] = classify(pts[i], pts[i + 1]);
            if (kinds[i] != EdgeKind::coast)
                touches_outline = true;
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole)
                cut = true;
        }
        auto seg_kind = [](EdgeKind k) {
            return k == EdgeKind::open ? SegmentKind::open : SegmentKind::coast;
        };
        if (!cut) {
            Chain c;
            c.pts.push_back(pts[0]);
            for (std::size_t i = 0; i < n; ++i)
                append_densified(c.pts, c.kinds, pts[i], pts[i + 1], seg_kind(kinds[i]));
            c.pts.pop_back(); // closed ring: last == first
            whole_.push_back(std::move(c));
            return touches_outline;
        }
        // Start right after a removed edge and cut the ring into chains.
        std::size_t start = 0;
        for (std::size_t i = 0; i < n; ++i)
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole)
                start = (i + 1) % n;
        Chain current;
        for (std::size_t k = 0; k < n; ++k) {
            std::size_t i = (start + k) % n;
            const LonLat &p = pts[i];
            const LonLat &q = pts[i + 1];
            if (kinds[i] == EdgeKind::seam || kinds[i] == EdgeKind::pole) {
                if (kinds[i] == EdgeKind::seam)
                    seam_.push_back({p.lat, q.lat});
                if (current.pts.size() >= 2)
                    chains_.push_back(std::move(current));
                current = Chain{};
                continue;
            }
            if (current.pts.empty())
                current.pts.push_back(p);
            append_densified(current.pts, current.kinds, p, q, seg_kind(kinds[i]));
        }
        if (current.pts.size() >= 2)
            chains_.push_back(std::move(current));
        return touches_outline;
    }

    /// Cancels seam edges that are glued to the opposite side, links the chains into closed
    /// rings and returns every ring (lon/lat, not closed, with segment kinds).
    std::vector<Chain> finish() {
        add_seam_leftovers();
        std::vector<Chain> rings = std::move(whole_);
        std::multimap<NodeKey, std::size_t> by_start;
        for (std::size_t i = 0; i < chains_.size(); ++i)
            by_start.insert({node_key(chains_[i].pts.front()), i});
        std::vector<bool> used(chains_.size(), false);
        for (std::size_t first = 0; first < chains_.size(); ++first) {
            if (used[first])
                continue;
            Chain ring;
            std::size_t cur = first;
            NodeKey start_key = node_key(chains_[first].pts.front());
            bool closed = false;
            for (std::size_t guard = 0; guard <= chains_.size() && !closed; ++guard) {
                used[cur] = true;
                const Chain &c = chains_[cur];
                std::size_t skip = ring.pts.empty() ? 0 : 1;
                ring.pts.insert(ring.pts.end(), c.pts.begin() + static_cast<long>(skip),
                                c.pts.end());
                ring.kinds.insert(ring.kinds.end(), c.kinds.begin(), c.kinds.end());
                NodeKey end_key = node_key(c.pts.back());
                std::size_t next = pick_next(c, end_key, by_start, used,
                                             end_key == start_key ? first : chains_.size());
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
            if (!closed)
                throw DataError("coast: the ocean outline does not close (inconsistent +-180 cut)");
            ring.pts.pop_back(); // the ring came back to its first node
            rings.push_back(std::move(ring));
        }
        return rings;
    }

private:
    void add_seam_leftovers() {
        if (seam_.empty())
            return;
        std::vector<double> lats;
        for (auto [a, b] : seam_) {
            lats.push_back(a);
            lats.push_back(b);
        }
        std::sort(lats.begin(), lats.end());
        lats.erase(std::unique(lats.begin(), lats.end()), lats.end());
        std::vector<long> net(lats.size(), 0);
        auto index = [&](double v) {
            return static_cast<std::size_t>(std::lower_bound(lats.begin(), lats.end(), v) -
                                            lats.begin());
        };
        for (auto [a, b] : seam_) {
            std::size_t i = index(a), j = index(b);
            if (i < j) {
                ++net[i];
                --net[j];
            } else if (j < i) {
                --net[j];
                ++net[i];
            }
        }
        long run = 0;
        for (std::size_t k = 0; k + 1 < lats.size(); ++k) {
            run += net[k];
            for (long c = 0; c < std::abs(run); ++c) {
                // Ocean on one side of the seam only: a (data) coast along the meridian, or
                // where a region file ends there its open edge. Going north the ocean on the
                // left is on the +180 side.
                Chain ch;
                LonLat lo{180.0, lats[k]}, hi{180.0, lats[k + 1]};
                ch.pts.push_back(run > 0 ? lo : hi);
                append_densified(ch.pts, ch.kinds, run > 0 ? lo : hi, run > 0 ? hi : lo,
                                 seam_kind(lats[k], lats[k + 1], run > 0));
                chains_.push_back(std::move(ch));
            }
        }
    }

    /// The unused chain starting at `key` that keeps the same face on the left: the first
    /// outgoing direction clockwise from the incoming one (seen from outside the sphere).
    std::size_t pick_next(const Chain &in, const NodeKey &key,
                          const std::multimap<NodeKey, std::size_t> &by_start,
                          const std::vector<bool> &used, std::size_t closing) const {
        auto [lo, hi] = by_start.equal_range(key);
        std::vector<std::size_t> options;
        if (closing != chains_.size())
            options.push_back(closing);
        for (auto it = lo; it != hi; ++it)
            if (!used[it->second])
                options.push_back(it->second);
        if (options.empty())
            return chains_.size();
        if (options.size() == 1)
            return options[0];
        Vec3 p = lonlat_to_vec(in.pts.back());
        Vec3 a = lonlat_to_vec(in.pts[in.pts.size() - 2]);
        Vec3 ta = a - dot(p, a) * p;
        std::size_t best = options[0];
        double best_ccw = -1;
        for (std::size_t o : options) {
            Vec3 b = lonlat_to_vec(chains_[o].pts[1]);
            Vec3 tb = b - dot(p, b) * p;
            double ccw = std::atan2(dot(p, cross(ta, tb)), dot(ta, tb));
            if (ccw <= 0)
                ccw += 2 * pi;
            if (ccw > best_ccw) {
                best_ccw = ccw;
                best = o;
            }
        }
        return best;
    }

    Geos &geos_;
    const Clip &clip_;
    std::vector<Chain> whole_;
    std::vector<Chain> chains_;
    std::vector<std::pair<double, double>> seam_;
};

/// Geodesic area to the left of densified chains (closed rings), km2.
double chains_area_km2(const std::vector<Chain> &chains) {
    std::vector<std::vector<LonLat>> ll;
    for (const auto &c : chains)
        ll.push_back(c.pts);
    return coast_detail::rings_area_km2(ll);
}

struct Bbox {
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    explicit Bbox(const PointList &pts) {
        for (const auto &p : pts) {
            x0 = std::min(x0, p.lon), y0 = std::min(y0, p.lat);
            x1 = std::max(x1, p.lon), y1 = std::max(y1, p.lat);
        }
    }
    bool inside(const Bbox &o) const {
        return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1;
    }
};

/// The --region box (two boxes when it crosses +-180), its sides on the snap grid; `clip` says so.
GeomPtr box_domain(Geos &geos, const std::array<double, 4> &region, Clip &clip) {
    auto [w, s, e, n] = region;
    if (!(s < n) || s < -90 || n > 90 || w < -180 || w > 180 || e < -180 || e > 180 || w == e)
        throw UsageError(option("region") +
                         " W,S,E,N: need -180 <= W, E <= 180, W != E, -90 <= S < N <= 90");
    // The box's sides on the land's snap grid, so that land clipped to the same box (data
    // downloaded for the area) meets them exactly instead of leaving slivers of ocean.
    auto on_grid = [](double v) { return std::nearbyint(v / snap_grid_deg) * snap_grid_deg; };
    w = on_grid(w), s = on_grid(s), e = on_grid(e), n = on_grid(n);
    clip.box = true;
    clip.w = w, clip.s = s, clip.e = e, clip.n = n;
    clip.seam_glued = w > e || (w == -180 && e == 180);
    std::vector<GeomPtr> boxes;
    if (w < e) {
        boxes.push_back(
            own(geos, GEOSGeom_createRectangle_r(geos.get(), w, s, e, n), "build the region"));
    } else {
        boxes.push_back(
            own(geos, GEOSGeom_createRectangle_r(geos.get(), w, s, 180, n), "build the region"));
        boxes.push_back(
            own(geos, GEOSGeom_createRectangle_r(geos.get(), -180, s, e, n), "build the region"));
    }
    GeomPtr domain = make_collection(geos, boxes);
    return own(geos, GEOSUnaryUnion_r(geos.get(), domain.get()), "build the region");
}

/// The --region-file polygons (`region`, as read_source read them), valid, dissolved and clipped
/// to the globe; `clip` gets their prepared outline (held in `outline` and `prepared_outline`).
GeomPtr file_domain(Geos &geos, const CoastOptions &options, const Source &region, Clip &clip,
                    GeomPtr &outline, PreparedPtr &prepared_outline) {
    std::vector<GeomPtr> rparts;
    for (const auto &poly : region.polygons)
        add_wrapped(geos, make_valid(geos, make_polygon(geos, poly).get()), rparts);
    if (rparts.empty())
        throw DataError(option("region_file") + " " + options.region_file + " holds no polygons");
    GeomPtr all = make_collection(geos, rparts);
    GeomPtr domain = own(geos, GEOSUnaryUnionPrec_r(geos.get(), all.get(), snap_grid_deg),
                         "dissolve the region");
    GeomPtr world = own(geos, GEOSGeom_createRectangle_r(geos.get(), -180, -90, 180, 90), "build");
    domain = own(geos, GEOSIntersectionPrec_r(geos.get(), domain.get(), world.get(), snap_grid_deg),
                 "clip the region");
    outline = own(geos, GEOSBoundary_r(geos.get(), domain.get()), "take the region outline");
    prepared_outline.reset(GEOSPrepare_r(geos.get(), outline.get()));
    clip.boundary = prepared_outline.get();
    // The region's pieces either side of +-180 join there (a polygon across it, or round a
    // pole); where it ends at the seam, the seam is open (seam_kind).
    clip.seam_glued = true;
    return domain;
}

/// Per point of `points` (sorted by z), the distance (radians) to the nearest arc of `b` that
/// does not end at it, or `reach` where none comes within reach (an arc's z range taken from its
/// ends: a long arc's bulge past them is missed, and its point keeps `reach`).
std::vector<double> clearance_from_arcs(const Boundary &b, const std::vector<Vec3> &points,
                                        double reach) {
    std::vector<double> near(points.size(), reach);
    for (const Ring &r : b.rings)
        for (std::size_t k = 0, n = r.nodes.size(); k < n; ++k) {
            const Vec3 &a = r.nodes[k], &c = r.nodes[(k + 1) % n];
            auto it = std::lower_bound(points.begin(), points.end(), std::min(a.z, c.z) - reach,
                                       [](const Vec3 &p, double z) { return p.z < z; });
            for (; it != points.end() && it->z <= std::max(a.z, c.z) + reach; ++it)
                if (!(*it == a) && !(*it == c)) {
                    double &d = near[std::size_t(it - points.begin())];
                    d = std::min(d, arc_distance(a, c, *it));
                }
        }
    return near;
}

} // namespace

double signed_planar_area(const PointList &pts) {
    // About the first vertex: a small ring far from lon/lat 0 keeps its sign.
    if (pts.empty())
        return 0;
    const LonLat o = pts.front();
    double a = 0;
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
        a += (pts[i].lon - o.lon) * (pts[i + 1].lat - o.lat) -
             (pts[i + 1].lon - o.lon) * (pts[i].lat - o.lat);
    return 0.5 * a;
}

void orient(PointList &pts, bool ccw) {
    if ((signed_planar_area(pts) > 0) != ccw)
        std::reverse(pts.begin(), pts.end());
}

/// Converts a lon/lat ring to unit vectors, dropping nodes equal to the previous one.
Ring to_sphere(const Chain &c) {
    // Nodes closer than 1e-14 rad (check_boundary's touching distance) are one node: the two
    // copies of a point where a ring crosses the +-180 seam come from two GEOS cuts (at 180 and
    // at -180 shifted by 360) and may differ in the last bit of the latitude.
    auto same = [](const Vec3 &a, const Vec3 &b) { return norm(a - b) <= 1e-14; };
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

namespace {

bool node_less(const Vec3 &p, const Vec3 &q) {
    return std::tie(p.x, p.y, p.z) < std::tie(q.x, q.y, q.z);
}

/// Whether ring r read from node i comes before it read from node j (node by node, once round).
bool rotation_less(const Ring &r, std::size_t i, std::size_t j) {
    const std::size_t n = r.nodes.size();
    for (std::size_t k = 0; k < n; ++k) {
        const Vec3 &p = r.nodes[(i + k) % n], &q = r.nodes[(j + k) % n];
        if (node_less(p, q))
            return true;
        if (node_less(q, p))
            return false;
    }
    return false;
}

/// The index ring r starts from: its smallest node, and where the ring passes that node more
/// than once, the pass from which it reads smallest.
std::size_t canonical_start(const Ring &r) {
    const auto first = std::min_element(r.nodes.begin(), r.nodes.end(), node_less);
    std::size_t best = static_cast<std::size_t>(first - r.nodes.begin());
    for (std::size_t i = best + 1; i < r.nodes.size(); ++i)
        if (r.nodes[i] == *first && rotation_less(r, i, best))
            best = i;
    return best;
}

} // namespace

void canonical_order(Boundary &b) {
    for (Ring &r : b.rings) {
        const auto shift = static_cast<std::ptrdiff_t>(canonical_start(r));
        std::rotate(r.nodes.begin(), r.nodes.begin() + shift, r.nodes.end());
        std::rotate(r.kinds.begin(), r.kinds.begin() + shift, r.kinds.end());
    }
    // Rings along the Hilbert curve by their first node (neighbours on the sphere stay
    // neighbours in the mesh's arrays), then node by node (rings that meet at their first node).
    std::vector<std::pair<std::uint32_t, std::size_t>> keyed;
    for (std::size_t i = 0; i < b.rings.size(); ++i)
        keyed.emplace_back(detail::hilbert_key(b.rings[i].nodes.front()), i);
    std::sort(keyed.begin(), keyed.end(), [&](const auto &x, const auto &y) {
        if (x.first != y.first)
            return x.first < y.first;
        const Ring &r = b.rings[x.second], &s = b.rings[y.second];
        if (std::lexicographical_compare(r.nodes.begin(), r.nodes.end(), s.nodes.begin(),
                                         s.nodes.end(), node_less))
            return true;
        if (std::lexicographical_compare(s.nodes.begin(), s.nodes.end(), r.nodes.begin(),
                                         r.nodes.end(), node_less))
            return false;
        return r.kinds < s.kinds;
    });
    std::vector<Ring> sorted;
    sorted.reserve(b.rings.size());
    for (const auto &[key, i] : keyed)
        sorted.push_back(std::move(b.rings[i]));
    b.rings = std::move(sorted);
}

/// Moves every copy of a node that several arcs share (rings meeting at one point, valid in
/// GEOS) by 1e-7 rad into the sector its own two arcs bound with no other arc inside: the land
/// on its right where two land polygons touch, the water on its left where a lake touches its
/// coast (the coast's land sector holds the lake's arcs: moved into it, each copy crossed the
/// other ring's arcs; GSHHG high's Evros delta with --keep-inland-seas). A copy moves at most a
/// quarter of its shorter arc, and of the distance to the nearest arc that does not end at the
/// node: between two countries' borders that touch at a point (the Digital Chart of the World),
/// a gap's arc of 3e-8 rad (Hungary and Slovakia on the Danube) and an arc passing 1e-6 degree
/// from the node (Croatia at Neum) were crossed by copies moved 1e-7 rad.
std::size_t separate_pinches(Boundary &b) {
    struct Occ {
        Vec3 v;
        std::uint32_t ring, index;
    };
    std::vector<Occ> occ;
    for (std::uint32_t r = 0; r < b.rings.size(); ++r)
        for (std::uint32_t i = 0; i < b.rings[r].nodes.size(); ++i)
            occ.push_back({b.rings[r].nodes[i], r, i});
    std::sort(occ.begin(), occ.end(), [](const Occ &a, const Occ &c) {
        return std::tie(a.v.x, a.v.y, a.v.z, a.ring, a.index) <
               std::tie(c.v.x, c.v.y, c.v.z, c.ring, c.index);
    });
    std::size_t moved = 0;
    constexpr double delta = 1e-7;
    std::vector<std::array<Vec3, 2>> arcs; // per copy: the tangents towards its node before, after
    std::vector<Vec3> to;
    std::vector<double> reach; // per copy: how far it moves
    // The shared nodes, by z, and how far each lies from the arcs that do not end at it.
    std::vector<Vec3> shared;
    for (std::size_t i = 0; i + 1 < occ.size(); ++i)
        if (occ[i + 1].v == occ[i].v && (shared.empty() || !(shared.back() == occ[i].v)))
            shared.push_back(occ[i].v);
    auto z_first = [](const Vec3 &p, const Vec3 &q) {
        return std::tie(p.z, p.x, p.y) < std::tie(q.z, q.x, q.y);
    };
    std::sort(shared.begin(), shared.end(), z_first);
    const std::vector<double> clear = clearance_from_arcs(b, shared, 4 * delta);
    for (std::size_t i = 0; i < occ.size();) {
        std::size_t j = i + 1;
        while (j < occ.size() && occ[j].v == occ[i].v)
            ++j;
        if (j - i > 1) {
            const Vec3 p = occ[i].v;
            const auto at = std::lower_bound(shared.begin(), shared.end(), p, z_first);
            const double clearance = clear[std::size_t(at - shared.begin())];
            auto tangent = [&](const Vec3 &q) { return normalized(q - dot(p, q) * p); };
            arcs.clear();
            reach.clear();
            for (std::size_t k = i; k < j; ++k) {
                const auto &nodes = b.rings[occ[k].ring].nodes;
                const std::size_t n = nodes.size(), at = occ[k].index;
                const Vec3 &before = nodes[(at + n - 1) % n], &after = nodes[(at + 1) % n];
                arcs.push_back({tangent(before), tangent(after)});
                reach.push_back(std::min(delta, 0.25 * std::min({arc_angle(p, before),
                                                                 arc_angle(p, after), clearance})));
            }
            // The counter-clockwise angle from tangent s to tangent t, in (0, 2 pi].
            auto sweep = [&](const Vec3 &s, const Vec3 &t) {
                const double theta = std::atan2(dot(p, cross(s, t)), dot(s, t));
                return theta <= 0 ? theta + 2 * pi : theta;
            };
            // Whether another copy's arc lies strictly inside the sweep from s by theta.
            auto holds_other = [&](std::size_t own, const Vec3 &s, double theta) {
                for (std::size_t k = 0; k < arcs.size(); ++k)
                    for (const Vec3 &t : arcs[k])
                        if (k != own && sweep(s, t) < theta)
                            return true;
                return false;
            };
            to.clear();
            for (std::size_t k = 0; k < arcs.size(); ++k) {
                // The land is the sector swept counter-clockwise from the incoming arc to the
                // outgoing one, the water the rest.
                const auto &[ta, tc] = arcs[k];
                Vec3 from = ta;
                double theta = sweep(ta, tc);
                if (holds_other(k, ta, theta) && !holds_other(k, tc, 2 * pi - theta)) {
                    from = tc;
                    theta = 2 * pi - theta;
                }
                const Vec3 u =
                    std::cos(0.5 * theta) * from + std::sin(0.5 * theta) * cross(p, from);
                to.push_back(normalized(p + reach[k] * u));
            }
            for (std::size_t k = i; k < j; ++k)
                b.rings[occ[k].ring].nodes[occ[k].index] = to[k - i];
            moved += j - i;
        }
        i = j;
    }
    return moved;
}

/// The ocean of the whole globe: the land's rings reversed (ocean on the left), cut at the
/// seam and the poles and stitched. Holes of the land are inland water bodies: kept with
/// keep_inland_seas, otherwise dropped with every land polygon inside them, unless nothing else
/// is ocean (then the largest stays).
std::vector<Chain> world_rings(Geos &geos, const std::vector<GeomPtr> &land, bool keep_inland_seas,
                               CoastData &out) {
    struct Poly {
        PointList shell;
        std::vector<PointList> holes;
        const GEOSGeometry *geometry;
    };
    std::vector<Poly> polys;
    for (const auto &g : land) {
        Poly p;
        p.geometry = g.get();
        p.shell = ring_points(geos, GEOSGetExteriorRing_r(geos.get(), g.get()));
        if (std::abs(signed_planar_area(p.shell)) < min_ring_area_deg2)
            continue;
        orient(p.shell, false);
        for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), g.get()); ++h) {
            PointList hole = ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), g.get(), h));
            if (std::abs(signed_planar_area(hole)) < min_ring_area_deg2)
                continue; // zero-area sliver
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
        for (const auto &p : polys)
            boxes.emplace_back(p.shell);
        for (std::size_t k = 0; k < polys.size(); ++k) {
            for (const auto &hole : polys[k].holes) {
                Lake lake;
                lake.rings.push_back(hole);
                Bbox hb(hole);
                GeomPtr ring = make_ring(geos, hole);
                GeomPtr poly =
                    own(geos, GEOSGeom_createPolygon_r(geos.get(), ring.release(), nullptr, 0),
                        "build a lake");
                PreparedPtr prepared(GEOSPrepare_r(geos.get(), poly.get()),
                                     GeosDeleter{geos.get()});
                for (std::size_t j = 0; j < polys.size(); ++j) {
                    if (j == k || !boxes[j].inside(hb))
                        continue;
                    GeomPtr inner = own(geos, GEOSPointOnSurface_r(geos.get(), polys[j].geometry),
                                        "find an inner point");
                    if (GEOSPreparedContainsProperly_r(geos.get(), prepared.get(), inner.get()) !=
                        1)
                        continue;
                    in_lake[j] = true;
                    lake.rings.push_back(polys[j].shell);
                    for (const auto &h : polys[j].holes)
                        lake.rings.push_back(h);
                }
                lakes.push_back(std::move(lake));
            }
        }
    }
    for (std::size_t k = 0; k < polys.size(); ++k) {
        if (in_lake[k])
            continue;
        main.add_ring(polys[k].shell);
        if (keep_inland_seas)
            for (const auto &h : polys[k].holes)
                main.add_ring(h);
    }
    std::vector<Chain> rings = main.finish();
    std::vector<double> lake_area;
    std::vector<std::vector<Chain>> lake_chains;
    for (const auto &lake : lakes) {
        RingBuilder single(geos, clip);
        for (const auto &r : lake.rings)
            single.add_ring(r);
        lake_chains.push_back(single.finish());
        lake_area.push_back(chains_area_km2(lake_chains.back()));
    }
    std::size_t largest = lakes.size();
    if (rings.empty() && !lakes.empty())
        largest = static_cast<std::size_t>(std::max_element(lake_area.begin(), lake_area.end()) -
                                           lake_area.begin());
    for (std::size_t i = 0; i < lakes.size(); ++i) {
        if (i == largest) {
            for (auto &c : lake_chains[i])
                rings.push_back(std::move(c));
            continue;
        }
        ++out.lakes_removed;
        out.area_lost_km2 += lake_area[i];
    }
    if (rings.empty() && !land.empty())
        throw DataError("coast: no ocean is left (the land covers the whole globe)");
    return rings;
}

/// How far inside the region's outline a piece of land must lie to skip the overlay (degrees,
/// 64 times outline_snap_deg: about 100 m).
constexpr double interior_margin_deg = 64 * outline_snap_deg;

/// The dissolved land pieces near a region: those wholly inside it, interior_margin_deg clear of
/// its outline and without lakes, and the others.
struct RegionLand {
    std::vector<GeomPtr> interior, rest;
};

RegionLand split_interior(Geos &geos, const GEOSGeometry *domain, std::vector<GeomPtr> &pieces) {
    PreparedPtr prepared(GEOSPrepare_r(geos.get(), domain), GeosDeleter{geos.get()});
    RegionLand out;
    for (auto &p : pieces) {
        double x0, y0, x1, y1;
        GEOSGeom_getExtent_r(geos.get(), p.get(), &x0, &y0, &x1, &y1);
        const double m = interior_margin_deg;
        const GeomPtr box = own(
            geos, GEOSGeom_createRectangle_r(geos.get(), x0 - m, y0 - m, x1 + m, y1 + m), "box");
        const bool inside =
            GEOSGetNumInteriorRings_r(geos.get(), p.get()) == 0 &&
            GEOSPreparedContainsProperly_r(geos.get(), prepared.get(), box.get()) == 1;
        (inside ? out.interior : out.rest).push_back(std::move(p));
    }
    pieces.clear();
    return out;
}

std::vector<std::size_t> polygons_holding(Geos &geos,
                                          const std::vector<const GEOSGeometry *> &outer,
                                          const std::vector<GeomPtr> &inner) {
    std::vector<PreparedPtr> prepared;
    std::vector<std::array<double, 4>> extent(outer.size());
    for (std::size_t i = 0; i < outer.size(); ++i) {
        prepared.emplace_back(GEOSPrepare_r(geos.get(), outer[i]), GeosDeleter{geos.get()});
        auto &e = extent[i];
        GEOSGeom_getExtent_r(geos.get(), outer[i], &e[0], &e[1], &e[2], &e[3]);
    }
    std::vector<std::size_t> holder(inner.size(), outer.size());
    for (std::size_t k = 0; k < inner.size(); ++k) {
        const GeomPtr at =
            own(geos, GEOSPointOnSurface_r(geos.get(), inner[k].get()), "find an inner point");
        double x, y;
        GEOSGeomGetX_r(geos.get(), at.get(), &x);
        GEOSGeomGetY_r(geos.get(), at.get(), &y);
        for (std::size_t i = 0; i < outer.size() && holder[k] == outer.size(); ++i) {
            const auto &e = extent[i];
            if (x > e[0] && x < e[2] && y > e[1] && y < e[3] &&
                GEOSPreparedContainsProperly_r(geos.get(), prepared[i].get(), at.get()) == 1)
                holder[k] = i;
        }
    }
    return holder;
}

std::vector<GeomPtr> source_holes(Geos &geos, const std::vector<PolygonRings> &polygons) {
    std::vector<GeomPtr> holes;
    for (const PolygonRings &p : polygons)
        for (std::size_t h = 1; h < p.size(); ++h) {
            if (p[h].size() < 4)
                continue;
            GeomPtr g = make_polygon(geos, PolygonRings{p[h]});
            if (GEOSisValid_r(geos.get(), g.get()) != 1)
                g = make_valid(geos, g.get());
            add_wrapped(geos, std::move(g), holes);
        }
    return holes;
}

/// True when the water polygon p lies in one of `holes` (source_holes): a lake, not the ocean.
bool in_a_hole(Geos &geos, const std::vector<GeomPtr> &holes, const GEOSGeometry *p) {
    if (holes.empty())
        return false;
    GeomPtr at = own(geos, GEOSPointOnSurface_r(geos.get(), p), "find an inner point");
    for (const auto &h : holes)
        if (GEOSContains_r(geos.get(), h.get(), at.get()) == 1)
            return true;
    return false;
}

/// The ocean of a region (--region box, two boxes across +-180, or --region-file polygons):
/// region minus land with GEOS, its rings with region edges tagged open.
std::vector<Chain> region_rings(Geos &geos, std::vector<GeomPtr> &land,
                                const std::vector<GeomPtr> &holes, const CoastOptions &options,
                                const Source *region_file, const ErrorText &where, CoastData &out) {
    Clip clip;
    GeomPtr domain;
    PreparedPtr prepared_outline(nullptr, GeosDeleter{geos.get()});
    GeomPtr outline;
    if (options.region && !options.region_file.empty())
        throw UsageError(option("region") + " and " + option("region_file") +
                         " exclude each other: give one");
    if (options.region) {
        domain = box_domain(geos, *options.region, clip);
    } else {
        domain = file_domain(geos, options, *region_file, clip, outline, prepared_outline);
    }
    // Only the land near the region matters: cut it to the region's extent first (fast).
    double x0, y0, x1, y1;
    GEOSGeom_getExtent_r(geos.get(), domain.get(), &x0, &y0, &x1, &y1);
    std::vector<GeomPtr> near;
    for (auto &g : land) {
        double a0, b0, a1, b1;
        GEOSGeom_getExtent_r(geos.get(), g.get(), &a0, &b0, &a1, &b1);
        if (a1 < x0 || a0 > x1 || b1 < y0 || b0 > y1)
            continue;
        near.push_back(clip_to_box(geos, g.get(), x0, y0, x1, y1, "clip the land"));
    }
    // The land is dissolved already (load_coast): its pieces cut to the region go through the
    // same dissolve, which puts the cuts on the snap grid and unions only the pieces that meet
    // or nearly meet (one snap-rounding union of every piece took 35 s for the Arctic in GSHHG
    // high, 0.6 s for the whole globe's rings).
    SnapCount unused;
    std::vector<GeomPtr> dissolved = dissolve(geos, near, snap_grid_deg, unused);
    // The pieces wholly inside the region are the ocean's holes as they are: the overlay places
    // each hole in its polygon by a search that grows as their number squared in GEOS 3.11 (the
    // Arctic in GSHHG high: 7 s of 12). Only the others go through it.
    RegionLand pieces = split_interior(geos, domain.get(), dissolved);
    std::vector<GEOSGeometry *> raw;
    for (auto &p : pieces.rest)
        raw.push_back(p.release());
    GeomPtr land_near = own(geos,
                            GEOSGeom_createCollection_r(geos.get(), GEOS_MULTIPOLYGON, raw.data(),
                                                        static_cast<unsigned>(raw.size())),
                            "collect the land");
    // An outline that runs along the coast (land clipped to the region, or the region drawn
    // from the same data in another CRS) follows the land there: it takes the land's vertices
    // within outline_snap_deg, so no sliver of water is left between the two.
    domain = own(geos, GEOSSnap_r(geos.get(), domain.get(), land_near.get(), outline_snap_deg),
                 "snap the region to the coast");
    if (GEOSisValid_r(geos.get(), domain.get()) != 1)
        domain = make_valid(geos, domain.get());
    // On the land's snap grid: where the land runs along the outline (clipped to the same box or
    // polygon), the two meet exactly, and slivers narrower than half a cell collapse.
    GeomPtr ocean =
        own(geos, GEOSDifferencePrec_r(geos.get(), domain.get(), land_near.get(), snap_grid_deg),
            "subtract the land");

    std::vector<const GEOSGeometry *> ocean_polys;
    polygons_of(geos, ocean.get(), ocean_polys);
    if (ocean_polys.empty())
        throw DataError(where +
                        ": no ocean is left in the region (it is all land); widen the region");
    std::vector<double> planar_area(ocean_polys.size());
    for (std::size_t i = 0; i < ocean_polys.size(); ++i)
        GEOSArea_r(geos.get(), ocean_polys[i], &planar_area[i]);
    const std::vector<std::size_t> holder = polygons_holding(geos, ocean_polys, pieces.interior);
    std::vector<std::vector<PointList>> island_holes(ocean_polys.size());
    for (std::size_t k = 0; k < pieces.interior.size(); ++k) {
        if (holder[k] == ocean_polys.size())
            continue;
        double area;
        GEOSArea_r(geos.get(), pieces.interior[k].get(), &area);
        planar_area[holder[k]] -= area;
        island_holes[holder[k]].push_back(
            ring_points(geos, GEOSGetExteriorRing_r(geos.get(), pieces.interior[k].get())));
    }

    RingBuilder builder(geos, clip);
    // Water bodies with no edge on the region outline, or in a hole of the land (a lake the
    // outline cuts), are inland seas (dropped unless keep_inland_seas, or unless nothing else
    // is ocean: then the largest stays).
    std::vector<std::pair<std::size_t, std::vector<PointList>>> inland;
    for (std::size_t i = 0; i < ocean_polys.size(); ++i) {
        const GEOSGeometry *p = ocean_polys[i];
        std::vector<PointList> prings;
        prings.push_back(ring_points(geos, GEOSGetExteriorRing_r(geos.get(), p)));
        if (std::abs(signed_planar_area(prings.back())) < min_ring_area_deg2)
            continue;
        orient(prings.back(), true);
        for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), p); ++h) {
            PointList hole = ring_points(geos, GEOSGetInteriorRingN_r(geos.get(), p, h));
            if (std::abs(signed_planar_area(hole)) < min_ring_area_deg2)
                continue; // zero-area sliver
            orient(hole, false);
            prings.push_back(std::move(hole));
        }
        for (PointList &hole : island_holes[i]) {
            if (std::abs(signed_planar_area(hole)) < min_ring_area_deg2)
                continue;
            orient(hole, false);
            prings.push_back(std::move(hole));
        }
        bool outline_edge = false;
        for (const auto &r : prings)
            for (std::size_t j = 0; j + 1 < r.size() && !outline_edge; ++j)
                outline_edge = builder.classify(r[j], r[j + 1]) != EdgeKind::coast;
        if (options.keep_inland_seas || (outline_edge && !in_a_hole(geos, holes, p))) {
            for (auto &r : prings)
                builder.add_ring(std::move(r));
        } else {
            inland.push_back({i, std::move(prings)});
        }
    }
    std::vector<Chain> rings = builder.finish();
    std::size_t largest = inland.size();
    if (rings.empty())
        for (std::size_t k = 0; k < inland.size(); ++k)
            if (largest == inland.size() ||
                planar_area[inland[k].first] > planar_area[inland[largest].first])
                largest = k;
    for (std::size_t k = 0; k < inland.size(); ++k) {
        RingBuilder single(geos, clip);
        for (auto &r : inland[k].second)
            single.add_ring(r);
        std::vector<Chain> chains = single.finish();
        if (k == largest) {
            for (auto &c : chains)
                rings.push_back(std::move(c));
        } else {
            ++out.lakes_removed;
            out.area_lost_km2 += chains_area_km2(chains);
        }
    }
    return rings;
}

} // namespace globemesh::coast_detail
