// Tests of bathymetry/: synthetic rasters written here with GDAL whose values are known exactly,
// and the real ETOPO5 fixtures checked against an independent read (netCDF-C coordinates and
// values, GDALRasterIO of single pixels).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <netcdf.h>
#include <ogr_srs_api.h>

#include "globemesh/bathymetry.hpp"
#include "globemesh/error.hpp"
#include "ring_through.hpp"
#include "support.hpp"

using namespace globemesh;
using globemesh::test::fixture;
using globemesh::test::TempDir;

namespace {

struct GridSpec {
    double west, north, dx, dy; // geotransform origin and pixel size (dy > 0 means north-up)
    int nx, ny;
    int epsg = 4326;
    bool georeferenced = true;
    GDALDataType type = GDT_Float32;
    std::optional<double> nodata;
    std::optional<std::pair<double, double>> scale_offset;
    int bands = 1;
    GridSpec(double w, double n, double x, double y, int nx_, int ny_, int epsg_ = 4326)
        : west(w), north(n), dx(x), dy(y), nx(nx_), ny(ny_), epsg(epsg_) {}
};

/// Writes a GeoTIFF whose pixel (i, j) holds value(x_centre, y_centre) (CRS units).
void write_tiff(const std::string &path, const GridSpec &s,
                const std::function<double(double, double)> &value) {
    GDALAllRegister();
    GDALDriverH drv = GDALGetDriverByName("GTiff");
    GDALDatasetH ds = GDALCreate(drv, path.c_str(), s.nx, s.ny, s.bands, s.type, nullptr);
    ASSERT_NE(ds, nullptr);
    if (s.georeferenced) {
        double gt[6] = {s.west, s.dx, 0, s.north, 0, -s.dy};
        GDALSetGeoTransform(ds, gt);
        OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
        OSRImportFromEPSG(srs, s.epsg);
        GDALSetSpatialRef(ds, srs);
        OSRRelease(srs);
    }
    std::vector<double> row(static_cast<std::size_t>(s.nx));
    for (int b = 1; b <= s.bands; ++b) {
        GDALRasterBandH band = GDALGetRasterBand(ds, b);
        if (s.nodata)
            GDALSetRasterNoDataValue(band, *s.nodata);
        if (s.scale_offset) {
            GDALSetRasterScale(band, s.scale_offset->first);
            GDALSetRasterOffset(band, s.scale_offset->second);
        }
        for (int j = 0; j < s.ny; ++j) {
            for (int i = 0; i < s.nx; ++i)
                row[static_cast<std::size_t>(i)] =
                    value(s.west + (i + 0.5) * s.dx, s.north - (j + 0.5) * s.dy);
            ASSERT_EQ(
                GDALRasterIO(band, GF_Write, 0, j, s.nx, 1, row.data(), s.nx, 1, GDT_Float64, 0, 0),
                CE_None);
        }
    }
    GDALClose(ds);
}

/// The value a Float32 raster stores for v.
double f32(double v) {
    return static_cast<double>(static_cast<float>(v));
}

MeshOptions options_for(const std::string &path) {
    MeshOptions o;
    o.bathy = path;
    return o;
}

/// One pixel of a raster read with GDALRasterIO as Float64, for independent checks.
double gdal_pixel(const std::string &path, int i, int j) {
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
    double v = std::nan("");
    if (ds) {
        if (GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, i, j, 1, 1, &v, 1, 1, GDT_Float64, 0,
                         0) != CE_None)
            v = std::nan("");
        GDALClose(ds);
    }
    return v;
}

} // namespace

TEST(Bathymetry, linear_slope_is_exact_at_nodes_and_inside_cells) {
    TempDir dir;
    const std::string path = (dir / "slope.tif").string();
    // Centres at multiples of 0.25 degrees: the plane has values exact in float.
    auto plane = [](double lon, double lat) { return -4000.0 + 20.0 * lon + 10.0 * lat; };
    write_tiff(path, {10, 50, 0.5, 0.5, 21, 15}, plane);
    Raster r = read_raster(path);
    ASSERT_EQ(r.nlon(), 21u);
    ASSERT_EQ(r.nlat(), 15u);
    EXPECT_FALSE(r.global());
    for (std::size_t j = 0; j < r.nlat(); ++j)
        for (std::size_t i = 0; i < r.nlon(); ++i) {
            double lon = 10.25 + 0.5 * static_cast<double>(i),
                   lat = 49.75 - 0.5 * static_cast<double>(j);
            EXPECT_NEAR(r.elevation_m(lon, lat), plane(lon, lat), 1e-9);
            EXPECT_NEAR(r.elevation_m(lonlat_to_vec(lon, lat)), plane(lon, lat), 1e-9);
            EXPECT_NEAR(r.depth_m(lonlat_to_vec(lon, lat)), -plane(lon, lat), 1e-9);
        }
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> ulon(10.25, 20.25), ulat(42.75, 49.75);
    for (int k = 0; k < 1000; ++k) {
        double lon = ulon(rng), lat = ulat(rng);
        EXPECT_NEAR(r.elevation_m(lon, lat), plane(lon, lat), 1e-9) << lon << " " << lat;
    }
    // Half a cell beyond the outermost centres holds the edge, and a quarter of a cell past the
    // cells' edges (Raster::edge_margin); farther is outside.
    EXPECT_NEAR(r.elevation_m(10.1, 45.25), plane(10.25, 45.25), 1e-9);
    EXPECT_NEAR(r.elevation_m(9.9, 45.25), plane(10.25, 45.25), 1e-9);
    EXPECT_NEAR(r.elevation_m(15.25, 50.1), plane(15.25, 49.75), 1e-9);
    EXPECT_NEAR(r.elevation_m(20.6, 42.6), plane(20.25, 42.75), 1e-9);
    EXPECT_TRUE(r.contains(9.9, 45.0) && r.contains(20.6, 42.6));
    EXPECT_TRUE(std::isnan(r.elevation_m(9.85, 45.0)));
    EXPECT_TRUE(std::isnan(r.elevation_m(15.0, 50.15)));
    EXPECT_TRUE(std::isnan(r.elevation_m(20.65, 45.0)));
    EXPECT_FALSE(r.contains(9.85, 45.0) || r.contains(15.0, 50.15));
    EXPECT_TRUE(std::isnan(r.elevation_m(-165.0, 45.0)));
}

TEST(Bathymetry, bilinear_function_is_reproduced_exactly_inside_cells) {
    TempDir dir;
    const std::string path = (dir / "bilinear.tif").string();
    auto f = [](double lon, double lat) {
        return 3.0 * (lon - 10.0) * (lat - 40.0) - 2.0 * lon + lat - 500.0;
    };
    write_tiff(path, {10, 50, 0.5, 0.5, 21, 15}, f);
    Raster r = read_raster(path);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ulon(10.25, 20.25), ulat(42.75, 49.75);
    for (int k = 0; k < 1000; ++k) {
        double lon = ulon(rng), lat = ulat(rng);
        // Bilinear interpolation reproduces a*lon*lat + b*lon + c*lat + d exactly within a cell.
        EXPECT_NEAR(r.elevation_m(lon, lat), f(lon, lat), 1e-9) << lon << " " << lat;
    }
}

TEST(Bathymetry, gaussian_seamount_matches_its_formula) {
    TempDir dir;
    const std::string path = (dir / "seamount.tif").string();
    auto z = [](double lon, double lat) {
        double r2 = (lon + 30) * (lon + 30) + (lat - 20) * (lat - 20);
        return -5000.0 + 4000.0 * std::exp(-r2 / (2 * 0.5 * 0.5));
    };
    write_tiff(path, {-32, 22, 0.02, 0.02, 200, 200}, z);
    Raster r = read_raster(path);
    double max_node_err = 0, max_err = 0;
    for (std::size_t j = 0; j < r.nlat(); j += 7)
        for (std::size_t i = 0; i < r.nlon(); i += 7) {
            double lon = -32 + 0.01 + 0.02 * static_cast<double>(i),
                   lat = 22 - 0.01 - 0.02 * static_cast<double>(j);
            max_node_err =
                std::max(max_node_err, std::abs(r.elevation_m(lon, lat) - f32(z(lon, lat))));
            // Between nodes: bilinear error bounded by |second derivative| * h^2 / 8.
            max_err = std::max(max_err, std::abs(r.elevation_m(lon + 0.007, lat - 0.013) -
                                                 z(lon + 0.007, lat - 0.013)));
        }
    EXPECT_LT(max_node_err, 1e-9);
    // |z''| <= 4000 / 0.25 per degree^2 = 16000; h = 0.02 deg: 16000 * 4e-4 / 8 * 2 axes = 1.6 m.
    EXPECT_LT(max_err, 1.6);
    EXPECT_NEAR(r.elevation_m(-30.01, 20.01), f32(z(-30.01, 20.01)), 1e-9);
}

TEST(Bathymetry, global_grid_in_0_360_wraps_across_the_antimeridian) {
    TempDir dir;
    const std::string path = (dir / "global360.tif").string();
    // 1-degree cells, lon 0..360; integer values so that float storage is exact.
    auto z = [](double lon, double lat) {
        return std::round(1000 * std::cos(lon * deg_to_rad) * std::cos(lat * deg_to_rad)) - 2000;
    };
    write_tiff(path, {0, 90, 1, 1, 360, 180}, z);
    MeshOptions o = options_for(path);
    Raster r = read_bathymetry(o); // covers the globe: no DataError
    ASSERT_TRUE(r.global());
    // Nodes, asked for in -180..180 longitudes.
    for (double lat : {-89.5, -30.5, 0.5, 60.5, 89.5})
        for (double lon = 0.5; lon < 360; lon += 17)
            EXPECT_NEAR(r.elevation_m(lon > 180 ? lon - 360 : lon, lat), z(lon, lat), 1e-9);
    // Across the seam between column 359 (359.5) and column 0 (0.5 == 360.5).
    for (double lon : {-0.3, 359.7, 0.2, -359.8}) {
        double u = (std::fmod(lon + 360.0, 360.0) - 359.5 + (lon > 0 && lon < 0.5 ? 360 : 0));
        if (u < 0)
            u += 360;
        double expect = (1 - u) * z(359.5, 10.5) + u * z(0.5, 10.5);
        EXPECT_NEAR(r.elevation_m(lon, 10.5), expect, 1e-9) << lon;
    }
    // Near the poles the first and last rows are held.
    EXPECT_NEAR(r.elevation_m(lonlat_to_vec(0, 90)), z(0.5, 89.5) * 0.5 + z(359.5, 89.5) * 0.5,
                1e-9);
    EXPECT_NEAR(r.elevation_m(45.5, -89.9), z(45.5, -89.5), 1e-9);
}

TEST(Bathymetry, node_registered_global_grid_drops_its_repeated_meridian) {
    TempDir dir;
    const std::string path = (dir / "nodes.tif").string();
    // 361 x 181 nodes from -180 to 180: pixel centres on whole degrees.
    auto z = [](double lon, double lat) {
        return std::round(lat * 10) + std::round(std::sin(lon * deg_to_rad) * 100);
    };
    write_tiff(path, {-180.5, 90.5, 1, 1, 361, 181}, z);
    Raster r = read_raster(path);
    EXPECT_EQ(r.nlon(), 360u);
    EXPECT_TRUE(r.global());
    EXPECT_NEAR(r.elevation_m(180, 10), z(-180, 10), 1e-9);
    EXPECT_NEAR(r.elevation_m(179.5, 10), 0.5 * (z(179, 10) + z(-180, 10)), 1e-9);
    EXPECT_NEAR(r.elevation_m(0, 90), z(0, 90), 1e-9);
}

