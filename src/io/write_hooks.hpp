// Test hooks of the writers, outside the public API: tests (and benchmarks) include this header
// from src/ to stop a writer half-way and check that it leaves no file.
#pragma once

#include <functional>
#include <utility>

namespace globemesh::detail {

/// Called once by write_ugrid, write_gpkg and write_preview_png of this thread after their data
/// is partly written, before the rename; empty in normal use.
inline thread_local std::function<void()> after_partial_write;

/// Sets after_partial_write for the life of this object.
class PartialWriteHook {
public:
    explicit PartialWriteHook(std::function<void()> hook) { after_partial_write = std::move(hook); }
    ~PartialWriteHook() { after_partial_write = nullptr; }
    PartialWriteHook(const PartialWriteHook &) = delete;
    PartialWriteHook &operator=(const PartialWriteHook &) = delete;
};

} // namespace globemesh::detail
