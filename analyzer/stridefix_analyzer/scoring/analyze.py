"""``stridefix analyze``: read LCM logs, score POSE against TRUTH, write metrics.json + analysis.npz.

Outputs in ``--out DIR`` (default ``out/analyze``):

- ``metrics.json``: the summary (see :meth:`stridefix_analyzer.metrics.Metrics.summary`; per scheme
  and for the primary scheme the ``ipin_score`` [m], p75 of 2-D error + 15 m × |floor error| by Matlab's
  quantile: :func:`stridefix_analyzer.scoring.metrics.ipin_score`) plus
  ``inputs``, ``messages`` (events per channel), ``unknown_channels``, ``decode_errors``,
  ``health`` (last HEALTH fields), ``config`` (``version``, ``dbc_sha256``, ``params``) and
  ``warnings``. Non-finite numbers are written as ``null``.
  ``fix_sources`` (FIX records per scheme and per method, Wi-Fi, GNSS, BLE, landmark: offered,
  accepted, rejected and rejected by reason; :mod:`stridefix_analyzer.scoring.fixsources`),
  ``context`` when the logs hold CONTEXT (the multi-scheme controller's events, switches by rule,
  time per context, radios-on seconds from the last HEALTH; :mod:`stridefix_analyzer.scoring.context`;
  null without CONTEXT), and
- ``analysis.npz``: the per-truth-sample series the report plots
  (see :meth:`stridefix_analyzer.metrics.Metrics.series`).

Exit status (:mod:`stridefix_common.exits`): 0 success; 1 nothing could be scored (every truth
sample precedes the first POSE); 2 missing or unreadable input, or no TRUTH / no POSE in the logs;
3 nothing valid in them (not an LCM log, or neither TRUTH nor POSE in any).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from typing import Any

import numpy as np
from stridefix_common.exits import input_error_status

from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.logread import (
    KNOWN_CHANNELS,
    LogData,
    LogReadError,
    LogTruncatedWarning,
    read_logs,
)
from stridefix_analyzer.io.results import write_analyze_metrics
from stridefix_analyzer.schemes import NAMES, is_fused
from stridefix_analyzer.scoring import floor_height, iso18305
from stridefix_analyzer.scoring.context import context_summary, format_context_line
from stridefix_analyzer.scoring.fixsources import fix_source_counts, format_fix_sources
from stridefix_analyzer.scoring.floor_height import FloorHeightError, FloorHeights
from stridefix_analyzer.scoring.metrics import (
    IPIN_FLOOR_PENALTY_M,
    Metrics,
    MetricsInputError,
    run_metrics,
    scheme_code,
)

DEFAULT_OUT = os.path.join("out", "analyze")
METRICS_FILE = "metrics.json"
SERIES_FILE = "analysis.npz"

# channels the analysis needs decoded; the rest (IMU, MAG, ...) are only counted, which is faster
_DECODE = ("POSE", "TRUTH", "STEP", "FIX", "HEALTH", "CONFIG", "CONTEXT")


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare the ``analyze`` sub-command and its options."""
    p = subparsers.add_parser(
        "analyze",
        help="score POSE against TRUTH in LCM logs; write metrics.json and analysis.npz",
        description="Read one or more LCM event logs (e.g. the firmware's log and the simulator's "
        "truth log), score every POSE scheme against TRUTH with the causal protocol of "
        "DESIGN.md, and write DIR/metrics.json and DIR/analysis.npz.",
    )
    p.add_argument("logs", nargs="+", metavar="LOG", help="LCM event log(s); events of all logs are merged")
    p.add_argument(
        "--out",
        default=DEFAULT_OUT,
        metavar="DIR",
        help=f"output directory, created if needed (default: {DEFAULT_OUT})",
    )
    p.add_argument(
        "--scheme",
        default=None,
        metavar="NAME",
        help="pose scheme reported at the top level when POSE holds several "
        f"({', '.join(NAMES)} or a number; default: the one with most POSE messages)",
    )
    p.add_argument(
        "--truth-source",
        default=None,
        choices=["simulation", "waypoint"],
        help="score only TRUTH of this source, e.g. waypoint = the reference points of a "
        "walk (default: all TRUTH)",
    )
    p.add_argument(
        "--label",
        default=None,
        metavar="TEXT",
        help="what this run is (e.g. 'PDR only, truth-initialised start'); kept in "
        "metrics.json and shown as the report's title",
    )
    p.add_argument(
        "--tum",
        default=None,
        metavar="DIR",
        help="also write TUM trajectories into DIR: truth.tum and <scheme>.tum with the "
        "POSE matched causally to each scored truth time (for evo)",
    )
    p.add_argument(
        "--csv",
        default=None,
        metavar="DIR",
        help="also write CSV files into DIR: <scheme>.csv (every POSE as logged), "
        "<scheme>_matched.csv (the POSE matched to each truth sample, with its error) and truth.csv",
    )
    p.add_argument(
        "--site",
        default=None,
        metavar="FILE",
        help="site file whose floor-height table gives each floor its height: the vertical "
        "ISO/IEC 18305 terms and the TUM z (default: the log's CONFIG floor.height_m, uniform)",
    )
    p.add_argument(
        "--all-channels",
        action="store_true",
        help=f"decode every known channel ({', '.join(KNOWN_CHANNELS)}) to check their "
        "payloads, not only those the analysis needs (slower on long logs)",
    )
    return p


