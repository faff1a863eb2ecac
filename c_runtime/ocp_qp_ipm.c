/*
 * ocp_qp_ipm.c: primal-dual interior-point solver of ocp_qp (see ocp_qp_ipm.h for the algorithm and
 * the termination rules).
 *
 * Notation as in ocp_qp_ipm.h and hm_types.h (ocp_qp_ipm_stage). Every inequality is written
 * a' v + t = b with slack t >= 0 and multiplier z >= 0: a bound side sign * ux[c] + t = b, a soft row
 * -(d' p + s) + t = -lg, a soft slack's bound -s + s = 0 (its slack is s itself), a hard row
 * -d' p + t = -lg.
 *
 * One iteration is five passes over the stages, each fused so that a stage's data is touched once;
 * in passes A, C and E the bound pairs take a sweep of their own over their stage-major arrays
 * (hm_types.h: ocp_qp_ipm_bounds), eight stages at a time in vector lanes:
 *   A (forward)   take the last step, evaluate the residuals, the weights z / t, and condense the
 *                 inequalities into their stage: Hessian terms (Hd, Hpp), the predictor's gradient
 *                 (ha) and the gradient per unit of sigma mu (hmu); termination measures.
 *   B (backward)  factorise, and the predictor's backward substitution.
 *   C (forward)   the predictor's forward substitution; its inequality steps give the step length,
 *                 mu_aff and the corrector's second-order gradient terms (hdl), condensed at once.
 *   D (backward)  the corrector's backward substitution with ha + hdl + sigma mu hmu.
 *   E (forward)   the corrector's forward substitution and inequality steps, and the step length.
 * The predictor rhs is (-r_v, -r_y, -rho) with rho = r - c / z per inequality (c the complementarity
 * target: t z for the predictor, t z + dt dz - sigma mu for the corrector); the corrector's differs
 * from it only in rho, linearly, which is what lets pass D run on stage vectors alone.
 */
#include "ocp_qp.h"
#include "ocp_qp_kkt.h"
#include "ocp_qp_ipm.h"
#include "ocp_qp_hsde.c"

/* hm_types.h writes the sizes out: the padded stage count of ocp_qp_ipm_bounds must be HM_QP_NNP,
 * the length of the row list of ocp_qp_ipm_rows HM_QP_NR */
typedef char ocp_qp_ipm_nr_matches[sizeof(((hm_ocp_qp_ipm_rows *)0)->ss) == HM_QP_NR * sizeof(hm_real) ? 1 : -1];
typedef char ocp_qp_ipm_nnp_matches[sizeof(((hm_ocp_qp_ipm_bounds *)0)->v[0]) == HM_QP_NNP * sizeof(hm_real) ? 1 : -1];

/* Cap of the weights z / t, relative to the curvature of the cost. Near the solution the weights
 * of active rows grow like 1 / mu; condensed into the Riccati recursion, whose Schur complements
 * subtract them again, they leave rounding errors of eps * weight in the moderate directions, and
 * beyond ~1e-6 / eps the cost-to-go matrices lose definiteness and the steps go wrong. Capping the
 * weight makes the Newton step slightly inexact on active rows only; that error shrinks with the
 * step itself, so convergence is kept. In single precision 1e6 (not 1e-6 / eps = 1e1): a tighter
 * cap makes the steps on active rows so inexact that RTI replays took 25-50 iterations (MAX_ITER
 * in one step out of 20) against 12-23 at 1e6, which matches the double build's counts. */
#ifdef HM_REAL_IS_FLOAT
#define OCP_QP_IPM_W_MAX_REL HM_R(1e6)
#else
#define OCP_QP_IPM_W_MAX_REL HM_R(1e10)
#endif

/* The termination tests measure the inequalities once the residuals are within this factor of
 * passing on the stage vectors' normalisation alone and a test that ends the solve could pass
 * (ocp_qp_ipm_solve). */
#define OCP_QP_IPM_MEASURE_NEAR HM_R(1e3)

/* Between stage measures the dual residual and the gap are compared with tol times this factor
 * (their normalisations are the last stage measures', ocp_qp_ipm_solve). */
#define OCP_QP_IPM_STAGE_NEAR HM_R(10.0)

/* Iterations over which a feasible iterate's mu must fall by 4 (ocp_qp_ipm_solve). */
#define OCP_QP_IPM_STALL_ITERS 4

/* max/min without libm's calls (whose NaN rule is not needed here: NaN is caught on the sums) */
#define OCP_QP_IPM_MAX(a, b) ((a) > (b) ? (a) : (b))
#define OCP_QP_IPM_MIN(a, b) ((a) < (b) ? (a) : (b))
#define OCP_QP_IPM_ABS(a) ((a) < HM_R(0.0) ? -(a) : (a))

/* Profiling builds only (-DOCP_QP_IPM_PROFILE; docs/pass_profile.sh): the time of each part of the
 * solves accumulates in ocp_qp_ipm_profile_ns[part], read with the including program's clock
 * ocp_qp_ipm_profile_clock_ns(). The counters are the program's, shared by every solver in it. */
enum {
    OCP_QP_IPM_PROF_SETUP,     /* data check, stage blocks and starting point */
    OCP_QP_IPM_PROF_A,
    OCP_QP_IPM_PROF_B,
    OCP_QP_IPM_PROF_C,
    OCP_QP_IPM_PROF_D,
    OCP_QP_IPM_PROF_E,
    OCP_QP_IPM_PROF_FINISH,    /* solution, residuals, polish, and the fallback solver when it runs */
    OCP_QP_IPM_PROF_PARTS
};
#ifdef OCP_QP_IPM_PROFILE
extern double ocp_qp_ipm_profile_ns[OCP_QP_IPM_PROF_PARTS];
extern double ocp_qp_ipm_profile_clock_ns(void);
#define OCP_QP_IPM_PROF(part, stmt)                                                    \
    do {                                                                               \
        const double prof_t0_ = ocp_qp_ipm_profile_clock_ns();                         \
        stmt;                                                                          \
        ocp_qp_ipm_profile_ns[part] += ocp_qp_ipm_profile_clock_ns() - prof_t0_;       \
    } while (0)
#else
#define OCP_QP_IPM_PROF(part, stmt) \
    do {                            \
        stmt;                       \
    } while (0)
#endif

HM_FUNC void ocp_qp_ipm_arg_set_default(hm_ocp_qp_ipm_arg *arg)
{
    arg->max_iter = 50;
#ifdef HM_REAL_IS_FLOAT
    /* single precision carries 7 digits; residuals of sums of O(1) terms stop near 1e-6 */
    arg->tol = HM_R(1e-4);
    arg->tol_infeas = HM_R(1e-4);
#else
    arg->tol = HM_R(1e-6);
    arg->tol_infeas = HM_R(1e-8);
#endif
    arg->step_frac = HM_R(0.99);
    arg->min_step = HM_R(1e-8);
    arg->polish = 0;
    arg->residuals = 1;
    arg->detect_unbounded = 1;
    arg->recurrence = 1;
    arg->should_stop = NULL;
    arg->stop_ctx = NULL;
    arg->warm_start = 0;
    arg->warm_mu = HM_R(0.0);
}

HM_FUNC const char *ocp_qp_status_message(int status)
{
    switch (status) {
    case HM_QP_SOLVED:
        return "QP solved";
    case HM_QP_MAX_ITER:
        return "QP iteration limit reached before convergence";
    case HM_QP_INFEASIBLE:
        return "QP infeasible: no point satisfies the hard constraints";
    case HM_QP_NUMERICAL:
        return "QP numerical failure: singular Newton system, no progress, or unbounded";
    case HM_QP_NONFINITE:
        return "QP data or iterates not finite (NaN/Inf, or ng out of range)";
    case HM_QP_TIMEOUT:
        return "QP stopped by the deadline hook";
    default:
        return "unknown QP status";
    }
}

/* ------------------------------------------------------------------------------------------------
 * Setup: the families, the scaled cost, the norms, the starting point
 * ---------------------------------------------------------------------------------------------- */

/* The bounds of component i of (u, x) at stage n (n <= HM_N); 0 if the stage has no such component
 * (u at stage HM_N, x at stage 0: not part of the problem). */
HM_FUNC int ocp_qp_ipm_bounds_of(const hm_ocp_qp *qp, int n, int i, hm_real *lb, hm_real *ub)
{
    if (i < HM_NU) {
        if (n == HM_N) return 0;
        *lb = qp->lbu[n][i];
        *ub = qp->ubu[n][i];
    } else {
        if (n == 0) return 0;
        *lb = qp->lbx[n][i - HM_NU];
        *ub = qp->ubx[n][i - HM_NU];
    }
    return 1;
}

/* The soft rows' passes take the list eight rows at a time (ocp_qp_ipm_rows). */
#define OCP_QP_IPM_LANES 8

/* rows of the list rounded up to whole blocks of lanes */
HM_FUNC int ocp_qp_ipm_rows_blocks(const hm_ocp_qp_ipm_rows *sr)
{
    return (sr->nr + OCP_QP_IPM_LANES - 1) / OCP_QP_IPM_LANES * OCP_QP_IPM_LANES;
}

/* Row r of the list as an absent row (a stage's padding row, or the list's past its last stage): no
 * coupling (d = 0), zero residuals at the state s = t = z = zs = 1, which pass A restores every
 * iteration; its steps never shorten the step length. */
HM_FUNC void ocp_qp_ipm_rows_absent(hm_ocp_qp_ipm_rows *sr, int r)
{
    sr->srow[r] = 0;
    sr->sd0[r] = sr->sd1[r] = sr->slg[r] = HM_R(0.0);
    sr->szl[r] = sr->sZl[r] = HM_R(1.0);
    sr->slive[r] = HM_R(0.0);
    sr->ss[r] = sr->st[r] = sr->sz[r] = sr->szs[r] = HM_R(1.0);
    sr->sds[r] = sr->sdt[r] = sr->sdz[r] = sr->sdzs[r] = HM_R(0.0);
    sr->gp[r] = sr->gd[r] = sr->sdr[r] = sr->sdsb[r] = sr->se[r] = HM_R(0.0);
}

/* Builds the stage blocks of qp and the starting point. Returns HM_QP_INFEASIBLE if a lower bound
 * exceeds its upper bound; *bad = stage * HM_QP_NUX + component. */
