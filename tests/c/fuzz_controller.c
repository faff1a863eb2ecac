/*
 * fuzz_controller.c: a property fuzzer over a generated package's navigation controller, with an oracle
 * of its safety guarantees.
 *
 * A seeded generator drives one controller through episodes: a robot (the unicycle, moved by the
 * controller's commands, its state sometimes replaced) among more tracks than the OCP sees (up to twice
 * the input's capacity, handed over by <prefix>controller_set_tracks), with and without covariances,
 * people placed within d_h of the robot, beside it, behind it and ahead, goals far, near (at the goal,
 * turning to its heading) and none, paths, obstacle points, reversing allowed or not, parameter changes
 * between steps (bounds, d_h, separation, the speed limit, the deadline), and a clock that is sometimes
 * so slow that every deadline passes. Now and then an input is made non-finite or absurd.
 *
 * The oracle, after every step:
 *   - the command and u0 are finite, and stop agrees with stop_reason;
 *   - someone within d_h of the robot (any track handed in, whatever the OCP saw): a stop;
 *   - a stop brakes: no turning; the commanded speed between 0 and the measured one (0 when that is not
 *     a number), and u0 towards 0;
 *   - without a stop: the command and u0 within the bounds in force (to the command guard's tolerance).
 * What the controller was doing (following, stalled, at the goal, turning there, without a goal) is
 * counted with the steps that had someone within d_h, and the outcomes and stops by reason; all printed
 * at the end. A failed check prints the step and exits 1.
 *
 * Build: cc -O2 -DSOLVER_HEADER='"paper.h"' -DSOLVER_PREFIX=paper_ -DSOLVER_UPREFIX=PAPER_ -I<dir>
 *        fuzz_controller.c <dir>/paper.c <dir>/paper_model.c -lm
 * Run:   ./fuzz_controller STEPS SEED [tamper]
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include SOLVER_HEADER

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define S(x) CAT(SOLVER_PREFIX, x)
#define U(x) CAT(SOLVER_UPREFIX, x)

#define MAX_TRACKS U(MAX_TRACKS)
#define GIVEN_MAX (2 * MAX_TRACKS)
#define DT 0.1
#define TOL 1e-6
#define N_OUTCOMES 8
/* What the controller was doing, whatever a stop made of it. */
enum situation { FOLLOWING, STALLED, AT_GOAL, TURNING_AT_GOAL, NO_GOAL, N_SITUATIONS };
static const char *const situation_name[N_SITUATIONS] = {"following", "stalled", "at the goal",
                                                         "turning at the goal", "no goal"};

static S(controller) ctl;
static S(controller_input) in;
static S(controller_output) out;
static S(params) spec;
static S(controller_params) own_spec;

/* xorshift64*: a seeded run replays exactly */
static uint64_t rng_state;
static double uniform(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
}
static double between(double lo, double hi) { return lo + (hi - lo) * uniform(); }
static int chance(double p) { return uniform() < p; }

/* The harness's clock: every reading moves by tick ns (0: the package's own clock is not used). */
static unsigned long long clock_now, clock_tick;
static unsigned long long fuzz_clock(void *ctx)
{
    (void)ctx;
    clock_now += clock_tick;
    return clock_now;
}

static double tracks[GIVEN_MAX][4], covariances[GIVEN_MAX][3];
static int ids[GIVEN_MAX], has_cov[GIVEN_MAX];
static double robot[4];   /* x, y, theta, v */

static unsigned long long steps_by_outcome[N_OUTCOMES], stops_by_reason[64];
static unsigned long long steps_by_situation[N_SITUATIONS], close_by_situation[N_SITUATIONS];
static double p_close;   /* of a track placed within d_h, this episode */
static int was_stalled;  /* the last step's output was stalled */
/* The oracle's own test: "tamper" hands it outputs broken in one way each, which it must catch. */
static int tamper;
static unsigned long long steps, steps_close, steps_reversing, steps_dropped, steps_over_nh;

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_controller: step %llu: %s (outcome %d stop %d reason %d v %g cmd [%g %g] u0 [%g %g])\n",
            steps, what, out.outcome, out.stop, out.stop_reason, in.v, out.command[0], out.command[1], out.u[0],
            out.u[1]);
    exit(1);
}