TEST(Bathymetry, projected_raster_is_read_through_a_warp_to_lonlat) {
    TempDir dir;
    const std::string path = (dir / "mercator.tif").string();
    // EPSG:3857: x is linear in longitude, so a plane in x and y is known at every lon/lat.
    const double a = 6378137.0;
    auto plane = [](double x, double y) { return -3000.0 + 1e-3 * x + 5e-4 * (y - 5e6); };
    write_tiff(path, {0, 6.0e6, 5000, 5000, 200, 200, 3857}, plane);
    Raster r = read_raster(path);
    EXPECT_NEAR(r.bounds().west, 0.0, 0.1);
    for (double lon = 1; lon <= 8; lon += 0.7)
        for (double lat = 41; lat <= 46; lat += 0.6) {
            double x = a * lon * deg_to_rad,
                   y = a * std::log(std::tan(pi / 4 + lat * deg_to_rad / 2));
            // Warp (upsampling, bilinear): exact on a plane but for float storage (1.2e-4 m);
            // our lon/lat bilinear errs by 5e-4 * y'' * dlat^2 / 8 < 1e-3 m.
            EXPECT_NEAR(r.elevation_m(lon, lat), plane(x, y), 2e-3) << lon << " " << lat;
        }
    // Beyond the source footprint there is no data.
    EXPECT_TRUE(std::isnan(r.elevation_m(-5.0, 43.0)));
}

TEST(Bathymetry, nodata_holes_give_nan_or_the_fill) {
    TempDir dir;
    const std::string path = (dir / "holes.tif").string();
    auto z = [](double lon, double lat) {
        if (lon > 2 && lon < 4 && lat > 2 && lat < 4)
            return -9999.0;
        if (lon > 6 && lat < 1)
            return std::nan("");
        return -100.0 * std::round(lon) - std::round(lat);
    };
    GridSpec s{0, 10, 0.5, 0.5, 20, 20};
    s.nodata = -9999.0;
    write_tiff(path, s, z);
    Raster r = read_raster(path);
    EXPECT_TRUE(std::isnan(r.elevation_m(3.0, 3.0)));
    EXPECT_TRUE(std::isnan(r.elevation_m(8.0, 0.5)));
    EXPECT_NEAR(r.elevation_m(7.25, 7.25), z(7.25, 7.25), 1e-9);
    // Nearest corner valid, one corner in the hole: renormalised weights of the three others.
    // Cell (1.75..2.25) x (1.75..2.25): the hole corner is (2.25, 2.25).
    double lon = 1.85, lat = 1.95, fu = (lon - 1.75) / 0.5, fv = (lat - 1.75) / 0.5;
    double w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv;
    double expect =
        (w00 * z(1.75, 1.75) + w10 * z(2.25, 1.75) + w01 * z(1.75, 2.25)) / (w00 + w10 + w01);
    EXPECT_NEAR(r.elevation_m(lon, lat), expect, 1e-9);
    // Nearest corner in the hole: no data.
    EXPECT_TRUE(std::isnan(r.elevation_m(2.2, 2.2)));
    r.set_fill_elevation_m(-42.0);
    EXPECT_EQ(r.elevation_m(3.0, 3.0), -42.0);
    EXPECT_EQ(r.depth_m(lonlat_to_vec(3.0, 3.0)), 42.0);
    EXPECT_EQ(r.elevation_m(50.0, 3.0), -42.0); // outside the raster
}

TEST(Bathymetry, scale_offset_and_depth_positive_are_honoured) {
    TempDir dir;
    const std::string path = (dir / "scaled.tif").string();
    GridSpec s{0, 10, 1, 1, 10, 10};
    s.type = GDT_Int16;
    s.scale_offset = std::make_pair(0.5, -1000.0);
    write_tiff(path, s, [](double lon, double lat) { return std::round(lon * 10 + lat); });
    Raster r = read_raster(path);
    EXPECT_NEAR(r.elevation_m(3.5, 4.5), std::round(39.5) * 0.5 - 1000.0,
                1e-9); // raw = round(3.5*10 + 4.5)
    Raster d = read_raster(path, 1, true);
    EXPECT_NEAR(d.elevation_m(3.5, 4.5), -r.elevation_m(3.5, 4.5), 1e-9);
    EXPECT_NEAR(d.depth_m(lonlat_to_vec(3.5, 4.5)), r.elevation_m(3.5, 4.5), 1e-9);
}

TEST(Bathymetry, bad_inputs_give_one_line_errors_naming_the_file_or_option) {
    TempDir dir;
    auto one_line = [](const std::string &m) { return m.find('\n') == std::string::npos; };
    const std::string bare = (dir / "bare.tif").string();
    GridSpec s{0, 10, 1, 1, 4, 4};
    s.georeferenced = false;
    write_tiff(bare, s, [](double, double) { return -1.0; });
    std::string m = test::thrown_message<DataError>([&] { read_raster(bare); },
                                                    "a raster without georeferencing");
    EXPECT_NE(m.find(bare), std::string::npos) << m;
    EXPECT_NE(m.find("georeferencing"), std::string::npos) << m;
    EXPECT_TRUE(one_line(m));
    const std::string ok = (dir / "ok.tif").string();
    write_tiff(ok, {0, 10, 1, 1, 4, 4}, [](double, double) { return -1.0; });
    // Its CRS unset on a pixel-is-point GeoTIFF (as the ETOPO5 fixture is; Python's
    // SetProjection('') does the same): the raster-type geokey stays, and GDAL reads back a
    // local CRS of unknown units that no transformation reaches (before: "cannot reproject
    // ... ENGCRS[...]").
    const std::string local = (dir / "local.tif").string();
    write_tiff(local, {0, 10, 1, 1, 4, 4}, [](double, double) { return -1.0; });
    {
        GDALDatasetH ds = GDALOpen(local.c_str(), GA_Update);
        ASSERT_NE(ds, nullptr);
        GDALSetMetadataItem(ds, "AREA_OR_POINT", "Point", nullptr);
        GDALSetProjection(ds, "");
        GDALClose(ds);
    }
    m = test::thrown_message<DataError>([&] { read_raster(local); }, "a raster in a local CRS");
    EXPECT_NE(m.find("has no georeferencing"), std::string::npos) << m;
    EXPECT_TRUE(one_line(m));
    m = test::thrown_message<UsageError>([&] { read_raster(ok, 2); }, "band 2 of 1");
    EXPECT_NE(m.find("bathy_band 2"), std::string::npos) << m;
    const std::string empty = (dir / "nodata.tif").string();
    GridSpec n{0, 10, 1, 1, 4, 4};
    n.nodata = -1.0;
    write_tiff(empty, n, [](double, double) { return -1.0; });
    EXPECT_THROW(read_raster(empty), DataError);
    EXPECT_THROW(read_raster((dir / "missing.tif").string()), IoError);
    // A regional raster does not cover the globe, nor a region beyond it, unless filled.
    MeshOptions o = options_for(ok);
    m = test::thrown_message<DataError>([&] { read_bathymetry(o); }, "a partial coverage");
    EXPECT_NE(m.find("bathy_fill_m"), std::string::npos) << m;
    EXPECT_TRUE(one_line(m));
    o.region = std::array<double, 4>{1, 7, 3, 9};
    EXPECT_NO_THROW(read_bathymetry(o));
    o.region = std::array<double, 4>{1, 7, 5, 9};
    EXPECT_THROW(read_bathymetry(o), DataError);
    o.bathy_fill_m = 30.0;
    Raster filled = read_bathymetry(o);
    EXPECT_EQ(filled.elevation_m(4.8, 8.0), -30.0);
}

TEST(Bathymetry, decimates_rasters_larger_than_the_cell_cap) {
    TempDir dir;
    const std::string path = (dir / "big.tif").string();
    auto plane = [](double lon, double lat) { return -4000.0 + 20.0 * lon + 10.0 * lat; };
    write_tiff(path, {0, 40, 0.25, 0.25, 80, 40}, plane);
    Raster r = read_raster(path, 1, false, {}, 800); // 3200 cells -> 40 x 20 averaged
    EXPECT_EQ(r.nlon(), 40u);
    EXPECT_EQ(r.nlat(), 20u);
    // The average of a plane over a 2x2 block is the plane at the block centre.
    for (double lon = 1; lon < 19; lon += 1.7)
        EXPECT_NEAR(r.elevation_m(lon, 35.3), plane(lon, 35.3), 1e-3);
}

TEST(Bathymetry, etopo5_global_netcdf_matches_its_own_coordinates_and_values) {
    const std::string path = fixture("bathy/etopo5_global_10min.nc").string();
    Raster r = read_bathymetry(options_for(path));
    EXPECT_TRUE(r.global());
    EXPECT_EQ(r.nlon(), 2160u);
    EXPECT_EQ(r.nlat(), 1080u);
    // Independent read with netCDF-C: the file's own lon/lat variables and elevation.
    int nc = -1, lon_id, lat_id, z_id;
    ASSERT_EQ(nc_open(path.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lon", &lon_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lat", &lat_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "elevation", &z_id), NC_NOERR);
    std::mt19937 rng(11);
    std::uniform_int_distribution<std::size_t> ui(0, 2159), uj(0, 1079);
    int land = 0, sea = 0;
    for (int k = 0; k < 300; ++k) {
        std::size_t idx[2] = {uj(rng), ui(rng)};
        double lon, lat, z;
        ASSERT_EQ(nc_get_var1_double(nc, lon_id, &idx[1], &lon), NC_NOERR);
        ASSERT_EQ(nc_get_var1_double(nc, lat_id, &idx[0], &lat), NC_NOERR);
        ASSERT_EQ(nc_get_var1_double(nc, z_id, idx, &z), NC_NOERR);
        EXPECT_NEAR(r.elevation_m(lonlat_to_vec(lon, lat)), z, 1e-6) << lon << " " << lat;
        (z > 0 ? land : sea)++;
    }
    nc_close(nc);
    EXPECT_GT(sea, land);                       // most of the Earth is ocean
    EXPECT_LT(r.elevation_m(-155, 0), -3000);   // central Pacific
    EXPECT_GT(r.elevation_m(86.9, 28.0), 3000); // Himalaya
}

// GDAL's block cache is capped while a raster is read (each block is read once; the default,
// 5% of the RAM, is memory that --max-memory does not see: a 40000 x 20000 GeoTIFF read coarse
// under --max-memory 1GB peaked at 1.31 GB) and restored after; a GDAL_CACHEMAX the user set
// stays. Watched from the progress callback, which runs during the read.
TEST(Bathymetry, gdal_block_cache_is_capped_while_a_raster_is_read_and_restored_after) {
    const std::string path = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    const GIntBig before = GDALGetCacheMax64();
    const GIntBig large = GIntBig{1} << 30; // 5% of a 20 GB machine
    GDALSetCacheMax64(large);
    GIntBig during = 0;
    const Progress watch = [&](double, std::string_view) {
        during = std::max(during, GDALGetCacheMax64());
        return true;
    };
    read_raster(path, 1, false, watch);
    EXPECT_GT(during, 0);
    EXPECT_LE(during, GIntBig{64} << 20);
    EXPECT_EQ(GDALGetCacheMax64(), large);
    // Under a budget, a quarter of what the raster may take.
    RasterLimits limits;
    limits.max_bytes = std::uint64_t{40} << 20;
    during = 0;
    read_raster(path, 1, false, watch, limits);
    EXPECT_LE(during, GIntBig{10} << 20);
    EXPECT_EQ(GDALGetCacheMax64(), large);
    CPLSetConfigOption("GDAL_CACHEMAX", "1024");
    during = 0;
    read_raster(path, 1, false, watch);
    EXPECT_EQ(during, large);
    CPLSetConfigOption("GDAL_CACHEMAX", nullptr);
    GDALSetCacheMax64(before);
}

