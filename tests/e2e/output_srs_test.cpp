// --output-srs through the globemesh executable: a regional mesh from real data (Natural Earth
// 1:50m land, ETOPO5 north-west shelf) written as ADCIRC .14, SCHISM .gr3 and .ll, SELAFIN .slf
// and gmsh .msh in UTM, each read back by a reader that is not the writer (a fort.14 reader
// written here from the format's documentation, gmsh's Python API, meshio, QGIS/MDAL) and
// compared with the UGRID file's lon/lat transformed independently (osgeo.osr); the CRS in the
// .msh file; and the refusals: one line, exit 1 or 2, no file left.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "support.hpp"

namespace fs = std::filesystem;
using namespace globemesh::test;

namespace {

const std::string exe = GLOBEMESH_EXE;
const std::string land110 = fixture("coast/ne_110m_land.gpkg").string();
const std::string land50 = fixture("coast/ne_50m_land.gpkg").string();
const std::string shelf_dem = fixture("bathy/etopo5_nwshelf_5min.tif").string();

std::string quote(const std::string &s) {
    return globemesh::test::shell_quote(s);
}

/// Runs the executable; `err` gets its stderr (support.hpp).
int run_exe(const std::vector<std::string> &args, std::string &err, const fs::path &dir) {
    return globemesh::test::run_exe_in(exe, args, err, dir);
}

std::string run_python(const TempDir &dir, const std::string &script,
                       const std::vector<std::string> &args) {
    std::ofstream(dir / "check.py") << script;
    std::string command = "/usr/bin/python3 " + quote((dir / "check.py").string());
    for (const auto &a : args)
        command += " " + quote(a);
    std::string out;
    EXPECT_EQ(run_command(command + " 2>&1", out), 0) << out;
    return out;
}

bool python_available(const std::string &modules, const std::string &what) {
    std::string out;
    if (run_command("/usr/bin/python3 -c 'import " + modules + "' 2>&1", out) == 0)
        return true;
    tool_missing(what);
    return false;
}

// argv: UGRID, CRS, then the outputs: NAME.14, NAME.gr3, NAME.ll, NAME.msh (any may be "-").
// The nodes of each equal the UGRID lon/lat transformed by osr to 1 mm (.ll: 1e-9 degrees);
// prints "OK n".
const char *const planar_check = R"(
import sys, netCDF4, numpy as np
from osgeo import osr
nc, crs, f14, gr3, ll, msh = sys.argv[1:7]
ds = netCDF4.Dataset(nc)
ds.set_auto_mask(False)
lon, lat = ds['mesh_node_lon'][:], ds['mesh_node_lat'][:]
depth = ds['depth'][:]
src, dst = osr.SpatialReference(), osr.SpatialReference()
src.ImportFromEPSG(4326)
dst.SetFromUserInput(crs)
for s in (src, dst):
    s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
t = osr.CoordinateTransformation(src, dst)
want = np.array(t.TransformPoints(np.c_[lon, lat]))[:, :2]
assert np.ptp(want[:, 1]) > 1e5, 'metres, not degrees'

def grid(path):  # ADCIRC's grid file: title, NE NP, NP lines "id x y depth", NE lines "id 3 a b c"
    lines = open(path).read().splitlines()
    ne, np_ = map(int, lines[1].split()[:2])
    nodes = np.array([[float(v) for v in l.split()[:4]] for l in lines[2:2 + np_]])
    assert np.array_equal(nodes[:, 0], np.arange(1, np_ + 1)), 'node ids'
    return ne, nodes[:, 1:3], nodes[:, 3]

nfaces = ds['mesh_face_nodes'].shape[0]
for path in (f14, gr3):
    if path == '-':
        continue
    ne, xy, d = grid(path)
    assert ne == nfaces and len(xy) == len(lon), path
    assert np.abs(xy - want).max() < 1e-3, (path, np.abs(xy - want).max())
    assert np.allclose(d, depth), path
if ll != '-':
    ne, xy, d = grid(ll)
    assert np.abs(xy - np.c_[lon, lat]).max() < 1e-9, 'hgrid.ll is lon/lat'
if msh != '-':
    import gmsh, meshio
    gmsh.initialize()
    gmsh.option.setNumber('General.Terminal', 0)
    gmsh.open(msh)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = xyz.reshape(-1, 3)[np.argsort(tags)]
    gmsh.finalize()
    assert len(xyz) == len(lon) and np.abs(xyz[:, :2] - want).max() < 1e-3, 'gmsh nodes'
    assert np.all(xyz[:, 2] == 0)
    m = meshio.read(msh)
    assert np.abs(np.asarray(m.points)[:, :2] - want).max() < 1e-3, 'meshio nodes'
    # seamsh's way: a section $Projection holding "WKT" and the WKT, which osr reads back
    text = open(msh).read()
    section = text[text.index('$Projection\n'):text.index('$EndProjection')].splitlines()
    assert section[1] == 'WKT' and len(section) == 3, section[:2]
    back = osr.SpatialReference()
    assert back.ImportFromWkt(section[2]) == 0 and back.IsSame(dst), 'the CRS in the file'
print('OK %d' % len(lon))
)";

