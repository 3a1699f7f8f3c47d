#!/usr/bin/env bash
# bench_workers.sh - Algorithm 2.2 and psb_explore on workers (psb_branch_options.workers,
# psb_explore_options.drafts; run by `make bench`).
#   1. wall time of whole runs of the block (M800, M3200, M12800 with --large) and the triangle
#      (M1024), and of the explorer on block M800 and triangle M1024 (--explore): the serial
#      sweep, and the phased sweep (and drafts) on 1 and 2 threads (--workers N) and, in
#      builds with MPI, on 1 and 2 MPI ranks (tools/mpirun.sh K ... --workers mpi), with
#      OPENBLAS_NUM_THREADS=1; Algorithm 2.2's factorisations beside.
#   2. the sweep's critical path: W = 1, 2, 4, 8, 16, 32 logical workers run one after another
#      (--workers W --logical), the longest worker's factorisations in each parallel phase summed,
#      the calling solver's own added; against the serial sweep's factorisations.
#   3. the same for psb_explore (--explore): its edges drafted on the W workers, each sweep's
#      directions too; what stays on the calling solver beside.
#   4. peak resident memory of the cases of 1 on 1, 2, 4, 8 threads (GNU time).
# Tables on stdout; CSV in bench/out/workers_wall.csv, workers_model.csv, workers_explore.csv,
# workers_memory.csv;
# the log-log plots of 2 and 3 in docs/img/workers_critical_path.png and
# explorer_critical_path.png when gnuplot is there.
# Usage: bench/bench_workers.sh [--large] [--plot] (--plot: only redraw the plots from
# bench/out/workers_model.csv and workers_explore.csv)
set -u
cd "$(dirname "$0")/.."
large=0
plot_only=0
while [ $# -gt 0 ]; do
    case "$1" in
    --large) large=1 ;;
    --plot) plot_only=1 ;;
    *) echo "usage: bench/bench_workers.sh [--large] [--plot]" >&2; exit 2 ;;
    esac
    shift
done
export OPENBLAS_NUM_THREADS=1
mkdir -p bench/out
for p in fe/block fe/triangle; do [ -x "$p" ] || { echo "build $p first (make examples)"; exit 1; }; done
sweeps="serial 1 2"
if command -v mpirun >/dev/null && fe/block --workers mpi --help >/dev/null 2>&1 &&
    fe/triangle --workers mpi --help >/dev/null 2>&1; then
    sweeps="$sweeps mpi1 mpi2"
fi

# f22 OUTPUT: Algorithm 2.2's factorisations; crit OUTPUT: the modelled longest path
f22() { printf '%s\n' "$1" | sed -n 's/.*Algorithm 2.2: \([0-9]*\) factorisations.*/\1/p' | head -n 1; }
crit() { printf '%s\n' "$1" | sed -n 's/.*the longest path \([0-9]*\).*/\1/p' | head -n 1; }

model_csv=bench/out/workers_model.csv
explore_csv=bench/out/workers_explore.csv
if [ "$plot_only" = 0 ]; then
echo "bench_workers: Algorithm 2.2 on workers (nproc $(nproc), OPENBLAS_NUM_THREADS=1)"
echo
echo "  case                   sweep       wall [s]  CPU [s]  factorisations in 2.2  branches  ratio to 1 worker"
wall_csv=bench/out/workers_wall.csv
echo "case,sweep,wall_seconds,cpu_seconds,factorisations_22,branches" >"$wall_csv"
cases="block-M800:fe/block --mesh 20x40|block-M3200:fe/block --mesh 40x80|triangle-M1024:fe/triangle --mesh 32"
cases="$cases|explore-block-M800:fe/block --mesh 20x40 --explore|explore-triangle-M1024:fe/triangle --mesh 32 --explore"
[ "$large" = 1 ] && cases="$cases|block-M12800:fe/block --mesh 80x160"
IFS='|' read -r -a list <<<"$cases"
for c in "${list[@]}"; do
    name=${c%%:*}
    cmd=${c#*:}
    one=""
    for sweep in $sweeps; do
        flags="--quiet --verbose"
        run=$cmd
        case "$sweep" in
        serial) ;;
        mpi*) flags="$flags --workers mpi"; run="sh tools/mpirun.sh ${sweep#mpi} $cmd" ;;
        *) flags="$flags --workers $sweep" ;;
        esac
        t0=$(date +%s.%N)
        out=$($run $flags 2>&1)
        t1=$(date +%s.%N)
        wall=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')
        cpu=$(printf '%s\n' "$out" | sed -n 's/.*time \([0-9.]*\) s (CPU).*/\1/p' | tail -n 1)
        nbr=$(printf '%s\n' "$out" | sed -n 's/.*  \([0-9]*\) distinct branches.*/\1/p' | tail -n 1)
        ratio=""
        case "$sweep" in 1 | mpi1) one=$wall ;; esac
        case "$sweep" in 2 | mpi2) [ -n "$one" ] && ratio=$(awk -v a="$wall" -v b="$one" 'BEGIN { printf "%.2f", a / b }') ;; esac
        printf '  %-22s %-10s %9s %8s %23s %9s  %s\n' "$name" "$sweep" "$wall" "$cpu" "$(f22 "$out")" "$nbr" "$ratio"
        echo "$name,$sweep,$wall,$cpu,$(f22 "$out"),$nbr" >>"$wall_csv"
    done
done

