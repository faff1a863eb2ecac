/*
 * ocp_qp_ipm_cert.h: the certificates of the interior-point method (ocp_qp_ipm_cert.c): Farkas
 * (infeasible) and a direction of unbounded descent.
 */
#ifndef OCP_QP_IPM_CERT_H
#define OCP_QP_IPM_CERT_H

#include "hm_common.h"

/* Farkas test of the dual part w = (y, z) of a vector in the solver's layout: b' w < 0 and
 * ||A' w||_inf <= tol_infeas * (-b' w) (z >= 0 is the caller's). Returns 1 if it passes, with b' w. */
HM_FUNC int ocp_qp_ipm_farkas(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_vec *w,
                              hm_real tol_infeas, hm_real *bw_out);

/* 1 if the last step's primal direction is one of unbounded descent (tol_infeas, in the data's units). */
HM_FUNC int ocp_qp_ipm_unbounded_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas);

/* The last step's multiplier steps, clipped at 0, into ws->u.f.va (primal part zero): the candidate
 * certificate of ocp_qp_ipm_farkas when the multipliers diverge. */
HM_FUNC void ocp_qp_ipm_ray_from_step(hm_ocp_qp_ipm_ws *ws);

#endif /* OCP_QP_IPM_CERT_H */
