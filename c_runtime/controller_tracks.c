/*
 * controller_tracks.c: a controller input's tracks from any number of them (controller_tracks.h).
 *
 * One pass, no memory beyond the input: the first HM_MAX_TRACKS fill the input, and every later track
 * replaces the farthest kept one when it is nearer (O(n M) comparisons, a few microseconds for hundreds
 * of tracks).
 */
#include "controller_tracks.h"

#include "monitor.h"

/* Squared distance of a track from the pose; -1 (nearest of all) for a position that is not finite. */
static hm_real controller_track_rank(const hm_real *pose, const hm_real *t)
{
    const hm_real dx = t[0] - pose[0], dy = t[1] - pose[1];
    const hm_real d2 = dx * dx + dy * dy;
    return monitor_finite(t[0]) && monitor_finite(t[1]) && monitor_finite(d2) ? d2 : HM_R(-1.0);
}

static void controller_put_track(hm_controller_input *in, int slot, int i, const hm_real (*tracks)[4], const int *ids,
                                 const hm_real (*covariances)[3], const int *has_covariance)
{
    int k;
    for (k = 0; k < 4; k++) in->tracks[slot][k] = tracks[i][k];
    in->track_ids[slot] = ids[i];
    in->track_has_covariance[slot] = covariances != 0 && has_covariance != 0 && has_covariance[i] == 1;
    for (k = 0; k < 3; k++)
        in->track_covariances[slot][k] = in->track_has_covariance[slot] ? covariances[i][k] : HM_R(0.0);
}

HM_FUNC int controller_set_tracks(hm_controller_input *in, int n, const hm_real (*tracks)[4], const int *ids,
                                  const hm_real (*covariances)[3], const int *has_covariance)
{
    hm_real rank[HM_MAX_TRACKS];
    int i, kept = 0;
    in->n_tracks = 0;
    in->n_tracks_dropped = 0;
    if (n < 0 || (n > 0 && (tracks == 0 || ids == 0))) return -1;
    for (i = 0; i < n; i++) {
        const hm_real r = controller_track_rank(in->pose, tracks[i]);
        int slot = -1;
        if (kept < HM_MAX_TRACKS) {
            slot = kept++;
        } else {
            int j, far = 0;
            for (j = 1; j < HM_MAX_TRACKS; j++)
                if (rank[j] > rank[far]) far = j;
            if (r < rank[far]) slot = far;
        }
        if (slot >= 0) {
            rank[slot] = r;
            controller_put_track(in, slot, i, tracks, ids, covariances, has_covariance);
        }
    }
    in->n_tracks = kept;
    in->n_tracks_dropped = n - kept;
    return n - kept;
}
