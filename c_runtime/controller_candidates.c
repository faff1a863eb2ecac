/*
 * controller_candidates.c: passing decisions (controller_candidates.h).
 *
 * A real-time iteration improves the plan it had: in front of a person who stands on the robot's line, or
 * beside one who crosses at the robot's own speed, that plan waits or walks along, and no single
 * warm-started iteration reaches the plan that passes (de Groot et al., T-MPC: plans in different
 * homotopy classes, optimised in parallel). Our step costs a fraction of a millisecond, so the period
 * affords several.
 */
#include "controller_candidates.h"

#include "controller_safety.h"

#include "ocp_nlp_iterate.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_rti.h"
#include "ocp_nlp_screen.h"
#include "ocp_nlp_sqp.h"
#include "ocp_qp.h"

/* The guide's clearance beyond the potential's half-height distance d_th [m], and its pursuit: the turn
 * rate per radian of bearing, the nodes it looks ahead along the route after the person. */
#define CANDIDATE_CLEARANCE HM_R(0.3)
#define CANDIDATE_TURN_GAIN HM_R(2.0)
#define CANDIDATE_LOOKAHEAD 5
/* SQP iterations from a guide (a guide is no solution: one iteration leaves it far from one). */
#define CANDIDATE_SEED_ITERATIONS 1
/* The screening radius of a candidate's rows at every node [m], below the cold start's (the robot's reach,
 * 5.5 m by the horizon's end, whose QPs held 217 rows at 30 people against the main plan's 55): the step
 * from a guide moves its nodes far less, and a row the step violates joins the QP all the same
 * (ocp_nlp_screen.c), so the radius changes the work, not the solution. */
#define CANDIDATE_SCREEN_RADIUS HM_R(1.5)

/* 1 when a plan may be applied: no stop, its QP solved, and the guard's tests of a moving plan passed (a
 * plan the guard would stop is no choice while another passes: in a crowd the cheapest plan was stopped
 * in time and the people walked into the robot at rest while a plan that stepped aside passed). */
static int candidate_usable(const hm_controller *c, const hm_controller_input *cin, const hm_output *o)
{
    return !o->stop && o->qp_status == HM_QP_SOLVED && controller_moving_plan_reason(c, cin, o) == HM_STOP_NONE;
}

#if HM_NCAND > 1

/* The route's point at node n: the per-node goal (the progress objective), else the carrot approached at
 * the speed to track. */
static void candidate_route(const hm_input *in, int n, hm_real *p)
{
    if (in->has_refs) {
        p[0] = in->refs[n][0];
        p[1] = in->refs[n][1];
    } else {
        const hm_real dx = in->goal[0] - in->x0[0], dy = in->goal[1] - in->x0[1];
        const hm_real len = hm_sqrt(dx * dx + dy * dy);
        const hm_real f = len > HM_R(1e-9) ? hm_fmin(HM_R(1.0), hm_fmax(in->goal[3], HM_R(0.3)) * HM_R(HM_DT) *
                                                                     (hm_real)n / len)
                                          : HM_R(0.0);
        p[0] = in->x0[0] + f * dx;
        p[1] = in->x0[1] + f * dy;
    }
}

/* A guide round person j on side `side` (+1 left, -1 right of the route), simulated by the model from
 * the measured state into s->x, s->u: pursue a waypoint beside the person where the route comes nearest
 * to their prediction, then the route a few nodes ahead. */
static void candidate_guide(hm_solver *s, const hm_input *in, int j, hm_real side)
{
    const hm_params *p = &s->params;
    hm_real best = HM_INF, way[2], a[2], b[2], tx, ty, len;
    int n, i, m = 0, passed = 0;
    for (n = 0; n <= HM_N; n++) {
        hm_real r[2];
        candidate_route(in, n, r);
        {
            const hm_real dx = r[0] - in->humans_pred[n][j][0], dy = r[1] - in->humans_pred[n][j][1];
            const hm_real d2 = dx * dx + dy * dy;
            if (d2 < best) {
                best = d2;
                m = n;
            }
        }
    }
    candidate_route(in, m > 0 ? m - 1 : 0, a);
    candidate_route(in, m < HM_N ? m + 1 : HM_N, b);
    tx = b[0] - a[0];
    ty = b[1] - a[1];
    len = hm_sqrt(tx * tx + ty * ty);
    if (len < HM_R(1e-6)) {
        tx = hm_cos(in->x0[2]);
        ty = hm_sin(in->x0[2]);
    } else {
        tx /= len;
        ty /= len;
    }
    {
        const hm_real c = hm_fmax(p->d_th, p->d_h) + CANDIDATE_CLEARANCE;
        way[0] = in->humans_pred[m][j][0] - side * ty * c;
        way[1] = in->humans_pred[m][j][1] + side * tx * c;
    }
    for (i = 0; i < HM_NX; i++) s->x[0][i] = in->x0[i];
    for (n = 0; n < HM_N; n++) {
        const hm_real *x = s->x[n];
        hm_real target[2], e, v_want;
        if (!passed && (n >= m || (x[0] - way[0]) * (x[0] - way[0]) + (x[1] - way[1]) * (x[1] - way[1]) <
                                       HM_R(0.25)))
            passed = 1;
        if (passed) {
            candidate_route(in, n + CANDIDATE_LOOKAHEAD < HM_N ? n + CANDIDATE_LOOKAHEAD : HM_N, target);
        } else {
            target[0] = way[0];
            target[1] = way[1];
        }
        e = hm_atan2(target[1] - x[1], target[0] - x[0]) - x[2];
        e = hm_atan2(hm_sin(e), hm_cos(e));
        v_want = hm_fmax(in->has_refs ? in->refs[n][3] : in->goal[3], HM_R(0.3)) * hm_fmax(hm_cos(e), HM_R(0.0));
        v_want = hm_fmin(hm_fmax(v_want, p->v_bounds[0]), p->v_bounds[1]);
        s->u[n][0] = hm_fmin(hm_fmax((v_want - x[3]) / HM_R(HM_DT), p->a_bounds[0]), p->a_bounds[1]);
        s->u[n][1] = hm_fmin(hm_fmax(CANDIDATE_TURN_GAIN * e, p->omega_bounds[0]), p->omega_bounds[1]);
        hm_model_dynamics(s->x[n], s->u[n], s->x[n + 1], s->qp.A[n], s->qp.B[n]);
    }
    s->dyn_fresh = 1;
    ocp_qp_sol_set_zero(&s->mult);
    ocp_nlp_screen_reach(s);
    for (n = 0; n <= HM_N; n++) s->screen_radius[n] = hm_fmin(s->screen_radius[n], CANDIDATE_SCREEN_RADIUS);
    s->warm = 1;
}

