// globemesh/options.hpp: every user choice of a meshing run, with its default.
//
// Each module has its options (CoastOptions, BathymetryOptions, SizeFieldOptions,
// MeshingOptions); MeshOptions is all of them, a plain aggregate (GDAL's GDALTranslateOptions,
// JIGSAW's jigsaw_jig_t) and the single source of defaults: the CLI binds its flags to these
// fields. Units are in the names: lengths km, areas km2, depths m, periods h, angles degrees.
// validate() checks the values alone (no file is opened) and throws UsageError naming the field.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace globemesh {

/// The coastline's options (coast.hpp: load_coast, shape_boundary).
struct CoastOptions {
    std::string coast;       ///< any OGR vector source of land polygons or coast lines (required)
    std::string coast_layer; ///< layer name; default the only polygon/line layer
    std::string coast_where; ///< OGR SQL attribute filter; default none
    std::string coast_srs;   ///< CRS of a layer that declares none (e.g. EPSG:4326)
    /// W,S,E,N in degrees; W > E crosses +-180. Default: the whole globe.
    std::optional<std::array<double, 4>> region;
    std::string region_file;        ///< polygons (any OGR source, any CRS) bounding the ocean
    std::string region_layer;       ///< layer of region_file; default the only polygon/line layer
    double min_island_area_km2 = 0; ///< drop islands and lakes smaller than this (km2)
    /// Islands whose area is below this many equilateral triangles of the local size are dropped.
    double min_island_triangles = 4;
    /// Coast nodes closer together than this times the local size are merged where no arc then
    /// touches or crosses another (the topology repair makes nodes of the source's vertices,
    /// metres apart in a canal narrower than the size), and again once the inlets have closed
    /// (MesherOptions::close_node_gap: a closed mouth's ends). 0 keeps every node; no flag sets
    /// it.
    double close_node_gap = 1.0 / 32;
    bool keep_inland_seas = false; ///< keep water bodies not connected to the ocean
    /// Keep open the straits narrower than a triangle, with their triangles centred on land,
    /// instead of closing them (MesherOptions::close_straits).
    bool keep_straits = false;
};

/// The bathymetry's options (bathymetry.hpp: read_bathymetry), and the depth floor applied to
/// the depths sampled at the mesh's nodes.
struct BathymetryOptions {
    std::string bathy;                  ///< any GDAL raster of elevation (or depth); default none
    int bathy_band = 1;                 ///< 1-based band number
    bool depth_positive = false;        ///< the raster stores depth positive down
    std::optional<double> bathy_fill_m; ///< depth (m) where the raster has no data
    /// Depth (m, positive down) that every node shallower than it is raised to after sampling
    /// (depth := max(depth, min_depth_m)); nullopt keeps the sampled depths.
    std::optional<double> min_depth_m;
    std::string bathy_srs; ///< CRS of the raster, replacing the file's (e.g. EPSG:4326)
};

/// The size field's options (sizefield.hpp: build_size_field), lengths in km.
struct SizeFieldOptions {
    double hmax_km = 100.0; ///< largest edge length (km, at most 5000); alone gives a uniform mesh
    double hmin_km = 0.0;   ///< smallest edge length (km); 0: a floor of max(hmax/1000, 10 m)
    double coast_size_km = 0.0;   ///< edge length at the coast (km); 0 = off
    double coast_rate = 0.1;      ///< growth of h with distance from the coast (km/km)
    double wavelength = 0.0;      ///< points per wavelength of the tide; 0 = off
    double wave_period_h = 12.42; ///< period of that wave (hours; M2 by default)
    double slope = 0.0;           ///< points per topographic length scale; 0 = off
    double feature_size = 0.0;    ///< elements across every channel (h <= 2 lfs / n); 0 = off
    std::string size_regions;     ///< polygons with a "size_km" attribute: the edge length inside
    /// The layer of size_regions to read; default every layer with a size_km field.
    std::string size_regions_layer;
    /// Lines drawn across straits from land to land (any OGR source, passages.hpp): the field is
    /// width / passage_cells along each (below hmin_km if need be) and no strait is closed there.
    std::string passages;
    std::string passages_layer; ///< the layer of passages to read; default every layer
    int passage_cells = 2;      ///< edges across each passage's water, 1..100
    double grade = 0.15;        ///< largest |grad h| (km/km), in (0, 10)
};

