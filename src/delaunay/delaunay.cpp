#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "hilbert.hpp"

namespace globemesh {

using predicates::in_circle;
using predicates::orient;

namespace {

constexpr int next3(int i) { return i == 2 ? 0 : i + 1; }
constexpr int prev3(int i) { return i == 0 ? 2 : i - 1; }

// True when three points are not on one line in 3-D (so they span a plane): some orient3d with
// the origin or a coordinate axis point is non-zero (those four points are not coplanar).
bool spans_plane(const Vec3& a, const Vec3& b, const Vec3& c) {
    static const Vec3 probes[] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const Vec3& q : probes)
        if (predicates::orient3d(a, b, c, q) != 0) return true;
    return false;
}

// arc_angle(a, p) <= tol, skipping the atan2 when the chord already shows the points apart (the
// chord is never longer than the arc; the 1e-14 margin dwarfs the rounding of both formulas).
inline bool within(const Vec3& a, const Vec3& p, double tol) {
    const double dx = a.x - p.x, dy = a.y - p.y, dz = a.z - p.z;
    const double far = tol + 1e-14;
    if (dx * dx + dy * dy + dz * dz > far * far) return false;
    return arc_angle(a, p) <= tol;
}

// Picks, in the sequence at(0), at(1), ..., a first point, a distinct second, a third spanning a
// plane with them, and a fourth off that plane; k receives their positions.
template <class At>
void pick_tetrahedron(At at, std::size_t n, double tol, std::size_t k[4]) {
    k[0] = k[1] = k[2] = k[3] = 0;
    std::size_t found = n > 0 ? 1 : 0;
    for (std::size_t i = 1; i < n && found < 4; ++i) {
        const Vec3& p = at(i);
        bool ok = false;
        if (found == 1) ok = arc_angle(at(k[0]), p) > tol;
        else if (found == 2)
            ok = arc_angle(at(k[0]), p) > tol && arc_angle(at(k[1]), p) > tol && spans_plane(at(k[0]), at(k[1]), p);
        else
            ok = predicates::orient3d(at(k[0]), at(k[1]), at(k[2]), p) != 0;
        if (ok) k[found++] = i;
    }
    if (found < 3) throw DataError("fewer than 3 distinct points: nothing to triangulate");
    if (found < 4)
        throw DataError("all points lie on one circle of the sphere (e.g. one great circle): "
                        "their triangulation is degenerate");
}

} // namespace

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

bool SphericalDelaunay::visible(TriangleId t, const Vec3& p) const {
    return in_circle(points_[vertex(t, 0)], points_[vertex(t, 1)], points_[vertex(t, 2)], p) > 0;
}

// ---------------------------------------------------------------------------------------------
// Construction
// ---------------------------------------------------------------------------------------------

