/*
 * controller_progress_checker.c: progress towards the goal (controller_progress_checker.h).
 *
 * A robot that makes no progress while nothing stops it (a local solution in front of a person who does
 * not move) is reported as stalled, and the recoveries (controller_recovery.h) try another start, at most
 * once per stall_time.
 */
#include "controller_progress_checker.h"

#include "controller_goal_checker.h"
#include "ocp_nlp_out.h"

/* Progress towards the goal: the distance left must shrink by stall_distance within stall_time; a
 * path that grows (a replanned detour) restarts the measure, not the timer; a protective stop or a
 * new goal restarts both. Returns 1 when stalled; *slow: 1 when the robot has gone slower than half
 * the speed it tracks for stall_time. */
HM_FUNC int controller_progress(hm_controller *c, const hm_controller_input *cin, const hm_controller_goal *g,
                                int stopped, int *slow, hm_controller_output *out)
{
    const hm_controller_params *p = &c->params;
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

/* 1 when the plan o is nearer the carrot half a horizon on than the robot is now: a plan that starts off
 * sideways or away to go round someone (standing people round a robot facing 94 degrees off its carrot:
 * every period's plan set off eastwards to turn north, and braking it held the robot for 23 s). Not its
 * end: walking along beside a crossing person, the plans put the turn back off to their last nodes. */
static int controller_plan_heads_nearer(const hm_input *in, const hm_output *o)
{
    const hm_real ex = in->goal[0] - o->x[HM_N / 2][0], ey = in->goal[1] - o->x[HM_N / 2][1];
    const hm_real rx = in->goal[0] - in->x0[0], ry = in->goal[1] - in->x0[1];
    return ex * ex + ey * ey < rx * rx + ry * ry;
}

HM_FUNC int controller_stalled_command(hm_controller *c)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_real v = c->out.command[0];
    const hm_real towards = hm_cos(controller_carrot_bearing(in, in->x0));
    const int warm = s->warm;
    if (c->out.stop || !(hm_fabs(v) > CONTROLLER_AT_REST) || v * towards > HM_R(0.0) ||
        controller_plan_heads_nearer(in, &c->out))
        return 0;
    ocp_nlp_protective_stop(s, in, &c->out, HM_STOP_NONE);
    c->out.stop = 0;
    /* the solver keeps its plan: a cold start from the braking state finds the same standstill (measured:
     * braking and starting cold every stalled period held a robot for good) */
    s->warm = warm;
    return 1;
}
