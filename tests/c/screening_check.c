/*
 * screening_check.c (white box): the QP solution of every RTI step, solved with the distance rows
 * far from binding screened out (ocp_nlp_sqp.c), is a solution of the whole QP: compared with the
 * whole QP solved from scratch, the same objective to the QP tolerance, no row of the whole QP
 * violated, the same stationarity. The solver's translation unit is included, so that its QP,
 * solution and static QP solver are reachable.
 *
 * Build: cc -DSOLVER_SOURCE='"crowd.c"' -DSOLVER_PREFIX=crowd_ -I<dir> screening_check.c <dir>/crowd_model.c -lm
 * Run:   ./screening_check STEPS   (prints one JSON line: steps checked, re-solves, worst measures)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include SOLVER_SOURCE

#define CAT_(a, b) a##b
#define CAT(a, b) CAT_(a, b)
#define S(x) CAT(SOLVER_PREFIX, x)
#define NH_ALLOC ((int)(sizeof(((S(input) *)0)->humans_now) / sizeof(((S(input) *)0)->humans_now[0])))
#define NNODES ((int)(sizeof(((S(output) *)0)->x) / sizeof(((S(output) *)0)->x[0])))

static S(solver) solver;
static S(input) in;
static S(output) out;
static hm_ocp_qp qp_full;
static hm_ocp_qp_sol sol_full;
static hm_ocp_qp_ipm_ws ws_full;
static unsigned long long rng = 88172645463325252ULL;

static double uni(double lo, double hi)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return lo + (hi - lo) * (double)(rng >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv)
{
    const int steps = argc > 1 ? atoi(argv[1]) : 200;
    double pos[64][2], vel[64][2], x[4] = {0, 0, 0, 0};
    double worst_obj = 0, worst_ineq = 0, worst_stat = 0, worst_stat_full = 0;
    int t, j, n, checked = 0, resolves = 0;
    long far_rows = 0;
    hm_ocp_qp_ipm_arg arg;
    S(solver_init)(&solver);
    for (j = 0; j < NH_ALLOC; j++) {
        pos[j][0] = uni(1, 12);
        pos[j][1] = uni(-5, 5);
        vel[j][0] = uni(-1, 1);
        vel[j][1] = uni(-1, 1);
    }
    for (t = 0; t < steps; t++) {
        memset(&in, 0, sizeof in);
        for (j = 0; j < 4; j++) in.x0[j] = x[j];
        in.goal[0] = 12;
        in.goal[3] = 0.8;
        in.n_humans = NH_ALLOC;
        for (j = 0; j < NH_ALLOC; j++) {
            in.humans_now[j][0] = pos[j][0];
            in.humans_now[j][1] = pos[j][1];
            in.humans_vel[j][0] = vel[j][0];
            in.humans_vel[j][1] = vel[j][1];
            for (n = 0; n < NNODES; n++) {
                in.humans_pred[n][j][0] = pos[j][0] + 0.1 * n * vel[j][0];
                in.humans_pred[n][j][1] = pos[j][1] + 0.1 * n * vel[j][1];
            }
        }
        in.has_obstacle = 1;
        in.obstacle[0] = 6;
        in.obstacle[1] = 1;
        S(solver_step)(&solver, &in, &out);
        if (out.qp_solves >= 1 && out.qp_status == 0) {
            hm_ocp_qp_res r_scr, r_full;
            qp_full = solver.qp;
            /* the rows the linearisation left unevaluated as far beyond the screening radius (lg
             * -inf, ocp_nlp_screen_far): evaluated here at the linearisation point, so that the whole
             * QP has every row */
            for (n = 1; n <= HM_N; n++) {
                for (j = 0; j < qp_full.ng[n]; j++) {
                    const int human = j < in.n_humans;
                    hm_real g, hess[4];
                    if (qp_full.lg[n][j] != -HM_INF) continue;
                    S(distance_constraint)(solver.x_base[n], human ? in.humans_now[j] : in.obstacle,
                                           human ? &solver.params.d_h : &solver.params.d_s, &g, qp_full.D[n][j], hess);
                    qp_full.lg[n][j] = -g;
                    far_rows++;
                }
            }
            arg = solver.ipm_arg;
            arg.should_stop = 0;
            arg.residuals = 1;
            ocp_qp_ipm_solve(&qp_full, &sol_full, &ws_full, &arg);
            ocp_qp_res_compute(&qp_full, &solver.mult, &r_scr);   /* every row, the unevaluated ones too */
            r_full = ws_full.out.res;
            {
                const double dobj = fabs(r_scr.obj - r_full.obj) / fmax(1.0, fabs(r_full.obj));
                if (dobj > worst_obj) worst_obj = dobj;
                if (r_scr.ineq > worst_ineq) worst_ineq = r_scr.ineq;
                if (r_scr.stat > worst_stat) worst_stat = r_scr.stat;
                if (r_full.stat > worst_stat_full) worst_stat_full = r_full.stat;
            }
            checked++;
            resolves += out.qp_solves > 1;
        }
        if (!out.stop) {
            for (j = 0; j < 10; j++) {
                x[0] += 0.01 * x[3] * cos(x[2]);
                x[1] += 0.01 * x[3] * sin(x[2]);
                x[2] += 0.01 * out.u0[1];
                x[3] += 0.01 * out.u0[0];
            }
        }
        for (j = 0; j < NH_ALLOC; j++) {
            pos[j][0] += 0.1 * vel[j][0];
            pos[j][1] += 0.1 * vel[j][1];
        }
    }
    printf("{\"checked\": %d, \"resolves\": %d, \"far_rows\": %ld, \"obj_rel\": %.3e, \"ineq\": %.3e, \"stat\": %.3e, "
           "\"stat_full\": %.3e}\n", checked, resolves, far_rows, worst_obj, worst_ineq, worst_stat, worst_stat_full);
    return 0;
}
