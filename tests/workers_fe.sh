#!/usr/bin/env bash
# An FE program with Algorithm 2.2 on workers: the same output, but for timings and the workers
# lines, on 1, 2 and 4 threads and 4 logical workers, or with --mpi on 1, 2 and 4 MPI
# ranks (tools/mpirun.sh), as on 1 thread. Usage: tests/workers_fe.sh [--mpi] PROGRAM ARGS...
set -u
cd "$(dirname "$0")/.."
mpi=0
# mpirun binds each rank to a core, where a threaded BLAS runs on one thread and may round
# otherwise than on two: every run here gets one BLAS thread, so that only the workers differ
if [ "${1:-}" = --mpi ]; then mpi=1; shift; export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1; fi
out() { "$@" --quiet 2>&1 | sed -E 's/[0-9.]+ s \(CPU\)/X s (CPU)/; /^  Algorithm 2.2 on /d; s/; on [0-9]+ logical workers.*//'; }
first=$(out "$@" --workers 1) || { printf '%s\n' "$first"; exit 1; }
runs=("2" "4" "4 --logical")
[ "$mpi" = 1 ] && runs=("1" "2" "4")
for w in "${runs[@]}"; do
    if [ "$mpi" = 1 ]; then other=$(out sh tools/mpirun.sh "$w" "$@" --workers mpi); else other=$(out "$@" --workers $w); fi
    if [ "$other" != "$first" ]; then
        echo "workers_fe: $* on $w $([ "$mpi" = 1 ] && echo ranks || echo workers) differs from --workers 1:"
        diff <(printf '%s\n' "$first") <(printf '%s\n' "$other") | head -n 20
        exit 1
    fi
done
printf '%s\n' "$first" | grep -q 'OK' || { printf '%s\n' "$first"; exit 1; }
