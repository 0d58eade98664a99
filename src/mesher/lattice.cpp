// The icosahedral lattice: the open ocean filled with near-equilateral triangles.
#include "lattice_points.hpp"
#include "mesher_state.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace globemesh::mesher_internal {

namespace {

// The lattice points walked, per face of the icosahedron and row: row i of face f walks j in
// [lo, hi] (weights i, j, rows - i - j on the face's corners), its cells at cell[start + j -
// lo], each the index of its point or `none` (not kept).
struct LatticeCells {
    static constexpr std::uint32_t none = 0xffffffffu;
    struct Row {
        int lo = 1, hi = 0;
        std::size_t start = 0;
    };
    int rows = 0;
    std::vector<Row> row_of; // 20 * (rows + 1)
    std::vector<std::uint32_t> cell;

    const Row &row(int f, int i) const {
        return row_of[static_cast<std::size_t>(f) * (rows + 1) + i];
    }
    /// The cell of (i, j) in face f, or SIZE_MAX outside the face or the rows walked.
    std::size_t index(int f, int i, int j) const {
        if (i < 0 || i > rows || j < 0 || j > rows - i)
            return SIZE_MAX;
        const Row &r = row(f, i);
        return j < r.lo || j > r.hi ? SIZE_MAX : r.start + static_cast<std::size_t>(j - r.lo);
    }
    /// The entry of (i, j) of face f in `of` (an array over the cells), or none outside.
    std::uint32_t at(const std::vector<std::uint32_t> &of, int f, int i, int j) const {
        const std::size_t c = index(f, i, j);
        return c == SIZE_MAX ? none : of[c];
    }
    /// The point at (i, j) of face f, or none.
    std::uint32_t kept(int f, int i, int j) const { return at(cell, f, i, j); }
};

// Adds the lattice's points (those `grid` names) to the triangulation. A node inside its face
// whose six neighbours are kept too is "inner": its whole star is the lattice's six
// triangles. The others (on the lattice's rim, or on the icosahedron's edges) are inserted as
// any points; their triangulation with the boundary's then holds every edge of a lattice
// triangle whose corners are all kept (its circumcircle holds no other lattice node, and no
// boundary node or segment, which are lattice_clearance away), so the region of each face's
// whole lattice triangles is bounded by such edges, and the lattice's triangles replace
// whatever triangles the rim nodes made there (replace_region). Lawson flips then mend any
// lattice edge the rounding or the icosahedron's distortion left non-Delaunay: the result is
// the triangulation point insertion would give, without locating each point and testing its
// cavity. Returns the number of nodes added.
std::size_t place_lattice(Mesher &m, LatticeCells &grid, std::vector<Vec3> &points) {
    SphericalDelaunay &dt = m.dt;
    constexpr std::uint32_t none = LatticeCells::none;
    const int rows = grid.rows;
    const std::vector<std::uint32_t> &cell = grid.cell;
    auto kept = [&](int f, int i, int j) { return grid.kept(f, i, j); };
    const std::size_t before = dt.vertex_count();
    std::vector<char> inner(points.size(), 0);
    for (int f = 0; f < 20; ++f)
        for (int i = 1; i < rows; ++i) {
            const LatticeCells::Row &row = grid.row(f, i);
            for (int j = std::max(row.lo, 1); j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::uint32_t id = cell[row.start + static_cast<std::size_t>(j - row.lo)];
                if (id == none)
                    continue;
                inner[id] = kept(f, i + 1, j) != none && kept(f, i - 1, j) != none &&
                            kept(f, i, j + 1) != none && kept(f, i, j - 1) != none &&
                            kept(f, i + 1, j - 1) != none && kept(f, i - 1, j + 1) != none;
            }
        }
    std::vector<Vec3> rim, inside;
    // Each to its size first: growing by doubling would copy and touch about twice the points.
    const auto inner_count = static_cast<std::size_t>(std::count(inner.begin(), inner.end(), 1));
    inside.reserve(inner_count);
    rim.reserve(points.size() - inner_count);
    std::vector<VertexId> vertex_of(points.size(),
                                    no_vertex); // point -> vertex (inner: filled below)
    for (std::size_t q = 0; q < points.size(); ++q)
        (inner[q] ? inside : rim).push_back(points[q]);
    if (!rim.empty()) {
        const std::vector<VertexId> ids = dt.insert_points(rim);
        for (std::size_t q = 0, r = 0; q < points.size(); ++q)
            if (!inner[q])
                vertex_of[q] = ids[r++];
    }
    points.clear();
    points.shrink_to_fit();
    for (std::size_t q = 0, r = 0; q < vertex_of.size(); ++q)
        if (inner[q])
            vertex_of[q] = static_cast<VertexId>(dt.vertex_count() + r++);
    inner.clear();
    inner.shrink_to_fit();
    // The lattice triangles whose corners are all kept: up (i, j), (i + 1, j), (i, j + 1) at
    // the cell of (i, j), and down (i + 1, j - 1), (i + 1, j), (i, j) at the cell of (i, j),
    // numbered first so that each can name its neighbours; counter-clockwise as the faces are
    // (replace_region checks).
    std::vector<std::uint32_t> up(cell.size(), none), down(cell.size(), none);
    std::uint32_t count = 0;
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i < rows; ++i) {
            const LatticeCells::Row &row = grid.row(f, i);
            for (int j = row.lo; j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::size_t c = row.start + static_cast<std::size_t>(j - row.lo);
                if (cell[c] == none || kept(f, i + 1, j) == none)
                    continue;
                if (kept(f, i, j + 1) != none)
                    up[c] = count++;
                if (kept(f, i + 1, j - 1) != none)
                    down[c] = count++;
            }
        }
    std::vector<VertexId> triangles(3 * static_cast<std::size_t>(count));
    std::vector<std::uint32_t> adjacent(3 * static_cast<std::size_t>(count));
    std::vector<HalfEdge> border;
    const std::vector<HalfEdge> star = dt.vertex_half_edges();
    bool fits = true;
    // Links half-edge e of new triangle r (corners v) to edge e2 of new triangle t on its other
    // side or, when t is none, to the edge of the rim nodes' triangulation that it replaces
    // (a border edge; `fits` turns false when that edge is missing).
    auto set_edge = [&](std::uint32_t r, int e, const VertexId *v, std::uint32_t t, int e2) {
        if (t != none) {
            adjacent[3 * r + e] = 3 * t + e2;
            return;
        }
        const VertexId from = v[next3(e)], to = v[prev3(e)];
        const HalfEdge h = from < star.size() ? dt.find_edge(star[from], to) : no_half_edge;
        fits = fits && h != no_half_edge;
        adjacent[3 * r + e] =
            SphericalDelaunay::patch_border | static_cast<std::uint32_t>(border.size());
        border.push_back(h);
    };
    for (int f = 0; f < 20 && fits; ++f)
        for (int i = 0; i < rows && fits; ++i) {
            const LatticeCells::Row &row = grid.row(f, i);
            for (int j = row.lo; j <= std::min(row.hi, rows - i - 1); ++j) {
                const std::size_t c = row.start + static_cast<std::size_t>(j - row.lo);
                if (const std::uint32_t r = up[c]; r != none) {
                    VertexId *v = &triangles[3 * r];
                    v[0] = vertex_of[cell[c]], v[1] = vertex_of[kept(f, i + 1, j)],
                    v[2] = vertex_of[kept(f, i, j + 1)];
                    // Edge 0, (i + 1, j) -> (i, j + 1), is the down triangle's at (i, j + 1)
                    // edge 1; edge 1, (i, j + 1) -> (i, j), that at (i - 1, j + 1) edge 2;
                    // edge 2, (i, j) -> (i + 1, j), that at (i, j) edge 0.
                    set_edge(r, 0, v, grid.at(down, f, i, j + 1), 1);
                    set_edge(r, 1, v, grid.at(down, f, i - 1, j + 1), 2);
                    set_edge(r, 2, v, down[c], 0);
                }
                if (const std::uint32_t r = down[c]; r != none) {
                    VertexId *w = &triangles[3 * r];
                    w[0] = vertex_of[kept(f, i + 1, j - 1)], w[1] = vertex_of[kept(f, i + 1, j)],
                    w[2] = vertex_of[cell[c]];
                    // Edge 0, (i + 1, j) -> (i, j), is the up triangle's at (i, j) edge 2; edge
                    // 1, (i, j) -> (i + 1, j - 1), that at (i, j - 1) edge 0; edge 2,
                    // (i + 1, j - 1) -> (i + 1, j), that at (i + 1, j - 1) edge 1.
                    set_edge(r, 0, w, up[c], 2);
                    set_edge(r, 1, w, grid.at(up, f, i, j - 1), 0);
                    set_edge(r, 2, w, grid.at(up, f, i + 1, j - 1), 1);
                }
            }
        }
    up.clear(), up.shrink_to_fit(), down.clear(), down.shrink_to_fit();
    grid.cell.clear(), grid.cell.shrink_to_fit();
    std::vector<TriangleId> slots;
    vertex_of.clear();
    vertex_of.shrink_to_fit();
    const std::size_t n_inside = inside.size();
    if (!fits || !dt.replace_region(border, inside, triangles, adjacent, ocean, &slots)) {
        // Only if rounding kept an edge of the lattice's rim out of the rim nodes' triangulation
        // (not seen; replace_region's checks are the guard): insert the inner nodes as points.
        dt.insert_points(inside);
        return dt.vertex_count() - before;
    }
    // Every new edge once (an edge between two new triangles from its smaller half-edge).
    std::vector<char> is_new(dt.triangle_slots(), 0);
    for (TriangleId t : slots)
        is_new[t] = 1;
    std::vector<HalfEdge> to_check;
    to_check.reserve(3 * slots.size() / 2 + border.size());
    for (TriangleId t : slots)
        for (int e = 0; e < 3; ++e) {
            const HalfEdge h = half_edge(t, e), o = dt.twin(h);
            if (h < o || !is_new[triangle_of(o)])
                to_check.push_back(h);
        }
    dt.make_delaunay(to_check);
    m.report.lattice_patched = n_inside;
    return dt.vertex_count() - before;
}

