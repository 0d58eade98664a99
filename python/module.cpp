// The extension globemesh._globemesh: mesh_ocean() through the command line's own option parser
// (the same names, units, defaults and messages as `globemesh mesh`), triangulate() of lon/lat
// arrays, and the library's errors as Python exceptions. globemesh/__init__.py is the API.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "gdal_warnings.hpp"
#include "globemesh/command.hpp"
#include "globemesh/error.hpp"
#include "globemesh/pipeline.hpp"
#include "progress_bridge.hpp"
#include "result.hpp"

namespace globemesh::python {

namespace {

/// (keyword, is a flag, values it takes) of each option mesh_ocean() takes, keywords as the
/// long option names with '_' for '-'.
std::vector<std::tuple<std::string, bool, int>> mesh_keywords() {
    std::vector<std::tuple<std::string, bool, int>> keywords;
    for (const command::Keyword &k : command::mesh_keywords())
        keywords.emplace_back(k.name, k.flag, k.values);
    return keywords;
}

/// mesh_ocean(args, progress): `args` are those of `globemesh mesh` without outputs.
std::shared_ptr<PyMesh> mesh_ocean_args(const std::vector<std::string> &args, py::object callback) {
    auto result = std::make_shared<PyMesh>();
    ProgressBridge bridge(std::move(callback));
    result->run = run_without_gil(
        bridge, [&](const Progress &progress) { return command::mesh(args, progress); });
    warn_run(result->run.warnings);
    return result;
}

/// The points of lon/lat arrays (degrees) on the sphere. Throws UsageError for arrays of other
/// shapes and for a point that is no place.
std::vector<Vec3> points_of(const py::array_t<double, py::array::forcecast> &lon,
                            const py::array_t<double, py::array::forcecast> &lat) {
    if (lon.ndim() != 1 || lat.ndim() != 1 || lon.size() != lat.size())
        throw UsageError("lon and lat must be 1-D arrays of the same length");
    std::vector<Vec3> points;
    points.reserve(std::size_t(lon.size()));
    const auto x = lon.unchecked<1>(), y = lat.unchecked<1>();
    for (py::ssize_t i = 0; i < x.shape(0); ++i) {
        if (!std::isfinite(x(i)) || !std::isfinite(y(i)) || std::abs(y(i)) > 90)
            throw UsageError("point " + std::to_string(i) + " (lon " + report_number(x(i)) +
                             ", lat " + report_number(y(i)) +
                             ") is no place: lon must be finite, lat in [-90, 90]");
        points.push_back(lonlat_to_vec(x(i), y(i)));
    }
    return points;
}

/// triangulate(lon, lat, progress): the spherical Delaunay triangulation of the points.
std::shared_ptr<PyMesh> triangulate_arrays(const py::array_t<double, py::array::forcecast> &lon,
                                           const py::array_t<double, py::array::forcecast> &lat,
                                           py::object callback) {
    std::vector<Vec3> points = points_of(lon, lat);
    auto result = std::make_shared<PyMesh>();
    ProgressBridge bridge(std::move(callback));
    result->run = run_without_gil(bridge, [&](const Progress &progress) {
        return command::triangulate(std::move(points), progress);
    });
    return result;
}

/// The library's errors as the command line says them (one line, options named by their
/// flags), each as its Python exception.
void register_errors(py::module_ &m) {
    static py::exception<Error> base(m, "Error", PyExc_RuntimeError);
    // globemesh.Error catches them all; ValueError and OSError as Python's own kinds.
    static py::exception<UsageError> usage(m, "UsageError",
                                           py::make_tuple(base, py::handle(PyExc_ValueError)));
    static py::exception<DataError> data(m, "DataError", base.ptr());
    static py::exception<IoError> io(m, "IoError", py::make_tuple(base, py::handle(PyExc_OSError)));
    static py::exception<Cancelled> cancelled(m, "Cancelled", base.ptr());
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p)
                std::rethrow_exception(p);
        } catch (const Cancelled &) {
            cancelled("cancelled, no output written");
        } catch (const UsageError &e) {
            usage(command::error_message(e).c_str());
        } catch (const IoError &e) {
            io(command::error_message(e).c_str());
        } catch (const DataError &e) {
            data(command::error_message(e).c_str());
        } catch (const Error &e) {
            base(command::error_message(e).c_str());
        }
    });
}

} // namespace

} // namespace globemesh::python

PYBIND11_MODULE(_globemesh, m) {
    using namespace globemesh::python;
    m.doc() = "globemesh's library: see the package globemesh";
    m.attr("__version__") = GLOBEMESH_VERSION;
    register_errors(m);
    gdal_warning_class() = py::reinterpret_steal<py::object>(
        PyErr_NewException("globemesh._globemesh.GdalWarning", PyExc_UserWarning, nullptr));
    m.attr("GdalWarning") = gdal_warning_class();
    mesh_warning_class() = py::reinterpret_steal<py::object>(
        PyErr_NewException("globemesh._globemesh.MeshWarning", PyExc_UserWarning, nullptr));
    m.attr("MeshWarning") = mesh_warning_class();
    bind_result(m);
    m.def("mesh_keywords", &mesh_keywords);
    // For the tests: a GDAL warning raised during a run, as a reader's would be.
    m.def("_gdal_warning_in_a_run", [](const std::string &message) {
        ProgressBridge bridge{py::none()};
        run_without_gil(bridge, [&](const globemesh::Progress &) {
            CPLError(CE_Warning, CPLE_AppDefined, "%s", message.c_str());
            return true;
        });
    });
    m.def("mesh_ocean", &mesh_ocean_args, py::arg("args"), py::arg("progress") = py::none());
    m.def("triangulate", &triangulate_arrays, py::arg("lon"), py::arg("lat"),
          py::arg("progress") = py::none());
}