HM_FUNC int ocp_qp_ipm_setup(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, int *bad)
{
    hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    int n, i, j, k, l, m = 0, off = 0;
    int bounded[HM_QP_NUX];
    hm_real norm_q = HM_R(0.0), norm_b = HM_R(0.0), hscale = HM_R(0.0), c;

    /* bound pairs: a slot for every component bounded at some stage (crossing bounds, found in
     * stage order, make the QP infeasible), its sides per stage; the starting point t = max(b, 1),
     * z = 1 / t; a side absent at a stage keeps sign 0, b = t = z = 1 */
    for (i = 0; i < HM_QP_NUX; i++) bounded[i] = 0;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_QP_NUX; i++) {
            hm_real lb = HM_R(0.0), ub = HM_R(0.0);
            int lp, up;
            if (!ocp_qp_ipm_bounds_of(qp, n, i, &lb, &ub)) continue;
            lp = ocp_qp_bound_present(lb);
            up = ocp_qp_bound_present(ub);
            if (lp && up && lb > ub) {
                *bad = n * HM_QP_NUX + i;
                return HM_QP_INFEASIBLE;
            }
            if (lp || up) bounded[i] = 1;
        }
    }
    bd->nbp = 0;
    for (i = 0; i < HM_QP_NUX; i++) {
        if (bounded[i]) bd->bc[bd->nbp++] = (unsigned char)i;
    }
    for (k = 0; k < bd->nbp; k++) {
        const int comp = bd->bc[k];
        for (n = 0; n < HM_QP_NNP; n++) {
            hm_real lb = -HM_INF, ub = HM_INF;
            int lp = 0, up = 0;
            if (n <= HM_N && ocp_qp_ipm_bounds_of(qp, n, comp, &lb, &ub)) {
                lp = ocp_qp_bound_present(lb);
                up = ocp_qp_bound_present(ub);
            }
            bd->sg[k][0][n] = lp ? HM_R(-1.0) : HM_R(0.0);
            bd->sg[k][1][n] = up ? HM_R(1.0) : HM_R(0.0);
            bd->b[k][0][n] = lp ? -lb : HM_R(1.0);
            bd->b[k][1][n] = up ? ub : HM_R(1.0);
            if (lp) norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(lb));
            if (up) norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(ub));
            m += lp + up;
        }
        /* the starting point of the slot's sides: a loop of its own, without the branches of the
         * bounds' lookup, so that its divisions run in vector lanes (an absent side has b = 1) */
        for (l = 0; l < 2; l++) {
            const hm_real *restrict b = bd->b[k][l];
            hm_real *restrict t = bd->t[k][l];
            hm_real *restrict z = bd->z[k][l];
            hm_real *restrict dt = bd->dt[k][l];
            hm_real *restrict dz = bd->dz[k][l];
            for (n = 0; n < HM_QP_NNP; n++) {
                t[n] = OCP_QP_IPM_MAX(b[n], HM_R(1.0));
                z[n] = HM_R(1.0) / t[n];
                dt[n] = dz[n] = HM_R(0.0);
            }
        }
        for (n = 0; n < HM_QP_NNP; n++) bd->v[k][n] = bd->dv[k][n] = HM_R(0.0);
    }

    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        int ns = 0, nh = 0;
        sn->soff = off;
        /* general rows: soft ones and hard ones, each in QP order */
        if (n > 0) {
            for (i = 0; i < qp->ng[n]; i++) {
                const hm_real lg = qp->lg[n][i];
                if (!ocp_qp_bound_present(lg)) continue;
                norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(lg));
                if (qp->soft[n][i]) {
                    const int row = off + ns;
                    sr->srow[row] = (unsigned char)i;
                    sr->sd0[row] = qp->D[n][i][0];
                    sr->sd1[row] = qp->D[n][i][1];
                    sr->slg[row] = lg;
                    sr->szl[row] = qp->zl[n][i];
                    sr->sZl[row] = qp->Zl[n][i];
                    sr->slive[row] = HM_R(1.0);
                    norm_q = OCP_QP_IPM_MAX(norm_q, hm_fabs(qp->zl[n][i]));
                    hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->Zl[n][i]));
                    ns++;
                } else {
                    sn->hrow[nh] = (unsigned char)i;
                    sn->hd0[nh] = qp->D[n][i][0];
                    sn->hd1[nh] = qp->D[n][i][1];
                    sn->hlg[nh] = lg;
                    sn->hlive[nh] = HM_R(1.0);
                    nh++;
                }
            }
        }
        sn->ns = ns;
        sn->nh = nh;
        sn->ns2 = ns + (ns & 1);
        sn->nh2 = nh + (nh & 1);
        off += sn->ns2;
        m += 2 * ns + nh;

        /* cost and dynamics offset, unscaled for now; x_0 is data, its terms move into stage 0 */
        for (i = 0; i < HM_NU * HM_NU; i++) sn->R[i] = n < HM_N ? qp->R[n][i] : HM_R(0.0);
        for (i = 0; i < HM_NU * HM_NX; i++) sn->S[i] = (n > 0 && n < HM_N) ? qp->S[n][i] : HM_R(0.0);
        for (i = 0; i < HM_NX * HM_NX; i++) sn->Q[i] = n > 0 ? qp->Q[n][i] : HM_R(0.0);
        for (i = 0; i < HM_NU; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->r[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->S[0][i + k * HM_NU] * qp->x0[k];
                }
                hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->R[n][i * (HM_NU + 1)]));
            }
            sn->q[i] = acc;
        }
        for (i = 0; i < HM_NX; i++) {
            sn->q[HM_NU + i] = n == 0 ? HM_R(0.0) : qp->q[n][i];
            if (n > 0) hscale = OCP_QP_IPM_MAX(hscale, hm_fabs(qp->Q[n][i * (HM_NX + 1)]));
        }
        for (i = 0; i < HM_QP_NUX; i++) norm_q = OCP_QP_IPM_MAX(norm_q, hm_fabs(sn->q[i]));
        for (i = 0; i < HM_NX; i++) {
            hm_real acc = HM_R(0.0);
            if (n < HM_N) {
                acc = qp->b[n][i];
                if (n == 0) {
                    for (k = 0; k < HM_NX; k++) acc += qp->A[0][i + k * HM_NX] * qp->x0[k];
                }
            }
            sn->beq[i] = acc;
            norm_b = OCP_QP_IPM_MAX(norm_b, hm_fabs(acc));
        }
        sn->a_id = 0;
        sn->ab_int = 0;
        if (n < HM_N) {
            const hm_real *A = qp->A[n];
            const hm_real *B = qp->B[n];
            sn->a_id = A[0] == HM_R(1.0) && A[1] == HM_R(0.0) && A[2] == HM_R(0.0) && A[3] == HM_R(0.0)
                       && A[4] == HM_R(0.0) && A[5] == HM_R(1.0) && A[6] == HM_R(0.0) && A[7] == HM_R(0.0);
            sn->ab_int = sn->a_id && A[10] == HM_R(1.0) && A[11] == HM_R(0.0) && A[14] == HM_R(0.0)
                         && A[15] == HM_R(1.0) && B[2] == HM_R(0.0) && B[7] == HM_R(0.0);
        }
    }
    ws->m = m;
    sr->nr = off;

    /* Cost scaling (as in Clarabel): a cost measured in hundreds (goal weight 250) or a slack
     * penalty of 1e4 against rows measured in metres. Clipped so that tiny or huge data are not
     * blown up. */
    {
        const hm_real mag = OCP_QP_IPM_MAX(hscale, norm_q);
        c = HM_R(1.0) / (mag < HM_R(1e-4) ? HM_R(1e-4) : (mag > HM_R(1e4) ? HM_R(1e4) : mag));
        ws->cost_scale = c;
        ws->norm_q = norm_q * c;
        ws->norm_b = norm_b;
        ws->w_max = OCP_QP_IPM_W_MAX_REL * OCP_QP_IPM_MAX(HM_R(1.0), hscale * c);
    }

    /* scaled cost, padding rows, starting point: v = 0 (soft slacks satisfying their rows with a
     * margin of 1), y = 0, t = max(b - a' v, 1), z = 1 / t; zero step */
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (i = 0; i < HM_NU * HM_NU; i++) sn->R[i] *= c;
        for (i = 0; i < HM_NU * HM_NX; i++) sn->S[i] *= c;
        for (i = 0; i < HM_NX * HM_NX; i++) sn->Q[i] *= c;
        for (i = 0; i < HM_QP_NUX; i++) {
            sn->q[i] *= c;
            sn->ux[i] = HM_R(0.0);
            sn->dux[i] = HM_R(0.0);
        }
        for (i = 0; i < HM_NX; i++) {
            sn->y[i] = HM_R(0.0);
            sn->dy[i] = HM_R(0.0);
            sn->ry[i] = HM_R(0.0);
        }
        for (i = 0; i < HM_QP_NUX; i++) sn->rv[i] = HM_R(0.0);   /* set by the first stage measures */
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real s = OCP_QP_IPM_MAX(HM_R(0.0), sr->slg[row]) + HM_R(1.0);
            const hm_real t = OCP_QP_IPM_MAX(s - sr->slg[row], HM_R(1.0));
            sr->szl[row] *= c;
            sr->sZl[row] *= c;
            sr->ss[row] = s;
            sr->st[row] = t;   /* z = 1 / t and zs = 1 / s below, over the whole list */
        }
        if (sn->ns & 1) ocp_qp_ipm_rows_absent(sr, sn->soff + sn->ns);   /* the stage's padding row */
        for (j = sn->soff; j < sn->soff + sn->ns; j++) sr->sds[j] = sr->sdt[j] = sr->sdz[j] = sr->sdzs[j] = HM_R(0.0);
        for (j = 0; j < sn->nh; j++) {
            const hm_real t = OCP_QP_IPM_MAX(-sn->hlg[j], HM_R(1.0));
            sn->ht[j] = t;
            sn->hz[j] = HM_R(1.0) / t;
        }
        if (sn->nh & 1) {
            j = sn->nh;
            sn->hd0[j] = sn->hd1[j] = HM_R(0.0);
            sn->hlg[j] = HM_R(-1.0);
            sn->hlive[j] = HM_R(0.0);
            sn->ht[j] = sn->hz[j] = HM_R(1.0);
        }
        for (j = 0; j < sn->nh2; j++) sn->hdt[j] = sn->hdz[j] = HM_R(0.0);
    }
    /* the rows' starting multipliers, in vector lanes (a stage's padding row: 1 / 1) */
    {
        const hm_real *restrict ss = sr->ss, *restrict st = sr->st;
        hm_real *restrict sz = sr->sz, *restrict szs = sr->szs;
        for (j = 0; j < sr->nr; j++) {
            sz[j] = HM_R(1.0) / st[j];
            szs[j] = HM_R(1.0) / ss[j];
        }
    }
    /* the list's padding rows up to the last block of the passes */
    for (j = sr->nr; j < ocp_qp_ipm_rows_blocks(sr); j++) ocp_qp_ipm_rows_absent(sr, j);
    return 0;
}

/* ------------------------------------------------------------------------------------------------
 * Bound pairs, one side of one slot over all stages at once (ocp_qp_ipm_bounds). Functions of their
 * own so that the arrays are restrict parameters: the compiler then runs the stages in vector lanes.
 * ---------------------------------------------------------------------------------------------- */

/* Pass A: the step, the weights and the side's parts of the diagonal and the gradients; per stage
 * t z, b z and the residual |rho + t|. (Its part of A' w, sign * z, only the stage measures read.) */
