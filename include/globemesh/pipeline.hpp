// globemesh/pipeline.hpp: the library's top-level jobs, one call each (GDAL's *_lib pattern).
//
// mesh_ocean() runs the whole flow of DESIGN.md: read and shape the coastline, read the
// bathymetry, build the size field, mesh, attach depth and size. It returns the mesh with what
// each stage did as typed reports (OceanMesh); the run's metadata that the writers put in the
// files (Mesh::attributes) is formatted once from those reports (ocean_attributes).
// triangulate_file() is the scattered-points job. Both fill a StageTimings with the seconds each
// stage took.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "globemesh/coast.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/options.hpp"
#include "globemesh/passages.hpp"
#include "globemesh/progress.hpp"

namespace globemesh {

/// What reading the coast repaired (counts of load_coast's CoastData).
struct CoastRepairs {
    std::size_t polygons_joined = 0; ///< land polygons joined at near-touches
    std::size_t rings_changed = 0;   ///< rings gained or lost by snap rounding
    std::size_t arcs_split = 0;      ///< nodes added to great-circle arcs that strayed
};

/// The sampled depths at the mesh's nodes (m, positive down), as sampled and after --min-depth.
struct DepthReport {
    std::size_t above_sea_level = 0;   ///< nodes whose sampled depth is < 0
    double shallowest_m = 0;           ///< the smallest sampled depth when above_sea_level > 0
    std::optional<double> min_depth_m; ///< MeshOptions::min_depth_m, when set
    std::size_t raised = 0;            ///< nodes raised to min_depth_m
    std::size_t nodes = 0;             ///< nodes sampled
};

/// The size field the mesher used.
struct SizeFieldReport {
    bool uniform = true;           ///< one size everywhere (no term on), no background grid
    std::size_t grid_nodes = 0;    ///< nodes of the background grid (0 when uniform)
    double min_km = 0, max_km = 0; ///< smallest and largest size of the field (km)
};

/// The result of mesh_ocean: the mesh and what each stage did.
struct OceanMesh {
    Mesh mesh;                   ///< attributes: ocean_attributes(*this)
    std::string coast_file;      ///< MeshOptions::coast
    std::string coast_layer;     ///< the layer read
    std::string bathymetry_file; ///< MeshOptions::bathy ("" without bathymetry)
    CoastRepairs coast_repairs;
    CoastReport coast; ///< the shaped boundary
    SizeFieldReport size_field;
    MesherReport mesher;
    bool straits_closing = false;     ///< the mesher closed straits (a land mask and close_straits)
    std::optional<DepthReport> depth; ///< set with bathymetry
    std::vector<PassageReport> passages; ///< MeshOptions::passages inside the region, in order
    int passage_cells = 2;               ///< MeshOptions::passage_cells, the cells each needs
};

/// Meshes the ocean as the options say (validate(options) first). Deterministic: the same
/// options and inputs give the same mesh. Throws UsageError (bad options), DataError (inputs
/// that give no mesh, a run over max_nodes or max_memory_bytes, a node where the bathymetry has
/// no data and no bathy_fill_m is set), IoError (unreadable inputs) or
/// Cancelled (progress returned false); the messages name options by their MeshOptions field
/// (Error::message says them in a caller's words).
OceanMesh mesh_ocean(const MeshOptions &options, const Progress &progress = {},
                     StageTimings *timings = nullptr);

/// The run's metadata as key/value text, in the order the files carry it (UGRID global
/// attributes, the GeoPackage's mesh_info): inputs, depth counts, coast and mesher reports.
std::vector<std::pair<std::string, std::string>> ocean_attributes(const OceanMesh &run);

// One-line texts of the reports, as ocean_attributes and the command line's summary say them.
/// "P polygons joined at near-touches, R rings changed by snap rounding, A nodes added to straying
/// arcs"
std::string coast_repairs_text(const CoastRepairs &repairs);
/// "L (R removed, opening H holes, joining J loops, N moved off)": faces left on land.
std::string land_faces_text(const MesherReport &report);
/// "S (cutting off B basins: A km2, ...; W km2 of water closed with them; N nodes split)"
std::string straits_closed_text(const MesherReport &report);
/// "N (A km2)": inlets closed and the water they held.
std::string inlets_closed_text(const MesherReport &report);
/// "A km2 kept; B km2 dropped; ...": the ocean's components.
std::string ocean_components_text(const MesherReport &report);
/// Places as "lon lat" (degrees, 2 decimals) joined by ", ": the first `limit`, then ", ..."
/// when there are more.
std::string places_text(const std::vector<Vec3> &points, std::size_t limit);
/// A number as the reports write it (iostream's default: 6 significant digits).
std::string report_number(double v);

struct TriangulateOptions {
    std::string points; ///< any OGR point source (CSV with lon/lat columns, GPKG, SHP)
    std::string layer;  ///< layer name; default the first layer
    double merge_tolerance_rad = 1e-12; ///< points closer than this are merged
    std::uint64_t seed = 1;
};

/// Spherical Delaunay triangulation of the points of an OGR source (reprojected to lon/lat).
/// Keeps solid triangles only (see delaunay.hpp). Stages "read", "sort"+"triangulate" (timed
/// together as "triangulate" when not separable), "write" is the caller's.
Mesh triangulate_file(const TriangulateOptions &options, const Progress &progress = {},
                      StageTimings *timings = nullptr);

/// The same triangulation of points already on the sphere (unit vectors), for callers that hold
/// them in memory (the Python module). options.points names them in messages ("": "the
/// points"); options.layer is unused. Stages "sort" and "triangulate". Throws DataError (too
/// many points, no triangle) or Cancelled.
Mesh triangulate_points(std::vector<Vec3> points, const TriangulateOptions &options,
                        const Progress &progress = {}, StageTimings *timings = nullptr);

} // namespace globemesh
