/*
 * ocp_nlp_sqp.c: the solver object, from init (parameters, QP options, clock) and reset (cold
 * start), and the full SQP: linearise, test the NLP's KKT residuals, solve the QP and take a line-search
 * step, to a tolerance or an iteration limit (tests, references); then the same safety checks and
 * output as the real-time iteration.
 */
#include "ocp_nlp_sqp.h"

#include "monitor.h"
#include "ocp_nlp_cost.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_out.h"
#include "ocp_nlp_step.h"
#include "ocp_qp.h"
#include "ocp_qp_ipm.h"

/* Each RTI QP keeps its first iterate after the start with mu <= this (scaled; 1 at the cold start)
 * for the next step's QP to start from (ocp_qp_ipm_warm.c). */
#define OCP_NLP_WARM_MU HM_R(0.2)

HM_FUNC void ocp_nlp_sqp_init(hm_solver *s, const hm_params *params)
{
    int i;
    s->params = *params;
    ocp_qp_ipm_arg_set_default(&s->ipm_arg);
    /* Every QP of the SQP is bounded by construction (box bounds on both inputs of every stage, the
     * states follow from them, soft slacks cost zl >= 0 and only relax their rows): a ray test could
     * only give false positives, and in single precision it did (a large early step whose cost
     * decrease dwarfs its rounding-level residuals, RTI replays with 30 humans). */
    s->ipm_arg.detect_unbounded = 0;
    s->ipm_arg.warm_mu = OCP_NLP_WARM_MU;
#if defined(HM_HAVE_POSIX_CLOCK)
    s->clock = hm_clock_posix_ns;
#else
    s->clock = 0;
#endif
    s->clock_ctx = 0;
    for (i = 0; i < HM_NX; i++) s->x0_last[i] = HM_R(0.0);
    ocp_nlp_sqp_reset(s);
}

HM_FUNC void ocp_nlp_sqp_reset(hm_solver *s)
{
    int n, i;
    s->warm = 0;
    s->prepared = 0;
    s->ipm_ws.warm.ready = 0;
    s->dyn_fresh = 0;
    s->qp_budget = -1;
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) s->u[n][i] = HM_R(0.0);
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) s->x[n][i] = HM_R(0.0);
    s->cost = HM_R(0.0);
    s->time_prepare_ms = HM_R(0.0);
    s->screen_radius[0] = HM_INF;
    s->clock_fault = 0;
    /* x0_last is kept: the last measured state stays what it was (a solver made warm from outside, as
     * the controller's nudged recovery does, compares with it) */
}

/* How the SQP is run: as the reference (tests, recoveries), or for a candidate plan
 * (ocp_nlp_sqp_candidate_step: its QPs with the recurrence, none of the residuals). */
enum ocp_nlp_sqp_mode { OCP_NLP_SQP_REFERENCE, OCP_NLP_SQP_CANDIDATE };

/* The cost the reference reports after its last iteration (its final linearisation with the exact
 * Hessian, then ocp_nlp_set_x0), bit for bit, without the linearisation: the speed-and-separation bounds
 * of the iterate, then the objective as that linearisation adds it up. */
static void ocp_nlp_sqp_final_cost(hm_solver *s, const hm_input *in)
{
    const hm_params *p = &s->params;
    int n;
    if (p->separation)
        for (n = 2; n <= HM_N; n++)
            s->v_separation[n] = monitor_separation_bound(in, p, s->x[n - 1], n - 1, p->v_bounds[1]);
    s->cost = ocp_nlp_plan_cost(s, in, 1);
    s->cost_slack = HM_R(0.0);
    ocp_nlp_set_x0(s, in);
}

/* Under the same monitors as the real-time iteration: the inputs and parameters before, the deadline of
 * params.deadline_ms from t0 (polled inside the QPs and between the iterations), every QP solved (one
 * stopped at its iteration limit, infeasible or failed ends the SQP, its iterate not applied), the
 * clock, C1 / C2 on the plan and the command guard; each failure a protective stop. max_iter < 1 or a
 * tolerance that is not a positive finite number is an invalid input: nothing is solved. A candidate's
 * step (ocp_nlp_sqp.h) differs where marked. */
