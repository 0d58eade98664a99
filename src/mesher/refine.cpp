// Refinement: frontal Delaunay refinement (Rebay's points off the front, Ruppert's segment
// splits) until every ocean triangle fits the size field and the shape bounds.
#include "mesher_state.hpp"

#include <new>

#include "../delaunay/hilbert.hpp"

namespace globemesh::mesher_internal {

namespace {

// Refinement stops when every circumradius is below this factor times that of an equilateral
// triangle of side h: above 1, so that the edge lengths centre on h after smoothing.
constexpr double circumradius_factor = 1.35;
// Frontal points make triangles of circumradius this factor times the refinement bound: it
// puts the median edge within about 1% of h.
constexpr double frontal_radius_factor = 0.75;
// Largest circumradius of a frontal triangle relative to its front edge's length.
constexpr double front_growth = 1.0;
// Refinement splits triangles whose circumradius exceeds this factor times their shortest edge
// (sqrt(2): smallest angle 20.7 degrees, the bound for which Ruppert's algorithm terminates).
constexpr double shape_bound = 1.4142135623730951;
// Triangles with a boundary corner are split above this ratio instead (smallest angle 25.8
// degrees): smoothing moves at most two of their corners, and the coast's crowded places leave
// it little room. (Below sqrt(2) the refinement still ends: shape stops counting below
// refine_floor.)
constexpr double coast_shape_bound = 1.15;
// The refinement pops the worst triangles first, their badness coarsened to this many levels per
// doubling; within a level, along the Hilbert curve. Consecutive insertions are then neighbours
// on the sphere and so are the new vertices' numbers, which keeps the refinement and the
// smoothing in cache.
constexpr double badness_levels_per_doubling = 8;

// How much triangle t wants refining: > 1 means too large for the size field or too
// skinny (radius-edge ratio above sqrt(2), i.e. a smallest angle below about 20.7 degrees).
// Lengths are chords, not arcs: below 0.1 rad (637 km) they differ by under 0.05%, and a
// chord needs no atan2 (this runs for every triangle the refinement creates).
double badness(const Mesher &m, TriangleId t) {
    const SphericalDelaunay &dt = m.dt;
    const Vec3 &a = dt.point(dt.vertex(t, 0));
    const Vec3 &b = dt.point(dt.vertex(t, 1));
    const Vec3 &d = dt.point(dt.vertex(t, 2));
    const double r = norm(m.circumcentre(t) - a);
    double h = km_to_rad(m.size_km(m.centroid(t)));
    double size_ratio = r / (circumradius_factor * h / std::sqrt(3.0));
    // A triangle at a sharp coast corner keeps the corner's small angle whatever is inserted:
    // only its size counts (Ruppert's algorithm needs input angles of 60 degrees or more).
    if (m.is_sharp(dt.vertex(t, 0)) || m.is_sharp(dt.vertex(t, 1)) || m.is_sharp(dt.vertex(t, 2)))
        return size_ratio;
    const Vec3 ab = b - a, bd = d - b, da = a - d;
    const double shortest = std::sqrt(std::min({dot(ab, ab), dot(bd, bd), dot(da, da)}));
    // Below a floor, shape does not count: pinch points of the coast (rings moved 0.64 m
    // apart where they touched) would otherwise be refined down to their own scale.
    // A triangle with a boundary corner is held to a tighter shape; one with two or three,
    // which smoothing cannot mend, is refined until its quality reaches quality_goal.
    const int corners =
        m.is_fixed(dt.vertex(t, 0)) + m.is_fixed(dt.vertex(t, 1)) + m.is_fixed(dt.vertex(t, 2));
    double shape_ratio = r / shortest / (corners > 0 ? coast_shape_bound : shape_bound);
    if (corners >= 2)
        shape_ratio =
            std::max(shape_ratio, quality_goal / std::max(1e-3, triangle_quality(a, b, d)));
    if (size_ratio < refine_floor)
        shape_ratio = 0;
    return std::max(size_ratio, shape_ratio);
}

// A refinement candidate: 16 bytes. `order` is the badness level (badness_levels_per_doubling)
// above the Hilbert key of the triangle's centroid. `stamp` is the generation of slot t when it
// was queued (twice, plus 1 when the triangle was on the front); a slot's generation (24 bits)
// grows each time the core puts a new triangle in it, so an entry whose stamp no longer matches
// is stale.
struct Candidate {
    std::uint64_t order;
    TriangleId t;
    std::uint32_t stamp;
    bool active() const {
        return (stamp & 1u) != 0;
    } // next to an accepted triangle or the boundary
    bool operator<(const Candidate &o) const {
        if (active() != o.active())
            return !active();
        if (order != o.order)
            return order < o.order;
        return t > o.t; // deterministic ties
    }
};

// Cache-line aligned storage for the heap below.
template <class T> struct LineAllocator {
    using value_type = T;
    LineAllocator() = default;
    template <class U> LineAllocator(const LineAllocator<U> &) {}
    T *allocate(std::size_t n) {
        return static_cast<T *>(::operator new (n * sizeof(T), std::align_val_t{64}));
    }
    void deallocate(T *p, std::size_t) { ::operator delete (p, std::align_val_t{64}); }
    template <class U> bool operator==(const LineAllocator<U> &) const { return true; }
};

// A max-heap of candidates with four children per node: half the depth of a binary heap, and
// the four children of a node (16 bytes each) fill one 64-byte cache line, so a sift-down
// touches one line per level. Node i lives at index i + 3, which puts the children 4i+1..4i+4
// at indices 4(i+1)..4(i+1)+3 of a 64-byte aligned array. Pops come in the order of
// Candidate::operator< (entries that compare equal are interchangeable: the same triangle,
// badness and front flag, so either identical or stale).
class CandidateHeap {
public:
    bool empty() const { return size() == 0; }
    std::size_t size() const { return a_.size() - pad; }
    void push(const Candidate &c) {
        a_.push_back(c);
        std::size_t i = size() - 1;
        while (i > 0) {
            const std::size_t parent = (i - 1) / 4;
            if (!(at(parent) < c))
                break;
            at(i) = at(parent);
            i = parent;
        }
        at(i) = c;
    }
    Candidate pop() {
        const Candidate top = at(0);
        const Candidate last = a_.back();
        a_.pop_back();
        if (!empty())
            sift_down(0, last);
        return top;
    }
    /// Drops the entries for which `drop` holds and restores the heap.
    template <class F> void remove_if(F drop) {
        std::erase_if(a_, [&](const Candidate &c) { return &c >= a_.data() + pad && drop(c); });
        for (std::size_t i = size() / 4 + 1; i-- > 0;)
            if (i < size())
                sift_down(i, at(i));
    }
    void release() { std::vector<Candidate, LineAllocator<Candidate>>().swap(a_); }

private:
    static constexpr std::size_t pad = 3;
    Candidate &at(std::size_t i) { return a_[i + pad]; }
    void sift_down(std::size_t i, const Candidate c) { // c by value: it may be at(i)
        const std::size_t n = size();
        for (;;) {
            const std::size_t first = 4 * i + 1;
            if (first >= n)
                break;
            std::size_t best = first;
            const std::size_t end = std::min(first + 4, n);
            for (std::size_t k = first + 1; k < end; ++k)
                if (at(best) < at(k))
                    best = k;
            if (!(c < at(best)))
                break;
            at(i) = at(best);
            i = best;
        }
        at(i) = c;
    }
    std::vector<Candidate, LineAllocator<Candidate>> a_ =
        std::vector<Candidate, LineAllocator<Candidate>>(pad);
};

// The refinement's queue and per-slot state (the lambdas of one loop, as members).
class Refinement {
public:
    explicit Refinement(Mesher &m) : m(m), dt(m.dt) {}
    void run(const Progress &progress);

private:
    Mesher &m;
    SphericalDelaunay &dt;
    // Badness per triangle slot, computed once when the core creates the triangle: a triangle
    // never changes while it lives (its corners, their fixed/sharp flags and the size field are
    // all fixed), and every triangle an insertion creates has the new vertex as a corner.
    std::vector<double> bad = std::vector<double>(dt.triangle_slots(), 0.0);
    // Per slot: the generation of its triangle (bits 8-31, grows each time the core puts a new
    // triangle in the slot) and how many copies of its candidate, off the front (bits 0-3) and
    // on it (bits 4-7), are queued. Copies of one candidate are identical, so the heap holds one
    // entry for them and puts it back after each pop while copies remain: the same pops as one
    // entry per copy, with a smaller heap and fewer stale pops.
    std::vector<std::uint32_t> slot_state = std::vector<std::uint32_t>(dt.triangle_slots(), 0);
    CandidateHeap queue;
    std::vector<TriangleId> star_triangles; // consider_star's scratch

