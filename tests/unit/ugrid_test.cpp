// UGRID writer, reader and statistics. Oracles: Euler's formula, 4*pi*R^2, GeographicLib's
// ellipsoid area, the netCDF-C API reading the file back, and ../shared/tools/mesh-verify.
#include <gtest/gtest.h>

#include <netcdf.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/PolygonArea.hpp>

#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>
#include <sstream>
#include <thread>

#include "globemesh/bathymetry.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/ugrid.hpp"
#include "io_test_meshes.hpp"
#include "netcdf_handle.hpp"
#include "support.hpp"
#include "write_hooks.hpp"

using namespace globemesh;
using namespace globemesh::test;
namespace fs = std::filesystem;

namespace {

/// The face areas of a UGRID file (its variable "area"), n of them.
std::vector<double> file_areas(const fs::path &file, std::size_t n) {
    std::vector<double> area(n);
    int nc, v;
    EXPECT_EQ(nc_open(file.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    EXPECT_EQ(nc_inq_varid(nc, "area", &v), NC_NOERR);
    EXPECT_EQ(nc_get_var_double(nc, v, area.data()), NC_NOERR);
    nc_close(nc);
    return area;
}

std::vector<std::string> folder_listing(const fs::path &dir) {
    std::vector<std::string> names;
    for (const auto &e : fs::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::string file_bytes(const fs::path &p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}

std::string text_att(int nc, int var, const char *name) {
    std::size_t len = 0;
    if (nc_inq_attlen(nc, var, name, &len) != NC_NOERR)
        return "<missing>";
    std::string s(len, '\0');
    nc_get_att_text(nc, var, name, s.data());
    return s;
}

void expect_same_stats(const MeshStats &a, const MeshStats &b) {
    EXPECT_EQ(a.nodes, b.nodes);
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.boundary_edges, b.boundary_edges);
    EXPECT_EQ(a.boundary_loops, b.boundary_loops);
    EXPECT_NEAR(a.quality_min, b.quality_min, 1e-12);
    EXPECT_NEAR(a.quality_mean, b.quality_mean, 1e-12);
    EXPECT_EQ(a.quality_histogram, b.quality_histogram);
    EXPECT_NEAR(a.edge_km_min, b.edge_km_min, 1e-6);
    EXPECT_NEAR(a.edge_km_max, b.edge_km_max, 1e-6);
    EXPECT_NEAR(a.area_km2, b.area_km2, 1e-6 * a.area_km2);
    EXPECT_NEAR(a.lon_min, b.lon_min, 1e-9);
    EXPECT_NEAR(a.lat_max, b.lat_max, 1e-9);
    EXPECT_EQ(a.has_size, b.has_size);
    EXPECT_NEAR(a.size_ratio_median, b.size_ratio_median, 1e-9);
    EXPECT_NEAR(a.size_ratio_in_range, b.size_ratio_in_range, 1e-12);
}

/// Writes a small UGRID file the way another tool might, with the netCDF-C API directly.
void write_foreign(const fs::path &path, const Mesh &m, bool transposed, int start,
                   bool four_columns) {
    int nc, d_node, d_face, d_col, vx, vy, vf, topo;
    ASSERT_EQ(nc_create(path.c_str(), NC_CLOBBER, &nc), NC_NOERR);
    nc_def_dim(nc, "nodes", m.nodes.size(), &d_node);
    nc_def_dim(nc, "cells", m.faces.size(), &d_face);
    const int cols = four_columns ? 4 : 3;
    nc_def_dim(nc, "corners", cols, &d_col);
    nc_def_var(nc, "Mesh2", NC_INT, 0, nullptr, &topo);
    auto text = [&](int v, const char *n, const std::string &s) {
        nc_put_att_text(nc, v, n, s.size(), s.c_str());
    };
    text(topo, "cf_role", "mesh_topology");
    int two = 2;
    nc_put_att_int(nc, topo, "topology_dimension", NC_INT, 1, &two);
    text(topo, "node_coordinates", "Mesh2_node_x Mesh2_node_y");
    text(topo, "face_node_connectivity", "Mesh2_face_nodes");
    text(topo, "face_dimension", "cells");
    nc_def_var(nc, "Mesh2_node_x", NC_DOUBLE, 1, &d_node, &vx);
    nc_def_var(nc, "Mesh2_node_y", NC_DOUBLE, 1, &d_node, &vy);
    text(vx, "standard_name", "longitude"), text(vx, "units", "degrees_east");
    text(vy, "standard_name", "latitude"), text(vy, "units", "degrees_north");
    int dims[2] = {d_face, d_col};
    if (transposed)
        std::swap(dims[0], dims[1]);
    nc_def_var(nc, "Mesh2_face_nodes", NC_INT, 2, dims, &vf);
    text(vf, "cf_role", "face_node_connectivity");
    nc_put_att_int(nc, vf, "start_index", NC_INT, 1, &start);
    int fill = -999;
    if (four_columns)
        nc_put_att_int(nc, vf, "_FillValue", NC_INT, 1, &fill);
    int vd;
    nc_def_var(nc, "bathymetry", NC_FLOAT, 1, &d_node, &vd);
    text(vd, "mesh", "Mesh2"), text(vd, "location", "node"), text(vd, "units", "m");
    nc_enddef(nc);
    std::vector<double> x, y;
    std::vector<float> depth;
    for (const auto &v : m.nodes) {
        LonLat p = vec_to_lonlat(v);
        x.push_back(p.lon + 360.0 * (p.lon < 0)); // another tool may use [0, 360)
        y.push_back(p.lat);
        depth.push_back(float(100.0 * (1.0 + v.z)));
    }
    nc_put_var_double(nc, vx, x.data());
    nc_put_var_double(nc, vy, y.data());
    nc_put_var_float(nc, vd, depth.data());
    std::vector<int> conn(m.faces.size() * cols);
    for (std::size_t f = 0; f < m.faces.size(); ++f)
        for (int k = 0; k < cols; ++k) {
            int value = k < 3 ? int(m.faces[f][k]) + start : fill;
            if (transposed)
                conn[k * m.faces.size() + f] = value;
            else
                conn[f * cols + k] = value;
        }
    nc_put_var_int(nc, vf, conn.data());
    ASSERT_EQ(nc_close(nc), NC_NOERR);
}

} // namespace

TEST(Ugrid, closed_icosphere_passes_mesh_verify_and_round_trips_its_statistics) {
    TempDir dir;
    Mesh m = icosphere(3);
    add_fields(m);
    write_ugrid(m, dir / "ico.nc");
    expect_mesh_verify(dir / "ico.nc", "--size-var target_size");

    MeshStats s = compute_stats(m);
    EXPECT_EQ(s.faces, 1280u);
    EXPECT_EQ(s.nodes, 642u);
    EXPECT_EQ(s.edges, 1920u);
    EXPECT_EQ(long(s.nodes) - long(s.edges) + long(s.faces), 2); // Euler, closed sphere
    EXPECT_EQ(s.boundary_edges, 0u);
    EXPECT_EQ(s.boundary_loops, 0u);
    EXPECT_NEAR(s.area_km2, 4 * pi * earth_radius_km * earth_radius_km, 1e-9 * s.area_km2);
    EXPECT_TRUE(s.has_size);

    Mesh back = read_ugrid(dir / "ico.nc");
    ASSERT_EQ(back.nodes.size(), m.nodes.size());
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        EXPECT_LT(norm(back.nodes[i] - m.nodes[i]), 1e-14);
    EXPECT_EQ(back.faces, m.faces);
    ASSERT_NE(back.node_field("depth"), nullptr);
    EXPECT_EQ(back.node_field("depth")->values, m.node_field("depth")->values);
    EXPECT_EQ(back.node_field("depth")->standard_name, "sea_floor_depth_below_geoid");
    ASSERT_NE(back.face_field("quality"), nullptr);
    expect_same_stats(compute_stats(back), s);
}

// netCDF-C and HDF5 are not thread-safe: two UGRID files written at once in one process (two
// Python threads, two QGIS Processing tasks) failed with made-up errors ("String match to name
// in use", "HDF error") or crashed, and so did a NetCDF raster read through GDAL meanwhile. An
// open netCDF file holds the process's netCDF lock: a raster read and a UGRID write in other
// threads wait for it to close. Then both threads' writes and the read run at once.
TEST(Ugrid, netcdf_files_and_raster_reads_take_turns_across_threads) {
    TempDir dir;
    Mesh m = icosphere(4);
    add_fields(m);
    std::atomic<bool> closed{false}, read_early{false}, written_early{false};
    std::thread reader, writer;
    {
        io::NcHandle held; // as a writer holds its file
        reader = std::thread([&] {
            read_raster(fixture("bathy/etopo5_global_10min.nc").string());
            read_early = !closed;
        });
        writer = std::thread([&] {
            write_ugrid(m, dir / "w.nc");
            written_early = !closed;
        });
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        closed = true;
    }
    reader.join();
    writer.join();
    EXPECT_FALSE(read_early) << "a raster read while a netCDF file was open";
    EXPECT_FALSE(written_early) << "a UGRID file written while another was open";

    std::atomic<int> failures{0};
    auto writes = [&](const std::string &name) {
        for (int k = 0; k < 6; ++k)
            try {
                UgridOptions o;
                o.overwrite = true;
                write_ugrid(m, dir / name, o);
            } catch (const std::exception &e) {
                ++failures;
                ADD_FAILURE() << name << ": " << e.what();
            }
    };
    std::thread a(writes, "a.nc"), b(writes, "b.nc");
    a.join();
    b.join();
    EXPECT_EQ(failures.load(), 0);
    for (const char *name : {"a.nc", "b.nc"})
        EXPECT_EQ(read_ugrid(dir / name).faces, m.faces) << name;
}

TEST(Ugrid, size_ratio_median_is_the_median_of_all_edge_ratios) {
    // compute_stats finds the median from bin counts and the values of the middle bins only:
    // check it against sorting every ratio, for sizes putting ratios far below 1 and beyond the
    // last bin (4), for an even count and, with the edges at a pole left out (a negative target),
    // an odd one.
    Mesh m = icosphere(3);
    add_fields(m);
    Field &size = m.node_fields[1];
    auto sorted_median = [&] {
        std::set<std::pair<NodeIndex, NodeIndex>> edges;
        for (const auto &f : m.faces)
            for (int k = 0; k < 3; ++k)
                edges.insert(std::minmax(f[k], f[(k + 1) % 3]));
        std::vector<double> ratios;
        for (auto [a, b] : edges) {
            const double target = 0.5 * (size.values[a] + size.values[b]);
            if (target > 0)
                ratios.push_back(arc_km(m.nodes[a], m.nodes[b]) / target);
        }
        std::sort(ratios.begin(), ratios.end());
        const std::size_t n = ratios.size();
        return std::pair{n, n % 2 ? ratios[n / 2] : 0.5 * (ratios[n / 2] + ratios[n / 2 - 1])};
    };
    for (int spread : {0, 1, 2}) {
        for (std::size_t i = 0; i < m.nodes.size(); ++i)
            size.values[i] =
                spread == 0 ? 500.0 + 100.0 * m.nodes[i].y : 10.0 + 3000.0 * double(i % 7) / spread;
        for (bool odd : {false, true}) {
            if (odd)
                size.values[0] = -1e9; // node 0, the north pole, has 5 edges
            const auto [count, median] = sorted_median();
            EXPECT_EQ(count % 2, odd ? 1u : 0u);
            EXPECT_EQ(compute_stats(m).size_ratio_median, median)
                << "spread " << spread << " odd " << odd;
        }
    }
}

TEST(Ugrid, statistics_passed_in_the_options_are_written_as_given) {
    TempDir dir;
    Mesh m = icosphere(2);
    MeshStats s = compute_stats(m);
    s.quality_min =
        0.125; // not this mesh's: shows the writer took them instead of computing its own
    UgridOptions options;
    options.stats = &s;
    write_ugrid(m, dir / "given.nc", options);
    write_ugrid(m, dir / "own.nc");
    for (const auto &[name, expected] :
         {std::pair{"given.nc", 0.125}, std::pair{"own.nc", compute_stats(m).quality_min}}) {
        int nc;
        ASSERT_EQ(nc_open((dir / name).c_str(), NC_NOWRITE, &nc), NC_NOERR);
        double q = -1;
        EXPECT_EQ(nc_get_att_double(nc, NC_GLOBAL, "quality_min", &q), NC_NOERR);
        EXPECT_EQ(q, expected) << name;
        nc_close(nc);
    }
}

TEST(Ugrid, mesh_with_holes_keeps_tagged_boundary_loops_and_passes_mesh_verify) {
    TempDir dir;
    Mesh m = icosphere_with_holes(3);
    ASSERT_FALSE(m.boundary.empty());
    write_ugrid(m, dir / "holes.nc");
    expect_mesh_verify(dir / "holes.nc");
    MeshStats s = compute_stats(m);
    EXPECT_EQ(s.boundary_loops, 3u);
    EXPECT_EQ(s.boundary_edges, m.boundary.size());
    EXPECT_EQ(long(s.nodes) - long(s.edges) + long(s.faces), 2 - 3); // sphere with three holes

    Mesh back = read_ugrid(dir / "holes.nc");
    expect_same_stats(compute_stats(back), s);
    auto sorted = [](std::vector<BoundaryEdge> b) {
        std::vector<std::tuple<NodeIndex, NodeIndex, int>> t;
        for (auto e : b)
            t.emplace_back(e.a, e.b, int(e.tag));
        std::sort(t.begin(), t.end());
        return t;
    };
    EXPECT_EQ(sorted(back.boundary), sorted(m.boundary)); // same edges, orientation and tags
    int open = 0;
    for (auto e : back.boundary)
        open += e.tag == EdgeTag::open;
    EXPECT_GT(open, 0);
    EXPECT_LT(open, int(back.boundary.size()));
}

// A cap across the antimeridian: longitudes in [0, 360), so that no face spans the map (QGIS,
// through MDAL, drew a Pacific region's faces across 180 as bands over the whole world), as the
// model formats write them; valid by mesh-verify, which reads any longitude.
TEST(Ugrid, antimeridian_cap_passes_mesh_verify_with_longitudes_in_0_to_360) {
    TempDir dir;
    Mesh m = icosphere_cap(4, 180, 0, 30);
    write_ugrid(m, dir / "pacific.nc");
    expect_mesh_verify(dir / "pacific.nc", "--size-var target_size");
    int nc, v;
    ASSERT_EQ(nc_open((dir / "pacific.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
    std::vector<double> node_lon;
    for (const char *name : {"mesh_node_lon", "mesh_face_lon", "mesh_edge_lon"}) {
        ASSERT_EQ(nc_inq_varid(nc, name, &v), NC_NOERR);
        std::size_t n;
        int dim;
        nc_inq_vardimid(nc, v, &dim);
        nc_inq_dimlen(nc, dim, &n);
        std::vector<double> lon(n);
        nc_get_var_double(nc, v, lon.data());
        for (double x : lon) {
            EXPECT_GE(x, 145.0) << name;
            EXPECT_LE(x, 215.0) << name;
        }
        if (node_lon.empty())
            node_lon = lon;
    }
    nc_close(nc);
    for (const auto &f : m.faces) {
        const auto [lo, hi] = std::minmax({node_lon[f[0]], node_lon[f[1]], node_lon[f[2]]});
        EXPECT_LT(hi - lo, 180.0);
    }
}

TEST(Ugrid, file_carries_every_connectivity_start_index_crs_and_only_int_float_double_data) {
    TempDir dir;
    Mesh m = icosphere_with_holes(2);
    m.attributes = {{"coast_file", "land.gpkg"}, {"min size km", "10"}};
    UgridOptions o;
    o.history = "globemesh mesh --coast land.gpkg -o x.nc (2024-01-01)";
    write_ugrid(m, dir / "m.nc", o);
    int nc, topo, crs, lon;
    ASSERT_EQ(nc_open((dir / "m.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
    int format;
    nc_inq_format(nc, &format);
    EXPECT_EQ(format, NC_FORMAT_NETCDF4);
    ASSERT_EQ(nc_inq_varid(nc, "mesh", &topo), NC_NOERR);
    EXPECT_EQ(text_att(nc, topo, "cf_role"), "mesh_topology");
    EXPECT_EQ(text_att(nc, topo, "node_coordinates"), "mesh_node_lon mesh_node_lat");
    for (const char *role :
         {"face_node_connectivity", "edge_node_connectivity", "face_edge_connectivity",
          "face_face_connectivity", "edge_face_connectivity", "boundary_node_connectivity"}) {
        std::string name = text_att(nc, topo, role);
        int v;
        ASSERT_EQ(nc_inq_varid(nc, name.c_str(), &v), NC_NOERR) << role;
        EXPECT_EQ(text_att(nc, v, "cf_role"), role);
        int start = -7;
        EXPECT_EQ(nc_get_att_int(nc, v, "start_index", &start), NC_NOERR) << role;
        EXPECT_EQ(start, 0);
    }
    ASSERT_EQ(nc_inq_varid(nc, "mesh_node_lon", &lon), NC_NOERR);
    EXPECT_EQ(text_att(nc, lon, "grid_mapping"), "crs");
    ASSERT_EQ(nc_inq_varid(nc, "crs", &crs), NC_NOERR);
    EXPECT_EQ(text_att(nc, crs, "EPSG_code"), "EPSG:4326");
    EXPECT_EQ(text_att(nc, crs, "grid_mapping_name"), "latitude_longitude");
    int epsg = 0;
    nc_get_att_int(nc, crs, "epsg", &epsg);
    EXPECT_EQ(epsg, 4326);
    EXPECT_EQ(text_att(nc, NC_GLOBAL, "Conventions"), "CF-1.8 UGRID-1.0");
    EXPECT_EQ(text_att(nc, NC_GLOBAL, "history"), o.history);
    EXPECT_EQ(text_att(nc, NC_GLOBAL, "coast_file"), "land.gpkg");
    EXPECT_EQ(text_att(nc, NC_GLOBAL, "min_size_km"), "10");
    EXPECT_NE(text_att(nc, NC_GLOBAL, "source").find("globemesh"), std::string::npos);
    int faces = 0;
    nc_get_att_int(nc, NC_GLOBAL, "face_count", &faces);
    EXPECT_EQ(std::size_t(faces), m.faces.size());
    int nvars;
    nc_inq_nvars(nc, &nvars);
    int data_vars = 0;
    for (int v = 0; v < nvars; ++v) {
        nc_type t;
        nc_inq_vartype(nc, v, &t);
        EXPECT_TRUE(t == NC_INT || t == NC_FLOAT || t == NC_DOUBLE)
            << "variable " << v << " type " << t;
        if (text_att(nc, v, "mesh") == "mesh")
            ++data_vars;
    }
    EXPECT_EQ(data_vars, 5); // depth, target_size, quality, area, boundary_tag
    int tag;
    ASSERT_EQ(nc_inq_varid(nc, "boundary_tag", &tag), NC_NOERR);
    EXPECT_EQ(text_att(nc, tag, "flag_meanings"), "interior coast open");
    EXPECT_EQ(text_att(nc, tag, "location"), "edge");
    nc_close(nc);
}

TEST(Ugrid, face_areas_are_geodesic_and_tile_the_wgs84_ellipsoid) {
    TempDir dir;
    write_ugrid(icosphere(3), dir / "ico.nc");
    int nc, v, dim;
    ASSERT_EQ(nc_open((dir / "ico.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "area", &v), NC_NOERR);
    EXPECT_EQ(text_att(nc, v, "units"), "m2");
    nc_inq_vardimid(nc, v, &dim);
    std::size_t n;
    nc_inq_dimlen(nc, dim, &n);
    std::vector<double> area(n);
    nc_get_var_double(nc, v, area.data());
    nc_close(nc);
    double total = 0;
    for (double a : area)
        total += a;
    EXPECT_NEAR(total, GeographicLib::Geodesic::WGS84().EllipsoidArea(), 1e-8 * total);
}

namespace {

/// `m` turned about the polar axis by `angle` radians.
Mesh turned(Mesh m, double angle) {
    for (Vec3 &p : m.nodes)
        p = {std::cos(angle) * p.x - std::sin(angle) * p.y,
             std::sin(angle) * p.x + std::cos(angle) * p.y, p.z};
    return m;
}

} // namespace

// The writer solves each edge's geodesic problem once for its two faces; GeographicLib's
// PolygonArea, face by face, is the independent reference. The meshes have faces with a corner at
// a pole, faces across lon 0 and 180, and (without pole nodes) a face round each pole. Turned by
// a hair, the corners on lon 0 and 180 come within rounding of them on either side (the writer
// finds the faces that cannot cross lon 0 without their longitudes).
TEST(Ugrid, each_face_area_is_polygonarea_of_its_corners) {
    // Each mesh with the number of its faces that go round a pole without a corner on it.
    std::vector<std::pair<Mesh, int>> meshes;
    for (const double angle : {0.0, 1e-16, -1e-16, 1e-13, -1e-13, 5e-12, -5e-12}) {
        meshes.emplace_back(turned(icosphere(3), angle), 0);
        meshes.emplace_back(turned(icosphere_without_pole_nodes(3), angle), 2);
    }
    for (const auto &[m, round_pole_expected] : meshes) {
        TempDir dir;
        write_ugrid(m, dir / "ico.nc");
        const std::vector<double> area = file_areas(dir / "ico.nc", m.faces.size());
        int round_pole = 0;
        for (std::size_t f = 0; f < m.faces.size(); ++f) {
            GeographicLib::PolygonArea poly(GeographicLib::Geodesic::WGS84());
            for (NodeIndex k : m.faces[f]) {
                const LonLat p = vec_to_lonlat(m.nodes[k]);
                poly.AddPoint(p.lat, p.lon);
            }
            double perimeter, expected;
            poly.Compute(false, true, perimeter, expected);
            // Only the rounding of the edges' S12 terms (each up to a quarter of the ellipsoid,
            // 1.3e14 m2, so a few 0.01 m2) may differ.
            EXPECT_NEAR(area[f], std::fabs(expected), 0.1) << "face " << f;
            const Vec3 &a = m.nodes[m.faces[f][0]], &b = m.nodes[m.faces[f][1]],
                       &c = m.nodes[m.faces[f][2]];
            for (const Vec3 pole : {Vec3{0, 0, 1}, Vec3{0, 0, -1}})
                round_pole += dot(pole, cross(a, b)) > 0 && dot(pole, cross(b, c)) > 0 &&
                              dot(pole, cross(c, a)) > 0;
        }
        EXPECT_EQ(round_pole, round_pole_expected);
    }
}

TEST(Ugrid, face_areas_asked_for_are_the_files_own) {
    // Several blocks of faces (written on every core), the classic and the netCDF-4 writer.
    const Mesh m = icosphere(6);
    for (const bool classic : {false, true}) {
        TempDir dir;
        std::vector<double> given = {1, 2, 3}; // replaced
        UgridOptions o;
        o.classic = classic;
        o.face_areas_m2 = &given;
        write_ugrid(m, dir / "ico.nc", o);
        EXPECT_EQ(given, file_areas(dir / "ico.nc", m.faces.size()));
    }
}

TEST(Ugrid, same_mesh_gives_identical_bytes) {
    TempDir dir;
    Mesh m = icosphere_with_holes(2);
    write_ugrid(m, dir / "a.nc");
    write_ugrid(m, dir / "b.nc");
    EXPECT_EQ(file_bytes(dir / "a.nc"), file_bytes(dir / "b.nc"));
    UgridOptions classic;
    classic.classic = true;
    write_ugrid(m, dir / "c.nc", classic);
    write_ugrid(m, dir / "d.nc", classic);
    EXPECT_EQ(file_bytes(dir / "c.nc"), file_bytes(dir / "d.nc"));
}

// netCDF-4 variables are shuffled and deflated a chunk at a time on every core and stored as
// whole chunks (hdf5_chunks.hpp); classic ones go through netCDF-C as they are. On a mesh of
// several chunks a variable, with a partial last chunk, netCDF-C (HDF5's own filters) must read
// every value of the first exactly as of the second, each variable must declare the filters
// its chunks were made with, and two runs must give the same bytes, whatever the threads did.
TEST(Ugrid, netcdf4_chunks_written_on_every_core_read_back_as_the_classic_file) {
    TempDir dir;
    const Mesh m = icosphere_with_holes(7); // over 65,536 rows in the node, face and edge variables
    UgridOptions classic;
    classic.classic = true;
    write_ugrid(m, dir / "a.nc");
    write_ugrid(m, dir / "b.nc");
    write_ugrid(m, dir / "c.nc", classic);
    EXPECT_EQ(file_bytes(dir / "a.nc"), file_bytes(dir / "b.nc"));
    int a, c, nvars;
    ASSERT_EQ(nc_open((dir / "a.nc").c_str(), NC_NOWRITE, &a), NC_NOERR);
    ASSERT_EQ(nc_open((dir / "c.nc").c_str(), NC_NOWRITE, &c), NC_NOERR);
    ASSERT_EQ(nc_inq_nvars(a, &nvars), NC_NOERR);
    std::size_t multi_chunk = 0;
    for (int v = 0; v < nvars; ++v) {
        char name[NC_MAX_NAME + 1];
        int ndims, dims[NC_MAX_VAR_DIMS], vc;
        ASSERT_EQ(nc_inq_var(a, v, name, nullptr, &ndims, dims, nullptr), NC_NOERR);
        SCOPED_TRACE(name);
        ASSERT_EQ(nc_inq_varid(c, name, &vc), NC_NOERR);
        std::size_t values = 1, rows = 1;
        for (int k = 0; k < ndims; ++k) {
            std::size_t len;
            nc_inq_dimlen(a, dims[k], &len);
            values *= len;
            if (k == 0)
                rows = len;
        }
        std::vector<double> from_a(values), from_c(values);
        ASSERT_EQ(nc_get_var_double(a, v, from_a.data()), NC_NOERR);
        ASSERT_EQ(nc_get_var_double(c, vc, from_c.data()), NC_NOERR);
        EXPECT_EQ(std::memcmp(from_a.data(), from_c.data(), values * sizeof(double)), 0);
        if (ndims == 0)
            continue;
        int shuffle, deflate, level, storage;
        std::size_t chunk[NC_MAX_VAR_DIMS];
        ASSERT_EQ(nc_inq_var_deflate(a, v, &shuffle, &deflate, &level), NC_NOERR);
        ASSERT_EQ(nc_inq_var_chunking(a, v, &storage, chunk), NC_NOERR);
        EXPECT_TRUE(shuffle && deflate && level == 1 && storage == NC_CHUNKED);
        EXPECT_EQ(chunk[0], std::min<std::size_t>(rows, 65536));
        multi_chunk += rows > 65536 && rows % 65536 != 0;
    }
    nc_close(a);
    nc_close(c);
    EXPECT_GE(multi_chunk, 10u); // coordinates, connectivities and fields of nodes, faces and edges
    expect_mesh_verify(dir / "a.nc");
}

// A field named as a dimension or a fixed variable gets a suffix, in both formats: netCDF-4
// would store a variable named as a dimension under another name in HDF5, and the chunks are
// written by name (hdf5_chunks.hpp), so they would go to the dimension's own dataset.
TEST(Ugrid, fields_named_as_dimensions_or_variables_are_written_under_suffixed_names) {
    TempDir dir;
    Mesh m = icosphere(2);
    for (const char *name : {"Two", "nMesh_node", "quality"}) {
        Field f{name, name, "1", "", {}};
        for (const Vec3 &p : m.nodes)
            f.values.push_back(p.x + 2 * p.y + 3 * p.z);
        m.node_fields.push_back(f);
    }
    Field f{"nMesh_face", "faces", "1", "", {}};
    for (std::size_t i = 0; i < m.faces.size(); ++i)
        f.values.push_back(double(i));
    m.face_fields.push_back(f);
    for (const bool classic : {false, true}) {
        SCOPED_TRACE(classic ? "classic" : "netcdf4");
        UgridOptions o;
        o.classic = classic;
        write_ugrid(m, dir / "o.nc", o);
        int nc;
        ASSERT_EQ(nc_open((dir / "o.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
        auto values = [&](const char *name) {
            int v;
            std::size_t len = 0;
            int dim;
            std::vector<double> out;
            if (nc_inq_varid(nc, name, &v) != NC_NOERR || nc_inq_vardimid(nc, v, &dim) != NC_NOERR)
                return out;
            nc_inq_dimlen(nc, dim, &len);
            out.resize(len);
            EXPECT_EQ(nc_get_var_double(nc, v, out.data()), NC_NOERR);
            return out;
        };
        EXPECT_EQ(values("Two_node"), m.node_fields[0].values);
        EXPECT_EQ(values("nMesh_node_node"), m.node_fields[1].values);
        EXPECT_EQ(values("quality_node"), m.node_fields[2].values);
        EXPECT_EQ(values("nMesh_face_face"), m.face_fields[0].values);
        EXPECT_EQ(values("Two"), std::vector<double>{}); // a dimension, no variable
        EXPECT_EQ(values("quality").size(), m.faces.size());
        nc_close(nc);
        fs::remove(dir / "o.nc");
    }
}

TEST(Ugrid, classic_format_is_netcdf3_and_reads_back_the_same) {
    TempDir dir;
    Mesh m = icosphere_with_holes(2);
    UgridOptions o;
    o.classic = true;
    write_ugrid(m, dir / "c.nc", o);
    int nc, format;
    ASSERT_EQ(nc_open((dir / "c.nc").c_str(), NC_NOWRITE, &nc), NC_NOERR);
    nc_inq_format(nc, &format);
    nc_close(nc);
    EXPECT_TRUE(format == NC_FORMAT_CLASSIC || format == NC_FORMAT_64BIT_OFFSET);
    expect_mesh_verify(dir / "c.nc");
    expect_same_stats(compute_stats(read_ugrid(dir / "c.nc")), compute_stats(m));
}

TEST(Ugrid, reads_one_based_four_column_file_with_fill_value_from_another_tool) {
    TempDir dir;
    Mesh m = icosphere(2);
    write_foreign(dir / "other.nc", m, false, 1, true);
    expect_mesh_verify(dir / "other.nc");
    Mesh back = read_ugrid(dir / "other.nc");
    EXPECT_EQ(back.faces, m.faces);
    ASSERT_EQ(back.nodes.size(), m.nodes.size());
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
        EXPECT_LT(norm(back.nodes[i] - m.nodes[i]), 1e-13);
    ASSERT_NE(back.node_field("bathymetry"), nullptr);
    expect_same_stats(compute_stats(back), compute_stats(m));
}

TEST(Ugrid, reads_transposed_connectivity_named_by_face_dimension) {
    TempDir dir;
    Mesh m = icosphere(2);
    write_foreign(dir / "t.nc", m, true, 0, false);
    expect_mesh_verify(dir / "t.nc");
    EXPECT_EQ(read_ugrid(dir / "t.nc").faces, m.faces);
}

TEST(Ugrid, out_of_range_index_and_non_ugrid_files_are_errors_not_read) {
    TempDir dir;
    Mesh m = icosphere(1);
    m.nodes.pop_back(); // the faces now reference a node that is not in the file
    write_foreign(dir / "bad.nc", m, false, 1, false);
    const std::string message =
        test::thrown_message<DataError>([&] { read_ugrid(dir / "bad.nc"); });
    EXPECT_NE(message.find("outside [1, 41]"), std::string::npos) << message;
    std::ofstream(dir / "text.nc") << "not netcdf";
    EXPECT_THROW(read_ugrid(dir / "text.nc"), IoError);
    EXPECT_THROW(read_ugrid(dir / "missing.nc"), IoError);
}

TEST(Ugrid, existing_output_is_refused_without_overwrite_and_replaced_with_it) {
    TempDir dir;
    std::ofstream(dir / "out.nc") << "keep me";
    EXPECT_THROW(write_ugrid(icosphere(1), dir / "out.nc"), IoError);
    EXPECT_EQ(file_bytes(dir / "out.nc"), "keep me");
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"out.nc"});
    UgridOptions o;
    o.overwrite = true;
    write_ugrid(icosphere(1), dir / "out.nc", o);
    EXPECT_EQ(read_ugrid(dir / "out.nc").faces.size(), 80u);
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"out.nc"});
}

TEST(Ugrid, unwritable_or_missing_folder_is_an_io_error_and_leaves_nothing) {
    TempDir dir;
    EXPECT_THROW(write_ugrid(icosphere(1), dir / "no/such/folder/out.nc"), IoError);
    fs::create_directory(dir / "ro");
    fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    if (::geteuid() != 0) {
        EXPECT_THROW(write_ugrid(icosphere(1), dir / "ro/out.nc"), IoError);
        EXPECT_TRUE(folder_listing(dir / "ro").empty());
    } else {
        // root ignores permission bits: /proc refuses new files whatever the user.
        EXPECT_THROW(write_ugrid(icosphere(1), "/proc/globemesh-io-test.nc"), IoError);
        EXPECT_FALSE(fs::exists("/proc/globemesh-io-test.nc"));
    }
    fs::permissions(dir / "ro", fs::perms::owner_all);
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"ro"});
}

TEST(Ugrid, run_cancelled_during_writing_leaves_no_partial_or_temporary_file) {
    TempDir dir;
    UgridOptions o;
    bool hook_ran = false;
    const detail::PartialWriteHook hook([&] {
        hook_ran = true;
        EXPECT_EQ(folder_listing(dir.path()).size(), 1u); // the temporary file, being written
        EXPECT_FALSE(fs::exists(dir / "out.nc"));
        throw Cancelled();
    });
    EXPECT_THROW(write_ugrid(icosphere(2), dir / "out.nc", o), Cancelled);
    EXPECT_TRUE(hook_ran);
    EXPECT_TRUE(folder_listing(dir.path()).empty());
    o.classic = true;
    EXPECT_THROW(write_ugrid(icosphere(2), dir / "out.nc", o), Cancelled);
    EXPECT_TRUE(folder_listing(dir.path()).empty());
}

// A full disk, on a 1 MiB tmpfs mounted in a child process's own mount namespace (root only;
// skipped elsewhere). Files of increasing size fail in a block's write. Then one netCDF-4 file
// that fits is written after fillers that leave it a little less room each time, down to none
// for its data: some of those fail in the final flush, which writes HDF5's metadata (the chunk
// indexes) after the data. Each must give an IoError saying the disk is full and leave no file,
// and the process must then exit normally: a flush that failed while closing left HDF5 holding
// the file, and HDF5 crashed closing it again at exit (netcdf_handle.hpp, hdf5_chunks.hpp).
TEST(Ugrid, a_full_disk_is_an_io_error_with_no_file_left_and_a_clean_exit) {
    TempDir dir;
    const fs::path disk = dir / "disk", log = dir / "log.txt";
    fs::create_directory(disk);
    constexpr int cannot_mount = 77;
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        if (unshare(CLONE_NEWNS) != 0 ||
            mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0 ||
            mount("tmpfs", disk.c_str(), "tmpfs", 0, "size=1m") != 0)
            _exit(cannot_mount);
        std::ofstream out(log);
        for (const bool classic : {false, true})
            for (int level = 4; level <= 7; ++level) {
                UgridOptions o;
                o.classic = classic;
                out << (classic ? "classic" : "netcdf4") << " level " << level << ": ";
                try {
                    write_ugrid(icosphere(level), disk / "o.nc", o);
                    out << "written";
                    fs::remove(disk / "o.nc");
                } catch (const IoError &e) {
                    out << "error " << e.what();
                }
                out << (fs::is_empty(disk) ? "" : " FILES LEFT") << "\n";
            }
        const Mesh m = icosphere(5);
        write_ugrid(m, disk / "o.nc", {});
        const auto size = std::uintmax_t(fs::file_size(disk / "o.nc"));
        fs::remove(disk / "o.nc");
        for (std::uintmax_t short_by = 0; short_by <= 64 * 1024; short_by += 4096) {
            {
                std::ofstream filler(disk / "filler", std::ios::binary);
                filler << std::string(std::size_t((1u << 20) - size - 8192 + short_by), '\0');
            }
            out << "netcdf4 short by " << short_by << ": ";
            try {
                write_ugrid(m, disk / "o.nc", {});
                out << "written";
                fs::remove(disk / "o.nc");
            } catch (const IoError &e) {
                out << "error " << e.what();
            }
            fs::remove(disk / "filler");
            out << (fs::is_empty(disk) ? "" : " FILES LEFT") << "\n";
        }
        out.close();
        umount(disk.c_str());
        std::exit(0); // through the exit handlers, HDF5's among them
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    if (WIFEXITED(status) && WEXITSTATUS(status) == cannot_mount)
        GTEST_SKIP() << "cannot mount a small tmpfs here (needs root and a mount namespace)";
    const std::string text = file_bytes(log);
    ASSERT_TRUE(WIFEXITED(status))
        << "the process died of signal " << WTERMSIG(status) << " after:\n"
        << text;
    EXPECT_EQ(WEXITSTATUS(status), 0) << text;
    int full = 0, short_written = 0;
    std::set<std::string> short_failed_at; // the steps where the one file failed
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        EXPECT_EQ(line.find("FILES LEFT"), std::string::npos) << line;
        const bool short_run = line.find("short by") != std::string::npos;
        if (line.find("error") == std::string::npos) {
            short_written += short_run;
            continue;
        }
        ++full;
        EXPECT_TRUE(line.find("(the disk is full)") != std::string::npos ||
                    line.find("No space left on device") != std::string::npos)
            << line;
        if (short_run)
            short_failed_at.insert(line.substr(line.rfind(": ", line.find(": HDF error") - 1)));
    }
    EXPECT_GE(full, 4) << "too few of the files filled the disk:\n" << text;
    EXPECT_GE(short_written, 1) << "the file never fitted:\n" << text;
    EXPECT_GE(short_failed_at.size(), 3u)
        << "the fillers did not stop the file at different steps:\n"
        << text;
}

// The writer reports the share of its rows written, and a callback that returns false stops it
// at once: nothing left behind, Cancelled rather than an error.
TEST(Ugrid, reports_its_progress_and_stops_when_asked) {
    TempDir dir;
    const Mesh m = icosphere(7); // 163,842 nodes: several blocks of 65,536 rows a variable
    for (const bool classic : {false, true}) {
        SCOPED_TRACE(classic ? "classic" : "netcdf4");
        UgridOptions o;
        o.classic = classic;
        std::vector<double> seen;
        o.progress = [&](double f, std::string_view stage) {
            EXPECT_EQ(stage, "write_ugrid");
            seen.push_back(f);
            return true;
        };
        write_ugrid(m, dir / "o.nc", o);
        ASSERT_GE(seen.size(), 20u);
        EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
        EXPECT_GT(seen.front(), 0.0);
        EXPECT_EQ(seen.back(), 1.0); // every row counted once
        fs::remove(dir / "o.nc");
        int calls = 0;
        o.progress = [&](double, std::string_view) { return ++calls < 3; };
        EXPECT_THROW(write_ugrid(m, dir / "o.nc", o), Cancelled);
        EXPECT_EQ(calls, 3);
        EXPECT_TRUE(folder_listing(dir.path()).empty());
    }
}

// A symbolic link as the target is written through (as the shell's > does): the link stays and
// the file it names gets the content. Before, the rename replaced the link, and with --overwrite
// "--report /dev/stdout" replaced the system's /dev/stdout link with a regular file.
TEST(OutputFile, a_symbolic_link_is_written_through_and_kept) {
    TempDir dir;
    std::ofstream(dir / "real.json") << "old";
    fs::create_symlink("real.json", dir / "link.json");
    OutputFile::write_text(dir / "link.json", "new", true);
    EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
    EXPECT_EQ(file_bytes(dir / "real.json"), "new");
    EXPECT_THROW(OutputFile::write_text(dir / "link.json", "x", false), IoError); // exists
    EXPECT_EQ(folder_listing(dir.path()), (std::vector<std::string>{"link.json", "real.json"}));
}

// A device or a pipe takes text as it is (--report /dev/stdout) and is refused as a file
// output (a NetCDF or GeoPackage cannot be streamed), with or without overwrite; it is never
// replaced.
TEST(OutputFile, a_device_takes_text_and_is_refused_as_a_file) {
    ASSERT_TRUE(OutputFile::is_stream("/dev/null"));
    OutputFile::write_text("/dev/null", "{}\n", false);
    for (bool overwrite : {false, true}) {
        const std::string m = test::thrown_message<IoError>(
            [&] { OutputFile out("/dev/null", overwrite, "UGRID output"); },
            "a device as a file output");
        EXPECT_NE(m.find("/dev/null is not a regular file"), std::string::npos) << m;
    }
    EXPECT_EQ(fs::status("/dev/null").type(), fs::file_type::character);
    EXPECT_FALSE(OutputFile::is_stream(fs::temp_directory_path()));
}

TEST(OutputFile, write_text_is_atomic_and_refuses_existing_files) {
    TempDir dir;
    OutputFile::write_text(dir / "r.json", "{}\n", false);
    EXPECT_EQ(file_bytes(dir / "r.json"), "{}\n");
    EXPECT_THROW(OutputFile::write_text(dir / "r.json", "x", false), IoError);
    OutputFile::write_text(dir / "r.json", "[]\n", true);
    EXPECT_EQ(file_bytes(dir / "r.json"), "[]\n");
    {
        OutputFile abandoned(dir / "never.txt", false);
        std::ofstream(abandoned.temp_path()) << "partial";
    }
    EXPECT_EQ(folder_listing(dir.path()), std::vector<std::string>{"r.json"});
}
