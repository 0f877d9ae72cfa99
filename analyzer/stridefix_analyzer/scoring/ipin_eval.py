"""The IPIN competition's own score of an estimate file, as the organisers' evaluation script computes it.

Follows the scorer published with the IPIN 2023 Track 3 (smartphone) data set ("03 Evaluation": the
scoring trials' ground truth, sample submissions and the organisers' output table), figure for figure:

* **ground truth** (:func:`read_truth`): a CSV, one evaluation point per line: app time [s], longitude,
  latitude [deg], floor, point number.
* **estimate** (:func:`read_estimate`), the competition's submission format: comma-separated, the first
  :data:`SKIP_ROWS` rows skipped; column 1 the time [s], columns 5 and 6 longitude and latitude [deg]
  (swapped when the median of column 6 is below :data:`SWAP_BELOW_DEG`: a file written lat, lon),
  column 7 the floor; the other columns are not read.
* **match** (:func:`match_points`): each point takes the latest estimate whose time is at or before the
  point's time + :data:`MATCH_SLACK_S` (equal times: the later row). A point before every estimate is
  not scored (counted in ``unmatched``).
* **error** (:func:`point_errors`): the horizontal distance on the WGS-84 ellipsoid in the local tangent
  plane about the point (:func:`~stridefix_analyzer.datasets.gsd_convert.project`) +
  :data:`~.metrics.IPIN_FLOOR_PENALTY_M` × |floor difference|.
* **figures** (:func:`figures`), the columns of the organisers' table: EvAAL = the 75th percentile
  (:func:`~.metrics.ipin_score`, the one IPIN score of every report), mean, RMSE, median and P95 of the
  error (median and P95 by :func:`~.metrics.matlab_quantile` too), floor hit rate [%], mean planar error
  and the number of points. :func:`format_table` prints them in the organisers' layout, with their
  ranking (a team = the file id without its trailing trial number, ranked by its best file).

A file that cannot be read or parsed raises :class:`IpinFileError` naming the file, line and field.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from stridefix_common.exits import NothingValid
from stridefix_common.geodesy import project

from stridefix_analyzer.scoring.metrics import IPIN_FLOOR_PENALTY_M, ipin_score, matlab_quantile

#: rows at the top of an estimate file that the organisers' scorer skips
SKIP_ROWS = 2
#: an estimate counts for a point when its time is at or before the point's time + this [s]
MATCH_SLACK_S = 0.01
#: columns 5 and 6 of an estimate file are taken as latitude, longitude when the median of column 6
#: is below this [deg] (the organisers' rule: a file written lat, lon at a site east of 0° and west of
#: 10° E, north of 10° N)
SWAP_BELOW_DEG = 10.0
#: the estimate file's columns (1-based, as the format states them) and the truth file's
EST_COLUMNS = {"time": 1, "longitude": 5, "latitude": 6, "floor": 7}
TRUTH_COLUMNS = {"time": 1, "longitude": 2, "latitude": 3, "floor": 4, "point": 5}


class IpinFileError(ValueError):
    """A ground-truth or estimate file that cannot be read or parsed (exit status 2).

    Attributes
    ----------
    path : str
        The file.
    line : int or None
        1-based line number of the fault (None: the file as a whole).
    field : str or None
        The column at fault, e.g. ``"column 6 (latitude)"``.
    """

    def __init__(self, path: str | Path, problem: str, line: int | None = None, field: str | None = None):
        self.path, self.line, self.field = str(path), line, field
        where = self.path + (f", line {line}" if line is not None else "") + (f", {field}" if field else "")
        super().__init__(f"{where}: {problem}")


class IpinNothingValidError(IpinFileError, NothingValid):
    """A file read without fault but holding no data row (exit status 3)."""


@dataclasses.dataclass(frozen=True)
class Track:
    """Positions in time order, all arrays of shape (n,).

    Attributes
    ----------
    t_s : ndarray
        Time [s].
    lon_deg, lat_deg : ndarray
        WGS-84 longitude and latitude [deg].
    floor : ndarray
        Floor number (float: the estimate format allows any number).
    line : ndarray of int
        The 1-based line of each row in its file (for messages).
    """

    t_s: np.ndarray
    lon_deg: np.ndarray
    lat_deg: np.ndarray
    floor: np.ndarray
    line: np.ndarray


def _read_rows(path: str | Path, columns: dict[str, int], skip: int) -> tuple[np.ndarray, np.ndarray]:
    """The named ``columns`` (1-based) of a comma-separated file after its first ``skip`` lines, as
    (values, shape (n, len(columns)); 1-based line numbers, shape (n,)); blank lines are ignored."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise IpinFileError(path, f"cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise IpinNothingValidError(path, f"not a text file (byte {exc.start}: {exc.reason})") from None
    need = max(columns.values())
    rows, lines = [], []
    for number, raw in enumerate(text.splitlines(), start=1):
        if number <= skip or not raw.strip():
            continue
        cells = raw.split(",")
        if len(cells) < need:
            raise IpinFileError(path, f"{len(cells)} comma-separated fields, {need} needed", number)
        row = []
        for name, col in columns.items():
            try:
                value = float(cells[col - 1])
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                field = f"column {col} ({name})"
                raise IpinFileError(path, f"{cells[col - 1].strip()!r} is not a finite number", number, field)
            row.append(value)
        rows.append(row)
        lines.append(number)
    if not rows:
        raise IpinNothingValidError(
            path, f"no data row (after the first {skip} lines)" if skip else "no data row"
        )
    return np.array(rows, dtype=np.float64), np.array(lines, dtype=np.int64)


