#!/usr/bin/env bash
# The programs' command lines (the teaching examples' own parsers, fe/cli.h for the applications):
# for every program, --help and -h print the usage on stdout and exit 0; malformed command lines
# exit 2 (usage errors) or 1 (a file that cannot be read or written) with a message on stderr
# naming the offending option or value, and never crash (exit status < 128). Ends with
# `N passed, M failed`; exit status 1 on any failure.
# The programs come from examples/, fe/ and fc_solve/ (built by `make examples`), or all from one
# folder $CLI_BIN, e.g. builds under AddressSanitizer and UndefinedBehaviorSanitizer, whose
# reports (leaks too) count as failures.
set -u
cd "$(dirname "$0")/.." || exit 1
# where PROG is built
where() {
    if [ -n "${CLI_BIN:-}" ]; then
        echo "$CLI_BIN/$1"
    else
        case $1 in
        [0-9][0-9]_*) echo "examples/$1" ;;
        fc_solve) echo fc_solve/fc_solve ;;
        *) echo "fe/$1" ;;
        esac
    fi
}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0

for prog in 01_branching 02_explore 03_pitchforks 04_evolution 06_count_map block triangle fc_solve quasistatic; do
    if [ ! -x "$(where "$prog")" ]; then
        echo "tests/cli.sh: $(where "$prog") is missing (make examples)"
        exit 1
    fi
done

pass() { passed=$((passed + 1)); }
fail() {
    failed=$((failed + 1))
    echo "FAIL $*"
}

# help PROG: --help and -h exit 0 with the usage on stdout and nothing on stderr
help() {
    local prog=$1 opt rc
    for opt in --help -h; do
        "$(where "$prog")" $opt >"$tmp/out" 2>"$tmp/err"
        rc=$?
        if [ $rc -eq 0 ] && grep -q "^usage: $prog" "$tmp/out" && grep -q -- '--' "$tmp/out" && [ ! -s "$tmp/err" ]; then
            pass
        else
            fail "$prog $opt: exit $rc, stdout: $(head -n 1 "$tmp/out"), stderr: $(head -n 1 "$tmp/err")"
        fi
    done
}

# expect RC TEXT PROG ARGS...: PROG ARGS exits RC and its stderr contains TEXT (fixed string)
expect() {
    local want=$1 text=$2 prog=$3 rc
    shift 3
    "$(where "$prog")" "$@" >"$tmp/out" 2>"$tmp/err"
    rc=$?
    if [ $rc -eq "$want" ] && grep -qF -- "$text" "$tmp/err"; then
        pass
    else
        fail "$prog $* (exit $rc, expected $want with '$text'): $(grep -v '^[a-z_0-9]*: \(building\|Newton\|continuation\|Algorithms\|tracing\|choosing\)' "$tmp/err" | head -n 2)"
    fi
    if [ $rc -ge 128 ]; then fail "$prog $*: killed by signal $((rc - 128))"; fi
    # under a sanitizer build (CLI_BIN): no report, leaks included, on any of these paths
    if grep -qE 'Sanitizer|runtime error:' "$tmp/err"; then fail "$prog $*: $(grep -m 1 -E 'Sanitizer|runtime error:' "$tmp/err")"; fi
}
usage() { expect 2 "$@"; }
fails() { expect 1 "$@"; }

for prog in 01_branching 02_explore 03_pitchforks 04_evolution 06_count_map block triangle fc_solve quasistatic; do help "$prog"; done

# end-point files for --refine: a hostile header (a heap overflow once), a missing file
printf 'fe-ends rect 40 80 65536 65536\n1 4295098369\n' >"$tmp/hostile.txt"
printf 'fe-ends rect 40 80 5 10\n1 66\nbranch 1 gamma 1\n0 0 0\n' >"$tmp/short.txt"
# valid files of a mesh the run's does not refine: Q1 in a P1 run, a finer triangle, 3x3 in 4x4
{ printf 'fe-ends rect 1 1 2 2\n1 9\nbranch 1 gamma 1\n'; for i in 1 2 3 4 5 6 7 8 9; do echo '0 0 0 0 0 0'; done; } >"$tmp/q1.txt"
{ printf 'fe-ends tri 1 16\n1 153\nbranch 1 gamma 1\n'; i=0; while [ $i -lt 153 ]; do echo '0 0 0 0 0 0'; i=$((i + 1)); done; } >"$tmp/tri16.txt"
{ printf 'fe-ends rect 40 80 3 3\n1 16\nbranch 1 gamma 1\n'; i=0; while [ $i -lt 16 ]; do echo '0 0 0 0 0 0'; i=$((i + 1)); done; } >"$tmp/rect3.txt"

