/*
 * ocp_qp_ipm_common.h: what the files of the interior-point method (ocp_qp_ipm*.c) share: the
 * checks of the sizes that ocp_qp_ipm_types.h writes out, max/min without libm, the lane count of
 * the soft rows' passes, and the stage Hessian product that the stage measures, the certificates
 * and the polish inline. No state: constants and an inline kernel.
 */
#ifndef OCP_QP_IPM_COMMON_H
#define OCP_QP_IPM_COMMON_H

#include "hm_common.h"
#include "ocp_qp_kkt.h"

/* ocp_qp_ipm_types.h writes the sizes out: the padded stage count of ocp_qp_ipm_bounds must be
 * HM_QP_NNP, the length of the row list of ocp_qp_ipm_rows HM_QP_NR */
typedef char ocp_qp_ipm_nr_matches[sizeof(((hm_ocp_qp_ipm_rows *)0)->ss) == HM_QP_NR * sizeof(hm_real) ? 1 : -1];
typedef char ocp_qp_ipm_nnp_matches[sizeof(((hm_ocp_qp_ipm_bounds *)0)->v[0]) == HM_QP_NNP * sizeof(hm_real) ? 1 : -1];
/* and the bound slots and the hard-row slots per stage */
typedef char ocp_qp_ipm_nbp_matches[sizeof(((hm_ocp_qp_ipm_bounds *)0)->bc) == HM_QP_NBP ? 1 : -1];
typedef char ocp_qp_ipm_nghp_matches[sizeof(((hm_ocp_qp_ipm_hard *)0)->hrow) == HM_QP_NGHP ? 1 : -1];
typedef char ocp_qp_ipm_nhb_matches[sizeof(((hm_ocp_qp_ipm_ws *)0)->u.f.hd) == HM_QP_NHB * sizeof(hm_ocp_qp_ipm_hard)
                                    ? 1 : -1];
typedef char ocp_qp_ipm_nbp_range[HM_QP_NBP >= 1 && HM_QP_NBP <= HM_QP_NUX ? 1 : -1];
typedef char ocp_qp_ipm_ngh_range[HM_QP_NGH >= 0 && HM_QP_NGH <= HM_NG ? 1 : -1];
/* and the soft rows a QP may hold: at least one, at most every row */
typedef char ocp_qp_ipm_nrc_range[HM_QP_NRC >= 1 && HM_QP_NRC <= (HM_N + 1) * HM_NG ? 1 : -1];
typedef char ocp_qp_ipm_nrc_matches[sizeof(((hm_ocp_qp_ipm_ws *)0)->warm.srow) == HM_QP_NRC ? 1 : -1];

/* max/min without libm's calls (whose NaN rule is not needed here: NaN is caught on the sums) */
#define OCP_QP_IPM_MAX(a, b) ((a) > (b) ? (a) : (b))
#define OCP_QP_IPM_MIN(a, b) ((a) < (b) ? (a) : (b))
#define OCP_QP_IPM_ABS(a) ((a) < HM_R(0.0) ? -(a) : (a))

/* The soft rows' passes take the list eight rows at a time (ocp_qp_ipm_rows). */
#define OCP_QP_IPM_LANES 8

/* y = H_n x for the cost Hessian [R S; S' Q] of stage n on (u, x), times the cost scale c; the parts
 * absent at stage 0 (x) and stage N (u) are zero. The blocks are read from the QP, each entry times c
 * where it is used: (c * qp->R[n][i]) is the product a per-stage copy of the scaled cost would hold,
 * so the same numbers without 224 bytes a stage (double) of copies. The fallback's product
 * (ocp_qp_hsde_stage_hess_mul) scales after the sums instead: each keeps the rounding its solver's
 * iterates were made with. */
HM_KERNEL void ocp_qp_ipm_hess_mul(const hm_ocp_qp *restrict qp, int n, hm_real c, const hm_real *restrict x,
                                   hm_real *restrict y)
{
    const hm_real u0 = x[0], u1 = x[1];
    hm_real yx[HM_NX];
    int i, k;
    if (n < HM_N) {
        const hm_real *restrict R = qp->R[n];
        y[0] = (c * R[0]) * u0 + (c * R[2]) * u1;
        y[1] = (c * R[1]) * u0 + (c * R[3]) * u1;
    } else {
        y[0] = y[1] = HM_R(0.0);
    }
    if (n == 0) {
        for (i = 0; i < HM_NX; i++) y[HM_NU + i] = HM_R(0.0);
        return;
    }
    {
        const hm_real *restrict Q = qp->Q[n];
        for (i = 0; i < HM_NX; i++) yx[i] = (c * Q[i]) * x[HM_NU];
        for (k = 1; k < HM_NX; k++) {
            const hm_real xk = x[HM_NU + k];
            for (i = 0; i < HM_NX; i++) yx[i] += (c * Q[i + k * HM_NX]) * xk;
        }
    }
    if (n < HM_N) {
        const hm_real *restrict S = qp->S[n];
        for (k = 0; k < HM_NX; k++) {
            const hm_real s0 = c * S[k * HM_NU], s1 = c * S[k * HM_NU + 1];
            y[0] += s0 * x[HM_NU + k];
            y[1] += s1 * x[HM_NU + k];
            yx[k] += s0 * u0 + s1 * u1;
        }
    }
    for (i = 0; i < HM_NX; i++) y[HM_NU + i] = yx[i];
}

#endif /* OCP_QP_IPM_COMMON_H */
