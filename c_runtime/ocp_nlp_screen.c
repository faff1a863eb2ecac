/*
 * ocp_nlp_screen.c: row screening around the QP solve of every SQP iteration: far rows left out of
 * the QP, the rows its solution violates admitted and the QP solved again, all rows restored with
 * their exact multipliers, and the radii of the next linearisation sized from this step.
 */
#include "ocp_nlp_screen.h"

#include "ocp_nlp_cost.h"
#include "ocp_qp_ipm.h"

/* ------------------------------------------------------------------------------------------------
 * Row screening
 *
 * Most distance rows of a crowd are far from binding: a human 3 m from the planned node cannot
 * constrain a step that moves the node by centimetres. Such rows are left out of the QP, and the
 * QP's solution is checked against every one of them afterwards. If it satisfies them all, it is
 * the solution of the whole QP (the QP is convex and its feasible set a subset of the screened
 * one's; a soft row satisfied at s = 0 adds nothing to the objective), with multipliers zero on
 * the rows left out and the slack bound's multiplier equal to the L1 weight. Rows found violated
 * join the QP, which is solved again: the outcome is exact whatever the screening radius, which
 * only decides the cost. The radius of a stage follows the last QP step there: SCREEN_MIN plus
 * twice the larger displacement of the two nodes that the shift brings to it (RTI steps move the
 * far end of the plan by metres and the near end by centimetres). Without a previous step (cold
 * start, braking retry) it is the distance the robot can drive by that node (ocp_nlp_screen_reach):
 * measured with 30 people, the braking retries took 0.60 ms instead of 0.77 ms unscreened. Before
 * the first step (screen_radius[0] = HM_INF) nothing is screened.
 * ---------------------------------------------------------------------------------------------- */

#define OCP_NLP_SCREEN_MIN HM_R(0.5)   /* smallest screening radius [m] */
#define OCP_NLP_SCREEN_ROUNDS 3        /* re-solves with violated rows before all rows go in */

/* Screening radii for a guess that is not the previous QP's solution (cold start, braking retry):
 * the distance the robot can cover by node n at its top speed, plus the margin (the QP's plan may
 * leave the guess anywhere within it; rows found violated are admitted all the same). */
HM_FUNC void ocp_nlp_screen_reach(hm_solver *s)
{
    const hm_real vmax = hm_fmax(hm_fabs(s->params.v_bounds[0]), hm_fabs(s->params.v_bounds[1]));
    int n;
    for (n = 0; n <= HM_N; n++) s->screen_radius[n] = HM_R(0.5) + vmax * HM_R(HM_DT) * (hm_real)n;
}

/* The plain distance beyond which a row of node n with minimum distance d_min is screened whatever
 * its exact margin: the stage's radius plus d_min, the smooth distance of the model being at least
 * the plain one (ocp_nlp_screen_rows). HM_INF when screening is off or has no radii yet, so that no
 * row is far. Taken once per node and kind of row, then tested per row by ocp_nlp_screen_far. */
HM_FUNC hm_real ocp_nlp_screen_far_reach(const hm_solver *s, int n, hm_real d_min)
{
    const hm_real reach = s->screen_radius[n] + d_min;
    return s->params.row_screening && s->screen_radius[0] < HM_INF && reach > HM_R(0.0) ? reach : HM_INF;
}

/* 1 when the row of the point c at the node x is beyond reach (ocp_nlp_screen_far_reach) by plain
 * distance: |x - c| >= reach. Such a row is not evaluated by the linearisation (lg = -HM_INF, D = 0;
 * with 100 people most of the 5,100 rows of a step): ocp_nlp_admit_violated_rows evaluates it only if
 * the QP's step moves its node far enough to reach it. */
HM_FUNC int ocp_nlp_screen_far(const hm_real *x, const hm_real *c, hm_real reach)
{
    const hm_real dx = x[0] - c[0], dy = x[1] - c[1];
    return reach < HM_INF && dx * dx + dy * dy >= reach * reach;
}

/* The row j of node n evaluated at the linearisation point (a row ocp_nlp_screen_far left out), into
 * the QP's D and, kept aside as a screened row's, its lg. */
static void ocp_nlp_evaluate_row(hm_solver *s, const hm_input *in, int n, int j)
{
    const ocp_nlp_row r = ocp_nlp_row_of(&s->params, in, ocp_nlp_clamp_humans(in), j);
    hm_real g, hess_d[HM_NPOS * HM_NPOS];
    hm_model_distance_constraint(s->x[n], r.c, r.d_min, &g, s->qp.D[n][j], hess_d);
    s->screened_lg[n][j] = -g;
}

