// Summary statistics of a mesh: see MeshStats in globemesh/ugrid.hpp.
#include <algorithm>
#include <cmath>

#include "globemesh/ugrid.hpp"
#include "mesh_topology.hpp"

namespace globemesh {

namespace io {

MeshStats compute_stats(const Mesh& mesh, const MeshTopology& topo) {
    MeshStats s;
    s.nodes = mesh.nodes.size();
    s.faces = mesh.faces.size();
    s.edges = topo.edge_nodes.size();
    s.boundary_edges = topo.boundary_edges.size();
    s.boundary_loops = count_boundary_loops(topo, mesh.nodes.size());
    if (!mesh.nodes.empty()) {
        s.lon_min = s.lat_min = 1e300;
        s.lon_max = s.lat_max = -1e300;
        for (const auto& v : mesh.nodes) {
            LonLat p = vec_to_lonlat(v);
            s.lon_min = std::min(s.lon_min, p.lon), s.lon_max = std::max(s.lon_max, p.lon);
            s.lat_min = std::min(s.lat_min, p.lat), s.lat_max = std::max(s.lat_max, p.lat);
        }
    }
    if (!mesh.faces.empty()) {
        s.quality_min = 1e300;
        double qsum = 0, area = 0;
        std::size_t above = 0;
        for (const auto& f : mesh.faces) {
            const Vec3 &a = mesh.nodes[f[0]], &b = mesh.nodes[f[1]], &c = mesh.nodes[f[2]];
            double q = triangle_quality(a, b, c);
            s.quality_min = std::min(s.quality_min, q);
            qsum += q;
            if (q > 0.8) ++above;
            s.quality_histogram[std::clamp(int(q * 10.0), 0, 9)]++;
            area += std::fabs(spherical_triangle_area(a, b, c));
        }
        s.quality_mean = qsum / double(mesh.faces.size());
        s.quality_above_0_8 = double(above) / double(mesh.faces.size());
        s.area_km2 = area * earth_radius_km * earth_radius_km;
    }
    const Field* size = mesh.node_field("target_size");
    s.has_size = size && size->values.size() == mesh.nodes.size();
    if (!topo.edge_nodes.empty()) {
        s.edge_km_min = 1e300;
        double sum = 0;
        std::vector<double> ratios;
        if (s.has_size) ratios.reserve(topo.edge_nodes.size());
        for (const auto& e : topo.edge_nodes) {
            double km = arc_km(mesh.nodes[e[0]], mesh.nodes[e[1]]);
            s.edge_km_min = std::min(s.edge_km_min, km);
            s.edge_km_max = std::max(s.edge_km_max, km);
            sum += km;
            if (s.has_size) {
                double target = 0.5 * (size->values[e[0]] + size->values[e[1]]);
                if (target > 0 && std::isfinite(target)) ratios.push_back(km / target);
            }
        }
        s.edge_km_mean = sum / double(topo.edge_nodes.size());
        if (!ratios.empty()) {
            std::size_t in = std::count_if(ratios.begin(), ratios.end(), [](double r) { return r >= 0.7 && r <= 1.4; });
            s.size_ratio_in_range = double(in) / double(ratios.size());
            auto mid = ratios.begin() + std::ptrdiff_t(ratios.size() / 2);
            std::nth_element(ratios.begin(), mid, ratios.end());
            double median = *mid;
            if (ratios.size() % 2 == 0) median = 0.5 * (median + *std::max_element(ratios.begin(), mid));
            s.size_ratio_median = median;
        }
    }
    return s;
}

} // namespace io

MeshStats compute_stats(const Mesh& mesh) { return io::compute_stats(mesh, io::build_topology(mesh)); }

} // namespace globemesh
