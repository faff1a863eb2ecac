/*
 * ocp_qp_ipm_pred_corr.c: passes B to E of every interior-point iteration: B factorises the Newton
 * matrix and runs the predictor's backward substitution, C its forward substitution and inequality
 * steps (the step length, mu_aff, the corrector's second-order terms), D and E the same for the
 * corrector, whose step the next pass A takes.
 */
#include "ocp_qp_kkt.h"
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_lanes.h"
#include "ocp_qp_ipm_pred_corr.h"
#include "ocp_qp_ipm_setup.h"

/* ------------------------------------------------------------------------------------------------
 * Passes B to E
 * ---------------------------------------------------------------------------------------------- */

/* Pass B: factorisation and the predictor's backward substitution. */
HM_FUNC int ocp_qp_ipm_pass_b(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws)
{
    int n;
    for (n = HM_N; n >= 0; n--) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const hm_ocp_qp_ipm_stage *sn1 = n < HM_N ? &ws->u.f.st[n + 1] : sn;
        if (ocp_qp_kkt_factor_stage(qp, sn, sn1, n, ws->cost_scale)) return HM_QP_NUMERICAL;
        ocp_qp_kkt_backward_stage(qp, sn, sn1, n, sn->ha);
    }
    return 0;
}

/* Pass D: the corrector's backward substitution, gradient ha + hdl + smu * hmu. */
HM_FUNC void ocp_qp_ipm_pass_d(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws, hm_real smu,
                               hm_real kdel)
{
    int n, i;
    for (n = HM_N; n >= 0; n--) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        hm_real h[HM_QP_NUX];
        for (i = 0; i < HM_QP_NUX; i++) h[i] = sn->ha[i] + kdel * sn->hdl[i] + smu * sn->hmu[i];
        ocp_qp_kkt_backward_stage(qp, sn, n < HM_N ? &ws->u.f.st[n + 1] : sn, n, h);
    }
}


/* The (u, x) step of stage n from the forward substitution, in place: reads the state step from
 * sn->dux (zero at n = 0, written by stage n - 1 otherwise), writes the input step there and the
 * next state step into stage n + 1's dux, and the dynamics' multiplier step into dy. The steps go
 * straight to memory that the passes read entry by entry: copied through a local array, whose
 * entries were stored one by one, they were reloaded whole (a failed store forwarding per stage). */
HM_FUNC void ocp_qp_ipm_stage_step(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws, int n,
                                   hm_real *restrict dy)
{
    hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
    if (n < HM_N) {
        hm_ocp_qp_ipm_stage *restrict sn1 = &ws->u.f.st[n + 1];
        ocp_qp_kkt_forward_stage(qp, sn, sn1, n, &sn->dux[HM_NU], sn->dux, &sn1->dux[HM_NU], dy);
    } else {
        sn->dux[0] = sn->dux[1] = HM_R(0.0);
    }
}

/* Pass C: the predictor's forward substitution and inequality steps; per inequality dt dz for the
 * corrector, and per stage its second-order gradient terms hdl. */
