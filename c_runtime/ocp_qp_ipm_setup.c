/*
 * ocp_qp_ipm_setup.c: the set-up of an interior-point solve: from the QP data, the bound pairs, the
 * soft and the hard rows of every stage, the scaled cost, the norms of the data and the cold
 * starting point (the warm start, ocp_qp_ipm_warm.c, overwrites the last). Run once per solve,
 * before the first iteration.
 */
#include "ocp_qp.h"
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_setup.h"

/* Cap of the weights z / t, relative to the curvature of the cost. Near the solution the weights
 * of active rows grow like 1 / mu; condensed into the Riccati recursion, whose Schur complements
 * subtract them again, they leave rounding errors of eps * weight in the moderate directions, and
 * beyond ~1e-6 / eps the cost-to-go matrices lose definiteness and the steps go wrong. Capping the
 * weight makes the Newton step slightly inexact on active rows only; that error shrinks with the
 * step itself, so convergence is kept. In single precision 1e6 (not 1e-6 / eps = 1e1): a tighter
 * cap makes the steps on active rows so inexact that RTI replays took 25-50 iterations (MAX_ITER
 * in one step out of 20) against 12-23 at 1e6, which matches the double build's counts. */
#ifdef HM_REAL_IS_FLOAT
#define OCP_QP_IPM_W_MAX_REL HM_R(1e6)
#else
#define OCP_QP_IPM_W_MAX_REL HM_R(1e10)
#endif

/* ------------------------------------------------------------------------------------------------
 * Setup: the families, the scaled cost, the norms, the starting point
 * ---------------------------------------------------------------------------------------------- */

/* The bounds of component i of (u, x) at stage n (n <= HM_N); 0 if the stage has no such component
 * (u at stage HM_N, x at stage 0: not part of the problem). */
HM_FUNC int ocp_qp_ipm_bounds_of(const hm_ocp_qp *qp, int n, int i, hm_real *lb, hm_real *ub)
{
    if (i < HM_NU) {
        if (n == HM_N) return 0;
        *lb = qp->lbu[n][i];
        *ub = qp->ubu[n][i];
    } else {
        if (n == 0) return 0;
        *lb = qp->lbx[n][i - HM_NU];
        *ub = qp->ubx[n][i - HM_NU];
    }
    return 1;
}

/* rows of the list rounded up to whole blocks of lanes */
HM_FUNC int ocp_qp_ipm_rows_blocks(const hm_ocp_qp_ipm_rows *sr)
{
    return (sr->nr + OCP_QP_IPM_LANES - 1) / OCP_QP_IPM_LANES * OCP_QP_IPM_LANES;
}

/* Row r of the list as an absent row (a stage's padding row, or the list's past its last stage): no
 * coupling (d = 0), zero residuals at the state s = t = z = zs = 1, which pass A restores every
 * iteration; its steps never shorten the step length. */
HM_FUNC void ocp_qp_ipm_rows_absent(hm_ocp_qp_ipm_rows *sr, int r)
{
    sr->srow[r] = 0;
    sr->sd0[r] = sr->sd1[r] = sr->slg[r] = HM_R(0.0);
    sr->szl[r] = sr->sZl[r] = HM_R(1.0);
    sr->slive[r] = HM_R(0.0);
    sr->ss[r] = sr->st[r] = sr->sz[r] = sr->szs[r] = HM_R(1.0);
    sr->sds[r] = sr->sdt[r] = sr->sdz[r] = sr->sdzs[r] = HM_R(0.0);
    sr->gp[r] = sr->gd[r] = sr->sdr[r] = sr->sdsb[r] = sr->se[r] = HM_R(0.0);
}

/* Builds the stage blocks of qp and the starting point. Returns HM_QP_INFEASIBLE if a lower bound
 * exceeds its upper bound (*bad = stage * HM_QP_NUX + component), HM_QP_NONFINITE if the QP has more
 * bounded components or hard rows in a stage, or soft rows in all, than the solver was sized for
 * (HM_QP_NBP, HM_QP_NGH, HM_QP_NRC). */
