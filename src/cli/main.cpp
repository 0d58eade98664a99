// The globemesh executable: forwards argv to run_cli and nothing else.
#include <iostream>
#include <string>
#include <vector>

#include "globemesh/cli.hpp"

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    return globemesh::run_cli(args, std::cout, std::cerr);
}
