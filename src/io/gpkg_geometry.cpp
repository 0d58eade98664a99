// GeoPackage geometry of the mesh: see gpkg_geometry.hpp.
#include "gpkg_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

namespace globemesh::io {

namespace {

std::pair<double, double> lon_range(const LonLatPart &part) {
    auto [lo, hi] = std::minmax_element(part.begin(), part.end(),
                                        [](const auto &p, const auto &q) { return p[0] < q[0]; });
    return {(*lo)[0], (*hi)[0]};
}

/// Sutherland-Hodgman clip of a ring to lo <= lon <= hi (exact at the cut meridians).
LonLatPart clip_ring_to_band(const LonLatPart &ring, double lo, double hi) {
    LonLatPart r = ring;
    for (int side = 0; side < 2; ++side) {
        const double x = side ? hi : lo;
        auto inside = [&](const LonLatPoint &p) { return side ? p[0] <= x : p[0] >= x; };
        LonLatPart out;
        for (std::size_t i = 0; i < r.size(); ++i) {
            const auto &p = r[i], &q = r[(i + 1) % r.size()];
            const bool pin = inside(p), qin = inside(q);
            if (pin)
                out.push_back(p);
            if (pin != qin)
                out.push_back({x, p[1] + (x - p[0]) / (q[0] - p[0]) * (q[1] - p[1])});
        }
        r = std::move(out);
    }
    return r;
}

} // namespace

/// The ring itself if it is at most 180 degrees wide, else its pieces between the meridians at
/// multiples of 180 (0 for a ring within [-180, 180]), each at most 180 wide. Only a face round a
/// pole, closed along the pole line and so lon-monotone, is that wide: each band holds one piece.
std::vector<LonLatPart> narrow_rings(LonLatPart ring) {
    const auto [lo, hi] = lon_range(ring);
    if (hi - lo <= max_part_width_deg)
        return {std::move(ring)};
    std::vector<LonLatPart> parts;
    const double w = max_part_width_deg;
    for (double band = std::floor(lo / w) * w; band < hi; band += w) {
        LonLatPart piece = clip_ring_to_band(ring, std::max(lo, band), std::min(hi, band + w));
        if (piece.size() >= 3 && std::fabs(2 * ring_area(piece)) > 1e-18) // twice the area
            parts.push_back(std::move(piece));
    }
    return parts;
}

/// A line cut into pieces at most 180 degrees wide: a piece ends at the vertex before the one that
/// would widen it past 180, and the next piece starts at that same vertex (the line stays joined).
std::vector<LonLatPart> narrow_lines(const LonLatPart &line) {
    std::vector<LonLatPart> parts;
    LonLatPart current;
    double lo = 0, hi = 0;
    for (const auto &p : line) {
        if (!current.empty() && std::max(hi, p[0]) - std::min(lo, p[0]) > max_part_width_deg) {
            parts.push_back(current);
            current = {current.back()};
            lo = hi = current.back()[0];
        }
        if (current.empty())
            lo = hi = p[0];
        current.push_back(p);
        lo = std::min(lo, p[0]), hi = std::max(hi, p[0]);
    }
    if (current.size() >= 2)
        parts.push_back(std::move(current));
    return parts;
}

namespace {

/// GeoPackage geometry blobs (GeoPackage 1.2, 2.1.3) as GDAL writes them: "GP", version 0,
/// flags (little-endian, with an xy envelope except for a point), srs_id, then the geometry's
/// ISO WKB, little-endian. Appended to one buffer, a block's rows one after the other.
class BlobBytes {
public:
    /// Writes the next `bytes` bytes of `out` (it grows by them now).
    BlobBytes(std::vector<unsigned char> &out, std::size_t bytes) : out_(out), at_(out.size()) {
        out.resize(at_ + bytes);
    }
    void u8(unsigned v) { out_[at_++] = static_cast<unsigned char>(v); }
    void u32(std::uint32_t v) { put(v); }
    void f64(double d) {
        std::uint64_t v;
        std::memcpy(&v, &d, sizeof v);
        put(v);
    }
    /// The header, with `envelope` when given; `empty` flags a geometry with no points.
    void header(const Envelope *envelope, bool empty = false) {
        u8('G'), u8('P'), u8(0), u8((envelope ? 0x03 : 0x01) | (empty ? 0x10 : 0)),
            u32(wgs84_srs_id);
        if (envelope)
            for (double d : *envelope)
                f64(d);
    }
    static constexpr std::size_t header_bytes(bool envelope) { return 8 + (envelope ? 32 : 0); }

private:
    /// v little-endian (one store on a little-endian machine: GCC merges the bytes' stores).
    template <class U> void put(U v) {
        for (std::size_t i = 0; i < sizeof v; ++i, v >>= 8)
            out_[at_ + i] = static_cast<unsigned char>(v);
        at_ += sizeof v;
    }
    static constexpr std::uint32_t wgs84_srs_id = 4326;
    std::vector<unsigned char> &out_;
    std::size_t at_;
};

/// A multipolygon of one ring per part (each closed by repeating its first point) appended to
/// `out` as a GeoPackage blob; returns its envelope, the points' extremes as OGR takes them
/// (none, an empty envelope, for no part: a degenerate face, written as GDAL writes an empty
/// geometry).
template <class Parts>
Envelope append_multipolygon(std::vector<unsigned char> &out, const Parts &parts) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    Envelope e = {inf, -inf, inf, -inf};
    for (const auto &part : parts)
        for (const auto &p : part) {
            e[0] = p[0] < e[0] ? p[0] : e[0], e[1] = p[0] > e[1] ? p[0] : e[1];
            e[2] = p[1] < e[2] ? p[1] : e[2], e[3] = p[1] > e[3] ? p[1] : e[3];
        }
    std::size_t bytes = BlobBytes::header_bytes(!parts.empty()) + 9;
    for (const auto &ring : parts)
        bytes += 13 + 16 * (ring.size() + 1);
    BlobBytes b(out, bytes);
    b.header(parts.empty() ? nullptr : &e, parts.empty());
    constexpr unsigned little_endian = 1, wkb_polygon = 3, wkb_multipolygon = 6;
    b.u8(little_endian), b.u32(wkb_multipolygon), b.u32(std::uint32_t(parts.size()));
    for (const auto &ring : parts) {
        b.u8(little_endian), b.u32(wkb_polygon), b.u32(1), b.u32(std::uint32_t(ring.size() + 1));
        for (std::size_t i = 0; i <= ring.size(); ++i)
            b.f64(ring[i % ring.size()][0]), b.f64(ring[i % ring.size()][1]);
    }
    return e;
}

} // namespace

