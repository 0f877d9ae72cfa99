"""Fixtures for the end-to-end SIL tests: one default simulated walk (stridefixd and the CLI come
from tests/python/conftest.py)."""

from __future__ import annotations

import json

import pytest


@pytest.fixture(scope="session")
def default_walk(tmp_path_factory, cli) -> dict:
    """GIVEN the built-in default scenario simulated once: its output directory and summary."""
    out = tmp_path_factory.mktemp("walk")
    proc = cli("sim", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "sim_summary.json").read_text())
    return {"dir": out, "summary": summary}
