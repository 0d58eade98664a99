// Internal: disjoint sets of 0 .. n - 1, union-find with path halving, for the mesher, the coast
// and the writers (each set's root is the same for the same joins in the same order).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace globemesh {

template <class Index = std::uint32_t> class DisjointSets {
public:
    explicit DisjointSets(std::size_t n) : parent_(n) {
        for (std::size_t i = 0; i < n; ++i)
            parent_[i] = static_cast<Index>(i);
    }
    Index find(Index i) {
        while (parent_[i] != i)
            i = parent_[i] = parent_[parent_[i]];
        return i;
    }
    /// b's set joins a's: b's root then points at a's.
    void join(Index a, Index b) { parent_[find(b)] = find(a); }
    /// Each element's root, in place (roots stay roots); the sets are spent.
    std::vector<Index> roots() && {
        for (std::size_t i = 0; i < parent_.size(); ++i)
            parent_[i] = find(static_cast<Index>(i));
        return std::move(parent_);
    }

private:
    std::vector<Index> parent_;
};

} // namespace globemesh
