#!/usr/bin/env bash
# A coast given as lines against the same land as polygons (issue 41: the coast stage scales with
# the input): GSHHG at each resolution asked for, its land polygons' rings written as closed
# LineStrings (ogr2ogr -nlt MULTILINESTRING), meshed globally at 50 km from the lines and from the
# polygons by each binary given. Prints read_coast, the whole run's wall seconds and peak, nodes
# and q min, and the machine's load before each run.
#   bench/coast_lines.sh "RES..." GLOBEMESH [GLOBEMESH...]     e.g. bench/coast_lines.sh "i h" a b
# Needs /tmp/gshhg/RES.gpkg (bench/gshhg_land.py RES /tmp/gshhg/RES.gpkg; layer 'land').
set -euo pipefail
res=$1
shift
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for r in $res; do
    ogr2ogr -f GPKG -nlt MULTILINESTRING -nln coast "$work/lines_$r.gpkg" "/tmp/gshhg/$r.gpkg" land
    for exe in "$@"; do
        for kind in lines polygons; do
            if [ $kind = lines ]; then coast=("$work/lines_$r.gpkg" --coast-layer coast); else
                coast=("/tmp/gshhg/$r.gpkg" --coast-layer land); fi
            load=$(cut -d' ' -f1 /proc/loadavg)
            /usr/bin/time -f '%e %M' -o "$work/time" "$exe" mesh -q --overwrite --coast "${coast[@]}" \
                --hmax 50km -o "$work/o.nc" --timings "$work/t.json" --report "$work/r.json" >/dev/null
            /usr/bin/python3 - "$work/t.json" "$work/r.json" "$work/time" "$r $kind $exe" "$load" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))["stages"]; m = json.load(open(sys.argv[2]))["mesh"]
wall, kb = map(float, open(sys.argv[3]).read().split()[-2:])
print(f'{sys.argv[4]}: load {sys.argv[5]}; read_coast {t["read_coast"]:.2f} s, wall {wall:.1f} s, '
      f'peak {kb / 1024:.0f} MiB; {m["nodes"]:,} nodes, q min {m["quality"]["min"]:.3f}')
PY
        done
    done
done
