// The gmsh .msh output through the globemesh executable, read back by gmsh's own Python API
// (python3-gmsh) and by meshio (python3-meshio), and compared with the UGRID file of the same run
// read by netCDF4: node and triangle counts, coordinates, the boundary lines (node pairs) per
// physical group, and the depth. Skipped where a reader is absent (a failure under CI=true).
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

bool readers_available() {
    std::string out;
    if (run_command("/usr/bin/python3 -c 'import gmsh, meshio, netCDF4, numpy'", out) == 0)
        return true;
    tool_missing("gmsh's and meshio's Python modules (python3-gmsh, python3-meshio)");
    return false;
}

// Compares MSH (argv[1]) with UGRID (argv[2]); argv[3] is "lonlat" or the sphere's radius.
// Prints "OK coast=N open=M" or fails with the difference.
const char *const check_script = R"(
import sys, gmsh, meshio, netCDF4, numpy as np
msh, nc, coords = sys.argv[1], sys.argv[2], sys.argv[3]
ds = netCDF4.Dataset(nc)
ds.set_auto_mask(False)
lon, lat = ds['mesh_node_lon'][:], ds['mesh_node_lat'][:]
faces = ds['mesh_face_nodes']
nfaces = faces.shape[0]
edges = ds['mesh_edge_nodes'][:] - int(getattr(ds['mesh_edge_nodes'], 'start_index', 0))
tag = ds['boundary_tag'][:]
want = {name: set(map(tuple, np.sort(edges[tag == t], axis=1))) for name, t in (('coast', 1), ('open', 2))}
depth = ds['depth'][:] if 'depth' in ds.variables else None

def check_points(xyz):
    if coords.startswith('lonlat'):
        # The same longitudes, or 360 more (a region across 180 is written in [0, 360)).
        d = (xyz[:, 0] - lon + 180) % 360 - 180
        assert np.allclose(d, 0, atol=1e-9) and np.allclose(xyz[:, 1], lat, atol=1e-9), 'lon/lat'
        assert np.all(xyz[:, 2] == 0), 'z'
    else:
        r = float(coords)
        assert np.allclose(np.linalg.norm(xyz, axis=1), r, rtol=1e-12), 'radius'
        assert np.allclose(np.degrees(np.arcsin(xyz[:, 2] / r)), lat, atol=1e-7), 'lat'
        d = (np.degrees(np.arctan2(xyz[:, 1], xyz[:, 0])) - lon + 180) % 360 - 180
        assert np.allclose(d[np.abs(lat) < 89.9], 0, atol=1e-7), 'lon'

# gmsh's own reader
gmsh.initialize()
gmsh.option.setNumber('General.Terminal', 0)
gmsh.open(msh)
tags, xyz, _ = gmsh.model.mesh.getNodes()
order = np.argsort(tags)
assert len(tags) == len(lon), ('gmsh nodes', len(tags), len(lon))
check_points(xyz.reshape(-1, 3)[order])
groups = {}
for dim, ptag in gmsh.model.getPhysicalGroups():
    name = gmsh.model.getPhysicalName(dim, ptag)
    elems = []
    for e in gmsh.model.getEntitiesForPhysicalGroup(dim, ptag):
        types, _, nodes = gmsh.model.mesh.getElements(dim, e)
        for t, n in zip(types, nodes):
            k = 3 if t == 2 else 2
            assert t == (2 if dim == 2 else 1), ('element type', name, t)
            elems.append(np.asarray(n, dtype=np.int64).reshape(-1, k) - 1)
    groups[name] = (dim, np.concatenate(elems))
assert groups['ocean'][0] == 2 and len(groups['ocean'][1]) == nfaces, ('ocean', nfaces)
if coords == 'lonlat-ccw':  # every triangle counter-clockwise in the file's own x, y
    p = xyz.reshape(-1, 3)[order][groups['ocean'][1]]
    area = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - \
           (p[:, 2, 0] - p[:, 0, 0]) * (p[:, 1, 1] - p[:, 0, 1])
    assert (area > 0).all(), ('clockwise triangles', int((area <= 0).sum()))