# block
usage "unknown option '--bogus'" block --bogus
usage "see 'block --help'" block --bogus
usage "--mesh abc: expected NXxNY" block --mesh abc
usage "--mesh 10x20abc: expected NXxNY" block --mesh 10x20abc
usage "--mesh 65536x65536: NX and NY must be between 2 and 2048" block --mesh 65536x65536
usage "--mesh 1x5: NX and NY must be between 2" block --mesh 1x5
usage "--mesh -4x5" block --mesh=-4x5
usage "--mesh 99999999999999999999x2" block --mesh 99999999999999999999x2
usage "--mesh needs a value" block --mesh
usage "--mesh needs a value" block --mesh --verbose
usage "--ndir 0: must be between 1 and 10000" block --ndir 0
usage "--ndir 2147483648: must be between 1 and" block --ndir 2147483648
usage "--nspan abc: expected an integer" block --nspan abc
usage "--restart foo: expected one of mixed, paper, global" block --restart foo
usage "--dirichlet foo: expected one of mult, elim" block --dirichlet foo
usage "--solver condensed" block --solver condensed
usage "--seed abc: expected a non-negative integer" block --seed abc
usage "--seed -1: expected a non-negative integer" block --seed -1
usage "--seed 99999999999999999999: must be at most" block --seed 99999999999999999999
usage "--kappa nan: must be a finite number" block --kappa nan
usage "--kappa 0: must be > 0" block --kappa 0
usage "--hmin inf: must be a finite number" block --hmin inf
usage "--hmin 2: must be <= 1" block --hmin 2
usage "--input 7: must be between 0 and 6" block --input 7
usage "--start 0: expected one of -1, 1" block --start 0
usage "--maxiter 10x: expected an integer" block --maxiter 10x
usage "--expect-npc -5: must be between 0" block --expect-npc -5
usage "--mult-weight -1: must be > 0" block --mult-weight -1
usage "--verbose takes no value" block --verbose=yes
usage "--compare e: at most 4 files" block --compare a --compare b --compare c --compare d --compare e
usage "--out: empty value" block --out ''
usage "unexpected argument 'foo'" block foo
fails "hostile.txt: not a valid end-point file" block --quiet --refine "$tmp/hostile.txt"
fails "short.txt: not a valid end-point file" block --quiet --mesh 10x20 --refine "$tmp/short.txt"
fails "cannot read $tmp/none.txt" block --quiet --refine "$tmp/none.txt"
fails "/dev/full is not a directory" block --quiet --out /dev/full
# values the library would refuse only after the continuation: refused before it
usage "--hmin 1e-300: must be >= 1e-290" block --hmin 1e-300
usage "--hmin 1e-300: must be >= 1e-290" triangle --hmin 1e-300
usage "lies outside [1e-290, 1e290]" block --quiet --branch-mult-weight 1e-320
fails "cannot write /dev/full" block --quiet --mesh 5x10 --save /dev/full
fails "cannot write /dev/full" block --quiet --mesh 5x10 --compare "$tmp/short.txt" --save /dev/full
# an output file that cannot be opened inside a writable --out (a directory in its place)
mkdir -p "$tmp/o1/plot.gp" "$tmp/o2/folds.csv" "$tmp/o3/branches_01.csv" "$tmp/o4/branch_3.vtk" "$tmp/o5/marks.csv" \
    "$tmp/o6/diagram.json" "$tmp/o7/step_0003.vtu" "$tmp/o8/evolution.csv" "$tmp/o9/points.csv"
fails "cannot write $tmp/o1/plot.gp: Is a directory" block --quiet --mesh 5x10 --out "$tmp/o1"
fails "cannot write $tmp/o4/branch_3.vtk: Is a directory" block --quiet --mesh 5x10 --out "$tmp/o4"
fails "cannot write $tmp/o9/points.csv: Is a directory" block --quiet --explore --mesh 5x10 --out "$tmp/o9"
fails "cannot write $tmp/o5/marks.csv: Is a directory" block --quiet --explore --mesh 5x10 --out "$tmp/o5"

