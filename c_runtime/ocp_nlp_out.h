/*
 * ocp_nlp_out.h: what a solver step hands back (ocp_nlp_out.c): residuals, the plan or the
 * protective stop, and the safety checks that choose between them.
 */
#ifndef OCP_NLP_OUT_H
#define OCP_NLP_OUT_H

#include "ocp_nlp_common.h"

/* KKT residuals of the NLP at the linearisation point with the multipliers in s->mult, into out. */
HM_FUNC void ocp_nlp_residuals(hm_solver *s, hm_output *out);

/* The plan of s (and the smallest distance of its path to the present humans) into out. */
HM_FUNC void ocp_nlp_report(const hm_solver *s, const hm_input *in, hm_output *out);

/* Protective stop for reason (enum hm_stop_reason): out's plan brakes to standstill; after a failure
 * the next step starts cold. */
HM_FUNC void ocp_nlp_protective_stop(hm_solver *s, const hm_input *in, hm_output *out, int reason);

/* out as before any solving: no stop, status HM_STATUS_SKIPPED, counts and residuals zero. */
HM_FUNC void ocp_nlp_clear_output(hm_output *out);

/* A step's QP counts (qp_solves, qp_rows_max, qp_rows_capped of the solver): zeroed when the step
 * starts (the RTI's feedback, the full SQP), copied into out when it ends. */
HM_FUNC void ocp_nlp_step_counts_reset(hm_solver *s);
HM_FUNC void ocp_nlp_step_counts_report(const hm_solver *s, hm_output *out);

/* The plan after the command guard, or the protective stop of reason (see ocp_nlp_out.c). */
HM_FUNC void ocp_nlp_finish(hm_solver *s, const hm_input *in, hm_output *out, int reason);

/* The checks that come before any solving; returns the stop reason or HM_STOP_NONE. checked_but_x0:
 * the input passed monitor_check_input(in, 0) already in this step (its preparation's), only x0 is
 * checked again. */
HM_FUNC int ocp_nlp_check_before(const hm_solver *s, const hm_input *in, int checked_but_x0);

/* C1 (a finite plan) and C2 on the plan of s; returns the stop reason or HM_STOP_NONE. */
HM_FUNC int ocp_nlp_check_plan(const hm_solver *s, const hm_input *in);

#endif /* OCP_NLP_OUT_H */
