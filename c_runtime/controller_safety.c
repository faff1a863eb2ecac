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

/* The first test of controller_guard that fails, HM_STOP_NONE when all pass. */
static int controller_guard_reason(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                   int braking)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    const hm_output *o = &c->out;
    if (controller_nearest_track(cin, in->x0) < s->params.d_h) return HM_STOP_HUMAN_TOO_CLOSE;
    if (!braking) {
        const hm_real v = o->command[0];
        const hm_real bound = controller_separation_bound(cin, in->x0, hm_cos(in->x0[2]), hm_sin(in->x0[2]), v,
                                                          &s->params);
        if (monitor_separation_exceeded(v, bound, &s->params)) return HM_STOP_SEPARATION;
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
