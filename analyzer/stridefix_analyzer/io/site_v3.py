"""The site file's version-3 content: the multi-scheme controller's positioning context map
(buildings and outlines, per-port extras, port links, contexts, constellations; ``site_t.lcm``,
Jäger, Süß, Becker §III-C).

:func:`stridefix_analyzer.io.sitefile.validate_site` calls :func:`validate_contexts` after the
version-2 rules; ``firmware/board/sf_site_v3.c`` applies the same rules in the same order with the
same words. Rules, in order (every array's length equal to its count first, :data:`V3_ARRAYS`):

* outlines: each vertex's building in 0 … n_buildings−1, a finite position, each building's vertices
  consecutive; then each building has at least 3 vertices;
* port extras: ``port_building`` in −1 … n_buildings−1, ``port_outdoor`` 0 or 1, ``port_steps`` ≥ 0
  (and > 0 for stairs when the site has contexts: the controller's stairs rule counts them; a site
  without contexts keeps :func:`fill_port_defaults`' neutral 0; 0 for doors and elevators, which the
  controller refuses otherwise), finite endpoints;
* links: both ports in range, not one port linked with itself;
* contexts: kind one of ``CONTEXT_*``; building −1 for the outdoor context, in range for the others;
  floor within the site's floors; scheme a fusion scheme (0 … ``pose_t.SCHEME_CONTROLLER`` − 1);
  method and cdd_method one of ``fix_t.METHOD_WIFI``/``_GNSS``/``_BLE``; ``cdd_min_hits`` ≥ 1; at most
  one outdoor context; at most one context per (kind, building, floor);
* constellations: context in range and non-decreasing, id in 0 … 2⁴⁸−1, finite ``cdd_min_dbm``; a
  context recognised by GNSS has no members.

:func:`fill_port_defaults` gives ports built without the controller's extras the neutral ones, so a
site without a context map encodes (every per-port array must hold ``n_ports`` values).
Cost O(n_outline + n_ports + n_links + n_contexts² + n_cdd) (n_contexts is a handful).
"""

from __future__ import annotations

import numpy as np
from stridefix import fix_t, pose_t, site_t

from stridefix_analyzer.io.site_v2 import PORT_KINDS, SiteV2ValidationError, check_len, finite

#: The version-3 fields of ``site_t``: each count with its arrays (the per-port extras under
#: ``n_ports``, which the version-2 table counts from ``port_kind``). The one list the checks, the
#: empty content, the counts and the test vectors (tests/vectors/gen_site_vectors.py) read.
V3_ARRAYS = {
    "n_buildings": ("building_name",),
    "n_outline": ("outline_x_m", "outline_y_m", "outline_building"),
    "n_ports": (
        "port_building",
        "port_outdoor",
        "port_steps",
        "port_lo_x_m",
        "port_lo_y_m",
        "port_hi_x_m",
        "port_hi_y_m",
    ),
    "n_links": ("link_a", "link_b"),
    "n_contexts": (
        "context_kind",
        "context_building",
        "context_floor",
        "context_scheme",
        "context_method",
        "context_cdd_method",
        "context_cdd_min_hits",
    ),
    "n_cdd": ("cdd_context", "cdd_id", "cdd_min_dbm"),
}
#: Context kinds (``site_t.CONTEXT_*``) and their names in building descriptions and summaries.
CONTEXT_KINDS = {
    site_t.CONTEXT_OUTDOOR: "outdoor",
    site_t.CONTEXT_BUILDING: "building",
    site_t.CONTEXT_FLOOR: "floor",
}
#: The absolute methods a context's scheme fuses and its CLS recognises it by (``fix_t.METHOD_*``).
CONTEXT_METHODS = {fix_t.METHOD_WIFI: "wifi", fix_t.METHOD_GNSS: "gnss", fix_t.METHOD_BLE: "ble"}
_METHOD_TEXT = "wifi (1), gnss (2) or ble (4)"
ID_LIMIT = 1 << 48


class SiteV3ValidationError(SiteV2ValidationError):
    """A version-3 rule failure (sitefile re-raises it as SiteValidationError)."""


