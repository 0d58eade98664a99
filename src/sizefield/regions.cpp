// --size-regions: polygons with a size_km attribute, burnt onto the background grid with GDAL's
// rasteriser (the grid's node is the centre of a raster cell) into every cell a polygon touches:
// by the default rule, cell centre inside, a strip 1 km wide along a coast fell between the
// centres of a global grid's 14 km cells (its nodes got 5.7 to 8.5 km of its 5).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <cpl_error.h>
#include <gdal.h>
#include <gdal_alg.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "gdal_handles.hpp"
#include "globemesh/error.hpp"
#include "grid.hpp"
#include "map_edge.hpp"
#include "pole_rings.hpp"
#include "projected_edges.hpp"

namespace globemesh::detail {

namespace {

using gdal::DatasetPtr;
using gdal::FeaturePtr;
using gdal::GeometryPtr;
using gdal::TransformPtr;

std::string last_message() {
    return gdal::last_error("unknown error");
}

/// "a, b, c": the layer names of `ds`, for messages.
std::string layer_names(GDALDatasetH ds) {
    std::string list;
    for (int l = 0; l < GDALDatasetGetLayerCount(ds); ++l)
        list += (l ? ", " : "") + std::string(OGR_L_GetName(GDALDatasetGetLayer(ds, l)));
    return list.empty() ? "none" : list;
}

/// The layers to read: `name` alone when given (DataError when the file has no such layer or
/// it has no size_km field), else every layer of `ds`.
std::vector<OGRLayerH> size_layers(GDALDatasetH ds, const std::string &path,
                                   const std::string &name) {
    std::vector<OGRLayerH> layers;
    if (name.empty()) {
        for (int l = 0; l < GDALDatasetGetLayerCount(ds); ++l)
            layers.push_back(GDALDatasetGetLayer(ds, l));
        return layers;
    }
    OGRLayerH layer = GDALDatasetGetLayerByName(ds, name.c_str());
    if (!layer)
        throw DataError(option("size_regions") + " " + path + ": no layer named '" + name + "' (" +
                        option("size_regions_layer") + "); layers: " + layer_names(ds));
    if (OGR_FD_GetFieldIndex(OGR_L_GetLayerDefn(layer), "size_km") < 0)
        throw DataError(option("size_regions") + " " + path + " layer '" + name +
                        "' has no size_km field (edge length in km)");
    layers.push_back(layer);
    return layers;
}

/// Features a layer's reading skipped, for its message: how many, and the first.
struct Skipped {
    std::size_t count = 0;
    GIntBig first = OGRNullFID;
    OGRwkbGeometryType first_type = wkbNone;
    void add(OGRFeatureH f, OGRwkbGeometryType type) {
        if (count++ == 0)
            first = OGR_F_GetFID(f), first_type = type;
    }
    /// "feature 3 `one`" or "2 features `many` (the first, feature 3, `first`)".
    std::string text(const std::string &one, const std::string &many,
                     const std::string &first_is) const {
        const std::string fid = "feature " + std::to_string(first);
        return count == 1 ? fid + " " + one
                          : std::to_string(count) + " features " + many + " (the first, " + fid +
                                ", " + first_is + ")";
    }
    /// The first one's geometry type, "a Line String" or "no geometry".
    std::string first_geometry() const {
        return first_type == wkbNone ? "no geometry"
                                     : std::string("a ") + OGRGeometryTypeToName(first_type);
    }
};

/// Widens `lon_range` to the longitudes of `g` (a polygon may be drawn past +-180).
void widen_lon_range(OGRGeometryH g, std::array<double, 2> &lon_range) {
    OGREnvelope e;
    OGR_G_GetEnvelope(g, &e);
    lon_range = {std::min(lon_range[0], e.MinX), std::max(lon_range[1], e.MaxX)};
}

/// Each ring of a polygon or multipolygon reprojected to lon/lat from a projected CRS: closed
/// through its pole where it goes round or through one, from a CRS that holds a pole as a point
/// (`pole_point`; close_at_pole: drawn about a pole, it burnt nothing), else joined across +-180
/// where it jumps there (join_across_seam: drawn across the antimeridian, it burnt every
/// longitude but its own); `lon_range` widened to its longitudes (which may then pass +-180).
void unwrap_rings(OGRGeometryH g, bool pole_point, std::array<double, 2> &lon_range) {
    if (wkbFlatten(OGR_G_GetGeometryType(g)) == wkbMultiPolygon) {
        for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i)
            unwrap_rings(OGR_G_GetGeometryRef(g, i), pole_point, lon_range);
        return;
    }
    for (int i = 0; i < OGR_G_GetGeometryCount(g); ++i) {
        OGRGeometryH ring = OGR_G_GetGeometryRef(g, i);
        std::vector<LonLat> pts(static_cast<std::size_t>(OGR_G_GetPointCount(ring)));
        for (std::size_t k = 0; k < pts.size(); ++k)
            pts[k] = {OGR_G_GetX(ring, int(k)), OGR_G_GetY(ring, int(k))};
        if (!(pole_point && detail::close_at_pole(pts)) && !detail::join_across_seam(pts))
            continue;
        OGR_G_SetPointCount(ring, static_cast<int>(pts.size()));
        for (std::size_t k = 0; k < pts.size(); ++k)
            OGR_G_SetPoint_2D(ring, int(k), pts[k].lon, pts[k].lat);
    }
    widen_lon_range(g, lon_range);
}

} // namespace

