// Step 4 of shape_boundary: coast nodes far closer together than the local size merged.
#include <algorithm>
#include <cstdint>
#include <vector>

#include "coast_internal.hpp"
#include "globemesh/error.hpp"

namespace globemesh::coast_detail {

namespace {

/// One ring's samples as they stand: `order` the samples kept (indices of the resampled ring),
/// `pending` those dropped in this pass (not yet known to be clear), `locked` those that stay.
struct MergeRing {
    std::vector<std::uint32_t> order;
    std::vector<char> dropped, pending, locked;
};

/// Ring r rebuilt from its kept samples, and named to the grid: an arc whose two ends were
/// consecutive before is the same arc.
void rebuild(std::uint32_t r, const std::vector<Vec3> &samples, MergeRing &s,
             std::vector<Vec3> &ring, ArcGrid &grid) {
    const std::vector<std::uint32_t> before = s.order;
    std::vector<std::uint32_t> position(samples.size(), ArcGrid::none);
    for (std::uint32_t i = 0; i < before.size(); ++i)
        position[before[i]] = i;
    s.order.clear();
    for (std::uint32_t k = 0; k < samples.size(); ++k)
        if (!s.dropped[k])
            s.order.push_back(k);
    std::vector<std::uint32_t> old_of(s.order.size(), ArcGrid::none);
    ring.clear();
    for (std::uint32_t i = 0; i < s.order.size(); ++i) {
        ring.push_back(samples[s.order[i]]);
        const std::uint32_t a = position[s.order[i]],
                            b = position[s.order[(i + 1) % s.order.size()]];
        if (a != ArcGrid::none && b != ArcGrid::none && b == (a + 1) % before.size())
            old_of[i] = a;
    }
    grid.replace(r, old_of);
}

/// Drops, in one pass over ring `s`, samples that end an arc shorter than gap times its ends'
/// smaller size: of the arc's two ends, the movable one nearer the arc between its neighbours,
/// with neither neighbour dropped in the same pass. At least four samples stay. Returns whether
/// any was dropped.
bool drop_short(const std::vector<Vec3> &p, const std::vector<double> &h,
                const std::vector<char> &movable, double gap, MergeRing &s) {
    const std::uint32_t n = static_cast<std::uint32_t>(s.order.size());
    auto at = [&](std::uint32_t i) { return s.order[i % n]; };
    // The deviation of the sample at position i from the arc that would replace it, or -1.
    auto deviation = [&](std::uint32_t i) {
        const std::uint32_t k = at(i), before = at(i + n - 1), after = at(i + 1);
        if (!movable[k] || s.locked[k] || s.pending[k] || s.pending[before] || s.pending[after])
            return -1.0;
        return arc_distance(p[before], p[after], p[k]);
    };
    std::uint32_t left = n;
    for (std::uint32_t i = 0; i < n && left > 4; ++i) {
        const std::uint32_t a = at(i), b = at(i + 1);
        if (arc_angle(p[a], p[b]) >= gap * std::min(h[a], h[b]))
            continue;
        const double da = deviation(i), db = deviation(i + 1);
        if (da < 0 && db < 0)
            continue;
        const std::uint32_t k = db < 0 || (da >= 0 && da <= db) ? a : b;
        s.dropped[k] = s.pending[k] = 1;
        --left;
    }
    return left < n;
}

} // namespace

std::size_t merge_close_samples(const std::vector<std::vector<Vec3>> &samples,
                                const std::vector<std::vector<double>> &h,
                                const std::vector<std::vector<char>> &movable, double gap,
                                std::vector<std::vector<Vec3>> &rings, ArcGrid &grid,
                                std::vector<std::vector<std::uint32_t>> &kept) {
    const std::uint32_t count = static_cast<std::uint32_t>(samples.size());
    std::vector<MergeRing> state(count);
    for (std::uint32_t r = 0; r < count; ++r) {
        const std::size_t n = samples[r].size();
        state[r].order.resize(n);
        for (std::uint32_t k = 0; k < n; ++k)
            state[r].order[k] = k;
        state[r].dropped.assign(n, 0);
        state[r].pending.assign(n, 0);
        state[r].locked.assign(n, 0);
    }
    for (;;) {
        std::vector<std::uint32_t> changed;
        for (std::uint32_t r = 0; r < count; ++r)
            if (drop_short(samples[r], h[r], movable[r], gap, state[r])) {
                rebuild(r, samples[r], state[r], rings[r], grid);
                changed.push_back(r);
            }
        if (changed.empty())
            break;
        // Every conflict has an arc made in this pass: its dropped sample comes back, to stay.
        for (grid.update(); !changed.empty(); grid.update()) {
            const std::vector<ArcPair> conflicts = grid.conflicts();
            std::vector<std::uint32_t> restored;
            auto restore = [&](std::uint32_t r, std::uint32_t seg) {
                MergeRing &s = state[r];
                const std::size_t n = samples[r].size();
                const std::uint32_t from = s.order[seg], to = s.order[(seg + 1) % s.order.size()];
                for (std::uint32_t k = (from + 1) % n; k != to; k = (k + 1) % n)
                    if (s.pending[k]) {
                        s.dropped[k] = s.pending[k] = 0;
                        s.locked[k] = 1;
                        restored.push_back(r);
                    }
            };
            for (const ArcPair &c : conflicts) {
                restore(c.ring_a, c.seg_a);
                restore(c.ring_b, c.seg_b);
            }
            if (conflicts.empty())
                break;
            if (restored.empty())
                throw DataError("internal: merging close coast nodes left arcs that cross");
            std::sort(restored.begin(), restored.end());
            restored.erase(std::unique(restored.begin(), restored.end()), restored.end());
            for (const std::uint32_t r : restored)
                rebuild(r, samples[r], state[r], rings[r], grid);
        }
        for (MergeRing &s : state)
            std::fill(s.pending.begin(), s.pending.end(), 0);
    }
    std::size_t merged = 0;
    kept.assign(count, {});
    for (std::uint32_t r = 0; r < count; ++r) {
        merged += samples[r].size() - state[r].order.size();
        kept[r] = std::move(state[r].order);
    }
    return merged;
}

} // namespace globemesh::coast_detail
