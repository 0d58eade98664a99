// `globemesh convert` through the executable: a regional UGRID mesh of the test's run converted to
// gmsh (read back by gmsh's Python API and meshio), to fort.14 (read by a reader written here
// from ADCIRC's documentation) and to UGRID, and fort.14 back to UGRID; another tool's 1-based
// layout (made here with netCDF4: other names, (nodes, faces) order with a fill column, depth as
// altitude) with and without boundary tags; and the refusals. Every comparison is with the source
// read by netCDF4.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "support.hpp"

namespace fs = std::filesystem;
using namespace globemesh::test;

namespace {

const std::string exe = GLOBEMESH_EXE;

std::string quote(const std::string &s) {
    return "'" + s + "'";
}

/// Runs the executable in `dir`; `err` gets stderr.
int run_exe(const std::vector<std::string> &args, std::string &err, const fs::path &dir) {
    std::string command = quote(exe);
    for (const auto &a : args)
        command += " " + quote(a);
    std::string out;
    const int status =
        run_command("( cd " + quote(dir.string()) + " && " + command + " >/dev/null 2>.err )", out);
    std::ifstream e(dir / ".err");
    err.assign(std::istreambuf_iterator<char>(e), {});
    fs::remove(dir / ".err");
    return status;
}

// Modes: one-based SRC DST tags|none; same SRC OUT [coast]; msh SRC MSH; fort14 SRC FORT14.
const char *const check_script = R"(
import sys, netCDF4, numpy as np

def ugrid(path):
    """Nodes, faces (0-based), boundary edges by tag and depth of a UGRID file, read with netCDF4."""
    ds = netCDF4.Dataset(path)
    ds.set_auto_mask(False)
    topo = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
    x, y = (ds[n][:] for n in topo.node_coordinates.split())
    if getattr(ds[topo.node_coordinates.split()[0]], 'standard_name', '') == 'latitude':
        x, y = y, x
    fv = ds[topo.face_node_connectivity]
    f = fv[:].astype(np.int64)
    if fv.dimensions[0] != getattr(topo, 'face_dimension', fv.dimensions[0]):
        f = f.T
    fill = getattr(fv, '_FillValue', None)
    f = f[:, :3] - int(getattr(fv, 'start_index', 0))
    if fill is not None:
        assert np.all(fv[:][:, 3:] == fill) if f.shape[1] > 3 else True
    tags = {1: set(), 2: set()}
    name = topo.name
    bt = [v for v in ds.variables.values() if v.name == 'boundary_tag' and getattr(v, 'mesh', '') == name]
    if bt:
        ev = ds[topo.edge_node_connectivity]
        e = ev[:].astype(np.int64) - int(getattr(ev, 'start_index', 0))
        t = bt[0][:]
        for k in (1, 2):
            tags[k] = set(map(tuple, np.sort(e[t == k], axis=1)))
    depth = None
    for v in ds.variables.values():
        if getattr(v, 'mesh', '') == name and getattr(v, 'location', '') == 'node':
            sn = getattr(v, 'standard_name', '')
            if v.name == 'depth' or sn.startswith('sea_floor_depth'):
                depth = v[:].astype(float)
            elif sn == 'altitude' and depth is None:
                depth = -v[:].astype(float)
    return np.asarray(x, float), np.asarray(y, float), f, tags, depth

def boundary(f):
    """Edges of one face (sorted node pairs)."""
    e = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    u, n = np.unique(e, axis=0, return_counts=True)
    return set(map(tuple, u[n == 1]))

def same_mesh(a, b, coast_only=False):
    assert np.allclose(a[0], b[0], rtol=0, atol=1e-11) and np.allclose(a[1], b[1], rtol=0, atol=1e-11), 'nodes'
    assert np.array_equal(a[2], b[2]), 'faces'
    want = {1: a[3][1] | a[3][2], 2: set()} if coast_only else a[3]
    assert b[3] == want, ('tags', len(b[3][1]), len(b[3][2]), len(want[1]), len(want[2]))
    assert a[4] is not None and b[4] is not None and np.array_equal(a[4], b[4]), 'depth'

def make_one_based(src, dst, with_tags):
    """Another tool's layout: 1-based, (nodes-per-face, faces) order with a 4th fill column,
    other names, depth as altitude (positive up)."""
    x, y, f, tags, depth = ugrid(src)
    ds = netCDF4.Dataset(dst, 'w', format='NETCDF4_CLASSIC')
    ds.createDimension('nNodes', len(x)); ds.createDimension('nFaces', len(f)); ds.createDimension('nMax', 4)
    m = ds.createVariable('Mesh2', 'i4'); m.cf_role = 'mesh_topology'; m.topology_dimension = 2
    m.node_coordinates = 'Mesh2_node_y Mesh2_node_x'; m.face_node_connectivity = 'Mesh2_face_nodes'
    m.face_dimension = 'nFaces'
    for n, sn, v in (('Mesh2_node_y', 'latitude', y), ('Mesh2_node_x', 'longitude', x)):
        c = ds.createVariable(n, 'f8', ('nNodes',)); c.standard_name = sn; c[:] = v
    c = ds.createVariable('Mesh2_face_nodes', 'i4', ('nMax', 'nFaces'), fill_value=-999)
    c.cf_role = 'face_node_connectivity'; c.start_index = 1
    full = np.full((len(f), 4), -999); full[:, :3] = f + 1
    c[:] = full.T
    z = ds.createVariable('Mesh2_node_z', 'f8', ('nNodes',)); z.mesh = 'Mesh2'; z.location = 'node'
    z.standard_name = 'altitude'; z[:] = -depth
    if with_tags:
        e = np.array(sorted(tags[1]) + sorted(tags[2])) if tags[1] | tags[2] else np.zeros((0, 2), int)
        ds.createDimension('nEdges', len(e)); ds.createDimension('Two', 2)
        m.edge_node_connectivity = 'Mesh2_edge_nodes'; m.edge_dimension = 'nEdges'
        c = ds.createVariable('Mesh2_edge_nodes', 'i4', ('nEdges', 'Two')); c.start_index = 1; c[:] = e + 1
        t = ds.createVariable('boundary_tag', 'i1', ('nEdges',)); t.mesh = 'Mesh2'; t.location = 'edge'
        t[:] = [1] * len(tags[1]) + [2] * len(tags[2])
    ds.close()

def check_msh(src, msh):
    import gmsh, meshio
    x, y, f, tags, depth = ugrid(src)
    gmsh.initialize(); gmsh.option.setNumber('General.Terminal', 0); gmsh.open(msh)
    nt, xyz, _ = gmsh.model.mesh.getNodes()
    xyz = xyz.reshape(-1, 3)[np.argsort(nt)]
    assert len(nt) == len(x) and np.allclose(xyz[:, 0], x, atol=1e-9) and np.allclose(xyz[:, 1], y, atol=1e-9), 'gmsh nodes'
    groups = {}
    for dim, p in gmsh.model.getPhysicalGroups():
        el = []
        for ent in gmsh.model.getEntitiesForPhysicalGroup(dim, p):
            _, _, nodes = gmsh.model.mesh.getElements(dim, ent)
            el += [np.asarray(n, np.int64).reshape(-1, dim + 1) - 1 for n in nodes]
        groups[gmsh.model.getPhysicalName(dim, p)] = np.concatenate(el)
    gmsh.finalize()
    got = set(map(tuple, np.sort(groups['ocean'], axis=1)))
    assert got == set(map(tuple, np.sort(f, axis=1))) and len(groups['ocean']) == len(f), 'gmsh faces'
    for name, k in (('coast', 1), ('open', 2)):
        g = set(map(tuple, np.sort(groups[name], axis=1))) if name in groups else set()
        assert g == tags[k], ('gmsh', name, len(g), len(tags[k]))
    m = meshio.read(msh)
    assert np.allclose(m.points[:, :2], np.c_[x, y], atol=1e-9), 'meshio nodes'
    tri = np.concatenate([b.data for b in m.cells if b.type == 'triangle'])
    assert np.array_equal(np.sort(tri, axis=1), np.sort(f, axis=1)), 'meshio faces'
    assert np.allclose(m.point_data['depth'], depth), 'meshio depth'
    print('OK coast=%d open=%d' % (len(tags[1]), len(tags[2])))

def check_fort14(src, path):
    """ADCIRC grid file as its documentation lays it out: title; NE NP; NP node lines; NE element
    lines; NOPE, NETA, per open string NVDLL then its nodes; NBOU, NVEL, per land string NVELL
    IBTYPE then its nodes."""
    x, y, f, tags, depth = ugrid(src)
    lines = open(path).read().splitlines()
    ne, np_ = map(int, lines[1].split()[:2])
    assert (ne, np_) == (len(f), len(x)), 'counts'
    nodes = np.array([l.split()[:4] for l in lines[2:2 + np_]], float)
    assert np.array_equal(nodes[:, 0], np.arange(1, np_ + 1)), 'node ids'
    assert np.allclose(nodes[:, 1], x, atol=1e-7) and np.allclose(nodes[:, 2], y, atol=1e-7), 'node positions'
    assert np.allclose(nodes[:, 3], depth, atol=1e-3), 'depth'
    el = np.array([l.split()[:5] for l in lines[2 + np_:2 + np_ + ne]], np.int64)
    assert np.all(el[:, 1] == 3) and np.array_equal(el[:, 2:] - 1, f), 'elements'
    rows = iter([l.split('!')[0].split() for l in lines[2 + np_ + ne:]])
    def strings():
        # count line, total nodes line, then per string a line "n [IBTYPE]" and n node lines
        count = int(next(rows)[0]); next(rows)
        edges = set()
        for _ in range(count):
            s = [int(next(rows)[0]) - 1 for _ in range(int(next(rows)[0]))]
            edges |= {tuple(sorted(p)) for p in zip(s, s[1:])}
        return count, edges
    nope, open_edges = strings()
    nbou, land_edges = strings()
    assert tags[2] <= open_edges and (nope >= 1) == bool(tags[2]), ('open', nope)
    assert tags[1] <= land_edges, 'coast'
    print('OK nope=%d nbou=%d' % (nope, nbou))

mode = sys.argv[1]
if mode == 'one-based':
    make_one_based(sys.argv[2], sys.argv[3], sys.argv[4] == 'tags')
elif mode == 'same':
    same_mesh(ugrid(sys.argv[2]), ugrid(sys.argv[3]), len(sys.argv) > 4)
    print('OK')
elif mode == 'msh':
    check_msh(sys.argv[2], sys.argv[3])
elif mode == 'fort14':
    check_fort14(sys.argv[2], sys.argv[3])
)";

