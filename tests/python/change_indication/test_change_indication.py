"""Change indication: a fresh replay of each fixed input must match its committed CSV byte for byte.

A behaviour change (anything that moves a pose, a floor, a step or a fix verdict) shows up here as a
diff. When the change is intended, regenerate with `make change-indication` and commit the CSVs with
the change, so review sees what moved."""

from __future__ import annotations

import difflib
import importlib.util
from pathlib import Path

import pytest

CI_DIR = Path(__file__).resolve().parents[2] / "change_indication"
_spec = importlib.util.spec_from_file_location("sf_change_indication", CI_DIR / "replay.py")
assert _spec is not None and _spec.loader is not None
replay = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(replay)


@pytest.mark.parametrize("case", sorted(replay.CASES))
def test_replay_matches_committed_csv(case, stridefixd, tmp_path):
    data = replay.REAL_DATA_CASES.get(case)
    if data is not None and not data.is_dir():
        pytest.skip(f"{data} not found (needs ../shared/data beside the repository)")
    committed = CI_DIR / f"{case}.csv"
    assert committed.is_file(), f"{committed} missing: run `make change-indication` and commit it"
    fresh = replay.run_case(case, tmp_path, stridefixd)
    want, got = committed.read_text(), fresh.read_text()
    if want != got:
        diff = list(
            difflib.unified_diff(want.splitlines(), got.splitlines(), "committed", "fresh", lineterm="", n=0)
        )
        pytest.fail(
            f"{case}: behaviour changed ({len(diff)} diff lines; `make change-indication` "
            "regenerates the CSVs if intended):\n" + "\n".join(diff[:40])
        )
