#!/bin/sh
# tools/mpirun.sh NP CMD [ARGS...]: CMD on NP MPI ranks of this machine, as the tests and the
# benchmarks run it. Open MPI needs to be told that root may run it (containers, CI), that a rank
# may share a core (--oversubscribe: 2 ranks on a loaded 2-core machine), that idle ranks yield
# the core (they poll otherwise: M200's 2-rank run took 32 s instead of 15), and to use no
# cross-memory attach (refused in many containers). Other MPIs get plain `mpirun -np NP`.
np=$1
shift
if mpirun --version 2>/dev/null | grep -q "Open MPI"; then
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
    OMPI_MCA_mpi_yield_when_idle=1 exec mpirun --oversubscribe -np "$np" "$@"
fi
exec mpirun -np "$np" "$@"
