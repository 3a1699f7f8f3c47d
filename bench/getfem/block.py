#!/usr/bin/python3
"""block.py - the block of Section 3.2 of Ligursky & Renard solved with GetFEM's own
continuation and non-smooth branching (getfem.ContStruct, 'non-smooth', singularities 2), the
reference for bench/getfem_side_by_side.sh. Written here from GetFEM's documented Python API.

The problem is fe/block.c's (fe/fe.h, fe_block_model): a 40 mm x 80 mm block, NX x NY
bilinear squares, 3 x 3 Gauss points, plane-strain Ciarlet-Geymonat (lambda = 4000, mu = 120,
a = 30 N/mm^2), fixed on top by Lagrange multipliers (bilinear traces), loaded by
h = gamma (-2, 0.12 (x1 - 20)) N/mm^2 on both lateral sides, on a rigid foundation x2 >= 0 with
nodal contact and Coulomb friction F = 1 in the non-symmetric Alart-Curnier form of eq. (2)
(GetFEM's nodal contact brick, augmented version 1), r = 10.

The run is the same as `fe/block --mesh NXxNY` (gfcont.py): Newton at gamma = -1 on
branch 1, continuation towards gamma = 0, GetFEM's Algorithms 2.1-2.2 at the nonsmooth point
(h = 5e-7, h_init = 5e-4, c_diff = 0.99999, n_dir = 20, n_span = 15 unless given), every branch
traced to |gamma| = 1. GetFEM returns a tangent per one-sided branch it finds and each is traced
(on M200 12 tangents for six branches: the sticking ones come back four times each); the tracing
time of one tangent per distinct branch is printed too.

The branches are numbered as in the paper (1-3 forced right, gamma < 0; 4-6 left; lower vertex on
that side lifted, sticking, slipping). --compare FILE (fe/block's --out DIR/branches.csv)
prints the end values beside pscbranch's.

Usage: /usr/bin/python3 bench/getfem/block.py [--mesh NXxNY] [--ndir N] [--nspan N]
           [--lsolver mumps|superlu|auto] [--trace-min-cos C] [--single-struct]
           [--compare FILE] [--verbose]
--trace-min-cos: GetFEM's min_cos while tracing the branches (default 0.9, GetFEM's default);
--single-struct: trace with the branching's ContStruct (min_cos 0.99999 and singular-point tests
at every step), slower. Exit status 0 when the six branches are found, each ends on |gamma| = 1
with |H| <= 1e-8, and (with --compare) pscbranch found the same ones.
"""
import sys

import numpy as np
import getfem as gf

import gfcont

TOP, BOTTOM, LATERAL, RIGHT = 1, 2, 3, 4
LX, LY = 40.0, 80.0
LAMBDA, MU, A = 4000.0, 120.0, 30.0
R_AUG, FRICTION = 10.0, 1.0


def build(nx, ny):
    """The model, the GetFEM objects it uses (mesh, fem, integration), the u dofs (u1, u2) of the lower left and right vertices."""
    m = gf.Mesh('cartesian', np.linspace(0, LX, nx + 1), np.linspace(0, LY, ny + 1))
    for region, normal in ((TOP, [0, 1]), (BOTTOM, [0, -1]), (LATERAL, [-1, 0]), (RIGHT, [1, 0])):
        m.set_region(region, m.outer_faces_with_direction(normal, 0.01))
    m.region_merge(LATERAL, RIGHT)
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
    md.add_nonlinear_term(mim, "(%.17g*F + (%.17g*sqr(Det(F)) - %.17g)*Inv(F)'):Grad_Test_u"
                          % (2 * (A + b), 2 * (b + c), d))
    md.add_Dirichlet_condition_with_multipliers(mim, 'u', mfu, TOP)
    md.add_initialized_data('gamma', [0.0])
    md.add_source_term(mim, 'gamma*[-2, 0.12*(X(1)-20)].Test_u', LATERAL)
    ncontact = len(mfu.basic_dof_on_region(BOTTOM)) // 2
    md.add_variable('lambda_n', ncontact)
    md.add_variable('lambda_t', ncontact)
    md.add_initialized_data('r', [R_AUG])
    md.add_initialized_data('friction', [FRICTION])
    md.add_nodal_contact_with_rigid_obstacle_brick(mim, 'u', 'lambda_n', 'lambda_t', 'r', 'friction',
                                                   BOTTOM, 'y', 1)  # 1: non-symmetric Alart-Curnier
    dofs = mfu.basic_dof_on_region(BOTTOM)
    xy = mfu.basic_dof_nodes(dofs)
    left = sorted(int(d) for k, d in enumerate(dofs) if xy[0, k] < 1e-9)
    right = sorted(int(d) for k, d in enumerate(dofs) if xy[0, k] > LX - 1e-9)
    return md, (m, mfu, mim), left + right  # GetFEM objects kept alive with the model


def classify(gamma, v, tol=1e-6):
    """Paper numbering from the lower vertex on the side the block is forced to (v: u1, u2 of the
    lower left vertex, then of the lower right one)."""
    right = gamma < 0
    u1, u2 = (v[2], v[3]) if right else (v[0], v[1])
    kind = 1 if u2 > tol else (2 if abs(u1) <= tol else 3)
    return (0 if right else 3) + kind


def main():
    a = gfcont.arguments(__doc__, '10x20', 20, 15)
    nx, ny = (int(s) for s in a.mesh.split('x'))
    gf.util_trace_level(0)
    md, (m, mfu, mim), corner = build(nx, ny)
    print('getfem-block: M%d (%d x %d Q1, 3x3 Gauss), N = %d unknowns, linear solver %s'
          % (nx * ny, nx, ny, md.nbdof(), a.lsolver))

    def start(md):
        # pscbranch's Newton from zero lands on branch 1; GetFEM's lands on branch 2, so it starts
        # from the sheared guess u = 3 (1 - x2/80) (1, 0) with its systematic line search
        xy = mfu.basic_dof_nodes()
        md.set_variable('u', np.where(np.arange(mfu.nbdof()) % 2 == 0, 3 * (1 - xy[1] / LY), 0.0))
        md.set_variable('gamma', [-1.0])
        md.solve('max_res', 1e-9, 'max_iter', 50, 'lsolver', a.lsolver, 'lsearch', 'systematic')
        return classify(-1.0, gfcont.vertex_values(md, md.from_variables(), corner)) == 1

    return gfcont.run('block', a, md, corner, classify, {1, 2, 3, 4, 5, 6}, 'mm', start, 5e-7, 0.99999)


if __name__ == '__main__':
    sys.exit(main())
