// The even-odd fill of coastline rings: what a symmetric difference of all of them gives, by
// their nesting where they stay apart and by GEOS's overlay only among those that meet (GSHHG
// intermediate as 32,996 lines: an overlay of all of them took 21-29 s).
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <geos_c.h>

#include "coast_load_internal.hpp"
#include "disjoint_sets.hpp"

namespace globemesh::coast_detail {
namespace {

/// The items of an STR tree of geometries whose boxes meet g's box.
class Boxes {
public:
    Boxes(Geos &geos, const std::vector<GeomPtr> &geoms)
        : geos_(geos), tree_(GEOSSTRtree_create_r(geos.get(), 10), GeosDeleter{geos.get()}) {
        for (std::size_t i = 0; i < geoms.size(); ++i)
            GEOSSTRtree_insert_r(geos.get(), tree_.get(), geoms[i].get(),
                                 reinterpret_cast<void *>(i));
    }
    const std::vector<std::size_t> &near(const GEOSGeometry *g) {
        hits_.clear();
        GEOSSTRtree_query_r(geos_.get(), tree_.get(), g, collect, &hits_);
        return hits_;
    }

private:
    static void collect(void *item, void *user) {
        static_cast<std::vector<std::size_t> *>(user)->push_back(
            reinterpret_cast<std::size_t>(item));
    }
    Geos &geos_;
    TreePtr tree_;
    std::vector<std::size_t> hits_;
};

/// Prepared geometries of a list, made when first asked for.
class Prepared {
public:
    Prepared(Geos &geos, const std::vector<GeomPtr> &geoms)
        : geos_(geos), geoms_(geoms), prepared_(geoms.size()) {}
    const GEOSPreparedGeometry *operator[](std::size_t i) {
        if (!prepared_[i])
            prepared_[i] =
                PreparedPtr(GEOSPrepare_r(geos_.get(), geoms_[i].get()), GeosDeleter{geos_.get()});
        return prepared_[i].get();
    }

private:
    Geos &geos_;
    const std::vector<GeomPtr> &geoms_;
    std::vector<PreparedPtr> prepared_;
};

/// XOR of polygonal geometries by pairwise reduction, valid.
GeomPtr symmetric_difference_all(Geos &geos, std::vector<GeomPtr> parts) {
    while (parts.size() > 1) {
        std::vector<GeomPtr> next;
        for (std::size_t i = 0; i + 1 < parts.size(); i += 2)
            next.push_back(own(geos,
                               GEOSSymDifference_r(geos.get(), parts[i].get(), parts[i + 1].get()),
                               "combine coastline rings"));
        if (parts.size() % 2)
            next.push_back(std::move(parts.back()));
        parts = std::move(next);
    }
    return make_valid(geos, parts.front().get());
}

/// The faces whose boundaries stay apart from every other's: each group of faces whose
/// boundaries meet (they intersect, neither inside the other's interior) replaced by its XOR.
std::vector<GeomPtr> faces_apart(Geos &geos, std::vector<GeomPtr> faces) {
    const std::size_t n = faces.size();
    std::vector<int> vertices(n);
    std::vector<std::array<double, 4>> box(n);
    for (std::size_t i = 0; i < n; ++i) {
        vertices[i] = GEOSGetNumCoordinates_r(geos.get(), faces[i].get());
        auto &b = box[i];
        GEOSGeom_getExtent_r(geos.get(), faces[i].get(), &b[0], &b[1], &b[2], &b[3]);
    }
    auto within = [&](std::size_t a, std::size_t b) { // a's box inside b's
        return box[a][0] >= box[b][0] && box[a][1] >= box[b][1] && box[a][2] <= box[b][2] &&
               box[a][3] <= box[b][3];
    };
    // Inside the other's interior is asked only where the boxes nest; the smaller face inside
    // the larger (by vertices) is the common case, the other way round is prepared here.
    Groups groups(n);
    join_meeting(
        geos, faces, vertices, groups,
        [&](Geos &g, const GEOSPreparedGeometry *prepared, std::size_t big, std::size_t small) {
            const GEOSGeometry *b = faces[big].get(), *s = faces[small].get();
            if (GEOSPreparedIntersects_r(g.get(), prepared, s) != 1 ||
                (within(small, big) && GEOSPreparedContainsProperly_r(g.get(), prepared, s) == 1))
                return false;
            if (!within(big, small))
                return true;
            const PreparedPtr around(GEOSPrepare_r(g.get(), s), GeosDeleter{g.get()});
            return GEOSPreparedContainsProperly_r(g.get(), around.get(), b) != 1;
        });
    std::vector<std::vector<GeomPtr>> members(n);
    for (std::size_t i = 0; i < n; ++i)
        members[groups.find(i)].push_back(std::move(faces[i]));
    std::vector<GeomPtr> out;
    for (auto &m : members) {
        if (m.size() == 1)
            out.push_back(std::move(m.front()));
        else if (m.size() > 1)
            out.push_back(symmetric_difference_all(geos, std::move(m)));
    }
    return out;
}

/// A polygon of each ring of the faces (shells and holes alike).
std::vector<GeomPtr> ring_polygons(Geos &geos, const std::vector<GeomPtr> &faces) {
    std::vector<GeomPtr> rings;
    auto add = [&](const GEOSGeometry *ring) {
        rings.push_back(own(
            geos,
            GEOSGeom_createPolygon_r(geos.get(), GEOSGeom_clone_r(geos.get(), ring), nullptr, 0),
            "build a polygon"));
    };
    for (const GeomPtr &f : faces) {
        std::vector<const GEOSGeometry *> polys;
        polygons_of(geos, f.get(), polys);
        for (const GEOSGeometry *p : polys) {
            add(GEOSGetExteriorRing_r(geos.get(), p));
            for (int h = 0; h < GEOSGetNumInteriorRings_r(geos.get(), p); ++h)
                add(GEOSGetInteriorRingN_r(geos.get(), p, h));
        }
    }
    return rings;
}

/// Whether ring a lies inside ring b, which it does not cross (they may touch at points: a
/// shell and its hole): tested at a's first vertex, or at the first middle of one of a's
/// segments that is not on b.
bool inside(Geos &geos, const GEOSGeometry *a, const GEOSPreparedGeometry *b) {
    const GEOSCoordSequence *seq =
        GEOSGeom_getCoordSeq_r(geos.get(), GEOSGetExteriorRing_r(geos.get(), a));
    unsigned size = 0;
    GEOSCoordSeq_getSize_r(geos.get(), seq, &size);
    double x0, y0;
    GEOSCoordSeq_getXY_r(geos.get(), seq, 0, &x0, &y0);
    for (unsigned k = 0; k < size; ++k) {
        double x = x0, y = y0;
        if (k > 0) {
            double x1, y1;
            GEOSCoordSeq_getXY_r(geos.get(), seq, k - 1, &x, &y);
            GEOSCoordSeq_getXY_r(geos.get(), seq, k, &x1, &y1);
            x = 0.5 * (x + x1), y = 0.5 * (y + y1);
        }
        GeomPtr at = own(geos, GEOSGeom_createPointFromXY_r(geos.get(), x, y), "build a point");
        if (GEOSPreparedContains_r(geos.get(), b, at.get()) == 1)
            return true;
        if (GEOSPreparedIntersects_r(geos.get(), b, at.get()) != 1)
            return false;
    }
    return false;
}

/// For each ring, how many rings hold it, and the one of them held by one fewer (the ring just
/// outside it; n when none holds it). Rings that do not cross nest: the holders form a chain.
std::pair<std::vector<std::size_t>, std::vector<std::size_t>>
nesting(Geos &geos, const std::vector<GeomPtr> &rings) {
    const std::size_t n = rings.size();
    Boxes boxes(geos, rings);
    Prepared prepared(geos, rings);
    std::vector<std::vector<std::size_t>> holders(n);
    for (std::size_t i = 0; i < n; ++i) {
        coast::GeosInterrupt::poll();
        for (std::size_t j : boxes.near(rings[i].get()))
            if (j != i && inside(geos, rings[i].get(), prepared[j]))
                holders[i].push_back(j);
    }
    std::vector<std::size_t> depth(n), parent(n, n);
    for (std::size_t i = 0; i < n; ++i)
        depth[i] = holders[i].size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j : holders[i])
            if (depth[j] + 1 == depth[i])
                parent[i] = j;
    return {depth, parent};
}

GeomPtr ring_copy(Geos &geos, const GeomPtr &polygon) {
    return clone(geos, GEOSGetExteriorRing_r(geos.get(), polygon.get()), "copy a ring");
}

} // namespace

