// A program outside globemesh: meshes the ocean of a land layer through the installed library
// (mesh_ocean) at a coarse uniform size and checks the mesh with its own geometry.
// Usage: ocean_consumer LAND_GPKG  (Natural Earth 1:110m land, layer "land"); exit 0 when it holds.
#include <globemesh/coast.hpp>
#include <globemesh/pipeline.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace {

using globemesh::Vec3;

// Area of a spherical triangle on the unit sphere (Van Oosterom and Strackee).
double triangle_area(const Vec3 &a, const Vec3 &b, const Vec3 &c) {
    return 2 * std::atan2(std::fabs(dot(a, cross(b, c))), 1 + dot(a, b) + dot(b, c) + dot(c, a));
}

int failures = 0;
void check(bool ok, const char *what) {
    if (!ok)
        std::fprintf(stderr, "ocean_consumer: FAILED: %s\n", what);
    failures += !ok;
}

} // namespace

int main(int argc, char **argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: ocean_consumer LAND_GPKG\n");
        return 2;
    }
    constexpr double hmax_km = 500, earth_radius_km = 6371.0088;
    globemesh::MeshOptions options;
    options.coast = argv[1];
    options.coast_layer = "land";
    options.hmax_km = hmax_km;
    const globemesh::OceanMesh run = globemesh::mesh_ocean(options);
    const globemesh::Mesh &mesh = run.mesh;

    double area = 0;
    bool indices_ok = true, unit_ok = true, ccw_ok = true;
    std::map<std::pair<globemesh::NodeIndex, globemesh::NodeIndex>, int> edge_faces;
    std::vector<double> edge_km;
    for (const auto &n : mesh.nodes)
        unit_ok = unit_ok && std::fabs(dot(n, n) - 1) < 1e-12;
    for (const auto &f : mesh.faces) {
        if (f[0] >= mesh.nodes.size() || f[1] >= mesh.nodes.size() || f[2] >= mesh.nodes.size()) {
            indices_ok = false;
            continue;
        }
        const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
        ccw_ok = ccw_ok && dot(a, cross(b, c)) > 0; // counter-clockwise seen from outside
        area += triangle_area(a, b, c);
        for (int i = 0; i < 3; ++i) {
            const auto p = f[i], q = f[(i + 1) % 3];
            if (++edge_faces[{std::min(p, q), std::max(p, q)}] == 1)
                edge_km.push_back(
                    earth_radius_km *
                    std::acos(std::clamp(dot(mesh.nodes[p], mesh.nodes[q]), -1.0, 1.0)));
        }
    }
    std::size_t open_edges = 0, overused_edges = 0;
    for (const auto &[edge, faces] : edge_faces) {
        open_edges += faces == 1;
        overused_edges += faces > 2;
    }
    std::nth_element(edge_km.begin(), edge_km.begin() + edge_km.size() / 2, edge_km.end());
    const double median_km = edge_km.empty() ? 0 : edge_km[edge_km.size() / 2];
    const double ocean_share = area / (4 * std::numbers::pi);
    std::printf(
        "ocean_consumer: %zu nodes, %zu faces, ocean %.3f of the sphere, median edge %.0f km\n",
        mesh.nodes.size(), mesh.faces.size(), ocean_share, median_km);

    check(mesh.faces.size() > 1000, "a few thousand faces at 500 km over the world ocean");
    check(indices_ok, "face node indices within the node array");
    check(unit_ok, "nodes are unit vectors");
    check(ccw_ok, "faces counter-clockwise seen from outside");
    check(overused_edges == 0, "no edge shared by more than two faces");
    check(open_edges == mesh.boundary.size(),
          "the boundary edges are exactly the edges of one face");
    // The ocean is about 71% of the Earth's surface; the coarse coast and the inland seas it
    // drops (Caspian, and at 500 km the Black Sea) move that by a point or two, never to 60 or 80.
    check(ocean_share > 0.65 && ocean_share < 0.77,
          "the mesh covers the world ocean's share of the sphere");
    // A uniform request: most edges near hmax, the coast's own and the graded ones shorter.
    check(median_km > 0.5 * hmax_km && median_km < 1.3 * hmax_km, "median edge length near hmax");

    // The library's errors reach a user as its own types.
    options.coast = "no-such-land.gpkg";
    bool typed_error = false;
    try {
        globemesh::mesh_ocean(options);
    } catch (const globemesh::Error &e) {
        typed_error = true;
        std::printf("ocean_consumer: missing input: %s\n", e.what());
    }
    check(typed_error, "a missing coast file throws a globemesh::Error");

    // One module alone, with its own options struct: the coast of a region, no MeshOptions.
    globemesh::CoastOptions coast;
    coast.coast = argv[1];
    coast.coast_layer = "land";
    coast.region = {{-12, 48, 12, 64}}; // the North Sea and the Channel: ocean and land
    const globemesh::CoastData region = globemesh::load_coast(coast);
    check(!region.rings.empty() && region.ocean_area_km2 > 1e5 && region.ocean_area_km2 < 5e6,
          "load_coast(CoastOptions) cuts the region's ocean");
    // A library user reads the option's field, never a command-line flag: with no layer named,
    // the two polygon layers of Natural Earth's file (land, ocean) ask for coast_layer.
    coast.coast_layer = "";
    std::string message;
    try {
        globemesh::load_coast(coast);
    } catch (const globemesh::DataError &e) {
        message = e.what();
    }
    check(message.find("coast_layer") != std::string::npos &&
              message.find("--") == std::string::npos,
          "a message asking for a layer names the coast_layer field, not a flag");
    return failures == 0 ? 0 : 1;
}
