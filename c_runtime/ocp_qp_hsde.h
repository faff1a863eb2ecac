/*
 * ocp_qp_hsde.h: the fallback solver of ocp_qp_ipm_solve: an interior-point method on the homogeneous
 * self-dual embedding of the QP (as in Clarabel, Goulart & Chen 2024), three Riccati solves per
 * iteration. Slower than ocp_qp_ipm's primal-dual method, but it certifies infeasibility and
 * unboundedness robustly, including in single precision: ocp_qp_ipm_solve hands a QP over to it
 * when its own iteration stalls (ocp_qp_ipm.h).
 *
 * Algorithm. The QP with primal v = (u, x, s), dynamics A_E v = b_E and packed inequality rows
 * A_I v + t = b_I, t >= 0, is solved through its embedding: unknowns (v, y, z, t, tau, kappa) with
 *     P v + A' (y, z) + q tau = 0,   A v + (0, t) = b tau,   kappa = -v' P v / tau - q' v - b' (y, z),
 *     z, t, tau, kappa >= 0 and complementary.
 * The cost is scaled as in ocp_qp_ipm. One iteration factorises the Newton matrix once and solves it
 * three times: a constant right-hand side (for the tau direction), the affine predictor, and the
 * Mehrotra corrector with centring sigma = (1 - alpha_affine)^3. The start is Clarabel's: one solve
 * with unit row weights for (-q, b), t and z shifted into the positive orthant, tau = kappa = 1.
 *
 * Termination as in ocp_qp_ipm.h with the QP point v / tau, SOLVED only with kappa <= tau; with
 * kappa > tau, INFEASIBLE when (y, z) is a Farkas certificate (b' w < 0, ||A' w|| <= tol_infeas
 * (-b' w)), NUMERICAL with ws->out.unbounded when v is a direction of unbounded descent (q' v < 0 with
 * P v, A_E v and A_I v + t small against it). The embedding drives tau -> 0 on infeasible problems
 * at the rate it converges on feasible ones, so the certificate appears in a bounded number of
 * iterations (measured: 7-28, typically 15).
 */
#ifndef OCP_QP_HSDE_H
#define OCP_QP_HSDE_H

#include "hm_common.h"
#include "ocp_qp_kkt.h"

/* Inequality rows of one stage at most (both sides of the components that may be bounded,
 * HM_QP_NBP of ocp_qp_kkt.h), and of the whole QP. */
#define HM_QP_HSDE_NC_STAGE (2 * HM_QP_NBP + 2 * HM_NG)
/* General rows of the whole QP at most: the soft ones (HM_QP_NRC) and a stage's hard ones (HM_QP_NGH)
 * in every stage, never more than every row; and the inequality rows in all (with the s >= 0 of the
 * soft rows). */
#define HM_QP_HSDE_NGR HM_QP_MIN_((HM_N + 1) * HM_NG, HM_QP_NRC + (HM_N + 1) * HM_QP_NGH)
#define HM_QP_HSDE_NC_MAX ((HM_N + 1) * 2 * HM_QP_NBP + HM_QP_HSDE_NGR + HM_QP_NRC)

/* Solve qp from scratch; returns an enum hm_qp_status (also in ws->out.status); ws->out.iter iterations. */
HM_FUNC int ocp_qp_hsde_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws,
                              const hm_ocp_qp_ipm_arg *arg);

#endif /* OCP_QP_HSDE_H */
