"""Stages of a SIL chain run as child processes: the ``stridefix`` tool itself and firmware replays.

Benchmarks and experiments chain ``stridefix sim`` → ``stridefixd`` → ``stridefix radiomap build``.
:func:`run_stage` runs one ``stridefix`` stage (the console script next to this interpreter) and
:func:`simulate` one simulator run, :func:`replay` one firmware replay through :class:`~stridefix_analyzer.firmware.Firmware`; both raise
the caller's error type naming the stage, the command and the end of its stderr.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware, FirmwareError


class StageError(RuntimeError):
    """A stage of the chain failed; the message names the stage and its output."""


def stridefix_exe() -> str:
    """The ``stridefix`` console script of this interpreter's environment."""
    return str(Path(sys.executable).with_name("stridefix"))


def run_stage(
    cmd: list[str], what: str, error: type[Exception] = StageError, tail: int = 2000
) -> subprocess.CompletedProcess[str]:
    """Runs ``cmd``; a non-zero exit raises ``error`` with ``what``, the command and stderr's end."""
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise error(f"{what} failed (exit {proc.returncode}): {' '.join(cmd)}\n{proc.stderr[-tail:]}")
    return proc


def replay(
    firmware: Firmware, what: str, error: type[Exception] = StageError, **kw: Any
) -> subprocess.CompletedProcess[str]:
    """One replay through ``firmware`` (arguments as :meth:`Firmware.run`), failures as ``error``."""
    try:
        return firmware.run(**kw)
    except FirmwareError as exc:
        raise error(f"{what} failed: {exc}") from exc


def simulate(
    scenario: str | Path | None, seed: int, out: Path, what: str, error: type[Exception] = StageError
) -> dict[str, Any]:
    """``stridefix sim`` of ``scenario`` (a built-in name or a TOML file; None = the default) into
    ``out``; returns its ``sim_summary.json``."""
    out.mkdir(parents=True, exist_ok=True)
    cmd = [stridefix_exe(), "sim", "--out", str(out), "--seed", str(seed)]
    if scenario is not None:
        cmd += ["--scenario", str(scenario)]
    run_stage(cmd, what, error)
    summary: dict[str, Any] = json.loads((out / "sim_summary.json").read_text())
    return summary