TEST(Bathymetry, etopo5_nwshelf_geotiff_nodes_sit_on_whole_5_minutes) {
    const std::string path = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    MeshOptions o = options_for(path);
    // The whole file: 301 x 193 nodes, PixelIsPoint: node 0 at 12 W, 62 N.
    Raster whole = read_raster(path);
    EXPECT_EQ(whole.nlon(), 301u);
    EXPECT_EQ(whole.nlat(), 193u);
    EXPECT_NEAR(whole.lon_deg(0), -12.0, 1e-9);
    EXPECT_NEAR(whole.lat_deg(0), 62.0, 1e-9);
    // With --region only the file's nodes near the region are read (a margin of 1% of 20 degrees
    // and three 5-minute cells: 0.45 degree), still on the file's nodes.
    o.region = std::array<double, 4>{-10, 48, 10, 60};
    Raster r = read_bathymetry(o);
    const LonLatBounds b = r.bounds();
    EXPECT_LE(b.west, -10.45);
    EXPECT_GT(b.west, -10.45 - 1.0 / 12);
    EXPECT_GE(b.east, 10.45);
    EXPECT_LT(b.east, 10.45 + 1.0 / 12);
    EXPECT_LE(b.south, 47.55);
    EXPECT_GE(b.north, 60.45);
    EXPECT_LT(b.north, 60.45 + 1.0 / 12);
    const int i0 = static_cast<int>(std::lround((r.lon_deg(0) + 12) * 12)),
              j0 = static_cast<int>(std::lround((62 - r.lat_deg(0)) * 12));
    EXPECT_NEAR(r.lon_deg(0), -12.0 + i0 / 12.0, 1e-9);
    EXPECT_NEAR(r.lat_deg(0), 62.0 - j0 / 12.0, 1e-9);
    for (std::size_t j = 0; j < r.nlat(); j += 15)
        for (std::size_t i = 0; i < r.nlon(); i += 23) {
            double lon = r.lon_deg(i), lat = r.lat_deg(j);
            EXPECT_NEAR(r.elevation_m(lon, lat), gdal_pixel(path, int(i) + i0, int(j) + j0), 1e-9)
                << lon << " " << lat;
        }
    EXPECT_LT(r.elevation_m(3.0, 56.0), 0);    // North Sea
    EXPECT_GT(r.elevation_m(-4.0, 57.0), 100); // Scottish Highlands
    // The whole globe is not covered.
    EXPECT_THROW(read_bathymetry(options_for(path)), DataError);
}

namespace {

/// A VRT of nx x ny Int16 cells over the globe whose source is the whole 10-minute ETOPO5
/// fixture (2160 x 1080) stretched onto it: 69120 x 34560 declares 4.8 GB and costs nothing.
std::string huge_global_vrt(const TempDir &dir, int nx, int ny) {
    const std::string path = (dir / "huge.vrt").string();
    const double dx = 360.0 / nx, dy = 180.0 / ny;
    std::ofstream(path) << "<VRTDataset rasterXSize=\"" << nx << "\" rasterYSize=\"" << ny
                        << "\">\n"
                        << "  <SRS>EPSG:4326</SRS>\n"
                        << std::setprecision(17) << "  <GeoTransform>-180, " << dx << ", 0, 90, 0, "
                        << -dy << "</GeoTransform>\n"
                        << "  <VRTRasterBand dataType=\"Int16\" band=\"1\">\n"
                        << "    <SimpleSource>\n"
                        << "      <SourceFilename relativeToVRT=\"0\">"
                        << fixture("bathy/etopo5_global_10min.nc").string() << "</SourceFilename>\n"
                        << "      <SourceBand>1</SourceBand>\n"
                        << "      <SrcRect xOff=\"0\" yOff=\"0\" xSize=\"2160\" ySize=\"1080\"/>\n"
                        << "      <DstRect xOff=\"0\" yOff=\"0\" xSize=\"" << nx << "\" ySize=\""
                        << ny << "\"/>\n"
                        << "    </SimpleSource>\n"
                        << "  </VRTRasterBand>\n"
                        << "</VRTDataset>\n";
    return path;
}

/// The 2160 x 1080 cells of the 10-minute ETOPO5 fixture, read by GDALRasterIO alone (empty
/// when that fails).
std::vector<double> etopo5_cells() {
    const std::string source = fixture("bathy/etopo5_global_10min.nc").string();
    GDALDatasetH ds = GDALOpen(source.c_str(), GA_ReadOnly);
    if (!ds)
        return {};
    std::vector<double> cells(2160 * 1080);
    if (GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, 2160, 1080, cells.data(), 2160, 1080,
                     GDT_Float64, 0, 0) != CE_None)
        cells.clear();
    GDALClose(ds);
    return cells;
}

} // namespace

TEST(Bathymetry, four_gigabyte_raster_is_read_at_the_cell_size_asked_and_equals_its_source) {
    TempDir dir;
    const std::string vrt = huge_global_vrt(dir, 69120, 34560); // 32 x 32 copies of each cell
    RasterLimits limits;
    limits.min_cell_deg = 1.0 / 6; // the source's own 10 minutes
    limits.max_bytes = 64'000'000;
    Raster r = read_raster(vrt, 1, false, {}, limits);
    ASSERT_EQ(r.nlon(), 2160u);
    ASSERT_EQ(r.nlat(), 1080u);
    EXPECT_TRUE(r.global());
    // The average of 32 x 32 equal Int16 values is that value: every cell equals the fixture's
    // cell read independently by GDALRasterIO.
    const std::vector<double> truth = etopo5_cells();
    ASSERT_EQ(truth.size(), 2160u * 1080u);
    std::size_t differ = 0;
    for (std::size_t j = 0; j < 1080; ++j)
        for (std::size_t i = 0; i < 2160; ++i)
            differ += r.value(i, j) != truth[j * 2160 + i];
    EXPECT_EQ(differ, 0u);
    EXPECT_NEAR(r.lon_deg(0), -180 + 1.0 / 12, 1e-9);
    EXPECT_NEAR(r.lat_deg(0), 90 - 1.0 / 12, 1e-9);
}

