// globemesh/preview.hpp: a PNG picture of a mesh (GDAL's rasterizer and PNG driver).
//
// write_preview_png draws the faces coloured by quality or depth, over the land polygons when
// given, on a lon/lat (plate carree) picture. Written to a temporary name and renamed at the
// end: a failure leaves no file.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "globemesh/mesh.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

struct PreviewOptions {
    std::string
        land; ///< optional OGR land polygons drawn under the mesh (layer "land", else the first)
    std::string colour_by = "quality"; ///< "quality" or "depth" (the node field of that name)
    int width_px = 1600;               ///< picture width in pixels; the height follows the extent
    std::optional<std::array<double, 4>>
        extent_deg; ///< W,S,E,N in degrees; default the mesh extent or globe
    bool overwrite =
        false; ///< replace an existing file; otherwise an existing output is an IoError
    /// Reports the share drawn and written (stage "write_preview"); returning false cancels.
    Progress progress;
};

/// Draws the mesh as a PNG. Throws UsageError (bad colour_by, width or extent), DataError (no
/// depth field to colour by, a land file without a layer), IoError (unwritable, existing output,
/// unreadable land) or Cancelled, and leaves no partial or temporary file.
void write_preview_png(const Mesh &mesh, const std::filesystem::path &path,
                       const PreviewOptions &options = {});

} // namespace globemesh