GeomPtr parity_fill(Geos &geos, std::vector<GeomPtr> faces) {
    std::vector<GeomPtr> rings = ring_polygons(geos, faces_apart(geos, std::move(faces)));
    // A ring inside an even number of others is a shell; the rest are holes of the ring just
    // outside them.
    const auto [depth, parent] = nesting(geos, rings);
    std::vector<std::vector<std::size_t>> holes(rings.size() + 1);
    for (std::size_t i = 0; i < rings.size(); ++i)
        if (depth[i] % 2 == 1)
            holes[parent[i]].push_back(i);
    if (!holes.back().empty()) // rings that do not nest as rings apart do: GEOS's overlay decides
        return symmetric_difference_all(geos, std::move(rings));
    std::vector<GeomPtr> land;
    for (std::size_t i = 0; i < rings.size(); ++i) {
        if (depth[i] % 2 == 1)
            continue;
        std::vector<GEOSGeometry *> inner;
        for (std::size_t h : holes[i])
            inner.push_back(ring_copy(geos, rings[h]).release());
        land.push_back(
            own(geos,
                GEOSGeom_createPolygon_r(geos.get(), ring_copy(geos, rings[i]).release(),
                                         inner.data(), static_cast<unsigned>(inner.size())),
                "build a polygon"));
    }
    std::vector<GEOSGeometry *> raw;
    for (GeomPtr &p : land)
        raw.push_back(p.release());
    return own(geos,
               GEOSGeom_createCollection_r(geos.get(), GEOS_MULTIPOLYGON, raw.data(),
                                           static_cast<unsigned>(raw.size())),
               "collect land polygons");
}

} // namespace globemesh::coast_detail
