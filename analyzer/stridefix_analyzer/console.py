"""What the long-running commands tell the user on stderr, at the verbosity ``stridefix -q``/``-v`` chose.

Three levels: :data:`QUIET` (``-q``: nothing but errors), :data:`NORMAL` (a line per phase, and on a
terminal one live progress line per command that every phase reuses, cleared by :func:`end_progress`
when the command ends) and :data:`VERBOSE` (``-v``: also a line per step of a
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
#: the command's one live progress line on a terminal (a tqdm bar), shared by its phases
_live: Any = None
_live_stream: Any = None
#: phases not yet closed (their count may never be reached): :func:`end_progress` closes them
_open: list[Progress] = []


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
        if _live is not None:
            _live.clear()  # the phase's line above the live progress line, not through it
        print(msg, file=stream or sys.stderr, flush=True)
        if _live is not None:
            _live.refresh()


def end_progress() -> None:
    """End the command's progress: close every phase still open and clear the live line (the
    command's console script calls it when the command returns)."""
    global _live
    for p in list(_open):
        p.close()
    if _live is not None:
        _live.close()
        _live = None


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

    ``-v``: that line for every step. Otherwise, on a terminal, the command's one live line (a tqdm bar
    that each phase resets to its own count, so phases never stack up bars, finished or not); off a
    terminal (a log file, a pipe, CI), one line when the phase is done. ``-q`` or ``stream`` None:
    nothing."""

    def __init__(self, what: str, n: int, stream: TextIO | None = sys.stderr, prefix: str = "realbench"):
        self.what, self.n, self.stream, self.prefix = what, n, stream, prefix
        self.t0, self.i = time.perf_counter(), 0
        self._bar: Any = None
        self._closed = False
        global _live, _live_stream
        if _level == NORMAL and n > 0 and stream is not None and _is_tty(stream):
            for p in list(_open):
                p.close()  # a phase that never reached its count gives the line to this one
            if _live is None or _live_stream is not stream:
                end_progress()
                from tqdm import tqdm  # only when a bar is drawn: a plain import costs ~50 ms

                _live = tqdm(total=n, desc=f"{prefix}: {what}", file=stream, leave=False, dynamic_ncols=True)
                _live_stream = stream
            else:
                _live.reset(total=n)
                _live.set_description(f"{prefix}: {what}", refresh=False)
                _live.set_postfix_str("", refresh=True)
            self._bar = _live
        if stream is not None and n > 0:
            _open.append(self)

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
        if self in _open:
            _open.remove(self)
        if self._bar is not None:
            self._bar.refresh()  # the phase's final count, drawn however fast its last steps came
            self._bar = None  # the live line stays for the next phase; end_progress clears it
        elif _level == NORMAL and self.i and self.stream is not None:
            el = time.perf_counter() - self.t0
            print(
                f"{self.prefix}: {self.what} {self.i}/{self.n} {'done' if self.i >= self.n else 'ended'} ({el:.0f} s)",
                file=self.stream,
                flush=True,
            )
