"""Fixtures for the analyzer tests: synthetic LCM logs written with the real generated types."""

from __future__ import annotations

import importlib
import types

import lcm
import numpy as np
import pytest
from stridefix import config_t, health_t, pose_t, step_t, truth_t
from stridefix_analyzer import cli
from stridefix_lab.bench import perf


def make_truth(t_us, x_m, y_m, floor=0, step_count=-1, heading_rad=float("nan")):
    m = truth_t()
    m.t_us, m.x_m, m.y_m, m.floor = int(t_us), float(x_m), float(y_m), int(floor)
    m.heading_rad, m.step_count, m.source = heading_rad, int(step_count), truth_t.SOURCE_SIMULATION
    return m


def make_pose(t_us, x_m, y_m, floor=0, step_count=0, scheme=pose_t.SCHEME_ADAPTIVE, sigma_m=1.0):
    m = pose_t()
    m.t_us, m.x_m, m.y_m, m.floor = int(t_us), float(x_m), float(y_m), int(floor)
    m.heading_rad, m.sigma_m, m.step_count, m.scheme = 0.0, sigma_m, int(step_count), int(scheme)
    return m


def make_step(t_us, index, length_m=0.7):
    m = step_t()
    m.t_us, m.index, m.length_m, m.heading_rad = int(t_us), int(index), length_m, 0.0
    m.activity = step_t.ACTIVITY_WALKING
    return m


def make_health(t_us, frames):
    m = health_t()
    m.t_us, m.host_t_us, m.frames_total, m.frames_ok = int(t_us), 1_700_000_000_000_000 + t_us, frames, frames
    m.loop_mean_us, m.loop_max_us = 12.5, 80.0
    return m


def make_config(pairs, version="0.1.0-test"):
    m = config_t()
    m.t_us, m.version, m.dbc_sha256 = 0, version, "ab" * 32
    m.n, m.key, m.value = len(pairs), list(pairs), list(pairs.values())
    return m


@pytest.fixture
def write_log(tmp_path):
    """``write_log(name, [(channel, msg_or_bytes), ...]) -> path``: an LCM event log in tmp_path.

    Events are written in list order; the log timestamp is the message's t_us when it has one.
    """

    def _write(name, events):
        path = tmp_path / name
        log = lcm.EventLog(str(path), "w", overwrite=True)
        for i, (channel, msg) in enumerate(events):
            data = msg if isinstance(msg, bytes) else msg.encode()
            log.write_event(int(getattr(msg, "t_us", i)), channel, data)
        log.close()
        return path

    return _write


@pytest.fixture
def straight_walk():
    """Truth: 10 s walk along +x at 1 m/s sampled at 10 Hz, t = 1 s … 10.9 s; 100 samples.

    Returns (t_us, x_m, y_m) arrays of shape (100,).
    """
    t_us = 1_000_000 + np.arange(100) * 100_000
    x_m = (t_us - t_us[0]) / 1e6
    return t_us, x_m, np.zeros_like(x_m)


@pytest.fixture
def cli_main(monkeypatch):
    """``cli.main`` limited to sub-commands whose modules import.

    The sim sub-command's module is written separately; until it exists, build_parser() would fail
    on it, so the analyzer's own sub-commands are tested without it.
    """
    available = {}
    for name, module in cli.SUBCOMMANDS.items():
        try:
            importlib.import_module(module)
        except ModuleNotFoundError:
            continue
        available[name] = module
    monkeypatch.setattr(cli, "SUBCOMMANDS", available)
    return cli.main


@pytest.fixture
def msg():
    """Message builders with the real generated types: ``msg.truth(t_us, x_m, y_m, ...)``,
    ``msg.pose(...)``, ``msg.step(...)``, ``msg.health(...)``, ``msg.config({key: value})``."""
    return types.SimpleNamespace(
        truth=make_truth, pose=make_pose, step=make_step, health=make_health, config=make_config
    )


@pytest.fixture
def walk_logs(write_log, straight_walk):
    """A firmware log and a separate simulator truth log of ``straight_walk``; returns (fw, sim).

    Firmware: CONFIG, HEALTH, and POSE 20 ms after each truth sample for two schemes: adaptive
    1 m to the left of the truth (step_count = k), pdr_only 2 m ahead. Simulator: TRUTH with
    step_count = k. So the first truth sample is unscored.
    """
    t, x, y = straight_walk
    fw = [("CONFIG", make_config({"fusion.mode": "adaptive"})), ("HEALTH", make_health(t[-1], 99))]
    fw += [
        ("POSE", make_pose(ti + 20_000, xi, yi + 1.0, step_count=k))
        for k, (ti, xi, yi) in enumerate(zip(t, x, y))
    ]
    fw += [
        ("POSE", make_pose(ti + 20_000, xi + 2.0, yi, scheme=pose_t.SCHEME_PDR_ONLY))
        for ti, xi, yi in zip(t, x, y)
    ]
    sim = [("TRUTH", make_truth(ti, xi, yi, step_count=k)) for k, (ti, xi, yi) in enumerate(zip(t, x, y))]
    return write_log("fw.lcmlog", fw), write_log("sim.lcmlog", sim)


@pytest.fixture(scope="module")
def harness(stridefixd):
    """``sf_core_cost``, bench perf's harness, of the build under test (test_bench_perf*.py)."""
    path = perf.harness_path(stridefixd)
    if not path.is_file():
        pytest.fail(f"{path} not built: run `make build`")
    return path
