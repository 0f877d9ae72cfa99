"""``stridefix compare A.json B.json``: two runs side by side, per walk, with a significance figure.

A and B are each a realbench ``results.json`` (every walk of every group, per scheme) or an
``analyze`` ``metrics.json`` (one walk, named by its ``--label``). The walks are paired by (group,
walk) and the schemes by name (:func:`pair_runs`; two ``metrics.json`` are one walk each, so they are
the pair whatever their labels, and the console says so; nothing paired is exit status 3 with the
groups and walks of each side), so a ``--set`` what-if run compares against its baseline walk by walk: for each scheme the
per-walk difference B − A of the chosen statistic (``--metric``, default the mean position error),
its mean and median, the walks where B is better / worse / equal, and the two-sided Wilcoxon
signed-rank test's p-value over the paired differences (``scipy.stats.wilcoxon``: no normality
assumed; walks with equal values drop out, as the test's default zero method does). A p-value needs
at least :data:`MIN_PAIRS` non-zero differences; two ``metrics.json`` (one walk) are compared
without one. Lower is better for every metric offered (errors, IPIN score) except the floor hit
rate. Writes ``--out`` HTML (the tables and a paired-difference plot) and ``--json``.
"""

from __future__ import annotations

import argparse
import html
import json
import math
import os
import sys
from collections.abc import Mapping
from typing import Any, cast

import numpy as np
from stridefix_common.exits import EXIT_NOTHING_VALID, EXIT_USAGE, input_error_status

from stridefix_analyzer.io.results import ResultsFileError, read_any_results

#: statistics a walk row offers: realbench walk rows and analyze's per_scheme position_error_m
METRICS = ("mean", "median", "p75", "p90", "p95", "max", "rmse", "ipin_score", "floor_hit_rate")
HIGHER_IS_BETTER = frozenset({"floor_hit_rate"})
#: fewest non-zero paired differences for a p-value (Wilcoxon's exact two-sided p ≥ 1/16 below 5)
MIN_PAIRS = 5


#: the group of an analyze metrics.json's one walk (its walk name is the --label)
SINGLE_WALK_GROUP = "walk"


class CompareInputError(ValueError):
    """A run file is missing, unreadable or of an unknown kind (the message names it); ``status``:
    the command's exit status for it (3 for a file that is not JSON, else 2)."""

    def __init__(self, message: str, status: int = EXIT_USAGE) -> None:
        super().__init__(message)
        self.status = status


class NothingPairedError(ValueError):
    """A and B have no walk in common (the message shows what each side has)."""


Run = dict[tuple[str, str], dict[str, dict[str, float]]]


def _sides(run: Run) -> str:
    groups: dict[str, list[str]] = {}
    for g, w in sorted(run):
        groups.setdefault(g, []).append(w)
    return "; ".join(
        f"group {g!r}: {len(ws)} walk(s) "
        + ", ".join(repr(w) for w in ws[:3])
        + (", ..." if len(ws) > 3 else "")
        for g, ws in groups.items()
    )


def pair_runs(a: Run, b: Run, name_a: str, name_b: str) -> tuple[Run, Run, str]:
    """A and B ready for :func:`compare`, and the line saying how they were paired: two single-walk
    metrics.json are paired whatever their labels (B's walk takes A's key); otherwise by (group, walk).
    Raises :class:`NothingPairedError` when no walk pairs."""
    single = all(len(r) == 1 and next(iter(r))[0] == SINGLE_WALK_GROUP for r in (a, b))
    if single:
        (ka,), (kb,) = a, b
        if ka != kb:
            note = (
                f"paired the one walk of each metrics.json regardless of label: A {ka[1]!r} with B {kb[1]!r}"
            )
            return a, {ka: b[kb]}, note
        return a, b, f"paired the one walk of each metrics.json ({ka[1]!r})"
    common = set(a) & set(b)
    if not common:
        raise NothingPairedError(
            f"no walk pairs: walks pair by (group, walk), and {name_a} has {_sides(a)}, while {name_b} has "
            f"{_sides(b)} (an analyze metrics.json is group {SINGLE_WALK_GROUP!r}, walk = its --label)"
        )
    return a, b, f"paired {len(common)} walk(s) by (group, walk): {len(a)} in A, {len(b)} in B"


