"""docs/datasets.md "Your own building": the recipe's blocks run as written.

msindoor site1/F2 (the site built from every trace but the one looked at): the primary pose on that
walk is within twice the realbench level of the floor, measured here by a leave-one-walk-out realbench
run on the floor's first walks; the same walk without its truth gets a field report, and its GeoJSON
and MCAP exports hold its track. IPIN 2023 (gsd logs, the site from every other log of the building):
the walk's field report and exports, the GeoJSON track lying on the walk's own latitude/longitude
truth (its POSI records)."""

from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys

import pytest
from stridefix_analyzer.io.results import read_analyze_metrics, read_realbench_results
from stridefix_common.geodesy import project

from .conftest import MSINDOOR, REPO

MARK = "<!-- run by tests/python/realdata/test_own_building.py -->"
GSD_MARK = "<!-- run by tests/python/realdata/test_own_building.py (gsd) -->"
FLOOR = MSINDOOR / "site1" / "F2"
IPIN = REPO.parent / "shared" / "data" / "ipin2023"
#: walks of realbench's measurement: enough folds for a floor-level mean, a minute at most on 2 cores
REALBENCH_WALKS = 24


def _block(mark: str = MARK) -> str:
    text = (REPO / "docs" / "datasets.md").read_text(encoding="utf-8")
    m = re.search(re.escape(mark) + r"\n```sh\n(.*?)\n```", text, re.S)
    assert m, f"docs/datasets.md: the block after {mark}"
    return m.group(1)


def _run_block(mark: str, stridefixd, env: dict[str, str]) -> subprocess.CompletedProcess:
    script = "set -euo pipefail\n" + _block(mark).replace("build/firmware/stridefixd", str(stridefixd))
    env = {**os.environ, **env, "MPLBACKEND": "Agg"}
    return subprocess.run(
        ["bash", "-c", script], cwd=REPO, env=env, capture_output=True, text=True, timeout=900
    )


def _field_outputs(w) -> list[tuple[float, float]]:
    """The truth-less report and the exports of a recipe's walk: (lon, lat) of the GeoJSON track."""
    field = read_analyze_metrics(w / "field" / "metrics.json")
    assert field["truth"] is False and (w / "field" / "report.html").is_file()
    assert field["walk"]["steps"]["count"] > 50
    from mcap.reader import make_reader

    with open(w / "walk.mcap", "rb") as f:
        topics = {ch.topic for _, ch, _ in make_reader(f).iter_messages()}
    assert {"POSE", "STEP", "FIX"} <= topics, topics
    doc = json.loads((w / "walk.geojson").read_text())
    return [tuple(c[:2]) for feat in doc["features"] for c in feat["geometry"]["coordinates"]]


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
    # GIVEN the recipe's commands as the doc prints them, WHEN they run
    proc = _run_block(MARK, stridefixd, {"F2": str(floor), "W": str(tmp_path / "mine")})
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
    # AND the walk without its truth: a field report and its track on the map, in the floor's frame
    points = _field_outputs(tmp_path / "mine")
    assert len(points) > 100 and all(math.isfinite(v) for p in points for v in p)


def test_gsd_recipe_puts_the_walk_on_its_own_truth(tmp_path, stridefixd):
    if not IPIN.is_dir():
        pytest.skip(f"needs the IPIN 2023 logs in {IPIN} (docs/datasets.md)")
    w = tmp_path / "mine"
    proc = _run_block(GSD_MARK, stridefixd, {"IPIN": str(IPIN), "W": str(w)})
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    points = _field_outputs(w)
    # the walk's own truth: its POSI records (latitude, longitude), in metres about the recipe's origin
    walk = re.search(r"mv \$W/walks/(\w+)\.lcmlog", _block(GSD_MARK)).group(1)
    posi = [
        line.split(";")
        for line in (IPIN / f"{walk}.txt").read_text(encoding="utf-8", errors="replace").splitlines()
        if line.startswith("POSI;")
    ]
    origin = re.search(r"--origin ([-\d.]+),([-\d.]+)", _block(GSD_MARK)).groups()
    tx, ty = project([float(p[3]) for p in posi], [float(p[4]) for p in posi], *map(float, origin))
    ex, ey = project([p[1] for p in points], [p[0] for p in points], *map(float, origin))
    # every truth point has the exported track nearby: the track runs where the walker walked
    # (a fused pose's error on this building is metres; 15 m is the IPIN score's floor penalty)
    nearest = [min(math.hypot(x - a, y - b) for a, b in zip(ex, ey)) for x, y in zip(tx, ty)]
    assert len(nearest) > 10 and sorted(nearest)[len(nearest) // 2] < 15.0, nearest
