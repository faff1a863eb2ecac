/*
 * ocp_qp_ipm_pass_a.c: pass A of every interior-point iteration (forward over the stages): the step
 * of the last iteration taken, the residuals (those of the linear equations by their recurrence),
 * the weights z / t, and the inequalities condensed into their stages' Newton blocks; the sums of
 * the termination tests (ocp_qp_ipm_sums).
 */
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_lanes.h"
#include "ocp_qp_ipm_pass_a.h"
#include "ocp_qp_ipm_setup.h"

/* ------------------------------------------------------------------------------------------------
 * Pass A: step, residuals, weights, condensation
 * ---------------------------------------------------------------------------------------------- */


HM_FUNC void ocp_qp_ipm_pass_a(hm_ocp_qp_ipm_ws *restrict ws, hm_real alpha, ocp_qp_ipm_sums *restrict sm)
{
    const hm_real wmax = ws->w_max;
    const hm_real keep = HM_R(1.0) - alpha;
    hm_real qv = HM_R(0.0), bw = HM_R(0.0), vPv = HM_R(0.0), tz = HM_R(0.0), vz = HM_R(0.0);
    hm_real rd = HM_R(0.0), rp = HM_R(0.0), rd_eq = HM_R(0.0), rp_eq = HM_R(0.0);
    /* The maxima are taken entry by entry across the stages and reduced at the end: the same
     * numbers (max is exact in any order), in vector lanes instead of one scalar chain. */
    hm_real rd_v[HM_QP_NUX], rpe_v[HM_NX], vz_v[HM_QP_NUX];
    hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i, j, k, l;

    for (i = 0; i < HM_QP_NUX; i++) rd_v[i] = vz_v[i] = HM_R(0.0);
    for (i = 0; i < HM_NX; i++) rpe_v[i] = HM_R(0.0);

    /* the step, for all stages before the stage loop reads them: updated inside it, a stage's
     * (u, x) was stored in parts and read back across those parts while the stores were still in
     * flight (a failed store forwarding per stage) */
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) {
            sn->ux[i] += alpha * sn->dux[i];
            vz_v[i] += HM_R(0.0) * sn->ux[i];   /* in lanes: one chain of 306 additions took 3 % */
        }
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) sn->y[i] += alpha * sn->dy[i];
        }
        for (j = sn->soff; j < sn->soff + sn->ns2; j++)
            sr->gp[j] = sr->sd0[j] * sn->ux[HM_NU] + sr->sd1[j] * sn->ux[HM_NU + 1];
    }

    /* soft rows, all at once; their parts of the stages are summed in the stage loop */
    {
        hm_real lane[6][OCP_QP_IPM_LANES];
        for (l = 0; l < OCP_QP_IPM_LANES; l++)
            lane[0][l] = lane[1][l] = lane[2][l] = lane[3][l] = lane[4][l] = lane[5][l] = HM_R(0.0);
        ocp_qp_ipm_rows_a(sr, ocp_qp_ipm_rows_blocks(sr), alpha, wmax, lane);
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            tz += lane[0][l];
            bw += lane[1][l];
            qv += lane[2][l];
            vPv += lane[3][l];
            rp = OCP_QP_IPM_MAX(rp, lane[4][l]);
            rd = OCP_QP_IPM_MAX(rd, lane[5][l]);
        }
    }

    /* bound pairs, all stages of a slot at once (an absent side has sign 0 and stays at t = z = 1);
     * their parts of the diagonal and of the gradients go to the stage loop below */
    {
        hm_real tz_v[HM_QP_NNP], bw_v[HM_QP_NNP], rp_v[HM_QP_NNP];
        for (n = 0; n < HM_QP_NNP; n++) tz_v[n] = bw_v[n] = rp_v[n] = HM_R(0.0);
        for (k = 0; k < bd->nbp; k++) {
            hm_real *restrict v = bd->v[k];
            const hm_real *restrict dv = bd->dv[k];
            hm_real *restrict Hd_b = bd->Hd[k];
            hm_real *restrict hf_b = bd->hf[k];
            hm_real *restrict hmu_b = bd->hmu[k];
            for (n = 0; n < HM_QP_NNP; n++) {
                v[n] += alpha * dv[n];
                Hd_b[n] = hf_b[n] = hmu_b[n] = HM_R(0.0);
            }
            for (l = 0; l < 2; l++)
                ocp_qp_ipm_bound_side_a(alpha, wmax, bd->sg[k][l], bd->b[k][l], v, bd->dt[k][l], bd->dz[k][l],
                                        bd->t[k][l], bd->z[k][l], bd->w[k][l], bd->ti[k][l], bd->zi[k][l],
                                        bd->rho[k][l], Hd_b, hf_b, hmu_b, tz_v, bw_v, rp_v);
        }
        for (n = 0; n < HM_QP_NNP; n++) {
            tz += tz_v[n];
            bw += bw_v[n];
            rp = OCP_QP_IPM_MAX(rp, rp_v[n]);
        }
    }

    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];

        /* dynamics n -> n + 1, by the recurrence */
        if (n < HM_N) {
            const hm_real *restrict y = sn->y;
            for (i = 0; i < HM_NX; i++) {
                const hm_real r = keep * sn->ry[i];
                sn->ry[i] = r;
                rpe_v[i] = OCP_QP_IPM_MAX(rpe_v[i], OCP_QP_IPM_ABS(r));
            }
            bw += (sn->beq[0] * y[0] + sn->beq[1] * y[1]) + (sn->beq[2] * y[2] + sn->beq[3] * y[3]);
        }
        /* stationarity of (u, x) by the recurrence. The predictor's gradient r + A_I' W rho, the
         * stage's diagonal and hmu start from it and take the bound pairs' and the rows' parts
         * entry by entry, in place: summed in local arrays and copied whole, they were read back
         * while the entries' stores were in flight (a failed store forwarding per stage). The
         * parts absent at stage 0 (x) and stage N (u) are exact zeros in every term. */
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = keep * sn->rv[i];
            sn->rv[i] = ri;
            sn->ha[i] = ri;
            sn->hmu[i] = HM_R(0.0);
            sn->Hd[i] = HM_R(0.0);
            rd_v[i] = OCP_QP_IPM_MAX(rd_v[i], OCP_QP_IPM_ABS(ri));
        }

        /* bound pairs (above) */
        for (k = 0; k < bd->nbp; k++) {
            const int c = bd->bc[k];
            sn->Hd[c] += bd->Hd[k][n];
            sn->ha[c] += bd->hf[k][n];
            sn->hmu[c] += bd->hmu[k][n];
        }

        if (n > 0) {
            const hm_real p0 = sn->ux[HM_NU], p1 = sn->ux[HM_NU + 1];
            hm_real h00[2] = {HM_R(0.0), HM_R(0.0)}, h10[2] = {HM_R(0.0), HM_R(0.0)}, h11[2] = {HM_R(0.0), HM_R(0.0)};
            hm_real g0[2] = {HM_R(0.0), HM_R(0.0)}, g1[2] = {HM_R(0.0), HM_R(0.0)};
            hm_real m0[2] = {HM_R(0.0), HM_R(0.0)}, m1[2] = {HM_R(0.0), HM_R(0.0)};
            hm_real tz_l[2] = {HM_R(0.0), HM_R(0.0)}, bw_l[2] = {HM_R(0.0), HM_R(0.0)};
            hm_real rp_l[2] = {HM_R(0.0), HM_R(0.0)};

            /* soft rows (ocp_qp_ipm_rows_a, above): their parts summed into the stage */
            for (j = sn->soff; j < sn->soff + sn->ns2; j++) {
                const hm_real d0 = sr->sd0[j], d1 = sr->sd1[j], we = sr->sdr[j];
                const hm_real e = sr->sdsb[j], cmu = sr->se[j];
                h00[0] += we * d0 * d0;
                h10[0] += we * d0 * d1;
                h11[0] += we * d1 * d1;
                g0[0] -= d0 * e;
                g1[0] -= d1 * e;
                m0[0] -= d0 * cmu;
                m1[0] -= d1 * cmu;
            }
            /* hard rows, in pairs */
            for (j = 0; j < sn->nh2; j += 2) {
                for (l = 0; l < 2; l++) {
                    const int q = j + l;
                    const hm_real msk = sn->hr->hlive[q];
                    const hm_real t = msk * (sn->hr->ht[q] + alpha * sn->hr->hdt[q]) + (HM_R(1.0) - msk);
                    const hm_real z = msk * (sn->hr->hz[q] + alpha * sn->hr->hdz[q]) + (HM_R(1.0) - msk);
                    const hm_real d0 = sn->hr->hd0[q], d1 = sn->hr->hd1[q], lg = sn->hr->hlg[q];
                    const hm_real rho = lg - (d0 * p0 + d1 * p1);
                    const hm_real ia = HM_R(1.0) / (t * z);
                    const hm_real ti = z * ia, zi = t * ia;
                    const hm_real w = OCP_QP_IPM_MIN(z * ti, wmax);
                    const hm_real wr = w * rho, wz = w * zi;
                    sn->hr->ht[q] = t;
                    sn->hr->hz[q] = z;
                    sn->hr->hti[q] = ti;
                    sn->hr->hzi[q] = zi;
                    sn->hr->hw[q] = w;
                    h00[l] += w * d0 * d0;
                    h10[l] += w * d0 * d1;
                    h11[l] += w * d1 * d1;
                    g0[l] -= d0 * wr;
                    g1[l] -= d1 * wr;
                    m0[l] -= d0 * wz;
                    m1[l] -= d1 * wz;
                    tz_l[l] += msk * t * z;
                    bw_l[l] -= msk * lg * z;
                    rp_l[l] = OCP_QP_IPM_MAX(rp_l[l], OCP_QP_IPM_ABS(t + rho));
                }
            }
            sn->Hpp[0] = h00[0] + h00[1];
            sn->Hpp[1] = h10[0] + h10[1];
            sn->Hpp[2] = h11[0] + h11[1];
            sn->ha[HM_NU] += g0[0] + g0[1];
            sn->ha[HM_NU + 1] += g1[0] + g1[1];
            sn->hmu[HM_NU] += m0[0] + m0[1];
            sn->hmu[HM_NU + 1] += m1[0] + m1[1];
            tz += tz_l[0] + tz_l[1];
            bw += bw_l[0] + bw_l[1];
            rp = OCP_QP_IPM_MAX(rp, OCP_QP_IPM_MAX(rp_l[0], rp_l[1]));
        } else {
            sn->Hpp[0] = sn->Hpp[1] = sn->Hpp[2] = HM_R(0.0);
        }
    }
    for (i = 0; i < HM_QP_NUX; i++) {
        rd_eq = OCP_QP_IPM_MAX(rd_eq, rd_v[i]);
        vz += vz_v[i];
    }
    for (i = 0; i < HM_NX; i++) rp_eq = OCP_QP_IPM_MAX(rp_eq, rpe_v[i]);
    sm->bw = bw;
    sm->tz = tz;
    sm->vz = vz;
    sm->rp_in = rp;
    sm->rd_in = rd;
    sm->rp_eq = rp_eq;
    sm->rd_eq = rd_eq;
    sm->rp = OCP_QP_IPM_MAX(rp, rp_eq);
    sm->rd = OCP_QP_IPM_MAX(rd, rd_eq);
    sm->qv_in = qv;
    sm->vPv_in = vPv;
    /* not measured yet: the stage measures (ocp_qp_ipm_stage_measures) and the inequality measures
     * (ocp_qp_ipm_row_measures); neutral for the normalisation and the certificate, and no natural
     * residual small enough to declare a solution */
    sm->exact = 0;
    sm->measured = 0;
    sm->qv = sm->vPv = HM_R(0.0);
    sm->atw = sm->pv = sm->av_eq = HM_R(0.0);
    sm->av_ineq = sm->nt = sm->atw_s = sm->pv_s = HM_R(0.0);
    sm->ncr = HM_INF;
}
