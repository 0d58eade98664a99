#include "globemesh/mesher.hpp"

#include "mesher_state.hpp"


#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "globemesh/delaunay.hpp"
#include "globemesh/error.hpp"
#include "globemesh/predicates.hpp"
#include "../delaunay/hilbert.hpp"
#include "star_search.hpp"

namespace globemesh {

namespace mesher_internal {
namespace {

// The tuned constants of the stages still here (bench/RESULTS-mesher.md has the measurements).
// Then the nodes of triangles below this quality (away from sharp corners) get a pattern search
// for their star's best worst triangle, for this many rounds (more rounds change nothing).
constexpr double worst_goal = 0.6;
constexpr int search_rounds = 2;
constexpr int mend_passes = 3;
// Rounds of the last, quality-driven smoothing of the nodes of triangles below q count_cap:
// past 6, a round gains under 0.02% of faces above q 0.8.
constexpr int improve_rounds = 6;
// Those rounds move each node where its star has the most triangles above count_quality (the
// issue's q 0.8), ties broken by the sum of the qualities capped at count_cap, with no triangle
// below min(the star's worst, worst_goal) (star_count_score): the count and the capped sum at
// 0.82 gave the most faces above 0.8. The nodes are those of the triangles below count_cap: a
// node whose triangles are all above it has the best score already and stays.
constexpr double count_quality = 0.8;
constexpr double count_cap = 0.82;
constexpr double count_worst_weight = 1000; // the worst up to worst_goal comes first
constexpr detail::CountRule count_rule{worst_goal, count_quality, count_cap, count_worst_weight};
// The output splits a node between two fans of ocean (close_straits) this far into each fan.
constexpr double pinch_apart = 1e-7; // 0.64 m

} // namespace
} // namespace mesher_internal

using namespace mesher_internal;

Mesh mesh_boundary(const Boundary& boundary, const std::function<double(const Vec3&)>& size_km,
                   const MesherOptions& options, MesherReport* report_out, const Progress& progress,
                   StageTimings* timings) {
    MesherReport local_report;
    MesherReport& report = report_out ? *report_out : local_report;
    report = MesherReport{};
    Mesher m(SphericalDelaunay::Options{1e-12, options.seed}, size_km, report);
    SphericalDelaunay& dt = m.dt;

    // ---- 1. boundary nodes and segments --------------------------------------------------------
    auto t0 = Clock::now();
    const std::vector<VertexId> ids = insert_boundary(m, boundary);
    globemesh::report(progress, 0.05, "insert_boundary");
    if (timings) timings->add("insert_boundary", seconds_since(t0));
    t0 = Clock::now();
    recover_segments(m, boundary, ids);
    globemesh::report(progress, 0.1, "recover");
    if (timings) timings->add("recover", seconds_since(t0));

    // ---- 2. classify -------------------------------------------------------------------------
    t0 = Clock::now();
    classify_ocean(m, boundary, options);
    if (options.inlet_width > 0 && !boundary.empty()) close_inlets(m, options, report);
    globemesh::report(progress, 0.15, "classify");
    mark_sharp_corners(m);
    estimate_nodes(m, options);
    if (timings) timings->add("classify", seconds_since(t0));

    // ---- 3. lattice and refinement -----------------------------------------------------------
    t0 = Clock::now();
    const auto lattice_first = static_cast<VertexId>(dt.vertex_count()); // the lattice nodes follow
    // The lattice's points over the whole sphere may be a few times the nodes asked for (the
    // global ocean: 1.5 times), not more.
    if (options.lattice_km > 0)
        report.lattice_nodes = fill_lattice(m, options.lattice_km, 4.0 * double(report.estimated_nodes) + 1000);
    refine(m, progress);
    if (timings) timings->add("refine", seconds_since(t0));

    // ---- 5. improve --------------------------------------------------------------------------
    t0 = Clock::now();
    std::vector<char> as_made = smooth(m, options, lattice_first, progress);
    // Then the nodes of the triangles still below q count_cap (next to the coast, or at valence
    // defects), a few rounds: each interior node goes where its star has the most triangles
    // above count_quality (star_count_score), searched from the best of a few candidates (the
    // mean of the apexes that would make each star triangle equilateral on its far edge, the
    // mean of its neighbours, halfway to either); each boundary node slides near the coast the
    // same way (slide_reach).
    {
        // The nodes of the ocean triangles below `below` (those at a sharp corner left out when
        // `skip_sharp`), each with a triangle next to it: the hint that finds its star in a step
        // or two. Interior nodes go to `todo`; boundary nodes to `*fixed_todo` when given.
        std::vector<std::pair<VertexId, TriangleId>> todo, slide_todo;
        // With `near`, only the triangles with a corner marked there. Every corner of the
        // triangles collected is marked in `dirty`.
        std::vector<char> dirty(dt.vertex_count(), 0);
        auto collect = [&](double below, bool skip_sharp, std::vector<std::pair<VertexId, TriangleId>>* fixed_todo = nullptr,
                           const std::vector<char>* near = nullptr) {
            todo.clear();
            if (fixed_todo) fixed_todo->clear();
            for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
                if (!dt.is_live(t) || dt.label(t) != ocean) continue;
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                if (near && !(*near)[a] && !(*near)[b] && !(*near)[c]) continue;
                if (skip_sharp && (m.is_sharp(a) || m.is_sharp(b) || m.is_sharp(c))) continue;
                if (as_made[a] && as_made[b] && as_made[c]) continue;
                if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) >= below) continue;
                for (VertexId u : {a, b, c}) {
                    dirty[u] = 1;
                    if (!m.is_fixed(u)) todo.emplace_back(u, t);
                    else if (fixed_todo) fixed_todo->emplace_back(u, t);
                }
            }
            for (auto* list : {&todo, fixed_todo}) {
                if (!list) continue;
                std::sort(list->begin(), list->end());
                list->erase(std::unique(list->begin(), list->end(), [](const auto& x, const auto& y) { return x.first == y.first; }),
                            list->end());
            }
        };
        std::vector<Vec3> candidates;
        std::vector<VertexId> touched;                 // move_checked's scratch
        std::vector<FarEdge> far;        // a star's far edges b -> c (triangles v, b, c)
        std::vector<FarEdge> land_far;   // slide_node's: the star's far edges on land
        std::vector<Vec3> chain;                       // slide_node's: the points its search improved through
        // Moves v (`from` leaves it) to `to` (Mesher::move_if) when the ocean triangles the move
        // and its flips leave near it all keep q >= floor and none with two or three boundary
        // corners falls below quality_goal (the mending would have to split it); `ends` as in
        // move_if. With `changed`, a move marks every vertex whose star it changed.
        auto move_checked = [&](VertexId v, HalfEdge from, const Vec3& to, double floor, std::vector<char>* changed,
                                const VertexId* ends = nullptr) {
            auto holds = [&](TriangleId t) {
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                const double q = triangle_quality(dt.point(a), dt.point(b), dt.point(c));
                return q >= floor && (q >= quality_goal || m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2);
            };
            if (!m.move_if(from, to, ends, touched, holds, [] { return true; })) return false;
            as_made[v] = 0;
            // Every star the move changed: where the search rounds look for what is left.
            if (dirty.size() < dt.vertex_count()) dirty.resize(dt.vertex_count(), 0);
            dirty[v] = 1;
            for (VertexId u : touched) dirty[u] = 1;
            if (changed) {
                (*changed)[v] = 1;
                for (VertexId u : touched) (*changed)[u] = 1;
            }
            return true;
        };
        // A half-edge leaving v, found from `hint` (a triangle next to v when it was collected,
        // updated to one next to it now), or no_half_edge.
        auto leaving = [&](VertexId v, TriangleId& hint) {
            const HalfEdge from = dt.leaving(v, dt.is_live(hint) ? hint : no_triangle);
            if (from == no_half_edge || dt.origin(from) != v) return no_half_edge;
            hint = triangle_of(from);
            return from;
        };
        // The candidates for interior node v (p0, its star's far edges `far`) and the pattern
        // search's first step, 0.2 of its mean equilateral apex height.
        auto star_candidates = [&](const Vec3& p0) {
            Vec3 apex{0, 0, 0}, mean{0, 0, 0};
            double step = 0;
            for (const FarEdge& e : far) {
                const double d = 0.5 * std::sqrt(3.0) * arc_angle(e.b, e.c);
                apex = apex + (std::cos(d) * arc_midpoint(e.b, e.c) + std::sin(d) * normalized(cross(e.b, e.c)));
                mean = mean + e.b;
                step += d;
            }
            candidates.clear();
            for (const Vec3& p : {normalized(apex), normalized(mean)}) {
                candidates.push_back(p);
                candidates.push_back(normalized(p0 + p));
            }
            return step * 0.2 / double(far.size());
        };
        // The quality rounds' move of interior node v: the candidates, then a pattern search,
        // for the best star_count_score.
        auto count_node = [&](VertexId v, TriangleId& hint, std::vector<char>* changed) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            if (!m.ocean_star(from, far)) return;
            const Vec3 p0 = dt.point(v);
            const double floor = std::min(star_worst_quality(p0, far), worst_goal);
            double best = star_count_score(p0, far, count_rule, floor);
            if (best >= star_count_best(far.size(), count_rule)) return; // every triangle above count_cap
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
                if (score <= best + 1e-12) return false;
                best = score;
                to = p;
                return true;
            };
            // Half the search rounds' first step, and 4 halvings instead of 6.
            const double step = 0.5 * star_candidates(p0);
            for (const Vec3& p : candidates) consider(p);
            if (best < star_count_best(far.size(), count_rule))
                to = pattern_search(to, step, step / 16, [&](const Points8& p) { return star_count_accepts(p, far, count_rule, floor, best); });
            if (to != p0) move_checked(v, from, to, floor, changed);
        };
        // The same for boundary node v, between two coast segments of one ring, neither end a
        // sharp corner: its star's land triangles must stay counter-clockwise too, and it stays
        // within slide_reach h of the source coast; the candidates lie along its two segments.
        auto slide_node = [&](VertexId v, TriangleId& hint, std::vector<char>* changed) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            VertexId ends[2];
            if (!m.slide_star(from, far, land_far, ends)) return;
            const Vec3 p0 = dt.point(v);
            const double reach = slide_reach * km_to_rad(size_km(p0));
            const double floor = std::min(star_worst_quality(p0, far), worst_goal);
            double best = star_count_score(p0, far, count_rule, floor);
            if (best >= star_count_best(far.size(), count_rule)) return; // every triangle above count_cap
            // The search scores the star alone; the coast and land rules are checked on the points
            // it improved through, from the best back.
            chain.clear();
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                for (const FarEdge& e : land_far)
                    if (predicates::orient(p, e) <= 0) return false;
                const double score = star_count_score(p, far, count_rule, floor, best + 1e-12);
                if (score <= best + 1e-12) return false;
                best = score;
                to = p;
                chain.push_back(p);
                return true;
            };
            for (VertexId e : ends)
                for (double f : {0.1, 0.2, 0.3}) consider(normalized((1 - f) * p0 + f * dt.point(e)));
            const double step = 0.5 * reach;
            if (best < star_count_best(far.size(), count_rule))
                pattern_search(to, step, step / 8, [&](const Points8& p) {
                    const unsigned accepted = star_count_accepts(p, far, count_rule, floor, best, &land_far);
                    for (int k = 0; k < 8; ++k)
                        if (accepted >> k & 1u) chain.push_back(p[k]);
                    return accepted;
                });
            // The star's faces centred on land where it is now are counted only when a point
            // has some (rarely: most stars have none either way).
            int land0 = -1;
            for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
                if (!options.land->coast_within(*it, reach)) continue;
                if (const int land = star_faces_on_land(*options.land, *it, far); land > 0) {
                    if (land0 < 0) land0 = star_faces_on_land(*options.land, p0, far);
                    if (land > land0) continue;
                }
                move_checked(v, from, *it, floor, changed, ends);
                return;
            }
        };
        // The search rounds' move: to the candidate, then, when the star is still below
        // worst_goal, the point of a pattern search, that best raises the star's worst.
        auto improve_node = [&](VertexId v, TriangleId& hint) {
            const HalfEdge from = leaving(v, hint);
            if (from == no_half_edge) return;
            if (!m.ocean_star(from, far)) return;
            const Vec3 p0 = dt.point(v);
            const double before = star_worst_quality(p0, far);
            double best = before;
            Vec3 to = p0;
            auto consider = [&](const Vec3& p) {
                const double w = star_worst_quality(p, far, best + 1e-9);
                if (w <= best + 1e-9) return false;
                best = w;
                to = p;
                return true;
            };
            const double step = star_candidates(p0);
            for (const Vec3& p : candidates) consider(p);
            if (best < worst_goal)
                to = pattern_search(to, step, step / 64, [&](const Points8& p) { return star_worst_accepts(p, far, best); });
            if (to != p0) move_checked(v, from, to, std::min(before, worst_goal), nullptr);
        };
        collect(count_cap, false, options.land ? &slide_todo : nullptr);
        {
            // A node's move depends on its star's points alone: a node whose star has not
            // changed since it last stayed would stay again, and is skipped (the same mesh,
            // fewer evaluations). A move changes the stars of the node, its neighbours and,
            // when it needs flips, the corners of the flipped edges' quadrilaterals.
            std::vector<char> changed(dt.vertex_count(), 1);
            for (int round = 0; round < improve_rounds; ++round) {
                for (auto& [v, hint] : todo)
                    if (changed[v]) {
                        changed[v] = 0;
                        count_node(v, hint, &changed);
                    }
                for (auto& [v, hint] : slide_todo)
                    if (changed[v]) {
                        changed[v] = 0;
                        slide_node(v, hint, &changed);
                    }
            }
        }
        // Last, search_rounds rounds over the nodes of the triangles still below worst_goal
        // (away from sharp corners), collected again each round. Such a triangle was below
        // count_cap before the quality rounds, or a move changed it: only the triangles with a corner
        // marked in `dirty` are looked at.
        for (int round = 0; round < search_rounds; ++round) {
            collect(worst_goal, true, nullptr, &dirty);
            if (todo.empty()) break;
            for (auto& [v, hint] : todo) improve_node(v, hint);
        }
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
                if (!dt.is_live(t) || dt.label(t) != ocean) continue;
                const VertexId a = dt.vertex(t, 0), b = dt.vertex(t, 1), c = dt.vertex(t, 2);
                if (m.is_fixed(a) + m.is_fixed(b) + m.is_fixed(c) < 2 || m.is_sharp(a) || m.is_sharp(b) || m.is_sharp(c)) continue;
                if (triangle_quality(dt.point(a), dt.point(b), dt.point(c)) < quality_goal) mend.push_back(t);
            }
            if (mend.empty()) break;
            for (TriangleId t : mend) {
                if (!dt.is_live(t)) continue; // gone with an earlier one's cavity
                HalfEdge blocked;
                const Vec3 centre = m.circumcentre(t);
                const TriangleId in = m.walk_towards(t, centre, blocked);
                VertexId v = no_vertex;
                if (blocked != no_half_edge) {
                    v = m.split_segment(blocked);
                    if (v != no_vertex) ++report.encroached_splits;
                } else if (dt.label(in) == ocean) {
                    const std::size_t before = dt.vertex_count();
                    v = dt.insert_in_triangle(centre, in);
                    if (dt.vertex_count() == before) v = no_vertex;
                }
                if (v == no_vertex) continue;
                as_made.resize(dt.vertex_count(), 0);
                around.assign(m.is_fixed(v) ? 0 : 1, {v, dt.last_triangle()});
                const HalfEdge from = dt.leaving(v, dt.last_triangle());
                HalfEdge h = from;
                do {
                    if (!m.is_fixed(dt.destination(h))) around.emplace_back(dt.destination(h), triangle_of(h));
                    h = dt.next_around_origin(h);
                } while (h != from);
                for (int round = 0; round < 2; ++round)
                    for (auto& [u, hint] : around) improve_node(u, hint);
                ++report.corners_mended;
            }
        }
    }
    std::vector<TriangleId> island_faces;
    report.island_centroids_left = clear_dropped_islands(m, boundary, report, island_faces);
    if (timings) timings->add("improve", seconds_since(t0));
    if (options.land) {
        t0 = Clock::now();
        std::vector<TriangleId> left;
        BoundaryLoops loops;
        remove_land_faces(m, *options.land, std::move(island_faces), options.inlet_area, report, left, loops);
        report.land_faces_nudged = nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        if (options.close_straits && !left.empty()) {
            close_straits(m, *options.land, left, options, loops, report);
            report.land_faces_at.clear();
            if (!left.empty()) report.land_faces_nudged += nudge_off_land(m, *options.land, left, left, report.land_faces_at);
        }
        report.land_faces_left = report.land_faces_at.size();
        if (timings) timings->add("land", seconds_since(t0));
    }

    // ---- output ------------------------------------------------------------------------------
    // The faces first, then the triangulation goes and its points become the nodes in place: the
    // triangulation and the output nodes never coexist (this is the mesher's peak).
    Mesh mesh;
    std::vector<NodeIndex> node_of(dt.vertex_count(), 0xffffffffu);
    std::size_t face_count = 0, node_count = 0;
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t)
        if (dt.is_live(t) && dt.label(t) == ocean) {
            ++face_count;
            for (int i = 0; i < 3; ++i) node_of[dt.vertex(t, i)] = 0;
        }
    for (VertexId v = 0; v < dt.vertex_count(); ++v)
        if (node_of[v] == 0) node_of[v] = static_cast<NodeIndex>(node_count++);
    if (node_count == 0) throw DataError("no ocean is left to mesh at this size: the water was closed as inlets or straits, or removed as land; a smaller size keeps it");
    // A vertex between two or more fans of ocean (close_straits closed a strait there at a
    // point): each fan after the first gets a node of its own, pinch_apart into the fan, so
    // that the mesh is a manifold. (fan_corner, fan_node): the corners of those fans' faces and
    // their nodes, sorted; fan_point: the new nodes' points, numbered from node_count.
    std::vector<std::pair<TriangleId, VertexId>> fan_corner;
    std::vector<NodeIndex> fan_node;
    std::vector<Vec3> fan_point;
    {
        std::sort(m.pinched.begin(), m.pinched.end());
        m.pinched.erase(std::unique(m.pinched.begin(), m.pinched.end()), m.pinched.end());
        std::vector<std::tuple<TriangleId, VertexId, NodeIndex>> corners;
        std::vector<std::vector<TriangleId>> fans;
        for (const VertexId v : m.pinched) {
            fans.clear();
            const int n = m.ocean_fans(dt.leaving(v, no_triangle), [&](TriangleId t, int k) {
                if (k == int(fans.size())) fans.emplace_back();
                fans[std::size_t(k)].push_back(t);
            });
            const Vec3& p = dt.point(v);
            for (int k = 1; k < n; ++k) {
                const std::vector<TriangleId>& fan = fans[std::size_t(k)];
                // Towards the centroid of the fan's middle face (inside the fan's angle),
                // pinch_apart or less: every face of the fan must stay counter-clockwise (a
                // sliver of the fan may be thinner than pinch_apart).
                const Vec3 into = m.centroid(fan[fan.size() / 2]) - p;
                const Vec3 dir = normalized(into - dot(into, p) * p);
                auto far_edge = [&](TriangleId t) {
                    int i = 0;
                    while (dt.vertex(t, i) != v) ++i;
                    return std::pair{dt.point(dt.vertex(t, next3(i))), dt.point(dt.vertex(t, prev3(i)))};
                };
                Vec3 q = p;
                for (double d = pinch_apart; d > 1e-15; d *= 0.5) {
                    const Vec3 moved = normalized(p + d * dir);
                    bool ccw = true;
                    for (const TriangleId t : fan) {
                        const auto [a, b] = far_edge(t);
                        ccw = ccw && predicates::orient(moved, a, b) > 0;
                    }
                    if (ccw) {
                        q = moved;
                        break;
                    }
                }
                fan_point.push_back(q);
                const auto node = static_cast<NodeIndex>(node_count + fan_point.size() - 1);
                for (const TriangleId t : fan) corners.emplace_back(t, v, node);
            }
        }
        std::sort(corners.begin(), corners.end());
        for (const auto& [t, v, node] : corners) {
            fan_corner.emplace_back(t, v);
            fan_node.push_back(node);
        }
        report.nodes_split = fan_point.size();
    }
    auto node_at = [&](TriangleId t, VertexId v) {
        if (!fan_corner.empty()) {
            const auto it = std::lower_bound(fan_corner.begin(), fan_corner.end(), std::pair{t, v});
            if (it != fan_corner.end() && *it == std::pair{t, v}) return fan_node[std::size_t(it - fan_corner.begin())];
        }
        return node_of[v];
    };
    mesh.faces.reserve(face_count); // sized once: no doubling, no copy while growing
    for (TriangleId t = 0; t < dt.triangle_slots(); ++t) {
        if (!dt.is_live(t) || dt.label(t) != ocean) continue;
        mesh.faces.push_back({node_at(t, dt.vertex(t, 0)), node_at(t, dt.vertex(t, 1)), node_at(t, dt.vertex(t, 2))});
        for (int i = 0; i < 3; ++i) {
            HalfEdge h = half_edge(t, i);
            TriangleId other = triangle_of(dt.twin(h));
            if (dt.label(other) == ocean) continue;
            VertexId a = dt.origin(h), b = dt.destination(h);
            auto it = m.segments.find(key(a, b));
            EdgeTag tag = it != m.segments.end() && it->second == SegmentKind::open ? EdgeTag::open : EdgeTag::coast;
            mesh.boundary.push_back({node_at(t, a), node_at(t, b), tag});
        }
    }
    std::vector<NodeIndex> cut_nodes; // a node of each face beside a cut
    for (const TriangleId t : m.cut_sides)
        if (dt.is_live(t) && dt.label(t) == ocean) cut_nodes.push_back(node_at(t, dt.vertex(t, 0)));
    // Node k is the k-th vertex used by a face, so moving each down to its index is in place.
    mesh.nodes = m.dt.release_points();
    for (VertexId v = 0; v < node_of.size(); ++v)
        if (node_of[v] != 0xffffffffu) mesh.nodes[node_of[v]] = mesh.nodes[v];
    mesh.nodes.resize(node_count);
    mesh.nodes.insert(mesh.nodes.end(), fan_point.begin(), fan_point.end());
    mesh.nodes.shrink_to_fit(); // the triangulation is gone: the copy is not the peak
    std::vector<NodeIndex>().swap(node_of);
    if (!cut_nodes.empty()) {
        // The basins the closed straits cut off: the mesh's pieces (union-find over the nodes
        // through the faces) beside a cut, but for the largest.
        std::vector<NodeIndex> parent(mesh.nodes.size());
        for (NodeIndex i = 0; i < parent.size(); ++i) parent[i] = i;
        auto find = [&](NodeIndex i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        for (const auto& f : mesh.faces) {
            const NodeIndex r = find(f[0]);
            for (int k = 1; k < 3; ++k) parent[find(f[k])] = r;
        }
        std::unordered_map<NodeIndex, double> area; // steradians per piece beside a cut
        for (const NodeIndex n : cut_nodes) area.emplace(find(n), 0.0);
        std::vector<std::uint32_t> faces_of(mesh.nodes.size(), 0);
        for (const auto& f : mesh.faces) ++faces_of[find(f[0])];
        const NodeIndex largest = static_cast<NodeIndex>(std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
        area.erase(largest);
        for (const auto& f : mesh.faces)
            if (auto it = area.find(find(f[0])); it != area.end())
                it->second += spherical_triangle_area(mesh.nodes[f[0]], mesh.nodes[f[1]], mesh.nodes[f[2]]);
        for (const auto& [r, a] : area) report.seas_cut_off.push_back(a * earth_radius_km * earth_radius_km);
        std::sort(report.seas_cut_off.rbegin(), report.seas_cut_off.rend());
    }
    std::vector<double> ocean_angle(mesh.nodes.size(), 0.0);
    std::vector<char> on_boundary(mesh.nodes.size(), 0);
    for (const auto& e : mesh.boundary) on_boundary[e.a] = on_boundary[e.b] = 1;
    for (const auto& f : mesh.faces)
        for (int i = 0; i < 3; ++i) {
            if (!on_boundary[f[i]]) continue;
            const Vec3& p = mesh.nodes[f[i]];
            const Vec3& q = mesh.nodes[f[next3(i)]];
            const Vec3& r = mesh.nodes[f[prev3(i)]];
            ocean_angle[f[i]] += std::atan2(norm(cross(q - p, r - p)), dot(q - p, r - p));
        }
    std::vector<char> sharp(mesh.nodes.size(), 0);
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v)
        if (on_boundary[v] && ocean_angle[v] < 60.0 * deg_to_rad) {
            sharp[v] = 1;
            ++report.sharp_corners;
        }
    for (const auto& f : mesh.faces)
        if (sharp[f[0]] || sharp[f[1]] || sharp[f[2]]) ++report.sharp_corner_faces;
    Field target{"target_size", "target edge length", "km", "", {}};
    target.values.reserve(mesh.nodes.size());
    for (const Vec3& p : mesh.nodes) target.values.push_back(size_km(p));
    mesh.node_fields.push_back(std::move(target));
    globemesh::report(progress, 1.0, "improve");
    return mesh;
}

} // namespace globemesh

