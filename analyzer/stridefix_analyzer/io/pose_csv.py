"""CSV exports of a scored analysis (``stridefix analyze --csv DIR``), for spreadsheets and pandas.

Files written into a folder by :func:`write_csv`:

- ``<scheme>.csv``: every POSE of the scheme as logged, one row per message, in time order; the
  columns are the pose_t fields (``t_us``, ``x_m``, ``y_m``, ``floor``, ``heading_rad``, ``sigma_m``,
  the covariance, …, names with their units) and ``t_s`` (t_us / 1e6);
- ``<scheme>_matched.csv``: one row per truth sample, the POSE matched causally to it exactly as the
  scores pair them (:func:`stridefix_analyzer.scoring.metrics.match_causal`: ``scored``, the truth's
  and the pose's position and floor, ``error_m``);
- ``truth.csv``: the TRUTH rows scored against.

Floats are written with 17 significant digits (``repr``), so reading them back gives the same values.
"""

from __future__ import annotations

import csv
import os
from typing import TYPE_CHECKING

import numpy as np

from stridefix_analyzer.io.logread import Table

if TYPE_CHECKING:
    from stridefix_analyzer.scoring.metrics import Metrics

_MATCHED = (
    "t_us",
    "scored",
    "truth_x_m",
    "truth_y_m",
    "truth_floor",
    "pose_t_us",
    "pose_x_m",
    "pose_y_m",
    "pose_floor",
    "pose_sigma_m",
    "error_m",
)


def _cell(v: object) -> object:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, (np.integer, np.bool_)):
        return int(v)
    return v


def write_table(
    path: str, table: Table, names: list[str] | tuple[str, ...] | None = None, t_s: bool = False
) -> None:
    """``table``'s columns ``names`` (default all, in order) as a CSV file; ``t_s`` adds t_us / 1e6 first."""
    cols = [n for n in (names or table.names) if n in table]
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow((["t_s"] if t_s else []) + cols)
        data = [np.asarray(table[c]) for c in cols]
        t = np.asarray(table["t_us"], np.int64) if t_s else None
        for i in range(len(table)):
            row = [_cell(d[i]) for d in data]
            if t is not None:
                row.insert(0, f"{t[i] // 1_000_000}.{t[i] % 1_000_000:06d}")
            w.writerow(row)


def write_csv(metrics: Metrics, out_dir: str | os.PathLike[str]) -> dict[str, str]:
    """Write the files of the module docstring into ``out_dir``; returns name → path."""
    os.makedirs(out_dir, exist_ok=True)
    paths: dict[str, str] = {}

    def out(name: str) -> str:
        paths[name] = os.path.join(out_dir, f"{name}.csv")
        return paths[name]

    for s in metrics.schemes.values():
        write_table(out(s.name), s.pose, t_s=True)
        write_table(out(f"{s.name}_matched"), s.match, _MATCHED)
    write_table(out("truth"), metrics.truth, t_s=True)
    return paths