static int within(double x, const double *b)
{
    return x >= b[0] - TOL * (1.0 + fabs(b[0])) && x <= b[1] + TOL * (1.0 + fabs(b[1]));
}

/* Parameters for an episode: the spec's, some of them moved (always within their rules). */
static void new_params(void)
{
    S(params) *p = S(controller_solver_params)(&ctl);
    S(controller_params) *o = S(controller_own_params)(&ctl);
    *p = spec;
    *o = own_spec;
    if (chance(0.3)) p->v_bounds[0] = -between(0.1, 1.0);                 /* reversing allowed */
    if (chance(0.2)) p->a_bounds[0] = -between(0.1, 3.0);
    if (chance(0.2)) p->a_bounds[1] = between(0.1, 3.0);
    if (chance(0.2)) p->d_h = between(0.2, 1.0);
    if (chance(0.2)) p->separation = !p->separation;
    if (chance(0.2)) o->speed_limit = between(0.2, 1.5);
    if (chance(0.1)) p->deadline_ms = between(0.01, 1.0);
    if (chance(0.1)) o->yaw_goal_tolerance = between(0.05, 3.2);
    if (S(params_check)(p) != 0 || S(controller_params_check)(o) != 0) {
        *p = spec;
        *o = own_spec;
    }
}

/* A track near the robot: within d_h (sometimes), within a few metres (often), or far. */
static void place_track(int i, double d_h)
{
    const double r = chance(p_close) ? between(0.0, d_h) : chance(0.6) ? between(d_h, 4.0) : between(4.0, 15.0);
    const double a = between(-M_PI, M_PI), s = chance(0.5) ? between(0.0, 1.8) : 0.0, h = between(-M_PI, M_PI);
    tracks[i][0] = robot[0] + r * cos(a);
    tracks[i][1] = robot[1] + r * sin(a);
    tracks[i][2] = s * cos(h);
    tracks[i][3] = s * sin(h);
    ids[i] = (int)(uniform() * 1e6);
    has_cov[i] = chance(0.4);
    covariances[i][0] = has_cov[i] ? between(0.0, 4.0) : 0.0;
    covariances[i][1] = 0.0;
    covariances[i][2] = has_cov[i] ? between(0.0, 4.0) : 0.0;
}

static void new_episode(int *n_given)
{
    int i;
    S(controller_reset)(&ctl);
    new_params();
    p_close = chance(0.5) ? 0.0 : 0.03;
    robot[0] = between(-5.0, 5.0);
    robot[1] = between(-5.0, 5.0);
    robot[2] = between(-M_PI, M_PI);
    robot[3] = between(S(controller_solver_params)(&ctl)->v_bounds[0], 1.2);
    *n_given = chance(0.2) ? (int)between(0, 4) : (int)between(0, GIVEN_MAX + 1);
    for (i = 0; i < *n_given; i++) place_track(i, S(controller_solver_params)(&ctl)->d_h);
    clock_tick = chance(0.1) ? 2000000ULL : 1000ULL;   /* 2 ms a reading: every deadline passes */
    in.has_goal = 0;
    in.n_path = 0;
    if (chance(0.85)) {
        const double r = chance(0.3) ? between(0.0, 0.5) : between(0.5, 8.0), a = between(-M_PI, M_PI);
        in.has_goal = 1;
        in.goal[0] = robot[0] + r * cos(a);
        in.goal[1] = robot[1] + r * sin(a);
        in.goal[2] = between(-M_PI, M_PI);
        if (chance(0.3)) {
            in.n_path = 3;
            for (i = 0; i < 3; i++) {
                in.path[i][0] = robot[0] + (in.goal[0] - robot[0]) * i / 2.0 + (i == 1 ? between(-1, 1) : 0.0);
                in.path[i][1] = robot[1] + (in.goal[1] - robot[1]) * i / 2.0 + (i == 1 ? between(-1, 1) : 0.0);
            }
        }
    }
    in.n_obstacles = chance(0.5) ? (int)between(0, 8) : 0;
    for (i = 0; i < in.n_obstacles; i++) {
        in.obstacles[i][0] = robot[0] + between(-3.0, 3.0);
        in.obstacles[i][1] = robot[1] + between(-3.0, 3.0);
    }
}

