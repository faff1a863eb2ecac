/*
 * qp_selftest.c: the QP solver on generated problems, C only, so that the sanitizers
 * (-fsanitize=address,undefined) see every path of the solver: feasible QPs of several kinds
 * (checked through ocp_qp_res_compute), contradictory hard rows and unreachable states
 * (INFEASIBLE, certificate checked), crossing bounds, non-finite data, the stop hook, the iteration
 * limit and an unbounded QP. Built by tests/test_ocp_qp.py for double and float; exit status 0 if
 * every check passes, otherwise the number of failed checks (each one printed).
 */
#ifdef HM_REAL_IS_FLOAT
#define HM_REAL float
#define TOL_RES 2e-3f
#else
#define HM_REAL double
#define TOL_RES 1e-6
#endif
#define HM_QP_POLISH /* the polish and the general solve too (ocp_qp_ipm_types.h) */
#define HM_NS(x) HM_CONCAT(qps_, x)
#define HM_N 8
#define HM_NG 4
#include "hm_types.h"
typedef HM_REAL hm_real;
#include "hm_aliases.h"

#include "qp_runtime.h"

#include <stdio.h>
#include <stdlib.h>

static hm_ocp_qp g_qp;
static hm_ocp_qp_sol g_sol;
static hm_ocp_qp_ipm_ws g_ws;
static int g_failures;

static unsigned long long g_rng = 0x9E3779B97F4A7C15ULL;
static double urand(void) /* xorshift64: uniform in [0, 1) */
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

static double srand1(void)
{
    return 2.0 * urand() - 1.0;
}

static void check(int ok, const char *what, int case_id)
{
    if (!ok) {
        printf("FAIL case %d: %s\n", case_id, what);
        g_failures++;
    }
}

/* A feasible QP: random stable-ish dynamics, a feasible reference trajectory, bounds and hard rows
 * that the reference satisfies, soft rows anywhere. kind 0: positive definite cost, 1: cost only
 * linear in u (R = 0, all inputs bounded), 2: soft rows with Zl = 0. */
static void make_qp(int kind, double xref[HM_N + 1][HM_NX])
{
    double uref[HM_NU];
    int n, i, j, k;
    ocp_qp_set_zero(&g_qp);
    for (i = 0; i < HM_NX; i++) g_qp.x0[i] = (hm_real)srand1();
    for (i = 0; i < HM_NX; i++) xref[0][i] = (double)g_qp.x0[i];
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            for (j = 0; j < HM_NX; j++) g_qp.A[n][i + j * HM_NX] = (hm_real)((i == j ? 1.0 : 0.0) + 0.2 * srand1());
            for (j = 0; j < HM_NU; j++) g_qp.B[n][i + j * HM_NX] = (hm_real)(0.5 * srand1());
            g_qp.b[n][i] = (hm_real)(0.1 * srand1());
        }
        for (j = 0; j < HM_NU; j++) {
            g_qp.lbu[n][j] = (hm_real)(-0.5 - urand());
            g_qp.ubu[n][j] = (hm_real)(0.5 + urand());
            uref[j] = 0.4 * srand1();
            g_qp.r[n][j] = (hm_real)srand1();
        }
        for (i = 0; i < HM_NX; i++) {
            double acc = (double)g_qp.b[n][i];
            for (j = 0; j < HM_NX; j++) acc += (double)g_qp.A[n][i + j * HM_NX] * xref[n][j];
            for (j = 0; j < HM_NU; j++) acc += (double)g_qp.B[n][i + j * HM_NX] * uref[j];
            xref[n + 1][i] = acc;
        }
        if (kind != 1) {
            g_qp.R[n][0] = g_qp.R[n][3] = (hm_real)(0.5 + urand());
            g_qp.R[n][1] = g_qp.R[n][2] = (hm_real)(0.1 * srand1());
            g_qp.S[n][0] = (hm_real)(0.1 * srand1());
        }
    }
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            g_qp.Q[n][i * (HM_NX + 1)] = (hm_real)(kind == 1 ? 0.1 * urand() : 0.2 + urand());
            g_qp.q[n][i] = (hm_real)srand1();
        }
        if (n == 0) continue;
        for (i = 0; i < HM_NX; i++) {
            if (urand() < 0.3) g_qp.lbx[n][i] = (hm_real)(xref[n][i] - 0.5 * urand());
            if (urand() < 0.3) g_qp.ubx[n][i] = (hm_real)(xref[n][i] + 0.5 * urand());
        }
        g_qp.ng[n] = (int)(urand() * (HM_NG + 1));
        for (k = 0; k < g_qp.ng[n]; k++) {
            const double a = 6.283185307179586 * urand();
            const double val = cos(a) * xref[n][0] + sin(a) * xref[n][1];
            g_qp.D[n][k][0] = (hm_real)cos(a);
            g_qp.D[n][k][1] = (hm_real)sin(a);
            g_qp.soft[n][k] = urand() < 0.5;
            if (g_qp.soft[n][k]) {
                g_qp.lg[n][k] = (hm_real)(val + srand1());
                g_qp.zl[n][k] = (hm_real)(0.5 + urand());
                g_qp.Zl[n][k] = (hm_real)(kind == 2 ? 0.0 : urand());
            } else {
                g_qp.lg[n][k] = (hm_real)(val - 0.3 * urand());
            }
        }
        /* rows beyond ng are not part of the problem: junk, including NaN, must not matter */
        for (k = g_qp.ng[n]; k < HM_NG; k++) {
            g_qp.D[n][k][0] = (hm_real)NAN;
            g_qp.lg[n][k] = (hm_real)INFINITY;
            g_qp.zl[n][k] = (hm_real)NAN;
            g_qp.soft[n][k] = -7;
        }
    }
}

