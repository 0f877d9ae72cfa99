"""Run independent tasks serially, on a local Dask cluster, or on a Dask scheduler at an address.

``run_tasks(fn, tasks, scheduler, workers, shared)`` returns ``[fn(t, shared) for t in tasks]`` in
task order whichever runs them, so a caller that merges the results in that order gets the same
answer from every scheduler (the pair-block binning of :mod:`.blocks`, the grouped solve of
:mod:`.scale_solve`). ``shared`` is sent once to every worker (``Client.scatter(broadcast=True)``)
instead of with every task.

Schedulers: None = serial in this process; ``"local"`` = ``dask.distributed.LocalCluster`` with
``workers`` single-threaded worker processes (one task per core, BLAS in each worker single-threaded
too, so 2 workers use 2 cores); ``"tcp://host:port"`` (or any address ``Client`` takes) = that
scheduler's workers.
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Callable, Iterator, Sequence
from typing import Any

SCHEDULER_HELP = "None/serial, 'local' (a LocalCluster of --workers processes) or a scheduler address"

#: Keep BLAS single-threaded in the worker processes (one task per core).
_WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


class SchedulerError(Exception):
    """The scheduler option names nothing we can run on, or the cluster failed to start."""


def check_scheduler(scheduler: str | None) -> str | None:
    """The scheduler option normalised (``serial``/empty → None); raises SchedulerError if unknown."""
    if scheduler in (None, "", "serial", "none"):
        return None
    if scheduler == "local" or "://" in str(scheduler):
        return str(scheduler)
    raise SchedulerError(f"--scheduler {scheduler!r}: expected 'local' or an address like tcp://host:8786")


@contextlib.contextmanager
def dask_client(scheduler: str, workers: int = 2) -> Iterator[Any]:
    """A ``dask.distributed.Client`` on ``scheduler`` (a LocalCluster for ``"local"``), closed after."""
    try:
        from dask.distributed import Client, LocalCluster  # noqa: PLC0415 - optional dependency
    except ImportError as exc:  # pragma: no cover - dask is in requirements.txt
        raise SchedulerError(f"dask.distributed is not installed ({exc})") from exc
    if scheduler == "local":
        if workers < 1:
            raise SchedulerError(f"--workers {workers}: need at least 1")
        old = {k: os.environ.get(k) for k in _WORKER_ENV}
        os.environ.update(_WORKER_ENV)  # inherited by the spawned worker processes
        try:
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
        finally:
            for k, v in old.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
    else:
        try:
            client = Client(scheduler, timeout="20s")
        except OSError as exc:
            raise SchedulerError(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from exc
        try:
            yield client
        finally:
            client.close()


def run_tasks(
    fn: Callable[[Any, Any], Any],
    tasks: Sequence[Any],
    scheduler: str | None = None,
    workers: int = 2,
    shared: Any = None,
    client: Any = None,
) -> list[Any]:
    """``[fn(task, shared) for task in tasks]`` on ``scheduler`` (module docstring), in task order.

    ``client``: an open ``dask.distributed.Client`` to use instead of starting one (then
    ``scheduler``/``workers`` are ignored).
    """
    if client is None:
        scheduler = check_scheduler(scheduler)
        if scheduler is None:
            return [fn(t, shared) for t in tasks]
        with dask_client(scheduler, workers) as c:
            return run_tasks(fn, tasks, shared=shared, client=c)
    if not tasks:
        return []
    # a list is scattered element by element: wrap it so the whole object is one future
    sh = client.scatter([shared], broadcast=True)[0] if shared is not None else None
    futures = client.map(fn, list(tasks), shared=sh, pure=False)
    return list(client.gather(futures))
