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
