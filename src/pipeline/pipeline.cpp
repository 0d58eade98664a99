// mesh_ocean(): the one function that calls every module, in the order of DESIGN.md's flow.
#include "globemesh/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cmath>
#include <optional>
#include <sstream>
#include <vector>

#include "coast/geos_interrupt.hpp"
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

/// Largest background grid of the size field: 2^22 nodes (about 10 km at the equator
/// globally) builds in a few seconds; regional grids are finer for the same count.
constexpr std::size_t size_grid_max_nodes = std::size_t{1} << 22;

/// Peak bytes per node of the background grid while it is built (sizefield/grid.cpp): the
/// values, the coast distance's keys, nearest sources, flags and distances, the gradation's
/// copy, flags and heap, the depths; 44 counted, rounded up.
constexpr std::uint64_t size_grid_bytes_per_node = 64;

/// Bytes per node of the full-resolution coast rings (a Vec3 and its segment tag, with the
/// vector's slack). They are freed once the boundary is shaped, before meshing, but the budget
/// still counts them there: it errs on the safe side.
constexpr std::uint64_t ring_bytes_per_node = 40;

/// Bytes per vertex of the land test (LandMask) while meshing: GEOS coordinates (24), the
/// prepared polygons' segment index, the outline as unit vectors (24) and its pieces' envelopes,
/// rounded up; its cells come on top (LandMask::cell_bytes).
constexpr std::uint64_t land_bytes_per_vertex = 100;

/// Upper bound of the background grid's node count (make_background_grid: spacing hfloor / 2,
/// the region plus a cell of margin, at most size_grid_max_nodes).
double size_grid_nodes(const MeshOptions& o) {
    const double hfloor = size_floor_km(o);
    const double spacing = std::max(1e-6, 0.5 * hfloor / earth_radius_km * rad_to_deg);
    double lon_span = 360, lat_span = 180;
    if (o.region) {
        const auto& r = *o.region;
        lon_span = std::min(360.0, (r[2] > r[0] ? r[2] - r[0] : r[2] - r[0] + 360) + 2 * spacing);
        lat_span = std::min(180.0, r[3] - r[1] + 2 * spacing);
    }
    const double nodes = (std::ceil(lon_span / spacing) + 1) * (std::ceil(lat_span / spacing) + 1);
    return std::min(nodes, static_cast<double>(size_grid_max_nodes));
}

/// The --max-memory budget: what the stages already hold, and a check before each large
/// allocation. The budget never changes a result; it only refuses, naming the stage.
class MemoryBudget {
public:
    explicit MemoryBudget(std::uint64_t total) : total_(total) {}
    void hold(double bytes) { held_ += bytes; }
    /// Bytes left for the next stages (0: the budget is spent); meaningless without a budget.
    std::uint64_t left() const { return held_ >= static_cast<double>(total_) ? 0 : total_ - static_cast<std::uint64_t>(held_); }
    /// Throws DataError when `bytes` more do not fit; `what` says what needs them.
    void require(double bytes, const std::string& what, const std::string& remedy) const {
        if (total_ == 0 || held_ + bytes <= static_cast<double>(total_)) return;
        throw DataError(what + " needs about " + memory_text(bytes) + ", more than the " +
                        memory_text(static_cast<double>(left())) + " left of --max-memory " +
                        memory_text(static_cast<double>(total_)) + " after reading the inputs (" +
                        memory_text(held_) + "); raise --max-memory" + remedy);
    }

private:
    std::uint64_t total_;
    double held_ = 0;
};

/// What --min-depth found and changed in the sampled depths.
struct DepthFloor {
    std::size_t above_sea_level = 0; ///< nodes with depth < 0 as sampled
    double shallowest_m = 0;         ///< the smallest sampled depth when some are < 0 (m)
    std::size_t raised = 0;          ///< nodes set to min_depth_m
};

