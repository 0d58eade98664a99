// Internal to the mesher's parts: where the lunes' borders go (parts_lunes.cpp), chosen from
// where the mesher's work lies along the longitudes and where the coast runs near a meridian.
#pragma once

#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/parts.hpp"
#include "globemesh/size_fn.hpp"

namespace globemesh::parts_detail {

/// The longitudes are counted in lon_bins bins of equal width from default_border_lon; a
/// border may lie at the start of any bin. 1440 divides by every part count up to max_parts.
inline constexpr int lon_bins = 1440;

/// The bin (0 .. lon_bins - 1) holding p's longitude.
int lon_bin(const Vec3 &p);

/// Adds `nodes` to `bins` (lon_bins values) spread evenly over the longitudes the spherical
/// triangle a, b, c spans (over all of them where it holds a pole): the node estimate's pieces
/// span up to 32 sizes, tens of degrees at a coarse size.
void spread_over_longitudes(std::vector<double> &bins, const Vec3 &a, const Vec3 &b, const Vec3 &c,
                            double nodes);

/// Lunes of `count` parts whose first border is chosen among the lon_bins / count positions
/// of one lune's width, counting a bin's work as its estimated nodes (`nodes`, lon_bins values,
/// spread_over_longitudes) plus coast_node_work per node of the rings kept (`kept`, one flag per
/// ring) in it: among the positions whose busiest part has at most balance_slack more work than
/// the best one's, the one whose borders pass the kept rings least closely (a coast running
/// along a border less than a face off it leaves a part a sliver of water, meshed with faces as
/// narrow), then the better balanced, then the first.
Lunes choose_lunes(int count, const std::vector<double> &nodes, const std::vector<Ring> &rings,
                   const std::vector<char> &kept, const SizeFn &size_km);

} // namespace globemesh::parts_detail
