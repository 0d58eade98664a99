// TELEMAC SELAFIN (.slf) and boundary conditions (.cli) outputs, read back two ways and compared
// with the UGRID file of the same run (netCDF4): by QGIS/MDAL's SELAFIN driver (node and face
// counts, node positions, the BOTTOM dataset), and by a reader written here from the format's
// description (big-endian Fortran records: title; NBV1 NBV2; names; IPARAM, a date record when
// IPARAM(10) = 1; NELEM NPOIN NDP 1; IKLE; IPOBO; X; Y; per time step the time and each
// variable), which also reads the .cli (LIHBOR LIUBOR LIVBOR HBOR UBOR VBOR AUBOR LITBOR TBOR
// ATBOR BTBOR N K per boundary node; 2 2 2 a solid wall, 5 4 4 prescribed elevation).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
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

std::string quote(const std::string &s) {
    return globemesh::test::shell_quote(s);
}

/// Runs the executable; `err` gets its stderr (support.hpp).
int run_exe(const std::vector<std::string> &args, std::string &err, const fs::path &dir) {
    return globemesh::test::run_exe_in(exe, args, err, dir);
}

/// The reader from the format description, and the comparison; prints "OK nptfr open" or fails.
const std::string checker = R"(
import struct, sys, netCDF4, numpy as np

def records(path):
    data, at, out = open(path, 'rb').read(), 0, []
    while at < len(data):
        n, = struct.unpack('>i', data[at:at + 4])
        body = data[at + 4:at + 4 + n]
        end, = struct.unpack('>i', data[at + 4 + n:at + 8 + n])
        assert end == n and len(body) == n, ('record framing', at)
        out.append(body)
        at += n + 8
    return out

def read_slf(path):
    r = iter(records(path))
    title = next(r); assert len(title) == 80 and title[72:] in (b'SERAFIN ', b'SERAFIND'), title
    real = '>f8' if title[72:] == b'SERAFIND' else '>f4'  # every real record in that type
    nbv1, nbv2 = struct.unpack('>2i', next(r))
    names = [next(r) for _ in range(nbv1 + nbv2)]
    iparam = struct.unpack('>10i', next(r))
    if iparam[9] == 1:
        next(r)
    nelem, npoin, ndp, one = struct.unpack('>4i', next(r))
    assert ndp == 3 and one == 1, (ndp, one)
    ikle = np.frombuffer(next(r), '>i4').reshape(nelem, 3)
    ipobo = np.frombuffer(next(r), '>i4')
    x, y = np.frombuffer(next(r), real), np.frombuffer(next(r), real)
    steps = []
    for time in r:
        assert len(time) == np.dtype(real).itemsize and np.frombuffer(time, real)[0] == 0
        steps.append([np.frombuffer(next(r), real) for _ in range(nbv1)])
    assert ipobo.size == npoin and x.size == npoin and len(steps) == 1, (ipobo.size, len(steps))
    return names, ikle, ipobo, x, y, steps[0], real

def read_cli(path):
    rows = [l.split() for l in open(path).read().splitlines()]
    assert all(len(v) == 13 for v in rows), 'a .cli line without 13 values'
    return [(' '.join(v[0:3]), int(v[7]), int(v[11]), int(v[12])) for v in rows]

nc = netCDF4.Dataset(sys.argv[1])
lon, lat = nc['mesh_node_lon'][:], nc['mesh_node_lat'][:]
faces = nc['mesh_face_nodes'][:] - nc['mesh_face_nodes'].start_index
depth = np.asarray(nc['depth'][:], dtype=float)
en = nc['mesh_edge_nodes'][:] - nc['mesh_edge_nodes'].start_index
tag = nc['boundary_tag'][:]  # on edges: 0 interior, 1 coast, 2 open
names, ikle, ipobo, x, y, (bottom,), real = read_slf(sys.argv[2])
assert names == [b'BOTTOM          M               '], names
assert np.array_equal(ikle - 1, faces), 'IKLE is not the faces'
# float32 keeps lon/lat to about 1e-5 degrees; SERAFIND has the UGRID file's doubles exactly.
tol = 1e-4 if real == '>f4' else 0
assert np.abs((x - lon + 180) % 360 - 180).max() <= tol and np.abs(y - lat).max() <= tol
assert np.array_equal(bottom, (-depth).astype(real)), 'BOTTOM is not minus the depth'
# IPOBO numbers exactly the nodes of the boundary edges, 1 .. NPTFR once each.
on_boundary = set(en[tag > 0].ravel())
nptfr = len(on_boundary)
assert set(np.nonzero(ipobo)[0]) == on_boundary, 'IPOBO is not the boundary nodes'
assert sorted(ipobo[ipobo > 0]) == list(range(1, nptfr + 1)), 'IPOBO is not 1..NPTFR'
cli = read_cli(sys.argv[3])
assert [k for _, _, _, k in cli] == list(range(1, nptfr + 1)), 'K is not the boundary numbering'
assert all(ipobo[n - 1] == k for _, _, n, k in cli), 'N and K disagree with IPOBO'
open_nodes = set(en[tag == 2].ravel())
assert {n - 1 for c, lit, n, k in cli if c == '5 4 4' and lit == 4} == open_nodes, 'open nodes'
assert {n - 1 for c, lit, n, k in cli if c == '2 2 2' and lit == 2} == on_boundary - open_nodes
# In boundary order, each boundary edge with the mesh on its left (as its face runs) goes from
# boundary number k to k + 1, except the one closing each loop.
numbers = np.zeros(lon.size, dtype=np.int64)
for _, _, n, k in cli:
    numbers[n - 1] = k
