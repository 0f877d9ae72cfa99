"""Fixtures for the simulator tests: short simulated runs (via the CLI), the default walk simulated
once in-process, a reference step detector and a candump parser."""

from __future__ import annotations

import argparse
import re
import time
from pathlib import Path

import cantools
import numpy as np
import pytest
from stridefix_sim import cli as sim_cli_module
from stridefix_sim.board import DBC_PATH
from stridefix_sim.pipeline import simulate
from stridefix_sim.scenario import default_scenario

SHORT_S = 25.0
WRAP_START_MS = 2**32 - 5_000
CANDUMP_RE = re.compile(r"^\((\d+)\.(\d{6})\) can0 ([0-9A-F]{3})#((?:[0-9A-F]{2}){0,8})$")


def run_cli(argv: list[str]) -> int:
    """Run ``stridefix sim ARGV`` through the sub-command's own parser; returns the exit status."""
    parser = argparse.ArgumentParser(prog="stridefix")
    sub = parser.add_subparsers(dest="command", required=True)
    sim_cli_module.add_parser(sub)
    return sim_cli_module.run(parser.parse_args(["sim", *argv]))


def parse_candump(path: Path) -> list[tuple[int, int, bytes]]:
    """Lines of a candump -L file as (host time µs, CAN id, data); asserts every line is well formed."""
    frames = []
    for n, line in enumerate(path.read_text(encoding="ascii").splitlines(), 1):
        m = CANDUMP_RE.match(line)
        assert m, f"line {n} is not candump -L: {line!r}"
        frames.append((int(m[1]) * 1_000_000 + int(m[2]), int(m[3], 16), bytes.fromhex(m[4])))
    return frames


@pytest.fixture(scope="session")
def dbc():
    return cantools.database.load_file(str(DBC_PATH))


@pytest.fixture(scope="session")
def sim_run(tmp_path_factory):
    """Factory: run the simulator once per distinct argument list (cached), return the output dir."""
    cache: dict[tuple, Path] = {}

    def _run(*argv: str) -> Path:
        if argv not in cache:
            out = tmp_path_factory.mktemp("sim")
            assert run_cli([*argv, "--out", str(out)]) == 0
            cache[argv] = out
        return cache[argv]

    return _run


@pytest.fixture(scope="session")
def short_run(sim_run) -> Path:
    return sim_run("--duration-s", str(SHORT_S), "--seed", "11")


@pytest.fixture(scope="session")
def lossy_run(sim_run) -> Path:
    return sim_run("--duration-s", str(SHORT_S), "--seed", "11", "--loss-rate", "0.1")


@pytest.fixture(scope="session")
def wrap_run(sim_run) -> Path:
    return sim_run("--duration-s", str(SHORT_S), "--seed", "11", "--board-time-start-ms", str(WRAP_START_MS))


@pytest.fixture(scope="session")
def short_s() -> float:
    """Simulated duration of the short runs [s]."""
    return SHORT_S


@pytest.fixture(scope="session")
def wrap_start_ms() -> int:
    """Board time start of the wrap run: 5 s before the uint32 millisecond counter wraps."""
    return WRAP_START_MS


@pytest.fixture(scope="session")
def candump():
    """The candump -L parser: path -> [(host time µs, CAN id, data)]."""
    return parse_candump


@pytest.fixture(scope="session")
def sim_cli():
    """``stridefix sim`` entry: argv list -> exit status."""
    return run_cli


@pytest.fixture(scope="session")
def default_result():
    """GIVEN the built-in default scenario (two-floor tour) simulated once: (SimResult, seconds taken)."""
    t0 = time.perf_counter()
    result = simulate(default_scenario())
    return result, time.perf_counter() - t0


def detect_steps(
    accel_mps2: np.ndarray, rate_hz: float = 100.0, threshold_mps2: float = 0.3, min_gap_s: float = 0.3
) -> np.ndarray:
    """Reference step detector (not the firmware's): project on the mean gravity direction (fixed
    mounting), remove the mean, keep samples above ``threshold_mps2`` that are the maximum within
    ±``min_gap_s``. Returns sample indices."""
    g = accel_mps2.mean(axis=0)
    vert = accel_mps2 @ (g / np.linalg.norm(g))
    vert = vert - np.median(vert)
    half = int(round(min_gap_s * rate_hz))
    padded = np.pad(vert, half, constant_values=-np.inf)
    win_max = np.lib.stride_tricks.sliding_window_view(padded, 2 * half + 1).max(axis=1)
    peaks = np.flatnonzero((vert >= win_max) & (vert > threshold_mps2))
    peaks = peaks[peaks < len(vert) - half]  # a peak is confirmed only by a full window after it
    # plateaus (equal neighbours) would count twice: keep the first of a run
    return peaks[np.concatenate([[True], np.diff(peaks) > half])] if len(peaks) else peaks


@pytest.fixture(scope="session")
def step_detector():
    return detect_steps