HM_FUNC void ocp_qp_ipm_bound_side_a(hm_real alpha, hm_real wmax, const hm_real *restrict sg,
                                     const hm_real *restrict b, const hm_real *restrict v,
                                     const hm_real *restrict dt, const hm_real *restrict dz, hm_real *restrict t,
                                     hm_real *restrict z, hm_real *restrict w, hm_real *restrict ti,
                                     hm_real *restrict zi, hm_real *restrict rho,
                                     hm_real *restrict Hd, hm_real *restrict hf, hm_real *restrict hmu,
                                     hm_real *restrict tz, hm_real *restrict bw, hm_real *restrict rp)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n];
        const hm_real msk = s * s;
        const hm_real tn = msk * (t[n] + alpha * dt[n]) + (HM_R(1.0) - msk);
        const hm_real zn = msk * (z[n] + alpha * dz[n]) + (HM_R(1.0) - msk);
        const hm_real r = s * v[n] - b[n];
        const hm_real inv = HM_R(1.0) / (tn * zn);
        const hm_real tin = zn * inv, zin = tn * inv;
        const hm_real wn = OCP_QP_IPM_MIN(zn * tin, wmax);
        t[n] = tn;
        z[n] = zn;
        w[n] = wn;
        ti[n] = tin;
        zi[n] = zin;
        rho[n] = r;
        Hd[n] += msk * wn;
        hf[n] += s * wn * r;
        hmu[n] += s * wn * zin;
        tz[n] += msk * tn * zn;
        rp[n] = OCP_QP_IPM_MAX(rp[n], OCP_QP_IPM_ABS(r + tn));
        bw[n] += msk * b[n] * zn;
    }
}

/* Pass C: the predictor's steps from the (u, x) step dv, their products dt dz (kept in del), the
 * side's part of hdl, and per stage the step ratio, t dz + z dt and dt dz. */
HM_FUNC void ocp_qp_ipm_bound_side_c(const hm_real *restrict sg, const hm_real *restrict t,
                                     const hm_real *restrict z, const hm_real *restrict w,
                                     const hm_real *restrict ti, const hm_real *restrict zi,
                                     const hm_real *restrict rho, const hm_real *restrict dv,
                                     hm_real *restrict del, hm_real *restrict hdl, hm_real *restrict ratio,
                                     hm_real *restrict tdz, hm_real *restrict dtdz)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n], msk = s * s;
        const hm_real dzn = w[n] * (s * dv[n] + rho[n]);
#ifdef OCP_QP_IPM_DT_PRIMAL
        const hm_real dtn = -(rho[n] + t[n]) - s * dv[n];
#else
        const hm_real dtn = -t[n] - t[n] * dzn * zi[n];
#endif
        const hm_real d = dtn * dzn;
        del[n] = d;
        hdl[n] -= s * w[n] * zi[n] * d;
        ratio[n] = OCP_QP_IPM_MAX(ratio[n], OCP_QP_IPM_MAX(-dtn * ti[n], -dzn * zi[n]));
        tdz[n] += msk * (t[n] * dzn + z[n] * dtn);
        dtdz[n] += msk * d;
    }
}

/* Pass E: the corrector's steps (target smu, second-order term kdel * del) and the step ratio. */
HM_FUNC void ocp_qp_ipm_bound_side_e(hm_real smu, hm_real kdel, const hm_real *restrict sg,
                                     const hm_real *restrict t, const hm_real *restrict z,
                                     const hm_real *restrict w, const hm_real *restrict ti,
                                     const hm_real *restrict zi, const hm_real *restrict rho,
                                     const hm_real *restrict del, const hm_real *restrict dv, hm_real *restrict dt,
                                     hm_real *restrict dz, hm_real *restrict ratio)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n];
        const hm_real cc = smu - kdel * del[n];
        const hm_real dzn = w[n] * (s * dv[n] + rho[n] + cc * zi[n]);
#ifdef OCP_QP_IPM_DT_PRIMAL
        const hm_real dtn = -(rho[n] + t[n]) - s * dv[n];
        (void)z;
#else
        const hm_real dtn = -(t[n] * z[n] - cc + t[n] * dzn) * zi[n];
#endif
        dz[n] = dzn;
        dt[n] = dtn;
        ratio[n] = OCP_QP_IPM_MAX(ratio[n], OCP_QP_IPM_MAX(-dtn * ti[n], -dzn * zi[n]));
    }
}

/* The termination tests' measures: per stage |A_I v + t|, t and min(t, z) of the present sides. */
HM_FUNC void ocp_qp_ipm_bound_side_measures(const hm_real *restrict sg, const hm_real *restrict t,
                                            const hm_real *restrict z, const hm_real *restrict v,
                                            hm_real *restrict av, hm_real *restrict nt, hm_real *restrict ncr)
{
    int n;
    for (n = 0; n < HM_QP_NNP; n++) {
        const hm_real s = sg[n], msk = s * s;
        av[n] = OCP_QP_IPM_MAX(av[n], msk * OCP_QP_IPM_ABS(s * v[n] + t[n]));
        nt[n] = OCP_QP_IPM_MAX(nt[n], msk * t[n]);
        ncr[n] = OCP_QP_IPM_MAX(ncr[n], msk * OCP_QP_IPM_MIN(t[n], z[n]));
    }
}

/* ------------------------------------------------------------------------------------------------
 * Soft rows, eight rows of the list at a time (ocp_qp_ipm_rows): the same arithmetic for every row,
 * the stages' parts summed afterwards. Lanes keep the sums and maxima of the passes.
 * ---------------------------------------------------------------------------------------------- */

/* Pass A: the step, the weights, the eliminated slack, and per row the factors of its parts of the
 * stage's (px, py) block and gradients, we (in sdr), e (in sdsb) and cmu (in se); lanes: t z, b w,
 * q v, v P v, the primal and the slack's dual residual. */
HM_FUNC void ocp_qp_ipm_rows_a(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real alpha, hm_real wmax,
                               hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real s = msk * (sr->ss[q] + alpha * sr->sds[q]) + (HM_R(1.0) - msk);
            const hm_real t = msk * (sr->st[q] + alpha * sr->sdt[q]) + (HM_R(1.0) - msk);
            const hm_real z = msk * (sr->sz[q] + alpha * sr->sdz[q]) + (HM_R(1.0) - msk);
            const hm_real zs = msk * (sr->szs[q] + alpha * sr->sdzs[q]) + (HM_R(1.0) - msk);
            const hm_real lg = sr->slg[q], Zl = sr->sZl[q];
            const hm_real rho = lg - sr->gp[q] - s;
            const hm_real rs = Zl * s + sr->szl[q] - z - zs;
            const hm_real ia = HM_R(1.0) / (t * z), ib = HM_R(1.0) / (s * zs);
            const hm_real ti = z * ia, zi = t * ia, si = zs * ib, zsi = s * ib;
            const hm_real wr = OCP_QP_IPM_MIN(z * ti, wmax), wsl = OCP_QP_IPM_MIN(zs * si, wmax);
            const hm_real hinv = HM_R(1.0) / (Zl + wr + wsl);
            const hm_real hw = hinv * wr;
            const hm_real we = hw * (Zl + wsl);
            const hm_real e = we * rho + hw * (rs + wsl * s);
            const hm_real cmu = we * zi - hw * wsl * zsi;
            sr->ss[q] = s;
            sr->st[q] = t;
            sr->sz[q] = z;
            sr->szs[q] = zs;
            sr->sti[q] = ti;
            sr->szi[q] = zi;
            sr->ssi[q] = si;
            sr->szsi[q] = zsi;
            sr->swr[q] = wr;
            sr->sws[q] = wsl;
            sr->shi[q] = hinv;
            sr->srs[q] = rs;
            sr->sdr[q] = we;
            sr->sdsb[q] = e;
            sr->se[q] = cmu;
            lane[0][l] += msk * (t * z + s * zs);
            lane[1][l] -= msk * lg * z;
            lane[2][l] += msk * sr->szl[q] * s;
            lane[3][l] += msk * Zl * s * s;
            lane[4][l] = OCP_QP_IPM_MAX(lane[4][l], OCP_QP_IPM_ABS(t + rho));
            lane[5][l] = OCP_QP_IPM_MAX(lane[5][l], OCP_QP_IPM_ABS(rs));
        }
    }
}

/* Pass C: the predictor's steps from the position steps (gd), their products (kept in sdr, sdsb for
 * the corrector), per row the factor of its part of hdl on (px, py) in se; lanes: the step ratio,
 * t dz + z dt and dt dz. */
HM_FUNC void ocp_qp_ipm_rows_c(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real s = sr->ss[q], t = sr->st[q], z = sr->sz[q], zs = sr->szs[q];
            const hm_real wr = sr->swr[q], wsl = sr->sws[q], hinv = sr->shi[q];
            const hm_real zi = sr->szi[q], zsi = sr->szsi[q];
            const hm_real hw = hinv * wr, we = hw * (sr->sZl[q] + wsl);
            const hm_real gd = sr->gd[q];
            const hm_real rho = sr->slg[q] - sr->gp[q] - s;
            const hm_real ds = hinv * (wr * rho - wsl * s - sr->srs[q]) - hw * gd;
            const hm_real dz = wr * (rho - gd - ds);
            const hm_real dzs = -wsl * (s + ds);
#ifdef OCP_QP_IPM_DT_PRIMAL
            const hm_real dt = gd + ds - (t + rho);
#else
            const hm_real dt = -t - t * dz * zi;
#endif
            const hm_real dr = dt * dz, dsb = ds * dzs;
            const hm_real coef = we * zi * dr - hw * wsl * zsi * dsb;
            sr->sdr[q] = dr;
            sr->sdsb[q] = dsb;
            sr->se[q] = coef;
            lane[0][l] = OCP_QP_IPM_MAX(lane[0][l], OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(-dt * sr->sti[q], -dz * zi),
                                                                  OCP_QP_IPM_MAX(-ds * sr->ssi[q], -dzs * zsi)));
            lane[1][l] += msk * (t * dz + z * dt + s * dzs + zs * ds);
            lane[2][l] += msk * (dr + dsb);
        }
    }
}

/* Pass E: the corrector's steps (target smu, second-order term kdel * (sdr, sdsb)); lane: the step
 * ratio. */
HM_FUNC void ocp_qp_ipm_rows_e(hm_ocp_qp_ipm_rows *restrict sr, int nrp, hm_real smu, hm_real kdel,
                               hm_real *restrict lane)
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real s = sr->ss[q], t = sr->st[q], z = sr->sz[q];
            const hm_real wr = sr->swr[q], wsl = sr->sws[q], hinv = sr->shi[q];
            const hm_real zi = sr->szi[q], zsi = sr->szsi[q];
            const hm_real cr = smu - kdel * sr->sdr[q], cs = smu - kdel * sr->sdsb[q];
            const hm_real hw = hinv * wr;
            const hm_real gd = sr->gd[q];
            const hm_real rho0 = sr->slg[q] - sr->gp[q] - s;
            const hm_real rho = rho0 + cr * zi;
            const hm_real rhos = cs * zsi - s;
            const hm_real ds = hinv * (wr * rho + wsl * rhos - sr->srs[q]) - hw * gd;
            const hm_real dz = wr * (rho - gd - ds);
            const hm_real dzs = wsl * (rhos - ds);
#ifdef OCP_QP_IPM_DT_PRIMAL
            const hm_real dt = gd + ds - (t + rho0);
            (void)z;
#else
            const hm_real dt = -(t * z - cr + t * dz) * zi;
#endif
            sr->sds[q] = ds;
            sr->sdt[q] = dt;
            sr->sdz[q] = dz;
            sr->sdzs[q] = dzs;
            lane[l] = OCP_QP_IPM_MAX(lane[l], OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(-dt * sr->sti[q], -dz * zi),
                                                             OCP_QP_IPM_MAX(-ds * sr->ssi[q], -dzs * zsi)));
        }
    }
}

