"""Radio-map input: LCM logs with ``WIFI`` (scans) and ``TRUTH`` (positions), grouped into recordings.

Logs are grouped into *recordings* that share a clock: an argument ``a.lcmlog,b.lcmlog`` is one
recording of those files; a plain argument holding both WIFI and TRUTH is a recording by itself; the
remaining plain arguments (e.g. the simulator's firmware log and its truth log) are merged into one
recording.
"""

from __future__ import annotations

import warnings

import numpy as np

from stridefix_analyzer.io.logread import LogData, LogTruncatedWarning, Table, read_logs


class RadioMapInputError(Exception):
    """The logs cannot make a radio map (no WIFI or TRUTH, no scan placed, bad options)."""


class Recording:
    """One set of logs on one clock: WIFI scans, their APs and TRUTH, sorted by time."""

    def __init__(self, files: list[str], wifi: Table, wifi_ap: Table, truth: Table):
        self.files, self.wifi, self.wifi_ap, self.truth = list(files), wifi, wifi_ap, truth
        self.name = " + ".join(self.files)


def _read_one(path: str) -> LogData:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        return read_logs([path], decode=("WIFI", "TRUTH"))


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
    return Recording(files, wifi, Table(cols), truth)


def load_recordings(args: list[str]) -> list[Recording]:
    """Group log arguments into recordings (see the module docstring) and read them.

    Raises LogReadError (a file unreadable) or RadioMapInputError (a recording lacks WIFI/TRUTH).
    """
    recordings, rest = [], []
    for arg in args:
        files = [f for f in str(arg).split(",") if f]
        datas = [_read_one(f) for f in files]
        if len(files) > 1 or (datas[0].table("WIFI") and datas[0].table("TRUTH")):
            recordings.append(_merge(files, datas))
        else:
            rest.append((files[0], datas[0]))
    if rest:
        recordings.append(_merge([f for f, _ in rest], [d for _, d in rest]))
    return recordings
