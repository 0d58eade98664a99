// The executables' allocation policy (allocation.cpp): linked, as the object library
// globemesh_allocation, into the globemesh executable and into the benchmarks that measure it,
// so that they allocate alike. Linking it replaces the global operator new and delete (blocks of
// 1 MiB and more mapped on their own, aligned for and backed by transparent huge pages, on Linux
// with glibc); the library itself never depends on it.
#pragma once

namespace globemesh {

/// Sets glibc's allocator options for a whole run (a fixed 1 MiB mmap threshold, a 256 MiB trim
/// threshold); call first thing in main. Does nothing elsewhere.
void configure_allocation();

/// True where linking this policy replaces operator new and delete (Linux with glibc, not under
/// AddressSanitizer).
bool replaces_operator_new();

} // namespace globemesh
