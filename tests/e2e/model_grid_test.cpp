// ADCIRC fort.14 and SCHISM hgrid.gr3 / hgrid.ll outputs, read back by a reader written here from
// ADCIRC's description of the grid and boundary information file (AGRID; NE NP; NP lines
// JN X Y DP; NE lines JE NHY NM1 NM2 NM3; NOPE, NETA, per open segment NVDLL [IBTYPEE] and NVDLL
// node lines; NBOU, NVEL, per land segment NVELL IBTYPE and NVELL node lines; the values of a
// line first, anything after them ignored), and compared with the UGRID file of the same run read
// by netCDF4.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "support.hpp"
#include "unit/io_test_meshes.hpp"

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

/// The reader and the comparison: prints "OK nope nbou" or fails (non-zero status, the reason).
const std::string checker = R"(
import sys, netCDF4, numpy as np

def read_grid(path):
    """fort.14 / hgrid.gr3 as ADCIRC documents it; each line's leading values, the rest ignored."""
    lines = iter(open(path).read().split('\n'))
    values = lambda: next(lines).split()
    title = next(lines)
    ne, np_ = (int(v) for v in values()[:2])
    xyz = np.empty((np_, 3))
    for k in range(np_):
        v = values()
        assert int(v[0]) == k + 1, ('node id', k, v)
        xyz[k] = [float(t) for t in v[1:4]]
    elems = np.empty((ne, 3), dtype=np.int64)
    for k in range(ne):
        v = values()
        assert int(v[0]) == k + 1 and int(v[1]) == 3, ('element', k, v)
        elems[k] = [int(t) for t in v[2:5]]
    def strings(with_type):
        count, total = int(values()[0]), int(values()[0])
        out = []
        for k in range(count):
            v = values()
            n, kind = int(v[0]), (int(v[1]) if with_type else None)
            out.append((kind, [int(values()[0]) for _ in range(n)]))
        assert sum(len(s) for _, s in out) == total, ('node total', total)
        return out
    opens = strings(False)
    lands = strings(True)
    assert all(l.strip() == '' for l in lines), 'text after the land boundaries'
    return xyz, elems, opens, lands

def check(grid, ugrid, regional):
    nc = netCDF4.Dataset(ugrid)
    lon, lat = nc['mesh_node_lon'][:], nc['mesh_node_lat'][:]
    faces = nc['mesh_face_nodes'][:] - nc['mesh_face_nodes'].start_index
    depth = nc['depth'][:]
    en = nc['mesh_edge_nodes'][:] - nc['mesh_edge_nodes'].start_index
    tag = nc['boundary_tag'][:]  # on edges: 0 interior, 1 coast, 2 open
    xyz, elems, opens, lands = read_grid(grid)
    assert xyz.shape[0] == lon.size and elems.shape[0] == faces.shape[0], (xyz.shape, elems.shape)
    dlon = (xyz[:, 0] - lon + 180) % 360 - 180
    assert np.abs(dlon).max() < 1e-9 and np.abs(xyz[:, 1] - lat).max() < 1e-9
    assert np.array_equal(xyz[:, 2], np.asarray(depth, dtype=float)), 'depths'
    assert np.array_equal(elems - 1, faces), 'elements'
    # Counter-clockwise in x, y: every element of a region; on the globe those not cut by the
    # antimeridian (a longitude span under 180 degrees).
    x, y = xyz[elems - 1, 0], xyz[elems - 1, 1]
    area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    uncut = np.ptp(x, axis=1) < 180
    assert regional == bool(uncut.all()), uncut.sum()
    assert (area[uncut] > 0).all(), (area[uncut] <= 0).sum()
    edge = lambda a, b: (min(a, b), max(a, b))
    want = {t: sorted(edge(a + 1, b + 1) for (a, b), g in zip(en, tag) if g == t) for t in (1, 2)}
    steps = lambda strs: sorted(edge(a, b) for _, s in strs for a, b in zip(s, s[1:]))
    assert steps(opens) == want[2], 'open strings are not the open edges'
    assert steps(lands) == want[1], 'land strings do not cover each coast edge once'
    for kind, s in lands:
        assert kind in (0, 1), kind
        assert kind == 0 or s[0] == s[-1], 'an island string is not closed'
    ends = {s[0] for _, s in opens} | {s[-1] for _, s in opens}
    land_ends = {s[0] for k, s in lands if s[0] != s[-1]} | {s[-1] for k, s in lands if s[0] != s[-1]}
    assert ends == land_ends, 'open and land runs do not meet end to end'
    mainland = sum(k == 0 for k, s in lands if s[0] == s[-1])
    assert regional or mainland == 1, mainland
    if regional:
        assert len(opens) >= 1
    else:
        assert len(opens) == 0, len(opens)
    return len(opens), len(lands)

