#!/usr/bin/python3
"""fold.py - the triangle's fold study (Section 3.3 of Ligursky & Renard, Fig. 9) traced with GetFEM's
own continuation, the reference for bench/getfem_side_by_side.sh (FOLD=N). Written here from
GetFEM's documented Python API.

The model is triangle.py's with the load of fe/triangle's --problem fold,
h(gamma) = (-20 - 10 gamma, -7.5) GN/m^2 on the vertical leg. The run is the example's: Newton at
gamma = -3 (pushing; Newton from zero), then GetFEM's continuation with its tangent switch for
non-smooth problems ('non-smooth') and its limit-point test ('singularities', 1) up to gamma = 1.
H is piecewise linear, so the limit points are kinks where the tangent's gamma component changes
sign; each is reported at the gamma extremum of the two points on either side. The options are
the example's: h_init 1e-2, h_max 0.2, h_min 1e-9 (the kinks are located to it), residual and
correction tolerances 1e-9, kappa = 1/N (GetFEM's sc_fac), min_cos = 1 - 1e-10 (pscbranch's
c_diff: a step whose tangent turns is retaken shorter, as pscbranch locates a kink), GetFEM's
defaults for the rest (h_inc 1.3, h_dec 0.5, max_iter 10, thr_iter 4).

Usage: /usr/bin/python3 bench/getfem/fold.py [--mesh N] [--lsolver mumps|superlu|auto]
           [--min-cos C] [--compare FILE] [--verbose]
--compare takes fe/triangle --problem fold's --out DIR/folds.csv.
"""
import argparse
import sys
import time

import getfem as gf

import triangle

PAPER = {64: (0.56541, 0.66665), 128: (0.5883, 0.70731), 256: (0.59996, 0.73289), 512: (0.60585, 0.7499)}


def read_folds(path):
    """fe/triangle's folds.csv: the limit points' gamma, sorted."""
    with open(path) as f:
        next(f)
        return sorted(float(line.split(',')[1]) for line in f if line.strip())


def main():
    p = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    p.add_argument('--mesh', type=int, default=64)
    # Debian's GetFEM 5.4.2 crashes (SIGSEGV) in SuperLU on these models: MUMPS (sequential)
    p.add_argument('--lsolver', default='mumps')
    p.add_argument('--min-cos', type=float, default=1 - 1e-10)
    p.add_argument('--compare')
    p.add_argument('--verbose', action='store_true')
    a = p.parse_args()
    n = a.mesh
    gf.util_trace_level(0)
    gf.util_warning_level(0)
    t_start, w_start = time.process_time(), time.perf_counter()
    md, keep, _, ncontact = triangle.build(n, '[-20 - 10*gamma, -7.5]')
    N = md.nbdof()
    print('getfem-fold: M%d (%d subdivisions per leg, P1), N = %d unknowns, %d contact nodes, linear solver %s'
          % (n * n, n, N, ncontact, a.lsolver))
    md.set_variable('gamma', [-3.0])
    md.solve('max_res', 1e-9, 'max_iter', 50, 'lsolver', a.lsolver)
    x, gamma = md.from_variables(), -3.0
    S = gf.ContStruct(md, 'gamma', 1.0 / N, 'lsolver', a.lsolver, 'h_init', 1e-2, 'h_max', 0.2, 'h_min', 1e-9,
                      'h_inc', 1.3, 'h_dec', 0.5, 'max_iter', 10, 'thr_iter', 4, 'max_res', 1e-9, 'max_diff', 1e-9,
                      'max_res_solve', 1e-10, 'min_cos', a.min_cos, 'non-smooth', 'singularities', 1,
                      *(('noisy',) if a.verbose else ()))
    t_newton = time.process_time()
    tx, tgamma, h = S.init_Moore_Penrose_continuation(x, gamma, 1.0)
    steps, labels, folds = 0, 0, []
    while gamma < 1 and h != 0 and steps < 20000:
        out = S.Moore_Penrose_continuation(x, gamma, tx, tgamma, h)
        x1, g1, tx1, tg1, h = out[0], float(out[1]), out[2], float(out[3]), out[4]
        label = out[6] if len(out) > 6 else ''
        steps += 1
        if h == 0:
            break
        if label:
            labels += 1
        if (tg1 > 0) != (tgamma > 0):  # gamma has an extremum between the two points
            folds.append(max(gamma, g1) if tgamma > 0 else min(gamma, g1))
        if a.verbose:
            print('  step %d: gamma %.9f, t_gamma %+.3e, h %.3e %s' % (steps, g1, tg1, h, label))
        x, gamma, tx, tgamma = x1, g1, tx1, tg1
    t_end, w_end = time.process_time(), time.perf_counter()
    ok = gamma >= 1 and len(folds) == 2
    print('  continuation from gamma = -3: %s after %d steps, gamma = %.8g; GetFEM flagged %d singular points'
          % ('reached gamma = 1' if gamma >= 1 else 'FAILED', steps, gamma, labels))
    print('  limit points (gamma): %s' % ', '.join('%.5f' % g for g in folds) if folds else '  limit points: none')
    if n in PAPER:
        print('   (paper, this mesh: %.5f, %.5f)' % PAPER[n])
    if a.compare:
        ref = read_folds(a.compare)
        same = len(ref) == len(folds)
        worst = max((abs(u - v) for u, v in zip(sorted(folds), ref)), default=0.0) if same else float('inf')
        ok = ok and same and worst <= 1e-5
        print('  against pscbranch (%s): %d limit points there; largest limit-point difference %.1e'
              % (a.compare, len(ref), worst))
    print('\n  %d limit points; time %.2f s (CPU, set-up to gamma = 1), wall %.2f s' % (len(folds), t_end - t_start, w_end - w_start))
    print('  phases (CPU s): set-up and Newton %.2f, continuation %.2f' % (t_newton - t_start, t_end - t_newton))
    print('getfem-fold: %s' % ('OK (two limit points%s)' % (', as pscbranch\'s' if a.compare else '') if ok
                               else 'FAILED'))
    del keep
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
