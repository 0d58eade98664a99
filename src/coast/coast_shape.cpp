// Stage 2 of the coast: drop small rings, simplify to the local size with topology preserved,
// resample along great-circle arcs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "coast_internal.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"

namespace globemesh {
namespace {

/// Largest arc kept between two simplified nodes (radians): keeps arcs far below pi/2, where
/// the crossing test and "shorter arc" are unambiguous.
constexpr double max_simplified_arc = 0.25;

/// Area to the left of one closed ring on the unit sphere, steradians in [0, 4 pi).
double left_area_sr(const std::vector<Vec3> &nodes) {
    Vec3 sum{};
    for (const auto &v : nodes)
        sum = sum + v;
    Vec3 ref = norm(sum) > 1e-3 ? normalized(sum) : normalized(nodes[0] + Vec3{0.3, 0.5, 0.7});
    double s = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i)
        s += spherical_triangle_area(ref, nodes[i], nodes[(i + 1) % nodes.size()]);
    s = std::fmod(s, 4 * pi);
    if (s < 0)
        s += 4 * pi;
    return s;
}

/// Douglas-Peucker tolerance, as a fraction of the local size: every resampled node lies on the
/// simplified line, so within this of the source (the mesher's fidelity target is h/4).
constexpr double simplify_tolerance = 0.3;

/// The same for a node between two open segments (a region's outline), in the last pass: the
/// mesh stays inside the region. A box's parallel kept as its chord bulged past it (NE 1:50m,
/// the north-west shelf to 62N at 60 km: nodes at 62.127N, past the raster cut there).
constexpr double open_simplify_tolerance = 0.002;

/// A kept node where the simplified line turns by more than this is a corner: the resampled ring
/// passes through it. Elsewhere resampling cuts across the simplified line's small bends.
constexpr double corner_turn = 40.0 * deg_to_rad;

struct ShapedRing {
    const Ring *ring;
    std::vector<double> h_rad;       // target size at every node, radians
    std::vector<std::uint32_t> kept; // indices of kept nodes, increasing
    std::vector<bool> anchor;        // nodes that must stay
    std::vector<bool> corner;        // nodes the resampled ring must pass through
};

/// A node of a resampled ring: on the kept arc from source node `node` to the next kept one.
struct Sample {
    Vec3 p;
    std::uint32_t node;
};

/// A ring as last resampled: its samples, and per run (from corner `from` to corner `to`, as
/// source node indices) where its samples are.
struct Resampled {
    struct Run {
        std::uint32_t from, to;
        std::size_t offset, count;
    };
    std::vector<Sample> samples;
    std::vector<Run> runs;
};

/// Douglas-Peucker between kept nodes i < j (indices modulo n): keeps the node farthest from the
/// arc while it is farther than `tolerance` times the local size (`open_tolerance` between two
/// open segments), or while the arc is too long.
void simplify_span(const ShapedRing &s, std::uint32_t i, std::uint32_t j, double tolerance,
                   double open_tolerance, std::vector<bool> &keep) {
    const auto &nodes = s.ring->nodes;
    const auto &kinds = s.ring->kinds;
    std::uint32_t n = static_cast<std::uint32_t>(nodes.size());
    auto tolerance_at = [&](std::uint32_t k) {
        const bool open =
            kinds[k] == SegmentKind::open && kinds[(k + n - 1) % n] == SegmentKind::open;
        return open ? open_tolerance : tolerance;
    };
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{i, j}};
    while (!stack.empty()) {
        auto [a, b] = stack.back();
        stack.pop_back();
        if (b <= a + 1)
            continue;
        const Vec3 &pa = nodes[a % n];
        const Vec3 &pb = nodes[b % n];
        double worst = 0;
        std::uint32_t at = a + 1;
        for (std::uint32_t k = a + 1; k < b; ++k) {
            double r = arc_distance(pa, pb, nodes[k % n]) / (tolerance_at(k % n) * s.h_rad[k % n]);
            if (r > worst) {
                worst = r;
                at = k;
            }
        }
        bool too_long = arc_angle(pa, pb) > max_simplified_arc || pa == pb || norm(pa + pb) < 1e-9;
        if (worst > 1.0 || too_long) {
            if (worst <= 1.0)
                at = a + (b - a) / 2;
            keep[at % n] = true;
            stack.push_back({a, at});
            stack.push_back({at, b});
        }
    }
}

