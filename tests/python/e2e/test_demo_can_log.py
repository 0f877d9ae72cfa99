"""The demo's CAN log opens in python-can as it is: `can.LogReader` picks the candump text reader by the
`.log` suffix, so the demo keeps `board.log` (the same file as `board.candump`)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import can

from ..conftest import REPO


def test_demo_can_log_opens_in_python_can(tmp_path, stridefixd):
    # GIVEN the demo run as `make demo` runs it
    out = tmp_path / "demo"
    venv = Path(sys.executable).parent.parent
    proc = subprocess.run(
        ["bash", str(REPO / "tools" / "demo.sh"), str(out), str(stridefixd), str(venv)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=600,
        env={"MPLBACKEND": "Agg", "PATH": "/usr/bin:/bin"},
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    # WHEN its CAN log is opened with python-can's LogReader, by name, with no options
    frames = list(can.LogReader(str(out / "board.log")))
    # THEN every candump line is a frame, in order, with the line's id and data
    lines = [ln.split() for ln in (out / "board.candump").read_text().splitlines() if ln.strip()]
    assert len(frames) == len(lines) > 1000
    for frame, (_, _, text) in zip(frames[:50], lines[:50]):
        ident, data = text.split("#")
        assert frame.arbitration_id == int(ident, 16) and frame.data.hex().upper() == data.upper()
