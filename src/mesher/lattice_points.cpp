// The icosahedral lattice's points: see lattice_points.hpp.
#include "lattice_points.hpp"

#include <algorithm>
#include <cmath>

namespace globemesh::mesher_internal {

namespace {

/// Each point is moved by this share of the spacing (lattice_shift).
constexpr double lattice_jitter = 1e-6;

// The pseudo-random shift of lattice point (f, i, j), each coordinate in [-0.5, 0.5) (its index
// hashed, splitmix64): the lattice's mirror symmetries make many four points exactly
// cocircular, each an in-circle test that only exact arithmetic decides.
Vec3 lattice_shift(int f, int i, int j) {
    std::uint64_t x = (static_cast<std::uint64_t>(f) << 42) ^
                      (static_cast<std::uint64_t>(i) << 21) ^ static_cast<std::uint64_t>(j);
    Vec3 shift;
    for (double *e : {&shift.x, &shift.y, &shift.z}) {
        x += 0x9e3779b97f4a7c15ull;
        std::uint64_t z = x;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        *e = double((z ^ (z >> 31)) >> 11) * 0x1p-53 - 0.5;
    }
    return shift;
}

// The first face with the edge a-b, or with the corner a when b < 0: a node shared by faces (on
// an edge or a corner) is made by the first face that has it.
int owner(int a, int b) {
    for (int f = 0; f < 20; ++f) {
        const int *v = ico_face[f];
        const bool has_a = v[0] == a || v[1] == a || v[2] == a;
        const bool has_b = b < 0 || v[0] == b || v[1] == b || v[2] == b;
        if (has_a && has_b)
            return f;
    }
    return -1;
}

} // namespace

std::array<Vec3, 12> ico_corners() {
    const double g = 0.5 * (1.0 + std::sqrt(5.0));
    return {normalized(Vec3{-1, g, 0}),  normalized(Vec3{1, g, 0}),   normalized(Vec3{-1, -g, 0}),
            normalized(Vec3{1, -g, 0}),  normalized(Vec3{0, -1, g}),  normalized(Vec3{0, 1, g}),
            normalized(Vec3{0, -1, -g}), normalized(Vec3{0, 1, -g}),  normalized(Vec3{g, 0, -1}),
            normalized(Vec3{g, 0, 1}),   normalized(Vec3{-g, 0, -1}), normalized(Vec3{-g, 0, 1})};
}

bool owns_node(int f, int i, int j, int k) {
    const int ia = ico_face[f][0], ib = ico_face[f][1], ic = ico_face[f][2];
    const int zeros = (i == 0) + (j == 0) + (k == 0);
    if (zeros == 2)
        return owner(i > 0 ? ia : j > 0 ? ib : ic, -1) == f;
    if (zeros == 1)
        return owner(i == 0 ? ib : ia, k == 0 ? ib : ic) == f;
    return true;
}

LatticePoints::LatticePoints(double s_km)
    : s_(km_to_rad(s_km)),
      rows_(static_cast<int>(std::max(1.0, std::round(lattice_edge_scale / s_)))),
      corner_(ico_corners()) {
    for (int f = 0; f < 20; ++f) {
        const Vec3 &a = corner_[ico_face[f][0]], &b = corner_[ico_face[f][1]],
                   &c = corner_[ico_face[f][2]];
        // The rows of [a b c]^-1: the cross products of the columns over the determinant.
        const double det = dot(a, cross(b, c));
        inverse_[f] = {(1 / det) * cross(b, c), (1 / det) * cross(c, a), (1 / det) * cross(a, b)};
    }
}

Vec3 LatticePoints::point(int f, int i, int j) const {
    const Vec3 &a = corner_[ico_face[f][0]], &b = corner_[ico_face[f][1]],
               &c = corner_[ico_face[f][2]];
    const int k = rows_ - i - j;
    return normalized(normalized(double(i) * a + double(j) * b + double(k) * c) +
                      (lattice_jitter * s_) * lattice_shift(f, i, j));
}

void LatticePoints::near(const Vec3 &p, int reach, std::vector<Index> &out) const {
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
                    out.push_back({f, i, j});
    }
}

bool LatticePoints::is_point(const Vec3 &p) const {
    std::vector<Index> nearest;
    near(p, 0, nearest); // a lattice point's weights round to its own (the jitter is 1e-6)
    return std::any_of(nearest.begin(), nearest.end(), [&](const Index &x) {
        const Vec3 q = point(x.f, x.i, x.j);
        return q.x == p.x && q.y == p.y && q.z == p.z;
    });
}

} // namespace globemesh::mesher_internal
