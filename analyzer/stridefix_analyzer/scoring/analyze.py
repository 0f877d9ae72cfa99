"""``stridefix analyze``: read LCM logs, score POSE against TRUTH, write metrics.json + analysis.npz.

Without TRUTH (a field recording) the walk is described instead of scored: metrics.json then has
``"truth": false``, the primary scheme and ``walk`` (:mod:`stridefix_analyzer.scoring.walk`: steps,
floors, barometric height, claimed σ, the fixes' innovation consistency, HEALTH growth) and none
of the error keys below; with TRUTH it has ``"truth": true`` and ``walk`` besides them. The primary
scheme is the one the firmware published on POSE (:mod:`stridefix_analyzer.scoring.primary`,
``primary_from`` says how it was chosen), ``--scheme`` overrides it.

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
  null without CONTEXT), and with a ``--site`` that has walls ``wall_crossings`` per scheme and
  ``truth_wall_crossings`` (:mod:`stridefix_analyzer.scoring.walls`), and
- ``analysis.npz``: the per-truth-sample series the report plots
  (see :meth:`stridefix_analyzer.metrics.Metrics.series`).

Exit status (:mod:`stridefix_common.exits`): 0 success; 1 nothing could be scored (every truth
sample precedes the first POSE); 2 missing or unreadable input, or no POSE in the logs;
3 nothing valid in them (not an LCM log, or neither TRUTH nor POSE in any). The tables on stdout
follow the console verbosity (``stridefix -q analyze``: errors only).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from typing import Any

import numpy as np
from stridefix_common.exits import input_error_status

from stridefix_analyzer import console
from stridefix_analyzer.io.jsonio import json_ready
from stridefix_analyzer.io.lcmfile import require_records
from stridefix_analyzer.io.logread import (
    KNOWN_CHANNELS,
    LogData,
    LogReadError,
    LogTruncatedWarning,
    read_logs,
)
from stridefix_analyzer.io.results import write_analyze_metrics
from stridefix_analyzer.schemes import NAMES, is_fused, scheme_name
from stridefix_analyzer.scoring import floor_height, iso18305, walk_report, walls
from stridefix_analyzer.scoring.context import context_summary, format_context_line
from stridefix_analyzer.scoring.fixsources import fix_source_counts, format_fix_sources
from stridefix_analyzer.scoring.floor_height import FloorHeightError, FloorHeights
from stridefix_analyzer.scoring.metrics import (
    IPIN_FLOOR_PENALTY_M,
    Metrics,
    MetricsInputError,
    NothingToScoreError,
    choose_primary,
    run_metrics,
    scheme_code,
)
from stridefix_analyzer.scoring.walk import Walk, run_walk

DEFAULT_OUT = os.path.join("out", "analyze")
METRICS_FILE = "metrics.json"
SERIES_FILE = "analysis.npz"

# channels the analysis needs decoded; the rest (IMU, MAG, ...) are only counted, which is faster
_DECODE = ("POSE", "TRUTH", "STEP", "FIX", "HEALTH", "CONFIG", "CONTEXT", "BARO")


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare the ``analyze`` sub-command and its options."""
    p = subparsers.add_parser(
        "analyze",
        help="score POSE against TRUTH in LCM logs (or, without TRUTH, describe the walk); write "
        "metrics.json and analysis.npz",
        description="Read one or more LCM event logs (e.g. the firmware's log and the simulator's "
        "truth log), score every POSE scheme against TRUTH with the causal protocol of "
        "DESIGN.md, and write DIR/metrics.json and DIR/analysis.npz. Without TRUTH (a field "
        "recording) the walk is described instead: steps, floors, barometric height, the sigma the "
        "estimator claims, every fix's verdict and the consistency of its innovation, HEALTH.",
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
        f"({', '.join(NAMES)} or a number; default: the one the firmware published on the POSE "
        "channel)",
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
        help="site file whose floor-height table gives each floor its height (the vertical "
        "ISO/IEC 18305 terms and the TUM z; default: the log's CONFIG floor.height_m, uniform) and "
        "whose walls the report draws under the tracks",
    )
    p.add_argument(
        "--all-channels",
        action="store_true",
        help=f"decode every known channel ({', '.join(KNOWN_CHANNELS)}) to check their "
        "payloads, not only those the analysis needs (slower on long logs)",
    )
    return p


def build_summary(data: LogData, metrics: Metrics | None, walk: Walk, label: str | None = None) -> dict:
    """The metrics.json document for ``data`` scored as ``metrics`` (None: no TRUTH) and described as
    ``walk`` (JSON-ready)."""
    doc: dict[str, Any] = {"label": label, "inputs": data.inputs}
    if metrics is not None:
        doc.update(metrics.summary())
    else:
        doc.update(primary_scheme=scheme_name(walk.primary), primary_from=walk.primary_from)
    doc.update(truth=metrics is not None, walk=walk.summary)
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


def add_wall_crossings(summary: dict, metrics: Metrics, plan: np.ndarray) -> None:
    """``wall_crossings`` per scheme (its POSE track) and ``truth_wall_crossings`` into ``summary``:
    the walls of the site each track passes through (:func:`.walls.crossings`; the truth's is 0 on
    a plan that fits the walk)."""
    for s in metrics.schemes.values():
        summary["per_scheme"][s.name]["wall_crossings"] = walls.crossings(
            s.pose["x_m"], s.pose["y_m"], s.pose["floor"], plan
        )
    t = metrics.truth
    summary["truth_wall_crossings"] = walls.crossings(t["x_m"], t["y_m"], t["floor"], plan)


def _end_us(data: LogData) -> int | None:
    """The walk's end for the time per context [µs]: the last POSE (None without one)."""
    pose = data.table("POSE")
    return int(pose["t_us"][-1]) if pose is not None and len(pose) else None


