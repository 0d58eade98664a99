// End to end through the globemesh executable (and run_cli with the real library): the runs a
// user makes, judged by independent readers (python3 netCDF4 and json, mesh-verify) rather than
// by globemesh's own output.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "globemesh/cli.hpp"
#include "support.hpp"

namespace fs = std::filesystem;
using globemesh::test::expect_mesh_verify;
using globemesh::test::fixture;
using globemesh::test::run_command;
using globemesh::test::TempDir;

namespace {

const std::string exe = GLOBEMESH_EXE;
const std::string land110 = fixture("coast/ne_110m_land.gpkg").string();
const std::string land50 = fixture("coast/ne_50m_land.gpkg").string();
const std::string shelf_dem = fixture("bathy/etopo5_nwshelf_5min.tif").string();

std::string quote(const std::string &s) {
    return "'" + s + "'";
}

/// Runs the executable; `out` gets stdout only, `err` stderr only.
int run_exe(const std::vector<std::string> &args, std::string &out, std::string &err,
            const fs::path &dir) {
    std::string command = quote(exe);
    for (const auto &a : args) {
        command += ' '; // appended apart: GCC 12 warns (-Wrestrict, a false positive) on " " + s
        command += quote(a);
    }
    const fs::path err_file = dir / ".stderr";
    const int status = run_command("( " + command + " 2>" + quote(err_file.string()) + " )", out);
    std::ifstream e(err_file);
    std::stringstream s;
    s << e.rdbuf();
    err = s.str();
    fs::remove(err_file);
    return status;
}

/// Runs a python3 script (independent reader) and returns its stdout; fails the test on error.
std::string python(const std::string &script, const fs::path &dir) {
    const fs::path file = dir / ".check.py";
    std::ofstream(file) << script;
    std::string out;
    const int status = run_command("/usr/bin/python3 " + quote(file.string()), out);
    fs::remove(file);
    EXPECT_EQ(status, 0) << out;
    return out;
}

std::set<std::string> files_in(const fs::path &dir) {
    std::set<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

/// Python (netCDF4, numpy, OSR) defining nodes_in(path): a UGRID file's node coordinates in
/// EPSG:`epsg` (x, y) and its target_size.
std::string nodes_in_crs_python(int epsg) {
    return R"(
import netCDF4, numpy as np
from osgeo import osr
wgs, crs = osr.SpatialReference(), osr.SpatialReference()
wgs.ImportFromEPSG(4326); crs.ImportFromEPSG()" +
           std::to_string(epsg) + R"()
wgs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
crs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
def nodes_in(path):
    m = netCDF4.Dataset(path)
    xy = np.array(osr.CoordinateTransformation(wgs, crs).TransformPoints(
        np.c_[m['mesh_node_lon'][:], m['mesh_node_lat'][:]]))
    return xy[:, 0], xy[:, 1], m['target_size'][:]
)";
}

/// Writes a GeoPackage at `path` of one polygon (`wkt`, in EPSG:`epsg`) with a size_km of
/// `size_km` (OGR, python3).
void write_polygon(const std::string &path, int epsg, const std::string &wkt, double size_km,
                   const fs::path &dir) {
    python(R"(
from osgeo import ogr, osr
crs = osr.SpatialReference(); crs.ImportFromEPSG()" +
               std::to_string(epsg) + R"()
ds = ogr.GetDriverByName('GPKG').CreateDataSource(')" +
               path + R"(')
layer = ds.CreateLayer('region', crs, ogr.wkbPolygon)
layer.CreateField(ogr.FieldDefn('size_km', ogr.OFTReal))
f = ogr.Feature(layer.GetLayerDefn()); f.SetField('size_km', )" +
               std::to_string(size_km) + R"()
f.SetGeometry(ogr.CreateGeometryFromWkt(')" +
               wkt + R"('))
layer.CreateFeature(f); f = layer = None; ds = None
)",
           dir);
}

/// Expects two UGRID files to hold the same nodes and faces (read by netCDF4).
void expect_same_mesh(const std::string &a, const std::string &b, const fs::path &dir) {
    EXPECT_EQ(python(R"(
import netCDF4, numpy as np
a, b = netCDF4.Dataset(')" +
                         a + R"('), netCDF4.Dataset(')" + b + R"(')
for v in ('mesh_node_lon', 'mesh_node_lat', 'mesh_face_nodes'):
    assert np.array_equal(a[v][:], b[v][:]), v
print('OK')
)",
                     dir),
              "OK\n")
        << a << " and " << b;
}

int count_lines(const std::string &s) {
    int n = 0;
    for (char c : s)
        n += c == '\n';
    return n;
}

/// The summary's "area" line (km2) as printed, "" when it has none.
std::string summary_area(const std::string &out) {
    std::vector<std::string> area;
    return globemesh::test::regex_search(out, "\\narea +([0-9.]+) km2", &area) ? area[1] : "";
}

} // namespace

TEST(CliE2e, global_mesh_writes_every_output_and_the_report_matches_the_file) {
    TempDir dir;
    std::string out, err;
    const int status =
        run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "400km", "-o",
                 (dir / "g.nc").string(), "--gpkg", (dir / "g.gpkg").string(), "--preview",
                 (dir / "g.png").string(), "--report", (dir / "r.json").string(), "--timings",
                 (dir / "t.json").string(), "--check"},
                out, err, dir.path());
    ASSERT_EQ(status, 0) << err;
    EXPECT_NE(out.find("nodes"), std::string::npos) << out;
    EXPECT_NE(out.find("peak memory"), std::string::npos) << out;
    EXPECT_NE(err.find("100 - done."), std::string::npos) << err;
    // The summary's coast line: rings kept, each one boundary loop of the mesh (checked below),
    // and the holes that removing faces centred on land opened, each one more loop, and the
    // loops it joined, each one fewer; each strait closed (the Bosphorus at 400 km) cuts a loop
    // in two or splits one at a node at most.
    std::vector<std::string> rings, holes, straits;
    ASSERT_TRUE(globemesh::test::regex_search(
        out,
        R"(\ncoast +(\d+) rings kept, islands dropped \d+, lakes dropped \d+, close nodes merged \d+, inlets closed \d+ \()",
        &rings))
        << out;
    ASSERT_TRUE(globemesh::test::regex_search(
        out,
        R"(\nfaces on land +0 \(\d+ removed, opening (\d+) holes, joining (\d+) loops, \d+ moved off\))",
        &holes))
        << out;
    ASSERT_TRUE(globemesh::test::regex_search(
        out,
        R"(\nstraits closed +(\d+) at (\d+) places? \(cutting off \d+ basins.*; (\d+) nodes split\)\n +at )",
        &straits))
        << out;
    const int loops = std::stoi(rings[1]) + std::stoi(holes[1]) - std::stoi(holes[2]);
    const int loops_at_most = loops + std::stoi(straits[1]) + std::stoi(straits[3]);
    // Exactly the outputs asked for: no temporary file left beside them.
    EXPECT_EQ(files_in(dir.path()),
              (std::set<std::string>{"g.nc", "g.gpkg", "g.png", "r.json", "t.json"}));
    expect_mesh_verify(dir / "g.nc");
    // The report and timings against the NetCDF file, read by netCDF4 and json.
    const std::string verdict = python(R"(
import json, netCDF4, numpy as np
r = json.load(open(')" + (dir / "r.json").string() +
                                           R"('))
t = json.load(open(')" + (dir / "t.json").string() +
                                           R"('))
ds = netCDF4.Dataset(')" + (dir / "g.nc").string() +
                                           R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
lon = ds.variables[mesh.node_coordinates.split()[0]]
faces = ds.variables[mesh.face_node_connectivity]
assert r['mesh']['nodes'] == lon.shape[0], (r['mesh']['nodes'], lon.shape)
assert r['mesh']['faces'] == faces.shape[0], (r['mesh']['faces'], faces.shape)
assert sum(r['mesh']['quality']['histogram']) == faces.shape[0]
assert 0 < r['mesh']['quality']['min'] <= r['mesh']['quality']['mean'] <= 1
assert r['peak_memory_bytes'] > 1e6
for k in ('mesh', 'write_ugrid', 'write', 'total'):
    assert k in t['stages'], t
assert t['stages']['write_ugrid'] <= t['stages']['write'] <= t['stages']['total'], t
assert all(v >= 0 for v in t['stages'].values())
assert 0.6 * 400 < r['mesh']['edge_km']['mean'] < 1.3 * 400, r['mesh']['edge_km']
assert )" + std::to_string(loops) + R"( <= r['mesh']['boundary_loops'] <= )" +
                                           std::to_string(loops_at_most) +
                                           R"(, r['mesh']['boundary_loops']
# The run's attributes, as in the NetCDF file's global attributes.
for k in ('coast_file', 'boundary_rings', 'faces_on_land', 'inlets_closed', 'straits_closed', 'straits_closed_at'):
    assert r['attributes'][k] == ds.getncattr(k), (k, r['attributes'].get(k), ds.getncattr(k))
# Every closing has a place, the places numbered 0 .. the summary's count - 1 as they first come.
places = [c['place'] for c in r['straits_closed']]
assert len(places) == )" + straits[1] + R"( and sorted(set(places)) == list(range()" +
                                           straits[2] + R"()), places
assert all(p <= max(places[:i], default=-1) + 1 for i, p in enumerate(places)), places
print('OK', lon.shape[0])
)",
                                       dir.path());
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
    // info reads back the same counts.
    std::string info_out, info_err;
    ASSERT_EQ(run_exe({"info", (dir / "g.nc").string(), "--json"}, info_out, info_err, dir.path()),
              0)
        << info_err;
    fs::path info_json = dir / "info.json";
    std::ofstream(info_json) << info_out;
    const std::string same = python(R"(
import json
a = json.load(open(')" + info_json.string() +
                                        R"('))
b = json.load(open(')" + (dir / "r.json").string() +
                                        R"('))['mesh']
for k in ('nodes', 'faces', 'edges', 'boundary_edges', 'boundary_loops'):
    assert a[k] == b[k], (k, a[k], b[k])
assert abs(a['quality']['mean'] - b['quality']['mean']) < 1e-9
print('OK')
)",
                                    dir.path());
    EXPECT_EQ(same, "OK\n");
}

// The format of -o is its extension's, or -f's (as ogr2ogr -f); --co FORMAT=NC2 and the older
// --format classic write the same netCDF-3 file. Read back by OGR (osgeo) and netCDF4.
TEST(CliE2e, the_output_format_comes_from_the_extension_or_from_f) {
    TempDir dir;
    const std::vector<std::string> base = {"mesh", "--coast", land110, "--coast-layer",
                                           "land", "--hmax",  "800km", "-q"};
    auto run = [&](std::vector<std::string> outputs) {
        std::vector<std::string> args = base;
        args.insert(args.end(), outputs.begin(), outputs.end());
        std::string out, err;
        const int status = run_exe(args, out, err, dir.path());
        EXPECT_EQ(status, 0) << err;
        return out;
    };
    const auto p = [&](const char *name) { return (dir / name).string(); };
    run({"-o", p("a.nc"), "-o", p("b.gpkg"), "-o", p("c.png")});
    run({"-f", "GPKG", "-o", p("d.dat")});
    run({"-o", p("e.nc"), "--co", "FORMAT=NC2"});
    run({"-o", p("f.nc"), "--format", "classic"});
    EXPECT_EQ(files_in(dir.path()),
              (std::set<std::string>{"a.nc", "b.gpkg", "c.png", "d.dat", "e.nc", "f.nc"}));
    expect_mesh_verify(dir / "a.nc");
    const std::string verdict = python(R"(
import netCDF4, numpy as np
from osgeo import gdal, ogr
gdal.UseExceptions()
gdal.PushErrorHandler('CPLQuietErrorHandler')  # "non conformant file extension" of d.dat: asked for
d = ')" + dir.path().string() + R"('
a = netCDF4.Dataset(d + '/a.nc')
mesh = [v for v in a.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
faces = a.variables[mesh.face_node_connectivity].shape[0]
assert a.data_model == 'NETCDF4', a.data_model
for name in ('b.gpkg', 'd.dat'):
    g = ogr.Open(d + '/' + name)
    assert g.GetDriver().GetName() == 'GPKG', (name, g.GetDriver().GetName())
    assert g.GetLayerByName('faces').GetFeatureCount() == faces, (name, faces)
png = gdal.Open(d + '/c.png')
assert png.GetDriver().ShortName == 'PNG' and png.RasterCount >= 3, png.GetDriver().ShortName
e, f = netCDF4.Dataset(d + '/e.nc'), netCDF4.Dataset(d + '/f.nc')
for c in (e, f):
    assert c.data_model == 'NETCDF3_64BIT_OFFSET', c.data_model
    assert set(c.variables) == set(a.variables), sorted(set(c.variables) ^ set(a.variables))
for v in e.variables:
    assert np.array_equal(e[v][...], f[v][...]), v
print('OK', faces)
)",
                                       dir.path());
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
    // An unknown extension: one line naming the formats (those of today first), status 2,
    // nothing written.
    std::string out, err;
    std::vector<std::string> args = base;
    args.insert(args.end(), {"-o", p("g.dat")});
    EXPECT_EQ(run_exe(args, out, err, dir.path()), 2);
    EXPECT_EQ(err.rfind("globemesh: --output " + p("g.dat") +
                            ": no format has the extension .dat; the formats are UGRID (.nc, "
                            ".nc4), GPKG (.gpkg), "
                            "PNG (.png)",
                        0),
              0u)
        << err;
    EXPECT_NE(err.find("; name the file so, or choose the format with -f NAME\n"),
              std::string::npos)
        << err;
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_FALSE(fs::exists(dir / "g.dat"));
}

TEST(CliE2e, a_region_whose_ocean_falls_in_pieces_at_its_edges_meshes_every_piece) {
    // A box across Panama (NE 1:50m at 10 km): its Pacific (29,800 km2) and Caribbean (25,100
    // km2) sides are apart inside the box, but both reach its edges, so both are the ocean (no
    // inland sea); only the largest was meshed, with a warning to add --keep-inland-seas.
    TempDir dir;
    std::string out, err;
    const std::vector<std::string> run{
        "mesh",   "--coast", land50, "--coast-layer",        "land", "--region", "-81,7.5,-78,10",
        "--hmax", "10km",    "-o",   (dir / "p.nc").string()};
    ASSERT_EQ(run_exe(run, out, err, dir.path()), 0) << err;
    EXPECT_FALSE(globemesh::test::regex_search(err, "in pieces apart")) << err;
    const std::string area = summary_area(out);
    ASSERT_FALSE(area.empty()) << out;
    EXPECT_GT(std::stod(area), 50000.0) << out;
    EXPECT_LT(std::stod(area), 60000.0) << out;
    // --keep-inland-seas adds nothing here: no piece is closed off by the coast.
    std::vector<std::string> kept = run;
    kept.insert(kept.end(), {"--keep-inland-seas", "--overwrite"});
    std::string out_kept;
    ASSERT_EQ(run_exe(kept, out_kept, err, dir.path()), 0) << err;
    const std::string area_kept = summary_area(out_kept);
    ASSERT_FALSE(area_kept.empty()) << out_kept;
    EXPECT_EQ(area_kept, area);
}

TEST(CliE2e, a_lake_the_region_outline_cuts_stays_an_inland_sea) {
    // A box from the Aegean to 52 E (NE 1:50m at 30 km) cuts the Caspian, a hole in Eurasia: its
    // water reaches the box's edge but joins no ocean, so it goes as an inland sea (the
    // Mediterranean and Black Sea, 702,700 km2, stay) unless --keep-inland-seas.
    TempDir dir;
    std::string out, err;
    const std::vector<std::string> run{
        "mesh",   "--coast", land50, "--coast-layer",        "land", "--region", "25,35,52,48",
        "--hmax", "30km",    "-o",   (dir / "c.nc").string()};
    ASSERT_EQ(run_exe(run, out, err, dir.path()), 0) << err;
    std::string area = summary_area(out);
    ASSERT_FALSE(area.empty()) << out;
    EXPECT_LT(std::stod(area), 720000.0) << out;
    EXPECT_TRUE(globemesh::test::regex_search(out, "lakes dropped 1,")) << out;
    std::vector<std::string> kept = run;
    kept.insert(kept.end(), {"--keep-inland-seas", "--overwrite"});
    ASSERT_EQ(run_exe(kept, out, err, dir.path()), 0) << err;
    area = summary_area(out);
    ASSERT_FALSE(area.empty()) << out;
    EXPECT_GT(std::stod(area), 950000.0) << out;
}

TEST(CliE2e, a_box_reaching_the_north_pole_away_from_lon_0_is_covered_by_a_global_raster) {
    // ETOPO5 covers the globe, but a box from 155 to 161 E up to 90 N was refused: its window
    // held no column at lon 0, where the pole inside its ocean was looked up.
    TempDir dir;
    std::string out, err;
    const std::string etopo = fixture("bathy/etopo5_global_10min.nc").string();
    for (const char *region : {"155,80,161,90", "-120,85,-100,90"}) {
        const std::vector<std::string> run{
            "mesh",          "-q",      "--overwrite", "--coast", land50,
            "--coast-layer", "land",    "--region",    region,    "--hmax",
            "20km",          "--bathy", etopo,         "-o",      (dir / "n.nc").string()};
        EXPECT_EQ(run_exe(run, out, err, dir.path()), 0) << region << ": " << err;
    }
}

TEST(CliE2e, regional_run_has_coast_and_open_boundaries_inside_the_region) {
    TempDir dir;
    std::string out, err;
    const int status =
        run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-12,46,13,62",
                 "--bathy", shelf_dem, "--hmax", "60km", "--hmin", "10km", "--coast-size", "15km",
                 "-o", (dir / "r.nc").string(), "--quiet"},
                out, err, dir.path());
    ASSERT_EQ(status, 0) << err;
    EXPECT_EQ(err, ""); // --quiet
    expect_mesh_verify(dir / "r.nc");
    const std::string verdict = python(R"(
import netCDF4, numpy as np
ds = netCDF4.Dataset(')" + (dir / "r.nc").string() +
                                           R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
lon = ds.variables[mesh.node_coordinates.split()[0]][:]
lat = ds.variables[mesh.node_coordinates.split()[1]][:]
# The region's parallels are followed by nodes on them, whose great-circle arcs bulge poleward
# (at most 1.5 h long: 0.003 degree at 62N), never below S; no coast node slides out of it.
north = 62 + 0.003
assert lon.min() >= -12 - 1e-6 and lon.max() <= 13 + 1e-6, (lon.min(), lon.max())
assert lat.min() >= 46 - 1e-6 and lat.max() <= north + 1e-6, (lat.min(), lat.max(), north)
tag = ds.variables['boundary_tag'][:]
assert (tag == 1).any() and (tag == 2).any(), np.unique(tag)
assert 'depth' in ds.variables
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
}

// A strip of water a few km wide between the region's south edge (70N) and the coast of the
// Gulf of Boothia is closed by the land removal along a segment across the land; a corner's
// split of that segment made a face centred on land (85.86W 70.05N), which mesh-verify, reading
// the same polygons, counts.
TEST(CliE2e, a_corner_split_beside_a_closed_strip_leaves_no_face_centred_on_land) {
    TempDir dir;
    std::string out, err;
    ASSERT_EQ(
        run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-100,70,-70,90",
                 "--hmin", "50", "--hmax", "50", "-o", (dir / "b.nc").string(), "--quiet"},
                out, err, dir.path()),
        0)
        << err;
    expect_mesh_verify(dir / "b.nc",
                       "--coast " + land50 + " --coast-layer land --max-land-faces 0");
}

TEST(CliE2e, preview_region_zooms_the_picture_and_draws_the_edges_through_the_nodes) {
    // Oracles: the picture's size follows the asked region; each node of the UGRID file (read by
    // netCDF4) placed by the asked region's W,S,E,N lands on or next to a dark edge pixel of the
    // PNG (read by GDAL); a whole-globe picture of the same mesh (faces about 2 pixels) has none.
    TempDir dir;
    std::string out, err;
    for (const auto &[name, region] : {std::pair{"r", "-8,49,2,56"}, {"g", "-180,-90,180,90"}}) {
        const int status =
            run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-12,48,10,62",
                     "--bathy", shelf_dem, "--hmax", "60km", "--hmin", "10km", "-o",
                     (dir / (std::string(name) + ".nc")).string(), "--preview",
                     (dir / (std::string(name) + ".png")).string(),
                     "--preview-region=" + std::string(region), "--quiet"},
                    out, err, dir.path());
        ASSERT_EQ(status, 0) << err;
    }
    // convert zooms its picture as mesh does (no land under it: convert has no coast).
    ASSERT_EQ(run_exe({"convert", (dir / "g.nc").string(), (dir / "c.png").string(),
                       "--preview-region=-8,49,2,56", "--quiet"},
                      out, err, dir.path()),
              0)
        << err;
    expect_mesh_verify(dir / "r.nc");
    const std::string verdict = python(R"(
import netCDF4, numpy as np
from osgeo import gdal
ds = netCDF4.Dataset(')" + (dir / "r.nc").string() +
                                           R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
lon = np.asarray(ds.variables[mesh.node_coordinates.split()[0]][:])
lat = np.asarray(ds.variables[mesh.node_coordinates.split()[1]][:])
def rgb(name):
    png = gdal.Open(')" + dir.path().string() +
                                           R"(/' + name)
    return np.stack([png.GetRasterBand(b).ReadAsArray() for b in (1, 2, 3)], axis=-1).astype(int)
def dark(a):  # the edges' colour (40, 40, 40): no face, land or background colour is grey
    return (a[..., 0] == 40) & (a[..., 1] == 40) & (a[..., 2] == 40)
zoom = rgb('r.png')
W, S, E, N = -8, 49, 2, 56
h, w = zoom.shape[:2]
assert w == 1600 and abs(h - round(1600 * (N - S) / (E - W))) <= 1, (w, h)
col = (lon - W) / (E - W) * w
row = (N - lat) / (N - S) * h
inside = (col >= 2) & (col < w - 2) & (row >= 2) & (row < h - 2)
assert inside.sum() > 50, inside.sum()
edge = dark(zoom)
near = [edge[int(r) - 1:int(r) + 2, int(c) - 1:int(c) + 2].any() for c, r in zip(col[inside], row[inside])]
assert np.mean(near) > 0.95, np.mean(near)
assert edge.mean() > 0.005, edge.mean()
assert not dark(rgb('g.png')).any()
converted = rgb('c.png')
assert converted.shape == zoom.shape, converted.shape
edge = dark(converted)
near = [edge[int(r) - 1:int(r) + 2, int(c) - 1:int(c) + 2].any() for c, r in zip(col[inside], row[inside])]
assert np.mean(near) > 0.95, np.mean(near)
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
}

TEST(CliE2e, a_config_file_run_equals_the_same_run_by_options) {
    TempDir dir;
    std::string out, err;
    ASSERT_EQ(run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "600km",
                       "--seed", "3", "--smooth", "2", "-o", (dir / "a.nc").string(), "-q"},
                      out, err, dir.path()),
              0)
        << err;
    std::ofstream(dir / "run.toml")
        << "coast = \"" << land110 << "\"\ncoast-layer = \"land\"\nhmax = \"600000m\"\n"
        << "seed = 3\nsmooth = 2\nquiet = true\n";
    ASSERT_EQ(
        run_exe({"mesh", "--config", (dir / "run.toml").string(), "-o", (dir / "b.nc").string()},
                out, err, dir.path()),
        0)
        << err;
    const std::string verdict = python(R"(
import netCDF4, numpy as np
a = netCDF4.Dataset(')" + (dir / "a.nc").string() +
                                           R"(')
b = netCDF4.Dataset(')" + (dir / "b.nc").string() +
                                           R"(')
assert set(a.variables) == set(b.variables)
for name in a.variables:
    if a.variables[name].shape == ():
        continue  # attribute containers (mesh, crs): their value carries no data
    assert np.array_equal(np.ma.filled(a.variables[name][:], -1), np.ma.filled(b.variables[name][:], -1)), name
print('OK', len(a.variables))
)",
                                       dir.path());
    EXPECT_EQ(verdict.rfind("OK ", 0), 0u) << verdict;
}

TEST(CliE2e, print_config_output_reads_back_to_the_same_configuration) {
    TempDir dir;
    std::string first, second, err;
    ASSERT_EQ(
        run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-12,46,13,62",
                 "--bathy", shelf_dem, "--hmax", "20km", "--min-island-area", "5e7m2",
                 "--wave-period", "25h", "-o", (dir / "x.nc").string(), "--print-config"},
                first, err, dir.path()),
        0)
        << err;
    std::ofstream(dir / "p.toml") << first;
    ASSERT_EQ(run_exe({"mesh", "--config", (dir / "p.toml").string(), "--print-config"}, second,
                      err, dir.path()),
              0)
        << err;
    EXPECT_EQ(first, second);
    EXPECT_NE(first.find("hmax=20"), std::string::npos) << first;
    EXPECT_NE(first.find("min-island-area=50"), std::string::npos) << first;
    EXPECT_FALSE(fs::exists(dir / "x.nc"));
}

TEST(CliE2e, triangulate_stations_gives_a_closed_triangulation) {
    TempDir dir;
    std::string out, err;
    ASSERT_EQ(run_exe({"triangulate", fixture("points/stations.csv").string(), "-o",
                       (dir / "s.nc").string(), "--timings", (dir / "t.json").string(), "-q"},
                      out, err, dir.path()),
              0)
        << err;
    expect_mesh_verify(dir / "s.nc");
    // 2000 points in general position on the sphere: V - E + F = 2 and 3F = 2E give F = 2V - 4.
    const std::string verdict = python(R"(
import json, netCDF4
ds = netCDF4.Dataset(')" + (dir / "s.nc").string() +
                                           R"(')
mesh = [v for v in ds.variables.values() if getattr(v, 'cf_role', '') == 'mesh_topology'][0]
n = ds.variables[mesh.node_coordinates.split()[0]].shape[0]
f = ds.variables[mesh.face_node_connectivity].shape[0]
assert n == 2000 and f == 2 * n - 4, (n, f)
t = json.load(open(')" + (dir / "t.json").string() +
                                           R"('))
assert 'read' in t['stages'] and 'write' in t['stages'], t
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
    EXPECT_NE(out.find("3996"), std::string::npos) << out;
}

struct ExeError {
    std::string name;
    std::vector<std::string> args; // "{dir}" is the test's folder
    std::set<int> statuses;
    std::string named;
};

class CliE2eErrors : public ::testing::TestWithParam<ExeError> {};

TEST_P(CliE2eErrors, exit_status_one_line_and_no_output) {
    const ExeError &c = GetParam();
    TempDir dir;
    std::ofstream(dir / "existing.nc") << "keep me";
    std::vector<std::string> args;
    for (auto a : c.args) {
        for (auto p = a.find("{dir}"); p != std::string::npos; p = a.find("{dir}"))
            a.replace(p, 5, dir.path().string());
        args.push_back(a);
    }
    std::string out, err;
    const int status = run_exe(args, out, err, dir.path());
    EXPECT_TRUE(c.statuses.count(status)) << "status " << status << ": " << err;
    EXPECT_EQ(out, "");
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_EQ(err.rfind("globemesh: ", 0), 0u) << err;
    EXPECT_NE(err.find(c.named), std::string::npos) << err;
    EXPECT_EQ(files_in(dir.path()), std::set<std::string>{"existing.nc"});
}

INSTANTIATE_TEST_SUITE_P(
    CliE2e, CliE2eErrors,
    ::testing::Values(
        ExeError{"unknown_unit",
                 {"mesh", "--coast", land110, "--hmax", "20parsecs", "-o", "{dir}/o.nc"},
                 {2},
                 "--hmax"},
        ExeError{"negative_size",
                 {"mesh", "--coast", land110, "--coast-size", "-3km", "-o", "{dir}/o.nc"},
                 {2},
                 "--coast-size"},
        ExeError{"hmin_above_hmax",
                 {"mesh", "--coast", land110, "--hmin", "200km", "-o", "{dir}/o.nc"},
                 {2},
                 "--hmin"},
        // A layer that is not there: the option's value is wrong (2) or the data lacks it (1).
        ExeError{"unknown_layer",
                 {"mesh", "--coast", land110, "--coast-layer", "nosuch", "-o", "{dir}/o.nc", "-q"},
                 {1, 2},
                 "nosuch"},
        ExeError{"missing_file",
                 {"mesh", "--coast", "{dir}/land.gpkg", "-o", "{dir}/o.nc"},
                 {1},
                 "land.gpkg"},
        ExeError{"region_without_ocean",
                 {"mesh", "--coast", land110, "--coast-layer", "land", "--region", "0,20,10,25",
                  "-o", "{dir}/o.nc", "-q"},
                 {1},
                 "region"},
        ExeError{"output_in_missing_folder",
                 {"mesh", "--coast", land110, "-o", "{dir}/none/o.nc"},
                 {1},
                 "none"},
        ExeError{"existing_output",
                 {"mesh", "--coast", land110, "-o", "{dir}/existing.nc"},
                 {1},
                 "--overwrite"},
        // The ocean at 1 m would take some 4e14 nodes: refused at once from its area, not after
        // minutes of shaping a coast of billions of nodes.
        ExeError{"a_size_of_metres",
                 {"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "1m", "-o",
                  "{dir}/o.nc", "-q"},
                 {1},
                 "--max-nodes"},
        // GDAL opens a vector file as no raster without a message of its own.
        ExeError{"bathy_not_a_raster",
                 {"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "500km", "--bathy",
                  land110, "-o", "{dir}/o.nc", "-q"},
                 {1},
                 "not a raster format GDAL reads"},
        ExeError{"unknown_subcommand", {"mesj"}, {2}, "mesj"},
        ExeError{"info_on_a_non_mesh", {"info", "{dir}/existing.nc"}, {1}, "existing.nc"}),
    [](const auto &info) { return info.param.name; });

class CliE2eSignal : public ::testing::TestWithParam<int> {};

// Ctrl-C, and `kill` or a batch scheduler's time limit (SIGTERM).
TEST_P(CliE2eSignal, stops_a_run_and_leaves_no_output) {
    // A global 15 km mesh of the 1:50m land (about 3.7 M nodes) takes minutes: the signal lands
    // mid-run. The test sends it to the process it started, by its id.
    const int signal = GetParam();
    TempDir dir;
    const std::string output = (dir / "big.nc").string();
    std::vector<std::string> args = {
        exe,    "mesh",   "--coast", land50,   "--coast-layer",
        "land", "--hmax", "15km",    "--gpkg", (dir / "big.gpkg").string(),
        "-o",   output,   "-q"};
    std::vector<char *> argv;
    for (auto &a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string err_path =
        (dir.path().parent_path() / (dir.path().filename().string() + ".err")).string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    // Run it in the test's folder, so that a temporary file written next to the cwd would show.
    posix_spawn_file_actions_addchdir_np(&actions, dir.path().c_str());
    pid_t pid = 0;
    const int spawned = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ASSERT_EQ(spawned, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(2500));
    const auto sent = std::chrono::steady_clock::now();
    kill(pid, signal);
    int wstatus = 0;
    ASSERT_EQ(waitpid(pid, &wstatus, 0), pid);
    const double stop_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
    std::stringstream err;
    err << std::ifstream(err_path).rdbuf();
    fs::remove(err_path);
    // Stopped cleanly (status 1), or, in a call that does not report for longer than the
    // guard's grace, ended by the signal after removing its files (cli_support.hpp).
    if (WIFSIGNALED(wstatus)) {
        EXPECT_EQ(WTERMSIG(wstatus), signal);
    } else {
        ASSERT_NE(WEXITSTATUS(wstatus), 0)
            << "the run finished within 2.5 s: it is too short for this test";
        EXPECT_EQ(WEXITSTATUS(wstatus), 1); // cli.hpp: cancellation is status 1
    }
    EXPECT_EQ(
        err.str(),
        signal == SIGINT
            ? "globemesh: cancelled, no output written\n"
            : "globemesh: cancelled by SIGTERM, no output written\n"); // one line, nothing else
    EXPECT_TRUE(fs::is_empty(dir.path())) << "output or temporary files left behind";
    EXPECT_LT(stop_s, 10.0) << "the run took " << stop_s << " s to stop after the signal";
}

INSTANTIATE_TEST_SUITE_P(Signals, CliE2eSignal, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto &info) {
                             return info.param == SIGINT ? "sigint" : "sigterm";
                         });

namespace {

/// Writes a GeoPackage of `features` square-ish polygons of `vertices_each` vertices (a circle
/// of radius 0.4 degree around a distinct centre each) with python3's GDAL bindings, from WKB
/// built with numpy: an independent writer, and fast enough for 1e7 vertices.
void write_many_vertex_layer(const fs::path &path, int features, int vertices_each,
                             const fs::path &dir) {
    python("import numpy as np, struct\n"
           "from osgeo import ogr, osr\n"
           "ogr.UseExceptions()\n"
           "ds = ogr.GetDriverByName('GPKG').CreateDataSource('" +
               path.string() +
               "')\n"
               "srs = osr.SpatialReference(); srs.ImportFromEPSG(4326)\n"
               "lyr = ds.CreateLayer('dense_land', srs, ogr.wkbPolygon)\n"
               "n = " +
               std::to_string(vertices_each) +
               "\n"
               "t = np.linspace(0, 2 * np.pi, n)  # n vertices, the last equal to the first\n"
               "lyr.StartTransaction()\n"
               "for k in range(" +
               std::to_string(features) +
               "):\n"
               "    cx, cy = -170 + (k % 100) * 3.0, -60 + (k // 100) * 3.0\n"
               "    xy = np.empty((n, 2)); xy[:, 0] = cx + 0.4 * np.cos(t); xy[:, 1] = cy + 0.4 * "
               "np.sin(t)\n"
               "    xy[-1] = xy[0]\n"
               "    wkb = struct.pack('<BIII', 1, 3, 1, n) + xy.astype('<f8').tobytes()\n"
               "    f = ogr.Feature(lyr.GetLayerDefn()); "
               "f.SetGeometry(ogr.CreateGeometryFromWkb(wkb))\n"
               "    lyr.CreateFeature(f)\n"
               "lyr.CommitTransaction()\n"
               "ds = None\n",
           dir);
}

/// Runs `globemesh mesh ARGS` in-process through the real library.
int run_mesh_in_process(std::vector<std::string> args, std::string &out, std::string &err) {
    args.insert(args.begin(), "mesh");
    std::ostringstream o, e;
    const int status = globemesh::run_cli(args, o, e);
    out = o.str();
    err = e.str();
    return status;
}

} // namespace

TEST(CliE2e, a_coastline_of_ten_million_vertices_is_refused_in_one_line_without_exhausting_memory) {
    TempDir dir;
    const fs::path coast = dir / "dense.gpkg";
    write_many_vertex_layer(coast, 100, 100'000, dir.path()); // 1e7 vertices, 160 MB of WKB
    std::string out, err;
    // 1 GB keeps at most 5e6 vertices (200 B each): the loader stops keeping them half-way and
    // only counts the rest.
    const int status = run_mesh_in_process(
        {"--coast", coast.string(), "-o", (dir / "o.nc").string(), "--max-memory", "1GB", "-q"},
        out, err);
    EXPECT_EQ(status, 1);
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_NE(err.find("layer 'dense_land' has 10000000 vertices"), std::string::npos) << err;
    EXPECT_NE(err.find("--max-memory"), std::string::npos) << err;
    EXPECT_EQ(out, "");
    EXPECT_FALSE(fs::exists(dir / "o.nc"));
}

TEST(CliE2e, a_coastline_within_the_budget_is_read_and_meshed) {
    // The same loader below the limit: 4 features of 5000 vertices, 1 MB per 5000 vertices.
    TempDir dir;
    const fs::path coast = dir / "dense.gpkg";
    write_many_vertex_layer(coast, 4, 5000, dir.path());
    std::string out, err;
    EXPECT_EQ(run_mesh_in_process({"--coast", coast.string(), "-o", (dir / "refused.nc").string(),
                                   "--max-memory", "3MB", "--hmax", "500km", "-q"},
                                  out, err),
              1);
    EXPECT_NE(err.find("has 20000 vertices, more than the 15000"), std::string::npos) << err;
    ASSERT_EQ(run_mesh_in_process({"--coast", coast.string(), "-o", (dir / "o.nc").string(),
                                   "--max-memory", "500MB", "--hmax", "500km", "-q"},
                                  out, err),
              0)
        << err;
    expect_mesh_verify(dir / "o.nc");
}

TEST(CliE2e, a_four_gigabyte_raster_is_read_coarse_or_refused_without_reading_it_whole) {
    // A VRT declares 69120 x 34560 Int16 cells (4.8 GB) over the 10-minute ETOPO5 fixture,
    // each source cell repeated 32 x 32 times (cells of 0.3125 arc-minute).
    TempDir dir;
    const fs::path vrt = dir / "huge.vrt";
    std::ofstream(vrt) << "<VRTDataset rasterXSize=\"69120\" rasterYSize=\"34560\">\n"
                          "  <SRS>EPSG:4326</SRS>\n"
                          "  <GeoTransform>-180, 0.005208333333333333, 0, 90, 0, "
                          "-0.005208333333333333</GeoTransform>\n"
                          "  <VRTRasterBand dataType=\"Int16\" band=\"1\">\n"
                          "    <SimpleSource>\n"
                          "      <SourceFilename relativeToVRT=\"0\">"
                       << fixture("bathy/etopo5_global_10min.nc").string()
                       << "</SourceFilename>\n"
                          "      <SourceBand>1</SourceBand>\n"
                          "      <SrcRect xOff=\"0\" yOff=\"0\" xSize=\"2160\" ySize=\"1080\"/>\n"
                          "      <DstRect xOff=\"0\" yOff=\"0\" xSize=\"69120\" ySize=\"34560\"/>\n"
                          "    </SimpleSource>\n"
                          "  </VRTRasterBand>\n"
                          "</VRTDataset>\n";
    std::string out, err;
    // Fine sizes ask for cells of 1 km: refused before any large allocation, naming the option.
    EXPECT_EQ(
        run_mesh_in_process({"--coast", land110, "--coast-layer", "land", "--bathy", vrt.string(),
                             "--hmax", "300km", "--hmin", "2km", "--coast-size", "100km",
                             "--max-memory", "200MB", "-o", (dir / "fine.nc").string(), "-q"},
                            out, err),
        1);
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_NE(err.find("--bathy " + vrt.string() + ": 69120 x 34560 cells"), std::string::npos)
        << err;
    EXPECT_NE(err.find("--max-memory"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir / "fine.nc"));
    // Coarse sizes (hmin 100 km: cells of 50 km) read about 800 x 400 cells and mesh.
    ASSERT_EQ(
        run_mesh_in_process({"--coast", land110, "--coast-layer", "land", "--bathy", vrt.string(),
                             "--hmax", "300km", "--hmin", "100km", "--max-memory", "200MB", "-o",
                             (dir / "coarse.nc").string(), "-q"},
                            out, err),
        0)
        << err;
    expect_mesh_verify(dir / "coarse.nc");
}

TEST(CliE2e, a_size_field_grid_or_a_mesh_beyond_the_budget_is_refused_before_it_is_built) {
    TempDir dir;
    std::string out, err;
    // 2^22 grid nodes at 64 B: 268 MB.
    EXPECT_EQ(run_mesh_in_process({"--coast", land110, "--coast-layer", "land", "--hmax", "100km",
                                   "--hmin", "1km", "--coast-size", "5km", "--max-memory", "100MB",
                                   "-o", (dir / "o.nc").string(), "-q"},
                                  out, err),
              1);
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_NE(err.find("background grid"), std::string::npos) << err;
    EXPECT_NE(err.find("--max-memory"), std::string::npos) << err;
    // A uniform 5 km mesh: about 25 M nodes, far beyond 1 GB at the mesher's 800 B a node.
    EXPECT_EQ(run_mesh_in_process({"--coast", land110, "--coast-layer", "land", "--hmax", "5km",
                                   "--max-nodes", "1000000000", "--max-memory", "1GB", "-o",
                                   (dir / "o.nc").string(), "-q"},
                                  out, err),
              1);
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_NE(err.find("--max-memory"), std::string::npos) << err;
    EXPECT_TRUE(fs::is_empty(dir.path()));
}

// --report /dev/stdout (a pipe here) prints the JSON among the summary, with or without
// --overwrite, and leaves /dev/stdout as it was (before, --overwrite renamed a regular file
// over the system's /dev/stdout link).
TEST(CliE2e, a_report_to_dev_stdout_is_printed_and_dev_stdout_is_kept) {
    TempDir dir;
    const auto before = fs::symlink_status("/dev/stdout").type();
    for (const char *overwrite : {"--quiet", "--overwrite"}) {
        std::string out, err;
        ASSERT_EQ(
            run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--hmax", "800km", "-o",
                     (dir / "p.nc").string(), "--report", "/dev/stdout", "--overwrite", overwrite},
                    out, err, dir.path()),
            0)
            << err;
        EXPECT_NE(out.find("\"peak_memory_bytes\": "), std::string::npos) << out;
        EXPECT_NE(out.find("faces"), std::string::npos) << out; // and the summary
        EXPECT_EQ(fs::symlink_status("/dev/stdout").type(), before);
        EXPECT_EQ(files_in(dir.path()), std::set<std::string>{"p.nc"});
    }
}

TEST(CliE2e, run_cli_in_process_prints_the_summary_on_out_only) {
    TempDir dir;
    std::ostringstream out, err;
    const std::vector<std::string> args = {
        "mesh",   "--coast", land110, "--coast-layer",         "land",
        "--hmax", "800km",   "-o",    (dir / "p.nc").string(), "--quiet"};
    ASSERT_EQ(globemesh::run_cli(args, out, err), 0) << err.str();
    EXPECT_EQ(err.str(), "");
    EXPECT_NE(out.str().find("faces"), std::string::npos);
    expect_mesh_verify(dir / "p.nc");
}

// A square drawn in polar stereographic (EPSG:3413) about the North Pole as a --size-regions
// polygon (1200 km side, size_km 30): its sides are the straight lines of that CRS, not lines
// straight in lon/lat between the corners (which set its size up to 242 km past them). Read back
// with OSR: no node at its size lies past its sides by more than that size.
TEST(CliE2e, a_size_region_drawn_in_a_projected_crs_keeps_its_straight_sides) {
    TempDir dir;
    const std::string size = (dir / "size.gpkg").string();
    write_polygon(size, 3413, "POLYGON((-6e5 -6e5,6e5 -6e5,6e5 6e5,-6e5 6e5,-6e5 -6e5))", 30,
                  dir.path());
    std::string out, err;
    ASSERT_EQ(
        run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "-180,70,180,90",
                 "--hmax", "100", "--size-regions", size, "-o", (dir / "s.nc").string(), "--quiet"},
                out, err, dir.path()),
        0)
        << err;
    const std::string verdict = python(nodes_in_crs_python(3413) + R"(
x, y, size = nodes_in(')" + (dir / "s.nc").string() +
                                           R"(')
past = np.maximum(np.abs(x), np.abs(y)) - 6e5
assert (size < 30.5).sum() > 100 and past[size < 30.5].max() < 30e3, past[size < 30.5].max()
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
}

// A rectangle drawn in UTM zone 1N across the antimeridian (the western Aleutians, 330 x 270
// km), reprojected, jumps from 179 to -179 degrees: as a --region-file it meshed the whole band
// of latitudes but its own longitudes (nodes from 59W to 3W), and as --size-regions (5 km) it
// set that size all round the band (nodes at it 571 km outside). Read back with OSR in UTM 1N:
// every node of the region's mesh lies within 5 km of the rectangle (a region file's sides
// run straight in lon/lat between its vertices: 2.6 km off the UTM lines here), and the nodes at
// the size region's size lie in it while those 20 km inside it all have that size.
TEST(CliE2e, polygons_drawn_in_utm_across_the_antimeridian_stay_where_they_are_drawn) {
    TempDir dir;
    write_polygon(dir.path().string() + "/aleutians.gpkg", 32601,
                  "POLYGON((150e3 5600e3,480e3 5600e3,480e3 5870e3,150e3 5870e3,150e3 5600e3))", 5,
                  dir.path());
    const std::string file = (dir / "aleutians.gpkg").string();
    std::string out, err;
    ASSERT_EQ(run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region-file", file,
                       "--hmax", "20", "-o", (dir / "r.nc").string(), "--quiet"},
                      out, err, dir.path()),
              0)
        << err;
    expect_mesh_verify(dir / "r.nc");
    ASSERT_EQ(
        run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region", "170,45,-170,60",
                 "--hmax", "50", "--size-regions", file, "-o", (dir / "s.nc").string(), "--quiet"},
                out, err, dir.path()),
        0)
        << err;
    const std::string verdict = python(nodes_in_crs_python(32601) + R"(
def outside(path):
    x, y, size = nodes_in(path)
    return np.maximum.reduce([150e3 - x, x - 480e3, 5600e3 - y, y - 5870e3]), size
past, _ = outside(')" + (dir / "r.nc").string() +
                                           R"(')
assert past.max() < 5e3, past.max()
past, size = outside(')" + (dir / "s.nc").string() +
                                           R"(')
at = size < 5.05
assert at.sum() > 100 and past[at].max() < 1e3, past[at].max()
assert at[past < -20e3].all(), (~at[past < -20e3]).sum()
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
}

// Region files and size regions that hold the wrong things, derived from the real
// fixtures with OGR: DCW's Denmark buffered about South Funen as closed lines meshes as its
// polygon does (a closed line bounds the same water, as --help says; the two meshes' nodes are
// equal), and every other case is refused in one line naming the file and the cause, with no
// output: an open line (a critical passage) as the region, a region layer of no features, size
// regions with lines or a null size_km (were ignored without a word). Size regions' rows without
// a shape are left out, as GDAL's tools leave them.
TEST(CliE2e, region_and_size_region_files_holding_the_wrong_things_say_what_is_wrong) {
    TempDir dir;
    const std::string d = dir.path().string() + "/";
    python(R"(
from osgeo import ogr
d = ')" + d + R"('
src = ogr.Open(')" +
               fixture("regions/dcw_denmark_buffer_0.02_south_funen.geojson").string() +
               R"(')
region = src.GetLayer(0)
passages_ds = ogr.Open(')" +
               fixture("passages/passages.geojson").string() + R"(')
passages = passages_ds.GetLayer(0)
srs = region.GetSpatialRef()
feature = region.GetNextFeature()  # kept: its geometry is a reference into it
polygon = feature.GetGeometryRef().Clone()
lines = [f.GetGeometryRef().Clone() for f in passages]
def write(name, geometry_type, features):
    ds = ogr.GetDriverByName('GPKG').CreateDataSource(d + name + '.gpkg')
    l = ds.CreateLayer(name, srs, geometry_type)
    l.CreateField(ogr.FieldDefn('size_km', ogr.OFTReal))
    for g, size in features:
        f = ogr.Feature(l.GetLayerDefn()); f.SetGeometry(g)
        if size is not None:
            f.SetField('size_km', size)
        l.CreateFeature(f)
    f = l = None; ds = None  # the layer before its data set
write('outline', ogr.wkbMultiLineString, [(ogr.ForceToMultiLineString(polygon.GetBoundary()), None)])
write('empty', ogr.wkbPolygon, [])
write('open_line', ogr.wkbLineString, [(lines[0], None)])
write('size_lines', ogr.wkbUnknown, [(polygon, 2), (lines[0], 2), (lines[1], 2)])
write('size_null', ogr.wkbPolygon, [(polygon, 2), (polygon, None)])
write('size_one', ogr.wkbPolygon, [(polygon, 2)])
write('size_and_no_shape', ogr.wkbPolygon, [(None, 3), (polygon, 2), (None, None)])
)",
           dir.path());
    const std::string coast = fixture("coast/hostile/gshhg_i_south_funen.geojson").string();
    std::string out, err;
    for (const std::string region : {"outline", "polygon"}) {
        const std::string file =
            region == "outline"
                ? d + "outline.gpkg"
                : fixture("regions/dcw_denmark_buffer_0.02_south_funen.geojson").string();
        ASSERT_EQ(run_exe({"mesh", "--coast", coast, "--region-file", file, "--hmax", "5", "-o",
                           d + region + ".nc", "--quiet"},
                          out, err, dir.path()),
                  0)
            << err;
    }
    expect_same_mesh(d + "outline.nc", d + "polygon.nc", dir.path());
    // Rows without a shape (a table edited in QGIS) size nothing: the same mesh as without them.
    for (const std::string sizes : {"size_one", "size_and_no_shape"})
        ASSERT_EQ(
            run_exe({"mesh", "--coast", coast, "--region", "9.9,55,10.3,55.3", "--hmax", "5",
                     "--size-regions", d + sizes + ".gpkg", "-o", d + sizes + ".nc", "--quiet"},
                    out, err, dir.path()),
            0)
            << err;
    expect_same_mesh(d + "size_one.nc", d + "size_and_no_shape.nc", dir.path());
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"--region-file", d + "open_line.gpkg"},
         "does not close; give polygons (or closed lines)"},
        {{"--region-file", d + "empty.gpkg"},
         "layer 'empty' has no features; give a layer of polygons (or closed lines)"},
        {{"--region", "9.9,55,10.3,55.3", "--size-regions", d + "size_lines.gpkg"},
         "2 features are not polygons (the first, feature 2, is a Line String)"},
        {{"--region", "9.9,55,10.3,55.3", "--size-regions", d + "size_null.gpkg"},
         "feature 2 has no size_km (null)"},
    };
    for (const auto &[args, message] : cases) {
        std::vector<std::string> run = {"mesh", "--coast", coast,      "--hmax",
                                        "5",    "-o",      d + "x.nc", "-q"};
        run.insert(run.end(), args.begin(), args.end());
        EXPECT_EQ(run_exe(run, out, err, dir.path()), 1) << err;
        EXPECT_EQ(count_lines(err), 1) << err;
        EXPECT_NE(err.find(message), std::string::npos) << err;
        EXPECT_FALSE(fs::exists(d + "x.nc"));
    }
}

// GSHHG's coast of South Funen buffered 0.006 degree (a strip about 1 km wide) as a 5 km size
// region of a global 100 km mesh, whose size grid's cells are some 14 km: the strip fell between
// their centres and its nodes got 5.7 to 8.5 km. Read back with OGR and netCDF4, every node in
// the strip has the size it asks, within the grid's interpolation (5.5 km).
TEST(CliE2e, a_size_region_narrower_than_a_grid_cell_sets_the_size_where_it_lies) {
    TempDir dir;
    const std::string strip = (dir / "strip.gpkg").string();
    const std::string nodes_in_strip = R"(
from osgeo import ogr
src = ogr.Open(')" + fixture("coast/hostile/gshhg_i_south_funen.geojson").string() +
                                       R"(')
land = src.GetLayer(0)
strips = [f.GetGeometryRef().GetBoundary().Buffer(0.006) for f in land]
)";
    python(nodes_in_strip + R"(
ds = ogr.GetDriverByName('GPKG').CreateDataSource(')" +
               strip + R"(')
layer = ds.CreateLayer('strip', land.GetSpatialRef(), ogr.wkbMultiPolygon)
layer.CreateField(ogr.FieldDefn('size_km', ogr.OFTReal))
for g in strips:
    f = ogr.Feature(layer.GetLayerDefn()); f.SetGeometry(ogr.ForceToMultiPolygon(g))
    f.SetField('size_km', 5); layer.CreateFeature(f)
f = layer = None; ds = None
)",
           dir.path());
    std::string out, err;
    ASSERT_EQ(run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--hmax", "100",
                       "--size-regions", strip, "-o", (dir / "g.nc").string(), "--quiet"},
                      out, err, dir.path()),
              0)
        << err;
    EXPECT_EQ(python(nodes_in_strip + R"(
import netCDF4, numpy as np
m = netCDF4.Dataset(')" + (dir / "g.nc").string() +
                         R"(')
lon, lat, size = m['mesh_node_lon'][:], m['mesh_node_lat'][:], m['target_size'][:]
sizes = []
for i in np.flatnonzero((lon > 9.7) & (lon < 10.5) & (lat > 54.8) & (lat < 55.5)):
    p = ogr.Geometry(ogr.wkbPoint); p.AddPoint_2D(float(lon[i]), float(lat[i]))
    if any(g.Contains(p) for g in strips):
        sizes.append(float(size[i]))
assert len(sizes) >= 5 and max(sizes) <= 5.5, sizes
print('OK')
)",
                     dir.path()),
              "OK\n");
}

// DCW's Denmark buffered about South Funen as --region-file, GSHHG's coast there, --coast-size
// 300 m: the size field's grid was the globe's (cells of some 14 km) for a region 25 km across,
// and the nodes on the coast got 362 m at least. Its grid now covers the region's ocean: read
// back with OGR, every node on the coast (within 1e-6 degree of it) has 300 m, to 10 m.
TEST(CliE2e, a_region_file_gets_a_size_grid_over_its_own_ocean) {
    TempDir dir;
    const std::string coast = fixture("coast/hostile/gshhg_i_south_funen.geojson").string();
    std::string out, err;
    ASSERT_EQ(
        run_exe({"mesh", "--coast", coast, "--region-file",
                 fixture("regions/dcw_denmark_buffer_0.02_south_funen.geojson").string(),
                 "--coast-size", "0.3", "--hmax", "3", "-o", (dir / "f.nc").string(), "--quiet"},
                out, err, dir.path()),
        0)
        << err;
    EXPECT_EQ(python(R"(
import netCDF4, numpy as np
from osgeo import ogr
src = ogr.Open(')" + coast +
                         R"(')
shores = [f.GetGeometryRef().GetBoundary() for f in src.GetLayer(0)]
m = netCDF4.Dataset(')" + (dir / "f.nc").string() +
                         R"(')
on_coast = []
for x, y, h in zip(m['mesh_node_lon'][:], m['mesh_node_lat'][:], m['target_size'][:]):
    p = ogr.Geometry(ogr.wkbPoint); p.AddPoint_2D(float(x), float(y))
    if min(s.Distance(p) for s in shores) < 1e-6:
        on_coast.append(float(h))
assert len(on_coast) > 30 and abs(np.array(on_coast) - 0.3).max() < 0.01, (len(on_coast), max(on_coast))
print('OK')
)",
                     dir.path()),
              "OK\n");
}

// A --region-file about the North Pole (a 2000 km square in EPSG:3413), Natural Earth 1:110m,
// --coast-size 4 km: the grid of a region round a pole is its band of latitudes, not the globe's
// (with --coast-size 2 the nodes on the coast got up to 2.64 km before, 2.16 after). Read back
// with OGR: every node on the coast has 4 km to within a quarter of a km.
TEST(CliE2e, a_region_file_about_a_pole_gets_a_size_grid_over_its_band) {
    TempDir dir;
    const std::string d = dir.path().string() + "/";
    write_polygon(d + "cap.gpkg", 3413, "POLYGON((-1e6 -1e6,1e6 -1e6,1e6 1e6,-1e6 1e6,-1e6 -1e6))",
                  4, dir.path());
    std::string out, err;
    ASSERT_EQ(
        run_exe({"mesh", "--coast", land110, "--coast-layer", "land", "--region-file",
                 d + "cap.gpkg", "--hmax", "100", "--coast-size", "4", "-o", d + "c.nc", "--quiet"},
                out, err, dir.path()),
        0)
        << err;
    EXPECT_EQ(python(R"(
import netCDF4, numpy as np
from osgeo import ogr
src = ogr.Open(')" + land110 +
                         R"(')
layer = src.GetLayerByName('land'); layer.SetSpatialFilterRect(-180, 60, 180, 90)
shores = [f.GetGeometryRef().GetBoundary() for f in layer]
m = netCDF4.Dataset(')" + d +
                         R"(c.nc')
on_coast = []
for x, y, h in zip(m['mesh_node_lon'][:], m['mesh_node_lat'][:], m['target_size'][:]):
    p = ogr.Geometry(ogr.wkbPoint); p.AddPoint_2D(float(x), float(y))
    if any(s.Distance(p) < 1e-6 for s in shores):
        on_coast.append(float(h))
assert len(on_coast) > 30 and abs(np.array(on_coast) - 4).max() < 0.25, (len(on_coast), max(on_coast))
print('OK')
)",
                     dir.path()),
              "OK\n");
}

// A region across the antimeridian as ogr2ogr -wrapdateline stores it (two polygons, one either
// side of 180) was read as going round the globe: the whole coast layer was read for it (GSHHG
// high: 11 s and 566 MB, against 0.2 s and 65 MB for the polygon drawn past 180), and within
// --max-memory 4MB the 1:50m layer's 60,669 vertices were refused. Now it is one box across 180:
// the run fits, and meshes the same nodes as the polygon drawn past 180 (netCDF4).
TEST(CliE2e, a_region_file_split_at_the_antimeridian_reads_only_the_coast_near_it) {
    TempDir dir;
    const std::string d = dir.path().string() + "/";
    write_polygon(d + "past.gpkg", 4326, "POLYGON((176 50.5,183 50.5,183 53,176 53,176 50.5))", 0,
                  dir.path());
    python(R"(
from osgeo import gdal, ogr
gdal.UseExceptions()
gdal.VectorTranslate(')" +
               d + R"(split.gpkg', ')" + d +
               R"(past.gpkg', options='-wrapdateline -nlt MULTIPOLYGON')
split = ogr.Open(')" +
               d + R"(split.gpkg')
feature = split.GetLayer(0).GetNextFeature()
assert feature.GetGeometryRef().GetGeometryCount() == 2
)",
           dir.path());
    std::string out, err;
    for (const std::string name : {"split", "past"})
        ASSERT_EQ(run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--region-file",
                           d + name + ".gpkg", "--hmax", "20", "--max-memory", "4MB", "-o",
                           d + name + ".nc", "--quiet"},
                          out, err, dir.path()),
                  0)
            << err;
    expect_same_mesh(d + "split.nc", d + "past.nc", dir.path());
}

// GSHHG's Chukotka (one polygon from 175E to 185E) reprojected to polar stereographic (EPSG:3413)
// as --coast: back in lon/lat its ring jumped from 180 to -180 and the land was meshed as sea
// (1,016 faces on land at 10 km). mesh-verify, given the lon/lat polygons, finds no face on land,
// and the ocean's area is the lon/lat source's (netCDF4, within 0.1%).
TEST(CliE2e, a_coast_in_a_polar_crs_with_land_across_the_antimeridian_stays_land) {
    TempDir dir;
    const std::string d = dir.path().string() + "/";
    const std::string lonlat = fixture("coast/hostile/gshhg_i_chukotka_175_185.geojson").string();
    python(R"(
from osgeo import gdal
gdal.UseExceptions()
gdal.VectorTranslate(')" +
               d + R"(polar.gpkg', ')" + lonlat + R"(', options='-t_srs EPSG:3413 -nln land')
)",
           dir.path());
    std::string out, err;
    for (const std::string &coast : {d + "polar.gpkg", lonlat})
        ASSERT_EQ(
            run_exe({"mesh", "--coast", coast, "--region", "176,64.5,-176,67.5", "--hmax", "10",
                     "-o", d + (coast == lonlat ? "lonlat" : "polar") + ".nc", "--quiet"},
                    out, err, dir.path()),
            0)
            << err;
    expect_mesh_verify(d + "polar.nc", "--coast " + lonlat + " --max-land-faces 0");
    EXPECT_EQ(python(R"(
import netCDF4
polar, lonlat = (netCDF4.Dataset(')" +
                         d + R"(' + n + '.nc')['area'][:].sum() for n in ('polar', 'lonlat'))
assert abs(polar / lonlat - 1) < 1e-3, (polar, lonlat)
print('OK')
)",
                     dir.path()),
              "OK\n");
}

// A CUDEM tile as published (CF lon/lat axes, no CRS) meshes a region given as a polygon in
// UTM 15N: read as lon/lat (--verbose says so), the raster need cover only that region's ocean,
// and every node's depth is the tile's bilinear value there (netCDF4 and numpy). A region
// reaching south of the tile into the water is refused, one line, no output.
TEST(CliE2e, a_cf_tile_without_a_crs_meshes_a_region_file_in_utm) {
    TempDir dir;
    const std::string tile = fixture("bathy/cudem_sabine_unequal_48x40.nc").string();
    python(R"(
from osgeo import ogr, osr
wgs, utm = osr.SpatialReference(), osr.SpatialReference()
wgs.ImportFromEPSG(4326); utm.ImportFromEPSG(32615)
wgs.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
for name, south in (('inside', 29.7530), ('beyond', 29.7450)):
    ring = ogr.Geometry(ogr.wkbLinearRing)
    for x, y in ((-93.8905, south), (-93.8775, south), (-93.8775, 29.7628), (-93.8905, 29.7628), (-93.8905, south)):
        ring.AddPoint_2D(x, y)
    poly = ogr.Geometry(ogr.wkbPolygon); poly.AddGeometry(ring)
    poly.Transform(osr.CoordinateTransformation(wgs, utm))
    ds = ogr.GetDriverByName('GPKG').CreateDataSource(')" +
               dir.path().string() + R"(/' + name + '.gpkg')
    layer = ds.CreateLayer('region', utm, ogr.wkbPolygon)
    f = ogr.Feature(layer.GetLayerDefn()); f.SetGeometry(poly); layer.CreateFeature(f)
    ds = None
)",
           dir.path());
    std::string out, err;
    int status = run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--bathy", tile,
                          "--region-file", (dir / "inside.gpkg").string(), "--hmax", "100m",
                          "--wavelength", "40", "-o", (dir / "m.nc").string(), "--verbose"},
                         out, err, dir.path());
    ASSERT_EQ(status, 0) << err;
    EXPECT_NE(err.find("its axes are CF longitude/latitude: read as WGS 84 lon/lat"),
              std::string::npos)
        << err;
    expect_mesh_verify(dir / "m.nc");
    const std::string verdict = python(R"(
import netCDF4, numpy as np
t = netCDF4.Dataset(')" + tile + R"(')
x, y, z = t['lon'][:], t['lat'][:], t['Band1'][:].astype(float)
m = netCDF4.Dataset(')" + (dir / "m.nc").string() +
                                           R"(')
lon, lat, depth = m['mesh_node_lon'][:], m['mesh_node_lat'][:], m['depth'][:]
assert len(lon) > 100 and not np.isnan(depth).any(), len(lon)
i = np.clip(np.searchsorted(x, lon) - 1, 0, len(x) - 2); j = np.clip(np.searchsorted(y, lat) - 1, 0, len(y) - 2)
u = np.clip((lon - x[i]) / (x[i + 1] - x[i]), 0, 1); v = np.clip((lat - y[j]) / (y[j + 1] - y[j]), 0, 1)
expect = -((1-u)*(1-v)*z[j, i] + u*(1-v)*z[j, i+1] + (1-u)*v*z[j+1, i] + u*v*z[j+1, i+1])
assert np.abs(expect - depth).max() < 1e-4, np.abs(expect - depth).max()
print('OK')
)",
                                       dir.path());
    EXPECT_EQ(verdict, "OK\n");
    status = run_exe({"mesh", "--coast", land50, "--coast-layer", "land", "--bathy", tile,
                      "--region-file", (dir / "beyond.gpkg").string(), "--hmax", "100m", "-o",
                      (dir / "b.nc").string(), "--quiet"},
                     out, err, dir.path());
    EXPECT_EQ(status, 1) << err;
    EXPECT_EQ(count_lines(err), 1) << err;
    EXPECT_NE(err.find("but the ocean of --region-file " + (dir / "beyond.gpkg").string() +
                       " reaches lon"),
              std::string::npos)
        << err;
    EXPECT_FALSE(fs::exists(dir / "b.nc"));
}
