// Internal to io/: large arrays whose fresh pages are first written on every core.
//
// The first write to a page the process has not used yet costs a fault in which the kernel
// clears it: on the 2-core machine, at 1.7e7 nodes, more than the topology's and the face
// areas' own computation (bench/RESULTS-writers.md). A std::vector of n values writes them all
// (zeros) on the calling thread; these are left unwritten and their pages touched from every
// core instead (for_each_range), before the caller fills them.
#pragma once

#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "ordered_blocks.hpp"

namespace globemesh::io {

/// Touches the pages of n values at `data` (written before their own values are), on every
/// core when they span at least a few pages.
template <class T> void touch_pages(T *data, std::size_t n) {
    static_assert(std::is_trivially_copyable_v<T>);
    constexpr std::size_t page = 4096, step = sizeof(T) >= page ? 1 : page / sizeof(T);
    const std::size_t pages = (n + step - 1) / step;
    auto touch = [&](std::size_t first, std::size_t last) {
        for (std::size_t p = first; p < last; ++p)
            data[p * step] = T{};
    };
    if (pages < 64)
        touch(0, pages);
    else
        for_each_range(pages, touch);
}

/// n values of T, unwritten (to be filled by the caller), their pages touched on every core.
template <class T> std::unique_ptr<T[]> fresh_array(std::size_t n) {
    static_assert(std::is_trivially_default_constructible_v<T>);
    auto a = std::make_unique_for_overwrite<T[]>(n);
    touch_pages(a.get(), n);
    return a;
}

/// An allocator whose vectors leave new elements of trivial types unwritten (resize does not
/// write zeros), for vectors filled by index after touch_pages.
template <class T> struct FreshAllocator : std::allocator<T> {
    template <class U> struct rebind { using other = FreshAllocator<U>; };
    FreshAllocator() = default;
    template <class U> FreshAllocator(const FreshAllocator<U> &) noexcept {}
    template <class U> void construct(U *p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void *>(p)) U;
    }
    template <class U, class... Args> void construct(U *p, Args &&...args) {
        ::new (static_cast<void *>(p)) U(std::forward<Args>(args)...);
    }
};

/// An empty vector resized to n unwritten values, their pages touched on every core.
template <class T> void fresh_resize(std::vector<T, FreshAllocator<T>> &v, std::size_t n) {
    v.resize(n);
    touch_pages(v.data(), n);
}

} // namespace globemesh::io
