// Summary statistics of a mesh: see MeshStats in globemesh/ugrid.hpp.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <future>
#include <utility>
#include <vector>

#include "globemesh/ugrid.hpp"
#include "mesh_topology.hpp"
#include "ordered_blocks.hpp"

namespace globemesh {

namespace io {

namespace {

/// Counts of positive values in bins of width 1/1024 up to 4 and one bin for the rest: enough to
/// find which few bins hold the middle ranks, so that the exact median needs only their values
/// (a few thousand at 1e6 edges) instead of a table of all of them (8 bytes an edge; the caller
/// keeps each edge's bin, 2 bytes, to find them again).
class RatioBins {
public:
    static constexpr std::size_t bin_count = 4 * 1024 + 1;
    static constexpr std::uint16_t no_bin = UINT16_MAX; ///< above every bin
    /// Counts r (>= 0) and returns its bin.
    std::uint16_t add(double r) {
        const std::size_t b = r < 4.0 ? std::size_t(r * 1024.0) : bin_count - 1;
        ++counts_[b];
        ++count_;
        return std::uint16_t(b);
    }
    std::size_t count() const { return count_; }
    /// Number of values in the bins before bin b.
    std::size_t count_below(std::size_t b) const {
        std::size_t n = 0;
        for (std::size_t i = 0; i < b; ++i)
            n += counts_[i];
        return n;
    }
    /// The bins of the lower and upper middle values (ranks (count-1)/2 and count/2, 0-based).
    std::pair<std::size_t, std::size_t> middle_bins() const {
        return {bin_of_rank((count_ - 1) / 2), bin_of_rank(count_ / 2)};
    }

private:
    std::size_t bin_of_rank(std::size_t rank) const {
        std::size_t b = 0, below = counts_[0];
        while (below <= rank)
            below += counts_[++b];
        return b;
    }
    std::vector<std::size_t> counts_ = std::vector<std::size_t>(bin_count, 0);
    std::size_t count_ = 0;
};

/// Faces or edges per block of compute_stats' loops (two doubles each: 2 MB a block).
constexpr std::size_t stats_block = std::size_t(1) << 17;

} // namespace

MeshStats compute_stats(const Mesh &mesh, const MeshTopology &topo) {
    MeshStats s;
    s.nodes = mesh.nodes.size();
    s.faces = mesh.faces.size();
    s.edges = topo.edge_count();
    s.boundary_edges = topo.boundary_edges.size();
    s.boundary_loops = count_boundary_loops(topo, mesh.nodes.size());
    // The nodes' extent is computed on another thread meanwhile: it sets members of `s` of its
    // own, so the statistics do not depend on the timing.
    // The longitudes in [0, 360) where the writers put them so (east_longitudes: a region across
    // 180, or up to it), else in [-180, 180).
    auto node_extent = [&] {
        if (mesh.nodes.empty())
            return;
        s.lon_min = s.lat_min = 1e300;
        s.lon_max = s.lat_max = -1e300;
        double east_min = 1e300, east_max = -1e300;
        for (const auto &v : mesh.nodes) {
            LonLat p = vec_to_lonlat(v);
            s.lon_min = std::min(s.lon_min, p.lon), s.lon_max = std::max(s.lon_max, p.lon);
            s.lat_min = std::min(s.lat_min, p.lat), s.lat_max = std::max(s.lat_max, p.lat);
            const double east = p.lon < 0 ? p.lon + 360 : p.lon;
            east_min = std::min(east_min, east), east_max = std::max(east_max, east);
        }
        if (east_longitudes(mesh))
            s.lon_min = east_min, s.lon_max = east_max;
    };
    // Joined before `s` is returned, or by its destructor should the faces or edges throw.
    std::future<void> nodes_done = start_task(node_extent);
    // The faces' quality and area, then the edges' lengths, computed a block at a time on every
    // core and summed here in face and edge order: the sums of the loop in turn, bit for bit.
    struct Values {
        std::vector<double> a, b;
    };
    auto blocks_of = [](std::size_t n) { return (n + stats_block - 1) / stats_block; };
    if (!mesh.faces.empty()) {
        s.quality_min = 1e300;
        double qsum = 0, area = 0;
        std::size_t above = 0;
        compute_in_order<Values, char>(
            blocks_of(mesh.faces.size()),
            [&](std::size_t k, Values &v, char &) {
                const std::size_t first = k * stats_block,
                                  last = std::min(mesh.faces.size(), first + stats_block);
                v.a.resize(last - first), v.b.resize(last - first);
                for (std::size_t i = first; i < last; ++i) {
                    const auto &f = mesh.faces[i];
                    const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
                    v.a[i - first] = triangle_quality(a, b, c);
                    v.b[i - first] = std::fabs(spherical_triangle_area(a, b, c));
                }
            },
            [&](std::size_t, const Values &v) {
                for (std::size_t i = 0; i < v.a.size(); ++i) {
                    const double q = v.a[i];
                    s.quality_min = std::min(s.quality_min, q);
                    qsum += q;
                    if (q > 0.8)
                        ++above;
                    s.quality_histogram[std::clamp(int(q * 10.0), 0, 9)]++;
                    area += v.b[i];
                }
            });
        s.quality_mean = qsum / double(mesh.faces.size());
        s.quality_above_0_8 = double(above) / double(mesh.faces.size());
        s.area_km2 = area * earth_radius_km * earth_radius_km;
    }
    const Field *size = mesh.node_field("target_size");
    s.has_size = size && size->values.size() == mesh.nodes.size();
    if (topo.edge_count() > 0) {
        s.edge_km_min = 1e300;
        double sum = 0;
        auto edge_km = [&](std::size_t e) {
            const auto n = topo.edge_nodes(e);
            return arc_km(mesh.nodes[n[0]], mesh.nodes[n[1]]);
        };
        // Edge length over the mean target of its ends, for edges whose target is positive and
        // finite; NaN for the others.
        auto ratio = [&](std::size_t e, double km) {
            const auto n = topo.edge_nodes(e);
            const double target = 0.5 * (size->values[n[0]] + size->values[n[1]]);
            return target > 0 && std::isfinite(target) ? km / target : std::nan("");
        };
        RatioBins bins;
        // The bin of each edge's ratio, so that the second pass recomputes only the ratios in the
        // middle bins (2 bytes an edge).
        std::vector<std::uint16_t> edge_bin(s.has_size ? topo.edge_count() : 0, RatioBins::no_bin);
        std::size_t in = 0;
        compute_in_order<Values, char>(
            blocks_of(topo.edge_count()),
            [&](std::size_t k, Values &v, char &) {
                const std::size_t first = k * stats_block,
                                  last = std::min(topo.edge_count(), first + stats_block);
                v.a.resize(last - first), v.b.resize(s.has_size ? last - first : 0);
                for (std::size_t e = first; e < last; ++e) {
                    v.a[e - first] = edge_km(e);
                    if (s.has_size)
                        v.b[e - first] = ratio(e, v.a[e - first]);
                }
            },
            [&](std::size_t k, const Values &v) {
                for (std::size_t i = 0; i < v.a.size(); ++i) {
                    const double km = v.a[i];
                    s.edge_km_min = std::min(s.edge_km_min, km);
                    s.edge_km_max = std::max(s.edge_km_max, km);
                    sum += km;
                    if (!s.has_size || std::isnan(v.b[i]))
                        continue;
                    const double r = v.b[i];
                    edge_bin[k * stats_block + i] = bins.add(r);
                    if (r >= 0.7 && r <= 1.4)
                        ++in;
                }
            });
        s.edge_km_mean = sum / double(topo.edge_count());
        if (bins.count() > 0) {
            s.size_ratio_in_range = double(in) / double(bins.count());
            // Second pass: the ratios in the bins of the middle ranks, computed again.
            const auto [first, last] = bins.middle_bins();
            std::vector<double> middle;
            middle.reserve(bins.count_below(last + 1) - bins.count_below(first));
            for (std::size_t e = 0; e < edge_bin.size(); ++e)
                if (edge_bin[e] >= first && edge_bin[e] <= last)
                    middle.push_back(ratio(e, edge_km(e)));
            // Rank of the upper middle value (the median for an odd count) among `middle`.
            auto mid = middle.begin() + std::ptrdiff_t(bins.count() / 2 - bins.count_below(first));
            std::nth_element(middle.begin(), mid, middle.end());
            double median = *mid;
            if (bins.count() % 2 == 0)
                median = 0.5 * (median + *std::max_element(middle.begin(), mid));
            s.size_ratio_median = median;
        }
    }
    nodes_done.get();
    return s;
}

} // namespace io

MeshStats compute_stats(const Mesh &mesh) {
    return io::compute_stats(mesh, *io::topology_of(mesh));
}

} // namespace globemesh
