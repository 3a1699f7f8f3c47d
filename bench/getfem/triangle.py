#!/usr/bin/python3
"""triangle.py - the triangle of Section 3.3 of Ligursky & Renard solved with GetFEM's own
continuation and non-smooth branching, the reference for bench/getfem_side_by_side.sh (TRIANGLE=N).
Written here from GetFEM's documented Python API.

The problem is fe/triangle.c's branching run (fe/fe.h, fe_triangle_model): a right
isosceles triangle with 1 m legs on the axes, the n x n grid of squares cut parallel to the
hypotenuse (n^2 P1 triangles), plane-strain Hooke law (lambda = 100, mu = 82 GN/m^2), fixed along
the hypotenuse by Lagrange multipliers (linear traces), loaded on the vertical leg by
h = gamma (-26.4, -7.5) GN/m^2, lying on a rigid foundation x2 >= 0 along the bottom leg with
nodal contact and Coulomb friction F = 1.7 in the Alart-Curnier form of eq. (2) (GetFEM's nodal
contact brick, version 1), r = 10. The corner (1, 0) is fixed, so n contact nodes remain.

The run (gfcont.py) is `fe/triangle --mesh N --load 26.4`'s: Newton at gamma = -1 from zero
(branch 2), continuation towards gamma = 0, GetFEM's Algorithms 2.1-2.2 with the paper's triangle
parameters (h = 5e-8, h_init = 5e-4, c_diff = 1 - 1e-10, n_dir = 30, n_span = 10), every branch
traced to |gamma| = 1. The paper finds four branches: 2 (gamma < 0); 1, 3, 4 (gamma > 0) with the
lower left vertex separated, sticking, slipping.

Usage: /usr/bin/python3 bench/getfem/triangle.py [--mesh N] [--ndir N] [--nspan N]
           [--lsolver mumps|superlu|auto] [--trace-min-cos C] [--single-struct]
           [--compare FILE] [--verbose]
(options as in block.py; --compare takes fe/triangle's --out DIR/branches.csv)
"""
import sys

import numpy as np
import getfem as gf

import gfcont

BOTTOM, HYPOTENUSE, LEFT, CONTACT = 1, 2, 3, 4
LAMBDA, MU = 100.0, 82.0
R_AUG, FRICTION = 10.0, 1.7
LOAD = (-26.4, -7.5)


def build(n, load='gamma*[%.17g, %.17g]' % LOAD):
    """The model, the GetFEM objects it uses, the u dofs (u1, u2) of the first and the last contact
    node along the bottom leg (x1 = 0 and x1 = (n - 1)/n). load: the traction on the vertical leg
    in GetFEM's weak-form language, a function of the datum gamma (fold.py gives its own)."""
    m = gf.Mesh('empty', 2)
    tris = []
    for j in range(n):
        for i in range(n - j):
            tris.append([(i, j), (i + 1, j), (i, j + 1)])
            if i + j + 1 < n:  # the upper triangle of the square is inside too
                tris.append([(i + 1, j), (i + 1, j + 1), (i, j + 1)])
    pts = np.array([[[p[0] / n for p in t], [p[1] / n for p in t]] for t in tris])  # ntri x 2 x 3
    m.add_convex(gf.GeoTrans('GT_PK(2,1)'), np.transpose(pts, (1, 2, 0)))
    m.set_region(BOTTOM, m.outer_faces_with_direction([0, -1], 0.01))
    m.set_region(LEFT, m.outer_faces_with_direction([-1, 0], 0.01))
    m.set_region(HYPOTENUSE, m.outer_faces_with_direction([1, 1], 0.01))
    # contact on the bottom leg without the face at the fixed corner (1, 0)
    bottom = m.region(BOTTOM)
    keep = [k for k in range(bottom.shape[1]) if m.pts_from_cvid(int(bottom[0, k]))[0][0].max() < 1 - 1e-12]
    m.set_region(CONTACT, bottom[:, keep])
    mfu = gf.MeshFem(m, 2)
    mfu.set_fem(gf.Fem('FEM_PK(2,1)'))
    mim = gf.MeshIm(m, gf.Integ('IM_TRIANGLE(2)'))  # exact for P1 stiffness, edge masses and loads

    md = gf.Model('real')
    md.add_fem_variable('u', mfu)
    md.add_initialized_data('lambda', [LAMBDA])
    md.add_initialized_data('mu', [MU])
    md.add_isotropic_linearized_elasticity_brick(mim, 'u', 'lambda', 'mu')
    md.add_Dirichlet_condition_with_multipliers(mim, 'u', mfu, HYPOTENUSE)
    md.add_initialized_data('gamma', [0.0])
    md.add_source_term(mim, '(%s).Test_u' % load, LEFT)
    dofs = mfu.basic_dof_on_region(CONTACT)
    ncontact = len(dofs) // 2
    md.add_variable('lambda_n', ncontact)
    md.add_variable('lambda_t', ncontact)
    md.add_initialized_data('r', [R_AUG])
    md.add_initialized_data('friction', [FRICTION])
    md.add_nodal_contact_with_rigid_obstacle_brick(mim, 'u', 'lambda_n', 'lambda_t', 'r', 'friction',
                                                   CONTACT, 'y', 1)
    xy = mfu.basic_dof_nodes(dofs)
    first = sorted(int(d) for k, d in enumerate(dofs) if xy[0, k] < 1e-9)
    last = sorted(int(d) for k, d in enumerate(dofs) if abs(xy[0, k] - (n - 1) / n) < 1e-9)
    return md, (m, mfu, mim), first + last, ncontact  # GetFEM objects kept alive with the model


def classify(gamma, v, tol=1e-8):
    """Paper numbering: gamma < 0 is branch 2; gamma > 0 by the lower left vertex: 1 separated,
    3 sticking, 4 slipping."""
    if gamma < 0:
        return 2
    return 1 if v[1] > tol else (3 if abs(v[0]) <= tol else 4)


def main():
    a = gfcont.arguments(__doc__, '32', 30, 10)
    n = int(a.mesh)
    gf.util_trace_level(0)
    md, keep, corner, ncontact = build(n)
    print('getfem-triangle: M%d (%d subdivisions per leg, P1), N = %d unknowns, %d contact nodes, linear solver %s'
          % (n * n, n, md.nbdof(), ncontact, a.lsolver))

    def start(md):
        md.set_variable('gamma', [-1.0])
        md.solve('max_res', 1e-9, 'max_iter', 50, 'lsolver', a.lsolver)
        return True

    return gfcont.run('triangle', a, md, corner, classify, {1, 2, 3, 4}, 'm', start, 5e-8, 1 - 1e-10, stop_at_kink=True)


if __name__ == '__main__':
    sys.exit(main())
