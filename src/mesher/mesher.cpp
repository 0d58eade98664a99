// mesh_boundary: the mesher's stages in sequence, each in its own file (mesher_state.hpp lists
// them and holds the state they share).
#include "globemesh/mesher.hpp"

#include "corners.hpp"
#include "mesher_state.hpp"
#include "stage_hook.hpp"

namespace globemesh {

using namespace mesher_internal;

Mesh mesh_boundary(const Boundary &boundary, const std::function<double(const Vec3 &)> &size_km,
                   const MesherOptions &options, MesherReport *report_out, const Progress &progress,
                   StageTimings *timings) {
    MesherReport local_report;
    MesherReport &report = report_out ? *report_out : local_report;
    report = MesherReport{};
    Mesher m(SphericalDelaunay::Options{1e-12, options.seed}, size_km, report);
    // Each timed() adds the seconds since the last to `timings` under the stage's name.
    auto t0 = Clock::now();
    auto timed = [&](const char *stage) {
        if (timings)
            timings->add(stage, seconds_since(t0));
        if (after_stage)
            after_stage(stage);
        t0 = Clock::now();
    };

    // Boundary insertion and recovery (insert.cpp).
    const std::vector<VertexId> ids = insert_boundary(m, boundary);
    note_whole_rings(m, boundary, ids, options.whole_rings);
    globemesh::report(progress, 0.05, "insert_boundary");
    timed("insert_boundary");
    recover_segments(m, boundary, ids);
    globemesh::report(progress, 0.1, "recover");
    timed("recover");

    // Classification, inlets, sharp corners and the node estimate (classify.cpp).
    classify_ocean(m, boundary, options);
    if (options.inlet_width > 0 && !boundary.empty())
        close_inlets(m, options, report);
    if (!boundary.empty())
        report.coast_nodes_merged = merge_close_coast_nodes(m, options);
    globemesh::report(progress, 0.15, "classify");
    mark_sharp_corners(m);
    estimate_nodes(m, options);
    timed("classify");

    // The lattice (lattice.cpp), whose points over the whole sphere may be a few times the nodes
    // asked for (the global ocean: 1.5 times), not more; then the refinement (refine.cpp).
    const auto lattice_first =
        static_cast<VertexId>(m.dt.vertex_count()); // the lattice nodes follow
    if (options.lattice_km > 0)
        report.lattice_nodes =
            fill_lattice(m, options.lattice_km, 4.0 * double(report.estimated_nodes) + 1000,
                         options.lattice_within, options.lattice_share);
    refine(m, progress);
    timed("refine");

    // Improvement: smoothing (smooth.cpp), quality rounds (quality.cpp), faces off the dropped
    // islands (islands.cpp).
    std::vector<char> as_made = smooth(m, options, lattice_first, progress);
    improve_quality(m, options, as_made);
    std::vector<TriangleId> island_faces;
    report.island_centroids_left = clear_dropped_islands(m, boundary, report, island_faces);
    timed("improve");

    // Land and strait clean-up (land.cpp, straits.cpp).
    if (options.land) {
        clear_land(m, options, std::move(island_faces));
        timed("land");
    }

    // Last, the coast's corners too sharp for the faces there (corners.cpp), then the floor
    // (quality.cpp). The floor's moves can leave a sliver on the coast below it, which blunting
    // removes: then both run once more.
    const auto before_corners = static_cast<VertexId>(m.dt.vertex_count());
    blunt_sharp_corners(m, options);
    if (!raise_quality_floor(m, options, as_made)) {
        blunt_sharp_corners(m, options);
        raise_quality_floor(m, options, as_made);
    }
    if (options.land)
        clear_land_after_splits(m, options, before_corners);
    // The closings may leave small pieces alone (a face hanging at a pinched node): they go.
    close_cut_off_pieces(m, options, report);
    if (options.land && options.measure_straits)
        measure_closed_straits(size_km, *options.land, report);
    group_closed_straits(size_km, report);

    // Conversion to Mesh (output.cpp); a part's border nodes stay whole for the join.
    keep_border_nodes_whole(m, options.lattice_within);
    Mesh mesh = to_mesh(m, options.lattice_within);
    globemesh::report(progress, 1.0, "improve");
    return mesh;
}

} // namespace globemesh