def _bad(text: str) -> SiteV3ValidationError:
    return SiteV3ValidationError(text)


def _validate_outlines(site: site_t, n_buildings: int) -> None:
    first_of: dict[int, int] = {}
    counts = [0] * n_buildings
    for i in range(site.n_outline):
        b, x, y = site.outline_building[i], site.outline_x_m[i], site.outline_y_m[i]
        if not 0 <= b < n_buildings:
            raise _bad(f"outline vertex {i}: building {b} outside 0..{n_buildings - 1}")
        if not finite(x, y):
            raise _bad(f"outline vertex {i}: position ({x:g}, {y:g}) not finite")
        prev = site.outline_building[i - 1] if i > 0 else -1
        if b != prev and b in first_of:
            raise _bad(
                f"outline vertex {i}: building {b}'s vertices not consecutive (its first is vertex {first_of[b]})"
            )
        first_of.setdefault(b, i)
        counts[b] += 1
    for b, n in enumerate(counts):
        if n < 3:
            raise _bad(f"building {b}: {n} outline vertices, needs at least 3")


def _validate_port_extras(site: site_t, n_buildings: int) -> None:
    for i in range(site.n_ports):
        b, out, steps = site.port_building[i], site.port_outdoor[i], site.port_steps[i]
        if not -1 <= b < n_buildings:
            raise _bad(f"port {i}: port_building {b} outside -1..{n_buildings - 1}")
        if out not in (0, 1):
            raise _bad(f"port {i}: port_outdoor {out} is not 0 or 1")
        if steps < 0:
            raise _bad(f"port {i}: port_steps {steps} is negative")
        if steps == 0 and site.port_kind[i] == site_t.PORT_STAIRS and site.n_contexts > 0:
            raise _bad(
                f"port {i}: stairs with port_steps 0 (a staircase needs its step count when the site has contexts)"
            )
        if steps != 0 and site.port_kind[i] != site_t.PORT_STAIRS:
            raise _bad(
                f"port {i}: a {PORT_KINDS.get(site.port_kind[i], 'port')} with port_steps {steps} "
                f"(steps are a staircase's: 0 for doors and elevators)"
            )
        lx, ly, hx, hy = site.port_lo_x_m[i], site.port_lo_y_m[i], site.port_hi_x_m[i], site.port_hi_y_m[i]
        if not finite(lx, ly, hx, hy):
            raise _bad(f"port {i}: endpoints ({lx:g}, {ly:g}) - ({hx:g}, {hy:g}) not finite")


def _validate_links(site: site_t) -> None:
    for i in range(site.n_links):
        a, b = site.link_a[i], site.link_b[i]
        for p in (a, b):
            if not 0 <= p < site.n_ports:
                raise _bad(f"link {i}: port {p} outside 0..{site.n_ports - 1}")
        if a == b:
            raise _bad(f"link {i}: links port {a} with itself")


def _validate_context_rows(site: site_t, n_buildings: int, lowest: int, top: int) -> None:
    seen: dict[tuple[int, int, int], int] = {}
    outdoor = -1
    for i in range(site.n_contexts):
        kind, b, f = site.context_kind[i], site.context_building[i], site.context_floor[i]
        scheme, method = site.context_scheme[i], site.context_method[i]
        cdd_method, hits = site.context_cdd_method[i], site.context_cdd_min_hits[i]
        if kind not in CONTEXT_KINDS:
            raise _bad(f"context {i}: kind {kind} unknown (1 outdoor, 2 building, 3 floor)")
        if kind == site_t.CONTEXT_OUTDOOR and b != -1:
            raise _bad(f"context {i}: an outdoor context has building {b}, must be -1")
        if kind != site_t.CONTEXT_OUTDOOR and not 0 <= b < n_buildings:
            raise _bad(f"context {i}: building {b} outside 0..{n_buildings - 1}")
        if not lowest <= f <= top:
            raise _bad(f"context {i}: floor {f} outside {lowest}..{top}")
        if not 0 <= scheme < pose_t.SCHEME_CONTROLLER:
            raise _bad(
                f"context {i}: scheme {scheme} is not a fusion scheme (0..{pose_t.SCHEME_CONTROLLER - 1})"
            )
        if method not in CONTEXT_METHODS:
            raise _bad(f"context {i}: method {method} is not {_METHOD_TEXT}")
        if cdd_method not in CONTEXT_METHODS:
            raise _bad(f"context {i}: cdd_method {cdd_method} is not {_METHOD_TEXT}")
        if hits < 1:
            raise _bad(f"context {i}: cdd_min_hits {hits}, must be >= 1")
        if kind == site_t.CONTEXT_OUTDOOR:
            if outdoor >= 0:
                raise _bad(f"context {i}: a second outdoor context (context {outdoor} is one)")
            outdoor = i
        key = (kind, b, f)
        if key in seen:
            raise _bad(f"context {i}: kind {kind}, building {b}, floor {f} already context {seen[key]}")
        seen[key] = i


