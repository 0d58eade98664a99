#include "hilbert.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

namespace globemesh::detail {

namespace {

// Hilbert index of (x, y) in a 2^order x 2^order grid: the classic rotate-and-flip loop, run as
// a table-driven state machine. The loop's rotations (swap x and y; complement the lower bits)
// compose into 4 states; one table step reads 3 bits of x and 3 of y and gives 6 bits of the
// index and the next state. Same index as the loop, without its unpredictable branches.
struct HilbertTable {
    std::uint8_t digits[4][64]; // 6 output bits
    std::uint8_t next[4][64];   // next state
    constexpr HilbertTable() : digits{}, next{} {
        for (int state = 0; state < 4; ++state)
            for (int in = 0; in < 64; ++in) {
                int swapped = state & 1, inverted = (state >> 1) & 1;
                int out = 0;
                for (int bit = 2; bit >= 0; --bit) {
                    int xb = (in >> (3 + bit)) & 1, yb = (in >> bit) & 1;
                    int rx = (swapped ? yb : xb) ^ inverted;
                    int ry = (swapped ? xb : yb) ^ inverted;
                    out = (out << 2) | ((3 * rx) ^ ry);
                    if (ry == 0) {
                        if (rx == 1)
                            inverted ^= 1;
                        swapped ^= 1;
                    }
                }
                digits[state][in] = static_cast<std::uint8_t>(out);
                next[state][in] = static_cast<std::uint8_t>(swapped | (inverted << 1));
            }
    }
};
constexpr HilbertTable hilbert_table{};

std::uint64_t hilbert_index(std::uint32_t x, std::uint32_t y, int order) {
    // order is a multiple of 3 here (15).
    std::uint64_t d = 0;
    unsigned state = 0;
    for (int shift = order - 3; shift >= 0; shift -= 3) {
        const unsigned in = (((x >> shift) & 7u) << 3) | ((y >> shift) & 7u);
        d = (d << 6) | hilbert_table.digits[state][in];
        state = hilbert_table.next[state][in];
    }
    return d;
}

} // namespace

std::uint32_t hilbert_key(const Vec3 &p) {
    constexpr int order = 15;
    double ax = std::fabs(p.x), ay = std::fabs(p.y), az = std::fabs(p.z);
    std::uint32_t face;
    double u, v, m;
    if (ax >= ay && ax >= az) {
        face = p.x >= 0 ? 0 : 1;
        m = ax;
        u = p.y;
        v = p.z;
    } else if (ay >= az) {
        face = p.y >= 0 ? 2 : 3;
        m = ay;
        u = p.z;
        v = p.x;
    } else {
        face = p.z >= 0 ? 4 : 5;
        m = az;
        u = p.x;
        v = p.y;
    }
    if (!(m > 0))
        return 0;
    const double scale = static_cast<double>((1u << order) - 1);
    auto cell = [&](double w) {
        double t = (w / m + 1.0) * 0.5; // [0, 1]
        t = std::clamp(t, 0.0, 1.0);
        return static_cast<std::uint32_t>(t * scale);
    };
    return (face << 29) | static_cast<std::uint32_t>(hilbert_index(cell(u), cell(v), order) >> 1);
}

std::vector<std::uint32_t> brio_order(std::span<const Vec3> points, std::uint64_t seed) {
    const std::size_t n = points.size();
    // One 64-bit word per point: its 32-bit Hilbert key above its index, so sorting the words
    // sorts by (key, index). Keyed in input order (sequential reads
    // of the points), then shuffled: std::shuffle's swaps depend only on the generator and the
    // length, so this is the shuffled index order with its keys alongside. Half the bytes of
    // (key, index) pairs, and a plain integer comparison.
    std::vector<std::uint64_t> keyed(n);
    for (std::size_t i = 0; i < n; ++i)
        keyed[i] = (std::uint64_t{hilbert_key(points[i])} << 32) | static_cast<std::uint32_t>(i);
    std::mt19937_64 rng(seed);
    std::shuffle(keyed.begin(), keyed.end(), rng);
    // Round boundaries: [0, n/2^R), [n/2^R, n/2^(R-1)), ..., [n/2, n).
    std::size_t lo = 0;
    std::vector<std::size_t> ends;
    for (std::size_t end = n; end > 64; end /= 2)
        ends.push_back(end);
    std::reverse(ends.begin(), ends.end());
    if (ends.empty() || ends.back() != n)
        ends.push_back(n);
    for (std::size_t end : ends) {
        std::sort(keyed.begin() + lo, keyed.begin() + end);
        lo = end;
    }
    std::vector<std::uint32_t> order(n);
    for (std::size_t j = 0; j < n; ++j)
        order[j] = static_cast<std::uint32_t>(keyed[j]);
    return order;
}

} // namespace globemesh::detail
