/*
 * ocp_qp_hsde.c: the fallback solver of ocp_qp_ipm_solve (ocp_qp_hsde.h): the homogeneous self-dual
 * embedding interior-point method, its start, iteration, solution and polish; with its own packed
 * row layout (ocp_qp_hsde_setup.c), residuals (ocp_qp_hsde_res.c) and Riccati factorisation
 * (ocp_qp_hsde_kkt.c). Runs when the primal-dual iteration stalls, from scratch, in the memory that
 * the primal-dual method's stage blocks otherwise occupy (ocp_qp_ipm_ws.u).
 */
#include "ocp_qp.h"
#include "ocp_qp_res.h"
#include "ocp_qp_hsde.h"
#include "ocp_qp_hsde_common.h"
#include "ocp_qp_hsde_kkt.h"
#include "ocp_qp_hsde_res.h"
#include "ocp_qp_hsde_setup.h"
#include "ocp_qp_kkt.h"

/* The tau pivot of the Newton system, -kappa/tau + c' v1 + b' w1 - v' P v / tau^2 for the constant
 * solve (v1, w1). Evaluated in the equal form -kappa/tau - (v1 - v/tau)' P (v1 - v/tau) -
 * sum_j z1_j^2 / w_j, negative by construction: near the solution the first form cancels to rounding
 * noise and can even come out positive. */
HM_FUNC hm_real ocp_qp_hsde_tau_pivot(const hm_ocp_qp *restrict qp, const hm_ocp_qp_hsde_ws *restrict ws,
                                     hm_real tinv)
{
    const hm_ocp_qp_hsde_vec *restrict v1 = &ws->v1;
    const hm_ocp_qp_hsde_vec *restrict v = &ws->v;
    hm_real acc = ws->kappa * tinv;
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        hm_real d[HM_QP_NUX], Hd[HM_QP_NUX];
        for (i = 0; i < HM_QP_NUX; i++) d[i] = v1->ux[n][i] - tinv * v->ux[n][i];
        ocp_qp_hsde_stage_hess_mul(qp, n, ws->cost_scale, d, Hd);
        for (i = 0; i < HM_QP_NUX; i++) acc += d[i] * Hd[i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[so + j];
            const hm_real ds = v1->s[ro + kr] - tinv * v->s[ro + kr];
            acc += ws->soft_Zl[so + j] * ds * ds;
        }
    }
    for (j = 0; j < ws->m; j++) acc += v1->z[j] * v1->z[j] * ocp_qp_hsde_weight(ws->t[j], v->z[j], ws->w_max).winv;
    return -acc;
}

/* y += a x on the (u, x), soft-slack and dynamics-multiplier parts (z is each caller's own). */
HM_FUNC void ocp_qp_hsde_vec_axpy_except_z(const hm_ocp_qp_hsde_ws *restrict ws, hm_real a,
                                         const hm_ocp_qp_hsde_vec *restrict x, hm_ocp_qp_hsde_vec *restrict y)
{
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        for (i = 0; i < HM_QP_NUX; i++) y->ux[n][i] += a * x->ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[so + j];
            y->s[ro + kr] += a * x->s[ro + kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) y->y[n][i] += a * x->y[n][i];
    }
}

/* The step (ws->dv, ws->dt, ws->dtau, ws->dkappa) that leaves (1 - keep) of the residuals, for the
 * complementarity targets t o z + z o dt + t o dz = t o z - ds (ds in ws->ds) and
 * tau kappa + kappa dtau + tau dkappa = tau kappa - dk. den is the tau pivot of this factorisation.
 * Returns the largest alpha in (0, 1] with t, z, tau, kappa + alpha * step >= 0 (dividing only
 * where a row shortens the step). */
