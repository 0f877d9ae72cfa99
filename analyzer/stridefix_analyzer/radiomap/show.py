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
    if "n_walls" in s:
        plan = f"plan        {s['n_walls']} wall segments, {s['n_ports']} ports, {s['n_beacons']} beacons"
        if s.get("ble_model"):
            r1, n, sig = s["ble_model"]
            plan += f" (RSSI(d) = {r1:.1f} dBm - 10·{n:.2f}·log10 d, σ {sig:.1f} dB)"
        lines.append(plan)
    if s.get("floor_plan"):
        fp = s["floor_plan"]
        lines.append(
            f"floor plan  floor {fp['floor']}: {fp['waypoints_inside_outline']:.1%} of {fp['waypoints']} "
            f"waypoints inside the outline; {fp['edges_raw']} edges -> {fp['walls_simplified']} walls, "
            f"{fp['openings']} openings ({fp['crossings']} crossings of {fp['truth_segments']} truth "
            f"segments) -> {fp['walls_opened']} wall segments; held-out walks cross a kept wall in "
            f"{fp.get('held_out_crossing_fraction', float('nan')):.1%} of their segments; "
            f"geo scale x {fp['geo_scale'][0]:.4f}, y {fp['geo_scale'][1]:.4f}"
        )
    if s.get("ble"):
        b = s["ble"]
        text = f"ble         {b['placed']} of {b['readings']} readings placed on the truth"
        if "from_table" in b:
            text += (
                f"; {b['from_table']} beacons from the table, {b['learnt']} learnt, {b['left_out']} left out"
            )
            text += f"; model {'learnt' if b['model_learnt'] else 'defaults'}"
        lines.append(text)
        if b.get("table_matched"):
            lines.append(
                "  table ↔ MAC " + ", ".join(f"{n}={m or '?'}" for n, m in b["table_matched"].items())
            )
    if s.get("context_map"):
        lines += format_context_map(s["context_map"])
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


def format_context_map(m: dict) -> list[str]:
    """Lines of a context map summary (:func:`~.contexts.context_map_summary` or a build's): each
    context with its LSD and CDD and member count, a warning for each the CLS cannot identify, and
    the ports with their extras when given."""
    cs = m["contexts"]
    lines = [
        f"contexts    {len(cs)} in {len(m['buildings'])} building(s) ({', '.join(m['buildings'])}), "
        f"{m['n_links']} port links, {m['n_cdd']} constellation members"
    ]
    for i, c in enumerate(cs):
        where = c["kind"] if c["building"] is None else f"{c['kind']} {c['building']}"
        cdd = f"CDD {c['cdd_method']}"
        if c["cdd_method"] != "gnss":
            cdd += f": {c['members']} members, {c['min_hits']} to hear"
            cdd += f" (from {c['cdd_from']})" if "cdd_from" in c else ""
        lines.append(f"  {i:>2} {where:<16} floor {c['floor']:>3}  LSD {c['scheme']} + {c['method']}  {cdd}")
    for i, c in enumerate(cs):
        if not c["identifiable"]:
            lines.append(
                f"  warning: context {i} ({c['kind']} {c['building']} floor {c['floor']}) has no constellation "
                f"member: the CLS cannot identify it"
            )
    for i, p in enumerate(m.get("ports", [])):
        lo, hi = p["floors"]
        text = f"  port {i:>2} {p['kind']:<8} floors {lo}..{hi}  building {p['building'] or '-'}"
        text += "  outdoor" if p["outdoor"] else ""
        text += f"  {p['steps']} steps" if p["steps"] else ""
        text += f"  linked to {', '.join(str(k) for k in p['links'])}" if p["links"] else ""
        lines.append(text)
    return lines


def _outlines(site: site_t) -> list[tuple[str, list[tuple[float, float]]]]:
    """(name, vertices) of each building of the site's context map."""
    b = np.asarray(site.outline_building)
    return [
        (name, [(site.outline_x_m[i], site.outline_y_m[i]) for i in np.flatnonzero(b == k)])
        for k, name in enumerate(site.building_name)
    ]