/// Runs the check script with `args` in `dir`; returns its output, "OK..." when it passed.
std::string check(const std::string &args, const fs::path &dir) {
    std::ofstream(dir / "check.py") << check_script;
    std::string out;
    run_command("cd " + quote(dir.string()) + " && /usr/bin/python3 check.py " + args + " 2>&1",
                out);
    return out;
}

bool readers_available() {
    std::string out;
    if (run_command("/usr/bin/python3 -c 'import gmsh, meshio, netCDF4, numpy'", out) == 0)
        return true;
    tool_missing("gmsh's and meshio's Python modules (python3-gmsh, python3-meshio)");
    return false;
}

/// A regional mesh with open boundaries and depths (North-West European shelf), as r.nc in `dir`.
void regional_mesh(const fs::path &dir) {
    std::string err;
    ASSERT_EQ(run_exe({"mesh", "--coast", fixture("coast/ne_50m_land.gpkg").string(),
                       "--coast-layer", "land", "--region", "-12,46,13,62", "--bathy",
                       fixture("bathy/etopo5_nwshelf_5min.tif").string(), "--hmax", "60km",
                       "--hmin", "10km", "--coast-size", "15km", "-q", "-o", "r.nc"},
                      err, dir),
              0)
        << err;
}

} // namespace

