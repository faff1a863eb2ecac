/*
 * controller.c: the navigation controller (controller.h), split by role as nav2 splits a controller:
 * path handling (controller_path.h), the objective of the period (controller_objective.h), the people
 * and the obstacle the OCP sees (controller_people.h), passing decisions (controller_candidates.h),
 * recoveries of the main plan (controller_recovery.h), goal checking (controller_goal_checker.h),
 * progress checking (controller_progress_checker.h) and the safety guard (controller_safety.h). This
 * file checks the inputs and runs one period through them (docs/ARCHITECTURE.md, "One control period").
 */
#include "controller.h"

#include "controller_candidates.h"
#include "controller_goal_checker.h"
#include "controller_objective.h"
#include "controller_path.h"
#include "controller_people.h"
#include "controller_progress_checker.h"
#include "controller_recovery.h"
#include "controller_safety.h"
#include "monitor.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_out.h"
#include "ocp_nlp_rti.h"
#include "ocp_nlp_screen.h"
#include "ocp_nlp_sqp.h"
#include "ocp_qp.h"

/* The progress objective's speed to track, lowered by speed and separation towards the goal, not below this
 * fraction of itself (chosen on tuning seeds: docs/evaluation.md, "How the defaults were chosen"). The speed
 * itself stays bounded by the OCP's constraints and the guard. */
#define CONTROLLER_PROGRESS_SPEED_FLOOR HM_R(0.5)

/* 1 when every input is usable: counts within their capacities, numbers finite and not absurd. */
static int controller_input_ok(const hm_controller_input *cin)
{
    int i;
    if (!monitor_finite(cin->time) || !monitor_position_ok(cin->pose)) return 0;
    if (!(hm_fabs(cin->pose[2]) <= HM_MONITOR_MAX_ANGLE) || !(hm_fabs(cin->v) <= HM_MONITOR_MAX_SPEED) ||
        !(hm_fabs(cin->omega) <= HM_MONITOR_MAX_SPEED))
        return 0;
    if (cin->n_path < 0 || cin->n_path > HM_MAX_PATH_POINTS || cin->n_tracks < 0 ||
        cin->n_tracks > HM_MAX_TRACKS || cin->n_obstacles < 0 || cin->n_obstacles > HM_MAX_OBSTACLE_POINTS ||
        (cin->has_goal != 0 && cin->has_goal != 1) || cin->n_tracks_dropped < 0)
        return 0;
    if (cin->has_goal && (!monitor_position_ok(cin->goal) || !(hm_fabs(cin->goal[2]) <= HM_MONITOR_MAX_ANGLE)))
        return 0;
    for (i = 0; i < cin->n_path; i++)
        if (!monitor_position_ok(cin->path[i])) return 0;
    for (i = 0; i < cin->n_tracks; i++) {
        const hm_real *t = cin->tracks[i];
        const hm_real *c = cin->track_covariances[i];
        if (!monitor_position_ok(t) || !(hm_fabs(t[2]) <= HM_MONITOR_MAX_SPEED) ||
            !(hm_fabs(t[3]) <= HM_MONITOR_MAX_SPEED))
            return 0;
        if (cin->track_has_covariance[i] != 0 && cin->track_has_covariance[i] != 1) return 0;
        if (cin->track_has_covariance[i] &&
            !(c[0] >= HM_R(0.0) && c[2] >= HM_R(0.0) && c[0] <= HM_R(1e6) && c[2] <= HM_R(1e6) &&
              hm_fabs(c[1]) <= HM_R(1e6)))
            return 0;
    }
    for (i = 0; i < cin->n_obstacles; i++)
        if (!monitor_position_ok(cin->obstacles[i])) return 0;
    return 1;
}

HM_FUNC void controller_reset(hm_controller *c)
{
    ocp_nlp_sqp_reset(&c->solver);
    c->has_goal = 0;
    c->has_time = 0;
    c->has_recovery = 0;
    c->has_theta = 0;
    c->has_origin = 0;
    c->has_lead = 0;
    c->lead = HM_R(0.0);
    c->arriving = 0;
    controller_candidates_reset(c);
    c->best_left = HM_INF;
    c->time_progress = HM_R(0.0);
    c->time_brisk = HM_R(0.0);
    c->time_last = HM_R(0.0);
    c->time_recovery = HM_R(0.0);
    c->theta = HM_R(0.0);
}

HM_FUNC void controller_init(hm_controller *c, const hm_params *params, const hm_controller_params *own)
{
    int j;
    c->params = *own;
    ocp_nlp_sqp_init(&c->solver, params);
    c->in.n_humans = 0;
    c->in.has_obstacle = 0;
    c->in.has_refs = 0;
    for (j = 0; j < 2; j++) c->in.obstacle[j] = HM_R(0.0);
    controller_reset(c);
}

