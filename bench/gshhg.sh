#!/usr/bin/env bash
# Global meshes of the GSHHG coastline (Debian gmt-gshhg-{low,high,full}) at several sizes:
# the coast stage's time, the whole run and mesh-verify's verdict with --coast (issue 37).
# Usage: bench/gshhg.sh BUILD_DIR [RESOLUTIONS (default "i h f")] [SIZES_KM (default "100 50 25")]
# The assembled land polygons are cached in ${GSHHG_CACHE:-/tmp/globemesh-gshhg} (gshhg_R.gpkg,
# or R.gpkg as bench/gshhg_land.py's callers left them in /tmp/gshhg). GSHHG_VERIFY=0 skips
# mesh-verify (minutes on f). Meshes and timings go to ${GSHHG_OUT:-the cache}.
set -euo pipefail
build=${1:?usage: bench/gshhg.sh BUILD_DIR [RESOLUTIONS] [SIZES_KM]}
resolutions=${2:-i h f}
sizes=${3:-100 50 25}
here=$(cd "$(dirname "$0")" && pwd)
cache=${GSHHG_CACHE:-/tmp/globemesh-gshhg}
verify="$here/../../shared/tools/mesh-verify"
out_dir=${GSHHG_OUT:-$cache}
mkdir -p "$cache" "$out_dir"
for r in $resolutions; do
    land="$cache/gshhg_$r.gpkg"
    [ -f "$land" ] || [ ! -f "$cache/$r.gpkg" ] || land="$cache/$r.gpkg"
    [ -f "$land" ] || "$here/gshhg_land.py" "$r" "$land"
    for h in $sizes; do
        out="$out_dir/gshhg_${r}_${h}km.nc"
        /usr/bin/time -f "%e s wall, %U+%S s CPU, %M KB peak" "$build/src/globemesh" mesh --coast "$land" --hmax "${h}km" \
            -o "$out" --timings "$out_dir/t.json" --overwrite --quiet 2> "$out_dir/time.txt" >/dev/null || {
            echo "gshhg $r ${h} km: FAILED: $(tail -1 "$out_dir/time.txt")"; continue; }
        coast=$(sed -nE 's/.*"read_coast": ([0-9.]+).*/\1/p' "$out_dir/t.json")
        quality=$("$build/src/globemesh" info "$out" | sed -nE "s/^quality +//p" | head -1)
        verdict="mesh-verify SKIPPED"
        [ -x "$verify" ] && [ "${GSHHG_VERIFY:-1}" != 0 ] && verdict=$("$verify" "$out" --coast "$land" 2>&1 | grep -m1 -oE "RESULT: [A-Z]+")
        echo "gshhg $r ${h} km: read_coast ${coast} s, run $(tail -1 "$out_dir/time.txt"), quality ${quality}, ${verdict}"
    done
done
