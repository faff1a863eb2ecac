/*
 * qp_harness.c: the QP runtime instantiated with test sizes, exported as plain C functions for the
 * Python tests (cffi ABI mode). Built by tests/qp_harness.py with
 *     -DQPT_N=<stages> -DQPT_NG=<rows per stage> [-DQPT_NRC=<soft rows a QP may hold>] [-DHM_REAL_IS_FLOAT]
 * One static problem, solution, workspace and options; the Python side writes the problem through
 * a struct layout it declares itself and checks against qp_harness_sizeof().
 */
#ifdef HM_REAL_IS_FLOAT
#define HM_REAL float
#else
#define HM_REAL double
#endif
/* the tests' QP build: with the active-set polish and the general solve (ocp_qp_ipm_types.h) */
#define HM_QP_POLISH
#define HM_NS(x) HM_CONCAT(qpt_, x)
#define HM_N QPT_N
#define HM_NG QPT_NG
#ifdef QPT_NRC
#define HM_NRC QPT_NRC
#endif
#include "hm_types.h"
typedef HM_REAL hm_real;
#include "hm_aliases.h"

#include "qp_runtime.h"

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
void qp_harness_warm(int warm_start, double warm_mu);
int qp_harness_solve(void);
int qp_harness_solve_fallback(void);
int qp_harness_rows(void);
int qp_harness_info(int *iter, int *polls, int *flags, double *res6, double *scaled3, double *mtk3);
void qp_harness_res(double *res6);
const char *qp_harness_status_message(int status);
int qp_harness_kkt_map(int *m, int *off, int *nb, int *nr, int *ns, int *kernel, double *cost_scale);
int qp_harness_kkt_solve(const hm_real *w, const hm_real *rhs, hm_real *sol);

static hm_ocp_qp g_qp;
static hm_ocp_qp_sol g_sol;
static hm_ocp_qp_ipm_ws g_ws;
static hm_ocp_qp_ipm_arg g_arg;
static hm_ocp_qp_ipm_vec g_vec;
static int g_stop_after = -1;
static int g_polls;

/* Inequalities of the whole QP at most: per stage both sides of 6 components, and soft rows (2). */
#define QPT_NC_MAX ((HM_N + 1) * (2 * HM_QP_NUX + 2 * HM_NG))

int qp_harness_dims(int *n, int *ng, int *real_size, int *nc_max)
{
    *n = HM_N;
    *ng = HM_NG;
    *real_size = (int)sizeof(hm_real);
    *nc_max = QPT_NC_MAX;
    return 0;
}

