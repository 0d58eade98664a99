// Internal pieces of the coast module shared by its source files (not installed).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::coast_detail {

/// Squared distance from (px, py) to the segment a-b, in the lon/lat plane.
inline double planar_distance2(double px, double py, double ax, double ay, double bx, double by) {
    const double dx = bx - ax, dy = by - ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ex = ax + t * dx - px, ey = ay + t * dy - py;
    return ex * ex + ey * ey;
}

/// Two arcs (ring_a, seg_a) and (ring_b, seg_b) that touch or cross.
struct ArcPair {
    std::uint32_t ring_a, seg_a, ring_b, seg_b;
};

/// True when the great-circle arcs a-b and c-d (each shorter than pi/2) touch or cross.
bool arcs_conflict(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &d);

/// Every pair of arcs of the closed rings that touch or cross (consecutive arcs of one ring only
/// when they fold back), found through a uniform 3-D grid; sorted, at most max_pairs.
std::vector<ArcPair> find_conflicts(const std::vector<const std::vector<Vec3> *> &rings,
                                    std::size_t max_pairs = static_cast<std::size_t>(-1));

/// find_conflicts for rings that change a few arcs at a time: the grid and the conflicting
/// pairs are kept, and after a change only the new arcs are tested (against the new and the
/// kept ones). The rings are read through the pointers given, so a ring's vector is changed
/// in place and then named in replace().
class ArcGrid {
public:
    static constexpr std::uint32_t none = 0xffffffffu;
    /// Indexes every arc of the rings and finds the conflicts.
    explicit ArcGrid(const std::vector<const std::vector<Vec3> *> &rings);
    /// Ring r has changed: its arc i (from node i to the next) is its former arc old_of[i], the
    /// same two points, or `none` (a new arc). Two arcs kept must stay in their order, and two
    /// that followed each other must still.
    void replace(std::uint32_t r, const std::vector<std::uint32_t> &old_of);
    /// After the rings' replace() calls: the conflicts again.
    void update();
    /// The conflicts, as find_conflicts gives them.
    std::vector<ArcPair> conflicts(std::size_t max_pairs = static_cast<std::size_t>(-1)) const;

private:
    struct Box {
        double lo[3], hi[3];
    };
    using Entry = std::pair<std::uint64_t, std::uint32_t>; // (cell, arc id)
    std::uint32_t add_arc(std::uint32_t r, std::uint32_t i, std::vector<Entry> &entries);
    void test(std::uint32_t s, std::uint32_t t); // adds (s, t) to pairs_ when they conflict
    template <class Also>
    void test_cells(std::vector<Entry> &entries, Also &&also); // see boundary_check.cpp
    void settle();                                             // sorts pairs_, each once

    const std::vector<const std::vector<Vec3> *> &rings_;
    double cell_ = 0.05;
    std::vector<std::uint32_t> ring_, index_; // per arc id: its ring and its index there now
    std::vector<char> alive_;                 // per arc id: still in its ring
    std::vector<Box> boxes_;
    std::vector<std::vector<std::uint32_t>> ids_of_; // per ring, its arcs' ids in order
    std::vector<Entry> entries_;                     // sorted
    std::vector<Entry> fresh_;                       // the new arcs', until update()
    std::vector<std::pair<std::uint32_t, std::uint32_t>>
        pairs_; // conflicting arc ids, smaller first
};

/// Merges the samples of rings that lie closer together than `gap` times the local size
/// (h[r][k], radians, at sample k of ring r): of an arc that short, one end is dropped (one that
/// is `movable`) unless the arc that replaces it would touch or cross another (coast_merge.cpp).
/// `rings` are the samples as the grid indexes them, changed in place; `kept` gets each ring's
/// samples kept, in order (at least four of a ring). Returns the samples dropped.
std::size_t merge_close_samples(const std::vector<std::vector<Vec3>> &samples,
                                const std::vector<std::vector<double>> &h,
                                const std::vector<std::vector<char>> &movable, double gap,
                                std::vector<std::vector<Vec3>> &rings, ArcGrid &grid,
                                std::vector<std::vector<std::uint32_t>> &kept);

/// Pairs (i < j) of polygons (each its closed lon/lat rings) whose outlines come within
/// `distance` degrees of each other in the lon/lat plane, touching or crossing included
/// (near_pairs.cpp). Sorted, each once.
std::vector<std::pair<std::uint32_t, std::uint32_t>>
near_pairs(const std::vector<std::vector<std::vector<LonLat>>> &polygons, double distance);

/// Splits every arc that touches or crosses another at the midpoint of its lon/lat edge, and
/// again for the halves that still do, for at most max_rounds rounds (arc_split.cpp). Returns
/// the nodes added; conflicts that remain are the data's own (check_boundary reports them).
/// `clear` (when given) is set to whether no arc touches or crosses another at the end.
std::size_t split_conflicting_arcs(Boundary &boundary, int max_rounds, bool *clear = nullptr);

/// check_boundary without its search for arcs that touch or cross, for a boundary that
/// split_conflicting_arcs left clear: the same issues, without indexing every arc again.
std::vector<BoundaryIssue> check_boundary_clear(const Boundary &boundary, std::size_t max_issues);

/// Geodesic area (WGS84) to the left of all the closed lon/lat rings, km2 (sum of signed
/// GeographicLib areas modulo the Earth's area); the whole Earth when there is no ring.
double rings_area_km2(const std::vector<std::vector<LonLat>> &rings);

} // namespace globemesh::coast_detail
