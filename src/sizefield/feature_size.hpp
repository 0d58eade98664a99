// Internal to sizefield/: the feature-size component (--feature-size), from the medial axis of
// the water approximated by the Delaunay triangles of dense coast samples on the sphere.
#pragma once

#include <cstddef>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"
#include "grid.hpp"

namespace globemesh::detail {

/// A Delaunay triangle of coast samples that lies in water and spans a channel: its empty
/// circumcircle touches the coast on both sides, so its centre is a vertex of the Voronoi
/// diagram on the water's medial axis and its radius is the local feature size there.
struct ChannelTriangle {
    Vec3 a, b, c;      ///< corners (coast samples, unit vectors, counter-clockwise)
    double lfs_km = 0; ///< circumradius: half the channel's width (great-circle km)
};

/// The channel triangles of the coast segments of `b` sampled every spacing_km (at most
/// max_samples samples: the spacing grows on a longer coast), those with lfs_km <= max_lfs_km.
/// A triangle is in water when its centroid lies on the ocean side (the left) of the coast at
/// a majority of its corners; it spans a channel when two of its corners lie on different
/// pieces of coast or more than four radii apart along the coast (a tighter triangle is a bend
/// of one shore, not a channel).
std::vector<ChannelTriangle> channel_triangles(const Boundary &b, double spacing_km,
                                               double max_lfs_km,
                                               std::size_t max_samples = std::size_t{1} << 21);

/// Lowers h to 2 lfs / elements on the grid nodes within 1.5 grid rows of each channel triangle
/// of `b` (samples every grid row's spacing): `elements` triangles across each channel.
void apply_feature_size(const BackgroundGrid &g, const Boundary &b, double elements, double hmax_km,
                        std::vector<float> &h, const Progress &progress);

} // namespace globemesh::detail
