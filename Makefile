# pscbranch: build, test, demo, examples, benchmarks, install.
#   make test      check what the build needs (tools/deps.sh: installs it with apt-get when it can,
#                  else says what to run), build everything with strict warnings, run the suite
#   make check     the same without the dependency step
#   make demo      run the main demo and draw its pictures (gnuplot, installed like the rest)
#   make examples  every program: the teaching examples (examples/), the FE applications (fe/)
#                  and the frictional-contact solver (fc_solve/)
#   make asan / make ubsan   the suite under AddressSanitizer / UndefinedBehaviorSanitizer
#   make tsan      Algorithm 2.2 on threads (tests/test_workers.c) under ThreadSanitizer
#   make bench     the benchmarks (bench/out/), with GetFEM side by side when python3-getfem is there
#                  (bash bench/bench_mumps.sh --large: banded against MUMPS on 1 and 2 ranks up to M12800)
#   make fuzz [FUZZ_SECONDS=30 | FUZZ_RUNS=N [FUZZ_SEED=1]]   every libFuzzer target in fuzz/
#                  for a time, or for N runs from a fixed seed (clang; see fuzz/README.md)
#   make images    the README's pictures in docs/img/ (docs/make_images.sh)
#   make install PREFIX=/usr/local [DESTDIR=...]   the header, pscbranch.pc, the CMake package
#                  (find_package(pscbranch)), the docs and the programs' sources
#   make uninstall PREFIX=... [DESTDIR=...]        removes what install put there
#   (bash tests/packaging.sh checks install with pkg-config and CMake consumers; CI: .ci/run)
#   make bench-large   the long benchmarks: block M12800 per backend and on 1 and 2 workers,
#                  triangle fold studies
# LAPACK_LIBS chooses the LAPACK/BLAS (default -llapack -lblas); HDF5= builds fc_solve without
# HDF5 even when libhdf5-dev is installed; SUITESPARSE= builds the FE applications without
# SuiteSparse; MUMPS= and MUMPS_SEQ= leave MUMPS out (below).
CC ?= cc
CXX ?= c++
LAPACK_LIBS ?= -llapack -lblas
WARN = -std=c99 -Wall -Wextra -Wpedantic -Werror
OPT ?= -O2
CFLAGS ?=
SAN ?=
ALL_CFLAGS = $(WARN) $(OPT) $(SAN) -I. $(CFLAGS)
LIBS = $(LAPACK_LIBS) -lm
DATA = fc_solve/data
BUILD ?= build
# checks (and installs) what a target needs, silently when all is there: see tools/deps.sh
DEPS = CC="$(CC)" CXX="$(CXX)" LAPACK_LIBS="$(LAPACK_LIBS)" sh tools/deps.sh

HEADER = pscbranch.h
TESTS = $(BUILD)/test_core $(BUILD)/test_linear $(BUILD)/test_linear_dgbtrf $(BUILD)/test_linear_nosimd \
	$(BUILD)/test_contact $(BUILD)/test_fc_solve $(BUILD)/test_detect $(BUILD)/test_faults \
	$(BUILD)/test_fe $(BUILD)/test_linkage $(BUILD)/test_static $(BUILD)/test_quasistatic $(BUILD)/test_explore \
	$(BUILD)/test_diagram $(BUILD)/test_fold_map $(BUILD)/test_count_map \
	$(BUILD)/test_event_curve $(BUILD)/test_branch_curve $(BUILD)/test_workers $(SPARSE_TESTS)
# the teaching examples (examples/NN_name.c, each one file on pscbranch.h alone) and the applications
TEACHING = $(patsubst %.c,%,$(sort $(wildcard examples/[0-9][0-9]_*.c)))
APPS = fe/block fe/triangle fe/quasistatic fc_solve/fc_solve
EXAMPLES = $(TEACHING) $(APPS)

.PHONY: all test check demo demo-run examples bench bench-large asan ubsan tsan fuzz fuzz-run install uninstall clean \
	quasistatic-demo quasistatic-demo-run images images-run

all: $(TESTS) $(EXAMPLES)

$(BUILD):
	mkdir -p $(BUILD)

$(BUILD)/test_core: tests/test_core.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_core.c -o $@ $(LIBS)

$(BUILD)/test_linear: tests/test_linear.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_linear.c -o $@ $(LIBS)

# the banded backend again with LAPACK's dgbtrf, and with the banded LU's scalar loops
$(BUILD)/test_linear_dgbtrf: tests/test_linear.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -DPSCBRANCH_USE_DGBTRF -Itests tests/test_linear.c -o $@ $(LIBS)

$(BUILD)/test_linear_nosimd: tests/test_linear.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -DPSCBRANCH_NO_SIMD -Itests tests/test_linear.c -o $@ $(LIBS)

$(BUILD)/test_detect: tests/test_detect.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_detect.c -o $@ $(LIBS)

