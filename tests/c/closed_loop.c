/*
 * closed_loop.c: a generated solver driven in C, in a changing random crowd, checking the safety
 * invariants at every step. Used for the sanitizer builds, the valgrind memcheck run and the soak.
 *
 * Build: cc -DSOLVER_HEADER='"soak.h"' -DSOLVER_PREFIX=soak_ -I<dir> closed_loop.c <dir>/soak.c
 *        <dir>/soak_model.c -lm
 * Run:   ./closed_loop STEPS SEED DEADLINE_MS [fixed]   (build with -DDT=T/N for a spec whose interval is not 0.1 s)
 * With "fixed", all N_h humans are present at every step and nothing is injected: the workload of
 * the benchmark's crowds, for instruction counts (valgrind --tool=callgrind; docs/benchmarks.md).
 * Every step: the command is finite; a stop has a reason and no other step has one; whenever the
 * robot is within d_h of a present human a stop is in force; a step without a stop solved its QP.
 * Now and then a NaN is injected into one input (and must give a stop). Prints the counts per stop
 * reason and an FNV-1a hash of the state and the command of every step (two builds that print the
 * same hash took the same steps bit for bit); the exit status is the number of violated
 * invariants (capped), 0 when none.
 * Built with -DCLOSED_LOOP_TRACE it prints a line per step to stderr (step, SQP iterations, QP iterations,
 * QP solves, QP rows, stop reason: docs/step_work.sh).
 * Built with -DOCP_QP_IPM_PROFILE (and _POSIX_C_SOURCE for the clock), it also prints where the
 * steps' time went: the solver's preparation and step timers, and the QP solver's parts
 * (ocp_qp_ipm.c), in microseconds per step (docs/pass_profile.sh).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include SOLVER_HEADER

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define S(x) CAT(SOLVER_PREFIX, x)

#define NH_ALLOC ((int)(sizeof(((S(input) *)0)->humans_now) / sizeof(((S(input) *)0)->humans_now[0])))
#define NNODES ((int)(sizeof(((S(output) *)0)->x) / sizeof(((S(output) *)0)->x[0])))
/* The period of the loop: one shooting interval (the RTI shifts its plan by one per step), and the
 * predictions' node spacing. Give the solver's T / N with -DDT=... when it is not 0.1 s. */
#ifndef DT
#define DT 0.1
#endif
#define MAX_REASONS 32 /* the table has n_reasons rows (counted at start, by their messages) */

#ifdef OCP_QP_IPM_PROFILE
#include <time.h>
double ocp_qp_ipm_profile_ns[7];
double ocp_qp_ipm_profile_clock_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}
static const char *const profile_parts[7] = {"qp_setup", "qp_pass_a", "qp_pass_b", "qp_pass_c", "qp_pass_d",
                                             "qp_pass_e", "qp_finish"};
#endif

static S(solver) solver; /* all memory of the solver, placed statically */
static S(input) in;
static S(output) out;

static unsigned long long rng_state;

static double uniform(double lo, double hi)
{
    rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(rng_state >> 11) / 9007199254740992.0;
}

static double pos[NH_ALLOC][2], vel[NH_ALLOC][2];

static void spawn(int j, const double *robot)
{
    do {
        pos[j][0] = uniform(-1.0, 13.0);
        pos[j][1] = uniform(-5.0, 5.0);
    } while (hypot(pos[j][0] - robot[0], pos[j][1] - robot[1]) < 2.0);
    {
        const double speed = uniform(0.2, 1.3), heading = uniform(-3.14159, 3.14159);
        vel[j][0] = speed * cos(heading);
        vel[j][1] = speed * sin(heading);
    }
}

static unsigned long long fnv1a(unsigned long long h, const void *data, size_t size)
{
    const unsigned char *b = (const unsigned char *)data;
    size_t i;
    for (i = 0; i < size; i++) h = (h ^ b[i]) * 1099511628211ULL;
    return h;
}

static double wrap(double v, double lo, double hi)
{
    const double w = hi - lo;
    while (v < lo) v += w;
    while (v >= hi) v -= w;
    return v;
}

