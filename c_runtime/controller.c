/*
 * controller.c: the navigation controller (controller.h).
 *
 * One period: check the inputs; the goal the OCP sees (a carrot on the path) and, near the goal, the
 * approach; the solver's parameters for this period (the caller's, with the approach weights and the
 * speed limit); the people and the obstacle the OCP sees; one real-time iteration; a recovery by a
 * bounded SQP from a cold start when its plan is a loop or the robot has stalled; the command.
 *
 * Why each piece (measured in the evaluation, docs/evaluation.md):
 * - the speed taper: the OCP tracks v_ref, and with a constant v_ref the robot circles its goal at
 *   cruising speed; the speed it tracks is at most goal_taper times the distance left.
 * - the approach: once the horizon reaches the goal, a speed to track over all of it makes the plan
 *   loop around the goal to spend its length; the approach drops that weight, weighs the position at
 *   every node and asks for the goal at rest. It also ends the collision potential at the robot's
 *   earliest arrival (plus arrival_margin): predictions of people crossing the goal after the robot
 *   has stopped there held it short of the goal.
 * - the loop recovery: a real-time iteration improves the last plan by one step, so it stays in the
 *   local solution it is in; when that is a loop (its end nearer its start than loop_ratio times its
 *   length), a few SQP iterations from a cold start find the direct one.
 * - the stall: a robot that makes no progress while nothing stops it (a local solution in front of a
 *   person who does not move) is reported as stalled, and a recovery is tried once per stall_time.
 * - the goal behind: standing with the carrot behind (after an overshoot, or given a goal behind), the OCP
 *   has no gradient towards turning (turning in place moves no node) and may not back up, so the real-time
 *   iteration stands for good; a recovery from a turn towards the carrot starts it, and its plan is kept
 *   when it ends nearer the carrot.
 * - the slow follower: behind a slow walker on the robot's own line the plan that follows is a saddle
 *   of the OCP, symmetric between passing left and right, where SQP iterations from any symmetric
 *   start stay (measured: a person 1.1 m ahead at 0.15 m/s, cost 2467 following, 873 passing). A
 *   robot that has gone slower than half the speed it tracks for stall_time tries a recovery from a
 *   start that steps sideways, towards the carrot's side (left when it is straight ahead); its plan
 *   is kept only when it costs less.
 */
#include "controller.h"

#include "controller_candidates.h"
#include "controller_goal.h"
#include "controller_people.h"
#include "controller_safety.h"
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
/* The turn in place to a goal pose's heading: its rate per radian of the heading's error, within the
 * turn-rate bounds (at 2 per second the error halves in 0.35 s once below the bound's reach). */
#define CONTROLLER_TURN_GAIN HM_R(2.0)
/* Slower than this a robot counts as standing: it may turn in place at its goal (the evaluation's threshold
 * of moving, python/eval/metrics.py). */
#define CONTROLLER_AT_REST HM_R(0.05)
/* Slower than this a person counts as standing [m/s]. */
#define CONTROLLER_STANDING HM_R(0.2)

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
    c->arriving = 0;
    controller_candidates_reset(c);
    c->best_left = HM_INF;
    c->time_progress = HM_R(0.0);
    c->time_brisk = HM_R(0.0);
    c->time_last = HM_R(0.0);
    c->time_recovery = HM_R(0.0);
    c->theta = HM_R(0.0);
}

HM_FUNC void controller_init(hm_controller *c, const hm_params *params)
{
    int j;
    c->params = *params;
    ocp_nlp_sqp_init(&c->solver, params);
#if HM_NCAND > 1
    for (j = 0; j < HM_NCAND - 1; j++) ocp_nlp_sqp_init(&c->candidates[j], params);
#endif
    c->in.n_humans = 0;
    c->in.has_obstacle = 0;
    c->in.has_refs = 0;
    for (j = 0; j < 2; j++) c->in.obstacle[j] = HM_R(0.0);
    controller_reset(c);
}

/* The end of the collision potential near the goal: the robot's earliest arrival within goal_tolerance from
 * rest (at v_ref or the speed cap, whichever is lower, reached at the upper acceleration bound) plus
 * arrival_margin, or the caller's collision_horizon when that is sooner. */
