#!/usr/bin/env bash
# Global meshes of the GSHHG coastline (Debian gmt-gshhg-{low,high,full}) at several sizes:
# the coast stage's time, the whole run and mesh-verify's verdict with --coast (issue 37).
# Usage: bench/gshhg.sh BUILD_DIR [RESOLUTIONS (default "i h f")] [SIZES_KM (default "100 50 25")]
# The assembled land polygons are cached in ${GSHHG_CACHE:-/tmp/globemesh-gshhg}.
set -euo pipefail
build=${1:?usage: bench/gshhg.sh BUILD_DIR [RESOLUTIONS] [SIZES_KM]}
resolutions=${2:-i h f}
sizes=${3:-100 50 25}
here=$(cd "$(dirname "$0")" && pwd)
cache=${GSHHG_CACHE:-/tmp/globemesh-gshhg}
verify="$here/../../shared/tools/mesh-verify"
mkdir -p "$cache"
for r in $resolutions; do
    land="$cache/gshhg_$r.gpkg"
    [ -f "$land" ] || "$here/gshhg_land.py" "$r" "$land"
    for h in $sizes; do
        out="$cache/gshhg_${r}_${h}km.nc"
        /usr/bin/time -f "%e s wall, %M KB peak" "$build/src/globemesh" mesh --coast "$land" --hmax "${h}km" \
            -o "$out" --timings "$cache/t.json" --overwrite --quiet 2> "$cache/time.txt" >/dev/null || {
            echo "gshhg $r ${h} km: FAILED: $(tail -1 "$cache/time.txt")"; continue; }
        coast=$(sed -nE 's/.*"read_coast": ([0-9.]+).*/\1/p' "$cache/t.json")
        quality=$("$build/src/globemesh" info "$out" | sed -nE "s/^quality +//p" | head -1)
        verdict="mesh-verify SKIPPED"
        [ -x "$verify" ] && verdict=$("$verify" "$out" --coast "$land" 2>&1 | grep -m1 -oE "RESULT: [A-Z]+")
        echo "gshhg $r ${h} km: read_coast ${coast} s, run $(tail -1 "$cache/time.txt"), quality ${quality}, ${verdict}"
    done
done
