// Independent checks for the coast tests: a brute-force crossing test on unit vectors written
// apart from the library's (no grid, no epsilon: signs of triple products), and geodesic areas
// of OGR layers computed straight from the source file with GeographicLib.
#pragma once

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_api.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::test {

inline double triple(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    return dot(a, cross(b, c));
}

/// Number of pairs of non-adjacent arcs that properly cross, plus nodes used twice, plus
/// consecutive equal nodes, over all rings. Brute force with a bounding-cap prefilter.
inline std::size_t count_violations(const Boundary &b) {
    struct Seg {
        Vec3 a, b, mid;
        double radius;
        std::size_t ring, index, n;
    };
    std::vector<Seg> segs;
    std::vector<std::tuple<double, double, double>> nodes;
    std::size_t bad = 0;
    for (std::size_t r = 0; r < b.rings.size(); ++r) {
        const auto &ns = b.rings[r].nodes;
        if (ns.size() < 3)
            ++bad;
        for (std::size_t i = 0; i < ns.size(); ++i) {
            const Vec3 &p = ns[i];
            const Vec3 &q = ns[(i + 1) % ns.size()];
            if (p == q)
                ++bad;
            nodes.emplace_back(p.x, p.y, p.z);
            Vec3 m = normalized(p + q);
            segs.push_back({p, q, m, std::max(norm(p - m), norm(q - m)) + 1e-12, r, i, ns.size()});
        }
    }
    std::sort(nodes.begin(), nodes.end());
    bad += static_cast<std::size_t>(nodes.end() - std::unique(nodes.begin(), nodes.end()));
    // Sort by z of the midpoint so the prefilter can stop early.
    std::sort(segs.begin(), segs.end(),
              [](const Seg &s, const Seg &t) { return s.mid.z < t.mid.z; });
    double max_r = 0;
    for (const auto &s : segs)
        max_r = std::max(max_r, s.radius);
    for (std::size_t i = 0; i < segs.size(); ++i) {
        for (std::size_t j = i + 1; j < segs.size() && segs[j].mid.z - segs[i].mid.z <= 2 * max_r;
             ++j) {
            const Seg &s = segs[i];
            const Seg &t = segs[j];
            if (norm(s.mid - t.mid) > s.radius + t.radius)
                continue;
            if (s.ring == t.ring &&
                ((s.index + 1) % s.n == t.index || (t.index + 1) % t.n == s.index))
                continue;
            double d1 = triple(s.a, s.b, t.a), d2 = triple(s.a, s.b, t.b);
            double d3 = triple(t.a, t.b, s.a), d4 = triple(t.a, t.b, s.b);
            if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) &&
                ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
                ++bad;
        }
    }
    return bad;
}

/// Geodesic area (km2, WGS84) of every polygon of an OGR layer in lon/lat, exteriors minus
/// holes; with largest_only, of its largest polygon only.
inline double layer_area_km2(const std::string &path, const std::string &layer_name,
                             bool largest_only = false) {
    GDALAllRegister();
    GDALDatasetH ds = GDALOpenEx(path.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    EXPECT_NE(ds, nullptr) << path;
    if (!ds)
        return 0;
    OGRLayerH layer = GDALDatasetGetLayerByName(ds, layer_name.c_str());
    const auto &wgs = GeographicLib::Geodesic::WGS84();
    auto ring_area = [&](OGRGeometryH ring) {
        GeographicLib::PolygonArea poly(wgs);
        int n = OGR_G_GetPointCount(ring);
        for (int i = 0; i + 1 < n; ++i)
            poly.AddPoint(OGR_G_GetY(ring, i), OGR_G_GetX(ring, i));
        double perimeter, area;
        poly.Compute(false, false, perimeter,
                     area); // unsigned: orientation as stored does not matter
        double small = std::min(area, wgs.EllipsoidArea() - area);
        // Natural Earth's ocean exterior runs along lat 90: it encloses the North Pole, the larger
        // part.
        bool north = false;
        for (int i = 0; i < n; ++i)
            north = north || OGR_G_GetY(ring, i) == 90.0;
        return (north ? wgs.EllipsoidArea() - small : small) * 1e-6;
    };
    std::vector<double> areas;
    OGR_L_ResetReading(layer);
    while (OGRFeatureH f = OGR_L_GetNextFeature(layer)) {
        OGRGeometryH g = OGR_F_GetGeometryRef(f);
        for (int p = 0; p < OGR_G_GetGeometryCount(g); ++p) {
            OGRGeometryH poly = OGR_G_GetGeometryRef(g, p);
            double a = ring_area(OGR_G_GetGeometryRef(poly, 0));
            for (int h = 1; h < OGR_G_GetGeometryCount(poly); ++h)
                a -= ring_area(OGR_G_GetGeometryRef(poly, h));
            areas.push_back(a);
        }
        OGR_F_Destroy(f);
    }
    GDALClose(ds);
    if (largest_only)
        return *std::max_element(areas.begin(), areas.end());
    double sum = 0;
    for (double a : areas)
        sum += a;
    return sum;
}

/// Copies the vector data set `src` to `dst` as ogr2ogr does with `args` (GDALVectorTranslate);
/// false when GDAL cannot open or write it.
inline bool ogr2ogr(const std::string &src, const std::string &dst,
                    std::vector<const char *> args) {
    GDALAllRegister();
    GDALDatasetH in = GDALOpenEx(src.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
    if (!in)
        return false;
    args.push_back(nullptr);
    GDALVectorTranslateOptions *opts =
        GDALVectorTranslateOptionsNew(const_cast<char **>(args.data()), nullptr);
    GDALDatasetH out = GDALVectorTranslate(dst.c_str(), nullptr, 1, &in, opts, nullptr);
    GDALVectorTranslateOptionsFree(opts);
    if (out)
        GDALClose(out);
    GDALClose(in);
    return out != nullptr;
}

} // namespace globemesh::test
