"""HTML report of ``stridefix-lab realbench fusion`` (one self-contained file, PNGs embedded).

Per group (floor or building): the learned constants, the scheme table, the error CDF of every
scheme, a box plot per scheme (errors at the ground-truth times, all walks pooled), and the worst
walks' trajectories — truth against that walk's best and worst scheme — over the floor plan
(the data set's :meth:`~stridefix_analyzer.datasets.protocol.Dataset.floor_plan`: msindoor's
``floor_image.png`` stretched over 0..width × 0..height m of ``floor_info.json``, origin at the
bottom-left; plain axes where the set has none). No metric is computed here: everything comes from the document of
:func:`stridefix_lab.realbench.fusion.run_fusion` and each walk's ``analysis.npz``.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from stridefix_analyzer import datasets  # noqa: E402
from stridefix_analyzer.datasets.protocol import DatasetError  # noqa: E402
from stridefix_analyzer.schemes import PDR_ONLY, UnknownSchemeError, scheme_code, scheme_colour  # noqa: E402
from stridefix_analyzer.scoring import style  # noqa: E402
from stridefix_analyzer.scoring.fixsources import fix_sources_html  # noqa: E402
from stridefix_analyzer.scoring.plots import to_png  # noqa: E402
from stridefix_analyzer.scoring.style import CSS  # noqa: E402

from stridefix_lab.realbench.summary import (  # noqa: E402
    PDR_TRUE_START_LABEL,
    loses_text,
    pdr_true_start,
    pdr_true_start_text,
)

WORST_WALKS = 3
#: a floor plan as drawn: the image and its extent (0, width, 0, height) [m]
Plan = tuple[np.ndarray, tuple[float, float, float, float]]


def _f(v: Any, d: int = 2) -> str:
    return "-" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.{d}f}"


def _img(png: bytes, alt: str) -> str:
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{base64.b64encode(png).decode()}"/>'


def _colour(name: str) -> str:
    """A scheme's report colour (:mod:`stridefix_analyzer.schemes`); black for an unknown name."""
    try:
        return scheme_colour(scheme_code(name))
    except UnknownSchemeError:
        return "k"


def floor_plan(fmt: str, floor_dir: str | Path | None) -> Plan | None:
    """(image, extent) of a group's floor plan from its data set: extent (0, width, 0, height) [m];
    None when the set has none there."""
    if not floor_dir:
        return None
    try:
        plan = datasets.get(fmt).floor_plan(floor_dir)
    except DatasetError:
        return None
    if plan is None or plan.image is None:
        return None
    try:
        return plt.imread(str(plan.image)), (0.0, plan.width_m, 0.0, plan.height_m)
    except (OSError, ValueError):
        return None


def _pooled(group: dict, tag: str = "fixes") -> dict[str, np.ndarray]:
    out: dict[str, list] = {}
    for row in group["walk_rows"]:
        for name, s in (row.get(tag) or {}).items():
            out.setdefault(name, []).append(np.asarray(s.get("errors_m", []), float))
    return {k: np.concatenate(v) for k, v in out.items()}


def plot_cdf(pooled: dict[str, np.ndarray], title: str) -> Figure:
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    for name, e in pooled.items():
        e = np.sort(e[np.isfinite(e)])
        if len(e):
            ax.step(
                e,
                np.arange(1, len(e) + 1) / len(e),
                where="post",
                color=_colour(name),
                label=f"{name} (mean {e.mean():.1f} m, n {len(e)})",
            )
    ax.axvline(15.0, color="k", ls=":", lw=0.8)
    ax.set(
        xlabel="position error at ground-truth times [m]",
        ylabel="fraction of samples",
        title=title,
        ylim=(0, 1),
        xlim=(0, None),
    )
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    return fig


def plot_box(pooled: dict[str, np.ndarray], title: str) -> Figure:
    names = list(pooled)
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    data = [pooled[n][np.isfinite(pooled[n])] for n in names]
    bp = ax.boxplot(data, tick_labels=names, showmeans=True, whis=(5, 95), flierprops={"ms": 2})
    for patch, n in zip(bp["boxes"], names):
        patch.set_color(_colour(n))
    ax.set(ylabel="position error [m]", title=f"{title} (whiskers p5–p95, triangle = mean)")
    ax.grid(alpha=0.3, axis="y")
    return fig