def load_run(path: str) -> Run:
    """(group, walk) → scheme → statistic of one run file (module docstring)."""
    try:
        run = read_any_results(path)
    except ResultsFileError as exc:
        raise CompareInputError(str(exc), input_error_status(exc)) from exc
    walks: dict[tuple[str, str], dict[str, dict[str, float]]] = {}
    if run.realbench is not None:
        for g in run.realbench["groups"]:
            group = str(g.get("label") or cast(Mapping[str, Any], g).get("group") or "?")
            for row in g.get("walk_rows", []):
                fixes = row.get("fixes")
                if row.get("error") or not fixes:
                    continue
                walks[(group, str(row["walk"]))] = {
                    name: {k: _num(cast(Mapping[str, Any], s).get(k)) for k in METRICS}
                    for name, s in fixes.items()
                }
    elif run.metrics is not None:
        m = run.metrics
        if m.get("truth") is False:
            raise CompareInputError(
                f"{path}: an analyze metrics.json of a walk without truth has no position errors to "
                "compare; analyze the walk with its TRUTH log"
            )
        walks[
            (
                SINGLE_WALK_GROUP,
                str(m.get("label") or os.path.basename(os.path.dirname(os.path.abspath(path)))),
            )
        ] = {
            name: {
                **{k: _num(e.get(k)) for k in METRICS if k in e},
                "ipin_score": _num(s.get("ipin_score")),
                "floor_hit_rate": _num(s.get("floor_hit_rate")),
            }
            for name, s in m["per_scheme"].items()
            for e in [cast(Mapping[str, Any], s["position_error_m"])]
        }
    else:
        raise CompareInputError(
            f"{path}: {run.kind}: a crowd-map file has no per-scheme walk rows; compare realbench fusion "
            "results.json or analyze metrics.json files"
        )
    if not walks:
        raise CompareInputError(f"{path}: no scored walk in it")
    return walks


def _num(v: Any) -> float:
    return float(v) if isinstance(v, (int, float)) else float("nan")  # None (JSON null) → NaN


def compare(a: dict, b: dict, metric: str = "mean") -> dict[str, Any]:
    """Per scheme: the paired per-walk values of ``metric`` in A and B and their test (JSON-ready)."""
    from scipy.stats import wilcoxon  # scipy only when comparing

    if metric not in METRICS:
        raise CompareInputError(f"unknown metric {metric!r}; one of {', '.join(METRICS)}")
    common = sorted(set(a) & set(b))
    schemes = sorted({n for w in common for n in a[w]} & {n for w in common for n in b[w]})
    sign = -1.0 if metric in HIGHER_IS_BETTER else 1.0
    rows = []
    for name in schemes:
        pairs = [
            (w, a[w][name][metric], b[w][name][metric])
            for w in common
            if name in a[w]
            and name in b[w]
            and math.isfinite(a[w][name][metric])
            and math.isfinite(b[w][name][metric])
        ]
        va = np.array([p[1] for p in pairs])
        vb = np.array([p[2] for p in pairs])
        d = vb - va
        nonzero = int(np.count_nonzero(d))
        p_value = float("nan")
        if nonzero >= MIN_PAIRS:
            p_value = float(wilcoxon(vb, va, alternative="two-sided").pvalue)
        rows.append(
            {
                "scheme": name,
                "walks": len(pairs),
                "a_mean": float(va.mean()) if len(pairs) else float("nan"),
                "b_mean": float(vb.mean()) if len(pairs) else float("nan"),
                "diff_mean": float(d.mean()) if len(pairs) else float("nan"),
                "diff_median": float(np.median(d)) if len(pairs) else float("nan"),
                "b_better": int(np.count_nonzero(sign * d < 0)),
                "b_worse": int(np.count_nonzero(sign * d > 0)),
                "equal": len(pairs) - nonzero,
                "wilcoxon_p": p_value,
                "per_walk": [{"group": w[0], "walk": w[1], "a": x, "b": y} for (w, x, y) in pairs],
            }
        )
    return {
        "metric": metric,
        "lower_is_better": metric not in HIGHER_IS_BETTER,
        "walks_a": len(a),
        "walks_b": len(b),
        "walks_paired": len(common),
        "only_in_a": [list(w) for w in sorted(set(a) - set(b))],
        "only_in_b": [list(w) for w in sorted(set(b) - set(a))],
        "schemes": rows,
    }


def _f(v: float, d: int = 3) -> str:
    return "-" if not math.isfinite(v) else f"{v:.{d}f}"


def _p(v: float) -> str:
    return "-" if not math.isfinite(v) else (f"{v:.2g}" if v < 0.001 else f"{v:.3f}")


def format_table(doc: dict[str, Any], a: str, b: str) -> str:
    """The console table of :func:`compare`'s document."""
    lines = [
        f"compare {doc['metric']} per walk: A = {a}, B = {b}; {doc['walks_paired']} walks paired "
        f"({len(doc['only_in_a'])} only in A, {len(doc['only_in_b'])} only in B)",
        f"{'scheme':<14}{'walks':>6}{'A':>9}{'B':>9}{'B-A':>9}{'median':>9}{'better':>8}{'worse':>7}{'equal':>7}"
        f"{'p':>9}",
    ]
    for r in doc["schemes"]:
        lines.append(
            f"{r['scheme']:<14}{r['walks']:>6}{_f(r['a_mean']):>9}{_f(r['b_mean']):>9}{_f(r['diff_mean']):>9}"
            f"{_f(r['diff_median']):>9}{r['b_better']:>8}{r['b_worse']:>7}{r['equal']:>7}{_p(r['wilcoxon_p']):>9}"
        )
    direction = "lower" if doc["lower_is_better"] else "higher"
    lines.append(
        f"(A, B: mean over the paired walks; better/worse: walks where B is {direction}; p: two-sided Wilcoxon "
        f"signed-rank over the per-walk differences, '-' below {MIN_PAIRS} non-zero differences)"
    )
    return "\n".join(lines)