/* The termination tests' measures over the live rows (padding rows masked to 0): |A_I v + t|, t,
 * min(t, z) and min(s, zs), the slack's A' w and P v. */
HM_FUNC void ocp_qp_ipm_rows_measures(const hm_ocp_qp_ipm_rows *restrict sr, int nrp,
                                      hm_real (*restrict lane)[OCP_QP_IPM_LANES])
{
    int r0, l;
    for (r0 = 0; r0 < nrp; r0 += OCP_QP_IPM_LANES) {
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            const int q = r0 + l;
            const hm_real msk = sr->slive[q];
            const hm_real t = sr->st[q], z = sr->sz[q], s = sr->ss[q], zs = sr->szs[q];
            const hm_real av = t - sr->gp[q] - s;
            lane[0][l] = OCP_QP_IPM_MAX(lane[0][l], msk * OCP_QP_IPM_ABS(av));
            lane[1][l] = OCP_QP_IPM_MAX(lane[1][l], msk * t);
            lane[2][l] = OCP_QP_IPM_MAX(lane[2][l], msk * OCP_QP_IPM_MAX(OCP_QP_IPM_MIN(t, z), OCP_QP_IPM_MIN(s, zs)));
            lane[3][l] = OCP_QP_IPM_MAX(lane[3][l], msk * (z + zs));
            lane[4][l] = OCP_QP_IPM_MAX(lane[4][l], msk * OCP_QP_IPM_ABS(sr->sZl[q] * s));
        }
    }
}

/* ------------------------------------------------------------------------------------------------
 * Pass A: step, residuals, weights, condensation
 * ---------------------------------------------------------------------------------------------- */

/* Scalars of one residual evaluation. Pass A computes the inequalities' parts exactly and takes the
 * residuals of the dynamics (ry) and of the stationarity of (u, x) (rv) by their recurrence: a
 * Newton step solves those linear equations, so a step of length alpha leaves (1 - alpha) of them.
 * The recurrence saves the stage products (P v, A' w, A_E v) in most iterations; they are evaluated
 * exactly (ocp_qp_ipm_stage_measures: the residuals afresh, the norms of the stage vectors, the
 * cost) in the first iteration and whenever the termination tests could pass, so no test passes on
 * recurred values and rounding drift cannot accumulate into the solution (ocp_qp_ipm_solve). The
 * norms over the inequalities (av_ineq .. pv_s) only enter the termination tests' normalisation,
 * the natural residual and the certificate test, and are computed by ocp_qp_ipm_row_measures only
 * when one of those tests can pass. */
typedef struct {
    hm_real qv, bw, vPv, tz;          /* q' v, b' w, v' P v, t' z (q' v, v' P v: after stage measures) */
    hm_real atw, pv, av_eq;           /* inf-norms over (u, x) of A' w and P v; of A_E v (the same) */
    hm_real rd, rp;                   /* inf-norms of the dual and primal residuals */
    hm_real rd_eq, rp_eq;             /* their parts of the stationarity of (u, x), of the dynamics */
    hm_real rd_in, rp_in;             /* and of the soft slacks, of the inequalities */
    hm_real qv_in, vPv_in;            /* the soft slacks' parts of q' v and v' P v */
    hm_real vz;                       /* 0 * sum of v: NaN if v holds a NaN or an infinity */
    int exact;                        /* the stage measures are of this iterate */
    int measured;                     /* so are the inequality measures */
    hm_real av_ineq, nt;              /* inf-norms of A_I v + t and of t */
    hm_real ncr;                      /* max over inequalities of min(t, z) */
    hm_real atw_s, pv_s;              /* inf-norms over the soft slacks of A' w and P v */
} ocp_qp_ipm_sums;

/* y = H_n x for the (scaled) cost Hessian [R S; S' Q] of stage n on (u, x); parts absent at stage 0
 * (x) and stage N (u) are zero in the stage block and in x. */
HM_KERNEL void ocp_qp_ipm_hess_mul(const hm_ocp_qp_ipm_stage *restrict sn, const hm_real *restrict x,
                                 hm_real *restrict y)
{
    const hm_real *restrict R = sn->R;
    const hm_real *restrict S = sn->S;
    const hm_real *restrict Q = sn->Q;
    const hm_real u0 = x[0], u1 = x[1];
    hm_real yx[HM_NX];
    int i, k;
    y[0] = R[0] * u0 + R[2] * u1;
    y[1] = R[1] * u0 + R[3] * u1;
    for (i = 0; i < HM_NX; i++) yx[i] = Q[i] * x[HM_NU];
    for (k = 1; k < HM_NX; k++) {
        const hm_real xk = x[HM_NU + k];
        for (i = 0; i < HM_NX; i++) yx[i] += Q[i + k * HM_NX] * xk;
    }
    for (k = 0; k < HM_NX; k++) {
        const hm_real *restrict sk = &S[k * HM_NU];
        y[0] += sk[0] * x[HM_NU + k];
        y[1] += sk[1] * x[HM_NU + k];
        yx[k] += sk[0] * u0 + sk[1] * u1;
    }
    for (i = 0; i < HM_NX; i++) y[HM_NU + i] = yx[i];
}

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
                    const hm_real msk = sn->hlive[q];
                    const hm_real t = msk * (sn->ht[q] + alpha * sn->hdt[q]) + (HM_R(1.0) - msk);
                    const hm_real z = msk * (sn->hz[q] + alpha * sn->hdz[q]) + (HM_R(1.0) - msk);
                    const hm_real d0 = sn->hd0[q], d1 = sn->hd1[q], lg = sn->hlg[q];
                    const hm_real rho = lg - (d0 * p0 + d1 * p1);
                    const hm_real ia = HM_R(1.0) / (t * z);
                    const hm_real ti = z * ia, zi = t * ia;
                    const hm_real w = OCP_QP_IPM_MIN(z * ti, wmax);
                    const hm_real wr = w * rho, wz = w * zi;
                    sn->ht[q] = t;
                    sn->hz[q] = z;
                    sn->hti[q] = ti;
                    sn->hzi[q] = zi;
                    sn->hw[q] = w;
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

/* The rows' part of A' w at stage n > 0 (on (px, py): -d z of each row), subtracted from atw. */
HM_KERNEL void ocp_qp_ipm_rows_atw(const hm_ocp_qp_ipm_stage *restrict sn, const hm_ocp_qp_ipm_rows *restrict sr,
                                   hm_real *restrict atw)
{
    int j;
    for (j = sn->soff; j < sn->soff + sn->ns2; j++) {
        atw[HM_NU] -= sr->sd0[j] * sr->sz[j];
        atw[HM_NU + 1] -= sr->sd1[j] * sr->sz[j];
    }
    for (j = 0; j < sn->nh2; j++) {
        atw[HM_NU] -= sn->hd0[j] * sn->hz[j];
        atw[HM_NU + 1] -= sn->hd1[j] * sn->hz[j];
    }
}

/* The bound pairs' part of A' w at stage n (sign * z of each side), added to atw. */
HM_KERNEL void ocp_qp_ipm_bounds_atw(const hm_ocp_qp_ipm_bounds *restrict bd, int n, hm_real *restrict atw)
{
    int k;
    for (k = 0; k < bd->nbp; k++)
        atw[bd->bc[k]] += bd->sg[k][0][n] * bd->z[k][0][n] + bd->sg[k][1][n] * bd->z[k][1][n];
}

/* The exact stage measures of the iterate left by pass A (see ocp_qp_ipm_sums): the residuals of
 * the dynamics and of the stationarity of (u, x) evaluated afresh (the predictor's gradient ha
 * corrected by the difference to the recurred ones), the norms of A' w, P v and A_E v, and q' v,
 * v' P v. */
HM_FUNC void ocp_qp_ipm_stage_measures(const hm_ocp_qp *restrict qp, hm_ocp_qp_ipm_ws *restrict ws,
                                       ocp_qp_ipm_sums *restrict sm)
{
    hm_real qv = HM_R(0.0), vPv = HM_R(0.0), atw_n = HM_R(0.0), pv_n = HM_R(0.0), aveq_n = HM_R(0.0);
    hm_real rd_eq = HM_R(0.0), rp_eq = HM_R(0.0);
    hm_real rd_v[HM_QP_NUX], pv_v[HM_QP_NUX], atw_v[HM_QP_NUX], eq_v[HM_NX], rpe_v[HM_NX];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i, k;

    for (i = 0; i < HM_QP_NUX; i++) rd_v[i] = pv_v[i] = atw_v[i] = HM_R(0.0);
    for (i = 0; i < HM_NX; i++) eq_v[i] = rpe_v[i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        const hm_real *restrict ux = sn->ux;
        hm_real Pux[HM_QP_NUX], atw[HM_QP_NUX];

        /* dynamics n - 1 -> n: x_n - A x_{n-1} - B u_{n-1} = b_{n-1} */
        if (n > 0) {
            hm_ocp_qp_ipm_stage *restrict sp = &ws->u.f.st[n - 1];
            const hm_real *restrict A = qp->A[n - 1];
            const hm_real *restrict B = qp->B[n - 1];
            const hm_real *restrict up = sp->ux;
            hm_real e[HM_NX];
            for (i = 0; i < HM_NX; i++) e[i] = ux[HM_NU + i] - B[i] * up[0] - B[i + HM_NX] * up[1];
            /* all of A, also where its first columns are e_0, e_1 (sp->a_id): the products with
             * 1 and 0 are exact, and a uniform loop keeps e in registers (the special case
             * stored half of e and reloaded it whole, a failed store forwarding per stage) */
            if (n > 1) {
                for (k = 0; k < HM_NX; k++) {
                    const hm_real xk = up[HM_NU + k];
                    for (i = 0; i < HM_NX; i++) e[i] -= A[i + k * HM_NX] * xk;
                }
            }
            for (i = 0; i < HM_NX; i++) {
                const hm_real ri = e[i] - sp->beq[i];
                sp->ry[i] = -ri;
                eq_v[i] = OCP_QP_IPM_MAX(eq_v[i], OCP_QP_IPM_ABS(e[i]));
                rpe_v[i] = OCP_QP_IPM_MAX(rpe_v[i], OCP_QP_IPM_ABS(ri));
            }
        }

        /* A' w: the dynamics, the rows, the bound pairs (sign * z of each side) */
        if (n < HM_N) {
            const hm_real *restrict B = qp->B[n];
            const hm_real *restrict y = sn->y;
            atw[0] = -(B[0] * y[0] + B[1] * y[1] + B[2] * y[2] + B[3] * y[3]);
            atw[1] = -(B[4] * y[0] + B[5] * y[1] + B[6] * y[2] + B[7] * y[3]);
        } else {
            atw[0] = atw[1] = HM_R(0.0);
        }
        if (n > 0) {
            const hm_real *restrict ym = ws->u.f.st[n - 1].y;
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = ym[i];
            if (n < HM_N) {
                const hm_real *restrict A = qp->A[n];
                const hm_real *restrict y = sn->y;
                for (i = 0; i < HM_NX; i++) {
                    const hm_real *restrict a = &A[i * HM_NX];
                    atw[HM_NU + i] -= (a[0] * y[0] + a[1] * y[1]) + (a[2] * y[2] + a[3] * y[3]);
                }
            }
            ocp_qp_ipm_rows_atw(sn, sr, atw);
        } else {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] = HM_R(0.0);
        }
        ocp_qp_ipm_bounds_atw(bd, n, atw);

        /* stationarity of (u, x): r = P v + q + A' w */
        ocp_qp_ipm_hess_mul(sn, ux, Pux);
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = Pux[i] + sn->q[i] + atw[i];
            sn->ha[i] += ri - sn->rv[i];
            sn->rv[i] = ri;
            atw_v[i] = OCP_QP_IPM_MAX(atw_v[i], OCP_QP_IPM_ABS(atw[i]));
            pv_v[i] = OCP_QP_IPM_MAX(pv_v[i], OCP_QP_IPM_ABS(Pux[i]));
            rd_v[i] = OCP_QP_IPM_MAX(rd_v[i], OCP_QP_IPM_ABS(ri));
        }
        for (i = 0; i < HM_QP_NUX; i++) {
            qv += sn->q[i] * ux[i];
            vPv += Pux[i] * ux[i];
        }
    }
    for (i = 0; i < HM_QP_NUX; i++) {
        atw_n = OCP_QP_IPM_MAX(atw_n, atw_v[i]);
        pv_n = OCP_QP_IPM_MAX(pv_n, pv_v[i]);
        rd_eq = OCP_QP_IPM_MAX(rd_eq, rd_v[i]);
    }
    for (i = 0; i < HM_NX; i++) {
        aveq_n = OCP_QP_IPM_MAX(aveq_n, eq_v[i]);
        rp_eq = OCP_QP_IPM_MAX(rp_eq, rpe_v[i]);
    }
    sm->qv = sm->qv_in + qv;
    sm->vPv = sm->vPv_in + vPv;
    sm->atw = atw_n;
    sm->pv = pv_n;
    sm->av_eq = aveq_n;
    sm->rp_eq = rp_eq;
    sm->rd_eq = rd_eq;
    sm->rp = OCP_QP_IPM_MAX(sm->rp_in, rp_eq);
    sm->rd = OCP_QP_IPM_MAX(sm->rd_in, rd_eq);
    sm->exact = 1;
}