for name, pairs in want.items():
    got = set(map(tuple, np.sort(groups[name][1], axis=1))) if name in groups else set()
    assert (name not in groups) == (len(pairs) == 0), ('group present', name)
    assert name not in groups or groups[name][0] == 1, ('dim', name)
    assert got == pairs, (name, len(got), len(pairs))
assert set(groups) <= {'ocean', 'coast', 'open'}, groups.keys()
views = gmsh.view.getTags()
if depth is None:
    assert len(views) == 0, 'depth without a bathymetry'
else:
    assert gmsh.option.getString('View[0].Name') == 'depth', 'view name'
    _, ntags, data, _, ncomp = gmsh.view.getModelData(views[0], 0)
    got = np.zeros(len(lon))
    got[np.asarray(ntags) - 1] = np.asarray(data).ravel()
    assert ncomp == 1 and len(ntags) == len(lon) and np.allclose(got, depth), 'gmsh depth'
gmsh.finalize()

# meshio
m = meshio.read(msh)
check_points(np.asarray(m.points))
assert len(m.points) == len(lon)
count = {}
for block, phys in zip(m.cells, m.cell_data['gmsh:physical']):
    for p in np.unique(phys):
        count[(block.type, int(p))] = count.get((block.type, int(p)), 0) + int(np.sum(phys == p))
names = {name: int(v[0]) for name, v in m.field_data.items()}
assert count.get(('triangle', names['ocean'])) == nfaces, count
for name, pairs in want.items():
    assert count.get(('line', names.get(name, -1)), 0) == len(pairs), (name, count)
assert sum(len(b.data) for b in m.cells if b.type == 'line') == int(np.sum(tag != 0)), 'lines'
if depth is not None:
    assert np.allclose(m.point_data['depth'], depth), 'meshio depth'
print('OK coast=%d open=%d' % (len(want['coast']), len(want['open'])))
)";

/// Runs the check on `msh` against `nc`; returns its one line.
std::string check(const fs::path &msh, const fs::path &nc, const std::string &coords,
                  const fs::path &dir) {
    std::ofstream(dir / "check.py") << check_script;
    std::string out;
    const int status =
        run_command("/usr/bin/python3 " + quote((dir / "check.py").string()) + " " +
                        quote(msh.string()) + " " + quote(nc.string()) + " " + coords,
                    out);
    EXPECT_EQ(status, 0) << out;
    return out;
}

const std::vector<std::string> regional = {
    "mesh",     "--coast",      land50,    "--coast-layer", "land",
    "--region", "-12,46,13,62", "--bathy", shelf_dem,       "--hmax",
    "60km",     "--hmin",       "10km",    "--coast-size",  "15km"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string> &more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
}

} // namespace

TEST(GmshE2e, regional_41_and_22_read_back_as_the_ugrid_file_says) {
    if (!readers_available())
        return;
    TempDir dir;
    std::string err;
    ASSERT_EQ(
        run_exe(with(regional, {"-o", (dir / "r.nc").string(), "-o", (dir / "r.msh").string()}),
                err, dir.path()),
        0)
        << err;
    expect_mesh_verify(dir / "r.nc");
    std::ifstream head(dir / "r.msh");
    std::string line;
    std::getline(head, line);
    std::getline(head, line);
    EXPECT_EQ(line, "4.1 0 8");
    const std::string out = check(dir / "r.msh", dir / "r.nc", "lonlat", dir.path());
    EXPECT_NE(out.find("OK coast="), std::string::npos) << out;
    EXPECT_EQ(out.find("open=0"), std::string::npos) << out; // a region has open edges

    ASSERT_EQ(run_exe(with(regional, {"-o", (dir / "s.nc").string(), "-o", (dir / "s.msh").string(),
                                      "--co", "MSH_VERSION=2.2"}),
                      err, dir.path()),
              0)
        << err;
    std::ifstream head22(dir / "s.msh");
    std::getline(head22, line);
    std::getline(head22, line);
    EXPECT_EQ(line, "2.2 0 8");
    EXPECT_EQ(check(dir / "s.msh", dir / "s.nc", "lonlat", dir.path()), out);
}

