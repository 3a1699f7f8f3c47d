# pscbranch: build, test, demo, examples, benchmarks.
#   make test    build everything with strict warnings and run the suite
#   make demo    run the main demo
#   make asan / make ubsan   the suite under AddressSanitizer / UndefinedBehaviorSanitizer
CC ?= cc
CXX ?= c++
LAPACK_LIBS ?= -llapack -lblas
WARN = -std=c99 -Wall -Wextra -Wpedantic -Werror
OPT ?= -O2
CFLAGS ?=
SAN ?=
ALL_CFLAGS = $(WARN) $(OPT) $(SAN) -I. $(CFLAGS)
LIBS = $(LAPACK_LIBS) -lm
SHARED ?= ../shared
BUILD ?= build

HEADER = pscbranch.h
TESTS = $(BUILD)/test_core $(BUILD)/test_linear $(BUILD)/test_linear_dgbtrf $(BUILD)/test_linear_nosimd \
	$(BUILD)/test_contact $(BUILD)/test_fc_solve \
	$(BUILD)/test_fe $(BUILD)/test_linkage $(BUILD)/test_static
EXAMPLES = examples/01_branching examples/fc_solve examples/block examples/triangle

.PHONY: all test demo examples bench asan ubsan fuzz clean

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

$(BUILD)/test_contact: tests/test_contact.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_contact.c -o $@ $(LIBS)

$(BUILD)/test_fc_solve: tests/test_fc_solve.c tests/fc_gen.h tests/harness.h examples/fc_solve.c $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) $(FC_HDF5_CFLAGS) -Itests tests/test_fc_solve.c -o $@ $(FC_HDF5_LIBS) $(LIBS)

$(BUILD)/test_fe: tests/test_fe.c tests/harness.h examples/fe.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_fe.c -o $@ $(LIBS)

$(BUILD)/test_static: tests/test_static.c tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -Itests tests/test_static.c -o $@ $(LIBS)

$(BUILD)/linkage_impl.o: tests/linkage_impl.cpp $(HEADER) | $(BUILD)
	$(CXX) -Wall -Wextra -Wpedantic -Werror $(OPT) $(SAN) -c tests/linkage_impl.cpp -o $@

# a program with a C++ object links with the C++ driver: under AddressSanitizer g++ gives the
# C++-compiled implementation exception cleanups that need the C++ runtime
$(BUILD)/test_linkage: tests/test_linkage.c $(BUILD)/linkage_impl.o tests/harness.h $(HEADER) | $(BUILD)
	$(CC) $(ALL_CFLAGS) -c tests/test_linkage.c -o $(BUILD)/test_linkage.o
	$(CXX) $(OPT) $(SAN) $(BUILD)/test_linkage.o $(BUILD)/linkage_impl.o -o $@ $(LIBS)

examples/%: examples/%.c $(HEADER)
	$(CC) $(ALL_CFLAGS) $< -o $@ $(LIBS)

# fc_solve reads FCLib's HDF5 files too when HDF5 is installed (libhdf5-dev; HDF5= to build
# without); the library itself never depends on it
HDF5 ?= $(shell pkg-config --exists hdf5 2>/dev/null && echo yes)
ifeq ($(HDF5),yes)
FC_HDF5_CFLAGS = -DFC_SOLVE_HDF5 $(shell pkg-config --cflags hdf5)
FC_HDF5_LIBS = $(shell pkg-config --libs hdf5)
SMOKE_HDF5 = "smoke:examples/fc_solve $(SHARED)/fc-problems/harder/*.hdf5"
endif
examples/fc_solve: examples/fc_solve.c $(HEADER)
	$(CC) $(ALL_CFLAGS) $(FC_HDF5_CFLAGS) $< -o $@ $(FC_HDF5_LIBS) $(LIBS)

examples/block examples/triangle: examples/fe.h

examples: $(EXAMPLES)

# each example exits non-zero when its result differs from the analytic or the papers' one
SMOKE = "smoke:examples/01_branching" \
	"smoke:examples/fc_solve $(SHARED)/fc-problems/*.dat" \
	"smoke:examples/fc_solve $(SHARED)/fc-problems/harder/*.dat" $(SMOKE_HDF5) \
	"smoke:examples/block" \
	"smoke:examples/block --mesh 20x40 --input 3 --ndir 50 --nspan 1 --paper-sweep --branch-mult-weight 1 --no-screen --expect-npc 72" \
	"smoke:examples/block --mesh 20x40 --input 3 --ndir 50 --nspan 1 --paper-sweep --branch-mult-weight 1" \
	"smoke:examples/block --mesh 5x10 --save $(BUILD)/ends_5x10.txt && examples/block --mesh 10x20 --refine $(BUILD)/ends_5x10.txt --compare $(BUILD)/ends_5x10.txt" \
	"smoke:examples/triangle --mesh 16" \
	"smoke:examples/triangle --mesh 16 --problem fold"

