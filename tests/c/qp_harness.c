/*
 * qp_harness.c: the QP runtime instantiated with test sizes, exported as plain C functions for the
 * Python tests (cffi ABI mode). Built by tests/qp_harness.py with
 *     -DQPT_N=<stages> -DQPT_NG=<rows per stage> [-DHM_REAL_IS_FLOAT]
 * One static problem, solution, workspace and options; the Python side writes the problem through
 * a struct layout it declares itself and checks against qp_harness_sizeof().
 */
#ifdef HM_REAL_IS_FLOAT
#define HM_REAL float
#else
#define HM_REAL double
#endif
#define HM_NS(x) HM_CONCAT(qpt_, x)
#define HM_N QPT_N
#define HM_NG QPT_NG
#include "hm_types.h"
typedef HM_REAL hm_real;
#include "hm_aliases.h"

#include "ocp_qp.c"
#include "ocp_qp_kkt.c"
#include "ocp_qp_ipm.c"

#include <stddef.h>
#include <string.h>

/* exported entry points (prototypes first: the file is built with -Wmissing-prototypes too) */
int qp_harness_dims(int *n, int *ng, int *real_size, int *nc_max);
size_t qp_harness_sizeof(int which);
hm_ocp_qp *qp_harness_qp(void);
hm_ocp_qp_sol *qp_harness_sol(void);
void qp_harness_set_zero(void);
int qp_harness_check(void);
void qp_harness_arg(int max_iter, double tol, double tol_infeas, int stop_after, int polish);
int qp_harness_solve(void);
int qp_harness_info(int *iter, int *polls, int *flags, double *res6, double *scaled3, double *mtk3);
void qp_harness_res(double *res6);
const char *qp_harness_status_message(int status);
int qp_harness_kkt_map(int *m, int *off, int *nb, int *nr, int *ns, double *cost_scale);
int qp_harness_kkt_solve(const hm_real *w, const hm_real *rhs, hm_real *sol);

static hm_ocp_qp g_qp;
static hm_ocp_qp_sol g_sol;
static hm_ocp_qp_ipm_ws g_ws;
static hm_ocp_qp_ipm_arg g_arg;
static hm_ocp_qp_ipm_vec g_vec;
static int g_stop_after = -1;
static int g_polls;

int qp_harness_dims(int *n, int *ng, int *real_size, int *nc_max)
{
    *n = HM_N;
    *ng = HM_NG;
    *real_size = (int)sizeof(hm_real);
    *nc_max = HM_QP_NC_MAX;
    return 0;
}

/* 0: ocp_qp, 1: ocp_qp_sol, 2: ocp_qp_ipm_vec, 3: ocp_qp_ipm_ws */
size_t qp_harness_sizeof(int which)
{
    switch (which) {
    case 0: return sizeof(hm_ocp_qp);
    case 1: return sizeof(hm_ocp_qp_sol);
    case 2: return sizeof(hm_ocp_qp_ipm_vec);
    default: return sizeof(hm_ocp_qp_ipm_ws);
    }
}

hm_ocp_qp *qp_harness_qp(void)
{
    return &g_qp;
}

hm_ocp_qp_sol *qp_harness_sol(void)
{
    return &g_sol;
}

void qp_harness_set_zero(void)
{
    ocp_qp_set_zero(&g_qp);
    ocp_qp_sol_set_zero(&g_sol);
    ocp_qp_ipm_arg_set_default(&g_arg);
    g_stop_after = -1;
}

int qp_harness_check(void)
{
    return ocp_qp_check(&g_qp);
}

/* The hook fires on the poll after stop_after polls; stop_after < 0: no hook. */
static int qp_harness_should_stop(void *ctx)
{
    int *polls = (int *)ctx;
    ++*polls;
    return *polls > g_stop_after;
}

