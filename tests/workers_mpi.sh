#!/usr/bin/env bash
# fe/block with Algorithm 2.2 on 1, 2 and 4 MPI ranks (--workers mpi, tools/mpirun.sh): rank 0's
# output is --workers 1's but for timings and the workers line. Usage: tests/workers_mpi.sh ARGS...
set -u
cd "$(dirname "$0")/.."
mask() { sed -E 's/[0-9.]+ s \(CPU\)/X s (CPU)/; /^  Algorithm 2.2 on /d'; }
first=$(fe/block --quiet --workers 1 "$@" 2>&1 | mask)
for np in 1 2 4; do
    other=$(sh tools/mpirun.sh "$np" fe/block --quiet --workers mpi "$@" 2>&1 | mask)
    if [ "$other" != "$first" ]; then
        echo "workers_mpi: $np ranks differ from --workers 1:"
        diff <(printf '%s\n' "$first") <(printf '%s\n' "$other") | head -n 20
        exit 1
    fi
done
printf '%s\n' "$first" | grep -q 'OK' || { printf '%s\n' "$first"; exit 1; }