HM_FUNC hm_real ocp_qp_hsde_direction(const hm_ocp_qp *restrict qp, hm_ocp_qp_hsde_ws *restrict ws, hm_real keep,
                                  hm_real dk, hm_real den)
{
    hm_ocp_qp_hsde_vec *restrict d = &ws->dv;
    const hm_ocp_qp_hsde_vec *restrict r = &ws->rv;
    const hm_ocp_qp_hsde_vec *restrict v1 = &ws->v1;
    const hm_real tau = ws->tau;
    hm_real dtau, a = HM_R(1.0);
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        for (i = 0; i < HM_QP_NUX; i++) d->ux[n][i] = -keep * r->ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[so + j];
            d->s[ro + kr] = -keep * r->s[ro + kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) d->y[n][i] = -keep * r->y[n][i];
    }
    for (j = 0; j < ws->m; j++) d->z[j] = ws->ds[j] * ocp_qp_hsde_weight(ws->t[j], ws->v.z[j], ws->w_max).zinv - keep * r->z[j];
    dtau = (dk / tau - keep * ws->rtau - ocp_qp_hsde_kkt_solve(qp, ws, d, d)) / den;
    ocp_qp_hsde_vec_axpy_except_z(ws, dtau, v1, d);
    ws->dtau = dtau;
    ws->dkappa = -(dk + ws->kappa * dtau) / tau;
    if (-ws->dtau * a > ws->tau) a = -ws->tau / ws->dtau;
    if (-ws->dkappa * a > ws->kappa) a = -ws->kappa / ws->dkappa;
    for (j = 0; j < ws->m; j++) {
        const hm_real dz = d->z[j] + dtau * v1->z[j];
        const hm_real tj = ws->t[j], zj = ws->v.z[j];
        const hm_real dtj = -(ws->ds[j] + tj * dz) * ocp_qp_hsde_weight(tj, zj, ws->w_max).zinv;
        d->z[j] = dz;
        ws->dt[j] = dtj;
        if (-dtj * a > tj) a = -tj / dtj;
        if (-dz * a > zj) a = -zj / dz;
    }
    return a;
}

/* Clarabel's shift of a starting vector into the interior of the nonnegative orthant. */
HM_FUNC void ocp_qp_hsde_shift_interior(hm_real *x, int m)
{
    hm_real mn = HM_INF, pos = HM_R(0.0), target;
    int j;
    if (m == 0) return;
    for (j = 0; j < m; j++) {
        mn = x[j] < mn ? x[j] : mn;
        pos += OCP_QP_HSDE_MAX(x[j], HM_R(0.0));
    }
    target = OCP_QP_HSDE_MAX(HM_R(1.0), HM_R(0.1) * pos / (hm_real)m);
    if (mn <= HM_R(0.0)) {
        /* in two stages: x - mn + target in one go can round x_min to 0 when target << |mn| */
        for (j = 0; j < m; j++) x[j] -= mn;
        for (j = 0; j < m; j++) x[j] += target;
    } else if (mn < target) {
        for (j = 0; j < m; j++) x[j] += target - mn;
    }
}

/* The right-hand side (-q, b) of the constant solve, into a. */
HM_FUNC void ocp_qp_hsde_constant_rhs(const hm_ocp_qp_hsde_ws *restrict ws, hm_ocp_qp_hsde_vec *restrict a)
{
    int n, i, j;
    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        for (i = 0; i < HM_QP_NUX; i++) a->ux[n][i] = -ws->q_ux[n][i];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[so + j];
            a->s[ro + kr] = -ws->q_s[ro + kr];
        }
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) a->y[n][i] = ws->b_eq[n][i];
    }
    for (j = 0; j < ws->m; j++) a->z[j] = ws->b_ineq[j];
}

/* sol := the point v (an iterate, or the polished solution) with the primal part scaled by sp
 * (1 / tau) and the multipliers by sc (1 / (tau * cost scale)); or, with sp = 0, the certificate
 * w scaled by sc (1 / -b'w). */
