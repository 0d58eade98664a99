#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "globemesh/error.hpp"
#include "globemesh/options.hpp"
#include "globemesh/parts.hpp"

namespace globemesh {

namespace {

void require(bool ok, const ErrorText &message) {
    if (!ok)
        throw UsageError(message);
}

bool positive(double v) {
    return std::isfinite(v) && v > 0;
}

/// The largest --hmax: 45 degrees of arc. Coarser, the shaping drops the continents as islands
/// (1:50m land: one ring kept at 5000 and 6000 km, 33 and 19 nodes; none from 7000 km), and from
/// 8000 km the mesh is the seed octahedron (90-degree edges, 6 nodes), whose antipodal nodes
/// leave mesh-verify's boundary crossing test to rounding (it then reports crossings).
constexpr double max_hmax_km = 5000;

/// A length as the options take it back: "2.5km".
std::string km(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%gkm", v);
    return buf;
}

/// Below this no run fits: the smallest meshes and GDAL's own buffers take more.
constexpr std::uint64_t min_memory_budget_bytes = 1'000'000;

} // namespace

namespace {

void validate_size(const SizeFieldOptions &o) {
    const ErrorText hmax = option("hmax_km"), hmin = option("hmin_km");
    require(positive(o.hmax_km), hmax + " must be a positive length, e.g. 100km");
    require(o.hmax_km <= max_hmax_km, hmax + " must be at most " +
                                          std::to_string(int(max_hmax_km)) +
                                          "km (an eighth of the Earth's circumference)");
    require(std::isfinite(o.hmin_km) && o.hmin_km >= 0,
            hmin + " must be a positive length, e.g. 10km");
    require(o.hmin_km <= o.hmax_km, hmin + " (" + km(o.hmin_km) + ") must not be larger than " +
                                        hmax + " (" + km(o.hmax_km) + ")");
    require(std::isfinite(o.coast_size_km) && o.coast_size_km >= 0,
            option("coast_size_km") + " must be a positive length, e.g. 20km");
    require(std::isfinite(o.coast_rate) && o.coast_rate >= 0,
            option("coast_rate") + " must be >= 0");
    require(std::isfinite(o.wavelength) && o.wavelength >= 0,
            option("wavelength") + " must be >= 0 (points per wavelength)");
    require(positive(o.wave_period_h),
            option("wave_period_h") + " must be a positive number of hours");
    require(std::isfinite(o.slope) && o.slope >= 0,
            option("slope") + " must be >= 0 (points per length scale)");
    require(std::isfinite(o.feature_size) && o.feature_size >= 0,
            option("feature_size") + " must be >= 0 (elements across a channel)");
    require(positive(o.grade) && o.grade < 10, option("grade") + " must be in (0, 10)");
    // A layer without its file would be ignored without a word.
    require(o.size_regions_layer.empty() || !o.size_regions.empty(),
            option("size_regions_layer") + " names a layer of " + option("size_regions") +
                ", which is not given");
    require(o.passage_cells >= 1 && o.passage_cells <= 100,
            option("passage_cells") + " must be in 1..100 (edges across each passage)");
    require(o.passages_layer.empty() || !o.passages.empty(),
            option("passages_layer") + " names a layer of " + option("passages") +
                ", which is not given");
}

void validate_meshing(const MeshingOptions &o) {
    require(o.max_nodes >= 3, option("max_nodes") + " must be at least 3");
    require(o.max_memory_bytes == 0 || o.max_memory_bytes >= min_memory_budget_bytes,
            option("max_memory_bytes") + " must be 0 (no limit) or at least 1MB, e.g. 4GB");
    require(o.smooth_iterations >= 0 && o.smooth_iterations <= 1000,
            option("smooth_iterations") + " must be in 0..1000");
    require(o.parts >= 0 && o.parts <= max_parts,
            option("parts") + " must be in 0.." + std::to_string(max_parts) +
                " (lunes meeting at the poles at 360 / N degrees; 0 chooses from the mesh size)");
    require(std::isnan(o.parts_border_lon) ||
                (o.parts_border_lon >= -180 && o.parts_border_lon <= 180),
            option("parts_border_lon") + " must be a longitude in -180..180 degrees");
    require(o.threads >= 0 && o.threads <= 1024,
            option("threads") + " must be in 0..1024 (0: one per core)");
    require(std::isfinite(o.inlet_width) && o.inlet_width >= 0 && o.inlet_width <= 2,
            option("inlet_width") +
                " must be in 0..2 (a fraction of the local edge length; 0 keeps every inlet)");
}

void validate_coast(const CoastOptions &o) {
    require(std::isfinite(o.min_island_area_km2) && o.min_island_area_km2 >= 0,
            option("min_island_area_km2") + " must be a positive area, e.g. 100km2");
    require(o.close_node_gap >= 0 && o.close_node_gap <= 0.25,
            "close_node_gap must be a fraction of the local size in [0, 0.25]");
    const ErrorText region = option("region"), region_file = option("region_file");
    if (o.region) {
        const auto &r = *o.region;
        for (double v : r)
            require(std::isfinite(v), region + " values must be numbers: W,S,E,N in degrees");
        require(r[0] >= -180 && r[0] <= 180 && r[2] >= -180 && r[2] <= 180,
                region + " longitudes must be in [-180, 180]");
        require(r[1] >= -90 && r[3] <= 90 && r[1] < r[3],
                region + " needs -90 <= S < N <= 90 (W,S,E,N in degrees)");
        require(r[0] != r[2], region + " W and E must differ (W > E crosses +-180)");
    }
    require(!(o.region && !o.region_file.empty()),
            region + " and " + region_file + " cannot be used together");
    // A layer without its file would be ignored without a word.
    require(o.region_layer.empty() || !o.region_file.empty(),
            option("region_layer") + " names a layer of " + region_file + ", which is not given");
}

/// Refuses the raster's options without the raster (bathy): they would be ignored without a word.
/// The band only when not the default 1, which --print-config writes for every run.
void require_bathy_for_its_options(const BathymetryOptions &o) {
    if (!o.bathy.empty())
        return;
    const ErrorText needs = " needs " + option("bathy");
    require(!o.min_depth_m, option("min_depth_m") + needs + ": it raises the sampled depths");
    require(!o.bathy_fill_m,
            option("bathy_fill_m") + needs + ": it is the depth where the raster has no data");
    require(!o.depth_positive,
            option("depth_positive") + needs + ": it says the raster stores depth");
    require(o.bathy_srs.empty(), option("bathy_srs") + needs + ": it is the raster's CRS");
    require(o.bathy_band == 1, option("bathy_band") + " " + std::to_string(o.bathy_band) + needs +
                                   ": it picks a band of the raster");
}

void validate_bathymetry(const BathymetryOptions &o) {
    require(o.bathy_band >= 1, option("bathy_band") + " must be 1 or more");
    if (o.min_depth_m)
        require(std::isfinite(*o.min_depth_m),
                option("min_depth_m") + " must be a depth in metres, e.g. 5m");
    require_bathy_for_its_options(o);
}

} // namespace

void validate(const CoastOptions &o) {
    validate_coast(o);
}

void validate(const BathymetryOptions &o) {
    validate_bathymetry(o);
}

void validate(const SizeFieldOptions &o) {
    validate_size(o);
}

void validate(const MeshingOptions &o) {
    validate_meshing(o);
}

void validate(const MeshOptions &o) {
    validate_size(o);
    validate_coast(o);
    validate_bathymetry(o);
    validate_meshing(o);
}

std::string memory_text(double bytes) {
    const char *units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
    int u = 0;
    while (bytes >= 1000 && u < 5)
        bytes /= 1000, ++u;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g %s", bytes, units[u]);
    return buf;
}

} // namespace globemesh
