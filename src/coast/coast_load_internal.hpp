// Internal to the coast module: the stages of load_coast (coast_load.cpp) shared by their files:
// the OGR source (coast_source.cpp), the GEOS operations (coast_geos.cpp) and the ocean's rings
// (coast_rings.cpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "geos_handles.hpp"
#include "globemesh/boundary.hpp"
#include "globemesh/coast.hpp"
#include "globemesh/error.hpp"
#include "globemesh/sphere.hpp"

namespace globemesh {
template <class Index> class DisjointSets; // disjoint_sets.hpp
} // namespace globemesh

namespace globemesh::coast_detail {

using PointList = std::vector<LonLat>;

/// One polygon in lon/lat: shell first, then holes (each ring closed, first == last).
using PolygonRings = std::vector<PointList>;

struct Source {
    std::vector<PolygonRings> polygons;
    std::vector<PointList> lines;
    std::size_t points = 0;   ///< point geometries seen (ignored)
    std::size_t features = 0; ///< features read
    std::string layer;
};

/// The land is snap-rounded to a lon/lat grid of 2^-20 degree (0.11 m at the equator): near-
/// touches closer than about half a cell (an islet's vertex 5 cm from the mainland's edge)
/// become touches, spikes narrower collapse, and what stays apart is at least half a cell
/// apart. A power of two, so that +-180, +-90 and grid multiples are exact in binary.
constexpr double snap_grid_deg = 1.0 / (1 << 20);

// ----------------------------------------------------------------------------- OGR source

/// A box x0, y0, x1, y1: lon/lat degrees, or a layer's CRS.
using Box = std::array<double, 4>;

/// The region W,S,E,N widened by 1% of its larger side, as lon/lat boxes: one, or its two
/// sides when it crosses +-180, each also shifted by 360 degrees east where x_max passes 180
/// and west where x_min passes -180 (a source's longitudes; by default both): land stored past
/// +-180 (read_source's filter, load_coast's clip).
std::vector<Box> near_boxes(const std::array<double, 4> &near,
                            double x_min = -std::numeric_limits<double>::infinity(),
                            double x_max = std::numeric_limits<double>::infinity());

/// Reads every polygon and line of a layer of `path` in lon/lat (WGS84, GIS axis order); from a
/// CRS that holds a pole as a point, a polygon's ring round or through the pole is closed
/// through it (pole_rings.hpp: its longitudes may then pass +-180, for add_wrapped).
/// `field` is the option whose file it is, named in messages ("coast" or "region_file"; its
/// layer option is "coast_layer" or "region_layer"). With `near` (a region
/// W,S,E,N) a polygon layer is read through OGR's spatial filter: only the features whose
/// envelope meets the box widened by 1% of its larger side, in the layer's CRS; the land
/// elsewhere plays no part in a region (region_rings cuts it off), and a layer with an index
/// (GeoPackage, a shapefile's .qix) is then not read whole. In lon/lat a box across +-180 is
/// read as its two sides, and every box also shifted by 360 degrees where the layer's extent
/// passes +-180 (land stored from 0 to 360); a projected layer is read through the box's
/// bounds in its CRS (across +-180, the box's latitude band). When the filter leaves no
/// feature (a region of open sea) the layer is read whole only up to a first polygon or line,
/// so that a layer of no features, or of points only, gets the errors below as without a
/// region. Line layers are read whole: their lines close into land only together.
/// `where` goes to OGR in parentheses; a failure GDAL reports while reading (a filter that
/// fails only inside the spatial filter's statement) is a UsageError naming coast_where, or
/// without one an IoError: never a partial read.
/// max_bytes (0: no limit): the layer's vertices are counted while they are read; once they
/// pass max_bytes / coast_bytes_per_vertex nothing more is kept (memory stays bounded by one
/// feature), the rest is only counted, and a DataError names the layer, the count and
/// max_memory_bytes.
Source read_source(const std::string &path, const std::string &layer_name, const std::string &where,
                   const std::string &srs_override, const char *field, std::uint64_t max_bytes = 0,
                   const std::optional<std::array<double, 4>> &near = std::nullopt);

// ----------------------------------------------------------------------------- GEOS operations

GeomPtr make_ring(Geos &geos, const PointList &pts);
GeomPtr make_polygon(Geos &geos, const PolygonRings &rings);
/// A GEOMETRYCOLLECTION of the parts (taken from `parts`, which is left empty).
GeomPtr make_collection(Geos &geos, std::vector<GeomPtr> &parts);
/// MakeValid (STRUCTURE method, collapsed parts dropped): polygonal output only.
GeomPtr make_valid(Geos &geos, const GEOSGeometry *g);
/// The non-empty polygons of a polygonal geometry or collection, in order (not owned).
void polygons_of(Geos &geos, const GEOSGeometry *g, std::vector<const GEOSGeometry *> &out);
/// The vertices of a GEOS ring or line; DataError when GEOS cannot give them.
PointList ring_points(const Geos &geos, const GEOSGeometry *ring);
/// The signed area of a closed lon/lat ring in the plane (degrees^2, counter-clockwise positive).
double signed_planar_area(const PointList &pts);
/// Orients a closed lon/lat ring: counter-clockwise in the plane when ccw, else clockwise (the
/// first vertex stays first).
void orient(PointList &pts, bool ccw);

/// The rings of a GEOS polygon, shell first.
PolygonRings polygon_rings(const Geos &geos, const GEOSGeometry *polygon);
/// Polygonizes closed coastline lines (GSHHG / OSM style). Lines are first merged at shared
/// ends; a line whose ends lie on the +-180 seam is closed along it (same side) or through the
/// nearer pole (opposite sides, as Antarctica). Land is the even-odd fill of all rings, so the
/// orientation of the lines does not matter and islands in lakes come out right. Valid output.
/// With `near` (a region's boxes, near_boxes), the rings whose lon/lat box meets none of them are
/// left out: their land and holes lie off the region, and they hold no part of it.
GeomPtr polygonize_lines(Geos &geos, const std::vector<PointList> &lines, const ErrorText &where,
                         const std::vector<Box> &near = {});

/// Union-find over polygon indices.
using Groups = DisjointSets<std::size_t>;
/// Whether polygons `big` (prepared in the thread's context) and `small` meet, big the one of
/// the pair with more vertices.
using MeetTest = std::function<bool(Geos &, const GEOSPreparedGeometry *big_prepared,
                                    std::size_t big, std::size_t small)>;
/// Joins in `groups` the polygons whose boxes meet (an STR tree's candidates) and that
/// `meet_test` finds meeting. Each pair is tested against its polygon with more vertices
/// (`vertices`), prepared once on the thread that takes it: a continent meets hundreds of
/// islands' boxes, and GEOS builds the index of the geometry tested against a prepared one anew
/// on every call. On every core, the largest polygons first; the joins in pair order, as one
/// thread makes them (the same groups, the same roots).
void join_meeting(Geos &geos, const std::vector<GeomPtr> &polys, const std::vector<int> &vertices,
                  Groups &groups, const MeetTest &meet_test);

/// The even-odd fill of valid polygonal faces' rings (a polygon's shell and holes alike), as
/// their symmetric difference (ring_parity.cpp): faces whose boundaries meet are overlaid by
/// GEOS, then every ring is a shell or a hole by how many rings hold it. Valid output.
GeomPtr parity_fill(Geos &geos, std::vector<GeomPtr> faces);

/// What snap rounding did to the land (CoastData reports it).
struct SnapCount {
    std::size_t joined = 0;  ///< polygons joined to another that they only came within 2 cells of
    std::size_t changed = 0; ///< rings gained or lost by dissolving and snap rounding, per batch
};

/// Dissolves valid polygonal parts into non-overlapping polygons, snap-rounded to a lon/lat
/// grid of `grid` degrees (GEOS's snap-rounding noder, OverlayNG): every vertex on the grid, and
/// every edge that passes through a vertex's grid cell noded at that vertex, so two rings that
/// came within about half a cell of each other touch there, and no vertex lies closer than half
/// a cell to an edge it is not on. Polygons that intersect (an STR tree's candidates confirmed by
/// GEOS's prepared test) or come within 2 cells of each other (near_pairs) are snap-rounded
/// together (one union; a group of hundreds, countries side by side, by tiles: tiled_union),
/// every other one alone: most coastline polygons are disjoint, and a union of all of them costs
/// seconds at 1:10m. Output order: each group where its first polygon
/// stands, the lone polygons with the batch they were rounded in (deterministic).
std::vector<GeomPtr> dissolve(Geos &geos, const std::vector<GeomPtr> &parts, double grid,
                              SnapCount &count);

/// For each of `inner` (islands, holes as polygons), the index of the polygon of `outer` that
/// holds a point inside it (outer.size() when none does: an island then lies in no water the
/// overlay kept).
std::vector<std::size_t> polygons_holding(Geos &geos,
                                          const std::vector<const GEOSGeometry *> &outer,
                                          const std::vector<GeomPtr> &inner);

/// The snap-rounding union of a group of polygons as dissolve's, by tiles (tiled_union.cpp):
/// the group is cut in halves (clip_to_box, on grid lines) until a tile holds at most
/// `tile_vertices`; each tile's pieces are snap-rounded together; the tiles' shells, their holes
/// set aside, are joined by an overlay without rounding (they meet only along the tile lines, at
/// vertices they have: checked); each hole goes back into the polygon around it, and a polygon
/// in another's hole (an island in a lake) stays whole. GEOS 3.11 places each hole of a union by
/// a scan of the shells around it, so one union of a group with many gaps between its polygons
/// (countries side by side) costs holes x shell vertices. The land is the same, the rounding
/// the tiles' (a vertex may lie within half a cell of an edge across a tile line). Empty when
/// the join made a vertex or a hole finds no polygon around it: the caller unions the group
/// whole.
std::vector<GeomPtr> tiled_union(Geos &geos, const std::vector<GeomPtr> &polygons, double grid,
                                 std::size_t tile_vertices);

/// A valid polygon's rings rounded to the lon/lat grid of `grid` degrees (as GEOS rounds), when
/// every vertex lies at least 2.5 cells from every edge it is not an end of: each vertex then
/// moves at most 0.71 cell, so no edge crosses or comes within half a cell of another and the
/// result is what snap rounding would give, but for the order of its rings' vertices. Else
/// std::nullopt (the polygon needs GEOS's snap-rounding noder). Most coastline polygons are
/// clear: this costs a sort of their edges by grid cell, the noder a KdTree query per edge.
std::optional<PolygonRings> rounded_if_clear(const PolygonRings &rings, double grid);

/// The part of a valid polygonal geometry inside a lon/lat box: a copy when it lies inside,
/// else GEOS's overlay intersection with the box (valid output). Not GEOSClipByRect: its
/// polygon reconnection leaks memory and can build wrong polygons when edges run along the box
/// (GEOS 3.11; libgeos/geos#605), as edges on a +-180 cut do (found by fuzz_coast: a leak).
GeomPtr clip_to_box(Geos &geos, const GEOSGeometry *g, double x0, double y0, double x1, double y1,
                    const char *what);
/// Adds a valid polygonal geometry to `parts`, cutting what lies beyond +-180 (a ring drawn
/// across the antimeridian with longitudes such as 190) and wrapping it back by 360 degrees.
void add_wrapped(Geos &geos, GeomPtr g, std::vector<GeomPtr> &parts);

// ----------------------------------------------------------------------------- ocean rings

struct Chain {
    PointList pts;
    std::vector<SegmentKind> kinds; // kinds[i]: pts[i] -> pts[i+1]
};

/// The ocean of the whole globe (coast_rings.cpp): the land's rings reversed (ocean on the left),
/// cut at the seam and the poles and stitched; inland water as keep_inland_seas says.
std::vector<Chain> world_rings(Geos &geos, const std::vector<GeomPtr> &land, bool keep_inland_seas,
                               CoastData &out);
/// The holes of the source's polygons (lakes, inland seas), each a polygon wrapped as the land
/// is: read before the land is cut to a region, where an outline across a lake makes it a bay.
std::vector<GeomPtr> source_holes(Geos &geos, const std::vector<PolygonRings> &polygons);
/// The ocean of a region (--region box, or --region-file polygons: `region_file`, as read_source
/// read them, null for a box): the region less the land; water the outline reaches but lying in
/// one of `holes` (source_holes) is an inland sea.
std::vector<Chain> region_rings(Geos &geos, std::vector<GeomPtr> &land,
                                const std::vector<GeomPtr> &holes, const CoastOptions &options,
                                const Source *region_file, const ErrorText &where, CoastData &out);
/// Converts a lon/lat ring to unit vectors, dropping nodes equal to the previous one.
Ring to_sphere(const Chain &c);
/// Moves every copy of a node that several arcs share (rings meeting at one point, valid in
/// GEOS) by 1e-7 rad into the land on its right.
std::size_t separate_pinches(Boundary &b);
/// Each ring started at its smallest node (by x, y, z; of a node it passes twice, the pass it
/// reads smallest from) and the rings sorted along the Hilbert curve by that node, then node by
/// node: an order that depends on the rings alone, not on how the source stored them or GEOS
/// produced them.
void canonical_order(Boundary &b);

} // namespace globemesh::coast_detail