def _cdd_pass(site: site_t) -> bool:
    """Whether every cdd row keeps the rules of :func:`_validate_cdd`, checked at once with numpy;
    False (or anything numpy cannot hold) sends the per-row loop, which names the first one broken."""
    try:
        c = np.asarray(site.cdd_context, np.int64)
        ident, dbm = np.asarray(site.cdd_id, np.int64), np.asarray(site.cdd_min_dbm, float)
        method = np.asarray(site.context_cdd_method, np.int64)
        if not (len(c) == len(ident) == len(dbm) == site.n_cdd and np.all((c >= 0) & (c < site.n_contexts))):
            return False
        return bool(
            len(method) >= site.n_contexts
            and np.all(c[1:] >= c[:-1])
            and np.all((ident >= 0) & (ident < ID_LIMIT))
            and np.all(np.isfinite(dbm))
            and not np.any(method[c] == fix_t.METHOD_GNSS)
        )
    except (TypeError, ValueError, OverflowError, IndexError):
        return False


def _validate_cdd(site: site_t) -> None:
    for i in range(0 if _cdd_pass(site) else site.n_cdd):
        c, ident, dbm = site.cdd_context[i], site.cdd_id[i], site.cdd_min_dbm[i]
        if not 0 <= c < site.n_contexts:
            raise _bad(f"cdd {i}: context {c} outside 0..{site.n_contexts - 1}")
        if i > 0 and c < site.cdd_context[i - 1]:
            raise _bad(
                f"cdd {i}: context {c} below cdd {i - 1}'s {site.cdd_context[i - 1]} (must be non-decreasing)"
            )
        if not 0 <= ident < ID_LIMIT:
            raise _bad(f"cdd {i}: id {ident} outside 0..2^48-1")
        if not finite(dbm):
            raise _bad(f"cdd {i}: cdd_min_dbm is {dbm:g}, must be finite")
        if site.context_cdd_method[c] == fix_t.METHOD_GNSS:
            raise _bad(f"cdd {i}: context {c} is recognised by GNSS and has no constellation")


def validate_contexts(site: site_t, lowest: int, top: int) -> None:
    """The version-3 rules of the module docstring against the floors ``lowest`` … ``top``; raise
    :class:`SiteV3ValidationError` on the first broken, naming the field and index."""
    n_buildings = 0
    for count, arrays in V3_ARRAYS.items():
        n = check_len(site, count, *arrays, error=SiteV3ValidationError)
        n_buildings = n if count == "n_buildings" else n_buildings
    _validate_outlines(site, n_buildings)
    _validate_port_extras(site, n_buildings)
    _validate_links(site)
    _validate_context_rows(site, n_buildings, lowest, top)
    _validate_cdd(site)


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


def init_v3_fields(s: site_t) -> None:
    """Empty version-3 content: no buildings, outlines, per-port extras, links, contexts or members."""
    for arrays in V3_ARRAYS.values():
        for name in arrays:
            setattr(s, name, [])


def set_v3_counts(s: site_t) -> None:
    """Each version-3 count from its first array (``n_ports`` stays the version-2 table's)."""
    for count, arrays in V3_ARRAYS.items():
        if count != "n_ports":
            setattr(s, count, len(getattr(s, arrays[0])))