/// Counts the depths (m, positive down) above sea level and raises those below `min_depth_m`
/// (when set) to it; no-data values (NaN) stay as they are.
DepthFloor apply_min_depth(std::vector<double>& depths, std::optional<double> min_depth_m) {
    DepthFloor f;
    for (double& d : depths) {
        if (d < 0) {
            f.shallowest_m = f.above_sea_level == 0 ? d : std::min(f.shallowest_m, d);
            ++f.above_sea_level;
        }
        if (min_depth_m && d < *min_depth_m) {
            d = *min_depth_m;
            ++f.raised;
        }
    }
    return f;
}

} // namespace

Mesh mesh_ocean(const MeshOptions& o, const Progress& run_progress, StageTimings* timings) {
    // A long GEOS operation of the coast stages stops too when the run is cancelled.
    const coast::GeosInterrupt geos_interrupt(run_progress);
    const Progress& progress = geos_interrupt.progress();
    validate(o);
    if (o.coast.empty()) throw UsageError("--coast is required: a land polygon or coastline file (any OGR source)");
    StageClock clock(timings);

    // load_coast and read_bathymetry check their own reads against --max-memory (the coast
    // counts its vertices while reading, the raster is read no finer than the mesh needs).
    MemoryBudget budget(o.max_memory_bytes);
    CoastData coast = load_coast(o, sub_progress(progress, 0.0, 0.1));
    for (const Ring& r : coast.rings.rings) budget.hold(static_cast<double>(r.nodes.size() * ring_bytes_per_node));
    clock.lap("read_coast");
    // The mesher's node estimate (nodes_for_area) with every size at --hmax (the field's
    // largest). The mesher's own estimate, over the shaped ocean and the field's sizes, is larger
    // but for the area the shaping closes (inlets, lakes; a few per mil of the global ocean), so
    // only 90% of this one is held against --max-nodes: a size far too small is refused here,
    // before the bathymetry, the size field and the coast's shaping spend minutes and gigabytes
    // on it.
    if (const double estimate = nodes_for_area(coast.ocean_area_km2, o.hmax_km);
        0.9 * estimate > static_cast<double>(o.max_nodes))
        throw DataError("the ocean (" + std::to_string(std::llround(coast.ocean_area_km2)) + " km2) takes about " +
                        std::to_string(std::llround(estimate)) + " nodes at --hmax " + number(o.hmax_km) +
                        " km, more than --max-nodes " + std::to_string(o.max_nodes) + ": raise --hmax or --max-nodes");
    // The same for the water along the coast at --coast-size: the size grows from s there at
    // rate g = min(--coast-rate, --grade) up to --hmax, and along a straight coast of length L
    // the band takes L * integral of dd / (c (s + g d)^2) = L (1/s - 1/hmax) / (c g) nodes (c h^2
    // the area of a node, nodes_for_area). The mesher counts them exactly, but only after the
    // size field and the coast's shaping, which at a size of metres take seconds to minutes.
    // Made / counted on 1:50m land at --hmax 100km: --coast-size 1km 5.22 / 6.75 million, 5km
    // 1.12 / 1.30 million, 20km 217,000 / 273,000 (bays share their bands). The source coast
    // is longer than the shaped one where the size is above its segments' mean length (the
    // shaping simplifies it), so the count is held against --max-nodes only below that length,
    // and at half its value.
    if (o.coast_size_km > 0) {
        double coast_km = 0;
        std::size_t segments = 0;
        for (const Ring& r : coast.rings.rings)
            for (std::size_t i = 0; i < r.nodes.size(); ++i)
                if (r.kinds[i] == SegmentKind::coast) {
                    coast_km += arc_km(r.nodes[i], r.nodes[(i + 1) % r.nodes.size()]);
                    ++segments;
                }
        const double floor = size_floor_km(o), s = std::clamp(o.coast_size_km, floor, o.hmax_km);
        const double rate = std::min(o.coast_rate, o.grade);
        const double estimate = rate > 0 ? nodes_for_area(coast_km * (1 / s - 1 / o.hmax_km) / rate, 1.0)
                                         : nodes_for_area(coast_km * s, s); // a band one size wide
        if (segments > 0 && s <= coast_km / double(segments) && 0.5 * estimate > static_cast<double>(o.max_nodes))
            throw DataError("the water along the coast (" + std::to_string(std::llround(coast_km)) + " km) takes about " +
                            std::to_string(std::llround(estimate)) + " nodes at --coast-size " + number(o.coast_size_km) + " km" +
                            (s > o.coast_size_km ? " (" + number(s) + " km: sizes stop at --hmin, by default --hmax / 1000)" : "") +
                            ", more than --max-nodes " + std::to_string(o.max_nodes) + ": raise --coast-size" +
                            (s > o.coast_size_km ? " and --hmin" : "") + " or --max-nodes");
    }

    std::optional<Raster> bathy;
    if (!o.bathy.empty()) {
        bathy = read_bathymetry(o, sub_progress(progress, 0.1, 0.15), &coast.rings); // covering the ocean cut
        budget.hold(static_cast<double>(bathy->values().size() * sizeof(float)));
    }
    clock.lap("read_bathy");

    // --hmax alone is a uniform field: no background grid needed.
    const bool uniform = o.coast_size_km == 0 && o.wavelength == 0 && o.slope == 0 && o.size_regions.empty();
    SizeFn size;
    SizeField field;
    if (uniform) {
        size = uniform_size(std::max(o.hmax_km, o.hmin_km));
    } else {
        const double grid_nodes = size_grid_nodes(o);
        budget.require(grid_nodes * static_cast<double>(size_grid_bytes_per_node),
                       "the size field's background grid (" +
                           std::to_string(static_cast<std::uint64_t>(grid_nodes)) + " nodes)",
                       " or --hmin");
        field = build_size_field(o, bathy ? &*bathy : nullptr, &coast.rings,
                                 sub_progress(progress, 0.15, 0.25), size_grid_max_nodes);
        size = field.function();
        budget.hold(static_cast<double>(field.grid().values().size() * sizeof(float)));
    }
    clock.lap("size_field");

    CoastReport coast_report;
    Boundary boundary = shape_boundary(coast, size, o, &coast_report, sub_progress(progress, 0.25, 0.3));
    clock.lap("boundary");
    // A size wider than the region leaves too little of its outline for a triangle: say so, and
    // which option to change, rather than the mesher's "fewer than 4 nodes".
    if (std::size_t n = 0; !boundary.empty()) {
        for (const Ring& r : boundary.rings) n += r.nodes.size();
        if (n < 4)
            throw DataError("no ocean to mesh: at --hmax " + number(o.hmax_km) + " km the coast and region keep only " +
                            std::to_string(n) + " boundary nodes; lower --hmax");
    }
    coast.rings = Boundary{}; // done with: the mesher reuses their memory (only coast.layer is used below)

    MesherOptions mo;
    mo.max_nodes = o.max_nodes;
    if (o.max_memory_bytes > 0) {
        // The mesher refuses from its node estimate against what the inputs left.
        budget.require(static_cast<double>(mesher_bytes_per_node), "meshing", " or --hmin/--hmax");
        mo.max_memory = budget.left();
    }
    mo.smooth_iterations = o.smooth_iterations;
    mo.keep_inland_seas = o.keep_inland_seas;
    mo.close_straits = !o.keep_straits;
    mo.inlet_width = o.inlet_width;
    mo.lattice_km = std::max(o.hmax_km, o.hmin_km); // the field's largest value
    mo.seed = o.seed;
    if (coast.land) {
        // The land test holds the land polygons (GEOS coordinates and their prepared index).
        budget.hold(static_cast<double>(coast.land->vertices() * land_bytes_per_vertex + coast.land->cell_bytes()));
        mo.land = coast.land;
    }
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

    std::optional<DepthFloor> depth_floor;
    if (bathy) {
        Field depth{"depth", "sea floor depth below mean sea level", "m",
                    "sea_floor_depth_below_mean_sea_level", {}};
        depth.values.reserve(mesh.nodes.size());
        for (const Vec3& p : mesh.nodes) depth.values.push_back(bathy->depth_m(p));
        depth_floor = apply_min_depth(depth.values, o.min_depth_m);
        mesh.node_fields.insert(mesh.node_fields.begin(), std::move(depth));
    }

    auto& a = mesh.attributes;
    a.emplace_back("coast_file", o.coast);
    a.emplace_back("coast_layer", coast.layer);
    if (!o.bathy.empty()) a.emplace_back("bathymetry_file", o.bathy);
    if (depth_floor) {
        // As sampled, before --min-depth (the CLI warns from them when it is not given).
        a.emplace_back("nodes_above_sea_level", std::to_string(depth_floor->above_sea_level));
        if (depth_floor->above_sea_level > 0) a.emplace_back("min_sampled_depth_m", number(depth_floor->shallowest_m));
        if (o.min_depth_m) {
            a.emplace_back("min_depth_m", number(*o.min_depth_m));
            a.emplace_back("nodes_raised_to_min_depth", std::to_string(depth_floor->raised));
        }
    }
    a.emplace_back("boundary_rings", std::to_string(coast_report.rings));
    a.emplace_back("boundary_nodes", std::to_string(coast_report.nodes));
    a.emplace_back("islands_removed", std::to_string(coast_report.islands_removed));
    a.emplace_back("lakes_removed", std::to_string(coast_report.lakes_removed));
    a.emplace_back("coast_repairs", std::to_string(coast.polygons_joined) + " polygons joined at near-touches, " +
                                        std::to_string(coast.rings_changed) + " rings changed by snap rounding, " +
                                        std::to_string(coast.arcs_split) + " nodes added to straying arcs");
    a.emplace_back("faces_on_removed_islands", std::to_string(report.island_centroids_left) + " (" +
                                                   std::to_string(report.island_centroids_moved) + " moved off)");
    a.emplace_back("faces_on_land", std::to_string(report.land_faces_left) + " (" +
                                        std::to_string(report.land_faces_removed) + " removed, opening " +
                                        std::to_string(report.land_holes) + " holes, joining " +
                                        std::to_string(report.land_loops_joined) + " loops, " +
                                        std::to_string(report.land_faces_nudged) + " moved off)");
    // Places as lon lat (degrees), the first 50.
    auto places = [](const std::vector<Vec3>& points) {
        std::string at;
        char buf[48];
        for (std::size_t i = 0; i < points.size() && i < 50; ++i) {
            const LonLat ll = vec_to_lonlat(points[i]);
            std::snprintf(buf, sizeof buf, "%s%.2f %.2f", i ? ", " : "", ll.lon, ll.lat);
            at += buf;
        }
        if (points.size() > 50) at += ", ...";
        return at;
    };
    if (!report.land_faces_at.empty()) a.emplace_back("faces_on_land_at", places(report.land_faces_at));
    if (mo.land && mo.close_straits) {
        std::string closed = std::to_string(report.straits_closed) + " (cutting off " +
                             std::to_string(report.seas_cut_off.size()) + " basins";
        for (std::size_t i = 0; i < report.seas_cut_off.size(); ++i)
            closed += (i ? ", " : ": ") + number(report.seas_cut_off[i]) + " km2";
        closed += "; " + number(report.straits_water_km2) + " km2 of water closed with them; " +
                  std::to_string(report.nodes_split) + " nodes split)";
        a.emplace_back("straits_closed", closed);
        if (!report.straits_closed_at.empty()) a.emplace_back("straits_closed_at", places(report.straits_closed_at));
    }
    a.emplace_back("ocean_area_km2", number(coast_report.ocean_area_km2));
    a.emplace_back("segments_split", std::to_string(report.segments_split + report.encroached_splits));
    a.emplace_back("inlets_closed", std::to_string(report.inlets_closed) + " (" +
                                        number(report.inlet_area_km2) + " km2)");
    a.emplace_back("lattice_nodes", std::to_string(report.lattice_nodes));
    a.emplace_back("corners_blunted", std::to_string(report.corners_blunted));
    a.emplace_back("sharp_coast_corners", std::to_string(report.sharp_corners));
    a.emplace_back("faces_at_sharp_corners", std::to_string(report.sharp_corner_faces));
    std::ostringstream comps;
    for (const auto& c : report.components) comps << (comps.tellp() ? "; " : "") << number(c.area_km2) << " km2 " << (c.kept ? "kept" : "dropped");
    a.emplace_back("ocean_components", comps.str());
    return mesh;
}

} // namespace globemesh
