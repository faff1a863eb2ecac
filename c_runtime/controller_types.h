/*
 * controller_types.h: the sized type of the navigation controller around the solver, instantiated
 * once per solver like ocp_nlp_types.h (no include guard; the same HM_NS / HM_REAL / HM_N / HM_NG
 * contract, and HM_NCAND: the candidate plans, 1 for one). Included by a generated public header after ocp_nlp_types.h: the controller embeds a
 * solver, its input and output, and what it remembers between control periods.
 */
typedef struct HM_NS(controller) {
    HM_NS(controller_params) params;  /* the caller's parameters of the controller */
    HM_NS(solver) solver;         /* solver.params: the caller's parameters of the solver, between steps; a
                                   * step changes the few it derives (controller_objective.h) and puts the
                                   * caller's back */
    HM_NS(input) in;              /* the solver's input, built from the controller's */
    HM_NS(output) out;            /* the real-time iteration's output */
    HM_NS(output) recovery_out;   /* a recovery SQP's output */
    /* Progress towards the goal (the stall timer). */
    int has_goal;                 /* 1: goal_xy is the final goal of the last period */
    HM_REAL goal_xy[2];
    HM_REAL best_left;            /* the smallest distance left since the timer started */
    HM_REAL time_progress;        /* when the distance left last shrank by stall_distance */
    HM_REAL time_brisk;           /* when the robot last went at half the speed it tracks, or stopped */
    int has_time;
    HM_REAL time_last;
    int has_recovery;             /* 1: time_recovery holds the last stall recovery */
    HM_REAL time_recovery;
    int has_theta;                /* 1: theta is the last period's heading, unwrapped */
    HM_REAL theta;
    /* The start of a straight path to a goal pose given alone (the progress objective measures progress
     * along a line that does not move with the robot): where the robot was when it got that goal. */
    int has_origin;
    HM_REAL origin[2];
    HM_REAL origin_goal[2];
    /* The progress objective's lead (controller_references): how far along the path its goals start ahead
     * of the robot's projection; the distance left, the time and the goal of the period that set it. */
    int has_lead;
    HM_REAL lead;
    HM_REAL lead_left;
    HM_REAL lead_time;
    HM_REAL lead_goal[2];
    /* Passing decisions (controller_candidates.h): the other candidate plans are solved one after the other
     * in the solver's own memory, its warm start kept aside meanwhile (main_kept); of their outputs only
     * those that may still be applied are kept (the cheapest so far, the decision of last period, and the one
     * being solved: at most three). The decision applied last period: the track id passed (-1: the main
     * plan) and the side. */
#if HM_NCAND > 1
    HM_NS(ocp_nlp_iterate) main_kept;
    HM_NS(output) candidate_out[HM_NCAND - 1 < 3 ? HM_NCAND - 1 : 3];
#endif
    int chosen_id;
    int chosen_side;
    /* Arriving at the goal arrival_goal: braking to a standstill since it came within goal_tolerance. */
    int arriving;
    HM_REAL arrival_goal[2];
} HM_NS(controller);
