"""Recorded pedestrians (ETH / UCY) replayed as a non-reactive crowd.

A recording file has whitespace-separated rows ``frame pedestrian_id x y`` (two more columns,
a velocity estimate, are ignored), positions in metres in a fixed world frame, annotations
``ANNOTATION_PERIOD`` = 0.4 s apart (``../shared/data/pedestrians/README.md``). The video's
frame rate differs between files (15 frames per second in ``biwi_eth``, 25 in the others), so
the frames per annotation are read from the data: the smallest step between two annotations of
one pedestrian. A recording's time is ``(frame - first frame) * 0.4 s / frames per annotation``.

**Tracks.** One pedestrian's annotations, in frame order, split wherever two consecutive ones
are more than one annotation apart (the person was not seen in between: where they were is not
known, so they are absent). A track is a continuous stretch, and its index in the recording is
the id the crowd and the predictor see: a pedestrian who reappears after a gap is a new person
to them, with no velocity history.

**Presence and interpolation.** A track's person is present from its first annotation to its
last, both included (a track of a single annotation is present at that instant only), and moves
linearly between consecutive annotations, so a replay can be sampled at any period (the control
period, 0.1 s). Outside that interval the person is absent: they are not in the crowd's
``positions`` at all (no placeholder position).

**Replay.** :class:`RecordedCrowd` plays a recording from a start time ``t0`` on; people move as
recorded, whatever the robot does (``step`` ignores the robot). Its time is kept as a step count
times the period, so long episodes do not drift off the annotation instants.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

ANNOTATION_PERIOD = 0.4  # s between two annotations of a pedestrian (the README's 2.5 Hz)
PEDESTRIANS_ENV = "HUMANMPC_PEDESTRIANS"  # folder with the recording files, if not the default
_TIME_TOL = 1e-6  # s: instants closer than this are the same instant


@dataclass(frozen=True)
class Recording:
    """The tracks of one recorded scene.

    ``start[i]`` is the time of track i's first annotation (s), ``count[i]`` its number of
    annotations, ``xy[i, :count[i]]`` their positions (m); entries beyond ``count[i]`` are NaN.
    ``pedestrian[i]`` is the file's pedestrian id of track i.
    """

    name: str
    start: FloatArray  # (n,)
    count: IntArray  # (n,)
    xy: FloatArray  # (n, L, 2)
    pedestrian: IntArray  # (n,)
    period: float = ANNOTATION_PERIOD
    _end: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        n = self.start.shape[0]
        if self.start.shape != (n,) or self.count.shape != (n,) or self.pedestrian.shape != (n,):
            raise ValueError("Recording: start, count and pedestrian must have one entry per track")
        if self.xy.ndim != 3 or self.xy.shape[0] != n or self.xy.shape[2] != 2:
            raise ValueError(f"Recording: xy must have shape (tracks, length, 2), got {self.xy.shape}")
        if n and (np.any(self.count < 1) or int(self.count.max()) > self.xy.shape[1]):
            raise ValueError("Recording: every track needs between 1 and xy.shape[1] annotations")
        if not self.period > 0:
            raise ValueError(f"Recording: the annotation period must be > 0 s, got {self.period}")
        object.__setattr__(self, "_end", self.start + (self.count - 1) * self.period)

    @property
    def size(self) -> int:
        """Number of tracks."""
        return int(self.start.shape[0])

    @property
    def end(self) -> FloatArray:
        """Time of every track's last annotation (s), (n,)."""
        return self._end.copy()

    @property
    def duration(self) -> tuple[float, float]:
        """First and last annotated instant of the recording (s)."""
        if self.size == 0:
            return (0.0, 0.0)
        return float(self.start.min()), float(self._end.max())

    def annotations(self) -> FloatArray:
        """Every annotated position of every track, (total, 2) (m)."""
        keep = np.arange(self.xy.shape[1])[None, :] < self.count[:, None]
        return self.xy[keep]

    def present(self, t: float | ArrayLike) -> NDArray[np.bool_]:
        """Which tracks are present at time(s) ``t``: shape ``t.shape + (n,)``."""
        tt = np.asarray(t, dtype=float)[..., None]
        return (self.start - _TIME_TOL <= tt) & (tt <= self._end + _TIME_TOL)

    def at(self, t: float) -> tuple[IntArray, FloatArray]:
        """The ids (track indices, increasing) of the people present at ``t`` and their
        positions, linearly interpolated between annotations: ``(k,)`` and ``(k, 2)``."""
        ids = np.nonzero(self.present(t))[0].astype(np.int64)
        u = np.clip((float(t) - self.start[ids]) / self.period, 0.0, (self.count[ids] - 1).astype(float))
        k0 = np.minimum(np.floor(u).astype(np.int64), np.maximum(self.count[ids] - 2, 0))
        k1 = np.minimum(k0 + 1, self.count[ids] - 1)
        frac = (u - k0)[:, None]
        pos = (1.0 - frac) * self.xy[ids, k0] + frac * self.xy[ids, k1]
        return ids, pos


