// Internal to the coast module: independent pieces of work (polygons, snap-rounding batches,
// rings) run on every core, their results kept per piece so that the caller joins them in a
// fixed order: the output never depends on the number of threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

#include "geos_handles.hpp"
#include "geos_interrupt.hpp"

namespace globemesh::coast_detail {

/// Threads of the coast's parallel loops: one per core, at most 16.
inline std::size_t coast_threads() {
    return std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
}

/// Runs task(i) for i = 0 .. n-1 on every core, the calling thread included (the only one that
/// reports progress and sees a cancelled run: it then stops the others), started in the order of
/// `first` when given (a permutation: the longest tasks first keep a core from finishing alone).
/// After all, a cancelled run's Cancelled is thrown, else the exception of the lowest i that
/// threw. `start` runs a worker's loop (given the loop to run), e.g. in a GEOS context of its own.
template <class Task, class Start>
void parallel_for_each(std::size_t n, const Task &task, const Start &start,
                       const std::vector<std::size_t> *first = nullptr) {
    std::atomic<std::size_t> next{0};
    std::atomic<bool> stop{false};
    std::vector<std::exception_ptr> errors(n);
    auto loop = [&] {
        for (std::size_t k; !stop && (k = next.fetch_add(1)) < n;) {
            const std::size_t i = first ? (*first)[k] : k;
            try {
                task(i);
            } catch (...) {
                errors[i] = std::current_exception();
                if (coast::GeosInterrupt::interrupted()) // true on the calling thread only
                    stop = true;
            }
        }
    };
    std::vector<std::thread> pool;
    const std::size_t threads = std::min(coast_threads(), n);
    try {
        for (std::size_t k = 1; k < threads; ++k)
            pool.emplace_back([&] { start(loop); });
    } catch (const std::system_error &) {
        // No more threads (a process limit): fewer workers take the pieces.
    }
    loop();
    for (auto &t : pool)
        t.join();
    coast::GeosInterrupt::poll();
    for (const auto &e : errors)
        if (e)
            std::rethrow_exception(e);
}

/// parallel_for_each for tasks that need no GEOS.
template <class Task> void parallel_for_each(std::size_t n, const Task &task) {
    parallel_for_each(n, task, [](const auto &loop) { loop(); });
}

/// Indices 0 .. sizes.size()-1, the largest size first (ties in index order).
inline std::vector<std::size_t> largest_first(const std::vector<std::size_t> &sizes) {
    std::vector<std::size_t> order(sizes.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return sizes[a] > sizes[b]; });
    return order;
}

/// parallel_for_each with task(geos, i): `geos` is the caller's context on its thread and a
/// worker's own elsewhere. A geometry made in a worker's context outlives the loop only as a raw
/// pointer (owned again by the caller, e.g. GeomPtr{g, GeosDeleter{caller's}}): the worker's
/// context ends with the loop. GEOS 3.11's reentrant API runs concurrently in separate contexts;
/// they share only the default GeometryFactory, whose reference count (unsynchronised) GEOS never
/// acts on for that factory.
template <class Task>
void parallel_for_each_geos(Geos &geos, std::size_t n, const Task &task,
                            const std::vector<std::size_t> *first = nullptr) {
    thread_local Geos *mine = nullptr;
    Geos *const caller = &geos;
    parallel_for_each(
        n, [&](std::size_t i) { task(mine ? *mine : *caller, i); },
        [](const auto &loop) {
            Geos own;
            mine = &own;
            loop();
            mine = nullptr;
        },
        first);
}

} // namespace globemesh::coast_detail
