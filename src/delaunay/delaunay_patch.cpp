// SphericalDelaunay::replace_region: a region replaced by a triangulation the caller knows.
#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "delaunay_internal.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

// ---------------------------------------------------------------------------------------------
// Replacing a region by a known patch
// ---------------------------------------------------------------------------------------------

namespace {

// The patch alone (see replace_region): corners (new, or on the border), orientation, symmetric
// links, each border edge taken once with its own ends. taker[k] gets the new half-edge in
// border[k]'s place.
template <class At>
bool patch_fits(const SphericalDelaunay &d, std::span<const HalfEdge> border,
                const std::vector<VertexId> &triangles, const std::vector<std::uint32_t> &adjacent,
                std::size_t first, std::size_t end, const std::vector<char> &on_border, At at,
                std::vector<std::uint32_t> &taker) {
    const std::size_t nt = triangles.size() / 3;
    for (std::size_t r = 0; r < nt; ++r) {
        const VertexId *v = &triangles[3 * r];
        if (v[0] >= end || v[1] >= end || v[2] >= end || v[0] == v[1] || v[1] == v[2] ||
            v[2] == v[0])
            return false;
        for (int i = 0; i < 3; ++i)
            if (v[i] < first && !on_border[v[i]])
                return false;
        if (predicates::orient(at(v[0]), at(v[1]), at(v[2])) <= 0)
            return false;
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t a = adjacent[3 * r + i];
            if (a & SphericalDelaunay::patch_border) {
                const std::uint32_t k = a & ~SphericalDelaunay::patch_border;
                if (k >= border.size() || taker[k] != no_half_edge)
                    return false;
                taker[k] = static_cast<std::uint32_t>(3 * r + i);
                if (d.origin(border[k]) != v[next3(i)] || d.destination(border[k]) != v[prev3(i)])
                    return false;
            } else if (a >= 3 * nt || adjacent[a] != 3 * r + i || a / 3 == r ||
                       triangles[a - a % 3 + next3(a % 3)] != v[prev3(i)] ||
                       triangles[a - a % 3 + prev3(a % 3)] != v[next3(i)]) {
                return false;
            }
        }
    }
    return std::find(taker.begin(), taker.end(), no_half_edge) == taker.end();
}

} // namespace

