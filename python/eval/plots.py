"""Figures of episodes in the spirit of the paper's (headless, Agg backend).

* :func:`plot_episodes`: one map per episode given (robot path in its planner's colour, the people of
  that episode, obstacles, start and goal, contacts marked); below, the distance to the nearest human,
  the robot's speed (its protective stops shaded, contacts marked where they start, as on the map) and
  the planner time over time, every episode in one plot each.
* :func:`animate_episode`: an animated GIF of one episode (pillow writer).

People and planners never share colours: planners are drawn in saturated categorical colours (MPC red,
DWB blue, the paper's MPC orange, others purple, brown, pink, olive), people in shades of green, each
person's track a thin line from a hollow disc where they were first seen, with arrows every 1.5 s
along it in their direction of walking (legend entry "people"). Contacts are marked at the robot's
position where they start: a black cross where the robot was at fault (it moved with the person within
+-90 degrees of its heading, :func:`humanmpc.eval.metrics.robot_at_fault`), a white one where the person
was, an orange square where the robot's disc reached a wall or obstacle. The legend sits below each map,
outside the scene. Simulated people react to the robot, so every episode has its own map.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Patch
from matplotlib.patches import Polygon as PolygonPatch

from ..sim.world import World
from .episode import EpisodeLog, FloatArray
from .metrics import D_TH, human_distances, person_distances, rising_edges, robot_at_fault

PLANNER_COLOURS = {"mpc": "tab:red", "dwb": "tab:blue", "mpc_paper": "tab:orange"}
_OTHER = ["tab:purple", "tab:brown", "tab:pink", "tab:olive"]
PEOPLE_CMAP = "Greens"  # people: shades of green, never a planner's colour
PEOPLE_COLOUR = "tab:green"  # their legend entry
ARROW_EVERY = 1.5  # s between two arrows on a person's track
ARROW_LENGTH = 0.35  # m


def planner_colour(name: str, index: int = 0) -> str:
    """A planner's colour: by its registered name (the part before a parameter list ``mpc[q=10]``)."""
    return PLANNER_COLOURS.get(name.split("[")[0], _OTHER[index % len(_OTHER)])


def draw_world(ax: Axes, world: World) -> None:
    for c in world.circles:
        ax.add_patch(CirclePatch(c.center, c.radius, color="0.35", zorder=2))
    for p in world.polygons:
        ax.add_patch(PolygonPatch(p.array, closed=True, color="0.35", zorder=2))
    xmin, xmax, ymin, ymax = world.bounds
    ax.set_xlim(xmin, xmax)
    ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def people_colours(k: int) -> list[tuple[float, float, float, float]]:
    """``k`` shades of the people's colour map, distinguishable from one person to the next."""
    cmap = plt.get_cmap(PEOPLE_CMAP)
    return [cmap(0.45 + 0.5 * ((i * 0.618) % 1.0)) for i in range(k)]


def draw_humans(ax: Axes, log: EpisodeLog) -> None:
    """Every person's track (module docstring): a line, a hollow disc where first seen, arrows along the
    direction of walking every ARROW_EVERY seconds (people absent at a sample have no point there)."""
    k = log.humans.shape[1]
    if k == 0:
        return
    present = log.present
    every = max(1, round(ARROW_EVERY / log.dt))
    for i, colour in enumerate(people_colours(k)):
        here = np.nonzero(present[:, i])[0]
        if here.size == 0:
            continue
        track = log.humans[here, i]
        ax.plot(track[:, 0], track[:, 1], color=colour, lw=1.0, zorder=3)
        ax.add_patch(CirclePatch(track[0], log.robot.human_radius, fill=False, ec=colour, lw=1.0, zorder=3))
        at = np.arange(0, here.size - 1, every)
        step = track[np.minimum(at + 1, here.size - 1)] - track[at]
        norm = np.linalg.norm(step, axis=1)
        moving = norm > 1e-6
        if np.any(moving):
            d = step[moving] / norm[moving, None] * ARROW_LENGTH
            ax.quiver(track[at[moving], 0], track[at[moving], 1], d[:, 0], d[:, 1], color=colour, angles="xy",
                      scale_units="xy", scale=1.0, width=0.006, headwidth=4, headlength=4, zorder=3)


