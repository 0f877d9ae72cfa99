"""Figures for the analysis report (matplotlib, Agg backend; no metrics computed here).

Every function takes the arrays of ``analysis.npz`` (see
:meth:`stridefix_analyzer.metrics.Metrics.series`) and returns a matplotlib Figure;
:func:`to_png` renders one to PNG bytes and closes it.
"""

from __future__ import annotations

import io
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

from stridefix_analyzer.schemes import scheme_colour, scheme_name  # noqa: E402

_TRUTH_STYLE: dict[str, Any] = dict(color="black", linewidth=2.0, label="truth")
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


def plot_trajectory(series: dict):
    """Truth path and every scheme's POSE track in the map frame, equal aspect.

    Parameters
    ----------
    series : dict
        ``truth_x_m``, ``truth_y_m`` (n_truth,); ``scheme_codes``; ``s<c>_pose_x_m``,
        ``s<c>_pose_y_m`` (n_pose,) per scheme code c. Positions in metres.
    """
    fig, ax = plt.subplots(figsize=(7.5, 6.5))
    tx, ty = series["truth_x_m"], series["truth_y_m"]
    ax.plot(tx, ty, **_TRUTH_STYLE)
    colors = _colors(_scheme_codes(series))
    for code, color in colors.items():
        px, py = series[f"s{code}_pose_x_m"], series[f"s{code}_pose_y_m"]
        ax.plot(px, py, color=color, linewidth=1.0, alpha=0.85, label=scheme_name(code))
        if len(px):
            ax.plot(px[-1], py[-1], marker="s", color=color, markersize=6, linestyle="none")
    if len(tx):
        ax.plot(
            tx[0], ty[0], marker="o", color="green", markersize=10, linestyle="none", label="start (truth)"
        )
        ax.plot(tx[-1], ty[-1], marker="X", color="red", markersize=10, linestyle="none", label="end (truth)")
    ax.plot([], [], marker="s", color="grey", linestyle="none", label="end (pose)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Trajectory: POSE vs truth (map frame)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    return fig


def plot_error_time(series: dict):
    """Position error against time since the first truth sample, one line per scheme.

    Parameters
    ----------
    series : dict
        ``truth_t_us`` (n_truth,) [µs]; ``scheme_codes``; ``s<c>_error_m`` (n_truth,) [m], NaN
        where unscored; ``primary_scheme``.
    """
    fig, ax = plt.subplots(figsize=(9, 3.8))
    t_s = (series["truth_t_us"] - _t0_us(series)) / 1e6
    primary = int(series["primary_scheme"])
    for code, color in _colors(_scheme_codes(series)).items():
        ax.plot(
            t_s,
            series[f"s{code}_error_m"],
            color=color,
            linewidth=1.6 if code == primary else 0.9,
            label=scheme_name(code),
        )
    ax.set_xlabel("time since first truth sample [s]")
    ax.set_ylabel("horizontal error [m]")
    ax.set_title("Position error over time (latest POSE at or before each truth time)")
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
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
    """All report figures as PNG bytes: ``trajectory``, ``error_time``, ``error_cdf``."""
    return {
        "trajectory": to_png(plot_trajectory(series)),
        "error_time": to_png(plot_error_time(series)),
        "error_cdf": to_png(plot_error_cdf(series)),
    }
