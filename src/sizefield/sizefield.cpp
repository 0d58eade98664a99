// SizeField, build_size_field and the analytic size functions.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "feature_size.hpp"
#include "globemesh/error.hpp"
#include "globemesh/sizefield.hpp"
#include "grid.hpp"

namespace globemesh {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

std::string km(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g km", v);
    return buf;
}

} // namespace

double wavelength_size_km(double depth_m, double period_h, double n) {
    const double d = std::max(depth_m, min_depth_m);
    return period_h * 3600.0 * std::sqrt(standard_gravity * d) / n / 1000.0;
}

double slope_size_km(double depth_m, double grad_m_per_km, double n) {
    const double d = std::max(depth_m, min_depth_m);
    if (!(grad_m_per_km > 0))
        return inf;
    return 2.0 * pi * d / (n * grad_m_per_km);
}

namespace {

/// The same grid with rows south to north (dlat > 0).
Raster south_to_north(Raster grid) {
    if (grid.dlat_deg() > 0)
        return grid;
    const std::size_t nx = grid.nlon(), ny = grid.nlat();
    std::vector<float> v(grid.values().size());
    for (std::size_t j = 0; j < ny; ++j)
        std::copy_n(grid.values().begin() + static_cast<std::ptrdiff_t>((ny - 1 - j) * nx), nx,
                    v.begin() + static_cast<std::ptrdiff_t>(j * nx));
    return Raster(grid.lon0_deg(), grid.lat_deg(ny - 1), grid.dlon_deg(), -grid.dlat_deg(), nx, ny,
                  std::move(v));
}

double row_min(const Raster &g, std::size_t j) {
    double m = inf;
    for (std::size_t i = 0; i < g.nlon(); ++i)
        m = std::min(m, static_cast<double>(g.value(i, j)));
    return m;
}

} // namespace

SizeField::SizeField(Raster grid) : SizeField(std::move(grid), std::nan(""), std::nan("")) {}

SizeField::SizeField(Raster grid, double south_pole_km, double north_pole_km) {
    if (grid.values().empty())
        throw DataError("size field: empty background grid");
    grid = south_to_north(std::move(grid));
    min_ = inf;
    max_ = 0;
    for (float v : grid.values()) {
        if (!(std::isfinite(v) && v > 0))
            throw DataError("size field: a background node is not a positive size");
        min_ = std::min(min_, static_cast<double>(v));
        max_ = std::max(max_, static_cast<double>(v));
    }
    const double dlat = grid.dlat_deg(), first = grid.lat_deg(0),
                 last = grid.lat_deg(grid.nlat() - 1);
    south_cap_ = grid.global() && first > -90.0 && first - dlat <= -90.0 + 1e-9 * dlat;
    north_cap_ = grid.global() && last < 90.0 && last + dlat >= 90.0 - 1e-9 * dlat;
    if (south_cap_)
        south_ = std::isnan(south_pole_km) ? row_min(grid, 0) : south_pole_km;
    if (north_cap_)
        north_ = std::isnan(north_pole_km) ? row_min(grid, grid.nlat() - 1) : north_pole_km;
    for (double v : {south_cap_ ? south_ : 1.0, north_cap_ ? north_ : 1.0})
        if (!(v > 0 && std::isfinite(v)))
            throw DataError("size field: a pole value is not a positive size");
    if (south_cap_)
        min_ = std::min(min_, south_), max_ = std::max(max_, south_);
    if (north_cap_)
        min_ = std::min(min_, north_), max_ = std::max(max_, north_);
    grid_ = std::make_shared<const Raster>(std::move(grid));
}

SizeField SizeField::uniform(double h_km) {
    if (!(std::isfinite(h_km) && h_km > 0))
        throw UsageError("uniform size: h must be a positive length in km");
    SizeField f;
    f.min_ = f.max_ = h_km;
    return f;
}