/* ocp_qp_ipm_stage_measures at the starting point, where v = 0 and y = 0 (the cold start and the warm
 * start both begin there, and pass A's step is zero): every product with v or y vanishes, so the
 * residuals are r_y = b_E and r_v = q + A_I' z (the inequalities' multipliers alone), the norms of P v
 * and A_E v are zero, and so are q' v and v' P v. The same numbers as the general sweep (up to the
 * sign of a zero), without its products: the first iteration of every solve takes them. */
HM_FUNC void ocp_qp_ipm_stage_measures_start(hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm)
{
    hm_real atw_n = HM_R(0.0), rd_eq = HM_R(0.0), rp_eq = HM_R(0.0);
    hm_real rd_v[HM_QP_NUX], atw_v[HM_QP_NUX], rpe_v[HM_NX];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, i;

    for (i = 0; i < HM_QP_NUX; i++) rd_v[i] = atw_v[i] = HM_R(0.0);
    for (i = 0; i < HM_NX; i++) rpe_v[i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        hm_real atw[HM_QP_NUX];
        /* dynamics n -> n + 1: the residual of x_{n+1} - A x_n - B u_n = b_n is -b_n */
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) {
                sn->ry[i] = sn->beq[i];
                rpe_v[i] = OCP_QP_IPM_MAX(rpe_v[i], OCP_QP_IPM_ABS(sn->beq[i]));
            }
        }
        /* A' w: the rows and the bound pairs */
        for (i = 0; i < HM_QP_NUX; i++) atw[i] = HM_R(0.0);
        if (n > 0) {
            ocp_qp_ipm_rows_atw(sn, sr, atw);
        }
        ocp_qp_ipm_bounds_atw(bd, n, atw);
        /* stationarity of (u, x): r = q + A' w */
        for (i = 0; i < HM_QP_NUX; i++) {
            const hm_real ri = sn->q[i] + atw[i];
            sn->ha[i] += ri - sn->rv[i];
            sn->rv[i] = ri;
            atw_v[i] = OCP_QP_IPM_MAX(atw_v[i], OCP_QP_IPM_ABS(atw[i]));
            rd_v[i] = OCP_QP_IPM_MAX(rd_v[i], OCP_QP_IPM_ABS(ri));
        }
    }
    for (i = 0; i < HM_QP_NUX; i++) {
        atw_n = OCP_QP_IPM_MAX(atw_n, atw_v[i]);
        rd_eq = OCP_QP_IPM_MAX(rd_eq, rd_v[i]);
    }
    for (i = 0; i < HM_NX; i++) rp_eq = OCP_QP_IPM_MAX(rp_eq, rpe_v[i]);
    sm->qv = sm->qv_in;
    sm->vPv = sm->vPv_in;
    sm->atw = atw_n;
    sm->pv = HM_R(0.0);
    sm->av_eq = HM_R(0.0);
    sm->rp_eq = rp_eq;
    sm->rd_eq = rd_eq;
    sm->rp = OCP_QP_IPM_MAX(sm->rp_in, rp_eq);
    sm->rd = OCP_QP_IPM_MAX(sm->rd_in, rd_eq);
    sm->exact = 1;
}

/* The norms over the inequalities of the iterate left by pass A (see ocp_qp_ipm_sums). */
HM_FUNC void ocp_qp_ipm_row_measures(const hm_ocp_qp_ipm_ws *restrict ws, ocp_qp_ipm_sums *restrict sm)
{
    hm_real av = HM_R(0.0), nt = HM_R(0.0), ncr = HM_R(0.0), atw_s = HM_R(0.0), pv_s = HM_R(0.0);
    /* bound lanes: maxima per lane (as in pass A), absent sides masked to zero */
    hm_real avb[HM_QP_NNP], ntb[HM_QP_NNP], ncrb[HM_QP_NNP];
    const hm_ocp_qp_ipm_bounds *restrict bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *restrict sr = &ws->u.f.sr;
    int n, k, l, j;
    for (n = 0; n < HM_QP_NNP; n++) avb[n] = ntb[n] = ncrb[n] = HM_R(0.0);
    for (k = 0; k < bd->nbp; k++) {
        for (l = 0; l < 2; l++)
            ocp_qp_ipm_bound_side_measures(bd->sg[k][l], bd->t[k][l], bd->z[k][l], bd->v[k], avb, ntb, ncrb);
    }
    for (n = 0; n < HM_QP_NNP; n++) {
        av = OCP_QP_IPM_MAX(av, avb[n]);
        nt = OCP_QP_IPM_MAX(nt, ntb[n]);
        ncr = OCP_QP_IPM_MAX(ncr, ncrb[n]);
    }
    /* soft rows, all at once (the padding rows masked) */
    {
        hm_real lane[5][OCP_QP_IPM_LANES];
        for (l = 0; l < OCP_QP_IPM_LANES; l++)
            lane[0][l] = lane[1][l] = lane[2][l] = lane[3][l] = lane[4][l] = HM_R(0.0);
        ocp_qp_ipm_rows_measures(sr, ocp_qp_ipm_rows_blocks(sr), lane);
        for (l = 0; l < OCP_QP_IPM_LANES; l++) {
            av = OCP_QP_IPM_MAX(av, lane[0][l]);
            nt = OCP_QP_IPM_MAX(nt, lane[1][l]);
            ncr = OCP_QP_IPM_MAX(ncr, lane[2][l]);
            atw_s = OCP_QP_IPM_MAX(atw_s, lane[3][l]);
            pv_s = OCP_QP_IPM_MAX(pv_s, lane[4][l]);
        }
    }
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *restrict sn = &ws->u.f.st[n];
        const hm_real p0 = sn->ux[HM_NU], p1 = sn->ux[HM_NU + 1];
        if (n == 0) continue;
        for (j = 0; j < sn->nh; j++) {
            const hm_real t = sn->ht[j], z = sn->hz[j];
            av = OCP_QP_IPM_MAX(av, OCP_QP_IPM_ABS(t - (sn->hd0[j] * p0 + sn->hd1[j] * p1)));
            nt = OCP_QP_IPM_MAX(nt, t);
            ncr = OCP_QP_IPM_MAX(ncr, OCP_QP_IPM_MIN(t, z));
        }
    }
    sm->av_ineq = av;
    sm->nt = nt;
    sm->ncr = ncr;
    sm->atw_s = atw_s;
    sm->pv_s = pv_s;
    sm->measured = 1;
}

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
        if (ocp_qp_kkt_factor_stage(qp, sn, sn1, n)) return HM_QP_NUMERICAL;
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

/* Scalars of the predictor's forward pass. */
typedef struct {
    hm_real ratio;    /* max of -dt / t and -dz / z: the step to the boundary is 1 / max(1, ratio) */
    hm_real tdz;      /* sum t dz + z dt */
    hm_real dtdz;     /* sum dt dz */
} ocp_qp_ipm_pred;

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
                        const hm_real msk = sn->hlive[q];
                        const hm_real d0 = sn->hd0[q], d1 = sn->hd1[q];
                        const hm_real t = sn->ht[q], z = sn->hz[q], w = sn->hw[q], zi = sn->hzi[q];
                        const hm_real gd = d0 * dp0 + d1 * dp1;
                        const hm_real rho = sn->hlg[q] - (d0 * p0 + d1 * p1);
                        const hm_real dz = w * (rho - gd);
#ifdef OCP_QP_IPM_DT_PRIMAL
                        const hm_real dt = gd - (t + rho);
#else
                        const hm_real dt = -t - t * dz * zi;
#endif
                        const hm_real del = dt * dz;
                        const hm_real coef = w * zi * del;
                        sn->hdel[q] = del;
                        g0[l] += d0 * coef;
                        g1[l] += d1 * coef;
                        ra[l] = OCP_QP_IPM_MAX(ra[l], OCP_QP_IPM_MAX(-dt * sn->hti[q], -dz * zi));
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
        ocp_qp_ipm_rows_c(sr, ocp_qp_ipm_rows_blocks(sr), lane);
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
                        const hm_real d0 = sn->hd0[q], d1 = sn->hd1[q];
                        const hm_real t = sn->ht[q], z = sn->hz[q], w = sn->hw[q], zi = sn->hzi[q];
                        const hm_real cc = smu - kdel * sn->hdel[q];
                        const hm_real gd = d0 * dp0 + d1 * dp1;
                        const hm_real rho0 = sn->hlg[q] - (d0 * p0 + d1 * p1);
                        const hm_real dz = w * (rho0 + cc * zi - gd);
#ifdef OCP_QP_IPM_DT_PRIMAL
                        const hm_real dt = gd - (t + rho0);
                        (void)z;
#else
                        const hm_real dt = -(t * z - cc + t * dz) * zi;
#endif
                        sn->hdz[q] = dz;
                        sn->hdt[q] = dt;
                        ra[l] = OCP_QP_IPM_MAX(ra[l], OCP_QP_IPM_MAX(-dt * sn->hti[q], -dz * zi));
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
        ocp_qp_ipm_rows_e(sr, ocp_qp_ipm_rows_blocks(sr), smu, kdel, lane);
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
    for (j = 0; j < sn->nh; j++) sol->lam_lg[n][sn->hrow[j]] = sc * zh[j];
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
                               &ws->u.f.sr.ss[sn->soff], &ws->u.f.sr.sz[sn->soff], &ws->u.f.sr.szs[sn->soff], sn->hz,
                               sc, sp);
    }
}

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

