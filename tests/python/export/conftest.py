"""Fixtures of the export tests: one simulated walk replayed through stridefixd with a geo-referenced
site, and the poses its log holds per channel, read with LCM's own reader (not the analyzer's)."""

from __future__ import annotations

import subprocess
from pathlib import Path

import lcm
import pytest
from stridefix import pose_t


@pytest.fixture(scope="session")
def geo_walk(tmp_path_factory, cli, stridefixd) -> dict[str, Path]:
    """GIVEN the default simulated walk (two floors) → stridefixd → a site built from it with the
    simulator's building.toml (its [geo]: origin, altitude and a 20° rotation; its walls) → the walk
    replayed with that site: every scheme on its POSE_<SCHEME> channel, the primary on POSE."""
    out = tmp_path_factory.mktemp("geo_walk")
    proc = cli("-q", "sim", "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    first = subprocess.run(
        [str(stridefixd), "--input", str(out / "board.candump"), "--log", str(out / "survey.lcmlog"), "-q"],
        capture_output=True,
        text=True,
    )
    assert first.returncode == 0, first.stderr
    proc = cli(
        "-q", "radiomap", "build", str(out / "survey.lcmlog"), str(out / "truth.lcmlog"),
        "--out", str(out / "site.sfsite"), "--building", str(out / "building.toml"),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    run = subprocess.run(
        [
            str(stridefixd),
            "--input",
            str(out / "board.candump"),
            "--log",
            str(out / "run.lcmlog"),
            "--site",
            str(out / "site.sfsite"),
            "-q",
        ],  # fmt: skip
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    return {"dir": out, "log": out / "run.lcmlog", "site": out / "site.sfsite", "truth": out / "truth.lcmlog"}


@pytest.fixture(scope="session")
def logged_poses(geo_walk) -> dict[str, list]:
    """Channel → its pose_t messages in the walk's log, in time order (lcm.EventLog + pose_t.decode)."""
    out: dict[str, list] = {}
    for event in lcm.EventLog(str(geo_walk["log"]), "r"):
        if event.channel == "POSE" or event.channel.startswith("POSE_"):
            out.setdefault(event.channel, []).append(pose_t.decode(event.data))
    for msgs in out.values():
        msgs.sort(key=lambda m: m.t_us)
    return out