# fault injection and misuse (issue 20); its allocator replaces PSCBRANCH_MALLOC. The public
# API's libFuzzer target is fuzz/fuzz_api.c (seeds in fuzz/corpus/api/), built by `make fuzz`
$(BUILD)/test_faults: tests/test_faults.c tests/harness.h tests/pl_problems.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_faults.c -o $@ $(LIBS)

$(BUILD)/test_contact: tests/test_contact.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_contact.c -o $@ $(LIBS)

$(BUILD)/test_fc_solve: fc_solve/tests/test_fc_solve.c fc_solve/tests/fc_gen.h tests/harness.h fc_solve/fc_solve.c \
		$(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) $(FC_HDF5_CFLAGS) -Itests fc_solve/tests/test_fc_solve.c -o $@ $(FC_HDF5_LIBS) $(LIBS)

$(BUILD)/test_fe: fe/tests/test_fe.c tests/harness.h fe/fe.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests fe/tests/test_fe.c -o $@ $(LIBS)

$(BUILD)/test_explore: tests/test_explore.c tests/harness.h tests/pl_problems.h tests/kink_curves.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_explore.c -o $@ $(LIBS)

$(BUILD)/test_diagram: tests/test_diagram.c tests/harness.h tests/pl_problems.h tests/kink_curves.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_diagram.c -o $@ $(LIBS)

# Algorithm 2.2 on workers: POSIX threads and logical workers (contrib/psb_workers.h)
$(BUILD)/test_workers: tests/test_workers.c tests/harness.h tests/pl_problems.h contrib/psb_workers.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_workers.c -o $@ $(LIBS) -pthread

$(BUILD)/test_fold_map: tests/test_fold_map.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_fold_map.c -o $@ $(LIBS)
$(BUILD)/test_count_map: tests/test_count_map.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_count_map.c -o $@ $(LIBS)
$(BUILD)/test_event_curve: tests/test_event_curve.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_event_curve.c -o $@ $(LIBS)
$(BUILD)/test_branch_curve: tests/test_branch_curve.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_branch_curve.c -o $@ $(LIBS)

$(BUILD)/test_static: tests/test_static.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_static.c -o $@ $(LIBS)

$(BUILD)/test_quasistatic: tests/test_quasistatic.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_quasistatic.c -o $@ $(LIBS)

$(BUILD)/linkage_impl.o: tests/linkage_impl.cpp $(HEADER) | $(BUILD)
	$(CXX) -std=c++11 -Wall -Wextra -Wpedantic -Werror $(OPT) $(SAN) -c tests/linkage_impl.cpp -o $@

# a program with a C++ object links with the C++ driver: under AddressSanitizer g++ gives the
# C++-compiled implementation exception cleanups that need the C++ runtime
$(BUILD)/test_linkage: tests/test_linkage.c $(BUILD)/linkage_impl.o tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -c tests/test_linkage.c -o $(BUILD)/test_linkage.o
	$(CXX) $(OPT) $(SAN) $(BUILD)/test_linkage.o $(BUILD)/linkage_impl.o -o $@ $(LIBS)

# a user's program (tests/packaging.sh builds it against an installed copy): includes <pscbranch.h>
$(BUILD)/consumer: tests/consumer/consumer.c $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) tests/consumer/consumer.c -o $@ $(LIBS)

examples/%: examples/%.c $(HEADER)
	$(CC) $(ALL_CFLAGS) $< -o $@ $(LIBS)

# fc_solve reads FCLib's HDF5 files too when HDF5 is installed (libhdf5-dev; HDF5= to build
# without); the library itself never depends on it. The stamp rebuilds fc_solve when that changes.
HDF5 ?= $(shell pkg-config --exists hdf5 2>/dev/null && echo yes)
ifeq ($(HDF5),yes)
FC_HDF5_CFLAGS = -DFC_SOLVE_HDF5 $(shell pkg-config --cflags hdf5)
FC_HDF5_LIBS = $(shell pkg-config --libs hdf5)
SMOKE_HDF5 = "smoke:fc_solve/fc_solve $(DATA)/fc-problems/harder/*.hdf5"
endif
$(BUILD)/fc_solve-hdf5-$(HDF5): | $(BUILD)
	rm -f $(BUILD)/fc_solve-hdf5-*
	touch $@
fc_solve/fc_solve: fc_solve/fc_solve.c fe/cli.h $(HEADER) $(BUILD)/fc_solve-hdf5-$(HDF5)
	$(CC) $(ALL_CFLAGS) $(FC_HDF5_CFLAGS) $< -o $@ $(FC_HDF5_LIBS) $(LIBS)

