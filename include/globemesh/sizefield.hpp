// globemesh/sizefield.hpp: the target edge length h(x) in km, built once, evaluated fast.
//
// build_size_field() computes h on a background lon/lat grid and SizeField::size_km() evaluates
// it piecewise linearly in (lon, lat) between the grid nodes (each cell split into two triangles
// along its south-east to north-west diagonal), and linearly in latitude from the first and
// last rows of a global grid to one value at each pole (one vec_to_lonlat and four loads). h is
//   h = grade_limit( clamp( min(components the options turn on, hmax), hfloor, hmax ) )
// with the components (all km):
//   coast      h = coast_size + coast_rate * d, d the great-circle distance to the boundary rings
//              (nearest-point propagation on the grid from the rings densified to a quarter of
//              the grid spacing: error below about a quarter of the grid spacing);
//   wavelength h = T * sqrt(g * D) / n      (T = wave_period_h hours, g = 9.80665 m/s2,
//              n = wavelength, D the depth in metres);
//   slope      h = 2 pi D / (n * |grad D|)   (n = slope, |grad D| in m/km by central
//              differences on the grid);
//   feature    h = 2 lfs / n (n = feature_size) over the channels of water, lfs their half width:
//              the circumradius of the spherical Delaunay triangles of coast samples (every grid
//              row) that lie in water and touch two shores, their circumcentres on the medial
//              axis (sizefield/feature_size.hpp), on the nodes within 1.5 rows of them;
//   regions    h = size_km of every size_regions polygon holding the node (OGR, any CRS).
// and after the clamp, so below hfloor where a passage needs it:
//   passages   h = width / passage_cells on the grid cells each passage's line runs through
//              (passages.hpp; the width is measured by the caller).
// Depth floor: where the raster says land or is shallower than min_depth_m (5 m) at a point the
// mesh treats as ocean, D = 5 m for the wavelength and slope components (a coarse raster puts
// shallow coastal water above sea level); where the raster has no data and no fill, those two
// components are off at that node.
// hfloor is hmin_km, or when hmin_km is 0 the sane floor max(hmax / 1000, 0.01 km).
// Gradation: h is then lowered where needed so that the evaluated field is grade-Lipschitz on the
// sphere: |h(p) - h(q)| <= grade * arc(p, q) for every pair of points (great-circle distance,
// km), not only along the grid lines. The solver (grid.cpp) holds in every cell, corners 00, 10,
// 01, 11, the two corner conditions of its triangles
//   ((h10 - h00) / dx)^2 + ((h01 - h00) / dy)^2 <= grade^2,  ((h11 - h01) / dx)^2 + ((h11 - h10) /
//   dy)^2 <= grade^2
// (dx = R dlon cos(lat) at the cell's poleward row, dy = R dlat), which bound the Riemannian
// gradient of the linear interpolant by grade everywhere in the cell, and the like conditions of
// the polar caps. It accepts nodes in increasing order of value (fast marching with those
// conditions in place of the upwind eikonal update), never lowers a node below the
// smallest initial value (so hfloor still holds) and rounds down to float: the bound holds up to
// float rounding (relative 1e-6). A regional grid holds its edge values outside its nodes: there
// the bound holds except poleward of the grid, where a held row's east-west differences sit on
// shorter parallels (never reached by a mesh of the region: the grid has a cell of margin).
//
// Background grid: cell centres, nlon even, spacing half the smallest size the field can take
// but never more than max_nodes nodes (2^24 by default: 64 MiB of float in the final field, about
// 6.5 km spacing on a global grid). That size is hfloor, or, when every component that is on has
// a lower bound above it (coast: coast_size_km; wavelength: its value at the 5 m depth floor;
// slope, feature size and size regions have none) and there are no passages, the least of those
// bounds (at most hmax): the grid --hmin at that size would give, and the same field. Building
// needs about 4 more arrays of the same size at peak. No grid at all when no component is on: the
// field is then uniform (SizeField::is_uniform). Global unless options.region is set; a regional
// grid covers the region plus one cell and holds its edge values outside.
//
// References: Persson, "Mesh size functions for implicit geometries and PDE-based gradient
// limiting", Eng. Comput. 22 (2006); Roberts et al., OceanMesh2D, GMD 12 (2019) for the
// wavelength, slope and feature-size components.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>

#include "globemesh/bathymetry.hpp"
#include "globemesh/boundary.hpp"
#include "globemesh/options.hpp"
#include "globemesh/passages.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/size_fn.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

/// Gravity used by the wavelength component, m/s2 (standard gravity).
inline constexpr double standard_gravity = 9.80665;
/// Depth floor of the wavelength and slope components, metres.
inline constexpr double min_depth_m = 5.0;

/// Wavelength component: T * sqrt(g * max(depth, min_depth_m)) / n, km. period_h in hours,
/// depth_m positive down, points_per_wavelength n > 0.
double wavelength_size_km(double depth_m, double period_h, double points_per_wavelength);

