/*
 * ocp_qp_ipm_polish.c: the active-set polish of a solved QP (arg->polish): the inequalities that look
 * active taken as equalities, the QP solved on them by the general Riccati solve with iterative
 * refinement, the active set corrected and solved again (six solves at most), the result kept only
 * if it improves the worst KKT residual. Runs at the end of a solve, on the solve's memory.
 */
#include "ocp_qp.h"
#include "ocp_qp_res.h"
#include "ocp_qp_kkt.h"
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_polish.h"
#include "ocp_qp_ipm_sol.h"

#ifdef HM_QP_POLISH
/* ------------------------------------------------------------------------------------------------
 * Active-set polish
 * ---------------------------------------------------------------------------------------------- */

/* Residual of the Newton system with the polish's weights at (d, dz), as rhs - K d, written as
 * e = -(K d - rhs) for the constant right-hand side (-q, b): e.ux = -(P v + q + A' w),
 * e.y = -(A_E v - b_E), e.z = -(A_I v + t - b_I) with t = 0 on active inequalities and -dz / w on
 * dropped ones (as factorised). */
HM_FUNC void ocp_qp_ipm_polish_residual(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws,
                                        const hm_ocp_qp_ipm_vec *d, hm_ocp_qp_ipm_vec *e)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    const hm_ocp_qp_ipm_general *gs = &ws->u.f.gs;
    const hm_real wmax = ws->w_max;
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const hm_real *ux = d->ux[n];
        hm_real r[HM_QP_NUX];
        ocp_qp_ipm_hess_mul(qp, n, ws->cost_scale, ux, r);
        for (i = 0; i < HM_QP_NUX; i++) r[i] += sn->q[i];
        if (n < HM_N) {
            const hm_real *B = qp->B[n];
            const hm_real *A = qp->A[n];
            const hm_real *y = d->y[n];
            hm_real ex[HM_NX];
            for (i = 0; i < HM_NU; i++) r[i] -= ocp_qp_kkt_dot4(B + i * HM_NX, y);
            if (n > 0) {
                for (i = 0; i < HM_NX; i++) r[HM_NU + i] -= ocp_qp_kkt_dot4(A + i * HM_NX, y);
            }
            for (i = 0; i < HM_NX; i++) {
                hm_real acc = d->ux[n + 1][HM_NU + i] - B[i] * ux[0] - B[i + HM_NX] * ux[1] - sn->beq[i];
                if (n > 0) {
                    for (k = 0; k < HM_NX; k++) acc -= A[i + k * HM_NX] * ux[HM_NU + k];
                }
                ex[i] = acc;
            }
            for (i = 0; i < HM_NX; i++) e->y[n][i] = -ex[i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) r[HM_NU + i] += d->y[n - 1][i];
        }
        for (k = 0; k < bd->nbp; k++) {
            const int c = bd->bc[k];
            for (l = 0; l < 2; l++) {
                const hm_real w = bd->w[k][l][n];
                const hm_real t = w < wmax ? -d->zb[n][k][l] / w : HM_R(0.0);
                r[c] += bd->sg[k][l][n] * d->zb[n][k][l];
                e->zb[n][k][l] = -(bd->sg[k][l][n] * ux[c] + t - bd->b[k][l][n]);
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real gp = sr->sd0[row] * ux[HM_NU] + sr->sd1[row] * ux[HM_NU + 1];
            const hm_real tr = gs->swr[row] < wmax ? -d->zr[n][j] / gs->swr[row] : HM_R(0.0);
            const hm_real ts = gs->sws[row] < wmax ? -d->zs[n][j] / gs->sws[row] : HM_R(0.0);
            r[HM_NU] -= sr->sd0[row] * d->zr[n][j];
            r[HM_NU + 1] -= sr->sd1[row] * d->zr[n][j];
            e->s[n][j] = -(sr->sZl[row] * d->s[n][j] + sr->szl[row] - d->zr[n][j] - d->zs[n][j]);
            e->zr[n][j] = -(tr - gp - d->s[n][j] + sr->slg[row]);
            e->zs[n][j] = -(ts - d->s[n][j]);
        }
        for (j = 0; j < sn->nh; j++) {
            const hm_real gp = sn->hr->hd0[j] * ux[HM_NU] + sn->hr->hd1[j] * ux[HM_NU + 1];
            const hm_real t = sn->hr->hw[j] < wmax ? -d->zh[n][j] / sn->hr->hw[j] : HM_R(0.0);
            r[HM_NU] -= sn->hr->hd0[j] * d->zh[n][j];
            r[HM_NU + 1] -= sn->hr->hd1[j] * d->zh[n][j];
            e->zh[n][j] = -(t - gp + sn->hr->hlg[j]);
        }
        for (i = 0; i < HM_QP_NUX; i++) e->ux[n][i] = -r[i];
    }
}

