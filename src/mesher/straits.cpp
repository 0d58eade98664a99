// Straits narrower than a face closed.
#include <algorithm>
#include <numeric>

#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

// Closes the straits narrower than a face that `faces` (those still centred on land after the
// nudge) lie across (MesherOptions::close_straits): remove_land_faces with `straits`. The
// small pieces a closing cut the mesh into go (close_small_pieces). Leaves in `faces` those
// still on land.
void close_straits(Mesher &m, const LandTest &land_test, std::vector<TriangleId> &faces,
                   const MesherOptions &options, BoundaryLoops &loops, MesherReport &report) {
    SphericalDelaunay &dt = m.dt;
    auto is_ocean = [&](TriangleId t) { return dt.is_live(t) && dt.label(t) == ocean; };
    std::vector<TriangleId> left;
    // The faces across a passage stay (with those left on land).
    const auto kept = std::stable_partition(
        faces.begin(), faces.end(), [&](TriangleId t) { return !on_passage(m, options, t); });
    std::vector<TriangleId> passage_faces(kept, faces.end());
    faces.erase(kept, faces.end());
    const std::size_t sides_before = m.cut_sides.size();
    remove_land_faces(m, land_test, faces, options, report, left, loops, true);
    close_small_pieces(m, {m.cut_sides.begin() + std::ptrdiff_t(sides_before), m.cut_sides.end()},
                       options, &land_test, report);
    faces.clear();
    for (const TriangleId t : left)
        if (is_ocean(t))
            faces.push_back(t);
    for (const TriangleId t : passage_faces)
        if (is_ocean(t))
            faces.push_back(t);
}

namespace {

constexpr int passage_rings = 16; // passage_width's grid: rings of samples out to its reach

// The width (radians) of the narrowest passage of the water around p, within `reach`: twice the
// bottleneck distance to the coast on the water path, sampled on a polar grid, that joins two
// separate stretches of water on the grid's rim (the widest such path: a maximin, samples added
// from the farthest from the coast). 0 when the rim has one stretch of water or none, or when the
// water there is narrower than the grid.
double passage_width(const LandTest &land, const Vec3 &p, double reach) {
    constexpr int rings = passage_rings, spokes = 48;
    const Vec3 east =
        normalized(std::abs(p.z) < 0.9 ? cross(Vec3{0, 0, 1}, p) : cross(Vec3{1, 0, 0}, p));
    const Vec3 north = cross(p, east);
    const int n = 1 + rings * spokes; // sample 0 is p; ring r, spoke k is 1 + (r - 1) * spokes + k
    auto index = [&](int r, int k) {
        return r == 0 ? 0 : 1 + (r - 1) * spokes + (k + spokes) % spokes;
    };
    auto sample = [&](int r, int k) {
        const double d = reach * r / rings, a = 2 * M_PI * k / spokes;
        return normalized(std::cos(d) * p +
                          std::sin(d) * (std::cos(a) * east + std::sin(a) * north));
    };
    // The rim's stretches of water first (each rim sample's stretch, -1 on land): most closings
    // have one stretch or none at some zooms, where the inner samples are not needed.
    std::vector<char> rim_water(spokes);
    for (int k = 0; k < spokes; ++k)
        rim_water[k] = !land.contains(sample(rings, k));
    std::vector<int> stretch(spokes, -1);
    int stretches = 0;
    for (int k = 0; k < spokes; ++k)
        if (rim_water[k] && !rim_water[(k + spokes - 1) % spokes])
            stretch[k] = stretches++;
    // (A rim all water is one stretch: no passage to measure.)
    if (stretches < 2)
        return 0;
    std::vector<double> clearance(n, -1); // -1: land
    for (int r = 0; r <= rings; ++r)
        for (int k = 0; k < (r ? spokes : 1); ++k)
            if (const Vec3 q = sample(r, k); r == rings ? rim_water[k] : !land.contains(q))
                clearance[index(r, k)] = land.coast_distance(q, reach);
    for (int k = 0; k < 2 * spokes; ++k)
        if (stretch[k % spokes] < 0 && clearance[index(rings, k)] >= 0)
            stretch[k % spokes] = stretch[(k + spokes - 1) % spokes];
    std::vector<int> order, reached(n, -1); // reached: a stretch the component touches
    for (int i = 0; i < n; ++i)
        if (clearance[i] >= 0)
            order.push_back(i);
    std::sort(order.begin(), order.end(),
              [&](int x, int y) { return clearance[x] > clearance[y]; });
    DisjointSets components(static_cast<std::size_t>(n));
    auto root = [&](int x) { return int(components.find(std::uint32_t(x))); };
    std::vector<char> added(n, 0);
    for (const int i : order) {
        added[i] = 1;
        const int r = i == 0 ? 0 : 1 + (i - 1) / spokes, k = i == 0 ? 0 : (i - 1) % spokes;
        if (r == rings)
            reached[i] = stretch[k];
        std::vector<int> next;
        if (r == 0)
            for (int j = 0; j < spokes; ++j)
                next.push_back(index(1, j));
        else
            next = {index(r - 1, k), index(r, k - 1), index(r, k + 1)};
        if (r > 0 && r < rings)
            next.push_back(index(r + 1, k));
        for (const int j : next) {
            if (!added[j])
                continue;
            const int a = root(i), b = root(j);
            if (a == b)
                continue;
            if (reached[a] >= 0 && reached[b] >= 0 && reached[a] != reached[b])
                return 2 * clearance[i];
            components.join(std::uint32_t(a), std::uint32_t(b));
            if (reached[a] < 0)
                reached[a] = reached[b];
        }
    }
    return 0;
}

} // namespace

