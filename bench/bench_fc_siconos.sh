#!/usr/bin/env bash
# fc_solve against Siconos numerics on KaplasTower-like stacks (bench/bench_fc_siconos.c), side by
# side in one process, one thread. Run by hand: bash bench/bench_fc_siconos.sh [LAYERS...]
# (default 16: 552 contacts). Needs libsiconos-numerics-dev (Debian: apt-get install
# libsiconos-numerics-dev); its code is linked, none of it is in this repository.
set -eu
cd "$(dirname "$0")/.."
if [ ! -e /usr/include/siconos/numerics/NonSmoothDrivers.h ]; then
    echo "bench_fc_siconos.sh: Siconos numerics is not installed (apt-get install libsiconos-numerics-dev)" >&2
    exit 1
fi
mkdir -p bench/out
CC=${CC:-cc}
$CC -std=c99 -O2 -Wall -Wno-unused-function -I. -I/usr/include/siconos bench/bench_fc_siconos.c -o bench/out/bench_fc_siconos \
    -lsiconos_numerics ${LAPACK_LIBS:--llapack -lblas} -lm
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
blas=$(ldd bench/out/bench_fc_siconos | awk '/libblas/ {print $3}' | head -n 1)
echo "BLAS: $(readlink -f "$blas" 2>/dev/null || echo unknown), 1 thread; $(uname -m), $(nproc) cores"
for layers in "${@:-16}"; do
    bench/out/bench_fc_siconos --layers "$layers" --repeat 3
done