def islands_in_the_plane(grid, crs):
    """Closed land strings of a planar grid (or of a lon/lat one projected to crs by GDAL) turn as
    ADCIRC orders them (mesh on the left): outer boundaries (IBTYPE 0) counter-clockwise, islands
    (1) clockwise. Returns the islands."""
    xyz, _, _, lands = read_grid(grid)
    if crs:
        from osgeo import osr
        wgs84, to = osr.SpatialReference(), osr.SpatialReference()
        wgs84.ImportFromEPSG(4326)
        to.SetFromUserInput(crs)
        for s in (wgs84, to):
            s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        xyz[:, :2] = np.array(osr.CoordinateTransformation(wgs84, to).TransformPoints(xyz[:, :2]))[:, :2]
    islands = 0
    for kind, s in lands:
        if s[0] != s[-1]:
            continue
        x, y = xyz[np.array(s) - 1, 0], xyz[np.array(s) - 1, 1]
        area = np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]) / 2
        assert (area < 0) == (kind == 1), ('closed string of', len(s), 'IBTYPE', kind, area)
        islands += kind == 1
    return islands

if sys.argv[2].startswith('planar'):  # 'planar' or 'planar:CRS'
    print('OK islands %d' % islands_in_the_plane(sys.argv[3], sys.argv[2][len('planar:'):]))
    sys.exit(0)
ugrid, regional = sys.argv[1], sys.argv[2] == 'regional'
counts = {check(g, ugrid, regional) for g in sys.argv[3:]}
assert len(counts) == 1, counts
print('OK %d %d' % counts.pop())
)";

/// Runs the checker on the UGRID file and the grid files; returns its output.
std::string check_grids(const TempDir &dir, const std::string &kind,
                        const std::vector<std::string> &grids) {
    const fs::path script = dir / "check.py";
    std::ofstream(script) << checker;
    std::string command = "/usr/bin/python3 " + quote(script.string()) + " " +
                          quote((dir / "m.nc").string()) + " " + kind;
    for (const auto &g : grids)
        command += " " + quote((dir / g).string());
    std::string out;
    EXPECT_EQ(run_command(command, out), 0) << out;
    return out;
}

/// Meshes NE 1:110m land at 400 km with `options` (a region, an --output-srs) into m.nc and
/// fort.14; returns the checker's verdict on how the closed strings turn in the file's plane, or
/// in `crs` (a lon/lat file's nodes projected there by GDAL).
std::string planar_islands(const TempDir &dir, const std::vector<std::string> &options,
                           const std::string &crs = "") {
    std::vector<std::string> args = {"mesh",
                                     "--coast",
                                     fixture("coast/ne_110m_land.gpkg").string(),
                                     "--coast-layer",
                                     "land",
                                     "--hmax",
                                     "400km",
                                     "-o",
                                     (dir / "m.nc").string(),
                                     "-o",
                                     (dir / "fort.14").string(),
                                     "-q"};
    args.insert(args.end(), options.begin(), options.end());
    std::string err;
    EXPECT_EQ(run_exe(args, err, dir.path()), 0) << err;
    return check_grids(dir, crs.empty() ? "planar" : "planar:" + crs, {"fort.14"});
}

