// Quality rounds: after the smoothing, the nodes of the triangles still below q count_cap (next
// to the coast, or at valence defects) move where their star scores best, boundary nodes slide
// near the coast, pattern searches raise the worst triangles, and triangles with two or three
// boundary corners are mended.
#include "corners.hpp"
#include "mesher_state.hpp"

namespace globemesh::mesher_internal {

namespace {

// Then the nodes of triangles below this quality (away from sharp corners) get a pattern search
// for their star's best worst triangle, for this many rounds (more rounds change nothing).
constexpr double worst_goal = detail::quality_count_rule.worst_goal; // 0.6
constexpr int search_rounds = 2;
constexpr int mend_passes = 3;
// Rounds of the last, quality-driven smoothing of the nodes of triangles below q count_cap:
// past 6, a round gains under 0.02% of faces above q 0.8.
constexpr int improve_rounds = 6;
// The faces below the floor that get a node's trial (each copies the triangulation and scans its
// faces): the last few a run leaves; a mesh with more has another problem to find.
constexpr std::size_t max_floor_trials = 64;
// Those rounds move each node where its star has the most triangles above q 0.8 (the issue's),
// ties broken by the sum of the qualities capped at count_cap, with no triangle below min(the
// star's worst, worst_goal) (star_count_score), the worst up to worst_goal first (weight 1000):
// the count and the capped sum at 0.82 gave the most faces above 0.8. The nodes are those of the
// triangles below count_cap: a node whose triangles are all above it has the best score already
// and stays. The four values: detail::quality_count_rule, which the join of parts shares.
constexpr double count_cap = detail::quality_count_rule.count_cap; // 0.82
constexpr detail::CountRule count_rule = detail::quality_count_rule;

// The rounds' state: the nodes to move and the scratch of their stars (the lambdas of one
// block, as members).
class QualityRounds {
public:
    QualityRounds(Mesher &m, const MesherOptions &options, std::vector<char> &as_made)
        : m(m), dt(m.dt), options(options), as_made(as_made) {}
    void run_count_rounds();
    void run_search_rounds();
    void mend_corners();
    bool raise_floor();
    bool floor_holds() const;
    std::size_t remove_floor_nodes();
    std::size_t insert_floor_nodes();
    bool try_floor_node(TriangleId t, VertexId a, VertexId b,
                        std::pair<std::size_t, double> &before);
    std::pair<std::size_t, double> floor_faces(std::vector<TriangleId> *low) const;
    double face_quality(TriangleId t) const {
        return triangle_quality(dt.point(dt.vertex(t, 0)), dt.point(dt.vertex(t, 1)),
                                dt.point(dt.vertex(t, 2)));
    }
    bool is_cut(TriangleId t) const {
        return std::find(m.cut_sides.begin(), m.cut_sides.end(), t) != m.cut_sides.end();
    }

private:
    Mesher &m;
    SphericalDelaunay &dt;
    const MesherOptions &options;
    std::vector<char> &as_made; // per vertex: a lattice node that has not moved (smooth)
    std::vector<std::pair<VertexId, TriangleId>> todo,
        slide_todo; // collect's: interior and sliding nodes
    std::vector<char> dirty =
        std::vector<char>(dt.vertex_count(), 0); // collect's and move_checked's marks
    std::vector<Vec3> candidates;
    std::vector<VertexId> touched; // move_checked's scratch
    std::vector<FarEdge> far;      // a star's far edges b -> c (triangles v, b, c)
    std::vector<FarEdge> land_far; // slide_node's: the star's far edges on land
    std::vector<Vec3> chain;       // slide_node's: the points its search improved through

