# Sourced by the benchmark scripts: Natural Earth's land at a scale (110m, 50m or 10m), from
# fixtures/coast or, for 1:10m (7.8 MB, not copied into fixtures), ../shared/data beside the
# repository. Prints the file's path, or says what is missing and exits 2.
natural_earth_land() {
    local root f
    root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
    for f in "$root/fixtures/coast/ne_$1_land.gpkg" "$root/../shared/data/ne_$1_land.gpkg"; do
        [[ -f $f ]] && { echo "$f"; return; }
    done
    echo "$(basename "$0"): no ne_$1_land.gpkg in fixtures/coast or ../shared/data" >&2
    exit 2
}

# The land of a benchmark size SIZE[:SCALE] (km, then 110m, 50m or 10m; 1:50m without a scale).
coast_of_size() {
    if [[ $1 == *:* ]]; then natural_earth_land "${1#*:}"; else natural_earth_land 50m; fi
}

# Every size's land there, or the script stops before its first run (a command substitution's
# exit would not stop it).
check_sizes_coasts() {
    local s
    for s in "$@"; do coast_of_size "$s" >/dev/null; done
}