/// Slope component: 2 pi max(depth, min_depth_m) / (n * grad), km; grad = |grad depth| in m/km.
/// Infinite where grad is 0.
double slope_size_km(double depth_m, double grad_m_per_km, double points_per_length);

/// The size field: one size everywhere (uniform), or values on a background grid (km, no NaN).
class SizeField {
public:
    SizeField() = default;
    /// One size h_km everywhere, without a grid. Throws UsageError unless h_km > 0.
    static SizeField uniform(double h_km);
    /// Wraps a grid of sizes (km, all finite and > 0). A global grid whose first (last) row lies
    /// within one row spacing of a pole is closed by a polar cap, linear in latitude from that row
    /// to the pole value (south_pole_km, north_pole_km; NaN: the smallest value of the row).
    /// Throws DataError on a non-positive or non-finite size.
    explicit SizeField(Raster grid);
    SizeField(Raster grid, double south_pole_km, double north_pole_km);

    /// Target edge length at p, km: piecewise linear on the background grid's triangles (exact
    /// at the nodes; edge values held outside a regional grid, polar caps on a global one).
    double size_km(const Vec3 &p) const;
    double size_km(double lon_deg, double lat_deg) const;
    double operator()(const Vec3 &p) const { return size_km(p); }

    /// True when the field is one size everywhere (no term of the options is on): no grid.
    bool is_uniform() const { return !grid_; }
    /// The background grid (node values in km), for checks and output; only when !is_uniform().
    const Raster &grid() const { return *grid_; }
    /// A SizeFn sharing this field's grid (cheap to copy).
    SizeFn function() const;

    /// Pole values of the caps, km (NaN where the grid has no cap).
    double south_pole_km() const { return south_cap_ ? south_ : std::nan(""); }
    double north_pole_km() const { return north_cap_ ? north_ : std::nan(""); }

    /// Smallest and largest node value (poles included), km.
    double min_km() const { return min_; }
    double max_km() const { return max_; }

private:
    std::shared_ptr<const Raster> grid_;
    double min_ = 0, max_ = 0;
    bool south_cap_ = false, north_cap_ = false;
    double south_ = 0, north_ = 0;
};

/// Builds the size field the options ask for (see the file comment), over `region` (the run's
/// CoastOptions::region, or the box of a region file's ocean; W,S,E,N degrees; nullopt: the whole
/// globe). bathy: the bathymetry
/// (required when wavelength or slope is on, else may be null); coast: the boundary rings at
/// full resolution (required when coast_size_km or feature_size is on). max_nodes caps the
/// background grid.
/// When no component is on the field is uniform (max(hmax_km, hmin_km), SizeField::is_uniform)
/// and no grid is built; otherwise before_grid, when set, is called once before the grid is
/// allocated (to refuse the run by throwing). passages: the lines of options.passages with their
/// widths (read_passages, measure_passages); the field has a grid when there are any.
/// threads: how many threads compute the per-node terms (0: one per core); the field does not
/// depend on it (the same floats), and the gradation runs on the calling thread.
/// Throws UsageError (bad sizes or region, a component without its input, naming the option),
/// DataError (a size_regions file without a size_km field) or IoError (size_regions unreadable).
SizeField build_size_field(const SizeFieldOptions &options,
                           const std::optional<std::array<double, 4>> &region, const Raster *bathy,
                           const Boundary *coast, const Progress &progress = {},
                           std::size_t max_nodes = std::size_t{1} << 24,
                           const std::function<void()> &before_grid = {},
                           std::span<const Passage> passages = {}, std::size_t threads = 0);

/// build_size_field with the size field's part and the region of a whole run's options.
inline SizeField build_size_field(const MeshOptions &options, const Raster *bathy,
                                  const Boundary *coast, const Progress &progress = {},
                                  std::size_t max_nodes = std::size_t{1} << 24,
                                  const std::function<void()> &before_grid = {},
                                  std::span<const Passage> passages = {}, std::size_t threads = 0) {
    return build_size_field(size_field_options(options), options.region, bathy, coast, progress,
                            max_nodes, before_grid, passages, threads);
}

/// Uniform size h_km everywhere. Throws UsageError unless h_km > 0.
SizeFn uniform_size(double h_km);

/// h_near within radius_km of centre, h_far beyond radius_km + ramp_km, linear in the
/// great-circle distance between (a Gulf-Stream-like refinement; default gradient 0.14).
SizeFn gulf_stream_size(Vec3 centre, double h_near_km = 20, double h_far_km = 160,
                        double radius_km = 1500, double ramp_km = 1000);

/// h_equator + (h_pole - h_equator) * |sin(lat)|: small at the equator, growing with latitude
/// (|grad h| <= |h_pole - h_equator| / earth_radius_km).
SizeFn latitude_size(double h_equator_km, double h_pole_km);

} // namespace globemesh
