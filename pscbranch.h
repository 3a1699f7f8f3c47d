/* SPDX-License-Identifier: MIT */
/* pscbranch.h - v0.11.0 - piecewise-smooth continuation and numerical branching - MIT license

   Traces piecewise-smooth (PC^1) solution curves of H(y) = 0, H: R^{N+1} -> R^N, through folds
   and kinks, and finds every smooth branch leaving a nonsmooth point, with the method of T.
   Ligursky and Y. Renard (CMAME 280 (2014); Algorithms 2.1 and 2.2 of "A method of piecewise-
   smooth numerical branching", ZAMM 97 (2017)). It also locates folds, branch points and events,
   switches at branch points, explores whole diagrams, steps quasi-static evolutions through
   snap-throughs, and maps folds, kinks and branch counts in a second parameter. Frictional
   contact is the motivating case; helpers for it are included.

   In exactly one C or C++ file:       #define PSCBRANCH_IMPLEMENTATION
                                       #include "pscbranch.h"
   Link with LAPACK and BLAS:          cc ... -llapack -lblas -lm

   QUICK START: trace a curve to a nonsmooth point and find the branches leaving it
   ----------------------------------------------------------------------------------
     static int H(const double *y, double *h, void *user)      // y = (x1, x2, g): N = 2
     { ... h[0] = ..., h[1] = ...; return 0; }                  // 0 ok, >0 retry smaller, <0 stop
     static int dH(const double *y, double *jac, int ld, void *user)
     { ... jac[i + j*ld] = dH_i/dy_j of the smooth piece y lies on ...; return 0; }
     static int stop_at_kink(const psb_point *p, void *u) { return p->flags & PSB_POINT_KINK; }

     psb_problem prob;  psb_options opt = {0};  psb_solver s;
     psb_problem_init(&prob, 2, H, dH, NULL);           // the parameter is y[2], the last
     opt.h_min = 5e-7;  opt.h_init = 5e-4;              // zero fields take their defaults
     if (psb_solver_init(&s, &prob, &opt) < 0) puts(psb_solver_message(&s));
     double y[3] = {1, 1, 1}, t[3], ys[8*3], ts[8*3];
     psb_solve_at_param(&s, y, 0);                      // a solution at g = 1
     psb_tangent(&s, y, NULL, t);                       // unit tangent, t[2] > 0 ...
     for (int i = 0; i < 3; i++) t[i] = -t[i];          // ... turned towards smaller g
     psb_trace_options to = {0};  to.locate_kinks = 1;  to.on_point = stop_at_kink;
     psb_trace(&s, y, t, &to, NULL);                    // stops just before the first kink
     psb_branch_options bo = {0};  bo.h = 5e-7;         // branching's options (NULL: defaults)
     psb_locate_end(&s, y, t, &bo, NULL);               // Algorithm 2.1
     psb_branch_report rep;
     psb_find_branches(&s, y, t, &bo, 8, ys, ts, &rep); // Algorithm 2.2: rep.n_branches couples
     psb_solver_free(&s);                               // (ys + k*3, ts + k*3), branch 0 incoming
   examples/01_branching.c is this program in full.

   CONTENTS  1. Concepts             4. Result codes             7. Contact helpers
             2. The API at a glance  5. Options and defaults     8. Compile-time macros
             3. Callbacks            6. Algorithms

   1. CONCEPTS ------------------------------------------------------------------------------------
   y = (state, parameter) has N+1 components; problem.param_index says which one is the load
   parameter (psb_problem_init: the last). A couple (y, t) is a point with H(y) ~ 0 and a unit
   tangent t, dH(y) t = 0, ||t||_w = 1, whose sign is the direction of travel. Weighted inner
   product <a,b>_w = sum_i w_i a_i b_i, w_i = options.kappa for the state and 1 for the parameter
   (or options.weights). Every norm, cosine and normalisation in y uses it, so step sizes,
   tol_correction and branching lengths are lengths in it: y in units far from 1 wants weights
   1/u_i^2, u_i the size of component i; unknowns weighted far below the others make pieces that
   differ only there look alike. tol_residual is absolute (section 5). H is PC^1: continuous, and
   near every point equal to one of finitely many C^1 selections. The Jacobian callback returns the
   gradient of a selection active at y (a B-Jacobian element). Without one, dH comes from finite
   differences, column j stepping fd_step max(1, |y_j|) (rescale components far below 1); a quotient
   whose step crosses a kink mixes pieces, so give an analytic selection gradient when branching at
   kinks. With differences and h left at 0, the h of Algorithms 2.1 and 2.2 follows the point (10^4
   difference steps, within [h_min, h_init / 8]), Algorithm 2.2 samples tangents with steps below
   h/1000 and Algorithm 2.1 keeps its entering tangent: branch sets come out about as with an
   analytic dH. A kink is a point where a curve passes from one piece to another with a different
   tangent; a nonsmooth point (a PC^1 bifurcation) is one where more than two smooth branches meet.
   Algorithms 2.1 and 2.2 assume the paper's (I)-(III): near the point the solutions form one-sided
   smooth branches in distinct regions, every selection's gradient has full rank, and the kernels of
   two different selections meet only in 0.

   2. THE API AT A GLANCE (most functions return psb_result) --------------------------------------
   psb_problem_init             zero a psb_problem; set N, callbacks, param_index = N (void)
   psb_options_resolve, psb_branch_options_resolve   the options a solver, a call would use
   psb_solver_init, _init_with_memory, _memory_size   a solver: allocated, or on your memory
   psb_solver_free              release it (void); later calls return PSB_ERR_NULL
   psb_solver_message, psb_result_string   the last failure's diagnostic; a code's meaning
   psb_dot_w, psb_norm_w        weighted inner product and norm (double; NaN on bad arguments)
   psb_solve_at_param           Newton on H(y) = 0 with the parameter held: a starting point
   psb_tangent, psb_correct     unit tangent at y (oriented by a reference); the corrector
   psb_step                     one predictor-corrector step with step control
   psb_switch_tangent           the tangent switch at a couple where steps fail
   psb_trace                    the driver: from (y, t) to a bound, budget, end point or loop
   psb_locate_end, psb_find_branches   Algorithms 2.1, 2.2: a branch's end point, the branches there
   psb_workers_memory_size, _task_output; psb_explore_workers_memory_size   workers (section 6)
   psb_branch_point_switch      the branches through a smooth branch point psb_trace located
   psb_evolve_step              one time step of a quasi-static evolution, through folds
   psb_two_param_problem_init, _lift; psb_fold_map_memory_size(_for), _init, _start, _refine
   psb_event_curve_*, psb_branch_curve_*, psb_count_map(_memory_size)   maps in two parameters
   psb_explore                  every branch reachable from one couple, as a graph
   psb_diagram_init, _init_with_memory, _free, _memory_size, _set_points, _set_growth   storage
   psb_node_kind_string, psb_edge_end_string; psb_diagram_write_json, _csv, _points_csv (STDIO)
   psb_proj_*, psb_ac2d_*, psb_fc3d_*, psb_fc_nat_error, psb_contact_convert: section 7
   Inputs are never modified on failure, but psb_trace's (y, t) hold the last accepted couple once a
   step was accepted, the branching calls' (ys, ts) the branches found so far, psb_explore's diagram
   the graph so far. Only psb_solver_init and psb_diagram_init allocate, and psb_explore through the
   allocator of a diagram set to grow. Single operations (psb_solve_at_param, _tangent, _correct,
   _step, _switch_tangent, _locate_end, _find_branches) may be called from a point or event callback
   of psb_trace on the same solver; the other calls there return PSB_ERR_INPUT and leave the trace
   as it was. A solver is not thread-safe, but there is no global state: distinct solvers may run in
   distinct threads. Same inputs, options and seed: same results, bit for bit. psb_solver is
   caller-owned; public: prob (fd_step resolved), opt (resolved), branch (the latest branching
   call's resolved options), stats (cumulative counters) and message; internal_ (type psb__internal)
   is opaque. A freed solver, or one whose init failed, gives PSB_ERR_NULL.

   3. CALLBACKS -----------------------------------------------------------------------------------
   int residual(const double *y, double *h, void *user)             h = H(y), N values
   int jacobian(const double *y, double *jac, int ld, void *user)   dense: all of dH(y), N x
       (N+1) column-major, (i, j) at jac[i + j*ld]; NULL: finite differences
   int band_jacobian(const double *y, double *band, int ldband, double *dparam, void *user)
       banded: A = dH/dx at band[PSB_BAND_INDEX(ku, ldband, i, j)] (zeroed on entry; state column
       j is y_j below param_index, else y_{j+1}), dparam = dH/dparameter; NULL: differences
   solver.factor(y, row, ctx), solver.solve(b, nrhs, ctx)   user backend: factor B = [dH(y);
       row^T] (you form dH), then solve in place, nrhs <= 2 columns of N+1; > 0: singular
   int piece(const double *y, unsigned long long *id, void *user)   optional: an id shared only
       by points where one C^1 selection gives H; > 0: not known here
   Return 0 on success; > 0 for a recoverable failure (the trial is rejected and shortened; with
   no retry left, PSB_ERR_CALLBACK_FAILED); < 0 to stop at once (PSB_ERR_CALLBACK). NaN or Inf
   counts as recoverable (then PSB_ERR_NONFINITE). An outcome resting on a failed trial (an end
   point, a branch set) or on a Jacobian of rank < N (differences: where nothing succeeded) is
   reported as that failure, never as a success.
   int on_point(const psb_point *p, void *user)   psb_trace's start, accepted points, located
   kinks and special points; nonzero stops (PSB_STOPPED). p->flags: PSB_POINT_START; _FOLD (t's
   parameter component changed sign; p->fold_param estimates the limit point); _SWITCH (after a
   tangent switch); _BOUND (exactly on a bound); _KINK (the last couple before a kink, within
   h_min); _SPECIAL (p->special, reported before the accepted point that follows it).
   int event(const double *y, double *g, void *user)   the n_events values g(y); < 0 stops,
   > 0 or NaN/Inf fails the trace (PSB_ERR_CALLBACK, _CALLBACK_FAILED, _NONFINITE).

   4. RESULT CODES (0 success, > 0 informational, < 0 failure: test with `< 0`) -------------------
   PSB_SUCCESS              0  done
   PSB_PARAM_BOUND          1  trace landed exactly on param_min or param_max
   PSB_STEP_BUDGET          2  trace used max_steps; psb_explore: max_traces or max_points
   PSB_NONSMOOTH_END        3  an end point: steps failed, the switch too (or no_switch); no fault
   PSB_STOPPED              4  a point callback returned nonzero, or stop_at
   PSB_LOOP_CLOSED          5  (detect_loop) the curve came back to its start
   PSB_BRANCH_CAPACITY      6  more branches than room, or a diagram full: what fits is kept
   PSB_ERR_NULL            -1  a required pointer is NULL, or the solver is not initialised
   PSB_ERR_SIZE            -2  a size or index out of range (n, param_index, kl, max_branches...)
   PSB_ERR_OPTIONS         -3  invalid or inconsistent options (the message names the field)
   PSB_ERR_NOMEM           -4  allocation failed, or the caller's memory block is too small
   PSB_ERR_CALLBACK        -5  a callback returned < 0
   PSB_ERR_CALLBACK_FAILED -6  a callback returned > 0 where no smaller step was left to try
   PSB_ERR_NONFINITE       -7  NaN or Inf in the input or from a callback
   PSB_ERR_SINGULAR        -8  rank(dH) < N, or a bordered system (or solver.factor) singular
   PSB_ERR_LAPACK          -9  LAPACK rejected an argument (a bug in pscbranch: please report)
   PSB_ERR_NO_CONVERGENCE -10  Newton / corrector iterations did not converge
   PSB_ERR_STEP_TOO_SMALL -11  psb_step: every trial down to h_min failed
   PSB_ERR_INPUT          -12  bad numbers (zero t, start out of bounds), or a call from a trace

   5. OPTIONS AND DEFAULTS (a zero field takes the default in brackets) ---------------------------
   In psb_options and psb_branch_options every real must be finite, every length and tolerance at
   least 1e-290 (PSB_ERR_OPTIONS names the field); psb_options_resolve and _branch_options_resolve
   show the values used. psb_problem (psb_solver_init; s->prob keeps a copy with fd_step set):
     param_index [psb_problem_init: N]  the load parameter's component, 0..N (0 means y[0])
     linear [PSB_LINEAR_DENSE] PSB_LINEAR_DENSE (N <= 46000), _BANDED or _USER (section 6)
     kl, ku [0]                banded: sub- and super-diagonals of A = dH/dx, in [0, N-1]
     band_jacobian [NULL]      banded: A and dH/dparameter (section 3); NULL: differences
     band_lean [0]             banded: 1 keeps one copy of A ((kl+ku+1) N doubles less, less reuse)
     solver [none]             user backend: factor and solve (both required), ctx
     fd_step [1.49e-8; central 6.06e-6]  differences: column j steps fd_step max(1, |y_j|); < 1
     fd_central [0]            1: central differences (2 (N+1) residuals a Jacobian, not N+1)
     piece [NULL]              the smooth piece's id at y: Algorithm 2.2's piece memo
   psb_options (psb_solver_init; s->opt holds them resolved):
     kappa [1]                 weight of each state component, in [1e-290, 1e290]
     weights [NULL]            N+1 weights replacing kappa and 1, in [1e-290, 1e290]; copied
     h_init [1e-2]             first step, and the first after each tangent switch
     h_min [1e-6]              smallest trial step; h_min <= h_init <= h_max
     h_max [1e-1]              largest step
     h_inc [1.3]               growth after a step of < iter_threshold iterations, in [1, 100]
     h_dec [0.5]               shrink after a rejected trial, in [1e-3, 0.9]
     max_iter [10]             corrector iterations per trial, <= PSB_MAX_ITER_LIMIT (1000)
     iter_threshold [4]        see h_inc; <= 1000
     tol_residual [1e-10]      ||H(y)||_2 at convergence, absolute (below)
     tol_correction [1e-10]    distance to the solution at convergence, ||.||_w
     c_min [0.9]               least cosine between a step's tangents, in (-1, 1)
     switch_delta_min, _max [h_min, h_init]  first and last probe distance of the tangent switch
     switch_no_sweep [0]       1: no sweep around a kink when nothing lies straight ahead
     switch_n_dir [20]         directions of that sweep, <= PSB_MAX_DIR_LIMIT (10000)
     c_diff [0.99999]          cosine above which two tangents are one branch, in (0, 1)
     seed [0]                  seed of the random draws (Algorithm 2.2, branch point switch...)
   A step tries h, h h_dec, ... down to h_min: keep h_min well below h_max h_dec. Where H's terms
   are large, a point also converges once its correction is below tol_correction and ||H|| stops
   falling; where they are far below 1, set tol_residual to ~1e-10 times their size (else non-
   solutions pass for branches in Algorithm 2.2).
   psb_trace_options (each psb_trace; NULL: defaults):
     param_min, param_max [none]  bounds on y[param_index] (none when min >= max); may be +-inf
     max_steps [10000]         accepted steps
     no_switch [0]             1: end (PSB_NONSMOOTH_END) where steps fail, no tangent switch
     detect_loop [0]           1: end (PSB_LOOP_CLOSED) when the curve returns to its start
     locate_kinks [0]          1: locate the first kink of each step; 2: each, up to 8 a step
     on_point, point_user [NULL]  the point callback (section 3) and its pointer
     detect [0: none]          PSB_DETECT_* mask: FOLDS 1, BRANCH 2, PC1 4 (not _USER), EVENTS 8
     stop_at [0]               bit 1u << PSB_SPECIAL_*: stop (PSB_STOPPED) on such a point
     locate_tol [1e-10]        precision of a special point, ||.||_w along the curve
     n_events [0]; event, event_user, event_work  callback, pointer, 3 n_events doubles of yours
   psb_branch_options (the branching calls, NULL: defaults; checked at each call; h_min, h_init
   in brackets are psb_options'; the paper: h 5e-7, h_min h/2^14, h_init 5e-4, n_dir 20, n_span 15):
     h [h_min; differences: expert.h_fd_steps steps at the point]  h of Algorithms 2.1, 2.2
     h_min [h / 2^14]          precision of Algorithm 2.1; h_min < h
     h_init [h_init]           first step of Algorithm 2.2's trials; branch point switch: r
     n_dir [20]                directions per span (branch point switch: 2 n_dir), <= 10000
     n_span [15]               counted spans, <= 10000; left at 0 (memo on), the length adapts
     n_span_max [60 if n_span is 0 and the memo is on, else n_span]  above n_span: adapts
     max_pc [0: none]          stop once rep.n_pc reaches it (workers: checked per n_dir directions)
     workers [NULL: none]      Algorithm 2.2's directions on these workers (section 6, "Workers")
     expert (psb_branch_expert) for reproducing the paper and for experiments; a user leaves it 0:
     expert.as_printed [0]     1: as printed: the next three 1, restart _PAPER (_GLOBAL refused)
     expert.paper_sweep [0]    1: directions sin(a) t~1 + cos(a) t~2 as printed; closest pair first
     expert.no_memo [0]        1: every direction tried (no idle spans; fixed length by default)
     expert.no_screen [0]      1: each trial along its sampled tangent (no screening, no cuts)
     expert.restart [PSB_RESTART_MIXED]  random spans: _MIXED, _PAPER (Remark 2.3(ii)), _GLOBAL
     expert.h_fd_steps [1e4]   differences, h left at 0: h in difference steps, in [1, 1e8]
     expert.trial_h_min [h_min]  Algorithm 2.2's trial steps give up below this step
     expert.patience [0: never]  stop after that many counted spans in a row found no branch
   psb_explore_options (psb_explore; NULL: defaults):
     trace [0; eo NULL: detect FOLDS|BRANCH|PC1]  each trace's bounds, max_steps, detect, events
     branch [0]                the psb_branch_options of every branching
     box_min, box_max [NULL]   N+1 values each: a trace ends at its first point outside the box
     state_max [0: none]       a trace ends where the state part of y exceeds it in ||.||_w
     one_direction [0]         1: from the start along t only, not -t
     max_traces, max_points [0: max_edges, none]  edges traced, accepted points, in all
     branch_at_kinks [0]       1: locate every kink a trace passes and branch there
     kink_spans [0: full]      branch_at_kinks: a first look at a kink with this many spans
     kink_nodes [0]            1: ordinary kinks are nodes (PSB_NODE_KINK); implies branch_at_kinks
     node_tol [16 branch.h; differences: 16 h at the node]  branching points this close: one node
     on_point, point_user [NULL]  int on_point(int edge, const psb_point *p, void *user)
     drafts [8; -1: none], draft_points [128]  branch.workers: edges drafted at once (section 6)
   psb_evolve_options (psb_evolve_step; NULL: defaults):
     mode [PSB_EVOLVE_AUTO]    AUTO: Newton, else continuation; _NEWTON or _CONTINUATION only
     newton_max_iter [20]      Newton's iterations at the new parameter, <= 1000
     newton_max_jump [0: any]  AUTO: a Newton solution farther than this (||.||_w) is refused
     param_min, param_max [none]  the path's range (none when min >= max); y, target inside
     max_steps, max_length [10000, 0: none]  accepted continuation steps, longest path (||.||_w)
     no_switch [0]             1: the path does not pass kinks
     on_point, point_user [NULL]  every point of the path; nonzero: PSB_ERR_CALLBACK

   6. ALGORITHMS ----------------------------------------------------------------------------------
   Linear algebra (problem.linear). Every system is bordered, B = [dH(y); row^T] (row = W t in the
   corrector), regular at folds where dH/dx is singular; one factorisation serves an iteration's
   right-hand sides. PSB_LINEAR_DENSE: dgetrf/dgetrs on B, ~2 (N+1)^2 doubles. PSB_LINEAR_BANDED:
   A = dH/dx with kl sub- and ku super-diagonals, ~(4 kl + 3 ku) N doubles; B by block elimination
   (w = A^{-1} dH/dparameter per factorisation); the LU is dgbtrf's in panels of four columns
   (its factors bit for bit). Where d - c.w cancels (g = (|d| + sum |c_j w_j|) / |d - c.w| > 16)
   a solution is refined by its residual in B; where A is singular or that stalls, A + sqrt(eps)
   ||B|| I is factored and refined against B. A bit-identical A (piecewise-linear H) reuses its
   factors (stats.n_factor_reused). PSB_LINEAR_USER: problem.solver factors B itself; contrib/
   has psb_sparse.h (UMFPACK, KLU), psb_mumps.h (MUMPS), psb_condense.h (static condensation).
   A solver also holds ~100 vectors of N+1 and Algorithm 2.2's memos (psb_solver_memory_size).

   Corrector and tangent. The tangent at y solves [dH(y); (W r)^T] t = e_{N+1}, r the reference
   direction; where that is singular or (dense) its scaled condition estimate exceeds 1/sqrt(eps),
   the dense backend takes the kernel of dH(y) from a QR factorisation (exact at folds; rank < N:
   PSB_ERR_SINGULAR), the others border with e_param, then a fixed row; t is normalised with <t,
   r>_w >= 0. The corrector factors B = [dH(y); (W t)^T] once per iteration and solves B [dy, v] =
   [[H(y); 0], [0; 1]]: y -= dy, t = v / ||v||_w. It converges when ||H(y)||_2 <= tol_residual and
   the distance to the solution (||dy||_w, or Newton's estimate theta ||dy|| / (1 - theta) for a
   contraction theta <= 1/2) is below tol_correction, or when ||dy||_w <= tol_correction and ||H||
   fell by less than half (H's rounding; every Newton solve here accepts it). A trial step predicts
   y + h t and is accepted when the corrector converged within max_iter, within h of the prediction
   (a longer jump landed elsewhere on the curve), with a tangent within c_min of t; otherwise h *=
   h_dec, down to h_min. An iterate 4 h away ends a trial (not Algorithm 2.2's: at kinks the
   corrector would hop between far kernels). A branch within a step of the traced one can still
   take the corrector: keep h_max below the distances between branches.

   Trace and its detectors. psb_trace takes steps, h growing by h_inc after a step of fewer than
   iter_threshold iterations, up to h_max. Where every trial fails down to h_min, the tangent switch
   probes the tangent t~ at y + delta t, delta doubling from switch_delta_min to switch_delta_max;
   once cos(t~, t) < c_diff it tries steps along +t~, then -t~, and takes the first couple that does
   not go back along the incoming branch. With nothing straight ahead it sweeps the plane of -t and
   the tangent ahead (switch_n_dir directions, three probe distances), then both again for tangents
   within c_diff of t but beyond rounding; nothing found, and no fault: PSB_NONSMOOTH_END. Where
   more than two branches meet it goes on along one. Folds: t[param] changes sign, estimated at the
   extremum of the cubic Hermite interpolant. Kinks (locate_kinks): after a step that turned by more
   than c_diff's angle, half (and quarter) steps tell a kink, whose turn does not shrink with the
   step, from a smooth turn; bisection locates it to h_min, a step of 2 h_min across confirms it
   (analytic dH). Bounds: a step across one gives way to Newton at the bound. Special points
   (detect; the accepted points stay the same): FOLD (located), FOLD_KINK (the couple before the
   kink), BRANCH (sgn det [dH; (W t)^T] changed on a smooth piece: located, with the kernel
   direction), PC1 (it changed across a kink: the couple before it), EVENT (located). The
   determinant, continuous along a curve oriented by its travel, vanishes where dH loses rank; its
   sign comes from the corrector's LU in O(N) (the user backend watches det B / det [B b_k; c_k^T
   d_k] for two random borders instead: no PC1). Locations: Illinois regula falsi along the curve
   (each point on the bracket's branch), to locate_tol. A det jump in a step that did not turn is a
   nonsmooth point passed straight through: PC1 with special->located = 1 (for psb_find_branches as
   it is). Unseen: two sign changes in a step, det keeping its sign. PC1: the outward signs of the
   branches leaving a nonsmooth point add up to 0, so the test fires only where more than two meet,
   and not at every such point: to miss none, stop at kinks and run Algorithm 2.2.

   Algorithm 2.1 (psb_locate_end). As in the paper, h is halved from branch h to h_min, y moving to
   the correction of y + h t whenever that converges with a tangent within c_diff of t. After a
   move the same h is tried again (the printed version moves at most h in all); a move must land
   h/2 ahead with a tangent within c_diff of the entering one too (no falling back, no turns adding
   up), and a branch that only turned smoothly is followed on. With differences the entering
   tangent is kept, stalls are told from smooth turns by chords, t is the branch's tangent 16 h
   back, and a pass with steps 10^4 times shorter goes on where the quotients mixed the pieces. y
   is then within *precision of the end point (the last h; with differences 2 h plus 1e-2 of that
   pass's move), t along the branch into it; over 1000 moves: PSB_ERR_NO_CONVERGENCE.

   Algorithm 2.2 (psb_find_branches). As in the paper, with Section 3's restarts: branch 0 is (y0,
   -t0); each span of two tangents t~1, t~2 is swept in n_dir directions v, the tangent at y0 + h v
   sampled (skipped where it repeats the previous one), and trial steps from y0 along it both ways
   (h_init down to trial_h_min) land on branches; a landing h or more from y0 is new if its outward
   tangent differs from every found one's by more than c_diff (on curved branches the sphere
   through it decides), and one on a ray from y0 along its own tangent counts even where the step
   tests fail. Choices (expert switches; as_printed undoes them): Sweep: t~2 is made w-orthogonal
   to t~1, so directions spread evenly. Restarts: pairs of found branches, the most nearly
   orthogonal first; then random spans, MIXED alternating uniform draws with spans beside a found
   branch t_j (the tangent at y0 + h (t_j + 0.1 r), r random). Memos: a tangent within c_diff of
   one tried in the call is skipped (n_memo); points with a bit-identical analytic dH, or one piece
   id (Piece memo), share a tangent, which only decides skips. Screening: near y0 the pieces are,
   to first order, cones with apex y0, and cones scale: a trial along x from y0 + h_init x lands as
   the trial along k, the tangent there. So trials go along k, skipped when k is a found branch's
   or a known trial's (n_screened), and stop once an iteration's tangent is (n_cut, analytic dH);
   The memo's cut: the memo can tell that before the iteration's factorisation (n_cut_memo). A
   trial also stops after a step that failed on pieces checked to be conic. Sweep length (n_span
   left at 0): spans that try nothing new do not count; the sweep goes on while fewer than 3 times
   the last new branch's span have passed, up to n_span_max. An odd count: branches crossing a
   small sphere about y0 transversally come in even number, their outward signs adding up to 0; an
   odd or unbalanced set most likely misses branches, so an adapting sweep goes on to n_span_max,
   then between the directions swept (not with patience). An odd rep.n_branches or rep.unbalanced
   flags what is left; a balanced set proves nothing. Kinks within h_init: the cones reach the next
   kink only; a landing chord turning from its tangent by over 0.05 rad, H off its affine map
   through y0, or an odd count restart the run with h_init / 16 (up to 3 times, staying >= 8 h).
   Random numbers: xoshiro256**, reseeded from options.seed at each call.

   Workers (psb_workers; contrib/psb_workers.h): the caller's run puts tasks on threads or MPI
   ranks (psb_workers_task_output), each with its own solver and user data. A span goes in phases:
   sample tangents on the workers; Step 4 (skip a repeated tangent), the memo in order; trials, a
   task each sign, on the memos as the phase found them; merged in order. Counts differ from the
   serial sweep's (no trial sees another's memo entries: 1.2-1.6x), never with the worker count.
   psb_explore drafts the queue's next `drafts` edges' first traces at once on the workers; in
   order, each edge replays its draft as far as the diagram now allows: the diagram of drafts off.

   Branch point switch (psb_branch_point_switch). Near a simple branch point y* the branches are,
   to first order, lines through y* in the plane of t and the kernel direction k. Trials at y* + r
   (cos a t + sin a k), r = branch h_init, 2 n_dir angles (-t, then +t first: branches 0 and 1),
   are corrected by Newton on the sphere ||y - y*||_w = r to where a branch crosses it (within r
   sqrt(2 (1 - c_diff)): one branch); fewer than 4 branches, or -t or +t lost: r/8, then r/64
   (both lost: PSB_ERR_NO_CONVERGENCE). Each branch is walked back towards y*; a kink on the way
   brings the sweep inside it (three rounds at most). A larger kernel: up to 3 more directions by
   inverse iteration, 2 n_dir kdim^2 random trials in it.

   Exploring the whole diagram (psb_explore). From a regular couple it traces every branch it can
   reach: nodes are special points, edges the segments between. The queue is the untraced branches,
   nodes in order, the start's +t and -t first. An edge ends at a bound or the box (a bound node),
   its budget, a failure (exploring goes on; the call returns the first failed edge's code), its
   start (a loop), or a branching point: Algorithms 2.1 and 2.2 where the trace ends or reports PC1
   (nonsmooth, pc1 nodes), the branch point switch at a smooth branch point (branch node); branch 0
   is the one arrived by, the others join the queue. Folds and events are nodes on their edge. A
   branching point within node_tol + 4 (both precisions) of a node, or a chord passing that close,
   arrives there (found through an index). Two branches whose signs cancel make an ordinary kink
   (d->n_kinks_plain): the edge goes on, or ends at a kink node (kink_nodes). Odd or unbalanced
   nodes count in d->n_odd. PC1 is silent where the branches a trace joins have opposite outward
   signs (the paper's block): branch_at_kinks runs Algorithm 2.2 at every kink (kink_spans: a
   short look first). psb_diagram_write_json's declaration has the JSON keys.

   Quasi-static evolution (psb_evolve_step). Step k solves H_k(u, lambda_k) = 0, H_k holding the
   previous state (in problem.user, updated between calls). Where Newton from u_{k-1} fails (a
   snap-through), H_k = 0 is traced from (u_{k-1}, lambda_{k-1}), which solves it too, through folds
   and kinks to its first point at lambda_k. AUTO tries Newton first (kept unless farther than
   newton_max_jump); else y is polished (a move over h_init: PSB_ERR_INPUT) and the trace is bounded
   at lambda_k only, landing there exactly. Else PSB_ERR_NO_CONVERGENCE (report.trace_end).

   Fold curves in two parameters (psb_fold_map_*). H on (x, lambda, mu): at_mu is H at mu held; fold
   is [H; sigma] = 0, mu its parameter, [H_x b; c^T 0] [v; sigma] = [0; 1] (b, c: null vectors at
   the start; sigma's gradient: dH's central difference along v), traced through H's kinks; a FOLD
   on it is a cusp. Banded: fold's user backend eliminates on H_x's LU, refined, shifted as above.

   Branch counts in two parameters (psb_count_map). At each mu the point is found again from a
   branch of the last (continuation to its first kink, Algorithm 2.1) and Algorithm 2.2 counts its
   branches, two within c_diff's angle as one; a change is bisected by counts, then located where
   the larger count's two closest branches, followed in mu, meet (a bracketed secant on their
   angle). Event and branch point curves (psb_event_curve_*, _branch_curve_*): [H; g_k] = 0, [H +
   beta b; s] = 0 (s: a corank-one test of dH), traced like fold.

   7. CONTACT HELPERS (frictional contact as a PC^1 system; formulas in each declaration) ---------
   Each returns its value, one element of its B-Jacobian (column-major) and a piece id, both of
   one piece: piece_request PSB_PIECE_DEFAULT (-1) picks it by the rules below, k >= 0 takes piece
   k's formula. Failures write nothing: PSB_ERR_NULL, _NONFINITE (also on overflow), _INPUT, _SIZE.
   psb_proj_nonpos, _nonneg: min(x, 0), max(x, 0); IN (x), OUT (0); x = 0: IN. psb_proj_interval:
   min(max(x, a), b); IN, LOWER, UPPER (a == b: LOWER, or UPPER if x > b). psb_proj_disk: onto
   {|x| <= s} in R^2 (s <= 0: {0}); IN, BOUNDARY (s x / |x|), ZERO. psb_proj_cone: onto {|x_T| <=
   mu x_N} in R^3; IN, POLAR (0), BOUNDARY; mu = 0: IN never default. psb_proj_*_active: the pieces
   active within tol. psb_ac2d_node, _active, _state: a node's 2D Alart-Curnier residual (Haslinger
   et al.), its 2 x 4 Jacobian and piece; its active pieces; its state. psb_fc3d_ac, _jm, _nat: a
   contact's 3D Alart-Curnier, Jean-Moreau residuals, natural map with De Saxce's velocity
   (psb_fc3d_desaxce) (Acary et al.); psb_fc_nat_error: their eq. (15). psb_contact_convert:
   between the two conventions (r = -lam, u_N = g - u_n, u_T = -u_t).

   8. COMPILE-TIME MACROS (define before including the header) ------------------------------------
   PSCBRANCH_IMPLEMENTATION   in exactly one file: compile the implementation there
   PSCBRANCH_STATIC           make every function static (a private copy per file)
   PSCBRANCH_DEF              the linkage of every public function [extern; static with _STATIC]
   PSCBRANCH_MALLOC(size), _FREE(ptr)  both or neither: the solver's, diagram's allocator [malloc]
   PSCBRANCH_LAPACK_INT       the Fortran INTEGER of your LAPACK [int]; long for ILP64
   PSCBRANCH_FORTRAN(name)    the symbol of a LAPACK routine [name##_]
   PSCBRANCH_NO_FORTRAN_STRLEN  for a LAPACK whose character arguments carry no hidden length
   PSCBRANCH_USE_DGBTRF       the banded backend calls LAPACK's dgbtrf (say, a tuned LAPACK)
   PSCBRANCH_NO_SIMD          no SSE2 intrinsics in the banded LU (the same results)
   PSCBRANCH_STDIO            declares and defines psb_diagram_write_json and _csv (FILE *)
   Defined here: PSCBRANCH_VERSION_MAJOR, _MINOR, _PATCH, _STRING; the guards PSCBRANCH_H,
   PSCBRANCH_IMPLEMENTATION_DONE; with the implementation, PSCBRANCH_STRLEN_ONE for its LAPACK
   calls. LAPACK used: dgetrf, dgetrs, dlacn2, dgeqr2, dorm2r (dgbtrf). */

#ifndef PSCBRANCH_H
#define PSCBRANCH_H

#include <stddef.h>

#ifndef PSCBRANCH_DEF
#ifdef PSCBRANCH_STATIC
#if defined(__GNUC__) || defined(__clang__)
#define PSCBRANCH_DEF static __attribute__((unused)) /* a private copy need not use everything */
#else
#define PSCBRANCH_DEF static
#endif
#else
#define PSCBRANCH_DEF extern
#endif
#endif

#define PSCBRANCH_VERSION_MAJOR 0
#define PSCBRANCH_VERSION_MINOR 11
#define PSCBRANCH_VERSION_PATCH 0
/* "MAJOR.MINOR.PATCH", made from the three numbers above */
#define PSB__VERSION_STR(x) #x
#define PSB__VERSION_XSTR(x) PSB__VERSION_STR(x)
#define PSCBRANCH_VERSION_STRING                                                                   \
    PSB__VERSION_XSTR(PSCBRANCH_VERSION_MAJOR) "." PSB__VERSION_XSTR(PSCBRANCH_VERSION_MINOR) "."  \
    PSB__VERSION_XSTR(PSCBRANCH_VERSION_PATCH)

#ifdef __cplusplus
extern "C" {
#endif

/* ---- result codes: 0 success, > 0 informational, < 0 failure (test with `< 0`) ---------- */
typedef enum psb_result {
    PSB_SUCCESS = 0,
    PSB_PARAM_BOUND = 1,      /* trace: landed exactly on a parameter bound */
    PSB_STEP_BUDGET = 2,      /* trace: the step budget was used up */
    PSB_NONSMOOTH_END = 3,    /* trace/switch: an end point the tangent switch could not pass */
    PSB_STOPPED = 4,          /* trace: the point callback asked to stop */
    PSB_LOOP_CLOSED = 5,      /* trace: the curve came back to its starting point */
    PSB_BRANCH_CAPACITY = 6,  /* more branches, or a diagram fuller, than room; what fits is kept */

    PSB_ERR_NULL = -1,            /* a required pointer is NULL, or the solver not initialised */
    PSB_ERR_SIZE = -2,            /* a size or index is out of range */
    PSB_ERR_OPTIONS = -3,         /* inconsistent or invalid options */
    PSB_ERR_NOMEM = -4,           /* allocation failed or caller memory too small */
    PSB_ERR_CALLBACK = -5,        /* a callback returned < 0: stopped at once */
    PSB_ERR_CALLBACK_FAILED = -6, /* a callback returned > 0 where no retry is possible */
    PSB_ERR_NONFINITE = -7,       /* NaN or Inf in the input or in a callback's output */
    PSB_ERR_SINGULAR = -8,        /* singular (bordered) matrix: no unique tangent or correction */
    PSB_ERR_LAPACK = -9,          /* LAPACK rejected an argument (a library bug: please report) */
    PSB_ERR_NO_CONVERGENCE = -10, /* Newton/corrector iterations did not converge */
    PSB_ERR_STEP_TOO_SMALL = -11, /* every trial step down to h_min failed */
    PSB_ERR_INPUT = -12           /* invalid numerical input (zero tangent, start out of bounds...) */
} psb_result;

/* Name of a result code ("PSB_ERR_SINGULAR: ..."); never NULL. */
PSCBRANCH_DEF const char *psb_result_string(psb_result code);

/* ---- the problem ------------------------------------------------------------------------ */

/* H(y): y has n+1 components (in), h has n (out). Return 0 on success, > 0 for a recoverable
   failure (the step is rejected and shortened), < 0 to stop at once. */
typedef int (*psb_residual_fn)(const double *y, double *h, void *user);
/* dH/dy at y: an n x (n+1) column-major matrix with leading dimension ldjac >= n; entry (i, j)
   is jac[i + j*ldjac]. Fill every entry of the n x (n+1) block. Same return convention. */
typedef int (*psb_jacobian_fn)(const double *y, double *jac, int ldjac, void *user);
/* The smooth piece of H that y lies in (optional, psb_problem.piece): write to *id a value that
   is the same for two points only if one C1 function gives H near both, e.g. a hash of the
   contact helpers' piece indices over the contact nodes (psb_ac2d_node's *piece). Return 0, > 0
   when the piece is not known at y (the tangent is then computed), < 0 to stop at once. */
typedef int (*psb_piece_fn)(const double *y, unsigned long long *id, void *user);

/* Banded problems (linear = PSB_LINEAR_BANDED): A = dH/dx, the n x n Jacobian with respect to
   the state x (y without its parameter component: state column j is y component j when
   j < param_index, j+1 otherwise), has kl sub- and ku super-diagonals. Fill A(i, j) for
   max(0, j-ku) <= i <= min(n-1, j+kl) at band[PSB_BAND_INDEX(ku, ldband, i, j)] (LAPACK's
   band layout, ldband >= kl+ku+1: use the ldband given; the block arrives zeroed) and
   dparam[i] = dH_i/dparameter. It may be called twice at the same y (manual, section 3). */
typedef int (*psb_band_jacobian_fn)(const double *y, double *band, int ldband, double *dparam,
                                    void *user);
#define PSB_BAND_INDEX(ku, ldband, i, j) ((size_t)((ku) + (i) - (j)) + (size_t)(j) * (size_t)(ldband))

/* A linear solver of your own (linear = PSB_LINEAR_USER), e.g. a sparse direct solver: factor
   the bordered (n+1) x (n+1) matrix B = [dH(y); row^T] (the last row is `row`, n+1 values; you
   evaluate dH(y) yourself), then solve B z = b for nrhs right-hand sides stored column-major
   with leading dimension n+1, in place. Return 0 on success, > 0 when B is singular or the
   factorisation failed (the step is rejected), < 0 to stop at once. The library calls solve
   only after a successful factor, at most with nrhs = 2, and never calls factor while a
   previous factorisation is still needed. */
typedef struct psb_linear_solver {
    int (*factor)(const double *y, const double *row, void *ctx);
    int (*solve)(double *b, int nrhs, void *ctx);
    void *ctx;
} psb_linear_solver;

/* How the bordered systems are solved (see section 6 of the manual). */
typedef enum psb_linear {
    PSB_LINEAR_DENSE = 0,  /* LAPACK dgetrf on the (n+1) x (n+1) matrix (the default) */
    PSB_LINEAR_BANDED = 1, /* LU of the banded state block (dgbtrf's) + bordering */
    PSB_LINEAR_USER = 2    /* problem.solver */
} psb_linear;

typedef struct psb_problem {
    int n;                    /* N, the number of equations; y has N+1 components */
    psb_residual_fn residual; /* required */
    psb_jacobian_fn jacobian; /* dense: optional, NULL means finite differences (fd_step) */
    void *user;               /* passed to every callback */
    int param_index;          /* component of y that is the load parameter, 0..N
                                 (psb_problem_init sets N, the last component) */
    psb_linear linear;        /* PSB_LINEAR_DENSE (0), _BANDED or _USER */
    int kl, ku;               /* banded: bandwidths of dH/dx, 0 <= kl, ku < N */
    psb_band_jacobian_fn band_jacobian; /* banded: optional, NULL means finite differences
                                           (kl + ku + 2 residuals per Jacobian) */
    int band_lean;            /* banded: 1 keeps one copy of dH/dx instead of two, (kl + ku + 1) N
                                 doubles less; its factors are then reused only at the same y,
                                 not whenever dH/dx repeats (piecewise-linear H) [0] */
    psb_linear_solver solver; /* user: factor and solve, both required */
    /* finite-difference Jacobian (dense jacobian or banded band_jacobian NULL): column j steps
       fd_step * max(1, |y_j|), forward differences unless fd_central; the solver's copy
       (s->prob) holds the resolved step */
    double fd_step;           /* [sqrt(DBL_EPSILON) ~ 1.49e-8; 6.06e-6 ~ cbrt(DBL_EPSILON) if
                                 central]; 0 < fd_step < 1 */
    int fd_central;           /* 0: forward (n+1 residuals per Jacobian), 1: central (2(n+1));
                                 banded: kl+ku+2 and 2(kl+ku+2) [0] */
    psb_piece_fn piece;       /* optional [NULL]: lets Algorithm 2.2 take a sample point's
                                 tangent from an earlier sample point of the same piece instead
                                 of a factorisation (manual, section 6, "Piece memo") */
} psb_problem;

/* Zeroes *p (dense backend), fills it and sets param_index to n (the last component). */
PSCBRANCH_DEF void psb_problem_init(psb_problem *p, int n, psb_residual_fn residual,
                                    psb_jacobian_fn jacobian, void *user);

/* Random spans of Algorithm 2.2 (after the pairs of known branches are used up): t~2 becomes
   the tangent at y0 + h d, where d is
   PSB_RESTART_PAPER:  the previous t~2 plus 0.1 times a random unit vector, t~1 kept
                       (Remark 2.3(ii));
   PSB_RESTART_GLOBAL: a random unit vector, uniform on the sphere of the weighted norm, t~1 kept;
   PSB_RESTART_MIXED:  alternately GLOBAL's and t_j plus 0.1 times a random unit vector,
                       with t~1 = t_j, the found branches' tangents in turn. */
typedef enum psb_restart { PSB_RESTART_MIXED = 0, PSB_RESTART_PAPER = 1, PSB_RESTART_GLOBAL = 2 } psb_restart;

/* ---- options: every field's zero value means "the default in brackets" ------------------ */
/* Upper limits of the options' counts (PSB_ERR_OPTIONS above them) */
#define PSB_MAX_ITER_LIMIT 1000   /* max_iter, iter_threshold */
#define PSB_MAX_DIR_LIMIT 10000   /* n_dir, switch_n_dir */
#define PSB_MAX_SPAN_LIMIT 10000  /* n_span, n_span_max */
typedef struct psb_options {
    /* weighted inner product <a,b>_w = sum_i w_i a_i b_i, used for every norm, cosine and
       normalisation in the library */
    double kappa;          /* weight of each state component [1]; the parameter's weight is 1 */
    const double *weights; /* N+1 positive weights overriding kappa [NULL]; copied at init */

    /* predictor-corrector */
    double h_init;         /* first step size, and after each tangent switch [1e-2] */
    double h_min;          /* smallest step before the step is declared failed [1e-6] */
    double h_max;          /* largest step [1e-1] */
    double h_inc;          /* growth factor after an easy step, in [1, 100] [1.3] */
    double h_dec;          /* shrink factor after a rejected step, in [1e-3, 0.9] [0.5] */
    int max_iter;          /* corrector iterations per trial step [10] */
    int iter_threshold;    /* the step grows only when the corrector took fewer iterations [4] */
    double tol_residual;   /* ||H(y)||_2 at convergence [1e-10] */
    double tol_correction; /* distance to the solution at convergence, ||.||_w [1e-10] */
    double c_min;          /* smallest cosine between successive tangents in a step [0.9] */

    /* simple tangent switch: trial points y + delta t, delta doubling from min to max */
    double switch_delta_min; /* [h_min] */
    double switch_delta_max; /* [h_init] */
    int switch_no_sweep;     /* 1: when nothing lies straight ahead, stop instead of sweeping
                                switch_n_dir directions around the kink [0] */
    int switch_n_dir;        /* directions of that sweep [20]; <= PSB_MAX_DIR_LIMIT */

    /* tangents: two are one branch when their cosine exceeds c_diff (the tangent switch, kink
       tests, and Algorithms 2.1 and 2.2 alike) */
    double c_diff;         /* [0.99999] */
    unsigned long long seed; /* seed of every random draw: Algorithm 2.2's random spans, the
                                branch point switch's kernel search, psb_trace's random
                                borders (user backend) [0 is a valid seed] */
} psb_options;

/* Returns *opt (or all defaults when opt is NULL) with every zero field replaced by the value
   a solver uses, so a log or a test can show it; given back to psb_solver_init it means the
   same. Does not validate. */
PSCBRANCH_DEF psb_options psb_options_resolve(const psb_options *opt);

/* ---- branching options: Algorithms 2.1 and 2.2, psb_branch_point_switch ------------------ */
/* Switches for reproducing the paper and for experiments: a user leaves them at 0, which is
   the library's method (manual, section 5). */
typedef struct psb_branch_expert {
    int as_printed;       /* 1: Algorithm 2.2 exactly as printed, as far as a switch below
                             departs from it: paper_sweep = no_memo = no_screen = 1 and
                             restart = PSB_RESTART_PAPER (so a fixed length of n_span spans);
                             the other fields keep their meaning [0] */
    int paper_sweep;      /* 1: directions v = sin(a) t~1 + cos(a) t~2 exactly as printed;
                             0: t~2 is first made w-orthogonal to t~1, so that the directions
                             spread evenly over the plane [0] */
    int no_memo;          /* 1: try every direction whose region is new to its sweep, as
                             printed; 0: skip one whose tangent was tried already [0] */
    int no_screen;        /* 1: each trial along the sampled tangent, as printed; 0: along the
                             tangent at its predictor point, skipped when that one's trial is
                             known [0] */
    int restart;          /* how random spans are drawn once the pairs of known branches are
                             used up [PSB_RESTART_MIXED]: see psb_restart */
    double h_fd_steps;    /* finite differences, h left at 0: h is this many difference steps
                             at the point [1e4]; resolved to 0 when not used, while h then
                             stays 0, meaning "follows the point" */
    double trial_h_min;   /* trial steps of Algorithm 2.2 give up below this step [h_min];
                             e.g. h_init / 16 bounds each trial to 5 correctors */
    int patience;         /* stop after this many counted spans in a row found no new branch
                             [0: never] */
} psb_branch_expert;

/* Workers for Algorithm 2.2's sweep (psb_branch_options.workers) and psb_explore's drafts
   (psb_explore_options.drafts; manual, section 6, "Workers").
   run(ctx, n_tasks, task, arg) calls task(arg, i, w) once for each i in 0 .. n_tasks - 1, on
   workers w in 0 .. n_workers - 1, one task at a time on each, in any order and concurrently,
   and returns once all are done: 0, or nonzero for a failure (PSB_ERR_CALLBACK). solver[w] is
   worker w's solver: initialised on the same problem (its own user data and backend), distinct
   from the others and from the calling solver; each call sets its options to the caller's.
   memory: at least psb_workers_memory_size(n, n_dir) bytes, aligned for double (for
   psb_explore, psb_explore_workers_memory_size(n, n_dir, eo)). Same inputs:
   same results, reports and counters, bit for bit, whatever n_workers and the order the tasks
   ran in; counts differ from the serial sweep's (workers NULL). contrib/psb_workers.h has a run
   on POSIX threads and one on logical workers in turn (a model of the critical path),
   contrib/psb_workers_mpi.h one on MPI ranks (psb_workers_task_output). */
#define PSB_MAX_WORKERS 1024
struct psb_solver;
typedef void (*psb_task_fn)(void *arg, int task, int worker);
typedef struct psb_workers {
    int n_workers;               /* in [1, PSB_MAX_WORKERS] */
    struct psb_solver *const *solver; /* n_workers solvers */
    int (*run)(void *ctx, int n_tasks, psb_task_fn task, void *arg);
    void *ctx;                   /* run's */
    void *memory;                /* the tasks' results, bytes long */
    size_t bytes;
} psb_workers;

/* Given to psb_locate_end, psb_find_branches and psb_branch_point_switch (NULL: defaults) and
   in psb_explore_options.branch; every zero field takes the default in brackets (manual,
   section 5). "h_min", "h_init" in brackets are psb_options', the continuation's. */
typedef struct psb_branch_options {
    double h;             /* h of Algorithms 2.1 and 2.2 [h_min; with finite differences
                             expert.h_fd_steps difference steps at each branching point] */
    double h_min;         /* precision of Algorithm 2.1 [h / 2^14] */
    double h_init;        /* first step of each trial predictor-corrector step of 2.2, and the
                             radius of psb_branch_point_switch's sphere [h_init] */
    int n_dir;            /* directions per span of two tangents (psb_branch_point_switch:
                             2 n_dir angles on its circle) [20] */
    int n_span;           /* counted spans (selections of the two spanning tangents) [15]; with
                             the memo on, a span whose every tangent was tried before does not
                             count */
    int n_span_max;       /* counted spans at most when the sweep adapts its length [60 when
                             n_span is left at 0 and the memo is on, else n_span]: n_span <
                             n_span_max adapts; n_span_max = n_span is a fixed length */
    long max_pc;          /* stop the sweep when n_pc reaches this budget [0: no budget] */
    psb_branch_expert expert; /* paper reproduction and experiments [all 0] */
    const psb_workers *workers; /* Algorithm 2.2's directions on these workers [NULL: none] */
} psb_branch_options;

/* ---- counters ---------------------------------------------------------------------------- */
typedef struct psb_stats {
    long n_residual;    /* evaluations of H, finite differences included */
    long n_jacobian;    /* Jacobians formed (analytic or finite differences) */
    long n_factor;      /* LU or QR factorisations */
    long n_factor_reused; /* banded: factorisations skipped because dH/dx was bit-identical to
                             the one already factored (piecewise-linear problems, repeated
                             points); the results are those of factoring again */
    long n_pc_steps;    /* predictor-corrector trials (accepted or rejected) */
    long n_newton;      /* corrector / Newton iterations */
    long n_rejected;    /* rejected trials */
    long n_switches;    /* successful tangent switches */
    long n_tangents;    /* tangents computed on their own (not inside a corrector) */
    long n_tangent_reused; /* Algorithm 2.2's sample tangents taken from its Jacobian memo (dH
                              bit-identical to one whose tangent was computed in the same call:
                              piecewise-linear H) or its piece memo (problem.piece), no
                              factorisation (manual, section 6) */
} psb_stats;

/* ---- the solver: caller-owned state, all memory set up at init ------------------------ */
/* Algorithm 2.2's working state (psb_find_branches): its memos, its cone test and its sweep's
   bookkeeping. Storage set up at init; each run starts it afresh (psb__find_branches). */
typedef struct psb__sweep_state {
    double *memo;            /* tangents whose trials were made in this run (memo_n) */
    double *known;           /* tangents whose trials' outcomes are known (known_n, a ring) */
    int memo_n, known_n, memo_cap; /* entries stored, and the capacity of each memo */
    double *jmemo_t;         /* Jacobian memo: the unit tangent of each entry's dH */
    unsigned long long *jmemo_key; /* its keys: two 64-bit hashes of dH, or a piece id */
    signed char *jmemo_sign; /* its outward sign sgn det [dH; (W t)^T], 0 if not known */
    int jmemo_n;             /* its entries stored so far */
    int jmemo_dh;            /* its keys may hash dH (psb__jmemo_usable); else piece ids */
    long jmemo_looks, jmemo_hits; /* its look-ups and hits in the current run */
    long memo_cuts;          /* trials cut by psb__path_memo_cut, in all */
    int pmemo_checks;        /* piece memo against a trial's own tangents: pairs compared in */
    double pmemo_drift;      /* the current run, and the largest angle between them */
    double *path;            /* a trial's corrector tangents (psb__trial_watch) */
    int conic_h0_ok;         /* H(y0) is held for the conic test (PSB__V_BR_H0) */
    double cone_defect;      /* how far the trials saw H depart from cones about y0 (largest
                                psb__conic_excess) */
    double chord_turn_max, chord_turn_min; /* the landing points' chords from y0 against
                                              their tangents */
    unsigned long long pairs_done[32]; /* pairs (i, j), i < j < 64, of found branches swept,
                                          bit j (j - 1) / 2 + i */
    signed char branch_sign[64]; /* the outward signs of found branches 0 .. */
    int branch_signs_n;          /* .. this - 1; -1: some sign cannot be told (psb__unbalanced) */
    double sweep_offset; /* span directions at angles 2 pi (i + offset) / n, */
    int sweep_n_dir;     /* i < n = this (0: n_dir) */
    int frozen;          /* a worker's copy: the memos are read only; the last entry that would
                            have been stored goes to held (its tangent aside) */
    int held, held_sign;
    unsigned long long held_key[2];
} psb__sweep_state;

/* The solver's working storage and the algorithms' state: private, treat as opaque. */
typedef struct psb__internal {
    /* sizes, weights, memory */
    int n, np1;            /* N and N + 1 */
    double *w;             /* the weights of <.,.>_w, N + 1 */
    double *vec;           /* the named scratch vectors PSB__V_*, N + 1 each */
    double *rhs, *res, *res2, *work; /* right-hand sides, H values, a bordering row's work */
    void *owned;           /* the allocation psb_solver_init made (NULL: caller's memory) */
    unsigned ready;        /* PSB__READY between a successful init and psb_solver_free */
    unsigned long long rng[4]; /* xoshiro256** state, reseeded from options.seed per call */
    /* linear algebra: dense */
    double *jac, *mat, *tau; /* dH (N x (N+1)), B or its LU, QR's scalars */
    void *ipiv, *iwork;    /* LAPACK integers */
    /* linear algebra: banded */
    int ldlu, shifted;     /* the LU's leading dimension; A + sigma I was factored */
    int band_ok, bv_ok, border_ok; /* band holds dH/dx at yfac / bv is A^{-1} dpfac /
                                      delta is current */
    double *bandpair[2], *band, *afac; /* two copies of A; band is one, afac the one lu holds */
    double *lu, *gbw, *dparam, *dpfac, *row, *bv, *bx, *bres, *yfac, *fdh;
    double delta, mnorm, bamp; /* the Schur complement, ||B||, the amplification bound */
    int tangent_sign;      /* that of the last psb__tangent_from_jacobian's tangent */
    /* outcome of the current algorithm's trials */
    int last_fail;         /* why the last corrector run or trial step failed (PSB__FAIL_*) */
    long faults[4];        /* trials that failed because of a fault, by cause: callback > 0,
                              NaN/Inf, singular Jacobian; [3]: singular difference Jacobians,
                              a fault only when n_ok = 0 (psb__note_fault) */
    long n_ok;             /* tangents and corrector runs that succeeded */
    /* the algorithms' own */
    int in_trace_callback; /* a trace's on_point or event callback is running (psb__trace_busy) */
    double sp_d[2];        /* psb_trace's detectors: the corners d of the random borders (user
                              backend) */
    int branch_h_auto, branch_h_min_auto; /* the branching h follows the point (psb__branch_h) */
    psb__sweep_state sweep; /* Algorithm 2.2's */
} psb__internal;

typedef struct psb_solver {
    psb_problem prob; /* fd_step resolved */
    psb_options opt;  /* resolved */
    psb_branch_options branch; /* what the latest branching call used, resolved (before any:
                                  the defaults); with finite differences and h left at 0, h
                                  and h_min are the values at that call's point (Algorithms
                                  2.1 and 2.2; the branch point switch uses neither) */
    psb_stats stats;  /* cumulative; zero it whenever you like */
    char message[200]; /* diagnostic of the last failure ("" when none) */
    psb__internal internal_; /* private: treat as opaque */
} psb_solver;

/* Returns *bo (or all defaults when bo is NULL) with every zero field replaced by what the
   branching calls use on solver s (s NULL or not initialised: psb_options' defaults and an
   analytic Jacobian), and as_printed's switches set. Adaptive values say so: n_span <
   n_span_max (the sweep's length adapts between them), and with finite differences and h
   left at 0, h = 0 (h_min too unless set) with h_fd_steps > 0 (they follow each branching
   point; s->branch shows the last values). Given back to a branching call it means the same.
   Does not validate (the branching calls do: PSB_ERR_OPTIONS). */
PSCBRANCH_DEF psb_branch_options psb_branch_options_resolve(const psb_branch_options *bo,
                                                            const psb_solver *s);

/* Bytes of memory psb_solver_init_with_memory needs for the problem (0 if its sizes are
   invalid): the backend's matrices (dense ~ 2 (n+1)^2 doubles, banded ~ (4 kl + 3 ku) n), about
   100 vectors of n+1 and Algorithm 2.2's memos, 2 or 3 x c (n+1) doubles, c = min(256, max(32,
   2^19 / (n+1))). */
PSCBRANCH_DEF size_t psb_solver_memory_size(const psb_problem *p);
/* Sets up s on caller memory (at least psb_solver_memory_size(p) bytes, aligned for double);
   never allocates. Validates the problem and the options.
   Returns PSB_SUCCESS, PSB_ERR_NULL, PSB_ERR_SIZE, PSB_ERR_OPTIONS, PSB_ERR_NOMEM (too small). */
PSCBRANCH_DEF psb_result psb_solver_init_with_memory(psb_solver *s, const psb_problem *p,
                                                     const psb_options *opt, void *memory,
                                                     size_t bytes);
/* Same, allocating with PSCBRANCH_MALLOC; release with psb_solver_free. */
PSCBRANCH_DEF psb_result psb_solver_init(psb_solver *s, const psb_problem *p,
                                         const psb_options *opt);
/* Frees what psb_solver_init allocated (nothing for caller memory) and clears s (its stats
   stay), so that every later call on it returns PSB_ERR_NULL until the next init. s may be
   NULL; freeing twice is harmless. */
PSCBRANCH_DEF void psb_solver_free(psb_solver *s);
/* The last diagnostic message, "" if none; never NULL. */
PSCBRANCH_DEF const char *psb_solver_message(const psb_solver *s);

/* Weighted inner product and norm of vectors of n+1 components; NaN when s is NULL, freed or
   not initialised, or a or b is NULL. */
PSCBRANCH_DEF double psb_dot_w(const psb_solver *s, const double *a, const double *b);
PSCBRANCH_DEF double psb_norm_w(const psb_solver *s, const double *a);

/* ---- single operations (none allocates; all may be called from a point callback) -------- */

/* Newton's method on H(y) = 0 with y[param_index] held fixed, for a starting point.
   y (in/out, n+1): untouched unless PSB_SUCCESS. max_iter <= 0 means 50; above
   PSB_MAX_ITER_LIMIT: PSB_ERR_INPUT.
   Returns PSB_SUCCESS, PSB_ERR_NO_CONVERGENCE, PSB_ERR_SINGULAR, PSB_ERR_NONFINITE,
   PSB_ERR_CALLBACK(_FAILED), PSB_ERR_NULL. */
PSCBRANCH_DEF psb_result psb_solve_at_param(psb_solver *s, double *y, int max_iter);

/* Unit tangent t (out, n+1) at y (in): dH(y) t = 0, ||t||_w = 1, <t, ref>_w >= 0. Solves the
   bordered system [dH(y); (W ref)^T] t = e_{n+1}; when that is singular or ill-conditioned
   (ref nearly orthogonal to the kernel, e.g. at a fold with ref = e_param) it falls back to
   the QR factorisation of dH(y)^T. ref may be NULL (then e_param orients t).
   Returns PSB_SUCCESS, PSB_ERR_SINGULAR (rank of dH(y) < n), PSB_ERR_NONFINITE, ...; t is
   written only on success. */
PSCBRANCH_DEF psb_result psb_tangent(psb_solver *s, const double *y, const double *ref,
                                     double *t);

/* Moore-Penrose corrector from the couple (y, t) (in/out): each iteration factors
   [dH(y); (W t)^T] once and solves it for the point update (rhs [H(y); 0]) and the new
   tangent (rhs [0; 1]). iterations (out, may be NULL): the iterations spent, also on failure.
   Returns PSB_SUCCESS, PSB_ERR_NO_CONVERGENCE, PSB_ERR_SINGULAR, ...; y, t untouched on failure. */
PSCBRANCH_DEF psb_result psb_correct(psb_solver *s, double *y, double *t, int *iterations);

/* One predictor-corrector step from (y, t) with step size *h, shrinking it (h_dec) until the
   corrector converges no farther than *h from the prediction y + *h t, with a tangent within
   c_min of t, or until *h < h_min. On success (y, t) is
   the new couple and *h the step that was accepted, already adapted for the next step (h_inc
   when the corrector was quick, capped at h_max). On failure y, t and *h are untouched.
   Returns PSB_SUCCESS, PSB_ERR_STEP_TOO_SMALL (every trial failed for the curve's sake),
   PSB_ERR_CALLBACK_FAILED / _NONFINITE / _SINGULAR (a trial failed because of the callback,
   a NaN or a Jacobian of rank < N, and no smaller one converged; with differences, _SINGULAR
   when no trial converged and dH(y) has no tangent either), PSB_ERR_CALLBACK, ... */
PSCBRANCH_DEF psb_result psb_step(psb_solver *s, double *y, double *t, double *h);

/* Simple tangent switch at a couple (y, t) where steps fail (a kink ahead): computes the
   tangent t~ at y + delta t for delta = switch_delta_min, 2 delta, ... <= switch_delta_max and,
   once t~ differs from t (cosine < c_diff), tries steps from y along +t~ then -t~, accepting a
   new couple that does not go back along the incoming branch; then the sweep, then both again
   for any t~ that differs from t beyond rounding (section 6).
   Returns PSB_SUCCESS (y, t updated), PSB_NONSMOOTH_END (nothing found; y, t untouched), or
   a failure (y, t untouched), also when a probe or trial failed because of a fault (section 3). */
PSCBRANCH_DEF psb_result psb_switch_tangent(psb_solver *s, double *y, double *t);

/* ---- the driver -------------------------------------------------------------------------- */
#define PSB_POINT_START 1  /* the first point of a trace */
#define PSB_POINT_FOLD 2   /* the parameter component of t changed sign since the last point */
#define PSB_POINT_SWITCH 4 /* reached through a tangent switch (a kink was passed) */
#define PSB_POINT_BOUND 8  /* the point lies exactly on a parameter bound */
#define PSB_POINT_KINK 16  /* the last couple before a kink, located to h_min (locate_kinks) */
#define PSB_POINT_SPECIAL 32 /* p->special describes a located special point (its own on_point
                                call, before the accepted point that follows it; detect) */
#define PSB_MAX_FOLDS 16

/* Kinds of special points on a traced curve (psb_trace_options.detect; manual section 6,
   "Special points on the path"). */
typedef enum psb_special_kind {
    PSB_SPECIAL_FOLD = 1,      /* limit point: the parameter component of t vanishes (smooth) */
    PSB_SPECIAL_FOLD_KINK = 2, /* nonsmooth fold: the parameter has an extremum at a kink */
    PSB_SPECIAL_BRANCH = 3,    /* smooth branch point: the sign of det [dH; t^T] changes */
    PSB_SPECIAL_PC1 = 4,       /* PC1 bifurcation passed through: det sign changes across a kink */
    PSB_SPECIAL_EVENT = 5      /* a user event function changed sign */
} psb_special_kind;

typedef struct psb_special {
    psb_special_kind kind;
    const double *y, *t;  /* FOLD, BRANCH, EVENT: the located point on the curve and the unit
                             tangent there (direction of travel), n+1 each. PC1, FOLD_KINK:
                             the last couple on the incoming smooth piece, within `precision`
                             of the kink (ready for psb_locate_end + psb_find_branches) */
    const double *kernel; /* BRANCH: unit (||.||_w) second kernel direction of dH at the point,
                             w-orthogonal to t (for psb_branch_point_switch); NULL otherwise,
                             and where it could not be computed (no fault: the point is kept).
                             y, t, kernel point into the solver's memory: valid during the
                             on_point call and until the next library call on the solver
                             (psb_branch_point_switch and psb_locate_end take them as input) */
    double param;         /* y[param_index] of the reported point */
    double precision;     /* bound on the location error, ||.||_w along the curve, of the zero
                             of the test function as computed (0: hit exactly); with dH by
                             finite differences that zero is off by about fd_step */
    int event;            /* EVENT: index of the event component; -1 otherwise */
    int direction;        /* EVENT: +1 rising, -1 falling; 0 otherwise */
    int located;          /* PC1: 1 when the trace went straight through the nonsmooth point
                             (the tangent did not turn, det jumped there): y is within
                             `precision` of it already, and psb_locate_end, which looks for a
                             turn, finds none: pass the couple to psb_find_branches as it is */
} psb_special;

/* psb_trace_options.detect: a bit mask */
#define PSB_DETECT_FOLDS 1  /* smooth folds located, nonsmooth folds reported at their kink */
#define PSB_DETECT_BRANCH 2 /* smooth branch points (dense, banded and user backends) */
#define PSB_DETECT_PC1 4    /* PC1 bifurcation points passed through (dense and banded) */
#define PSB_DETECT_EVENTS 8 /* sign changes of the event functions */
#define PSB_DETECT_ALL 15

/* Event functions g(y) = (g_0 .. g_{n_events-1}) (y: n+1 values in, g: n_events out); same
   return convention as the residual (0 ok; > 0 or NaN/Inf: the trace fails with
   PSB_ERR_CALLBACK_FAILED / PSB_ERR_NONFINITE; < 0 stops with PSB_ERR_CALLBACK). */
typedef int (*psb_event_fn)(const double *y, double *g, void *user);

typedef struct psb_point {
    const double *y, *t; /* the accepted couple (n+1 each) */
    double h;            /* the step that reached it (0 for the start) */
    long index;          /* 0 for the start, then 1, 2, ... */
    int flags;           /* PSB_POINT_* */
    double fold_param;   /* with PSB_POINT_FOLD: estimated parameter value of the limit point */
    const psb_special *special; /* non-NULL only with PSB_POINT_SPECIAL */
} psb_point;

/* Called for every accepted point; return nonzero to stop the trace (PSB_STOPPED). */
typedef int (*psb_point_fn)(const psb_point *pt, void *user);

typedef struct psb_trace_options {
    double param_min, param_max; /* bounds on y[param_index]; ignored when param_min >= param_max;
                                    either may be infinite, NaN gives PSB_ERR_INPUT. The trace
                                    ends on the first point of the curve on a bound, also where
                                    a fold lies beyond it within a step (retaken shorter) */
    long max_steps;              /* accepted steps [0 -> 10000]; < 0 gives PSB_ERR_OPTIONS */
    int no_switch;               /* 1: stop (PSB_NONSMOOTH_END) instead of switching at a kink */
    int detect_loop;             /* 1: stop (PSB_LOOP_CLOSED) when the curve returns to its start */
    int locate_kinks;            /* 1: locate the first kink of each step that passes one (where
                                    the tangent turns by an angle that does not shrink with the
                                    step) to within h_min and report the couple just before it as
                                    a PSB_POINT_KINK point; a nonzero return from on_point there
                                    stops the trace on it. 2: every kink of the step, in order
                                    (up to 8), at a search of the rest of the step past each.
                                    Other values give PSB_ERR_OPTIONS */
    psb_point_fn on_point;       /* optional */
    void *point_user;
    /* special points on the path (manual section 6, "Special points on the path") */
    int detect;                  /* PSB_DETECT_* bit mask [0: none; results as without] */
    unsigned stop_at;            /* bit (1u << kind): stop (PSB_STOPPED) with (y, t) the special
                                    point's couple [0] */
    double locate_tol;           /* precision of location, ||.||_w along the curve [1e-10] */
    int n_events;                /* event components (PSB_DETECT_EVENTS) [0] */
    psb_event_fn event;          /* required when n_events > 0 */
    void *event_user;
    double *event_work;          /* 3 n_events doubles of the caller's for the event values
                                    (no allocation in the library) */
} psb_trace_options;

typedef struct psb_trace_report {
    psb_result end;   /* how the trace ended (the return value) */
    long steps;       /* accepted steps */
    int n_switches;   /* kinks passed */
    int n_folds;      /* limit points detected */
    int n_kinks;      /* kinks located (locate_kinks) */
    double fold_params[PSB_MAX_FOLDS]; /* their parameter values (the first PSB_MAX_FOLDS) */
    double h;         /* the step size at the end */
    int n_special[6]; /* special points reported, by kind (index PSB_SPECIAL_*; 0 unused) */
} psb_trace_report;

/* Traces the curve through (y, t) (in/out; t is the direction of travel, ||t||_w = 1 is
   enforced) until a bound, the step budget, an end point it cannot pass, or a failure. At the
   end (y, t) is the last accepted couple; a failure before the first accepted step leaves them
   untouched. With bounds, the last point lies exactly on the bound (bounds may be infinite;
   NaN gives PSB_ERR_INPUT). to and rep may be NULL (rep is always written). Returns
   PSB_PARAM_BOUND, PSB_STEP_BUDGET, PSB_NONSMOOTH_END, PSB_STOPPED, PSB_LOOP_CLOSED, or a
   failure (PSB_ERR_CALLBACK when a callback returned < 0). With detectors, a fault while
   evaluating a test function or an event, or while locating a special point (a callback's
   > 0 or NaN/Inf; with the user backend also solver.factor/solve's failure where the matrix
   is regular) fails the trace with that code rather than miss or mislocate the point; a
   singular matrix next to a branch point is geometry: the location stops there, with
   special.precision the bracket reached. */
PSCBRANCH_DEF psb_result psb_trace(psb_solver *s, double *y, double *t,
                                   const psb_trace_options *to, psb_trace_report *rep);

/* ---- branching at a nonsmooth point ---------------------------------------------------- */

/* Algorithm 2.1: from the last couple (y, t) (in/out) of a branch ending at a nonsmooth point,
   halves h from bo->h down to bo->h_min (bo: psb_branch_options, NULL for defaults), moving y
   towards the end point whenever a correction of y + h t converges with a tangent within
   c_diff of t (and trying the same h again after each such move, see section 6; where the
   branch only curved by more than c_diff's angle since t, it follows on from there with the
   tangent there, or with finite differences along a chord there). On return y
   approximates the end point, t (unit) points out of the branch's region, *precision (may be
   NULL) bounds y's distance from it (manual section 6). Returns PSB_SUCCESS or a failure, with y, t and *precision
   untouched: PSB_ERR_CALLBACK_FAILED / _NONFINITE / _SINGULAR when the last trial failed
   because of a fault (the end point is then not located), PSB_ERR_NO_CONVERGENCE when no end
   point lies within 1000 moves or, with finite differences, no branch tangent could be
   computed 4 to 64 h behind it, PSB_ERR_OPTIONS (bo; psb_solver_message names the field),
   PSB_ERR_CALLBACK ... s->branch holds the resolved options used (unchanged by PSB_ERR_NULL or
   _OPTIONS). */
PSCBRANCH_DEF psb_result psb_locate_end(psb_solver *s, double *y, double *t,
                                        const psb_branch_options *bo, double *precision);

typedef struct psb_branch_report {
    int n_branches;   /* found, input branch included */
    long n_pc;        /* trial predictor-corrector steps (Step 5 and 6), as n_pc of the paper */
    int n_rand;       /* spans chosen at random (Remark 2.3(ii)), as n_rand of the paper */
    int n_span;       /* spans that tried a direction (these count against n_span) */
    int n_span_idle;  /* spans whose every tangent had been tried before: they cost n_dir
                         tangents, try nothing and do not count (memo on, see n_span) */
    long n_tangents;  /* tangents computed at y0 + h v, and at predictor points (screening) */
    long n_memo;      /* directions not tried because their tangent was tried before */
    long n_screened;  /* trials skipped: the tangent at their predictor point had been
                         tried, or was a found branch's (see no_screen) */
    long n_cut;       /* trials (counted in n_pc) ended once a corrector iteration's tangent
                         was one of those (see no_screen) */
    long n_cut_memo;  /* of those, trials ended before that iteration's factorisation: the
                         memo held the tangent (section 6, "The memo's cut") */
    int span_last_new;    /* the counted span (1-based) in which the last new branch was
                             found: the smallest n_span that finds them all, all else equal */
    long n_pc_last_new;   /* n_pc and n_rand at the end of that span, i.e. what a run with */
    int n_rand_last_new;  /* n_span = span_last_new would report */
    int n_span_odd;       /* of n_span, the spans of the sweeps that an odd count or unbalanced
                             signs began, with directions between the first sweep's (section
                             6, "An odd count"; 0 when the first sweep's set was balanced) */
    int unbalanced;       /* 1: an even count whose outward signs do not add up to 0, so most
                             likely two branches missing (dense and banded backends; section
                             6, "An odd count"); 0 otherwise, odd counts included */
    long n_failed;        /* trials and sample tangents that failed because of a fault, the sum
                             of the next three; psb_find_branches succeeds only when it is 0 */
    long n_failed_callback;  /* ... because a callback returned > 0 */
    long n_failed_nonfinite; /* ... because of NaN or Inf from a callback */
    long n_failed_singular;  /* ... because dH had rank < N there (no tangent), or
                                solver.factor failed whatever the bordering row */
} psb_branch_report;

/* Algorithm 2.2 with the restarts of Section 3: bo->n_span spans of two tangents, each swept
   in bo->n_dir directions (with the memo, spans that try nothing new do not count: section 6);
   bo NULL: defaults; s->branch the resolved options used. (y0, t0) is Algorithm 2.1's output.
   Branch k (k < max_branches) is the couple ys[k*(n+1) ...], ts[k*(n+1) ...] with ts oriented
   away from the point; branch 0 is the incoming branch (y0, -t0). rep may be NULL. Where a
   kink lies within h_init the run is made again with a smaller h_init (section 6, "Kinks
   within h_init"; rep is the last run's). Same seed, same result, bit for bit. Returns
   PSB_SUCCESS, PSB_BRANCH_CAPACITY, or a failure: PSB_ERR_CALLBACK_FAILED / _NONFINITE / _SINGULAR when a trial or sample tangent failed
   because of a fault (the set may be incomplete; rep->n_failed* count them), PSB_ERR_OPTIONS
   (bo), PSB_ERR_CALLBACK, ... After a failure ys, ts hold the rep->n_branches branches found
   until then and rep is written; y0, t0 are inputs only. A success with an odd
   rep->n_branches or with rep->unbalanced most likely misses branches (section 6, "An odd
   count"). */
PSCBRANCH_DEF psb_result psb_find_branches(psb_solver *s, const double *y0, const double *t0,
                                           const psb_branch_options *bo, int max_branches,
                                           double *ys, double *ts, psb_branch_report *rep);
/* Bytes of psb_workers.memory for problems of n unknowns swept in n_dir directions (0 when
   either is below 1). With bo->workers set, psb_find_branches, psb_locate_end,
   psb_branch_point_switch and psb_explore (eo.branch) also return PSB_ERR_NULL (run, solver or
   memory NULL, a solver not initialised), PSB_ERR_SIZE (n_workers out of range, or a solver of
   another size, backend or set of callbacks), PSB_ERR_INPUT (a solver given twice, or the
   calling one), PSB_ERR_NOMEM (memory too small) and PSB_ERR_CALLBACK (run returned nonzero). */
PSCBRANCH_DEF size_t psb_workers_memory_size(int n, int n_dir);
struct psb_explore_options;
/* Bytes of psb_workers.memory for psb_explore with options eo (NULL: defaults): the sweep's and
   eo->drafts drafts of eo->draft_points points (0 for values out of range). */
PSCBRANCH_DEF size_t psb_explore_workers_memory_size(int n, int n_dir, const struct psb_explore_options *eo);
/* For workers in address spaces of their own (MPI ranks that all run the same program on the
   same data, each with one solver, n_workers 1): what task `task` of a run (arg as given to run)
   writes, bytes at out, and its group; tasks of one group must run on one rank, and once they
   ran, their bytes go to every other rank (MPI_Bcast from it: contrib/psb_workers_mpi.h). */
PSCBRANCH_DEF void psb_workers_task_output(const void *arg, int task, int *group, void **out,
                                           size_t *bytes);

/* Branches through a smooth branch point located by psb_trace (y, t, kernel of a
   PSB_SPECIAL_BRANCH point): every branch's couple (ys[k*(n+1) ...], ts[k*(n+1) ...],
   k < max_branches) on the sphere of radius bo->h_init around y (bo NULL: defaults; of bo it
   uses h_init and n_dir), ts oriented away from
   the point; k = 0 is the traced curve backwards (-t), k = 1 forwards (+t), k >= 2 the new
   ones (where more than two curves cross, all of them: in the plane of t and kernel, and in
   a kernel of up to 5 dimensions); the radius is smaller where a kink lies between the point
   and a crossing (section 6). rep as psb_find_branches' (n_branches; n_pc counts the
   sphere corrections, n_tangents the kernel's dimension besides t, n_span the radii tried).
   Same seed, same result. Returns PSB_SUCCESS, PSB_BRANCH_CAPACITY, or a failure:
   PSB_ERR_NULL, PSB_ERR_SIZE (max_branches < 1), PSB_ERR_NONFINITE (y, t or kernel; or a
   callback's NaN/Inf), PSB_ERR_INPUT (t zero, kernel zero or parallel to t), PSB_ERR_OPTIONS
   (bo), PSB_ERR_NO_CONVERGENCE (the traced curve, -t and +t, crosses none of the spheres: y is
   not on it), and, as psb_find_branches, PSB_ERR_CALLBACK_FAILED / _NONFINITE / _SINGULAR
   when a sphere trial or the kernel's computation failed because of a fault (a branch may be
   missing; rep->n_failed* count them), PSB_ERR_CALLBACK. After a failure ys, ts hold the
   rep->n_branches couples found until then and rep is written; y, t, kernel are inputs only. */
PSCBRANCH_DEF psb_result psb_branch_point_switch(psb_solver *s, const double *y, const double *t,
                                                 const double *kernel, const psb_branch_options *bo,
                                                 int max_branches, double *ys, double *ts,
                                                 psb_branch_report *rep);
/* ---- quasi-static evolution: one time step through folds (manual, section 6) ------------- */

/* How psb_evolve_step solves its step. */
typedef enum psb_evolve_mode {
    PSB_EVOLVE_AUTO = 0,        /* Newton at param_next from y; continuation when Newton fails
                                   or lands farther than newton_max_jump */
    PSB_EVOLVE_NEWTON = 1,      /* Newton only (plain time stepping) */
    PSB_EVOLVE_CONTINUATION = 2 /* continuation only */
} psb_evolve_mode;

typedef struct psb_evolve_options {
    int mode;               /* psb_evolve_mode [PSB_EVOLVE_AUTO] */
    int newton_max_iter;    /* Newton iterations at param_next [20] */
    double newton_max_jump; /* AUTO: a Newton solution farther than this from y (||.||_w) is
                               not accepted; continuation decides [0: any distance] */
    double param_min, param_max; /* the path may not leave [param_min, param_max] (ignored when
                                    param_min >= param_max); y's parameter and param_next must
                                    lie in it [unbounded beyond the start] */
    long max_steps;         /* accepted continuation steps [0 -> 10000] */
    double max_length;      /* longest continuation path, ||.||_w [0: no limit] */
    int no_switch;          /* 1: do not pass kinks (psb_trace_options.no_switch) [0] */
    psb_point_fn on_point;  /* optional: every point of the continuation path (psb_trace's
                               points); a nonzero return stops the step (PSB_ERR_CALLBACK) */
    void *point_user;
} psb_evolve_options;

typedef struct psb_evolve_report {
    int method;            /* PSB_EVOLVE_NEWTON or _CONTINUATION: what solved the step (0 on
                              failure) */
    psb_result newton;     /* Newton's outcome at param_next (PSB_SUCCESS also when its
                              solution was rejected as a jump); PSB_SUCCESS when not run */
    int newton_run;        /* 1: Newton was tried */
    double newton_jump;    /* ||y_Newton - y||_w when Newton converged, else -1 */
    double newton_gap;     /* ||y_Newton - y_continuation||_w when both exist, else -1: how far
                              plain time stepping would have landed from the path's end */
    int snap_through;      /* 1: the path passed a fold (n_folds > 0): the solution jumped */
    int n_folds;           /* folds passed, and their parameter values (as psb_trace_report) */
    double fold_params[PSB_MAX_FOLDS];
    int n_switches;        /* kinks passed by the tangent switch */
    long steps;            /* accepted continuation steps */
    double path_length;    /* length of the continuation path, ||.||_w (chords) */
    double param_low, param_high; /* parameter range the path covered */
    double jump;           /* ||y_new - y||_w on success */
    psb_result trace_end;  /* how psb_trace ended (PSB_PARAM_BOUND when it reached param_next) */
    psb_stats cost;        /* the step's own counters (factorisations, residuals, trials) */
} psb_evolve_report;

/* One time step of a discretised quasi-static evolution problem (Ligursky-Renard, CMAME 280
   (2014)): from the previous state y (in/out, n+1; y[param_index] = lambda_{k-1}, H(y) = 0 with
   the step's data, e.g. previous tangential displacements held in problem.user) to a solution
   at param_next. AUTO: Newton at param_next from y; if it fails (or jumps farther than
   newton_max_jump), the curve H(y) = 0 is traced from y towards param_next, through folds and
   kinks, and the step ends where it first reaches param_next (psb_trace bounded on that side
   only; behind the start the path is free up to param_min/param_max). The direction of travel
   is the tangent's at y with its parameter component towards param_next (at a fold of the
   start itself it is arbitrary). On success y holds the new state, y[param_index] =
   param_next exactly; param_next equal to y's parameter only corrects y by Newton. Does not
   allocate; not callable from a point callback of psb_trace (it runs one).
   eo and rep may be NULL. Returns PSB_SUCCESS; PSB_ERR_NULL, PSB_ERR_NONFINITE (y or
   param_next), PSB_ERR_OPTIONS (eo), PSB_ERR_INPUT (y or param_next outside the range, or y
   does not solve H = 0: no solution within h_init of it); Newton's failure in
   PSB_EVOLVE_NEWTON mode; PSB_ERR_NO_CONVERGENCE when the path ended elsewhere
   (rep->trace_end says how: step budget, max_length, an end point, a closed loop, the range's
   far bound); PSB_ERR_CALLBACK (a callback returned < 0, or on_point stopped the path); or a
   failure of psb_tangent or psb_trace (PSB_ERR_SINGULAR at a start where dH has rank < N,
   PSB_ERR_STEP_TOO_SMALL, ...); a callback's failure (> 0, NaN/Inf) or a singular matrix
   while y is polished is returned as itself (PSB_ERR_CALLBACK_FAILED, _NONFINITE,
   _SINGULAR), not as PSB_ERR_INPUT. newton_max_iter <= PSB_MAX_ITER_LIMIT. y is untouched
   unless PSB_SUCCESS; rep is always written. */
PSCBRANCH_DEF psb_result psb_evolve_step(psb_solver *s, double *y, double param_next,
                                         const psb_evolve_options *eo, psb_evolve_report *rep);

/* ---- fold curves in two parameters (manual section 6, "Fold curves in two parameters") ---- */

/* A two-parameter problem's banded Jacobian (linear = PSB_LINEAR_BANDED): H_x, n x n with kl
   sub- and ku super-diagonals, at band[PSB_BAND_INDEX(ku, ldband, i, j)] as for
   psb_band_jacobian_fn (zeroed on entry; state column j is the j-th component of y that is
   neither lambda nor mu), and the columns dlambda = dH/dlambda, dmu = dH/dmu (n each). */
typedef int (*psb_two_band_jacobian_fn)(const double *y, double *band, int ldband,
                                        double *dlambda, double *dmu, void *user);

/* A problem in two parameters: n equations H(y) = 0 in n+2 unknowns y, the load lambda =
   y[lambda_index], a second parameter mu = y[mu_index], and the state x, the other n components
   in their order. residual and jacobian (psb_residual_fn, psb_jacobian_fn) take y with n+2
   components; the jacobian fills all n+2 columns (a selection gradient where H is PC^1). */
typedef struct psb_two_param_problem {
    int n;                      /* N >= 1, the number of equations */
    psb_residual_fn residual;   /* required */
    psb_jacobian_fn jacobian;   /* dense: required, H_x enters the fold condition (no
                                   differences); banded: not used */
    void *user;                 /* passed to every callback */
    int lambda_index, mu_index; /* distinct, in [0, n+1] (psb_two_param_problem_init: n, n+1) */
    psb_linear linear;          /* PSB_LINEAR_DENSE (0) or _BANDED (not _USER) */
    int kl, ku;                 /* banded: bandwidths of H_x, in [0, n-1] */
    psb_two_band_jacobian_fn band_jacobian; /* banded: required */
} psb_two_param_problem;

/* Zeroes *p and fills it; lambda_index = n, mu_index = n+1 (y = (x, lambda, mu)). */
PSCBRANCH_DEF void psb_two_param_problem_init(psb_two_param_problem *p, int n,
                                              psb_residual_fn residual,
                                              psb_jacobian_fn jacobian, void *user);

/* The two problems a two-parameter problem gives, on caller memory. at_mu is H at fixed mu for
   every one-parameter call: its y is the user's without the mu component (those after it move
   down one), its param_index lambda's. fold is the fold curve: N+1 equations [H(y); sigma(y)] =
   0 in the user's own y (N+2 components), param_index = mu_index, where sigma solves
   [H_x b; c^T 0] [v; sigma] = [0; 1] with the borders b, c of psb_fold_map_start. Give each to
   psb_solver_init (their user pointer is the map, so a map is not copied). Dense problem: both
   are dense. Banded: at_mu is banded (kl, ku), fold has the user backend (PSB_LINEAR_USER, no
   PC1 detection) that the map implements by block elimination on the LU of H_x, refined
   against the bordered matrix (manual, section 6). A map serves one thread at a time; it holds
   no allocation (nothing to free). */
typedef struct psb_fold_map {
    psb_two_param_problem two; /* a copy of the problem */
    double mu;           /* at_mu's mu: set it between calls only [psb_fold_map_init's] */
    psb_problem at_mu;   /* H(., mu): n equations, n+1 unknowns */
    psb_problem fold;    /* the fold curve: n+1 equations, n+2 unknowns, parameter mu */
    const double *b, *c; /* the borders (n each, unit 2-norm; zero before the first start) */
    long n_factor;       /* LUs made by fold's residual, Jacobian and banded solver, cumulative
                            (dense: of [H_x b; c^T 0]; banded: of H_x) */
    struct {             /* private: treat as opaque */
        double *jac, *mat, *rhs, *y_eval, *y_lift, *y_try, *b, *c, *b_old, *c_old;
        double *ab, *ab_d, *lu, *gbw, *dpar, *dpar_d, *bx, *bres, *bdx, *brow, *y_fac, *y_usr;
        double *wc, *wkey; /* A^{-1} C (A^{-T} R) of three kinds of solve, and their C (R) */
        double dmat[4], mnorm; /* the fold matrix's lower right block; ||H_x||_1 of the LU */
        long lu_gen, wgen[3]; /* factorisations made; the one each wc slot was made with */
        int *state;      /* y's component of each state column */
        void *ipiv;
        int lu_ok, shifted; /* lu holds the factors of H_x(y_fac) (+ a shift) */
        unsigned ready;
    } internal_;
} psb_fold_map;

/* Bytes psb_fold_map_init needs for a dense problem of n equations (0 when n < 1 or n >
   46000): about 2 (n+1)^2 doubles. */
PSCBRANCH_DEF size_t psb_fold_map_memory_size(int n);
/* Bytes psb_fold_map_init needs for p, dense or banded (0 when p is NULL or its n, kl, ku or
   linear are out of range); banded: about (4 kl + 3 ku + 31) n doubles. */
PSCBRANCH_DEF size_t psb_fold_map_memory_size_for(const psb_two_param_problem *p);
/* Sets up m for the problem p (copied) and the at_mu problem's mu, on caller memory (at least
   psb_fold_map_memory_size_for(p) bytes, aligned for double); never allocates. The fold curve
   needs borders: psb_fold_map_start. Returns PSB_SUCCESS, PSB_ERR_NULL (m, p, memory, a
   required callback), PSB_ERR_SIZE (n, lambda_index, mu_index, kl, ku), PSB_ERR_OPTIONS
   (linear not DENSE or BANDED), PSB_ERR_NONFINITE (mu), PSB_ERR_NOMEM (block too small); *m is
   cleared on failure. */
PSCBRANCH_DEF psb_result psb_fold_map_init(psb_fold_map *m, const psb_two_param_problem *p,
                                           double mu, void *memory, size_t bytes);
/* From a fold of the one-parameter problem at_mu (a couple (y, t), n+1 each in at_mu's
   coordinates, e.g. a PSB_SPECIAL_FOLD's special->y, ->t from psb_trace on a solver of m->at_mu)
   to the fold curve: takes the borders c = t's state part, b = the left null vector of H_x there,
   refines the fold by Newton on fold at mu = m->mu (fold_solver: a solver of m->fold), then
   takes the borders at the refined fold and refines again. y_fold (out, n+2): the fold in the
   user's coordinates; t_fold (out, n+2, may be NULL): the fold curve's unit tangent there,
   oriented towards larger mu (psb_tangent). Not callable from a callback of a trace on
   fold_solver. Returns PSB_SUCCESS; PSB_ERR_NULL; PSB_ERR_INPUT (fold_solver is not on m->fold,
   a call from its trace, t without a state part, or (y, t) is not a fold: Newton at fixed mu
   fails or moves it more than fold_solver's h_init, ||.||_w); PSB_ERR_NONFINITE (y, t, m->mu,
   a callback's NaN); PSB_ERR_SINGULAR ([H_x H_lambda; c^T 0] singular at y: dH of rank < n, or
   t no tangent); PSB_ERR_CALLBACK(_FAILED). On failure y_fold, t_fold and the borders are
   untouched (the message is fold_solver's). */
PSCBRANCH_DEF psb_result psb_fold_map_start(psb_fold_map *m, psb_solver *fold_solver,
                                            const double *y, const double *t, double *y_fold,
                                            double *t_fold);
/* The fold at y[mu_index] from y (in/out, n+2, the user's coordinates), e.g. a point of the
   fold curve taken to another mu: the borders are taken anew at y (from the current ones),
   Newton on fold at fixed mu (psb_solve_at_param on fold_solver, max_iter as there), borders
   at the result, Newton again. The borders stay the new ones, also for later traces of the
   fold curve (never while a trace of it runs). Returns as psb_solve_at_param, and
   PSB_ERR_INPUT (fold_solver not on m->fold, or a call from its trace), PSB_ERR_SINGULAR (the
   bordered matrix singular at y). y and the borders are untouched unless PSB_SUCCESS. */
PSCBRANCH_DEF psb_result psb_fold_map_refine(psb_fold_map *m, psb_solver *fold_solver, double *y,
                                             int max_iter);

/* ---- branch counts in two parameters (manual section 6, "Branch counts in two parameters") */

/* Sets the second parameter mu of the solver's problem (e.g. a field of problem.user) for the
   calls that follow. Returns 0; > 0: failed (PSB_ERR_CALLBACK_FAILED); < 0: stop
   (PSB_ERR_CALLBACK). */
typedef int (*psb_set_mu_fn)(double mu, void *user);

/* Zero-initialise; every zero field takes the default in brackets. */
typedef struct psb_count_map_options {
    int n_samples;   /* values of mu from mu_from to mu_to, evenly spaced, 2..100000 [11] */
    double mu_tol;   /* a change's bracket is narrowed to mu_tol (1 + |mu|), unless the
                        merging pair is too close to tell apart first, in [1e-15, 0.1] [1e-10] */
    int max_bisect;  /* halvings of a sample interval by counts before the merge is sought,
                        1..60 [8] */
    double approach; /* ||.||_w from the point (predicted from the last two) at which a
                        branch of the last point is taken up at a new mu, followed by
                        continuation to its end and Algorithm 2.1 [4 h_init] */
} psb_count_map_options;

/* The nonsmooth point at one sampled mu. */
typedef struct psb_count_sample {
    double mu;
    int n_branches;    /* Algorithm 2.2's count there, the incoming branch included; -1 when
                          the point was not found (result) */
    int unbalanced;    /* psb_branch_report.unbalanced there */
    psb_result result; /* of Algorithms 2.1 and 2.2 there (PSB_BRANCH_CAPACITY: more branches
                          than max_branches, the count is max_branches) */
} psb_count_sample;

/* Where the count changes between two samples. */
typedef struct psb_count_change {
    double mu;                   /* the change, in [mu_lo, mu_hi]: with merge, where the secant
                                    of the pair's angle vanishes (to rounding on a piecewise-
                                    linear H) or the bracket's middle once within mu_tol */
    double mu_lo, mu_hi;         /* a bracket: merge: the pair apart at one end, met at the
                                    other; else the counts differ at its ends */
    int count_lo, count_hi;      /* Algorithm 2.2's counts below and above the change ... */
    double mu_count_lo, mu_count_hi; /* ... found at these mu (mu_count_lo <= mu_lo, and
                                        mu_hi <= mu_count_hi) */
    int merge;                   /* 1: located where the two closest branches of the larger
                                    count meet, following them in mu; 0: by counts alone */
} psb_count_change;

typedef struct psb_count_map_report {
    int n_changes;  /* changes located (the first max_changes stored) */
    long n_find;    /* runs of Algorithm 2.2 */
    long n_follow;  /* corrections following a pair of branches in mu */
    psb_stats stats; /* the solver's counters the map spent */
} psb_count_map_report;

/* Bytes of caller memory psb_count_map needs (0 when n < 1 or max_branches outside
   2..100000): (12 max_branches + 31) (n+1) doubles. */
PSCBRANCH_DEF size_t psb_count_map_memory_size(int n, int max_branches);
/* The number of branches at a nonsmooth point as mu runs from mu_from to mu_to. s is a solver
   of the problem at fixed mu (any backend; set_mu(mu, mu_user) moves its mu); (y, t) the last
   couple of a branch ending at the point at mu_from, as for psb_locate_end. At each later
   sample a branch of the previous point (the incoming one first) is taken up `approach`
   before the point, followed to its end (psb_step, then Algorithm 2.1; through mu halfway
   where the point moved too far), and Algorithm 2.2 counts the branches there, with bo (NULL:
   defaults) and max_branches per point.
   Between samples whose counts differ the change is bisected by counts, then located where
   the two closest branches of the larger count merge (manual section 6). samples (n_samples)
   and changes (max_changes, in order of mu from mu_from) are written; y, t are inputs only;
   mu is left at the last one set. Returns PSB_SUCCESS; PSB_BRANCH_CAPACITY (more changes than
   max_changes, or a sample with more branches than max_branches); the first failure of a
   sample after the first (the others go on from the last point found); PSB_ERR_NULL, _SIZE,
   _NONFINITE (y, t, mu_from, mu_to), _INPUT (t zero, mu_from == mu_to, a call from a trace's
   callback), _OPTIONS, _NOMEM (bytes), _CALLBACK(_FAILED), or the first sample's failure. */
PSCBRANCH_DEF psb_result psb_count_map(psb_solver *s, psb_set_mu_fn set_mu, void *mu_user,
                                       const double *y, const double *t, double mu_from,
                                       double mu_to, const psb_count_map_options *options,
                                       const psb_branch_options *bo, int max_branches,
                                       void *memory, size_t bytes, psb_count_sample *samples,
                                       psb_count_change *changes, int max_changes,
                                       psb_count_map_report *rep);

/* ---- event and kink curves in two parameters (manual section 6, "Event curves") ---------- */

/* The user's y (n+2 components) from a one-parameter point y (n+1: the user's without the mu
   component, those after it moved down one) at mu: the lift of an at_mu point. */
PSCBRANCH_DEF void psb_two_param_lift(const psb_two_param_problem *p, const double *y, double mu,
                                      double *full);

/* The curve where event k vanishes on H = 0: n+1 equations [H(y); g_k(y)] = 0 in the user's y
   (n+2 components), param_index = mu_index, as the problem `curve` (dense; its user pointer is
   this struct: do not copy it). With g_k a switching function (the argument of the max, min or
   projection whose active piece changes) it is the curve of kinks; with a user event, that
   event's curve. g_k's gradient is a central difference (2 (n+2) event calls, steps fd_step
   max(1, |y_j|)). psb_event_curve_side_folds is an event function of 2 values for psb_trace on
   `curve`: on each side of the switching surface the sign of det H_x times |det H_x|^(1/n)
   (from the Jacobian at 1 and 2 side_offsets off the surface, extrapolated to it); a
   sign change of one of them is where a fold curve of that side meets the kink curve (between
   such points the kink is a fold at a kink: the curve turns back there). Serves one thread. */
typedef struct psb_event_curve {
    psb_two_param_problem two; /* a copy of the problem */
    psb_event_fn event;        /* the events, n_events values at the user's y */
    void *event_user;
    int n_events, k;           /* k: the event whose zero set is traced, 0 <= k < n_events */
    double fd_step;            /* [6.06e-6] difference step of g_k's gradient, in (0, 1) */
    double side_offset;        /* [1e-7] side_folds' points: y -+ side_offset max(1, |y|_inf)
                                  along g_k's gradient, in (0, 1) */
    psb_problem curve;         /* n+1 equations, n+2 unknowns, parameter mu */
    struct {                   /* private: treat as opaque */
        double *g, *y_eval, *grad, *jac, *lu;
        void *ipiv;
        unsigned ready;
    } internal_;
} psb_event_curve;

/* Bytes psb_event_curve_init needs (0 when n outside 1..46000 or n_events < 1): about 2 n^2
   doubles. */
PSCBRANCH_DEF size_t psb_event_curve_memory_size(int n, int n_events);
/* Sets up c on caller memory (aligned for double; never allocates). Returns PSB_SUCCESS,
   PSB_ERR_NULL (c, p, event, memory, a callback), PSB_ERR_SIZE (n, the indices, n_events, k),
   PSB_ERR_NOMEM (bytes); *c is cleared on failure. fd_step and side_offset may be set after. */
PSCBRANCH_DEF psb_result psb_event_curve_init(psb_event_curve *c, const psb_two_param_problem *p,
                                              psb_event_fn event, int n_events, int k,
                                              void *event_user, void *memory, size_t bytes);
/* The event function described above (user: the psb_event_curve; g: 2 values); 0, or the
   callbacks' nonzero code, or 1 when fd_step, side_offset are out of range or H_x is not
   finite. */
PSCBRANCH_DEF int psb_event_curve_side_folds(const double *y, double *g, void *user);

/* ---- branch point curves in two parameters (manual section 6, "Event curves") ------------- */

/* The curve of smooth branch points (dH of rank n-1) in two parameters: n+2 equations
   [H(y) + beta b; s_1(y); s_2(y)] = 0 in n+3 unknowns (the user's y, then beta), param_index =
   mu_index, as the problem `curve` (dense; its user pointer is this struct). s solves [D b;
   C^T 0] [V; s] = [0; I_2], D = dH without its mu column, b and C (two columns) near the left
   null vector and the kernel of D at the start: s = 0 exactly where D has rank n-1. A branch
   point persists in mu only where a symmetry or structure keeps it: there beta = 0 on the
   curve; beta != 0 follows the branch points of H + beta b, the problem the perturbation
   breaks. The gradients of s are one central difference of the Jacobian along each V_i. */
typedef struct psb_branch_curve {
    psb_two_param_problem two; /* a copy of the problem (dense) */
    double fd_step;            /* [6.06e-6] difference step of s's gradient (relative), (0, 1) */
    psb_problem curve;         /* n+2 equations, n+3 unknowns (y, beta), parameter mu */
    const double *b, *c;       /* the borders: b (n), c (2 columns of n+1); zero before start */
    struct {                   /* private: treat as opaque */
        double *jac, *jac2, *mat, *rhs, *y_eval, *y_pt, *y_first, *e_mu, *b, *c;
        int *z_index;          /* y's component of each column of D */
        void *ipiv;
        unsigned ready;
    } internal_;
} psb_branch_curve;

/* Bytes psb_branch_curve_init needs (0 when n outside 1..46000): about 3 n^2 doubles. */
PSCBRANCH_DEF size_t psb_branch_curve_memory_size(int n);
/* Sets up c on caller memory (aligned for double; never allocates). Returns PSB_SUCCESS,
   PSB_ERR_NULL (c, p, memory, a callback), PSB_ERR_SIZE (n, the indices), PSB_ERR_OPTIONS (a
   banded problem), PSB_ERR_NOMEM (bytes); *c is cleared on failure. */
PSCBRANCH_DEF psb_result psb_branch_curve_init(psb_branch_curve *c, const psb_two_param_problem *p,
                                               void *memory, size_t bytes);
/* From a branch point of the problem at mu (y, t, kernel: n+1 each in at_mu's coordinates, a
   PSB_SPECIAL_BRANCH's special->y, ->t, ->kernel) to the curve: borders C = (t, kernel), b the
   left null vector of D there, then Newton on `curve` at fixed mu (curve_solver: a solver of
   c->curve), borders again at the result and Newton again. y_bp (out, n+3: the user's y, then
   beta); t_bp (out, may be NULL): the curve's unit tangent there, towards larger mu. Returns
   PSB_SUCCESS; PSB_ERR_NULL; PSB_ERR_INPUT (curve_solver not on c->curve; t, kernel parallel;
   Newton fails or moves the point more than h_init); PSB_ERR_NONFINITE; PSB_ERR_SINGULAR (the
   bordered matrix singular: no branch point of corank one there); PSB_ERR_CALLBACK(_FAILED).
   On failure y_bp, t_bp and the borders are untouched. */
PSCBRANCH_DEF psb_result psb_branch_curve_start(psb_branch_curve *c, psb_solver *curve_solver,
                                                const double *y, const double *t,
                                                const double *kernel, double mu, double *y_bp,
                                                double *t_bp);

/* ---- exploring the whole diagram (manual section 6, "Exploring the whole diagram") ------- */

/* What a node of a diagram is. */
typedef enum psb_node_kind {
    PSB_NODE_START = 0,     /* the start couple */
    PSB_NODE_NONSMOOTH = 1, /* an end point a trace could not pass: Algorithms 2.1 and 2.2 */
    PSB_NODE_BRANCH = 2,    /* a smooth branch point (psb_branch_point_switch) */
    PSB_NODE_PC1 = 3,       /* a PC1 bifurcation point a trace passed through: 2.1 and 2.2 */
    PSB_NODE_FOLD = 4,      /* a limit point on an edge (smooth or at a kink) */
    PSB_NODE_EVENT = 5,     /* a sign change of an event function on an edge */
    PSB_NODE_BOUND = 6,     /* a trace's end on a parameter bound or out of the state box */
    PSB_NODE_BUDGET = 7,    /* a trace's end at its step budget (or the point budget) */
    PSB_NODE_FAILURE = 8,   /* a trace's end at a failure (edge.result says which) */
    PSB_NODE_KINK = 9       /* an ordinary kink (two branches), a node with kink_nodes = 1 */
} psb_node_kind;

/* How an edge (a traced branch segment) ended. */
typedef enum psb_edge_end {
    PSB_EDGE_NODE = 0,    /* at a branching node (new or known): edge.to, edge.to_branch */
    PSB_EDGE_BOUND = 1,   /* on a parameter bound */
    PSB_EDGE_BOX = 2,     /* at its first point out of the state box */
    PSB_EDGE_BUDGET = 3,  /* step budget of the edge, the point budget, or a stop */
    PSB_EDGE_LOOP = 4,    /* back at its start: a closed curve (edge.to = edge.from) */
    PSB_EDGE_FAILURE = 5  /* a failure of the trace or of the branching at its end */
} psb_edge_end;

typedef struct psb_node {
    psb_node_kind kind;
    double *y;         /* the point (n+1): branching nodes, where Algorithm 2.1 or the detector
                          put it; bound, budget and failure nodes, the edge's last couple */
    double precision;  /* bound on the location error, ||.||_w (Algorithm 2.1's last h, the
                          detector's precision); 0 where the point is exact */
    double param;      /* y[param_index] */
    int edge;          /* FOLD, EVENT: the edge the point lies on; BOUND, BUDGET, FAILURE: the
                          edge ending here; -1 for the others */
    int event, direction; /* EVENT: the event component and +1 rising, -1 falling; else -1, 0 */
    int n_branches;    /* branches found here (START: the directions asked for) */
    double *ys, *ts;   /* branch k: the couple (ys + k (n+1), ts + k (n+1)), ts pointing away
                          from the node (Algorithm 2.2's or the switch's output; branch 0 is the
                          one the node was reached by) */
    int *branch_edge;  /* the edge that traced branch k (leaving or arriving); -1: not traced
                          (still queued when exploring stopped early) */
} psb_node;

typedef struct psb_edge {
    int from, from_branch; /* the node and branch it leaves by */
    int to, to_branch;     /* the node it ends at (-1 when capacity ran out) and, at a branching
                              node, the branch it arrived by (-1 otherwise) */
    psb_edge_end end;
    psb_result result;     /* the trace's (or the branching's) result code */
    long n_points;         /* accepted points (the ones given to the point callback) */
    double length;         /* arc length, ||.||_w, node to node */
    long first_point;      /* its stored points (psb_diagram_set_points): the y of accepted */
    long n_stored;         /* point k is d->points + (first_point + k) (n+1), k < n_stored */
} psb_edge;

/* Called for every accepted point of every edge (the edge's index, the trace's point); return
   nonzero to stop exploring (psb_explore returns PSB_STOPPED, the diagram is kept). */
typedef int (*psb_explore_point_fn)(int edge, const psb_point *pt, void *user);

typedef struct psb_explore_options {
    psb_trace_options trace; /* every trace's options: param_min, param_max, max_steps, and the
                                detectors' (detect, as in psb_trace [0: none: nodes only where
                                traces end, and at kinks with branch_at_kinks; eo NULL: folds,
                                branch points, and PC1 points with the dense and banded
                                backends], locate_tol, events); the explorer sets on_point,
                                point_user, detect_loop (1), locate_kinks (branch_at_kinks) and
                                stop_at (0) itself */
    psb_branch_options branch; /* Algorithms 2.1, 2.2 and psb_branch_point_switch at every
                                  branching point (zero fields: defaults) */
    const double *box_min, *box_max; /* optional (n+1 each): a trace ends at its first point
                                        with some y_i outside [box_min_i, box_max_i] [NULL] */
    double state_max;  /* > 0: a trace ends at its first point whose state (y without the
                          parameter) has a weighted norm above it [0: none] */
    int one_direction; /* 1: from the start couple along t only; 0: along t and -t [0] (from
                          a start on a parameter bound, the direction leaving it is left out) */
    int max_traces;    /* edges traced in all [0: no limit but the diagram's max_edges] */
    long max_points;   /* accepted points in all [0: no limit] */
    int branch_at_kinks; /* 1: locate every kink a trace passes and run Algorithms 2.1 and 2.2
                            there; a kink with two branches is ordinary and the trace goes on
                            (diagram.n_kinks_plain). Finds bifurcations the detectors' tests
                            cannot see, at the price of Algorithm 2.2 at each kink [0] */
    int kink_spans;    /* branch_at_kinks: Algorithm 2.2 first looks at a kink with this many
                          spans, and sweeps in full (branch.n_span) unless that found two
                          balanced branches among two pieces' tangents [0: in full at once] */
    int kink_nodes;    /* 1: an ordinary kink is a node (PSB_NODE_KINK, its two branches) where
                          one edge ends and the next begins, so the graph keeps it (the corner
                          of two rays, say); implies branch_at_kinks [0: the edge goes on] */
    double node_tol;   /* two branching points within node_tol + 4 (their precisions) of each
                          other, ||.||_w, are one node [16 branch.h, resolved; with finite
                          differences and branch.h left at 0: 16 times h at the node] */
    psb_explore_point_fn on_point; /* optional */
    void *point_user;
    int drafts;        /* with branch.workers: the first traces of the queue's next edges,
                          as many as this, run at once on the workers, trace.event too (called
                          concurrently); the diagram is the same (manual, section 6, "Workers")
                          [8; -1: none, edges in turn]; <= PSB_MAX_WORKERS */
    long draft_points; /* the points a draft keeps (a longer first trace is traced again in
                          turn) [128]; <= 10^7. Memory: psb_explore_workers_memory_size */
} psb_explore_options;

/* A caller's allocator (psb_diagram_set_growth): alloc returns a block aligned for double, or
   NULL; release frees one. */
typedef struct psb_allocator {
    void *(*alloc)(size_t bytes, void *user);
    void (*release)(void *memory, void *user);
    void *user;
} psb_allocator;

typedef struct psb_diagram {
    int n;                  /* N of the problem */
    int param_index;        /* the problem's (set by psb_explore) */
    int max_nodes, max_edges, max_branches; /* capacities (max_branches per node) */
    int n_nodes, n_edges;
    psb_node *nodes;
    psb_edge *edges;
    long n_points;          /* accepted points of all edges */
    int n_branchings;       /* calls of Algorithm 2.2 or of the branch point switch */
    int n_kinks_plain;      /* kinks found ordinary (two branches; branch_at_kinks, or where the
                               tangent switch failed): the edge went on */
    int n_queued;           /* branches left untraced (budget, capacity or a stop) */
    int n_failed;           /* edges that ended in a failure */
    int n_odd;              /* branching nodes with an odd number of branches, or whose
                               outward signs do not add up to 0: where the pieces are
                               transversal they do, so such a node most likely misses
                               branches (manual section 6, "An odd count", PC1) */
    int truncated;          /* 1: a capacity ran out (nodes, edges, branches at a node, stored
                               points) */
    int n_drafts, n_drafts_used; /* edges' first traces drafted on workers, and replayed into
                                    the diagram (the rest were not needed or traced again) */
    psb_result result;      /* what the last psb_explore on d returned (PSB_SUCCESS: complete;
                               PSB_ERR_INPUT before the first) */
    double *points;         /* the edges' stored points, n+1 each (psb_diagram_set_points) */
    long max_points, n_stored_points;
    /* private */
    double *work_;
    double *index_key_; /* the explorer's node index (psb__index_key) */
    int *index_node_;
    void *owned_;
    int store_points_, grows_;
    psb_allocator grow_;
    size_t grow_max_, grown_bytes_;
    void *grown_, *grown_points_; /* blocks the diagram grew into (the first one stays) */
} psb_diagram;

/* Bytes psb_diagram_init_with_memory needs for n equations and the capacities (0 when a value
   is out of range: n < 1, a capacity < 1, or the size overflows). Memory is about
   max_nodes (2 max_branches + 1) (n+1) doubles. */
PSCBRANCH_DEF size_t psb_diagram_memory_size(int n, int max_nodes, int max_edges, int max_branches);
/* Sets up an empty diagram on caller memory (aligned for double); never allocates.
   Returns PSB_SUCCESS, PSB_ERR_NULL, PSB_ERR_SIZE, PSB_ERR_NOMEM (block too small). */
PSCBRANCH_DEF psb_result psb_diagram_init_with_memory(psb_diagram *d, int n, int max_nodes,
                                                      int max_edges, int max_branches,
                                                      void *memory, size_t bytes);
/* Same, allocating with PSCBRANCH_MALLOC; release with psb_diagram_free. */
PSCBRANCH_DEF psb_result psb_diagram_init(psb_diagram *d, int n, int max_nodes, int max_edges,
                                          int max_branches);
/* Frees what psb_diagram_init allocated and what d grew into (nothing of the caller's own
   memory). d may be NULL. */
PSCBRANCH_DEF void psb_diagram_free(psb_diagram *d);
/* Keeps every edge's accepted points (their y) in memory (max_points couples of n+1 doubles;
   NULL with max_points 0: none yet, for a diagram that grows): psb_edge.first_point, n_stored,
   the JSON's "path" and psb_diagram_write_points_csv. Points that do not fit are dropped and
   set d->truncated. Returns PSB_SUCCESS, PSB_ERR_NULL, PSB_ERR_SIZE (max_points < 0, or > 0
   with no memory). */
PSCBRANCH_DEF psb_result psb_diagram_set_points(psb_diagram *d, double *memory, long max_points);
/* Lets psb_explore grow d, instead of stopping at a capacity: where nodes, edges, branches at
   a node or stored points run out, it doubles that capacity in a new block from a (NULL:
   PSCBRANCH_MALLOC and PSCBRANCH_FREE) and releases the block it grew from (never the first:
   d's scratch stays there; psb_diagram_free releases the rest). max_bytes bounds a block (0:
   no bound); where a block would pass it or a is out of memory, the capacity stops exploring
   as without growth. After the call d->max_nodes, ... are the capacities reached, which
   psb_diagram_memory_size turns into the size of a block that needs no growth. Returns
   PSB_SUCCESS, PSB_ERR_NULL (d not set up, or a without alloc or release), PSB_ERR_INPUT (d
   has grown already: its blocks are the first allocator's until psb_diagram_free). */
PSCBRANCH_DEF psb_result psb_diagram_set_growth(psb_diagram *d, const psb_allocator *a, size_t max_bytes);
/* Names of the kinds ("nonsmooth", "bound", ...), as the JSON and CSV forms write them. */
PSCBRANCH_DEF const char *psb_node_kind_string(psb_node_kind kind);
PSCBRANCH_DEF const char *psb_edge_end_string(psb_edge_end end);

/* The whole diagram reachable from the couple (y, t) (in, n+1 each; t need not be unit): a
   queue of branches, first the start's directions; each is traced (psb_trace with the options
   and detectors of eo->trace) until a bound, the box, its budget, a loop, a failure or a
   branching point. There Algorithms 2.1 and 2.2 (nonsmooth and PC1 points) or
   psb_branch_point_switch (smooth branch points) give the branches, whose new ones join the
   queue; a branching point within node_tol of a known node, or a trace's chord passing that
   close to one, arrives at that node, and the branch arrived by is marked traced, so nothing
   is traced twice (a trace passing a known node adds the way on as a branch of it when the
   branch is new, taken from its first point past the node). A branch whose couple from
   Algorithm 2.2 lies beyond a parameter bound (its node is within a branching radius of the
   bound) ends on the bound: an edge of no points to a bound node, Newton's solution at the
   bound from the chord; so does an edge whose way on past an ordinary kink lies beyond one.
   A fold an edge meets within node_tol of the branching node it leaves or ends at is that
   node (difference quotients mix the pieces there and can flip the tangent's parameter
   component) and gets no node of its own. d is reset first and holds the graph (every node's
   and edge's index is the order it was made in). eo may be NULL. Same inputs and seed, same
   diagram, bit for bit, grown or not. No allocation but d's growth (psb_diagram_set_growth);
   s's scratch is used (not from a point callback). Returns PSB_SUCCESS (the queue emptied),
   PSB_BRANCH_CAPACITY (nodes, edges, branches at a node or stored points ran out: what fits
   is kept, d->truncated), PSB_STEP_BUDGET (max_traces or max_points reached first),
   PSB_STOPPED (on_point asked), or a failure: PSB_ERR_NULL, PSB_ERR_SIZE (d->n differs from
   the problem's), PSB_ERR_OPTIONS (eo->branch as the branching calls; NaN bounds or
   node_tol, negative budgets, box_min > box_max, PSB_DETECT_PC1 with a user backend, drafts
   or draft_points out of range), PSB_ERR_NOMEM (with drafts, eo->branch.workers' memory below
   psb_explore_workers_memory_size; PSB_ERR_SIZE where that overflows), the workers' codes
   (psb_workers_memory_size), PSB_ERR_INPUT (zero t, t not within c_min of the curve's tangent at y, start outside the
   bounds or box), PSB_ERR_NONFINITE, PSB_ERR_CALLBACK (a callback returned < 0; the diagram
   so far is kept). A trace or a branching that fails otherwise ends its edge
   (PSB_EDGE_FAILURE, d->n_failed) and exploring goes on; once the queue is done (or a budget
   or capacity ran out) the call returns the first failed edge's code (edge.result:
   PSB_ERR_CALLBACK_FAILED, _NONFINITE, _SINGULAR, ...), not PSB_SUCCESS, since what lies
   beyond a failed edge is missing. On every return but PSB_ERR_NULL, _SIZE, _OPTIONS, _INPUT,
   _NONFINITE, _NOMEM (checked before d is reset) d holds the graph made so far; y, t and eo are
   inputs only. */
PSCBRANCH_DEF psb_result psb_explore(psb_solver *s, const double *y, const double *t,
                                     const psb_explore_options *eo, psb_diagram *d);

#ifdef PSCBRANCH_STDIO
#include <stdio.h>
/* The diagram as JSON, and as two CSV tables, nodes and edges (either FILE may be NULL). JSON
   keys: format, version, n, param_index, complete (psb_explore returned PSB_SUCCESS),
   failed_edges, untraced_branches, odd_nodes, nodes (id, kind, param, precision, edge, event,
   direction, y, branches: edge, y, t), edges (id, from, from_branch, to, to_branch, end, result,
   points, length, path: the stored points); the CSV tables are the same. All numbers in the C
   locale's notation whatever setlocale. Return PSB_SUCCESS, PSB_ERR_NULL, or PSB_ERR_INPUT when
   writing failed. Defined where PSCBRANCH_STDIO is defined with the implementation. */
PSCBRANCH_DEF psb_result psb_diagram_write_json(const psb_diagram *d, FILE *f);
PSCBRANCH_DEF psb_result psb_diagram_write_csv(const psb_diagram *d, FILE *nodes, FILE *edges);
/* The edges' stored points (psb_diagram_set_points) as CSV: edge, index, y0 ... yn, one row a
   point in the order traced; an edge runs from its from node's y through them to its to
   node's y. Returns as psb_diagram_write_json. */
PSCBRANCH_DEF psb_result psb_diagram_write_points_csv(const psb_diagram *d, FILE *f);
#endif

/* ---- contact helpers: see the manual section "Contact helpers" ----------------------------- */

/* Pass as piece_request for automatic piece selection (documented default on kinks). */
#define PSB_PIECE_DEFAULT (-1)

/* Piece ids. Value and Jacobian of a projection are always those of the returned piece. */
enum { PSB_HALF_IN = 0, PSB_HALF_OUT = 1 };                       /* half-lines: x / 0     */
enum { PSB_IVL_IN = 0, PSB_IVL_LOWER = 1, PSB_IVL_UPPER = 2 };    /* interval: x / a / b   */
enum { PSB_DISK_IN = 0, PSB_DISK_BOUNDARY = 1, PSB_DISK_ZERO = 2 }; /* disk: x / s x/|x| / 0 */
enum { PSB_CONE_IN = 0, PSB_CONE_POLAR = 1, PSB_CONE_BOUNDARY = 2 }; /* cone: x / 0 / ray  */

/* Composite piece ids of the nodal residuals (pn: half-line piece, pi/pd: interval/disk piece,
   pr: piece of (r_N)_+ in the Jean-Moreau radius). */
#define PSB_AC2D_PIECE(pn, pi) ((pn) + 2 * (pi))              /* 0..5  */
#define PSB_FC3D_AC_PIECE(pn, pd) ((pn) + 2 * (pd))           /* 0..5  */
#define PSB_FC3D_JM_PIECE(pn, pr, pd) ((pn) + 2 * (pr) + 4 * (pd)) /* 0..11 */

/* Nodal contact state of the 2D Alart-Curnier law (slip named by the sign of u_t). */
typedef enum psb_contact_state {
    PSB_CONTACT_SEPARATED = 0, /* s = (lam_n - r(u_n - g))_- = 0: no contact force        */
    PSB_CONTACT_STICK = 1,     /* |lam_t - r u_t| <= F|s|                                   */
    PSB_CONTACT_SLIP_POS = 2,  /* lam_t - r u_t < F s: slides towards +tau, lam_t = F s      */
    PSB_CONTACT_SLIP_NEG = 3   /* lam_t - r u_t > -F s: slides towards -tau, lam_t = -F s    */
} psb_contact_state;

/* Projection onto ]-inf, 0] (the papers' (x)_- = min(x, 0)).
   in: x; piece_request (PSB_PIECE_DEFAULT or PSB_HALF_IN/OUT).
   out: *value = P(x); *deriv = dP/dx (may be NULL); *piece (may be NULL).
   Default: x <= 0 -> IN (value x, deriv 1), x > 0 -> OUT (0, 0).
   Returns PSB_ERR_NULL (value NULL), PSB_ERR_NONFINITE, PSB_ERR_SIZE (bad piece_request). */
PSCBRANCH_DEF psb_result psb_proj_nonpos(double x, int piece_request, double *value,
                                         double *deriv, int *piece);

/* Projection onto [0, +inf[ (max(x, 0)). Same arguments and results as psb_proj_nonpos.
   Default: x >= 0 -> IN, x < 0 -> OUT. */
PSCBRANCH_DEF psb_result psb_proj_nonneg(double x, int piece_request, double *value,
                                         double *deriv, int *piece);

/* Pieces of a half-line projection whose closure contains x within tol >= 0.
   in: x, tol; nonpos != 0 selects ]-inf,0], else [0,inf[.  out: *mask, bit k set = piece k.
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (tol < 0). */
PSCBRANCH_DEF psb_result psb_proj_half_active(double x, int nonpos, double tol, unsigned *mask);

/* Projection onto the interval [a, b], a <= b.
   in: x, a, b; piece_request (PSB_PIECE_DEFAULT or PSB_IVL_*).
   out: *value; d[3] = (dP/dx, dP/da, dP/db) (may be NULL); *piece (may be NULL).
   Default: x < a -> LOWER, x > b -> UPPER, a <= x <= b -> IN, except a == b -> LOWER.
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (a > b), PSB_ERR_SIZE. */
PSCBRANCH_DEF psb_result psb_proj_interval(double x, double a, double b, int piece_request,
                                           double *value, double d[3], int *piece);

/* Active interval pieces at (x, a, b) within tol (closures in (x, a, b)-space). out: *mask. */
PSCBRANCH_DEF psb_result psb_proj_interval_active(double x, double a, double b, double tol,
                                                  unsigned *mask);

/* Projection onto the disk {|y| <= s} of R^2 (s <= 0: the set {0}).
   in: x[2], s; piece_request (PSB_PIECE_DEFAULT or PSB_DISK_*).
   out: p[2]; jx[4] = dP/dx, 2x2 column-major (may be NULL); js[2] = dP/ds (may be NULL);
   *piece (may be NULL). Default: s <= 0 -> ZERO, |x| <= s -> IN, else BOUNDARY.
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_SIZE. */
PSCBRANCH_DEF psb_result psb_proj_disk(const double x[2], double s, int piece_request, double p[2],
                                       double jx[4], double js[2], int *piece);

/* Active disk pieces at (x, s) within tol. out: *mask. */
PSCBRANCH_DEF psb_result psb_proj_disk_active(const double x[2], double s, double tol,
                                              unsigned *mask);

/* Projection onto the Coulomb cone K = {|x_T| <= mu x_N} of R^3, x = (x_N, x_T1, x_T2), mu >= 0
   (mu = 0: the half-line x_T = 0, x_N >= 0).
   in: x[3], mu; piece_request (PSB_PIECE_DEFAULT or PSB_CONE_*).
   out: p[3]; j[9] = dP/dx, 3x3 column-major (may be NULL); *piece (may be NULL).
   Default: mu > 0 and |x_T| <= mu x_N -> IN; else mu|x_T| <= -x_N -> POLAR; else BOUNDARY.
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (mu < 0), PSB_ERR_SIZE. */
PSCBRANCH_DEF psb_result psb_proj_cone(const double x[3], double mu, int piece_request,
                                       double p[3], double j[9], int *piece);

/* Active cone pieces at x within tol (IN is never reported when mu = 0). out: *mask. */
PSCBRANCH_DEF psb_result psb_proj_cone_active(const double x[3], double mu, double tol,
                                              unsigned *mask);

/* 2D Alart-Curnier nodal residual, eq. (2) of Haslinger et al. (multipliers <= 0, nu pointing
   into the foundation):  s = (lam_n - r (u_n - gap))_-,
   res[0] = -(1/r) (lam_n - s),  res[1] = -(1/r) (lam_t - P_[F s, -F s](lam_t - r u_t)).
   in: u_n, u_t, lam_n, lam_t; r > 0; friction F >= 0; gap (0: none); piece_request
   (PSB_PIECE_DEFAULT or PSB_AC2D_PIECE(pn, pi)).
   out: res[2]; jac[8] = 2x4 column-major d res / d(u_n, u_t, lam_n, lam_t) (may be NULL);
   *piece = PSB_AC2D_PIECE(pn, pi) used (may be NULL).
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (r <= 0, F < 0), PSB_ERR_SIZE. */
PSCBRANCH_DEF psb_result psb_ac2d_node(double u_n, double u_t, double lam_n, double lam_t,
                                       double r, double friction, double gap, int piece_request,
                                       double res[2], double jac[8], int *piece);

/* Composite pieces PSB_AC2D_PIECE(pn, pi) active at the node within tol. out: *mask (bit id). */
PSCBRANCH_DEF psb_result psb_ac2d_active(double u_n, double u_t, double lam_n, double lam_t,
                                         double r, double friction, double gap, double tol,
                                         unsigned *mask);

/* Contact state of the node (see psb_contact_state). out: *state.
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (r <= 0, F < 0). */
PSCBRANCH_DEF psb_result psb_ac2d_state(double u_n, double u_t, double lam_n, double lam_t,
                                        double r, double friction, double gap,
                                        psb_contact_state *state);

/* 3D Alart-Curnier residual of one contact, eq. (11) of Acary et al. (reactions in K, u = W r + q):
   f_N = r_N - (r_N - rho_n u_N)_+,  f_T = r_T - P_D(mu (r_N - rho_n u_N)_+)(r_T - rho_t u_T).
   in: r[3], u[3] (N first); mu >= 0; rho_n, rho_t > 0; piece_request (PSB_PIECE_DEFAULT or
   PSB_FC3D_AC_PIECE(pn, pd)).  out: f[3]; jr[9] = df/dr, ju[9] = df/du, 3x3 column-major
   (may be NULL); *piece (may be NULL).
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (mu < 0, rho <= 0), PSB_ERR_SIZE. */
PSCBRANCH_DEF psb_result psb_fc3d_ac(const double r[3], const double u[3], double mu, double rho_n,
                                     double rho_t, int piece_request, double f[3], double jr[9],
                                     double ju[9], int *piece);

/* 3D Jean-Moreau residual, eq. (12): as psb_fc3d_ac with disk radius mu (r_N)_+.
   piece_request / *piece: PSB_FC3D_JM_PIECE(pn, pr, pd). Same results. */
PSCBRANCH_DEF psb_result psb_fc3d_jm(const double r[3], const double u[3], double mu, double rho_n,
                                     double rho_t, int piece_request, double f[3], double jr[9],
                                     double ju[9], int *piece);

/* De Saxce's modified velocity uhat = u + mu |u_T| e_N.
   out: uhat[3]; j[9] = d uhat / du column-major (may be NULL; at u_T = 0 uses d|u_T|/du_T = e_1).
   Returns PSB_ERR_NULL, PSB_ERR_NONFINITE, PSB_ERR_INPUT (mu < 0). */
PSCBRANCH_DEF psb_result psb_fc3d_desaxce(const double u[3], double mu, double uhat[3], double j[9]);

/* Natural map with De Saxce's velocity, eq. (13): f = r - P_K(r - rho (u + mu |u_T| e_N)).
   piece_request / *piece: cone piece (PSB_CONE_*). Other arguments as psb_fc3d_ac (rho > 0). */
PSCBRANCH_DEF psb_result psb_fc3d_nat(const double r[3], const double u[3], double mu, double rho,
                                      int piece_request, double f[3], double jr[9], double ju[9],
                                      int *piece);

/* Error of eq. (15): |F_nat(r)| / qnorm with rho = 1, over nc contacts of dimension dim (2 or 3;
   in 2D each contact is (N, T)). in: r[dim*nc], u[dim*nc] = W r + q, mu[nc], qnorm (<= 0: the
   absolute |F_nat(r)| is returned). out: *err.
   Returns PSB_ERR_NULL, PSB_ERR_SIZE (dim), PSB_ERR_NONFINITE, PSB_ERR_INPUT (mu < 0). */
PSCBRANCH_DEF psb_result psb_fc_nat_error(int dim, size_t nc, const double *r, const double *u,
                                          const double *mu, double qnorm, double *err);

/* Sign-convention map between Haslinger et al. (multipliers lam <= 0, displacement u with nu
   into the foundation, gap g: u_n <= g) and Acary et al. (reactions r in K, r_N >= 0, velocity
   or gap u with u_N >= 0 separating):  r = -lam,  u_N = g - u_n,  u_T = -u_t.
   It is its own inverse (apply it to (r, u) with the same g to get (lam, u) back).
   in: dim (2 or 3), force_in[dim], disp_in[dim], gap. out: force_out[dim], disp_out[dim] (may
   alias the inputs). Returns PSB_ERR_NULL, PSB_ERR_SIZE, PSB_ERR_NONFINITE. */
PSCBRANCH_DEF psb_result psb_contact_convert(int dim, const double *force_in,
                                             const double *disp_in, double gap,
                                             double *force_out, double *disp_out);

#ifdef __cplusplus
}
#endif
#endif /* PSCBRANCH_H */

#ifdef PSCBRANCH_IMPLEMENTATION
#ifndef PSCBRANCH_IMPLEMENTATION_DONE
#define PSCBRANCH_IMPLEMENTATION_DONE

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#if defined(__SSE2__) && !defined(PSCBRANCH_NO_SIMD) && !defined(PSCBRANCH_USE_DGBTRF)
#include <emmintrin.h>
#define PSB__SSE2 1
#endif
#define PSB__GB_NB 4 /* panel width of the banded LU (psb__gbtrf) */

#if defined(PSCBRANCH_MALLOC) && defined(PSCBRANCH_FREE)
#elif !defined(PSCBRANCH_MALLOC) && !defined(PSCBRANCH_FREE)
#include <stdlib.h>
#define PSCBRANCH_MALLOC(size) malloc(size)
#define PSCBRANCH_FREE(ptr) free(ptr)
#else
#error "define both PSCBRANCH_MALLOC and PSCBRANCH_FREE, or neither"
#endif

/* ==== Foundations ===============================================================================
   LAPACK's symbols, the scratch vectors, options and their checks, the solver's memory,
   weighted vector helpers, failure bookkeeping. Nothing here knows an algorithm. */

/* ---- LAPACK through its Fortran symbols ---------------------------------------------------
   PSCBRANCH_LAPACK_INT: the Fortran INTEGER (int; long for ILP64 builds).
   PSCBRANCH_FORTRAN(name): the symbol of a routine (name##_ for gfortran and most builds).
   Character arguments carry a hidden length (gfortran ABI); define PSCBRANCH_NO_FORTRAN_STRLEN
   for a LAPACK built without it. PSCBRANCH_STRLEN_ONE passes it for the caller's own calls. */
#ifndef PSCBRANCH_LAPACK_INT
#define PSCBRANCH_LAPACK_INT int
#endif
#ifndef PSCBRANCH_FORTRAN
#define PSCBRANCH_FORTRAN(name) name##_
#endif
#ifdef PSCBRANCH_NO_FORTRAN_STRLEN
#define PSB__STRLEN_ARG
#define PSCBRANCH_STRLEN_ONE
#else
#define PSB__STRLEN_ARG , size_t
#define PSCBRANCH_STRLEN_ONE , (size_t)1
#endif
#define PSB__STRLEN_ONE PSCBRANCH_STRLEN_ONE

typedef PSCBRANCH_LAPACK_INT psb__lint;

#ifdef __cplusplus
extern "C" {
#endif
extern void PSCBRANCH_FORTRAN(dgetrf)(const psb__lint *m, const psb__lint *n, double *a,
                                      const psb__lint *lda, psb__lint *ipiv, psb__lint *info);
extern void PSCBRANCH_FORTRAN(dgetrs)(const char *trans, const psb__lint *n,
                                      const psb__lint *nrhs, const double *a,
                                      const psb__lint *lda, const psb__lint *ipiv, double *b,
                                      const psb__lint *ldb, psb__lint *info PSB__STRLEN_ARG);
extern void PSCBRANCH_FORTRAN(dlacn2)(const psb__lint *n, double *v, double *x, psb__lint *isgn,
                                      double *est, psb__lint *kase, psb__lint *isave);
extern void PSCBRANCH_FORTRAN(dgbtrf)(const psb__lint *m, const psb__lint *n, const psb__lint *kl,
                                      const psb__lint *ku, double *ab, const psb__lint *ldab,
                                      psb__lint *ipiv, psb__lint *info);
/* not called by the library; declared for banded solves of the implementation's file */
extern void PSCBRANCH_FORTRAN(dgbtrs)(const char *trans, const psb__lint *n, const psb__lint *kl,
                                      const psb__lint *ku, const psb__lint *nrhs, const double *ab,
                                      const psb__lint *ldab, const psb__lint *ipiv, double *b,
                                      const psb__lint *ldb, psb__lint *info PSB__STRLEN_ARG);
extern void PSCBRANCH_FORTRAN(dgeqr2)(const psb__lint *m, const psb__lint *n, double *a,
                                      const psb__lint *lda, double *tau, double *work,
                                      psb__lint *info);
extern void PSCBRANCH_FORTRAN(dorm2r)(const char *side, const char *trans, const psb__lint *m,
                                      const psb__lint *n, const psb__lint *k, const double *a,
                                      const psb__lint *lda, const double *tau, double *c,
                                      const psb__lint *ldc, double *work,
                                      psb__lint *info PSB__STRLEN_ARG PSB__STRLEN_ARG);
#ifdef __cplusplus
}
#endif

/* Directions a pass of the tangent switch remembers (psb__switch_fresh) */
#define PSB__SW_RING 8

/* Scratch vectors of n+1 components, carved from one block at init. */
enum {
    PSB__V_Y,     /* corrector / Newton iterate */
    PSB__V_T,     /* corrector tangent iterate */
    PSB__V_FD,    /* finite-difference point */
    PSB__V_REF,   /* reference direction copy */
    PSB__V_STEP_Y, PSB__V_STEP_T,   /* psb_step trial couple */
    PSB__V_SW_Y, PSB__V_SW_T, PSB__V_SW_D, PSB__V_SW_P, PSB__V_SW_A, PSB__V_SW_B, PSB__V_SW_C, /* switch */
    PSB__V_SW_L, PSB__V_SW_L_END = PSB__V_SW_L + PSB__SW_RING - 1, /* its last directions tried */
    PSB__V_IO_Y, PSB__V_IO_T,       /* psb_step / psb_switch_tangent: the caller's couple, copied */
    PSB__V_TR_Y, PSB__V_TR_T, PSB__V_TR_Y0, PSB__V_TR_T0, PSB__V_TR_B, PSB__V_TR_S, PSB__V_TR_K, /* trace */
    PSB__V_TR_KY, PSB__V_TR_KT, /* trace: a step's first kink couple, kept across its callbacks */
    PSB__V_K_YA, PSB__V_K_TA, PSB__V_K_Y, PSB__V_K_T, /* kink location */
    PSB__V_BR_Y0, PSB__V_BR_T0, PSB__V_BR_T1, PSB__V_BR_T2, PSB__V_BR_V, PSB__V_BR_TT,
    PSB__V_BR_TP, PSB__V_BR_Y, PSB__V_BR_T, PSB__V_BR_P, PSB__V_BR_Q, PSB__V_BR_K, PSB__V_BR_S, /* branching */
    PSB__V_BP_K0, PSB__V_BP_K1, PSB__V_BP_K2, PSB__V_BP_K3, /* kernel at a smooth branch point */
    PSB__V_SP_Y, PSB__V_SP_T, PSB__V_SP_K, PSB__V_SP_YA, PSB__V_SP_TA, PSB__V_SP_YB, PSB__V_SP_TB,
    PSB__V_SP_YE, PSB__V_SP_TE, PSB__V_SP_B1, PSB__V_SP_B2, PSB__V_SP_C1, PSB__V_SP_C2, /* special points */
    PSB__V_EV_Y, PSB__V_EV_T, PSB__V_EV_N, /* psb_evolve_step: path couple, Newton's solution */
    PSB__V_BR_H0, PSB__V_BR_PE, /* Algorithm 2.2's trials: H(y0); the point h from y0 (conic test) */
    PSB__V_BR_MT, /* a trial's memo tangent (psb__path_memo_cut) */
    PSB__NVEC
};
/* Entries of each of psb_find_branches' stores, the tangents tried (memo), the directions
   whose trial is known (known) and the Jacobian memo (jmemo_t, analytic dH only): a few hundred
   entries serve a sweep; the three are held to 12 MB together (more only at the floor of 32
   entries, N > 16000) */
static int psb__memo_capacity(int n)
{
    int cap = (int)((1L << 19) / ((long)n + 1));
    return cap < 32 ? 32 : cap > 256 ? 256 : cap;
}
#define PSB__VEC(s, k) ((s)->internal_.vec + (size_t)(k) * (size_t)(s)->internal_.np1)
/* Corrector tangents a trial of Algorithm 2.2 records (its first iterations'; see
   psb__try_tangent) */
#define PSB__PATH_MAX 8

/* Why the last recoverable failure happened. Geometry (no convergence, a rejected or cut trial,
   a bordered matrix singular only because the curve turned across its bordering row: TURN)
   says something about the curve; a fault (a callback returned > 0, NaN or Inf, a Jacobian of
   rank < N or a failing solver.factor: SINGULAR) says nothing about it, and an algorithm whose
   outcome rests on one returns its code (psb__note_fault, psb__faults_code). A difference
   Jacobian of rank < N (FD_RANK) is geometry too: quotients across a piece boundary mix the
   pieces, which happens within a difference step of every kink; only when nothing at all
   succeeded is it a fault. */
enum { PSB__FAIL_NONE, PSB__FAIL_CONVERGE, PSB__FAIL_NONFINITE, PSB__FAIL_CALLBACK,
       PSB__FAIL_SINGULAR, PSB__FAIL_COSINE, PSB__FAIL_KNOWN, PSB__FAIL_TURN, PSB__FAIL_FD_RANK };
#define PSB__READY 0x70736231u /* psb_solver.internal_.ready of an initialised solver */

PSCBRANCH_DEF const char *psb_result_string(psb_result code)
{
    switch (code) {
    case PSB_SUCCESS: return "PSB_SUCCESS: success";
    case PSB_PARAM_BOUND: return "PSB_PARAM_BOUND: reached a parameter bound";
    case PSB_STEP_BUDGET: return "PSB_STEP_BUDGET: step budget used up";
    case PSB_NONSMOOTH_END: return "PSB_NONSMOOTH_END: end point that the tangent switch cannot pass";
    case PSB_STOPPED: return "PSB_STOPPED: stopped by the point callback";
    case PSB_LOOP_CLOSED: return "PSB_LOOP_CLOSED: the curve returned to its start";
    case PSB_BRANCH_CAPACITY: return "PSB_BRANCH_CAPACITY: more branches, nodes or edges than room given";
    case PSB_ERR_NULL: return "PSB_ERR_NULL: a required pointer is NULL, or the solver is not initialised";
    case PSB_ERR_SIZE: return "PSB_ERR_SIZE: a size or index is out of range";
    case PSB_ERR_OPTIONS: return "PSB_ERR_OPTIONS: invalid or inconsistent options";
    case PSB_ERR_NOMEM: return "PSB_ERR_NOMEM: out of memory or memory block too small";
    case PSB_ERR_CALLBACK: return "PSB_ERR_CALLBACK: a callback asked to stop";
    case PSB_ERR_CALLBACK_FAILED: return "PSB_ERR_CALLBACK_FAILED: a callback failed";
    case PSB_ERR_NONFINITE: return "PSB_ERR_NONFINITE: NaN or Inf";
    case PSB_ERR_SINGULAR: return "PSB_ERR_SINGULAR: singular matrix";
    case PSB_ERR_LAPACK: return "PSB_ERR_LAPACK: LAPACK rejected an argument";
    case PSB_ERR_NO_CONVERGENCE: return "PSB_ERR_NO_CONVERGENCE: iterations did not converge";
    case PSB_ERR_STEP_TOO_SMALL: return "PSB_ERR_STEP_TOO_SMALL: step size fell below h_min";
    case PSB_ERR_INPUT: return "PSB_ERR_INPUT: invalid numerical input";
    }
    return "unknown pscbranch result code";
}

PSCBRANCH_DEF void psb_problem_init(psb_problem *p, int n, psb_residual_fn residual,
                                    psb_jacobian_fn jacobian, void *user)
{
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->n = n;
    p->residual = residual;
    p->jacobian = jacobian;
    p->user = user;
    p->param_index = n;
}

/* Whether the library forms dH by finite differences (no analytic Jacobian callback). */
static int psb__fd_jacobian(const psb_problem *p)
{
    switch (p->linear) {
    case PSB_LINEAR_BANDED: return p->band_jacobian == NULL;
    case PSB_LINEAR_USER: return 0;
    default: return p->jacobian == NULL;
    }
}

PSCBRANCH_DEF psb_options psb_options_resolve(const psb_options *opt)
{
    psb_options o;
    if (opt) o = *opt;
    else memset(&o, 0, sizeof o);
    if (o.kappa == 0) o.kappa = 1.0;
    if (o.h_init == 0) o.h_init = 1e-2;
    if (o.h_min == 0) o.h_min = 1e-6;
    if (o.h_max == 0) o.h_max = 1e-1;
    if (o.h_inc == 0) o.h_inc = 1.3;
    if (o.h_dec == 0) o.h_dec = 0.5;
    if (o.max_iter == 0) o.max_iter = 10;
    if (o.iter_threshold == 0) o.iter_threshold = 4;
    if (o.tol_residual == 0) o.tol_residual = 1e-10;
    if (o.tol_correction == 0) o.tol_correction = 1e-10;
    if (o.c_min == 0) o.c_min = 0.9;
    if (o.switch_delta_min == 0) o.switch_delta_min = o.h_min;
    if (o.switch_delta_max == 0) o.switch_delta_max = o.h_init;
    if (o.switch_n_dir == 0) o.switch_n_dir = 20;
    if (o.c_diff == 0) o.c_diff = 0.99999;
    return o;
}

/* Fields that depend on the problem (h, finite differences: follows the point, and with it
   h_min) and on the continuation's options (h_min, h_init). Fields that mean "adaptive"
   resolve to the values the adaptation uses, with a field saying it adapts (n_span and
   n_span_max, h = 0 and h_fd_steps), so that a resolved set given back means the same. */
PSCBRANCH_DEF psb_branch_options psb_branch_options_resolve(const psb_branch_options *bo,
                                                            const psb_solver *s)
{
    psb_branch_options b;
    int ready = s && s->internal_.ready == PSB__READY, fd = ready && psb__fd_jacobian(&s->prob);
    double h_min = ready ? s->opt.h_min : 1e-6, h_init = ready ? s->opt.h_init : 1e-2;
    if (bo) b = *bo;
    else memset(&b, 0, sizeof b);
    if (b.expert.as_printed == 1) { /* the switches whose zero departs from the printed algorithm */
        b.expert.paper_sweep = b.expert.no_memo = b.expert.no_screen = 1;
        if (b.expert.restart == PSB_RESTART_MIXED) b.expert.restart = PSB_RESTART_PAPER;
    }
    if (b.h == 0 && fd) {
        if (b.expert.h_fd_steps == 0) b.expert.h_fd_steps = 1e4; /* h follows the point */
    } else {
        if (b.h == 0) b.h = h_min;
        if (b.h_min == 0) b.h_min = b.h / 16384.0;
        b.expert.h_fd_steps = 0; /* not used */
    }
    if (b.h_init == 0) b.h_init = h_init;
    if (b.n_dir == 0) b.n_dir = 20;
    if (b.n_span_max == 0) b.n_span_max = b.n_span == 0 && !b.expert.no_memo ? 60 : b.n_span ? b.n_span : 15;
    if (b.n_span == 0) b.n_span = 15;
    if (b.expert.trial_h_min == 0) b.expert.trial_h_min = h_min;
    return b;
}

static int psb__finite(double x) { return x - x == 0; }

/* x * 0 is NaN exactly when x is NaN or Inf, so one sum tells; no branch in the loop, which
   matters for the band checked in every corrector iteration. */
static int psb__all_finite(const double *a, size_t n)
{
    double acc0 = 0, acc1 = 0, acc2 = 0, acc3 = 0;
    size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        acc0 += a[i] * 0.0;
        acc1 += a[i + 1] * 0.0;
        acc2 += a[i + 2] * 0.0;
        acc3 += a[i + 3] * 0.0;
    }
    for (; i < n; i++) acc0 += a[i] * 0.0;
    return (acc0 + acc1) + (acc2 + acc3) == 0;
}

static psb_result psb__fail(psb_solver *s, psb_result code, const char *what)
{
    snprintf(s->message, sizeof s->message, "%s: %s", psb_result_string(code), what);
    return code;
}

/* to += sign d, counter by counter (sign +1 or -1). */
static void psb__stats_add(psb_stats *to, const psb_stats *d, long sign)
{
    to->n_residual += sign * d->n_residual;
    to->n_jacobian += sign * d->n_jacobian;
    to->n_factor += sign * d->n_factor;
    to->n_factor_reused += sign * d->n_factor_reused;
    to->n_pc_steps += sign * d->n_pc_steps;
    to->n_newton += sign * d->n_newton;
    to->n_rejected += sign * d->n_rejected;
    to->n_switches += sign * d->n_switches;
    to->n_tangents += sign * d->n_tangents;
    to->n_tangent_reused += sign * d->n_tangent_reused;
}

/* Checks the options after resolution; returns a message naming the field, or NULL. The upper
   limits keep every count the code forms within an int and every loop bounded: a step shrinks
   at most log(h_max / h_min) / log(1 / h_dec) times (h_dec <= 0.9: under 15000 trials). */
static const char *psb__check_options(const psb_options *o, int np1)
{
    int i;
    /* a weight far from the normal range takes its precision with it: w t^2 formed for a
       scaled t (psb__norm_w) underflows, and a subnormal w normalises t to a norm other than 1 */
#define PSB__WEIGHT_OK(x) ((x) >= 1e-290 && (x) <= 1e290)
    /* lengths and tolerances: normal numbers with room below them (section 5) */
#define PSB__LEN(x) ((x) >= 1e-290 && psb__finite(x)) /* false for NaN and Inf */
    if (!PSB__WEIGHT_OK(o->kappa)) return "kappa must lie in [1e-290, 1e290]";
    if (o->weights)
        for (i = 0; i < np1; i++)
            if (!PSB__WEIGHT_OK(o->weights[i])) return "weights must lie in [1e-290, 1e290]";
    if (!PSB__LEN(o->h_min) || !PSB__LEN(o->h_init) || !PSB__LEN(o->h_max) ||
        !(o->h_min <= o->h_init) || !(o->h_init <= o->h_max))
        return "h_min, h_init, h_max: need 1e-290 <= h_min <= h_init <= h_max < inf";
    if (!(o->h_inc >= 1 && o->h_inc <= 100)) return "h_inc must lie in [1, 100]";
    if (!(o->h_dec >= 1e-3 && o->h_dec <= 0.9)) return "h_dec must lie in [1e-3, 0.9]";
    if (o->max_iter < 1 || o->max_iter > PSB_MAX_ITER_LIMIT) return "max_iter must lie in [1, PSB_MAX_ITER_LIMIT = 1000]";
    if (o->iter_threshold < 1 || o->iter_threshold > PSB_MAX_ITER_LIMIT)
        return "iter_threshold must lie in [1, PSB_MAX_ITER_LIMIT = 1000]";
    if (!PSB__LEN(o->tol_residual)) return "tol_residual must be finite and >= 1e-290";
    if (!PSB__LEN(o->tol_correction)) return "tol_correction must be finite and >= 1e-290";
    if (!(o->c_min > -1 && o->c_min < 1)) return "c_min must lie in (-1, 1)";
    if (!PSB__LEN(o->switch_delta_min) || !PSB__LEN(o->switch_delta_max) ||
        !(o->switch_delta_min <= o->switch_delta_max))
        return "switch_delta_min, switch_delta_max: need 1e-290 <= switch_delta_min <= switch_delta_max < inf";
    if (o->switch_n_dir < 1 || o->switch_n_dir > PSB_MAX_DIR_LIMIT)
        return "switch_n_dir must lie in [1, PSB_MAX_DIR_LIMIT = 10000]";
    if (!(o->c_diff > 0 && o->c_diff < 1)) return "c_diff must lie in (0, 1)";
    return NULL;
}

/* Checks resolved branching options the same way; the message names the field. */
static const char *psb__check_branch(const psb_branch_options *b)
{
    if (b->expert.as_printed != 0 && b->expert.as_printed != 1) return "branch options: expert.as_printed must be 0 or 1";
    if (b->expert.as_printed && b->expert.restart != PSB_RESTART_PAPER)
        return "branch options: expert.as_printed = 1 draws random spans as printed (expert.restart PSB_RESTART_PAPER)";
    if (!PSB__LEN(b->h_init)) return "branch options: h_init must be finite and >= 1e-290";
    if (b->h == 0 && b->expert.h_fd_steps != 0) { /* follows the point (finite differences) */
        if (!(b->expert.h_fd_steps >= 1 && b->expert.h_fd_steps <= 1e8)) return "branch options: expert.h_fd_steps must lie in [1, 1e8]";
        if (b->h_min != 0 && !PSB__LEN(b->h_min)) return "branch options: h_min must be finite and >= 1e-290";
    } else if (!PSB__LEN(b->h) || !PSB__LEN(b->h_min) || !(b->h_min < b->h)) {
        return "branch options: h, h_min: need 1e-290 <= h_min < h < inf (h_min defaults to h / 16384)";
    }
    if (b->n_dir < 1 || b->n_dir > PSB_MAX_DIR_LIMIT)
        return "branch options: n_dir must lie in [1, PSB_MAX_DIR_LIMIT = 10000]";
    if (b->n_span < 1 || b->n_span > PSB_MAX_SPAN_LIMIT)
        return "branch options: n_span must lie in [1, PSB_MAX_SPAN_LIMIT = 10000]";
    if (b->n_span_max < b->n_span || b->n_span_max > PSB_MAX_SPAN_LIMIT)
        return "branch options: n_span_max must lie in [n_span, PSB_MAX_SPAN_LIMIT = 10000]";
    if (!PSB__LEN(b->expert.trial_h_min)) return "branch options: expert.trial_h_min must be finite and >= 1e-290";
    if (b->expert.patience < 0) return "branch options: expert.patience must be >= 0";
    if (b->max_pc < 0) return "branch options: max_pc must be >= 0";
    if (b->expert.restart < PSB_RESTART_MIXED || b->expert.restart > PSB_RESTART_GLOBAL)
        return "branch options: expert.restart must be PSB_RESTART_MIXED, _PAPER or _GLOBAL";
#undef PSB__WEIGHT_OK
#undef PSB__LEN
    return NULL;
}

static size_t psb__align(size_t x) { return (x + 15u) & ~(size_t)15u; }

/* Checks the problem's sizes and callbacks; returns a message or NULL, *code the result. */
static const char *psb__check_problem(const psb_problem *p, psb_result *code)
{
    *code = PSB_ERR_SIZE;
    if (p->n < 1) return "problem.n must be >= 1";
    if (p->param_index < 0 || p->param_index > p->n) return "problem.param_index must lie in [0, n]";
    switch (p->linear) {
    case PSB_LINEAR_DENSE:
        if (p->n > 46000) return "dense problems are limited to n <= 46000: use PSB_LINEAR_BANDED or _USER";
        break;
    case PSB_LINEAR_BANDED:
        if (p->kl < 0 || p->ku < 0 || p->kl >= p->n || p->ku >= p->n)
            return "problem.kl and problem.ku must lie in [0, n-1]";
        if ((double)(2 * (double)p->kl + p->ku + 1) * p->n > 1e15) return "band too large";
        break;
    case PSB_LINEAR_USER:
        *code = PSB_ERR_NULL;
        if (!p->solver.factor || !p->solver.solve) return "problem.solver.factor and .solve are required";
        break;
    default:
        *code = PSB_ERR_OPTIONS;
        return "problem.linear must be PSB_LINEAR_DENSE, _BANDED or _USER";
    }
    *code = PSB_ERR_NULL;
    if (!p->residual) return "problem.residual is NULL";
    return NULL;
}

/* Whether Algorithm 2.2 keeps a Jacobian memo (psb__sample_tangent): an analytic dH in the
   library's own storage, whose bits repeat wherever H is linear. Difference quotients carry
   the point's rounding, and a user backend forms dH itself. */
static int psb__jmemo_usable(const psb_problem *p)
{
    return (p->linear == PSB_LINEAR_DENSE && p->jacobian) ||
           (p->linear == PSB_LINEAR_BANDED && p->band_jacobian);
}

/* Carves the solver's arrays out of memory (when s is not NULL) and returns the bytes needed,
   so that the size query and the layout cannot disagree. */
static size_t psb__layout(const psb_problem *p, psb_solver *s, void *memory)
{
    size_t n = (size_t)p->n, np1 = n + 1, off = 0, ints = 0, kl = (size_t)p->kl, ku = (size_t)p->ku;
    double *base = (double *)memory;
#define PSB__TAKE(field, count)                                                                    \
    do {                                                                                           \
        if (s) s->internal_.field = base + off;                                                              \
        off += (count);                                                                            \
    } while (0)
    PSB__TAKE(w, np1);
    PSB__TAKE(rhs, 2 * np1);
    PSB__TAKE(res, n);
    PSB__TAKE(res2, n);
    PSB__TAKE(work, 4 * np1);
    PSB__TAKE(yfac, np1);
    PSB__TAKE(fdh, n);
    PSB__TAKE(vec, (size_t)PSB__NVEC * np1);
    PSB__TAKE(sweep.memo, (size_t)psb__memo_capacity(p->n) * np1);
    PSB__TAKE(sweep.known, (size_t)psb__memo_capacity(p->n) * np1);
    PSB__TAKE(sweep.path, (size_t)PSB__PATH_MAX * np1);
    if (psb__jmemo_usable(p) || p->piece) {
        size_t cap = (size_t)psb__memo_capacity(p->n);
        PSB__TAKE(sweep.jmemo_t, cap * np1);
        if (s) s->internal_.sweep.jmemo_key = (unsigned long long *)(void *)(base + off);
        off += 2 * cap; /* the keys: 8 bytes each, as a double */
        if (s) s->internal_.sweep.jmemo_sign = (signed char *)(void *)(base + off);
        off += (cap + sizeof(double) - 1) / sizeof(double);
    }
    if (p->linear == PSB_LINEAR_DENSE) {
        PSB__TAKE(jac, n * np1);
        PSB__TAKE(mat, np1 * np1);
        PSB__TAKE(tau, np1);
        ints = 2 * np1;
    } else if (p->linear == PSB_LINEAR_BANDED) {
        PSB__TAKE(bandpair[0], (kl + ku + 1) * n);
        PSB__TAKE(bandpair[1], p->band_lean ? 0 : (kl + ku + 1) * n);
        PSB__TAKE(dpfac, n);
        PSB__TAKE(lu, (2 * kl + ku + 1) * n);
        PSB__TAKE(dparam, n);
        PSB__TAKE(row, np1);
        PSB__TAKE(bv, n);
        PSB__TAKE(bx, np1);
        PSB__TAKE(bres, np1);
        PSB__TAKE(gbw, (kl + PSB__GB_NB) * PSB__GB_NB);
        ints = n;
    }
#undef PSB__TAKE
    off = psb__align(off * sizeof(double));
    if (s) {
        s->internal_.ipiv = (char *)memory + off;
        s->internal_.iwork = p->linear == PSB_LINEAR_DENSE ? (void *)((psb__lint *)s->internal_.ipiv + np1) : NULL;
    }
    return off + psb__align(ints * sizeof(psb__lint));
}

PSCBRANCH_DEF size_t psb_solver_memory_size(const psb_problem *p)
{
    psb_result code;
    if (!p || psb__check_problem(p, &code)) return 0;
    return psb__layout(p, NULL, NULL);
}

PSCBRANCH_DEF psb_result psb_solver_init_with_memory(psb_solver *s, const psb_problem *p,
                                                     const psb_options *opt, void *memory,
                                                     size_t bytes)
{
    const char *bad;
    psb_result code;
    int i;
    if (!s) return PSB_ERR_NULL;
    memset(s, 0, sizeof *s);
    if (!p || !memory) return psb__fail(s, PSB_ERR_NULL, "problem or memory is NULL");
    bad = psb__check_problem(p, &code);
    if (bad) return psb__fail(s, code, bad);
    if (bytes < psb__layout(p, NULL, NULL))
        return psb__fail(s, PSB_ERR_NOMEM, "memory block smaller than psb_solver_memory_size(p)");
    s->opt = psb_options_resolve(opt);
    bad = psb__check_options(&s->opt, p->n + 1);
    if (bad) return psb__fail(s, PSB_ERR_OPTIONS, bad);
    s->prob = *p;
    if (s->prob.fd_step == 0) s->prob.fd_step = p->fd_central ? 6.0554544523933395e-06 : 1.4901161193847656e-08;
    if (!(s->prob.fd_step > 0) || !(s->prob.fd_step < 1))
        return psb__fail(s, PSB_ERR_OPTIONS, "problem.fd_step must lie in (0, 1)");
    s->internal_.n = p->n;
    s->internal_.np1 = p->n + 1;
    s->internal_.ldlu = 2 * p->kl + p->ku + 1;
    s->internal_.sweep.memo_cap = psb__memo_capacity(p->n);
    s->internal_.sweep.jmemo_dh = psb__jmemo_usable(p);
    psb__layout(p, s, memory);
    s->internal_.band = s->internal_.bandpair[0];
    if (p->band_lean) s->internal_.bandpair[1] = NULL;
    for (i = 0; i < s->internal_.np1; i++)
        s->internal_.w[i] = s->opt.weights ? s->opt.weights[i]
                                  : (i == p->param_index ? 1.0 : s->opt.kappa);
    s->opt.weights = NULL; /* copied: the caller's array need not outlive init */
    s->internal_.ready = PSB__READY;
    s->branch = psb_branch_options_resolve(NULL, s);
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_solver_init(psb_solver *s, const psb_problem *p,
                                         const psb_options *opt)
{
    size_t bytes;
    void *mem;
    psb_result r, code;
    const char *bad;
    if (!s) return PSB_ERR_NULL;
    memset(s, 0, sizeof *s);
    if (!p) return psb__fail(s, PSB_ERR_NULL, "problem is NULL");
    bad = psb__check_problem(p, &code);
    if (bad) return psb__fail(s, code, bad);
    bytes = psb__layout(p, NULL, NULL);
    mem = PSCBRANCH_MALLOC(bytes);
    if (!mem) return psb__fail(s, PSB_ERR_NOMEM, "allocation failed");
    r = psb_solver_init_with_memory(s, p, opt, mem, bytes);
    if (r < 0) {
        PSCBRANCH_FREE(mem);
        return r;
    }
    s->internal_.owned = mem;
    return r;
}

PSCBRANCH_DEF void psb_solver_free(psb_solver *s)
{
    psb_stats stats;
    if (!s) return;
    if (s->internal_.ready == PSB__READY && s->internal_.owned) PSCBRANCH_FREE(s->internal_.owned);
    /* every pointer into the block goes, so that a later call fails cleanly (PSB_ERR_NULL);
       the counters stay readable */
    stats = s->stats;
    memset(s, 0, sizeof *s);
    s->stats = stats;
}

PSCBRANCH_DEF const char *psb_solver_message(const psb_solver *s) { return s ? s->message : ""; }

/* The weighted inner product of the library's own vectors (no checks: every caller has them) */
static double psb__dot_w(const psb_solver *s, const double *a, const double *b)
{
    double sum = 0;
    int i;
    for (i = 0; i < s->internal_.np1; i++) sum += s->internal_.w[i] * a[i] * b[i];
    return sum;
}

PSCBRANCH_DEF double psb_dot_w(const psb_solver *s, const double *a, const double *b)
{
    if (!s || s->internal_.ready != PSB__READY || !s->internal_.w || !a || !b) return NAN;
    return psb__dot_w(s, a, b);
}

/* ||a||_w; scaled by max |a_i| where the sum of squares leaves [1e-290, 1e290] (a direction
   given as 1e200 t or 1e-170 t is a direction, not an overflow or a zero) */
static double psb__norm_w(const psb_solver *s, const double *a)
{
    double sum = psb__dot_w(s, a, a), big = 0, scaled = 0;
    int i;
    if (sum >= 1e-290 && sum <= 1e290) return sqrt(sum);
    for (i = 0; i < s->internal_.np1; i++)
        if (fabs(a[i]) > big) big = fabs(a[i]);
    if (!(big > 0) || !psb__finite(big)) return sqrt(sum); /* zero, or NaN/Inf */
    for (i = 0; i < s->internal_.np1; i++) scaled += s->internal_.w[i] * (a[i] / big) * (a[i] / big);
    return big * sqrt(scaled);
}

PSCBRANCH_DEF double psb_norm_w(const psb_solver *s, const double *a)
{
    if (!s || s->internal_.ready != PSB__READY || !s->internal_.w || !a) return NAN;
    return psb__norm_w(s, a);
}

/* ||a - b||_w, formed from the differences (not from dot products, which cancel for close points) */
static double psb__dist_w(const psb_solver *s, const double *a, const double *b)
{
    double sum = 0, big = 0, scaled = 0;
    int i;
    for (i = 0; i < s->internal_.np1; i++) sum += s->internal_.w[i] * (a[i] - b[i]) * (a[i] - b[i]);
    if (!(sum > DBL_MAX)) return sqrt(sum); /* NaN included */
    /* overflowed: halves, so that even a[i] - b[i] stays finite, scaled by the largest */
    for (i = 0; i < s->internal_.np1; i++) big = fmax(big, fabs(0.5 * a[i] - 0.5 * b[i]));
    if (!psb__finite(big)) return sum;
    for (i = 0; i < s->internal_.np1; i++) {
        double d = (0.5 * a[i] - 0.5 * b[i]) / big;
        scaled += s->internal_.w[i] * d * d;
    }
    return 2 * big * sqrt(scaled);
}

static double psb__norm2(const double *a, int n)
{
    double sum = 0;
    int i;
    for (i = 0; i < n; i++) sum += a[i] * a[i];
    return sqrt(sum);
}

/* Weighted cosine of the angle between a and b (0 when either vanishes), with ||a||_w given
   as na (< 0: computed here). One pass forms the sums psb__norm_w and psb__dot_w would, term for
   term in the same order, so the value is theirs bit for bit; Algorithm 2.2 compares each trial
   direction with every stored one, so these passes are hot. */
static double psb__cos_w_na(const psb_solver *s, const double *a, double na, const double *b)
{
    double saa = 0, sbb = 0, sab = 0, nb;
    const double *w = s->internal_.w;
    int i;
    for (i = 0; i < s->internal_.np1; i++) {
        double wa = w[i] * a[i];
        saa += wa * a[i];
        sab += wa * b[i];
        sbb += w[i] * b[i] * b[i];
    }
    if (na < 0) na = saa >= 1e-290 && saa <= 1e290 ? sqrt(saa) : psb__norm_w(s, a);
    nb = sbb >= 1e-290 && sbb <= 1e290 ? sqrt(sbb) : psb__norm_w(s, b);
    return (na > 0 && nb > 0) ? sab / (na * nb) : 0.0;
}

static double psb__cos_w(const psb_solver *s, const double *a, const double *b)
{
    return psb__cos_w_na(s, a, -1.0, b);
}

static void psb__copy(double *dst, const double *src, int n) { memmove(dst, src, (size_t)n * sizeof *dst); }

/* dst = a + h b */
static void psb__axpy_to(double *dst, const double *a, double h, const double *b, int n)
{
    int i;
    for (i = 0; i < n; i++) dst[i] = a[i] + h * b[i];
}

static int psb__normalize_w(const psb_solver *s, double *a)
{
    double nrm = psb__norm_w(s, a);
    int i;
    if (!(nrm > 0) || !psb__finite(nrm)) return 0;
    if (nrm < 1e-290) { /* a norm among subnormals has lost its digits: rescale a first */
        double big = 0;
        for (i = 0; i < s->internal_.np1; i++) big = fmax(big, fabs(a[i]));
        for (i = 0; i < s->internal_.np1; i++) a[i] /= big;
        nrm = psb__norm_w(s, a);
    }
    for (i = 0; i < s->internal_.np1; i++) a[i] /= nrm;
    return 1;
}

/* Maps a callback's return value: 0 ok, < 0 hard stop, > 0 recoverable. */
static psb_result psb__callback_code(psb_solver *s, int rc, const char *which)
{
    if (rc == 0) return PSB_SUCCESS;
    if (rc < 0) return psb__fail(s, PSB_ERR_CALLBACK, which);
    s->internal_.last_fail = PSB__FAIL_CALLBACK;
    return psb__fail(s, PSB_ERR_CALLBACK_FAILED, which);
}

static int psb__fd_jacobian(const psb_problem *p);

/* Whether a recoverable failure code is a fault (not geometry): the codes of psb__tangent and
   psb__try_step, whose SINGULAR is a rank-deficient Jacobian (psb__correct's may be a TURN). */
static int psb__is_fault(psb_result r)
{
    return r == PSB_ERR_CALLBACK_FAILED || r == PSB_ERR_NONFINITE || r == PSB_ERR_SINGULAR;
}

/* Starts the count of faults of an algorithm (psb__note_fault, psb__faults_code). */
static void psb__faults_reset(psb_solver *s)
{
    memset(s->internal_.faults, 0, sizeof s->internal_.faults);
    s->internal_.n_ok = 0;
}

/* Counts a failed trial or tangent of the current algorithm when its code r is a fault;
   returns whether it was. A singular difference Jacobian is counted apart (FD_RANK). */
static int psb__note_fault(psb_solver *s, psb_result r)
{
    if (!psb__is_fault(r)) return 0;
    if (r == PSB_ERR_SINGULAR && psb__fd_jacobian(&s->prob)) {
        s->internal_.faults[3]++;
        return 0;
    }
    s->internal_.faults[r == PSB_ERR_CALLBACK_FAILED ? 0 : r == PSB_ERR_NONFINITE ? 1 : 2]++;
    return 1;
}

/* PSB_SUCCESS when no trial of the current algorithm failed because of a fault; otherwise the
   fault's code (a callback before NaN/Inf before singular) with a message counting them.
   Singular difference Jacobians are a fault when no tangent or corrector run succeeded. */
static psb_result psb__faults_code(psb_solver *s, const char *what)
{
    static const psb_result codes[3] = {PSB_ERR_CALLBACK_FAILED, PSB_ERR_NONFINITE, PSB_ERR_SINGULAR};
    int k;
    if (s->internal_.n_ok == 0 && s->internal_.faults[3] > 0) {
        s->internal_.faults[2] += s->internal_.faults[3];
        s->internal_.faults[3] = 0;
    }
    for (k = 0; k < 3; k++)
        if (s->internal_.faults[k]) {
            char buf[160];
            snprintf(buf, sizeof buf, "%s: failed trials: callback > 0 %ld, NaN/Inf %ld, "
                     "singular dH or solver.factor %ld", what, s->internal_.faults[0], s->internal_.faults[1], s->internal_.faults[2]);
            return psb__fail(s, codes[k], buf);
        }
    return PSB_SUCCESS;
}

/* ---- random numbers: every draw comes from options.seed (no global state) ---------------- */

/* splitmix64 seeds xoshiro256**: a small, fast generator with a fixed, portable sequence. */
static unsigned long long psb__splitmix(unsigned long long *x)
{
    unsigned long long z = (*x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

static unsigned long long psb__rotl(unsigned long long x, int k) { return (x << k) | (x >> (64 - k)); }

static unsigned long long psb__next(unsigned long long *st)
{
    unsigned long long result = psb__rotl(st[1] * 5, 7) * 9, t = st[1] << 17;
    st[2] ^= st[0];
    st[3] ^= st[1];
    st[1] ^= st[2];
    st[0] ^= st[3];
    st[2] ^= t;
    st[3] = psb__rotl(st[3], 45);
    return result;
}

/* A uniform draw in [0, 1) from the top 53 bits of a 64-bit random word. */
static double psb__unit(unsigned long long bits) { return (double)(bits >> 11) * (1.0 / 9007199254740992.0); }

/* Standard normal deviate (Box-Muller; the sine half is dropped to keep the sequence simple). */
static double psb__gauss(unsigned long long *st)
{
    double u1 = ((double)(psb__next(st) >> 11) + 1.0) * (1.0 / 9007199254740993.0);
    double u2 = psb__unit(psb__next(st));
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* ==== Linear algebra (dense, banded, user) ======================================================
   H and dH (analytic or finite differences) and the bordered matrix B = [dH; row^T]:
   factored by the backend problem.linear selects, solved, its determinant's sign. */

/* H(y) into out (n). */
static psb_result psb__residual(psb_solver *s, const double *y, double *out)
{
    int rc;
    psb_result r;
    s->stats.n_residual++;
    rc = s->prob.residual(y, out, s->prob.user);
    r = psb__callback_code(s, rc, "residual callback returned nonzero");
    if (r != PSB_SUCCESS) return r;
    if (!psb__all_finite(out, s->internal_.n)) {
        s->internal_.last_fail = PSB__FAIL_NONFINITE;
        return psb__fail(s, PSB_ERR_NONFINITE, "residual callback returned NaN or Inf");
    }
    return PSB_SUCCESS;
}

/* The difference step for component j at value x: fd_step max(1, |x|), at most fd_cap in the
   weighted norm when that is set. */
static double psb__fd_step(const psb_solver *s, int j, double x, double fd_cap)
{
    double step = s->prob.fd_step * (fabs(x) > 1 ? fabs(x) : 1.0);
    if (fd_cap > 0 && step * sqrt(s->internal_.w[j]) > fd_cap) step = fd_cap / sqrt(s->internal_.w[j]);
    return step;
}

/* dH(y) into s->internal_.jac (n x (n+1), ld n). h_at_y: H(y) if the caller has it (forward differences
   reuse it), else NULL. */
static psb_result psb__jacobian_dense(psb_solver *s, const double *y, const double *h_at_y, double fd_cap)
{
    int n = s->internal_.n, np1 = s->internal_.np1, i, j, rc;
    psb_result r;
    s->stats.n_jacobian++;
    if (s->prob.jacobian) {
        rc = s->prob.jacobian(y, s->internal_.jac, n, s->prob.user);
        r = psb__callback_code(s, rc, "jacobian callback returned nonzero");
        if (r != PSB_SUCCESS) return r;
        if (!psb__all_finite(s->internal_.jac, n * np1)) {
            s->internal_.last_fail = PSB__FAIL_NONFINITE;
            return psb__fail(s, PSB_ERR_NONFINITE, "jacobian callback returned NaN or Inf");
        }
        return PSB_SUCCESS;
    }
    {
        double *yp = PSB__VEC(s, PSB__V_FD);
        if (!s->prob.fd_central && !h_at_y) {
            r = psb__residual(s, y, s->internal_.res2);
            if (r != PSB_SUCCESS) return r;
            h_at_y = s->internal_.res2;
        }
        psb__copy(yp, y, np1);
        for (j = 0; j < np1; j++) {
            double step = psb__fd_step(s, j, y[j], fd_cap);
            double *col = s->internal_.jac + (size_t)j * (size_t)n, hp, hm;
            volatile double probe = y[j] + step; /* the step actually representable */
            hp = probe - y[j];
            yp[j] = y[j] + hp;
            r = psb__residual(s, yp, col);
            if (r != PSB_SUCCESS) { yp[j] = y[j]; return r; }
            if (s->prob.fd_central) {
                /* res2, not res: callers hold H(y) in res across this call */
                yp[j] = y[j] - hp;
                hm = hp;
                r = psb__residual(s, yp, s->internal_.res2);
                if (r != PSB_SUCCESS) { yp[j] = y[j]; return r; }
                for (i = 0; i < n; i++) col[i] = (col[i] - s->internal_.res2[i]) / (hp + hm);
            } else {
                for (i = 0; i < n; i++) col[i] = (col[i] - h_at_y[i]) / hp;
            }
            yp[j] = y[j];
        }
    }
    return PSB_SUCCESS;
}

/* Builds [jac; row^T] in mat ((n+1) x (n+1)) and LU-factors it.
   Returns PSB_SUCCESS or PSB_ERR_SINGULAR; *rcond (if not NULL) gets the reciprocal condition
   number of R B C in the 1-norm (dlacn2's estimate, as dgecon's, with the same LU): C scales
   column j by 1 / sqrt(w_j), the units the weights declare, and R then each row to a largest
   entry of 1, so neither the units of y nor those of H's rows count. Unscaled (dgecon), y in
   units of 1e-8 and 1e8 side by side, with the weights the manual asks for, made every
   tangent's bordered system look singular (PSB_ERR_SINGULAR). */
static psb_result psb__factor_dense(psb_solver *s, const double *row, double *rcond)
{
    int n = s->internal_.n, np1 = s->internal_.np1, i, j;
    psb__lint m = np1, info = 0, kase = 0, isave[3], one = 1;
    double anorm = 0, est = 0, *v = s->internal_.work, *x = s->internal_.work + np1, *rs = s->internal_.work + 2 * np1,
           *cs = s->internal_.work + 3 * np1;
    if (rcond)
        for (i = 0; i < np1; i++) rs[i] = 0;
    for (j = 0; j < np1; j++) {
        double *dst = s->internal_.mat + (size_t)j * (size_t)np1;
        const double *src = s->internal_.jac + (size_t)j * (size_t)n;
        memcpy(dst, src, (size_t)n * sizeof *dst);
        dst[n] = row[j];
        if (rcond) {
            cs[j] = 1 / sqrt(s->internal_.w[j]);
            for (i = 0; i < np1; i++)
                if (fabs(dst[i]) * cs[j] > rs[i]) rs[i] = fabs(dst[i]) * cs[j];
        }
    }
    if (rcond) {
        for (i = 0; i < np1; i++) rs[i] = rs[i] > 0 ? 1 / rs[i] : 1;
        for (j = 0; j < np1; j++) {
            const double *col = s->internal_.mat + (size_t)j * (size_t)np1;
            double colsum = 0;
            for (i = 0; i < np1; i++) colsum += rs[i] * fabs(col[i]) * cs[j];
            if (colsum > anorm) anorm = colsum;
        }
    }
    s->stats.n_factor++;
    PSCBRANCH_FORTRAN(dgetrf)(&m, &m, s->internal_.mat, &m, (psb__lint *)s->internal_.ipiv, &info);
    if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dgetrf rejected an argument");
    if (info > 0) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "bordered matrix is exactly singular");
    }
    if (rcond) {
        /* ||(R B C)^-1||_1: (R B C)^-1 x = C^-1 B^-1 R^-1 x, its transpose R^-1 B^-T C^-1 x */
        for (;;) {
            PSCBRANCH_FORTRAN(dlacn2)(&m, v, x, (psb__lint *)s->internal_.iwork, &est, &kase, isave);
            if (kase == 0) break;
            for (i = 0; i < np1; i++) x[i] /= kase == 1 ? rs[i] : cs[i];
            PSCBRANCH_FORTRAN(dgetrs)(kase == 1 ? "N" : "T", &m, &one, s->internal_.mat, &m, (psb__lint *)s->internal_.ipiv, x, &m,
                                      &info PSB__STRLEN_ONE);
            if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dgetrs rejected an argument");
            for (i = 0; i < np1; i++) x[i] /= kase == 1 ? cs[i] : rs[i];
        }
        *rcond = est > 0 && anorm > 0 && isfinite(est * anorm) ? 1 / (est * anorm) : 0;
    }
    return PSB_SUCCESS;
}

static psb_result psb__solve_dense(psb_solver *s, double *b, int nrhs)
{
    psb__lint m = s->internal_.np1, nr = nrhs, info = 0;
    PSCBRANCH_FORTRAN(dgetrs)("N", &m, &nr, s->internal_.mat, &m, (psb__lint *)s->internal_.ipiv, b, &m, &info PSB__STRLEN_ONE);
    if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dgetrs rejected an argument");
    if (!psb__all_finite(b, s->internal_.np1 * nrhs)) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "solution of the bordered system is not finite");
    }
    return PSB_SUCCESS;
}


/* ---- banded backend: LU of the state block A = dH/dx (as dgbtrf) and bordering ----------------
   The bordered matrix is B = [A b; c^T d] up to the position of the parameter (b = dH/dparam,
   (c, d) the border row). Block elimination: w = A^{-1} b once per factorisation,
   delta = d - c.w; for each right-hand side (f, g): z = A^{-1} f, xi = (g - c.z) / delta,
   x = z - w xi, one banded solve (none for the tangent's (0, 1)). Near a fold A is nearly
   singular (B is not) and this cancels, so every result is checked by its residual in B and
   refined; if A is exactly singular, or refinement stalls, A + sigma I (sigma ~ sqrt(eps) ||B||)
   is factored instead and refinement against the true B converges at a rate ~ sigma ||B^{-1}||.
   It takes 2 banded solves per corrector iteration where mixed elimination needs 3.
   A is kept beside its factors (two band buffers take turns), and a new A bit-identical to the
   factored one reuses them: on a piecewise-linear H, A only changes with the piece, so the
   corrector's second iteration and the tangent at an accepted point usually cost no
   factorisation. The LU being deterministic, the results are those of factoring again. */

/* state column j <-> y component */
static int psb__ycol(const psb_solver *s, int j) { return j < s->prob.param_index ? j : j + 1; }

/* band_jacobian at y into band and dparam (zeroed by the caller). Every entry is checked,
   since an Inf on the diagonal factors into finite, wrong solutions. */
static psb_result psb__band_callback(psb_solver *s, const double *y)
{
    int ld = s->prob.kl + s->prob.ku + 1;
    size_t size = (size_t)ld * (size_t)s->internal_.n;
    psb_result r = psb__callback_code(s, s->prob.band_jacobian(y, s->internal_.band, ld, s->internal_.dparam, s->prob.user),
                                      "band_jacobian callback returned nonzero");
    if (r != PSB_SUCCESS) return r;
    if (!psb__all_finite(s->internal_.band, size) || !psb__all_finite(s->internal_.dparam, (size_t)s->internal_.n)) {
        s->internal_.last_fail = PSB__FAIL_NONFINITE;
        return psb__fail(s, PSB_ERR_NONFINITE, "band_jacobian callback returned NaN or Inf");
    }
    return PSB_SUCCESS;
}

/* A = dH/dx at y into band, the buffer of the pair that lu's factors did not come from. */
static psb_result psb__jacobian_banded(psb_solver *s, const double *y, const double *h_at_y, double fd_cap)
{
    int n = s->internal_.n, kl = s->prob.kl, ku = s->prob.ku, ld = kl + ku + 1, p = s->prob.param_index;
    int i, j, g;
    psb_result r;
    if (!s->internal_.bandpair[1]) s->internal_.afac = NULL; /* one buffer: the factors' A is overwritten */
    s->internal_.band = s->internal_.afac == s->internal_.bandpair[0] ? s->internal_.bandpair[1] : s->internal_.bandpair[0];
    s->internal_.band_ok = 0;
    psb__copy(s->internal_.yfac, y, s->internal_.np1);
    memset(s->internal_.band, 0, (size_t)ld * (size_t)n * sizeof(double));
    memset(s->internal_.dparam, 0, (size_t)n * sizeof(double));
    if (s->prob.band_jacobian) {
        r = psb__band_callback(s, y);
        s->internal_.band_ok = r == PSB_SUCCESS;
        return r;
    }
    /* finite differences, Curtis-Powell-Reid: state columns j = g, g + ld, g + 2 ld, ... touch
       disjoint rows, so one residual serves the whole group (two when central) */
    {
        double *yp = PSB__VEC(s, PSB__V_FD), *hp = s->internal_.fdh, *steps = s->internal_.bx, scale;
        const double *base;
        int central = s->prob.fd_central;
        if (!h_at_y && !central) {
            r = psb__residual(s, y, s->internal_.res2);
            if (r != PSB_SUCCESS) return r;
            h_at_y = s->internal_.res2;
        }
        for (g = 0; g <= ld; g++) {
            int side;
            if (g < ld) {
                for (j = g; j < n; j += ld) {
                    int c = psb__ycol(s, j);
                    volatile double probe = y[c] + psb__fd_step(s, c, y[c], fd_cap);
                    steps[j] = probe - y[c];
                }
            } else {
                volatile double probe = y[p] + psb__fd_step(s, p, y[p], fd_cap);
                steps[0] = probe - y[p];
            }
            /* side 1: y + steps into hp; side -1 (central): y - steps into res2 (not res:
               callers hold H(y) there across this call) */
            for (side = 1; side >= (central ? -1 : 1); side -= 2) {
                psb__copy(yp, y, s->internal_.np1);
                if (g < ld) {
                    for (j = g; j < n; j += ld) yp[psb__ycol(s, j)] += side * steps[j];
                } else {
                    yp[p] += side * steps[0];
                }
                r = psb__residual(s, yp, side > 0 ? hp : s->internal_.res2);
                if (r != PSB_SUCCESS) return r;
            }
            base = central ? s->internal_.res2 : h_at_y;
            scale = central ? 2 : 1;
            if (g < ld) {
                for (j = g; j < n; j += ld) {
                    int lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
                    for (i = lo; i <= hi; i++)
                        s->internal_.band[PSB_BAND_INDEX(ku, ld, i, j)] = (hp[i] - base[i]) / (scale * steps[j]);
                }
            } else {
                for (i = 0; i < n; i++) s->internal_.dparam[i] = (hp[i] - base[i]) / (scale * steps[0]);
            }
        }
    }
    s->internal_.band_ok = 1;
    return PSB_SUCCESS;
}

#ifndef PSCBRANCH_USE_DGBTRF
/* Banded LU with partial pivoting, dgbtrf's algorithm, storage and pivots: ab holds A in rows
   kl .. 2 kl + ku of ldab (A(i,j) at ab[kl + ku + i - j + j ldab]), rows 0 .. kl - 1 zero (room
   for fill-in). Returns 0, or j + 1 at the first exactly zero pivot j (the factorisation stops
   there). Panels of PSB__GB_NB columns: each is factored as dgbtf2 does, then every column to
   its right takes the panel's interchanges and its PSB__GB_NB eliminations in one pass, the
   multipliers first permuted by the panel's later interchanges (w: (kl + PSB__GB_NB)
   PSB__GB_NB doubles). Every entry undergoes the same operations in the same order as in
   dgbtf2, so the factors are dgbtrf's bit for bit (reference LAPACK); what changes is that a
   column entry is loaded and stored once per panel instead of once per column (bench_linear
   measures it against dgbtrf). */
static int psb__gbtrf(int n, int kl, int ku, double *ab, int ldab, psb__lint *ipiv, double *w)
{
    int kv = kl + ku, ju = 0, j0, juk[PSB__GB_NB];
#define PSB__AB(i, j) ab[(size_t)(kv + (i) - (j)) + (size_t)(j) * (size_t)ldab]
    for (j0 = 0; j0 < n; j0 += PSB__GB_NB) {
        int jb = n - j0 < PSB__GB_NB ? n - j0 : PSB__GB_NB, jend = j0 + jb - 1, hgt = jb + kl;
        int hi = jend + kl < n - 1 ? jend + kl : n - 1; /* last row the panel's multipliers reach */
        int j, k, c, i;
        for (j = j0; j <= jend; j++) { /* the panel, as dgbtf2 */
            int km = kl < n - 1 - j ? kl : n - 1 - j, p = j, cend;
            double amax = fabs(PSB__AB(j, j));
            for (i = j + 1; i <= j + km; i++)
                if (fabs(PSB__AB(i, j)) > amax) { amax = fabs(PSB__AB(i, j)); p = i; }
            ipiv[j] = p + 1;
            if (PSB__AB(p, j) == 0) return j + 1;
            if ((p + ku < n - 1 ? p + ku : n - 1) > ju) ju = p + ku < n - 1 ? p + ku : n - 1;
            juk[j - j0] = ju;
            cend = ju < jend ? ju : jend;
            if (p != j)
                for (c = j; c <= cend; c++) {
                    double t = PSB__AB(j, c);
                    PSB__AB(j, c) = PSB__AB(p, c);
                    PSB__AB(p, c) = t;
                }
            if (km > 0) {
                double r = 1 / PSB__AB(j, j), *l = &PSB__AB(j + 1, j);
                for (i = 0; i < km; i++) l[i] *= r;
                for (c = j + 1; c <= cend; c++) {
                    double u = PSB__AB(j, c), *a = &PSB__AB(j + 1, c);
                    if (u != 0)
                        for (i = 0; i < km; i++) a[i] -= l[i] * u;
                }
            }
        }
        if (ju <= jend) continue;
        /* w column k (rows j0 .. hi): the multipliers of step j0 + k, later interchanges applied */
        memset(w, 0, (size_t)hgt * (size_t)jb * sizeof(double));
        for (k = 0; k < jb; k++) {
            int jj = j0 + k, km = kl < n - 1 - jj ? kl : n - 1 - jj, kk;
            double *wk = w + (size_t)k * (size_t)hgt;
            for (i = 1; i <= km; i++) wk[k + i] = PSB__AB(jj + i, jj);
            for (kk = k + 1; kk < jb; kk++) {
                int q = (int)ipiv[j0 + kk] - 1 - j0;
                if (q != kk) {
                    double t = wk[kk];
                    wk[kk] = wk[q];
                    wk[q] = t;
                }
            }
        }
        for (c = jend + 1; c <= ju; c++) {
            /* col[r] = A(j0 + r, c), rows j0 .. hi; w column k at w + k hgt, same rows */
            double *col = ab + ((ptrdiff_t)c * ldab + kv + j0 - c); /* c ldab + kv + j0 - c >= 0 */
            int k0 = 0, rhi = hi - j0;
            while (c > juk[k0]) k0++; /* steps before k0 left column c untouched (all zero) */
            for (k = k0; k < jb; k++) {
                int q = (int)ipiv[j0 + k] - 1 - j0;
                if (q != k) {
                    double t = col[k];
                    col[k] = col[q];
                    col[q] = t;
                }
            }
            if (k0 == 0 && jb == PSB__GB_NB) {
                const double *w0 = w, *w1 = w0 + hgt, *w2 = w1 + hgt, *w3 = w2 + hgt;
                double u0 = col[0], u1, u2, u3;
                u1 = col[1] - w0[1] * u0;
                u2 = (col[2] - w0[2] * u0) - w1[2] * u1;
                u3 = ((col[3] - w0[3] * u0) - w1[3] * u1) - w2[3] * u2;
                col[1] = u1;
                col[2] = u2;
                col[3] = u3;
                i = PSB__GB_NB;
#ifdef PSB__SSE2
                {
                    __m128d v0 = _mm_set1_pd(u0), v1 = _mm_set1_pd(u1), v2 = _mm_set1_pd(u2), v3 = _mm_set1_pd(u3);
                    for (; i + 1 <= rhi; i += 2) {
                        __m128d t = _mm_loadu_pd(col + i);
                        t = _mm_sub_pd(t, _mm_mul_pd(_mm_loadu_pd(w0 + i), v0));
                        t = _mm_sub_pd(t, _mm_mul_pd(_mm_loadu_pd(w1 + i), v1));
                        t = _mm_sub_pd(t, _mm_mul_pd(_mm_loadu_pd(w2 + i), v2));
                        t = _mm_sub_pd(t, _mm_mul_pd(_mm_loadu_pd(w3 + i), v3));
                        _mm_storeu_pd(col + i, t);
                    }
                }
#endif
                for (; i <= rhi; i++) col[i] = (((col[i] - w0[i] * u0) - w1[i] * u1) - w2[i] * u2) - w3[i] * u3;
            } else {
                for (k = k0; k < jb; k++) {
                    const double *wk = w + (size_t)k * (size_t)hgt;
                    double u = col[k];
                    if (u != 0)
                        for (i = k + 1; i <= rhi; i++) col[i] -= wk[i] * u;
                }
            }
        }
    }
#undef PSB__AB
    return 0;
}
#endif

/* A + shift I (ab: band layout, ld = kl + ku + 1) into lu (dgbtrf's layout, kl extra rows on
   top, ldlu) and its LU, pivots in ipiv (w: psb__gbtrf's work). 0; > 0 at an exactly zero
   pivot; < 0 when dgbtrf rejected an argument. */
static long psb__band_factor(int n, int kl, int ku, const double *ab, double shift, double *lu, int ldlu,
                             psb__lint *ipiv, double *w)
{
    int ld = kl + ku + 1, j;
    for (j = 0; j < n; j++) {
        double *dst = lu + (size_t)j * (size_t)ldlu;
        memset(dst, 0, (size_t)kl * sizeof(double));
        memcpy(dst + kl, ab + (size_t)j * (size_t)ld, (size_t)ld * sizeof(double));
        dst[kl + ku] += shift;
    }
#ifdef PSCBRANCH_USE_DGBTRF
    {
        psb__lint nn = n, kkl = kl, kku = ku, lldlu = ldlu, linfo = 0;
        (void)w;
        PSCBRANCH_FORTRAN(dgbtrf)(&nn, &nn, &kkl, &kku, lu, &lldlu, ipiv, &linfo);
        return (long)linfo;
    }
#else
    return psb__gbtrf(n, kl, ku, lu, ldlu, ipiv, w);
#endif
}

/* LU of A + shift I into lu (dgbtrf layout: kl extra rows on top), unless lu holds the
   unshifted factors of a bit-identical A already. */
static psb_result psb__band_lu(psb_solver *s, double shift)
{
    int n = s->internal_.n, kl = s->prob.kl, ku = s->prob.ku, ld = kl + ku + 1;
    size_t size = (size_t)ld * (size_t)n;
    long info;
    if (!s->internal_.band_ok) return psb__fail(s, PSB_ERR_INPUT, "no Jacobian to factor");
    if (shift == 0 && s->internal_.afac &&
        (s->internal_.afac == s->internal_.band || !memcmp(s->internal_.afac, s->internal_.band, size * sizeof(double)))) {
        s->stats.n_factor_reused++;
        return PSB_SUCCESS;
    }
    s->internal_.afac = NULL;
    s->internal_.bv_ok = 0;
    s->stats.n_factor++;
    info = psb__band_factor(n, kl, ku, s->internal_.band, shift, s->internal_.lu, s->internal_.ldlu,
                            (psb__lint *)s->internal_.ipiv, s->internal_.gbw);
    if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dgbtrf rejected an argument");
    if (info > 0) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "banded block is exactly singular");
    }
    if (shift == 0) s->internal_.afac = s->internal_.band;
    return PSB_SUCCESS;
}

#if defined(__cplusplus)
#define PSB__RESTRICT __restrict
#else
#define PSB__RESTRICT restrict
#endif

/* x += a c and, when y is not NULL, y += b c (m entries). Unrolled by four with each c[i]
   loaded once: this runs well at -O2, where compilers do not vectorise loops of unknown length. */
static void psb__band_axpy(int m, const double *PSB__RESTRICT c, double a, double *PSB__RESTRICT x,
                           double b, double *PSB__RESTRICT y)
{
    int i = 0;
    if (y) {
        for (; i + 4 <= m; i += 4) {
            double c0 = c[i], c1 = c[i + 1], c2 = c[i + 2], c3 = c[i + 3];
            x[i] += c0 * a; x[i + 1] += c1 * a; x[i + 2] += c2 * a; x[i + 3] += c3 * a;
            y[i] += c0 * b; y[i + 1] += c1 * b; y[i + 2] += c2 * b; y[i + 3] += c3 * b;
        }
        for (; i < m; i++) { x[i] += c[i] * a; y[i] += c[i] * b; }
    } else {
        for (; i + 4 <= m; i += 4) {
            x[i] += c[i] * a; x[i + 1] += c[i + 1] * a; x[i + 2] += c[i + 2] * a; x[i + 3] += c[i + 3] * a;
        }
        for (; i < m; i++) x[i] += c[i] * a;
    }
}

/* x <- A^{-1} x and, when y is not NULL, y <- A^{-1} y in the same pass over dgbtrf's factors
   lu (leading dimension ldlu, pivots ipiv) of A, n x n with kl, ku: dgbtrs' substitutions
   ("N", column by column) with the same operations in the same order, two right-hand sides
   sharing every load of the factors (about half the time of two dgbtrs calls: bench_linear). */
static void psb__band_subst_lu(int n, int kl, int ku, const double *lu, size_t ldlu, const psb__lint *ipiv,
                               double *x, double *y)
{
    int kv = kl + ku, j;
    for (j = 0; kl > 0 && j < n - 1; j++) {
        const double *col = lu + (size_t)j * ldlu + kv + 1;
        int l = (int)ipiv[j] - 1;
        if (l != j) {
            double tmp = x[l];
            x[l] = x[j]; x[j] = tmp;
            if (y) { tmp = y[l]; y[l] = y[j]; y[j] = tmp; }
        }
        psb__band_axpy(kl < n - 1 - j ? kl : n - 1 - j, col, -x[j], x + j + 1, y ? -y[j] : 0,
                       y ? y + j + 1 : NULL);
    }
    for (j = n - 1; j >= 0; j--) {
        const double *col = lu + (size_t)j * ldlu;
        int above = j < kv ? j : kv; /* U's entries above the diagonal in column j */
        x[j] /= col[kv];
        if (y) y[j] /= col[kv];
        psb__band_axpy(above, col + kv - above, -x[j], x + j - above, y ? -y[j] : 0,
                       y ? y + j - above : NULL);
    }
}

/* psb__band_subst_lu on the solver's factors. */
static void psb__band_subst(const psb_solver *s, double *x, double *y)
{
    psb__band_subst_lu(s->internal_.n, s->prob.kl, s->prob.ku, s->internal_.lu, (size_t)s->internal_.ldlu,
                       (const psb__lint *)s->internal_.ipiv, x, y);
}

/* Factors A (shifted if asked) for the border row in row; w = A^{-1} b and delta = d - c.w
   follow with the first solve (psb__band_border), in the same pass as its right-hand side. */
static psb_result psb__band_prepare(psb_solver *s, double shift)
{
    psb_result r = psb__band_lu(s, shift);
    if (r != PSB_SUCCESS) return r;
    if (s->internal_.bv_ok && memcmp(s->internal_.dpfac, s->internal_.dparam, (size_t)s->internal_.n * sizeof(double))) s->internal_.bv_ok = 0;
    s->internal_.border_ok = 0;
    return PSB_SUCCESS;
}

/* w = A^{-1} b (unless current) and delta = d - c.w; x, when not NULL, is replaced by A^{-1} x
   in the same pass over the factors. */
static psb_result psb__band_border(psb_solver *s, double *x)
{
    int n = s->internal_.n, j;
    double delta;
    if (s->internal_.bv_ok) {
        if (x) psb__band_subst(s, x, NULL);
    } else {
        memcpy(s->internal_.dpfac, s->internal_.dparam, (size_t)n * sizeof(double));
        memcpy(s->internal_.bv, s->internal_.dparam, (size_t)n * sizeof(double));
        psb__band_subst(s, s->internal_.bv, x);
        s->internal_.bv_ok = 1;
    }
    delta = s->internal_.row[s->prob.param_index];
    s->internal_.bamp = fabs(delta);
    for (j = 0; j < n; j++) {
        delta -= s->internal_.row[psb__ycol(s, j)] * s->internal_.bv[j];
        s->internal_.bamp += fabs(s->internal_.row[psb__ycol(s, j)] * s->internal_.bv[j]);
    }
    if (!psb__finite(delta) || delta == 0 || !psb__all_finite(s->internal_.bv, (size_t)n)) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "bordered banded system is singular");
    }
    /* cancellation in delta = d - c.w: the factor by which block elimination can amplify the
       banded solves' errors (large only near a fold, where A is nearly singular) */
    s->internal_.bamp /= fabs(delta);
    s->internal_.delta = delta;
    s->internal_.border_ok = 1;
    return PSB_SUCCESS;
}

/* ||B||_1 (largest column sum), the scale of the refinement test and of the shift; computed
   only where one of them is needed (near folds), not in every corrector iteration. */
static double psb__band_mnorm(psb_solver *s)
{
    int n = s->internal_.n, ld = s->prob.kl + s->prob.ku + 1, i, j;
    double bnorm = 0, sum;
    if (s->internal_.mnorm >= 0) return s->internal_.mnorm;
    for (j = 0; j < n; j++) {
        const double *col = s->internal_.band + (size_t)j * (size_t)ld;
        for (sum = fabs(s->internal_.row[psb__ycol(s, j)]), i = 0; i < ld; i++) sum += fabs(col[i]);
        if (sum > bnorm) bnorm = sum;
    }
    for (sum = fabs(s->internal_.row[s->prob.param_index]), i = 0; i < n; i++) sum += fabs(s->internal_.dparam[i]);
    s->internal_.mnorm = sum > bnorm ? sum : bnorm;
    return s->internal_.mnorm;
}

static double psb__band_shift(psb_solver *s)
{
    double m = psb__band_mnorm(s);
    return 1.4901161193847656e-08 * (m > 0 ? m : 1); /* sqrt(eps) ||B|| */
}

/* A nearly or exactly singular: A + sigma I instead (refinement then solves with the true B) */
static psb_result psb__band_prepare_shifted(psb_solver *s)
{
    psb_result r = psb__band_prepare(s, psb__band_shift(s));
    s->internal_.shifted = r == PSB_SUCCESS;
    return r;
}

static psb_result psb__factor_banded(psb_solver *s, const double *row)
{
    psb_result r;
    psb__copy(s->internal_.row, row, s->internal_.np1);
    s->internal_.mnorm = -1;
    s->internal_.shifted = 0;
    r = psb__band_prepare(s, 0.0);
    return r == PSB_ERR_SINGULAR ? psb__band_prepare_shifted(s) : r;
}

/* One block elimination solve with the current factors: z = B_shift^{-1} rhs. A right-hand
   side (0, 1), the tangent's, needs no banded solve: z = (-w, 1) / delta. Where delta vanishes
   on the unshifted factors, A is refactored shifted. */
static psb_result psb__band_apply(psb_solver *s, const double *rhs, double *z)
{
    int n = s->internal_.n, j, p = s->prob.param_index, zero_f = 1;
    double xi = rhs[n], *x = s->internal_.work + s->internal_.np1; /* work[0, np1) holds the caller's rhs */
    psb_result r;
    for (j = 0; j < n && zero_f; j++) zero_f = rhs[j] == 0;
    for (;;) {
        if (zero_f) memset(x, 0, (size_t)n * sizeof(double));
        else memcpy(x, rhs, (size_t)n * sizeof(double));
        if (s->internal_.border_ok) {
            if (!zero_f) psb__band_subst(s, x, NULL);
            break;
        }
        r = psb__band_border(s, zero_f ? NULL : x);
        if (r == PSB_SUCCESS) break;
        if (r != PSB_ERR_SINGULAR || s->internal_.shifted) return r;
        r = psb__band_prepare_shifted(s);
        if (r != PSB_SUCCESS) return r;
    }
    for (j = 0; j < n; j++) xi -= s->internal_.row[psb__ycol(s, j)] * x[j];
    xi /= s->internal_.delta;
    for (j = 0; j < n; j++) z[psb__ycol(s, j)] = x[j] - s->internal_.bv[j] * xi;
    z[p] = xi;
    return PSB_SUCCESS;
}

/* res = rhs - B z with the unshifted B; returns ||res||_inf. */
static double psb__band_residual(const psb_solver *s, const double *rhs, const double *z, double *res)
{
    int n = s->internal_.n, kl = s->prob.kl, ku = s->prob.ku, ld = kl + ku + 1, i, j, p = s->prob.param_index;
    double big = 0, last = rhs[n];
    for (i = 0; i < n; i++) res[i] = rhs[i] - s->internal_.dparam[i] * z[p];
    for (j = 0; j < n; j++) {
        double zj = z[psb__ycol(s, j)];
        int lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
        for (i = lo; i <= hi; i++) res[i] -= s->internal_.band[PSB_BAND_INDEX(ku, ld, i, j)] * zj;
    }
    for (i = 0; i <= n; i++) last -= s->internal_.row[i] * z[i];
    res[n] = last;
    for (i = 0; i <= n; i++)
        if (fabs(res[i]) > big || res[i] != res[i]) big = res[i] != res[i] ? HUGE_VAL : fabs(res[i]);
    return big;
}

static psb_result psb__solve_banded(psb_solver *s, double *b, int nrhs)
{
    int np1 = s->internal_.np1, k, it, i;
    for (k = 0; k < nrhs; k++) {
        double *rhs = s->internal_.bres, *z = b + (size_t)k * (size_t)np1, *dz = s->internal_.bx;
        double bnorm = 0, znorm, resn, prev = HUGE_VAL;
        int max_it = s->internal_.shifted ? 30 : 4, done = 0;
        psb_result r;
        /* keep the right-hand side: the solution overwrites it */
        memcpy(s->internal_.work, z, (size_t)np1 * sizeof(double));
        for (i = 0; i < np1; i++) bnorm = fabs(z[i]) > bnorm ? fabs(z[i]) : bnorm;
        r = psb__band_apply(s, s->internal_.work, z);
        if (r != PSB_SUCCESS) return r;
        /* far from folds block elimination is as accurate as the LU solve itself (backward stable):
           the residual check and refinement are for a nearly singular A only */
        if (!s->internal_.shifted && s->internal_.bamp <= 16) continue;
        for (it = 0; it <= max_it && !done; it++) {
            znorm = 0;
            for (i = 0; i < np1; i++) znorm = fabs(z[i]) > znorm ? fabs(z[i]) : znorm;
            resn = psb__band_residual(s, s->internal_.work, z, rhs);
            if (resn <= 32 * DBL_EPSILON * (psb__band_mnorm(s) * znorm + bnorm)) { done = 1; break; }
            if (!(resn < 0.5 * prev) && it >= 2) break; /* stalled */
            prev = resn;
            r = psb__band_apply(s, rhs, dz);
            if (r != PSB_SUCCESS) return r;
            for (i = 0; i < np1; i++) z[i] += dz[i];
        }
        if (!done) {
            if (!s->internal_.shifted) {
                /* nearly singular A: refactor shifted, restart this column */
                r = psb__band_prepare_shifted(s);
                if (r != PSB_SUCCESS) return r;
                memcpy(z, s->internal_.work, (size_t)np1 * sizeof(double));
                k--;
                continue;
            }
            s->internal_.last_fail = PSB__FAIL_SINGULAR;
            return psb__fail(s, PSB_ERR_SINGULAR, "bordered banded system: refinement did not converge");
        }
    }
    return PSB_SUCCESS;
}

/* ---- backend dispatch ------------------------------------------------------------------- */

/* dH(y) for the next factorisation. h_at_y: H(y) if the caller has it (finite differences
   reuse it), else NULL. */
static psb_result psb__jacobian_capped(psb_solver *s, const double *y, const double *h_at_y, double fd_cap)
{
    switch (s->prob.linear) {
    case PSB_LINEAR_BANDED: s->stats.n_jacobian++; return psb__jacobian_banded(s, y, h_at_y, fd_cap);
    case PSB_LINEAR_USER: psb__copy(s->internal_.yfac, y, s->internal_.np1); return PSB_SUCCESS;
    default: return psb__jacobian_dense(s, y, h_at_y, fd_cap);
    }
}

static psb_result psb__jacobian(psb_solver *s, const double *y, const double *h_at_y)
{
    return psb__jacobian_capped(s, y, h_at_y, 0);
}

/* Factors [dH(y); row^T] for the y of the last psb__jacobian. rcond (dense only, may be NULL):
   reciprocal condition estimate; the other backends report 1 and detect trouble when solving. */
static psb_result psb__factor_bordered(psb_solver *s, const double *row, double *rcond)
{
    int rc;
    psb_result r;
    if (rcond) *rcond = 1;
    switch (s->prob.linear) {
    case PSB_LINEAR_BANDED: return psb__factor_banded(s, row);
    case PSB_LINEAR_USER:
        s->stats.n_factor++;
        s->stats.n_jacobian++;
        rc = s->prob.solver.factor(s->internal_.yfac, row, s->prob.solver.ctx);
        r = psb__callback_code(s, rc, "solver.factor returned nonzero");
        if (r == PSB_ERR_CALLBACK_FAILED) {
            s->internal_.last_fail = PSB__FAIL_SINGULAR;
            return psb__fail(s, PSB_ERR_SINGULAR, "solver.factor reported a singular matrix");
        }
        return r;
    default: return psb__factor_dense(s, row, rcond);
    }
}

static psb_result psb__solve_factored(psb_solver *s, double *b, int nrhs)
{
    int rc;
    psb_result r;
    switch (s->prob.linear) {
    case PSB_LINEAR_BANDED: r = psb__solve_banded(s, b, nrhs); break;
    case PSB_LINEAR_USER:
        rc = s->prob.solver.solve(b, nrhs, s->prob.solver.ctx);
        r = psb__callback_code(s, rc, "solver.solve returned nonzero");
        if (r == PSB_ERR_CALLBACK_FAILED) {
            s->internal_.last_fail = PSB__FAIL_SINGULAR;
            r = psb__fail(s, PSB_ERR_SINGULAR, "solver.solve failed");
        }
        break;
    default: return psb__solve_dense(s, b, nrhs);
    }
    if (r == PSB_SUCCESS && !psb__all_finite(b, s->internal_.np1 * nrhs)) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "solution of the bordered system is not finite");
    }
    return r;
}

/* Kernel of s->internal_.jac through the QR factorisation of its transpose: the last column of Q spans
   the orthogonal complement of range(jac^T) = ker(jac) when jac has rank n. Factored as
   (R jac C)^T, C scaling column j by 1 / sqrt(w_j) and R then each row to a largest entry of 1,
   so that the rank test does not depend on the units of y or H; t = C z from its kernel z. */
static psb_result psb__kernel_qr(psb_solver *s, double *t)
{
    int n = s->internal_.n, np1 = s->internal_.np1, i, j;
    psb__lint m = np1, nn = n, one = 1, info = 0;
    double rmax = 0, rmin = HUGE_VAL, *rs = s->internal_.work; /* taken before dgeqr2 uses it */
    for (i = 0; i < n; i++) {
        double big = 0;
        for (j = 0; j < np1; j++)
            if (fabs(s->internal_.jac[i + (size_t)j * (size_t)n]) / sqrt(s->internal_.w[j]) > big)
                big = fabs(s->internal_.jac[i + (size_t)j * (size_t)n]) / sqrt(s->internal_.w[j]);
        rs[i] = big > 0 ? 1 / big : 1;
    }
    for (j = 0; j < np1; j++)
        for (i = 0; i < n; i++)
            s->internal_.mat[j + (size_t)i * (size_t)np1] = rs[i] * s->internal_.jac[i + (size_t)j * (size_t)n] / sqrt(s->internal_.w[j]);
    s->stats.n_factor++;
    PSCBRANCH_FORTRAN(dgeqr2)(&m, &nn, s->internal_.mat, &m, s->internal_.tau, s->internal_.work, &info);
    if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dgeqr2 rejected an argument");
    for (i = 0; i < n; i++) {
        double d = fabs(s->internal_.mat[i + (size_t)i * (size_t)np1]);
        if (d > rmax) rmax = d;
        if (d < rmin) rmin = d;
    }
    if (!(rmin > rmax * DBL_EPSILON * np1)) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "Jacobian has rank < n: no unique tangent");
    }
    memset(t, 0, (size_t)np1 * sizeof *t);
    t[n] = 1;
    PSCBRANCH_FORTRAN(dorm2r)("L", "N", &m, &one, &nn, s->internal_.mat, &m, s->internal_.tau, t, &m, s->internal_.work,
                              &info PSB__STRLEN_ONE PSB__STRLEN_ONE);
    if (info < 0) return psb__fail(s, PSB_ERR_LAPACK, "dorm2r rejected an argument");
    for (j = 0; j < np1; j++) t[j] /= sqrt(s->internal_.w[j]);
    return PSB_SUCCESS;
}

/* sgn det B and log|det B| (logabs may be NULL) from the current LU factors of B = [dH; row^T]:
   dense, or banded with A unshifted and the border current (det B = (-1)^(n - p) det A (d -
   c.w), the parameter column moved last); 0 where the factors do not tell it. O(N). */
static int psb__factors_det(const psb_solver *s, double *logabs)
{
    int n = s->internal_.n, np1 = s->internal_.np1, i, sign = 1;
    const psb__lint *ipiv = (const psb__lint *)s->internal_.ipiv;
    double la = 0;
    if (s->prob.linear == PSB_LINEAR_DENSE) {
        for (i = 0; i < np1; i++) {
            double u = s->internal_.mat[i + (size_t)i * (size_t)np1];
            if ((u < 0) != (ipiv[i] != i + 1)) sign = -sign;
            if (logabs) la += log(fabs(u));
        }
    } else if (s->prob.linear == PSB_LINEAR_BANDED && !s->internal_.shifted && s->internal_.border_ok) {
        int kv = s->prob.kl + s->prob.ku;
        for (i = 0; i < n; i++) {
            double u = s->internal_.lu[(size_t)kv + (size_t)i * (size_t)s->internal_.ldlu];
            if ((u < 0) != (ipiv[i] != i + 1)) sign = -sign;
            if (logabs) la += log(fabs(u));
        }
        if (s->internal_.delta < 0) sign = -sign;
        if ((n - s->prob.param_index) % 2) sign = -sign;
        if (logabs) la += log(fabs(s->internal_.delta));
    } else {
        return 0;
    }
    if (logabs) *logabs = la;
    return sign;
}

/* Unit tangent at y oriented by ref (both n+1); y's Jacobian is evaluated here. */
/* ==== Corrector and tangent =====================================================================
   The tangent (a bordered solve, QR at folds) and the Moore-Penrose corrector; a caller
   watches a corrector run through psb__corr_watch, never through solver fields. */

/* psb__tangent's work once dH(y) is formed (psb__jacobian). Also sets tangent_sign, the
   outward sign sgn det [dH; (W t)^T] of the t returned (0 where the factors do not tell it):
   x solves [dH; row^T] x = e_(n+1), so row.x = 1 > 0 and det [dH; (W x)^T] has det B's sign. */
static psb_result psb__tangent_from_jacobian(psb_solver *s, const double *ref, double *t)
{
    int np1 = s->internal_.np1, i, attempt, sign = 0;
    double rcond = 0, *row = s->internal_.rhs + np1, *x = s->internal_.rhs;
    psb_result r;
    s->internal_.tangent_sign = 0;
    /* bordered with ref; if that is singular (ref orthogonal to the kernel), the dense backend
       asks QR of dH^T, the others border with e_param, then with a fixed generic row */
    for (attempt = 0; attempt < 3; attempt++) {
        for (i = 0; i < np1; i++)
            row[i] = s->internal_.w[i] * (attempt == 0 ? ref[i]
                                 : attempt == 1 ? (double)(i == s->prob.param_index)
                                                : 1.0 + 0.1 * (i % 7));
        r = psb__factor_bordered(s, row, &rcond);
        if (r == PSB_SUCCESS && rcond > 1.4901161193847656e-08) {
            memset(x, 0, (size_t)np1 * sizeof *x);
            x[np1 - 1] = 1;
            r = psb__solve_factored(s, x, 1);
            if (r == PSB_SUCCESS) {
                sign = psb__factors_det(s, NULL);
                break;
            }
        }
        if (r != PSB_SUCCESS && r != PSB_ERR_SINGULAR) return r;
        if (s->prob.linear == PSB_LINEAR_DENSE) {
            r = psb__kernel_qr(s, x);
            if (r != PSB_SUCCESS) return r;
            break;
        }
    }
    if (r != PSB_SUCCESS) return r;
    if (psb__dot_w(s, x, ref) < 0) {
        for (i = 0; i < np1; i++) x[i] = -x[i];
        sign = -sign;
    }
    if (!psb__normalize_w(s, x)) {
        s->internal_.last_fail = PSB__FAIL_SINGULAR;
        return psb__fail(s, PSB_ERR_SINGULAR, "tangent vanished");
    }
    psb__copy(t, x, np1);
    s->internal_.tangent_sign = sign;
    s->internal_.n_ok++;
    return PSB_SUCCESS;
}

/* The unit tangent at y oriented by ref; difference steps (no Jacobian callback) at most
   fd_cap in the weighted norm when fd_cap > 0. */
static psb_result psb__tangent_capped(psb_solver *s, const double *y, const double *ref, double *t,
                                      double fd_cap)
{
    psb_result r;
    s->stats.n_tangents++;
    r = psb__jacobian_capped(s, y, NULL, fd_cap);
    if (r != PSB_SUCCESS) return r;
    return psb__tangent_from_jacobian(s, ref, t);
}

static psb_result psb__tangent(psb_solver *s, const double *y, const double *ref, double *t)
{
    return psb__tangent_capped(s, y, ref, t, 0);
}

static int psb__is_fatal(psb_result r)
{
    return r == PSB_ERR_CALLBACK || r == PSB_ERR_LAPACK || r == PSB_ERR_NULL ||
           r == PSB_ERR_NOMEM;
}

/* Whether Newton has reached what H's rounding allows though ||H|| > tol_residual: the last
   correction is below tol_correction (the point lies that close to the solution) and the
   residual no longer falls by half, i.e. it is rounding. tol_residual is absolute, and terms
   of size S carry rounding ~ eps S: past S ~ 1e5 the corrector could never converge, and
   traces ended at smooth points (an LCP scaled by 1e8: a wrong diagram, success reported). */
static int psb__at_rounding(const psb_solver *s, double corr, double res, double res_before)
{
    /* an overflowed residual is no rounding (inf >= inf / 2) */
    return corr <= s->opt.tol_correction && psb__finite(res) && res >= 0.5 * res_before;
}

/* What a caller watches in a corrector run beyond convergence (Algorithm 2.2's trials watch
   for a known outcome and for pieces that are not cones about their point). The corrector
   calls fn at each event with the couple named there; fn returns 0 to go on, 1 when the run
   can end because its outcome is known (at ITERATE, JACOBIAN and TANGENT: last_fail KNOWN; at
   REJECTED: psb__try_step_from tries no smaller step), or a result code < 0 that ends it. */
typedef enum psb__corr_event {
    PSB__CORR_STEP,      /* psb__try_step_from begins a trial step */
    PSB__CORR_START,     /* the run begins: H at its start is in res */
    PSB__CORR_ITERATE,   /* an iterate (y, t), before dH(y) is formed */
    PSB__CORR_JACOBIAN,  /* dH(y) formed at the iterate (y, t), H(y) in res */
    PSB__CORR_SOLVED,    /* the iteration's bordered system solved; y still the iterate */
    PSB__CORR_TANGENT,   /* the next iterate (y, t), t normalised; sign: det of the B factored */
    PSB__CORR_CORRECTED, /* before H at that iterate is evaluated (only < 0 counts) */
    PSB__CORR_REJECTED   /* psb__try_step_from rejected a trial step (last_fail says why) */
} psb__corr_event;
typedef struct psb__corr_watch psb__corr_watch;
struct psb__corr_watch {
    int (*fn)(psb__corr_watch *w, psb_solver *s, psb__corr_event e, const double *y,
              const double *t, int sign);
};

/* Moore-Penrose corrector on internal copies; (y, t) replaced only on convergence. reach > 0:
   the run gives up once an iterate lies farther than reach from y. watch (may be NULL) sees
   the run's events (psb__corr_watch). */
static psb_result psb__correct_run(psb_solver *s, double *y, double *t, double reach,
                                   psb__corr_watch *watch, int *iterations, double fd_cap)
{
    int n = s->internal_.n, np1 = s->internal_.np1, it, i;
    double *yc = PSB__VEC(s, PSB__V_Y), *tc = PSB__VEC(s, PSB__V_T), *row = s->internal_.work, corr_prev = 0, res_prev;
    psb_result r;
    psb__copy(yc, y, np1);
    psb__copy(tc, t, np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "zero tangent");
    r = psb__residual(s, yc, s->internal_.res);
    if (r != PSB_SUCCESS) return r;
    res_prev = psb__norm2(s->internal_.res, n);
    if (watch) watch->fn(watch, s, PSB__CORR_START, yc, tc, 0);
    for (it = 1; it <= s->opt.max_iter; it++) {
        double corr, res;
        int cut = 0, tc_sign;
        s->stats.n_newton++;
        if (watch) cut = watch->fn(watch, s, PSB__CORR_ITERATE, yc, tc, 0);
        if (cut == 0) {
            r = psb__jacobian_capped(s, yc, s->internal_.res, fd_cap);
            if (r != PSB_SUCCESS) return r;
            if (watch) cut = watch->fn(watch, s, PSB__CORR_JACOBIAN, yc, tc, 0);
        }
        if (cut < 0) return (psb_result)cut;
        if (cut) {
            *iterations = it;
            s->internal_.last_fail = PSB__FAIL_KNOWN;
            return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "trial's outcome known");
        }
        for (i = 0; i < np1; i++) row[i] = s->internal_.w[i] * tc[i];
        r = psb__factor_bordered(s, row, NULL);
        if (r != PSB_SUCCESS) return r;
        /* two right-hand sides, one factorisation: [H(y); 0] and [0; 1] */
        memcpy(s->internal_.rhs, s->internal_.res, (size_t)n * sizeof(double));
        s->internal_.rhs[n] = 0;
        memset(s->internal_.rhs + np1, 0, (size_t)np1 * sizeof(double));
        s->internal_.rhs[np1 + n] = 1;
        r = psb__solve_factored(s, s->internal_.rhs, 2);
        if (r != PSB_SUCCESS) return r;
        tc_sign = psb__factors_det(s, NULL); /* row.tc = 1: det [dH; (W tc)^T] has det B's sign */
        if (watch) watch->fn(watch, s, PSB__CORR_SOLVED, yc, tc, tc_sign);
        for (i = 0; i < np1; i++) yc[i] -= s->internal_.rhs[i];
        psb__copy(tc, s->internal_.rhs + np1, np1);
        if (reach > 0) {
            double away = psb__dist_w(s, yc, y);
            /* a non-finite iterate goes on to the fault checks below */
            if (away > reach && psb__finite(away)) {
                *iterations = it;
                s->internal_.last_fail = PSB__FAIL_CONVERGE;
                return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "corrector iterate left the step's reach");
            }
        }
        if (!psb__normalize_w(s, tc)) {
            s->internal_.last_fail = PSB__FAIL_SINGULAR;
            return psb__fail(s, PSB_ERR_SINGULAR, "corrector tangent vanished");
        }
        *iterations = it;
        if (watch && watch->fn(watch, s, PSB__CORR_TANGENT, yc, tc, tc_sign)) {
            s->internal_.last_fail = PSB__FAIL_KNOWN;
            return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "trial's outcome known");
        }
        corr = psb__norm_w(s, s->internal_.rhs);
        if (watch) {
            int w = watch->fn(watch, s, PSB__CORR_CORRECTED, yc, tc, 0);
            if (w < 0) return (psb_result)w;
        }
        r = psb__residual(s, yc, s->internal_.res);
        if (r != PSB_SUCCESS) return r;
        res = psb__norm2(s->internal_.res, n);
        if ((res <= s->opt.tol_residual &&
             (corr <= s->opt.tol_correction ||
              (it > 1 && corr <= 0.5 * corr_prev && corr * corr <= (corr_prev - corr) * s->opt.tol_correction))) ||
            psb__at_rounding(s, corr, res, res_prev)) {
            /* a residual that vanishes at an overflowed iterate (steps of ~1e300) is no
               solution */
            if (!psb__all_finite(yc, np1)) return psb__fail(s, PSB_ERR_NONFINITE, "corrector iterate overflowed");
            psb__copy(y, yc, np1);
            psb__copy(t, tc, np1);
            return PSB_SUCCESS;
        }
        corr_prev = corr;
        res_prev = res;
    }
    s->internal_.last_fail = PSB__FAIL_CONVERGE;
    return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "corrector did not converge in max_iter iterations");
}

/* The corrector; *iterations (may be NULL) gets the iterations spent, also on failure. A
   singular bordered matrix is geometry when dH has a tangent where it happened (the curve
   turned across the bordering row: last_fail TURN), a fault when it has none (rank < N, or a
   solver.factor that fails with any row: last_fail SINGULAR); the extra tangent costs a
   factorisation only on that failure. With differences it is never a fault (FD_RANK); fd_cap
   > 0 bounds their steps (psb__fd_step). */
static psb_result psb__correct_capped(psb_solver *s, double *y, double *t, double reach,
                                      psb__corr_watch *watch, int *iterations, double fd_cap)
{
    int its = 0;
    psb_result r = psb__correct_run(s, y, t, reach, watch, &its, fd_cap), rt;
    if (iterations) *iterations = its;
    if (r == PSB_SUCCESS) s->internal_.n_ok++;
    if (r != PSB_ERR_SINGULAR) return r;
    if (psb__fd_jacobian(&s->prob)) { /* either way no fault (FD_RANK): spare the test */
        s->internal_.last_fail = PSB__FAIL_FD_RANK;
        s->internal_.faults[3]++;
        return r;
    }
    rt = psb__tangent(s, PSB__VEC(s, PSB__V_Y), PSB__VEC(s, PSB__V_T), s->internal_.rhs);
    if (rt == PSB_SUCCESS) {
        s->internal_.last_fail = PSB__FAIL_TURN;
        return psb__fail(s, PSB_ERR_SINGULAR, "bordered matrix singular: the tangent turned across the bordering row");
    }
    if (rt == PSB_ERR_SINGULAR) s->internal_.last_fail = PSB__FAIL_SINGULAR;
    return rt;
}

static psb_result psb__correct(psb_solver *s, double *y, double *t, double reach,
                               psb__corr_watch *watch, int *iterations)
{
    return psb__correct_capped(s, y, t, reach, watch, iterations, 0);
}

/* Whether psb__correct's failure r was a fault (psb__is_fault, its SINGULAR told apart). */
static int psb__correct_fault(const psb_solver *s, psb_result r)
{
    return psb__is_fault(r) && s->internal_.last_fail != PSB__FAIL_TURN && s->internal_.last_fail != PSB__FAIL_FD_RANK;
}

/* Whether y1 lies on the line through y0 along t (|cosine| >= c_diff), at most dmax away. */
static int psb__on_ray(psb_solver *s, const double *y0, const double *y1, const double *t,
                       double dmax)
{
    double *d = PSB__VEC(s, PSB__V_FD), dn;
    int i;
    for (i = 0; i < s->internal_.np1; i++) d[i] = y1[i] - y0[i];
    dn = psb__norm_w(s, d);
    return dn > 0 && dn <= dmax && fabs(psb__dot_w(s, d, t)) >= s->opt.c_diff * dn * psb__norm_w(s, t);
}

/* Trial steps from (y, t) starting at *h and shrinking by h_dec down to h_floor; on success
   (y, t) is the new couple, *h the accepted step and *iters the corrector's iterations.
   ray_from (Algorithm 2.2's trials, else NULL): a converged point that fails the jump or the
   cosine test is accepted all the same when it lies, within 8 steps of ray_from, on the line
   through ray_from along its own tangent (|cosine| >= c_diff): a point of a branch leaving
   ray_from, wherever the corrector found it. watch (may be NULL) sees each corrector run
   and each rejection (psb__corr_watch). */
static psb_result psb__try_step_from(psb_solver *s, double *y, double *t, double *h,
                                    double h_floor, int *iters, const double *ray_from,
                                    psb__corr_watch *watch)
{
    int np1 = s->internal_.np1;
    double *yt = PSB__VEC(s, PSB__V_STEP_Y), *tt = PSB__VEC(s, PSB__V_STEP_T), hh = *h;
    psb_result fault = PSB_SUCCESS; /* the first fault among the failed trials */
    s->internal_.last_fail = PSB__FAIL_NONE;
    while (hh >= h_floor) {
        psb_result r;
        psb__axpy_to(yt, y, hh, t, np1);
        psb__copy(tt, t, np1);
        s->stats.n_pc_steps++;
        if (watch) watch->fn(watch, s, PSB__CORR_STEP, yt, tt, 0);
        /* a step is accepted within hh of its prediction: an iterate 4 hh away is lost (at
           a kink the corrector hops between pieces' far kernels until max_iter). Not for
           Algorithm 2.2's trials, which accept a landing anywhere on a ray from ray_from */
        r = psb__correct(s, yt, tt, ray_from ? 0 : 4 * hh, watch, iters);
        if (psb__is_fatal(r)) return r;
        if (r == PSB_SUCCESS) {
            /* a corrector that travelled farther than the step jumped to another part of the
               curve (a parallel piece, another loop): the tangent test cannot see that */
            double jump = 0;
            int i;
            for (i = 0; i < np1; i++) {
                double d = yt[i] - y[i] - hh * t[i];
                jump += s->internal_.w[i] * d * d;
            }
            if ((sqrt(jump) <= hh && psb__cos_w(s, tt, t) >= s->opt.c_min) ||
                (ray_from && psb__on_ray(s, ray_from, yt, tt, 8 * hh))) {
                psb__copy(y, yt, np1);
                psb__copy(t, tt, np1);
                *h = hh;
                return PSB_SUCCESS;
            }
            s->internal_.last_fail = PSB__FAIL_COSINE;
        } else if (fault == PSB_SUCCESS && psb__correct_fault(s, r)) {
            fault = r;
        }
        s->stats.n_rejected++;
        /* a cut trial: a smaller step is the same trial scaled down */
        if (s->internal_.last_fail == PSB__FAIL_KNOWN) return PSB_ERR_NO_CONVERGENCE;
        /* so is one that the watch knows smaller steps repeat */
        if (watch && watch->fn(watch, s, PSB__CORR_REJECTED, yt, tt, 0))
            return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "trial step failed on pieces conic about "
                                                         "the point: smaller steps repeat it");
        hh *= s->opt.h_dec;
    }
    /* a trial that failed because of a fault might have converged: the steps did not run out
       because of the curve */
    switch (fault) {
    case PSB_ERR_NONFINITE: return psb__fail(s, fault, "NaN or Inf at a trial step, and no smaller step converged");
    case PSB_ERR_CALLBACK_FAILED: return psb__fail(s, fault, "a callback failed at a trial step, and no smaller step converged");
    case PSB_ERR_SINGULAR: return psb__fail(s, fault, "singular Jacobian (no tangent) at a trial step, and no smaller step converged");
    default: return psb__fail(s, PSB_ERR_STEP_TOO_SMALL, "no trial step converged down to h_min");
    }
}

static psb_result psb__try_step(psb_solver *s, double *y, double *t, double *h, double h_floor,
                                int *iters)
{
    return psb__try_step_from(s, y, t, h, h_floor, iters, NULL, NULL);
}

/* Whether s is an initialised solver (not freed). A non-NULL s that is not gets the message
   "solver not initialised". */
static int psb__ready(psb_solver *s)
{
    if (!s) return 0;
    if (s->internal_.ready == PSB__READY && s->internal_.vec) return 1;
    psb__fail(s, PSB_ERR_NULL, "solver not initialised (or freed)");
    return 0;
}

static psb_result psb__check_couple(psb_solver *s, const void *y, const void *t)
{
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (!y || !t) return psb__fail(s, PSB_ERR_NULL, "y or t is NULL");
    if (!psb__all_finite((const double *)y, s->internal_.np1) || !psb__all_finite((const double *)t, s->internal_.np1))
        return psb__fail(s, PSB_ERR_NONFINITE, "y or t contains NaN or Inf");
    {
        double nt = psb__norm_w(s, (const double *)t);
        if (!(nt > 0)) return psb__fail(s, PSB_ERR_INPUT, "t is zero");
        if (!psb__finite(nt)) return psb__fail(s, PSB_ERR_INPUT, "t's weighted norm overflows");
    }
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_solve_at_param(psb_solver *s, double *y, int max_iter)
{
    int n, np1, it, i, k;
    double *yc, *yt, *row, res;
    psb_result r;
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (!y) return psb__fail(s, PSB_ERR_NULL, "y is NULL");
    if (!psb__all_finite(y, s->internal_.np1)) return psb__fail(s, PSB_ERR_NONFINITE, "y contains NaN or Inf");
    if (max_iter > PSB_MAX_ITER_LIMIT) return psb__fail(s, PSB_ERR_INPUT, "max_iter > PSB_MAX_ITER_LIMIT");
    n = s->internal_.n;
    np1 = s->internal_.np1;
    if (max_iter <= 0) max_iter = 50;
    yc = PSB__VEC(s, PSB__V_Y);
    yt = PSB__VEC(s, PSB__V_T);
    row = PSB__VEC(s, PSB__V_REF);
    memset(row, 0, (size_t)np1 * sizeof *row);
    row[s->prob.param_index] = 1;
    psb__copy(yc, y, np1);
    r = psb__residual(s, yc, s->internal_.res);
    if (r != PSB_SUCCESS) return r;
    res = psb__norm2(s->internal_.res, n);
    for (it = 1; it <= max_iter; it++) {
        double corr, lambda = 1, res_before = res;
        s->stats.n_newton++;
        r = psb__jacobian(s, yc, s->internal_.res);
        if (r != PSB_SUCCESS) return r;
        r = psb__factor_bordered(s, row, NULL);
        if (r != PSB_SUCCESS) return r;
        memcpy(s->internal_.rhs, s->internal_.res, (size_t)n * sizeof(double));
        s->internal_.rhs[n] = 0;
        r = psb__solve_factored(s, s->internal_.rhs, 1);
        if (r != PSB_SUCCESS) return r;
        /* zero in exact arithmetic (the border row is e_param, its right-hand side 0): an
           iterative user solver's round-off must not move the parameter off its value */
        s->internal_.rhs[s->prob.param_index] = 0;
        corr = psb__norm_w(s, s->internal_.rhs);
        /* backtracking on ||H||: full steps when they reduce it, which is the usual case */
        for (k = 0; k < 12; k++, lambda *= 0.5) {
            double trial;
            for (i = 0; i < np1; i++) yt[i] = yc[i] - lambda * s->internal_.rhs[i];
            r = psb__residual(s, yt, s->internal_.res2);
            if (psb__is_fatal(r)) return r;
            if (r != PSB_SUCCESS) continue;
            trial = psb__norm2(s->internal_.res2, n);
            if (trial <= (1 - 1e-4 * lambda) * res || k == 11) {
                res = trial;
                break;
            }
        }
        if (r != PSB_SUCCESS) return r;
        psb__copy(yc, yt, np1);
        memcpy(s->internal_.res, s->internal_.res2, (size_t)n * sizeof(double));
        if ((res <= s->opt.tol_residual || psb__at_rounding(s, lambda * corr, res, res_before)) &&
            lambda * corr <= s->opt.tol_correction) {
            if (!psb__all_finite(yc, np1)) return psb__fail(s, PSB_ERR_NONFINITE, "Newton iterate overflowed");
            psb__copy(y, yc, np1);
            return PSB_SUCCESS;
        }
    }
    return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "Newton at fixed parameter did not converge");
}

PSCBRANCH_DEF psb_result psb_tangent(psb_solver *s, const double *y, const double *ref, double *t)
{
    double *r0;
    psb_result r;
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (!y || !t) return psb__fail(s, PSB_ERR_NULL, "y or t is NULL");
    if (!psb__all_finite(y, s->internal_.np1) || (ref && !psb__all_finite(ref, s->internal_.np1)))
        return psb__fail(s, PSB_ERR_NONFINITE, "y or ref contains NaN or Inf");
    r0 = PSB__VEC(s, PSB__V_REF);
    if (ref) {
        if (!(psb__norm_w(s, ref) > 0)) return psb__fail(s, PSB_ERR_INPUT, "ref is zero");
        psb__copy(r0, ref, s->internal_.np1);
    } else {
        memset(r0, 0, (size_t)s->internal_.np1 * sizeof *r0);
        r0[s->prob.param_index] = 1;
    }
    r = psb__tangent(s, y, r0, PSB__VEC(s, PSB__V_T));
    if (r == PSB_SUCCESS) psb__copy(t, PSB__VEC(s, PSB__V_T), s->internal_.np1);
    return r;
}

PSCBRANCH_DEF psb_result psb_correct(psb_solver *s, double *y, double *t, int *iterations)
{
    psb_result r = psb__check_couple(s, y, t);
    if (r != PSB_SUCCESS) return r;
    return psb__correct(s, y, t, 0, NULL, iterations);
}

/* ==== Trace and its detectors ===================================================================
   psb_step, the tangent switch, kinks, folds, bounds, the special-point detectors
   (psb__detector, the trace's own state) and psb_trace, the driver. */

/* Step size for the next step after a step of size h that took iters corrector iterations. */
static double psb__adapt(const psb_solver *s, double h, int iters)
{
    if (iters < s->opt.iter_threshold) h *= s->opt.h_inc;
    return h < s->opt.h_max ? h : s->opt.h_max;
}

PSCBRANCH_DEF psb_result psb_step(psb_solver *s, double *y, double *t, double *h)
{
    int iters = 0;
    double hh, *yc, *tc;
    psb_result r = psb__check_couple(s, y, t);
    if (r != PSB_SUCCESS) return r;
    if (!h) return psb__fail(s, PSB_ERR_NULL, "h is NULL");
    if (!(*h > 0) || !psb__finite(*h)) return psb__fail(s, PSB_ERR_INPUT, "step size must be positive");
    hh = *h < s->opt.h_max ? *h : s->opt.h_max;
    /* on copies: the caller's couple and h stay as they were unless a step is accepted */
    yc = PSB__VEC(s, PSB__V_IO_Y);
    tc = PSB__VEC(s, PSB__V_IO_T);
    psb__copy(yc, y, s->internal_.np1);
    psb__copy(tc, t, s->internal_.np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "t is zero");
    psb__faults_reset(s);
    r = psb__try_step(s, yc, tc, &hh, s->opt.h_min, &iters);
    /* no trial converged and difference Jacobians were singular: a fault when dH(y) has no
       tangent either (rank < N), the curve's when it has (a kink turned the trials across the
       bordering row, as psb__correct tells apart with an analytic Jacobian) */
    if (r == PSB_ERR_STEP_TOO_SMALL && s->internal_.n_ok == 0 && s->internal_.faults[3] > 0) {
        psb_result rt = psb__tangent(s, y, t, tc);
        if (rt == PSB_ERR_SINGULAR) return psb__faults_code(s, "psb_step");
        if (psb__is_fatal(rt)) return rt;
        return psb__fail(s, r, "no trial step converged down to h_min");
    }
    if (r != PSB_SUCCESS) return r;
    psb__copy(y, yc, s->internal_.np1);
    psb__copy(t, tc, s->internal_.np1);
    *h = psb__adapt(s, hh, iters);
    return r;
}

/* Tries steps from y along +dir then -dir; accepts the first couple that does not go back
   along t (or t_before). Returns PSB_SUCCESS with (y, t) replaced, PSB_NONSMOOTH_END, or a
   fatal code. */
static psb_result psb__switch_try(psb_solver *s, double *y, double *t, const double *t_before,
                                  const double *dir, double h_floor)
{
    int np1 = s->internal_.np1, sign, iters, i;
    double *yd = PSB__VEC(s, PSB__V_SW_Y), *td = PSB__VEC(s, PSB__V_SW_T), h;
    psb_result r;
    for (sign = 1; sign >= -1; sign -= 2) {
        psb__copy(yd, y, np1);
        for (i = 0; i < np1; i++) td[i] = sign * dir[i];
        h = s->opt.h_init;
        r = psb__try_step(s, yd, td, &h, h_floor, &iters);
        if (psb__is_fatal(r)) return r;
        if (r != PSB_SUCCESS) {
            psb__note_fault(s, r);
            continue;
        }
        /* going back along the incoming branch is no continuation */
        if (-psb__cos_w(s, td, t) >= s->opt.c_diff) continue;
        if (t_before && -psb__cos_w(s, td, t_before) >= s->opt.c_diff) continue;
        psb__copy(y, yd, np1);
        psb__copy(t, td, np1);
        s->stats.n_switches++;
        return PSB_SUCCESS;
    }
    return PSB_NONSMOOTH_END;
}

/* Whether the switch tries dir: not when it is, to rounding, a direction (either sign) it tried
   among the last PSB__SW_RING of this pass (*n_tried counts them). In a piece every probe's
   tangent is the same, and a try from y along it with a floor at least that try's (the floors
   only grow within a pass) ends as that try did, and at a cluster of kinks the probes meet the
   same direction many times, each try halving h from h_init to h_min; most repeats fall
   within the last 8. */
static int psb__switch_fresh(psb_solver *s, const double *dir, int *n_tried)
{
    int k, n = *n_tried < PSB__SW_RING ? *n_tried : PSB__SW_RING;
    for (k = 0; k < n; k++)
        if (fabs(psb__cos_w(s, dir, PSB__VEC(s, PSB__V_SW_L + k))) >= 1 - 1e-9) return 0;
    psb__copy(PSB__VEC(s, PSB__V_SW_L + *n_tried % PSB__SW_RING), dir, s->internal_.np1);
    ++*n_tried;
    return 1;
}

/* One pass of the tangent switch: directions whose cosine with t lies in [c_done, c_sw)
   (|cosine| in the sweep; c_done: -2, or the c_sw of a pass before, whose directions were
   tried there and failed the same way). PSB_SUCCESS, PSB_NONSMOOTH_END (faults noted), or a
   fatal code. */
static psb_result psb__switch_pass(psb_solver *s, double *y, double *t, const double *t_before,
                                   double c_done, double c_sw)
{
    int np1 = s->internal_.np1, i, k, pass, n_tried = 0;
    double *dir = PSB__VEC(s, PSB__V_SW_D), *probe = PSB__VEC(s, PSB__V_SW_P);
    double *t1 = PSB__VEC(s, PSB__V_SW_A), *q = PSB__VEC(s, PSB__V_SW_B), delta;
    psb_result r;
    /* the simple tangent switch: probe straight ahead */
    for (delta = s->opt.switch_delta_min; delta <= s->opt.switch_delta_max; delta *= 2) {
        psb__axpy_to(probe, y, delta, t, np1);
        r = psb__tangent(s, probe, t, dir);
        if (psb__is_fatal(r)) return r;
        psb__note_fault(s, r);
        if (r != PSB_SUCCESS || psb__cos_w(s, dir, t) >= c_sw || psb__cos_w(s, dir, t) < c_done) continue;
        if (!psb__switch_fresh(s, dir, &n_tried)) continue;
        r = psb__switch_try(s, y, t, t_before, dir, s->opt.h_min);
        if (r != PSB_NONSMOOTH_END) return r;
    }
    /* Nothing straight ahead (the region there holds no branch, as at sharp turns): sweep the
       plane of -t and the tangent ahead, as Algorithm 2.2 does, at three probe distances. */
    if (!s->opt.switch_no_sweep) {
        for (k = 0; k < np1; k++) t1[k] = -t[k];
        for (pass = 1; pass <= 3; pass++) {
            delta = s->opt.switch_delta_min * pow(s->opt.switch_delta_max / s->opt.switch_delta_min, pass / 3.0);
            psb__axpy_to(probe, y, delta, t, np1);
            r = psb__tangent(s, probe, t, q);
            if (psb__is_fatal(r)) return r;
            psb__note_fault(s, r);
            if (r != PSB_SUCCESS) continue;
            {
                double c = psb__dot_w(s, t1, q);
                for (k = 0; k < np1; k++) q[k] -= c * t1[k];
                if (!psb__normalize_w(s, q)) continue;
            }
            for (i = 1; i < s->opt.switch_n_dir; i++) { /* i = 0 is straight ahead: done above */
                double alpha = 6.283185307179586 * i / s->opt.switch_n_dir;
                for (k = 0; k < np1; k++) dir[k] = sin(alpha) * t1[k] + cos(alpha) * q[k];
                psb__axpy_to(probe, y, delta, dir, np1);
                psb__copy(PSB__VEC(s, PSB__V_SW_C), dir, np1);
                r = psb__tangent(s, probe, PSB__VEC(s, PSB__V_SW_C), dir);
                if (psb__is_fatal(r)) return r;
                psb__note_fault(s, r);
                if (r != PSB_SUCCESS || fabs(psb__cos_w(s, dir, t)) >= c_sw || fabs(psb__cos_w(s, dir, t)) < c_done)
                    continue;
                if (!psb__switch_fresh(s, dir, &n_tried)) continue;
                /* steps much shorter than the probe distance see only the kink itself */
                r = psb__switch_try(s, y, t, t_before, dir, fmax(s->opt.h_min, delta / 64));
                if (r != PSB_NONSMOOTH_END) return r;
            }
        }
    }
    return PSB_NONSMOOTH_END;
}

/* t_before (may be NULL): the tangent before the previous kink when (y, t) was itself reached
   by a switch with no regular step since: a continuation that reverses it goes back too. */
static psb_result psb__switch(psb_solver *s, double *y, double *t, const double *t_before)
{
    psb_result r;
    psb__faults_reset(s);
    r = psb__switch_pass(s, y, t, t_before, -2, s->opt.c_diff);
    /* Steps fail at a kink whose turn is below acos(c_diff) too: where a thin wedge of other
       selections lies straight ahead, the corrector cycles between them. The probes' tangents
       then differ from t by less than c_diff, and the pass above tries none of them. Before
       calling the point an end, try every direction that differs from t at all (beyond the
       rounding of a tangent). */
    if (r == PSB_NONSMOOTH_END && s->opt.c_diff < 1 - 1e-12)
        r = psb__switch_pass(s, y, t, t_before, s->opt.c_diff, 1 - 1e-12);
    if (r != PSB_NONSMOOTH_END) return r;
    /* nothing found: an end point only if no probe or trial failed because of a fault */
    r = psb__faults_code(s, "tangent switch");
    if (r != PSB_SUCCESS) return r;
    s->message[0] = 0;
    return PSB_NONSMOOTH_END;
}

PSCBRANCH_DEF psb_result psb_switch_tangent(psb_solver *s, double *y, double *t)
{
    double *yc, *tc;
    psb_result r = psb__check_couple(s, y, t);
    if (r != PSB_SUCCESS) return r;
    /* on copies: the caller's couple stays as it was unless the switch succeeds */
    yc = PSB__VEC(s, PSB__V_IO_Y);
    tc = PSB__VEC(s, PSB__V_IO_T);
    psb__copy(yc, y, s->internal_.np1);
    psb__copy(tc, t, s->internal_.np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "t is zero");
    r = psb__switch(s, yc, tc, NULL);
    if (r != PSB_SUCCESS) return r;
    psb__copy(y, yc, s->internal_.np1);
    psb__copy(t, tc, s->internal_.np1);
    return r;
}

/* Parameter value of the limit point between two couples whose tangents' parameter components
   have opposite signs: extremum of the cubic Hermite interpolant in the (weighted) chord
   length, whose derivatives at the ends are the tangents' parameter components. */
static double psb__fold_param(const psb_solver *s, const double *y0, const double *t0,
                              const double *y1, const double *t1)
{
    int p = s->prob.param_index, i;
    double len = psb__dist_w(s, y0, y1), g0 = y0[p], g1 = y1[p], m0, m1, a, b, c, roots[2], best = g0;
    int nroots = 0;
    m0 = t0[p] * len;
    m1 = t1[p] * len;
    /* g(x) = (2x^3-3x^2+1) g0 + (x^3-2x^2+x) m0 + (-2x^3+3x^2) g1 + (x^3-x^2) m1, x in [0,1];
       g'(x) = a x^2 + b x + c */
    a = 6 * g0 + 3 * m0 - 6 * g1 + 3 * m1;
    b = -6 * g0 - 4 * m0 + 6 * g1 - 2 * m1;
    c = m0;
    if (fabs(a) > 1e-14 * (fabs(b) + fabs(c))) {
        double disc = b * b - 4 * a * c;
        if (disc >= 0) {
            double q = -0.5 * (b + (b >= 0 ? sqrt(disc) : -sqrt(disc)));
            roots[nroots++] = q / a;
            if (q != 0) roots[nroots++] = c / q;
        }
    } else if (b != 0) {
        roots[nroots++] = -c / b;
    }
    for (i = 0; i < nroots; i++) {
        double x = roots[i];
        if (x >= 0 && x <= 1) {
            double x2 = x * x, x3 = x2 * x;
            best = (2 * x3 - 3 * x2 + 1) * g0 + (x3 - 2 * x2 + x) * m0 + (-2 * x3 + 3 * x2) * g1 +
                   (x3 - x2) * m1;
            break;
        }
    }
    return best;
}

static double psb__angle_w(const psb_solver *s, const double *a, const double *b)
{
    double c = psb__cos_w(s, a, b);
    return acos(c > 1 ? 1 : (c < -1 ? -1 : c));
}

/* After an accepted step of size h from (y0, t0) to a couple with tangent t1: decides whether a
   kink was crossed and, if so, leaves in K_YA/K_TA the last couple before it, within h_min.
   A smooth turn shrinks with the step (the half step turns by about half the angle); a kink
   does not, so the half step tells them apart and bisection on the same test locates it.
   expect: the turn the step would have at the curve's last known rate (-1: unknown).
   Returns 1 (kink located), 0 (smooth), or a fatal failure code. */
static int psb__locate_kink_in(psb_solver *s, const double *y0, const double *t0, const double *t1,
                               double h, double expect)
{
    int np1 = s->internal_.np1, iters;
    double *ya = PSB__VEC(s, PSB__V_K_YA), *ta = PSB__VEC(s, PSB__V_K_TA);
    double *yt = PSB__VEC(s, PSB__V_K_Y), *tt = PSB__VEC(s, PSB__V_K_T);
    double theta = psb__angle_w(s, t0, t1), hs = 0.5 * h, trial, half_theta;
    psb_result r;
    if (psb__cos_w(s, t0, t1) >= s->opt.c_diff) return 0;
    psb__copy(ya, y0, np1);
    psb__copy(ta, t0, np1);
    psb__copy(yt, y0, np1);
    psb__copy(tt, t0, np1);
    trial = hs;
    r = psb__try_step(s, yt, tt, &trial, hs, &iters);
    if (r != PSB_SUCCESS && !psb__is_fatal(r) && s->prob.linear == PSB_LINEAR_USER) {
        /* a failed half step says "kink": once more, as a user solver's passing failure
           (PSB_ERR_SINGULAR, as a turn of the corrector) would call a smooth fold a kink */
        psb__copy(yt, y0, np1);
        psb__copy(tt, t0, np1);
        trial = hs;
        r = psb__try_step(s, yt, tt, &trial, hs, &iters);
    }
    if (psb__is_fatal(r) || psb__is_fault(r)) return r; /* a fault leaves the kink unlocated */
    if (r == PSB_SUCCESS) {
        half_theta = psb__angle_w(s, t0, tt);
        if (half_theta >= 0.25 * theta && half_theta <= 0.75 * theta) {
            /* Two kinks, one in each half, give the half step their middle piece's tangent
               (theta / 2 for equal angles) and would go by unseen. A smooth turn grows strictly along the step, so
               the tangents after a quarter and three quarters of it lie apart from their
               neighbours (t0, the half step's, t1), by theta / 16 or more for turns growing
               like any power s^q of the length with the half step's turn in the band (q in
               [0.42, 2]); two kinks leave one of them on a piece next to it (within theta / 32:
               exact on piecewise-linear H). Then the first point where the turn reaches
               theta / 4 is located from y0. Skipped where the turn is within a factor 2 of
               expect (> 0), the trace's last smooth step's turn per length times h: a curve
               turning at the rate it did, which the half step already told smooth. */
            double frac;
            int flat = 0;
            if (expect > 0 && theta >= 0.5 * expect && theta <= 2 * expect) return 0;
            for (frac = 0.25; frac < 1 && !flat; frac += 0.5) {
                psb__copy(ya, y0, np1);
                psb__copy(ta, t0, np1);
                trial = frac * h;
                r = psb__try_step(s, ya, ta, &trial, trial, &iters);
                if (psb__is_fatal(r) || psb__is_fault(r)) return r;
                if (r != PSB_SUCCESS) return 0;
                flat = fmin(psb__angle_w(s, ta, tt), psb__angle_w(s, ta, frac < 0.5 ? t0 : t1)) < theta / 32;
            }
            if (!flat) return 0;
            psb__copy(ya, y0, np1);
            psb__copy(ta, t0, np1);
            hs = h;
        } else if (half_theta < 0.25 * theta) { /* the kink lies in the second half */
            psb__copy(ya, yt, np1);
            psb__copy(ta, tt, np1);
        }
    } else {
        /* the half step may end next to a smooth branch point, where its corrector lands on
           the other branch (and is rejected): a smooth turn shows at 3/8 or 5/8 of the step */
        double frac;
        for (frac = 0.375; frac < 0.7; frac += 0.25) {
            psb__copy(yt, y0, np1);
            psb__copy(tt, t0, np1);
            trial = frac * h;
            r = psb__try_step(s, yt, tt, &trial, trial, &iters);
            if (psb__is_fatal(r) || psb__is_fault(r)) return r;
            half_theta = psb__angle_w(s, t0, tt);
            if (r == PSB_SUCCESS && half_theta >= 0.5 * frac * theta && half_theta <= 1.5 * frac * theta) return 0;
        }
    }
    /* the kink lies within hs of ya */
    while (hs >= s->opt.h_min) {
        double half = 0.5 * hs;
        psb__copy(yt, ya, np1);
        psb__copy(tt, ta, np1);
        trial = half;
        r = psb__try_step(s, yt, tt, &trial, half, &iters);
        if (psb__is_fatal(r) || psb__is_fault(r)) return r;
        if (r == PSB_SUCCESS && psb__angle_w(s, ta, tt) < 0.25 * theta) {
            psb__copy(ya, yt, np1);
            psb__copy(ta, tt, np1);
        }
        hs = half;
    }
    /* Confirmed across it: a kink turns a step of 2 h_min from ya by about theta, a smooth
       turn by theta 2 h_min / h. The half-step test alone calls a smooth turn a kink where
       the curvature grows from near 0 across the step (then the half step turns by 1/4 of
       the whole), and a located "kink" on a smooth branch stops a trace before nothing.
       Not with difference quotients: next to a kink they mix its pieces, the step's tangent
       is off by as much, and the test then passes kinks by */
    if (!psb__fd_jacobian(&s->prob)) {
        psb__copy(yt, ya, np1);
        psb__copy(tt, ta, np1);
        trial = 2 * s->opt.h_min;
        r = psb__try_step(s, yt, tt, &trial, trial, &iters);
        if (psb__is_fatal(r) || psb__is_fault(r)) return r;
        if (r == PSB_SUCCESS && psb__angle_w(s, ta, tt) < 0.25 * theta) return 0;
    }
    s->message[0] = 0;
    return 1;
}

/* psb__locate_kink_in for the first kink of the step: the one it locates is where the turn
   from t0 reaches a quarter of the whole, and where the tangent had turned by more than c_diff's
   angle before it, the stretch from y0 to it is searched again (a branching point just before
   an ordinary kink, in one step, would otherwise be passed for the far kink). The located couple is kept in the switch's scratch,
   idle here, while the stretch before it is searched. */
static int psb__locate_kink(psb_solver *s, const double *y0, const double *t0, const double *t1,
                            double h, double expect)
{
    int np1 = s->internal_.np1, found = psb__locate_kink_in(s, y0, t0, t1, h, expect), depth, inner;
    double *ya = PSB__VEC(s, PSB__V_K_YA), *ta = PSB__VEC(s, PSB__V_K_TA);
    double *sy = PSB__VEC(s, PSB__V_SW_A), *st = PSB__VEC(s, PSB__V_SW_B), d;
    for (depth = 0; found == 1 && depth < 8 && psb__cos_w(s, t0, ta) < s->opt.c_diff; depth++) {
        d = psb__dist_w(s, y0, ya);
        if (!(d > 4 * s->opt.h_min)) break;
        psb__copy(sy, ya, np1);
        psb__copy(st, ta, np1);
        inner = psb__locate_kink_in(s, y0, t0, st, d, -1);
        if (inner < 0) return inner;
        if (inner == 0) { /* a smooth turn before it */
            psb__copy(ya, sy, np1);
            psb__copy(ta, st, np1);
            break;
        }
    }
    return found;
}

/* Whether the fold within the step from (y0, t0) to (y1, t1) (t0[p] t1[p] < 0) may lie beyond the
   bound it turns towards. The Hermite estimate of the fold's parameter is off by up to a fraction
   of its rise above the step's ends, so the rise counts twice: a shorter step decides, and as
   steps shrink the rise falls like their square. */
static int psb__fold_beyond_bound(const psb_solver *s, const psb_trace_options *to, const double *y0,
                                  const double *t0, const double *y1, const double *t1)
{
    int p = s->prob.param_index;
    double fold = psb__fold_param(s, y0, t0, y1, t1);
    if (t0[p] > 0) return 2 * fold - fmax(y0[p], y1[p]) > to->param_max;
    return 2 * fold - fmin(y0[p], y1[p]) < to->param_min;
}

/* Solves for the point with y[param] = bound between y0 (inside) and y1 (outside), starting from
   the chord; on success y1 holds it. */
static psb_result psb__land_on_bound(psb_solver *s, const double *y0, double *y1, double bound)
{
    int p = s->prob.param_index, np1 = s->internal_.np1, i;
    double *yb = PSB__VEC(s, PSB__V_TR_B), frac = (bound - y0[p]) / (y1[p] - y0[p]);
    psb_result r;
    for (i = 0; i < np1; i++) yb[i] = y0[i] + frac * (y1[i] - y0[i]);
    yb[p] = bound;
    r = psb_solve_at_param(s, yb, s->opt.max_iter);
    if (r == PSB_SUCCESS) psb__copy(y1, yb, np1);
    return r;
}

/* ---- special points on the path (psb_trace_options.detect) -------------------------------- */


/* The branch-point test function at the current factors of B = [dH(y); row^T]. Dense and
   banded: sign and log|.| of det B from the LU factors, O(N) and exact in sign. User backend
   (factor/solve only): tau_k = 1 / (d_k - c_k^T B^{-1} b_k) = det B / det [B b_k; c_k^T d_k]
   for two random borders, one solve with two right-hand sides. A tau changes sign at the
   zeros of det B and at its own poles (where its bordered matrix is singular), and where a
   pole lies next to a zero it shows neither: a sign change of either tau is located and kept
   when |tau| shrank there (a zero), not grew (a pole). */
typedef struct psb__mon {
    double sign[2], logabs[2];
} psb__mon;

static psb_result psb__monitor(psb_solver *s, psb__mon *m)
{
    int np1 = s->internal_.np1, i, k;
    double sign = 1, logabs = 0;
    psb_result r;
    if (s->prob.linear == PSB_LINEAR_DENSE) {
        sign = psb__factors_det(s, &logabs);
    } else if (s->prob.linear == PSB_LINEAR_BANDED) {
        /* factors of A + sigma I (A nearly singular) would move a zero of det B by ~sigma: A
           is factored as it is (exactly singular: det B = 0) */
        if (s->internal_.shifted) {
            r = psb__band_prepare(s, 0.0);
            s->internal_.shifted = 0;
            if (r == PSB_ERR_SINGULAR) {
                s->internal_.border_ok = s->internal_.bv_ok = 0; /* no usable factors: the next solve refactors */
                m->sign[0] = m->sign[1] = 1;
                m->logabs[0] = m->logabs[1] = -700;
                return PSB_SUCCESS;
            }
            if (r != PSB_SUCCESS) return r;
        }
        if (!s->internal_.border_ok) {
            r = psb__band_border(s, NULL);
            if (r != PSB_SUCCESS) return r;
        }
        sign = psb__factors_det(s, &logabs);
    } else {
        double *x = s->internal_.rhs, q[2];
        int attempt;
        for (attempt = 0; attempt < 2; attempt++) { /* a user solver's failure may be passing */
            psb__copy(x, PSB__VEC(s, PSB__V_SP_B1), np1);
            psb__copy(x + np1, PSB__VEC(s, PSB__V_SP_B2), np1);
            r = psb__solve_factored(s, x, 2);
            if (r != PSB_ERR_SINGULAR) break;
        }
        if (r != PSB_SUCCESS) return r;
        if (!psb__all_finite(x, (size_t)(2 * np1)))
            return psb__fail(s, PSB_ERR_NONFINITE, "solver.solve gave NaN or Inf");
        for (k = 0; k < 2; k++) {
            const double *c = PSB__VEC(s, k ? PSB__V_SP_C2 : PSB__V_SP_C1);
            q[k] = s->internal_.sp_d[k];
            for (i = 0; i < np1; i++) q[k] -= c[i] * x[(size_t)k * (size_t)np1 + (size_t)i];
        }
        for (k = 0; k < 2; k++) {
            m->sign[k] = q[k] < 0 ? -1 : 1;
            m->logabs[k] = -log(fabs(q[k]));
            if (!psb__finite(m->logabs[k])) m->logabs[k] = m->logabs[k] > 0 ? 700 : -700;
        }
        return PSB_SUCCESS;
    }
    if (!psb__finite(logabs)) logabs = -700;
    m->sign[0] = m->sign[1] = sign;
    m->logabs[0] = m->logabs[1] = logabs;
    return PSB_SUCCESS;
}

/* Newton's method on H(y) = 0 plus one scalar equation, from the prediction in y (in/out,
   replaced only on convergence): dir != NULL, the plane <dir, y - base>_w = value (points of
   the curve by their pseudo-arclength from base); dir == NULL, the sphere ||y - base||_w =
   value. t (out, may be NULL): the unit tangent there, oriented along dir (or outwards), from
   the same factorisation as the last correction, whose factors stay for psb__monitor.
   Converged as the corrector, but on the last correction alone (<= tol_correction). */
/* How far y lies from psb__newton_on's constraint, ||.||_w: from the plane <dir, y - base>_w =
   value, or the sphere ||y - base||_w = value. A small last correction need not mean it holds
   (an inaccurate solve, e.g. the banded backend's shifted A). */
static double psb__newton_on_gap(const psb_solver *s, const double *y, const double *base,
                                 const double *dir, double value)
{
    double dot = 0;
    int i;
    if (!dir) return fabs(psb__dist_w(s, y, base) - value);
    for (i = 0; i < s->internal_.np1; i++) dot += s->internal_.w[i] * dir[i] * (y[i] - base[i]);
    return fabs(dot - value) / psb__norm_w(s, dir);
}

static psb_result psb__newton_on(psb_solver *s, double *y, double *t, const double *base,
                                 const double *dir, double value)
{
    int n = s->internal_.n, np1 = s->internal_.np1, it, i;
    double *yc = PSB__VEC(s, PSB__V_Y), *row = s->internal_.work, res_prev;
    psb_result r;
    psb__copy(yc, y, np1);
    r = psb__residual(s, yc, s->internal_.res);
    if (r != PSB_SUCCESS) return r;
    res_prev = psb__norm2(s->internal_.res, n);
    for (it = 1; it <= s->opt.max_iter; it++) {
        double corr, res, g = 0;
        s->stats.n_newton++;
        r = psb__jacobian(s, yc, s->internal_.res);
        if (r != PSB_SUCCESS) return r;
        for (i = 0; i < np1; i++) {
            double d = yc[i] - base[i];
            row[i] = s->internal_.w[i] * (dir ? dir[i] : d);
            g += row[i] * (dir ? d : 0.5 * d);
        }
        g -= dir ? value : 0.5 * value * value;
        r = psb__factor_bordered(s, row, NULL);
        if (r != PSB_SUCCESS) return r;
        memcpy(s->internal_.rhs, s->internal_.res, (size_t)n * sizeof(double));
        s->internal_.rhs[n] = g;
        memset(s->internal_.rhs + np1, 0, (size_t)np1 * sizeof(double));
        s->internal_.rhs[np1 + n] = 1;
        r = psb__solve_factored(s, s->internal_.rhs, 2);
        if (r != PSB_SUCCESS) return r;
        for (i = 0; i < np1; i++) yc[i] -= s->internal_.rhs[i];
        corr = psb_norm_w(s, s->internal_.rhs);
        r = psb__residual(s, yc, s->internal_.res);
        if (r != PSB_SUCCESS) return r;
        res = psb__norm2(s->internal_.res, n);
        /* not on the contraction estimate: the tangent and the test function come from the
           factors at the iterate before the last correction, which must be as small as the
           location's precision */
        if ((res <= s->opt.tol_residual || psb__at_rounding(s, corr, res, res_prev)) &&
            corr <= s->opt.tol_correction && psb__newton_on_gap(s, yc, base, dir, value) <= s->opt.tol_correction) {
            if (!psb__all_finite(yc, np1)) return psb__fail(s, PSB_ERR_NONFINITE, "Newton iterate overflowed");
            if (t) {
                psb__copy(t, s->internal_.rhs + np1, np1);
                if (!psb__normalize_w(s, t)) {
                    s->internal_.last_fail = PSB__FAIL_SINGULAR;
                    return psb__fail(s, PSB_ERR_SINGULAR, "tangent vanished");
                }
            }
            psb__copy(y, yc, np1);
            return PSB_SUCCESS;
        }
        res_prev = res;
    }
    s->internal_.last_fail = PSB__FAIL_CONVERGE;
    return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "Newton on the constrained system did not converge");
}

/* The scalar whose sign change marks a special point, at a point (y, t) just computed by
   psb__newton_on: t[param] (folds), det B scaled by exp(-ref) (branch points), g_k(y)
   (events). */
typedef struct psb__sp_fn {
    psb_special_kind kind;
    int index;
    const psb_trace_options *to;
    double ref;
} psb__sp_fn;

/* A trace's on_point callback, marked as running (psb__trace_busy). */
static int psb__call_point(psb_solver *s, const psb_trace_options *to, const psb_point *p)
{
    int outer = s->internal_.in_trace_callback, rc;
    s->internal_.in_trace_callback = 1;
    rc = to->on_point(p, to->point_user);
    s->internal_.in_trace_callback = outer;
    return rc;
}

/* PSB_ERR_INPUT when called from a trace's callback: a trace (also inside psb_explore,
   psb_evolve_step, psb_branch_point_switch) would reuse the outer trace's scratch vectors */
static psb_result psb__trace_busy(psb_solver *s, const char *what)
{
    char buf[160];
    if (!s->internal_.in_trace_callback) return PSB_SUCCESS;
    snprintf(buf, sizeof buf, "%s called from a callback of a trace on the same solver (use another solver)", what);
    return psb__fail(s, PSB_ERR_INPUT, buf);
}

static psb_result psb__event_values(psb_solver *s, const psb_trace_options *to, const double *y,
                                    double *g)
{
    int outer = s->internal_.in_trace_callback, rc;
    psb_result r;
    s->internal_.in_trace_callback = 1;
    rc = to->event(y, g, to->event_user);
    s->internal_.in_trace_callback = outer;
    r = psb__callback_code(s, rc, "event callback returned nonzero");
    if (r != PSB_SUCCESS) return r;
    if (!psb__all_finite(g, (size_t)to->n_events))
        return psb__fail(s, PSB_ERR_NONFINITE, "event callback returned NaN or Inf");
    return PSB_SUCCESS;
}

/* Whether a detector's evaluation failed because of a fault it must not hide (a special point
   missed or mislocated while the trace succeeds): a callback's failure, NaN/Inf, anything
   fatal, and where the matrix is regular by geometry (`regular`: at accepted points and
   their re-evaluations, and anywhere but next to a branch point), the user solver's failure
   (PSB_ERR_SINGULAR, the user's way to report it). Next to a branch point a singular matrix
   is the geometry's: the detectors go on. */
static int psb__sp_fault(const psb_solver *s, psb_result r, int regular)
{
    return psb__is_fatal(r) || r == PSB_ERR_CALLBACK_FAILED || r == PSB_ERR_NONFINITE ||
           (regular && r == PSB_ERR_SINGULAR && s->prob.linear == PSB_LINEAR_USER);
}

static psb_result psb__sp_value(psb_solver *s, const psb__sp_fn *fn, const double *y,
                                const double *t, double *f)
{
    psb__mon m;
    psb_result r;
    switch (fn->kind) {
    case PSB_SPECIAL_FOLD: *f = t[s->prob.param_index]; return PSB_SUCCESS;
    case PSB_SPECIAL_EVENT: {
        double *g = fn->to->event_work + 2 * (size_t)fn->to->n_events;
        r = psb__event_values(s, fn->to, y, g);
        *f = g[fn->index];
        return r;
    }
    default:
        r = psb__monitor(s, &m);
        if (r != PSB_SUCCESS) return r;
        *f = m.sign[fn->index] * exp(fmin(fmax(m.logabs[fn->index] - fn->ref, -700.0), 700.0));
        return PSB_SUCCESS;
    }
}

/* Whether (ye, te), corrected on the plane at the fraction lambda of the bracket from (ya, ta)
   to (yb, tb), continues the curve the ends lie on, rather than another branch the plane cuts
   as well (near a branch point it cuts them all, and Newton may land on any). Along one
   smooth curve the point departs from the chord by at most its sagitta, w |ta - tb| / 8 for a
   bracket of length w, and the tangent from the ends' interpolate by O(w^2); a branch
   crossing at an angle phi has a tangent phi away, and its point departs by ~ phi times the
   distance to the crossing. Bounds: the tangent within c_min of both ends' (as a step's) and
   within |ta - tb| / 2 + 0.05 of the interpolate (the floor: a point within tol_correction of
   the curve at a distance d from a branch point has its tangent off by ~ tol_correction / d),
   the point within w (|ta - tb| / 2 + 0.05) + tol_correction of the chord. */
static int psb__on_bracket(const psb_solver *s, const double *ya, const double *ta, const double *yb,
                           const double *tb, double lambda, const double *ye, const double *te)
{
    double len = 0, turn = 0, off = 0, tdev = 0, bound;
    int i;
    for (i = 0; i < s->internal_.np1; i++) {
        double dy = yb[i] - ya[i], dt = tb[i] - ta[i];
        double ey = ye[i] - ya[i] - lambda * dy, et = te[i] - ta[i] - lambda * dt;
        len += s->internal_.w[i] * dy * dy;
        turn += s->internal_.w[i] * dt * dt;
        off += s->internal_.w[i] * ey * ey;
        tdev += s->internal_.w[i] * et * et;
    }
    bound = 0.5 * sqrt(turn) + 0.05;
    return psb__cos_w(s, te, ta) >= s->opt.c_min && psb__cos_w(s, te, tb) >= s->opt.c_min &&
           sqrt(tdev) <= bound && sqrt(off) <= sqrt(len) * bound + s->opt.tol_correction;
}

/* A point (ye, te) of the curve between the bracket's ends (sa, ya, ta) and (sb, yb, tb), by
   Newton on the plane s = *sm (s = <t0, y - y0>_w), accepted when psb__on_bracket holds.
   Predicted by the cubic Hermite interpolate of the ends (it lies on the plane, an error
   O(w^4): the secant's points close to a branch point, where the branches are close too,
   land on the traced one). When that fails, *sm moves halfway to the end far_b selects (the
   one farther from the zero: away from the other branches and from where the points, within
   tol_correction of the curve, have tangents off by tol_correction / distance), up to 12
   times (a singular matrix is geometry here: a user solver's is tried twice, as its failure
   may be passing). Returns PSB_SUCCESS, PSB_ERR_NO_CONVERGENCE (no point of the branch found),
   PSB_ERR_SINGULAR (none found, and the user solver refused a matrix on the way: the caller
   decides whether that can be geometry), a fault (callback > 0, NaN/Inf) or a fatal code. */
static psb_result psb__bracket_point(psb_solver *s, const double *y0, const double *t0, double sa,
                                     const double *ya, const double *ta, double sb, const double *yb,
                                     const double *tb, int far_b, double *sm, double *ye, double *te)
{
    int np1 = s->internal_.np1, k, i, user_singular = 0;
    double w = sb - sa, ca = psb_dot_w(s, t0, ta), cb = psb_dot_w(s, t0, tb);
    for (k = 0; k < 12; k++) {
        double l = (*sm - sa) / w, l2 = l * l, l3 = l2 * l, h00, h10, h01, h11;
        psb_result r;
        h00 = 2 * l3 - 3 * l2 + 1;
        h01 = 1 - h00;
        h10 = (l3 - 2 * l2 + l) * w / ca;
        h11 = (l3 - l2) * w / cb;
        for (i = 0; i < np1; i++) ye[i] = h00 * ya[i] + h10 * ta[i] + h01 * yb[i] + h11 * tb[i];
        r = psb__newton_on(s, ye, te, y0, t0, *sm);
        if (r == PSB_ERR_SINGULAR && s->prob.linear == PSB_LINEAR_USER) {
            /* a singular matrix stays singular; a user solver's passing failure does not */
            for (i = 0; i < np1; i++) ye[i] = h00 * ya[i] + h10 * ta[i] + h01 * yb[i] + h11 * tb[i];
            r = psb__newton_on(s, ye, te, y0, t0, *sm);
            if (r == PSB_ERR_SINGULAR) user_singular = 1;
        }
        if (psb__is_fatal(r) || r == PSB_ERR_CALLBACK_FAILED || r == PSB_ERR_NONFINITE) return r;
        if (r == PSB_SUCCESS && psb__on_bracket(s, ya, ta, yb, tb, l, ye, te)) return PSB_SUCCESS;
        *sm += 0.5 * ((far_b ? sb : sa) - *sm);
    }
    return user_singular ? PSB_ERR_SINGULAR : PSB_ERR_NO_CONVERGENCE;
}

/* Locates the sign change of fn between the accepted couples (y0, t0) and y1, on the curve
   parameterised by s = <t0, y - y0>_w: both ends are evaluated again on that
   parameterisation, then the bracket shrinks by the Illinois variant of regula falsi,
   bisecting whenever two evaluations did not halve it, until its ends are within tol of each
   other. Every point is one of the curve the ends lie on (psb__bracket_point), so the zero
   lies on the arc between them: the precision is their distance, a true bound (up to the
   arc's excess over its chord, O(w^3)). Leaves in SP_Y/SP_T the end with the smaller |f|
   (*fend_abs); f01_abs: |f| at the first two ends. Returns PSB_SUCCESS, PSB_NONSMOOTH_END (no
   sign change on re-evaluation: nothing to locate), or a failure; when no point of the curve
   is found inside, the bracket reached is kept. */
static psb_result psb__locate_change(psb_solver *s, psb__sp_fn *fn, const double *y0,
                                     const double *t0, const double *y1, double tol,
                                     double *precision, double *fend_abs, double *f01_abs)
{
    int np1 = s->internal_.np1, iter, side = 0, bisect = 0, evals = 0, found = 0, i;
    double *ya = PSB__VEC(s, PSB__V_SP_YA), *ta = PSB__VEC(s, PSB__V_SP_TA);
    double *yb = PSB__VEC(s, PSB__V_SP_YB), *tb = PSB__VEC(s, PSB__V_SP_TB);
    double *ye = PSB__VEC(s, PSB__V_SP_YE), *te = PSB__VEC(s, PSB__V_SP_TE);
    double sa = 0, sb = 0, fa, fb, ga, gb, width_before = 0;
    psb_result r;
    for (i = 0; i < np1; i++) sb += s->internal_.w[i] * t0[i] * (y1[i] - y0[i]);
    if (!(sb > 0)) return PSB_NONSMOOTH_END;
    psb__copy(ya, y0, np1);
    r = psb__newton_on(s, ya, ta, y0, t0, 0);
    if (r == PSB_SUCCESS) {
        psb__mon m;
        if (fn->kind == PSB_SPECIAL_BRANCH) {
            r = psb__monitor(s, &m);
            fn->ref = m.logabs[fn->index];
        }
        if (r == PSB_SUCCESS) r = psb__sp_value(s, fn, ya, ta, &fa);
    }
    if (r != PSB_SUCCESS) return psb__sp_fault(s, r, 1) ? r : PSB_NONSMOOTH_END;
    psb__copy(yb, y1, np1);
    r = psb__newton_on(s, yb, tb, y0, t0, sb);
    if (r == PSB_SUCCESS) r = psb__sp_value(s, fn, yb, tb, &fb);
    if (r != PSB_SUCCESS) return psb__sp_fault(s, r, 1) ? r : PSB_NONSMOOTH_END;
    f01_abs[0] = fabs(fa);
    f01_abs[1] = fabs(fb);
    if ((fa < 0) == (fb < 0)) return PSB_NONSMOOTH_END;
    ga = fa;
    gb = fb;
    for (iter = 0; iter < 200 && fa != 0 && fb != 0; iter++) {
        double width = psb__dist_w(s, ya, yb), sm, fm, margin;
        if (width <= tol) break;
        if (evals % 2 == 0) {
            bisect = evals > 0 && width > 0.5 * width_before;
            width_before = width;
        }
        sm = bisect ? 0.5 * (sa + sb) : (sa * gb - sb * ga) / (gb - ga);
        if (!(sm > sa && sm < sb)) sm = 0.5 * (sa + sb);
        /* at least min(tol, w) / 4 inside (as Brent's method steps): an end converging on the
           zero alone would keep the other where it is */
        margin = 0.25 * fmin(tol, sb - sa);
        sm = fmin(fmax(sm, sa + margin), sb - margin);
        r = psb__bracket_point(s, y0, t0, sa, ya, ta, sb, yb, tb, fabs(fb) > fabs(fa), &sm, ye, te);
        if (r == PSB_SUCCESS) r = psb__sp_value(s, fn, ye, te, &fm);
        /* the user solver refusing every point inside the step's bracket is its failure, not
           a branch point's geometry (singular at the point only: the points tried move away) */
        if (psb__sp_fault(s, r, fn->kind != PSB_SPECIAL_BRANCH || found == 0)) return r;
        /* the user backend's tau growing far beyond its values at the ends: a pole */
        if (r == PSB_SUCCESS && fn->kind == PSB_SPECIAL_BRANCH && s->prob.linear == PSB_LINEAR_USER &&
            fabs(fm) > 1e3 * fmax(f01_abs[0], f01_abs[1]))
            return PSB_NONSMOOTH_END;
        evals++;
        if (r != PSB_SUCCESS) {
            if (bisect) break; /* even the midpoint failed: keep the bracket reached */
            bisect = 1;
            continue;
        }
        found++;
        if ((fm < 0) == (fa < 0)) {
            sa = sm; fa = ga = fm;
            psb__copy(ya, ye, np1); psb__copy(ta, te, np1);
            if (side == -1) gb *= 0.5; /* Illinois: the end kept twice has its value halved */
            side = -1;
        } else {
            sb = sm; fb = gb = fm;
            psb__copy(yb, ye, np1); psb__copy(tb, te, np1);
            if (side == 1) ga *= 0.5;
            side = 1;
        }
    }
    if (fabs(fa) <= fabs(fb)) {
        psb__copy(PSB__VEC(s, PSB__V_SP_Y), ya, np1);
        psb__copy(PSB__VEC(s, PSB__V_SP_T), ta, np1);
        *fend_abs = fabs(fa);
    } else {
        psb__copy(PSB__VEC(s, PSB__V_SP_Y), yb, np1);
        psb__copy(PSB__VEC(s, PSB__V_SP_T), tb, np1);
        *fend_abs = fabs(fb);
    }
    *precision = fa == 0 || fb == 0 ? 0 : psb__dist_w(s, ya, yb);
    s->message[0] = 0;
    return PSB_SUCCESS;
}

/* Tangent and second kernel direction at a located branch point y* = SP_Y, s* from y0 along
   t0. The tangent from B^{-1} e_{N+1} right at y* carries an error ~ eps cond(B), and B is
   singular there; the mean of the tangents at s* -+ delta is O(delta^2 + eps / delta) off.
   The kernel: two steps of inverse iteration with B at s* + delta (nearly singular, its
   near-null vector is, to O(delta), dH's second kernel direction w-orthogonal to t0; each
   step gains a factor ~ delta), from a random right-hand side, then made w-orthogonal to the
   tangent. Results in SP_T, SP_K. */
static psb_result psb__branch_directions(psb_solver *s, const double *y0, const double *t0,
                                         double span)
{
    int np1 = s->internal_.np1, i, k, it;
    double *ys = PSB__VEC(s, PSB__V_SP_Y), *ts = PSB__VEC(s, PSB__V_SP_T), *ks = PSB__VEC(s, PSB__V_SP_K);
    double *ye = PSB__VEC(s, PSB__V_SP_YE), *te = PSB__VEC(s, PSB__V_SP_TE);
    double *tsum = PSB__VEC(s, PSB__V_SP_TA), *kb = PSB__VEC(s, PSB__V_SP_TB), sstar = 0, delta, c;
    psb_result r = PSB_ERR_SINGULAR;
    for (i = 0; i < np1; i++) sstar += s->internal_.w[i] * t0[i] * (ys[i] - y0[i]);
    delta = fmin(1e-5 * span, 0.25 * fmin(sstar, span - sstar));
    memset(tsum, 0, (size_t)np1 * sizeof(double));
    for (k = -1; k <= 1 && delta > 0; k += 2) {
        /* twice with the user backend: its factor or solve reports any failure as singular,
           which next to a branch point passes for the geometry's (psb__sp_fault), so a passing
           failure would drop the kernel and with it the switch (psb__locate_kink likewise) */
        for (it = 0; it < (s->prob.linear == PSB_LINEAR_USER ? 2 : 1); it++) {
            psb__axpy_to(ye, ys, k * delta / psb_dot_w(s, t0, ts), ts, np1);
            r = psb__newton_on(s, ye, te, y0, t0, sstar + k * delta);
            if (r != PSB_ERR_SINGULAR) break;
        }
        if (r != PSB_SUCCESS) return r;
        for (i = 0; i < np1; i++) tsum[i] += te[i];
    }
    if (r != PSB_SUCCESS) return r;
    psb__copy(ts, tsum, np1);
    psb__normalize_w(s, ts);
    for (i = 0; i < np1; i++) ks[i] = psb__gauss(s->internal_.rng);
    for (it = 0; it < 2; it++) {
        psb__copy(kb, ks, np1);
        r = psb__solve_factored(s, ks, 1);
        if (r == PSB_ERR_SINGULAR && s->prob.linear == PSB_LINEAR_USER) {
            psb__copy(ks, kb, np1);
            r = psb__solve_factored(s, ks, 1);
        }
        if (r != PSB_SUCCESS) return r;
        if (!psb__normalize_w(s, ks)) break;
    }
    /* projected twice: once leaves a part along ts of eps / (the part across it) */
    for (it = 0; it < 2; it++) {
        c = psb_dot_w(s, ks, ts);
        for (i = 0; i < np1; i++) ks[i] -= c * ts[i];
        if (it == 0 && !(psb__norm_w(s, ks) > 1e-8)) break; /* ks was unit: along the tangent */
    }
    if (it < 2 || !psb__normalize_w(s, ks))
        return psb__fail(s, PSB_ERR_SINGULAR, "kernel estimate vanished or along the tangent");
    return PSB_SUCCESS;
}

/* What psb_trace's detectors carry from one accepted point to the next. */
typedef struct psb__detector {
    psb_solver *s;
    const psb_trace_options *to;
    psb_trace_report *rep;
    psb__mon mon_old, mon_new;
    int mon_on, mon_old_ok, mon_new_ok;
    double *g_old, *g_new;
    psb_special sp;
} psb__detector;

/* The test function at (y, t) by a factorisation of its own (start point, bound landing). */
static psb_result psb__monitor_at(psb_solver *s, const double *y, const double *t, psb__mon *m,
                                  double fd_cap)
{
    int i;
    psb_result r = psb__jacobian_capped(s, y, NULL, fd_cap);
    if (r != PSB_SUCCESS) return r;
    for (i = 0; i < s->internal_.np1; i++) s->internal_.work[i] = s->internal_.w[i] * t[i];
    r = psb__factor_bordered(s, s->internal_.work, NULL);
    if (r == PSB_SUCCESS && s->prob.linear == PSB_LINEAR_BANDED) r = psb__band_border(s, NULL);
    if (r != PSB_SUCCESS) return r;
    return psb__monitor(s, m);
}

/* Sets up the detectors at the start couple: borders of the user backend's test function
   from the generator, reseeded from options.seed; the test function and events there. */
static psb_result psb__detect_start(psb_solver *s, psb__detector *d, const double *y, const double *t)
{
    const psb_trace_options *to = d->to;
    unsigned long long seed = s->opt.seed;
    int k, i;
    psb_result r;
    for (k = 0; k < 4; k++) s->internal_.rng[k] = psb__splitmix(&seed);
    for (k = 0; k < 2; k++) {
        double *b = PSB__VEC(s, k ? PSB__V_SP_B2 : PSB__V_SP_B1), *c = PSB__VEC(s, k ? PSB__V_SP_C2 : PSB__V_SP_C1);
        for (i = 0; i < s->internal_.np1; i++) b[i] = psb__gauss(s->internal_.rng);
        for (i = 0; i < s->internal_.np1; i++) c[i] = psb__gauss(s->internal_.rng);
        s->internal_.sp_d[k] = psb__gauss(s->internal_.rng);
    }
    d->mon_on = (to->detect & (PSB_DETECT_BRANCH | PSB_DETECT_PC1)) != 0;
    d->mon_old_ok = 0;
    if (d->mon_on) {
        r = psb__monitor_at(s, y, t, &d->mon_old, 0);
        if (psb__sp_fault(s, r, 1)) return r;
        d->mon_old_ok = r == PSB_SUCCESS;
    }
    if ((to->detect & PSB_DETECT_EVENTS) && to->n_events > 0) {
        d->g_old = to->event_work;
        d->g_new = to->event_work + to->n_events;
        r = psb__event_values(s, to, y, d->g_old);
        if (r != PSB_SUCCESS) return r;
    }
    s->message[0] = 0;
    return PSB_SUCCESS;
}

/* Reports d->sp: counted, passed to on_point; returns 1 when the trace is to stop there. */
static int psb__report_special(psb__detector *d, long index)
{
    psb_point p;
    d->rep->n_special[d->sp.kind]++;
    memset(&p, 0, sizeof p);
    p.y = d->sp.y;
    p.t = d->sp.t;
    p.index = index;
    p.flags = PSB_POINT_SPECIAL;
    p.special = &d->sp;
    if (d->to->on_point && psb__call_point(d->s, d->to, &p)) return 1;
    return (d->to->stop_at >> d->sp.kind & 1u) != 0;
}

static void psb__special_init(psb__detector *d, psb_special_kind kind, const double *y,
                              const double *t, int param_index)
{
    memset(&d->sp, 0, sizeof d->sp);
    d->sp.kind = kind;
    d->sp.y = y;
    d->sp.t = t;
    d->sp.param = y[param_index];
    d->sp.event = -1;
}

/* Whether the test function's sign change that psb__locate_change located (precision: the
   bracket's width, fend: |f| at its end nearer the zero, f01: |f| at y0 and y1) is a jump rather
   than a zero. At a simple zero |f| at the bracket's end is at most its slope times the
   bracket's width, and the slope is that of the secants from y0 and y1 to within the curvature;
   across a nonsmooth point f jumps and keeps its one-sided size at any width. A zero within
   1e3 widths of an end is not told apart (called a zero). */
static int psb__sign_jumped(const psb_solver *s, const double *y0, const double *y1, double precision,
                            double fend, const double *f01)
{
    const double *ys = PSB__VEC(s, PSB__V_SP_Y);
    double d0 = psb__dist_w(s, y0, ys), d1 = psb__dist_w(s, y1, ys), slope = 0;
    if (!(precision > 0)) return 0;
    if (d0 > 1e3 * precision) slope = fmax(slope, f01[0] / d0);
    if (d1 > 1e3 * precision) slope = fmax(slope, f01[1] / d1);
    return slope > 0 && fend > 1e3 * slope * precision;
}

/* The detectors for the accepted step from (y0, t0) to (y1, t1) of length h_step: kink
   (1: the couple before a kink is in K_YA/K_TA, 2: (y0, t0) is, the step was a tangent
   switch, 0: none known). Returns 0 to go on, 1 to stop at d->sp (PSB_STOPPED), or a
   failure code. */
static int psb__detect_step(psb_solver *s, psb__detector *d, const double *y0, const double *t0,
                            const double *y1, const double *t1, int kink, double h_step, long index)
{
    const psb_trace_options *to = d->to;
    int p = s->prob.param_index, detect = to->detect, k, fold, branch, changed[2];
    double tol = to->locate_tol > 0 ? to->locate_tol : 1e-10, precision, fend, f01[2];
    const double *yk = NULL, *tk = NULL;
    psb__sp_fn fn;
    psb_result r;
    fold = (detect & PSB_DETECT_FOLDS) && t0[p] * t1[p] < 0;
    for (k = 0; k < 2; k++)
        changed[k] = d->mon_on && d->mon_old_ok && d->mon_new_ok && d->mon_old.sign[k] != d->mon_new.sign[k];
    branch = changed[0] || changed[1];
    if (!kink && (fold || branch) && psb__cos_w(s, t0, t1) < s->opt.c_diff) {
        /* a fold or a det sign change in a step that turned: at a kink, or smooth? */
        int found = psb__locate_kink(s, y0, t0, t1, h_step, -1);
        if (found < 0) return found;
        kink = found;
    }
    if (kink == 1) {
        yk = PSB__VEC(s, PSB__V_K_YA);
        tk = PSB__VEC(s, PSB__V_K_TA);
    } else if (kink == 2) {
        yk = y0;
        tk = t0;
    }
    memset(&fn, 0, sizeof fn);
    fn.to = to;
    if (fold) {
        if (kink) {
            psb__special_init(d, PSB_SPECIAL_FOLD_KINK, yk, tk, p);
            d->sp.precision = s->opt.h_min / s->opt.h_dec;
            if (psb__report_special(d, index)) return 1;
        } else {
            fn.kind = PSB_SPECIAL_FOLD;
            r = psb__locate_change(s, &fn, y0, t0, y1, tol, &precision, &fend, f01);
            if (r < 0) return r;
            if (r == PSB_SUCCESS) {
                psb__special_init(d, PSB_SPECIAL_FOLD, PSB__VEC(s, PSB__V_SP_Y), PSB__VEC(s, PSB__V_SP_T), p);
                d->sp.precision = precision;
                if (psb__report_special(d, index)) return 1;
            }
        }
    }
    if (branch && kink && (detect & PSB_DETECT_PC1)) {
        psb__special_init(d, PSB_SPECIAL_PC1, yk, tk, p);
        d->sp.precision = s->opt.h_min / s->opt.h_dec;
        if (psb__report_special(d, index)) return 1;
    } else if (branch && !kink && (detect & (PSB_DETECT_BRANCH | PSB_DETECT_PC1))) {
        /* a smooth branch point, or (PC1) a nonsmooth point crossed straight through */
        fn.kind = PSB_SPECIAL_BRANCH;
        r = PSB_NONSMOOTH_END;
        for (k = 0; k < 2 && r != PSB_SUCCESS; k++) {
            if (!changed[k]) continue;
            fn.index = k;
            r = psb__locate_change(s, &fn, y0, t0, y1, tol, &precision, &fend, f01);
            if (r < 0) return r;
            /* the user backend's tau also changes sign at its poles: a zero shrinks |tau|
               below its values at the ends, a pole grows it beyond */
            if (r == PSB_SUCCESS && s->prob.linear == PSB_LINEAR_USER && fend > fmin(f01[0], f01[1]))
                r = PSB_NONSMOOTH_END;
            if (r == PSB_SUCCESS && psb__sign_jumped(s, y0, y1, precision, fend, f01)) {
                /* det jumped at a nonsmooth point passed straight through (no kink: the
                   tangent did not turn), a PC1 point: the couple before it, for Algorithm 2.2 */
                r = PSB_NONSMOOTH_END;
                if (!(detect & PSB_DETECT_PC1)) break;
                psb__special_init(d, PSB_SPECIAL_PC1, PSB__VEC(s, PSB__V_SP_YA), PSB__VEC(s, PSB__V_SP_TA), p);
                d->sp.precision = precision;
                d->sp.located = 1;
                if (psb__report_special(d, index)) return 1;
                break;
            }
        }
        if (r == PSB_SUCCESS && (detect & PSB_DETECT_BRANCH)) {
            double span = 0;
            for (k = 0; k < s->internal_.np1; k++) span += s->internal_.w[k] * t0[k] * (y1[k] - y0[k]);
            r = psb__branch_directions(s, y0, t0, span);
            if (psb__sp_fault(s, r, 0)) return r;
            psb__special_init(d, PSB_SPECIAL_BRANCH, PSB__VEC(s, PSB__V_SP_Y), PSB__VEC(s, PSB__V_SP_T), p);
            d->sp.kernel = r == PSB_SUCCESS ? PSB__VEC(s, PSB__V_SP_K) : NULL;
            d->sp.precision = precision;
            if (psb__report_special(d, index)) return 1;
        }
    }
    if ((detect & PSB_DETECT_EVENTS) && to->n_events > 0) {
        double *swap;
        r = psb__event_values(s, to, y1, d->g_new);
        if (r != PSB_SUCCESS) return r;
        for (k = 0; k < to->n_events; k++) {
            if ((d->g_old[k] < 0) == (d->g_new[k] < 0)) continue;
            fn.kind = PSB_SPECIAL_EVENT;
            fn.index = k;
            r = psb__locate_change(s, &fn, y0, t0, y1, tol, &precision, &fend, f01);
            if (r < 0) return r;
            if (r != PSB_SUCCESS) continue;
            psb__special_init(d, PSB_SPECIAL_EVENT, PSB__VEC(s, PSB__V_SP_Y), PSB__VEC(s, PSB__V_SP_T), p);
            d->sp.precision = precision;
            d->sp.event = k;
            d->sp.direction = d->g_new[k] > d->g_old[k] ? 1 : -1;
            if (psb__report_special(d, index)) return 1;
        }
        swap = d->g_old;
        d->g_old = d->g_new;
        d->g_new = swap;
    }
    d->mon_old = d->mon_new;
    d->mon_old_ok = d->mon_new_ok;
    s->message[0] = 0;
    return 0;
}

/* The detectors' test function at the accepted couple (y, t), by a factorisation there.
   Returns PSB_SUCCESS, or the fault or fatal code that ends the trace. */
static psb_result psb__trace_monitor_at(psb_solver *s, psb__detector *det, const double *y, const double *t)
{
    psb_result r = psb__monitor_at(s, y, t, &det->mon_new, 0);
    if (psb__sp_fault(s, r, 1)) return r;
    det->mon_new_ok = r == PSB_SUCCESS;
    return PSB_SUCCESS;
}

/* A fold between the accepted couples (yold, told) and (yc, tc): t[param] changed sign.
   Records its estimate in *pt and rep (at a kink reached by the switch, yold's parameter). */
static void psb__trace_fold(psb_solver *s, psb_trace_report *rep, psb_point *pt, const double *yold,
                            const double *told, const double *yc, const double *tc)
{
    int p = s->prob.param_index;
    pt->fold_param = 0;
    if (told[p] * tc[p] >= 0) return;
    pt->flags |= PSB_POINT_FOLD;
    pt->fold_param = (pt->flags & PSB_POINT_SWITCH) ? yold[p] : psb__fold_param(s, yold, told, yc, tc);
    if (rep->n_folds < PSB_MAX_FOLDS) rep->fold_params[rep->n_folds] = pt->fold_param;
    rep->n_folds++;
}

/* psb_trace's options, checked against the start y, with max_steps' default, into *opts. */
static psb_result psb__trace_options(psb_solver *s, const psb_trace_options *to, const double *y,
                                     psb_trace_options *opts)
{
    int p = s->prob.param_index;
    if (to) *opts = *to;
    else memset(opts, 0, sizeof *opts);
    if (opts->max_steps < 0) return psb__fail(s, PSB_ERR_OPTIONS, "trace options: max_steps must be >= 0");
    if (opts->locate_kinks < 0 || opts->locate_kinks > 2)
        return psb__fail(s, PSB_ERR_OPTIONS, "trace options: locate_kinks must be 0, 1 or 2");
    if (opts->max_steps == 0) opts->max_steps = 10000;
    if (opts->param_min != opts->param_min || opts->param_max != opts->param_max)
        return psb__fail(s, PSB_ERR_INPUT, "trace options: param_min or param_max is NaN");
    if (opts->param_min < opts->param_max && (!(y[p] >= opts->param_min) || !(y[p] <= opts->param_max)))
        return psb__fail(s, PSB_ERR_INPUT, "start point outside the parameter bounds");
    if (opts->detect < 0 || opts->detect > PSB_DETECT_ALL || !(opts->locate_tol >= 0) ||
        !psb__finite(opts->locate_tol))
        return psb__fail(s, PSB_ERR_OPTIONS, "detect must be a PSB_DETECT_* mask and locate_tol >= 0");
    if ((opts->detect & PSB_DETECT_PC1) && s->prob.linear == PSB_LINEAR_USER)
        return psb__fail(s, PSB_ERR_OPTIONS, "PSB_DETECT_PC1 needs the dense or banded backend");
    if (opts->n_events < 0) return psb__fail(s, PSB_ERR_SIZE, "n_events must be >= 0");
    if ((opts->detect & PSB_DETECT_EVENTS) && opts->n_events > 0 && (!opts->event || !opts->event_work))
        return psb__fail(s, PSB_ERR_NULL, "event or event_work is NULL");
    return PSB_SUCCESS;
}

/* Reports the kinks of an accepted step from (yold, told) to (yc, tc), the first (kink set)
   in K_YA/K_TA; with locate_kinks = 2 it searches the rest of the step past each (up to 8),
   and leaves the first in K_YA/K_TA again for the detectors (TR_KY/TR_KT keep it across the
   callbacks: a point callback may call psb_switch_tangent, whose scratch SW_* is). Returns 1
   when the trace ends (rep->end set; (yc, tc) the couple it ends on), else 0. */
static int psb__trace_kinks(psb_solver *s, const psb_trace_options *opts, psb_trace_report *rep,
                            int kink, int switched, const double *yold, const double *told,
                            double *yc, double *tc)
{
    int np1 = s->internal_.np1, n_step_kinks, first = kink;
    psb_result r;
    for (n_step_kinks = 0; kink; n_step_kinks++) {
        psb_point kp;
        double *yp = PSB__VEC(s, PSB__V_SW_C), *tp = PSB__VEC(s, PSB__V_SW_D), hp = 4 * s->opt.h_min;
        int past_iters;
        memset(&kp, 0, sizeof kp);
        kp.y = PSB__VEC(s, PSB__V_K_YA);
        kp.t = PSB__VEC(s, PSB__V_K_TA);
        kp.index = rep->steps;
        kp.flags = PSB_POINT_KINK;
        rep->n_kinks++;
        if (opts->on_point && psb__call_point(s, opts, &kp)) {
            psb__copy(yc, kp.y, np1);
            psb__copy(tc, kp.t, np1);
            rep->end = PSB_STOPPED;
            return 1;
        }
        /* a later kink of the same step: the rest of the step is searched from a couple just
           past this one (the switch's scratch, idle here but in the callback above) */
        kink = 0;
        if (opts->locate_kinks < 2 || switched || n_step_kinks >= 7) break;
        if (n_step_kinks == 0) {
            psb__copy(PSB__VEC(s, PSB__V_TR_KY), kp.y, np1);
            psb__copy(PSB__VEC(s, PSB__V_TR_KT), kp.t, np1);
        }
        psb__copy(yp, kp.y, np1);
        psb__copy(tp, kp.t, np1);
        r = psb__try_step(s, yp, tp, &hp, hp, &past_iters);
        if (psb__is_fatal(r) || psb__is_fault(r)) {
            psb__copy(yc, yold, np1);
            psb__copy(tc, told, np1);
            rep->end = r;
            return 1;
        }
        if (r == PSB_SUCCESS && psb__cos_w(s, tp, kp.t) < s->opt.c_diff && psb__cos_w(s, tp, tc) < s->opt.c_diff &&
            psb__dist_w(s, yp, yc) > 4 * s->opt.h_min) {
            int found = psb__locate_kink(s, yp, tp, tc, psb__dist_w(s, yp, yc), -1);
            if (found < 0) {
                psb__copy(yc, yold, np1);
                psb__copy(tc, told, np1);
                rep->end = (psb_result)found;
                return 1;
            }
            kink = found;
        }
    }
    if (first && n_step_kinks > 0 && opts->locate_kinks) {
        psb__copy(PSB__VEC(s, PSB__V_K_YA), PSB__VEC(s, PSB__V_TR_KY), np1);
        psb__copy(PSB__VEC(s, PSB__V_K_TA), PSB__VEC(s, PSB__V_TR_KT), np1);
    }
    return 0;
}

/* A step from (yold, told) that left the parameter bounds to (yc, tc): lands on the bound it
   crossed (flags gets PSB_POINT_BOUND), or ends the trace leaving through the bound it
   started on. Returns 0 (landed), 1 (the trace ends: rep->end set, (yc, tc) the couple it ends
   on), or 2: (yc, tc) back at yold, to try the shorter step *h (counted in *landings_failed:
   a tangent switch that crosses the bound again restarts at h_init, so this could loop). */
static int psb__trace_bound(psb_solver *s, const psb_trace_options *opts, psb_trace_report *rep,
                            psb__detector *det, const double *yold, const double *told, double *yc,
                            double *tc, double *h, int *landings_failed, int *flags)
{
    int np1 = s->internal_.np1, p = s->prob.param_index;
    double bound = yc[p] > opts->param_max ? opts->param_max : opts->param_min;
    psb_result r;
    if (yold[p] == bound) { /* leaving through the bound we started on */
        psb__copy(yc, yold, np1);
        psb__copy(tc, told, np1);
        rep->end = PSB_PARAM_BOUND;
        return 1;
    }
    r = psb__land_on_bound(s, yold, yc, bound);
    /* (a singular Newton matrix there is a fold at the bound: a shorter step may land) */
    if (!psb__is_fatal(r) && r != PSB_ERR_CALLBACK_FAILED && r != PSB_ERR_NONFINITE) {
        if (r == PSB_SUCCESS) r = psb__tangent(s, yc, tc, tc);
        if (!psb__is_fatal(r) && !psb__is_fault(r) && r != PSB_SUCCESS) {
            psb__copy(yc, yold, np1);
            psb__copy(tc, told, np1);
            *h *= s->opt.h_dec;
            if (*h >= s->opt.h_min && ++*landings_failed <= 64) return 2;
            rep->end = psb__fail(s, PSB_ERR_NO_CONVERGENCE, "could not land on the parameter bound");
            return 1;
        }
    }
    if (r != PSB_SUCCESS) {
        psb__copy(yc, yold, np1);
        psb__copy(tc, told, np1);
        rep->end = r;
        return 1;
    }
    *flags |= PSB_POINT_BOUND;
    if (det->mon_on) {
        r = psb__trace_monitor_at(s, det, yc, tc);
        if (r != PSB_SUCCESS) {
            rep->end = r;
            return 1;
        }
    }
    return 0;
}

/* Whether the trace closed a loop: its start lies on the last chord (yold, yc) of length seg,
   and the curve went further than that chord already (travelled). */
static int psb__trace_loop_closed(psb_solver *s, const double *yold, const double *yc,
                                  const double *ystart, double seg, double travelled)
{
    int i, np1 = s->internal_.np1;
    double *d = PSB__VEC(s, PSB__V_TR_B), seg2 = seg * seg, proj = 0, dist2 = 0, x;
    for (i = 0; i < np1; i++) proj += s->internal_.w[i] * (yc[i] - yold[i]) * (ystart[i] - yold[i]);
    x = seg2 > 0 ? proj / seg2 : -1;
    if (!(x >= 0 && x <= 1 && travelled > 4 * sqrt(seg2))) return 0;
    for (i = 0; i < np1; i++) d[i] = yold[i] + x * (yc[i] - yold[i]) - ystart[i];
    for (i = 0; i < np1; i++) dist2 += s->internal_.w[i] * d[i] * d[i];
    return dist2 <= 0.0025 * seg2 + s->opt.tol_correction * s->opt.tol_correction;
}

PSCBRANCH_DEF psb_result psb_trace(psb_solver *s, double *y, double *t,
                                   const psb_trace_options *to, psb_trace_report *rep)
{
    psb_trace_options opts;
    psb_trace_report local;
    psb_point pt;
    psb__detector det;
    int np1, p, bounded, iters, flags, kink, step_kink, just_switched = 0, landings_failed = 0;
    double turn_rate = -1; /* the last smooth step's turn per length (-1: none known) */
    double h, h_step = 0, travelled = 0;
    double *yc, *tc, *yold, *told, *ystart, *tkink;
    psb_result r;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    r = psb__check_couple(s, y, t);
    if (r == PSB_SUCCESS) r = psb__trace_busy(s, "psb_trace");
    if (r != PSB_SUCCESS) return rep->end = r;
    r = psb__trace_options(s, to, y, &opts);
    if (r != PSB_SUCCESS) return rep->end = r;
    np1 = s->internal_.np1;
    p = s->prob.param_index;
    bounded = opts.param_min < opts.param_max;
    yc = PSB__VEC(s, PSB__V_TR_Y), tc = PSB__VEC(s, PSB__V_TR_T);
    yold = PSB__VEC(s, PSB__V_TR_Y0), told = PSB__VEC(s, PSB__V_TR_T0);
    ystart = PSB__VEC(s, PSB__V_TR_S), tkink = PSB__VEC(s, PSB__V_TR_K);
    psb__copy(yc, y, np1);
    psb__copy(tc, t, np1);
    psb__normalize_w(s, tc);
    psb__copy(ystart, yc, np1);
    h = s->opt.h_init;
    memset(&det, 0, sizeof det);
    det.s = s, det.to = &opts, det.rep = rep;
    if (opts.detect && (r = psb__detect_start(s, &det, yc, tc)) != PSB_SUCCESS) { rep->end = r; goto done; }
    memset(&pt, 0, sizeof pt);
    pt.y = yc;
    pt.t = tc;
    pt.flags = PSB_POINT_START;
    if (opts.on_point && psb__call_point(s, &opts, &pt)) {
        rep->end = PSB_STOPPED;
        goto done;
    }
    while (rep->steps < opts.max_steps) {
        psb__copy(yold, yc, np1);
        psb__copy(told, tc, np1);
        flags = 0;
        kink = 0;
        r = psb__try_step(s, yc, tc, &h, s->opt.h_min, &iters);
        h_step = h;
        if (r == PSB_ERR_STEP_TOO_SMALL) {
            if (opts.no_switch) { rep->end = PSB_NONSMOOTH_END; goto done; }
            r = psb__switch(s, yc, tc, just_switched ? tkink : NULL);
            psb__copy(tkink, told, np1);
            if (r != PSB_SUCCESS) { rep->end = r; goto done; } /* PSB_NONSMOOTH_END too */
            /* the test function from the factors of the switch step's last corrector iteration */
            flags |= PSB_POINT_SWITCH; /* counted once its step is accepted (a bound may undo it) */
            h = s->opt.h_init;
            turn_rate = -1;
            if (opts.locate_kinks) { /* steps failed right before it: yold is the kink couple */
                psb__copy(PSB__VEC(s, PSB__V_K_YA), yold, np1);
                psb__copy(PSB__VEC(s, PSB__V_K_TA), told, np1);
                kink = 1;
            }
        } else if (r != PSB_SUCCESS) {
            rep->end = r;
            goto done;
        } else if (bounded && told[p] * tc[p] < 0 && h_step * s->opt.h_dec >= s->opt.h_min &&
                   psb__fold_beyond_bound(s, &opts, yold, told, yc, tc)) {
            /* a fold within the step beyond a bound, both ends inside: the curve reached the
               bound first on the way up to the fold; a shorter step from yold lands on it */
            psb__copy(yc, yold, np1);
            psb__copy(tc, told, np1);
            h = h_step * s->opt.h_dec;
            continue;
        } else {
            /* the test function from the factors of the step's last corrector iteration */
            if (det.mon_on) {
                /* from factors that just served the corrector: any failure is a fault (the
                   user's solve) */
                r = psb__monitor(s, &det.mon_new);
                if (psb__sp_fault(s, r, 1)) { rep->end = r; goto done; }
                det.mon_new_ok = r == PSB_SUCCESS;
            }
            if (opts.locate_kinks) {
                int found = psb__locate_kink(s, yold, told, tc, h, turn_rate >= 0 ? turn_rate * h : -1);
                if (found < 0) { psb__copy(yc, yold, np1); psb__copy(tc, told, np1); rep->end = (psb_result)found; goto done; }
                kink = found;
                turn_rate = found ? -1 : psb__angle_w(s, told, tc) / h;
            }
            h = psb__adapt(s, h, iters);
        }
        step_kink = kink; /* the step's first kink, for the detectors */
        if (psb__trace_kinks(s, &opts, rep, kink, (flags & PSB_POINT_SWITCH) != 0, yold, told, yc, tc)) goto done;
        /* across a kink the corrector's last factorisation may be at an iterate on the other
           piece: the test function then costs a factorisation at the accepted point */
        if (det.mon_on && ((flags & PSB_POINT_SWITCH) || psb__cos_w(s, told, tc) < s->opt.c_diff)) {
            r = psb__trace_monitor_at(s, &det, yc, tc);
            if (r != PSB_SUCCESS) { rep->end = r; goto done; }
        }
        if (bounded && (yc[p] > opts.param_max || yc[p] < opts.param_min)) {
            int landed = psb__trace_bound(s, &opts, rep, &det, yold, told, yc, tc, &h, &landings_failed, &flags);
            if (landed == 1) goto done;
            if (landed == 2) continue;
        }
        just_switched = (flags & PSB_POINT_SWITCH) != 0;
        rep->n_switches += just_switched;
        landings_failed = 0;
        rep->steps++;
        pt.h = psb__dist_w(s, yold, yc);
        travelled += pt.h;
        pt.flags = flags;
        psb__trace_fold(s, rep, &pt, yold, told, yc, tc);
        flags = pt.flags;
        if (opts.detect) {
            int stop = psb__detect_step(s, &det, yold, told, yc, tc,
                                        (flags & PSB_POINT_SWITCH) ? 2 : step_kink, h_step, rep->steps);
            if (stop < 0) { rep->end = (psb_result)stop; goto done; }
            if (stop) {
                psb__copy(yc, det.sp.y, np1);
                psb__copy(tc, det.sp.t, np1);
                rep->end = PSB_STOPPED;
                goto done;
            }
        }
        pt.index = rep->steps;
        pt.flags = flags;
        if (opts.on_point && psb__call_point(s, &opts, &pt)) { rep->end = PSB_STOPPED; goto done; }
        if (flags & PSB_POINT_BOUND) { rep->end = PSB_PARAM_BOUND; goto done; }
        if (opts.detect_loop && rep->steps >= 3 && psb__trace_loop_closed(s, yold, yc, ystart, pt.h, travelled)) {
            rep->end = PSB_LOOP_CLOSED;
            goto done;
        }
    }
    rep->end = PSB_STEP_BUDGET;
done:
    /* a failure before the first accepted step leaves the caller's couple as it was (t not
       normalised); otherwise (y, t) is the last accepted couple */
    if (rep->end >= 0 || rep->steps > 0) {
        psb__copy(y, yc, np1);
        psb__copy(t, tc, np1);
    }
    rep->h = h;
    return rep->end;
}

/* ==== Algorithm 2.1 (psb_locate_end) ============================================================
   The branching calls' h (psb__branch_h) and Algorithm 2.1: approach the end point of
   a branch. */

/* Sets s->branch.h (and h_min) for Algorithms 2.1-2.2 at y. With finite differences and h
   left to its default: 10^4 times the largest difference step at y measured in
   the weighted norm, max_j fd_step max(1, |y_j|) sqrt(w_j), within [h_min, h_init / 8 (s->branch)]
   (trial points must lie farther than branch_h). Tangents are sampled at y + branch_h v; a
   quotient there mixes pieces when a piece boundary lies within a difference step, with odds
   ~ step / branch_h per boundary and sample, and a mixed tangent the memo takes for new makes
   an idle span count. The crossing kinks and a curved variant (k = 4, every entry): 10^3
   steps left 1 and 7 of the 16 entries incomplete, 10^4 none. */
static double psb__auto_branch_h(const psb_solver *s, const psb_branch_options *b, const double *y)
{
    int j;
    double step = 0, h;
    for (j = 0; j < s->internal_.np1; j++) {
        double sj = s->prob.fd_step * (fabs(y[j]) > 1 ? fabs(y[j]) : 1.0) * sqrt(s->internal_.w[j]);
        if (sj > step) step = sj;
    }
    h = b->expert.h_fd_steps * step;
    if (h > b->h_init / 8) h = b->h_init / 8;
    return h > s->opt.h_min ? h : s->opt.h_min;
}

/* The h that follows the point y under options b, or -1 where an h_min the caller set
   (h_min_set) is not below it: PSB_ERR_OPTIONS, as for an h_min not below a set h. */
static double psb__point_h(const psb_solver *s, const psb_branch_options *b, int h_min_set, const double *y)
{
    double h = psb__auto_branch_h(s, b, y);
    return h_min_set && !(b->h_min < h) ? -1 : h;
}

#define PSB__H_MIN_ABOVE "branch options: h_min must lie below h, which follows the point here"

/* Sets s->branch.h (and h_min) at y where they follow the point. PSB_ERR_OPTIONS where an
   h_min the caller set is not below that h (s->branch as it was). */
static psb_result psb__branch_h(psb_solver *s, const double *y)
{
    double h;
    if (!s->internal_.branch_h_auto) return PSB_SUCCESS;
    h = psb__point_h(s, &s->branch, !s->internal_.branch_h_min_auto, y);
    if (h < 0) return psb__fail(s, PSB_ERR_OPTIONS, PSB__H_MIN_ABOVE);
    s->branch.h = h;
    if (s->internal_.branch_h_min_auto) s->branch.h_min = h / 16384.0;
    return PSB_SUCCESS;
}

static psb_result psb__check_workers(psb_solver *s, const psb_branch_options *b);

/* Resolves and checks the branching options of a call at the point y into s->branch (left as
   it was when they are bad): where h follows the point, a set h_min is checked against it at
   y, as against a set h. */
static psb_result psb__branch_begin(psb_solver *s, const psb_branch_options *bo, const double *y)
{
    psb_branch_options b = psb_branch_options_resolve(bo, s);
    const char *bad = psb__check_branch(&b);
    psb_result r;
    if (!bad && b.h == 0 && psb__point_h(s, &b, b.h_min != 0, y) < 0) bad = PSB__H_MIN_ABOVE;
    if (bad) return psb__fail(s, PSB_ERR_OPTIONS, bad);
    r = psb__check_workers(s, &b);
    if (r != PSB_SUCCESS) return r;
    s->branch = b;
    /* finite differences and h left at 0: h follows the difference steps at each point */
    s->internal_.branch_h_auto = b.h == 0;
    s->internal_.branch_h_min_auto = b.h_min == 0;
    return PSB_SUCCESS;
}

/* Algorithm 2.1 with finite differences keeps its entering tangent tin, so where it stalls at
   yc it cannot tell an end point from a smooth point where the branch has turned by more than
   c_diff's angle a since the start (a start far up a curved branch). Chords can, as they need
   no difference quotients: from yc, points corrected delta behind and delta ahead along tin
   give two chords that differ by about the curvature times delta on a smooth branch and by
   nearly the kink's angle (a or more) at an end point. A smooth point is one where they agree
   to a / 2, at delta = max(256 h_min, 4 d) or, for an end point ahead of yc within that,
   max(64 h_min, d): yc lies within h_min of an end point, so a kink turns the chords by 0.97
   of its angle or more, and d = 32 tol_correction / a keeps the chords' own error (4
   tol_correction / delta at most) below a / 8. Scales beyond branch.h are not tried (then
   the stall is the end point). Returns 1 with the point ahead in ya and the chord
   to it in ta (follow on from there: a tangent from quotients there may mix pieces), 0 for an
   end point (or no point ahead or behind), or a failure (fatal, or a fault at a chord's
   point). */
static int psb__fd_smooth_stall(psb_solver *s, const double *yc, const double *tin, double *ya, double *ta)
{
    int np1 = s->internal_.np1, side, scale, i;
    double *yb = PSB__VEC(s, PSB__V_BR_P), *tb = PSB__VEC(s, PSB__V_BR_Q), *ub = PSB__VEC(s, PSB__V_BR_V);
    double d = 32 * s->opt.tol_correction / sqrt(2 * (1 - s->opt.c_diff)), agree = 1 - 0.25 * (1 - s->opt.c_diff);
    for (scale = 0; scale < 2; scale++) {
        double delta = scale ? fmax(64 * s->branch.h_min, d) : fmax(256 * s->branch.h_min, 4 * d), along;
        int converged = 1;
        psb_result r;
        if (delta > s->branch.h) continue;
        for (side = -1; side <= 1 && converged; side += 2) {
            double *yp = side < 0 ? yb : ya, *tp = side < 0 ? tb : ta;
            psb__axpy_to(yp, yc, side * delta, tin, np1);
            psb__copy(tp, tin, np1);
            s->stats.n_pc_steps++;
            r = psb__correct(s, yp, tp, 0, NULL, NULL);
            if (psb__is_fatal(r)) return r;
            if (r != PSB_SUCCESS && psb__correct_fault(s, r)) { /* the test cannot tell: no success */
                psb__note_fault(s, r);
                return psb__faults_code(s, "Algorithm 2.1, the chords through the end point");
            }
            along = 0;
            for (i = 0; i < np1; i++) along += s->internal_.w[i] * (yp[i] - yc[i]) * tin[i];
            converged = r == PSB_SUCCESS && side * along >= 0.5 * delta;
        }
        if (!converged) continue;
        for (i = 0; i < np1; i++) ub[i] = yc[i] - yb[i];
        for (i = 0; i < np1; i++) tb[i] = ya[i] - yc[i];
        if (psb__cos_w(s, ub, tb) >= agree) {
            psb__copy(ta, tb, np1);
            return psb__normalize_w(s, ta);
        }
    }
    return 0;
}

/* Algorithm 2.1 with the options in s->branch (psb_locate_end, psb_explore). */
static psb_result psb__locate_end(psb_solver *s, double *y, double *t, double *precision)
{
    int np1, last_fault = 0, turned_only = 0, refined = 0;
    long advances = 0;
    double h, *yc, *tc, *yt, *tt, *tin, fd_cap = 0, refined_move = 0;
    psb_result r = psb__check_couple(s, y, t);
    if (r != PSB_SUCCESS) return r;
    np1 = s->internal_.np1;
    yc = PSB__VEC(s, PSB__V_BR_Y0);
    tc = PSB__VEC(s, PSB__V_BR_T0);
    yt = PSB__VEC(s, PSB__V_BR_Y);
    tt = PSB__VEC(s, PSB__V_BR_T);
    tin = PSB__VEC(s, PSB__V_BR_T1); /* the entering tangent (Algorithm 2.2 owns it later) */
    psb__copy(yc, y, np1);
    psb__copy(tc, t, np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "t is zero");
    psb__copy(tin, tc, np1);
    r = psb__branch_h(s, yc);
    if (r != PSB_SUCCESS) return r;
    /* Steps 1-5, except that after a successful move the same h is tried again before it is
       halved: the paper's version moves at most h in all, so it cannot reach an end point
       farther than h (the last step of a continuation can stop up to h_min / h_dec away). */
    h = s->branch.h;
    psb__faults_reset(s);
follow:
    do {
        int moved = 0;
        h *= 0.5;
        do {
            psb__axpy_to(yt, yc, h, tc, np1);
            psb__copy(tt, tc, np1);
            s->stats.n_pc_steps++;
            r = psb__correct_capped(s, yt, tt, 0, NULL, NULL, fd_cap);
            if (psb__is_fatal(r)) return r;
            /* a fault at the last trial leaves the end point unlocated (one that a later trial
               outlived cost nothing: the same h is tried again after every move) */
            last_fault = r != PSB_SUCCESS && psb__correct_fault(s, r);
            if (last_fault) psb__note_fault(s, r);
            /* Step 4, also against the entering tangent, so that small turns passing c_diff
               one by one cannot add up to another direction, and only for a point ahead: the
               corrector may fall back from beyond the end point onto the branch behind it
               (with finite differences, whose tangents there mix the pieces, that passed the
               cosine test over and over without moving) */
            moved = r == PSB_SUCCESS && psb__cos_w(s, tt, tc) >= s->opt.c_diff;
            if (moved) {
                double ahead = 0;
                int i;
                for (i = 0; i < np1; i++) ahead += s->internal_.w[i] * (yt[i] - yc[i]) * tc[i];
                moved = ahead >= 0.5 * h;
            }
            /* a step that fails the entering tangent's test alone: the branch goes on,
               smoothly here, but has turned since y */
            turned_only = moved && psb__cos_w(s, tt, tin) < s->opt.c_diff;
            moved = moved && !turned_only;
            if (moved) {
                if (refined) refined_move += psb__dist_w(s, yc, yt);
                psb__copy(yc, yt, np1);
                /* a finite-difference Jacobian within fd_step of the end point mixes the
                   pieces meeting there: keep the entering tangent, which over these few
                   branch_h is the branch's own to far better than c_diff */
                if (!psb__fd_jacobian(&s->prob)) psb__copy(tc, tt, np1);
                if (++advances > 1000) return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "no end point within 1000 steps of branch_h");
            }
        } while (moved);
    } while (h >= s->branch.h_min);
    if (last_fault) return psb__faults_code(s, "Algorithm 2.1");
    if (psb__fd_jacobian(&s->prob)) {
        int smooth = psb__fd_smooth_stall(s, yc, tin, yt, tt);
        if (smooth < 0) return (psb_result)smooth;
        if (smooth) {
            if (++advances > 1000) return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "no end point within 1000 steps of branch_h");
            psb__copy(yc, yt, np1);
            psb__copy(tc, tt, np1);
            psb__copy(tin, tt, np1);
            h = s->branch.h;
            goto follow;
        }
    }
    /* the last step, of h_min, went on along the branch (its tangent within c_diff of the
       one before): no end point here, the branch only turned by more than c_diff's angle
       since y, a curvature where y lay farther up a curved branch than it stays straight.
       Follow it from here with the tangent here (the 1000 moves bound it all) */
    if (turned_only) {
        psb__copy(tin, tc, np1);
        h = s->branch.h;
        turned_only = 0;
        goto follow;
    }
    if (psb__fd_jacobian(&s->prob) && !refined) {
        /* the entering tangent too may come from quotients mixing the pieces (the last couple
           of a trace lies within h_min of the end point): take the branch's tangent 16
           branch_h back, where a difference step meets a piece boundary only if the branch
           runs within ~fd_step / (16 branch_h) radians of it. The point must lie behind and
           the tangent pass the continuation's own test, c_min, against one that may be off
           by more than c_diff allows (central differences: 0.05 rad). When that correction
           fails, 32, 8, 64 and 4 branch_h back; when all fail the call fails: kept, the
           entering tangent was found a second time by the sweep as a new branch */
        static const double backs[5] = {16, 32, 8, 64, 4};
        int i, k, repaired = 0;
        for (k = 0; k < 5 && !repaired; k++) {
            double behind = 0, back = backs[k] * s->branch.h;
            psb__axpy_to(yt, yc, -back, tc, np1);
            psb__copy(tt, tc, np1);
            s->stats.n_pc_steps++;
            r = psb__correct(s, yt, tt, 0, NULL, NULL);
            if (psb__is_fatal(r)) return r;
            if (r != PSB_SUCCESS && psb__correct_fault(s, r)) {
                psb__note_fault(s, r);
                return psb__faults_code(s, "Algorithm 2.1, the tangent behind the end point");
            }
            for (i = 0; i < np1; i++) behind += s->internal_.w[i] * (yc[i] - yt[i]) * tc[i];
            repaired = r == PSB_SUCCESS && behind >= 0.5 * back && psb__cos_w(s, tt, tc) >= s->opt.c_min;
        }
        if (!repaired)
            return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "Algorithm 2.1: no branch tangent behind the end point "
                             "(finite differences; 4 to 64 branch_h back)");
        psb__copy(tc, tt, np1);
        /* With that tangent, once more with difference steps 10^4 times shorter: within a
           step of a piece boundary the quotients mix the pieces and the corrector fails, so
           the pass stopped up to fd_step / sin(the branch's angle with the boundary) short of
           the end point, far beyond h_min; shorter steps (their rounding, about 1e-4 of dH,
           still lets Newton converge) bring that gap under h_min but where the branch runs
           nearly along a boundary. That gap shrinks with the step: what is left of it is
           about 1e-4 of this pass's move (refined_move): the precision adds 1e-2 of it and
           takes 2 h, since the shorter steps still mix the pieces once the trial lies within
           their reach of the boundary (measured on contact systems: under 1.2 h without). */
        fd_cap = HUGE_VAL;
        for (i = 0; i < np1; i++) fd_cap = fmin(fd_cap, 1e-4 * psb__fd_step(s, i, yc[i], 0) * sqrt(s->internal_.w[i]));
        refined = 1;
        psb__copy(tin, tc, np1);
        h = s->branch.h;
        goto follow;
    }
    psb__copy(y, yc, np1);
    psb__copy(t, tc, np1);
    if (precision) *precision = refined ? 2 * h + 1e-2 * refined_move : h;
    s->message[0] = 0;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_locate_end(psb_solver *s, double *y, double *t,
                                        const psb_branch_options *bo, double *precision)
{
    psb_result r = psb__check_couple(s, y, t);
    if (r == PSB_SUCCESS) r = psb__branch_begin(s, bo, y);
    return r == PSB_SUCCESS ? psb__locate_end(s, y, t, precision) : r;
}

/* ==== Algorithm 2.2 (psb_find_branches) =========================================================
   Every branch leaving a nonsmooth point, with its working state in psb__sweep_state
   (memos, cone test, sweep bookkeeping), passed down as an argument. */

/* A 128-bit hash of the n doubles at a (their bits), into key[0] and key[1], which seed it. */
static void psb__hash_doubles(const double *a, size_t n, unsigned long long *key)
{
    /* four lanes, word i in lane i % 4, each a multiply-xorshift chain (a bijection of the
       lane for a given word), so that the chains run side by side; then two 64-bit keys, each
       a splitmix64 finaliser of all four lanes in a different order */
    static const unsigned long long prime[4] = {0x9e3779b97f4a7c15ull, 0xc2b2ae3d27d4eb4full,
                                                0x165667b19e3779f9ull, 0xd6e8feb86659fd93ull};
    unsigned long long lane[4], x;
    size_t i;
    int j;
    for (j = 0; j < 4; j++) lane[j] = key[j & 1] + prime[j];
    for (i = 0; i + 4 <= n; i += 4)
        for (j = 0; j < 4; j++) {
            memcpy(&x, a + i + (size_t)j, sizeof x);
            lane[j] = (lane[j] ^ x) * prime[j];
            lane[j] ^= lane[j] >> 29;
        }
    for (j = 0; i < n; i++, j++) {
        memcpy(&x, a + i, sizeof x);
        lane[j] = (lane[j] ^ x) * prime[j];
        lane[j] ^= lane[j] >> 29;
    }
    for (j = 0; j < 2; j++) {
        unsigned long long z = lane[j] ^ (lane[j + 1] << 17 | lane[j + 1] >> 47) ^
                               (lane[(j + 2) & 3] << 31 | lane[(j + 2) & 3] >> 33) ^
                               (lane[(j + 3) & 3] << 47 | lane[(j + 3) & 3] >> 17) ^ (unsigned long long)n;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        key[j] = z ^ (z >> 31);
    }
}
/* Hashes the dH just formed (psb__jacobian) into key[2]. */
static void psb__jmemo_key(const psb_solver *s, unsigned long long *key)
{
    key[0] = 0xcbf29ce484222325ull;
    key[1] = 0;
    if (s->prob.linear == PSB_LINEAR_DENSE) {
        psb__hash_doubles(s->internal_.jac, (size_t)s->internal_.n * (size_t)s->internal_.np1, key);
    } else {
        psb__hash_doubles(s->internal_.band, (size_t)(s->prob.kl + s->prob.ku + 1) * (size_t)s->internal_.n, key);
        psb__hash_doubles(s->internal_.dparam, (size_t)s->internal_.n, key);
    }
}

/* The Jacobian memo's entry with this key, or -1. */
static int psb__jmemo_find(const psb__sweep_state *sw, const unsigned long long *key)
{
    int m, stored = sw->jmemo_n < sw->memo_cap ? sw->jmemo_n : sw->memo_cap;
    for (m = 0; m < stored; m++)
        if (sw->jmemo_key[2 * m] == key[0] && sw->jmemo_key[2 * m + 1] == key[1]) return m;
    return -1;
}

/* A look-up in the memo (counted for psb__jmemo_hashing): *m the entry under key or -1; 1 with
   its tangent oriented by ref in t, 0 when there is none or ref is (nearly) orthogonal to it
   (then the orientation is the computed tangent's, psb__tangent_from_jacobian, not a sign of
   the dot product). */
static int psb__jmemo_get(psb_solver *s, psb__sweep_state *sw, const unsigned long long *key, const double *ref, double *t, int *m)
{
    int i, np1 = s->internal_.np1;
    const double *tm;
    double dot;
    *m = psb__jmemo_find(sw, key);
    sw->jmemo_looks++;
    sw->jmemo_hits += *m >= 0;
    if (*m < 0) return 0;
    tm = sw->jmemo_t + (size_t)*m * (size_t)np1;
    dot = psb__dot_w(s, tm, ref);
    if (!(fabs(dot) > 1.4901161193847656e-08 * psb__norm_w(s, ref))) return 0;
    for (i = 0; i < np1; i++) t[i] = dot < 0 ? -tm[i] : tm[i];
    return 1;
}

/* Stores the unit tangent t and its outward sign (0: not known) under key (the oldest entry
   makes room when the memo is full). */
static void psb__jmemo_store(psb_solver *s, psb__sweep_state *sw, const unsigned long long *key, const double *t, int sign)
{
    int m = sw->jmemo_n % sw->memo_cap;
    if (sw->frozen) {
        sw->held = 1;
        sw->held_sign = sign;
        sw->held_key[0] = key[0];
        sw->held_key[1] = key[1];
        return;
    }
    sw->jmemo_key[2 * m] = key[0];
    sw->jmemo_key[2 * m + 1] = key[1];
    sw->jmemo_sign[m] = (signed char)sign;
    psb__copy(sw->jmemo_t + (size_t)m * (size_t)s->internal_.np1, t, s->internal_.np1);
    sw->jmemo_n++;
}

/* Whether the memo keys by dH's hash: it can (analytic dH, dense or banded), and it pays. A
   memo that rarely hits (sample points mostly in pieces of their own, as on the block) costs a
   hash per tangent for nothing: after 64 look-ups in a call, it needs a hit in 8. */
static int psb__jmemo_hashing(const psb__sweep_state *sw)
{
    return sw->jmemo_dh && !(sw->jmemo_looks >= 64 && 8 * sw->jmemo_hits < sw->jmemo_looks);
}

/* The memo's key of the piece at y (problem.piece, set), *known 0 when the callback knows no
   id there (> 0). */

/* The piece id of y from problem.piece, as a memo key (*known 0: the callback named none). */
static psb_result psb__piece_key(psb_solver *s, const double *y, unsigned long long *key, int *known)
{
    int rc = s->prob.piece(y, key, s->prob.user);
    if (rc < 0) return psb__callback_code(s, rc, "piece callback returned a negative value");
    key[1] = 0x9e3779b97f4a7c15ull; /* never a dH hash: those memos are not mixed */
    *known = rc == 0;
    if (!*known) key[0] = key[1] = 0;
    return PSB_SUCCESS;
}

static int psb__trial_known(const psb_solver *s, const psb__sweep_state *sw, const double *x,
                            const double *ts, int n_ts, const double *done, int own);

/* An Algorithm 2.2 trial's watch on the corrector (psb__try_tangent): it records the tangents
   of the trial's iterates (path), cuts the trial once one of them is a tangent whose trial is
   known (psb__path_memo_cut, psb__trial_known), stores the tangents it computes in the
   Jacobian memo, and, with y0 set, runs the conic test (psb__conic_excess): every iterate of
   a run on pieces conic about y0, which makes a trial that failed there fail at every smaller
   step as well. */
typedef struct psb__trial_watch {
    psb__corr_watch base;
    psb__sweep_state *sw; /* the run's memos (psb_find_branches) */
    const double *ts;  /* the found branches' tangents, nts of them */
    int nts, own;      /* and the trial's own known entry (-1: none), for the cut */
    const double *y0;  /* the point for the conic test (NULL: none) */
    int conic_ok;      /* every iterate of the current run passed the conic test */
    int armed;         /* the test runs: a step of the trial was rejected already */
    int path_n;        /* tangents recorded in sw->path for the current step */
    unsigned long long store_key[2], dh_key[2]; /* the current iterate's memo key, dH's hash */
    int by_piece;      /* store_key is a piece id */
    int pmemo_check;   /* the next tangent is compared with the piece memo's (BR_MT) */
    /* on a frozen sw: the memo entry each path tangent would have made (psb__task_trials) */
    int path_held[PSB__PATH_MAX], path_sign[PSB__PATH_MAX];
    unsigned long long path_key[2 * PSB__PATH_MAX];
} psb__trial_watch;

/* Whether a piece's tangent may decide (psb__path_memo_cut): the memo's pieces checked that
   many times and found nearly linear. */
static int psb__pmemo_trusted(const psb_solver *s, const psb__sweep_state *sw, int checks)
{
    return sw->pmemo_checks >= checks && sw->pmemo_drift <= acos(s->opt.c_diff) / 8;
}

/* The memo's cut of an Algorithm 2.2 trial (watched by tw) at its corrector iterate y, bordered by
   t: the tangent this iteration would compute is the unit kernel of dH(y), oriented by t, and
   Algorithm 2.2's memo (psb__sample_tangent) may hold it already, keyed by y's piece id
   (before dH is formed, dh_key NULL; *by_piece set when the callback gave one) or by dH's
   hash (dh_key, of the dH just formed; *by_piece as the first call left it). If that
   tangent's trial is known, the corrector's cut (psb__correct_run) applies without the
   factorisation. As with sample tangents, the memo's tangent only decides this skip.
   A dH hash gives the tangent of the same dH. A piece id gives one from another point of the
   piece, which is the tangent here only where H is nearly linear across the piece; on a curved
   piece the wrong verdict can cost a branch. So a piece's tangent decides a cut only after the memo has met
   4 tangents computed at trial iterates of pieces it held, and found them all within an
   eighth of c_diff's angle of its own (pmemo_drift, measured by the corrector).
   key gets the key under which the corrector stores the tangent it computes (zero when there
   is none or the memo holds it).
   Returns 1 (cut), 0, or a fatal or fault code from the piece callback (< 0). */
static int psb__path_memo_cut(psb_solver *s, psb__trial_watch *tw, const double *y, const double *t,
                              const unsigned long long *dh_key)
{
    psb__sweep_state *sw = tw->sw;
    unsigned long long *key = tw->store_key;
    int *by_piece = &tw->by_piece;
    int m, got;
    double *x = PSB__VEC(s, PSB__V_BR_MT);
    if (!dh_key) {
        psb_result r;
        key[0] = key[1] = 0;
        *by_piece = 0;
        if (!s->prob.piece) return 0;
        r = psb__piece_key(s, y, key, by_piece);
        if (r != PSB_SUCCESS) return r;
        if (!*by_piece) return 0;
    } else {
        if (*by_piece || !psb__jmemo_hashing(sw)) return 0;
        key[0] = dh_key[0];
        key[1] = dh_key[1];
    }
    got = psb__jmemo_get(s, sw, key, t, x, &m);
    if (m >= 0) key[0] = key[1] = 0; /* held already: nothing to store */
    if (!got) return 0;
    if (*by_piece && !psb__pmemo_trusted(s, sw, 4)) {
        tw->pmemo_check = 1; /* no cut yet: the watch compares the next tangent with x */
        return 0;
    }
    return psb__trial_known(s, sw, x, tw->ts, tw->nts, NULL, tw->own);
}

/* How far from cones about y0 Algorithm 2.2's trials may see H before the run is made again
   with a smaller h_init (psb__find_branches): a landing point's chord from y0 against its
   tangent (radians), or an iterate's psb__conic_excess. */
#define PSB__CHORD_TURN 0.05

/* Whether Algorithm 2.2's run still watches for H off the cones about y0 (cone_defect): H(y0)
   is held, the evidence is not in yet, and a rerun could still follow (h_init / 16 stays above
   8 h, psb__find_branches). */
static int psb__cone_watched(const psb_solver *s, const psb__sweep_state *sw)
{
    return sw->conic_h0_ok && sw->cone_defect <= PSB__CHORD_TURN &&
           s->branch.h_init / 16 >= 8 * s->branch.h;
}

/* Records an excess of psb__conic_excess in cone_defect (HUGE_VAL, no scale, tells nothing). */
static void psb__note_cone_excess(psb__sweep_state *sw, double excess)
{
    if (excess > sw->cone_defect && excess < HUGE_VAL) sw->cone_defect = excess;
}

/* How far H is from affine through y0 at a point y of an Algorithm 2.2 trial whose dH(y) was
   just formed and H(y) is in res: the largest row error of H(y) = H(y0) + dH(y) (y - y0)
   beyond rounding (1024 eps times the terms' magnitudes |dH| (|y| + |y0|) + |H(y)| +
   |H(y0)|), relative to the step's own scale max_i (|dH| |y - y0|)_i; HUGE_VAL for NaN, or
   for an error where the step has no scale. The conic test of the trials
   (psb__try_tangent), first half, asks at most 10^-6: y0 lies within Algorithm 2.1's
   precision of the kink, not on it, and its pieces' affine maps meet there to that order;
   Algorithm 2.2's rerun asks more (psb__cone_tolerance). The conic test's second half
   (psb__correct_run, with dH(y)'s hash): dH is the same, bit for bit, at the point of the
   segment from y0 to y at distance s->branch.h from y0. Pieces of a
   piecewise-linear H are polyhedra, convex where one selection of its affine parts holds, so
   the whole segment then lies in y's piece, and a run scaled towards y0 meets the same dH and
   the same H scaled: the same run. */
static double psb__conic_excess(const psb_solver *s, const double *y0, const double *y)
{
    int n = s->internal_.n, np1 = s->internal_.np1, i, j;
    const double *h0 = PSB__VEC(s, PSB__V_BR_H0);
    double excess = 0, step = 0; /* the largest row error beyond rounding, and row size */
    for (i = 0; i < n; i++) {
        double sum = 0, size = 0, scale = fabs(s->internal_.res[i]) + fabs(h0[i]);
        if (s->prob.linear == PSB_LINEAR_DENSE) {
            for (j = 0; j < np1; j++) {
                double a = s->internal_.jac[(size_t)i + (size_t)j * (size_t)n];
                sum += a * (y[j] - y0[j]);
                size += fabs(a * (y[j] - y0[j]));
                scale += fabs(a) * (fabs(y[j]) + fabs(y0[j]));
            }
        } else {
            int kl = s->prob.kl, ku = s->prob.ku, ld = kl + ku + 1, p = s->prob.param_index;
            int lo = i - kl > 0 ? i - kl : 0, hi = i + ku < n - 1 ? i + ku : n - 1;
            for (j = lo; j <= hi; j++) { /* state column j is y component j, or j + 1 past p */
                int c = j < p ? j : j + 1;
                double a = s->internal_.band[PSB_BAND_INDEX(ku, ld, i, j)];
                sum += a * (y[c] - y0[c]);
                size += fabs(a * (y[c] - y0[c]));
                scale += fabs(a) * (fabs(y[c]) + fabs(y0[c]));
            }
            sum += s->internal_.dparam[i] * (y[p] - y0[p]);
            size += fabs(s->internal_.dparam[i] * (y[p] - y0[p]));
            scale += fabs(s->internal_.dparam[i]) * (fabs(y[p]) + fabs(y0[p]));
        }
        sum = fabs(s->internal_.res[i] - h0[i] - sum) - 1024 * DBL_EPSILON * scale;
        if (isnan(sum)) return HUGE_VAL;
        if (sum > excess) excess = sum;
        if (size > step) step = size;
    }
    return step > 0 ? excess / step : excess > 0 ? HUGE_VAL : 0;
}


static int psb__trial_watch_fn(psb__corr_watch *w, psb_solver *s, psb__corr_event e,
                               const double *y, const double *t, int sign)
{
    psb__trial_watch *tw = (psb__trial_watch *)(void *)w;
    psb__sweep_state *sw = tw->sw;
    int np1 = s->internal_.np1, i, cut = 0;
    switch (e) {
    case PSB__CORR_STEP:
        tw->path_n = 0; /* the path of this step alone */
        return 0;
    case PSB__CORR_START:
        tw->conic_ok = tw->y0 != NULL && tw->armed;
        return 0;
    case PSB__CORR_ITERATE:
        tw->pmemo_check = 0;
        tw->store_key[0] = tw->store_key[1] = tw->dh_key[0] = tw->dh_key[1] = 0;
        tw->by_piece = 0;
        cut = psb__path_memo_cut(s, tw, y, t, NULL);
        break;
    case PSB__CORR_JACOBIAN:
        if (tw->conic_ok || (!tw->by_piece && psb__jmemo_hashing(sw))) psb__jmemo_key(s, tw->dh_key);
        if (tw->y0) { /* before the memo's cut, which the test may void */
            int watch = psb__cone_watched(s, sw) && psb__dist_w(s, y, tw->y0) <= 2 * s->branch.h_init;
            if (tw->conic_ok || watch) {
                double excess = psb__conic_excess(s, tw->y0, y);
                if (tw->conic_ok) tw->conic_ok = excess <= 1e-6;
                if (watch) psb__note_cone_excess(sw, excess);
            }
        }
        cut = psb__path_memo_cut(s, tw, y, t, tw->dh_key);
        break;
    case PSB__CORR_SOLVED:
        if (tw->conic_ok) { /* the point s->branch.h from y0 towards this iterate */
            double dist = psb__dist_w(s, y, tw->y0), *pe = PSB__VEC(s, PSB__V_BR_PE);
            tw->conic_ok = dist > s->branch.h;
            for (i = 0; i < np1 && tw->conic_ok; i++)
                pe[i] = tw->y0[i] + s->branch.h / dist * (y[i] - tw->y0[i]);
        }
        return 0;
    case PSB__CORR_TANGENT:
        i = tw->path_n < PSB__PATH_MAX ? tw->path_n++ : -1;
        if (i >= 0) psb__copy(sw->path + (size_t)i * (size_t)np1, t, np1);
        sw->held = 0;
        if ((tw->store_key[0] || tw->store_key[1]) && (!tw->by_piece || psb__pmemo_trusted(s, sw, 0)))
            psb__jmemo_store(s, sw, tw->store_key, t, sign);
        if (i >= 0) {
            tw->path_held[i] = sw->held;
            tw->path_sign[i] = sw->held_sign;
            tw->path_key[2 * i] = sw->held_key[0];
            tw->path_key[2 * i + 1] = sw->held_key[1];
        }
        if (tw->pmemo_check) {
            double drift = psb__angle_w(s, t, PSB__VEC(s, PSB__V_BR_MT));
            tw->pmemo_check = 0;
            sw->pmemo_checks++;
            if (!(drift <= sw->pmemo_drift)) sw->pmemo_drift = drift; /* NaN: never cuts */
        }
        return psb__trial_known(s, sw, t, tw->ts, tw->nts, NULL, tw->own);
    case PSB__CORR_CORRECTED:
        if (tw->conic_ok) { /* psb__conic_excess's second half */
            unsigned long long key[2] = {0, 0};
            psb_result r = psb__jacobian(s, PSB__VEC(s, PSB__V_BR_PE), NULL);
            if (psb__is_fatal(r)) return r;
            if (r == PSB_SUCCESS) psb__jmemo_key(s, key);
            tw->conic_ok = r == PSB_SUCCESS && key[0] == tw->dh_key[0] && key[1] == tw->dh_key[1];
        }
        return 0;
    case PSB__CORR_REJECTED:
        /* a trial that failed for the curve's sake on H conic about y0: no convergence, or
           the jump or cosine test, where every iterate passed both halves of the conic test
           (a turn ends the run before its last iterate's second half) */
        if (tw->y0 && tw->conic_ok &&
            (s->internal_.last_fail == PSB__FAIL_CONVERGE || s->internal_.last_fail == PSB__FAIL_COSINE))
            return 1;
        /* the test costs a Jacobian and two hashes per iteration: only for trials that have
           failed once (most trials land, or are cut, at their first step) */
        tw->armed = tw->y0 != NULL;
        return 0;
    }
    if (cut > 0) sw->memo_cuts++;
    return cut;
}

/* A watch for a trial of the run sw from y0 (conic test with y0; NULL: none) that cuts on the found
   branches' tangents ts (nts of them) and the trial's own known entry own (-1: none). */
static void psb__trial_watch_init(psb__trial_watch *tw, psb__sweep_state *sw, const double *ts,
                                  int nts, int own, const double *y0)
{
    memset(tw, 0, sizeof *tw);
    tw->base.fn = psb__trial_watch_fn;
    tw->sw = sw;
    tw->ts = ts;
    tw->nts = nts;
    tw->own = own;
    tw->y0 = y0;
}

/* The tangent at sample point pt, formed there. With finite differences the steps stay below
   s->branch.h / 1000: a step that crosses a piece boundary mixes the pieces, with odds ~ step /
   branch_h, and near the end point H is small, so the quotients' rounding error, ~ eps |H| /
   step, stays small too. */
static psb_result psb__sample_tangent_at(psb_solver *s, const double *pt, const double *ref, double *t)
{
    return psb__tangent_capped(s, pt, ref, t, 1e-3 * s->branch.h);
}

/* Records psb__conic_excess at p, the screening point of an Algorithm 2.2 trial from
   y0 (NULL: nothing to do), in cone_defect; dH(p) was just formed (psb__sample_tangent). The
   screen takes the tangent at p for the trial's, which holds on cones about y0 alone, and p
   may lie beyond a kink that the trial's own iterates never meet (a kink nearer y0 than
   h_init: branches lost, every trial cut). Only while the run watches
   (psb__cone_watched). It costs H(p). Returns PSB_SUCCESS or a fatal code; a fault is noted. */
static psb_result psb__probe_cone(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *p)
{
    psb_result r;
    if (!y0 || !psb__cone_watched(s, sw)) return PSB_SUCCESS;
    r = psb__residual(s, p, s->internal_.res);
    if (r != PSB_SUCCESS) {
        if (psb__is_fatal(r)) return r;
        psb__note_fault(s, r);
        return PSB_SUCCESS;
    }
    psb__note_cone_excess(sw, psb__conic_excess(s, y0, p));
    return PSB_SUCCESS;
}

/* The tangent at a sample point pt of Algorithm 2.2 (oriented by ref). Difference steps there
   stay below s->branch.h / 1000 (section 1).
   Jacobian memo (analytic dH, dense or banded storage): the unit kernel of dH is a function of
   dH alone, and on a piecewise-linear H every sample point of a piece has the same dH, bit for
   bit. So dH is hashed (128 bits from all its entries, dH/dparameter included:
   psb__hash_doubles) and a dH seen before in this call gives its tangent again, oriented by
   ref, without a factorisation (stats.n_tangent_reused, *from_memo set: 1, or 2 when a piece
   id gave it; with from_memo NULL
   the tangent is always computed, and remembered). A reused tangent differs from a recomputed
   one by rounding (the bordering row differs), which on degenerate problems (crossing kinks,
   whose sample points can fall on piece boundaries) can steer a sweep elsewhere: so a reused
   tangent only decides skips (a tangent tried before, a trial whose outcome is known, the region of
   the previous direction), and a tangent that goes on to be used is recomputed from the same
   dH (psb__sample_refresh). Idle spans and screened trials on piecewise-linear problems then
   cost Jacobian evaluations only, and the sweep is the one without the memo.
   Piece memo (problem.piece set, any Jacobian and backend): the key is the piece's id, and
   neither dH nor its factors are formed on a hit. Where H is smooth but not linear within a
   piece (the block), two sample points of one piece near y0 have tangents a turn of about
   curvature times their distance apart (at most 2 h_init), far below c_diff's angle on
   problems where Algorithm 2.2 can tell branches apart at all; the skips it decides are
   those of the tangent at the first point, and a tangent that goes on to be used is computed
   at its own point. */
static psb_result psb__sample_tangent(psb_solver *s, psb__sweep_state *sw, const double *pt, const double *ref, double *t,
                                      int *from_memo, const double *cone_y0)
{
    psb_result r;
    unsigned long long key[2];
    int m, by_piece = s->prob.piece != NULL;
    if (from_memo) *from_memo = 0;
    if (by_piece) {
        r = psb__piece_key(s, pt, key, &by_piece);
        if (r != PSB_SUCCESS) return r;
    }
    if (!by_piece && !psb__jmemo_hashing(sw)) return psb__sample_tangent_at(s, pt, ref, t);
    if (!by_piece) {
        s->stats.n_tangents++;
        r = psb__jacobian(s, pt, NULL);
        if (r != PSB_SUCCESS) return r;
        psb__jmemo_key(s, key);
        r = psb__probe_cone(s, sw, cone_y0, pt);
        if (r != PSB_SUCCESS) return r;
    }
    if (psb__jmemo_get(s, sw, key, ref, t, &m) && from_memo) {
        s->stats.n_tangent_reused++;
        s->internal_.n_ok++;
        *from_memo = by_piece ? 2 : 1;
        return PSB_SUCCESS;
    }
    r = by_piece ? psb__sample_tangent_at(s, pt, ref, t) : psb__tangent_from_jacobian(s, ref, t);
    if (r == PSB_SUCCESS && m < 0) psb__jmemo_store(s, sw, key, t, s->internal_.tangent_sign);
    return r;
}

/* The tangent at the sample point pt that psb__sample_tangent just took from its memo
   (from_memo, its output), computed afresh (with ref's bordering, as without the memo): from
   the dH formed there, or, when a piece id gave it (2), at pt itself. */
static psb_result psb__sample_refresh(psb_solver *s, int from_memo, const double *pt, const double *ref,
                                      double *t)
{
    if (from_memo == 2) return psb__sample_tangent_at(s, pt, ref, t);
    s->stats.n_tangents++;
    return psb__tangent_from_jacobian(s, ref, t);
}

/* Whether t is within c_diff of a tangent tried before in this call (the memo). */
static int psb__memo_seen(const psb_solver *s, const psb__sweep_state *sw, const double *t)
{
    int m, stored = sw->memo_n < sw->memo_cap ? sw->memo_n : sw->memo_cap;
    double nt = psb__norm_w(s, t);
    for (m = 0; m < stored; m++)
        if (fabs(psb__cos_w_na(s, t, nt, sw->memo + (size_t)m * (size_t)s->internal_.np1)) >= s->opt.c_diff) return 1;
    return 0;
}

/* Whether a trial along the unit direction x would repeat one whose outcome is known: x is
   within c_diff of a found branch's tangent (the trial lands on that branch), of a direction
   whose trial was made (known, entry `own` left out: -1 or the trial asking), of `done` (NULL
   or the current tangent's sign already handled), or, either way round, of a tangent handled
   before (memo). */
static int psb__trial_known(const psb_solver *s, const psb__sweep_state *sw, const double *x, const double *ts, int n_ts,
                            const double *done, int own)
{
    int m, np1 = s->internal_.np1, stored = sw->known_n < sw->memo_cap ? sw->known_n : sw->memo_cap;
    double nx = psb__norm_w(s, x);
    for (m = 0; m < n_ts; m++)
        if (psb__cos_w_na(s, x, nx, ts + (size_t)m * (size_t)np1) >= s->opt.c_diff) return 1;
    for (m = 0; m < stored; m++)
        if (m != own && psb__cos_w_na(s, x, nx, sw->known + (size_t)m * (size_t)np1) >= s->opt.c_diff)
            return 1;
    if (done && psb__cos_w_na(s, x, nx, done) >= s->opt.c_diff) return 1;
    return psb__memo_seen(s, sw, x);
}

/* Adds x to one of psb_find_branches' stores (memo or known, *count entries so far); when
   full, the oldest entry makes room. */
static void psb__store_add(const psb_solver *s, const psb__sweep_state *sw, double *store, int *count, const double *x)
{
    psb__copy(store + (size_t)(*count % sw->memo_cap) * (size_t)s->internal_.np1, x, s->internal_.np1);
    (*count)++;
}

/* The faults counted so far into a branching report. */
static void psb__report_faults(const psb_solver *s, psb_branch_report *rep)
{
    rep->n_failed_callback = s->internal_.faults[0];
    rep->n_failed_nonfinite = s->internal_.faults[1];
    rep->n_failed_singular = s->internal_.faults[2];
    rep->n_failed = s->internal_.faults[0] + s->internal_.faults[1] + s->internal_.faults[2];
}

/* The angle between t and the chord from y0 to y (at distance d > 0), whose unit vector goes
   to c. */
static double psb__chord_angle(const psb_solver *s, const double *y0, const double *y, double d,
                               const double *t, double *c)
{
    int k;
    for (k = 0; k < s->internal_.np1; k++) c[k] = (y[k] - y0[k]) / d;
    return psb__angle_w(s, c, t);
}

/* Step 5(ii) on a curved branch: whether the landing point yb (tangent tb there) lies on
   found branch j although tb and ts_j differ by more than c_diff. Over a distance d a branch
   of curvature kappa turns its tangent by kappa d, and the chord from y0 leaves the tangent at
   its far end by about kappa d / 2 =: a. Tangents taken at different distances from y0 can so
   differ by up to 2 (a_b + a_j), and the trial's landing point lies anywhere from h to h_init
   away: c_diff alone makes two branches of one. Within 4 (a_b + a_j) beyond c_diff's angle
   the crossings of the sphere ||y - y0||_w = d = ||yb - y0||_w decide, as in
   psb_branch_point_switch: Newton on it from y0 + d u_j (u_j the chord to ys_j, ts_j when
   ys_j = y0) lands where branch j crosses it, which is yb when they are one branch (within
   d sqrt(2 (1 - c_diff))). Straight branches (chord along the tangent) skip the test, so
   piecewise-linear problems keep their results and cost. Returns 1 (same), 0, or a fatal
   code (< 0). */
static int psb__same_curved_branch(psb_solver *s, const double *y0, const double *yb, const double *tb,
                                   const double *ysj, const double *tsj)
{
    int np1 = s->internal_.np1, k;
    double *z = PSB__VEC(s, PSB__V_BR_S), d = psb__dist_w(s, yb, y0), dj = psb__dist_w(s, ysj, y0);
    double a_b, a_j = 0;
    psb_result r;
    if (!(d > 0)) return 0;
    /* tb and ts_j point away from y0, as the chords do */
    a_b = psb__chord_angle(s, y0, yb, d, tb, z);
    if (dj > 0.5 * s->branch.h) {
        a_j = psb__chord_angle(s, y0, ysj, dj, tsj, z);
    } else {
        psb__copy(z, tsj, np1);
        psb__normalize_w(s, z);
    }
    if (!(psb__angle_w(s, tb, tsj) <= acos(s->opt.c_diff) + 4 * (a_b + a_j))) return 0;
    for (k = 0; k < np1; k++) z[k] = y0[k] + d * z[k];
    r = psb__newton_on(s, z, NULL, y0, NULL, d);
    if (psb__is_fatal(r)) return r;
    if (r != PSB_SUCCESS) {
        /* a fault leaves the verdict open: the reported set may hold one branch twice */
        if (r == PSB_ERR_CALLBACK_FAILED || r == PSB_ERR_NONFINITE) psb__note_fault(s, r);
        return 0;
    }
    return psb__dist_w(s, z, yb) <= d * sqrt(2 * (1 - s->opt.c_diff));
}

/* Appends the branch (yb, tb) to (ys, ts), or sets *overflow when there is no room. */
static void psb__add_branch(const psb_solver *s, const double *yb, const double *tb, int max_branches, double *ys,
                            double *ts, psb_branch_report *rep, int *overflow)
{
    int np1 = s->internal_.np1;
    if (rep->n_branches >= max_branches) {
        *overflow = 1;
        return;
    }
    psb__copy(ys + (size_t)rep->n_branches * (size_t)np1, yb, np1);
    psb__copy(ts + (size_t)rep->n_branches * (size_t)np1, tb, np1);
    rep->n_branches++;
}

/* Step 5 for a trial from y0 that landed at yb with tangent tb (turned away from y0 here): a new
   branch into (ys, ts) unless it lies within h of y0 or is a found one (*overflow when there is
   no room). Returns PSB_SUCCESS or a fatal code. */
static psb_result psb__take_landing(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *yb,
                                    double *tb, int max_branches, double *ys, double *ts,
                                    psb_branch_report *rep, int *overflow)
{
    int np1 = s->internal_.np1, j, k, is_new = 1;
    double *pk = PSB__VEC(s, PSB__V_BR_S), dotp = 0, turn, dist = psb__dist_w(s, yb, y0);
    /* a point closer to y0 than the sampling distance h tells nothing reliable about the
       branches: pieces that touch the end point are active there */
    if (dist < s->branch.h) return PSB_SUCCESS;
    /* Step 5(i): orient away from the point */
    for (k = 0; k < np1; k++) dotp += s->internal_.w[k] * tb[k] * (yb[k] - y0[k]);
    if (dotp < 0)
        for (k = 0; k < np1; k++) tb[k] = -tb[k];
    turn = psb__chord_angle(s, y0, yb, dist, tb, pk);
    if (turn > sw->chord_turn_max) sw->chord_turn_max = turn;
    if (turn < sw->chord_turn_min) sw->chord_turn_min = turn;
    /* Step 5(ii): a new branch unless it is within c_diff of a known one */
    for (j = 0; j < rep->n_branches; j++)
        if (psb__cos_w(s, tb, ts + (size_t)j * (size_t)np1) >= s->opt.c_diff) is_new = 0;
    for (j = 0; j < rep->n_branches && is_new; j++) {
        int same = psb__same_curved_branch(s, y0, yb, tb, ys + (size_t)j * (size_t)np1,
                                           ts + (size_t)j * (size_t)np1);
        if (same < 0) return (psb_result)same;
        is_new = !same;
    }
    if (!is_new) return PSB_SUCCESS;
    psb__add_branch(s, yb, tb, max_branches, ys, ts, rep, overflow);
    return PSB_SUCCESS;
}

/* After a trial from y0 that landed at (yb, tb) or was cut (cut): the n tangents of its path
   (path, n + 1 apart) are known, and a landing goes to Step 5 (psb__take_landing). */
static psb_result psb__trial_done(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *path, int n,
                                  int cut, const double *yb, double *tb, int max_branches, double *ys, double *ts,
                                  psb_branch_report *rep, int *overflow)
{
    int j, np1 = s->internal_.np1;
    for (j = 0; j < n; j++) {
        const double *ki = path + (size_t)j * (size_t)np1;
        if (!psb__trial_known(s, sw, ki, ts, rep->n_branches, NULL, -1)) psb__store_add(s, sw, sw->known, &sw->known_n, ki);
    }
    return cut ? PSB_SUCCESS : psb__take_landing(s, sw, y0, yb, tb, max_branches, ys, ts, rep, overflow);
}

/* Steps 5-7 of Algorithm 2.2 for the tangent tt: trial steps from y0 along +tt and -tt, and
   a new branch for each that converges away from y0 in a direction no known branch has.
   Skipped when tt was tried before in this call (memo). Stops before a trial when the n_pc
   budget is spent.
   Screening (no_screen = 0). Near y0 the pieces are, to first order, cones with apex
   y0, H = dH_R (y - y0) on piece R. A trial along x starts at p = y0 + h x; its first
   corrector iteration, bordered by x, moves along dH(p) d = H(p), <x, d>_w = 0, to
   y0 + (h / <x, k>_w) k, k the unit kernel of dH(p) (oriented by x), and borders the next
   iteration by k. A trial along k starts at y0 + h k bordered by k: the same state, scaled.
   Cones scale, so from there both trials make the same iterations scaled, and one that lands
   on a branch within the acceptance distance lands on the same ray as the other (the trial
   along x, with the longer path, accepts no more). So k, a tangent at p costing one
   factorisation, stands for the trial: when k's trial is known (psb__trial_known) the trial is
   skipped (report.n_screened), otherwise the trial is made along k and k remembered, and so
   are the tangents of its corrector iterations when it lands (the same argument, iteration
   by iteration). On smooth pieces the argument holds to O(h); the figures are in
   docs/branching-notes.md. */
static psb_result psb__try_tangent(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *tt,
                                   int max_branches, double *ys, double *ts,
                                   psb_branch_report *rep, int *overflow)
{
    int np1 = s->internal_.np1, k, sign, iters, cut, from_memo, own, watched;
    long memo_cuts;
    psb__trial_watch tw;
    double *yb = PSB__VEC(s, PSB__V_BR_Y), *tb = PSB__VEC(s, PSB__V_BR_T);
    double *pk = PSB__VEC(s, PSB__V_BR_S), *kx = PSB__VEC(s, PSB__V_BR_K);
    psb_result r;
    /* the trials from y0 along +-tt depend on y0 and tt alone: a tangent within c_diff of one
       tried before in this call (any span) repeats its trials and their verdict */
    if (!s->branch.expert.no_memo && psb__memo_seen(s, sw, tt)) {
        rep->n_memo++;
        return PSB_SUCCESS;
    }
    for (sign = 1; sign >= -1; sign -= 2) {
        double hh = s->branch.h_init;
        own = -1;
        for (k = 0; k < np1; k++) tb[k] = sign * tt[k];
        if (s->branch.max_pc && rep->n_pc >= s->branch.max_pc) return PSB_SUCCESS;
        if (!s->branch.expert.no_screen) {
            psb__axpy_to(pk, y0, hh, tb, np1);
            rep->n_tangents++;
            r = psb__sample_tangent(s, sw, pk, tb, kx, &from_memo, y0);
            if (psb__is_fatal(r)) return r;
            /* no tangent at p (singular there): the trial along tb as printed */
            if (r == PSB_SUCCESS) {
                if (psb__trial_known(s, sw, kx, ts, rep->n_branches, sign < 0 ? tt : NULL, -1)) {
                    rep->n_screened++;
                    continue;
                }
                if (from_memo) {
                    r = psb__sample_refresh(s, from_memo, pk, tb, kx);
                    if (psb__is_fatal(r)) return r;
                }
            }
            if (r == PSB_SUCCESS) {
                own = sw->known_n % sw->memo_cap;
                psb__store_add(s, sw, sw->known, &sw->known_n, kx);
                psb__copy(tb, kx, np1);
            }
        }
        psb__copy(yb, y0, np1);
        rep->n_pc++;
        /* not with finite differences: the corrector's quotients (steps not held below
           branch_h / 1000 as at sample points) can mix the pieces at its iterates, and
           recorded paths then cost branches */
        watched = !s->branch.expert.no_screen && !psb__fd_jacobian(&s->prob);
        psb__trial_watch_init(&tw, sw, ts, rep->n_branches, own, sw->conic_h0_ok ? y0 : NULL);
        memo_cuts = sw->memo_cuts;
        r = psb__try_step_from(s, yb, tb, &hh, s->branch.expert.trial_h_min, &iters, y0,
                               watched ? &tw.base : NULL);
        rep->n_cut_memo += sw->memo_cuts - memo_cuts;
        if (psb__is_fatal(r)) return r;
        if (psb__note_fault(s, r)) continue;
        /* cut at iteration i: the trial is then a trial along k_i scaled up, whose outcome is
           known (k_i passes the screen): it lands on a found branch, or repeats a trial made
           before, which found no branch that is not known now; having spent i iterations it
           can do no better. Nor can the trials along its k_j, j < i: they are known too */
        cut = r != PSB_SUCCESS && s->internal_.last_fail == PSB__FAIL_KNOWN;
        rep->n_cut += cut;
        if (r != PSB_SUCCESS && !cut) continue;
        /* after iteration i the trial is in the state a trial along its tangent k_i starts
           in, scaled up: that trial would land on the same ray, sooner and nearer, so the
           k_i of a trial that landed or was cut are known too (a failed trial's are not: with
           i more iterations to spare the trial along k_i might converge) */
        r = psb__trial_done(s, sw, y0, sw->path, watched ? tw.path_n : 0, cut, yb, tb, max_branches, ys, ts, rep,
                            overflow);
        if (r != PSB_SUCCESS) return r;
    }
    if (!s->branch.expert.no_memo) psb__store_add(s, sw, sw->memo, &sw->memo_n, tt);
    return PSB_SUCCESS;
}

/* The outward sign sgn det [dH; (W t)^T] of the branch (p, t) from Algorithm 2.2's memo: the
   entry of p's piece (problem.piece) or of dH(p) (the Jacobian memo), when its sign is known
   and its tangent lies along t (on a piece of a piecewise-linear H it is t's, up to
   orientation; on a smooth piece near y0 nearly so, and the sign holds short of a fold).
   *sign 0 otherwise. Returns PSB_SUCCESS or a fatal code (a failing evaluation tells nothing). */
static psb_result psb__memo_sign(psb_solver *s, psb__sweep_state *sw, const double *p, const double *t, int *sign)
{
    unsigned long long key[2];
    int m, known = 0, np1 = s->internal_.np1;
    double dot;
    psb_result r;
    *sign = 0;
    if (sw->jmemo_n == 0) return PSB_SUCCESS;
    if (s->prob.piece) {
        r = psb__piece_key(s, p, key, &known);
        if (r != PSB_SUCCESS) return psb__is_fatal(r) ? r : PSB_SUCCESS;
    }
    if (!known) {
        if (!psb__jmemo_usable(&s->prob)) return PSB_SUCCESS;
        r = psb__jacobian(s, p, NULL);
        if (r != PSB_SUCCESS) return psb__is_fatal(r) ? r : PSB_SUCCESS;
        psb__jmemo_key(s, key);
    }
    m = psb__jmemo_find(sw, key);
    if (m < 0 || !sw->jmemo_sign[m]) return PSB_SUCCESS;
    dot = psb__cos_w(s, sw->jmemo_t + (size_t)m * (size_t)np1, t);
    if (fabs(dot) >= s->opt.c_diff) *sign = dot > 0 ? sw->jmemo_sign[m] : -sw->jmemo_sign[m];
    return PSB_SUCCESS;
}

/* Whether the branches found (ys, ts: outward tangents, branch 0 the incoming one, ys[0] = y0)
   cannot be all of them: an odd count (section 6, "An odd count"), or an even one whose
   outward signs sgn det [dH; (W t)^T] do not add up to 0, as those of a complete set do
   (section 6, PC1). Dense and banded backends: each branch's sign once (branch_sign), at its
   landing point (branch 0's on its tangent, as far from y0 as branch 1's): from the memo where
   the point's piece or dH has an entry of known sign (psb__memo_sign), else by a bordered
   factorisation there, difference steps as at sample points. Where a sign cannot be told
   (user backend, over 64 branches, a failing evaluation or factorisation) the count alone
   decides. A fatal code goes to *fatal (and 0 is returned). */
static int psb__unbalanced(psb_solver *s, psb__sweep_state *sw, const double *ys, const double *ts, int n_branches,
                           psb_result *fatal)
{
    int np1 = s->internal_.np1, j, sum = 0;
    if (n_branches % 2 != 0) return 1;
    if (s->prob.linear == PSB_LINEAR_USER || n_branches > 64 || sw->branch_signs_n < 0) return 0;
    for (j = sw->branch_signs_n; j < n_branches; j++) {
        const double *tj = ts + (size_t)j * (size_t)np1, *p = ys + (size_t)j * (size_t)np1;
        psb__mon m;
        psb_result r;
        int sign = 0;
        if (j == 0) {
            double d = psb__dist_w(s, ys + np1, ys), *q = PSB__VEC(s, PSB__V_BR_S);
            psb__axpy_to(q, ys, d > 0 ? d : s->branch.h, tj, np1);
            p = q;
        }
        r = psb__memo_sign(s, sw, p, tj, &sign);
        if (r == PSB_SUCCESS && !sign) { /* difference steps below h / 1000, as at sample points */
            r = psb__monitor_at(s, p, tj, &m, 1e-3 * s->branch.h);
            /* banded factors of an exactly singular A tell no sign (psb__monitor's -700) */
            if (r == PSB_SUCCESS && !(m.logabs[0] > -700)) r = PSB_ERR_SINGULAR;
            if (r == PSB_SUCCESS) sign = m.sign[0] < 0 ? -1 : 1;
        }
        if (psb__is_fatal(r)) {
            *fatal = r;
            return 0;
        }
        s->message[0] = 0; /* a failed look-up or factorisation here tells nothing */
        if (r != PSB_SUCCESS) {
            sw->branch_signs_n = -1; /* no verdict: the count's */
            return 0;
        }
        sw->branch_sign[j] = (signed char)sign;
        sw->branch_signs_n = j + 1;
    }
    for (j = 0; j < n_branches; j++) sum += sw->branch_sign[j];
    return sum != 0;
}

/* ---- Algorithm 2.2 on workers (psb_branch_options.workers) ----------------------------------
   A span's directions go in batches of n_dir. Phase A, on the workers: every direction's memo
   key, then the tangents of the keys neither the memo nor an earlier direction holds. Phase B, in
   order on the calling solver: Step 4 and the memo choose the directions to try. Phase C, on the
   workers: their screening tangents, then (after a screening in order) their trials, each sign a
   task. Phase D, in order: psb__try_tangent's decisions on the trials' results. A task reads the
   memos as its phase found them (psb__sweep_state.frozen) and writes only its own record; the
   merges take records in order. So the result depends on the batch alone, never on which worker
   ran what or when. */

/* a direction's vectors: its tangent; for each sign the screen tangent, landing point and tangent,
   and the trial's path (psb__trial_watch) */
#define PSB__TASK_VECS (7 + 2 * PSB__PATH_MAX)

/* What tasks spent, merged and cleared in order by psb__task_merge. */
typedef struct psb__spent {
    psb_stats stats;
    long faults[4], n_ok, looks, hits, memo_cuts, n_tangents, n_pc;
    int pchecks;
    double pdrift, cone;
    char message[200]; /* a fatal code's */
} psb__spent;

/* One direction's task results. */
typedef struct psb__task {
    int skip;                /* no direction (v was 0) */
    psb_result ra;           /* phase A: the sample tangent's result, */
    int from_memo;           /* and its memo hit (1, 2) */
    int keyed, need, lead;   /* its memo key (1 dH's hash, 2 a piece id), to be computed, leads its
                                key (stores its tangent) */
    int follow;              /* takes its tangent from that direction's, the lead of its key (-1) */
    int sign;                /* its outward sign (psb__jmemo_store) */
    unsigned long long key[2];
    int todo, pick;          /* lists: rec[j].todo the j-th task's direction, rec[j].pick the j-th
                                chosen direction */
    psb_result rc, rcs[2];   /* phase C: the recomputed tangent's result (unscreened trials);
                                each sign's fatal code */
    int seen;                /* its tangent was tried before */
    psb_result rs[2], rt[2]; /* each sign: the screen tangent's result, the trial's; */
    int screened[2], go[2], fail[2]; /* screened (frozen memos, earlier screening tangents), the
                                        trial to make, why it failed */
    int path_n[2];           /* each sign: the trial's path, and the memo entries of its screening */
    int held[2][1 + PSB__PATH_MAX], held_sign[2][1 + PSB__PATH_MAX]; /* tangent and its path */
    unsigned long long held_key[2][2 + 2 * PSB__PATH_MAX];
    psb__spent spent[2];     /* by its tasks: phase A's and the first sign's, the second sign's */
} psb__task;

/* What a run's arg is (psb_workers_task_output): a batch of a sweep's directions (psb__par) or
   of the explorer's drafts (psb__drafts); each starts with its kind. */
enum { PSB__RUN_SWEEP = 1, PSB__RUN_DRAFTS };

typedef struct psb__par {
    int run_kind;                   /* PSB__RUN_SWEEP */
    psb_solver *s;                  /* the calling solver: read only while tasks run */
    psb__sweep_state *sw;           /* its memos, frozen while tasks run */
    const psb_workers *wk;
    const double *y0, *t1, *q, *ts; /* the point, the span's plane, the found branches */
    int n_br, n_dir, first;         /* found branches; directions first + i of n_dir */
    char *mem;                      /* the records: each direction's psb__task and its */
    size_t stride;                  /* PSB__TASK_VECS vectors, stride bytes in all */
    int phase;                      /* the current run's tasks (PSB__PHASE_*) */
} psb__par;

/* The tasks of a run: memo keys (task j: direction j), tangents (direction rec[j].todo), screening
   tangents and trials (direction rec[j / 2].todo, sign j % 2). */
enum { PSB__PHASE_KEY, PSB__PHASE_TANGENT, PSB__PHASE_SCREEN, PSB__PHASE_TRIAL };

/* Direction i's record. */
static psb__task *psb__rec(const psb__par *p, int i)
{
    return (psb__task *)(void *)(p->mem + (size_t)i * p->stride);
}

static void psb__drafts_output(const void *arg, int task, int *group, void **out, size_t *bytes);

PSCBRANCH_DEF void psb_workers_task_output(const void *arg, int task, int *group, void **out, size_t *bytes)
{
    const psb__par *p = (const psb__par *)arg;
    static const int vecs[4] = {0, 1, 7, PSB__TASK_VECS}; /* the vectors each phase's tasks write */
    int i;
    if (*(const int *)arg == PSB__RUN_DRAFTS) {
        psb__drafts_output(arg, task, group, out, bytes);
        return;
    }
    i = p->phase == PSB__PHASE_KEY ? task : psb__rec(p, p->phase == PSB__PHASE_TANGENT ? task : task / 2)->todo;
    *group = i;
    *out = psb__rec(p, i);
    *bytes = sizeof(psb__task) + (size_t)vecs[p->phase] * (size_t)p->s->internal_.np1 * sizeof(double);
}

PSCBRANCH_DEF size_t psb_workers_memory_size(int n, int n_dir)
{
    if (n < 1 || n_dir < 1 || n_dir > PSB_MAX_DIR_LIMIT) return 0;
    return (size_t)n_dir * (sizeof(psb__task) + (size_t)PSB__TASK_VECS * ((size_t)n + 1) * sizeof(double));
}

/* Checks s->branch.workers for a call on s (PSB_SUCCESS when there are none). */
static psb_result psb__check_workers(psb_solver *s, const psb_branch_options *b)
{
    const psb_workers *wk = b->workers;
    int w, v;
    if (!wk) return PSB_SUCCESS;
    if (wk->n_workers < 1 || wk->n_workers > PSB_MAX_WORKERS)
        return psb__fail(s, PSB_ERR_SIZE, "workers: n_workers must lie in [1, PSB_MAX_WORKERS = 1024]");
    if (!wk->run || !wk->solver || !wk->memory)
        return psb__fail(s, PSB_ERR_NULL, "workers: run, solver or memory is NULL");
    for (w = 0; w < wk->n_workers; w++) {
        const psb_solver *ws = wk->solver[w];
        if (!ws || ws->internal_.ready != PSB__READY)
            return psb__fail(s, PSB_ERR_NULL, "workers: a solver is NULL or not initialised");
        if (ws->internal_.np1 != s->internal_.np1 || ws->prob.param_index != s->prob.param_index ||
            ws->prob.linear != s->prob.linear || ws->prob.kl != s->prob.kl || ws->prob.ku != s->prob.ku ||
            ws->prob.band_lean != s->prob.band_lean || !ws->prob.jacobian != !s->prob.jacobian ||
            !ws->prob.band_jacobian != !s->prob.band_jacobian || !ws->prob.piece != !s->prob.piece)
            return psb__fail(s, PSB_ERR_SIZE, "workers: a solver's problem differs in size, backend or callbacks");
        if (ws == s) return psb__fail(s, PSB_ERR_INPUT, "workers: the calling solver is a worker");
        for (v = 0; v < w; v++)
            if (wk->solver[v] == ws) return psb__fail(s, PSB_ERR_INPUT, "workers: a solver is given twice");
    }
    if (wk->bytes < psb_workers_memory_size(s->internal_.n, b->n_dir))
        return psb__fail(s, PSB_ERR_NOMEM, "workers: memory is below psb_workers_memory_size(n, n_dir)");
    return PSB_SUCCESS;
}

/* Vector k of direction i's task. */
static double *psb__task_vec(const psb__par *p, int i, int k)
{
    return (double *)(void *)(psb__rec(p, i) + 1) + (size_t)k * (size_t)p->s->internal_.np1;
}

/* Sets the workers to the calling solver's options (h following the point or not), weights and
   H(y0) (before a batch). */
static void psb__workers_sync(psb_solver *s, const psb_workers *wk)
{
    int w, np1 = s->internal_.np1;
    for (w = 0; w < wk->n_workers; w++) {
        psb_solver *ws = wk->solver[w];
        ws->opt = s->opt;
        ws->branch = s->branch;
        ws->internal_.branch_h_auto = s->internal_.branch_h_auto;
        ws->internal_.branch_h_min_auto = s->internal_.branch_h_min_auto;
        psb__copy(ws->internal_.w, s->internal_.w, np1);
        psb__copy(PSB__VEC(ws, PSB__V_BR_H0), PSB__VEC(s, PSB__V_BR_H0), np1);
    }
}

/* A task's start on worker ws (a sweep's or the explorer's): ws forgets the factors it holds, so
   that what the task spends never depends on the task before it. What it spends is taken from
   here on (psb__worker_end) into stats, faults and n_ok, which start at 0. */
static void psb__worker_begin(psb_solver *ws, psb_stats *stats, long *faults, long *n_ok)
{
    int k;
    ws->internal_.afac = NULL;
    ws->internal_.bv_ok = ws->internal_.border_ok = 0;
    ws->internal_.in_trace_callback = 0;
    ws->message[0] = 0;
    psb__stats_add(stats, &ws->stats, -1);
    for (k = 0; k < 4; k++) faults[k] -= ws->internal_.faults[k];
    *n_ok -= ws->internal_.n_ok;
}

static void psb__worker_end(const psb_solver *ws, psb_stats *stats, long *faults, long *n_ok)
{
    int k;
    psb__stats_add(stats, &ws->stats, 1);
    for (k = 0; k < 4; k++) faults[k] += ws->internal_.faults[k];
    *n_ok += ws->internal_.n_ok;
}

/* Adds what a task spent to the calling solver s (in order) and clears it. */
static void psb__worker_merge(psb_solver *s, psb_stats *stats, long *faults, long *n_ok)
{
    int k;
    psb__stats_add(&s->stats, stats, 1);
    memset(stats, 0, sizeof *stats);
    for (k = 0; k < 4; k++) s->internal_.faults[k] += faults[k], faults[k] = 0;
    s->internal_.n_ok += *n_ok;
    *n_ok = 0;
}

/* A task's start on worker ws: sw becomes a frozen copy of the batch's memos with ws's own path
   (psb__worker_begin). */
static void psb__task_begin(const psb__par *p, psb_solver *ws, psb__sweep_state *sw, psb__spent *rec)
{
    *sw = *p->sw;
    sw->frozen = 1;
    sw->path = ws->internal_.sweep.path;
    psb__worker_begin(ws, &rec->stats, rec->faults, &rec->n_ok);
}

/* A task's end: what it spent into rec (the fatal message too). */
static void psb__task_end(const psb__par *p, psb_solver *ws, const psb__sweep_state *sw, psb__spent *rec, psb_result r)
{
    psb__worker_end(ws, &rec->stats, rec->faults, &rec->n_ok);
    rec->looks += sw->jmemo_looks - p->sw->jmemo_looks;
    rec->hits += sw->jmemo_hits - p->sw->jmemo_hits;
    rec->memo_cuts += sw->memo_cuts - p->sw->memo_cuts;
    rec->pchecks += sw->pmemo_checks - p->sw->pmemo_checks;
    if (sw->pmemo_drift > rec->pdrift || isnan(sw->pmemo_drift)) rec->pdrift = sw->pmemo_drift;
    if (sw->cone_defect > rec->cone) rec->cone = sw->cone_defect;
    if (psb__is_fatal(r)) memcpy(rec->message, ws->message, sizeof rec->message);
}

/* Direction i's sample point pt and direction v (0: none). */
static int psb__task_point(const psb__par *p, psb_solver *ws, int i, double *v, double *pt)
{
    int k, np1 = ws->internal_.np1;
    double alpha = 6.283185307179586 * (p->first + i + p->sw->sweep_offset) / p->n_dir;
    for (k = 0; k < np1; k++) v[k] = sin(alpha) * p->t1[k] + cos(alpha) * p->q[k];
    if (!psb__normalize_w(ws, v)) return 0;
    psb__axpy_to(pt, p->y0, ws->branch.h, v, np1);
    return 1;
}

/* Phase A, direction i on worker w: the memo key of y0 + h v (psb__sample_tangent's). */
static void psb__task_key(void *arg, int i, int w)
{
    psb__par *p = (psb__par *)arg;
    psb_solver *ws = p->wk->solver[w];
    psb__task *rec = psb__rec(p, i);
    psb__sweep_state sw;
    double *v = PSB__VEC(ws, PSB__V_BR_V), *pt = PSB__VEC(ws, PSB__V_BR_P);
    psb_result r = PSB_SUCCESS;
    int by_piece = ws->prob.piece != NULL;
    psb__task_begin(p, ws, &sw, rec->spent);
    rec->skip = !psb__task_point(p, ws, i, v, pt);
    if (!rec->skip) {
        rec->spent[0].n_tangents++;
        if (by_piece) r = psb__piece_key(ws, pt, rec->key, &by_piece);
        if (r == PSB_SUCCESS && !by_piece && psb__jmemo_hashing(&sw)) {
            ws->stats.n_tangents++;
            r = psb__jacobian(ws, pt, NULL);
            if (r == PSB_SUCCESS) psb__jmemo_key(ws, rec->key);
            psb__note_fault(ws, r);
            by_piece = -1;
        }
        rec->keyed = r != PSB_SUCCESS ? 0 : by_piece < 0 ? 1 : by_piece ? 2 : 0;
    }
    rec->ra = r;
    psb__task_end(p, ws, &sw, rec->spent, r);
}

/* Phase A, task j on worker w: the tangent at direction rec[j].todo's sample point (phase C
   again where phase A took it from the memo, which only chose it, and the trial goes along it). */
static void psb__task_tangent(void *arg, int j, int w)
{
    psb__par *p = (psb__par *)arg;
    psb_solver *ws = p->wk->solver[w];
    int i = psb__rec(p, j)->todo;
    psb__task *rec = psb__rec(p, i);
    psb__sweep_state sw;
    double *v = PSB__VEC(ws, PSB__V_BR_V), *pt = PSB__VEC(ws, PSB__V_BR_P);
    psb_result r;
    psb__task_begin(p, ws, &sw, rec->spent);
    psb__task_point(p, ws, i, v, pt);
    r = psb__sample_tangent_at(ws, pt, v, psb__task_vec(p, i, 0));
    psb__note_fault(ws, r);
    rec->sign = ws->internal_.tangent_sign;
    rec->ra = r;
    psb__task_end(p, ws, &sw, rec->spent, r);
}

/* Phase C, task j on worker w: the screening tangent of direction rec[j / 2].todo along +tt (j
   even) or -tt (psb__try_tangent's, on the frozen memos, its memo entry kept for the merge). */
static void psb__task_screen(void *arg, int j, int w)
{
    psb__par *p = (psb__par *)arg;
    psb_solver *ws = p->wk->solver[w];
    int i = psb__rec(p, j / 2)->todo, side = j % 2, np1 = ws->internal_.np1, k, from_memo;
    psb__task *rec = psb__rec(p, i);
    psb__spent *sp = rec->spent + side;
    psb__sweep_state sw;
    double *pk = PSB__VEC(ws, PSB__V_BR_S), *tt = psb__task_vec(p, i, 0);
    double *kx = psb__task_vec(p, i, 1 + 3 * side), *tb = psb__task_vec(p, i, 3 + 3 * side);
    psb_result r;
    psb__task_begin(p, ws, &sw, sp);
    for (k = 0; k < np1; k++) tb[k] = (side ? -1 : 1) * tt[k];
    psb__axpy_to(pk, p->y0, ws->branch.h_init, tb, np1);
    sp->n_tangents++;
    sw.held = 0;
    r = psb__sample_tangent(ws, &sw, pk, tb, kx, &from_memo, p->y0);
    rec->held[side][0] = sw.held;
    rec->held_sign[side][0] = sw.held_sign;
    rec->held_key[side][0] = sw.held_key[0];
    rec->held_key[side][1] = sw.held_key[1];
    rec->screened[side] = r == PSB_SUCCESS && psb__trial_known(ws, &sw, kx, p->ts, p->n_br, side ? tt : NULL, -1);
    if (r == PSB_SUCCESS && from_memo && !rec->screened[side]) r = psb__sample_tangent_at(ws, pk, tb, kx);
    rec->rs[side] = r;
    rec->rcs[side] = psb__is_fatal(r) ? r : PSB_SUCCESS;
    psb__task_end(p, ws, &sw, sp, r);
}

/* Phase C, task j on worker w: the trial of direction rec[j / 2].todo along +tt (j even) or -tt,
   when the screening let it through (go), along the screening tangent (psb__try_tangent's, on the
   frozen memos; its memo entries and path are kept for the merge). */
static void psb__task_trial(void *arg, int j, int w)
{
    psb__par *p = (psb__par *)arg;
    psb_solver *ws = p->wk->solver[w];
    int i = psb__rec(p, j / 2)->todo, side = j % 2, np1 = ws->internal_.np1, k, iters;
    int watched = !ws->branch.expert.no_screen && !psb__fd_jacobian(&ws->prob);
    psb__task *rec = psb__rec(p, i);
    psb__spent *sp = rec->spent + side;
    psb__sweep_state sw;
    psb__trial_watch tw;
    double *tt = psb__task_vec(p, i, 0), hh = ws->branch.h_init;
    double *yb = psb__task_vec(p, i, 2 + 3 * side), *tb = psb__task_vec(p, i, 3 + 3 * side);
    psb_result r;
    if (!rec->go[side]) return;
    psb__task_begin(p, ws, &sw, sp);
    if (ws->branch.expert.no_screen || rec->rs[side] != PSB_SUCCESS)
        for (k = 0; k < np1; k++) tb[k] = (side ? -1 : 1) * tt[k];
    else
        psb__copy(tb, psb__task_vec(p, i, 1 + 3 * side), np1);
    psb__copy(yb, p->y0, np1);
    sp->n_pc++;
    psb__trial_watch_init(&tw, &sw, p->ts, p->n_br, -1, sw.conic_h0_ok ? p->y0 : NULL);
    r = rec->rt[side] = psb__try_step_from(ws, yb, tb, &hh, ws->branch.expert.trial_h_min, &iters, p->y0,
                                           watched ? &tw.base : NULL);
    rec->fail[side] = ws->internal_.last_fail;
    rec->path_n[side] = watched ? tw.path_n : 0;
    for (k = 0; k < rec->path_n[side]; k++) {
        psb__copy(psb__task_vec(p, i, 7 + side * PSB__PATH_MAX + k), sw.path + (size_t)k * (size_t)np1, np1);
        rec->held[side][1 + k] = tw.path_held[k];
        rec->held_sign[side][1 + k] = tw.path_sign[k];
        rec->held_key[side][2 + 2 * k] = tw.path_key[2 * k];
        rec->held_key[side][3 + 2 * k] = tw.path_key[2 * k + 1];
    }
    psb__note_fault(ws, r);
    rec->rcs[side] = psb__is_fatal(r) ? r : PSB_SUCCESS;
    psb__task_end(p, ws, &sw, sp, r);
}

/* Merges what direction i's tasks spent into s, sw and rep, in order; their fatal code (or
   PSB_SUCCESS) with its message. */
static psb_result psb__task_merge(psb_solver *s, psb__sweep_state *sw, psb__spent *rec, psb_branch_report *rep,
                                  psb_result r)
{
    psb__worker_merge(s, &rec->stats, rec->faults, &rec->n_ok);
    sw->jmemo_looks += rec->looks;
    sw->jmemo_hits += rec->hits;
    sw->memo_cuts += rec->memo_cuts;
    rep->n_cut_memo += rec->memo_cuts;
    sw->pmemo_checks += rec->pchecks;
    if (rec->pdrift > sw->pmemo_drift || isnan(rec->pdrift)) sw->pmemo_drift = rec->pdrift;
    psb__note_cone_excess(sw, rec->cone);
    rep->n_tangents += rec->n_tangents;
    rep->n_pc += rec->n_pc;
    rec->looks = rec->hits = rec->memo_cuts = rec->n_tangents = rec->n_pc = 0;
    rec->pchecks = 0;
    rec->pdrift = rec->cone = 0;
    if (!psb__is_fatal(r)) return PSB_SUCCESS;
    memcpy(s->message, rec->message, sizeof s->message);
    s->message[sizeof s->message - 1] = 0;
    return r;
}

/* Runs n tasks on the workers. */
static psb_result psb__par_run(psb__par *p, int n, psb_task_fn task, int phase)
{
    if (n == 0) return PSB_SUCCESS;
    p->phase = phase;
    if (p->wk->run(p->wk->ctx, n, task, p) != 0)
        return psb__fail(p->s, PSB_ERR_CALLBACK, "workers: run failed");
    return PSB_SUCCESS;
}

/* Which trials of the n directions rec[j].todo to make: those the screening on the frozen memos
   let through, unless the screening tangent of one before it (in order) already stands for it,
   as it would in the known memo of the serial sweep. A fatal screening ends the list there. */
static void psb__par_screen(psb__par *p, int n)
{
    psb_solver *s = p->s;
    int j, side, m, other, fatal = 0;
    for (j = 0; j < n; j++)
        for (side = 0; side < 2; side++) {
            psb__task *rec = psb__rec(p, psb__rec(p, j)->todo);
            const double *kx = psb__task_vec(p, psb__rec(p, j)->todo, 1 + 3 * side);
            double nx;
            rec->go[side] = 0;
            if (fatal || rec->screened[side]) continue;
            fatal = rec->rcs[side] != PSB_SUCCESS;
            rec->go[side] = !fatal;
            if (fatal || s->branch.expert.no_screen || rec->rs[side] != PSB_SUCCESS) continue;
            nx = psb__norm_w(s, kx);
            for (m = 0; m <= j && !rec->screened[side]; m++)
                for (other = 0; other < (m < j ? 2 : side); other++) {
                    const psb__task *o = psb__rec(p, psb__rec(p, m)->todo);
                    if (o->go[other] && o->rs[other] == PSB_SUCCESS &&
                        psb__cos_w_na(s, kx, nx, psb__task_vec(p, psb__rec(p, m)->todo, 1 + 3 * other)) >= s->opt.c_diff)
                        rec->screened[side] = 1;
                }
            rec->go[side] = !rec->screened[side];
        }
}

/* Orients the memo tangent tm by direction i's v into its tangent (psb__jmemo_get's test): 1, or
   0 when v is nearly orthogonal to it (the tangent is then computed). */
static int psb__par_oriented(psb__par *p, int i, const double *tm)
{
    psb_solver *s = p->s;
    double *v = PSB__VEC(s, PSB__V_BR_V), *pt = PSB__VEC(s, PSB__V_BR_P), *tt = psb__task_vec(p, i, 0), dot;
    int k;
    psb__task_point(p, s, i, v, pt);
    dot = psb__dot_w(s, tm, v);
    if (!(fabs(dot) > 1.4901161193847656e-08 * psb__norm_w(s, v))) return 0;
    for (k = 0; k < s->internal_.np1; k++) tt[k] = dot < 0 ? -tm[k] : tm[k];
    s->stats.n_tangent_reused++;
    s->internal_.n_ok++;
    return 1;
}

/* Phase A: the sample tangents of directions 0 .. count - 1 of the batch, as psb__sample_tangent
   gives them in order: the memo keys first (when the memo keys), then the tangents of the
   directions whose key neither the memo nor an earlier direction holds, then of those whose
   key's lead failed or whose memo tangent is nearly orthogonal to v. Returns PSB_SUCCESS or the
   first fatal code in order. */
static psb_result psb__par_tangents(psb__par *p, int count, psb_branch_report *rep)
{
    psb_solver *s = p->s;
    psb__sweep_state *sw = p->sw;
    int np1 = s->internal_.np1, i, j, m, n, round;
    psb_result r;
    if (s->prob.piece || psb__jmemo_hashing(sw)) {
        r = psb__par_run(p, count, psb__task_key, PSB__PHASE_KEY);
        if (r != PSB_SUCCESS) return r;
    } else {
        for (i = 0; i < count; i++) {
            psb__rec(p, i)->skip = !psb__task_point(p, s, i, PSB__VEC(s, PSB__V_BR_V), PSB__VEC(s, PSB__V_BR_P));
            psb__rec(p, i)->spent[0].n_tangents = !psb__rec(p, i)->skip;
        }
    }
    for (i = 0; i < count; i++) {
        psb__task *rec = psb__rec(p, i);
        r = psb__task_merge(s, sw, rec->spent, rep, rec->ra);
        if (r != PSB_SUCCESS) return r;
        rec->follow = -1;
        if (rec->skip || rec->ra != PSB_SUCCESS) continue;
        rec->need = 1;
        if (!rec->keyed) continue;
        sw->jmemo_looks++;
        m = psb__jmemo_find(sw, rec->key);
        if (m >= 0) {
            sw->jmemo_hits++;
            if (psb__par_oriented(p, i, sw->jmemo_t + (size_t)m * (size_t)np1)) {
                rec->need = 0;
                rec->from_memo = rec->keyed;
            }
            continue;
        }
        for (j = 0; j < i; j++)
            if (psb__rec(p, j)->lead && psb__rec(p, j)->key[0] == rec->key[0] && psb__rec(p, j)->key[1] == rec->key[1]) break;
        if (j < i) {
            sw->jmemo_hits++;
            rec->need = 0;
            rec->follow = j;
        } else {
            rec->lead = 1;
        }
    }
    for (round = 0; round < 2; round++) {
        for (i = n = 0; i < count; i++)
            if (psb__rec(p, i)->need) psb__rec(p, n++)->todo = i;
        r = psb__par_run(p, n, psb__task_tangent, PSB__PHASE_TANGENT);
        if (r != PSB_SUCCESS) return r;
        for (i = 0; i < count; i++) {
            psb__task *rec = psb__rec(p, i);
            if (rec->need) {
                rec->need = 0;
                r = psb__task_merge(s, sw, rec->spent, rep, rec->ra);
                if (r != PSB_SUCCESS) return r;
                if (rec->lead && rec->ra == PSB_SUCCESS)
                    psb__jmemo_store(s, sw, rec->key, psb__task_vec(p, i, 0), rec->sign);
            } else if (rec->follow >= 0) {
                const psb__task *lead = psb__rec(p, rec->follow);
                if (lead->ra == PSB_SUCCESS && psb__par_oriented(p, i, psb__task_vec(p, rec->follow, 0)))
                    rec->from_memo = rec->keyed;
                else
                    rec->need = 1; /* computed in the next round, not stored */
                rec->follow = -1;
            }
        }
    }
    return PSB_SUCCESS;
}

/* Phase D for direction i (phase C's results): psb__try_tangent's decisions, in order, on the
   memos and branches as the directions before it left them. */
static psb_result psb__par_merge(psb__par *p, int i, int max_branches, double *ys, double *ts,
                                 psb_branch_report *rep, int *overflow)
{
    psb_solver *s = p->s;
    psb__sweep_state *sw = p->sw;
    psb__task *rec = psb__rec(p, i);
    const double *y0 = p->y0, *tt = psb__task_vec(p, i, 0);
    int side, k;
    psb_result r = psb__task_merge(s, sw, rec->spent, rep, psb__is_fatal(rec->rc) ? rec->rc : rec->rcs[0]);
    if (r == PSB_SUCCESS) r = psb__task_merge(s, sw, rec->spent + 1, rep, rec->rcs[1]);
    if (r != PSB_SUCCESS) return r;
    if (rec->rc != PSB_SUCCESS) return PSB_SUCCESS; /* a fault, counted */
    if (!s->branch.expert.no_memo && (rec->seen || psb__memo_seen(s, sw, tt))) {
        rep->n_memo++;
        return PSB_SUCCESS;
    }
    for (side = 0; side < 2; side++) {
        double *kx = psb__task_vec(p, i, 1 + 3 * side), *yb = psb__task_vec(p, i, 2 + 3 * side);
        double *tb = psb__task_vec(p, i, 3 + 3 * side);
        int cut;
        if (rec->screened[side]) {
            rep->n_screened++;
            continue;
        }
        if (!s->branch.expert.no_screen && rec->rs[side] == PSB_SUCCESS) {
            if (psb__trial_known(s, sw, kx, ts, rep->n_branches, side ? tt : NULL, -1)) {
                rep->n_screened++;
                continue;
            }
            psb__store_add(s, sw, sw->known, &sw->known_n, kx);
        }
        /* the memo entries the trial made, as the serial sweep makes them */
        for (k = 0; k <= rec->path_n[side]; k++)
            if (rec->held[side][k] && psb__jmemo_find(sw, rec->held_key[side] + 2 * k) < 0)
                psb__jmemo_store(s, sw, rec->held_key[side] + 2 * k,
                                 k ? psb__task_vec(p, i, 6 + side * PSB__PATH_MAX + k) : kx, rec->held_sign[side][k]);
        r = rec->rt[side];
        if (psb__is_fault(r)) continue;
        cut = r != PSB_SUCCESS && rec->fail[side] == PSB__FAIL_KNOWN;
        rep->n_cut += cut;
        if (r != PSB_SUCCESS && !cut) continue;
        r = psb__trial_done(s, sw, y0, psb__task_vec(p, i, 7 + side * PSB__PATH_MAX), rec->path_n[side], cut, yb, tb,
                            max_branches, ys, ts, rep, overflow);
        if (r != PSB_SUCCESS) return r;
    }
    if (!s->branch.expert.no_memo) psb__store_add(s, sw, sw->memo, &sw->memo_n, tt);
    return PSB_SUCCESS;
}

/* psb__sweep on workers: the n_dir directions of the span of t1 and q (t2 made orthogonal), in
   batches of s->branch.n_dir. Counts differ from the serial sweep's (the trials of a batch do not
   see each other's memo entries), results not at all with the number of workers. */
static psb_result psb__sweep_par(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *t1,
                                 const double *q, int n_dir, int max_branches, double *ys, double *ts,
                                 psb_branch_report *rep, int *overflow)
{
    const psb_workers *wk = s->branch.workers;
    int np1 = s->internal_.np1, batch = s->branch.n_dir, first, i, j, m, n;
    double *tprev = PSB__VEC(s, PSB__V_BR_TP);
    psb__par p;
    psb_result r;
    p.run_kind = PSB__RUN_SWEEP;
    p.s = s;
    p.sw = sw;
    p.wk = wk;
    p.y0 = y0;
    p.t1 = t1;
    p.q = q;
    p.n_dir = n_dir;
    p.mem = (char *)wk->memory;
    p.stride = sizeof(psb__task) + (size_t)PSB__TASK_VECS * (size_t)np1 * sizeof(double);
    psb__workers_sync(s, wk);
    for (first = 0; first < n_dir; first += batch) {
        int count = n_dir - first < batch ? n_dir - first : batch, n_pick = 0;
        if (s->branch.max_pc && rep->n_pc >= s->branch.max_pc) return PSB_SUCCESS;
        for (i = 0; i < count; i++) memset(psb__rec(&p, i), 0, sizeof(psb__task));
        p.first = first;
        r = psb__par_tangents(&p, count, rep);
        if (r != PSB_SUCCESS) return r;
        /* phase B: Step 4 and the memo in order */
        for (i = 0; i < count; i++) {
            psb__task *rec = psb__rec(&p, i);
            double *tt = psb__task_vec(&p, i, 0);
            int seen = 0;
            if (rec->skip || rec->ra != PSB_SUCCESS) continue;
            if (first + i > 0 && fabs(psb__cos_w(s, tt, tprev)) >= s->opt.c_diff) continue;
            psb__copy(tprev, tt, np1);
            if (!s->branch.expert.no_memo) {
                seen = psb__memo_seen(s, sw, tt);
                for (m = 0; m < n_pick && !seen; m++)
                    seen = fabs(psb__cos_w(s, tt, psb__task_vec(&p, psb__rec(&p, m)->pick, 0))) >= s->opt.c_diff;
            }
            if (seen) {
                rep->n_memo++;
                continue;
            }
            psb__rec(&p, n_pick++)->pick = i;
        }
        /* phase C: the trials (both signs apart) on the memos as they are now; phase D: their
           merge in order. A tangent phase A took from the memo places the screening points as
           well as the computed one would (the trials go along the tangents there), so only
           unscreened trials wait for it to be computed */
        p.ts = ts;
        p.n_br = rep->n_branches;
        for (j = n = 0; j < n_pick; j++)
            if (psb__rec(&p, psb__rec(&p, j)->pick)->from_memo && s->branch.expert.no_screen)
                psb__rec(&p, n++)->todo = psb__rec(&p, j)->pick;
        r = psb__par_run(&p, n, psb__task_tangent, PSB__PHASE_TANGENT);
        if (r != PSB_SUCCESS) return r;
        for (j = 0; j < n; j++) psb__rec(&p, psb__rec(&p, j)->todo)->rc = psb__rec(&p, psb__rec(&p, j)->todo)->ra;
        for (j = n = 0; j < n_pick; j++) {
            psb__task *rec = psb__rec(&p, psb__rec(&p, j)->pick);
            if (rec->rc == PSB_SUCCESS && !s->branch.expert.no_memo)
                rec->seen = psb__memo_seen(s, sw, psb__task_vec(&p, psb__rec(&p, j)->pick, 0));
            if (rec->rc == PSB_SUCCESS && !rec->seen) psb__rec(&p, n++)->todo = psb__rec(&p, j)->pick;
        }
        r = psb__par_run(&p, s->branch.expert.no_screen ? 0 : 2 * n, psb__task_screen, PSB__PHASE_SCREEN);
        if (r != PSB_SUCCESS) return r;
        psb__par_screen(&p, n);
        r = psb__par_run(&p, 2 * n, psb__task_trial, PSB__PHASE_TRIAL);
        if (r != PSB_SUCCESS) return r;
        for (j = 0; j < n_pick; j++) {
            r = psb__par_merge(&p, psb__rec(&p, j)->pick, max_branches, ys, ts, rep, overflow);
            if (r != PSB_SUCCESS) return r;
        }
    }
    return PSB_SUCCESS;
}

/* One span of Algorithm 2.2 (Steps 2-7) with the spanning tangents t1, t2. */
static psb_result psb__sweep(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *t1, const double *t2,
                             int max_branches, double *ys, double *ts, psb_branch_report *rep,
                             int *overflow)
{
    int np1 = s->internal_.np1, i, k, from_memo, n_dir = sw->sweep_n_dir ? sw->sweep_n_dir : s->branch.n_dir;
    double *v = PSB__VEC(s, PSB__V_BR_V), *tt = PSB__VEC(s, PSB__V_BR_TT);
    double *tprev = PSB__VEC(s, PSB__V_BR_TP), *pt = PSB__VEC(s, PSB__V_BR_P);
    double h = s->branch.h, *q = PSB__VEC(s, PSB__V_BR_Q);
    psb_result r;
    psb__copy(q, t2, np1);
    if (!s->branch.expert.paper_sweep) {
        /* t2 made w-orthogonal to t1: the same plane, but the n_dir directions spread evenly
           over it even when t1 and t2 are nearly parallel (then the printed combination
           bunches them around +-t1 and +-t2 and misses the regions in between) */
        double c = psb__dot_w(s, t1, t2) / psb__dot_w(s, t1, t1);
        for (k = 0; k < np1; k++) q[k] = t2[k] - c * t1[k];
        if (!psb__normalize_w(s, q)) return PSB_SUCCESS; /* t2 parallel to t1: no plane */
        for (k = 0; k < np1; k++) q[k] *= psb__norm_w(s, t1);
    }
    if (s->branch.workers) return psb__sweep_par(s, sw, y0, t1, q, n_dir, max_branches, ys, ts, rep, overflow);
    for (i = 0; i < n_dir; i++) {
        double alpha = 6.283185307179586 * (i + sw->sweep_offset) / n_dir;
        for (k = 0; k < np1; k++) v[k] = sin(alpha) * t1[k] + cos(alpha) * q[k];
        if (!psb__normalize_w(s, v)) continue;
        psb__axpy_to(pt, y0, h, v, np1);
        rep->n_tangents++;
        r = psb__sample_tangent(s, sw, pt, v, tt, &from_memo, NULL);
        if (psb__is_fatal(r)) return r;
        if (r != PSB_SUCCESS) {
            psb__note_fault(s, r);
            continue;
        }
        /* Step 4: a tangent seen at the previous direction belongs to the same region */
        if (i > 0 && fabs(psb__cos_w(s, tt, tprev)) >= s->opt.c_diff) continue;
        /* a tangent tried before is skipped by psb__try_tangent; one that will be tried is
           the recomputed one (psb__sample_tangent) */
        if (from_memo && (s->branch.expert.no_memo || !psb__memo_seen(s, sw, tt))) {
            r = psb__sample_refresh(s, from_memo, pt, v, tt);
            if (psb__is_fatal(r)) return r;
            if (r != PSB_SUCCESS) {
                psb__note_fault(s, r);
                continue;
            }
        }
        psb__copy(tprev, tt, np1);
        r = psb__try_tangent(s, sw, y0, tt, max_branches, ys, ts, rep, overflow);
        if (r != PSB_SUCCESS) return r;
        if (s->branch.max_pc && rep->n_pc >= s->branch.max_pc) return PSB_SUCCESS;
    }
    return PSB_SUCCESS;
}

/* Section 3, strategy (1): the next pair (i, j), i < j, of the found branches ts (n_br) to
   span a sweep, each once, among the first 64 (their 2016 pairs outlast any sweep with
   n_span < 250); 0 when all were swept. Orthogonalised sweep: the smallest |cosine| first;
   printed sweep: the largest first (section 6, "Restarts"); ties in the order
   (0,1), (0,2), (1,2), (0,3), ... */
static int psb__next_pair(psb_solver *s, psb__sweep_state *sw, const double *ts, int n_br, int *pi, int *pj)
{
    int i, j, np1 = s->internal_.np1, nb = n_br < 64 ? n_br : 64;
    double best = -1;
    *pi = -1;
    for (j = 1; j < nb; j++)
        for (i = 0; i < j; i++) {
            int bit = j * (j - 1) / 2 + i;
            double c;
            if (sw->pairs_done[bit / 64] >> (bit % 64) & 1u) continue;
            c = fabs(psb__cos_w(s, ts + (size_t)i * (size_t)np1, ts + (size_t)j * (size_t)np1));
            if (!s->branch.expert.paper_sweep) c = 1 - c;
            if (c > best) {
                best = c;
                *pi = i;
                *pj = j;
            }
        }
    if (*pi < 0) return 0;
    i = *pj * (*pj - 1) / 2 + *pi;
    sw->pairs_done[i / 64] |= 1ull << (i % 64);
    return 1;
}

/* Section 3, strategy (2): where the sample point of the n_rand-th random span lies. NULL: at
   y0 + h r, r uniformly random; else at y0 + h (d + 0.1 r) for the d returned. Remark 2.3(ii)
   perturbs the previous t~2 (prev) and keeps t~1: PSB_RESTART_PAPER. Uniform draws reach
   regions no span found so far comes near, but rarely the thin ones beside found branches
   (section 6, "Restarts"), so PSB_RESTART_MIXED alternates them, uniform first, with
   perturbations of the found branches' tangents ts (n_br) in turn, each spanned with t~1 = it. */
static const double *psb__restart_centre(const psb_solver *s, const double *ts, int n_br, int n_rand,
                                         const double *prev, double *t1)
{
    if (s->branch.expert.restart == PSB_RESTART_GLOBAL || (s->branch.expert.restart == PSB_RESTART_MIXED && n_rand % 2 == 0))
        return NULL;
    if (s->branch.expert.restart == PSB_RESTART_PAPER) return prev;
    psb__copy(t1, ts + (size_t)(n_rand / 2 % n_br) * (size_t)s->internal_.np1, s->internal_.np1);
    return t1;
}

/* Steps 2-7 of Algorithm 2.2 after Step 1 (psb__find_branches_once) has set t~1, t~2 and
   branch 0; *overflow is set when a new branch found no room.
   A span whose tangents were all tried before (the memo skips every direction, or the
   screen every trial) tries nothing: it does not count against n_span. When the pairs of
   known branches give only such spans, as on H = min(x, g - x) in R^k, whose 2^k rays
   pairwise span planes meeting no other ray's region, they would use up every span and
   starve the random ones: after one, a random span comes next. 2 n_span idle random spans
   in a row (in R^2, where every span sweeps the one plane there is, they follow the first)
   or 4 n_span spans in all (8 n_span when the length adapts, below) end the sweep: they
   bound the tangents spent.
   Idle spans of pairs count in neither: each is followed by a random span, so they are
   bounded by those, and counted they ended the sweep on the crossing kinks, k = 5, before
   its random spans had found every ray (section 6, "Sweep length").
   n_span left at its default (memo on): the sweep goes on past n_span until it has gone
   twice as many counted spans without a new branch as it took to find the last one, up
   to 4 n_span counted spans (section 6, "Sweep length": where regions are thin, branches
   keep trickling in, and how long they took to come tells how long to wait); while the
   count is odd it goes on to n_span_max (section 6, "An odd count": where the pieces are
   transversal the branches come in pairs, so one is missing).
   dense: the count stayed odd (psb__odd_sweeps): the spans again, pairs first (span 0 too),
   while the count is odd, up to n_span counted spans. Returns PSB_SUCCESS or a fatal code. */
static psb_result psb__span_loop(psb_solver *s, psb__sweep_state *sw, const double *y0, int max_branches,
                                 double *ys, double *ts,
                                 psb_branch_report *rep, int *overflow, int dense)
{
    int np1 = s->internal_.np1, k, span, global, found_before, idle = 0, pair_span = 0, pair_stale = 0;
    int idle_spans_in_a_row = 0, idle_pair_spans = 0, extend, spans_in_all, pi, pj;
    int counted_before = rep->n_span;
    long pc_before;
    double *t1 = PSB__VEC(s, PSB__V_BR_T1);
    double *t2 = PSB__VEC(s, PSB__V_BR_T2), *pt = PSB__VEC(s, PSB__V_BR_P);
    psb_result r, fatal = PSB_SUCCESS;
    extend = s->branch.n_span_max > s->branch.n_span;
    spans_in_all = 4 * s->branch.n_span > 2 * s->branch.n_span_max ? 4 * s->branch.n_span : 2 * s->branch.n_span_max;
    if (dense) spans_in_all = 4 * s->branch.n_span;
    for (span = 0; (dense ? rep->n_span - counted_before < s->branch.n_span &&
                                psb__unbalanced(s, sw, ys, ts, rep->n_branches, &fatal)
                          : rep->n_span < s->branch.n_span ||
                                (extend && rep->n_span < s->branch.n_span_max &&
                                 (rep->n_span < 3 * rep->span_last_new ||
                                  psb__unbalanced(s, sw, ys, ts, rep->n_branches, &fatal)))) &&
                   span - idle_pair_spans < spans_in_all; span++) {
        found_before = rep->n_branches;
        pc_before = rep->n_pc;
        if (span > 0 || dense) {
            pair_span = !pair_stale && psb__next_pair(s, sw, ts, rep->n_branches, &pi, &pj);
            if (pair_span) {
                psb__copy(t1, ts + (size_t)pi * (size_t)np1, np1);
                psb__copy(t2, ts + (size_t)pj * (size_t)np1, np1);
            } else {
                /* strategy (2): a random span (psb__restart_centre) */
                double *rnd = PSB__VEC(s, PSB__V_BR_V), *prev = PSB__VEC(s, PSB__V_BR_TT);
                const double *centre;
                /* z / sqrt(w) with z standard normal is isotropic for <.,.>_w */
                for (k = 0; k < np1; k++) rnd[k] = psb__gauss(s->internal_.rng) / sqrt(s->internal_.w[k]);
                if (!psb__normalize_w(s, rnd)) continue;
                psb__copy(prev, t2, np1);
                centre = psb__restart_centre(s, ts, rep->n_branches, rep->n_rand, prev, t1);
                global = !centre;
                for (k = 0; k < np1; k++)
                    pt[k] = y0[k] + s->branch.h * (global ? rnd[k] : centre[k] + 0.1 * rnd[k]);
                rep->n_rand++;
                rep->n_tangents++;
                r = psb__sample_tangent(s, sw, pt, global ? prev : centre, t2, NULL, NULL);
                if (psb__is_fatal(r)) {
                    fatal = r;
                    break;
                }
                if (r != PSB_SUCCESS) {
                    psb__note_fault(s, r);
                    psb__copy(t2, prev, np1);
                    continue;
                }
                /* a tangent tried before: the plane through it and t~1 likely revisits swept
                   ground (on a piecewise-linear H it is two piece directions); beside a found
                   branch t_j whose region holds the random point, the tangent is t_j = t~1,
                   and the plane would be t~1's and rounding noise's. The random direction
                   spans a fresh one */
                if (global ? !s->branch.expert.no_memo && psb__memo_seen(s, sw, t2)
                           : s->branch.expert.restart == PSB_RESTART_MIXED && fabs(psb__cos_w(s, t2, t1)) >= s->opt.c_diff)
                    psb__copy(t2, rnd, np1);
            }
        }
        r = psb__sweep(s, sw, y0, t1, t2, max_branches, ys, ts, rep, overflow);
        if (r != PSB_SUCCESS) {
            fatal = r;
            break;
        }
        pair_stale = pair_span && rep->n_pc == pc_before;
        if (rep->n_pc == pc_before && !s->branch.expert.no_memo) {
            rep->n_span_idle++;
            if (pair_span) idle_pair_spans++;
            else if (++idle_spans_in_a_row >= 2 * s->branch.n_span &&
                     !((extend || dense) && psb__unbalanced(s, sw, ys, ts, rep->n_branches, &fatal)))
                break;
            if (fatal != PSB_SUCCESS) break;
            continue;
        }
        idle_spans_in_a_row = 0;
        rep->n_span++;
        if (s->branch.max_pc && rep->n_pc >= s->branch.max_pc) break;
        if (rep->n_branches > found_before) {
            rep->span_last_new = rep->n_span;
            rep->n_pc_last_new = rep->n_pc;
            rep->n_rand_last_new = rep->n_rand;
        }
        /* adaptive end: spans in a row that brought no new branch */
        idle = rep->n_branches > found_before ? 0 : idle + 1;
        if (s->branch.expert.patience && idle >= s->branch.expert.patience) break;
    }
    return fatal;
}

/* How a run of Algorithm 2.2 whose sweeps ended with r (PSB_SUCCESS or a fatal code) ends:
   the fault counts into rep; a trial that failed because of a fault might have found a
   branch, so the set is not known to be complete; else PSB_BRANCH_CAPACITY on overflow. */
static psb_result psb__sweeps_end(psb_solver *s, psb_branch_report *rep, psb_result r, int overflow)
{
    psb__report_faults(s, rep);
    if (r != PSB_SUCCESS) return r;
    r = psb__faults_code(s, "Algorithm 2.2 (ys, ts: the branches found)");
    if (r != PSB_SUCCESS) return r;
    s->message[0] = 0;
    return overflow ? PSB_BRANCH_CAPACITY : PSB_SUCCESS;
}

/* One run of Algorithm 2.2 with the options in s->branch (psb__find_branches). */
static psb_result psb__find_branches_once(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *t0,
                                          int max_branches, double *ys, double *ts, psb_branch_report *rep)
{
    psb_branch_report local;
    int np1, k, overflow = 0;
    unsigned long long seed;
    const double *yc = y0;
    double *tc, *t1, *t2, *pt;
    psb_result r;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    r = psb__check_couple(s, y0, t0);
    if (r != PSB_SUCCESS) return r;
    if (!ys || !ts) return psb__fail(s, PSB_ERR_NULL, "ys or ts is NULL");
    if (max_branches < 1) return psb__fail(s, PSB_ERR_SIZE, "max_branches must be >= 1");
    np1 = s->internal_.np1;
    tc = PSB__VEC(s, PSB__V_BR_T0);
    t1 = PSB__VEC(s, PSB__V_BR_T1);
    t2 = PSB__VEC(s, PSB__V_BR_T2);
    pt = PSB__VEC(s, PSB__V_BR_P);
    psb__copy(tc, t0, np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "t0 is zero");
    r = psb__branch_h(s, yc);
    if (r != PSB_SUCCESS) return r;
    /* H(y0) for the trials' conic test (psb__conic_excess); the test is off without it */
    sw->conic_h0_ok = 0;
    if (sw->jmemo_dh && !s->branch.expert.no_screen) {
        r = psb__residual(s, yc, PSB__VEC(s, PSB__V_BR_H0));
        if (psb__is_fatal(r)) return r;
        sw->conic_h0_ok = r == PSB_SUCCESS;
    }
    seed = s->opt.seed;
    for (k = 0; k < 4; k++) s->internal_.rng[k] = psb__splitmix(&seed);
    sw->memo_n = 0;
    sw->known_n = 0;
    sw->jmemo_n = 0;
    sw->jmemo_looks = sw->jmemo_hits = 0;
    sw->pmemo_checks = 0;
    sw->pmemo_drift = 0;
    sw->cone_defect = 0;
    sw->chord_turn_max = 0;
    sw->chord_turn_min = HUGE_VAL;
    memset(sw->pairs_done, 0, sizeof sw->pairs_done);
    sw->branch_signs_n = 0;
    psb__faults_reset(s);

    /* Step 1: t~1 = -t0, t~2 the tangent beyond the end point; branch 0 is the incoming one */
    for (k = 0; k < np1; k++) t1[k] = -tc[k];
    psb__axpy_to(pt, yc, s->branch.h, tc, np1);
    rep->n_tangents++;
    r = psb__sample_tangent(s, sw, pt, tc, t2, NULL, NULL);
    if (r != PSB_SUCCESS) {
        if (psb__note_fault(s, r)) psb__report_faults(s, rep); /* n_failed > 0 on every fault */
        return r;
    }
    psb__copy(ys, yc, np1);
    psb__copy(ts, t1, np1);
    rep->n_branches = 1;

    r = psb__span_loop(s, sw, yc, max_branches, ys, ts, rep, &overflow, 0);
    return psb__sweeps_end(s, rep, r, overflow);
}

/* A count still odd at the end of an adaptive sweep (psb__find_branches): the missing region
   is most often thin and lies between directions already sampled. So the spans again, pairs
   first, each direction halfway between two of the first sweep's (psb__span_loop, dense);
   then, while the count is odd, the spans of pairs with 2 and then 4 times n_dir directions,
   each halfway between two swept before, as long as these have not sampled more tangents
   than the call had before them (with many branches their pairs are many). Returns
   PSB_SUCCESS or a fatal code. */
static psb_result psb__odd_sweeps(psb_solver *s, psb__sweep_state *sw, const double *y0, int max_branches,
                                  double *ys, double *ts,
                                  psb_branch_report *rep, int *overflow)
{
    int level, pi, pj, np1 = s->internal_.np1;
    long budget;
    psb_result r;
    memset(sw->pairs_done, 0, sizeof sw->pairs_done);
    sw->sweep_offset = 0.5;
    r = psb__span_loop(s, sw, y0, max_branches, ys, ts, rep, overflow, 1);
    budget = 2 * rep->n_tangents;
    for (level = 2; level <= 3 && r == PSB_SUCCESS && !*overflow && psb__unbalanced(s, sw, ys, ts, rep->n_branches, &r);
         level++) {
        memset(sw->pairs_done, 0, sizeof sw->pairs_done);
        sw->sweep_n_dir = s->branch.n_dir << (level - 1);
        while (!*overflow && !(s->branch.max_pc && rep->n_pc >= s->branch.max_pc) &&
               rep->n_tangents + sw->sweep_n_dir <= budget && psb__unbalanced(s, sw, ys, ts, rep->n_branches, &r) &&
               psb__next_pair(s, sw, ts, rep->n_branches, &pi, &pj)) {
            long pc_before = rep->n_pc;
            r = psb__sweep(s, sw, y0, ts + (size_t)pi * (size_t)np1,
                           ts + (size_t)pj * (size_t)np1, max_branches, ys, ts, rep, overflow);
            if (r != PSB_SUCCESS) break;
            if (rep->n_pc > pc_before) rep->n_span++;
            else rep->n_span_idle++;
        }
    }
    sw->sweep_offset = 0;
    sw->sweep_n_dir = 0;
    return r;
}

/* How far from conic (psb__conic_excess) H may look at a trial's point before Algorithm
   2.2 looks again with a smaller h_init. On smooth pieces the excess at distance d is about
   curvature x d / 2, as a landing point's chord turn is, so PSB__CHORD_TURN for both. Where
   some landing point's chord runs straight along its tangent (a piecewise-linear H), the
   pieces bend nowhere and an excess tells a kink: a kink at distance a from y0 shows about
   a / h_init times its angle. There 8 times the straightest landing's turn, at least 1e-3. */
static double psb__cone_tolerance(const psb__sweep_state *sw)
{
    double tol = 8 * sw->chord_turn_min;
    return tol < 1e-3 ? 1e-3 : tol > PSB__CHORD_TURN ? PSB__CHORD_TURN : tol;
}

/* Algorithm 2.2 with the options in s->branch (psb_find_branches, psb_explore). Its trials
   and their screening take the pieces for cones with apex y0 out to h_init. Where another
   kink lies closer, a trial's landing point lies beyond it, and the branch's chord from y0
   turns away from its tangent there by about the kink's angle (on a straight branch not at
   all, on a curved one by curvature x distance / 2): trials reach other points' branches and
   the screen skips real ones.
   So when a landing point's chord turns by more than PSB__CHORD_TURN from its tangent, or a
   trial's iterate or screening point finds H that far from conic (cone_defect), or the
   count is odd (manual, "An odd count"; a branch that ended at a nearby kink's tells no turn),
   the run is made again with h_init / 16, up to 3 times (h_init stays above 8 h); an odd count
   that the smaller h_init kept ends it. */
static psb_result psb__find_branches(psb_solver *s, psb__sweep_state *sw, const double *y0, const double *t0,
                                     int max_branches, double *ys, double *ts, psb_branch_report *rep)
{
    double h_init = s->branch.h_init, *y0c = PSB__VEC(s, PSB__V_BR_Y0);
    int round, before = -1, full = 0;
    psb_branch_report local;
    psb_result r = PSB_SUCCESS;
    if (!rep) rep = &local;
    psb__copy(y0c, y0, s->internal_.np1); /* held apart: ys may alias the caller's y0 */
    for (round = 0; round < 4; round++) {
        int turned;
        r = psb__find_branches_once(s, sw, y0c, t0, max_branches, ys, ts, rep);
        full |= r == PSB_BRANCH_CAPACITY; /* a rerun that finds fewer does not undo it */
        if (r < 0 || round == 3 || s->branch.h_init / 16 < 8 * s->branch.h) break;
        turned = sw->chord_turn_max > PSB__CHORD_TURN || sw->cone_defect > psb__cone_tolerance(sw);
        /* an odd count that a smaller h_init kept is no kink's doing: on cones the run
           is the same, scaled */
        if (!turned && (rep->n_branches % 2 == 0 || rep->n_branches == before)) break;
        before = rep->n_branches;
        s->branch.h_init /= 16;
    }
    /* not with patience (the caller chose to stop early), nor past max_pc */
    if (r == PSB_SUCCESS && s->branch.n_span_max > s->branch.n_span && !s->branch.expert.no_memo &&
        !s->branch.expert.patience && !(s->branch.max_pc && rep->n_pc >= s->branch.max_pc) &&
        psb__unbalanced(s, sw, ys, ts, rep->n_branches, &r)) {
        int overflow = 0, counted = rep->n_span;
        r = psb__odd_sweeps(s, sw, y0c, max_branches, ys, ts, rep, &overflow);
        rep->n_span_odd = rep->n_span - counted;
        r = psb__sweeps_end(s, rep, r, overflow);
    }
    if ((r == PSB_SUCCESS || r == PSB_BRANCH_CAPACITY) && rep->n_branches % 2 == 0)
        rep->unbalanced = psb__unbalanced(s, sw, ys, ts, rep->n_branches, &r);
    s->branch.h_init = h_init;
    return r == PSB_SUCCESS && full ? PSB_BRANCH_CAPACITY : r;
}

PSCBRANCH_DEF psb_result psb_find_branches(psb_solver *s, const double *y0, const double *t0,
                                           const psb_branch_options *bo, int max_branches,
                                           double *ys, double *ts, psb_branch_report *rep)
{
    psb_result r;
    if (rep) memset(rep, 0, sizeof *rep);
    r = psb__check_couple(s, y0, t0);
    if (r == PSB_SUCCESS) r = psb__branch_begin(s, bo, y0);
    return r == PSB_SUCCESS ? psb__find_branches(s, &s->internal_.sweep, y0, t0, max_branches, ys, ts, rep) : r;
}

/* ==== Branch point switch (psb_branch_point_switch) =============================================
   Every branch through a smooth branch point: Newton on spheres around it.
   Near a branch point y* the solutions lie, to first order, on lines through y* in the kernel
   of dH(y*): the plane of t and the second kernel direction k at a simple branch point. Trial
   points y* + r v, v in that kernel, are corrected by Newton on the sphere ||y - y*||_w = r,
   which lands where a branch crosses the sphere: the crossings are isolated points, so two
   trials landed on the same branch when they lie within r sqrt(2 (1 - c_diff)) of each other
   (c_diff's angle seen from y*). Unlike a trial step's landing point, which lies anywhere from
   h_min to h from y*, a crossing does not depend on where the trial started, so curved
   branches are told apart by c_diff as straight ones are. */

#define PSB__KERNEL_MAX 4 /* kernel directions besides t that psb_branch_point_switch sweeps */

/* One trial from y* + r v (v unit); a new crossing is stored (*overflow when no room). landed
   (the traced curve's trials, -t and +t; else NULL): counts the trials that land, and a
   failed one stores the couple (y*, v), so that branches 0 and 1 stay the traced curve. */
static psb_result psb__sphere_trial(psb_solver *s, const double *y, const double *v, double r,
                                    int *landed, int max_branches, double *ys, double *ts,
                                    psb_branch_report *rep, int *overflow)
{
    int np1 = s->internal_.np1, j, m;
    double *yb = PSB__VEC(s, PSB__V_BR_Y), *tb = PSB__VEC(s, PSB__V_BR_T);
    psb_result res;
    for (m = 0; m < np1; m++) yb[m] = y[m] + r * v[m];
    rep->n_pc++;
    s->stats.n_pc_steps++;
    res = psb__newton_on(s, yb, tb, y, NULL, r);
    if (psb__is_fatal(res)) return res;
    if (res != PSB_SUCCESS) {
        psb__note_fault(s, res); /* a trial lost to a fault may be a branch lost */
        if (!landed) return PSB_SUCCESS;
        psb__copy(yb, y, np1);
        psb__copy(tb, v, np1);
    } else {
        double same = r * sqrt(2 * (1 - s->opt.c_diff));
        if (landed) (*landed)++;
        for (j = 0; j < rep->n_branches; j++)
            if (psb__dist_w(s, yb, ys + (size_t)j * (size_t)np1) <= same) return PSB_SUCCESS;
    }
    psb__add_branch(s, yb, tb, max_branches, ys, ts, rep, overflow);
    return PSB_SUCCESS;
}

/* Kernel directions of dH at y beyond t and ks[0] (given): inverse iteration, two steps from
   random vectors, with B = [dH(y + delta t); (W t)^T], delta = 1e-4 r, whose near-null vectors
   span the kernel w-orthogonal to t to O(delta). A direction is new when its part outside t
   and the known ones is above 1e-3 (a near-null vector keeps O(1) of it, any other ~delta^2).
   Returns the number of directions in ks (PSB__KERNEL_MAX at most), at least 1, or a fatal
   result code (< 0: a callback's stop). */
static int psb__kernel_dirs(psb_solver *s, const double *y, const double *t, double r, double *ks)
{
    int np1 = s->internal_.np1, kdim = 1, i, j, it, attempt;
    double *yq = PSB__VEC(s, PSB__V_BR_P), *row = s->internal_.work, *v = ks + (size_t)kdim * (size_t)np1;
    psb_result res = PSB_ERR_SINGULAR;
    for (attempt = 0; attempt < 3 && res != PSB_SUCCESS; attempt++) {
        psb__axpy_to(yq, y, 1e-4 * r * pow(4.0, attempt), t, np1);
        res = psb__jacobian(s, yq, NULL);
        if (res != PSB_SUCCESS) break;
        for (i = 0; i < np1; i++) row[i] = s->internal_.w[i] * t[i];
        res = psb__factor_bordered(s, row, NULL);
    }
    if (psb__is_fatal(res)) return (int)res;
    if (res != PSB_SUCCESS) { /* the kernel beyond ks[0] unknown: a fault may hide branches */
        psb__note_fault(s, res);
        return kdim;
    }
    while (kdim < PSB__KERNEL_MAX) {
        double before, after;
        v = ks + (size_t)kdim * (size_t)np1;
        for (i = 0; i < np1; i++) v[i] = psb__gauss(s->internal_.rng) / sqrt(s->internal_.w[i]);
        for (it = 0; it < 2; it++) {
            res = psb__solve_factored(s, v, 1);
            if (psb__is_fatal(res)) return (int)res;
            if (res != PSB_SUCCESS) psb__note_fault(s, res);
            if (res != PSB_SUCCESS || !psb__normalize_w(s, v)) return kdim;
        }
        before = psb_norm_w(s, v);
        for (it = 0; it < 2; it++) { /* twice: Gram-Schmidt that keeps orthogonality */
            double c = psb_dot_w(s, v, t);
            for (i = 0; i < np1; i++) v[i] -= c * t[i];
            for (j = 0; j < kdim; j++) {
                const double *kj = ks + (size_t)j * (size_t)np1;
                c = psb_dot_w(s, v, kj);
                for (i = 0; i < np1; i++) v[i] -= c * kj[i];
            }
        }
        after = psb_norm_w(s, v);
        if (!(after > 1e-3 * before) || !psb__normalize_w(s, v)) break;
        kdim++;
    }
    s->message[0] = 0;
    return kdim;
}

/* The trials at radius r: the circle of t and ks[0] (2 n_dir angles, -t first, then +t, then
   the others in order), and with a larger kernel (kdim > 1) 2 n_dir kdim^2 random directions
   in it. *traced: how many of the -t and +t trials landed. */
static psb_result psb__sphere_sweep(psb_solver *s, const double *y, const double *t, const double *ks,
                                    int kdim, double r, int max_branches, double *ys, double *ts,
                                    psb_branch_report *rep, int *overflow, int *traced)
{
    int np1 = s->internal_.np1, n_trial = 2 * s->branch.n_dir, i, j, m;
    double *v = PSB__VEC(s, PSB__V_BR_TT);
    psb_result res;
    *traced = 0;
    for (i = 0; i < n_trial; i++) {
        int step = i == 0 ? n_trial / 2 : i == 1 ? 0 : i <= n_trial / 2 ? i - 1 : i;
        double a = 6.283185307179586 * step / n_trial;
        for (m = 0; m < np1; m++) v[m] = cos(a) * t[m] + sin(a) * ks[m];
        res = psb__sphere_trial(s, y, v, r, i < 2 ? traced : NULL, max_branches, ys, ts, rep, overflow);
        if (res != PSB_SUCCESS) return res;
    }
    for (i = 0; kdim > 1 && i < n_trial * kdim * kdim; i++) {
        double g = psb__gauss(s->internal_.rng);
        for (m = 0; m < np1; m++) v[m] = g * t[m];
        for (j = 0; j < kdim; j++) {
            g = psb__gauss(s->internal_.rng);
            for (m = 0; m < np1; m++) v[m] += g * ks[(size_t)j * (size_t)np1 + (size_t)m];
        }
        if (!psb__normalize_w(s, v)) continue;
        res = psb__sphere_trial(s, y, v, r, NULL, max_branches, ys, ts, rep, overflow);
        if (res != PSB_SUCCESS) return res;
    }
    return PSB_SUCCESS;
}

/* psb__switch_inner_kink's stop: the walk back from a crossing has come within r / 64 of the
   branch point y0 along the chord u (or passed it), or met a kink (kink set). */
typedef struct psb__inner_walk {
    const psb_solver *s;
    const double *y0, *u;
    double stop;
    int kink;
} psb__inner_walk;

static int psb__inner_walk_point(const psb_point *pt, void *user)
{
    psb__inner_walk *w = (psb__inner_walk *)user;
    double along = 0;
    int i;
    if (pt->flags & PSB_POINT_KINK) return w->kink = 1;
    for (i = 0; i < w->s->internal_.np1; i++) along += w->s->internal_.w[i] * (pt->y[i] - w->y0[i]) * w->u[i];
    return along <= w->stop;
}

/* The distance from the branch point y0 to a kink between it and the crossing (ysk, tsk) of
   the sphere of radius r, or r when the branch runs smoothly from r / 64 to r (or the walk
   cannot tell); < 0 a fatal code. The walk back from the crossing (steps of r / 8, up to
   r / 4) stops at the first kink, passed (locate_kinks) or not (no_switch): the branches
   leaving a smooth branch point are traced from their crossings outwards, so a kink, a PC1
   point among them, closer than the radius would never be met. */
static double psb__switch_inner_kink(psb_solver *s, const double *y0, double r, const double *ysk,
                                     const double *tsk)
{
    int np1 = s->internal_.np1, i;
    double *y = PSB__VEC(s, PSB__V_BR_Y), *t = PSB__VEC(s, PSB__V_BR_T), *u = PSB__VEC(s, PSB__V_BR_S);
    double d = psb__dist_w(s, ysk, y0), h_init = s->opt.h_init, h_max = s->opt.h_max;
    psb_trace_options to;
    psb_trace_report tr;
    psb__inner_walk walk;
    psb_result res;
    long faults[4], n_ok = s->internal_.n_ok;
    if (!(d > 0.5 * r)) return r;
    memcpy(faults, s->internal_.faults, sizeof faults);
    for (i = 0; i < np1; i++) u[i] = (ysk[i] - y0[i]) / d;
    psb__copy(y, ysk, np1);
    for (i = 0; i < np1; i++) t[i] = -tsk[i];
    memset(&to, 0, sizeof to);
    to.no_switch = 1;
    to.locate_kinks = 1;
    to.max_steps = 256; /* about 5 steps; more only where h_max < r / 4 */
    to.on_point = psb__inner_walk_point;
    to.point_user = &walk;
    walk.s = s;
    walk.y0 = y0;
    walk.u = u;
    walk.stop = r / 64;
    walk.kink = 0;
    s->opt.h_max = fmax(fmin(h_max, r / 4), s->opt.h_min);
    s->opt.h_init = fmax(fmin(r / 8, s->opt.h_max), s->opt.h_min);
    res = psb_trace(s, y, t, &to, &tr);
    s->opt.h_init = h_init;
    s->opt.h_max = h_max;
    if (psb__is_fatal(res)) return res;
    /* the sweep's own fault accounting, plus a fault of the walk's: a kink it missed for it
       may be a branch lost */
    memcpy(s->internal_.faults, faults, sizeof faults);
    s->internal_.n_ok = n_ok;
    if (res == PSB_ERR_CALLBACK_FAILED || res == PSB_ERR_NONFINITE) psb__note_fault(s, res);
    s->message[0] = 0;
    if (res != PSB_NONSMOOTH_END && !walk.kink) return r;
    d = psb__dist_w(s, y, y0);
    return d < r ? d : r;
}

/* The switch with the options in s->branch (psb_branch_point_switch, psb_explore). */
static psb_result psb__branch_point_switch(psb_solver *s, const double *y, const double *t,
                                           const double *kernel, int max_branches, double *ys,
                                           double *ts, psb_branch_report *rep)
{
    psb_branch_report local;
    int np1, i, overflow = 0, kdim, traced = 0, round, tried = 0;
    unsigned long long seed;
    double *yc, *tc, *kc, c, r = 0, r0, kink_at;
    psb_result res;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    res = psb__check_couple(s, y, t);
    if (res != PSB_SUCCESS) return res;
    if (!kernel || !ys || !ts) return psb__fail(s, PSB_ERR_NULL, "kernel, ys or ts is NULL");
    if (max_branches < 1) return psb__fail(s, PSB_ERR_SIZE, "max_branches must be >= 1");
    np1 = s->internal_.np1;
    if (!psb__all_finite(kernel, (size_t)np1)) return psb__fail(s, PSB_ERR_NONFINITE, "kernel contains NaN or Inf");
    yc = PSB__VEC(s, PSB__V_BR_Y0);
    tc = PSB__VEC(s, PSB__V_BR_T0);
    kc = PSB__VEC(s, PSB__V_BP_K0); /* PSB__KERNEL_MAX vectors from here: BP_K0 .. BP_K3 */
    psb__copy(yc, y, np1);
    psb__copy(tc, t, np1);
    if (!psb__normalize_w(s, tc)) return psb__fail(s, PSB_ERR_INPUT, "t is zero");
    c = psb_dot_w(s, kernel, tc);
    for (i = 0; i < np1; i++) kc[i] = kernel[i] - c * tc[i];
    /* a part across t at rounding level of the kernel's own is no direction: parallel to t */
    if (!(psb__norm_w(s, kc) > 64 * DBL_EPSILON * psb__norm_w(s, kernel)) || !psb__normalize_w(s, kc))
        return psb__fail(s, PSB_ERR_INPUT, "kernel is zero or parallel to t");
    seed = s->opt.seed;
    for (i = 0; i < 4; i++) s->internal_.rng[i] = psb__splitmix(&seed);
    psb__faults_reset(s);
    kdim = psb__kernel_dirs(s, yc, tc, s->branch.h_init, kc);
    if (kdim < 0) return (psb_result)kdim;
    rep->n_tangents = kdim;
    /* a simple branch point has four half-branches, two of them the traced curve; fewer at
       h_init (a radius beyond the branches' curvature, or crossings too close for Newton's
       basins) -> a smaller one. A kink between y and a crossing (psb__switch_inner_kink) ->
       a radius within it, so that the trace from the crossing meets the kink */
    r0 = s->branch.h_init;
    for (round = 0; round < 3; round++) {
        for (r = r0, i = 0; i < 3; i++, r *= 0.125) {
            psb_branch_report attempt;
            memset(&attempt, 0, sizeof attempt);
            overflow = 0;
            res = psb__sphere_sweep(s, yc, tc, kc, kdim, r, max_branches, ys, ts, &attempt, &overflow, &traced);
            attempt.n_pc += rep->n_pc;
            attempt.n_tangents = kdim;
            *rep = attempt;
            rep->n_span = ++tried;
            if (res != PSB_SUCCESS) return res;
            if ((rep->n_branches >= 4 && traced == 2) || overflow) break;
        }
        if (i == 3) r *= 8; /* the radius of the last sweep */
        kink_at = r;
        /* from 1: branch 0 is the traced curve behind y, which the trace came along */
        for (i = 1; i < rep->n_branches && i < max_branches; i++) {
            double d = psb__switch_inner_kink(s, yc, r, ys + (size_t)i * (size_t)np1, ts + (size_t)i * (size_t)np1);
            if (d < 0) return (psb_result)d;
            if (d < kink_at) kink_at = d;
        }
        if (kink_at >= r) break;
        r0 = 0.25 * kink_at;
    }
    psb__report_faults(s, rep);
    res = psb__faults_code(s, "psb_branch_point_switch");
    if (res != PSB_SUCCESS) return res;
    /* the traced curve passes through a branch point: found in neither direction at any
       radius, y is not on it (or h_init lies far beyond its curvature) */
    if (!traced) {
        rep->n_branches = 0; /* the kept (y*, -+t) are no crossings */
        return psb__fail(s, PSB_ERR_NO_CONVERGENCE, "psb_branch_point_switch: the traced curve crosses none of "
                                                     "the spheres around y (y not on it, or h_init too large)");
    }
    s->message[0] = 0;
    return overflow ? PSB_BRANCH_CAPACITY : PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_branch_point_switch(psb_solver *s, const double *y, const double *t,
                                                 const double *kernel, const psb_branch_options *bo,
                                                 int max_branches, double *ys, double *ts,
                                                 psb_branch_report *rep)
{
    psb_result r;
    if (rep) memset(rep, 0, sizeof *rep);
    r = psb__check_couple(s, y, t);
    if (r == PSB_SUCCESS) r = psb__trace_busy(s, "psb_branch_point_switch");
    if (r == PSB_SUCCESS) r = psb__branch_begin(s, bo, y);
    return r == PSB_SUCCESS ? psb__branch_point_switch(s, y, t, kernel, max_branches, ys, ts, rep) : r;
}

/* ==== Exploring the whole diagram (psb_explore) =================================================
   The explorer's queue and graph (psb__explorer) over psb_trace and the branching calls. */

/* Scratch vectors of the explorer (n+1 each), after the nodes' storage: the couple being
   traced, the couple where a trace stopped for a branching (a kink's or a detector's), the
   detector's kernel direction, the stop couple before Algorithm 2.1 moved it, the trace's
   previous accepted point, and the node index's direction (psb__index_key). */
enum { PSB__X_Y, PSB__X_T, PSB__X_SY, PSB__X_ST, PSB__X_K, PSB__X_P, PSB__X_PREV, PSB__X_V, PSB__NX };

/* Carves the diagram's arrays out of memory (when d is not NULL) and returns the bytes needed
   (0 for invalid sizes), so that the size query and the layout cannot disagree. */
static size_t psb__diagram_layout(int n, int max_nodes, int max_edges, int max_branches,
                                  psb_diagram *d, void *memory)
{
    size_t np1 = (size_t)n + 1, nn = (size_t)max_nodes, nb = (size_t)max_branches, off, dbl, i;
    char *base = (char *)memory;
    double total;
    if (n < 1 || max_nodes < 1 || max_edges < 1 || max_branches < 1) return 0;
    total = (double)max_nodes * (sizeof(psb_node) + ((2.0 * max_branches + 1) * (n + 1.0) + 1) * sizeof(double) +
                                 (max_branches + 1.0) * (double)sizeof(int)) +
            (double)max_edges * sizeof(psb_edge) + (PSB__NX + 4.0) * (n + 1.0) * sizeof(double) + 64;
    if (total > (double)((size_t)-1 / 2)) return 0;
    off = psb__align(nn * sizeof(psb_node));
    off += psb__align((size_t)max_edges * sizeof(psb_edge));
    dbl = off;
    off += psb__align(((nn * (2 * nb + 1) + PSB__NX) * np1 + nn) * sizeof(double));
    if (d) {
        double *pool = (double *)(void *)(base + dbl);
        int *ints = (int *)(void *)(base + off);
        d->nodes = (psb_node *)(void *)base;
        d->edges = (psb_edge *)(void *)(base + psb__align(nn * sizeof(psb_node)));
        for (i = 0; i < nn; i++) {
            psb_node *nd = d->nodes + i;
            nd->y = pool + i * (2 * nb + 1) * np1;
            nd->ys = nd->y + np1;
            nd->ts = nd->ys + nb * np1;
            nd->branch_edge = ints + i * nb;
        }
        d->work_ = pool + nn * (2 * nb + 1) * np1;
        d->index_key_ = d->work_ + (size_t)PSB__NX * np1;
        d->index_node_ = ints + nn * nb;
    }
    return off + psb__align(nn * (nb + 1) * sizeof(int));
}

PSCBRANCH_DEF size_t psb_diagram_memory_size(int n, int max_nodes, int max_edges, int max_branches)
{
    return psb__diagram_layout(n, max_nodes, max_edges, max_branches, NULL, NULL);
}

PSCBRANCH_DEF psb_result psb_diagram_init_with_memory(psb_diagram *d, int n, int max_nodes,
                                                      int max_edges, int max_branches,
                                                      void *memory, size_t bytes)
{
    size_t need;
    if (!d) return PSB_ERR_NULL;
    memset(d, 0, sizeof *d);
    if (!memory) return PSB_ERR_NULL;
    need = psb__diagram_layout(n, max_nodes, max_edges, max_branches, NULL, NULL);
    if (!need) return PSB_ERR_SIZE;
    if (bytes < need) return PSB_ERR_NOMEM;
    d->n = n;
    d->param_index = n;
    d->result = PSB_ERR_INPUT; /* nothing explored yet */
    d->max_nodes = max_nodes;
    d->max_edges = max_edges;
    d->max_branches = max_branches;
    psb__diagram_layout(n, max_nodes, max_edges, max_branches, d, memory);
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_diagram_init(psb_diagram *d, int n, int max_nodes, int max_edges,
                                          int max_branches)
{
    size_t bytes;
    void *mem;
    psb_result r;
    if (!d) return PSB_ERR_NULL;
    memset(d, 0, sizeof *d);
    bytes = psb__diagram_layout(n, max_nodes, max_edges, max_branches, NULL, NULL);
    if (!bytes) return PSB_ERR_SIZE;
    mem = PSCBRANCH_MALLOC(bytes);
    if (!mem) return PSB_ERR_NOMEM;
    r = psb_diagram_init_with_memory(d, n, max_nodes, max_edges, max_branches, mem, bytes);
    if (r < 0) {
        PSCBRANCH_FREE(mem);
        return r;
    }
    d->owned_ = mem;
    return r;
}

PSCBRANCH_DEF void psb_diagram_free(psb_diagram *d)
{
    if (!d) return;
    if (d->owned_) PSCBRANCH_FREE(d->owned_);
    if (d->grown_) d->grow_.release(d->grown_, d->grow_.user);
    if (d->grown_points_) d->grow_.release(d->grown_points_, d->grow_.user);
    d->owned_ = d->grown_ = d->grown_points_ = NULL;
    d->nodes = NULL;
    d->edges = NULL;
    d->points = NULL;
    d->n_nodes = d->n_edges = 0;
    d->max_points = d->n_stored_points = 0;
}

PSCBRANCH_DEF psb_result psb_diagram_set_points(psb_diagram *d, double *memory, long max_points)
{
    if (!d || !d->nodes) return PSB_ERR_NULL;
    if (max_points < 0 || (max_points > 0 && !memory)) return PSB_ERR_SIZE;
    if (d->grown_points_) d->grow_.release(d->grown_points_, d->grow_.user);
    d->grown_points_ = NULL;
    d->points = memory;
    d->max_points = max_points;
    d->n_stored_points = 0;
    d->store_points_ = 1;
    return PSB_SUCCESS;
}

static void *psb__default_alloc(size_t bytes, void *user)
{
    (void)user;
    return PSCBRANCH_MALLOC(bytes);
}

static void psb__default_release(void *memory, void *user)
{
    (void)user;
    PSCBRANCH_FREE(memory);
}

PSCBRANCH_DEF psb_result psb_diagram_set_growth(psb_diagram *d, const psb_allocator *a, size_t max_bytes)
{
    if (!d || !d->nodes || (a && (!a->alloc || !a->release))) return PSB_ERR_NULL;
    if (d->grown_ || d->grown_points_) return PSB_ERR_INPUT;
    if (a) {
        d->grow_ = *a;
    } else {
        d->grow_.alloc = psb__default_alloc;
        d->grow_.release = psb__default_release;
        d->grow_.user = NULL;
    }
    d->grows_ = 1;
    d->grow_max_ = max_bytes;
    return PSB_SUCCESS;
}

/* Moves d into a block with the given capacities (each at least the current one), from its
   allocator; d's scratch (work_) stays in its first block. Returns 1, or 0 (no growth, the
   bound, or no memory: d unchanged). */
static int psb__diagram_grow(psb_diagram *d, int max_nodes, int max_edges, int max_branches)
{
    psb_diagram g;
    size_t bytes, np1 = (size_t)d->n + 1, nb, i;
    void *mem;
    if (!d->grows_) return 0;
    bytes = psb__diagram_layout(d->n, max_nodes, max_edges, max_branches, NULL, NULL);
    if (!bytes || (d->grow_max_ && bytes > d->grow_max_)) return 0;
    mem = d->grow_.alloc(bytes, d->grow_.user);
    if (!mem) return 0;
    memset(&g, 0, sizeof g);
    psb__diagram_layout(d->n, max_nodes, max_edges, max_branches, &g, mem);
    for (i = 0; i < (size_t)d->n_nodes; i++) {
        const psb_node *from = d->nodes + i;
        psb_node *to = g.nodes + i, keep = *to;
        nb = (size_t)from->n_branches;
        *to = *from;
        to->y = keep.y;
        to->ys = keep.ys;
        to->ts = keep.ts;
        to->branch_edge = keep.branch_edge;
        psb__copy(to->y, from->y, (int)np1);
        if (nb) {
            memcpy(to->ys, from->ys, nb * np1 * sizeof(double));
            memcpy(to->ts, from->ts, nb * np1 * sizeof(double));
            memcpy(to->branch_edge, from->branch_edge, nb * sizeof(int));
        }
    }
    if (d->n_edges) memcpy(g.edges, d->edges, (size_t)d->n_edges * sizeof(psb_edge));
    memcpy(g.index_key_, d->index_key_, (size_t)d->max_nodes * sizeof(double));
    memcpy(g.index_node_, d->index_node_, (size_t)d->max_nodes * sizeof(int));
    if (d->grown_) d->grow_.release(d->grown_, d->grow_.user);
    d->grown_ = mem;
    d->nodes = g.nodes;
    d->edges = g.edges;
    d->index_key_ = g.index_key_;
    d->index_node_ = g.index_node_;
    d->max_nodes = max_nodes;
    d->max_edges = max_edges;
    d->max_branches = max_branches;
    return 1;
}

/* Twice the capacity c, at most INT_MAX. */
static int psb__twice(int c) { return c > INT_MAX / 2 ? INT_MAX : 2 * c; }

/* Room for one more stored point: grows the points where d grows. Returns 1, or 0. */
static int psb__diagram_point_room(psb_diagram *d)
{
    long cap;
    size_t np1 = (size_t)d->n + 1, bytes;
    double *mem;
    if (d->n_stored_points < d->max_points) return 1;
    if (!d->grows_) return 0;
    cap = d->max_points < 64 ? 128 : (d->max_points > LONG_MAX / 2 ? LONG_MAX : 2 * d->max_points);
    if ((double)cap * (double)np1 * sizeof(double) > (double)((size_t)-1 / 2)) return 0;
    bytes = (size_t)cap * np1 * sizeof(double);
    if (d->grow_max_ && bytes > d->grow_max_) return 0;
    mem = (double *)d->grow_.alloc(bytes, d->grow_.user);
    if (!mem) return 0;
    if (d->n_stored_points) memcpy(mem, d->points, (size_t)d->n_stored_points * np1 * sizeof(double));
    if (d->grown_points_) d->grow_.release(d->grown_points_, d->grow_.user);
    d->grown_points_ = mem;
    d->points = mem;
    d->max_points = cap;
    return 1;
}

PSCBRANCH_DEF const char *psb_node_kind_string(psb_node_kind kind)
{
    static const char *const names[] = {"start", "nonsmooth", "branch", "pc1", "fold",
                                        "event", "bound", "budget", "failure", "kink"};
    return kind >= PSB_NODE_START && kind <= PSB_NODE_KINK ? names[kind] : "unknown";
}

PSCBRANCH_DEF const char *psb_edge_end_string(psb_edge_end end)
{
    static const char *const names[] = {"node", "bound", "box", "budget", "loop", "failure"};
    return end >= PSB_EDGE_NODE && end <= PSB_EDGE_FAILURE ? names[end] : "unknown";
}

/* Why the explorer's point callback stopped a trace. */
enum { PSB__XS_NONE, PSB__XS_USER, PSB__XS_POINTS, PSB__XS_BOX, PSB__XS_KINK, PSB__XS_SPECIAL,
       PSB__XS_NODE };

typedef struct psb__explorer {
    psb_solver *s;
    psb_diagram *d;
    const psb_explore_options *eo;
    double node_tol;
    int edge, from, stop, stop_node;
    psb_node_kind stop_kind; /* the branching the stop asks for (NONSMOOTH, BRANCH, PC1) */
    int has_kernel;
    int detect;    /* the edge's detectors (PSB_DETECT_*) */
    int located;   /* the stop's PC1 point is located already (psb_special.located) */
    int plain_ok;  /* a two-branch end where the switch failed may resume as an ordinary kink */
    double stop_precision;
    long points;
    double length;
    int away;      /* the edge has been farther than away_r from its origin node, or past a */
    double away_r; /* kink: a return to the origin is an arrival there, not the edge's start */
    int queue_from; /* no node below it has an untraced branch */
    /* the branching nodes' index (psb__index_key): how many, and the largest tolerance plus
       4 precisions and key magnitude among them */
    int n_index;
    double index_reach, index_abs;
    int from_branch;  /* the edge's branch of node from */
    double *work;     /* the scratch vectors (PSB__X_*): the diagram's, or a draft's own */
    struct psb__draft *draft; /* a draft's trace on a worker (psb__draft_task), else NULL */
    const struct psb__drafts *drafts; /* the drafts' slots (with draft) */
} psb__explorer;

#define PSB__XVEC(x, k) ((x)->work + (size_t)(k) * (size_t)(x)->s->internal_.np1)

/* node_tol at node nd: as set or resolved; with differences and h following the point, 16
   times h at the node (Algorithm 2.1 stops about a difference step short of the point, often
   10 times beyond its precision bound: with 0, a loop's PC1 points became two nodes each and
   every edge was traced twice). */
static double psb__explore_tol(const psb__explorer *x, const psb_node *nd)
{
    return x->node_tol > 0 || !x->s->internal_.branch_h_auto ? x->node_tol : 16 * psb__auto_branch_h(x->s, &x->s->branch, nd->y);
}

/* Whether y is within tolerance of node nd (precision: y's own location error). */
static int psb__explore_near(const psb__explorer *x, const psb_node *nd, const double *y,
                             double precision)
{
    return psb__dist_w(x->s, y, nd->y) <= psb__explore_tol(x, nd) + 4 * (precision + nd->precision);
}

static int psb__is_branching_node(psb_node_kind kind)
{
    return kind == PSB_NODE_NONSMOOTH || kind == PSB_NODE_BRANCH || kind == PSB_NODE_PC1;
}

/* A node that edges end at and leave from: a branching node or a kink node. */
static int psb__is_junction(psb_node_kind kind) { return psb__is_branching_node(kind) || kind == PSB_NODE_KINK; }

/* The node index: the branching nodes sorted by their key <v, y>, v = X_V a fixed direction
   with |<v, a - b>| <= ||a - b||_w (v_i = sqrt(w_i) u_i / |u|, u drawn from a fixed seed).
   A node within r of a point, or of a chord, has its key within r of the point's, or of the
   chord's range of keys: a look-up visits only those, not every node. *abs_sum: the terms'
   magnitude, for the rounding margin. */
static double psb__index_key(const psb__explorer *x, const double *y, double *abs_sum)
{
    const double *v = PSB__XVEC(x, PSB__X_V);
    double key = 0, a = 0;
    int i;
    for (i = 0; i < x->s->internal_.np1; i++) {
        key += v[i] * y[i];
        a += fabs(v[i] * y[i]);
    }
    if (abs_sum) *abs_sum = a;
    return key;
}

static void psb__index_direction(psb__explorer *x)
{
    double *v = PSB__XVEC(x, PSB__X_V), norm = 0;
    unsigned long long seed = 0x5eed1dc0ffeeULL;
    int i, np1 = x->s->internal_.np1;
    for (i = 0; i < np1; i++) {
        v[i] = 2 * psb__unit(psb__splitmix(&seed)) - 1;
        norm += v[i] * v[i];
    }
    norm = sqrt(norm);
    for (i = 0; i < np1; i++) v[i] = norm > 0 ? sqrt(x->s->internal_.w[i]) * v[i] / norm : 0;
    x->n_index = 0;
    x->index_reach = x->index_abs = 0;
}

/* The first index position whose key is >= key. */
static int psb__index_lower(const psb__explorer *x, double key)
{
    int lo = 0, hi = x->n_index;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        if (x->d->index_key_[mid] < key) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Puts branching node j into the index (its reach: tolerance plus 4 precisions). */
static void psb__index_add(psb__explorer *x, int j)
{
    const psb_node *nd = x->d->nodes + j;
    double a, key = psb__index_key(x, nd->y, &a), reach = psb__explore_tol(x, nd) + 4 * nd->precision;
    int at = psb__index_lower(x, key), i;
    for (i = x->n_index; i > at; i--) {
        x->d->index_key_[i] = x->d->index_key_[i - 1];
        x->d->index_node_[i] = x->d->index_node_[i - 1];
    }
    x->d->index_key_[at] = key;
    x->d->index_node_[at] = j;
    x->n_index++;
    if (reach > x->index_reach) x->index_reach = reach;
    if (a > x->index_abs) x->index_abs = a;
}

/* The index's range [*first, *last) that may hold a node within `extra` (beyond its own
   reach) of the chord from a to b (b may be a). */
static void psb__index_range(const psb__explorer *x, const double *a, const double *b, double extra,
                             int *first, int *last)
{
    double abs_a, abs_b, ka = psb__index_key(x, a, &abs_a), kb = psb__index_key(x, b, &abs_b);
    double margin = x->index_reach + extra +
                    4 * DBL_EPSILON * (x->s->internal_.np1 + 2) * (abs_a + abs_b + x->index_abs);
    *first = psb__index_lower(x, fmin(ka, kb) - margin);
    *last = psb__index_lower(x, fmax(ka, kb) + margin);
    while (*last < x->n_index && x->d->index_key_[*last] <= fmax(ka, kb) + margin) (*last)++;
}

/* A new node of the given kind at y, or -1 when the nodes are used up. */
static int psb__explore_add_node(psb__explorer *x, psb_node_kind kind, const double *y,
                                 double precision, int edge)
{
    psb_diagram *d = x->d;
    psb_node *nd;
    if (d->n_nodes == d->max_nodes &&
        !psb__diagram_grow(d, psb__twice(d->max_nodes), d->max_edges, d->max_branches)) {
        d->truncated = 1;
        return -1;
    }
    nd = d->nodes + d->n_nodes;
    nd->kind = kind;
    psb__copy(nd->y, y, x->s->internal_.np1);
    nd->precision = precision;
    nd->param = y[x->s->prob.param_index];
    nd->edge = edge;
    nd->event = -1;
    nd->direction = 0;
    nd->n_branches = 0;
    if (psb__is_junction(kind)) psb__index_add(x, d->n_nodes);
    return d->n_nodes++;
}

/* Ends edge e at a new node of the given kind at y (bound, budget, failure). */
static void psb__explore_end(psb__explorer *x, int e, psb_edge_end end, psb_node_kind kind,
                             const double *y)
{
    int to = psb__explore_add_node(x, kind, y, 0, e); /* may move the edges */
    psb_edge *ed = x->d->edges + e;
    ed->end = end;
    ed->to = to;
    ed->to_branch = -1;
    if (end == PSB_EDGE_FAILURE) x->d->n_failed++;
}

/* Whether y's parameter lies outside the traces' bounds (when they are set). */
static int psb__explore_beyond_bound(const psb__explorer *x, const double *y)
{
    const psb_trace_options *to = &x->eo->trace;
    int p = x->s->prob.param_index;
    return to->param_min < to->param_max && (!(y[p] >= to->param_min) || !(y[p] <= to->param_max));
}

/* Ends edge e on the parameter bound between y0 (inside) and y (beyond it), at Newton's
   solution there from the chord (into y), adding its distance from y0 to the edge's length. A
   failure there ends the edge as one. Returns PSB_SUCCESS or a fatal code. */
static psb_result psb__explore_end_on_bound(psb__explorer *x, int e, const double *y0, double *y)
{
    psb_solver *s = x->s;
    psb_edge *ed = x->d->edges + e;
    const psb_trace_options *to = &x->eo->trace;
    psb_result r = psb__land_on_bound(s, y0, y, y[s->prob.param_index] < to->param_min ? to->param_min
                                                                                      : to->param_max);
    ed->result = r == PSB_SUCCESS ? PSB_PARAM_BOUND : r;
    ed->length += psb__dist_w(s, y0, y);
    if (r == PSB_SUCCESS) {
        psb__explore_end(x, e, PSB_EDGE_BOUND, PSB_NODE_BOUND, y);
        return PSB_SUCCESS;
    }
    psb__explore_end(x, e, PSB_EDGE_FAILURE, PSB_NODE_FAILURE, y);
    return psb__is_fatal(r) ? r : PSB_SUCCESS;
}

/* The cosine between the chords from node nd to y and to its branch kb's couple (the
   couple's tangent where it lies at the node itself); -2 when y is at the node. */
static double psb__explore_chord_cos(const psb__explorer *x, const psb_node *nd, int kb, const double *y)
{
    const psb_solver *s = x->s;
    int np1 = s->internal_.np1, i;
    const double *ys = nd->ys + (size_t)kb * (size_t)np1, *ts = nd->ts + (size_t)kb * (size_t)np1;
    double dot = 0, na = 0, nb = 0;
    int at_node = psb__dist_w(s, ys, nd->y) <= psb__explore_tol(x, nd);
    for (i = 0; i < np1; i++) {
        double a = y[i] - nd->y[i], b = at_node ? ts[i] : ys[i] - nd->y[i];
        dot += s->internal_.w[i] * a * b;
        na += s->internal_.w[i] * a * a;
        nb += s->internal_.w[i] * b * b;
    }
    return na > 0 && nb > 0 ? dot / sqrt(na * nb) : -2;
}

/* Edge e arrived at node j along the branch whose tangent away from j is -t: marks that
   branch traced (the best match by cosine, taken at c_diff, else at c_min), or adds it. */
/* The branch of nd that a trace arriving with tangent t comes in by (its outward tangent the
   closest to -t; -1 when nd has none), *best_cos that cosine. */
static int psb__explore_arrival_branch(const psb__explorer *x, const psb_node *nd, const double *t,
                                       double *best_cos)
{
    int k, best = -1;
    *best_cos = -2;
    for (k = 0; k < nd->n_branches; k++) {
        double c = -psb__cos_w(x->s, t, nd->ts + (size_t)k * (size_t)x->s->internal_.np1);
        if (c > *best_cos) {
            *best_cos = c;
            best = k;
        }
    }
    return best;
}

static void psb__explore_arrive(psb__explorer *x, int e, int j, const double *t)
{
    psb_solver *s = x->s;
    psb_diagram *d = x->d;
    psb_node *nd = d->nodes + j;
    psb_edge *ed;
    int np1 = s->internal_.np1, k;
    double best_cos;
    int best = psb__explore_arrival_branch(x, nd, t, &best_cos);
    if (best >= 0 && best_cos < s->opt.c_diff && best_cos < s->opt.c_min) best = -1;
    if (best < 0 && nd->n_branches == d->max_branches &&
        psb__diagram_grow(d, d->max_nodes, d->max_edges, psb__twice(d->max_branches)))
        nd = d->nodes + j;
    ed = d->edges + e;
    if (best < 0 && nd->n_branches < x->d->max_branches) {
        best = nd->n_branches++;
        psb__copy(nd->ys + (size_t)best * (size_t)np1, nd->y, np1);
        for (k = 0; k < np1; k++) nd->ts[(size_t)best * (size_t)np1 + (size_t)k] = -t[k];
        psb__normalize_w(s, nd->ts + (size_t)best * (size_t)np1);
        nd->branch_edge[best] = e;
    } else if (best < 0) {
        x->d->truncated = 1;
    } else if (nd->branch_edge[best] < 0) {
        nd->branch_edge[best] = e;
    }
    ed->end = PSB_EDGE_NODE;
    ed->to = j;
    ed->to_branch = best;
}

/* The branching at the end of edge e: (y, t) is the couple where the trace stopped (before a
   nonsmooth or PC1 point, or at a located smooth branch point with its kernel estimate in
   X_K). A known node is arrived at; a new one gets its branches (Algorithm 2.1 and 2.2, or
   the switch), branch 0 being the one arrived by. *resume (kinks, with branch_at_kinks): the
   kink was ordinary and (y, t) is now the couple to go on from. Returns PSB_SUCCESS,
   PSB_BRANCH_CAPACITY, or a fatal failure. */
static psb_result psb__explore_branching(psb__explorer *x, int e, double *y, double *t,
                                         int kink, int *resume)
{
    psb_solver *s = x->s;
    psb_diagram *d = x->d;
    psb_edge *ed = d->edges + e;
    psb_node *nd;
    psb_branch_report br;
    psb_node_kind kind = kink ? PSB_NODE_PC1 : x->stop_kind;
    int np1 = s->internal_.np1, j, k, nb;
    /* two balanced branches: an ordinary kink, also where the PC1 detector reported the point
       (a sign change from a smooth branch point within the same step: it is found on the way) */
    int plain_possible = kink || kind == PSB_NODE_PC1 || (kind == PSB_NODE_NONSMOOTH && x->plain_ok);
    double precision = x->stop_precision, *before = PSB__XVEC(x, PSB__X_P);
    psb_result r = PSB_SUCCESS;
    *resume = 0;
    psb__copy(before, y, np1);
    if (kind != PSB_NODE_BRANCH && !(kind == PSB_NODE_PC1 && !kink && x->located)) {
        r = psb__locate_end(s, y, t, &precision);
        if (r < 0) {
            ed->result = r;
            psb__explore_end(x, e, PSB_EDGE_FAILURE, PSB_NODE_FAILURE, y);
            return psb__is_fatal(r) ? r : PSB_SUCCESS;
        }
    }
    ed->length += psb__dist_w(s, before, y);
    {
        /* the first known branching node near y */
        int first, last, i, found = -1;
        psb__index_range(x, y, y, 4 * precision, &first, &last);
        for (i = first; i < last; i++) {
            j = d->index_node_[i];
            if ((found < 0 || j < found) && psb__explore_near(x, d->nodes + j, y, precision)) found = j;
        }
        if (found >= 0) {
            psb__explore_arrive(x, e, found, t);
            return PSB_SUCCESS;
        }
    }
    if (d->n_nodes == d->max_nodes && !psb__diagram_grow(d, psb__twice(d->max_nodes), d->max_edges, d->max_branches)) {
        d->truncated = 1;
        ed = d->edges + e;
        ed->end = PSB_EDGE_NODE;
        ed->to = -1;
        return PSB_BRANCH_CAPACITY;
    }
    for (;;) { /* again with room for more branches where d grows */
        nd = d->nodes + d->n_nodes; /* filled in place, counted once it is a node */
        if (kind == PSB_NODE_BRANCH && x->has_kernel)
            r = psb__branch_point_switch(s, y, t, PSB__XVEC(x, PSB__X_K), d->max_branches, nd->ys,
                                         nd->ts, &br);
        else if (kink && x->eo->kink_spans > 0 && x->eo->kink_spans < s->branch.n_span) {
            /* a short look first: an ordinary kink is told by it, two branches whose outward
               signs cancel (br.unbalanced: two of one sign are not all) among the tangents of
               two pieces alone (sweep.memo_n: a third piece's tangent means three pieces meet
               here, where the look can have missed a pair of branches); else the full sweep
               (reseeded: the same result as without the look) */
            int n_span = s->branch.n_span, n_span_max = s->branch.n_span_max;
            s->branch.n_span = s->branch.n_span_max = x->eo->kink_spans;
            r = psb__find_branches(s, &s->internal_.sweep, y, t, d->max_branches, nd->ys, nd->ts, &br);
            s->branch.n_span = n_span;
            s->branch.n_span_max = n_span_max;
            if (r >= 0 && (br.n_branches != 2 || r == PSB_BRANCH_CAPACITY || br.unbalanced ||
                           s->internal_.sweep.memo_n > 2))
                r = psb__find_branches(s, &s->internal_.sweep, y, t, d->max_branches, nd->ys, nd->ts, &br);
        } else {
            r = psb__find_branches(s, &s->internal_.sweep, y, t, d->max_branches, nd->ys, nd->ts, &br);
        }
        if (r != PSB_BRANCH_CAPACITY ||
            !psb__diagram_grow(d, d->max_nodes, d->max_edges, psb__twice(d->max_branches)))
            break;
    }
    ed = d->edges + e;
    d->n_branchings++;
    if (r < 0) {
        ed->result = r;
        psb__explore_end(x, e, PSB_EDGE_FAILURE, PSB_NODE_FAILURE, y);
        return psb__is_fatal(r) ? r : PSB_SUCCESS;
    }
    if (r == PSB_BRANCH_CAPACITY) d->truncated = 1;
    nb = br.n_branches < d->max_branches ? br.n_branches : d->max_branches;
    /* an ordinary kink, located (branch_at_kinks) or where the tangent switch failed: the other
       branch */
    /* two left unbalanced are no ordinary kink but a node, counted in n_odd */
    if (plain_possible && nb == 2 && !br.unbalanced && r != PSB_BRANCH_CAPACITY) {
        const double *y1 = nd->ys + np1;
        /* a limit point at the kink (the trace stopped there before its fold detector saw the
           parameter turn): a fold node of the edge, as the detector would have made */
        int fold = (x->detect & PSB_DETECT_FOLDS) && t[s->prob.param_index] * nd->ts[np1 + s->prob.param_index] < 0;
        d->n_kinks_plain++;
        if (x->eo->kink_nodes) {
            j = psb__explore_add_node(x, PSB_NODE_KINK, y, precision, -1); /* in the slot: no growth */
            nd = d->nodes + j;
            nd->n_branches = 2;
            nd->branch_edge[0] = e;
            nd->branch_edge[1] = -1;
            ed->end = PSB_EDGE_NODE;
            ed->to = j;
            ed->to_branch = 0;
            if (fold) psb__explore_add_node(x, PSB_NODE_FOLD, y, precision, e);
            return PSB_SUCCESS;
        }
        if (psb__explore_beyond_bound(x, y1)) {
            /* the way on landed beyond a bound (the kink lies within h_init of it): the
               edge ends on the bound, as a branch of a node there does (psb__explore_edge_trace) */
            psb__copy(before, y, np1);
            psb__copy(y, y1, np1);
            return psb__explore_end_on_bound(x, e, before, y);
        }
        if (fold) psb__explore_add_node(x, PSB_NODE_FOLD, y, precision, e); /* in the slot */
        ed->length += psb__dist_w(s, y, y1);
        psb__copy(y, y1, np1);
        psb__copy(t, nd->ts + np1, np1);
        *resume = 1;
        return PSB_SUCCESS;
    }
    j = psb__explore_add_node(x, kind, y, precision, -1); /* in the slot: no growth */
    if ((nb % 2 != 0 || br.unbalanced) && r != PSB_BRANCH_CAPACITY) d->n_odd++;
    nd->n_branches = nb;
    nd->branch_edge[0] = e;
    for (k = 1; k < nb; k++) nd->branch_edge[k] = -1;
    ed->end = PSB_EDGE_NODE;
    ed->to = j;
    ed->to_branch = 0;
    return r == PSB_BRANCH_CAPACITY ? r : PSB_SUCCESS;
}

/* Whether a trace at the edge's origin with tangent t comes back along the branch it left by
   (a turn back: after a fault, say), not round a loop into another of the origin's branches. */
static int psb__explore_turned_back(const psb__explorer *x, const double *t)
{
    double best_cos;
    return psb__explore_arrival_branch(x, x->d->nodes + x->from, t, &best_cos) == x->from_branch;
}

/* A kink or branching point (y, t) at the edge's origin node: the edge's own start, which it
   leaves (0), or, once the edge has been away (a loop back into its origin through the point,
   not along the branch it left by), an arrival there that stops the trace (1). Else -1. An
   arrival must lie within the origin's tolerance itself: a point located only roughly (its
   precision 0.02 after a fault, 0.02 from the start) is near enough to be the start, not to be
   come back to. */
static int psb__explore_at_origin(psb__explorer *x, const double *y, const double *t, double precision)
{
    int np1 = x->s->internal_.np1;
    const psb_node *nf = x->d->nodes + x->from;
    if (!psb__explore_near(x, nf, y, precision)) return -1;
    if (!x->away || psb__explore_turned_back(x, t) || !psb__explore_near(x, nf, y, 0)) return 0;
    psb__copy(PSB__XVEC(x, PSB__X_SY), y, np1);
    psb__copy(PSB__XVEC(x, PSB__X_ST), t, np1);
    x->stop_node = x->from;
    x->stop = PSB__XS_NODE;
    return 1;
}

/* A special point reported by a trace: folds and events become nodes on the edge; a branch
   or PC1 point (other than the one the edge leaves) stops the trace for the branching. */
static int psb__explore_special(psb__explorer *x, const psb_special *sp)
{
    int np1 = x->s->internal_.np1, j;
    if (sp->kind == PSB_SPECIAL_BRANCH || sp->kind == PSB_SPECIAL_PC1) {
        int at = psb__explore_at_origin(x, sp->y, sp->t, sp->precision);
        if (at >= 0) return at;
        psb__copy(PSB__XVEC(x, PSB__X_SY), sp->y, np1);
        psb__copy(PSB__XVEC(x, PSB__X_ST), sp->t, np1);
        x->has_kernel = sp->kernel != NULL;
        x->located = sp->located;
        if (sp->kernel) psb__copy(PSB__XVEC(x, PSB__X_K), sp->kernel, np1);
        x->stop_kind = sp->kind == PSB_SPECIAL_BRANCH ? PSB_NODE_BRANCH : PSB_NODE_PC1;
        x->stop_precision = sp->precision;
        x->stop = PSB__XS_SPECIAL;
        return 1;
    }
    if (x->draft) return 0; /* the replay adds the node */
    j = psb__explore_add_node(x, sp->kind == PSB_SPECIAL_EVENT ? PSB_NODE_EVENT : PSB_NODE_FOLD,
                              sp->y, sp->precision, x->edge);
    if (j >= 0 && sp->kind == PSB_SPECIAL_EVENT) {
        x->d->nodes[j].event = sp->event;
        x->d->nodes[j].direction = sp->direction;
    }
    return 0;
}

/* The branching node, or the edge's own origin once the edge has been away from it (x->away;
   a loop, whatever the origin's kind, not a turn back), that the chord from prev to the
   accepted point passes within tolerance of, or -1: a trace going straight through a known
   point (a piecewise-linear branch meets no kink there, and the detectors may see nothing)
   arrives at it. The chord stands for the curve to within 1e-3 of its length. */
static int psb__explore_chord_near(const psb__explorer *x, const double *prev, const psb_point *pt, int j)
{
    const psb_solver *s = x->s;
    const psb_node *nd = x->d->nodes + j;
    int np1 = s->internal_.np1, i;
    double seg2 = pt->h * pt->h, proj = 0, dist2 = 0, a, tol;
    for (i = 0; i < np1; i++) proj += s->internal_.w[i] * (pt->y[i] - prev[i]) * (nd->y[i] - prev[i]);
    a = seg2 > 0 ? proj / seg2 : 0;
    a = a < 0 ? 0 : (a > 1 ? 1 : a);
    for (i = 0; i < np1; i++) {
        double di = prev[i] + a * (pt->y[i] - prev[i]) - nd->y[i];
        dist2 += s->internal_.w[i] * di * di;
    }
    tol = psb__explore_tol(x, nd) + 4 * nd->precision + 1e-3 * pt->h;
    return dist2 <= tol * tol;
}

static int psb__explore_passed(const psb__explorer *x, const double *prev, const psb_point *pt)
{
    int first, last, i, found = -1;
    if (x->away && !psb__explore_turned_back(x, pt->t) && psb__explore_chord_near(x, prev, pt, x->from))
        found = x->from;
    psb__index_range(x, prev, pt->y, 1e-3 * pt->h, &first, &last);
    for (i = first; i < last; i++) {
        int j = x->d->index_node_[i];
        if (j != x->from && (found < 0 || j < found) && psb__explore_chord_near(x, prev, pt, j)) found = j;
    }
    return found;
}

/* The points the explorer has used: the diagram's, and a draft's own (the diagram counts them
   at the replay). */
static long psb__explore_points_used(const psb__explorer *x)
{
    return x->d->n_points + (x->draft ? x->points : 0);
}

/* The explorer's answer to a trace's point: 1 stops the trace (x->stop says why). A draft
   (x->draft) decides on the diagram as its round found it and changes nothing of it: the
   replay adds the nodes and points and calls on_point. */
static int psb__explore_decide(const psb_point *pt, psb__explorer *x)
{
    psb_solver *s = x->s;
    const psb_explore_options *eo = x->eo;
    int np1 = s->internal_.np1, i;
    if (pt->flags & PSB_POINT_KINK) {
        int at = psb__explore_at_origin(x, pt->y, pt->t, 0);
        if (at >= 0) return at;
        psb__copy(PSB__XVEC(x, PSB__X_SY), pt->y, np1);
        psb__copy(PSB__XVEC(x, PSB__X_ST), pt->t, np1);
        x->stop = PSB__XS_KINK;
        return 1;
    }
    if (pt->flags & PSB_POINT_SPECIAL) return psb__explore_special(x, pt->special);
    if (eo->max_points && psb__explore_points_used(x) >= eo->max_points) { /* spent: not counted */
        x->stop = PSB__XS_POINTS;
        return 1;
    }
    if (!x->draft) x->d->n_points++;
    x->points++;
    x->length += pt->h;
    if (x->d->store_points_ && !x->draft) {
        psb_diagram *d = x->d;
        if (psb__diagram_point_room(d)) {
            psb__copy(d->points + (size_t)d->n_stored_points * (size_t)np1, pt->y, np1);
            d->n_stored_points++;
            d->edges[x->edge].n_stored++;
        } else {
            d->truncated = 1;
        }
    }
    if (pt->index > 0) {
        int j = psb__explore_passed(x, PSB__XVEC(x, PSB__X_PREV), pt);
        if (j >= 0) {
            psb__copy(PSB__XVEC(x, PSB__X_SY), pt->y, np1);
            psb__copy(PSB__XVEC(x, PSB__X_ST), pt->t, np1);
            x->stop_node = j;
            x->stop = PSB__XS_NODE;
            return 1;
        }
    }
    /* away once past a kink, too: a loop of pieces can stay within away_r of its origin */
    if (!x->away && ((pt->flags & PSB_POINT_SWITCH) ||
                     psb__dist_w(s, pt->y, x->d->nodes[x->from].y) > x->away_r))
        x->away = 1;
    psb__copy(PSB__XVEC(x, PSB__X_PREV), pt->y, np1);
    if (eo->on_point && !x->draft && eo->on_point(x->edge, pt, eo->point_user)) {
        x->stop = PSB__XS_USER;
        return 1;
    }
    for (i = 0; eo->box_min && i < np1; i++)
        if (pt->y[i] < eo->box_min[i] || pt->y[i] > eo->box_max[i]) {
            x->stop = PSB__XS_BOX;
            return 1;
        }
    if (eo->state_max > 0) {
        double sum = 0;
        for (i = 0; i < np1; i++)
            if (i != s->prob.param_index) sum += s->internal_.w[i] * pt->y[i] * pt->y[i];
        if (sqrt(sum) > eo->state_max) {
            x->stop = PSB__XS_BOX;
            return 1;
        }
    }
    if (eo->max_points && psb__explore_points_used(x) >= eo->max_points) {
        x->stop = PSB__XS_POINTS;
        return 1;
    }
    return 0;
}

static int psb__draft_keep(psb__explorer *x, const psb_point *pt, int answer);

static int psb__explore_point(const psb_point *pt, void *user)
{
    psb__explorer *x = (psb__explorer *)user;
    int answer = psb__explore_decide(pt, x);
    return x->draft ? psb__draft_keep(x, pt, answer) : answer;
}

/* The edge resumes past an ordinary kink at (y, t), up to a branching radius beyond the kink
   couple in X_PREV: the edge is away from its origin now, and where that jump passes a known
   node (the origin itself, closing a loop, or a branching node) the edge arrives there, as a
   traced chord would (psb__explore_passed). Returns 1 with x->stop set to arrive, else 0. */
static int psb__explore_jumped(psb__explorer *x, const double *y, const double *t)
{
    psb_point jump;
    int j;
    x->away = 1;
    memset(&jump, 0, sizeof jump);
    jump.y = y;
    jump.t = t;
    jump.h = psb__dist_w(x->s, PSB__XVEC(x, PSB__X_PREV), y);
    j = psb__explore_passed(x, PSB__XVEC(x, PSB__X_PREV), &jump);
    if (j < 0) return 0;
    x->d->edges[x->edge].length += jump.h;
    x->stop_node = j;
    x->stop = PSB__XS_NODE;
    return 1;
}

/* An edge's start from branch k of node `from` on x (the explorer, or a draft's copy): its
   couple into y, t, the first trace's options (*to), its length from the node, and x's state for
   the edge. Returns 1 where the couple lies beyond a bound (no trace: the edge ends on it). */
static int psb__explore_edge_start(psb__explorer *x, int from, int k, double *y, double *t,
                                   psb_trace_options *to, double *length)
{
    const psb_node *nf = x->d->nodes + from;
    int np1 = x->s->internal_.np1;
    psb__copy(y, nf->ys + (size_t)k * (size_t)np1, np1);
    psb__copy(t, nf->ts + (size_t)k * (size_t)np1, np1);
    /* the branching landed beyond a bound (the node lies within a branching radius of it) */
    if (psb__explore_beyond_bound(x, y)) return 1;
    *length = psb__dist_w(x->s, nf->y, y);
    *to = x->eo->trace;
    to->on_point = psb__explore_point;
    to->point_user = x;
    to->detect_loop = 1;
    to->locate_kinks = x->eo->branch_at_kinks || x->eo->kink_nodes;
    to->stop_at = 0; /* psb__explore_special stops where a branching is due */
    /* max_steps bounds the edge, also across the ordinary kinks it resumes at (a closed curve
       of such arcs never closes within one trace: its detect_loop starts at each kink) */
    to->max_steps = to->max_steps > 0 ? to->max_steps : 10000;
    x->detect = to->detect;
    x->from = from;
    x->from_branch = k;
    /* away: twice the start's distance from the origin, at least its tolerance beyond */
    x->away = 0;
    x->away_r = 2 * *length + psb__explore_tol(x, nf) + 4 * nf->precision;
    return 0;
}

/* ---- Drafts: the edges' first traces on the workers (psb_explore_options.drafts) -------------
   The queue's next untraced branches, in order, are traced at once on the workers, each on the
   diagram as the round found it (psb__explore_decide, which changes nothing then), keeping every
   point the explorer's callback saw with its answer. At the branch's turn its edge replays them
   through the callback on the diagram as it is by then. The answers are the draft's, except
   where the diagram now stops the trace sooner (a node an edge of the round added, the point
   budget, on_point): psb_trace would have stopped there, with that point's couple and steps.
   Nodes added later come after the round's, so a node the draft arrived at is the one the
   diagram finds. Only a turn back depends on what can change otherwise (the origin's branches):
   where they changed, or the draft overflowed its slot, the edge is traced in turn. What follows
   the first trace (branchings, traces resumed past a kink) runs in turn on the calling solver.
   So the diagram is psb_explore's with drafts off, for any number of workers; the counters add
   the drafts' work, used or not (they depend on drafts, never on n_workers). */

typedef struct psb__draft {
    int from, k;          /* the branch (from < 0: the slot is free) */
    int from_branches;    /* node from's n_branches when drafted */
    int overflow;         /* more points than the slot keeps: the edge is traced in turn */
    psb_result r;         /* psb_trace's */
    long steps, kept;     /* its rep.steps; the entries kept */
    psb_stats stats;      /* what it spent on its worker */
    long faults[4], n_ok;
    char message[200];    /* a failure's */
} psb__draft;

/* A point the draft's callback saw, followed by its y and t (a special point's kernel takes the
   next entry's y). special: the psb_special_kind + 1 (0: none). */
typedef struct psb__draft_point {
    int answer, flags, special, event, direction, located, has_kernel;
    long index;
    double h, fold_param, param, precision;
} psb__draft_point;

typedef struct psb__drafts {
    int run_kind;         /* PSB__RUN_DRAFTS */
    psb__explorer *x;     /* the explorer: read only while drafts run */
    const psb_workers *wk;
    char *mem;            /* n_slots slots of stride bytes: a psb__draft, its couple, its */
    size_t stride, entry, out_bytes; /* entries (entry bytes each; out_bytes up to here), scratch */
    int n_slots;
    long max_kept;        /* entries of a slot */
    int n_todo, todo[PSB_MAX_WORKERS]; /* the run's slots */
} psb__drafts;

#define PSB__DEFAULT_DRAFTS 8
#define PSB__DEFAULT_DRAFT_POINTS 128
#define PSB__MAX_DRAFT_POINTS 10000000L

/* eo's drafts (0: none) and the points a draft keeps, resolved. */
static void psb__drafts_resolve(const psb_explore_options *eo, int *drafts, long *points)
{
    *drafts = !eo || eo->drafts == 0 ? PSB__DEFAULT_DRAFTS : eo->drafts < 0 ? 0 : eo->drafts;
    *points = !eo || eo->draft_points == 0 ? PSB__DEFAULT_DRAFT_POINTS : eo->draft_points;
}

/* The bytes of a slot's output (its psb__draft, couple and entries; *entry each), and in
   *stride the slot's, with the draft's scratch and event values; 0 where they would overflow. */
static size_t psb__draft_layout(int n, long points, int n_events, size_t *stride, size_t *entry)
{
    size_t np1 = (size_t)n + 1, e, out;
    if (((points + 1.0) * ((double)sizeof(psb__draft_point) + 2.0 * (n + 1.0) * sizeof(double)) + sizeof(psb__draft) +
         (PSB__NX * (n + 1.0) + 3.0 * n_events) * sizeof(double) + 64) > (double)((size_t)-1 / 4))
        return 0;
    e = psb__align(sizeof(psb__draft_point)) + 2 * np1 * sizeof(double);
    out = psb__align(sizeof(psb__draft)) + 2 * np1 * sizeof(double) + (size_t)points * e;
    if (entry) *entry = e;
    if (stride) *stride = psb__align(out + ((size_t)PSB__NX * np1 + 3 * (size_t)n_events) * sizeof(double));
    return out;
}

PSCBRANCH_DEF size_t psb_explore_workers_memory_size(int n, int n_dir, const psb_explore_options *eo)
{
    size_t sweep = psb_workers_memory_size(n, n_dir), stride;
    int drafts, n_events = eo ? eo->trace.n_events : 0;
    long points;
    psb__drafts_resolve(eo, &drafts, &points);
    if (!sweep || (eo && eo->drafts < -1) || drafts > PSB_MAX_WORKERS || points < 1 || points > PSB__MAX_DRAFT_POINTS ||
        n_events < 0)
        return 0;
    if (!drafts) return sweep;
    if (!psb__draft_layout(n, points, n_events, &stride, NULL) || (double)drafts * stride > (double)((size_t)-1 / 4))
        return 0;
    return psb__align(sweep) + (size_t)drafts * stride; /* drafts outlive a sweep */
}

static psb__draft *psb__draft_slot(const psb__drafts *q, int j)
{
    return (psb__draft *)(void *)(q->mem + (size_t)j * q->stride);
}

/* The draft's couple (2 vectors), its entry i, an entry's vector v (0: y, 1: t), its scratch. */
static double *psb__draft_couple(psb__draft *dr)
{
    return (double *)(void *)((char *)dr + psb__align(sizeof(psb__draft)));
}

static psb__draft_point *psb__draft_entry(const psb__drafts *q, psb__draft *dr, long i)
{
    size_t np1 = (size_t)q->x->s->internal_.np1;
    return (psb__draft_point *)(void *)((char *)(psb__draft_couple(dr) + 2 * np1) + (size_t)i * q->entry);
}

static double *psb__draft_point_vec(const psb__drafts *q, psb__draft_point *e, int v)
{
    return (double *)(void *)((char *)e + psb__align(sizeof(psb__draft_point))) +
           (size_t)v * (size_t)q->x->s->internal_.np1;
}

static double *psb__draft_scratch(const psb__drafts *q, psb__draft *dr)
{
    return (double *)(void *)((char *)dr + q->out_bytes);
}

/* A draft's callback: keeps the point and the answer. A point past the slot stops the draft
   (an overflow: its edge is traced in turn). */
static int psb__draft_keep(psb__explorer *x, const psb_point *pt, int answer)
{
    const psb__drafts *q = x->drafts;
    psb__draft *dr = x->draft;
    const psb_special *sp = pt->special;
    int np1 = x->s->internal_.np1, kernel = sp && sp->kernel;
    psb__draft_point *e;
    if (dr->kept + 1 + kernel > q->max_kept) {
        dr->overflow = 1;
        return 1;
    }
    e = psb__draft_entry(q, dr, dr->kept);
    memset(e, 0, sizeof *e);
    e->answer = answer;
    e->flags = pt->flags;
    e->index = pt->index;
    e->h = pt->h;
    e->fold_param = pt->fold_param;
    psb__copy(psb__draft_point_vec(q, e, 0), pt->y, np1);
    psb__copy(psb__draft_point_vec(q, e, 1), pt->t, np1);
    if (sp) { /* psb_trace reports a special point at its own couple (sp->y, sp->t are pt's) */
        e->special = (int)sp->kind + 1;
        e->event = sp->event;
        e->direction = sp->direction;
        e->located = sp->located;
        e->param = sp->param;
        e->precision = sp->precision;
        e->has_kernel = kernel;
        if (kernel) psb__copy(psb__draft_point_vec(q, psb__draft_entry(q, dr, dr->kept + 1), 0), sp->kernel, np1);
    }
    dr->kept += 1 + kernel;
    return answer;
}

/* Draft q->todo[task] on worker w: its edge's first trace (psb__explore_edge_start, psb_trace). */
static void psb__draft_task(void *arg, int task, int w)
{
    psb__drafts *q = (psb__drafts *)arg;
    psb_solver *ws = q->wk->solver[w];
    psb__draft *dr = psb__draft_slot(q, q->todo[task]);
    psb__explorer x = *q->x;
    psb_trace_options to;
    psb_trace_report rep;
    int np1 = ws->internal_.np1;
    double *y = psb__draft_couple(dr), *t = y + np1, length;
    x.s = ws;
    x.work = psb__draft_scratch(q, dr);
    x.draft = dr;
    x.drafts = q;
    psb__copy(PSB__XVEC(&x, PSB__X_V), PSB__XVEC(q->x, PSB__X_V), np1); /* the index's direction */
    psb__worker_begin(ws, &dr->stats, dr->faults, &dr->n_ok);
    /* a couple beyond a bound is no trace: its edge ends on the bound (psb__explore_edge_trace) */
    if (!psb__explore_edge_start(&x, dr->from, dr->k, y, t, &to, &length)) {
        x.stop = PSB__XS_NONE;
        x.points = 0;
        x.length = 0;
        if (to.n_events > 0) to.event_work = x.work + (size_t)PSB__NX * (size_t)np1;
        dr->r = psb_trace(ws, y, t, &to, &rep);
        dr->steps = rep.steps;
        if (dr->r < 0) memcpy(dr->message, ws->message, sizeof dr->message);
    }
    psb__worker_end(ws, &dr->stats, dr->faults, &dr->n_ok);
}

static void psb__drafts_output(const void *arg, int task, int *group, void **out, size_t *bytes)
{
    const psb__drafts *q = (const psb__drafts *)arg;
    *group = task;
    *out = psb__draft_slot(q, q->todo[task]);
    *bytes = q->out_bytes;
}

/* The slot drafted for branch k of node `from`, or NULL. */
static psb__draft *psb__draft_find(const psb__drafts *q, int from, int k)
{
    int j;
    for (j = 0; j < q->n_slots; j++) {
        psb__draft *dr = psb__draft_slot(q, j);
        if (dr->from == from && dr->k == k) return dr;
    }
    return NULL;
}

/* Frees a slot, what its draft spent added to the calling solver's. */
static void psb__draft_free(psb_solver *s, psb__draft *dr)
{
    if (dr->from < 0) return;
    psb__worker_merge(s, &dr->stats, dr->faults, &dr->n_ok);
    dr->from = -1;
}

/* A round: drafts the queue's untraced branches from branch kb of node `from` on, in order, as
   many as there are slots and at most `budget` (< 0: no bound), keeping the drafts of the same
   branches made before. Returns PSB_SUCCESS, or PSB_ERR_CALLBACK (run failed). */
static psb_result psb__drafts_round(psb__drafts *q, int from, int kb, int budget)
{
    psb__explorer *x = q->x;
    psb_diagram *d = x->d;
    int want[2 * PSB_MAX_WORKERS], n_want = 0, i, j, k, m, limit = budget < 0 || budget > q->n_slots ? q->n_slots : budget;
    for (i = from; i < d->n_nodes && n_want < limit; i++)
        for (k = i == from ? kb : 0; k < d->nodes[i].n_branches && n_want < limit; k++)
            if (d->nodes[i].branch_edge[k] < 0) {
                want[2 * n_want] = i;
                want[2 * n_want++ + 1] = k;
            }
    for (j = 0; j < q->n_slots; j++) { /* drafts of branches no longer wanted */
        psb__draft *dr = psb__draft_slot(q, j);
        int keep = 0;
        for (m = 0; m < n_want && !keep; m++) keep = dr->from == want[2 * m] && dr->k == want[2 * m + 1];
        if (!keep) psb__draft_free(x->s, dr);
    }
    q->n_todo = 0;
    for (m = 0; m < n_want; m++) {
        psb__draft *dr;
        if (psb__draft_find(q, want[2 * m], want[2 * m + 1])) continue;
        for (j = 0; psb__draft_slot(q, j)->from >= 0; j++) {}
        dr = psb__draft_slot(q, j);
        memset(dr, 0, sizeof *dr);
        dr->from = want[2 * m];
        dr->k = want[2 * m + 1];
        dr->from_branches = d->nodes[dr->from].n_branches;
        q->todo[q->n_todo++] = j;
    }
    if (!q->n_todo) return PSB_SUCCESS;
    d->n_drafts += q->n_todo;
    psb__workers_sync(x->s, q->wk);
    if (q->wk->run(q->wk->ctx, q->n_todo, psb__draft_task, q) != 0) {
        for (m = 0; m < q->n_todo; m++) psb__draft_free(x->s, psb__draft_slot(q, q->todo[m]));
        return psb__fail(x->s, PSB_ERR_CALLBACK, "workers: run failed");
    }
    return PSB_SUCCESS;
}

/* The first trace of the edge being traced from draft dr: its points replayed through the
   explorer's callback, psb_trace's result as the trace on the calling solver would have had it
   (y, t, *steps). */
static psb_result psb__explore_replay(psb__explorer *x, psb__draft *dr, double *y, double *t, long *steps)
{
    const psb__drafts *q = x->drafts;
    psb_solver *s = x->s;
    int np1 = s->internal_.np1, outer = s->internal_.in_trace_callback;
    long i;
    const double *end = psb__draft_couple(dr), *end_t = end + np1;
    s->internal_.in_trace_callback = 1;
    for (i = 0; i < dr->kept; i++) {
        psb__draft_point *e = psb__draft_entry(q, dr, i);
        psb_point pt;
        psb_special sp;
        memset(&pt, 0, sizeof pt);
        pt.y = psb__draft_point_vec(q, e, 0);
        pt.t = psb__draft_point_vec(q, e, 1);
        pt.h = e->h;
        pt.index = e->index;
        pt.flags = e->flags;
        pt.fold_param = e->fold_param;
        if (e->special) {
            memset(&sp, 0, sizeof sp);
            sp.kind = (psb_special_kind)(e->special - 1);
            sp.y = pt.y;
            sp.t = pt.t;
            sp.kernel = e->has_kernel ? psb__draft_point_vec(q, psb__draft_entry(q, dr, ++i), 0) : NULL;
            sp.param = e->param;
            sp.precision = e->precision;
            sp.event = e->event;
            sp.direction = e->direction;
            sp.located = e->located;
            pt.special = &sp;
        }
        if (psb__explore_point(&pt, x) && !e->answer) { /* stopped here now, as psb_trace would */
            s->internal_.in_trace_callback = outer;
            psb__copy(y, pt.y, np1);
            psb__copy(t, pt.t, np1);
            *steps = pt.index;
            return PSB_STOPPED;
        }
    }
    s->internal_.in_trace_callback = outer;
    psb__copy(y, end, np1);
    psb__copy(t, end_t, np1);
    *steps = dr->steps;
    if (dr->r < 0) memcpy(s->message, dr->message, sizeof s->message);
    return dr->r;
}

/* Traces branch k of node `from` as a new edge, to its end (psb__explore_edge); its first trace
   from draft dr where that holds (NULL: none). */
static psb_result psb__explore_edge_trace(psb__explorer *x, int from, int k, psb__draft *dr)
{
    psb_solver *s = x->s;
    psb_diagram *d = x->d;
    psb_trace_options to;
    psb_trace_report rep;
    int np1 = s->internal_.np1, e, resume;
    long steps_left, steps;
    double *y = PSB__XVEC(x, PSB__X_Y), *t = PSB__XVEC(x, PSB__X_T);
    psb_result r;
    /* d may grow (psb_diagram_set_growth) wherever a node, a branch or a point is added: nodes
       and edges are reached by index (ND, ED) after every call that can add one */
#define ND(j) (d->nodes + (j))
#define ED (d->edges + e)
    if (d->n_edges == d->max_edges && !psb__diagram_grow(d, d->max_nodes, psb__twice(d->max_edges), d->max_branches)) {
        d->truncated = 1;
        return PSB_BRANCH_CAPACITY;
    }
    e = d->n_edges++;
    memset(ED, 0, sizeof *ED);
    ED->from = from;
    ED->from_branch = k;
    ED->to = ED->to_branch = -1;
    ED->first_point = d->n_stored_points;
    ND(from)->branch_edge[k] = e;
    if (psb__explore_edge_start(x, from, k, y, t, &to, &ED->length))
        return psb__explore_end_on_bound(x, e, ND(from)->y, y);
    x->edge = e;
    steps_left = to.max_steps;
    if (dr && (dr->overflow || dr->from_branches != ND(from)->n_branches)) dr = NULL;
    if (dr) d->n_drafts_used++;
    for (;;) {
        x->stop = PSB__XS_NONE;
        x->points = 0;
        x->length = 0;
        if (steps_left <= 0) {
            r = ED->result = PSB_STEP_BUDGET;
            break;
        }
        to.max_steps = steps_left;
        if (dr) {
            r = psb__explore_replay(x, dr, y, t, &steps);
            dr = NULL;
        } else {
            r = psb_trace(s, y, t, &to, &rep);
            steps = rep.steps;
        }
        steps_left -= steps;
        ED->n_points += x->points;
        ED->length += x->length;
        ED->result = r;
        if (x->stop == PSB__XS_KINK || x->stop == PSB__XS_SPECIAL) {
            /* the stop couple lies beyond the last accepted point */
            ED->length += psb__dist_w(s, PSB__XVEC(x, PSB__X_PREV), PSB__XVEC(x, PSB__X_SY));
            psb__copy(y, PSB__XVEC(x, PSB__X_SY), np1);
            psb__copy(t, PSB__XVEC(x, PSB__X_ST), np1);
            psb__copy(PSB__XVEC(x, PSB__X_PREV), y, np1);
            r = psb__explore_branching(x, e, y, t, x->stop == PSB__XS_KINK, &resume);
            if (resume && psb__explore_jumped(x, y, t)) break;
            if (resume) continue;
            return r;
        }
        if (x->stop == PSB__XS_NONE && r == PSB_NONSMOOTH_END) {
            x->stop_kind = PSB_NODE_NONSMOOTH;
            x->stop_precision = 0;
            x->plain_ok = steps > 0; /* a trace that made no step does not resume */
            psb__copy(PSB__XVEC(x, PSB__X_PREV), y, np1);
            r = psb__explore_branching(x, e, y, t, 0, &resume);
            if (resume && psb__explore_jumped(x, y, t)) break;
            if (resume) continue;
            return r;
        }
        break;
    }
    switch (x->stop) {
    case PSB__XS_NODE: {
        /* through a known node: arrive, and make sure the way on is one of its branches */
        psb_node *nd;
        int kb, best = -1;
        double best_cos = -2;
        if (x->stop_node == from && !psb__is_junction(ND(from)->kind)) {
            /* back through its start (the resumes kept psb_trace's detect_loop from seeing it) */
            r = PSB_LOOP_CLOSED;
            break;
        }
        /* the trace went past the node by about this much (never below 0: an edge that passed
           its node within its first step) */
        ED->length = fmax(0, ED->length - psb__dist_w(s, y, ND(x->stop_node)->y));
        psb__explore_arrive(x, e, x->stop_node, t);
        nd = ND(x->stop_node);
        /* by its tangent or by its chord from the node, whichever matches better: the tangent
           alone misses on a curved branch (the node's couples lie elsewhere on it), and with
           differences it is off near the node, where the quotients mix the pieces (a single
           failed residual call made a trace turn back at a node there and add the branch
           it came by as a new one) */
        for (kb = 0; kb < nd->n_branches; kb++) {
            double c = psb__cos_w(s, t, nd->ts + (size_t)kb * (size_t)np1);
            double c_chord = psb__explore_chord_cos(x, nd, kb, y);
            if (c_chord > c) c = c_chord;
            if (c > best_cos) { best_cos = c; best = kb; }
        }
        /* only from a point past the node: a tangent at the node itself (a trace landing on a
           PC1 point) is some piece's and need not point along any branch */
        if ((best < 0 || (best_cos < s->opt.c_diff && best_cos < s->opt.c_min)) &&
            psb__dist_w(s, y, nd->y) > psb__explore_tol(x, nd) + 4 * nd->precision) {
            if (nd->n_branches == d->max_branches &&
                psb__diagram_grow(d, d->max_nodes, d->max_edges, psb__twice(d->max_branches)))
                nd = ND(x->stop_node);
            if (nd->n_branches == d->max_branches) {
                d->truncated = 1;
            } else {
                kb = nd->n_branches++;
                psb__copy(nd->ys + (size_t)kb * (size_t)np1, y, np1);
                psb__copy(nd->ts + (size_t)kb * (size_t)np1, t, np1);
                nd->branch_edge[kb] = -1;
                if (x->stop_node < x->queue_from) x->queue_from = x->stop_node;
            }
        }
        return PSB_SUCCESS;
    }
    case PSB__XS_USER: psb__explore_end(x, e, PSB_EDGE_BUDGET, PSB_NODE_BUDGET, y); return PSB_STOPPED;
    case PSB__XS_POINTS: psb__explore_end(x, e, PSB_EDGE_BUDGET, PSB_NODE_BUDGET, y); return PSB_STEP_BUDGET;
    case PSB__XS_BOX: psb__explore_end(x, e, PSB_EDGE_BOX, PSB_NODE_BOUND, y); return PSB_SUCCESS;
    default: break;
    }
    switch (r) {
    case PSB_PARAM_BOUND: psb__explore_end(x, e, PSB_EDGE_BOUND, PSB_NODE_BOUND, y); break;
    case PSB_STEP_BUDGET: psb__explore_end(x, e, PSB_EDGE_BUDGET, PSB_NODE_BUDGET, y); break;
    case PSB_LOOP_CLOSED:
        ED->length += psb__dist_w(s, y, ND(from)->y);
        psb__explore_arrive(x, e, from, t);
        ED->end = PSB_EDGE_LOOP;
        break;
    default:
        psb__explore_end(x, e, PSB_EDGE_FAILURE, PSB_NODE_FAILURE, y);
        if (psb__is_fatal(r)) return r;
    }
    return PSB_SUCCESS;
#undef ND
#undef ED
}

/* Checks the explorer's options; a message or NULL. */
static const char *psb__check_explore(const psb_solver *s, const psb_explore_options *eo)
{
    int i, np1 = s->internal_.np1;
    if (eo->trace.param_min != eo->trace.param_min || eo->trace.param_max != eo->trace.param_max)
        return "the parameter bounds are NaN";
    if (!(eo->node_tol >= 0) || !psb__finite(eo->node_tol)) return "node_tol must be finite and >= 0";
    if (eo->kink_spans < 0 || eo->kink_spans > PSB_MAX_SPAN_LIMIT) return "kink_spans must lie in [0, PSB_MAX_SPAN_LIMIT]";
    if (eo->kink_nodes < 0 || eo->kink_nodes > 1) return "kink_nodes must be 0 or 1";
    /* psb_trace's own checks, made once here rather than failing every edge */
    if (eo->trace.detect < 0 || eo->trace.detect > PSB_DETECT_ALL) return "trace.detect must be a PSB_DETECT_* mask";
    if ((eo->trace.detect & PSB_DETECT_PC1) && s->prob.linear == PSB_LINEAR_USER)
        return "trace.detect: PSB_DETECT_PC1 needs the dense or banded backend";
    if (!(eo->trace.locate_tol >= 0) || !psb__finite(eo->trace.locate_tol)) return "trace.locate_tol must be finite and >= 0";
    if (eo->trace.n_events < 0) return "trace.n_events must be >= 0";
    if (eo->trace.n_events > 0 && (!eo->trace.event || !eo->trace.event_work))
        return "trace.event and trace.event_work are needed with n_events > 0";
    if (!(eo->state_max >= 0)) return "state_max must be >= 0";
    if (eo->max_traces < 0 || eo->max_points < 0 || eo->trace.max_steps < 0)
        return "budgets must be >= 0";
    if (eo->drafts < -1 || eo->drafts > PSB_MAX_WORKERS) return "drafts must lie in [-1, PSB_MAX_WORKERS]";
    if (eo->draft_points < 0 || eo->draft_points > PSB__MAX_DRAFT_POINTS) return "draft_points must lie in [0, 10^7]";
    if (!eo->box_min != !eo->box_max) return "give both box_min and box_max, or neither";
    for (i = 0; eo->box_min && i < np1; i++)
        if (!(eo->box_min[i] <= eo->box_max[i])) return "need box_min <= box_max (no NaN)";
    return NULL;
}

/* Traces branch k of node `from` as a new edge, to its end. Returns PSB_SUCCESS (the edge
   ended, however), PSB_BRANCH_CAPACITY (edges or nodes ran out), PSB_STEP_BUDGET (the point
   budget), PSB_STOPPED, or a fatal failure.
   A fold the edge met within tolerance of the branching node it leaves or ends at is that
   node, not a fold of the edge, and is dropped: with difference quotients the tangent's
   parameter component can change sign within a step of a nonsmooth point, where the pieces
   mix (an analytic dH reports none there), and a turn at the node itself is the node's. */
static psb_result psb__explore_edge(psb__explorer *x, int from, int k, psb__draft *dr)
{
    psb_diagram *d = x->d;
    int first = d->n_nodes, e = d->n_edges, j, i, at_from = psb__is_branching_node(d->nodes[from].kind);
    psb_result r = psb__explore_edge_trace(x, from, k, dr);
    if (d->n_edges == e) return r; /* no edge: capacity */
    for (j = d->n_nodes - 1; j >= first; j--) {
        psb_node *nd = d->nodes + j, moved;
        const psb_edge *ed = d->edges + e;
        int at_to = ed->to >= 0 && ed->to != j && psb__is_branching_node(d->nodes[ed->to].kind);
        if (nd->kind != PSB_NODE_FOLD || nd->edge != e) continue;
        if (!(at_from && psb__explore_near(x, d->nodes + from, nd->y, nd->precision)) &&
            !(at_to && psb__explore_near(x, d->nodes + ed->to, nd->y, nd->precision)))
            continue;
        /* the later nodes move down; the node's storage moves to the free end */
        moved = *nd;
        for (i = j; i < d->n_nodes - 1; i++) d->nodes[i] = d->nodes[i + 1];
        d->nodes[--d->n_nodes] = moved;
        if (d->edges[e].to > j) d->edges[e].to--;
        for (i = 0; i < x->n_index; i++) d->index_node_[i] -= d->index_node_[i] > j;
    }
    return r;
}

PSCBRANCH_DEF psb_result psb_explore(psb_solver *s, const double *y, const double *t,
                                     const psb_explore_options *eo, psb_diagram *d)
{
    psb_explore_options local;
    psb__explorer x;
    psb__drafts q;
    psb_node *start;
    const char *bad;
    int np1, p, i, k, traces = 0, max_traces, drafts;
    long draft_points;
    psb_result r = psb__check_couple(s, y, t), result = PSB_SUCCESS;
    if (r == PSB_SUCCESS) r = psb__trace_busy(s, "psb_explore");
    if (r != PSB_SUCCESS) return r;
    if (!d || !d->nodes || !d->work_) return psb__fail(s, PSB_ERR_NULL, "the diagram is NULL or not set up");
    if (d->n != s->internal_.n) return psb__fail(s, PSB_ERR_SIZE, "the diagram's n differs from the problem's");
    if (!eo) { /* the defaults: every detector the backend has */
        memset(&local, 0, sizeof local);
        local.trace.detect = PSB_DETECT_FOLDS | PSB_DETECT_BRANCH |
                             (s->prob.linear != PSB_LINEAR_USER ? PSB_DETECT_PC1 : 0);
        eo = &local;
    }
    np1 = s->internal_.np1;
    p = s->prob.param_index;
    bad = psb__check_explore(s, eo);
    if (bad) return psb__fail(s, PSB_ERR_OPTIONS, bad);
    r = psb__branch_begin(s, &eo->branch, y);
    if (r != PSB_SUCCESS) return r;
    psb__drafts_resolve(eo, &drafts, &draft_points);
    if (!s->branch.workers) drafts = 0;
    if (drafts) {
        size_t need = psb_explore_workers_memory_size(s->internal_.n, s->branch.n_dir, eo);
        if (!need) return psb__fail(s, PSB_ERR_SIZE, "drafts: drafts x draft_points couples exceed the address space");
        if (s->branch.workers->bytes < need)
            return psb__fail(s, PSB_ERR_NOMEM, "workers: memory is below psb_explore_workers_memory_size(n, n_dir, eo) "
                                               "(drafts -1: none)");
    }
    if (eo->trace.param_min < eo->trace.param_max &&
        (y[p] < eo->trace.param_min || y[p] > eo->trace.param_max))
        return psb__fail(s, PSB_ERR_INPUT, "start point outside the parameter bounds");
    for (i = 0; eo->box_min && i < np1; i++)
        if (y[i] < eo->box_min[i] || y[i] > eo->box_max[i])
            return psb__fail(s, PSB_ERR_INPUT, "start point outside the box");
    {
        /* t must lie along the curve: from a direction across it both starts would trace one arm
           (a start where dH has no unique tangent is taken as given) */
        double *tan = PSB__VEC(s, PSB__V_BR_TT), c;
        r = psb__tangent(s, y, t, tan);
        if (psb__is_fatal(r)) return r;
        c = r == PSB_SUCCESS ? fabs(psb__cos_w(s, t, tan)) : 1;
        if (!(c >= s->opt.c_min)) {
            char buf[120];
            snprintf(buf, sizeof buf, "t is not tangent to the curve at y (cosine %.3g with the tangent, "
                                      "below c_min)", c);
            return psb__fail(s, PSB_ERR_INPUT, buf);
        }
        s->message[0] = 0;
    }
    d->n_nodes = d->n_edges = 0;
    d->n_points = d->n_stored_points = 0;
    d->n_branchings = d->n_kinks_plain = d->n_queued = d->n_failed = d->n_odd = d->truncated = 0;
    d->n_drafts = d->n_drafts_used = 0;
    d->result = PSB_ERR_NO_CONVERGENCE; /* until the call returns */
    d->param_index = p;
    memset(&x, 0, sizeof x);
    x.s = s;
    x.d = d;
    x.eo = eo;
    x.work = d->work_;
    if (drafts) {
        memset(&q, 0, sizeof q);
        q.run_kind = PSB__RUN_DRAFTS;
        q.x = &x;
        q.wk = s->branch.workers;
        q.mem = (char *)q.wk->memory + psb__align(psb_workers_memory_size(s->internal_.n, s->branch.n_dir));
        q.n_slots = drafts;
        q.max_kept = draft_points;
        q.out_bytes = psb__draft_layout(s->internal_.n, draft_points, eo->trace.n_events, &q.stride, &q.entry);
        for (i = 0; i < drafts; i++) psb__draft_slot(&q, i)->from = -1;
        x.drafts = &q;
    }
    x.node_tol = eo->node_tol > 0 ? eo->node_tol : 16 * s->branch.h;
    max_traces = eo->max_traces > 0 ? eo->max_traces : -1;
    psb__index_direction(&x);

    /* the start node: its directions are the first branches of the queue */
    psb__explore_add_node(&x, PSB_NODE_START, y, 0, -1);
    for (k = 0; k < (eo->one_direction ? 1 : 2); k++) {
        double *tk, dir = k ? -t[p] : t[p];
        /* a direction leaving the parameter interval from a start on its bound is left out */
        if (eo->trace.param_min < eo->trace.param_max &&
            ((y[p] == eo->trace.param_min && dir < 0) || (y[p] == eo->trace.param_max && dir > 0)))
            continue;
        if (d->nodes->n_branches == d->max_branches &&
            !psb__diagram_grow(d, d->max_nodes, d->max_edges, psb__twice(d->max_branches))) {
            d->truncated = 1;
            break;
        }
        start = d->nodes;
        tk = start->ts + (size_t)start->n_branches * (size_t)np1;
        psb__copy(start->ys + (size_t)start->n_branches * (size_t)np1, y, np1);
        for (i = 0; i < np1; i++) tk[i] = k ? -t[i] : t[i];
        psb__normalize_w(s, tk);
        start->branch_edge[start->n_branches++] = -1;
    }

    /* the queue: the first untraced branch in the order nodes were made */
    for (;;) {
        int from = -1, kb = -1;
        psb__draft *dr;
        for (i = x.queue_from; i < d->n_nodes && from < 0; i++)
            for (k = 0; k < d->nodes[i].n_branches; k++)
                if (d->nodes[i].branch_edge[k] < 0) {
                    from = i;
                    kb = k;
                    break;
                }
        x.queue_from = from < 0 ? d->n_nodes : from;
        if (from < 0) break;
        if (traces == max_traces) {
            result = PSB_STEP_BUDGET;
            break;
        }
        traces++;
        dr = NULL;
        if (drafts) {
            dr = psb__draft_find(&q, from, kb);
            if (!dr) {
                r = psb__drafts_round(&q, from, kb, max_traces < 0 ? -1 : max_traces - traces + 1);
                if (r != PSB_SUCCESS) {
                    result = r;
                    break;
                }
                dr = psb__draft_find(&q, from, kb);
            }
        }
        r = psb__explore_edge(&x, from, kb, dr);
        if (dr) psb__draft_free(s, dr);
        if (r < 0 || r == PSB_STOPPED || r == PSB_STEP_BUDGET) {
            result = r;
            break;
        }
        if (r == PSB_BRANCH_CAPACITY && d->n_edges == d->max_edges) break;
    }
    for (i = 0; i < drafts; i++) psb__draft_free(s, psb__draft_slot(&q, i));
    for (i = 0; i < d->n_nodes; i++)
        for (k = 0; k < d->nodes[i].n_branches; k++) d->n_queued += d->nodes[i].branch_edge[k] < 0;
    if (result == PSB_SUCCESS && d->truncated) result = PSB_BRANCH_CAPACITY;
    if (result >= 0 && result != PSB_STOPPED && d->n_failed > 0) {
        /* a failed edge may hide branches: the diagram is kept, the call fails with the first
           failed edge's code */
        char buf[160];
        psb_result first = PSB_ERR_NO_CONVERGENCE;
        for (i = 0; i < d->n_edges; i++)
            if (d->edges[i].end == PSB_EDGE_FAILURE) {
                if (d->edges[i].result < 0) first = d->edges[i].result;
                break;
            }
        snprintf(buf, sizeof buf, "psb_explore: %d edge(s) ended in a failure, the first (edge %d) with %s",
                 d->n_failed, i, psb_result_string(first));
        d->result = first;
        return psb__fail(s, first, buf);
    }
    if (result >= 0) s->message[0] = 0;
    d->result = result;
    return result;
}

#ifdef PSCBRANCH_STDIO
/* Whether writing to f failed; flushed first: a write the stream still buffers fails only
   then (a full disk). */
static int psb__write_failed(FILE *f) { return fflush(f) != 0 || ferror(f); }

/* Rewrites in place a finite number printf formatted with %.17g into the C locale's notation:
   under setlocale the decimal point may be a comma or several bytes, which would break JSON's
   numbers and CSV's columns. The number's other characters are digits, signs and 'e'. */
static void psb__c_number(char *num)
{
    char *out = num;
    const char *in = num;
    while (*in) {
        char c = *in;
        if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == 'e' || c == 'E') {
            *out++ = *in++;
        } else { /* the decimal point, whatever its bytes */
            *out++ = '.';
            while (*in && !((*in >= '0' && *in <= '9') || *in == 'e' || *in == 'E')) in++;
        }
    }
    *out = 0;
}

/* x with 17 significant digits in the C locale's notation; JSON has no NaN or Inf (null). */
static void psb__put_double(FILE *f, double x, int json)
{
    char num[64];
    if (!psb__finite(x)) {
        fputs(json ? "null" : x != x ? "nan" : x > 0 ? "inf" : "-inf", f);
        return;
    }
    snprintf(num, sizeof num, "%.17g", x);
    psb__c_number(num);
    fputs(num, f);
}

static void psb__write_vec(FILE *f, const double *v, int np1, const char *sep, int json)
{
    int i;
    for (i = 0; i < np1; i++) {
        if (i) fputs(sep, f);
        psb__put_double(f, v[i], json);
    }
}

PSCBRANCH_DEF psb_result psb_diagram_write_json(const psb_diagram *d, FILE *f)
{
    int i, k, np1;
    if (!d || !f || !d->nodes) return PSB_ERR_NULL;
    np1 = d->n + 1;
    /* complete: psb_explore returned PSB_SUCCESS (no branch left, nothing cut off or stopped,
       no edge failed) */
    fprintf(f, "{\n  \"format\": \"pscbranch-diagram\",\n  \"version\": 1,\n  \"n\": %d,\n"
               "  \"param_index\": %d,\n  \"complete\": %s,\n  \"failed_edges\": %d,\n"
               "  \"untraced_branches\": %d,\n  \"odd_nodes\": %d,\n  \"nodes\": [",
            d->n, d->param_index, d->result == PSB_SUCCESS ? "true" : "false",
            d->n_failed, d->n_queued, d->n_odd);
    for (i = 0; i < d->n_nodes; i++) {
        const psb_node *nd = d->nodes + i;
        fprintf(f, "%s\n    {\"id\": %d, \"kind\": \"%s\", \"param\": ", i ? "," : "", i,
                psb_node_kind_string(nd->kind));
        psb__put_double(f, nd->param, 1);
        fputs(", \"precision\": ", f);
        psb__put_double(f, nd->precision, 1);
        fprintf(f, ", \"edge\": %d, \"event\": %d, \"direction\": %d,\n     \"y\": [", nd->edge, nd->event,
                nd->direction);
        psb__write_vec(f, nd->y, np1, ", ", 1);
        fprintf(f, "],\n     \"branches\": [");
        for (k = 0; k < nd->n_branches; k++) {
            fprintf(f, "%s\n       {\"edge\": %d, \"y\": [", k ? "," : "", nd->branch_edge[k]);
            psb__write_vec(f, nd->ys + (size_t)k * (size_t)np1, np1, ", ", 1);
            fprintf(f, "], \"t\": [");
            psb__write_vec(f, nd->ts + (size_t)k * (size_t)np1, np1, ", ", 1);
            fprintf(f, "]}");
        }
        fprintf(f, "]}");
    }
    fprintf(f, "\n  ],\n  \"edges\": [");
    for (i = 0; i < d->n_edges; i++) {
        const psb_edge *ed = d->edges + i;
        long k;
        fprintf(f, "%s\n    {\"id\": %d, \"from\": %d, \"from_branch\": %d, \"to\": %d, \"to_branch\": %d, "
                   "\"end\": \"%s\", \"result\": %d, \"points\": %ld, \"length\": ",
                i ? "," : "", i, ed->from, ed->from_branch, ed->to, ed->to_branch,
                psb_edge_end_string(ed->end), (int)ed->result, ed->n_points);
        psb__put_double(f, ed->length, 1);
        fputs(", \"path\": [", f);
        for (k = 0; d->points && k < ed->n_stored; k++) {
            fputs(k ? ",\n       [" : "\n       [", f);
            psb__write_vec(f, d->points + (size_t)(ed->first_point + k) * (size_t)np1, np1, ", ", 1);
            fputc(']', f);
        }
        fputs("]}", f);
    }
    fprintf(f, "\n  ]\n}\n");
    return psb__write_failed(f) ? PSB_ERR_INPUT : PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_diagram_write_points_csv(const psb_diagram *d, FILE *f)
{
    int i, np1;
    long k;
    if (!d || !d->nodes || !f) return PSB_ERR_NULL;
    np1 = d->n + 1;
    fprintf(f, "edge,index");
    for (i = 0; i < np1; i++) fprintf(f, ",y%d", i);
    fputc('\n', f);
    for (i = 0; d->points && i < d->n_edges; i++) {
        const psb_edge *ed = d->edges + i;
        for (k = 0; k < ed->n_stored; k++) {
            fprintf(f, "%d,%ld,", i, k);
            psb__write_vec(f, d->points + (size_t)(ed->first_point + k) * (size_t)np1, np1, ",", 0);
            fputc('\n', f);
        }
    }
    return psb__write_failed(f) ? PSB_ERR_INPUT : PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_diagram_write_csv(const psb_diagram *d, FILE *nodes, FILE *edges)
{
    int i, np1;
    if (!d || !d->nodes || (!nodes && !edges)) return PSB_ERR_NULL;
    np1 = d->n + 1;
    if (nodes) {
        fprintf(nodes, "id,kind,param,precision,edge,event,direction,n_branches,n_untraced");
        for (i = 0; i < np1; i++) fprintf(nodes, ",y%d", i);
        fprintf(nodes, "\n");
        for (i = 0; i < d->n_nodes; i++) {
            const psb_node *nd = d->nodes + i;
            int k, untraced = 0;
            for (k = 0; k < nd->n_branches; k++) untraced += nd->branch_edge[k] < 0;
            fprintf(nodes, "%d,%s,", i, psb_node_kind_string(nd->kind));
            psb__put_double(nodes, nd->param, 0);
            fputc(',', nodes);
            psb__put_double(nodes, nd->precision, 0);
            fprintf(nodes, ",%d,%d,%d,%d,%d,", nd->edge, nd->event, nd->direction, nd->n_branches, untraced);
            psb__write_vec(nodes, nd->y, np1, ",", 0);
            fprintf(nodes, "\n");
        }
        if (psb__write_failed(nodes)) return PSB_ERR_INPUT;
    }
    if (edges) {
        fprintf(edges, "id,from,from_branch,to,to_branch,end,result,points,length\n");
        for (i = 0; i < d->n_edges; i++) {
            const psb_edge *ed = d->edges + i;
            fprintf(edges, "%d,%d,%d,%d,%d,%s,%d,%ld,", i, ed->from, ed->from_branch, ed->to,
                    ed->to_branch, psb_edge_end_string(ed->end), (int)ed->result, ed->n_points);
            psb__put_double(edges, ed->length, 0);
            fputc('\n', edges);
        }
        if (psb__write_failed(edges)) return PSB_ERR_INPUT;
    }
    return PSB_SUCCESS;
}
#endif

/* ==== Quasi-static evolution (psb_evolve_step) ==================================================
   One time step: Newton at the new load, else continuation in the load through folds. */

/* Counters spent since `before`. */
static psb_stats psb__stats_since(const psb_solver *s, const psb_stats *before)
{
    psb_stats d = s->stats;
    psb__stats_add(&d, before, -1);
    return d;
}

/* psb_evolve_step's point callback: measures the path, enforces max_length, calls the user's. */
typedef struct psb__evolve_ctx {
    const psb_evolve_options *eo;
    int p, user_stop, too_long;
    double length, low, high;
} psb__evolve_ctx;

static int psb__evolve_point(const psb_point *pt, void *user)
{
    psb__evolve_ctx *c = (psb__evolve_ctx *)user;
    double g = pt->y[c->p];
    c->length += pt->h;
    if (g < c->low) c->low = g;
    if (g > c->high) c->high = g;
    if (c->eo->on_point && c->eo->on_point(pt, c->eo->point_user)) return c->user_stop = 1;
    if (c->eo->max_length > 0 && c->length > c->eo->max_length && !(pt->flags & PSB_POINT_BOUND))
        return c->too_long = 1;
    return 0;
}

static const char *psb__check_evolve_options(const psb_evolve_options *o)
{
    if (o->mode < PSB_EVOLVE_AUTO || o->mode > PSB_EVOLVE_CONTINUATION) return "mode is not a psb_evolve_mode";
    if (o->newton_max_iter < 0 || o->newton_max_iter > PSB_MAX_ITER_LIMIT)
        return "newton_max_iter must lie in [0, PSB_MAX_ITER_LIMIT]";
    if (!(o->newton_max_jump >= 0)) return "newton_max_jump must be >= 0 (0: any)";
    if (o->param_min != o->param_min || o->param_max != o->param_max) return "param_min or param_max is NaN";
    if (o->max_steps < 0) return "max_steps < 0";
    if (!(o->max_length >= 0)) return "max_length must be >= 0 (0: no limit)";
    return NULL;
}

PSCBRANCH_DEF psb_result psb_evolve_step(psb_solver *s, double *y, double param_next,
                                         const psb_evolve_options *eo, psb_evolve_report *rep)
{
    psb_evolve_options o;
    psb_evolve_report local;
    psb_trace_options to;
    psb_trace_report tr;
    psb__evolve_ctx ctx;
    psb_stats before;
    const char *bad;
    int np1, p, ranged, up, i;
    double g0, far, *yn, *yc, *tc;
    psb_result r;
    if (!rep) rep = &local;
    memset(rep, 0, sizeof *rep);
    rep->newton_jump = rep->newton_gap = -1;
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (psb__trace_busy(s, "psb_evolve_step")) return PSB_ERR_INPUT;
    if (!y) return psb__fail(s, PSB_ERR_NULL, "y is NULL");
    if (eo) o = *eo;
    else memset(&o, 0, sizeof o);
    if ((bad = psb__check_evolve_options(&o)) != NULL) return psb__fail(s, PSB_ERR_OPTIONS, bad);
    np1 = s->internal_.np1;
    p = s->prob.param_index;
    if (!psb__all_finite(y, np1) || !psb__finite(param_next))
        return psb__fail(s, PSB_ERR_NONFINITE, "y or param_next contains NaN or Inf");
    g0 = y[p];
    ranged = o.param_min < o.param_max;
    if (ranged && (g0 < o.param_min || g0 > o.param_max || param_next < o.param_min || param_next > o.param_max))
        return psb__fail(s, PSB_ERR_INPUT, "y's parameter or param_next lies outside [param_min, param_max]");
    if (o.newton_max_iter == 0) o.newton_max_iter = 20;
    if (o.max_steps == 0) o.max_steps = 10000;
    before = s->stats;
    rep->param_low = rep->param_high = g0;
    yn = PSB__VEC(s, PSB__V_EV_N);
    yc = PSB__VEC(s, PSB__V_EV_Y);
    tc = PSB__VEC(s, PSB__V_EV_T);

    /* plain time stepping: Newton at param_next from the previous state */
    if (o.mode != PSB_EVOLVE_CONTINUATION || param_next == g0) {
        rep->newton_run = 1;
        psb__copy(yn, y, np1);
        yn[p] = param_next;
        r = rep->newton = psb_solve_at_param(s, yn, o.newton_max_iter);
        if (r == PSB_SUCCESS) {
            yn[p] = param_next;
            rep->newton_jump = psb__dist_w(s, y, yn);
            if (o.mode == PSB_EVOLVE_NEWTON || param_next == g0 || o.newton_max_jump == 0 ||
                rep->newton_jump <= o.newton_max_jump) {
                rep->method = PSB_EVOLVE_NEWTON;
                rep->jump = rep->newton_jump;
                rep->param_low = fmin(g0, param_next);
                rep->param_high = fmax(g0, param_next);
                rep->cost = psb__stats_since(s, &before);
                psb__copy(y, yn, np1);
                return PSB_SUCCESS;
            }
        } else if (psb__is_fatal(r) || o.mode == PSB_EVOLVE_NEWTON || param_next == g0) {
            rep->cost = psb__stats_since(s, &before);
            return r;
        }
    }

    /* the step's continuation problem: from (y, lambda_{k-1}) along the curve to param_next */
    up = param_next > g0;
    psb__copy(yc, y, np1);
    r = psb_tangent(s, yc, NULL, tc);
    if (r == PSB_SUCCESS && !up)
        for (i = 0; i < np1; i++) tc[i] = -tc[i];
    if (r == PSB_SUCCESS) r = psb__residual(s, yc, s->internal_.res);
    if (r == PSB_SUCCESS && psb__norm2(s->internal_.res, s->internal_.n) > s->opt.tol_residual) {
        /* a polish of the previous solution; a move longer than a step means it was none */
        r = psb_correct(s, yc, tc, NULL);
        /* (a fault, a NaN or a singular matrix is reported as such, not as a bad y) */
        if ((r != PSB_SUCCESS && !psb__is_fatal(r) && !psb__is_fault(r)) ||
            (r == PSB_SUCCESS && psb__dist_w(s, y, yc) > s->opt.h_init))
            r = psb__fail(s, PSB_ERR_INPUT, "y does not solve H(y) = 0 (no solution within h_init of it)");
    }
    if (r != PSB_SUCCESS) {
        rep->cost = psb__stats_since(s, &before);
        return r;
    }
    memset(&to, 0, sizeof to);
    far = up ? (ranged ? o.param_min : -DBL_MAX) : (ranged ? o.param_max : DBL_MAX);
    to.param_min = up ? far : param_next;
    to.param_max = up ? param_next : far;
    to.max_steps = o.max_steps;
    to.no_switch = o.no_switch;
    to.detect_loop = 1;
    to.on_point = psb__evolve_point;
    to.point_user = &ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.eo = &o;
    ctx.p = p;
    ctx.low = ctx.high = yc[p];
    r = psb_trace(s, yc, tc, &to, &tr);
    rep->trace_end = r;
    rep->steps = tr.steps;
    rep->n_folds = tr.n_folds;
    for (i = 0; i < tr.n_folds && i < PSB_MAX_FOLDS; i++) rep->fold_params[i] = tr.fold_params[i];
    rep->snap_through = tr.n_folds > 0;
    rep->n_switches = tr.n_switches;
    rep->path_length = ctx.length;
    rep->param_low = fmin(ctx.low, g0);
    rep->param_high = fmax(ctx.high, g0);
    rep->cost = psb__stats_since(s, &before);
    if (r == PSB_PARAM_BOUND && fabs(yc[p] - param_next) < fabs(yc[p] - far)) {
        yc[p] = param_next;
        rep->method = PSB_EVOLVE_CONTINUATION;
        rep->jump = psb__dist_w(s, y, yc);
        if (rep->newton_run && rep->newton == PSB_SUCCESS) rep->newton_gap = psb__dist_w(s, yn, yc);
        psb__copy(y, yc, np1);
        s->message[0] = 0;
        return PSB_SUCCESS;
    }
    if (ctx.user_stop) return psb__fail(s, PSB_ERR_CALLBACK, "on_point stopped the step");
    if (r < 0) return r;
    return psb__fail(s, PSB_ERR_NO_CONVERGENCE,
                     r == PSB_PARAM_BOUND ? "the path left [param_min, param_max] before param_next"
                     : r == PSB_STEP_BUDGET ? "the path used max_steps before param_next"
                     : ctx.too_long ? "the path grew longer than max_length before param_next"
                     : r == PSB_LOOP_CLOSED ? "the path closed a loop without reaching param_next"
                     : "the path ended at a point the tangent switch could not pass");
}

/* ==== Fold curves in two parameters (psb_fold_map_*) ============================================
   H(x, lambda, mu) = 0 at fixed mu (the map's at_mu problem), and the fold curve as the solution
   curve of the minimally augmented system [H; sigma] = 0 (Govaerts, Numerical Methods for
   Bifurcations of Dynamical Equilibria, SIAM 2000): sigma solves [H_x b; c^T 0] [v; sigma] =
   [0; 1]. By Cramer's rule sigma = det H_x / det [H_x b; c^T 0], so its zeros are the folds whatever
   the borders, as long as the bordered matrix is regular: b and c only need to be near the
   left and right null vectors of H_x. A limit point in mu on that curve is a cusp. */

#define PSB__FOLD_READY 0x70736266u /* psb_fold_map.internal_.ready of a set-up map */

/* Bytes a map of p needs; carves m's arrays out of memory when m is not NULL. 0: p out of
   range (dense: the dense backend's limit). */
static size_t psb__fold_layout(const psb_two_param_problem *p, psb_fold_map *m, void *memory)
{
    int n = p->n, band = p->linear == PSB_LINEAR_BANDED;
    size_t nn = (size_t)n, np1 = nn + 1, np2 = nn + 2, off = 0, ld, ldlu;
    double *base = (double *)memory;
    if (n < 1 || (p->linear != PSB_LINEAR_DENSE && !band)) return 0;
    if (band ? p->kl < 0 || p->ku < 0 || p->kl > n - 1 || p->ku > n - 1 : n > 46000) return 0;
    ld = band ? (size_t)p->kl + (size_t)p->ku + 1 : 0;
    ldlu = ld + (band ? (size_t)p->kl : 0);
#define PSB__TAKE(field, count)                                                                    \
    do {                                                                                           \
        if (m) m->internal_.field = base + off;                                                    \
        off += (count);                                                                            \
    } while (0)
    PSB__TAKE(jac, band ? 0 : nn * np2);
    PSB__TAKE(mat, band ? 0 : np1 * np1);
    PSB__TAKE(rhs, 2 * np1);
    PSB__TAKE(y_eval, np2);
    PSB__TAKE(y_lift, np2);
    PSB__TAKE(y_try, np2);
    PSB__TAKE(b, nn);
    PSB__TAKE(c, nn);
    PSB__TAKE(b_old, nn);
    PSB__TAKE(c_old, nn);
    if (band) {
        PSB__TAKE(ab, ld * nn);
        PSB__TAKE(ab_d, ld * nn);
        PSB__TAKE(lu, ldlu * nn);
        PSB__TAKE(gbw, ((size_t)p->kl + PSB__GB_NB) * PSB__GB_NB);
        PSB__TAKE(dpar, 2 * nn);
        PSB__TAKE(dpar_d, 2 * nn);
        PSB__TAKE(bx, np2);
        PSB__TAKE(bres, np2);
        PSB__TAKE(bdx, np2);
        PSB__TAKE(brow, 2 * nn);
        PSB__TAKE(y_fac, np2);
        PSB__TAKE(y_usr, np2);
        PSB__TAKE(wc, 4 * nn);
        PSB__TAKE(wkey, 4 * nn);
    }
#undef PSB__TAKE
    off = psb__align(off * sizeof(double));
    if (m) m->internal_.ipiv = (char *)memory + off;
    off += psb__align((band ? nn : np1) * sizeof(psb__lint));
    if (m) m->internal_.state = (int *)(void *)((char *)memory + off);
    return off + psb__align(nn * sizeof(int));
}

/* at_mu's point y (n+1) with mu inserted at mu_index: the user's y (n+2). */
static int psb__fold_at_mu_residual(const double *y, double *h, void *user)
{
    psb_fold_map *m = (psb_fold_map *)user;
    psb_two_param_lift(&m->two, y, m->mu, m->internal_.y_eval);
    return m->two.residual(m->internal_.y_eval, h, m->two.user);
}

/* the user's n x (n+2) Jacobian without its mu column */
static int psb__fold_at_mu_jacobian(const double *y, double *jac, int ld, void *user)
{
    psb_fold_map *m = (psb_fold_map *)user;
    int n = m->two.n, j, k = 0, rc;
    psb_two_param_lift(&m->two, y, m->mu, m->internal_.y_eval);
    rc = m->two.jacobian(m->internal_.y_eval, m->internal_.jac, n, m->two.user);
    if (rc) return rc;
    for (j = 0; j < n + 2; j++)
        if (j != m->two.mu_index)
            memcpy(jac + (size_t)k++ * (size_t)ld, m->internal_.jac + (size_t)j * (size_t)n, (size_t)n * sizeof *jac);
    return 0;
}

/* LU of [A col; row^T 0] in internal_.mat, A the state columns of jac (leading dimension ldj).
   0; 1 when singular; 2 when not finite. */
static int psb__fold_factor(psb_fold_map *m, const double *jac, int ldj, const double *col,
                            const double *row)
{
    int n = m->two.n, np1 = n + 1, i, k;
    psb__lint order = np1, info = 0;
    double *mat = m->internal_.mat;
    for (k = 0; k < n; k++) {
        const double *src = jac + (size_t)m->internal_.state[k] * (size_t)ldj;
        double *dst = mat + (size_t)k * (size_t)np1;
        for (i = 0; i < n; i++) dst[i] = src[i];
        dst[n] = row[k];
    }
    for (i = 0; i < n; i++) mat[(size_t)n * (size_t)np1 + (size_t)i] = col[i];
    mat[(size_t)n * (size_t)np1 + (size_t)n] = 0;
    if (!psb__all_finite(mat, (size_t)np1 * (size_t)np1)) return 2;
    m->n_factor++;
    PSCBRANCH_FORTRAN(dgetrf)(&order, &order, mat, &order, (psb__lint *)m->internal_.ipiv, &info);
    return info != 0;
}

/* z (n+1) = M^{-1} e_{n+1} (trans "N") or M^{-T} e_{n+1} ("T"), M factored in internal_.mat.
   0, or 1 when z is not finite. */
static int psb__fold_solve_last(psb_fold_map *m, const char *trans, double *z)
{
    int np1 = m->two.n + 1;
    psb__lint order = np1, one = 1, info = 0;
    memset(z, 0, (size_t)np1 * sizeof *z);
    z[np1 - 1] = 1;
    PSCBRANCH_FORTRAN(dgetrs)(trans, &order, &one, m->internal_.mat, &order,
                              (psb__lint *)m->internal_.ipiv, z, &order, &info PSB__STRLEN_ONE);
    return info != 0 || !psb__all_finite(z, (size_t)np1);
}

/* ---- banded: block elimination on the LU of H_x ---------------------------------------------
   The map borders A = H_x by k <= 2 columns C and rows R (n x k, column-major), M = [A C; R^T D]
   (D k x k, row-major). On the fold curve A is singular by construction and M is not, so block
   elimination on A's LU cancels: every solution is refined against M, and where that stalls, A +
   sqrt(eps) ||A|| I is factored instead; refinement then converges at a rate ~ shift ||M^{-1}||
   (the banded backend's bordering, with two borders). */

/* ab (+ shift I) into lu, dgbtrf's layout and pivots; 0, or 1 at an exactly zero pivot. */
static int psb__fold_band_lu(psb_fold_map *m, double shift)
{
    int kl = m->two.kl, ku = m->two.ku;
    long info;
    m->n_factor++;
    /* arguments are checked at init: a nonzero info is a zero pivot */
    info = psb__band_factor(m->two.n, kl, ku, m->internal_.ab, shift, m->internal_.lu, 2 * kl + ku + 1,
                            (psb__lint *)m->internal_.ipiv, m->internal_.gbw) != 0;
    m->internal_.shifted = shift != 0;
    m->internal_.lu_ok = info == 0;
    m->internal_.lu_gen++;
    return info != 0;
}

/* x <- A^{-1} x, or A^{-T} x with trans (dgbtrs' "T" substitutions), on lu's factors */
static void psb__fold_band_subst(const psb_fold_map *m, int trans, double *x)
{
    int n = m->two.n, kl = m->two.kl, kv = kl + m->two.ku, i, j;
    size_t ldlu = (size_t)kv + 1 + (size_t)kl;
    const double *lu = m->internal_.lu;
    const psb__lint *ipiv = (const psb__lint *)m->internal_.ipiv;
    double tmp, sum;
    if (!trans) {
        psb__band_subst_lu(n, kl, m->two.ku, lu, ldlu, ipiv, x, NULL);
        return;
    }
    for (j = 0; j < n; j++) {
        const double *col = lu + (size_t)j * ldlu;
        int above = j < kv ? j : kv;
        for (sum = x[j], i = 1; i <= above; i++) sum -= col[kv - i] * x[j - i];
        x[j] = sum / col[kv];
    }
    for (j = n - 2; kl > 0 && j >= 0; j--) {
        const double *col = lu + (size_t)j * ldlu + kv + 1;
        int l = (int)ipiv[j] - 1, km = kl < n - 1 - j ? kl : n - 1 - j;
        for (sum = x[j], i = 0; i < km; i++) sum -= col[i] * x[j + 1 + i];
        x[j] = sum;
        if (l != j) tmp = x[l], x[l] = x[j], x[j] = tmp;
    }
}

/* res = rhs - M sol (trans: M^T), A unshifted; returns ||res||_inf (Inf if not finite) and in
   *scale the largest |rhs_i| + sum_j |M_ij sol_j|, the size of the rows' rounding. */
static double psb__fold_band_residual(const psb_fold_map *m, int trans, int k, const double *C,
                                      const double *R, const double *D, const double *rhs,
                                      const double *sol, double *res, double *scale)
{
    int n = m->two.n, kl = m->two.kl, ku = m->two.ku, ld = kl + ku + 1, i, j, l, l2;
    const double *ab = m->internal_.ab, *cc = trans ? R : C, *rr = trans ? C : R;
    double big = 0, *mag = m->internal_.bdx; /* |terms| per row; bdx is free until the update */
    for (i = 0; i < n + k; i++) {
        res[i] = rhs[i];
        mag[i] = fabs(rhs[i]);
    }
    for (j = 0; j < n; j++) {
        int lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
        for (i = lo; i <= hi; i++) {
            double a = ab[PSB_BAND_INDEX(ku, ld, i, j)], p = trans ? a * sol[i] : a * sol[j];
            res[trans ? j : i] -= p;
            mag[trans ? j : i] += fabs(p);
        }
    }
    for (l = 0; l < k; l++) {
        for (i = 0; i < n; i++) {
            double p = cc[(size_t)l * (size_t)n + (size_t)i] * sol[n + l], q = rr[(size_t)l * (size_t)n + (size_t)i] * sol[i];
            res[i] -= p;
            mag[i] += fabs(p);
            res[n + l] -= q;
            mag[n + l] += fabs(q);
        }
        for (l2 = 0; l2 < k; l2++) {
            double p = (trans ? D[l2 * k + l] : D[l * k + l2]) * sol[n + l2];
            res[n + l] -= p;
            mag[n + l] += fabs(p);
        }
    }
    *scale = 0;
    for (i = 0; i < n + k; i++) {
        if (res[i] != res[i]) return HUGE_VAL;
        big = fmax(big, fabs(res[i]));
        *scale = fmax(*scale, mag[i]);
    }
    return big;
}

/* sol = M_s^{-1} rhs (trans: M_s^{-T}) by block elimination, M_s being M with lu's shift:
   0, or 1 when the k x k Schur complement is singular or the result not finite. */
static int psb__fold_band_apply(psb_fold_map *m, int trans, int k, const double *C, const double *R,
                                const double *D, const double *rhs, double *sol)
{
    int n = m->two.n, i, l, l2;
    const double *cc = trans ? R : C, *rr = trans ? C : R;
    int slot = k == 2 ? 2 : trans; /* each kind of solve borders with its own C: a slot each */
    size_t off = (size_t)slot * (size_t)n, kn = (size_t)k * (size_t)n;
    double *w = m->internal_.wc + off, *key = m->internal_.wkey + off, sc[4], g[2], xi[2], det;
    memcpy(sol, rhs, (size_t)n * sizeof *sol);
    psb__fold_band_subst(m, trans, sol);
    if (m->internal_.wgen[slot] != m->internal_.lu_gen || memcmp(key, cc, kn * sizeof *key)) {
        memcpy(key, cc, kn * sizeof *key);
        memcpy(w, cc, kn * sizeof *w);
        for (l = 0; l < k; l++) psb__fold_band_subst(m, trans, w + (size_t)l * (size_t)n);
        m->internal_.wgen[slot] = m->internal_.lu_gen;
    }
    for (l = 0; l < k; l++) {
        const double *r = rr + (size_t)l * (size_t)n;
        for (g[l] = rhs[n + l], i = 0; i < n; i++) g[l] -= r[i] * sol[i];
        for (l2 = 0; l2 < k; l2++) {
            const double *wc = w + (size_t)l2 * (size_t)n;
            double v = trans ? D[l2 * k + l] : D[l * k + l2];
            for (i = 0; i < n; i++) v -= r[i] * wc[i];
            sc[l * k + l2] = v;
        }
    }
    if (k == 1) {
        det = sc[0];
        xi[0] = g[0] / det;
    } else {
        det = sc[0] * sc[3] - sc[1] * sc[2];
        xi[0] = (sc[3] * g[0] - sc[1] * g[1]) / det;
        xi[1] = (sc[0] * g[1] - sc[2] * g[0]) / det;
    }
    if (det == 0 || !psb__finite(det)) return 1;
    for (l = 0; l < k; l++) {
        const double *wc = w + (size_t)l * (size_t)n;
        for (i = 0; i < n; i++) sol[i] -= wc[i] * xi[l];
        sol[n + l] = xi[l];
    }
    return !psb__all_finite(sol, (size_t)n + (size_t)k);
}

/* M sol = rhs (trans: M^T sol = rhs) to working precision: the residual down to the rounding
   of its rows (32 eps their size; where refinement stalls, sqrt(n) times that, the rounding of
   the borders' long dot products). 0, or 1 when M is singular (the Schur complement vanishes,
   or refinement on the shifted factors stalls above that). */
static int psb__fold_band_solve(psb_fold_map *m, int trans, int k, const double *C, const double *R,
                                const double *D, const double *rhs, double *sol)
{
    int n = m->two.n, i, it, attempt;
    double *res = m->internal_.bres, *dx = m->internal_.bdx, scale;
    for (attempt = 0; attempt < 2; attempt++) {
        double prev = HUGE_VAL;
        int max_it = m->internal_.shifted ? 30 : 4;
        if (m->internal_.lu_ok && !psb__fold_band_apply(m, trans, k, C, R, D, rhs, sol))
            for (it = 0; it <= max_it; it++) {
                double rn = psb__fold_band_residual(m, trans, k, C, R, D, rhs, sol, res, &scale);
                if (rn <= 32 * DBL_EPSILON * scale) return 0;
                if (!(rn < 0.5 * prev) && it >= 2) { /* stalled */
                    if (rn <= 32 * DBL_EPSILON * sqrt((double)n + k) * scale) return 0;
                    break;
                }
                prev = rn;
                if (psb__fold_band_apply(m, trans, k, C, R, D, res, dx)) break;
                for (i = 0; i < n + k; i++) sol[i] += dx[i];
            }
        if (m->internal_.shifted) return 1;
        psb__fold_band_lu(m, 1.4901161193847656e-08 * (m->internal_.mnorm > 0 ? m->internal_.mnorm : 1));
    }
    return 1;
}

/* H_x, H_lambda, H_mu at y into ab, dpar (lambda's column, mu's) and H_x's LU into lu, unless
   they are y's already. Returns band_jacobian's nonzero code, else 0 with *bad 0, 2 for NaN or
   Inf, 1 when A and A + shift I are both singular. */
static int psb__fold_band_at(psb_fold_map *m, const double *y, int *bad)
{
    int n = m->two.n, ld = m->two.kl + m->two.ku + 1, rc, i, j;
    size_t size = (size_t)ld * (size_t)n, np2 = (size_t)n + 2;
    double big = 0;
    *bad = 0;
    if (m->internal_.lu_ok && !memcmp(m->internal_.y_fac, y, np2 * sizeof *y)) return 0;
    m->internal_.lu_ok = 0;
    memset(m->internal_.ab, 0, size * sizeof(double));
    rc = m->two.band_jacobian(y, m->internal_.ab, ld, m->internal_.dpar, m->internal_.dpar + n, m->two.user);
    if (rc) return rc;
    if (!psb__all_finite(m->internal_.ab, size) || !psb__all_finite(m->internal_.dpar, 2 * (size_t)n)) {
        *bad = 2;
        return 0;
    }
    for (j = 0; j < n; j++) {
        double sum = 0;
        for (i = 0; i < ld; i++) sum += fabs(m->internal_.ab[(size_t)j * (size_t)ld + (size_t)i]);
        big = fmax(big, sum);
    }
    m->internal_.mnorm = big;
    memcpy(m->internal_.y_fac, y, np2 * sizeof *y);
    if (psb__fold_band_lu(m, 0) && psb__fold_band_lu(m, 1.4901161193847656e-08 * (big > 0 ? big : 1))) *bad = 1;
    return 0;
}

/* v (n+1: v and sigma) from [H_x b; c^T 0] [v; sigma] = e_{n+1}, and w (n+1) from its
   transpose when w is not NULL, on the factors at y_fac; 0 or 1 (singular). */
static int psb__fold_band_vw(psb_fold_map *m, double *v, double *w)
{
    int n = m->two.n;
    double *e = m->internal_.bx, zero = 0;
    memset(e, 0, (size_t)(n + 1) * sizeof *e);
    e[n] = 1;
    if (psb__fold_band_solve(m, 0, 1, m->internal_.b, m->internal_.c, &zero, e, v)) return 1;
    return w && psb__fold_band_solve(m, 1, 1, m->internal_.b, m->internal_.c, &zero, e, w);
}

/* the fold problem's banded residual: H(y), sigma(y) */
static int psb__fold_band_residual_fn(psb_fold_map *m, const double *y, double *h)
{
    int n = m->two.n, bad, rc = m->two.residual(y, h, m->two.user);
    if (rc) return rc;
    rc = psb__fold_band_at(m, y, &bad);
    if (rc) return rc;
    if (bad == 2) {
        h[n] = NAN;
        return 0;
    }
    if (bad || psb__fold_band_vw(m, m->internal_.rhs, NULL)) return 1;
    h[n] = m->internal_.rhs[n];
    return 0;
}

/* The fold problem's solver.factor: the matrix [H_x H_lambda H_mu; d sigma; row^T], kept as
   A = H_x's LU with the borders C = (H_lambda, H_mu), R = (sigma's gradient, row) over the
   state, D their lambda and mu entries; sigma's gradient as psb__fold_jacobian's. */
static int psb__fold_band_factor(const double *y, const double *row, void *ctx)
{
    psb_fold_map *m = (psb_fold_map *)ctx;
    int n = m->two.n, np2 = n + 2, ld = m->two.kl + m->two.ku + 1, kl = m->two.kl, ku = m->two.ku;
    int i, j, k, rc, bad, side, li = m->two.lambda_index, mi = m->two.mu_index;
    const int *state = m->internal_.state;
    double *v = m->internal_.rhs, *w = m->internal_.rhs + n + 1, *yd = m->internal_.y_eval;
    double *g = m->internal_.brow, *ad = m->internal_.ab_d, *dd = m->internal_.dpar_d;
    double vmax = 0, ymax = 1, step, gl = 0, gm = 0;
    psb__copy(m->internal_.y_usr, y, np2);
    rc = psb__fold_band_at(m, y, &bad);
    if (rc) return rc;
    if (bad || psb__fold_band_vw(m, v, w)) return 1;
    for (k = 0; k < n; k++) {
        vmax = fmax(vmax, fabs(v[k]));
        ymax = fmax(ymax, fabs(y[state[k]]));
    }
    step = 6.0554544523933395e-06 * ymax / vmax; /* cbrt(eps) relative, in the largest component */
    memset(g, 0, (size_t)n * sizeof *g);
    for (side = 1; side >= -1; side -= 2) {
        memcpy(yd, y, (size_t)np2 * sizeof *yd);
        for (k = 0; k < n; k++) yd[state[k]] += side * step * v[k];
        memset(ad, 0, (size_t)ld * (size_t)n * sizeof *ad);
        rc = m->two.band_jacobian(yd, ad, ld, dd, dd + n, m->two.user);
        if (rc) return rc;
        for (j = 0; j < n; j++) {
            int lo = j - ku > 0 ? j - ku : 0, hi = j + kl < n - 1 ? j + kl : n - 1;
            double dot = 0;
            for (i = lo; i <= hi; i++) dot += w[i] * ad[PSB_BAND_INDEX(ku, ld, i, j)];
            g[j] -= side * dot;
        }
        for (i = 0; i < n; i++) {
            gl -= side * w[i] * dd[i];
            gm -= side * w[i] * dd[n + i];
        }
    }
    for (j = 0; j < n; j++) {
        g[j] /= 2 * step;
        g[n + j] = row[state[j]];
    }
    m->internal_.dmat[0] = gl / (2 * step);
    m->internal_.dmat[1] = gm / (2 * step);
    m->internal_.dmat[2] = row[li];
    m->internal_.dmat[3] = row[mi];
    return !psb__all_finite(g, (size_t)n) || !psb__finite(m->internal_.dmat[0]) || !psb__finite(m->internal_.dmat[1]);
}

/* The fold problem's solver.solve, in place, nrhs columns of n+2 (rows: H, sigma, the border
   row; solutions in y's order). A residual evaluated since the factorisation moved H_x's LU
   elsewhere: it is formed again at the factorisation's y. */
static int psb__fold_band_solve_user(double *b, int nrhs, void *ctx)
{
    psb_fold_map *m = (psb_fold_map *)ctx;
    int n = m->two.n, np2 = n + 2, col, j, bad, rc;
    double *sol = m->internal_.rhs, *z;
    if (!m->internal_.lu_ok || memcmp(m->internal_.y_fac, m->internal_.y_usr, (size_t)np2 * sizeof(double))) {
        rc = psb__fold_band_at(m, m->internal_.y_usr, &bad);
        if (rc) return rc;
        if (bad) return 1;
    }
    for (col = 0; col < nrhs; col++) {
        z = b + (size_t)col * (size_t)np2;
        memcpy(m->internal_.y_eval, z, (size_t)np2 * sizeof *z);
        if (psb__fold_band_solve(m, 0, 2, m->internal_.dpar, m->internal_.brow, m->internal_.dmat,
                                 m->internal_.y_eval, sol))
            return 1;
        for (j = 0; j < n; j++) z[m->internal_.state[j]] = sol[j];
        z[m->two.lambda_index] = sol[n];
        z[m->two.mu_index] = sol[n + 1];
    }
    return 0;
}

static int psb__fold_at_mu_band(const double *y, double *band, int ldband, double *dparam, void *user)
{
    psb_fold_map *m = (psb_fold_map *)user;
    psb_two_param_lift(&m->two, y, m->mu, m->internal_.y_eval);
    return m->two.band_jacobian(m->internal_.y_eval, band, ldband, dparam, m->internal_.dpar_d + m->two.n,
                                m->two.user);
}

/* fold's residual: H(y) and sigma(y). A singular bordered matrix is a recoverable failure (the
   step shortens); a NaN in the Jacobian shows as sigma = NaN (PSB_ERR_NONFINITE). */
static int psb__fold_residual(const double *y, double *h, void *user)
{
    psb_fold_map *m = (psb_fold_map *)user;
    int n = m->two.n, rc, f;
    if (m->two.linear == PSB_LINEAR_BANDED) return psb__fold_band_residual_fn(m, y, h);
    rc = m->two.residual(y, h, m->two.user);
    if (rc) return rc;
    rc = m->two.jacobian(y, m->internal_.jac, n, m->two.user);
    if (rc) return rc;
    f = psb__fold_factor(m, m->internal_.jac, n, m->internal_.b, m->internal_.c);
    if (f == 2) {
        h[n] = NAN;
        return 0;
    }
    if (f || psb__fold_solve_last(m, "N", m->internal_.rhs)) return 1;
    h[n] = m->internal_.rhs[n];
    return 0;
}

/* fold's Jacobian: the user's n rows, and sigma's gradient, d sigma / d y_j = -w^T (d H_x /
   d y_j) v with [w; .] = M^{-T} e_{n+1} (differentiate M [v; sigma] = e_{n+1}). By the symmetry
   of second derivatives (d H_x / d y_j) v is column j of the derivative of dH along (v, 0, 0),
   so one central difference of the user's Jacobian along v, two evaluations with error
   O(step^2), gives the whole row. Differences of fold's residual would cost n+2 Jacobians and
   LUs for a row good to sqrt(eps) only. Within a step of a kink of H_x the quotient mixes
   pieces, as the library's own differences do. */
static int psb__fold_jacobian(const double *y, double *jac, int ld, void *user)
{
    psb_fold_map *m = (psb_fold_map *)user;
    int n = m->two.n, np2 = n + 2, i, j, k, rc, f, side;
    const int *state = m->internal_.state;
    double *v = m->internal_.rhs, *w = m->internal_.rhs + n + 1, *yd = m->internal_.y_eval,
           *jd = m->internal_.jac, vmax = 0, ymax = 1, step;
    rc = m->two.jacobian(y, jac, ld, m->two.user);
    if (rc) return rc;
    f = psb__fold_factor(m, jac, ld, m->internal_.b, m->internal_.c);
    if (f == 2) {
        for (j = 0; j < np2; j++) jac[n + (size_t)j * (size_t)ld] = NAN;
        return 0;
    }
    if (f || psb__fold_solve_last(m, "N", v) || psb__fold_solve_last(m, "T", w)) return 1;
    for (k = 0; k < n; k++) {
        vmax = fmax(vmax, fabs(v[k]));
        ymax = fmax(ymax, fabs(y[state[k]]));
    }
    step = 6.0554544523933395e-06 * ymax / vmax; /* cbrt(eps) relative, in the largest component */
    for (j = 0; j < np2; j++) jac[n + (size_t)j * (size_t)ld] = 0;
    for (side = 1; side >= -1; side -= 2) {
        memcpy(yd, y, (size_t)np2 * sizeof *yd);
        for (k = 0; k < n; k++) yd[state[k]] += side * step * v[k];
        rc = m->two.jacobian(yd, jd, n, m->two.user);
        if (rc) return rc;
        for (j = 0; j < np2; j++) {
            double dot = 0;
            for (i = 0; i < n; i++) dot += w[i] * jd[i + (size_t)j * (size_t)n];
            jac[n + (size_t)j * (size_t)ld] -= side * dot;
        }
    }
    for (j = 0; j < np2; j++) jac[n + (size_t)j * (size_t)ld] /= 2 * step;
    return 0;
}

PSCBRANCH_DEF void psb_two_param_problem_init(psb_two_param_problem *p, int n,
                                              psb_residual_fn residual,
                                              psb_jacobian_fn jacobian, void *user)
{
    if (!p) return;
    memset(p, 0, sizeof *p);
    p->n = n;
    p->residual = residual;
    p->jacobian = jacobian;
    p->user = user;
    p->lambda_index = n;
    p->mu_index = n + 1;
}

PSCBRANCH_DEF size_t psb_fold_map_memory_size(int n)
{
    psb_two_param_problem p;
    memset(&p, 0, sizeof p);
    p.n = n;
    return psb__fold_layout(&p, NULL, NULL);
}

PSCBRANCH_DEF size_t psb_fold_map_memory_size_for(const psb_two_param_problem *p)
{
    return p ? psb__fold_layout(p, NULL, NULL) : 0;
}

/* lambda_index and mu_index distinct columns of the n+2 */
static int psb__two_param_indices_ok(const psb_two_param_problem *p)
{
    return p->lambda_index >= 0 && p->lambda_index <= p->n + 1 && p->mu_index >= 0 && p->mu_index <= p->n + 1 &&
           p->lambda_index != p->mu_index;
}

PSCBRANCH_DEF psb_result psb_fold_map_init(psb_fold_map *m, const psb_two_param_problem *p,
                                           double mu, void *memory, size_t bytes)
{
    size_t need;
    int n, j, k = 0;
    if (!m) return PSB_ERR_NULL;
    memset(m, 0, sizeof *m);
    if (!p || !memory || !p->residual) return PSB_ERR_NULL;
    if (p->linear != PSB_LINEAR_DENSE && p->linear != PSB_LINEAR_BANDED) return PSB_ERR_OPTIONS;
    if (p->linear == PSB_LINEAR_BANDED ? !p->band_jacobian : !p->jacobian) return PSB_ERR_NULL;
    n = p->n;
    need = psb__fold_layout(p, NULL, NULL);
    if (!need || !psb__two_param_indices_ok(p)) return PSB_ERR_SIZE;
    if (!psb__finite(mu)) return PSB_ERR_NONFINITE;
    if (bytes < need) return PSB_ERR_NOMEM;
    memset(memory, 0, need); /* zero borders until a start */
    m->two = *p;
    m->mu = mu;
    psb__fold_layout(p, m, memory);
    for (j = 0; j < n + 2; j++)
        if (j != p->lambda_index && j != p->mu_index) m->internal_.state[k++] = j;
    psb_problem_init(&m->at_mu, n, psb__fold_at_mu_residual, psb__fold_at_mu_jacobian, m);
    m->at_mu.param_index = p->lambda_index - (p->lambda_index > p->mu_index);
    psb_problem_init(&m->fold, n + 1, psb__fold_residual, psb__fold_jacobian, m);
    m->fold.param_index = p->mu_index;
    if (p->linear == PSB_LINEAR_BANDED) {
        m->at_mu.jacobian = NULL;
        m->at_mu.linear = PSB_LINEAR_BANDED;
        m->at_mu.kl = p->kl;
        m->at_mu.ku = p->ku;
        m->at_mu.band_jacobian = psb__fold_at_mu_band;
        m->fold.jacobian = NULL;
        m->fold.linear = PSB_LINEAR_USER;
        m->fold.solver.factor = psb__fold_band_factor;
        m->fold.solver.solve = psb__fold_band_solve_user;
        m->fold.solver.ctx = m;
    }
    m->b = m->internal_.b;
    m->c = m->internal_.c;
    m->internal_.ready = PSB__FOLD_READY;
    return PSB_SUCCESS;
}

/* The checks psb_fold_map_start and _refine share: PSB_SUCCESS, or the failure (message on s
   when s is a solver). */
static psb_result psb__fold_check(psb_fold_map *m, psb_solver *s, const char *what)
{
    char buf[160];
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (!m || m->internal_.ready != PSB__FOLD_READY)
        return psb__fail(s, PSB_ERR_NULL, "the fold map is NULL or not set up (psb_fold_map_init)");
    if (s->prob.residual != psb__fold_residual || s->prob.user != (void *)m) {
        snprintf(buf, sizeof buf, "%s: the solver is not one of this map's fold problem", what);
        return psb__fail(s, PSB_ERR_INPUT, buf);
    }
    return psb__trace_busy(s, what);
}

/* The user's Jacobian at y into internal_.jac, its failures mapped as the library's. */
static psb_result psb__fold_user_jacobian(psb_fold_map *m, psb_solver *s, const double *y)
{
    int n = m->two.n, bad;
    psb_result r;
    if (m->two.linear == PSB_LINEAR_BANDED) {
        r = psb__callback_code(s, psb__fold_band_at(m, y, &bad), "band_jacobian callback returned nonzero");
        if (r != PSB_SUCCESS) return r;
        if (bad == 2) return psb__fail(s, PSB_ERR_NONFINITE, "band_jacobian callback returned NaN or Inf");
        if (bad) return psb__fail(s, PSB_ERR_SINGULAR, "H_x and H_x + sqrt(eps) ||H_x|| I are singular at y");
        return PSB_SUCCESS;
    }
    r = psb__callback_code(s, m->two.jacobian(y, m->internal_.jac, n, m->two.user),
                           "jacobian callback returned nonzero");
    if (r != PSB_SUCCESS) return r;
    if (!psb__all_finite(m->internal_.jac, (size_t)n * (size_t)(n + 2)))
        return psb__fail(s, PSB_ERR_NONFINITE, "jacobian callback returned NaN or Inf");
    return PSB_SUCCESS;
}

/* New borders at y from the current ones: c = v, b = w of the bordered systems there, each
   of unit 2-norm; at a fold these are the right and left null vectors of H_x. */
static psb_result psb__fold_new_borders(psb_fold_map *m, psb_solver *s, const double *y)
{
    int n = m->two.n, k;
    double *v = m->internal_.rhs, *w = m->internal_.rhs + n + 1, nv, nw;
    psb_result r = psb__fold_user_jacobian(m, s, y);
    if (r != PSB_SUCCESS) return r;
    if (m->two.linear == PSB_LINEAR_BANDED ? psb__fold_band_vw(m, v, w)
                                           : psb__fold_factor(m, m->internal_.jac, n, m->internal_.b, m->internal_.c) ||
                                                 psb__fold_solve_last(m, "N", v) || psb__fold_solve_last(m, "T", w))
        return psb__fail(s, PSB_ERR_SINGULAR, "the bordered matrix [H_x b; c^T 0] is singular at y");
    nv = psb__norm2(v, n);
    nw = psb__norm2(w, n);
    for (k = 0; k < n; k++) {
        m->internal_.b[k] = w[k] / nw;
        m->internal_.c[k] = v[k] / nv;
    }
    return PSB_SUCCESS;
}

/* Newton at fixed mu on fold from y, borders anew at its solution, Newton again: the fold in
   internal_.y_try on success. */
static psb_result psb__fold_refine(psb_fold_map *m, psb_solver *s, const double *y, int max_iter)
{
    double *yt = m->internal_.y_try;
    psb_result r;
    psb__copy(yt, y, m->two.n + 2);
    r = psb_solve_at_param(s, yt, max_iter);
    if (r == PSB_SUCCESS) r = psb__fold_new_borders(m, s, yt);
    if (r == PSB_SUCCESS) r = psb_solve_at_param(s, yt, max_iter);
    return r;
}

static void psb__fold_keep_borders(psb_fold_map *m, int restore)
{
    size_t bytes = (size_t)m->two.n * sizeof(double);
    if (restore) {
        memcpy(m->internal_.b, m->internal_.b_old, bytes);
        memcpy(m->internal_.c, m->internal_.c_old, bytes);
    } else {
        memcpy(m->internal_.b_old, m->internal_.b, bytes);
        memcpy(m->internal_.c_old, m->internal_.c, bytes);
    }
}

PSCBRANCH_DEF psb_result psb_fold_map_start(psb_fold_map *m, psb_solver *fold_solver,
                                            const double *y, const double *t, double *y_fold,
                                            double *t_fold)
{
    psb_solver *s = fold_solver;
    psb_result r = psb__fold_check(m, s, "psb_fold_map_start");
    int n, k;
    double *yl, *q, *p, nq, np;
    if (r != PSB_SUCCESS) return r;
    if (!y || !t || !y_fold) return psb__fail(s, PSB_ERR_NULL, "y, t or y_fold is NULL");
    n = m->two.n;
    if (!psb__all_finite(y, (size_t)n + 1) || !psb__all_finite(t, (size_t)n + 1) || !psb__finite(m->mu))
        return psb__fail(s, PSB_ERR_NONFINITE, "y, t or the map's mu contains NaN or Inf");
    yl = m->internal_.y_lift;
    q = m->internal_.y_try; /* t lifted, for its state part */
    p = m->internal_.rhs;
    psb_two_param_lift(&m->two, t, 0, q);
    for (k = 0; k < n; k++) q[k] = q[m->internal_.state[k]];
    nq = psb__norm2(q, n);
    if (!(nq > 0)) return psb__fail(s, PSB_ERR_INPUT, "t has no state component");
    psb_two_param_lift(&m->two, y, m->mu, yl);
    r = psb__fold_user_jacobian(m, s, yl);
    if (r != PSB_SUCCESS) return r;
    psb__fold_keep_borders(m, 0);
    /* c along t's state part, the right null vector at a fold; b the left one, from
       [H_x H_lambda; c^T 0]^T [b; .] = e_{n+1} (regular where dH has rank n and c is not
       orthogonal to the kernel of H_x) */
    for (k = 0; k < n; k++) m->internal_.c[k] = q[k] / nq;
    if (m->two.linear == PSB_LINEAR_BANDED) {
        double zero = 0, *e = m->internal_.bx;
        memset(e, 0, (size_t)(n + 1) * sizeof *e);
        e[n] = 1;
        k = psb__fold_band_solve(m, 1, 1, m->internal_.dpar, m->internal_.c, &zero, e, p);
    } else {
        k = psb__fold_factor(m, m->internal_.jac, n, m->internal_.jac + (size_t)m->two.lambda_index * (size_t)n,
                             m->internal_.c) ||
            psb__fold_solve_last(m, "T", p);
    }
    if (k || !((np = psb__norm2(p, n)) > 0)) {
        psb__fold_keep_borders(m, 1);
        return psb__fail(s, PSB_ERR_SINGULAR, "dH has rank < n at (y, t), or t is no tangent there");
    }
    for (k = 0; k < n; k++) m->internal_.b[k] = p[k] / np;
    r = psb__fold_refine(m, s, yl, 0);
    /* Newton failing for the geometry's sake (no convergence, a singular system: a fault such
       as a callback's > 0 or a NaN is reported as itself), or landing far: no fold here */
    if ((r != PSB_SUCCESS && !psb__is_fatal(r) && r != PSB_ERR_CALLBACK_FAILED && r != PSB_ERR_NONFINITE) ||
        (r == PSB_SUCCESS && psb__dist_w(s, yl, m->internal_.y_try) > s->opt.h_init))
        r = psb__fail(s, PSB_ERR_INPUT, "(y, t) is not a fold: Newton at fixed mu finds none within h_init");
    if (r == PSB_SUCCESS && t_fold) r = psb_tangent(s, m->internal_.y_try, NULL, t_fold);
    if (r != PSB_SUCCESS) {
        psb__fold_keep_borders(m, 1);
        return r;
    }
    psb__copy(y_fold, m->internal_.y_try, n + 2);
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_fold_map_refine(psb_fold_map *m, psb_solver *fold_solver, double *y,
                                             int max_iter)
{
    psb_solver *s = fold_solver;
    psb_result r = psb__fold_check(m, s, "psb_fold_map_refine");
    if (r != PSB_SUCCESS) return r;
    if (!y) return psb__fail(s, PSB_ERR_NULL, "y is NULL");
    if (!psb__all_finite(y, (size_t)m->two.n + 2)) return psb__fail(s, PSB_ERR_NONFINITE, "y contains NaN or Inf");
    if (max_iter > PSB_MAX_ITER_LIMIT) return psb__fail(s, PSB_ERR_INPUT, "max_iter above PSB_MAX_ITER_LIMIT");
    psb__fold_keep_borders(m, 0);
    r = psb__fold_new_borders(m, s, y);
    if (r == PSB_SUCCESS) r = psb__fold_refine(m, s, y, max_iter);
    if (r != PSB_SUCCESS) {
        psb__fold_keep_borders(m, 1);
        return r;
    }
    psb__copy(y, m->internal_.y_try, m->two.n + 2);
    return PSB_SUCCESS;
}

/* ==== Branch counts in two parameters (psb_count_map) ===========================================
   The method: manual section 6, "Branch counts in two parameters". */

#define PSB__COUNT_STATES 6 /* the previous and current sample; bisection's low, high and trial;
                               a step on the way to a sample */

/* A nonsmooth point at one mu: (p, t) from Algorithm 2.1, the branches from Algorithm 2.2, and
   the point's velocity dp/dmu from the state it was found from (0 at the first). */
typedef struct psb__count_state {
    double mu, *p, *t, *v, *ys, *ts;
    int n_br, unbalanced;
    psb_result result;
} psb__count_state;

typedef struct psb__count_run {
    psb_solver *s;
    psb_set_mu_fn set_mu;
    void *mu_user;
    const psb_count_map_options *o;
    psb_branch_options bo;
    int max_branches;
    double approach;
    psb__count_state st[PSB__COUNT_STATES];
    double *pair[4], *next[4]; /* the followed pair (qi, ti, qj, tj) at pair_mu, and at a trial mu */
    double pair_mu;
    const double *pair_v; /* the point's velocity, which moves the pair's predictors */
    double *scratch_y, *scratch_t, *walk_from, *walk_y, *walk_t; /* approaching the point */
    psb_count_map_report *rep;
} psb__count_run;

static size_t psb__count_layout(int n, int max_branches, psb__count_run *c, void *memory)
{
    size_t np1 = (size_t)n + 1, per = (3 + 2 * (size_t)max_branches) * np1, off = 0;
    double *base = (double *)memory;
    int k;
    for (k = 0; k < PSB__COUNT_STATES; k++, off += per) {
        if (!c) continue;
        c->st[k].p = base + off;
        c->st[k].t = base + off + np1;
        c->st[k].v = base + off + 2 * np1;
        c->st[k].ys = base + off + 3 * np1;
        c->st[k].ts = base + off + (3 + (size_t)max_branches) * np1;
    }
    for (k = 0; k < 4 && c; k++) {
        c->pair[k] = base + off + (size_t)k * np1;
        c->next[k] = base + off + (4 + (size_t)k) * np1;
    }
    if (c) {
        c->scratch_y = base + off + 8 * np1;
        c->scratch_t = base + off + 9 * np1;
        c->walk_from = base + off + 10 * np1;
        c->walk_y = base + off + 11 * np1;
        c->walk_t = base + off + 12 * np1;
    }
    off += 13 * np1;
    return off * sizeof(double);
}

static void psb__count_copy(const psb__count_run *c, psb__count_state *to, const psb__count_state *from)
{
    int np1 = c->s->internal_.np1;
    to->mu = from->mu;
    to->n_br = from->n_br;
    to->unbalanced = from->unbalanced;
    to->result = from->result;
    psb__copy(to->p, from->p, np1);
    psb__copy(to->t, from->t, np1);
    psb__copy(to->v, from->v, np1);
    psb__copy(to->ys, from->ys, from->n_br * np1);
    psb__copy(to->ts, from->ts, from->n_br * np1);
}

static psb_result psb__count_set_mu(psb__count_run *c, double mu)
{
    return psb__callback_code(c->s, c->set_mu(mu, c->mu_user), "set_mu failed");
}

/* Algorithms 2.1 and 2.2 at the mu already set, from the couple (y, t) (scratch, overwritten)
   approaching the point: into `to`. With walk > 0, continuation steps first bring y along t
   next to the branch's first kink, for at most `walk`: Algorithm 2.1 moves by its h, too short
   for the distance a point moves between samples. A step that turns the tangent beyond c_diff
   crossed a kink (psb_step alone passes kinks of small turns): it is halved instead. */
static psb_result psb__count_find(psb__count_run *c, double *y, double *t, double walk,
                                  psb__count_state *to)
{
    psb_solver *s = c->s;
    psb_branch_report br;
    psb_result r = psb_correct(s, y, t, NULL);
    int np1 = s->internal_.np1, steps;
    double h = 0.25 * walk, h_end = 64 * (c->bo.h > 0 ? c->bo.h : s->opt.h_min);
    psb__copy(c->walk_from, y, np1);
    for (steps = 0; r == PSB_SUCCESS && steps < 1000 && h >= h_end; steps++) {
        double step = h;
        psb__copy(c->walk_y, y, np1);
        psb__copy(c->walk_t, t, np1);
        r = psb_step(s, c->walk_y, c->walk_t, &step);
        if (psb__is_fatal(r)) return r;
        if (r != PSB_SUCCESS || psb__cos_w(s, c->walk_t, t) < s->opt.c_diff ||
            psb__dist_w(s, c->walk_y, c->walk_from) > walk) {
            r = PSB_SUCCESS;
            h *= 0.5;
            continue;
        }
        psb__copy(y, c->walk_y, np1);
        psb__copy(t, c->walk_t, np1);
    }
    if (r == PSB_SUCCESS) r = psb_locate_end(s, y, t, &c->bo, NULL);
    if (r != PSB_SUCCESS) return r;
    c->rep->n_find++;
    r = psb_find_branches(s, y, t, &c->bo, c->max_branches, to->ys, to->ts, &br);
    if (r < 0) return r;
    psb__copy(to->p, y, s->internal_.np1);
    psb__copy(to->t, t, s->internal_.np1);
    to->n_br = br.n_branches < c->max_branches ? br.n_branches : c->max_branches;
    to->unbalanced = br.unbalanced;
    to->result = r;
    return PSB_SUCCESS;
}

/* The point at mu from the point of `from`: continuation steps and Algorithm 2.1 along the
   incoming branch, else along each other branch of `from`, from `approach` before the point
   predicted by from's velocity. PSB_SUCCESS with `to` filled, or the first candidate's failure
   (to->result too). */
static psb_result psb__count_try(psb__count_run *c, const psb__count_state *from, double mu,
                                 psb__count_state *to)
{
    psb_solver *s = c->s;
    int np1 = s->internal_.np1, j, k;
    double *y = c->scratch_y, *t = c->scratch_t;
    psb_result r = psb__count_set_mu(c, mu), first = PSB_SUCCESS;
    to->mu = mu;
    to->n_br = -1;
    to->unbalanced = 0;
    if (r != PSB_SUCCESS) return to->result = r;
    for (j = 0; j < (from->n_br > 1 ? from->n_br : 1); j++) {
        /* candidate j: branch 0 is the incoming one, arriving along from->t; the others leave
           along their ts and are walked back */
        for (k = 0; k < np1; k++) {
            double dir = j == 0 ? from->t[k] : -from->ts[(size_t)j * np1 + k];
            y[k] = from->p[k] + (mu - from->mu) * from->v[k] - c->approach * dir;
            t[k] = dir;
        }
        r = psb__count_find(c, y, t, 2 * c->approach, to);
        if (r == PSB_SUCCESS) {
            for (k = 0; k < np1; k++) to->v[k] = (to->p[k] - from->p[k]) / (mu - from->mu);
            return PSB_SUCCESS;
        }
        if (psb__is_fatal(r)) return to->result = r;
        if (j == 0) first = r;
    }
    return to->result = first;
}

/* psb__count_try, through points at mu halfway where the point moved too far to be found
   (before the first velocity is known, or where it turns): 12 halvings at most. */
static psb_result psb__count_at(psb__count_run *c, const psb__count_state *from, double mu,
                                psb__count_state *to)
{
    psb__count_state *step = &c->st[5];
    const psb__count_state *base = from;
    double target = mu;
    int halvings = 0;
    for (;;) {
        psb_result r = psb__count_try(c, base, target, to);
        if (r == PSB_SUCCESS && target == mu) return r;
        if (r == PSB_SUCCESS) {
            psb__count_copy(c, step, to);
            base = step;
            target = mu;
            continue;
        }
        if (psb__is_fatal(r) || ++halvings > 12) {
            to->mu = mu;
            return r;
        }
        target = base->mu + 0.5 * (target - base->mu);
    }
}

/* Follows the couple (q, tq) at pair_mu to mu (already set) into (qn, tn): a correction from q
   moved with the point and pushed by 1e-2 of its distance away from the other branch (along
   tq - t_other): near the merge the two lie on either side of a piece boundary closer to each
   other than the point is known (Algorithm 2.1's precision), and a predictor on the wrong side
   would land on the other's. The result must stay near the predictor (within reach, the
   tangent within 60 degrees). 1 when it did. */
static int psb__count_follow(psb__count_run *c, double mu, const double *q, const double *tq,
                             const double *t_other, double *qn, double *tn, double reach,
                             psb_result *fatal)
{
    psb_solver *s = c->s;
    int np1 = s->internal_.np1, k;
    double d = 0.01 * c->approach / fmax(psb__dist_w(s, tq, t_other), DBL_MIN);
    psb_result r;
    for (k = 0; k < np1; k++) qn[k] = q[k] + (mu - c->pair_mu) * c->pair_v[k] + d * (tq[k] - t_other[k]);
    psb__copy(c->walk_from, qn, np1);
    psb__copy(tn, tq, np1);
    r = psb_correct(s, qn, tn, NULL);
    c->rep->n_follow++;
    if (psb__is_fatal(r)) *fatal = r;
    return r == PSB_SUCCESS && psb__dist_w(s, qn, c->walk_from) <= reach && psb__cos_w(s, tn, tq) >= 0.5;
}

/* The angle between two unit tangents, accurate where it is small. */
static double psb__count_angle(const psb_solver *s, const double *a, const double *b)
{
    return 2 * asin(fmin(1, 0.5 * psb__dist_w(s, a, b)));
}

/* The followed pair at mu: its angle in *phi (0 when the two met), or -1 when a follow failed:
   past the merge. The pair moves to mu only when both followed and stayed apart. */
static psb_result psb__count_pair_at(psb__count_run *c, double mu, double reach, double *phi)
{
    psb_result fatal = PSB_SUCCESS, r = psb__count_set_mu(c, mu);
    int ok, k;
    if (r != PSB_SUCCESS) return r;
    ok = psb__count_follow(c, mu, c->pair[0], c->pair[1], c->pair[3], c->next[0], c->next[1], reach, &fatal) &&
         psb__count_follow(c, mu, c->pair[2], c->pair[3], c->pair[1], c->next[2], c->next[3], reach, &fatal);
    if (fatal != PSB_SUCCESS) return fatal;
    *phi = ok ? psb__count_angle(c->s, c->next[1], c->next[3]) : -1;
    if (*phi > 64 * DBL_EPSILON) {
        for (k = 0; k < 4; k++) psb__copy(c->pair[k], c->next[k], c->s->internal_.np1);
        c->pair_mu = mu;
    }
    return PSB_SUCCESS;
}

/* The merge of the two closest branches of `many`, gone at mu_few or else at mu_far (the
   sample beyond): the followed pair's angle driven to zero by a secant kept inside the bracket
   (halving where it leaves it), until the bracket is within the tolerance or the pair is too
   close to tell from one that met (then the secant's root). Sets change->mu, its bracket
   (the pair apart at one end, met at the other) and merge = 1; else change is untouched. */
static psb_result psb__count_merge(psb__count_run *c, const psb__count_state *many, double mu_few,
                                   double mu_far, psb_count_change *change)
{
    psb_solver *s = c->s;
    int np1 = s->internal_.np1, i, j, bi = -1, bj = -1, it, overshot;
    double best = -2, reach, mu_a, phi_a, mu_b, phi_b, mu_past, phi, tol, trust, close = 0;
    psb_result r;
    for (i = 0; i < many->n_br; i++)
        for (j = i + 1; j < many->n_br; j++) {
            double cs = psb__cos_w(s, many->ts + (size_t)i * np1, many->ts + (size_t)j * np1);
            if (cs > best) best = cs, bi = i, bj = j;
        }
    if (bi < 0) return PSB_SUCCESS;
    /* the pair taken up at `approach` from the point along the two tangents (on a ray of a
       piecewise-linear H; a correction at many->mu puts it on curved branches) */
    psb__axpy_to(c->pair[0], many->p, c->approach, many->ts + (size_t)bi * np1, np1);
    psb__copy(c->pair[1], many->ts + (size_t)bi * np1, np1);
    psb__axpy_to(c->pair[2], many->p, c->approach, many->ts + (size_t)bj * np1, np1);
    psb__copy(c->pair[3], many->ts + (size_t)bj * np1, np1);
    c->pair_mu = many->mu;
    c->pair_v = many->v;
    /* a followed point moves with the point and its branch, by much less than `approach` */
    reach = 0.5 * c->approach;
    r = psb__count_pair_at(c, many->mu, reach, &phi);
    if (r != PSB_SUCCESS || !(phi > 64 * DBL_EPSILON)) return r;
    mu_a = mu_b = many->mu;
    phi_a = phi_b = phi;
    tol = c->o->mu_tol * (1 + fabs(mu_few));
    /* the few side must be past the merge for the pair too: Algorithm 2.2 merges branches
       closer than c_diff's angle */
    for (mu_past = mu_few, it = 0; it < 2; it++, mu_past = mu_far) {
        r = psb__count_pair_at(c, mu_past, reach, &phi);
        if (r != PSB_SUCCESS) return r;
        if (phi <= 64 * DBL_EPSILON) break;
        mu_a = mu_b, phi_a = phi_b, mu_b = mu_past, phi_b = phi;
    }
    if (it == 2) return PSB_SUCCESS;
    /* a pair closer than this is not told apart from one that met: the corrector stops within
       tol_correction, and past the merge it alternates between the two pieces at distance
       approach * phi; a difference Jacobian mixes them within its steps of the boundary */
    trust = 16 * fmax(s->opt.tol_correction, psb__fd_jacobian(&s->prob) ? 4 * s->prob.fd_step : 0) /
            c->approach;
    for (it = 0, overshot = 0; it < 200 && fabs(mu_past - mu_b) > tol; it++) {
        /* after a secant step that overshot (it is now mu_past) or came too close to tell,
           the root is near: just short of it */
        double lo = fmin(mu_b, mu_past), hi = fmax(mu_b, mu_past);
        double mu_next = overshot == 2 ? mu_b + 0.9 * (close - mu_b)
                                       : mu_b + (overshot ? 0.9 : 0.5) * (mu_past - mu_b);
        int secant = 0;
        if (!overshot && phi_a != phi_b && mu_a != mu_b) {
            double root = mu_b - phi_b * (mu_b - mu_a) / (phi_b - phi_a);
            /* inside the bracket by a tenth of the tolerance, so that it shrinks */
            if (root > lo + 0.1 * tol && root < hi - 0.1 * tol) mu_next = root, secant = 1;
        }
        r = psb__count_pair_at(c, mu_next, reach, &phi);
        if (r != PSB_SUCCESS) return r;
        overshot = 0;
        if (phi >= trust) {
            mu_a = mu_b, phi_a = phi_b, mu_b = mu_next, phi_b = phi;
        } else if (phi <= 64 * DBL_EPSILON) {
            mu_past = mu_next;
            overshot = secant;
        } else if (secant && fabs(mu_b - mu_a) > 1e4 * tol) {
            close = mu_next; /* too close to tell, from a wide secant: a first guess */
            overshot = 2;
        } else { /* too close to tell: the root of the secant through the two nearest angles */
            double root = phi_a != phi_b ? mu_b - phi_b * (mu_b - mu_a) / (phi_b - phi_a) : mu_next;
            change->mu = root > lo - tol && root < hi + tol ? root : mu_next;
            break;
        }
    }
    if (it == 200) return PSB_SUCCESS;
    if (fabs(mu_past - mu_b) <= tol) change->mu = 0.5 * (mu_b + mu_past);
    change->mu_lo = fmin(mu_b, mu_past);
    change->mu_hi = fmax(mu_b, mu_past);
    change->merge = 1;
    return PSB_SUCCESS;
}

static void psb__count_swap(psb__count_state **a, psb__count_state **b)
{
    psb__count_state *x = *a;
    *a = *b;
    *b = x;
}

/* Bisects the count's change between the samples a and b (a->mu < b->mu or >), first by
   counts to 1/2^max_bisect of their distance, then by the merge, else by counts to mu_tol.
   Near a merge Algorithm 2.2 may see one branch of the pair (an odd count between an even
   pair): a count that is neither a's nor b's goes with the smaller one's side. Appends the
   change (when there is room). */
static psb_result psb__count_change(psb__count_run *c, const psb__count_state *a,
                                    const psb__count_state *b, psb_count_change *changes,
                                    int max_changes)
{
    psb__count_state *lo = &c->st[2], *hi = &c->st[3], *mid = &c->st[4];
    psb_count_change ch;
    double width = fabs(b->mu - a->mu), tol = c->o->mu_tol * (1 + fmax(fabs(a->mu), fabs(b->mu)));
    double seen_a = a->mu, seen_b = b->mu; /* nearest mu where a's, b's count was found */
    int phase, a_many = a->n_br > b->n_br;
    psb_result r;
    psb__count_copy(c, lo, a);
    psb__count_copy(c, hi, b);
    memset(&ch, 0, sizeof ch);
    for (phase = 0; phase < 2; phase++) {
        double stop = phase == 0 ? fmax(tol, width / ldexp(1.0, c->o->max_bisect)) : tol;
        while (fabs(hi->mu - lo->mu) > stop) {
            double m = 0.5 * (lo->mu + hi->mu);
            r = psb__count_at(c, lo, m, mid);
            if (r != PSB_SUCCESS && !psb__is_fatal(r)) r = psb__count_at(c, hi, m, mid);
            if (psb__is_fatal(r)) return r;
            if (r != PSB_SUCCESS) break; /* the point is lost here: the bracket stays */
            if (mid->n_br == a->n_br) seen_a = m;
            if (mid->n_br == b->n_br) seen_b = m;
            if (mid->n_br == a->n_br || (mid->n_br != b->n_br && !a_many))
                psb__count_swap(&lo, &mid);
            else
                psb__count_swap(&hi, &mid);
        }
        ch.mu = 0.5 * (lo->mu + hi->mu);
        ch.mu_lo = fmin(lo->mu, hi->mu);
        ch.mu_hi = fmax(lo->mu, hi->mu);
        if (phase == 0 && (a->n_br - b->n_br) % 2 == 0) {
            const psb__count_state *many = a_many ? lo : hi, *few = a_many ? hi : lo;
            r = psb__count_merge(c, many, few->mu, a_many ? b->mu : a->mu, &ch);
            if (r != PSB_SUCCESS) return r;
            if (ch.merge) break;
        }
    }
    /* a confirmation inside the bracket (or beyond it) does not count: the sample's own then */
    if (a->mu < b->mu ? !(seen_a <= ch.mu_lo) : !(seen_a >= ch.mu_hi)) seen_a = a->mu;
    if (a->mu < b->mu ? !(seen_b >= ch.mu_hi) : !(seen_b <= ch.mu_lo)) seen_b = b->mu;
    ch.count_lo = a->mu < b->mu ? a->n_br : b->n_br;
    ch.count_hi = a->mu < b->mu ? b->n_br : a->n_br;
    ch.mu_count_lo = a->mu < b->mu ? seen_a : seen_b;
    ch.mu_count_hi = a->mu < b->mu ? seen_b : seen_a;
    if (c->rep->n_changes < max_changes) changes[c->rep->n_changes] = ch;
    c->rep->n_changes++;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF size_t psb_count_map_memory_size(int n, int max_branches)
{
    if (n < 1 || n > 100000000 || max_branches < 2 || max_branches > 100000) return 0;
    return psb__count_layout(n, max_branches, NULL, NULL);
}

static psb_result psb__count_map(psb__count_run *c, const double *y, const double *t, double mu_from,
                                 double mu_to, psb_count_sample *samples, psb_count_change *changes,
                                 int max_changes)
{
    psb__count_state *prev = &c->st[0], *cur = &c->st[1];
    int np1 = c->s->internal_.np1, k, n = c->o->n_samples, full = 0;
    psb_result r, first_failure = PSB_SUCCESS;
    for (k = 0; k < n; k++) {
        double mu = k == n - 1 ? mu_to : mu_from + (mu_to - mu_from) * k / (n - 1);
        if (k == 0) {
            r = psb__count_set_mu(c, mu);
            psb__copy(c->scratch_y, y, np1);
            psb__copy(c->scratch_t, t, np1);
            if (r == PSB_SUCCESS) r = psb__count_find(c, c->scratch_y, c->scratch_t, 0, cur);
            memset(cur->v, 0, (size_t)np1 * sizeof(double));
            cur->mu = mu;
            if (r != PSB_SUCCESS) cur->result = r;
        } else {
            r = psb__count_at(c, prev, mu, cur);
        }
        samples[k].mu = mu;
        samples[k].result = r == PSB_SUCCESS ? cur->result : r; /* PSB_BRANCH_CAPACITY too */
        if (samples[k].result == PSB_BRANCH_CAPACITY) full = 1;
        samples[k].n_branches = r == PSB_SUCCESS ? cur->n_br : -1;
        samples[k].unbalanced = r == PSB_SUCCESS ? cur->unbalanced : 0;
        if (psb__is_fatal(r) || (k == 0 && r != PSB_SUCCESS)) return r;
        if (r != PSB_SUCCESS) { /* the next sample starts from the last one found */
            if (first_failure == PSB_SUCCESS) first_failure = r;
            continue;
        }
        if (k > 0 && cur->n_br != prev->n_br) {
            r = psb__count_change(c, prev, cur, changes, max_changes);
            if (r != PSB_SUCCESS) return r;
        }
        psb__count_swap(&prev, &cur);
    }
    if (first_failure != PSB_SUCCESS) return first_failure;
    return full || c->rep->n_changes > max_changes ? PSB_BRANCH_CAPACITY : PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_count_map(psb_solver *s, psb_set_mu_fn set_mu, void *mu_user,
                                       const double *y, const double *t, double mu_from,
                                       double mu_to, const psb_count_map_options *options,
                                       const psb_branch_options *bo, int max_branches,
                                       void *memory, size_t bytes, psb_count_sample *samples,
                                       psb_count_change *changes, int max_changes,
                                       psb_count_map_report *rep)
{
    psb__count_run c;
    psb_count_map_options o;
    psb_count_map_report local;
    psb_stats before;
    psb_result r;
    size_t need;
    memset(&local, 0, sizeof local);
    if (rep) memset(rep, 0, sizeof *rep);
    r = psb__check_couple(s, y, t);
    if (r == PSB_SUCCESS) r = psb__trace_busy(s, "psb_count_map");
    if (r != PSB_SUCCESS) return r;
    if (!set_mu || !memory || !samples || (max_changes > 0 && !changes))
        return psb__fail(s, PSB_ERR_NULL, "set_mu, memory, samples or changes is NULL");
    if (max_changes < 0 || max_branches < 2 || max_branches > 100000)
        return psb__fail(s, PSB_ERR_SIZE, "max_changes < 0, or max_branches outside 2..100000");
    if (!psb__finite(mu_from) || !psb__finite(mu_to))
        return psb__fail(s, PSB_ERR_NONFINITE, "mu_from or mu_to is NaN or Inf");
    if (mu_from == mu_to) return psb__fail(s, PSB_ERR_INPUT, "mu_from equals mu_to");
    memset(&o, 0, sizeof o);
    if (options) o = *options;
    if (o.n_samples == 0) o.n_samples = 11;
    if (o.mu_tol == 0) o.mu_tol = 1e-10;
    if (o.max_bisect == 0) o.max_bisect = 8;
    memset(&c, 0, sizeof c);
    c.bo = psb_branch_options_resolve(bo, s);
    if (o.approach == 0) o.approach = 4 * s->opt.h_init;
    if (o.n_samples < 2 || o.n_samples > 100000)
        return psb__fail(s, PSB_ERR_OPTIONS, "n_samples outside 2..100000");
    if (!(o.mu_tol >= 1e-15 && o.mu_tol <= 0.1))
        return psb__fail(s, PSB_ERR_OPTIONS, "mu_tol outside [1e-15, 0.1]");
    if (o.max_bisect < 1 || o.max_bisect > 60)
        return psb__fail(s, PSB_ERR_OPTIONS, "max_bisect outside 1..60");
    if (!(o.approach > 0 && o.approach <= 1e300))
        return psb__fail(s, PSB_ERR_OPTIONS, "approach is not positive and finite");
    need = psb_count_map_memory_size(s->prob.n, max_branches);
    if (bytes < need) return psb__fail(s, PSB_ERR_NOMEM, "memory is smaller than psb_count_map_memory_size");
    c.s = s;
    c.set_mu = set_mu;
    c.mu_user = mu_user;
    c.o = &o;
    c.max_branches = max_branches;
    c.approach = o.approach;
    c.rep = rep ? rep : &local;
    psb__count_layout(s->prob.n, max_branches, &c, memory);
    before = s->stats;
    r = psb__count_map(&c, y, t, mu_from, mu_to, samples, changes, max_changes);
    c.rep->stats = psb__stats_since(s, &before);
    return r;
}

/* ==== Event and kink curves in two parameters (psb_event_curve_*) ===============================
   [H; g_k] = 0 is a PC^1 system of n+1 equations in n+2 unknowns like any other: psb_trace
   traces it, with mu its parameter, through the kinks of H off the switching surface. */

#define PSB__EVENT_READY 0x70736563u /* psb_event_curve.internal_.ready of a set-up curve */

static size_t psb__event_layout(int n, int n_events, psb_event_curve *c, void *memory)
{
    size_t nn = (size_t)n, np2 = nn + 2, off = 0;
    double *base = (double *)memory;
    if (n < 1 || n > 46000 || n_events < 1 || n_events > 1000000) return 0;
    if (c) {
        c->internal_.g = base;
        c->internal_.y_eval = base + n_events;
        c->internal_.grad = base + n_events + np2;
        c->internal_.jac = base + n_events + 2 * np2;
        c->internal_.lu = base + n_events + 2 * np2 + nn * np2;
    }
    off = psb__align(((size_t)n_events + 2 * np2 + nn * np2 + nn * nn) * sizeof(double));
    if (c) c->internal_.ipiv = (char *)memory + off;
    return off + psb__align(nn * sizeof(psb__lint));
}

PSCBRANCH_DEF void psb_two_param_lift(const psb_two_param_problem *p, const double *y, double mu,
                                      double *full)
{
    int j, k = 0;
    if (!p || !y || !full) return;
    for (j = 0; j < p->n + 2; j++) full[j] = j == p->mu_index ? mu : y[k++];
}

/* g_k at y (n+2); 0 or the callback's code (1 for NaN/Inf). */
static int psb__event_value(psb_event_curve *c, const double *y, double *gk)
{
    int rc = c->event(y, c->internal_.g, c->event_user);
    if (rc) return rc;
    *gk = c->internal_.g[c->k];
    return psb__finite(*gk) ? 0 : 1;
}

static int psb__event_curve_residual(const double *y, double *h, void *user)
{
    psb_event_curve *c = (psb_event_curve *)user;
    int rc = c->two.residual(y, h, c->two.user);
    return rc ? rc : psb__event_value(c, y, h + c->two.n);
}

/* g_k's gradient at y by central differences into internal_.grad. */
static int psb__event_gradient(psb_event_curve *c, const double *y)
{
    int j, rc, np2 = c->two.n + 2;
    double *ye = c->internal_.y_eval, gp, gm;
    if (!(c->fd_step > 0 && c->fd_step < 1)) return 1;
    memcpy(ye, y, (size_t)np2 * sizeof *ye);
    for (j = 0; j < np2; j++) {
        double step = c->fd_step * fmax(1, fabs(y[j]));
        ye[j] = y[j] + step;
        rc = psb__event_value(c, ye, &gp);
        if (!rc) {
            ye[j] = y[j] - step;
            rc = psb__event_value(c, ye, &gm);
        }
        ye[j] = y[j];
        if (rc) return rc;
        c->internal_.grad[j] = (gp - gm) / (2 * step);
    }
    return 0;
}

static int psb__event_curve_jacobian(const double *y, double *jac, int ld, void *user)
{
    psb_event_curve *c = (psb_event_curve *)user;
    int n = c->two.n, j, rc = c->two.jacobian(y, jac, ld, c->two.user);
    if (rc || (rc = psb__event_gradient(c, y))) return rc;
    for (j = 0; j < n + 2; j++) jac[(size_t)j * (size_t)ld + (size_t)n] = c->internal_.grad[j];
    return 0;
}

PSCBRANCH_DEF size_t psb_event_curve_memory_size(int n, int n_events)
{
    return psb__event_layout(n, n_events, NULL, NULL);
}

PSCBRANCH_DEF psb_result psb_event_curve_init(psb_event_curve *c, const psb_two_param_problem *p,
                                              psb_event_fn event, int n_events, int k,
                                              void *event_user, void *memory, size_t bytes)
{
    size_t need;
    if (!c) return PSB_ERR_NULL;
    memset(c, 0, sizeof *c);
    if (!p || !event || !memory || !p->residual || !p->jacobian) return PSB_ERR_NULL;
    if (p->n < 1 || p->n > 46000 || !psb__two_param_indices_ok(p) || n_events < 1 || k < 0 || k >= n_events)
        return PSB_ERR_SIZE;
    need = psb__event_layout(p->n, n_events, NULL, NULL);
    if (!need) return PSB_ERR_SIZE;
    if (bytes < need) return PSB_ERR_NOMEM;
    c->two = *p;
    c->event = event;
    c->event_user = event_user;
    c->n_events = n_events;
    c->k = k;
    c->fd_step = 6.055454452393343e-06; /* cbrt(DBL_EPSILON): central differences */
    c->side_offset = 1e-7;
    psb__event_layout(p->n, n_events, c, memory);
    psb_problem_init(&c->curve, p->n + 1, psb__event_curve_residual, psb__event_curve_jacobian, c);
    c->curve.param_index = p->mu_index;
    c->internal_.ready = PSB__EVENT_READY;
    return PSB_SUCCESS;
}

/* sign(det A) |det A|^(1/n) of the state block of internal_.jac (n x (n+2)), by LU; 1 when it
   is not finite. */
static int psb__event_state_det(psb_event_curve *c, double *out)
{
    int n = c->two.n, j, k = 0;
    psb__lint order = n, info = 0;
    double logdet = 0;
    int sign = 1;
    for (j = 0; j < n + 2; j++)
        if (j != c->two.lambda_index && j != c->two.mu_index)
            memcpy(c->internal_.lu + (size_t)k++ * (size_t)n, c->internal_.jac + (size_t)j * (size_t)n,
                   (size_t)n * sizeof(double));
    if (!psb__all_finite(c->internal_.lu, (size_t)n * (size_t)n)) return 1;
    PSCBRANCH_FORTRAN(dgetrf)(&order, &order, c->internal_.lu, &order, (psb__lint *)c->internal_.ipiv, &info);
    if (info < 0) return 1;
    for (j = 0; j < n; j++) {
        double d = c->internal_.lu[(size_t)j * (size_t)n + (size_t)j];
        if (d == 0) {
            *out = 0;
            return 0;
        }
        if (d < 0) sign = -sign;
        if (((psb__lint *)c->internal_.ipiv)[j] != j + 1) sign = -sign;
        logdet += log(fabs(d));
    }
    *out = sign * exp(logdet / n);
    return 0;
}

PSCBRANCH_DEF int psb_event_curve_side_folds(const double *y, double *g, void *user)
{
    psb_event_curve *c = (psb_event_curve *)user;
    int n, np2, j, side, rc;
    double gnorm = 0, ynorm = 0, shift;
    if (!c || c->internal_.ready != PSB__EVENT_READY || !y || !g) return 1;
    if (!(c->side_offset > 0 && c->side_offset < 1)) return 1;
    n = c->two.n;
    np2 = n + 2;
    if ((rc = psb__event_gradient(c, y))) return rc;
    for (j = 0; j < np2; j++) {
        gnorm = fmax(gnorm, fabs(c->internal_.grad[j]));
        ynorm = fmax(ynorm, fabs(y[j]));
    }
    if (!(gnorm > 0) || !psb__finite(gnorm)) return 1;
    shift = c->side_offset * fmax(1, ynorm) / gnorm;
    /* each side's test at 1 and 2 offsets, extrapolated to the surface (2 f(d) - f(2 d)): the
       offset's O(d) error goes, the piece stays the side's */
    for (side = 0; side < 2; side++) {
        double *ye = c->internal_.y_eval, at[2];
        int m;
        for (m = 0; m < 2; m++) {
            for (j = 0; j < np2; j++) ye[j] = y[j] + (side ? 1 : -1) * (m + 1) * shift * c->internal_.grad[j];
            rc = c->two.jacobian(ye, c->internal_.jac, n, c->two.user);
            if (rc) return rc;
            if (psb__event_state_det(c, at + m)) return 1;
        }
        g[side] = 2 * at[0] - at[1];
    }
    return 0;
}

/* ==== Branch point curves in two parameters (psb_branch_curve_*) ================================
   The minimally augmented system of a corank-one rank defect of dH (Govaerts, Numerical
   Methods for Bifurcations of Dynamical Equilibria, SIAM 2000), with the unfolding beta. */

#define PSB__BP_READY 0x70736262u /* psb_branch_curve.internal_.ready of a set-up curve */

static size_t psb__bp_layout(int n, psb_branch_curve *c, void *memory)
{
    size_t nn = (size_t)n, np1 = nn + 1, np2 = nn + 2, off = 0;
    double *base = (double *)memory;
    if (n < 1 || n > 46000) return 0;
#define PSB__TAKE(field, count)                                                                    \
    do {                                                                                           \
        if (c) c->internal_.field = base + off;                                                    \
        off += (count);                                                                            \
    } while (0)
    PSB__TAKE(jac, nn * np2);
    PSB__TAKE(jac2, nn * np2);
    PSB__TAKE(mat, np2 * np2);
    PSB__TAKE(rhs, 3 * np2);
    PSB__TAKE(y_eval, np2);
    PSB__TAKE(y_pt, np2 + 1);     /* start's point, its first value, e_mu */
    PSB__TAKE(y_first, np2 + 1);
    PSB__TAKE(e_mu, np2 + 1);
    PSB__TAKE(b, 2 * nn);         /* b, then its copy while start runs */
    PSB__TAKE(c, 4 * np1);        /* C, then its copy */
#undef PSB__TAKE
    off = psb__align(off * sizeof(double));
    if (c) c->internal_.ipiv = (char *)memory + off;
    off += psb__align(np2 * sizeof(psb__lint));
    if (c) c->internal_.z_index = (int *)(void *)((char *)memory + off);
    return off + psb__align(np1 * sizeof(int));
}

/* LU of [D b; C^T 0] from jac (n x (n+2), leading dimension n). 0; 1 singular; 2 not finite. */
static int psb__bp_factor(psb_branch_curve *c, const double *jac)
{
    int n = c->two.n, np1 = n + 1, np2 = n + 2, i, k;
    psb__lint order = np2, info = 0;
    double *mat = c->internal_.mat;
    for (k = 0; k < np1; k++) {
        const double *src = jac + (size_t)c->internal_.z_index[k] * (size_t)n;
        double *dst = mat + (size_t)k * (size_t)np2;
        for (i = 0; i < n; i++) dst[i] = src[i];
        dst[n] = c->internal_.c[k];
        dst[n + 1] = c->internal_.c[(size_t)np1 + (size_t)k];
    }
    for (i = 0; i < n; i++) mat[(size_t)np1 * (size_t)np2 + (size_t)i] = c->internal_.b[i];
    mat[(size_t)np1 * (size_t)np2 + (size_t)n] = mat[(size_t)np1 * (size_t)np2 + (size_t)n + 1] = 0;
    if (!psb__all_finite(mat, (size_t)np2 * (size_t)np2)) return 2;
    PSCBRANCH_FORTRAN(dgetrf)(&order, &order, mat, &order, (psb__lint *)c->internal_.ipiv, &info);
    return info != 0;
}

/* After psb__bp_factor: rhs columns 0, 1 = [V_i; s_i] (A [V; s] = [0; I_2]), column 2 = u
   (A^T u = e_{n+2}, whose first n components w give s's gradient). 0, or 1 when not finite. */
static int psb__bp_solve(psb_branch_curve *c)
{
    int np2 = c->two.n + 2;
    psb__lint order = np2, two = 2, one = 1, info = 0;
    double *rhs = c->internal_.rhs;
    memset(rhs, 0, 3 * (size_t)np2 * sizeof *rhs);
    rhs[np2 - 2] = 1;
    rhs[(size_t)np2 + (size_t)np2 - 1] = 1;
    rhs[2 * (size_t)np2 + (size_t)np2 - 1] = 1;
    PSCBRANCH_FORTRAN(dgetrs)("N", &order, &two, c->internal_.mat, &order, (psb__lint *)c->internal_.ipiv,
                              rhs, &order, &info PSB__STRLEN_ONE);
    if (info == 0)
        PSCBRANCH_FORTRAN(dgetrs)("T", &order, &one, c->internal_.mat, &order, (psb__lint *)c->internal_.ipiv,
                                  rhs + 2 * (size_t)np2, &order, &info PSB__STRLEN_ONE);
    return info != 0 || !psb__all_finite(rhs, 3 * (size_t)np2);
}

/* The user's Jacobian at y into internal_.jac, factored with s solved: 0, the callback's code,
   or 1 (singular, not finite). */
static int psb__bp_at(psb_branch_curve *c, const double *y)
{
    int rc = c->two.jacobian(y, c->internal_.jac, c->two.n, c->two.user);
    if (rc) return rc;
    return psb__bp_factor(c, c->internal_.jac) || psb__bp_solve(c) ? 1 : 0;
}

/* psb__bp_at from the Jacobian already in the curve's jac (rows 0 .. n-1, leading dimension
   ld): the same factors without a second evaluation. */
static int psb__bp_at_jac(psb_branch_curve *c, const double *jac, int ld)
{
    int n = c->two.n, j;
    for (j = 0; j < n + 2; j++)
        memcpy(c->internal_.jac + (size_t)j * (size_t)n, jac + (size_t)j * (size_t)ld, (size_t)n * sizeof(double));
    return psb__bp_factor(c, c->internal_.jac) || psb__bp_solve(c) ? 1 : 0;
}

static int psb__bp_residual(const double *yb, double *h, void *user)
{
    psb_branch_curve *c = (psb_branch_curve *)user;
    int n = c->two.n, i, rc = c->two.residual(yb, h, c->two.user);
    if (rc) return rc;
    for (i = 0; i < n; i++) h[i] += yb[n + 2] * c->internal_.b[i];
    if ((rc = psb__bp_at(c, yb))) return rc;
    h[n] = c->internal_.rhs[n + 1];
    h[n + 1] = c->internal_.rhs[(size_t)(n + 2) + (size_t)n + 1];
    return 0;
}

static int psb__bp_jacobian(const double *yb, double *jac, int ld, void *user)
{
    psb_branch_curve *c = (psb_branch_curve *)user;
    int n = c->two.n, np2 = n + 2, i, j, k, rc = c->two.jacobian(yb, jac, ld, c->two.user);
    const double *w = c->internal_.rhs + 2 * (size_t)np2;
    double *ye = c->internal_.y_eval;
    if (rc) return rc;
    for (i = 0; i < n; i++) jac[(size_t)(n + 2) * (size_t)ld + (size_t)i] = c->internal_.b[i];
    if ((rc = psb__bp_at_jac(c, jac, ld))) return rc;
    if (!(c->fd_step > 0 && c->fd_step < 1)) return 1;
    for (i = 0; i < 2; i++) { /* row n+i: -w^T (dH(y + e V_i) - dH(y - e V_i)) / (2 e) */
        const double *v = c->internal_.rhs + (size_t)i * (size_t)np2;
        double vmax = 0, ymax = 0, e;
        for (k = 0; k <= n; k++) vmax = fmax(vmax, fabs(v[k]));
        for (j = 0; j < np2; j++) ymax = fmax(ymax, fabs(yb[j]));
        if (!(vmax > 0)) return 1;
        e = c->fd_step * fmax(1, ymax) / vmax;
        for (k = 0; k < 2; k++) {
            memcpy(ye, yb, (size_t)np2 * sizeof *ye);
            for (j = 0; j <= n; j++) ye[c->internal_.z_index[j]] += (k ? -e : e) * v[j];
            rc = c->two.jacobian(ye, k ? c->internal_.jac2 : c->internal_.jac, n, c->two.user);
            if (rc) return rc;
        }
        for (j = 0; j < np2; j++) {
            double sum = 0;
            for (k = 0; k < n; k++)
                sum += w[k] * (c->internal_.jac[(size_t)j * (size_t)n + (size_t)k] -
                               c->internal_.jac2[(size_t)j * (size_t)n + (size_t)k]);
            jac[(size_t)j * (size_t)ld + (size_t)(n + i)] = -sum / (2 * e);
        }
        jac[(size_t)(n + 2) * (size_t)ld + (size_t)(n + i)] = 0;
    }
    return 0;
}

PSCBRANCH_DEF size_t psb_branch_curve_memory_size(int n) { return psb__bp_layout(n, NULL, NULL); }

PSCBRANCH_DEF psb_result psb_branch_curve_init(psb_branch_curve *c, const psb_two_param_problem *p,
                                               void *memory, size_t bytes)
{
    int j, k = 0;
    if (!c) return PSB_ERR_NULL;
    memset(c, 0, sizeof *c);
    if (!p || !memory || !p->residual || !p->jacobian) return PSB_ERR_NULL;
    if (p->n < 1 || p->n > 46000 || !psb__two_param_indices_ok(p)) return PSB_ERR_SIZE;
    if (p->linear != PSB_LINEAR_DENSE) return PSB_ERR_OPTIONS;
    if (bytes < psb__bp_layout(p->n, NULL, NULL)) return PSB_ERR_NOMEM;
    c->two = *p;
    c->fd_step = 6.055454452393343e-06; /* cbrt(DBL_EPSILON): central differences */
    psb__bp_layout(p->n, c, memory);
    memset(c->internal_.b, 0, 2 * (size_t)p->n * sizeof(double));
    memset(c->internal_.c, 0, 4 * ((size_t)p->n + 1) * sizeof(double));
    for (j = 0; j < p->n + 2; j++)
        if (j != p->mu_index) c->internal_.z_index[k++] = j;
    c->b = c->internal_.b;
    c->c = c->internal_.c;
    psb_problem_init(&c->curve, p->n + 2, psb__bp_residual, psb__bp_jacobian, c);
    c->curve.param_index = p->mu_index;
    c->internal_.ready = PSB__BP_READY;
    return PSB_SUCCESS;
}

/* C = the two columns (a, b) made orthonormal (2-norm); 0 when they are (nearly) parallel. */
static int psb__bp_set_kernel(psb_branch_curve *c, const double *a, const double *b)
{
    int np1 = c->two.n + 1, k;
    double *c1 = c->internal_.c, *c2 = c1 + np1, na = psb__norm2(a, np1), nb, d = 0;
    if (!(na > 0)) return 0;
    for (k = 0; k < np1; k++) c1[k] = a[k] / na;
    for (k = 0; k < np1; k++) d += c1[k] * b[k];
    for (k = 0; k < np1; k++) c2[k] = b[k] - d * c1[k];
    nb = psb__norm2(c2, np1);
    if (!(nb > 1e-8 * psb__norm2(b, np1))) return 0;
    for (k = 0; k < np1; k++) c2[k] /= nb;
    return 1;
}

/* New borders at y (the user's n+2): b from u's w, C from the span of V. */
static psb_result psb__bp_borders(psb_branch_curve *c, psb_solver *s, const double *y)
{
    int n = c->two.n, np2 = n + 2, k, rc = c->two.jacobian(y, c->internal_.jac, n, c->two.user);
    double *w = c->internal_.rhs + 2 * (size_t)np2, nw;
    if (rc) return psb__callback_code(s, rc, "jacobian callback failed");
    if (!psb__all_finite(c->internal_.jac, (size_t)n * (size_t)np2))
        return psb__fail(s, PSB_ERR_NONFINITE, "the Jacobian contains NaN or Inf");
    if (psb__bp_factor(c, c->internal_.jac) || psb__bp_solve(c) || !((nw = psb__norm2(w, n)) > 0))
        return psb__fail(s, PSB_ERR_SINGULAR, "[D b; C^T 0] is singular here: no branch point of corank one");
    for (k = 0; k < n; k++) c->internal_.b[k] = w[k] / nw;
    if (!psb__bp_set_kernel(c, c->internal_.rhs, c->internal_.rhs + np2))
        return psb__fail(s, PSB_ERR_SINGULAR, "[D b; C^T 0] is singular here: no branch point of corank one");
    return PSB_SUCCESS;
}

/* Saves (restore 0) or restores (1) the borders. */
static void psb__bp_keep_borders(psb_branch_curve *c, int restore)
{
    size_t nb = (size_t)c->two.n * sizeof(double), nc = 2 * ((size_t)c->two.n + 1) * sizeof(double);
    double *b_old = c->internal_.b + c->two.n, *c_old = c->internal_.c + 2 * (c->two.n + 1);
    if (restore) {
        memcpy(c->internal_.b, b_old, nb);
        memcpy(c->internal_.c, c_old, nc);
    } else {
        memcpy(b_old, c->internal_.b, nb);
        memcpy(c_old, c->internal_.c, nc);
    }
}

PSCBRANCH_DEF psb_result psb_branch_curve_start(psb_branch_curve *c, psb_solver *curve_solver,
                                                const double *y, const double *t,
                                                const double *kernel, double mu, double *y_bp,
                                                double *t_bp)
{
    psb_solver *s = curve_solver;
    int n, np1, np2, k, pass;
    double *yb;
    unsigned long long seed = 0x70736262ull;
    psb_result r;
    if (!psb__ready(s)) return PSB_ERR_NULL;
    s->message[0] = 0;
    if (!c || c->internal_.ready != PSB__BP_READY)
        return psb__fail(s, PSB_ERR_NULL, "the branch curve is NULL or not set up (psb_branch_curve_init)");
    if (s->prob.residual != psb__bp_residual || s->prob.user != (void *)c)
        return psb__fail(s, PSB_ERR_INPUT, "psb_branch_curve_start: the solver is not one of this curve's problem");
    r = psb__trace_busy(s, "psb_branch_curve_start");
    if (r != PSB_SUCCESS) return r;
    if (!y || !t || !kernel || !y_bp) return psb__fail(s, PSB_ERR_NULL, "y, t, kernel or y_bp is NULL");
    n = c->two.n;
    np1 = n + 1;
    np2 = n + 2;
    if (!psb__all_finite(y, (size_t)np1) || !psb__all_finite(t, (size_t)np1) ||
        !psb__all_finite(kernel, (size_t)np1) || !psb__finite(mu))
        return psb__fail(s, PSB_ERR_NONFINITE, "y, t, kernel or mu contains NaN or Inf");
    psb__bp_keep_borders(c, 0);
    if (!psb__bp_set_kernel(c, t, kernel)) {
        psb__bp_keep_borders(c, 1);
        return psb__fail(s, PSB_ERR_INPUT, "t and kernel are zero or parallel");
    }
    /* a first b off range(D) (any vector not orthogonal to the left null vector); the solve
       then gives that null vector (psb__bp_borders) */
    for (k = 0; k < n; k++) c->internal_.b[k] = 0.5 + psb__unit(psb__splitmix(&seed));
    yb = c->internal_.y_pt; /* the point: the user's y, then beta = 0 */
    psb_two_param_lift(&c->two, y, mu, yb);
    yb[np2] = 0;
    psb__copy(c->internal_.y_first, yb, np2 + 1);
    r = PSB_SUCCESS;
    for (pass = 0; pass < 2 && r == PSB_SUCCESS; pass++) {
        r = psb__bp_borders(c, s, yb);
        if (r == PSB_SUCCESS) r = psb_solve_at_param(s, yb, 0);
    }
    /* Newton failing for the geometry's sake, or landing far: no branch point here */
    if ((r != PSB_SUCCESS && !psb__is_fatal(r) && r != PSB_ERR_CALLBACK_FAILED && r != PSB_ERR_NONFINITE &&
         r != PSB_ERR_SINGULAR) ||
        (r == PSB_SUCCESS && psb__dist_w(s, yb, c->internal_.y_first) > s->opt.h_init))
        r = psb__fail(s, PSB_ERR_INPUT, "(y, t, kernel) is no branch point: Newton at fixed mu finds none within h_init");
    if (r == PSB_SUCCESS && t_bp) {
        double *e = c->internal_.e_mu;
        memset(e, 0, ((size_t)np2 + 1) * sizeof(double));
        e[c->two.mu_index] = 1;
        r = psb_tangent(s, yb, e, t_bp);
    }
    if (r != PSB_SUCCESS) {
        psb__bp_keep_borders(c, 1);
        return r;
    }
    psb__copy(y_bp, yb, np2 + 1);
    return PSB_SUCCESS;
}

/* ==== Contact helpers =============================================================================
   Projections, complementarity functions and their Jacobians for frictional contact. */
/* The helpers' one exit: values are computed into locals, and copied to the caller's outputs
   (dst NULL: not asked for) only when every asked-for value is finite. So a helper never
   returns success with Inf or NaN (overflow inside gives PSB_ERR_NONFINITE), and writes no
   output when it fails. */
typedef struct psb__ct_out {
    double *dst;
    const double *src;
    int n;
} psb__ct_out;

static psb_result psb__ct_emit(const psb__ct_out *outs, int count, int *piece_dst, int piece)
{
    int i;
    for (i = 0; i < count; i++)
        if (outs[i].dst && !psb__all_finite(outs[i].src, (size_t)outs[i].n)) return PSB_ERR_NONFINITE;
    for (i = 0; i < count; i++)
        if (outs[i].dst) memmove(outs[i].dst, outs[i].src, (size_t)outs[i].n * sizeof(double));
    if (piece_dst) *piece_dst = piece;
    return PSB_SUCCESS;
}

/* Unit direction of (a, b) != 0 and its length as m nu, m = the larger magnitude (in *m), nu =
   |(a, b)| / m in [1, sqrt 2] (returned): scaled first, so that subnormal components keep their
   direction (hypot alone rounds (5e-324, -5e-324) to length 5e-324 and direction (1, -1)) and
   products with the length can be formed where the length itself overflows. */
static double psb__ct_dir2(double a, double b, double *m, double *d0, double *d1)
{
    double ua, ub, nu;
    *m = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    ua = a / *m;
    ub = b / *m;
    nu = hypot(ua, ub);
    *d0 = ua / nu;
    *d1 = ub / nu;
    return nu;
}

/* mu |x_T| for a friction coefficient mu >= 0: 0 when mu = 0, also where |x_T| overflows */
static double psb__ct_mu_times(double mu, double t) { return mu > 0.0 ? mu * t : 0.0; }
/* x_N and |x_T| for the cone's piece tests (|x_T| <= mu x_N, mu |x_T| <= -x_N), which are
   homogeneous in x: where |x_T| overflows (and mu > 0; mu = 0 tests x_N alone), both and tol are
   halved, exactly but for a subnormal x_N, which cannot decide a test beside such |x_T| */
static void psb__ct_cone_tests(const double x[3], double mu, double *n, double *t, double *tol)
{
    *n = x[0];
    *t = hypot(x[1], x[2]);
    if (*t > DBL_MAX && mu > 0.0) {
        *n = 0.5 * x[0];
        *t = hypot(0.5 * x[1], 0.5 * x[2]);
        if (tol)
            *tol *= 0.5;
    }
}
/* Shared by both half-lines: sign = +1 for [0,inf[, -1 for ]-inf,0]. */
static psb_result psb__ct_proj_half(double x, double sign, int req, double *value, double *deriv,
                                 int *piece)
{
    int pc;
    if (!value)
        return PSB_ERR_NULL;
    if (!psb__finite(x))
        return PSB_ERR_NONFINITE;
    if (req < PSB_PIECE_DEFAULT || req > PSB_HALF_OUT)
        return PSB_ERR_SIZE;
    pc = req >= 0 ? req : (sign * x >= 0.0 ? PSB_HALF_IN : PSB_HALF_OUT);
    {
        double v = pc == PSB_HALF_IN ? x : 0.0, d = pc == PSB_HALF_IN ? 1.0 : 0.0;
        psb__ct_out outs[2];
        outs[0].dst = value, outs[0].src = &v, outs[0].n = 1;
        outs[1].dst = deriv, outs[1].src = &d, outs[1].n = 1;
        return psb__ct_emit(outs, 2, piece, pc);
    }
}

PSCBRANCH_DEF psb_result psb_proj_nonpos(double x, int piece_request, double *value,
                                         double *deriv, int *piece)
{
    return psb__ct_proj_half(x, -1.0, piece_request, value, deriv, piece);
}

PSCBRANCH_DEF psb_result psb_proj_nonneg(double x, int piece_request, double *value,
                                         double *deriv, int *piece)
{
    return psb__ct_proj_half(x, 1.0, piece_request, value, deriv, piece);
}

PSCBRANCH_DEF psb_result psb_proj_half_active(double x, int nonpos, double tol, unsigned *mask)
{
    double y;
    if (!mask)
        return PSB_ERR_NULL;
    if (!psb__finite(x) || !psb__finite(tol))
        return PSB_ERR_NONFINITE;
    if (tol < 0.0)
        return PSB_ERR_INPUT;
    y = nonpos ? -x : x; /* y >= 0 <=> x in the set */
    *mask = 0u;
    if (y >= -tol)
        *mask |= 1u << PSB_HALF_IN;
    if (y <= tol)
        *mask |= 1u << PSB_HALF_OUT;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_proj_interval(double x, double a, double b, int piece_request,
                                           double *value, double d[3], int *piece)
{
    int pc;
    if (!value)
        return PSB_ERR_NULL;
    if (!psb__finite(x) || !psb__finite(a) || !psb__finite(b))
        return PSB_ERR_NONFINITE;
    if (a > b)
        return PSB_ERR_INPUT;
    if (piece_request < PSB_PIECE_DEFAULT || piece_request > PSB_IVL_UPPER)
        return PSB_ERR_SIZE;
    if (piece_request >= 0)
        pc = piece_request;
    else if (x > b)
        pc = PSB_IVL_UPPER;
    else if (x < a || a == b) /* a == b: {a} has no interior, use a constant piece */
        pc = PSB_IVL_LOWER;
    else
        pc = PSB_IVL_IN;
    {
        double v = pc == PSB_IVL_IN ? x : (pc == PSB_IVL_LOWER ? a : b), dv[3];
        psb__ct_out outs[2];
        dv[0] = pc == PSB_IVL_IN ? 1.0 : 0.0;
        dv[1] = pc == PSB_IVL_LOWER ? 1.0 : 0.0;
        dv[2] = pc == PSB_IVL_UPPER ? 1.0 : 0.0;
        outs[0].dst = value, outs[0].src = &v, outs[0].n = 1;
        outs[1].dst = d, outs[1].src = dv, outs[1].n = 3;
        return psb__ct_emit(outs, 2, piece, pc);
    }
}

PSCBRANCH_DEF psb_result psb_proj_interval_active(double x, double a, double b, double tol,
                                                  unsigned *mask)
{
    if (!mask)
        return PSB_ERR_NULL;
    if (!psb__finite(x) || !psb__finite(a) || !psb__finite(b) || !psb__finite(tol))
        return PSB_ERR_NONFINITE;
    if (a > b || tol < 0.0)
        return PSB_ERR_INPUT;
    *mask = 0u;
    if (x >= a - tol && x <= b + tol)
        *mask |= 1u << PSB_IVL_IN;
    if (x <= a + tol)
        *mask |= 1u << PSB_IVL_LOWER;
    if (x >= b - tol)
        *mask |= 1u << PSB_IVL_UPPER;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_proj_disk(const double x[2], double s, int piece_request, double p[2],
                                       double jx[4], double js[2], int *piece)
{
    double nx, d0, d1, k, pv[2], jv[4], sv[2];
    int pc;
    if (!x || !p)
        return PSB_ERR_NULL;
    if (!psb__all_finite(x, 2) || !psb__finite(s))
        return PSB_ERR_NONFINITE;
    if (piece_request < PSB_PIECE_DEFAULT || piece_request > PSB_DISK_ZERO)
        return PSB_ERR_SIZE;
    nx = hypot(x[0], x[1]);
    if (piece_request >= 0)
        pc = piece_request;
    else if (s <= 0.0)
        pc = PSB_DISK_ZERO;
    else if (nx <= s)
        pc = PSB_DISK_IN;
    else
        pc = PSB_DISK_BOUNDARY;
    if (pc == PSB_DISK_BOUNDARY) {
        /* P = s x/|x|, dP/dx = (s/|x|)(I - d d^T), dP/ds = d. At x = 0 (only a neighbour when
           s = 0) take the limit along d = e1 with s/|x| -> 0; for s > 0 use s/|x| = 1. */
        if (nx >= DBL_MIN && nx <= DBL_MAX) {
            d0 = x[0] / nx;
            d1 = x[1] / nx;
            k = s / nx;
        } else if (nx > 0.0) {
            /* |x| subnormal (s/|x| may overflow) or beyond DBL_MAX (s/|x| may not underflow):
               the direction of the scaled x, s/|x| = (s/m)/|x/m| */
            double m, nu = psb__ct_dir2(x[0], x[1], &m, &d0, &d1);
            k = s / m / nu;
        } else {
            d0 = 1.0;
            d1 = 0.0;
            k = s > 0.0 ? 1.0 : 0.0;
        }
        pv[0] = s * d0;
        pv[1] = s * d1;
        jv[0] = k * (1.0 - d0 * d0);
        jv[1] = -k * d0 * d1;
        jv[2] = jv[1];
        jv[3] = k * (1.0 - d1 * d1);
        sv[0] = d0;
        sv[1] = d1;
    } else {
        double id = pc == PSB_DISK_IN ? 1.0 : 0.0;
        pv[0] = id * x[0];
        pv[1] = id * x[1];
        jv[0] = id;
        jv[1] = 0.0;
        jv[2] = 0.0;
        jv[3] = id;
        sv[0] = sv[1] = 0.0;
    }
    {
        psb__ct_out outs[3];
        outs[0].dst = p, outs[0].src = pv, outs[0].n = 2;
        outs[1].dst = jx, outs[1].src = jv, outs[1].n = 4;
        outs[2].dst = js, outs[2].src = sv, outs[2].n = 2;
        return psb__ct_emit(outs, 3, piece, pc);
    }
}

PSCBRANCH_DEF psb_result psb_proj_disk_active(const double x[2], double s, double tol,
                                              unsigned *mask)
{
    double nx;
    if (!x || !mask)
        return PSB_ERR_NULL;
    if (!psb__all_finite(x, 2) || !psb__finite(s) || !psb__finite(tol))
        return PSB_ERR_NONFINITE;
    if (tol < 0.0)
        return PSB_ERR_INPUT;
    nx = hypot(x[0], x[1]);
    *mask = 0u;
    if (s >= -tol && nx <= s + tol) /* closure of {|x| < s} */
        *mask |= 1u << PSB_DISK_IN;
    if (s >= -tol && nx >= s - tol) /* closure of {|x| > s > 0} */
        *mask |= 1u << PSB_DISK_BOUNDARY;
    if (s <= tol) /* closure of {s < 0} */
        *mask |= 1u << PSB_DISK_ZERO;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_proj_cone(const double x[3], double mu, int piece_request,
                                       double p[3], double j[9], int *piece)
{
    double n, t, d0, d1, c, k = 0.0, w, wm, wmm, mc, mch = 0.0, pv[3], jv[9];
    int pc, a, b, scaled = 0;
    if (!x || !p)
        return PSB_ERR_NULL;
    if (!psb__all_finite(x, 3) || !psb__finite(mu))
        return PSB_ERR_NONFINITE;
    if (mu < 0.0)
        return PSB_ERR_INPUT;
    if (piece_request < PSB_PIECE_DEFAULT || piece_request > PSB_CONE_BOUNDARY)
        return PSB_ERR_SIZE;
    n = x[0];
    t = hypot(x[1], x[2]);
    if (piece_request >= 0) {
        pc = piece_request;
    } else {
        double nc, tc;
        psb__ct_cone_tests(x, mu, &nc, &tc, NULL);
        if (mu > 0.0 && nc >= 0.0 && tc <= mu * nc) /* mu = 0: IN has no interior, never the
                                                        default; n < 0: mu n may underflow to -0 */
            pc = PSB_CONE_IN;
        else if (psb__ct_mu_times(mu, tc) <= -nc)
            pc = PSB_CONE_POLAR;
        else
            pc = PSB_CONE_BOUNDARY;
    }
    if (pc == PSB_CONE_BOUNDARY) {
        /* Nearest point on the ray (1, mu d)/sqrt(1+mu^2), d = x_T/|x_T|:
           P = c (1, mu d), c = (x_N + mu |x_T|)/(1+mu^2);
           dP/dx = [[1, mu d^T], [mu d, mu^2 d d^T]]/(1+mu^2) + k [[0,0],[0, I - d d^T]],
           k = mu c/|x_T|. At x_T = 0 the formula has no limit; use d = e1 and the limit at the
           apex along x_N = 0, k = mu^2/(1+mu^2) (for mu = 0 every d-term vanishes anyway). */
        w = 1.0 / (1.0 + mu * mu);
        c = (n + mu * t) * w;
        wm = mu * w;
        wmm = mu * mu * w;
        mc = mu * c;
        if (!(t >= DBL_MIN || t == 0.0) || !psb__finite(mu * mu) || !psb__finite(mc) || fabs(c) < DBL_MIN) {
            /* extreme magnitudes: mu^2, mu |x_T| or mu c overflow, x_T is subnormal, or c
               underflows (mu c, the tangential part, may not: mu 1e150, x_T 1e-200). The
               weights 1, mu, mu^2 over 1 + mu^2 are formed without mu^2 and c, mu c as sums
               of bounded multiples of x_N and |x_T| (finite unless the projection is not) */
            double im = 1.0 / mu, m, nu;
            w = mu <= 1.0 ? 1.0 / (1.0 + mu * mu) : im / (mu + im);
            wm = mu <= 1.0 ? mu / (1.0 + mu * mu) : 1.0 / (mu + im);
            wmm = mu <= 1.0 ? mu * mu / (1.0 + mu * mu) : 1.0 / (1.0 + im * im);
            if (t > 0.0) {
                /* |x_T| = m nu, nu in [1, sqrt 2]; products with m first: |x_T| may overflow
                   where the projection does not */
                nu = psb__ct_dir2(x[1], x[2], &m, &d0, &d1);
                c = w * n + (wm * m) * nu;
                mc = wm * n + (wmm * m) * nu;
                /* |P_T| = mu c may overflow where each of P_T's components does not */
                mch = 0.5 * wm * n + (wmm * (0.5 * m)) * nu;
                k = mu > 0.0 ? wm * (n / m / nu) + wmm : 0.0; /* mu = 0: n/m may overflow */
            } else {
                c = w * n;
                mc = wm * n;
            }
            scaled = 1;
            /* the default piece has x_N + mu |x_T| > 0, so c > 0; these sums may round below 0
               where they cancel (then P is below their rounding: the apex) */
            if (piece_request < 0 && (c < 0.0 || mc < 0.0 || mch < 0.0))
                c = mc = mch = 0.0;
            /* P on its ray, |P_T| = mu P_N, though each sum carries its own rounding: the
               smaller of c, mu c from the larger (the same relative error, but a subnormal
               grid or an overflow for the one alone) */
            if (mu >= 1.0)
                c = psb__finite(mc) ? mc / mu : 2.0 * (mch / mu);
            else
                mc = mu * c;
        }
        if (t > 0.0) {
            if (!scaled) {
                d0 = x[1] / t;
                d1 = x[2] / t;
                k = mc / t;
            }
        } else {
            d0 = 1.0;
            d1 = 0.0;
            k = wmm;
        }
        pv[0] = c;
        pv[1] = psb__finite(mc) ? mc * d0 : 2.0 * (mch * d0);
        pv[2] = psb__finite(mc) ? mc * d1 : 2.0 * (mch * d1);
        {
            double dd[2];
            dd[0] = d0;
            dd[1] = d1;
            jv[0] = w;
            jv[1] = wm * d0;
            jv[2] = wm * d1;
            jv[3] = wm * d0;
            jv[6] = wm * d1;
            for (a = 0; a < 2; a++)
                for (b = 0; b < 2; b++)
                    jv[(1 + a) + 3 * (1 + b)] =
                        wmm * dd[a] * dd[b] + k * ((a == b ? 1.0 : 0.0) - dd[a] * dd[b]);
        }
    } else {
        double id = pc == PSB_CONE_IN ? 1.0 : 0.0;
        for (a = 0; a < 3; a++)
            pv[a] = id * x[a];
        for (a = 0; a < 9; a++)
            jv[a] = (a % 4 == 0) ? id : 0.0;
    }
    {
        psb__ct_out outs[2];
        outs[0].dst = p, outs[0].src = pv, outs[0].n = 3;
        outs[1].dst = j, outs[1].src = jv, outs[1].n = 9;
        return psb__ct_emit(outs, 2, piece, pc);
    }
}

PSCBRANCH_DEF psb_result psb_proj_cone_active(const double x[3], double mu, double tol,
                                              unsigned *mask)
{
    double n, t;
    if (!x || !mask)
        return PSB_ERR_NULL;
    if (!psb__all_finite(x, 3) || !psb__finite(mu) || !psb__finite(tol))
        return PSB_ERR_NONFINITE;
    if (mu < 0.0 || tol < 0.0)
        return PSB_ERR_INPUT;
    psb__ct_cone_tests(x, mu, &n, &t, &tol);
    *mask = 0u;
    /* as psb_proj_cone's default piece: n < 0 outside IN (mu n may underflow to -0) */
    if (mu > 0.0 && n >= -tol && t <= mu * n + tol)
        *mask |= 1u << PSB_CONE_IN;
    if (psb__ct_mu_times(mu, t) <= -n + tol)
        *mask |= 1u << PSB_CONE_POLAR;
    if (mu * n <= t + tol && -n <= psb__ct_mu_times(mu, t) + tol)
        *mask |= 1u << PSB_CONE_BOUNDARY;
    return PSB_SUCCESS;
}

static psb_result psb__ct_ac2d_check(double u_n, double u_t, double lam_n, double lam_t, double r,
                                  double friction, double gap)
{
    if (!psb__finite(u_n) || !psb__finite(u_t) || !psb__finite(lam_n) || !psb__finite(lam_t) ||
        !psb__finite(r) || !psb__finite(friction) || !psb__finite(gap))
        return PSB_ERR_NONFINITE;
    if (r <= 0.0 || friction < 0.0)
        return PSB_ERR_INPUT;
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_ac2d_node(double u_n, double u_t, double lam_n, double lam_t,
                                       double r, double friction, double gap, int piece_request,
                                       double res[2], double jac[8], int *piece)
{
    double xn, xt, s = 0.0, dn = 0.0, pt = 0.0, di[3] = {0.0, 0.0, 0.0}, ps, rv[2], jv[8];
    int pn = 0, pi = 0, rn = PSB_PIECE_DEFAULT, ri = PSB_PIECE_DEFAULT;
    psb_result e;
    if (!res)
        return PSB_ERR_NULL;
    e = psb__ct_ac2d_check(u_n, u_t, lam_n, lam_t, r, friction, gap);
    if (e != PSB_SUCCESS)
        return e;
    if (piece_request < PSB_PIECE_DEFAULT || piece_request > PSB_AC2D_PIECE(1, 2))
        return PSB_ERR_SIZE;
    if (piece_request >= 0) {
        rn = piece_request % 2;
        ri = piece_request / 2;
    }
    xn = lam_n - r * (u_n - gap);
    xt = lam_t - r * u_t;
    /* the only failure left is overflow of xn, xt or F s (F s <= 0 <= -F s always holds) */
    if (psb_proj_nonpos(xn, rn, &s, &dn, &pn) != PSB_SUCCESS ||
        psb_proj_interval(xt, friction * s, -friction * s, ri, &pt, di, &pi) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE;
    rv[0] = -(lam_n - s) / r;
    rv[1] = -(lam_t - pt) / r;
    ps = friction * (di[1] - di[2]) * dn; /* dP/dx_n through a = F s, b = -F s */
    jv[0] = -dn;                  /* d res0 / d u_n   */
    jv[1] = -ps;                  /* d res1 / d u_n   */
    jv[2] = 0.0;                  /* d res0 / d u_t   */
    jv[3] = -di[0];               /* d res1 / d u_t   */
    jv[4] = -(1.0 - dn) / r;      /* d res0 / d lam_n */
    jv[5] = ps / r;               /* d res1 / d lam_n */
    jv[6] = 0.0;                  /* d res0 / d lam_t */
    jv[7] = -(1.0 - di[0]) / r;   /* d res1 / d lam_t */
    {
        psb__ct_out outs[2];
        outs[0].dst = res, outs[0].src = rv, outs[0].n = 2;
        outs[1].dst = jac, outs[1].src = jv, outs[1].n = 8;
        return psb__ct_emit(outs, 2, piece, PSB_AC2D_PIECE(pn, pi));
    }
}

PSCBRANCH_DEF psb_result psb_ac2d_active(double u_n, double u_t, double lam_n, double lam_t,
                                         double r, double friction, double gap, double tol,
                                         unsigned *mask)
{
    double xn, xt, s;
    unsigned mn = 0u, mi = 0u;
    int pn, pi;
    psb_result e;
    if (!mask)
        return PSB_ERR_NULL;
    e = psb__ct_ac2d_check(u_n, u_t, lam_n, lam_t, r, friction, gap);
    if (e == PSB_SUCCESS && !psb__finite(tol))
        e = PSB_ERR_NONFINITE;
    if (e == PSB_SUCCESS && tol < 0.0)
        e = PSB_ERR_INPUT;
    if (e != PSB_SUCCESS)
        return e;
    xn = lam_n - r * (u_n - gap);
    xt = lam_t - r * u_t;
    s = xn < 0.0 ? xn : 0.0;
    if (psb_proj_half_active(xn, 1, tol, &mn) != PSB_SUCCESS ||
        psb_proj_interval_active(xt, friction * s, -friction * s, tol, &mi) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE; /* overflow */
    *mask = 0u;
    for (pn = 0; pn < 2; pn++)
        for (pi = 0; pi < 3; pi++) {
            if (!(mn & (1u << pn)) || !(mi & (1u << pi)))
                continue;
            /* the interval [F s, -F s] has an interior only where s < 0 (pn = IN) and F > 0 */
            if (pi == PSB_IVL_IN && (pn == PSB_HALF_OUT || friction == 0.0))
                continue;
            *mask |= 1u << PSB_AC2D_PIECE(pn, pi);
        }
    return PSB_SUCCESS;
}

PSCBRANCH_DEF psb_result psb_ac2d_state(double u_n, double u_t, double lam_n, double lam_t,
                                        double r, double friction, double gap,
                                        psb_contact_state *state)
{
    double xn, xt, s;
    psb_result e;
    if (!state)
        return PSB_ERR_NULL;
    e = psb__ct_ac2d_check(u_n, u_t, lam_n, lam_t, r, friction, gap);
    if (e != PSB_SUCCESS)
        return e;
    xn = lam_n - r * (u_n - gap);
    xt = lam_t - r * u_t;
    if (!psb__finite(xn) || !psb__finite(xt))
        return PSB_ERR_NONFINITE; /* overflow inside, as psb_ac2d_node */
    s = xn < 0.0 ? xn : 0.0;
    if (s == 0.0)
        *state = PSB_CONTACT_SEPARATED;
    else if (xt < friction * s)
        *state = PSB_CONTACT_SLIP_POS;
    else if (xt > -friction * s)
        *state = PSB_CONTACT_SLIP_NEG;
    else
        *state = PSB_CONTACT_STICK;
    return PSB_SUCCESS;
}

static psb_result psb__ct_fc3d_check(const double r[3], const double u[3], double mu, double rho_n,
                                  double rho_t, const double *f)
{
    if (!r || !u || !f)
        return PSB_ERR_NULL;
    if (!psb__all_finite(r, 3) || !psb__all_finite(u, 3) || !psb__finite(mu) || !psb__finite(rho_n) ||
        !psb__finite(rho_t))
        return PSB_ERR_NONFINITE;
    if (mu < 0.0 || rho_n <= 0.0 || rho_t <= 0.0)
        return PSB_ERR_INPUT;
    return PSB_SUCCESS;
}

/* Shared body of the Alart-Curnier (jm = 0) and Jean-Moreau (jm = 1) residuals. */
static psb_result psb__ct_fc3d_acjm(const double r[3], const double u[3], double mu, double rho_n,
                                 double rho_t, int jm, int req, double f[3], double jr[9],
                                 double ju[9], int *piece)
{
    double xn, pn_v = 0.0, an = 0.0, rad_arg, pr_v = 0.0, ar = 0.0, xt[2], pt[2] = {0.0, 0.0};
    double jx[4] = {0.0, 0.0, 0.0, 0.0}, js[2] = {0.0, 0.0}, fv[3], tr[9], tu[9];
    int rn = PSB_PIECE_DEFAULT, rr = PSB_PIECE_DEFAULT, rd = PSB_PIECE_DEFAULT, pn = 0, pr = 0;
    int pd = 0;
    int a, b, nmax;
    psb_result e = psb__ct_fc3d_check(r, u, mu, rho_n, rho_t, f);
    if (e != PSB_SUCCESS)
        return e;
    nmax = jm ? PSB_FC3D_JM_PIECE(1, 1, 2) : PSB_FC3D_AC_PIECE(1, 2);
    if (req < PSB_PIECE_DEFAULT || req > nmax)
        return PSB_ERR_SIZE;
    if (req >= 0) {
        rn = req % 2;
        if (jm) {
            rr = (req / 2) % 2;
            rd = req / 4;
        } else {
            rd = req / 2;
        }
    }
    xn = r[0] - rho_n * u[0];
    if (psb_proj_nonneg(xn, rn, &pn_v, &an, &pn) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE; /* overflow */
    if (jm) {
        psb_proj_nonneg(r[0], rr, &pr_v, &ar, &pr);
        rad_arg = pr_v;
    } else {
        pr_v = pn_v;
        ar = an;
        rad_arg = pn_v;
    }
    xt[0] = r[1] - rho_t * u[1];
    xt[1] = r[2] - rho_t * u[2];
    if (rd < 0) {
        /* The disk's own default at radius 0 is ZERO, but in the composite that is a B-limit only
           where the radius is identically 0 (its half-line piece OUT, or mu = 0); where the
           radius can grow (piece IN, radius exactly 0) take the neighbouring BOUNDARY piece, or
           IN at x_T = 0, so the Jacobian is a limit of the composite's own pieces. */
        int rpiece = jm ? pr : pn;
        if (rpiece == PSB_HALF_OUT || mu == 0.0)
            rd = PSB_DISK_ZERO;
        else if (rad_arg == 0.0)
            rd = (xt[0] != 0.0 || xt[1] != 0.0) ? PSB_DISK_BOUNDARY : PSB_DISK_IN;
    }
    if (psb_proj_disk(xt, mu * rad_arg, rd, pt, jr || ju ? jx : NULL, jr || ju ? js : NULL, &pd) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE; /* overflow */
    fv[0] = r[0] - pn_v;
    fv[1] = r[1] - pt[0];
    fv[2] = r[2] - pt[1];
    {
        for (a = 0; a < 9; a++)
            tr[a] = tu[a] = 0.0;
        tr[0] = 1.0 - an;
        tu[0] = an * rho_n;
        for (a = 0; a < 2; a++) {
            /* radius mu*(x_n)_+ (AC: x_n = r_N - rho_n u_N) or mu*(r_N)_+ (JM) */
            tr[1 + a] = -js[a] * mu * ar;
            tu[1 + a] = jm ? 0.0 : js[a] * mu * ar * rho_n;
            for (b = 0; b < 2; b++) {
                tr[(1 + a) + 3 * (1 + b)] = (a == b ? 1.0 : 0.0) - jx[a + 2 * b];
                tu[(1 + a) + 3 * (1 + b)] = rho_t * jx[a + 2 * b];
            }
        }
    }
    {
        psb__ct_out outs[3];
        outs[0].dst = f, outs[0].src = fv, outs[0].n = 3;
        outs[1].dst = jr, outs[1].src = tr, outs[1].n = 9;
        outs[2].dst = ju, outs[2].src = tu, outs[2].n = 9;
        return psb__ct_emit(outs, 3, piece, jm ? PSB_FC3D_JM_PIECE(pn, pr, pd) : PSB_FC3D_AC_PIECE(pn, pd));
    }
}

PSCBRANCH_DEF psb_result psb_fc3d_ac(const double r[3], const double u[3], double mu, double rho_n,
                                     double rho_t, int piece_request, double f[3], double jr[9],
                                     double ju[9], int *piece)
{
    return psb__ct_fc3d_acjm(r, u, mu, rho_n, rho_t, 0, piece_request, f, jr, ju, piece);
}

PSCBRANCH_DEF psb_result psb_fc3d_jm(const double r[3], const double u[3], double mu, double rho_n,
                                     double rho_t, int piece_request, double f[3], double jr[9],
                                     double ju[9], int *piece)
{
    return psb__ct_fc3d_acjm(r, u, mu, rho_n, rho_t, 1, piece_request, f, jr, ju, piece);
}

PSCBRANCH_DEF psb_result psb_fc3d_desaxce(const double u[3], double mu, double uhat[3], double j[9])
{
    double t, uv[3], jv[9];
    int a;
    if (!u || !uhat)
        return PSB_ERR_NULL;
    if (!psb__all_finite(u, 3) || !psb__finite(mu))
        return PSB_ERR_NONFINITE;
    if (mu < 0.0)
        return PSB_ERR_INPUT;
    t = hypot(u[1], u[2]);
    for (a = 0; a < 9; a++)
        jv[a] = (a % 4 == 0) ? 1.0 : 0.0;
    /* d|u_T|/du_T = u_T/|u_T|; at u_T = 0 the B-limit along e1 (subnormal or overflowing |u_T|:
       scaled by m = max |u_T,i|, and mu |u_T| = (mu m) |u_T/m|) */
    if (t >= DBL_MIN && t <= DBL_MAX) {
        jv[3] = mu * u[1] / t;
        jv[6] = mu * u[2] / t;
        uv[0] = u[0] + mu * t;
    } else if (t > 0.0) {
        double d0, d1, m, nu = psb__ct_dir2(u[1], u[2], &m, &d0, &d1);
        jv[3] = mu * d0;
        jv[6] = mu * d1;
        uv[0] = mu > 0.0 ? u[0] + (mu * m) * nu : u[0];
    } else {
        jv[3] = mu;
        jv[6] = 0.0;
        uv[0] = u[0];
    }
    uv[1] = u[1];
    uv[2] = u[2];
    {
        psb__ct_out outs[2];
        outs[0].dst = uhat, outs[0].src = uv, outs[0].n = 3;
        outs[1].dst = j, outs[1].src = jv, outs[1].n = 9;
        return psb__ct_emit(outs, 2, NULL, 0);
    }
}

PSCBRANCH_DEF psb_result psb_fc3d_nat(const double r[3], const double u[3], double mu, double rho,
                                      int piece_request, double f[3], double jr[9], double ju[9],
                                      int *piece)
{
    double uh[3], jh[9], z[3], p[3], jk[9], fv[3], tr[9], tu[9];
    int a, b, c, pc;
    psb_result e = psb__ct_fc3d_check(r, u, mu, rho, rho, f);
    if (e != PSB_SUCCESS)
        return e;
    if (piece_request < PSB_PIECE_DEFAULT || piece_request > PSB_CONE_BOUNDARY)
        return PSB_ERR_SIZE;
    if (psb_fc3d_desaxce(u, mu, uh, jh) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE;
    for (a = 0; a < 3; a++)
        z[a] = r[a] - rho * uh[a];
    if (psb_proj_cone(z, mu, piece_request, p, jk, &pc) != PSB_SUCCESS)
        return PSB_ERR_NONFINITE; /* overflow of z */
    for (a = 0; a < 3; a++)
        fv[a] = r[a] - p[a];
    for (a = 0; a < 9; a++)
        tr[a] = ((a % 4 == 0) ? 1.0 : 0.0) - jk[a];
    for (a = 0; a < 3; a++) /* df/du = rho J_K d uhat/du */
        for (b = 0; b < 3; b++) {
            double sum = 0.0;
            for (c = 0; c < 3; c++)
                sum += jk[a + 3 * c] * jh[c + 3 * b];
            tu[a + 3 * b] = rho * sum;
        }
    {
        psb__ct_out outs[3];
        outs[0].dst = f, outs[0].src = fv, outs[0].n = 3;
        outs[1].dst = jr, outs[1].src = tr, outs[1].n = 9;
        outs[2].dst = ju, outs[2].src = tu, outs[2].n = 9;
        return psb__ct_emit(outs, 3, piece, pc);
    }
}

PSCBRANCH_DEF psb_result psb_fc_nat_error(int dim, size_t nc, const double *r, const double *u,
                                          const double *mu, double qnorm, double *err)
{
    size_t i;
    double sum = 0.0, scale = 0.0, f[3], r3[3], u3[3];
    int k;
    psb_result e;
    if (!err || (nc > 0 && (!r || !u || !mu)))
        return PSB_ERR_NULL;
    if (dim != 2 && dim != 3)
        return PSB_ERR_SIZE;
    if (!psb__finite(qnorm))
        return PSB_ERR_NONFINITE;
    for (i = 0; i < nc; i++) {
        /* a 2D contact is the 3D one restricted to T2 = 0, which the cone projection keeps */
        r3[2] = u3[2] = 0.0;
        for (k = 0; k < dim; k++) {
            r3[k] = r[i * (size_t)dim + (size_t)k];
            u3[k] = u[i * (size_t)dim + (size_t)k];
        }
        e = psb_fc3d_nat(r3, u3, mu[i], 1.0, PSB_PIECE_DEFAULT, f, NULL, NULL, NULL);
        if (e != PSB_SUCCESS)
            return e;
        for (k = 0; k < 3; k++) { /* scaled sum of squares: no overflow for huge residuals */
            double v = fabs(f[k]);
            if (v > scale) {
                sum = 1.0 + sum * (scale / v) * (scale / v);
                scale = v;
            } else if (v > 0.0) {
                sum += (v / scale) * (v / scale);
            }
        }
    }
    {
        double e_out = scale * sqrt(sum);
        psb__ct_out out;
        if (qnorm > 0.0)
            e_out /= qnorm;
        out.dst = err, out.src = &e_out, out.n = 1;
        return psb__ct_emit(&out, 1, NULL, 0);
    }
}

PSCBRANCH_DEF psb_result psb_contact_convert(int dim, const double *force_in,
                                             const double *disp_in, double gap,
                                             double *force_out, double *disp_out)
{
    double fi[3], di[3];
    int k;
    if (!force_in || !disp_in || !force_out || !disp_out)
        return PSB_ERR_NULL;
    if (dim != 2 && dim != 3)
        return PSB_ERR_SIZE;
    if (!psb__all_finite(force_in, dim) || !psb__all_finite(disp_in, dim) || !psb__finite(gap))
        return PSB_ERR_NONFINITE;
    for (k = 0; k < dim; k++) { /* copy first: outputs may alias inputs */
        fi[k] = force_in[k];
        di[k] = disp_in[k];
    }
    for (k = 0; k < dim; k++) {
        fi[k] = -fi[k];
        di[k] = k == 0 ? gap - di[0] : -di[k];
    }
    {
        psb__ct_out outs[2];
        outs[0].dst = force_out, outs[0].src = fi, outs[0].n = dim;
        outs[1].dst = disp_out, outs[1].src = di, outs[1].n = dim;
        return psb__ct_emit(outs, 2, NULL, 0);
    }
}

#endif /* PSCBRANCH_IMPLEMENTATION_DONE */
#endif /* PSCBRANCH_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
MIT License

Copyright (c) 2026 the pscbranch authors

Permission is hereby granted, free of charge, to any person obtaining a copy of this software and
associated documentation files (the "Software"), to deal in the Software without restriction,
including without limitation the rights to use, copy, modify, merge, publish, distribute,
sublicense, and/or sell copies of the Software, and to permit persons to whom the Software is
furnished to do so, subject to the following conditions:

The above copyright notice and this permission notice shall be included in all copies or
substantial portions of the Software.

THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR IMPLIED, INCLUDING BUT
NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY, FITNESS FOR A PARTICULAR PURPOSE AND
NONINFRINGEMENT. IN NO EVENT SHALL THE AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES
OR OTHER LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN
CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------
*/
