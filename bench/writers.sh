#!/usr/bin/env bash
# The writers against the mesher (issue 41): a 1e6-node aqua-planet (one 2-degree island,
# --hmax 24km) and a 1e6-node global ocean on GSHHG low (--hmax 20km), each written as UGRID
# and GeoPackage, ROUNDS times; prints mesh, write_ugrid, write_gpkg and total seconds of each
# run, and the ratios to mesh (measured in one run).
#   bench/writers.sh GLOBEMESH [ROUNDS] [GSHHG_LOW_GPKG]
# GSHHG_LOW_GPKG defaults to /tmp/gshhg/l.gpkg (bench/gshhg.sh makes it; layer 'land').
set -euo pipefail
exe=$(realpath "$1") rounds=${2:-3} gshhg=${3:-/tmp/gshhg/l.gpkg}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/aqua.geojson" <<'JSON'
{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-150,0],[-148,0],[-148,2],[-150,2],[-150,0]]]}}]}
JSON
printf '%-6s %5s %9s %6s %11s %10s %7s %9s %9s %9s\n' case round nodes mesh write_ugrid write_gpkg total \
    ugrid/mesh gpkg/mesh total/mesh
for r in $(seq "$rounds"); do
    for c in aqua gshhg_l; do
        if [ $c = aqua ]; then args=(--coast "$work/aqua.geojson" --hmax 24km); else
            args=(--coast "$gshhg" --coast-layer land --hmax 20km); fi
        "$exe" mesh -q --overwrite "${args[@]}" -o "$work/o.nc" --gpkg "$work/o.gpkg" \
            --timings "$work/t.json" --report "$work/r.json" >/dev/null
        /usr/bin/python3 - "$work/t.json" "$work/r.json" "$c" "$r" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["stages"]; n = json.load(open(sys.argv[2]))["mesh"]["nodes"]
m = t["mesh"]
print(f'{sys.argv[3]:<6} {sys.argv[4]:>5} {n:>9} {m:6.2f} {t["write_ugrid"]:11.2f} {t["write_gpkg"]:10.2f} '
      f'{t["total"]:7.2f} {t["write_ugrid"]/m:9.2f} {t["write_gpkg"]/m:9.2f} {t["total"]/m:9.2f}')
PY
    done
done
