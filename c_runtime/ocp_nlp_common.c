/*
 * ocp_nlp_common.c: the helpers that every part of the NLP layer calls (ocp_nlp_common.h): the
 * present humans of an input, the solver's clock, the usable QP statuses. Stateless.
 */
#include "ocp_nlp_common.h"

HM_FUNC int ocp_nlp_clamp_humans(const hm_input *in)
{
    int nh = in->n_humans;
    if (nh < 0) nh = 0;
    if (nh > HM_NG - 1) nh = HM_NG - 1;
    return nh;
}

HM_FUNC unsigned long long ocp_nlp_now(const hm_solver *s)
{
    return s->clock ? s->clock(s->clock_ctx) : 0ULL;
}

HM_FUNC int ocp_nlp_qp_usable(int status)
{
    return status == HM_QP_SOLVED || status == HM_QP_MAX_ITER;
}