// A region across 180 (W > E), and one ending at 180: the lon/lat of MSH are the other model
// formats' (longitudes in [0, 360) where that spares every face a cut at the seam). They were
// in [-180, 180): faces spanning 350 degrees, clockwise in the file's x, y (124 of 3,980 at
// GSHHG low 170,-50,-170,-30 at 50 km), and a region ending at 180 had its east edge at -180.
TEST(GmshE2e, a_region_across_or_up_to_180_has_every_triangle_counter_clockwise) {
    if (!readers_available())
        return;
    TempDir dir;
    for (const std::string box : {"170,-50,-170,-30", "170,-50,180,-30"}) {
        SCOPED_TRACE(box);
        std::string err;
        ASSERT_EQ(run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", box,
                           "--hmax", "60km", "-o", (dir / "r.nc").string(), "-o",
                           (dir / "r.msh").string(), "--overwrite"},
                          err, dir.path()),
                  0)
            << err;
        const std::string out = check(dir / "r.msh", dir / "r.nc", "lonlat-ccw", dir.path());
        EXPECT_NE(out.find("OK coast="), std::string::npos) << out;
    }
}

TEST(GmshE2e, global_on_the_sphere_has_no_open_group_in_either_version) {
    if (!readers_available())
        return;
    TempDir dir;
    const std::vector<std::string> global = {"mesh",   "--coast", land110,  "--coast-layer", "land",
                                             "--hmax", "400km",   "--hmin", "100km"};
    for (const std::string version : {"4.1", "2.2"}) {
        const fs::path nc = dir / ("g" + version + ".nc"), msh = dir / ("g" + version + ".msh");
        std::string err;
        ASSERT_EQ(run_exe(with(global, {"-o", nc.string(), "-o", msh.string(), "--co",
                                        "MSH_VERSION=" + version, "--co", "coords=sphere", "--co",
                                        "RADIUS=6371000"}),
                          err, dir.path()),
                  0)
            << err;
        expect_mesh_verify(nc);
        const std::string out = check(msh, nc, "6371000", dir.path());
        EXPECT_NE(out.find("OK coast="), std::string::npos) << version << ": " << out;
        EXPECT_NE(out.find(" open=0"), std::string::npos) << version << ": " << out;
    }
}

TEST(GmshE2e, refusals_are_one_line_and_leave_no_file) {
    TempDir dir;
    struct Case {
        std::vector<std::string> extra;
        int status;
        std::string says;
    };
    const std::vector<Case> cases = {
        {{"-o", (dir / "no" / "x.msh").string()}, 1, "x.msh"},
        {{"-o", (dir / "x.msh").string(), "--co", "MSH_VERSION=3"}, 2, "MSH_VERSION=4.1 or 2.2"},
        {{"-o", (dir / "x.msh").string(), "--co", "COORDS=SPHERE", "--co", "RADIUS=-1"},
         2,
         "RADIUS=-1"},
        {{"-o", (dir / "x.msh").string(), "--co", "RADIUS=6371000"}, 2, "COORDS=SPHERE"},
    };
    for (const auto &c : cases) {
        std::string err;
        EXPECT_EQ(run_exe(with(regional, with(c.extra, {"--quiet"})), err, dir.path()), c.status)
            << err;
        EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
        EXPECT_NE(err.find(c.says), std::string::npos) << err;
        EXPECT_TRUE(fs::is_empty(dir.path())) << err;
    }
}