HM_FUNC void controller_candidates_reset(hm_controller *c)
{
    c->chosen_id = -1;
    c->chosen_side = 0;
}

/* An output buffer that holds neither the cheapest usable plan so far nor the last decision's (their
 * candidate indices best and last, 0 or -1 for none in a buffer): of three, one is always free. */
static int candidate_free_buffer(const int *buffer, int best, int last)
{
    int b;
    for (b = 0;; b++)
        if (!(best > 0 && buffer[best] == b) && !(last > 0 && buffer[last] == b)) return b;
}

HM_FUNC int controller_candidates_step(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                       hm_controller_output *out)
{
    hm_solver *s = &c->solver;
    const hm_input *in = &c->in;
    /* its QP to params.qp_tol, the main plan's (the line search's QP: to min(qp_tol, 0.1 tol)) */
    const hm_real tol = HM_R(10.0) * s->params.qp_tol;
    int usable[HM_NCAND], id[HM_NCAND], side[HM_NCAND], buffer[HM_NCAND];
    hm_real cost[HM_NCAND];
    int k, best = -1, last = -1, ok = 0, kept = 0;
    for (k = 0; k < HM_NCAND; k++) {
        const int j = (k - 1) / 2;
        usable[k] = 0;
        cost[k] = HM_INF;
        buffer[k] = -1;
        side[k] = k == 0 ? 0 : (k - 1) % 2 == 0 ? 1 : -1;
        id[k] = k == 0 ? -1 : j < in->n_humans ? out->people_ids[j] : -1;
        if (k == 0) {
            usable[0] = candidate_usable(c, cin, &c->out);
            cost[0] = c->out.cost;
        } else if (j < in->n_humans && c->params.passing) {
            if (!kept) {
                /* the main plan's warm start, for its next period: the candidates use its solver */
                ocp_nlp_iterate_save(s, &c->main_kept);
                kept = 1;
            }
            buffer[k] = candidate_free_buffer(buffer, best, last);
            /* from its guide in every period: warm from its own last plan, a candidate drifted into the main
             * plan's standstills (walking along beside a crossing person: 16 of 32 crossings missed the goal
             * in time, none from the guide). From the measured state, so the solver's jump test compares it
             * with this period's (the main plan's): a candidate's own last one, from the last period it ran,
             * refused it in the first period of an episode and after periods without it. */
            ocp_nlp_sqp_reset(s);
            candidate_guide(s, in, j, (hm_real)side[k]);
            ocp_nlp_sqp_candidate_step(s, in, &c->candidate_out[buffer[k]], CANDIDATE_SEED_ITERATIONS, tol, t0);
            usable[k] = candidate_usable(c, cin, &c->candidate_out[buffer[k]]);
            cost[k] = c->candidate_out[buffer[k]].cost;
        }
        /* in the order of the indices, as over all of them at the end: the first of the lowest cost, the
         * last of the decision applied last period */
        ok += usable[k];
        if (usable[k] && (best < 0 || cost[k] < cost[best])) best = k;
        if (usable[k] && id[k] == c->chosen_id && side[k] == c->chosen_side) last = k;
    }
    if (kept) ocp_nlp_iterate_restore(s, &c->main_kept);
    /* hysteresis: the passing decision applied last period (the same person on the same side, or the main
     * plan) stays unless another plan costs less by the fraction */
    if (best >= 0 && last >= 0 && last != best &&
        !(cost[best] < (HM_R(1.0) - c->params.candidate_hysteresis) * cost[last]))
        best = last;
    if (best < 0) best = 0;   /* none usable: the main plan's stop stands */
    if (best > 0) c->out = c->candidate_out[buffer[best]];
    c->chosen_id = id[best];
    c->chosen_side = side[best];
    out->candidate = best;
    out->candidates_ok = ok;
    return best;
}

#else /* HM_NCAND == 1: the main plan alone */

HM_FUNC void controller_candidates_reset(hm_controller *c)
{
    c->chosen_id = -1;
    c->chosen_side = 0;
}

HM_FUNC int controller_candidates_step(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                       hm_controller_output *out)
{
    (void)t0;
    out->candidate = 0;
    out->candidates_ok = candidate_usable(c, cin, &c->out);
    return 0;
}

#endif
