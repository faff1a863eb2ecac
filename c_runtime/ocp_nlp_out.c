/*
 * ocp_nlp_out.c: what a solver step hands back, at its end: the NLP's KKT residuals, the plan, or
 * the protective stop that replaces it, and the safety checks (the inputs before any solving, C1
 * and C2 on the plan after) that decide which: the monitor's tests (monitor.h) applied here, where
 * the solver's state is.
 */
#include "ocp_nlp_out.h"

#include "monitor.h"
#include "ocp_qp.h"
#include "ocp_qp_res.h"

/* KKT residuals of the NLP at the linearisation point with the multipliers in s->mult: exactly those
 * of the QP of this linearisation at a zero step (its gradient is the NLP's, its constraints are the
 * NLP's linearised here), soft rows carrying the slack they need at this point. */
HM_FUNC void ocp_nlp_residuals(hm_solver *s, hm_output *out)
{
    const hm_ocp_qp *qp = &s->qp;
    const hm_ocp_qp_sol *m = &s->mult;
    hm_ocp_qp_res res;
    hm_real gap = HM_R(0.0);
    int i;
    for (i = 0; i < HM_NX; i++) gap = hm_fmax(gap, hm_fabs(qp->x0[i]));
    ocp_qp_res_at_zero_step(qp, m, &res);
    out->kkt_stat = res.stat;
    out->kkt_eq = hm_fmax(res.eq, gap);
    out->kkt_ineq = res.ineq;
    out->kkt_comp = res.comp;
}

/* Smallest distance of the robot's path (nodes 0..N of s->x) to the present humans' current
 * positions, HM_INF without humans. */
static hm_real ocp_nlp_min_human_distance(const hm_solver *s, const hm_input *in)
{
    const int nh = ocp_nlp_clamp_humans(in);
    hm_real best = HM_INF;   /* of the squared distances: one square root (it is monotonic) */
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        for (j = 0; j < nh; j++) {
            const hm_real dx = s->x[n][0] - in->humans_now[j][0];
            const hm_real dy = s->x[n][1] - in->humans_now[j][1];
            const hm_real d2 = dx * dx + dy * dy;
            if (d2 < best) best = d2;
        }
    }
    return nh > 0 ? hm_sqrt(best) : HM_INF;
}

static int ocp_nlp_plan_finite(const hm_solver *s)
{
    hm_real acc = HM_R(0.0);
    int n, i;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) acc += s->x[n][i] * HM_R(0.0);
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) acc += s->u[n][i] * HM_R(0.0);
    return acc == HM_R(0.0); /* 0 * x is NaN for NaN or infinite x */
}

HM_FUNC void ocp_nlp_report(const hm_solver *s, const hm_input *in, hm_output *out)
{
    int n, i;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) out->x[n][i] = s->x[n][i];
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) out->u[n][i] = s->u[n][i];
    out->u0[0] = s->u[0][0];
    out->u0[1] = s->u[0][1];
    out->command[0] = s->x[1][3];
    out->command[1] = s->u[0][1];
    out->cost = s->cost;
    out->min_human_distance = ocp_nlp_min_human_distance(s, in);
}

/* The braking control from speed v: towards v = 0 within one interval, at most at the configured rate of
 * its direction (forward motion brakes at a_min < 0, reverse motion at a_max > 0; the parameter rules keep
 * both at least BRAKING_MIN). */
static hm_real ocp_nlp_braking_control(hm_real v, hm_real a_min, hm_real a_max)
{
    return hm_fmin(hm_fmax(-v / HM_R(HM_DT), a_min), a_max);
}

/* Protective stop: brake to standstill at the configured rates (a_bounds, whenever their row of the
 * parameter table holds, even with another row broken; else the spec's a_bounds), from either direction,
 * no turning; out's plan shows the braking from the measured state. Without a usable pose the plan's
 * positions are zeros, but a usable speed is still braked from; without a usable speed the command is
 * v = 0 and u0 zero (the direction to brake in is unknown: a fixed braking acceleration would speed up a
 * robot moving the other way). After a failure (C1, unusable inputs, the command guard, the clock, a
 * state jump) the next step starts cold, exactly as a fresh solver; after a C2 stop the plan is kept, so
 * that the next steps go on improving it (a cold start would put the unsafe straight-line guess back
 * every time). */
