"""The one way the analyzer runs the firmware: :class:`Firmware` wraps the ``stridefixd`` binary.

Every replay of a recording (candump or raw-sensor LCM log) through the estimator goes through
:meth:`Firmware.run`, so the command line is built in one place, failures raise one exception type
naming the command and its stderr, and ``--set KEY=VALUE`` keys are checked once against the
firmware's own parameter table (``stridefixd --print-config --json``, generated from the X-macro
of ``firmware/core/sf_params.h``). Python never spells the list of parameter keys itself.
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[2]
DEFAULT_STRIDEFIXD = REPO / "build" / "firmware" / "stridefixd"


#: Heading variants a hand-held walk is replayed with. realbench uses, per fold, the one whose STEP
#: headings agree best with the training walks' truth directions (radiomap/heading.py); the crowd solves
#: the one whose walks agree best on their heading bias at the anchors (crowd/graph.py). The question
#: the firmware default answers for a body-worn board, not for every device: is the gait-learned
#: mounting offset better than a fixed one (a hand-held phone: so far yes for the fixed one). The
#: "wide magnetometer gate" variants (tolerances 16 uT / 16 deg) are gone: they made up for field and
#: dip references acquired during a phone's calibration gestures, which the attitude now acquires from
#: quiet samples and acquires again after a long rejection (sf_attitude.h); chosen per fold they cost
#: ipin2023's truth-initialised PDR 0.5 m (6.17 against 5.68 m mean) and were even on msindoor site2/F3.
HEADING_VARIANTS = {
    "learned": [],
    "fixed": ["heading.learn_offset=0"],
}


class FirmwareError(RuntimeError):
    """stridefixd is missing, refused its arguments or failed; the message names the command."""


@dataclasses.dataclass(frozen=True)
class Param:
    """One firmware parameter: ``key`` is ``section.name`` as ``--set`` and INI files spell it."""

    key: str
    default: str
    unit: str = ""
    min: float | None = None
    max: float | None = None
    help: str = ""


def default_path() -> Path:
    """``$STRIDEFIXD`` when set (make test sets it), else the CMake build's binary; for an installed
    analyzer (no build beside it) the ``stridefixd`` beside this Python (``cmake --install --prefix
    VENV``), else the one on ``PATH``."""
    if os.environ.get("STRIDEFIXD"):
        return Path(os.environ["STRIDEFIXD"])
    beside = Path(sys.executable).parent / "stridefixd"
    on_path = shutil.which("stridefixd")
    for found in (DEFAULT_STRIDEFIXD, beside, Path(on_path) if on_path else None):
        if found is not None and found.is_file():
            return found
    return DEFAULT_STRIDEFIXD


def add_stridefixd_argument(parser: argparse.ArgumentParser) -> None:
    """The ``--stridefixd PATH`` option every command that replays through the firmware takes."""
    parser.add_argument(
        "--stridefixd",
        default=str(default_path()),
        metavar="PATH",
        help="firmware binary ($STRIDEFIXD when set, else build/firmware/stridefixd, else the installed one)",
    )


def set_args(sets: Iterable[str]) -> list[str]:
    """``["--set", kv, ...]`` for KEY=VALUE strings."""
    return [a for kv in sets for a in ("--set", kv)]


class Firmware:
    """A built ``stridefixd``. ``path`` defaults to :func:`default_path`."""

    def __init__(self, path: str | os.PathLike[str] | None = None) -> None:
        self.path = Path(path) if path is not None else default_path()

    def __repr__(self) -> str:
        return f"Firmware({str(self.path)!r})"

    def check_executable(self) -> None:
        """Raises :class:`FirmwareError` unless the binary exists and is executable."""
        if not (self.path.is_file() and os.access(self.path, os.X_OK)):
            raise FirmwareError(f"{self.path}: stridefixd not found or not executable (build it: make build)")

    def _call(self, args: Sequence[str], timeout: float | None = None) -> subprocess.CompletedProcess[str]:
        self.check_executable()
        cmd = [str(self.path), *map(str, args)]
        try:
            return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired as exc:
            raise FirmwareError(f"{' '.join(cmd)}: no answer within {timeout} s") from exc

    @functools.cached_property
    def params(self) -> dict[str, Param]:
        """Every parameter of the firmware's table (``--print-config --json``), by key; read once."""
        proc = self._call(["--print-config", "--json"], timeout=30)
        if proc.returncode != 0:
            raise FirmwareError(
                f"{self.path} --print-config --json exited {proc.returncode}: {proc.stderr[-300:]}"
            )
        try:
            return {
                r["key"]: Param(
                    key=r["key"],
                    default=str(r["default"]),
                    unit=r.get("unit", ""),
                    min=r.get("min"),
                    max=r.get("max"),
                    help=r.get("help", ""),
                )
                for r in json.loads(proc.stdout)["params"]
            }
        except (ValueError, KeyError, TypeError) as exc:
            raise FirmwareError(f"{self.path} --print-config --json: unreadable ({exc})") from exc

    def check_sets(self, sets: Iterable[str]) -> list[str]:
        """Validates KEY=VALUE overrides once: every key must be in :attr:`params` and stridefixd must
        accept the values (range, syntax). Returns them as a list; raises :class:`FirmwareError`."""
        sets = list(sets)
        bad = [kv for kv in sets if "=" not in kv or kv.split("=", 1)[0].strip() not in self.params]
        if bad:
            raise FirmwareError(
                f"--set: unknown key or not KEY=VALUE: {bad}; see `stridefixd --print-config`"
            )
        if sets:
            proc = self._call(["--print-config", *set_args(sets)], timeout=30)
            if proc.returncode != 0:
                raise FirmwareError(f"--set: {proc.stderr.strip()[-300:]}")
        return sets

    def version(self) -> str:
        """``stridefixd -V`` (or why it is unknown)."""
        try:
            return self._call(["-V"], timeout=10).stdout.strip()
        except (OSError, FirmwareError) as exc:
            return f"unknown ({exc})"

    def command(
        self,
        *,
        log: str | os.PathLike[str],
        input: str | os.PathLike[str] | None = None,
        replay: str | os.PathLike[str] | None = None,
        site: str | os.PathLike[str] | None = None,
        fusion: str | None = None,
        sets: Iterable[str] = (),
        quiet: bool = True,
        extra: Sequence[str] = (),
        channels: Sequence[str] | None = None,
    ) -> list[str]:
        """The stridefixd command line for one replay: exactly one of ``input`` (candump file or
        ``lcmlog:FILE``) and ``replay`` (a raw-sensor LCM log); ``channels``: write only these
        (``--channels``; None: every channel)."""
        if (input is None) == (replay is None):
            raise FirmwareError("Firmware.run: give exactly one of input= and replay=")
        cmd = [str(self.path)]
        cmd += ["--input", str(input)] if input is not None else ["--replay", str(replay)]
        # --force: the log is this run's output, replaced on a re-run (stridefixd refuses otherwise)
        cmd += ["--log", str(log), "--force"]
        if site is not None:
            cmd += ["--site", str(site)]
        if fusion is not None:
            cmd += ["--fusion", fusion]
        if channels is not None:
            cmd += ["--channels", ",".join(channels)]
        if quiet:
            cmd.append("-q")
        return cmd + set_args(sets) + [str(a) for a in extra]

    def run_batch(
        self, runs: Sequence[dict[str, Any]], batch_file: str | os.PathLike[str]
    ) -> list[int] | None:
        """Runs several replays (each the arguments of :meth:`command`) in one ``stridefixd --batch``
        process, the batch file written to ``batch_file`` (removed after): their exit statuses, in
        order, or None when an argument cannot go into a batch line (a TAB or a line break) or the
        batch itself failed; a failed replay's messages are in no one place, so run it alone."""
        self.check_executable()
        lines = [self.command(**kw)[1:] for kw in runs]
        if any("\t" in a or "\n" in a or "\r" in a for line in lines for a in line):
            return None
        path = Path(batch_file)
        path.write_text("".join("\t".join(line) + "\n" for line in lines), encoding="utf-8")
        try:
            proc = subprocess.run([str(self.path), "--batch", str(path)], capture_output=True, text=True)
        finally:
            path.unlink(missing_ok=True)
        statuses = [int(v) for v in proc.stdout.split()]
        return statuses if proc.returncode == 0 and len(statuses) == len(lines) else None

    def run(
        self, *, check: bool = True, timeout: float | None = None, **kw: Any
    ) -> subprocess.CompletedProcess[str]:
        """Runs one replay (arguments as :meth:`command`). With ``check`` a non-zero exit raises
        :class:`FirmwareError` with the command and the end of stderr; otherwise the caller reads
        ``returncode``."""
        self.check_executable()
        cmd = self.command(**kw)
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired as exc:
            raise FirmwareError(f"{' '.join(cmd)}: still running after {timeout} s") from exc
        if check and proc.returncode != 0:
            raise FirmwareError(
                f"stridefixd exit {proc.returncode}: {' '.join(cmd)}: {proc.stderr.strip()[-500:]}"
            )
        return proc