/// The face with corners v (lon/lat ll) appended to `out` as a GeoPackage blob: its rings as
/// face_polygons and narrow_rings cut them (`empty` when it has none); returns its envelope.
Envelope append_face(std::vector<unsigned char> &out, const Vec3 v[3], const LonLat ll[3],
                     bool &empty) {
    std::array<std::array<LonLatPoint, 3>, 1> one;
    if (simple_face_ring(v, ll, one[0])) { // most faces: one triangle, made in place
        const auto [lo, hi] = std::minmax({one[0][0][0], one[0][1][0], one[0][2][0]});
        if (hi - lo <= max_part_width_deg) {
            empty = false;
            return append_multipolygon(out, one);
        }
    }
    std::vector<LonLatPart> parts;
    for (auto &ring : face_polygons(v[0], v[1], v[2]))
        for (auto &part : narrow_rings(std::move(ring)))
            parts.push_back(std::move(part));
    empty = parts.empty();
    return append_multipolygon(out, parts);
}

/// A point appended to `out` as a GeoPackage blob (no envelope, as GDAL writes points).
void append_point(std::vector<unsigned char> &out, double x, double y) {
    BlobBytes b(out, BlobBytes::header_bytes(false) + 21);
    b.header(nullptr);
    constexpr unsigned little_endian = 1, wkb_point = 1;
    b.u8(little_endian), b.u32(wkb_point), b.f64(x), b.f64(y);
}

} // namespace globemesh::io
