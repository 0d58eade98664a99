// SphericalDelaunay: construction and insertion (Bowyer-Watson cavities and fans).
#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "delaunay_internal.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "hilbert.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

namespace {

// True when three points are not on one line in 3-D (so they span a plane): some orient3d with
// the origin or a coordinate axis point is non-zero (those four points are not coplanar).
bool spans_plane(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    static const Vec3 probes[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const Vec3 &q : probes)
        if (predicates::orient3d(a, b, c, q) != 0)
            return true;
    return false;
}

// arc_angle(a, p) <= tol, skipping the atan2 when the chord already shows the points apart (the
// chord is never longer than the arc; the 1e-14 margin dwarfs the rounding of both formulas).
inline bool within(const Vec3 &a, const Vec3 &p, double tol) {
    const double dx = a.x - p.x, dy = a.y - p.y, dz = a.z - p.z;
    const double far = tol + 1e-14;
    if (dx * dx + dy * dy + dz * dz > far * far)
        return false;
    return arc_angle(a, p) <= tol;
}

// Picks, in the sequence at(0), at(1), ..., a first point, a distinct second, a third spanning a
// plane with them, and a fourth off that plane; k receives their positions.
template <class At> void pick_tetrahedron(At at, std::size_t n, double tol, std::size_t k[4]) {
    k[0] = k[1] = k[2] = k[3] = 0;
    std::size_t found = n > 0 ? 1 : 0;
    for (std::size_t i = 1; i < n && found < 4; ++i) {
        const Vec3 &p = at(i);
        bool ok = false;
        if (found == 1)
            ok = arc_angle(at(k[0]), p) > tol;
        else if (found == 2)
            ok = arc_angle(at(k[0]), p) > tol && arc_angle(at(k[1]), p) > tol &&
                 spans_plane(at(k[0]), at(k[1]), p);
        else
            ok = predicates::orient3d(at(k[0]), at(k[1]), at(k[2]), p) != 0;
        if (ok)
            k[found++] = i;
    }
    if (found < 3)
        throw DataError("fewer than 3 distinct points: nothing to triangulate");
    if (found < 4)
        throw DataError("all points lie on one circle of the sphere (e.g. one great circle): "
                        "their triangulation is degenerate");
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------------------------

void SphericalDelaunay::initial_tetrahedron(std::span<const Vec3> points,
                                            std::span<const std::uint32_t> order,
                                            std::vector<VertexId> &vertex_of) {
    std::size_t k[4];
    pick_tetrahedron([&](std::size_t i) -> const Vec3 & { return points[order[i]]; }, order.size(),
                     options_.merge_tolerance_rad, k);
    VertexId v[4];
    for (int j = 0; j < 4; ++j) {
        v[j] = static_cast<VertexId>(points_.size());
        points_.push_back(points[order[k[j]]]);
        bounded_ = bounded_ && bounded(points_.back());
        vertex_of[order[k[j]]] = v[j];
    }
    make_tetrahedron(v);
}

void SphericalDelaunay::make_tetrahedron(VertexId v[4]) {
    // Faces counter-clockwise from outside: with orient3d(a,b,c,d) < 0 they are
    // (a,b,c), (a,c,d), (a,d,b), (b,d,c) (each face has the fourth vertex below it).
    if (predicates::orient3d(points_[v[0]], points_[v[1]], points_[v[2]], points_[v[3]]) > 0)
        std::swap(v[0], v[1]);
    const VertexId faces[4][3] = {
        {v[0], v[1], v[2]}, {v[0], v[2], v[3]}, {v[0], v[3], v[1]}, {v[1], v[3], v[2]}};
    TriangleId t[4];
    for (int f = 0; f < 4; ++f)
        t[f] = new_triangle(faces[f][0], faces[f][1], faces[f][2], 0);
    // Link every pair of faces sharing an edge (each edge a->b of one face is b->a of another).
    for (int f = 0; f < 4; ++f)
        for (int i = 0; i < 3; ++i) {
            VertexId a = vertex(t[f], next3(i)), b = vertex(t[f], prev3(i));
            for (int g = 0; g < 4; ++g)
                for (int j = 0; j < 3; ++j)
                    if (vertex(t[g], next3(j)) == b && vertex(t[g], prev3(j)) == a)
                        links_[half_edge(t[f], i)] = half_edge(t[g], j);
        }
}

std::vector<std::uint32_t> SphericalDelaunay::insertion_order(std::span<const Vec3> points,
                                                              std::uint64_t seed) {
    return detail::brio_order(points, seed);
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::vector<Vec3> &&points) {
    std::vector<std::uint32_t> order = insertion_order(points, options_.seed);
    return insert_points(std::move(points), std::move(order));
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::vector<Vec3> &&points,
                                                       std::vector<std::uint32_t> &&order) {
    if (!points_.empty() || triangle_slots() != 0)
        throw std::invalid_argument(
            "SphericalDelaunay::insert_points(vector&&) needs an empty triangulation");
    const std::size_t n = points.size();
    if (order.size() != n || n >= 0x80000000u)
        throw std::invalid_argument(
            "SphericalDelaunay::insert_points: the order does not match the points");
    // vertex_of[input index] = position in the order (scattered writes, independent of each
    // other); a repeated or out-of-range entry means `order` is not a permutation.
    std::vector<VertexId> vertex_of(n, no_vertex);
    for (std::size_t j = 0; j < n; ++j) {
        const std::uint32_t i = order[j];
        if (i >= n || vertex_of[i] != no_vertex)
            throw std::invalid_argument(
                "SphericalDelaunay::insert_points: the order is not a permutation of the points");
        vertex_of[i] = static_cast<VertexId>(j);
    }
    // Gather the points in insertion order into an exact-size copy (independent reads, where
    // following the permutation's cycles in place makes one long chain of cache misses). Both
    // copies exist only here, before any triangle: 24 + 24 + 4 + 4 B/point, below the peak.
    {
        std::vector<Vec3> gathered;
        gathered.reserve(n);
        bool all_bounded = true;
        for (std::size_t j = 0; j < n; ++j) {
            gathered.push_back(points[order[j]]);
            all_bounded = all_bounded && bounded(gathered.back());
        }
        bounded_ = all_bounded;
        points = std::move(gathered);
    }
    order.clear();
    order.shrink_to_fit();

    points_ = std::move(points);
    points.clear();
    reserve_for(n);
    // The first four points not on one plane, in order, make the initial tetrahedron.
    std::size_t k[4];
    pick_tetrahedron([&](std::size_t i) -> const Vec3 & { return points_[i]; }, n,
                     options_.merge_tolerance_rad, k);
    VertexId tetra[4];
    for (int j = 0; j < 4; ++j)
        tetra[j] = static_cast<VertexId>(k[j]);
    make_tetrahedron(tetra);
    std::vector<std::pair<VertexId, VertexId>> merges; // (merged vertex, vertex it joined)
    TriangleId hint = last_;
    for (VertexId v = 0; v < n; ++v) {
        if (v == tetra[0] || v == tetra[1] || v == tetra[2] || v == tetra[3])
            continue;
        const Vec3 p = points_[v];
        VertexId got = insert_vertex(p, v, hint);
        if (got != v)
            merges.emplace_back(v, got);
        hint = last_;
    }
    if (!merges.empty())
        for (auto &id : vertex_of) {
            auto it =
                std::lower_bound(merges.begin(), merges.end(), std::make_pair(id, VertexId{0}));
            if (it != merges.end() && it->first == id)
                id = it->second;
        }
    resolve_dropped(vertex_of);
    return vertex_of;
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::span<const Vec3> points) {
    std::vector<VertexId> vertex_of(points.size(), no_vertex);
    std::vector<std::uint32_t> order = detail::brio_order(points, options_.seed);
    const std::size_t expected = points_.size() + points.size();
    reserve(expected);
    if (triangle_count() == 0)
        initial_tetrahedron(points, order, vertex_of);
    TriangleId hint = last_;
    for (std::uint32_t i : order) {
        if (vertex_of[i] != no_vertex)
            continue;
        vertex_of[i] = insert(points[i], hint);
        hint = last_;
    }
    order.clear();
    order.shrink_to_fit();
    resolve_dropped(vertex_of);
    return vertex_of;
}

// ---------------------------------------------------------------------------------------------
// Insertion (Bowyer-Watson)
// ---------------------------------------------------------------------------------------------

// Greedy descent over the vertex graph from the vertices of t: move to a neighbour closer to p
// while there is one. In a Delaunay triangulation a vertex that is not the nearest to p has a
// neighbour closer to p, so this ends at the nearest vertex (Bose and Morin, "Online routing in
// triangulations", 2004); the distance falls strictly at each step, so it ends. A flat region
// (triangles on one great circle through the origin, closing a hull in a closed hemisphere) is
// no Delaunay triangulation of its points in this sense: the walk stops on any flat triangle of
// the great circle p lies on, whose vertices need not neighbour p's nearest. So the descent
// starts from the nearest vertex of the flat region around t and of the triangles bordering it.
VertexId SphericalDelaunay::nearest_vertex(const Vec3 &p, TriangleId t) const {
    HalfEdge best = half_edge(t, 0);
    double best_d = arc_angle(points_[origin(best)], p);
    auto consider = [&](TriangleId s) {
        for (int i = 0; i < 3; ++i) {
            const double d = arc_angle(points_[origin(half_edge(s, i))], p);
            if (d < best_d)
                best = half_edge(s, i), best_d = d;
        }
    };
    auto flat = [&](TriangleId s) {
        return orient(points_[vertex(s, 0)], points_[vertex(s, 1)], points_[vertex(s, 2)]) == 0;
    };
    consider(t);
    if (flat(t)) {
        std::vector<TriangleId> region{t};
        for (std::size_t k = 0; k < region.size(); ++k)
            for (int i = 0; i < 3; ++i) {
                const TriangleId nb = neighbour(region[k], i);
                if (std::find(region.begin(), region.end(), nb) != region.end())
                    continue;
                consider(nb);
                if (flat(nb))
                    region.push_back(nb);
            }
    }
    for (bool moved = true; moved;) {
        moved = false;
        HalfEdge h = best;
        std::size_t guard = 0;
        do {
            const double d = arc_angle(points_[destination(h)], p);
            if (d < best_d) {
                best_d = d;
                best = twin(h); // leaves the closer vertex
                moved = true;
                break;
            }
            h = next_around_origin(h);
        } while (h != best && ++guard < triangle_slots());
    }
    return origin(best);
}

void SphericalDelaunay::resolve_dropped(std::vector<VertexId> &map) const {
    if (dropped_.empty())
        return;
    std::vector<VertexId> into(points_.size(), no_vertex);
    for (const auto &[w, u] : dropped_)
        into[w] = u;
    for (VertexId &v : map) {
        if (v >= into.size())
            continue;
        std::size_t guard = 0;
        while (into[v] != no_vertex && ++guard <= dropped_.size())
            v = into[v];
    }
}

VertexId SphericalDelaunay::insert(const Vec3 &p, TriangleId hint) {
    return insert_vertex(p, no_vertex, hint);
}

VertexId SphericalDelaunay::insert_vertex(const Vec3 &p, VertexId id, TriangleId hint) {
    const TriangleId start = start_triangle(hint);
    if (start == no_triangle)
        throw DataError("cannot insert into an empty triangulation");
    bool inside = false;
    const TriangleId located = walk(p, start, inside);
    // Merge with a vertex of the located triangle when within tolerance (exact duplicates land
    // here).
    for (int i = 0; i < 3; ++i)
        if (within(points_[vertex(located, i)], p, options_.merge_tolerance_rad)) {
            ++merged_;
            return vertex(located, i);
        }
    const Vec3 &a = points_[vertex(located, 0)];
    const Vec3 &b = points_[vertex(located, 1)];
    const Vec3 &c = points_[vertex(located, 2)];
    // p is on or left of the three edges when the walk stopped by itself; test them otherwise.
    const bool inside_solid =
        orient(a, b, c) > 0 &&
        (inside || (orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0));
    const bool located_visible = visible(located, p);
    TriangleId seed = located;
    if (!inside_solid && !located_visible) {
        // p is outside the solid region (in the ghost part) or the walk stopped early: search
        // breadth-first for a triangle p is beyond. search_ lists every triangle marked.
        seed = no_triangle;
        search_.clear();
        search_.push_back(located);
        set_mark(located);
        for (std::size_t k = 0; k < search_.size() && seed == no_triangle; ++k) {
            for (int i = 0; i < 3 && seed == no_triangle; ++i) {
                TriangleId nb = neighbour(search_[k], i);
                if (marked(nb))
                    continue;
                set_mark(nb);
                search_.push_back(nb);
                if (visible(nb, p))
                    seed = nb;
            }
        }
        for (TriangleId s : search_)
            clear_mark(s);
    }
    if (seed == no_triangle || (inside_solid && !located_visible)) {
        // p lies inside the hull of its neighbours (closer than rounding lets the hull resolve):
        // merge it into its nearest vertex. That need not be a vertex of the located triangle:
        // the walk can stop on a flat triangle of a great circle through p far from p's twin.
        ++merged_;
        return nearest_vertex(p, located);
    }
    VertexId v;
    if (insert_fan(p, seed, id, v))
        return v;
    return insert_in_cavity(p, seed, no_half_edge, id);
}

// The cavity of p without constraints, grown depth-first from `seed` (a triangle p is beyond)
// so that its rim comes out in counter-clockwise order: entering a neighbour across rim edge
// u->w replaces that edge by the neighbour's edges u->x then x->w. The fan around p then links
// each new triangle to the next one along the rim directly, and reuses the cavity's slots.
// Returns false, with nothing changed, when the cavity touches a constrained edge or its rim is
// not one closed chain (a vertex swallowed by the cavity): insert_in_cavity handles those.
bool SphericalDelaunay::insert_fan(const Vec3 &p, TriangleId seed, VertexId id, VertexId &result) {
    cavity_.clear();
    rim_.clear();
    auto &stack = search_;
    stack.clear();
    set_mark(seed);
    cavity_.push_back(seed);
    stack.push_back(half_edge(seed, 2));
    stack.push_back(half_edge(seed, 1));
    stack.push_back(half_edge(seed, 0));
    bool ok = true;
    while (!stack.empty()) {
        const HalfEdge h = stack.back();
        stack.pop_back();
        const std::uint32_t word = links_[h];
        if (word & constrained_bit) {
            ok = false;
            break;
        }
        const HalfEdge o = word & link_mask;
        const TriangleId nb = triangle_of(o);
        if (marked(nb)) {
            // Reached a cavity triangle a second way: the cavity swallows a vertex (possible
            // only for points closer than rounding resolves); insert_in_cavity handles that.
            ok = false;
            break;
        }
        if (visible(nb, p)) {
            set_mark(nb);
            cavity_.push_back(nb);
            const int j = edge_of(o);
            stack.push_back(half_edge(nb, prev3(j)));
            stack.push_back(half_edge(nb, next3(j)));
        } else {
            const TriangleId s = triangle_of(h);
            const int i = edge_of(h);
            rim_.push_back({vertex(s, next3(i)), vertex(s, prev3(i)), word, labels_[s]});
        }
    }
    // Without such a cycle the depth-first order walks round a disk glued from the cavity's
    // triangles along the edges it crossed: consecutive rim edges share their vertex, and the
    // rim has k + 2 edges for k triangles.
    const std::size_t m = rim_.size();
    if (!ok) {
        for (TriangleId s : cavity_)
            clear_mark(s);
        return false;
    }
    // Merge with a rim vertex within tolerance (the nearest vertex to p is on the rim).
    for (const Rim &r : rim_)
        if (within(points_[r.u], p, options_.merge_tolerance_rad)) {
            for (TriangleId s : cavity_)
                clear_mark(s);
            ++merged_;
            result = r.u;
            return true;
        }
    const std::size_t k = cavity_.size(); // m == k + 2
    if (free_.size() < m - k &&
        3 * (static_cast<std::uint64_t>(triangle_slots()) + (m - k - free_.size())) > link_mask)
        throw DataError("triangulation too large: more than " + std::to_string(link_mask / 3) +
                        " triangles (about 178 million points)");
    VertexId v = id;
    if (v == no_vertex) {
        v = static_cast<VertexId>(points_.size());
        points_.push_back(p);
        bounded_ = bounded_ && bounded(p);
    }
    // Slots of the fan: the cavity's k, then two free or new ones.
    for (std::size_t r = k; r < m; ++r)
        cavity_.push_back(new_slot());
    const TriangleId *fan = cavity_.data();
    for (std::size_t r = 0; r < m; ++r) {
        const TriangleId t = fan[r];
        const Rim &e = rim_[r];
        tri_vertices_[3 * t] = v;
        tri_vertices_[3 * t + 1] = e.u;
        tri_vertices_[3 * t + 2] = e.w;
        labels_[t] = e.label;
        const HalfEdge o = e.outside & link_mask;
        const std::uint32_t flag = e.outside & constrained_bit;
        links_[3 * t] = o | flag;
        links_[o] = 3 * t | flag;
        links_[3 * t + 1] = half_edge(fan[r + 1 == m ? 0 : r + 1], 2); // w -> v
        links_[3 * t + 2] = half_edge(fan[r == 0 ? m - 1 : r - 1], 1); // v -> u
    }
    last_ = fan[m - 1];
    result = v;
    return true;
}

VertexId SphericalDelaunay::insert_in_triangle(const Vec3 &p, TriangleId t) {
    for (int i = 0; i < 3; ++i) {
        if (arc_angle(points_[vertex(t, i)], p) <= options_.merge_tolerance_rad) {
            ++merged_;
            return vertex(t, i);
        }
    }
    // A point exactly on an edge splits it (both triangles must go).
    for (int i = 0; i < 3; ++i)
        if (orient(points_[vertex(t, next3(i))], points_[vertex(t, prev3(i))], p) == 0)
            return insert_in_cavity(p, t, half_edge(t, i));
    return insert_in_cavity(p, t, no_half_edge);
}

VertexId SphericalDelaunay::split_edge(HalfEdge h, const Vec3 &p) {
    for (VertexId v : {origin(h), destination(h)})
        if (arc_angle(points_[v], p) <= options_.merge_tolerance_rad) {
            ++merged_;
            return v;
        }
    return insert_in_cavity(p, triangle_of(h), h);
}

// The cavity of p: grown from `seed` (and across `split` when given) over unconstrained edges to
// the triangles p lies beyond, then shrunk until it is star-shaped from p. Leaves the cavity's
// triangles marked in cavity_ and its rim in cavity_boundary_.
void SphericalDelaunay::grow_cavity(const Vec3 &p, TriangleId seed, HalfEdge split) {
    cavity_.clear();
    cavity_.push_back(seed);
    set_mark(seed);
    TriangleId other = no_triangle;
    if (split != no_half_edge) {
        other = triangle_of(twin(split));
        cavity_.push_back(other);
        set_mark(other);
    }
    for (std::size_t k = 0; k < cavity_.size(); ++k) {
        TriangleId s = cavity_[k];
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(s, i);
            if (is_constrained(h))
                continue;
            TriangleId nb = triangle_of(twin(h));
            if (marked(nb))
                continue;
            if (visible(nb, p)) {
                set_mark(nb);
                cavity_.push_back(nb);
            }
        }
    }

    // Boundary of the cavity. Without constraints the cavity is exactly the part of the hull
    // visible from p, a disk that every rim edge sees p from. A constraint can cut that region
    // so that a rim edge no longer sees p on its left: then shrink the cavity (the seed
    // triangles always stay) until every rim edge of a solid triangle does.
    bool touches_constraint = false;
    for (TriangleId s : cavity_)
        for (int i = 0; i < 3; ++i)
            if (is_constrained(half_edge(s, i)))
                touches_constraint = true;
    for (;;) {
        cavity_boundary_.clear();
        TriangleId drop = no_triangle;
        for (TriangleId s : cavity_) {
            for (int i = 0; i < 3; ++i) {
                HalfEdge h = half_edge(s, i);
                HalfEdge o = twin(h);
                bool inner =
                    marked(triangle_of(o)) && !(is_constrained(h) && h != split && o != split);
                if (inner)
                    continue;
                cavity_boundary_.push_back(h);
                if (touches_constraint && drop == no_triangle && s != seed && s != other) {
                    const Vec3 &u = points_[origin(h)];
                    const Vec3 &w = points_[destination(h)];
                    if (orient(u, w, p) <= 0 && is_solid(s))
                        drop = s;
                }
            }
        }
        if (drop == no_triangle)
            break;
        clear_mark(drop);
        cavity_.erase(std::find(cavity_.begin(), cavity_.end(), drop));
    }
}

// A vertex of the cavity that is not on its rim would leave the triangulation with the
// cavity ("swallowed": p's cavity holds its whole star, possible only when it lies within
// rounding of the hull of p and its neighbours). When p is nearer to it than any rim vertex
// is, p merges into it and nothing changes; otherwise it is dropped and merged into its
// nearest rim vertex (a twin a few ulps away), recorded so that insert_points maps it there.
// (Sorted lists: a cavity can be large, e.g. every ghost triangle for a far point.)
// Returns the swallowed vertex p merges into, or no_vertex, with by_start_ holding (dropped,
// into) for each vertex dropped and `drops` their number.
VertexId SphericalDelaunay::swallowed_vertex(const Vec3 &p, VertexId split_a, VertexId split_b,
                                             std::size_t &drops) {
    swallowed_.clear();
    by_start_.clear();
    rim_vertices_.clear();
    for (HalfEdge h : cavity_boundary_)
        rim_vertices_.push_back(origin(h));
    std::sort(rim_vertices_.begin(), rim_vertices_.end());
    for (TriangleId s : cavity_)
        for (int i = 0; i < 3; ++i)
            if (!std::binary_search(rim_vertices_.begin(), rim_vertices_.end(), vertex(s, i)))
                swallowed_.push_back(vertex(s, i));
    std::sort(swallowed_.begin(), swallowed_.end());
    swallowed_.erase(std::unique(swallowed_.begin(), swallowed_.end()), swallowed_.end());
    drops = 0;
    if (!swallowed_.empty()) {
        VertexId closest = no_vertex; // the swallowed vertex nearest to p that p is nearest to
        double closest_d = 0;
        for (const VertexId w : swallowed_) {
            const double to_p = arc_angle(points_[w], p);
            VertexId target = no_vertex;
            double target_d = to_p;
            for (HalfEdge h : cavity_boundary_) {
                const double d = arc_angle(points_[w], points_[origin(h)]);
                if (d < target_d)
                    target = origin(h), target_d = d;
            }
            // The ends of a split edge stay (the caller holds them): p merges into one instead.
            if (target == no_vertex || w == split_a || w == split_b) {
                if (closest == no_vertex || to_p < closest_d)
                    closest = w, closest_d = to_p;
            } else {
                by_start_.emplace_back(w, target); // scratch: (dropped, into)
                ++drops;
            }
        }
        return closest;
    }
    return no_vertex;
}

// Replaces the cavity of p (grow_cavity) by a fan around p, or merges p into a vertex of it.
VertexId SphericalDelaunay::insert_in_cavity(const Vec3 &p, TriangleId seed, HalfEdge split,
                                             VertexId id) {
    const bool split_constrained = split != no_half_edge && is_constrained(split);
    const VertexId split_a = split != no_half_edge ? origin(split) : no_vertex;
    const VertexId split_b = split != no_half_edge ? destination(split) : no_vertex;
    grow_cavity(p, seed, split);

    // Merge with a boundary vertex within tolerance (the nearest vertex to p is on the boundary).
    for (HalfEdge h : cavity_boundary_) {
        VertexId u = origin(h);
        if (within(points_[u], p, options_.merge_tolerance_rad)) {
            for (TriangleId s : cavity_)
                clear_mark(s);
            ++merged_;
            return u;
        }
    }

    std::size_t drops = 0;
    const VertexId closest = swallowed_vertex(p, split_a, split_b, drops);
    if (closest != no_vertex) {
        by_start_.clear();
        for (TriangleId s : cavity_)
            clear_mark(s);
        ++merged_;
        return closest;
    }

    // Record each boundary edge's outside half-edge and flag before the cavity is freed.
    // Each new triangle keeps the label of the cavity triangle it replaces along its rim edge:
    // when a constrained edge is split, the two sides (e.g. ocean and land) keep their labels.
    for (TriangleId s : cavity_)
        clear_mark(s);
    std::vector<Rim> &rim = rim_;
    rim.clear();
    for (HalfEdge h : cavity_boundary_)
        rim.push_back({origin(h), destination(h), links_[h], labels_[triangle_of(h)]});
    for (TriangleId s : cavity_)
        free_triangle(s);
    if (drops > 0) {
        dropped_.insert(dropped_.end(), by_start_.begin(), by_start_.end());
        merged_ += drops;
    }

    VertexId v = id;
    if (v == no_vertex) {
        v = static_cast<VertexId>(points_.size());
        points_.push_back(p);
        bounded_ = bounded_ && bounded(p);
    }
    // Fan: triangle (v, u, w) per rim edge u->w. Edge 0 (u->w) faces outside; edge 1 (w->v) is
    // the twin of edge 2 (v->w) of the triangle whose rim edge starts at w.
    auto &by_start = by_start_;
    by_start.clear();
    for (const Rim &r : rim) {
        TriangleId t = new_triangle(v, r.u, r.w, r.label);
        HalfEdge h = half_edge(t, 0);
        HalfEdge o = r.outside & link_mask;
        links_[h] = r.outside;
        links_[o] = h | (r.outside & constrained_bit);
        by_start.emplace_back(r.u, t);
    }
    std::sort(by_start.begin(), by_start.end());
    for (const auto &[u, t] : by_start) {
        VertexId w = vertex(t, 2);
        auto it =
            std::lower_bound(by_start.begin(), by_start.end(), std::make_pair(w, TriangleId{0}));
        TriangleId tw = it->second;
        links_[half_edge(t, 1)] = half_edge(tw, 2);
        links_[half_edge(tw, 2)] = half_edge(t, 1);
    }
    if (split_constrained) {
        // Both halves of the split constraint stay constrained.
        for (const auto &[u, t] : by_start) {
            if (u == split_a || u == split_b)
                set_constrained(half_edge(t, 2), true); // v -> u
        }
    }
    return v;
}

} // namespace globemesh