    void collect(double below, bool skip_sharp,
                 std::vector<std::pair<VertexId, TriangleId>> *fixed_todo = nullptr,
                 const std::vector<char> *near = nullptr);
    bool move_checked(VertexId v, HalfEdge from, const Vec3 &to, double floor,
                      std::vector<char> *changed, const VertexId *ends = nullptr);
    HalfEdge leaving(VertexId v, TriangleId &hint);
    double star_candidates(const Vec3 &p0);
    void count_node(VertexId v, TriangleId &hint, std::vector<char> *changed);
    void slide_node(VertexId v, TriangleId &hint, std::vector<char> *changed);
    void improve_node(VertexId v, TriangleId &hint);
};

// The nodes of the ocean triangles below `below` (those at a sharp corner left out when
// `skip_sharp`), each with a triangle next to it: the hint that finds its star in a step
// or two. Interior nodes go to `todo`; boundary nodes to `*fixed_todo` when given.
// With `near`, only the triangles with a corner marked there. Every corner of the
// triangles collected is marked in `dirty`.
void QualityRounds::collect(double below, bool skip_sharp,
                            std::vector<std::pair<VertexId, TriangleId>> *fixed_todo,
                            const std::vector<char> *near) {
    todo.clear();
    if (fixed_todo)
        fixed_todo->clear();
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        if (near && !(*near)[a] && !(*near)[b] && !(*near)[c])
            continue;
        if (skip_sharp && (m.is_sharp(a) || m.is_sharp(b) || m.is_sharp(c)))
            continue;
        if (as_made[a] && as_made[b] && as_made[c])
            continue;
        if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) >= below)
            continue;
        for (VertexId u : {a, b, c}) {
            dirty[u] = 1;
            if (!m.is_fixed(u))
                todo.emplace_back(u, t);
            else if (fixed_todo)
                fixed_todo->emplace_back(u, t);
        }
    }
    for (auto *list : {&todo, fixed_todo}) {
        if (!list)
            continue;
        std::sort(list->begin(), list->end());
        list->erase(std::unique(list->begin(), list->end(),
                                [](const auto &x, const auto &y) { return x.first == y.first; }),
                    list->end());
    }
}

// Moves v (`from` leaves it) to `to` (Mesher::move_if) when the ocean triangles the move
// and its flips leave near it all keep q >= floor and none with two or three boundary
// corners falls below quality_goal (the mending would have to split it); `ends` as in
// move_if. With `changed`, a move marks every vertex whose star it changed.
bool QualityRounds::move_checked(VertexId v, HalfEdge from, const Vec3 &to, double floor,
                                 std::vector<char> *changed, const VertexId *ends) {
    auto holds = [&](TriangleId t) {
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        const double q = triangle_quality(dt.point(a), dt.point(b), dt.point(c));
        return q >= floor &&
               (q >= quality_goal || m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2);
    };
    if (!m.move_if(from, to, ends, touched, holds, [] { return true; }))
        return false;
    as_made[v] = 0;
    // Every star the move changed: where the search rounds look for what is left.
    if (dirty.size() < dt.vertex_count())
        dirty.resize(dt.vertex_count(), 0);
    dirty[v] = 1;
    for (VertexId u : touched)
        dirty[u] = 1;
    if (changed) {
        (*changed)[v] = 1;
        for (VertexId u : touched)
            (*changed)[u] = 1;
    }
    return true;
}

// A half-edge leaving v, found from `hint` (a triangle next to v when it was collected,
// updated to one next to it now), or no_half_edge.
HalfEdge QualityRounds::leaving(VertexId v, TriangleId &hint) {
    const HalfEdge from = dt.leaving(v, dt.is_live(hint) ? hint : no_triangle);
    if (from == no_half_edge || dt.origin(from) != v)
        return no_half_edge;
    hint = triangle_of(from);
    return from;
}

// The candidates for interior node v (p0, its star's far edges `far`) and the pattern
// search's first step, 0.2 of its mean equilateral apex height.
double QualityRounds::star_candidates(const Vec3 &p0) {
    Vec3 apex{0, 0, 0}, mean{0, 0, 0};
    double step = 0;
    for (const FarEdge &e : far) {
        const double d = 0.5 * std::sqrt(3.0) * arc_angle(e.b, e.c);
        apex = apex +
               (std::cos(d) * arc_midpoint(e.b, e.c) + std::sin(d) * normalized(cross(e.b, e.c)));
        mean = mean + e.b;
        step += d;
    }
    candidates.clear();
    for (const Vec3 &p : {normalized(apex), normalized(mean)}) {
        candidates.push_back(p);
        candidates.push_back(normalized(p0 + p));
    }
    return step * 0.2 / double(far.size());
}