double SizeField::size_km(double lon, double lat) const {
    if (!grid_)
        return min_; // uniform
    const Raster &g = *grid_;
    const std::size_t nx = g.nlon(), ny = g.nlat();
    const float *values = g.values().data();
    // Column pair and fraction; a regional grid holds its edge columns outside.
    double u;
    std::size_t i0, i1;
    if (g.global()) {
        u = (lon - g.lon0_deg()) / g.dlon_deg();
        u -= std::floor(u / static_cast<double>(nx)) * static_cast<double>(nx);
        i0 = std::min(static_cast<std::size_t>(u), nx - 1);
        i1 = i0 + 1 == nx ? 0 : i0 + 1;
        u -= static_cast<double>(i0);
    } else {
        const double span = static_cast<double>(nx - 1) * g.dlon_deg();
        const double centre = g.lon0_deg() + 0.5 * span;
        u = std::clamp(0.5 * span + std::remainder(lon - centre, 360.0), 0.0, span) / g.dlon_deg();
        i0 = std::min(static_cast<std::size_t>(u), nx > 1 ? nx - 2 : 0);
        i1 = std::min(i0 + 1, nx - 1);
        u -= static_cast<double>(i0);
    }
    auto row = [&](std::size_t j) {
        const float *r = values + j * nx;
        return (1 - u) * static_cast<double>(r[i0]) + u * static_cast<double>(r[i1]);
    };
    // Polar caps: linear in latitude between the edge row and the pole value.
    const double first = g.lat0_deg(), last = g.lat_deg(ny - 1);
    if (lat < first) {
        if (!south_cap_)
            return row(0);
        const double t = std::max(0.0, (lat + 90.0) / (first + 90.0));
        return (1 - t) * south_ + t * row(0);
    }
    if (lat > last) {
        if (!north_cap_)
            return row(ny - 1);
        const double t = std::max(0.0, (90.0 - lat) / (90.0 - last));
        return (1 - t) * north_ + t * row(ny - 1);
    }
    if (ny == 1)
        return row(0);
    double v = (lat - first) / g.dlat_deg();
    const std::size_t j0 = std::min(static_cast<std::size_t>(v), ny - 2);
    v -= static_cast<double>(j0);
    // Two triangles split along the 10-01 diagonal, linear in (lon, lat): the gradation
    // solver's corner conditions hold their gradients below --grade (grid.cpp).
    const float *r0 = values + j0 * nx;
    const float *r1 = r0 + nx;
    const double h10 = r0[i1], h01 = r1[i0];
    if (u + v <= 1) {
        const double h00 = r0[i0];
        return h00 + u * (h10 - h00) + v * (h01 - h00);
    }
    const double h11 = r1[i1];
    return h11 + (1 - u) * (h01 - h11) + (1 - v) * (h10 - h11);
}

double SizeField::size_km(const Vec3 &p) const {
    const LonLat ll = vec_to_lonlat(p);
    return size_km(ll.lon, ll.lat);
}

SizeFn SizeField::function() const {
    if (is_uniform())
        return uniform_size(min_);
    SizeField copy = *this;
    return [copy](const Vec3 &p) { return copy.size_km(p); };
}

