#!/usr/bin/env bash
# bench_solvers.sh - whole runs of the FE applications per linear solver (run by `make bench` when
# SuiteSparse is there): block M800 and M3200 with the banded LU, UMFPACK and KLU (the
# defaults otherwise: input branch 1, n_dir 20, n_span 15), triangle M4096 branching (banded,
# UMFPACK, condensed).
# --large: block M12800 (banded, UMFPACK) and triangle M16384 (fold study, with condensed too).
# Table on stdout, CSV in bench/out/solvers.csv. Set OPENBLAS_NUM_THREADS=1 with OpenBLAS.
set -u
cd "$(dirname "$0")/.."
mkdir -p bench/out
large=0
[ "${1:-}" = --large ] && large=1
echo "bench_solvers: whole runs per linear solver"
ldd fe/block | grep -E 'blas|lapack|umfpack|klu' | sed 's/^[[:space:]]*/  linked: /'
csv=bench/out/solvers$([ $large = 1 ] && echo _large).csv
echo "example,mesh,solver,n,seconds,factorisations,branches" >"$csv"
echo "  example   mesh     solver    N       time [s]   factorisations  branches / limit points"
run() { # example mesh solver args...
    local ex=$1 mesh=$2 solver=$3 out n secs fact nbr
    shift 3
    out=$(fe/$ex --quiet --mesh "$mesh" --solver "$solver" "$@" 2>&1)
    n=$(printf '%s\n' "$out" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
    secs=$(printf '%s\n' "$out" | sed -n 's/.*time \([0-9.]*\) s.*/\1/p' | tail -n 1)
    fact=$(printf '%s\n' "$out" | sed -n 's/.*, factorisations \([0-9][0-9]*\),.*/\1/p' | head -n 1)
    nbr=$(printf '%s\n' "$out" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p; s/.*limit points (gamma): \(.*\)/\1/p' | tail -n 1)
    printf '  %-9s %-8s %-9s %-7s %-10s %-15s %s\n' "$ex" "$mesh" "$solver" "$n" "$secs" "$fact" "$nbr"
    echo "$ex,$mesh,$solver,$n,$secs,$fact,$nbr" >>"$csv"
}
if [ $large = 0 ]; then
    for s in banded umfpack klu; do run block 20x40 $s; done
    for s in banded umfpack klu; do run block 40x80 $s; done
    for s in banded umfpack condensed; do run triangle 64 $s --load 26.4; done
else
    for s in banded umfpack; do run block 80x160 $s; done
    for s in banded umfpack condensed; do run triangle 128 $s --problem fold; done
fi
echo "  CSV: $csv"
