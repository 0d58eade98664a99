// FESOM2 mesh folders, read back by a reader written here from FESOM2's own description of its
// mesh files (the FESOM2 documentation, "Meshes", and read_mesh in FESOM2's src/oce_mesh.F90:
// nod2d.out "n" then "id lon lat flag" with flag 0 wet, 1 closed boundary, 2 open boundary;
// elem2d.out "n" then three node numbers a line; aux3d.out the number of levels, the levels,
// then one depth a node, negative down), and compared with the UGRID file of the same mesh read
// by netCDF4. The failures leave no folder and no file.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
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

/// The reader and the comparison: prints "OK nodes elements coast open" or fails.
const std::string checker = R"(
import sys, netCDF4, numpy as np

def read_fesom2(folder):
    """The three files as FESOM2's read_mesh reads them (list-directed, a record a line)."""
    nod = open(folder + '/nod2d.out').read().split('\n')
    n = int(nod[0])
    rows = [l.split() for l in nod[1:n + 1]]
    assert all(l.strip() == '' for l in nod[n + 1:]), 'text after the nodes'
    assert [int(r[0]) for r in rows] == list(range(1, n + 1)), 'node numbers'
    lonlat = np.array([[float(r[1]), float(r[2])] for r in rows])
    flag = np.array([int(r[3]) for r in rows])
    el = open(folder + '/elem2d.out').read().split('\n')
    e = int(el[0])
    elems = np.array([[int(v) for v in l.split()] for l in el[1:e + 1]])
    assert elems.shape == (e, 3) and all(l.strip() == '' for l in el[e + 1:]), 'elements'
    aux = open(folder + '/aux3d.out').read().split()
    nl = int(aux[0])
    zbar = np.array(aux[1:nl + 1], dtype=float)
    depth = np.array(aux[nl + 1:], dtype=float)
    assert depth.size == n, ('depths', depth.size, n)
    return lonlat, flag, elems, zbar, depth