static void controller_clear_output(hm_controller_output *out)
{
    out->outcome = HM_OUTCOME_FOLLOWING;
    out->goal_reached = 0;
    out->stalled = 0;
    out->recovered = 0;
    out->loop_detected = 0;
    out->candidate = 0;
    out->candidates_ok = 0;
    out->n_people = 0;
    out->has_obstacle = 0;
    out->distance_to_goal = HM_INF;
    out->time_without_progress = HM_R(0.0);
    out->time_solver_ms = HM_R(0.0);
    out->time_recovery_ms = HM_R(0.0);
}

/* out from the solver's output c->out (the plan, the command, the stop). */
static void controller_report(const hm_controller *c, hm_controller_output *out)
{
    const hm_output *o = &c->out;
    int n, i;
    out->command[0] = o->command[0];
    out->command[1] = o->command[1];
    out->u[0] = o->u0[0];
    out->u[1] = o->u0[1];
    out->stop = o->stop;
    out->stop_reason = o->stop_reason;
    out->status = o->status;
    out->qp_status = o->qp_status;
    out->qp_iterations = o->qp_iterations;
    out->sqp_iterations = o->sqp_iterations;
    out->qp_rows = o->qp_rows;
    out->qp_rows_capped = o->qp_rows_capped;
    out->min_human_distance = o->min_human_distance;
    for (n = 0; n <= HM_N; n++)
        for (i = 0; i < HM_NX; i++) out->plan[n][i] = o->x[n][i];
    for (n = 0; n < HM_N; n++)
        for (i = 0; i < HM_NU; i++) out->controls[n][i] = o->u[n][i];
    for (i = 0; i < HM_NX; i++) out->ocp_goal[i] = c->in.goal[i];
    out->has_obstacle = c->in.has_obstacle;
    out->obstacle[0] = c->in.obstacle[0];
    out->obstacle[1] = c->in.obstacle[1];
    if (o->stop) out->outcome = HM_OUTCOME_STOPPED;
}

/* The heading the OCP sees winds continuously (odometry's wrap at +-pi would be a jump of 2 pi), but not
 * without bound: a robot that keeps turning one way would reach the inputs' limit (1e4 rad, 2.8 h at
 * 1 rad/s) and stop for good. Beyond this many radians the unwound heading, the solver's plan and its
 * last state are moved back by whole turns, which changes nothing the OCP sees (its dynamics and costs
 * read headings through sin and cos, and the carrot's heading is unwound to the robot's). */
#define CONTROLLER_HEADING_WIND HM_R(64.0)

/* The measured heading unwound against the last period's, kept within CONTROLLER_HEADING_WIND. */
static hm_real controller_heading(hm_controller *c, hm_real measured)
{
    hm_solver *s = &c->solver;
    hm_real theta = c->has_theta ? controller_unwrap(measured, c->theta) : measured;
    if (hm_fabs(theta) > CONTROLLER_HEADING_WIND) {
        const hm_real shift = theta - controller_unwrap(measured, HM_R(0.0));
        int n;
        theta -= shift;
        for (n = 0; n <= HM_N; n++) s->x[n][2] -= shift;
        s->x0_last[2] -= shift;
    }
    c->theta = theta;
    c->has_theta = 1;
    return theta;
}

/* The period's path: what the robot does, into c->out (and out's flags); returns 1 when c->out is the
 * controller's own braking plan (at the goal, without a goal), 0 for a plan of the solver's. */
