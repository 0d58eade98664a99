// globemesh/cli.hpp: the whole command line as a library function (PROJ's projinfo_lib split).
//
// run_cli parses the arguments (CLI11, config files), validates them, calls the library, shows
// GDAL-style progress on `err`, and maps errors to one line on `err` prefixed "globemesh:" and an
// exit status: 0 success, 1 data/IO error, 2 usage error. It never calls exit().
#pragma once

#include <ostream>
#include <span>
#include <string>

namespace globemesh {

int run_cli(std::span<const std::string> args, std::ostream& out, std::ostream& err);

} // namespace globemesh
