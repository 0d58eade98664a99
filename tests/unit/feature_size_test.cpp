// Tests of the feature-size component (--feature-size): the local feature size of a strait of
// known width on the sphere, the field it gives, and the elements across the channels of a real
// fjord coast (GSHHG full, Sogn) measured on the mesh by walking cross-sections.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "feature_size.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/sizefield.hpp"
#include "globemesh/ugrid.hpp"
#include "support.hpp"

namespace globemesh {
namespace {

/// Shores of the strait: parallels at 60 N -+ half_deg, the strait along them (lon -1..1).
constexpr double strait_lat = 60, half_deg = 0.05;
/// Its width along a meridian, km.
const double strait_width_km = 2 * half_deg * deg_to_rad * earth_radius_km;

/// Two land polygons (a vertex every 0.01 degree) with the strait between them, as GeoJSON.
std::filesystem::path write_strait(const test::TempDir &dir) {
    auto ring = [](double south, double north) {
        std::string s = "[[";
        for (int i = 0; i <= 200; ++i)
            s += "[" + std::to_string(-1 + 0.01 * i) + "," + std::to_string(south) + "],";
        for (int i = 200; i >= 0; --i)
            s += "[" + std::to_string(-1 + 0.01 * i) + "," + std::to_string(north) + "],";
        return s + "[-1," + std::to_string(south) + "]]]";
    };
    const std::filesystem::path path = dir / "strait.geojson";
    std::ofstream(path)
        << R"({"type":"FeatureCollection","features":[)"
        << R"({"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":)"
        << ring(strait_lat - 1, strait_lat - half_deg) << "}},"
        << R"({"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":)"
        << ring(strait_lat + half_deg, strait_lat + 1) << "}}]}";
    return path;
}

CoastOptions strait_coast(const std::filesystem::path &path) {
    CoastOptions o;
    o.coast = path.string();
    o.region = std::array<double, 4>{-0.5, strait_lat - 0.5, 0.5, strait_lat + 0.5};
    return o;
}

TEST(FeatureSize, StraitOfKnownWidthHasHalfItsWidthAsLocalFeatureSize) {
    test::TempDir dir;
    const CoastData coast = load_coast(strait_coast(write_strait(dir)));
    for (double spacing : {0.25, 1.0}) {
        const auto channels = detail::channel_triangles(coast.rings, spacing, 100);
        std::size_t inner = 0;
        for (const auto &t : channels) {
            const LonLat g = vec_to_lonlat(normalized(t.a + t.b + t.c));
            EXPECT_NEAR(g.lat, strait_lat, half_deg) << "a channel triangle off the strait";
            if (std::abs(g.lon) > 0.4)
                continue; // the strait's open ends
            ++inner;
            EXPECT_NEAR(t.lfs_km, strait_width_km / 2, spacing)
                << "spacing " << spacing << " at lon " << g.lon;
        }
        // Triangles tile the strait: about two per sample along each 0.8 degree of shore.
        const double shore_km =
            0.8 * deg_to_rad * earth_radius_km * std::cos(strait_lat * deg_to_rad);
        EXPECT_GT(static_cast<double>(inner), 1.5 * shore_km / spacing) << "spacing " << spacing;
    }
}

TEST(FeatureSize, FieldHoldsThreeElementsAcrossTheStrait) {
    test::TempDir dir;
    const CoastOptions co = strait_coast(write_strait(dir));
    const CoastData coast = load_coast(co);
    SizeFieldOptions o;
    o.hmax_km = 50;
    o.hmin_km = 0.5;
    o.feature_size = 3;
    const SizeField field = build_size_field(o, co.region, nullptr, &coast.rings);
    SizeFieldOptions without = o;
    without.feature_size = 0;
    const SizeField off = build_size_field(without, co.region, nullptr, &coast.rings);
    EXPECT_TRUE(off.is_uniform());
    const double target = strait_width_km / 3; // 2 lfs / 3
    for (double lon : {-0.3, 0.0, 0.25})
        for (double dlat : {-0.04, 0.0, 0.03}) {
            const double h = field.size_km(lon, strait_lat + dlat);
            EXPECT_LE(h, target + 0.01) << lon << " " << dlat;
            EXPECT_GE(h, target - 0.5 * 2 / 3.0) << lon << " " << dlat; // within the spacing
        }
    // Far from the strait (on land 0.4 degree away, 44 km) the field is graded back up.
    EXPECT_GT(field.size_km(0.0, strait_lat + 0.45), target + 0.15 * 30);
}

TEST(FeatureSize, NegativeOrWithoutCoastIsRefused) {
    SizeFieldOptions o;
    o.feature_size = -1;
    EXPECT_THROW(build_size_field(o, std::nullopt, nullptr, nullptr), UsageError);
    o.feature_size = 3;
    const std::string m = test::thrown_message<UsageError>(
        [&] { build_size_field(o, std::nullopt, nullptr, nullptr); }, "build_size_field");
    EXPECT_NE(m.find("feature_size"), std::string::npos) << m;
}

/// Locates points in a mesh's faces through buckets of a lon/lat grid over its extent.
class FaceLocator {
public:
    explicit FaceLocator(const Mesh &m) : mesh_(m) {
        for (const Vec3 &p : m.nodes) {
            const LonLat q = vec_to_lonlat(p);
            lo_ = {std::min(lo_.lon, q.lon), std::min(lo_.lat, q.lat)};
            hi_ = {std::max(hi_.lon, q.lon), std::max(hi_.lat, q.lat)};
        }
        buckets_.resize(n * n);
        for (std::size_t f = 0; f < m.faces.size(); ++f) {
            LonLat a{1e9, 1e9}, b{-1e9, -1e9};
            for (auto v : m.faces[f]) {
                const LonLat q = vec_to_lonlat(m.nodes[v]);
                a = {std::min(a.lon, q.lon), std::min(a.lat, q.lat)};
                b = {std::max(b.lon, q.lon), std::max(b.lat, q.lat)};
            }
            for (std::size_t j = cell(a.lat, 1); j <= cell(b.lat, 1); ++j)
                for (std::size_t i = cell(a.lon, 0); i <= cell(b.lon, 0); ++i)
                    buckets_[j * n + i].push_back(f);
        }
    }
    /// The face holding p, or -1 outside the mesh.
    long face(const Vec3 &p) const {
        const LonLat q = vec_to_lonlat(p);
        if (q.lon < lo_.lon || q.lon > hi_.lon || q.lat < lo_.lat || q.lat > hi_.lat)
            return -1;
        for (std::size_t f : buckets_[cell(q.lat, 1) * n + cell(q.lon, 0)]) {
            const auto &t = mesh_.faces[f];
            const Vec3 &a = mesh_.nodes[t[0]], &b = mesh_.nodes[t[1]], &c = mesh_.nodes[t[2]];
            if (dot(cross(a, b), p) >= 0 && dot(cross(b, c), p) >= 0 && dot(cross(c, a), p) >= 0)
                return static_cast<long>(f);
        }
        return -1;
    }

private:
    static constexpr std::size_t n = 256;
    std::size_t cell(double x, int axis) const {
        const double lo = axis ? lo_.lat : lo_.lon, hi = axis ? hi_.lat : hi_.lon;
        return std::min(n - 1, static_cast<std::size_t>(std::max(0.0, (x - lo) / (hi - lo) * n)));
    }
    const Mesh &mesh_;
    LonLat lo_{1e9, 1e9}, hi_{-1e9, -1e9};
    std::vector<std::vector<std::size_t>> buckets_;
};

/// Cross-sections of the channels: from the midpoint of each coast edge of the mesh straight
/// into the water (perpendicular to the edge) to the far shore. A section that leaves the mesh
/// within 0.5 km of the region's sides (W,S,E,N) ends at the region's open edge, not at a shore,
/// and is left out.
struct Section {
    double width_km = 0;     ///< to where the section leaves the mesh
    double edges_across = 0; ///< width over the mean edge length of the faces crossed
};

std::vector<Section> sections(const Mesh &m, const std::array<double, 4> &region, double step_km) {
    const FaceLocator locate(m);
    const double margin_deg = 0.5 / earth_radius_km * rad_to_deg;
    auto near_region_side = [&](const Vec3 &p) {
        const LonLat q = vec_to_lonlat(p);
        const double lon_margin = margin_deg / std::cos(q.lat * deg_to_rad);
        return q.lon < region[0] + lon_margin || q.lon > region[2] - lon_margin ||
               q.lat < region[1] + margin_deg || q.lat > region[3] - margin_deg;
    };
    std::vector<Section> out;
    for (const BoundaryEdge &e : m.boundary) {
        if (e.tag != EdgeTag::coast)
            continue;
        const Vec3 &a = m.nodes[e.a], &b = m.nodes[e.b]; // the mesh on the left
        const Vec3 mid = normalized(a + b), inward = normalized(cross(mid, b - a));
        Section s;
        std::vector<long> crossed;
        double length_sum = 0;
        Vec3 p = mid;
        for (double d = step_km; d < 100; d += step_km) {
            p = normalized(mid + std::tan(km_to_rad(d)) * inward);
            const long g = locate.face(p);
            s.width_km = d;
            if (g < 0)
                break;
            if (std::find(crossed.begin(), crossed.end(), g) == crossed.end()) {
                crossed.push_back(g);
                const auto &u = m.faces[static_cast<std::size_t>(g)];
                for (int k = 0; k < 3; ++k)
                    length_sum += arc_km(m.nodes[u[k]], m.nodes[u[(k + 1) % 3]]) / 3;
            }
        }
        if (crossed.empty() || near_region_side(p))
            continue;
        s.edges_across = s.width_km / (length_sum / static_cast<double>(crossed.size()));
        out.push_back(s);
    }
    return out;
}

/// Share of the sections across channels wider than min_width_km that hold fewer than
/// `elements` edges, and how many such sections there are.
std::pair<double, std::size_t> short_share(const std::vector<Section> &all, double min_width_km,
                                           double elements) {
    std::size_t wide = 0, short_ = 0;
    for (const Section &s : all)
        if (s.width_km > min_width_km) {
            ++wide;
            short_ += s.edges_across < elements;
        }
    return {wide ? static_cast<double>(short_) / static_cast<double>(wide) : 0.0, wide};
}

TEST(FeatureSize, FjordCoastHasThreeEdgesAcrossEveryChannel) {
    // GSHHG full land of the Sogn coast (fjords and skerries, UTM 32N shapefile).
    MeshOptions o;
    o.coast = test::fixture("coast/hostile/gshhg_f_sogn_25832.shp").string();
    o.region = std::array<double, 4>{4.8, 61.3, 5.3, 61.6};
    o.hmin_km = 0.2;
    o.hmax_km = 3;
    const OceanMesh without = mesh_ocean(o);
    o.feature_size = 3;
    const OceanMesh with = mesh_ocean(o);
    const double min_width = 3 * o.hmin_km;
    const auto [share_without, wide_without] =
        short_share(sections(without.mesh, *o.region, 0.01), min_width, 3);
    const std::vector<Section> with_sections = sections(with.mesh, *o.region, 0.01);
    const auto [share_with, wide_with] = short_share(with_sections, min_width, 3);
    std::printf("feature size 3 on Sogn: %zu nodes (%zu without), %zu sections wider than %.1f km "
                "(%zu without), %.1f%% with fewer than 3 edges across (%.1f%% without)\n",
                with.mesh.nodes.size(), without.mesh.nodes.size(), wide_with, min_width,
                wide_without, 100 * share_with, 100 * share_without);
    EXPECT_GT(wide_with, 500u);
    EXPECT_GT(share_without, 0.3) << "the run without the term is already fine: no test";
    // The mesher's edges spread about the target size (edge / target in [0.7, 1.4], median 1):
    // a channel near 3 hmin, where the size stops at hmin, can hold a little under 3 edges, and
    // near a fjord's head (the coast samples there too close along the coast to count as two
    // shores) the field is the grading's. 15 sections of 1326 (1.1%) hold fewer than 3.
    EXPECT_LT(share_with, 0.015);
    for (const Section &s : with_sections) {
        if (s.width_km > 4 * o.hmin_km) {
            EXPECT_GE(s.edges_across, 2.9) << "a channel " << s.width_km << " km wide";
        }
    }
    // A run the term would take over --max-nodes is refused before meshing, naming the option.
    o.max_nodes = with.mesh.nodes.size() / 3;
    const std::string m = test::thrown_message<DataError>([&] { mesh_ocean(o); }, "mesh_ocean");
    EXPECT_NE(m.find("max_nodes"), std::string::npos) << m;
    test::TempDir dir;
    write_ugrid(with.mesh, dir / "sogn.nc");
    test::expect_mesh_verify(dir / "sogn.nc", "--min-quality 0.3");
}

} // namespace
} // namespace globemesh
