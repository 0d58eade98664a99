#!/usr/bin/env bash
# Issue 4's two timing ratios, measured in alternated rounds (a shared or virtual machine's speed
# drifts by tens of percent over minutes, so a figure taken alone says little):
#   - `mesh` of the run nearest 1e6 nodes against the core's time to sort and triangulate 1e6
#     random points (delaunay_memory, which allocates as the executable does), bound 4x;
#   - the time per node of each run from 1e5 nodes up, as a percentage of their mean, bound +-30%;
#   - a least-squares fit of each round's `mesh` to a*nodes + b*boundary edges (no constant), with
#     each run's residual: the share of the time per node that the coast's length explains.
# Each round runs the core once, then `globemesh mesh` on the 1:50m land at each uniform size;
# the last lines give the median of the rounds.
#
# Usage: bench/mesh_rounds.sh [BUILD_DIR] [ROUNDS] [SIZE[:SCALE]...]
#        (default build/release, 3 rounds, sizes 64 20 10: about 1e5, 1e6 and 4e6 nodes)
# A size is in km; with :SCALE (110m, 50m or 10m) it meshes Natural Earth's land at that scale
# instead of 1:50m (bench/natural_earth.sh: 1:10m is read from ../shared/data).
# `64:110m 20:50m 10:10m` gives each size the finest scale drawn no finer than it (1 mm of a
# 1:110m map is 110 km): the coast a user would take for that mesh.
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
source "$root/bench/natural_earth.sh"
check_sizes_coasts $sizes
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
: > "$tmp/rows"
for r in $(seq "$rounds"); do
    c=$("$core" 1000000 uniform | sed -n 's/.*points: \([0-9.]*\) s.*/\1/p')
    for s in $sizes; do
        h=${s%%:*}
        "$exe" mesh --coast "$(coast_of_size "$s")" --coast-layer land --hmax "${h}km" -o "$tmp/m.nc" --overwrite \
            --quiet --report "$tmp/r.json" >/dev/null
        /usr/bin/python3 - "$r" "$c" "$s" "$tmp/r.json" >> "$tmp/rows" <<'PY'
import json, sys
r, core, h = sys.argv[1:4]
rep = json.load(open(sys.argv[4]))
print(r, core, h, rep["mesh"]["nodes"], rep["stages"]["mesh"], rep["mesh"]["boundary_edges"])
PY
    done
done
/usr/bin/python3 - "$tmp/rows" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
# A size's label: "64 km", or "64 km 1:110m" with its coast's scale.
def lab(s): return s.split(":")[0] + " km" + (" 1:" + s.split(":")[1] if ":" in s else "")
by_round = {}
boundary = {}
for r, core, h, n, mesh, b in rows:
    by_round.setdefault(int(r), []).append((h, int(n), float(mesh), float(core)))
    boundary[h] = int(b)
ratios, spreads = [], {}
print(f"{'round':<6} {'core_s':>7}  " + "  ".join(f"{lab(h):>22}" for h, *_ in by_round[1]) + f"  {'mesh/core':>9}  spread of us/node (from 1e5 nodes)")
for r, runs in sorted(by_round.items()):
    core = runs[0][3]
    near = min(runs, key=lambda x: abs(x[1] - 1e6))
    ratio = near[2] / core
    ratios.append(ratio)
    per_node = {h: 1e6 * mesh / n for h, n, mesh, _ in runs if n >= 0.9e5}
    mean = statistics.mean(per_node.values()) if per_node else 0
    spread = {h: 100 * (v / mean - 1) for h, v in per_node.items()}
    for h, s in spread.items(): spreads.setdefault(h, []).append(s)
    cells = "  ".join(f"{mesh:7.3f} s {1e6 * mesh / n:5.2f} us/node" for h, n, mesh, _ in runs)
    print(f"{r:<6} {core:7.3f}  {cells}  {ratio:8.2f}x  " + " / ".join(f"{s:+.0f}%" for s in spread.values()))
print(f"median mesh/core at {lab(near[0])} ({near[1]} nodes): {statistics.median(ratios):.2f}x (bound 4x)")
# T = a N + b B by least squares on the relative residuals (each size weighted 1/T), over the
# medians of each size: the 2x2 normal equations.
med = {h: statistics.median(float(x[2]) for runs in by_round.values() for x in runs if x[0] == h) for h, *_ in by_round[1]}
nodes = {h: n for h, n, *_ in by_round[1]}
x = {h: (nodes[h] / med[h], boundary[h] / med[h]) for h in med}
snn = sum(u * u for u, v in x.values()); snb = sum(u * v for u, v in x.values()); sbb = sum(v * v for u, v in x.values())
sn = sum(u for u, v in x.values()); sb = sum(v for u, v in x.values())
det = snn * sbb - snb * snb
if len(med) >= 2 and det > 0:
    a, b = (sn * sbb - sb * snb) / det, (snn * sb - snb * sn) / det
    print(f"fit of the medians, mesh = a nodes + b boundary edges: a {1e6 * a:.2f} us, b {1e6 * b:.1f} us; residuals "
          + " / ".join(f"{lab(h)} {100 * (a * nodes[h] + b * boundary[h] - med[h]) / med[h]:+.0f}% (B/N {boundary[h] / nodes[h]:.4f})" for h in med))
print("median spread: " + " / ".join(f"{lab(h)} {statistics.median(v):+.0f}%" for h, v in spreads.items()) + " (bound +-30%)")
PY
