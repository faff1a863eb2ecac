/*
 * fuzz_step.c: libFuzzer harness over a generated solver's entry points, with an oracle.
 *
 * The fuzzer's bytes are a program: a sequence of up to 24 operations on one solver, each followed by
 * its arguments: step, prepare + feedback, solve (any max_iter and tol), reset, one parameter written
 * with an arbitrary value (any field, any bytes: firmware can write anything into the struct) or a
 * valid but extreme one (any real field, 24 decades of either sign, kept when every rule holds), the
 * clock (forwards, stuck, backwards, or so slow that every deadline passes). Inputs are decoded
 * from the bytes as mostly plausible numbers (a robot driving among people near it, its state
 * following its commands), any of which may be replaced by NaN, an infinity, a denormal, an absurd
 * magnitude or raw bytes; the human count and the obstacle flag take any int. The clock is the
 * harness's own, so a run replays exactly.
 *
 * The oracle, after every operation that returns a command (the sanitizers, address and undefined,
 * watch every access besides):
 *   - the command and u0 are finite; stop and stop_reason agree; the reason is a row of the table;
 *   - without a stop: the command (v, omega) and u0 (a, omega) are within the bounds in force
 *     (to the command guard's tolerance);
 *   - with a stop: it brakes: no turning, the speed commanded between 0 and the measured one, at the
 *     configured rate of its direction (a_bounds[0] forward, a_bounds[1] backward, whenever their rule
 *     holds, else the spec's), a pose or not; without a usable speed, v = 0 and no acceleration;
 *   - whatever was bad is a stop with its reason: broken parameters (invalid_params), an input the
 *     harness made non-finite or absurd (invalid_input or invalid_params), a clock that stood still
 *     or ran backwards over a solved QP (a stop).
 * A failed check prints what failed and aborts, which libFuzzer reports with the input.
 *
 * Build: clang -fsanitize=fuzzer,address,undefined -DSOLVER_HEADER='"fuzz.h"' -DSOLVER_PREFIX=fuzz_
 *        -DSOLVER_UPREFIX=FUZZ_ -I<dir> fuzz_step.c <dir>/fuzz.c <dir>/fuzz_model.c -lm
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include SOLVER_HEADER

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define S(x) CAT(SOLVER_PREFIX, x)
#define U(x) CAT(SOLVER_UPREFIX, x)

#define NH_ALLOC ((int)(sizeof(((S(input) *)0)->humans_now) / sizeof(((S(input) *)0)->humans_now[0])))
#define NNODES ((int)(sizeof(((S(input) *)0)->humans_pred) / sizeof(((S(input) *)0)->humans_pred[0])))
#define TOL 1e-6

static S(solver) solver;
static S(params) spec;   /* the spec's parameters */
static S(input) in;
static S(output) out;
static double robot[4];  /* the robot's true state: the next step's measurement, unless jumped */
/* Counts over a run, printed at exit: solver calls that return a command, and their stops by reason. */
static unsigned long long calls, stops_by_reason[64];

/* The harness's clock: every reading moves by tick ns. */
static unsigned long long clock_now;
static long long clock_tick;
static unsigned long long fuzz_clock(void *ctx)
{
    (void)ctx;
    clock_now += (unsigned long long)clock_tick;
    return clock_now;
}

typedef struct {
    const uint8_t *p;
    size_t n;
} source;

static unsigned take8(source *s)
{
    if (s->n == 0) return 0;
    s->n--;
    return *s->p++;
}

/* A number in [lo, hi], or (1 in 16) an attack: NaN, +-inf, a denormal, +-1e300, -0, or raw bytes. */
static double take_real(source *s, double lo, double hi)
{
    const unsigned mode = take8(s);
    const unsigned frac = take8(s) | (take8(s) << 8);
    if ((mode & 15) != 0) return lo + (hi - lo) * (double)frac / 65535.0;
    switch ((mode >> 4) & 7) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return 4.9e-324;
    case 4: return (frac & 1) ? 1e300 : -1e300;
    case 5: return -0.0;
    default: {
        double v;
        uint64_t bits = 0;
        unsigned i;
        for (i = 0; i < 8; i++) bits = (bits << 8) | take8(s);
        memcpy(&v, &bits, sizeof v);
        return v;
    }
    }
}

