// D-Flow FM net file (`_net.nc`) output, read back two ways and compared with the UGRID file of
// the same run: by netCDF4 against the layout D-Flow FM reads (Deltares' UGRID flavour: mesh2d,
// 1-based mesh2d_edge_nodes and mesh2d_face_nodes, mesh2d_node_z the bed level positive up,
// mesh2d_edge_type 1 internal / 2 open / 3 closed, the wgs84 CRS variable, netCDF classic), with
// the edges and the boundary derived here from the faces; and by QGIS/MDAL's UGRID driver, which
// shows mesh2d_node_z as "Bed Elevation" as it does for D-Flow FM's own files.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::run_command;
using globemesh::test::TempDir;

namespace {

const std::string exe = GLOBEMESH_EXE;

/// Runs the words (each quoted) through the shell, `redirect` applied; `out` gets what it shows
/// (run_command: its standard output and error).
int run(const std::vector<std::string> &words, std::string &out, const char *redirect = "") {
    std::string command;
    for (const auto &w : words)
        command += "'" + w + "' ";
    return run_command("( " + command + redirect + " )", out);
}

/// Runs the executable with `args`; `err` gets its standard error.
int run_globemesh(std::vector<std::string> args, std::string &err) {
    args.insert(args.begin(), exe);
    return run(args, err, ">/dev/null");
}

/// The net file against the UGRID file (argv 1, 2); prints "OK nodes faces edges open coast".
const std::string checker = R"(
import sys, netCDF4, numpy as np
u, d = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
d.set_auto_mask(False)
assert d.file_format.startswith('NETCDF3'), d.file_format
assert d.Conventions.split() == ['CF-1.8', 'UGRID-1.0', 'Deltares-0.10'], d.Conventions
m = d['mesh2d']
assert m.cf_role == 'mesh_topology' and m.topology_dimension == 2
assert m.node_coordinates == 'mesh2d_node_x mesh2d_node_y'
assert (m.edge_node_connectivity, m.face_node_connectivity) == ('mesh2d_edge_nodes', 'mesh2d_face_nodes')
assert d['wgs84'].epsg == 4326 and int(d['wgs84'][...]) == 4326
nn, nf, ne = (d.dimensions['mesh2d_n' + k].size for k in ('Nodes', 'Faces', 'Edges'))
assert (nn, nf, ne) == tuple(u.dimensions['nMesh_' + k].size for k in ('node', 'face', 'edge'))
fv, ev = d['mesh2d_face_nodes'], d['mesh2d_edge_nodes']
assert fv.start_index == 1 and ev.start_index == 1
fn, en = fv[:] - 1, ev[:] - 1
assert np.array_equal(fn, u['mesh_face_nodes'][:])
x, y = d['mesh2d_node_x'][:], d['mesh2d_node_y'][:]
assert np.abs((x - u['mesh_node_lon'][:] + 180) % 360 - 180).max() < 1e-9
assert np.abs(y - u['mesh_node_lat'][:]).max() < 1e-9
# The bed level is minus the depth (positive up); D-Flow FM's missing value where there is none.
z = d['mesh2d_node_z']
assert z.positive == 'up' and z.standard_name == 'altitude'
depth = np.ma.filled(u['depth'][:].astype(float), np.nan)
have = ~np.isnan(depth)
assert np.array_equal(z[:] == z._FillValue, ~have)
assert np.array_equal(z[:][have], -depth[have])
# Every side of every face is one edge; the sides of one face only are the boundary.
sides = np.sort(np.concatenate([fn[:, [0, 1]], fn[:, [1, 2]], fn[:, [2, 0]]]), axis=1)
keys, uses = np.unique(sides[:, 0] * nn + sides[:, 1], return_counts=True)
ek = np.sort(en, axis=1)
ek = ek[:, 0] * nn + ek[:, 1]
assert np.array_equal(np.sort(ek), keys), 'edges'
t = d['mesh2d_edge_type'][:]
assert set(np.unique(t)) <= {1, 2, 3}
assert np.array_equal(np.sort(ek[t >= 2]), keys[uses == 1]), 'boundary edges'
ue = np.sort(u['mesh_edge_nodes'][:], axis=1)
uk, tag = ue[:, 0] * nn + ue[:, 1], u['boundary_tag'][:]
assert set(ek[t == 2]) == set(uk[tag == 2]), 'open edges'
assert set(ek[t == 3]) == set(uk[tag == 1]), 'coast edges'
# Faces counter-clockwise (those not across the antimeridian, in lon/lat).
px, py = x[fn], y[fn]
area = ((px[:, 1] - px[:, 0]) * (py[:, 2] - py[:, 0]) - (px[:, 2] - px[:, 0]) * (py[:, 1] - py[:, 0]))
plain = (px.max(axis=1) - px.min(axis=1) < 90) & (np.abs(py).max(axis=1) < 85)
assert plain.sum() > 0.9 * nf and (area[plain] > 0).all(), 'orientation'
print('OK %d %d %d %d %d' % (nn, nf, ne, (t == 2).sum(), (t == 3).sum()))
)";

