// Internal to io/: the node coordinates of the model formats (ADCIRC, SCHISM, SELAFIN, gmsh):
// the mesh's lon/lat, or planar ones in an --output-srs (WriteOptions::output_srs), transformed by
// GDAL/PROJ with the axes in the traditional GIS order (x = easting or longitude); and the check
// that every node has the depth the models need (ADCIRC, SCHISM, SELAFIN, FESOM2).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "globemesh/mesh.hpp"

namespace globemesh::io {

/// A parsed --output-srs.
struct OutputCrs {
    std::string wkt;        ///< WKT1 on one line (as seamsh writes it into gmsh files)
    std::string name;       ///< as the CRS names itself, for messages
    bool projected = false; ///< false: geographic on WGS 84, the mesh's own lon/lat
    int epsg = 0;           ///< its EPSG code when it has one (as GDAL identifies it), else 0
};

/// Parses `text`. Throws UsageError naming `option` for a text GDAL does not read as a CRS, and
/// for a CRS neither projected nor geographic on WGS 84: another datum's lon/lat would move every
/// node by a datum shift that no model format records, and a geocentric or vertical CRS has no
/// plane.
OutputCrs parse_output_crs(const std::string &text, const std::string &option);

/// The nodes as a model format writes them.
struct ModelCoordinates {
    std::vector<double> x, y;     ///< per node: lon/lat degrees, or the CRS's units (metres)
    std::optional<OutputCrs> crs; ///< the --output-srs they are in; unset: none was asked
};

/// node_lonlats without an `output_srs` or with a geographic one; else the nodes transformed.
/// Throws DataError beginning with `what` (e.g. "ADCIRC output fort.14") for a node whose
/// transform fails or is not finite (naming its lon/lat), and for a mesh the projection cannot
/// hold: a face that turns over in it, where the mesh crosses a tear or fold of the projection
/// (a global mesh always does).
ModelCoordinates model_coordinates(const Mesh &mesh, const std::string &output_srs,
                                   const std::string &what);

/// Throws DataError beginning with `what` (e.g. "ADCIRC output fort.14") when nodes of `depth`
/// have none (NaN, as in a converted file), naming bathy_fill_m: the model needs one at every
/// node.
void require_depths(const Field &depth, const std::string &what);

} // namespace globemesh::io