# MUMPS (contrib/psb_mumps.h), optional: with MPI (libmumps-dev, libopenmpi-dev: pkg-config mpi-c)
# fe/block is built with -DFE_MUMPS (--solver mumps; MPI starts only then) and test_mumps
# runs on 1 rank and, with mpirun, on 2 (tools/mpirun.sh); with the sequential library
# (libmumps-seq-dev) test_mumps_seq. Each is detected by linking a probe, and left out when absent.
MPI_CFLAGS := $(shell pkg-config --cflags mpi-c 2>/dev/null)
MPI_LIBS := $(shell pkg-config --libs mpi-c 2>/dev/null)
MUMPS_LIBS = -ldmumps -lmumps_common $(MPI_LIBS)
MUMPS_SEQ_CFLAGS = -DPSB_MUMPS_SEQ -isystem /usr/include/mumps_seq
MUMPS_SEQ_LIBS = -ldmumps_seq
MUMPS_PROBE = printf '\043include <mpi.h>\n\043include <dmumps_c.h>\nint main(void) { DMUMPS_STRUC_C id; id.job = -1; dmumps_c(&id); return 0; }\n' | \
	$(CC) -x c - -o /dev/null
MUMPS ?= $(shell pkg-config --exists mpi-c 2>/dev/null && $(MUMPS_PROBE) $(MPI_CFLAGS) $(MUMPS_LIBS) $(LIBS) >/dev/null 2>&1 && echo yes)
MUMPS_SEQ ?= $(shell $(MUMPS_PROBE) $(MUMPS_SEQ_CFLAGS) $(MUMPS_SEQ_LIBS) $(LIBS) >/dev/null 2>&1 && echo yes)
MPIRUN ?= $(shell command -v mpirun 2>/dev/null)
# MPI alone (libopenmpi-dev): fe/block and fe/triangle are built with -DFE_MPI (--workers mpi;
# MPI starts only then)
MPI_PROBE = printf '\043include <mpi.h>\nint main(void) { int f = 0; return MPI_Initialized(&f); }\n' | \
	$(CC) -x c - -o /dev/null
MPI ?= $(shell pkg-config --exists mpi-c 2>/dev/null && $(MPI_PROBE) $(MPI_CFLAGS) $(MPI_LIBS) >/dev/null 2>&1 && echo yes)
ifeq ($(MPI),yes)
FE_MPI_CFLAGS = -DFE_MPI $(MPI_CFLAGS)
FE_MPI_LIBS = $(MPI_LIBS)
ifneq ($(MPIRUN),)
# Algorithm 2.2 on 1, 2, 4 MPI ranks (contrib/psb_workers_mpi.h): tests/test_workers.c's
# outcomes, and the programs' --workers mpi
TESTS += $(BUILD)/test_workers_mpi_np1 $(BUILD)/test_workers_mpi_np2 $(BUILD)/test_workers_mpi_np4
SMOKE_MPI = "smoke:bash tests/workers_fe.sh --mpi fe/block" "smoke:bash tests/workers_fe.sh --mpi fe/block --explore" \
	"smoke:bash tests/workers_fe.sh --mpi fe/triangle --mesh 16"
endif
endif
$(BUILD)/fe-mpi-$(MPI): | $(BUILD)
	rm -f $(BUILD)/fe-mpi-*
	touch $@
$(BUILD)/test_workers_mpi: tests/test_workers.c tests/harness.h tests/pl_problems.h contrib/psb_workers.h \
		contrib/psb_workers_mpi.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -DTEST_WORKERS_MPI $(MPI_CFLAGS) -Itests tests/test_workers.c -o $@ $(MPI_LIBS) $(LIBS) -pthread
# the same program on K ranks: a script, so that tests/run.sh reads its RESULT line; one BLAS
# thread on every rank, as a rank bound to a core has (tests/workers_fe.sh)
$(BUILD)/test_workers_mpi_np%: $(BUILD)/test_workers_mpi tools/mpirun.sh
	printf '#!/bin/sh\nOPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 exec sh tools/mpirun.sh $* %s\n' \
		$(BUILD)/test_workers_mpi > $@
	chmod +x $@
ifeq ($(MUMPS),yes)
BLOCK_CFLAGS = -DFE_MUMPS $(MPI_CFLAGS)
BLOCK_LIBS = $(MUMPS_LIBS)
TESTS += $(BUILD)/test_mumps
SMOKE_MUMPS = "smoke:bash tests/mumps_ends.sh fe/block"
ifneq ($(MPIRUN),)
TESTS += $(BUILD)/test_mumps_np2
endif
endif
ifeq ($(MUMPS_SEQ),yes)
TESTS += $(BUILD)/test_mumps_seq
endif
$(BUILD)/block-mumps-$(MUMPS): | $(BUILD)
	rm -f $(BUILD)/block-mumps-*
	touch $@

$(BUILD)/test_mumps: tests/test_mumps.c contrib/psb_mumps.h tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) $(MPI_CFLAGS) -Itests tests/test_mumps.c -o $@ $(MUMPS_LIBS) $(LIBS)