/* Farkas test of the dual part w = (y, z) of a vector in the solver's layout: b' w < 0 and
 * ||A' w||_inf <= tol_infeas * (-b' w) (z >= 0 is the caller's). Returns 1 if it passes, with b' w. */
HM_FUNC int ocp_qp_ipm_farkas(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_vec *w,
                              hm_real tol_infeas, hm_real *bw_out)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_real bw = HM_R(0.0), atw_n = HM_R(0.0);
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real atw[HM_QP_NUX];
        for (i = 0; i < HM_QP_NUX; i++) atw[i] = HM_R(0.0);
        if (n < HM_N) {
            const hm_real *y = w->y[n];
            for (i = 0; i < HM_NU; i++) atw[i] -= ocp_qp_kkt_dot4(qp->B[n] + i * HM_NX, y);
            if (n > 0) {
                for (i = 0; i < HM_NX; i++) atw[HM_NU + i] -= ocp_qp_kkt_dot4(qp->A[n] + i * HM_NX, y);
            }
            for (i = 0; i < HM_NX; i++) bw += sn->beq[i] * y[i];
        }
        if (n > 0) {
            for (i = 0; i < HM_NX; i++) atw[HM_NU + i] += w->y[n - 1][i];
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                const hm_real sg = bd->sg[k][l][n];
                atw[bd->bc[k]] += sg * w->zb[n][k][l];
                bw += sg * sg * bd->b[k][l][n] * w->zb[n][k][l];
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real as = OCP_QP_IPM_ABS(w->zr[n][j] + w->zs[n][j]);
            atw[HM_NU] -= sr->sd0[row] * w->zr[n][j];
            atw[HM_NU + 1] -= sr->sd1[row] * w->zr[n][j];
            bw -= sr->slg[row] * w->zr[n][j];
            atw_n = OCP_QP_IPM_MAX(atw_n, as);
        }
        for (j = 0; j < sn->nh; j++) {
            atw[HM_NU] -= sn->hd0[j] * w->zh[n][j];
            atw[HM_NU + 1] -= sn->hd1[j] * w->zh[n][j];
            bw -= sn->hlg[j] * w->zh[n][j];
        }
        for (i = c0; i < c1; i++) atw_n = OCP_QP_IPM_MAX(atw_n, OCP_QP_IPM_ABS(atw[i]));
    }
    *bw_out = bw;
    return bw < HM_R(0.0) && atw_n <= tol_infeas * -bw;
}

/* Test of the last step's primal direction d = (du, dx, ds) as a direction of unbounded descent:
 * q' d < 0 and ||P d||, ||A_E d||, ||(A_I d)_+|| (inf-norms) <= tol_infeas * (-q' d), in the units
 * of the data. Along such a d every feasible point can be improved without bound. */
HM_FUNC int ocp_qp_ipm_unbounded_ray(const hm_ocp_qp *qp, const hm_ocp_qp_ipm_ws *ws, hm_real tol_infeas)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    const hm_real cinv = HM_R(1.0) / ws->cost_scale;
    hm_real qd = HM_R(0.0), pd = HM_R(0.0), ad = HM_R(0.0);
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const hm_real *d = sn->dux;
        const int c0 = n == HM_N ? HM_NU : 0;
        const int c1 = n == 0 ? HM_NU : HM_QP_NUX;
        hm_real Pd[HM_QP_NUX];
        ocp_qp_ipm_hess_mul(sn, d, Pd);
        for (i = c0; i < c1; i++) {
            qd += sn->q[i] * d[i];
            pd = OCP_QP_IPM_MAX(pd, OCP_QP_IPM_ABS(Pd[i]));
        }
        if (n < HM_N) {
            const hm_real *A = qp->A[n];
            const hm_real *B = qp->B[n];
            const hm_real *dn = &ws->u.f.st[n + 1].dux[HM_NU];
            for (i = 0; i < HM_NX; i++) {
                hm_real e = dn[i] - B[i] * d[0] - B[i + HM_NX] * d[1];
                if (n > 0) {
                    for (k = 0; k < HM_NX; k++) e -= A[i + k * HM_NX] * d[HM_NU + k];
                }
                ad = OCP_QP_IPM_MAX(ad, OCP_QP_IPM_ABS(e));
            }
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) ad = OCP_QP_IPM_MAX(ad, bd->sg[k][l][n] * d[bd->bc[k]]);
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            const hm_real gd = sr->sd0[row] * d[HM_NU] + sr->sd1[row] * d[HM_NU + 1];
            qd += sr->szl[row] * sr->sds[row];
            pd = OCP_QP_IPM_MAX(pd, OCP_QP_IPM_ABS(sr->sZl[row] * sr->sds[row]));
            ad = OCP_QP_IPM_MAX(ad, OCP_QP_IPM_MAX(-(gd + sr->sds[row]), -sr->sds[row]));
        }
        for (j = 0; j < sn->nh; j++) ad = OCP_QP_IPM_MAX(ad, -(sn->hd0[j] * d[HM_NU] + sn->hd1[j] * d[HM_NU + 1]));
    }
    return qd < HM_R(0.0) && OCP_QP_IPM_MAX(pd * cinv, ad) <= tol_infeas * -qd * cinv;
}

/* The dual part of the last step's direction, its multiplier steps clipped at 0, into ws->u.f.va (primal
 * part zero): when the multipliers diverge along a certificate, their steps point along it with
 * less of the bounded part that the iterate carries. */
HM_FUNC void ocp_qp_ipm_ray_from_step(hm_ocp_qp_ipm_ws *ws)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_ocp_qp_ipm_vec *v = &ws->u.f.va;
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (i = 0; i < HM_QP_NUX; i++) v->ux[n][i] = HM_R(0.0);
        if (n < HM_N) {
            for (i = 0; i < HM_NX; i++) v->y[n][i] = sn->dy[i];
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) v->zb[n][k][l] = OCP_QP_IPM_MAX(bd->dz[k][l][n], HM_R(0.0));
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j;
            v->s[n][j] = HM_R(0.0);
            v->zr[n][j] = OCP_QP_IPM_MAX(sr->sdz[row], HM_R(0.0));
            v->zs[n][j] = OCP_QP_IPM_MAX(sr->sdzs[row], HM_R(0.0));
        }
        for (j = 0; j < sn->nh; j++) v->zh[n][j] = OCP_QP_IPM_MAX(sn->hdz[j], HM_R(0.0));
    }
}

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
    const hm_real wmax = ws->w_max;
    int n, i, k, j, l;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const hm_real *ux = d->ux[n];
        hm_real r[HM_QP_NUX];
        ocp_qp_ipm_hess_mul(sn, ux, r);
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
            const hm_real tr = sr->swr[row] < wmax ? -d->zr[n][j] / sr->swr[row] : HM_R(0.0);
            const hm_real ts = sr->sws[row] < wmax ? -d->zs[n][j] / sr->sws[row] : HM_R(0.0);
            r[HM_NU] -= sr->sd0[row] * d->zr[n][j];
            r[HM_NU + 1] -= sr->sd1[row] * d->zr[n][j];
            e->s[n][j] = -(sr->sZl[row] * d->s[n][j] + sr->szl[row] - d->zr[n][j] - d->zs[n][j]);
            e->zr[n][j] = -(tr - gp - d->s[n][j] + sr->slg[row]);
            e->zs[n][j] = -(ts - d->s[n][j]);
        }
        for (j = 0; j < sn->nh; j++) {
            const hm_real gp = sn->hd0[j] * ux[HM_NU] + sn->hd1[j] * ux[HM_NU + 1];
            const hm_real t = sn->hw[j] < wmax ? -d->zh[n][j] / sn->hw[j] : HM_R(0.0);
            r[HM_NU] -= sn->hd0[j] * d->zh[n][j];
            r[HM_NU + 1] -= sn->hd1[j] * d->zh[n][j];
            e->zh[n][j] = -(t - gp + sn->hlg[j]);
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
            if (ocp_qp_ipm_undecided_pair(sn->ht[j], sn->hz[j], sn->hdt[j], sn->hdz[j], alpha)) return 1;
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
    hm_ocp_qp_ipm_vec *d = &ws->u.f.va;
    hm_ocp_qp_ipm_vec *e = &ws->u.f.vb;
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
            sr->swr[row] = row_on ? wmax : w_drop;
            sr->sws[row] = slack_on ? wmax : w_drop;
        }
        for (j = 0; j < sn->nh; j++)
            sn->hw[j] = ocp_qp_ipm_polish_active(sn->ht[j], sn->hz[j], sn->hdt[j], sn->hdz[j], alpha) ? wmax : w_drop;
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
            for (j = 0; j < sn->nh; j++) e->zh[n][j] = -sn->hlg[j];
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
                sr->swr[row] = ocp_qp_ipm_polish_weight(sr->swr[row], &d->zr[n][j], g, wmax, w_drop, &changed);
                sr->sws[row] = ocp_qp_ipm_polish_weight(sr->sws[row], &d->zs[n][j], d->s[n][j], wmax, w_drop, &changed);
            }
            for (j = 0; j < sn->nh; j++) {
                const hm_real g = sn->hd0[j] * v[HM_NU] + sn->hd1[j] * v[HM_NU + 1] - sn->hlg[j];
                sn->hw[j] = ocp_qp_ipm_polish_weight(sn->hw[j], &d->zh[n][j], g, wmax, w_drop, &changed);
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

/* ------------------------------------------------------------------------------------------------
 * Warm start
 *
 * Consecutive QPs of the real-time iteration differ little: the new one is the last one shifted by
 * a stage, linearised at its solution. An interior-point method started from a solution stalls (the
 * slacks of the active inequalities and the multipliers of the inactive ones are tiny, and wherever
 * the new data changed which is which, every step to the boundary is short), so the solve keeps an
 * early, well-centred iterate instead: the first after the start with mu <= arg->warm_mu (the real-
 * time iteration's 0.2 where the cold start has 1: one iteration in). The next solve starts from it,
 * slacks and multipliers floored at OCP_QP_IPM_WARM_FLOOR, with v = 0, y = 0, and the inequalities
 * it does not have from the cold start. Measured on 16 x 2,000 closed-loop steps at N_h = 5: 10.7
 * instead of 11.7 iterations per QP (floor 0.1: 11.0; 0.02 to 0.05 with warm_mu 0.05 to 0.3: 10.7),
 * about 3 fallbacks per 2,000 steps as from the cold start; a floor of 1e-3 with warm_mu 0.01 gave
 * 50 (two short steps in a row).
 * ---------------------------------------------------------------------------------------------- */

#define OCP_QP_IPM_WARM_FLOOR HM_R(0.02)

/* Keep the iterate of pass A in ws->warm (multipliers unscaled: the next QP's scale may differ). */
HM_FUNC void ocp_qp_ipm_warm_keep(hm_ocp_qp_ipm_ws *ws)
{
    const hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    const hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    hm_ocp_qp_ipm_warm *w = &ws->warm;
    const hm_real cinv = HM_R(1.0) / ws->cost_scale;
    int n, k, l, j;
    for (n = 0; n <= HM_N; n++) {
        const hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        for (k = 0; k < HM_QP_NUX; k++) {
            w->bt[n][k][0] = w->bt[n][k][1] = HM_R(0.0);
            w->bz[n][k][0] = w->bz[n][k][1] = HM_R(0.0);
        }
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                if (bd->sg[k][l][n] == HM_R(0.0)) continue;
                w->bt[n][bd->bc[k]][l] = bd->t[k][l][n];
                w->bz[n][bd->bc[k]][l] = bd->z[k][l][n] * cinv;
            }
        }
        for (j = 0; j < HM_NG; j++) w->kind[n][j] = 0;
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j, i = sr->srow[row];
            w->kind[n][i] = 1;
            w->rt[n][i] = sr->st[row];
            w->rz[n][i] = sr->sz[row] * cinv;
            w->rs[n][i] = sr->ss[row];
            w->rzs[n][i] = sr->szs[row] * cinv;
        }
        for (j = 0; j < sn->nh; j++) {
            const int i = sn->hrow[j];
            w->kind[n][i] = 2;
            w->rt[n][i] = sn->ht[j];
            w->rz[n][i] = sn->hz[j] * cinv;
        }
    }
    w->ready = 1;
}

