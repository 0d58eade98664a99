// Where a passage line meets the mesh's triangles (passages.hpp): the mesher's strait check and
// the run's count of the cells across each passage; and whether it reaches a region's ocean.
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

/// The number of arcs of `ocean` (but ring `skip_ring`'s segment `skip`) that the short arc p-q
/// crosses or touches, or -1 when one only touches it (an end on the arc, or the arc through a
/// ring's node: the count's parity is then unknown).
long arcs_crossed(const Vec3 &p, const Vec3 &q, const Boundary &ocean, std::size_t skip_ring,
                  std::size_t skip) {
    const Vec3 n = cross(p, q);
    long count = 0;
    for (std::size_t r = 0; r < ocean.rings.size(); ++r) {
        const std::vector<Vec3> &nodes = ocean.rings[r].nodes;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            if (r == skip_ring && i == skip)
                continue;
            const Vec3 &a = nodes[i], &b = nodes[(i + 1) % nodes.size()];
            if (!arcs_meet(p, q, a, b))
                continue;
            if (dot(n, a) == 0 || dot(n, b) == 0 || side(a, b, p) == 0 || side(a, b, q) == 0)
                return -1;
            ++count;
        }
    }
    return count;
}

/// True when p lies in the ocean of `ocean` (left of its rings): the arc from p to the middle
/// of a ring's segment crosses the other segments an even number of times when p lies on the
/// segment's ocean side. A segment whose arc from p is not short enough, or only touches
/// another, gives way to the next.
bool in_ocean(const Vec3 &p, const Boundary &ocean) {
    for (std::size_t r = 0; r < ocean.rings.size(); ++r) {
        const std::vector<Vec3> &nodes = ocean.rings[r].nodes;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const Vec3 &a = nodes[i], &b = nodes[(i + 1) % nodes.size()];
            const Vec3 m = arc_midpoint(a, b);
            const double s = side(a, b, p);
            if (s == 0 || dot(p, m) <= 0) // on the segment's great circle, or a half turn away
                continue;
            const long crossed = arcs_crossed(p, m, ocean, r, i);
            if (crossed >= 0)
                return (s > 0) == (crossed % 2 == 0);
        }
    }
    return ocean.rings.empty(); // the whole sphere is ocean
}

} // namespace

bool line_meets_ocean(std::span<const Vec3> line, const Boundary &ocean) {
    if (line.empty())
        return false;
    for (std::size_t i = 0; i + 1 < line.size(); ++i)
        for (const Ring &ring : ocean.rings)
            for (std::size_t k = 0; k < ring.nodes.size(); ++k)
                if (arcs_meet(line[i], line[i + 1], ring.nodes[k],
                              ring.nodes[(k + 1) % ring.nodes.size()]))
                    return true;
    // No arc meets the outline: the line lies all in the ocean or all out of it.
    return in_ocean(line.front(), ocean);
}

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
