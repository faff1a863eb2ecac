/*
 * ocp_qp_hsde_setup.h: the set-up of a fallback solve (ocp_qp_hsde_setup.c).
 */
#ifndef OCP_QP_HSDE_SETUP_H
#define OCP_QP_HSDE_SETUP_H

#include "hm_common.h"

/* Packs the present inequality rows and computes the data of the embedding and its norms. Returns
 * HM_QP_INFEASIBLE if a lower bound exceeds its upper bound (*bad = stage * HM_QP_NUX + component),
 * HM_QP_NONFINITE if a stage bounds more components than the solver was sized for (HM_QP_NBP). */
HM_FUNC int ocp_qp_hsde_setup(const hm_ocp_qp *qp, hm_ocp_qp_hsde_ws *ws, int *bad);

#endif /* OCP_QP_HSDE_SETUP_H */
