// The boundary cut into lunes (docs/parallel.md, sections 1-3): crossings of the rings with the
// border meridians, the borders' ocean stretches discretised from the size field, and each
// part's rings joined from its ring pieces and border nodes (Weiler-Atherton on the sphere).
#include "globemesh/parts.hpp"

#include <algorithm>
#include <cmath>

#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

namespace {

/// A crossing within this fraction of h of a ring node replaces the node: no segment shorter.
constexpr double snap_fraction = 0.1;
/// A ring node within this fraction of h of a crossing goes too where it lies within
/// straight_fraction h of the arc from the crossing to the node after it: a short segment of
/// straight coast at a border made faces as short, whose centroids then fell on land (GSHHG low
/// at 20 km, 2.01E: the Benin coast, a 6.5 km segment, faces of q 0.54).
constexpr double short_fraction = 0.5;
constexpr double straight_fraction = 0.05;
/// A ring's excursion across a border no deeper than this fraction of h is dropped: below the
/// h / 4 by which the mesh's coast may stray from the source's elsewhere (land.cpp).
constexpr double excursion_fraction = 0.2;
/// The border's size-field integral is summed in steps of this fraction of h.
constexpr double border_step_fraction = 0.125;
/// A segment crossing two borders (near a pole) is halved at most this many times.
constexpr int max_halvings = 40;

struct Crossing {
    Vec3 p;
    int border = 0;
    bool east = false;    // the ring goes east across the border (ocean to the north)
    bool dropped = false; // with an excursion (drop_excursions): not on the border any more
};

struct Node {
    Vec3 p;
    SegmentKind kind; // of the segment from this node
    int crossing = -1;
    std::uint32_t ring = no_whole_ring; // of the whole boundary the segment from it lies on
};

struct Splitter {
    const Lunes &lunes;
    const SizeFn &size_km;
    std::vector<Crossing> crossings;
    std::vector<Vec3> by_z; // every ring's nodes, sorted by z (holds_node)

    /// Whether a node of the rings other than a, b and c lies inside or on the spherical
    /// triangle a, b, c (at most a few h across): dropping b for the arc a-c would then cross
    /// that coast (a ring no part could recover).
    bool holds_node(const Vec3 &a, const Vec3 &b, const Vec3 &c) const {
        using predicates::orient;
        const int turn = orient(a, b, c);
        if (turn == 0)
            return false; // b on the arc a-c: no room between
        const double reach = std::max({norm(a - b), norm(b - c), norm(c - a)});
        const auto [lo, hi] = std::minmax({a.z, b.z, c.z});
        auto first = std::lower_bound(by_z.begin(), by_z.end(), lo - reach,
                                      [](const Vec3 &p, double z) { return p.z < z; });
        for (auto it = first; it != by_z.end() && it->z <= hi + reach; ++it) {
            const Vec3 &x = *it;
            if (x == a || x == b || x == c || dot(x, a) <= 0)
                continue;
            if (orient(a, b, x) != -turn && orient(b, c, x) != -turn && orient(c, a, x) != -turn)
                return true;
        }
        return false;
    }

    /// Where arc a-b crosses border k's meridian, if it does.
    bool cross_border(const Vec3 &a, const Vec3 &b, int k, Vec3 &p) const {
        const Vec3 normal = lunes.border_normal(k);
        if ((dot(normal, a) > 0) == (dot(normal, b) > 0))
            return false;
        p = normalized(cross(cross(a, b), normal));
        if (dot(p, a + b) < 0)
            p = Vec3{-p.x, -p.y, -p.z};
        return dot(p, lunes.border_direction(k)) > 0;
    }

