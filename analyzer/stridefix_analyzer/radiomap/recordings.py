"""Radio-map input: LCM logs with ``WIFI`` (scans) and ``TRUTH`` (positions), grouped into recordings.
A recording also carries its ``BLE`` readings (one row per beacon of each ble_scan_t: t_us,
beacon_id, rssi_dbm), which the beacon learning (:mod:`.beacons`) uses.

Logs are grouped into *recordings* that share a clock: an argument ``a.lcmlog,b.lcmlog`` is one
recording of those files; a plain argument holding both WIFI and TRUTH is a recording by itself; the
remaining plain arguments (e.g. the simulator's firmware log and its truth log) are merged into one
recording. Each argument is read as one task (:mod:`stridefix_analyzer.parallel`: serially, or on
local processes or Dask workers for a fleet of walks); the recordings come back in argument order, so
the site is the same whoever read them.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from stridefix_analyzer.io.lcmfile import require_records
from stridefix_analyzer.io.logread import LogData, LogTruncatedWarning, Table, read_logs
from stridefix_analyzer.parallel import TaskRunner


class RadioMapInputError(Exception):
    """The logs cannot make a radio map (no WIFI or TRUTH, no scan placed, bad options)."""


class Recording:
    """One set of logs on one clock: WIFI scans, their APs, TRUTH and BLE readings, sorted by time."""

    def __init__(self, files: list[str], wifi: Table, wifi_ap: Table, truth: Table, ble: Table | None = None):
        self.files, self.wifi, self.wifi_ap, self.truth = list(files), wifi, wifi_ap, truth
        self.ble = ble if ble is not None else _ble_table([])
        self.name = " + ".join(self.files)


def _ble_table(rows: list[tuple[int, int, float]]) -> Table:
    a = list(zip(*rows)) if rows else [(), (), ()]
    return Table(
        {
            "t_us": np.asarray(a[0], dtype=np.int64),
            "beacon_id": np.asarray(a[1], dtype=np.int64),
            "rssi_dbm": np.asarray(a[2], dtype=np.float64),
        }
    ).sorted_by("t_us")


def read_ble(paths: list[str]) -> Table:
    """The BLE readings of the logs: one row (t_us, beacon_id, rssi_dbm) per beacon of each
    ble_scan_t on channel BLE (bad payloads skipped), sorted by time."""
    from stridefix import ble_scan_t

    from stridefix_analyzer.io.lcmfile import read_file
    from stridefix_analyzer.io.lcmindex import index_file

    rows: list[tuple[int, int, float]] = []

    def on_event(channel: str, payload: bytes) -> None:
        if channel != "BLE":
            return
        try:
            m = ble_scan_t.decode(payload)
        except Exception:  # noqa: BLE001 - a corrupt payload is bad data, skipped
            return
        rows.extend((int(m.t_us), int(b), float(r)) for b, r in zip(m.beacon_id, m.rssi_dbm))

    for path in paths:
        try:
            index = index_file(path)
        except OSError:
            index = None
        if index is None:  # not one unbroken chain of records: read_file salvages (and names errors)
            read_file(path, on_event)
            continue
        for record in index.records_of("BLE"):  # the same records, without a Python step per IMU one
            on_event("BLE", index.payload(int(record)))
    return _ble_table(rows)


def _read_one(path: str) -> LogData:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        data = read_logs([path], decode=("WIFI", "TRUTH"))
    require_records(data.inputs)  # an empty log, or one cut in its first record: nothing valid
    return data


def _merge(files: list[str], datas: list[LogData]) -> Recording:
    """Merge the WIFI / WIFI_AP / TRUTH tables of several files into one Recording."""
    name = " + ".join(files)
    missing = [ch for ch in ("WIFI", "TRUTH") if not any(d.table(ch) for d in datas)]
    if missing:
        raise RadioMapInputError(
            f"{name}: no {' and no '.join(missing)} messages (a radio map "
            f"needs Wi-Fi scans and ground truth on the same clock)"
        )
    wifi_parts, ap_parts, truth_parts, offset = [], [], [], 0
    for d in datas:
        w, truth = d.table("WIFI"), d.table("TRUTH")
        if w:
            wifi_parts.append(w.to_dict())
            cols = d.tables["WIFI_AP"].to_dict()
            cols["scan_row"] = cols["scan_row"] + offset
            ap_parts.append(cols)
            offset += len(w)
        if truth:
            truth_parts.append(truth.to_dict())

    def cat(parts):
        return Table({k: np.concatenate([p[k] for p in parts]) for k in parts[0]})

    wifi, wifi_ap, truth = cat(wifi_parts), cat(ap_parts), cat(truth_parts).sorted_by("t_us")
    order = np.argsort(wifi["t_us"], kind="stable")
    renumber = np.empty(len(order), dtype=np.int64)
    renumber[order] = np.arange(len(order))
    wifi = wifi.rows(order)
    cols = wifi_ap.to_dict()
    cols["scan_row"] = renumber[cols["scan_row"]]
    return Recording(files, wifi, Table(cols), truth, read_ble(files))


def arg_files(arg: Any) -> list[str]:
    """The log files of one argument (``a,b`` is two files of one recording)."""
    return [f for f in str(arg).split(",") if f]


def read_arg(arg: Any) -> Recording | tuple[str, LogData]:
    """One argument read (a task): its recording, or (file, its data) for a plain argument that is
    not a recording by itself (merged with the other such files afterwards)."""
    files = arg_files(arg)
    datas = [_read_one(f) for f in files]
    if len(files) > 1 or (datas[0].table("WIFI") and datas[0].table("TRUTH")):
        return _merge(files, datas)
    return files[0], datas[0]


def load_recordings(args: list[str], tasks: TaskRunner | None = None) -> list[Recording]:
    """Group log arguments into recordings (see the module docstring) and read them, one task per
    argument on ``tasks`` (None: in this process).

    Raises LogReadError (a file unreadable) or RadioMapInputError (a recording lacks WIFI/TRUTH).
    """
    recordings, rest = [], []
    for r in (tasks or TaskRunner(None, 1)).map(read_arg, args):
        if isinstance(r, Recording):
            recordings.append(r)
        else:
            rest.append(r)
    if rest:
        recordings.append(_merge([f for f, _ in rest], [d for _, d in rest]))
    return recordings
