#!/usr/bin/env bash
# bench_mumps.sh - whole runs of the block example (Section 3.2: approach, Algorithms 2.1-2.2,
# six branches traced to |gamma| = 1) with the banded backend, MUMPS on 1 rank and MUMPS on 2
# ranks (tools/mpirun.sh), side by side in one sitting: wall seconds (MPI start-up included), CPU
# seconds of all processes (user + system: on a shared machine the wall time also counts the
# other jobs), factorisations, MUMPS's memory, the six branches. M800 and M3200; --large adds M12800.
# OPENBLAS_NUM_THREADS=1 (one BLAS thread per rank: the ranks are the parallelism). The
# end points of the MUMPS runs are checked against the banded run's by tests/mumps_ends.sh.
# Then MUMPS alone (bench/bench_mumps_factor): a factorisation and a 2-column solve of the
# block's bordered Jacobian on M3200 and M12800, 1 and 2 ranks.
# Tables on stdout and in bench/out/mumps.md, CSV in bench/out/mumps.csv (run by `make bench`
# when fe/block is built with MUMPS). Usage: bench/bench_mumps.sh [--large]
set -u
cd "$(dirname "$0")/.."
meshes="20x40 40x80"
for a in "$@"; do
    case "$a" in --large) meshes="$meshes 80x160" ;; *) echo "usage: bench/bench_mumps.sh [--large]" >&2; exit 2 ;; esac
done
block=fe/block
[ -x "$block" ] || { echo "build fe/block first (make examples)"; exit 1; }
"$block" --solver mumps --help >/dev/null 2>&1 || { echo "bench_mumps: fe/block is built without MUMPS, skipped"; exit 0; }
export OPENBLAS_NUM_THREADS=1
mkdir -p bench/out
out=bench/out/mumps.md
csv=bench/out/mumps.csv
{
    echo "bench_mumps: block whole runs, banded against MUMPS (wall seconds, $(nproc) cores, OPENBLAS_NUM_THREADS=1)"
    ldd "$block" | awk '/lib(blas|lapack|openblas|dmumps)/ { print $1, $3 }' | while read -r lib path; do
        echo "  linked: $lib => $(readlink -f "$path")"
    done
    echo "  load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo
    echo "| mesh | N | backend | wall [s] | CPU [s] | factorisations | MUMPS MB (largest rank / all) | branches | wall vs banded |"
    echo "|---|---|---|---|---|---|---|---|---|"
} | tee "$out"
echo "mesh,n,backend,seconds,cpu_seconds,factorisations,mumps_mb_rank,mumps_mb_all,ok" >"$csv"
# run MESH BACKEND CMD...: wall time of CMD, its figures; sets $secs
run() {
    local mesh=$1 backend=$2 t0 t1 o n fact mb="-" ok=FAILED speed="-" cpu
    shift 2
    t0=$(date +%s.%N)
    o=$({ TIMEFORMAT="cpu %U %S"; time "$@" --quiet --mesh "$mesh"; } 2>&1) # bash's time: every descendant
    t1=$(date +%s.%N)
    cpu=$(printf '%s\n' "$o" | awk '$1 == "cpu" { printf "%.1f", $2 + $3 }')
    secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    n=$(printf '%s\n' "$o" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
    fact=$(printf '%s\n' "$o" | sed -n 's/.*distinct branches.*factorisations \([0-9]*\).*/\1/p')
    printf '%s\n' "$o" | grep -q 'block: OK (six branches' && ok=6
    if printf '%s\n' "$o" | grep -q 'MUMPS on'; then
        mb=$(printf '%s\n' "$o" | sed -n 's/.*memory \([0-9]*\) MB on the largest rank, \([0-9]*\) MB in all.*/\1 \/ \2/p')
    fi
    [ "$backend" != banded ] && speed=$(awk -v s="$secs" -v b="$banded" 'BEGIN { printf "%.2fx", b / s }')
    echo "| M$(( ${mesh%x*} * ${mesh#*x} )) | $n | $backend | $secs | $cpu | $fact | $mb | $ok | $speed |" | tee -a "$out"
    echo "$mesh,$n,$backend,$secs,$cpu,$fact,${mb%% /*},${mb##*/ },$ok" >>"$csv"
}
for mesh in $meshes; do
    run "$mesh" banded "$block" --solver banded; banded=$secs
    run "$mesh" "MUMPS 1 rank" "$block" --solver mumps
    run "$mesh" "MUMPS 2 ranks" sh tools/mpirun.sh 2 "$block" --solver mumps
done
fac=bench/bench_mumps_factor
if [ -x "$fac" ]; then
    {
        echo
        echo "| mesh | N | ranks | analysis + 1st factorisation [ms] | factorisation [ms] | solve, 2 columns [ms] | MUMPS Mflop per factorisation |"
        echo "|---|---|---|---|---|---|---|"
    } | tee -a "$out"
    for nx in 40 80; do
        for np in 1 2; do
            if [ $np = 1 ]; then o=$("$fac" $nx 10); else o=$(sh tools/mpirun.sh 2 "$fac" $nx 10); fi
            printf '%s\n' "$o" | awk '{ for (i = 2; i <= NF; i++) { split($i, kv, "="); v[kv[1]] = kv[2] }
                printf "| %s | %s | %s | %s | %s | %s | %s |\n", $1, v["N"], v["ranks"], v["first_ms"], v["factor_ms"], v["solve2_ms"], v["mflops"] }' | tee -a "$out"
        done
    done
fi
echo "  load average after: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$out"
