#!/usr/bin/env bash
# --passages default on real coasts: node count, quality, fewest cells across a passage and time,
# against the same run without it. Figures in bench/RESULTS-passages.md.
#   bench/passages.sh [GLOBEMESH] [COAST:LAYER ...]   (default: NE 1:10m, GSHHG l and i)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${1:-$root/build/release/src/globemesh}
shift || true
coasts=("$@")
[ ${#coasts[@]} -gt 0 ] || coasts=("$root/../shared/data/ne_10m_land.gpkg:land" /tmp/gshhg/l.gpkg:land /tmp/gshhg/i.gpkg:land)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| coast | hmax | passages | nodes | q min | q>0.8 | fewest cells | straits closed | time (s) |\n|---|---|---|---|---|---|---|---|---|\n'
for c in "${coasts[@]}"; do
    for h in 100 50; do
        for p in no default; do
            args=(mesh -q --overwrite --coast "${c%%:*}" --coast-layer "${c##*:}" --hmax "${h}km"
                  -o "$out/m.nc" --report "$out/r.json")
            [ "$p" = no ] || args+=(--passages "$p")
            nice "$exe" "${args[@]}" >/dev/null
            /usr/bin/python3 - "$out/r.json" "$(basename "${c%%:*}")" "$h" "$p" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); m = r["mesh"]; a = dict(r["attributes"])
p = r.get("passages")
fewest = min((x["cells"], x["name"]) for x in p["list"]) if p else None
q = m["quality"]
# "S (cutting off B basins: A km2, ...": the count and the largest basin cut off
import re
closed = a.get("straits_closed", "0")
areas = [float(x) for x in re.findall(r"([0-9.e+]+) km2", closed.split("; ")[0])]
closed = closed.split(" ")[0] + (f", largest basin cut off {max(areas):.0f} km2" if areas else "")
print(f"| {sys.argv[2]} | {sys.argv[3]} km | {sys.argv[4]} | {m['nodes']} | {q['min']:.3f} | "
      f"{100 * q['above_0_8']:.1f}% | "
      f"{f'{fewest[0]} ({fewest[1]})' if fewest else '-'} | {closed} | {r['total_seconds']:.2f} |")
PY
        done
    done
done