# triangle
usage "unknown option '--bogus'" triangle --bogus
usage "--mesh 100000: must be between 2 and 2048" triangle --mesh 100000
usage "--mesh 16x: expected an integer" triangle --mesh 16x
usage "--mesh 1: must be between 2" triangle --mesh 1
usage "--problem foo: expected one of branching, fold" triangle --problem foo
usage "--fold-trace both: expected one of auto, start, end" triangle --fold-trace both
usage "--fold-stop-kink" triangle --fold-stop-kink 0
usage "--load -3: must be > 0" triangle --load -3
usage "--load abc: expected a number" triangle --load abc
usage "--nspan 1001: must be between 1 and 1000" triangle --nspan 1001
usage "--refine needs --load" triangle --refine "$tmp/short.txt"
usage "--seed 12abc: expected a non-negative integer" triangle --seed 12abc
usage "--dirichlet foo: expected one of mult, elim" triangle --dirichlet foo
usage "--map needs --problem fold" triangle --map
usage "--map-min 2: must be below --map-max 1.95" triangle --problem fold --map --map-min 2
usage "--friction 0: must be > 0" triangle --friction 0
usage "--map-tol 0: must be >= 1e-12" triangle --problem fold --map --map-tol 0
usage "--count-map 3: give A:B" triangle --count-map 3
usage "--count-map 3:3: A equals B" triangle --count-map 3:3
usage "--count-map goes with the branching problem alone" triangle --count-map 24:25 --problem fold
usage "--count-map moves the load" triangle --count-map 24:25 --solver condensed
usage "--workers 0: must be between 1 and 64" triangle --workers 0
usage "--workers mpi2: expected an integer" triangle --workers mpi2
usage "--workers needs a value" triangle --workers
usage "--workers 65: must be between 1 and 64" block --workers 65
usage "unexpected argument 'x'" 06_count_map x
fails "/dev/full is not a directory" triangle --quiet --mesh 16 --problem fold --out /dev/full
fails "cannot write /dev/full" triangle --quiet --mesh 8 --problem branching --save /dev/full
fails "cannot write $tmp/o2/folds.csv: Is a directory" triangle --quiet --mesh 16 --problem fold --out "$tmp/o2"
fails "cannot write $tmp/o6/diagram.json: Is a directory" triangle --quiet --explore --mesh 8 --out "$tmp/o6"
fails "not a valid end-point file" triangle --quiet --mesh 8 --load 26 --refine "$tmp/hostile.txt"
fails "q1.txt: its mesh is not a coarser mesh nested in this one" triangle --quiet --mesh 8 --load 26 --refine "$tmp/q1.txt"
fails "tri16.txt: its mesh is not a coarser mesh nested in this one" triangle --quiet --mesh 8 --load 26 --refine "$tmp/tri16.txt"
fails "rect3.txt: its mesh is not a coarser mesh nested in this one" block --quiet --mesh 4x4 --refine "$tmp/rect3.txt"
mkdir -p "$tmp/o11/fold_map.csv"
fails "cannot write $tmp/o11/fold_map.csv: Is a directory" triangle --quiet --mesh 8 --problem fold --map --map-max 1.8 --map-tol 1e-3 --out "$tmp/o11"
# the fold map at M64 (--mesh 8): the limit points against the friction coefficient, its end (the two limit
# points merge at F = 1.6915) bracketed by two one-parameter runs 1e-5 apart and confirmed by
# them (two limit points, none), its files written
"$(where triangle)" --quiet --mesh 8 --problem fold --map --out "$tmp/map" >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -eq 0 ] && grep -q "snap-through exists for F in (1.69145[0-9], 1.950000)" "$tmp/out" &&
    grep -q "an end of the fold curves: the two limit points merge" "$tmp/out" &&
    grep -A2 "^  change at F = 1.6914" "$tmp/out" | grep -q "F = 1.69145[0-9]*: no limit point" &&
    grep -A2 "^  change at F = 1.6914" "$tmp/out" | grep -q "F = 1.69146[0-9]*: two limit points" &&
    [ "$(grep -c '^1\.[0-9]*,two,2,' "$tmp/map/fold_map.csv")" -ge 10 ] && [ -s "$tmp/map/fold_map_ends.csv" ] &&
    grep -q "fold_map.png" "$tmp/map/plot.gp" && ! grep -qE 'Sanitizer|runtime error:' "$tmp/err"; then
    pass
