// The outputs opened in real QGIS (../shared/tools/qgis-check, QGIS 3.22 + MDAL): the .nc is a
// valid mesh layer with CRS EPSG:4326, the right vertex/face counts and its datasets; the .gpkg
// layers have the right feature counts, no face part wider than 180 degrees, and the faces layer
// opens with the stored graduated-by-quality style. Skipped where QGIS or ../shared is absent
// (a failure under CI=true).
#include <gtest/gtest.h>

#include <fstream>

#include "../unit/io_test_meshes.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/ugrid.hpp"
#include "support.hpp"

using namespace globemesh;
using namespace globemesh::test;

namespace {

std::filesystem::path qgis_check() {
    return std::filesystem::path(GLOBEMESH_SHARED_DIR) / "tools" / "qgis-check";
}

bool qgis_available() {
    std::string out;
    return std::filesystem::exists(qgis_check()) &&
           run_command("/usr/bin/python3 -c 'import qgis.core'", out) == 0;
}

void check_in_qgis(const Mesh &m, const std::string &name, const std::string &crs) {
    if (!qgis_available())
        return tool_missing("qgis-check (" + qgis_check().string() + ") or QGIS (python3-qgis)");
    TempDir dir;
    write_ugrid(m, dir / (name + ".nc"));
    write_gpkg(m, dir / (name + ".gpkg"));
    std::string out;
    const std::string files =
        (dir / (name + ".nc")).string() + " " + (dir / (name + ".gpkg")).string();
    int status =
        run_command(qgis_check().string() + " --expect-faces " + std::to_string(m.faces.size()) +
                        " --expect-nodes " + std::to_string(m.nodes.size()) + " --crs " + crs +
                        " --png " + (dir / "look.png").string() + " " + files,
                    out);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("(MDAL driver Ugrid)"), std::string::npos) << out;
    EXPECT_NE(out.find("crs EPSG:4326"), std::string::npos) << out;
    EXPECT_NE(out.find("vertices " + std::to_string(m.nodes.size()) + ", faces " +
                       std::to_string(m.faces.size())),
              std::string::npos)
        << out;
    for (const char *dataset :
         {"'sea floor depth' on vertices", "'quality (2*sqrt(3)*inradius/longest edge)' on faces",
          "'target edge length' on vertices", "'face area (geodesic, WGS84)' on faces"})
        EXPECT_NE(out.find(dataset), std::string::npos) << dataset << "\n" << out;
    EXPECT_NE(out.find("layer 'faces' (provider ogr): valid, " + std::to_string(m.faces.size()) +
                       " features, MultiPolygon"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("layer 'nodes' (provider ogr): valid, " + std::to_string(m.nodes.size()) +
                       " features, Point"),
              std::string::npos)
        << out;
    // qgis-check warns about smeared parts through the R-tree; the .gpkg must have none (the .nc
    // stores each node once, so its warning about long triangles in lon/lat is expected).
    std::string gpkg_part = out.substr(out.find(name + ".gpkg"));
    gpkg_part = gpkg_part.substr(0, gpkg_part.find(name + ".nc"));
    EXPECT_EQ(gpkg_part.find("wider than 180"), std::string::npos) << out;
    EXPECT_EQ(gpkg_part.find("WARNING"), std::string::npos) << out;
    EXPECT_TRUE(std::filesystem::file_size(dir / "look.png") > 1000);

    // The stored default style is what QGIS applies when it opens the faces layer.
    std::ofstream(dir / "style.py")
        << "import os, sys\nos.environ['QT_QPA_PLATFORM'] = 'offscreen'\n"
           "from qgis.core import QgsApplication, QgsVectorLayer\n"
           "app = QgsApplication([], False)\napp.initQgis()\n"
           "l = QgsVectorLayer(sys.argv[1] + '|layername=faces', 'f', 'ogr')\n"
           "r = l.renderer()\nprint('RENDERER', r.type(), r.classAttribute() if "
           "r.type() == 'graduatedSymbol' else '-', flush=True)\nos._exit(0)\n";
    status = run_command("/usr/bin/python3 " + (dir / "style.py").string() + " " +
                             (dir / (name + ".gpkg")).string(),
                         out);
    EXPECT_EQ(status, 0) << out;
    EXPECT_NE(out.find("RENDERER graduatedSymbol quality"), std::string::npos) << out;
}

} // namespace

TEST(QgisCheck, global_mesh_with_holes_loads_in_qgis_as_mesh_and_layers) {
    check_in_qgis(icosphere_with_holes(4), "global", "EPSG:4326");
}

TEST(QgisCheck, pacific_mesh_across_the_antimeridian_loads_in_qgis) {
    check_in_qgis(icosphere_cap(4, 180, 0, 30), "pacific", "EPSG:3832");
}