# the same program on 2 ranks: a script, so that tests/run.sh reads its RESULT line
$(BUILD)/test_mumps_np2: $(BUILD)/test_mumps tools/mpirun.sh
	printf '#!/bin/sh\nexec sh tools/mpirun.sh 2 %s\n' $(BUILD)/test_mumps > $@
	chmod +x $@

$(BUILD)/test_mumps_seq: tests/test_mumps.c contrib/psb_mumps.h tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) $(MUMPS_SEQ_CFLAGS) -Itests tests/test_mumps.c -o $@ $(MUMPS_SEQ_LIBS) $(LIBS)


# The sparse direct solvers of contrib/psb_sparse.h (UMFPACK, KLU) when SuiteSparse is installed
# (libsuitesparse-dev): fe/block and fe/triangle then take --solver umfpack|klu (and the triangle
# contrib/psb_condense.h's --solver condensed, its default on small meshes), and build/test_sparse
# joins the suite. The library itself never depends on it. The stamp rebuilds when that changes.
SUITESPARSE_INC ?= /usr/include/suitesparse
SUITESPARSE ?= $(shell test -f $(SUITESPARSE_INC)/umfpack.h && test -f $(SUITESPARSE_INC)/klu.h && echo yes)
ifeq ($(SUITESPARSE),yes)
SS_CFLAGS = -DFE_SUITESPARSE -I$(SUITESPARSE_INC)
SS_LIBS = -lumfpack -lklu
SPARSE_TESTS = $(BUILD)/test_sparse
SMOKE_SPARSE = "smoke:fe/block --solver umfpack" "smoke:fe/block --solver klu" \
	"smoke:fe/triangle --mesh 16 --solver umfpack" "smoke:fe/triangle --mesh 16 --problem fold --solver klu" \
	"smoke:fe/triangle --mesh 16 --solver banded" "smoke:fe/triangle --mesh 16 --problem fold --solver banded"
endif
$(BUILD)/suitesparse-$(SUITESPARSE): | $(BUILD)
	rm -f $(BUILD)/suitesparse-*
	touch $@
fe/block fe/triangle: fe/%: fe/%.c $(HEADER) fe/fe.h fe/explore_out.h fe/cli.h fe/fe_solvers.h fe/fe_workers.h \
		contrib/psb_sparse.h contrib/psb_condense.h contrib/psb_workers.h contrib/psb_workers_mpi.h \
		$(BUILD)/suitesparse-$(SUITESPARSE) $(BUILD)/fe-mpi-$(MPI)
	$(CC) $(ALL_CFLAGS) $(SS_CFLAGS) $(FE_MPI_CFLAGS) $(if $(filter fe/block,$@),$(BLOCK_CFLAGS)) $< -o $@ $(SS_LIBS) \
		$(if $(filter fe/block,$@),$(BLOCK_LIBS)) $(FE_MPI_LIBS) $(LIBS) -pthread
fe/block: fe/fe_mumps.h contrib/psb_mumps.h $(BUILD)/block-mumps-$(MUMPS)

$(BUILD)/test_sparse: tests/test_sparse.c tests/condense_decl.c tests/harness.h contrib/psb_sparse.h contrib/psb_condense.h \
		fe/fe.h $(HEADER) $(BUILD)/contrib_cxx.o | $(BUILD)
	$(CC) $(ALL_CFLAGS) $(SS_CFLAGS) -Itests tests/test_sparse.c tests/condense_decl.c -o $@ $(SS_LIBS) $(LIBS)
# the contrib headers' implementations compile as C++ too (built, not linked)
$(BUILD)/contrib_cxx.o: tests/contrib_cxx.cpp contrib/psb_sparse.h contrib/psb_condense.h $(HEADER) | $(BUILD)
	$(CXX) -std=c++11 -Wall -Wextra -Wpedantic -Werror $(OPT) $(SAN) -I. $(SS_CFLAGS) -c tests/contrib_cxx.cpp -o $@
fe/quasistatic: fe/quasistatic.c fe/fe.h fe/cli.h $(HEADER)
	$(CC) $(ALL_CFLAGS) $< -o $@ $(LIBS)

examples: $(EXAMPLES)