def _check_range(path: str | Path, track: Track, columns: dict[str, int]) -> None:
    """Raises :class:`IpinFileError` at the first latitude outside ±90° or longitude outside ±180°."""
    for name, values, top in (("latitude", track.lat_deg, 90.0), ("longitude", track.lon_deg, 180.0)):
        bad = np.flatnonzero(np.abs(values) > top)
        if bad.size:
            i = int(bad[0])
            field = f"column {columns[name]} ({name})"
            raise IpinFileError(path, f"{values[i]:g} is outside ±{top:g}°", int(track.line[i]), field)


def read_truth(path: str | Path) -> tuple[Track, np.ndarray]:
    """The organisers' ground truth: (points as a :class:`Track` in file order, point numbers, shape (n,)).

    Raises
    ------
    IpinFileError
        Unreadable file, a short line, a field that is no finite number, a position out of range.
    IpinNothingValidError
        No data row.
    """
    values, lines = _read_rows(path, TRUTH_COLUMNS, skip=0)
    track = Track(values[:, 0], values[:, 1], values[:, 2], values[:, 3], lines)
    _check_range(path, track, TRUTH_COLUMNS)
    return track, values[:, 4].astype(np.int64)


def read_estimate(path: str | Path) -> Track:
    """An estimate file in the competition format, sorted by time (stable: equal times keep file order);
    columns 5 and 6 swapped when the median of column 6 is below :data:`SWAP_BELOW_DEG`.

    Raises
    ------
    IpinFileError
        Unreadable file, a short line, a field that is no finite number, a position out of range.
    IpinNothingValidError
        No row after the first :data:`SKIP_ROWS`.
    """
    values, lines = _read_rows(path, EST_COLUMNS, skip=SKIP_ROWS)
    lon, lat = values[:, 1], values[:, 2]
    columns = dict(EST_COLUMNS)
    if np.median(lat) < SWAP_BELOW_DEG:
        lon, lat = lat, lon
        columns.update(longitude=EST_COLUMNS["latitude"], latitude=EST_COLUMNS["longitude"])
    order = np.argsort(values[:, 0], kind="stable")
    track = Track(values[order, 0], lon[order], lat[order], values[order, 3], lines[order])
    _check_range(path, track, columns)
    return track


def match_points(truth: Track, estimate: Track) -> np.ndarray:
    """Row of ``estimate`` (sorted by time) for each truth point, shape (n_points,): the latest whose
    time ≤ the point's time + :data:`MATCH_SLACK_S` (equal times: the later row); −1 where none."""
    return np.searchsorted(estimate.t_s, truth.t_s + MATCH_SLACK_S, side="right") - 1


def planar_distance_m(
    lat_deg: np.ndarray, lon_deg: np.ndarray, ref_lat_deg: np.ndarray, ref_lon_deg: np.ndarray
) -> np.ndarray:
    """Horizontal distance [m] of each position from its reference, shape (n,): the WGS-84 local tangent
    plane about the reference (:func:`~stridefix_analyzer.datasets.gsd_convert.project`); all [deg]."""
    out = np.empty(len(lat_deg))
    for i, (la, lo, la0, lo0) in enumerate(zip(lat_deg, lon_deg, ref_lat_deg, ref_lon_deg)):
        x, y = project([la], [lo], float(la0), float(lo0))
        out[i] = math.hypot(float(x[0]), float(y[0]))
    return out


