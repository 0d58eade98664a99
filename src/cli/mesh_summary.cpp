// The summary and the --report JSON of a `mesh` run (mesh_summary.hpp).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "globemesh/sphere.hpp"
#include "globemesh/writers.hpp"
#include "mesh_summary.hpp"

namespace globemesh::cli {

namespace {

/// A whole number with thousands separators: 33251 -> "33,251", -2505 -> "-2,505".
std::string grouped(long long v) {
    std::string digits = std::to_string(v < 0 ? -v : v), r;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0)
            r += ',';
        r += digits[i];
    }
    return (v < 0 ? "-" : "") + r;
}

/// The depth counts (nodes above sea level as sampled, those --min-depth raised) as a JSON object.
std::string depth_json(const DepthReport &d) {
    auto number_or_null = [](bool set, double v) {
        return set ? report_number(v) : std::string("null");
    };
    return "{\"nodes_above_sea_level\": " + std::to_string(d.above_sea_level) +
           ", \"min_sampled_depth_m\": " + number_or_null(d.above_sea_level > 0, d.shallowest_m) +
           ", \"min_depth_m\": " +
           number_or_null(d.min_depth_m.has_value(), d.min_depth_m.value_or(0)) +
           ", \"nodes_raised_to_min_depth\": " + std::to_string(d.min_depth_m ? d.raised : 0) + "}";
}

/// The summary's depth line, and unless `quiet` the warning on `err` when nodes above sea level
/// are written with negative depth (no --min-depth); when most of the ocean's nodes are, the
/// raster's sign is the likely cause (depth read as height, or height as depth), and the warning
/// names --depth-positive instead: --min-depth would flatten the whole ocean to it.
void print_depth(std::ostream &out, std::ostream &err, const DepthReport &d, bool depth_positive,
                 bool quiet) {
    const auto count = static_cast<long long>(d.above_sea_level);
    std::string down_to;
    if (d.above_sea_level > 0)
        down_to = " (down to " + grouped(std::llround(d.shallowest_m)) + " m)";
    out << "depth             " << count << " nodes above sea level" << down_to;
    if (d.min_depth_m)
        out << ", " << d.raised << " raised to --min-depth " << report_number(*d.min_depth_m)
            << " m";
    out << "\n";
    if (quiet)
        return;
    if (2 * d.above_sea_level > d.nodes)
        err << "globemesh: warning: " << grouped(count) << " of the "
            << grouped(static_cast<long long>(d.nodes))
            << " nodes lie above sea level: does --bathy hold "
            << (depth_positive ? "heights (positive up)? then leave out --depth-positive"
                               : "depths (positive down)? then pass --depth-positive")
            << "\n";
    else if (count > 0 && !d.min_depth_m)
        err << "globemesh: warning: " << grouped(count)
            << (count == 1 ? " node lies" : " nodes lie") << " above sea level" << down_to
            << (count == 1 ? " and is" : " and are")
            << " written with negative depth; --min-depth 5 would raise them to 5 m\n";
}

/// The cells a strait needs across to stay open (the size it needs: its width over this).
constexpr double strait_cells = 2;
/// The quality floor the mesher keeps where straits close (issue 37's, mesher/corners.hpp).
constexpr double quality_floor = 0.3;

/// Whether the closings have their places (MesherReport::straits_closed_place); where not, each
/// is a place of its own.
bool grouped(const MesherReport &m) {
    return m.straits_closed_place.size() == m.straits_closed_at.size();
}

std::uint32_t place_of(const MesherReport &m, std::size_t i) {
    return grouped(m) ? m.straits_closed_place[i] : static_cast<std::uint32_t>(i);
}

/// Closing i's width, or the bound it is under when narrower than the sampling (width 0).
double width_bound(const MesherReport &m, std::size_t i) {
    return m.straits_closed_width_km[i] > 0 ? m.straits_closed_width_km[i]
                                            : m.straits_closed_width_below_km[i];
}

