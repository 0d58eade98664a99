#!/usr/bin/env bash
# The whole run against the mesh stage at scale (issue 41): the 1.7e7-node global ocean on GSHHG
# low at 5 km, as one part (the default) and as two (total / mesh, peak bytes per node), and the
# global mesh of GSHHG full at 50 km (180,161 polygons: the whole run's wall seconds). Prints each run's stages (--timings), wall
# and CPU seconds and peak (/usr/bin/time) and the machine's load before it.
#   bench/whole_run.sh GLOBEMESH [GSHHG_DIR]
# GSHHG_DIR holds l.gpkg and f.gpkg (bench/gshhg_land.py l|f GSHHG_DIR/R.gpkg; default /tmp/gshhg).
set -euo pipefail
exe=$(realpath "$1") dir=${2:-/tmp/gshhg}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
run() { # NAME COAST HMAX [MORE OPTIONS]
    local load name=$1 coast=$2 hmax=$3
    shift 3
    load=$(cut -d' ' -f1 /proc/loadavg)
    /usr/bin/time -f '%e %U %S %M' -o "$work/time" "$exe" mesh -q --overwrite --coast "$coast" \
        --coast-layer land --hmax "$hmax" -o "$work/o.nc" --timings "$work/t.json" \
        --report "$work/r.json" "$@" >/dev/null
    /usr/bin/python3 - "$work/t.json" "$work/r.json" "$work/time" "$name" "$load" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["stages"]; n = json.load(open(sys.argv[2]))["mesh"]["nodes"]
wall, user, sys_, kb = map(float, open(sys.argv[3]).read().split()[-4:])
print(f'{sys.argv[4]}: {n:,} nodes, load {sys.argv[5]}; wall {wall:.1f} s, cpu {user + sys_:.1f} s, '
      f'peak {kb / 1024:.0f} MiB = {kb * 1024 / n:.0f} B/node; total/mesh {t["total"] / t["mesh"]:.2f}')
print('  ' + ', '.join(f'{k} {v:.2f}' for k, v in t.items()))
PY
}
run "GSHHG low, 5 km (the default: one part)" "$dir/l.gpkg" 5km
run "GSHHG low, 5 km, --parts 2" "$dir/l.gpkg" 5km --parts 2
run "GSHHG full, 50 km" "$dir/f.gpkg" 50km