/// The ring resampled evenly: every corner stays, and each run of the simplified line between
/// two corners is cut into pieces of equal length in units of the local size (the integral of
/// ds / h along the line), as many as round that length, so that coast segments are about h long
/// and neighbours differ little. A ring without corners is one closed run from its first node.
/// `last` holds the ring as resampled before and gets it as now: a run between the same two
/// corners as then (no corner came between) is taken from it as it was, since nothing it is
/// made from has changed. `old_of` gets, per arc of the new ring, its arc in `last` with the
/// same two points, or ArcGrid::none.
template <class H>
void resample(const ShapedRing &s, const H &h_at, Resampled &last,
              std::vector<std::uint32_t> &old_of) {
    const auto &nodes = s.ring->nodes;
    const std::uint32_t m = static_cast<std::uint32_t>(s.kept.size());
    auto at = [&](std::uint32_t k) -> const Vec3 & { return nodes[s.kept[k % m]]; };
    std::vector<std::uint32_t> corners;
    for (std::uint32_t k = 0; k < m; ++k)
        if (s.corner[s.kept[k]])
            corners.push_back(k);
    if (corners.empty())
        corners.push_back(0);
    // Per run: its arcs' cumulative size-length at sample points, and the pieces it gets.
    struct Point {
        double along; // integral of ds / h from the run's start
        std::uint32_t arc;
        double t; // fraction along the arc
    };
    std::vector<std::vector<Point>> runs(corners.size());
    std::vector<long> pieces(corners.size());
    std::vector<const Resampled::Run *> same(corners.size(), nullptr); // the run of `last` to copy
    std::vector<const Resampled::Run *> by_from;
    for (const auto &r : last.runs)
        by_from.push_back(&r);
    std::sort(by_from.begin(), by_from.end(),
              [](const auto *x, const auto *y) { return x->from < y->from; });
    auto end_of = [&](std::size_t c) {
        return c + 1 < corners.size() ? corners[c + 1] : corners[0] + m;
    };
    auto measure = [&](std::size_t c) {
        const std::uint32_t first = corners[c], end = end_of(c);
        auto &run = runs[c];
        double along = 0;
        run.push_back({0, first % m, 0});
        for (std::uint32_t k = first; k < end; ++k) {
            const Vec3 &a = at(k);
            const Vec3 &b = at(k + 1);
            const double len = arc_angle(a, b);
            const double ha = s.h_rad[s.kept[k % m]], hb = s.h_rad[s.kept[(k + 1) % m]];
            const int steps = static_cast<int>(
                std::clamp(std::ceil(len / (0.25 * std::min(ha, hb))), 1.0, 4096.0));
            double h_prev = ha;
            for (int i = 1; i <= steps; ++i) {
                const double t = double(i) / steps;
                const double h = i == steps ? hb : h_at(arc_interpolate(a, b, t));
                along += len / steps * 0.5 * (1 / h_prev + 1 / h);
                run.push_back({along, k % m, t});
                h_prev = h;
            }
        }
        pieces[c] = std::max(1L, std::lround(along));
    };
    for (std::size_t c = 0; c < corners.size(); ++c) {
        const std::uint32_t from = s.kept[corners[c] % m], to = s.kept[end_of(c) % m];
        const auto it =
            std::lower_bound(by_from.begin(), by_from.end(), from,
                             [](const auto *r, std::uint32_t x) { return r->from < x; });
        if (it != by_from.end() && (*it)->from == from && (*it)->to == to) {
            same[c] = *it;
            pieces[c] = static_cast<long>((*it)->count);
        } else {
            measure(c);
        }
    }
    // A ring needs three nodes: add pieces where they are longest (every run measured then).
    if (std::accumulate(pieces.begin(), pieces.end(), 0L) < 3)
        for (std::size_t c = 0; c < corners.size(); ++c)
            if (same[c]) {
                same[c] = nullptr;
                measure(c);
            }
    for (long total = 0; (total = std::accumulate(pieces.begin(), pieces.end(), 0L)) < 3;) {
        std::size_t best = 0;
        for (std::size_t c = 1; c < runs.size(); ++c)
            if (runs[c].back().along / pieces[c] > runs[best].back().along / pieces[best])
                best = c;
        ++pieces[best];
    }
    Resampled now;
    std::vector<Sample> &out = now.samples;
    old_of.clear();
    for (std::size_t c = 0; c < runs.size(); ++c) {
        const std::size_t offset = out.size();
        if (const Resampled::Run *r = same[c]) {
            out.insert(out.end(), last.samples.begin() + static_cast<std::ptrdiff_t>(r->offset),
                       last.samples.begin() + static_cast<std::ptrdiff_t>(r->offset + r->count));
            for (std::size_t j = 0; j < r->count; ++j)
                old_of.push_back(static_cast<std::uint32_t>(r->offset + j));
            now.runs.push_back({r->from, r->to, offset, r->count});
            continue;
        }
        const auto &run = runs[c];
        out.push_back({at(corners[c]), s.kept[corners[c] % m]});
        std::size_t i = 1;
        for (long p = 1; p < pieces[c]; ++p) {
            const double want = run.back().along * double(p) / double(pieces[c]);
            while (run[i].along < want)
                ++i;
            const Point &lo = run[i - 1];
            const Point &hi = run[i];
            const double f = hi.along > lo.along ? (want - lo.along) / (hi.along - lo.along) : 0.0;
            const double t0 = lo.arc == hi.arc ? lo.t : 0.0;
            const double t = t0 + f * (hi.t - t0);
            out.push_back({arc_interpolate(at(hi.arc), at(hi.arc + 1), t), s.kept[hi.arc]});
        }
        old_of.resize(out.size(), coast_detail::ArcGrid::none);
        now.runs.push_back(
            {s.kept[corners[c] % m], s.kept[end_of(c) % m], offset, out.size() - offset});
    }
    last = std::move(now);
}

