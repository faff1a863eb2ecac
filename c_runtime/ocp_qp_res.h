/*
 * ocp_qp_res.h: the KKT residuals of a primal-dual pair of the stage-structured QP (ocp_qp_res.c),
 * in the sign conventions of ocp_qp.h.
 */
#ifndef OCP_QP_RES_H
#define OCP_QP_RES_H

#include "hm_common.h"

/* Residuals of the KKT conditions of (qp, sol) in the conventions of ocp_qp.h (ocp_qp_types.h:
 * ocp_qp_res). */
HM_FUNC void ocp_qp_res_compute(const hm_ocp_qp *qp, const hm_ocp_qp_sol *sol, hm_ocp_qp_res *res);

/* The same at the zero step (u = 0, x_n = 0 for n >= 1, x_0 = qp->x0: the linearisation point of an
 * SQP), each soft row with the slack it needs there, max(0, lg), and sol's multipliers; sol's u, x and
 * s are not read. What ocp_qp_res_compute gives for that point, without its products with zeros. */
HM_FUNC void ocp_qp_res_at_zero_step(const hm_ocp_qp *qp, const hm_ocp_qp_sol *sol, hm_ocp_qp_res *res);

/* The worst of the residuals, the measure by which a polished solution must improve. */
HM_FUNC hm_real ocp_qp_res_worst(const hm_ocp_qp_res *res);

#endif /* OCP_QP_RES_H */
