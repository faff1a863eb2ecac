/*
 * ocp_qp_ipm.h: primal-dual interior-point solver (Mehrotra predictor-corrector) for ocp_qp, with
 * Riccati-factorised Newton systems (ocp_qp_kkt.h).
 *
 * Algorithm. The QP (hm_types.h) with primal v = (u, x, s), dynamics A_E v = b_E and inequality rows
 * A_I v + t = b_I, t >= 0, is solved through its homogeneous self-dual embedding (as in Clarabel,
 * Goulart & Chen 2024): unknowns (v, y, z, t, tau, kappa) with
 *     P v + A' (y, z) + q tau = 0,   A v + (0, t) = b tau,   kappa = -v' P v / tau - q' v - b' (y, z),
 *     z, t, tau, kappa >= 0 and complementary.
 * The cost is scaled by 1 / max(largest Hessian diagonal, largest gradient entry) (clipped to
 * [1e-4, 1e4]) so that tau and kappa balance cost against constraints whatever the units.
 * One iteration factorises the Newton matrix once (ocp_qp_kkt_factorize) and solves it three times:
 * a constant right-hand side (for the tau direction), the affine predictor, and the Mehrotra
 * corrector with centring sigma = (1 - alpha_affine)^3. The step is a fraction of the largest step
 * that keeps t, z, tau, kappa >= 0: arg->step_frac early, rising to 1 - mu/mu_0 late (never above
 * 1 - sqrt(eps)). The row weights z / t of the Newton matrix are capped (ocp_qp_ipm.c) so that the
 * Riccati recursion keeps its accuracy near the solution. The start is Clarabel's: one solve with
 * unit row weights for (-q, b), t and z shifted into the positive orthant, tau = kappa = 1.
 *
 * Termination, checked at each iterate before the next factorisation:
 *   SOLVED      kappa <= tau, and with the QP point v / tau: primal and dual residuals (inf-norms),
 *               each divided by max(1, norms of the terms it is made of), and the complementarity
 *               t' z / tau^2 (the duality gap) in absolute terms or relative to max(1, |cost|), all
 *               below arg->tol. Then, with arg->polish, the active-set polish (ocp_qp_ipm.c): the QP
 *               solved once more as an equality-constrained QP on the rows the iterate has active,
 *               kept only if its worst KKT residual (ocp_qp_res_compute) is smaller (ws->polished).
 *   INFEASIBLE  kappa > tau and the dual iterate is a Farkas certificate: b' w < 0 and
 *               ||A' w||_inf <= tol_infeas * (-b' w), w = (y, z), z >= 0. Then every (u, x, s)
 *               satisfying the hard constraints has ||(u, x, s)||_1 >= 1 / tol_infeas: there is none
 *               of any practical size. Soft rows cannot take part (their z is forced to 0). The
 *               embedding drives tau -> 0 on infeasible problems at the rate it converges on feasible
 *               ones, so the certificate appears in a bounded number of iterations (measured: 7-28,
 *               typically 15). Contradictory bounds (lb > ub) are reported before any iteration.
 *   NUMERICAL   a pivot of the Riccati recursion is not safely positive, the step is below
 *               arg->min_step, mu fell below eps^2 mu_0 (the residuals are stuck at their rounding
 *               floor above tol), or a direction of unbounded descent was found (kappa > tau,
 *               q' v < 0 with P v, A_E v and A_I v + t small: ws->unbounded = 1; no minimiser).
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
 * ws->iter, ws->res (ocp_qp_res_compute of sol) and the scaled measures report the solve.
 */
#ifndef OCP_QP_IPM_H
#define OCP_QP_IPM_H

#include "hm_common.h"

/* Inequality rows of one stage at most, and of the whole QP. */
#define HM_QP_NC_STAGE (2 * (HM_NU + HM_NX) + 2 * HM_NG)
#define HM_QP_NC_MAX ((HM_N + 1) * HM_QP_NC_STAGE)

/* max_iter 50, tol 1e-6 (1e-4 in single precision), tol_infeas 1e-8 (1e-4), step_frac 0.99,
 * min_step 1e-8, no polish, no stop hook. */
HM_FUNC void ocp_qp_ipm_arg_set_default(hm_ocp_qp_ipm_arg *arg);

/* Solve qp; returns an enum hm_qp_status (also in ws->status). */
HM_FUNC int ocp_qp_ipm_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws,
                             const hm_ocp_qp_ipm_arg *arg);

/* One line of text for a status, "unknown QP status" for values outside enum hm_qp_status. */
HM_FUNC const char *ocp_qp_status_message(int status);

#endif /* OCP_QP_IPM_H */