def build_summary(data: LogData, metrics: Metrics, label: str | None = None) -> dict:
    """The metrics.json document for ``data`` scored as ``metrics`` (JSON-ready)."""
    doc: dict[str, Any] = {"label": label, "inputs": data.inputs}
    doc.update(metrics.summary())
    doc.update(
        messages=dict(sorted(data.messages.items())),
        unknown_channels=data.unknown_channels,
        decode_errors=data.decode_errors,
        health=data.health,
        fix_sources=fix_source_counts(data.table("FIX")),
        context=context_summary(data.table("CONTEXT"), data.health, _end_us(data)),
        config={**data.versions, "params": data.config},
        warnings=data.warnings,
    )
    return json_ready(doc)


def _end_us(data: LogData) -> int | None:
    """The walk's end for the time per context [µs]: the last POSE (None without one)."""
    pose = data.table("POSE")
    return int(pose["t_us"][-1]) if pose is not None and len(pose) else None


def write_outputs(out_dir: str, summary: dict, metrics: Metrics, site: Any = None) -> tuple[str, str]:
    """Write metrics.json and analysis.npz into ``out_dir``; return their paths. With a ``site``
    (site_t) the npz also holds its walls (``site_wall_*``: the report's floor plans)."""
    os.makedirs(out_dir, exist_ok=True)
    json_path = os.path.join(out_dir, METRICS_FILE)
    npz_path = os.path.join(out_dir, SERIES_FILE)
    write_analyze_metrics(json_path, summary)
    series: dict[str, Any] = metrics.series()
    if site is not None:
        for col in ("x0_m", "y0_m", "x1_m", "y1_m"):
            series[f"site_wall_{col}"] = np.asarray(getattr(site, f"wall_{col}"), np.float64)
        series["site_wall_floor"] = np.asarray(site.wall_floor, np.int64)
    np.savez_compressed(npz_path, **series)
    return json_path, npz_path


def _fmt(value, digits: int = 2) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return str(value)


def format_summary(summary: dict) -> str:
    """A compact plain-text table of the per-scheme scores, for the terminal."""
    cols = ["n", "mean", "median", "p75", "p90", "p95", "max", "rmse"]
    lines = [
        f"{'scheme':<11}"
        + "".join(f"{c:>8}" for c in cols)
        + f"{'ipin':>8}{'floor%':>8}{'final':>8}{'final%':>8}{'hdgRMS':>8}{'steps':>8}"
    ]
    for name, s in summary["per_scheme"].items():
        e = s["position_error_m"]
        mark = "*" if name == summary["primary_scheme"] else " "
        floor = s["floor_hit_rate"]
        lines.append(
            f"{mark}{name:<10}"
            + "".join(f"{_fmt(e[c]):>8}" for c in cols)
            + f"{_fmt(s.get('ipin_score')):>8}"
            + f"{_fmt(None if floor is None else 100 * floor, 1):>8}"
            + f"{_fmt(s['final_error_m']):>8}"
            + f"{_fmt(s['final_error_pct_of_distance']):>8}"
            + f"{_fmt(s['heading_error']['rms_deg'], 1):>8}"
            + f"{_fmt(s['steps']['error']):>8}"
        )
    st = summary["steps"]
    lines.append(
        f"(errors in m; ipin = IPIN score, p75 of 2-D error + {IPIN_FLOOR_PENALTY_M:g} m x |floor "
        f"error| (Matlab quantile); final% of distance walked; hdgRMS in deg; * primary scheme; steps = detected - truth)  "
        f"truth samples {summary['n_truth']}, unscored {summary['unscored']}, "
        f"walked {summary['distance_walked_m']:.1f} m, "
        f"steps detected {st['detected']} / truth {_fmt(st['truth'])}"
    )
    return "\n".join(lines)


