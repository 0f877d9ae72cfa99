"""The inputs of both realbench benchmarks: which walks (through the data-set protocol), their imports
(cached), and the firmware that replays them.

Every walk of a group is imported once into ``<cache>/<stem>.lcmlog`` with a ``<stem>.import.json``
beside it (the import summary plus its cache key: file, size, mtime, data set, importer version and read
options); a later run with the same key reuses the log. Nothing here knows a data set by name.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from stridefix_analyzer import datasets
from stridefix_analyzer.datasets.lines import MalformedLineWarning
from stridefix_analyzer.datasets.protocol import Dataset, DatasetError, WalkGroup
from stridefix_analyzer.firmware import Firmware, FirmwareError
from stridefix_analyzer.io.jsonio import json_ready
from stridefix_common.exits import NothingValid


class RealbenchError(RuntimeError):
    """The benchmark cannot run (no walks, no firmware binary, a bad --set). The message says what."""


class NoWalkImportedError(RealbenchError, NothingValid):
    """Walks were found but not one could be imported (every file empty, binary, not of the format):
    nothing valid in the input, so nothing to fold or score."""


def check_some_imported(walks: Sequence[Mapping[str, Any]]) -> None:
    """Raise :class:`NoWalkImportedError` naming the first walk's file and error when ``walks`` (records
    of :func:`new_walk`) are not empty and none was imported."""
    if not walks or any(w["import"] is not None for w in walks):
        return
    first = walks[0]
    why = str(first["error"]).removeprefix("import failed: ")
    more = f"; {len(walks) - 1} more walk(s) failed alike" if len(walks) > 1 else ""
    raise NoWalkImportedError(
        f"nothing valid in the input: not one walk imported ({first['trace']}: {why}{more})"
    )


def new_walk(trace: Path) -> dict[str, Any]:
    """The record of one walk before anything ran: ``trace``, ``walk`` (its stem), ``import``,
    ``error`` (None or why the walk could not be run), ``warnings``."""
    return {"trace": str(trace), "walk": trace.stem, "import": None, "error": None, "warnings": []}


def dataset(name: str) -> Dataset:
    """The registered data set ``name``; raises :class:`RealbenchError`."""
    try:
        return datasets.get(name)
    except DatasetError as exc:
        raise RealbenchError(str(exc)) from None


def find_groups(ds: Dataset, dirs: Sequence[str | Path], limit: int | None = None) -> list[WalkGroup]:
    """``ds.find_walks(dirs)``, each group cut to its first ``limit`` walks; raises :class:`RealbenchError`."""
    try:
        groups = ds.find_walks(dirs)
    except DatasetError as exc:
        raise RealbenchError(str(exc)) from None
    if limit is None:
        return groups
    n = max(int(limit), 0)
    return [WalkGroup(g.label, g.walks[:n], g.folder, g.floor_dir, g.options) for g in groups]


def firmware(path: str | Path, sets: Sequence[str] = ()) -> Firmware:
    """The firmware at ``path``, checked: executable, and every ``--set`` KEY=VALUE accepted (once,
    not in every replay). Raises :class:`RealbenchError`."""
    fw = Firmware(path)
    try:
        fw.check_executable()
        fw.check_sets(sets)
    except FirmwareError as exc:
        raise RealbenchError(str(exc)) from None
    return fw


def cached_import(
    ds: Dataset, walk: Path, cache_dir: Path, options: Mapping[str, Any], reimport: bool = False
) -> dict[str, Any]:
    """Import ``walk`` into ``cache_dir/<stem>.lcmlog`` unless an up-to-date copy is there; returns
    the import summary (with ``out``, ``warnings`` and ``cache_key``).

    ``options`` are the read options (``max_wifi_age_s``, the group's own); JSON-able, part of the key.
    Raises what :meth:`~stridefix_analyzer.datasets.protocol.Dataset.import_walk` raises.
    """
    log = cache_dir / f"{walk.stem}.lcmlog"
    meta = cache_dir / f"{walk.stem}.import.json"
    st = walk.stat()
    key = {
        "trace": str(walk.resolve()),
        "size": st.st_size,
        "mtime_ns": st.st_mtime_ns,
        "dataset": ds.name,
        "importer_version": ds.version,
        "options": json.loads(json.dumps(dict(options))),
    }
    if not reimport and log.is_file() and meta.is_file():
        try:
            cached = json.loads(meta.read_text(encoding="utf-8"))
            if cached.get("cache_key") == key:
                return dict(cached)
        except (OSError, ValueError):
            pass
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MalformedLineWarning)
        summary = ds.import_walk(walk, log, **options)
    summary["warnings"] = [str(w.message) for w in caught]
    summary["cache_key"] = key
    meta.write_text(json.dumps(json_ready(summary), indent=1) + "\n", encoding="utf-8")
    return summary
