/*
 * ocp_qp_ipm_sol.c: the QP solution in the conventions of ocp_qp.h, written at the end of a solve
 * from the interior-point iterate (unscaled), from the polished vector, or from a certificate.
 */
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_sol.h"

/* ------------------------------------------------------------------------------------------------
 * Output
 * ---------------------------------------------------------------------------------------------- */

/* Multipliers and slacks of stage n into sol from the given inequality values (stage blocks or a
 * vector); sc scales the multipliers, sp the slacks. */
HM_FUNC void ocp_qp_ipm_write_stage(const hm_ocp_qp_ipm_stage *sn, const hm_ocp_qp_ipm_bounds *bd,
                                    const hm_ocp_qp_ipm_rows *sr, int n,
                                    hm_ocp_qp_sol *sol,
                                    const hm_real (*zb)[2], const hm_real *s, const hm_real *zr,
                                    const hm_real *zs, const hm_real *zh, hm_real sc, hm_real sp)
{
    int i, k, j;
    for (i = 0; i < HM_NG; i++) {
        sol->s[n][i] = HM_R(0.0);
        sol->lam_lg[n][i] = HM_R(0.0);
        sol->lam_ls[n][i] = HM_R(0.0);
    }
    for (i = 0; i < HM_NX; i++) {
        sol->lam_lbx[n][i] = HM_R(0.0);
        sol->lam_ubx[n][i] = HM_R(0.0);
    }
    if (n < HM_N) {
        for (i = 0; i < HM_NU; i++) {
            sol->lam_lbu[n][i] = HM_R(0.0);
            sol->lam_ubu[n][i] = HM_R(0.0);
        }
    }
    for (k = 0; k < bd->nbp; k++) {
        const int c = bd->bc[k];
        hm_real lo, up;
        if (c < HM_NU ? n == HM_N : n == 0) continue;   /* the slot's component is not part of stage n */
        /* an absent side has sign 0: its multiplier is written as 0 */
        lo = sc * bd->sg[k][0][n] * bd->sg[k][0][n] * zb[k][0];
        up = sc * bd->sg[k][1][n] * bd->sg[k][1][n] * zb[k][1];
        if (c < HM_NU) {
            sol->lam_lbu[n][c] = lo;
            sol->lam_ubu[n][c] = up;
        } else {
            sol->lam_lbx[n][c - HM_NU] = lo;
            sol->lam_ubx[n][c - HM_NU] = up;
        }
    }
    for (j = 0; j < sn->ns; j++) {
        const int row = sn->soff + j;
        const int i_row = sr->srow[row];
        sol->s[n][i_row] = sp * s[j];
        sol->lam_lg[n][i_row] = sc * zr[j];
        sol->lam_ls[n][i_row] = sc * zs[j];
    }
    for (j = 0; j < sn->nh; j++) sol->lam_lg[n][sn->hr->hrow[j]] = sc * zh[j];
}

/* sol := the iterate with the primal part scaled by sp (1) and the multipliers by sc
 * (1 / cost scale); or, with sp = 0, the certificate w scaled by sc (1 / -b'w). */
HM_FUNC void ocp_qp_ipm_write_sol(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_ocp_qp_sol *sol,
                                  hm_real sc, hm_real sp)
{
    int n, i;
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        if (n < HM_N) {
            for (i = 0; i < HM_NU; i++) sol->u[n][i] = sp * sn->ux[i];
            for (i = 0; i < HM_NX; i++) sol->pi[n][i] = -sc * sn->y[i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) sol->x[n][i] = sp * sn->ux[HM_NU + i];
        }
        hm_real zb[HM_QP_NUX][2];
        int k;
        for (k = 0; k < ws->u.f.bd.nbp; k++) {
            zb[k][0] = ws->u.f.bd.z[k][0][n];
            zb[k][1] = ws->u.f.bd.z[k][1][n];
        }
        ocp_qp_ipm_write_stage(sn, &ws->u.f.bd, &ws->u.f.sr, n, sol, (const hm_real (*)[2])zb,
                               &ws->u.f.sr.ss[sn->soff], &ws->u.f.sr.sz[sn->soff], &ws->u.f.sr.szs[sn->soff], sn->hr->hz,
                               sc, sp);
    }
}

/* sol := the ray of ocp_qp_ipm_farkas_step (the last step's multiplier steps clipped at 0) scaled by
 * sc (1 / -b'w), primal part zero but x_0 = x0: the certificate of an infeasible QP. */
HM_FUNC void ocp_qp_ipm_write_sol_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_ocp_qp_sol *sol, hm_real sc)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    int n, i, k, j;
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        /* the stage's clipped multiplier steps, written as write_stage writes an iterate's (slacks 0) */
        hm_real zb[HM_QP_NUX][2], zr[HM_NG], zs[HM_NG], zh[HM_NG], none[HM_NG];
        if (n < HM_N) {
            for (i = 0; i < HM_NU; i++) sol->u[n][i] = HM_R(0.0);
            for (i = 0; i < HM_NX; i++) sol->pi[n][i] = -sc * sn->dy[i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) sol->x[n][i] = HM_R(0.0);
        }
        for (k = 0; k < bd->nbp; k++) {
            zb[k][0] = OCP_QP_IPM_MAX(bd->dz[k][0][n], HM_R(0.0));
            zb[k][1] = OCP_QP_IPM_MAX(bd->dz[k][1][n], HM_R(0.0));
        }
        for (j = 0; j < sn->ns; j++) {
            zr[j] = OCP_QP_IPM_MAX(sr->sdz[sn->soff + j], HM_R(0.0));
            zs[j] = OCP_QP_IPM_MAX(sr->sdzs[sn->soff + j], HM_R(0.0));
            none[j] = HM_R(0.0);
        }
        for (j = 0; j < sn->nh; j++) zh[j] = OCP_QP_IPM_MAX(sn->hr->hdz[j], HM_R(0.0));
        ocp_qp_ipm_write_stage(sn, bd, sr, n, sol, (const hm_real (*)[2])zb, none, zr, zs, zh, sc, HM_R(1.0));
    }
}

#ifdef HM_QP_POLISH
/* The same from a vector in the solver's layout (the polished solution). */
HM_FUNC void ocp_qp_ipm_write_sol_vec(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws,
                                      const hm_ocp_qp_ipm_vec *v, hm_ocp_qp_sol *sol, hm_real sc)
{
    int n, i;
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    for (n = 0; n <= HM_N; n++) {
        if (n < HM_N) {
            for (i = 0; i < HM_NU; i++) sol->u[n][i] = v->ux[n][i];
            for (i = 0; i < HM_NX; i++) sol->pi[n][i] = -sc * v->y[n][i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) sol->x[n][i] = v->ux[n][HM_NU + i];
        }
        ocp_qp_ipm_write_stage(&ws->u.f.st[n], &ws->u.f.bd, &ws->u.f.sr, n, sol, (const hm_real (*)[2])v->zb[n],
                               v->s[n], v->zr[n], v->zs[n], v->zh[n], sc, HM_R(1.0));
    }
}
#endif
