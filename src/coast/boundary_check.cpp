// Invariant checks of a Boundary on the sphere (double precision) and its geodesic area.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include "coast_internal.hpp"
#include "coast_parallel.hpp"
#include "globemesh/coast.hpp"

namespace globemesh {
namespace coast_detail {

namespace {

constexpr double touch_eps = 1e-14;

int side(double d) {
    return d > touch_eps ? 1 : (d < -touch_eps ? -1 : 0);
}

/// True when p (on the great circle of arc a-b, normal n) lies within the arc.
bool within_arc(const Vec3 &a, const Vec3 &b, const Vec3 &n, const Vec3 &p) {
    return dot(cross(a, p), n) >= -touch_eps && dot(cross(p, b), n) >= -touch_eps;
}

} // namespace

/// a x b computed as (a + b) x (b - a) / 2, accurate also for nearby points (S2's robust cross
/// product): its direction error stays near one ulp however short the arc.
Vec3 robust_cross(const Vec3 &a, const Vec3 &b) {
    return 0.5 * cross(a + b, b - a);
}

bool arcs_conflict(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d) {
    if (dot(a + b, c + d) <= 0)
        return false; // far apart (arcs are shorter than pi/2 here)
    Vec3 n1 = robust_cross(a, b), n2 = robust_cross(c, d);
    double l1 = norm(n1), l2 = norm(n2);
    if (l1 == 0 || l2 == 0)
        return true; // degenerate arc: treat as a conflict
    n1 = (1.0 / l1) * n1;
    n2 = (1.0 / l2) * n2;
    int sa = side(dot(n2, a)), sb = side(dot(n2, b));
    int sc = side(dot(n1, c)), sd = side(dot(n1, d));
    if (sa * sb > 0 || sc * sd > 0)
        return false;
    Vec3 x = cross(n1, n2);
    double lx = norm(x);
    if ((sa == 0 && sb == 0) || (sc == 0 && sd == 0) || lx < 1e-12) { // one great circle: overlap?
        return within_arc(a, b, n1, c) || within_arc(a, b, n1, d) || within_arc(c, d, n2, a) ||
               within_arc(c, d, n2, b);
    }
    // Each arc's ends straddle (or touch) the other's great circle: they meet iff the meeting
    // point lies on the same side for both arcs.
    x = (1.0 / lx) * x;
    double s1 = dot(x, a + b), s2 = dot(x, c + d);
    if (std::abs(s1) < touch_eps || std::abs(s2) < touch_eps)
        return true;
    return (s1 > 0) == (s2 > 0);
}

ArcGrid::ArcGrid(const std::vector<const std::vector<Vec3> *> &rings) : rings_(rings) {
    double total = 0;
    std::size_t count = 0;
    for (const auto *ring : rings)
        for (std::size_t i = 0; i < ring->size(); ++i, ++count)
            total += norm((*ring)[i] - (*ring)[(i + 1) % ring->size()]);
    // Cell size: a few mean chords, bounded so the grid stays small.
    cell_ = count == 0 ? 0.05 : std::clamp(4.0 * total / static_cast<double>(count), 2e-5, 0.05);
    ids_of_.resize(rings.size());
    for (std::uint32_t r = 0; r < rings.size(); ++r)
        for (std::uint32_t i = 0; i < rings[r]->size(); ++i)
            ids_of_[r].push_back(add_arc(r, i, entries_));
    test_cells(entries_, [](std::size_t, std::size_t) {});
    settle();
}

// Sorts `entries` (each once), tests every two arcs that share a cell, and calls also(i, j)
// with each cell's run entries[i, j).
template <class Also> void ArcGrid::test_cells(std::vector<Entry> &entries, Also &&also) {
    std::sort(entries.begin(), entries.end());
    entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
    for (std::size_t i = 0; i < entries.size();) {
        std::size_t j = i;
        while (j < entries.size() && entries[j].first == entries[i].first)
            ++j;
        for (std::size_t p = i; p < j; ++p)
            for (std::size_t q = p + 1; q < j; ++q)
                test(entries[p].second, entries[q].second);
        also(i, j);
        i = j;
    }
}

std::uint32_t ArcGrid::add_arc(std::uint32_t r, std::uint32_t i, std::vector<Entry> &entries) {
    const auto id = static_cast<std::uint32_t>(ring_.size());
    ring_.push_back(r);
    index_.push_back(i);
    alive_.push_back(1);
    const auto &nodes = *rings_[r];
    const Vec3 &a = nodes[i];
    const Vec3 &b = nodes[(i + 1) % nodes.size()];
    const double chord = norm(a - b);
    // The arc bulges out of the chord's box by at most chord^2 / 8 (plus rounding).
    const double bulge = 1e-12 + 0.125 * chord * chord;
    boxes_.push_back(
        {{std::min(a.x, b.x) - bulge, std::min(a.y, b.y) - bulge, std::min(a.z, b.z) - bulge},
         {std::max(a.x, b.x) + bulge, std::max(a.y, b.y) + bulge, std::max(a.z, b.z) + bulge}});
    auto cell_of = [this](double v) {
        return static_cast<std::uint64_t>(std::floor((v + 1.5) / cell_));
    };
    const int pieces = std::max(1, static_cast<int>(std::ceil(chord / (0.5 * cell_))));
    Vec3 prev = a;
    for (int k = 1; k <= pieces; ++k) {
        const Vec3 next = k == pieces ? b : arc_interpolate(a, b, double(k) / pieces);
        const double piece = norm(next - prev);
        const double pad = 1e-12 + 0.125 * piece * piece;
        const double lo[3] = {std::min(prev.x, next.x) - pad, std::min(prev.y, next.y) - pad,
                              std::min(prev.z, next.z) - pad};
        const double hi[3] = {std::max(prev.x, next.x) + pad, std::max(prev.y, next.y) + pad,
                              std::max(prev.z, next.z) + pad};
        for (std::uint64_t ix = cell_of(lo[0]); ix <= cell_of(hi[0]); ++ix)
            for (std::uint64_t iy = cell_of(lo[1]); iy <= cell_of(hi[1]); ++iy)
                for (std::uint64_t iz = cell_of(lo[2]); iz <= cell_of(hi[2]); ++iz)
                    entries.push_back({(ix << 42) | (iy << 21) | iz, id});
        prev = next;
    }
    return id;
}

void ArcGrid::test(std::uint32_t s, std::uint32_t t) {
    if (s == t)
        return;
    const Box &p = boxes_[s];
    const Box &q = boxes_[t];
    if (!(p.lo[0] <= q.hi[0] && q.lo[0] <= p.hi[0] && p.lo[1] <= q.hi[1] && q.lo[1] <= p.hi[1] &&
          p.lo[2] <= q.hi[2] && q.lo[2] <= p.hi[2]))
        return;
    const auto &ru = *rings_[ring_[s]];
    const auto &rv = *rings_[ring_[t]];
    const std::uint32_t ui = index_[s], vi = index_[t];
    const Vec3 &a = ru[ui];
    const Vec3 &b = ru[(ui + 1) % ru.size()];
    const Vec3 &c = rv[vi];
    const Vec3 &d = rv[(vi + 1) % rv.size()];
    bool conflict;
    if (ring_[s] == ring_[t] && ru.size() > 2 &&
        ((ui + 1) % ru.size() == vi || (vi + 1) % ru.size() == ui)) {
        // Consecutive arcs share one node: they conflict only when one folds back on the
        // other (a zero-width spike).
        const bool u_first = (ui + 1) % ru.size() == vi;
        const Vec3 &pp = u_first ? a : c;
        const Vec3 &m = u_first ? b : d;
        const Vec3 &qq = u_first ? d : b;
        const Vec3 n = robust_cross(pp, m);
        const double ln = norm(n);
        conflict =
            ln == 0 || (std::abs(dot((1.0 / ln) * n, qq)) < touch_eps && dot(m - pp, qq - m) < 0);
    } else {
        conflict = arcs_conflict(a, b, c, d);
    }
    if (conflict)
        pairs_.emplace_back(std::min(s, t), std::max(s, t));
}

void ArcGrid::settle() {
    std::sort(pairs_.begin(), pairs_.end());
    pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
}

void ArcGrid::replace(std::uint32_t r, const std::vector<std::uint32_t> &old_of) {
    std::vector<std::uint32_t> &ids = ids_of_[r];
    for (const std::uint32_t id : ids)
        alive_[id] = 0;
    std::vector<std::uint32_t> now(old_of.size());
    for (std::uint32_t i = 0; i < old_of.size(); ++i) {
        if (old_of[i] == none) {
            now[i] = add_arc(r, i, fresh_);
            continue;
        }
        now[i] = ids[old_of[i]];
        alive_[now[i]] = 1;
        index_[now[i]] = i;
    }
    ids = std::move(now);
}

void ArcGrid::update() {
    // The pairs found before whose arcs both stay still conflict (the same arcs, and two arcs of
    // one ring consecutive before are consecutive now); every other pair has a new arc.
    std::erase_if(pairs_, [&](const auto &st) { return !alive_[st.first] || !alive_[st.second]; });
    // New against new in each cell, then against the arcs indexed before that stay.
    test_cells(fresh_, [&](std::size_t i, std::size_t j) {
        const auto lo =
            std::lower_bound(entries_.begin(), entries_.end(), Entry{fresh_[i].first, 0});
        for (auto e = lo; e != entries_.end() && e->first == fresh_[i].first; ++e)
            if (alive_[e->second])
                for (std::size_t p = i; p < j; ++p)
                    test(fresh_[p].second, e->second);
    });
    settle();
    // The new arcs join the index; the entries of arcs gone are dropped once they are half.
    const std::size_t middle = entries_.size();
    entries_.insert(entries_.end(), fresh_.begin(), fresh_.end());
    std::inplace_merge(entries_.begin(), entries_.begin() + static_cast<std::ptrdiff_t>(middle),
                       entries_.end());
    fresh_.clear();
    std::size_t alive = 0;
    for (const auto &e : entries_)
        alive += alive_[e.second];
    if (2 * alive < entries_.size())
        std::erase_if(entries_, [&](const auto &e) { return !alive_[e.second]; });
}

std::vector<ArcPair> ArcGrid::conflicts(std::size_t max_pairs) const {
    std::vector<ArcPair> out;
    out.reserve(pairs_.size());
    for (const auto &[s, t] : pairs_) {
        ArcPair x{ring_[s], index_[s], ring_[t], index_[t]};
        if (std::tie(x.ring_b, x.seg_b) < std::tie(x.ring_a, x.seg_a))
            x = {x.ring_b, x.seg_b, x.ring_a, x.seg_a};
        out.push_back(x);
    }
    std::sort(out.begin(), out.end(), [](const ArcPair &x, const ArcPair &y) {
        return std::tie(x.ring_a, x.seg_a, x.ring_b, x.seg_b) <
               std::tie(y.ring_a, y.seg_a, y.ring_b, y.seg_b);
    });
    if (out.size() > max_pairs)
        out.resize(max_pairs);
    return out;
}

std::vector<ArcPair> find_conflicts(const std::vector<const std::vector<Vec3> *> &rings,
                                    std::size_t max_pairs) {
    return ArcGrid(rings).conflicts(max_pairs);
}

double rings_area_km2(const std::vector<std::vector<LonLat>> &rings) {
    const auto &wgs = GeographicLib::Geodesic::WGS84();
    double earth = wgs.EllipsoidArea() * 1e-6;
    if (rings.empty())
        return earth;
    // The rings on every core, summed in their order (the same sum on any number of threads).
    std::vector<double> areas(rings.size());
    parallel_for_each(rings.size(), [&](std::size_t r) {
        GeographicLib::PolygonArea poly(wgs, false);
        for (const auto &p : rings[r])
            poly.AddPoint(p.lat, p.lon);
        double perimeter;
        poly.Compute(false, true, perimeter, areas[r]);
    });
    double sum = 0;
    for (double area : areas)
        sum += area * 1e-6;
    double r = std::fmod(sum, earth);
    if (r < 0)
        r += earth;
    // A region that is almost the whole Earth and one that is almost empty differ by a full
    // Earth; the rounding of the sum can only matter within a few m2 of those ends.
    if (r < 1e-6 * earth && sum > 0.5 * earth)
        r = earth;
    return r;
}

} // namespace coast_detail

namespace {

/// check_boundary; the search for arcs that touch or cross only when `conflicts`.
std::vector<BoundaryIssue> check_rings(const Boundary &boundary, std::size_t max_issues,
                                       bool conflicts) {
    std::vector<BoundaryIssue> issues;
    auto add = [&](std::string what, long ring, long seg, long oring = -1, long oseg = -1) {
        if (issues.size() < max_issues)
            issues.push_back({std::move(what), ring, seg, oring, oseg});
    };
    std::vector<const std::vector<Vec3> *> rings;
    for (long r = 0; r < static_cast<long>(boundary.rings.size()); ++r) {
        const Ring &ring = boundary.rings[r];
        rings.push_back(&ring.nodes);
        if (ring.nodes.size() < 3)
            add("ring has fewer than 3 nodes", r, -1);
        if (ring.kinds.size() != ring.nodes.size())
            add("ring has kinds.size() != nodes.size()", r, -1);
        for (long i = 0; i < static_cast<long>(ring.nodes.size()); ++i) {
            const Vec3 &a = ring.nodes[i];
            const Vec3 &b = ring.nodes[(i + 1) % ring.nodes.size()];
            if (std::abs(norm(a) - 1.0) > 1e-12)
                add("node is not a unit vector", r, i);
            if (a == b)
                add("consecutive nodes are equal", r, i);
            else if (norm(a + b) < 1e-12)
                add("consecutive nodes are antipodal", r, i);
        }
    }
    if (!issues.empty() || !conflicts)
        return issues;
    for (const auto &c : coast_detail::find_conflicts(rings, max_issues))
        add("arcs touch or cross", c.ring_a, c.seg_a, c.ring_b, c.seg_b);
    return issues;
}

} // namespace

std::vector<BoundaryIssue> check_boundary(const Boundary &boundary, std::size_t max_issues) {
    return check_rings(boundary, max_issues, true);
}

std::vector<BoundaryIssue> coast_detail::check_boundary_clear(const Boundary &boundary,
                                                              std::size_t max_issues) {
    return check_rings(boundary, max_issues, false);
}

double boundary_area_km2(const Boundary &boundary) {
    std::vector<std::vector<LonLat>> rings(boundary.rings.size());
    coast_detail::parallel_for_each(rings.size(), [&](std::size_t r) {
        rings[r].reserve(boundary.rings[r].nodes.size());
        for (const auto &v : boundary.rings[r].nodes)
            rings[r].push_back(vec_to_lonlat(v));
    });
    return coast_detail::rings_area_km2(rings);
}

} // namespace globemesh