/* Rows with margin -lg = d - d_min not below the stage's radius leave the QP: their lg is kept in
 * screened_lg and made absent (-HM_INF), which the QP solvers skip like any absent bound. Nothing
 * else of the QP moves, so putting a row back is one store. Returns the rows kept (rows of node 0,
 * which the QP ignores, never have a present lg: ocp_nlp_lin.c). */
static int ocp_nlp_screen_rows(hm_solver *s)
{
    hm_ocp_qp *qp = &s->qp;
    int n, j, kept = 0;
    for (n = 0; n <= HM_N; n++) {
        const hm_real radius = s->screen_radius[n];
        for (j = 0; j < qp->ng[n]; j++) {
            const hm_real lg = qp->lg[n][j];
            const int out = !(-lg < radius);
            s->screened[n][j] = (unsigned char)out;
            s->screened_lg[n][j] = lg;
            qp->lg[n][j] = out ? -HM_INF : lg;
            kept += !out;
        }
    }
    return kept;
}

/* Rows left out that the QP's step violates (by more than tol) join the QP; returns how many. A row
 * the linearisation did not evaluate (lg = -HM_INF) is evaluated first if the step's displacement of
 * its node reaches it: its linearised margin moves by at most that much (|D| <= 1), from one at least
 * its plain distance's. */
static int ocp_nlp_admit_violated_rows(hm_solver *s, const hm_input *in, hm_real tol)
{
    hm_ocp_qp *qp = &s->qp;
    const int nh = ocp_nlp_clamp_humans(in);
    int n, j, added = 0;
    for (n = 1; n <= HM_N; n++) {
        const hm_real dp0 = s->mult.x[n][0], dp1 = s->mult.x[n][1];
        const hm_real step = hm_sqrt(dp0 * dp0 + dp1 * dp1);   /* once per node, not per row */
        for (j = 0; j < qp->ng[n]; j++) {
            hm_real lg;
            if (s->screened[n][j] && s->screened_lg[n][j] == -HM_INF) {
                const int human = j < nh;
                const hm_real *c = human ? in->humans_now[j] : in->obstacle;
                const hm_real d_min = human ? s->params.d_h : s->params.d_s;
                const hm_real dx = s->x[n][0] - c[0], dy = s->x[n][1] - c[1];
                const hm_real reach = step + d_min;
                if (dx * dx + dy * dy > reach * reach) continue;   /* the step cannot reach it */
                ocp_nlp_evaluate_row(s, in, n, j);
            }
            lg = s->screened_lg[n][j];
            if (s->screened[n][j]
                && qp->D[n][j][0] * dp0 + qp->D[n][j][1] * dp1 < lg - tol * hm_fmax(HM_R(1.0), hm_fabs(lg))) {
                s->screened[n][j] = 0;
                qp->lg[n][j] = lg;
                added++;
            }
        }
    }
    return added;
}

/* All rows back in the QP. With sol: the rows left out get their exact multipliers (zero; the slack
 * bound's the L1 weight) and slack (zero). */
static void ocp_nlp_unscreen_rows(hm_solver *s, hm_ocp_qp_sol *sol)
{
    hm_ocp_qp *qp = &s->qp;
    int n, j;
    for (n = 0; n <= HM_N; n++) {
        for (j = 0; j < qp->ng[n]; j++) {
            if (!s->screened[n][j]) continue;
            s->screened[n][j] = 0;
            qp->lg[n][j] = s->screened_lg[n][j];
            if (sol) {
                sol->s[n][j] = HM_R(0.0);
                sol->lam_lg[n][j] = HM_R(0.0);
                sol->lam_ls[n][j] = qp->soft[n][j] ? qp->zl[n][j] : HM_R(0.0);
            }
        }
    }
}

