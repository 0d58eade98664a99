// The globemesh executable: forwards argv to run_cli, after one allocator setting.
#include <iostream>
#include <string>
#include <vector>
#ifdef __GLIBC__ // defined by the headers above
#include <malloc.h>
#endif

#include "globemesh/cli.hpp"

int main(int argc, char** argv) {
#ifdef __GLIBC__
    // glibc raises its mmap threshold each time a large block is freed (up to 32 MiB), so the
    // arrays of one stage, once freed, stay in the heap and in the resident set under the next
    // stage's. A fixed 1 MiB threshold gives every large array back when it is freed: the peak
    // at 1e6 nodes goes from about 199 to 187 bytes a node, the write about 5% slower.
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
    std::vector<std::string> args(argv + 1, argv + argc);
    return globemesh::run_cli(args, std::cout, std::cerr);
}
