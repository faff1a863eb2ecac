/*
 * controller_objective.c: the OCP's objective for one period (controller_objective.h).
 *
 * Why each piece (measured in the evaluation, docs/evaluation.md):
 * - the progress objective: a speed to track pays for speed in any direction, and beside a person who
 *   crosses at the robot's own speed walking along with them was a local optimum; goals per node along
 *   the path at the cruising speed make motion that does not bring the robot along its path cost.
 * - the speed taper (the paper's objective): the OCP tracks v_ref, and with a constant v_ref the robot
 *   circles its goal at cruising speed; the speed it tracks is at most goal_taper times the distance left.
 * - the approach (the paper's objective): once the horizon reaches the goal, a speed to track over all of
 *   it makes the plan loop around the goal to spend its length; the approach drops that weight, weighs the
 *   position at every node and asks for the goal at rest.
 * - both end the collision potential at the robot's earliest arrival (plus arrival_margin): predictions
 *   of people crossing the goal after the robot has stopped there held it short of the goal.
 */
#include "controller_objective.h"

#include "controller_path.h"

/* Slower than this a person counts as standing [m/s]. */
#define CONTROLLER_STANDING HM_R(0.2)

/* The end of the collision potential near the goal: the robot's earliest arrival within goal_tolerance from
 * rest (at v_ref or the speed cap, whichever is lower, reached at the upper acceleration bound) plus
 * arrival_margin, or the caller's collision_horizon when that is sooner. */
static hm_real controller_arrival(const hm_controller_params *p, const hm_params *sp, hm_real caller_horizon,
                                  const hm_controller_goal *g)
{
    const hm_real v_arrive = hm_fmin(p->v_ref, sp->v_bounds[1]);
    const hm_real arrival = hm_fmax(g->left - p->goal_tolerance, HM_R(0.0)) / v_arrive +
                            v_arrive / (HM_R(2.0) * sp->a_bounds[1]) + p->arrival_margin;
    return hm_fmin(caller_horizon, arrival);
}

HM_FUNC void controller_caller_keep(const hm_controller *c, controller_caller_params *caller)
{
    const hm_params *sp = &c->solver.params;
    int i;
    for (i = 0; i < HM_NX; i++) {
        caller->w_goal[i] = sp->w_goal[i];
        caller->w_goal_terminal[i] = sp->w_goal_terminal[i];
    }
    caller->v_max = sp->v_bounds[1];
    caller->collision_horizon = sp->collision_horizon;
}

HM_FUNC void controller_caller_restore(hm_controller *c, const controller_caller_params *caller)
{
    hm_params *sp = &c->solver.params;
    int i;
    for (i = 0; i < HM_NX; i++) {
        sp->w_goal[i] = caller->w_goal[i];
        sp->w_goal_terminal[i] = caller->w_goal_terminal[i];
    }
    sp->v_bounds[1] = caller->v_max;
    sp->collision_horizon = caller->collision_horizon;
}

/* The solver's parameters for this period: the caller's (c->solver.params holds them when the period
 * starts; controller_caller_restore puts them back when it ends), with the speed limit and, within the
 * horizon's reach of the goal, the approach weights and the collision potential's end. Sets the goal's
 * speed (in->goal[3]). */
HM_FUNC void controller_solver_params(hm_controller *c, const hm_controller_goal *g)
{
    const hm_controller_params *p = &c->params;
    hm_params *sp = &c->solver.params;
    const hm_real horizon = HM_R(HM_DT) * (hm_real)HM_N;
    const hm_real cap = hm_fmin(sp->v_bounds[1], p->speed_limit);
    const hm_real caller_horizon = sp->collision_horizon;
    if (cap > sp->v_bounds[0]) sp->v_bounds[1] = cap;
    if (p->progress) {
        /* the per-node goals brake to the goal themselves (controller_references): no taper, no approach
         * weights; the potential's end at the earliest arrival as in the approach (below) */
        int i;
        for (i = 0; i < HM_NX; i++) sp->w_goal[i] = p->progress_weights[i];
        c->in.goal[3] = p->v_ref;
        if (g->left < p->v_ref * horizon) sp->collision_horizon = controller_arrival(p, sp, caller_horizon, g);
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
        sp->collision_horizon = controller_arrival(p, sp, caller_horizon, g);
    }
}