/// Step 1 of shape_boundary: the rings kept, each with its size at every node; the small ones
/// dropped are counted in `rep` and the islands among them added to `dropped_islands`.
template <class H>
std::vector<ShapedRing> drop_small_rings(const CoastData &coast, const H &h_at,
                                         const CoastOptions &options, CoastReport &rep,
                                         std::vector<std::vector<Vec3>> &dropped_islands) {
    // 1. Small rings: islands (land on the right smaller than a few triangles, or as small a
    //    hole in a region's outline: kept, a thin one came out of resampling as a triangle the
    //    other way round) and enclosed water bodies (ocean on the left that small, also a pocket
    //    of water that land cuts off at a region's edge).
    const double r2 = earth_radius_km * earth_radius_km;
    std::vector<ShapedRing> shaped;
    bool dropped_water = false;
    // The largest water ring on a region's outline stays whatever its size (a size wider than
    // the region is refused later, naming it).
    const auto &source = coast.rings.rings;
    std::vector<double> left_of(source.size()); // each ring's area on its left (sr)
    std::size_t largest_open = source.size();
    for (std::size_t r = 0; r < source.size(); ++r) {
        left_of[r] = left_area_sr(source[r].nodes);
        const auto &kinds = source[r].kinds;
        if (left_of[r] < 2 * pi &&
            std::find(kinds.begin(), kinds.end(), SegmentKind::open) != kinds.end() &&
            (largest_open == source.size() || left_of[r] > left_of[largest_open]))
            largest_open = r;
    }
    for (std::size_t r = 0; r < source.size(); ++r) {
        const Ring &ring = source[r];
        ShapedRing s{&ring, {}, {}, {}, {}};
        s.h_rad.reserve(ring.nodes.size());
        for (const auto &v : ring.nodes)
            s.h_rad.push_back(h_at(v));
        if (options.min_island_triangles > 0 && r != largest_open) {
            const double left = left_of[r];
            Vec3 sum{};
            for (const auto &v : ring.nodes)
                sum = sum + v;
            double hc = norm(sum) > 1e-9 ? h_at(normalized(sum)) : s.h_rad[0];
            double threshold = options.min_island_triangles * std::sqrt(3.0) / 4.0 * hc * hc;
            if (left < 2 * pi) { // a closed water body
                if (left < threshold) {
                    ++rep.lakes_removed;
                    rep.area_lost_km2 += left * r2;
                    dropped_water = true;
                    continue;
                }
            } else if (4 * pi - left < threshold) {
                ++rep.islands_removed;
                rep.area_gained_km2 += (4 * pi - left) * r2;
                dropped_islands.push_back(ring.nodes);
                continue;
            }
        }
        shaped.push_back(std::move(s));
    }
    if (shaped.empty() && dropped_water)
        throw DataError("the ocean of " + option("coast") + " " + options.coast +
                        " is smaller than a few triangles of the target size: lower the size or " +
                        option("min_island_triangles"));
    return shaped;
}

