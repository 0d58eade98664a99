// Raster: the lon/lat grid and its bilinear sampling (no GDAL here).
#include <algorithm>
#include <cmath>
#include <limits>

#include "globemesh/bathymetry.hpp"
#include "globemesh/error.hpp"

namespace globemesh {

namespace {

constexpr double nan_value = std::numeric_limits<double>::quiet_NaN();

/// x modulo m in [0, m).
double positive_mod(double x, double m) {
    double r = std::fmod(x, m);
    if (r < 0)
        r += m;
    return r >= m ? 0.0 : r;
}

} // namespace

Raster::Raster(double lon0_deg, double lat0_deg, double dlon_deg, double dlat_deg, std::size_t nlon,
               std::size_t nlat, std::vector<float> values)
    : lon0_(lon0_deg), lat0_(lat0_deg), dlon_(dlon_deg), dlat_(dlat_deg), nlon_(nlon), nlat_(nlat),
      values_(std::move(values)) {
    if (nlon == 0 || nlat == 0 || values_.size() != nlon * nlat)
        throw DataError("raster grid: " + std::to_string(nlon) + " x " + std::to_string(nlat) +
                        " nodes but " + std::to_string(values_.size()) + " values");
    if (!(dlon_ > 0) || !(dlat_ != 0) || !std::isfinite(lon0_) || !std::isfinite(lat0_))
        throw DataError("raster grid: spacing must be dlon > 0 and dlat != 0 degrees");
    global_ = std::abs(static_cast<double>(nlon_) * dlon_ - 360.0) <= 1e-6 * dlon_;
    // Rows are valid from half a cell before the first to half a cell after the last, and
    // edge_margin beyond; a global grid whose edge row lies within one cell of a pole holds that
    // row up to the pole.
    v_lo_ = -0.5 - edge_margin - 1e-9;
    v_hi_ = static_cast<double>(nlat_) - 0.5 + edge_margin + 1e-9;
    if (global_) {
        for (double pole : {-90.0, 90.0}) {
            double v = (pole - lat0_) / dlat_;
            if (v < v_lo_ && v >= v_lo_ - 1.0)
                v_lo_ = v - 1e-9;
            if (v > v_hi_ && v <= v_hi_ + 1.0)
                v_hi_ = v + 1e-9;
        }
    }
}

LonLatBounds Raster::bounds() const {
    double w = lon0_ - 0.5 * dlon_;
    double e = lon0_ + (static_cast<double>(nlon_) - 0.5) * dlon_;
    double a = lat0_ - 0.5 * dlat_;
    double b = lat0_ + (static_cast<double>(nlat_) - 0.5) * dlat_;
    return {w, std::max(-90.0, std::min(a, b)), e, std::min(90.0, std::max(a, b))};
}

bool Raster::contains(double lon, double lat) const {
    if (!std::isfinite(lon) || !std::isfinite(lat))
        return false;
    double v = (lat - lat0_) / dlat_;
    if (v < v_lo_ || v > v_hi_)
        return false;
    if (global_)
        return true;
    return on_columns(column_at(lon, lat));
}

double Raster::column_at(double lon, double lat) const {
    const double u = column_of(lon);
    if (std::abs(lat) < 90.0 || on_columns(u))
        return u;
    return 0.5 * (static_cast<double>(nlon_) - 1.0);
}

double Raster::column_of(double lon) const {
    const double from = lon0_ - (0.5 + edge_margin) * dlon_;
    const double l = from + positive_mod(lon - from + 1e-9 * dlon_, 360.0) - 1e-9 * dlon_;
    return (l - lon0_) / dlon_;
}

namespace {

// The pair of grid lines around position u (in cell units, clamped to [0, n - 1]) and the
// fraction of the way from the first to the second; a single line is its own pair.
void bracket(double u, std::size_t n, std::size_t &k0, std::size_t &k1, double &f) {
    u = std::clamp(u, 0.0, static_cast<double>(n) - 1.0);
    if (n == 1) {
        k0 = k1 = 0;
        f = 0;
        return;
    }
    k0 = std::min(static_cast<std::size_t>(u), n - 2);
    k1 = k0 + 1;
    f = u - static_cast<double>(k0);
}

} // namespace

double Raster::sample(double lon, double lat) const {
    if (values_.empty() || !std::isfinite(lon) || !std::isfinite(lat))
        return nan_value;
    const double n_lon = static_cast<double>(nlon_);
    // Column position u in cell units from column 0, and the pair of columns around it.
    std::size_t i0, i1;
    double fu;
    if (global_) {
        double u = positive_mod((lon - lon0_) / dlon_, n_lon);
        double fl = std::floor(u);
        i0 = std::min(static_cast<std::size_t>(fl), nlon_ - 1);
        i1 = i0 + 1 == nlon_ ? 0 : i0 + 1;
        fu = u - fl;
    } else {
        const double u = column_at(lon, lat);
        if (!on_columns(u))
            return nan_value;
        bracket(u, nlon_, i0, i1, fu);
    }
    double v = (lat - lat0_) / dlat_;
    if (v < v_lo_ || v > v_hi_)
        return nan_value;
    std::size_t j0, j1;
    double fv;
    bracket(v, nlat_, j0, j1, fv);
    const double z00 = values_[j0 * nlon_ + i0], z10 = values_[j0 * nlon_ + i1];
    const double z01 = values_[j1 * nlon_ + i0], z11 = values_[j1 * nlon_ + i1];
    const double w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
    if (!std::isnan(z00) && !std::isnan(z10) && !std::isnan(z01) && !std::isnan(z11))
        return w00 * z00 + w10 * z10 + w01 * z01 + w11 * z11;
    // Some corner has no data: no data when the nearest corner has none, otherwise the
    // renormalised bilinear mean of the valid corners.
    double nearest = fu < 0.5 ? (fv < 0.5 ? z00 : z01) : (fv < 0.5 ? z10 : z11);
    if (std::isnan(nearest))
        return nan_value;
    double sum = 0, weight = 0;
    const double z[4] = {z00, z10, z01, z11}, w[4] = {w00, w10, w01, w11};
    for (int k = 0; k < 4; ++k)
        if (!std::isnan(z[k])) {
            sum += w[k] * z[k];
            weight += w[k];
        }
    return weight > 0 ? sum / weight : nearest;
}

double Raster::elevation_m(double lon, double lat) const {
    double z = sample(lon, lat);
    if (std::isnan(z) && fill_)
        return *fill_;
    return z;
}

double Raster::elevation_m(const Vec3 &p) const {
    LonLat ll = vec_to_lonlat(p);
    return elevation_m(ll.lon, ll.lat);
}

std::size_t Raster::valid_count() const {
    return static_cast<std::size_t>(
        std::count_if(values_.begin(), values_.end(), [](float v) { return !std::isnan(v); }));
}

} // namespace globemesh
