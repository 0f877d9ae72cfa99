"""Disk full, for real: a 2 MB tmpfs in the test's own mount namespace.

Regression: on a full disk the summary said 78,942 events written and 1,226 dropped while the file
held 23,317, and the error gave no reason. GIVEN 25,000 frames of the default walk, WHEN the log's
disk fills during the first half and space returns before the second, THEN the estimator runs on,
the reason is printed once when the episode starts and once when logging resumes, events and bytes
in = written + dropped exactly (against a clean run of the same frames), and the file holds exactly
the events the summary says were written, whole. The other tests hold the disk full longer, fill it
before the first event, or never free it (diskfull_run.py's options).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

HELPER = Path(__file__).with_name("diskfull_run.py")
N_FRAMES = 25_000


def can_mount_tmpfs(where: Path) -> str | None:
    """None if this process may `unshare --mount` and mount a tmpfs, else why not."""
    try:
        probe = subprocess.run(
            ["unshare", "--mount", "sh", "-c", f"mount -t tmpfs -o size=64k tmpfs '{where}'"],
            capture_output=True,
            text=True,
            timeout=30,
        )
    except FileNotFoundError:
        return "no unshare(1) on this machine"
    if probe.returncode != 0:
        return f"unshare --mount + mount tmpfs not permitted here: {probe.stderr.strip()}"
    return None


@pytest.fixture(scope="module")
def frames(default_walk, tmp_path_factory) -> Path:
    """GIVEN the first N_FRAMES frames of the default walk."""
    path = tmp_path_factory.mktemp("diskfull") / "frames.candump"
    lines = (default_walk["dir"] / "board.candump").read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:N_FRAMES]))
    return path


@pytest.fixture(scope="module")
def clean(stridefixd, frames, log_detail) -> dict[str, int]:
    """The log detail of the same frames written to a disk with room."""
    proc = subprocess.run(
        [str(stridefixd), "-i", str(frames), "-l", str(frames.with_suffix(".lcmlog")), "-q"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0, proc.stderr
    return log_detail(proc.stderr)


@pytest.fixture
def episode(stridefixd, frames, tmp_path):
    """``episode(*options) -> dict``: diskfull_run.py's result for these frames on a tmpfs of its own."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    why_not = can_mount_tmpfs(mnt)
    if why_not:
        pytest.skip(why_not)

    def run(*options: str) -> dict:
        proc = subprocess.run(
            [
                "unshare",
                "--mount",
                sys.executable,
                str(HELPER),
                str(stridefixd),
                str(frames),
                str(mnt),
                *options,
            ],
            capture_output=True,
            text=True,
            timeout=180,
        )
        assert proc.returncode == 0, proc.stderr
        return json.loads(proc.stdout)

    return run


def test_disk_full_drops_are_counted_exactly_and_logging_resumes(episode, clean, log_detail):
    r = episode()
    want = clean
    got = log_detail(r["stderr"])
    assert r["full_seen"], r["stderr"]
    assert r["status"] == 1, r["stderr"]  # the log is incomplete: said so, after the summary
    assert r["stderr"].count("No space left on device") == 1, r["stderr"]  # once per episode
    assert r["stderr"].count("logging resumed") == 1, r["stderr"]
    assert f"{N_FRAMES} frames" in r["stderr"]  # the estimator saw every frame
    assert got["drops"] > 0 and got["drop_bytes"] > 0
    assert got["events"] + got["drops"] == want["events"]
    assert got["bytes"] + got["drop_bytes"] == want["bytes"]
    assert (r["file_events"], r["file_bytes"]) == (got["events"], got["bytes"])
    assert (r["truncated_bytes"], r["skipped_bytes"], r["notes"]) == (0, 0, [])
    # the last HEALTH, written after logging resumed, carries the drops of the episode
    assert r["health"]["log_drops"] == got["drops"] and r["health"]["log_drop_bytes"] == got["drop_bytes"]


def test_logging_resumed_is_not_said_while_the_disk_is_still_full(episode, clean, log_detail):
    # Regression: the periodic fdatasync of what was written before the disk filled succeeds on a
    # full disk, and that success ended the episode: "logging resumed" was printed a second after
    # the failure with the disk still full, and the next write started a second episode. GIVEN the
    # disk stays full for 1.6 s (more than output.fsync_interval_ms) after the first failed write,
    # THEN nothing says it resumed until space returns, and the failure is told once.
    r = episode("--hold-s", "1.6")
    assert r["full_seen"], r["stderr"]
    assert "logging resumed" not in r["stderr_while_full"], r["stderr_while_full"]
    assert r["stderr"].count("No space left on device") == 1, r["stderr"]
    assert r["stderr"].count("logging resumed") == 1, r["stderr"]
    got = log_detail(r["stderr"])
    assert got["events"] + got["drops"] == clean["events"]


def test_a_log_started_on_a_full_disk_still_opens_with_config(episode, clean, log_detail):
    # Regression: CONFIG is written once, first; on a disk full from the start it was dropped, and
    # the log written once space returned had no CONFIG (no parameters, no firmware version).
    # GIVEN a disk without one free block at start, WHEN space returns mid-run, THEN the log's first
    # event is CONFIG (a copy, counted as one), and every event is still written or counted dropped.
    r = episode("--free", "0")
    assert r["full_seen"], r["stderr"]
    assert r["status"] == 1, r["stderr"]
    assert r["first_channel"] == "CONFIG", r
    got = log_detail(r["stderr"])
    assert got["copies"] == 1
    assert got["events"] - got["copies"] + got["drops"] == clean["events"]
    assert (r["file_events"], r["file_bytes"]) == (got["events"], got["bytes"])
    assert (r["truncated_bytes"], r["skipped_bytes"], r["notes"]) == (0, 0, [])


def test_a_log_nothing_could_be_written_to_is_not_left_as_an_empty_file(episode, clean, log_detail):
    # Regression: with no room for the whole run the empty .part was renamed to the log's final
    # name, a 0-byte file that looks like a finished log. GIVEN a disk that never has a free block,
    # THEN no file is left under either name, the run exits 1 and says why, and every event is
    # counted dropped.
    r = episode("--free", "0", "--never-free")
    assert r["full_seen"], r["stderr"]
    assert r["status"] == 1, r["stderr"]
    assert r["files"] == [], r["files"]
    assert "full.lcmlog: nothing could be written; no log file left" in r["stderr"], r["stderr"]
    got = log_detail(r["stderr"])
    assert (got["events"], got["bytes"]) == (0, 0)
    assert got["drops"] == clean["events"]