static hm_real controller_arrival(const hm_params *p, const hm_params *sp, const hm_controller_goal *g)
{
    const hm_real v_arrive = hm_fmin(p->v_ref, sp->v_bounds[1]);
    const hm_real arrival = hm_fmax(g->left - p->goal_tolerance, HM_R(0.0)) / v_arrive +
                            v_arrive / (HM_R(2.0) * p->a_bounds[1]) + p->arrival_margin;
    return hm_fmin(p->collision_horizon, arrival);
}

/* The solver's parameters for this period: the caller's, with the speed limit and, within the
 * horizon's reach of the goal, the approach weights and the collision potential's end. Sets the goal's
 * speed (in->goal[3]). */
static void controller_solver_params(hm_controller *c, const hm_controller_goal *g)
{
    const hm_params *p = &c->params;
    hm_params *sp = &c->solver.params;
    const hm_real horizon = HM_R(HM_DT) * (hm_real)HM_N;
    const hm_real cap = hm_fmin(p->v_bounds[1], p->speed_limit);
    *sp = *p;
    if (cap > p->v_bounds[0]) sp->v_bounds[1] = cap;
    if (p->progress) {
        /* the per-node goals brake to the goal themselves (controller_references): no taper, no approach
         * weights; the potential's end at the earliest arrival as in the approach (below) */
        int i;
        for (i = 0; i < HM_NX; i++) sp->w_goal[i] = p->progress_weights[i];
        c->in.goal[3] = p->v_ref;
        if (g->left < p->v_ref * horizon) sp->collision_horizon = controller_arrival(p, sp, g);
        return;
    }
    c->in.goal[3] = hm_fmin(p->v_ref, p->goal_taper * g->left);
    if (p->approach && g->left < p->v_ref * horizon) {
        sp->w_goal[3] = HM_R(0.0);
        sp->w_goal[0] = sp->w_goal[1] = p->approach_position;
        sp->w_goal_terminal[3] = p->approach_stop;
        c->in.goal[3] = HM_R(0.0);
        /* The plan's nodes after the robot has arrived describe a future the controller never drives:
         * within goal_tolerance it brakes and reports the goal reached. People predicted to cross the
         * goal after that pushed the whole plan away from it (corridor: the robot waited 0.34 m short of
         * a goal that nobody was near, then a recovery left the corridor), so the potential acts only
         * on the nodes up to the earliest arrival from rest (at v_ref or the speed cap, whichever is
         * lower, reached at the upper acceleration bound), plus arrival_margin. Earlier nodes, the
         * distance rows (people's current positions) and the speed-and-separation bound (predictions
         * over the whole horizon) are unchanged. */
        sp->collision_horizon = controller_arrival(p, sp, g);
    }
}

/* Where a straight path to a goal pose given alone starts: with the progress objective, where the robot
 * was when it got that goal (the line must not move with the robot, or walking off sideways would cost
 * nothing); else the robot itself (the carrot of the paper's objective). */
static const hm_real *controller_origin(hm_controller *c, const hm_controller_input *cin)
{
    const hm_real *end = cin->n_path == 1 ? cin->path[0] : cin->goal;
    if (!c->params.progress || cin->n_path >= 2) return cin->pose;
    if (!c->has_origin || c->origin_goal[0] != end[0] || c->origin_goal[1] != end[1]) {
        c->origin[0] = cin->pose[0];
        c->origin[1] = cin->pose[1];
        c->origin_goal[0] = end[0];
        c->origin_goal[1] = end[1];
        c->has_origin = 1;
    }
    return c->origin;
}

/* The progress objective's goal per node (params.progress): node n's goal is the point of the path where
 * a robot that started at its projection now would be at node n's time, going at the speed to track
 * (in->goal[3]: the cruising speed, lowered by speed and separation; not the measured speed, from which a
 * standing robot's goals would move off too slowly to ever start it) and braking at half the lower bound
 * to arrive at the goal at rest; heading: the path's there; speed: that speed. Motion that does not bring
 * the robot along its path falls behind these goals and costs; so does standing, once they have moved on.
 * Sets in->refs and in->has_refs. */
