/*
 * ocp_nlp_step.h: the step of an SQP iteration from its QP (ocp_nlp_step.c).
 */
#ifndef OCP_NLP_STEP_H
#define OCP_NLP_STEP_H

#include "ocp_nlp_common.h"

/* Solve the QP (ocp_nlp_qp_solve); when usable, take the full step (real-time iteration). */
HM_FUNC int ocp_nlp_qp_step(hm_solver *s, const hm_input *in, int shifted, int *qp_iter);

/* Solve the QP to a tolerance below tol; when usable, a step with a backtracking line search on the
 * l1 merit. */
HM_FUNC int ocp_nlp_qp_line_search_step(hm_solver *s, const hm_input *in, hm_real tol, int shifted,
                                        int *qp_iter);

#endif /* OCP_NLP_STEP_H */
