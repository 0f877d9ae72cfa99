"""Fixtures shared by every Python test folder: the built stridefixd, the `stridefix` console script and
the lab's `stridefix-lab`."""

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


def run_lab(*args: str, **kwargs) -> subprocess.CompletedProcess:
    """Runs the lab's `stridefix-lab` console script of this venv."""
    exe = Path(sys.executable).with_name("stridefix-lab")
    return subprocess.run([str(exe), *args], capture_output=True, text=True, **kwargs)


def _assert_reads_alike(paths, decode=None):
    """read_logs of ``paths`` indexed (numpy, :mod:`stridefix_analyzer.io.lcmindex`) and record by
    record (lcm.EventLog) give the same LogData: every table bit for bit with its dtype, every count
    and warning in the same order. Returns the indexed read."""
    from stridefix_analyzer.io.logread import read_logs

    fast, slow = read_logs(paths, decode, indexed=True), read_logs(paths, decode, indexed=False)
    assert list(fast.tables) == list(slow.tables)
    for channel, table in fast.tables.items():
        other = slow.tables[channel]
        assert table.names == other.names, channel
        for name in table.names:
            a, b = table[name], other[name]
            assert (a.dtype, a.shape) == (b.dtype, b.shape), (channel, name)
            assert a.tobytes() == b.tobytes(), (channel, name)  # NaN payloads included
    assert fast.inputs == slow.inputs
    for field in ("messages", "unknown_channels", "decode_errors", "type_mismatches", "health", "config"):
        # in the same order too: metrics.json writes some of them as they are
        assert list(getattr(fast, field).items()) == list(getattr(slow, field).items()), field
    assert (fast.versions, fast.warnings) == (slow.versions, slow.warnings)
    return fast


@pytest.fixture(scope="session")
def assert_reads_alike():
    """``assert_reads_alike(paths, decode=None) -> LogData``: the fast reader gives exactly what the
    record-by-record reader gives on these logs."""
    return _assert_reads_alike


@pytest.fixture(scope="session")
def cli():
    """The `stridefix` console script, as a function of its arguments."""
    return run_cli


@pytest.fixture(scope="session")
def lab():
    """The lab's `stridefix-lab` console script, as a function of its arguments."""
    return run_lab