TEST(ConvertE2e, ugrid_to_msh_fort14_and_ugrid_keep_nodes_faces_tags_and_depth) {
    if (!readers_available())
        return;
    TempDir dir;
    ASSERT_NO_FATAL_FAILURE(regional_mesh(dir.path()));
    std::string err;
    ASSERT_EQ(run_exe({"convert", "r.nc", "c.msh", "fort.14", "-o", "c.nc", "-q"}, err, dir.path()),
              0)
        << err;
    const std::string msh = check("msh r.nc c.msh", dir.path());
    EXPECT_NE(msh.find("OK coast=1"), std::string::npos) << msh; // gmsh may print an empty line
    EXPECT_EQ(msh.find("open=0"), std::string::npos) << msh;
    const std::string fort = check("fort14 r.nc fort.14", dir.path());
    EXPECT_EQ(fort.rfind("OK nope=", 0), 0u) << fort;
    EXPECT_EQ(fort.find("nope=0"), std::string::npos) << fort; // a region has open strings
    EXPECT_EQ(check("same r.nc c.nc", dir.path()), "OK\n");
    expect_mesh_verify(dir / "c.nc");
    // Back from fort.14 (its strings as tags), and from a fort.14 without the boundary section
    // (as oceanmesh writes it): every boundary edge coast.
    ASSERT_EQ(run_exe({"convert", "fort.14", "back.nc", "-q"}, err, dir.path()), 0) << err;
    EXPECT_EQ(check("same r.nc back.nc", dir.path()), "OK\n");
    std::string out;
    ASSERT_EQ(
        run_command("cd " + quote(dir.path().string()) +
                        " && awk 'NR == 2 { n = $1 + $2 + 2 } NR < 3 || NR <= n' fort.14 > bare.14",
                    out),
        0);
    ASSERT_EQ(run_exe({"convert", "bare.14", "bare.nc", "-q"}, err, dir.path()), 0) << err;
    EXPECT_EQ(check("same r.nc bare.nc coast", dir.path()), "OK\n");
    // MSH 2.2 by --co, as `mesh` takes it.
    ASSERT_EQ(run_exe({"convert", "r.nc", "-o", "v.msh", "--co", "MSH_VERSION=2.2", "-q"}, err,
                      dir.path()),
              0)
        << err;
    std::ifstream head(dir / "v.msh");
    std::string line;
    std::getline(head, line);
    std::getline(head, line);
    EXPECT_EQ(line, "2.2 0 8");
    EXPECT_NE(check("msh r.nc v.msh", dir.path()).find("OK coast="), std::string::npos);
    // Back from gmsh, 4.1 and 2.2, from points on a sphere (COORDS=SPHERE) and with one group per
    // open boundary (OPEN_GROUPS=YES): the same nodes, faces, tags and depth.
    for (const char *co : {"COORDS=SPHERE", "OPEN_GROUPS=YES"})
        ASSERT_EQ(run_exe({"convert", "r.nc", "-o", std::string(co).substr(0, 4) + ".msh", "--co",
                           co, "-q"},
                          err, dir.path()),
                  0)
            << err;
    for (const std::string m : {"c.msh", "v.msh", "COOR.msh", "OPEN.msh"}) {
        ASSERT_EQ(run_exe({"convert", m, m + ".nc", "-q"}, err, dir.path()), 0) << err;
        EXPECT_EQ(check("same r.nc " + m + ".nc", dir.path()), "OK\n") << m;
    }
}

