/*
 * monitor.c: the safety monitor's tests (see monitor.h): input and parameter checks and the distance
 * of the robot to the humans now, stateless, called before and after every solver step. The
 * protective stop itself and the C1/C2 decisions are in ocp_nlp_out.c, where the solver's state is.
 */
#include "monitor.h"

HM_FUNC int monitor_finite(hm_real v)
{
    /* v - v is 0 for finite v and NaN for NaN or infinity; no isfinite(), which C99 freestanding
     * targets may lack for float. */
    return (v - v) == (v - v);
}

HM_FUNC int monitor_position_ok(const hm_real *p)
{
    return monitor_finite(p[0]) && monitor_finite(p[1]) && hm_fabs(p[0]) <= HM_MONITOR_MAX_POSITION &&
           hm_fabs(p[1]) <= HM_MONITOR_MAX_POSITION;
}

static int monitor_state_ok(const hm_real *x)
{
    return monitor_position_ok(x) && monitor_finite(x[2]) && monitor_finite(x[3]) &&
           hm_fabs(x[2]) <= HM_MONITOR_MAX_ANGLE && hm_fabs(x[3]) <= HM_MONITOR_MAX_SPEED;
}

/* A person's velocity: finite, each component within HM_MONITOR_MAX_SPEED (a comparison with NaN is
 * false). */
static int monitor_velocity_ok(const hm_real *v)
{
    return hm_fabs(v[0]) <= HM_MONITOR_MAX_SPEED && hm_fabs(v[1]) <= HM_MONITOR_MAX_SPEED;
}

/* The present humans' predicted positions, in one sweep without early exits (the step checks
 * (N + 1) N_h of them, twice): a comparison with NaN or an infinity is false, so the range test
 * alone also rejects non-finite entries. */
static int monitor_predictions_ok(const hm_input *in)
{
    int n, j, bad = 0;
    for (n = 0; n <= HM_N; n++) {
        for (j = 0; j < in->n_humans; j++) {
            const hm_real *p = in->humans_pred[n][j];
            bad |= !(hm_fabs(p[0]) <= HM_MONITOR_MAX_POSITION) | !(hm_fabs(p[1]) <= HM_MONITOR_MAX_POSITION);
        }
    }
    return !bad;
}

/* 1 when every input that takes part in the step is usable. check_x0 = 0 for the preparation
 * phase, which runs before the measurement. Entries of absent humans are not read. */
HM_FUNC int monitor_check_input(const hm_input *in, int check_x0)
{
    int j;
    if (check_x0 && !monitor_state_ok(in->x0)) return 0;
    if (!monitor_state_ok(in->goal)) return 0;
    if (in->has_refs != 0 && in->has_refs != 1) return 0;
    if (in->has_refs) {
        int n;
        for (n = 0; n <= HM_N; n++)
            if (!monitor_state_ok(in->refs[n])) return 0;
    }
    if (in->n_humans < 0 || in->n_humans > HM_NG - 1) return 0;
    if (in->has_obstacle != 0 && in->has_obstacle != 1) return 0;
    if (in->has_obstacle && !monitor_position_ok(in->obstacle)) return 0;
    for (j = 0; j < in->n_humans; j++)
        if (!monitor_position_ok(in->humans_now[j]) || !monitor_velocity_ok(in->humans_vel[j])) return 0;
    return monitor_predictions_ok(in);
}

/* 1 when the runtime parameters keep the rules of the parameter table (see monitor.h). */
HM_FUNC int monitor_check_params(const hm_params *p)
{
    return hm_params_check(p) == 0;
}

/* Distance from the robot now to the closest present human (HM_INF when none). */
HM_FUNC hm_real monitor_distance_now(const hm_input *in)
{
    hm_real best = HM_INF;
    int j;
    for (j = 0; j < in->n_humans; j++) {
        const hm_real dx = in->x0[0] - in->humans_now[j][0];
        const hm_real dy = in->x0[1] - in->humans_now[j][1];
        const hm_real d = hm_sqrt(dx * dx + dy * dy);
        if (d < best) best = d;
    }
    return best;
}

