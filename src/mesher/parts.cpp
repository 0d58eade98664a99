// mesh_parts (docs/parallel.md, sections 4-8): the inland seas told on the whole boundary, the
// parts meshed on threads (each part's mesh independent of the schedule, stored by part index),
// then joined in part order (join_parts).
#include "globemesh/parts.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <future>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "globemesh/error.hpp"
#include "mesher_state.hpp"
#include "parts_lunes.hpp"

namespace globemesh {

using namespace mesher_internal;
using parts_detail::choose_lunes;
using parts_detail::lon_bins;
using parts_detail::spread_over_longitudes;

namespace {

/// The land test under a lock: LandMask caches its answers and shares one GEOS context, neither
/// safe from two threads; its answers do not depend on the order of the calls.
class LockedLand : public LandTest {
public:
    explicit LockedLand(std::shared_ptr<const LandTest> land) : land_(std::move(land)) {}
    bool contains(const Vec3 &p) const override {
        const std::lock_guard<std::mutex> lock(mutex_);
        return land_->contains(p);
    }
    bool coast_within(const Vec3 &p, double angle) const override {
        const std::lock_guard<std::mutex> lock(mutex_);
        return land_->coast_within(p, angle);
    }
    double coast_distance(const Vec3 &p, double reach) const override {
        const std::lock_guard<std::mutex> lock(mutex_);
        return land_->coast_distance(p, reach);
    }

private:
    std::shared_ptr<const LandTest> land_;
    mutable std::mutex mutex_;
};

/// The rings that bound some of the ocean mesh_boundary keeps (the largest component, or all
/// with keep_inland_seas), told on the triangulation of the boundary nodes alone, as
/// classify_ocean does; the components (of the whole ocean) go to report.components. A count of
/// 0 in `lunes` becomes parts_for_nodes of the node estimate, and a first border of NaN the one
/// choose_lunes finds on this pass. With more than one part, the inlets a border
/// crosses, closed there by one part's inlet rule, are cut from the rings
/// (rings_with_inlets_closed) and counted in the report, their mouths' corners in `mouths`: a
/// part's own rule keeps water against its border open, and an inlet a border ran up was meshed
/// in both parts with faces as narrow as it. Throws DataError as mesh_boundary does when the
/// node estimate passes max_nodes or max_memory.
Boundary drop_inland_seas(const Boundary &boundary, const SizeFn &size_km,
                          const MesherOptions &options, MesherReport &report, Lunes &lunes,
                          std::vector<std::array<double, 3>> &mouths) {
    MesherReport local;
    Mesher m(SphericalDelaunay::Options{1e-12, options.seed}, size_km, local);
    const std::vector<VertexId> ids = insert_boundary(m, boundary);
    recover_segments(m, boundary, ids);
    classify_ocean(m, boundary, options);
    // Refused here as one part would be, before any part; the nodes spread over the longitudes.
    std::vector<double> by_lon(lon_bins, 0.0);
    estimate_nodes(m, options, false,
                   [&](const Vec3 &a, const Vec3 &b, const Vec3 &c, double nodes) {
                       spread_over_longitudes(by_lon, a, b, c, nodes);
                   });
    report.components = local.components;
    report.estimated_nodes = local.estimated_nodes;
    if (lunes.count == 0)
        lunes.count = parts_for_nodes(report.estimated_nodes);
    std::vector<char> ocean_ring;
    std::size_t offset = 0;
    for (const Ring &r : boundary.rings) {
        bool ocean = false, found = false;
        for (std::size_t i = 0; i < r.nodes.size() && !found; ++i) {
            const VertexId a = ids[offset + i], b = ids[offset + (i + 1) % r.nodes.size()];
            const HalfEdge h = a == b ? no_half_edge : m.dt.find_edge(m.dt.leaving(a), b);
            found = h != no_half_edge;
            ocean = found && m.dt.label(triangle_of(h)) == mesher_internal::ocean;
        }
        ocean_ring.push_back(ocean || !found);
        offset += r.nodes.size();
    }
    if (lunes.count > 1 && std::isnan(lunes.first_lon))
        lunes = choose_lunes(lunes.count, by_lon, boundary.rings, ocean_ring, size_km);
    std::vector<Ring> rings = boundary.rings;
    if (lunes.count > 1 && options.inlet_width > 0 && !boundary.empty()) {
        const std::size_t first = m.directed.size();
        close_inlets(m, options, local);
        // A segment crosses a border where its ends lie in two parts (as split_boundary cuts).
        InletCut cut =
            rings_with_inlets_closed(m, boundary, ids, first, [&](const Vec3 &a, const Vec3 &b) {
                return lunes.part_of(a) != lunes.part_of(b);
            });
        rings = std::move(cut.rings);
        mouths = std::move(cut.mouths);
        report.inlets_closed += cut.closed;
        report.inlet_area_km2 += cut.area_km2;
    }
    Boundary kept;
    kept.dropped_islands = boundary.dropped_islands;
    for (std::size_t r = 0; r < rings.size(); ++r)
        if (ocean_ring[r])
            kept.rings.push_back(std::move(rings[r]));
    return kept;
}

/// Lune k of `lunes` as MesherOptions::lattice_within takes it: east of border k, west of
/// border k + 1 (the part's ocean lies there, its borders being arcs of those meridians' planes).
std::vector<Vec3> lune_normals(const Lunes &lunes, int k) {
    return {lunes.border_normal(k), -lunes.border_normal(k + 1)};
}

/// Adds a part's report to the run's (counts summed, lists concatenated; not the components).
void add_report(MesherReport &run, const MesherReport &part) {
    auto append = [](auto &to, const auto &from) { to.insert(to.end(), from.begin(), from.end()); };
    run.boundary_nodes += part.boundary_nodes;
    run.segments_split += part.segments_split;
    run.encroached_splits += part.encroached_splits;
    run.estimated_nodes += part.estimated_nodes;
    run.sharp_corners += part.sharp_corners;
    run.sharp_corner_faces += part.sharp_corner_faces;
    run.inlets_closed += part.inlets_closed;
    run.coast_nodes_merged += part.coast_nodes_merged;
    run.inlet_area_km2 += part.inlet_area_km2;
    run.lattice_nodes += part.lattice_nodes;
    run.lattice_patched += part.lattice_patched;
    run.island_centroids_moved += part.island_centroids_moved;
    run.island_centroids_left += part.island_centroids_left;
    run.valence_flips += part.valence_flips;
    run.corners_mended += part.corners_mended;
    run.corners_blunted += part.corners_blunted;
    run.floor_nodes_removed += part.floor_nodes_removed;
    run.floor_nodes_added += part.floor_nodes_added;
    run.land_faces_removed += part.land_faces_removed;
    run.land_faces_left += part.land_faces_left;
    run.land_faces_nudged += part.land_faces_nudged;
    append(run.land_faces_at, part.land_faces_at);
    run.water_faces_removed += part.water_faces_removed;
    run.land_holes += part.land_holes;
    run.land_loops_joined += part.land_loops_joined;
    run.straits_closed += part.straits_closed;
    append(run.straits_closed_at, part.straits_closed_at);
    append(run.cut_points, part.cut_points); // seas_cut_off: told on the joined mesh
    run.straits_water_km2 += part.straits_water_km2;
    run.nodes_split += part.nodes_split;
}

/// The parts' progress as one: their mean fraction, reported under a lock (the caller's
/// callback need not be thread-safe); once it asks to stop, every part stops.
class SharedProgress {
public:
    SharedProgress(const Progress &parent, std::size_t parts)
        : parent_(parent), fractions_(parts, 0.0) {}
    Progress part(std::size_t k) {
        return [this, k](double f, std::string_view stage) {
            const std::lock_guard<std::mutex> lock(mutex_);
            fractions_[k] = f;
            double sum = 0;
            for (double x : fractions_)
                sum += x;
            if (parent_ && !stop_ && !parent_(sum / double(fractions_.size()), stage))
                stop_ = true;
            return !stop_;
        };
    }

private:
    const Progress &parent_;
    std::vector<double> fractions_;
    std::mutex mutex_;
    bool stop_ = false;
};

/// The joined mesh's pieces apart closed by the inlet rule, and the basins the parts' closed
/// straits cut off told there (a part's pieces beside a cut may reach the ocean through another
/// part: alone, a part counted half of Hudson Bay).
void close_pieces(Mesh &mesh, const SizeFn &size_km, const MesherOptions &options,
                  MesherReport &report) {
    std::set<std::array<double, 3>> cut;
    for (const Vec3 &p : report.cut_points)
        cut.insert({p.x, p.y, p.z});
    // A node is looked up only when a cut point shares its x's bucket (a few in 1e6 do).
    auto bucket = [](double x) {
        std::uint64_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        return (bits * 0x9e3779b97f4a7c15ull) >> 50;
    };
    std::vector<char> may(std::size_t(1) << 14, 0);
    for (const Vec3 &p : report.cut_points)
        may[bucket(p.x)] = 1;
    std::vector<NodeIndex> cut_nodes;
    for (NodeIndex i = 0; i < mesh.nodes.size(); ++i)
        if (may[bucket(mesh.nodes[i].x)] &&
            cut.count({mesh.nodes[i].x, mesh.nodes[i].y, mesh.nodes[i].z}))
            cut_nodes.push_back(i);
    close_joined_pieces(mesh, cut_nodes, size_km, options, report);
}

/// Runs work(k, t) for k in [0, count) on `threads` threads (t the thread's number, 0 this
/// one), each taking the next k; rethrows the first exception in k order once all have ended.
template <class Work> void run_parts(std::size_t count, unsigned threads, Work work) {
    std::vector<std::exception_ptr> errors(count);
    std::atomic<std::size_t> next{0};
    auto loop = [&](unsigned t) {
        for (std::size_t k; (k = next++) < count;) {
            try {
                work(k, t);
            } catch (...) {
                errors[k] = std::current_exception();
            }
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < std::min<std::size_t>(threads, count); ++t)
        pool.emplace_back(loop, t);
    loop(0);
    for (auto &t : pool)
        t.join();
    for (auto &e : errors)
        if (e)
            std::rethrow_exception(e);
}

} // namespace

Mesh mesh_parts(const Boundary &boundary, const SizeFn &size_km, const MesherOptions &options,
                int parts, unsigned threads, MesherReport *report_out, const Progress &progress,
                StageTimings *timings) {
    if (parts == 1)
        return mesh_boundary(boundary, size_km, options, report_out, progress, timings);
    MesherReport local_report;
    MesherReport &report = report_out ? *report_out : local_report;
    report = MesherReport{};
    auto t0 = Clock::now();
    // The other threads' copies of the land test are made meanwhile, on threads of their own:
    // the whole-ocean pass and the split run on this one (a copy of GSHHG low's took 0.025 s, at
    // the start of a part's thread).
    const unsigned most_threads =
        std::min<unsigned>(std::max(1u, threads), parts == 0 ? auto_parts : parts);
    const auto copier = options.land && most_threads > 1 ? options.land->copier() : nullptr;
    std::vector<std::future<std::shared_ptr<const LandTest>>> copies;
    for (unsigned t = 1; copier && t < most_threads; ++t)
        copies.push_back(std::async(std::launch::async, copier));
    std::vector<std::array<double, 3>> mouths;
    Lunes lunes{parts, options.parts_border_lon};
    const Boundary kept = drop_inland_seas(boundary, size_km, options, report, lunes, mouths);
    parts = lunes.count;
    if (parts == 1) { // chosen
        if (timings)
            timings->add("parts", seconds_since(t0)); // the pass that chose one part
        return mesh_boundary(boundary, size_km, options, report_out, progress, timings);
    }
    report.parts = parts;
    report.parts_border_lon = lunes.first_lon;
    MesherOptions part_options = options;
    part_options.keep_inland_seas = true; // a sea cut by a border is two components
    part_options.mouth_corners = std::move(mouths);
    part_options.measure_straits = false; // below, beside the join
    const std::vector<PartBoundary> split =
        split_boundary(kept, size_km, lunes, options.land.get());
    // The land test: each thread its own (the first the caller's, the others the copies; the
    // same answers), or one under a lock where it cannot be copied.
    threads = std::min<unsigned>(std::max(1u, threads), static_cast<unsigned>(split.size()));
    std::vector<std::shared_ptr<const LandTest>> lands(threads);
    if (options.land && threads > 1 && !copier)
        part_options.land = std::make_shared<LockedLand>(options.land);
    else if (options.land)
        lands[0] = options.land;
    for (unsigned t = 1; t < threads && t <= copies.size(); ++t)
        lands[t] = copies[t - 1].get();
    if (timings)
        timings->add("split", seconds_since(t0));

    std::vector<Mesh> meshes(split.size());
    std::vector<MesherReport> reports(split.size());
    std::vector<StageTimings> times(split.size());
    SharedProgress shared(progress, split.size());
    run_parts(split.size(), threads, [&](std::size_t k, unsigned t) {
        if (!split[k].has_ocean)
            return;
        MesherOptions lune = part_options;
        if (lands[t])
            lune.land = lands[t];
        lune.lattice_within = lune_normals(lunes, static_cast<int>(k));
        lune.lattice_share = 1.0 / parts;
        lune.whole_rings = split[k].whole_rings;
        meshes[k] =
            mesh_boundary(split[k].boundary, size_km, lune, &reports[k], shared.part(k), &times[k]);
    });
    t0 = Clock::now();
    const std::size_t estimated = report.estimated_nodes;
    for (const MesherReport &r : reports)
        add_report(report, r);
    report.estimated_nodes = estimated;    // the whole ocean's, as one part counts it
    group_closed_straits(size_km, report); // a place may reach across a border
    // Each stage's seconds summed over the parts (the parts ran at once: more than its wall time).
    if (timings) {
        StageTimings summed;
        for (const StageTimings &t : times)
            for (const auto &[stage, seconds] : t.stages)
                summed.add_to(stage, seconds);
        for (const auto &s : summed.stages)
            timings->stages.push_back(s);
    }
    // The widths of the straits closed are measured on a thread of their own while this one
    // joins the parts (the join does not use the land test); the same widths as in the parts.
    MesherReport widths;
    widths.straits_closed_at = report.straits_closed_at;
    auto measure = [&] {
        if (options.land && options.measure_straits)
            measure_closed_straits(size_km, *options.land, widths);
    };
    std::future<void> measured;
    if (threads > 1)
        measured = std::async(std::launch::async, measure);
    // The lattice is stitched back only where the parts laid one (fill_lattice skips it when
    // the size field is below its largest value over most of the ocean).
    Mesh mesh =
        join_parts(meshes, lunes, size_km, report.lattice_nodes > 0 ? options.lattice_km : 0.0);
    close_pieces(mesh, size_km, options, report);
    if (measured.valid())
        measured.get();
    else
        measure();
    report.straits_closed_width_km = std::move(widths.straits_closed_width_km);
    report.straits_closed_width_below_km = std::move(widths.straits_closed_width_below_km);
    if (timings)
        timings->add("join", seconds_since(t0));
    return mesh;
}

} // namespace globemesh
