"""stridefixd --speed X: a replay published at X times its recorded pace, the log unchanged.

GIVEN a 60 s SIL walk's candump, WHEN stridefixd replays it as fast as it can and again with
``--speed 50`` (and its own log once more through ``--replay``, paced and not), THEN the paced run
takes the walk's span / 50 (to the scheduler's slack), the unpaced one a fraction of it, and the two
logs hold the same events: the same channels and event timestamps (the input's times, not the wall
clock's) and the same payloads byte for byte, except HEALTH's ``loop_mean_us`` and ``loop_max_us``,
the main loop's measured time per item, which differ between any two runs.
"""

from __future__ import annotations

import signal
import subprocess
import time
from pathlib import Path

import lcm
import pytest
from stridefix import health_t

SPEED = 50.0
#: HEALTH fields measured on the wall clock (the loop's cost), different in any two runs
MEASURED = {"loop_mean_us", "loop_max_us"}


@pytest.fixture(scope="module")
def walk(tmp_path_factory, cli) -> Path:
    out = tmp_path_factory.mktemp("speed")
    proc = cli("sim", "--out", str(out), "--duration-s", "60")
    assert proc.returncode == 0, proc.stderr
    return out


def _replay(stridefixd: Path, log: Path, *args: str) -> float:
    t0 = time.monotonic()
    proc = subprocess.run(
        [str(stridefixd), *args, "--log", str(log), "-q"], capture_output=True, text=True, timeout=120
    )
    elapsed = time.monotonic() - t0
    assert proc.returncode == 0, proc.stderr
    return elapsed


def _span_s(log: Path) -> float:
    stamps = [e.timestamp for e in lcm.EventLog(str(log), "r")]
    return (max(stamps) - min(stamps)) * 1e-6


def _assert_same_log(a: Path, b: Path) -> int:
    """The two logs event by event: channel, timestamp and payload equal (HEALTH's measured fields
    aside). The number of events."""
    ea, eb = list(lcm.EventLog(str(a), "r")), list(lcm.EventLog(str(b), "r"))
    assert [(e.channel, e.timestamp) for e in ea] == [(e.channel, e.timestamp) for e in eb]
    differing: set[str] = set()
    for x, y in zip(ea, eb, strict=True):
        if x.channel == "HEALTH":
            hx, hy = health_t.decode(x.data), health_t.decode(y.data)
            differing |= {f for f in hx.__slots__ if getattr(hx, f) != getattr(hy, f)}
        else:
            assert x.data == y.data, x.channel
    assert differing <= MEASURED
    return len(ea)


@pytest.mark.parametrize("source", ["candump", "lcmlog"])
def test_speed_paces_the_replay_and_keeps_the_log(stridefixd, walk, tmp_path, source):
    if source == "candump":
        spec = ["--input", str(walk / "board.candump")]
    else:  # the raw samples of a first replay's log, replayed as an LCM log
        first = tmp_path / "first.lcmlog"
        _replay(stridefixd, first, "--input", str(walk / "board.candump"))
        spec = ["--replay", str(first)]
    fast, paced = tmp_path / "fast.lcmlog", tmp_path / "paced.lcmlog"
    t_fast = _replay(stridefixd, fast, *spec)
    t_paced = _replay(stridefixd, paced, *spec, "--speed", f"{SPEED:g}")
    span = _span_s(fast)
    assert span == pytest.approx(60.0, abs=0.5)
    # the span at 50x is 1.2 s: never less, and no more than the replay's own work and a start later
    assert span / SPEED <= t_paced < span / SPEED + t_fast + 1.0
    assert t_fast < 0.5 * span / SPEED
    assert _assert_same_log(fast, paced) > 10000


def test_signals_while_paced(stridefixd, walk, tmp_path):
    """SIGHUP while a paced replay waits rotates the log and loses no item: the files, CONFIG copies
    aside, hold the unpaced log's events; SIGTERM ends the wait at once, as at the end of the input."""
    fast = tmp_path / "fast.lcmlog"
    _replay(stridefixd, fast, "--input", str(walk / "board.candump"))
    paced = tmp_path / "paced.lcmlog"
    cmd = [
        str(stridefixd),
        "--input",
        str(walk / "board.candump"),
        "--log",
        str(paced),
        "-q",
        "--speed",
        "30",
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    for _ in range(2):
        time.sleep(0.6)
        proc.send_signal(signal.SIGHUP)
    assert proc.wait(timeout=30) == 0, proc.stderr.read() if proc.stderr else ""
    files = [paced, tmp_path / "paced.001.lcmlog", tmp_path / "paced.002.lcmlog"]
    assert sorted(tmp_path.glob("paced*")) == sorted(files)
    got: list[tuple[str, int, bytes]] = []
    for i, f in enumerate(files):
        events = [(e.channel, e.timestamp, e.data) for e in lcm.EventLog(str(f), "r")]
        got += [e for e in events[1 if i else 0 :] if e[0] != "HEALTH"]  # a rotated file opens with CONFIG
    want = [(e.channel, e.timestamp, e.data) for e in lcm.EventLog(str(fast), "r") if e.channel != "HEALTH"]
    assert got == want and len(want) > 10000

    slow = tmp_path / "slow.lcmlog"
    cmd = [str(stridefixd), "--input", str(walk / "board.candump"), "--log", str(slow), "-q", "--speed", "1"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    t0 = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=10) == 0
    assert time.monotonic() - t0 < 1.0
    assert slow.is_file() and _span_s(slow) < 5.0  # about the one second it ran, not the walk


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--input", "socketcan:can0", "--speed", "20"], "is live"),
        (["--input", "x.candump", "--speed", "0"], "expected a number in [0.001, 1e+06]"),
        (["--input", "x.candump", "--speed", "fast"], "expected a number"),
        (["--input", "x.candump", "--speed", "nan"], "expected a number"),
    ],
)
def test_speed_refuses_bad_usage(stridefixd, args, message):
    proc = subprocess.run([str(stridefixd), *args], capture_output=True, text=True, timeout=10)
    assert proc.returncode == 2 and message in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
