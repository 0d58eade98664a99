// The joined mesh near the borders (docs/parallel.md, section 6): Lawson flips, smoothing with
// a pattern search, and the removal of nodes with four faces, over the faces of the zone that
// join_parts marks around the borders.
#include "parts_smooth.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "globemesh/predicates.hpp"
#include "star_search.hpp"

namespace globemesh::parts_detail {

namespace {

/// In the last round, a node near a border whose star's worst face is below this quality (the
/// share above q 0.8 is what the benches count) gets two pattern searches (smooth_near_borders).
constexpr double search_below = 0.8;
constexpr int search_steps = 16; // the worst face's search: its steps

/// The worst quality of `faces`, -1 when one of them is folded.
double worst_quality(const Mesh &mesh, const std::vector<std::uint32_t> &faces) {
    double q = 1;
    for (std::uint32_t f : faces) {
        const auto &t = mesh.faces[f];
        const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]];
        if (predicates::orient(a, b, c) <= 0)
            return -1;
        q = std::min(q, triangle_quality(a, b, c));
    }
    return q;
}

/// The faces of `faces` above q 0.8 and the worst quality (-1 when one is folded).
std::pair<int, double> count_and_worst(const Mesh &mesh, const std::vector<std::uint32_t> &faces) {
    int count = 0;
    double worst = 1;
    bool folded = false;
    for (std::uint32_t f : faces) {
        const auto &t = mesh.faces[f];
        const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]];
        folded = folded || predicates::orient(a, b, c) <= 0;
        const double q = triangle_quality(a, b, c);
        count += q > 0.8;
        worst = std::min(worst, q);
    }
    return {count, folded ? -1 : worst};
}

/// A pattern search for the place of v where its star's worst face is best (as the mesher's
/// quality rounds do inside a part): steps along two tangent directions from a fifth of the
/// mean edge, halved whenever none of the four raises the worst face.
void worst_search_node(Mesh &mesh, NodeIndex v, const std::vector<std::uint32_t> &faces) {
    double length = 0;
    for (std::uint32_t f : faces)
        for (NodeIndex u : mesh.faces[f])
            length += norm(mesh.nodes[u] - mesh.nodes[v]);
    double step = 0.2 * length / (2.0 * static_cast<double>(faces.size()));
    double best = worst_quality(mesh, faces);
    for (int k = 0; k < search_steps; ++k) {
        const Vec3 base = mesh.nodes[v];
        const Vec3 t1 =
            normalized(cross(base, std::abs(base.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0}));
        const Vec3 t2 = cross(base, t1);
        Vec3 best_place = base;
        for (const Vec3 &d : {t1, -t1, t2, -t2}) {
            mesh.nodes[v] = normalized(base + step * d);
            if (const double q = worst_quality(mesh, faces); q > best)
                best = q, best_place = mesh.nodes[v];
        }
        mesh.nodes[v] = best_place;
        if (best_place == base)
            step *= 0.5;
    }
}

/// The mesher's quality rounds' score (quality.cpp): the worst face first up to q 0.6, then the
/// count of faces above q 0.8, ties broken by their qualities capped at 0.82.
constexpr detail::CountRule count_rule = detail::quality_count_rule;

/// A pattern search for the place of v with the best count score of its star (as the mesher's
/// quality rounds do inside a part), from a tenth of the star's mean edge, its worst face kept
/// at or above where it is.
void count_search_node(Mesh &mesh, NodeIndex v, const std::vector<std::uint32_t> &faces) {
    std::vector<detail::FarEdge> far;
    double length = 0;
    for (std::uint32_t f : faces) {
        const auto &t = mesh.faces[f];
        const int i = t[0] == v ? 0 : t[1] == v ? 1 : 2;
        far.emplace_back(mesh.nodes[t[(i + 1) % 3]], mesh.nodes[t[(i + 2) % 3]]);
        length += norm(far.back().b - mesh.nodes[v]);
    }
    const Vec3 p0 = mesh.nodes[v];
    const double floor = detail::star_worst_quality(p0, far);
    double best = detail::star_count_score(p0, far, count_rule, floor);
    if (floor < 0 || best >= detail::star_count_best(far.size(), count_rule))
        return;
    const double step = 0.1 * length / static_cast<double>(far.size());
    mesh.nodes[v] = detail::pattern_search(p0, step, step / 64, [&](const detail::Points8 &p) {
        return detail::star_count_accepts(p, far, count_rule, floor, best);
    });
}

