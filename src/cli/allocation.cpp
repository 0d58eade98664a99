// The executables' allocation policy (globemesh and the benchmarks that stand for it): large
// blocks are mappings of their own, aligned for and backed by transparent huge pages, given back
// when freed; the heap of small blocks keeps its top.
//
// Why huge pages: the core and the mesher fill arrays of tens to hundreds of MiB, and every first
// touch of a 4 KiB page is a page fault. On the project's machines (a paravirtualised VM, where
// a fault costs about 6.5-10 us) mesh_boundary at 20 km (1.08e6 nodes) ran 3.7-3.9 s, 2 s of it
// system time; with every block of 2 MiB or more advised MADV_HUGEPAGE, 2.1-2.3 s, and the
// core's 1e6 random points 0.82 -> 0.59-0.60 s (bench/RESULTS.md, session 15). Those blocks were
// malloc's, placed on any 4 KiB boundary, where the kernel backs only the whole aligned 2 MiB
// with huge pages; blocks of 1 MiB and more are now mapped here on a 2 MiB boundary (operator
// new below). Alternated runs of globemesh mesh on 1:50m land: mesh 64 km 0.277 -> 0.240 s,
// 20 km 1.49 -> 1.30 s, 10 km 4.4 -> 3.8 s, the peak unchanged (session 25). The kernel's
// default (transparent_hugepage=madvise, as Debian ships it) gives huge pages only where asked;
// glibc's own switch for it, the glibc.malloc.hugetlb tunable, is read from the environment at
// start-up only and does not align, so the executable does it, in the allocation functions C++
// lets a program replace.
// The library never relies on it: it is the program's choice, as mallopt is.
#include "allocation.hpp"

#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <new>

#ifdef __GLIBC__
#include <malloc.h> // mallopt
#endif
#if defined(__GLIBC__) && defined(__linux__)
#include <sys/mman.h>
#define GLOBEMESH_HUGE_PAGES 1
#endif
// Under the sanitizers the runtime's own operator new must stay (it tracks every block).
#if defined(__SANITIZE_ADDRESS__)
#undef GLOBEMESH_HUGE_PAGES
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#undef GLOBEMESH_HUGE_PAGES
#endif
#endif

namespace globemesh {
namespace {
// glibc's mmap threshold (configure_allocation), and the size from which operator new below maps
// a block itself: one size, so that every large block is a mapping of its own either way.
constexpr std::size_t own_mapping_bytes = std::size_t{1} << 20;
} // namespace

void configure_allocation() {
#ifdef __GLIBC__
    // glibc raises its mmap threshold each time a large block is freed (up to 32 MiB), so the
    // arrays of one stage, once freed, stay in the heap and in the resident set under the next
    // stage's. A fixed 1 MiB threshold gives every large array back when it is freed: the peak
    // at 1e6 nodes goes from about 199 to 187 bytes a node, the write about 5% slower. (The
    // blocks C++ allocates from 1 MiB up are mappings of operator new's below.)
    mallopt(M_MMAP_THRESHOLD, int(own_mapping_bytes));
    // The blocks under 1 MiB come from the heap, and glibc gives its top back to the system as
    // soon as 128 KiB there are free, so that a loop allocating and freeing a few hundred KiB
    // (GEOS's monotone chains in load_coast above all) faults the same pages in again
    // and again. A top kept up to 256 MiB (never more than the small blocks held at once):
    // mesh_boundary at 20 km 181,000 -> 38,000 page faults in its process, mesh 2.06-2.17 ->
    // 1.91-1.93 s, its peak 116-117 -> 118 B/node.
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
#endif
}

bool replaces_operator_new() {
#ifdef GLOBEMESH_HUGE_PAGES
    return true;
#else
    return false;
#endif
}

} // namespace globemesh

#ifdef GLOBEMESH_HUGE_PAGES
namespace {

constexpr std::size_t huge_page_bytes = std::size_t{2} << 20;
constexpr std::uintptr_t page_bytes = 4096;

// The live blocks of map_block, for operator delete. Large blocks are few (tens at a time), so a
// fixed table scanned under a lock is enough, and it allocates nothing itself; when it is full,
// blocks come from malloc as smaller ones do.
struct Mapping {
    void *at;
    std::size_t bytes;
};
constexpr std::size_t max_mappings = 1024;
Mapping mappings[max_mappings];
std::size_t mapping_count = 0;
std::mutex mappings_lock;

// A mapping of at least n bytes (whole pages, and at least one huge page) that starts on a 2 MiB
// boundary, advised MADV_HUGEPAGE, or null. malloc maps a large block wherever the kernel puts
// it, on any 4 KiB boundary, and the kernel backs with a huge page only a whole aligned 2 MiB of
// an advised mapping: the blocks of 1 to 4 MiB that a mesh of 1e5 nodes is made of got few huge
// pages or none, and were filled 4 KiB page fault by page fault. Rounding a block under 2 MiB up
// to one huge page costs its unused part once touched, at most 1 MiB a block.
void *map_block(std::size_t n) {
    const std::size_t bytes =
        n < huge_page_bytes ? huge_page_bytes : (n + page_bytes - 1) & ~(page_bytes - 1);
    const std::size_t span = bytes + huge_page_bytes; // room to slide to a 2 MiB boundary
    void *raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED)
        return nullptr;
    const auto first = reinterpret_cast<std::uintptr_t>(raw);
    const auto at = (first + huge_page_bytes - 1) & ~(huge_page_bytes - 1);
    if (at > first)
        munmap(raw, at - first);
    if (first + span > at + bytes)
        munmap(reinterpret_cast<void *>(at + bytes), first + span - (at + bytes));
    void *p = reinterpret_cast<void *>(at);
    madvise(p, bytes, MADV_HUGEPAGE); // advice only: a failure changes nothing
    const std::lock_guard<std::mutex> hold(mappings_lock);
    if (mapping_count == max_mappings) {
        munmap(p, bytes);
        return nullptr;
    }
    mappings[mapping_count++] = {p, bytes};
    return p;
}

// Unmaps p when map_block made it; false otherwise (malloc's blocks are never 2 MiB-aligned
// but by chance, which the table settles).
bool unmap_block(void *p) {
    if ((reinterpret_cast<std::uintptr_t>(p) & (huge_page_bytes - 1)) != 0)
        return false;
    const std::lock_guard<std::mutex> hold(mappings_lock);
    for (std::size_t i = 0; i < mapping_count; ++i)
        if (mappings[i].at == p) {
            munmap(p, mappings[i].bytes);
            mappings[i] = mappings[--mapping_count];
            return true;
        }
    return false;
}

} // namespace

// The replaceable global allocation and deallocation functions ([new.delete.single]): large
// blocks from map_block, the others (and large ones map_block cannot give) from malloc as by
// default. libstdc++'s array, nothrow and sized forms call these two, so these are the two to
// replace; the over-aligned forms keep their own (aligned_alloc and free).
void *operator new(std::size_t n) {
    if (n == 0)
        n = 1;
    if (n >= globemesh::own_mapping_bytes)
        if (void *p = map_block(n))
            return p;
    void *p;
    while ((p = std::malloc(n)) == nullptr) {
        std::new_handler handler = std::get_new_handler();
        if (!handler)
            throw std::bad_alloc();
        handler();
    }
    return p;
}

void operator delete(void *p) noexcept {
    if (p != nullptr && unmap_block(p))
        return;
    std::free(p);
}

void operator delete(void *p, std::size_t) noexcept {
    operator delete(p);
}
#endif