    /// Appends to `out` the crossings of arc a-b (kind `kind`), halving it where it crosses
    /// more than one border.
    void split_segment(const Vec3 &a, const Vec3 &b, SegmentKind kind, int depth,
                       std::vector<Node> &out) {
        const int la = lunes.part_of(a), lb = lunes.part_of(b), n = lunes.count;
        if (la == lb)
            return;
        const int east = (la + 1) % n, west = (la + n - 1) % n;
        Vec3 p;
        if (lb == east && cross_border(a, b, east, p)) {
            crossings.push_back({p, east, true});
        } else if (lb == west && cross_border(a, b, la, p)) {
            crossings.push_back({p, la, false});
        } else {
            if (depth >= max_halvings)
                throw DataError("parts: a coast segment near " +
                                std::to_string(vec_to_lonlat(a).lon) + "," +
                                std::to_string(vec_to_lonlat(a).lat) +
                                " cannot be cut at a part border; use --parts 1");
            const Vec3 mid = arc_midpoint(a, b);
            split_segment(a, mid, kind, depth + 1, out);
            out.push_back({mid, kind, -1});
            split_segment(mid, b, kind, depth + 1, out);
            return;
        }
        out.push_back({p, kind, static_cast<int>(crossings.size() - 1)});
    }

    /// Whether p lies within excursion_fraction * h of border k's meridian plane.
    bool near_border(const Vec3 &p, int k) const {
        return std::fabs(dot(p, lunes.border_normal(k))) <
               std::sin(excursion_fraction * km_to_rad(size_km(p)));
    }

    /// The nodes kept before i and after j (not dropped yet): the shortcut's ends.
    static std::pair<std::size_t, std::size_t> kept_ends(const std::vector<Node> &nodes,
                                                         const std::vector<char> &drop,
                                                         std::size_t i, std::size_t j) {
        const std::size_t n = nodes.size();
        std::size_t a = (i + n - 1) % n, b = (j + 1) % n;
        for (std::size_t guard = 0; drop[a] && guard < n; ++guard)
            a = (a + n - 1) % n;
        for (std::size_t guard = 0; drop[b] && guard < n; ++guard)
            b = (b + 1) % n;
        return {a, b};
    }

    /// Whether the shortcut that would replace nodes i to j passes over a node of any ring: the
    /// polygon it closes with them, fanned from its first corner, holds one (every point inside
    /// lies in a fan triangle). An excursion at a cape had its shortcut cut the cape and cross
    /// another ring (NE 1:50m at 150 km in 4 parts, the border at 67.74W: across Alexander
    /// Island's coast, a ring no part could recover).
    bool shortcut_sweeps(const std::vector<Node> &nodes, const std::vector<char> &drop,
                         std::size_t i, std::size_t j) const {
        const auto [a, b] = kept_ends(nodes, drop, i, j);
        std::vector<Vec3> fan{nodes[a].p};
        for (std::size_t v = i; v != j; v = (v + 1) % nodes.size())
            fan.push_back(nodes[v].p);
        fan.push_back(nodes[j].p);
        fan.push_back(nodes[b].p);
        for (std::size_t t = 1; t + 1 < fan.size(); ++t)
            if (holds_node(fan[0], fan[t], fan[t + 1]))
                return true;
        return false;
    }

    /// Whether the arc that would replace nodes i to j (from the node kept before i to the one
    /// kept after j) crosses or touches the ring's other segments: an excursion can hold a
    /// bulge of the coast whose far side then lies on the wrong side of the shortcut (GSHHG low
    /// at 150 km in 5 parts: Mindanao's east coast within 30 km of 126.01E, its shortcut across
    /// the island's north coast, a ring no part could recover).
    static bool shortcut_crosses(const std::vector<Node> &nodes, const std::vector<char> &drop,
                                 std::size_t i, std::size_t j) {
        const std::size_t n = nodes.size();
        const auto [a, b] = kept_ends(nodes, drop, i, j);
        const Vec3 &pa = nodes[a].p, &pb = nodes[b].p;
        using predicates::orient;
        // The segments from b on round to a, each from a kept node to the next kept one.
        std::size_t u = b;
        for (std::size_t guard = 0; u != a && guard < n; ++guard) {
            std::size_t w = (u + 1) % n;
            while (drop[w] && w != a)
                w = (w + 1) % n;
            if (u != b && w != a) {
                const Vec3 &pu = nodes[u].p, &pw = nodes[w].p;
                const int s1 = orient(pa, pb, pu), s2 = orient(pa, pb, pw);
                const int s3 = orient(pu, pw, pa), s4 = orient(pu, pw, pb);
                if (s1 * s2 <= 0 && s3 * s4 <= 0 && dot(pu + pw, pa + pb) > 0)
                    return true;
            }
            u = w;
        }
        return false;
    }

