/*
 * ocp_qp_ipm_warm.c: the warm start of the interior-point method: keep (the first iterate of a solve
 * with mu <= arg->warm_mu, in ws->warm), then, in the next solve, shift it by a stage (or not) and
 * restore it over the cold start, floored. The kept iterate serves one solve at most.
 */
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_warm.h"

/* ------------------------------------------------------------------------------------------------
 * Warm start
 *
 * Consecutive QPs of the real-time iteration differ little: the new one is the last one shifted by
 * a stage, linearised at its solution. An interior-point method started from a solution stalls (the
 * slacks of the active inequalities and the multipliers of the inactive ones are tiny, and wherever
 * the new data changed which is which, every step to the boundary is short), so the solve keeps an
 * early, well-centred iterate instead: the first after the start with mu <= arg->warm_mu (the real-
 * time iteration's 0.2 where the cold start has 1: one iteration in). The next solve starts from it,
 * slacks and multipliers floored at OCP_QP_IPM_WARM_FLOOR, with v = 0, y = 0, and the inequalities
 * it does not have from the cold start. Measured on 16 x 2,000 closed-loop steps at N_h = 5: 10.7
 * instead of 11.7 iterations per QP (floor 0.1: 11.0; 0.02 to 0.05 with warm_mu 0.05 to 0.3: 10.7),
 * about 3 fallbacks per 2,000 steps as from the cold start; a floor of 1e-3 with warm_mu 0.01 gave
 * 50 (two short steps in a row).
 * ---------------------------------------------------------------------------------------------- */

#define OCP_QP_IPM_WARM_FLOOR HM_R(0.02)

/* Keep the iterate of pass A in ws->warm (multipliers unscaled: the next QP's scale may differ), the
 * bound sides by slot with the slots' components. */
HM_FUNC void ocp_qp_ipm_warm_keep(hm_ocp_qp_ipm_ws *ws)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_ocp_qp_ipm_warm *w = &ws->warm;
    const hm_real cinv = HM_R(1.0) / ws->cost_scale;
    int n, k, l, j, off = 0;
    w->nbp = bd->nbp;
    for (k = 0; k < bd->nbp; k++) w->bc[k] = bd->bc[k];
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                const int present = bd->sg[k][l][n] != HM_R(0.0);
                w->bt[n][k][l] = present ? bd->t[k][l][n] : HM_R(0.0);
                w->bz[n][k][l] = present ? bd->z[k][l][n] * cinv : HM_R(0.0);
            }
        }
        w->soff[n] = off;
        w->ns[n] = sn->ns;
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            w->srow[off + j] = sr->srow[row];
            w->st[off + j] = sr->st[row];
            w->sz[off + j] = sr->sz[row] * cinv;
            w->ss[off + j] = sr->ss[row];
            w->szs[off + j] = sr->szs[row] * cinv;
        }
        off += sn->ns;
        w->nh[n] = sn->nh;
        for (j = 0; j < sn->nh; j++) {
            const int hb = HM_QP_HB(n);
            w->hrow[hb][j] = sn->hr->hrow[j];
            w->ht[hb][j] = sn->hr->ht[j];
            w->hz[hb][j] = sn->hr->hz[j] * cinv;
        }
    }
    w->ready = 1;
}

HM_KERNEL hm_real ocp_qp_ipm_warm_floor(hm_real v)
{
    return OCP_QP_IPM_MAX(v, OCP_QP_IPM_WARM_FLOOR);
}

/* Overwrite the cold start (ocp_qp_ipm_setup) with the kept iterate: stage n from kept stage
 * n + shift (the last stage from itself), wherever the kept stage has the same inequality (a bound
 * side of the same component, a row of the same index and kind). */
HM_FUNC void ocp_qp_ipm_warm_apply(hm_ocp_qp_ipm_ws *ws, int shift)
{
    hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    const hm_ocp_qp_ipm_warm *w = &ws->warm;
    const hm_real c = ws->cost_scale;
    int n, k, l, j, kept[HM_QP_NBP];
    /* the kept slot of each slot's component, -1 if the kept iterate bounded it nowhere */
    for (k = 0; k < bd->nbp; k++) {
        kept[k] = -1;
        for (j = 0; j < w->nbp; j++)
            if (w->bc[j] == bd->bc[k]) kept[k] = j;
    }
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const int m = n + shift <= HM_N ? n + shift : HM_N;
        for (k = 0; k < bd->nbp; k++) {
            if (kept[k] < 0) continue;
            for (l = 0; l < 2; l++) {
                const hm_real t = w->bt[m][kept[k]][l];
                if (bd->sg[k][l][n] == HM_R(0.0) || !(t > HM_R(0.0))) continue;
                bd->t[k][l][n] = ocp_qp_ipm_warm_floor(t);
                bd->z[k][l][n] = ocp_qp_ipm_warm_floor(w->bz[m][kept[k]][l] * c);
            }
        }
        /* the rows of the kept stage with the QP rows of this one: both lists ascend */
        {
            int a = w->soff[m];
            const int end = a + w->ns[m];
            for (j = 0; j < sn->ns; j++) {
                const int row = sn->soff + j, i = sr->srow[row];
                while (a < end && w->srow[a] < i) a++;
                if (a == end) break;
                if (w->srow[a] != i) continue;
                sr->st[row] = ocp_qp_ipm_warm_floor(w->st[a]);
                sr->sz[row] = ocp_qp_ipm_warm_floor(w->sz[a] * c);
                sr->ss[row] = ocp_qp_ipm_warm_floor(w->ss[a]);
                sr->szs[row] = ocp_qp_ipm_warm_floor(w->szs[a] * c);
            }
        }
        {
            const int hb = HM_QP_HB(m);
            int a = 0;
            for (j = 0; j < sn->nh; j++) {
                const int i = sn->hr->hrow[j];
                while (a < w->nh[m] && w->hrow[hb][a] < i) a++;
                if (a == w->nh[m]) break;
                if (w->hrow[hb][a] != i) continue;
                sn->hr->ht[j] = ocp_qp_ipm_warm_floor(w->ht[hb][a]);
                sn->hr->hz[j] = ocp_qp_ipm_warm_floor(w->hz[hb][a] * c);
            }
        }
    }
}