test: $(TESTS) $(EXAMPLES)
	@bash tests/run.sh $(TESTS) $(SMOKE)

demo: examples/01_branching examples/block
	@mkdir -p out/block
	./examples/01_branching --out out
	./examples/block --out out/block
	@if command -v gnuplot >/dev/null 2>&1; then \
	  (cd out/block && gnuplot plot.gp) && echo "plots: out/block/*.png"; \
	else echo "gnuplot not installed (apt-get install gnuplot-nox): plot data and script are in out/block"; fi

BENCH = bench/bench_linear bench/bench_branching

bench/%: bench/%.c $(HEADER) tests/pl_problems.h
	$(CC) $(ALL_CFLAGS) -D_POSIX_C_SOURCE=199309L $< -o $@ $(LIBS)

bench: $(BENCH) examples/block
	@mkdir -p bench/out
	./bench/bench_linear --csv bench/out/linear.csv
	./bench/bench_branching --csv bench/out/branching.csv
	bash bench/bench_block.sh

asan:
	$(MAKE) BUILD=build-asan OPT="-O1 -g" SAN="-fsanitize=address -fno-omit-frame-pointer" EXAMPLES= SMOKE= test

ubsan:
	$(MAKE) BUILD=build-ubsan OPT="-O1 -g" SAN="-fsanitize=undefined -fno-sanitize-recover=all" EXAMPLES= SMOKE= test

# libFuzzer targets (clang, ASan + UBSan): every fuzz/fuzz_NAME.c is built into build-fuzz/ and
# run for FUZZ_SECONDS on a scratch copy of its seed corpus fuzz/corpus/NAME/ (the runs never
# grow the repository); any crash, sanitizer report, leak or timeout fails the target. See
# fuzz/README.md. The fc_hdf5 target needs HDF5 (left out without it).
FUZZ_SECONDS ?= 30
FUZZ_CC ?= clang
FUZZ_BUILD ?= build-fuzz
FUZZ_CFLAGS = -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all -I. -Itests
FUZZ_NAMES = $(filter-out $(if $(FC_HDF5_CFLAGS),,fc_hdf5),$(patsubst fuzz/fuzz_%.c,%,$(wildcard fuzz/fuzz_*.c)))
$(FUZZ_BUILD)/fuzz_fc_hdf5: FUZZ_EXTRA_CFLAGS = $(FC_HDF5_CFLAGS)
$(FUZZ_BUILD)/fuzz_fc_hdf5: FUZZ_EXTRA_LIBS = $(FC_HDF5_LIBS)

$(FUZZ_BUILD)/fuzz_%: fuzz/fuzz_%.c $(HEADER) $(wildcard fuzz/*.h examples/*.c examples/*.h tests/*.h)
	@mkdir -p $(FUZZ_BUILD)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(FUZZ_EXTRA_CFLAGS) $< -o $@ $(FUZZ_EXTRA_LIBS) $(LIBS)

fuzz: $(patsubst %,$(FUZZ_BUILD)/fuzz_%,$(FUZZ_NAMES))
	@set -e; for n in $(FUZZ_NAMES); do \
	  rm -rf $(FUZZ_BUILD)/corpus-$$n; mkdir -p $(FUZZ_BUILD)/corpus-$$n; \
	  if [ -d fuzz/corpus/$$n ]; then cp -R fuzz/corpus/$$n/. $(FUZZ_BUILD)/corpus-$$n/; fi; \
	  echo "fuzz_$$n: $(FUZZ_SECONDS) s"; \
	  $(FUZZ_BUILD)/fuzz_$$n -max_total_time=$(FUZZ_SECONDS) -timeout=10 -print_final_stats=1 \
	    -artifact_prefix=$(FUZZ_BUILD)/$$n- $(FUZZ_BUILD)/corpus-$$n \
	    > $(FUZZ_BUILD)/$$n.log 2>&1 || { tail -n 60 $(FUZZ_BUILD)/$$n.log; \
	    echo "fuzz_$$n: FINDING (log $(FUZZ_BUILD)/$$n.log, input $(FUZZ_BUILD)/$$n-*)"; exit 1; }; \
	  grep -E '^stat::number_of_executed_units|^stat::peak_rss_mb' $(FUZZ_BUILD)/$$n.log; \
	done

clean:
	rm -rf build build-asan build-ubsan out bench/out $(EXAMPLES) $(BENCH)
