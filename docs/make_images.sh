#!/bin/sh
# docs/make_images.sh - regenerate the README's pictures in docs/img/ (640x400 PNG, < 100 KB):
# builds the programs, runs each with --out into a scratch folder and renders its gnuplot script
# at the README's size. Needs gnuplot (Debian: apt-get install gnuplot-nox).
# Usage (from anywhere): sh docs/make_images.sh
set -eu
cd "$(dirname "$0")/.."
command -v gnuplot >/dev/null 2>&1 || {
    echo "make_images.sh: gnuplot not found; install it with: apt-get install gnuplot-nox" >&2
    exit 1
}
make examples >/dev/null
img=docs/img
mkdir -p "$img"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT INT TERM

# Render a gnuplot script written by an example: its pngcairo terminals are set to WxH
# (every "set terminal pngcairo size ..." line, noenhanced kept), in the script's folder.
# The two diagram panels (block, triangle) get wider gaps and taller margins for their titles,
# tick labels and a legend without a frame. The deformed bodies' panels are small at that size:
# they are drawn with gnuplot's built-in tiny font as a palette PNG (libgd's png terminal), which
# keeps the file small, with "branch " left out of their titles so that neighbours do not meet.
render() { # dir width height
    awk -v size="$2,$3" '
        /^set terminal pngcairo size/ { pending = 1; enh = /noenhanced/ ? " noenhanced" : ""; next }
        pending && /^set output .bodies\.png./ {
            print "set terminal png size " size " tiny"; print
            pending = 0; bodies = 1; next }
        pending { print "set terminal pngcairo size " size " font \",9\"" enh; pending = 0 }
        /^set multiplot layout 1,2/ {
            sub(/margins [0-9.,]*/, "margins 0.1,0.98,0.4,0.84"); sub(/spacing [0-9.,]*/, "spacing 0.15,0") }
        /^set key at screen/ { sub(/maxrows 2/, "maxrows 3"); sub(/ box opaque width 1/, "") }
        bodies && /^set title .branch / { sub(/branch /, "") }
        { print }' "$1/plot.gp" >"$1/plot_small.gp"
    (cd "$1" && gnuplot plot_small.gp)
}

# 01_branching: the four rays it finds, drawn in the (x1, x2) plane at g = 1 (ray = t / t_g).
mkdir -p "$scratch/01"
./examples/01_branching --out "$scratch/01" >/dev/null
cat >"$scratch/01/plot.gp" <<'GP'
set datafile separator ','
stats 'branches_01.csv' every ::1 using 1 nooutput  # before the ranges, which it obeys
last = int(STATS_max)
set terminal pngcairo size 640,400 font ',9'
set output 'branches.png'
set linetype 1 lc rgb '#0072B2'  # Okabe-Ito without its yellow, as the examples' own plots
set linetype 2 lc rgb '#D55E00'
set linetype 3 lc rgb '#009E73'
set linetype 4 lc rgb '#CC79A7'
set linetype 5 lc rgb '#E69F00'
set linetype 6 lc rgb '#56B4E9'
set linetype cycle 6
set title 'examples/01\_branching: the four branches leaving the origin, at g = 1'
set xlabel 'x_1'
set ylabel 'x_2'
set grid
set key at 1.28,0.38 right  # below the incoming ray, above the x1 axis
set label 'branch 1: x = 0 for every g' at 0.04,0.06
set size ratio -1
set xrange [-0.1:1.3]
set yrange [-0.1:1.3]
plot for [k=0:last] 'branches_01.csv' every ::1 using ($1==k?0:1/0):(0):($2/$4):($3/$4) \
       with vectors head filled lw 2 lc k+1 title sprintf(k == 0 ? 'branch %d (incoming)' : 'branch %d', k), \
     for [k=0:last] 'branches_01.csv' every ::1 using ($1==k?$2/$4:1/0):($3/$4) \
       with points pt 7 ps 1.5 lc k+1 notitle