def contact_starts(log: EpisodeLog) -> tuple[np.ndarray, np.ndarray]:
    """The samples at which a contact with a person starts, the robot's fault and the person's."""
    r = log.robot.radius + log.robot.human_radius
    contact = person_distances(log.states[:, :2], log.humans, log.present) < r
    fault = robot_at_fault(log.states, log.humans) & contact
    robot: list[int] = []
    person: list[int] = []
    for k in range(contact.shape[1]):
        for t in rising_edges(contact[:, k]):
            (robot if fault[t, k] else person).append(int(t))
    return np.array(sorted(robot), dtype=int), np.array(sorted(person), dtype=int)


def wall_contact_starts(log: EpisodeLog) -> np.ndarray:
    """The samples at which a contact with an obstacle or wall starts (the robot's disc reaches it)."""
    contact = log.world.signed_distance(log.states[:, :2]) < log.robot.radius
    return np.asarray(rising_edges(np.asarray(contact, dtype=bool)), dtype=int)


WALL_MARK = {"marker": "s", "mfc": "orange", "mec": "black"}
# the contacts with people, by fault, on the map and on the speed plot alike
CONTACT_MARKS = (
    ("contact, robot's fault", {"marker": "X", "mfc": "black", "mec": "white"}),
    ("contact, person's fault", {"marker": "X", "mfc": "white", "mec": "black"}),
)


def draw_contact_marks(ax: Axes, x: FloatArray, y: FloatArray, log: EpisodeLog, ms: float) -> None:
    """Each contact with a person marked at (x, y)[its first sample], by fault (CONTACT_MARKS)."""
    for (_, mark), starts in zip(CONTACT_MARKS, contact_starts(log), strict=True):
        if starts.size:
            ax.plot(x[starts], y[starts], ls="none", ms=ms, zorder=6, **mark)  # type: ignore[arg-type]


def contact_legend_handles(ms: float) -> list[Line2D]:
    """The legend entries of the two contact marks."""
    return [
        Line2D([], [], ls="none", ms=ms, label=label, **mark)  # type: ignore[arg-type]
        for label, mark in CONTACT_MARKS
    ]


def draw_contacts(ax: Axes, log: EpisodeLog) -> None:
    wall = wall_contact_starts(log)
    xy = log.states[:, :2]
    draw_contact_marks(ax, xy[:, 0], xy[:, 1], log, ms=11)
    if wall.size:
        ax.plot(xy[wall, 0], xy[wall, 1], ls="none", ms=9, zorder=6, **WALL_MARK)  # type: ignore[arg-type]


def draw_speed(ax: Axes, log: EpisodeLog, colour: str) -> None:
    """The robot's speed over time, the periods of a protective stop shaded and the contacts with people
    marked where they start: what the robot did when someone came into contact (a stop before a contact at
    the person's fault is the commonest story of a failed episode in a crowd)."""
    v = log.states[:, 3]
    ax.plot(log.times, v, color=colour, label=log.planner)
    # each run of stopped periods k0..k1 - 1 spans times[k0] to times[k1]: its last period included
    edges = np.flatnonzero(np.diff(np.concatenate(([0], log.stops.astype(int), [0]))))
    for k0, k1 in zip(edges[::2], edges[1::2], strict=True):
        ax.axvspan(log.times[k0], log.times[k1], color=colour, alpha=0.18, lw=0)
    draw_contact_marks(ax, log.times, v, log, ms=9)


