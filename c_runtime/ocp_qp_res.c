/*
 * ocp_qp_res.c: the KKT residuals of a primal-dual pair of the stage-structured QP (ocp_qp_res.h),
 * measured after a solve (the QP solvers, the polish) and at the SQP's linearisation point (the
 * NLP's residuals). Stateless.
 */
#include "ocp_qp.h"
#include "ocp_qp_res.h"

/* The residuals' running maxima. Each is a plain max, b > a ? b : a (one instruction); the NaNs are
 * noted on the side and make their maximum NaN at the end, so that a broken solution cannot look
 * like a good one. (A max that propagated the NaN itself compiled to compares and data-dependent
 * branches per entry, which mispredicted: 3.5 % of an RTI step went to the NLP's residuals.) */
typedef struct {
    hm_ocp_qp_res r;
    int nan_stat, nan_eq, nan_ineq, nan_comp, nan_dual;
} ocp_qp_res_acc;

#define OCP_QP_RES_MAX(ra, field, value)                                                           \
    do {                                                                                           \
        const hm_real v_ = (value);                                                                \
        (ra)->nan_##field |= v_ != v_;                                                             \
        (ra)->r.field = v_ > (ra)->r.field ? v_ : (ra)->r.field;                                   \
    } while (0)

/* Violation of lb <= v <= ub, complementarity and multiplier signs of one bounded component. */
HM_KERNEL void ocp_qp_res_bound(hm_real v, hm_real lb, hm_real ub, hm_real lam_lb, hm_real lam_ub,
                                ocp_qp_res_acc *ra)
{
    if (ocp_qp_bound_present(lb)) {
        OCP_QP_RES_MAX(ra, ineq, lb - v);
        OCP_QP_RES_MAX(ra, comp, hm_fabs(lam_lb * (v - lb)));
    }
    if (ocp_qp_bound_present(ub)) {
        OCP_QP_RES_MAX(ra, ineq, v - ub);
        OCP_QP_RES_MAX(ra, comp, hm_fabs(lam_ub * (ub - v)));
    }
    OCP_QP_RES_MAX(ra, dual, -lam_lb);
    OCP_QP_RES_MAX(ra, dual, -lam_ub);
}

/* The residuals of ocp_qp_res_compute, at sol's primal point or (zero = 1, a constant in each caller
 * so that the compiler drops the products with zeros) at u = 0 and x_n = 0 for n >= 1 with the soft
 * rows' slacks max(0, lg), where sol's u, x_1..x_N and s are not read (ocp_qp_res_at_zero_step). */