/// The summary's lines of the closed straits: the first six places, each by its narrowest
/// closing (its width and the size it needs), with how many closings it holds.
void print_straits(std::ostream &out, const MesherReport &m) {
    constexpr std::size_t shown = 6;
    const std::size_t n = m.straits_closed_at.size();
    const std::size_t places = grouped(m) ? m.straits_closed_places : n;
    std::vector<std::size_t> narrowest(places, n), closings(places, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t p = place_of(m, i);
        ++closings[p];
        if (narrowest[p] == n || width_bound(m, i) < width_bound(m, narrowest[p]))
            narrowest[p] = i;
    }
    for (std::size_t p = 0; p < places && p < shown; ++p) {
        const std::size_t i = narrowest[p];
        const LonLat ll = vec_to_lonlat(m.straits_closed_at[i]);
        const double w = m.straits_closed_width_km[i];
        const std::string width =
            w > 0 ? report_number(w) + " km wide: needs h <= "
                  : "under " + report_number(width_bound(m, i)) + " km wide: needs h < ";
        const std::string along =
            closings[p] > 1 ? " (" + std::to_string(closings[p]) + " closings there)" : "";
        char line[96];
        std::snprintf(line, sizeof line, "                  at %.2f %.2f, ", ll.lon, ll.lat);
        out << line << width << report_number(width_bound(m, i) / strait_cells) << " km" << along
            << "\n";
    }
    if (places > shown)
        out << "                  ... " << places - shown
            << " more places (every closing in --report's straits_closed; the first in "
               "straits_closed_at)\n";
}

/// The warning on `err` that straits were closed, and how to keep them.
void warn_straits(std::ostream &err, const MesherReport &m) {
    err << "globemesh: warning: " << m.straits_closed
        << (m.straits_closed == 1 ? " strait narrower than its faces was closed"
                                  : " straits narrower than their faces were closed")
        << " at " << m.straits_closed_places
        << (m.straits_closed_places == 1 ? " place" : " places")
        << " (listed in the summary); keep one open with --passages (a line drawn across it, or "
           "'default' for the world's critical passages) or --size-regions (h at most half its "
           "width there), every channel with --feature-size 3, or all with --keep-straits\n";
}

/// The warning on `err` that --keep-straits left faces centred on land across straits narrower
/// than them (the mesh's worst faces, often: a face across a strait spans it from coast to
/// coast), and how to resolve such a strait instead.
void warn_kept_straits(std::ostream &err, const MesherReport &m, double quality_min) {
    err << "globemesh: warning: --keep-straits kept " << m.land_faces_left
        << (m.land_faces_left == 1 ? " face" : " faces")
        << " centred on land across straits narrower than a face (listed in the summary under "
           "'faces on land'; the mesh's worst face has q "
        << report_number(std::round(quality_min * 1000) / 1000)
        << "); resolve a strait with --size-regions (h at most half its width there) or every "
           "channel with --feature-size 3\n";
}

/// The warning on `err` that --keep-straits left a face below the floor (q 0.3, issue 37's; the
/// mesher's own guarantee where straits close) in water: a channel narrowing to a point between
/// two coasts, its faces squeezed (GSHHG i in the Sundarbans at 1.3 km: q 0.108, no face on land).
void warn_thin_channels(std::ostream &err, const Mesh &mesh) {
    double worst = 2;
    std::size_t at = 0;
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &t = mesh.faces[f];
        const double q = triangle_quality(mesh.nodes[t[0]], mesh.nodes[t[1]], mesh.nodes[t[2]]);
        if (q < worst)
            worst = q, at = f;
    }
    const auto &t = mesh.faces[at];
    const LonLat ll =
        vec_to_lonlat(normalized(mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]));
    char place[64];
    std::snprintf(place, sizeof place, "lon %.3f, lat %.3f", ll.lon, ll.lat);
    err << "globemesh: warning: --keep-straits kept channels narrower than a face open; the "
           "mesh's worst face has q "
        << report_number(std::round(worst * 1000) / 1000) << " at " << place
        << "; resolve a channel with --size-regions (h at most half its width there) or every "
           "channel with --feature-size 3\n";
}

