// PNG preview of a mesh: see globemesh/gpkg.hpp.
//
// Plate carree (lon/lat) picture drawn with GDAL's rasterizer into a MEM RGBA raster and written
// by the PNG driver: background, optional land polygons, faces coloured by quality or depth
// (cut at +-180, so nothing smears), and the edges as thin dark lines when the mean edge of the
// faces shown spans at least 4 pixels (min_outline_edge_px).
// An extent that crosses the antimeridian (W > E, or E > 180) is drawn continuously.
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <gdal_alg.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include "face_geometry.hpp"
#include "gdal_util.hpp"
#include "globemesh/error.hpp"
#include "globemesh/gpkg.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/preview.hpp"
#include "globemesh/ugrid.hpp"
#include "globemesh/writers.hpp"
#include "ordered_blocks.hpp"
#include "write_hooks.hpp"

namespace globemesh {

namespace {

using Rgba = std::array<double, 4>;

/// Interpolates a colour ramp of (position, colour) stops at t in [0, 1].
Rgba ramp(const std::vector<std::pair<double, Rgba>> &stops, double t) {
    t = std::clamp(t, 0.0, 1.0);
    for (std::size_t i = 1; i < stops.size(); ++i)
        if (t <= stops[i].first) {
            double u = (t - stops[i - 1].first) / (stops[i].first - stops[i - 1].first);
            Rgba c;
            for (int k = 0; k < 4; ++k)
                c[k] = std::round(stops[i - 1].second[k] +
                                  u * (stops[i].second[k] - stops[i - 1].second[k]));
            return c;
        }
    return stops.back().second;
}

/// Geometries to burn, each with its RGBA; owns them.
class BurnList {
public:
    ~BurnList() { clear(); }
    std::size_t size() const { return geoms_.size(); }
    void clear() {
        for (auto g : geoms_)
            OGRGeometryFactory::destroyGeometry(OGRGeometry::FromHandle(g));
        geoms_.clear();
        values_.clear();
    }
    void add(OGRGeometry *g, const Rgba &c) {
        geoms_.push_back(OGRGeometry::ToHandle(g));
        values_.insert(values_.end(), c.begin(), c.end());
    }
    /// Burns them into ds, reporting on [lo, hi] of `progress`.
    void burn(GDALDataset *ds, const char *all_touched, const std::filesystem::path &path,
              const Progress &progress = {}, double lo = 0, double hi = 1) {
        if (geoms_.empty())
            return;
        int bands[4] = {1, 2, 3, 4};
        char *opts[] = {const_cast<char *>(all_touched), nullptr};
        gdal::ProgressBridge bridge{&progress, lo, hi, "write_preview"};
        const CPLErr err =
            GDALRasterizeGeometries(GDALDataset::ToHandle(ds), 4, bands, int(geoms_.size()),
                                    geoms_.data(), nullptr, nullptr, values_.data(), opts,
                                    progress ? gdal::ProgressBridge::call : nullptr, &bridge);
        if (bridge.cancelled)
            throw Cancelled();
        if (err != CE_None)
            throw IoError("preview " + path.string() +
                          ": rasterizing failed: " + io::last_gdal_error());
    }

private:
    std::vector<OGRGeometryH> geoms_;
    std::vector<double> values_;
};

/// The copies of a part shifted by -360/0/+360 that meet the extent's longitudes [w, e].
std::vector<double> shifts_for(double lon_min, double lon_max, double w, double e) {
    std::vector<double> s;
    for (double shift : {-360.0, 0.0, 360.0})
        if (lon_max + shift >= w && lon_min + shift <= e)
            s.push_back(shift);
    return s;
}

/// Whether the box [x0, x1] x [y0, y1] (lon/lat) may hold the centre of a pixel of the raster
/// with geotransform gt (north up): false only when it certainly holds none, with a margin of
/// 1e-6 pixel for rounding. GDAL's rasterizer burns a polygon into the pixels whose centres it
/// holds (ALL_TOUCHED=FALSE), so a face whose box holds none burns nothing: at 1e6 nodes on a
/// 1600-pixel picture most faces are smaller than a pixel.
bool holds_a_centre(const double (&gt)[6], double x0, double x1, double y0, double y1) {
    constexpr double margin = 1e-6;
    auto any_integer = [](double from, double to) {
        return std::ceil(from - margin) <= std::floor(to + margin);
    };
    // Pixel column i has its centre at gt[0] + (i + 0.5) gt[1]; row j at gt[3] + (j + 0.5) gt[5].
    return any_integer((x0 - gt[0]) / gt[1] - 0.5, (x1 - gt[0]) / gt[1] - 0.5) &&
           any_integer((y1 - gt[3]) / gt[5] - 0.5, (y0 - gt[3]) / gt[5] - 0.5);
}

std::array<double, 4> default_extent(const Mesh &mesh) {
    std::vector<double> lons;
    double south = 90, north = -90;
    for (const auto &v : mesh.nodes) {
        LonLat p = vec_to_lonlat(v);
        if (!(v.x == 0 && v.y == 0))
            lons.push_back(p.lon);
        south = std::min(south, p.lat), north = std::max(north, p.lat);
    }
    if (lons.empty())
        return {-180, -90, 180, 90};
    std::sort(lons.begin(), lons.end());
    // The widest gap between node longitudes (circularly) is where the picture is cut.
    double gap = lons.front() + 360 - lons.back(), west = lons.front(), east = lons.back();
    for (std::size_t i = 1; i < lons.size(); ++i)
        if (lons[i] - lons[i - 1] > gap)
            gap = lons[i] - lons[i - 1], west = lons[i], east = lons[i - 1] + 360;
    if (gap < 30 || north - south > 150)
        return {-180, -90, 180, 90};
    double pad_x = 0.03 * (east - west), pad_y = 0.03 * (north - south);
    return {west - pad_x, std::max(-90.0, south - pad_y), east + pad_x,
            std::min(90.0, north + pad_y)};
}

/// Checks the options against the mesh; returns the extent W, S, E, N in degrees, with E > W.
std::array<double, 4> checked_extent(const Mesh &mesh, const std::filesystem::path &path,
                                     const PreviewOptions &options) {
    if (options.colour_by != "quality" && options.colour_by != "depth")
        throw UsageError("preview colour \"" + options.colour_by + "\": use quality or depth");
    if (options.width_px < 16 || options.width_px > 20000)
        throw UsageError("preview width " + std::to_string(options.width_px) +
                         ": use 16 to 20000 pixels");
    if (options.colour_by == "depth" && !mesh.node_field("depth"))
        throw DataError("preview " + path.string() + ": the mesh has no depth field to colour by");
    auto [w, s, e, n] = options.extent_deg ? *options.extent_deg : default_extent(mesh);
    if (e <= w)
        e += 360;
    if (!(n > s) || s < -90 || n > 90 || e - w > 360)
        throw UsageError(
            "preview extent: give W,S,E,N in degrees with S < N, both within [-90, 90]");
    return {w, s, e, n};
}

/// Burns the land polygons of options.land into the canvas (geotransform gt, longitudes w to e).
void draw_land(GDALDataset *canvas, double (&gt)[6], double w, double e,
               const PreviewOptions &options, const std::filesystem::path &path) {
    const double n = gt[3];
    io::GdalDatasetPtr land(
        GDALDataset::Open(options.land.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY));
    if (!land)
        throw IoError("preview land " + options.land + ": cannot open (" + io::last_gdal_error() +
                      ")");
    OGRSpatialReference wgs84;
    wgs84.importFromEPSG(4326);
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    const Rgba land_colour = {205, 195, 170, 255};
    std::vector<std::unique_ptr<OGRGeometry>> land_geoms;
    // The layer named "land" when there is one, else the first (a file may also hold "ocean").
    OGRLayer *layer = land->GetLayerByName("land");
    if (!layer)
        layer = land->GetLayer(0);
    if (!layer)
        throw DataError("preview land " + options.land + ": the file has no layer");
    {
        std::unique_ptr<OGRCoordinateTransformation> ct;
        if (const OGRSpatialReference *srs = layer->GetSpatialRef(); srs && !srs->IsSame(&wgs84)) {
            ct.reset(OGRCreateCoordinateTransformation(srs, &wgs84));
            if (!ct)
                throw DataError("preview land " + options.land + ": cannot transform layer " +
                                layer->GetName() + " to EPSG:4326");
        }
        for (auto &feature : *layer) {
            const OGRGeometry *g = feature->GetGeometryRef();
            if (!g || wkbFlatten(g->getGeometryType()) == wkbPoint)
                continue;
            std::unique_ptr<OGRGeometry> copy(g->clone());
            if (ct && copy->transform(ct.get()) != OGRERR_NONE)
                continue;
            land_geoms.push_back(std::move(copy));
        }
    }
    // Land copies one turn east or west are drawn by moving the picture's origin instead.
    for (double shift : shifts_for(-180, 180, w, e)) {
        BurnList burn;
        for (const auto &g : land_geoms)
            burn.add(g->clone(), land_colour);
        double shifted[6] = {w - shift, gt[1], 0, n, 0, gt[5]};
        canvas->SetGeoTransform(shifted);
        burn.burn(canvas, "ALL_TOUCHED=FALSE", path);
    }
    canvas->SetGeoTransform(gt);
}

/// The mean edge of a mesh is drawn as outlines when it spans at least this many pixels.
constexpr double min_outline_edge_px = 4.0;

/// The mean length in pixels (of geotransform gt, pixel width in longitude) of the edges of the
/// faces whose first corner lies in the picture [west, east] x [south, north]; 0 when none does.
/// Measured on the faces shown, so a zoom onto a region judges that region's faces.
double mean_edge_px(const Mesh &mesh, const double (&gt)[6], double west, double east,
                    double south) {
    const double north = gt[3];
    double sum_rad = 0;
    std::size_t edges = 0;
    for (const auto &t : mesh.faces) {
        const LonLat p = vec_to_lonlat(mesh.nodes[t[0]]);
        if (shifts_for(p.lon, p.lon, west, east).empty() || p.lat > north || p.lat < south)
            continue;
        for (int k = 0; k < 3; ++k)
            sum_rad += arc_angle(mesh.nodes[t[k]], mesh.nodes[t[(k + 1) % 3]]);
        edges += 3;
    }
    return edges == 0 ? 0.0 : sum_rad / double(edges) * rad_to_deg / gt[1];
}

/// The edges of one ring of a face (face_polygons) shifted by `shift` degrees, as lines, without
/// the sides that are no edge of the mesh: a pole corner's side along +-90 and, for a face cut
/// at +-180, its sides along the cut. Null when none is left.
std::unique_ptr<OGRGeometry> face_edges(const io::LonLatPart &ring, double shift, bool cut) {
    auto on_seam = [cut](const io::LonLatPoint &p, const io::LonLatPoint &q) {
        return (std::fabs(p[1]) == 90 && q[1] == p[1]) ||
               (cut && std::fabs(p[0]) == 180 && q[0] == p[0]);
    };
    auto lines = std::make_unique<OGRMultiLineString>();
    for (std::size_t i = 0; i < ring.size(); ++i) {
        const auto &p = ring[i], &q = ring[(i + 1) % ring.size()];
        if (on_seam(p, q))
            continue;
        auto line = std::make_unique<OGRLineString>();
        line->addPoint(p[0] + shift, p[1]);
        line->addPoint(q[0] + shift, q[1]);
        lines->addGeometryDirectly(line.release());
    }
    if (lines->IsEmpty())
        return nullptr;
    return lines;
}

/// Burns the faces into the canvas (geotransform gt, longitudes west to east), coloured by
/// quality (red poor .. green good) or depth (light to dark blue), with their outlines when
/// faces are large enough; reports the progress from 0.08 to 0.97.
void draw_faces(GDALDataset *canvas, const double (&gt)[6], double west, double east,
                const Mesh &mesh, const PreviewOptions &options,
                const std::filesystem::path &path) {
    const Field *depth = mesh.node_field("depth");
    double depth_max = 1;
    if (depth)
        for (double d : depth->values)
            if (std::isfinite(d))
                depth_max = std::max(depth_max, d);
    const std::vector<std::pair<double, Rgba>> quality_ramp = {{0.0, {165, 0, 38, 255}},
                                                               {0.4, {244, 109, 67, 255}},
                                                               {0.6, {254, 224, 139, 255}},
                                                               {0.8, {166, 217, 106, 255}},
                                                               {1.0, {0, 104, 55, 255}}};
    const std::vector<std::pair<double, Rgba>> depth_ramp = {
        {0.0, {222, 235, 247, 255}}, {0.5, {66, 146, 198, 255}}, {1.0, {8, 48, 107, 255}}};
    BurnList faces, outlines;
    const double south = gt[3] + gt[5] * canvas->GetRasterYSize();
    const bool draw_outlines = mean_edge_px(mesh, gt, west, east, south) >= min_outline_edge_px;
    const Rgba outline = {40, 40, 40, 255};
    // The faces' polygons are made a block at a time on every core and added in order on this
    // thread (ordered_blocks.hpp): the same lists, so the same picture.
    struct Shapes {
        std::vector<std::unique_ptr<OGRGeometry>> faces, outlines;
        std::vector<Rgba> colours;
    };
    constexpr std::size_t block_faces = 16384, burn_batch = 262144;
    io::compute_in_order<Shapes, char>(
        (mesh.faces.size() + block_faces - 1) / block_faces,
        [&](std::size_t k, Shapes &shapes, char &) {
            shapes.faces.clear(), shapes.outlines.clear(), shapes.colours.clear();
            const std::size_t first = k * block_faces,
                              last = std::min(mesh.faces.size(), first + block_faces);
            for (std::size_t f = first; f < last; ++f) {
                const auto &t = mesh.faces[f];
                const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]];
                const Rgba colour =
                    options.colour_by == "depth"
                        ? ramp(depth_ramp,
                               (depth->values[t[0]] + depth->values[t[1]] + depth->values[t[2]]) /
                                   3.0 / depth_max)
                        : ramp(quality_ramp, triangle_quality(a, b, c));
                const auto rings = io::face_polygons(a, b, c);
                const bool cut = rings.size() > 1; // parts of a face across +-180
                for (const auto &ring : rings) {
                    double lo = 1e9, hi = -1e9, south = 90, north = -90;
                    for (const auto &p : ring) {
                        lo = std::min(lo, p[0]), hi = std::max(hi, p[0]);
                        south = std::min(south, p[1]), north = std::max(north, p[1]);
                    }
                    for (double shift : shifts_for(lo, hi, west, east)) {
                        if (!draw_outlines &&
                            !holds_a_centre(gt, lo + shift, hi + shift, south, north))
                            continue;
                        auto r = std::make_unique<OGRLinearRing>();
                        for (const auto &p : ring)
                            r->addPoint(p[0] + shift, p[1]);
                        r->closeRings();
                        if (draw_outlines)
                            if (auto lines = face_edges(ring, shift, cut); lines)
                                shapes.outlines.push_back(std::move(lines));
                        auto poly = std::make_unique<OGRPolygon>();
                        poly->addRingDirectly(r.release());
                        shapes.faces.push_back(std::move(poly));
                        shapes.colours.push_back(colour);
                    }
                }
            }
        },
        [&](std::size_t k, Shapes &shapes) {
            report(options.progress,
                   0.08 + 0.86 * double(k * block_faces) / double(mesh.faces.size()),
                   "write_preview");
            for (std::size_t i = 0; i < shapes.faces.size(); ++i)
                faces.add(shapes.faces[i].release(), shapes.colours[i]);
            for (auto &g : shapes.outlines)
                outlines.add(g.release(), outline);
            // Burnt as they come, in order (a later face still covers an earlier one's pixels):
            // all of them held at once made the picture the run's peak (at 20 km, 721 MiB).
            if (faces.size() >= burn_batch) {
                faces.burn(canvas, "ALL_TOUCHED=FALSE", path);
                faces.clear();
            }
        });
    faces.burn(canvas, "ALL_TOUCHED=FALSE", path);
    outlines.burn(canvas, "ALL_TOUCHED=FALSE", path, options.progress, 0.94, 0.97);
}