static void controller_references(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g)
{
    hm_input *in = &c->in;
    const hm_params *sp = &c->solver.params;
    const hm_real dt = HM_R(HM_DT), a_down = HM_R(-0.5) * sp->a_bounds[0];
    const hm_real *origin = controller_origin(c, cin);
    hm_real v = in->goal[3], d = HM_R(0.0);
    int n;
    for (n = 0; n <= HM_N; n++) {
        const hm_real left = hm_fmax(g->length - g->s_proj - d, HM_R(0.0));
        hm_real *r = in->refs[n];
        controller_path_at(cin, origin, in->x0[2], g->s_proj + d, g, r);
        r[3] = v;
        d += v * dt;
        /* from the speed to track, the speed only falls (the braking term shrinks with the way left) */
        v = hm_fmin(in->goal[3], hm_sqrt(HM_R(2.0) * a_down * hm_fmax(left - v * dt, HM_R(0.0))));
    }
    in->has_refs = 1;
}

/* People who stand within goal_clearance of the final goal carry no collision potential: its half-height
 * distance d_th (1 m) held the robot 1.3-1.9 m short of a goal beside people standing still. The hard
 * distance d_h, C2 and speed and separation still keep them. */
static void controller_goal_people(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                                   const hm_controller_output *out)
{
    const hm_real r = c->params.goal_clearance;
    int j;
    for (j = 0; j < c->in.n_humans; j++) {
        const hm_real *t = cin->tracks[out->people_index[j]];
        const hm_real dx = t[0] - g->final[0], dy = t[1] - g->final[1];
        c->in.humans_no_potential[j] = dx * dx + dy * dy < r * r &&
                                       t[2] * t[2] + t[3] * t[3] < CONTROLLER_STANDING * CONTROLLER_STANDING;
    }
}

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
static int controller_is_loop(const hm_params *p, const hm_output *o)
{
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

/* The bearing of the carrot from a robot at x, in (-pi, pi]. */
static hm_real controller_carrot_bearing(const hm_input *in, const hm_real *x)
{
    const hm_real e = hm_atan2(in->goal[1] - x[1], in->goal[0] - x[0]) - x[2];
    return hm_atan2(hm_sin(e), hm_cos(e));
}

/* 1 when the carrot is behind the robot (more than 90 degrees off its heading) and the plan stands (its
 * path shorter than stall_distance): the standstill where the OCP is stuck with a goal behind. At rest,
 * turning in place moves no node, so the position terms give the turn no gradient, and v >= 0 forbids
 * backing up: within the approach (no speed to track) the real-time iteration stays there for good (a
 * goal 0.66 to 3 m straight behind was never reached), and a recovery from a cold or a sideways start
 * finds the same standstill. */
static int controller_stuck_facing_away(const hm_controller *c)
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

/* Where a recovery's SQP starts. */
enum controller_start {
    CONTROLLER_START_COLD,     /* a standstill guess: after a loop */
    CONTROLLER_START_SIDEWAYS, /* a step to the side (controller_nudge): slow or stalled */
    CONTROLLER_START_TURN      /* a turn towards the carrot (controller_turn_start): standing, the carrot behind */
};

/* A bounded SQP inside the period's deadline (counted from t0), from the given start. Its plan replaces
 * the real-time iteration's when it is solved and safe, and, from a step to the side, costs less (the
 * real-time iteration's may be a good plan in another local solution), or, from a turn, ends nearer the
 * carrot (the real-time iteration's stands where the OCP's cost over the horizon cannot tell a turn
 * around from standing); otherwise the real-time iteration's stands (it passed the monitors) and the next
 * period starts cold. Returns 1 when it replaced it. */
static int controller_recover(hm_controller *c, unsigned long long t0, enum controller_start start,
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
static int controller_may_recover(const hm_controller *c, const hm_controller_input *cin,
                                  const hm_controller_output *out)
{
    return !out->recovered && !c->out.stop && c->params.recovery_iterations > 0 &&
           (!c->has_recovery || cin->time - c->time_recovery >= c->params.stall_time);
}

/* controller_recover, its time taken for the pace of controller_may_recover. */
static int controller_recover_paced(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                    enum controller_start start, hm_controller_output *out)
{
    c->has_recovery = 1;
    c->time_recovery = cin->time;
    return controller_recover(c, t0, start, out);
}

/* Braking to a standstill at the goal, or without one: the protective stop's braking plan, which is
 * not a protective stop. */
static void controller_brake(hm_controller *c)
{
    ocp_nlp_clear_output(&c->out);
    ocp_nlp_protective_stop(&c->solver, &c->in, &c->out, HM_STOP_NONE);
    c->out.stop = 0;
    ocp_nlp_sqp_reset(&c->solver);
}

/* 1 once the robot has come within goal_tolerance of this goal (nav2's stateful goal checker): a robot that
 * enters the tolerance at speed brakes to a standstill where the braking carries it (past the tolerance,
 * by at most its braking distance), and turns to the goal's heading there; the plan would otherwise turn
 * back at speed and overshoot again. A new goal ends it. */
static int controller_arriving(hm_controller *c, const hm_controller_goal *g)
{
    if (!(c->arriving && c->arrival_goal[0] == g->final[0] && c->arrival_goal[1] == g->final[1]))
        c->arriving = 0;
    if (g->to_final <= c->params.goal_tolerance) {
        c->arriving = 1;
        c->arrival_goal[0] = g->final[0];
        c->arrival_goal[1] = g->final[1];
    }
    return c->arriving;
}

/* What the robot does within goal_tolerance of its goal (controller_at_goal). */
enum controller_at_goal_state {
    CONTROLLER_GOAL_DONE,    /* the heading is within yaw_goal_tolerance, or there is none to meet: braking */
    CONTROLLER_GOAL_TURNING  /* braking, then turning in place to the goal's heading */
};

/* Within goal_tolerance of a goal pose whose heading is more than yaw_goal_tolerance off: brake, then turn
 * in place towards the heading (the turn rate CONTROLLER_TURN_GAIN times the heading's error, within the
 * turn-rate bounds); someone within d_h holds it in a protective stop (controller_guard). The OCP, cut off
 * at goal_tolerance, would leave the robot facing the way it came (up to 170 degrees off the goal's
 * heading); nav2's goal checkers test the heading too. A path without a goal pose has no heading to meet.
 * c->out: the braking plan, with the turn. */
static enum controller_at_goal_state controller_at_goal(hm_controller *c, const hm_controller_input *cin,
                                                        hm_real heading)
{
    const hm_params *p = &c->params;
    hm_output *o = &c->out;
    hm_real A[HM_NX * HM_NX], B[HM_NX * HM_NU];
    int n;
    controller_brake(c);
    if (cin->has_goal != 1 || !(hm_fabs(heading - c->in.x0[2]) > p->yaw_goal_tolerance)) return CONTROLLER_GOAL_DONE;
    for (n = 0; n < HM_N; n++) {
        /* brake first, then turn: turning while still rolling would swing the robot off the goal */
        const hm_real w = hm_fabs(o->x[n][3]) < CONTROLLER_AT_REST ? CONTROLLER_TURN_GAIN * (heading - o->x[n][2])
                                                                   : HM_R(0.0);
        o->u[n][1] = hm_fmin(hm_fmax(w, p->omega_bounds[0]), p->omega_bounds[1]);
        hm_model_dynamics(o->x[n], o->u[n], o->x[n + 1], A, B);
    }
    o->u0[1] = o->u[0][1];
    o->command[1] = o->u[0][1];
    return CONTROLLER_GOAL_TURNING;
}

/* Progress towards the goal: the distance left must shrink by stall_distance within stall_time; a
 * path that grows (a replanned detour) restarts the measure, not the timer; a protective stop or a
 * new goal restarts both. Returns 1 when stalled; *slow: 1 when the robot has gone slower than half
 * the speed it tracks for stall_time. */
static int controller_progress(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                               int stopped, int *slow, hm_controller_output *out)
{
    const hm_params *p = &c->params;
    const int new_goal = !c->has_goal || hm_fabs(g->final[0] - c->goal_xy[0]) > HM_R(1e-6) ||
                         hm_fabs(g->final[1] - c->goal_xy[1]) > HM_R(1e-6);
    if (new_goal || stopped || !c->has_time || cin->time < c->time_last ||
        cin->v >= HM_R(0.5) * c->in.goal[3])
        c->time_brisk = cin->time;
    *slow = cin->time - c->time_brisk > p->stall_time;
    if (new_goal || stopped || !c->has_time || cin->time < c->time_last) {
        c->best_left = g->left;
        c->time_progress = cin->time;
        c->has_recovery = 0;
    } else if (g->left < c->best_left - p->stall_distance) {
        c->best_left = g->left;
        c->time_progress = cin->time;
    } else if (g->left > c->best_left) {
        c->best_left = g->left;
    }
    c->has_goal = 1;
    c->goal_xy[0] = g->final[0];
    c->goal_xy[1] = g->final[1];
    c->has_time = 1;
    c->time_last = cin->time;
    out->time_without_progress = cin->time - c->time_progress;
    return out->time_without_progress > p->stall_time;
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
        s->params = c->params;
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
     * elsewhere: with people between it and the goal, it circled at cruising speed. */
    {
        const hm_real dx = in->goal[0] - in->x0[0], dy = in->goal[1] - in->x0[1];
        const hm_real len = hm_sqrt(dx * dx + dy * dy);
        if (len > HM_R(1e-9))
            in->goal[3] = hm_fmin(in->goal[3], controller_separation_bound(cin, in->x0, dx / len, dy / len, in->goal[3],
                                                                           &c->params));
    }
    if (c->params.progress) controller_references(c, cin, &g);
    controller_expected_path(s, cin, path);
    controller_select_people(path, cin, &s->params, hm_fmax(hm_fabs(cin->v), s->params.v_bounds[1]), in, out);
    controller_nearest_obstacle(path, cin, c->solver.params.v_bounds[1], in);
    controller_goal_people(c, cin, &g, out);
    t1 = ocp_nlp_now(s);
    ocp_nlp_sqp_rti_step_from(s, in, &c->out, t0);
    chosen = controller_candidates_step(c, t0, out);
    out->time_solver_ms = HM_ELAPSED_MS(ocp_nlp_now(s), t1);
    if (chosen != 0) {
        /* a candidate passes someone: the recoveries are for the main plan's standstills and loops */
        out->stalled = controller_progress(c, cin, &g, c->out.stop, &slow, out);
        if (out->stalled) out->outcome = HM_OUTCOME_STALLED;
        return 0;
    }
    if (!c->out.stop && c->params.recovery_iterations > 0 && controller_is_loop(&c->params, &c->out)) {
        out->loop_detected = 1;
        out->recovered = controller_recover(c, t0, CONTROLLER_START_COLD, out);
    }
    out->stalled = controller_progress(c, cin, &g, c->out.stop, &slow, out);
    if (controller_may_recover(c, cin, out) && controller_stuck_facing_away(c))
        out->recovered = controller_recover_paced(c, cin, t0, CONTROLLER_START_TURN, out);
    if ((out->stalled || slow) && controller_may_recover(c, cin, out))
        out->recovered = controller_recover_paced(c, cin, t0, CONTROLLER_START_SIDEWAYS, out);
    if (out->stalled) out->outcome = HM_OUTCOME_STALLED;
    return 0;
}

HM_FUNC int controller_step(hm_controller *c, const hm_controller_input *cin, hm_controller_output *out)
{
    hm_solver *s = &c->solver;
    hm_input *in = &c->in;
    const unsigned long long t0 = ocp_nlp_now(s);
    controller_clear_output(out);
    in->n_humans = 0;
    in->has_obstacle = 0;
    in->has_refs = 0;
    in->x0[0] = cin->pose[0];
    in->x0[1] = cin->pose[1];
    in->x0[2] = cin->pose[2];
    in->x0[3] = cin->v;
    out->n_tracks_dropped = cin->n_tracks_dropped;
    if (!controller_input_ok(cin) || !monitor_check_params(&c->params)) {
        int i;
        const int reason = monitor_check_params(&c->params) ? HM_STOP_INVALID_INPUT : HM_STOP_INVALID_PARAMS;
        for (i = 0; i < HM_NX; i++) in->goal[i] = in->x0[i];
        s->params = c->params;
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
