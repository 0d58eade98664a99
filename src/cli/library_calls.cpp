// The real library calls of run_cli, in their own file: a program linking run_cli(args, out,
// err) links the whole library, while tests that pass their own CliLibrary need only the parts
// they use.
#include "globemesh/cli.hpp"

namespace globemesh {

CliLibrary library_calls() {
    CliLibrary lib;
    lib.mesh_ocean = [](const MeshOptions &o, const Progress &p, StageTimings *t) {
        return mesh_ocean(o, p, t);
    };
    lib.triangulate_file = [](const TriangulateOptions &o, const Progress &p, StageTimings *t) {
        return triangulate_file(o, p, t);
    };
    lib.writers = writers();
    lib.read_ugrid = [](const std::filesystem::path &p) { return read_ugrid(p); };
    lib.read_adcirc = [](const std::filesystem::path &p) { return read_adcirc(p); };
    lib.read_gmsh = [](const std::filesystem::path &p) { return read_gmsh(p); };
    lib.compute_stats = [](const Mesh &m) { return compute_stats(m); };
    return lib;
}

int run_cli(std::span<const std::string> args, std::ostream &out, std::ostream &err) {
    return run_cli(args, out, err, library_calls());
}

} // namespace globemesh