/// Writes the canvas as a PNG to `temp` (the output's temporary file).
void write_png(GDALDriver *png, GDALDataset *canvas, const std::filesystem::path &temp,
               const std::filesystem::path &path) {
    // Written without georeferencing sidecars (no .aux.xml, no world file): a picture only.
    double identity[6] = {0, 1, 0, 0, 0, 1};
    canvas->SetGeoTransform(identity);
    io::ScopedGdalConfig no_pam("GDAL_PAM_ENABLED", "NO");
    io::GdalDatasetPtr written(
        png->CreateCopy(temp.c_str(), canvas, FALSE, nullptr, nullptr, nullptr));
    if (!written)
        throw IoError("preview " + path.string() + ": writing the PNG failed: " +
                      io::last_gdal_error() + OutputFile::full_disk_note(path));
    if (!io::close_dataset(written))
        throw IoError("preview " + path.string() + ": closing the PNG failed: " +
                      io::last_gdal_error() + OutputFile::full_disk_note(path));
}

} // namespace

void write_preview_png(const Mesh &mesh, const std::filesystem::path &path,
                       const PreviewOptions &options) {
    const auto [w, s, e, n] = checked_extent(mesh, path, options);
    OutputFile out(path, options.overwrite, "preview");

    GDALAllRegister();
    io::QuietGdalErrors quiet;
    const int width = options.width_px;
    const int height = std::max(16, int(std::lround(width * (n - s) / (e - w))));
    GDALDriver *mem = GetGDALDriverManager()->GetDriverByName("MEM");
    GDALDriver *png = GetGDALDriverManager()->GetDriverByName("PNG");
    if (!mem || !png)
        throw IoError("preview " + path.string() + ": GDAL lacks the MEM or PNG driver");
    io::GdalDatasetPtr canvas(mem->Create("", width, height, 4, GDT_Byte, nullptr));
    if (!canvas)
        throw IoError("preview " + path.string() +
                      ": cannot allocate the picture: " + io::last_gdal_error());
    double gt[6] = {w, (e - w) / width, 0, n, 0, -(n - s) / height};
    canvas->SetGeoTransform(gt);
    const Rgba background = {236, 242, 248, 255};
    for (int b = 1; b <= 4; ++b)
        canvas->GetRasterBand(b)->Fill(background[b - 1]);

    if (!options.land.empty())
        draw_land(canvas.get(), gt, w, e, options, path);
    // Shares of the progress, as measured at 20 km (2.1e6 faces, 2.6 s): the land 8%, the faces'
    // polygons and their burning 86%, the outlines and the PNG the rest.
    report(options.progress, 0.08, "write_preview");
    draw_faces(canvas.get(), gt, w, e, mesh, options, path);
    if (detail::after_partial_write)
        detail::after_partial_write(); // tests only (write_hooks.hpp)
    write_png(png, canvas.get(), out.temp_path(), path);
    report(options.progress, 1.0, "write_preview");
    out.commit();
}

/// The PNG row of the writers table (writers.cpp): coloured by depth when the mesh has it.
void write_as_png(const Mesh &mesh, const std::filesystem::path &path,
                  const WriteOptions &options) {
    PreviewOptions preview;
    preview.land = options.land;
    preview.colour_by = mesh.node_field("depth") ? "depth" : "quality";
    preview.extent_deg = options.extent_deg;
    preview.overwrite = options.overwrite;
    preview.progress = options.progress;
    write_preview_png(mesh, path, preview);
}

} // namespace globemesh