void apply_size_regions(const BackgroundGrid &g, const std::string &path,
                        const std::string &layer_name, std::vector<float> &h) {
    GDALAllRegister();
    gdal::QuietErrors quiet;
    DatasetPtr ds = gdal::open_vector(path, option("size_regions") + " " + path);

    gdal::SrsRefPtr wgs84(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);

    // Polygons in lon/lat with their sizes, and their longitudes' range.
    std::vector<std::pair<double, GeometryPtr>> regions;
    std::array<double, 2> lon_range{180.0, -180.0};
    bool any_field = false;
    // Sides drawn in a projected CRS are split a grid cell apart (the rasteriser sees no finer).
    const double edge_step_m = g.dlat * earth_radius_km * 1000 * pi / 180;
    for (OGRLayerH layer : size_layers(ds.get(), path, layer_name)) {
        OGRFeatureDefnH defn = OGR_L_GetLayerDefn(layer);
        int field = OGR_FD_GetFieldIndex(defn, "size_km");
        if (field < 0)
            continue;
        any_field = true;
        OGRSpatialReferenceH srs = OGR_L_GetSpatialRef(layer);
        if (!srs || OSRIsLocal(srs)) // a local CRS (LOCAL_CS, unknown units) is no more use
            throw DataError(option("size_regions") + " " + path + ": layer " +
                            OGR_L_GetName(layer) + " has no CRS" +
                            (srs ? " (only a local one, of unknown units)" : "") +
                            "; assign one (e.g. ogr2ogr -a_srs EPSG:4326)");
        TransformPtr to_lonlat(OCTNewCoordinateTransformation(srs, wgs84.get()));
        if (!to_lonlat)
            throw DataError(option("size_regions") + " " + path + ": cannot transform layer " +
                            OGR_L_GetName(layer) + " to lon/lat");
        const bool projected = OSRIsProjected(srs),
                   pole_point = detail::holds_a_pole_as_a_point(srs);
        const MapEdge edge = projected ? map_edge(srs) : MapEdge{};
        Skipped not_polygons, without_size;
        OGR_L_ResetReading(layer);
        while (FeaturePtr f{OGR_L_GetNextFeature(layer)}) {
            OGRFeatureH fh = f.get();
            OGRGeometryH geom = OGR_F_GetGeometryRef(fh);
            if (!geom || OGR_G_IsEmpty(geom))
                continue; // a row without a shape (a table edited in QGIS) sizes nothing
            const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(geom));
            if (type != wkbPolygon && type != wkbMultiPolygon) {
                not_polygons.add(fh, type);
                continue;
            }
            if (!OGR_F_IsFieldSetAndNotNull(fh, field)) {
                without_size.add(fh, type);
                continue;
            }
            double size = OGR_F_GetFieldAsDouble(fh, field);
            if (!(std::isfinite(size) && size > 0))
                throw DataError(option("size_regions") + " " + path + ": feature " +
                                std::to_string(OGR_F_GetFID(fh)) + " has size_km " +
                                OGR_F_GetFieldAsString(fh, field) + "; sizes must be positive km");
            GeometryPtr split(OGR_G_Clone(geom));
            split_projected_edges(split.get(), srs, edge_step_m);
            std::string why; // a world map's points on its +-180 edge are retried (map_edge.hpp)
            GeometryPtr copy = reprojected(split.get(), to_lonlat.get(), projected, edge, why);
            if (!copy)
                throw DataError(option("size_regions") + " " + path +
                                ": cannot transform feature " + std::to_string(OGR_F_GetFID(fh)) +
                                " to lon/lat");
            if (projected)
                unwrap_rings(copy.get(), pole_point, lon_range);
            else
                widen_lon_range(copy.get(), lon_range);
            regions.emplace_back(size, std::move(copy));
        }
        const ErrorText where =
            option("size_regions") + " " + path + " layer '" + OGR_L_GetName(layer) + "'";
        if (not_polygons.count)
            throw DataError(
                where + ": " +
                not_polygons.text("is " + not_polygons.first_geometry() + ", not a polygon",
                                  "are not polygons", "is " + not_polygons.first_geometry()) +
                "; size regions are polygons with a size_km");
        if (without_size.count)
            throw DataError(
                where + ": " +
                without_size.text("has no size_km (null)", "have no size_km (null)", "has none") +
                "; give each polygon its edge length in km, or leave them out "
                "(ogr2ogr -where \"size_km IS NOT NULL\")");
    }
    if (!any_field)
        throw DataError(option("size_regions") + " " + path +
                        ": no layer has a size_km field (edge length in km)");
    if (regions.empty())
        throw DataError(option("size_regions") + " " + path +
                        ": no polygon in it; size regions are polygons with a size_km");
    // Largest first: with the REPLACE rule the smallest size burnt last wins (a minimum).
    std::stable_sort(regions.begin(), regions.end(),
                     [](const auto &a, const auto &b) { return a.first > b.first; });
    std::vector<OGRGeometryH> geoms;
    std::vector<double> burn;
    for (auto &r : regions) {
        geoms.push_back(r.second.get());
        burn.push_back(r.first);
    }

    GDALDriverH mem = GDALGetDriverByName("MEM");
    const int nx = static_cast<int>(g.nlon), ny = static_cast<int>(g.nlat);
    const double west = g.lon0 - 0.5 * g.dlon,
                 north = g.lat0 + (static_cast<double>(g.nlat) - 0.5) * g.dlat;
    std::vector<float> row(g.nlon);
    // Grids reaching beyond [-180, 180], and polygons, also burn the polygons shifted by 360
    // degrees.
    for (double shift : {0.0, -360.0, 360.0}) {
        const double east = west + static_cast<double>(g.nlon) * g.dlon;
        if (shift < 0 && east <= 180.0 && lon_range[0] >= -180.0)
            continue;
        if (shift > 0 && west >= -180.0 && lon_range[1] <= 180.0)
            continue;
        DatasetPtr target(GDALCreate(mem, "", nx, ny, 1, GDT_Float32, nullptr));
        if (!target)
            throw IoError(option("size_regions") +
                          ": cannot create an in-memory grid: " + last_message());
        // North-up: raster row r is grid row nlat-1-r. Shift moves the polygons' lon by -shift.
        double gt[6] = {west + shift, g.dlon, 0, north, 0, -g.dlat};
        GDALSetGeoTransform(target.get(), gt);
        GDALRasterBandH band = GDALGetRasterBand(target.get(), 1);
        GDALFillRaster(band, std::numeric_limits<double>::infinity(), 0);
        int one = 1;
        const char *all_touched[] = {"ALL_TOUCHED=TRUE", nullptr}; // see the file's head
        if (GDALRasterizeGeometries(target.get(), 1, &one, static_cast<int>(geoms.size()),
                                    geoms.data(), nullptr, nullptr, burn.data(),
                                    const_cast<char **>(all_touched), nullptr, nullptr) != CE_None)
            throw IoError(option("size_regions") + " " + path +
                          ": rasterising failed: " + last_message());
        for (int r = 0; r < ny; ++r) {
            if (GDALRasterIO(band, GF_Read, 0, r, nx, 1, row.data(), nx, 1, GDT_Float32, 0, 0) !=
                CE_None)
                throw IoError(option("size_regions") +
                              ": reading the in-memory grid failed: " + last_message());
            std::size_t j = g.nlat - 1 - static_cast<std::size_t>(r);
            for (std::size_t i = 0; i < g.nlon; ++i)
                h[j * g.nlon + i] = std::min(h[j * g.nlon + i], row[i]);
        }
    }
}

} // namespace globemesh::detail
