/*
 * ocp_qp_ipm_setup.h: the set-up of an interior-point solve (ocp_qp_ipm_setup.c): the inequality
 * families, the scaled cost and its norms, and the cold starting point, built afresh by every solve.
 */
#ifndef OCP_QP_IPM_SETUP_H
#define OCP_QP_IPM_SETUP_H

#include "hm_common.h"

/* Rows of the soft-row list rounded up to whole blocks of lanes (OCP_QP_IPM_LANES): the extent of
 * every pass over the list. */
HM_FUNC int ocp_qp_ipm_rows_blocks(const hm_ocp_qp_ipm_rows *sr);

/* Builds the stage blocks of qp and the starting point. Returns HM_QP_INFEASIBLE if a lower bound
 * exceeds its upper bound (*bad = stage * HM_QP_NUX + component), HM_QP_NONFINITE if the QP has more
 * bounded components or hard rows in a stage than the solver was sized for (HM_QP_NBP, HM_QP_NGH). */
HM_FUNC int ocp_qp_ipm_setup(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, int *bad);

#endif /* OCP_QP_IPM_SETUP_H */
