/*
 * qp_bench.c: time of the QP solver on QPs shaped like the navigation MPC's.
 *
 *     cc -O2 -Ic_runtime -DQPB_N=50 -DQPB_NG=6 tests/c/qp_bench.c -o qp_bench -lm
 *     ./qp_bench [repetitions [polish [tol [qp_file]]]]      (prints one line per case)
 *
 * With qp_file (raw ocp_qp structs of these sizes, one after the other, e.g. dumped from a generated
 * solver after each RTI step), every QP of the file is solved repetitions times instead, and the
 * distribution over the file of the per-QP median solve time is printed (median, p90, p99, max),
 * with the iteration counts and statuses.
 *
 * The QPs linearise the unicycle (RK4 with dt = T / N) around a curved reference trajectory, with
 * the paper's weights (goal, terminal, a small Levenberg-Marquardt term), bounds on v, a and omega,
 * and per stage HM_NG distance half-planes: about a third soft (obstacle), the rest hard (humans),
 * a few of them active. Each case is solved repetitions times from the same data (cold start, as in
 * the SQP); the median and minimum wall time per solve and per interior-point iteration are printed.
 * Under valgrind --tool=callgrind, pass one repetition and divide by the iteration count printed.
 */
#define _POSIX_C_SOURCE 199309L
#define HM_REAL double
#define HM_QP_POLISH /* the polish and the general solve too (ocp_qp_ipm_types.h) */
#define HM_NS(x) HM_CONCAT(qpb_, x)
#define HM_N QPB_N
#define HM_NG QPB_NG
#include "hm_types.h"
typedef HM_REAL hm_real;
#include "hm_aliases.h"

#include "qp_runtime.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static hm_ocp_qp g_qp;
static hm_ocp_qp_sol g_sol;
static hm_ocp_qp_ipm_ws g_ws;

static unsigned long long g_rng = 88172645463325252ULL;
static double urand(void) /* xorshift64, uniform in [0, 1) */
{
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return (double)(g_rng >> 11) * (1.0 / 9007199254740992.0);
}

static void unicycle(const double *x, const double *u, double *f)
{
    f[0] = x[3] * cos(x[2]);
    f[1] = x[3] * sin(x[2]);
    f[2] = u[1];
    f[3] = u[0];
}