    /// The nodes of `nodes` with its excursions across a border dropped: two successive
    /// crossings of one border and the nodes between them, when all of those lie within
    /// excursion_fraction * h of it (a coast vertex a few metres past a border made a piece of
    /// one node, faces of q 0.09 at the border where one part has none). The ring then stays on
    /// the side it was on before and after (a lune is convex), moved by less than that.
    std::vector<Node> drop_excursions(std::vector<Node> nodes) {
        std::vector<std::size_t> at;
        for (std::size_t i = 0; i < nodes.size(); ++i)
            if (nodes[i].crossing >= 0)
                at.push_back(i);
        std::vector<char> drop(nodes.size(), 0);
        std::size_t dropped = 0;
        for (std::size_t c = 0; at.size() >= 2 && c < at.size(); ++c) {
            const std::size_t i = at[c], j = at[(c + 1) % at.size()];
            const int k = crossings[static_cast<std::size_t>(nodes[i].crossing)].border;
            if (drop[i] || drop[j] ||
                k != crossings[static_cast<std::size_t>(nodes[j].crossing)].border)
                continue;
            bool near = true;
            std::size_t between = 0;
            for (std::size_t v = (i + 1) % nodes.size(); v != j && near;
                 v = (v + 1) % nodes.size(), ++between)
                near = near_border(nodes[v].p, k);
            if (!near || nodes.size() - dropped - between - 2 < 3 ||
                shortcut_crosses(nodes, drop, i, j) || shortcut_sweeps(nodes, drop, i, j))
                continue;
            for (std::size_t v = i; v != j; v = (v + 1) % nodes.size())
                drop[v] = 1;
            drop[j] = 1;
            dropped += between + 2;
        }
        if (dropped == 0)
            return nodes;
        std::vector<Node> kept;
        for (std::size_t i = 0; i < nodes.size(); ++i)
            if (!drop[i])
                kept.push_back(nodes[i]);
            else if (nodes[i].crossing >= 0)
                crossings[static_cast<std::size_t>(nodes[i].crossing)].dropped = true;
        return kept;
    }

    /// The nodes of `nodes` less each node next to a crossing that drops(crossing, node, the node
    /// after it) tells to go: only from a piece of three nodes or more (each piece keeps a node
    /// inside), and none where fewer than three would be left.
    template <class Drops>
    static std::vector<Node> drop_beside_crossings(const std::vector<Node> &nodes, Drops drops) {
        const std::size_t m = nodes.size();
        std::vector<char> drop(m, 0);
        for (std::size_t i = 0; i < m; ++i) {
            if (nodes[i].crossing < 0)
                continue;
            for (std::size_t step : {m - 1, std::size_t{1}}) {
                std::size_t run = 0;
                while (run < 3 && nodes[(i + (run + 1) * step) % m].crossing < 0)
                    ++run;
                const std::size_t j = (i + step) % m;
                if (run == 3 && drops(nodes[i], nodes[j], nodes[(j + step) % m]))
                    drop[j] = 1;
            }
        }
        const bool too_few = m - std::count(drop.begin(), drop.end(), 1) < 3;
        std::vector<Node> kept;
        for (std::size_t i = 0; i < m; ++i)
            if (!drop[i] || too_few)
                kept.push_back(nodes[i]);
        return kept;
    }

    /// The ring's nodes with its crossings inserted, its shallow excursions across a border
    /// dropped, ring nodes within snap_fraction * h of a crossing dropped, and those within
    /// short_fraction * h where the coast runs straight on past them; none where another coast's
    /// node lies between the node and the arc that would replace it.
    std::vector<Node> cut_ring(const Ring &r) {
        std::vector<Node> nodes;
        const std::size_t m = r.nodes.size();
        for (std::size_t i = 0; i < m; ++i) {
            nodes.push_back({r.nodes[i], r.kinds[i], -1});
            split_segment(r.nodes[i], r.nodes[(i + 1) % m], r.kinds[i], 0, nodes);
        }
        // Off the arc as near_border measures off a meridian: the sine against the plane's normal.
        auto drops = [&](const Node &c, const Node &v, const Node &after) {
            const double h = km_to_rad(size_km(c.p)), gap = arc_angle(c.p, v.p);
            const double off = std::fabs(dot(v.p, normalized(cross(c.p, after.p))));
            return (gap < snap_fraction * h ||
                    (gap < short_fraction * h && off < std::sin(straight_fraction * h))) &&
                   !holds_node(c.p, v.p, after.p);
        };
        return drop_beside_crossings(drop_excursions(std::move(nodes)), drops);
    }