/* ------------------------------------------------------------------------------------------------
 * Row capacity
 *
 * The QP solvers hold at most HM_QP_NRC soft rows (solver.qp_rows; by default sized so that the
 * closed loops of the evaluation almost never need more, docs/benchmarks.md). A QP with more rows
 * than that keeps the HM_QP_NRC of smallest margin: the linearised margin D' dp - lg at the QP's step
 * dp of the row's node (at the linearisation point before the first solve, dp = 0: -lg, the distance
 * beyond d_min); the others leave it as screened rows do and are checked after the solve like them.
 * A row left out that the step violates comes back, and the rows of largest margin at that step
 * leave instead, within the rounds of screening; what the last round leaves out violated is not
 * in the step's QP, whose plan the monitor then checks as it checks every plan (C1, C2). Counted in
 * the step's output (qp_rows_capped).
 * ---------------------------------------------------------------------------------------------- */

/* The linearised margin of present row j of node n at the step (dp0, dp1) of its node. */
HM_KERNEL hm_real ocp_nlp_row_margin(const hm_ocp_qp *qp, int n, int j, hm_real dp0, hm_real dp1)
{
    return qp->D[n][j][0] * dp0 + qp->D[n][j][1] * dp1 - qp->lg[n][j];
}

/* Rows present in the QP (those whose margin at the linearisation point is a number: as
 * ocp_nlp_keep_capacity counts them). */
static int ocp_nlp_rows_present(const hm_solver *s)
{
    const hm_ocp_qp *qp = &s->qp;
    int n, j, present = 0;
    for (n = 1; n <= HM_N; n++) {
        for (j = 0; j < qp->ng[n]; j++)
            if (ocp_qp_bound_present(qp->lg[n][j]))
                present += ocp_nlp_row_margin(qp, n, j, HM_R(0.0), HM_R(0.0)) <= HM_INF;
    }
    return present;
}

/* Rows of margin <= theta among the np margins m. */
static int ocp_nlp_margins_within(const hm_real *m, int np, hm_real theta)
{
    int k, within = 0;
    for (k = 0; k < np; k++) within += m[k] <= theta;
    return within;
}

/* Keeps the QP, with *present rows in it, within its row capacity (above), *present counting what it
 * keeps; returns 1 if it left rows out. The threshold of the kept margins is found by bisection over
 * counts (no sort: it runs only when the capacity binds); rows at the threshold are kept in order while
 * there is room. The present rows' margins are taken once, into the QP workspace's scratch (free
 * between solves), and the bisection counts over them: at N_h = 100 a pass over every row of every
 * node for each of up to 40 counts had been 3 % of the step. */
static int ocp_nlp_keep_capacity(hm_solver *s, int at_step, int *present)
{
    hm_ocp_qp *qp = &s->qp;
    hm_real *margin = s->ipm_ws.u.scratch;
    hm_real lo = HM_INF, hi = -HM_INF;
    int n, j, kept = 0, it, room, np = 0;
    if (*present > s->qp_rows_max) s->qp_rows_max = *present;
    if (*present <= HM_QP_NRC) return 0;
    for (n = 1; n <= HM_N; n++) {
        const hm_real dp0 = at_step ? s->mult.x[n][0] : HM_R(0.0), dp1 = at_step ? s->mult.x[n][1] : HM_R(0.0);
        for (j = 0; j < qp->ng[n]; j++) {
            hm_real m;
            if (!ocp_qp_bound_present(qp->lg[n][j])) continue;
            m = ocp_nlp_row_margin(qp, n, j, dp0, dp1);
            margin[np++] = m;
            if (m < lo) lo = m;
            if (m > hi) hi = m;
        }
    }
    /* count(margin <= lo) <= capacity < count(margin <= hi) (but for ties at the smallest margin); a
     * threshold that keeps exactly the capacity ends the search, and so does a bracket below 1e-6 m:
     * the rows within it fill what room is left, in order */
    for (it = 0; it < 40 && hi - lo > HM_R(1e-6); it++) {
        const hm_real mid = lo + (hi - lo) * HM_R(0.5);
        const int within = ocp_nlp_margins_within(margin, np, mid);
        if (within <= HM_QP_NRC) lo = mid;
        else hi = mid;
        if (within == HM_QP_NRC) break;
    }
    room = HM_QP_NRC - ocp_nlp_margins_within(margin, np, lo);
    np = 0;
    for (n = 1; n <= HM_N; n++) {
        for (j = 0; j < qp->ng[n]; j++) {
            const hm_real lg = qp->lg[n][j];
            hm_real m;
            if (!ocp_qp_bound_present(lg)) continue;
            m = margin[np++];
            if (kept < HM_QP_NRC && (m <= lo || (m <= hi && room > 0))) {
                room -= m > lo;
                kept++;
                continue;
            }
            s->screened[n][j] = 1;
            s->screened_lg[n][j] = lg;
            qp->lg[n][j] = -HM_INF;
        }
    }
    *present = kept;
    s->qp_rows_capped++;
    return 1;
}