// A mesh gmsh itself made (its Python API: a lon/lat rectangle, physical groups "open" on its
// west side and "coast" on the others, "ocean" on the surface), in MSH 4.1 and 2.2, converts to
// UGRID with gmsh's node and triangle counts and its open lines as open boundary edges.
TEST(ConvertE2e, a_mesh_gmsh_made_converts_with_its_physical_groups) {
    if (!readers_available())
        return;
    TempDir dir;
    std::ofstream(dir / "made.py") << R"(
import sys, gmsh, netCDF4, numpy as np
version, binary, msh = sys.argv[1], int(sys.argv[2]), sys.argv[3]
gmsh.initialize(); gmsh.option.setNumber('General.Terminal', 0)
gmsh.option.setNumber('Mesh.MshFileVersion', float(version))
gmsh.option.setNumber('Mesh.Binary', binary)
occ = gmsh.model.geo
p = [occ.addPoint(x, y, 0, 0.4) for x, y in ((0, 50), (4, 50), (4, 53), (0, 53))]
l = [occ.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]
s = occ.addPlaneSurface([occ.addCurveLoop(l)]); occ.synchronize()
for dim, tags, tag, name in ((1, l[:3], 1, 'coast'), (1, [l[3]], 2, 'open'), (2, [s], 3, 'ocean')):
    gmsh.model.addPhysicalGroup(dim, tags, tag); gmsh.model.setPhysicalName(dim, tag, name)
gmsh.model.mesh.generate(2); gmsh.write(msh)
nt, xyz, _ = gmsh.model.mesh.getNodes()
tris = sum(len(t) for t in gmsh.model.mesh.getElements(2, s)[1])
opens = sum(len(t) for t in gmsh.model.mesh.getElements(1, l[3])[1])
# A depth view saved with its mesh ($NodeData "depth"): 100 m + 10 m per degree north.
v = gmsh.view.add('depth')
gmsh.view.addModelData(v, 0, gmsh.model.getCurrent(), 'NodeData', list(nt),
                       [[100.0 + 10 * xyz[3 * i + 1]] for i in range(len(nt))])
gmsh.option.setNumber('PostProcessing.SaveMesh', 1)
gmsh.view.write(v, 'depth_' + msh)
print(len(nt), tris, opens)
)";
    std::ofstream(dir / "read.py") << R"(