/* The harness's own reading of the input contract (monitor.h: finite, positions within 1e5 m, angles
 * within 1e4 rad, speeds (the robot's, each component of a person's velocity) within 100 m/s; 0 <= n_humans <= N_h; has_obstacle 0 or 1; only present
 * humans and a present obstacle are read): 1 when the input breaks it. */
static int finite_within(double v, double limit)
{
    return isfinite(v) && fabs(v) <= limit;
}

static int state_ok(const S(real) *x)
{
    return finite_within((double)x[0], 1e5) && finite_within((double)x[1], 1e5) && finite_within((double)x[2], 1e4) &&
           finite_within((double)x[3], 100.0);
}

static int input_bad(void)
{
    int j, n;
    if (!state_ok(in.x0) || !state_ok(in.goal)) return 1;
    if (in.n_humans < 0 || in.n_humans > NH_ALLOC) return 1;
    if (in.has_obstacle != 0 && in.has_obstacle != 1) return 1;
    if (in.has_obstacle && !(finite_within((double)in.obstacle[0], 1e5) && finite_within((double)in.obstacle[1], 1e5)))
        return 1;
    for (j = 0; j < in.n_humans; j++) {
        if (!(finite_within((double)in.humans_now[j][0], 1e5) && finite_within((double)in.humans_now[j][1], 1e5)))
            return 1;
        if (!(finite_within((double)in.humans_vel[j][0], 100.0) && finite_within((double)in.humans_vel[j][1], 100.0)))
            return 1;
        for (n = 0; n < NNODES; n++)
            if (!(finite_within((double)in.humans_pred[n][j][0], 1e5) &&
                  finite_within((double)in.humans_pred[n][j][1], 1e5)))
                return 1;
    }
    return 0;
}

static void fill_input(source *s)
{
    int j, n, nh;
    const unsigned count = take8(s);
    memset(&in, 0, sizeof in);
    /* the measurement: the robot's state, now and then jumped or replaced */
    for (j = 0; j < 4; j++) in.x0[j] = robot[j];
    if ((take8(s) & 7) == 0) {
        in.x0[0] += take_real(s, -50.0, 50.0);
        in.x0[3] = take_real(s, -3.0, 3.0);
    }
    in.goal[0] = robot[0] + take_real(s, -20.0, 20.0);
    in.goal[1] = robot[1] + take_real(s, -20.0, 20.0);
    in.goal[2] = take_real(s, -4.0, 4.0);
    in.goal[3] = take_real(s, 0.0, 2.0);
    /* the human count: mostly 0..N_h, sometimes any small int */
    nh = (count & 0x80) ? (int)(signed char)count : (int)(count % (unsigned)(NH_ALLOC + 1));
    in.n_humans = nh;
    for (j = 0; j < NH_ALLOC; j++) {
        const double hx = robot[0] + take_real(s, -6.0, 6.0), hy = robot[1] + take_real(s, -6.0, 6.0);
        const double vx = take_real(s, -1.5, 1.5), vy = take_real(s, -1.5, 1.5);
        in.humans_now[j][0] = hx;
        in.humans_now[j][1] = hy;
        in.humans_vel[j][0] = vx;
        in.humans_vel[j][1] = vy;
        for (n = 0; n < NNODES; n++) {
            in.humans_pred[n][j][0] = hx + vx * 0.1 * n;
            in.humans_pred[n][j][1] = hy + vy * 0.1 * n;
        }
    }
    in.has_obstacle = (int)(take8(s) % 3) - ((take8(s) & 31) == 0 ? 1000 : 0); /* 2 and below 0: garbage */
    in.obstacle[0] = robot[0] + take_real(s, -5.0, 5.0);
    in.obstacle[1] = robot[1] + take_real(s, -5.0, 5.0);
}

