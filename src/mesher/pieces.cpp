// The small pieces closings cut the mesh into, closed by the inlet rule.
#include "globemesh/passages.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

bool on_passage(const Mesher &m, const MesherOptions &options, TriangleId t) {
    const SphericalDelaunay &dt = m.dt;
    const Vec3 &a = dt.point(dt.vertex(t, 0)), &b = dt.point(dt.vertex(t, 1)),
               &c = dt.point(dt.vertex(t, 2));
    for (const std::vector<Vec3> &line : options.passages)
        if (line_meets_triangle(line, a, b, c))
            return true;
    return false;
}

namespace {

// A flood over shared edges from one face beside a closing; floods that meet are one piece
// (union-find), whose sums are kept at its root.
struct Flood {
    std::vector<TriangleId> faces; // visited; those before `next` counted in the root's sums
    std::size_t next = 0;
    std::uint32_t parent;
    double area = 0, perimeter = 0; // the piece's, at its root (radians)
    bool open = false;              // the piece touches an open (sea) boundary
};

class Pieces {
public:
    Pieces(Mesher &m, const MesherOptions &options) : m(m), dt(m.dt), options(options) {}

    void flood_from(const std::vector<TriangleId> &sides) {
        for (const TriangleId t : sides)
            if (is_ocean(t) && piece.emplace(t, static_cast<std::uint32_t>(floods.size())).second)
                floods.push_back({{t}, 0, static_cast<std::uint32_t>(floods.size())});
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            grow(f);
    }

    // The whole pieces (none of their floods has faces left) but the largest when no piece is
    // left growing (every piece beside the cuts small: one of them stays).
    std::vector<std::uint32_t> whole() {
        std::vector<std::uint32_t> out;
        std::vector<char> growing(floods.size(), 0);
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (floods[f].next < floods[f].faces.size())
                growing[root(f)] = 1;
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == f && !growing[f])
                out.push_back(f);
        if (std::find(growing.begin(), growing.end(), 1) == growing.end() && !out.empty())
            out.erase(
                std::max_element(out.begin(), out.end(), [&](std::uint32_t x, std::uint32_t y) {
                    return floods[x].area < floods[y].area;
                }));
        return out;
    }

    // Closes piece k when the inlet rule would and it touches no open boundary nor a passage.
    void close_if_small(std::uint32_t k, const LandTest *land_test, MesherReport &report) {
        const Flood &p = floods[k];
        const double h = km_to_rad(m.size_km(m.centroid(p.faces[0])));
        if (p.open || !inlet_closes(p.area, p.perimeter, h, options) || passes_through(k))
            return;
        report.straits_water_km2 += p.area * earth_radius_km * earth_radius_km;
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == k)
                for (const TriangleId t : floods[f].faces) {
                    dt.set_label(t, land);
                    ++(land_test && land_test->contains(m.centroid(t))
                           ? report.land_faces_removed
                           : report.water_faces_removed);
                }
    }

private:
    bool is_ocean(TriangleId t) const { return dt.is_live(t) && dt.label(t) == ocean; }

    std::uint32_t root(std::uint32_t f) {
        while (floods[f].parent != f)
            f = floods[f].parent = floods[floods[f].parent].parent;
        return f;
    }

    // Flood f until whole or its piece holds over inlet_narrow_area h^2 (then it stays whatever
    // it is: the ocean, or a sea cut off).
    void grow(std::uint32_t f) {
        const double h = km_to_rad(m.size_km(m.centroid(floods[f].faces[0])));
        const double cap = inlet_narrow_area * h * h;
        while (floods[f].next < floods[f].faces.size() && floods[root(f)].area <= cap) {
            const TriangleId t = floods[f].faces[floods[f].next++];
            Flood &r = floods[root(f)];
            r.area += spherical_triangle_area(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                              dt.point(dt.vertex(t, 2)));
            for (int i = 0; i < 3; ++i) {
                const TriangleId n = dt.neighbour(t, i);
                if (!is_ocean(n)) {
                    const VertexId x = dt.vertex(t, next3(i)), y = dt.vertex(t, prev3(i));
                    r.perimeter += arc_angle(dt.point(x), dt.point(y));
                    r.open = r.open || m.is_open(x, y);
                    continue;
                }
                const auto [it, added] = piece.emplace(n, f);
                if (added) {
                    floods[f].faces.push_back(n);
                } else if (const std::uint32_t g = root(it->second), rf = root(f); g != rf) {
                    floods[g].parent = rf; // the same piece: its sums go to one root
                    floods[rf].area += floods[g].area;
                    floods[rf].perimeter += floods[g].perimeter;
                    floods[rf].open = floods[rf].open || floods[g].open;
                }
            }
        }
    }

    // A piece a passage runs through stays.
    bool passes_through(std::uint32_t k) {
        for (std::uint32_t f = 0; f < floods.size(); ++f)
            if (root(f) == k)
                for (const TriangleId t : floods[f].faces)
                    if (on_passage(m, options, t))
                        return true;
        return false;
    }

    Mesher &m;
    SphericalDelaunay &dt;
    const MesherOptions &options;
    std::vector<Flood> floods;
    std::unordered_map<TriangleId, std::uint32_t> piece;
};

} // namespace

// The pieces beside the closings `sides`, each flooded until whole or over inlet_narrow_area
// h^2. Of the whole ones (all but the largest when every piece is whole), those close_inlets'
// rule would close go (at most inlet_area h^2 of water, or narrow on average and at most
// inlet_narrow_area h^2: the rest of a strait, a narrow sound, a face hanging at a pinched
// node), unless they touch an open boundary or a passage runs through them; the others stay
// as basins of their own (report.seas_cut_off).
void close_small_pieces(Mesher &m, const std::vector<TriangleId> &sides,
                        const MesherOptions &options, const LandTest *land_test,
                        MesherReport &report) {
    Pieces pieces(m, options);
    pieces.flood_from(sides);
    for (const std::uint32_t k : pieces.whole())
        pieces.close_if_small(k, land_test, report);
}

// The pieces beside the cuts and pinches (Mesher::cut_sides), after every closing: a face or
// two left hanging at a pinched node go (the output splits the node, so they stand apart).
void close_cut_off_pieces(Mesher &m, const MesherOptions &options, MesherReport &report) {
    if (options.close_pieces_apart && options.inlet_width > 0 && !m.cut_sides.empty())
        close_small_pieces(m, m.cut_sides, options, options.land.get(), report);
}

} // namespace globemesh::mesher_internal