    void refresh(TriangleId t) {
        if (t >= bad.size()) {
            bad.resize(dt.triangle_slots(), 0.0);
            slot_state.resize(dt.triangle_slots(), 0);
        }
        slot_state[t] = ((slot_state[t] >> 8) + 1) << 8;
        bad[t] = dt.label(t) == ocean ? badness(m, t) : 0.0;
    }
    std::uint64_t order_of(double b, TriangleId t) const {
        const auto level =
            static_cast<std::uint64_t>(std::log2(b) * badness_levels_per_doubling); // b > 1
        return level << 32 | detail::hilbert_key(m.centroid(t));
    }
    void push(double b, TriangleId t, bool active) {
        const int shift = active ? 4 : 0;
        const std::uint32_t copies = (slot_state[t] >> shift) & 15u;
        if (copies == 0)
            queue.push({order_of(b, t), t, (slot_state[t] >> 8) << 1 | (active ? 1u : 0u)});
        if (copies < 15)
            slot_state[t] += 1u << shift; // (more than 15 copies: counted as 15)
    }
    bool stale(const Candidate &c) const {
        return !dt.is_live(c.t) || slot_state[c.t] >> 8 != c.stamp >> 1 || dt.label(c.t) != ocean;
    }
    int front_edge(TriangleId t) const;
    void consider(TriangleId t);
    void consider_star(VertexId v);
    Vec3 insertion_point(TriangleId t) const;
    bool insert_for(TriangleId t);
};

// Frontal order (Rebay 1993): a bad triangle whose edge borders an accepted triangle or the
// boundary is on the front and goes first; its new node is placed off that edge. Returns the
// shortest such edge, or -1.
int Refinement::front_edge(TriangleId t) const {
    int best = -1;
    double best_len = 0;
    for (int i = 0; i < 3; ++i) {
        HalfEdge h = half_edge(t, i);
        TriangleId nb = triangle_of(dt.twin(h));
        bool accepted = dt.is_constrained(h) || dt.label(nb) != ocean || bad[nb] <= 1.0;
        if (!accepted)
            continue;
        const Vec3 d = dt.point(dt.destination(h)) - dt.point(dt.origin(h));
        const double len = dot(d, d); // the shortest chord is the shortest arc
        if (best < 0 || len < best_len) {
            best = i;
            best_len = len;
        }
    }
    return best;
}

void Refinement::consider(TriangleId t) {
    if (!dt.is_live(t) || dt.label(t) != ocean)
        return;
    double b = bad[t];
    if (b > 1.0) {
        push(b, t, front_edge(t) >= 0);
    } else {
        // An accepted triangle puts its bad neighbours on the front.
        for (int i = 0; i < 3; ++i) {
            TriangleId nb = triangle_of(dt.twin(half_edge(t, i)));
            if (dt.label(nb) == ocean && !dt.is_constrained(half_edge(t, i))) {
                double bn = bad[nb];
                if (bn > 1.0)
                    push(bn, nb, true);
            }
        }
    }
}

void Refinement::consider_star(VertexId v) {
    // Every triangle created by the last insertion has v as a corner: rotate around v, give
    // each its badness first (front_edge reads the neighbours'), then consider each.
    TriangleId last = dt.last_triangle();
    int k = 0;
    while (k < 3 && dt.vertex(last, k) != v)
        ++k;
    if (k == 3)
        return;
    HalfEdge from = half_edge(last, prev3(k)); // leaves v
    HalfEdge h = from;
    star_triangles.clear();
    do {
        star_triangles.push_back(triangle_of(h));
        refresh(triangle_of(h));
        h = dt.next_around_origin(h);
    } while (h != from);
    for (TriangleId t : star_triangles)
        consider(t);
}

// The point inserted for bad triangle t: its circumcentre or, on the front, the apex off the
// front edge.
Vec3 Refinement::insertion_point(TriangleId t) const {
    Vec3 centre = m.circumcentre(t);
    if (int e = front_edge(t); e >= 0) {
        // Off the front edge u->w (t on its left): the apex of an isosceles triangle whose
        // circumradius is the target's, kept inside t's circumcircle (Rebay's point).
        const Vec3 &u = dt.point(dt.vertex(t, next3(e)));
        const Vec3 &w = dt.point(dt.vertex(t, prev3(e)));
        Vec3 mid = arc_midpoint(u, w);
        Vec3 left = normalized(cross(u, w));
        double half = 0.5 * arc_angle(u, w);
        // Grow from short front edges (e.g. short coast segments) at most by the edge's own
        // length, so the mesh grades away from them instead of leaving slivers.
        double target = circumradius_factor * km_to_rad(m.size_km(mid)) / std::sqrt(3.0) *
                        frontal_radius_factor;
        double rho = std::max(half, std::min(target, 2.0 * half * front_growth));
        double height = rho + std::sqrt(std::max(0.0, rho * rho - half * half));
        double to_centre =
            std::atan2(dot(centre, left), dot(centre, mid)); // signed, along the bisector
        if (to_centre > 0) {
            double d = std::min(height, to_centre);
            centre = normalized(std::cos(d) * mid + std::sin(d) * left);
        }
    }
    return centre;
}

// Inserts the point for bad triangle t, or splits the segment it encroaches on; false when
// nothing was inserted.
bool Refinement::insert_for(TriangleId t) {
    const Vec3 centre = insertion_point(t);
    // Walk from t to the circumcentre; stop at the first constrained edge in the way, or at
    // one whose diametral circle it lands in (Ruppert's rule): split that segment instead.
    HalfEdge blocked = no_half_edge;
    const TriangleId cur = m.walk_towards(t, centre, blocked);
    VertexId v;
    if (blocked != no_half_edge) {
        // The circumcentre lies beyond a boundary segment: split the segment, if it is
        // not already short against the size field.
        v = m.split_segment(blocked);
        if (v == no_vertex)
            return false;
        ++m.report.encroached_splits;
        consider_star(v);
        // The triangle itself may survive the split: look at it again.
        consider(t);
    } else {
        if (dt.label(cur) != ocean)
            return false;
        std::size_t before = dt.vertex_count();
        v = dt.insert_in_triangle(centre, cur);
        if (dt.vertex_count() == before)
            return false; // merged with a close vertex
        consider_star(v);
    }
    return true;
}

void Refinement::run(const Progress &progress) {
    const MesherReport &report = m.report;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean)
            bad[t] = badness(m, t);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        consider(t);
    const std::size_t node_limit = 4 * report.estimated_nodes + 1000;
    std::size_t inserted = 0;
    // Stale entries are dropped whenever the heap doubles since the last sweep (this keeps the
    // pop order: only entries that would be skipped go).
    std::size_t compact_at = std::max<std::size_t>(2 * queue.size(), 1 << 16);
    while (!queue.empty()) {
        if (queue.size() >= compact_at) {
            queue.remove_if([&](const Candidate &c) { return stale(c); });
            compact_at = std::max<std::size_t>(2 * queue.size(), 1 << 16);
        }
        const Candidate c = queue.pop();
        const TriangleId t = c.t;
        if (stale(c))
            continue;
        const int shift = c.active() ? 4 : 0;
        slot_state[t] -= 1u << shift;
        if ((slot_state[t] >> shift & 15u) != 0)
            queue.push(c); // the next copy
        if (dt.vertex_count() > node_limit)
            throw DataError("refinement does not converge (over " + std::to_string(node_limit) +
                            " nodes): the size field may be too small for the boundary");
        if (!insert_for(t))
            continue;
        if ((++inserted & 0x3fff) == 0)
            globemesh::report(progress,
                              0.15 + 0.6 * std::min(1.0, double(dt.vertex_count()) /
                                                             double(report.estimated_nodes + 1)),
                              "refine");
    }
}

} // namespace

void refine(Mesher &m, const Progress &progress) {
    Refinement(m).run(progress);
}

} // namespace globemesh::mesher_internal
