"""Disk full, for real: a 2 MB tmpfs in the test's own mount namespace.

Regression: on a full disk the summary said 78,942 events written and 1,226 dropped while the file
held 23,317, and the error gave no reason. GIVEN 25,000 frames of the default walk, WHEN the log's
disk fills during the first half and space returns before the second, THEN the estimator runs on,
the reason is printed once when the episode starts and once when logging resumes, events and bytes
in = written + dropped exactly (against a clean run of the same frames), and the file holds exactly
the events the summary says were written, whole.
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


def test_disk_full_drops_are_counted_exactly_and_logging_resumes(
    stridefixd, default_walk, tmp_path, log_detail
):
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    why_not = can_mount_tmpfs(mnt)
    if why_not:
        pytest.skip(why_not)
    frames = tmp_path / "frames.candump"
    lines = (default_walk["dir"] / "board.candump").read_text().splitlines(keepends=True)
    frames.write_text("".join(lines[:N_FRAMES]))
    clean = subprocess.run(
        [str(stridefixd), "-i", str(frames), "-l", str(tmp_path / "clean.lcmlog"), "-q"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert clean.returncode == 0, clean.stderr
    want = log_detail(clean.stderr)

    proc = subprocess.run(
        ["unshare", "--mount", sys.executable, str(HELPER), str(stridefixd), str(frames), str(mnt)],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 0, proc.stderr
    r = json.loads(proc.stdout)
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