/// The mesher's options as a user sets them (the pipeline turns them into mesher.hpp's
/// MesherOptions, with what it measured of the inputs).
struct MeshingOptions {
    std::uint64_t max_nodes = 20'000'000; ///< refuse runs estimated larger
    /// Refuse runs whose estimated peak memory exceeds this many bytes; 0 = no limit. The
    /// budget never changes a result: a run fits (the same mesh as without it) or is refused.
    std::uint64_t max_memory_bytes = 0;
    int smooth_iterations = 4; ///< smoothing/relaxation sweeps, 0..1000
    /// Close inlets and lagoons whose mouth is narrower than this times the local size and whose
    /// water is under the local size squared, 0..2; 0 keeps every inlet.
    double inlet_width = 0.5;
    /// Close by the inlet rule the channels the strait closings leave as dead ends, and the water
    /// behind any chord shorter than inlet_width h / 2 (MesherOptions::close_dead_ends); no flag
    /// sets it.
    bool close_dead_ends = true;
    std::uint64_t seed = 1; ///< seed of every pseudo-random choice
    /// Parts meshed apart and joined (docs/parallel.md), 1..6: the mesh depends on it; 0, the
    /// default, chooses from the node estimate (parts_for_nodes: 1 below 2e6 nodes, else 2), 1
    /// for a region: never from the core count.
    int parts = 0;
    /// The longitude (degrees, -180..180) of the parts' first border; NaN, the default: chosen
    /// from the inputs, balancing the parts' work and keeping the borders off the coasts.
    double parts_border_lon = std::numeric_limits<double>::quiet_NaN();
    /// Threads meshing the parts at once, 0: one per core; the mesh never depends on it.
    int threads = 0;
};

/// Every choice of a meshing run: the four modules' options together. Each field keeps its
/// module's name (o.hmax_km); a module's function takes its own part (a MeshOptions converts)
/// and, as separate parameters, the few values it needs of another module's (load_coast the
/// memory budget, read_bathymetry a BathymetryContext, build_size_field the region); each
/// module's header also keeps a MeshOptions overload that passes them from the whole.
/// The command line's flags and config keys are the fields' names in its words (--hmax).
struct MeshOptions : CoastOptions, BathymetryOptions, SizeFieldOptions, MeshingOptions {};

/// Each module's part of a run's options.
inline const CoastOptions &coast_options(const MeshOptions &o) {
    return o;
}
inline const BathymetryOptions &bathymetry_options(const MeshOptions &o) {
    return o;
}
inline const SizeFieldOptions &size_field_options(const MeshOptions &o) {
    return o;
}
inline const MeshingOptions &meshing_options(const MeshOptions &o) {
    return o;
}

/// The size field's floor hfloor (sizefield.hpp) for `options`: hmin_km, or when it is 0 the
/// sane floor max(hmax_km / 1000, 10 m).
inline double size_floor_km(const SizeFieldOptions &options) {
    return options.hmin_km > 0 ? options.hmin_km : std::max(options.hmax_km / 1000, 0.01);
}

/// Checks option values alone (ranges, hmin_km <= hmax_km, region bounds, an option that needs
/// another); throws UsageError naming the option's field (e.g. "hmax_km must be a positive
/// length"). Opens no file. The one place the options are checked: mesh_ocean calls it first.
void validate(const MeshOptions &options);

/// validate for one module's options alone (a module's entry point checks its own part).
void validate(const CoastOptions &options);
void validate(const BathymetryOptions &options);
void validate(const SizeFieldOptions &options);
void validate(const MeshingOptions &options);

/// Bytes with an SI unit, as --max-memory takes them: memory_text(1.2e9) == "1.2 GB".
std::string memory_text(double bytes);

} // namespace globemesh
