// Meshes built directly for the io tests (no mesher needed): icospheres with nodes at the poles,
// the same with holes (tagged boundary loops), and regional caps crossing the antimeridian.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "globemesh/mesh.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::test {

/// Icosahedron with nodes at both poles (exactly (0,0,+-1)), midpoint-subdivided `level` times:
/// 20 * 4^level faces, counter-clockwise from outside. Every face touching a pole and the faces
/// across lon 180 are there on purpose.
inline Mesh icosphere(int level) {
    Mesh m;
    const double lat = std::atan(0.5) * rad_to_deg;
    m.nodes.push_back(lonlat_to_vec(0, 90));
    for (int i = 0; i < 5; ++i)
        m.nodes.push_back(lonlat_to_vec(-180 + 72.0 * i, lat));
    for (int i = 0; i < 5; ++i)
        m.nodes.push_back(lonlat_to_vec(-144 + 72.0 * i, -lat));
    m.nodes.push_back(lonlat_to_vec(0, -90));
    for (NodeIndex i = 0; i < 5; ++i) {
        NodeIndex u = 1 + i, un = 1 + (i + 1) % 5, l = 6 + i, ln = 6 + (i + 1) % 5;
        m.faces.push_back({0, u, un});
        m.faces.push_back({u, l, un});
        m.faces.push_back({un, l, ln});
        m.faces.push_back({l, 11, ln});
    }
    for (int s = 0; s < level; ++s) {
        std::map<std::pair<NodeIndex, NodeIndex>, NodeIndex> mid;
        auto midpoint = [&](NodeIndex a, NodeIndex b) {
            auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end())
                return it->second;
            m.nodes.push_back(normalized(m.nodes[a] + m.nodes[b]));
            return mid[key] = NodeIndex(m.nodes.size() - 1);
        };
        std::vector<std::array<NodeIndex, 3>> faces;
        for (auto [a, b, c] : m.faces) {
            NodeIndex ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            faces.push_back({a, ab, ca});
            faces.push_back({ab, b, bc});
            faces.push_back({ca, bc, c});
            faces.push_back({ab, bc, ca});
        }
        m.faces = std::move(faces);
    }
    for (auto &f : m.faces) // make every face counter-clockwise seen from outside
        if (dot(m.nodes[f[0]], cross(m.nodes[f[1]], m.nodes[f[2]])) < 0)
            std::swap(f[1], f[2]);
    return m;
}

/// Adds node fields depth (m, from a smooth function) and target_size (km).
inline void add_fields(Mesh &m) {
    Field depth{"depth", "sea floor depth", "m", "sea_floor_depth_below_geoid", {}};
    Field size{"target_size", "target edge length", "km", "", {}};
    for (const auto &v : m.nodes) {
        depth.values.push_back(2000.0 + 1500.0 * v.z + 500.0 * v.x);
        size.values.push_back(500.0 + 100.0 * v.y);
    }
    m.node_fields = {depth, size};
}

/// Keeps the faces for which keep(face index) is true, drops unused nodes (and their field
/// values) and tags each new boundary edge with tag(a, b) (mesh on the left, a -> b).
inline Mesh keep_faces(const Mesh &in, const std::function<bool(std::size_t)> &keep,
                       const std::function<EdgeTag(const Vec3 &, const Vec3 &)> &tag) {
    Mesh m;
    std::vector<NodeIndex> map(in.nodes.size(), NodeIndex(-1));
    std::map<std::pair<NodeIndex, NodeIndex>, int> edge_use;
    for (std::size_t f = 0; f < in.faces.size(); ++f) {
        if (!keep(f))
            continue;
        std::array<NodeIndex, 3> t;
        for (int k = 0; k < 3; ++k) {
            NodeIndex v = in.faces[f][k];
            if (map[v] == NodeIndex(-1)) {
                map[v] = NodeIndex(m.nodes.size());
                m.nodes.push_back(in.nodes[v]);
            }
            t[k] = map[v];
        }
        m.faces.push_back(t);
        for (int k = 0; k < 3; ++k)
            edge_use[{t[k], t[(k + 1) % 3]}]++;
    }
    for (const auto &[e, n] : edge_use)
        if (!edge_use.count({e.second, e.first}))
            m.boundary.push_back({e.first, e.second, tag(m.nodes[e.first], m.nodes[e.second])});
    for (const auto &f : in.node_fields) {
        Field g = f;
        g.values.assign(m.nodes.size(), 0.0);
        for (std::size_t v = 0; v < in.nodes.size(); ++v)
            if (map[v] != NodeIndex(-1))
                g.values[map[v]] = f.values[v];
        m.node_fields.push_back(g);
    }
    return m;
}