// The quality rounds' move of interior node v: the candidates, then a pattern search,
// for the best star_count_score.
void QualityRounds::count_node(VertexId v, TriangleId &hint, std::vector<char> *changed) {
    const HalfEdge from = leaving(v, hint);
    if (from == no_half_edge)
        return;
    if (!m.ocean_star(from, far))
        return;
    const Vec3 p0 = dt.point(v);
    const double floor = std::min(star_worst_quality(p0, far), worst_goal);
    double best = star_count_score(p0, far, count_rule, floor);
    if (best >= star_count_best(far.size(), count_rule))
        return; // every triangle above count_cap
    Vec3 to = p0;
    auto consider = [&](const Vec3 &p) {
        const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
        if (score <= best + 1e-12)
            return false;
        best = score;
        to = p;
        return true;
    };
    // Half the search rounds' first step, and 4 halvings instead of 6.
    const double step = 0.5 * star_candidates(p0);
    for (const Vec3 &p : candidates)
        consider(p);
    if (best < star_count_best(far.size(), count_rule))
        to = pattern_search(to, step, step / 16, [&](const Points8 &p) {
            return star_count_accepts(p, far, count_rule, floor, best);
        });
    if (to != p0)
        move_checked(v, from, to, floor, changed);
}

// The same for boundary node v, between two coast segments of one ring, neither end a
// sharp corner: its star's land triangles must stay counter-clockwise too, and it stays
// within slide_reach h of the source coast; the candidates lie along its two segments.
void QualityRounds::slide_node(VertexId v, TriangleId &hint, std::vector<char> *changed) {
    const HalfEdge from = leaving(v, hint);
    if (from == no_half_edge)
        return;
    VertexId ends[2];
    if (!m.slide_star(from, far, land_far, ends))
        return;
    const Vec3 p0 = dt.point(v);
    const double reach = slide_reach * km_to_rad(m.size_km(p0));
    const double floor = std::min(star_worst_quality(p0, far), worst_goal);
    double best = star_count_score(p0, far, count_rule, floor);
    if (best >= star_count_best(far.size(), count_rule))
        return; // every triangle above count_cap
    // The search scores the star alone; the coast and land rules are checked on the points
    // it improved through, from the best back.
    chain.clear();
    Vec3 to = p0;
    auto consider = [&](const Vec3 &p) {
        if (!in_region(options, p))
            return false;
        for (const FarEdge &e : land_far)
            if (predicates::orient(p, e) <= 0)
                return false;
        const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
        if (score <= best + 1e-12)
            return false;
        best = score;
        to = p;
        chain.push_back(p);
        return true;
    };
    for (VertexId e : ends)
        for (double f : {0.1, 0.2, 0.3})
            consider(normalized((1 - f) * p0 + f * dt.point(e)));
    const double step = 0.5 * reach;
    if (best < star_count_best(far.size(), count_rule))
        pattern_search(to, step, step / 8, [&](const Points8 &p) {
            const unsigned accepted =
                star_count_accepts(p, far, count_rule, floor, best, &land_far);
            for (int k = 0; k < 8; ++k)
                if (accepted >> k & 1u)
                    chain.push_back(p[k]);
            return accepted;
        });
    // The star's faces centred on land where it is now are counted only when a point
    // has some (rarely: most stars have none either way).
    int land0 = -1;
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        if (!in_region(options, *it) || !options.land->coast_within(*it, reach))
            continue;
        if (const int land = star_faces_on_land(*options.land, *it, far); land > 0) {
            if (land0 < 0)
                land0 = star_faces_on_land(*options.land, p0, far);
            if (land > land0)
                continue;
        }
        move_checked(v, from, *it, floor, changed, ends);
        return;
    }
}

