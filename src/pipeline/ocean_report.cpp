// The run's metadata and report texts, formatted once from mesh_ocean's typed reports.
#include <charconv>
#include <cstdio>
#include <sstream>

#include "globemesh/pipeline.hpp"

namespace globemesh {

std::string report_number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

std::string coast_repairs_text(const CoastRepairs &r) {
    return std::to_string(r.polygons_joined) + " polygons joined at near-touches, " +
           std::to_string(r.rings_changed) + " rings changed by snap rounding, " +
           std::to_string(r.arcs_split) + " nodes added to straying arcs";
}

std::string land_faces_text(const MesherReport &r) {
    return std::to_string(r.land_faces_left) + " (" + std::to_string(r.land_faces_removed) +
           " removed, opening " + std::to_string(r.land_holes) + " holes, joining " +
           std::to_string(r.land_loops_joined) + " loops, " + std::to_string(r.land_faces_nudged) +
           " moved off)";
}

std::string straits_closed_text(const MesherReport &r) {
    std::string closed = std::to_string(r.straits_closed);
    if (r.straits_closed > 0)
        closed += " at " + std::to_string(r.straits_closed_places) +
                  (r.straits_closed_places == 1 ? " place" : " places");
    closed += " (cutting off " + std::to_string(r.seas_cut_off.size()) + " basins";
    for (std::size_t i = 0; i < r.seas_cut_off.size(); ++i)
        closed += (i ? ", " : ": ") + report_number(r.seas_cut_off[i]) + " km2";
    return closed + "; " + report_number(r.straits_water_km2) + " km2 of water closed with them; " +
           std::to_string(r.nodes_split) + " nodes split)";
}

std::string inlets_closed_text(const MesherReport &r) {
    return std::to_string(r.inlets_closed) + " (" + report_number(r.inlet_area_km2) + " km2)";
}

std::string ocean_components_text(const MesherReport &r) {
    std::string text;
    for (const auto &c : r.components)
        text += (text.empty() ? "" : "; ") + report_number(c.area_km2) + " km2 " +
                (c.kept ? "kept" : "dropped");
    return text;
}

std::string places_text(const std::vector<Vec3> &points, std::size_t limit) {
    std::string at;
    char buf[48];
    for (std::size_t i = 0; i < points.size() && i < limit; ++i) {
        const LonLat ll = vec_to_lonlat(points[i]);
        std::snprintf(buf, sizeof buf, "%s%.2f %.2f", i ? ", " : "", ll.lon, ll.lat);
        at += buf;
    }
    if (points.size() > limit)
        at += ", ...";
    return at;
}

std::vector<std::pair<std::string, std::string>> ocean_attributes(const OceanMesh &run) {
    /// The files list at most this many places of a kind.
    constexpr std::size_t max_places = 50;
    std::vector<std::pair<std::string, std::string>> a;
    a.emplace_back("coast_file", run.coast_file);
    a.emplace_back("coast_layer", run.coast_layer);
    if (!run.bathymetry_file.empty())
        a.emplace_back("bathymetry_file", run.bathymetry_file);
    if (const auto &d = run.depth) {
        // As sampled, before --min-depth.
        a.emplace_back("nodes_above_sea_level", std::to_string(d->above_sea_level));
        if (d->above_sea_level > 0)
            a.emplace_back("min_sampled_depth_m", report_number(d->shallowest_m));
        if (d->min_depth_m) {
            a.emplace_back("min_depth_m", report_number(*d->min_depth_m));
            a.emplace_back("nodes_raised_to_min_depth", std::to_string(d->raised));
        }
    }
    const CoastReport &c = run.coast;
    const MesherReport &m = run.mesher;
    a.emplace_back("boundary_rings", std::to_string(c.rings));
    a.emplace_back("boundary_nodes", std::to_string(c.nodes));
    a.emplace_back("islands_removed", std::to_string(c.islands_removed));
    a.emplace_back("lakes_removed", std::to_string(c.lakes_removed));
    a.emplace_back("coast_nodes_merged",
                   std::to_string(c.close_nodes_merged + m.coast_nodes_merged));
    a.emplace_back("coast_repairs", coast_repairs_text(run.coast_repairs));
    a.emplace_back("faces_on_removed_islands", std::to_string(m.island_centroids_left) + " (" +
                                                   std::to_string(m.island_centroids_moved) +
                                                   " moved off)");
    a.emplace_back("faces_on_land", land_faces_text(m));
    if (!m.land_faces_at.empty())
        a.emplace_back("faces_on_land_at", places_text(m.land_faces_at, max_places));
    if (run.straits_closing) {
        a.emplace_back("straits_closed", straits_closed_text(m));
        if (!m.straits_closed_at.empty())
            a.emplace_back("straits_closed_at", places_text(m.straits_closed_at, max_places));
        if (!m.straits_closed_width_km.empty()) {
            std::string widths;
            for (std::size_t i = 0; i < m.straits_closed_width_km.size() && i < max_places; ++i) {
                if (i)
                    widths += ", ";
                const bool measured = m.straits_closed_width_km[i] > 0; // else only a bound
                if (!measured)
                    widths += '<';
                widths += report_number(measured ? m.straits_closed_width_km[i]
                                                 : m.straits_closed_width_below_km[i]);
            }
            a.emplace_back("straits_closed_width_km", widths);
        }
    }
    a.emplace_back("ocean_area_km2", report_number(c.ocean_area_km2));
    a.emplace_back("segments_split", std::to_string(m.segments_split + m.encroached_splits));
    a.emplace_back("inlets_closed", inlets_closed_text(m));
    a.emplace_back("lattice_nodes", std::to_string(m.lattice_nodes));
    if (m.parts > 1) {
        a.emplace_back("parts", std::to_string(m.parts)); // --parts, or chosen from the estimate
        // Every digit: --parts-border given this text makes the same borders.
        char lon[32];
        const auto end = std::to_chars(lon, lon + sizeof lon, m.parts_border_lon).ptr;
        a.emplace_back("parts_border_lon", std::string(lon, end));
    }
    a.emplace_back("corners_blunted", std::to_string(m.corners_blunted));
    a.emplace_back("floor_nodes_removed", std::to_string(m.floor_nodes_removed));
    a.emplace_back("floor_nodes_added", std::to_string(m.floor_nodes_added));
    a.emplace_back("sharp_coast_corners", std::to_string(m.sharp_corners));
    a.emplace_back("faces_at_sharp_corners", std::to_string(m.sharp_corner_faces));
    a.emplace_back("ocean_components", ocean_components_text(m));
    return a;
}

} // namespace globemesh
