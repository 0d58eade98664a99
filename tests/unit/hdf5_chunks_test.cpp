// The UGRID writer's chunk encoding (src/io/hdf5_chunks.hpp) read by zlib itself, as HDF5's
// deflate filter reads it: a chunk inflates to HDF5's byte shuffle of its rows (zeros past the
// last row) for doubles that are noise (only stored blocks), doubles of which only the high
// bytes compress (stored blocks, then deflated ones in the same stream), and integers (all
// deflated); and storing a double's noise costs under 1% of the size deflating it all gives.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <libdeflate.h>
#include <zlib.h>

#include "hdf5_chunks.hpp"

namespace {

using globemesh::io::ChunkEncoder;

/// HDF5's shuffle of `rows` values of T into a chunk of chunk_rows (zeros past them).
template <class T>
std::vector<unsigned char> shuffled(const std::vector<T> &v, std::size_t chunk_rows) {
    std::vector<unsigned char> out(chunk_rows * sizeof(T), 0);
    for (std::size_t i = 0; i < v.size(); ++i)
        for (std::size_t j = 0; j < sizeof(T); ++j)
            out[j * chunk_rows + i] = reinterpret_cast<const unsigned char *>(&v[i])[j];
    return out;
}

/// The chunk inflated by zlib's uncompress (which checks the zlib header and Adler-32), or
/// empty when zlib refuses it.
std::vector<unsigned char> inflated(const std::vector<unsigned char> &chunk, std::size_t bytes) {
    std::vector<unsigned char> out(bytes + 1);
    uLongf length = out.size();
    if (uncompress(out.data(), &length, chunk.data(), chunk.size()) != Z_OK)
        return {};
    out.resize(length);
    return out;
}

template <class T>
std::vector<unsigned char> encoded(const std::vector<T> &v, std::size_t chunk_rows) {
    ChunkEncoder encoder;
    std::vector<unsigned char> out;
    encoder.encode(v.data(), v.size(), chunk_rows, sizeof(T), sizeof(T), out);
    return out;
}

TEST(Hdf5Chunks, doubles_that_are_noise_are_stored_and_inflate_to_the_shuffle) {
    std::mt19937_64 rng(3);
    std::vector<double> v(70000); // two stored blocks a plane
    for (double &x : v) {
        const std::uint64_t bits =
            (rng() & ~(std::uint64_t(0x7ff) << 52)) | (std::uint64_t(0x3ff) << 52);
        std::memcpy(&x, &bits, sizeof x); // in [1, 2): random mantissa, one exponent
        x = rng() % 2 ? x : -x;
    }
    const std::size_t chunk_rows = v.size();
    const auto chunk = encoded(v, chunk_rows);
    const auto plain = shuffled(v, chunk_rows);
    EXPECT_EQ(inflated(chunk, chunk_rows * 8), plain);
    // The six random planes stored (the first block's bytes follow the 2-byte zlib header and
    // its own 5 bytes verbatim), the sign and exponent planes deflated.
    ASSERT_GT(chunk.size(), 7 + 65535u);
    EXPECT_EQ(std::memcmp(chunk.data() + 7, plain.data(), 65535), 0);
    EXPECT_GT(chunk.size(), 6 * chunk_rows);
    EXPECT_LT(chunk.size(), 7 * chunk_rows);
}

TEST(Hdf5Chunks, a_chunk_of_noise_in_every_plane_is_stored_blocks_to_the_final_one) {
    std::mt19937_64 rng(5);
    std::vector<double> v(20000);
    for (double &x : v) {
        const std::uint64_t bits = rng();
        std::memcpy(&x, &bits, sizeof x);
    }
    const auto chunk = encoded(v, v.size());
    EXPECT_EQ(inflated(chunk, v.size() * 8), shuffled(v, v.size()));
    EXPECT_LT(chunk.size(), v.size() * 8 + 100);
}

TEST(Hdf5Chunks, coordinates_and_integers_inflate_to_the_shuffle_within_1_percent_of_deflate) {
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> lon(-180, 180);
    std::vector<double> coords(65536 - 100); // a last chunk: rows past the values are zeros
    for (double &x : coords)
        x = lon(rng);
    std::vector<std::int32_t> links(3 * 50000);
    for (std::size_t i = 0; i < links.size(); ++i)
        links[i] = std::int32_t(i / 2 + rng() % 64);
    const auto c = encoded(coords, 65536);
    EXPECT_EQ(inflated(c, 65536 * 8), shuffled(coords, 65536));
    std::vector<unsigned char> l;
    ChunkEncoder().encode(links.data(), 50000, 50000, 12, 4, l);
    EXPECT_EQ(inflated(l, links.size() * 4), shuffled(links, links.size()));
    // Against libdeflate's own zlib stream of the whole shuffled chunk at the same level.
    auto *d = libdeflate_alloc_compressor(1);
    const auto plain = shuffled(coords, 65536);
    std::vector<unsigned char> all(libdeflate_zlib_compress_bound(d, plain.size()));
    all.resize(libdeflate_zlib_compress(d, plain.data(), plain.size(), all.data(), all.size()));
    libdeflate_free_compressor(d);
    EXPECT_LT(double(c.size()), 1.01 * double(all.size()));
    EXPECT_LT(double(c.size()), 0.9 * double(plain.size())); // the high planes are deflated
}

} // namespace
