/*
 * ocp_nlp_cost.h: the NLP's objective (ocp_nlp_cost.c), evaluated in one place for the two that need
 * it: the linearisation (value and derivatives, into the QP) and the line search's merit (value).
 * Each term is one function, so what the objective is (which goal and weights a node tracks, which
 * people carry the collision potential there, which rows cost what slack) is written once.
 */
#ifndef OCP_NLP_COST_H
#define OCP_NLP_COST_H

#include "ocp_nlp_common.h"

/* What an input's objective is made of: its present people (the first rows), its rows (people, then
 * the obstacle), and the collision potential's reach, squared (beyond it the potential is below
 * 1e-10 q: ocp_nlp_cost.c). */
typedef struct {
    int nh;
    int ng;
    hm_real reach2;
} ocp_nlp_terms;

HM_FUNC ocp_nlp_terms ocp_nlp_cost_terms(const hm_params *p, const hm_input *in);

/* Row j of an input (j < nh: person j's position now, else the obstacle): its centre, the distance it
 * keeps, and the L1 and L2 weights of its slack. */
typedef struct {
    const hm_real *c;
    const hm_real *d_min;
    hm_real l1;
    hm_real l2;
} ocp_nlp_row;

HM_FUNC ocp_nlp_row ocp_nlp_row_of(const hm_params *p, const hm_input *in, int nh, int j);

/* The tracking cost of node n (stage n < N at x, u; terminal n = N at x, u unused): its value, its
 * gradient gx (and gu) and Hessian hx (and hu), written. */
HM_FUNC hm_real ocp_nlp_cost_tracking(const hm_params *p, const hm_input *in, int n, const hm_real *x,
                                      const hm_real *u, hm_real *gx, hm_real *gu, hm_real *hx, hm_real *hu);

/* The collision potential of node n at x: every present person within its horizon and reach and not
 * exempt (humans_no_potential), at their predicted position. Returns acc with each value added in
 * turn (a caller's running sum, so that every caller adds in the same order); with gx non-null, each
 * gradient and Hessian (exact = 1: exact, else Gauss-Newton) is added to the (px, py) entries of gx
 * and of hx (column-major, HM_NX rows). */
HM_FUNC hm_real ocp_nlp_cost_people(const hm_params *p, const hm_input *in, const ocp_nlp_terms *t, int n,
                                    const hm_real *x, int exact, hm_real acc, hm_real *gx, hm_real *hx);

/* The cost of the slack that a row with value g needs (s = max(0, -g)), penalised by l1 and l2. */
HM_FUNC hm_real ocp_nlp_slack_penalty(hm_real g, hm_real l1, hm_real l2);

/* The exact penalty (human_slack_l1) on the iterate's speeds above the speed-and-separation bounds
 * of the last ocp_nlp_set_x0; 0 without params.separation. */
HM_FUNC hm_real ocp_nlp_separation_penalty(const hm_solver *s);

/* The objective of the iterate s->x, s->u: tracking, collision potential and every row's slack
 * penalty, node by node, and the separation penalty. The linearisation adds up the same terms with
 * their derivatives (its s->cost: the rows' penalties summed apart, screened rows, whose slack is
 * zero, left out). */
HM_FUNC hm_real ocp_nlp_objective(const hm_solver *s, const hm_input *in);

/* The objective of the iterate s->x, s->u as ocp_nlp_linearize adds it up into s->cost (exact: its
 * Hessian flag, which picks the collision potential's evaluation), bit for bit, without the derivatives
 * and without the separation penalty (ocp_nlp_set_x0 adds it): tracking and collision potential node by
 * node, the rows' slack penalties summed apart. A row keeps its slack at zero, adding nothing, when its
 * plain distance is beyond d_min (the smooth distance is at least the plain one), and is not evaluated. */
HM_FUNC hm_real ocp_nlp_plan_cost(const hm_solver *s, const hm_input *in, int exact);

/* 1 when node n is within the collision potential's horizon (params collision_horizon): later nodes
 * carry no collision cost. */
HM_FUNC int ocp_nlp_collision_node(const hm_params *p, int n);

#endif /* OCP_NLP_COST_H */