def _site_floors(site: site_t) -> list[int]:
    """Floors with anything to draw (RPs, walls, beacons, ports), else the lowest."""
    used = set(np.asarray(site.rp_floor).tolist()) | set(np.asarray(site.wall_floor).tolist())
    used |= set(np.asarray(site.beacon_floor).tolist())
    for lo, hi in zip(site.port_floor_lo, site.port_floor_hi):
        used |= set(range(lo, hi + 1))
    floors = [site.lowest_floor + i for i in range(site.n_floors) if site.lowest_floor + i in used]
    return floors or [site.lowest_floor]


def plot_site(site: site_t, png_path: str) -> None:
    """PNG of the site per floor (one panel each): walls (grey lines), RPs coloured by the number of
    APs heard, beacons (triangles with their ids' last two bytes), ports (circles: door green,
    stairs orange, elevator purple) and the buildings' outlines (dashed blue, named)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle, Polygon

    rp_floor = np.asarray(site.rp_floor)
    n_aps = np.bincount(np.asarray(site.entry_rp, dtype=np.int64), minlength=site.n_rp)
    floors = _site_floors(site)
    fig, axes = plt.subplots(
        1, len(floors), figsize=(6 * len(floors), 5.5), squeeze=False, constrained_layout=True
    )
    vmax = max(1, int(n_aps.max())) if site.n_rp else 1
    wall_floor, beacon_floor = np.asarray(site.wall_floor), np.asarray(site.beacon_floor)
    port_colours = {1: "tab:green", 2: "tab:orange", 3: "tab:purple"}
    sc = None
    for ax, f in zip(axes[0], floors):
        w = np.flatnonzero(wall_floor == f)
        if len(w):
            segs = [
                [(site.wall_x0_m[i], site.wall_y0_m[i]), (site.wall_x1_m[i], site.wall_y1_m[i])] for i in w
            ]
            ax.add_collection(LineCollection(segs, colors="0.35", linewidths=0.8, zorder=1))
            ax.autoscale()
        sel = rp_floor == f
        sc = ax.scatter(
            np.asarray(site.rp_x_m)[sel],
            np.asarray(site.rp_y_m)[sel],
            c=n_aps[sel],
            cmap="viridis",
            vmin=0,
            vmax=vmax,
            s=14,
            zorder=2,
        )
        for i in np.flatnonzero(beacon_floor == f):
            x, y = site.beacon_x_m[i], site.beacon_y_m[i]
            ax.plot(x, y, "^", color="tab:red", ms=8, zorder=3)
            ax.annotate(
                f"{site.beacon_id[i] & 0xFFFF:04x}",
                (x, y),
                fontsize=7,
                xytext=(3, 3),
                textcoords="offset points",
            )
        for k in range(site.n_ports):
            if site.port_floor_lo[k] <= f <= site.port_floor_hi[k]:
                ax.add_patch(
                    Circle(
                        (site.port_x_m[k], site.port_y_m[k]),
                        site.port_radius_m[k],
                        fill=False,
                        color=port_colours.get(site.port_kind[k], "k"),
                        lw=1.5,
                        zorder=3,
                    )
                )
        for name, vertices in _outlines(site):
            ax.add_patch(
                Polygon(vertices, closed=True, fill=False, ls="--", color="tab:blue", lw=1.2, zorder=1)
            )
            ax.annotate(name, vertices[0], fontsize=8, color="tab:blue")
            ax.autoscale()
        ax.set_title(
            f"floor {f}: {int(sel.sum())} RPs, {len(w)} walls, {int(np.sum(beacon_floor == f))} beacons"
        )
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    if sc is not None:
        fig.colorbar(sc, ax=list(axes[0]), label="APs heard at RP")
    fig.suptitle(site.name or "site")
    os.makedirs(os.path.dirname(os.path.abspath(png_path)), exist_ok=True)
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