// The search rounds' move: to the candidate, then, when the star is still below
// worst_goal, the point of a pattern search, that best raises the star's worst.
void QualityRounds::improve_node(VertexId v, TriangleId &hint) {
    const HalfEdge from = leaving(v, hint);
    if (from == no_half_edge)
        return;
    if (!m.ocean_star(from, far))
        return;
    const Vec3 p0 = dt.point(v);
    const double before = star_worst_quality(p0, far);
    double best = before;
    Vec3 to = p0;
    auto consider = [&](const Vec3 &p) {
        const double w = star_worst_quality(p, far, best + 1e-9);
        if (w <= best + 1e-9)
            return false;
        best = w;
        to = p;
        return true;
    };
    const double step = star_candidates(p0);
    for (const Vec3 &p : candidates)
        consider(p);
    if (best < worst_goal)
        to = pattern_search(to, step, step / 64,
                            [&](const Points8 &p) { return star_worst_accepts(p, far, best); });
    if (to != p0)
        move_checked(v, from, to, std::min(before, worst_goal), nullptr);
}

void QualityRounds::run_count_rounds() {
    collect(count_cap, false, options.land ? &slide_todo : nullptr);
    {
        // A node's move depends on its star's points alone: a node whose star has not
        // changed since it last stayed would stay again, and is skipped (the same mesh,
        // fewer evaluations). A move changes the stars of the node, its neighbours and,
        // when it needs flips, the corners of the flipped edges' quadrilaterals.
        std::vector<char> changed(dt.vertex_count(), 1);
        for (int round = 0; round < improve_rounds; ++round) {
            for (auto &[v, hint] : todo)
                if (changed[v]) {
                    changed[v] = 0;
                    count_node(v, hint, &changed);
                }
            for (auto &[v, hint] : slide_todo)
                if (changed[v]) {
                    changed[v] = 0;
                    slide_node(v, hint, &changed);
                }
        }
    }
}

void QualityRounds::run_search_rounds() {
    // Last, search_rounds rounds over the nodes of the triangles still below worst_goal
    // (away from sharp corners), collected again each round. Such a triangle was below
    // count_cap before the quality rounds, or a move changed it: only the triangles with a corner
    // marked in `dirty` are looked at.
    for (int round = 0; round < search_rounds; ++round) {
        collect(worst_goal, true, nullptr, &dirty);
        if (todo.empty())
            break;
        for (auto &[v, hint] : todo)
            improve_node(v, hint);
    }
}

void QualityRounds::mend_corners() {
    // Last, a triangle with two or three boundary corners left below quality_goal (away
    // from sharp corners) has one node or none to move, and the flips of smoothing may have
    // made it after the refinement (an ear of the coast: two segments and the edge across
    // their corner). It gets its circumcentre when that lies in the ocean without
    // encroaching on a segment, else the segment in the way is split at its midpoint (as the
    // refinement does), and the new node and its free neighbours get their search, twice; a
    // few passes, as a search may leave another such triangle.
    std::vector<TriangleId> mend;
    std::vector<std::pair<VertexId, TriangleId>> around;
    for (int pass = 0; pass < mend_passes; ++pass) {
        mend.clear();
        for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
            if (!dt.is_live(t) || dt.label(t) != ocean)
                continue;
            const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
            if (m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2 || m.is_sharp(a) ||
                m.is_sharp(b) || m.is_sharp(c))
                continue;
            if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) < quality_goal)
                mend.push_back(t);
        }
        if (mend.empty())
            break;
        for (TriangleId t : mend) {
            if (!dt.is_live(t))
                continue; // gone with an earlier one's cavity
            HalfEdge blocked;
            const Vec3 centre = m.circumcentre(t);
            const TriangleId in = m.walk_towards(t, centre, blocked);
            VertexId v = no_vertex;
            if (blocked != no_half_edge) {
                v = m.split_segment(blocked);
                if (v != no_vertex)
                    ++m.report.encroached_splits;
            } else if (dt.label(in) == ocean) {
                const std::size_t before = dt.vertex_count();
                v = dt.insert_in_triangle(centre, in);
                if (dt.vertex_count() == before)
                    v = no_vertex;
            }
            if (v == no_vertex)
                continue;
            as_made.resize(dt.vertex_count(), 0);
            around.assign(m.is_fixed(v) ? 0 : 1, {v, dt.last_triangle()});
            const HalfEdge from = dt.leaving(v, dt.last_triangle());
            HalfEdge h = from;
            do {
                if (!m.is_fixed(dt.destination(h)))
                    around.emplace_back(dt.destination(h), triangle_of(h));
                h = dt.next_around_origin(h);
            } while (h != from);
            for (int round = 0; round < 2; ++round)
                for (auto &[u, hint] : around)
                    improve_node(u, hint);
            ++m.report.corners_mended;
        }
    }
}