HM_FUNC void ocp_qp_ipm_pass_c(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws,
                               ocp_qp_ipm_pred *restrict pr)
{
    hm_real ratio = HM_R(0.0), tdz = HM_R(0.0), dtdz = HM_R(0.0);
    hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i, j, k, l;
    /* the predictor's step lives in the stages' dux until pass E writes the corrector's over it
     * (pass A has taken the last one) */
    for (i = 0; i < HM_NX; i++) ws->u.f.st[0].dux[HM_NU + i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        ocp_qp_ipm_stage_step(qp, ws, n, NULL);   /* the predictor's dy is never used */
        {
            hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
            const hm_real *restrict dux = sn->dux;
            /* the hard rows' part of hdl, on (px, py) only (the soft rows' and the bound pairs' are
             * added after the sweep); kept in scalars and stored entry by entry: a local array half
             * written and then copied whole is a failed store forwarding per stage */
            hm_real hdl0 = HM_R(0.0), hdl1 = HM_R(0.0);
            for (k = 0; k < bd->nbp; k++) bd->dv[k][n] = dux[bd->bc[k]];   /* pass A has taken E's */
            if (n > 0) {
                const hm_real p0 = sn->ux[HM_NU], p1 = sn->ux[HM_NU + 1];
                const hm_real dp0 = dux[HM_NU], dp1 = dux[HM_NU + 1];
                hm_real g0[2] = {HM_R(0.0), HM_R(0.0)}, g1[2] = {HM_R(0.0), HM_R(0.0)};
                hm_real ra[2] = {HM_R(0.0), HM_R(0.0)}, sa[2] = {HM_R(0.0), HM_R(0.0)}, sb[2] = {HM_R(0.0), HM_R(0.0)};
                for (j = 0; j < sn->nh2; j += 2) {
                    for (l = 0; l < 2; l++) {
                        const int q = j + l;
                        const hm_real msk = sn->hr->hlive[q];
                        const hm_real d0 = sn->hr->hd0[q], d1 = sn->hr->hd1[q];
                        const hm_real t = sn->hr->ht[q], z = sn->hr->hz[q], w = sn->hr->hw[q], zi = sn->hr->hzi[q];
                        const hm_real gd = d0 * dp0 + d1 * dp1;
                        const hm_real rho = sn->hr->hlg[q] - (d0 * p0 + d1 * p1);
                        const hm_real dz = w * (rho - gd);
#ifdef OCP_QP_IPM_DT_PRIMAL
                        const hm_real dt = gd - (t + rho);
#else
                        const hm_real dt = -t - t * dz * zi;
#endif
                        const hm_real del = dt * dz;
                        const hm_real coef = w * zi * del;
                        sn->hr->hdel[q] = del;
                        g0[l] += d0 * coef;
                        g1[l] += d1 * coef;
                        ra[l] = OCP_QP_IPM_MAX(ra[l], OCP_QP_IPM_MAX(-dt * sn->hr->hti[q], -dz * zi));
                        sa[l] += msk * (t * dz + z * dt);
                        sb[l] += msk * del;
                    }
                }
                hdl0 = g0[0] + g0[1];
                hdl1 = g1[0] + g1[1];
                ratio = OCP_QP_IPM_MAX(ratio, OCP_QP_IPM_MAX(ra[0], ra[1]));
                tdz += sa[0] + sa[1];
                dtdz += sb[0] + sb[1];
            }
            for (i = 0; i < HM_QP_NUX; i++) sn->hdl[i] = HM_R(0.0);
            sn->hdl[HM_NU] = hdl0;
            sn->hdl[HM_NU + 1] = hdl1;
        }
    }
    /* soft rows, all at once, from the position steps of their stages; their parts of hdl below */
    {
        hm_real lane[3][OCP_QP_IPM_LANES];
        for (n = 1; n <= HM_N; n++) {
            const hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
            for (j = sn->soff; j < sn->soff + sn->ns2; j++)
                sr->gd[j] = sr->sd0[j] * sn->dux[HM_NU] + sr->sd1[j] * sn->dux[HM_NU + 1];
        }
        for (l = 0; l < OCP_QP_IPM_LANES; l++) lane[0][l] = lane[1][l] = lane[2][l] = HM_R(0.0);
        ocp_qp_ipm_rows_c(sr, ocp_qp_ipm_rows_blocks(sr), ws->w_max, lane);
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            ratio = OCP_QP_IPM_MAX(ratio, lane[0][l]);
            tdz += lane[1][l];
            dtdz += lane[2][l];
        }
    }
    /* bound pairs, all stages of a slot at once */
    {
        hm_real r_v[HM_QP_NNP], tdz_v[HM_QP_NNP], dtdz_v[HM_QP_NNP];
        for (n = 0; n < HM_QP_NNP; n++) r_v[n] = tdz_v[n] = dtdz_v[n] = HM_R(0.0);
        for (k = 0; k < bd->nbp; k++) {
            const hm_real *restrict dvp = bd->dv[k];
            hm_real *restrict hdl_b = bd->hdl[k];
            for (n = 0; n < HM_QP_NNP; n++) hdl_b[n] = HM_R(0.0);
            for (l = 0; l < 2; l++)
                ocp_qp_ipm_bound_side_c(bd->sg[k][l], bd->t[k][l], bd->z[k][l], bd->w[k][l], bd->ti[k][l],
                                        bd->zi[k][l], bd->rho[k][l], dvp, bd->del[k][l], hdl_b, r_v, tdz_v, dtdz_v);
        }
        for (n = 0; n < HM_QP_NNP; n++) {
            ratio = OCP_QP_IPM_MAX(ratio, r_v[n]);
            tdz += tdz_v[n];
            dtdz += dtdz_v[n];
        }
        /* into the stages' hdl, which pass D reads (off its sequential chain here), with the soft
         * rows' parts */
        for (n = 0; n <= HM_N; n++) {
            hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
            hm_real *restrict hdl = sn->hdl;
            hm_real h0 = HM_R(0.0), h1 = HM_R(0.0);
            for (j = sn->soff; j < sn->soff + sn->ns2; j++) {
                h0 += sr->sd0[j] * sr->se[j];
                h1 += sr->sd1[j] * sr->se[j];
            }
            hdl[HM_NU] += h0;
            hdl[HM_NU + 1] += h1;
            for (k = 0; k < bd->nbp; k++) hdl[bd->bc[k]] += bd->hdl[k][n];
        }
    }
    pr->ratio = ratio;
    pr->tdz = tdz;
    pr->dtdz = dtdz;
}

