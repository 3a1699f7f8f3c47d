#!/usr/bin/python3
"""block.py - the block of Section 3.2 of Ligursky & Renard solved with GetFEM's own
continuation and non-smooth branching (getfem.ContStruct, 'non-smooth', singularities 2), the
reference for bench/getfem_side_by_side.sh. Written here from GetFEM's documented Python API.

The problem is examples/block.c's (examples/fe.h, fe_block_model): a 40 mm x 80 mm block, NX x NY
bilinear squares, 3 x 3 Gauss points, plane-strain Ciarlet-Geymonat (lambda = 4000, mu = 120,
a = 30 N/mm^2), fixed on top by Lagrange multipliers (bilinear traces), loaded by
h = gamma (-2, 0.12 (x1 - 20)) N/mm^2 on both lateral sides, on a rigid foundation x2 >= 0 with
nodal contact and Coulomb friction F = 1 in the non-symmetric Alart-Curnier form of eq. (2)
(GetFEM's nodal contact brick, augmented version 1), r = 10.

The run is the same as `examples/block --mesh NXxNY`: Newton at gamma = -1 from zero (branch 1),
continuation towards gamma = 0, GetFEM's Algorithms 2.1-2.2 at the nonsmooth point (h = 5e-7,
15 halvings, h_init = 5e-4, cosine threshold 0.99999, n_dir = 20, n_span = 15 unless given),
then every branch found is traced to |gamma| = 1. Inner product kappa = 1/N on all unknowns, 1 on
gamma (GetFEM weighs multipliers like displacements). GetFEM's other step controls keep their
defaults (h_inc 1.3, h_dec 0.5, thr_iter 4, max_iter 10); the tracing uses a second ContStruct
with GetFEM's default min_cos 0.9 and no singular-point tests, GetFEM at its fastest here.
GetFEM returns a tangent per one-sided branch it finds; each is traced (on M200 12 tangents for
six branches: the sticking branches come back four times each); the tracing time of the first
tangent of each distinct branch is printed too.

The branches are numbered as in the paper (1-3 forced right, gamma < 0; 4-6 left; lower vertex on
that side lifted, sticking, slipping). --compare FILE (examples/block's --out DIR/branches.csv)
prints the end values beside pscbranch's.

Usage: /usr/bin/python3 bench/getfem/block.py [--mesh NXxNY] [--ndir N] [--nspan N]
           [--lsolver mumps|superlu|auto] [--trace-min-cos C] [--single-struct]
           [--compare FILE] [--verbose]
--trace-min-cos: GetFEM's min_cos while tracing the branches (default 0.9, GetFEM's default);
--single-struct: trace with the branching's ContStruct too (min_cos 0.99999 and singular-point
tests at every step), slower.
Prints "getfem-block: ... time S s" lines the side-by-side script parses; exit status 0 when the
six branches are found and end on |gamma| = 1.
"""
import argparse
import sys
import time

import numpy as np
import getfem as gf

TOP, BOTTOM, LEFT, RIGHT = 1, 2, 3, 4
LX, LY = 40.0, 80.0
LAMBDA, MU, A = 4000.0, 120.0, 30.0
R_AUG, FRICTION = 10.0, 1.0


def build(nx, ny):
    """The model; returns (md, mfu, contact dofs of the two lower vertices)."""
    m = gf.Mesh('cartesian', np.linspace(0, LX, nx + 1), np.linspace(0, LY, ny + 1))
    for region, normal in ((TOP, [0, 1]), (BOTTOM, [0, -1]), (LEFT, [-1, 0]), (RIGHT, [1, 0])):
        m.set_region(region, m.outer_faces_with_direction(normal, 0.01))
    m.region_merge(LEFT, RIGHT)  # LEFT now holds both lateral sides
    mfu = gf.MeshFem(m, 2)
    mfu.set_fem(gf.Fem('FEM_QK(2,1)'))
    mim = gf.MeshIm(m, gf.Integ('IM_GAUSS_PARALLELEPIPED(2,5)'))  # 3 x 3 points, 3 per edge

    md = gf.Model('real')
    md.add_fem_variable('u', mfu)
    # Ciarlet-Geymonat in plane strain (Ft = diag(F, 1)): P = 2(a + b) F + (2(b + c) J^2 - d) F^-T
    b = MU / 2 - A
    c = LAMBDA / 4 - MU / 2 + A
    d = LAMBDA / 2 + MU
    md.add_macro('F', 'Id(2) + Grad_u')
    md.add_nonlinear_term(mim, '(%.17g*F + (%.17g*sqr(Det(F)) - %.17g)*Inv(F)\'):Grad_Test_u'
                          % (2 * (A + b), 2 * (b + c), d))
    md.add_Dirichlet_condition_with_multipliers(mim, 'u', mfu, TOP)
    md.add_initialized_data('gamma', [0.0])
    md.add_source_term(mim, 'gamma*[-2, 0.12*(X(1)-20)].Test_u', LEFT)
    ncontact = len(mfu.basic_dof_on_region(BOTTOM)) // 2
    md.add_variable('lambda_n', ncontact)
    md.add_variable('lambda_t', ncontact)
    md.add_initialized_data('r', [R_AUG])
    md.add_initialized_data('friction', [FRICTION])
    md.add_nodal_contact_with_rigid_obstacle_brick(mim, 'u', 'lambda_n', 'lambda_t', 'r', 'friction',
                                                   BOTTOM, 'y', 1)
    # the two lower vertices' displacement dofs (x, y components)
    dofs = mfu.basic_dof_on_region(BOTTOM)
    xy = mfu.basic_dof_nodes(dofs)
    corner = {}
    for k, dof in enumerate(dofs):
        side = 'left' if xy[0, k] < 1e-9 else ('right' if xy[0, k] > LX - 1e-9 else None)
        if side:
            corner.setdefault(side, []).append(int(dof))
    return md, mfu, {s: sorted(v) for s, v in corner.items()}


