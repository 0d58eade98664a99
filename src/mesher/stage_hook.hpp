// Internal to the library and its benchmarks, not installed: a hook mesh_boundary calls as each
// of its stages ends, while nothing of the next has run (bench/mesher_memory samples the
// process's memory there). Empty in every run of the library and the command line.
#pragma once

#include <functional>
#include <string>

namespace globemesh::mesher_internal {

/// Called with the stage's name (as in StageTimings) after each stage of this thread's
/// mesh_boundary calls; empty: nothing is called.
inline thread_local std::function<void(const std::string &stage)> after_stage;

} // namespace globemesh::mesher_internal
