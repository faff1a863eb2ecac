/*
 * ocp_qp_ipm_measures.c: the exact measures of the iterate that pass A left, for the termination
 * tests: the residuals of the linear equations afresh (which resets their recurrence), the norms of
 * the stage vectors and the cost, and the norms over the inequalities. Taken in the first
 * iteration of a solve and whenever a test that ends it could pass (ocp_qp_ipm.c).
 */
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_lanes.h"
#include "ocp_qp_ipm_measures.h"
#include "ocp_qp_ipm_setup.h"

/* The rows' part of A' w at stage n > 0 (on (px, py): -d z of each row), subtracted from atw. */
HM_KERNEL void ocp_qp_ipm_rows_atw(const hm_ocp_qp_ipm_stage *restrict sn, const hm_ocp_qp_ipm_rows *restrict sr,
                                   hm_real *restrict atw)
{
    int j;
    for (j = sn->soff; j < sn->soff + sn->ns2; j++) {
        atw[HM_NU] -= sr->sd0[j] * sr->sz[j];
        atw[HM_NU + 1] -= sr->sd1[j] * sr->sz[j];
    }
    for (j = 0; j < sn->nh2; j++) {
        atw[HM_NU] -= sn->hr->hd0[j] * sn->hr->hz[j];
        atw[HM_NU + 1] -= sn->hr->hd1[j] * sn->hr->hz[j];
    }
}

/* The bound pairs' part of A' w at stage n (sign * z of each side), added to atw. */
HM_KERNEL void ocp_qp_ipm_bounds_atw(const hm_ocp_qp_ipm_bounds *restrict bd, int n, hm_real *restrict atw)
{
    int k;
    for (k = 0; k < bd->nbp; k++)
        atw[bd->bc[k]] += bd->sg[k][0][n] * bd->z[k][0][n] + bd->sg[k][1][n] * bd->z[k][1][n];
}

/* The exact stage measures of the iterate left by pass A (see ocp_qp_ipm_sums): the residuals of
 * the dynamics and of the stationarity of (u, x) evaluated afresh (the predictor's gradient ha
 * corrected by the difference to the recurred ones), the norms of A' w, P v and A_E v, and q' v,
 * v' P v. */