def speed_legend_handles() -> list[Line2D | Patch]:
    """The speed plot's legend: the stop shading (in each planner's colour) and the two contact marks."""
    return [Patch(color="0.5", alpha=0.3, label="protective stop"), *contact_legend_handles(ms=8)]


def legend_handles(colour: str, label: str) -> list[Line2D]:
    """The map's legend: the robot's path, the people, the three contact marks, start and goal."""
    return [
        Line2D([], [], color=colour, lw=2.0, label=label),
        Line2D([], [], color=PEOPLE_COLOUR, lw=1.0, marker=r"$\rightarrow$", ms=9,
               label="people, one shade of green each\n(circle: first seen; arrows: walking)"),
        *contact_legend_handles(ms=9),
        Line2D([], [], ls="none", ms=8, label="contact with a wall or obstacle", **WALL_MARK),  # type: ignore[arg-type]
        Line2D([], [], ls="none", marker="o", ms=8, mfc="white", mec="k", label="robot's start"),
        Line2D([], [], ls="none", marker="*", ms=12, color="gold", mec="k", label="goal"),
        Line2D([], [], ls="none", marker="s", ms=8, color="0.35", label="obstacles, walls"),
    ]


ENDED_BY = {"goal": "reached the goal", "time_limit": "timed out", "collision": "ended by a contact"}


def path_label(log: EpisodeLog) -> str:
    """``robot path, mpc: reached the goal``: the planner's line and how its episode ended, in words."""
    return f"robot path, {log.planner}: {ENDED_BY.get(log.ended_by, 'ended: ' + log.ended_by)}"


def draw_map(ax: Axes, log: EpisodeLog, colour: str) -> None:
    """One episode on its map: world, people, robot path, contacts, start and goal; the legend below the
    map, outside the scene, so that it covers neither the start nor anyone's path."""
    draw_world(ax, log.world)
    draw_humans(ax, log)
    xy = log.states[:, :2]
    ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=2.0, zorder=4)
    draw_contacts(ax, log)
    ax.plot(*xy[0], marker="o", ms=10, mfc="white", mec="k", zorder=5)
    ax.plot(*log.goal[:2], marker="*", ms=15, color="gold", mec="k", zorder=5)
    ax.legend(handles=legend_handles(colour, path_label(log)), loc="upper center", bbox_to_anchor=(0.5, 0.0),
              borderaxespad=4.0, ncol=2, fontsize=7, frameon=False)


def figure_path(path: str | Path) -> Path:
    """The path of a figure whose format matplotlib writes (by its extension); ValueError otherwise.
    Checked before an episode runs, so that a typo does not cost the run."""
    out = Path(path)
    formats = sorted(Figure().canvas.get_supported_filetypes())
    if out.suffix.lower().lstrip(".") not in formats:
        raise ValueError(f"{out.name}: {out.suffix or 'no extension'} is not a figure format; use one of "
                         f"{', '.join('.' + f for f in formats)}")
    return out


def animation_path(path: str | Path) -> Path:
    """The path of a GIF; ValueError otherwise."""
    out = Path(path)
    if out.suffix.lower() != ".gif":
        raise ValueError(f"animate_episode writes a GIF; give a .gif file name, got {out.name}")
    return out


