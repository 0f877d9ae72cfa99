"""Plots of the crowdsourced model (kept apart from the numbers): fit and solved positions."""

from __future__ import annotations

import os

import numpy as np

from stridefix_analyzer.crowd.model import DistanceModel, PairBins


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_fit(
    bins: PairBins, model: DistanceModel, png_path: str, title: str = "", display_width_db: float = 2.0
) -> None:
    """Binned true distance vs dissimilarity (mean ± 1 std per display bin, pair counts shaded)
    with the fitted g(d)."""
    plt = _plt()
    factor = max(1, int(round(display_width_db / bins.width)))
    b = bins.coarsen(factor)
    mx, md, sd, n = b.means()
    fig, (ax, axn) = plt.subplots(
        2, 1, figsize=(7, 6), sharex=True, gridspec_kw={"height_ratios": [3, 1]}, constrained_layout=True
    )
    ax.fill_between(mx, md - sd, md + sd, color="tab:blue", alpha=0.2, label="±1 std (per bin)")
    ax.plot(mx, md, "o", ms=3, color="tab:blue", label=f"mean distance per {b.width:g} dB bin")
    xs = np.linspace(0, float(mx.max()) if len(mx) else 1.0, 300)
    X = model.params
    ax.plot(
        xs,
        model(xs),
        "r-",
        lw=2,
        label=f"g(d) = max({X[0]:.2f}, {X[1]:.2f} + {X[2]:.3f}·d)  RMSE {model.rmse_m:.2f} m, "
        f"R² {model.r2:.2f}",
    )
    ax.set_ylabel("true distance [m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(title or f"dissimilarity ({model.mode}) vs distance, {bins.n_pairs} pairs")
    axn.bar(mx, n, width=b.width * 0.9, color="gray")
    axn.set_yscale("log")
    axn.set_ylabel("pairs")
    axn.set_xlabel("dissimilarity [dB]")
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=110)
    plt.close(fig)


def plot_solution(
    xy: np.ndarray,
    truth_xy: np.ndarray,
    is_truth: np.ndarray,
    anchor_index: np.ndarray,
    png_path: str,
    title: str = "",
) -> None:
    """Truth (red o) vs estimate (blue *) with a black line per pair, as in the thesis; anchors ■."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 5), constrained_layout=True)
    t = np.flatnonzero(is_truth)
    for k in t:
        ax.plot([truth_xy[k, 0], xy[k, 0]], [truth_xy[k, 1], xy[k, 1]], "k-", lw=0.5)
    ax.plot(truth_xy[t, 0], truth_xy[t, 1], "ro", ms=3, mfc="none", label="truth")
    ax.plot(xy[:, 0], xy[:, 1], "b*", ms=3, label="estimate (all points)")
    ax.plot(truth_xy[anchor_index, 0], truth_xy[anchor_index, 1], "ks", ms=3, label="anchors")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=110)
    plt.close(fig)


def plot_models(sel, png_path: str, display_bins: int = 40) -> None:
    """Per feature: binned true distance (mean ± 1 std) vs the feature, with the curves of the
    unstratified candidates fitted on all walks, labelled with their held-out R² (:mod:`.select_model`)."""
    from stridefix_analyzer.crowd.blocks import merge_bins
    from stridefix_analyzer.crowd.features import FEATURES
    from stridefix_analyzer.crowd.models import form_predict

    plt = _plt()
    feats = list(sel.bins)
    cols = min(3, len(feats))
    rows_n = (len(feats) + cols - 1) // cols
    fig, axes = plt.subplots(
        rows_n, cols, figsize=(5 * cols, 3.8 * rows_n), squeeze=False, constrained_layout=True
    )
    r2 = {r["name"]: r["heldout_r2"] for r in sel.rows}
    for ax, feat in zip(axes.ravel(), feats, strict=False):
        b = merge_bins(sel.bins[feat], width_db=FEATURES[feat][1])
        if not b.used().any():
            continue
        b = b.coarsen(max(1, len(b.count) // display_bins))
        mx, md, sd, _ = b.means()
        ax.fill_between(mx, md - sd, md + sd, color="tab:blue", alpha=0.15)
        ax.plot(mx, md, "o", ms=3, color="tab:blue", label="mean distance per bin")
        xs = np.linspace(0.0, float(mx.max()), 300)
        for name, m in sel.fitted.items():
            if m.feature != feat or len(m.params) != 1:
                continue
            lw = 2.5 if name == sel.best.name else 1.2
            ax.plot(
                xs,
                form_predict(m.form, m.params[0], xs),
                lw=lw,
                label=f"{m.form}: held-out R² {r2[name]:.2f}",
            )
        ax.set_xlabel(f"{feat} [{FEATURES[feat][0]}]")
        ax.set_ylabel("true distance [m]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    for ax in axes.ravel()[len(feats) :]:
        ax.axis("off")
    fig.suptitle(f"candidates, best {sel.best.name} ({sel.chosen_by})")
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=100)
    plt.close(fig)