/// Corners: where the kind changes, and where the line turns sharply at the scale of h;
/// of two corners less than h/2 apart along the line, the one that turns less goes.
/// Marks them in s.corner among the nodes `keep` holds.
void mark_corners(ShapedRing &s, const std::vector<bool> &keep) {
    const Ring &ring = *s.ring;
    const std::uint32_t n = static_cast<std::uint32_t>(ring.nodes.size());
    s.corner.assign(n, false);
    std::vector<std::uint32_t> coarse;
    for (std::uint32_t i = 0; i < n; ++i)
        if (keep[i])
            coarse.push_back(i);
    const std::size_t m = coarse.size();
    std::vector<double> turn(m, 0.0);
    std::vector<char> must(m, 0);
    for (std::size_t k = 0; k < m; ++k) {
        const std::uint32_t i = coarse[k];
        must[k] = ring.kinds[i] != ring.kinds[(i + n - 1) % n];
        turn[k] = turn_angle(ring.nodes[coarse[(k + m - 1) % m]], ring.nodes[i],
                             ring.nodes[coarse[(k + 1) % m]]);
    }
    std::size_t prev = m; // the last corner kept, m: none yet
    double since = 0;     // line length from it, in units of h
    for (std::size_t k = 0; k < m; ++k) {
        if (k > 0) {
            const std::uint32_t a = coarse[k - 1], b = coarse[k];
            since += arc_angle(ring.nodes[a], ring.nodes[b]) / std::min(s.h_rad[a], s.h_rad[b]);
        }
        if (!must[k] && !(turn[k] > corner_turn))
            continue;
        if (prev < m && since < 0.5) {
            if (must[prev] || (!must[k] && turn[prev] >= turn[k]))
                continue;                   // k goes
            s.corner[coarse[prev]] = false; // prev goes
        }
        s.corner[coarse[k]] = true;
        prev = k;
        since = 0;
    }
}

/// Step 2 of shape_boundary, for one ring: Douglas-Peucker on the sphere between anchors (kind
/// changes, plus three spread nodes); s gets its anchors, corners and kept nodes.
void simplify_ring(ShapedRing &s) {
    const Ring &ring = *s.ring;
    std::uint32_t n = static_cast<std::uint32_t>(ring.nodes.size());
    std::vector<bool> keep(n, false);
    for (std::uint32_t i = 0; i < n; ++i)
        if (ring.kinds[i] != ring.kinds[(i + n - 1) % n])
            keep[i] = true;
    keep[0] = keep[n / 3] = keep[(2 * n) / 3] = true;
    s.anchor = keep;
    // The shape at the scale of h (tolerance h/2, nodes at least h/2 apart) gives the corners.
    auto simplify = [&](double tolerance, double open_tolerance) {
        std::vector<std::uint32_t> from;
        for (std::uint32_t i = 0; i < n; ++i)
            if (keep[i])
                from.push_back(i);
        for (std::size_t a = 0; a < from.size(); ++a)
            simplify_span(s, from[a], a + 1 < from.size() ? from[a + 1] : from[0] + n, tolerance,
                          open_tolerance, keep);
    };
    simplify(0.5, 0.5);
    // Thin nodes closer than half the local size to the previous kept node.
    std::uint32_t last = 0;
    for (std::uint32_t i = 1; i < n; ++i) {
        if (!keep[i])
            continue;
        if (!s.anchor[i] && arc_angle(ring.nodes[last], ring.nodes[i]) <
                                0.5 * std::min(s.h_rad[last], s.h_rad[i])) {
            std::uint32_t next = i + 1;
            while (next < n && !keep[next])
                ++next;
            std::uint32_t nn = next % n;
            // Only when the merged arc stays short and close to the dropped node.
            if (arc_angle(ring.nodes[last], ring.nodes[nn]) < max_simplified_arc &&
                arc_distance(ring.nodes[last], ring.nodes[nn], ring.nodes[i]) < 0.5 * s.h_rad[i]) {
                keep[i] = false;
                continue;
            }
        }
        last = i;
    }
    mark_corners(s, keep);
    // The line the nodes are placed on: within simplify_tolerance * h of the source.
    simplify(simplify_tolerance, open_simplify_tolerance);
    for (std::uint32_t i = 0; i < n; ++i)
        if (keep[i])
            s.kept.push_back(i);
}

