/*
 * ocp_qp_ipm_measures.h: the exact measures of an iterate for the termination tests
 * (ocp_qp_ipm_measures.c), completing pass A's ocp_qp_ipm_sums.
 */
#ifndef OCP_QP_IPM_MEASURES_H
#define OCP_QP_IPM_MEASURES_H

#include "ocp_qp_ipm_pass_a.h"

/* The residuals of the dynamics and of the stationarity of (u, x) afresh (the predictor's gradient
 * corrected), the norms of A' w, P v and A_E v, q' v and v' P v: sm->exact = 1. */
HM_FUNC void ocp_qp_ipm_stage_measures(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws,
                                       ocp_qp_ipm_sums *restrict sm);

/* The same at the starting point (v = 0, y = 0), without the products that vanish there. */
HM_FUNC void ocp_qp_ipm_stage_measures_start(hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm);

/* The norms over the inequalities: sm->measured = 1. */
HM_FUNC void ocp_qp_ipm_row_measures(const hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm);

#endif /* OCP_QP_IPM_MEASURES_H */
