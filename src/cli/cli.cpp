#include "globemesh/cli.hpp"

namespace globemesh {

int run_cli(std::span<const std::string>, std::ostream&, std::ostream& err) {
    err << "globemesh: not yet implemented\n";
    return 1;
}

} // namespace globemesh