/// Each free zone node (not on the boundary) with each of its faces, in node order: the same
/// sweep every run.
std::vector<std::pair<NodeIndex, std::uint32_t>>
free_zone_stars(const Mesh &mesh, const std::vector<char> &zone,
                const std::vector<std::uint32_t> &zone_face_list) {
    std::vector<char> fixed(mesh.nodes.size(), 0);
    for (const BoundaryEdge &e : mesh.boundary)
        fixed[e.a] = fixed[e.b] = 1;
    // Sorted as 64-bit keys (node, face): the pairs' order, at a third of a pair sort's time.
    std::vector<std::uint64_t> keys;
    keys.reserve(3 * zone_face_list.size());
    for (std::uint32_t f : zone_face_list)
        for (NodeIndex v : mesh.faces[f])
            if (zone[v] && !fixed[v])
                keys.push_back((std::uint64_t(v) << 32) | f);
    std::sort(keys.begin(), keys.end());
    std::vector<std::pair<NodeIndex, std::uint32_t>> at(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i)
        at[i] = {static_cast<NodeIndex>(keys[i] >> 32), static_cast<std::uint32_t>(keys[i])};
    return at;
}

} // namespace

FaceOfEdge::FaceOfEdge(std::size_t edges) {
    std::size_t slots = 16;
    while (slots < 4 * edges)
        slots *= 2;
    keys_.assign(slots, empty);
    faces_.assign(slots, 0);
    mask_ = slots - 1;
}

// The first slot of key's probe (a multiplicative hash of both node indices).
std::size_t FaceOfEdge::slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9e3779b97f4a7c15ull) >> 20) & mask_;
}

std::uint32_t *FaceOfEdge::find(std::uint64_t key) {
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
        if (keys_[s] == key)
            return &faces_[s];
        if (keys_[s] == empty)
            return nullptr;
    }
}

void FaceOfEdge::set(std::uint64_t key, std::uint32_t face) {
    std::size_t reuse = keys_.size(); // the first erased slot on the probe
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
        if (keys_[s] == key) {
            faces_[s] = face;
            return;
        }
        if (keys_[s] == erased && reuse == keys_.size())
            reuse = s;
        if (keys_[s] == empty) {
            const std::size_t at = reuse < keys_.size() ? reuse : s;
            keys_[at] = key, faces_[at] = face;
            if (at == s && ++filled_ > 3 * (mask_ + 1) / 4)
                rebuild();
            return;
        }
    }
}

void FaceOfEdge::rebuild() {
    std::vector<std::uint64_t> keys(keys_.size(), empty);
    std::vector<std::uint32_t> faces(faces_.size(), 0);
    keys.swap(keys_), faces.swap(faces_);
    filled_ = 0;
    for (std::size_t s = 0; s < keys.size(); ++s)
        if (keys[s] != empty && keys[s] != erased)
            set(keys[s], faces[s]);
}

void FaceOfEdge::erase(std::uint64_t key) {
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
        if (keys_[s] == key) {
            keys_[s] = erased;
            return;
        }
        if (keys_[s] == empty)
            return;
    }
}

/// The face of each directed edge of `faces`, which the flips keep up to date.
FaceOfEdge faces_of_edges(const Mesh &mesh, const std::vector<std::uint32_t> &faces) {
    FaceOfEdge face_of(3 * faces.size());
    for (std::uint32_t f : faces) {
        const auto &t = mesh.faces[f];
        for (int i = 0; i < 3; ++i)
            face_of.set(edge_key(t[i], t[(i + 1) % 3]), f);
    }
    return face_of;
}

/// Lawson flips of the edges near the borders whose opposite node lies inside the circumcircle
/// (the borders were constrained in their parts, and a fan split leaves such edges): the faces of
/// `faces` (zone_faces, their edges' faces in face_of), the joined mesh Delaunay there as inside.
void flip_near_borders(Mesh &mesh, const std::vector<std::uint32_t> &faces, FaceOfEdge &face_of) {
    const auto key = edge_key;
    std::vector<std::pair<NodeIndex, NodeIndex>> stack;
    stack.reserve(3 * faces.size());
    for (std::uint32_t f : faces) {
        const auto &t = mesh.faces[f];
        for (int i = 0; i < 3; ++i)
            stack.push_back({t[i], t[(i + 1) % 3]});
    }
    auto third = [&](std::uint32_t f, NodeIndex a, NodeIndex b) {
        for (NodeIndex v : mesh.faces[f])
            if (v != a && v != b)
                return v;
        return a;
    };
    using predicates::orient;
    for (std::size_t budget = 20 * stack.size() + 100; !stack.empty() && budget > 0; --budget) {
        const auto [a, b] = stack.back();
        stack.pop_back();
        const std::uint32_t *i1 = face_of.find(key(a, b)), *i2 = face_of.find(key(b, a));
        if (!i1 || !i2)
            continue;
        const std::uint32_t f1 = *i1, f2 = *i2;
        const NodeIndex c = third(f1, a, b), d = third(f2, b, a);
        const Vec3 &pa = mesh.nodes[a], &pb = mesh.nodes[b], &pc = mesh.nodes[c],
                   &pd = mesh.nodes[d];
        if (predicates::orient3d(pa, pb, pc, pd) <= 0 || orient(pa, pd, pc) <= 0 ||
            orient(pd, pb, pc) <= 0)
            continue;
        mesh.faces[f1] = {a, d, c};
        mesh.faces[f2] = {d, b, c};
        face_of.erase(key(a, b));
        face_of.erase(key(b, a));
        face_of.set(key(a, d), f1), face_of.set(key(d, c), f1), face_of.set(key(c, a), f1);
        face_of.set(key(d, b), f2), face_of.set(key(b, c), f2), face_of.set(key(c, d), f2);
        for (auto e : {std::pair{a, d}, std::pair{d, b}, std::pair{b, c}, std::pair{c, a}})
            stack.push_back(e);
    }
}

