"""The truth-less walk in words and tables: ``analyze``'s console lines and the report's sections.

:func:`format_walk` is what ``stridefix analyze`` prints for a log without TRUTH; :func:`walk_sections`
the HTML sections of ``stridefix report`` (all of them without truth; with truth, beside the error
sections, the ones truth does not replace). The numbers are metrics.json's ``walk``
(:mod:`.walk`), the figures :mod:`.walk_plots`'s, the per-fix table analysis.npz's ``walk_fix_*``.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping
from typing import Any

import numpy as np

from stridefix_analyzer.scoring.fixsources import method_label, method_name, reason_name

#: how metrics.json's ``primary_from`` reads
PRIMARY_FROM = {
    "pose_channel": "the scheme the firmware published on POSE",
    "requested": "--scheme",
    "fallback": "a log with every scheme on POSE: the controller, else most poses",
}


def _f(v: Any, digits: int = 2) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        return f"{v:.{digits}f}"
    return str(v)


def _pct(v: Any) -> str:
    return "–" if v is None else f"{100 * v:.1f} %"


def overview_rows(summary: Mapping[str, Any]) -> list[tuple[str, str]]:
    """(item, value) rows of the walk: primary, duration, steps, floors, barometric height."""
    w = summary["walk"]
    st, baro = w["steps"], w["barometric_height_m"]
    return [
        (
            "primary scheme",
            f"{summary['primary_scheme']} ({PRIMARY_FROM.get(str(summary.get('primary_from')), '?')})",
        ),
        ("duration [s]", _f(w["duration_s"], 1)),
        (
            "steps / stride sum [m] / cadence [steps/min]",
            f"{st['count']} / {_f(st['walked_m'], 1)} / {_f(st['cadence_spm'], 1)}",
        ),
        (
            "floors visited (primary) / floor changes",
            f"{', '.join(map(str, w['floors_visited']))} / {w['floor_changes']}",
        ),
        (
            "barometric height min / max / final [m]",
            f"{_f(baro['min'])} / {_f(baro['max'])} / {_f(baro['final'])}",
        ),
    ]


def scheme_rows(summary: Mapping[str, Any]) -> list[list[str]]:
    """Per scheme: poses, track [m], claimed σ median / p95 / final [m], fixes offered / accepted /
    judged, mean NIS and share within χ²(2) 95 %."""
    rows = []
    for name, s in summary["walk"]["per_scheme"].items():
        sig, fx = s["sigma_m"], s["fixes"]
        rows.append(
            [
                name,
                str(s["n_pose"]),
                _f(s["track_length_m"], 1),
                _f(sig["median"]),
                _f(sig["p95"]),
                _f(sig["final"]),
                str(fx["offered"]),
                str(fx["accepted"]),
                str(fx["judged"]),
                _f(fx["nis_mean"]),
                _pct(fx["within_chi2_95_rate"]),
            ]
        )
    return rows


_SCHEME_HEAD = [
    "scheme",
    "poses",
    "track [m]",
    "σ median",
    "σ p95",
    "σ final",
    "fixes",
    "accepted",
    "judged",
    "NIS mean",
    "NIS ≤ χ²95",
]


def format_walk(summary: Mapping[str, Any]) -> str:
    """The console lines of a truth-less analysis."""
    lines = ["walk without ground truth (no TRUTH in the logs):"]
    lines += [f"  {k}: {v}" for k, v in overview_rows(summary)]
    widths = [11, 7, 10, 9, 7, 8, 7, 9, 7, 9, 11]
    lines.append(
        "".join(f"{h:>{w}}" if i else f"{h:<{w}}" for i, (h, w) in enumerate(zip(_SCHEME_HEAD, widths)))
    )
    for row in scheme_rows(summary):
        mark = "*" if row[0] == summary["primary_scheme"] else " "
        lines.append(
            mark + "".join(f"{c:>{w}}" if i else f"{c:<{w - 1}}" for i, (c, w) in enumerate(zip(row, widths)))
        )
    c = summary["walk"]["consistency"]
    lines.append(
        f"(σ: the pose's claimed 1σ [m]; * primary; NIS = test ratio x gate² ({c['gate_sigma']:g}) of every judged fix, "
        f"chi-square with 2 dof when the claimed covariance is honest: mean 2, 95 % within {c['chi2_95']:.2f})"
    )
    return "\n".join(lines)


def _table(head: list[str], rows: list[list[str]], primary: str | None = None) -> str:
    h = "".join(f"<th{' class=k' if i == 0 else ''}>{html.escape(c)}</th>" for i, c in enumerate(head))
    body = []
    for r in rows:
        cls = " class='primary'" if primary is not None and r[0] == primary else ""
        cells = "".join(f"<td{' class=k' if i == 0 else ''}>{html.escape(c)}</td>" for i, c in enumerate(r))
        body.append(f"<tr{cls}>{cells}</tr>")
    return f"<table><tr>{h}</tr>{''.join(body)}</table>"


def _img(png: bytes | None, alt: str) -> str:
    if png is None:
        return ""
    return (
        f"<img alt='{html.escape(alt)}' src='data:image/png;base64,{base64.b64encode(png).decode('ascii')}'>"
    )


def fix_rows(series: Mapping[str, np.ndarray]) -> list[list[str]]:
    """Every FIX record of the primary scheme: time [s], source, verdict, innovation x / y [m],
    √S [m], NIS."""
    if "walk_fix_t_us" not in series:
        return []
    sel = np.flatnonzero(np.asarray(series["walk_fix_scheme"]) == int(series["primary_scheme"]))
    t0 = min((int(series[k][0]) for k in series if k.endswith("_pose_t_us") and len(series[k])), default=0)
    rows = []
    for i in sel:
        verdict = "accepted" if series["walk_fix_accepted"][i] else "rejected"
        rows.append(
            [
                f"{(int(series['walk_fix_t_us'][i]) - t0) / 1e6:.1f}",
                method_label(method_name(int(series["walk_fix_method"][i]))),
                f"{verdict} ({reason_name(int(series['walk_fix_reason'][i]))})",
                _f(float(series["walk_fix_innovation_x_m"][i])),
                _f(float(series["walk_fix_innovation_y_m"][i])),
                _f(float(np.sqrt(max(float(series["walk_fix_innovation_var_m2"][i]), 0.0)))),
                _f(float(series["walk_fix_nis"][i])) if np.isfinite(series["walk_fix_nis"][i]) else "–",
            ]
        )
    return rows


def walk_sections(
    summary: Mapping[str, Any], series: Mapping[str, np.ndarray], figs: Mapping[str, bytes], truth: bool
) -> list[str]:
    """The report's walk sections (module docstring); ``figs`` from :func:`.walk_plots.render_walk`.
    With ``truth`` the tracks and the overview are left out (the scored sections show them)."""
    w = summary["walk"]
    primary = summary["primary_scheme"]
    c = w["consistency"]
    parts = []
    if not truth:
        parts += [
            "<h2>The walk (no ground truth)</h2>",
            _table(["item", "value"], [list(r) for r in overview_rows(summary)]),
            "<h2>Tracks on the floor plan</h2>",
            _img(figs.get("tracks"), "tracks, one panel per floor"),
        ]
    st = w["steps"]
    activity = [[a, str(v["steps"]), _f(v["seconds"], 1)] for a, v in st["activity"].items()]
    fixes = fix_rows(series)
    grew = [[k, str(v)] for k, v in w["health"]["grew"].items()]
    parts += [
        "<h2>Floors and barometric height</h2>",
        _img(figs.get("floor_height"), "floor and barometric height over time"),
        "<h2>Steps and activity</h2>",
        f"<p class='note'>{st['count']} steps, stride sum {_f(st['walked_m'], 1)} m, cadence "
        f"{_f(st['cadence_spm'], 1)} steps/min (60 / median period of walking steps).</p>",
        _table(["activity", "steps", "seconds"], activity)
        if activity
        else "<p class='note'>no STEP message</p>",
        _img(figs.get("steps"), "steps and activity over time"),
        "<h2>Claimed σ and innovation consistency by scheme</h2>",
        "<p class='note'>σ: the 1σ each scheme claims for its pose (pose_t.sigma_m) [m]. NIS = ν'S⁻¹ν of every "
        f"fix the scheme judged against its prediction (test ratio × gate², gate {c['gate_sigma']:g} from "
        f"{html.escape(c['gate_sigma_from'])}), accepted or not: with an honest claimed covariance it is χ² "
        f"with 2 degrees of freedom, mean 2 and 95 % within {c['chi2_95']:.2f}. Mean NIS above 2: the scheme "
        "claims too small a σ (or its fixes too good an accuracy); below: too large. No truth needed.</p>",
        _table(_SCHEME_HEAD, scheme_rows(summary), primary),
        _img(figs.get("sigma"), "claimed sigma over time"),
        f"<h2>Every fix: verdict and innovation ({html.escape(primary)})</h2>",
        _img(figs.get("fixes"), "innovation and NIS of every fix"),
        (
            f"<details><summary>{len(fixes)} FIX records of {html.escape(primary)}</summary>"
            + _table(["t [s]", "source", "verdict", "ν x [m]", "ν y [m]", "√S [m]", "NIS"], fixes)
            + "</details>"
        )
        if fixes
        else "<p class='note'>no FIX record of the primary scheme</p>",
        "<h2>HEALTH over time</h2>",
        f"<p class='note'>{w['health']['reports']} HEALTH reports over {_f(w['health']['span_s'], 1)} s; the "
        "counters that grew (from the first report to the last):</p>",
        _table(["counter", "growth"], grew) if grew else "<p class='note'>no counter grew</p>",
        _img(figs.get("health"), "HEALTH counters over time"),
    ]
    return parts