TEST(Bathymetry, four_gigabyte_raster_beyond_the_budget_is_refused_naming_max_memory) {
    TempDir dir;
    const std::string vrt = huge_global_vrt(dir, 69120, 34560);
    MeshOptions o = options_for(vrt);
    o.hmin_km = 1;                    // cells of 0.5 km asked: more than the 2^28-cell cap
    o.max_memory_bytes = 500'000'000; // half of it for the raster: less than 2^28 floats
    const std::string m = test::thrown_message<DataError>([&] { read_bathymetry(o); },
                                                          "a 1 GiB read within a 250 MB share");
    EXPECT_NE(m.find(vrt + ": 69120 x 34560 cells"), std::string::npos) << m;
    EXPECT_NE(m.find("max_memory_bytes"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    // Coarser sizes fit: hmin 40 km asks for cells of 20 km (0.18 degree, 34.5 of the file's);
    // rows rounded up in count, columns averaged by whole blocks that divide half the globe's
    // 69120 (2^9 3^3 5): 32, no more than asked.
    o.hmin_km = 40;
    o.hmax_km = 100;
    const RasterLimits limits = bathymetry_limits(o);
    EXPECT_NEAR(limits.min_cell_deg, 20.0 / (earth_radius_km * deg_to_rad), 1e-12);
    EXPECT_EQ(limits.max_bytes, 250'000'000u);
    Raster r = read_bathymetry(o);
    const double cell = 20.0 / (earth_radius_km * deg_to_rad);
    EXPECT_EQ(r.nlon(), 69120u / 32);
    EXPECT_EQ(r.nlat(), static_cast<std::size_t>(std::ceil(180 / cell)));
    EXPECT_LE(r.dlon_deg(), cell);
}

TEST(Bathymetry, a_region_reads_only_its_window_of_a_four_gigabyte_global_raster) {
    TempDir dir;
    const std::string vrt = huge_global_vrt(dir, 69120, 34560); // cells of 1/192 degree
    MeshOptions o = options_for(vrt);
    o.hmin_km = 1; // cells of 0.5 km asked (0.0045 degree): finer than the file's
    o.max_memory_bytes = 500'000'000; // the whole globe at that size is refused (test above)
    o.region = std::array<double, 4>{-10, 40, 0, 50};
    // A run on the region reads a few million cells of the 2.4 billion, within the budget.
    const Raster run = read_bathymetry(o);
    EXPECT_LT(run.nlon() * run.nlat(), 4'500'000u);
    EXPECT_GE(run.nlon() * run.nlat(), 1920u * 1920u);
    // The window alone: the box and a margin of three of the file's cells (1/64 degree) on each
    // side, 10 + 2/64 degrees at 192 cells a degree, from column (180 - 10 - 1/64) * 192 = 32637
    // and row 7677.
    RasterLimits limits = bathymetry_limits(o);
    limits.window = LonLatBounds{-10, 40, 0, 50};
    Raster r = read_raster(vrt, 1, false, {}, limits);
    ASSERT_EQ(r.nlon(), 1926u);
    ASSERT_EQ(r.nlat(), 1926u);
    EXPECT_FALSE(r.global());
    EXPECT_NEAR(r.lon_deg(0), -10 - 1.0 / 64 + 0.5 / 192, 1e-9);
    EXPECT_NEAR(r.lat_deg(0), 50 + 1.0 / 64 - 0.5 / 192, 1e-9);
    // Every cell is its 10-minute fixture cell (32 x 32 copies each), read independently.
    const std::vector<double> truth = etopo5_cells();
    ASSERT_EQ(truth.size(), 2160u * 1080u);
    std::size_t differ = 0;
    for (std::size_t j = 0; j < r.nlat(); ++j)
        for (std::size_t i = 0; i < r.nlon(); ++i)
            differ += r.value(i, j) != truth[(j + 7677) / 32 * 2160 + (i + 32637) / 32];
    EXPECT_EQ(differ, 0u);
}

TEST(Bathymetry, a_region_across_the_antimeridian_reads_its_rows_and_wraps) {
    TempDir dir;
    auto z = [](double lon, double lat) {
        return std::round(1000 * std::cos(lon * deg_to_rad) * std::cos(lat * deg_to_rad)) - 2000;
    };
    for (double west : {0.0, -180.0}) {
        const std::string path = (dir / (west == 0 ? "g360.tif" : "g180.tif")).string();
        write_tiff(path, {west, 90, 1, 1, 360, 180}, z);
        MeshOptions o = options_for(path);
        o.region = std::array<double, 4>{170, -10, -170, 10};
        Raster r = read_bathymetry(o);
        // 1-degree cells; a margin of 1% of 20 degrees and three cells, 3.2 degrees: the cells
        // from 14 N to 14 S. In 0..360 the region lies inside the file (the cells from 166 to
        // 194 E); in -180..180 it runs across the file's seam, so every column is read and the
        // grid stays global.
        EXPECT_EQ(r.nlat(), 28u) << path;
        if (west == 0) {
            EXPECT_EQ(r.nlon(), 28u);
            EXPECT_FALSE(r.global());
        } else {
            EXPECT_EQ(r.nlon(), 360u);
            EXPECT_TRUE(r.global());
        }
        for (double lat : {-9.5, 0.5, 9.5})
            for (double lon : {170.5, 179.5, -179.5, -170.5})
                EXPECT_NEAR(r.elevation_m(lon, lat), z(lon, lat), 1e-9)
                    << path << " " << lon << " " << lat;
        // Across 180: halfway between the cells at 179.5 and -179.5.
        EXPECT_NEAR(r.elevation_m(180, 0.5), 0.5 * (z(179.5, 0.5) + z(-179.5, 0.5)), 1e-9) << path;
    }
}

TEST(Bathymetry, without_a_budget_or_a_floor_the_raster_is_read_at_full_resolution) {
    // The default limits change nothing for a raster within the cell cap.
    const std::string path = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    MeshOptions o = options_for(path);
    o.bathy_fill_m = 10.0;
    const RasterLimits limits = bathymetry_limits(o); // hmin 0, hmax 100: cells of 50 m
    EXPECT_EQ(limits.max_bytes, 0u);
    Raster r = read_bathymetry(o);
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr);
    EXPECT_EQ(r.nlon(), static_cast<std::size_t>(GDALGetRasterXSize(ds)));
    EXPECT_EQ(r.nlat(), static_cast<std::size_t>(GDALGetRasterYSize(ds)));
    GDALClose(ds);
}

// ---------------------------------------------------------------------------------------------
// CF lon/lat grids without a CRS, --bathy-srs, wrap columns, the coverage of a region's ocean

namespace {

/// A CF grid written with netCDF-C: z(lat, lon) float (or variables of the given names, the k-th
/// z - k), coordinate variables lon and lat of the given type with the given attributes (name,
/// value) each, and no CRS (no grid_mapping).
struct CfGrid {
    std::vector<double> lon, lat;
    std::vector<float> z; // row j (lat[j]) after row
    nc_type lon_type = NC_DOUBLE;
    std::vector<std::pair<std::string, std::string>> lon_attributes{{"standard_name", "longitude"},
                                                                    {"units", "degrees_east"}};
    std::vector<std::pair<std::string, std::string>> lat_attributes{{"standard_name", "latitude"},
                                                                    {"units", "degrees_north"}};
    std::vector<std::string> variables{"z"};
};

void write_cf(const std::string &path, const CfGrid &g) {
    int nc = -1, dims[2], lon_id, lat_id;
    ASSERT_EQ(nc_create(path.c_str(), NC_CLOBBER | NC_64BIT_OFFSET, &nc), NC_NOERR);
    ASSERT_EQ(nc_def_dim(nc, "lat", g.lat.size(), &dims[0]), NC_NOERR);
    ASSERT_EQ(nc_def_dim(nc, "lon", g.lon.size(), &dims[1]), NC_NOERR);
    ASSERT_EQ(nc_def_var(nc, "lat", NC_DOUBLE, 1, &dims[0], &lat_id), NC_NOERR);
    ASSERT_EQ(nc_def_var(nc, "lon", g.lon_type, 1, &dims[1], &lon_id), NC_NOERR);
    std::vector<int> z_ids(g.variables.size());
    for (std::size_t k = 0; k < g.variables.size(); ++k)
        ASSERT_EQ(nc_def_var(nc, g.variables[k].c_str(), NC_FLOAT, 2, dims, &z_ids[k]), NC_NOERR);
    for (const auto &[k, v] : g.lon_attributes)
        nc_put_att_text(nc, lon_id, k.c_str(), v.size(), v.c_str());
    for (const auto &[k, v] : g.lat_attributes)
        nc_put_att_text(nc, lat_id, k.c_str(), v.size(), v.c_str());
    ASSERT_EQ(nc_enddef(nc), NC_NOERR);
    ASSERT_EQ(nc_put_var_double(nc, lat_id, g.lat.data()), NC_NOERR);
    ASSERT_EQ(nc_put_var_double(nc, lon_id, g.lon.data()), NC_NOERR); // netCDF converts to lon_type
    for (std::size_t k = 0; k < g.variables.size(); ++k) {
        std::vector<float> z = g.z;
        for (float &v : z)
            v -= static_cast<float>(k);
        ASSERT_EQ(nc_put_var_float(nc, z_ids[k], z.data()), NC_NOERR);
    }
    ASSERT_EQ(nc_close(nc), NC_NOERR);
}

/// The stage names a read reports, in order, each once.
struct Stages {
    std::vector<std::string> names;
    Progress callback() {
        return [this](double, std::string_view s) {
            if (names.empty() || names.back() != s)
                names.emplace_back(s);
            return true;
        };
    }
    bool any_contains(const std::string &text) const {
        return std::any_of(names.begin(), names.end(),
                           [&](const std::string &n) { return n.find(text) != std::string::npos; });
    }
};

/// A closed ring through the lon/lat points, all segments tagged open.
Ring ring_of(const std::vector<LonLat> &points) {
    return test::ring_of_points(points, SegmentKind::open);
}

} // namespace

// A CUDEM tile (NOAA, Sabine Pass; 48 x 40 of its non-square cells, as published: CF lon/lat
// axes, no CRS) is read as WGS 84 lon/lat, and the progress line says so; values and
// coordinates checked against netCDF-C.
TEST(Bathymetry, cf_lonlat_grid_without_a_crs_is_read_as_wgs84_and_says_so) {
    const std::string path = fixture("bathy/cudem_sabine_unequal_48x40.nc").string();
    Stages stages;
    Raster r = read_raster(path, 1, false, stages.callback(), RasterLimits{});
    EXPECT_TRUE(stages.any_contains(
        "no CRS in the file, and its axes are CF longitude/latitude: read as WGS 84"))
        << stages.names.front();
    ASSERT_EQ(r.nlon(), 48u);
    ASSERT_EQ(r.nlat(), 40u);
    int nc = -1, lon_id, lat_id, z_id;
    ASSERT_EQ(nc_open(path.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lon", &lon_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lat", &lat_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "Band1", &z_id), NC_NOERR);
    std::vector<double> lon(48), lat(40), z(48 * 40);
    ASSERT_EQ(nc_get_var_double(nc, lon_id, lon.data()), NC_NOERR);
    ASSERT_EQ(nc_get_var_double(nc, lat_id, lat.data()), NC_NOERR);
    ASSERT_EQ(nc_get_var_double(nc, z_id, z.data()), NC_NOERR);
    nc_close(nc);
    int sea = 0;
    for (std::size_t j = 0; j < 40; ++j)
        for (std::size_t i = 0; i < 48; ++i) {
            EXPECT_NEAR(r.elevation_m(lon[i], lat[j]), z[j * 48 + i], 1e-6) << i << " " << j;
            sea += z[j * 48 + i] < 0;
        }
    EXPECT_GT(sea, 300); // water and marsh both
    // Inside a cell: bilinear between the file's four values, at the file's coordinates.
    const double fu = 0.3, fv = 0.8, x = lon[10] + fu * (lon[11] - lon[10]),
                 y = lat[20] + fv * (lat[21] - lat[20]);
    const double expect = (1 - fu) * (1 - fv) * z[20 * 48 + 10] + fu * (1 - fv) * z[20 * 48 + 11] +
                          (1 - fu) * fv * z[21 * 48 + 10] + fu * fv * z[21 * 48 + 11];
    EXPECT_NEAR(r.elevation_m(x, y), expect, 1e-5);
}

TEST(Bathymetry, a_grid_without_crs_or_lonlat_axes_is_refused_and_bathy_srs_gives_its_crs) {
    TempDir dir;
    auto z = [](double x, double y) { return -100.0 - 2.0 * x - 3.0 * y; };
    CfGrid g;
    for (int i = 0; i < 12; ++i)
        g.lon.push_back(0.25 + 0.5 * i);
    for (int j = 0; j < 10; ++j)
        g.lat.push_back(40.25 + 0.5 * j);
    for (double y : g.lat)
        for (double x : g.lon)
            g.z.push_back(static_cast<float>(z(x, y)));
    // The same grid with axes that do not say they are degrees: refused, naming --bathy-srs.
    CfGrid bare = g;
    bare.lon_attributes = {{"long_name", "x"}};
    bare.lat_attributes = {{"long_name", "y"}};
    const std::string bare_path = (dir / "bare.nc").string();
    write_cf(bare_path, bare);
    std::string m =
        test::thrown_message<DataError>([&] { read_raster(bare_path); }, "no CRS, no CF axes");
    EXPECT_NE(m.find("has no georeferencing"), std::string::npos) << m;
    EXPECT_NE(m.find("bathy_srs"), std::string::npos) << m;
    // Degrees by its units but an extent no lon/lat grid has (latitudes in the thousands): refused.
    CfGrid far = g;
    for (double &y : far.lat)
        y *= 100;
    const std::string far_path = (dir / "far.nc").string();
    write_cf(far_path, far);
    EXPECT_THROW(read_raster(far_path), DataError);
    // --bathy-srs gives the CRS: values as written.
    Stages stages;
    Raster r = read_raster(bare_path, 1, false, stages.callback(), RasterLimits{}, "EPSG:4326");
    EXPECT_TRUE(stages.any_contains("CRS WGS 84 (EPSG:4326) from --bathy-srs"))
        << stages.names.front();
    for (double y : {40.3, 42.0, 44.7})
        for (double x : {0.3, 2.2, 5.7})
            EXPECT_NEAR(r.elevation_m(x, y), z(x, y), 1e-4) << x << " " << y;
    // A string that is no CRS: one line naming the option, before any file is opened.
    for (const std::string bad : {"EPSG:99999", "not a crs", "LOCAL_CS[\"x\"]"}) {
        m = test::thrown_message<UsageError>([&] { validate_bathy_srs(bad); }, bad);
        EXPECT_EQ(m.rfind("bathy_srs '" + bad + "' is not a CRS", 0), 0u) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        EXPECT_THROW(read_raster(bare_path, 1, false, {}, RasterLimits{}, bad), UsageError) << bad;
    }
    EXPECT_NO_THROW(validate_bathy_srs(""));
    EXPECT_NO_THROW(validate_bathy_srs("+proj=longlat +datum=WGS84"));
}

// A GeoTIFF whose coordinates are lon/lat but whose CRS says Web Mercator (metres): read as
// declared it lies within metres of 0,0; --bathy-srs replaces the CRS and the progress line
// names both.
TEST(Bathymetry, bathy_srs_replaces_a_wrong_declared_crs) {
    TempDir dir;
    const std::string path = (dir / "mislabelled.tif").string();
    auto plane = [](double lon, double lat) { return -3000.0 + 10.0 * lon + 4.0 * lat; };
    write_tiff(path, {100, 30, 0.5, 0.5, 40, 20, 3857}, plane);
    Raster declared = read_raster(path);
    EXPECT_LT(declared.bounds().east, 0.01);
    Stages stages;
    Raster r = read_raster(path, 1, false, stages.callback(), RasterLimits{}, "EPSG:4326");
    EXPECT_TRUE(stages.any_contains(
        "from --bathy-srs, not the file's WGS 84 / Pseudo-Mercator (EPSG:3857)"))
        << stages.names.front();
    EXPECT_NEAR(r.bounds().west, 100, 1e-9);
    EXPECT_NEAR(r.bounds().north, 30, 1e-9);
    for (double lon : {100.3, 105.1, 119.7})
        EXPECT_NEAR(r.elevation_m(lon, 25.2), plane(lon, 25.2), 1e-3) << lon;
    // The file's own CRS given again: nothing replaced, nothing said of it.
    Stages same;
    read_raster(path, 1, false, same.callback(), RasterLimits{}, "EPSG:3857");
    EXPECT_TRUE(same.any_contains("(EPSG:3857) from --bathy-srs)")) << same.names.front();
}

// ---------------------------------------------------------------------------------------------
// Geographic CRSs other than WGS 84: warped to it, as a projected raster is

namespace {

/// Opens `source`, writes `path` from it with `make` (a GDAL utility), closes both.
void gdal_app(const std::string &source, const std::string &path,
              const std::function<GDALDatasetH(GDALDatasetH)> &make) {
    GDALAllRegister();
    GDALDatasetH src = GDALOpen(source.c_str(), GA_ReadOnly);
    ASSERT_NE(src, nullptr) << source;
    GDALDatasetH out = make(src);
    EXPECT_NE(out, nullptr) << path;
    if (out)
        GDALClose(out); // before its source: a VRT refers to it
    GDALClose(src);
}

/// `args` as a GDAL argv list (CSLDestroy frees it).
char **argv_of(const std::vector<std::string> &args) {
    char **argv = nullptr;
    for (const std::string &a : args)
        argv = CSLAddString(argv, a.c_str());
    return argv;
}

/// gdal_translate `args` `source` `path`, as the sweep made its variants of the fixtures.
void translate(const std::string &source, const std::string &path,
               const std::vector<std::string> &args) {
    char **argv = argv_of(args);
    GDALTranslateOptions *opts = GDALTranslateOptionsNew(argv, nullptr);
    CSLDestroy(argv);
    gdal_app(source, path,
             [&](GDALDatasetH src) { return GDALTranslate(path.c_str(), src, opts, nullptr); });
    GDALTranslateOptionsFree(opts);
}

/// (lon, lat) in degrees from the geographic CRS `from` to `to` (EPSG codes) by PROJ, as GDAL's
/// warper moves a raster of extent `area` (W, S, E, N): PROJ's operation for that area (NAD27's
/// differ by 4 m between areas).
LonLat transformed(int from, int to, LonLat p, const std::array<double, 4> &area) {
    OGRSpatialReferenceH a = OSRNewSpatialReference(nullptr), b = OSRNewSpatialReference(nullptr);
    OSRImportFromEPSG(a, from);
    OSRImportFromEPSG(b, to);
    OSRSetAxisMappingStrategy(a, OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(b, OAMS_TRADITIONAL_GIS_ORDER);
    OGRCoordinateTransformationOptionsH options = OCTNewCoordinateTransformationOptions();
    OCTCoordinateTransformationOptionsSetAreaOfInterest(options, area[0], area[1], area[2],
                                                        area[3]);
    OGRCoordinateTransformationH ct = OCTNewCoordinateTransformationEx(a, b, options);
    EXPECT_TRUE(ct != nullptr && OCTTransform(ct, 1, &p.lon, &p.lat, nullptr));
    OCTDestroyCoordinateTransformationOptions(options);
    OCTDestroyCoordinateTransformation(ct);
    OSRRelease(a);
    OSRRelease(b);
    return p;
}

/// The global fixture averaged to half a degree (720 x 360 cells) as dir/name, with
/// gdal_translate's `more` arguments (a CRS, an extent); its path.
std::string half_degree_etopo(const TempDir &dir, const std::string &name,
                              std::vector<std::string> more) {
    const std::string path = (dir / name).string();
    more.insert(more.end(), {"-outsize", "720", "360", "-r", "average"});
    translate(fixture("bathy/etopo5_global_10min.nc").string(), path, more);
    return path;
}

} // namespace

// ETOPO5's north-west shelf (the fixture) labelled with a CRS on the Paris meridian, its
// longitudes less Paris's 2.33722917 degrees east of Greenwich (the sweep's shelf_paris): the
// same cells on the same ground. Read, it is the fixture again (within 1e-3 m, 4e-5 m measured:
// the warp's cells fall on the fixture's), not the fixture moved 2.3 degrees west, as when every
// geographic CRS in degrees was taken for WGS 84 (up to 4.6 km off), nor 0.6 m off as with the
// warp's cell size written to six decimals.
TEST(Bathymetry, a_raster_on_the_paris_meridian_is_read_where_it_lies) {
    const std::string source = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    TempDir dir;
    const std::string path = (dir / "paris.tif").string();
    translate(source, path,
              {"-a_srs", "+proj=longlat +ellps=WGS84 +towgs84=0,0,0 +pm=paris +no_defs", "-a_ullr",
               "-14.378895836666666", "62.041666666666664", "10.704437496666666",
               "45.958333333333336"});
    const Raster truth = read_raster(source), r = read_raster(path);
    EXPECT_NEAR(r.bounds().west, truth.bounds().west, 1e-6);
    EXPECT_NEAR(r.bounds().east, truth.bounds().east, 1e-6);
    std::mt19937 rng(41);
    std::uniform_real_distribution<double> ulon(-11.5, 12.5), ulat(46.5, 61.5);
    for (int k = 0; k < 2000; ++k) {
        const double x = ulon(rng), y = ulat(rng);
        EXPECT_NEAR(r.elevation_m(x, y), truth.elevation_m(x, y), 1e-3) << x << " " << y;
    }
}

// A plane in NAD27 longitude and latitude (EPSG:4267) at Sabine Pass, where PROJ puts NAD27
// about 25 m from WGS 84: read, a WGS 84 point takes the plane's value at its NAD27
// coordinates (PROJ's transformation, computed here), not at its own (9.4 m off). The
// bilinear warp and sample are exact on a plane.
TEST(Bathymetry, a_nad27_raster_is_moved_to_wgs84) {
    TempDir dir;
    const std::string path = (dir / "nad27.tif").string();
    auto plane = [](double lon, double lat) {
        return -100.0 + 20000.0 * (lon + 93.9) - 30000.0 * (lat - 29.8);
    };
    write_tiff(path, {-94.0, 29.9, 0.001, 0.001, 200, 200, 4267}, plane);
    const Raster r = read_raster(path);
    const std::array<double, 4> area{-94.0, 29.7, -93.8, 29.9};
    const LonLat shift = transformed(4267, 4326, {-93.9, 29.8}, area);
    ASSERT_GT(std::hypot(shift.lon + 93.9, shift.lat - 29.8), 1e-4) << "PROJ moves NAD27 here";
    for (double lon : {-93.97, -93.9, -93.83})
        for (double lat : {29.73, 29.8, 29.87}) {
            const LonLat nad27 = transformed(4326, 4267, {lon, lat}, area);
            EXPECT_NEAR(r.elevation_m(lon, lat), plane(nad27.lon, nad27.lat), 0.01)
                << lon << " " << lat;
        }
}

// ETOPO5 (the global fixture, averaged to half a degree) labelled ED50 by its Helmert shift to
// WGS 84: at a pole every longitude is one point, which the shift moves as one, so the warp's
// cell size sampled there was nothing and GDAL was asked for a -2147483648-cell raster. A
// geographic raster keeps its own cells' size: read, global, every cell valid, and the grid
// moved by the shift's 200 m (of its 55 km cells): the median point within 1 m of it.
TEST(Bathymetry, a_global_raster_on_another_datum_is_warped_at_its_own_cell_size) {
    TempDir dir;
    const Raster r = read_raster(half_degree_etopo(
                     dir, "ed50.tif",
                     {"-a_srs", "+proj=longlat +ellps=intl +towgs84=-87,-98,-121"})),
                 truth = read_raster(half_degree_etopo(dir, "wgs84.tif", {}));
    EXPECT_TRUE(r.global());
    EXPECT_EQ(r.nlon(), 720u);
    EXPECT_NEAR(r.dlon_deg(), 0.5, 1e-12);
    EXPECT_EQ(r.valid_count(), r.values().size());
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> ulon(-180, 180), ulat(-80, 80);
    std::vector<double> off;
    for (int k = 0; k < 1001; ++k) {
        const double x = ulon(rng), y = ulat(rng);
        off.push_back(std::abs(r.elevation_m(x, y) - truth.elevation_m(x, y)));
    }
    std::nth_element(off.begin(), off.begin() + 500, off.end());
    EXPECT_LT(off[500], 1.0);
}

// The same half-degree grid labelled with the Paris meridian, its longitudes less Paris's
// 2.33722917 degrees: the same cells on the same ground, round the globe. GDAL widened the
// bilinear kernel of each warped block by its source window over its size, and a block across
// the seam takes the raster's whole width: a quarter of the globe came out smoothed, 1 km
// off. With the plain kernel in every block it is the grid again.
TEST(Bathymetry, a_global_raster_on_the_paris_meridian_is_read_cell_for_cell) {
    TempDir dir;
    const Raster r = read_raster(
                     half_degree_etopo(dir, "paris.tif",
                                       {"-a_srs", "+proj=longlat +ellps=WGS84 +pm=paris", "-a_ullr",
                                        "-182.33722917", "90", "177.66277083", "-90"})),
                 truth = read_raster(half_degree_etopo(dir, "wgs84.tif", {}));
    EXPECT_TRUE(r.global());
    std::mt19937 rng(47);
    std::uniform_real_distribution<double> ulon(-180, 180), ulat(-89, 89);
    for (int k = 0; k < 2000; ++k) {
        const double x = ulon(rng), y = ulat(rng);
        EXPECT_NEAR(r.elevation_m(x, y), truth.elevation_m(x, y), 1e-3) << x << " " << y;
    }
}

// WGS 84 lon/lat however it is written stays a plain read of the cells, with no warp: the
// fixture labelled EPSG:4326, OGC:CRS84, the WGS 84 ellipsoid without a datum (what GDAL's
// netCDF driver makes of a CF latitude_longitude grid mapping) and the fixture as GDAL writes it
// to NetCDF are read to the same grid and the same values.
TEST(Bathymetry, wgs84_lonlat_in_any_spelling_is_read_as_its_cells) {
    const std::string source = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    TempDir dir;
    const Raster truth = read_raster(source);
    struct Variant {
        std::string name;
        std::vector<std::string> args;
    };
    for (const Variant &v : {Variant{"epsg4326.tif", {"-a_srs", "EPSG:4326"}},
                             Variant{"crs84.tif", {"-a_srs", "OGC:CRS84"}},
                             Variant{"ellipsoid.tif", {"-a_srs", "+proj=longlat +ellps=WGS84"}},
                             Variant{"gdal.nc", {"-of", "netCDF"}}}) {
        const std::string path = (dir / v.name).string();
        translate(source, path, v.args);
        const Raster r = read_raster(path);
        ASSERT_EQ(r.nlon(), truth.nlon()) << v.name;
        ASSERT_EQ(r.nlat(), truth.nlat()) << v.name;
        EXPECT_EQ(r.dlon_deg(), truth.dlon_deg()) << v.name;
        EXPECT_NEAR(r.lon0_deg(), truth.lon0_deg(), 1e-12) << v.name;
        EXPECT_NEAR(r.lat0_deg(), truth.lat0_deg(), 1e-12) << v.name;
        EXPECT_EQ(r.values(), truth.values()) << v.name;
    }
}

// ---------------------------------------------------------------------------------------------
// A NetCDF file of several 2-D variables: GDAL opens it with no band, its variables as subdatasets

namespace {

/// The ETOPO5 shelf fixture as a CF grid (write_cf) of 2-D variables of the given names.
void write_variables(const std::string &path, const std::vector<std::string> &variables) {
    const std::string source = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    GDALAllRegister();
    GDALDatasetH ds = GDALOpen(source.c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr);
    const int nx = GDALGetRasterXSize(ds), ny = GDALGetRasterYSize(ds);
    double gt[6];
    GDALGetGeoTransform(ds, gt);
    CfGrid g;
    g.variables = variables;
    g.z.resize(std::size_t(nx) * std::size_t(ny));
    ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, nx, ny, g.z.data(), nx, ny,
                           GDT_Float32, 0, 0),
              CE_None);
    GDALClose(ds);
    for (int i = 0; i < nx; ++i)
        g.lon.push_back(gt[0] + (i + 0.5) * gt[1]);
    for (int j = 0; j < ny; ++j)
        g.lat.push_back(gt[3] + (j + 0.5) * gt[5]);
    write_cf(path, g);
}

} // namespace

