"""Fixtures for the end-to-end SIL tests: one default simulated walk (stridefixd and the CLI come
from tests/python/conftest.py)."""

from __future__ import annotations

import json
import re
from collections.abc import Callable

import pytest

_LOG_DETAIL = re.compile(
    r"log detail: (\d+) files, (\d+) events written "
    r"\((\d+) of them CONFIG copies heading a file: rotated, or after a full disk\), "
    r"(\d+) bytes written; (\d+) events dropped, (\d+) bytes"
)


@pytest.fixture(scope="session")
def default_walk(tmp_path_factory, cli) -> dict:
    """GIVEN the built-in default scenario simulated once: its output directory and summary."""
    out = tmp_path_factory.mktemp("walk")
    proc = cli("sim", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "sim_summary.json").read_text())
    return {"dir": out, "summary": summary}


@pytest.fixture(scope="session")
def log_detail() -> Callable[[str], dict[str, int]]:
    """stridefixd's summary line on its log, from its stderr, as numbers: files, events (written),
    copies (CONFIG heading rotated files, or a file after a full disk), bytes, drops, drop_bytes."""

    def parse(stderr: str) -> dict[str, int]:
        m = _LOG_DETAIL.search(stderr)
        assert m, stderr
        keys = ("files", "events", "copies", "bytes", "drops", "drop_bytes")
        return dict(zip(keys, map(int, m.groups()), strict=True))

    return parse