HM_FUNC void ocp_nlp_protective_stop(hm_solver *s, const hm_input *in, hm_output *out, int reason)
{
    hm_params spec_params;
    const hm_params *brake = &s->params;
    hm_real a_min, a_max;
    int x0_ok, v_ok, n, i;
    if (!hm_params_brake_ok(brake)) {
        hm_params_default(&spec_params);
        brake = &spec_params;
    }
    a_min = brake->a_bounds[0];
    a_max = brake->a_bounds[1];
    x0_ok = monitor_check_state(in->x0);
    v_ok = monitor_finite(in->x0[3]) && hm_fabs(in->x0[3]) <= HM_MONITOR_MAX_SPEED;
    out->stop = 1;
    out->stop_reason = reason;
    if (!x0_ok) {
        /* No trustworthy pose: a plan of zeros but for the braking speeds, nothing else computed. */
        for (n = 0; n <= HM_N; n++)
            for (i = 0; i < HM_NX; i++) out->x[n][i] = HM_R(0.0);
        out->x[0][3] = v_ok ? in->x0[3] : HM_R(0.0);
        for (n = 0; n < HM_N; n++) {
            out->u[n][0] = v_ok ? ocp_nlp_braking_control(out->x[n][3], a_min, a_max) : HM_R(0.0);
            out->u[n][1] = HM_R(0.0);
            out->x[n + 1][3] = out->x[n][3] + HM_R(HM_DT) * out->u[n][0];
        }
        out->min_human_distance = HM_INF;
    } else {
        hm_real A[HM_NX * HM_NX], B[HM_NX * HM_NU];
        hm_real best = HM_INF;
        int j, humans_ok;
        for (i = 0; i < HM_NX; i++) out->x[0][i] = in->x0[i];
        for (n = 0; n < HM_N; n++) {
            out->u[n][0] = ocp_nlp_braking_control(out->x[n][3], a_min, a_max);
            out->u[n][1] = HM_R(0.0);
            hm_model_dynamics(out->x[n], out->u[n], out->x[n + 1], A, B);
        }
        humans_ok = monitor_check_input(in, 1);   /* loop-invariant: once, not at every node */
        for (n = 0; n <= HM_N && humans_ok; n++) {
            for (j = 0; j < ocp_nlp_clamp_humans(in); j++) {
                const hm_real dx = out->x[n][0] - in->humans_now[j][0];
                const hm_real dy = out->x[n][1] - in->humans_now[j][1];
                best = hm_fmin(best, hm_sqrt(dx * dx + dy * dy));
            }
        }
        out->min_human_distance = best;
    }
    out->u0[0] = out->u[0][0];
    out->u0[1] = HM_R(0.0);
    /* a speed braked to zero within the interval is zero, not the model's rounding past it */
    out->command[0] = v_ok && out->x[1][3] * out->x[0][3] > HM_R(0.0) ? out->x[1][3] : HM_R(0.0);
    out->command[1] = HM_R(0.0);
    s->prepared = 0;
    /* the safety decisions about people leave a sound plan to start from; the failures do not */
    if (reason != HM_STOP_UNSAFE_PLAN && reason != HM_STOP_HUMAN_TOO_CLOSE && reason != HM_STOP_SEPARATION &&
        reason != HM_STOP_PREDICTED_CONTACT)
        s->warm = 0;
}

/* The end of every step, feedback and solve: the plan (reason HM_STOP_NONE) or the protective stop.
 * A plan passes the command guard first (monitor_command_ok): a command that is not finite or leaves
 * the bounds is a protective stop of its own reason, and the next step starts cold. The measured
 * state is remembered for the next step's jump test (monitor_state_follows). */
HM_FUNC void ocp_nlp_finish(hm_solver *s, const hm_input *in, hm_output *out, int reason)
{
    int i;
    if (reason == HM_STOP_NONE) {
        ocp_nlp_report(s, in, out);
        if (monitor_command_ok(&s->params, out)) reason = -1;
        else {
            reason = HM_STOP_COMMAND_BOUNDS;
            s->ipm_ws.warm.ready = 0;
        }
    }
    if (reason >= 0) ocp_nlp_protective_stop(s, in, out, reason);
    if (monitor_check_state(in->x0))
        for (i = 0; i < HM_NX; i++) s->x0_last[i] = in->x0[i];
}

