#!/usr/bin/env bash
# Parallel meshing (issue 41, docs/parallel.md): the mesh stage of a 1e6-node aqua-planet (one
# 2-degree island, --hmax 24km) and a 1e6-node global ocean on GSHHG low (--hmax 20km), as one
# part and as --parts 2 with --threads 1 and 2. Prints per run the mesh stage's wall seconds,
# the process's wall and CPU seconds (user + sys; the machine is shared: the load average is
# printed before each run), the quality and size-fit figures, and whether the two thread
# counts wrote the same file (every variable and attribute but the history line, which holds
# the date and the command line: tools/same-outputs compare) and mesh-verify's verdict.
#   bench/parallel.sh GLOBEMESH [ROUNDS] [GSHHG_LOW_GPKG] [PARTS]
# AQUA_HMAX and GSHHG_HMAX (default 24km and 20km: about 1e6 nodes each) set the sizes: 12km and
# 10km give about 4.2e6 and 4.3e6 nodes, where --parts 0 meshes in two parts.
set -euo pipefail
exe=$(realpath "$1") rounds=${2:-1} gshhg=${3:-/tmp/gshhg/l.gpkg} parts=${4:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
verify=${MESH_VERIFY:-$root/../shared/tools/mesh-verify}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cat >"$work/aqua.geojson" <<'JSON'
{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon","coordinates":[[[-150,0],[-148,0],[-148,2],[-150,2],[-150,0]]]}}]}
JSON
printf '%-7s %5s %-9s %9s %6s %7s %6s %5s %6s %7s %6s %7s %6s %s\n' case round run nodes mesh wall cpu \
    load q_min q_mean "q>0.8" fit_med fit_in verify
for r in $(seq "$rounds"); do
    for c in aqua gshhg_l; do
        if [ $c = aqua ]; then args=(--coast "$work/aqua.geojson" --hmax "${AQUA_HMAX:-24km}"); else
            args=(--coast "$gshhg" --coast-layer land --hmax "${GSHHG_HMAX:-20km}"); fi
        for run in p1 "p$parts-t1" "p$parts-t2"; do
            p=${run#p}; p=${p%-t*}; t=${run##*-t}; [ "$run" = p1 ] && t=2
            mkdir -p "$work/$run"
            load=$(cut -d' ' -f1 /proc/loadavg)
            /usr/bin/time -f '%e %U %S' -o "$work/time" "$exe" mesh -q --overwrite "${args[@]}" \
                --parts "$p" --threads "$t" -o "$work/$run/mesh.nc" --timings "$work/t.json" \
                --report "$work/r.json" >/dev/null
            v=-
            [ -x "$verify" ] && { "$verify" "$work/$run/mesh.nc" --quiet >/dev/null 2>&1 && v=VALID || v=INVALID; }
            /usr/bin/python3 - "$work/t.json" "$work/r.json" "$work/time" "$c" "$r" "$run" "$load" "$v" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["stages"]; m = json.load(open(sys.argv[2]))["mesh"]
wall, user, sys_ = map(float, open(sys.argv[3]).read().split()[-3:])
q, f = m["quality"], m["size_ratio"]
open(sys.argv[1] + '.mesh', 'w').write(str(t["mesh"]))
print(f'{sys.argv[4]:<7} {sys.argv[5]:>5} {sys.argv[6]:<9} {m["nodes"]:>9} {t["mesh"]:6.3f} {wall:7.2f} '
      f'{user + sys_:6.2f} {float(sys.argv[7]):5.1f} {q["min"]:6.3f} {q["mean"]:7.4f} {100 * q["above_0_8"]:6.2f} '
      f'{f["median"]:7.3f} {100 * f["in_0_7_1_4"]:6.2f} {sys.argv[8]}')
PY
            cp "$work/t.json.mesh" "$work/$run.mesh"
        done
        echo "$c: mesh stage --threads 1 / --threads 2: $(/usr/bin/python3 -c "import sys; print('%.2fx' % (float(open(sys.argv[1]).read()) / float(open(sys.argv[2]).read())))" "$work/p$parts-t1.mesh" "$work/p$parts-t2.mesh")"
        "$root/tools/same-outputs" compare "$work/p$parts-t1" "$work/p$parts-t2" >/dev/null &&
            echo "$c: --threads 1 and 2 wrote the same mesh file (but the history line)" ||
            echo "$c: --threads 1 and 2 DIFFER"
    done
done
