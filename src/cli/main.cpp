// The globemesh executable: forwards argv to run_cli, under the executables' allocation policy
// (allocation.cpp).
#include <iostream>
#include <string>
#include <vector>

#include "allocation.hpp"
#include "globemesh/cli.hpp"

int main(int argc, char **argv) {
    globemesh::configure_allocation();
    std::vector<std::string> args(argv + 1, argv + argc);
    return globemesh::run_cli(args, std::cout, std::cerr);
}
