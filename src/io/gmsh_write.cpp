// The gmsh MSH writer (the GMSH row of writers.cpp): MSH 4.1 ASCII, or 2.2 by MSH_VERSION=2.2.
//
// The file holds the nodes, the faces as triangles of the physical group "ocean" (2-D) and the
// boundary edges as lines of the groups "coast" and "open" (1-D), with the boundary tags of the
// topology the UGRID writer uses; a group without elements is left out (a global mesh has no
// "open"). Physical tags are fixed so that model scripts can use the numbers: coast 1, open 2,
// ocean 3. With OPEN_GROUPS=YES each open boundary is its own group instead of "open": open_1,
// open_2... (tags 4, 5...), in the order of the ADCIRC writer's open strings. In 4.1 the entities
// are the discrete curves 1 (coast) and 2 (open; open_k: 1 + k) and the surface 1 (ocean), which
// holds every node. The depth, when the mesh has one, follows as $NodeData "depth" (metres,
// positive down). Coordinates: lon/lat degrees (z = 0) as the other model formats place them
// (longitudes in [0, 360) for a region across 180); with COORDS=SPHERE, x y z in metres on the
// sphere of RADIUS; with an --output-srs (WriteOptions), x y in that CRS (z = 0), whose WKT ends
// the file as seamsh writes it, a section "$Projection" of two lines, "WKT" and the WKT, which
// gmsh keeps as the model attribute "Projection". Written as it goes through a buffer of 1 MiB.
#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "buffered_file.hpp"
#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"
#include "globemesh/writers.hpp"
#include "mesh_topology.hpp"
#include "model_coordinates.hpp"

namespace globemesh {

namespace {

namespace fs = std::filesystem;

constexpr int coast_group = 1, open_group = 2, ocean_group = 3;
constexpr int ocean_surface = 1;
constexpr std::size_t report_every = 1 << 16;

/// The creation options as the writer uses them.
struct MshChoices {
    bool v22 = false;
    bool sphere = false;
    bool open_groups = false;
    double radius = 6371000;
};

MshChoices msh_choices(const CreationOptions &options, const fs::path &path) {
    MshChoices c;
    c.v22 = creation_option(options, "MSH_VERSION", "4.1") == "2.2";
    c.sphere = creation_option(options, "COORDS", "LONLAT") == "SPHERE";
    c.open_groups = creation_option(options, "OPEN_GROUPS", "NO") == "YES";
    const std::string radius = creation_option(options, "RADIUS");
    if (radius.empty())
        return c;
    const char *end = radius.data() + radius.size();
    auto [at, ec] = std::from_chars(radius.data(), end, c.radius);
    if (ec != std::errc() || at != end || !std::isfinite(c.radius) || c.radius <= 0)
        throw UsageError(path.string() + ": GMSH creation option RADIUS=" + radius +
                         ": give the sphere's radius in metres, e.g. RADIUS=6371000");
    if (!c.sphere)
        throw UsageError(path.string() + ": GMSH creation option RADIUS=" + radius +
                         " is for COORDS=SPHERE (lon/lat output has no radius)");
    return c;
}

/// Text through a buffer, numbers formatted with to_chars (shortest text that reads back to the
/// same double).
class MshStream {
public:
    MshStream(const fs::path &temp, const fs::path &target) : file_(temp, target, "gmsh output") {}
    MshStream &operator<<(std::string_view s) {
        file_.put(s);
        return *this;
    }
    MshStream &operator<<(char c) {
        file_.put({&c, 1});
        return *this;
    }
    MshStream &operator<<(double v) { return number(v); }
    MshStream &operator<<(std::size_t v) { return number(v); }
    MshStream &operator<<(int v) { return number(v); }
    /// Writes what is left and closes the file; throws IoError on a failed write.
    void close() { file_.close(); }

private:
    template <class T> MshStream &number(T v) {
        char text[32];
        file_.put({text, std::to_chars(text, text + sizeof text, v).ptr});
        return *this;
    }
    io::BufferedFile file_;
};

/// A discrete curve of the file: its entity and physical tags, its group name and its boundary
/// edges (indices into topology's boundary_edges).
struct Curve {
    int entity = 0, physical = 0;
    std::string name;
    std::vector<std::size_t> edges;
};

/// The curves with edges: coast (entity 1), then open (entity 2) or, with open_groups, each open
/// boundary (entities 2, 3...; physical tags 4, 5...: after ocean's) in the order of the ADCIRC
/// open strings, its edges in walking order.
std::vector<Curve> boundary_curves(const io::MeshTopology &topo, std::size_t node_count,
                                   bool open_groups) {
    Curve coast{1, coast_group, "coast", {}}, open{2, open_group, "open", {}};
    for (std::size_t b = 0; b < topo.boundary_edges.size(); ++b)
        (topo.boundary_tags[b] == int(EdgeTag::open) ? open : coast).edges.push_back(b);
    std::vector<Curve> curves;
    if (!coast.edges.empty())
        curves.push_back(std::move(coast));
    if (!open_groups) {
        if (!open.edges.empty())
            curves.push_back(std::move(open));
        return curves;
    }
    int k = 0;
    for (const auto &loop : io::boundary_loops(topo, node_count))
        for (const io::BoundaryRun &run : io::loop_runs(topo, loop)) {
            if (run.tag != int(EdgeTag::open))
                continue;
            ++k;
            Curve c{1 + k, ocean_group + k, "open_" + std::to_string(k), {}};
            for (std::size_t i = 0; i < run.count; ++i)
                c.edges.push_back(loop[(run.first + i) % loop.size()]);
            curves.push_back(std::move(c));
        }
    return curves;
}

/// What the writer writes of one mesh, in order.
class MshWriter {
public:
    MshWriter(const Mesh &mesh, const io::MeshTopology &topo, MshChoices choices,
              const io::ModelCoordinates *xy, MshStream &out, const Progress &progress)
        : mesh_(mesh), topo_(topo), c_(choices), xy_(xy), out_(out), progress_(progress) {
        curves_ = boundary_curves(topo, mesh.nodes.size(), choices.open_groups);
        depth_ = mesh.node_field("depth");
        total_ = double(mesh.nodes.size()) * (depth_ ? 2 : 1) + double(mesh.faces.size()) +
                 double(topo.boundary_edges.size()) + 1;
    }