// The fixture as a NetCDF with elevation and source_id (the sweep's shelf_2var.nc) used to be
// refused as "bathy_band 1: ... has 0 bands". The message names the variables as GDAL opens them
// (NETCDF:"file":elevation), and one given as bathy reads as the fixture.
TEST(Bathymetry, a_netcdf_of_several_variables_names_them_as_rasters_to_give) {
    TempDir dir;
    const std::string path = (dir / "two.nc").string();
    write_variables(path, {"elevation", "source_id"});
    const std::string m =
        test::thrown_message<UsageError>([&] { read_raster(path); }, "two variables");
    const std::string elevation = "NETCDF:\"" + path + "\":elevation";
    EXPECT_EQ(m, "bathy " + path +
                     ": holds 2 rasters (subdatasets), not one; give one of them as bathy (in "
                     "single quotes in a shell): " +
                     elevation + ", NETCDF:\"" + path + "\":source_id");
    const Raster r = read_raster(elevation),
                 truth = read_raster(fixture("bathy/etopo5_nwshelf_5min.tif").string());
    ASSERT_EQ(r.nlon(), truth.nlon());
    ASSERT_EQ(r.nlat(), truth.nlat());
    EXPECT_NEAR(r.lon0_deg(), truth.lon0_deg(), 1e-9);
    EXPECT_NEAR(r.lat0_deg(), truth.lat0_deg(), 1e-9);
    EXPECT_EQ(r.values(), truth.values());
    // Six: the first four named, and how many more.
    const std::string six = (dir / "six.nc").string();
    write_variables(six, {"a", "b", "c", "d", "e", "f"});
    const std::string m6 = test::thrown_message<UsageError>([&] { read_raster(six); }, "six");
    EXPECT_NE(m6.find(":\"" + six + "\":d and 2 more (gdalinfo lists them)"), std::string::npos)
        << m6;
    EXPECT_EQ(m6.find(":e"), std::string::npos) << m6;
}

