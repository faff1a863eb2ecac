/*
 * ocp_qp_hsde_res.h: the residuals of the fallback solver's embedding (ocp_qp_hsde_res.c) and the
 * record of their scalars, which the solve loop tests.
 */
#ifndef OCP_QP_HSDE_RES_H
#define OCP_QP_HSDE_RES_H

#include "hm_common.h"

/* Scalars of one residual evaluation. */
typedef struct {
    hm_real qv, bw, vPv, tz;          /* q' v, b' w, v' P v, t' z */
    hm_real atw, pv, av_eq, av_ineq;  /* inf-norms of A' w, P v, A_E v, A_I v + t */
    hm_real rd, rp;                   /* inf-norms of the dual and primal residuals */
    hm_real nv, nw, nt;               /* inf-norms of v, w, t */
} ocp_qp_hsde_sums;

/* y = c H_n x for the cost Hessian [R S'; S Q] of stage n on (u, x) and the cost scale c; parts
 * absent at stage 0 (x) and stage N (u) are zero in y and ignored in x. */
HM_FUNC void ocp_qp_hsde_stage_hess_mul(const hm_ocp_qp *restrict qp, int n, hm_real c, const hm_real *restrict x,
                                       hm_real *restrict y);

/* Residuals of the embedding at the point (v, t, tau, ws->kappa) into ws->rv:
 *   rv.ux, rv.s = P v + A' w + q tau,   rv.y = A_E v - b_E tau,   rv.z = A_I v + t - b_I tau,
 *   rtau = kappa + q' v + b' w + v' P v / tau,
 * the vector c = q + 2 P v / tau of the tau row, and the scalars of the termination tests. With
 * weights, also the row weights of the Newton matrix at this point (ws->w). */
HM_FUNC void ocp_qp_hsde_residuals(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws,
                                  const hm_ocp_qp_hsde_vec *restrict v, const hm_real *restrict t, hm_real tau,
                                  int weights, ocp_qp_hsde_sums *restrict sm);

#endif /* OCP_QP_HSDE_RES_H */