static double wrap(double a) { return atan2(sin(a), cos(a)); }

static void check(double v_measured, double nearest, const S(params) *p, const S(controller_params) *o)
{
    const double v_max = fmin(p->v_bounds[1], o->speed_limit);
    const double v_in_force[2] = {p->v_bounds[0], v_max};
    if (!isfinite(out.command[0]) || !isfinite(out.command[1]) || !isfinite(out.u[0]) || !isfinite(out.u[1]))
        fail("a non-finite command");
    if ((out.stop != 0) != (out.stop_reason != U(STOP_NONE))) fail("stop and stop_reason disagree");
    if (nearest < p->d_h && !out.stop) fail("someone within d_h and no stop");
    if (out.stop) {
        if (out.command[1] != 0.0 || out.u[1] != 0.0) fail("a stop that turns");
        if (isfinite(v_measured) && fabs(v_measured) <= 100.0) {
            if (!(fabs(out.command[0]) <= fabs(v_measured) + 1e-12 && out.command[0] * v_measured >= 0.0))
                fail("a stop that does not brake");
            if (out.u[0] * v_measured > 0.0) fail("a stop that accelerates");
        } else if (out.command[0] != 0.0) {
            fail("a stop from an unknown speed that does not command 0");
        }
    } else if (!within(out.command[0], v_in_force) || !within(out.command[1], p->omega_bounds) ||
               !within(out.u[0], p->a_bounds) || !within(out.u[1], p->omega_bounds)) {
        fail("a command outside the bounds without a stop");
    }
}

