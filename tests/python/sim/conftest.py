"""Fixtures for the simulator tests: short simulated runs (via the CLI) and a candump parser."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

import cantools
import pytest

from stridefix_sim import cli as sim_cli_module
from stridefix_sim.board import DBC_PATH

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
