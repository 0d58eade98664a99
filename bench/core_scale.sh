#!/bin/sh
# Spherical Delaunay core at scale: peak bytes per point and seconds (one process per size and
# kind, so each high-water mark is its own), then our time per point. The comparison with CGAL
# is bench/cgal_rounds.sh (alternated rounds).
# Usage: bench/core_scale.sh [BUILD_DIR]   (default build/release; needs the delaunay_memory and
# delaunay_bench targets built in Release)
set -eu
build=${1:-build/release}
bin="$build/bench"
for kind_n in "uniform 10000" "uniform 100000" "uniform 1000000" "uniform 4000000" \
              "clustered 100000" "clustered 1000000"; do
    set -- $kind_n
    "$bin/delaunay_memory" "$2" "$1"
done
"$bin/delaunay_bench" --benchmark_filter='BM_globemesh_(uniform|clustered)' \
    --benchmark_counters_tabular=true