HM_FUNC void ocp_qp_hsde_write_sol(const hm_ocp_qp *qp, const hm_ocp_qp_hsde_ws *ws, const hm_ocp_qp_hsde_vec *v,
                                  hm_ocp_qp_sol *sol, hm_real sc, hm_real sp)
{
    int n, i, j, k;
    ocp_qp_sol_set_zero(sol);
    for (i = 0; i < HM_NX; i++) sol->x[0][i] = qp->x0[i];
    for (n = 0; n <= HM_N; n++) {
        const int so = ws->soff[n], ro = ws->roff[n];
        const int off = ws->off[n];
        const int base = off + ws->nb[n];
        const int nr = ws->nr[n];
        if (n < HM_N) {
            for (i = 0; i < HM_NU; i++) sol->u[n][i] = sp * v->ux[n][i];
            for (i = 0; i < HM_NX; i++) sol->pi[n][i] = -sc * v->y[n][i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) sol->x[n][i] = sp * v->ux[n][HM_NU + i];
        }
        for (k = 0; k < ws->nb[n]; k++) {
            const int c = ws->box_comp[n][k];
            const hm_real lam = sc * v->z[off + k];
            const int upper = ws->box_sign[n][k] > HM_R(0.0);
            if (c < HM_NU) {
                if (upper) sol->lam_ubu[n][c] = lam;
                else sol->lam_lbu[n][c] = lam;
            } else {
                if (upper) sol->lam_ubx[n][c - HM_NU] = lam;
                else sol->lam_lbx[n][c - HM_NU] = lam;
            }
        }
        for (k = 0; k < nr; k++) sol->lam_lg[n][ws->row_idx[ro + k]] = sc * v->z[base + k];
        for (j = 0; j < ws->ns[n]; j++) {
            const int kr = ws->soft_of[so + j];
            const int i_row = ws->row_idx[ro + kr];
            sol->s[n][i_row] = sp * v->s[ro + kr];
            sol->lam_ls[n][i_row] = sc * v->z[base + nr + j];
        }
    }
}

/* Starting point (Clarabel's for QPs): (v, w) solving the Newton system with unit row weights for
 * the right-hand side (-q, b), i.e. the minimiser of the cost plus 1/2 ||A_I v - b_I||^2 under the
 * dynamics; then t = b_I - A_I v and z, each shifted into the interior; tau = kappa = 1. */
HM_FUNC int ocp_qp_hsde_init(const hm_ocp_qp *qp, hm_ocp_qp_hsde_ws *ws)
{
    int j;
    for (j = 0; j < ws->m; j++) ws->w[j] = HM_R(1.0);
    if (ocp_qp_hsde_kkt_factorize(qp, ws)) return HM_QP_NUMERICAL;
    ocp_qp_hsde_constant_rhs(ws, &ws->v);
    ocp_qp_hsde_kkt_solve(qp, ws, &ws->v, &ws->v);
    for (j = 0; j < ws->m; j++) ws->t[j] = -ws->v.z[j];
    ocp_qp_hsde_shift_interior(ws->t, ws->m);
    ocp_qp_hsde_shift_interior(ws->v.z, ws->m);
    ws->tau = HM_R(1.0);
    ws->kappa = HM_R(1.0);
    return 0;
}

/* Active-set polish (after OSQP's): rows whose slack is smaller than their multiplier are taken as
 * active and become equalities, the others are dropped, and the QP is solved on that active set. An
 * interior-point iterate stops at complementarity ~ tol, where a constraint that is active with a
 * zero multiplier (degenerate) keeps a slack of ~sqrt(tol); the polished point has none. The
 * equality-constrained system is solved by the Riccati factorisation with the active rows held by the
 * largest row weight and the dropped ones by a negligible one, plus two steps of iterative
 * refinement against the exact system, which remove both that penalty error and the rounding error
 * of the large weights. A degenerate row can be taken as active and come out with a (tiny) negative
 * multiplier: such rows are dropped and the solve repeated once. The result replaces the iterate
 * only if its worst KKT residual is smaller. Costs one or two factorisations, three solves each. */
