"""can-utils' log2asc and asc2log (interoperability with the CAN tools): the simulator's candump log converted to Vector ASC and
back. asc2log writes a direction flag (" R") after every frame, which the firmware's candump parser
reads; the replay of the round trip is the replay of the original. can-utils is a Debian package
(tools/deps.sh installs it); without it these tests are skipped.

asc2log dates the log from the ASC header's "date" line, which it parses in a de_DE or en_US locale;
without one it takes the current time: the round trip keeps every frame and the times between
frames to the µs, and moves them all by one offset (host time; board time is in the frames)."""

from __future__ import annotations

import shutil
import subprocess

import can
import numpy as np
import pytest

pytestmark = pytest.mark.skipif(
    shutil.which("log2asc") is None or shutil.which("asc2log") is None,
    reason="can-utils (log2asc, asc2log) not installed; tools/deps.sh installs it",
)

# What a replay writes that may differ between two runs of the same frames: the config (names the
# input) and HEALTH (host time, loop timing); both are compared field by field below.
RUN_CHANNELS = {"CONFIG", "HEALTH"}


@pytest.fixture(scope="module")
def round_trip(lossless_walk, tmp_path_factory):
    """WHEN board.log goes through log2asc (Vector ASC) and back through asc2log."""
    d = tmp_path_factory.mktemp("asc")
    asc, back = d / "board.asc", d / "back.log"
    subprocess.run(["log2asc", "-I", str(lossless_walk.log), "-O", str(asc), "can0"], check=True)
    subprocess.run(["asc2log", "-I", str(asc), "-O", str(back)], check=True, capture_output=True)
    return asc, back


def test_asc_holds_every_frame_and_asc2log_flags_every_line(lossless_walk, round_trip):
    asc, back = round_trip
    n = lossless_walk.summary["frames_total"]
    assert sum(" Rx " in line for line in asc.read_text(encoding="ascii").splitlines()) == n
    lines = back.read_text(encoding="ascii").splitlines()
    assert len(lines) == n
    assert all(line.endswith(" R") for line in lines)


def test_round_trip_keeps_frames_and_times_between_them(lossless_walk, round_trip):
    with can.LogReader(str(lossless_walk.log)) as a, can.LogReader(str(round_trip[1])) as b:
        orig, back = list(a), list(b)
    assert [(m.arbitration_id, bytes(m.data)) for m in back] == [
        (m.arbitration_id, bytes(m.data)) for m in orig
    ]
    assert all(m.is_rx for m in back)  # python-can reads the flag too
    t_orig = np.array([round(m.timestamp * 1e6) for m in orig])
    t_back = np.array([round(m.timestamp * 1e6) for m in back])
    offset_us = t_back - t_orig
    assert offset_us.max() - offset_us.min() <= 1  # µs: one offset for all (float s rounding)


def test_replay_of_the_round_trip_is_the_replay_of_the_original(lossless_walk, round_trip, replay):
    orig, back = replay(lossless_walk.log), replay(round_trip[1])
    assert {c: len(e) for c, e in back.events.items()} == {c: len(e) for c, e in orig.events.items()}
    assert len(orig.events["POSE"]) > 0 and len(orig.events["STEP"]) > 0
    for channel, events in orig.events.items():
        if channel in RUN_CHANNELS:
            continue
        # every sample, step, pose and fix the same bytes (board time); the log times one offset
        assert [d for _, d in back.events[channel]] == [d for _, d in events], channel
        shift = {tb - to for (tb, _), (to, _) in zip(back.events[channel], events)}
        assert len(shift) == 1, channel
    counters = ("frames_total", "frames_ok", "bad_syntax", "unknown_id", "bad_length", "decode_errors")
    counters += ("seq_gaps", "unsynced", "imu_samples", "mag_samples", "baro_samples", "wifi_scans")
    for name in counters:
        assert getattr(back.health, name) == getattr(orig.health, name), name
    assert orig.health.frames_total == orig.health.frames_ok == lossless_walk.summary["frames_total"]
