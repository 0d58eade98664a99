// globemesh/coast.hpp: coastlines from any OGR source, turned into Boundary rings on the sphere.
//
// Two stages, because the size field needs the cleaned full-resolution coast before the
// simplification that depends on it:
//
//   1. load_coast(): read any OGR vector layer (land polygons, or closed coastline lines that are
//      polygonized), reproject to lon/lat (GIS axis order) through OGR/PROJ, make valid (GEOS
//      MakeValid, STRUCTURE method), dissolve (union), keep holes, clip to --region or
//      --region-file, drop islands and lakes below --min-island-area (geodesic area), then build
//      the ocean's rings on the sphere: edges along the +-180 meridian cancel where the ocean
//      lies on both sides (stitching), edges along lat +-90 vanish (pole closures), so
//      Antarctica becomes one ring around the South Pole with no node on the artificial cut.
//      GIS operations run in planar lon/lat with GEOS (where they are planar by nature); the
//      rings then become great-circle polylines (planar edges longer than 0.5 degree are first
//      densified in lon/lat) and are verified on the sphere.
//   2. shape_boundary(): drop islands (and holes of a region's outline, and closed water
//      bodies) smaller than options.min_island_triangles equilateral triangles of the local
//      size; find each ring's corners at the scale of h (Douglas-Peucker on the sphere with
//      tolerance h/2, nodes closer than h/2 thinned, then the nodes where that line turns by
//      more than 40 degrees, at least h/2 apart); simplify again to 0.3 h and cut each run of
//      that line between corners into equal pieces of about h(x) (boundary nodes lie within
//      about 0.3 h of the source); make an original node a corner wherever a resampled arc
//      would touch or cross another arc (topology preserved: rings never cross, islands never
//      merge).
//
// Invariants of every Boundary returned (boundary.hpp): rings closed, >= 3 nodes, no two
// consecutive nodes equal or antipodal, rings simple and mutually non-crossing as great-circle
// arcs (checked by check_boundary(); a violation that cannot be repaired is a DataError), ocean
// on the left. Segments on a region edge are SegmentKind::open, every other one coast.
//
// Input rules: the layer is --coast-layer, else the only polygon or line layer of the source
// (else a DataError listing the layers); --coast-srs, when given, overrides the layer's CRS;
// polygons drawn with longitudes beyond +-180 are cut there and wrapped back by 360 degrees.
// A polygon ring reprojected from a CRS that holds a pole as a point (polar stereographic) that
// goes round the pole, or through it at whatever longitude the projection gives it, is closed
// through it along lat +-90, as Antarctica is drawn in lon/lat.
// Coastline lines are merged at shared ends; a line whose ends lie within 0.001 degree of the
// seam is closed along it (same side) or through the nearer pole (opposite sides, Antarctica);
// a gap of at most 0.5 degree is closed straight; any other open line is a DataError. Land is
// the even-odd fill of the closed lines, so their orientation does not matter.
// Inland water (holes of the land, and in a region every water body with no edge on the region
// outline) is dropped unless options.keep_inland_seas, or unless it is all the ocean there is
// (then the largest body stays), together with the islands inside it.
//
// Repairs stated in numbers: longitudes within 1e-9 degree of +-180 are put on it (so
// 180.00000000000014 becomes 180; for reprojected data the side is taken from the neighbouring
// vertices); latitudes within 0.002 degree (220 m) of a pole are put on the pole, because
// datasets close Antarctica there; rings enclosing less than 1e-14 square degree (zero-area
// slivers, collapsed holes) are dropped; where two rings (or one ring) meet at a single point
// (valid in GEOS, not for a mesher) each copy of that node is moved 1e-7 rad (0.64 m) into the
// land. The land is snap-rounded to a lon/lat grid of 2^-20 degree (0.11 m; GEOS's snap-rounding
// noder): near-touches closer than about half a cell become touches, spikes narrower collapse,
// and polygons whose outlines come within 2 cells are snap-rounded together (CoastData counts
// them). A great-circle arc that strays across a neighbour its lon/lat edge keeps clear of is
// split at the edge's midpoint until none does (CoastData::arcs_split). A region's outline takes
// the land's vertices within 2^-16 degree (1.7 m), so that land clipped to the region (or the
// region drawn from the same coast in another CRS) leaves no sliver of water along it; the
// region's box sides lie on the snap grid. Ocean left on one side only of the +-180 seam (halves of
// an island that do not match, as Fiji at 1:50m) keeps that stretch of meridian as coast.
//
// Units: areas km2 (GeographicLib on WGS84), lengths km (mean radius, sphere.hpp).
// Deterministic: every container is ordered; the same input gives the same rings.
// References: GEOS C API (MakeValid, UnaryUnion, Polygonize); GeographicLib PolygonArea
// (Karney 2013, "Algorithms for geodesics"); Douglas & Peucker (1973).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "globemesh/boundary.hpp"
#include "globemesh/options.hpp"
#include "globemesh/progress.hpp"
#include "globemesh/size_fn.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {

