/*
 * ocp_nlp_rti.c: the real-time iteration, once per control step: the preparation (shift and
 * linearise, before the measurement), then the feedback (the measured state in, one screened QP
 * with the deadline polled inside it, the full step or a line search, the safety checks with one
 * retry from the braking guess, and the plan or the protective stop out).
 *
 * Warm start: the previous plan is shifted by one interval and its controls are re-simulated from
 * the predicted state x_1, so the linearisation has no dynamics gaps. Large gaps are what make
 * linearised human half-planes unreachable after bang-bang steps (measured with acados on this
 * problem); re-simulation removes them before the QP sees them. The measured state enters in the
 * feedback phase as the QP's initial-state offset only.
 */
#include "ocp_nlp_rti.h"

#include "monitor.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_out.h"
#include "ocp_nlp_step.h"
#include "ocp_qp.h"

/* Byte-wise copy and comparison of the parameters (struct assignment need not copy padding bytes). */
static void ocp_nlp_params_remember(hm_solver *s)
{
    const unsigned char *from = (const unsigned char *)&s->params;
    unsigned char *to = (unsigned char *)&s->params_prepared;
    size_t i;
    for (i = 0; i < sizeof s->params; i++) to[i] = from[i];
}

static int ocp_nlp_params_changed(const hm_solver *s)
{
    const unsigned char *a = (const unsigned char *)&s->params;
    const unsigned char *b = (const unsigned char *)&s->params_prepared;
    unsigned diff = 0;
    size_t i;
    for (i = 0; i < sizeof s->params; i++) diff |= (unsigned)(a[i] ^ b[i]);
    return diff != 0;
}

static void ocp_nlp_rti_prepare(hm_solver *s, const hm_input *in)
{
    const unsigned long long t0 = ocp_nlp_now(s);
    /* Prepared already (a preparation not yet followed by its feedback, then step() or prepare()
     * again): the plan was shifted once; it is linearised again with these inputs, not shifted twice. */
    const int again = s->prepared;
    s->prepared = 0;
    /* Nothing is computed from unusable data; the feedback phase turns it into a stop. A cold
     * start reads x0 (the caller's guess) already here. */
    if (monitor_check_params(&s->params) && monitor_check_input(in, !s->warm)) {
        if (!again) {
            ocp_nlp_shift(s, in);
            /* a line search stays between this point and the QP's solution: start it within the bounds */
            if (s->params.line_search) ocp_nlp_project_guess(s);
        }
        /* exact_hessian: the Lagrangian's Hessian at the shifted multipliers of the last QP (a cold
         * start has none: Gauss-Newton). With the paper's zero control weights and a far goal the
         * Gauss-Newton model misses the costate-weighted curvature of the dynamics, and its full steps
         * flip omega between its bounds from one step to the next. */
        ocp_nlp_linearize(s, in, s->warm && s->params.exact_hessian);
        s->prepared = 1;
    }
    s->time_prepare_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
}

/* The preparation alone, before a separate feedback: which may come under changed parameters, so
 * the ones it used are remembered (a whole step needs no copy: nothing runs between its phases). */
HM_FUNC void ocp_nlp_sqp_rti_prepare(hm_solver *s, const hm_input *in)
{
    ocp_nlp_rti_prepare(s, in);
    if (s->prepared) ocp_nlp_params_remember(s);
}