import sys, netCDF4, numpy as np
ds = netCDF4.Dataset(sys.argv[1]); ds.set_auto_mask(False)
topo = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
x = ds[topo.node_coordinates.split()[0]][:]
f = ds[topo.face_node_connectivity][:]
t = ds['boundary_tag'][:]
if len(sys.argv) > 2:  # the depth file's: gmsh's values at the nodes' latitudes
    lat = ds[topo.node_coordinates.split()[1]][:]
    assert np.abs(ds['depth'][:] - (100 + 10 * lat)).max() < 1e-9, 'depth'
print(len(x), len(f), int((t == 2).sum()))
)";
    // ASCII and binary (Mesh.Binary 1: gmsh -bin), with gmsh's numbers as ints, size_t, doubles.
    for (const std::string version : {"4.1", "2.2"})
        for (const std::string binary : {"0", "1"}) {
            SCOPED_TRACE(version + " binary " + binary);
            const std::string msh = "g" + version + "_" + binary + ".msh", nc = msh + ".nc";
            std::string made, read, err;
            ASSERT_EQ(run_command("cd " + quote(dir.path().string()) +
                                      " && /usr/bin/python3 made.py " + version + " " + binary +
                                      " " + msh,
                                  made),
                      0)
                << made;
            ASSERT_EQ(run_exe({"convert", msh, nc, "-q"}, err, dir.path()), 0) << err;
            ASSERT_EQ(run_exe({"convert", "depth_" + msh, "depth_" + nc, "-q"}, err, dir.path()), 0)
                << err;
            ASSERT_EQ(run_command("cd " + quote(dir.path().string()) +
                                      " && /usr/bin/python3 read.py depth_" + nc + " depth",
                                  read),
                      0)
                << read;
            ASSERT_EQ(run_command("cd " + quote(dir.path().string()) +
                                      " && /usr/bin/python3 read.py " + nc,
                                  read),
                      0)
                << read;
            // gmsh's counts (the last line it printed) equal the converted file's.
            made = made.substr(made.rfind('\n', made.size() - 2) + 1);
            EXPECT_EQ(read, made);
            // gmsh's mesh is Delaunay in the lon/lat plane, not on the sphere: a few edges fail
            // the spherical test; everything else must hold.
            expect_mesh_verify(dir / nc, "--allow-nondelaunay 20");
        }
}

