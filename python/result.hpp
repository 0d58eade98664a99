// Private to python/: the result of mesh_ocean() and triangulate() as Python sees it (the
// extension's class Mesh, wrapped by globemesh.Result).
#pragma once

#include <optional>

#include <pybind11/pybind11.h>

#include "globemesh/command.hpp"

namespace globemesh::python {

namespace py = pybind11;

/// A finished run, with the arrays the UGRID writer derives (computed once, when first asked for).
struct PyMesh {
    command::Run run;
    std::optional<command::Arrays> derived;

    const command::Arrays &derive();
};

/// Adds the class Mesh (arrays without copies, write) to the extension.
void bind_result(py::module_ &m);

} // namespace globemesh::python