def plot_walk(
    series: Mapping[str, np.ndarray], walk: str, schemes: list[str], plan: Plan | None, title: str
) -> Figure:
    """Truth (waypoints joined) and the POSE tracks of ``schemes`` of one walk, over the plan."""
    fig, ax = plt.subplots(figsize=(7.5, 6.0))
    if plan is not None:
        img, extent = plan
        ax.imshow(img, extent=extent, origin="upper", **style.PLAN_IMAGE)
    tx, ty = series["truth_x_m"], series["truth_y_m"]
    ax.plot(tx, ty, **{**style.TRUTH, "marker": "o", "markersize": 4, "label": "truth (waypoints)"})
    if len(tx):
        ax.plot(tx[0], ty[0], **style.START, zorder=4)
    codes = [int(c) for c in series["scheme_codes"]]
    for name in schemes:
        c = scheme_code(name)
        if c not in codes:
            continue
        px, py = series[f"s{c}_pose_x_m"], series[f"s{c}_pose_y_m"]
        ax.plot(px, py, **{**style.TRACK, "color": _colour(name), "label": name})
        err_x = series[f"s{c}_error_m"]
        ok = np.isfinite(err_x)
        # the matched estimate at each truth time, joined to its truth point
        m = series.get(f"m{c}_xy")
        if m is not None:
            for (x0, y0), (x1, y1) in zip(np.column_stack([tx, ty])[ok], m[ok]):
                ax.plot([x0, x1], [y0, y1], ":", color=_colour(name), lw=0.8, zorder=2)
    if plan is not None:
        ax.set_xlim(plan[1][0], plan[1][1])
        ax.set_ylim(plan[1][2], plan[1][3])
    ax.set_aspect("equal")
    ax.set(xlabel="x [m]", ylabel="y [m]", title=title)
    ax.grid(alpha=0.2)
    ax.legend(loc="best", fontsize="small")
    return fig


