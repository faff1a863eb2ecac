/*
 * ocp_nlp_cost.c: the NLP's objective, term by term (ocp_nlp_cost.h): tracking, collision potential,
 * the rows' slack penalties and the speed-and-separation penalty. Stateless.
 * Model functions: the hm_model_* macros of the translation unit (ocp_nlp_common.h).
 */
#include "ocp_nlp_cost.h"

/* The collision potential f(d) = q / (1 + exp(kappa (d - d_th))) is below 1e-10 q beyond
 * d_th + ln(1e10) / kappa (its gradient kappa f and curvature kappa^2 f likewise, relative to kappa
 * and kappa^2): 5.6 m with the default kappa = 5, where f <= 5e-9 against goal terms of order 1 and a
 * QP tolerance of 1e-2 in the cost's units. People farther from a node than that are left out of its
 * cost: with 100 people most of the 5,100 evaluations of an RTI step, each with an exponential.
 * The squared reach; HM_INF: none left out. */
static hm_real ocp_nlp_collision_reach2(const hm_params *p)
{
    const hm_real reach = p->d_th + HM_R(23.025850929940457) / p->kappa;
    return p->kappa > HM_R(0.0) && reach < HM_R(1e6) ? reach * reach : HM_INF;
}

/* 1 when the person at h is within the collision potential's reach (squared, above) of the node at x. */
static int ocp_nlp_collision_near(const hm_real *x, const hm_real *h, hm_real reach2)
{
    const hm_real dx = x[0] - h[0], dy = x[1] - h[1];
    return dx * dx + dy * dy <= reach2;
}

/* Node n's time against the collision potential's horizon, with half a period's slack so that a
 * horizon of k periods keeps node k whatever the rounding of k * dt. */
HM_FUNC int ocp_nlp_collision_node(const hm_params *p, int n)
{
    return HM_R(HM_DT) * ((hm_real)n - HM_R(0.5)) <= p->collision_horizon;
}

HM_FUNC ocp_nlp_terms ocp_nlp_cost_terms(const hm_params *p, const hm_input *in)
{
    ocp_nlp_terms t;
    t.nh = ocp_nlp_clamp_humans(in);
    t.ng = t.nh + (in->has_obstacle ? 1 : 0);
    t.reach2 = ocp_nlp_collision_reach2(p);
    return t;
}

HM_FUNC ocp_nlp_row ocp_nlp_row_of(const hm_params *p, const hm_input *in, int nh, int j)
{
    ocp_nlp_row r;
    const int human = j < nh;
    r.c = human ? in->humans_now[j] : in->obstacle;
    r.d_min = human ? &p->d_h : &p->d_s;
    r.l1 = human ? p->human_slack_l1 : p->slack_l1;
    r.l2 = human ? p->human_slack_l2 : p->slack_l2;
    return r;
}

HM_FUNC hm_real ocp_nlp_cost_tracking(const hm_params *p, const hm_input *in, int n, const hm_real *x,
                                      const hm_real *u, hm_real *gx, hm_real *gu, hm_real *hx, hm_real *hu)
{
    hm_real l;
    if (n < HM_N)
        hm_model_cost_stage(x, u, ocp_nlp_goal_at(in, n), p->w_goal, p->w_control, &l, gx, gu, hx, hu);
    else
        hm_model_cost_terminal(x, ocp_nlp_goal_at(in, n), p->w_goal_terminal, &l, gx, hx);
    return l;
}

HM_FUNC hm_real ocp_nlp_cost_people(const hm_params *p, const hm_input *in, const ocp_nlp_terms *t, int n,
                                    const hm_real *x, int exact, hm_real acc, hm_real *gx, hm_real *hx)
{
    /* the people whose potential this node carries: none beyond the potential's horizon */
    const int nh_cost = ocp_nlp_collision_node(p, n) ? t->nh : 0;
    int j;
    for (j = 0; j < nh_cost; j++) {
        const hm_real *h = in->humans_pred[n][j];
        hm_real f, grad[HM_NPOS], hess_gn[HM_NPOS * HM_NPOS], hess_exact[HM_NPOS * HM_NPOS];
        const hm_real *hess = hess_gn;
        if (in->humans_no_potential[j] == 1 || !ocp_nlp_collision_near(x, h, t->reach2)) continue;
        if (exact) {
            hm_model_cost_collision(x, h, &p->q, &p->d_th, &p->kappa, &f, grad, hess_gn, hess_exact);
            hess = hess_exact;
        } else {
            hm_model_cost_collision_gn(x, h, &p->q, &p->d_th, &p->kappa, &f, grad, hess_gn);
        }
        acc += f;
        if (gx == 0) continue;
        /* exact gradient; the Hessian on the (px, py) block */
        gx[0] += grad[0];
        gx[1] += grad[1];
        hx[0] += hess[0];
        hx[1] += hess[1];
        hx[HM_NX] += hess[2];
        hx[HM_NX + 1] += hess[3];
    }
    return acc;
}

