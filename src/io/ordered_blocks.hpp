// Internal to io/: the writers' blocks of rows or features, computed on every core and stored in
// order from the calling thread.
//
// The file libraries (netCDF-C and HDF5, GDAL and SQLite) are called from one thread; what goes
// into a file (coordinates, connectivity, compressed chunks, features with their geometry) is
// computed from the mesh alone. So block k is computed on any thread, into a slot of its own,
// and stored by the calling thread once blocks 0 .. k - 1 are: the file does not depend on the
// timing. The calling thread computes too while the next block to store is not ready, and alone
// when no thread can be started. start_task runs one computation beside the caller the same way.
#pragma once

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <future>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace globemesh::io {

/// Threads for the writers' blocks: one per core, at most 8.
inline std::size_t block_threads() {
    return std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 8);
}

/// std::async(task) on a thread of its own, or deferred (run in turn when its result is asked
/// for) when the process may start no more threads.
template <class Task> auto start_task(const Task &task) {
    try {
        return std::async(std::launch::async, task);
    } catch (const std::system_error &) {
        return std::async(std::launch::deferred, task);
    }
}

/// Runs task(k) for k in 0 .. parts - 1: task(0) on this thread, each other on a thread of its
/// own (start_task); returns once all have ended, rethrowing the first exception in k order.
template <class Task> void for_each_part(std::size_t parts, const Task &task) {
    std::vector<std::future<void>> others;
    for (std::size_t k = 1; k < parts; ++k)
        others.push_back(start_task([&, k] { task(k); }));
    task(0);
    for (auto &done : others)
        done.get();
}

/// Runs range(first, last) over [0, n) cut into one range per block thread, the first on this
/// thread; range must only read shared data and write what belongs to its own indices.
template <class Range> void for_each_range(std::size_t n, const Range &range) {
    const std::size_t parts = std::max<std::size_t>(1, std::min(n, block_threads()));
    for_each_part(parts, [&](std::size_t k) { range(n * k / parts, n * (k + 1) / parts); });
}

/// Runs compute(k, slot, worker) for each block k in 0 .. blocks - 1 on up to block_threads()
/// threads, then store(k, slot) on this thread in ascending k. A Slot holds a block's results
/// (slots are reused, one per thread: at most that many blocks computed ahead of the one
/// stored); a Worker is each thread's own scratch (default-constructed in the thread). compute
/// must only read shared data. An exception from compute is rethrown here when its block's turn
/// comes; one from store (a failure, a cancel) stops the threads and propagates.
template <class Slot, class Worker, class Compute, class Store>
void compute_in_order(std::size_t blocks, const Compute &compute, const Store &store) {
    if (blocks == 0)
        return;
    struct Entry {
        Slot slot{};
        std::exception_ptr error;
        bool ready = false;
    };
    const std::size_t threads = block_threads();
    std::vector<Entry> entries(std::min(blocks, threads));
    std::mutex mutex;
    std::condition_variable changed;
    std::size_t claimed = 0, stored = 0;
    bool stop = false;
    // Computes the next block when one is left and its entry is free (the lock held on entry and
    // on return); false otherwise.
    auto compute_next = [&](std::unique_lock<std::mutex> &lock, Worker &worker) {
        if (stop || claimed == blocks || claimed == stored + entries.size())
            return false;
        const std::size_t k = claimed++;
        Entry &e = entries[k % entries.size()];
        lock.unlock();
        try {
            compute(k, e.slot, worker);
        } catch (...) {
            e.error = std::current_exception();
        }
        lock.lock();
        e.ready = true;
        changed.notify_all();
        return true;
    };
    auto work = [&] {
        std::unique_lock lock(mutex);
        try {
            Worker worker{};
            while (!stop && claimed < blocks)
                if (!compute_next(lock, worker))
                    changed.wait(lock);
        } catch (...) {
            // No memory for the worker's scratch: the other threads do its share.
        }
    };
    std::vector<std::thread> pool;
    // Stops and joins the threads however this returns.
    struct Join {
        std::vector<std::thread> &pool;
        std::mutex &mutex;
        bool &stop;
        std::condition_variable &changed;
        ~Join() {
            {
                std::lock_guard lock(mutex);
                stop = true;
            }
            changed.notify_all();
            for (auto &t : pool)
                t.join();
        }
    } join{pool, mutex, stop, changed};
    try {
        for (std::size_t t = 1; t < threads && t < blocks; ++t)
            pool.emplace_back(work);
    } catch (const std::system_error &) {
        // No more threads (a process limit): fewer compute, this one among them.
    }
    Worker worker{};
    for (std::size_t k = 0; k < blocks; ++k) {
        Entry &e = entries[k % entries.size()];
        {
            std::unique_lock lock(mutex);
            while (!e.ready)
                if (!compute_next(lock, worker))
                    changed.wait(lock);
        }
        if (e.error)
            std::rethrow_exception(e.error);
        store(k, e.slot);
        {
            std::lock_guard lock(mutex);
            e.ready = false;
            ++stored;
        }
        changed.notify_all();
    }
}

} // namespace globemesh::io