# each program exits non-zero when its result differs from the analytic or the papers' one
SMOKE = "smoke:$(BUILD)/consumer" \
	$(patsubst %,"smoke:%",$(TEACHING)) \
	"smoke:fc_solve/fc_solve $(DATA)/fc-problems/*.dat" \
	"smoke:fc_solve/fc_solve $(DATA)/fc-problems/harder/*.dat" $(SMOKE_HDF5) \
	"smoke:fe/block" \
	"smoke:fe/block --mesh 20x40 --input 3 --ndir 50 --nspan 1 --paper-sweep --branch-mult-weight 1 --no-screen --expect-npc 72" \
	"smoke:fe/block --mesh 20x40 --input 3 --ndir 50 --nspan 1 --paper-sweep --branch-mult-weight 1" \
	"smoke:fe/block --mesh 5x10 --save $(BUILD)/ends_5x10.txt && fe/block --mesh 10x20 --refine $(BUILD)/ends_5x10.txt --compare $(BUILD)/ends_5x10.txt" \
	"smoke:fe/triangle --mesh 16" \
	"smoke:fe/triangle --mesh 16 --problem fold" \
	"smoke:fe/triangle --mesh 16 --problem fold --fold-trace end" \
	"smoke:fe/triangle --mesh 16 --problem fold --fold-stop-kink 8 > $(BUILD)/fold_meet8.txt && grep -q 'gamma = 0.4886.*gamma rising, a limit point' $(BUILD)/fold_meet8.txt" \
	"smoke:fe/triangle --mesh 16 --problem fold --fold-stop-kink 2 > $(BUILD)/fold_meet2.txt && grep -q 'monotone through it, not a limit point' $(BUILD)/fold_meet2.txt" \
	"smoke:fe/block --explore" \
	"smoke:fe/triangle --mesh 16 --explore" \
	"smoke:fe/triangle --mesh 16 --explore --problem fold" \
	"smoke:fe/triangle --mesh 16 --count-map 24:25.2 --count-samples 7 > $(BUILD)/count_map16.txt && grep -q 'four branches for H1 in (24.402769[0-9]*, 24.886268' $(BUILD)/count_map16.txt" \
	"smoke:bash tests/workers_fe.sh fe/block" "smoke:bash tests/workers_fe.sh fe/block --explore" \
	"smoke:bash tests/workers_fe.sh fe/triangle --mesh 16" \
	"smoke:fe/quasistatic --mesh 8 --dt 0.1" $(SMOKE_SPARSE) $(SMOKE_MUMPS) $(SMOKE_MPI) \
	"smoke:bash tests/cli.sh" \
	"smoke:bash tests/readme_program.sh"

# MKL's Intel threading layer beside libgomp (SuiteSparse's) computes wrong factors: every
# program run from here gets MKL's GNU layer unless one was chosen (fe/fe_solvers.h)
export MKL_THREADING_LAYER ?= GNU

# test and demo first see to their dependencies, then run make again: its variables (HDF5) then
# see what was just installed
test:
	@$(DEPS) cc cxx lapack 'hdf5?' 'suitesparse?'
	@$(MAKE) --no-print-directory check

check: $(TESTS) $(EXAMPLES) $(if $(SMOKE),$(BUILD)/consumer)
	@bash tests/run.sh $(TESTS) $(SMOKE)

demo:
	@$(DEPS) cc lapack gnuplot
	@$(MAKE) --no-print-directory demo-run

demo-run: examples/01_branching fe/block
	@mkdir -p out/block
	./examples/01_branching --out out
	./fe/block --out out/block
	cd out/block && gnuplot plot.gp
	@echo "plots: out/block/*.png"

# the quasi-static snap-through: CSV, VTK time series (evolution.pvd) and quasistatic.png
quasistatic-demo:
	@$(DEPS) cc lapack gnuplot
	@$(MAKE) --no-print-directory quasistatic-demo-run

quasistatic-demo-run: fe/quasistatic
	./fe/quasistatic --out out/quasistatic
	cd out/quasistatic && gnuplot plot.gp
	@echo "plot: out/quasistatic/quasistatic.png"

# the README's pictures (docs/img/*.png), remade from the examples
images:
	@$(DEPS) cc lapack gnuplot
	@$(MAKE) --no-print-directory images-run

images-run: $(EXAMPLES)
	sh docs/make_images.sh

BENCH = bench/bench_linear bench/bench_branching bench/bench_detect bench/bench_explore bench/bench_fold_map

bench/%: bench/%.c $(HEADER) tests/pl_problems.h bench/bench_time.h
	$(CC) $(ALL_CFLAGS) -D_POSIX_C_SOURCE=199309L $< -o $@ $(LIBS)

bench/bench_mumps_factor: bench/bench_mumps_factor.c bench/bench_time.h fe/fe_mumps.h contrib/psb_mumps.h fe/fe.h $(HEADER)
	$(CC) $(ALL_CFLAGS) $(MPI_CFLAGS) $< -o $@ $(MUMPS_LIBS) $(LIBS)

# the sparse solvers' factorisation times (bench_sparse) and whole runs per solver, with SuiteSparse
bench/bench_sparse: bench/bench_sparse.c bench/bench_time.h $(HEADER) fe/fe.h contrib/psb_sparse.h contrib/psb_condense.h
	$(CC) $(ALL_CFLAGS) -D_POSIX_C_SOURCE=199309L $(SS_CFLAGS) $< -o $@ $(SS_LIBS) $(LIBS)

