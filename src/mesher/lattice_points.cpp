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

// Two points of a face's plane whose weights differ by h steps in i or j (a step is an edge of the
// flat face's n^2 triangles, |a - b| / n) are at least sqrt(3) / 2 h of those edges apart, and a
// point outside the box near() walks is at least reach + 1/2 steps from p's rounded weights.
// Projected from the centre, a flat distance is at most the arc between the points over
// cos^2(phi) / cos(phi_face), phi the larger angle of an arc's point from the face's centre: at
// most phi_face (0.65 rad, the corners') plus the arc. Past 1.45 rad no box is sure to hold them.
int LatticePoints::reach_for(double chord) const {
    const Vec3 &a = corner_[ico_face[0][0]], &b = corner_[ico_face[0][1]],
               &c = corner_[ico_face[0][2]];
    const double cos_face = dot(normalized(a + b + c), a); // the corners' angle from the centre
    const double arc = 2 * std::asin(std::min(1.0, 0.5 * chord));
    const double phi = std::acos(cos_face) + arc;
    if (phi > 1.45)
        return -1;
    const double flat = arc * cos_face / std::pow(std::cos(phi), 2);
    const double step = 0.5 * std::sqrt(3.0) * norm(a - b) / rows_;
    return static_cast<int>(std::ceil(flat / step - 0.5)) + 1;
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
