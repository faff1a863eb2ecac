/*
 * ocp_qp_ipm.c: the primal-dual interior-point solver of ocp_qp, its entry point and solve loop (see
 * ocp_qp_ipm.h for the algorithm and the termination rules): per solve the set-up, the warm start,
 * the iterations to termination, the solution, the polish and, when the iteration stalls, the
 * hand-over to the fallback solver (ocp_qp_hsde.h). The parts are files of their own, ocp_qp_ipm_*.c.
 *
 * Notation as in ocp_qp_ipm.h and ocp_qp_ipm_types.h (ocp_qp_ipm_stage). Every inequality is written
 * a' v + t = b with slack t >= 0 and multiplier z >= 0: a bound side sign * ux[c] + t = b, a soft row
 * -(d' p + s) + t = -lg, a soft slack's bound -s + s = 0 (its slack is s itself), a hard row
 * -d' p + t = -lg.
 *
 * One iteration is five passes over the stages, each fused so that a stage's data is touched once;
 * in passes A, C and E the bound pairs take a sweep of their own over their stage-major arrays
 * (ocp_qp_ipm_types.h: ocp_qp_ipm_bounds), eight stages at a time in vector lanes:
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
#include "ocp_qp_res.h"
#include "ocp_qp_hsde.h"
#include "ocp_qp_ipm.h"
#include "ocp_qp_ipm_cert.h"
#include "ocp_qp_ipm_common.h"
#include "ocp_qp_ipm_measures.h"
#include "ocp_qp_ipm_pass_a.h"
#include "ocp_qp_ipm_polish.h"
#include "ocp_qp_ipm_pred_corr.h"
#include "ocp_qp_ipm_setup.h"
#include "ocp_qp_ipm_sol.h"
#include "ocp_qp_ipm_warm.h"

/* The termination tests measure the inequalities once the residuals are within this factor of
 * passing on the stage vectors' normalisation alone and a test that ends the solve could pass
 * (ocp_qp_ipm_solve). */
#define OCP_QP_IPM_MEASURE_NEAR HM_R(1e3)

/* Between stage measures the dual residual and the gap are compared with tol times this factor
 * (their normalisations are the last stage measures', ocp_qp_ipm_solve). */
#define OCP_QP_IPM_STAGE_NEAR HM_R(10.0)

/* Iterations over which a feasible iterate's mu must fall by 4 (ocp_qp_ipm_solve). */
#define OCP_QP_IPM_STALL_ITERS 4

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
        HM_QP_STATUS_TABLE(HM_STATUS_CASE_ROW)
    default:
        return "unknown QP status";
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
#ifdef HM_QP_POLISH
    polish = status == HM_QP_SOLVED && (polish == 1 || (polish == 2 && ocp_qp_ipm_undecided(ws, alpha)));
#else
    /* built without the polish (ocp_qp_ipm_types.h: HM_QP_POLISH): arg->polish has no effect */
    polish = 0;
    (void)alpha;
#endif
    if (residuals || polish || status != HM_QP_SOLVED) {
        ocp_qp_res_compute(qp, sol, &ws->out.res);
    } else {
        ws->out.res.stat = ws->out.res.eq = ws->out.res.ineq = ws->out.res.comp = ws->out.res.dual = ws->out.res.obj = HM_R(0.0);
    }
#ifdef HM_QP_POLISH
    if (polish) ocp_qp_ipm_polish(qp, sol, ws, alpha);
#endif
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

