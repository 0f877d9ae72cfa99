"""The figures of ``stridefix-lab bench controller`` that need no firmware: true contexts, transition
latencies, false switches, per-context errors (Jäger, Süß, Becker §III-C).

Contexts are named by keys: ``"outdoor"``, ``"<building>/<floor>"`` (a floor context, e.g. ``"A/1"``)
and ``"<building>"`` (a building context: the building on any floor). The truth's context at a sample
is the building whose outline holds its (x, y) — with the truth's floor — or ``"outdoor"`` outside
every outline (:func:`truth_contexts`); the controller's is the context its CONTEXT message names
(:func:`controller_keys`, building index → name from the site).

* latency of a truth transition (the walker's crossing at ``t_us``, from the simulator's summary):
  from the crossing to the first CONTEXT with ``switched`` into a context that holds the truth's new
  one (:func:`context_holds`), searched from ``SWITCH_TOLERANCE_S`` before the crossing (not before
  the previous transition) to :data:`MISS_AFTER_S` after it (not past the next one); none: missed;
* a switch is false when the truth is in none of the switched-into context's samples within
  ±:data:`SWITCH_TOLERANCE_S` of it, or when another switch came after the same truth transition
  (two switches with no truth transition between them: the second is false).

Everything is vectorised over the samples; cost O(n_truth · n_vertices + n_switches · n_truth).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from stridefix import context_t

#: a switch up to this long before / after the truth's crossing is not false (and counts as a
#: detection); the issue's "within ±5 s" of a switch [s]
SWITCH_TOLERANCE_S = 5.0
#: a transition with no switch into its new context this long after the crossing is missed [s]
MISS_AFTER_S = 30.0
#: the issue's target: every transition detected within this long [s]
LATENCY_TARGET_S = 5.0
OUTDOOR = "outdoor"

Array = npt.NDArray[Any]


class TransitionsError(ValueError):
    """The simulator's summary lists transitions the bench cannot read; the message names the field."""


@dataclasses.dataclass(frozen=True)
class Outline:
    """One building: its name and outline polygon in the map frame [m], shape (n, 2), n ≥ 3."""

    name: str
    polygon: Array


@dataclasses.dataclass(frozen=True)
class Transition:
    """A context change the walker made: the crossing time [µs, board time], the port kind (door,
    stairs, elevator) and the context keys before and after."""

    t_us: int
    kind: str
    src: str
    dst: str


def floor_key(building: str, floor: int) -> str:
    """The key of floor ``floor`` of building ``building``."""
    return f"{building}/{int(floor)}"