def parse_recording(text: str, name: str = "recording", period: float = ANNOTATION_PERIOD) -> Recording:
    """The tracks of a recording file's text (format in the module docstring).

    ``ValueError`` naming the line for a row that is not ``frame id x y [...]`` with integer
    frame and id and finite positions, for a pedestrian annotated twice in one frame, and for
    annotation steps that are not whole multiples of the smallest one.
    """
    rows: list[tuple[int, int, float, float]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = line.split()
        if not fields or fields[0].startswith("#"):
            continue
        try:
            if len(fields) < 4:
                raise ValueError("fewer than 4 columns")
            frame_f, pid_f, x, y = (float(v) for v in fields[:4])
            if frame_f != round(frame_f) or pid_f != round(pid_f):
                raise ValueError("frame and pedestrian id must be integers")
            if not (np.isfinite(x) and np.isfinite(y)):
                raise ValueError("positions must be finite")
        except ValueError as err:
            raise ValueError(f"{name}: line {number}: {err} (expected 'frame pedestrian_id x y'): {line.strip()!r}") \
                from None
        rows.append((round(frame_f), round(pid_f), x, y))
    if not rows:
        raise ValueError(f"{name}: no annotation rows")
    data = np.array([(f, p) for f, p, _, _ in rows], dtype=np.int64)
    pos = np.array([(x, y) for _, _, x, y in rows], dtype=float)
    order = np.lexsort((data[:, 0], data[:, 1]))  # by pedestrian, then frame
    data, pos = data[order], pos[order]
    same_pid = data[1:, 1] == data[:-1, 1]
    steps = np.diff(data[:, 0])[same_pid]
    if np.any(steps == 0):
        pid = int(data[1:, 1][same_pid][steps == 0][0])
        raise ValueError(f"{name}: pedestrian {pid} is annotated twice in one frame")
    if steps.size == 0:  # nobody annotated twice: one annotation period per frame step
        per_annotation = 1
    else:
        per_annotation = int(steps.min())
        if np.any(steps % per_annotation):
            raise ValueError(f"{name}: annotation steps {sorted(set(steps.tolist()))[:5]} (frames) are not whole "
                             f"multiples of the smallest one, {per_annotation}")
    first_frame = int(data[:, 0].min())
    # a new track at every new pedestrian and at every gap
    new_track = np.concatenate([[True], ~same_pid | (np.diff(data[:, 0]) != per_annotation)])
    track_of_row = np.cumsum(new_track) - 1
    n = int(track_of_row[-1]) + 1
    heads = np.nonzero(new_track)[0]
    count = np.diff(np.append(heads, len(data))).astype(np.int64)
    xy = np.full((n, int(count.max()), 2), np.nan)
    xy[track_of_row, np.arange(len(data)) - heads[track_of_row]] = pos
    start = (data[heads, 0] - first_frame) / per_annotation * period
    return Recording(name, start.astype(float), count, xy, data[heads, 1].astype(np.int64), period)


def pedestrian_data_dir() -> Path:
    """The folder of the recording files: ``$HUMANMPC_PEDESTRIANS`` if set, else the repository's
    sibling ``shared/data/pedestrians`` (``FileNotFoundError`` saying where it looked)."""
    env = os.environ.get(PEDESTRIANS_ENV)
    shared = Path("shared", "data", "pedestrians")
    # the source checkout's sibling folder (an editable install), then the working directory's
    checkout = Path(__file__).resolve().parents[2]
    candidates = [Path(env)] if env else [checkout.parent / shared, Path.cwd().parent / shared]
    for folder in candidates:
        if folder.is_dir():
            return folder
    if env:
        where = f"${PEDESTRIANS_ENV} is {env!r}, which is not a folder"
    else:
        unique = list(dict.fromkeys(str(c) for c in candidates))  # from the checkout, both are the same
        where = f"{PEDESTRIANS_ENV} is not set, and there is no folder {' or '.join(unique)}"
    raise FileNotFoundError(
        "the recorded pedestrian trajectories were not found: " + where + ". They are the ETH/UCY recordings "
        "(biwi_eth.txt and biwi_hotel.txt of the BIWI Walking Pedestrians dataset, crowds_zara01.txt of UCY's "
        "Crowds by Example, as redistributed for trajectory-prediction research); "
        f"set {PEDESTRIANS_ENV} to the folder that holds them"
    )


@functools.lru_cache(maxsize=8)
def load_recording(name: str) -> Recording:
    """The recording ``<name>.txt`` of the pedestrian data folder (cached per process)."""
    path = pedestrian_data_dir() / f"{name}.txt"
    if not path.is_file():
        raise FileNotFoundError(f"recording {name!r}: {path} does not exist")
    return parse_recording(path.read_text(), name)


@dataclass(frozen=True)
class RecordedCrowdSpec:
    """A replay: ``recording`` played from its time ``t0`` (s) on, which is the episode's time 0."""

    recording: Recording
    t0: float

    @property
    def ids(self) -> IntArray:
        """Ids of the people present at the episode's start."""
        return self.recording.at(self.t0)[0]

    @property
    def positions(self) -> FloatArray:
        """Positions of the people present at the episode's start, (k, 2)."""
        return self.recording.at(self.t0)[1]


class RecordedCrowd:
    """The running replay of a :class:`RecordedCrowdSpec`, one period ``dt`` per :meth:`step`.

    Implements :class:`~humanmpc.sim.crowd.HumanCrowd`: ``ids`` and ``positions`` are those of
    the people present now (their number changes as people enter and leave).
    """

    def __init__(self, spec: RecordedCrowdSpec, dt: float = 0.1) -> None:
        if not dt > 0:
            raise ValueError(f"RecordedCrowd: the period must be > 0 s, got {dt}")
        self.spec = spec
        self.dt = float(dt)
        self._steps = 0
        self._ids, self._pos = spec.recording.at(spec.t0)

    @property
    def time(self) -> float:
        """Time since the replay started (s)."""
        return self._steps * self.dt

    @property
    def ids(self) -> IntArray:
        return self._ids.copy()

    @property
    def positions(self) -> FloatArray:
        return self._pos.copy()

    def step(self, robot_position: ArrayLike | None = None, robot_velocity: ArrayLike | None = None) -> None:
        """Advance by one period. The people do not react to the robot: its state is ignored."""
        self._steps += 1
        self._ids, self._pos = self.spec.recording.at(self.spec.t0 + self._steps * self.dt)