@dataclasses.dataclass(frozen=True)
class PointErrors:
    """The errors at the matched points, arrays of shape (n_matched,).

    Attributes
    ----------
    planar_m : ndarray
        Horizontal distance [m].
    floor_diff : ndarray
        |estimated floor − true floor| [floors].
    error_m : ndarray
        ``planar_m`` + :data:`~.metrics.IPIN_FLOOR_PENALTY_M` × ``floor_diff`` [m].
    point : ndarray of int
        The truth's point numbers.
    unmatched : int
        Points with no estimate at or before them (not scored).
    """

    planar_m: np.ndarray
    floor_diff: np.ndarray
    error_m: np.ndarray
    point: np.ndarray
    unmatched: int


def point_errors(truth: Track, points: np.ndarray, estimate: Track) -> PointErrors:
    """Match (:func:`match_points`) and measure the error at every truth point that has an estimate."""
    row = match_points(truth, estimate)
    ok = row >= 0
    r = row[ok]
    planar = planar_distance_m(estimate.lat_deg[r], estimate.lon_deg[r], truth.lat_deg[ok], truth.lon_deg[ok])
    floor_diff = np.abs(estimate.floor[r] - truth.floor[ok])
    error = planar + IPIN_FLOOR_PENALTY_M * floor_diff
    return PointErrors(planar, floor_diff, error, points[ok], int(np.count_nonzero(~ok)))


#: the figures of the organisers' table: key → column heading
COLUMNS = {
    "evaal_m": "EvAAL",
    "mean_m": "MEAN",
    "rmse_m": "RMSE",
    "median_m": "MEDIAN",
    "p95_m": "P95",
    "floor_hit_rate_pct": "FHR(%)",
    "mean_planar_error_m": "MPExy",
}


def figures(errors: PointErrors) -> dict[str, float | int]:
    """The organisers' figures of one file: :data:`COLUMNS` (NaN when no point matched), ``points``
    (matched) and ``unmatched``. EvAAL, median and P95 by :func:`~.metrics.matlab_quantile` [m]."""
    e, n = errors.error_m, len(errors.error_m)
    nan = math.nan
    median, p95 = (float(v) for v in matlab_quantile(e, [0.5, 0.95])) if n else (nan, nan)
    return {
        "evaal_m": ipin_score(errors.planar_m, errors.floor_diff),
        "mean_m": float(np.mean(e)) if n else nan,
        "rmse_m": float(np.sqrt(np.mean(e**2))) if n else nan,
        "median_m": median,
        "p95_m": p95,
        "floor_hit_rate_pct": 100.0 * float(np.mean(errors.floor_diff == 0)) if n else nan,
        "mean_planar_error_m": float(np.mean(errors.planar_m)) if n else nan,
        "points": n,
        "unmatched": errors.unmatched,
    }


def file_id(path: str | Path) -> str:
    """The id the organisers' table shows: the file name without its extension."""
    return Path(path).stem


def team_of(ident: str) -> str:
    """A file id's team: the id without its trailing trial number (``S323ZENODOTS01`` → ``S323ZENODOTS``)."""
    return re.sub(r"\d+$", "", ident) or ident


def score_file(truth: tuple[Track, np.ndarray], estimate_path: str | Path) -> dict[str, float | int | str]:
    """Score one estimate file against ``truth`` (:func:`read_truth`'s pair): ``{"id": file_id,
    **figures}`` (see :func:`figures`).

    Raises
    ------
    IpinFileError
        The estimate file unreadable or malformed (:class:`IpinNothingValidError`: no data row).
    """
    estimate = read_estimate(estimate_path)
    return {"id": file_id(estimate_path), **figures(point_errors(*truth, estimate))}


def ranking(results: Sequence[dict]) -> list[tuple[str, float]]:
    """(team, its best EvAAL [m]) sorted best first; files with no matched point are left out."""
    best: dict[str, float] = {}
    for r in results:
        v = float(r["evaal_m"])
        if math.isfinite(v):
            team = team_of(str(r["id"]))
            best[team] = min(v, best.get(team, math.inf))
    return sorted(best.items(), key=lambda kv: (kv[1], kv[0]))


def format_table(results: Sequence[dict]) -> str:
    """The organisers' table (tab-separated: one row per file, figures to 2 decimals) and ranking."""
    lines = ["TeamName-FileId".ljust(20) + "".join(f"\t{h:<7}" for h in COLUMNS.values()) + "\tPOINTS"]
    for r in results:
        cells = "".join(f"\t{float(r[k]):7.2f}" for k in COLUMNS)
        lines.append(f"{r['id']:>20}:{cells}\t{r['points']}")
    lines += ["", "Ranking:", " Team name \t 3rd quantile "]
    lines += [f"{k} {team} \t{v:11.2f} m " for k, (team, v) in enumerate(ranking(results), start=1)]
    return "\n".join(lines)