def write_outputs(
    out_dir: str, summary: dict, metrics: Metrics | None, walk: Walk, site: Any = None
) -> tuple[str, str]:
    """Write metrics.json and analysis.npz into ``out_dir``; return their paths. The npz holds the
    walk's series and, with TRUTH, the scored ones (:meth:`Metrics.series`); with a ``site``
    (site_t) also its walls and ports (``site_wall_*``,
    ``site_port_*``: the report's floor plans)."""
    os.makedirs(out_dir, exist_ok=True)
    json_path = os.path.join(out_dir, METRICS_FILE)
    npz_path = os.path.join(out_dir, SERIES_FILE)
    write_analyze_metrics(json_path, summary)
    series: dict[str, Any] = walk.series()
    if metrics is not None:
        series.update(metrics.series())
    if site is not None:
        series.update(walls.plan_series(site))
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
    """Read ``logs``, score them against their TRUTH and write the outputs; return (summary, metrics).

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
    summary, metrics = analyze_logs(
        logs, out_dir, scheme, all_channels, label, truth_source, site, heights, True
    )
    assert metrics is not None  # need_truth: raised otherwise
    return summary, metrics


def analyze_logs(
    logs: list[str],
    out_dir: str = DEFAULT_OUT,
    scheme: str | None = None,
    all_channels: bool = False,
    label: str | None = None,
    truth_source: str | None = None,
    site: str | None = None,
    heights: FloorHeights | None = None,
    need_truth: bool = False,
) -> tuple[dict, Metrics | None]:
    """:func:`run_analyze`, and without TRUTH (unless ``need_truth``) the truth-less description
    alone: (summary, None)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)  # kept in data.warnings instead
        data = read_logs(logs, decode=None if all_channels else _DECODE)
    require_records(data.inputs)  # an empty log, or one cut in its first record: nothing valid
    code = scheme_code(scheme) if scheme is not None else None
    site_obj = floor_height.read_site_for_scoring(site) if site is not None else None
    truth = data.table("TRUTH")
    metrics = None
    if need_truth or truth_source is not None or (truth is not None and len(truth)):
        if heights is None:
            heights = floor_height.resolve(data.config, site_obj, str(site))
        metrics = run_metrics(data, scheme=code, truth_source=truth_source, heights=heights)
        walk = run_walk(data, metrics.primary, metrics.primary_from)
    else:
        pose = data.table("POSE")
        if pose is None or not len(pose):
            inputs = ", ".join(i["path"] for i in data.inputs) or "the input"
            raise NothingToScoreError(f"no TRUTH and no POSE messages in {inputs}")
        walk = run_walk(data, *choose_primary(data, code))
    summary = build_summary(data, metrics, walk, label)
    if metrics is not None and site_obj is not None and site_obj.n_walls:
        add_wall_crossings(summary, metrics, walls.wall_array(site_obj))
    write_outputs(out_dir, summary, metrics, walk, site_obj)
    return summary, metrics


#: a log without any fused scheme's pose came from a replay without a site (stridefixd then runs PDR only)
NO_SITE_NOTE = (
    "stridefix analyze: note: no fused scheme in the log: they need a site (stridefixd --site SITE.sfsite; "
    "build one from walks with known points: stridefix site, docs/datasets.md)"
)


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix analyze``; returns the exit status."""
    try:
        summary, metrics = analyze_logs(
            args.logs, args.out, args.scheme, args.all_channels, args.label, args.truth_source, args.site
        )
    except (LogReadError, MetricsInputError, FloorHeightError) as exc:
        print(f"stridefix analyze: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    show = console.show
    for note in summary["warnings"]:
        console.say(f"stridefix analyze: warning: {note}")
    schemes = summary.get("per_scheme") or summary.get("walk", {}).get("per_scheme", {})
    if not any(is_fused(name) for name in schemes):
        console.say(NO_SITE_NOTE)  # -q: errors only
    if metrics is None:
        show(walk_report.format_walk(summary))
    else:
        show(format_summary(summary))
        show(iso18305.format_line(summary.get("iso18305"), summary["primary_scheme"]))
        if "truth_wall_crossings" in summary:
            counts = ", ".join(f"{n} {s['wall_crossings']}" for n, s in summary["per_scheme"].items())
            show(
                f"wall crossings (the site's walls a track passes through): {counts}; "
                f"truth {summary['truth_wall_crossings']}"
            )
    show(format_fix_sources(summary["fix_sources"]))
    show(format_context_line(summary.get("context")))
    show(f"wrote {os.path.join(args.out, METRICS_FILE)} and {os.path.join(args.out, SERIES_FILE)}")
    if metrics is None:
        if getattr(args, "tum", None) or getattr(args, "csv", None):
            print("stridefix analyze: error: --tum and --csv need TRUTH in the logs", file=sys.stderr)
            return 2
        return 0
    if getattr(args, "tum", None):
        from stridefix_analyzer.io.tum import TumError, write_tum

        try:
            paths = write_tum(metrics, args.tum)
        except TumError as exc:
            print(f"stridefix analyze: error: {exc}", file=sys.stderr)
            return 2
        z_source = metrics.heights.source if metrics.heights is not None else "0"
        show(f"wrote {len(paths)} TUM trajectories into {args.tum} (z: {z_source})")
    if getattr(args, "csv", None):
        from stridefix_analyzer.io.pose_csv import write_csv

        paths = write_csv(metrics, args.csv)
        show(f"wrote {len(paths)} CSV files into {args.csv}")
    if summary["position_error_m"]["n"] == 0:
        print(
            "stridefix analyze: error: no truth sample could be scored (all precede the first "
            "POSE of the primary scheme)",
            file=sys.stderr,
        )
        return 1
    return 0
