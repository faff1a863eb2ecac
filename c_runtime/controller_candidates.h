/*
 * controller_candidates.h: passing decisions (controller_candidates.c). Beside the main plan (the
 * real-time iteration warm from its own last solution), HM_NCAND - 1 candidate plans each pass one of the
 * people the OCP sees on one side (left, right of the first person, then of the second, ...): each starts
 * from a guide that goes round that person on its side, in every period, and takes one SQP iteration of
 * the same fixed-size solver within the period's deadline. The cheapest plan that passes the monitors and
 * the guard's tests of a moving plan (controller_safety.h) is applied, with hysteresis: another plan
 * replaces the passing decision applied last period (that person on that side, or the main plan) only when
 * it costs less by candidate_hysteresis (a fraction). HM_NCAND = 1:
 * the main plan alone, and nothing here runs.
 *
 * Memory: the candidates are solved one after the other in the main plan's solver, its warm start kept
 * aside meanwhile (ocp_nlp_iterate.h) and put back after them, so that its next period runs bit for bit as
 * it would have; of the candidates' outputs at most three are kept (the cheapest so far, last period's
 * decision, the one being solved). A candidate beyond the first costs a few bytes, not a solver.
 */
#ifndef CONTROLLER_CANDIDATES_H
#define CONTROLLER_CANDIDATES_H
#include "controller_common.h"

/* Forget every candidate's plan and passing decision (a new episode). */
HM_FUNC void controller_candidates_reset(hm_controller *c);

/* After the main plan's real-time iteration into c->out (c->in and the solver's parameters of this
 * period set): solves the candidates and, when one is chosen, copies its plan into c->out. Reports the
 * chosen plan (out->candidate: 0 the main one) and how many plans passed the monitors and the guard's
 * tests of a moving plan (one plan too). Returns the chosen index.
 * t0: the period's first clock reading (the deadline's origin). */
HM_FUNC int controller_candidates_step(hm_controller *c, const hm_controller_input *cin, unsigned long long t0,
                                       hm_controller_output *out);

#endif /* CONTROLLER_CANDIDATES_H */
