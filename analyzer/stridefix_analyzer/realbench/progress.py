"""Progress lines of the realbench phases on stderr: ``realbench: WHAT [i/n] note  elapsed, ETA``."""

from __future__ import annotations

import sys
import time
from typing import TextIO


class Progress:
    """Counts the steps of one phase of ``n`` steps and prints a line per step to ``stream``."""

    def __init__(self, what: str, n: int, stream: TextIO = sys.stderr):
        self.what, self.n, self.t0, self.i, self.stream = what, n, time.perf_counter(), 0, stream

    def step(self, note: str = "") -> None:
        self.i += 1
        el = time.perf_counter() - self.t0
        eta = el / self.i * (self.n - self.i)
        print(
            f"realbench: {self.what} [{self.i}/{self.n}] {note}  elapsed {el:.0f} s, ETA {eta:.0f} s",
            file=self.stream,
            flush=True,
        )
