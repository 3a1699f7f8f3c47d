#!/usr/bin/env bash
# bench_count_map.sh - the cost of a branch-count map (psb_count_map) per sample, run by `make
# bench`: the teaching example's bilinear spring (11 samples) and the triangle's count at gamma
# = 0 as H1 runs across its four-branch window (M256, M1024; 7 samples each). For each: the
# samples, the changes located, Algorithm 2.2 runs, factorisations in all and per sample, and
# CPU seconds. OPENBLAS_NUM_THREADS=1 (small problems). Table on stdout, CSV in
# bench/out/count_map.csv. Usage: bench/bench_count_map.sh
set -u
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1
mkdir -p bench/out
for p in examples/06_count_map fe/triangle; do
    [ -x "$p" ] || { echo "build $p first (make examples)"; exit 1; }
done
csv=bench/out/count_map.csv
echo "problem,samples,changes,find_runs,factorisations,per_sample,seconds" >"$csv"
echo "bench_count_map: psb_count_map, the cost per sampled mu (OPENBLAS_NUM_THREADS=1)"
ldd fe/triangle | grep -E 'blas|lapack' | sed 's/^[[:space:]]*/  linked: /'
echo
printf '  %-26s %7s %7s %9s %14s %10s %8s\n' problem samples changes "2.2 runs" factorisations "per sample" "CPU [s]"
# row NAME SAMPLES OUTPUT SECONDS: parses the "cost:" line and the changes of one run
row() {
    local cost runs fact changes per
    cost=$(printf '%s\n' "$3" | grep 'cost:')
    runs=$(printf '%s\n' "$cost" | sed -n 's/.*cost: \([0-9]*\) runs.*/\1/p')
    fact=$(printf '%s\n' "$cost" | sed -n 's/.* \([0-9]*\) factorisations.*/\1/p')
    changes=$(printf '%s\n' "$3" | grep -c 'the count changes')
    per=$(awk -v f="$fact" -v s="$2" 'BEGIN { printf "%.0f", f / s }')
    printf '  %-26s %7d %7d %9d %14d %10d %8s\n' "$1" "$2" "$changes" "$runs" "$fact" "$per" "$4"
    echo "$1,$2,$changes,$runs,$fact,$per,$4" >>"$csv"
}
# timed CMD...: runs CMD, sets $out and $secs (CPU seconds of the child)
timed() {
    local t0 t1
    t0=$(awk '{ print $14 + $15 + $16 + $17 }' /proc/$$/stat)
    out=$("$@" 2>/dev/null)
    status=$?
    t1=$(awk '{ print $14 + $15 + $16 + $17 }' /proc/$$/stat)
    secs=$(awk -v a="$t0" -v b="$t1" -v hz="$(getconf CLK_TCK)" 'BEGIN { printf "%.1f", (b - a) / hz }')
}
timed ./examples/06_count_map
[ "$status" = 0 ] || echo "  06_count_map FAILED"
row "bilinear spring (06)" 11 "$out" "$secs"
timed ./fe/triangle --mesh 16 --count-map 24:25.2 --count-samples 7 --quiet
[ "$status" = 0 ] || echo "  triangle M256 FAILED"
row "triangle M256, H1 24-25.2" 7 "$out" "$secs"
timed ./fe/triangle --mesh 32 --count-map 24.6:26.4 --count-samples 7 --quiet
[ "$status" = 0 ] || echo "  triangle M1024 FAILED"
row "triangle M1024, H1 24.6-26.4" 7 "$out" "$secs"
