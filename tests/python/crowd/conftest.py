"""Fixtures for the crowdsourced-model tests: hand-made scans, synthetic pairs, short SIL walks."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

NAN = np.nan


@pytest.fixture
def hand_scans() -> np.ndarray:
    """Four scans × three APs [dBm]; scans 0 and 2 share no AP."""
    return np.array([[-50.0, -60.0, NAN], [-52.0, NAN, -70.0], [NAN, NAN, -80.0], [-50.0, -61.0, -75.0]])


@pytest.fixture
def random_scans():
    """40 scans × 12 APs of integer RSS with ~60 % missing (some pairs share no AP), positions on
    two floors."""
    rng = np.random.default_rng(7)
    R = rng.integers(-90, -30, size=(40, 12)).astype(float)
    R[rng.random(R.shape) < 0.6] = np.nan
    R[5] = np.nan
    R[5, 0] = -70.0
    R[6] = np.nan
    R[6, 11] = -65.0
    xy = rng.uniform(0, 50, size=(40, 2))
    floor = (np.arange(40) % 3 == 0).astype(np.int64)
    return R, xy, floor


@pytest.fixture(scope="session")
def sil_walks(tmp_path_factory, stridefixd) -> list[str]:
    """GIVEN three 60 s walkers of the office loop (pace_normal, seeds 1–3) replayed through
    stridefixd: the walk arguments 'stridefixd.lcmlog,truth.lcmlog'."""
    base = tmp_path_factory.mktemp("crowd_sil")
    specs = []
    procs = []
    for seed in (1, 2, 3):
        out = base / f"s{seed}"
        procs.append(
            (
                out,
                subprocess.Popen(
                    [
                        str(Path(sys.executable).with_name("stridefix")),
                        "sim",
                        "--scenario",
                        "pace_normal",
                        "--seed",
                        str(seed),
                        "--duration-s",
                        "60",
                        "--out",
                        str(out),
                    ],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.PIPE,
                    text=True,
                ),
            )
        )
    for out, p in procs:
        _, err = p.communicate()
        assert p.returncode == 0, err
        fw = subprocess.run(
            [
                str(stridefixd),
                "--input",
                str(out / "board.candump"),
                "--log",
                str(out / "stridefixd.lcmlog"),
                "-q",
                "--config",
                str(out / "init_truth.ini"),
            ],
            capture_output=True,
            text=True,
        )
        assert fw.returncode == 0, fw.stderr
        specs.append(f"{out / 'stridefixd.lcmlog'},{out / 'truth.lcmlog'}")
    return specs
