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

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesh_stats.hpp"
#include "globemesh/pipeline.hpp"
#include "mesh_summary.hpp"
#include "option_flags.hpp"
#include "progress_bridge.hpp"
#include "result.hpp"

namespace globemesh::python {

namespace {

/// Whether mesh_ocean() takes this option of `globemesh mesh`: all but the outputs (those are
/// Result.write's) and the terminal's.
bool python_takes(const CLI::Option &option) {
    const std::string name = option.get_lnames().empty() ? "" : option.get_lnames().front();
    return option.get_group() != "Output" && !name.empty() && name != "help" && name != "version" &&
           name != "quiet" && name != "verbose" && name != "print-config";
}

/// (keyword, is a flag, values it takes) of each option mesh_ocean() takes, keywords as the
/// long option names with '_' for '-'.
std::vector<std::tuple<std::string, bool, int>> mesh_keywords() {
    cli::MeshCommand command;
    std::vector<std::tuple<std::string, bool, int>> keywords;
    for (const CLI::Option *option : command.app.get_options()) {
        if (!python_takes(*option))
            continue;
        std::string name = option->get_lnames().front();
        std::replace(name.begin(), name.end(), '-', '_');
        keywords.emplace_back(name, option->get_expected_max() == 0, option->get_expected_max());
    }
    return keywords;
}

/// The inputs that must be readable files, as `globemesh mesh` checks them before any run.
void check_inputs(const CliOptions &o) {
    if (o.mesh.coast.empty())
        throw UsageError(
            "--coast is required: land polygons or coast lines, e.g. --coast land.gpkg");
    const std::pair<std::string, std::string> inputs[] = {{"--coast", o.mesh.coast},
                                                          {"--bathy", o.mesh.bathy},
                                                          {"--region-file", o.mesh.region_file},
                                                          {"--size-regions", o.mesh.size_regions},
                                                          {"--config", o.config}};
    for (const auto &[name, path] : inputs)
        cli::check_input_path(path, name);
}

/// The run's mesh, checked when --check asks, with its statistics in `stats`.
OceanMesh mesh_and_check(const CliOptions &o, const Progress &progress, StageTimings &timings,
                         MeshStats &stats) {
    OceanMesh run = mesh_ocean(o.mesh, progress, &timings);
    if (o.check) {
        const auto problems = check_mesh(run.mesh);
        if (!problems.empty())
            throw DataError("--check: the mesh breaks " + std::to_string(problems.size()) +
                            (problems.size() >= 20 ? "+" : "") + " invariants, first: " +
                            problems.front() + "; please report this with the command line");
    }
    stats = compute_stats(run.mesh);
    return run;
}

/// mesh_ocean(args, progress): `args` are those of `globemesh mesh` without outputs.
std::shared_ptr<PyMesh> mesh_ocean_args(const std::vector<std::string> &args, py::object callback) {
    cli::MeshCommand command;
    try {
        command.parse(args);
    } catch (const CLI::ParseError &e) {
        throw UsageError(cli::usage_text(e, "mesh"));
    }
    const CliOptions &o = command.o;
    validate(o.mesh);
    check_inputs(o);
    auto result = std::make_shared<PyMesh>();
    StageTimings timings;
    const auto t0 = std::chrono::steady_clock::now();
    ProgressBridge bridge(std::move(callback));
    OceanMesh run = run_without_gil(bridge, [&](const Progress &progress) {
        return mesh_and_check(o, progress, timings, result->stats);
    });
    // The effective configuration travels with the mesh, as the command line's files carry it.
    run.mesh.attributes.emplace_back(
        "globemesh_configuration", cli::file_configuration(command.app.config_to_str(true, false)));
    result->history = cli::history_text("mesh", args);
    cli::MeshRunSummary summary{o, {}, result->stats, run, timings, result->history};
    summary.total_s = cli::seconds_since(t0);
    summary.peak = cli::peak_memory_bytes();
    result->report_json = cli::report_json(summary);
    result->land = o.mesh.coast;
    result->extent_deg = o.mesh.region;
    result->mesh = std::move(run.mesh);
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
    result->mesh = run_without_gil(bridge, [&](const Progress &progress) {
        Mesh mesh = triangulate_points(std::move(points), TriangulateOptions{}, progress);
        result->stats = compute_stats(mesh);
        return mesh;
    });
    result->history = cli::history_text("triangulate", std::vector<std::string>{"(Python)"});
    result->report_json = "{\"mesh\": " + cli::stats_json(result->stats, "") + "}";
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
            usage(cli::one_line(e.message(cli::flag_of)).c_str());
        } catch (const IoError &e) {
            io(cli::one_line(e.message(cli::flag_of)).c_str());
        } catch (const DataError &e) {
            data(cli::one_line(e.message(cli::flag_of)).c_str());
        } catch (const Error &e) {
            base(cli::one_line(e.message(cli::flag_of)).c_str());
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
    bind_result(m);
    m.def("mesh_keywords", &mesh_keywords);
    m.def("mesh_ocean", &mesh_ocean_args, py::arg("args"), py::arg("progress") = py::none());
    m.def("triangulate", &triangulate_arrays, py::arg("lon"), py::arg("lat"),
          py::arg("progress") = py::none());
}
