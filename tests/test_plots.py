"""The episode figure reads at a glance: the legend outside the scene, every mark explained, wall contacts
marked like people's."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from humanmpc.eval.episode import run_episode
from humanmpc.eval.metrics import compute_metrics
from humanmpc.eval.plots import ENDED_BY, draw_map, path_label, wall_contact_starts
from humanmpc.planners.interface import Observation, PlanResult
from humanmpc.sim.scenarios import make_scenario


class Veer:
    """Drives at 0.5 m/s on a circle of 1 m radius to the left: into the corridor's wall."""

    name = "veer"

    def reset(self) -> None:
        pass

    def plan(self, obs: Observation) -> PlanResult:
        return PlanResult(u=np.array([(0.5 - obs.x[3]) / obs.dt, 0.5]))


def test_wall_contacts_are_found_and_drawn_with_the_legend_below_the_map() -> None:
    log = run_episode(make_scenario("corridor", 0), Veer())
    walls = wall_contact_starts(log)
    assert walls.size >= 1 and walls.size == compute_metrics(log).obstacle_collisions
    fig, ax = plt.subplots()
    draw_map(ax, log, "tab:red")
    fig.canvas.draw()
    legend = ax.get_legend()
    labels = [t.get_text() for t in legend.get_texts()]
    assert "contact with a wall or obstacle" in labels
    assert any(label.startswith("people, one shade") for label in labels)
    assert labels[0] == path_label(log) and log.planner in labels[0] and "(" not in labels[0]
    # the legend lies below the scene (its top under the axes' bottom): it covers neither start nor paths
    assert legend.get_window_extent().y1 <= ax.get_window_extent().y0
    wall_marks = [line for line in ax.get_lines() if line.get_marker() == "s" and line.get_xdata().size]
    assert wall_marks and len(wall_marks[0].get_xdata()) == walls.size
    plt.close(fig)


def test_path_label_says_how_the_episode_ended_in_words() -> None:
    assert set(ENDED_BY) == {"goal", "time_limit", "collision"}  # every way an episode ends
    log = run_episode(make_scenario("corridor", 0), Veer())
    assert path_label(log) == f"robot path, veer: {ENDED_BY[log.ended_by]}"