// Global grids whose last column repeats the first meridian (node registered), from 20 1/6 E
// (longitudes as float32: GDAL's spacing then misses 1/3 by 1e-8, 360 degrees by 1e-5), from
// 20 E (doubles) and from -180 to 180 (float32): global, and interpolated across the seam. The
// field is smooth and periodic, steepest across the seam, so holding the last column instead
// (the old clamp) is off by about half the step between the two columns there (1.5 m).
TEST(Bathymetry, a_repeated_wrap_column_is_recognised_and_interpolated_across) {
    TempDir dir;
    struct Case {
        double west;
        nc_type type;
    };
    const double step = 1.0 / 3.0;
    for (const Case c : {Case{20 + 1.0 / 6, NC_FLOAT}, Case{20, NC_DOUBLE}, Case{-180, NC_FLOAT}}) {
        auto f = [&](double lon, double lat) {
            return -1000.0 -
                   500.0 * std::sin((lon - c.west) * deg_to_rad) * std::cos(lat * deg_to_rad);
        };
        CfGrid g;
        g.lon_type = c.type;
        for (int i = 0; i <= 1080; ++i) {
            const double lon = c.west + i * step;
            g.lon.push_back(c.type == NC_FLOAT ? static_cast<double>(static_cast<float>(lon))
                                               : lon);
        }
        for (int j = 0; j <= 36; ++j)
            g.lat.push_back(-90.0 + 5.0 * j);
        for (double lat : g.lat)
            for (int i = 0; i <= 1080; ++i)
                g.z.push_back(static_cast<float>(f(c.west + i * step, lat)));
        const std::string path = (dir / "wrap.nc").string();
        write_cf(path, g);
        const std::string what =
            std::to_string(c.west) + (c.type == NC_FLOAT ? " float" : " double");
        MeshOptions o = options_for(path);
        Raster r = read_bathymetry(o); // covers the globe: no DataError
        ASSERT_TRUE(r.global()) << what;
        EXPECT_EQ(r.nlon(), 1080u) << what;
        EXPECT_NEAR(r.dlon_deg(), step, 1e-12) << what;
        // Across the seam: between the last column that is not a repeat and the first, at the
        // grid's latitudes, from the two stored values by hand.
        for (double lat : {-45.0, 0.0, 30.0, 85.0})
            for (double t : {0.1, 0.5, 0.9}) {
                const double lon = c.west - step + t * step;
                const double expect =
                    (1 - t) * f32(f(c.west - step, lat)) + t * f32(f(c.west, lat));
                EXPECT_NEAR(r.elevation_m(lon, lat), expect, 2e-3)
                    << what << " " << lon << " " << lat;
                EXPECT_NEAR(r.elevation_m(lon + 360, lat), expect, 2e-3) << what;
                EXPECT_NEAR(r.elevation_m(lon - 360, lat), expect, 2e-3) << what;
                // Bilinear within h^2/8 |f''| = 0.0085 m of the field itself.
                EXPECT_NEAR(r.elevation_m(lon, lat), f(lon, lat), 0.01) << what;
            }
        // Across 180, and at the repeated column itself.
        for (double lon : {179.9, -179.9, 180.0, -180.0, c.west, c.west + 360})
            EXPECT_NEAR(r.elevation_m(lon, 10.0), f(lon, 10.0), 0.01) << what << " " << lon;
    }
}

// ETOPO5 (the fixture) cut into a node-registered grid from 20 E round to 20 E again, its
// longitudes float32 and no CRS (as a CF file from another tool comes): read, it equals the
// fixture everywhere, the seam at 20 E included. Every third row, to keep the file small.
TEST(Bathymetry, etopo5_with_a_repeated_wrap_column_reads_as_etopo5) {
    const std::string source = fixture("bathy/etopo5_global_10min.nc").string();
    int nc = -1, lon_id, lat_id, z_id;
    ASSERT_EQ(nc_open(source.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lon", &lon_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "lat", &lat_id), NC_NOERR);
    ASSERT_EQ(nc_inq_varid(nc, "elevation", &z_id), NC_NOERR);
    std::vector<double> lon(2160), lat(1080);
    std::vector<float> z(2160 * 1080);
    ASSERT_EQ(nc_get_var_double(nc, lon_id, lon.data()), NC_NOERR);
    ASSERT_EQ(nc_get_var_double(nc, lat_id, lat.data()), NC_NOERR);
    ASSERT_EQ(nc_get_var_float(nc, z_id, z.data()), NC_NOERR);
    nc_close(nc);
    const std::size_t k0 = 1200; // the column centred at 20 1/12 E
    ASSERT_NEAR(lon[k0], 20 + 1.0 / 12, 1e-9);
    CfGrid g;
    g.lon_type = NC_FLOAT;
    for (std::size_t i = 0; i <= 2160; ++i)
        g.lon.push_back(lon[(k0 + i) % 2160] + (k0 + i >= 2160 ? 360 : 0));
    for (std::size_t j = 1; j < 1080; j += 3) {
        g.lat.push_back(lat[j]);
        for (std::size_t i = 0; i <= 2160; ++i)
            g.z.push_back(z[j * 2160 + (k0 + i) % 2160]);
    }
    TempDir dir;
    const std::string path = (dir / "etopo5_wrap20.nc").string();
    write_cf(path, g);
    Raster r = read_bathymetry(options_for(path));
    ASSERT_TRUE(r.global());
    ASSERT_EQ(r.nlon(), 2160u);
    Raster truth = read_bathymetry(options_for(source));
    // float32 longitudes sit up to 1e-6 degrees off: 3e-3 m on the steepest ETOPO5 slopes.
    std::mt19937 rng(37);
    std::uniform_real_distribution<double> ulon(-180, 180);
    std::uniform_int_distribution<std::size_t> urow(0, g.lat.size() - 1);
    for (int k = 0; k < 2000; ++k) {
        const double x = ulon(rng), y = g.lat[urow(rng)];
        EXPECT_NEAR(r.elevation_m(x, y), truth.elevation_m(x, y), 0.01) << x << " " << y;
    }
    // The seam, from the file's two values by hand (20 1/12 E is column k0, 19 11/12 E k0 - 1).
    for (std::size_t row : {std::size_t{100}, std::size_t{200}, std::size_t{300}}) {
        const std::size_t j = 1 + 3 * row;
        for (double t : {0.25, 0.5, 0.75}) {
            const double x = lon[k0 - 1] + t / 6;
            const double expect = (1 - t) * z[j * 2160 + k0 - 1] + t * z[j * 2160 + k0];
            EXPECT_NEAR(r.elevation_m(x, lat[j]), expect, 0.01) << x << " " << lat[j];
        }
    }
}

TEST(Bathymetry, ocean_extent_takes_the_short_way_round_and_the_pole_an_ocean_holds) {
    // A box across 180, ocean inside (counter-clockwise seen from outside).
    Boundary box;
    box.rings.push_back(ring_of({{170, -10}, {-170, -10}, {-170, 10}, {170, 10}}));
    EXPECT_EQ(ocean_pole_winding(box), 0);
    auto e = ocean_extent(box);
    ASSERT_TRUE(e);
    EXPECT_NEAR(e->west, 170, 0.125);
    EXPECT_NEAR(e->east, 190, 0.125);
    EXPECT_LE(e->west, 170);
    EXPECT_GE(e->east, 190);
    EXPECT_NEAR(e->south, -10, 1e-9);
    EXPECT_NEAR(e->north, 10, 1e-9);
    // A parallel at 60 N walked east: the ocean on its left is the cap round the north pole.
    std::vector<LonLat> parallel;
    for (int k = 0; k < 36; ++k)
        parallel.push_back({-180.0 + 10 * k, 60});
    Boundary cap;
    cap.rings.push_back(ring_of(parallel));
    EXPECT_EQ(ocean_pole_winding(cap), 1);
    e = ocean_extent(cap);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->north, 90);
    EXPECT_NEAR(e->south, 60, 1e-9);
    EXPECT_EQ(e->east - e->west, 360);
    // Walked west: the ocean is everything south of it, the south pole too.
    std::reverse(cap.rings[0].nodes.begin(), cap.rings[0].nodes.end());
    EXPECT_EQ(ocean_pole_winding(cap), -1);
    e = ocean_extent(cap);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->south, -90);
    EXPECT_NEAR(e->north, 60, 1e-9);
    EXPECT_FALSE(ocean_extent(Boundary{})); // no rings: the whole sphere
}

// The region a raster must cover is the ocean the coast stage cut (--region box or
// --region-file): its land needs no raster; an ocean reaching beyond is refused naming where.
// The window read is the ocean's extent for --region-file.
TEST(Bathymetry, coverage_is_that_of_the_ocean_of_the_region_file_or_box) {
    TempDir dir;
    const std::string path = (dir / "regional.tif").string();
    write_tiff(path, {0, 10, 0.05, 0.05, 200, 200},
               [](double lon, double lat) { return -50.0 - lon - lat; });
    MeshOptions o = options_for(path);
    o.region_file = (dir / "region.gpkg").string(); // not opened here: the coast stage read it
    Boundary ocean;
    ocean.rings.push_back(ring_of({{2, 2}, {4, 2}, {4, 3}, {2, 3}}));
    Raster r = read_bathymetry(o, {}, &ocean);
    // The window: the ocean's extent (to 1/8 degree), 1% of its side and three cells beyond.
    EXPECT_LT(r.nlon(), 60u);
    EXPECT_LT(r.nlat(), 40u);
    EXPECT_NEAR(r.elevation_m(3.0, 2.5), -55.5, 1e-4);
    // Without the ocean, --region-file leaves the whole globe to cover, as before.
    EXPECT_THROW(read_bathymetry(o), DataError);
    // An ocean reaching east of the raster (10 E): refused, naming the file and the place
    // farthest out.
    ocean.rings[0] = ring_of({{2, 2}, {11, 2}, {11, 3}, {2, 3}});
    std::string m =
        test::thrown_message<DataError>([&] { read_bathymetry(o, {}, &ocean); }, "ocean beyond");
    EXPECT_NE(m.find("the ocean of region_file " + o.region_file + " reaches lon 11, lat 2"),
              std::string::npos)
        << m;
    EXPECT_NE(m.find("bathy_fill_m"), std::string::npos) << m;
    // A --region box running west of the raster over land: its ocean is inside, so it is covered.
    o.region_file.clear();
    o.region = std::array<double, 4>{-5, 1, 9, 9};
    ocean.rings[0] = ring_of({{1, 1}, {9, 1}, {9, 9}, {1, 9}});
    EXPECT_NO_THROW(read_bathymetry(o, {}, &ocean));
    EXPECT_THROW(read_bathymetry(o), DataError); // the box alone is not
    // A segment bulging past the raster between two covered nodes: the great circle from
    // (9.5, 9.99) to (0.5, 9.99) reaches 10.02 N, past the raster's edge at 10 N.
    o.region = std::array<double, 4>{-5, 1, 9.5, 9.99};
    ocean.rings[0] = ring_of({{0.5, 1}, {9.5, 1}, {9.5, 9.99}, {0.5, 9.99}});
    m = test::thrown_message<DataError>([&] { read_bathymetry(o, {}, &ocean); }, "bulge");
    EXPECT_NE(m.find("reaches lon"), std::string::npos) << m;
    o.bathy_fill_m = 20.0; // the fill answers for the rest
    EXPECT_NO_THROW(read_bathymetry(o, {}, &ocean));
}

