/*
 * ocp_qp_ipm_cert.h: the certificates of the interior-point method (ocp_qp_ipm_cert.c): Farkas
 * (infeasible) and a direction of unbounded descent.
 */
#ifndef OCP_QP_IPM_CERT_H
#define OCP_QP_IPM_CERT_H

#include "hm_common.h"

/* Farkas test of the last step's multiplier steps clipped at 0 (w = (dy, max(dz, 0))): b' w < 0 and
 * ||A' w||_inf <= tol_infeas * (-b' w), the candidate certificate when the multipliers diverge.
 * Returns 1 if it passes, with b' w. */
HM_FUNC int ocp_qp_ipm_farkas_step(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas,
                                   hm_real *bw_out);

/* 1 if the last step's primal direction is one of unbounded descent (tol_infeas, in the data's units). */
HM_FUNC int ocp_qp_ipm_unbounded_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas);

#endif /* OCP_QP_IPM_CERT_H */
