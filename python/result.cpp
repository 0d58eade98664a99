// The extension's class Mesh: the mesh's arrays as numpy views of the library's vectors (the
// Python object owns them, so no copy), those the UGRID writer derives (edges, boundary, quality,
// areas) computed once by the writer's own functions, and write() through the writers table.
#include "result.hpp"

#include <mutex>
#include <tuple>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "cli_outputs.hpp"
#include "face_area.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "progress_bridge.hpp"

namespace globemesh::python {

namespace {

/// Serialises the first computation of the derived arrays (the getters release the GIL).
std::mutex derive_mutex;

/// Each face's geodesic area (m2) as the UGRID writer computes it.
std::vector<double> face_areas(const io::MeshTopology &topo, std::size_t faces) {
    const io::GeodesicFaceAreas areas(topo);
    std::vector<std::int32_t> edges;
    io::face_edges(topo, 0, faces, edges);
    std::vector<double> m2(faces);
    for (std::size_t f = 0; f < faces; ++f)
        m2[f] = areas.face_m2(f, &edges[3 * f]);
    return m2;
}

/// The edges, their tags and the boundary as the UGRID file numbers them.
void derive_edges(const io::MeshTopology &topo, Derived &d) {
    d.edges.resize(topo.edge_count());
    for (std::size_t e = 0; e < topo.edge_count(); ++e)
        d.edges[e] = topo.edge_nodes(e);
    d.edge_tags.assign(topo.edge_count(), std::int32_t(EdgeTag::interior));
    for (std::size_t i = 0; i < topo.boundary_edges.size(); ++i) {
        const auto e = std::size_t(topo.boundary_edges[i]);
        d.edge_tags[e] = topo.boundary_tags[i];
        d.boundary.push_back(topo.edge_nodes(e));
        d.boundary_tags.push_back(topo.boundary_tags[i]);
    }
}

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
const Derived &derived_of(PyMesh &m) {
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
    const auto &table = writers();
    const cli::OutputChoices choices{paths, format, creation, {}};
    const auto planned =
        cli::plan_outputs(choices, table, {}, m.mesh.node_field("depth") != nullptr);
    const std::vector<OutputRequest> requests = cli::requests(planned);
    check_output_srs(output_srs, requests);
    cli::check_output_files(cli::output_files(planned, "", "", table), {}, overwrite);
    WriteOptions options;
    options.overwrite = overwrite;
    options.history = m.history;
    options.stats = &m.stats;
    options.land = m.land;
    options.extent_deg = m.extent_deg;
    options.output_srs = output_srs;
    ProgressBridge bridge(std::move(callback));
    run_without_gil(bridge, [&](const Progress &progress) {
        options.progress = progress;
        write_outputs(m.mesh, requests, options);
        return true;
    });
}

} // namespace

const Derived &PyMesh::derive() {
    if (derived)
        return *derived;
    Derived d;
    const io::MeshTopology topo = io::build_topology(mesh);
    for (const Vec3 &p : mesh.nodes) {
        const LonLat ll = vec_to_lonlat(p);
        d.lon.push_back(ll.lon);
        d.lat.push_back(ll.lat);
    }
    derive_edges(topo, d);
    for (const auto &f : mesh.faces)
        d.quality.push_back(triangle_quality(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]));
    d.area_m2 = face_areas(topo, mesh.faces.size());
    derived = std::move(d);
    return *derived;
}

void bind_result(py::module_ &m) {
    using Self = PyMesh;
    py::class_<Self, std::shared_ptr<Self>> c(m, "Mesh");
    c.def_property_readonly(
        "faces", [](py::object self) { return rows(self, self.cast<Self &>().mesh.faces); });
    c.def_property_readonly("nodes_xyz", [](py::object self) {
        const auto &nodes = self.cast<Self &>().mesh.nodes;
        static_assert(sizeof(Vec3) == 3 * sizeof(double));
        return view(self, &nodes.data()->x, {py::ssize_t(nodes.size()), 3},
                    {py::ssize_t(sizeof(Vec3)), py::ssize_t(sizeof(double))});
    });
    c.def_property_readonly("node_fields", [](py::object self) {
        return fields(self, self.cast<Self &>().mesh.node_fields);
    });
    c.def_property_readonly("face_fields", [](py::object self) {
        return fields(self, self.cast<Self &>().mesh.face_fields);
    });
    // Derived: views of the vectors PyMesh::derive computed once.
    const std::pair<const char *, std::vector<double> Derived::*> doubles[] = {
        {"node_lon", &Derived::lon},
        {"node_lat", &Derived::lat},
        {"quality", &Derived::quality},
        {"face_area", &Derived::area_m2}};
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
    c.def_property_readonly("attributes", [](const Self &s) { return s.mesh.attributes; });
    c.def_property_readonly("report_json", [](const Self &s) { return s.report_json; });
    c.def("write", &write_mesh, py::arg("paths"), py::arg("format") = "",
          py::arg("creation_options") = std::vector<std::string>{}, py::arg("overwrite") = false,
          py::arg("output_srs") = "", py::arg("progress") = py::none());
}

} // namespace globemesh::python