HM_FUNC void ocp_qp_hsde_polish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws)
{
    hm_ocp_qp_hsde_vec *d = &ws->dv;
    hm_ocp_qp_hsde_vec *e = &ws->v1;
    const hm_ocp_qp_hsde_vec *r = &ws->rv;
    /* dropped rows keep a weight far below rounding level, not zero: a soft row's slack may have
     * neither curvature nor an active bound, and its elimination divides by the sum of the three */
    const hm_real w_drop = HM_EPS * HM_EPS / ws->w_max;
    const hm_real before = ocp_qp_res_worst(&ws->out.res);
    hm_ocp_qp_res res;
    ocp_qp_hsde_sums sm;
    int j, k, n, i, round, dropped = 1;

    for (j = 0; j < ws->m; j++) ws->w[j] = ws->t[j] < ws->v.z[j] ? ws->w_max : w_drop;
    for (round = 0; round < 2 && dropped; round++) {
        if (ocp_qp_hsde_kkt_factorize(qp, ws)) return;
        ocp_qp_hsde_constant_rhs(ws, d);
        ocp_qp_hsde_kkt_solve(qp, ws, d, d);
        for (k = 0; k < 2; k++) {
            /* residual of the exact system: active rows a' v = b, dropped rows as factorised */
            for (j = 0; j < ws->m; j++) ws->dt[j] = ws->w[j] < ws->w_max ? -d->z[j] / ws->w[j] : HM_R(0.0);
            ocp_qp_hsde_residuals(qp, ws, d, ws->dt, HM_R(1.0), 0, &sm);
            for (n = 0; n <= HM_N; n++) {
                const int so = ws->soff[n], ro = ws->roff[n];
                for (i = 0; i < HM_QP_NUX; i++) e->ux[n][i] = -r->ux[n][i];
                for (j = 0; j < ws->ns[n]; j++) {
                    const int kr = ro + ws->soft_of[so + j];
                    e->s[kr] = -r->s[kr];
                }
            }
            for (n = 0; n < HM_N; n++) {
                for (i = 0; i < HM_NX; i++) e->y[n][i] = -r->y[n][i];
            }
            for (j = 0; j < ws->m; j++) e->z[j] = -r->z[j];
            ocp_qp_hsde_kkt_solve(qp, ws, e, e);
            for (n = 0; n <= HM_N; n++) {
                const int so = ws->soff[n], ro = ws->roff[n];
                for (i = 0; i < HM_QP_NUX; i++) d->ux[n][i] += e->ux[n][i];
                for (j = 0; j < ws->ns[n]; j++) {
                    const int kr = ro + ws->soft_of[so + j];
                    d->s[kr] += e->s[kr];
                }
            }
            for (n = 0; n < HM_N; n++) {
                for (i = 0; i < HM_NX; i++) d->y[n][i] += e->y[n][i];
            }
            for (j = 0; j < ws->m; j++) d->z[j] += e->z[j];
        }
        dropped = 0;
        for (j = 0; j < ws->m; j++) {
            if (ws->w[j] < ws->w_max) {
                d->z[j] = HM_R(0.0);
            } else if (d->z[j] < HM_R(0.0)) {
                ws->w[j] = w_drop;
                dropped = 1;
            }
        }
    }
    ocp_qp_hsde_write_sol(qp, ws, d, sol, HM_R(1.0) / ws->cost_scale, HM_R(1.0));
    ocp_qp_res_compute(qp, sol, &res);
    if (ocp_qp_res_worst(&res) < before) {
        ws->out.res = res;
        ws->out.polished = 1;
    } else {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / (ws->tau * ws->cost_scale), HM_R(1.0) / ws->tau);
    }
}

/* Ends a solve: the solution, the certificate (with b' w = bw) or zeros (before the first iterate,
 * or for non-finite iterates) into sol, its residuals into ws->out.res. */