int main(int argc, char **argv)
{
    const unsigned long long total = argc > 1 ? strtoull(argv[1], 0, 10) : 100000ULL;
    int n_given = 0, k, i;
    double t = 0.0;
    tamper = argc > 3 && strcmp(argv[3], "tamper") == 0;
    rng_state = (argc > 2 ? strtoull(argv[2], 0, 10) : 1ULL) * 0x9E3779B97F4A7C15ULL + 1ULL;
    S(controller_create)(&ctl);
    spec = *S(controller_solver_params)(&ctl);
    own_spec = *S(controller_own_params)(&ctl);
    S(controller_set_clock)(&ctl, fuzz_clock, 0);
    new_episode(&n_given);
    for (steps = 0; steps < total; steps++) {
        S(params) p;
        S(controller_params) o;
        double nearest = INFINITY;
        int bad = 0;
        if (chance(0.01)) new_episode(&n_given);
        if (chance(0.02)) new_params();
        p = *S(controller_solver_params)(&ctl);
        o = *S(controller_own_params)(&ctl);
        for (i = 0; i < n_given; i++) {   /* people walk on; some come close, some leave */
            tracks[i][0] += DT * tracks[i][2];
            tracks[i][1] += DT * tracks[i][3];
            if (chance(0.01)) place_track(i, p.d_h);
        }
        t += DT;
        in.time = t;
        in.pose[0] = robot[0];
        in.pose[1] = robot[1];
        in.pose[2] = wrap(robot[2]);
        in.v = robot[3];
        in.omega = 0.0;
        if (chance(0.005)) {   /* an unusable input */
            const double attack[4] = {NAN, INFINITY, -1e300, 1e6};
            const double value = attack[(int)between(0, 4)];
            k = (int)between(0, 3);
            if (k == 0) in.pose[(int)between(0, 3)] = value;
            else if (k == 1) in.v = value;
            else if (n_given > 0) tracks[(int)between(0, n_given)][(int)between(0, 4)] = value;
            bad = 1;
        }
        if (S(controller_set_tracks)(&in, n_given, (const double(*)[4])tracks, ids,
                                     (const double(*)[3])covariances, has_cov) < 0)
            fail("set_tracks refused valid arguments");
        for (i = 0; i < n_given; i++) {
            const double d = hypot(tracks[i][0] - in.pose[0], tracks[i][1] - in.pose[1]);
            if (d < nearest || isnan(d)) nearest = isnan(d) ? -1.0 : d;
        }
        S(controller_step)(&ctl, &in, &out);
        if (tamper && nearest < p.d_h && steps > 1000) {
            out.stop = 0;   /* the oracle must see someone within d_h and no stop */
            out.stop_reason = U(STOP_NONE);
        }
        check(in.v, nearest, &p, &o);
        if (out.outcome < 0 || out.outcome >= N_OUTCOMES) fail("an outcome outside the table");
        steps_by_outcome[out.outcome]++;
        {
            /* the situation: the final goal is the path's end, or the goal pose */
            const double gx = in.n_path > 0 ? in.path[in.n_path - 1][0] : in.goal[0];
            const double gy = in.n_path > 0 ? in.path[in.n_path - 1][1] : in.goal[1];
            const int at_goal = hypot(gx - in.pose[0], gy - in.pose[1]) <= o.goal_tolerance;
            const enum situation sit = !in.has_goal && in.n_path == 0 ? NO_GOAL
                                       : at_goal ? (in.has_goal && fabs(wrap(in.goal[2] - in.pose[2])) >
                                                                       o.yaw_goal_tolerance ? TURNING_AT_GOAL : AT_GOAL)
                                       : was_stalled ? STALLED : FOLLOWING;
            steps_by_situation[sit]++;
            if (nearest < p.d_h) {
                steps_close++;
                close_by_situation[sit]++;
            }
        }
        was_stalled = out.stalled;
        if (out.stop && out.stop_reason >= 0 && out.stop_reason < 64) stops_by_reason[out.stop_reason]++;
        steps_reversing += in.v < 0.0;
        steps_dropped += out.n_tracks_dropped > 0;
        steps_over_nh += in.n_tracks > U(NH);
        if (bad || !isfinite(out.command[0])) {
            was_stalled = 0;
            new_episode(&n_given);
            continue;
        }
        /* the robot follows the command (sometimes it is pushed: a state it did not reach by itself) */
        robot[3] = out.command[0];
        robot[2] += DT * out.command[1];
        robot[0] += DT * robot[3] * cos(robot[2]);
        robot[1] += DT * robot[3] * sin(robot[2]);
        if (chance(0.01)) robot[3] = between(-1.0, 1.5);
    }
    printf("steps %llu; with someone within d_h %llu; reversing %llu; more tracks than N_h %llu; tracks dropped %llu\n",
           steps, steps_close, steps_reversing, steps_over_nh, steps_dropped);
    for (k = 0; k < N_SITUATIONS; k++)
        printf("doing %-20s steps %8llu  with someone within d_h %8llu\n", situation_name[k], steps_by_situation[k],
               close_by_situation[k]);
    for (k = 0; k < N_OUTCOMES; k++)
        if (steps_by_outcome[k]) printf("outcome %-60s %8llu\n", S(outcome_message)(k), steps_by_outcome[k]);
    for (k = 0; k < 64; k++)
        if (stops_by_reason[k]) printf("stop %-40s %8llu\n", S(stop_reason_message)(k), stops_by_reason[k]);
    printf("violations 0\n");
    return 0;
}