def inside_polygon(polygon: Array, x_m: Array, y_m: Array) -> Array:
    """Boolean (n,): the points lie inside ``polygon`` (even-odd rule; closed implicitly)."""
    px, py = np.asarray(polygon, float)[:, 0], np.asarray(polygon, float)[:, 1]
    x, y = np.asarray(x_m, float)[:, None], np.asarray(y_m, float)[:, None]
    x0, y0, x1, y1 = px, py, np.roll(px, -1), np.roll(py, -1)
    straddles = (y0 > y) != (y1 > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        x_cross = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
    hits = straddles & (x < x_cross)
    return np.asarray(np.count_nonzero(hits, axis=1) % 2 == 1)


def truth_contexts(x_m: Array, y_m: Array, floor: Array, outlines: Sequence[Outline]) -> Array:
    """The truth's context key per sample (object array, shape (n,)): the first outline holding the
    point with its floor, else :data:`OUTDOOR`."""
    x, y, f = np.asarray(x_m, float), np.asarray(y_m, float), np.asarray(floor, np.int64)
    out = np.full(x.shape, OUTDOOR, dtype=object)
    free = np.ones(x.shape, bool)
    for o in outlines:
        hit = free & inside_polygon(o.polygon, x, y)
        out[hit] = [floor_key(o.name, int(v)) for v in f[hit]]
        free &= ~hit
    return out


def context_holds(ctl: str, truth: str) -> bool:
    """True when the controller's context ``ctl`` holds the truth's context ``truth`` (the same key,
    or ``ctl`` is the building of the floor ``truth``)."""
    return ctl == truth or (ctl != OUTDOOR and "/" not in ctl and truth.startswith(ctl + "/"))


def controller_keys(kind: Array, building: Array, floor: Array, building_names: Sequence[str]) -> list[str]:
    """The context key of each CONTEXT message (``""`` for none yet)."""
    keys = []
    for k, b, f in zip(np.asarray(kind), np.asarray(building), np.asarray(floor), strict=True):
        name = building_names[int(b)] if 0 <= int(b) < len(building_names) else f"building {int(b)}"
        if int(k) == context_t.KIND_OUTDOOR:
            keys.append(OUTDOOR)
        elif int(k) == context_t.KIND_BUILDING:
            keys.append(name)
        elif int(k) == context_t.KIND_FLOOR:
            keys.append(floor_key(name, int(f)))
        else:
            keys.append("")
    return keys


# --- the simulator's transitions -------------------------------------------------------------------


def _context_key(c: Any, contexts: Sequence[Any], where: str) -> str:
    """A context of the summary (an index into ``contexts``, a {kind, building, floor} mapping, a
    [kind, building, floor] list, or a key) as a key."""
    if isinstance(c, bool):
        raise TransitionsError(f"{where}: a context, not {c!r}")
    if isinstance(c, int):
        if not 0 <= c < len(contexts):
            raise TransitionsError(f"{where}: context index {c} not in 0..{len(contexts) - 1}")
        return _context_key(contexts[c], (), where)
    if isinstance(c, str):
        return c
    if isinstance(c, Mapping):
        kind, building, floor = c.get("kind"), c.get("building"), c.get("floor")
    elif isinstance(c, Sequence) and len(c) == 3:
        kind, building, floor = c
    else:
        raise TransitionsError(f"{where}: context {c!r} is not (kind, building, floor)")
    if kind == "outdoor":
        return OUTDOOR
    if kind == "building" and building is not None:
        return str(building)
    if kind == "floor" and building is not None and floor is not None:
        return floor_key(str(building), int(floor))
    raise TransitionsError(f"{where}: context {c!r}: kind must be outdoor, building or floor")


def sim_transitions(summary: Mapping[str, Any]) -> list[Transition]:
    """The walk's transitions from ``sim_summary.json`` (``transitions``: kind, from, to and the
    crossing time ``t_us`` — board time — or ``t_s`` since the simulation's start, which the board's
    ``board_time_start_ms`` turns into board time), in time order. Raises :class:`TransitionsError`."""
    rows = summary.get("transitions")
    if not isinstance(rows, list):
        raise TransitionsError("sim_summary.json: no 'transitions' list (a world without contexts?)")
    contexts = summary.get("contexts") or []
    start_us = int(summary.get("board_time_start_ms", 0)) * 1000
    out = []
    for i, r in enumerate(rows):
        where = f"sim_summary.json: transitions[{i}]"
        if not isinstance(r, Mapping):
            raise TransitionsError(f"{where}: not a table")
        if "t_us" in r:
            t_us = int(r["t_us"])
        elif "t_s" in r:
            t_us = start_us + int(round(float(r["t_s"]) * 1e6))
        else:
            raise TransitionsError(f"{where}: no t_us (or t_s)")
        src = _context_key(r.get("from", r.get("src")), contexts, f"{where}.from")
        dst = _context_key(r.get("to", r.get("dst")), contexts, f"{where}.to")
        out.append(Transition(t_us, str(r.get("kind", "")), src, dst))
    return sorted(out, key=lambda tr: tr.t_us)


def truth_transitions(t_us: Array, keys: Array) -> list[Transition]:
    """The context changes of a truth timeline (the sample where the key changes; kind ``truth``: the
    timeline does not say which port)."""
    k = np.asarray(keys, dtype=object)
    change = np.flatnonzero(k[1:] != k[:-1]) + 1
    return [Transition(int(t_us[i]), "truth", str(k[i - 1]), str(k[i])) for i in change]


# --- latency and false switches ----------------------------------------------------------------------


def latencies(
    transitions: Sequence[Transition], sw_t_us: Array, sw_keys: Sequence[str]
) -> list[dict[str, Any]]:
    """Per transition: its figures and the latency [s] to the first switch into its new context
    (None: missed; see the module docstring). ``sw_*``: the switches (switched CONTEXT messages)."""
    t = np.asarray(sw_t_us, np.int64)
    out = []
    for i, tr in enumerate(transitions):
        lo = tr.t_us - int(SWITCH_TOLERANCE_S * 1e6)
        if i > 0:
            lo = max(lo, transitions[i - 1].t_us)
        hi = tr.t_us + int(MISS_AFTER_S * 1e6)
        if i + 1 < len(transitions):
            hi = min(hi, transitions[i + 1].t_us)
        hit = [j for j in range(len(t)) if lo <= t[j] < hi and context_holds(sw_keys[j], tr.dst)]
        lat = (int(t[hit[0]]) - tr.t_us) / 1e6 if hit else None
        out.append(
            {
                "t_us": tr.t_us,
                "kind": tr.kind,
                "from": tr.src,
                "to": tr.dst,
                "latency_s": lat,
                "detected": lat is not None,
                "within_target": lat is not None and lat <= LATENCY_TARGET_S,
            }
        )
    return out


def false_switches(
    transitions: Sequence[Transition],
    sw_t_us: Array,
    sw_keys: Sequence[str],
    truth_t_us: Array,
    truth_keys: Array,
    sw_rules: Sequence[str] | None = None,
) -> list[dict[str, Any]]:
    """Every switch with its verdict: ``false`` and ``why`` (``wrong context``: the truth is not in it
    within ±:data:`SWITCH_TOLERANCE_S`; ``no transition``: an earlier switch already followed the
    same truth transition, or none happened yet and this is not the first; a wrong switch does not
    count as following one)."""
    tt, tk = np.asarray(truth_t_us, np.int64), np.asarray(truth_keys, dtype=object)
    tol = int(SWITCH_TOLERANCE_S * 1e6)
    crossings = np.asarray([tr.t_us for tr in transitions], np.int64)
    seen_bins: set[int] = set()
    out = []
    for j, (t, key) in enumerate(zip(np.asarray(sw_t_us, np.int64), sw_keys, strict=True)):
        near = np.flatnonzero(np.abs(tt - t) <= tol)
        if near.size == 0 and tt.size:
            near = np.array([int(np.argmin(np.abs(tt - t)))])
        wrong = not any(context_holds(key, str(tk[i])) for i in near)
        b = int(np.count_nonzero(crossings - tol <= t))  # the truth transitions this switch may follow
        repeat = b in seen_bins
        if not wrong:  # a wrong switch does not use up the transition: the next one may correct it
            seen_bins.add(b)
        why = "wrong context" if wrong else ("no transition" if repeat else None)
        out.append(
            {
                "t_us": int(t),
                "to": key,
                "rule": None if sw_rules is None else sw_rules[j],
                "false": why is not None,
                "why": why,
            }
        )
    return out


def errors_by_context(keys: Array, error_m: Array) -> dict[str, list[float]]:
    """Finite errors [m] grouped by the truth's context key, plus ``"whole walk"``."""
    e = np.asarray(error_m, float)
    k = np.asarray(keys, dtype=object)
    ok = np.isfinite(e)
    out = {str(c): e[ok & (k == c)].tolist() for c in sorted({str(v) for v in k[ok]})}
    out["whole walk"] = e[ok].tolist()
    return out


def timeline(t_us: Array, keys: Array) -> list[tuple[int, int, str]]:
    """Runs of equal keys as (start µs, end µs, key): the truth's context timeline."""
    k = np.asarray(keys, dtype=object)
    t = np.asarray(t_us, np.int64)
    if t.size == 0:
        return []
    starts = np.concatenate([[0], np.flatnonzero(k[1:] != k[:-1]) + 1])
    ends = np.append(starts[1:], t.size - 1)
    return [(int(t[s]), int(t[e]), str(k[s])) for s, e in zip(starts, ends, strict=True)]
