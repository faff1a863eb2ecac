/*
 * ocp_nlp_lin.h: the linearisation of the NLP (ocp_nlp_lin.c): its point and the QP built there.
 */
#ifndef OCP_NLP_LIN_H
#define OCP_NLP_LIN_H

#include "ocp_nlp_cost.h"

/* Initial guess of the next step: the previous plan shifted by one interval (the last control
 * repeated), re-simulated from the predicted state; or, cold, the controls held at zero from x0. */
HM_FUNC void ocp_nlp_shift(hm_solver *s, const hm_input *in);

/* The safe fallback guess: brake to standstill from the measured state, without turning. */
HM_FUNC void ocp_nlp_init_braking(hm_solver *s, const hm_input *in);
/* The guess moved into the bounds of a, omega and v and re-simulated (before a line-search RTI step). */
HM_FUNC void ocp_nlp_project_guess(hm_solver *s);

/* Build the QP of the current iterate (everything but the initial-state offset) and the NLP
 * objective there; exact = 1: the Hessian of the Lagrangian at s->mult, projected onto the PSD cone
 * per stage, else Gauss-Newton. */
HM_FUNC void ocp_nlp_linearize(hm_solver *s, const hm_input *in, int exact);

/* The measured state into the QP, as the offset of its fixed x_0 from the iterate's. */
HM_FUNC void ocp_nlp_set_x0(hm_solver *s, const hm_input *in);

#endif /* OCP_NLP_LIN_H */