// argv: UGRID, CRS, what QGIS read (selafin_test's format: counts, then "x y bottom" a vertex).
// MDAL adds IPARAM(3), IPARAM(4) back; the float32 offsets from them keep 2 cm.
const char *const slf_check = R"(
import sys, netCDF4, numpy as np
from osgeo import osr
ds = netCDF4.Dataset(sys.argv[1])
lon, lat, depth = ds['mesh_node_lon'][:], ds['mesh_node_lat'][:], ds['depth'][:]
src, dst = osr.SpatialReference(), osr.SpatialReference()
src.ImportFromEPSG(4326)
dst.SetFromUserInput(sys.argv[2])
for s in (src, dst):
    s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
want = np.array(osr.CoordinateTransformation(src, dst).TransformPoints(np.c_[lon, lat]))[:, :2]
lines = open(sys.argv[3]).read().splitlines()
assert int(lines[0].split()[1]) == ds['mesh_face_nodes'].shape[0], lines[0]
v = np.array([[float(t) for t in l.split()] for l in lines[1:]])
assert v.shape[0] == lon.size
err = np.abs(v[:, :2] - want).max()
assert err < 0.02, ('SELAFIN x y', err)
assert np.array_equal(v[:, 2], np.asarray(-depth, dtype=np.float32).astype(float)), 'BOTTOM'
print('OK %d %.4f' % (v.shape[0], err))
)";

// argv: UGRID, CRS, NAME_net.nc. D-Flow FM's nodes equal the transform to 1 mm, its edge
// midpoints and face centres the means of their nodes, and its CRS variable names the CRS (read
// by osr from crs_wkt, and by QGIS/MDAL as the layer's CRS); prints "OK n".
const char *const dflow_check = R"(
import os, sys, netCDF4, numpy as np
from osgeo import osr
ds = netCDF4.Dataset(sys.argv[1]); ds.set_auto_mask(False)
lon, lat, depth = ds['mesh_node_lon'][:], ds['mesh_node_lat'][:], ds['depth'][:]
src, dst = osr.SpatialReference(), osr.SpatialReference()
src.ImportFromEPSG(4326)
dst.SetFromUserInput(sys.argv[2])
for s in (src, dst):
    s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
want = np.array(osr.CoordinateTransformation(src, dst).TransformPoints(np.c_[lon, lat]))[:, :2]
net = netCDF4.Dataset(sys.argv[3]); net.set_auto_mask(False)
xy = np.c_[net['mesh2d_node_x'][:], net['mesh2d_node_y'][:]]
assert np.abs(xy - want).max() < 1e-3, ('nodes', np.abs(xy - want).max())
assert net['mesh2d_node_x'].units == 'm' and net['mesh2d_node_x'].standard_name == 'projection_x_coordinate'
e = net['mesh2d_edge_nodes'][:] - 1
assert np.allclose(np.c_[net['mesh2d_edge_x'][:], net['mesh2d_edge_y'][:]], xy[e].mean(axis=1), rtol=0, atol=1e-6)
f = net['mesh2d_face_nodes'][:] - 1
assert np.allclose(np.c_[net['mesh2d_face_x'][:], net['mesh2d_face_y'][:]], xy[f].mean(axis=1), rtol=0, atol=1e-6)
crs = net['projected_coordinate_system']
back = osr.SpatialReference()
assert back.ImportFromWkt(crs.crs_wkt) == 0 and back.IsSame(dst), 'crs_wkt'
assert net['mesh2d_node_z'].grid_mapping == 'projected_coordinate_system'
assert np.allclose(net['mesh2d_node_z'][:], np.where(np.isnan(depth), -999, -depth))
os.environ['QT_QPA_PLATFORM'] = 'offscreen'
from qgis.core import QgsApplication, QgsMeshLayer
app = QgsApplication([], False)
app.initQgis()
layer = QgsMeshLayer(sys.argv[3], 'm', 'mdal')
assert layer.isValid() and layer.crs().authid() == 'EPSG:%d' % crs.epsg, layer.crs().authid()
print('OK %d' % len(xy))
sys.stdout.flush()
os._exit(0)
)";

