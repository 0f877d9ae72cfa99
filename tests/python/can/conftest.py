"""Fixtures for the CAN interoperability tests: a short SIL walk simulated in-process and written
with the ``.log`` suffix (python-can's candump reader), the DBC loaded by cantools, and the walk
replayed through stridefixd."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cantools
import lcm
import pytest
from stridefix import health_t
from stridefix_analyzer.firmware import Firmware
from stridefix_common.exits import EXIT_OK
from stridefix_sim.board import DBC_PATH
from stridefix_sim.pipeline import SimResult, simulate, write_outputs
from stridefix_sim.scenario import default_scenario

WALK_S = 20.0
SEED = 11


@dataclass(frozen=True)
class Walk:
    """One simulated walk: the result (what the board sent), its summary and output directory."""

    result: SimResult
    summary: dict
    dir: Path

    @property
    def log(self) -> Path:
        return self.dir / "board.log"


def simulate_walk(out: Path, loss_rate: float) -> Walk:
    scenario = default_scenario().with_overrides(seed=SEED, duration_s=WALK_S, **{"can.loss_rate": loss_rate})
    result = simulate(scenario)
    summary = write_outputs(result, out, candump_suffix=".log")
    return Walk(result, summary, out)


@pytest.fixture(scope="session")
def dbc():
    return cantools.database.load_file(str(DBC_PATH))


@pytest.fixture(scope="session", params=[0.0, 0.05], ids=["lossless", "5% loss"])
def walk(request, tmp_path_factory) -> Walk:
    """GIVEN a 20 s walk written as board.log (candump -L lines), without and with frame loss."""
    return simulate_walk(tmp_path_factory.mktemp("walk"), request.param)


@pytest.fixture(scope="session")
def lossless_walk(tmp_path_factory) -> Walk:
    return simulate_walk(tmp_path_factory.mktemp("lossless"), 0.0)


@dataclass(frozen=True)
class Replay:
    """stridefixd's LCM log of one input: its events by channel (timestamp µs, payload) and the last
    HEALTH."""

    events: dict[str, list[tuple[int, bytes]]]
    health: health_t


@pytest.fixture(scope="session")
def replay(stridefixd, lossless_walk, tmp_path_factory):
    """WHEN stridefixd replays a CAN log (with the lossless walk's true start pose): path -> Replay."""
    firmware = Firmware(stridefixd)

    def _replay(path: Path) -> Replay:
        log = tmp_path_factory.mktemp("replay") / "stridefixd.lcmlog"
        ini = lossless_walk.dir / "init_truth.ini"
        proc = firmware.run(input=path, log=log, extra=["--config", str(ini)])
        assert proc.returncode == EXIT_OK, proc.stderr
        events: dict[str, list[tuple[int, bytes]]] = {}
        for e in lcm.EventLog(str(log), "r"):
            events.setdefault(e.channel, []).append((e.timestamp, bytes(e.data)))
        return Replay(events, health_t.decode(events["HEALTH"][-1][1]))

    return _replay
