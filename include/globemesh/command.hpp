// globemesh/command.hpp: the command line's `mesh` and `triangulate` runs and its choice of
// outputs, for bindings (the Python module) that must take the same options, give the same
// messages and write the same files as `globemesh` without its terminal. Implemented in
// libglobemesh_cli.a (globemesh::cli), over the command line's own option parser.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/mesh.hpp"
#include "globemesh/mesh_stats.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh::command {

/// An option of `globemesh mesh` that mesh() takes: all but the outputs and the terminal's.
struct Keyword {
    std::string name; ///< the long option name with '_' for '-' (coast_layer)
    bool flag;        ///< takes no value (keep_inland_seas)
    int values;       ///< how many values it takes (4 for region)
};

/// The options mesh() takes, in the order `globemesh help mesh` lists them.
std::vector<Keyword> mesh_keywords();

/// A finished run: the mesh and what writing it as the command line does needs.
struct Run {
    Mesh mesh;
    MeshStats stats;
    std::string report_json; ///< the command line's --report JSON
    std::string history;     ///< the files' `history` attribute
    std::string land;        ///< the coast a preview draws under the mesh ("": none)
    std::optional<std::array<double, 4>> extent_deg; ///< a preview's extent (the region)
    /// The run's input files by keyword (coast, bathy, ...), absolute where they are files: no
    /// write replaces one, whatever the directory by then.
    std::vector<std::pair<std::string, std::string>> inputs;
    /// The command line's warnings about the run (its "globemesh: warning: ..." lines on stderr,
    /// without that prefix): straits closed, a region's ocean in pieces, nodes above sea level.
    std::vector<std::string> warnings;
    std::string title; ///< the files' title ("": the writers' own, an ocean mesh's)
};

/// `globemesh mesh ARGS` without outputs: ARGS parsed by the command line's parser ("--hmax=50km",
/// --passages default resolved), checked, meshed (with --check's invariants when asked). Throws
/// the library's errors with the command line's checks (UsageError for a bad option, IoError for
/// an input that cannot be read).
Run mesh(std::span<const std::string> args, const Progress &progress);

/// The spherical Delaunay triangulation of `points`, as `globemesh triangulate` makes it.
Run triangulate(std::vector<Vec3> points, const Progress &progress);

/// What `-o PATH... [-f FORMAT] [--co KEY=VALUE]... [--output-srs CRS] [--overwrite]` asks.
struct Outputs {
    std::vector<std::string> paths;
    std::string format;                ///< "": from each path's extension
    std::vector<std::string> creation; ///< KEY=VALUE
    bool overwrite = false;
    std::string output_srs;
};

/// Writes the run's mesh to `outputs` by the command line's writers, after its checks (formats,
/// options, files: UsageError or IoError with its messages): all or, on an error or a cancel, none.
void write(const Run &run, const Outputs &outputs, const Progress &progress);

/// The one line the command line prints for a library error (options named by their flags).
std::string error_message(const Error &e);

/// The arrays the UGRID file holds beside the nodes and faces, computed by its writer's code.
struct Arrays {
    std::vector<double> lon, lat;                      ///< of the nodes, degrees
    std::vector<std::array<std::int32_t, 2>> edges;    ///< mesh_edge_nodes
    std::vector<std::int32_t> edge_tags;               ///< boundary_tag of every edge
    std::vector<std::array<std::int32_t, 2>> boundary; ///< mesh_boundary_nodes
    std::vector<std::int32_t> boundary_tags;           ///< the tag of each of them
    std::vector<double> quality, area_m2;              ///< per face: quality, geodesic area (m2)
};

/// The arrays of `mesh` as the UGRID file numbers them.
Arrays ugrid_arrays(const Mesh &mesh);

} // namespace globemesh::command