edge_set = {(min(a, b), max(a, b)) for a, b in en[tag > 0]}
jumps = 0
for f in faces:
    for a, b in zip(f, np.roll(f, -1)):
        if (min(a, b), max(a, b)) in edge_set and numbers[b] != numbers[a] + 1:
            jumps += 1
parent = list(range(lon.size))
def root(v):
    while parent[v] != v:
        parent[v] = parent[parent[v]]
        v = parent[v]
    return v
for a, b in edge_set:
    parent[root(a)] = root(b)
loops = len({root(v) for v in on_boundary})
assert jumps == loops, ('boundary order', jumps, loops)
print('OK %d %d' % (nptfr, len(open_nodes)))
)";

/// What QGIS (MDAL's SELAFIN driver) reads: counts, then each vertex's x y and dataset value.
const std::string qgis_reader = R"(
import os, sys
os.environ['QT_QPA_PLATFORM'] = 'offscreen'
from qgis.core import QgsApplication, QgsMeshLayer, QgsMeshDatasetIndex, QgsMesh
app = QgsApplication([], False)
app.initQgis()
layer = QgsMeshLayer(sys.argv[1], 'm', 'mdal')
dp = layer.dataProvider()
print('VALID', layer.isValid(), dp.vertexCount(), dp.faceCount(), dp.datasetGroupCount(), flush=True)
mesh = QgsMesh()
dp.populateMesh(mesh)
values = dp.datasetValues(QgsMeshDatasetIndex(0, 0), 0, dp.vertexCount())
with open(sys.argv[2], 'w') as out:
    out.write('%d %d %s\n' % (dp.vertexCount(), dp.faceCount(), dp.datasetGroupMetadata(0).name()))
    for i in range(dp.vertexCount()):
        v = mesh.vertex(i)
        out.write('%r %r %r\n' % (v.x(), v.y(), values.value(i).scalar()))
os._exit(0)
)";

/// Compares what QGIS read with the UGRID file: prints "SAME n" or fails.
const std::string qgis_compare = R"(
import sys, netCDF4, numpy as np
nc = netCDF4.Dataset(sys.argv[1])
lines = open(sys.argv[2]).read().splitlines()
nodes, faces, name = lines[0].split()[:3]
assert name.lower() == 'bottom', lines[0]
assert int(faces) == nc['mesh_face_nodes'].shape[0], (faces, nc['mesh_face_nodes'].shape)
assert int(nodes) == nc['mesh_node_lon'].size, nodes
v = np.array([[float(t) for t in l.split()] for l in lines[1:]])
lon, lat, depth = nc['mesh_node_lon'][:], nc['mesh_node_lat'][:], nc['depth'][:]
assert v.shape[0] == lon.size
# A double precision (SERAFIND) file as the UGRID file's doubles, through repr's 17 digits.
real, tol = (np.float64, 0) if sys.argv[3:] == ['double'] else (np.float32, 1e-4)
assert np.abs((v[:, 0] - lon + 180) % 360 - 180).max() <= tol and np.abs(v[:, 1] - lat).max() <= tol
assert np.array_equal(v[:, 2], np.asarray(-depth, dtype=real).astype(float)), 'BOTTOM'
print('SAME %d' % v.shape[0])
)";

std::string run_python(const TempDir &dir, const std::string &name, const std::string &script,
                       const std::vector<fs::path> &args) {
    std::ofstream(dir / name) << script;
    std::string command = "/usr/bin/python3 " + quote((dir / name).string());
    for (const auto &a : args)
        command += " " + quote(a.string());
    std::string out;
    EXPECT_EQ(run_command(command + " 2>&1", out), 0) << out;
    return out;
}

bool qgis_available() {
    std::string out;
    return run_command("/usr/bin/python3 -c 'import qgis.core' 2>&1", out) == 0;
}

