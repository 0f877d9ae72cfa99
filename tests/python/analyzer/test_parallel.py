"""The one fan-out (stridefix_analyzer.parallel): task order, progress, task isolation, errors and the
check that Dask workers see the files the tasks need, on every scheduler."""

from __future__ import annotations

import ipaddress
import os
import urllib.parse

import psutil
import pytest
from stridefix_analyzer.parallel import (
    NEEDS,
    SchedulerError,
    WorkerFiles,
    check_scheduler,
    check_workers,
    dask_client,
    task_runner,
    worker_problems,
)


class TaskFailed(Exception):
    """Raised by a task, to be seen by the caller."""


def square_plus(task: int, shared: int) -> int:
    return task * task + shared


def pid_of(task: int) -> tuple[int, int]:
    return task, os.getpid()


def grow(task: list[int]) -> list[int]:
    """Changes its input: in a worker that is a copy, and so it must be in the serial run."""
    task.append(len(task))
    return task


def fail_on_three(task: int) -> int:
    if task == 3:
        raise TaskFailed(f"task {task}")
    return task


@pytest.fixture(scope="module")
def client():
    with dask_client("local", 2) as c:
        yield c


@pytest.fixture(params=["serial", "processes", "dask"])
def runner(request, client):
    """GIVEN a task runner of each kind (Dask: a LocalCluster of 2 workers, shared by the module)."""
    if request.param == "dask":
        with task_runner("local", 2, client=client) as r:
            yield r
    else:
        with task_runner(request.param, 2) as r:
            yield r


@pytest.mark.parametrize("chunksize", [1, 3])
def test_results_come_in_task_order_and_each_is_reported_once(runner, chunksize):
    seen = []
    out = runner.map(
        square_plus, range(10), shared=5, on_result=lambda i, r: seen.append((i, r)), chunksize=chunksize
    )
    assert out == [t * t + 5 for t in range(10)]
    assert sorted(seen) == list(enumerate(out))


def test_a_task_changes_a_copy_of_its_input_on_every_scheduler(runner):
    tasks = [[1], [1, 2]]
    out = runner.map(grow, tasks)
    assert out == [[1, 1], [1, 2, 2]]
    assert tasks == [[1], [1, 2]]  # the caller's tasks are untouched, as they are by a worker


def test_a_task_error_reaches_the_caller(runner):
    with pytest.raises(TaskFailed, match="task 3"):
        runner.map(fail_on_three, range(6))


def test_processes_and_dask_run_in_other_processes(client):
    with task_runner("processes", 2) as r:
        assert os.getpid() not in {p for _, p in r.map(pid_of, range(8))}
    with task_runner("local", 2, client=client) as r:
        assert os.getpid() not in {p for _, p in r.map(pid_of, range(8))}
    with task_runner("serial") as r:
        assert {p for _, p in r.map(pid_of, range(3))} == {os.getpid()}
    with task_runner("processes", 1) as r:  # one process: no pool, this one
        assert r.describe() == "serial"


def test_scheduler_names():
    assert check_scheduler(None) is None and check_scheduler("serial") is None
    assert check_scheduler("local") == "local" and check_scheduler("processes") == "processes"
    assert check_scheduler("tcp://10.0.0.1:8786") == "tcp://10.0.0.1:8786"
    with pytest.raises(SchedulerError, match="'threads'"):
        check_scheduler("threads")
    with pytest.raises(SchedulerError, match="--workers 0"):
        with task_runner("processes", 0):
            pass


def test_worker_problems_name_every_missing_or_foreign_file(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    exe = tmp_path / "stridefixd"
    exe.write_bytes(b"build 1")
    files = WorkerFiles(read=[data, tmp_path / "gone"], write=[tmp_path / "out"], same=[exe])
    digests = {str(exe): "0" * 64}  # the client's build differs
    assert worker_problems(files, digests) == [
        f"missing {tmp_path / 'gone'}",
        f"missing {tmp_path / 'out'}",
        f"{exe} differs from the client's (another build)",
    ]


def test_a_worker_that_lacks_a_file_is_named_with_what_it_needs(client, tmp_path):
    exe = tmp_path / "stridefixd"
    exe.write_bytes(b"build 1")
    check_workers(client, WorkerFiles(read=[tmp_path], write=[tmp_path], same=[exe]))  # all there
    with pytest.raises(SchedulerError) as err:
        check_workers(client, WorkerFiles(read=[tmp_path / "site1" / "F2"], same=[exe]))
    msg = str(err.value)
    workers = list(client.scheduler_info()["workers"])
    assert len(workers) == 2 and all(
        f"worker {w}: missing {tmp_path / 'site1' / 'F2'}" in msg for w in workers
    )
    assert NEEDS in msg


def test_a_scheduler_address_runs_on_its_workers(client):
    # the address path of task_runner (a Client of its own on the LocalCluster's scheduler)
    address = client.scheduler.address
    assert address.startswith("tcp://")
    with task_runner(address, files=WorkerFiles(read=[os.getcwd()])) as r:
        assert r.describe() == address
        assert r.map(square_plus, range(4), shared=1) == [1, 2, 5, 10]


def _listening(pid: int) -> set[str]:
    """The addresses process ``pid`` listens on (TCP)."""
    return {c.laddr.ip for c in psutil.Process(pid).net_connections("tcp") if c.status == psutil.CONN_LISTEN}


def test_the_local_cluster_listens_on_loopback_only(client):
    # a Dask client can run any function on a worker: nothing of a local run may be reachable from
    # another machine, the dashboard included
    scheduler = urllib.parse.urlparse(client.scheduler.address).hostname
    dashboard = urllib.parse.urlparse(client.dashboard_link).hostname
    workers = [urllib.parse.urlparse(w).hostname for w in client.scheduler_info()["workers"]]
    assert ipaddress.ip_address(scheduler).is_loopback and dashboard in ("127.0.0.1", "localhost")
    assert workers and all(ipaddress.ip_address(w).is_loopback for w in workers)
    pids = [os.getpid(), *client.run(os.getpid).values()]
    listening = {pid: _listening(pid) for pid in pids}
    assert listening[os.getpid()], "the scheduler and dashboard listen in this process"
    assert all(ipaddress.ip_address(ip).is_loopback for ips in listening.values() for ip in ips), listening