// The cap holding the ocean: around the mean of the ocean triangles' corners, out to the
// farthest corner. A cap narrower than a hemisphere holds each triangle whose corners it holds;
// a wider one is taken as the whole sphere (cos_r -1).
struct Cap {
    Vec3 centre{0, 0, 0};
    double cos_r = -1;
    bool contains(const Vec3 &p) const {
        return dot(p, centre) >= cos_r * norm(p);
    } // p need not be unit
};

// The ocean's cap, with a margin of twice the spacing s for the jitter.
Cap ocean_cap(const SphericalDelaunay &dt, double s) {
    Cap cap;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean)
            for (int i = 0; i < 3; ++i)
                cap.centre = cap.centre + dt.point(dt.vertex(t, i));
    if (norm(cap.centre) > 0) {
        cap.centre = normalized(cap.centre);
        cap.cos_r = 1;
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
            if (dt.is_live(t) && dt.label(t) == ocean)
                for (int i = 0; i < 3; ++i)
                    cap.cos_r = std::min(cap.cos_r, dot(dt.point(dt.vertex(t, i)), cap.centre));
        const double r = std::acos(cap.cos_r) + 2 * s; // a margin for the jitter
        cap.cos_r = r < 1.5 ? std::cos(r) : -1;
    }
    return cap;
}

