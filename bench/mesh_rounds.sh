#!/usr/bin/env bash
# Issue 4's two timing ratios, measured in alternated rounds (a shared or virtual machine's speed
# drifts by tens of percent over minutes, so a figure taken alone says little):
#   - `mesh` of the run nearest 1e6 nodes against the core's time to sort and triangulate 1e6
#     random points (delaunay_memory, which allocates as the executable does), bound 4x;
#   - the time per node of each run from 1e5 nodes up, as a percentage of their mean, bound +-30%.
# Each round runs the core once, then `globemesh mesh` on the 1:50m land at each uniform size;
# the last lines give the median of the rounds.
#
# Usage: bench/mesh_rounds.sh [BUILD_DIR] [ROUNDS] [sizes in km...]
#        (default build/release, 3 rounds, sizes 64 20 10: about 1e5, 1e6 and 4e6 nodes)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build/release}
rounds=${2:-3}
shift 2 || shift $#
sizes=${*:-"64 20 10"}
exe=$build/src/globemesh
core=$build/bench/delaunay_memory
for f in "$exe" "$core"; do
    [[ -x $f ]] || { echo "mesh_rounds.sh: $f not built (cmake --build $build)" >&2; exit 2; }
done
coast=$root/fixtures/coast/ne_50m_land.gpkg
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
: > "$tmp/rows"
for r in $(seq "$rounds"); do
    c=$("$core" 1000000 uniform | sed -n 's/.*points: \([0-9.]*\) s.*/\1/p')
    for h in $sizes; do
        "$exe" mesh --coast "$coast" --coast-layer land --hmax "${h}km" -o "$tmp/m.nc" --overwrite \
            --quiet --report "$tmp/r.json" >/dev/null
        /usr/bin/python3 - "$r" "$c" "$h" "$tmp/r.json" >> "$tmp/rows" <<'PY'
import json, sys
r, core, h = sys.argv[1:4]
rep = json.load(open(sys.argv[4]))
print(r, core, h, rep["mesh"]["nodes"], rep["stages"]["mesh"])
PY
    done
done
/usr/bin/python3 - "$tmp/rows" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
by_round = {}
for r, core, h, n, mesh in rows:
    by_round.setdefault(int(r), []).append((h, int(n), float(mesh), float(core)))
ratios, spreads = [], {}
print(f"{'round':<6} {'core_s':>7}  " + "  ".join(f"{h + ' km':>22}" for h, *_ in by_round[1]) + f"  {'mesh/core':>9}  spread of us/node (from 1e5 nodes)")
for r, runs in sorted(by_round.items()):
    core = runs[0][3]
    near = min(runs, key=lambda x: abs(x[1] - 1e6))
    ratio = near[2] / core
    ratios.append(ratio)
    per_node = {h: 1e6 * mesh / n for h, n, mesh, _ in runs if n >= 0.9e5}
    mean = statistics.mean(per_node.values())
    spread = {h: 100 * (v / mean - 1) for h, v in per_node.items()}
    for h, s in spread.items(): spreads.setdefault(h, []).append(s)
    cells = "  ".join(f"{mesh:7.3f} s {1e6 * mesh / n:5.2f} us/node" for h, n, mesh, _ in runs)
    print(f"{r:<6} {core:7.3f}  {cells}  {ratio:8.2f}x  " + " / ".join(f"{s:+.0f}%" for s in spread.values()))
print(f"median mesh/core at {near[0]} km ({near[1]} nodes): {statistics.median(ratios):.2f}x (bound 4x)")
print("median spread: " + " / ".join(f"{h} km {statistics.median(v):+.0f}%" for h, v in spreads.items()) + " (bound +-30%)")
PY
