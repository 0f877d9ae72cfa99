"""Figures of a walk without ground truth (matplotlib, Agg; no metrics computed here).

Every function takes the arrays :meth:`stridefix_analyzer.scoring.walk.Walk.series` writes into
analysis.npz and returns a Figure, or None when the log had nothing to draw;
:func:`render_walk` renders the lot to PNG bytes (:func:`stridefix_analyzer.scoring.plots.to_png`).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

from stridefix_analyzer.schemes import scheme_colour, scheme_name  # noqa: E402
from stridefix_analyzer.scoring import style  # noqa: E402
from stridefix_analyzer.scoring.fixsources import method_label, method_name  # noqa: E402
from stridefix_analyzer.scoring.plots import _on_floor, _walls, to_png  # noqa: E402
from stridefix_analyzer.scoring.walk import ACTIVITY_NAMES, CHI2_2DOF_95  # noqa: E402


def _codes(series: dict) -> list[int]:
    """Scheme codes, the primary last (drawn on top)."""
    primary = int(series["primary_scheme"])
    return sorted((int(c) for c in series["scheme_codes"]), key=lambda c: c == primary)


def _t0_us(series: dict) -> int:
    starts = [int(series[f"s{c}_pose_t_us"][0]) for c in _codes(series) if len(series[f"s{c}_pose_t_us"])]
    return min(starts) if starts else 0


def _s(series: dict, key: str) -> np.ndarray:
    return (np.asarray(series[key], np.float64) - _t0_us(series)) / 1e6


def plot_tracks(series: dict):
    """Every scheme's track in the map frame, one panel per floor its poses visited, over the site's
    walls when analyze had ``--site``; the primary heavier, start ○ and end □ of the primary."""
    codes, primary = _codes(series), int(series["primary_scheme"])
    floors = sorted({int(f) for c in codes for f in series[f"s{c}_pose_floor"]}) or [0]
    cols = min(len(floors), 2)
    rows = -(-len(floors) // cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(7.0 * cols, 6.0 * rows + 0.8), squeeze=False, layout="constrained"
    )
    for k, f in enumerate(floors):
        ax = axes[k // cols][k % cols]
        walls = _walls(ax, series, f)
        for c in codes:
            x, y, fl = (series[f"s{c}_pose_{col}"] for col in ("x_m", "y_m", "floor"))
            lw = style.PRIMARY_LINEWIDTH if c == primary else style.TRACK["linewidth"]
            label = scheme_name(c) + (" (primary)" if c == primary else "")
            ax.plot(
                *_on_floor(x, y, fl, f),
                **{**style.TRACK, "linewidth": lw, "color": scheme_colour(c), "label": label},
            )
            if c == primary and len(x):
                if int(fl[0]) == f:
                    ax.plot(x[0], y[0], **{**style.START, "label": "start (primary)"})
                if int(fl[-1]) == f:
                    ax.plot(x[-1], y[-1], color=scheme_colour(c), **style.POSE_END, label="end (primary)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set(xlabel="x [m]", ylabel="y [m]", title=f"floor {f}" + (" (walls: site)" if walls else ""))
        ax.grid(True, **style.GRID)
        if k == 0:
            fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=6, fontsize="small")
    for k in range(len(floors), rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    fig.suptitle("Tracks (map frame, no ground truth), one panel per floor")
    return fig


def plot_floor_height(series: dict):
    """The primary pose's floor and the barometric height relative to the start over time."""
    fig, (ax_f, ax_h) = plt.subplots(2, 1, figsize=(9, 4.6), sharex=True, layout="constrained")
    primary = int(series["primary_scheme"])
    ax_f.step(
        _s(series, f"s{primary}_pose_t_us"),
        series[f"s{primary}_pose_floor"],
        where="post",
        color=scheme_colour(primary),
        label=f"{scheme_name(primary)} (primary)",
    )
    ax_f.set(ylabel="floor", title="Floor of the primary pose and barometric height")
    ax_f.yaxis.get_major_locator().set_params(integer=True)
    ax_f.grid(True, **style.GRID)
    if len(series.get("walk_baro_t_us", [])):
        ax_h.plot(_s(series, "walk_baro_t_us"), series["walk_baro_height_m"], color="#555", linewidth=0.8)
    else:
        ax_h.text(0.5, 0.5, "no BARO samples in the logs", transform=ax_h.transAxes, ha="center")
    ax_h.set(xlabel="time since the first pose [s]", ylabel="height [m]")
    ax_h.grid(True, **style.GRID)
    return fig