HM_KERNEL void ocp_qp_res_eval(const hm_ocp_qp *qp, const hm_ocp_qp_sol *sol, int zero, hm_ocp_qp_res *out)
{
    static const hm_real origin[HM_NU + HM_NX] = {HM_R(0.0)};
    /* accumulated in a local copy: through the caller's pointer every max would be a store and a
     * reload */
    ocp_qp_res_acc local;
    ocp_qp_res_acc *ra = &local;
    hm_ocp_qp_res *res = &local.r;
    int n, i, j, k, ng_n;
    hm_real obj = HM_R(0.0);
    res->stat = HM_R(0.0);
    res->eq = HM_R(0.0);
    res->ineq = HM_R(0.0);
    res->comp = HM_R(0.0);
    res->dual = HM_R(0.0);
    ra->nan_stat = ra->nan_eq = ra->nan_ineq = ra->nan_comp = ra->nan_dual = 0;
    if (!zero) {
        for (j = 0; j < HM_NX; j++) OCP_QP_RES_MAX(ra, eq, hm_fabs(sol->x[0][j] - qp->x0[j]));
    }

    for (n = 0; n <= HM_N; n++) {
        /* the problem fixes x_0: stage 0 is evaluated at qp->x0, not at whatever sol->x[0] holds */
        const hm_real *x = n == 0 ? qp->x0 : (zero ? origin : sol->x[n]);
        const int moved = !zero || n == 0;   /* x_n can be nonzero */
        hm_real gx[HM_NX], gu[HM_NU];
        for (i = 0; i < HM_NX; i++) {
            hm_real acc = qp->q[n][i];
            if (moved) {
                for (k = 0; k < HM_NX; k++) acc += qp->Q[n][i + k * HM_NX] * x[k];
                obj += x[i] * (qp->q[n][i] + HM_R(0.5) * (acc - qp->q[n][i]));
            }
            gx[i] = acc;
        }
        if (n < HM_N) {
            const hm_real *u = zero ? origin : sol->u[n];
            for (i = 0; i < HM_NU; i++) {
                hm_real su = HM_R(0.0), ru = HM_R(0.0);
                if (moved) {
                    for (k = 0; k < HM_NX; k++) su += qp->S[n][i + k * HM_NU] * x[k];
                }
                if (!zero) {
                    for (k = 0; k < HM_NU; k++) ru += qp->R[n][i + k * HM_NU] * u[k];
                    obj += u[i] * (su + HM_R(0.5) * ru + qp->r[n][i]);
                }
                gu[i] = ru + su + qp->r[n][i] - sol->lam_lbu[n][i] + sol->lam_ubu[n][i];
                for (k = 0; k < HM_NX; k++) gu[i] += qp->B[n][k + i * HM_NX] * sol->pi[n][k];
            }
            for (k = 0; k < HM_NX; k++) {
                if (!zero) {
                    for (i = 0; i < HM_NU; i++) gx[k] += qp->S[n][i + k * HM_NU] * u[i];
                }
                for (i = 0; i < HM_NX; i++) gx[k] += qp->A[n][i + k * HM_NX] * sol->pi[n][i];
            }
            for (i = 0; i < HM_NX; i++) {
                hm_real acc = qp->b[n][i] - (zero ? HM_R(0.0) : sol->x[n + 1][i]);
                if (moved) {
                    for (k = 0; k < HM_NX; k++) acc += qp->A[n][i + k * HM_NX] * x[k];
                }
                if (!zero) {
                    for (k = 0; k < HM_NU; k++) acc += qp->B[n][i + k * HM_NX] * u[k];
                }
                OCP_QP_RES_MAX(ra, eq, hm_fabs(acc));
            }
            for (i = 0; i < HM_NU; i++) {
                OCP_QP_RES_MAX(ra, stat, hm_fabs(gu[i]));
                ocp_qp_res_bound(u[i], qp->lbu[n][i], qp->ubu[n][i], sol->lam_lbu[n][i],
                                 sol->lam_ubu[n][i], ra);
            }
        }
        if (n == 0) continue;
        /* ng out of range is invalid data (ocp_qp_check); its residuals are still evaluated safely */
        ng_n = qp->ng[n] < 0 ? 0 : (qp->ng[n] > HM_NG ? HM_NG : qp->ng[n]);
        for (i = 0; i < HM_NX; i++) {
            gx[i] += sol->lam_ubx[n][i] - sol->lam_lbx[n][i] - sol->pi[n - 1][i];
            ocp_qp_res_bound(x[i], qp->lbx[n][i], qp->ubx[n][i], sol->lam_lbx[n][i],
                             sol->lam_ubx[n][i], ra);
        }
        for (i = 0; i < ng_n; i++) {
            const hm_real lam = sol->lam_lg[n][i];
            const int soft = qp->soft[n][i] != 0;
            /* At the zero step a soft row that is satisfied there (lg <= 0, so s = 0) with the
             * multipliers of an inactive one (0, and its slack bound's its L1 weight) adds nothing: each
             * of its terms is <= 0 against maxima that start at 0, its stationarity term is zl - zl = 0,
             * and gx only moves by a zero. The screened rows of an RTI step are such rows: most of
             * them, 5,000 of 5,100 with 100 people. */
            if (zero && soft && lam == HM_R(0.0) && sol->lam_ls[n][i] == qp->zl[n][i] && qp->lg[n][i] <= HM_R(0.0))
                continue;
            /* at the zero step a soft row carries the slack it needs there, max(0, lg) */
            const hm_real s = !soft ? HM_R(0.0) : zero ? (qp->lg[n][i] > HM_R(0.0) ? qp->lg[n][i] : HM_R(0.0)) : sol->s[n][i];
            hm_real g;
            if (!ocp_qp_bound_present(qp->lg[n][i])) continue;
            gx[0] -= qp->D[n][i][0] * lam;
            gx[1] -= qp->D[n][i][1] * lam;
            g = qp->D[n][i][0] * x[0] + qp->D[n][i][1] * x[1] + s - qp->lg[n][i];
            OCP_QP_RES_MAX(ra, ineq, -g);
            OCP_QP_RES_MAX(ra, comp, hm_fabs(lam * g));
            OCP_QP_RES_MAX(ra, dual, -lam);
            if (soft) {
                const hm_real gs = qp->Zl[n][i] * s + qp->zl[n][i] - lam - sol->lam_ls[n][i];
                OCP_QP_RES_MAX(ra, stat, hm_fabs(gs));
                OCP_QP_RES_MAX(ra, ineq, -s);
                OCP_QP_RES_MAX(ra, comp, hm_fabs(sol->lam_ls[n][i] * s));
                OCP_QP_RES_MAX(ra, dual, -sol->lam_ls[n][i]);
                obj += s * (qp->zl[n][i] + HM_R(0.5) * qp->Zl[n][i] * s);
            }
        }
        for (i = 0; i < HM_NX; i++) OCP_QP_RES_MAX(ra, stat, hm_fabs(gx[i]));
    }
    res->obj = obj;
    if (ra->nan_stat) res->stat = (hm_real)NAN;
    if (ra->nan_eq) res->eq = (hm_real)NAN;
    if (ra->nan_ineq) res->ineq = (hm_real)NAN;
    if (ra->nan_comp) res->comp = (hm_real)NAN;
    if (ra->nan_dual) res->dual = (hm_real)NAN;
    *out = local.r;
}

HM_FUNC void ocp_qp_res_compute(const hm_ocp_qp *qp, const hm_ocp_qp_sol *sol, hm_ocp_qp_res *out)
{
    ocp_qp_res_eval(qp, sol, 0, out);
}

HM_FUNC void ocp_qp_res_at_zero_step(const hm_ocp_qp *qp, const hm_ocp_qp_sol *sol, hm_ocp_qp_res *out)
{
    ocp_qp_res_eval(qp, sol, 1, out);
}

HM_FUNC hm_real ocp_qp_res_worst(const hm_ocp_qp_res *res)
{
    hm_real a = res->stat > res->eq ? res->stat : res->eq;
    a = a > res->ineq ? a : res->ineq;
    a = a > res->comp ? a : res->comp;
    return a > res->dual ? a : res->dual;
}