const char *const qgis_reader = R"(
import os, sys
os.environ['QT_QPA_PLATFORM'] = 'offscreen'
from qgis.core import QgsApplication, QgsMeshLayer, QgsMeshDatasetIndex, QgsMesh
app = QgsApplication([], False)
app.initQgis()
layer = QgsMeshLayer(sys.argv[1], 'm', 'mdal')
dp = layer.dataProvider()
mesh = QgsMesh()
dp.populateMesh(mesh)
values = dp.datasetValues(QgsMeshDatasetIndex(0, 0), 0, dp.vertexCount())
with open(sys.argv[2], 'w') as out:
    out.write('%d %d\n' % (dp.vertexCount(), dp.faceCount()))
    for i in range(dp.vertexCount()):
        v = mesh.vertex(i)
        out.write('%r %r %r\n' % (v.x(), v.y(), values.value(i).scalar()))
os._exit(0)
)";

const std::vector<std::string> regional = {"mesh",    "--coast",  land50,       "--coast-layer",
                                           "land",    "--region", "-6,48,4,54", "--bathy",
                                           shelf_dem, "--hmax",   "30km",       "-q"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string> &more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

} // namespace

TEST(OutputSrs, regional_utm_31n_in_every_planar_format_equals_the_independent_transform) {
    if (!python_available("gmsh, meshio, netCDF4, numpy, osgeo", "python3-gmsh, -meshio, -gdal"))
        return;
    TempDir dir;
    std::string err;
    std::vector<std::string> outputs;
    for (const char *name : {"m.nc", "fort.14", "m.gr3", "m.ll", "m.msh", "m.slf", "m_net.nc"})
        outputs.insert(outputs.end(), {"-o", (dir / name).string()});
    ASSERT_EQ(
        run_exe(with(with(regional, outputs), {"--output-srs", "EPSG:32631"}), err, dir.path()), 0)
        << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string out =
        run_python(dir, planar_check,
                   {(dir / "m.nc").string(), "EPSG:32631", (dir / "fort.14").string(),
                    (dir / "m.gr3").string(), (dir / "m.ll").string(), (dir / "m.msh").string()});
    EXPECT_NE(out.find("OK "), std::string::npos) << out;
    if (!python_available("qgis.core", "QGIS (python3-qgis)"))
        return;
    const std::string net = run_python(
        dir, dflow_check, {(dir / "m.nc").string(), "EPSG:32631", (dir / "m_net.nc").string()});
    EXPECT_NE(net.find("OK "), std::string::npos) << net;
    // Read back, a projected net file is refused in one line (the readers take lon/lat).
    EXPECT_EQ(run_exe({"convert", (dir / "m_net.nc").string(), (dir / "back.nc").string()}, err,
                      dir.path()),
              1);
    EXPECT_NE(err.find("in a projected CRS"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "back.nc"));
    run_python(dir, qgis_reader, {(dir / "m.slf").string(), (dir / "qgis.txt").string()});
    const std::string slf = run_python(
        dir, slf_check, {(dir / "m.nc").string(), "EPSG:32631", (dir / "qgis.txt").string()});
    EXPECT_NE(slf.find("OK "), std::string::npos) << slf;
}

TEST(OutputSrs, convert_writes_utm_30n_from_a_proj_string_in_both_msh_versions) {
    if (!python_available("gmsh, meshio, netCDF4, numpy, osgeo", "python3-gmsh, -meshio, -gdal"))
        return;
    TempDir dir;
    std::string err;
    ASSERT_EQ(run_exe(with(regional, {"-o", (dir / "m.nc").string()}), err, dir.path()), 0) << err;
    const std::string utm30 = "+proj=utm +zone=30 +datum=WGS84 +units=m +no_defs";
    for (const std::string version : {"4.1", "2.2"}) {
        const std::string msh = (dir / ("m" + version + ".msh")).string();
        ASSERT_EQ(run_exe({"convert", "-q", (dir / "m.nc").string(), msh, (dir / "m.14").string(),
                           "--output-srs", utm30, "--msh-version", version, "--overwrite"},
                          err, dir.path()),
                  0)
            << err;
        std::ifstream head(msh);
        std::string line;
        std::getline(head, line);
        std::getline(head, line);
        EXPECT_EQ(line, version + " 0 8");
        const std::string out =
            run_python(dir, planar_check,
                       {(dir / "m.nc").string(), utm30, (dir / "m.14").string(), "-", "-", msh});
        EXPECT_NE(out.find("OK "), std::string::npos) << out;
    }
}