    /// The nodes strictly between p and q (p south of q, both on border k's meridian), spaced
    /// by equal shares of the integral of ds / h.
    std::vector<Vec3> stretch_nodes(const Vec3 &p, const Vec3 &q, int k) const {
        const double lon = lunes.border_lon(k) * deg_to_rad;
        auto at = [&](double lat) {
            return Vec3{std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon),
                        std::sin(lat)};
        };
        const double lat0 = std::asin(std::clamp(p.z, -1.0, 1.0));
        const double lat1 = std::asin(std::clamp(q.z, -1.0, 1.0));
        std::vector<double> lats{lat0}, sums{0};
        double inv = 1 / km_to_rad(size_km(p));
        while (lats.back() < lat1) {
            const double step = std::max(1e-9, border_step_fraction / inv); // radians of latitude
            const double next = std::min(lat1, lats.back() + step);
            const double inv_next = 1 / km_to_rad(size_km(next == lat1 ? q : at(next)));
            sums.push_back(sums.back() + 0.5 * (inv + inv_next) * (next - lats.back()));
            lats.push_back(next);
            inv = inv_next;
        }
        const long pieces = std::max(1L, std::lround(sums.back()));
        std::vector<Vec3> out;
        std::size_t j = 1;
        for (long i = 1; i < pieces; ++i) {
            const double target = sums.back() * double(i) / double(pieces);
            while (sums[j] < target)
                ++j;
            const double f = (target - sums[j - 1]) / (sums[j] - sums[j - 1]);
            out.push_back(at(lats[j - 1] + f * (lats[j] - lats[j - 1])));
        }
        return out;
    }

    /// Whether a border no ring crosses is ocean: as the south pole is, which any crossed
    /// border tells (ocean south of its first crossing where that crossing goes west); with no
    /// crossing anywhere, not for a region's outline (the ocean is inside it, away from every
    /// border), else where `land` (may be null) has no land.
    bool uncrossed_ocean(int k, const LandTest *land, bool region) const {
        const Crossing *first = nullptr;
        for (const Crossing &c : crossings)
            if (!c.dropped && (!first || c.p.z < first->p.z))
                first = &c;
        if (first)
            return !first->east;
        return !region && !(land && land->contains(lunes.border_direction(k)));
    }

    /// Border k's nodes from the south pole to the north: crossings, and the ocean stretches'
    /// nodes with the poles where they are ocean.
    std::vector<Node> border_nodes(int k, const LandTest *land, bool region) const {
        std::vector<int> on;
        for (std::size_t c = 0; c < crossings.size(); ++c)
            if (crossings[c].border == k && !crossings[c].dropped)
                on.push_back(static_cast<int>(c));
        std::sort(on.begin(), on.end(), [&](int a, int b) {
            return crossings[a].p.z != crossings[b].p.z ? crossings[a].p.z < crossings[b].p.z
                                                        : a < b;
        });
        const Vec3 south{0, 0, -1}, north{0, 0, 1};
        bool ocean = on.empty() ? uncrossed_ocean(k, land, region) : !crossings[on.front()].east;
        std::vector<Node> out;
        Vec3 from = south;
        if (ocean)
            out.push_back({south, SegmentKind::open, -1});
        for (std::size_t i = 0; i <= on.size(); ++i) {
            const Vec3 to = i < on.size() ? crossings[on[i]].p : north;
            if (ocean)
                for (const Vec3 &v : stretch_nodes(from, to, k))
                    out.push_back({v, SegmentKind::open, -1});
            if (i == on.size()) {
                if (ocean)
                    out.push_back({north, SegmentKind::open, -1});
                break;
            }
            if (crossings[on[i]].east == ocean)
                throw DataError("parts: the coast does not alternate between land and ocean along "
                                "the part border at longitude " +
                                std::to_string(lunes.border_lon(k)) +
                                " (rings crossing); use --parts 1");
            out.push_back({to, SegmentKind::open, on[i]});
            ocean = crossings[on[i]].east;
            from = to;
        }
        return out;
    }
};