namespace {

/// ETOPO5 (the fixture) rewritten with netCDF-C as elevation(lon, lat): X before Y, as some CF
/// writers store it, every third row and column to keep it small, its CRS variable kept; with
/// `time` a leading dimension of one step. Returns the source's lon, lat and values read there.
struct Etopo5Sample {
    std::vector<double> lon, lat;
    std::vector<float> z; // z[j * lon.size() + i] at (lon[i], lat[j])
};

Etopo5Sample write_etopo5_lon_lat(const std::string &path, bool time) {
    const std::string source = fixture("bathy/etopo5_global_10min.nc").string();
    int nc = -1, lon_id, lat_id, z_id;
    std::vector<double> lon(2160), lat(1080);
    std::vector<float> z(2160 * 1080);
    EXPECT_EQ(nc_open(source.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    nc_inq_varid(nc, "lon", &lon_id);
    nc_inq_varid(nc, "lat", &lat_id);
    nc_inq_varid(nc, "elevation", &z_id);
    nc_get_var_double(nc, lon_id, lon.data());
    nc_get_var_double(nc, lat_id, lat.data());
    EXPECT_EQ(nc_get_var_float(nc, z_id, z.data()), NC_NOERR);
    nc_close(nc);
    Etopo5Sample s;
    for (std::size_t i = 1; i < 2160; i += 3)
        s.lon.push_back(lon[i]);
    for (std::size_t j = 1; j < 1080; j += 3)
        s.lat.push_back(lat[j]);
    for (std::size_t j = 1; j < 1080; j += 3)
        for (std::size_t i = 1; i < 2160; i += 3)
            s.z.push_back(z[j * 2160 + i]);
    std::vector<float> transposed(s.z.size()); // [i * nlat + j]
    for (std::size_t j = 0; j < s.lat.size(); ++j)
        for (std::size_t i = 0; i < s.lon.size(); ++i)
            transposed[i * s.lat.size() + j] = s.z[j * s.lon.size() + i];
    int out = -1, dims[3], t_id, crs_id;
    EXPECT_EQ(nc_create(path.c_str(), NC_CLOBBER | NC_NETCDF4, &out), NC_NOERR);
    nc_def_dim(out, "time", 1, &dims[0]);
    nc_def_dim(out, "lon", s.lon.size(), &dims[1]);
    nc_def_dim(out, "lat", s.lat.size(), &dims[2]);
    nc_def_var(out, "time", NC_DOUBLE, 1, &dims[0], &t_id);
    nc_def_var(out, "lon", NC_DOUBLE, 1, &dims[1], &lon_id);
    nc_def_var(out, "lat", NC_DOUBLE, 1, &dims[2], &lat_id);
    nc_def_var(out, "crs", NC_INT, 0, nullptr, &crs_id);
    EXPECT_EQ(nc_def_var(out, "elevation", NC_FLOAT, time ? 3 : 2, time ? dims : dims + 1, &z_id),
              NC_NOERR);
    auto text = [&](int id, const char *k, const std::string &v) {
        nc_put_att_text(out, id, k, v.size(), v.c_str());
    };
    text(t_id, "units", "days since 2000-01-01");
    text(lon_id, "standard_name", "longitude");
    text(lon_id, "units", "degrees_east");
    text(lat_id, "standard_name", "latitude");
    text(lat_id, "units", "degrees_north");
    text(crs_id, "grid_mapping_name", "latitude_longitude");
    const double a = 6378137, rf = 298.257223563;
    nc_put_att_double(out, crs_id, "semi_major_axis", NC_DOUBLE, 1, &a);
    nc_put_att_double(out, crs_id, "inverse_flattening", NC_DOUBLE, 1, &rf);
    text(z_id, "grid_mapping", "crs");
    text(z_id, "units", "m");
    EXPECT_EQ(nc_enddef(out), NC_NOERR);
    const double t0 = 0;
    nc_put_var_double(out, t_id, &t0);
    nc_put_var_double(out, lon_id, s.lon.data());
    nc_put_var_double(out, lat_id, s.lat.data());
    EXPECT_EQ(nc_put_var_float(out, z_id, transposed.data()), NC_NOERR);
    EXPECT_EQ(nc_close(out), NC_NOERR);
    return s;
}

} // namespace

// A CF variable stored elevation(lon, lat) is a valid grid that ncview, xarray and GDAL's
// multidimensional API read with X along longitude; GDAL's netCDF raster driver swaps its axes
// (columns along latitude: Hawaii read 5 km off). Read the right way round, it equals the
// source at every cell centre; with a further dimension it is refused saying how to reorder.
TEST(Bathymetry, a_netcdf_variable_stored_lon_lat_is_read_with_its_axes_the_right_way) {
    TempDir dir;
    const std::string path = (dir / "etopo5_lon_lat.nc").string();
    const Etopo5Sample s = write_etopo5_lon_lat(path, false);
    Raster r = read_raster(path, 1, false, {}, RasterLimits{});
    EXPECT_EQ(r.nlon(), s.lon.size());
    EXPECT_EQ(r.nlat(), s.lat.size());
    EXPECT_TRUE(r.global());
    for (std::size_t j = 0; j < s.lat.size(); j += 7)
        for (std::size_t i = 0; i < s.lon.size(); i += 5)
            ASSERT_NEAR(r.elevation_m(s.lon[i], s.lat[j]), s.z[j * s.lon.size() + i], 1e-6)
                << s.lon[i] << " " << s.lat[j];
    // Between cells: bilinear between the four source values.
    const std::size_t i = 300, j = 200, n = s.lon.size();
    const double x = s.lon[i] + 0.25 * (s.lon[i + 1] - s.lon[i]),
                 y = s.lat[j] + 0.5 * (s.lat[j + 1] - s.lat[j]);
    const double expect = 0.75 * 0.5 * s.z[j * n + i] + 0.25 * 0.5 * s.z[j * n + i + 1] +
                          0.75 * 0.5 * s.z[(j + 1) * n + i] + 0.25 * 0.5 * s.z[(j + 1) * n + i + 1];
    EXPECT_NEAR(r.elevation_m(x, y), expect, 1e-3);

    const std::string timed = (dir / "etopo5_time_lon_lat.nc").string();
    write_etopo5_lon_lat(timed, true);
    const std::string m = test::thrown_message<DataError>(
        [&] { read_raster(timed, 1, false, {}, RasterLimits{}); }, "a 3-D lon, lat variable");
    EXPECT_NE(m.find("ncpdq -a time,lat,lon"), std::string::npos) << m;
}

namespace {

/// gdalwarp `args` `source` `path` (GeoTIFF), as a user reprojects a raster.
void warp(const std::string &source, const std::string &path,
          const std::vector<std::string> &args) {
    char **argv = argv_of(args);
    GDALWarpAppOptions *opts = GDALWarpAppOptionsNew(argv, nullptr);
    CSLDestroy(argv);
    gdal_app(source, path, [&](GDALDatasetH src) {
        return GDALWarp(path.c_str(), nullptr, 1, &src, opts, nullptr);
    });
    GDALWarpAppOptionsFree(opts);
}

} // namespace

// ETOPO5's north-west shelf (the fixture) warped to UTM 31N at 10 km (gdalwarp), as a user's
// projected raster comes. Read, it has a depth up to the source's edges: at points 2% of a
// pixel inside its outline (moved to lon/lat by PROJ) within the range of the source pixels
// around them. 79 of these 204 points had none: the warper leaves a lon/lat cell without data
// when its centre falls off the source, and GDALWarp's -tr rounded the lon/lat grid's size to
// the nearest step, cutting 0.48 of a step off its east edge.
TEST(Bathymetry, a_projected_raster_is_read_up_to_its_edges) {
    TempDir dir;
    const std::string path = (dir / "nwshelf_utm31.tif").string();
    warp(fixture("bathy/etopo5_nwshelf_5min.tif").string(), path,
         {"-t_srs", "EPSG:32631", "-r", "bilinear", "-tr", "10000", "10000", "-te", "200000",
          "5300000", "640000", "6600000"});
    const int nx = 44, ny = 130;
    std::vector<double> z(nx * ny);
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr);
    ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, nx, ny, z.data(), nx, ny,
                           GDT_Float64, 0, 0),
              CE_None);
    GDALClose(ds);
    Raster r = read_raster(path, 1, false, {}, RasterLimits{});
    int tested = 0;
    auto check = [&](double px, double py) {
        const double x = 200000 + 10000 * px, y = 6600000 - 10000 * py;
        const LonLat p = transformed(32631, 4326, {x, y}, {-3, 47, 7, 60});
        double lo = 1e9, hi = -1e9;
        for (int j = std::max(0, int(py) - 2); j <= std::min(ny - 1, int(py) + 2); ++j)
            for (int i = std::max(0, int(px) - 2); i <= std::min(nx - 1, int(px) + 2); ++i)
                lo = std::min(lo, z[j * nx + i]), hi = std::max(hi, z[j * nx + i]);
        const double v = r.elevation_m(p.lon, p.lat);
        EXPECT_TRUE(v >= lo - 1e-3 && v <= hi + 1e-3)
            << v << " at " << p.lon << " " << p.lat << " (pixel " << px << " " << py << ")";
        ++tested;
    };
    for (double t = 0.01; t < 1; t += 0.02) {
        check(0.02, t * ny);
        check(nx - 0.02, t * ny);
        check(t * nx, 0.02);
        check(t * nx, ny - 0.02);
    }
    for (double px : {0.02, nx - 0.02})
        for (double py : {0.02, ny - 0.02})
            check(px, py); // the north-east corner is the source's easternmost point
    EXPECT_EQ(tested, 204);
}