def check(folder, ugrid, regional, levels):
    nc = netCDF4.Dataset(ugrid)
    lon, lat = nc['mesh_node_lon'][:], nc['mesh_node_lat'][:]
    faces = nc['mesh_face_nodes'][:] - nc['mesh_face_nodes'].start_index
    depth = np.asarray(nc['depth'][:], dtype=float)
    en = nc['mesh_edge_nodes'][:] - nc['mesh_edge_nodes'].start_index
    tag = nc['boundary_tag'][:]  # on edges: 0 interior, 1 coast, 2 open
    lonlat, flag, elems, zbar, d = read_fesom2(folder)
    assert lonlat.shape[0] == lon.size and elems.shape[0] == faces.shape[0]
    dlon = (lonlat[:, 0] - lon + 180) % 360 - 180
    assert np.abs(dlon).max() < 1e-9 and np.abs(lonlat[:, 1] - lat).max() < 1e-9, 'coordinates'
    assert np.array_equal(elems - 1, faces), 'elements'
    x, y = lonlat[elems - 1, 0], lonlat[elems - 1, 1]
    area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
    uncut = np.ptp(x, axis=1) < 180
    assert (area[uncut] > 0).all(), ('clockwise elements', (area[uncut] <= 0).sum())
    # Levels: at least 3 (read_mesh stops with fewer), from 0 down; depths negative down, a node
    # at or above sea level 0.
    assert nl_ok(zbar, levels), zbar
    assert np.array_equal(d, np.where(depth > 0, -depth, 0.0)), 'depths'
    assert (np.abs(d) <= 11000).all(), 'read_mesh takes |depth| > 11000 for a FESOM1.4 file'
    # Flags from the UGRID edge tags: open wins where coast and open meet.
    want = np.zeros(lon.size, dtype=int)
    for t in (1, 2):
        nodes = en[tag == t].ravel()
        want[nodes] = np.maximum(want[nodes], t)
    assert np.array_equal(flag, want), ('flags', (flag != want).sum())
    # And from elem2d.out alone: the nodes of the edges one element has are the flagged ones.
    pairs = np.sort(np.concatenate([elems[:, [0, 1]], elems[:, [1, 2]], elems[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(pairs, axis=0, return_counts=True)
    boundary = np.zeros(lon.size, dtype=bool)
    boundary[uniq[count == 1].ravel() - 1] = True
    assert np.array_equal(boundary, flag > 0), 'flagged nodes are not the boundary nodes'
    assert regional == bool((flag == 2).any()), 'open nodes'
    return '%d %d %d %d' % (lon.size, elems.shape[0], (flag == 1).sum(), (flag == 2).sum())

def nl_ok(zbar, levels):
    want = -np.array([float(v) for v in levels.split(',')]) + 0.0
    return zbar.size >= 3 and np.array_equal(zbar, want)

folder, ugrid, kind, levels = sys.argv[1:5]
print('OK ' + check(folder, ugrid, kind == 'regional', levels))
)";

/// The 48 levels of FESOM2's CORE2 mesh (FESOM2's mesh tools), the writer's default.
const std::string core2 = "0,5,10,20,30,40,50,60,70,80,90,100,115,135,160,190,230,280,340,410,"
                          "490,580,680,790,910,1040,1180,1330,1500,1700,1920,2150,2400,2650,2900,"
                          "3150,3400,3650,3900,4150,4400,4650,4900,5150,5400,5650,6000,6250";

/// Runs the checker on a FESOM2 folder and the UGRID file; returns its output.
std::string check_folder(const TempDir &dir, const fs::path &folder, const fs::path &ugrid,
                         const std::string &kind, const std::string &levels = core2) {
    const fs::path script = dir / "check.py";
    std::ofstream(script) << checker;
    std::string out;
    EXPECT_EQ(run_command("/usr/bin/python3 " + quote(script.string()) + " " +
                              quote(folder.string()) + " " + quote(ugrid.string()) + " " + kind +
                              " " + levels,
                          out),
              0)
        << out;
    return out;
}

std::vector<std::string> global_run(const fs::path &out, const std::string &format = "") {
    std::vector<std::string> args = {"mesh",
                                     "--coast",
                                     fixture("coast/ne_110m_land.gpkg").string(),
                                     "--coast-layer",
                                     "land",
                                     "--bathy",
                                     fixture("bathy/etopo5_global_10min.nc").string(),
                                     "--hmax",
                                     "400km",
                                     "-q",
                                     "-o",
                                     out.string()};
    if (!format.empty())
        args.insert(args.end(), {"-f", format});
    return args;
}

void write_fesom2(const globemesh::Mesh &mesh, const fs::path &folder,
                  const std::function<bool()> &cancelled = {}, globemesh::Progress progress = {}) {
    const globemesh::OutputRequest request{
        globemesh::find_writer(globemesh::writers(), "FESOM2"), folder, {}};
    globemesh::WriteOptions options;
    options.progress = std::move(progress);
    globemesh::write_outputs(mesh, {&request, 1}, options, cancelled);
}

} // namespace

// A regional mesh of real data (Natural Earth 1:50m, ETOPO5 north-west shelf) written with its
// UGRID file in one run (-f names the -o without an extension), with open nodes flagged 2.
TEST(Fesom2, a_regional_mesh_has_its_open_nodes_flagged_2) {
    TempDir dir;
    std::string err;
    ASSERT_EQ(run_exe({"mesh",
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
                       "-q",
                       "-o",
                       (dir / "m.nc").string(),
                       "-o",
                       (dir / "fesom").string(),
                       "-f",
                       "fesom2",
                       "--co",
                       "LEVELS=0,10,25,50,100,200,500"},
                      err, dir.path()),
              0)
        << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string verdict =
        check_folder(dir, dir / "fesom", dir / "m.nc", "regional", "0,10,25,50,100,200,500");
    std::vector<std::string> n;
    ASSERT_TRUE(globemesh::test::regex_match(verdict, "OK (\\d+) (\\d+) (\\d+) (\\d+)\n", &n))
        << verdict;
    EXPECT_GT(std::stoi(n[3]), 0) << "coast nodes";
    EXPECT_GT(std::stoi(n[4]), 0) << "open nodes";
}

// A global mesh (Natural Earth 1:110m, ETOPO5) converted from its UGRID file: coast nodes only,
// the CORE2 levels.
TEST(Fesom2, a_global_mesh_converted_from_ugrid_has_coast_nodes_and_no_open_ones) {
    TempDir dir;
    std::string err;
    ASSERT_EQ(run_exe(global_run(dir / "g.nc"), err, dir.path()), 0) << err;
    expect_mesh_verify(dir / "g.nc");
    ASSERT_EQ(
        run_exe({"convert", "-q", (dir / "g.nc").string(), (dir / "g").string(), "-f", "FESOM2"},
                err, dir.path()),
        0)
        << err;
    const std::string verdict = check_folder(dir, dir / "g", dir / "g.nc", "global");
    std::vector<std::string> n;
    ASSERT_TRUE(globemesh::test::regex_match(verdict, "OK (\\d+) (\\d+) (\\d+) 0\n", &n))
        << verdict;
    EXPECT_GT(std::stoi(n[3]), 0);
}

// Bad levels are a usage error before the mesh is made: nothing is written.
TEST(Fesom2, bad_levels_are_refused_before_meshing) {
    TempDir dir;
    std::string err;
    auto args = global_run(dir / "fesom", "fesom2");
    args.insert(args.end(), {"--co", "LEVELS=0,50,20"});
    EXPECT_EQ(run_exe(args, err, dir.path()), 2);
    EXPECT_NE(err.find("LEVELS=0,50,20: give at least 3 level depths"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Fesom2, a_missing_parent_is_one_line_and_creates_nothing) {
    TempDir dir;
    std::string err;
    const fs::path folder = dir / "no-such-folder" / "fesom";
    EXPECT_EQ(run_exe(global_run(folder, "fesom2"), err, dir.path()), 1);
    EXPECT_NE(err.find("no-such-folder does not exist"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(Fesom2, existing_mesh_files_are_kept_without_overwrite_and_replaced_with_it) {
    TempDir dir;
    fs::create_directory(dir / "fesom");
    std::ofstream(dir / "fesom" / "elem2d.out") << "stale\n";
    std::string err;
    EXPECT_EQ(run_exe(global_run(dir / "fesom", "fesom2"), err, dir.path()), 1);
    EXPECT_NE(err.find("elem2d.out exists; use --overwrite"), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_FALSE(fs::exists(dir / "fesom" / "nod2d.out"));
    EXPECT_EQ(fs::file_size(dir / "fesom" / "elem2d.out"), 6u);
    auto args = global_run(dir / "fesom", "fesom2");
    args.push_back("--overwrite");
    EXPECT_EQ(run_exe(args, err, dir.path()), 0) << err;
    EXPECT_GT(fs::file_size(dir / "fesom" / "elem2d.out"), 6u);
    EXPECT_TRUE(fs::exists(dir / "fesom" / "aux3d.out"));
}

// Without -f an existing folder is no file name: the message says how to write FESOM2 into it.
TEST(Fesom2, a_folder_without_the_format_suggests_it) {
    TempDir dir;
    fs::create_directory(dir / "fesom");
    std::string err;
    EXPECT_EQ(run_exe(global_run(dir / "fesom"), err, dir.path()), 1);
    EXPECT_NE(err.find("is a folder; give a file name, or -f FESOM2 to write a FESOM2 mesh folder "
                       "into it"),
              std::string::npos)
        << err;
    EXPECT_TRUE(fs::is_empty(dir / "fesom"));
}

// A run stopped after the FESOM2 files are written (the other outputs' turn), or while they are
// written, leaves neither the files nor the folder it made.
TEST(Fesom2, a_failing_run_leaves_no_folder) {
    TempDir dir;
    const globemesh::Mesh cap = globemesh::test::icosphere_cap(4, 20, 50, 15);
    EXPECT_THROW(write_fesom2(cap, dir / "after", [] { return true; }), globemesh::Cancelled);
    int calls = 0;
    EXPECT_THROW(write_fesom2(cap, dir / "during", {},
                              [&](double, std::string_view) { return ++calls < 3; }),
                 globemesh::Cancelled);
    EXPECT_EQ(calls, 3);
    EXPECT_TRUE(fs::is_empty(dir.path()));
    // An existing folder stays, without the files.
    fs::create_directory(dir / "kept");
    EXPECT_THROW(write_fesom2(cap, dir / "kept", [] { return true; }), globemesh::Cancelled);
    EXPECT_TRUE(fs::is_empty(dir / "kept"));
    // And the run that completes: an all-open cap, every boundary node 2.
    write_fesom2(cap, dir / "done");
    std::ifstream nodes(dir / "done" / "nod2d.out");
    std::size_t n = 0, open = 0, id = 0, flag = 0;
    double lon = 0, lat = 0;
    nodes >> n;
    EXPECT_EQ(n, cap.nodes.size());
    while (nodes >> id >> lon >> lat >> flag) {
        EXPECT_TRUE(flag == 0 || flag == 2) << id;
        open += flag == 2;
    }
    EXPECT_GT(open, 0u);
}

// What a second signal runs (remove_temporaries) removes an adopted folder when it is empty.
TEST(Fesom2, the_signal_cleanup_removes_the_folder_a_writer_made_when_empty) {
    TempDir dir;
    fs::create_directory(dir / "made");
    fs::create_directory(dir / "filled");
    globemesh::OutputBatch batch;
    ASSERT_TRUE(globemesh::OutputBatch::adopt_folder(dir / "made"));
    ASSERT_TRUE(globemesh::OutputBatch::adopt_folder(dir / "filled"));
    std::ofstream(dir / "filled" / "mine.txt") << "a file the user put there\n";
    globemesh::OutputFile::remove_temporaries();
    EXPECT_FALSE(fs::exists(dir / "made"));
    EXPECT_TRUE(fs::exists(dir / "filled" / "mine.txt"));
}

TEST(Fesom2, bad_levels_and_a_mesh_without_depths_are_refused_before_the_folder) {
    TempDir dir;
    globemesh::Mesh cap = globemesh::test::icosphere_cap(3, 20, 50, 15);
    const globemesh::OutputRequest request{
        globemesh::find_writer(globemesh::writers(), "FESOM2"), dir / "f", {{"LEVELS", "0,10"}}};
    const std::string message = globemesh::test::thrown_message<globemesh::UsageError>([&] {
        globemesh::write_outputs(cap, {&request, 1}, {});
    });
    EXPECT_NE(message.find("at least 3"), std::string::npos) << message;
    cap.node_fields.clear();
    EXPECT_THROW(write_fesom2(cap, dir / "f"), globemesh::DataError);
    EXPECT_TRUE(fs::is_empty(dir.path()));
}