/* The stopping reach, d_h + v_cap t_r + v_cap^2 / 2a + speed_h (t_r + v_cap / a): the farthest a person
 * closing at speed_h can be and still bound a speed up to v_cap. Its terms that do not depend on the
 * person (*reach0, and *per_speed, the reach per m/s of theirs) are taken once for many people. */
static void monitor_separation_reach(hm_real d_h, hm_real t_r, hm_real a_brake, hm_real v_cap, hm_real *reach0,
                                     hm_real *per_speed)
{
    *reach0 = d_h + v_cap * t_r + v_cap * v_cap / (HM_R(2.0) * a_brake);
    *per_speed = t_r + v_cap / a_brake;
}

HM_FUNC hm_real monitor_stopping_reach(hm_real d_h, hm_real t_r, hm_real a_brake, hm_real v_cap, hm_real speed_h)
{
    hm_real reach0, per_speed;
    monitor_separation_reach(d_h, t_r, a_brake, v_cap, &reach0, &per_speed);
    return reach0 + speed_h * per_speed;
}

/* 1 when the person at (dx, dy) from the robot is ahead of its heading: only they bound its speed. */
static int monitor_separation_ahead(hm_real cos_t, hm_real sin_t, hm_real dx, hm_real dy)
{
    return cos_t * dx + sin_t * dy > HM_R(0.0);
}

/* 1 when the person at (dx, dy), velocity vh, is beyond the stopping reach: even v_cap, with their
 * whole speed towards the robot, keeps the separation. Most people are: no root for them. */
static int monitor_separation_far(hm_real dx, hm_real dy, const hm_real *vh, hm_real reach0, hm_real per_speed)
{
    const hm_real reach = reach0 + hm_sqrt(vh[0] * vh[0] + vh[1] * vh[1]) * per_speed;
    return dx * dx + dy * dy >= reach * reach;
}

/* The largest speed for a person ahead and within reach, at (dx, dy) from the robot (see monitor.h). */
static hm_real monitor_separation_root(hm_real cos_t, hm_real sin_t, hm_real dx, hm_real dy, const hm_real *vh,
                                       hm_real d_h, hm_real t_r, hm_real a_brake)
{
    const hm_real d = hm_sqrt(dx * dx + dy * dy);
    const hm_real cos_phi = (cos_t * dx + sin_t * dy) / d;
    hm_real c = -(vh[0] * dx + vh[1] * dy) / d, alpha, beta, gamma;
    if (c < HM_R(0.0)) c = HM_R(0.0);
    /* alpha v^2 + beta v + gamma <= 0, gamma < 0 for a bound above 0: its positive root, written
     * without the cancellation of -beta + sqrt(...) */
    alpha = cos_phi / (HM_R(2.0) * a_brake);
    beta = cos_phi * t_r + c / a_brake;
    gamma = c * t_r - (d - d_h);
    if (!(gamma < HM_R(0.0))) return HM_R(0.0);
    return HM_R(-2.0) * gamma / (beta + hm_sqrt(beta * beta - HM_R(4.0) * alpha * gamma));
}

HM_FUNC hm_real monitor_separation_speed(const hm_real *p, hm_real cos_t, hm_real sin_t, const hm_real *h,
                                         const hm_real *vh, hm_real d_h, hm_real t_r, hm_real a_brake,
                                         hm_real v_cap)
{
    const hm_real dx = h[0] - p[0], dy = h[1] - p[1];
    hm_real reach0, per_speed;
    if (!monitor_separation_ahead(cos_t, sin_t, dx, dy)) return HM_INF;
    monitor_separation_reach(d_h, t_r, a_brake, v_cap, &reach0, &per_speed);
    if (monitor_separation_far(dx, dy, vh, reach0, per_speed)) return HM_INF;
    return monitor_separation_root(cos_t, sin_t, dx, dy, vh, d_h, t_r, a_brake);
}