/// The coast's nodes at the local size, at least (each arc over the larger size at its
/// ends): a size of metres asks a global coast for billions, refused here as the mesher
/// would refuse them, before the resampling spends the time and memory to make them.
void check_node_count(const std::vector<ShapedRing> &shaped, std::uint64_t max_nodes) {
    double coast_nodes = 0;
    for (const ShapedRing &s : shaped)
        for (std::size_t k = 0; k < s.kept.size(); ++k) {
            const std::uint32_t a = s.kept[k], b = s.kept[(k + 1) % s.kept.size()];
            coast_nodes +=
                arc_angle(s.ring->nodes[a], s.ring->nodes[b]) / std::max(s.h_rad[a], s.h_rad[b]);
        }
    if (coast_nodes > static_cast<double>(max_nodes))
        throw DataError("the coast alone asks for about " +
                        std::to_string(std::llround(coast_nodes)) +
                        " nodes at the target size, more than " + option("max_nodes") + " " +
                        std::to_string(max_nodes) + ": raise " + option("hmin_km") + "/" +
                        option("hmax_km") + " or " + option("max_nodes"));
}

/// Whether sample y lies on a region's outline: on an open source segment, or at a node that ends
/// one.
bool on_outline(const Ring &source, const Sample &y) {
    const std::size_t n = source.nodes.size();
    return source.kinds[y.node] == SegmentKind::open ||
           (y.p == source.nodes[y.node] && source.kinds[(y.node + n - 1) % n] == SegmentKind::open);
}

/// The kind of the shaped segment from sample x to sample y: its source segment's, but coast
/// where it would leave the outline. A kind change closer than h/2 to another corner goes with
/// the resampling, and the segment from the box edge to the coast beyond it (Porto Lagos at 41N,
/// 3-20 km: to 24.96E, 40.95N, across 9 km of coast) was open for the box edge it started on.
SegmentKind span_kind(const Ring &source, const Sample &x, const Sample &y) {
    const SegmentKind kind = source.kinds[x.node];
    return kind == SegmentKind::open && !on_outline(source, y) ? SegmentKind::coast : kind;
}

/// Step 3's last part: merge_close_samples on the resampled rings (every arc clear in `grid`),
/// for nodes closer than `gap` times the local size (CoastOptions::close_node_gap; dropping one
/// moves the coast by less than that, well within the fidelity target h/4). A sample can go
/// when it and the one before start coast segments and it is no anchor.
void merge_close(const std::vector<ShapedRing> &shaped, double gap,
                 std::vector<Resampled> &resampled, std::vector<std::vector<Vec3>> &rings,
                 coast_detail::ArcGrid &grid, CoastReport &rep) {
    if (gap <= 0)
        return;
    const std::size_t count = shaped.size();
    const std::vector<std::vector<Vec3>> points = rings; // the samples, as resampled
    std::vector<std::vector<double>> h(count);
    std::vector<std::vector<char>> movable(count);
    for (std::size_t r = 0; r < count; ++r) {
        const Ring &source = *shaped[r].ring;
        const std::vector<Sample> &x = resampled[r].samples;
        for (std::size_t k = 0; k < x.size(); ++k) {
            const std::uint32_t node = x[k].node, before = x[(k + x.size() - 1) % x.size()].node;
            h[r].push_back(shaped[r].h_rad[node]);
            movable[r].push_back(source.kinds[node] == SegmentKind::coast &&
                                 source.kinds[before] == SegmentKind::coast &&
                                 !(shaped[r].anchor[node] && x[k].p == source.nodes[node]));
        }
    }
    std::vector<std::vector<std::uint32_t>> kept;
    rep.close_nodes_merged +=
        coast_detail::merge_close_samples(points, h, movable, gap, rings, grid, kept);
    for (std::size_t r = 0; r < count; ++r) {
        if (kept[r].size() == resampled[r].samples.size())
            continue;
        std::vector<Sample> samples;
        for (const std::uint32_t k : kept[r])
            samples.push_back(resampled[r].samples[k]);
        resampled[r].samples = std::move(samples);
        resampled[r].runs.clear(); // (not resampled again)
    }
}

