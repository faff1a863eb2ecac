/*
 * ocp_qp_hsde_setup.c: the set-up of a fallback solve, once per solve: the present inequality rows
 * packed stage after stage, the data of the embedding (cost gradient, right-hand sides, the terms of
 * the fixed x_0 moved into stage 0), its norms, the cost scale and the cap of the row weights.
 */
#include "ocp_qp.h"
#include "ocp_qp_hsde.h"
#include "ocp_qp_hsde_common.h"
#include "ocp_qp_hsde_setup.h"

/* Cap of the row weights z / t, relative to the curvature of the cost. Near the solution the weights
 * of active rows grow like 1 / mu; condensed into the Riccati recursion, whose Schur complements
 * subtract them again, they leave rounding errors of eps * weight in the moderate directions, and
 * beyond ~1e-6 / eps the cost-to-go matrices lose definiteness and the steps go wrong. Capping the
 * weight makes the Newton step slightly inexact on active rows only; that error shrinks with the
 * step itself, so convergence is kept (measured on random QPs solved to 1e-10: 300/300 with the cap,
 * 70% without it). */
#ifdef HM_REAL_IS_FLOAT
#define OCP_QP_HSDE_W_MAX_REL HM_R(1e4)
#else
#define OCP_QP_HSDE_W_MAX_REL HM_R(1e10)
#endif


/* Packs the present inequality rows and computes the data of the embedding and its norms. Returns
 * HM_QP_INFEASIBLE if a lower bound exceeds its upper bound (*bad = stage * HM_QP_NUX + component),
 * HM_QP_NONFINITE if a stage bounds more components, or the QP has more rows, than the solver was
 * sized for (HM_QP_NBP; HM_QP_HSDE_NGR rows, HM_QP_NRC soft ones). */