// Row i of the face a, b, c is an arc of a great circle (weights j on b, len - j on c): its
// points in the cap are an interval [lo, hi] of j around the point nearest the cap's centre,
// found by a ternary search (the cosine to the centre is unimodal along an arc under pi), and
// its ends by bisection. False when no point of the row is in the cap.
bool row_in_cap(const Cap &cap, const Vec3 &a, const Vec3 &b, const Vec3 &c, int i, int len,
                int &lo, int &hi) {
    auto at = [&](int j) { return double(i) * a + double(j) * b + double(len - j) * c; };
    auto closeness = [&](int j) {
        const Vec3 q = at(j);
        return dot(q, cap.centre) / norm(q);
    };
    int x0 = 0, x1 = len;
    while (x1 - x0 > 2) {
        const int m1 = x0 + (x1 - x0) / 3, m2 = x1 - (x1 - x0) / 3;
        if (closeness(m1) < closeness(m2))
            x0 = m1 + 1;
        else
            x1 = m2;
    }
    int best = x0;
    for (int j = x0 + 1; j <= x1; ++j)
        if (closeness(j) > closeness(best))
            best = j;
    if (!cap.contains(at(best)))
        return false;
    int l = 0, r = best; // the first j in the cap
    while (l < r) {
        const int mid = l + (r - l) / 2;
        if (cap.contains(at(mid)))
            r = mid;
        else
            l = mid + 1;
    }
    lo = l;
    l = best, r = len; // the last
    while (l < r) {
        const int mid = l + (r - l + 1) / 2;
        if (cap.contains(at(mid)))
            l = mid;
        else
            r = mid - 1;
    }
    hi = l;
    return true;
}

