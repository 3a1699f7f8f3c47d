#!/usr/bin/env bash
# bench_block.sh - the block example of Section 3.2 as a benchmark (run by `make bench`).
#   1. dense against banded on M200 (and banded on M800; M3200 with --full): seconds,
#      factorisations, n_pc, speed-up; banded also without the piece memo (run "nopiece").
#   2. the study of Tables 1-2 on the paper's M800: for input branches 1, 2, 3 and n_dir in
#      {20, 30, 40, 50, 60, 100}, the smallest n_span that finds all six branches (one run with
#      n_span = 40: the span of the last new branch) with its n_pc and n_rand, the same with the
#      adaptive end (patience = 3 and 6, block --patience) and with Table 2's fixed n_span, beside the
#      paper's figures; for the example's defaults and for the paper's sweep and inner product.
#   3. the mesh study of Table 3: six branches on M200, M800, M3200; M12800 by Newton from the
#      M3200 end points; relative H1 errors against M12800.
# Tables on stdout, CSV in bench/out/. Usage: bench/bench_block.sh [--full] [--quick]
# (--quick: M200 and one n_dir only, and M3200 as the finest mesh; a few minutes less than 20.)
set -u
cd "$(dirname "$0")/.."
full=0
quick=0
for a in "$@"; do
    case "$a" in --full) full=1 ;; --quick) quick=1 ;; esac
done
mkdir -p bench/out
block=fe/block
[ -x "$block" ] || { echo "build fe/block first (make examples)"; exit 1; }


echo "bench_block: the block of Section 3.2 (n_dir 20, n_span 15, input branch 1 unless stated)"
ldd "$block" | grep -E 'blas|lapack' | sed 's/^[[:space:]]*/  linked: /'
echo
echo "  mesh    run    backend      N   time [s]   factorisations   n_pc  branches   speed-up"
csv=bench/out/block_backends.csv
echo "mesh,run,backend,n,seconds,factorisations,n_pc,branches" >"$csv"
# row MESH RUN BACKEND FLAGS...: one run of the example, printed and appended to the CSV;
# sets $secs (the speed-up column compares a dense row with the banded row before it)
# parse_run OUTPUT: sets n, hb, secs, fact, nbr, npc from one run's output
parse_run() {
    local line
    n=$(printf '%s\n' "$1" | sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' | head -n 1)
    hb=$(printf '%s\n' "$1" | sed -n 's/.*half band \([0-9]*\).*/\1/p' | head -n 1)
    line=$(printf '%s\n' "$1" | grep 'distinct branches')
    secs=$(printf '%s\n' "$line" | sed -n 's/.*time \([0-9.]*\) s.*/\1/p')
    fact=$(printf '%s\n' "$line" | sed -n 's/.*factorisations \([0-9]*\).*/\1/p')
    nbr=$(printf '%s\n' "$line" | sed -n 's/^ *\([0-9]*\) distinct.*/\1/p')
    npc=$(printf '%s\n' "$1" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
}
row() {
    local mesh=$1 run=$2 backend=$3 speed="-"
    shift 3
    parse_run "$($block --mesh "$mesh" "$@" 2>&1)"
    if [ "$backend" = dense ]; then speed=$(awk -v d="$secs" -v b="$banded_time" 'BEGIN { if (b > 0) printf "%.1fx", d / b; else print "-" }'); fi
    printf '  %-7s %-6s %-8s %6s %10s %16s %6s %9s %10s\n' "$mesh" "$run" "$backend" "$n" "$secs" "$fact" "$npc" "$nbr" "$speed"
    echo "$mesh,$run,$backend,$n,$secs,$fact,$npc,$nbr" >>"$csv"
}
meshes="10x20 20x40"
[ $full -eq 1 ] && meshes="$meshes 40x80"
[ $quick -eq 1 ] && meshes="10x20"
for mesh in $meshes; do
    row "$mesh" whole banded --solver banded; banded_time=$secs
    # the same without psb_problem.piece (Algorithm 2.2's piece memo off)
    row "$mesh" nopiece banded --solver banded --no-piece-memo
    if [ "$mesh" = 10x20 ]; then
        row "$mesh" whole dense --solver dense
    elif [ "$mesh" = 20x40 ]; then
        # a whole dense run costs ~1 h here (~0.7 s per factorisation): both backends on the
        # same short run instead (Algorithm 2.2 with 2 directions in 1 span, found branches traced)
        row "$mesh" short banded --ndir 2 --nspan 1 --solver banded; banded_time=$secs
        row "$mesh" short dense --ndir 2 --nspan 1 --solver dense
    fi
done

echo
# The paper's figures (GetFEM runs on M800): Table 1 = smallest n_span and its n_pc (a range over
# the paper's three runs), Table 2 = n_pc with n_span fixed a priori (15-16 for n_dir 20, 10 for
# 50 and 60, 8 for 100).
paper_t1() { # input ndir
    case "$1:$2" in
    1:20) echo "8-13 168-266" ;; 1:40) echo "7-14 292-478" ;; 1:50) echo "3 162" ;; 1:60) echo "5 232" ;; 1:100) echo "3 206" ;;
    2:20) echo "4-8 136-240" ;; 2:40) echo "4-5 260-316" ;; 2:50) echo "4-7 274-490" ;; 2:60) echo "5-9 374-654" ;; 2:100) echo "4-7 372-662" ;;
    3:20) echo "5 128" ;; 3:40) echo "3 134" ;; 3:50) echo "1 72" ;; 3:60) echo "4 202" ;; 3:100) echo "1 102" ;;
    *) echo "- -" ;;
    esac
}
paper_t2() { # input ndir
    case "$1:$2" in
    1:20) echo "310-346" ;; 1:50) echo "400" ;; 1:60) echo "416" ;; 1:100) echo "474" ;;
    2:20) echo "350-434" ;; 2:50) echo "518-562" ;; 2:60) echo "618-734" ;; 2:100) echo "642-720" ;;
    3:20) echo "318-334" ;; 3:50) echo "396" ;; 3:60) echo "414" ;; 3:100) echo "456" ;;
    *) echo "-" ;;
    esac
}
paper_t2_nspan() { # ndir: Table 2's n_span fixed a priori
    case "$1" in 20) echo 15 ;; 50|60) echo 10 ;; 100) echo 8 ;; *) echo "" ;; esac
}