/* x_next = RK4(x, u, dt) and its Jacobians by central differences (accurate enough for a QP). */
static void rk4(const double *x, const double *u, double dt, double *xn)
{
    double k1[4], k2[4], k3[4], k4[4], t[4];
    int i;
    unicycle(x, u, k1);
    for (i = 0; i < 4; i++) t[i] = x[i] + 0.5 * dt * k1[i];
    unicycle(t, u, k2);
    for (i = 0; i < 4; i++) t[i] = x[i] + 0.5 * dt * k2[i];
    unicycle(t, u, k3);
    for (i = 0; i < 4; i++) t[i] = x[i] + dt * k3[i];
    unicycle(t, u, k4);
    for (i = 0; i < 4; i++) xn[i] = x[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

static void build_qp(int case_id)
{
    const double T = 5.0, dt = T / HM_N, h = 1e-6;
    const double goal[4] = {4.0, 2.0, 0.0, 0.5};
    double xr[HM_N + 1][4], ur[HM_N][2];
    int n, i, j, k;
    ocp_qp_set_zero(&g_qp);
    g_rng = 88172645463325252ULL + (unsigned long long)case_id;
    xr[0][0] = 0.0;
    xr[0][1] = 0.0;
    xr[0][2] = 0.3;
    xr[0][3] = 0.4;
    for (n = 0; n < HM_N; n++) {
        ur[n][0] = 0.2 * (urand() - 0.5);
        ur[n][1] = 0.5 * sin(0.1 * n) + 0.1 * (urand() - 0.5);
        rk4(xr[n], ur[n], dt, xr[n + 1]);
    }
    for (i = 0; i < 4; i++) g_qp.x0[i] = 0.05 * (urand() - 0.5); /* deviation from the reference */
    for (n = 0; n < HM_N; n++) {
        double xp[4], xm[4], up[2], um[2], fp[4], fm[4], fr[4];
        rk4(xr[n], ur[n], dt, fr);
        for (j = 0; j < 4; j++) {
            for (i = 0; i < 4; i++) xp[i] = xm[i] = xr[n][i];
            xp[j] += h;
            xm[j] -= h;
            rk4(xp, ur[n], dt, fp);
            rk4(xm, ur[n], dt, fm);
            for (i = 0; i < 4; i++) g_qp.A[n][i + 4 * j] = (fp[i] - fm[i]) / (2.0 * h);
        }
        for (j = 0; j < 2; j++) {
            up[0] = um[0] = ur[n][0];
            up[1] = um[1] = ur[n][1];
            up[j] += h;
            um[j] -= h;
            rk4(xr[n], up, dt, fp);
            rk4(xr[n], um, dt, fm);
            for (i = 0; i < 4; i++) g_qp.B[n][i + 4 * j] = (fp[i] - fm[i]) / (2.0 * h);
        }
        for (i = 0; i < 4; i++) g_qp.b[n][i] = fr[i] - xr[n + 1][i];
        for (i = 0; i < 2; i++) {
            g_qp.R[n][i * 3] = 1e-4; /* Wu = 0 plus Levenberg-Marquardt */
            g_qp.r[n][i] = 1e-4 * ur[n][i];
        }
        g_qp.lbu[n][0] = -1.0 - ur[n][0];
        g_qp.ubu[n][0] = 1.0 - ur[n][0];
        g_qp.lbu[n][1] = -1.0 - ur[n][1];
        g_qp.ubu[n][1] = 1.0 - ur[n][1];
    }
    for (n = 0; n <= HM_N; n++) {
        const double W[4] = {0.5, 0.5, 1e-4, 250.0}, WN[4] = {40.0, 40.0, 2.0, 1e-4};
        for (i = 0; i < 4; i++) {
            const double w = n == HM_N ? WN[i] : W[i];
            g_qp.Q[n][i * 5] = w + 1e-4;
            g_qp.q[n][i] = w * (xr[n][i] - goal[i]);
        }
        if (n == 0) continue;
        g_qp.lbx[n][3] = 0.0 - xr[n][3];
        g_qp.ubx[n][3] = 1.0 - xr[n][3];
        g_qp.ng[n] = HM_NG;
        for (k = 0; k < HM_NG; k++) {
            /* a half-plane tangent to a circle of radius 0.5 around a point near the path */
            const double ang = 6.283185307179586 * urand();
            const double d0 = cos(ang), d1 = sin(ang);
            const double dist = (k % 3 == 0 ? 0.3 : 0.8) + 2.0 * urand();
            g_qp.D[n][k][0] = d0;
            g_qp.D[n][k][1] = d1;
            /* the row is D'(p_ref + dp) >= D'p_ref - dist + 0.5: satisfied by dp = 0 unless dist < 0.5 */
            g_qp.lg[n][k] = 0.5 - dist;
            g_qp.soft[n][k] = k % 3 == 0;
            g_qp.zl[n][k] = 100.0;
            g_qp.Zl[n][k] = 10.0;
        }
    }
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#define QPB_FILE_MAX 4096
static double g_med[QPB_FILE_MAX], g_per_iter[QPB_FILE_MAX];
static int g_iters[QPB_FILE_MAX];

static int bench_file(const char *path, int reps, const hm_ocp_qp_ipm_arg *arg)
{
    static double times[1000];
    FILE *f = fopen(path, "rb");
    int count = 0, k, status_count[6] = {0, 0, 0, 0, 0, 0}, it_hist[64] = {0}, it_sum = 0, fallbacks = 0;
    if (!f) {
        printf("cannot open %s\n", path);
        return 1;
    }
    while (count < QPB_FILE_MAX && fread(&g_qp, sizeof g_qp, 1, f) == 1) {
        int r, status = 0;
        for (r = 0; r < reps && r < 1000; r++) {
            const double t0 = now_s();
            status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, arg);
            times[r] = now_s() - t0;
        }
        qsort(times, (size_t)r, sizeof times[0], cmp_double);
        g_med[count] = times[r / 2];
        g_iters[count] = g_ws.out.iter;
        g_per_iter[count] = times[r / 2] / (g_ws.out.iter > 0 ? g_ws.out.iter : 1);
        it_sum += g_ws.out.iter;
        fallbacks += g_ws.fallback;
        it_hist[g_ws.out.iter < 63 ? g_ws.out.iter : 63]++;
        if (status >= 0 && status < 6) status_count[status]++;
        count++;
    }
    fclose(f);
    if (count == 0) return 1;
    qsort(g_med, (size_t)count, sizeof g_med[0], cmp_double);
    qsort(g_per_iter, (size_t)count, sizeof g_per_iter[0], cmp_double);
    printf("N=%d NG=%d file %s: %d QPs, solve median %.2f p90 %.2f p99 %.2f max %.2f us; per iteration median %.2f us;"
           " iterations mean %.2f; status solved %d max_iter %d infeasible %d numerical %d; fallbacks %d\n",
           HM_N, HM_NG, path, count, 1e6 * g_med[count / 2], 1e6 * g_med[(count * 9) / 10],
           1e6 * g_med[(count * 99) / 100], 1e6 * g_med[count - 1], 1e6 * g_per_iter[count / 2],
           (double)it_sum / count, status_count[0], status_count[1], status_count[2], status_count[3], fallbacks);
    printf("iterations:");
    for (k = 0; k < 64; k++) {
        if (it_hist[k]) printf(" %d:%d", k, it_hist[k]);
    }
    printf("\n");
    return 0;
}

int main(int argc, char **argv)
{
    const int reps = argc > 1 ? atoi(argv[1]) : 2000;
    static double times[100000];
    hm_ocp_qp_ipm_arg arg;
    int c;
    ocp_qp_ipm_arg_set_default(&arg);
    if (argc > 2) arg.polish = atoi(argv[2]);
    if (argc > 3) arg.tol = (hm_real)atof(argv[3]);
    if (argc > 4) return bench_file(argv[4], reps, &arg);
    for (c = 0; c < 4; c++) {
        int r, status = 0, iters = 0;
        double med, mn;
        build_qp(c);
        for (r = 0; r < reps && r < 100000; r++) {
            const double t0 = now_s();
            status = ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &arg);
            times[r] = now_s() - t0;
            iters = g_ws.out.iter;
        }
        qsort(times, (size_t)r, sizeof times[0], cmp_double);
        med = times[r / 2];
        mn = times[0];
        printf("N=%d NG=%d case %d: %s, iterations %d  median %.2f us/solve %.2f us/iter  min %.2f us/solve"
               "  (stat %.1e eq %.1e ineq %.1e comp %.1e)\n",
               HM_N, HM_NG, c, ocp_qp_status_message(status), iters, 1e6 * med, 1e6 * med / (iters > 0 ? iters : 1), 1e6 * mn,
               g_ws.out.res.stat, g_ws.out.res.eq, g_ws.out.res.ineq, g_ws.out.res.comp);
    }
    return 0;
}