/// The source node that becomes a corner where the resampled arc p-q conflicts: the farthest
/// from p-q among the nodes whose projection falls between p and q (a corner there moves p-q
/// itself; one past its ends can leave p-q in conflict round after round: GSHHG full at 50 km
/// took 909 rounds, 3 this way), else the farthest in range; the ring's size when none is left.
std::uint32_t corner_under(const ShapedRing &s, const Sample &p, const Sample &q) {
    const std::uint32_t n = static_cast<std::uint32_t>(s.ring->nodes.size());
    // From p's arc's start to q's arc's end (the kept node after q's), or to q's node when q
    // lies on it: the nodes past it are not under p-q (DCW: 6,600 rounds at one conflict).
    std::uint32_t a = p.node;
    const auto after = std::upper_bound(s.kept.begin(), s.kept.end(), q.node);
    std::uint32_t b = q.p == s.ring->nodes[q.node] ? q.node
                      : after == s.kept.end()      ? s.kept.front()
                                                   : *after;
    if (b <= a)
        b += n;
    const Vec3 pole = cross(p.p, q.p);
    double worst = -1, worst_under = -1;
    std::uint32_t at = n, at_under = n;
    for (std::uint32_t k = a + 1; k < b; ++k) {
        if (s.corner[k % n])
            continue;
        const Vec3 &v = s.ring->nodes[k % n];
        const double d = arc_distance(p.p, q.p, v);
        if (d > worst)
            worst = d, at = k % n;
        if (d > worst_under && dot(cross(p.p, v), pole) >= 0 && dot(cross(v, q.p), pole) >= 0)
            worst_under = d, at_under = k % n;
    }
    return at_under < n ? at_under : at;
}

/// Step 3 of shape_boundary: the rings resampled until no two arcs touch or cross.
template <class H>
std::vector<Resampled> resample_clear(std::vector<ShapedRing> &shaped, const H &h_at, double gap,
                                      CoastReport &rep, const Progress &progress) {
    // 3. Resample, then topology: where a resampled arc touches or crosses another, the source
    //    node farthest from it (corner_under) becomes a corner, until no arcs conflict.
    //    This ends: with every source node a corner, the arcs lie on the source rings, which do
    //    not conflict.
    //    Each round after the first resamples only the runs that got a corner (resample) and
    //    tests only their new arcs (ArcGrid): the same rings and conflicts as doing it all again,
    //    in a fraction of the time (bench/RESULTS-core-coast.md).
    std::vector<Resampled> resampled(shaped.size());
    std::vector<std::vector<Vec3>> rings(shaped.size());
    std::vector<const std::vector<Vec3> *> ptrs;
    for (const auto &r : rings)
        ptrs.push_back(&r);
    std::vector<char> changed(shaped.size(), 1);
    std::optional<coast_detail::ArcGrid> grid;
    std::vector<std::uint32_t> old_of;
    for (int round = 0;; ++round) {
        for (std::size_t r = 0; r < shaped.size(); ++r) {
            if (!changed[r])
                continue;
            resample(shaped[r], h_at, resampled[r], old_of);
            rings[r].clear();
            rings[r].reserve(resampled[r].samples.size());
            for (const auto &x : resampled[r].samples)
                rings[r].push_back(x.p);
            if (grid)
                grid->replace(static_cast<std::uint32_t>(r), old_of);
        }
        if (grid)
            grid->update();
        else
            grid.emplace(ptrs);
        const auto conflicts = grid->conflicts();
        if (conflicts.empty())
            break;
        std::vector<std::vector<std::uint32_t>> insert(shaped.size());
        auto refine = [&](std::uint32_t r, std::uint32_t seg) {
            const auto &x = resampled[r].samples;
            const std::uint32_t at = corner_under(shaped[r], x[seg], x[(seg + 1) % x.size()]);
            if (at < shaped[r].ring->nodes.size())
                insert[r].push_back(at);
        };
        for (const auto &c : conflicts) {
            refine(c.ring_a, c.seg_a);
            refine(c.ring_b, c.seg_b);
        }
        bool progress_made = false;
        for (std::size_t r = 0; r < shaped.size(); ++r) {
            auto &s = shaped[r];
            changed[r] = 0;
            for (auto i : insert[r]) {
                if (s.corner[i])
                    continue;
                s.corner[i] = true;
                s.kept.push_back(i);
                ++rep.conflicts_repaired;
                changed[r] = 1;
            }
            if (!changed[r])
                continue;
            progress_made = true;
            std::sort(s.kept.begin(), s.kept.end());
            s.kept.erase(std::unique(s.kept.begin(), s.kept.end()), s.kept.end());
        }
        if (!progress_made) {
            const auto &c = conflicts.front();
            LonLat at = vec_to_lonlat(rings[c.ring_a][c.seg_a]);
            throw DataError("coast: rings touch or cross near lon " + std::to_string(at.lon) +
                            ", lat " + std::to_string(at.lat) +
                            " at full resolution; repair the coastline there");
        }
        report(progress, 0.5 + 0.4 * (1.0 - 1.0 / (round + 2)), "checking coast topology");
    }
    merge_close(shaped, gap, resampled, rings, *grid, rep);
    return resampled;
}

} // namespace

