"""Fixtures shared by every Python test folder: the built stridefixd and the `stridefix` console script."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


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