HM_KERNEL hm_real ocp_qp_ipm_warm_floor(hm_real v)
{
    return OCP_QP_IPM_MAX(v, OCP_QP_IPM_WARM_FLOOR);
}

/* Overwrite the cold start (ocp_qp_ipm_setup) with the kept iterate: stage n from kept stage
 * n + shift (the last stage from itself), wherever the kept stage has the same inequality. */
HM_FUNC void ocp_qp_ipm_warm_apply(hm_ocp_qp_ipm_ws *ws, int shift)
{
    hm_ocp_qp_ipm_bounds *bd = &ws->u.f.bd;
    hm_ocp_qp_ipm_rows *sr = &ws->u.f.sr;
    const hm_ocp_qp_ipm_warm *w = &ws->warm;
    const hm_real c = ws->cost_scale;
    int n, k, l, j;
    for (n = 0; n <= HM_N; n++) {
        hm_ocp_qp_ipm_stage *sn = &ws->u.f.st[n];
        const int m = n + shift <= HM_N ? n + shift : HM_N;
        for (k = 0; k < bd->nbp; k++) {
            for (l = 0; l < 2; l++) {
                const hm_real t = w->bt[m][bd->bc[k]][l];
                if (bd->sg[k][l][n] == HM_R(0.0) || !(t > HM_R(0.0))) continue;
                bd->t[k][l][n] = ocp_qp_ipm_warm_floor(t);
                bd->z[k][l][n] = ocp_qp_ipm_warm_floor(w->bz[m][bd->bc[k]][l] * c);
            }
        }
        for (j = 0; j < sn->ns; j++) {
            const int row = sn->soff + j, i = sr->srow[row];
            if (w->kind[m][i] != 1) continue;
            sr->st[row] = ocp_qp_ipm_warm_floor(w->rt[m][i]);
            sr->sz[row] = ocp_qp_ipm_warm_floor(w->rz[m][i] * c);
            sr->ss[row] = ocp_qp_ipm_warm_floor(w->rs[m][i]);
            sr->szs[row] = ocp_qp_ipm_warm_floor(w->rzs[m][i] * c);
        }
        for (j = 0; j < sn->nh; j++) {
            const int i = sn->hrow[j];
            if (w->kind[m][i] != 2) continue;
            sn->ht[j] = ocp_qp_ipm_warm_floor(w->rt[m][i]);
            sn->hz[j] = ocp_qp_ipm_warm_floor(w->rz[m][i] * c);
        }
    }
}

/* ------------------------------------------------------------------------------------------------
 * The solve
 * ---------------------------------------------------------------------------------------------- */

/* Ends a solve: the solution, the certificate (with b' w = bw) or zeros (before the first iterate,
 * or for non-finite iterates) into sol, its residuals into ws->out.res. */
HM_FUNC int ocp_qp_ipm_finish(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws, int status,
                              hm_real bw, int have_iterate, int polish, int residuals, hm_real alpha)
{
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_ipm_write_sol(qp, ws, sol, HM_R(1.0) / -bw, HM_R(0.0));
    } else if (status == HM_QP_NONFINITE || !have_iterate) {
        ocp_qp_sol_set_zero(sol);
    } else {
        ocp_qp_ipm_write_sol(qp, ws, sol, HM_R(1.0) / ws->cost_scale, HM_R(1.0));
    }
    polish = status == HM_QP_SOLVED && (polish == 1 || (polish == 2 && ocp_qp_ipm_undecided(ws, alpha)));
    if (residuals || polish || status != HM_QP_SOLVED) {
        ocp_qp_res_compute(qp, sol, &ws->out.res);
    } else {
        ws->out.res.stat = ws->out.res.eq = ws->out.res.ineq = ws->out.res.comp = ws->out.res.dual = ws->out.res.obj = HM_R(0.0);
    }
    if (polish) ocp_qp_ipm_polish(qp, sol, ws, alpha);
    ws->out.status = status;
    return status;
}

/* Hands the QP over to the fallback solver (ocp_qp_hsde.h) with the iterations that are left, and
 * reports its outcome as this solve's. */
HM_FUNC int ocp_qp_ipm_fallback(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws,
                                const hm_ocp_qp_ipm_arg *arg)
{
    hm_ocp_qp_ipm_arg a = *arg;
    hm_ocp_qp_hsde_ws *h = &ws->u.hsde;
    const int done = ws->out.iter;
    int status;
    a.max_iter = arg->max_iter - done;
    status = ocp_qp_hsde_solve(qp, sol, h, &a);
    ws->fallback = 1;
    ws->out = h->out;
    ws->out.iter = done + h->out.iter;
    return status;
}

/* The primal residual rp fails to fall with mu (from mu0 and rp0 of the first iterate): the
 * precondition of the stuck-residual fallback (ocp_qp_ipm_solve), which the termination measures
 * also test for. */
HM_KERNEL int ocp_qp_ipm_rp_stuck(int iter, hm_real mu, hm_real mu0, hm_real rp, hm_real rp0)
{
    return iter > 1 && mu < HM_R(1e-2) * mu0 && rp * mu0 > HM_R(1e3) * rp0 * mu;
}

/* ocp_qp_ipm_run's answer when a warm-started iteration stalls: the caller starts cold again */
#define OCP_QP_IPM_COLD_AGAIN (-100)