void grow_rings(const Mesh &mesh, const std::vector<std::uint32_t> *faces, std::vector<char> &ring,
                char last) {
    auto grow = [&](const std::array<NodeIndex, 3> &t, char r) {
        if (ring[t[0]] == r || ring[t[1]] == r || ring[t[2]] == r)
            for (NodeIndex v : t)
                if (!ring[v])
                    ring[v] = static_cast<char>(r + 1);
    };
    for (char r = 1; r < last; ++r) {
        if (faces)
            for (std::uint32_t f : *faces)
                grow(mesh.faces[f], r);
        else
            for (const auto &t : mesh.faces)
                grow(t, r);
    }
}

/// The faces with a node in the zone: the only ones the join's flips and smoothing rewrite (a
/// flip turns two of them into two others of the same four nodes).
std::vector<std::uint32_t> zone_faces(const Mesh &mesh, const std::vector<char> &zone) {
    std::vector<std::uint32_t> faces;
    for (std::uint32_t f = 0; f < mesh.faces.size(); ++f) {
        const auto &t = mesh.faces[f];
        if (zone[t[0]] || zone[t[1]] || zone[t[2]])
            faces.push_back(f);
    }
    return faces;
}

/// Smoothing that crosses the borders (each part smoothed only its inside): sweeps over the
/// free nodes near the borders, in index order, each moved to the mean of its neighbours where
/// its star's worst quality rises and no face folds, then, with `search`, searched for a better
/// place where its star's worst face is still below search_below.
void smooth_near_borders(Mesh &mesh, const std::vector<char> &zone,
                         const std::vector<std::uint32_t> &zone_face_list, bool search) {
    const auto at = free_zone_stars(mesh, zone, zone_face_list);
    std::vector<std::uint32_t> faces;
    for (std::size_t i = 0; i < at.size();) {
        const NodeIndex v = at[i].first;
        faces.clear();
        for (; i < at.size() && at[i].first == v; ++i)
            faces.push_back(at[i].second);
        Vec3 sum{0, 0, 0};
        for (std::uint32_t f : faces)
            for (NodeIndex u : mesh.faces[f])
                if (u != v)
                    sum = sum + mesh.nodes[u];
        const Vec3 old = mesh.nodes[v];
        const double before = worst_quality(mesh, faces);
        mesh.nodes[v] = normalized(sum);
        if (worst_quality(mesh, faces) <= before)
            mesh.nodes[v] = old;
        if (search && worst_quality(mesh, faces) < search_below) {
            // Two searches: for the most faces above q 0.8, then for the best worst face, kept
            // where it keeps as many.
            count_search_node(mesh, v, faces);
            const Vec3 counted = mesh.nodes[v];
            const auto counted_score = count_and_worst(mesh, faces);
            worst_search_node(mesh, v, faces);
            if (count_and_worst(mesh, faces) < counted_score)
                mesh.nodes[v] = counted;
        }
    }
}

void compact_mesh(Mesh &mesh, const std::vector<char> &dead_node,
                  const std::vector<char> &dead_face, std::vector<char> *zone) {
    std::vector<NodeIndex> new_index(mesh.nodes.size());
    std::size_t kept = 0;
    for (std::size_t v = 0; v < mesh.nodes.size(); ++v) {
        new_index[v] = static_cast<NodeIndex>(kept);
        if (!dead_node[v]) {
            mesh.nodes[kept] = mesh.nodes[v];
            if (zone)
                (*zone)[kept] = (*zone)[v];
            for (Field &field : mesh.node_fields)
                field.values[kept] = field.values[v];
            ++kept;
        }
    }
    mesh.nodes.resize(kept);
    if (zone)
        zone->resize(kept);
    for (Field &field : mesh.node_fields)
        field.values.resize(kept);
    std::size_t faces_kept = 0;
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        if (!dead_face[f]) {
            auto t = mesh.faces[f];
            for (NodeIndex &u : t)
                u = new_index[u];
            mesh.faces[faces_kept] = t;
            for (Field &field : mesh.face_fields)
                field.values[faces_kept] = field.values[f];
            ++faces_kept;
        }
    mesh.faces.resize(faces_kept);
    for (Field &field : mesh.face_fields)
        field.values.resize(faces_kept);
    for (BoundaryEdge &e : mesh.boundary)
        e.a = new_index[e.a], e.b = new_index[e.b];
}