/* Where a straight path to a goal pose given alone starts: with the progress objective, where the robot
 * was when it got that goal (the line must not move with the robot, or walking off sideways would cost
 * nothing); else the robot itself (the carrot of the paper's objective). */
HM_FUNC const hm_real *controller_origin(hm_controller *c, const hm_controller_input *cin)
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

/* The lead of the progress objective's goals. They start at the robot's projection, so node n's pull grows
 * with n: beside people standing ahead the collision potential outweighs it on the first nodes, and a plan
 * that stands for a node and then goes is planned again in every period while the robot stands for good.
 * While the robot has gone slower than half its speed to track for CONTROLLER_LEAD_WAIT and everyone within
 * CONTROLLER_LEAD_NEAR of it stands, the goals go on without it: the lead grows by the way it falls behind
 * that speed, up to that speed times CONTROLLER_LEAD_TIME; otherwise it decays with that time constant. Not
 * while someone near walks: there waiting is the way through, and a lead that pulls the robot on lets
 * social-force people walk into it. The values were chosen on tuning seeds (docs/evaluation.md, "How the
 * defaults were chosen"). */
#define CONTROLLER_LEAD_TIME HM_R(2.0)   /* s */
#define CONTROLLER_LEAD_WAIT HM_R(2.0)   /* s */
#define CONTROLLER_LEAD_NEAR HM_R(2.0)   /* m */
/* Longer than this between periods [s], or a new goal: the lead starts again from 0. */
#define CONTROLLER_LEAD_GAP HM_R(0.5)

/* 1 when everyone tracked within CONTROLLER_LEAD_NEAR of the robot stands. */
static int controller_near_people_stand(const hm_controller_input *cin)
{
    const hm_real near2 = CONTROLLER_LEAD_NEAR * CONTROLLER_LEAD_NEAR;
    const hm_real standing2 = CONTROLLER_STANDING * CONTROLLER_STANDING;
    int i;
    for (i = 0; i < cin->n_tracks; i++) {
        const hm_real *t = cin->tracks[i];
        const hm_real dx = t[0] - cin->pose[0], dy = t[1] - cin->pose[1];
        if (dx * dx + dy * dy < near2 && t[2] * t[2] + t[3] * t[3] >= standing2) return 0;
    }
    return 1;
}

/* This period's lead (above), from the last period's and the way the robot made since along the path to
 * the goal g, v the speed to track. */
static hm_real controller_lead(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                               hm_real v)
{
    const hm_real dt = cin->time - c->lead_time;
    hm_real lead = HM_R(0.0);
    if (c->has_lead && dt >= HM_R(0.0) && dt <= CONTROLLER_LEAD_GAP && c->lead_goal[0] == g->final[0] &&
        c->lead_goal[1] == g->final[1]) {
        const int waits = cin->time - c->time_brisk > CONTROLLER_LEAD_WAIT && controller_near_people_stand(cin);
        lead = waits ? c->lead + v * dt - (c->lead_left - g->left) : c->lead - c->lead * dt / CONTROLLER_LEAD_TIME;
    }
    lead = hm_fmin(hm_fmax(lead, HM_R(0.0)), hm_fmin(g->left, v * CONTROLLER_LEAD_TIME));
    c->has_lead = 1;
    c->lead = lead;
    c->lead_left = g->left;
    c->lead_time = cin->time;
    c->lead_goal[0] = g->final[0];
    c->lead_goal[1] = g->final[1];
    return lead;
}

/* The progress objective's goal per node (params.progress): node n's goal is the point of the path where
 * a robot that started at its projection now, plus the lead (above), would be at node n's time, going at
 * the speed to track (in->goal[3]: the cruising speed, lowered by speed and separation; not the measured
 * speed, from which a standing robot's goals would move off too slowly to ever start it) and braking at half
 * the lower bound to arrive at the goal at rest; heading: the path's there; speed: that speed. Motion that
 * does not bring the robot along its path falls behind these goals and costs; so does standing, once they
 * have moved on. Sets in->refs and in->has_refs, and c->lead. */
HM_FUNC void controller_references(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g)
{
    hm_input *in = &c->in;
    const hm_params *sp = &c->solver.params;
    const hm_real dt = HM_R(HM_DT), a_down = HM_R(-0.5) * sp->a_bounds[0];
    const hm_real *origin = controller_origin(c, cin);
    hm_real v = in->goal[3], d = controller_lead(c, cin, g, in->goal[3]);
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
HM_FUNC void controller_goal_people(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
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
