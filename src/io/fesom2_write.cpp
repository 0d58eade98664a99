// FESOM2 mesh writer (the FESOM2 row of writers.cpp): the folder -o names, with the three files
// FESOM2's mesh partitioner and model read (FESOM2 src/oce_mesh.F90, read_mesh; the FESOM2
// documentation, "Meshes"), each read there list-directed, a record a line:
//   nod2d.out   the node count; then "id lon lat flag" a node a line, 1-based, lon/lat degrees,
//               flag 0 for a wet (interior) node, 1 on the closed boundary (coast), 2 on an open
//               boundary. A node where coast and open edges meet takes 2 (as our .cli does).
//   elem2d.out  the element count; then the three 1-based nodes of each triangle,
//               counter-clockwise.
//   aux3d.out   the number of levels; the levels (metres, written negative: read_mesh negates
//               positive ones); then one depth a node, negative below sea level ("deps must be
//               negative"). read_mesh reads a positive value as a depth too, so a node at or
//               above sea level is written 0 rather than as its height; FESOM2 then deepens it
//               to its fifth level, as it does every node shallower than that.
// The levels are the 48 of FESOM2's CORE2 mesh unless the creation option LEVELS gives others.
// Coordinates are io::node_lonlats': [-180, 180), or [0, 360) for a region across the
// antimeridian. A FESOM2 mesh needs aux3d.out, so the format needs depths (Writer::needs).
//
// The folder is created when missing (its parent must exist) and handed to the run's
// OutputBatch, which removes it again if the run fails; the three files appear together.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "model_coordinates.hpp"
#include "text_out.hpp"

namespace globemesh {

std::string fesom2_levels_problem(const std::string &levels);

namespace {

namespace fs = std::filesystem;
using io::TextOut;

constexpr std::size_t report_every = 1 << 16;

/// The level depths (metres, positive down) of FESOM2's CORE2 mesh.
const std::vector<double> core2_levels = {
    0,    5,    10,   20,   30,   40,   50,   60,   70,   80,   90,   100,  115,  135,  160,  190,
    230,  280,  340,  410,  490,  580,  680,  790,  910,  1040, 1180, 1330, 1500, 1700, 1920, 2150,
    2400, 2650, 2900, 3150, 3400, 3650, 3900, 4150, 4400, 4650, 4900, 5150, 5400, 5650, 6000, 6250};

/// The levels of a LEVELS value ("0,10,25,..."), empty when it is not at least 3 (read_mesh
/// stops with fewer) depths from 0 and increasing.
std::vector<double> parse_levels(const std::string &text) {
    std::vector<double> r;
    std::istringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        std::size_t used = 0;
        try {
            r.push_back(std::fabs(std::stod(item, &used)));
        } catch (const std::exception &) {
            return {};
        }
        if (item.find_first_not_of(" ", used) != std::string::npos || !std::isfinite(r.back()))
            return {};
    }
    const bool ok = r.size() >= 3 && r.front() == 0 &&
                    std::adjacent_find(r.begin(), r.end(), std::greater_equal<>()) == r.end();
    return ok ? r : std::vector<double>{};
}

/// The LEVELS creation option's levels (checked when the run was planned), or the CORE2 ones.
std::vector<double> levels(const WriteOptions &options, const fs::path &path) {
    const std::string text = creation_option(options.creation_options, "LEVELS");
    if (text.empty())
        return core2_levels;
    std::vector<double> r = parse_levels(text);
    if (r.empty())
        throw UsageError("FESOM2 output " + path.string() + ": LEVELS=" + text + ": " +
                         fesom2_levels_problem(text));
    return r;
}

/// Creates `folder` when it is missing (its parent must exist); true when it did.
bool make_folder(const fs::path &folder) {
    std::error_code ec;
    if (fs::is_directory(folder, ec))
        return false;
    const std::string what = "FESOM2 output " + folder.string();
    if (fs::exists(folder, ec))
        throw IoError(what + " is a file; FESOM2 writes a folder of files: give a folder name");
    const fs::path named = folder.has_filename() ? folder : folder.parent_path(); // "dir/"
    const fs::path parent = named.parent_path().empty() ? fs::path(".") : named.parent_path();
    if (!fs::is_directory(parent, ec))
        throw IoError(what + ": the folder " + parent.string() +
                      " does not exist; create it first");
    if (!fs::create_directory(folder, ec))
        throw IoError(what + ": cannot create the folder (" + ec.message() + ")");
    return true;
}

/// 0 interior, 1 coast, 2 open: the FESOM2 flag of each node, from the boundary edges' tags.
std::vector<unsigned char> node_flags(const Mesh &mesh) {
    const auto topology = io::topology_of(mesh);
    const io::MeshTopology &topo = *topology;
    std::vector<unsigned char> flags(mesh.nodes.size(), 0);
    for (std::size_t i = 0; i < topo.boundary_edges.size(); ++i) {
        const unsigned char flag = topo.boundary_tags[i] == int(EdgeTag::open) ? 2 : 1;
        for (auto v : topo.edge_nodes(std::size_t(topo.boundary_edges[i])))
            flags[std::size_t(v)] = std::max(flags[std::size_t(v)], flag);
    }
    return flags;
}

void write_nodes(const Mesh &mesh, const fs::path &temp, const fs::path &target,
                 const Progress &progress) {
    const std::vector<unsigned char> flags = node_flags(mesh);
    const std::vector<LonLat> p = io::node_lonlats(mesh);
    TextOut out(temp, target, "FESOM2 output");
    out.integer(p.size()).line();
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (i % report_every == 0)
            report(progress, double(i) / double(p.size()), "write_fesom2");
        out.integer(i + 1).text(" ").real(p[i].lon).text(" ").real(p[i].lat).text(" ");
        out.integer(flags[i]).line();
    }
    out.close();
}

