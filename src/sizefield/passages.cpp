// --passages: lines across straits read from OGR (any CRS, to lon/lat as --size-regions), their
// widths in water, and the size they ask along them on the background grid.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <cpl_error.h>
#include <gdal.h>
#include <ogr_api.h>
#include <ogr_srs_api.h>

#include "gdal_handles.hpp"
#include "globemesh/error.hpp"
#include "globemesh/passages.hpp"
#include "grid.hpp"

namespace globemesh {

namespace {

using gdal::DatasetPtr;
using gdal::FeaturePtr;
using gdal::GeometryPtr;
using gdal::TransformPtr;

ErrorText where(const std::string &path) {
    return option("passages") + " " + path;
}

/// The layers to read: `name` alone when given, else every layer of `ds`.
std::vector<OGRLayerH> passage_layers(GDALDatasetH ds, const std::string &path,
                                      const std::string &name) {
    std::vector<OGRLayerH> layers;
    if (name.empty()) {
        for (int l = 0; l < GDALDatasetGetLayerCount(ds); ++l)
            layers.push_back(GDALDatasetGetLayer(ds, l));
        return layers;
    }
    if (OGRLayerH layer = GDALDatasetGetLayerByName(ds, name.c_str()))
        return {layer};
    std::string list;
    for (int l = 0; l < GDALDatasetGetLayerCount(ds); ++l)
        list += (l ? ", " : "") + std::string(OGR_L_GetName(GDALDatasetGetLayer(ds, l)));
    throw DataError(where(path) + ": no layer named '" + name + "' (" + option("passages_layer") +
                    "); layers: " + (list.empty() ? "none" : list));
}

/// The line strings of a (multi)line geometry in lon/lat, as unit vectors.
void add_lines(OGRGeometryH geom, const std::string &name, std::vector<Passage> &out) {
    const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(geom));
    if (type == wkbMultiLineString || type == wkbGeometryCollection) {
        const int parts = OGR_G_GetGeometryCount(geom);
        for (int k = 0; k < parts; ++k)
            add_lines(OGR_G_GetGeometryRef(geom, k),
                      parts > 1 ? name + " " + std::to_string(k + 1) : name, out);
        return;
    }
    if (type != wkbLineString || OGR_G_GetPointCount(geom) < 2)
        return;
    Passage p{name, {}, 0};
    for (int i = 0; i < OGR_G_GetPointCount(geom); ++i)
        p.line.push_back(lonlat_to_vec(OGR_G_GetX(geom, i), OGR_G_GetY(geom, i)));
    out.push_back(std::move(p));
}

/// The passages of one layer; DataError for a layer of polygons or points.
void read_layer(OGRLayerH layer, const std::string &path, OGRSpatialReferenceH wgs84,
                std::vector<Passage> &out) {
    const std::string lname = OGR_L_GetName(layer);
    const OGRwkbGeometryType ltype = wkbFlatten(OGR_L_GetGeomType(layer));
    if (ltype != wkbUnknown && ltype != wkbLineString && ltype != wkbMultiLineString)
        throw DataError(where(path) + ": layer " + lname + " holds " +
                        OGRGeometryTypeToName(ltype) +
                        " geometries; passages are lines drawn across straits");
    OGRSpatialReferenceH srs = OGR_L_GetSpatialRef(layer);
    if (!srs || OSRIsLocal(srs))
        throw DataError(where(path) + ": layer " + lname +
                        " has no CRS; assign one (e.g. ogr2ogr -a_srs EPSG:4326)");
    TransformPtr to_lonlat(OCTNewCoordinateTransformation(srs, wgs84));
    if (!to_lonlat)
        throw DataError(where(path) + ": cannot transform layer " + lname + " to lon/lat");
    const int name_field = OGR_FD_GetFieldIndex(OGR_L_GetLayerDefn(layer), "name");
    OGR_L_ResetReading(layer);
    while (FeaturePtr f{OGR_L_GetNextFeature(layer)}) {
        OGRGeometryH geom = OGR_F_GetGeometryRef(f.get());
        if (!geom)
            continue;
        const std::string fid = std::to_string(OGR_F_GetFID(f.get()));
        const OGRwkbGeometryType type = wkbFlatten(OGR_G_GetGeometryType(geom));
        if (type != wkbLineString && type != wkbMultiLineString)
            throw DataError(where(path) + ": feature " + fid + " of layer " + lname + " is a " +
                            OGRGeometryTypeToName(type) +
                            "; passages are lines drawn across straits");
        GeometryPtr copy(OGR_G_Clone(geom));
        if (OGR_G_Transform(copy.get(), to_lonlat.get()) != OGRERR_NONE)
            throw DataError(where(path) + ": cannot transform feature " + fid + " to lon/lat");
        const bool named = name_field >= 0 && OGR_F_IsFieldSetAndNotNull(f.get(), name_field);
        add_lines(copy.get(),
                  named ? OGR_F_GetFieldAsString(f.get(), name_field) : "passage " + fid, out);
    }
}

} // namespace