HM_FUNC int ocp_qp_hsde_setup(const hm_ocp_qp *qp, hm_ocp_qp_hsde_ws *ws, int *bad)
{
    int n, i, k, m = 0, roff = 0, soff = 0;
    hm_real norm_q = HM_R(0.0), norm_b = HM_R(0.0), hscale = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        int nb = 0, nr = 0, ns = 0, nbc = 0;
        ws->off[n] = m;
        ws->roff[n] = roff;
        ws->soff[n] = soff;
        for (i = 0; i < HM_QP_NUX; i++) {
            hm_real lb, ub;
            if (i < HM_NU) {
                if (n == HM_N) continue;
                lb = qp->lbu[n][i];
                ub = qp->ubu[n][i];
            } else {
                if (n == 0) continue;
                lb = qp->lbx[n][i - HM_NU];
                ub = qp->ubx[n][i - HM_NU];
            }
            /* more bounded components than the solver has room for (HM_QP_NBP): a QP of another shape */
            if ((ocp_qp_bound_present(lb) || ocp_qp_bound_present(ub)) && ++nbc > HM_QP_NBP) return HM_QP_NONFINITE;
            if (ocp_qp_bound_present(lb)) {
                if (ocp_qp_bound_present(ub) && lb > ub) {
                    *bad = n * HM_QP_NUX + i;
                    return HM_QP_INFEASIBLE;
                }
                ws->box_comp[n][nb] = (unsigned char)i;
                ws->box_sign[n][nb] = HM_R(-1.0);
                ws->b_ineq[m + nb] = -lb;
                nb++;
            }
            if (ocp_qp_bound_present(ub)) {
                ws->box_comp[n][nb] = (unsigned char)i;
                ws->box_sign[n][nb] = HM_R(1.0);
                ws->b_ineq[m + nb] = ub;
                nb++;
            }
        }
        if (n > 0) {
            for (i = 0; i < qp->ng[n]; i++) {
                if (!ocp_qp_bound_present(qp->lg[n][i])) continue;
                /* more rows than the solver holds (HM_QP_HSDE_NGR, HM_QP_NRC; the NLP keeps within them) */
                if (roff + nr == HM_QP_HSDE_NGR || (qp->soft[n][i] && soff + ns == HM_QP_NRC)) return HM_QP_NONFINITE;
                ws->row_idx[roff + nr] = (unsigned char)i;
                ws->D[roff + nr][0] = qp->D[n][i][0];
                ws->D[roff + nr][1] = qp->D[n][i][1];
                ws->b_ineq[m + nb + nr] = -qp->lg[n][i];
                if (qp->soft[n][i]) {
                    ws->soft_of[soff + ns] = (unsigned char)nr;
                    ws->q_s[roff + nr] = qp->zl[n][i];
                    norm_q = OCP_QP_HSDE_MAX(norm_q, hm_fabs(qp->zl[n][i]));
                    hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->Zl[n][i]));
                    ns++;
                }
                nr++;
            }
            /* the soft rows' s >= 0 follow the stage's general rows */
            for (k = 0; k < ns; k++) ws->b_ineq[m + nb + nr + k] = HM_R(0.0);
        }
        ws->nb[n] = nb;
        ws->nr[n] = nr;
        ws->ns[n] = ns;
        /* the tau row is evaluated by every solve, also those before the first residuals */
        for (i = 0; i < HM_QP_NUX; i++) ws->c_ux[n][i] = HM_R(0.0);
        for (k = 0; k < nr; k++) ws->c_s[roff + k] = HM_R(0.0);
        m += nb + nr + ns;
        roff += nr;
        soff += ns;

        /* linear cost on (u, x); x_0 is data, its terms move into stage 0 */
        for (i = 0; i < HM_NU; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->r[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->S[0][i + k * HM_NU] * qp->x0[k];
                }
                hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->R[n][i * (HM_NU + 1)]));
            }
            ws->q_ux[n][i] = acc;
        }
        for (i = 0; i < HM_NX; i++) {
            ws->q_ux[n][HM_NU + i] = n == 0 ? HM_R(0.0) : qp->q[n][i];
            if (n > 0) hscale = OCP_QP_HSDE_MAX(hscale, hm_fabs(qp->Q[n][i * (HM_NX + 1)]));
        }
        for (i = 0; i < HM_QP_NUX; i++) norm_q = OCP_QP_HSDE_MAX(norm_q, hm_fabs(ws->q_ux[n][i]));
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) {
                hm_real acc = qp->b[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->A[0][i + k * HM_NX] * qp->x0[k];
                }
                ws->b_eq[n][i] = acc;
                norm_b = OCP_QP_HSDE_MAX(norm_b, hm_fabs(acc));
            }
        }
    }
    ws->m = m;
    for (i = 0; i < m; i++) norm_b = OCP_QP_HSDE_MAX(norm_b, hm_fabs(ws->b_ineq[i]));

    /* Cost scaling (as in Clarabel): the embedding balances cost against constraints through tau and
     * kappa, and a cost measured in hundreds (goal weight 250) against rows measured in metres made
     * it take twice the iterations. Clipped so that tiny or huge data are not blown up. */
    {
        const hm_real mag = OCP_QP_HSDE_MAX(hscale, norm_q);
        const hm_real c = HM_R(1.0) / (mag < HM_R(1e-4) ? HM_R(1e-4) : (mag > HM_R(1e4) ? HM_R(1e4) : mag));
        for (n = 0; n <= HM_N; n++) {
            const int so = ws->soff[n], ro = ws->roff[n];
            for (i = 0; i < HM_QP_NUX; i++) ws->q_ux[n][i] *= c;
            for (k = 0; k < ws->nr[n]; k++) ws->q_s[ro + k] *= c;
            for (k = 0; k < ws->ns[n]; k++) ws->soft_Zl[so + k] = c * qp->Zl[n][ws->row_idx[ro + ws->soft_of[so + k]]];
        }
        ws->cost_scale = c;
        ws->norm_q = norm_q * c;
        ws->w_max = OCP_QP_HSDE_W_MAX_REL * OCP_QP_HSDE_MAX(HM_R(1.0), hscale * c);
    }
    ws->norm_b = norm_b;
    return 0;
}