// Narrows row i's [lo, hi] (weights j on b, len - j on c) to the points where dot(p, n) > 0 for
// each normal n, with one point of margin each side (the jitter, the rounding): dot is linear in
// j before the point is normalized. False when no point is left.
bool row_within(const std::vector<Vec3> &normals, const Vec3 &a, const Vec3 &b, const Vec3 &c,
                int i, int len, int &lo, int &hi) {
    for (const Vec3 &n : normals) {
        const double at0 = double(i) * dot(a, n) + double(len) * dot(c, n);
        const double slope = dot(b, n) - dot(c, n);
        // at0 + j * slope > 0: j above or below -at0 / slope.
        if (std::fabs(slope) < 1e-300) {
            if (at0 <= 0)
                return false;
            continue;
        }
        const double j0 = -at0 / slope;
        if (slope > 0)
            lo = std::max(
                lo, static_cast<int>(std::max(-1.0, std::min(double(len), std::floor(j0)))) - 1);
        else
            hi = std::min(
                hi, static_cast<int>(std::max(-1.0, std::min(double(len) + 1, std::ceil(j0)))) + 1);
    }
    lo = std::max(lo, 0);
    hi = std::min(hi, len);
    return lo <= hi;
}

// The nodes on the icosahedron's 30 edges (by their smaller corner and the steps from it) and at
// its 12 corners, shared by the faces that have them.
class SharedNodes {
public:
    explicit SharedNodes(int rows)
        : rows(rows), edge_node(30 * static_cast<std::size_t>(rows + 1), LatticeCells::none) {
        for (auto &e : edge_id)
            e.fill(-1);
        int edges = 0;
        for (const auto &v : ico_face)
            for (int q = 0; q < 3; ++q) {
                const int u = std::min(v[q], v[(q + 1) % 3]), w = std::max(v[q], v[(q + 1) % 3]);
                if (edge_id[u][w] < 0)
                    edge_id[u][w] = edges++;
            }
        corner_node.fill(LatticeCells::none);
    }
    // The shared entry of node (i, j, k) of face f (weights on its corners a, b, c), or null
    // inside the face.
    std::uint32_t *at(int f, int i, int j, int k) {
        const int zeros = (i == 0) + (j == 0) + (k == 0);
        if (zeros == 0)
            return nullptr;
        const int *v = ico_face[f];
        if (zeros == 2)
            return &corner_node[i > 0 ? v[0] : j > 0 ? v[1] : v[2]];
        int u = v[0], w = v[1], wu = i, ww = j; // k == 0: the edge a-b
        if (i == 0)
            u = v[1], w = v[2], wu = j, ww = k;
        else if (j == 0)
            u = v[0], w = v[2], wu = i, ww = k;
        if (u > w)
            std::swap(u, w), std::swap(wu, ww);
        return &edge_node[static_cast<std::size_t>(edge_id[u][w]) * (rows + 1) + ww];
    }
    void release() { edge_node.clear(), edge_node.shrink_to_fit(); }

private:
    int rows;
    std::array<std::array<int, 12>, 12> edge_id{};
    std::vector<std::uint32_t> edge_node;
    std::array<std::uint32_t, 12> corner_node;
};

// Whether point p, in the ocean triangle t, has no boundary segment and no node within the
// clearance: the triangles whose edges come that close, from t.
class Clearance {
public:
    Clearance(const SphericalDelaunay &dt, double clearance)
        : dt(dt), clearance(clearance), sin2(std::pow(std::sin(clearance), 2)),
          chord2(std::pow(2.0 * std::sin(0.5 * clearance), 2)) {}
    bool clear(const Vec3 &p, TriangleId t) {
        seen.assign(1, t);
        for (std::size_t k = 0; k < seen.size(); ++k) {
            for (int i = 0; i < 3; ++i) {
                const HalfEdge e = half_edge(seen[k], i);
                const Vec3 &u = dt.point(dt.origin(e));
                const Vec3 &w = dt.point(dt.destination(e));
                if (dot(u - p, u - p) < chord2)
                    return false;
                const Vec3 c = cross(u, w);
                const double d = dot(p, c);
                if (d * d >= sin2 * dot(c, c) || beyond_ends(u, w, p, c))
                    continue; // far from the arc's circle, or its ends
                if (dt.is_constrained(e))
                    return false;
                const TriangleId nb = triangle_of(dt.twin(e));
                if (std::find(seen.begin(), seen.end(), nb) != seen.end())
                    continue;
                if (seen.size() == 64)
                    return false; // a fan of long edges: leave it to the refinement
                seen.push_back(nb);
            }
        }
        return true;
    }

private:
    // Whether arc u-w (c = u x w) lies the clearance or farther from p, p being nearer than
    // that to its great circle: p's foot on the circle lies beyond the arc's ends and both ends
    // are that far (arc_distance's cases, compared as chords: no asin or atan2 per edge, each
    // lattice point of a part's lune is near a dozen of its border's long edges).
    bool beyond_ends(const Vec3 &u, const Vec3 &w, const Vec3 &p, const Vec3 &c) const {
        if (dot(c, c) > 1e-30 && dot(cross(u, p), c) >= 0 && dot(cross(p, w), c) >= 0)
            return false;
        return dot(u - p, u - p) >= chord2 && dot(w - p, w - p) >= chord2;
    }