/// The warning on `err` that a region's ocean fell into pieces and one enclosed by the coast
/// (no edge on the region's outline: water that joins no ocean outside the region) was dropped,
/// where it holds a tenth of the largest's area or more, and how to keep them all.
void warn_region_pieces(std::ostream &err, const MesherReport &m) {
    double kept = 0, dropped = 0;
    std::size_t count = 0;
    for (const OceanComponent &c : m.components) {
        if (c.kept)
            kept = std::max(kept, c.area_km2);
        else
            dropped = std::max(dropped, c.area_km2), ++count;
    }
    if (count == 0 || dropped < 0.1 * kept)
        return;
    err << "globemesh: warning: the region's ocean is in pieces apart; " << count
        << (count == 1 ? " piece" : " pieces") << " enclosed by the coast"
        << (count == 1 ? " is" : " are") << " dropped beside the largest kept ("
        << report_number(kept) << " km2; the largest dropped " << report_number(dropped)
        << " km2); --keep-inland-seas meshes them all\n";
}

/// The closed straits in the --report JSON: place, width and the size each needs.
std::string straits_json(const MesherReport &m) {
    std::string r = "[";
    for (std::size_t i = 0; i < m.straits_closed_at.size(); ++i) {
        const LonLat ll = vec_to_lonlat(m.straits_closed_at[i]);
        // A passage narrower than the sampling: its width is null, under width_below_km.
        const double w = m.straits_closed_width_km[i], below = m.straits_closed_width_below_km[i];
        r += std::string(i ? ", " : "") + "{\"lon\": " + json_number(ll.lon) +
             ", \"lat\": " + json_number(ll.lat) +
             ", \"width_km\": " + (w > 0 ? json_number(w) : std::string("null")) +
             (w > 0 ? "" : ", \"width_below_km\": " + json_number(below)) +
             ", \"size_needed_km\": " + json_number(width_bound(m, i) / strait_cells) +
             ", \"place\": " + std::to_string(place_of(m, i)) + "}";
    }
    return r + "]";
}

/// What the run changed of the coast and the land: the summary's lines from the typed reports.
void print_coast(std::ostream &out, const OceanMesh &run) {
    const MesherReport &m = run.mesher;
    out << "coast             " << run.coast.rings << " rings kept, islands dropped "
        << run.coast.islands_removed << ", lakes dropped " << run.coast.lakes_removed
        << ", close nodes merged " << run.coast.close_nodes_merged + m.coast_nodes_merged
        << ", inlets closed " << inlets_closed_text(m) << ", corners blunted " << m.corners_blunted
        << ", floor nodes removed " << m.floor_nodes_removed << " / added " << m.floor_nodes_added
        << "\n"
        << "coast repairs     " << coast_repairs_text(run.coast_repairs) << "\n"
        << "faces on land     " << land_faces_text(m) << "\n";
    // The first six places (lon lat); all of them, up to 50, are in the file's attribute `key`.
    auto places = [&](const std::vector<Vec3> &at, const char *key) {
        constexpr std::size_t shown = 6;
        if (at.empty())
            return;
        out << "                  at " << places_text(at, shown)
            << (at.size() > shown ? std::string(" (") + key + ")" : "") << "\n";
    };
    places(m.land_faces_at, "faces_on_land_at");
    if (run.straits_closing && m.straits_closed > 0) {
        out << "straits closed    " << straits_closed_text(m) << "\n";
        print_straits(out, m);
    }
    out << "ocean components  " << ocean_components_text(m) << "\n";
    if (m.parts > 1)
        out << "parts             " << m.parts << " lunes meshed apart and joined (--parts; of "
            << m.estimated_nodes << " nodes estimated), the first border at "
            << report_number(m.parts_border_lon) << " E (--parts-border)\n";
}

} // namespace