def run_analyze(
    logs: list[str],
    out_dir: str = DEFAULT_OUT,
    scheme: str | None = None,
    all_channels: bool = False,
    label: str | None = None,
    truth_source: str | None = None,
    site: str | None = None,
    heights: FloorHeights | None = None,
) -> tuple[dict, Metrics]:
    """Read ``logs``, score them and write the outputs; return (summary, metrics).

    Floor heights (vertical ISO/IEC 18305 terms, TUM z): ``heights`` when given, else those of
    :func:`stridefix_analyzer.scoring.floor_height.resolve` (``site``'s table, else the CONFIG's).

    Raises
    ------
    LogReadError
        A log is missing or unreadable.
    MetricsInputError
        No TRUTH or no POSE, or the requested scheme is absent.
    FloorHeightError
        The site or the CONFIG's floor.height_m is unusable.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)  # kept in data.warnings instead
        data = read_logs(logs, decode=None if all_channels else _DECODE)
    code = scheme_code(scheme) if scheme is not None else None
    site_obj = floor_height.read_site_for_scoring(site) if site is not None else None
    if heights is None:
        heights = floor_height.resolve(data.config, site_obj, str(site))
    metrics = run_metrics(data, scheme=code, truth_source=truth_source, heights=heights)
    summary = build_summary(data, metrics, label)
    write_outputs(out_dir, summary, metrics, site_obj)
    return summary, metrics


#: a log without any fused scheme's pose came from a replay without a site (stridefixd then runs PDR only)
NO_SITE_NOTE = (
    "stridefix analyze: note: no fused scheme in the log: they need a site (stridefixd --site SITE.sfsite; "
    "build one from walks with known points: stridefix site, docs/datasets.md)"
)


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix analyze``; returns the exit status."""
    try:
        summary, metrics = run_analyze(
            args.logs, args.out, args.scheme, args.all_channels, args.label, args.truth_source, args.site
        )
    except (LogReadError, MetricsInputError, FloorHeightError) as exc:
        print(f"stridefix analyze: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    for note in summary["warnings"]:
        print(f"stridefix analyze: warning: {note}", file=sys.stderr)
    if not any(is_fused(name) for name in summary["per_scheme"]):
        print(NO_SITE_NOTE, file=sys.stderr)
    print(format_summary(summary))
    print(iso18305.format_line(summary.get("iso18305"), summary["primary_scheme"]))
    print(format_fix_sources(summary["fix_sources"]))
    print(format_context_line(summary.get("context")))
    print(f"wrote {os.path.join(args.out, METRICS_FILE)} and {os.path.join(args.out, SERIES_FILE)}")
    if getattr(args, "tum", None):
        from stridefix_analyzer.io.tum import TumError, write_tum

        try:
            paths = write_tum(metrics, args.tum)
        except TumError as exc:
            print(f"stridefix analyze: error: {exc}", file=sys.stderr)
            return 2
        z_source = metrics.heights.source if metrics.heights is not None else "0"
        print(f"wrote {len(paths)} TUM trajectories into {args.tum} (z: {z_source})")
    if getattr(args, "csv", None):
        from stridefix_analyzer.io.pose_csv import write_csv

        paths = write_csv(metrics, args.csv)
        print(f"wrote {len(paths)} CSV files into {args.csv}")
    if summary["position_error_m"]["n"] == 0:
        print(
            "stridefix analyze: error: no truth sample could be scored (all precede the first "
            "POSE of the primary scheme)",
            file=sys.stderr,
        )
        return 1
    return 0
