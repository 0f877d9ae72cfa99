"""``stridefix report``: turn an ``analyze`` output directory into one self-contained HTML page.

Reads ``DIR/metrics.json`` and ``DIR/analysis.npz`` (written by ``stridefix analyze``) and writes
``report.html`` (default ``DIR/report.html``) with inline CSS and the figures of
:mod:`stridefix_analyzer.plots` embedded as base64 PNG data URIs, so the file can be mailed or
archived alone. An analysis without TRUTH (metrics.json ``"truth": false``) gets the walk's
sections instead of the error ones (:mod:`stridefix_analyzer.scoring.walk_report`); with TRUTH the
walk's sections follow the error ones. Exit status: 0 written; 2 the directory or one of its two
files is missing or unreadable.
"""

from __future__ import annotations

import argparse
import base64
import html
import os
import sys

import numpy as np
from stridefix_common.exits import NothingValid, input_error_status

from stridefix_analyzer.io.results import AnalyzeMetrics, ResultsFileError, read_analyze_metrics
from stridefix_analyzer.scoring import plots, walk_plots
from stridefix_analyzer.scoring.analyze import METRICS_FILE, SERIES_FILE
from stridefix_analyzer.scoring.config_table import config_html
from stridefix_analyzer.scoring.context import context_html
from stridefix_analyzer.scoring.fixsources import fix_sources_html
from stridefix_analyzer.scoring.metrics import IPIN_FLOOR_PENALTY_M
from stridefix_analyzer.scoring.style import CSS
from stridefix_analyzer.scoring.walk_report import walk_sections


class ReportInputError(Exception):
    """An analysis directory lacks a file or holds an unreadable one; the message names it."""


class ReportNothingValidError(ReportInputError, NothingValid):
    """A file of the analysis directory was read but is not what analyze writes (not JSON, not .npz)."""


_STAT_COLS = ("n", "mean", "median", "p75", "p90", "p95", "max", "rmse")


def load_analysis(directory: str) -> tuple[AnalyzeMetrics, dict]:
    """Load (metrics.json as dict, analysis.npz as dict of arrays) from ``directory``.

    Raises
    ------
    ReportInputError
        The directory or a file is missing, or a file cannot be parsed; names the file.
    """
    if not os.path.isdir(directory):
        raise ReportInputError(f"{directory}: no such directory (run `stridefix analyze` first)")
    json_path = os.path.join(directory, METRICS_FILE)
    npz_path = os.path.join(directory, SERIES_FILE)
    missing = [p for p in (json_path, npz_path) if not os.path.isfile(p)]
    if missing:
        raise ReportInputError(f"missing {', '.join(missing)} (run `stridefix analyze` first)")
    try:
        summary = read_analyze_metrics(json_path)
    except ResultsFileError as exc:
        raise (ReportNothingValidError if isinstance(exc, NothingValid) else ReportInputError)(
            str(exc)
        ) from exc
    try:
        with np.load(npz_path) as z:
            series = {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError) as exc:
        raise ReportNothingValidError(f"{npz_path}: nothing valid in the input: not .npz ({exc})") from exc
    truth = summary.get("truth", True)
    need = [
        k
        for k in ("truth_t_us", "truth_x_m", "truth_y_m", "scheme_codes", "primary_scheme")
        if k not in series and (truth or not k.startswith("truth_"))
    ]
    for key in ("per_scheme", "primary_scheme", "position_error_m") if truth else ("primary_scheme", "walk"):
        if key not in summary:
            need.append(f"{METRICS_FILE}:{key}")
    if need:
        raise ReportInputError(f"{directory}: analysis files lack {', '.join(need)}")
    return summary, series


def _cell(value, digits: int = 2) -> str:
    if value is None:
        text = "–"
    elif isinstance(value, bool):
        text = "yes" if value else "no"
    elif isinstance(value, float):
        text = f"{value:.{digits}f}"
    else:
        text = str(value)
    return html.escape(text)


def _pct(rate) -> str | None:
    return None if rate is None else f"{100 * rate:.1f} %"


