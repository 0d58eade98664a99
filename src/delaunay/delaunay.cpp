// SphericalDelaunay: storage, location and renumbering (insertion, constraints, flips and
// validation are in the delaunay_*.cpp beside it).
#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "delaunay_internal.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

// ---------------------------------------------------------------------------------------------
// Storage
// ---------------------------------------------------------------------------------------------

void SphericalDelaunay::link(HalfEdge a, HalfEdge b) {
    // The constrained flag lives on both sides; keep whatever a carried.
    std::uint32_t flag = links_[a] & constrained_bit;
    links_[a] = b | flag;
    links_[b] = a | flag;
}

void SphericalDelaunay::set_constrained(HalfEdge h, bool on) {
    HalfEdge t = twin(h);
    if (on) {
        links_[h] |= constrained_bit;
        links_[t] |= constrained_bit;
    } else {
        links_[h] &= link_mask;
        links_[t] &= link_mask;
    }
}

TriangleId SphericalDelaunay::new_triangle(VertexId a, VertexId b, VertexId c, std::uint8_t label) {
    TriangleId t;
    if (!free_.empty()) {
        t = free_.back();
        free_.pop_back();
    } else {
        t = static_cast<TriangleId>(tri_vertices_.size() / 3);
        if (3 * static_cast<std::uint64_t>(t) + 3 > link_mask)
            throw DataError("triangulation too large: more than " + std::to_string(link_mask / 3) +
                            " triangles (about 178 million points)");
        tri_vertices_.resize(tri_vertices_.size() + 3);
        links_.resize(links_.size() + 3, 0);
        labels_.push_back(0);
    }
    tri_vertices_[3 * t] = a;
    tri_vertices_[3 * t + 1] = b;
    tri_vertices_[3 * t + 2] = c;
    links_[3 * t] = links_[3 * t + 1] = links_[3 * t + 2] = 0;
    labels_[t] = label;
    last_ = t;
    return t;
}

TriangleId SphericalDelaunay::new_slot() {
    if (!free_.empty()) {
        const TriangleId t = free_.back();
        free_.pop_back();
        return t;
    }
    const TriangleId t = static_cast<TriangleId>(tri_vertices_.size() / 3);
    tri_vertices_.resize(tri_vertices_.size() + 3);
    links_.resize(links_.size() + 3, 0);
    labels_.push_back(0);
    return t;
}

void SphericalDelaunay::free_triangle(TriangleId t) {
    tri_vertices_[3 * t] = no_vertex;
    free_.push_back(t);
}

bool SphericalDelaunay::is_solid(TriangleId t) const {
    return orient(points_[vertex(t, 0)], points_[vertex(t, 1)], points_[vertex(t, 2)]) > 0;
}

bool SphericalDelaunay::visible(TriangleId t, const Vec3 &p) const {
    return in_circle(points_[vertex(t, 0)], points_[vertex(t, 1)], points_[vertex(t, 2)], p) > 0;
}

void SphericalDelaunay::reserve(std::size_t points) {
    points_.reserve(points);
    reserve_for(points);
}

void SphericalDelaunay::reserve_for(std::size_t points) {
    // A closed triangulation of n points has 2n - 4 triangles; reserve once.
    tri_vertices_.reserve(3 * (2 * points + 4));
    links_.reserve(3 * (2 * points + 4));
    labels_.reserve(2 * points + 4);
}

// ---------------------------------------------------------------------------------------------
// Location
// ---------------------------------------------------------------------------------------------

TriangleId SphericalDelaunay::start_triangle(TriangleId hint) const {
    TriangleId t = hint;
    if (t == no_triangle || t >= triangle_slots() || !is_live(t)) {
        t = last_;
        if (t == no_triangle || t >= triangle_slots() || !is_live(t)) {
            for (t = 0; t < triangle_slots() && !is_live(t); ++t) {
            }
            if (t == triangle_slots())
                return no_triangle;
        }
    }
    return t;
}

TriangleId SphericalDelaunay::locate(const Vec3 &p, TriangleId hint) const {
    const TriangleId t = start_triangle(hint);
    if (t == no_triangle)
        return no_triangle;
    bool inside = false;
    return walk(p, t, inside);
}

// Visibility walk across edges that have p strictly on their right. The edge a triangle was
// entered by has p on its left (its twin had p on its right), so only the other two are tested;
// which of the two goes first is drawn from a small deterministic generator (a stand-in for the
// stochastic walk, which cannot cycle for ever in a Delaunay triangulation); the step bound
// guards constrained or ghost regions. `inside` is true when the walk stopped at a triangle
// with p on or left of all three edges (every one tested or known), false when the bound hit.
TriangleId SphericalDelaunay::walk(const Vec3 &p, TriangleId t, bool &inside) const {
    const std::size_t limit =
        64 + 32 * static_cast<std::size_t>(std::sqrt(double(triangle_slots())));
    const VertexId *tv = tri_vertices_.data();
    const Vec3 *pts = points_.data();
    const bool fast = bounded_ && bounded(p);
    auto right_of = [&](TriangleId s, int i) {
        const Vec3 &u = pts[tv[3 * s + next3(i)]];
        const Vec3 &w = pts[tv[3 * s + prev3(i)]];
        if (fast) {
            // det[u, w, p] rounded, certified when beyond a static bound: every coordinate is
            // at most 2 in magnitude, so the 6 monomials add up to at most 48 and the 5
            // roundings each passes through err by at most gamma_5 * 48 < 241 u (Higham, lemma
            // 3.1; underflow adds at most a few 2^-1074). 256 u = 2^-45.
            const double m1 = w.y * p.z - w.z * p.y;
            const double m2 = w.z * p.x - w.x * p.z;
            const double m3 = w.x * p.y - w.y * p.x;
            const double det = u.x * m1 + u.y * m2 + u.z * m3;
            if (det < -0x1p-45)
                return true;
            if (det > 0x1p-45)
                return false;
        }
        // p at an end of the edge (a walk to a vertex's own point): orient is 0, which only the
        // exact stage would tell.
        if (p == u || p == w)
            return false;
        return orient(u, w, p) < 0;
    };
    // The first triangle: all three edges.
    int cross = -1;
    for (int i = 0; i < 3 && cross < 0; ++i)
        if (right_of(t, i))
            cross = i;
    std::uint32_t bits = 0x2545f491u;
    for (std::size_t step = 0; cross >= 0; ++step) {
        if (step == limit) {
            inside = false;
            return t;
        }
        const HalfEdge o = twin(half_edge(t, cross));
        t = triangle_of(o);
        const int entry = edge_of(o);
        bits ^= bits << 13;
        bits ^= bits >> 17;
        bits ^= bits << 5;
        int first = next3(entry), second = prev3(entry);
        if (bits & 1u)
            std::swap(first, second);
        cross = right_of(t, first) ? first : right_of(t, second) ? second : -1;
    }
    inside = true;
    return t;
}