/// A ring's stretch inside one part, from an entry crossing to (not including) the exit.
struct Piece {
    int part = 0;
    int exit = -1;
    std::vector<Node> nodes;
};

/// The pieces of a ring cut at its crossings (at least one), each with its part.
void cut_pieces(const std::vector<Node> &ring, const Lunes &lunes, std::vector<Piece> &pieces,
                std::vector<int> &piece_of_entry) {
    std::size_t start = 0;
    while (ring[start].crossing < 0)
        ++start;
    const std::size_t m = ring.size();
    Piece piece;
    for (std::size_t s = 0; s <= m; ++s) {
        const Node &v = ring[(start + s) % m];
        if (s > 0 && v.crossing >= 0) {
            piece.exit = v.crossing;
            const Vec3 inside =
                piece.nodes.size() > 1 ? piece.nodes[1].p : arc_midpoint(piece.nodes[0].p, v.p);
            piece.part = lunes.part_of(inside);
            piece_of_entry[piece.nodes[0].crossing] = static_cast<int>(pieces.size());
            pieces.push_back(std::move(piece));
            piece = Piece{};
        }
        if (s < m)
            piece.nodes.push_back(v);
    }
}

/// Part k's outline with the part on its left: its east border south to north, its west border
/// north to south (the poles once).
std::vector<Node> part_outline(const std::vector<std::vector<Node>> &borders, int k, int n) {
    std::vector<Node> loop = borders[(k + 1) % n];
    auto is_pole = [](const Node &v) { return v.crossing < 0 && std::abs(v.p.z) == 1.0; };
    const auto &west = borders[k];
    for (auto it = west.rbegin(); it != west.rend(); ++it) {
        const bool seen = !loop.empty() && ((is_pole(loop.back()) && loop.back().p.z == it->p.z) ||
                                            (is_pole(loop.front()) && loop.front().p.z == it->p.z));
        if (!(is_pole(*it) && seen))
            loop.push_back(*it);
    }
    return loop;
}

/// Part k's rings from its pieces, each exit joined to the next entry along its outline.
void join_pieces(const std::vector<Node> &loop, const std::vector<Piece> &pieces,
                 const std::vector<int> &piece_of_entry, int k, std::size_t crossing_count,
                 PartBoundary &out) {
    std::vector<int> position(crossing_count, -1);
    for (std::size_t i = 0; i < loop.size(); ++i)
        if (loop[i].crossing >= 0)
            position[loop[i].crossing] = static_cast<int>(i);
    std::vector<char> used(pieces.size(), 0);
    for (std::size_t first = 0; first < pieces.size(); ++first) {
        if (pieces[first].part != k || used[first])
            continue;
        Ring ring;
        std::vector<std::uint32_t> whole;
        auto add = [&](const Node &v, SegmentKind kind, std::uint32_t r) {
            ring.nodes.push_back(v.p), ring.kinds.push_back(kind), whole.push_back(r);
        };
        for (std::size_t p = first, guard = 0; !used[p]; ++guard) {
            if (guard > pieces.size() || position[pieces[p].exit] < 0)
                throw DataError("parts: a coast piece leaves its part where no border is; use "
                                "--parts 1");
            used[p] = 1;
            for (const Node &v : pieces[p].nodes)
                add(v, v.kind, v.ring);
            std::size_t i = static_cast<std::size_t>(position[pieces[p].exit]);
            add(loop[i], SegmentKind::open, no_whole_ring);
            for (i = (i + 1) % loop.size(); loop[i].crossing < 0; i = (i + 1) % loop.size())
                add(loop[i], SegmentKind::open, no_whole_ring);
            p = static_cast<std::size_t>(piece_of_entry[loop[i].crossing]);
            if (pieces[p].part != k)
                throw DataError("parts: the coast enters a part across a border it leaves; use "
                                "--parts 1");
        }
        out.boundary.rings.push_back(std::move(ring));
        out.whole_rings.push_back(std::move(whole));
    }
}

} // namespace