/* d += e over the parts of the vector in use */
HM_FUNC void ocp_qp_ipm_vec_add(const hm_ocp_qp_ipm_ws *ws, hm_ocp_qp_ipm_vec *d, const hm_ocp_qp_ipm_vec *e)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    int n, i, k, j;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) d->ux[n][i] += e->ux[n][i];
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) d->y[n][i] += e->y[n][i];
        }
        for (k = 0; k < bd->nbp; k++) {
            d->zb[n][k][0] += e->zb[n][k][0];
            d->zb[n][k][1] += e->zb[n][k][1];
        }
        for (j = 0; j < sn->ns; j++) {
            d->s[n][j] += e->s[n][j];
            d->zr[n][j] += e->zr[n][j];
            d->zs[n][j] += e->zs[n][j];
        }
        for (j = 0; j < sn->nh; j++) d->zh[n][j] += e->zh[n][j];
    }
}

/* The active-set update of one inequality after a polish solve with multiplier *z and slack
 * `slack` (b - a' v): an active one (weight wmax) whose multiplier came out negative is dropped, a
 * dropped one that the solution violates is made active (*changed = 1 either way), and a dropped one
 * gets the multiplier 0. Returns the new weight. */
HM_FUNC hm_real ocp_qp_ipm_polish_weight(hm_real w, hm_real *z, hm_real slack, hm_real wmax, hm_real w_drop,
                                         int *changed)
{
    if (w < wmax) {
        *z = HM_R(0.0);
        if (slack < HM_R(0.0)) {
            *changed = 1;
            return wmax;
        }
        return w;
    }
    if (*z < HM_R(0.0)) {
        *changed = 1;
        return w_drop;
    }
    return w;
}

/* Whether an inequality with slack t and multiplier z, reached by the step alpha (dt, dz), looks
 * active: by Tapia's indicators, the multiplier kept more of its value over the last step than the
 * slack did (the slack of an active one falls to zero, its multiplier converges); without a step
 * (alpha = 0), the slack is smaller than the multiplier. */
HM_FUNC int ocp_qp_ipm_polish_active(hm_real t, hm_real z, hm_real dt, hm_real dz, hm_real alpha)
{
    const hm_real tp = t - alpha * dt, zp = z - alpha * dz;
    if (alpha > HM_R(0.0) && tp > HM_R(0.0) && zp > HM_R(0.0)) return z * tp > t * zp;
    return t < z;
}

/* Whether some inequality is undecided at the end of a solve: over the last step (alpha, dt, dz)
 * neither its slack nor its multiplier fell below UNDEC of its value (a strictly complementary pair
 * converges with one of them going to zero superlinearly; a degenerate one, both at a linear rate,
 * which leaves the primal point sqrt(mu) away from the solution). */
#ifndef OCP_QP_IPM_UNDEC
#define OCP_QP_IPM_UNDEC HM_R(0.1)
#endif
HM_FUNC int ocp_qp_ipm_undecided_pair(hm_real t, hm_real z, hm_real dt, hm_real dz, hm_real alpha)
{
    const hm_real tp = t - alpha * dt, zp = z - alpha * dz;
    return t > OCP_QP_IPM_UNDEC * tp && z > OCP_QP_IPM_UNDEC * zp;
}