/* Pass E: the corrector's forward substitution and inequality steps (stored: the step taken by the
 * next pass A); returns the largest ratio -dt / t, -dz / z. */
HM_FUNC hm_real ocp_qp_ipm_pass_e(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws, hm_real smu,
                                  hm_real kdel)
{
    hm_real ratio = HM_R(0.0);
    hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i, j, k, l;
    for (i = 0; i < HM_NX; i++) ws->u.f.st[0].dux[HM_NU + i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        ocp_qp_ipm_stage_step(qp, ws, n, ws->u.f.st[n].dy);
        {
            hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
            const hm_real *restrict dux = sn->dux;
            for (k = 0; k < bd->nbp; k++) bd->dv[k][n] = dux[bd->bc[k]];
            if (n > 0) {
                const hm_real p0 = sn->ux[HM_NU], p1 = sn->ux[HM_NU + 1];
                const hm_real dp0 = dux[HM_NU], dp1 = dux[HM_NU + 1];
                hm_real ra[2] = {HM_R(0.0), HM_R(0.0)};
                for (j = 0; j < sn->nh2; j += 2) {
                    for (l = 0; l < 2; l++) {
                        const int q = j + l;
                        const hm_real d0 = sn->hr->hd0[q], d1 = sn->hr->hd1[q];
                        const hm_real t = sn->hr->ht[q], z = sn->hr->hz[q], w = sn->hr->hw[q], zi = sn->hr->hzi[q];
                        const hm_real cc = smu - kdel * sn->hr->hdel[q];
                        const hm_real gd = d0 * dp0 + d1 * dp1;
                        const hm_real rho0 = sn->hr->hlg[q] - (d0 * p0 + d1 * p1);
                        const hm_real dz = w * (rho0 + cc * zi - gd);
#ifdef OCP_QP_IPM_DT_PRIMAL
                        const hm_real dt = gd - (t + rho0);
                        (void)z;
#else
                        const hm_real dt = -(t * z - cc + t * dz) * zi;
#endif
                        sn->hr->hdz[q] = dz;
                        sn->hr->hdt[q] = dt;
                        ra[l] = OCP_QP_IPM_MAX(ra[l], OCP_QP_IPM_MAX(-dt * sn->hr->hti[q], -dz * zi));
                    }
                }
                ratio = OCP_QP_IPM_MAX(ratio, OCP_QP_IPM_MAX(ra[0], ra[1]));
            }
        }
    }
    /* soft rows, all at once */
    {
        hm_real lane[OCP_QP_IPM_LANES];
        for (n = 1; n <= HM_N; n++) {
            const hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
            for (j = sn->soff; j < sn->soff + sn->ns2; j++)
                sr->gd[j] = sr->sd0[j] * sn->dux[HM_NU] + sr->sd1[j] * sn->dux[HM_NU + 1];
        }
        for (l = 0; l < OCP_QP_IPM_LANES; l++) lane[l] = HM_R(0.0);
        ocp_qp_ipm_rows_e(sr, ocp_qp_ipm_rows_blocks(sr), ws->w_max, smu, kdel, lane);
        for (l = 0; l < OCP_QP_IPM_LANES; l++) ratio = OCP_QP_IPM_MAX(ratio, lane[l]);
    }
    /* bound pairs, all stages of a slot at once */
    {
        hm_real r_v[HM_QP_NNP];
        for (n = 0; n < HM_QP_NNP; n++) r_v[n] = HM_R(0.0);
        for (k = 0; k < bd->nbp; k++) {
            const hm_real *restrict dvp = bd->dv[k];
            for (l = 0; l < 2; l++)
                ocp_qp_ipm_bound_side_e(smu, kdel, bd->sg[k][l], bd->t[k][l], bd->z[k][l], bd->w[k][l], bd->ti[k][l],
                                        bd->zi[k][l], bd->rho[k][l], bd->del[k][l], dvp, bd->dt[k][l], bd->dz[k][l],
                                        r_v);
        }
        for (n = 0; n < HM_QP_NNP; n++) ratio = OCP_QP_IPM_MAX(ratio, r_v[n]);
    }
    return ratio;
}