HM_FUNC void ocp_qp_ipm_stage_measures(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws,
                                       ocp_qp_ipm_sums *restrict sm)
{
    hm_real qv = HM_R(0.0), vPv = HM_R(0.0), atw_n = HM_R(0.0), pv_n = HM_R(0.0), aveq_n = HM_R(0.0);
    hm_real rd_eq = HM_R(0.0), rp_eq = HM_R(0.0);
    hm_real rd_v[HM_QP_NUX], pv_v[HM_QP_NUX], atw_v[HM_QP_NUX], eq_v[HM_NX], rpe_v[HM_NX];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i, k;

    for (i = 0; i < HM_QP_NUX; i++) rd_v[i] = pv_v[i] = atw_v[i] = HM_R(0.0);
    for (i = 0; i < HM_NX; i++) eq_v[i] = rpe_v[i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        const hm_real *restrict ux = sn->ux;
        hm_real Pux[HM_QP_NUX], atw[HM_QP_NUX];

        /* dynamics n - 1 -> n: x_n - A x_{n-1} - B u_{n-1} = b_{n-1} */
        if (n > 0) {
            hm_ocp_qp_ipm_stage *restrict sp = &ws->u.f.st[n - 1];
            const hm_real *restrict A = qp->A[n - 1];
            const hm_real *restrict B = qp->B[n - 1];
            const hm_real *restrict up = sp->ux;
            hm_real e[HM_NX];
            for (i = 0; i < HM_NX; i++) e[i] = ux[HM_NU + i] - B[i] * up[0] - B[i + HM_NX] * up[1];
            /* all of A, also where its first columns are e_0, e_1 (sp->a_id): the products with
             * 1 and 0 are exact, and a uniform loop keeps e in registers (the special case
             * stored half of e and reloaded it whole, a failed store forwarding per stage) */
            if (n > 1) {
                for (k = 0; k < HM_NX; k++) {
                    const hm_real xk = up[HM_NU + k];
                    for (i = 0; i < HM_NX; i++) e[i] -= A[i + k * HM_NX] * xk;
                }
            }
            for (i = 0; i < HM_NX; i++) {
                const hm_real ri = e[i] - sp->beq[i];
                sp->ry[i] = -ri;
                eq_v[i] = OCP_QP_IPM_MAX(eq_v[i], OCP_QP_IPM_ABS(e[i]));
                rpe_v[i] = OCP_QP_IPM_MAX(rpe_v[i], OCP_QP_IPM_ABS(ri));
            }
        }

        /* A' w: the dynamics, the rows, the bound pairs (sign * z of each side) */
        if (n < HM_N) {
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = sn->y;
            atw[0] = -(B[0] * y[0] + B[1] * y[1] + B[2] * y[2] + B[3] * y[3]);
            atw[1] = -(B[4] * y[0] + B[5] * y[1] + B[6] * y[2] + B[7] * y[3]);
        } else {
            atw[0] = atw[1] = HM_R(0.0);
        }
        if (n > 0) {
            const hm_real *restrict ym = ws->u.f.st[n - 1].y;
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = ym[i];
            if (n < HM_N) {
                const hm_real *restrict A = qp->A[n];
                const hm_real *restrict y = sn->y;
                for (i = 0; i < HM_NX; i++) {
                    const hm_real *restrict a = &A[i * HM_NX];
                    atw[HM_NU + i] -= (a[0] * y[0] + a[1] * y[1]) + (a[2] * y[2] + a[3] * y[3]);
                }
            }
            ocp_qp_ipm_rows_atw(sn, sr, atw);
        } else {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = HM_R(0.0);
        }
        ocp_qp_ipm_bounds_atw(bd, n, atw);

        /* stationarity of (u, x): r = P v + q + A' w */
        ocp_qp_ipm_hess_mul(qp, n, ws->cost_scale, ux, Pux);
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = Pux[i] + sn->q[i] + atw[i];
            sn->ha[i] += ri - sn->rv[i];
            sn->rv[i] = ri;
            atw_v[i] = OCP_QP_IPM_MAX(atw_v[i], OCP_QP_IPM_ABS(atw[i]));
            pv_v[i] = OCP_QP_IPM_MAX(pv_v[i], OCP_QP_IPM_ABS(Pux[i]));
            rd_v[i] = OCP_QP_IPM_MAX(rd_v[i], OCP_QP_IPM_ABS(ri));
        }
        for (i = 0; i < HM_QP_NUX; i++) {
            qv += sn->q[i] * ux[i];
            vPv += Pux[i] * ux[i];
        }
    }
    for (i = 0; i < HM_QP_NUX; i++) {
        atw_n = OCP_QP_IPM_MAX(atw_n, atw_v[i]);
        pv_n = OCP_QP_IPM_MAX(pv_n, pv_v[i]);
        rd_eq = OCP_QP_IPM_MAX(rd_eq, rd_v[i]);
    }
    for (i = 0; i < HM_NX; i++) {
        aveq_n = OCP_QP_IPM_MAX(aveq_n, eq_v[i]);
        rp_eq = OCP_QP_IPM_MAX(rp_eq, rpe_v[i]);
    }
    sm->qv = sm->qv_in + qv;
    sm->vPv = sm->vPv_in + vPv;
    sm->atw = atw_n;
    sm->pv = pv_n;
    sm->av_eq = aveq_n;
    sm->rp_eq = rp_eq;
    sm->rd_eq = rd_eq;
    sm->rp = OCP_QP_IPM_MAX(sm->rp_in, rp_eq);
    sm->rd = OCP_QP_IPM_MAX(sm->rd_in, rd_eq);
    sm->exact = 1;
}

/* ocp_qp_ipm_stage_measures at the starting point, where v = 0 and y = 0 (the cold start and the warm
 * start both begin there, and pass A's step is zero): every product with v or y vanishes, so the
 * residuals are r_y = b_E and r_v = q + A_I' z (the inequalities' multipliers alone), the norms of P v
 * and A_E v are zero, and so are q' v and v' P v. The same numbers as the general sweep (up to the
 * sign of a zero), without its products: the first iteration of every solve takes them. */