TEST(ConvertE2e, another_tools_one_based_file_converts_with_its_tags_or_all_coast_without) {
    if (!readers_available())
        return;
    TempDir dir;
    ASSERT_NO_FATAL_FAILURE(regional_mesh(dir.path()));
    ASSERT_EQ(check("one-based r.nc o1.nc tags", dir.path()), "");
    ASSERT_EQ(check("one-based r.nc o0.nc none", dir.path()), "");
    std::string err;
    ASSERT_EQ(run_exe({"convert", "o1.nc", "o1c.nc", "o1.msh", "-q"}, err, dir.path()), 0) << err;
    EXPECT_EQ(check("same r.nc o1c.nc", dir.path()), "OK\n");
    EXPECT_NE(check("msh r.nc o1.msh", dir.path()).find("OK coast="), std::string::npos);
    expect_mesh_verify(dir / "o1c.nc");
    // Without boundary_tag every boundary edge (the source's coast and open ones) is coast.
    ASSERT_EQ(run_exe({"convert", "o0.nc", "o0c.nc", "-q"}, err, dir.path()), 0) << err;
    EXPECT_EQ(check("same r.nc o0c.nc coast", dir.path()), "OK\n");
    EXPECT_NE(check("same r.nc o0c.nc", dir.path()), "OK\n"); // the check tells the two apart
}

TEST(ConvertE2e, refusals_are_one_line_and_leave_no_file) {
    TempDir dir;
    std::ofstream(dir / "text.nc") << "not netcdf\n";
    std::ofstream(dir / "bad.14") << "title\n2 x\n";
    std::ofstream(dir / "binary.msh") << "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n";
    std::ofstream(dir / "text.msh") << "not a mesh\n";
    // As globemesh and seamsh write a projected mesh: the CRS's WKT in a $Projection section.
    std::ofstream(dir / "utm.msh") << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Projection\nWKT\n"
                                      "PROJCS[\"WGS 84 / UTM zone 31N\"]\n$EndProjection\n";
    std::ofstream(dir / "quads.msh") << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n"
                                        "1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n"
                                        "$Elements\n1\n1 3 0 1 2 3 4\n$EndElements\n";
    const std::string etopo = fixture("bathy/etopo5_global_10min.nc").string();
    std::string err;
    ASSERT_EQ(run_exe({"triangulate", fixture("points/stations.csv").string(), "-o", "m.nc", "-q"},
                      err, dir.path()),
              0)
        << err;
    struct Case {
        std::vector<std::string> args;
        int status;
        std::string says;
    };
    const Case cases[] = {
        {{"convert", "missing.nc", "out.msh"}, 1, "does not exist"},
        {{"convert", "text.nc", "out.msh"}, 1, "cannot open"},
        {{"convert", etopo, "out.msh"}, 1, "not a UGRID mesh"},
        {{"convert", "bad.14", "out.msh"}, 1, "line 2: NP 'x' is not an integer"},
        {{"convert", "binary.msh", "out.nc"}, 1, "line 2: a binary file's int 1 does not follow"},
        {{"convert", "text.msh", "out.nc"}, 1, "not a gmsh MSH file"},
        {{"convert", "quads.msh", "out.nc"}, 1, "element type 3 is not read"},
        {{"convert", "utm.msh", "out.nc"}, 1, "projected CRS ($Projection)"},
        {{"convert", "m.nc", "out.xyz"}, 2, "no format has the extension .xyz"},
        {{"convert", "m.nc", "-f", "NOSUCH", "-o", "out.msh"}, 2, "no such format"},
        {{"convert", "m.nc"}, 2, "give the file to write"},
        {{"convert", "m.nc", "out.msh", "m.nc", "--overwrite"}, 2, "is the IN file"},
    };
    for (const auto &c : cases) {
        EXPECT_EQ(run_exe(c.args, err, dir.path()), c.status) << c.args[1] << ": " << err;
        EXPECT_NE(err.find(c.says), std::string::npos) << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
        EXPECT_FALSE(fs::exists(dir / "out.msh") || fs::exists(dir / "out.xyz") ||
                     fs::exists(dir / "out.nc"))
            << c.args[1];
    }
}
