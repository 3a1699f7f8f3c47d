"""gfcont.py - the run shared by block.py and triangle.py, on GetFEM's documented Python API:
Newton at gamma = -1, GetFEM's continuation (getfem.ContStruct, 'non-smooth', singularities 2)
towards the nonsmooth point at gamma = 0, where GetFEM itself runs Algorithms 2.1-2.2 of Ligursky
& Renard inside the continuation step that cannot go on; then every tangent it returns is traced
to |gamma| = 1 and the end point re-solved at gamma = +-1 exactly. Times, branch table and the
comparison with pscbranch's end values (examples' --out DIR/branches.csv) are printed.

GetFEM's parameters mapped from pscbranch's examples: the paper's h of Algorithms 2.1-2.2 is
GetFEM's h_min (Algorithm 2.1 then halves it 15 times), h_init its first trial step, c_diff its
min_cos, n_dir / n_span its nb_dir / nb_span; the inner product is kappa = 1/N on all unknowns
(GetFEM weighs multipliers like displacements), 1 on gamma. The other step controls keep
GetFEM's defaults (h_inc 1.3, h_dec 0.5, thr_iter 4, max_iter 10), h_max = 0.2 as in the
examples. min_cos is also GetFEM's test for accepting a continuation step, so the tracing after
the branching uses a second ContStruct with GetFEM's default min_cos 0.9 and no tests for singular
points (pscbranch's tracing makes none either): GetFEM at its fastest here. --single-struct
traces with the branching's ContStruct instead (the paper's single set of options).
"""
import argparse
import time

import numpy as np
import getfem as gf


def arguments(doc, mesh, ndir, nspan):
    p = argparse.ArgumentParser(description=doc.split('\n')[0])
    p.add_argument('--mesh', default=mesh)
    p.add_argument('--ndir', type=int, default=ndir)
    p.add_argument('--nspan', type=int, default=nspan)
    # Debian's GetFEM 5.4.2 crashes (SIGSEGV) in SuperLU on these models: MUMPS (sequential)
    p.add_argument('--lsolver', default='mumps')
    p.add_argument('--trace-min-cos', type=float, default=0.9)
    p.add_argument('--single-struct', action='store_true')
    p.add_argument('--compare')
    p.add_argument('--verbose', action='store_true')
    return p.parse_args()


def vertex_values(md, x, dofs):
    """Displacements at the given dofs of variable u in the state x."""
    iu = md.interval_of_variable('u')[0]
    return [float(x[iu + d]) for d in dofs]


def read_reference(path):
    """pscbranch's branches.csv: {branch number: [u1_left, u2_left, u1_right, u2_right]}."""
    ref = {}
    with open(path) as f:
        next(f)
        for line in f:
            c = line.strip().split(',')
            ref[int(c[0])] = [float(t) for t in c[2:6]]
    return ref


