/*
 * controller_goal_checker.c: at the goal (controller_goal_checker.h).
 */
#include "controller_goal_checker.h"

#include "monitor.h"
#include "ocp_nlp_lin.h"
#include "ocp_nlp_out.h"
#include "ocp_nlp_rti.h"
#include "ocp_nlp_screen.h"
#include "ocp_nlp_sqp.h"
#include "ocp_qp.h"

/* The turn in place to a goal pose's heading: its rate per radian of the heading's error, within the
 * turn-rate bounds (at 2 per second the error halves in 0.35 s once below the bound's reach). */
#define CONTROLLER_TURN_GAIN HM_R(2.0)

/* Braking to a standstill at the goal, or without one: the protective stop's braking plan, which is
 * not a protective stop. */
HM_FUNC void controller_brake(hm_controller *c)
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
HM_FUNC int controller_arriving(hm_controller *c, const hm_controller_goal *g)
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

/* Within goal_tolerance of a goal pose whose heading is more than yaw_goal_tolerance off: brake, then turn
 * in place towards the heading (the turn rate CONTROLLER_TURN_GAIN times the heading's error, within the
 * turn-rate bounds); someone within d_h holds it in a protective stop (controller_guard). The OCP, cut off
 * at goal_tolerance, would leave the robot facing the way it came (up to 170 degrees off the goal's
 * heading); nav2's goal checkers test the heading too. A path without a goal pose has no heading to meet.
 * c->out: the braking plan, with the turn. */
HM_FUNC enum controller_at_goal_state controller_at_goal(hm_controller *c, const hm_controller_input *cin,
                                                         hm_real heading)
{
    const hm_controller_params *p = &c->params;
    const hm_params *sp = &c->solver.params;
    hm_output *o = &c->out;
    hm_real A[HM_NX * HM_NX], B[HM_NX * HM_NU];
    int n;
    controller_brake(c);
    if (cin->has_goal != 1 || !(hm_fabs(heading - c->in.x0[2]) > p->yaw_goal_tolerance)) return CONTROLLER_GOAL_DONE;
    for (n = 0; n < HM_N; n++) {
        /* brake first, then turn: turning while still rolling would swing the robot off the goal */
        const hm_real w = hm_fabs(o->x[n][3]) < CONTROLLER_AT_REST ? CONTROLLER_TURN_GAIN * (heading - o->x[n][2])
                                                                   : HM_R(0.0);
        o->u[n][1] = hm_fmin(hm_fmax(w, sp->omega_bounds[0]), sp->omega_bounds[1]);
        hm_model_dynamics(o->x[n], o->u[n], o->x[n + 1], A, B);
    }
    o->u0[1] = o->u[0][1];
    o->command[1] = o->u[0][1];
    return CONTROLLER_GOAL_TURNING;
}
