"""The importer contract: what a data set module provides, so realbench, crowd and ``stridefix import``
drive every set alike and a new set is one module (plus its test).

A data set module defines one subclass of :class:`Dataset` and exposes an instance as ``DATASET``;
the registry (:mod:`stridefix_analyzer.datasets`) finds it by itself. The subclass says

* who it is: :attr:`~Dataset.name` (``stridefix import NAME``, ``realbench --format NAME``), its help
  texts, :attr:`~Dataset.version` (bump when the written log changes for the same input: caches
  compare it) and :attr:`~Dataset.defaults` (e.g. the Wi-Fi age beyond which an entry is cached);
* how walks group: :meth:`~Dataset.find_walks` turns folders into :class:`WalkGroup` s (the walks that
  share a map: a floor, a building) with read options common to the group (e.g. one projection
  origin), and :meth:`~Dataset.regroup` may split a group once the walks are read (e.g. by building);
* how a walk is read: :meth:`~Dataset.read` → one :class:`~.rawwalk.RawWalk`, raising
  :class:`DatasetReadError` (or a subclass) naming the file when it is missing or unusable; its
  JSON-ready :meth:`~Dataset.summary` and one-line :meth:`~Dataset.format_summary`;
* what else it has: :meth:`~Dataset.floor_plan` and :meth:`~Dataset.beacons` (None where it has none).

Writing is not the set's business: :meth:`Dataset.import_walk` reads, writes with the one LCM writer
(:func:`.lcmwrite.write_lcmlog`) and returns the summary.
"""

from __future__ import annotations

import abc
import argparse
import dataclasses
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar

from stridefix_common.exits import NothingValid

from stridefix_analyzer.datasets.lcmwrite import write_lcmlog
from stridefix_analyzer.datasets.lines import not_text_hint
from stridefix_analyzer.datasets.rawwalk import RawWalk
from stridefix_analyzer.io.logread import Table

PathLike = str | os.PathLike[str]


class DatasetError(Exception):
    """Base of the data-set errors; the message says what is missing and where."""


class DatasetReadError(DatasetError):
    """A walk's file is missing, unreadable or unusable. The message names the file."""

    def __init__(self, path: PathLike, reason: str):
        super().__init__(f"{os.fspath(path)}: {reason}")
        self.path = os.fspath(path)
        self.reason = reason


class NothingValidError(DatasetReadError, NothingValid):
    """A walk's file was read but held not one valid sensor record (empty, binary, UTF-16, a header
    only): nothing is written, ``stridefix import`` exits
    :data:`~stridefix_common.exits.EXIT_NOTHING_VALID`. The message names the file, what was read,
    and the first malformed line."""


def check_has_records(raw: RawWalk) -> None:
    """Raise :class:`NothingValidError` when ``raw`` has no sensor record (see the class)."""
    if raw.n_sensor_records() > 0:
        return
    lines = raw.stats.get("lines")
    parts = [f"{lines} line(s) read" if lines is not None else "read"]
    if raw.skipped:
        line_no, reason = raw.skipped[0]
        parts.append(f"{len(raw.skipped)} malformed (the first: line {line_no}, {reason[:80]})")
    hint = not_text_hint(raw.path)
    if hint:
        parts.append(hint)
    raise NothingValidError(
        raw.path, f"nothing valid in the input: no sensor record (IMU MAG BARO GNSS WIFI); {', '.join(parts)}"
    )


class WalkDiscoveryError(DatasetError):
    """A folder given to :meth:`Dataset.find_walks` does not exist or holds no walk."""


class UnknownDatasetError(DatasetError):
    """No data set of that name is registered."""


#: Default age beyond which a Wi-Fi entry counts as cached [s] ("more than ~2 s older than
#: its scan is a cached entry"): every data set's, and so every command's ``--max-wifi-age-s`` (import,
#: realbench fusion and pdr-distance; pdr-distance once had 3).
DEFAULT_MAX_WIFI_AGE_S = 2.0


@dataclasses.dataclass(frozen=True)
class Defaults:
    """A data set's import defaults."""

    #: Wi-Fi entries last seen more than this before their scan are cached results, dropped [s].
    max_wifi_age_s: float


@dataclasses.dataclass(frozen=True)
class WalkGroup:
    """Walks that share one map (a floor, a building), before they are read.

    Attributes
    ----------
    label : str, e.g. ``site1/F2`` or the folder name
    walks : the walk files, sorted
    folder : where the group's side files are (floor plan, beacon table)
    floor_dir : the folder of the group's floor plan, or None when the set has none
    options : read options every walk of the group is read with (JSON-able values)
    """

    label: str
    walks: tuple[Path, ...]
    folder: Path
    floor_dir: Path | None = None
    options: Mapping[str, Any] = dataclasses.field(default_factory=dict)


@dataclasses.dataclass(frozen=True)
class FloorPlan:
    """A floor plan as the data set ships it: extent [m] (origin bottom-left), image, GeoJSON."""

    width_m: float
    height_m: float
    image: Path | None = None
    geojson: Mapping[str, Any] | None = None