/// Removes the free nodes near the borders with four faces (a lattice's valence defect that a
/// border leaves: its faces near q 0.72, which no move of one node mends): the quadrilateral of
/// their neighbours becomes two faces (the diagonal that keeps both positive; the flips that
/// follow make it Delaunay), and the nodes and faces are compacted away. Returns how many.
std::size_t remove_valence_four(Mesh &mesh, std::vector<char> &zone,
                                const std::vector<std::uint32_t> &zone_face_list) {
    const auto at = free_zone_stars(mesh, zone, zone_face_list);
    std::vector<char> dead_node(mesh.nodes.size(), 0), dead_face(mesh.faces.size(), 0),
        touched(mesh.nodes.size(), 0);
    std::size_t removed = 0;
    using predicates::orient;
    for (std::size_t i = 0; i < at.size();) {
        const NodeIndex v = at[i].first;
        std::size_t j = i;
        while (j < at.size() && at[j].first == v)
            ++j;
        const std::size_t count = j - i;
        const std::size_t first = i;
        i = j;
        if (count != 4 || touched[v])
            continue;
        // The star's faces as (v, x, y), counter-clockwise; the ring x0 -> x1 -> x2 -> x3.
        std::array<std::pair<NodeIndex, NodeIndex>, 4> side;
        for (std::size_t k = 0; k < 4; ++k) {
            const auto &t = mesh.faces[at[first + k].second];
            const int r = t[0] == v ? 0 : t[1] == v ? 1 : 2;
            side[k] = {t[(r + 1) % 3], t[(r + 2) % 3]};
        }
        std::array<NodeIndex, 4> ring{side[0].first, side[0].second, 0, 0};
        bool closed = true;
        for (std::size_t k = 2; k < 4 && closed; ++k) {
            const auto next = std::find_if(side.begin(), side.end(),
                                           [&](const auto &e) { return e.first == ring[k - 1]; });
            closed = next != side.end();
            if (closed)
                ring[k] = next->second;
        }
        if (!closed || std::none_of(side.begin(), side.end(), [&](const auto &e) {
                return e.first == ring[3] && e.second == ring[0];
            }))
            continue;
        if (std::any_of(ring.begin(), ring.end(), [&](NodeIndex u) { return touched[u]; }))
            continue;
        const auto &p = mesh.nodes;
        // The diagonal between the two neighbours with the fewer faces first (it adds one to
        // each): valences nearer six. The smoothing and flips that follow settle it.
        auto faces_at = [&](NodeIndex u) {
            return std::count_if(at.begin(), at.end(), [u](const auto &x) { return x.first == u; });
        };
        const bool first_diagonal =
            faces_at(ring[0]) + faces_at(ring[2]) <= faces_at(ring[1]) + faces_at(ring[3]);
        auto fits = [&](int s) {
            return orient(p[ring[s]], p[ring[s + 1]], p[ring[(s + 2) % 4]]) > 0 &&
                   orient(p[ring[s]], p[ring[(s + 2) % 4]], p[ring[(s + 3) % 4]]) > 0;
        };
        int s = first_diagonal ? 0 : 1;
        if (!fits(s))
            s = 1 - s;
        if (!fits(s))
            continue;
        const std::array<std::array<NodeIndex, 3>, 2> two = {
            {{ring[s], ring[s + 1], ring[(s + 2) % 4]},
             {ring[s], ring[(s + 2) % 4], ring[(s + 3) % 4]}}};
        const std::array<std::array<NodeIndex, 3>, 4> four = {
            mesh.faces[at[first].second], mesh.faces[at[first + 1].second],
            mesh.faces[at[first + 2].second], mesh.faces[at[first + 3].second]};
        const double after = lowest_quality(p, two);
        if (after < join_floor && after < lowest_quality(p, four))
            continue; // a star the join made at a fan split (fan_or_star)
        mesh.faces[at[first].second] = two[0];
        mesh.faces[at[first + 1].second] = two[1];
        dead_face[at[first + 2].second] = dead_face[at[first + 3].second] = 1;
        dead_node[v] = touched[v] = 1;
        for (NodeIndex u : ring)
            touched[u] = 1;
        ++removed;
    }
    if (removed > 0)
        compact_mesh(mesh, dead_node, dead_face, &zone);
    return removed;
}

} // namespace globemesh::parts_detail