static int g_polls;
static int stop_after_three(void *ctx)
{
    (void)ctx;
    return ++g_polls > 3;
}

static void check_solved(const hm_ocp_qp_ipm_arg *arg, int case_id)
{
    const int status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, arg);
    hm_ocp_qp_res res;
    check(status == HM_QP_SOLVED, "feasible QP solved", case_id);
    ocp_qp_res_compute(&g_qp, &g_sol, &res);
    if (getenv("QPS_VERBOSE")) printf("case %d: stat %g eq %g ineq %g comp %g dual %g obj %g iter %d status %d\n", case_id, (double)res.stat, (double)res.eq, (double)res.ineq, (double)res.comp, (double)res.dual, (double)res.obj, g_ws.out.iter, status);
    /* the solver's tolerance is relative: the gap (sum of complementarity products) against the
     * objective, stationarity against the gradient terms (all O(1) here, up to ~10 with the bounds) */
    check(res.stat < (hm_real)(TOL_RES * 10) && res.eq < (hm_real)TOL_RES && res.ineq < (hm_real)TOL_RES
          && res.comp < (hm_real)TOL_RES * (1 + hm_fabs(res.obj)) && res.dual <= 0,
          "KKT residuals of the solution", case_id);
    check(res.stat == g_ws.out.res.stat && res.comp == g_ws.out.res.comp, "workspace reports the residuals", case_id);
    check(g_ws.out.iter > 0 && g_ws.out.iter < 40, "iteration count", case_id);
}

/* The certificate of ocp_qp_ipm.h: stationarity without the cost, value 1, signs. */
static void check_certificate(int case_id)
{
    double value = 0.0, worst = 0.0;
    int n, i, k;
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NU; i++) {
            double g = (double)(g_sol.lam_ubu[n][i] - g_sol.lam_lbu[n][i]);
            for (k = 0; k < HM_NX; k++) g += (double)(g_qp.B[n][k + i * HM_NX] * g_sol.pi[n][k]);
            worst = fmax(worst, fabs(g));
            value += (double)(g_qp.lbu[n][i] * g_sol.lam_lbu[n][i] - g_qp.ubu[n][i] * g_sol.lam_ubu[n][i]);
            check(g_sol.lam_lbu[n][i] >= 0 && g_sol.lam_ubu[n][i] >= 0, "certificate signs (u)", case_id);
        }
        for (i = 0; i < HM_NX; i++) {
            double c = (double)g_qp.b[n][i];
            if (n == 0) {
                for (k = 0; k < HM_NX; k++) c += (double)(g_qp.A[0][i + k * HM_NX] * g_qp.x0[k]);
            }
            value += c * (double)g_sol.pi[n][i];
        }
    }
    for (n = 1; n <= HM_N; n++) {
        for (i = 0; i < HM_NX; i++) {
            double g = (double)(g_sol.lam_ubx[n][i] - g_sol.lam_lbx[n][i] - g_sol.pi[n - 1][i]);
            if (n < HM_N) {
                for (k = 0; k < HM_NX; k++) g += (double)(g_qp.A[n][k + i * HM_NX] * g_sol.pi[n][k]);
            }
            for (k = 0; k < g_qp.ng[n] && i < HM_NPOS; k++) g -= (double)(g_qp.D[n][k][i] * g_sol.lam_lg[n][k]);
            worst = fmax(worst, fabs(g));
            if (ocp_qp_bound_present(g_qp.lbx[n][i])) value += (double)(g_qp.lbx[n][i] * g_sol.lam_lbx[n][i]);
            if (ocp_qp_bound_present(g_qp.ubx[n][i])) value -= (double)(g_qp.ubx[n][i] * g_sol.lam_ubx[n][i]);
        }
        for (k = 0; k < g_qp.ng[n]; k++) value += (double)(g_qp.lg[n][k] * g_sol.lam_lg[n][k]);
    }
    check(fabs(value - 1.0) < (double)TOL_RES * 100 && worst < (double)TOL_RES * 100, "Farkas certificate", case_id);
}