/// The land of the cleaned coast at full resolution, as GIS software (and mesh-verify) sees it:
/// polygons in planar lon/lat, after validation, dissolving, --min-island-area and the region
/// clip. The mesher asks it which face centroids lie on land and how near the coast a node is
/// (MesherOptions::land). GEOS prepared polygons under an STR tree of their envelopes, with lon/lat
/// cells in front, and the outlines as unit vectors in short pieces under a second tree; one
/// GEOS context of its own.
class LandMask final : public LandTest {
public:
    /// Each polygon is its shell, then its holes (lon/lat rings, first == last). The polygons are
    /// prepared on every core, or on the calling thread alone without `every_core` (the copies
    /// that the threads meshing parts make while the others mesh).
    explicit LandMask(const std::vector<std::vector<std::vector<LonLat>>> &polygons,
                      bool every_core = true);
    ~LandMask();
    LandMask(const LandMask &) = delete;
    LandMask &operator=(const LandMask &) = delete;
    /// True when p lies strictly inside a land polygon (not in one of its holes, not on its
    /// outline): GEOS's answer, asked once per component of the lon/lat cells (1/16 degree)
    /// that no outline segment's box touches, and at every point of a cell one touches. Not
    /// thread-safe (one GEOS context, and the components' answers kept as they are asked).
    bool contains(const Vec3 &p) const override;
    /// True when the coast (a land polygon's outline, shells and holes, each segment taken as a
    /// great-circle arc, as mesh-verify measures it) comes within `angle` radians of p.
    bool coast_within(const Vec3 &p, double angle) const override;
    /// The least distance from p to the outline's arcs within `reach` (the nearest coast is
    /// found in one query of the segments' index), else `reach`.
    double coast_distance(const Vec3 &p, double reach) const override;
    /// Reads the polygons' rings now; the maker builds a LandMask of its own from them (as much
    /// memory again, and the build's time, on the thread that runs it).
    std::function<std::shared_ptr<const LandTest>()> copier() const override;
    std::size_t vertices() const { return vertices_; }
    /// The bytes of the cells in front of `contains` (about 2.7 MB for the world's land).
    std::size_t cell_bytes() const;

private:
    struct Impl;
    /// visit(k) for the outline segments near p (land_mask.cpp), until it returns true.
    template <class Visit>
    void visit_segments_near(const Vec3 &p, double angle, Visit &&visit) const;
    std::unique_ptr<Impl> impl_;
    std::size_t vertices_ = 0;
};

/// The cleaned ocean domain at full resolution (stage 1).
struct CoastData {
    Boundary rings;            ///< ocean on the left, segments tagged coast/open, no resampling
    double ocean_area_km2 = 0; ///< geodesic (WGS84) area of the ocean domain the rings enclose
    std::size_t islands_removed = 0; ///< land polygons dropped by --min-island-area
    std::size_t lakes_removed = 0; ///< holes and inland water bodies dropped (area or inland seas)
    double area_gained_km2 = 0;    ///< ocean added by dropping islands
    double area_lost_km2 = 0;      ///< ocean lost by dropping lakes and inland seas
    std::size_t polygons_joined =
        0; ///< land polygons joined to another they came within the snap grid of
    /// rings gained or lost by dissolving and snap rounding (overlapping polygons merged, a ring
    /// split where it touched itself, a sliver collapsed), summed over GEOS's batches
    std::size_t rings_changed = 0;
    std::size_t arcs_split =
        0; ///< nodes added where a great-circle arc strayed across the lon/lat edge's neighbour
    std::string layer;                    ///< name of the layer that was read
    std::shared_ptr<const LandMask> land; ///< the land those rings leave out, for the mesher
};