/// The whitespace-separated leading numbers of each line of a file (what follows "!" dropped).
std::vector<std::vector<double>> number_lines(const fs::path &file) {
    std::ifstream in(file);
    std::string line;
    std::getline(in, line); // the title
    std::vector<std::vector<double>> rows;
    while (std::getline(in, line)) {
        std::istringstream s(line.substr(0, line.find('!')));
        rows.emplace_back();
        for (double v; s >> v;)
            rows.back().push_back(v);
    }
    return rows;
}

void write_adcirc(const globemesh::Mesh &mesh, const fs::path &file) {
    const globemesh::OutputRequest request{
        globemesh::find_writer(globemesh::writers(), "ADCIRC"), file, {}};
    globemesh::write_outputs(mesh, {&request, 1}, {});
}

} // namespace

// A cap across the antimeridian, all open: longitudes in [0, 360) so that no element is cut,
// every element counter-clockwise there, one open string closed on itself and no land.
TEST(ModelGrid, a_region_across_the_antimeridian_is_written_in_0_to_360) {
    TempDir dir;
    const globemesh::Mesh cap = globemesh::test::icosphere_cap(4, 180, 10, 15);
    write_adcirc(cap, dir / "cap.14");
    const auto rows = number_lines(dir / "cap.14");
    const std::size_t ne = std::size_t(rows.at(0).at(0)), np = std::size_t(rows.at(0).at(1));
    ASSERT_EQ(np, cap.nodes.size());
    ASSERT_EQ(ne, cap.faces.size());
    for (std::size_t i = 1; i <= np; ++i)
        EXPECT_TRUE(rows[i][1] > 160 && rows[i][1] < 200) << rows[i][1];
    for (std::size_t i = np + 1; i <= np + ne; ++i) {
        const auto &e = rows[i];
        const auto &a = rows[std::size_t(e[2])], &b = rows[std::size_t(e[3])],
                   &c = rows[std::size_t(e[4])];
        EXPECT_GT((b[1] - a[1]) * (c[2] - a[2]) - (c[1] - a[1]) * (b[2] - a[2]), 0) << i;
    }
    std::size_t at = np + ne + 1;
    EXPECT_EQ(rows.at(at)[0], 1);                          // NOPE
    const std::size_t n = std::size_t(rows.at(at + 2)[0]); // NVDLL
    EXPECT_EQ(rows.at(at + 1)[0], n);                      // NETA
    EXPECT_EQ(rows.at(at + 3)[0], rows.at(at + 2 + n)[0]); // closed on itself
    EXPECT_EQ(rows.at(at + 3 + n)[0], 0);                  // NBOU
    EXPECT_EQ(rows.at(at + 4 + n)[0], 0);                  // NVEL
    EXPECT_EQ(rows.size(), at + 5 + n);
}

// A node without a depth (NaN) has no value a model can run on: refused, no file. The message
// names bathy_fill_m, the way to mesh one with a depth everywhere: `globemesh convert` of a
// UGRID file with a missing depth says it in its own words (--bathy-fill).
TEST(ModelGrid, a_node_without_depth_is_refused_and_nothing_is_written) {
    TempDir dir;
    globemesh::Mesh cap = globemesh::test::icosphere_cap(3, 0, 0, 20);
    cap.node_fields.front().values[1] = std::nan("");
    ASSERT_EQ(cap.node_fields.front().name, "depth");
    const std::string message = globemesh::test::thrown_message<globemesh::DataError>(
        [&] { write_adcirc(cap, dir / "cap.14"); });
    EXPECT_NE(message.find("1 nodes have no depth"), std::string::npos) << message;
    EXPECT_NE(message.find("or with bathy_fill_m DEPTH"), std::string::npos) << message;
    EXPECT_TRUE(fs::is_empty(dir.path()));
    globemesh::write_ugrid(cap, dir / "cap.nc");
    std::string err;
    EXPECT_EQ(run_exe({"convert", "-q", (dir / "cap.nc").string(), (dir / "cap.14").string()}, err,
                      dir.path()),
              1);
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find("1 nodes have no depth"), std::string::npos) << err;
    EXPECT_NE(err.find("or with --bathy-fill DEPTH"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "cap.14"));
}

