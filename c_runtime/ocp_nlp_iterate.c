/*
 * ocp_nlp_iterate.c: a solver's warm start kept aside and put back (ocp_nlp_iterate.h).
 */
#include "ocp_nlp_iterate.h"

HM_FUNC void ocp_nlp_iterate_save(const hm_solver *s, hm_ocp_nlp_iterate *it)
{
    int n, i;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_NX; i++) it->x[n][i] = s->x[n][i];
        for (i = 0; i < HM_NG; i++) it->lam_lg[n][i] = s->mult.lam_lg[n][i];
        it->screen_radius[n] = s->screen_radius[n];
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NU; i++) it->u[n][i] = s->u[n][i];
        for (i = 0; i < HM_NX; i++) it->pi[n][i] = s->mult.pi[n][i];
    }
    for (i = 0; i < HM_NX; i++) it->x0_last[i] = s->x0_last[i];
    it->cost = s->cost;
    it->cost_slack = s->cost_slack;
    it->merit_mu = s->merit_mu;
    it->time_prepare_ms = s->time_prepare_ms;
    it->ipm_arg = s->ipm_arg;
    it->t_start = s->t_start;
    it->deadline_ns = s->deadline_ns;
    it->warm = s->warm;
    it->prepared = s->prepared;
    it->n_active = s->n_active;
    it->dyn_fresh = s->dyn_fresh;
    it->qp_solves = s->qp_solves;
    it->qp_rows_max = s->qp_rows_max;
    it->qp_rows_capped = s->qp_rows_capped;
    it->qp_budget = s->qp_budget;
    it->clock_fault = s->clock_fault;
    it->qp_warm_ready = s->ipm_ws.warm.ready;
}

HM_FUNC void ocp_nlp_iterate_restore(hm_solver *s, const hm_ocp_nlp_iterate *it)
{
    int n, i;
    for (n = 0; n <= HM_N; n++) {
        for (i = 0; i < HM_NX; i++) s->x[n][i] = it->x[n][i];
        for (i = 0; i < HM_NG; i++) s->mult.lam_lg[n][i] = it->lam_lg[n][i];
        s->screen_radius[n] = it->screen_radius[n];
    }
    for (n = 0; n < HM_N; n++) {
        for (i = 0; i < HM_NU; i++) s->u[n][i] = it->u[n][i];
        for (i = 0; i < HM_NX; i++) s->mult.pi[n][i] = it->pi[n][i];
    }
    for (i = 0; i < HM_NX; i++) s->x0_last[i] = it->x0_last[i];
    s->cost = it->cost;
    s->cost_slack = it->cost_slack;
    s->merit_mu = it->merit_mu;
    s->time_prepare_ms = it->time_prepare_ms;
    s->ipm_arg = it->ipm_arg;
    s->t_start = it->t_start;
    s->deadline_ns = it->deadline_ns;
    s->warm = it->warm;
    s->prepared = it->prepared;
    s->n_active = it->n_active;
    s->dyn_fresh = it->dyn_fresh;
    s->qp_solves = it->qp_solves;
    s->qp_rows_max = it->qp_rows_max;
    s->qp_rows_capped = it->qp_rows_capped;
    s->qp_budget = it->qp_budget;
    s->clock_fault = it->clock_fault;
    s->ipm_ws.warm.ready = it->qp_warm_ready;
}