study_mesh=20x40
[ $quick -eq 1 ] && study_mesh=10x20
ndirs="20 30 40 50 60 100"
inputs="1 2 3"
[ $quick -eq 1 ] && ndirs="20" && inputs="1"
# Two configurations: the example's defaults (t~2 made orthogonal to t~1, multipliers weighted
# 1/r^2 = 0.01), and the paper's (the printed sweep, every unknown weighted alike in Algorithms
# 2.1-2.2, as in GetFEM's continuation), which reproduces Table 1's spans.
echo "mesh,config,input,n_dir,n_span_needed,n_pc,n_rand,branches,paper_t1_n_span,paper_t1_n_pc,adaptive_branches,adaptive_n_pc,adaptive_n_rand,adaptive_spans,patience6_branches,patience6_n_pc,t2_n_span,t2_branches,t2_n_pc,paper_t2_n_pc" >bench/out/block_tables.csv
for config in defaults paper; do
    flags=""
    [ "$config" = paper ] && flags="--paper-sweep --branch-mult-weight 1"
    echo
    echo "  Tables 1-2 study, $config configuration${flags:+ ($flags)}, M${study_mesh} (the paper's mesh is 20x40 = M800):"
    echo "  smallest n_span finding all six branches, from one run with n_span = 40 (the span of the last new"
    echo "  branch); the adaptive end (patience = 3, and 6); n_span fixed as in Table 2; beside the paper"
    echo "  input  n_dir | n_span   n_pc  n_rand | paper T1 n_span  n_pc | patience 3: branches  n_pc  n_rand  spans | patience 6: branches  n_pc | T2 n_span: branches  n_pc | paper T2 n_pc"
    csv=bench/out/block_tables.csv
    for input in $inputs; do
        for ndir in $ndirs; do
            out=$($block --mesh "$study_mesh" --input "$input" --ndir "$ndir" --nspan 40 $flags 2>&1)
            nbr=$(printf '%s\n' "$out" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
            need=$(printf '%s\n' "$out" | sed -n 's/.*last new branch in span \([0-9]*\).*/\1/p')
            npc=$(printf '%s\n' "$out" | sed -n 's/.*with n_span = [0-9]*: n_pc = \([0-9]*\).*/\1/p')
            nrand=$(printf '%s\n' "$out" | sed -n 's/.*with n_span = [0-9]*: n_pc = [0-9]*, n_rand = \([0-9]*\).*/\1/p')
            ad=$($block --mesh "$study_mesh" --input "$input" --ndir "$ndir" --nspan 40 --patience 3 $flags 2>&1)
            anbr=$(printf '%s\n' "$ad" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
            anpc=$(printf '%s\n' "$ad" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
            anrand=$(printf '%s\n' "$ad" | sed -n 's/.*; n_pc = [0-9]*, n_rand = \([0-9]*\).*/\1/p' | head -n 1)
            aspans=$(printf '%s\n' "$ad" | sed -n 's/.*, spans = \([0-9]*\)[ ,].*/\1/p' | head -n 1)
            ad6=$($block --mesh "$study_mesh" --input "$input" --ndir "$ndir" --nspan 40 --patience 6 $flags 2>&1)
            a6nbr=$(printf '%s\n' "$ad6" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
            a6npc=$(printf '%s\n' "$ad6" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
            t2span=$(paper_t2_nspan "$ndir") t2nbr="-" t2npc="-"
            if [ -n "$t2span" ]; then
                fx=$($block --mesh "$study_mesh" --input "$input" --ndir "$ndir" --nspan "$t2span" $flags 2>&1)
                t2nbr=$(printf '%s\n' "$fx" | sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p')
                t2npc=$(printf '%s\n' "$fx" | sed -n 's/.*; n_pc = \([0-9]*\), n_rand.*/\1/p' | head -n 1)
            fi
            [ "$nbr" = 6 ] || need="(only $nbr)"
            set -- $(paper_t1 "$input" "$ndir")
            p1span=$1 p1pc=$2
            p2=$(paper_t2 "$input" "$ndir")
            printf '  %5s  %5s | %6s %6s %7s | %15s %5s | %20s %5s %7s %6s | %20s %5s | %9s: %8s %5s | %13s\n' "$input" "$ndir" "$need" "$npc" "$nrand" \
                "$p1span" "$p1pc" "$anbr" "$anpc" "$anrand" "$aspans" "$a6nbr" "$a6npc" "${t2span:--}" "$t2nbr" "$t2npc" "$p2"
            echo "$study_mesh,$config,$input,$ndir,$need,$npc,$nrand,$nbr,$p1span,$p1pc,$anbr,$anpc,$anrand,$aspans,$a6nbr,$a6npc,$t2span,$t2nbr,$t2npc,$p2" >>"$csv"
        done
    done
done

# The mesh study (Table 3): six branches on M200, M800, M3200 (full runs; M3200 skipped with
# --quick), then M12800 from the M3200 end points by Newton (--refine; a full banded branching
# run there costs about an hour) and the relative H1 errors at |gamma| = 1 against M12800.
echo
echo "  mesh study (Table 3): full runs, then M12800 by Newton from the interpolated M3200 end points"
csv=bench/out/block_meshes.csv
echo "mesh,n,half_band,seconds,factorisations,n_pc,branches" >"$csv"
study="10x20 20x40 40x80"
[ $quick -eq 1 ] && study="10x20 20x40"
last=""
compare=""
for mesh in $study; do
    parse_run "$($block --mesh "$mesh" --save "bench/out/ends_$mesh.txt" 2>&1)"
    printf '  %-7s N %6s  half band %4s  %8s s  factorisations %5s  n_pc %4s  branches %s\n' "$mesh" "$n" "$hb" "$secs" "$fact" "$npc" "$nbr"
    echo "$mesh,$n,$hb,$secs,$fact,$npc,$nbr" >>"$csv"
    last=$mesh
    compare="$compare --compare bench/out/ends_$mesh.txt"
done
fine=80x160
[ $quick -eq 1 ] && fine=40x80
out=$($block --mesh "$fine" --refine "bench/out/ends_$last.txt" --save "bench/out/ends_$fine.txt" $compare 2>&1)
printf '%s\n' "$out" | grep -E 'refined|distinct|block:' | sed 's/^ */  /'
echo "  relative H1 errors at |gamma| = 1 against $fine (branches 1-6; 4-6 mirror 1-3):"
printf '%s\n' "$out" | grep -E '^  M[0-9]+ ' | tee bench/out/block_table3.txt
echo "  paper (Table 3, vs M12800): M200 6.1e-2 1.7e-1 4.3e-2; M800 2.3e-2 1.1e-1 1.1e-2"
echo "  CSV: bench/out/block_backends.csv, bench/out/block_tables.csv, bench/out/block_meshes.csv, bench/out/block_table3.txt"
