// Internal: longitudes into [-180, 180), and whether a point lies in a region's box W,S,E,N in
// degrees (W > E crosses 180), for the pipeline's passages and the mesher's slides.
#pragma once

#include <array>
#include <cmath>

#include "globemesh/sphere.hpp"

namespace globemesh {

/// lon moved by a multiple of 360 degrees into [-180, 180).
inline double wrap_lon(double lon) {
    return lon - 360 * std::floor((lon + 180) / 360);
}

/// Whether p lies in `box` (W, S, E, N degrees; W > E across 180), edges included: its longitude
/// east of W by at most the box's span (modulo 360, so that 180 and -180 are one meridian).
inline bool in_lonlat_box(const std::array<double, 4> &box, const LonLat &p) {
    double east = p.lon - box[0];
    east -= 360 * std::floor(east / 360);
    const double span = box[2] > box[0] ? box[2] - box[0] : box[2] - box[0] + 360;
    return p.lat >= box[1] && p.lat <= box[3] && east <= span;
}

} // namespace globemesh