GP
(cd "$scratch/01" && gnuplot plot.gp)
cp "$scratch/01/branches.png" "$img/01_branching.png"

# block (M200, the example's defaults): the six branches' diagram and the deformed bodies.
mkdir -p "$scratch/block"
./fe/block --quiet --out "$scratch/block" >/dev/null
render "$scratch/block" 640 400
cp "$scratch/block/diagram.png" "$img/block_diagram.png"
cp "$scratch/block/bodies.png" "$img/block_bodies.png"

# triangle (the example's default mesh, 32 x 32): the four branches' diagram.
mkdir -p "$scratch/triangle"
./fe/triangle --quiet --out "$scratch/triangle" >/dev/null
render "$scratch/triangle" 640 400
cp "$scratch/triangle/diagram.png" "$img/triangle_diagram.png"

# triangle --problem fold --map on the paper's M4096: the two limit points against the friction
# coefficient, to where they merge (about a minute).
mkdir -p "$scratch/triangle_map"
OPENBLAS_NUM_THREADS=1 ./fe/triangle --quiet --mesh 64 --problem fold --map --out "$scratch/triangle_map" >/dev/null
render "$scratch/triangle_map" 640 400
cp "$scratch/triangle_map/fold_map.png" "$img/triangle_fold_map.png"

# 02_explore and 03_pitchforks: the graphs psb_explore finds (a PC1 point with four rays; three
# pitchforks and six folds), and block --explore: the block's diagram from one start point.
for ex in 02_explore 03_pitchforks; do
    mkdir -p "$scratch/$ex"
    ./examples/$ex --out "$scratch/$ex" >/dev/null
    render "$scratch/$ex" 640 400
    cp "$scratch/$ex/diagram.png" "$img/$ex.png"
done
mkdir -p "$scratch/block_explore"
./fe/block --explore --quiet --out "$scratch/block_explore" >/dev/null
render "$scratch/block_explore" 640 400
cp "$scratch/block_explore/diagram.png" "$img/block_explore.png"

# 04_evolution: the truss's two snap-throughs, the time steps in order and the traced paths.
mkdir -p "$scratch/04"
./examples/04_evolution --out "$scratch/04" >/dev/null
render "$scratch/04" 640 400
cp "$scratch/04/evolution.png" "$img/04_evolution.png"

# quasistatic: the load-displacement path through the snap-through, the step's static diagram.
mkdir -p "$scratch/quasistatic"
./fe/quasistatic --quiet --out "$scratch/quasistatic" >/dev/null
render "$scratch/quasistatic" 640 400
cp "$scratch/quasistatic/quasistatic.png" "$img/quasistatic.png"

# triangle --count-map: the branches at gamma = 0 as H1 of the load runs across the window where
# three solutions exist (M1024), with the two located changes.
mkdir -p "$scratch/count_map"
./fe/triangle --mesh 32 --count-map 24.6:26.4 --count-samples 19 --quiet --out "$scratch/count_map" >/dev/null
cat >"$scratch/count_map/plot.gp" <<'GP'
set datafile separator ','
set terminal pngcairo size 640,400 font ',9'
set output 'count_map.png'
set title 'fe/triangle --mesh 32 --count-map: branches at {/Symbol g} = 0 for the load {/Symbol g} (-H1, -7.5)'
set xlabel 'H1'
set ylabel 'branches at the nonsmooth point'
set yrange [0:5]
set ytics 1
set grid
set key at 25.6,1.3 center
plot 'count_map.csv' every ::1 using 1:2 with points pt 7 ps 1.2 lc rgb '#0072B2' title 'count at each sample', \
     'count_changes.csv' every ::1 using 1:(4.6):(0):(-4.6) with vectors nohead dt 2 lw 1.5 lc rgb '#D55E00' title 'changes (psb\_count\_map)'
GP
(cd "$scratch/count_map" && gnuplot plot.gp)
cp "$scratch/count_map/count_map.png" "$img/triangle_count_map.png"

ls -l "$img"/*.png