    const SphericalDelaunay &dt;
    const double clearance, sin2, chord2;
    std::vector<TriangleId> seen;
};

/// The grid's cells whose lattice point may lie within `clearance` (radians) of a node or a
/// constrained edge of the triangulation: only those need Clearance's walk, the others are clear.
/// (In a part's lune with a small island, the island's fan of long edges made that walk see five
/// triangles a point.) Each edge marks the cells within clearance of its midpoint plus half its
/// chord, in pieces no longer than `piece` (radians); a node on no constrained edge, its own.
std::vector<char> near_boundary(const SphericalDelaunay &dt, const LatticePoints &lattice,
                                const LatticeCells &grid, double clearance, double piece) {
    std::vector<char> near(grid.cell.size(), 0);
    const double chord = 2 * std::sin(0.5 * clearance);
    auto mark = [&](const Vec3 &p, double reach_chord) {
        const int reach = lattice.reach_for(reach_chord);
        if (reach < 0) { // a lattice of a few rows: every cell
            std::fill(near.begin(), near.end(), 1);
            return;
        }
        lattice.for_each_near(p, reach, [&](const auto &x) {
            const std::size_t c = grid.index(x.f, x.i, x.j);
            if (c != SIZE_MAX)
                near[c] = 1;
        });
    };
    std::vector<char> on_edge(dt.vertex_count(), 0);
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t))
            continue;
        for (int i = 0; i < 3; ++i) {
            const HalfEdge h = half_edge(t, i);
            const VertexId a = dt.origin(h), b = dt.destination(h);
            if (!dt.is_constrained(h) || a > b)
                continue; // each edge once, from its smaller end
            on_edge[a] = on_edge[b] = 1;
            const Vec3 &u = dt.point(a), &w = dt.point(b);
            const int pieces = std::max(1, static_cast<int>(std::ceil(norm(u - w) / piece)));
            Vec3 from = u;
            for (int k = 1; k <= pieces; ++k) {
                const Vec3 to =
                    k == pieces ? w : normalized(double(pieces - k) * u + double(k) * w);
                const Vec3 mid = normalized(from + to);
                mark(mid, chord + norm(from - mid));
                from = to;
            }
        }
    }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (!on_edge[v])
            mark(dt.point(v), chord);
    return near;
}

} // namespace

