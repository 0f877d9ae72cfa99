"""realbench on Dask: 6 real site1/F2 walks (enough for the inner cross-validation) run serially, on
a LocalCluster of 2 workers and on a scheduler address give the same results.json, apart from the
timers and the record of how the run was scheduled."""

from __future__ import annotations

import pytest
from stridefix_analyzer.io.results import read_realbench_results
from stridefix_analyzer.parallel import dask_client
from stridefix_lab.realbench.summary import untimed

from .conftest import MSINDOOR


@pytest.fixture(scope="module")
def scheduler_address():
    """GIVEN a Dask scheduler with 2 workers at a tcp:// address (a LocalCluster's)."""
    with dask_client("local", 2) as c:
        yield c.scheduler.address


@pytest.fixture(scope="module")
def serial_and_dask(request, tmp_path_factory, cli, scheduler_address, lab) -> dict:
    """GIVEN `stridefix-lab realbench --format msindoor site1/F2 --limit 6` with --scheduler serial, then
    --scheduler local --workers 2, then --scheduler tcp://… (a LocalCluster's scheduler started here),
    into the same folder (same paths in every document)."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor}")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench_dask") / "results.json"
    docs = {}
    for name, opts in (
        ("serial", ["--scheduler", "serial"]),
        ("dask", ["--scheduler", "local", "--workers", "2"]),
        ("address", ["--scheduler", scheduler_address]),
    ):
        proc = lab(
            "realbench",
            "--format",
            "msindoor",
            str(floor),
            "--limit",
            "6",
            "--no-report",
            "--quiet",
            "--stridefixd",
            str(stridefixd),
            "--out",
            str(out),
            *opts,
        )
        docs[name] = doc = read_realbench_results(out)
        # a walk the 5 others cannot place (no fix matched: no POSE) fails the run, named, and only then
        failed = [e["walk"] for g in doc["groups"] for e in g["failed"] + g["fold_errors"]]
        assert proc.returncode == (1 if failed else 0), proc.stderr[-2000:]
        assert all(w in proc.stderr for w in failed), proc.stderr[-2000:]
    return docs


def test_serial_and_two_dask_workers_give_the_same_results(serial_and_dask):
    serial, dask = serial_and_dask["serial"], serial_and_dask["dask"]
    assert serial["params"]["scheduler"] == "serial"
    assert dask["params"]["scheduler"] == "local x2"
    (g,) = serial["groups"]
    # the case covers every kind of task: 6 prepares, the inner-CV replays of each row, 6 folds
    assert len(g["walk_rows"]) == 6 and g["matcher_selection"]["chosen_by"].startswith("cross-validation")
    assert g["adaptive_selection"]["chosen_by"].startswith("cross-validation")
    assert all(r["fold"]["content_content_s"] > 0 for r in g["walk_rows"])  # a timer, left out below
    assert serial["run_s"]["total"] > 0
    assert untimed(dask) == untimed(serial)


def test_a_scheduler_address_gives_the_same_results(serial_and_dask):
    on = serial_and_dask["address"]
    assert on["params"]["scheduler"].startswith("tcp://127.0.0.1:")
    assert untimed(on) == untimed(serial_and_dask["serial"])
