"""Run independent tasks serially, on local processes, on a local Dask cluster or on a Dask scheduler
at an address: the one fan-out of realbench, ``radiomap build`` and ``crowd fit``.

``TaskRunner.map(fn, tasks)`` returns ``[fn(t) for t in tasks]`` (``[fn(t, shared) ...]`` when
``shared`` is given) in task order whichever scheduler ran them, so a caller that merges the results
in that order gets the same answer from every scheduler; ``on_result(i, result)`` sees each result as
it arrives (the progress lines). On Dask ``shared`` is sent once to every worker
(``Client.scatter(broadcast=True)``) instead of with every task; the process pool pickles it with every
chunk of ``chunksize`` tasks (one chunk = one submission, fewer round trips for short tasks).

Schedulers (``--scheduler``, :data:`SCHEDULER_HELP`):

* ``serial`` (None): in this process. Each task and its result cross a pickle as they would to and
  from a worker, so a task that changes its input changes it for no later task, as in a worker;
* ``processes``: a ``concurrent.futures.ProcessPoolExecutor`` of ``workers`` forked processes (no
  start-up cost; realbench's default on one machine);
* ``local``: a ``dask.distributed.LocalCluster`` of ``workers`` single-threaded worker processes (BLAS
  in each worker single-threaded too, so 2 workers use 2 cores); its scheduler, workers and dashboard
  listen on loopback only (:data:`LOOPBACK`), since a Dask client can run any function on a worker;
* ``tcp://host:port`` (or any address ``Client`` takes): that scheduler's workers, however many.

A Dask worker runs the task functions of this package by name and reads and writes files by path, so
every worker needs the same ``stridefix`` package (same Python, dask and distributed versions), the
same ``stridefixd`` build, the input data and the output folder at the same paths as this process.
:func:`check_workers` asks every worker before the first task (:class:`WorkerFiles`: which paths must
exist, which folders must be writable, which files must be byte-identical) and raises
:class:`SchedulerError` naming the worker and the path.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import dataclasses
import hashlib
import logging
import os
import pickle
from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any

SCHEDULERS = ("serial", "processes", "local")
SCHEDULER_HELP = (
    "serial (this process), processes (a pool of --workers local processes), local (a Dask "
    "LocalCluster of --workers processes) or a Dask scheduler address tcp://HOST:PORT"
)
#: what a worker that lacks the files is told to provide (docs/scale-out.md)
NEEDS = (
    "Dask workers need the same stridefix package, stridefixd build, input data and output folder at the "
    "same paths as this machine (docs/scale-out.md)"
)

#: Keep BLAS single-threaded in the worker processes (one task per core).
_WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
#: Dask submissions in flight per worker: enough to keep each busy, few enough that the scheduler
#: never holds every task of a long run (a fold task carries its group's radio-map statistics)
_IN_FLIGHT_PER_WORKER = 4
#: where ``--scheduler local`` listens (scheduler, workers, dashboard): this machine only
LOOPBACK = "127.0.0.1"
_UNSET: Any = object()


class SchedulerError(Exception):
    """The scheduler option names nothing we can run on, the cluster failed to start, or a worker
    lacks what the tasks need."""


def check_scheduler(scheduler: str | None) -> str | None:
    """The scheduler option normalised (``serial``/empty → None); raises SchedulerError if unknown."""
    if scheduler in (None, "", "serial", "none"):
        return None
    if scheduler in SCHEDULERS or is_remote(scheduler):
        return str(scheduler)
    raise SchedulerError(
        f"--scheduler {scheduler!r}: expected serial, processes, local or an address like tcp://host:8786"
    )


def is_remote(scheduler: str | None) -> bool:
    """A scheduler address (its workers may run elsewhere: every path the tasks see must be absolute)."""
    return bool(scheduler) and "://" in str(scheduler)


#: Worker processes of every command's ``--jobs``/``--workers`` (realbench pdr-distance took
#: the CPU count, the others 2): the development machine's 2 cores; a bigger one says -j N.
DEFAULT_JOBS = 2


def add_jobs_argument(parser: Any, help_text: str, dest: str = "jobs") -> None:
    """Declare ``--jobs``/``-j``/``--workers N`` (the same spellings and default on every command)."""
    parser.add_argument(
        "--jobs",
        "-j",
        "--workers",
        dest=dest,
        type=int,
        default=DEFAULT_JOBS,
        metavar="N",
        help=f"{help_text} (default {DEFAULT_JOBS})",
    )


def add_scheduler_argument(parser: Any, default: str = "serial") -> None:
    """Declare ``--scheduler`` on ``parser`` (the worker count is each command's own option)."""
    parser.add_argument(
        "--scheduler",
        default=default,
        metavar="serial|processes|local|tcp://HOST:PORT",
        help=f"where the tasks run: {SCHEDULER_HELP} (default {default}; results are identical on every one)",
    )


@dataclasses.dataclass(frozen=True)
class WorkerFiles:
    """What the tasks read and write by path, checked on every Dask worker (:func:`check_workers`)."""

    #: files or folders that must exist (the input data, the stridefixd binary)
    read: Sequence[str | os.PathLike[str]] = ()
    #: folders that must exist and be writable (the output folder, the import cache)
    write: Sequence[str | os.PathLike[str]] = ()
    #: files whose bytes must equal this machine's (the stridefixd build: another build gives other results)
    same: Sequence[str | os.PathLike[str]] = ()


def _sha256(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def worker_problems(files: WorkerFiles, digests: dict[str, str]) -> list[str]:
    """What this machine lacks of ``files`` (``digests``: path → the client's SHA-256), one line each;
    runs on a worker (and in the tests)."""
    out = [
        f"missing {p}" for p in map(str, (*files.read, *files.write, *files.same)) if not os.path.exists(p)
    ]
    out += [
        f"cannot write into {p}"
        for p in map(str, files.write)
        if os.path.exists(p) and not os.access(p, os.W_OK)
    ]
    for p, want in digests.items():
        if os.path.isfile(p) and _sha256(p) != want:
            out.append(f"{p} differs from the client's (another build)")
    return out


def check_workers(client: Any, files: WorkerFiles) -> None:
    """Raise SchedulerError naming each worker of ``client`` that cannot run the tasks: the package
    does not import there, or a path of ``files`` is missing, unwritable or another build."""
    digests = {str(p): _sha256(str(p)) for p in files.same if os.path.isfile(p)}
    try:
        seen = client.run(worker_problems, files, digests)
    except Exception as exc:  # noqa: BLE001 - whatever a worker raised: it cannot import or run us
        raise SchedulerError(
            f"the Dask workers cannot run stridefix_analyzer tasks ({exc!r}); {NEEDS}"
        ) from exc
    if not seen:
        raise SchedulerError(f"the Dask scheduler {client.scheduler.address} has no workers")
    bad = {w: p for w, p in sorted(seen.items()) if p}
    if bad:
        lines = "; ".join(f"worker {w}: {', '.join(p)}" for w, p in bad.items())
        raise SchedulerError(f"{lines}. {NEEDS}")


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
            # Loopback only, dashboard included: whoever reaches a Dask scheduler can run any function
            # on its workers, as this user. No fixed port: two clusters at once must not collide.
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                host=LOOPBACK,
                dashboard_address=f"{LOOPBACK}:0",
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


def _run_chunk(fn: Callable[..., Any], items: Sequence[Any], shared: Any, pass_shared: bool) -> list[Any]:
    """One submission: ``fn`` over consecutive tasks (module level, so workers unpickle it by name)."""
    return [fn(t, shared) if pass_shared else fn(t) for t in items]


def _copy(obj: Any) -> Any:
    return pickle.loads(pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL))


class TaskRunner:
    """Where the tasks of one run go (module docstring); reuse it for every phase of the run (one
    cluster start, one process pool). Build it with :func:`task_runner`."""

    def __init__(self, scheduler: str | None, workers: int, client: Any = None, pool: Any = None) -> None:
        self.scheduler, self.workers, self.client, self.pool = scheduler, workers, client, pool

    def describe(self) -> str:
        """``serial``, ``processes x2``, ``local x2`` or the scheduler address (progress lines)."""
        if self.client is not None and self.scheduler not in (None, "local"):
            return str(self.scheduler or "client")
        return "serial" if self.scheduler is None else f"{self.scheduler} x{self.workers}"

    def map(
        self,
        fn: Callable[..., Any],
        tasks: Iterable[Any],
        shared: Any = _UNSET,
        on_result: Callable[[int, Any], None] | None = None,
        chunksize: int = 1,
    ) -> list[Any]:
        """``[fn(t) for t in tasks]`` (``fn(t, shared)`` when ``shared`` is given) in task order;
        ``on_result(i, r)`` for each as it arrives. A task's exception is raised here."""
        tasks = list(tasks)
        pass_shared = shared is not _UNSET
        shared = None if shared is _UNSET else shared
        chunks = [tasks[i : i + max(1, chunksize)] for i in range(0, len(tasks), max(1, chunksize))]
        starts = [i * max(1, chunksize) for i in range(len(chunks))]
        out: list[Any] = [None] * len(tasks)

        def take(k: int, results: list[Any]) -> None:
            for j, r in enumerate(results):
                out[starts[k] + j] = r
                if on_result:
                    on_result(starts[k] + j, r)

        if not chunks:
            return out
        if self.client is not None:
            self._dask(chunks, fn, shared, pass_shared, take)
        elif self.pool is not None:
            futs = {self.pool.submit(_run_chunk, fn, c, shared, pass_shared): k for k, c in enumerate(chunks)}
            try:
                for fut in concurrent.futures.as_completed(futs):
                    take(futs[fut], fut.result())
            except BaseException:
                for fut in futs:
                    fut.cancel()
                raise
        else:
            for k, c in enumerate(chunks):
                take(k, _copy(_run_chunk(fn, _copy(c), shared, pass_shared)))
        return out

    def _dask(
        self,
        chunks: list[list[Any]],
        fn: Callable[..., Any],
        shared: Any,
        pass_shared: bool,
        take: Callable[[int, list[Any]], None],
    ) -> None:
        from dask.distributed import as_completed  # noqa: PLC0415 - optional dependency

        c = self.client
        # a list is scattered element by element: wrap it so the whole object is one future; a key of
        # its own (hash=False): an equal object scattered by the previous map may still be released
        sh = (
            c.scatter([shared], broadcast=True, hash=False)[0]
            if pass_shared and shared is not None
            else shared
        )
        n_workers = max(1, len(c.scheduler_info().get("workers", {})))
        window = _IN_FLIGHT_PER_WORKER * n_workers
        index: dict[Any, int] = {}

        def submit(k: int) -> Any:
            f = c.submit(_run_chunk, fn, chunks[k], sh, pass_shared, pure=False)
            index[f] = k
            return f

        first = [submit(k) for k in range(min(window, len(chunks)))]
        pending = as_completed(first)
        nxt = len(first)
        try:
            for f in pending:
                k = index.pop(f)
                take(k, f.result())
                if nxt < len(chunks):
                    pending.add(submit(nxt))
                    nxt += 1
        except BaseException:
            c.cancel(list(index))
            raise


@contextlib.contextmanager
def task_runner(
    scheduler: str | None = None,
    workers: int = 2,
    files: WorkerFiles | None = None,
    client: Any = None,
) -> Iterator[TaskRunner]:
    """A :class:`TaskRunner` on ``scheduler`` with ``workers`` (local ones only), closed after.

    ``client``: an open ``dask.distributed.Client`` to use instead (``scheduler``/``workers`` then
    only label it). ``files``: checked on every Dask worker first (:func:`check_workers`).
    Raises SchedulerError."""
    if client is not None:
        if files is not None:
            check_workers(client, files)
        yield TaskRunner(scheduler or "client", workers, client=client)
        return
    scheduler = check_scheduler(scheduler)
    if scheduler is not None and workers < 1:
        raise SchedulerError(f"--workers {workers}: need at least 1")
    if scheduler is None or (scheduler == "processes" and workers == 1):
        yield TaskRunner(None, 1)
    elif scheduler == "processes":
        with concurrent.futures.ProcessPoolExecutor(max_workers=workers) as pool:
            yield TaskRunner(scheduler, workers, pool=pool)
    else:
        with dask_client(scheduler, workers) as c:
            if files is not None:
                check_workers(c, files)
            yield TaskRunner(scheduler, workers, client=c)


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
    ``scheduler``/``workers`` are ignored)."""
    if not tasks:
        return []
    with task_runner(scheduler, workers, client=client) as runner:
        return runner.map(fn, tasks, shared=shared)