class Dataset(abc.ABC):
    """One public data set (see the module docstring). Subclasses set the class attributes."""

    #: the format name
    name: ClassVar[str]
    #: one line for ``stridefix import --help``, and the sub-command's description
    title: ClassVar[str]
    description: ClassVar[str]
    #: the positional argument of ``stridefix import NAME``: metavar, help, and its noun in messages
    input_metavar: ClassVar[str] = "FILE"
    input_help: ClassVar[str] = "input file(s)"
    input_noun: ClassVar[str] = "file"
    #: summary keys printed as one JSON line per imported input
    summary_keys: ClassVar[tuple[str, ...]] = ("trace", "out", "messages", "skipped_lines", "duration_s")
    #: bump when the log content for the same input changes (caches compare it)
    version: ClassVar[int] = 1
    defaults: ClassVar[Defaults] = Defaults(max_wifi_age_s=DEFAULT_MAX_WIFI_AGE_S)
    #: firmware overrides (KEY=VALUE) for what the recording device already did to its samples, so the
    #: firmware does not do it twice; realbench and crowd replay this set's walks with them, before any
    #: ``--set`` of the user (which wins)
    firmware_sets: ClassVar[tuple[str, ...]] = ()
    #: position in listings (help texts, choices); the built-in sets in the order they were added
    list_order: ClassVar[int] = 100

    def __repr__(self) -> str:
        return f"<data set {self.name}>"

    # --- discovery ---------------------------------------------------------------------------------

    @abc.abstractmethod
    def find_walks(self, dirs: Sequence[PathLike]) -> list[WalkGroup]:
        """The groups of walks under ``dirs``. Raises :class:`WalkDiscoveryError`."""

    def regroup(
        self, group: WalkGroup, summaries: Sequence[Mapping[str, Any] | None]
    ) -> list[tuple[str, list[int]]]:
        """Split ``group`` once its walks are imported (``summaries[i]``: walk i's import summary, None
        when it failed): (label, walk indices) per part. Default: the group as it is."""
        return [(group.label, list(range(len(summaries))))]

    # --- reading -----------------------------------------------------------------------------------

    @abc.abstractmethod
    def read(self, path: PathLike, *, max_wifi_age_s: float | None = None, **options: Any) -> RawWalk:
        """Read one walk. ``max_wifi_age_s`` None: :attr:`defaults`. Raises :class:`DatasetReadError`."""

    @abc.abstractmethod
    def summary(self, raw: RawWalk) -> dict[str, Any]:
        """Counts per channel, duration, what was skipped: a JSON-ready dict with at least
        :attr:`summary_keys` but ``out`` (added by :meth:`import_walk`) and ``waypoints``."""

    @abc.abstractmethod
    def format_summary(self, summary: Mapping[str, Any]) -> str:
        """One line for the terminal."""

    def import_walk(self, path: PathLike, out_path: PathLike, **options: Any) -> dict[str, Any]:
        """Read one walk and write its raw-sensor LCM log; returns :meth:`summary` plus ``out``,
        ``events`` and ``importer_version``. Raises :class:`DatasetReadError` (:class:`NothingValidError`
        for a walk without one sensor record: nothing is written) or OSError."""
        raw = self.read(path, **options)
        check_has_records(raw)
        events = write_lcmlog(raw, out_path)
        summary = self.summary(raw)
        summary.update(out=os.fspath(out_path), events=events, importer_version=self.version)
        return summary

    # --- what else the set ships -----------------------------------------------------------------

    def floor_plan(self, folder: PathLike) -> FloorPlan | None:
        """The floor plan in ``folder`` (a group's ``floor_dir``), or None."""
        return None

    def beacons(self, folder: PathLike) -> Table | None:
        """The beacon table in ``folder`` (id, lat_deg, lon_deg, floor, ...), or None."""
        return None

    # --- ``stridefix import NAME`` -------------------------------------------------------------

    def add_arguments(self, parser: argparse.ArgumentParser) -> None:
        """The set's own import options (after the input and output arguments)."""
        add_max_wifi_age_argument(parser, self.defaults)

    def options(self, args: argparse.Namespace) -> dict[str, Any]:
        """The :meth:`read` options from parsed :meth:`add_arguments`."""
        return {"max_wifi_age_s": args.max_wifi_age_s}


def seconds_arg(text: str) -> float:
    """An argparse type: a finite number of seconds >= 0 (``float`` alone takes ``nan`` and ``-1``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a finite number of seconds >= 0")
    return value


def add_max_wifi_age_argument(parser: argparse.ArgumentParser, defaults: Defaults) -> None:
    """``--max-wifi-age-s S`` with the set's default."""
    parser.add_argument(
        "--max-wifi-age-s",
        type=seconds_arg,
        default=defaults.max_wifi_age_s,
        metavar="S",
        help="drop Wi-Fi entries last seen more than S before the scan time "
        f"(cached results; default {defaults.max_wifi_age_s:g})",
    )
