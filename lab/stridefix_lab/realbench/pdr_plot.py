"""The figure of ``realbench pdr-distance`` (no metric is computed here): PDR against true segment
distance, and the CDFs of the absolute errors of the Weinberg, fixed-stride and firmware distances.
"""

from __future__ import annotations

import io

import numpy as np
from stridefix_analyzer.io.logread import Table


def plot_pdr_distance(seg: Table, title: str, target_pct: float) -> bytes:
    """PNG: PDR vs true segment distance (scatter, 1:1 and ±5 % lines) and the |error| CDFs, with the
    target median error ``target_pct`` marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    used = seg["excluded"] == ""
    true = seg["true_m"][used]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5.2))
    ax1.scatter(true, seg["baseline_m"][used], s=9, color="0.6", label="fixed stride × steps")
    ax1.scatter(true, seg["pdr_m"][used], s=9, color="C0", label="Weinberg, K LOWO")
    top = float(np.nanmax(np.r_[true, seg["pdr_m"][used], 1.0])) * 1.05
    x = np.array([0, top])
    ax1.plot(x, x, "k-", lw=1, label="1:1")
    ax1.plot(x, 1.05 * x, "k:", lw=0.8, label="±5 %")
    ax1.plot(x, 0.95 * x, "k:", lw=0.8)
    ax1.set(
        xlim=(0, top),
        ylim=(0, top),
        xlabel="true segment distance [m]",
        ylabel="PDR distance [m]",
        title=f"{title}: {int(used.sum())} segments",
    )
    ax1.set_aspect("equal")
    ax1.legend(loc="upper left", fontsize=8)
    for col, name, color in (
        ("err_pct", "Weinberg, K LOWO", "C0"),
        ("baseline_err_pct", "fixed stride × steps", "0.5"),
        ("fw_err_pct", "firmware length_m", "C3"),
    ):
        e = np.sort(np.abs(seg[col][used]))
        e = e[np.isfinite(e)]
        if len(e):
            ax2.step(
                e,
                np.arange(1, len(e) + 1) / len(e),
                where="post",
                color=color,
                label=f"{name} (median {np.median(e):.1f} %)",
            )
    ax2.axvline(target_pct, color="k", ls=":", lw=0.8)
    ax2.axhline(0.5, color="k", ls=":", lw=0.8)
    ax2.set(
        xlim=(0, 50),
        ylim=(0, 1),
        xlabel="|distance error| [%]",
        ylabel="fraction of segments",
        title="error CDF",
    )
    ax2.grid(alpha=0.3)
    ax2.legend(loc="lower right", fontsize=8)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()
