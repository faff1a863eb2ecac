/*
 * ocp_qp.c: helpers on the data of the stage-structured QP (see ocp_qp.h): set to zero, checked
 * before a solve, and the certificate of crossing bounds. Stateless.
 */
#include "ocp_qp.h"

HM_FUNC void ocp_qp_set_zero(hm_ocp_qp *qp)
{
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_NX * HM_NX; i++) qp->Q[n][i] = HM_R(0.0);
        for (i = 0; i < HM_NX; i++) {
            qp->q[n][i] = HM_R(0.0);
            qp->lbx[n][i] = -HM_INF;
            qp->ubx[n][i] = HM_INF;
        }
        qp->ng[n] = 0;
        for (i = 0; i < HM_NG; i++) {
            for (j = 0; j < HM_NPOS; j++) qp->D[n][i][j] = HM_R(0.0);
            qp->lg[n][i] = -HM_INF;
            qp->soft[n][i] = 0;
            qp->zl[n][i] = HM_R(0.0);
            qp->Zl[n][i] = HM_R(0.0);
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX * HM_NX; i++) qp->A[n][i] = HM_R(0.0);
        for (i = 0; i < HM_NX * HM_NU; i++) {
            qp->B[n][i] = HM_R(0.0);
            qp->S[n][i] = HM_R(0.0);
        }
        for (i = 0; i < HM_NU * HM_NU; i++) qp->R[n][i] = HM_R(0.0);
        for (i = 0; i < HM_NX; i++) qp->b[n][i] = HM_R(0.0);
        for (i = 0; i < HM_NU; i++) {
            qp->r[n][i] = HM_R(0.0);
            qp->lbu[n][i] = -HM_INF;
            qp->ubu[n][i] = HM_INF;
        }
    }
    for (i = 0; i < HM_NX; i++) qp->x0[i] = HM_R(0.0);
}

HM_FUNC void ocp_qp_sol_set_zero(hm_ocp_qp_sol *sol)
{
    int n, i;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            sol->x[n][i] = HM_R(0.0);
            sol->lam_lbx[n][i] = HM_R(0.0);
            sol->lam_ubx[n][i] = HM_R(0.0);
        }
        for (i = 0; i < HM_NG; i++) {
            sol->s[n][i] = HM_R(0.0);
            sol->lam_lg[n][i] = HM_R(0.0);
            sol->lam_ls[n][i] = HM_R(0.0);
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) sol->pi[n][i] = HM_R(0.0);
        for (i = 0; i < HM_NU; i++) {
            sol->u[n][i] = HM_R(0.0);
            sol->lam_lbu[n][i] = HM_R(0.0);
            sol->lam_ubu[n][i] = HM_R(0.0);
        }
    }
}

HM_FUNC int ocp_qp_bound_present(hm_real bound)
{
    return !HM_IS_INF(bound);
}

/* 1 if all of v[0..len-1] are finite. 0 * v is 0 for a finite v and NaN for any other, and a sum
 * of those cannot overflow (a sum of the data would, on large finite data); no branch per entry and
 * four lanes, so that the loop runs in vector registers (it reads every number of every QP). */
HM_FUNC int ocp_qp_all_finite(const hm_real *v, int len)
{
    hm_real a0 = HM_R(0.0), a1 = HM_R(0.0), a2 = HM_R(0.0), a3 = HM_R(0.0);
    int i;
    for (i = 0; i + 4 <= len; i += 4) {
        a0 += v[i] * HM_R(0.0);
        a1 += v[i + 1] * HM_R(0.0);
        a2 += v[i + 2] * HM_R(0.0);
        a3 += v[i + 3] * HM_R(0.0);
    }
    for (; i < len; i++) a0 += v[i] * HM_R(0.0);
    return (a0 + a1) + (a2 + a3) == HM_R(0.0);
}

/* Bounds may be infinite (absent), never NaN. */
HM_FUNC int ocp_qp_no_nan(const hm_real *v, int len)
{
    int i, nan = 0;
    for (i = 0; i < len; i++) nan |= v[i] != v[i];
    return !nan;
}

HM_FUNC int ocp_qp_check(const hm_ocp_qp *qp)
{
    int n, i;
    if (!ocp_qp_all_finite(&qp->A[0][0], HM_N * HM_NX * HM_NX)
        || !ocp_qp_all_finite(&qp->B[0][0], HM_N * HM_NX * HM_NU)
        || !ocp_qp_all_finite(&qp->b[0][0], HM_N * HM_NX)
        || !ocp_qp_all_finite(&qp->Q[0][0], (HM_N + 1) * HM_NX * HM_NX)
        || !ocp_qp_all_finite(&qp->S[0][0], HM_N * HM_NU * HM_NX)
        || !ocp_qp_all_finite(&qp->R[0][0], HM_N * HM_NU * HM_NU)
        || !ocp_qp_all_finite(&qp->q[0][0], (HM_N + 1) * HM_NX)
        || !ocp_qp_all_finite(&qp->r[0][0], HM_N * HM_NU)
        || !ocp_qp_all_finite(qp->x0, HM_NX)
        || !ocp_qp_no_nan(&qp->lbu[0][0], HM_N * HM_NU)
        || !ocp_qp_no_nan(&qp->ubu[0][0], HM_N * HM_NU)
        || !ocp_qp_no_nan(&qp->lbx[1][0], HM_N * HM_NX)
        || !ocp_qp_no_nan(&qp->ubx[1][0], HM_N * HM_NX))
        return HM_QP_NONFINITE;
    for (n = 1; n <= HM_N; n++) {
        if (qp->ng[n] < 0 || qp->ng[n] > HM_NG) return HM_QP_NONFINITE;
        for (i = 0; i < qp->ng[n]; i++) {
            if (qp->lg[n][i] == -HM_INF) continue;   /* absent: no solver reads it (most rows of a screened QP) */
            if (!ocp_qp_all_finite(qp->D[n][i], HM_NPOS) || isnan(qp->lg[n][i])) return HM_QP_NONFINITE;
            if (qp->soft[n][i] && (!isfinite(qp->zl[n][i]) || !isfinite(qp->Zl[n][i])))
                return HM_QP_NONFINITE;
        }
    }
    return 0;
}

HM_FUNC void ocp_qp_sol_box_certificate(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, int bad)
{
    const int n = bad / (HM_NU + HM_NX);
    const int c = bad % (HM_NU + HM_NX);
    int i;
    ocp_qp_sol_set_zero(sol);
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    if (c < HM_NU) {
        const hm_real lam = HM_R(1.0) / (qp->lbu[n][c] - qp->ubu[n][c]);
        sol->lam_lbu[n][c] = lam;
        sol->lam_ubu[n][c] = lam;
    } else {
        const hm_real lam = HM_R(1.0) / (qp->lbx[n][c - HM_NU] - qp->ubx[n][c - HM_NU]);
        sol->lam_lbx[n][c - HM_NU] = lam;
        sol->lam_ubx[n][c - HM_NU] = lam;
    }
}