/* separate: a feedback after the caller's own preparation, whose parameters may have changed since */
static int ocp_nlp_rti_feedback_from(hm_solver *s, const hm_input *in, hm_output *out, unsigned long long t_start,
                                     int separate)
{
    unsigned long long t_feedback;
    int qp_status, status, reason;
    /* the plan moved on by one stage since the last QP, whose kept iterate (if any: dropped after a
     * stop, below) the QP starts from */
    const int shifted = s->warm;
    ocp_nlp_start_clock(s, t_start);
    ocp_nlp_clear_output(out);
    ocp_nlp_step_counts_reset(s);
    s->qp_budget = 0;
    out->sqp_iterations = 1;
    /* a whole step: its preparation, just now, checked the same input (s->prepared: it passed) */
    reason = ocp_nlp_check_before(s, in, !separate && s->prepared);
    if (reason == HM_STOP_NONE) {
        /* all QP solves of this step, the re-solves of screening and the braking retry's too: two
         * QPs' worth (measured: at most 46 in 24,000 double steps at N_h = 30, 77 in float); set once
         * the parameters passed their check (a runtime qp_max_iter out of range overflowed it) */
        s->qp_budget = 2 * s->params.qp_max_iter;
        if (!s->prepared) {
            ocp_nlp_rti_prepare(s, in);
        } else if (separate && ocp_nlp_params_changed(s)) {
            /* the parameters changed since the preparation, whose QP holds the old bounds and
             * weights: linearise again at the point it shifted to (not a second shift) */
            ocp_nlp_linearize(s, in, s->warm && s->params.exact_hessian);
            ocp_nlp_params_remember(s);
        }
        t_feedback = ocp_nlp_now(s);
        if (!s->warm) ocp_qp_sol_set_zero(&s->mult);
        ocp_nlp_set_x0(s, in);
        s->ipm_arg.should_stop = ocp_nlp_deadline_passed;
        s->ipm_arg.stop_ctx = s;
        if (s->params.line_search) {
            /* A damped step: with the paper's zero control weights the Gauss-Newton curvature in
             * omega is tiny, and full steps overshoot from one bound of omega to the other. */
            s->merit_mu = HM_R(1.0);
            qp_status = ocp_nlp_qp_line_search_step(s, in, s->params.qp_tol, shifted, &out->qp_iterations);
        } else {
            qp_status = ocp_nlp_qp_step(s, in, shifted, &out->qp_iterations);
        }
        s->ipm_arg.should_stop = 0;
        s->ipm_arg.stop_ctx = 0;
        /* With the multipliers of this QP: how far the linearisation point is from a KKT point. */
        ocp_nlp_residuals(s, out);
        s->prepared = 0;
        out->qp_status = qp_status;
        status = qp_status == HM_QP_SOLVED ? HM_STATUS_OK
                 : qp_status == HM_QP_MAX_ITER ? HM_STATUS_MAX_ITER : HM_STATUS_QP_FAILED;
        out->status = status;
        if (qp_status == HM_QP_TIMEOUT) {
            reason = HM_STOP_DEADLINE;
        } else if (qp_status != HM_QP_SOLVED) {
            reason = HM_STOP_QP_FAILED;  /* the iteration limit too: not a solution */
        } else {
            reason = ocp_nlp_check_plan(s, in);
            if (reason == HM_STOP_UNSAFE_PLAN) {
                /* The warm start led the plan between humans it cannot pass (a local solution in
                 * the wrong homotopy class). Solve once more from the braking guess, which keeps
                 * d_h whenever braking does. */
                out->sqp_iterations = 2;
                ocp_nlp_init_braking(s, in);
                ocp_nlp_linearize(s, in, 0);
                ocp_nlp_set_x0(s, in);
                s->ipm_arg.should_stop = ocp_nlp_deadline_passed;
                s->ipm_arg.stop_ctx = s;
                qp_status = ocp_nlp_qp_step(s, in, 0, &out->qp_iterations);
                s->ipm_arg.should_stop = 0;
                s->ipm_arg.stop_ctx = 0;
                ocp_nlp_residuals(s, out);
                out->qp_status = qp_status;
                out->status = qp_status == HM_QP_SOLVED ? HM_STATUS_OK
                              : qp_status == HM_QP_MAX_ITER ? HM_STATUS_MAX_ITER : HM_STATUS_QP_FAILED;
                reason = qp_status == HM_QP_TIMEOUT ? HM_STOP_DEADLINE
                         : qp_status != HM_QP_SOLVED ? HM_STOP_QP_FAILED : ocp_nlp_check_plan(s, in);
            }
            if (reason == HM_STOP_NONE && ocp_nlp_deadline_passed(s)) reason = HM_STOP_DEADLINE;
        }
        /* a clock that ran backwards or stood still: the deadline could not be kept */
        if (ocp_nlp_clock_fault(s, ocp_nlp_now(s))) reason = HM_STOP_CLOCK;
    } else {
        s->prepared = 0;
        t_feedback = ocp_nlp_now(s);
    }
    if (reason == HM_STOP_NONE || reason == HM_STOP_UNSAFE_PLAN || reason == HM_STOP_SEPARATION) s->warm = 1;
    /* after a stop the next QP starts cold: after the braking retry (HM_STOP_UNSAFE_PLAN) its kept
     * iterate is the retry's, whose linearisation the plan has left; a stop before solving leaves one
     * from an older step */
    if (reason != HM_STOP_NONE) s->ipm_ws.warm.ready = 0;
    ocp_nlp_finish(s, in, out, reason); /* the command guard, or the stop */
    ocp_nlp_step_counts_report(s, out);
    out->time_prepare_ms = s->time_prepare_ms;
    out->time_feedback_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t_feedback);
    out->time_total_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t_start);
    return out->status;
}

/* Feedback after a separate preparation: the deadline counts from here. */
HM_FUNC int ocp_nlp_sqp_rti_feedback(hm_solver *s, const hm_input *in, hm_output *out)
{
    if (!s->prepared) s->time_prepare_ms = HM_R(0.0);
    return ocp_nlp_rti_feedback_from(s, in, out, ocp_nlp_now(s), 1);
}

/* A whole real-time iteration: the deadline counts from the start of the preparation. */
HM_FUNC int ocp_nlp_sqp_rti_step(hm_solver *s, const hm_input *in, hm_output *out)
{
    return ocp_nlp_sqp_rti_step_from(s, in, out, ocp_nlp_now(s));
}

HM_FUNC int ocp_nlp_sqp_rti_step_from(hm_solver *s, const hm_input *in, hm_output *out, unsigned long long t0)
{
    ocp_nlp_rti_prepare(s, in);
    return ocp_nlp_rti_feedback_from(s, in, out, t0, 0);
}