def vertex_values(md, x, corner):
    """u1, u2 of the lower left and lower right vertices in the state x."""
    iu = md.interval_of_variable('u')[0]
    return [x[iu + corner[s][k]] for s in ('left', 'right') for k in (0, 1)]


def classify(gamma, v, tol=1e-6):
    """Paper numbering from the lower vertex on the side the block is forced to."""
    right = gamma < 0
    u1, u2 = (v[2], v[3]) if right else (v[0], v[1])
    kind = 1 if u2 > tol else (2 if abs(u1) <= tol else 3)
    return (0 if right else 3) + kind


def main():
    p = argparse.ArgumentParser()
    p.add_argument('--mesh', default='10x20')
    p.add_argument('--ndir', type=int, default=20)
    p.add_argument('--nspan', type=int, default=15)
    p.add_argument('--lsolver', default='mumps')  # Debian's 5.4.2 crashes with superlu here
    p.add_argument('--compare')
    p.add_argument('--trace-min-cos', type=float, default=0.9)
    p.add_argument('--single-struct', action='store_true')
    p.add_argument('--verbose', action='store_true')
    a = p.parse_args()
    nx, ny = (int(s) for s in a.mesh.split('x'))
    gf.util_trace_level(0)
    gf.util_warning_level(0)

    t_start = time.process_time()
    w_start = time.perf_counter()
    md, mfu, corner = build(nx, ny)
    n = md.nbdof()
    print('getfem-block: M%d (%d x %d Q1, 3x3 Gauss), N = %d unknowns, GetFEM %s, linear solver %s'
          % (nx * ny, nx, ny, n, gf.__version__ if hasattr(gf, '__version__') else '5.4', a.lsolver))
    print('  continuation: h_min = 5e-7 (= the paper\'s h), h_init = 5e-4, min_cos = 0.99999, n_dir = %d, n_span = %d'
          % (a.ndir, a.nspan))

    # Newton at gamma = -1 on branch 1 (pscbranch's Newton from zero lands there; GetFEM's from
    # zero lands on branch 2, so it starts from the sheared guess u = 3 (1 - x2/80) (1, 0) with
    # its systematic line search, and the start is checked)
    xy = mfu.basic_dof_nodes()
    md.set_variable('u', np.where(np.arange(mfu.nbdof()) % 2 == 0, 3 * (1 - xy[1] / LY), 0.0))
    md.set_variable('gamma', [-1.0])
    md.solve('max_res', 1e-9, 'max_iter', 50, 'lsolver', a.lsolver, 'lsearch', 'systematic')
    x = md.from_variables()
    gamma = -1.0
    if classify(gamma, vertex_values(md, x, corner)) != 1:
        print('getfem-block: FAILED (Newton at gamma = -1 did not land on branch 1)')
        return 1
    common = ('lsolver', a.lsolver, 'h_init', 5e-4, 'h_max', 0.2, 'h_min', 5e-7, 'h_inc', 1.3, 'h_dec', 0.5,
              'max_iter', 10, 'thr_iter', 4, 'max_res', 1e-9, 'max_diff', 1e-9, 'max_res_solve', 1e-10,
              'non-smooth') + (('noisy',) if a.verbose else ())
    # the approach and the branching: GetFEM runs Algorithms 2.1-2.2 inside a continuation step
    # that cannot go on, with the step's min_cos as c_diff
    S = gf.ContStruct(md, 'gamma', 1.0 / n, *common, 'min_cos', 0.99999, 'singularities', 2,
                      'nb_dir', a.ndir, 'nb_span', a.nspan)
    # the tracing: GetFEM's default min_cos, no tests for singular points (pscbranch's tracing
    # makes none either); kinks are passed by GetFEM's non-smooth tangent switch
    T = gf.ContStruct(md, 'gamma', 1.0 / n, *common, 'min_cos', a.trace_min_cos, 'singularities', 0)
    if a.single_struct:  # one ContStruct for everything, as a single set of options would give
        T = S

    def step(x, gamma, tx, tgamma, h, cs=S):
        out = cs.Moore_Penrose_continuation(x, gamma, tx, tgamma, h)
        return out[0], out[1], out[2], out[3], out[4], (out[6] if len(out) > 6 else '')

    # continuation towards gamma = 0 until GetFEM's non-smooth branching has run there
    t_newton = time.process_time()
    tx, tgamma, h = S.init_Moore_Penrose_continuation(x, gamma, 1.0)
    approach_steps = 0
    label = ''
    while True:
        x, gamma, tx, tgamma, h, label = step(x, gamma, tx, tgamma, h)
        approach_steps += 1
        if h == 0 or label == 'non-smooth bifurcation point' or approach_steps > 2000:
            break
    if label != 'non-smooth bifurcation point':
        print('getfem-block: FAILED (no non-smooth bifurcation point detected on the way to gamma = 0; %d steps, gamma = %g)'
              % (approach_steps, gamma))
        return 1
    xs, gs, txs, tgs = S.sing_data()
    txs = np.atleast_2d(np.asarray(txs))
    if txs.shape[0] != n and txs.shape[1] == n:
        txs = txs.T
    tgs = np.atleast_1d(np.asarray(tgs, dtype=float))
    nfound = len(tgs)
    t_branch = time.process_time()
    print('  approach: %d steps; non-smooth point at gamma = %.3e; %d one-sided branches found there'
          ' (the input branch among them)' % (approach_steps, gs, nfound))

    # trace every branch from the point to |gamma| = 1, the last point re-solved at gamma = +-1
    ends = []
    for k in range(nfound):
        tk = time.process_time()
        x, gamma, tx, tgamma, h = np.array(xs), float(gs), np.array(txs[:, k]), float(tgs[k]), 5e-4
        steps = 0
        prev = None
        while abs(gamma) < 1 and steps < 2000:
            prev = (x, gamma)
            x, gamma, tx, tgamma, h, _ = step(x, gamma, tx, tgamma, h, T)
            steps += 1
            if h == 0:
                break
        if abs(gamma) < 1:
            print('  branch tangent %d: continuation failed at gamma = %g after %d steps' % (k, gamma, steps))
            ends.append(None)
            continue
        g1 = 1.0 if gamma > 0 else -1.0
        s = (g1 - prev[1]) / (gamma - prev[1])
        md.to_variables(prev[0] + s * (x - prev[0]))
        md.set_variable('gamma', [g1])
        nit, conv = md.solve('max_res', 1e-9, 'max_iter', 50, 'lsolver', a.lsolver)
        xe = md.from_variables()
        md.assembly('build_rhs')
        res = np.linalg.norm(md.rhs())
        v = vertex_values(md, xe, corner)
        ends.append((classify(g1, v), g1, v, steps, res, time.process_time() - tk))
    t_end = time.process_time()
    w_end = time.perf_counter()

    ref = {}
    if a.compare:
        with open(a.compare) as f:
            next(f)
            for line in f:
                c = line.strip().split(',')
                ref[int(c[0])] = [float(t) for t in c[2:6]]
    print('\n  branch  gamma   u1_left     u2_left     u1_right    u2_right    steps  |H|      %s'
          % ('max |diff| to pscbranch' if ref else ''))
    numbers = set()
    first = {}
    for e in sorted((x for x in ends if x), key=lambda e: e[0]):
        num, g1, v, steps, res, secs = e
        first.setdefault(num, secs)
        diff = ''
        if num in ref:
            diff = '%.1e' % max(abs(p - q) for p, q in zip(v, ref[num]))
        print('  %-6d  %+5.2f  %+.4e %+.4e %+.4e %+.4e %5d  %.1e  %s' % (num, g1, *v, steps, res, diff))
        numbers.add(num)
    ok = numbers == {1, 2, 3, 4, 5, 6} and all(e and e[4] < 1e-6 for e in ends)
    if ref:
        worst = max((max(abs(p - q) for p, q in zip(e[2], ref[e[0]])) for e in ends if e and e[0] in ref), default=float('nan'))
        print('  against pscbranch (%s): branches %s here, %s there; largest end-value difference %.1e mm'
              % (a.compare, sorted(numbers), sorted(ref), worst))
    print('\n  %d distinct branches (paper: 6) from %d tangents; time %.2f s (CPU, set-up to last branch), wall %.2f s'
          % (len(numbers), nfound, t_end - t_start, w_end - w_start))
    print('  phases (CPU s): set-up and Newton %.2f, approach and branching %.2f, tracing all %d tangents %.2f'
          ' (one per distinct branch: %.2f)'
          % (t_newton - t_start, t_branch - t_newton, nfound, t_end - t_branch, sum(first.values())))
    print('getfem-block: %s' % ('OK (six branches as in the paper)' if ok else 'FAILED (branches differ from the paper)'))
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main())