def _plot_png(doc: dict[str, Any]) -> bytes:
    """Per scheme, each walk's B − A as a dot (its colour from the scheme registry), zero marked."""
    from stridefix_analyzer.schemes import UnknownSchemeError, scheme_code, scheme_colour
    from stridefix_analyzer.scoring.plots import plt, to_png

    rows = doc["schemes"]
    fig, ax = plt.subplots(figsize=(8, 0.5 + 0.45 * max(len(rows), 1)))
    for i, r in enumerate(rows):
        d = np.array([w["b"] - w["a"] for w in r["per_walk"]])
        try:
            colour = scheme_colour(scheme_code(r["scheme"]))
        except UnknownSchemeError:
            colour = "black"
        jitter = np.linspace(-0.15, 0.15, len(d)) if len(d) > 1 else np.zeros(len(d))
        ax.plot(d, i + jitter, "o", color=colour, ms=4, alpha=0.8)
        if len(d):
            ax.plot([d.mean()], [i], "|", color="black", ms=16, mew=2)
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_yticks(range(len(rows)), [r["scheme"] for r in rows])
    ax.invert_yaxis()  # the table's order, top down
    ax.set_xlabel(f"B − A, {doc['metric']} per walk" + (" [m]" if doc["metric"] != "floor_hit_rate" else ""))
    ax.set_title("Paired differences per walk (bar: mean)")
    ax.grid(alpha=0.3, axis="x")
    return to_png(fig)


def render_html(doc: dict[str, Any], a: str, b: str) -> str:
    import base64

    from stridefix_analyzer.scoring.style import CSS

    head = "".join(
        f"<th>{h}</th>"
        for h in ("scheme", "walks", "A", "B", "B − A", "median", "B better", "B worse", "equal", "p")
    )
    body = "".join(
        f"<tr><td class='k'>{html.escape(r['scheme'])}</td><td>{r['walks']}</td><td>{_f(r['a_mean'])}</td>"
        f"<td>{_f(r['b_mean'])}</td><td>{_f(r['diff_mean'])}</td><td>{_f(r['diff_median'])}</td>"
        f"<td>{r['b_better']}</td><td>{r['b_worse']}</td><td>{r['equal']}</td><td>{_p(r['wilcoxon_p'])}</td></tr>"
        for r in doc["schemes"]
    )
    png = base64.b64encode(_plot_png(doc)).decode("ascii")
    return (
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>StrideFix compare</title>"
        f"<style>{CSS}</style></head><body><h1>StrideFix compare: {html.escape(doc['metric'])} per walk</h1>"
        f"<p class='note'>A = {html.escape(a)}<br>B = {html.escape(b)}<br>{doc['walks_paired']} walks paired. "
        f"p: two-sided Wilcoxon signed-rank over the per-walk differences (none below {MIN_PAIRS} "
        f"non-zero differences).</p><table><tr>{head}</tr>{body}</table>"
        f"<img alt='paired differences' src='data:image/png;base64,{png}'></body></html>"
    )


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "compare",
        help="compare two runs (realbench results.json or analyze metrics.json) walk by walk",
        description="Pair the walks of run A and run B and compare a statistic per scheme: mean "
        "difference, walks better and worse, and a Wilcoxon signed-rank p-value.",
    )
    p.add_argument("a", metavar="A.json", help="the baseline run")
    p.add_argument("b", metavar="B.json", help="the run compared with it (e.g. a --set what-if)")
    p.add_argument("--metric", default="mean", choices=METRICS, help="statistic per walk (default: mean)")
    p.add_argument("--out", metavar="FILE", help="also write the comparison as HTML (tables and a plot)")
    p.add_argument("--json", metavar="FILE", help="also write the comparison as JSON")
    return p


def run(args: argparse.Namespace) -> int:
    try:
        a, b, note = pair_runs(load_run(args.a), load_run(args.b), args.a, args.b)
        doc = compare(a, b, args.metric)
    except CompareInputError as exc:
        print(f"stridefix compare: error: {exc}", file=sys.stderr)
        return exc.status
    except NothingPairedError as exc:
        print(f"stridefix compare: error: {exc}", file=sys.stderr)
        return EXIT_NOTHING_VALID
    print(f"stridefix compare: {note}")
    print(format_table(doc, args.a, args.b))
    if args.json:
        from stridefix_analyzer.io.jsonio import json_ready

        _write(args.json, json.dumps(json_ready(doc), indent=2, allow_nan=False) + "\n")
    if args.out:
        _write(args.out, render_html(doc, args.a, args.b))
    return 0 if doc["walks_paired"] else 1


def _write(path: str, text: str) -> None:
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {path}")
