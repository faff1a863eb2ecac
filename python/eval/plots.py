"""Figures of episodes in the spirit of the paper's (headless, Agg backend).

* :func:`plot_episodes`: robot paths of one or more planners on the same scenario (MPC red,
  DWB blue), human tracks with time-faded markers, obstacles, start and goal; below, the
  distance to the nearest human and the planner time over time.
* :func:`animate_episode`: an animated GIF of one episode (pillow writer).

Simulated humans react to the robot, so their tracks differ between planners (recorded ones do
not); the map shows the tracks of the first log given.
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
from matplotlib.patches import Circle as CirclePatch
from matplotlib.patches import Polygon as PolygonPatch

from ..sim.world import World
from .episode import EpisodeLog
from .metrics import D_TH, human_distances

PLANNER_COLOURS = {"mpc": "tab:red", "dwb": "tab:blue", "mpc_paper": "tab:orange"}
_OTHER = ["tab:green", "tab:purple", "tab:orange", "tab:brown"]


def planner_colour(name: str, index: int = 0) -> str:
    return PLANNER_COLOURS.get(name, _OTHER[index % len(_OTHER)])


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


def draw_humans(ax: Axes, log: EpisodeLog, every: int = 5) -> None:
    """Human tracks as markers fading from light (start) to dark (end), each person's disc where
    they were first seen (people absent at a sample have no marker there)."""
    T, k = log.humans.shape[:2]
    if k == 0:
        return
    idx = np.arange(0, T, every)
    alpha = 0.15 + 0.75 * idx / max(T - 1, 1)
    cmap = plt.get_cmap("tab10")
    present = log.present
    for i in range(k):
        seen = present[idx, i]
        if not np.any(present[:, i]):
            continue
        colour = np.array(cmap(i % 10))
        rgba = np.tile(colour, (int(np.count_nonzero(seen)), 1))
        rgba[:, 3] = alpha[seen]
        ax.scatter(log.humans[idx[seen], i, 0], log.humans[idx[seen], i, 1], s=12, c=rgba, edgecolors="none",
                   zorder=3)
        first = log.humans[int(np.argmax(present[:, i])), i]
        ax.add_patch(CirclePatch(first, log.robot.human_radius, fill=False, ec=colour, lw=1.0, zorder=3))


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
    """Write the paths figure (PNG, SVG or PDF by extension) and return its path."""
    if not logs:
        raise ValueError("plot_episodes needs at least one episode log")
    out = figure_path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig = plt.figure(figsize=(7.5, 10.0))
    grid = fig.add_gridspec(3, 1, height_ratios=[3.2, 1, 1])
    ax = fig.add_subplot(grid[0])
    ax_d = fig.add_subplot(grid[1])
    ax_t = fig.add_subplot(grid[2], sharex=ax_d)
    first = logs[0]
    draw_world(ax, first.world)
    draw_humans(ax, first)
    for n, log in enumerate(logs):
        colour = planner_colour(log.planner, n)
        xy = log.states[:, :2]
        ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=2.0, label=f"{log.planner} ({log.ended_by})", zorder=4)
        d = human_distances(xy, log.humans, log.present)
        ax_d.plot(log.times, d, color=colour, label=log.planner)
        ax_t.plot(log.times[1:], log.solve_ms, color=colour, label=log.planner)
    start, goal = first.states[0], first.goal
    ax.plot(*start[:2], marker="o", ms=10, mfc="white", mec="k", zorder=5, label="start")
    ax.plot(*goal[:2], marker="*", ms=15, color="gold", mec="k", zorder=5, label="goal")
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(title or f"{first.scenario}, seed {first.seed}")
    r_sum = first.robot.radius + first.robot.human_radius
    ax_d.axhline(D_TH, color="0.5", ls="--", lw=1, label="d_th")
    ax_d.axhline(r_sum, color="k", ls=":", lw=1, label="contact")
    ax_d.set_ylabel("nearest human [m]")
    ax_d.set_ylim(0, 4)
    ax_d.legend(fontsize=7, loc="upper right")
    ax_t.set_ylabel("planner time [ms]")
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
    humans = [CirclePatch((0, 0), r_h, color="tab:gray", zorder=5) for _ in range(log.humans.shape[1])]
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
