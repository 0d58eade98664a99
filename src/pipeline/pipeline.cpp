// mesh_ocean(): the one function that calls every module, in the order of DESIGN.md's flow.
#include "globemesh/pipeline.hpp"

#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include "globemesh/bathymetry.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/sizefield.hpp"

namespace globemesh {

namespace {

using Clock = std::chrono::steady_clock;

class StageClock {
public:
    explicit StageClock(StageTimings* t) : timings_(t) {}
    void lap(const std::string& name) {
        auto now = Clock::now();
        if (timings_) timings_->add(name, std::chrono::duration<double>(now - last_).count());
        last_ = now;
    }
    /// Starts the next lap now, for a stage timed elsewhere.
    void restart() { last_ = Clock::now(); }

private:
    StageTimings* timings_;
    Clock::time_point last_ = Clock::now();
};

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

} // namespace

Mesh mesh_ocean(const MeshOptions& o, const Progress& progress, StageTimings* timings) {
    validate(o);
    if (o.coast.empty()) throw UsageError("--coast is required: a land polygon or coastline file (any OGR source)");
    StageClock clock(timings);

    CoastData coast = load_coast(o, sub_progress(progress, 0.0, 0.1));
    clock.lap("read_coast");

    std::optional<Raster> bathy;
    if (!o.bathy.empty()) bathy = read_bathymetry(o, sub_progress(progress, 0.1, 0.15));
    clock.lap("read_bathy");

    // --hmax alone is a uniform field: no background grid needed.
    const bool uniform = o.coast_size_km == 0 && o.wavelength == 0 && o.slope == 0 && o.size_regions.empty();
    SizeFn size;
    SizeField field;
    if (uniform) {
        size = uniform_size(std::max(o.hmax_km, o.hmin_km));
    } else {
        // A background grid of 2^22 nodes (about 10 km at the equator globally) builds in a few
        // seconds; regional grids are finer for the same count.
        field = build_size_field(o, bathy ? &*bathy : nullptr, &coast.rings,
                                 sub_progress(progress, 0.15, 0.25), std::size_t{1} << 22);
        size = field.function();
    }
    clock.lap("size_field");

    CoastReport coast_report;
    Boundary boundary = shape_boundary(coast, size, o, &coast_report, sub_progress(progress, 0.25, 0.3));
    clock.lap("boundary");

    MesherOptions mo;
    mo.max_nodes = o.max_nodes;
    mo.smooth_iterations = o.smooth_iterations;
    mo.keep_inland_seas = o.keep_inland_seas;
    mo.seed = o.seed;
    MesherReport report;
    StageTimings mesher_times;
    auto mesh_start = Clock::now();
    Mesh mesh = mesh_boundary(boundary, size, mo, &report, sub_progress(progress, 0.3, 0.97), &mesher_times);
    double mesh_seconds = std::chrono::duration<double>(Clock::now() - mesh_start).count();
    clock.restart();
    if (timings) {
        for (auto& s : mesher_times.stages) timings->stages.push_back(s);
        timings->add("mesh", mesh_seconds);
    }

    if (bathy) {
        Field depth{"depth", "sea floor depth below mean sea level", "m",
                    "sea_floor_depth_below_mean_sea_level", {}};
        depth.values.reserve(mesh.nodes.size());
        for (const Vec3& p : mesh.nodes) depth.values.push_back(bathy->depth_m(p));
        mesh.node_fields.insert(mesh.node_fields.begin(), std::move(depth));
    }

    auto& a = mesh.attributes;
    a.emplace_back("coast_file", o.coast);
    a.emplace_back("coast_layer", coast.layer);
    if (!o.bathy.empty()) a.emplace_back("bathymetry_file", o.bathy);
    a.emplace_back("boundary_rings", std::to_string(coast_report.rings));
    a.emplace_back("boundary_nodes", std::to_string(coast_report.nodes));
    a.emplace_back("islands_removed", std::to_string(coast_report.islands_removed));
    a.emplace_back("lakes_removed", std::to_string(coast_report.lakes_removed));
    a.emplace_back("ocean_area_km2", number(coast_report.ocean_area_km2));
    a.emplace_back("segments_split", std::to_string(report.segments_split + report.encroached_splits));
    a.emplace_back("sharp_coast_corners", std::to_string(report.sharp_corners));
    a.emplace_back("faces_at_sharp_corners", std::to_string(report.sharp_corner_faces));
    std::ostringstream comps;
    for (const auto& c : report.components) comps << (comps.tellp() ? "; " : "") << number(c.area_km2) << " km2 " << (c.kept ? "kept" : "dropped");
    a.emplace_back("ocean_components", comps.str());
    return mesh;
}

} // namespace globemesh