HM_FUNC void ocp_nlp_step_counts_reset(hm_solver *s)
{
    s->qp_solves = 0;
    s->qp_rows_max = 0;
    s->qp_rows_capped = 0;
}

HM_FUNC void ocp_nlp_step_counts_report(const hm_solver *s, hm_output *out)
{
    out->qp_solves = s->qp_solves;
    out->qp_rows = s->qp_rows_max;
    out->qp_rows_capped = s->qp_rows_capped;
}

HM_FUNC void ocp_nlp_clear_output(hm_output *out)
{
    out->stop = 0;
    out->stop_reason = HM_STOP_NONE;
    out->status = HM_STATUS_SKIPPED;
    out->qp_status = HM_QP_NOT_RUN;
    out->qp_iterations = 0;
    out->sqp_iterations = 0;
    out->qp_solves = 0;
    out->qp_rows = 0;
    out->qp_rows_capped = 0;
    out->cost = HM_R(0.0);
    out->kkt_stat = HM_R(0.0);
    out->kkt_eq = HM_R(0.0);
    out->kkt_ineq = HM_R(0.0);
    out->kkt_comp = HM_R(0.0);
    out->min_human_distance = HM_INF;
}

/* The checks that come before any solving; returns the stop reason or HM_STOP_NONE. A warm solver's
 * measured state must follow the last one (monitor_state_follows): a jump beyond what the bounds allow
 * would have the plan of another place shifted and linearised. */
HM_FUNC int ocp_nlp_check_before(const hm_solver *s, const hm_input *in, int checked_but_x0)
{
    if (!monitor_check_params(&s->params)) return HM_STOP_INVALID_PARAMS;
    /* the preparation of this very step checked this very input, all of it but (warm) x0: its
     * predictions are (N + 1) N_h positions, a tenth of the step's work at N_h = 100 */
    if (checked_but_x0 ? !monitor_check_state(in->x0) : !monitor_check_input(in, 1)) return HM_STOP_INVALID_INPUT;
    if (monitor_distance_now(in) < s->params.d_h) return HM_STOP_HUMAN_TOO_CLOSE;
    if (s->warm && !monitor_state_follows(&s->params, s->x0_last, in->x0)) return HM_STOP_STATE_JUMP;
    return HM_STOP_NONE;
}

static int ocp_nlp_keeps_distance(const hm_real *x, const hm_input *in, hm_real limit)
{
    const int nh = ocp_nlp_clamp_humans(in);
    int j;
    for (j = 0; j < nh; j++) {
        const hm_real dx = x[0] - in->humans_now[j][0];
        const hm_real dy = x[1] - in->humans_now[j][1];
        if (dx * dx + dy * dy < limit * limit) return 0;
    }
    return 1;
}

/* C2 on the plan: its nodes 1..N against the humans' current positions, and the state the robot
 * really reaches after applying u0 for one interval (the model from the measured x0: the plan's
 * own x_1 is the QP's linear prediction of it). The allowance covers the distance smoothing
 * (eps^2 / (2 d_h) ~ 1e-6 m) and the QP tolerance. */
HM_FUNC int ocp_nlp_check_plan(const hm_solver *s, const hm_input *in)
{
    const hm_real limit = s->params.d_h - HM_R(1e-5);
    hm_real x1[HM_NX], A[HM_NX * HM_NX], B[HM_NX * HM_NU];
    int n;
    if (!ocp_nlp_plan_finite(s)) return HM_STOP_NONFINITE;
    for (n = 1; n <= HM_N; n++)
        if (!ocp_nlp_keeps_distance(s->x[n], in, limit)) return HM_STOP_UNSAFE_PLAN;
    hm_model_dynamics(in->x0, s->u[0], x1, A, B);
    if (!ocp_nlp_keeps_distance(x1, in, limit)) return HM_STOP_UNSAFE_PLAN;
    if (!monitor_check_separation(in, &s->params, s->x[1][3])) return HM_STOP_SEPARATION;
    return HM_STOP_NONE;
}
