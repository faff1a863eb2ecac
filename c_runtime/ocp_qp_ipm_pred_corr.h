/*
 * ocp_qp_ipm_pred_corr.h: passes B to E of an interior-point iteration (ocp_qp_ipm_pred_corr.c): the
 * factorisation, the predictor and the corrector.
 */
#ifndef OCP_QP_IPM_PRED_CORR_H
#define OCP_QP_IPM_PRED_CORR_H

#include "ocp_qp_ipm_common.h"

/* Scalars of the predictor's forward pass. */
typedef struct {
    hm_real ratio;    /* max of -dt / t and -dz / z: the step to the boundary is 1 / max(1, ratio) */
    hm_real tdz;      /* sum t dz + z dt */
    hm_real dtdz;     /* sum dt dz */
} ocp_qp_ipm_pred;

/* Pass B: factorisation and the predictor's backward substitution; 0 or HM_QP_NUMERICAL. */
HM_FUNC int ocp_qp_ipm_pass_b(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws);

/* Pass C: the predictor's forward substitution and inequality steps; its scalars into *pr. */
HM_FUNC void ocp_qp_ipm_pass_c(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws,
                               ocp_qp_ipm_pred *restrict pr);

/* Pass D: the corrector's backward substitution for the target smu and second-order weight kdel. */
HM_FUNC void ocp_qp_ipm_pass_d(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws, hm_real smu,
                               hm_real kdel);

/* Pass E: the corrector's forward substitution and inequality steps; the largest ratio -dt / t, -dz / z. */
HM_FUNC hm_real ocp_qp_ipm_pass_e(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws, hm_real smu,
                                  hm_real kdel);

#endif /* OCP_QP_IPM_PRED_CORR_H */