/// Meshes with `args` into dir/m.nc and dir/m.slf (double precision when asked), checks both
/// readers; returns the verdict.
std::string mesh_and_check(const TempDir &dir, std::vector<std::string> args,
                           bool double_precision = false) {
    args.insert(args.begin(), "mesh");
    for (const char *out : {"m.nc", "m.slf"})
        args.insert(args.end(), {"-o", (dir / out).string()});
    if (double_precision)
        args.insert(args.end(), {"--co", "PRECISION=DOUBLE"});
    args.push_back("-q");
    std::string err;
    EXPECT_EQ(run_exe(args, err, dir.path()), 0) << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string verdict =
        run_python(dir, "check.py", checker, {dir / "m.nc", dir / "m.slf", dir / "m.cli"});
    if (!qgis_available()) {
        globemesh::test::tool_missing("QGIS (python3-qgis)");
        return verdict;
    }
    const std::string seen =
        run_python(dir, "read_in_qgis.py", qgis_reader, {dir / "m.slf", dir / "qgis.txt"});
    EXPECT_NE(seen.find("VALID True"), std::string::npos) << seen;
    std::vector<fs::path> compared{dir / "m.nc", dir / "qgis.txt"};
    if (double_precision)
        compared.push_back("double");
    const std::string same = run_python(dir, "compare.py", qgis_compare, compared);
    EXPECT_EQ(same.rfind("SAME ", 0), 0u) << same;
    return verdict + seen;
}

} // namespace

TEST(Selafin, a_regional_slf_and_cli_match_the_ugrid_file_with_open_and_coast_nodes) {
    TempDir dir;
    const std::string verdict =
        mesh_and_check(dir, {"--coast", fixture("coast/ne_50m_land.gpkg").string(), "--coast-layer",
                             "land", "--region", "-12,46,13,62", "--bathy",
                             fixture("bathy/etopo5_nwshelf_5min.tif").string(), "--hmax", "60km",
                             "--hmin", "10km", "--coast-size", "15km"});
    std::vector<std::string> groups;
    ASSERT_TRUE(globemesh::test::regex_match(verdict.substr(0, verdict.find('\n') + 1),
                                             "OK (\\d+) (\\d+)\n", &groups))
        << verdict;
    EXPECT_GT(std::stoi(groups[2]), 0); // open nodes
}

// PRECISION=DOUBLE: a SERAFIND file, read by the reader here and by MDAL with the UGRID file's
// node positions and depths exactly (float32 rounds lon/lat by up to about 1e-5 degrees, a metre).
TEST(Selafin, a_double_precision_slf_has_the_ugrid_files_coordinates_exactly) {
    TempDir dir;
    const std::string verdict = mesh_and_check(
        dir,
        {"--coast", fixture("coast/ne_50m_land.gpkg").string(), "--coast-layer", "land", "--region",
         "-12,46,13,62", "--bathy", fixture("bathy/etopo5_nwshelf_5min.tif").string(), "--hmax",
         "60km", "--hmin", "10km"},
        true);
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
    std::ifstream slf(dir / "m.slf", std::ios::binary);
    std::string head(84, ' ');
    slf.read(head.data(), 84);
    EXPECT_EQ(head.substr(76, 8), "SERAFIND");
}

TEST(Selafin, a_global_slf_has_only_solid_boundary_nodes) {
    TempDir dir;
    const std::string verdict = mesh_and_check(
        dir, {"--coast", fixture("coast/ne_110m_land.gpkg").string(), "--coast-layer", "land",
              "--bathy", fixture("bathy/etopo5_global_10min.nc").string(), "--hmax", "400km"});
    std::vector<std::string> groups;
    ASSERT_TRUE(globemesh::test::regex_match(verdict.substr(0, verdict.find('\n') + 1),
                                             "OK (\\d+) 0\n", &groups))
        << verdict;
}

TEST(Selafin, an_unwritable_slf_is_one_line_and_leaves_no_file) {
    TempDir dir;
    std::string err;
    const fs::path missing = dir / "no-such-folder" / "m.slf";
    const int status = run_exe({"mesh", "--coast", fixture("coast/ne_110m_land.gpkg").string(),
                                "--coast-layer", "land", "--hmax", "800km", "-o",
                                (dir / "m.nc").string(), "-o", missing.string(), "-q"},
                               err, dir.path());
    EXPECT_NE(status, 0);
    EXPECT_NE(err.find(missing.string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

// The .cli is part of the output: an existing one (without --overwrite) stops the run, and
// neither the .slf nor the other outputs appear.
TEST(Selafin, an_existing_cli_is_refused_and_no_output_appears) {
    TempDir dir;
    std::ofstream(dir / "m.cli") << "kept\n";
    std::string err;
    const int status = run_exe({"mesh", "--coast", fixture("coast/ne_110m_land.gpkg").string(),
                                "--coast-layer", "land", "--hmax", "800km", "-o",
                                (dir / "m.nc").string(), "-o", (dir / "m.slf").string(), "-q"},
                               err, dir.path());
    EXPECT_NE(status, 0);
    EXPECT_NE(err.find((dir / "m.cli").string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(dir / "m.slf"));
    EXPECT_FALSE(fs::exists(dir / "m.nc"));
    std::ifstream kept(dir / "m.cli");
    std::string line;
    std::getline(kept, line);
    EXPECT_EQ(line, "kept");
}
