/*
 * controller_recovery.c: recoveries of the main plan (controller_recovery.h).
 *
 * A real-time iteration improves the last plan by one step, so it stays in the local solution it is in.
 * Why each recovery (measured in the evaluation, docs/evaluation.md):
 * - the loop: when the plan is a loop (its end nearer its start than loop_ratio times its length), a few
 *   SQP iterations from a cold start find the direct one.
 * - the goal behind: standing with the carrot behind (after an overshoot, or given a goal behind), the OCP
 *   has no gradient towards turning (turning in place moves no node) and may not back up, so the real-time
 *   iteration stands for good; a recovery from a turn towards the carrot starts it, and its plan is kept
 *   when it ends nearer the carrot.
 * - the slow follower and the stall: behind a slow walker on the robot's own line the plan that follows is
 *   a saddle of the OCP, symmetric between passing left and right, where SQP iterations from any symmetric
 *   start stay (measured: a person 1.1 m ahead at 0.15 m/s, cost 2467 following, 873 passing). A robot
 *   that has gone slower than half the speed it tracks for stall_time, or has stalled
 *   (controller_progress_checker.h), tries a recovery from a start that steps sideways, towards the
 *   carrot's side (left when it is straight ahead); its plan is kept only when it costs less.
 * Paced recoveries share one timer: at most one per stall_time.
 */
#include "controller_recovery.h"

#include "monitor.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_out.h"
#include "ocp_nlp_rti.h"
#include "ocp_nlp_screen.h"
#include "ocp_nlp_sqp.h"
#include "ocp_qp.h"

/* The sideways start of a recovery from a slow or stalled state: this turn rate for the first second,
 * the opposite for the next (a lateral step of about v * 0.5 m), then straight on. */
#define CONTROLLER_NUDGE_OMEGA HM_R(0.5)
#define CONTROLLER_NUDGE_SECONDS HM_R(1.0)
/* The turn start of a recovery turns until the carrot is this close to ahead (the cosine of the bearing:
 * 26 degrees), then drives; the SQP straightens the rest. */
#define CONTROLLER_TURN_ALIGNED HM_R(0.9)

/* The length of a planned path. */
static hm_real controller_plan_length(const hm_output *o)
{
    hm_real length = HM_R(0.0);
    int n;
    for (n = 0; n < HM_N; n++) {
        const hm_real dx = o->x[n + 1][0] - o->x[n][0], dy = o->x[n + 1][1] - o->x[n][1];
        length += hm_sqrt(dx * dx + dy * dy);
    }
    return length;
}

/* A planned path of at least loop_min_length metres whose end is nearer its start than loop_ratio
 * times its length. */
HM_FUNC int controller_plan_is_loop(const hm_controller *c)
{
    const hm_controller_params *p = &c->params;
    const hm_output *o = &c->out;
    hm_real length, dx, dy;
    if (!(p->loop_ratio > HM_R(0.0))) return 0;
    length = controller_plan_length(o);
    dx = o->x[HM_N][0] - o->x[0][0];
    dy = o->x[HM_N][1] - o->x[0][1];
    return length >= p->loop_min_length && hm_sqrt(dx * dx + dy * dy) < p->loop_ratio * length;
}

/* A recovery's SQP starts from the guess just simulated into s->x, s->u (whose dynamics' Jacobians it
 * left in the QP), with no multipliers and the screening radii of a guess that is not a QP's solution. */
static void controller_start_from_guess(hm_solver *s)
{
    s->dyn_fresh = 1;
    ocp_qp_sol_set_zero(&s->mult);
    ocp_nlp_screen_reach(s);
    s->warm = 1; /* the SQP starts from this plan, not from a standstill guess */
}

/* The start of a sideways recovery: the measured state, the speed the OCP tracks reached within the
 * acceleration bounds, a step to the side (CONTROLLER_NUDGE_*), simulated by the model. */
static void controller_nudge(hm_controller *c)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_real a_min = s->params.a_bounds[0], a_max = s->params.a_bounds[1];
    const hm_real dx = in->goal[0] - in->x0[0], dy = in->goal[1] - in->x0[1];
    const hm_real lateral = -hm_sin(in->x0[2]) * dx + hm_cos(in->x0[2]) * dy;
    const hm_real side = lateral < HM_R(-1e-3) ? HM_R(-1.0) : HM_R(1.0);
    const hm_real v_goal = hm_fmax(in->goal[3], HM_R(0.5) * c->params.v_ref);
    int n, i;
    for (i = 0; i < HM_NX; i++) s->x[0][i] = in->x0[i];
    for (n = 0; n < HM_N; n++) {
        const hm_real t = HM_R(HM_DT) * (hm_real)n;
        const hm_real w = t < CONTROLLER_NUDGE_SECONDS ? CONTROLLER_NUDGE_OMEGA
                          : t < HM_R(2.0) * CONTROLLER_NUDGE_SECONDS ? -CONTROLLER_NUDGE_OMEGA : HM_R(0.0);
        s->u[n][0] = hm_fmin(hm_fmax((v_goal - s->x[n][3]) / HM_R(HM_DT), a_min), a_max);
        s->u[n][1] = hm_fmin(hm_fmax(side * w, s->params.omega_bounds[0]), s->params.omega_bounds[1]);
        hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    }
    controller_start_from_guess(s);
}

