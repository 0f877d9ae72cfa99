"""Fixtures for the end-to-end SIL tests: the built stridefixd and one default simulated walk."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="session")
def stridefixd() -> Path:
    """The firmware binary built by CMake (make test passes its path in STRIDEFIXD)."""
    path = Path(os.environ.get("STRIDEFIXD", REPO / "build" / "firmware" / "stridefixd"))
    if not path.is_file():
        pytest.fail(f"stridefixd not built at {path}: run `make build` first")
    return path


def run_cli(*args: str, **kwargs) -> subprocess.CompletedProcess:
    """Runs the `stridefix` console script of this venv."""
    exe = Path(sys.executable).with_name("stridefix")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, **kwargs)


@pytest.fixture(scope="session")
def cli():
    """The `stridefix` console script, as a function of its arguments."""
    return run_cli


@pytest.fixture(scope="session")
def default_walk(tmp_path_factory) -> dict:
    """GIVEN the built-in default scenario simulated once: its output directory and summary."""
    out = tmp_path_factory.mktemp("walk")
    proc = run_cli("sim", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "sim_summary.json").read_text())
    return {"dir": out, "summary": summary}
