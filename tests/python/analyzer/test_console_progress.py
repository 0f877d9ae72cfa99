"""A long command's progress on a terminal is one live line that every phase reuses, finished or not,
cleared when the command ends; off a terminal each phase is one plain line. Measured on a real
pseudo-terminal."""

from __future__ import annotations

import fcntl
import io
import os
import pty
import select
import struct
import termios

import pytest
from stridefix_analyzer import console


@pytest.fixture
def normal_level():
    before = console.level()
    console.set_level(console.NORMAL)
    yield
    console.end_progress()
    console.set_level(before)


def _read_all(fd: int) -> str:
    """Everything written to the terminal so far (no wait once it is drained)."""
    chunks = []
    while select.select([fd], [], [], 0.2)[0]:
        try:
            data = os.read(fd, 65536)
        except OSError:
            break
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks).decode("utf-8", "replace")


def test_phases_share_one_live_line_on_a_terminal(normal_level):
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # a terminal's size
    stream = os.fdopen(slave, "w", buffering=1)
    try:
        # GIVEN three phases, two of which never reach their count (as realbench's cached replays)
        first = console.Progress("prepare", 4, stream)
        for _ in range(2):
            first.step("walk")
        bar = console._live
        second = console.Progress("choose", 3, stream)
        for _ in range(3):
            second.step()
        third = console.Progress("fold", 5, stream)
        third.step()
        # THEN every phase drew on the same bar
        assert bar is not None and console._live is bar
        # WHEN the command ends
        console.end_progress()
        stream.flush()
        out = _read_all(master)
    finally:
        stream.close()
        os.close(master)
    # THEN no bar was left on screen: the live line never starts a new line, and it is cleared
    assert console._live is None
    assert "\n" not in out.replace("\r\n", "\n").strip("\n"), repr(out[-300:])
    for what in ("prepare", "choose", "fold"):
        assert f"realbench: {what}" in out


def test_off_a_terminal_each_phase_is_one_plain_line(normal_level):
    stream = io.StringIO()
    first = console.Progress("prepare", 4, stream)
    first.step()
    second = console.Progress("fold", 2, stream)
    second.step()
    second.step()
    console.end_progress()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("realbench: fold 2/2 done") and lines[1].startswith(
        "realbench: prepare 1/4 ended"
    )