HM_FUNC int ocp_qp_ipm_setup(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, int *bad)
{
    hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    int n, i, j, k, l, m = 0, off = 0, nsoft = 0;
    int bounded[HM_QP_NUX];
    hm_real norm_q = HM_R(0.0), norm_b = HM_R(0.0), hscale = HM_R(0.0), c;

    /* bound pairs: a slot for every component bounded at some stage (crossing bounds, found in
     * stage order, make the QP infeasible), its sides per stage; the starting point t = max(b, 1),
     * z = 1 / t; a side absent at a stage keeps sign 0, b = t = z = 1 */
    for (i = 0; i < HM_QP_NUX; i++) bounded[i] = 0;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_QP_NUX; i++) {
            hm_real lb = HM_R(0.0), ub = HM_R(0.0);
            int lp, up;
            if (!ocp_qp_ipm_bounds_of(qp, n, i, &lb, &ub)) continue;
            lp = ocp_qp_bound_present(lb);
            up = ocp_qp_bound_present(ub);
            if (lp && up && lb > ub) {
                *bad = n * HM_QP_NUX + i;
                return HM_QP_INFEASIBLE;
            }
            if (lp || up) bounded[i] = 1;
        }
    }
    bd->nbp = 0;
    for (i = 0; i < HM_QP_NUX; i++) {
        if (!bounded[i]) continue;
        /* more bounded components than the solver has slots for: a QP of another shape */
        if (bd->nbp == HM_QP_NBP) return HM_QP_NONFINITE;
        bd->bc[bd->nbp++] = (unsigned char)i;
    }
    for (k = 0; k < bd->nbp; k++) {
        const int comp = bd->bc[k];
        for (n = 0; n < HM_QP_NNP; n++) {
            hm_real lb = -HM_INF, ub = HM_INF;
            int lp = 0, up = 0;
            if (n <= HM_N && ocp_qp_ipm_bounds_of(qp, n, comp, &lb, &ub)) {
                lp = ocp_qp_bound_present(lb);
                up = ocp_qp_bound_present(ub);
            }
            bd->sg[k][0][n] = lp ? HM_R(-1.0) : HM_R(0.0);
            bd->sg[k][1][n] = up ? HM_R(1.0) : HM_R(0.0);
            bd->b[k][0][n] = lp ? -lb : HM_R(1.0);
            bd->b[k][1][n] = up ? ub : HM_R(1.0);
            if (lp) norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(lb));
            if (up) norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(ub));
            m += lp + up;
        }
        /* the starting point of the slot's sides: a loop of its own, without the branches of the
         * bounds' lookup, so that its divisions run in vector lanes (an absent side has b = 1) */
        for (l = 0; l < 2; l++) {
            const hm_real *restrict b = bd->b[k][l];
            hm_real *restrict t = bd->t[k][l];
            hm_real *restrict z = bd->z[k][l];
            hm_real *restrict dt = bd->dt[k][l];
            hm_real *restrict dz = bd->dz[k][l];
            for (n = 0; n < HM_QP_NNP; n++) {
                t[n] = OCP_QP_IPM_MAX(b[n], HM_R(1.0));
                z[n] = HM_R(1.0) / t[n];
                dt[n] = dz[n] = HM_R(0.0);
            }
        }
        for (n = 0; n < HM_QP_NNP; n++) bd->v[k][n] = bd->dv[k][n] = HM_R(0.0);
    }

    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        int ns = 0, nh = 0;
        sn->soff = off;
        sn->hr = &ws->u.f.hd[HM_QP_HB(n)];
        /* general rows: soft ones and hard ones, each in QP order */
        if (n > 0) {
            for (i = 0; i < qp->ng[n]; i++) {
                const hm_real lg = qp->lg[n][i];
                if (!ocp_qp_bound_present(lg)) continue;
                norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(lg));
                if (qp->soft[n][i]) {
                    const int row = off + ns;
                    /* more soft rows than the solver holds (HM_QP_NRC; the NLP keeps within it) */
                    if (nsoft == HM_QP_NRC) return HM_QP_NONFINITE;
                    nsoft++;
                    sr->srow[row] = (unsigned char)i;
                    sr->sd0[row] = qp->D[n][i][0];
                    sr->sd1[row] = qp->D[n][i][1];
                    sr->slg[row] = lg;
                    sr->szl[row] = qp->zl[n][i];
                    sr->sZl[row] = qp->Zl[n][i];
                    sr->slive[row] = HM_R(1.0);
                    norm_q = OCP_QP_IPM_MAX(norm_q, hm_fabs(qp->zl[n][i]));
                    hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->Zl[n][i]));
                    ns++;
                } else {
                    if (nh == HM_QP_NGH) return HM_QP_NONFINITE;   /* more hard rows than the solver has room for */
                    sn->hr->hrow[nh] = (unsigned char)i;
                    sn->hr->hd0[nh] = qp->D[n][i][0];
                    sn->hr->hd1[nh] = qp->D[n][i][1];
                    sn->hr->hlg[nh] = lg;
                    sn->hr->hlive[nh] = HM_R(1.0);
                    nh++;
                }
            }
        }
        sn->ns = ns;
        sn->nh = nh;
        sn->ns2 = ns + (ns & 1);
        sn->nh2 = nh + (nh & 1);
        off += sn->ns2;
        m += 2 * ns + nh;

        /* cost gradient and dynamics offset, unscaled for now (the Hessian blocks stay in the QP: the
         * kernels read them times the cost scale); x_0 is data, its terms move into stage 0 */
        for (i = 0; i < HM_NU; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->r[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->S[0][i + k * HM_NU] * qp->x0[k];
                }
                hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->R[n][i * (HM_NU + 1)]));
            }
            sn->q[i] = acc;
        }
        for (i = 0; i < HM_NX; i++) {
            sn->q[HM_NU + i] = n == 0 ? HM_R(0.0) : qp->q[n][i];
            if (n > 0) hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->Q[n][i * (HM_NX + 1)]));
        }
        for (i = 0; i < HM_QP_NUX; i++) norm_q = OCP_QP_IPM_MAX(norm_q, hm_fabs(sn->q[i]));
        for (i = 0; i < HM_NX; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->b[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->A[0][i + k * HM_NX] * qp->x0[k];
                }
            }
            sn->beq[i] = acc;
            norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(acc));
        }
        sn->a_id = 0;
        sn->ab_int = 0;
        if (n < HM_N) {
            const hm_real *A = qp->A[n];
            const hm_real *B = qp->B[n];
            sn->a_id = A[0] == HM_R(1.0) && A[1] == HM_R(0.0) && A[2] == HM_R(0.0) && A[3] == HM_R(0.0)
                       && A[4] == HM_R(0.0) && A[5] == HM_R(1.0) && A[6] == HM_R(0.0) && A[7] == HM_R(0.0);
            sn->ab_int = sn->a_id && A[10] == HM_R(1.0) && A[11] == HM_R(0.0) && A[14] == HM_R(0.0)
                         && A[15] == HM_R(1.0) && B[2] == HM_R(0.0) && B[7] == HM_R(0.0);
        }
    }
    ws->m = m;
    sr->nr = off;

    /* Cost scaling (as in Clarabel): a cost measured in hundreds (goal weight 250) or a slack
     * penalty of 1e4 against rows measured in metres. Clipped so that tiny or huge data are not
     * blown up. */
    {
        const hm_real mag = OCP_QP_IPM_MAX(hscale, norm_q);
        c = HM_R(1.0) / (mag < HM_R(1e-4) ? HM_R(1e-4) : (mag > HM_R(1e4) ? HM_R(1e4) : mag));
        ws->cost_scale = c;
        ws->norm_q = norm_q * c;
        ws->norm_b = norm_b;
        ws->w_max = OCP_QP_IPM_W_MAX_REL * OCP_QP_IPM_MAX(HM_R(1.0), hscale * c);
    }

    /* scaled cost gradient, padding rows, starting point: v = 0 (soft slacks satisfying their rows with a
     * margin of 1), y = 0, t = max(b - a' v, 1), z = 1 / t; zero step */
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) {
            sn->q[i] *= c;
            sn->ux[i] = HM_R(0.0);
            sn->dux[i] = HM_R(0.0);
        }
        for (i = 0; i < HM_NX; i++) {
            sn->y[i] = HM_R(0.0);
            sn->dy[i] = HM_R(0.0);
            sn->ry[i] = HM_R(0.0);
        }
        for (i = 0; i < HM_QP_NUX; i++) sn->rv[i] = HM_R(0.0);   /* set by the first stage measures */
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real s = OCP_QP_IPM_MAX(HM_R(0.0), sr->slg[row]) + HM_R(1.0);
            const hm_real t = OCP_QP_IPM_MAX(s - sr->slg[row], HM_R(1.0));
            sr->szl[row] *= c;
            sr->sZl[row] *= c;
            sr->ss[row] = s;
            sr->st[row] = t;   /* z = 1 / t and zs = 1 / s below, over the whole list */
        }
        if (sn->ns & 1) ocp_qp_ipm_rows_absent(sr, sn->soff + sn->ns);   /* the stage's padding row */
        for (j = sn->soff; j < sn->soff + sn->ns; j++) sr->sds[j] = sr->sdt[j] = sr->sdz[j] = sr->sdzs[j] = HM_R(0.0);
        for (j = 0; j < sn->nh; j++) {
            const hm_real t = OCP_QP_IPM_MAX(-sn->hr->hlg[j], HM_R(1.0));
            sn->hr->ht[j] = t;
            sn->hr->hz[j] = HM_R(1.0) / t;
        }
        if (sn->nh & 1) {
            j = sn->nh;
            sn->hr->hd0[j] = sn->hr->hd1[j] = HM_R(0.0);
            sn->hr->hlg[j] = HM_R(-1.0);
            sn->hr->hlive[j] = HM_R(0.0);
            sn->hr->ht[j] = sn->hr->hz[j] = HM_R(1.0);
        }
        for (j = 0; j < sn->nh2; j++) sn->hr->hdt[j] = sn->hr->hdz[j] = HM_R(0.0);
    }
    /* the rows' starting multipliers, in vector lanes (a stage's padding row: 1 / 1) */
    {
        const hm_real *restrict ss = sr->ss, *restrict st = sr->st;
        hm_real *restrict sz = sr->sz, *restrict szs = sr->szs;
        for (j = 0; j < sr->nr; j++) {
            sz[j] = HM_R(1.0) / st[j];
            szs[j] = HM_R(1.0) / ss[j];
        }
    }
    /* the list's padding rows up to the last block of the passes */
    for (j = sr->nr; j < ocp_qp_ipm_rows_blocks(sr); j++) ocp_qp_ipm_rows_absent(sr, j);
    return 0;
}