void write_elements(const Mesh &mesh, const fs::path &temp, const fs::path &target,
                    const Progress &progress) {
    TextOut out(temp, target, "FESOM2 output");
    out.integer(mesh.faces.size()).line();
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        if (f % report_every == 0)
            report(progress, double(f) / double(mesh.faces.size()), "write_fesom2");
        const auto &face = mesh.faces[f];
        out.integer(face[0] + 1).text(" ").integer(face[1] + 1).text(" ");
        out.integer(face[2] + 1).line();
    }
    out.close();
}

void write_depths(const Field &depth, const std::vector<double> &levels, const fs::path &temp,
                  const fs::path &target, const Progress &progress) {
    TextOut out(temp, target, "FESOM2 output");
    out.integer(levels.size()).line();
    for (double z : levels)
        out.real(z > 0 ? -z : 0.0).line();
    for (std::size_t i = 0; i < depth.values.size(); ++i) {
        if (i % report_every == 0)
            report(progress, double(i) / double(depth.values.size()), "write_fesom2");
        const double d = depth.values[i];
        out.real(d > 0 ? -d : 0.0).line(); // at or above sea level: 0 (see the top)
    }
    out.close();
}

} // namespace

/// What is wrong with a LEVELS creation option, or "" (the FESOM2 row's check, writers.cpp).
std::string fesom2_levels_problem(const std::string &levels) {
    return parse_levels(levels).empty() ? "give at least 3 level depths in metres, from 0 and "
                                          "increasing, e.g. LEVELS=0,10,25,50,100"
                                        : "";
}

/// The FESOM2 row of the writers table (writers.cpp): nod2d.out, elem2d.out and aux3d.out in the
/// folder `path`.
void write_as_fesom2(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    const std::vector<double> z = levels(options, path);
    const Field *depth = mesh.node_field("depth");
    if (depth == nullptr)
        throw DataError("FESOM2 output " + path.string() +
                        " needs depths, and the mesh has none (mesh with a bathymetry)");
    io::require_depths(*depth, "FESOM2 output " + path.string());
    // A folder this call makes goes again if the run fails: the batch's task when one is alive,
    // else this guard's until the files are in place.
    const bool created = make_folder(path);
    struct Made {
        fs::path folder;
        bool own;
        ~Made() {
            std::error_code ec;
            if (own)
                fs::remove(folder, ec);
        }
    } made{path, created && !OutputBatch::adopt_folder(path)};
    {
        OutputFile nodes(path / "nod2d.out", options.overwrite, "FESOM2 output");
        OutputFile elements(path / "elem2d.out", options.overwrite, "FESOM2 output");
        OutputFile depths(path / "aux3d.out", options.overwrite, "FESOM2 output");
        const double n = double(mesh.nodes.size()), f = double(mesh.faces.size());
        const double total = 2 * n + f + 1;
        write_nodes(mesh, nodes.temp_path(), nodes.target(),
                    sub_progress(options.progress, 0, n / total));
        write_elements(mesh, elements.temp_path(), elements.target(),
                       sub_progress(options.progress, n / total, (n + f) / total));
        write_depths(*depth, z, depths.temp_path(), depths.target(),
                     sub_progress(options.progress, (n + f) / total, 1));
        // Under the run's batch the three wait for its other outputs; alone, they appear
        // together now.
        std::unique_ptr<OutputBatch> alone =
            OutputBatch::active() ? nullptr : std::make_unique<OutputBatch>();
        nodes.commit();
        elements.commit();
        depths.commit();
        if (alone)
            alone->commit();
    }
    made.own = false;
    report(options.progress, 1, "write_fesom2");
}

} // namespace globemesh
