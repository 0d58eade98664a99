// Internal to the mesher: the icosahedral lattice's points (lattice.cpp fills the ocean with
// them; the join of parts, parts_stitch.cpp, puts them back across the borders). A point is a
// function of the spacing and its index alone, so every part and the join compute the same bits.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "globemesh/sphere.hpp"

namespace globemesh::mesher_internal {

/// n subdivisions of an icosahedron's edge give a median chord of lattice_edge_scale / n (its
/// chords lie within [0.74, 1.09] of the median, its triangles' q above 0.88). A lattice node is
/// kept where the size field reaches lattice_level times the lattice's size, and no boundary
/// segment or other node lies within lattice_clearance times that size.
inline constexpr double lattice_edge_scale = 1.2185;
inline constexpr double lattice_level = 0.99;
inline constexpr double lattice_clearance = 1.5;

/// The icosahedron's 20 faces (indices of its corners, ico_corners).
inline constexpr int ico_face[20][3] = {
    {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};

/// The icosahedron's 12 corners on the unit sphere.
std::array<Vec3, 12> ico_corners();

/// Whether face f makes its node (i, j, k) (weights on its corners a, b, c): a node on the edge
/// opposite a corner (its weight 0) or at a corner belongs to the first face that has it.
bool owns_node(int f, int i, int j, int k);

/// The lattice of spacing s_km: its rows per face and its points.
class LatticePoints {
public:
    /// A lattice point's index: its owning face and weights i, j (k = rows - i - j).
    struct Index {
        int f, i, j;
    };
    explicit LatticePoints(double s_km);
    int rows() const { return rows_; }
    /// The spacing (radians) the lattice was asked for.
    double spacing() const { return s_; }
    /// Point (i, j, rows - i - j) of face f: its weights' direction, moved by a pseudo-random
    /// 1e-6 of the spacing (lattice_shift).
    Vec3 point(int f, int i, int j) const;
    /// Appends the lattice's points (each by the face that owns it) whose weights lie within
    /// `reach` steps of p's in a face of the icosahedron near p.
    void near(const Vec3 &p, int reach, std::vector<Index> &out) const {
        for_each_near(p, reach, [&](const Index &x) { out.push_back(x); });
    }
    /// Calls fn(Index) on each point near(p, reach) would append, in the same order.
    template <class Fn> void for_each_near(const Vec3 &p, int reach, Fn fn) const;
    /// A reach at which near(p, reach) holds every lattice point within `chord` of p (see
    /// lattice_points.cpp), or -1 where the chord is too long for any.
    int reach_for(double chord) const;
    /// How many indices index_of numbers: (rows + 1)^2 per face.
    std::size_t index_count() const { return 20 * std::size_t(rows_ + 1) * std::size_t(rows_ + 1); }
    std::size_t index_of(const Index &x) const {
        return (std::size_t(x.f) * std::size_t(rows_ + 1) + std::size_t(x.i)) *
                   std::size_t(rows_ + 1) +
               std::size_t(x.j);
    }
    /// Whether p is a lattice point, to the bit.
    bool is_point(const Vec3 &p) const;

private:
    double s_;
    int rows_;
    std::array<Vec3, 12> corner_;
    std::array<std::array<Vec3, 3>, 20> inverse_; // rows of each face's [a b c]^-1
};

template <class Fn> void LatticePoints::for_each_near(const Vec3 &p, int reach, Fn fn) const {
    for (int f = 0; f < 20; ++f) {
        // p's weights on the face's corners, scaled to sum to rows: where its ray meets the face.
        const std::array<double, 3> w = {dot(inverse_[f][0], p), dot(inverse_[f][1], p),
                                         dot(inverse_[f][2], p)};
        const double sum = w[0] + w[1] + w[2];
        if (sum <= 0)
            continue;
        const double i0 = rows_ * w[0] / sum, j0 = rows_ * w[1] / sum, k0 = rows_ - i0 - j0;
        if (i0 < -reach - 1 || j0 < -reach - 1 || k0 < -reach - 1)
            continue;
        const int ic = static_cast<int>(std::lround(i0)), jc = static_cast<int>(std::lround(j0));
        for (int i = std::max(0, ic - reach); i <= std::min(rows_, ic + reach); ++i)
            for (int j = std::max(0, jc - reach); j <= std::min(rows_ - i, jc + reach); ++j)
                if (owns_node(f, i, j, rows_ - i - j))
                    fn(Index{f, i, j});
    }
}

} // namespace globemesh::mesher_internal
