/*
 * ocp_qp.h: helpers on the data of the stage-structured QP (ocp_qp_types.h: ocp_qp, ocp_qp_sol).
 *
 * Sign conventions of ocp_qp_sol. All multipliers of inequalities are >= 0 and the Lagrangian is
 *
 *   L = cost + sum_n pi_n' (A_n x_n + B_n u_n + b_n - x_{n+1})
 *            - lam_lbu' (u - lbu) - lam_ubu' (ubu - u) - lam_lbx' (x - lbx) - lam_ubx' (ubx - x)
 *            - sum lam_lg (D' [x(0); x(1)] + s - lg) - sum lam_ls s,
 *
 * so pi_n is the gradient of the optimal cost-to-go at x_{n+1} (the Riccati costate), and
 *
 *   u_n:  R u + S x + r + B' pi_n - lam_lbu + lam_ubu = 0
 *   x_n:  Q x + S' u + q + A' pi_n - pi_{n-1} - lam_lbx + lam_ubx - D lam_lg = 0   (no A' pi_N term)
 *   s:    Zl s + zl - lam_lg - lam_ls = 0                                          (soft rows)
 *
 * Absent bounds and rows (and hard rows' s, lam_ls, and everything of stage 0 but x_0 = x0) are 0.
 */
#ifndef OCP_QP_H
#define OCP_QP_H

#include "hm_common.h"

/* All data zero, every bound absent, no general rows. */
HM_FUNC void ocp_qp_set_zero(hm_ocp_qp *qp);

HM_FUNC void ocp_qp_sol_set_zero(hm_ocp_qp_sol *sol);

/* 0 if the data that takes part in the problem is usable, else HM_QP_NONFINITE: a NaN anywhere in
 * it, an infinity outside a bound (where it means "absent"), or ng out of 0..HM_NG. Stage-0 bounds
 * and rows, rows i >= ng_n and rows absent by lg = -HM_INF are not part of the problem and may hold
 * anything. */
HM_FUNC int ocp_qp_check(const hm_ocp_qp *qp);

/* 1 if the bound or row right-hand side takes part in the problem. */
HM_FUNC int ocp_qp_bound_present(hm_real bound);

/* sol := the certificate of the crossing bounds lb > ub of component bad (stage * (HM_NU + HM_NX) +
 * component of (u, x)): lam_lb = lam_ub = 1 / (lb - ub), everything else zero, x_0 = qp->x0. */
HM_FUNC void ocp_qp_sol_box_certificate(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, int bad);

#endif /* OCP_QP_H */