// ---------------------------------------------------------------------------------------------
// Lookups
// ---------------------------------------------------------------------------------------------

std::vector<HalfEdge> SphericalDelaunay::vertex_half_edges() const {
    std::vector<HalfEdge> out(points_.size(), no_half_edge);
    for (TriangleId t = 0; t < triangle_slots(); ++t)
        if (is_live(t))
            for (int i = 0; i < 3; ++i)
                out[vertex(t, next3(i))] = half_edge(t, i);
    return out;
}

HalfEdge SphericalDelaunay::find_edge(HalfEdge from, VertexId b) const {
    // Rotate around a = origin(from).
    HalfEdge h = from;
    do {
        if (destination(h) == b)
            return h;
        h = next_around_origin(h);
    } while (h != from);
    return no_half_edge;
}

HalfEdge SphericalDelaunay::leaving(VertexId a, TriangleId hint) const {
    // A hint that has a as a corner is the answer the walk would give (a lies on two of its
    // edges and left of the third), without the walk's orientation tests through a itself, each
    // zero and so decided only by the exact stage.
    if (hint != no_triangle && hint < triangle_slots() && is_live(hint))
        for (int i = 0; i < 3; ++i)
            if (vertex(hint, next3(i)) == a)
                return half_edge(hint, i);
    TriangleId t = locate(points_[a], hint != no_triangle ? hint : last_);
    for (int i = 0; i < 3; ++i)
        if (vertex(t, next3(i)) == a)
            return half_edge(t, i);
    return vertex_half_edges()[a];
}

// ---------------------------------------------------------------------------------------------
// Renumbering
// ---------------------------------------------------------------------------------------------

std::vector<TriangleId> SphericalDelaunay::renumber(std::span<const VertexId> new_of_old) {
    // One array at a time, each old one freed before the next new one: the peak is the
    // triangulation and one array more.
    const std::size_t vertices = points_.size(), slots = triangle_slots();
    {
        std::vector<Vec3> points(vertices);
        for (std::size_t v = 0; v < vertices; ++v)
            points[new_of_old[v]] = points_[v];
        points_.swap(points);
    }
    // A counting sort of the live triangles by their smallest new corner.
    auto smallest = [&](TriangleId t) {
        return std::min(
            {new_of_old[vertex(t, 0)], new_of_old[vertex(t, 1)], new_of_old[vertex(t, 2)]});
    };
    std::vector<TriangleId> new_of_slot(slots, no_triangle);
    std::size_t live = 0;
    {
        std::vector<TriangleId> next(vertices + 1, 0);
        for (TriangleId t = 0; t < slots; ++t)
            if (is_live(t))
                ++next[smallest(t) + 1];
        for (std::size_t v = 0; v < vertices; ++v)
            next[v + 1] += next[v];
        live = next[vertices];
        for (TriangleId t = 0; t < slots; ++t)
            if (is_live(t))
                new_of_slot[t] = next[smallest(t)]++;
    }
    {
        std::vector<std::uint8_t> labels(live);
        for (TriangleId t = 0; t < slots; ++t)
            if (new_of_slot[t] != no_triangle)
                labels[new_of_slot[t]] = labels_[t];
        labels_.swap(labels);
    }
    {
        std::vector<std::uint32_t> links(3 * live);
        for (TriangleId t = 0; t < slots; ++t) {
            if (new_of_slot[t] == no_triangle)
                continue;
            for (int i = 0; i < 3; ++i) {
                const std::uint32_t word = links_[half_edge(t, i)];
                const HalfEdge twin = word & link_mask;
                links[half_edge(new_of_slot[t], i)] =
                    half_edge(new_of_slot[triangle_of(twin)], edge_of(twin)) | (word & ~link_mask);
            }
        }
        links_.swap(links);
    }
    {
        std::vector<VertexId> tri_vertices(3 * live);
        for (TriangleId t = 0; t < slots; ++t)
            if (new_of_slot[t] != no_triangle)
                for (int i = 0; i < 3; ++i)
                    tri_vertices[half_edge(new_of_slot[t], i)] = new_of_old[vertex(t, i)];
        tri_vertices_.swap(tri_vertices);
    }
    free_.clear();
    for (auto &[from, into] : dropped_)
        from = new_of_old[from], into = new_of_old[into];
    auto moved = [&](TriangleId t) { return t < slots ? new_of_slot[t] : no_triangle; };
    last_ = moved(last_);
    recover_hint_ = moved(recover_hint_);
    return new_of_slot;
}

} // namespace globemesh