    void write() {
        out_ << "$MeshFormat\n" << (c_.v22 ? "2.2" : "4.1") << " 0 8\n$EndMeshFormat\n";
        physical_names();
        if (!c_.v22)
            entities();
        nodes();
        elements();
        if (depth_)
            node_data();
        if (xy_ && xy_->crs) // as seamsh writes it: gmsh keeps the section as a model attribute
            out_ << "$Projection\nWKT\n" << xy_->crs->wkt << "\n$EndProjection\n";
        report(progress_, 1.0, "write_gmsh");
    }

private:
    std::array<double, 3> point(std::size_t i) const {
        const Vec3 &v = mesh_.nodes[i];
        if (c_.sphere)
            return {c_.radius * v.x, c_.radius * v.y, c_.radius * v.z};
        return {xy_->x[i], xy_->y[i], 0.0};
    }

    void tick() {
        if (++done_ % report_every == 0)
            report(progress_, double(done_) / total_, "write_gmsh");
    }

    void physical_names() {
        out_ << "$PhysicalNames\n" << curves_.size() + 1 << '\n';
        for (const Curve &c : curves_)
            out_ << "1 " << c.physical << " \"" << c.name << "\"\n";
        out_ << "2 " << ocean_group << " \"ocean\"\n$EndPhysicalNames\n";
    }

