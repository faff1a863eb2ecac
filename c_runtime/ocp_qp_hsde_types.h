/*
 * ocp_qp_hsde_types.h: the sized types of the fallback solver (ocp_qp_hsde.h): a vector in its
 * layout and its workspace, which every fallback solve fills from scratch.
 * No include guard: instantiated once per solver under the HM_NS / HM_REAL / HM_N / HM_NG contract of
 * hm_types.h, which includes it.
 */
#include "hm_common.h"

/* Inequality rows of one stage at most: both sides of each component of (u, x) that may be bounded
 * (HM_NBP, default all six: ocp_qp_ipm_types.h); general rows of the whole QP at most: the soft ones
 * up to the solver's capacity (HM_NRC, default every row) and HM_NGH hard ones a stage (default
 * HM_NG), never more than every row; and the inequality rows of the whole QP (bound sides, general
 * rows, s >= 0 of the soft ones). Written out (no include guard) as HM_QP_HSDE_NGR and
 * HM_QP_HSDE_NC_MAX of ocp_qp_hsde.h. */
#ifdef HM_NBP
#define HM_TYPES_HSDE_NB_ (2 * (HM_NBP))
#else
#define HM_TYPES_HSDE_NB_ (2 * (HM_NU + HM_NX))
#endif
#ifdef HM_NRC
#define HM_TYPES_HSDE_NRC_ (HM_NRC)
#else
#define HM_TYPES_HSDE_NRC_ ((HM_N + 1) * HM_NG)
#endif
#ifdef HM_NGH
#define HM_TYPES_HSDE_NGH_ (HM_NGH)
#else
#define HM_TYPES_HSDE_NGH_ HM_NG
#endif
#define HM_TYPES_HSDE_NGR_                                                                              \
    ((HM_N + 1) * HM_NG < HM_TYPES_HSDE_NRC_ + (HM_N + 1) * HM_TYPES_HSDE_NGH_                             \
         ? (HM_N + 1) * HM_NG                                                                             \
         : HM_TYPES_HSDE_NRC_ + (HM_N + 1) * HM_TYPES_HSDE_NGH_)
#define HM_TYPES_HSDE_NC_ ((HM_N + 1) * HM_TYPES_HSDE_NB_ + HM_TYPES_HSDE_NGR_ + HM_TYPES_HSDE_NRC_)

/* The variables of the embedding that live in the QP's shape: per stage (u, x) (u of stage HM_N and
 * x of stage 0 unused), slacks s[roff[n] + k] of the k-th general row of stage n if it is soft,
 * multipliers y of the dynamics and z of the packed inequality rows. Used for the iterate, the step,
 * the residuals and a constant solve. */
typedef struct HM_NS(ocp_qp_hsde_vec) {
    HM_REAL ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL s[HM_TYPES_HSDE_NGR_];
    HM_REAL y[HM_N][HM_NX];
    HM_REAL z[HM_TYPES_HSDE_NC_];
} HM_NS(ocp_qp_hsde_vec);

/* The fallback solver (ocp_qp_hsde.h): inequality rows (present bounds, general rows, s >= 0 of
 * soft rows) packed stage after stage into flat arrays. */
typedef struct HM_NS(ocp_qp_hsde_ws) {
    HM_NS(ocp_qp_outcome) out;        /* of the last solve */
    HM_REAL tau, kappa;               /* of the last iterate */

    /* packed inequality rows of stage n from off[n]: nb[n] bounds, nr[n] general rows, ns[n] rows
     * s >= 0 of the soft ones among them; m rows in all. The general rows of all stages are packed
     * too, stage n's from roff[n], and its soft ones from soff[n]. */
    int m;
    int off[HM_N + 1];
    int nb[HM_N + 1];
    int nr[HM_N + 1];
    int ns[HM_N + 1];
    int roff[HM_N + 1];
    int soff[HM_N + 1];
    unsigned char box_comp[HM_N + 1][HM_TYPES_HSDE_NB_];   /* component of (u, x) */
    HM_REAL box_sign[HM_N + 1][HM_TYPES_HSDE_NB_];          /* +1 upper bound, -1 lower bound */
    unsigned char row_idx[HM_TYPES_HSDE_NGR_];   /* QP row i of the k-th general row */
    unsigned char soft_of[HM_TYPES_HSDE_NRC_];   /* k of the j-th soft row */
    HM_REAL D[HM_TYPES_HSDE_NGR_][HM_NPOS];        /* D of the k-th general row */
    HM_REAL soft_Zl[HM_TYPES_HSDE_NRC_];         /* Zl of the j-th soft row, times cost_scale */
    /* the data of the embedding: cost gradient q and right-hand sides b (dynamics, inequality rows),
     * with the terms of the fixed x_0 moved into stage 0 */
    HM_REAL q_ux[HM_N + 1][HM_NU + HM_NX];
    HM_REAL q_s[HM_TYPES_HSDE_NGR_];
    HM_REAL b_eq[HM_N][HM_NX];
    HM_REAL b_ineq[HM_TYPES_HSDE_NC_];
    HM_REAL norm_q, norm_b;
    HM_REAL cost_scale;               /* the cost is solved scaled by this */
    HM_REAL w_max;                    /* cap of the row weights */

    /* iterate (v, t, tau, kappa), step, constant solve, residuals */
    HM_NS(ocp_qp_hsde_vec) v, dv, v1, rv;
    HM_REAL t[HM_TYPES_HSDE_NC_];
    HM_REAL dt[HM_TYPES_HSDE_NC_];
    HM_REAL dtau, dkappa, rtau;
    HM_REAL c_ux[HM_N + 1][HM_NU + HM_NX];   /* q + 2 P v / tau, the tau row of the Newton system */
    HM_REAL c_s[HM_TYPES_HSDE_NGR_];
    HM_REAL ds[HM_TYPES_HSDE_NC_];   /* complementarity target */

    /* Newton system: row weights z / t, stage-wise eliminated soft slacks, Riccati */
    HM_REAL w[HM_TYPES_HSDE_NC_];
    HM_REAL soft_hinv[HM_TYPES_HSDE_NRC_];     /* of the j-th soft row: 1 / (Zl + w_row + w_slack) */
    HM_REAL soft_e[HM_TYPES_HSDE_NRC_];        /* per solve: its slack step at a zero position step */
    HM_REAL P[HM_N + 1][HM_NX * HM_NX];     /* cost-to-go Hessians */
    HM_REAL p[HM_N + 1][HM_NX];             /* cost-to-go gradients, per solve */
    HM_REAL Lr[HM_N][3];                    /* Cholesky factor of the reduced input Hessian:
                                               1 / l00, l10, 1 / l11 */
    HM_REAL Y[HM_N][HM_NU * HM_NX];         /* Lr^-1 (S + B' P A) */
    HM_REAL yk[HM_N][HM_NU];                /* per solve: Lr^-1 (reduced input gradient) */
} HM_NS(ocp_qp_hsde_ws);

#undef HM_TYPES_HSDE_NC_
#undef HM_TYPES_HSDE_NB_
#undef HM_TYPES_HSDE_NRC_
#undef HM_TYPES_HSDE_NGH_
#undef HM_TYPES_HSDE_NGR_
