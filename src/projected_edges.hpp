// Internal to globemesh_lib: a polygon drawn in a projected CRS (UTM, polar stereographic) has
// straight edges in that CRS; reprojected vertex by vertex to lon/lat, each edge would become a
// line straight in lon/lat instead (a 1200 km square size region in EPSG:3413 about the North
// Pole set its size up to 242 km past the drawn sides). Its long edges are split in that CRS first,
// with OGR's segmentize, for --size-regions. Not for --region-file: its outline may be the coast
// reprojected vertex by vertex (issue 37, coast_test's Equal Earth land), whose edges are the
// lon/lat lines of the data it came from; split, it left slivers of ocean along the coast.
#pragma once

#include <ogr_api.h>
#include <ogr_srs_api.h>

namespace globemesh::detail {

/// Splits the edges of `g` (in the CRS `srs`) longer than `step_m` metres, so that its vertices
/// reprojected to lon/lat follow the lines drawn in that CRS; nothing where the CRS is not
/// projected (its edges are straight in its own longitudes and latitudes already).
inline void split_projected_edges(OGRGeometryH g, OGRSpatialReferenceH srs, double step_m) {
    if (!g || !srs || !OSRIsProjected(srs))
        return;
    const double metres_per_unit = OSRGetLinearUnits(srs, nullptr);
    if (metres_per_unit > 0 && step_m > 0)
        OGR_G_Segmentize(g, step_m / metres_per_unit);
}

} // namespace globemesh::detail