Vec3 Lunes::border_normal(int k) const {
    const double lon = border_lon(k) * deg_to_rad;
    return {-std::sin(lon), std::cos(lon), 0};
}

Vec3 Lunes::border_direction(int k) const {
    const double lon = border_lon(k) * deg_to_rad;
    return {std::cos(lon), std::sin(lon), 0};
}

double Lunes::east_of_first(const Vec3 &p) const {
    const double east = std::atan2(p.y, p.x) * rad_to_deg - first_lon;
    return east - 360 * std::floor(east / 360);
}

int Lunes::part_of(const Vec3 &p) const {
    return std::min(count - 1, static_cast<int>(east_of_first(p) / (360.0 / count)));
}

std::vector<PartBoundary> split_boundary(const Boundary &boundary, const SizeFn &size_km,
                                         const Lunes &lunes, const LandTest *land) {
    const int parts = lunes.count;
    Splitter s{lunes, size_km, {}, {}};
    for (const Ring &r : boundary.rings)
        s.by_z.insert(s.by_z.end(), r.nodes.begin(), r.nodes.end());
    std::sort(s.by_z.begin(), s.by_z.end(), [](const Vec3 &p, const Vec3 &q) { return p.z < q.z; });
    std::vector<PartBoundary> out(static_cast<std::size_t>(parts));
    std::vector<std::vector<Node>> cut;
    for (std::uint32_t r = 0; r < boundary.rings.size(); ++r) {
        std::vector<Node> nodes = s.cut_ring(boundary.rings[r]);
        for (Node &v : nodes)
            v.ring = r;
        if (std::none_of(nodes.begin(), nodes.end(),
                         [](const Node &v) { return v.crossing >= 0; })) {
            auto &b = out[static_cast<std::size_t>(lunes.part_of(nodes[0].p))];
            Ring kept; // r, less the excursions drop_excursions took
            for (const Node &v : nodes)
                kept.nodes.push_back(v.p), kept.kinds.push_back(v.kind);
            b.boundary.rings.push_back(std::move(kept));
            b.whole_rings.emplace_back(nodes.size(), r);
            b.has_ocean = true;
        } else {
            cut.push_back(std::move(nodes));
        }
    }
    std::vector<Piece> pieces;
    std::vector<int> piece_of_entry(s.crossings.size(), -1);
    for (const auto &nodes : cut)
        cut_pieces(nodes, lunes, pieces, piece_of_entry);
    // A region's outline is made of open segments; a coast's rings have none.
    const bool region =
        std::any_of(boundary.rings.begin(), boundary.rings.end(), [](const Ring &r) {
            return std::find(r.kinds.begin(), r.kinds.end(), SegmentKind::open) != r.kinds.end();
        });
    std::vector<std::vector<Node>> borders;
    for (int k = 0; k < parts; ++k)
        borders.push_back(s.border_nodes(k, land, region));
    for (int k = 0; k < parts; ++k) {
        const std::vector<Node> loop = part_outline(borders, k, parts);
        auto &b = out[static_cast<std::size_t>(k)];
        const bool crossed =
            std::any_of(loop.begin(), loop.end(), [](const Node &v) { return v.crossing >= 0; });
        if (crossed) {
            join_pieces(loop, pieces, piece_of_entry, k, s.crossings.size(), b);
        } else if (!loop.empty()) { // the whole outline is ocean
            Ring ring;
            for (const Node &v : loop)
                ring.nodes.push_back(v.p), ring.kinds.push_back(SegmentKind::open);
            b.boundary.rings.push_back(std::move(ring));
            b.whole_rings.emplace_back(loop.size(), no_whole_ring);
        }
        b.has_ocean = b.has_ocean || !loop.empty();
    }
    for (const auto &island : boundary.dropped_islands)
        out[static_cast<std::size_t>(lunes.part_of(island[0]))].boundary.dropped_islands.push_back(
            island);
    return out;
}

} // namespace globemesh
