// io::fresh_array, touch_pages and FreshAllocator (src/io/fresh_memory.hpp): the arrays hold
// what is written into them at every size, touch_pages writes one value a page and nothing past
// the end, and a FreshAllocator vector keeps its values when it grows.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "fresh_memory.hpp"

namespace {

namespace io = globemesh::io;

TEST(FreshMemory, an_array_holds_what_is_written_at_every_size) {
    for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(511), std::size_t(512),
                          std::size_t(513), std::size_t(1) << 20}) {
        auto a = io::fresh_array<std::uint64_t>(n);
        for (std::size_t i = 0; i < n; ++i)
            a[i] = 3 * i + 1;
        for (std::size_t i = 0; i < n; ++i)
            ASSERT_EQ(a[i], 3 * i + 1) << "n " << n << " i " << i;
    }
}

TEST(FreshMemory, touch_pages_writes_one_zero_at_the_start_of_each_page) {
    for (std::size_t n : {std::size_t(1000), std::size_t(700000)}) { // on one thread, then all
        std::vector<std::uint32_t> v(n, 7);
        io::touch_pages(v.data(), n);
        for (std::size_t i = 0; i < n; ++i)
            ASSERT_EQ(v[i], i % 1024 == 0 ? 0u : 7u) << "n " << n << " i " << i;
    }
}

TEST(FreshMemory, a_fresh_vector_keeps_its_values_when_it_grows) {
    std::vector<std::uint32_t, io::FreshAllocator<std::uint32_t>> v;
    io::fresh_resize(v, 5000);
    ASSERT_EQ(v.size(), 5000u);
    for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = std::uint32_t(i);
    v.push_back(5000);
    v.resize(100000);
    for (std::size_t i = 0; i <= 5000; ++i)
        ASSERT_EQ(v[i], i);
}

} // namespace
