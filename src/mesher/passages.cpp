// Where a passage line meets the mesh's triangles (passages.hpp): the mesher's strait check and
// the run's count of the cells across each passage.
#include <algorithm>
#include <cmath>

#include "globemesh/passages.hpp"

namespace globemesh {

namespace {

double side(const Vec3 &a, const Vec3 &b, const Vec3 &p) {
    return dot(cross(a, b), p);
}

/// True when the short arcs p-q and a-b cross or touch.
bool arcs_meet(const Vec3 &p, const Vec3 &q, const Vec3 &a, const Vec3 &b) {
    const Vec3 n = cross(p, q), m = cross(a, b);
    const double sa = dot(n, a), sb = dot(n, b), sp = dot(m, p), sq = dot(m, q);
    if ((sa > 0 && sb > 0) || (sa < 0 && sb < 0) || (sp > 0 && sq > 0) || (sp < 0 && sq < 0))
        return false;
    return dot(p + q, a + b) > 0; // not the antipodal crossing of the two great circles
}

bool inside(const Vec3 &a, const Vec3 &b, const Vec3 &c, const Vec3 &p) {
    return side(a, b, p) >= 0 && side(b, c, p) >= 0 && side(c, a, p) >= 0 && dot(a + b + c, p) > 0;
}

} // namespace

bool line_meets_triangle(std::span<const Vec3> line, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    for (const Vec3 &p : line)
        if (inside(a, b, c, p))
            return true;
    for (std::size_t i = 0; i + 1 < line.size(); ++i)
        for (const auto &[x, y] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}})
            if (arcs_meet(line[i], line[i + 1], *x, *y))
                return true;
    return false;
}

std::size_t faces_crossed(const Mesh &mesh, std::span<const Vec3> line) {
    if (line.empty())
        return 0;
    // A cap around the line skips the faces far from it: a face reaches no farther from its
    // nearest corner than its longest edge.
    Vec3 sum{0, 0, 0};
    for (const Vec3 &p : line)
        sum = sum + p;
    const Vec3 centre = normalized(sum);
    double radius = 0;
    for (const Vec3 &p : line)
        radius = std::max(radius, arc_angle(centre, p));
    std::size_t n = 0;
    for (const auto &f : mesh.faces) {
        const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
        const double near =
            std::min({arc_angle(centre, a), arc_angle(centre, b), arc_angle(centre, c)});
        const double edge = std::max({arc_angle(a, b), arc_angle(b, c), arc_angle(c, a)});
        if (near - edge <= radius && line_meets_triangle(line, a, b, c))
            ++n;
    }
    return n;
}

} // namespace globemesh