namespace {

/// Depth (m, positive down; NaN where the raster has none) at every grid node, rows on every
/// thread.
std::vector<float> grid_depths(const detail::BackgroundGrid &g, const Raster &bathy,
                               std::size_t threads, const Progress &progress) {
    std::vector<float> depth(g.size());
    detail::for_row_blocks(
        g.nlat, 16, threads,
        [&](std::size_t j0, std::size_t j1) {
            for (std::size_t j = j0; j < j1; ++j)
                for (std::size_t i = 0; i < g.nlon; ++i)
                    depth[j * g.nlon + i] =
                        static_cast<float>(-bathy.elevation_m(g.lon(i), g.lat(j)));
        },
        [&](double f) { report(progress, f, "size field"); });
    return depth;
}

/// The smaller of the wavelength and slope components the options turn on at node n, km
/// (+inf where neither applies).
double depth_size_km(const detail::BackgroundGrid &g, const std::vector<float> &depth,
                     const SizeFieldOptions &o, std::size_t n) {
    const double dn = depth[n];
    double v = inf;
    if (std::isnan(dn))
        return v;
    if (o.wavelength > 0)
        v = std::min(v, wavelength_size_km(dn, o.wave_period_h, o.wavelength));
    if (o.slope > 0) {
        // Central differences of the floored depth (one-sided at edges and no-data).
        auto floored = [&](std::size_t m) {
            return std::isnan(depth[m]) ? std::numeric_limits<double>::quiet_NaN()
                                        : std::max(static_cast<double>(depth[m]), min_depth_m);
        };
        auto derivative = [&](const std::size_t nb[2], double step) {
            double lo = nb[0] == detail::BackgroundGrid::npos ? std::nan("") : floored(nb[0]);
            double hi = nb[1] == detail::BackgroundGrid::npos ? std::nan("") : floored(nb[1]);
            double here = std::max(dn, min_depth_m);
            if (!std::isnan(lo) && !std::isnan(hi))
                return (hi - lo) / (2 * step);
            if (!std::isnan(hi))
                return (hi - here) / step;
            if (!std::isnan(lo))
                return (here - lo) / step;
            return 0.0;
        };
        std::size_t r[2], c[2];
        g.row_neighbours(n, r);
        g.column_neighbours(n, c);
        const double gx = derivative(r, g.dx_km[n / g.nlon]);
        const double gy = derivative(c, g.dy_km);
        v = std::min(v, slope_size_km(dn, std::hypot(gx, gy), o.slope));
    }
    return v;
}

/// Lowers h (the grid's values, km) to the wavelength and slope components of the depth on
/// the grid (see sizefield.hpp), where the options turn them on; each node on its own, rows on
/// every thread.
void lower_by_depth(const detail::BackgroundGrid &g, const Raster &bathy, const SizeFieldOptions &o,
                    std::vector<float> &h, std::size_t threads, const Progress &progress) {
    const std::vector<float> depth =
        grid_depths(g, bathy, threads, sub_progress(progress, 0.35, 0.5));
    detail::for_row_blocks(g.nlat, 16, threads, [&](std::size_t j0, std::size_t j1) {
        for (std::size_t n = j0 * g.nlon; n < j1 * g.nlon; ++n) {
            const double v = depth_size_km(g, depth, o, n);
            if (v < h[n])
                h[n] = static_cast<float>(v);
        }
    });
}

/// The smallest size the field can take before the passages, km: hfloor, or the least of the
/// lower bounds of the components that are on when each has one above hfloor (coast: coast_size;
/// wavelength: its value at the depth floor), at most hmax. Slope, feature size and size regions
/// have none. The grid's spacing is half of it: a field that cannot go below it gets the grid
/// --hmin at that value would give, the same sizes on fewer nodes.
double finest_size_km(const SizeFieldOptions &o, double hfloor) {
    if (o.slope > 0 || o.feature_size > 0 || !o.size_regions.empty())
        return hfloor;
    double finest = o.hmax_km;
    if (o.coast_size_km > 0)
        finest = std::min(finest, o.coast_size_km);
    if (o.wavelength > 0)
        finest = std::min(finest, wavelength_size_km(min_depth_m, o.wave_period_h, o.wavelength));
    return std::max(hfloor, finest);
}

} // namespace

