#include "option_flags.hpp"

#include <array>
#include <utility>

namespace globemesh::cli {

namespace {

/// Every MeshOptions field that a flag of `globemesh mesh` sets (mesh_command.cpp's MeshCommand).
constexpr std::array<std::pair<std::string_view, std::string_view>, 39> flags{{
    {"coast", "--coast"},
    {"coast_layer", "--coast-layer"},
    {"coast_where", "--coast-where"},
    {"coast_srs", "--coast-srs"},
    {"region", "--region"},
    {"region_file", "--region-file"},
    {"region_layer", "--region-layer"},
    {"min_island_area_km2", "--min-island-area"},
    // No flag sets it (the default, 4, always applies); the coast's message has named it so.
    {"min_island_triangles", "--min-island-triangles"},
    {"keep_inland_seas", "--keep-inland-seas"},
    {"keep_straits", "--keep-straits"},
    {"bathy", "--bathy"},
    {"bathy_band", "--bathy-band"},
    {"bathy_srs", "--bathy-srs"},
    {"depth_positive", "--depth-positive"},
    {"bathy_fill_m", "--bathy-fill"},
    {"min_depth_m", "--min-depth"},
    {"hmax_km", "--hmax"},
    {"hmin_km", "--hmin"},
    {"coast_size_km", "--coast-size"},
    {"coast_rate", "--coast-rate"},
    {"wavelength", "--wavelength"},
    {"wave_period_h", "--wave-period"},
    {"slope", "--slope"},
    {"feature_size", "--feature-size"},
    {"size_regions", "--size-regions"},
    {"size_regions_layer", "--size-regions-layer"},
    {"passages", "--passages"},
    {"passages_layer", "--passages-layer"},
    {"passage_cells", "--passage-cells"},
    {"grade", "--grade"},
    {"max_nodes", "--max-nodes"},
    {"max_memory_bytes", "--max-memory"},
    {"inlet_width", "--inlet-width"},
    {"smooth_iterations", "--smooth"},
    {"seed", "--seed"},
    {"parts", "--parts"},
    {"parts_border_lon", "--parts-border"},
    {"threads", "--threads"},
}};

} // namespace

std::string flag_of(std::string_view field) {
    for (const auto &[f, flag] : flags)
        if (f == field)
            return std::string(flag);
    return std::string(field);
}

} // namespace globemesh::cli