/// What QGIS (MDAL's UGRID driver) reads of the net file, compared with the UGRID file: prints
/// "SAME vertices faces" or fails.
const std::string qgis_reader = R"(
import os, sys, netCDF4, numpy as np
os.environ['QT_QPA_PLATFORM'] = 'offscreen'
from qgis.core import QgsApplication, QgsMeshLayer, QgsMeshDatasetIndex, QgsMesh
app = QgsApplication([], False)
app.initQgis()
layer = QgsMeshLayer(sys.argv[2], 'm', 'mdal')
dp = layer.dataProvider()
assert layer.isValid() and dp.driverMetadata().name() == 'Ugrid', 'not read'
u = netCDF4.Dataset(sys.argv[1])
lon, lat, depth = u['mesh_node_lon'][:], u['mesh_node_lat'][:], u['depth'][:]
depth = np.ma.filled(depth.astype(float), np.nan)
assert dp.vertexCount() == lon.size and dp.faceCount() == u['mesh_face_nodes'].shape[0]
assert layer.crs().authid() == 'EPSG:4326', layer.crs().authid()
groups = [dp.datasetGroupMetadata(g).name() for g in range(dp.datasetGroupCount())]
g = groups.index('Bed Elevation')
mesh = QgsMesh()
dp.populateMesh(mesh)
values = dp.datasetValues(QgsMeshDatasetIndex(g, 0), 0, dp.vertexCount())
v = np.array([[mesh.vertex(i).x(), mesh.vertex(i).y(), values.value(i).scalar()]
              for i in range(dp.vertexCount())])
assert np.abs((v[:, 0] - lon + 180) % 360 - 180).max() < 1e-9 and np.abs(v[:, 1] - lat).max() < 1e-9
have = ~np.isnan(depth)
assert np.array_equal(v[have, 2], -depth[have]), 'Bed Elevation'
assert np.isnan(v[~have, 2]).all() or (v[~have, 2] == -999).all()
print('SAME %d %d' % (dp.vertexCount(), dp.faceCount()), flush=True)
os._exit(0)
)";

/// A UGRID file against the one it was converted from through a net file (argv 1, 2): the same
/// nodes, faces, depths and boundary tags, and no coordinate read as a field; prints "ROUND".
const std::string round_trip = R"(
import sys, netCDF4, numpy as np
a, b = netCDF4.Dataset(sys.argv[1]), netCDF4.Dataset(sys.argv[2])
assert np.array_equal(a['mesh_face_nodes'][:], b['mesh_face_nodes'][:])
for k in ('lon', 'lat'):
    d = a['mesh_node_' + k][:] - b['mesh_node_' + k][:]
    assert np.abs((d + 180) % 360 - 180).max() < 1e-9, k
da, db = (np.ma.filled(f['depth'][:].astype(float), np.nan) for f in (a, b))
assert np.array_equal(da, db, equal_nan=True), 'depth'
assert np.array_equal(a['mesh_edge_nodes'][:], b['mesh_edge_nodes'][:])
assert np.array_equal(a['boundary_tag'][:], b['boundary_tag'][:]), 'boundary tags'
fields = [v for v in b.variables if getattr(b[v], 'location', '') in ('node', 'face')]
assert not [v for v in fields if v.endswith(('_x', '_y'))], fields
print('ROUND %d' % (b['boundary_tag'][:] == 2).sum())
)";

/// Runs `script` (saved as dir/name) with `args`; returns what it printed, failing on an error.
std::string python(const TempDir &dir, const std::string &name, const std::string &script,
                   const std::vector<fs::path> &args) {
    std::ofstream(dir / name) << script;
    std::vector<std::string> words = {"/usr/bin/python3", (dir / name).string()};
    for (const auto &a : args)
        words.push_back(a.string());
    std::string out;
    EXPECT_EQ(run(words, out), 0) << out;
    return out;
}

bool qgis_available() {
    std::string out;
    return run({"/usr/bin/python3", "-c", "import qgis.core"}, out) == 0;
}

