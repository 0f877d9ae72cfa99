"""Stages of a SIL chain: a simulator run, a firmware replay, a timed command.

Benchmarks and experiments chain the simulator → ``stridefixd`` → the analyzer. :func:`simulate` runs
one scenario in this process (:mod:`stridefix_sim`'s functions), :func:`replay` one firmware replay
through :class:`~stridefix_analyzer.firmware.Firmware` (the firmware is a process, as on a logger);
:func:`run_stage` runs a command whose process is what a bench measures (a ``stridefix`` command's
wall time, :func:`stridefix_exe`). Each raises the caller's error type naming the stage and the cause.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

from stridefix_analyzer.firmware import Firmware, FirmwareError
from stridefix_sim.pipeline import simulate as run_simulation
from stridefix_sim.pipeline import write_outputs
from stridefix_sim.scenario import ScenarioError, resolve_scenario


class StageError(RuntimeError):
    """A stage of the chain failed; the message names the stage and its output."""


def _console_script(name: str) -> str:
    """The console script ``name`` of this interpreter's environment."""
    return str(Path(sys.executable).with_name(name))


def stridefix_exe() -> str:
    """The product's ``stridefix`` console script."""
    return _console_script("stridefix")


def lab_exe() -> str:
    """The lab's ``stridefix-lab`` console script."""
    return _console_script("stridefix-lab")


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
    scenario: str | Path | None,
    seed: int | None,
    out: Path,
    what: str,
    error: type[Exception] = StageError,
    duration_s: float | None = None,
) -> dict[str, Any]:
    """The simulator's run of ``scenario`` (a built-in name or a TOML file; None = the default) with
    ``seed`` (None: the scenario's) written into ``out`` (what ``stridefix sim`` writes); returns its ``sim_summary.json``."""
    try:
        sc = resolve_scenario(None if scenario is None else str(scenario))
        sc = sc.with_overrides(seed=seed, duration_s=duration_s)
        write_outputs(run_simulation(sc), out)
    except (ScenarioError, OSError) as exc:
        raise error(f"{what} failed: {exc}") from exc
    summary: dict[str, Any] = json.loads((out / "sim_summary.json").read_text())
    return summary