else
    fail "triangle --mesh 8 --problem fold --map: exit $rc, $(grep -E 'snap-through|FAILED' "$tmp/out" | head -n 2)"
fi
# --mesh 2: the default load's fold problem fails; the message must not blame a --load not given
fails "choosing the default load" triangle --quiet --mesh 2
if grep -qF -- "--load auto" "$tmp/err"; then fail "triangle --mesh 2 blames --load auto"; else pass; fi
fails "--load auto: the fold problem" triangle --quiet --mesh 2 --load auto

# fc_solve
usage "no problem FILE given" fc_solve
usage "unknown option '--bogus'" fc_solve --bogus x.dat
usage "--tol 0: must be > 0" fc_solve --tol 0 x.dat
usage "--tol abc: expected a number" fc_solve --tol abc x.dat
usage "--tol nan: must be a finite number" fc_solve --tol nan x.dat
usage "--maxit 0: must be between 1 and 10000000" fc_solve --maxit 0 x.dat
usage "--maxit 1e3: expected an integer" fc_solve --maxit 1e3 x.dat
usage "--tol needs a value" fc_solve x.dat --tol
# files it cannot read: exit 2 and the reason (the system's where it has one)
usage "cannot read $tmp: not a regular file" fc_solve "$tmp"
usage "cannot read $tmp/none.dat: cannot open the file: No such file or directory" fc_solve "$tmp/none.dat"
# not reduced problems: a Siconos global problem whose M passes as W, data after mu
printf '3 1 0 3 3 3 3  1 0 0 0 1 0 0 0 1  0 3 3 3 3  1 0 0 0 1 0 0 0 1  -1 -1 -1 0 0 0  0.1 0\n' >"$tmp/global.dat"
usage "cannot read $tmp/global.dat: a Siconos global problem" fc_solve "$tmp/global.dat"
printf '2 1 0 2 2 2 2  1 0 0 1  -1 0.3  0.5  7\n' >"$tmp/trailing.dat"
usage "cannot read $tmp/trailing.dat: data after mu" fc_solve "$tmp/trailing.dat"
# --solution: one problem FILE; a path it cannot write is refused before solving
usage "--solution takes one problem FILE, 2 given" fc_solve --solution "$tmp/s.txt" a.dat b.dat
usage "--solution needs a value" fc_solve fc_solve/data/fc-problems/FC3D_Example1.dat --solution
usage "cannot write /dev/full: No space left on device" fc_solve --quiet --solution /dev/full fc_solve/data/fc-problems/FC3D_Example1.dat
usage "cannot write $tmp/none/s.txt: No such file or directory" fc_solve --solution "$tmp/none/s.txt" fc_solve/data/fc-problems/FC3D_Example1.dat
usage "File name too long" fc_solve --solution "$tmp/$(printf '%*s' 300 '' | tr ' ' a)" fc_solve/data/fc-problems/FC3D_Example1.dat
# corrupted HDF5 files on which libhdf5 itself crashes (Debian 12's 1.10.8: SIGFPE in H5Dopen,
# SIGSEGV, heap corruption) are read errors (exit 2) of the file, not crashes of fc_solve (HDF5
# builds only; this script runs the builds without sanitizers)
if ! "$(where fc_solve)" fc_solve/fuzz/corpus/fc_hdf5/csc2d.hdf5 2>/dev/null | grep -q "not supported by this build"; then
    for f in fc_solve/fuzz/libhdf5_faults/*.hdf5; do
        "$(where fc_solve)" "$f" >"$tmp/out" 2>"$tmp/err"
        rc=$?
        if [ $rc -eq 2 ] && grep -q "^$f error: " "$tmp/out" &&
            ! grep -qE 'Sanitizer|runtime error:' "$tmp/err"; then
            pass
        else
            fail "fc_solve $f: exit $rc, $(head -n 1 "$tmp/out")"
        fi
    done
fi

# 01_branching
usage "unknown option '--bogus'" 01_branching --bogus
usage "--out needs a value" 01_branching --out
usage "unexpected argument 'extra'" 01_branching extra
fails "cannot create directory /dev/full/x" 01_branching --out /dev/full/x
fails "cannot write $tmp/o3/branches_01.csv: Is a directory" 01_branching --out "$tmp/o3"

# 02_explore, 03_pitchforks
usage "unknown option '--bogus'" 02_explore --bogus
usage "--out needs a value" 02_explore --out
usage "--out: empty value" 02_explore --out=
usage "unexpected argument 'extra'" 02_explore extra
fails "cannot create directory /dev/full/x" 02_explore --out /dev/full/x
fails "cannot write $tmp/o5/marks.csv: Is a directory" 02_explore --out "$tmp/o5"
usage "unknown option '--quiet'" 03_pitchforks --quiet
usage "--out needs a value" 03_pitchforks --out --help
usage "unexpected argument 'x'" 03_pitchforks --out "$tmp" x
fails "/dev/full is not a directory" 03_pitchforks --out /dev/full
fails "cannot write $tmp/o6/diagram.json: Is a directory" 03_pitchforks --out "$tmp/o6"

# 04_evolution
usage "unknown option '--bogus'" 04_evolution --bogus
usage "--out needs a value" 04_evolution --out
usage "unexpected argument 'x'" 04_evolution x
fails "/dev/full is not a directory" 04_evolution --out /dev/full
fails "cannot write $tmp/o8/evolution.csv: Is a directory" 04_evolution --out "$tmp/o8"
mkdir -p "$tmp/o10/plot.gp"
fails "cannot write $tmp/o10/plot.gp: Is a directory" 04_evolution --out "$tmp/o10"

# quasistatic
usage "unknown option '--bogus'" quasistatic --bogus
usage "--mesh 1: must be between 2 and 512" quasistatic --mesh 1
usage "--mesh 100000: must be between 2 and 512" quasistatic --mesh 100000
usage "--mesh 8x8: expected an integer" quasistatic --mesh 8x8
usage "--mesh 4294967312: must be between 2 and 512" quasistatic --mesh 4294967312
usage "--dt 0: must be >= 0.0001" quasistatic --dt 0
usage "--dt -0.1: must be >= 0.0001" quasistatic --dt -0.1
usage "--dt 1e-300: must be >= 0.0001" quasistatic --dt 1e-300
usage "--dt 2: must be <= 1" quasistatic --dt 2
usage "--dt nan: must be a finite number" quasistatic --dt nan
usage "--dt 0.1s: expected a number" quasistatic --dt 0.1s
usage "--quiet takes no value" quasistatic --quiet=no
usage "unexpected argument 'now'" quasistatic now
fails "/dev/full is not a directory" quasistatic --quiet --out /dev/full
fails "cannot write $tmp/o7/step_0003.vtu: Is a directory" quasistatic --quiet --mesh 8 --dt 0.1 --out "$tmp/o7"
fails "cannot write $tmp/o8/evolution.csv: Is a directory" quasistatic --quiet --mesh 8 --dt 0.1 --out "$tmp/o8"

# a sweep too short for the block (2 directions, 1 span): the example says the set looks
# incomplete and fails the paper's count
"$(where block)" --ndir 2 --nspan 1 >"$tmp/out" 2>"$tmp/err"
rc=$?
if [ $rc -eq 1 ] && grep -q "most likely branches are missing" "$tmp/out"; then
    pass
else
    fail "block --ndir 2 --nspan 1: exit $rc, stdout: $(grep -m 1 distinct "$tmp/out")"
fi

# an --out folder whose path leaves no room for a file name in the programs' 1024-byte paths:
# a clear error and exit 1, never a file written under a cut name
long="$tmp/L"
for part in a b c d e; do long="$long/$(printf "$part%.0s" $(seq 1 200))"; done
if mkdir -p "$long" 2>/dev/null; then
    fails "File name too long" 01_branching --out "$long"
    fails "File name too long" 02_explore --out "$long"
    fails "File name too long" 03_pitchforks --out "$long"
    fails "File name too long" 04_evolution --out "$long"
    fails "File name too long" block --quiet --mesh 5x10 --out "$long"
    fails "File name too long" block --quiet --explore --mesh 5x10 --out "$long"
    fails "File name too long" triangle --quiet --mesh 16 --explore --out "$long"
    fails "File name too long" quasistatic --quiet --mesh 8 --dt 0.1 --out "$long"
    if [ -n "$(ls -A "$long")" ]; then fail "files written under cut names in $long: $(ls "$long" | head -n 3)"; else pass; fi
    for cut in "$(dirname "$long")"/*; do [ "$cut" = "$long" ] || fail "a cut path was created: $cut"; done
else
    fail "cannot make the long test folder $long"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