/* Screening radii of the next QP from the displacements of this QP's step (see above). */
static void ocp_nlp_size_screening(hm_solver *s)
{
    hm_real d2[HM_N + 2];
    int n;
    for (n = 0; n <= HM_N; n++) d2[n] = s->mult.x[n][0] * s->mult.x[n][0] + s->mult.x[n][1] * s->mult.x[n][1];
    d2[HM_N + 1] = d2[HM_N];
    for (n = 0; n <= HM_N; n++)
        s->screen_radius[n] = OCP_NLP_SCREEN_MIN + HM_R(2.0) * hm_sqrt(hm_fmax(d2[n], d2[n + 1]));
}

/* Solve the QP of the current linearisation (its x0 offset set), screened; residuals: the caller
 * reads ipm_ws.out.res. shifted: the QP is the last one's a stage on (the real-time iteration's
 * plan, shifted), and starts from the iterate that the last one kept (ocp_qp_ipm_warm.c);
 * the re-solves with more rows start from the first round's. Each solve may take qp_max_iter
 * interior-point iterations, or (s->qp_budget >= 0, the real-time iteration) what is left of the
 * step's budget; an exhausted budget ends the solve at HM_QP_MAX_ITER. Returns the QP status. */
HM_FUNC int ocp_nlp_qp_solve(hm_solver *s, const hm_input *in, hm_real tol, int residuals, int shifted, int *qp_iter)
{
    const int screen = s->params.row_screening && s->screen_radius[0] < HM_INF;
    int status = HM_QP_MAX_ITER, round, left_out, present, added;
    s->ipm_arg.tol = tol;
    s->ipm_arg.residuals = residuals;
    present = screen ? ocp_nlp_screen_rows(s) : ocp_nlp_rows_present(s);
    /* rows left out by the capacity are checked after the solve as screened rows are, screening or not */
    left_out = ocp_nlp_keep_capacity(s, 0, &present);
    for (round = 0;; round++) {
        s->ipm_arg.max_iter = s->params.qp_max_iter;
        if (s->qp_budget >= 0) {
            /* the real-time iteration's budget: its QP solves share 2 qp_max_iter iterations */
            if (s->qp_budget < 1) {
                if (round == 0) ocp_qp_sol_set_zero(&s->mult);   /* nothing solved: a zero step */
                status = HM_QP_MAX_ITER;
                break;
            }
            if (s->qp_budget < s->ipm_arg.max_iter) s->ipm_arg.max_iter = s->qp_budget;
        }
        s->ipm_arg.warm_start = round > 0 ? 2 : shifted;
        status = ocp_qp_ipm_solve(&s->qp, &s->mult, &s->ipm_ws, &s->ipm_arg);
        *qp_iter += s->ipm_ws.out.iter;
        if (s->qp_budget >= 0) s->qp_budget -= s->ipm_ws.out.iter;
        s->qp_solves++;
        if (!(screen || left_out) || !ocp_nlp_qp_usable(status)) break;
        if (round == OCP_NLP_SCREEN_ROUNDS) {
            /* pathological: rows keep turning up; the whole QP settles it (every row evaluated), as far
             * as the capacity holds it: the rows of smallest margin at this step */
            int n, j;
            for (n = 1; n <= HM_N; n++)
                for (j = 0; j < s->qp.ng[n]; j++)
                    if (s->screened[n][j] && s->screened_lg[n][j] == -HM_INF) ocp_nlp_evaluate_row(s, in, n, j);
            ocp_nlp_unscreen_rows(s, 0);
            present = ocp_nlp_rows_present(s);
            left_out = ocp_nlp_keep_capacity(s, 1, &present);
            continue;
        }
        if (round > OCP_NLP_SCREEN_ROUNDS) break;
        added = ocp_nlp_admit_violated_rows(s, in, tol);
        if (added == 0) break;
        present += added;
        if (ocp_nlp_keep_capacity(s, 1, &present)) left_out = 1;
    }
    if (screen || left_out) ocp_nlp_unscreen_rows(s, &s->mult);
    if (ocp_nlp_qp_usable(status)) ocp_nlp_size_screening(s);
    return status;
}