def _kv_table(rows: list[tuple[str, object]], header=("item", "value")) -> str:
    body = "".join(f"<tr><td class='k'>{html.escape(k)}</td><td>{_cell(v)}</td></tr>" for k, v in rows)
    return (
        f"<table><tr><th class='k'>{html.escape(header[0])}</th>"
        f"<th>{html.escape(header[1])}</th></tr>{body}</table>"
    )


def _scheme_table(summary: AnalyzeMetrics) -> str:
    head = (
        "<tr><th class='k'>scheme</th><th>POSE msgs</th>"
        + "".join(f"<th>{c}{'' if c == 'n' else ' [m]'}</th>" for c in _STAT_COLS)
        + "<th>IPIN score [m]</th><th>unscored</th><th>floor hit</th><th>within 1σ</th><th>final [m]</th>"
        "<th>final / distance</th></tr>"
    )
    rows = []
    for name, s in summary["per_scheme"].items():
        e = s["position_error_m"]
        cls = " class='primary'" if name == summary["primary_scheme"] else ""
        final_pct = s.get("final_error_pct_of_distance")
        rows.append(
            f"<tr{cls}><td class='k'>{html.escape(name)}</td><td>{_cell(s.get('n_pose'))}</td>"
            + "".join(f"<td>{_cell(e.get(c))}</td>" for c in _STAT_COLS)
            + f"<td>{_cell(s.get('ipin_score'))}</td>"
            + f"<td>{_cell(s.get('unscored'))}</td><td>{_cell(_pct(s.get('floor_hit_rate')))}</td>"
            f"<td>{_cell(_pct(s.get('within_1sigma_rate')))}</td>"
            f"<td>{_cell(s.get('final_error_m'))}</td>"
            f"<td>{_cell(None if final_pct is None else f'{final_pct:.2f} %')}</td></tr>"
        )
    return f"<table>{head}{''.join(rows)}</table>"


#: the ISO/IEC 18305 columns: (header, group in the terms dict or None for top level, key)
_ISO_COLS = (
    ("accuracy: mean [m]", "accuracy", "mean_error_m"),
    ("RMS [m]", "accuracy", "rms_error_m"),
    ("CE50 [m]", "accuracy", "ce50_m"),
    ("CE95 [m]", "accuracy", "ce95_m"),
    ("bias [m]", "accuracy", "bias_m"),
    ("precision: spread [m]", "precision", "spread_m"),
    ("σ of |error| [m]", "precision", "error_std_m"),
    ("vertical [m]", "vertical", "mean_error_m"),
    ("3-D [m]", "vertical", "mean_3d_error_m"),
)


def _iso18305_table(summary: AnalyzeMetrics) -> str:
    head = (
        "<tr><th class='k'>scheme</th>"
        + "".join(f"<th>{html.escape(h)}</th>" for h, _, _ in _ISO_COLS)
        + "<th>floor detection probability</th></tr>"
    )
    rows = []
    for name, s in summary["per_scheme"].items():
        t = s.get("iso18305") or {}
        cls = " class='primary'" if name == summary["primary_scheme"] else ""
        cells = "".join(f"<td>{_cell((t.get(g) or {}).get(k))}</td>" for _, g, k in _ISO_COLS)
        rows.append(
            f"<tr{cls}><td class='k'>{html.escape(name)}</td>{cells}"
            f"<td>{_cell(_pct(t.get('floor_detection_probability')))}</td></tr>"
        )
    return f"<table>{head}{''.join(rows)}</table>"


def _steps_table(summary: AnalyzeMetrics) -> str:
    head = (
        "<tr><th class='k'>scheme</th><th>detected</th><th>truth</th><th>error</th>"
        "<th>error %</th><th>STEP msgs</th></tr>"
    )
    rows = []
    for name, s in summary["per_scheme"].items():
        st = s["steps"]
        pct = st.get("error_pct")
        rows.append(
            f"<tr><td class='k'>{html.escape(name)}</td><td>{_cell(st.get('detected'))}</td>"
            f"<td>{_cell(st.get('truth'))}</td><td>{_cell(st.get('error'))}</td>"
            f"<td>{_cell(None if pct is None else f'{pct:+.2f} %')}</td>"
            f"<td>{_cell(st.get('step_messages'))}</td></tr>"
        )
    return f"<table>{head}{''.join(rows)}</table>"


