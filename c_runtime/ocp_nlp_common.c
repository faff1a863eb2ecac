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

HM_FUNC const hm_real *ocp_nlp_goal_at(const hm_input *in, int n)
{
    return in->has_refs == 1 ? in->refs[n] : in->goal;
}

HM_FUNC unsigned long long ocp_nlp_now(const hm_solver *s)
{
    return s->clock ? s->clock(s->clock_ctx) : 0ULL;
}

HM_FUNC int ocp_nlp_qp_usable(int status)
{
    return status == HM_QP_SOLVED || status == HM_QP_MAX_ITER;
}

/* A clock reading 2^63 ns (292 years) or more after the start of the step, in the unsigned
 * differences of hm_timing.h, is one from before it: the clock ran backwards. */
#define OCP_NLP_CLOCK_BACKWARDS (1ULL << 63)

/* Deadline hook of the QP iterations. A clock that runs backwards ends the QP too, and marks the
 * step's clock fault (ocp_nlp_clock_fault). */
HM_FUNC int ocp_nlp_deadline_passed(void *ctx)
{
    hm_solver *s = (hm_solver *)ctx;
    unsigned long long elapsed;
    if (s->clock == 0) return 0;
    elapsed = s->clock(s->clock_ctx) - s->t_start;
    if (elapsed >= OCP_NLP_CLOCK_BACKWARDS) {
        s->clock_fault = 1;
        return 1;
    }
    return elapsed > s->deadline_ns;
}

HM_FUNC int ocp_nlp_clock_fault(hm_solver *s, unsigned long long t_end)
{
    if (s->clock == 0) return 0;
    if (t_end - s->t_start >= OCP_NLP_CLOCK_BACKWARDS) s->clock_fault = 1;
    return s->clock_fault || (t_end == s->t_start && s->qp_solves > 0);
}

HM_FUNC void ocp_nlp_start_clock(hm_solver *s, unsigned long long t_start)
{
    /* deadline_ms * 1e6 in nanoseconds, without a real -> 64-bit integer conversion: on a
     * single-precision FPU libgcc does that one in soft double. Whole milliseconds and the fraction
     * are converted to 32 bits each (one FPU instruction); absurd or NaN deadlines are capped at
     * ~50 days (the monitor refuses non-positive or non-finite ones before any solving). */
    hm_real ms = s->params.deadline_ms;
    unsigned long whole, frac_ns;
    if (!(ms >= HM_R(0.0))) ms = HM_R(0.0);
    if (ms > HM_R(4.0e9)) ms = HM_R(4.0e9);
    whole = (unsigned long)ms;
    frac_ns = (unsigned long)((ms - (hm_real)whole) * HM_R(1e6));
    s->t_start = t_start;
    s->clock_fault = 0;
    s->deadline_ns = (unsigned long long)whole * 1000000ULL + frac_ns;
}
