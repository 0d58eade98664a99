// Issue 4's analytic size fields on a real coast: shapes the coast and meshes the ocean with one
// of them, then writes the UGRID file for mesh-verify (bench/mesher_quality.sh runs it).
// Usage: mesher_fields COAST LAYER FIELD OUT.nc [LATTICE_KM], FIELD one of
//   uniform:H          H km everywhere
//   gulf-stream        20 km within 1500 km of 65W 38N, 160 km beyond, a 1000 km linear ramp
//   latitude           20 km at the equator growing to 200 km at the poles
// LATTICE_KM is MesherOptions::lattice_km, by default the field's largest value (0: no lattice).
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "globemesh/coast.hpp"
#include "globemesh/mesher.hpp"
#include "globemesh/options.hpp"
#include "globemesh/sizefield.hpp"
#include "globemesh/ugrid.hpp"

int main(int argc, char **argv) {
    if (argc != 5 && argc != 6) {
        std::fprintf(stderr, "usage: mesher_fields COAST LAYER uniform:H|gulf-stream|latitude "
                             "OUT.nc [LATTICE_KM]\n");
        return 2;
    }
    try {
        globemesh::MeshOptions o;
        o.coast = argv[1];
        o.coast_layer = argv[2];
        const std::string field = argv[3];
        globemesh::SizeFn size;
        globemesh::MesherOptions mo;
        if (field.rfind("uniform:", 0) == 0) {
            mo.lattice_km = std::atof(field.c_str() + 8);
            size = globemesh::uniform_size(mo.lattice_km);
        } else if (field == "gulf-stream") {
            mo.lattice_km = 160;
            size = globemesh::gulf_stream_size(globemesh::lonlat_to_vec(-65, 38));
        } else if (field == "latitude") {
            mo.lattice_km = 200;
            size = globemesh::latitude_size(20, 200);
        } else {
            throw std::runtime_error("unknown field " + field);
        }
        if (argc == 6)
            mo.lattice_km = std::atof(argv[5]);
        globemesh::Boundary boundary;
        {
            globemesh::CoastData coast = globemesh::load_coast(o);
            boundary = globemesh::shape_boundary(coast, size, o);
            mo.land = coast.land;
        }
        globemesh::MesherReport report;
        globemesh::Mesh mesh = globemesh::mesh_boundary(boundary, size, mo, &report);
        globemesh::write_ugrid(mesh, argv[4]);
        std::printf("%s: %zu nodes (%zu from the lattice), %zu faces, %zu sharp corners touching "
                    "%zu faces, "
                    "%zu inlets closed (%.0f km2), %zu flips towards valence 6, %zu triangles of "
                    "boundary corners mended, %zu faces moved off "
                    "dropped islands (%zu left on them), %zu faces on land removed with %zu of "
                    "water (%zu holes, %zu loops joined, %zu moved off, %zu left)\n",
                    field.c_str(), mesh.nodes.size(), report.lattice_nodes, mesh.faces.size(),
                    report.sharp_corners, report.sharp_corner_faces, report.inlets_closed,
                    report.inlet_area_km2, report.valence_flips, report.corners_mended,
                    report.island_centroids_moved, report.island_centroids_left,
                    report.land_faces_removed, report.water_faces_removed, report.land_holes,
                    report.land_loops_joined, report.land_faces_nudged, report.land_faces_left);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "mesher_fields: %s\n", e.what());
        return 1;
    }
    return 0;
}