def _img(png: bytes, alt: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    return f"<img alt='{html.escape(alt)}' src='data:image/png;base64,{data}'>"


def _iso_overview(t: dict | None) -> str | None:
    if not t or not t.get("n"):
        return None
    return (
        f"{_cell(t['accuracy']['mean_error_m'])} / {_cell(t['precision']['spread_m'])}, "
        f"{_pct(t['floor_detection_probability'])}"
    )


def render_html(summary: AnalyzeMetrics, series: dict, title: str = "StrideFix walk report") -> str:
    """The complete report page for one analysis, as an HTML string."""
    truth = summary.get("truth", True)
    body = _truth_sections(summary, series) if truth else []
    if "walk" in summary:
        names = tuple(walk_plots.FIGURES)[1:] if truth else tuple(walk_plots.FIGURES)
        body += walk_sections(summary, series, walk_plots.render_walk(series, names), truth)
    return _page(summary, title, body, truth)


def _truth_sections(summary: AnalyzeMetrics, series: dict) -> list[str]:
    """The scored sections: overview, errors by scheme, ISO/IEC 18305, their figures, steps."""
    figs = plots.render_all(series)
    e = summary["position_error_m"]
    overview = [
        ("primary scheme", summary["primary_scheme"]),
        ("truth samples scored / unscored", f"{e.get('n')} / {summary.get('unscored')}"),
        (
            "mean / median / p95 error [m]",
            f"{_cell(e.get('mean'))} / {_cell(e.get('median'))} / {_cell(e.get('p95'))}",
        ),
        ("distance walked (truth) [m]", summary.get("distance_walked_m")),
        ("final error [m]", summary.get("final_error_m")),
        ("floor hit rate", _pct(summary.get("floor_hit_rate"))),
        ("IPIN score [m]", summary.get("ipin_score")),
        (
            "ISO/IEC 18305 accuracy / precision [m], floor detection",
            _iso_overview(summary.get("iso18305")),
        ),
        ("floors in truth", ", ".join(str(f) for f in summary.get("floors_in_truth", []))),
    ]
    return [
        "<p class='note'>Error at each truth time = horizontal distance to the latest POSE at or "
        "before it (causal; nothing looks ahead). Percentiles: numpy linear interpolation. "
        f"IPIN score (the IPIN competition's metric): p75 of 2-D error + {IPIN_FLOOR_PENALTY_M:g} m "
        "× |floor error|, by Matlab's quantile as the organisers compute it.</p>",
        _kv_table(overview, ("summary", "")),
        _warnings_html(summary),
        "<h2>Position error by scheme</h2>",
        _scheme_table(summary),
        "<h2>ISO/IEC 18305 terms by scheme</h2>",
        "<p class='note'>Accuracy: closeness to the truth (mean horizontal error, RMS, CE50/CE95, bias = "
        "length of the mean error vector). Precision: spread of the error vector about its mean "
        "(√trace of its covariance) and the σ of the error magnitude. Vertical and 3-D: the estimated "
        f"floor's height against the true floor's ({html.escape(str(summary.get('floor_heights') or 'heights unknown'))})."
        " Floor detection probability: share of scored samples on the true floor.</p>",
        _iso18305_table(summary),
        _img(figs["trajectory"], "trajectory, one panel per floor"),
        _img(figs["floor_time"], "estimated vs true floor over time"),
        _img(figs["error_time"], "error over time, one panel per scheme"),
        _img(figs["error_cdf"], "error CDF"),
        "<h2>Steps</h2>",
        _steps_table(summary),
    ]


def _warnings_html(summary: AnalyzeMetrics) -> str:
    items = "".join(f"<li class='warn'>{html.escape(w)}</li>" for w in summary.get("warnings", []))
    return f"<ul>{items}</ul>" if items else ""


def _page(summary: AnalyzeMetrics, title: str, body: list[str], truth: bool) -> str:
    """The page around ``body``: title, (without truth: a note and the warnings), then fix sources,
    context, HEALTH, messages, inputs and configuration."""
    inputs = summary.get("inputs", [])
    input_rows = "".join(
        f"<tr><td class='k'>{html.escape(str(i.get('path')))}</td><td>{_cell(i.get('bytes'))}</td>"
        f"<td>{_cell(i.get('events'))}</td><td>{_cell(i.get('truncated_bytes'))}</td>"
        f"<td>{_cell(i.get('skipped_bytes'))}</td></tr>"
        for i in inputs
    )
    health = summary.get("health") or {}
    config = summary.get("config") or {}
    params = config.get("params") or {}
    version_rows = [(k, v) for k, v in config.items() if k != "params"]
    messages = summary.get("messages", {})
    extra_counts = [("unknown channel " + k, v) for k, v in summary.get("unknown_channels", {}).items()] + [
        ("decode errors on " + k, v) for k, v in summary.get("decode_errors", {}).items()
    ]
    no_truth = [
        "<p class='note'>No TRUTH in the logs: nothing here is an error against ground truth. The "
        "figures are what the firmware's own log says: its tracks, floors, steps, the σ it claims and "
        "how its fixes' innovations agree with that claim.</p>",
        _warnings_html(summary),
    ]
    parts = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>{html.escape(title)}</title><style>{CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        *([] if truth else no_truth),
        *body,
        "<h2>Fix sources</h2>",
        "<p class='note'>FIX records per scheme and source (every scheme judges every fix): offered, "
        "accepted, rejected and why.</p>",
        fix_sources_html(summary.get("fix_sources") or {}),
        "<h2>Positioning context (multi-scheme controller)</h2>",
        "<p class='note'>CONTEXT messages: every state change of the controller, the rule that fired "
        "and its evidence; the primary pose follows the scheme of the context it selects.</p>",
        context_html(summary.get("context")),
        "<h2>Logger health (last HEALTH report)</h2>",
        _kv_table(list(health.items()), ("counter", "value"))
        if health
        else "<p class='note'>no HEALTH message in the logs</p>",
        "<h2>Messages per channel</h2>",
        _kv_table(list(messages.items()) + extra_counts, ("channel", "events")),
        "<h2>Inputs</h2>",
        "<table><tr><th class='k'>log</th><th>bytes</th><th>events</th><th>truncated bytes</th>"
        f"<th>skipped bytes</th></tr>{input_rows}</table>",
        "<h2>Configuration</h2>",
        config_html(version_rows, params),
        "</body></html>",
    ]
    return "\n".join(parts)


def run_report(directory: str, out_file: str | None = None) -> str:
    """Write the report for ``directory``; return the path written.

    Raises
    ------
    ReportInputError
        See :func:`load_analysis`.
    """
    summary, series = load_analysis(directory)
    out_file = out_file or os.path.join(directory, "report.html")
    parent = os.path.dirname(out_file)
    if parent:
        os.makedirs(parent, exist_ok=True)
    label = summary.get("label")
    page = render_html(
        summary, series, f"StrideFix walk report: {label}" if label else "StrideFix walk report"
    )
    with open(out_file, "w", encoding="utf-8") as f:
        f.write(page)
    return out_file


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare the ``report`` sub-command and its options."""
    p = subparsers.add_parser(
        "report",
        help="render an analyze output directory as a self-contained HTML report",
        description="Read DIR/metrics.json and DIR/analysis.npz (from `stridefix analyze`) and "
        "write one HTML file with inline CSS and embedded PNG figures.",
    )
    p.add_argument("directory", metavar="DIR", help="output directory of `stridefix analyze`")
    p.add_argument(
        "--out", default=None, metavar="FILE", help="HTML file to write (default: DIR/report.html)"
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix report``; returns the exit status."""
    try:
        path = run_report(args.directory, args.out)
    except ReportInputError as exc:
        print(f"stridefix report: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    print(f"wrote {path}")
    return 0
