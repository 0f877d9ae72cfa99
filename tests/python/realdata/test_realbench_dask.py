"""realbench on Dask: 6 real site1/F2 walks (enough for the inner cross-validation) run serially and
on a LocalCluster of 2 workers give the same results.json, apart from the timers and the record of
how the run was scheduled."""

from __future__ import annotations

import json

import pytest

from .conftest import MSINDOOR

#: wall-clock timers (the run's phases, each fold's site content and its floor-plan survey)
TIMERS = ("run_s", "content_content_s", "survey_s")


def untimed(doc):
    """``doc`` without the timers and ``params.jobs``/``params.scheduler`` (how it ran, not what)."""
    if isinstance(doc, dict):
        return {k: untimed(v) for k, v in doc.items() if k not in TIMERS}
    if isinstance(doc, list):
        return [untimed(v) for v in doc]
    return doc


@pytest.fixture(scope="module")
def serial_and_dask(request, tmp_path_factory, cli) -> dict:
    """GIVEN `stridefix realbench --format msindoor site1/F2 --limit 6` with --scheduler serial, then
    with --scheduler local --workers 2, into the same folder (same paths in both documents)."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor}")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench_dask") / "results.json"
    docs = {}
    for name, opts in (
        ("serial", ["--scheduler", "serial"]),
        ("dask", ["--scheduler", "local", "--workers", "2"]),
    ):
        proc = cli(
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
        assert proc.returncode == 0, proc.stderr[-2000:]
        docs[name] = json.loads(out.read_text())
    return docs


def test_serial_and_two_dask_workers_give_the_same_results(serial_and_dask):
    serial, dask = serial_and_dask["serial"], serial_and_dask["dask"]
    assert serial["params"].pop("scheduler") == "serial"
    assert dask["params"].pop("scheduler") == "local x2"
    for d in (serial, dask):
        d["params"].pop("jobs")
    (g,) = serial["groups"]
    # the case covers every kind of task: 6 prepares, the inner-CV replays of each row, 6 folds
    assert len(g["walk_rows"]) == 6 and g["matcher_selection"]["chosen_by"].startswith("cross-validation")
    assert g["adaptive_selection"]["chosen_by"].startswith("cross-validation")
    assert all(r["fold"]["content_content_s"] > 0 for r in g["walk_rows"])  # a timer, left out below
    assert serial["run_s"]["total"] > 0
    assert untimed(dask) == untimed(serial)
