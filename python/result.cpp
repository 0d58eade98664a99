// The extension's class Mesh: the mesh's arrays as numpy views of the library's vectors (the
// Python object owns them, so no copy), those the UGRID writer derives (edges, boundary, quality,
// areas) computed once by the writer's own functions, and write() through the writers table.
#include "result.hpp"

#include <mutex>
#include <tuple>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "progress_bridge.hpp"

namespace globemesh::python {

namespace {

/// Serialises the first computation of the derived arrays (the getters release the GIL).
std::mutex derive_mutex;

/// A read-only numpy view of `data` that keeps `owner` (the Python Mesh) alive.
template <class T>
py::array view(py::handle owner, const T *data, std::vector<py::ssize_t> shape,
               std::vector<py::ssize_t> strides) {
    py::array a(py::dtype::of<T>(), std::move(shape), std::move(strides), data, owner);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

template <class T> py::array column(py::handle owner, const std::vector<T> &v) {
    return view(owner, v.data(), {py::ssize_t(v.size())}, {py::ssize_t(sizeof(T))});
}

/// Rows of N int32 (std::array<int32 or uint32, N>), as (n, N) int32.
template <class Row> py::array rows(py::handle owner, const std::vector<Row> &v) {
    static_assert(sizeof(Row) == sizeof(std::int32_t) * std::tuple_size_v<Row>);
    const py::ssize_t n = std::tuple_size_v<Row>;
    return view(owner, reinterpret_cast<const std::int32_t *>(v.data()), {py::ssize_t(v.size()), n},
                {py::ssize_t(sizeof(Row)), 4});
}

/// The derived arrays, computed on first use with the GIL released.
const command::Arrays &derived_of(PyMesh &m) {
    py::gil_scoped_release release;
    std::lock_guard lock(derive_mutex);
    return m.derive();
}

/// {name: values} of node or face fields, as views.
py::dict fields(py::handle owner, const std::vector<Field> &list) {
    py::dict d;
    for (const Field &f : list)
        d[py::str(f.name)] = column(owner, f.values);
    return d;
}

/// Writes the mesh to `paths` as `globemesh mesh -o PATH... [-f FORMAT] [--co KEY=VALUE...]`
/// would: the same choice of formats, checks and messages, no file left on an error or cancel.
void write_mesh(PyMesh &m, const std::vector<std::string> &paths, const std::string &format,
                const std::vector<std::string> &creation, bool overwrite,
                const std::string &output_srs, py::object callback) {
    const command::Outputs outputs{paths, format, creation, overwrite, output_srs};
    ProgressBridge bridge(std::move(callback));
    run_without_gil(bridge, [&](const Progress &progress) {
        command::write(m.run, outputs, progress);
        return true;
    });
}

} // namespace

const command::Arrays &PyMesh::derive() {
    if (!derived)
        derived = command::ugrid_arrays(run.mesh);
    return *derived;
}

void bind_result(py::module_ &m) {
    using Self = PyMesh;
    py::class_<Self, std::shared_ptr<Self>> c(m, "Mesh");
    c.def_property_readonly(
        "faces", [](py::object self) { return rows(self, self.cast<Self &>().run.mesh.faces); });
    c.def_property_readonly("nodes_xyz", [](py::object self) {
        const auto &nodes = self.cast<Self &>().run.mesh.nodes;
        static_assert(sizeof(Vec3) == 3 * sizeof(double));
        return view(self, &nodes.data()->x, {py::ssize_t(nodes.size()), 3},
                    {py::ssize_t(sizeof(Vec3)), py::ssize_t(sizeof(double))});
    });
    c.def_property_readonly("node_fields", [](py::object self) {
        return fields(self, self.cast<Self &>().run.mesh.node_fields);
    });
    c.def_property_readonly("face_fields", [](py::object self) {
        return fields(self, self.cast<Self &>().run.mesh.face_fields);
    });
    // Derived: views of the vectors PyMesh::derive computed once.
    const std::pair<const char *, std::vector<double> command::Arrays::*> doubles[] = {
        {"node_lon", &command::Arrays::lon},
        {"node_lat", &command::Arrays::lat},
        {"quality", &command::Arrays::quality},
        {"face_area", &command::Arrays::area_m2}};
    for (const auto &[name, member] : doubles)
        c.def_property_readonly(name, [member = member](py::object self) {
            return column(self, derived_of(self.cast<Self &>()).*member);
        });
    c.def_property_readonly(
        "edges", [](py::object self) { return rows(self, derived_of(self.cast<Self &>()).edges); });
    c.def_property_readonly("edge_tags", [](py::object self) {
        return column(self, derived_of(self.cast<Self &>()).edge_tags);
    });
    c.def_property_readonly("boundary_edges", [](py::object self) {
        return rows(self, derived_of(self.cast<Self &>()).boundary);
    });
    c.def_property_readonly("boundary_tags", [](py::object self) {
        return column(self, derived_of(self.cast<Self &>()).boundary_tags);
    });
    c.def_property_readonly("attributes", [](const Self &s) { return s.run.mesh.attributes; });
    c.def_property_readonly("report_json", [](const Self &s) { return s.run.report_json; });
    c.def("write", &write_mesh, py::arg("paths"), py::arg("format") = "",
          py::arg("creation_options") = std::vector<std::string>{}, py::arg("overwrite") = false,
          py::arg("output_srs") = "", py::arg("progress") = py::none());
}

} // namespace globemesh::python
