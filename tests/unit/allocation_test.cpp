// The executables' allocation policy (src/cli/allocation.cpp), judged by the kernel's own account
// of the process's mappings: /proc/self/smaps lists each mapping's flags, "hg" where it was
// advised MADV_HUGEPAGE. This executable links globemesh_allocation as globemesh does.
#include <cstdint>
#include <fstream>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "allocation.hpp"

namespace {

// The VmFlags line of the mapping that holds p, or "" when none does (no smaps: not Linux).
std::string mapping_flags(const void *p) {
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> lo >> dash >> hi && dash == '-' &&
            line.find(':') > line.find(' ')) {
            inside = lo <= at && at < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0)
            return line;
    }
    return "";
}

bool advised_huge(const std::string &flags) {
    return flags.find(" hg") != std::string::npos;
}

class Allocation : public ::testing::Test {
protected:
    void SetUp() override {
        if (!globemesh::replaces_operator_new())
            GTEST_SKIP() << "operator new is not replaced in this build";
        globemesh::configure_allocation();
    }
};

TEST_F(Allocation, blocks_of_2_mib_and_more_are_advised_huge_pages) {
    for (const std::size_t mib : {2, 3, 16}) {
        const std::unique_ptr<char[]> block(new char[mib << 20]); // not touched
        const std::string flags = mapping_flags(block.get() + (mib << 19));
        ASSERT_FALSE(flags.empty()) << "no mapping found in /proc/self/smaps";
        EXPECT_TRUE(advised_huge(flags)) << mib << " MiB: " << flags;
    }
}

TEST_F(Allocation, blocks_of_1_mib_and_more_start_on_a_huge_page_boundary) {
    // Only a whole aligned 2 MiB of a mapping can be a huge page: a block placed anywhere else
    // would be filled 4 KiB at a time.
    for (const std::size_t kib : {1024, 1500, 3000, 16384}) {
        const std::unique_ptr<char[]> block(new char[kib << 10]);
        EXPECT_EQ(reinterpret_cast<std::uintptr_t>(block.get()) % (std::uintptr_t{2} << 20), 0u)
            << kib << " KiB";
        EXPECT_TRUE(advised_huge(mapping_flags(block.get()))) << kib << " KiB";
        block[(kib << 10) - 1] = 1; // the whole block is there to write
    }
}

TEST_F(Allocation, a_freed_large_block_is_given_back) {
    char *block = new char[3 << 20];
    ASSERT_FALSE(mapping_flags(block).empty());
    delete[] block;
    EXPECT_EQ(mapping_flags(block), "") << "the block's mapping is still there after delete";
}

TEST_F(Allocation, more_large_blocks_than_the_table_holds_come_from_malloc_and_are_freed_alike) {
    std::vector<std::unique_ptr<char[]>> blocks;
    for (int i = 0; i < 1100; ++i)
        blocks.emplace_back(new char[1 << 20]); // the table holds 1024
    std::size_t aligned = 0;
    for (std::size_t i = 0; i < blocks.size(); ++i) {
        if (reinterpret_cast<std::uintptr_t>(blocks[i].get()) % (std::uintptr_t{2} << 20) == 0) {
            ++aligned; // left untouched: each would take a whole huge page
            continue;
        }
        blocks[i][0] = 1, blocks[i][(1 << 20) - 1] = 2; // malloc's
        EXPECT_FALSE(advised_huge(mapping_flags(blocks[i].get())));
    }
    EXPECT_GE(aligned, 1024u);
    EXPECT_LT(aligned, 1100u);
    blocks.clear();
    const std::unique_ptr<char[]> again(new char[1 << 20]); // the table has room again
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(again.get()) % (std::uintptr_t{2} << 20), 0u);
}

TEST_F(Allocation, small_blocks_are_left_as_they_are) {
    const std::unique_ptr<char[]> block(new char[64 << 10]);
    const std::string flags = mapping_flags(block.get());
    ASSERT_FALSE(flags.empty()) << "no mapping found in /proc/self/smaps";
    EXPECT_FALSE(advised_huge(flags)) << flags;
}

// [new.delete.single]: on failure the new_handler runs, and bad_alloc comes once there is none.
int handler_calls = 0;
void give_up() {
    ++handler_calls;
    std::set_new_handler(nullptr);
}

TEST_F(Allocation, a_failed_allocation_calls_the_new_handler_then_throws_bad_alloc) {
    handler_calls = 0;
    std::set_new_handler(give_up);
    volatile std::size_t too_much = SIZE_MAX / 2; // no malloc can give it
    EXPECT_THROW((void)::operator new(too_much), std::bad_alloc);
    EXPECT_EQ(handler_calls, 1);
    std::set_new_handler(nullptr);
}

} // namespace