/// Reads, reprojects, cleans and clips the coast of options.coast (and options.region /
/// options.region_file) into full-resolution rings. Reads `options` (coast, coast_layer,
/// coast_where, coast_srs, region, region_file, region_layer, min_island_area_km2,
/// keep_inland_seas) and, to refuse a layer too large to read, max_memory_bytes (the run's
/// MeshingOptions::max_memory_bytes; 0: no limit).
/// Throws UsageError (no coast, bad coast_where or coast_srs), IoError (file missing or
/// unreadable), DataError (no usable layer, layer list in the message; no CRS; no ocean in the
/// region; rings that cannot be repaired), Cancelled. Messages name options by field (error.hpp).
CoastData load_coast(const CoastOptions &options, std::uint64_t max_memory_bytes = 0,
                     const Progress &progress = {});

/// load_coast with the coast's part and the memory budget of a whole run's options.
inline CoastData load_coast(const MeshOptions &options, const Progress &progress = {}) {
    return load_coast(coast_options(options), options.max_memory_bytes, progress);
}

struct CoastReport {
    std::size_t rings = 0;              ///< rings in the shaped boundary
    std::size_t nodes = 0;              ///< nodes in the shaped boundary
    std::size_t islands_removed = 0;    ///< by --min-island-area (stage 1) and by size (stage 2)
    std::size_t lakes_removed = 0;      ///< holes and closed water bodies removed (both stages)
    std::size_t conflicts_repaired = 0; ///< corners added because resampled arcs touched another
    std::size_t close_nodes_merged = 0; ///< nodes dropped from arcs far shorter than the size
    double area_lost_km2 = 0;   ///< ocean removed: dropped lakes + net loss of simplification
    double area_gained_km2 = 0; ///< ocean added: dropped islands + net gain of simplification
    double ocean_area_km2 = 0;  ///< geodesic area enclosed by the shaped boundary
};

/// Stage 2: drops rings smaller than options.min_island_triangles triangles of the local size,
/// simplifies to the local size with topology preserved and resamples every ring evenly between
/// its corners so consecutive nodes are about size_km(x) apart along great-circle arcs. Throws
/// DataError when the shaped rings cannot be made to satisfy boundary.hpp or need more than
/// max_nodes nodes (the run's MeshingOptions::max_nodes), Cancelled.
Boundary shape_boundary(const CoastData &coast, const SizeFn &size_km, const CoastOptions &options,
                        std::uint64_t max_nodes, CoastReport *report = nullptr,
                        const Progress &progress = {});

/// shape_boundary with the coast's part and the node limit of a whole run's options.
inline Boundary shape_boundary(const CoastData &coast, const SizeFn &size_km,
                               const MeshOptions &options, CoastReport *report = nullptr,
                               const Progress &progress = {}) {
    return shape_boundary(coast, size_km, coast_options(options), options.max_nodes, report,
                          progress);
}

/// One violated invariant of a Boundary: a message and where (ring, segment), -1 when none.
struct BoundaryIssue {
    std::string what;
    long ring = -1, segment = -1, other_ring = -1, other_segment = -1;
};

/// Checks every invariant of boundary.hpp except the side of the ocean: ring sizes, unit
/// vectors, consecutive nodes distinct and not antipodal, no two arcs (of one ring or two)
/// touching or crossing except consecutive arcs at their shared node, no arc folding back on
/// the previous one. Double precision: points closer than 1e-14 rad to an arc count as touching
/// it. Returns the issues found (empty when the boundary is valid), at most max_issues.
std::vector<BoundaryIssue> check_boundary(const Boundary &boundary, std::size_t max_issues = 100);

/// Geodesic area (WGS84, GeographicLib) of the region to the left of all rings, km2; the whole
/// Earth for an empty boundary. Exact for rings whose arcs are geodesics.
double boundary_area_km2(const Boundary &boundary);

} // namespace globemesh
