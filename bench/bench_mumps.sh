#!/usr/bin/env bash
# bench_mumps.sh - whole runs of the block example (Section 3.2: approach, Algorithms 2.1-2.2,
# six branches traced to |gamma| = 1) with the banded backend, MUMPS on 1 rank and MUMPS on 2
# ranks (tools/mpirun.sh), side by side in one sitting: wall seconds (MPI start-up included),
# factorisations, MUMPS's memory, the six branches. M800 and M3200; --large adds M12800.
# OPENBLAS_NUM_THREADS=1 (one BLAS thread per rank: the ranks are the parallelism). The
# end points of the MUMPS runs are checked against the banded run's by tests/mumps_ends.sh.
# Table on stdout and in bench/out/mumps.md, CSV in bench/out/mumps.csv (run by `make bench`
# when examples/block is built with MUMPS). Usage: bench/bench_mumps.sh [--large]
set -u
cd "$(dirname "$0")/.."
meshes="20x40 40x80"
for a in "$@"; do
    case "$a" in --large) meshes="$meshes 80x160" ;; *) echo "usage: bench/bench_mumps.sh [--large]" >&2; exit 2 ;; esac
done
block=examples/block
[ -x "$block" ] || { echo "build examples/block first (make examples)"; exit 1; }
"$block" --solver mumps --help >/dev/null 2>&1 || { echo "bench_mumps: examples/block is built without MUMPS, skipped"; exit 0; }
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
    echo "| mesh | N | backend | wall [s] | factorisations | MUMPS MB (largest rank / all) | branches | vs banded |"
    echo "|---|---|---|---|---|---|---|---|"
} | tee "$out"
echo "mesh,n,backend,seconds,factorisations,mumps_mb_rank,mumps_mb_all,ok" >"$csv"
# run MESH BACKEND CMD...: wall time of CMD, its figures; sets $secs
run() {
    local mesh=$1 backend=$2 t0 t1 o n fact mb="-" ok=FAILED speed="-"
    shift 2
    t0=$(date +%s.%N)
    o=$("$@" --quiet --mesh "$mesh" 2>&1)
    t1=$(date +%s.%N)
    secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')
    n=$(printf '%s\n' "$o" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
    fact=$(printf '%s\n' "$o" | sed -n 's/.*distinct branches.*factorisations \([0-9]*\).*/\1/p')
    printf '%s\n' "$o" | grep -q 'block: OK (six branches' && ok=6
    if printf '%s\n' "$o" | grep -q 'MUMPS on'; then
        mb=$(printf '%s\n' "$o" | sed -n 's/.*memory \([0-9]*\) MB on the largest rank, \([0-9]*\) MB in all.*/\1 \/ \2/p')
    fi
    [ "$backend" != banded ] && speed=$(awk -v s="$secs" -v b="$banded" 'BEGIN { printf "%.2fx", b / s }')
    echo "| M$(( ${mesh%x*} * ${mesh#*x} )) | $n | $backend | $secs | $fact | $mb | $ok | $speed |" | tee -a "$out"
    echo "$mesh,$n,$backend,$secs,$fact,${mb%% /*},${mb##*/ },$ok" >>"$csv"
}
for mesh in $meshes; do
    run "$mesh" banded "$block"; banded=$secs
    run "$mesh" "MUMPS 1 rank" "$block" --solver mumps
    run "$mesh" "MUMPS 2 ranks" sh tools/mpirun.sh 2 "$block" --solver mumps
done
echo "  load average after: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$out"