HM_FUNC int ocp_qp_ipm_undecided(const hm_ocp_qp_ipm_ws *ws, hm_real alpha)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    int n, k, l, j;
    if (!(alpha > HM_R(0.0))) return 0;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                if (bd->sg[k][l][n] != HM_R(0.0)
                    && ocp_qp_ipm_undecided_pair(bd->t[k][l][n], bd->z[k][l][n], bd->dt[k][l][n], bd->dz[k][l][n],
                                                 alpha))
                    return 1;
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            if (ocp_qp_ipm_undecided_pair(sr->st[row], sr->sz[row], sr->sdt[row], sr->sdz[row], alpha)
                || ocp_qp_ipm_undecided_pair(sr->ss[row], sr->szs[row], sr->sds[row], sr->sdzs[row], alpha))
                return 1;
        }
        for (j = 0; j < sn->nh; j++) {
            if (ocp_qp_ipm_undecided_pair(sn->hr->ht[j], sn->hr->hz[j], sn->hr->hdt[j], sn->hr->hdz[j], alpha)) return 1;
        }
    }
    return 0;
}

/* Active-set polish (after OSQP's): inequalities that look active (ocp_qp_ipm_polish_active) are
 * taken as equalities, the others are dropped, and the QP is solved on that
 * active set. An interior-point iterate stops at complementarity ~ tol, where a constraint that is
 * active with a zero multiplier (degenerate) keeps a slack of ~sqrt(tol); the polished point has
 * none. The equality-constrained system is solved by the Riccati factorisation with the active
 * inequalities held by the largest weight and the dropped ones by a negligible one, plus two steps of
 * iterative refinement against the exact system, which remove both that penalty error and the
 * rounding error of the large weights. A degenerate inequality can be taken as active and come out
 * with a (tiny) negative multiplier, or be taken as inactive and come out violated: such are moved
 * to the other side and the solve repeated (at most six solves). The result replaces the iterate
 * only if its worst KKT residual is smaller. */
