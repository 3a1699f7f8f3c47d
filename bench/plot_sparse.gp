# Log-log plot of bench_sparse's factorisation times: gnuplot -e "csv='bench/out/sparse_large.csv'"
#   bench/plot_sparse.gp   writes docs/img/sparse_factor.png
if (!exists("csv")) csv = 'bench/out/sparse_large.csv'
set datafile separator ','
set terminal pngcairo size 640,420 font ',10'
set output 'docs/img/sparse_factor.png'
set logscale xy
set xlabel 'N (unknowns)'
set ylabel 'one factorisation [s]'
set key top left
set grid
set title 'Bordered Jacobian factorisations (reference BLAS)'
plot csv using (strcol(1) eq 'block' ? $3 : 1/0):5 with linespoints lc 1 pt 5 title 'block, banded', \
     csv using (strcol(1) eq 'block' ? $3 : 1/0):6 with linespoints lc 2 pt 5 title 'block, UMFPACK', \
     csv using (strcol(1) eq 'block' ? $3 : 1/0):7 with linespoints lc 3 pt 5 title 'block, KLU', \
     csv using (strcol(1) eq 'triangle' ? $3 : 1/0):5 with linespoints lc 1 pt 7 dt 2 title 'triangle, banded', \
     csv using (strcol(1) eq 'triangle' ? $3 : 1/0):6 with linespoints lc 2 pt 7 dt 2 title 'triangle, UMFPACK', \
     csv using (strcol(1) eq 'triangle' ? $3 : 1/0):7 with linespoints lc 3 pt 7 dt 2 title 'triangle, KLU'
