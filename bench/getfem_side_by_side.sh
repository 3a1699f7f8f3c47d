#!/usr/bin/env bash
# getfem_side_by_side.sh - pscbranch against GetFEM's own continuation and branching (by the
# paper's authors) on the same problems, run one after the other in one sitting, REPEAT times:
#   block    fe/block --mesh MESH (M200 by default) against bench/getfem/block.py: Newton at
#            gamma = -1 on branch 1, continuation to the nonsmooth point gamma = 0, Algorithms
#            2.1-2.2 (n_dir 20, n_span 15), every branch traced to |gamma| = 1
#   triangle (TRIANGLE=N, off by default) fe/triangle --mesh N --load 26.4 against
#            bench/getfem/triangle.py: the same for the triangle of Section 3.3 (GetFEM's own
#            continuation passes its branching point unflagged; gfcont.py says how its
#            Algorithms 2.1-2.2 are made to run there)
#   fold     (FOLD=N, off by default) fe/triangle --mesh N --problem fold against
#            bench/getfem/fold.py: the triangle's fold study, traced from gamma = -3 to 1 with
#            the kinks located to h_min = 1e-9 and the two limit points read off
# Each side is one process timed by /usr/bin/time (wall and CPU = user + sys, Python start-up and
# model set-up included); each script's own CPU time of the computation is printed beside. GetFEM's
# end values are compared with pscbranch's branch by branch (the scripts print the differences).
# Needs GetFEM's Python interface for /usr/bin/python3 (Debian: apt-get install python3-getfem);
# without it the script says so and exits 0. Usage (from anywhere):
#   bash bench/getfem_side_by_side.sh                       # block M200, 3 sittings
#   REPEAT=1 MESH=20x40 bash bench/getfem_side_by_side.sh   # M800 once (GetFEM: minutes)
#   TRIANGLE=64 bash bench/getfem_side_by_side.sh           # the triangle M4096 too, once
#                                      (TRIANGLE_REPEAT=K: K sittings; GetFEM takes minutes there;
#                                      BLOCK=0 skips the block)
#   BLOCK=0 FOLD=64 FOLD_REPEAT=3 bash bench/getfem_side_by_side.sh   # the fold study, M4096
# Tables on stdout, CSV in bench/out/getfem_<problem>_<mesh>.csv, logs in bench/out/getfem/.
set -u
cd "$(dirname "$0")/.."
REPEAT=${REPEAT:-3}
MESH=${MESH:-10x20}
TRIANGLE=${TRIANGLE:-}
TRIANGLE_REPEAT=${TRIANGLE_REPEAT:-1}
FOLD=${FOLD:-}
FOLD_REPEAT=${FOLD_REPEAT:-1}
BLOCK=${BLOCK:-1}
PY=${GETFEM_PYTHON:-/usr/bin/python3}
OUT=bench/out
LOGS=$OUT/getfem
CC=${CC:-cc}

if ! "$PY" -c "import getfem" >/dev/null 2>&1; then
    echo "getfem_side_by_side: skipped: GetFEM's Python interface is not installed for $PY (Debian: apt-get install python3-getfem)"
    exit 0
fi
[ -x /usr/bin/time ] || { echo "getfem_side_by_side: skipped: /usr/bin/time is missing (Debian: apt-get install time)"; exit 0; }
mkdir -p "$LOGS"

# pscbranch's side: the FE applications built here with -O2 (the banded backend, as `make examples`)
if [ "$BLOCK" != 0 ]; then
    $CC -std=c99 -O2 -I. fe/block.c -o "$OUT/block_side" -llapack -lblas -lm || exit 1
