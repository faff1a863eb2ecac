/*
 * controller_tracks.h: a controller input's tracks from any number of them (controller_tracks.c).
 *
 * The input holds HM_MAX_TRACKS tracks; a tracker may report more. Every face (C callers, Python, the
 * ROS nodes) fills the input through this one function, so that too many tracks mean the same thing
 * everywhere: the nearest to the robot are kept, and how many were left out is reported
 * (in->n_tracks_dropped, copied to the output).
 */
#ifndef CONTROLLER_TRACKS_H
#define CONTROLLER_TRACKS_H
#include "controller_common.h"

/* Fills in's tracks (n_tracks, tracks, track_ids, track_has_covariance, track_covariances,
 * n_tracks_dropped) from n >= 0 tracks [x, y, vx, vy] with their ids and, optionally (NULL: none), their
 * position covariances [sxx, sxy, syy] and whether each has one. When n exceeds HM_MAX_TRACKS the
 * HM_MAX_TRACKS nearest to in->pose are kept (set the pose first); a track whose position is not finite
 * counts as nearest, so that it is kept and stops the robot as an invalid input. Returns the number left
 * out, or -1 (and no tracks, n_tracks_dropped 0) for n < 0 or missing arrays. */
HM_FUNC int controller_set_tracks(hm_controller_input *in, int n, const hm_real (*tracks)[4], const int *ids,
                                  const hm_real (*covariances)[3], const int *has_covariance);

#endif /* CONTROLLER_TRACKS_H */
