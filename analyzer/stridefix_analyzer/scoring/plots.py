"""Figures for the analysis report (matplotlib, Agg backend; no metrics computed here).

Every function takes the arrays of ``analysis.npz`` (see
:meth:`stridefix_analyzer.metrics.Metrics.series`) and returns a matplotlib Figure;
:func:`to_png` renders one to PNG bytes and closes it.
"""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402

from stridefix_analyzer.schemes import scheme_colour, scheme_name  # noqa: E402
from stridefix_analyzer.scoring import style  # noqa: E402
from stridefix_analyzer.scoring.walls import PORT_KINDS  # noqa: E402

_PERCENTILE_LINES = ((50, "p50", ":"), (75, "p75", "--"), (95, "p95", "-."))


def _scheme_codes(series: dict) -> list[int]:
    return [int(c) for c in series["scheme_codes"]]


def _colors(codes: list[int]) -> dict[int, str]:
    """Each scheme's own colour (the same in every plot and report, whichever schemes a log holds)."""
    return {c: scheme_colour(c) for c in codes}


def _t0_us(series: dict) -> int:
    return int(series["truth_t_us"][0]) if len(series["truth_t_us"]) else 0


def to_png(fig, dpi: int = 110) -> bytes:
    """Render ``fig`` to PNG bytes and close it."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def _floors(series: dict) -> list[int]:
    """Every floor of the truth and of any scheme's POSE, lowest first."""
    floors = {int(f) for f in series["truth_floor"]}
    for code in _scheme_codes(series):
        floors |= {int(f) for f in series[f"s{code}_pose_floor"]}
    return sorted(floors) or [0]


def _on_floor(x: np.ndarray, y: np.ndarray, floor: np.ndarray, f: int) -> tuple[np.ndarray, np.ndarray]:
    """x, y with the samples off floor ``f`` as NaN: the line breaks where the walk leaves it."""
    off = np.asarray(floor) != f
    return np.where(off, np.nan, x), np.where(off, np.nan, y)


def _walls(ax, series: dict, f: int) -> bool:
    """Draw the site's walls of floor ``f`` (``site_wall_*``, when analyze had ``--site``)."""
    if "site_wall_floor" not in series:
        return False
    on = np.asarray(series["site_wall_floor"]) == f
    if not on.any():
        return False
    x = np.column_stack([series["site_wall_x0_m"][on], series["site_wall_x1_m"][on]]).T
    y = np.column_stack([series["site_wall_y0_m"][on], series["site_wall_y1_m"][on]]).T
    ax.plot(x, y, **style.WALL)
    return True


def _port_kinds(series: dict) -> list[str]:
    """The kinds of port the site has (building.toml's names), in :data:`PORT_KINDS` order."""
    kinds = {int(k) for k in series.get("site_port_kind", [])}
    return [name for k, name in PORT_KINDS.items() if k in kinds]


def _ports(ax, series: dict, f: int) -> None:
    """Draw the site's ports that join floor ``f``: a marker per kind and the disc a walker passes."""
    if "site_port_kind" not in series:
        return
    lo, hi = np.asarray(series["site_port_floor_lo"]), np.asarray(series["site_port_floor_hi"])
    for k in np.flatnonzero((lo <= f) & (f <= hi)):
        name = PORT_KINDS.get(int(series["site_port_kind"][k]))
        if name is None:
            continue
        x, y, r = (float(series[f"site_port_{c}"][k]) for c in ("x_m", "y_m", "radius_m"))
        ax.plot(x, y, **style.PORT[name])
        ax.add_patch(Circle((x, y), r, edgecolor=style.PORT[name]["color"], **style.PORT_DISC))