bench: $(BENCH) fe/block fe/triangle examples/06_count_map $(if $(SS_LIBS),bench/bench_sparse) \
		$(if $(filter yes,$(MUMPS)),bench/bench_mumps_factor)
	@mkdir -p bench/out
	./bench/bench_linear --csv bench/out/linear.csv
	./bench/bench_branching --csv bench/out/branching.csv
	./bench/bench_detect --csv bench/out/detect.csv
	OPENBLAS_NUM_THREADS=1 ./bench/bench_explore --csv bench/out/explore.csv
	bash bench/bench_count_map.sh
	OPENBLAS_NUM_THREADS=1 ./bench/bench_fold_map --csv bench/out/fold_map.csv
	bash bench/bench_triangle_map.sh
	$(if $(SS_LIBS),./bench/bench_sparse --csv bench/out/sparse.csv && bash bench/bench_solvers.sh)
	bash bench/bench_block.sh
	bash bench/bench_workers.sh
	$(if $(filter yes,$(MUMPS)),bash bench/bench_mumps.sh,echo "bench_mumps: no MUMPS with MPI, skipped")
	REPEAT=1 bash bench/getfem_side_by_side.sh

# the long ones (an hour or more): factorisations up to block M12800 and triangle M16384, block
# M12800 and the triangle's M16384 fold study per solver
bench-large: fe/block fe/triangle $(if $(SS_LIBS),bench/bench_sparse)
	@mkdir -p bench/out
	$(if $(SS_LIBS),./bench/bench_sparse --large --csv bench/out/sparse_large.csv && bash bench/bench_solvers.sh --large,@echo "bench-large: needs SuiteSparse (libsuitesparse-dev)")
	$(if $(filter yes,$(MUMPS)),bash bench/bench_mumps.sh --large,@echo "bench-large: MUMPS with MPI not found, its runs skipped")
	bash bench/bench_workers.sh --large

# MUMPS= MPI= : Open MPI leaves its own allocations (~120 kB, none of ours) at MPI_Finalize,
# which LeakSanitizer reports; the sequential MUMPS build runs under AddressSanitizer instead
asan:
	@$(DEPS) cc cxx lapack
	$(MAKE) BUILD=build-asan OPT="-O1 -g" SAN="-fsanitize=address -fno-omit-frame-pointer" EXAMPLES= SMOKE= MUMPS= MPI= check

ubsan:
	@$(DEPS) cc cxx lapack
	$(MAKE) BUILD=build-ubsan OPT="-O1 -g" SAN="-fsanitize=undefined -fno-sanitize-recover=all" EXAMPLES= SMOKE= check

# the threaded runs of Algorithm 2.2 (tests/test_workers.c) under ThreadSanitizer
tsan:
	@$(DEPS) cc cxx lapack
	$(MAKE) BUILD=build-tsan OPT="-O1 -g" SAN="-fsanitize=thread" EXAMPLES= SMOKE= TESTS=build-tsan/test_workers check

