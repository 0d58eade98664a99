#!/usr/bin/env bash
# What two cores give two independent jobs on this machine: the bound of any --threads 2 speed-up.
# Runs the single-part mesh of the 1e6-node aqua-planet (bench/parallel.sh's case) alone, then two
# copies at once, and the same for a loop of floating-point additions that touches no memory;
# prints each job's seconds and the speed-up two cores give (2 x alone / together). A mesher
# whose two parts were perfectly balanced and had no serial step would reach that speed-up, no
# more. Figures in bench/RESULTS-parallel.md.
#   bench/pair_ceiling.sh GLOBEMESH [ROUNDS]
set -euo pipefail
exe=$(realpath "$1") rounds=${2:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/aqua.geojson" <<'JSON'
{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-150,0],[-148,0],[-148,2],[-150,2],[-150,0]]]}}]}
JSON
mesh() { # the mesh stage's seconds of one single-part run, job $1
    "$exe" mesh -q --overwrite --coast "$work/aqua.geojson" --hmax 24km --parts 1 --threads 1 \
        -o "$work/m$1.nc" --timings "$work/t$1.json" >/dev/null
    /usr/bin/python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['stages']['mesh'])" "$work/t$1.json"
}
loop() { # seconds of 1e8 additions in awk (registers only)
    /usr/bin/time -f %e awk 'BEGIN { for (i = 0; i < 1e8; i++) s += i * 0.5 }' 2>&1 >/dev/null
}
printf '%-6s %5s %6s %9s %9s %8s %s\n' job round load alone together speedup unit
for r in $(seq "$rounds"); do
    for job in mesh loop; do
        load=$(cut -d' ' -f1 /proc/loadavg)
        alone=$($job 1)
        $job 1 >"$work/a" & $job 2 >"$work/b" & wait
        together=$(sort -n "$work/a" "$work/b" | tail -1)
        /usr/bin/python3 -c "import sys; a, t = map(float, sys.argv[1:3]); print(f'{sys.argv[3]:<6} {sys.argv[4]:>5} {float(sys.argv[5]):6.2f} {a:9.3f} {t:9.3f} {2 * a / t:8.2f} s')" \
            "$alone" "$together" "$job" "$r" "$load"
    done
done
