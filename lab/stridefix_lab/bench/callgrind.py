"""The instructions a program spends inside some functions, counted by callgrind: the one valgrind call
of the cost benches (:mod:`.particle_cost`, :mod:`.perf`). Instruction counts repeat on a noisy machine,
where wall time does not."""

from __future__ import annotations

import re
import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

from stridefix_lab.stages import StageError

_COLLECTED = re.compile(r"Collected\s*:\s*(\d+)")


def instructions(program: Sequence[str], functions: Sequence[str], out: Path, bench: str) -> int:
    """Instructions inside ``functions`` (summed, ``--toggle-collect`` each) over one run of
    ``program``; callgrind's output goes to ``out``. Raises StageError naming ``bench`` when valgrind
    is missing or the run fails."""
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        raise StageError(f"{bench}: valgrind not found (apt-get install valgrind)")
    cmd = [valgrind, "--tool=callgrind", f"--callgrind-out-file={out}"]
    cmd += [f"--toggle-collect={f}" for f in functions]
    cmd += [str(a) for a in program]
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    m = _COLLECTED.search(proc.stderr)
    if proc.returncode != 0 or m is None:
        raise StageError(f"{bench}: {' '.join(cmd)} failed ({proc.returncode}): {proc.stderr[-400:]}")
    return int(m.group(1))
