#!/usr/bin/env bash
# Issue 40's feature-size term on real fjord coasts: each case meshed without the term, with
# --feature-size 3, and with a coast-distance field alone and with the term added (the size-field
# stage's own time against what the term adds). Prints one markdown row per run: nodes, the
# size_field stage's seconds (--timings), the whole run's seconds, mesh-verify (--min-quality 0.3).
#
# Usage: bench/feature_size.sh [globemesh binary] [mesh-verify]
# Reads ../shared/data/ne_10m_land.gpkg and /tmp/gshhg/h.gpkg (GSHHG high, bench/gshhg_land.py);
# cases whose input is missing are skipped. One run at a time (the machine is shared).
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${1:-$root/build/release/src/globemesh}
verify=${2:-$root/../shared/tools/mesh-verify}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
ne10=$root/../shared/data/ne_10m_land.gpkg
gshhg=/tmp/gshhg/h.gpkg

# name | coast | layer | --region | size options
cases=(
    "Norway NE 10m, 1-20 km|$ne10|land|4,58,16,66|--hmin 1km --hmax 20km"
    "Chile NE 10m, 1-20 km|$ne10|land|-76,-56,-66,-40|--hmin 1km --hmax 20km"
    "Norway GSHHG h, 2-20 km|$gshhg|land|4,58,16,66|--hmin 2km --hmax 20km"
    "Norway GSHHG h, 0.5-10 km|$gshhg|land|4,59,8,62|--hmin 0.5km --hmax 10km"
    "Chile GSHHG h, 1-20 km|$gshhg|land|-76,-56,-66,-40|--hmin 1km --hmax 20km"
)
# extra options of each run of a case
variants=("" "--feature-size 3" "--coast-size 2km" "--coast-size 2km --feature-size 3")

echo "| case | options | nodes | size_field s | total s | mesh-verify |"
echo "|---|---|---|---|---|---|"
for c in "${cases[@]}"; do
    IFS='|' read -r name coast layer region sizes <<<"$c"
    if [ ! -f "$coast" ]; then
        echo "| $name | skipped: $coast missing | | | | |"
        continue
    fi
    for v in "${variants[@]}"; do
        # shellcheck disable=SC2086
        start=$(date +%s.%N)
        if ! "$exe" mesh -q --overwrite --coast "$coast" --coast-layer "$layer" --region "$region" \
            $sizes $v -o "$tmp/m.nc" --timings "$tmp/t.json" >"$tmp/out" 2>"$tmp/err"; then
            echo "| $name | ${v:-(none)} | refused: $(tr -d '|' <"$tmp/err" | head -1) | | | |"
            continue
        fi
        total=$(echo "$(date +%s.%N) - $start" | bc)
        nodes=$(ncdump -h "$tmp/m.nc" | sed -n 's/.*nMesh_node = \([0-9]*\).*/\1/p')
        field=$(/usr/bin/python3 -c "import json,sys; d=json.load(open(sys.argv[1])); \
s=d.get('stages', d); print(next((x['seconds'] for x in s if x.get('name')=='size_field'), '?') \
if isinstance(s, list) else s.get('size_field','?'))" "$tmp/t.json")
        check=skipped
        if [ -x "$verify" ]; then
            if "$verify" "$tmp/m.nc" --quiet --min-quality 0.3 >"$tmp/v" 2>&1; then check=VALID
            else check="FAIL: $(head -1 "$tmp/v" | tr -d '|')"; fi
        fi
        printf '| %s | %s | %s | %.2f | %.1f | %s |\n' "$name" "${v:-(none)}" "$nodes" "$field" \
            "$total" "$check"
    done
done