def plot_steps(series: dict):
    """Steps against time, each step coloured by its activity; stride length below."""
    if not len(series.get("walk_step_t_us", [])):
        return None
    fig, (ax_n, ax_l) = plt.subplots(2, 1, figsize=(9, 4.6), sharex=True, layout="constrained")
    t = _s(series, "walk_step_t_us")
    act = np.asarray(series["walk_step_activity"])
    for a in np.unique(act):
        sel = act == a
        name = ACTIVITY_NAMES.get(int(a), f"activity_{int(a)}")
        ax_n.plot(t[sel], series["walk_step_index"][sel], ".", markersize=3, label=name)
        ax_l.plot(t[sel], series["walk_step_length_m"][sel], ".", markersize=3)
    ax_n.set(ylabel="step index", title="Steps and activity")
    ax_n.legend(fontsize="small", loc="upper left")
    ax_l.set(xlabel="time since the first pose [s]", ylabel="stride length [m]")
    for ax in (ax_n, ax_l):
        ax.grid(True, **style.GRID)
    return fig


def plot_sigma(series: dict):
    """The σ each scheme claims (pose_t.sigma_m) over time."""
    fig, ax = plt.subplots(figsize=(9, 3.2), layout="constrained")
    primary = int(series["primary_scheme"])
    for c in _codes(series):
        lw = style.PRIMARY_LINEWIDTH if c == primary else 1.0
        ax.plot(
            _s(series, f"s{c}_pose_t_us"),
            series[f"s{c}_pose_sigma_m"],
            color=scheme_colour(c),
            linewidth=lw,
            label=scheme_name(c),
        )
    ax.set(xlabel="time since the first pose [s]", ylabel="claimed σ [m]", title="The σ each scheme claims")
    ax.set_ylim(bottom=0)
    ax.grid(True, **style.GRID)
    ax.legend(fontsize="small", ncol=4)
    return fig


def plot_fixes(series: dict):
    """The primary scheme's fixes: |innovation| [m] and NIS per fix over time, by source; accepted
    filled, rejected crosses; the χ²(2) 95 % line on the NIS."""
    if not len(series.get("walk_fix_t_us", [])):
        return None
    sel = np.asarray(series["walk_fix_scheme"]) == int(series["primary_scheme"])
    if not sel.any():
        return None
    fig, (ax_i, ax_n) = plt.subplots(2, 1, figsize=(9, 5.0), sharex=True, layout="constrained")
    t = _s(series, "walk_fix_t_us")[sel]
    inn = np.hypot(series["walk_fix_innovation_x_m"][sel], series["walk_fix_innovation_y_m"][sel])
    nis, acc = series["walk_fix_nis"][sel], np.asarray(series["walk_fix_accepted"][sel], bool)
    method = np.asarray(series["walk_fix_method"])[sel]
    for k, m in enumerate(np.unique(method)):
        on = method == m
        colour = f"C{k}"
        label = method_label(method_name(int(m)))
        for ax, v in ((ax_i, inn), (ax_n, nis)):
            ax.plot(t[on & acc], v[on & acc], "o", markersize=3, color=colour, label=f"{label} accepted")
            ax.plot(t[on & ~acc], v[on & ~acc], "x", markersize=4, color=colour, label=f"{label} rejected")
    ax_n.axhline(CHI2_2DOF_95, color="k", linestyle="--", linewidth=0.8, label="χ²(2) 95 %")
    ax_n.set_yscale("log")
    ax_i.set(ylabel="|innovation| [m]", title=f"Fixes judged by {scheme_name(int(series['primary_scheme']))}")
    ax_n.set(xlabel="time since the first pose [s]", ylabel="NIS")
    ax_i.legend(fontsize="small", ncol=4)
    for ax in (ax_i, ax_n):
        ax.grid(True, **style.GRID)
    return fig


#: HEALTH panels at most (the table lists every counter that grew)
MAX_HEALTH_PANELS = 18


def plot_health(series: dict):
    """Each HEALTH counter that grew, against time since the first pose (small multiples)."""
    names = [
        k[len("walk_health_") :] for k in series if k.startswith("walk_health_") and k != "walk_health_t_us"
    ]
    if not names:
        return None
    shown = names[:MAX_HEALTH_PANELS]
    cols = 3
    rows = -(-len(names) // cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(10, 1.8 * rows + 0.6), squeeze=False, sharex=True, layout="constrained"
    )
    t = _s(series, "walk_health_t_us")
    for k, name in enumerate(shown):
        ax = axes[k // cols][k % cols]
        ax.step(t, series[f"walk_health_{name}"], where="post", color="#246")
        ax.set_title(name, fontsize="small")
        ax.grid(True, **style.GRID)
    for k in range(len(shown), rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    more = f", the first {len(shown)} of {len(names)} (all in the table)" if len(shown) < len(names) else ""
    fig.suptitle(f"HEALTH counters that grew (time since the first pose [s]){more}")
    return fig


#: the figures of :func:`render_walk`, in report order: name → function
FIGURES = {
    "tracks": plot_tracks,
    "floor_height": plot_floor_height,
    "steps": plot_steps,
    "sigma": plot_sigma,
    "fixes": plot_fixes,
    "health": plot_health,
}


def render_walk(series: dict, names=tuple(FIGURES)) -> dict[str, bytes]:
    """The figures ``names`` as PNG bytes; a figure with nothing to draw is left out."""
    out = {}
    for name in names:
        fig = FIGURES[name](series)
        if fig is not None:
            out[name] = to_png(fig)
    return out