def plot_trajectory(series: dict):
    """Truth path and every scheme's POSE track in the map frame, one panel per floor (the samples
    on that floor; the site's walls and ports (doors, stairs, elevators: a marker each and the disc
    a walker passes) under them when the analysis had a site), equal aspect.

    Parameters
    ----------
    series : dict
        ``truth_x_m``, ``truth_y_m``, ``truth_floor`` (n_truth,); ``scheme_codes``; ``s<c>_pose_x_m``,
        ``s<c>_pose_y_m``, ``s<c>_pose_floor`` (n_pose,) per scheme code c; optionally ``site_wall_*``
        and ``site_port_*`` (:func:`stridefix_analyzer.scoring.walls.plan_series`).
    """
    floors = _floors(series)
    cols = min(len(floors), 2)
    rows = -(-len(floors) // cols)
    fig, axes = plt.subplots(
        rows, cols, figsize=(7.0 * cols, 6.0 * rows + 0.8), squeeze=False, layout="constrained"
    )
    tx, ty, tf = series["truth_x_m"], series["truth_y_m"], series["truth_floor"]
    colors = _colors(_scheme_codes(series))
    primary = int(series["primary_scheme"]) if "primary_scheme" in series else None
    for k, f in enumerate(floors):
        ax = axes[k // cols][k % cols]
        walls = _walls(ax, series, f)
        _ports(ax, series, f)
        ax.plot(*_on_floor(tx, ty, tf, f), **style.TRUTH)
        for code, color in colors.items():
            px, py, pf = (
                series[f"s{code}_pose_x_m"],
                series[f"s{code}_pose_y_m"],
                series[f"s{code}_pose_floor"],
            )
            lw = style.PRIMARY_LINEWIDTH if code == primary else style.TRACK["linewidth"]
            ax.plot(
                *_on_floor(px, py, pf, f),
                **{**style.TRACK, "linewidth": lw, "color": color, "label": scheme_name(code)},
            )
            if len(px) and int(pf[-1]) == f:
                ax.plot(px[-1], py[-1], color=color, **style.POSE_END)
        if len(tx) and int(tf[0]) == f:
            ax.plot(tx[0], ty[0], **style.START)
        if len(tx) and int(tf[-1]) == f:
            ax.plot(tx[-1], ty[-1], **style.END)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set(xlabel="x [m]", ylabel="y [m]", title=f"floor {f}" + (" (walls: site)" if walls else ""))
        ax.grid(True, **style.GRID)
        if k == 0:
            ax.plot([], [], color="grey", **style.POSE_END, label="end (pose)")
            for name in _port_kinds(series):  # every kind of the site, whichever floor has it
                ax.plot([], [], **style.PORT[name], label=name)
            # under the panels, not over the tracks
            fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=6, fontsize="small")
    for k in range(len(floors), rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    fig.suptitle("Trajectory: POSE vs truth (map frame), one panel per floor")
    return fig


def plot_floor_time(series: dict):
    """The true floor and each scheme's estimated floor (its POSE) against time.

    Parameters
    ----------
    series : dict
        ``truth_t_us``, ``truth_floor`` (n_truth,); ``scheme_codes``; ``s<c>_pose_t_us``,
        ``s<c>_pose_floor`` (n_pose,) per scheme.
    """
    fig, ax = plt.subplots(figsize=(9, 3.0))
    t0 = _t0_us(series)
    codes = _scheme_codes(series)
    offsets = np.linspace(-0.12, 0.12, len(codes)) if len(codes) > 1 else [0.0]
    # the truth first, wide and pale, so every scheme's line stays visible on it
    truth = {**style.TRUTH, "linewidth": 6.0, "alpha": 0.25, "zorder": 1}
    ax.step((series["truth_t_us"] - t0) / 1e6, series["truth_floor"], where="post", **truth)
    for (code, color), off in zip(_colors(codes).items(), offsets):
        t = (series[f"s{code}_pose_t_us"] - t0) / 1e6
        f = series[f"s{code}_pose_floor"] + off
        ax.step(t, f, where="post", color=color, linewidth=1.2, label=scheme_name(code), zorder=2)
    floors = _floors(series)
    ax.set_yticks(floors)
    ax.set(
        xlabel="time since first truth sample [s]",
        ylabel="floor",
        title="Floor: estimated (each scheme, offset a little) vs true",
    )
    ax.grid(True, **style.GRID)
    ax.legend(loc="upper left", fontsize="small", ncol=min(len(codes) + 1, 5))
    return fig


def plot_error_time(series: dict):
    """Position error against time since the first truth sample: small multiples, one panel per
    scheme on shared axes (the primary scheme first).

    Parameters
    ----------
    series : dict
        ``truth_t_us`` (n_truth,) [µs]; ``scheme_codes``; ``s<c>_error_m`` (n_truth,) [m], NaN
        where unscored; ``primary_scheme``.
    """
    t_s = (series["truth_t_us"] - _t0_us(series)) / 1e6
    primary = int(series["primary_scheme"])
    codes = sorted(_scheme_codes(series), key=lambda c: c != primary)
    fig, axes = plt.subplots(
        len(codes),
        1,
        figsize=(9, 0.8 + 1.25 * len(codes)),
        sharex=True,
        sharey=True,
        squeeze=False,
        layout="constrained",
    )
    colors = _colors(codes)
    # one scale for every panel, set once: each panel's own set_ylim would freeze the shared top at
    # the first panel's data and clip the others
    tops = [np.nanmax(series[f"s{c}_error_m"]) for c in codes if np.isfinite(series[f"s{c}_error_m"]).any()]
    top = 1.08 * max(tops) if tops and max(tops) > 0 else 1.0
    for ax, code in zip(axes[:, 0], codes):
        err = series[f"s{code}_error_m"]
        ax.fill_between(t_s, 0, np.nan_to_num(err), color=colors[code], alpha=0.25, linewidth=0)
        lw = style.PRIMARY_LINEWIDTH if code == primary else 1.0
        ax.plot(t_s, err, color=colors[code], linewidth=lw)
        mean = float(np.nanmean(err)) if np.isfinite(err).any() else float("nan")
        ax.text(
            0.995,
            0.8,
            f"{scheme_name(code)}{' (primary)' if code == primary else ''}: mean {mean:.2f} m",
            transform=ax.transAxes,
            ha="right",
            fontsize="small",
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8),
        )
        ax.grid(True, **style.GRID)
    axes[0, 0].set_ylim(0, top)
    axes[-1, 0].set_xlabel("time since first truth sample [s]")
    axes[len(codes) // 2, 0].set_ylabel("horizontal error [m]")
    fig.suptitle("Position error over time (latest POSE at or before each truth time)")
    return fig


def plot_error_cdf(series: dict):
    """Empirical CDF of the position error per scheme; p50/p75/p95 marked for the primary scheme.

    Parameters
    ----------
    series : dict
        ``scheme_codes``; ``s<c>_error_m`` (n_truth,) [m], NaN where unscored; ``primary_scheme``.
    """
    fig, ax = plt.subplots(figsize=(7.5, 4.5))
    primary = int(series["primary_scheme"])
    for code, color in _colors(_scheme_codes(series)).items():
        err = series[f"s{code}_error_m"]
        e = np.sort(err[np.isfinite(err)])
        if not e.size:
            continue
        frac = np.arange(1, e.size + 1) / e.size
        ax.step(
            e,
            frac,
            where="post",
            color=color,
            linewidth=1.8 if code == primary else 1.0,
            label=scheme_name(code),
        )
        if code == primary:
            for pct, label, style in _PERCENTILE_LINES:
                v = float(np.percentile(e, pct))
                ax.axvline(v, color=color, linestyle=style, linewidth=0.9)
                ax.annotate(
                    f"{label} {v:.2f} m",
                    xy=(v, pct / 100),
                    xytext=(6, -4),
                    textcoords="offset points",
                    fontsize="small",
                    color=color,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8),
                )
    ax.set_xlabel("horizontal error [m]")
    ax.set_ylabel("fraction of truth samples")
    ax.set_title(f"Error CDF (marks: {scheme_name(primary)})")
    ax.set_ylim(0, 1.02)
    ax.set_xlim(left=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="lower right", fontsize="small")
    return fig


def render_all(series: dict) -> dict[str, bytes]:
    """All report figures as PNG bytes: ``trajectory``, ``floor_time``, ``error_time``, ``error_cdf``."""
    return {
        "trajectory": to_png(plot_trajectory(series)),
        "floor_time": to_png(plot_floor_time(series)),
        "error_time": to_png(plot_error_time(series)),
        "error_cdf": to_png(plot_error_cdf(series)),
    }
