// Hostile cases cut from real public coastlines (fixtures/coast/hostile/, sources in
// fixtures/README.md): each failed before issue 37 and must now mesh validly.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "globemesh/coast.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/pipeline.hpp"
#include "globemesh/ugrid.hpp"
#include "support.hpp"

namespace globemesh {
namespace {

MeshOptions region_run(const std::string &coast, std::array<double, 4> region, double h_km) {
    MeshOptions o;
    o.coast = test::fixture(coast).string();
    o.region = region;
    o.hmax_km = h_km;
    return o;
}

void expect_valid_mesh(const Mesh &mesh, const MeshOptions &o, const std::string &name) {
    test::TempDir dir;
    write_ugrid(mesh, dir / name);
    test::expect_mesh_verify(dir / name, "--coast " + o.coast + " --max-land-faces 0");
}

// GSHHG intermediate around the Great Sandy Strait (Queensland): an islet's vertex 0.4 m from
// the mainland's 5 km edge, which as a great-circle arc passes on the islet's other side. The
// check on the cleaned coast refused the whole run ("arcs touch or cross near lon 152.6166,
// lat -25.1746"); snap rounding and the split of straying arcs now resolve it. The land is
// also clipped to the region's own box.
TEST(CoastReal, an_islet_a_fraction_of_a_metre_off_the_mainland_meshes) {
    const MeshOptions o = region_run("coast/hostile/gshhg_i_great_sandy_strait.geojson",
                                     {152.3, -25.5, 153.3, -24.8}, 5);
    const CoastData d = load_coast(o);
    EXPECT_TRUE(check_boundary(d.rings).empty());
    // The near-touch is resolved, and said so: split arcs or joined polygons are counted.
    EXPECT_GT(d.arcs_split + d.polygons_joined, 0u);
    const Mesh mesh = mesh_ocean(o).mesh;
    EXPECT_GT(mesh.faces.size(), 100u);
    expect_valid_mesh(mesh, o, "strait.nc");
}

// GSHHG full resolution of the Sogn coast (western Norway), clipped to a lon/lat box and stored
// in UTM 32N (EPSG:25832) as a shapefile, meshed with that box as --region: the land runs
// along the region's outline, an island closes a notch of water against it, and every size
// from 10 km to 0.5 km was refused, by the outline check or by the mesher's ring orientation.
TEST(CoastReal, a_fjord_coast_clipped_to_its_region_meshes_at_every_size) {
    for (double h : {10.0, 5.0, 4.0, 2.5, 2.2, 1.8, 1.5, 1.0, 0.75, 0.5}) {
        SCOPED_TRACE("--hmax " + std::to_string(h) + " km");
        const MeshOptions o =
            region_run("coast/hostile/gshhg_f_sogn_25832.shp", {4.8, 61.3, 5.3, 61.6}, h);
        const Mesh mesh = mesh_ocean(o).mesh;
        EXPECT_GT(mesh.faces.size(), 10u);
        if (h == 10.0 || h == 1.5 || h == 0.5)
            expect_valid_mesh(mesh, o, "fjord.nc");
    }
}

} // namespace
} // namespace globemesh