/// Checks dir/net against the UGRID file dir/ugrid with both readers; returns the checker's
/// counts: nodes, faces, edges, open edges, coast edges.
std::vector<int> check(const TempDir &dir, const std::string &ugrid, const std::string &net) {
    expect_mesh_verify(dir / net);
    const std::string verdict = python(dir, "check.py", checker, {dir / ugrid, dir / net});
    std::vector<std::string> groups;
    EXPECT_TRUE(
        globemesh::test::regex_search(verdict, "OK (\\d+) (\\d+) (\\d+) (\\d+) (\\d+)\n", &groups))
        << verdict;
    if (!qgis_available()) {
        globemesh::test::tool_missing("QGIS (python3-qgis)");
    } else {
        const std::string seen =
            python(dir, "read_in_qgis.py", qgis_reader, {dir / ugrid, dir / net});
        EXPECT_NE(seen.find("SAME "), std::string::npos) << seen;
    }
    std::vector<int> counts;
    for (std::size_t i = 1; i < groups.size(); ++i)
        counts.push_back(std::stoi(groups[i]));
    return counts;
}

/// Meshes with `args` into dir/m.nc and dir/m_net.nc (one run); checks the net file.
std::vector<int> mesh_and_check(const TempDir &dir, std::vector<std::string> args) {
    args.insert(args.begin(), "mesh");
    for (const char *out : {"m_net.nc", "m.nc"})
        args.insert(args.end(), {"-o", (dir / out).string()});
    args.push_back("-q");
    std::string err;
    EXPECT_EQ(run_globemesh(args, err), 0) << err;
    expect_mesh_verify(dir / "m.nc");
    return check(dir, "m.nc", "m_net.nc");
}

std::vector<std::string> regional_run() {
    return {"--coast",       fixture("coast/ne_50m_land.gpkg").string(),
            "--coast-layer", "land",
            "--region",      "-12,46,13,62",
            "--bathy",       fixture("bathy/etopo5_nwshelf_5min.tif").string(),
            "--hmax",        "60km",
            "--hmin",        "10km"};
}

} // namespace

TEST(DflowFM, a_regional_net_file_matches_the_ugrid_file_of_the_run_with_open_and_coast_edges) {
    TempDir dir;
    const std::vector<int> counts = mesh_and_check(dir, regional_run());
    ASSERT_EQ(counts.size(), 5u);
    EXPECT_GT(counts[3], 0); // open
    EXPECT_GT(counts[4], 0); // coast
}

TEST(DflowFM, a_global_net_file_has_no_open_edge) {
    TempDir dir;
    const std::vector<int> counts = mesh_and_check(
        dir, {"--coast", fixture("coast/ne_110m_land.gpkg").string(), "--coast-layer", "land",
              "--bathy", fixture("bathy/etopo5_global_10min.nc").string(), "--hmax", "400km"});
    ASSERT_EQ(counts.size(), 5u);
    EXPECT_EQ(counts[3], 0);
    EXPECT_GT(counts[4], 0);
}

TEST(DflowFM, convert_writes_a_ugrid_file_as_a_net_file_chosen_by_its_name_in_any_case) {
    TempDir dir;
    std::vector<std::string> args = regional_run();
    args.insert(args.begin(), "mesh");
    args.insert(args.end(), {"-o", (dir / "m.nc").string(), "-q"});
    std::string err;
    ASSERT_EQ(run_globemesh(args, err), 0) << err;
    ASSERT_EQ(
        run_globemesh({"convert", "-q", (dir / "m.nc").string(), (dir / "c_NET.nc").string()}, err),
        0)
        << err;
    const std::vector<int> counts = check(dir, "m.nc", "c_NET.nc");
    ASSERT_EQ(counts.size(), 5u);
    EXPECT_GT(counts[3], 0);
}

TEST(DflowFM, an_unwritable_net_file_is_one_line_and_leaves_no_file) {
    TempDir dir;
    std::string err;
    const fs::path missing = dir / "no-such-folder" / "m_net.nc";
    const int status = run_globemesh(
        {"mesh", "--coast", fixture("coast/ne_110m_land.gpkg").string(), "--coast-layer", "land",
         "--hmax", "800km", "-o", (dir / "m.nc").string(), "-o", missing.string(), "-q"},
        err);
    EXPECT_EQ(status, 1);
    EXPECT_NE(err.find(missing.string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(DflowFM, a_net_file_converts_back_to_the_same_ugrid_mesh_with_its_open_boundary) {
    TempDir dir;
    mesh_and_check(dir, regional_run());
    std::string err;
    ASSERT_EQ(run_globemesh(
                  {"convert", "-q", (dir / "m_net.nc").string(), (dir / "back.nc").string()}, err),
              0)
        << err;
    const std::string same = python(dir, "round.py", round_trip, {dir / "m.nc", dir / "back.nc"});
    EXPECT_EQ(same.rfind("ROUND ", 0), 0u) << same;
    EXPECT_EQ(same.find("ROUND 0\n"), std::string::npos) << same;
}
