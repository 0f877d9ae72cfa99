"""docs/tools.md "The whole round, in one block": the block of commands runs as it stands, and each tool's output
says it did its job (lcm-logplayer's copy is the log, python-can reads every frame, the ASC round
trip replays the same walk, evo's APE is our 3-D error)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess

import lcm
import pytest
from stridefix_analyzer.io.results import read_analyze_metrics

from ..conftest import REPO

MARK = "<!-- run by tests/python/e2e/test_readme_tools.py -->"
TOOLS = ("lcm-logplayer", "log2asc", "asc2log")


def _block() -> str:
    text = (REPO / "docs" / "tools.md").read_text(encoding="utf-8")
    m = re.search(re.escape(MARK) + r"\n```sh\n(.*?)\n```", text, re.S)
    assert m, "docs/tools.md: the tools block and its marker"
    return m.group(1)


@pytest.mark.skipif(
    any(shutil.which(t) is None for t in TOOLS), reason=f"needs {', '.join(TOOLS)} (tools/deps.sh)"
)
def test_readme_tools_block_runs(tmp_path, stridefixd):
    script = "set -euo pipefail\n" + _block().replace("build/firmware/stridefixd", str(stridefixd))
    env = {**os.environ, "W": str(tmp_path), "MPLBACKEND": "Agg", "HOME": str(tmp_path / "home")}
    proc = subprocess.run(
        ["bash", "-c", script], cwd=REPO, env=env, capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    out = proc.stdout

    def events(name):
        return [(e.channel, e.data) for e in lcm.EventLog(str(tmp_path / name), "r")]

    assert events("copy.lcmlog") == events("run.lcmlog")  # lcm-logplayer played every event
    assert "lcm.spy.Spy" in out and "stridefix_lcmtypes.jar" in out
    frames = int(re.search(r"^(\d+) frames$", out, re.M).group(1))
    assert frames == sum(1 for line in (tmp_path / "board.log").read_text().splitlines() if line.strip())
    assert re.search(r"IMU_ACCEL\(", out)  # cantools decoded with the DBC
    # the ASC round trip replays the same walk: the same POSE payloads (host times move, see the CAN section)
    pose = [d for c, d in events("run.lcmlog") if c.startswith("POSE")]
    assert pose and pose == [d for c, d in events("back.lcmlog") if c.startswith("POSE")]
    metrics = read_analyze_metrics(tmp_path / "an" / "metrics.json")
    ape_mean = float(re.search(r"^\s+mean\s+([0-9.]+)", out, re.M).group(1))
    assert ape_mean == pytest.approx(metrics["iso18305"]["vertical"]["mean_3d_error_m"], abs=1e-5)
    assert (tmp_path / "csv" / "pdr_only_matched.csv").is_file()