int main(void)
{
    static double xref[HM_N + 1][HM_NX];
    hm_ocp_qp_ipm_arg arg;
    int c, status;
    ocp_qp_ipm_arg_set_default(&arg);

    for (c = 0; c < 60; c++) {
        make_qp(c % 3, xref);
        check_solved(&arg, c);
    }

    /* contradictory hard rows: D' p >= 1 and -D' p >= 0 at the same stage */
    for (c = 100; c < 110; c++) {
        const int n = 1 + c % HM_N;
        make_qp(0, xref);
        g_qp.ng[n] = 2;
        g_qp.D[n][0][0] = 1;
        g_qp.D[n][0][1] = 0;
        g_qp.D[n][1][0] = -1;
        g_qp.D[n][1][1] = 0;
        g_qp.lg[n][0] = (hm_real)(xref[n][0] + 0.5);
        g_qp.lg[n][1] = (hm_real)(-xref[n][0] + 0.5);
        g_qp.soft[n][0] = g_qp.soft[n][1] = 0;
        status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
        check(status == HM_QP_INFEASIBLE, "contradictory hard rows are infeasible", c);
        if (status == HM_QP_INFEASIBLE) check_certificate(c);
        /* the same rows soft: never infeasible */
        g_qp.soft[n][0] = g_qp.soft[n][1] = 1;
        g_qp.zl[n][0] = g_qp.zl[n][1] = 1;
        g_qp.Zl[n][0] = g_qp.Zl[n][1] = 0;
        check_solved(&arg, c);
    }

    /* a state bound beyond what one step of bounded inputs reaches */
    for (c = 200; c < 205; c++) {
        make_qp(0, xref);
        g_qp.lbx[1][0] = (hm_real)(xref[1][0] + 50.0);
        g_qp.ubx[1][0] = (hm_real)HM_INF;
        status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
        check(status == HM_QP_INFEASIBLE, "unreachable state bound is infeasible", c);
        if (status == HM_QP_INFEASIBLE) check_certificate(c);
    }

    /* crossing bounds are reported before any iteration */
    make_qp(0, xref);
    g_qp.lbx[3][2] = 1;
    g_qp.ubx[3][2] = 0;
    status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
    check(status == HM_QP_INFEASIBLE && g_ws.out.iter == 0, "crossing bounds", 300);
    if (status == HM_QP_INFEASIBLE) check_certificate(300);

    /* non-finite data */
    make_qp(0, xref);
    g_qp.B[4][3] = (hm_real)NAN;
    check(ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg) == HM_QP_NONFINITE && g_ws.out.iter == 0, "NaN in B", 400);
    make_qp(0, xref);
    g_qp.q[HM_N][1] = (hm_real)INFINITY;
    check(ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg) == HM_QP_NONFINITE, "Inf in q", 401);
    make_qp(0, xref);
    g_qp.ng[2] = HM_NG + 1;
    check(ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg) == HM_QP_NONFINITE, "ng out of range", 402);

    /* the stop hook: polled once per iteration, fires on the fourth poll */
    make_qp(0, xref);
    arg.should_stop = stop_after_three;
    g_polls = 0;
    status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
    check(status == HM_QP_TIMEOUT && g_ws.out.iter == 3 && g_polls == 4, "stop hook", 500);
    arg.should_stop = NULL;

    /* iteration limit */
    arg.max_iter = 2;
    status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
    check(status == HM_QP_MAX_ITER && g_ws.out.iter == 2, "iteration limit", 600);
    ocp_qp_ipm_arg_set_default(&arg);

    /* unbounded: an input without effect or curvature, bounded below only, whose cost falls as it
     * grows */
    make_qp(0, xref);
    g_qp.R[5][0] = g_qp.R[5][1] = g_qp.R[5][2] = 0;
    g_qp.S[5][0] = 0;
    g_qp.r[5][0] = -1;
    g_qp.ubu[5][0] = (hm_real)HM_INF;
    for (c = 0; c < HM_NX; c++) g_qp.B[5][c] = 0;
    status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
    check(status == HM_QP_NUMERICAL && g_ws.out.unbounded, "unbounded QP detected", 700);
    /* the same input also unbounded below: its curvature is zero, the Newton matrix singular */
    g_qp.lbu[5][0] = (hm_real)-HM_INF;
    status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
    check(status == HM_QP_NUMERICAL && !g_ws.out.unbounded, "singular Newton matrix", 701);
    printf("%s: %d failure(s); last status message: %s\n", g_failures ? "FAIL" : "OK", g_failures,
           ocp_qp_status_message(status));
    return g_failures;
}