static int controller_plan(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                           hm_controller_output *out)
{
    hm_solver *s = &c->solver;
    hm_input *in = &c->in;
    const hm_real horizon = HM_R(HM_DT) * (hm_real)HM_N;
    hm_controller_goal g;
    hm_real path[HM_N + 1][2];
    unsigned long long t1;
    int slow = 0, chosen;
    controller_goal(cin, controller_origin(c, cin), cin->pose, in->x0[2],
                    c->params.lookahead > HM_R(0.0) ? c->params.lookahead : c->params.v_ref * horizon, &g);
    if (!g.has) {
        in->goal[0] = in->x0[0];
        in->goal[1] = in->x0[1];
        in->goal[2] = in->x0[2];
        in->goal[3] = HM_R(0.0);
        controller_brake(c);
        out->outcome = HM_OUTCOME_NO_GOAL;
        c->has_goal = 0;
        return 1;
    }
    out->distance_to_goal = g.left;
    in->goal[0] = g.carrot[0];
    in->goal[1] = g.carrot[1];
    in->goal[2] = g.carrot[2];
    controller_solver_params(c, &g);
    if (controller_arriving(c, &g)) {
        /* reached: within the tolerance, the heading met, and at rest (nav2's stopped goal checker); until the
         * robot stands, it is braking towards its goal */
        const enum controller_at_goal_state state = controller_at_goal(c, cin, g.final[2]);
        out->goal_reached = state == CONTROLLER_GOAL_DONE && hm_fabs(cin->v) <= CONTROLLER_AT_REST;
        if (out->goal_reached) out->outcome = HM_OUTCOME_GOAL_REACHED;
        controller_progress(c, cin, &g, 1, &slow, out);
        return 1;
    }
    /* A speed to track that the robot may not use towards its goal rewards the plan for spending it
     * elsewhere: with people between it and the goal, it circled at cruising speed. The progress objective
     * spends it along the path only, and lowered all the way to the bound it left the path's goals creeping
     * beside a person who stood between the robot and its goal, where the robot then stood: there it is
     * lowered at most to CONTROLLER_PROGRESS_SPEED_FLOOR of itself. */
    {
        const hm_real dx = in->goal[0] - in->x0[0], dy = in->goal[1] - in->x0[1];
        const hm_real len = hm_sqrt(dx * dx + dy * dy);
        const hm_real v_floor = c->params.progress ? CONTROLLER_PROGRESS_SPEED_FLOOR * in->goal[3] : HM_R(0.0);
        if (len > HM_R(1e-9))
            in->goal[3] = hm_fmin(in->goal[3], hm_fmax(v_floor, controller_separation_bound(cin, in->x0, dx / len,
                                                                                          dy / len, in->goal[3],
                                                                                          &s->params)));
    }
    if (c->params.progress) controller_references(c, cin, &g);
    controller_expected_path(s, cin, path);
    controller_select_people(path, cin, &s->params, hm_fmax(hm_fabs(cin->v), s->params.v_bounds[1]), in, out);
    controller_nearest_obstacle(path, cin, s->params.v_bounds[1], in);
    controller_goal_people(c, cin, &g, out);
    t1 = ocp_nlp_now(s);
    ocp_nlp_sqp_rti_step_from(s, in, &c->out, t0);
    chosen = controller_candidates_step(c, cin, t0, out);
    out->time_solver_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t1);
    if (chosen != 0) {
        /* a candidate passes someone: the recoveries are for the main plan's standstills and loops */
        out->stalled = controller_progress(c, cin, &g, c->out.stop, &slow, out);
        if (out->stalled) {
            out->outcome = HM_OUTCOME_STALLED;
            controller_stalled_command(c);
        }
        return 0;
    }
    if (!c->out.stop && c->params.recovery_iterations > 0 && controller_plan_is_loop(c)) {
        out->loop_detected = 1;
        out->recovered = controller_recover(c, t0, CONTROLLER_START_COLD, out);
    }
    out->stalled = controller_progress(c, cin, &g, c->out.stop, &slow, out);
    if (controller_may_recover(c, cin, out) && controller_stuck_facing_away(c))
        out->recovered = controller_recover_paced(c, cin, t0, CONTROLLER_START_TURN, out);
    if ((out->stalled || slow) && controller_may_recover(c, cin, out))
        out->recovered = controller_recover_paced(c, cin, t0, CONTROLLER_START_SIDEWAYS, out);
    if (out->stalled) {
        out->outcome = HM_OUTCOME_STALLED;
        controller_stalled_command(c);
    }
    return 0;
}

/* 1 when both the solver's parameters and the controller's keep their rules. */
static int controller_params_ok(const hm_controller *c)
{
    return monitor_check_params(&c->solver.params) && hm_controller_params_check(&c->params) == 0;
}

HM_FUNC int controller_step(hm_controller *c, const hm_controller_input *cin, hm_controller_output *out)
{
    hm_solver *s = &c->solver;
    hm_input *in = &c->in;
    const unsigned long long t0 = ocp_nlp_now(s);
    controller_caller_params caller;
    controller_caller_keep(c, &caller);
    controller_clear_output(out);
    in->n_humans = 0;
    in->has_obstacle = 0;
    in->has_refs = 0;
    in->x0[0] = cin->pose[0];
    in->x0[1] = cin->pose[1];
    in->x0[2] = cin->pose[2];
    in->x0[3] = cin->v;
    out->n_tracks_dropped = cin->n_tracks_dropped;
    if (!controller_input_ok(cin) || !controller_params_ok(c)) {
        int i;
        const int reason = controller_params_ok(c) ? HM_STOP_INVALID_INPUT : HM_STOP_INVALID_PARAMS;
        for (i = 0; i < HM_NX; i++) in->goal[i] = in->x0[i];
        ocp_nlp_clear_output(&c->out);
        ocp_nlp_protective_stop(s, in, &c->out, reason);
        ocp_nlp_sqp_reset(s);
        c->has_time = 0;
        c->has_theta = 0;
    } else {
        int braking;
        in->x0[2] = controller_heading(c, cin->pose[2]);
        braking = controller_plan(c, cin, t0, out);
        controller_guard(c, cin, t0, braking);
    }
    controller_report(c, out);   /* a stop: the outcome "stopped", with its reason */
    controller_caller_restore(c, &caller);
    out->time_total_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t0);
    return out->outcome;
}

HM_FUNC const char *controller_outcome_message(int outcome)
{
    switch (outcome) {
        HM_OUTCOME_TABLE(HM_STATUS_CASE_ROW)
    default:
        return "unknown outcome";
    }
}