static int ocp_nlp_sqp_iterate(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol,
                               unsigned long long t0, enum ocp_nlp_sqp_mode mode)
{
    const int reference = mode == OCP_NLP_SQP_REFERENCE;
    int k, qp_status = HM_QP_SOLVED, status = HM_STATUS_MAX_ITER, reason, late = 0;
    ocp_nlp_clear_output(out);
    ocp_nlp_step_counts_reset(s);
    s->qp_budget = -1;   /* each of the SQP's QPs its own qp_max_iter */
    reason = ocp_nlp_check_before(s, in, 0);
    if (reason == HM_STOP_NONE && (max_iter < 1 || !(tol > HM_R(0.0) && tol < HM_INF)))
        reason = HM_STOP_INVALID_INPUT;
    if (reason != HM_STOP_NONE) {
        ocp_nlp_finish(s, in, out, reason);
        out->time_total_ms = out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
        out->time_prepare_ms = HM_R(0.0);
        return out->status;
    }
    if (!s->warm) {
        ocp_nlp_shift(s, in); /* cold: controls held at zero from x0 */
        ocp_qp_sol_set_zero(&s->mult);
        s->warm = 1;
    }
    s->merit_mu = HM_R(1.0);
    /* The reference: its QPs with exact residuals in every iteration. Their last steps then leave
     * the residuals far below the QP tolerance, which is relative to the scaled data; with the
     * recurrence they end just below it, and at tol = 1e-9 the SQP stalled on that (stationarity
     * 3.5e-7 after 300 iterations, 30 people). */
    s->ipm_arg.recurrence = !reference;   /* a candidate's QP: with the recurrence, as the RTI's */
    /* and all of them from the cold start (keeping none, so the next RTI step starts cold too) */
    s->ipm_arg.warm_mu = HM_R(0.0);
    ocp_nlp_start_clock(s, t0);
    s->ipm_arg.should_stop = ocp_nlp_deadline_passed;
    s->ipm_arg.stop_ctx = s;
    for (k = 0; k < max_iter; k++) {
        if (ocp_nlp_deadline_passed(s)) {
            late = 1;
            break;
        }
        ocp_nlp_linearize(s, in, k > 0);
        ocp_nlp_set_x0(s, in);
        if (reference) ocp_nlp_residuals(s, out);   /* a candidate's are tested by no one */
        if (reference && k > 0 && out->kkt_stat <= tol && out->kkt_eq <= tol && out->kkt_ineq <= tol && out->kkt_comp <= tol) {
            status = HM_STATUS_OK;
            break;
        }
        qp_status = ocp_nlp_qp_line_search_step(s, in, tol, 0, &out->qp_iterations);
        if (qp_status != HM_QP_SOLVED) { /* the iteration limit too: not a solution */
            status = HM_STATUS_QP_FAILED;
            late = qp_status == HM_QP_TIMEOUT;
            break;
        }
    }
    s->ipm_arg.should_stop = 0;
    s->ipm_arg.stop_ctx = 0;
    if (k == max_iter && !reference) {
        /* a candidate: its cost at the final iterate, which the plans are compared by (max_iter iterations,
         * untested: HM_STATUS_MAX_ITER) */
        ocp_nlp_sqp_final_cost(s, in);
    } else if (k == max_iter) {
        /* Report the residuals at the final iterate. */
        ocp_nlp_linearize(s, in, 1);
        ocp_nlp_set_x0(s, in);
        ocp_nlp_residuals(s, out);
        if (out->kkt_stat <= tol && out->kkt_eq <= tol && out->kkt_ineq <= tol && out->kkt_comp <= tol)
            status = HM_STATUS_OK;
    }
    s->ipm_arg.recurrence = 1;
    s->ipm_arg.warm_mu = OCP_NLP_WARM_MU;
    s->prepared = 0;
    out->status = status;
    out->qp_status = qp_status;
    out->sqp_iterations = k;
    ocp_nlp_step_counts_report(s, out);
    reason = HM_STOP_NONE;
    if (late) {
        reason = HM_STOP_DEADLINE;
    } else if (status == HM_STATUS_QP_FAILED) {
        reason = HM_STOP_QP_FAILED;
    } else {
        reason = ocp_nlp_check_plan(s, in);
    }
    if (ocp_nlp_clock_fault(s, ocp_nlp_now(s))) reason = HM_STOP_CLOCK;
    ocp_nlp_finish(s, in, out, reason); /* the command guard, or the stop */
    out->time_prepare_ms = HM_R(0.0);
    out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
    out->time_total_ms = out->time_feedback_ms;
    return status;
}

HM_FUNC int ocp_nlp_sqp_solve(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol)
{
    return ocp_nlp_sqp_iterate(s, in, out, max_iter, tol, ocp_nlp_now(s), OCP_NLP_SQP_REFERENCE);
}

HM_FUNC int ocp_nlp_sqp_solve_timed(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol,
                                    unsigned long long t0)
{
    return ocp_nlp_sqp_iterate(s, in, out, max_iter, tol, t0, OCP_NLP_SQP_REFERENCE);
}

HM_FUNC int ocp_nlp_sqp_candidate_step(hm_solver *s, const hm_input *in, hm_output *out, int max_iter, hm_real tol,
                                       unsigned long long t0)
{
    return ocp_nlp_sqp_iterate(s, in, out, max_iter, tol, t0, OCP_NLP_SQP_CANDIDATE);
}

HM_FUNC const char *ocp_nlp_status_message(int status)
{
    switch (status) {
        HM_STATUS_TABLE(HM_STATUS_CASE_ROW)
    default:
        return "unknown status";
    }
}
