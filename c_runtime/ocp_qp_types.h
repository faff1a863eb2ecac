/*
 * ocp_qp_types.h: the sized types of the stage-structured QP: its data (ocp_qp), a primal-dual pair
 * (ocp_qp_sol) and that pair's residuals (ocp_qp_res). Filled by the SQP's linearisation, read by
 * the QP solvers and ocp_qp.c.
 * No include guard: instantiated once per solver under the HM_NS / HM_REAL / HM_N / HM_NG contract of
 * hm_types.h, which includes it.
 */
#include "hm_common.h"

/* ------------------------------------------------------------------------------------------------
 * ocp_qp: the stage-structured QP solved at every SQP iteration.
 *
 *   minimise  sum_{n=0}^{N-1} [ 1/2 x_n' Q_n x_n + u_n' S_n x_n + 1/2 u_n' R_n u_n + q_n' x_n + r_n' u_n ]
 *             + 1/2 x_N' Q_N x_N + q_N' x_N
 *             + sum_{n=1}^{N} sum_{i<ng_n, soft} [ zl_{n,i} s_{n,i} + 1/2 Zl_{n,i} s_{n,i}^2 ]
 *   subject to
 *     x_0 = x0                                              (the initial state is fixed)
 *     x_{n+1} = A_n x_n + B_n u_n + b_n                     n = 0..N-1
 *     lbu_n <= u_n <= ubu_n                                 n = 0..N-1 (per component)
 *     lbx_n <= x_n <= ubx_n                                 n = 1..N   (per component)
 *     D_{n,i}' [x_n(0); x_n(1)] + s_{n,i} >= lg_{n,i}       n = 1..N, i < ng_n
 *     s_{n,i} >= 0                                          soft rows; s_{n,i} = 0 for hard rows
 *
 * A bound with magnitude >= HM_INF is absent. Rows i >= ng_n are absent and cost nothing: that is
 * how humans who are not present drop out. Row i is soft iff soft_{n,i} != 0. Stage-0 state bounds
 * and rows are ignored (x_0 is fixed).
 * ---------------------------------------------------------------------------------------------- */
typedef struct HM_NS(ocp_qp) {
    HM_REAL A[HM_N][HM_NX * HM_NX];
    HM_REAL B[HM_N][HM_NX * HM_NU];
    HM_REAL b[HM_N][HM_NX];
    HM_REAL Q[HM_N + 1][HM_NX * HM_NX];
    HM_REAL S[HM_N][HM_NU * HM_NX];
    HM_REAL R[HM_N][HM_NU * HM_NU];
    HM_REAL q[HM_N + 1][HM_NX];
    HM_REAL r[HM_N][HM_NU];
    HM_REAL x0[HM_NX];
    HM_REAL lbx[HM_N + 1][HM_NX];
    HM_REAL ubx[HM_N + 1][HM_NX];
    HM_REAL lbu[HM_N][HM_NU];
    HM_REAL ubu[HM_N][HM_NU];
    int ng[HM_N + 1];
    HM_REAL D[HM_N + 1][HM_NG][HM_NPOS];
    HM_REAL lg[HM_N + 1][HM_NG];
    int soft[HM_N + 1][HM_NG];
    HM_REAL zl[HM_N + 1][HM_NG];
    HM_REAL Zl[HM_N + 1][HM_NG];
} HM_NS(ocp_qp);

/* ocp_qp_sol: primal and dual solution of an ocp_qp (sign conventions in ocp_qp.h). */
typedef struct HM_NS(ocp_qp_sol) {
    HM_REAL x[HM_N + 1][HM_NX];
    HM_REAL u[HM_N][HM_NU];
    HM_REAL s[HM_N + 1][HM_NG];
    HM_REAL pi[HM_N][HM_NX];
    HM_REAL lam_lbx[HM_N + 1][HM_NX];
    HM_REAL lam_ubx[HM_N + 1][HM_NX];
    HM_REAL lam_lbu[HM_N][HM_NU];
    HM_REAL lam_ubu[HM_N][HM_NU];
    HM_REAL lam_lg[HM_N + 1][HM_NG];
    HM_REAL lam_ls[HM_N + 1][HM_NG];
} HM_NS(ocp_qp_sol);

/* Residuals of a primal-dual pair (ocp_qp_res_compute), infinity norms in the units of the data. */
typedef struct HM_NS(ocp_qp_res) {
    HM_REAL stat;    /* gradient of the Lagrangian with respect to u, x and s */
    HM_REAL eq;      /* dynamics */
    HM_REAL ineq;    /* largest violation of a bound, a row (hard or with its slack) or of s >= 0 */
    HM_REAL comp;    /* largest |multiplier * constraint value| */
    HM_REAL dual;    /* largest violation of multiplier >= 0 */
    HM_REAL obj;     /* objective, including the constant terms of the fixed x_0 */
} HM_NS(ocp_qp_res);