    /// Writes the bounding box of the nodes for which keep(i) holds.
    template <class Keep> void box(Keep keep) {
        constexpr double inf = std::numeric_limits<double>::infinity();
        std::array<double, 3> lo{inf, inf, inf}, hi{-inf, -inf, -inf};
        auto add = [&](std::size_t i) {
            const auto p = point(i);
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], p[k]);
                hi[k] = std::max(hi[k], p[k]);
            }
        };
        keep(add);
        for (double v : lo)
            out_ << v << ' ';
        for (double v : hi)
            out_ << v << ' ';
    }

    void entities() {
        out_ << "$Entities\n0 " << curves_.size() << " 1 0\n";
        for (const Curve &c : curves_) {
            out_ << c.entity << ' ';
            box([&](auto add) {
                for (auto b : c.edges)
                    for (auto n : topo_.edge_nodes(std::size_t(topo_.boundary_edges[b])))
                        add(std::size_t(n));
            });
            out_ << "1 " << c.physical << " 0\n";
        }
        out_ << ocean_surface << ' ';
        box([&](auto add) {
            for (std::size_t i = 0; i < mesh_.nodes.size(); ++i)
                add(i);
        });
        out_ << "1 " << ocean_group << ' ' << curves_.size();
        for (const Curve &c : curves_)
            out_ << ' ' << c.entity;
        out_ << "\n$EndEntities\n";
    }

    void nodes() {
        const std::size_t n = mesh_.nodes.size();
        out_ << "$Nodes\n";
        if (c_.v22) {
            out_ << n << '\n';
        } else {
            // One block, the ocean surface's, holding every node.
            out_ << "1 " << n << " 1 " << n << '\n';
            out_ << "2 " << ocean_surface << " 0 " << n << '\n';
            for (std::size_t i = 1; i <= n; ++i)
                out_ << i << '\n';
        }
        for (std::size_t i = 0; i < n; ++i) {
            const auto p = point(i);
            if (c_.v22)
                out_ << i + 1 << ' ';
            out_ << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
            tick();
        }
        out_ << "$EndNodes\n";
    }

    void elements() {
        const std::size_t nf = mesh_.faces.size();
        const std::size_t total = nf + topo_.boundary_edges.size();
        const std::size_t blocks = 1 + curves_.size();
        out_ << "$Elements\n";
        if (c_.v22)
            out_ << total << '\n';
        else
            out_ << blocks << ' ' << total << " 1 " << total << '\n'
                 << "2 " << ocean_surface << " 2 " << nf << '\n';
        std::size_t tag = 0;
        for (const auto &face : mesh_.faces) {
            out_ << ++tag;
            if (c_.v22)
                out_ << " 2 2 " << ocean_group << ' ' << ocean_surface;
            for (NodeIndex v : face)
                out_ << ' ' << std::size_t(v) + 1;
            out_ << '\n';
            tick();
        }
        for (const Curve &c : curves_) {
            if (!c_.v22)
                out_ << "1 " << c.entity << " 1 " << c.edges.size() << '\n';
            for (auto b : c.edges) {
                const auto ends = topo_.edge_nodes(std::size_t(topo_.boundary_edges[b]));
                out_ << ++tag;
                if (c_.v22)
                    out_ << " 1 2 " << c.physical << ' ' << c.entity;
                out_ << ' ' << std::size_t(ends[0]) + 1 << ' ' << std::size_t(ends[1]) + 1 << '\n';
                tick();
            }
        }
        out_ << "$EndElements\n";
    }

    void node_data() {
        const std::size_t n = mesh_.nodes.size();
        out_ << "$NodeData\n1\n\"depth\"\n1\n0\n3\n0\n1\n" << n << '\n';
        for (std::size_t i = 0; i < n; ++i) {
            out_ << i + 1 << ' ' << depth_->values[i] << '\n';
            tick();
        }
        out_ << "$EndNodeData\n";
    }

    const Mesh &mesh_;
    const io::MeshTopology &topo_;
    MshChoices c_;
    const io::ModelCoordinates *xy_;
    MshStream &out_;
    const Progress &progress_;
    const Field *depth_ = nullptr;
    std::vector<Curve> curves_;
    double total_ = 1;
    std::size_t done_ = 0;
};

} // namespace

void write_as_gmsh(const Mesh &mesh, const fs::path &path, const WriteOptions &options) {
    const MshChoices choices = msh_choices(options.creation_options, path);
    // In lon/lat as the other model formats place them (node_lonlats: in [0, 360) where that
    // spares every face a cut at the seam, as for a region across 180), or in --output-srs
    // (write_outputs' check_output_srs refuses it with COORDS=SPHERE).
    std::optional<io::ModelCoordinates> xy;
    if (!choices.sphere)
        xy = io::model_coordinates(mesh, options.output_srs, "gmsh output " + path.string());
    OutputFile out(path, options.overwrite, "gmsh output");
    const auto topology = io::topology_of(mesh);
    const io::MeshTopology &topo = *topology;
    {
        MshStream stream(out.temp_path(), path);
        MshWriter(mesh, topo, choices, xy ? &*xy : nullptr, stream, options.progress).write();
        stream.close();
    }
    out.commit();
}

} // namespace globemesh
