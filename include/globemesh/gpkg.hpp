// globemesh/gpkg.hpp: GeoPackage output (OGR).
//
// write_gpkg writes layers a QGIS user opens and styles at once: faces (cut at +-180, pole
// corners split), nodes, boundary (tagged lines), mesh_info, and a default style for faces in
// layer_styles. One feature per face. Written to a temporary name and renamed at the end.
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "globemesh/mesh.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

struct MeshStats;

struct GpkgOptions {
    bool overwrite =
        false; ///< replace an existing file; otherwise an existing output is an IoError
    /// compute_stats of this same mesh when the caller has it (mesh_info takes it as it is);
    /// null: the writer computes it.
    const MeshStats *stats = nullptr;
    /// Each face's area (m2) as write_ugrid gave it for this same mesh
    /// (UgridOptions::face_areas_m2); null, or not one per face: the writer computes them. The
    /// writer empties it (frees its memory) once the faces are written.
    std::vector<double> *face_areas_m2 = nullptr;
    /// Reports the share written (stage "write_gpkg"); returning false cancels (Cancelled, no
    /// file left).
    Progress progress;
};

/// Writes the mesh as a GeoPackage. Throws IoError and leaves no partial or temporary file.
void write_gpkg(const Mesh &mesh, const std::filesystem::path &path,
                const GpkgOptions &options = {});

} // namespace globemesh