def _matched(series: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """Add m<c>_xy: the POSE matched causally to each truth time (as the metrics do)."""
    out = dict(series)
    for c in series["scheme_codes"]:
        c = int(c)
        t = series[f"s{c}_pose_t_us"]
        row = np.searchsorted(t, series["truth_t_us"], side="right") - 1
        safe = np.clip(row, 0, max(len(t) - 1, 0))
        xy = (
            np.column_stack([series[f"s{c}_pose_x_m"][safe], series[f"s{c}_pose_y_m"][safe]])
            if len(t)
            else np.full((len(row), 2), np.nan)
        )
        xy[row < 0] = np.nan
        out[f"m{c}_xy"] = xy
    return out


_SUMMARY = {"fixes": "summary", "true_start": "summary_true_start"}


def _scheme_table(summary: dict, extra: Sequence[tuple[str, dict]] = ()) -> str:
    """The scheme table of one run; ``extra`` rows (label, row) come last, in bold; then the textbook
    references (:mod:`.reference`), labelled as such, and a scheme that loses to one is marked."""
    head = [
        "scheme",
        "n",
        "mean",
        "median",
        "p75",
        "p90",
        "p95",
        "max",
        "RMSE",
        "IPIN score",
        "floor hit %",
        "walks mean > 15 m",
    ]
    rows = []
    losers = {e["scheme"]: e["reference"] for e in summary.get("loses_to_reference", [])}
    refs = [(f"{n} (textbook reference, not a scheme)", r) for n, r in summary.get("references", {}).items()]
    for name, r in [*summary["schemes"].items(), *extra, *refs]:
        rows.append(
            [
                name + (f" — loses to {losers[name]}" if name in losers else ""),
                r["n"],
                _f(r["mean"]),
                _f(r["median"]),
                _f(r["p75"]),
                _f(r["p90"]),
                _f(r["p95"]),
                _f(r["max"]),
                _f(r["rmse"]),
                _f(r["ipin_score"]),
                _f(100 * r["floor_hit_rate"], 1),
                f"{r['walks_mean_over_15m']}/{r['walks']} ({_f(100 * r['share_walks_mean_over_15m'], 1)} %)",
            ]
        )
    table = _table(head, rows, bold_last=len(extra) + len(refs))
    return table + f"<p><b>{html.escape(loses_text(summary))}</b></p>"


def _table(head: Sequence[object], rows: Iterable[Sequence[object]], bold_last: int = 0) -> str:
    th = "".join(f"<th>{html.escape(str(h))}</th>" for h in head)
    rows = list(rows)
    body = "".join(
        ("<tr style='font-weight:bold'>" if i >= len(rows) - bold_last else "<tr>")
        + "".join(f"<td>{html.escape(str(c))}</td>" for c in r)
        + "</tr>"
        for i, r in enumerate(rows)
    )
    return f"<table><tr>{th}</tr>{body}</table>"


def render(doc: dict) -> str:
    parts = [
        f"<h1>StrideFix realbench: fusion schemes, leave one walk out ({doc['format']})</h1>",
        "<p>Every scheme starts from the fixes (except the runs labelled truth-initialised); the radio map, map rotation, floor heights and "
        "stride constant K of each walk come from the other walks of its floor/building only. "
        "Errors are taken at the walk's ground-truth times against the latest POSE at or "
        "before them (causal).</p>",
    ]
    for g in doc["groups"]:
        plan = floor_plan(doc["format"], g.get("floor_dir"))
        c = g["constants"]
        parts.append(f"<h2>{html.escape(g['label'])}</h2>")
        parts.append(
            f"<p>{g['walks']} walks, {g['ran']} ran. Learned per fold: K "
            f"{_f(c['K']['mean'], 3)} ({_f(c['K']['min'], 3)}–{_f(c['K']['max'], 3)}), "
            f"rotation {_f(c['rotation_deg']['mean'], 1)}° "
            f"({_f(c['rotation_deg']['min'], 1)}–{_f(c['rotation_deg']['max'], 1)}), "
            f"radio map {_f(c['n_rp']['mean'], 0)} RPs, {_f(c['n_ap']['mean'], 0)} APs. "
            f"adaptive vs wifi_only: "
            f"{_f(g['summary']['adaptive_vs_wifi_only_reduction_pct'], 1)} % lower mean."
            f"</p>"
        )
        true_pdr = pdr_true_start(g)
        parts.append(
            _scheme_table(g["summary"], [(PDR_TRUE_START_LABEL, true_pdr)] if true_pdr is not None else [])
        )
        parts.append(f"<p><b>{html.escape(pdr_true_start_text(doc['format'], g))}</b></p>")
        if "summary_true_start" in g:
            parts.append("<h3>Truth-initialised start (labelled run)</h3>")
            parts.append(_scheme_table(g["summary_true_start"]))
        if "fix_sources" in g:
            parts.append("<h3>Fix sources (FIX records per scheme and source, pooled over the walks)</h3>")
            parts.append(fix_sources_html(g["fix_sources"]))
        pooled = _pooled(g)
        if pooled:
            parts.append(_img(to_png(plot_cdf(pooled, f"{g['label']}: error CDF")), "CDF"))
            parts.append(_img(to_png(plot_box(pooled, g["label"])), "box plot"))
        # worst walks, ranked by the mean error of the group's best scheme
        sch = g["summary"]["schemes"]
        finite = {n: s["mean"] for n, s in sch.items() if s["mean"] is not None and math.isfinite(s["mean"])}
        best_overall = min(finite, key=lambda n: finite[n]) if finite else None
        rows = [r for r in g["walk_rows"] if r.get("fixes") and best_overall in r["fixes"]]
        rows.sort(key=lambda r: -(r["fixes"][best_overall]["mean"] or 0))
        if rows:
            parts.append(f"<h3>Worst walks (by {best_overall} mean error)</h3>")
        for r in rows[:WORST_WALKS]:
            means = {
                n: s["mean"]
                for n, s in r["fixes"].items()
                if s["mean"] is not None and math.isfinite(s["mean"])
            }
            if not means:
                continue
            best, worst = min(means, key=lambda n: means[n]), max(means, key=lambda n: means[n])
            npz = Path(r["dir"]) / "analysis.npz"
            if not npz.is_file():
                continue
            series = _matched(dict(np.load(npz)))
            title = f"{r['walk']}: best {best} {means[best]:.1f} m, worst {worst} {means[worst]:.1f} m (mean)"
            parts.append(_img(to_png(plot_walk(series, r["walk"], [best, worst], plan, title)), r["walk"]))
        ref_cols = [
            (tag, n)
            for tag in ("fixes", "true_start")
            for n in g.get(_SUMMARY[tag], {}).get("references", {})
        ]
        head = ["walk", "waypoints", "K", "rotation °", "RPs"] + [f"{n} mean" for n in sch]
        if true_pdr is not None:
            head.append(f"{PDR_TRUE_START_LABEL} mean")
        trows = []
        for r in g["walk_rows"]:
            fo = r.get("fold") or {}
            trows.append(
                [
                    r["walk"],
                    r["waypoints"],
                    _f(fo.get("K"), 3),
                    _f(fo.get("rotation_deg"), 1),
                    fo.get("n_rp", "-"),
                ]
                + [_f((r.get("fixes") or {}).get(n, {}).get("mean")) for n in sch]
                + (
                    [_f((r.get("true_start") or {}).get(PDR_ONLY, {}).get("mean"))]
                    if true_pdr is not None
                    else []
                )
                + [_f((r.get("references") or {}).get(tag, {}).get(n, {}).get("mean")) for tag, n in ref_cols]
            )
        head += [f"{n} mean" + (" (truth-initialised)" if tag == "true_start" else "") for tag, n in ref_cols]
        parts.append("<h3>Per walk</h3>" + _table(head, trows))
    return (
        f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>StrideFix realbench fusion"
        f"</title><style>{CSS}</style></head><body>{''.join(parts)}</body></html>"
    )


def write_report(doc: dict[str, Any], path: str | Path) -> str:
    """Render ``doc`` (with per-sample errors, before they are stripped) to ``path``."""
    Path(path).write_text(render(doc), encoding="utf-8")
    return str(path)
