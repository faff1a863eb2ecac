/*
 * controller_path.c: the goal the OCP sees (controller_path.h).
 *
 * The OCP tracks a goal with a quadratic cost; handing it a goal metres away along a path that bends
 * would pull the plan across the bend (through the wall of a U-shaped obstacle). The carrot is the
 * point lookahead metres along the path beyond the robot's projection, interpolated on its segment,
 * with the segment's heading: the OCP then follows the path, and sees the final goal (with its own
 * heading) once it is within lookahead. The projection is the nearest point of the whole path, so a
 * path replanned from anywhere is followed from where the robot is.
 */
#include "controller_path.h"

static hm_real controller_norm(hm_real dx, hm_real dy)
{
    return hm_sqrt(dx * dx + dy * dy);
}

/* Point i of the path the controller follows: the input's path, or the segment from origin to a goal pose
 * (straight). */
static const hm_real *controller_path_point(const hm_controller_input *cin, const hm_real *origin, int straight,
                                            int i)
{
    if (straight) return i == 0 ? origin : (cin->n_path == 1 ? cin->path[0] : cin->goal);
    return cin->path[i];
}

HM_FUNC void controller_goal(const hm_controller_input *cin, const hm_real *origin, const hm_real *position,
                             hm_real heading, hm_real lookahead, hm_controller_goal *g)
{
    const int straight = cin->n_path < 2;
    const int n = straight ? 2 : cin->n_path;
    hm_real best = HM_INF, s_proj = HM_R(0.0), total = HM_R(0.0);
    hm_real final_heading = heading;
    const hm_real *end;
    int i;
    g->has = cin->n_path >= 1 || cin->has_goal == 1;
    if (!g->has) return;
    /* the projection (first nearest point), the path's length and the heading of its last segment */
    for (i = 0; i + 1 < n; i++) {
        const hm_real *a = controller_path_point(cin, origin, straight, i);
        const hm_real *b = controller_path_point(cin, origin, straight, i + 1);
        const hm_real ex = b[0] - a[0], ey = b[1] - a[1];
        const hm_real len = controller_norm(ex, ey);
        hm_real t = HM_R(0.0), dx, dy, d2;
        if (len > HM_R(1e-9)) {
            t = ((position[0] - a[0]) * ex + (position[1] - a[1]) * ey) / (len * len);
            t = hm_fmin(hm_fmax(t, HM_R(0.0)), HM_R(1.0));
            final_heading = hm_atan2(ey, ex);
        }
        dx = a[0] + t * ex - position[0];
        dy = a[1] + t * ey - position[1];
        d2 = dx * dx + dy * dy;
        if (d2 < best) {
            best = d2;
            s_proj = total + t * len;
        }
        total += len;
    }
    end = controller_path_point(cin, origin, straight, n - 1);
    if (cin->has_goal == 1) final_heading = cin->goal[2];
    g->final[0] = end[0];
    g->final[1] = end[1];
    g->final[2] = controller_unwrap(final_heading, heading);
    g->left = hm_fmax(total - s_proj, HM_R(0.0));
    g->to_final = controller_norm(end[0] - position[0], end[1] - position[1]);
    g->s_proj = s_proj;
    g->length = total;
    /* the carrot: lookahead metres beyond the projection, or the final goal */
    controller_path_at(cin, origin, heading, s_proj + lookahead, g, g->carrot);
}

HM_FUNC void controller_path_at(const hm_controller_input *cin, const hm_real *origin, hm_real heading, hm_real s,
                                const hm_controller_goal *g, hm_real *point)
{
    const int straight = cin->n_path < 2;
    const int n = straight ? 2 : cin->n_path;
    hm_real total = HM_R(0.0);
    int i;
    point[0] = g->final[0];
    point[1] = g->final[1];
    point[2] = g->final[2];
    if (s >= g->length) return;
    for (i = 0; i + 1 < n; i++) {
        const hm_real *a = controller_path_point(cin, origin, straight, i);
        const hm_real *b = controller_path_point(cin, origin, straight, i + 1);
        const hm_real ex = b[0] - a[0], ey = b[1] - a[1];
        const hm_real len = controller_norm(ex, ey);
        if (len > HM_R(1e-9) && total + len >= s) {
            const hm_real t = (s - total) / len;
            point[0] = a[0] + t * ex;
            point[1] = a[1] + t * ey;
            point[2] = controller_unwrap(hm_atan2(ey, ex), heading);
            return;
        }
        total += len;
    }
}