TEST(OutputSrs, a_global_mesh_in_a_projection_that_cannot_hold_it_is_refused_leaving_nothing) {
    TempDir dir;
    const std::vector<std::string> global = {"mesh", "--coast", land110, "--coast-layer",
                                             "land", "--hmax",  "500km", "-q"};
    struct Case {
        std::string crs, output, message;
    };
    // UTM: nodes far from its zone have no coordinates; Mercator: faces across the antimeridian
    // turn over (every node has coordinates).
    for (const Case &c :
         {Case{"EPSG:32631", "g.14",
               "node [0-9]+ at lon -?[0-9.]+, lat -?[0-9.]+ "
               "has no coordinates in --output-srs"},
          Case{"EPSG:3395", "g.msh", "cannot hold this mesh: face [0-9]+ near lon "}}) {
        std::string err;
        EXPECT_EQ(run_exe(with(global, {"-o", (dir / "g.nc").string(), "-o",
                                        (dir / c.output).string(), "--output-srs", c.crs}),
                          err, dir.path()),
                  1)
            << err;
        EXPECT_TRUE(regex_search(err, "^globemesh: .*" + c.message + "[^\n]*\n$")) << err;
        EXPECT_TRUE(fs::is_empty(dir.path())) << "a refused run leaves no file";
    }
    // The sphere whole (the Delaunay triangulation of stations round the globe) fits no plane,
    // not even the polar stereographic projection that holds the global ocean (its one singular
    // point, the South Pole, lies in Antarctica).
    std::string err;
    ASSERT_EQ(run_exe({"triangulate", "-q", fixture("points/stations.csv").string(), "-o",
                       (dir / "s.nc").string()},
                      err, dir.path()),
              0)
        << err;
    EXPECT_EQ(run_exe({"convert", "-q", (dir / "s.nc").string(), (dir / "s.msh").string(),
                       "--output-srs", "EPSG:3995"},
                      err, dir.path()),
              1);
    EXPECT_TRUE(regex_search(err, "^globemesh: [^\n]*cannot hold this mesh[^\n]*\n$")) << err;
    EXPECT_FALSE(fs::exists(dir / "s.msh"));
    EXPECT_EQ(run_exe(with(global, {"-o", (dir / "g.14").string(), "--output-srs", "EPSG:3995"}),
                      err, dir.path()),
              0)
        << err;
}

TEST(OutputSrs, usage_errors_are_one_line_and_exit_2_before_meshing) {
    TempDir dir;
    const std::string m = (dir / "m.msh").string(), nc = (dir / "m.nc").string();
    struct Case {
        std::vector<std::string> args;
        std::string message;
    };
    const std::vector<Case> cases = {
        {{"-o", m, "--output-srs", "EPSG:99999"}, "--output-srs EPSG:99999: not a CRS"},
        {{"-o", m, "--output-srs", "EPSG:4269"}, "geographic on another datum than WGS 84"},
        {{"-o", m, "--output-srs", "EPSG:4978"}, "is not a projected CRS"},
        {{"-o", nc, "-o", (dir / "m.ll").string(), "--output-srs", "EPSG:32631"},
         "applies to none of the outputs"},
        {{"-o", m, "--co", "COORDS=SPHERE", "--output-srs", "EPSG:32631"},
         "ask for two kinds of coordinates"},
        {{"-o", m, "--co", "MSH_VERSION=4.1", "--msh-version", "2.2"}, "ask for two MSH versions"},
        {{"-o", m, "--msh-version", "3"}, "--msh-version 3: use 4.1 or 2.2"},
        {{"-o", nc, "--msh-version", "2.2"},
         "none of the outputs takes the creation option MSH_VERSION"},
    };
    for (const Case &c : cases) {
        std::string err;
        EXPECT_EQ(run_exe(with(regional, c.args), err, dir.path()), 2) << err;
        EXPECT_TRUE(regex_search(err, "^globemesh: [^\n]*\n$")) << err;
        EXPECT_NE(err.find(c.message), std::string::npos) << err;
        EXPECT_TRUE(fs::is_empty(dir.path()));
    }
}
