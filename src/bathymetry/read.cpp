// read_raster / read_bathymetry: GDAL in, Raster out. The only file of bathymetry/ that sees GDAL.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_string.h>
#include <gdal.h>
#include <gdal_alg.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include "gdal_handles.hpp"
#include "globemesh/bathymetry.hpp"
#include "globemesh/error.hpp"
#include "io/netcdf_lock.hpp"

namespace globemesh {

namespace {

using gdal::DatasetPtr;

/// An argv list for the GDAL utilities, freed on scope exit.
class StringList {
public:
    explicit StringList(std::initializer_list<const char *> items) {
        for (const char *s : items)
            list_ = CSLAddString(list_, s);
    }
    ~StringList() { CSLDestroy(list_); }
    StringList(const StringList &) = delete;
    StringList &operator=(const StringList &) = delete;
    char **get() const { return list_; }
    void add(const char *s) { list_ = CSLAddString(list_, s); }

private:
    char **list_ = nullptr;
};

/// True when PROJ's transformation from srs to WGS 84 lon/lat (EPSG:4326) is the identity over
/// the nx x ny raster of geotransform gt: it moves none of 3 x 3 cell centres spread over it
/// (latitudes clamped to the poles) by more than 1e-9 degrees, longitudes taken modulo 360.
/// Another datum with a known shift (NAD27), prime meridian (Paris) or angular unit moves them;
/// EPSG:4326, CRS84 or a bare WGS 84 ellipsoid (GDAL's netCDF "WGS 84") do not.
bool is_wgs84_in_effect(OGRSpatialReferenceH srs, const double gt[6], int nx, int ny) {
    gdal::SrsRefPtr wgs84(OSRNewSpatialReference(nullptr)), src(OSRClone(srs));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
    OSRSetAxisMappingStrategy(src.get(), OAMS_TRADITIONAL_GIS_ORDER);
    gdal::TransformPtr ct(OCTNewCoordinateTransformation(src.get(), wgs84.get()));
    if (!ct)
        return false;
    double x[9], y[9], z[9] = {}, x0[9], y0[9];
    int ok[9] = {};
    for (int k = 0; k < 9; ++k) {
        const double px = 0.5 + (nx - 1) * (k % 3) / 2.0, py = 0.5 + (ny - 1) * (k / 3) / 2.0;
        x[k] = x0[k] = gt[0] + px * gt[1];
        y[k] = y0[k] = std::clamp(gt[3] + py * gt[5], -90.0, 90.0);
    }
    if (!OCTTransformEx(ct.get(), 9, x, y, z, ok))
        return false;
    for (int k = 0; k < 9; ++k)
        if (!ok[k] || std::abs(std::remainder(x[k] - x0[k], 360.0)) > 1e-9 ||
            std::abs(y[k] - y0[k]) > 1e-9)
            return false;
    return true;
}

/// True when the dataset's CRS is WGS 84 lon/lat in effect (is_wgs84_in_effect) and its
/// geotransform is north- or south-up: then its cells are read as they are, with no warp.
bool is_plain_lonlat(GDALDatasetH ds, const double gt[6]) {
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    if (!srs || !OSRIsGeographic(srs) || gt[2] != 0 || gt[4] != 0 || !(gt[1] > 0) || gt[5] == 0)
        return false;
    return is_wgs84_in_effect(srs, gt, GDALGetRasterXSize(ds), GDALGetRasterYSize(ds));
}

/// True when GDAL's metadata of ds ("variable#attribute" items, as the netCDF driver gives a
/// file's attributes) names a longitude and a latitude coordinate the CF way: standard_name
/// longitude / latitude, or units degrees_east / degrees_north (or CF's other spellings). Not
/// when the file has 2-D coordinates (GDAL's GEOLOCATION arrays): its grid is not lon/lat.
bool has_cf_lonlat_axes(GDALDatasetH ds) {
    if (GDALGetMetadata(ds, "GEOLOCATION") != nullptr)
        return false;
    static const char *const east[] = {"degrees_east", "degree_east", "degrees_e",
                                       "degree_e",     "degreese",    "degreee"};
    static const char *const north[] = {"degrees_north", "degree_north", "degrees_n",
                                        "degree_n",      "degreesn",     "degreen"};
    auto one_of = [](const std::string &v, const auto &list) {
        return std::any_of(std::begin(list), std::end(list), [&](const char *u) { return v == u; });
    };
    bool lon = false, lat = false;
    for (char **item = GDALGetMetadata(ds, nullptr); item && *item; ++item) {
        const std::string s = *item;
        const std::size_t eq = s.find('='), hash = s.rfind('#', eq);
        if (eq == std::string::npos || hash == std::string::npos)
            continue;
        const std::string attribute = s.substr(hash + 1, eq - hash - 1);
        std::string value = s.substr(eq + 1);
        std::transform(value.begin(), value.end(), value.begin(),
                       [](unsigned char c) { return std::tolower(c); });
        if (attribute == "standard_name") {
            lon = lon || value == "longitude";
            lat = lat || value == "latitude";
        } else if (attribute == "units") {
            lon = lon || one_of(value, east);
            lat = lat || one_of(value, north);
        }
    }
    return lon && lat;
}

/// True when the geotransform of an nx x ny raster is north- or south-up and its extent can be
/// degrees: latitudes within a cell of +-90, longitudes in -360..720 and at most 360 degrees
/// and a cell wide.
bool lonlat_extent(const double gt[6], int nx, int ny) {
    if (gt[2] != 0 || gt[4] != 0 || !(gt[1] > 0) || gt[5] == 0)
        return false;
    const double west = gt[0], east = gt[0] + nx * gt[1];
    const double lat_a = gt[3], lat_b = gt[3] + ny * gt[5], cell = std::abs(gt[5]);
    return west >= -360 && east <= 720 && east - west <= 360 + 1.01 * gt[1] &&
           std::min(lat_a, lat_b) >= -90 - 1.01 * cell &&
           std::max(lat_a, lat_b) <= 90 + 1.01 * cell;
}

/// ds with the CRS `srs` (WKT) in place of its own, as a lazy in-memory VRT (gdal_translate
/// -a_srs).
DatasetPtr with_srs(GDALDatasetH ds, const std::string &srs, const std::string &path) {
    StringList argv{"-of", "VRT", "-a_srs", srs.c_str()};
    GDALTranslateOptions *opts = GDALTranslateOptionsNew(argv.get(), nullptr);
    int usage_error = 0;
    DatasetPtr out(GDALTranslate("", ds, opts, &usage_error));
    GDALTranslateOptionsFree(opts);
    if (!out)
        throw IoError(option("bathy") + " " + path +
                      ": cannot assign its CRS: " + gdal::last_error());
    return out;
}

/// --bathy-srs as a CRS; UsageError when it is none (or a local CRS of unknown units, or one
/// with no WKT).
gdal::SrsRefPtr parse_bathy_srs(const std::string &srs) {
    gdal::QuietErrors quiet;
    gdal::SrsRefPtr parsed(OSRNewSpatialReference(nullptr));
    char *wkt = nullptr;
    const bool ok = OSRSetFromUserInput(parsed.get(), srs.c_str()) == OGRERR_NONE &&
                    !OSRIsLocal(parsed.get()) && OSRExportToWkt(parsed.get(), &wkt) == OGRERR_NONE;
    CPLFree(wkt);
    if (!ok)
        throw UsageError(option("bathy_srs") + " '" + srs +
                         "' is not a CRS GDAL/PROJ understands (e.g. EPSG:4326)");
    return parsed;
}

/// The UsageError for band `band` missing from ds (the file `path`, `nbands` bands). A file of
/// no band but subdatasets (a NetCDF of several 2-D variables): their names (SUBDATASET_n_NAME,
/// the first four), to give one as bathy; any other: the band that does not exist.
UsageError missing_band_error(GDALDatasetH ds, const std::string &path, int band, int nbands) {
    std::vector<std::string> names;
    for (char **item = GDALGetMetadata(ds, "SUBDATASETS"); item && *item; ++item) {
        const std::string s = *item;
        const std::size_t eq = s.find('=');
        if (eq != std::string::npos && eq >= 5 && s.compare(eq - 5, 5, "_NAME") == 0)
            names.push_back(s.substr(eq + 1));
    }
    if (nbands > 0 || names.empty())
        return UsageError(option("bathy_band") + " " + std::to_string(band) + ": " + path +
                          " has " + std::to_string(nbands) + " band" + (nbands == 1 ? "" : "s"));
    std::string list;
    for (std::size_t i = 0; i < std::min<std::size_t>(names.size(), 4); ++i)
        list += (i ? ", " : "") + names[i];
    if (names.size() > 4)
        list += " and " + std::to_string(names.size() - 4) + " more (gdalinfo lists them)";
    return UsageError(option("bathy") + " " + path + ": holds " + std::to_string(names.size()) +
                      " rasters (subdatasets), not one; give one of them as " + option("bathy") +
                      " (in single quotes in a shell): " + list);
}

using GroupPtr = gdal::HandlePtr<GDALGroupH, GDALGroupRelease>;
using MdArrayPtr = gdal::HandlePtr<GDALMDArrayH, GDALMDArrayRelease>;

/// A netCDF variable stored X before Y (z(lon, lat)) as GDAL's multidimensional API reads it: a
/// classic raster with columns along X (GDALMDArrayAsClassicDataset), and the file it keeps open.
struct XyView {
    DatasetPtr multidim, classic;
};

/// The short name of ds's driver, "" when it has none.
std::string driver_name(GDALDatasetH ds) {
    GDALDriverH driver = GDALGetDatasetDriver(ds);
    return driver ? GDALGetDriverShortName(driver) : "";
}

/// The XyView of band `band` of ds when it is a netCDF variable whose last two dimensions are X
/// then Y (CF axes, as GDAL types them): GDAL's netCDF raster driver reads those with the axes
/// swapped (columns along latitude). Empty for any other raster. Throws DataError for such a
/// variable of more than two dimensions, which that view does not read (GDAL 3.6).
XyView netcdf_xy_view(GDALDatasetH ds, int band, const std::string &path) {
    const char *var = GDALGetMetadataItem(GDALGetRasterBand(ds, band), "NETCDF_VARNAME", nullptr);
    char **files = GDALGetFileList(ds);
    const std::string file = files && files[0] ? files[0] : "";
    CSLDestroy(files);
    if (driver_name(ds) != "netCDF" || !var || file.empty())
        return {};
    DatasetPtr multidim(GDALOpenEx(file.c_str(), GDAL_OF_MULTIDIM_RASTER | GDAL_OF_READONLY,
                                   nullptr, nullptr, nullptr));
    const GroupPtr root(multidim ? GDALDatasetGetRootGroup(multidim.get()) : nullptr);
    const MdArrayPtr array(root ? GDALGroupOpenMDArray(root.get(), var, nullptr) : nullptr);
    if (!array)
        return {};
    std::size_t n = 0;
    GDALDimensionH *dims = GDALMDArrayGetDimensions(array.get(), &n);
    std::vector<std::string> names, types;
    for (std::size_t k = 0; k < n; ++k) {
        const char *type = GDALDimensionGetType(dims[k]);
        names.emplace_back(GDALDimensionGetName(dims[k]));
        types.emplace_back(type ? type : "");
    }
    GDALReleaseDimensions(dims, n);
    if (n < 2 || types[n - 2] != "HORIZONTAL_X" || types[n - 1] != "HORIZONTAL_Y")
        return {};
    if (n > 2) {
        std::swap(names[n - 2], names[n - 1]);
        std::string order;
        for (const std::string &name : names)
            order += (order.empty() ? "" : ",") + name;
        throw DataError(option("bathy") + " " + path + ": variable " + var +
                        " has its X dimension before its Y one and more than two dimensions, "
                        "which GDAL does not read; reorder it, e.g. ncpdq -a " +
                        order + " IN.nc OUT.nc");
    }
    DatasetPtr classic(GDALMDArrayAsClassicDataset(array.get(), 0, 1));
    if (!classic)
        throw IoError(option("bathy") + " " + path + ": cannot read variable " + var +
                      " (stored X before Y): " + gdal::last_error());
    return {std::move(multidim), std::move(classic)};
}

/// The name of a CRS and its authority code when it has one: "WGS 84 (EPSG:4326)".
std::string srs_name(OGRSpatialReferenceH srs) {
    const char *name = OSRGetName(srs);
    const char *auth = OSRGetAuthorityName(srs, nullptr);
    const char *code = OSRGetAuthorityCode(srs, nullptr);
    return std::string(name ? name : "a CRS") +
           (auth && code ? std::string(" (") + auth + ":" + code + ")" : "");
}

/// The CRS read_raster gives a raster in place of its own: --bathy-srs when set (`srs`), WGS 84
/// lon/lat for a grid without a CRS whose axes are CF longitude and latitude (see
/// has_cf_lonlat_axes, on the file's `metadata`), none otherwise. `note` says which, for the
/// progress line.
struct AssignedCrs {
    DatasetPtr dataset; ///< the raster with that CRS (a VRT), or null: its own CRS stands
    std::string note;
};

AssignedCrs assign_crs(GDALDatasetH ds, GDALDatasetH metadata, const std::string &srs,
                       const std::string &path) {
    OGRSpatialReferenceH own = GDALGetSpatialRef(ds);
    if (own && OSRIsLocal(own))
        own = nullptr; // a local CRS of unknown units is none
    double gt[6];
    if (!srs.empty()) {
        const gdal::SrsRefPtr parsed = parse_bathy_srs(srs);
        char *wkt = nullptr;
        OSRExportToWkt(parsed.get(), &wkt);
        const std::string text = wkt ? wkt : "";
        CPLFree(wkt);
        const char *same_options[] = {"IGNORE_DATA_AXIS_TO_SRS_AXIS_MAPPING=YES", nullptr};
        const bool replaced = own && !OSRIsSameEx(own, parsed.get(), same_options);
        return {with_srs(ds, text, path),
                "CRS " + srs_name(parsed.get()) + " from --bathy-srs" +
                    (replaced ? ", not the file's " + srs_name(own) : "")};
    }
    if (own || GDALGetGeoTransform(ds, gt) != CE_None || !has_cf_lonlat_axes(metadata) ||
        !lonlat_extent(gt, GDALGetRasterXSize(ds), GDALGetRasterYSize(ds)))
        return {};
    return {with_srs(ds, SRS_WKT_WGS84_LAT_LONG, path),
            "no CRS in the file, and its axes are CF longitude/latitude: read as WGS 84 lon/lat, "
            "EPSG:4326"};
}

/// Columns of a lon/lat grid of pixel width dx degrees that go once round the globe: nx when
/// nx * dx is 360, nx - 1 when the last column repeats the first meridian ((nx - 1) * dx is
/// 360), 0 when neither. Within a tenth of a cell: coordinates written with few digits (0.333)
/// or as float32 miss 360 by a fraction of a cell, and no regional grid comes that close.
std::size_t global_columns(std::size_t nx, double dx) {
    for (std::size_t n : {nx, nx - 1})
        if (n > 0 && std::abs(static_cast<double>(n) * dx - 360.0) <= 0.1 * dx)
            return n;
    return 0;
}

/// True when GDAL marks band's cells without data by a mask besides a nodata value: a
/// per-dataset or per-band mask (internal, .msk) or an alpha band (GDALGetMaskFlags).
bool has_mask(GDALRasterBandH band) {
    return (GDALGetMaskFlags(band) & (GMF_ALL_VALID | GMF_NODATA)) == 0;
}

/// A VRT holding band `band` of ds alone (the warper takes every band otherwise), with that
/// band's mask as its own (an alpha band is not among the bands kept).
DatasetPtr single_band_vrt(GDALDatasetH ds, int band, const std::string &path) {
    std::string b = std::to_string(band), mask = "mask," + b;
    StringList argv{"-of", "VRT", "-b", b.c_str()};
    if (has_mask(GDALGetRasterBand(ds, band))) {
        argv.add("-mask");
        argv.add(mask.c_str());
    }
    GDALTranslateOptions *opts = GDALTranslateOptionsNew(argv.get(), nullptr);
    int usage_error = 0;
    DatasetPtr out(GDALTranslate("", ds, opts, &usage_error));
    GDALTranslateOptionsFree(opts);
    if (!out)
        throw IoError(option("bathy") + " " + path + ": cannot select band " + b + ": " +
                      gdal::last_error());
    return out;
}

/// The shorter side (degrees) of a geographic raster's cells, 0 for another CRS: another datum or
/// meridian barely changes it, where the steps finest_lonlat_step samples collapse at a pole
/// (every longitude there is one point, which a datum shift moves as one).
double geographic_cell_deg(GDALDatasetH ds) {
    double gt[6];
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    if (!srs || !OSRIsGeographic(srs) || GDALGetGeoTransform(ds, gt) != CE_None)
        return 0;
    const double unit_deg = OSRGetAngularUnits(srs, nullptr) / deg_to_rad;
    return unit_deg * std::min(std::hypot(gt[1], gt[4]), std::hypot(gt[2], gt[5]));
}

/// The smallest lon/lat size (degrees) of a source pixel step over a 21 x 21 sample of the
/// raster, or 0 when it cannot be computed. Warping at this resolution only upsamples, so GDAL's
/// bilinear kernel stays the plain 2 x 2 one (exact on planes); downsampling widens it.
double finest_lonlat_step(GDALDatasetH ds) {
    double gt[6];
    OGRSpatialReferenceH src = GDALGetSpatialRef(ds);
    if (!src || GDALGetGeoTransform(ds, gt) != CE_None)
        return 0;
    gdal::SrsRefPtr dst(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(dst.get(), 4326);
    OSRSetAxisMappingStrategy(dst.get(), OAMS_TRADITIONAL_GIS_ORDER);
    gdal::SrsRefPtr src_copy(OSRClone(src));
    OSRSetAxisMappingStrategy(src_copy.get(), OAMS_TRADITIONAL_GIS_ORDER);
    gdal::TransformPtr ct(OCTNewCoordinateTransformation(src_copy.get(), dst.get()));
    if (!ct)
        return 0;
    const double nx = GDALGetRasterXSize(ds), ny = GDALGetRasterYSize(ds);
    double best = 0;
    for (int a = 0; a <= 20; ++a)
        for (int b = 0; b <= 20; ++b) {
            double px = std::min(nx - 1, nx * a / 20.0), py = std::min(ny - 1, ny * b / 20.0);
            double x[3], y[3], z[3] = {0, 0, 0};
            int ok[3];
            for (int k = 0; k < 3; ++k) {
                double qx = px + (k == 1), qy = py + (k == 2);
                x[k] = gt[0] + qx * gt[1] + qy * gt[2];
                y[k] = gt[3] + qx * gt[4] + qy * gt[5];
            }
            if (!OCTTransformEx(ct.get(), 3, x, y, z, ok) || !ok[0] || !ok[1] || !ok[2])
                continue;
            for (int k = 1; k < 3; ++k) {
                double step = std::hypot(x[k] - x[0], y[k] - y[0]);
                if (step > 0 && std::isfinite(step) && (best == 0 || step < best))
                    best = step;
            }
        }
    return best;
}

/// Where a raster warped to lon/lat has cells: GDAL's transformer from lon/lat (EPSG:4326) to
/// the source's pixel positions, as the warper uses it.
class Footprint {
public:
    explicit Footprint(GDALDatasetH source)
        : nx_(GDALGetRasterXSize(source)), ny_(GDALGetRasterYSize(source)) {
        StringList options{"DST_SRS=EPSG:4326"};
        transformer_.reset(GDALCreateGenImgProjTransformer2(source, nullptr, options.get()));
    }
    /// GDAL's transformer (GDALGenImgProjTransform's argument), null when GDAL made none.
    void *transformer() const { return transformer_.get(); }
    /// True when (lon, lat) degrees lies on a cell of the source (or on its edge).
    bool contains(double lon, double lat) const {
        if (!transformer_)
            return true; // no transformer: the warp made none either, and failed before
        double x = lon, y = lat, z = 0;
        int ok = 0;
        GDALGenImgProjTransform(transformer_.get(), TRUE, 1, &x, &y, &z, &ok);
        return ok && x >= 0 && x <= nx_ && y >= 0 && y <= ny_;
    }

private:
    int nx_, ny_;
    std::unique_ptr<void, gdal::Deleter<GDALDestroyGenImgProjTransformer>> transformer_;
};

/// ds warped to EPSG:4326 by GDALWarp as a lazy in-memory VRT: bilinear, exact transformer,
/// Float32 with NaN where the source has no data or no coverage, and the options `extra`.
DatasetPtr warp_vrt(GDALDatasetH ds, const std::vector<std::string> &extra,
                    const std::string &path) {
    // XSCALE/YSCALE 1: the plain 2 x 2 kernel in every block. GDAL widens it by a block's source
    // window over its own size, which a block across a global raster's seam takes for a 4-fold
    // downsampling (ETOPO5 in ED50: 2 km off at Hawaii).
    StringList argv{"-of", "VRT",      "-t_srs", "EPSG:4326", "-r",         "bilinear",
                    "-et", "0",        "-ot",    "Float32",   "-dstnodata", "nan",
                    "-wo", "XSCALE=1", "-wo",    "YSCALE=1"};
    for (const std::string &item : extra)
        argv.add(item.c_str());
    GDALWarpAppOptions *opts = GDALWarpAppOptionsNew(argv.get(), nullptr);
    int usage_error = 0;
    GDALDatasetH src = ds;
    DatasetPtr out(GDALWarp("", nullptr, 1, &src, opts, &usage_error));
    GDALWarpAppOptionsFree(opts);
    if (!out)
        throw DataError(option("bathy") + " " + path +
                        ": cannot reproject to lon/lat (EPSG:4326): " + gdal::last_error());
    return out;
}

/// v with all its digits: std::to_string's six decimals cut 1/12 degree to 0.083333, 1 arc
/// second by 0.1%.
std::string all_digits(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

/// ds warped to EPSG:4326 (warp_vrt) at the source's finest pixel size, over the source's extent
/// in lon/lat (GDALSuggestedWarpOutput2, as GDALWarp computes it) with its pixels rounded up to
/// whole steps: GDALWarp rounds them to the nearest, cutting up to half a step off the east and
/// south edges of the source.
DatasetPtr warped_to_lonlat(GDALDatasetH ds, const std::string &path) {
    const double cell = geographic_cell_deg(ds), step = cell > 0 ? cell : finest_lonlat_step(ds);
    const Footprint footprint(ds);
    double gt[6], extent[4];
    int px = 0, py = 0;
    if (!(step > 0) || !footprint.transformer() ||
        GDALSuggestedWarpOutput2(ds, GDALGenImgProjTransform, footprint.transformer(), gt, &px, &py,
                                 extent, 0) != CE_None)
        return warp_vrt(ds, {}, path);
    const double west = extent[0], south = extent[1], east = extent[2], north = extent[3];
    // Rounded up; 1e-6 of a step absorbs the rounding of an extent that is whole steps.
    const double cols = std::ceil((east - west) / step - 1e-6),
                 rows = std::ceil((north - south) / step - 1e-6);
    const std::string res = all_digits(step);
    return warp_vrt(ds,
                    {"-tr", res, res, "-te", all_digits(west), all_digits(north - rows * step),
                     all_digits(west + cols * step), all_digits(north)},
                    path);
}

/// Gives the cells of a warped grid (bx x by, cell (0, 0) centred at lon0, lat0) that lie just
/// off the source's footprint the mean of their neighbours that have data, as a plain raster
/// holds its edge values past its edge: the warper leaves a cell without data when its centre
/// falls off the source, so a point on the source nearest such a cell would have none. Cells
/// without data on the footprint (the source's nodata) stay so.
void hold_footprint_edge(std::vector<float> &values, std::size_t bx, std::size_t by, double lon0,
                         double lat0, double dlon, double dlat, const Footprint &footprint) {
    const std::vector<float> read = values;
    for (std::size_t j = 0; j < by; ++j)
        for (std::size_t i = 0; i < bx; ++i) {
            if (!std::isnan(read[j * bx + i]))
                continue;
            double sum = 0;
            int n = 0;
            for (std::size_t jj = j ? j - 1 : 0; jj <= std::min(by - 1, j + 1); ++jj)
                for (std::size_t ii = i ? i - 1 : 0; ii <= std::min(bx - 1, i + 1); ++ii)
                    if (const float v = read[jj * bx + ii]; !std::isnan(v))
                        sum += v, ++n;
            if (n > 0 && !footprint.contains(lon0 + static_cast<double>(i) * dlon,
                                             lat0 + static_cast<double>(j) * dlat))
                values[j * bx + i] = static_cast<float>(sum / n);
        }
}

/// The columns (a whole number, at most f, at least 1) a global grid of nx columns read whole
/// is averaged by: a divisor of nx / 2 (of nx when odd), so that the blocks' edges fall on both
/// 0 and 180 E. GDAL averages a fractional block from the first column read, so the same grid
/// stored from 0 or from -180 E gave other cells (and another mesh with --slope).
std::size_t global_block(std::size_t nx, double f) {
    const std::size_t half = nx % 2 == 0 ? nx / 2 : nx;
    std::size_t k = static_cast<std::size_t>(std::min(f, static_cast<double>(half)));
    while (k > 1 && half % k != 0)
        --k;
    return std::max<std::size_t>(k, 1);
}

/// The lon/lat edges of an nx x ny north- or south-up raster of geotransform gt, latitudes
/// within the poles.
LonLatBounds grid_bounds(const double gt[6], std::size_t nx, std::size_t ny) {
    const double lat_a = gt[3], lat_b = gt[3] + static_cast<double>(ny) * gt[5];
    return {gt[0], std::max(-90.0, std::min(lat_a, lat_b)), gt[0] + static_cast<double>(nx) * gt[1],
            std::min(90.0, std::max(lat_a, lat_b))};
}

/// Columns [c_lo, c_hi) and rows [r_lo, r_hi) of an nx x ny lon/lat raster (geotransform gt,
/// not rotated) that cover box b and a margin of three cells (the raster's own, or min_cell_deg
/// when larger). The box is taken at whichever of its 360-degree shifts meets the raster most;
/// where it runs across the raster's east or west edge on a global raster (the seam), every
/// column is kept; a box the raster does not meet keeps the whole raster.
struct Window {
    std::size_t c_lo, c_hi, r_lo, r_hi;
};

Window window_of(const LonLatBounds &b, const double gt[6], std::size_t nx, std::size_t ny,
                 double min_cell_deg) {
    const Window whole{0, nx, 0, ny};
    const double mx = 3 * std::max(std::abs(gt[1]), min_cell_deg),
                 my = 3 * std::max(std::abs(gt[5]), min_cell_deg);
    const double r_west = gt[0], r_east = gt[0] + static_cast<double>(nx) * gt[1];
    const bool global = std::abs(r_east - r_west - 360.0) <= 1e-6 * std::abs(gt[1]);
    // Columns: the shift of the box that overlaps the raster most.
    const double west = b.west - mx, east = b.east + mx;
    double best_overlap = 0, lo = 0, hi = 0;
    for (int k = -2; k <= 2; ++k) {
        const double w = west + 360.0 * k, e = east + 360.0 * k;
        const double overlap = std::min(e, r_east) - std::max(w, r_west);
        if (overlap > best_overlap) {
            best_overlap = overlap;
            lo = w;
            hi = e;
        }
    }
    if (best_overlap <= 0)
        return whole;
    Window out = whole;
    if (hi - lo < 360 && (!global || (lo >= r_west && hi <= r_east))) {
        out.c_lo = static_cast<std::size_t>(
            std::clamp(std::floor((std::max(lo, r_west) - r_west) / gt[1]), 0.0, double(nx)));
        out.c_hi = static_cast<std::size_t>(
            std::clamp(std::ceil((std::min(hi, r_east) - r_west) / gt[1]), 0.0, double(nx)));
    }
    // Rows (north-up or south-up).
    const double y_s = (b.south - my - gt[3]) / gt[5], y_n = (b.north + my - gt[3]) / gt[5];
    out.r_lo =
        static_cast<std::size_t>(std::clamp(std::floor(std::min(y_s, y_n)), 0.0, double(ny)));
    out.r_hi = static_cast<std::size_t>(std::clamp(std::ceil(std::max(y_s, y_n)), 0.0, double(ny)));
    if (out.c_hi <= out.c_lo || out.r_hi <= out.r_lo)
        return whole;
    return out;
}

std::string fmt_deg(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.7g", v);
    return buf;
}

std::string fmt_count(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

/// Reads the window (columns c0 .. c0 + nx - 1, rows r0 .. r0 + ny - 1) of the band into
/// `values`, bx x by cells (GDAL's average when that is coarser, which leaves out masked cells),
/// as float; NaN where mask_band (when not null) says no cell has data.
void read_window(GDALRasterBandH read_band, GDALRasterBandH mask_band, std::size_t c0,
                 std::size_t r0, std::size_t nx, std::size_t ny, std::size_t bx, std::size_t by,
                 std::vector<float> &values, const Progress &progress, const std::string &stage,
                 const std::string &path) {
    const double sy = static_cast<double>(ny) / static_cast<double>(by);
    // Strips of rows, so that progress and cancellation are reported while GDAL reads its blocks.
    int block_x = 0, block_y = 0;
    GDALGetBlockSize(read_band, &block_x, &block_y);
    std::size_t strip = std::max<std::size_t>(1, std::min<std::size_t>(by, std::max(block_y, 64)));
    std::vector<float> mask;
    for (std::size_t s0 = 0; s0 < by; s0 += strip) {
        std::size_t s1 = std::min(by, s0 + strip);
        GDALRasterIOExtraArg extra;
        INIT_RASTERIO_EXTRA_ARG(extra);
        double y0 = static_cast<double>(s0) * sy, y1 = static_cast<double>(s1) * sy;
        int iy0 = static_cast<int>(std::floor(y0));
        int iy1 = std::min(static_cast<int>(ny), static_cast<int>(std::ceil(y1 - 1e-9)));
        if (bx != nx || by != ny) {
            extra.eResampleAlg = GRIORA_Average;
            extra.bFloatingPointWindowValidity = TRUE;
            extra.dfXOff = static_cast<double>(c0);
            extra.dfXSize = static_cast<double>(nx);
            extra.dfYOff = static_cast<double>(r0) + y0;
            extra.dfYSize = y1 - y0;
        }
        auto read = [&](GDALRasterBandH band, float *out, GDALRasterIOExtraArg *arg) {
            return GDALRasterIOEx(band, GF_Read, static_cast<int>(c0), static_cast<int>(r0) + iy0,
                                  static_cast<int>(nx), iy1 - iy0, out, static_cast<int>(bx),
                                  static_cast<int>(s1 - s0), GDT_Float32, 0, 0, arg);
        };
        // The mask first, without progress: the strip's share goes to the values.
        if (mask_band) {
            mask.resize((s1 - s0) * bx);
            if (read(mask_band, mask.data(), &extra) != CE_None)
                throw IoError(option("bathy") + " " + path +
                              ": reading its mask failed: " + gdal::last_error());
        }
        gdal::ProgressBridge bridge{
            &progress, 0.05 + 0.9 * static_cast<double>(s0) / static_cast<double>(by),
            0.05 + 0.9 * static_cast<double>(s1) / static_cast<double>(by), stage};
        if (progress) {
            extra.pfnProgress = gdal::ProgressBridge::call;
            extra.pProgressData = &bridge;
        }
        CPLErr err = read(read_band, values.data() + s0 * bx, &extra);
        if (bridge.cancelled)
            throw Cancelled();
        if (err != CE_None)
            throw IoError(option("bathy") + " " + path + ": read failed: " + gdal::last_error());
        for (std::size_t k = 0; k < mask.size() && mask_band; ++k)
            if (mask[k] == 0)
                values[s0 * bx + k] = std::numeric_limits<float>::quiet_NaN();
    }
}

/// Raw values -> metres, elevation positive up; nodata and NaN -> NaN.
void to_elevation(std::vector<float> &values, double scale, double offset, int has_nodata,
                  double nodata, bool depth_positive) {
    const float nodata_f = static_cast<float>(nodata);
    const bool nodata_nan = has_nodata && std::isnan(nodata);
    for (float &v : values) {
        if (!std::isfinite(v) || (has_nodata && !nodata_nan && v == nodata_f)) {
            v = std::numeric_limits<float>::quiet_NaN();
            continue;
        }
        double z = static_cast<double>(v) * scale + offset;
        v = static_cast<float>(depth_positive ? -z : z);
    }
}

} // namespace

Raster read_raster(const std::string &path, int band, bool depth_positive, const Progress &progress,
                   std::size_t max_cells) {
    RasterLimits limits;
    limits.max_cells = max_cells;
    return read_raster(path, band, depth_positive, progress, limits);
}

/// GDAL's block cache capped while a raster is read: every block is read once, so a larger cache
/// only holds blocks that are never asked for again (by default 5% of the RAM, which --max-memory
/// does not see). A GDAL_CACHEMAX the user set stays. 64 MB at most: no slower than a larger
/// cache, a tenth of its peak (bench/RESULTS-core-coast.md).
class BlockCacheCap {
public:
    explicit BlockCacheCap(std::uint64_t budget_bytes) : old_(GDALGetCacheMax64()) {
        if (CPLGetConfigOption("GDAL_CACHEMAX", nullptr))
            return;
        GIntBig cap = GIntBig{64} << 20;
        if (budget_bytes > 0)
            cap = std::min<GIntBig>(cap,
                                    std::max<GIntBig>(GIntBig{4} << 20, GIntBig(budget_bytes / 4)));
        if (cap < old_) {
            GDALSetCacheMax64(cap);
            set_ = true;
        }
    }
    ~BlockCacheCap() {
        if (set_)
            GDALSetCacheMax64(old_);
    }
    BlockCacheCap(const BlockCacheCap &) = delete;
    BlockCacheCap &operator=(const BlockCacheCap &) = delete;

private:
    GIntBig old_;
    bool set_ = false;
};

namespace {

/// A raster as read_source reads it: the lon/lat grid of the window read, the lon/lat extent of
/// the whole raster, and for one warped to lon/lat where its source has cells.
struct SourceRaster {
    Raster raster;
    LonLatBounds extent;
    std::shared_ptr<const Footprint> footprint; ///< null for a plain lon/lat raster
};

/// read_raster, with the extent and footprint read_bathymetry checks the coverage with.
SourceRaster read_source(const std::string &path, int band, bool depth_positive,
                         const Progress &progress, const RasterLimits &limits,
                         const std::string &srs) {
    // GDAL's netCDF driver under the process's netCDF lock too: its own mutex does not keep it
    // from this process's writers (netcdf_lock.hpp).
    const NetcdfLock netcdf(netcdf_mutex());
    quiet_hdf5_errors();
    GDALAllRegister();
    gdal::QuietErrors quiet;
    const BlockCacheCap cache(limits.max_bytes);

    DatasetPtr ds(
        GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
    if (!ds)
        throw IoError(
            option("bathy") + " " + path + ": cannot open as a raster: " +
            gdal::with_archive_hint(gdal::last_error("not a raster format GDAL reads"), path));
    GDALDatasetH h = ds.get();
    const int nbands = GDALGetRasterCount(h);
    if (band < 1 || band > nbands)
        throw missing_band_error(h, path, band, nbands);
    GDALRasterBandH src_band = GDALGetRasterBand(h, band);
    // The grid read: the file as GDAL's raster driver gives it, or for a netCDF variable stored
    // (lon, lat) its multidimensional view (the same cells, the axes the right way round).
    const XyView view = netcdf_xy_view(h, band, path);
    GDALDatasetH grid = view.classic ? view.classic.get() : h;

    // The CRS given in place of the file's (--bathy-srs, or lon/lat for CF lon/lat axes) is
    // said on the progress line, which --verbose shows.
    const AssignedCrs assigned = assign_crs(grid, h, srs, path);
    const std::string stage =
        assigned.dataset ? "read bathymetry (" + assigned.note + ")" : "read bathymetry";
    report(progress, 0.0, stage);
    GDALDatasetH geo = assigned.dataset ? assigned.dataset.get() : grid; // the grid with its CRS

    // Scale, offset and nodata belong to the original band; the warper keeps raw values.
    int has = 0;
    double scale = GDALGetRasterScale(src_band, &has);
    if (!has || !std::isfinite(scale) || scale == 0)
        scale = 1.0;
    double offset = GDALGetRasterOffset(src_band, &has);
    if (!has || !std::isfinite(offset))
        offset = 0.0;
    int has_nodata = 0;
    double nodata = GDALGetRasterNoDataValue(src_band, &has_nodata);

    double gt[6];
    // A GeoTIFF whose CRS was unset reads back with a local (engineering) CRS of unknown
    // units: no more georeferenced than one with none.
    const OGRSpatialReferenceH crs = GDALGetSpatialRef(geo);
    if (GDALGetGeoTransform(geo, gt) != CE_None || !crs || OSRIsLocal(crs))
        throw DataError(
            option("bathy") + " " + path +
            ": has no georeferencing (a geotransform and a geographic or projected CRS); give its "
            "CRS with " +
            option("bathy_srs") +
            " (e.g. EPSG:4326), or assign both, e.g. gdal_translate -a_srs "
            "EPSG:4326 -a_ullr W N E S");

    // The dataset actually read: the source, or a single-band VRT warped to lon/lat.
    DatasetPtr band_vrt, warped;
    GDALRasterBandH read_band = GDALGetRasterBand(grid, band);
    bool warp = !is_plain_lonlat(geo, gt);
    if (warp) {
        band_vrt = single_band_vrt(geo, band, path);
        warped = warped_to_lonlat(band_vrt.get(), path);
        read_band = GDALGetRasterBand(warped.get(), 1);
        if (GDALGetGeoTransform(warped.get(), gt) != CE_None)
            throw DataError(option("bathy") + " " + path +
                            ": the warped raster has no geotransform");
        has_nodata = 0; // the warper writes NaN where there is no data
    }
    GDALDatasetH read_ds = warped ? warped.get() : grid;
    std::size_t nx = static_cast<std::size_t>(GDALGetRasterXSize(read_ds));
    std::size_t ny = static_cast<std::size_t>(GDALGetRasterYSize(read_ds));

    // A global grid: its columns exactly 360 / n apart (the seam closes), and a last column
    // that repeats the first meridian dropped.
    const std::size_t global_nx = global_columns(nx, gt[1]);
    if (global_nx > 0) {
        const double first_centre = gt[0] + 0.5 * gt[1];
        gt[1] = 360.0 / static_cast<double>(global_nx);
        gt[0] = first_centre - 0.5 * gt[1];
        nx = global_nx;
    }
    const LonLatBounds extent = grid_bounds(gt, nx, ny);

    // The window of limits.window: columns c0 .. c0 + nx - 1 and rows r0 .. r0 + ny - 1.
    std::size_t c0 = 0, r0 = 0;
    if (limits.window) {
        const auto [c_lo, c_hi, r_lo, r_hi] =
            window_of(*limits.window, gt, nx, ny, limits.min_cell_deg);
        c0 = c_lo;
        r0 = r_lo;
        nx = c_hi - c_lo;
        ny = r_hi - r_lo;
    }

    // Decimate (GDAL average): cells finer than min_cell_deg, then rasters larger than max_cells.
    // Counts stay in double until they are known to be small (a declared raster may be huge).
    double cx = static_cast<double>(nx), cy = static_cast<double>(ny);
    if (limits.min_cell_deg > 0) {
        // Rounded up, so a cell never gets coarser than asked; 1e-9 absorbs the step's rounding.
        const double fx = limits.min_cell_deg / std::abs(gt[1]),
                     fy = limits.min_cell_deg / std::abs(gt[5]);
        if (fx > 1)
            cx = std::max(1.0, std::ceil(cx / fx - 1e-9));
        if (fy > 1)
            cy = std::max(1.0, std::ceil(cy / fy - 1e-9));
        // A global grid read whole: whole blocks (global_block), when they fit the budget.
        const double whole = global_nx > 0 && nx == global_nx && fx > 1
                                 ? static_cast<double>(nx / global_block(nx, fx))
                                 : cx;
        if (limits.max_bytes == 0 ||
            whole * cy * sizeof(float) <= static_cast<double>(limits.max_bytes))
            cx = whole;
    }
    if (limits.max_cells > 0 && cx * cy > static_cast<double>(limits.max_cells)) {
        double f = std::sqrt(cx * cy / static_cast<double>(limits.max_cells));
        cx = std::max(1.0, std::floor(cx / f));
        cy = std::max(1.0, std::floor(cy / f));
    }
    const double bytes = cx * cy * static_cast<double>(sizeof(float));
    if (limits.max_bytes > 0 && bytes > static_cast<double>(limits.max_bytes))
        throw DataError(option("bathy") + " " + path + ": " + std::to_string(nx) + " x " +
                        std::to_string(ny) + " cells, read as " + fmt_count(cx) + " x " +
                        fmt_count(cy) + " (" + memory_text(bytes) + "), exceed the " +
                        memory_text(static_cast<double>(limits.max_bytes)) + " that " +
                        option("max_memory_bytes") + " leaves for it; raise " +
                        option("max_memory_bytes") + " or " + option("hmin_km") +
                        ", or give a "
                        "coarser raster (gdal_translate -tr)");
    const std::size_t bx = static_cast<std::size_t>(cx), by = static_cast<std::size_t>(cy);
    const double sx = static_cast<double>(nx) / static_cast<double>(bx);
    const double sy = static_cast<double>(ny) / static_cast<double>(by);
    const double dlon = gt[1] * sx, dlat = gt[5] * sy;

    std::vector<float> values(bx * by);
    // A mask besides nodata (GDAL's per-dataset or per-band mask, an alpha band) marks cells
    // without data too; the warper applies it itself.
    GDALRasterBandH mask_band = has_mask(read_band) ? GDALGetMaskBand(read_band) : nullptr;
    read_window(read_band, mask_band, c0, r0, nx, ny, bx, by, values, progress, stage, path);

    to_elevation(values, scale, offset, has_nodata, nodata, depth_positive);

    const double west = gt[0] + static_cast<double>(c0) * gt[1],
                 top = gt[3] + static_cast<double>(r0) * gt[5];
    std::shared_ptr<const Footprint> footprint;
    if (warp) {
        footprint = std::make_shared<const Footprint>(band_vrt.get());
        hold_footprint_edge(values, bx, by, west + 0.5 * dlon, top + 0.5 * dlat, dlon, dlat,
                            *footprint);
    }
    Raster raster(west + 0.5 * dlon, top + 0.5 * dlat, dlon, dlat, bx, by, std::move(values));
    if (raster.valid_count() == 0)
        throw DataError(option("bathy") + " " + path + ": band " + std::to_string(band) +
                        " holds no valid value (all nodata)");
    report(progress, 1.0, stage);
    return {std::move(raster), extent, std::move(footprint)};
}

} // namespace

Raster read_raster(const std::string &path, int band, bool depth_positive, const Progress &progress,
                   const RasterLimits &limits, const std::string &srs) {
    return read_source(path, band, depth_positive, progress, limits, srs).raster;
}

void validate_bathy_srs(const std::string &srs) {
    if (!srs.empty())
        parse_bathy_srs(srs);
}

RasterLimits bathymetry_limits(const BathymetryContext &o, const Boundary *ocean) {
    // The mesh samples the raster at its nodes and on the size field's grid (spacing hfloor / 2):
    // finer cells only alias there, so they are averaged to that size.
    const double hfloor_km = o.hfloor_km;
    RasterLimits limits;
    limits.min_cell_deg = 0.5 * hfloor_km / (earth_radius_km * deg_to_rad);
    limits.max_bytes = o.max_memory_bytes / 2; // the other half: the size field and the mesh
    std::optional<LonLatBounds> box;
    if (o.region) {
        const auto &r = *o.region;
        box = LonLatBounds{r[0], r[1], r[2] > r[0] ? r[2] : r[2] + 360, r[3]};
    } else if (!o.region_file.empty() && ocean) {
        box = ocean_extent(*ocean);
        if (box && box->east - box->west >= 360 && box->south <= -90 && box->north >= 90)
            box.reset();
    }
    if (box) {
        // The region and 1% of its larger side: the size field's grid over it reaches a cell
        // beyond, and its cells are at most 1/2048 of that side (pipeline.cpp, 2^22 nodes).
        const double pad = 0.01 * std::max(box->east - box->west, box->north - box->south);
        limits.window = LonLatBounds{box->west - pad, std::max(-90.0, box->south - pad),
                                     box->east + pad, std::min(90.0, box->north + pad)};
    }
    return limits;
}

namespace {

/// How far (degrees, the larger of the two axes) a point lies outside the box b, 0 inside it;
/// longitudes taken modulo 360.
double outside_deg(const LonLatBounds &b, double lon, double lat) {
    const double dlat = std::max({0.0, b.south - lat, lat - b.north});
    double dlon = 0;
    if (b.east - b.west < 360) {
        const double x = b.west + std::fmod(std::fmod(lon - b.west, 360.0) + 360.0,
                                            360.0); // in [west, west + 360)
        dlon = x <= b.east ? 0.0 : std::min(x - b.east, b.west + 360 - x);
    }
    return std::max(dlat, dlon);
}

/// True when s covers (lon, lat): inside its grid and, for a warped raster, within about a
/// cell of its source's footprint (the point or a corner of the 3 x 3 cells round it on it),
/// where hold_footprint_edge gives the nearest cell data. A point refused here has none.
bool is_covered(const SourceRaster &s, double lon, double lat) {
    if (!s.raster.contains(lon, lat))
        return false;
    if (!s.footprint || s.footprint->contains(lon, lat))
        return true;
    const double hx = 1.5 * s.raster.dlon_deg(), hy = 1.5 * std::abs(s.raster.dlat_deg());
    for (const double dx : {-hx, hx})
        for (const double dy : {-hy, hy})
            if (s.footprint->contains(lon + dx, std::clamp(lat + dy, -90.0, 90.0)))
                return true;
    return false;
}

/// The point of the ocean's outline (its rings' nodes, and on segments longer than a raster
/// cell points a quarter of a cell apart, as the great-circle arcs bulge) or a pole inside it
/// that s does not cover, farthest outside its grid; nullopt when s covers them all.
std::optional<LonLat> uncovered_point(const SourceRaster &s, const Boundary &ocean) {
    const Raster &r = s.raster;
    const double cell = std::min(r.dlon_deg(), std::abs(r.dlat_deg())) * deg_to_rad,
                 step = 0.25 * cell;
    const LonLatBounds b = r.bounds();
    std::optional<LonLat> worst;
    double worst_deg = -1;
    auto check = [&](const LonLat &p) {
        if (is_covered(s, p.lon, p.lat))
            return;
        if (const double d = outside_deg(b, p.lon, p.lat); d > worst_deg)
            worst_deg = d, worst = p;
    };
    for (const Ring &ring : ocean.rings) {
        for (std::size_t i = 0; i < ring.nodes.size(); ++i) {
            const Vec3 &a = ring.nodes[i], &c = ring.nodes[(i + 1) % ring.nodes.size()];
            const double arc = arc_angle(a, c);
            const int parts =
                arc > cell ? static_cast<int>(std::min(1e4, std::ceil(arc / step))) : 1;
            check(vec_to_lonlat(a));
            for (int k = 1; k < parts; ++k)
                check(vec_to_lonlat(arc_interpolate(a, c, double(k) / parts)));
        }
    }
    const int winding = ocean_pole_winding(ocean);
    if (winding > 0)
        check(LonLat{0, 90});
    if (winding < 0)
        check(LonLat{0, -90});
    return worst;
}

} // namespace

Raster read_bathymetry(const BathymetryOptions &o, const BathymetryContext &context,
                       const Progress &progress, const Boundary *ocean) {
    if (o.bathy.empty())
        throw UsageError(option("bathy") + ": no raster given");
    if (o.bathy_fill_m && !std::isfinite(*o.bathy_fill_m))
        throw UsageError(option("bathy_fill_m") + " must be a depth in metres");
    SourceRaster source = read_source(o.bathy, o.bathy_band, o.depth_positive, progress,
                                      bathymetry_limits(context, ocean), o.bathy_srs);
    Raster &r = source.raster;
    if (o.bathy_fill_m) {
        r.set_fill_elevation_m(-*o.bathy_fill_m);
        return std::move(r);
    }
    // The whole raster's extent, not the window read; a warped one's cells fill only part of it.
    const LonLatBounds &b = source.extent;
    const ErrorText covers =
        option("bathy") + " " + o.bathy + ": covers only lon " + fmt_deg(b.west) + ".." +
        fmt_deg(b.east) + ", lat " + fmt_deg(b.south) + ".." + fmt_deg(b.north) +
        (source.footprint ? ErrorText(" (its cells, rotated or in another CRS, fill only part of "
                                      "that box)")
                          : ErrorText(""));
    const ErrorText remedy = "; pass " + option("bathy_fill_m") + " DEPTH for the rest, or a " +
                             option("region") + " or " + option("region_file") +
                             " inside the raster";
    // A region's ocean, as the coast stage cut it: its outline (a pole inside it) in the raster.
    if (ocean && !ocean->rings.empty() && (context.region || !context.region_file.empty())) {
        if (const auto p = uncovered_point(source, *ocean))
            throw DataError(covers + " but the ocean of " +
                            (context.region ? option("region")
                                            : option("region_file") + " " + context.region_file) +
                            " reaches lon " + fmt_deg(p->lon) + ", lat " + fmt_deg(p->lat) +
                            remedy);
        return std::move(r);
    }
    // Coverage of the region (the whole globe without --region), on a dense set of points.
    double w = -180, s = -90, e = 180, n = 90;
    if (context.region) {
        w = (*context.region)[0];
        s = (*context.region)[1];
        e = (*context.region)[2];
        n = (*context.region)[3];
        if (e <= w)
            e += 360;
    }
    const int steps = 720;
    bool covered = true;
    for (int k = 0; k <= steps && covered; ++k) {
        double lon = w + (e - w) * k / steps;
        double lat = s + (n - s) * k / steps;
        covered = is_covered(source, lon, 0.5 * (s + n)) &&
                  is_covered(source, 0.5 * (w + e), lat) && is_covered(source, lon, s) &&
                  is_covered(source, lon, n);
    }
    if (!covered)
        throw DataError(covers +
                        (context.region ? " but not all of " + option("region")
                                        : ErrorText(" but the region is the whole globe")) +
                        remedy);
    return std::move(r);
}

} // namespace globemesh
