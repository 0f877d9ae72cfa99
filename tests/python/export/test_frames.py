"""stridefix_analyzer.frames: a log as pandas DataFrames, the same rows as the analyzer's tables; and
the "Python and pandas" example of docs/tools.md run as it stands."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.testing import assert_array_equal
from stridefix_analyzer.frames import read_frames
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.schemes import scheme_name

REPO = Path(__file__).resolve().parents[3]


def test_pose_frame_has_the_rows_of_the_pose_table(geo_walk):
    log = read_logs([geo_walk["log"], geo_walk["truth"]])
    frames = read_frames([geo_walk["log"], geo_walk["truth"]])
    assert set(frames) == set(log.tables)
    table, pose = log.table("POSE"), frames["POSE"]
    assert len(pose) == len(table) == 8 * 3644
    for name in table.names:
        assert_array_equal(pose[name].to_numpy(), table[name], err_msg=name)
    assert pose["t_us"].dtype == np.int64
    assert_array_equal(pose["t_s"].to_numpy(), table["t_us"] * 1e-6)
    # the scheme's name beside its id, categories in the report order
    assert list(pose["scheme_name"].cat.categories) == [
        "pdr_only", "wifi_only", "overwrite", "static", "adaptive", "kalman", "ekf", "particle",
    ]  # fmt: skip
    assert (pose.loc[pose["scheme"] == 6, "scheme_name"] == "ekf").all()
    # every table: same rows; WIFI_AP (no time of its own) has no t_s
    for name, t in log.tables.items():
        assert len(frames[name]) == len(t), name
    assert "t_s" not in frames["WIFI_AP"] and "t_s" in frames["TRUTH"]


def test_channels_and_an_already_read_log(geo_walk):
    only = read_frames([geo_walk["log"]], channels=["STEP"])
    assert list(only) == ["STEP"]
    log = read_logs([geo_walk["log"]], decode=["FIX"])
    fix = read_frames([], log=log)["FIX"]
    assert isinstance(fix, pd.DataFrame) and len(fix) == len(log.table("FIX"))
    assert set(fix["scheme_name"].unique()) <= set(fix["scheme_name"].cat.categories)


def _docs_block() -> str:
    text = (REPO / "docs" / "tools.md").read_text(encoding="utf-8")
    m = re.search(r"<!-- run by tests/python/export/test_frames.py -->\n```python\n(.*?)```", text, re.S)
    assert m, "docs/tools.md lost its pandas example"
    return m.group(1)


def test_the_docs_pandas_example_runs(geo_walk, tmp_path):
    # GIVEN the example's paths (out/demo/stridefixd.lcmlog) pointing at the simulated walk's log
    demo = tmp_path / "out" / "demo"
    demo.mkdir(parents=True)
    (demo / "stridefixd.lcmlog").symlink_to(geo_walk["log"])
    # WHEN the block runs as it stands
    proc = subprocess.run([sys.executable, "-c", _docs_block()], cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    # THEN it prints each scheme's mean σ (the numbers the POSE table gives) and saves the plot
    pose = read_logs([geo_walk["log"]], decode=["POSE"]).table("POSE")
    printed = dict(line.split() for line in proc.stdout.splitlines()[1:])
    assert len(printed) == 8
    for code in np.unique(pose["scheme"]):
        mean = float(np.mean(pose["sigma_m"][pose["scheme"] == code]))
        assert abs(float(printed[scheme_name(code)]) - mean) <= 5e-4
    png = demo / "sigma.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
