/*
 * ocp_qp_hsde_common.h: what the files of the fallback solver (ocp_qp_hsde*.c) share: max without
 * libm, the row weights of the Newton matrix, the checks of the sizes its types write out. No state.
 */
#ifndef OCP_QP_HSDE_COMMON_H
#define OCP_QP_HSDE_COMMON_H

#include "hm_common.h"
#include "ocp_qp_hsde.h"

/* ocp_qp_hsde_types.h writes the sizes out: its packed rows must be HM_QP_HSDE_NGR and HM_QP_HSDE_NC_MAX */
typedef char ocp_qp_hsde_ngr_matches[sizeof(((hm_ocp_qp_hsde_ws *)0)->row_idx) == HM_QP_HSDE_NGR ? 1 : -1];
typedef char ocp_qp_hsde_nc_matches[sizeof(((hm_ocp_qp_hsde_ws *)0)->t) == HM_QP_HSDE_NC_MAX * sizeof(hm_real) ? 1 : -1];
typedef char ocp_qp_hsde_nrc_matches[sizeof(((hm_ocp_qp_hsde_ws *)0)->soft_of) == HM_QP_NRC ? 1 : -1];

/* max without libm's fmax call (whose NaN rule is not needed here: NaN is caught on the sums) */
#define OCP_QP_HSDE_MAX(a, b) ((a) > (b) ? (a) : (b))

/* A row's weight of the Newton matrix at (t, z): w = min(z / t, w_max), with 1 / w and 1 / z, one
 * division. The residuals keep w (ws->w, which the polish sets otherwise too); the tau pivot and the
 * directions derive 1 / w and 1 / z again from the same t and z, the same values without an array
 * each. */
typedef struct {
    hm_real w, winv, zinv;
} ocp_qp_hsde_row_weight;

HM_KERNEL ocp_qp_hsde_row_weight ocp_qp_hsde_weight(hm_real tj, hm_real zj, hm_real w_max)
{
    ocp_qp_hsde_row_weight r;
    const hm_real inv = HM_R(1.0) / (tj * zj);
    const hm_real wj = zj * zj * inv;
    r.zinv = tj * inv;
    if (wj < w_max) {
        r.w = wj;
        r.winv = tj * tj * inv;
    } else {
        r.w = w_max;
        r.winv = HM_R(1.0) / w_max;
    }
    return r;
}

#endif /* OCP_QP_HSDE_COMMON_H */
