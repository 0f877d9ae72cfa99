"""The fusion schemes, from their one source: the ``SCHEME_*`` constants of ``pose_t.lcm``.

Ids, names and report order come from the generated LCM binding (``stridefix.pose_t``); the only
thing Python adds per scheme is its colour in plots and reports (one row in :data:`_COLOURS`). A
scheme added to ``pose_t.lcm`` appears here by itself (with a fallback colour until it gets a row).
"""

from __future__ import annotations

import dataclasses

from stridefix import pose_t

# Report colour per scheme name: matplotlib's tab10 in id order, so plots keep the colours they had.
_COLOURS = {
    "pdr_only": "#1f77b4",
    "wifi_only": "#ff7f0e",
    "overwrite": "#2ca02c",
    "static": "#d62728",
    "adaptive": "#9467bd",
    "kalman": "#8c564b",
    "ekf": "#e377c2",
    # not tab10's grey (#7f7f7f): the particle filter's track runs along the floor plan's grey walls
    "particle": "#17becf",
    "controller": "#bcbd22",
}
# a scheme without a row, until it gets one: colours no row above has
_FALLBACK_COLOURS = ("#7f7f7f", "#393b79", "#637939", "#843c39")


class UnknownSchemeError(ValueError):
    """A scheme name or id that ``pose_t.lcm`` does not define."""


@dataclasses.dataclass(frozen=True)
class Scheme:
    """One fusion scheme: ``id`` is ``pose_t.SCHEME_<NAME>``, ``name`` its lower-case name."""

    id: int
    name: str
    colour: str


def _from_lcm() -> tuple[Scheme, ...]:
    consts = sorted(
        (int(v), k[len("SCHEME_") :].lower()) for k, v in vars(pose_t).items() if k.startswith("SCHEME_")
    )
    extra = iter(_FALLBACK_COLOURS * (1 + len(consts)))
    return tuple(Scheme(i, n, _COLOURS.get(n) or next(extra)) for i, n in consts)


SCHEMES: tuple[Scheme, ...] = _from_lcm()
"""Every scheme, in id order (the report order)."""
NAMES: tuple[str, ...] = tuple(s.name for s in SCHEMES)
FUSION_SCHEMES: tuple[Scheme, ...] = tuple(s for s in SCHEMES if s.id < pose_t.SCHEME_CONTROLLER)
"""The fusion schemes: every scheme but the controller, which follows one (it judges no fix)."""
_BY_ID = {s.id: s for s in SCHEMES}
_BY_NAME = {s.name: s for s in SCHEMES}


def scheme_name(code: int) -> str:
    """The name of scheme id ``code`` (``scheme_<code>`` for an id the LCM type does not know)."""
    s = _BY_ID.get(int(code))
    return s.name if s else f"scheme_{int(code)}"


def scheme_code(name: str | int) -> int:
    """The id of a scheme given by name (``adaptive``) or number (``4``)."""
    if isinstance(name, str) and name in _BY_NAME:
        return _BY_NAME[name].id
    try:
        code = int(name)
    except ValueError:
        raise UnknownSchemeError(f"unknown scheme {name!r}; known: {list(NAMES)}") from None
    if code not in _BY_ID:
        raise UnknownSchemeError(f"unknown scheme {name!r}; known: {list(NAMES)}")
    return code


def scheme_colour(code: int) -> str:
    """The report colour of scheme id ``code``."""
    s = _BY_ID.get(int(code))
    return s.colour if s else _FALLBACK_COLOURS[int(code) % len(_FALLBACK_COLOURS)]


PDR_ONLY: str = scheme_name(pose_t.SCHEME_PDR_ONLY)
"""The dead-reckoning baseline's name (its truth-initialised run is reported per data set)."""

CONTROLLER: str = scheme_name(pose_t.SCHEME_CONTROLLER)
"""The multi-scheme controller's primary pose: the pose of the fusion scheme its context selects."""

WIFI_ONLY: str = scheme_name(pose_t.SCHEME_WIFI_ONLY)
"""The Wi-Fi baseline's name (it follows Wi-Fi fixes only: the other sources are not its fixes)."""


def is_fused(name: str) -> bool:
    """Whether the scheme ``name`` fuses steps with fixes: every scheme but the two baselines
    (``pdr_only`` takes no fix, ``wifi_only`` no step) and the controller, which follows one."""
    return name not in (PDR_ONLY, WIFI_ONLY, CONTROLLER)