HM_FUNC void ocp_qp_ipm_polish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws, hm_real alpha)
{
    hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_ocp_qp_ipm_general *gs = &ws->u.f.gs;
    hm_ocp_qp_ipm_vec *d = &ws->u.f.gs.va;
    hm_ocp_qp_ipm_vec *e = &ws->u.f.gs.vb;
    const hm_real wmax = ws->w_max;
    /* dropped inequalities keep a weight far below rounding level, not zero: a soft row's slack may
     * have neither curvature nor an active bound, and its elimination divides by the sum of three */
    const hm_real w_drop = HM_EPS * HM_EPS / wmax;
    const hm_real before = ocp_qp_res_worst(&ws->out.res);
    hm_ocp_qp_res res;
    int n, i, k, j, l, round, changed = 1;

    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                /* an absent side: dropped (its sign 0 keeps it out of the system anyway) */
                const int act = bd->sg[k][l][n] != HM_R(0.0)
                                && ocp_qp_ipm_polish_active(bd->t[k][l][n], bd->z[k][l][n], bd->dt[k][l][n],
                                                            bd->dz[k][l][n], alpha);
                bd->w[k][l][n] = act ? wmax : w_drop;
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const int row_on = ocp_qp_ipm_polish_active(sr->st[row], sr->sz[row], sr->sdt[row], sr->sdz[row], alpha);
            const int slack_on = ocp_qp_ipm_polish_active(sr->ss[row], sr->szs[row], sr->sds[row], sr->sdzs[row], alpha);
            gs->swr[row] = row_on ? wmax : w_drop;
            gs->sws[row] = slack_on ? wmax : w_drop;
        }
        for (j = 0; j < sn->nh; j++) {
            hm_ocp_qp_ipm_hard *h = sn->hr;
            h->hw[j] = ocp_qp_ipm_polish_active(h->ht[j], h->hz[j], h->hdt[j], h->hdz[j], alpha) ? wmax : w_drop;
        }
    }
    for (round = 0; round < 6 && changed; round++) {
        ocp_qp_kkt_condense_weights(ws);
        if (ocp_qp_kkt_factorize(qp, ws)) {
#ifdef OCP_QP_IPM_TRACE
            printf("polish: factorisation failed\n");
#endif
            return;
        }
        /* the constant right-hand side (-q, b) */
        for (n = 0; n <= HM_N; n++) {
            const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
            for (i = 0; i < HM_QP_NUX; i++) e->ux[n][i] = -sn->q[i];
            if (n < HM_N) {
                for (i = 0; i < HM_NX; i++) e->y[n][i] = sn->beq[i];
            }
            for (k = 0; k < bd->nbp; k++) {
                e->zb[n][k][0] = bd->b[k][0][n];
                e->zb[n][k][1] = bd->b[k][1][n];
            }
            for (j = 0; j < sn->ns; j++) {
                const int row = sn->soff + j;
                e->s[n][j] = -sr->szl[row];
                e->zr[n][j] = -sr->slg[row];
                e->zs[n][j] = HM_R(0.0);
            }
            for (j = 0; j < sn->nh; j++) e->zh[n][j] = -sn->hr->hlg[j];
        }
        ocp_qp_kkt_solve(qp, ws, e, d);
        for (k = 0; k < 2; k++) {
            ocp_qp_ipm_polish_residual(qp, ws, d, e);
            ocp_qp_kkt_solve(qp, ws, e, e);
            ocp_qp_ipm_vec_add(ws, d, e);
        }
        changed = 0;
        for (n = 0; n <= HM_N; n++) {
            hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
            const hm_real *v = d->ux[n];
            for (k = 0; k < bd->nbp; k++) {
                for (l = 0; l < 2; l++) {
                    const hm_real slack = bd->b[k][l][n] - bd->sg[k][l][n] * v[bd->bc[k]];
                    bd->w[k][l][n] = ocp_qp_ipm_polish_weight(bd->w[k][l][n], &d->zb[n][k][l], slack, wmax, w_drop,
                                                              &changed);
                }
            }
            for (j = 0; j < sn->ns; j++) {
                const int row = sn->soff + j;
                const hm_real g = sr->sd0[row] * v[HM_NU] + sr->sd1[row] * v[HM_NU + 1] + d->s[n][j] - sr->slg[row];
                gs->swr[row] = ocp_qp_ipm_polish_weight(gs->swr[row], &d->zr[n][j], g, wmax, w_drop, &changed);
                gs->sws[row] = ocp_qp_ipm_polish_weight(gs->sws[row], &d->zs[n][j], d->s[n][j], wmax, w_drop, &changed);
            }
            for (j = 0; j < sn->nh; j++) {
                const hm_real g = sn->hr->hd0[j] * v[HM_NU] + sn->hr->hd1[j] * v[HM_NU + 1] - sn->hr->hlg[j];
                sn->hr->hw[j] = ocp_qp_ipm_polish_weight(sn->hr->hw[j], &d->zh[n][j], g, wmax, w_drop, &changed);
            }
        }
    }
    ocp_qp_ipm_write_sol_vec(qp, ws, d, sol, HM_R(1.0) / ws->cost_scale);
    ocp_qp_res_compute(qp, sol, &res);
#ifdef OCP_QP_IPM_TRACE
    printf("polish: before %.3e after %.3e (stat %.2e eq %.2e ineq %.2e comp %.2e dual %.2e)\n", (double)before,
           (double)ocp_qp_res_worst(&res), (double)res.stat, (double)res.eq, (double)res.ineq, (double)res.comp, (double)res.dual);
#endif
    if (ocp_qp_res_worst(&res) < before) {
        ws->out.res = res;
        ws->out.polished = 1;
    } else {
        ocp_qp_ipm_write_sol(qp, ws, sol, HM_R(1.0) / ws->cost_scale, HM_R(1.0));
    }
}
#endif /* HM_QP_POLISH */
