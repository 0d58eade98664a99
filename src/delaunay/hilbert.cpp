#include "hilbert.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace globemesh::detail {

namespace {

// Hilbert index of (x, y) in a 2^order x 2^order grid (the classic rotate-and-flip loop).
std::uint64_t hilbert_index(std::uint32_t x, std::uint32_t y, int order) {
    const std::uint32_t mask = (1u << order) - 1;
    std::uint64_t d = 0;
    for (std::uint32_t s = 1u << (order - 1); s > 0; s >>= 1) {
        std::uint32_t rx = (x & s) ? 1 : 0;
        std::uint32_t ry = (y & s) ? 1 : 0;
        d += static_cast<std::uint64_t>(s) * s * ((3 * rx) ^ ry);
        if (ry == 0) { // rotate the quadrant; only the lower bits matter from here on
            if (rx == 1) {
                x = mask - x;
                y = mask - y;
            }
            std::swap(x, y);
        }
    }
    return d;
}

} // namespace

std::uint64_t hilbert_key(const Vec3& p) {
    constexpr int order = 30;
    double ax = std::fabs(p.x), ay = std::fabs(p.y), az = std::fabs(p.z);
    int face;
    double u, v, m;
    if (ax >= ay && ax >= az) { face = p.x >= 0 ? 0 : 1; m = ax; u = p.y; v = p.z; }
    else if (ay >= az) { face = p.y >= 0 ? 2 : 3; m = ay; u = p.z; v = p.x; }
    else { face = p.z >= 0 ? 4 : 5; m = az; u = p.x; v = p.y; }
    if (!(m > 0)) return 0;
    const double scale = static_cast<double>((1u << order) - 1);
    auto cell = [&](double w) {
        double t = (w / m + 1.0) * 0.5; // [0, 1]
        t = std::clamp(t, 0.0, 1.0);
        return static_cast<std::uint32_t>(t * scale);
    };
    return (static_cast<std::uint64_t>(face) << 61) | hilbert_index(cell(u), cell(v), order);
}

std::vector<std::uint32_t> brio_order(std::span<const Vec3> points, std::uint64_t seed) {
    const std::size_t n = points.size();
    std::vector<std::uint32_t> order(n);
    for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
    std::mt19937_64 rng(seed);
    std::shuffle(order.begin(), order.end(), rng);
    std::vector<std::uint64_t> keys(n);
    for (std::size_t i = 0; i < n; ++i) keys[i] = hilbert_key(points[i]);
    // Round boundaries: [0, n/2^R), [n/2^R, n/2^(R-1)), ..., [n/2, n).
    std::size_t lo = 0;
    std::vector<std::size_t> ends;
    for (std::size_t end = n; end > 64; end /= 2) ends.push_back(end);
    std::reverse(ends.begin(), ends.end());
    if (ends.empty() || ends.back() != n) ends.push_back(n);
    for (std::size_t end : ends) {
        std::sort(order.begin() + lo, order.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
            return keys[a] != keys[b] ? keys[a] < keys[b] : a < b;
        });
        lo = end;
    }
    return order;
}

} // namespace globemesh::detail
