/*
 * ocp_qp_ipm_lanes.h: the inequality families' loops of passes A, C and E and of the termination
 * measures (ocp_qp_ipm_lanes.c), over all stages or all soft rows at once, in vector lanes.
 */
#ifndef OCP_QP_IPM_LANES_H
#define OCP_QP_IPM_LANES_H

#include "ocp_qp_ipm_common.h"

/* One side of one bound slot over all HM_QP_NNP stages (ocp_qp_ipm_bounds). */
HM_FUNC void ocp_qp_ipm_bound_side_a(hm_real alpha, hm_real wmax, const hm_real *restrict sg,
                                     const hm_real *restrict b, const hm_real *restrict v,
                                     const hm_real *restrict dt, const hm_real *restrict dz, hm_real *restrict t,
                                     hm_real *restrict z, hm_real *restrict w, hm_real *restrict ti,
                                     hm_real *restrict zi, hm_real *restrict rho,
                                     hm_real *restrict Hd, hm_real *restrict hf, hm_real *restrict hmu,
                                     hm_real *restrict tz, hm_real *restrict bw, hm_real *restrict rp);
HM_FUNC void ocp_qp_ipm_bound_side_c(const hm_real *restrict sg, const hm_real *restrict t,
                                     const hm_real *restrict z, const hm_real *restrict w,
                                     const hm_real *restrict ti, const hm_real *restrict zi,
                                     const hm_real *restrict rho, const hm_real *restrict dv,
                                     hm_real *restrict del, hm_real *restrict hdl, hm_real *restrict ratio,
                                     hm_real *restrict tdz, hm_real *restrict dtdz);
HM_FUNC void ocp_qp_ipm_bound_side_e(hm_real smu, hm_real kdel, const hm_real *restrict sg,
                                     const hm_real *restrict t, const hm_real *restrict z,
                                     const hm_real *restrict w, const hm_real *restrict ti,
                                     const hm_real *restrict zi, const hm_real *restrict rho,
                                     const hm_real *restrict del, const hm_real *restrict dv, hm_real *restrict dt,
                                     hm_real *restrict dz, hm_real *restrict ratio);
HM_FUNC void ocp_qp_ipm_bound_side_measures(const hm_real *restrict sg, const hm_real *restrict t,
                                            const hm_real *restrict z, const hm_real *restrict v,
                                            hm_real *restrict av, hm_real *restrict nt, hm_real *restrict ncr);

/* The soft-row list (ocp_qp_ipm_rows), nrp rows (ocp_qp_ipm_rows_blocks), OCP_QP_IPM_LANES at a time. */
HM_FUNC void ocp_qp_ipm_rows_a(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real alpha, hm_real wmax,
                               hm_real (*restrict lane)[OCP_QP_IPM_LANES]);
HM_FUNC void ocp_qp_ipm_rows_c(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real wmax,
                               hm_real (*restrict lane)[OCP_QP_IPM_LANES]);
HM_FUNC void ocp_qp_ipm_rows_e(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real wmax, hm_real smu, hm_real kdel,
                               hm_real *restrict lane);
HM_FUNC void ocp_qp_ipm_rows_measures(const hm_ocp_qp_ipm_rows *restrict sr, int nrp,
                                      hm_real (*restrict lane)[OCP_QP_IPM_LANES]);

#endif /* OCP_QP_IPM_LANES_H */