/* Options: max_iter / tol / tol_infeas <= 0 keep the defaults; polish < 0 too. */
void qp_harness_arg(int max_iter, double tol, double tol_infeas, int stop_after, int polish)
{
    ocp_qp_ipm_arg_set_default(&g_arg);
    if (polish >= 0) g_arg.polish = polish;
    if (max_iter > 0) g_arg.max_iter = max_iter;
    if (tol > 0.0) g_arg.tol = (hm_real)tol;
    if (tol_infeas > 0.0) g_arg.tol_infeas = (hm_real)tol_infeas;
    g_stop_after = stop_after;
    g_arg.should_stop = stop_after >= 0 ? qp_harness_should_stop : NULL;
    g_arg.stop_ctx = &g_polls;
}

int qp_harness_solve(void)
{
    g_polls = 0;
    return ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &g_arg);
}

static void qp_harness_copy_res(const hm_ocp_qp_res *res, double *res6)
{
    res6[0] = (double)res->stat;
    res6[1] = (double)res->eq;
    res6[2] = (double)res->ineq;
    res6[3] = (double)res->comp;
    res6[4] = (double)res->dual;
    res6[5] = (double)res->obj;
}

/* Report of the last solve; flags: 1 unbounded, 2 polished. Returns its status. */
int qp_harness_info(int *iter, int *polls, int *flags, double *res6, double *scaled3, double *mtk3)
{
    *iter = g_ws.iter;
    *polls = g_polls;
    *flags = g_ws.unbounded + 2 * g_ws.polished;
    qp_harness_copy_res(&g_ws.res, res6);
    scaled3[0] = (double)g_ws.res_primal;
    scaled3[1] = (double)g_ws.res_dual;
    scaled3[2] = (double)g_ws.gap;
    mtk3[0] = (double)g_ws.mu;
    mtk3[1] = (double)g_ws.tau;
    mtk3[2] = (double)g_ws.kappa;
    return g_ws.status;
}

/* ocp_qp_res_compute of the current problem and solution (which Python may have edited). */
void qp_harness_res(double *res6)
{
    hm_ocp_qp_res res;
    ocp_qp_res_compute(&g_qp, &g_sol, &res);
    qp_harness_copy_res(&res, res6);
}

const char *qp_harness_status_message(int status)
{
    return ocp_qp_status_message(status);
}

/* Builds the packed row map of the current problem; arrays have HM_N + 1 entries. Also reports the
 * cost scale the Newton system is built with. Returns the setup status (HM_QP_INFEASIBLE for
 * crossing bounds). */
int qp_harness_kkt_map(int *m, int *off, int *nb, int *nr, int *ns, double *cost_scale)
{
    int bad = 0, n;
    const int status = ocp_qp_ipm_setup(&g_qp, &g_ws, &bad);
    *m = g_ws.m;
    *cost_scale = (double)g_ws.cost_scale;
    for (n = 0; n <= HM_N; n++) {
        off[n] = g_ws.off[n];
        nb[n] = g_ws.nb[n];
        nr[n] = g_ws.nr[n];
        ns[n] = g_ws.ns[n];
    }
    return status;
}

/* Solves the Newton system of ocp_qp_kkt.h with row weights w[0..m-1] for the right-hand side rhs
 * (an ocp_qp_ipm_vec as a flat array) into sol (the same layout). Returns the factorisation status. */
int qp_harness_kkt_solve(const hm_real *w, const hm_real *rhs, hm_real *sol)
{
    int bad = 0, j, status;
    if (ocp_qp_ipm_setup(&g_qp, &g_ws, &bad)) return HM_QP_INFEASIBLE;
    for (j = 0; j < g_ws.m; j++) g_ws.w[j] = w[j];
    status = ocp_qp_kkt_factorize(&g_qp, &g_ws);
    if (status) return status;
    memcpy(&g_vec, rhs, sizeof g_vec);
    ocp_qp_kkt_solve(&g_qp, &g_ws, &g_vec, &g_vec);
    memcpy(sol, &g_vec, sizeof g_vec);
    return 0;
}
