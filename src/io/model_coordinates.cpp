// The model formats' node coordinates: see model_coordinates.hpp.
#include "model_coordinates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "gdal_handles.hpp"
#include "globemesh/error.hpp"
#include "globemesh/sphere.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"

namespace globemesh::io {

namespace {

using gdal::SrsPtr;
using gdal::TransformPtr;

SrsPtr wgs84_lonlat() {
    SrsPtr wgs84(OSRNewSpatialReference(nullptr));
    OSRImportFromEPSG(wgs84.get(), 4326);
    OSRSetAxisMappingStrategy(wgs84.get(), OAMS_TRADITIONAL_GIS_ORDER);
    return wgs84;
}

std::string lonlat_text(const LonLat &p) {
    char text[64];
    std::snprintf(text, sizeof text, "lon %.6f, lat %.6f", p.lon, p.lat);
    return text;
}

/// Refuses a mesh with a face that turns over (or flattens) in the plane.
void check_faces_keep_their_turn(const Mesh &mesh, const ModelCoordinates &c,
                                 const std::string &what) {
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &face = mesh.faces[f];
        const double ax = c.x[face[1]] - c.x[face[0]], ay = c.y[face[1]] - c.y[face[0]];
        const double bx = c.x[face[2]] - c.x[face[0]], by = c.y[face[2]] - c.y[face[0]];
        if (ax * by - ay * bx > 0)
            continue;
        throw DataError(what + ": --output-srs " + c.crs->name + " cannot hold this mesh: face " +
                        std::to_string(f + 1) + " near " +
                        lonlat_text(vec_to_lonlat(mesh.nodes[face[0]])) +
                        " turns over in it (the mesh crosses where the projection tears or folds, "
                        "as a global mesh does); choose a projection that holds the whole mesh, "
                        "or write lon/lat (no --output-srs)");
    }
}

} // namespace

OutputCrs parse_output_crs(const std::string &text, const std::string &option) {
    gdal::QuietErrors quiet;
    SrsPtr srs(OSRNewSpatialReference(nullptr));
    if (text.empty() || OSRSetFromUserInput(srs.get(), text.c_str()) != OGRERR_NONE)
        throw UsageError(option + " " + text +
                         ": not a CRS GDAL/PROJ reads; give e.g. EPSG:32631, a PROJ string or WKT");
    OutputCrs crs;
    const char *name = OSRGetName(srs.get());
    crs.name = name && *name && std::string(name) != "unknown" ? name : text;
    crs.projected = OSRIsProjected(srs.get()) != 0;
    if (!crs.projected) {
        const SrsPtr wgs84 = wgs84_lonlat();
        if (OSRIsGeographic(srs.get()) == 0)
            throw UsageError(option + " " + text + " (" + crs.name +
                             ") is not a projected CRS: the model formats take planar "
                             "coordinates, e.g. EPSG:32631 (UTM 31N)");
        if (OSRIsSameGeogCS(srs.get(), wgs84.get()) == 0)
            throw UsageError(option + " " + text + " (" + crs.name +
                             ") is geographic on another datum than WGS 84: the mesh is in "
                             "WGS 84 lon/lat, which the formats write without --output-srs; "
                             "give a projected CRS for planar coordinates");
    }
    OSRAutoIdentifyEPSG(srs.get());
    const char *authority = OSRGetAuthorityName(srs.get(), nullptr);
    const char *code = OSRGetAuthorityCode(srs.get(), nullptr);
    if (authority && code && std::string(authority) == "EPSG")
        crs.epsg = std::atoi(code);
    char *wkt = nullptr;
    OSRExportToWkt(srs.get(), &wkt);
    crs.wkt = wkt ? wkt : "";
    CPLFree(wkt);
    return crs;
}

ModelCoordinates model_coordinates(const Mesh &mesh, const std::string &output_srs,
                                   const std::string &what) {
    ModelCoordinates c;
    if (!output_srs.empty())
        c.crs = parse_output_crs(output_srs, "--output-srs");
    const std::vector<LonLat> p = node_lonlats(mesh);
    c.x.resize(p.size());
    c.y.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        c.x[i] = p[i].lon, c.y[i] = p[i].lat;
    if (!c.crs || !c.crs->projected)
        return c;
    gdal::QuietErrors quiet;
    const SrsPtr wgs84 = wgs84_lonlat();
    SrsPtr target(OSRNewSpatialReference(nullptr));
    OSRSetFromUserInput(target.get(), output_srs.c_str());
    OSRSetAxisMappingStrategy(target.get(), OAMS_TRADITIONAL_GIS_ORDER);
    TransformPtr transform(OCTNewCoordinateTransformation(wgs84.get(), target.get()));
    if (!transform)
        throw DataError(what + ": no transformation from WGS 84 lon/lat to --output-srs " +
                        c.crs->name + " (" + gdal::last_error() + ")");
    std::vector<int> ok(p.size(), 0);
    OCTTransformEx(transform.get(), int(p.size()), c.x.data(), c.y.data(), nullptr, ok.data());
    for (std::size_t i = 0; i < p.size(); ++i)
        if (!ok[i] || !std::isfinite(c.x[i]) || !std::isfinite(c.y[i]))
            throw DataError(what + ": node " + std::to_string(i + 1) + " at " + lonlat_text(p[i]) +
                            " has no coordinates in --output-srs " + c.crs->name +
                            " (outside the projection's domain: the mesh is too "
                            "large for it, or global)");
    check_faces_keep_their_turn(mesh, c, what);
    return c;
}

void require_depths(const Field &depth, const std::string &what) {
    const auto missing = std::count_if(depth.values.begin(), depth.values.end(),
                                       [](double d) { return !std::isfinite(d); });
    if (missing > 0)
        throw DataError(what + ": " + std::to_string(missing) +
                        " nodes have no depth, and the model needs one at every node: mesh with a "
                        "bathymetry that covers them, or with " +
                        option("bathy_fill_m") + " DEPTH");
}

} // namespace globemesh::io

namespace globemesh {

void check_output_srs(const std::string &srs, std::span<const OutputRequest> outputs,
                      const std::string &option) {
    if (srs.empty())
        return;
    io::parse_output_crs(srs, option);
    bool taken = false;
    for (const auto &o : outputs) {
        if (!takes_output_srs(o))
            continue;
        taken = true;
        if (creation_option(o.creation_options, "COORDS") == "SPHERE")
            throw UsageError(option + " " + srs + " and " + o.path.string() +
                             " COORDS=SPHERE ask for two kinds of coordinates: choose one");
    }
    if (taken)
        return;
    std::string takers;
    for (const Writer &w : writers())
        if (w.takes_output_srs)
            takers += (takers.empty() ? "" : ", ") + w.long_name;
    throw UsageError(option + " " + srs + " applies to none of the outputs: it sets the node " +
                     "coordinates of " + takers + " (not .ll); the other formats hold lon/lat");
}

} // namespace globemesh