HM_FUNC void ocp_qp_ipm_stage_measures_start(hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm)
{
    hm_real atw_n = HM_R(0.0), rd_eq = HM_R(0.0), rp_eq = HM_R(0.0);
    hm_real rd_v[HM_QP_NUX], atw_v[HM_QP_NUX], rpe_v[HM_NX];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i;

    for (i = 0; i < HM_QP_NUX; i++) rd_v[i] = atw_v[i] = HM_R(0.0);
    for (i = 0; i < HM_NX; i++) rpe_v[i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        hm_real atw[HM_QP_NUX];
        /* dynamics n -> n + 1: the residual of x_{n+1} - A x_n - B u_n = b_n is -b_n */
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) {
                sn->ry[i] = sn->beq[i];
                rpe_v[i] = OCP_QP_IPM_MAX(rpe_v[i], OCP_QP_IPM_ABS(sn->beq[i]));
            }
        }
        /* A' w: the rows and the bound pairs */
        for (i = 0; i < HM_QP_NUX; i++) atw[i] = HM_R(0.0);
        if (n > 0) {
            ocp_qp_ipm_rows_atw(sn, sr, atw);
        }
        ocp_qp_ipm_bounds_atw(bd, n, atw);
        /* stationarity of (u, x): r = q + A' w */
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = sn->q[i] + atw[i];
            sn->ha[i] += ri - sn->rv[i];
            sn->rv[i] = ri;
            atw_v[i] = OCP_QP_IPM_MAX(atw_v[i], OCP_QP_IPM_ABS(atw[i]));
            rd_v[i] = OCP_QP_IPM_MAX(rd_v[i], OCP_QP_IPM_ABS(ri));
        }
    }
    for (i = 0; i < HM_QP_NUX; i++) {
        atw_n = OCP_QP_IPM_MAX(atw_n, atw_v[i]);
        rd_eq = OCP_QP_IPM_MAX(rd_eq, rd_v[i]);
    }
    for (i = 0; i < HM_NX; i++) rp_eq = OCP_QP_IPM_MAX(rp_eq, rpe_v[i]);
    sm->qv = sm->qv_in;
    sm->vPv = sm->vPv_in;
    sm->atw = atw_n;
    sm->pv = HM_R(0.0);
    sm->av_eq = HM_R(0.0);
    sm->rp_eq = rp_eq;
    sm->rd_eq = rd_eq;
    sm->rp = OCP_QP_IPM_MAX(sm->rp_in, rp_eq);
    sm->rd = OCP_QP_IPM_MAX(sm->rd_in, rd_eq);
    sm->exact = 1;
}

/* The norms over the inequalities of the iterate left by pass A (see ocp_qp_ipm_sums). */
HM_FUNC void ocp_qp_ipm_row_measures(const hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm)
{
    hm_real av = HM_R(0.0), nt = HM_R(0.0), ncr = HM_R(0.0), atw_s = HM_R(0.0), pv_s = HM_R(0.0);
    /* bound lanes: maxima per lane (as in pass A), absent sides masked to zero */
    hm_real avb[HM_QP_NNP], ntb[HM_QP_NNP], ncrb[HM_QP_NNP];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, k, l, j;
    for (n = 0; n < HM_QP_NNP; n++) avb[n] = ntb[n] = ncrb[n] = HM_R(0.0);
    for (k = 0; k < bd->nbp; k++) {
        for (l = 0; l < 2; l++)
            ocp_qp_ipm_bound_side_measures(bd->sg[k][l], bd->t[k][l], bd->z[k][l], bd->v[k], avb, ntb, ncrb);
    }
    for (n = 0; n < HM_QP_NNP; n++) {
        av = OCP_QP_IPM_MAX(av, avb[n]);
        nt = OCP_QP_IPM_MAX(nt, ntb[n]);
        ncr = OCP_QP_IPM_MAX(ncr, ncrb[n]);
    }
    /* soft rows, all at once (the padding rows masked) */
    {
        hm_real lane[5][OCP_QP_IPM_LANES];
        for (l = 0; l < OCP_QP_IPM_LANES; l++)
            lane[0][l] = lane[1][l] = lane[2][l] = lane[3][l] = lane[4][l] = HM_R(0.0);
        ocp_qp_ipm_rows_measures(sr, ocp_qp_ipm_rows_blocks(sr), lane);
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            av = OCP_QP_IPM_MAX(av, lane[0][l]);
            nt = OCP_QP_IPM_MAX(nt, lane[1][l]);
            ncr = OCP_QP_IPM_MAX(ncr, lane[2][l]);
            atw_s = OCP_QP_IPM_MAX(atw_s, lane[3][l]);
            pv_s = OCP_QP_IPM_MAX(pv_s, lane[4][l]);
        }
    }
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        const hm_real p0 = sn->ux[HM_NU], p1 = sn->ux[HM_NU + 1];
        if (n == 0) continue;
        for (j = 0; j < sn->nh; j++) {
            const hm_real t = sn->hr->ht[j], z = sn->hr->hz[j];
            av = OCP_QP_IPM_MAX(av, OCP_QP_IPM_ABS(t - (sn->hr->hd0[j] * p0 + sn->hr->hd1[j] * p1)));
            nt = OCP_QP_IPM_MAX(nt, t);
            ncr = OCP_QP_IPM_MAX(ncr, OCP_QP_IPM_MIN(t, z));
        }
    }
    sm->av_ineq = av;
    sm->nt = nt;
    sm->ncr = ncr;
    sm->atw_s = atw_s;
    sm->pv_s = pv_s;
    sm->measured = 1;
}
