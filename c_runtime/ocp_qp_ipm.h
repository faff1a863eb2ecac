/*
 * ocp_qp_ipm.h: primal-dual interior-point solver (Mehrotra predictor-corrector) for ocp_qp, with
 * Riccati-factorised Newton systems (ocp_qp_kkt.h).
 *
 * Algorithm. The QP (ocp_qp_types.h) with primal v = (u, x, s), dynamics A_E v = b_E and
 * inequalities A_I v + t = b_I, t >= 0 (multipliers z >= 0) is solved by an infeasible-start primal-dual
 * interior-point method: the iterate (v, y, z, t) with t, z > 0 follows the central path of
 *     P v + q + A_E' y + A_I' z = 0,   A_E v = b_E,   A_I v + t = b_I,   t o z = mu.
 * A soft row's slack s is the slack of its own bound s >= 0 (no second slack variable). The cost is
 * scaled by 1 / max(largest Hessian diagonal, largest gradient entry) (clipped to [1e-4, 1e4]). The
 * start is v = 0 (soft slacks just satisfying their rows, plus 1), y = 0, t = max(b_I - A_I v, 1),
 * z = 1 / t, or (arg->warm_start) the slacks and multipliers of an early iterate that the previous
 * solve kept (arg->warm_mu), floored (ocp_qp_ipm_warm.c: consecutive QPs of the real-time
 * iteration). One iteration factorises the Newton matrix once (ocp_qp_kkt.h) and solves it twice:
 * the affine predictor, and the Mehrotra corrector with centring sigma = (mu_aff / mu)^3. Both
 * target the full primal and dual residuals; the step is a fraction of the largest step that keeps
 * t, z >= 0: arg->step_frac early, rising to 1 - mu/mu_0 late (never above 1 - sqrt(eps)). The
 * weights z / t of the Newton matrix are capped (ocp_qp_ipm_setup.c) so that the Riccati recursion
 * keeps its accuracy near the solution.
 *
 * The residuals of the linear equations (dynamics, stationarity of (u, x)) follow the steps by
 * their recurrence r <- (1 - alpha) r (a Newton step solves those equations), and are evaluated
 * afresh in the first iteration and whenever a termination test could pass (arg->recurrence; 0:
 * afresh in every iteration, as a reference solve wants).
 *
 * Termination, checked at each iterate before the next factorisation:
 *   SOLVED      primal and dual residuals (inf-norms), each divided by max(1, norms of the terms it
 *               is made of), and the complementarity t' z (the duality gap, in the units of the
 *               data) in absolute terms or relative to max(1, |cost|), all below arg->tol. Then, with
 *               arg->polish, the active-set polish (ocp_qp_ipm_polish.c): the QP solved once more as an
 *               equality-constrained QP on the rows the iterate has active, kept only if its worst
 *               KKT residual (ocp_qp_res_compute) is smaller (ws->out.polished). The polish is
 *               compiled in only with HM_QP_POLISH (the tests' QP builds, ocp_qp_ipm_types.h); a
 *               generated solver never polishes and leaves its memory out.
 *   INFEASIBLE  the dual iterate is a Farkas certificate: b' w < 0 and ||A' w||_inf <=
 *               tol_infeas * (-b' w), w = (y, z), z >= 0 (as every iterate's). Then every (u, x, s)
 *               satisfying the hard constraints has ||(u, x, s)||_1 >= 1 / tol_infeas: there is none
 *               of any practical size (sound whatever the iterates did before). On an infeasible
 *               QP the method cannot reduce the primal residual, and the multipliers grow
 *               geometrically along the certificate while A' w stays bounded by the cost terms, so
 *               the test is met in a bounded number of iterations (measured on the tests' infeasible
 *               QPs: 5-14, typically 8, the same as for feasible ones). Soft rows cannot take part
 *               (their A' w entry -(z_row + z_slack) must vanish). Contradictory bounds (lb > ub)
 *               are reported before any iteration.
 *   NUMERICAL   a pivot of the Riccati recursion is not safely positive, the step is below
 *               arg->min_step, mu fell below eps^2 mu_0 (the residuals are stuck at their rounding
 *               floor above tol), or (with arg->detect_unbounded) a direction of unbounded
 *               descent was found: q' v < 0 with
 *               P v, A_E v - b_E... see ocp_qp_ipm_cert.c (ws->out.unbounded = 1; no minimiser).
 *   NONFINITE   NaN or Inf in the data (checked before any work) or in the iterates.
 *   MAX_ITER / TIMEOUT  arg->max_iter iterations done / arg->should_stop returned nonzero (polled
 *               once per iteration, before its work).
 *
 * Output. sol holds the QP solution (ocp_qp.h conventions) for SOLVED, and the last iterate for
 * MAX_ITER, TIMEOUT and NUMERICAL (not to be applied). For INFEASIBLE the primal part of sol is zero
 * but x_0 = x0, and the multipliers hold the certificate: they satisfy the stationarity conditions
 * of ocp_qp.h with every cost term (Q, S, R, q, r, zl, Zl) set to zero, are >= 0, and
 *     sum_n pi_n' c_n + lbu' lam_lbu - ubu' lam_ubu + lbx' lam_lbx - ubx' lam_ubx + lg' lam_lg = 1
 * (sums over present bounds and rows, c_0 = b_0 + A_0 x0, c_n = b_n). For NONFINITE sol is zeroed.
 * ws->out.iter, ws->out.res (ocp_qp_res_compute of sol) and the scaled measures report the solve.
 */
#ifndef OCP_QP_IPM_H
#define OCP_QP_IPM_H

#include "hm_common.h"

/* max_iter 50, tol 1e-6 (1e-4 in single precision), tol_infeas 1e-8 (1e-4), step_frac 0.99,
 * min_step 1e-8, no polish, residual recurrence, no stop hook, cold start, no iterate kept. */
HM_FUNC void ocp_qp_ipm_arg_set_default(hm_ocp_qp_ipm_arg *arg);

/* Solve qp; returns an enum hm_qp_status (also in ws->out.status). */
HM_FUNC int ocp_qp_ipm_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws,
                             const hm_ocp_qp_ipm_arg *arg);

/* One line of text for a status, "unknown QP status" for values outside enum hm_qp_status. */
HM_FUNC const char *ocp_qp_status_message(int status);

#endif /* OCP_QP_IPM_H */