TEST(ModelGrid, a_regional_fort14_gr3_and_ll_have_the_open_and_land_strings_of_the_ugrid_file) {
    TempDir dir;
    std::string err;
    const int status = run_exe({"mesh",
                                "--coast",
                                fixture("coast/ne_50m_land.gpkg").string(),
                                "--coast-layer",
                                "land",
                                "--region",
                                "-12,46,13,62",
                                "--bathy",
                                fixture("bathy/etopo5_nwshelf_5min.tif").string(),
                                "--hmax",
                                "60km",
                                "--hmin",
                                "10km",
                                "--coast-size",
                                "15km",
                                "-o",
                                (dir / "m.nc").string(),
                                "-o",
                                (dir / "fort.14").string(),
                                "-o",
                                (dir / "hgrid.gr3").string(),
                                "-o",
                                (dir / "hgrid.ll").string(),
                                "-q"},
                               err, dir.path());
    ASSERT_EQ(status, 0) << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string verdict = check_grids(dir, "regional", {"fort.14", "hgrid.gr3", "hgrid.ll"});
    std::vector<std::string> groups;
    ASSERT_TRUE(globemesh::test::regex_match(verdict, "OK (\\d+) (\\d+)\n", &groups)) << verdict;
    EXPECT_GE(std::stoi(groups[1]), 1); // NOPE
}

TEST(ModelGrid, a_global_fort14_has_no_open_boundary_and_one_mainland) {
    TempDir dir;
    std::string err;
    const int status =
        run_exe({"mesh", "--coast", fixture("coast/ne_110m_land.gpkg").string(), "--coast-layer",
                 "land", "--bathy", fixture("bathy/etopo5_global_10min.nc").string(), "--hmax",
                 "400km", "-o", (dir / "m.nc").string(), "-o", (dir / "g.14").string(), "-q"},
                err, dir.path());
    ASSERT_EQ(status, 0) << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string verdict = check_grids(dir, "global", {"g.14"});
    EXPECT_EQ(verdict.rfind("OK 0 ", 0), 0u) << verdict;
}

// The Southern Ocean south of 50 S in lon/lat: Antarctica's coast winds round the pole, so its
// lon/lat area says nothing; in a part of the mesh with an open boundary it is an island
// (IBTYPE 1), clockwise in the polar stereographic plane, as ADCIRC orders islands.
TEST(ModelGrid, antarctica_in_a_southern_ocean_region_is_an_island) {
    TempDir dir;
    EXPECT_EQ(planar_islands(dir, {"--region", "-180,-90,180,-50"}, "EPSG:3031"), "OK islands 1\n");
}

// A global mesh in EPSG:3995 (the South Pole on land) is a plane domain whose outer boundary is
// Antarctica's coast: the closed strings are typed as they turn in the file's x y, where ADCIRC
// reads them, not by length (the Afro-Eurasian coast was IBTYPE 0 there, and clockwise).
TEST(ModelGrid, a_global_fort14_in_a_polar_projection_has_its_outer_boundary_as_mainland) {
    TempDir dir;
    EXPECT_EQ(planar_islands(dir, {"--output-srs", "EPSG:3995"}).rfind("OK islands ", 0), 0u);
}

TEST(ModelGrid, an_unwritable_fort14_is_one_line_and_leaves_no_file) {
    TempDir dir;
    std::string err;
    const fs::path missing = dir / "no-such-folder" / "fort.14";
    const int status = run_exe({"mesh", "--coast", fixture("coast/ne_110m_land.gpkg").string(),
                                "--coast-layer", "land", "--hmax", "800km", "-o",
                                (dir / "m.nc").string(), "-o", missing.string(), "-q"},
                               err, dir.path());
    EXPECT_NE(status, 0);
    EXPECT_NE(err.find(missing.string()), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(missing));
    EXPECT_FALSE(fs::exists(dir / "m.nc")); // the outputs of a run appear together or not at all
}
