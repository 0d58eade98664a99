// Internal to sizefield/: the background grid's geometry and the two grid solvers.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/options.hpp"
#include "globemesh/passages.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::detail {

/// A lon/lat grid of cell centres: node (i, j) at lon0 + i*dlon, lat0 + j*dlat (dlat > 0, rows
/// south to north). A global grid has an even nlon, wraps across +-180 and links row 0 (and the
/// last row) to the node 180 degrees away on the same row, across the pole.
struct BackgroundGrid {
    double lon0 = 0, lat0 = 0, dlon = 1, dlat = 1; // degrees
    std::size_t nlon = 0, nlat = 0;
    bool global = false;
    std::vector<double> sin_lon, cos_lon, sin_lat, cos_lat;
    std::vector<double> dx_km; ///< great-circle distance between neighbours on row j
    double dy_km = 0;          ///< great-circle distance between neighbours along a column
    /// Global grids whose first (last) row lies within one row spacing of the south (north)
    /// pole close that gap with a polar cap: the field is linear in latitude between the row and
    /// one value at the pole.
    bool south_cap = false, north_cap = false;

    BackgroundGrid(double lon0_deg, double lat0_deg, double dlon_deg, double dlat_deg,
                   std::size_t nlon_, std::size_t nlat_, bool global_);

    std::size_t size() const { return nlon * nlat; }
    double lon(std::size_t i) const { return lon0 + static_cast<double>(i) * dlon; }
    double lat(std::size_t j) const { return lat0 + static_cast<double>(j) * dlat; }
    Vec3 node(std::size_t i, std::size_t j) const {
        return {cos_lat[j] * cos_lon[i], cos_lat[j] * sin_lon[i], sin_lat[j]};
    }
    Vec3 node(std::size_t n) const { return node(n % nlon, n / nlon); }

    /// The two neighbours of node n along its row (west, east); npos where there is none.
    void row_neighbours(std::size_t n, std::size_t out[2]) const;
    /// The two neighbours of node n along its meridian (south, north); npos where there is none.
    void column_neighbours(std::size_t n, std::size_t out[2]) const;

    static constexpr std::size_t npos = static_cast<std::size_t>(-1);
};

/// Threads for the size field's per-node terms: `threads`, or one per core when 0 (at most 16).
std::size_t field_threads(std::size_t threads);

/// Runs rows(begin, end) over the row blocks of [0, n) (`block` rows each) on up to `threads`
/// threads, the calling one among them, which reports (fraction of the blocks done) to `progress`
/// after each block it runs. rows must write only what its rows own, so the results do not
/// depend on the thread count. An exception (Cancelled from progress, one from rows) stops the
/// blocks not started and is rethrown once every thread has returned.
void for_row_blocks(std::size_t n, std::size_t block, std::size_t threads,
                    const std::function<void(std::size_t, std::size_t)> &rows,
                    const std::function<void(double)> &progress = {});

/// The grid build_size_field uses for these options: see sizefield.hpp.
/// region: W,S,E,N degrees, nullopt for the whole globe.
BackgroundGrid make_background_grid(const std::optional<std::array<double, 4>> &region,
                                    double hfloor_km, std::size_t max_nodes);

/// Great-circle distance (km) from every node to the nearest point of the boundary rings, up to
/// max_km (nodes farther get +infinity).
std::vector<float> coast_distance_km(const BackgroundGrid &g, const Boundary &b, double max_km,
                                     const Progress &progress);

/// Sizes at the two poles (km) for the polar caps; NaN where the grid has no cap.
struct PoleSizes {
    double south = std::nan(""), north = std::nan("");
};

/// Lowers h (never below its smallest value) so that the field SizeField evaluates from it,
/// bilinear in lon/lat in each cell and linear in latitude over the polar caps, has
/// |grad h| <= grade everywhere on the sphere; returns the pole values of the caps. See
/// grid.cpp for the cell condition and the ordered (Dijkstra-like) solver.
PoleSizes limit_gradient(const BackgroundGrid &g, std::vector<float> &h, double grade,
                         const Progress &progress);

/// min(h, size_km) over the nodes inside each polygon of an OGR source with a size_km field:
/// of its layer `layer_name`, or of every layer with that field when it is empty.
void apply_size_regions(const BackgroundGrid &g, const std::string &path,
                        const std::string &layer_name, std::vector<float> &h);

/// min(h, width_km / cells) on the nodes of every grid cell each passage's line runs through,
/// for passages of positive width.
void apply_passages(const BackgroundGrid &g, std::span<const Passage> passages, int cells,
                    std::vector<float> &h);

} // namespace globemesh::detail