# peak resident memory against the worker count (GNU time's %M): each worker holds a solver, its
# backend's factors and the model's scratch; the tasks' records are psb_workers_memory_size
echo
if [ -x /usr/bin/time ] && /usr/bin/time -o /dev/null -f %M true >/dev/null 2>&1; then
    echo "  peak resident memory [MB] on W threads (serial: no workers)"
    echo "  case                   serial    W=1    W=2    W=4    W=8  per worker"
    mem_csv=bench/out/workers_memory.csv
    echo "case,workers,peak_rss_kb" >"$mem_csv"
    for c in "${list[@]}"; do
        name=${c%%:*}
        cmd=${c#*:}
        row=""
        for w in serial 1 2 4 8; do
            flags="--quiet"
            [ "$w" != serial ] && flags="$flags --workers $w"
            /usr/bin/time -o bench/out/workers_rss.txt -f %M $cmd $flags >/dev/null 2>&1
            kb=$(tail -n 1 bench/out/workers_rss.txt)
            echo "$name,$w,$kb" >>"$mem_csv"
            row="$row $(awk -v k="$kb" 'BEGIN { printf "%6.1f", k / 1024 }')"
            [ "$w" = 1 ] && kb1=$kb
            [ "$w" = 8 ] && kb8=$kb
        done
        printf '  %-22s%s  %10s\n' "$name" "$row" "$(awk -v a="$kb1" -v b="$kb8" 'BEGIN { printf "%.1f", (b - a) / 7 / 1024 }')"
    done
else
    echo "  peak resident memory: skipped (needs GNU time as /usr/bin/time)"
fi

echo
echo "  the sweep's critical path in factorisations (logical workers in turn)"
echo "  case            serial sweep  phased total      W=1    W=2    W=4    W=8   W=16   W=32  (W=32)/serial"
echo "case,workers,critical_path,phased_total,serial_sweep" >"$model_csv"
for c in "block-M200:fe/block" "block-M800:fe/block --mesh 20x40" "triangle-M256:fe/triangle --mesh 16" \
         "triangle-M1024:fe/triangle --mesh 32"; do
    name=${c%%:*}
    cmd=${c#*:}
    serial=$(f22 "$($cmd --quiet --verbose 2>&1)")
    row=""
    total=""
    for w in 1 2 4 8 16 32; do
        out=$($cmd --quiet --workers "$w" --logical 2>&1)
        cp=$(crit "$out")
        total=$(f22 "$out")
        row="$row $(printf '%6s' "$cp")"
        echo "$name,$w,$cp,$total,$serial" >>"$model_csv"
    done
    printf '  %-15s %12s %13s %s  %13s\n' "$name" "$serial" "$total" "$row" \
        "$(awk -v a="$cp" -v b="$serial" 'BEGIN { printf "%.3f", a / b }')"
done

echo
echo "  the explorer's critical path in factorisations (drafts and sweeps on W logical workers)"
echo "  case            serial sweeps  phased total      W=1    W=2    W=4    W=8   W=16   W=32  caller's own"
echo "case,workers,critical_path,phased_total,serial_sweeps,calling_solver" >"$explore_csv"
xf() { printf '%s\n' "$1" | sed -n 's/.*psb_explore: .*factorisations \([0-9]*\).*/\1/p' | head -n 1; }
own() { printf '%s\n' "$1" | sed -n 's/.*(\([0-9]*\) of them on the calling solver).*/\1/p' | head -n 1; }
for c in "block-M200:fe/block --explore" "block-M800:fe/block --mesh 20x40 --explore" \
         "triangle-M256:fe/triangle --mesh 16 --explore" "triangle-M1024:fe/triangle --mesh 32 --explore"; do
    name=${c%%:*}
    cmd=${c#*:}
    serial=$(xf "$($cmd --quiet 2>&1)")
    row=""
    for w in 1 2 4 8 16 32; do
        out=$($cmd --quiet --workers "$w" --logical 2>&1)
        cp=$(crit "$out")
        row="$row $(printf '%6s' "$cp")"
        echo "$name,$w,$cp,$(xf "$out"),$serial,$(own "$out")" >>"$explore_csv"
    done
    printf '  %-15s %13s %13s %s  %12s\n' "$name" "$serial" "$(xf "$out")" "$row" "$(own "$out")"
done
fi

if command -v gnuplot >/dev/null 2>&1; then
    mkdir -p docs/img
    gnuplot <<GP
set terminal pngcairo size 720,480 font ",11"
set output "docs/img/workers_critical_path.png"
set datafile separator ","
set logscale xy 2
set xlabel "logical workers W"
set ylabel "factorisations on the critical path"
set title "Algorithm 2.2 on W workers: the longest worker's factorisations (dashed: serial sweep / 8)"
set key top right
set grid
set xtics (1, 2, 4, 8, 16, 32)
cases = "block-M200 block-M800 triangle-M256 triangle-M1024"
plot for [i = 1:4] "< grep '^".word(cases, i).",' $model_csv" using 2:3 with linespoints lc i title word(cases, i), \
     for [i = 1:4] "< grep '^".word(cases, i).",' $model_csv" using 2:(\$5 / 8) with lines dashtype 2 lc i notitle
set output "docs/img/explorer_critical_path.png"
set title "The explorer on W workers: the longest worker's factorisations (dashed: the caller's)"
plot for [i = 1:4] "< grep '^".word(cases, i).",' $explore_csv" using 2:3 with linespoints lc i title word(cases, i), \
     for [i = 1:4] "< grep '^".word(cases, i).",' $explore_csv" using 2:6 with lines dashtype 2 lc i notitle
GP
    echo
    echo "  wrote docs/img/workers_critical_path.png, explorer_critical_path.png"
fi
