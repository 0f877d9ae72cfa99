"""The site file's version-3 content: the multi-scheme controller's positioning context map
(buildings and outlines, per-port extras, port links, contexts, constellations; ``site_t.lcm``).

:func:`fill_port_defaults` gives ports built without the controller's extras the neutral ones, so a
site without a context map encodes (every per-port array must hold ``n_ports`` values)."""

from __future__ import annotations

from stridefix import site_t


def fill_port_defaults(site: site_t) -> None:
    """Per-port extras for ports that have none: no building, not outdoor, no steps, endpoints at the
    centre (each array is filled only when it does not already hold ``n_ports`` values)."""
    n = site.n_ports
    neutral = {
        "port_building": [-1] * n,
        "port_outdoor": [0] * n,
        "port_steps": [0] * n,
        "port_lo_x_m": list(site.port_x_m),
        "port_lo_y_m": list(site.port_y_m),
        "port_hi_x_m": list(site.port_x_m),
        "port_hi_y_m": list(site.port_y_m),
    }
    for name, values in neutral.items():
        if len(getattr(site, name)) != n:
            setattr(site, name, values)
