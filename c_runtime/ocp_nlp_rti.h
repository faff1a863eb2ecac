/*
 * ocp_nlp_rti.h: the real-time iteration (ocp_nlp_rti.c): one QP per control step, split into a
 * preparation before the measurement and a feedback after it.
 */
#ifndef OCP_NLP_RTI_H
#define OCP_NLP_RTI_H

#include "ocp_nlp_common.h"

/* Linearises around the shifted previous plan; reads everything in `in` except x0 (unless cold). */
HM_FUNC void ocp_nlp_sqp_rti_prepare(hm_solver *s, const hm_input *in);
/* Inserts the measured x0, solves one QP, takes the step (or stops) and fills out; the deadline
 * counts from here. Returns out->status. */
HM_FUNC int ocp_nlp_sqp_rti_feedback(hm_solver *s, const hm_input *in, hm_output *out);
/* prepare + feedback, the deadline counting from the start of the preparation. */
HM_FUNC int ocp_nlp_sqp_rti_step(hm_solver *s, const hm_input *in, hm_output *out);
/* The same, the deadline counting from t0 (a clock reading taken before it): a caller that works before
 * the solver (the controller) spends the same deadline. */
HM_FUNC int ocp_nlp_sqp_rti_step_from(hm_solver *s, const hm_input *in, hm_output *out, unsigned long long t0);

#endif /* OCP_NLP_RTI_H */