Boundary shape_boundary(const CoastData &coast, const SizeFn &size_km, const CoastOptions &options,
                        std::uint64_t max_nodes, CoastReport *report_out,
                        const Progress &progress) {
    if (!size_km)
        throw UsageError("shape_boundary: no size function given");
    CoastReport rep;
    rep.islands_removed = coast.islands_removed;
    rep.lakes_removed = coast.lakes_removed;
    rep.area_gained_km2 = coast.area_gained_km2;
    rep.area_lost_km2 = coast.area_lost_km2;
    report(progress, 0.0, "shaping coast");

    auto h_at = [&](const Vec3 &v) {
        double h = size_km(v);
        if (!(h > 0) || !std::isfinite(h))
            throw UsageError("the target size must be positive (got " + std::to_string(h) + " km)");
        return km_to_rad(h);
    };

    std::vector<std::vector<Vec3>> dropped_islands;
    std::vector<ShapedRing> shaped = drop_small_rings(coast, h_at, options, rep, dropped_islands);
    report(progress, 0.2, "simplifying coast");

    for (auto &s : shaped)
        simplify_ring(s);
    report(progress, 0.5, "resampling coast");
    check_node_count(shaped, max_nodes);

    const std::vector<Resampled> resampled =
        resample_clear(shaped, h_at, options.close_node_gap, rep, progress);

    Boundary out;
    for (std::size_t r = 0; r < shaped.size(); ++r) {
        const auto &s = shaped[r];
        Ring ring;
        const auto &samples = resampled[r].samples;
        ring.nodes.reserve(samples.size());
        ring.kinds.reserve(samples.size());
        for (std::size_t k = 0; k < samples.size(); ++k) {
            ring.nodes.push_back(samples[k].p);
            ring.kinds.push_back(span_kind(*s.ring, samples[k], samples[(k + 1) % samples.size()]));
        }
        out.rings.push_back(std::move(ring));
    }

    out.dropped_islands = std::move(dropped_islands);
    auto issues = check_boundary(out, 1);
    if (!issues.empty()) {
        const auto &is = issues.front();
        LonLat at = vec_to_lonlat(out.rings[is.ring].nodes[std::max(is.segment, 0L)]);
        throw DataError("coast: the shaped boundary has " + is.what + " near lon " +
                        std::to_string(at.lon) + ", lat " + std::to_string(at.lat));
    }
    rep.rings = out.rings.size();
    for (const auto &r : out.rings)
        rep.nodes += r.nodes.size();
    rep.ocean_area_km2 = boundary_area_km2(out);
    double dropped_net =
        rep.area_gained_km2 - coast.area_gained_km2 - (rep.area_lost_km2 - coast.area_lost_km2);
    double net = rep.ocean_area_km2 - (coast.ocean_area_km2 + dropped_net);
    if (net > 0)
        rep.area_gained_km2 += net;
    else
        rep.area_lost_km2 -= net;
    if (report_out)
        *report_out = rep;
    report(progress, 1.0, "coast shaped");
    return out;
}

} // namespace globemesh
