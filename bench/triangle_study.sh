#!/usr/bin/env bash
# Triangle studies of Section 3.3 of Ligursky & Renard on the paper's meshes, with the sparse
# solver (UMFPACK through contrib/psb_sparse.h and pscbranch's user-solver callbacks):
#   (a) the three-solution intervals of Fig. 9, h = (-20 - 10 gamma, -7.5)  -> bench/out/triangle_folds.csv
#   (b) the branches at gamma = 0 for h = gamma (-26.4, -7.5), paper's parameters, each traced
#       to |gamma| = 1                                                       -> bench/out/triangle_branches.csv
#   (c) Table 4: relative H1 errors of the displacements at gamma = -1 (branch 2) and gamma = 1
#       (branches 1, 3, 4) of each mesh against the finest one computed      -> bench/out/triangle_table4.csv
# Not part of `make test`. Needs libsuitesparse-dev. Usage (from the repository root):
#   bash bench/triangle_study.sh                 # meshes n = 64 128 256 (M4096, M16384, M65536)
#   MESHES="64 128 256 512" bash bench/triangle_study.sh     # branching on M262144 too: ~2 s per
#       factorisation with OpenBLAS (1400 for the fold study, 2500 for branching), 3x that with
#       reference BLAS; REFINE="" skips (c), REFINE="256" stops at M65536
#   STUDIES="fold" / "branch" restricts to (a) / (b)+(c); BANDED=1 also times the banded backend on n = 64;
#   BLAS_DIR=DIR takes libblas.so.3 from DIR (e.g. /usr/lib/x86_64-linux-gnu/openblas-serial).
#   NOBUILD=1 reuses bench/out/triangle_sparse (two studies started side by side); REUSE=1 keeps
#   the runs already finished in bench/out/triangle_runs and only redoes the tables.
# Times are CPU seconds of each run (the example's clock()), wall seconds beside them.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=bench/out
RUNS=$OUT/triangle_runs
MESHES=${MESHES:-"64 128 256"}
STUDIES=${STUDIES:-"fold branch"}
BIN=$OUT/triangle_sparse
CC=${CC:-cc}
mkdir -p "$OUT" "$RUNS"

# the sparse build of the example (UMFPACK through contrib/psb_sparse.h; see the top of triangle.c)
SS_INC=${SS_INC:-/usr/include/suitesparse}
if [[ "${NOBUILD:-0}" != 1 ]]; then
    $CC -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 -I. -I"$SS_INC" -DFE_SUITESPARSE fe/triangle.c \
        -o "$BIN" -lumfpack -lklu -llapack -lblas -lm
fi

# BLAS_DIR=/usr/lib/x86_64-linux-gnu/openblas-serial runs UMFPACK on that directory's libblas.so.3
# (Debian's alternatives otherwise pick the system default one)
if [[ -n "${BLAS_DIR:-}" ]]; then export LD_LIBRARY_PATH="$BLAS_DIR${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"; fi
blas=$(ldd "$BIN" | awk '/libblas.so.3/{print $3}' | xargs readlink -f 2>/dev/null || echo unknown)
echo "triangle study: meshes n = $MESHES; $(nproc) cores; BLAS $blas"
{ echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"; echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2-), $(nproc) cores";
  echo "blas: $blas"; echo "umfpack: $(dpkg-query -W -f='${Version}' libumfpack5 2>/dev/null || echo '?')"; } > "$OUT/triangle_env.txt"

# paper values (Section 3.3 and Table 4) by n
declare -A PLO=([64]=0.56541 [128]=0.5883 [256]=0.59996 [512]=0.60585)
declare -A PHI=([64]=0.66665 [128]=0.70731 [256]=0.73289 [512]=0.7499)
declare -A T4=([64]="2.0e-2 2.8e-2 2.2e-1 2.5e-1" [128]="9.8e-3 1.4e-2 1.6e-1 1.1e-1" [256]="4.2e-3 6.0e-3 9.6e-2 4.1e-2")

run() { # run LOG ARGS...: the example with wall time appended to its log
    local log=$1; shift
    local t0 t1
    # REUSE=1: keep a finished run (its log ends with the wall time), e.g. one started by hand
    if [[ "${REUSE:-0}" == 1 ]] && grep -q '^wall ' "$log" 2>/dev/null; then return; fi
    t0=$(date +%s.%N)
    "$BIN" "$@" > "$log" 2>&1 || true
    t1=$(date +%s.%N)
    echo "wall $(printf "%.1f" "$(echo "$t1 - $t0" | bc)")" >> "$log"
}