SizeField build_size_field(const SizeFieldOptions &o,
                           const std::optional<std::array<double, 4>> &region, const Raster *bathy,
                           const Boundary *coast, const Progress &progress, std::size_t max_nodes,
                           const std::function<void()> &before_grid,
                           std::span<const Passage> passages, std::size_t threads) {
    validate(o);
    threads = detail::field_threads(threads);
    if (region) { // checked as the coast checks it
        CoastOptions with_region;
        with_region.region = region;
        validate(with_region);
    }
    if (!(o.hmax_km > 0))
        throw UsageError(option("hmax_km") + " must be a positive length, e.g. 100km");
    if ((o.wavelength > 0 || o.slope > 0) && !bathy)
        throw UsageError(option(o.wavelength > 0 ? "wavelength" : "slope") +
                         " needs a bathymetry raster: give " + option("bathy"));
    if ((o.coast_size_km > 0 || o.feature_size > 0) && !coast)
        throw UsageError(option(o.coast_size_km > 0 ? "coast_size_km" : "feature_size") +
                         " needs the coastline: give " + option("coast"));
    const double hmax = o.hmax_km;
    const double hfloor = size_floor_km(o);
    if (o.coast_size_km > 0 && o.coast_size_km > hmax)
        throw UsageError(option("coast_size_km") + " (" + km(o.coast_size_km) +
                         ") must not be larger than " + option("hmax_km") + " (" + km(hmax) + ")");

    // The background grid, made when the first component that is on asks for it: a field no
    // component asked for is uniform, so a component cannot be on and left out.
    std::optional<detail::BackgroundGrid> grid;
    std::vector<float> h;
    auto background = [&]() -> const detail::BackgroundGrid & {
        if (grid)
            return *grid;
        if (before_grid)
            before_grid();
        report(progress, 0.0, "size field");
        grid = detail::make_background_grid(
            region, passages.empty() ? finest_size_km(o, hfloor) : hfloor, max_nodes);
        h.assign(grid->size(), static_cast<float>(hmax));
        return *grid;
    };
    auto lower = [&](std::size_t n, double v) {
        if (v < h[n])
            h[n] = static_cast<float>(v);
    };

    // Distance to the coast.
    if (o.coast_size_km > 0) {
        const detail::BackgroundGrid &g = background();
        if (coast && !coast->empty()) {
            const double reach = o.coast_rate > 0 ? (hmax - o.coast_size_km) / o.coast_rate : inf;
            std::vector<float> d = detail::coast_distance_km(
                g, *coast, std::min(reach * 1.01 + 2 * g.dy_km, pi * earth_radius_km),
                sub_progress(progress, 0.05, 0.35));
            for (std::size_t n = 0; n < g.size(); ++n)
                if (std::isfinite(d[n]))
                    lower(n, o.coast_size_km + o.coast_rate * d[n]);
        }
    }
    if (grid)
        report(progress, 0.35, "size field");

    // Wavelength and slope, from the depth on the grid.
    if (o.wavelength > 0 || o.slope > 0)
        lower_by_depth(background(), *bathy, o, h, threads, progress);
    if (grid)
        report(progress, 0.55, "size field");

    // Feature size: elements across every channel of water.
    if (o.feature_size > 0) {
        const detail::BackgroundGrid &g = background();
        if (!coast->empty())
            detail::apply_feature_size(g, *coast, o.feature_size, hmax, h,
                                       sub_progress(progress, 0.55, 0.6));
    }

    if (!o.size_regions.empty())
        detail::apply_size_regions(background(), o.size_regions, o.size_regions_layer, h);
    if (!passages.empty())
        background();
    if (!grid)
        return SizeField::uniform(std::max(o.hmax_km, o.hmin_km));
    report(progress, 0.6, "size field");

    const detail::BackgroundGrid &g = *grid;
    for (float &v : h)
        v = std::clamp(v, static_cast<float>(hfloor), static_cast<float>(hmax));
    detail::apply_passages(g, passages, o.passage_cells, h); // below hfloor where they ask
    const detail::PoleSizes poles =
        detail::limit_gradient(g, h, o.grade, sub_progress(progress, 0.6, 1.0));
    report(progress, 1.0, "size field");
    return SizeField(Raster(g.lon0, g.lat0, g.dlon, g.dlat, g.nlon, g.nlat, std::move(h)),
                     poles.south, poles.north);
}

SizeFn uniform_size(double h_km) {
    if (!(std::isfinite(h_km) && h_km > 0))
        throw UsageError("uniform size: h must be a positive length in km");
    return [h_km](const Vec3 &) { return h_km; };
}

SizeFn gulf_stream_size(Vec3 centre, double h_near_km, double h_far_km, double radius_km,
                        double ramp_km) {
    if (!(h_near_km > 0 && h_far_km > 0 && std::isfinite(h_near_km) && std::isfinite(h_far_km)))
        throw UsageError("gulf_stream_size: sizes must be positive lengths in km");
    if (!(radius_km >= 0 && ramp_km >= 0))
        throw UsageError("gulf_stream_size: radius and ramp must be >= 0 km");
    const Vec3 c = normalized(centre);
    return [=](const Vec3 &p) {
        const double d = arc_km(c, p);
        if (d <= radius_km)
            return h_near_km;
        if (d >= radius_km + ramp_km)
            return h_far_km;
        return h_near_km + (h_far_km - h_near_km) * (d - radius_km) / ramp_km;
    };
}

SizeFn latitude_size(double h_equator_km, double h_pole_km) {
    if (!(h_equator_km > 0 && h_pole_km > 0 && std::isfinite(h_equator_km) &&
          std::isfinite(h_pole_km)))
        throw UsageError("latitude_size: sizes must be positive lengths in km");
    return [=](const Vec3 &p) {
        const double s = std::min(1.0, std::abs(p.z) / norm(p));
        return h_equator_km + (h_pole_km - h_equator_km) * s;
    };
}

} // namespace globemesh
