#!/usr/bin/env bash
# Issue 8's real-world sweep: the Natural Earth land at 1:110m, 1:50m and 1:10m meshed at sizes
# from 500 km down to 10 km, globally and in the regions that break meshers (the Mediterranean,
# the Arctic around the North Pole, the Southern Ocean around Antarctica, the Bering Strait and
# Fiji across +-180). Every output is judged by the independent checker mesh-verify (UGRID
# conformance, topology, orientation, overlap, Delaunay); the table goes to bench/RESULTS-sweep.md.
#
# Usage: bench/sweep.sh [globemesh binary] [mesh-verify]
#   SWEEP_ONLY="3 7" bench/sweep.sh ...   runs only those rows of the table (1-based)
# The 1:10m land is read from ../shared/data (not a fixture: 6 MB); rows needing it are skipped
# with a note when it is absent. Runs one at a time (the machine is shared): about 10 minutes.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=${1:-$root/build/release/src/globemesh}
verify=${2:-$root/../shared/tools/mesh-verify}
out_md=${SWEEP_OUT:-$root/bench/RESULTS-sweep.md}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

land110=$root/fixtures/coast/ne_110m_land.gpkg
land50=$root/fixtures/coast/ne_50m_land.gpkg
land10=$root/../shared/data/ne_10m_land.gpkg

# Regions (W,S,E,N degrees; W > E crosses +-180).
med=-6,30,37,46.5        # the Mediterranean from Gibraltar to the Levant
arctic=-180,60,180,90    # every longitude north of 60N: the North Pole inside
south=-180,-90,180,-45   # the Southern Ocean: Antarctica closed through the South Pole
bering=160,50,-150,72    # the Bering Strait and the Aleutians, across +-180
fiji=172,-25,-172,-10    # Fiji, split by the antimeridian

# land | region name | --region | size options | size label. Sizes cover every decade from
# 500 km to 10 km; uniform (--hmax) and graded (--coast-size with --hmax) alike.
runs=(
    "110m|global|-|--hmax 500km|500 km"
    "110m|global|-|--coast-size 50km --hmax 250km|50-250 km"
    "110m|Mediterranean|$med|--hmax 50km|50 km"
    "110m|Arctic|$arctic|--hmax 100km|100 km"
    "110m|Southern Ocean|$south|--coast-size 20km --hmax 200km|20-200 km"
    "110m|Bering Strait|$bering|--hmax 25km|25 km"
    "50m|global|-|--hmax 200km|200 km"
    "50m|Mediterranean|$med|--hmax 10km|10 km"
    "50m|Arctic|$arctic|--coast-size 15km --hmax 150km|15-150 km"
    "50m|Southern Ocean|$south|--hmax 50km|50 km"
    "50m|Fiji|$fiji|--hmax 10km|10 km"
    "10m|global|-|--coast-size 30km --hmax 300km|30-300 km"
    "10m|Mediterranean|$med|--coast-size 10km --hmax 60km|10-60 km"
    "10m|Arctic|$arctic|--hmax 30km|30 km"
    "10m|Bering Strait|$bering|--hmax 10km|10 km"
    "10m|global|-|--hmax 10km|10 km"
)

{
    echo "# Real-world sweep (issue 8)"
    echo
    echo "Natural Earth land meshed by \`bench/sweep.sh\` ($(date -u +%Y-%m-%d), $(nproc) cores shared, Release)."
    echo "q = 2 sqrt(3) r_in / l_max of each face's chordal triangle, as mesh-verify computes it (1 ="
    echo "equilateral), worst and mean over the faces. Seconds: the"
    echo "whole \`globemesh mesh\` process (read, size field, mesh, write). Verdict: mesh-verify's exit status"
    echo "with its default checks (UGRID conformance, topology, orientation, overlap, Delaunay)."
    echo
    echo "| # | land | region | size | nodes | worst q | mean q | seconds | mesh-verify |"
    echo "|---|------|--------|------|------:|--------:|-------:|--------:|-------------|"
} >"$tmp/table.md"

failures=0
i=0
for row in "${runs[@]}"; do
    i=$((i + 1))
    if [[ -n "${SWEEP_ONLY:-}" && " $SWEEP_ONLY " != *" $i "* ]]; then continue; fi
    IFS='|' read -r land name region sizes label <<<"$row"
    case $land in 110m) coast=$land110 ;; 50m) coast=$land50 ;; 10m) coast=$land10 ;; esac
    if [[ ! -f $coast ]]; then
        echo "| $i | $land | $name | $label | - | - | - | - | skipped: $coast absent |" >>"$tmp/table.md"
        continue
    fi
    args=(mesh --coast "$coast" --coast-layer land $sizes -o "$tmp/m.nc" --overwrite --quiet
          --report "$tmp/r.json")
    [[ $region != - ]] && args+=(--region "$region")
    echo "[$i] globemesh ${args[*]}" >&2
    t0=$(date +%s.%N)
    if ! "$exe" "${args[@]}" >"$tmp/out.txt" 2>"$tmp/err.txt"; then
        secs=$(echo "$(date +%s.%N) - $t0" | bc)
        msg=$(tr '\n' ' ' <"$tmp/err.txt" | cut -c1-120)
        echo "| $i | $land | $name | $label | - | - | - | $(printf %.1f "$secs") | **globemesh failed**: $msg |" >>"$tmp/table.md"
        echo "    FAILED: $msg" >&2
        failures=$((failures + 1))
        continue
    fi
    secs=$(echo "$(date +%s.%N) - $t0" | bc)
    /usr/bin/python3 "$verify" "$tmp/m.nc" --json "$tmp/v.json" --quiet >"$tmp/verify.txt" 2>&1
    status=$?
    verdict=$([[ $status == 0 ]] && echo pass || echo "**FAIL** ($(grep -m1 '^x' "$tmp/verify.txt" | cut -c1-100))")
    [[ $status == 0 ]] || failures=$((failures + 1))
    /usr/bin/python3 - "$tmp/v.json" "$tmp/r.json" "$i" "$land" "$name" "$label" "$secs" "$verdict" \
        >>"$tmp/table.md" <<'PY'
import json, sys
v_path, r_path, i, land, name, label, secs, verdict = sys.argv[1:]
try:
    v = json.load(open(v_path))
except Exception:
    v = {}
r = json.load(open(r_path))
q = v.get("quality", {}) if isinstance(v.get("quality"), dict) else {}
nodes = r["mesh"]["nodes"]
worst = q.get("min", r["mesh"]["quality"]["min"])
mean = q.get("mean", r["mesh"]["quality"]["mean"])
print(f"| {i} | {land} | {name} | {label} | {nodes} | {worst:.2g} | {mean:.3f} | {float(secs):.1f} | {verdict} |")
PY
    tail -1 "$tmp/table.md" >&2
    [[ $status == 0 ]] || cp "$tmp/m.nc" "$tmp/../sweep-failed-$i.nc" 2>/dev/null
done

{
    echo
    echo "Regions: Mediterranean $med, Arctic $arctic, Southern Ocean $south, Bering Strait $bering,"
    echo "Fiji $fiji (W,S,E,N degrees; W > E crosses +-180). Rerun: \`bench/sweep.sh build/release/src/globemesh\`."
    echo "Failures: $failures."
} >>"$tmp/table.md"
cp "$tmp/table.md" "$out_md"
cat "$out_md"
exit $((failures > 0))
