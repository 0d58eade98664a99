#!/bin/sh
# Spherical Delaunay core at scale: peak bytes per point and seconds (one process per size and
# kind, so each high-water mark is its own), then time per point against CGAL's
# Delaunay_triangulation_on_sphere_2 on the same points in the same run.
# Usage: bench/core_scale.sh [BUILD_DIR]   (default build/release; needs the delaunay_memory and
# delaunay_bench targets built in Release; CGAL rows appear when libcgal-dev was found)
set -eu
build=${1:-build/release}
bin="$build/bench"
for kind_n in "uniform 10000" "uniform 100000" "uniform 1000000" "uniform 4000000" \
              "clustered 100000" "clustered 1000000"; do
    set -- $kind_n
    "$bin/delaunay_memory" "$2" "$1"
done
"$bin/delaunay_bench" --benchmark_filter='BM_(globemesh|cgal)_(uniform|clustered)' \
    --benchmark_counters_tabular=true