/* A parameter field written with an attack (any offset of the struct, any value of its kind). */
static void poke_param(source *s)
{
    S(params) *p = S(solver_params)(&solver);
    const size_t offset = (size_t)(take8(s) | (take8(s) << 8)) % sizeof *p;
    const unsigned kind = take8(s) % 6;
    unsigned char *base = (unsigned char *)p;
    if (kind == 0) { /* back to the spec's */
        *p = spec;
    } else if (kind == 1) { /* a real with a value from the attacks, at an aligned offset */
        const double v = take_real(s, -1e3, 1e3);
        const S(real) r = (S(real))v;
        const size_t at = offset - offset % sizeof r;
        if (at + sizeof r <= sizeof *p) memcpy(base + at, &r, sizeof r);
    } else if (kind == 2) { /* an int field's worth of bytes */
        const int v = (int)(take8(s) | (take8(s) << 8)) - 32768;
        const size_t at = offset - offset % sizeof v;
        if (at + sizeof v <= sizeof *p) memcpy(base + at, &v, sizeof v);
    } else if (kind == 3) { /* one raw byte */
        base[offset] = (unsigned char)take8(s);
    } else { /* valid but extreme: a real of either sign over 24 decades, kept only if every rule holds */
        const S(params) before = *p;
        const unsigned e = take8(s), m = take8(s);
        const double v = ((m & 1) ? -1.0 : 1.0) * (1.0 + (double)(m >> 1) / 128.0) * pow(10.0, (double)(e % 25) - 12.0);
        const S(real) r = (S(real))v;
        const size_t at = offset - offset % sizeof r;
        if (at + sizeof r <= sizeof *p) memcpy(base + at, &r, sizeof r);
        if (S(params_check)(p) != 0) *p = before;
    }
}

static void fail(const char *what)
{
    fprintf(stderr, "oracle: %s (stop %d, reason %d, status %d, qp %d, u0 [%g, %g], command [%g, %g])\n", what,
            out.stop, out.stop_reason, out.status, out.qp_status, (double)out.u0[0], (double)out.u0[1],
            (double)out.command[0], (double)out.command[1]);
    abort();
}

static int within(double x, const S(real) *b)
{
    return x >= (double)b[0] - TOL * (1.0 + fabs((double)b[0])) && x <= (double)b[1] + TOL * (1.0 + fabs((double)b[1]));
}

/* bad: the input breaks its contract (input_bad); clock_bad: the clock stood still or ran backwards */
static void check(int bad, int clock_bad)
{
    const S(params) *p = S(solver_params)(&solver);
    const int params_bad = S(params_check)(p) != 0;
    calls++;
    if (out.stop_reason >= 0 && out.stop_reason < 64) stops_by_reason[out.stop_reason]++;
    if (!isfinite((double)out.u0[0]) || !isfinite((double)out.u0[1]) || !isfinite((double)out.command[0]) ||
        !isfinite((double)out.command[1]))
        fail("a command that is not finite");
    if ((out.stop != 0) != (out.stop_reason != 0)) fail("stop and stop_reason disagree");
    if (out.stop_reason < 0 || out.stop_reason >= U(STOP_REASON_COUNT)) fail("a stop reason outside the table");
    if (params_bad && out.stop_reason != U(STOP_INVALID_PARAMS)) fail("broken parameters without their stop");
    if (bad && out.stop_reason != U(STOP_INVALID_INPUT) && out.stop_reason != U(STOP_INVALID_PARAMS))
        fail("a broken input without its stop");
    if (clock_bad && out.qp_status != U(QP_NOT_RUN) && !out.stop) fail("a clock fault over a solved QP without a stop");
    if (!out.stop) {
        if (!within((double)out.command[0], p->v_bounds) || !within((double)out.command[1], p->omega_bounds) ||
            !within((double)out.u0[0], p->a_bounds) || !within((double)out.u0[1], p->omega_bounds))
            fail("a command outside the bounds without a stop");
    } else {
        const S(real) *a = S(params_check)(p) == 0 || (p->a_bounds[0] <= -0.1 && p->a_bounds[0] >= -100.0 &&
                                                     p->a_bounds[1] >= 0.1 && p->a_bounds[1] <= 100.0)
                               ? p->a_bounds
                               : spec.a_bounds;
        const int v_ok = isfinite((double)in.x0[3]) && fabs((double)in.x0[3]) <= 100.0;
        if (out.u0[1] != 0 || out.command[1] != 0) fail("a stop that turns");
        if (state_ok(in.x0) || v_ok) {
            /* a speed to brake from (with or without a usable pose): towards 0, at the rate of its direction */
            const double v0 = (double)in.x0[3], dt = U(DT);
            const double expect = fmin(fmax(-v0 / dt, (double)a[0]), (double)a[1]);
            if (fabs((double)out.u0[0] - expect) > 1e-9 * (1.0 + fabs(expect)))
                fail("a stop that does not brake at the configured rate");
            if (v0 >= 0 ? !((double)out.command[0] >= -1e-9 && (double)out.command[0] <= v0 + 1e-9)
                        : !((double)out.command[0] <= 1e-9 && (double)out.command[0] >= v0 - 1e-9))
                fail("a stop whose speed does not come down");
        } else if (out.command[0] != 0 || out.u0[0] != 0) {
            fail("a stop without a speed that does not command standstill with no acceleration");
        }
    }
}