/* 1 when the carrot is behind the robot (more than 90 degrees off its heading) and the plan stands (its
 * path shorter than stall_distance): the standstill where the OCP is stuck with a goal behind. At rest,
 * turning in place moves no node, so the position terms give the turn no gradient, and v >= 0 forbids
 * backing up: within the approach (no speed to track) the real-time iteration stays there for good (a
 * goal 0.66 to 3 m straight behind was never reached), and a recovery from a cold or a sideways start
 * finds the same standstill. */
HM_FUNC int controller_stuck_facing_away(const hm_controller *c)
{
    return hm_cos(controller_carrot_bearing(&c->in, c->in.x0)) < HM_R(0.0) &&
           controller_plan_length(&c->out) < c->params.stall_distance;
}

/* 1 when the point a is nearer the carrot than b. */
static int controller_nearer(const hm_input *in, const hm_real *a, const hm_real *b)
{
    const hm_real ax = in->goal[0] - a[0], ay = in->goal[1] - a[1], bx = in->goal[0] - b[0], by = in->goal[1] - b[1];
    return ax * ax + ay * ay < bx * bx + by * by;
}

/* The start of a recovery towards a carrot behind the robot: from the measured state, brake and turn
 * towards the carrot at the turn-rate bound until it is ahead, then drive to it at the speed the OCP
 * tracks (at least half the cruising speed), slowing to arrive at rest; simulated by the model. */
static void controller_turn_start(hm_controller *c)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_params *p = &s->params;
    const hm_real a_min = p->a_bounds[0], a_max = p->a_bounds[1];
    const hm_real v_goal = hm_fmax(in->goal[3], HM_R(0.5) * c->params.v_ref);
    int n, i, aligned = 0;
    for (i = 0; i < HM_NX; i++) s->x[0][i] = in->x0[i];
    for (n = 0; n < HM_N; n++) {
        const hm_real *x = s->x[n];
        const hm_real e = controller_carrot_bearing(in, x);
        const hm_real dx = in->goal[0] - x[0], dy = in->goal[1] - x[1];
        const hm_real left = hm_sqrt(dx * dx + dy * dy);
        hm_real v_want;
        if (hm_cos(e) > CONTROLLER_TURN_ALIGNED) aligned = 1;
        v_want = aligned ? hm_fmin(v_goal, hm_sqrt(HM_R(2.0) * -a_min * left)) : HM_R(0.0);
        s->u[n][0] = hm_fmin(hm_fmax((v_want - x[3]) / HM_R(HM_DT), a_min), a_max);
        s->u[n][1] = hm_fmin(hm_fmax(e / HM_R(HM_DT), p->omega_bounds[0]), p->omega_bounds[1]);
        hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    }
    controller_start_from_guess(s);
}

/* A bounded SQP inside the period's deadline (counted from t0), from the given start. Its plan replaces
 * the real-time iteration's when it is solved and safe, and, from a step to the side, costs less (the
 * real-time iteration's may be a good plan in another local solution), or, from a turn, ends nearer the
 * carrot (the real-time iteration's stands where the OCP's cost over the horizon cannot tell a turn
 * around from standing); otherwise the real-time iteration's stands (it passed the monitors) and the next
 * period starts cold. Returns 1 when it replaced it. */
HM_FUNC int controller_recover(hm_controller *c, unsigned long long t0, enum controller_start start,
                               hm_controller_output *out)
{
    hm_solver *s = &c->solver;
    const hm_real tol = hm_fmax(s->params.qp_tol, HM_R(1e-6));
    const unsigned long long t1 = ocp_nlp_now(s);
    hm_output *r = &c->recovery_out;
    int ok;
    ocp_nlp_sqp_reset(s);
    if (start == CONTROLLER_START_TURN) controller_turn_start(c);
    else if (start == CONTROLLER_START_SIDEWAYS) controller_nudge(c);
    ocp_nlp_sqp_solve_timed(s, &c->in, r, c->params.recovery_iterations, tol, t0);
    out->time_recovery_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t1);
    ok = !r->stop && r->qp_status == HM_QP_SOLVED &&
         (start == CONTROLLER_START_TURN       ? controller_nearer(&c->in, r->x[HM_N], c->out.x[HM_N])
          : start == CONTROLLER_START_SIDEWAYS ? r->cost < c->out.cost
                                               : 1);
    if (ok) {
        c->out = *r;
    } else {
        ocp_nlp_sqp_reset(s);
    }
    return ok;
}

/* 1 when a paced recovery (the goal behind's, the stall's) may run in this period: no plan recovered yet,
 * no stop, recoveries on, and none of them within the last stall_time (they share the timer). */
HM_FUNC int controller_may_recover(const hm_controller *c, const hm_controller_input *cin,
                                   const hm_controller_output *out)
{
    return !out->recovered && !c->out.stop && c->params.recovery_iterations > 0 &&
           (!c->has_recovery || cin->time - c->time_recovery >= c->params.stall_time);
}

/* controller_recover, its time taken for the pace of controller_may_recover. */
HM_FUNC int controller_recover_paced(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                     enum controller_start start, hm_controller_output *out)
{
    c->has_recovery = 1;
    c->time_recovery = cin->time;
    return controller_recover(c, t0, start, out);
}
