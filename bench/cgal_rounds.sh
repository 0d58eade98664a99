#!/bin/sh
# Spherical Delaunay core against CGAL's Delaunay_triangulation_on_sphere_2, in alternated rounds:
# each round times every case once for us and once for CGAL, one process each, the two back to
# back (ours first on odd rounds, CGAL first on even ones), so that a shared machine's drifting
# load falls on both alike. Prints every run, the load average around each round, and per case
# the medians over the rounds (us per point, CPU time and wall clock) and the range of the
# rounds' own CGAL / globemesh ratios.
# Usage: bench/cgal_rounds.sh [BUILD_DIR] [ROUNDS]   (default build/release, 5; needs the
#        delaunay_bench target built in Release with libcgal-dev installed)
#        bench/cgal_rounds.sh --summary SAVED_OUTPUT  (the table again from a saved run)
set -eu

summarise() { # summarise FILE: the table from the run lines in FILE
    /usr/bin/python3 - "$1" <<'PY'
import re, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    m = re.fullmatch(r"(\d+) (globemesh|cgal) (\w+) (\d+) \d+ (\S+) (\S+)\n?", line)
    if not m:
        continue
    r, lib, kind, n, wall, cpu = m.groups()
    per_point = lambda ms: float(ms) * 1000.0 / int(n)
    runs.setdefault((kind, int(n)), {}).setdefault(lib, {})[int(r)] = (per_point(cpu), per_point(wall))
print("| points | kind | rounds | globemesh us/pt | CGAL us/pt | CGAL / globemesh speed | "
      "rounds' ratios, min-max | wall us/pt: globemesh | wall: CGAL |")
print("|---:|---|---:|---:|---:|---:|---:|---:|---:|")
for (kind, n), by in sorted(runs.items(), key=lambda kv: (kv[0][0] != "uniform", kv[0][1])):
    g, c = by.get("globemesh", {}), by.get("cgal", {})
    paired = sorted(set(g) & set(c))
    if not paired:
        continue
    med = lambda d, i: statistics.median(d[r][i] for r in paired)
    ratios = [c[r][0] / g[r][0] for r in paired]
    size = f"{n:.0e}".replace("e+0", "e")
    print(f"| {size} | {kind} | {len(paired)} | {med(g, 0):.2f} | {med(c, 0):.2f} | "
          f"**{med(c, 0) / med(g, 0):.2f}** | {min(ratios):.2f}-{max(ratios):.2f} | "
          f"{med(g, 1):.2f} | {med(c, 1):.2f} |")
PY
}

if [ "${1:-}" = --summary ]; then
    summarise "$2"
    exit 0
fi
build=${1:-build/release}
rounds=${2:-5}
bench="$build/bench/delaunay_bench"
"$bench" --benchmark_list_tests | grep -q BM_cgal_ || {
    echo "cgal_rounds: $bench was built without CGAL (install libcgal-dev and reconfigure)" >&2
    exit 1
}
runs=$(mktemp)
trap 'rm -f "$runs"' EXIT
cases="uniform/10000 uniform/100000 uniform/1000000 uniform/4000000 clustered/100000 clustered/1000000"

run_one() { # run_one LIBRARY KIND/N ROUND: appends "ROUND LIBRARY KIND N ITERATIONS WALL_MS CPU_MS"
    "$bench" --benchmark_filter="^BM_$1_$2\$" --benchmark_format=csv 2>/dev/null |
        sed -n "s|^\"BM_$1_\([a-z]*\)/\([0-9]*\)\",\([0-9]*\),\([0-9.e+-]*\),\([0-9.e+-]*\),.*|$3 $1 \1 \2 \3 \4 \5|p" >>"$runs"
}

r=1
while [ "$r" -le "$rounds" ]; do
    echo "round $r: load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
    for c in $cases; do
        if [ $((r % 2)) -eq 1 ]; then
            run_one globemesh "$c" "$r"
            run_one cgal "$c" "$r"
        else
            run_one cgal "$c" "$r"
            run_one globemesh "$c" "$r"
        fi
    done
    echo "round $r: load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
    r=$((r + 1))
done

echo "# round library kind points iterations wall_ms_per_iteration cpu_ms_per_iteration"
cat "$runs"
echo
summarise "$runs"