int main(int argc, char **argv)
{
    const long steps = argc > 1 ? atol(argv[1]) : 1000;
    const double deadline_ms = argc > 3 ? atof(argv[3]) : 20.0;
    long t, counts[MAX_REASONS] = {0}, violations = 0, injected = 0;
    int n_reasons = 0;
    double x[4] = {0.0, 0.0, 0.0, 0.0}, goal[2][2] = {{12.0, 0.0}, {0.0, 0.0}}, worst_ms = 0.0;
    double closest = 1e9;
    const int fixed = argc > 4 && strcmp(argv[4], "fixed") == 0;
    int k = fixed || NH_ALLOC < 5 ? NH_ALLOC : 5, g = 0, j, n;
    long qp_iterations = 0, qp_rows_max = 0, qp_rows_capped = 0;
    unsigned long long xu_hash = 1469598103934665603ULL; /* FNV-1a of x and u at every step: bit-identity checks */
    double total_ms = 0.0, prepare_ms = 0.0;
    rng_state = (unsigned long long)(argc > 2 ? atol(argv[2]) : 1) * 2654435761ULL + 1ULL;
    while (n_reasons < MAX_REASONS && strcmp(S(stop_reason_message)(n_reasons), "unknown stop reason") != 0) n_reasons++;
    S(solver_init)(&solver);
    S(solver_params)(&solver)->deadline_ms = deadline_ms;
    for (j = 0; j < NH_ALLOC; j++) spawn(j, x);

    for (t = 0; t < steps; t++) {
        double d_goal, d_now = 1e9;
        int inject = 0;
        if (!fixed && t % 200 == 199) { /* the crowd changes: another size, some newcomers */
            k = (int)uniform(0.0, (double)NH_ALLOC + 0.999);
            for (j = 0; j < NH_ALLOC; j++)
                if (uniform(0.0, 1.0) < 0.3) spawn(j, x);
        }
        d_goal = hypot(goal[g][0] - x[0], goal[g][1] - x[1]);
        if (d_goal < 0.3) {
            g = 1 - g;
            d_goal = hypot(goal[g][0] - x[0], goal[g][1] - x[1]);
        }
        memset(&in, 0, sizeof in);
        for (j = 0; j < 4; j++) in.x0[j] = x[j];
        in.goal[0] = goal[g][0];
        in.goal[1] = goal[g][1];
        in.goal[2] = 0.0;
        in.goal[3] = d_goal * 0.5 < 0.8 ? d_goal * 0.5 : 0.8;
        in.n_humans = k;
        for (j = 0; j < k; j++) {
            in.humans_now[j][0] = pos[j][0];
            in.humans_now[j][1] = pos[j][1];
            in.humans_vel[j][0] = vel[j][0];
            in.humans_vel[j][1] = vel[j][1];
            for (n = 0; n < NNODES; n++) {
                in.humans_pred[n][j][0] = pos[j][0] + vel[j][0] * DT * n;
                in.humans_pred[n][j][1] = pos[j][1] + vel[j][1] * DT * n;
            }
            d_now = fmin(d_now, hypot(pos[j][0] - x[0], pos[j][1] - x[1]));
        }
        {
            const double cx = 6.0, cy = 0.9, r = 0.3, dx = x[0] - cx, dy = x[1] - cy, dn = hypot(dx, dy);
            in.has_obstacle = 1;
            in.obstacle[0] = cx + (dn > 1e-9 ? dx / dn : 1.0) * r;
            in.obstacle[1] = cy + (dn > 1e-9 ? dy / dn : 0.0) * r;
        }
        if (!fixed && t % 997 == 500) { /* a sensor glitch */
            inject = 1;
            injected++;
            if (k > 0 && uniform(0.0, 1.0) < 0.5)
                in.humans_pred[(int)uniform(0.0, NNODES - 0.001)][0][1] = NAN;
            else
                in.x0[(int)uniform(0.0, 3.999)] = NAN;
        }

        S(solver_step)(&solver, &in, &out);
#ifdef CLOSED_LOOP_TRACE
        /* one line per step, for the per-step instruction counts of docs/step_work.sh */
        fprintf(stderr, "trace %ld %d %d %d %d %d\n", t, out.sqp_iterations, out.qp_iterations, out.qp_solves,
                out.qp_rows, out.stop_reason);
#endif

        if (!isfinite(out.u0[0]) || !isfinite(out.u0[1]) || !isfinite(out.command[0]) ||
            !isfinite(out.command[1])) {
            fprintf(stderr, "step %ld: non-finite command\n", t);
            violations++;
        }
        if ((out.stop != 0) != (out.stop_reason != 0) || out.stop_reason < 0 || out.stop_reason >= n_reasons) {
            fprintf(stderr, "step %ld: stop %d with reason %d\n", t, out.stop, out.stop_reason);
            violations++;
        }
        if (d_now < S(solver_params)(&solver)->d_h && !out.stop) {
            fprintf(stderr, "step %ld: a human %.3f m away and no stop\n", t, d_now);
            violations++;
        }
        if (inject && out.stop_reason != 1) {
            fprintf(stderr, "step %ld: injected NaN gave reason %d\n", t, out.stop_reason);
            violations++;
        }
        if (!out.stop && out.qp_status != 0) {
            fprintf(stderr, "step %ld: no stop but QP status %d\n", t, out.qp_status);
            violations++;
        }
        if (out.stop_reason >= 0 && out.stop_reason < n_reasons) counts[out.stop_reason]++;
        qp_iterations += out.qp_iterations;
        qp_rows_capped += out.qp_rows_capped;
        if (out.qp_rows > qp_rows_max) qp_rows_max = out.qp_rows;
        if (out.time_total_ms > worst_ms) worst_ms = out.time_total_ms;
        total_ms += out.time_total_ms;
        prepare_ms += out.time_prepare_ms;
        closest = fmin(closest, d_now);

        xu_hash = fnv1a(xu_hash, x, sizeof x);
        xu_hash = fnv1a(xu_hash, out.u0, sizeof out.u0);
        { /* the plant: the unicycle under the command, finely integrated */
            int sub;
            for (sub = 0; sub < 10; sub++) {
                const double h = DT / 10.0;
                x[0] += h * x[3] * cos(x[2]);
                x[1] += h * x[3] * sin(x[2]);
                x[2] += h * out.u0[1];
                x[3] += h * out.u0[0];
            }
        }
        for (j = 0; j < NH_ALLOC; j++) {
            pos[j][0] = wrap(pos[j][0] + vel[j][0] * DT, -1.0, 13.0);
            pos[j][1] = wrap(pos[j][1] + vel[j][1] * DT, -5.0, 5.0);
        }
    }
    printf("{\"steps\": %ld, \"violations\": %ld, \"injected\": %ld, \"worst_ms\": %.3f, \"closest\": %.3f, "
           "\"stops\": {",
           steps, violations, injected, worst_ms, closest);
    for (j = 1; j < n_reasons; j++)
        printf("\"%s\": %ld%s", S(stop_reason_message)(j), counts[j], j + 1 < n_reasons ? ", " : "");
    printf("}, \"no_stop\": %ld, \"qp_iterations_mean\": %.2f, \"step_us\": %.3f, \"prepare_us\": %.3f",
           counts[0], (double)qp_iterations / (double)steps, 1e3 * total_ms / (double)steps,
           1e3 * prepare_ms / (double)steps);
#ifdef OCP_QP_IPM_PROFILE
    for (j = 0; j < 7; j++) printf(", \"%s_us\": %.3f", profile_parts[j], 1e-3 * ocp_qp_ipm_profile_ns[j] / (double)steps);
#endif
    printf(", \"qp_rows_max\": %ld, \"qp_rows_capped\": %ld", qp_rows_max, qp_rows_capped);
    printf(", \"solver_bytes\": %lu, \"xu_hash\": \"%016llx\"}\n", (unsigned long)sizeof solver, xu_hash);
    return violations > 100 ? 100 : (int)violations;
}