fi
# the triangle with the example's default solver (UMFPACK from M4096 when libsuitesparse-dev is
# there, the banded LU otherwise: fe/fe_solvers.h)
tri_flags=()
if [ -n "$TRIANGLE$FOLD" ]; then
    SS_INC=${SS_INC:-/usr/include/suitesparse}
    if [ -f "$SS_INC/umfpack.h" ]; then
        $CC -std=c99 -O2 -I. -I"$SS_INC" -DFE_SUITESPARSE fe/triangle.c -o "$OUT/triangle_side" -lumfpack -lklu -llapack -lblas -lm || exit 1
    else
        $CC -std=c99 -O2 -I. fe/triangle.c -o "$OUT/triangle_side" -llapack -lblas -lm || exit 1
    fi
    tri_backend="its default solver"
fi

# Both sides run single-threaded: pscbranch is, GetFEM's Debian build uses sequential MUMPS; a
# threaded BLAS (OpenBLAS) is held to one thread on both sides.
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
blas=$(ldd "$OUT/$([ "$BLOCK" != 0 ] && echo block || echo triangle)_side" | awk '/libblas.so.3/{print $3}' | xargs readlink -f 2>/dev/null)
gblas=$(ldd "$("$PY" -c 'import getfem._getfem as g; print(g.__file__)')" | awk '/libblas.so.3/{print $3}' | xargs readlink -f 2>/dev/null)
gver=$(dpkg-query -W -f='${Version}' python3-getfem 2>/dev/null || echo unknown)
echo "getfem_side_by_side: $(date -u +%Y-%m-%dT%H:%M:%SZ), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//'), $(grep -c ^processor /proc/cpuinfo) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "  BLAS: pscbranch $blas; GetFEM $gblas (OPENBLAS_NUM_THREADS=OMP_NUM_THREADS=1)"
echo "  GetFEM $gver (python3-getfem), linear solver MUMPS (sequential); $PY"
echo "  pscbranch: block banded LAPACK${TRIANGLE:+, triangle $tri_backend}${FOLD:+, fold study $tri_backend}"


# timed LOG CMD...: runs CMD with its output in LOG; sets wall, cpu (user + sys)
timed() {
    local log=$1 tf=$1.time
    shift
    /usr/bin/time -f '%e %U %S' -o "$tf" "$@" >"$log" 2>&1
    read -r wall u s <"$tf"
    cpu=$(awk -v u="$u" -v s="$s" 'BEGIN { printf "%.2f", u + s }')
}

