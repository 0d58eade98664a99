#!/usr/bin/env bash
# Issue 4's scale benchmark: the global ocean from the 1:50m land at uniform sizes giving about
# 1e4, 1e5, 1e6 and 4e6 nodes. Prints nodes, seconds per node of the meshing ("mesh" stage:
# rings and size field to final mesh, I/O excluded) and of each mesher stage, and peak bytes
# per node of the whole process. Usage: bench/mesh_scale.sh [globemesh binary] [sizes in km...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${1:-$root/build/release/src/globemesh}
shift || true
sizes=${*:-"200 64 20 10"}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%-8s %10s %10s %12s %12s %12s %12s %14s\n' h_km nodes mesh_s us/node refine_us improve_us recover_us peak_B/node
for h in $sizes; do
    "$exe" mesh --coast "$root/fixtures/coast/ne_50m_land.gpkg" --coast-layer land --hmax "${h}km" \
        -o "$tmp/m.nc" --overwrite --quiet --timings "$tmp/t.json" --report "$tmp/r.json" >/dev/null
    /usr/bin/python3 - "$h" "$tmp/t.json" "$tmp/r.json" <<'PY'
import json, sys
h, t, r = sys.argv[1], json.load(open(sys.argv[2]))["stages"], json.load(open(sys.argv[3]))
n = r.get("nodes") or r.get("mesh", {}).get("nodes")
peak = r.get("peak_memory_bytes") or r.get("peak_memory_mib", 0) * 1048576 or r.get("peak_memory_kib", 0) * 1024
us = lambda k: 1e6 * t.get(k, 0) / n
print(f"{h:<8} {n:>10} {t['mesh']:>10.2f} {us('mesh'):>12.2f} {us('refine'):>12.2f} {us('improve'):>12.2f} {us('recover'):>12.2f} {peak / n:>14.0f}")
PY
done
