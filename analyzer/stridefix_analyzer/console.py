"""What the long-running commands tell the user on stderr, at the verbosity ``stridefix -q``/``-v`` chose.

Three levels: :data:`QUIET` (``-q``: nothing but errors), :data:`NORMAL` (a line per phase, and one
updating progress bar per phase on a terminal) and :data:`VERBOSE` (``-v``: also a line per step of a
phase, with its note, elapsed time and ETA). The level is process-wide: :func:`stridefix_analyzer.cli.main`
sets it once from the global options, before the sub-command runs; worker processes never print.
Files never depend on it; a command's tables on stdout go through :func:`show`, which ``-q`` silences.
"""

from __future__ import annotations

import sys
import time
from typing import Any, TextIO

QUIET, NORMAL, VERBOSE = 0, 1, 2
_level = NORMAL


def set_level(level: int) -> None:
    """The verbosity from now on (:data:`QUIET`, :data:`NORMAL` or :data:`VERBOSE`)."""
    global _level
    if level not in (QUIET, NORMAL, VERBOSE):
        raise ValueError(f"verbosity {level}: expected {QUIET}, {NORMAL} or {VERBOSE}")
    _level = level


def level() -> int:
    return _level


def quiet() -> bool:
    return _level == QUIET


def say(msg: str, stream: TextIO | None = None) -> None:
    """A phase's line on stderr (or ``stream``), unless quiet."""
    if _level >= NORMAL:
        print(msg, file=stream or sys.stderr, flush=True)


def show(text: str) -> None:
    """A result table or line on stdout, unless quiet (``-q``: nothing but errors)."""
    if _level >= NORMAL:
        print(text, flush=True)


def _is_tty(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):  # a closed or file-less stream
        return False


class Progress:
    """The steps of one phase of ``n`` steps on ``stream``: ``PREFIX: WHAT [i/n] note  elapsed, ETA``.

    ``-v``: that line for every step. Otherwise, on a terminal, one tqdm bar that updates in place
    (about 1,000 lines per floor of ``realbench`` before); off a terminal (a log file, a pipe, CI), one
    line when the phase is done. ``-q`` or ``stream`` None: nothing."""

    def __init__(self, what: str, n: int, stream: TextIO | None = sys.stderr, prefix: str = "realbench"):
        self.what, self.n, self.stream, self.prefix = what, n, stream, prefix
        self.t0, self.i = time.perf_counter(), 0
        self._bar: Any = None
        self._closed = False
        if _level == NORMAL and n > 0 and stream is not None and _is_tty(stream):
            from tqdm import tqdm  # only when a bar is drawn: a plain import costs ~50 ms

            self._bar = tqdm(total=n, desc=f"{prefix}: {what}", file=stream, leave=True, dynamic_ncols=True)

    def step(self, note: str = "") -> None:
        self.i += 1
        if self.stream is None:
            return
        el = time.perf_counter() - self.t0
        if _level >= VERBOSE:
            eta = el / self.i * (self.n - self.i)
            print(
                f"{self.prefix}: {self.what} [{self.i}/{self.n}] {note}  elapsed {el:.0f} s, ETA {eta:.0f} s",
                file=self.stream,
                flush=True,
            )
        elif self._bar is not None:
            if note:
                self._bar.set_postfix_str(note[:60], refresh=False)
            self._bar.update(1)
        if self.i == self.n:
            self.close()

    def close(self) -> None:
        """End the phase: the bar closed, or (off a terminal) its one summary line."""
        if self._closed:
            return
        self._closed = True
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif _level == NORMAL and self.i and self.stream is not None:
            el = time.perf_counter() - self.t0
            print(
                f"{self.prefix}: {self.what} {self.i}/{self.n} done ({el:.0f} s)",
                file=self.stream,
                flush=True,
            )