void measure_closed_straits(const SizeFn &size_km, const LandTest &land, MesherReport &report) {
    // From 0.6 h (about the closed face's circumradius) in to 0.6 h / 64: the narrowest passage
    // found at any of these scales (at the widest, the rim may cross one sea twice around a cape,
    // joined by open water; closer in, only the strait joins the two sides). A passage found at
    // none is narrower than the finest grid's spacing, which bounds it.
    constexpr int zooms = 4;
    report.straits_closed_width_km.clear();
    report.straits_closed_width_below_km.clear();
    for (const Vec3 &p : report.straits_closed_at) {
        double reach = 0.6 * km_to_rad(size_km(p)), width = 0;
        for (int zoom = 0; zoom < zooms; ++zoom, reach /= 4)
            if (const double w = passage_width(land, p, reach); w > 0 && (width == 0 || w < width))
                width = w;
        report.straits_closed_width_km.push_back(width * earth_radius_km);
        report.straits_closed_width_below_km.push_back(
            width > 0 ? 0 : 4 * reach / passage_rings * earth_radius_km);
    }
}

// Closings in a chain of steps each shorter than the size (the larger of its two ends') are one
// place: union-find over the pairs, found in order of z within the largest size.
void group_closed_straits(const SizeFn &size_km, MesherReport &report) {
    const std::vector<Vec3> &at = report.straits_closed_at;
    const std::size_t n = at.size();
    std::vector<double> h(n);
    double most = 0;
    for (std::size_t i = 0; i < n; ++i)
        most = std::max(most, h[i] = km_to_rad(size_km(at[i])));
    std::vector<std::uint32_t> by_z(n);
    std::iota(by_z.begin(), by_z.end(), 0u);
    std::sort(by_z.begin(), by_z.end(), [&](std::uint32_t a, std::uint32_t b) {
        return at[a].z != at[b].z ? at[a].z < at[b].z : a < b;
    });
    DisjointSets chains(n);
    for (std::size_t k = 0; k < n; ++k)
        for (std::size_t l = k + 1; l < n && at[by_z[l]].z - at[by_z[k]].z < most; ++l) {
            const std::uint32_t i = by_z[k], j = by_z[l];
            if (arc_angle(at[i], at[j]) < std::max(h[i], h[j]))
                chains.join(j, i);
        }
    const std::vector<std::uint32_t> root = std::move(chains).roots();
    std::vector<std::uint32_t> place_of_root(n, UINT32_MAX);
    report.straits_closed_place.assign(n, 0);
    report.straits_closed_places = 0;
    for (std::size_t i = 0; i < n; ++i) {
        std::uint32_t &place = place_of_root[root[i]];
        if (place == UINT32_MAX)
            place = static_cast<std::uint32_t>(report.straits_closed_places++);
        report.straits_closed_place[i] = place;
    }
}

void clear_land(Mesher &m, const MesherOptions &options, std::vector<TriangleId> island_faces) {
    MesherReport &report = m.report;
    std::vector<TriangleId> left;
    BoundaryLoops loops;
    remove_land_faces(m, *options.land, std::move(island_faces), options, report, left, loops);
    report.land_faces_nudged =
        nudge_off_land(m, *options.land, options, left, left, report.land_faces_at);
    if (options.close_straits && !left.empty()) {
        close_straits(m, *options.land, left, options, loops, report);
        close_dead_ends(m, options, report);
        report.land_faces_at.clear();
        if (!left.empty())
            report.land_faces_nudged +=
                nudge_off_land(m, *options.land, options, left, left, report.land_faces_at);
    } else {
        close_dead_ends(m, options, report); // the short chords alone
    }
    report.land_faces_left = report.land_faces_at.size();
}

// A corner's split of a segment that a land removal drew across a strip of water narrower than a
// face makes faces over the land beside it (ne_50m_land, --region -100,70,-70,90 at 50 km: a face
// centred on land at 85.86W 70.05N): they go, or are nudged off, as clear_land's did.
void clear_land_after_splits(Mesher &m, const MesherOptions &options, VertexId first_new) {
    std::vector<TriangleId> faces;
    for (TriangleId t = 0; t < m.dt.triangle_slots(); ++t)
        if (m.dt.is_live(t) && m.dt.label(t) == ocean &&
            std::max({m.dt.vertex(t, 0), m.dt.vertex(t, 1), m.dt.vertex(t, 2)}) >= first_new &&
            options.land->contains(m.centroid(t)))
            faces.push_back(t);
    if (faces.empty())
        return;
    MesherReport &report = m.report;
    std::vector<TriangleId> left;
    BoundaryLoops loops;
    remove_land_faces(m, *options.land, std::move(faces), options, report, left, loops);
    report.land_faces_nudged +=
        nudge_off_land(m, *options.land, options, left, left, report.land_faces_at);
    report.land_faces_left = report.land_faces_at.size();
}

} // namespace globemesh::mesher_internal
