// globemesh/mesh_read.hpp: readers of the model formats globemesh also writes, so that
// `globemesh convert` converts between them (the UGRID reader is in ugrid.hpp).
#pragma once

#include <filesystem>

#include "globemesh/mesh.hpp"

namespace globemesh {

/// Reads an ADCIRC grid file (fort.14) or a SCHISM hgrid.gr3/.ll, in lon/lat degrees: nodes,
/// triangles, the depth (positive down) as node field "depth", and the boundary section's
/// strings as tags (open strings open, land strings coast; boundary edges on no string, or a
/// file without the section, coast). Throws IoError (not readable) or DataError (not the
/// format, indices out of range, coordinates not lon/lat).
Mesh read_adcirc(const std::filesystem::path &path);

/// Whether `path` is named as an ADCIRC or SCHISM grid (fort.14, .14, .gr3, .ll).
bool is_adcirc_name(const std::filesystem::path &path);

/// Reads a gmsh MSH file, 4.1 or 2.2, ASCII or binary (as globemesh, gmsh, seamsh and meshio write
/// them; binary in this machine's byte order): nodes in
/// lon/lat degrees (every z 0) or in 3-D on a sphere of any radius, the 3-node triangles as faces,
/// the 2-node lines as boundary tags (open in a physical group named "open" or "open_<k>", else
/// coast; boundary edges on no line are coast), and a $NodeData "depth" as node field "depth".
/// Throws IoError (not readable) or DataError (binary in the other byte order, a projected mesh
/// ($Projection), other element types, indices out of range, a file cut short).
Mesh read_gmsh(const std::filesystem::path &path);

/// Whether `path` is named as a gmsh mesh (.msh).
bool is_gmsh_name(const std::filesystem::path &path);

} // namespace globemesh