/// An icosphere with three holes: the stars of the nodes nearest three centres. The hole near
/// lon 0 is coast, the one near lon 90 open, the one near lon -90 coast on its northern half.
inline Mesh icosphere_with_holes(int level) {
    Mesh full = icosphere(level);
    add_fields(full);
    const Vec3 centres[3] = {lonlat_to_vec(0, 20), lonlat_to_vec(90, -30), lonlat_to_vec(-90, 40)};
    std::vector<char> drop(full.faces.size(), 0);
    for (const Vec3 &c : centres) {
        NodeIndex best = 0;
        for (NodeIndex v = 0; v < full.nodes.size(); ++v)
            if (dot(full.nodes[v], c) > dot(full.nodes[best], c))
                best = v;
        for (std::size_t f = 0; f < full.faces.size(); ++f)
            if (std::find(full.faces[f].begin(), full.faces[f].end(), best) != full.faces[f].end())
                drop[f] = 1;
    }
    return keep_faces(
        full, [&](std::size_t f) { return !drop[f]; },
        [](const Vec3 &a, const Vec3 &b) {
            LonLat p = vec_to_lonlat(normalized(a + b));
            if (std::fabs(p.lon - 90) < 30)
                return EdgeTag::open;
            if (std::fabs(p.lon + 90) < 30 && p.lat < 40)
                return EdgeTag::open;
            return EdgeTag::coast;
        });
}

/// An icosphere whose pole nodes are gone: each pole's star is re-triangulated as a fan from one
/// of its neighbours, so one face at each pole surrounds it without having it as a corner (the
/// face a global ocean mesh has when no node lands on the pole). Pole nodes are left unused.
inline Mesh icosphere_without_pole_nodes(int level) {
    Mesh m = icosphere(level);
    for (NodeIndex pole = 0; pole < m.nodes.size(); ++pole) {
        if (m.nodes[pole].x != 0 || m.nodes[pole].y != 0)
            continue;
        std::map<NodeIndex, NodeIndex> next; // star edges, counter-clockwise round the pole
        std::vector<std::array<NodeIndex, 3>> faces;
        for (const auto &f : m.faces) {
            const auto it = std::find(f.begin(), f.end(), pole);
            if (it == f.end()) {
                faces.push_back(f);
                continue;
            }
            const auto k = std::size_t(it - f.begin());
            next[f[(k + 1) % 3]] = f[(k + 2) % 3];
        }
        std::vector<NodeIndex> ring = {next.begin()->first};
        while (ring.size() < next.size())
            ring.push_back(next.at(ring.back()));
        for (std::size_t i = 1; i + 1 < ring.size(); ++i)
            faces.push_back({ring[0], ring[i], ring[i + 1]});
        m.faces = std::move(faces);
    }
    return m;
}

/// The faces of an icosphere whose centroid lies within radius_deg of (lon, lat), tagged open.
inline Mesh icosphere_cap(int level, double lon, double lat, double radius_deg) {
    Mesh full = icosphere(level);
    add_fields(full);
    const Vec3 c = lonlat_to_vec(lon, lat);
    const double cos_r = std::cos(radius_deg * deg_to_rad);
    return keep_faces(
        full,
        [&](std::size_t f) {
            const auto &t = full.faces[f];
            return dot(normalized(full.nodes[t[0]] + full.nodes[t[1]] + full.nodes[t[2]]), c) >
                   cos_r;
        },
        [](const Vec3 &, const Vec3 &) { return EdgeTag::open; });
}

} // namespace globemesh::test
