// The command line's name of each library option: MeshOptions' field names (hmax_km), which the
// library's messages use, mapped to the flags of `globemesh mesh` (--hmax).
#pragma once

#include <string>
#include <string_view>

namespace globemesh::cli {

/// The flag of the MeshOptions field `field` ("hmax_km" -> "--hmax"); the field itself when no
/// flag sets it.
std::string flag_of(std::string_view field);

} // namespace globemesh::cli
