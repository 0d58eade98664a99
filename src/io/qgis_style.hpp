// Internal to io/: the QGIS layer style (.qml) written beside a UGRID file.
#pragma once

#include <string>

namespace globemesh::io {

/// A QGIS 3 mesh layer style that draws dataset group `group` (QGIS numbers the groups of a UGRID
/// file in the byte order of their names) with a bathymetry colour ramp from 0 to `max_depth` m.
std::string qgis_depth_style(int group, double max_depth);

/// The comment line that marks a style globemesh wrote (its second line), so that a later run
/// with --overwrite may remove one it no longer matches, and never a user's own.
inline constexpr const char *qgis_style_mark =
    "<!-- globemesh: the depth style of its UGRID file -->";

} // namespace globemesh::io