HM_FUNC hm_real ocp_nlp_slack_penalty(hm_real g, hm_real l1, hm_real l2)
{
    /* The slack a row needs at this point: s = max(0, -g). */
    const hm_real sl = g < HM_R(0.0) ? -g : HM_R(0.0);
    return l1 * sl + HM_R(0.5) * l2 * sl * sl;
}

/* 1 when row r cannot need slack at the node x: its plain distance beyond d_min by a millimetre, the
 * smooth distance of the model being at least the plain one (g > 0, a penalty of exactly 0, which the
 * sums need not add: skipping it changes no bit of them). */
static int ocp_nlp_row_slack_free(const hm_real *x, const ocp_nlp_row *r)
{
    const hm_real dx = x[0] - r->c[0], dy = x[1] - r->c[1], near = *r->d_min + HM_R(1e-3);
    return dx * dx + dy * dy > near * near;
}

HM_FUNC hm_real ocp_nlp_separation_penalty(const hm_solver *s)
{
    hm_real excess = HM_R(0.0);
    int n;
    if (!s->params.separation) return HM_R(0.0);
    for (n = 1; n <= HM_N; n++) excess += hm_fmax(s->x[n][3] - s->v_separation[n], HM_R(0.0));
    return s->params.human_slack_l1 * excess;
}

/* The objective of the iterate s->x, s->u without the separation penalty, node by node: tracking, the
 * collision potential (exact: its Hessian flag), and the rows' slack penalties, added into the running sum
 * (rows_apart = 0: the line search's merit) or into a sum of their own added at the end (rows_apart = 1:
 * as ocp_nlp_linearize adds up s->cost). Two orders of the same terms, each its caller's bit for bit. */
static hm_real ocp_nlp_cost_sum(const hm_solver *s, const hm_input *in, int exact, int rows_apart)
{
    const hm_params *p = &s->params;
    const ocp_nlp_terms t = ocp_nlp_cost_terms(p, in);
    hm_real cost = HM_R(0.0), penalty = HM_R(0.0);
    hm_real *rows = rows_apart ? &penalty : &cost;
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        const hm_real *x = s->x[n];
        hm_real gx[HM_NX], hx[HM_NX * HM_NX], gu[HM_NU], hu[HM_NU * HM_NU];
        cost += ocp_nlp_cost_tracking(p, in, n, x, n < HM_N ? s->u[n] : 0, gx, gu, hx, hu);
        cost = ocp_nlp_cost_people(p, in, &t, n, x, exact, cost, 0, 0);
        /* node 0 is the measured state: its rows cannot be acted on */
        if (n == 0) continue;
        for (j = 0; j < t.ng; j++) {
            const ocp_nlp_row r = ocp_nlp_row_of(p, in, t.nh, j);
            hm_real g, jac[HM_NPOS], hess_d[HM_NPOS * HM_NPOS];
            if (ocp_nlp_row_slack_free(x, &r)) continue;   /* adds 0 */
            hm_model_distance_constraint(x, r.c, r.d_min, &g, jac, hess_d);
            *rows += ocp_nlp_slack_penalty(g, r.l1, r.l2);
        }
    }
    return rows_apart ? cost + penalty : cost;
}

HM_FUNC hm_real ocp_nlp_objective(const hm_solver *s, const hm_input *in)
{
    return ocp_nlp_cost_sum(s, in, 0, 0) + ocp_nlp_separation_penalty(s);
}

HM_FUNC hm_real ocp_nlp_plan_cost(const hm_solver *s, const hm_input *in, int exact)
{
    return ocp_nlp_cost_sum(s, in, exact, 1);
}