// argv: MSH written with OPEN_GROUPS=YES, the fort.14 and the UGRID file of the same run. Each
// group open_k holds the edges of the k-th open string of the fort.14 (read here from ADCIRC's
// documentation of the boundary section), per gmsh's API and per meshio; no group "open"; the
// groups together are the UGRID file's open edges. Prints "OK groups=K".
const char *const open_groups_script = R"(
import sys, gmsh, meshio, netCDF4, numpy as np
msh, f14, nc = sys.argv[1:4]
lines = [l.split('!')[0].split() for l in open(f14).read().splitlines()]
ne, np_ = map(int, lines[1][:2])
at = 2 + ne + np_
nope = int(lines[at][0]); at += 2
strings = []
for _ in range(nope):
    count = int(lines[at][0])
    nodes = [int(lines[at + 1 + i][0]) - 1 for i in range(count)]
    strings.append({tuple(sorted(p)) for p in zip(nodes[:-1], nodes[1:])})
    at += 1 + count
ds = netCDF4.Dataset(nc)
edges = ds['mesh_edge_nodes'][:] - int(getattr(ds['mesh_edge_nodes'], 'start_index', 0))
open_edges = set(map(tuple, np.sort(edges[ds['boundary_tag'][:] == 2], axis=1)))
assert set().union(*strings) == open_edges and sum(map(len, strings)) == len(open_edges), 'fort.14'

gmsh.initialize()
gmsh.option.setNumber('General.Terminal', 0)
gmsh.open(msh)
groups = {}
for dim, ptag in gmsh.model.getPhysicalGroups(1):
    pairs = set()
    for e in gmsh.model.getEntitiesForPhysicalGroup(dim, ptag):
        for t, n in zip(*gmsh.model.mesh.getElements(dim, e)[::2]):
            pairs |= set(map(tuple, np.sort(np.asarray(n, dtype=np.int64).reshape(-1, 2) - 1, axis=1)))
    groups[gmsh.model.getPhysicalName(dim, ptag)] = (ptag, pairs)
gmsh.finalize()
assert 'open' not in groups, groups.keys()
assert sorted(k for k in groups if k != 'coast') == sorted('open_%d' % (k + 1) for k in range(nope))
for k, pairs in enumerate(strings):
    assert groups['open_%d' % (k + 1)] == (4 + k, pairs), ('gmsh', k + 1)

m = meshio.read(msh)
names = {name: int(v[0]) for name, v in m.field_data.items()}
for k, pairs in enumerate(strings):
    got = set()
    for block, phys in zip(m.cells, m.cell_data['gmsh:physical']):
        if block.type == 'line':
            got |= set(map(tuple, np.sort(block.data[phys == names['open_%d' % (k + 1)]], axis=1)))
    assert got == pairs, ('meshio', k + 1)
print('OK groups=%d' % nope)
)";

TEST(GmshE2e, open_groups_are_the_adcirc_open_strings_in_both_versions) {
    if (!readers_available())
        return;
    TempDir dir;
    std::ofstream(dir / "groups.py") << open_groups_script;
    for (const std::string version : {"4.1", "2.2"}) {
        const fs::path nc = dir / (version + ".nc"), msh = dir / (version + ".msh"),
                       f14 = dir / (version + ".14");
        std::string err, out;
        ASSERT_EQ(run_exe(with(regional, {"-o", nc.string(), "-o", msh.string(), "-o", f14.string(),
                                          "--co", "OPEN_GROUPS=YES", "--msh-version", version}),
                          err, dir.path()),
                  0)
            << err;
        EXPECT_EQ(run_command("/usr/bin/python3 " + quote((dir / "groups.py").string()) + " " +
                                  quote(msh.string()) + " " + quote(f14.string()) + " " +
                                  quote(nc.string()) + " 2>&1",
                              out),
                  0)
            << out;
        std::vector<std::string> groups;
        ASSERT_TRUE(regex_search(out, "OK groups=([0-9]+)", &groups)) << out;
        EXPECT_GE(std::stoi(groups[1]), 2) << "the region has several open boundaries";
    }
}