/* 0: ocp_qp, 1: ocp_qp_sol, 2: the flat vector of qp_harness_kkt_solve, 3: ocp_qp_ipm_ws */
size_t qp_harness_sizeof(int which)
{
    switch (which) {
    case 0: return sizeof(hm_ocp_qp);
    case 1: return sizeof(hm_ocp_qp_sol);
    case 2: return sizeof(hm_real) * (size_t)((HM_N + 1) * HM_QP_NUX + (HM_N + 1) * HM_NG + HM_N * HM_NX + QPT_NC_MAX);
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

/* The warm start (after qp_harness_arg, which resets it): arg.warm_start and arg.warm_mu. */
void qp_harness_warm(int warm_start, double warm_mu)
{
    g_arg.warm_start = warm_start;
    g_arg.warm_mu = (hm_real)warm_mu;
}

int qp_harness_solve(void)
{
    g_polls = 0;
    return ocp_qp_ipm_solve(&g_qp, &g_sol, &g_ws, &g_arg);
}

/* The fallback solver alone (ocp_qp_hsde.h), reported as a solve of the workspace by the fallback. */
int qp_harness_solve_fallback(void)
{
    const int status = ocp_qp_hsde_solve(&g_qp, &g_sol, &g_ws.u.hsde, &g_arg);
    g_polls = 0;
    g_ws.fallback = 1;
    g_ws.out = g_ws.u.hsde.out;
    return status;
}

/* Soft rows a QP may hold (HM_QP_NRC: QPT_NRC, by default every row). */
int qp_harness_rows(void)
{
    return HM_QP_NRC;
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

/* Report of the last solve; flags: 1 unbounded, 2 polished, 4 solved by the fallback. Returns its
 * status. */
int qp_harness_info(int *iter, int *polls, int *flags, double *res6, double *scaled3, double *mtk3)
{
    *iter = g_ws.out.iter;
    *polls = g_polls;
    *flags = g_ws.out.unbounded + 2 * g_ws.out.polished + 4 * g_ws.fallback;
    qp_harness_copy_res(&g_ws.out.res, res6);
    scaled3[0] = (double)g_ws.out.res_primal;
    scaled3[1] = (double)g_ws.out.res_dual;
    scaled3[2] = (double)g_ws.out.gap;
    mtk3[0] = (double)g_ws.out.mu;
    mtk3[1] = 1.0; /* tau and kappa of the homogeneous embedding the solver no longer uses */
    mtk3[2] = 0.0;
    return g_ws.out.status;
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

/* The packed order of the inequalities of stage n (the order of tests/qp_harness.py's conic form):
 * present bound sides (u before x, lower before upper), present general rows in QP order, then the
 * s >= 0 rows of the soft ones. For each packed general row k of stage n, *is_soft and the index in
 * its family. */
static void qp_harness_row_map(int n, int *kind, int *fam)
{
    const hm_ocp_qp_ipm_stage *sn = &g_ws.u.f.st[n];
    const hm_ocp_qp_ipm_rows *sr = &g_ws.u.f.sr;
    int i, js = 0, jh = 0, k = 0;
    for (i = 0; i < g_qp.ng[n] && n > 0; i++) {
        if (!ocp_qp_bound_present(g_qp.lg[n][i])) continue;
        if (js < sn->ns && sr->srow[sn->soff + js] == i) {
            kind[k] = 1;
            fam[k] = js++;
        } else {
            kind[k] = 0;
            fam[k] = jh++;
        }
        k++;
    }
}

/* Builds the row map of the current problem; arrays have HM_N + 1 entries (packed offsets and
 * counts: bound sides, general rows, soft rows). Also reports the cost scale the Newton system is
 * built with. Returns the setup status (HM_QP_INFEASIBLE for crossing bounds). */
/* Per stage: the offset and counts of its packed inequality rows, and the path of the Riccati
 * recursion its dynamics take (ocp_qp_kkt.c: 0 general, 1 general with the position-free shortcut,
 * 2 the integrators' kernel). */
int qp_harness_kkt_map(int *m, int *off, int *nb, int *nr, int *ns, int *kernel, double *cost_scale)
{
    int bad = 0, n, k, total = 0;
    const int status = ocp_qp_ipm_setup(&g_qp, &g_ws, &bad);
    if (status) return status;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &g_ws.u.f.st[n];
        const hm_ocp_qp_ipm_bounds *bd = &g_ws.u.f.bd;
        int cnt = 0;
        for (k = 0; k < bd->nbp; k++) cnt += (bd->sg[k][0][n] != 0) + (bd->sg[k][1][n] != 0);
        off[n] = total;
        nb[n] = cnt;
        nr[n] = sn->ns + sn->nh;
        ns[n] = sn->ns;
        kernel[n] = n > 0 && n < HM_N && sn->a_id ? 1 + sn->ab_int : 0;   /* as ocp_qp_kkt_factor_stage */
        total += cnt + sn->ns + sn->nh + sn->ns;
    }
    *m = total;
    *cost_scale = (double)g_ws.cost_scale;
    return status;
}

/* Solves the Newton system of ocp_qp_kkt.h with weights w[0..m-1] (packed order) for the right-hand
 * side rhs into sol, both flat arrays of the layout (ux[HM_N+1][6], s[HM_N+1][HM_NG] by packed
 * general row, y[HM_N][4], z[m] packed). Returns the factorisation status. */
int qp_harness_kkt_solve(const hm_real *w, const hm_real *rhs, hm_real *sol)
{
    const int off_s = (HM_N + 1) * HM_QP_NUX;
    const int off_y = off_s + (HM_N + 1) * HM_NG;
    const int off_z = off_y + HM_N * HM_NX;
    int bad = 0, n, i, k, l, j, status, pos = 0;
    int kind[HM_NG], fam[HM_NG];
    hm_ocp_qp_ipm_vec *v = &g_vec;
    hm_ocp_qp_ipm_bounds *bd = &g_ws.u.f.bd;
    hm_ocp_qp_ipm_general *gs = &g_ws.u.f.gs;
    if (ocp_qp_ipm_setup(&g_qp, &g_ws, &bad)) return HM_QP_INFEASIBLE;
    memset(v, 0, sizeof *v);
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &g_ws.u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) v->ux[n][i] = rhs[n * HM_QP_NUX + i];
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) v->y[n][i] = rhs[off_y + n * HM_NX + i];
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                bd->w[k][l][n] = HM_R(1.0);
                if (bd->sg[k][l][n] == 0) continue;
                bd->w[k][l][n] = w[pos];
                v->zb[n][k][l] = rhs[off_z + pos];
                pos++;
            }
        }
        qp_harness_row_map(n, kind, fam);
        for (k = 0; k < sn->ns + sn->nh; k++) {
            if (kind[k]) {
                gs->swr[sn->soff + fam[k]] = w[pos];
                v->zr[n][fam[k]] = rhs[off_z + pos];
                v->s[n][fam[k]] = rhs[off_s + n * HM_NG + k];
            } else {
                sn->hr->hw[fam[k]] = w[pos];
                v->zh[n][fam[k]] = rhs[off_z + pos];
            }
            pos++;
        }
        for (j = 0; j < sn->ns; j++) {
            gs->sws[sn->soff + j] = w[pos];
            v->zs[n][j] = rhs[off_z + pos];
            pos++;
        }
    }
    ocp_qp_kkt_condense_weights(&g_ws);
    status = ocp_qp_kkt_factorize(&g_qp, &g_ws);
    if (status) return status;
    ocp_qp_kkt_solve(&g_qp, &g_ws, v, v);
    pos = 0;
    for (i = 0; i < off_z; i++) sol[i] = 0;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &g_ws.u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) sol[n * HM_QP_NUX + i] = v->ux[n][i];
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) sol[off_y + n * HM_NX + i] = v->y[n][i];
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                if (bd->sg[k][l][n] == 0) continue;
                sol[off_z + pos++] = v->zb[n][k][l];
            }
        }
        qp_harness_row_map(n, kind, fam);
        for (k = 0; k < sn->ns + sn->nh; k++) {
            if (kind[k]) {
                sol[off_z + pos] = v->zr[n][fam[k]];
                sol[off_s + n * HM_NG + k] = v->s[n][fam[k]];
            } else {
                sol[off_z + pos] = v->zh[n][fam[k]];
            }
            pos++;
        }
        for (j = 0; j < sn->ns; j++) sol[off_z + pos++] = v->zs[n][j];
    }
    return 0;
}
