// SphericalDelaunay::validate: every invariant of the triangulation checked, in words.
#include "globemesh/delaunay.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "delaunay_internal.hpp"
#include "globemesh/predicates.hpp"

namespace globemesh {

using delaunay_detail::next3;
using delaunay_detail::prev3;
using predicates::in_circle;
using predicates::orient;

// ---------------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------------

std::vector<std::string> SphericalDelaunay::validate() const {
    std::vector<std::string> problems;
    auto fail = [&](const std::string &s) {
        if (problems.size() < 50)
            problems.push_back(s);
    };
    std::vector<std::uint8_t> used(points_.size(), 0);
    std::size_t faces = 0, nondelaunay = 0, ghosts = 0, flat = 0;
    double area = 0;
    for (TriangleId t = 0; t < triangle_slots(); ++t) {
        if (!is_live(t))
            continue;
        ++faces;
        VertexId a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
        if (a >= points_.size() || b >= points_.size() || c >= points_.size() || a == b || b == c ||
            a == c) {
            fail("triangle " + std::to_string(t) + " has invalid or repeated vertices");
            continue;
        }
        used[a] = used[b] = used[c] = 1;
        area += spherical_triangle_area(points_[a], points_[b], points_[c]);
        int o = orient(points_[a], points_[b], points_[c]);
        if (o < 0)
            ++ghosts;
        if (o == 0)
            ++flat;
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            HalfEdge o = twin(h);
            if (o >= links_.size() || !is_live(triangle_of(o))) {
                fail("half-edge " + std::to_string(h) + " links to a dead triangle");
                continue;
            }
            if (twin(o) != h)
                fail("neighbour links of half-edge " + std::to_string(h) + " are not symmetric");
            if (origin(o) != destination(h) || destination(o) != origin(h))
                fail("half-edge " + std::to_string(h) + " and its twin do not share endpoints");
            if (is_constrained(o) != is_constrained(h))
                fail("constraint flag of half-edge " + std::to_string(h) +
                     " differs on its two sides");
            if (!is_constrained(h) && h < o) {
                const TriangleId s = triangle_of(o);
                if (in_circle(points_[a], points_[b], points_[c], points_[vertex(s, edge_of(o))]) >
                    0)
                    ++nondelaunay;
            }
        }
    }
    std::size_t v_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), 1));
    if (faces % 2 != 0)
        fail("odd number of triangles in a closed triangulation");
    long long euler = static_cast<long long>(v_used) - static_cast<long long>(3 * faces / 2) +
                      static_cast<long long>(faces);
    if (faces > 0 && euler != 2)
        fail("Euler characteristic V - E + F = " + std::to_string(euler) + ", not 2");
    if (nondelaunay)
        fail(std::to_string(nondelaunay) + " unconstrained edges are not locally Delaunay");
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