std::string report_json(const MeshRunSummary &s) {
    const Mesh &mesh = s.run.mesh;
    std::ostringstream r;
    r << "{\n  \"globemesh\": " << json_string(GLOBEMESH_VERSION) << ",\n"
      << "  \"history\": " << json_string(s.history) << ",\n"
      << "  \"outputs\": " << outputs_json(s.planned);
    r << ",\n  \"mesh\": " << stats_json(s.stats, "  ") << ",\n";
    if (s.run.depth)
        r << "  \"depth\": " << depth_json(*s.run.depth) << ",\n";
    if (s.run.straits_closing)
        r << "  \"straits_closed\": " << straits_json(s.run.mesher) << ",\n";
    if (!s.run.passages.empty())
        r << "  \"passages\": " << passages_json(s.run) << ",\n";
    // What the run did to the coast and the land, as the NetCDF file's global attributes say.
    r << "  \"attributes\": {";
    for (std::size_t i = 0; i < mesh.attributes.size(); ++i)
        r << (i ? ", " : "") << json_string(mesh.attributes[i].first) << ": "
          << json_string(mesh.attributes[i].second);
    r << "},\n"
      << "  \"stages\": " << stages_json(s.timings) << ",\n"
      << "  \"total_seconds\": " << json_number(s.total_s) << ",\n"
      << "  \"peak_memory_bytes\": " << s.peak << "\n}\n";
    return r.str();
}

/// Warns when a whole-globe mesh covers less than half the sphere: more land than ocean is a
/// layer of water read as land (Natural Earth's 'ocean' layer meshes the continents), as the
/// Earth's land is 29% of it.
void warn_more_land_than_ocean(std::ostream &err, const MeshRunSummary &s) {
    const double sphere_km2 = 4 * pi * earth_radius_km * earth_radius_km;
    const double share = s.stats.area_km2 / sphere_km2;
    if (s.run.mesh.faces.empty() || share >= 0.5)
        return;
    char text[200];
    std::snprintf(text, sizeof text,
                  "globemesh: warning: the mesh covers %.0f%% of the globe and the land %.0f%%: ",
                  100 * share, 100 * (1 - share));
    err << text << "--coast takes land polygons; is layer '" << s.run.coast_layer << "' water?\n";
}

void print_mesh_summary(std::ostream &out, std::ostream &err, const MeshRunSummary &s) {
    const CliOptions &o = s.options;
    print_stats(out, s.stats, false);
    print_coast(out, s.run);
    print_passages(out, err, s.run, o.quiet);
    if (s.run.depth)
        print_depth(out, err, *s.run.depth, o.mesh.depth_positive, o.quiet);
    if (s.run.straits_closing && s.run.mesher.straits_closed > 0 && !o.quiet)
        warn_straits(err, s.run.mesher);
    if (!s.run.straits_closing && s.run.mesher.land_faces_left > 0 && !o.quiet)
        warn_kept_straits(err, s.run.mesher, s.stats.quality_min);
    else if (o.mesh.keep_straits && !s.run.mesh.faces.empty() &&
             s.stats.quality_min < quality_floor && !o.quiet)
        warn_thin_channels(err, s.run.mesh);
    if ((o.mesh.region || !o.mesh.region_file.empty()) && !o.mesh.keep_inland_seas && !o.quiet)
        warn_region_pieces(err, s.run.mesher);
    if (!o.mesh.region && o.mesh.region_file.empty() && !o.quiet)
        warn_more_land_than_ocean(err, s);
    print_timings(out, s.timings); // its last line: the total
    out << "peak memory       " << exact_text(std::round(s.peak / 1048576.0 * 10) / 10) << " MiB\n"
        << "wrote             " << outputs_text(s.planned, &s.run.mesh);
    for (const auto *p : {&o.timings, &o.report})
        if (!p->empty())
            out << ", " << *p;
    out << "\n";
}

} // namespace globemesh::cli
