// --passages in a `mesh` run: the default list's place, and each passage in the summary and the
// --report JSON (mesh_summary.hpp).
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "globemesh/error.hpp"
#include "mesh_summary.hpp"

namespace globemesh::cli {

namespace fs = std::filesystem;

std::string default_passages_path() {
    constexpr const char *file = "passages.geojson";
    std::vector<fs::path> places;
    std::error_code ec;
    // Installed: beside the executable's prefix (relocatable), then the configured prefix; last
    // the source tree's fixtures, for a build that is not installed.
    if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec)
        places.push_back(exe.parent_path().parent_path() / "share" / "globemesh" / file);
    places.push_back(fs::path(GLOBEMESH_DATA_DIR) / file);
    places.push_back(fs::path(GLOBEMESH_SOURCE_DATA_DIR) / file);
    for (const fs::path &p : places)
        if (fs::is_regular_file(p, ec))
            return p.string();
    throw IoError("--passages default: the default list " + std::string(file) +
                  " is not installed (looked in " + places[1].parent_path().string() + " and " +
                  places[2].parent_path().string() + "); give a file of lines instead");
}

std::string passages_json(const OceanMesh &run) {
    std::string r = "{\"cells_needed\": " + std::to_string(run.passage_cells) + ", \"list\": [";
    for (std::size_t i = 0; i < run.passages.size(); ++i) {
        const PassageReport &p = run.passages[i];
        const LonLat at = vec_to_lonlat(p.at);
        r += std::string(i ? ", " : "") + "{\"name\": " + json_string(p.name) +
             ", \"width_km\": " + json_number(p.width_km) +
             ", \"size_km\": " + json_number(p.size_km) +
             ", \"cells\": " + std::to_string(p.cells) + ", \"lon\": " + json_number(at.lon) +
             ", \"lat\": " + json_number(at.lat) + "}";
    }
    return r + "]}";
}

void print_passages(std::ostream &out, std::ostream &err, const OceanMesh &run, bool quiet) {
    if (run.passages.empty())
        return;
    const auto fewest = std::min_element(
        run.passages.begin(), run.passages.end(),
        [](const PassageReport &a, const PassageReport &b) { return a.cells < b.cells; });
    const auto n = static_cast<std::size_t>(run.passage_cells);
    const auto short_of = std::count_if(run.passages.begin(), run.passages.end(),
                                        [&](const PassageReport &p) { return p.cells < n; });
    out << "passages          " << run.passages.size() << ", "
        << run.passages.size() - static_cast<std::size_t>(short_of) << " with >= " << n
        << " cells across (fewest " << fewest->cells << ": " << fewest->name << ", "
        << report_number(fewest->width_km) << " km wide); each in --report\n";
    if (quiet)
        return;
    for (const PassageReport &p : run.passages)
        if (p.cells < n)
            err << "globemesh: warning: passage " << p.name << " (" << report_number(p.width_km)
                << " km of water, at " << places_text({p.at}, 1) << ") has " << p.cells
                << (p.cells == 1 ? " cell" : " cells") << " across, fewer than --passage-cells "
                << n << "; check that its line runs across the strait from land to land\n";
}

} // namespace globemesh::cli