# ---- install: header-only, so nothing is compiled; the version comes from the header ----------
PREFIX ?= /usr/local
DESTDIR ?=
INCLUDEDIR ?= $(PREFIX)/include
LIBDIR ?= $(PREFIX)/lib
PKGCONFIGDIR ?= $(LIBDIR)/pkgconfig
CMAKEDIR ?= $(LIBDIR)/cmake/pscbranch
DOCDIR ?= $(PREFIX)/share/doc/pscbranch
VERSION := $(shell awk '/^\#define PSCBRANCH_VERSION_(MAJOR|MINOR|PATCH) /{v = v (v == "" ? "" : ".") $$3} END{print v}' $(HEADER))
INSTALL ?= install
DOCS = README.md LICENSE CHANGELOG.md
# pages README.md links to, installed at the same place under DOCDIR
DOC_PAGES = fuzz/README.md fc_solve/data/README.md
# the programs' sources, one folder each as in the repository (their tests, fuzz targets and data stay here)
PROGRAM_DIRS = examples fe fc_solve
PROGRAM_SOURCES = $(foreach d,$(PROGRAM_DIRS),$(wildcard $(d)/*.c $(d)/*.h $(d)/README.md))
# the optional solvers' headers, beside the applications that include them as "contrib/..."
CONTRIB_SOURCES = $(wildcard contrib/*.h)
# @VAR@ in the templates (the same ones CMakeLists.txt fills in for cmake --install)
SUBST = sed -e 's|@PSCBRANCH_VERSION@|$(VERSION)|g' -e 's|@PSCBRANCH_PREFIX@|$(PREFIX)|g' \
	-e 's|@PSCBRANCH_INCLUDEDIR@|$(INCLUDEDIR)|g' -e 's|@PSCBRANCH_LAPACK_LIBS@|$(LAPACK_LIBS)|g'

install:
	@case "$(PREFIX)" in /*) ;; *) echo "PREFIX must be an absolute path: $(PREFIX)" >&2; exit 1;; esac
	@test -n "$(VERSION)" || { echo "no version in $(HEADER)" >&2; exit 1; }
	$(INSTALL) -d "$(DESTDIR)$(INCLUDEDIR)" "$(DESTDIR)$(PKGCONFIGDIR)" "$(DESTDIR)$(CMAKEDIR)" \
		$(foreach d,$(PROGRAM_DIRS),"$(DESTDIR)$(DOCDIR)/$(d)") "$(DESTDIR)$(DOCDIR)/contrib"
	$(INSTALL) -m 644 $(HEADER) "$(DESTDIR)$(INCLUDEDIR)/"
	$(SUBST) pscbranch.pc.in > "$(DESTDIR)$(PKGCONFIGDIR)/pscbranch.pc"
	$(SUBST) cmake/pscbranchConfig.cmake.in > "$(DESTDIR)$(CMAKEDIR)/pscbranchConfig.cmake"
	$(SUBST) cmake/pscbranchConfigVersion.cmake.in > "$(DESTDIR)$(CMAKEDIR)/pscbranchConfigVersion.cmake"
	$(INSTALL) -m 644 cmake/pscbranch-lapack.cmake "$(DESTDIR)$(CMAKEDIR)/"
	$(INSTALL) -m 644 $(wildcard $(DOCS)) "$(DESTDIR)$(DOCDIR)/"
	if [ -d docs ]; then cp -R docs "$(DESTDIR)$(DOCDIR)/" && chmod -R u+w,go+rX "$(DESTDIR)$(DOCDIR)/docs"; fi
	$(foreach d,$(PROGRAM_DIRS),$(INSTALL) -m 644 $(filter $(d)/%,$(PROGRAM_SOURCES)) "$(DESTDIR)$(DOCDIR)/$(d)/" &&) true
	$(INSTALL) -m 644 $(CONTRIB_SOURCES) "$(DESTDIR)$(DOCDIR)/contrib/"
	$(foreach f,$(DOC_PAGES),$(INSTALL) -d "$(DESTDIR)$(DOCDIR)/$(dir $(f))" && \
		$(INSTALL) -m 644 $(f) "$(DESTDIR)$(DOCDIR)/$(f)" &&) true
	@echo "installed pscbranch $(VERSION) in $(DESTDIR)$(PREFIX)"

CMAKE_FILES = pscbranchConfig.cmake pscbranchConfigVersion.cmake pscbranch-lapack.cmake

# removes the files install writes, then the directories that are ours and left empty
uninstall:
	rm -f "$(DESTDIR)$(INCLUDEDIR)/$(HEADER)" "$(DESTDIR)$(PKGCONFIGDIR)/pscbranch.pc"
	rm -f $(addprefix "$(DESTDIR)$(CMAKEDIR)/,$(addsuffix ",$(CMAKE_FILES)))
	rm -f $(addprefix "$(DESTDIR)$(DOCDIR)/,$(addsuffix ",$(DOCS)))
	rm -f $(addprefix "$(DESTDIR)$(DOCDIR)/,$(addsuffix ",$(PROGRAM_SOURCES)))
	rm -f $(addprefix "$(DESTDIR)$(DOCDIR)/contrib/,$(addsuffix ",$(notdir $(CONTRIB_SOURCES))))
	rm -rf "$(DESTDIR)$(DOCDIR)/docs"
	rm -f $(addprefix "$(DESTDIR)$(DOCDIR)/,$(addsuffix ",$(DOC_PAGES)))
	rmdir "$(DESTDIR)$(DOCDIR)/fuzz" "$(DESTDIR)$(DOCDIR)/fc_solve/data" 2>/dev/null || true
	rmdir "$(DESTDIR)$(CMAKEDIR)" $(foreach d,$(PROGRAM_DIRS),"$(DESTDIR)$(DOCDIR)/$(d)") "$(DESTDIR)$(DOCDIR)/contrib" \
		"$(DESTDIR)$(DOCDIR)" 2>/dev/null || true

# libFuzzer targets (clang, ASan + UBSan): a target lives beside what it fuzzes, in fuzz/ (the
# library), fe/fuzz/ or fc_solve/fuzz/. Every DIR/fuzz_NAME.c is built into build-fuzz/ and run for
# FUZZ_SECONDS on a scratch copy of its seed corpus DIR/corpus/NAME/ (the runs never grow the
# repository); any crash, sanitizer report, leak or timeout fails the target. See
# fuzz/README.md. The fc_hdf5 target needs HDF5 (left out without it).
FUZZ_SECONDS ?= 30
# FUZZ_RUNS=N: N executions from the fixed FUZZ_SEED instead, the same inputs at every run (CI's
# gate: a finding there is reproducible; open-ended searches are FUZZ_SECONDS runs)
FUZZ_RUNS ?=
FUZZ_SEED ?= 1
FUZZ_LIMIT = $(if $(FUZZ_RUNS),-runs=$(FUZZ_RUNS) -seed=$(FUZZ_SEED),-max_total_time=$(FUZZ_SECONDS))
FUZZ_CC ?= clang
FUZZ_BUILD ?= build-fuzz
# FUZZ_NO_CMP=1: without libFuzzer's comparison tracing; the sanitizers check the same and edge
# coverage still guides, at 3.4x the inputs a second for fuzz_api (long counting runs; see
# fuzz/README.md); the gate and `make fuzz` keep the full instrumentation
FUZZ_NO_CMP ?=
FUZZ_CFLAGS = -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. -Itests \
	$(if $(FUZZ_NO_CMP),-fno-sanitize-coverage=trace-cmp)
FUZZ_DIRS = fuzz fe/fuzz fc_solve/fuzz
FUZZ_SOURCES = $(filter-out $(if $(FC_HDF5_CFLAGS),,%/fuzz_fc_hdf5.c),$(wildcard $(addsuffix /fuzz_*.c,$(FUZZ_DIRS))))
FUZZ_NAMES = $(patsubst fuzz_%.c,%,$(notdir $(FUZZ_SOURCES)))
vpath fuzz_%.c $(FUZZ_DIRS)
# FUZZ_HDF5_IN_PROCESS=1: fuzz_fc_hdf5 reads without fc_solve's child process, 4x the inputs a
# second and the reader's coverage seen, but libhdf5's own faults stop the run (long counting
# runs; see fuzz/README.md); the gate and `make fuzz` keep the child, as fc_solve runs
FUZZ_HDF5_IN_PROCESS ?=
$(FUZZ_BUILD)/fuzz_fc_hdf5: FUZZ_EXTRA_CFLAGS = $(FC_HDF5_CFLAGS) $(if $(FUZZ_HDF5_IN_PROCESS),-DFC_HDF5_IN_PROCESS)
$(FUZZ_BUILD)/fuzz_fc_hdf5: FUZZ_EXTRA_LIBS = $(FC_HDF5_LIBS)

# the build's knobs as a stamp, so that changing one rebuilds the targets
FUZZ_STAMP = $(FUZZ_BUILD)/knobs-cmp$(if $(FUZZ_NO_CMP),0,1)-inproc$(if $(FUZZ_HDF5_IN_PROCESS),1,0)
$(FUZZ_STAMP):
	@mkdir -p $(FUZZ_BUILD)
	rm -f $(FUZZ_BUILD)/knobs-*
	touch $@

$(FUZZ_BUILD)/fuzz_%: fuzz_%.c $(HEADER) $(wildcard $(addsuffix /*.h,$(FUZZ_DIRS)) fe/*.h fc_solve/*.c tests/*.h) \
		$(FUZZ_STAMP)
	@mkdir -p $(FUZZ_BUILD)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(FUZZ_EXTRA_CFLAGS) $< -o $@ $(FUZZ_EXTRA_LIBS) $(LIBS)

fuzz:
	@$(DEPS) lapack fuzz 'hdf5?'
	@$(MAKE) --no-print-directory fuzz-run

fuzz-run: $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(FUZZ_NAMES))
	@set -e; for s in $(FUZZ_SOURCES); do \
	  n=$${s##*/fuzz_}; n=$${n%.c}; seeds=$${s%/*}/corpus/$$n; \
	  rm -rf $(FUZZ_BUILD)/corpus-$$n; mkdir -p $(FUZZ_BUILD)/corpus-$$n; \
	  if [ -d $$seeds ]; then cp -R $$seeds/. $(FUZZ_BUILD)/corpus-$$n/; fi; \
	  echo "fuzz_$$n: $(if $(FUZZ_RUNS),$(FUZZ_RUNS) runs from seed $(FUZZ_SEED),$(FUZZ_SECONDS) s)"; \
	  $(FUZZ_BUILD)/fuzz_$$n $(FUZZ_LIMIT) -timeout=10 -print_final_stats=1 \
	    -artifact_prefix=$(FUZZ_BUILD)/$$n- $(FUZZ_BUILD)/corpus-$$n \
	    > $(FUZZ_BUILD)/$$n.log 2>&1 || { tail -n 60 $(FUZZ_BUILD)/$$n.log; \
	    echo "fuzz_$$n: FINDING (log $(FUZZ_BUILD)/$$n.log, input $(FUZZ_BUILD)/$$n-*)"; exit 1; }; \
	  grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' $(FUZZ_BUILD)/$$n.log; \
	done

clean:
	rm -rf build build-asan build-ubsan build-fuzz out bench/out $(EXAMPLES) $(BENCH) bench/bench_mumps_factor \
		bench/bench_sparse