bool SphericalDelaunay::replace_region(std::span<const HalfEdge> border, std::vector<Vec3> &points,
                                       std::vector<VertexId> &triangles,
                                       std::vector<std::uint32_t> &adjacent, std::uint8_t label,
                                       std::vector<TriangleId> *slots) {
    const std::size_t nt = triangles.size() / 3;
    if (triangles.size() != 3 * nt || adjacent.size() != triangles.size())
        throw std::invalid_argument(
            "SphericalDelaunay::replace_region: 3 vertices and 3 links per triangle");
    const std::size_t first = points_.size();
    const std::size_t end = first + points.size();
    if (nt == 0)
        return border.empty() && points.empty();
    if (end >= link_mask || nt < 2 * points.size())
        return false;
    auto at = [&](VertexId v) -> const Vec3 & {
        return v < first ? points_[v] : points[v - first];
    };
    // The border's half-edges and vertices, flagged (the triangulation before the patch is
    // the small one), and sorted for the index of a border half-edge: (half-edge, k).
    std::vector<char> is_border(links_.size(), 0), on_border(points_.size(), 0);
    std::vector<std::pair<HalfEdge, std::uint32_t>> by_edge(border.size());
    for (std::size_t k = 0; k < border.size(); ++k) {
        const HalfEdge h = border[k];
        if (h >= links_.size() || !is_live(triangle_of(h)) || is_border[h])
            return false;
        is_border[h] = 1;
        on_border[origin(h)] = 1;
        by_edge[k] = {h, static_cast<std::uint32_t>(k)};
    }
    std::sort(by_edge.begin(), by_edge.end());
    auto border_index = [&](HalfEdge h) -> std::uint32_t {
        if (!is_border[h])
            return no_half_edge;
        return std::lower_bound(by_edge.begin(), by_edge.end(), std::make_pair(h, std::uint32_t{0}))
            ->second;
    };
    // The patch alone; taker[k]: the new half-edge in border[k]'s place.
    std::vector<std::uint32_t> taker(border.size(), no_half_edge);
    if (!patch_fits(*this, border, triangles, adjacent, first, end, on_border, at, taker))
        return false;
    // Each border edge's other side (twin and constrained flag), read before any change.
    std::vector<std::uint32_t> outside(border.size());
    for (std::size_t k = 0; k < border.size(); ++k)
        outside[k] = links_[border[k]] & (link_mask | constrained_bit);
    // The region: flooded from the border's triangles without crossing it (marks cleared on
    // every way out). Its corners must all be border vertices, and a border edge's other side
    // lies outside it unless that side is a border edge too.
    std::vector<TriangleId> region;
    auto fail = [&] {
        for (TriangleId t : region)
            clear_mark(t);
        return false;
    };
    for (const HalfEdge h : border) {
        if (marked(triangle_of(h)))
            continue;
        set_mark(triangle_of(h));
        region.push_back(triangle_of(h));
        for (std::size_t q = region.size() - 1; q < region.size(); ++q) {
            if (region.size() + 2 * points.size() > nt)
                return fail(); // larger than the patch: a leak
            const TriangleId t = region[q];
            for (int i = 0; i < 3; ++i) {
                if (!on_border[vertex(t, i)])
                    return fail();
                const HalfEdge e = half_edge(t, i);
                if (is_border[e])
                    continue;
                if (is_constrained(e))
                    return fail();
                const TriangleId nb = triangle_of(twin(e));
                if (!marked(nb)) {
                    set_mark(nb);
                    region.push_back(nb);
                }
            }
        }
    }
    if (region.size() + 2 * points.size() != nt)
        return fail();
    for (std::size_t k = 0; k < border.size(); ++k) {
        const HalfEdge o = outside[k] & link_mask;
        if (marked(triangle_of(o)) && !is_border[o])
            return fail();
    }
    for (TriangleId t : region)
        clear_mark(t);

    if (3 * (static_cast<std::uint64_t>(triangle_slots()) + nt) > link_mask)
        throw DataError("triangulation too large: more than " + std::to_string(link_mask / 3) +
                        " triangles (about 178 million points)");
    // Apply, each input released once copied, and each array grown to its exact size: the
    // points; the slots (the region's, then free ones, then new ones); the corners; the links.
    points_.reserve(end);
    points_.insert(points_.end(), points.begin(), points.end());
    for (const Vec3 &p : points)
        bounded_ = bounded_ && bounded(p);
    std::vector<Vec3>().swap(points);
    std::vector<TriangleId> slot(nt);
    std::size_t r = 0;
    for (; r < region.size(); ++r)
        slot[r] = region[r];
    for (; r < nt && !free_.empty(); ++r) {
        slot[r] = free_.back();
        free_.pop_back();
    }
    const std::size_t grown = triangle_slots() + (nt - r);
    for (auto t = static_cast<TriangleId>(triangle_slots()); r < nt; ++r)
        slot[r] = t++;
    tri_vertices_.reserve(3 * grown);
    tri_vertices_.resize(3 * grown);
    labels_.reserve(grown);
    labels_.resize(grown);
    for (r = 0; r < nt; ++r) {
        const TriangleId t = slot[r];
        for (int i = 0; i < 3; ++i)
            tri_vertices_[3 * t + i] = triangles[3 * r + i];
        labels_[t] = label;
    }
    std::vector<VertexId>().swap(triangles);
    links_.reserve(3 * grown);
    links_.resize(3 * grown, 0);
    for (r = 0; r < nt; ++r) {
        const TriangleId t = slot[r];
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t a = adjacent[3 * r + i];
            if (!(a & patch_border)) {
                links_[3 * t + i] = half_edge(slot[a / 3], static_cast<int>(a % 3));
                continue;
            }
            const std::uint32_t word = outside[a & ~patch_border];
            const HalfEdge o = word & link_mask;
            const std::uint32_t flag = word & constrained_bit;
            const std::uint32_t k2 = border_index(o);
            if (k2 != no_half_edge) { // both sides new: the half-edge that took border[k2]'s place
                links_[3 * t + i] =
                    half_edge(slot[taker[k2] / 3], static_cast<int>(taker[k2] % 3)) | flag;
            } else {
                links_[3 * t + i] = o | flag;
                links_[o] = half_edge(t, i) | flag;
            }
        }
    }
    std::vector<std::uint32_t>().swap(adjacent);
    last_ = slot[nt - 1];
    if (slots)
        *slots = std::move(slot);
    return true;
}

} // namespace globemesh
