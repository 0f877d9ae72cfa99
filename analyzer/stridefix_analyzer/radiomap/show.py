"""Presenting a radio map: the text summary of a build or a site file, and the PNG of its RPs.

Plotting lives here, apart from building (matplotlib is imported only when a PNG is drawn).
"""

from __future__ import annotations

import os

import numpy as np
from stridefix import site_t


def format_summary(s: dict) -> str:
    """Human-readable lines of a build or site summary."""
    lines = []
    if s.get("name"):
        lines.append(f"site        {s['name']}")
    if "mode" in s:
        lines.append(f"mode        {s['mode']} ({s['mode_reason']})")
        sc = s["scans"]
        skipped = ", ".join(f"{k[8:]} {v}" for k, v in sc.items() if k.startswith("skipped_") and v)
        lines.append(
            f"scans       {sc['used']} used of {sc['total']} in "
            f"{len(s['recordings'])} recording(s)" + (f"; skipped: {skipped}" if skipped else "")
        )
    else:
        lines.append(f"source      {s['source']}")
    lines.append(
        f"radio map   {s['n_rp']} RPs, {s['n_ap']} APs, {s['n_entries']} entries"
        + (
            f" ({s['entries_below_min_count']} below min count {s['min_count']} dropped"
            f", and {s['rps_dropped_no_entry']} RPs left without one)"
            if "min_count" in s
            else ""
        )
        + (f"; {s['rps_without_ap']} RP(s) with no AP" if s["rps_without_ap"] else "")
    )
    cell = f"cell {s['cell_size_m']:g} m" if s["cell_size_m"] > 0 else "surveyed points"
    geo = f", origin {s['geo'][0]:.6f}, {s['geo'][1]:.6f}" if s.get("geo") else ""
    lines.append(f"frame       rotation {s['map_rotation_deg']:g} deg, {cell}{geo}")
    lines.append(f"floors      {s['n_floors']} from {s['lowest_floor']}")
    for f, info in s["floors"].items():
        text = f"  floor {f:>3}  h {info['height_m']:6.2f} m  {info['rps']:5d} RPs  {info['aps']:4d} APs"
        if info["rps"]:
            text += (
                f"  x {info['x_range_m'][0]:.1f}..{info['x_range_m'][1]:.1f} m"
                f"  y {info['y_range_m'][0]:.1f}..{info['y_range_m'][1]:.1f} m"
                f"  {info['mean_aps_per_rp']:.1f} APs/RP  {info['mean_scans_per_rp']:.1f} scans/RP"
            )
            if "cell_area_m2" in info:
                text += f"  {info['cell_area_m2']:.0f} m² covered"
        lines.append(text)
    return "\n".join(lines)


def plot_site(site: site_t, png_path: str) -> None:
    """PNG of the RPs per floor (one panel each), coloured by the number of APs heard."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rp_floor = np.asarray(site.rp_floor)
    n_aps = np.bincount(np.asarray(site.entry_rp, dtype=np.int64), minlength=site.n_rp)
    floors = [
        site.lowest_floor + i for i in range(site.n_floors) if np.any(rp_floor == site.lowest_floor + i)
    ] or [site.lowest_floor]
    fig, axes = plt.subplots(
        1, len(floors), figsize=(5 * len(floors), 4.5), squeeze=False, constrained_layout=True
    )
    vmax = max(1, int(n_aps.max())) if site.n_rp else 1
    for ax, f in zip(axes[0], floors):
        sel = rp_floor == f
        sc = ax.scatter(
            np.asarray(site.rp_x_m)[sel],
            np.asarray(site.rp_y_m)[sel],
            c=n_aps[sel],
            cmap="viridis",
            vmin=0,
            vmax=vmax,
            s=18,
        )
        ax.set_title(f"floor {f}: {int(sel.sum())} RPs")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    fig.colorbar(sc, ax=list(axes[0]), label="APs heard at RP")
    fig.suptitle(site.name or "radio map")
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