def plot_episodes(logs: Sequence[EpisodeLog], path: str | Path, title: str | None = None) -> Path:
    """Write the figure (PNG, SVG or PDF by extension; module docstring) and return its path."""
    if not logs:
        raise ValueError("plot_episodes needs at least one episode log")
    out = figure_path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    n = len(logs)
    width = max(7.5, 5.2 * n)
    # the maps' row as high as the widest world needs at the column's width (a corridor is flat), and
    # their legends below them
    aspect = max((log.world.bounds[3] - log.world.bounds[2]) / (log.world.bounds[1] - log.world.bounds[0])
                 for log in logs)
    map_height = min(0.75 * width / n * aspect, 7.0) + 1.5
    fig = plt.figure(figsize=(width, map_height + 4.5))
    grid = fig.add_gridspec(2, n, height_ratios=[map_height, 4.5])
    # the three plots over time in a grid of their own, close together: tight_layout spaces the rows of
    # one grid alike, and the maps' legends below them would pull these apart
    below = grid[1, :].subgridspec(3, 1, hspace=0.12)
    ax_d = fig.add_subplot(below[0])
    ax_v = fig.add_subplot(below[1], sharex=ax_d)
    ax_t = fig.add_subplot(below[2], sharex=ax_d)
    for ax_above in (ax_d, ax_v):
        ax_above.tick_params(labelbottom=False)
    first = logs[0]
    for i, log in enumerate(logs):
        colour = planner_colour(log.planner, i)
        ax = fig.add_subplot(grid[0, i])
        draw_map(ax, log, colour)
        ax.set_title(f"{log.planner}" if n > 1 else (title or f"{first.scenario}, seed {first.seed}"), fontsize=10)
        xy = log.states[:, :2]
        ax_d.plot(log.times, human_distances(xy, log.humans, log.present), color=colour, label=log.planner)
        draw_speed(ax_v, log, colour)
        ax_t.plot(log.times[1:], log.solve_ms, color=colour, label=log.planner)
    if n > 1:
        fig.suptitle(title or f"{first.scenario}, seed {first.seed}")
    r_sum = first.robot.radius + first.robot.human_radius
    ax_d.axhline(D_TH, color="0.5", ls="--", lw=1, label="d_th")
    ax_d.axhline(r_sum, color="k", ls=":", lw=1, label="contact")
    ax_d.set_ylabel("nearest\nhuman [m]", fontsize=9)
    ax_d.set_ylim(0, 4)
    ax_d.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax_v.set_ylabel("speed [m/s]", fontsize=9)
    ax_v.set_ylim(bottom=min(0.0, float(min(np.min(log.states[:, 3]) for log in logs))))
    ax_v.legend(handles=speed_legend_handles(), fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax_t.set_ylabel("planner\ntime [ms]", fontsize=9)
    ax_t.set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def animate_episode(log: EpisodeLog, path: str | Path, fps: int = 10, stride: int = 2) -> Path:
    """Write an animated GIF of the episode (every ``stride``-th step)."""
    out = animation_path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 6))
    draw_world(ax, log.world)
    colour = planner_colour(log.planner)
    ax.plot(*log.goal[:2], marker="*", ms=15, color="gold", mec="k", zorder=5)
    trail, = ax.plot([], [], color=colour, lw=2)
    plan_line, = ax.plot([], [], color=colour, lw=1, ls="--")
    robot = CirclePatch((0, 0), log.robot.radius, color=colour, zorder=6)
    ax.add_patch(robot)
    r_h = log.robot.human_radius
    humans = [CirclePatch((0, 0), r_h, color=c, zorder=5) for c in people_colours(log.humans.shape[1])]
    for h in humans:
        ax.add_patch(h)
    text = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
    frames = list(range(0, log.states.shape[0], stride))

    def update(i: int) -> list:
        robot.center = tuple(log.states[i, :2])
        trail.set_data(log.states[: i + 1, 0], log.states[: i + 1, 1])
        plan = log.plans[i] if i < len(log.plans) else None
        if plan is not None:
            plan_line.set_data(plan[:, 0], plan[:, 1])
        for h, p, here in zip(humans, log.humans[i], log.present[i], strict=True):
            h.set_visible(bool(here))
            if here:
                h.center = tuple(p)
        stop = i < len(log.stops) and bool(log.stops[i])
        text.set_text(f"{log.planner}  t = {log.times[i]:.1f} s" + ("  STOP" if stop else ""))
        return [robot, trail, plan_line, text, *humans]

    anim = FuncAnimation(fig, update, frames=frames, blit=False)
    anim.save(str(out), writer=PillowWriter(fps=fps))
    plt.close(fig)
    return out
