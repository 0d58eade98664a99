// SphericalDelaunay: removal of an unconstrained vertex (flips down to degree 3, one triangle for
// its last three, Lawson flips over the hole), undone exactly when refused.
#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <functional>
#include <vector>

#include "delaunay_internal.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::orient;

bool SphericalDelaunay::remove_vertex(VertexId v) {
    HalfEdge from = leaving(v);
    if (from == no_half_edge || origin(from) != v)
        return false;
    return remove_vertex_from(from);
}

bool SphericalDelaunay::star_removable(HalfEdge from, std::vector<TriangleId> &star) const {
    star.clear();
    HalfEdge h = from;
    do {
        if (is_constrained(h) || !is_solid(triangle_of(h)))
            return false;
        star.push_back(triangle_of(h));
        h = next_around_origin(h);
    } while (h != from);
    return star.size() >= 3;
}

// An ear clipping of the polygon ring (counter-clockwise, star-shaped): k - 2 triangles, three
// ring positions each, every one strictly counter-clockwise with no other ring vertex in it or on
// its sides; empty when none is found (points on one great circle, closer than rounding resolves).
std::vector<int> SphericalDelaunay::clip_ears(const std::vector<VertexId> &ring) const {
    std::vector<int> left(ring.size()), out;
    for (std::size_t i = 0; i < ring.size(); ++i)
        left[i] = static_cast<int>(i);
    auto pt = [&](int i) -> const Vec3 & { return points_[ring[static_cast<std::size_t>(i)]]; };
    while (left.size() > 3) {
        const std::size_t n = left.size();
        std::size_t ear = n;
        for (std::size_t j = 0; j < n && ear == n; ++j) {
            const int a = left[(j + n - 1) % n], b = left[j], c = left[(j + 1) % n];
            if (orient(pt(a), pt(b), pt(c)) <= 0)
                continue;
            bool empty = true;
            for (int d : left)
                if (d != a && d != b && d != c && orient(pt(a), pt(b), pt(d)) >= 0 &&
                    orient(pt(b), pt(c), pt(d)) >= 0 && orient(pt(c), pt(a), pt(d)) >= 0)
                    empty = false;
            if (empty)
                ear = j;
        }
        if (ear == n)
            return {};
        out.insert(out.end(), {left[(ear + n - 1) % n], left[ear], left[(ear + 1) % n]});
        left.erase(left.begin() + static_cast<std::ptrdiff_t>(ear));
    }
    if (orient(pt(left[0]), pt(left[1]), pt(left[2])) <= 0)
        return {};
    out.insert(out.end(), left.begin(), left.end());
    return out;
}

bool SphericalDelaunay::remove_vertex_from(HalfEdge from, std::vector<TriangleId> *changed,
                                           const std::function<bool()> &accept) {
    std::vector<TriangleId> star;
    if (!star_removable(from, star))
        return false;
    // The ring u0..u(k-1) counter-clockwise, with the outer link word of each side u(i)->u(i+1).
    const std::size_t k = star.size();
    std::vector<VertexId> ring(k);
    std::vector<std::uint32_t> outer(k);
    HalfEdge h = from;
    for (std::size_t i = 0; i < k; ++i) {
        ring[i] = destination(h);
        outer[i] = links_[half_edge(triangle_of(h), next3(edge_of(h)))];
        h = next_around_origin(h);
    }
    const std::vector<int> ears = clip_ears(ring);
    if (ears.empty())
        return false;
    // The star as it was, to undo exactly.
    std::vector<VertexId> saved_v(3 * k);
    std::vector<std::uint32_t> saved_l(3 * k);
    for (std::size_t s = 0; s < k; ++s)
        for (int i = 0; i < 3; ++i) {
            saved_v[3 * s + i] = tri_vertices_[3 * star[s] + i];
            saved_l[3 * s + i] = links_[3 * star[s] + i];
        }
    // The k - 2 new triangles take the first slots of the star; their sides are the ring's
    // (outer links) or diagonals shared by two of them, matched by their ends.
    std::vector<std::pair<std::pair<VertexId, VertexId>, HalfEdge>> sides;
    for (std::size_t r = 0; r + 2 < k; ++r) {
        const TriangleId t = star[r];
        for (int i = 0; i < 3; ++i)
            tri_vertices_[3 * t + i] = ring[static_cast<std::size_t>(ears[3 * r + i])];
        for (int i = 0; i < 3; ++i)
            sides.push_back({{vertex(t, next3(i)), vertex(t, prev3(i))}, half_edge(t, i)});
    }
    std::sort(sides.begin(), sides.end());
    for (std::size_t r = 0; r + 2 < k; ++r)
        for (int i = 0; i < 3; ++i) {
            const TriangleId t = star[r];
            const HalfEdge mine = half_edge(t, i);
            const VertexId a = vertex(t, next3(i)), b = vertex(t, prev3(i));
            const auto ring_side = std::find(ring.begin(), ring.end(), a) - ring.begin();
            if (ring[(static_cast<std::size_t>(ring_side) + 1) % k] == b) {
                const std::uint32_t o = outer[static_cast<std::size_t>(ring_side)];
                links_[mine] = o;
                links_[o & link_mask] = mine | (o & constrained_bit);
                continue;
            }
            auto it = std::lower_bound(sides.begin(), sides.end(),
                                       std::make_pair(std::make_pair(b, a), HalfEdge{0}));
            links_[mine] = it->second;
        }
    free_triangle(star[k - 2]);
    free_triangle(star[k - 1]);
    last_ = star[0];
    // Lawson flips from every edge of the hole's triangles make the whole Delaunay again.
    std::vector<HalfEdge> stack;
    for (std::size_t r = 0; r + 2 < k; ++r)
        for (int i = 0; i < 3; ++i)
            stack.push_back(half_edge(star[r], i));
    std::vector<FlipRecord> journal;
    const bool ok = legalize_from(stack, &journal, true, nullptr);
    if (ok && changed) {
        changed->assign(star.begin(), star.end() - 2);
        for (const FlipRecord &f : journal) {
            changed->push_back(f.t);
            changed->push_back(f.s);
        }
        std::sort(changed->begin(), changed->end());
        changed->erase(std::unique(changed->begin(), changed->end()), changed->end());
    }
    if (ok && (!accept || accept()))
        return true;
    // Undo: the Lawson flips, then the star (the two freed slots are the last ones freed).
    undo_flips(journal);
    free_.pop_back();
    free_.pop_back();
    for (std::size_t s = 0; s < k; ++s)
        for (int i = 0; i < 3; ++i) {
            tri_vertices_[3 * star[s] + i] = saved_v[3 * s + i];
            links_[3 * star[s] + i] = saved_l[3 * s + i];
        }
    for (std::size_t s = 0; s < k; ++s)
        for (int i = 0; i < 3; ++i) {
            const HalfEdge e = half_edge(star[s], i);
            links_[twin(e)] = e | (links_[e] & constrained_bit);
        }
    last_ = star[0];
    return false;
}

} // namespace globemesh
