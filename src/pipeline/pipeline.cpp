// mesh_ocean(): the one function that calls every module, in the order of DESIGN.md's flow.
#include "globemesh/pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "coast/geos_interrupt.hpp"
#include "globemesh/bathymetry.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/parts.hpp"
#include "globemesh/sizefield.hpp"
#include "lonlat_box.hpp"

namespace globemesh {

namespace {

/// A node estimate as the refusals write it: "about 4.18366e+26", or "too many" past a double.
std::string nodes_text(double estimate) {
    return std::isfinite(estimate) ? "about " + report_number(std::round(estimate)) : "too many";
}

using Clock = std::chrono::steady_clock;

class StageClock {
public:
    explicit StageClock(StageTimings *t) : timings_(t) {}
    /// Adds the seconds since the last lap as stage `name`, one that reads input files when
    /// `input` (StageTimings::add_input).
    void lap(const std::string &name, bool input = false) {
        auto now = Clock::now();
        const double seconds = std::chrono::duration<double>(now - last_).count();
        if (timings_ && input)
            timings_->add_input(name, seconds);
        else if (timings_)
            timings_->add(name, seconds);
        last_ = now;
    }
    /// Starts the next lap now, for a stage timed elsewhere.
    void restart() { last_ = Clock::now(); }

private:
    StageTimings *timings_;
    Clock::time_point last_ = Clock::now();
};

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

/// The region the size field's grid covers: --region, or with --region-file the lon/lat box of
/// the ocean it bounds (ocean_extent; the globe's grid, 14 km cells, sampled a region of a few km
/// as coarsely), or the globe (nullopt).
std::optional<std::array<double, 4>> size_grid_region(const MeshOptions &o, const Boundary &ocean) {
    if (o.region || o.region_file.empty())
        return o.region;
    const std::optional<LonLatBounds> box = ocean_extent(ocean);
    if (!box || (box->south <= -90 && box->north >= 90))
        return std::nullopt;
    if (box->east - box->west >= 360) // a band of latitudes (a cap about a pole)
        return std::array<double, 4>{-180, box->south, 180, box->north};
    return std::array<double, 4>{wrap_lon(box->west), box->south, wrap_lon(box->east), box->north};
}

/// Upper bound of the background grid's node count (make_background_grid: spacing hfloor / 2,
/// the region plus a cell of margin, at most size_grid_max_nodes).
double size_grid_nodes(const MeshOptions &o, const std::optional<std::array<double, 4>> &region) {
    const double hfloor = size_floor_km(o);
    const double spacing = std::max(1e-6, 0.5 * hfloor / earth_radius_km * rad_to_deg);
    double lon_span = 360, lat_span = 180;
    if (region) {
        const auto &r = *region;
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
    std::uint64_t left() const {
        return held_ >= static_cast<double>(total_) ? 0
                                                    : total_ - static_cast<std::uint64_t>(held_);
    }
    /// Throws DataError when `bytes` more do not fit; `what` says what needs them.
    void require(double bytes, const std::string &what, const ErrorText &remedy) const {
        if (total_ == 0 || held_ + bytes <= static_cast<double>(total_))
            return;
        throw DataError(what + " needs about " + memory_text(bytes) + ", more than the " +
                        memory_text(static_cast<double>(left())) + " left of " +
                        option("max_memory_bytes") + " " +
                        memory_text(static_cast<double>(total_)) + " after reading the inputs (" +
                        memory_text(held_) + "); raise " + option("max_memory_bytes") + remedy);
    }

private:
    std::uint64_t total_;
    double held_ = 0;
};

/// Counts the depths (m, positive down) above sea level and raises those below `min_depth_m`
/// (when set) to it; no-data values (NaN) stay as they are.
DepthReport apply_min_depth(std::vector<double> &depths, std::optional<double> min_depth_m) {
    DepthReport f;
    f.nodes = depths.size();
    f.min_depth_m = min_depth_m;
    for (double &d : depths) {
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

/// The DataError for `missing` nodes of `nodes` without a depth in `bathy` (the file `path`):
/// how many, where the first is, how many lie past the raster's edges, and bathy_fill_m.
DataError missing_depths(const Raster &bathy, const std::vector<Vec3> &nodes,
                         const std::vector<double> &depths, const std::string &path) {
    std::size_t missing = 0, outside = 0, first = nodes.size();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (!std::isnan(depths[i]))
            continue;
        ++missing;
        first = std::min(first, i);
        const LonLat p = vec_to_lonlat(nodes[i]);
        outside += !bathy.contains(p.lon, p.lat);
    }
    const LonLat at = vec_to_lonlat(nodes[first]);
    const LonLatBounds b = bathy.bounds();
    char where[256];
    std::snprintf(where, sizeof where,
                  "the first at lon %.5f, lat %.5f (%zu past the raster's edges at lon %.5f..%.5f, "
                  "lat %.5f..%.5f; %zu on cells without data)",
                  at.lon, at.lat, outside, b.west, b.east, b.south, b.north, missing - outside);
    return DataError(option("bathy") + " " + path + ": no data at " + std::to_string(missing) +
                     " of the mesh's " + std::to_string(nodes.size()) + " nodes, " + where +
                     "; pass " + option("bathy_fill_m") + " DEPTH to give them that depth");
}

/// The depths (m, positive down) of `bathy` (the file `path`) at `nodes`. Throws
/// missing_depths' DataError when some have none (no data there and no bathy_fill_m).
std::vector<double> node_depths(const Raster &bathy, const std::vector<Vec3> &nodes,
                                const std::string &path) {
    std::vector<double> depths;
    depths.reserve(nodes.size());
    for (const Vec3 &p : nodes)
        depths.push_back(bathy.depth_m(p));
    if (std::any_of(depths.begin(), depths.end(), [](double d) { return std::isnan(d); }))
        throw missing_depths(bathy, nodes, depths, path);
    return depths;
}

/// --parts, or with 0 (asked for) 1 for a region (the lunes' borders cross a region's coasts
/// wherever they happen to fall, and there the worst faces of the Gulf of Mexico at 0.85 km,
/// 2.8e6 nodes, went from q 0.60 to 0.53) and where even the field's smallest size over the whole
/// ocean (a quarter more, for the sphere's area against the ellipsoid's and the estimate's
/// sampling) and every boundary node stay below auto_parts_nodes: most runs, which then need no
/// whole-ocean pass to count their nodes; else 0, for mesh_parts to count them and choose.
int part_count(const MeshOptions &o, double ocean_area_km2, const SizeField &field,
               const Boundary &boundary) {
    if (o.parts != 0)
        return o.parts;
    if (o.region || !o.region_file.empty())
        return 1;
    std::size_t boundary_nodes = 0;
    for (const Ring &r : boundary.rings)
        boundary_nodes += r.nodes.size();
    const double most =
        nodes_for_area(1.25 * ocean_area_km2, field.min_km()) + static_cast<double>(boundary_nodes);
    return most < static_cast<double>(auto_parts_nodes) ? 1 : 0;
}

/// Refuses a run whose node count is far above max_nodes from the coast alone, before the
/// bathymetry, the size field and the coast's shaping spend minutes and gigabytes on it.
void refuse_too_many_nodes(const MeshOptions &o, const CoastData &coast) {
    // The mesher's node estimate (nodes_for_area) with every size at --hmax (the field's
    // largest). The mesher's own estimate, over the shaped ocean and the field's sizes, is larger
    // but for the area the shaping closes (inlets, lakes; a few per mil of the global ocean), so
    // only 90% of this one is held against --max-nodes: a size far too small is refused here,
    // before the bathymetry, the size field and the coast's shaping spend minutes and gigabytes
    // on it.
    if (const double estimate = nodes_for_area(coast.ocean_area_km2, o.hmax_km);
        0.9 * estimate > static_cast<double>(o.max_nodes))
        throw DataError("the ocean (" + std::to_string(std::llround(coast.ocean_area_km2)) +
                        " km2) takes " + nodes_text(estimate) + " nodes at " + option("hmax_km") +
                        " " + report_number(o.hmax_km) + " km, more than " + option("max_nodes") +
                        " " + std::to_string(o.max_nodes) + ": raise " + option("hmax_km") +
                        " or " + option("max_nodes"));
    // The same for the water along the coast at --coast-size: the size grows from s there at
    // rate g = min(--coast-rate, --grade) up to --hmax, and along a straight coast of length L
    // the band takes L * integral of dd / (c (s + g d)^2) = L (1/s - 1/hmax) / (c g) nodes (c h^2
    // the area of a node, nodes_for_area). The mesher counts them exactly, but only after the
    // size field and the coast's shaping, which at a size of metres take seconds to minutes.
    // It is at most twice the mesher's count (bays share their bands; bench/RESULTS-pipeline.md).
    // The source coast is longer than the shaped one where the size is above its segments' mean
    // length (the shaping simplifies it), so the count is held against --max-nodes only below
    // that length, and at half its value.
    if (o.coast_size_km > 0) {
        double coast_km = 0;
        std::size_t segments = 0;
        for (const Ring &r : coast.rings.rings)
            for (std::size_t i = 0; i < r.nodes.size(); ++i)
                if (r.kinds[i] == SegmentKind::coast) {
                    coast_km += arc_km(r.nodes[i], r.nodes[(i + 1) % r.nodes.size()]);
                    ++segments;
                }
        const double floor = size_floor_km(o), s = std::clamp(o.coast_size_km, floor, o.hmax_km);
        const double rate = std::min(o.coast_rate, o.grade);
        const double estimate = rate > 0
                                    ? nodes_for_area(coast_km * (1 / s - 1 / o.hmax_km) / rate, 1.0)
                                    : nodes_for_area(coast_km * s, s); // a band one size wide
        if (segments > 0 && s <= coast_km / double(segments) &&
            0.5 * estimate > static_cast<double>(o.max_nodes))
            throw DataError("the water along the coast (" + std::to_string(std::llround(coast_km)) +
                            " km) takes " + nodes_text(estimate) + " nodes at " +
                            option("coast_size_km") + " " + report_number(o.coast_size_km) + " km" +
                            (s > o.coast_size_km ? " (" + report_number(s) + " km: sizes stop at " +
                                                       option("hmin_km") + ", by default " +
                                                       option("hmax_km") + " / 1000)"
                                                 : ErrorText("")) +
                            ", more than " + option("max_nodes") + " " +
                            std::to_string(o.max_nodes) + ": raise " + option("coast_size_km") +
                            (s > o.coast_size_km ? " and " + option("hmin_km") : ErrorText("")) +
                            " or " + option("max_nodes"));
    }
}

/// The passages of --passages that reach into the region (a point of the line inside its W,S,E,N
/// box, or the line reaching the region's ocean `rings`, which a line across the box with its
/// ends outside does; all of them globally), with their widths in water on the source land.
std::vector<Passage> region_passages(const MeshOptions &o, const Boundary &rings,
                                     const LandTest *land) {
    std::vector<Passage> all = read_passages(o.passages, o.passages_layer), kept;
    auto inside = [&](const Vec3 &p) { return in_lonlat_box(*o.region, vec_to_lonlat(p)); };
    auto in_region = [&](const Passage &p) {
        if (!o.region && o.region_file.empty())
            return true;
        return (o.region && std::any_of(p.line.begin(), p.line.end(), inside)) ||
               line_meets_ocean(p.line, rings);
    };
    for (Passage &p : all)
        if (in_region(p))
            kept.push_back(std::move(p));
    measure_passages(kept, land);
    return kept;
}

/// Each passage's width, the field's size at its middle and the faces of `mesh` its line meets.
std::vector<PassageReport> passage_reports(const std::vector<Passage> &passages,
                                           const SizeField &field, const Mesh &mesh) {
    std::vector<PassageReport> reports;
    for (const Passage &p : passages) {
        const Vec3 at = arc_midpoint(p.line.front(), p.line.back());
        reports.push_back({p.name, p.width_km, field.size_km(at), faces_crossed(mesh, p.line), at});
    }
    return reports;
}

} // namespace

OceanMesh mesh_ocean(const MeshOptions &o, const Progress &run_progress, StageTimings *timings) {
    // A long GEOS operation of the coast stages stops too when the run is cancelled.
    const coast::GeosInterrupt geos_interrupt(run_progress);
    const Progress &progress = geos_interrupt.progress();
    validate(o);
    if (o.coast.empty())
        throw UsageError(option("coast") +
                         " is required: a land polygon or coastline file (any OGR source)");
    StageClock clock(timings);

    // load_coast and read_bathymetry check their own reads against --max-memory (the coast
    // counts its vertices while reading, the raster is read no finer than the mesh needs).
    MemoryBudget budget(o.max_memory_bytes);
    CoastData coast =
        load_coast(coast_options(o), o.max_memory_bytes, sub_progress(progress, 0.0, 0.1));
    for (const Ring &r : coast.rings.rings)
        budget.hold(static_cast<double>(r.nodes.size() * ring_bytes_per_node));
    clock.lap("read_coast", true);
    refuse_too_many_nodes(o, coast);
    const std::vector<Passage> passages = o.passages.empty()
                                              ? std::vector<Passage>{}
                                              : region_passages(o, coast.rings, coast.land.get());

    std::optional<Raster> bathy;
    if (!o.bathy.empty()) {
        bathy = read_bathymetry(bathymetry_options(o), bathymetry_context(o),
                                sub_progress(progress, 0.1, 0.15),
                                &coast.rings); // covering the ocean cut
        budget.hold(static_cast<double>(bathy->values().size() * sizeof(float)));
    }
    clock.lap("read_bathy", true);

    // The background grid, when the field needs one, is held against the budget before it is made.
    const std::optional<std::array<double, 4>> grid_region = size_grid_region(o, coast.rings);
    auto reserve_grid = [&] {
        const double grid_nodes = size_grid_nodes(o, grid_region);
        budget.require(grid_nodes * static_cast<double>(size_grid_bytes_per_node),
                       "the size field's background grid (" +
                           std::to_string(static_cast<std::uint64_t>(grid_nodes)) + " nodes)",
                       " or " + option("hmin_km"));
    };
    // Uniform when no component of the field is on: then no background grid is built.
    const SizeField field =
        build_size_field(size_field_options(o), grid_region, bathy ? &*bathy : nullptr,
                         &coast.rings, sub_progress(progress, 0.15, 0.25), size_grid_max_nodes,
                         reserve_grid, passages, static_cast<std::size_t>(std::max(0, o.threads)));
    const SizeFn size = field.function();
    SizeFieldReport size_report{field.is_uniform(), 0, field.min_km(), field.max_km()};
    if (!field.is_uniform()) {
        size_report.grid_nodes = field.grid().values().size();
        budget.hold(static_cast<double>(field.grid().values().size() * sizeof(float)));
    }
    clock.lap("size_field");

    CoastReport coast_report;
    Boundary boundary = shape_boundary(coast, size, coast_options(o), o.max_nodes, &coast_report,
                                       sub_progress(progress, 0.25, 0.3));
    clock.lap("boundary");
    // A size wider than the region leaves too little of its outline for a triangle: say so, and
    // which option to change, rather than the mesher's "fewer than 4 nodes".
    if (std::size_t n = 0; !boundary.empty()) {
        for (const Ring &r : boundary.rings)
            n += r.nodes.size();
        if (n < 4)
            throw DataError("no ocean to mesh: at " + option("hmax_km") + " " +
                            report_number(o.hmax_km) + " km the coast and region keep only " +
                            std::to_string(n) + " boundary nodes; lower " + option("hmax_km"));
    }
    coast.rings =
        Boundary{}; // done with: the mesher reuses their memory (only coast.layer is used below)

    MesherOptions mo;
    mo.max_nodes = o.max_nodes;
    if (o.max_memory_bytes > 0) {
        // The mesher refuses from its node estimate against what the inputs left.
        budget.require(static_cast<double>(mesher_bytes_per_node), "meshing",
                       " or " + option("hmin_km") + "/" + option("hmax_km"));
        mo.max_memory = budget.left();
    }
    mo.smooth_iterations = o.smooth_iterations;
    mo.keep_inland_seas = o.keep_inland_seas;
    mo.close_straits = !o.keep_straits;
    mo.inlet_width = o.inlet_width;
    mo.close_node_gap = o.close_node_gap;
    mo.close_dead_ends = o.close_dead_ends;
    mo.lattice_km = std::max(o.hmax_km, o.hmin_km); // the field's largest value
    mo.seed = o.seed;
    mo.parts_border_lon = o.parts_border_lon;
    mo.region = o.region;
    for (const Passage &p : passages)
        mo.passages.push_back(p.line);
    if (coast.land) {
        // The land test holds the land polygons (GEOS coordinates and their prepared index).
        budget.hold(static_cast<double>(coast.land->vertices() * land_bytes_per_vertex +
                                        coast.land->cell_bytes()));
        mo.land = coast.land;
    }
    MesherReport report;
    StageTimings mesher_times;
    auto mesh_start = Clock::now();
    const unsigned threads = o.threads > 0 ? static_cast<unsigned>(o.threads)
                                           : std::max(1u, std::thread::hardware_concurrency());
    Mesh mesh = mesh_parts(boundary, size, mo, part_count(o, coast.ocean_area_km2, field, boundary),
                           threads, &report, sub_progress(progress, 0.3, 0.97), &mesher_times);
    double mesh_seconds = std::chrono::duration<double>(Clock::now() - mesh_start).count();
    clock.restart();
    if (timings) {
        for (auto &s : mesher_times.stages)
            timings->stages.push_back(s);
        timings->add("mesh", mesh_seconds);
    }

    OceanMesh run;
    if (bathy) {
        Field depth{"depth",
                    "sea floor depth below mean sea level",
                    "m",
                    "sea_floor_depth_below_mean_sea_level",
                    {}};
        depth.values = node_depths(*bathy, mesh.nodes, o.bathy);
        run.depth = apply_min_depth(depth.values, o.min_depth_m);
        mesh.node_fields.insert(mesh.node_fields.begin(), std::move(depth));
    }
    run.coast_file = o.coast;
    run.coast_layer = coast.layer;
    run.bathymetry_file = o.bathy;
    run.coast_repairs = {coast.polygons_joined, coast.rings_changed, coast.arcs_split};
    run.coast = coast_report;
    run.size_field = size_report;
    run.mesher = std::move(report);
    run.straits_closing = mo.land && mo.close_straits;
    run.passages = passage_reports(passages, field, mesh);
    run.passage_cells = o.passage_cells;
    run.mesh = std::move(mesh);
    run.mesh.attributes = ocean_attributes(run);
    // The run's end: a caller's progress bar reaches the end of the run's share.
    globemesh::report(progress, 1.0, "mesh");
    return run;
}

} // namespace globemesh
