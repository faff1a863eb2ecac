/*
 * ocp_qp_ipm_warm.h: the warm start of the interior-point method (ocp_qp_ipm_warm.c).
 */
#ifndef OCP_QP_IPM_WARM_H
#define OCP_QP_IPM_WARM_H

#include "hm_common.h"

/* Keep the iterate of pass A in ws->warm (multipliers unscaled: the next QP's scale may differ). */
HM_FUNC void ocp_qp_ipm_warm_keep(hm_ocp_qp_ipm_ws *ws);

/* Overwrite the cold start (ocp_qp_ipm_setup) with the kept iterate: stage n from kept stage
 * n + shift (the last stage from itself), wherever the kept stage has the same inequality. */
HM_FUNC void ocp_qp_ipm_warm_apply(hm_ocp_qp_ipm_ws *ws, int shift);

#endif /* OCP_QP_IPM_WARM_H */
