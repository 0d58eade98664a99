#!/usr/bin/env bash
# Issue 4's scale benchmark: the global ocean from the 1:50m land at uniform sizes giving about
# 1e4, 1e5, 1e6 and 4e6 nodes, one process per size and measurement.
#
# Part 1, `globemesh mesh` (the whole command): nodes, seconds and us/node of the "mesh" stage
# (rings and size field to final mesh, I/O excluded) and of the refine and improve stages, and
# peak bytes per node of the whole process (reading, meshing and writing the UGRID file).
# Part 2, when BUILD/bench/mesher_memory exists (target mesher_memory): mesh_boundary alone,
# wall-clock and CPU us/node (CPU time is less disturbed by other work on a shared machine) and
# the peak bytes per node of that call alone (VmHWM reset before it; the writer not counted);
# then the process's peak in each step (read_coast, boundary, each mesher stage, write).
#
# Usage: bench/mesh_scale.sh [BUILD_DIR | globemesh binary] [SIZE[:SCALE]...]
#        (default build/release; sizes 200 64 20 10)
# A size is in km; with :SCALE (110m, 50m or 10m) Natural Earth's land at that scale instead of
# 1:50m (bench/natural_earth.sh), e.g. `200:110m 64:110m 20:50m 10:10m`: each size with the
# finest scale drawn no finer than it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
arg=${1:-$root/build/release}
shift || true
if [[ -d $arg ]]; then
    exe=$arg/src/globemesh
    mem=$arg/bench/mesher_memory
else
    exe=$arg
    mem=$(dirname "$exe")/../bench/mesher_memory
fi
sizes=${*:-"200 64 20 10"}
source "$root/bench/natural_earth.sh"
check_sizes_coasts $sizes
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "globemesh mesh (whole process)"
printf '%-8s %10s %10s %10s %12s %12s %14s\n' h_km nodes mesh_s us/node refine_us improve_us peak_B/node
for s in $sizes; do
    h=${s%%:*}
    "$exe" mesh --coast "$(coast_of_size "$s")" --coast-layer land --hmax "${h}km" \
        -o "$tmp/m.nc" --overwrite --quiet --timings "$tmp/t.json" --report "$tmp/r.json" >/dev/null
    /usr/bin/python3 - "$s" "$tmp/t.json" "$tmp/r.json" <<'PY'
import json, sys
h, t, r = sys.argv[1], json.load(open(sys.argv[2]))["stages"], json.load(open(sys.argv[3]))
n = r.get("nodes") or r.get("mesh", {}).get("nodes")
peak = r.get("peak_memory_bytes") or r.get("peak_memory_mib", 0) * 1048576 or r.get("peak_memory_kib", 0) * 1024
us = lambda k: 1e6 * t.get(k, 0) / n
print(f"{h:<8} {n:>10} {t['mesh']:>10.2f} {us('mesh'):>10.2f} {us('refine'):>12.2f} {us('improve'):>12.2f} {peak / n:>14.0f}")
PY
done
if [[ -x $mem ]]; then
    echo "mesh_boundary alone (bench/mesher_memory)"
    for s in $sizes; do "$mem" "$(coast_of_size "$s")" land "${s%%:*}" 1 "$tmp/mm.nc"; done
else
    echo "($mem not built: cmake --build BUILD --target mesher_memory for the mesher's own peak)"
fi
