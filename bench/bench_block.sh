#!/usr/bin/env bash
# bench_block.sh - the block example of Section 3.2 as a benchmark (run by `make bench`).
#   1. dense against banded on M200 (and banded on M800; M3200 with --full): seconds,
#      factorisations, n_pc, speed-up.
#   2. the study of Tables 1-2: for input branches 1, 2, 3 and n_dir in {20, 30, 40, 50, 60, 100},
#      the smallest n_span that finds all six branches (one run with n_span = 40: the span of the
#      last new branch) with its n_pc and n_rand, and the same with the adaptive end
#      (branch_patience = 3).
# Tables on stdout, CSV in bench/out/. Usage: bench/bench_block.sh [--full] [--quick]
set -u
cd "$(dirname "$0")/.."
full=0
quick=0
for a in "$@"; do
    case "$a" in --full) full=1 ;; --quick) quick=1 ;; esac
done
mkdir -p bench/out
block=examples/block
[ -x "$block" ] || { echo "build examples/block first (make examples)"; exit 1; }

field() { # field NAME TEXT: the number after "NAME = " or "NAME "
    printf '%s\n' "$2" | sed -n "s/.*$1 = \{0,1\}\([0-9.e+-]*\).*/\1/p" | head -n 1
}

echo "bench_block: the block of Section 3.2 (n_dir 20, n_span 15, input branch 1 unless stated)"
ldd "$block" | grep -E 'blas|lapack' | sed 's/^[[:space:]]*/  linked: /'
echo
echo "  mesh    backend      N   time [s]   factorisations   n_pc  branches   speed-up"
csv=bench/out/block_backends.csv
echo "mesh,backend,n,seconds,factorisations,n_pc,branches" >"$csv"
meshes="10x20 20x40"
[ $full -eq 1 ] && meshes="$meshes 40x80"
[ $quick -eq 1 ] && meshes="10x20"
for mesh in $meshes; do
    banded_time=""
    for backend in banded dense; do
        if [ "$backend" = dense ] && [ "$mesh" != 10x20 ]; then
            echo "  $mesh  dense     (not run: a dense factorisation of this size costs minutes per branching run)"
            continue
        fi
        flag=""
        [ "$backend" = dense ] && flag="--dense"
        out=$($block --mesh "$mesh" $flag 2>&1)
        n=$(printf '%s\n' "$out" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
        line=$(printf '%s\n' "$out" | grep 'distinct branches')
        secs=$(printf '%s\n' "$line" | sed -n 's/.*time \([0-9.]*\) s.*/\1/p')
        fact=$(printf '%s\n' "$line" | sed -n 's/.*factorisations \([0-9]*\).*/\1/p')
        nbr=$(printf '%s\n' "$line" | sed -n 's/^ *\([0-9]*\) distinct.*/\1/p')
        npc=$(printf '%s\n' "$out" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
        speed="-"
        if [ "$backend" = banded ]; then banded_time=$secs; else speed=$(awk -v d="$secs" -v b="$banded_time" 'BEGIN { if (b > 0) printf "%.1fx", d / b; else print "-" }'); fi
        printf '  %-7s %-8s %6s %10s %16s %6s %9s %10s\n' "$mesh" "$backend" "$n" "$secs" "$fact" "$npc" "$nbr" "$speed"
        echo "$mesh,$backend,$n,$secs,$fact,$npc,$nbr" >>"$csv"
    done
done

echo
echo "  Tables 1-2 study (M200): smallest n_span finding all six branches, from one run with n_span = 40"
echo "  input  n_dir | n_span   n_pc  n_rand | adaptive (patience 3): branches  n_pc  n_rand  spans"
csv=bench/out/block_tables.csv
echo "input,n_dir,n_span_needed,n_pc,n_rand,branches,adaptive_branches,adaptive_n_pc,adaptive_n_rand,adaptive_spans" >"$csv"
ndirs="20 30 40 50 60 100"
inputs="1 2 3"
[ $quick -eq 1 ] && ndirs="20" && inputs="1"
for input in $inputs; do
    for ndir in $ndirs; do
        out=$($block --input "$input" --ndir "$ndir" --nspan 40 2>&1)
        nbr=$(printf '%s\n' "$out" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
        need=$(printf '%s\n' "$out" | sed -n 's/.*last new branch in span \([0-9]*\).*/\1/p')
        npc=$(printf '%s\n' "$out" | sed -n 's/.*with n_span = [0-9]*: n_pc = \([0-9]*\).*/\1/p')
        nrand=$(printf '%s\n' "$out" | sed -n 's/.*with n_span = [0-9]*: n_pc = [0-9]*, n_rand = \([0-9]*\).*/\1/p')
        ad=$($block --input "$input" --ndir "$ndir" --nspan 40 --patience 3 2>&1)
        anbr=$(printf '%s\n' "$ad" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
        anpc=$(printf '%s\n' "$ad" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
        anrand=$(printf '%s\n' "$ad" | sed -n 's/.*; n_pc = [0-9]*, n_rand = \([0-9]*\).*/\1/p' | head -n 1)
        aspans=$(printf '%s\n' "$ad" | sed -n 's/.*, spans = \([0-9]*\),.*/\1/p' | head -n 1)
        [ "$nbr" = 6 ] || need="(only $nbr)"
        printf '  %5s  %5s | %6s %6s %7s | %27s %5s %7s %6s\n' "$input" "$ndir" "$need" "$npc" "$nrand" "$anbr" "$anpc" "$anrand" "$aspans"
        echo "$input,$ndir,$need,$npc,$nrand,$nbr,$anbr,$anpc,$anrand,$aspans" >>"$csv"
    done
done
echo
echo "  paper (Table 1, GetFEM): input 1: n_dir 20 -> n_span 8-13 (n_pc 168-266), 50 -> 3 (162), 100 -> 3 (206);"
echo "  input 2: n_dir 20 -> 4-8 (136-240), 50 -> 4-7 (274-490); input 3: n_dir 20 -> 5 (128), 50 -> 1 (72)"
echo "  CSV: bench/out/block_backends.csv, bench/out/block_tables.csv"