// Fills the open ocean where the size field reaches s_km, its largest value, with the nodes of
// an icosahedral lattice of that spacing: each of the icosahedron's 20 faces cut into n^2
// triangles and projected onto the sphere from its centre. Its triangles are close to
// equilateral and the right size, so the refinement then only fills the band between the
// lattice and the coast (or smaller sizes), growing fronts from both. The points are chosen on
// the triangulation of the boundary alone, whose triangles are large (walked face by face, row
// by row, each row the other way than the last, so each walk is a step); only those that may lie
// within the clearance of the boundary (near_boundary) look for it there. Those on the rim of
// the kept lattice and on the icosahedron's edges are then inserted as any point set; the
// others come with their six lattice triangles, put in place by replace_region (see below).
// Only the lattice's points in a cap around the ocean are walked (a region's), and none when
// those are more than `max_points` (about 10 n^2 times the cap's share of the sphere). Returns
// the number of nodes added.
std::size_t fill_lattice(Mesher &m, double s_km, double max_points, const std::vector<Vec3> &within,
                         double share) {
    auto inside = [&](const Vec3 &p) {
        return std::all_of(within.begin(), within.end(),
                           [&](const Vec3 &n) { return dot(p, n) > 0; });
    };
    SphericalDelaunay &dt = m.dt;
    const double s = km_to_rad(s_km);
    const LatticePoints lattice(s_km);
    const double n = lattice.rows();
    const Cap cap = ocean_cap(dt, s);
    const double cap_points = (10 * n * n + 2) * 0.5 * (1 - cap.cos_r) *
                              (cap.cos_r > -1 ? 1 : share); // the lattice's points there, about
    if (cap_points > max_points)
        return 0;
    const std::array<Vec3, 12> corner = ico_corners();
    Clearance clearance(dt, lattice_clearance * s);
    // The points walked (a node of an edge or corner that another face owns is filled in
    // after the walk).
    constexpr std::uint32_t none = LatticeCells::none;
    const int rows = static_cast<int>(n);
    LatticeCells grid;
    grid.rows = rows;
    grid.row_of.resize(20 * static_cast<std::size_t>(rows + 1));
    std::vector<std::uint32_t> &cell = grid.cell;
    SharedNodes shared_nodes(rows);
    std::vector<Vec3> points;
    // Room for every lattice point of the cap (those on land or too near the coast are never
    // written, so never touched): growing by doubling would copy and touch about twice the points.
    points.reserve(static_cast<std::size_t>(cap_points) + 1);
    // The rows first (each a run of cells), then the cells near the boundary, then the points.
    for (int f = 0; f < 20; ++f) {
        const Vec3 &a = corner[ico_face[f][0]], &b = corner[ico_face[f][1]],
                   &c = corner[ico_face[f][2]];
        // Skip a face whose cap (from its centre out to its corners) misses the ocean's.
        const Vec3 face_centre = normalized(a + b + c);
        if (cap.cos_r > -1 &&
            arc_angle(face_centre, cap.centre) > arc_angle(face_centre, a) + std::acos(cap.cos_r))
            continue;
        for (int i = 0; i <= rows; ++i) {
            const int len = rows - i;
            int lo = 0, hi = len;
            if ((cap.cos_r > -1 && !row_in_cap(cap, a, b, c, i, len, lo, hi)) ||
                !row_within(within, a, b, c, i, len, lo, hi))
                continue;
            grid.row_of[static_cast<std::size_t>(f) * (rows + 1) + i] = {lo, hi, cell.size()};
            cell.resize(cell.size() + static_cast<std::size_t>(hi - lo + 1), none);
        }
    }
    const std::vector<char> near = near_boundary(dt, lattice, grid, lattice_clearance * s, s);
    TriangleId hint = no_triangle;
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i <= rows; ++i) {
            const LatticeCells::Row &row = grid.row(f, i);
            for (int step = 0; step <= row.hi - row.lo; ++step) {
                const int j = i % 2 == 0 ? row.lo + step : row.hi - step;
                const int k = rows - i - j;
                if (!owns_node(f, i, j, k))
                    continue;
                // Each point moved by a pseudo-random 1e-6 of the spacing.
                const Vec3 p = lattice.point(f, i, j);
                if (!inside(p) || m.size_km(p) < lattice_level * s_km)
                    continue; // outside a part's lune: outside its ocean, not located
                hint = dt.locate(p, hint);
                const std::size_t at = row.start + static_cast<std::size_t>(j - row.lo);
                if (dt.label(hint) != ocean || (near[at] && !clearance.clear(p, hint)))
                    continue;
                const auto id = static_cast<std::uint32_t>(points.size());
                cell[at] = id;
                if (std::uint32_t *shared = shared_nodes.at(f, i, j, k))
                    *shared = id;
                points.push_back(p);
            }
        }
    if (points.empty())
        return 0;
    // Every face's edge and corner cells from their owners.
    for (int f = 0; f < 20; ++f)
        for (int i = 0; i <= rows; ++i) {
            const LatticeCells::Row &row = grid.row(f, i);
            for (int j = row.lo; j <= row.hi; ++j)
                if (const std::uint32_t *shared = shared_nodes.at(f, i, j, rows - i - j))
                    cell[row.start + static_cast<std::size_t>(j - row.lo)] = *shared;
        }
    shared_nodes.release();
    return place_lattice(m, grid, points);
}

} // namespace globemesh::mesher_internal
