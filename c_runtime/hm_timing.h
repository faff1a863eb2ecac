/*
 * hm_timing.h: the clock of the solver's timings and deadline.
 *
 * A clock is a function returning monotonic nanoseconds (any origin; differences are taken in
 * unsigned arithmetic, so a wrapping counter works). On POSIX systems the default is
 * clock_gettime(CLOCK_MONOTONIC); firmware installs its own (a cycle counter, a timer) with
 * <name>_solver_set_clock. Without a clock the timings read 0 and no deadline can fire.
 * The translation unit defines _POSIX_C_SOURCE before any system header for clock_gettime.
 */
#ifndef HM_TIMING_H
#define HM_TIMING_H

#if defined(__unix__) || defined(__APPLE__)
#include <time.h>
#if defined(CLOCK_MONOTONIC)
#define HM_HAVE_POSIX_CLOCK 1
HM_FUNC unsigned long long hm_clock_posix_ns(void *ctx)
{
    struct timespec ts;
    (void)ctx;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (unsigned long long)ts.tv_sec * 1000000000ULL + (unsigned long long)ts.tv_nsec;
}
#endif
#endif

/* Milliseconds between two clock readings, in the solver's real type; 0 for a reading 2^63 ns or more
 * after t0 in the unsigned difference, i.e. one before it: a clock that ran backwards is a clock fault
 * (ocp_nlp_clock_fault), and its times read 0 rather than 1.8e13 ms. */
HM_FUNC hm_real hm_elapsed_ms(unsigned long long t1, unsigned long long t0)
{
    const unsigned long long d = t1 - t0;
    return d >= (1ULL << 63) ? HM_R(0.0) : (hm_real)d * HM_R(1e-6);
}
#define HM_ELAPSED_MS(t1, t0) hm_elapsed_ms((t1), (t0))

#endif /* HM_TIMING_H */
