// The executables' allocation policy (globemesh and the benchmarks that stand for it): large
// blocks are given back when freed, and backed by transparent huge pages when they are touched;
// the heap of small blocks keeps its top.
//
// Why huge pages: the core and the mesher fill arrays of tens to hundreds of MiB, and every first
// touch of a 4 KiB page is a page fault. On the project's machines (a paravirtualised VM, where
// a fault costs about 6.5 us) mesh_boundary at 20 km (1.08e6 nodes) ran 3.7-3.9 s, 2 s of it
// system time; with every block of 2 MiB or more advised MADV_HUGEPAGE, 2.1-2.3 s, and the
// core's 1e6 random points 0.82 -> 0.59-0.60 s (bench/RESULTS.md, session 15). The kernel's
// default (transparent_hugepage=madvise, as Debian ships it) gives huge pages only where asked;
// glibc's own switch for it, the glibc.malloc.hugetlb tunable, is read from the environment at
// start-up only, so the executable asks itself, in the one allocation function C++ lets a
// program replace.
// The library never relies on it: it is the program's choice, as mallopt is.
#include "allocation.hpp"

#include <cstdint>
#include <cstdlib>
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

void configure_allocation() {
#ifdef __GLIBC__
    // glibc raises its mmap threshold each time a large block is freed (up to 32 MiB), so the
    // arrays of one stage, once freed, stay in the heap and in the resident set under the next
    // stage's. A fixed 1 MiB threshold gives every large array back when it is freed: the peak
    // at 1e6 nodes goes from about 199 to 187 bytes a node, the write about 5% slower. It also
    // makes every large block a mapping of its own, which operator new below advises.
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
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

// Blocks from this size up may hold a whole 2 MiB huge page.
constexpr std::size_t huge_page_bytes = std::size_t{2} << 20;
constexpr std::uintptr_t page_bytes = 4096;

// Advises the pages of [p, p + n) (widened to whole pages) to be backed by huge pages when first
// touched. A block of that size is a fresh mapping of its own (M_MMAP_THRESHOLD above), not yet
// touched but for malloc's header in its first page. Advice only: a failure changes nothing.
void advise_huge_pages(void* p, std::size_t n) {
    const auto begin = reinterpret_cast<std::uintptr_t>(p) & ~(page_bytes - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(p) + n + page_bytes - 1) & ~(page_bytes - 1);
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

} // namespace

// The replaceable global allocation function ([new.delete.single]): as the default one, with
// the advice for large blocks. The default operator delete frees with std::free, and the array
// and nothrow forms call this one (libstdc++), so this is the one function to replace.
void* operator new(std::size_t n) {
    if (n == 0) n = 1;
    void* p;
    while ((p = std::malloc(n)) == nullptr) {
        std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
    if (n >= huge_page_bytes) advise_huge_pages(p, n);
    return p;
}
#endif
