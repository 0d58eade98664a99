#!/usr/bin/env bash
# Options on real coasts nobody had run them on: GSHHG (every resolution the machine has) with
# each coast option, fine regions that break meshers, and the shared rasters, each run in one
# part and, where PARTS is given, in that many parts too. Every run is judged by its exit status
# (a refusal must be a one-line message, printed here) and every output by mesh-verify; q min
# of one part and of the parts side by side. Its GSHHG high run with --keep-inland-seas
# --keep-straits is how the lake touching its coast (6987404) was found.
#
#   bench/options_sweep.sh GLOBEMESH [PARTS] [GSHHG_DIR]
# GSHHG_DIR holds l.gpkg, i.gpkg, h.gpkg, f.gpkg (bench/gshhg_land.py; layer 'land'), default
# /tmp/gshhg; missing resolutions are skipped. With DCW=FILE.gpkg (bench/dcw_land.py: countries
# side by side) its runs follow: the regions whose gaps between countries were refused with
# --keep-inland-seas (80c48e6) and the global runs whose read was quadratic (d2ef012); about 10
# minutes more. ../shared/tools/mesh-verify and ../shared/data are used when present. About 15
# minutes on 2 cores without PARTS.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
exe=$(realpath "$1") parts=${2:-} gshhg=${3:-/tmp/gshhg}
verify=$root/../shared/tools/mesh-verify data=$root/../shared/data
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
n=0

# One run: its verdict, q min, and the last line it printed when it refused.
one() {
    local out=$work/m.nc
    if "$exe" mesh -q --overwrite "$@" -o "$out" >"$work/log" 2>&1; then
        local v=unchecked q
        [ -x "$verify" ] && v=$("$verify" "$out" 2>&1 | awk '/RESULT/ {print $2}')
        q=$("$exe" info "$out" | awk '/^quality/ {print $3}')
        printf '%s q %s' "$v" "$q"
    else
        printf 'refused: %s' "$(tail -n 1 "$work/log")"
    fi
    rm -f "$out"
}

run() {
    n=$((n + 1))
    printf '%3d | %s' "$n" "$(one "$@" --parts 1)"
    [ -n "$parts" ] && printf ' | %s parts: %s' "$parts" "$(one "$@" --parts "$parts")"
    printf ' | %s\n' "$*"
}

for r in l i h f; do
    [ -f "$gshhg/$r.gpkg" ] || { echo "GSHHG $r: $gshhg/$r.gpkg missing, skipped"; continue; }
    for opt in "" --keep-inland-seas --keep-straits "--min-island-area 100" "--passages default" \
        "--keep-inland-seas --keep-straits"; do
        # shellcheck disable=SC2086 # opt holds zero to two options
        run --coast "$gshhg/$r.gpkg" --coast-layer land --hmax 40km $opt
    done
done
for opt in "" --keep-inland-seas --keep-straits; do
    for case in "f 4,59,8,62 1km" "f -76,-50,-72,-46 3km" "f 22,36,28,41 3km" "h 9,53,31,66 5km" \
        "h 95,-11,141,6 10km" "h 170,-50,-170,-30 5km" "h -180,80,180,90 5km" \
        "i -180,-90,180,-60 10km" "f -94.5,29,-93,30.5 0.5km"; do
        read -r r box h <<<"$case"
        [ -f "$gshhg/$r.gpkg" ] || continue
        # shellcheck disable=SC2086
        run --coast "$gshhg/$r.gpkg" --coast-layer land --region "$box" --hmax "$h" $opt
    done
done
if [ -d "$data" ] && [ -f "$gshhg/i.gpkg" ] && [ -f "$gshhg/h.gpkg" ]; then
    run --coast "$gshhg/i.gpkg" --coast-layer land --bathy "$data/etopo5_global_10min.nc" \
        --hmin 10km --hmax 100km --wavelength 40 --slope 8
    run --coast "$gshhg/h.gpkg" --coast-layer land --bathy "$data/etopo5_nwshelf_5min.tif" \
        --region -12,48,10,62 --hmin 2km --hmax 20km --wavelength 60
fi
if [ -n "${DCW:-}" ] && [ -f "$DCW" ]; then
    for case in "4,58,12,64 2km" "13,42,19,46 2km" "20,35,28,41 3km" "8,54,13,58 1km" \
        "-12,34,42,66 10km" "95,-11,141,6 10km" "170,-50,-170,-30 5km"; do
        read -r box h <<<"$case"
        for opt in "" --keep-inland-seas --keep-straits; do
            # shellcheck disable=SC2086
            run --coast "$DCW" --coast-layer land --region "$box" --hmax "$h" $opt
        done
    done
    run --coast "$DCW" --coast-layer land --hmax 50km
    run --coast "$DCW" --coast-layer land --hmax 50km --keep-inland-seas
fi