void SphericalDelaunay::initial_tetrahedron(std::span<const Vec3> points,
                                            std::span<const std::uint32_t> order,
                                            std::vector<VertexId>& vertex_of) {
    std::size_t k[4];
    pick_tetrahedron([&](std::size_t i) -> const Vec3& { return points[order[i]]; }, order.size(),
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
    const VertexId faces[4][3] = {{v[0], v[1], v[2]}, {v[0], v[2], v[3]}, {v[0], v[3], v[1]}, {v[1], v[3], v[2]}};
    TriangleId t[4];
    for (int f = 0; f < 4; ++f) t[f] = new_triangle(faces[f][0], faces[f][1], faces[f][2], 0);
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

std::vector<std::uint32_t> SphericalDelaunay::insertion_order(std::span<const Vec3> points,
                                                              std::uint64_t seed) {
    return detail::brio_order(points, seed);
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::vector<Vec3>&& points) {
    std::vector<std::uint32_t> order = insertion_order(points, options_.seed);
    return insert_points(std::move(points), std::move(order));
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::vector<Vec3>&& points,
                                                       std::vector<std::uint32_t>&& order) {
    if (!points_.empty() || triangle_slots() != 0)
        throw std::invalid_argument("SphericalDelaunay::insert_points(vector&&) needs an empty triangulation");
    const std::size_t n = points.size();
    if (order.size() != n || n >= 0x80000000u)
        throw std::invalid_argument("SphericalDelaunay::insert_points: the order does not match the points");
    // vertex_of[input index] = position in the order (scattered writes, independent of each
    // other); a repeated or out-of-range entry means `order` is not a permutation.
    std::vector<VertexId> vertex_of(n, no_vertex);
    for (std::size_t j = 0; j < n; ++j) {
        const std::uint32_t i = order[j];
        if (i >= n || vertex_of[i] != no_vertex)
            throw std::invalid_argument("SphericalDelaunay::insert_points: the order is not a permutation of the points");
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
    pick_tetrahedron([&](std::size_t i) -> const Vec3& { return points_[i]; }, n,
                     options_.merge_tolerance_rad, k);
    VertexId tetra[4];
    for (int j = 0; j < 4; ++j) tetra[j] = static_cast<VertexId>(k[j]);
    make_tetrahedron(tetra);
    std::vector<std::pair<VertexId, VertexId>> merges; // (merged vertex, vertex it joined)
    TriangleId hint = last_;
    for (VertexId v = 0; v < n; ++v) {
        if (v == tetra[0] || v == tetra[1] || v == tetra[2] || v == tetra[3]) continue;
        const Vec3 p = points_[v];
        VertexId got = insert_vertex(p, v, hint);
        if (got != v) merges.emplace_back(v, got);
        hint = last_;
    }
    if (!merges.empty())
        for (auto& id : vertex_of) {
            auto it = std::lower_bound(merges.begin(), merges.end(), std::make_pair(id, VertexId{0}));
            if (it != merges.end() && it->first == id) id = it->second;
        }
    resolve_dropped(vertex_of);
    return vertex_of;
}

std::vector<VertexId> SphericalDelaunay::insert_points(std::span<const Vec3> points) {
    std::vector<VertexId> vertex_of(points.size(), no_vertex);
    std::vector<std::uint32_t> order = detail::brio_order(points, options_.seed);
    const std::size_t expected = points_.size() + points.size();
    reserve(expected);
    if (triangle_count() == 0) initial_tetrahedron(points, order, vertex_of);
    TriangleId hint = last_;
    for (std::uint32_t i : order) {
        if (vertex_of[i] != no_vertex) continue;
        vertex_of[i] = insert(points[i], hint);
        hint = last_;
    }
    order.clear();
    order.shrink_to_fit();
    resolve_dropped(vertex_of);
    return vertex_of;
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
            if (t == triangle_slots()) return no_triangle;
        }
    }
    return t;
}

TriangleId SphericalDelaunay::locate(const Vec3& p, TriangleId hint) const {
    const TriangleId t = start_triangle(hint);
    if (t == no_triangle) return no_triangle;
    bool inside = false;
    return walk(p, t, inside);
}

// Visibility walk across edges that have p strictly on their right. The edge a triangle was
// entered by has p on its left (its twin had p on its right), so only the other two are tested;
// which of the two goes first is drawn from a small deterministic generator (a stand-in for the
// stochastic walk, which cannot cycle for ever in a Delaunay triangulation); the step bound
// guards constrained or ghost regions. `inside` is true when the walk stopped at a triangle
// with p on or left of all three edges (every one tested or known), false when the bound hit.
TriangleId SphericalDelaunay::walk(const Vec3& p, TriangleId t, bool& inside) const {
    const std::size_t limit = 64 + 32 * static_cast<std::size_t>(std::sqrt(double(triangle_slots())));
    const VertexId* tv = tri_vertices_.data();
    const Vec3* pts = points_.data();
    const bool fast = bounded_ && bounded(p);
    auto right_of = [&](TriangleId s, int i) {
        const Vec3& u = pts[tv[3 * s + next3(i)]];
        const Vec3& w = pts[tv[3 * s + prev3(i)]];
        if (fast) {
            // det[u, w, p] rounded, certified when beyond a static bound: every coordinate is
            // at most 2 in magnitude, so the 6 monomials add up to at most 48 and the 5
            // roundings each passes through err by at most gamma_5 * 48 < 241 u (Higham, lemma
            // 3.1; underflow adds at most a few 2^-1074). 256 u = 2^-45.
            const double m1 = w.y * p.z - w.z * p.y;
            const double m2 = w.z * p.x - w.x * p.z;
            const double m3 = w.x * p.y - w.y * p.x;
            const double det = u.x * m1 + u.y * m2 + u.z * m3;
            if (det < -0x1p-45) return true;
            if (det > 0x1p-45) return false;
        }
        // p at an end of the edge (a walk to a vertex's own point): orient is 0, which only the
        // exact stage would tell.
        if (p == u || p == w) return false;
        return orient(u, w, p) < 0;
    };
    // The first triangle: all three edges.
    int cross = -1;
    for (int i = 0; i < 3 && cross < 0; ++i)
        if (right_of(t, i)) cross = i;
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
        if (bits & 1u) std::swap(first, second);
        cross = right_of(t, first) ? first : right_of(t, second) ? second : -1;
    }
    inside = true;
    return t;
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
VertexId SphericalDelaunay::nearest_vertex(const Vec3& p, TriangleId t) const {
    HalfEdge best = half_edge(t, 0);
    double best_d = arc_angle(points_[origin(best)], p);
    auto consider = [&](TriangleId s) {
        for (int i = 0; i < 3; ++i) {
            const double d = arc_angle(points_[origin(half_edge(s, i))], p);
            if (d < best_d) best = half_edge(s, i), best_d = d;
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
                if (std::find(region.begin(), region.end(), nb) != region.end()) continue;
                consider(nb);
                if (flat(nb)) region.push_back(nb);
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

void SphericalDelaunay::resolve_dropped(std::vector<VertexId>& map) const {
    if (dropped_.empty()) return;
    std::vector<VertexId> into(points_.size(), no_vertex);
    for (const auto& [w, u] : dropped_) into[w] = u;
    for (VertexId& v : map) {
        if (v >= into.size()) continue;
        std::size_t guard = 0;
        while (into[v] != no_vertex && ++guard <= dropped_.size()) v = into[v];
    }
}

VertexId SphericalDelaunay::insert(const Vec3& p, TriangleId hint) {
    return insert_vertex(p, no_vertex, hint);
}

VertexId SphericalDelaunay::insert_vertex(const Vec3& p, VertexId id, TriangleId hint) {
    const TriangleId start = start_triangle(hint);
    if (start == no_triangle) throw DataError("cannot insert into an empty triangulation");
    bool inside = false;
    const TriangleId located = walk(p, start, inside);
    // Merge with a vertex of the located triangle when within tolerance (exact duplicates land here).
    for (int i = 0; i < 3; ++i)
        if (within(points_[vertex(located, i)], p, options_.merge_tolerance_rad)) {
            ++merged_;
            return vertex(located, i);
        }
    const Vec3& a = points_[vertex(located, 0)];
    const Vec3& b = points_[vertex(located, 1)];
    const Vec3& c = points_[vertex(located, 2)];
    // p is on or left of the three edges when the walk stopped by itself; test them otherwise.
    const bool inside_solid = orient(a, b, c) > 0 &&
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
                if (marked(nb)) continue;
                set_mark(nb);
                search_.push_back(nb);
                if (visible(nb, p)) seed = nb;
            }
        }
        for (TriangleId s : search_) clear_mark(s);
    }
    if (seed == no_triangle || (inside_solid && !located_visible)) {
        // p lies inside the hull of its neighbours (closer than rounding lets the hull resolve):
        // merge it into its nearest vertex. That need not be a vertex of the located triangle:
        // the walk can stop on a flat triangle of a great circle through p far from p's twin.
        ++merged_;
        return nearest_vertex(p, located);
    }
    VertexId v;
    if (insert_fan(p, seed, id, v)) return v;
    return insert_in_cavity(p, seed, no_half_edge, id);
}

// The cavity of p without constraints, grown depth-first from `seed` (a triangle p is beyond)
// so that its rim comes out in counter-clockwise order: entering a neighbour across rim edge
// u->w replaces that edge by the neighbour's edges u->x then x->w. The fan around p then links
// each new triangle to the next one along the rim directly, and reuses the cavity's slots.
// Returns false, with nothing changed, when the cavity touches a constrained edge or its rim is
// not one closed chain (a vertex swallowed by the cavity): insert_in_cavity handles those.
bool SphericalDelaunay::insert_fan(const Vec3& p, TriangleId seed, VertexId id, VertexId& result) {
    cavity_.clear();
    rim_.clear();
    auto& stack = search_;
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
        for (TriangleId s : cavity_) clear_mark(s);
        return false;
    }
    // Merge with a rim vertex within tolerance (the nearest vertex to p is on the rim).
    for (const Rim& r : rim_)
        if (within(points_[r.u], p, options_.merge_tolerance_rad)) {
            for (TriangleId s : cavity_) clear_mark(s);
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
    for (std::size_t r = k; r < m; ++r) cavity_.push_back(new_slot());
    const TriangleId* fan = cavity_.data();
    for (std::size_t r = 0; r < m; ++r) {
        const TriangleId t = fan[r];
        const Rim& e = rim_[r];
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

VertexId SphericalDelaunay::insert_in_triangle(const Vec3& p, TriangleId t) {
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

VertexId SphericalDelaunay::split_edge(HalfEdge h, const Vec3& p) {
    for (VertexId v : {origin(h), destination(h)})
        if (arc_angle(points_[v], p) <= options_.merge_tolerance_rad) {
            ++merged_;
            return v;
        }
    return insert_in_cavity(p, triangle_of(h), h);
}

// Grows the cavity from `seed` (and across `split` when given) over unconstrained edges to the
// triangles p lies beyond, checks it is star-shaped from p, and replaces it by a fan around p.
VertexId SphericalDelaunay::insert_in_cavity(const Vec3& p, TriangleId seed, HalfEdge split, VertexId id) {
    const bool split_constrained = split != no_half_edge && is_constrained(split);
    const VertexId split_a = split != no_half_edge ? origin(split) : no_vertex;
    const VertexId split_b = split != no_half_edge ? destination(split) : no_vertex;

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
            if (is_constrained(h)) continue;
            TriangleId nb = triangle_of(twin(h));
            if (marked(nb)) continue;
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
            if (is_constrained(half_edge(s, i))) touches_constraint = true;
    for (;;) {
        cavity_boundary_.clear();
        TriangleId drop = no_triangle;
        for (TriangleId s : cavity_) {
            for (int i = 0; i < 3; ++i) {
                HalfEdge h = half_edge(s, i);
                HalfEdge o = twin(h);
                bool inner = marked(triangle_of(o)) && !(is_constrained(h) && h != split && o != split);
                if (inner) continue;
                cavity_boundary_.push_back(h);
                if (touches_constraint && drop == no_triangle && s != seed && s != other) {
                    const Vec3& u = points_[origin(h)];
                    const Vec3& w = points_[destination(h)];
                    if (orient(u, w, p) <= 0 && is_solid(s)) drop = s;
                }
            }
        }
        if (drop == no_triangle) break;
        clear_mark(drop);
        cavity_.erase(std::find(cavity_.begin(), cavity_.end(), drop));
    }

    // Merge with a boundary vertex within tolerance (the nearest vertex to p is on the boundary).
    for (HalfEdge h : cavity_boundary_) {
        VertexId u = origin(h);
        if (within(points_[u], p, options_.merge_tolerance_rad)) {
            for (TriangleId s : cavity_) clear_mark(s);
            ++merged_;
            return u;
        }
    }

    // A vertex of the cavity that is not on its rim would leave the triangulation with the
    // cavity ("swallowed": p's cavity holds its whole star, possible only when it lies within
    // rounding of the hull of p and its neighbours). When p is nearer to it than any rim vertex
    // is, p merges into it and nothing changes; otherwise it is dropped and merged into its
    // nearest rim vertex (a twin a few ulps away), recorded so that insert_points maps it there.
    // (Sorted lists: a cavity can be large, e.g. every ghost triangle for a far point.)
    swallowed_.clear();
    by_start_.clear();
    rim_vertices_.clear();
    for (HalfEdge h : cavity_boundary_) rim_vertices_.push_back(origin(h));
    std::sort(rim_vertices_.begin(), rim_vertices_.end());
    for (TriangleId s : cavity_)
        for (int i = 0; i < 3; ++i)
            if (!std::binary_search(rim_vertices_.begin(), rim_vertices_.end(), vertex(s, i)))
                swallowed_.push_back(vertex(s, i));
    std::sort(swallowed_.begin(), swallowed_.end());
    swallowed_.erase(std::unique(swallowed_.begin(), swallowed_.end()), swallowed_.end());
    std::size_t drops = 0;
    if (!swallowed_.empty()) {
        VertexId closest = no_vertex; // the swallowed vertex nearest to p that p is nearest to
        double closest_d = 0;
        for (const VertexId w : swallowed_) {
            const double to_p = arc_angle(points_[w], p);
            VertexId target = no_vertex;
            double target_d = to_p;
            for (HalfEdge h : cavity_boundary_) {
                const double d = arc_angle(points_[w], points_[origin(h)]);
                if (d < target_d) target = origin(h), target_d = d;
            }
            // The ends of a split edge stay (the caller holds them): p merges into one instead.
            if (target == no_vertex || w == split_a || w == split_b) {
                if (closest == no_vertex || to_p < closest_d) closest = w, closest_d = to_p;
            } else {
                by_start_.emplace_back(w, target); // scratch: (dropped, into)
                ++drops;
            }
        }
        if (closest != no_vertex) {
            by_start_.clear();
            for (TriangleId s : cavity_) clear_mark(s);
            ++merged_;
            return closest;
        }
    }

    // Record each boundary edge's outside half-edge and flag before the cavity is freed.
    // Each new triangle keeps the label of the cavity triangle it replaces along its rim edge:
    // when a constrained edge is split, the two sides (e.g. ocean and land) keep their labels.
    for (TriangleId s : cavity_) clear_mark(s);
    std::vector<Rim>& rim = rim_;
    rim.clear();
    for (HalfEdge h : cavity_boundary_) rim.push_back({origin(h), destination(h), links_[h], labels_[triangle_of(h)]});
    for (TriangleId s : cavity_) free_triangle(s);
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
    auto& by_start = by_start_;
    by_start.clear();
    for (const Rim& r : rim) {
        TriangleId t = new_triangle(v, r.u, r.w, r.label);
        HalfEdge h = half_edge(t, 0);
        HalfEdge o = r.outside & link_mask;
        links_[h] = r.outside;
        links_[o] = h | (r.outside & constrained_bit);
        by_start.emplace_back(r.u, t);
    }
    std::sort(by_start.begin(), by_start.end());
    for (const auto& [u, t] : by_start) {
        VertexId w = vertex(t, 2);
        auto it = std::lower_bound(by_start.begin(), by_start.end(), std::make_pair(w, TriangleId{0}));
        TriangleId tw = it->second;
        links_[half_edge(t, 1)] = half_edge(tw, 2);
        links_[half_edge(tw, 2)] = half_edge(t, 1);
    }
    if (split_constrained) {
        // Both halves of the split constraint stay constrained.
        for (const auto& [u, t] : by_start) {
            if (u == split_a || u == split_b) set_constrained(half_edge(t, 2), true); // v -> u
        }
    }
    return v;
}

// ---------------------------------------------------------------------------------------------
// Flips, constraints, moves
// ---------------------------------------------------------------------------------------------

void SphericalDelaunay::flip(HalfEdge h) {
    const TriangleId t = triangle_of(h);
    const int i = edge_of(h);
    const HalfEdge g = twin(h);
    const TriangleId s = triangle_of(g);
    const int j = edge_of(g);
    const VertexId x = vertex(t, i);
    const VertexId y = vertex(s, j);
    // Outer half-edges (with their flags): A across w->x, B across x->u, C across u->y, D across y->w.
    const std::uint32_t A = links_[half_edge(t, next3(i))];
    const std::uint32_t C = links_[half_edge(s, next3(j))];
    // t becomes (x, u, y): edge i = u->y (C), edge i+1 = y->x (diagonal), edge i+2 = x->u (B, unchanged).
    // s becomes (y, w, x): edge j = w->x (A), edge j+1 = x->y (diagonal), edge j+2 = y->w (D, unchanged).
    tri_vertices_[3 * t + prev3(i)] = y;
    tri_vertices_[3 * s + prev3(j)] = x;
    auto attach = [&](HalfEdge mine, std::uint32_t outer) {
        links_[mine] = outer;
        links_[outer & link_mask] = mine | (outer & constrained_bit);
    };
    attach(half_edge(t, i), C);
    attach(half_edge(s, j), A);
    links_[half_edge(t, next3(i))] = half_edge(s, next3(j));
    links_[half_edge(s, next3(j))] = half_edge(t, next3(i));
    last_ = t;
}

void SphericalDelaunay::flip_recorded(HalfEdge h, std::vector<FlipRecord>* journal) {
    if (journal) {
        const TriangleId t = triangle_of(h), s = triangle_of(twin(h));
        FlipRecord rec{t, s, {}, {}, {}, {}};
        for (int k = 0; k < 3; ++k) {
            rec.tv[k] = tri_vertices_[3 * t + k];
            rec.sv[k] = tri_vertices_[3 * s + k];
            rec.tl[k] = links_[3 * t + k];
            rec.sl[k] = links_[3 * s + k];
        }
        journal->push_back(rec);
    }
    flip(h);
}

void SphericalDelaunay::undo_flips(std::vector<FlipRecord>& journal) {
    // Newest first: restore both triangles, then the outer half-edges' links to them.
    for (auto r = journal.rbegin(); r != journal.rend(); ++r) {
        for (int k = 0; k < 3; ++k) {
            tri_vertices_[3 * r->t + k] = r->tv[k];
            tri_vertices_[3 * r->s + k] = r->sv[k];
            links_[3 * r->t + k] = r->tl[k];
            links_[3 * r->s + k] = r->sl[k];
        }
        for (int k = 0; k < 3; ++k) {
            const HalfEdge ht = half_edge(r->t, k), hs = half_edge(r->s, k);
            links_[twin(ht)] = ht | (links_[ht] & constrained_bit);
            links_[twin(hs)] = hs | (links_[hs] & constrained_bit);
        }
    }
    if (!journal.empty()) last_ = journal.front().t;
    journal.clear();
}

bool SphericalDelaunay::legalize_from(std::vector<HalfEdge>& stack, std::vector<FlipRecord>* journal, bool flat_folds,
                                      std::size_t* flips) {
    while (!stack.empty()) {
        HalfEdge h = stack.back();
        stack.pop_back();
        TriangleId t = triangle_of(h);
        if (!is_live(t) || is_constrained(h)) continue;
        HalfEdge g = twin(h);
        TriangleId s = triangle_of(g);
        int i = edge_of(h), j = edge_of(g);
        const Vec3& x = points_[vertex(t, i)];
        const Vec3& u = points_[vertex(t, next3(i))];
        const Vec3& w = points_[vertex(t, prev3(i))];
        const Vec3& y = points_[vertex(s, j)];
        if (in_circle(x, u, w, y) <= 0) continue;
        // A solid non-Delaunay edge bounds a convex quadrilateral when the points lie on the
        // sphere; with ghosts around, make sure the flip keeps both triangles oriented. Convex,
        // not strictly: in_circle's perturbation scales points radially, which keeps every
        // orient() sign, zeros included, so a new triangle with orient() == 0 is flat in the
        // perturbed set too (three vertices on one great circle, e.g. a rounded point exactly on
        // the chord of two others: a flat face of a hull in a closed hemisphere, as insertion
        // makes). Skipping that flip would leave the edge not locally Delaunay; only a clockwise
        // (folded) triangle is refused, and a flat one too when the caller asks.
        const int o1 = orient(x, u, y), o2 = orient(y, w, x);
        if ((o1 < 0 || o2 < 0 || (flat_folds && (o1 == 0 || o2 == 0))) && is_solid(t) && is_solid(s)) {
            // Rounded points are not exactly on the sphere: within ~1e-7 rad of each other their
            // radial rounding outweighs the sphere's curvature, and a vertex can sit inside the
            // hull of its neighbours, where no flip mends the edge.
            if (journal) return false;
            continue;
        }
        flip_recorded(h, journal);
        if (flips) ++*flips;
        // The four outer edges of the new pair.
        stack.push_back(half_edge(t, i));
        stack.push_back(half_edge(t, prev3(i)));
        stack.push_back(half_edge(s, j));
        stack.push_back(half_edge(s, prev3(j)));
    }
    return true;
}

std::size_t SphericalDelaunay::make_delaunay() {
    std::vector<HalfEdge> stack;
    for (TriangleId t = 0; t < triangle_slots(); ++t)
        if (is_live(t))
            for (int i = 0; i < 3; ++i) stack.push_back(half_edge(t, i));
    return make_delaunay(stack);
}

std::size_t SphericalDelaunay::make_delaunay(std::vector<HalfEdge>& edges) {
    std::size_t flips = 0;
    legalize_from(edges, nullptr, false, &flips);
    return flips;
}

std::vector<HalfEdge> SphericalDelaunay::vertex_half_edges() const {
    std::vector<HalfEdge> out(points_.size(), no_half_edge);
    for (TriangleId t = 0; t < triangle_slots(); ++t)
        if (is_live(t))
            for (int i = 0; i < 3; ++i) out[vertex(t, next3(i))] = half_edge(t, i);
    return out;
}

HalfEdge SphericalDelaunay::find_edge(HalfEdge from, VertexId b) const {
    // Rotate around a = origin(from).
    HalfEdge h = from;
    do {
        if (destination(h) == b) return h;
        h = next_around_origin(h);
    } while (h != from);
    return no_half_edge;
}

bool SphericalDelaunay::replace_region(std::span<const HalfEdge> border, std::vector<Vec3>& points,
                                       std::vector<VertexId>& triangles, std::vector<std::uint32_t>& adjacent,
                                       std::uint8_t label,
                                       std::vector<TriangleId>* slots) {
    const std::size_t nt = triangles.size() / 3;
    if (triangles.size() != 3 * nt || adjacent.size() != triangles.size())
        throw std::invalid_argument("SphericalDelaunay::replace_region: 3 vertices and 3 links per triangle");
    const std::size_t first = points_.size();
    const std::size_t end = first + points.size();
    if (nt == 0) return border.empty() && points.empty();
    if (end >= link_mask || nt < 2 * points.size()) return false;
    auto at = [&](VertexId v) -> const Vec3& { return v < first ? points_[v] : points[v - first]; };
    // The border's half-edges and vertices, flagged (the triangulation before the patch is
    // the small one), and sorted for the index of a border half-edge: (half-edge, k).
    std::vector<char> is_border(links_.size(), 0), on_border(points_.size(), 0);
    std::vector<std::pair<HalfEdge, std::uint32_t>> by_edge(border.size());
    for (std::size_t k = 0; k < border.size(); ++k) {
        const HalfEdge h = border[k];
        if (h >= links_.size() || !is_live(triangle_of(h)) || is_border[h]) return false;
        is_border[h] = 1;
        on_border[origin(h)] = 1;
        by_edge[k] = {h, static_cast<std::uint32_t>(k)};
    }
    std::sort(by_edge.begin(), by_edge.end());
    auto border_index = [&](HalfEdge h) -> std::uint32_t {
        if (!is_border[h]) return no_half_edge;
        return std::lower_bound(by_edge.begin(), by_edge.end(), std::make_pair(h, std::uint32_t{0}))->second;
    };
    // The patch alone: corners (new, or on the border), orientation, symmetric links, each
    // border edge taken once with its own ends. taker[k]: the new half-edge in border[k]'s place.
    std::vector<std::uint32_t> taker(border.size(), no_half_edge);
    for (std::size_t r = 0; r < nt; ++r) {
        const VertexId* v = &triangles[3 * r];
        if (v[0] >= end || v[1] >= end || v[2] >= end || v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return false;
        for (int i = 0; i < 3; ++i)
            if (v[i] < first && !on_border[v[i]]) return false;
        if (predicates::orient(at(v[0]), at(v[1]), at(v[2])) <= 0) return false;
        for (int i = 0; i < 3; ++i) {
            const std::uint32_t a = adjacent[3 * r + i];
            if (a & patch_border) {
                const std::uint32_t k = a & ~patch_border;
                if (k >= border.size() || taker[k] != no_half_edge) return false;
                taker[k] = static_cast<std::uint32_t>(3 * r + i);
                if (origin(border[k]) != v[next3(i)] || destination(border[k]) != v[prev3(i)]) return false;
            } else if (a >= 3 * nt || adjacent[a] != 3 * r + i || a / 3 == r ||
                       triangles[a - a % 3 + next3(a % 3)] != v[prev3(i)] ||
                       triangles[a - a % 3 + prev3(a % 3)] != v[next3(i)]) {
                return false;
            }
        }
    }
    if (std::find(taker.begin(), taker.end(), no_half_edge) != taker.end()) return false;
    // Each border edge's other side (twin and constrained flag), read before any change.
    std::vector<std::uint32_t> outside(border.size());
    for (std::size_t k = 0; k < border.size(); ++k) outside[k] = links_[border[k]] & (link_mask | constrained_bit);
    // The region: flooded from the border's triangles without crossing it (marks cleared on
    // every way out). Its corners must all be border vertices, and a border edge's other side
    // lies outside it unless that side is a border edge too.
    std::vector<TriangleId> region;
    auto fail = [&] {
        for (TriangleId t : region) clear_mark(t);
        return false;
    };
    for (const HalfEdge h : border) {
        if (marked(triangle_of(h))) continue;
        set_mark(triangle_of(h));
        region.push_back(triangle_of(h));
        for (std::size_t q = region.size() - 1; q < region.size(); ++q) {
            if (region.size() + 2 * points.size() > nt) return fail(); // larger than the patch: a leak
            const TriangleId t = region[q];
            for (int i = 0; i < 3; ++i) {
                if (!on_border[vertex(t, i)]) return fail();
                const HalfEdge e = half_edge(t, i);
                if (is_border[e]) continue;
                if (is_constrained(e)) return fail();
                const TriangleId nb = triangle_of(twin(e));
                if (!marked(nb)) {
                    set_mark(nb);
                    region.push_back(nb);
                }
            }
        }
    }
    if (region.size() + 2 * points.size() != nt) return fail();
    for (std::size_t k = 0; k < border.size(); ++k) {
        const HalfEdge o = outside[k] & link_mask;
        if (marked(triangle_of(o)) && !is_border[o]) return fail();
    }
    for (TriangleId t : region) clear_mark(t);

    if (3 * (static_cast<std::uint64_t>(triangle_slots()) + nt) > link_mask)
        throw DataError("triangulation too large: more than " + std::to_string(link_mask / 3) +
                        " triangles (about 178 million points)");
    // Apply, each input released once copied, and each array grown to its exact size: the
    // points; the slots (the region's, then free ones, then new ones); the corners; the links.
    points_.reserve(end);
    points_.insert(points_.end(), points.begin(), points.end());
    for (const Vec3& p : points) bounded_ = bounded_ && bounded(p);
    std::vector<Vec3>().swap(points);
    std::vector<TriangleId> slot(nt);
    std::size_t r = 0;
    for (; r < region.size(); ++r) slot[r] = region[r];
    for (; r < nt && !free_.empty(); ++r) {
        slot[r] = free_.back();
        free_.pop_back();
    }
    const std::size_t grown = triangle_slots() + (nt - r);
    for (auto t = static_cast<TriangleId>(triangle_slots()); r < nt; ++r) slot[r] = t++;
    tri_vertices_.reserve(3 * grown);
    tri_vertices_.resize(3 * grown);
    labels_.reserve(grown);
    labels_.resize(grown);
    for (r = 0; r < nt; ++r) {
        const TriangleId t = slot[r];
        for (int i = 0; i < 3; ++i) tri_vertices_[3 * t + i] = triangles[3 * r + i];
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
                links_[3 * t + i] = half_edge(slot[taker[k2] / 3], static_cast<int>(taker[k2] % 3)) | flag;
            } else {
                links_[3 * t + i] = o | flag;
                links_[o] = half_edge(t, i) | flag;
            }
        }
    }
    std::vector<std::uint32_t>().swap(adjacent);
    last_ = slot[nt - 1];
    if (slots) *slots = std::move(slot);
    return true;
}

HalfEdge SphericalDelaunay::leaving(VertexId a, TriangleId hint) const {
    // A hint that has a as a corner is the answer the walk would give (a lies on two of its
    // edges and left of the third), without the walk's orientation tests through a itself, each
    // zero and so decided only by the exact stage.
    if (hint != no_triangle && hint < triangle_slots() && is_live(hint))
        for (int i = 0; i < 3; ++i)
            if (vertex(hint, next3(i)) == a) return half_edge(hint, i);
    TriangleId t = locate(points_[a], hint != no_triangle ? hint : last_);
    for (int i = 0; i < 3; ++i)
        if (vertex(t, next3(i)) == a) return half_edge(t, i);
    return vertex_half_edges()[a];
}

bool SphericalDelaunay::insert_constraint(VertexId a, VertexId b) {
    // Journaled, so that a failure changes nothing: flips that cannot finish the edge (another
    // constraint crosses it, or the rounded points near it are not in convex position) would
    // otherwise leave edges that are not locally Delaunay.
    std::vector<HalfEdge> created;
    std::vector<FlipRecord> journal;
    std::vector<std::pair<VertexId, VertexId>> constrained;
    if (recover_segment(a, b, created, journal, constrained) && legalize_from(created, &journal, false, nullptr))
        return true;
    undo_flips(journal);
    // An edge constrained here that no undone flip restored lies between two triangles the
    // flips never touched: it was an edge before, unconstrained.
    for (auto [u, v] : constrained) {
        const HalfEdge from = leaving(u);
        const HalfEdge e = from == no_half_edge ? no_half_edge : find_edge(from, v);
        if (e != no_half_edge) set_constrained(e, false);
    }
    return false;
}

// True when the minor arcs a-b and c-d cross at a point interior to both (exact; the sign
// pattern of S2's CrossingSign: the endpoints of each arc straddle the other's great circle,
// and on the same hemisphere, which rules out the antipodal intersection).
static bool arcs_cross(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    int acb = -orient(a, b, c);
    int bda = orient(a, b, d);
    if (acb == 0 || acb != bda) return false;
    int cbd = -orient(c, d, b);
    if (cbd != acb) return false;
    return orient(c, d, a) == acb;
}

// True when vertex d lies on the minor arc a-b strictly between a and b.
static bool on_arc(const Vec3& a, const Vec3& b, const Vec3& d) {
    return orient(a, b, d) == 0 && arc_angle(a, d) < arc_angle(a, b) && arc_angle(d, b) < arc_angle(a, b);
}

bool SphericalDelaunay::recover_segment(VertexId a, VertexId b, std::vector<HalfEdge>& created,
                                        std::vector<FlipRecord>& journal,
                                        std::vector<std::pair<VertexId, VertexId>>& constrained) {
    if (a == b) return true;
    const Vec3& pa = points_[a];
    const Vec3& pb = points_[b];
    for (int round = 0; round < 64; ++round) {
        // From the last edge recovered or flipped: the previous segment of a ring ends at a,
        // and the flips below go along the arc. (Without a hint, every lookup walked from the
        // last insertion, across the mesh: 6 s for the 353,000 nodes of 1:110m land at 1 km.)
        const HalfEdge from = leaving(a, recover_hint_);
        if (from == no_half_edge) return false;
        HalfEdge e = find_edge(from, b);
        if (e != no_half_edge) {
            recover_hint_ = triangle_of(e);
            if (!is_constrained(e)) {
                set_constrained(e, true);
                constrained.emplace_back(a, b);
            }
            return true;
        }
        // Rotate around a to the triangle (a, d, third) the arc a->b leaves through its edge
        // d->third; a vertex exactly on the arc splits the constraint.
        HalfEdge exit = no_half_edge;
        HalfEdge h = from;
        do {
            TriangleId s = triangle_of(h);
            int i = edge_of(h);
            VertexId d = destination(h), third = vertex(s, i);
            if (on_arc(pa, pb, points_[d]))
                return recover_segment(a, d, created, journal, constrained) &&
                       recover_segment(d, b, created, journal, constrained);
            if (orient(pa, points_[d], pb) > 0 && orient(pa, points_[third], pb) < 0) {
                exit = half_edge(s, next3(i)); // d -> third, opposite a
                break;
            }
            h = next_around_origin(h);
        } while (h != from);
        if (exit == no_half_edge) return false;

        // Walk along the arc, collecting the edges it crosses.
        std::vector<HalfEdge> crossing;
        HalfEdge c = exit;
        for (;;) {
            if (is_constrained(c)) return false; // another constraint crosses a-b
            crossing.push_back(c);
            HalfEdge o = twin(c);
            TriangleId r = triangle_of(o);
            int k = edge_of(o);
            VertexId apex = vertex(r, k);
            if (apex == b) break;
            int side = orient(pa, pb, points_[apex]);
            if (side == 0) {
                if (!on_arc(pa, pb, points_[apex])) return false;
                return recover_segment(a, apex, created, journal, constrained) &&
                       recover_segment(apex, b, created, journal, constrained);
            }
            // r = (apex, third, d): d is right of a->b, third left; leave through the edge whose
            // endpoints are on opposite sides.
            c = side > 0 ? half_edge(r, next3(k)) /* d -> apex */ : half_edge(r, prev3(k)) /* apex -> third */;
            if (crossing.size() > 4 * triangle_slots()) return false;
        }
        // Flip crossing edges until none crosses (Sloan 1993); a non-convex quadrilateral is
        // retried later, after its neighbours have moved. Half-edge ids change under flips, so
        // the queue holds vertex pairs and each is looked up again before it is flipped.
        std::vector<std::pair<VertexId, VertexId>> queue;
        queue.reserve(crossing.size());
        for (HalfEdge e : crossing) queue.emplace_back(origin(e), destination(e));
        // In the plane these flips end (Sloan), after O(k^2) of them for k crossings at worst;
        // where rounded points are not in convex position (see insert_constraint) they can
        // cycle, so their number is bounded.
        const std::size_t max_flips = 4 * crossing.size() * crossing.size() + 64;
        std::size_t stall = 0, flips = 0;
        std::size_t head = 0;
        while (head < queue.size()) {
            if (flips > max_flips) return false;
            auto [qu, qw] = queue[head++];
            HalfEdge e2 = find_edge(leaving(qu, recover_hint_), qw);
            if (e2 == no_half_edge) continue; // already flipped away
            TriangleId s = triangle_of(e2);
            recover_hint_ = s;
            int i = edge_of(e2);
            HalfEdge g = twin(e2);
            const Vec3& x = points_[vertex(s, i)];
            const Vec3& u = points_[vertex(s, next3(i))];
            const Vec3& w = points_[vertex(s, prev3(i))];
            const Vec3& y = points_[vertex(triangle_of(g), edge_of(g))];
            if (orient(x, u, y) <= 0 || orient(y, w, x) <= 0) {
                queue.emplace_back(qu, qw);
                if (++stall > 2 * (queue.size() - head) + 8) return false;
                continue;
            }
            stall = 0;
            ++flips;
            flip_recorded(e2, &journal);
            // The quadrilateral's outer edges border changed triangles: recheck them afterwards.
            TriangleId r = triangle_of(g);
            created.push_back(half_edge(s, i));
            created.push_back(half_edge(s, prev3(i)));
            created.push_back(half_edge(r, edge_of(g)));
            created.push_back(half_edge(r, prev3(edge_of(g))));
            HalfEdge diag = half_edge(s, next3(i)); // the new diagonal y -> x
            VertexId d0 = origin(diag), d1 = destination(diag);
            bool touches = d0 == a || d0 == b || d1 == a || d1 == b;
            if (!touches && arcs_cross(pa, pb, points_[d0], points_[d1]))
                queue.emplace_back(d0, d1);
            else
                created.push_back(diag);
        }
    }
    return false;
}

bool SphericalDelaunay::move_vertex(VertexId v, const Vec3& p) {
    HalfEdge from = leaving(v);
    if (from == no_half_edge || origin(from) != v) return false;
    return move_vertex_from(from, p);
}

bool SphericalDelaunay::move_vertex_from(HalfEdge from, const Vec3& p, std::vector<VertexId>* flipped,
                                         const std::function<bool()>& accept) {
    const VertexId v = origin(from);
    // Every triangle of the star must be solid before the move and stay counter-clockwise with v
    // at p. (Moving v out of a ghost triangle changes whether the hull holds the origin, which
    // can leave ghosts far from v that no flip around v reaches.)
    // The edges the move can make non-Delaunay: each spoke v->b once, and each link edge b->c
    // (opposite v). Scratch buffers: smoothing calls this for every node, sweep after sweep.
    std::vector<HalfEdge>& stack = move_stack_;
    stack.clear();
    HalfEdge h = from;
    do {
        TriangleId t = triangle_of(h);
        const Vec3& b = points_[destination(h)];
        const Vec3& c = points_[vertex(t, edge_of(h))];
        if (orient(p, b, c) <= 0 || orient(points_[v], b, c) <= 0) return false;
        stack.push_back(h);
        stack.push_back(half_edge(t, next3(edge_of(h))));
        h = next_around_origin(h);
    } while (h != from);
    const Vec3 was = points_[v];
    const bool was_bounded = bounded_;
    points_[v] = p;
    bounded_ = bounded_ && bounded(p);
    // Lawson flips, journaled: a non-Delaunay edge whose quadrilateral is not convex (or makes
    // a flat triangle, which has no place in a mesh) means v at p lies inside the hull of its
    // neighbours (closer than rounding resolves), which flips cannot mend; then every flip is
    // undone and v goes back.
    std::vector<FlipRecord>& journal = move_journal_;
    journal.clear();
    if (legalize_from(stack, &journal, true, nullptr)) {
        if (flipped)
            for (const FlipRecord& f : journal) {
                flipped->insert(flipped->end(), f.tv, f.tv + 3);
                flipped->insert(flipped->end(), f.sv, f.sv + 3);
            }
        if (!accept || accept()) return true;
    }
    undo_flips(journal);
    points_[v] = was;
    bounded_ = was_bounded;
    last_ = triangle_of(from);
    return false;
}

bool SphericalDelaunay::place_vertex_from(HalfEdge from, const Vec3& p) {
    const VertexId v = origin(from);
    HalfEdge h = from;
    do {
        const TriangleId t = triangle_of(h);
        if (orient(p, points_[destination(h)], points_[vertex(t, edge_of(h))]) <= 0) return false;
        h = next_around_origin(h);
    } while (h != from);
    points_[v] = p;
    bounded_ = bounded_ && bounded(p);
    return true;
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
        for (std::size_t v = 0; v < vertices; ++v) points[new_of_old[v]] = points_[v];
        points_.swap(points);
    }
    // A counting sort of the live triangles by their smallest new corner.
    auto smallest = [&](TriangleId t) {
        return std::min({new_of_old[vertex(t, 0)], new_of_old[vertex(t, 1)], new_of_old[vertex(t, 2)]});
    };
    std::vector<TriangleId> new_of_slot(slots, no_triangle);
    std::size_t live = 0;
    {
        std::vector<TriangleId> next(vertices + 1, 0);
        for (TriangleId t = 0; t < slots; ++t)
            if (is_live(t)) ++next[smallest(t) + 1];
        for (std::size_t v = 0; v < vertices; ++v) next[v + 1] += next[v];
        live = next[vertices];
        for (TriangleId t = 0; t < slots; ++t)
            if (is_live(t)) new_of_slot[t] = next[smallest(t)]++;
    }
    {
        std::vector<std::uint8_t> labels(live);
        for (TriangleId t = 0; t < slots; ++t)
            if (new_of_slot[t] != no_triangle) labels[new_of_slot[t]] = labels_[t];
        labels_.swap(labels);
    }
    {
        std::vector<std::uint32_t> links(3 * live);
        for (TriangleId t = 0; t < slots; ++t) {
            if (new_of_slot[t] == no_triangle) continue;
            for (int i = 0; i < 3; ++i) {
                const std::uint32_t word = links_[half_edge(t, i)];
                const HalfEdge twin = word & link_mask;
                links[half_edge(new_of_slot[t], i)] = half_edge(new_of_slot[triangle_of(twin)], edge_of(twin)) | (word & ~link_mask);
            }
        }
        links_.swap(links);
    }
    {
        std::vector<VertexId> tri_vertices(3 * live);
        for (TriangleId t = 0; t < slots; ++t)
            if (new_of_slot[t] != no_triangle)
                for (int i = 0; i < 3; ++i) tri_vertices[half_edge(new_of_slot[t], i)] = new_of_old[vertex(t, i)];
        tri_vertices_.swap(tri_vertices);
    }
    free_.clear();
    for (auto& [from, into] : dropped_) from = new_of_old[from], into = new_of_old[into];
    auto moved = [&](TriangleId t) { return t < slots ? new_of_slot[t] : no_triangle; };
    last_ = moved(last_);
    recover_hint_ = moved(recover_hint_);
    return new_of_slot;
}

// ---------------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------------

std::vector<std::string> SphericalDelaunay::validate() const {
    std::vector<std::string> problems;
    auto fail = [&](const std::string& s) {
        if (problems.size() < 50) problems.push_back(s);
    };
    std::vector<std::uint8_t> used(points_.size(), 0);
    std::size_t faces = 0, nondelaunay = 0, ghosts = 0, flat = 0;
    double area = 0;
    for (TriangleId t = 0; t < triangle_slots(); ++t) {
        if (!is_live(t)) continue;
        ++faces;
        VertexId a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
        if (a >= points_.size() || b >= points_.size() || c >= points_.size() || a == b || b == c || a == c) {
            fail("triangle " + std::to_string(t) + " has invalid or repeated vertices");
            continue;
        }
        used[a] = used[b] = used[c] = 1;
        area += spherical_triangle_area(points_[a], points_[b], points_[c]);
        int o = orient(points_[a], points_[b], points_[c]);
        if (o < 0) ++ghosts;
        if (o == 0) ++flat;
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            HalfEdge o = twin(h);
            if (o >= links_.size() || !is_live(triangle_of(o))) {
                fail("half-edge " + std::to_string(h) + " links to a dead triangle");
                continue;
            }
            if (twin(o) != h) fail("neighbour links of half-edge " + std::to_string(h) + " are not symmetric");
            if (origin(o) != destination(h) || destination(o) != origin(h))
                fail("half-edge " + std::to_string(h) + " and its twin do not share endpoints");
            if (is_constrained(o) != is_constrained(h))
                fail("constraint flag of half-edge " + std::to_string(h) + " differs on its two sides");
            if (!is_constrained(h) && h < o) {
                const TriangleId s = triangle_of(o);
                if (in_circle(points_[a], points_[b], points_[c], points_[vertex(s, edge_of(o))]) > 0)
                    ++nondelaunay;
            }
        }
    }
    std::size_t v_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), 1));
    if (faces % 2 != 0) fail("odd number of triangles in a closed triangulation");
    long long euler = static_cast<long long>(v_used) - static_cast<long long>(3 * faces / 2) +
                      static_cast<long long>(faces);
    if (faces > 0 && euler != 2) fail("Euler characteristic V - E + F = " + std::to_string(euler) + ", not 2");
    if (nondelaunay) fail(std::to_string(nondelaunay) + " unconstrained edges are not locally Delaunay");
    // Orientation, globally: the signed areas of a closed surface wound once around the origin
    // add up to 4 pi; a surface that does not enclose the origin (all points in a hemisphere)
    // adds up to 0. Anything else is a fold.
    // A surface around the origin that still has a triangle with det <= 0 is folded there.
    if (faces > 0 && std::fabs(area - 4 * pi) <= 1e-6 && ghosts > 0)
        fail(std::to_string(ghosts) + " triangles are clockwise on the sphere in a triangulation "
                                      "around the origin: folded triangles");
    // (Flat triangles, on a great circle through the origin, close a hull whose points all lie
    // in a closed hemisphere; their spherical area is undefined, so the sum says nothing then.)
    if (faces > 0 && flat == 0 && std::fabs(area - 4 * pi) > 1e-6 && std::fabs(area) > 1e-6) {
        std::ostringstream s;
        s << "signed spherical areas add up to " << area << " sr, not 4 pi or 0: folded triangles";
        fail(s.str());
    }
    return problems;
}

} // namespace globemesh
