/*
 * controller_people.c: the people and the obstacle the OCP sees (controller_people.h).
 *
 * The solver handles N_h people; a crowd has more. The hard distance rows act on people's current
 * positions and the cost on their predictions, so the people that matter are those the robot's path
 * comes near over the horizon: someone 3 m away walking straight at the robot matters more than
 * someone 2 m away walking off. A track's relevance is the smallest distance between its prediction
 * and the robot's expected path at the same node, less two standard deviations of its position when
 * the tracker gives a covariance (an uncertain track counts as nearer). Relevance alone could leave out
 * someone right beside the robot (ten uncertain tracks 3 m away outranked a person 0.3 m away, who then
 * met neither the hard rows nor C2): everyone within the robot's stopping reach comes first.
 */
#include "controller_people.h"

#include "monitor.h"

HM_FUNC void controller_expected_path(const hm_solver *s, const hm_controller_input *cin, hm_real path[HM_N + 1][2])
{
    int n;
    for (n = 0; n <= HM_N; n++) {
        if (s->warm) {
            const int k = n + 1 <= HM_N ? n + 1 : HM_N;
            path[n][0] = s->x[k][0];
            path[n][1] = s->x[k][1];
        } else {
            const hm_real d = cin->v * HM_R(HM_DT) * (hm_real)n;
            path[n][0] = cin->pose[0] + d * hm_cos(cin->pose[2]);
            path[n][1] = cin->pose[1] + d * hm_sin(cin->pose[2]);
        }
    }
}

/* Largest standard deviation of a 2x2 covariance [sxx, sxy, syy] (its largest eigenvalue's root). */
static hm_real controller_sigma(const hm_real *c)
{
    const hm_real mean = HM_R(0.5) * (c[0] + c[2]);
    const hm_real half = HM_R(0.5) * (c[0] - c[2]);
    return hm_sqrt(hm_fmax(mean + hm_sqrt(half * half + c[1] * c[1]), HM_R(0.0)));
}

/* 1 when track i ranks before track j: everyone within the stopping reach first, nearest first (the hard
 * distance rows and the monitor's C2 act on them now, whatever their predictions); then the rest by their
 * relevance to the expected path. */
static int controller_ranks_before(const int *urgent, const hm_real *now, const hm_real *score, int i, int j)
{
    if (urgent[i] != urgent[j]) return urgent[i];
    return urgent[i] ? now[i] < now[j] : score[i] < score[j];
}

HM_FUNC void controller_select_people(hm_real path[HM_N + 1][2], const hm_controller_input *cin, const hm_params *p,
                                      hm_real v_cap, hm_input *in, hm_controller_output *out)
{
    hm_real score[HM_MAX_TRACKS], now[HM_MAX_TRACKS];
    int urgent[HM_MAX_TRACKS], chosen[HM_MAX_TRACKS];
    const hm_real a_brake = -p->a_bounds[0];
    int i, n, j, k = 0;
    for (i = 0; i < cin->n_tracks; i++) {
        const hm_real *t = cin->tracks[i];
        const hm_real ex = t[0] - cin->pose[0], ey = t[1] - cin->pose[1];
        hm_real best = HM_INF, closing, reach;
        for (n = 0; n <= HM_N; n++) {
            const hm_real tau = HM_R(HM_DT) * (hm_real)n;
            const hm_real dx = t[0] + tau * t[2] - path[n][0];
            const hm_real dy = t[1] + tau * t[3] - path[n][1];
            best = hm_fmin(best, dx * dx + dy * dy);
        }
        score[i] = hm_sqrt(best);
        if (cin->track_has_covariance[i] == 1) score[i] -= HM_R(2.0) * controller_sigma(cin->track_covariances[i]);
        now[i] = hm_sqrt(ex * ex + ey * ey);
        /* the speed at which they close in on the robot (none when walking off) */
        closing = now[i] > HM_R(0.0) ? hm_fmax(-(t[2] * ex + t[3] * ey) / now[i], HM_R(0.0)) : HM_R(0.0);
        reach = monitor_stopping_reach(p->d_h, p->reaction_time, a_brake, v_cap, closing);
        urgent[i] = now[i] < reach;
        chosen[i] = 0;
    }
    /* the HM_NH first, in order of rank (a partial selection sort: N_h passes over the tracks) */
    for (j = 0; j < HM_NH && j < cin->n_tracks; j++) {
        int pick = -1;
        for (i = 0; i < cin->n_tracks; i++)
            if (!chosen[i] && (pick < 0 || controller_ranks_before(urgent, now, score, i, pick))) pick = i;
        chosen[pick] = 1;
        out->people_index[k] = pick;
        out->people_ids[k] = cin->track_ids[pick];
        k++;
    }
    in->n_humans = k;
    out->n_people = k;
    for (j = 0; j < k; j++) {
        const hm_real *t = cin->tracks[out->people_index[j]];
        in->humans_now[j][0] = t[0];
        in->humans_now[j][1] = t[1];
        in->humans_vel[j][0] = t[2];
        in->humans_vel[j][1] = t[3];
        for (n = 0; n <= HM_N; n++) {
            const hm_real tau = HM_R(HM_DT) * (hm_real)n;
            in->humans_pred[n][j][0] = out->predictions[n][j][0] = t[0] + tau * t[2];
            in->humans_pred[n][j][1] = out->predictions[n][j][1] = t[1] + tau * t[3];
        }
    }
}

HM_FUNC void controller_nearest_obstacle(hm_real path[HM_N + 1][2], const hm_controller_input *cin, hm_real speed,
                                         hm_input *in)
{
    hm_real best = HM_INF;
    int i, n, pick = -1;
    for (i = 0; i < cin->n_obstacles; i++) {
        const hm_real *o = cin->obstacles[i];
        /* how soon the robot could be at the point: from where it is, or reaching node n, then going
         * straight to it */
        hm_real soon = hm_sqrt((o[0] - cin->pose[0]) * (o[0] - cin->pose[0]) +
                               (o[1] - cin->pose[1]) * (o[1] - cin->pose[1]));
        for (n = -1; n <= HM_N; n++) {
            if (n >= 0) {
                const hm_real dx = o[0] - path[n][0];
                const hm_real dy = o[1] - path[n][1];
                soon = hm_sqrt(dx * dx + dy * dy) + speed * HM_R(HM_DT) * (hm_real)n;
            }
            if (soon < best) {
                best = soon;
                pick = i;
            }
        }
    }
    in->has_obstacle = pick >= 0;
    if (pick >= 0) {
        in->obstacle[0] = cin->obstacles[pick][0];
        in->obstacle[1] = cin->obstacles[pick][1];
    }
}

HM_FUNC hm_real controller_separation_bound(const hm_controller_input *cin, const hm_real *x0, hm_real cos_t,
                                            hm_real sin_t, hm_real v_cap, const hm_params *params)
{
    hm_real bound = HM_INF;
    int i;
    if (!params->separation) return HM_INF;
    for (i = 0; i < cin->n_tracks; i++) {
        const hm_real *t = cin->tracks[i];
        bound = hm_fmin(bound, monitor_separation_speed(x0, cos_t, sin_t, t, t + 2, params->d_h, params->reaction_time,
                                                        -params->a_bounds[0], v_cap));
    }
    return bound;
}