std::vector<Passage> read_passages(const std::string &path, const std::string &layer) {
    GDALAllRegister();
    gdal::QuietErrors quiet;
    DatasetPtr ds = gdal::open_vector(path, where(path));
    gdal::SrsRefPtr wgs84(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
    std::vector<Passage> passages;
    for (OGRLayerH l : passage_layers(ds.get(), path, layer))
        read_layer(l, path, wgs84.get(), passages);
    if (passages.empty())
        throw DataError(where(path) + ": no line in it; passages are lines drawn across straits");
    return passages;
}

void measure_passages(std::vector<Passage> &passages, const LandTest *land) {
    for (Passage &p : passages) {
        double length = 0, water = 0;
        for (std::size_t i = 0; i + 1 < p.line.size(); ++i) {
            const double arc = arc_km(p.line[i], p.line[i + 1]);
            length += arc;
            if (!land)
                continue;
            // Samples every arc / n km, n for steps of at most 25 m and 4000 over the arc.
            const auto n = static_cast<std::size_t>(std::clamp(arc / 0.025, 4000.0, 200000.0));
            std::size_t wet = 0;
            for (std::size_t k = 0; k < n; ++k)
                wet += !land->contains(
                    arc_interpolate(p.line[i], p.line[i + 1], (static_cast<double>(k) + 0.5) / n));
            water += arc * static_cast<double>(wet) / static_cast<double>(n);
        }
        p.width_km = land ? water : length;
    }
}

namespace detail {

void apply_passages(const BackgroundGrid &g, std::span<const Passage> passages, int cells,
                    std::vector<float> &h) {
    // Each line, sampled four times per grid spacing (in lat and lon), sets the corners of its
    // cell: the field is then the passage's size on every cell the line runs through.
    for (const Passage &p : passages) {
        if (!(p.width_km > 0))
            continue;
        const auto size = static_cast<float>(p.width_km / cells);
        for (std::size_t i = 0; i + 1 < p.line.size(); ++i) {
            const double dlon = std::abs(std::remainder(
                vec_to_lonlat(p.line[i + 1]).lon - vec_to_lonlat(p.line[i]).lon, 360.0));
            const double spans =
                std::max(arc_km(p.line[i], p.line[i + 1]) / g.dy_km, dlon / g.dlon);
            const auto n = static_cast<std::size_t>(std::ceil(4 * spans)) + 1;
            for (std::size_t k = 0; k <= n; ++k) {
                const LonLat ll = vec_to_lonlat(
                    arc_interpolate(p.line[i], p.line[i + 1], static_cast<double>(k) / n));
                double u = (ll.lon - g.lon0) / g.dlon;
                if (g.global)
                    u -= std::floor(u / static_cast<double>(g.nlon)) * static_cast<double>(g.nlon);
                const double v = (ll.lat - g.lat0) / g.dlat;
                for (long dj = 0; dj <= 1; ++dj)
                    for (long di = 0; di <= 1; ++di) {
                        long i2 = static_cast<long>(std::floor(u)) + di;
                        const long j2 = static_cast<long>(std::floor(v)) + dj;
                        if (g.global)
                            i2 = (i2 + static_cast<long>(g.nlon)) % static_cast<long>(g.nlon);
                        if (i2 < 0 || j2 < 0 || i2 >= static_cast<long>(g.nlon) ||
                            j2 >= static_cast<long>(g.nlat))
                            continue;
                        float &x =
                            h[static_cast<std::size_t>(j2) * g.nlon + static_cast<std::size_t>(i2)];
                        x = std::min(x, size);
                    }
            }
        }
    }
}

} // namespace detail

} // namespace globemesh
