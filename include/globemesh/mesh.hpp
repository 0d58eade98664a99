// globemesh/mesh.hpp: the triangle mesh the library produces and the writers take.
//
// Invariants: nodes are unit vectors; every face lists three distinct node indices,
// counter-clockwise seen from outside the sphere; boundary edges are oriented as their face
// (mesh on the left) and tagged. Fields are named per-node or per-face arrays of doubles, in a
// fixed order (writers keep that order, so output is deterministic).
// Standard library only.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

using NodeIndex = std::uint32_t;

/// Tag of a mesh edge, as written to UGRID's boundary_tag (flag_values 0 1 2).
enum class EdgeTag : int { interior = 0, coast = 1, open = 2 };

struct BoundaryEdge {
    NodeIndex a = 0, b = 0; ///< oriented as the face it belongs to (mesh on the left)
    EdgeTag tag = EdgeTag::coast;
};

/// A named array on nodes or faces, with CF-style attributes for the writers.
struct Field {
    std::string name;          ///< variable name, e.g. "depth"
    std::string long_name;     ///< human-readable name (QGIS shows it)
    std::string units;         ///< UDUNITS string, e.g. "m", "km", "1"
    std::string standard_name; ///< CF standard name or empty
    std::vector<double> values;
};

struct Mesh {
    std::vector<Vec3> nodes;
    std::vector<std::array<NodeIndex, 3>> faces;
    std::vector<BoundaryEdge> boundary;
    std::vector<Field> node_fields;
    std::vector<Field> face_fields;
    /// Run metadata (input files, options, statistics) written as global attributes / mesh_info.
    std::vector<std::pair<std::string, std::string>> attributes;

    const Field *node_field(const std::string &name) const {
        for (const auto &f : node_fields)
            if (f.name == name)
                return &f;
        return nullptr;
    }
    const Field *face_field(const std::string &name) const {
        for (const auto &f : face_fields)
            if (f.name == name)
                return &f;
        return nullptr;
    }
};

} // namespace globemesh
