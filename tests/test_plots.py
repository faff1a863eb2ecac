"""The episode figure reads at a glance: the legend outside the scene, every mark explained, wall contacts
marked like people's, the robot's speed with its stops and contacts."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from humanmpc.eval.episode import run_episode
from humanmpc.eval.metrics import compute_metrics
from humanmpc.eval.plots import ENDED_BY, contact_starts, draw_map, draw_speed, path_label, wall_contact_starts
from humanmpc.planners.interface import Observation, PlanResult
from humanmpc.sim.scenarios import make_scenario


class Veer:
    """Drives at 0.5 m/s on a circle of 1 m radius to the left: into the corridor's wall."""

    name = "veer"

    def reset(self) -> None:
        pass

    def plan(self, obs: Observation) -> PlanResult:
        return PlanResult(u=np.array([(0.5 - obs.x[3]) / obs.dt, 0.5]))


class Charge:
    """Drives straight up at 0.8 m/s through whoever is there, and brakes in a protective stop from 2 to 3 s."""

    name = "charge"

    def reset(self) -> None:
        pass

    def plan(self, obs: Observation) -> PlanResult:
        stop = 2.0 - 1e-9 <= obs.time < 3.0 - 1e-9
        a = -1.0 if stop and obs.x[3] > 0.0 else 0.0 if stop else (0.8 - obs.x[3]) / obs.dt
        return PlanResult(u=np.array([a, 0.0]), stop=stop, reason="test" if stop else None)


def test_the_speed_plot_shades_the_protective_stops_and_marks_the_contacts_where_they_start() -> None:
    # one scene where it runs into people (the robot's fault), one where someone walks into it
    for scene, seed in (("crowdnav_circle_20", 0), ("circle_crossing", 1)):
        log = run_episode(make_scenario(scene, seed), Charge())
        robot, person = contact_starts(log)
        assert robot.size + person.size >= 1, f"{scene}: no contact, the marks are not tested"
        fig, ax = plt.subplots()
        draw_speed(ax, log, "tab:red")
        # in data coordinates whatever patch axvspan makes (a Polygon before matplotlib 3.9, a Rectangle since)
        spans = [ax.transData.inverted().transform(patch.get_verts())[:, 0] for patch in ax.patches]
        assert len(spans) == 1  # the ten periods of the stop, their last included, no more
        assert np.isclose(spans[0].min(), 2.0) and np.isclose(spans[0].max(), 3.0)
        marks = {line.get_markerfacecolor(): line for line in ax.get_lines() if line.get_marker() == "X"}
        for fault, starts in (("black", robot), ("white", person)):
            if starts.size:
                assert np.allclose(marks[fault].get_xdata(), log.times[starts])
                assert np.allclose(marks[fault].get_ydata(), log.states[starts, 3])
            else:
                assert fault not in marks
        plt.close(fig)


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