bool QualityRounds::raise_floor() {
    // After the land and corner clean-up, which move and remove faces after the rounds above:
    // the free nodes of the faces still below the floor (sharp corners included) get the
    // search that raises their star's worst, a few rounds; a move never lowers a star's worst.
    as_made.resize(dt.vertex_count(), 0);
    dirty.resize(dt.vertex_count(), 0);
    auto search = [&] {
        for (int round = 0; round < search_rounds; ++round) {
            collect(detail::blunt_floor, false);
            if (todo.empty())
                break;
            for (auto &[v, hint] : todo)
                improve_node(v, hint);
        }
    };
    search();
    // Then the nodes no position mends go, and the search runs again around them; last, a face
    // that neither mends gets a node on its shortest side, and the same again.
    while (remove_floor_nodes() > 0)
        search();
    if (insert_floor_nodes() > 0) {
        search();
        while (remove_floor_nodes() > 0)
            search();
    }
    return floor_holds();
}

// Whether no ocean face is below the floor (a face of three unmoved lattice nodes is not, as
// collect assumes).
bool QualityRounds::floor_holds() const {
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
        if (!(as_made[a] && as_made[b] && as_made[c]) && face_quality(t) < detail::blunt_floor)
            return false;
    }
    return true;
}

// A free node (not sharp) of a face still below the floor, whose star is all ocean, goes when
// every triangle its removal makes or changes is ocean and better than its star's worst: a node
// squeezed in a thin quadrilateral between nodes of very different spacing has no position that
// mends its faces. Returns the nodes removed (MesherReport::floor_nodes_removed).
std::size_t QualityRounds::remove_floor_nodes() {
    collect(detail::blunt_floor, false);
    std::size_t removed = 0;
    std::vector<TriangleId> star, changed;
    for (auto &[v, hint] : todo) {
        const HalfEdge from = m.is_sharp(v) ? no_half_edge : leaving(v, hint);
        if (from == no_half_edge)
            continue;
        double worst = 1;
        bool ocean_star = true;
        star.clear();
        HalfEdge h = from;
        do {
            const TriangleId t = triangle_of(h);
            ocean_star = ocean_star && dt.label(t) == ocean && !is_cut(t);
            worst = std::min(worst, face_quality(t));
            star.push_back(dt.destination(h));
            h = dt.next_around_origin(h);
        } while (h != from);
        if (!ocean_star || worst >= detail::blunt_floor)
            continue;
        auto better = [&] {
            for (TriangleId t : changed)
                if (dt.label(t) != ocean || is_cut(t) || face_quality(t) <= worst)
                    return false;
            return true;
        };
        if (!dt.remove_vertex_from(from, &changed, better))
            continue;
        ++removed;
        for (VertexId u : star)
            dirty[u] = 1;
        hint = changed.front();
    }
    m.report.floor_nodes_removed += removed;
    return removed;
}

// The faces below the floor: how many, and the worst.
std::pair<std::size_t, double> QualityRounds::floor_faces(std::vector<TriangleId> *low) const {
    std::size_t count = 0;
    double worst = 1;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean)
            continue;
        const double q = face_quality(t);
        if (q >= detail::blunt_floor)
            continue;
        ++count;
        worst = std::min(worst, q);
        if (low)
            low->push_back(t);
    }
    return {count, worst};
}

