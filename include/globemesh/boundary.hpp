// globemesh/boundary.hpp: the closed boundary rings of the ocean on the sphere.
//
// Invariants of a Boundary handed to the mesher: every ring is closed (the last node connects
// back to the first, which is not repeated), has at least 3 nodes, no two consecutive nodes are
// equal or antipodal, rings are simple and do not cross each other on the sphere, and the ocean
// lies on the LEFT of every ring when walked in node order, seen from outside the sphere.
// Segment i joins nodes[i] to nodes[(i+1) % n] along the shorter great-circle arc and is tagged
// coast (land on its right) or open (the edge of a user region, sea on both sides).
// Standard library only.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "globemesh/sphere.hpp"

namespace globemesh {

enum class SegmentKind : std::uint8_t { coast = 1, open = 2 };

struct Ring {
    std::vector<Vec3> nodes;        ///< unit vectors, ocean on the left
    std::vector<SegmentKind> kinds; ///< kinds[i] tags the segment nodes[i] -> nodes[i+1]
};

/// The land the rings leave out, at full resolution: asked by the mesher which face centroids
/// lie on land (coast.hpp's LandMask reads it from the coast's polygons).
class LandTest {
public:
    virtual ~LandTest() = default;
    /// True when p lies on land.
    virtual bool contains(const Vec3 &p) const = 0;
    /// True when the coast comes within `angle` radians of p (on the sphere).
    virtual bool coast_within(const Vec3 &p, double angle) const = 0;
    /// The distance (radians) from p to the coast when it is within `reach`, else `reach`. This
    /// default bisects with coast_within, to within reach / 2^13; LandMask's is exact.
    virtual double coast_distance(const Vec3 &p, double reach) const {
        if (!coast_within(p, reach))
            return reach;
        double lo = 0, hi = reach;
        for (int i = 0; i < 12; ++i) {
            const double mid = 0.5 * (lo + hi);
            (coast_within(p, mid) ? hi : lo) = mid;
        }
        return 0.5 * (lo + hi);
    }
    /// A maker of an independent copy giving the same answers, for another thread: what it
    /// needs is read now, on the calling thread; the maker may run on any thread. Empty when the
    /// test cannot be copied (the parts then share it under a lock).
    virtual std::function<std::shared_ptr<const LandTest>()> copier() const { return {}; }
};

struct Boundary {
    std::vector<Ring> rings;
    /// Islands the coast shaping dropped (too small for the size field), each a closed ring of
    /// unit vectors, not repeated at the end: meshed over as ocean, but the mesher keeps face
    /// centroids off them where it can (a model that samples depth at face centres).
    std::vector<std::vector<Vec3>> dropped_islands;
    /// True when no ring exists and the whole sphere is ocean (an aqua-planet).
    bool empty() const { return rings.empty(); }
};

} // namespace globemesh