def run(name, a, md, corner_dofs, classify, expected, unit, start, h_branch, c_diff, tol=1e-8, stop_at_kink=False):
    """The whole run; returns the exit status. start(md) puts the model at its Newton solution at
    gamma = -1 (and returns False when it is not the input branch); corner_dofs are the u dofs
    (u1, u2 of the first and the last contact node) printed and compared; classify(gamma, values)
    gives the paper's branch number; expected: the set of numbers the paper finds.
    stop_at_kink: GetFEM's continuation passes this point by its tangent switch without flagging
    it (its test function changes sign an even number of times), so the approach is made without
    the tangent switch (no 'non-smooth') up to the step that fails within h_min of the point, and
    that step is retaken by the branching ContStruct with h_max < 0.9 h_min, which disables the
    tangent switch: the step fails there and GetFEM runs its Algorithms 2.1-2.2."""
    gf.util_trace_level(0)
    gf.util_warning_level(0)
    n = md.nbdof()
    t_start = time.process_time()
    w_start = time.perf_counter()
    if not start(md):
        print('getfem-%s: FAILED (Newton at gamma = -1 did not land on the input branch)' % name)
        return 1
    x = md.from_variables()
    gamma = -1.0
    common = ('lsolver', a.lsolver, 'h_init', 5e-4, 'h_max', 0.2, 'h_min', h_branch, 'h_inc', 1.3, 'h_dec', 0.5,
              'max_iter', 10, 'thr_iter', 4, 'max_res', 1e-9, 'max_diff', 1e-9, 'max_res_solve', 1e-10,
              'non-smooth') + (('noisy',) if a.verbose else ())
    branching = ('min_cos', c_diff, 'singularities', 2, 'nb_dir', a.ndir, 'nb_span', a.nspan)
    S = gf.ContStruct(md, 'gamma', 1.0 / n, *common, *branching)
    if stop_at_kink:
        smooth = tuple(o for o in common if o != 'non-smooth')
        A = gf.ContStruct(md, 'gamma', 1.0 / n, *smooth, 'min_cos', c_diff, 'singularities', 0)
        S = gf.ContStruct(md, 'gamma', 1.0 / n, *common, *branching, 'h_max', 0.5 * h_branch)
    T = S if a.single_struct else gf.ContStruct(md, 'gamma', 1.0 / n, *common, 'min_cos', a.trace_min_cos,
                                                'singularities', 0)
    print('  GetFEM continuation: h_min = %g (the paper\'s h), h_init = 5e-4, min_cos = %.10g (c_diff), nb_dir = %d, '
          'nb_span = %d; tracing %s' % (h_branch, c_diff, a.ndir, a.nspan,
                                        'with the same ContStruct' if a.single_struct
                                        else 'min_cos %g, no singular-point tests' % a.trace_min_cos))

    def step(x, gamma, tx, tgamma, h, cs):
        out = cs.Moore_Penrose_continuation(x, gamma, tx, tgamma, h)
        return out[0], out[1], out[2], out[3], out[4], (out[6] if len(out) > 6 else '')

    t_newton = time.process_time()
    tx, tgamma, h = S.init_Moore_Penrose_continuation(x, gamma, 1.0)
    approach_steps, label = 0, ''
    if stop_at_kink:
        while approach_steps < 5000:
            x1, g1, tx1, tg1, h1, _ = step(x, gamma, tx, tgamma, h, A)
            approach_steps += 1
            if a.verbose:
                print('  approach step %d: gamma %.6e -> %.6e, h %.3e -> %.3e' % (approach_steps, gamma, g1, h, h1))
            if h1 == 0:
                break  # the step failed within h_min of the point: (x, gamma) is the last couple
            if g1 * gamma <= 0:
                h /= 2  # a step past gamma = 0: retaken shorter
                continue
            x, gamma, tx, tgamma, h = x1, g1, tx1, tg1, h1
        x, gamma, tx, tgamma, h, label = step(x, gamma, tx, tgamma, h_branch, S)
        approach_steps += 1
        if len(np.atleast_1d(S.sing_data()[3])) > 0:
            label = 'non-smooth bifurcation point'  # GetFEM's Algorithms 2.1-2.2 have run
    while h != 0 and label != 'non-smooth bifurcation point' and approach_steps < 5000:
        x, gamma, tx, tgamma, h, label = step(x, gamma, tx, tgamma, h, S)
        approach_steps += 1
        if a.verbose:
            print('  branching struct step %d: gamma %.6e, h %.3e, %s' % (approach_steps, gamma, h, label))
    if label != 'non-smooth bifurcation point':
        print('getfem-%s: FAILED (no non-smooth bifurcation point on the way to gamma = 0; %d steps, gamma = %g)'
              % (name, approach_steps, gamma))
        return 1
    xs, gs, txs, tgs = S.sing_data()
    txs = np.atleast_2d(np.asarray(txs))
    if txs.shape[0] != n:
        txs = txs.T
    tgs = np.atleast_1d(np.asarray(tgs, dtype=float))
    t_branch = time.process_time()
    print('  approach: %d continuation steps%s; non-smooth point at gamma = %.3e; %d one-sided branch tangents there'
          ' (the input branch among them)'
          % (approach_steps, ' (GetFEM\'s "Continuation has failed!" above: the approach stopping at the point,'
             ' then the branching forced there)' if stop_at_kink else '', gs, len(tgs)))

    ends = []
    for k in range(len(tgs)):
        tk = time.process_time()
        x, gamma, tx, tgamma, h = np.array(xs), float(gs), np.array(txs[:, k]), float(tgs[k]), 5e-4
        steps, prev = 0, None
        while abs(gamma) < 1 and h != 0 and steps < 5000:
            prev = (x, gamma)
            x, gamma, tx, tgamma, h, _ = step(x, gamma, tx, tgamma, h, T)
            steps += 1
        if abs(gamma) < 1:
            print('  tangent %d: continuation failed at gamma = %g after %d steps' % (k, gamma, steps))
            continue
        # the end point: interpolated to gamma = +-1 and re-solved there by GetFEM's Newton
        g1 = 1.0 if gamma > 0 else -1.0
        s = (g1 - prev[1]) / (gamma - prev[1])
        md.to_variables(prev[0] + s * (x - prev[0]))
        md.set_variable('gamma', [g1])
        md.solve('max_res', 1e-10, 'max_iter', 50, 'lsolver', a.lsolver)
        xe = md.from_variables()
        md.assembly('build_rhs')
        res = float(np.linalg.norm(md.rhs()))
        v = vertex_values(md, xe, corner_dofs)
        ends.append((classify(g1, v), k, g1, v, steps, res, time.process_time() - tk))
    t_end = time.process_time()
    w_end = time.perf_counter()

    ref = read_reference(a.compare) if a.compare else {}
    print('\n  branch  tangent  gamma   u1 first    u2 first    u1 last     u2 last     steps  |H|      %s'
          % ('max |diff| to pscbranch' if ref else ''))
    print('  (u at the first and the last contact node, %s)' % unit)
    first = {}
    worst = 0.0
    for num, k, g1, v, steps, res, secs in sorted(ends):
        first.setdefault(num, secs)
        diff = ''
        if num in ref:
            d = max(abs(p - q) for p, q in zip(v, ref[num]))
            worst = max(worst, d)
            diff = '%.1e' % d
        print('  %-6d  %7d  %+5.2f  %+.4e %+.4e %+.4e %+.4e %5d  %.1e  %s' % (num, k, g1, *v, steps, res, diff))
    numbers = set(e[0] for e in ends)
    ok = len(ends) == len(tgs) and all(e[5] <= tol for e in ends)
    paper = numbers == expected
    if ref:  # coarse meshes have fewer branches than the paper's (pscbranch's examples say so)
        same = numbers == set(ref)
        ok = ok and same
        print('  against pscbranch (%s): branches %s here, %s there (%s); largest end-value difference %.1e %s'
              % (a.compare, sorted(numbers), sorted(ref), 'the same' if same else 'DIFFERENT', worst, unit))
    else:
        ok = ok and paper
    print('\n  %d distinct branches (paper: %d) from %d tangents; time %.2f s (CPU, set-up to last branch), wall %.2f s'
          % (len(numbers), len(expected), len(tgs), t_end - t_start, w_end - w_start))
    print('  phases (CPU s): Newton %.2f, approach and branching %.2f, tracing all %d tangents %.2f'
          ' (one per distinct branch: %.2f)'
          % (t_newton - t_start, t_branch - t_newton, len(tgs), t_end - t_branch, sum(first.values())))
    print('getfem-%s: %s' % (name, ('OK (branches as in the paper)' if paper else 'OK (branches as pscbranch\'s)') if ok
                             else 'FAILED (branches differ)'))
    return 0 if ok else 1