// A face still below the floor (a short side, often a coast segment, beside nodes of a much
// coarser spacing) gets a node at the apex of the equilateral triangle on one of its sides, on
// the face's side (Ungor's off-centre at its most regular), the shortest side first, and the
// search runs on the node and its free neighbours. A trial stays when it leaves fewer faces below
// the floor and none worse than before; else the triangulation is restored from a copy. Returns
// the nodes added (MesherReport::floor_nodes_added).
std::size_t QualityRounds::insert_floor_nodes() {
    std::vector<TriangleId> low;
    auto before = floor_faces(&low);
    if (low.size() > max_floor_trials)
        low.resize(max_floor_trials);
    std::size_t added = 0;
    for (TriangleId t : low) {
        if (!dt.is_live(t) || dt.label(t) != ocean || face_quality(t) >= detail::blunt_floor)
            continue; // mended by an earlier node
        std::array<std::pair<double, int>, 3> sides;
        for (int i = 0; i < 3; ++i)
            sides[i] = {arc_angle(dt.point(dt.vertex(t, i)), dt.point(dt.vertex(t, next3(i)))), i};
        std::sort(sides.begin(), sides.end());
        const std::array<VertexId, 3> corners{dt.vertex(t, 0), dt.vertex(t, 1), dt.vertex(t, 2)};
        for (const auto &side : sides)
            if (try_floor_node(t, corners[side.second], corners[next3(side.second)], before)) {
                ++added;
                break;
            }
    }
    m.report.floor_nodes_added += added;
    return added;
}

// The trial of insert_floor_nodes: a node at the apex on side a-b of face t (counter-clockwise),
// kept when the faces below the floor improve on `before` (then updated).
bool QualityRounds::try_floor_node(TriangleId t, VertexId a, VertexId b,
                                   std::pair<std::size_t, double> &before) {
    const Vec3 &pa = dt.point(a), &pb = dt.point(b);
    const double height = 0.5 * std::sqrt(3.0) * arc_angle(pa, pb);
    const Vec3 p = normalized(std::cos(height) * arc_midpoint(pa, pb) +
                              std::sin(height) * normalized(cross(pa, pb)));
    HalfEdge blocked;
    const TriangleId in = m.walk_towards(t, p, blocked);
    if (blocked != no_half_edge || dt.label(in) != ocean || is_cut(in))
        return false;
    const SphericalDelaunay saved = dt; // the trial is undone exactly by restoring it
    const std::size_t vertices = dt.vertex_count();
    const VertexId v = dt.insert_in_triangle(p, in);
    bool kept = dt.vertex_count() > vertices;
    std::vector<std::pair<VertexId, TriangleId>> around;
    if (kept) {
        as_made.resize(dt.vertex_count(), 0);
        dirty.resize(dt.vertex_count(), 0);
        const HalfEdge from = dt.leaving(v, dt.last_triangle());
        around.assign(1, {v, triangle_of(from)});
        HalfEdge h = from;
        do {
            kept = kept && dt.label(triangle_of(h)) == ocean && !is_cut(triangle_of(h));
            if (!m.is_fixed(dt.destination(h)))
                around.emplace_back(dt.destination(h), triangle_of(h));
            h = dt.next_around_origin(h);
        } while (h != from);
    }
    for (int round = 0; kept && round < 2; ++round)
        for (auto &[u, hint] : around)
            improve_node(u, hint);
    const auto after = kept ? floor_faces(nullptr) : before;
    if (!kept || after.first >= before.first || after.second < before.second) {
        dt = saved;
        return false;
    }
    before = after;
    for (const auto &[u, hint] : around)
        dirty[u] = 1;
    return true;
}

} // namespace

bool raise_quality_floor(Mesher &m, const MesherOptions &options, std::vector<char> &as_made) {
    return QualityRounds(m, options, as_made).raise_floor();
}

void improve_quality(Mesher &m, const MesherOptions &options, std::vector<char> &as_made) {
    QualityRounds rounds(m, options, as_made);
    rounds.run_count_rounds();
    rounds.run_search_rounds();
    rounds.mend_corners();
}

} // namespace globemesh::mesher_internal
