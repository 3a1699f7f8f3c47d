#!/usr/bin/env bash
# bench_triangle_map.sh - the triangle's fold map (fe/triangle --problem fold --map, run by
# `make bench`): on M256, M1024 and M4096 (--mesh 16, 32, 64) the located end of the fold curves
# (where the two limit points merge), the interval of F with a snap-through, and what a point of
# the map costs: one run of the fold problem at one F (factorisations and CPU seconds a run).
# OpenBLAS on one thread. Table on stdout, CSV in bench/out/triangle_map.csv.
# Usage: bench/bench_triangle_map.sh [MESH...]
set -u
cd "$(dirname "$0")/.."
tri=fe/triangle
[ -x "$tri" ] || { echo "build fe/triangle first (make examples)"; exit 1; }
meshes=${*:-16 32 64}
mkdir -p bench/out
csv=bench/out/triangle_map.csv
echo "mesh,n,runs,factorisations,factorisations_per_run,seconds,seconds_per_run,end_F,end_lo,end_hi,snap_through" >"$csv"
echo "bench_triangle_map: triangle --problem fold --map (F in [1.5, 1.95] step 0.05, ends to 1e-5)"
printf '  %-6s %6s %5s %15s %9s %9s %9s  %-28s %s\n' mesh N runs factorisations "a run" "time [s]" "s a run" "end (two limit points merge)" "snap-through"
for m in $meshes; do
    out=$(OPENBLAS_NUM_THREADS=1 "$tri" --quiet --mesh "$m" --problem fold --map 2>&1)
    rc=$?
    n=$(printf '%s\n' "$out" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
    sum=$(printf '%s\n' "$out" | grep 'runs (points of the map)')
    runs=$(printf '%s\n' "$sum" | sed -n 's/^ *\([0-9]*\) runs.*/\1/p')
    fact=$(printf '%s\n' "$sum" | sed -n 's/.*map), \([0-9]*\) factorisations.*/\1/p')
    per=$(printf '%s\n' "$sum" | sed -n 's/.*factorisations, \([0-9]*\) a run.*/\1/p')
    secs=$(printf '%s\n' "$sum" | sed -n 's/.*time \([0-9.]*\) s (CPU).*/\1/p')
    sper=$(printf '%s\n' "$sum" | sed -n 's/.*CPU), \([0-9.]*\) s a run.*/\1/p')
    endl=$(printf '%s\n' "$out" | grep -B3 'two limit points merge' | grep '^  change at F' | head -n 1)
    endf=$(printf '%s\n' "$endl" | sed -n 's/.*change at F = \([0-9.]*\) .*/\1/p')
    lo=$(printf '%s\n' "$endl" | sed -n 's/.*(in (\([0-9.]*\), .*/\1/p')
    hi=$(printf '%s\n' "$endl" | sed -n 's/.*, \([0-9.]*\)), conf.*/\1/p')
    snap=$(printf '%s\n' "$out" | sed -n 's/.*snap-through exists for F in \(.*\)/\1/p')
    [ $rc -eq 0 ] || snap="FAILED (exit $rc) $snap"
    printf '  M%-5s %6s %5s %15s %9s %9s %9s  %-28s %s\n' "$((m * m))" "$n" "$runs" "$fact" "$per" "$secs" "$sper" \
        "$endf" "$snap"
    echo "M$((m * m)),$n,$runs,$fact,$per,$secs,$sper,$endf,$lo,$hi,\"$snap\"" >>"$csv"
done