/* The robot follows the command it got (a braking one too); an absurd state starts over. */
static void drive(void)
{
    const double v = (double)out.command[0], w = (double)out.command[1];
    robot[0] += 0.1 * robot[3] * cos(robot[2]);
    robot[1] += 0.1 * robot[3] * sin(robot[2]);
    robot[2] += 0.1 * w;
    robot[3] = v;
    if (!(fabs(robot[0]) < 1e4 && fabs(robot[1]) < 1e4 && fabs(robot[2]) < 1e3 && fabs(robot[3]) < 10.0))
        robot[0] = robot[1] = robot[2] = robot[3] = 0.0;
}

static void report(void)
{
    int k;
    fprintf(stderr, "fuzz_step: %llu solver calls (step, feedback, solve), stops by reason:", calls);
    for (k = 0; k < U(STOP_REASON_COUNT) && k < 64; k++) fprintf(stderr, " %d:%llu", k, stops_by_reason[k]);
    fprintf(stderr, "\n");
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    atexit(report);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    source s;
    int op, clock_bad = 0;
    s.p = data;
    s.n = size;
    S(solver_init)(&solver);
    S(params_default)(&spec);
    S(solver_set_clock)(&solver, fuzz_clock, 0);
    clock_now = 1000000000ULL;
    clock_tick = 1000; /* 1 us a reading: sanitizers are slow, the harness's clock is not */
    S(solver_params)(&solver)->deadline_ms = 1e4;
    spec.deadline_ms = 1e4;
    robot[0] = robot[1] = robot[2] = 0.0;
    robot[3] = 0.5;
    for (op = 0; op < 24 && s.n > 0; op++) {
        const unsigned what = take8(&s) % 10;
        if (what <= 3) { /* step */
            fill_input(&s);
            S(solver_step)(&solver, &in, &out);
            check(input_bad(), clock_bad);
            drive();
        } else if (what == 4) { /* prepare, then feedback with another measurement */
            fill_input(&s);
            S(solver_prepare)(&solver, &in);
            if (take8(&s) & 1) in.x0[3] = take_real(&s, -1.0, 2.0);
            S(solver_feedback)(&solver, &in, &out);
            check(input_bad(), clock_bad);
            drive();
        } else if (what == 5) { /* the full SQP, any max_iter and tol */
            const int max_iter = (int)(take8(&s) % 24) - 4;
            const double tol = take_real(&s, 1e-10, 1e-2);
            fill_input(&s);
            S(solver_solve)(&solver, &in, &out, max_iter, (S(real))tol);
            check(input_bad(), clock_bad);
            if ((max_iter < 1 || !(tol > 0 && tol < INFINITY)) && !out.stop)
                fail("solve() without iterations or a tolerance gave a command");
            drive();
        } else if (what == 6) {
            S(solver_reset)(&solver);
        } else if (what <= 8) {
            poke_param(&s);
        } else { /* the clock */
            const unsigned mode = take8(&s) % 4;
            clock_tick = mode == 0 ? 1000 : mode == 1 ? 0 : mode == 2 ? -1000 : 100000000; /* 100 ms a reading */
            clock_bad = mode == 1 || mode == 2;
        }
    }
    return 0;
}
