/*
 * controller_safety.c: the safety decisions of a control period (controller_safety.h).
 */
#include "controller_safety.h"

#include "controller_people.h"
#include "monitor.h"
#include "ocp_nlp_out.h"

HM_FUNC hm_real controller_nearest_track(const hm_controller_input *cin, const hm_real *p)
{
    hm_real best = HM_INF;   /* of the squared distances: one square root */
    int i;
    for (i = 0; i < cin->n_tracks; i++) {
        const hm_real dx = cin->tracks[i][0] - p[0], dy = cin->tracks[i][1] - p[1];
        best = hm_fmin(best, dx * dx + dy * dy);
    }
    return cin->n_tracks > 0 ? hm_sqrt(best) : HM_INF;
}

/* 1 when the robot, following the plan o for the reaction time and then braking along its heading as a
 * stop does, would still be moving when it comes within d_h of the predicted position of one of the people
 * the OCP sees: a stop decided later would come too late, so it is decided now. The speed-and-separation
 * bound sees people ahead only; a person overtaking from behind, and one the robot turns towards, come
 * from elsewhere. */
static int controller_stop_comes_too_late(const hm_solver *s, const hm_input *in, const hm_output *o)
{
    const hm_params *p = &s->params;
    const hm_real d_h2 = p->d_h * p->d_h;
    const int nh = ocp_nlp_clamp_humans(in);
    /* the nodes of the reaction time, rounded up, 1..N (clamped before the cast) */
    const int n_r = (int)hm_fmax(HM_R(1.0), hm_fmin((hm_real)HM_N, p->reaction_time / HM_R(HM_DT) +
                                                                        HM_R(1.0) - HM_R(1e-6)));
    const hm_real *x_r = o->x[n_r];
    const hm_real dir = x_r[3] < HM_R(0.0) ? HM_R(-1.0) : HM_R(1.0);
    /* towards v = 0 at the configured rate of the direction of travel (ocp_nlp_protective_stop) */
    const hm_real a_brake = x_r[3] < HM_R(0.0) ? p->a_bounds[1] : -p->a_bounds[0];
    const hm_real cos_t = dir * hm_cos(x_r[2]), sin_t = dir * hm_sin(x_r[2]);
    hm_real pos[2], v = hm_fabs(x_r[3]);
    int n, j;
    pos[0] = x_r[0];
    pos[1] = x_r[1];
    for (n = 1; n <= HM_N; n++) {
        const hm_real *x = n <= n_r ? o->x[n] : pos;
        if (n > n_r) {
            const hm_real v_next = hm_fmax(v - a_brake * HM_R(HM_DT), HM_R(0.0));
            const hm_real ds = HM_R(0.5) * (v + v_next) * HM_R(HM_DT);
            pos[0] += ds * cos_t;
            pos[1] += ds * sin_t;
            v = v_next;
            if (!(v > HM_R(0.0))) break;   /* at rest: whoever comes nearer comes to a robot that stands */
        } else if (!(hm_fabs(x[3]) > HM_R(0.0))) {
            continue;
        }
        for (j = 0; j < nh; j++) {
            const hm_real dx = x[0] - in->humans_pred[n][j][0], dy = x[1] - in->humans_pred[n][j][1];
            if (dx * dx + dy * dy < d_h2) return 1;
        }
    }
    return 0;
}

HM_FUNC int controller_moving_plan_reason(const hm_controller *c, const hm_controller_input *cin, const hm_output *o)
{
    const hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_real v = o->command[0];
    const hm_real bound = controller_separation_bound(cin, in->x0, hm_cos(in->x0[2]), hm_sin(in->x0[2]), v,
                                                      &s->params);
    if (monitor_separation_exceeded(v, bound, &s->params)) return HM_STOP_SEPARATION;
    if (s->params.separation && controller_stop_comes_too_late(s, in, o)) return HM_STOP_PREDICTED_CONTACT;
    return HM_STOP_NONE;
}

/* The first test of controller_guard that fails, HM_STOP_NONE when all pass. */
static int controller_guard_reason(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                   int braking)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_output *o = &c->out;
    if (controller_nearest_track(cin, in->x0) < s->params.d_h) return HM_STOP_HUMAN_TOO_CLOSE;
    if (!braking) {
        const int reason = controller_moving_plan_reason(c, cin, o);
        if (reason != HM_STOP_NONE) return reason;
    }
    {
        /* the bounds in force: the period's solver parameters, with the speed limit (without a goal the
         * solver's are the caller's, uncapped; with one, v_bounds[1] is capped already, at most the caller's) */
        hm_params bounds = s->params;
        const hm_real cap = hm_fmin(s->params.v_bounds[1], c->params.speed_limit);
        if (cap > bounds.v_bounds[0]) bounds.v_bounds[1] = hm_fmin(bounds.v_bounds[1], cap);
        if (!monitor_command_ok(&bounds, o)) return HM_STOP_COMMAND_BOUNDS;
    }
    ocp_nlp_start_clock(s, t0);
    if (ocp_nlp_deadline_passed(s)) return HM_STOP_DEADLINE;
    return HM_STOP_NONE;
}

HM_FUNC void controller_guard(hm_controller *c, const hm_controller_input *cin, unsigned long long t0, int braking)
{
    int reason;
    if (c->out.stop) return;
    reason = controller_guard_reason(c, cin, t0, braking);
    if (reason != HM_STOP_NONE) ocp_nlp_protective_stop(&c->solver, &c->in, &c->out, reason);
}
