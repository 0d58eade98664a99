// The part of the sphere a raster must cover for a run: the ocean the coast stage cut (no GDAL).
#include <algorithm>
#include <cmath>
#include <vector>

#include "globemesh/bathymetry.hpp"

namespace globemesh {

namespace {

/// True for a unit vector at a pole (its longitude is undefined).
bool at_pole(const Vec3 &p) {
    return std::hypot(p.x, p.y) < 1e-12;
}

/// Longitude of a unit vector, degrees in (-180, 180].
double lon_of(const Vec3 &p) {
    return std::atan2(p.y, p.x) * rad_to_deg;
}

/// a - b reduced to (-180, 180].
double lon_step(double a, double b) {
    double d = std::fmod(a - b, 360.0);
    if (d > 180)
        d -= 360;
    if (d <= -180)
        d += 360;
    return d;
}

} // namespace

int ocean_pole_winding(const Boundary &ocean) {
    // Walking north along a meridian, each ring crossed eastward (ocean on its left: north)
    // enters the ocean and each one crossed westward leaves it, so the net number of turns of
    // the rings about the axis is in(north pole) - in(south pole). Rings through a pole put
    // that pole on the boundary and are left out.
    double turns = 0;
    for (const Ring &r : ocean.rings) {
        if (std::any_of(r.nodes.begin(), r.nodes.end(), at_pole))
            continue;
        double sum = 0;
        for (std::size_t i = 0; i < r.nodes.size(); ++i)
            sum += lon_step(lon_of(r.nodes[(i + 1) % r.nodes.size()]), lon_of(r.nodes[i]));
        turns += std::round(sum / 360.0);
    }
    return static_cast<int>(turns);
}

std::optional<LonLatBounds> ocean_extent(const Boundary &ocean) {
    if (ocean.rings.empty())
        return std::nullopt;
    // Longitudes: bins of 1/8 degree marked along every segment (the shorter way round, as the
    // great-circle arc goes); the extent is the circle less its longest run of empty bins.
    constexpr int bins = 2880;
    constexpr double bin_deg = 360.0 / bins;
    std::vector<char> used(bins, 0);
    auto bin_of = [&](double lon) {
        return (static_cast<int>(std::floor((lon + 180.0) / bin_deg)) % bins + bins) % bins;
    };
    double south = 90, north = -90;
    for (const Ring &r : ocean.rings) {
        for (std::size_t i = 0; i < r.nodes.size(); ++i) {
            const Vec3 &a = r.nodes[i], &b = r.nodes[(i + 1) % r.nodes.size()];
            const double lat = vec_to_lonlat(a).lat;
            south = std::min(south, lat);
            north = std::max(north, lat);
            if (at_pole(a) && at_pole(b))
                continue;
            // A segment from a pole runs along the meridian of its other end.
            const double la = at_pole(a) ? lon_of(b) : lon_of(a),
                         lb = at_pole(b) ? lon_of(a) : lon_of(b);
            const double d = lon_step(lb, la);
            const int steps = static_cast<int>(std::ceil(std::abs(d) / bin_deg));
            for (int k = 0; k <= steps; ++k)
                used[bin_of(la + d * k / std::max(steps, 1))] = 1;
        }
    }
    const int winding = ocean_pole_winding(ocean);
    if (winding > 0)
        north = 90;
    if (winding < 0)
        south = -90;
    if (winding != 0 || north >= 90 || south <= -90)
        return LonLatBounds{-180, south, 180, north};
    // The longest circular run of empty bins.
    int best_len = 0, best_start = 0;
    for (int start = 0, len = 0, k = 0; k < 2 * bins; ++k) {
        if (used[k % bins]) {
            len = 0;
            continue;
        }
        if (len++ == 0)
            start = k;
        if (len > best_len && len <= bins)
            best_len = len, best_start = start;
    }
    if (best_len == 0)
        return LonLatBounds{-180, south, 180, north};
    const double west = -180.0 + ((best_start + best_len) % bins) * bin_deg;
    const double east = west + (bins - best_len) * bin_deg;
    return LonLatBounds{west, south, east, north};
}

} // namespace globemesh
