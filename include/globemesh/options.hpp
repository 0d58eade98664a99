// globemesh/options.hpp: every user choice of a meshing run, with its default.
//
// MeshOptions is a plain aggregate (GDAL's GDALTranslateOptions, JIGSAW's jigsaw_jig_t): the CLI
// binds its flags straight to these fields and config files use the same names, so this struct
// is the single source of defaults. Lengths are in km, areas in km2, angles in degrees.
// validate() checks the values alone (no file is opened) and throws UsageError naming the option.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace globemesh {

struct MeshOptions {
    // --- coastline (coast/) ---
    std::string coast;       ///< --coast: any OGR vector source of land polygons or coast lines
    std::string coast_layer; ///< --coast-layer: layer name; default the only polygon/line layer
    std::string coast_where; ///< --coast-where: OGR SQL attribute filter; default none
    std::string coast_srs;   ///< --coast-srs: CRS of a layer that declares none (e.g. EPSG:4326)
    /// --region W,S,E,N in degrees; W > E crosses +-180. Default: the whole globe.
    std::optional<std::array<double, 4>> region;
    std::string region_file; ///< --region-file: polygons (any OGR source, any CRS) bounding the ocean
    std::string region_layer; ///< --region-layer: layer of --region-file; default the only polygon/line layer
    double min_island_area_km2 = 0; ///< --min-island-area: drop islands and lakes smaller (km2)
    /// Islands whose area is below this many equilateral triangles of the local size are dropped.
    double min_island_triangles = 4;
    bool keep_inland_seas = false; ///< --keep-inland-seas: keep water bodies not connected to the ocean
    /// --keep-straits: keep open the straits narrower than a triangle, with their triangles
    /// centred on land, instead of closing them (MesherOptions::close_straits)
    bool keep_straits = false;

    // --- bathymetry (bathymetry/) ---
    std::string bathy;             ///< --bathy: any GDAL raster of elevation (or depth)
    int bathy_band = 1;            ///< --bathy-band: 1-based band number
    bool depth_positive = false;   ///< --depth-positive: the raster stores depth positive down
    std::optional<double> bathy_fill_m; ///< --bathy-fill: depth (m) where the raster has no data
    /// --min-depth: depth (m, positive down) that every node shallower than it is raised to
    /// after sampling (depth := max(depth, min_depth)); nullopt keeps the sampled depths.
    std::optional<double> min_depth_m;
    std::string bathy_srs;         ///< --bathy-srs: CRS of the raster, replacing the file's (e.g. EPSG:4326)

    // --- size field (sizefield/), km ---
    double hmax_km = 100.0;     ///< --hmax: largest edge length (km); alone gives a uniform mesh
    double hmin_km = 0.0;       ///< --hmin: smallest edge length (km); 0: a floor of max(hmax/1000, 10 m)
    double coast_size_km = 0.0; ///< --coast-size: edge length at the coast (km); 0 = off
    double coast_rate = 0.1;    ///< --coast-rate: growth of h with distance from the coast (km/km)
    double wavelength = 0.0;    ///< --wavelength: points per wavelength of the tide; 0 = off
    double wave_period_h = 12.42; ///< --wave-period: period of that wave (hours; M2 by default)
    double slope = 0.0;         ///< --slope: points per topographic length scale; 0 = off
    std::string size_regions;   ///< --size-regions: polygons with a "size_km" attribute
    /// --size-regions-layer: the layer of --size-regions to read; default every layer with a
    /// size_km field
    std::string size_regions_layer;
    double grade = 0.15;        ///< --grade: largest |grad h| (km/km)

    // --- mesher (mesher/) ---
    std::uint64_t max_nodes = 20'000'000; ///< --max-nodes: refuse runs estimated larger
    /// --max-memory: refuse runs whose estimated peak memory exceeds this many bytes; 0 = no
    /// limit (the library's default; the CLI's default is 3/4 of the physical memory). The
    /// budget never changes a result: a run fits (the same mesh as without it) or is refused.
    std::uint64_t max_memory_bytes = 0;
    int smooth_iterations = 4;            ///< --smooth: smoothing/relaxation sweeps
    /// --inlet-width: close inlets and lagoons whose mouth is narrower than this times the local
    /// size and whose water is under the local size squared; 0 keeps every inlet.
    double inlet_width = 0.5;
    std::uint64_t seed = 1;               ///< --seed: seed of every pseudo-random choice
};

/// The size field's floor hfloor (sizefield.hpp) for `options`: --hmin, or when it is 0 the sane
/// floor max(hmax / 1000, 10 m).
inline double size_floor_km(const MeshOptions& options) {
    return options.hmin_km > 0 ? options.hmin_km : std::max(options.hmax_km / 1000, 0.01);
}

/// Checks option values alone (ranges, hmin <= hmax, region bounds); throws UsageError naming
/// the option. Opens no file.
void validate(const MeshOptions& options);

/// Bytes with an SI unit, as --max-memory takes them: memory_text(1.2e9) == "1.2 GB".
std::string memory_text(double bytes);

} // namespace globemesh
