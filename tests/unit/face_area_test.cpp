// The writers' geodesic face areas (src/io/face_area.hpp) against GeographicLib's PolygonArea,
// face by face: small connected patches of 5-60 km triangles at random places, round a pole
// (a node on it), across the antimeridian and the prime meridian, and faces of long sides.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include "face_area.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"

namespace {

using globemesh::Mesh;
using globemesh::NodeIndex;
using globemesh::Vec3;

/// Adds to m an n x n grid of nodes of spacing km (on the tangent plane at lon, lat; the middle
/// node exactly there), split into triangles counter-clockwise from outside.
void add_patch(Mesh &m, double lon, double lat, double km, int n = 10) {
    const Vec3 c = lat == 90    ? Vec3{0, 0, 1}
                   : lat == -90 ? Vec3{0, 0, -1}
                                : globemesh::lonlat_to_vec(lon, lat);
    const Vec3 east =
        std::fabs(c.z) == 1 ? Vec3{1, 0, 0} : globemesh::normalized(globemesh::cross({0, 0, 1}, c));
    const Vec3 north = globemesh::cross(c, east);
    const auto first = NodeIndex(m.nodes.size());
    const double step = km / 6371.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = (i - n / 2) * step, y = (j - n / 2) * step;
            m.nodes.push_back(
                i == n / 2 && j == n / 2 ? c : globemesh::normalized(c + x * east + y * north));
        }
    auto node = [&](int i, int j) { return first + NodeIndex(j * n + i); };
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            m.faces.push_back({node(i, j), node(i + 1, j), node(i + 1, j + 1)});
            m.faces.push_back({node(i, j), node(i + 1, j + 1), node(i, j + 1)});
        }
}

/// The largest |area - PolygonArea| / (1e-9 area + 4 c^2 eps sum |dlon|) over m's faces: at most
/// 1 when every face agrees to 1e-9 relative, up to PolygonArea's own rounding (its per-side terms
/// c^2 * alpha12, c^2 the authalic radius squared, whose angles near a pole are as large as the
/// sides' longitude spans: 0.03 m2 on a face round a pole, 1e-4 m2 on a 5 km face elsewhere).
double worst_ratio(const Mesh &m, std::size_t &faces_checked) {
    const auto topo = globemesh::io::build_topology(m);
    const globemesh::io::GeodesicFaceAreas areas(topo);
    std::vector<std::int32_t> edges;
    globemesh::io::face_edges(topo, 0, m.faces.size(), edges);
    double worst = 0;
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
        const auto &t = m.faces[f];
        const double ours = areas.face_m2(f, &edges[3 * f]);
        const double ref =
            globemesh::io::polygon_area_m2(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]]);
        EXPECT_GT(ref, 0);
        double span = 0;
        for (int k = 0; k < 3; ++k) {
            const double d = globemesh::vec_to_lonlat(m.nodes[t[std::size_t(k)]]).lon -
                             globemesh::vec_to_lonlat(m.nodes[t[std::size_t(k + 1) % 3]]).lon;
            span += std::fabs(std::remainder(d, 360.0)) * globemesh::deg_to_rad;
        }
        const double c2 = GeographicLib::Geodesic::WGS84().EllipsoidArea() / (4 * M_PI);
        const double rounding = 4 * c2 * std::numeric_limits<double>::epsilon() * span;
        worst = std::max(worst, std::fabs(ours - ref) / (1e-9 * ref + rounding));
        ++faces_checked;
    }
    return worst;
}

TEST(FaceArea, RandomPatchesAgreeWithPolygonArea) {
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> u(0, 1);
    Mesh m;
    for (int k = 0; k < 24; ++k) // uniform on the sphere, spacing 5-60 km
        add_patch(m, -180 + 360 * u(rng), std::asin(2 * u(rng) - 1) * globemesh::rad_to_deg,
                  5 + 55 * u(rng));
    std::size_t n = 0;
    EXPECT_LE(worst_ratio(m, n), 1.0);
    EXPECT_EQ(n, 24u * 162u);
}

TEST(FaceArea, PolesAndMeridiansAgreeWithPolygonArea) {
    Mesh m;
    for (double km : {5.0, 25.0, 55.0}) {
        add_patch(m, 0, 90, km);    // a node on the north pole, faces round it
        add_patch(m, 0, -90, km);   // and the south
        add_patch(m, 37, 89.8, km); // faces going round the pole without a node on it
        add_patch(m, -120, -89.9, km);
        add_patch(m, 180, 0, km); // across the antimeridian
        add_patch(m, 180, 63, km);
        add_patch(m, 0, -45, km); // across the prime meridian
    }
    std::size_t n = 0;
    EXPECT_LE(worst_ratio(m, n), 1.0);
}

TEST(FaceArea, LongSidesArePolygonAreaItself) {
    Mesh m;
    add_patch(m, 10, 20, 1.2 * globemesh::io::GeodesicFaceAreas::short_side_km, 4);
    add_patch(m, 0, 90, 500, 4);
    const auto topo = globemesh::io::build_topology(m);
    const globemesh::io::GeodesicFaceAreas areas(topo);
    std::vector<std::int32_t> edges;
    globemesh::io::face_edges(topo, 0, m.faces.size(), edges);
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
        const auto &t = m.faces[f];
        EXPECT_EQ(areas.face_m2(f, &edges[3 * f]),
                  globemesh::io::polygon_area_m2(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]]));
    }
}

TEST(FaceArea, ASideEntersItsTwoFacesWithOppositeSigns) {
    // The two faces of a square share its diagonal: their areas add up to the square's
    // (PolygonArea of the four corners), the diagonal's terms cancelling.
    Mesh m;
    add_patch(m, -70, 41, 50, 2);
    ASSERT_EQ(m.faces.size(), 2u);
    const auto topo = globemesh::io::build_topology(m);
    const globemesh::io::GeodesicFaceAreas areas(topo);
    std::vector<std::int32_t> edges;
    globemesh::io::face_edges(topo, 0, 2, edges);
    GeographicLib::PolygonArea square(GeographicLib::Geodesic::WGS84());
    for (int k : {0, 1, 3, 2}) {
        const auto p = globemesh::vec_to_lonlat(m.nodes[std::size_t(k)]);
        square.AddPoint(p.lat, p.lon);
    }
    double perimeter, area;
    square.Compute(false, true, perimeter, area);
    EXPECT_NEAR(areas.face_m2(0, &edges[0]) + areas.face_m2(1, &edges[3]), area, 1e-9 * area);
}

} // namespace