ratios=()
side_by_side() { # PROBLEM MESH SITTINGS PSB_CMD... -- GETFEM_CMD...
    local problem=$1 mesh=$2 reps=$3 k psb=() gfm=() seen=0 compare=branches.csv
    [ "$problem" = fold ] && compare=folds.csv
    shift 3
    for a in "$@"; do
        if [ "$a" = -- ]; then seen=1; continue; fi
        if [ $seen = 0 ]; then psb+=("$a"); else gfm+=("$a"); fi
    done
    CSV=$OUT/getfem_${problem}_$mesh.csv
    echo "problem,mesh,sitting,side,wall_s,cpu_s,own_cpu_s,branches,status,end_value_difference" >"$CSV"
    echo
    echo "  $problem $mesh: sitting | pscbranch wall  CPU  (own) $([ "$problem" = fold ] && echo "limit points" || echo branches) | GetFEM wall  CPU  (own) $([ "$problem" = fold ] && echo "limit points" || echo branches) | ratio wall  CPU | $([ "$problem" = fold ] && echo "limit points" || echo "end values") vs pscbranch"
    for k in $(seq 1 "$reps"); do
        local d=$LOGS/${problem}_${mesh}_$k
        mkdir -p "$d"
        timed "$d/pscbranch.log" "${psb[@]}" --out "$d/psb"
        local pw=$wall pc=$cpu
        local pown pnb pst
        pown=$(sed -n 's/.*time \([0-9.]*\) s (CPU).*/\1/p' "$d/pscbranch.log" | head -n 1)
        pnb=$(sed -n 's/^ *\([0-9]*\) distinct branches.*/\1/p' "$d/pscbranch.log" | head -n 1)
        [ "$problem" = fold ] && pnb=$(grep -m1 'limit points (gamma):' "$d/pscbranch.log" | sed 's/(paper.*//' | grep -o '[0-9]\.[0-9]*' | wc -l)
        pst=$(grep -q ": OK" "$d/pscbranch.log" && echo OK || echo FAILED)
        timed "$d/getfem.log" "${gfm[@]}" --compare "$d/psb/$compare"
        local gw=$wall gc=$cpu
        local gown gnb gst diff
        gown=$(sed -n 's/.*time \([0-9.]*\) s (CPU, set-up.*/\1/p' "$d/getfem.log" | head -n 1)
        gnb=$(sed -n 's/^ *\([0-9]*\) \(distinct branches\|limit points;\).*/\1/p' "$d/getfem.log" | head -n 1)
        gst=$(grep -q "^getfem-$problem: OK" "$d/getfem.log" && echo OK || echo FAILED)
        diff=$(sed -n 's/.*largest \(end-value\|limit-point\) difference \(.*\)$/\2/p' "$d/getfem.log" | head -n 1)
        local rw rc
        rw=$(awk -v a="$gw" -v b="$pw" 'BEGIN { if (b > 0) printf "%.1f", a / b; else print "-" }')
        rc=$(awk -v a="$gc" -v b="$pc" 'BEGIN { if (b > 0) printf "%.1f", a / b; else print "-" }')
        ratios+=("$problem $mesh $rw $rc")
        printf "  %-15s %7s | %14s %5s %6s %2s %-6s | %11s %5s %6s %2s %-6s | %8sx %4sx | %s\n" "" "$k" "$pw" "$pc" "(${pown:-?})" "${pnb:-?}" "$pst" \
            "$gw" "$gc" "(${gown:-?})" "${gnb:-?}" "$gst" "$rw" "$rc" "max diff ${diff:-?}"
        echo "$problem,$mesh,$k,pscbranch,$pw,$pc,$pown,$pnb,$pst," >>"$CSV"
        echo "$problem,$mesh,$k,getfem,$gw,$gc,$gown,$gnb,$gst,$diff" >>"$CSV"
    done
    # spread of the ratios over the sittings
    printf '%s\n' "${ratios[@]}" | awk -v p="$problem" -v m="$mesh" '$1 == p && $2 == m { i = n + 0; w[i] = $3; c[i] = $4; n = i + 1 }
        END { if (n) { mw = Mw = w[0]; mc = Mc = c[0]
                for (i = 1; i < n; i++) { if (w[i] < mw) mw = w[i]; if (w[i] > Mw) Mw = w[i]; if (c[i] < mc) mc = c[i]; if (c[i] > Mc) Mc = c[i] }
                printf "  %s %s: GetFEM / pscbranch over %d sittings: wall %s-%sx, CPU %s-%sx\n", p, m, n, mw, Mw, mc, Mc } }'
    grep -h "phases (CPU s)" "$LOGS/${problem}_${mesh}_"*/getfem.log 2>/dev/null | head -n 1 | sed 's/^ */  GetFEM /'
}

[ "$BLOCK" = 0 ] || side_by_side block "$MESH" "$REPEAT" "$OUT/block_side" --mesh "$MESH" -- "$PY" bench/getfem/block.py --mesh "$MESH"
if [ -n "$TRIANGLE" ]; then
    side_by_side triangle "$TRIANGLE" "$TRIANGLE_REPEAT" "$OUT/triangle_side" --mesh "$TRIANGLE" --load 26.4 "${tri_flags[@]}" -- "$PY" bench/getfem/triangle.py --mesh "$TRIANGLE"
fi
if [ -n "$FOLD" ]; then
    side_by_side fold "$FOLD" "$FOLD_REPEAT" "$OUT/triangle_side" --mesh "$FOLD" --problem fold -- "$PY" bench/getfem/fold.py --mesh "$FOLD"
fi
echo
echo "  logs: $LOGS/, CSV: $OUT/getfem_<problem>_<mesh>.csv"
