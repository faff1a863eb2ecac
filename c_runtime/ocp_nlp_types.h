/*
 * ocp_nlp_types.h: the sized types of the SQP solver, instantiated once per solver like
 * hm_types.h (no include guard; same HM_NS / HM_REAL / HM_N / HM_NG contract). Included by a
 * generated public header after hm_types.h and after its own <name>_params, <name>_input and
 * <name>_output structs, which the solver embeds.
 */
/* The Gauss-Newton SQP (real-time iteration and full) over the OCP: all memory of a solver, so that
 * the caller may place it statically. */
typedef unsigned long long (*HM_NS(clock_fn))(void *ctx); /* monotonic time in nanoseconds */

typedef struct HM_NS(solver) {
    HM_NS(params) params;
    /* The iterate (linearisation point), and the last QP's solution: its step (x, u: applied in the
     * step that solved it) and its multipliers, which are the NLP's (the residuals' and, shifted, the
     * next linearisation's). One struct for both: the QP writes its solution where the NLP keeps its
     * multipliers (after a failed QP they are that QP's last iterate's, and the next step starts cold). */
    HM_REAL x[HM_N + 1][HM_NX];
    HM_REAL u[HM_N][HM_NU];
    HM_NS(ocp_qp_sol) mult;
    int warm;        /* 1: x, u, mult hold a previous solution to shift */
    int prepared;    /* 1: qp holds the linearisation for the next feedback */
    int n_active;    /* humans and obstacle rows of the current linearisation */
    int dyn_fresh;   /* 1: qp.A, qp.B are the dynamics' Jacobians at the iterate, which was just
                        simulated (no gaps): the next linearisation need not evaluate them again */
    /* Row screening (ocp_nlp_screen.c): rows of stage n whose linearised margin is not below
     * screen_radius[n] are left out of the QP (screened, their lg kept in screened_lg and made
     * absent in qp.lg) and checked after. */
    HM_REAL screen_radius[HM_N + 1];
    /* Speed and separation (params.separation): the bound on v at node n from the geometry of node
     * n - 1 (ocp_nlp_lin.c); node 1's from the measured state, at feedback. */
    HM_REAL v_separation[HM_N + 1];
    int qp_solves;   /* QPs solved in the current step */
    int qp_rows_max;     /* the most soft rows one of the step's QPs had, before the capacity (HM_QP_NRC) */
    int qp_rows_capped;  /* QPs of the step that had more, and held the HM_QP_NRC of smallest margin */
    int qp_budget;   /* interior-point iterations left to the real-time iteration's QP solves in this step
                        (2 qp_max_iter at its start: its re-solves and braking retry share them, which bounds
                        the work of a step); < 0: each QP may take qp_max_iter (the full SQP) */
    HM_REAL screened_lg[HM_N + 1][HM_NG];
    unsigned char screened[HM_N + 1][HM_NG];
    /* The QP of the current linearisation and its solver. */
    HM_NS(ocp_qp) qp;
    HM_NS(ocp_qp_ipm_arg) ipm_arg;
    HM_NS(ocp_qp_ipm_ws) ipm_ws;
    /* The linearisation point during a line search (full SQP). */
    HM_REAL x_base[HM_N + 1][HM_NX];
    HM_REAL u_base[HM_N][HM_NU];
    HM_REAL merit_mu;
    /* Evaluations kept from the linearisation for the residuals and the report. */
    HM_REAL cost;         /* objective at the linearisation point, soft-row penalties included */
    HM_REAL cost_slack;   /* the penalties alone */
    HM_REAL time_prepare_ms;
    HM_NS(clock_fn) clock;
    void *clock_ctx;
    unsigned long long t_start;      /* clock reading at the start of the step (deadline origin) */
    unsigned long long deadline_ns;
    /* The parameters the current preparation used, byte for byte: a feedback under changed ones
     * (new bounds, weights, ...) prepares again instead of solving a QP built with the old ones. */
    HM_NS(params) params_prepared;
    /* The measured state of the last step (the state jump test of a warm solver, monitor.h). */
    HM_REAL x0_last[HM_NX];
    /* 1: the clock ran backwards during this step (ocp_nlp_deadline_passed): a clock fault. */
    int clock_fault;
} HM_NS(solver);

/* What of a solver its next step reads, kept aside while other solves use its memory (ocp_nlp_iterate.h:
 * which fields and why these). */
typedef struct HM_NS(ocp_nlp_iterate) {
    HM_REAL x[HM_N + 1][HM_NX];
    HM_REAL u[HM_N][HM_NU];
    HM_REAL pi[HM_N][HM_NX];
    HM_REAL lam_lg[HM_N + 1][HM_NG];
    HM_REAL screen_radius[HM_N + 1];
    HM_REAL x0_last[HM_NX];
    HM_REAL cost, cost_slack, merit_mu, time_prepare_ms;
    HM_NS(ocp_qp_ipm_arg) ipm_arg;
    unsigned long long t_start, deadline_ns;
    int warm, prepared, n_active, dyn_fresh, qp_solves, qp_rows_max, qp_rows_capped, qp_budget, clock_fault;
    int qp_warm_ready;   /* ipm_ws.warm.ready */
} HM_NS(ocp_nlp_iterate);