/* The interior-point iteration from the cold start, or (warm) from the kept iterate. */
HM_FUNC int ocp_qp_ipm_run(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws,
                           const hm_ocp_qp_ipm_arg *arg, int warm)
{
    int status, bad = 0, ray = 0, fallback = 0, singular, stalling;
    ocp_qp_ipm_sums sm;
    hm_real mu0 = HM_R(1.0), alpha = HM_R(0.0), alpha_prev = HM_R(1.0), rp0 = HM_R(0.0);
    hm_real mu_hist[OCP_QP_IPM_STALL_ITERS] = {HM_R(0.0)};
    /* the last stage measures' dual normalisation and cost; whether they were taken near passing */
    hm_real nd_seen = HM_R(0.0), pcost_seen = HM_R(0.0);
    int near_seen = 0;

    ws->out.iter = 0;
    ws->out.unbounded = 0;
    ws->out.polished = 0;
    ws->fallback = 0;
    ws->out.res_primal = ws->out.res_dual = ws->out.gap = ws->out.mu = HM_R(0.0);

    OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_SETUP, status = ocp_qp_check(qp));
    if (status) return ocp_qp_ipm_finish(qp, sol, ws, status, HM_R(0.0), 0, 0, 1, HM_R(0.0));
    OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_SETUP, status = ocp_qp_ipm_setup(qp, ws, &bad));
    if (status == HM_QP_INFEASIBLE) {
        ocp_qp_sol_box_certificate(qp, sol, bad);
        ocp_qp_res_compute(qp, sol, &ws->out.res);
        ws->out.status = status;
        return status;
    }

    if (warm) ocp_qp_ipm_warm_apply(ws, arg->warm_start == 1);
    for (;;) {
        const hm_real mdeg = ws->m > 0 ? (hm_real)ws->m : HM_R(1.0);
        const hm_real cinv = HM_R(1.0) / ws->cost_scale;
        hm_real mu, res_p, res_d, pcost, gap, gap_rel, sigma, smu, alpha_aff, mu_aff, frac, ratio;
        ocp_qp_ipm_pred pr;

        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_A, ocp_qp_ipm_pass_a(ws, alpha, &sm));
        /* the stage measures in the first iteration, and where the certificate test needs A' w:
         * b' w < 0 and the soft slacks' part of A' w (the inequality measures) small enough */
        if (ws->out.iter > 0 && sm.bw < HM_R(0.0)) ocp_qp_ipm_row_measures(ws, &sm);
        if (ws->out.iter == 0)
            OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_A, ocp_qp_ipm_stage_measures_start(ws, &sm));
        else if (!arg->recurrence || (sm.bw < HM_R(0.0) && sm.atw_s <= arg->tol_infeas * -sm.bw))
            OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_A, ocp_qp_ipm_stage_measures(qp, ws, &sm));
        mu = sm.tz / mdeg;
        if (arg->warm_mu > HM_R(0.0) && !ws->warm.ready && ws->out.iter > 0 && mu <= arg->warm_mu)
            ocp_qp_ipm_warm_keep(ws);
        if (ws->out.iter == 0) {
            mu0 = mu;
            rp0 = sm.rp;
        }
        ws->out.mu = mu;
        /* a NaN anywhere in the iterate reaches one of these sums (t, z, s through t'z; v through
         * 0 * v; y through b'w, whose rows b multiply every entry (0 * NaN is NaN)) */
        if (!isfinite(mu + sm.rd + sm.rp + sm.vz + sm.bw + sm.qv + sm.vPv)) {
            status = HM_QP_NONFINITE;
            break;
        }

        /* termination tests. Their normalisations take the norms of the stage vectors and, where
         * one of the tests below that ends the solve could pass, the norms over the inequalities:
         * those only ever enlarge the normalisation, and cost a pass over the rows. Between stage
         * measures the primal one is bounded from above by ||A_E v|| <= ||b_E|| + ||A_E v - b_E||
         * (so res_p is not overstated there), the dual one and the cost are estimated by the last
         * stage measures. The tests that need res_p, res_d <= tol decide on exact values: the
         * stage measures are taken once the residuals are near passing (the first time, to renew
         * the estimates), and from then on where such a test could pass. */
        gap = sm.tz * cinv;
        /* mu has not fallen by 4 over the last OCP_QP_IPM_STALL_ITERS iterations */
        stalling = ws->out.iter >= OCP_QP_IPM_STALL_ITERS
                   && mu > HM_R(0.25) * mu_hist[ws->out.iter % OCP_QP_IPM_STALL_ITERS];
        for (;;) {
            const hm_real np_lb = OCP_QP_IPM_MAX(HM_R(1.0), ws->norm_b);
            const hm_real nd_lb = OCP_QP_IPM_MAX(HM_R(1.0), ws->norm_q);
            const hm_real np_stage = sm.exact ? OCP_QP_IPM_MAX(np_lb, sm.av_eq)
                                              : OCP_QP_IPM_MAX(np_lb, ws->norm_b + sm.rp_eq);
            const hm_real nd_stage = OCP_QP_IPM_MAX(nd_lb, sm.exact ? OCP_QP_IPM_MAX(sm.pv, sm.atw) : nd_seen);
            const hm_real pc = sm.exact ? (sm.qv + HM_R(0.5) * sm.vPv) * cinv : pcost_seen;
            /* the gap test, the stall test or the test of residuals stuck above tol could pass */
            const int could = gap <= arg->tol
                              || gap <= OCP_QP_IPM_STAGE_NEAR * arg->tol * OCP_QP_IPM_MAX(HM_R(1.0), hm_fabs(pc))
                              || stalling || ocp_qp_ipm_rp_stuck(ws->out.iter, mu, mu0, sm.rp, rp0);
            if (!sm.measured
                && ((could && sm.rp <= OCP_QP_IPM_MEASURE_NEAR * arg->tol * np_stage
                     && sm.rd <= OCP_QP_IPM_MEASURE_NEAR * arg->tol * nd_stage)
                    || (sm.bw < HM_R(0.0) && sm.atw <= arg->tol_infeas * -sm.bw)))
                ocp_qp_ipm_row_measures(ws, &sm);
            res_p = sm.rp / OCP_QP_IPM_MAX(np_stage, OCP_QP_IPM_MAX(sm.av_ineq, sm.nt));
            res_d = sm.rd / OCP_QP_IPM_MAX(nd_stage, OCP_QP_IPM_MAX(sm.pv_s, sm.atw_s));
            if (sm.exact) {
                nd_seen = OCP_QP_IPM_MAX(sm.pv, sm.atw);
                pcost_seen = pc;
                break;
            }
            if (!(res_p <= arg->tol && res_d <= OCP_QP_IPM_STAGE_NEAR * arg->tol)) break;
            if (near_seen && !could) break;
            near_seen = 1;
            OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_A, ocp_qp_ipm_stage_measures(qp, ws, &sm));
        }
        sm.atw = OCP_QP_IPM_MAX(sm.atw, sm.atw_s);
        /* the complementarity t' z (= primal - dual cost once the residuals vanish, but without the
         * cancellation of those two large numbers), absolute and relative to the cost, in the units
         * of the data */
        pcost = (sm.qv + HM_R(0.5) * sm.vPv) * cinv;
        gap_rel = gap / OCP_QP_IPM_MAX(HM_R(1.0), hm_fabs(pcost));
        ws->out.res_primal = res_p;
        ws->out.res_dual = res_d;
        ws->out.gap = gap_rel;
        /* and the natural residual of complementarity, max min(t, z): the product t z bounds the
         * distance to the solution only through its square root when a multiplier is small, the
         * natural residual linearly; near-degenerate QPs need it, others meet it with the gap */
        if (sm.exact && res_p <= arg->tol && res_d <= arg->tol && (gap <= arg->tol || gap_rel <= arg->tol)
            && sm.ncr <= HM_R(10.0) * arg->tol) {
            status = HM_QP_SOLVED;
            break;
        }
        if (sm.bw < HM_R(0.0) && sm.atw <= arg->tol_infeas * -sm.bw) {
            status = HM_QP_INFEASIBLE;
            break;
        }
        if (ws->out.iter > 0 && alpha < HM_R(0.5)) {
            hm_real bwr;
            ocp_qp_ipm_ray_from_step(ws);
            if (ocp_qp_ipm_farkas(qp, ws, &ws->u.f.va, arg->tol_infeas, &bwr)) {
                status = HM_QP_INFEASIBLE;
                ray = 1;
                sm.bw = bwr;
                break;
            }
        }
        /* a stalling iteration (short steps) may be on a problem without solution: test the last
         * step as a ray (ocp_qp_ipm_farkas, ocp_qp_ipm_unbounded_ray) */
        if (arg->detect_unbounded && ws->out.iter > 0 && alpha < HM_R(0.5)) {
            if (ocp_qp_ipm_unbounded_ray(qp, ws, arg->tol_infeas)) {
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
            fallback = 1;
            break;
        }
        /* A stalling iteration (two short steps in a row), or residuals that do not fall with mu,
         * is what an infeasible (or unbounded) problem does to this method when the certificate tests
         * above have not caught it: hand over to the embedding, which handles those robustly. */
        if (ws->out.iter > 1 && alpha < HM_R(0.1) && alpha_prev < HM_R(0.1)) {
            fallback = 1;
            break;
        }
        /* (only while the primal residual is above tol: once it is met, a residual that no longer
         * falls is at its rounding floor, as single precision reaches with mu still falling) */
        if (res_p > arg->tol && ocp_qp_ipm_rp_stuck(ws->out.iter, mu, mu0, sm.rp, rp0)) {
            fallback = 1;
            break;
        }
        /* Feasible to tol but the gap no longer falls: a degenerate pair (a row active with a
         * vanishing multiplier, its slack bound active too) sitting far below the central path
         * blocks every direction after a few roundings, and the iteration cycles between a blocked
         * affine step and a short centring step (seen on RTI QPs with screened rows: mu 1e-7 to
         * 3e-7 and back for 40 iterations). The embedding has no such pair. */
        if (sm.exact && stalling && res_p <= arg->tol && res_d <= arg->tol) {
            fallback = 1;
            break;
        }
        mu_hist[ws->out.iter % OCP_QP_IPM_STALL_ITERS] = mu;
        if (arg->should_stop && arg->should_stop(arg->stop_ctx)) {
            status = HM_QP_TIMEOUT;
            break;
        }
        ws->out.iter++;

        alpha_prev = alpha;

        /* predictor */
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_B, singular = ocp_qp_ipm_pass_b(qp, ws));
        if (singular) {
            /* singular at the start: the QP is not strictly convex in u; later: the weights of a
             * diverging iteration */
            if (ws->out.iter > 1) fallback = 1;
            status = HM_QP_NUMERICAL;
            break;
        }
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_C, ocp_qp_ipm_pass_c(qp, ws, &pr));
        alpha_aff = HM_R(1.0) / OCP_QP_IPM_MAX(HM_R(1.0), pr.ratio);
        mu_aff = (sm.tz + alpha_aff * (pr.tdz + alpha_aff * pr.dtdz)) / mdeg;
        sigma = mu > HM_R(0.0) ? mu_aff / mu : HM_R(0.0);
        sigma = OCP_QP_IPM_MIN(OCP_QP_IPM_MAX(sigma, HM_R(0.0)), HM_R(1.0));
        sigma = sigma * sigma * sigma;
        smu = sigma * mu;

        /* corrector */
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_D, ocp_qp_ipm_pass_d(qp, ws, smu, HM_R(1.0)));
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_E, ratio = ocp_qp_ipm_pass_e(qp, ws, smu, HM_R(1.0)));
        if (ratio > HM_R(10.0)) {
            /* a step below 0.1: the iterate is too far off the central path for Mehrotra's
             * second-order term; solve again for a centring step without it (one more solve, rare) */
            smu = OCP_QP_IPM_MAX(sigma, HM_R(0.5)) * mu;
            OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_D, ocp_qp_ipm_pass_d(qp, ws, smu, HM_R(0.0)));
            OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_E, ratio = ocp_qp_ipm_pass_e(qp, ws, smu, HM_R(0.0)));
        }

        /* fraction to the boundary: arg->step_frac far from the solution, closer to 1 as mu falls
         * (relative to its start, so the rule does not depend on the data's units), which turns the
         * last iterations' linear rate 1 - step_frac into a superlinear one; never so close that t
         * or z could round to zero */
        frac = hm_fmin(HM_R(1.0) - mu / mu0, HM_R(1.0) - hm_sqrt(HM_EPS));
        alpha = OCP_QP_IPM_MAX(arg->step_frac, frac) / OCP_QP_IPM_MAX(HM_R(1.0), ratio);
#ifdef OCP_QP_IPM_STATS
        {
            extern double g_stat_min2alpha, g_stat_incons;
            static double prev_alpha = 1.0, rp0 = 0.0;
            const double a2 = (double)(alpha > prev_alpha ? alpha : prev_alpha);
            if (ws->out.iter == 1) { prev_alpha = 1.0; rp0 = (double)sm.rp; g_stat_min2alpha = 1.0; g_stat_incons = 0.0; }
            if (ws->out.iter > 1 && a2 < g_stat_min2alpha) g_stat_min2alpha = a2;
            if (ws->out.iter > 1) {
                const double inc = ((double)sm.rp / rp0) / ((double)mu / (double)mu0);
                if ((double)mu / (double)mu0 < 1e-2 && inc > g_stat_incons) g_stat_incons = inc;
            }
            prev_alpha = (double)alpha;
        }
#endif
#ifdef OCP_QP_IPM_TRACE
        printf("it %2d mu %.3e res_p %.2e res_d %.2e gap %.2e gap_rel %.2e | a_aff %.4f sigma %.2e alpha %.6f bw %.2e atw %.2e\n",
               ws->out.iter, (double)mu, (double)res_p, (double)res_d, (double)gap, (double)gap_rel, (double)alpha_aff,
               (double)sigma, (double)alpha, (double)sm.bw, (double)sm.atw);
#endif
        if (!(alpha >= arg->min_step)) {
            if (isfinite(alpha)) {
                fallback = 1;
            } else {
                status = HM_QP_NONFINITE;
            }
            break;
        }
    }
    if (fallback) {
        if (warm) return OCP_QP_IPM_COLD_AGAIN;
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_FINISH, status = ocp_qp_ipm_fallback(qp, sol, ws, arg));
        return status;
    }
    if (ray) {
        ocp_qp_ipm_write_sol_vec(qp, ws, &ws->u.f.va, sol, HM_R(1.0) / -sm.bw);
        ocp_qp_res_compute(qp, sol, &ws->out.res);
        ws->out.status = status;
        return status;
    }
    OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_FINISH,
                    status = ocp_qp_ipm_finish(qp, sol, ws, status, sm.bw, 1, arg->polish, arg->residuals, alpha));
    return status;
}

HM_FUNC int ocp_qp_ipm_solve(const hm_ocp_qp *qp, hm_ocp_qp_sol *sol, hm_ocp_qp_ipm_ws *ws,
                             const hm_ocp_qp_ipm_arg *arg)
{
    /* the kept iterate serves one solve at most */
    const int warm = arg->warm_start && ws->warm.ready;
    int status;
    ws->warm.ready = 0;
    status = ocp_qp_ipm_run(qp, sol, ws, arg, warm);
    if (status == OCP_QP_IPM_COLD_AGAIN) {
        /* A warm start that stalls (a stage whose data changed too much for the kept iterate) is
         * cheaper to redo from the cold start than to hand to the fallback solver, which is several
         * times slower per iteration: in the bench's crowds of 30 those hand-overs made the slowest
         * 1 % of the steps. The iterations spent count against max_iter. */
        hm_ocp_qp_ipm_arg cold = *arg;
        const int done = ws->out.iter;
        cold.max_iter = arg->max_iter - done;
        ws->warm.ready = 0;
        status = ocp_qp_ipm_run(qp, sol, ws, &cold, 0);
        ws->out.iter += done;
    }
    return status;
}