HM_FUNC int ocp_qp_hsde_finish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws, int status,
                              hm_real bw, int have_iterate, int polish)
{
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / -bw, HM_R(0.0));
    } else if (status == HM_QP_NONFINITE || !have_iterate) {
        ocp_qp_sol_set_zero(sol);
    } else {
        ocp_qp_hsde_write_sol(qp, ws, &ws->v, sol, HM_R(1.0) / (ws->tau * ws->cost_scale), HM_R(1.0) / ws->tau);
    }
    ocp_qp_res_compute(qp, sol, &ws->out.res);
    if (status == HM_QP_SOLVED && polish) ocp_qp_hsde_polish(qp, sol, ws);
    ws->out.status = status;
    return status;
}

HM_FUNC int ocp_qp_hsde_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_hsde_ws *ws,
                             const hm_ocp_qp_ipm_arg *arg)
{
    int status, bad = 0, j;
    ocp_qp_hsde_sums sm;
    hm_real mu0 = HM_R(1.0);

    ws->out.iter = 0;
    ws->out.unbounded = 0;
    ws->out.polished = 0;
    ws->out.res_primal = ws->out.res_dual = ws->out.gap = ws->out.mu = HM_R(0.0);
    ws->tau = ws->kappa = HM_R(1.0);

    status = ocp_qp_check(qp);
    if (status) return ocp_qp_hsde_finish(qp, sol, ws, status, HM_R(0.0), 0, 0);
    status = ocp_qp_hsde_setup(qp, ws, &bad);
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_sol_box_certificate(qp, sol, bad);
        ocp_qp_res_compute(qp, sol, &ws->out.res);
        ws->out.status = status;
        return status;
    }
    if (status) return ocp_qp_hsde_finish(qp, sol, ws, status, HM_R(0.0), 0, 0);
    status = ocp_qp_hsde_init(qp, ws);
    if (status) return ocp_qp_hsde_finish(qp, sol, ws, status, HM_R(0.0), 0, 0);

    for (;;) {
        const hm_real mdeg = (hm_real)(ws->m + 1);
        hm_real mu, tinv, res_p, res_d, pcost, gap, gap_rel, den, sigma, dk, alpha_aff, corr, frac, alpha;

        ocp_qp_hsde_residuals(qp, ws, &ws->v, ws->t, ws->tau, 1, &sm);
        mu = (sm.tz + ws->tau * ws->kappa) / mdeg;
        if (ws->out.iter == 0) mu0 = mu;
        ws->out.mu = mu;
        if (!isfinite(mu + sm.rd + sm.rp + ws->rtau + sm.nv + sm.nw)) {
            status = HM_QP_NONFINITE;
            break;
        }

        /* termination tests on the QP point v / tau */
        tinv = HM_R(1.0) / ws->tau;
        res_p = sm.rp * tinv / OCP_QP_HSDE_MAX(HM_R(1.0), ws->norm_b + (sm.nv + sm.nt) * tinv);
        res_d = sm.rd * tinv / OCP_QP_HSDE_MAX(HM_R(1.0), ws->norm_q + (sm.nv + sm.nw) * tinv);
        /* the complementarity t' z of the QP point (= primal - dual cost once the residuals vanish,
         * but without the cancellation of those two large numbers), absolute and relative to the
         * cost, in the units of the data */
        pcost = (sm.qv * tinv + HM_R(0.5) * sm.vPv * tinv * tinv) / ws->cost_scale;
        gap = sm.tz * tinv * tinv / ws->cost_scale;
        gap_rel = gap / OCP_QP_HSDE_MAX(HM_R(1.0), hm_fabs(pcost));
        ws->out.res_primal = res_p;
        ws->out.res_dual = res_d;
        ws->out.gap = gap_rel;
        if (ws->kappa <= ws->tau && res_p <= arg->tol && res_d <= arg->tol
            && (gap <= arg->tol || gap_rel <= arg->tol)) {
            status = HM_QP_SOLVED;
            break;
        }
        if (ws->kappa > ws->tau) {
            if (sm.bw < HM_R(0.0) && sm.atw <= arg->tol_infeas * -sm.bw) {
                status = HM_QP_INFEASIBLE;
                break;
            }
            const hm_real cinv = HM_R(1.0) / ws->cost_scale;
            if (arg->detect_unbounded && sm.qv < HM_R(0.0)
                && OCP_QP_HSDE_MAX(sm.pv * cinv, OCP_QP_HSDE_MAX(sm.av_eq, sm.av_ineq)) <= arg->tol_infeas * -sm.qv * cinv) {
                ws->out.unbounded = 1;
                status = HM_QP_NUMERICAL;
                break;
            }
        }
        if (ws->out.iter >= arg->max_iter) {
            status = HM_QP_MAX_ITER;
            break;
        }
        /* the residuals have met their rounding floor above tol: going on only drives mu into
         * underflow and the iterates into noise */
        if (mu < mu0 * HM_EPS * HM_EPS) {
            status = HM_QP_NUMERICAL;
            break;
        }
        if (arg->should_stop && arg->should_stop(arg->stop_ctx)) {
            status = HM_QP_TIMEOUT;
            break;
        }
        ws->out.iter++;

        /* Newton matrix (weights from ocp_qp_hsde_residuals), and its solve for the constant right-hand
         * side (v1, w1) = K^-1 (-q, b) */
        if (ocp_qp_hsde_kkt_factorize(qp, ws)) {
            status = HM_QP_NUMERICAL;
            break;
        }
        ocp_qp_hsde_constant_rhs(ws, &ws->v1);
        ocp_qp_hsde_kkt_solve(qp, ws, &ws->v1, &ws->v1);
        den = ocp_qp_hsde_tau_pivot(qp, ws, tinv);
        if (!(den < HM_R(0.0))) {
            status = isfinite(den) ? HM_QP_NUMERICAL : HM_QP_NONFINITE;
            break;
        }

        /* affine predictor */
        for (j = 0; j < ws->m; j++) ws->ds[j] = ws->t[j] * ws->v.z[j];
        alpha_aff = ocp_qp_hsde_direction(qp, ws, HM_R(1.0), ws->tau * ws->kappa, den);
        sigma = (HM_R(1.0) - alpha_aff) * (HM_R(1.0) - alpha_aff) * (HM_R(1.0) - alpha_aff);

        /* Mehrotra corrector, with only part of the second-order term in the first iteration, whose
         * start may be far from central */
        corr = ws->out.iter > 1 ? HM_R(1.0) : alpha_aff;
        for (j = 0; j < ws->m; j++) ws->ds[j] += corr * ws->dt[j] * ws->dv.z[j] - sigma * mu;
        dk = ws->tau * ws->kappa + corr * ws->dtau * ws->dkappa - sigma * mu;
        alpha = ocp_qp_hsde_direction(qp, ws, HM_R(1.0) - sigma, dk, den);

        /* fraction to the boundary: arg->step_frac far from the solution, closer to 1 as mu falls
         * (relative to its start, so the rule does not depend on the data's units), which turns the
         * last iterations' linear rate 1 - step_frac into a superlinear one; never so close that t
         * or z could round to zero */
        frac = hm_fmin(HM_R(1.0) - mu / mu0, HM_R(1.0) - hm_sqrt(HM_EPS));
        alpha *= OCP_QP_HSDE_MAX(arg->step_frac, frac);
        if (!(alpha >= arg->min_step)) {
            status = isfinite(alpha) ? HM_QP_NUMERICAL : HM_QP_NONFINITE;
            break;
        }
        {
            hm_ocp_qp_hsde_vec *restrict v = &ws->v;
            const hm_ocp_qp_hsde_vec *restrict dv = &ws->dv;
            ocp_qp_hsde_vec_axpy_except_z(ws, alpha, dv, v);
            for (j = 0; j < ws->m; j++) {
                v->z[j] += alpha * dv->z[j];
                ws->t[j] += alpha * ws->dt[j];
            }
        }
        ws->tau += alpha * ws->dtau;
        ws->kappa += alpha * ws->dkappa;
    }
    return ocp_qp_hsde_finish(qp, sol, ws, status, sm.bw, 1, arg->polish);
}