// ETOPO5's north-west shelf (the fixture) with rotation terms in its geotransform (a copy whose
// columns run 0.01 degree north-east of east, its rows 0.005 east of south): its cells fill a
// parallelogram inside its lon/lat box. An ocean reaching the box's empty corner is refused
// as the raster is read, before any meshing, naming a point off the parallelogram; one on
// it is read. At main the box alone was checked and the mesh stage ran before the nodes off
// the parallelogram were found without data.
TEST(Bathymetry, a_rotated_raster_not_covering_the_ocean_is_refused_as_it_is_read) {
    TempDir dir;
    const std::string path = (dir / "nwshelf_rotated.tif").string();
    translate(fixture("bathy/etopo5_nwshelf_5min.tif").string(), path, {"-of", "GTiff"});
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_Update);
    ASSERT_NE(ds, nullptr);
    double gt[6] = {-12.041666666666666, 1.0 / 12, 0.01, 62.041666666666664, 0.005, -1.0 / 12};
    const std::string wkt = GDALGetProjectionRef(ds); // a rotated GeoTIFF writes both anew
    ASSERT_EQ(GDALSetGeoTransform(ds, gt), CE_None);
    ASSERT_EQ(GDALSetProjection(ds, wkt.c_str()), CE_None);
    GDALClose(ds);
    MeshOptions o = options_for(path);
    o.region = std::array<double, 4>{-11.5, 50, 0, 58};
    // The west edge of the cells (pixel column 0) at 50 N: x = gt0 + py * gt2, py from y.
    const double py = (50 - gt[3]) / gt[5], west_at_50 = gt[0] + py * gt[2];
    ASSERT_GT(west_at_50, -11.5 + 0.5); // the ring's corner lies half a degree off the cells
    Boundary ocean;
    ocean.rings.push_back(ring_of({{-11.5, 50}, {0, 50}, {0, 58}, {-11.5, 58}}));
    const std::string m =
        test::thrown_message<DataError>([&] { read_bathymetry(o, {}, &ocean); }, "rotated");
    EXPECT_NE(m.find("fill only part of that box"), std::string::npos) << m;
    EXPECT_NE(m.find("reaches lon -11.5, lat"), std::string::npos) << m;
    o.region = std::array<double, 4>{-9, 50, 0, 58};
    ocean.rings[0] = ring_of({{-9, 50}, {0, 50}, {0, 58}, {-9, 58}});
    EXPECT_NO_THROW(read_bathymetry(o, {}, &ocean));
}

// A region reaching south of ETOPO5's north-west shelf (the fixture, 45.96 N to 62.04 N): the
// refusal gives the raster's extent as gdalinfo does, not the window read for the region.
TEST(Bathymetry, the_coverage_error_gives_the_rasters_own_extent) {
    const std::string path = fixture("bathy/etopo5_nwshelf_5min.tif").string();
    GDALAllRegister();
    GDALDatasetH ds = GDALOpen(path.c_str(), GA_ReadOnly);
    ASSERT_NE(ds, nullptr);
    double gt[6];
    ASSERT_EQ(GDALGetGeoTransform(ds, gt), CE_None);
    const int nx = GDALGetRasterXSize(ds), ny = GDALGetRasterYSize(ds);
    GDALClose(ds);
    char extent[160];
    std::snprintf(extent, sizeof extent, "covers only lon %.7g..%.7g, lat %.7g..%.7g", gt[0],
                  gt[0] + nx * gt[1], gt[3] + ny * gt[5], gt[3]);
    MeshOptions o = options_for(path);
    o.region = std::array<double, 4>{-10, 44, 0, 50};
    Boundary ocean;
    ocean.rings.push_back(ring_of({{-10, 44}, {0, 44}, {0, 50}, {-10, 50}}));
    std::string m = test::thrown_message<DataError>([&] { read_bathymetry(o, {}, &ocean); },
                                                    "an ocean south of the raster");
    EXPECT_NE(m.find(extent), std::string::npos) << m << "\nnot: " << extent;
    m = test::thrown_message<DataError>([&] { read_bathymetry(o); }, "a box south of the raster");
    EXPECT_NE(m.find(extent), std::string::npos) << m << "\nnot: " << extent;
}

namespace {

/// ETOPO5's north-west shelf (the fixture) as a GeoTIFF whose cells in lon -8..-4, lat 46..48
/// (Biscay) hold 0 and are masked out by an internal per-dataset mask (GDAL_TIFF_INTERNAL_MASK),
/// not a nodata value; its path. `values` gets the fixture's cells, row after row.
std::string write_masked_shelf(const TempDir &dir, std::vector<double> &values, double gt[6]) {
    const std::string source = fixture("bathy/etopo5_nwshelf_5min.tif").string(),
                      path = (dir / "shelf_masked.tif").string();
    GDALAllRegister();
    GDALDatasetH src = GDALOpen(source.c_str(), GA_ReadOnly);
    EXPECT_NE(src, nullptr);
    const int nx = GDALGetRasterXSize(src), ny = GDALGetRasterYSize(src);
    GDALGetGeoTransform(src, gt);
    values.resize(static_cast<std::size_t>(nx * ny));
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(src, 1), GF_Read, 0, 0, nx, ny, values.data(), nx, ny,
                           GDT_Float64, 0, 0),
              CE_None);
    std::vector<double> stored = values;
    std::vector<GByte> mask(stored.size(), 255);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const double lon = gt[0] + (i + 0.5) * gt[1], lat = gt[3] + (j + 0.5) * gt[5];
            if (lon > -8 && lon < -4 && lat > 46 && lat < 48)
                stored[j * nx + i] = 0, mask[j * nx + i] = 0;
        }
    CPLSetConfigOption("GDAL_TIFF_INTERNAL_MASK", "YES");
    GDALDatasetH ds =
        GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), nx, ny, 1, GDT_Int16, nullptr);
    EXPECT_NE(ds, nullptr);
    GDALSetGeoTransform(ds, gt);
    GDALSetProjection(ds, GDALGetProjectionRef(src));
    GDALRasterBandH band = GDALGetRasterBand(ds, 1);
    EXPECT_EQ(GDALRasterIO(band, GF_Write, 0, 0, nx, ny, stored.data(), nx, ny, GDT_Float64, 0, 0),
              CE_None);
    EXPECT_EQ(GDALCreateDatasetMaskBand(ds, GMF_PER_DATASET), CE_None);
    EXPECT_EQ(GDALRasterIO(GDALGetMaskBand(band), GF_Write, 0, 0, nx, ny, mask.data(), nx, ny,
                           GDT_Byte, 0, 0),
              CE_None);
    GDALClose(ds);
    CPLSetConfigOption("GDAL_TIFF_INTERNAL_MASK", nullptr);
    GDALClose(src);
    return path;
}

} // namespace

// A raster whose cells without data are marked by a GDAL mask rather than a nodata value (an
// internal per-dataset mask, or the same as an alpha band in a VRT): the masked cells are no
// data, read at full resolution, averaged coarser, or warped (--bathy-srs ED50), and the others
// are the fixture's values. At main the masked cells were read as depth 0.
TEST(Bathymetry, cells_a_gdal_mask_marks_invalid_have_no_data) {
    TempDir dir;
    std::vector<double> z;
    double gt[6];
    const std::string masked = write_masked_shelf(dir, z, gt);
    // The same mask as an alpha band: gdal_translate -b 1 -b mask, band 2 called alpha.
    const std::string alpha = (dir / "shelf_alpha.vrt").string();
    translate(masked, alpha, {"-of", "VRT", "-b", "1", "-b", "mask"});
    GDALDatasetH vrt = GDALOpen(alpha.c_str(), GA_Update);
    ASSERT_NE(vrt, nullptr);
    GDALSetRasterColorInterpretation(GDALGetRasterBand(vrt, 2), GCI_AlphaBand);
    GDALClose(vrt);
    const int nx = 301;
    auto masked_cell = [](double lon, double lat) {
        return lon > -8 && lon < -4 && lat > 46 && lat < 48;
    };
    for (const std::string &path : {masked, alpha}) {
        const Raster r = read_raster(path, 1, false, {}, RasterLimits{});
        int holes = 0;
        for (std::size_t j = 0; j < r.nlat(); ++j)
            for (std::size_t i = 0; i < r.nlon(); ++i) {
                const double v = r.value(i, j);
                if (masked_cell(r.lon_deg(i), r.lat_deg(j))) {
                    EXPECT_TRUE(std::isnan(v)) << path << " " << i << " " << j << " " << v;
                    ++holes;
                } else {
                    ASSERT_EQ(v, z[j * nx + i]) << path << " " << i << " " << j;
                }
            }
        EXPECT_EQ(holes, 47 * 23) << path; // centres -7 11/12 .. -4 1/12, 46 1/12 .. 47 11/12
        // Averaged to a quarter degree (3 x 3 cells): a cell all masked has no data, one with
        // no masked cell has data.
        RasterLimits coarse;
        coarse.min_cell_deg = 0.25;
        const Raster c = read_raster(path, 1, false, {}, coarse);
        EXPECT_TRUE(std::isnan(c.elevation_m(-6, 47))) << path;
        EXPECT_FALSE(std::isnan(c.elevation_m(-9, 47))) << path;
        // Warped: the same file in ED50, whose cells lie about 100 m from WGS 84's.
        MeshOptions o = options_for(path);
        o.bathy_srs = "EPSG:4230";
        o.bathy_fill_m = 1.0; // no coverage check: the file is regional
        const Raster w = read_bathymetry(o);
        EXPECT_EQ(w.elevation_m(-6, 47), -1.0) << path;  // the fill
        EXPECT_LT(w.elevation_m(-9, 47), -1000) << path; // Biscay's abyssal plain, off the mask
    }
}

// ETOPO5 (the fixture, every third row) stored from -180 E and from 0 E, as CF files come:
// averaged to the cells a coarse mesh asks for (0.27 and 0.7 degree: 1.62 and 4.2 of its
// cells), both give the same depths everywhere. GDAL averaged fractional blocks from the first
// column read, so the two spellings gave node depths up to 766 m apart (and other meshes with
// --slope: 49852 nodes against 49505 at --hmin 60).
TEST(Bathymetry, a_global_grid_averages_the_same_stored_from_0_or_from_minus_180) {
    const std::string source = fixture("bathy/etopo5_global_10min.nc").string();
    int nc = -1, lon_id, lat_id, z_id;
    ASSERT_EQ(nc_open(source.c_str(), NC_NOWRITE, &nc), NC_NOERR);
    nc_inq_varid(nc, "lon", &lon_id);
    nc_inq_varid(nc, "lat", &lat_id);
    nc_inq_varid(nc, "elevation", &z_id);
    std::vector<double> lon(2160), lat(1080);
    std::vector<float> z(2160 * 1080);
    nc_get_var_double(nc, lon_id, lon.data());
    nc_get_var_double(nc, lat_id, lat.data());
    ASSERT_EQ(nc_get_var_float(nc, z_id, z.data()), NC_NOERR);
    nc_close(nc);
    TempDir dir;
    const std::string west = (dir / "from_180w.nc").string(), east = (dir / "from_0.nc").string();
    CfGrid a, b;
    for (std::size_t i = 0; i < 2160; ++i) {
        a.lon.push_back(lon[i]);
        b.lon.push_back(i < 1080 ? lon[i + 1080] : lon[i - 1080] + 360);
    }
    for (std::size_t j = 1; j < 1080; j += 3) {
        a.lat.push_back(lat[j]);
        b.lat.push_back(lat[j]);
        for (std::size_t i = 0; i < 2160; ++i) {
            a.z.push_back(z[j * 2160 + i]);
            b.z.push_back(z[j * 2160 + (i + 1080) % 2160]);
        }
    }
    write_cf(west, a);
    write_cf(east, b);
    std::mt19937 rng(43);
    std::uniform_real_distribution<double> ulon(-180, 180), ulat(-85, 85);
    for (const double cell : {0.27, 0.7}) {
        RasterLimits limits;
        limits.min_cell_deg = cell;
        const Raster ra = read_raster(west, 1, false, {}, limits),
                     rb = read_raster(east, 1, false, {}, limits);
        ASSERT_TRUE(ra.global() && rb.global());
        EXPECT_LE(ra.dlon_deg(), cell);
        for (int k = 0; k < 3000; ++k) {
            const double x = ulon(rng), y = ulat(rng);
            ASSERT_NEAR(ra.elevation_m(x, y), rb.elevation_m(x, y), 1e-6)
                << cell << " " << x << " " << y;
        }
    }
}