#ifdef HM_REAL_IS_FLOAT
/* Single precision's rounding floor. The dual residual of the RTI's QPs stops falling near 1e-6
 * (scaled): a soft row's multiplier is its L1 weight less its slack bound's, two numbers of about 1
 * (the exact penalty sets the cost scale) whose difference is the small multiplier of an inactive row,
 * and the Newton steps carry that rounding into the stationarity of the positions. The duality gap
 * in the data's units, which the tests of ocp_qp_ipm_solve want below tol, is mu times the number of
 * inequalities times the inverse cost scale (1e4): pushing mu down for it saturated the weights z / t,
 * the dual residual rose again and the steps failed (a negative Riccati pivot, the iteration limit;
 * the fallback, from scratch, met the same floor: docs/firmware.md). Two tests on the exact measures
 * therefore stand in for the gap in single precision:
 *   in every iteration with mu <= OCP_QP_IPM_FLOAT_DEEP tol (per inequality, scaled: HPIPM's
 *   complementarity test, with a margin of 50), the others of ocp_qp_ipm_solve as they are: primal and
 *   dual residual within tol, natural residual within 10 tol;
 *   where an iteration is about to fail (a refused pivot, a hand-over to the fallback, the iteration
 *   limit; rescue), on the iterate it started from (pass A's, which the later passes do not move):
 *   primal residual within tol, dual residual within 10 tol, mu within tol and the natural residual
 *   within 10 max(tol, sqrt(mu)) (a degenerate pair has t = z = sqrt(mu)).
 * Measured on the recorded replays (docs/firmware.md): no float QP fails where double solves. */
#define OCP_QP_IPM_FLOAT_DEEP HM_R(2e-2)

HM_FUNC int ocp_qp_ipm_at_float_floor(const hm_ocp_qp *qp, hm_ocp_qp_ipm_ws *ws, const hm_ocp_qp_ipm_arg *arg,
                                      ocp_qp_ipm_sums *sm, int rescue)
{
    const hm_real mdeg = ws->m > 0 ? (hm_real)ws->m : HM_R(1.0);
    const hm_real mu = sm->tz / mdeg;
    hm_real np, nd;
    if (!sm->exact) ocp_qp_ipm_stage_measures(qp, ws, sm);
    if (!sm->measured) ocp_qp_ipm_row_measures(ws, sm);
    np = OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(HM_R(1.0), ws->norm_b), OCP_QP_IPM_MAX(sm->av_eq, OCP_QP_IPM_MAX(sm->av_ineq, sm->nt)));
    nd = OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(HM_R(1.0), ws->norm_q),
                        OCP_QP_IPM_MAX(OCP_QP_IPM_MAX(sm->pv, sm->atw), OCP_QP_IPM_MAX(sm->pv_s, sm->atw_s)));
    if (!rescue) return sm->rp <= arg->tol * np && sm->rd <= arg->tol * nd && sm->ncr <= HM_R(10.0) * arg->tol;
    return sm->rp <= arg->tol * np && sm->rd <= HM_R(10.0) * arg->tol * nd && mu <= arg->tol
           && sm->ncr <= HM_R(10.0) * OCP_QP_IPM_MAX(arg->tol, hm_sqrt(mu));
}
#endif

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
    if (status) return ocp_qp_ipm_finish(qp, sol, ws, status, HM_R(0.0), 0, 0, 1, HM_R(0.0));

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
#ifdef HM_REAL_IS_FLOAT
        /* deep enough that a QP away from the floor has met the tests above (its gap falls with mu) */
        if (mu <= OCP_QP_IPM_FLOAT_DEEP * arg->tol && ocp_qp_ipm_at_float_floor(qp, ws, arg, &sm, 0)) {
            status = HM_QP_SOLVED;
            break;
        }
#endif
        if (sm.bw < HM_R(0.0) && sm.atw <= arg->tol_infeas * -sm.bw) {
            status = HM_QP_INFEASIBLE;
            break;
        }
        if (ws->out.iter > 0 && alpha < HM_R(0.5)) {
            hm_real bwr;
            if (ocp_qp_ipm_farkas_step(qp, ws, arg->tol_infeas, &bwr)) {
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
#ifdef HM_REAL_IS_FLOAT
    if ((fallback || status == HM_QP_MAX_ITER || (status == HM_QP_NUMERICAL && !ws->out.unbounded))
        && ocp_qp_ipm_at_float_floor(qp, ws, arg, &sm, 1)) {
        fallback = 0;
        status = HM_QP_SOLVED;
    }
#endif
    if (fallback) {
        if (warm) return OCP_QP_IPM_COLD_AGAIN;
        OCP_QP_IPM_PROF(OCP_QP_IPM_PROF_FINISH, status = ocp_qp_ipm_fallback(qp, sol, ws, arg));
        return status;
    }
    if (ray) {
        ocp_qp_ipm_write_sol_ray(qp, ws, sol, HM_R(1.0) / -sm.bw);
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
