// globemesh/sizefield.hpp: the target edge length h(x) in km, built once, evaluated fast.
//
// build_size_field() computes h on a background lon/lat grid and SizeField::size_km() evaluates
// it bilinearly (one vec_to_lonlat and four loads: 170 ns a call at random points on the
// 16.8 M-node global grid of the issue-5 options, mostly cache misses; see bench/). h is
//   h = grade_limit( clamp( min(components the options turn on, hmax), hfloor, hmax ) )
// with the components (all km):
//   coast      h = coast_size + coast_rate * d, d the great-circle distance to the boundary rings
//              (nearest-point propagation on the grid from the rings densified to a quarter of
//              the grid spacing: error below about a quarter of the grid spacing);
//   wavelength h = T * sqrt(g * D) / n      (T = wave_period_h hours, g = 9.80665 m/s2,
//              n = --wavelength, D the depth in metres);
//   slope      h = 2 pi D / (n * |grad D|)   (n = --slope, |grad D| in m/km by central
//              differences on the grid);
//   regions    h = size_km of every --size-regions polygon holding the node (OGR, any CRS).
// Depth floor: where the raster says land or is shallower than min_depth_m (5 m) at a point the
// mesh treats as ocean, D = 5 m for the wavelength and slope components (a coarse raster puts
// shallow coastal water above sea level); where the raster has no data and no fill, those two
// components are off at that node.
// hfloor is --hmin, or when --hmin is 0 the sane floor max(hmax / 1000, 0.01 km).
// Gradation: h is then lowered where needed so that |grad h| <= grade on the sphere, by fast
// marching of the upwind (Godunov) eikonal scheme on the grid: after it, every node satisfies
//   (max(h - h_west_or_east_min, 0) / dx)^2 + (max(h - h_south_or_north_min, 0) / dy)^2 <= grade^2
// with dx, dy the great-circle distances to the neighbours (float rounding: relative 1e-5), so
// |h(a) - h(b)| <= grade * |ab| along every grid row and column, across +-180 and across the
// poles (row 0's southern neighbour is the node 180 degrees away on row 0).
//
// Background grid: cell centres, nlon even, spacing hfloor / 2 but never more than max_nodes
// nodes (2^24 by default: 64 MiB of float in the final field, about 6.5 km spacing on a global
// grid; a 1e6-node global mesh, h ~ 20 km, needs a 10 km grid: 6.7 M nodes, 27 MB). Building
// needs about 4 more arrays of the same size at peak. Global unless options.region is set;
// a regional grid covers the region plus one cell and holds its edge values outside.
//
// References: Persson, "Mesh size functions for implicit geometries and PDE-based gradient
// limiting", Eng. Comput. 22 (2006); Roberts et al., OceanMesh2D, GMD 12 (2019) for the
// wavelength and slope components.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

#include "globemesh/bathymetry.hpp"
#include "globemesh/boundary.hpp"
#include "globemesh/options.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

/// A size function: target edge length in km at a unit vector.
using SizeFn = std::function<double(const Vec3&)>;

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

/// The size field on its background grid (values in km, no NaN).
class SizeField {
public:
    SizeField() = default;
    /// Wraps a grid of sizes (km, all finite and > 0). Throws DataError otherwise.
    explicit SizeField(Raster grid);

    /// Target edge length at p, km: bilinear on the background grid (edge values held outside
    /// a regional grid, first/last rows held up to the poles).
    double size_km(const Vec3& p) const;
    double size_km(double lon_deg, double lat_deg) const;
    double operator()(const Vec3& p) const { return size_km(p); }

    /// The background grid (node values in km), for checks and output.
    const Raster& grid() const { return *grid_; }
    /// A SizeFn sharing this field's grid (cheap to copy).
    SizeFn function() const;

    /// Smallest and largest node value, km.
    double min_km() const { return min_; }
    double max_km() const { return max_; }

private:
    std::shared_ptr<const Raster> grid_;
    double min_ = 0, max_ = 0;
};

/// Builds the size field the options ask for (see the file comment). bathy: the bathymetry
/// (required when --wavelength or --slope is on, else may be null); coast: the boundary rings at
/// full resolution (required when --coast-size is on). max_nodes caps the background grid.
/// Throws UsageError (bad sizes, a component without its input, naming the option), DataError
/// (a --size-regions file without a size_km field) or IoError (--size-regions unreadable).
SizeField build_size_field(const MeshOptions& options, const Raster* bathy, const Boundary* coast,
                           const Progress& progress = {},
                           std::size_t max_nodes = std::size_t{1} << 24);

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