sig4() { # same to 4 significant digits
    python3 -c "import sys; a,b=float(sys.argv[1]),float(sys.argv[2]); print('yes' if float('%.4g'%a)==float('%.4g'%b) else 'no')" "$1" "$2"
}

if [[ " $STUDIES " == *" fold "* ]]; then
    CSV=$OUT/triangle_folds.csv
    echo "mesh,n,N,gamma_lo,gamma_hi,paper_lo,paper_hi,match_4_digits,steps,kinks,factorisations,cpu_s,wall_s" > "$CSV"
    printf "\n(a) three-solution intervals, h = (-20 - 10 gamma, -7.5)\n"
    printf "  %-8s %7s  %-22s %-22s %-6s %8s %8s\n" mesh N "gamma interval" "paper" "4 dig" "CPU s" "wall s"
    for n in $MESHES; do
        d=$RUNS/fold_$n; mkdir -p "$d"
        run "$d/log.txt" --mesh "$n" --problem fold --solver umfpack --out "$d"
        log=$d/log.txt
        N=$(sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' "$log")
        lo=$(awk -F, 'NR>1{print $2}' "$d/folds.csv" 2>/dev/null | sort -g | head -1)
        hi=$(awk -F, 'NR>1{print $2}' "$d/folds.csv" 2>/dev/null | sort -g | tail -1)
        # summed over the traces (two when the one from gamma = -3 stops at a kink, see --fold-trace)
        steps=$(sed -n 's/.*after \([0-9]*\) steps, \([0-9]*\) kinks.*/\1/p' "$log" | awk '{s += $1} END {print s}')
        kinks=$(sed -n 's/.*after \([0-9]*\) steps, \([0-9]*\) kinks.*/\2/p' "$log" | awk '{s += $1} END {print s}')
        nf=$(sed -n 's/^  time .*, factorisations \([0-9]*\)$/\1/p' "$log")
        cpu=$(sed -n 's/^  time \([0-9.]*\) s (CPU).*/\1/p' "$log")
        wall=$(sed -n 's/^wall //p' "$log")
        m="no"
        [[ -n "$lo" && -n "$hi" ]] && [[ $(sig4 "$lo" "${PLO[$n]:-0}") == yes && $(sig4 "$hi" "${PHI[$n]:-0}") == yes ]] && m=yes
        echo "M$((n*n)),$n,$N,$lo,$hi,${PLO[$n]:-},${PHI[$n]:-},$m,$steps,$kinks,$nf,$cpu,$wall" >> "$CSV"
        printf "  %-8s %7s  (%.5f, %.5f)     (%s, %s)%*s %-6s %8s %8.1f\n" "M$((n*n))" "$N" "${lo:-nan}" "${hi:-nan}" \
            "${PLO[$n]:-?}" "${PHI[$n]:-?}" $((18 - ${#PLO[$n]} - ${#PHI[$n]})) "" "$m" "$cpu" "$wall"
    done
    echo "  -> $CSV"
fi

if [[ " $STUDIES " == *" branch "* ]]; then
    CSV=$OUT/triangle_branches.csv
    echo "mesh,n,N,branches,numbers,n_pc,n_rand,spans,factorisations,cpu_s,wall_s,status" > "$CSV"
    printf "\n(b) branches at gamma = 0, h = gamma (-26.4, -7.5) (paper: 4 on every mesh)\n"
    printf "  %-8s %7s %9s %-10s %6s %7s %8s %8s %8s  %s\n" mesh N branches numbers n_pc n_rand factor. "CPU s" "wall s" status
    for n in $MESHES; do
        d=$RUNS/branch_$n; mkdir -p "$d"
        run "$d/log.txt" --mesh "$n" --load 26.4 --solver umfpack --out "$d" --save "$d/ends.txt"
        log=$d/log.txt
        N=$(sed -n 's/.*N = \([0-9]*\) unknowns.*/\1/p' "$log")
        nb=$(sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p' "$log")
        nums=$(awk -F, 'NR>1{printf "%s%s", (NR>2?" ":""), $1}' "$d/branches.csv" 2>/dev/null || true)
        npc=$(sed -n 's/.*n_pc = \([0-9]*\), n_rand = \([0-9]*\), spans = \([0-9]*\).*/\1/p' "$log")
        nr=$(sed -n 's/.*n_pc = \([0-9]*\), n_rand = \([0-9]*\), spans = \([0-9]*\).*/\2/p' "$log")
        sp=$(sed -n 's/.*n_pc = \([0-9]*\), n_rand = \([0-9]*\), spans = \([0-9]*\).*/\3/p' "$log")
        nf=$(sed -n 's/.*factorisations \([0-9]*\).*/\1/p' "$log")
        cpu=$(sed -n 's/.*; time \([0-9.]*\) s (CPU).*/\1/p' "$log")
        wall=$(sed -n 's/^wall //p' "$log")
        st=$(grep -q "^triangle: OK" "$log" && echo OK || echo FAILED)
        echo "M$((n*n)),$n,$N,$nb,$nums,$npc,$nr,$sp,$nf,$cpu,$wall,$st" >> "$CSV"
        printf "  %-8s %7s %9s %-10s %6s %7s %8s %8s %8.1f  %s\n" "M$((n*n))" "$N" "${nb:-?}" "${nums:-?}" "${npc:-?}" \
            "${nr:-?}" "${nf:-?}" "${cpu:-?}" "$wall" "$st"
    done
    echo "  -> $CSV"

    # (c) Table 4: the finest branching run's end points re-solved on each REFINE mesh in turn
    # (H is piecewise linear: Newton from the interpolated solution lands on the same branch,
    # which the example checks by its contact states), compared at the last one
    fine=""; for n in $MESHES; do [[ -f $RUNS/branch_$n/ends.txt ]] && fine=$n; done
    REFINE=${REFINE-"256 512"}
    if [[ -n "$fine" && -n "$REFINE" ]]; then
        prev=$RUNS/branch_$fine/ends.txt; last=""
        for n in $REFINE; do
            (( n > fine && n % fine == 0 )) || continue
            d=$RUNS/refine_$n; mkdir -p "$d"
            cmp=(); for m in $MESHES; do [[ -f $RUNS/branch_$m/ends.txt ]] && cmp+=(--compare "$RUNS/branch_$m/ends.txt"); done
            for m in $REFINE; do (( m < n )) && [[ -f $RUNS/refine_$m/ends.txt ]] && cmp+=(--compare "$RUNS/refine_$m/ends.txt"); done
            run "$d/log.txt" --mesh "$n" --load 26.4 --solver umfpack --refine "$prev" --save "$d/ends.txt" "${cmp[@]}"
            printf "  refined onto M%d: %s (%s s wall)\n" $((n*n)) "$(grep -o 'OK (every.*\|FAILED.*' "$d/log.txt" | head -1)" \
                "$(sed -n 's/^wall //p' "$d/log.txt")"
            prev=$d/ends.txt; last=$n
        done
        if [[ -n "$last" ]]; then
            CSV=$OUT/triangle_table4.csv
            echo "mesh,reference,branch,rel_h1_error,paper" > "$CSV"
            printf "\n(c) Table 4: ||u_h - u_ref||_1 / ||u_ref||_1, ref = M%d (paper: M262144)\n" $((last*last))
            printf "  %-8s  %-20s %-20s %-20s %-20s\n" mesh "branch 1 (ours/paper)" "branch 2" "branch 3" "branch 4"
            grep -E '^  M[0-9]+ ' "$RUNS/refine_$last/log.txt" | while read -r mesh rest; do
                nn=$(python3 -c "import math; print(int(round(math.sqrt(${mesh#M}))))")
                read -r -a pap <<< "${T4[$nn]:-- - - -}"
                line=$(printf "  %-8s" "$mesh")
                for k in 1 2 3 4; do
                    e=$(printf '%s\n' "$rest" | sed -n "s/.*$k: \([0-9.e+-]*\).*/\1/p")
                    echo "$mesh,M$((last*last)),$k,${e:-nan},${pap[$((k-1))]}" >> "$CSV"
                    line+=$(printf "  %-20s" "${e:-nan} / ${pap[$((k-1))]}")
                done
                echo "$line"
            done
            echo "  -> $CSV"
        fi
    fi
fi

if [[ "${BANDED:-0}" == 1 ]]; then
    # the same n = 64 runs on the banded backend, for the speed ratio
    BB=$OUT/triangle_banded
    $CC -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 -I. fe/triangle.c -o "$BB" -llapack -lblas -lm
    printf "\nbanded backend, n = 64 (CPU s): "
    "$BB" --mesh 64 --problem fold > "$RUNS/banded_fold_64.txt" 2>&1 || true
    "$BB" --mesh 64 --load 26.4 > "$RUNS/banded_branch_64.txt" 2>&1 || true
    echo "fold $(sed -n 's/.*tangent switches, time \([0-9.]*\) s.*/\1/p' "$RUNS/banded_fold_64.txt"), branching $(sed -n 's/.*; time \([0-9.]*\) s (CPU).*/\1/p' "$RUNS/banded_branch_64.txt")"
fi