HM_FUNC hm_real monitor_separation_bound(const hm_input *in, const hm_params *p, const hm_real *x, int n,
                                         hm_real v_cap)
{
    const hm_real cos_t = hm_cos(x[2]), sin_t = hm_sin(x[2]);
    const hm_real a_brake = -p->a_bounds[0], t_r = p->reaction_time;
    hm_real bound = HM_INF, reach0, per_speed;
    int j;
    /* monitor_separation_speed for each person, with the reach's divisions taken once per call and the
     * velocity's two only for the people ahead */
    monitor_separation_reach(p->d_h, t_r, a_brake, v_cap, &reach0, &per_speed);
    for (j = 0; j < ocp_nlp_clamp_humans(in); j++) {
        const hm_real *h = n == 0 ? in->humans_now[j] : in->humans_pred[n][j];
        const hm_real *vh = in->humans_vel[j];
        const hm_real dx = h[0] - x[0], dy = h[1] - x[1];
        if (!monitor_separation_ahead(cos_t, sin_t, dx, dy)) continue;
        if (monitor_separation_far(dx, dy, vh, reach0, per_speed)) continue;
        bound = hm_fmin(bound, monitor_separation_root(cos_t, sin_t, dx, dy, vh, p->d_h, t_r, a_brake));
    }
    return bound;
}

HM_FUNC int monitor_separation_exceeded(hm_real v, hm_real bound, const hm_params *p)
{
    const hm_real tol = HM_R(1e-6) + p->qp_tol;
    return v > tol && v > bound + tol;
}

HM_FUNC int monitor_check_separation(const hm_input *in, const hm_params *p, hm_real v)
{
    return !p->separation || !monitor_separation_exceeded(v, monitor_separation_bound(in, p, in->x0, 0, v), p);
}

HM_FUNC const char *monitor_stop_reason_message(int reason)
{
    switch (reason) {
        HM_STOP_REASON_TABLE(HM_STATUS_CASE_ROW)
    default:
        return "unknown stop reason";
    }
}

static int monitor_within(hm_real x, const hm_real *bounds)
{
    /* false for NaN: the comparisons fail */
    return x >= bounds[0] - HM_MONITOR_COMMAND_TOL * (HM_R(1.0) + hm_fabs(bounds[0])) &&
           x <= bounds[1] + HM_MONITOR_COMMAND_TOL * (HM_R(1.0) + hm_fabs(bounds[1]));
}

HM_FUNC int monitor_command_ok(const hm_params *p, const hm_output *out)
{
    return monitor_within(out->command[0], p->v_bounds) && monitor_within(out->command[1], p->omega_bounds) &&
           monitor_within(out->u0[0], p->a_bounds) && monitor_within(out->u0[1], p->omega_bounds);
}

HM_FUNC int monitor_state_follows(const hm_params *p, const hm_real *x_last, const hm_real *x)
{
    const hm_real dt2 = HM_R(2.0) * HM_R(HM_DT);
    const hm_real v_max = hm_fmax(hm_fmax(hm_fabs(p->v_bounds[0]), hm_fabs(p->v_bounds[1])),
                                  hm_fmax(hm_fabs(x_last[3]), hm_fabs(x[3])));
    const hm_real a_max = hm_fmax(hm_fabs(p->a_bounds[0]), hm_fabs(p->a_bounds[1]));
    const hm_real dx = x[0] - x_last[0], dy = x[1] - x_last[1];
    const hm_real reach = dt2 * v_max + HM_MONITOR_JUMP_POSITION;
    return dx * dx + dy * dy <= reach * reach && hm_fabs(x[3] - x_last[3]) <= dt2 * a_max + HM_MONITOR_JUMP_SPEED;
}

HM_FUNC int monitor_check_state(const hm_real *x)
{
    return monitor_state_ok(x);
}
