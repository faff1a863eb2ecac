"""Where a campaign's episodes run: in this process, or on a Dask cluster (PyPI ``dask[distributed]``).

- :class:`InProcess`: one after another, here (``--workers 0``; the reference the clusters' rows are
  compared with);
- :class:`DaskEngine`: a local cluster of N worker processes with one thread each (``--workers N``,
  ``distributed.LocalCluster``; the processes are this one's children, so they share its niceness), or an
  existing cluster's scheduler (``--scheduler ADDRESS``, e.g. ``tcp://10.0.0.5:8786``; its workers need
  humanmpc and the campaign extra installed, and build the solver into their own working folder's cache).

Both hand back results as they finish, in any order. A task that raises is a :class:`TaskFailedError` naming
the episode, the exception and where it ran; the results finished before it have been handed back.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol

from .campaign import EpisodeTask
from .worker import EpisodeResult


class TaskFailedError(RuntimeError):
    """An episode raised on a worker; the message names it."""


class CampaignEngineError(RuntimeError):
    """A cluster that cannot be used (no Dask installed, a scheduler that does not answer)."""


TaskFunction = Callable[[EpisodeTask], EpisodeResult]


class Engine(Protocol):
    name: str
    workers: int
    startup_s: float

    def run(self, fn: TaskFunction, tasks: Sequence[EpisodeTask]) -> Iterator[EpisodeResult]: ...

    def close(self) -> None: ...


class InProcess:
    """Every episode here, one after another."""

    name = "this process"

    def __init__(self) -> None:
        self.workers = 1
        self.startup_s = 0.0

    def run(self, fn: TaskFunction, tasks: Sequence[EpisodeTask]) -> Iterator[EpisodeResult]:
        for task in tasks:
            try:
                result = fn(task)
            except Exception as err:
                raise TaskFailedError(f"episode {task.key} failed here: {type(err).__name__}: {err}") from err
            yield result

    def close(self) -> None:
        pass


def _dask() -> tuple[Any, Any, Any]:
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError as err:
        raise CampaignEngineError(f"running episodes on Dask needs dask[distributed] ({err}): pip install "
                                  "'humanmpc[campaign]', or --workers 0 to run them in this process") from None
    return Client, LocalCluster, as_completed


class DaskEngine:
    """A local Dask cluster of ``workers`` processes, or the cluster of ``scheduler`` (module docstring)."""

    def __init__(self, workers: int = 2, scheduler: str | None = None, connect_timeout: float = 20.0) -> None:
        Client, LocalCluster, _ = _dask()
        t0 = time.perf_counter()
        self._cluster: Any = None
        if scheduler is not None:
            try:
                self.client = Client(scheduler, timeout=f"{connect_timeout}s")
            except (OSError, TimeoutError, ValueError) as err:
                raise CampaignEngineError(
                    f"--scheduler {scheduler}: no Dask scheduler answered ({type(err).__name__}: {err}). Start one "
                    "(dask scheduler) and its workers (dask worker ADDRESS) where humanmpc is installed, or give "
                    "--workers N for a local cluster") from None
            self.workers = len(self.client.scheduler_info().get("workers", {}))
            self.name = f"the Dask cluster at {scheduler}"
        else:
            if workers < 1:
                raise CampaignEngineError(f"a local Dask cluster needs --workers >= 1, got {workers}")
            self._cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                         dashboard_address=None, silence_logs=logging.ERROR)
            self.client = Client(self._cluster)
            self.workers = workers
            self.name = f"a local Dask cluster of {workers} worker process{'es' if workers > 1 else ''}"
        self.startup_s = time.perf_counter() - t0

    def run(self, fn: TaskFunction, tasks: Sequence[EpisodeTask]) -> Iterator[EpisodeResult]:
        _, _, as_completed = _dask()
        if not tasks:
            return
        futures = self.client.map(fn, list(tasks), pure=False)
        which = {f.key: t for f, t in zip(futures, tasks, strict=True)}
        try:
            for future in as_completed(futures):
                if future.status == "error":
                    task = which[future.key]
                    err = future.exception()
                    raise TaskFailedError(f"episode {task.key} failed on a worker of {self.name}: "
                                     f"{type(err).__name__}: {err}")
                yield future.result()
                future.release()
        finally:
            self.client.cancel([f for f in futures if not f.done()])

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()


def make_engine(workers: int, scheduler: str | None = None) -> Engine:
    """``--scheduler`` given: that cluster; else ``workers`` >= 1: a local Dask cluster; 0: this process."""
    if scheduler is not None:
        return DaskEngine(scheduler=scheduler)
    return InProcess() if workers == 0 else DaskEngine(workers)
