"""realbench with a walk that cannot be scored: the run still writes results.json, names the walk on
stderr and exits 1 (a failed walk is a failed run, not a quiet gap in the tables)."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
from stridefix_analyzer.io.results import read_realbench_results

from .conftest import HANDMADE_LINES, MSINDOOR

FLOOR = MSINDOOR / "site1" / "F2"


def test_a_failed_walk_fails_the_run(tmp_path, stridefixd):
    traces = sorted((FLOOR / "path_data_files").glob("*.txt"))[:3] if FLOOR.is_dir() else []
    if len(traces) < 3:
        pytest.skip(f"needs the msindoor data in {FLOOR} (docs/datasets.md)")
    # GIVEN a floor of three real walks and one that holds a few samples only (nothing to score)
    floor = tmp_path / "site1" / "F2"
    (floor / "path_data_files").mkdir(parents=True)
    shutil.copy(FLOOR / "floor_info.json", floor)
    for t in traces:
        shutil.copy(t, floor / "path_data_files")
    lines = [line.replace("FloorName:B1", "FloorName:F2") for line in HANDMADE_LINES]
    (floor / "path_data_files" / "broken.txt").write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp_path / "rb" / "results.json"
    # WHEN realbench runs on it
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "stridefix_lab.cli",
            "realbench",
            "--format",
            "msindoor",
            str(floor),
            "--no-report",
        ]
        + ["--no-floor-plan", "--jobs", "2", "--stridefixd", str(stridefixd), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    # THEN it exits 1, names the failed walk in one error line, and still writes results.json with it
    assert proc.returncode == 1, proc.stderr[-2000:]
    errors = [line for line in proc.stderr.splitlines() if line.startswith("stridefix-lab realbench: error:")]
    assert len(errors) == 1 and "broken" in errors[0] and "1 walk(s) failed" in errors[0], proc.stderr[-2000:]
    group = read_realbench_results(out)["groups"][0]
    failed = [e["walk"] for e in group["failed"] + group["fold_errors"]]
    assert failed == ["broken"]
    assert group["summary"]["schemes"]["kalman"]["n"] > 0  # the other walks are scored
