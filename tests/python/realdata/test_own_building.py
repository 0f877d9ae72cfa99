"""docs/datasets.md "Your own building": the recipe's block runs as written on msindoor site1/F2 (the
site built from every trace but the one looked at), and the primary pose on that walk is within twice
the realbench level of the floor, measured here by a leave-one-walk-out realbench run on the floor's
first walks."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from stridefix_analyzer.io.results import read_analyze_metrics, read_realbench_results

from .conftest import MSINDOOR, REPO

MARK = "<!-- run by tests/python/realdata/test_own_building.py -->"
FLOOR = MSINDOOR / "site1" / "F2"
#: walks of realbench's measurement: enough folds for a floor-level mean, a minute at most on 2 cores
REALBENCH_WALKS = 24


def _block() -> str:
    text = (REPO / "docs" / "datasets.md").read_text(encoding="utf-8")
    m = re.search(re.escape(MARK) + r"\n```sh\n(.*?)\n```", text, re.S)
    assert m, "docs/datasets.md: the own-building block and its marker"
    return m.group(1)


@pytest.fixture(scope="module")
def floor():
    if not (FLOOR / "path_data_files").is_dir():
        pytest.skip(f"needs the msindoor data in {FLOOR} (docs/datasets.md)")
    return FLOOR


def _realbench_primary_mean(tmp_path, stridefixd) -> float:
    out = tmp_path / "rb" / "results.json"
    cmd = [sys.executable, "-m", "stridefix_lab.cli", "-q", "realbench", "--format", "msindoor", str(FLOOR)]
    cmd += ["--limit", str(REALBENCH_WALKS), "--jobs", "2", "--no-report", "--stridefixd", str(stridefixd)]
    proc = subprocess.run([*cmd, "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    group = read_realbench_results(out)["groups"][0]
    return float(group["summary"]["schemes"][group["summary"]["primary"]["scheme"]]["mean"])


def test_own_building_recipe_reaches_the_realbench_level(tmp_path, stridefixd, floor):
    # GIVEN the recipe's commands as the doc prints them
    script = "set -euo pipefail\n" + _block().replace("build/firmware/stridefixd", str(stridefixd))
    env = {**os.environ, "F2": str(floor), "W": str(tmp_path / "mine"), "MPLBACKEND": "Agg"}
    # WHEN they run
    proc = subprocess.run(
        ["bash", "-c", script], cwd=REPO, env=env, capture_output=True, text=True, timeout=900
    )
    # THEN every step succeeds, the walk looked at is not in the site, and a report is written
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    walk = re.search(r"mv \$W/walks/(\w+)\.lcmlog", _block()).group(1)
    assert not (tmp_path / "mine" / "walks" / f"{walk}.lcmlog").exists()
    assert re.search(r"learned\s+from (\d+) of \1 walk", proc.stdout), proc.stdout[-2000:]
    assert (tmp_path / "mine" / "an" / "report.html").is_file()
    metrics = read_analyze_metrics(tmp_path / "mine" / "an" / "metrics.json")
    primary = metrics["primary_scheme"]
    mean_m = metrics["per_scheme"][primary]["position_error_m"]["mean"]
    # AND the primary pose is within twice the realbench level of the floor
    level_m = _realbench_primary_mean(tmp_path, stridefixd)
    assert mean_m < 2.0 * level_m, f"{primary}: {mean_m:.2f} m vs realbench level {level_m:.2f} m"
    assert metrics["per_scheme"][primary]["floor_hit_rate"] == 1.0
