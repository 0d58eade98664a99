// Private to python/: the result of mesh_ocean() and triangulate() as Python sees it (the
// extension's class Mesh, wrapped by globemesh.Result).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "globemesh/mesh.hpp"
#include "globemesh/mesh_stats.hpp"

namespace globemesh::python {

namespace py = pybind11;

/// What the writers' topology gives (computed once, when first asked for): arrays as the UGRID
/// file holds them.
struct Derived {
    std::vector<double> lon, lat;                      ///< of the nodes, degrees
    std::vector<std::array<std::int32_t, 2>> edges;    ///< mesh_edge_nodes
    std::vector<std::int32_t> edge_tags;               ///< boundary_tag of every edge
    std::vector<std::array<std::int32_t, 2>> boundary; ///< mesh_boundary_nodes
    std::vector<std::int32_t> boundary_tags;           ///< the tag of each of them
    std::vector<double> quality, area_m2;              ///< per face
};

/// A finished run: the mesh and what writing it again needs.
struct PyMesh {
    Mesh mesh;
    MeshStats stats;
    std::string report_json; ///< the command line's --report JSON ("{}" for triangulate)
    std::string history;     ///< the files' `history` attribute
    std::string land;        ///< the coast a preview draws under the mesh ("" : none)
    std::optional<std::array<double, 4>> extent_deg; ///< a preview's extent (the region)
    std::optional<Derived> derived;

    const Derived &derive();
};

/// Adds the class Mesh (arrays without copies, write) to the extension.
void bind_result(py::module_ &m);

} // namespace globemesh::python
