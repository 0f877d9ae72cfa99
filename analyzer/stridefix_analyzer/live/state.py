"""What the live view shows, folded from the LCM messages as they arrive (no network, no clock).

:class:`LiveState` takes each decoded message (:meth:`LiveState.add`) and keeps, per scheme, the last
pose and its track (every :data:`TRACK_EVERY_S` of walk time, at most :data:`TRACK_MAX` points: a
long walk costs the page a fixed amount), the step count (STEP), the fix verdicts per scheme and
source (FIX: accepted, rejected by reason, and the last :data:`RECENT_FIXES` records), the last
HEALTH counters and CONTEXT, and the truth track when the log carries TRUTH. :meth:`snapshot` is the
JSON-ready document the page draws; ``version`` grows with every message so a client asks only
for what changed. POSE of any scheme goes to that scheme's track, whether it came on ``POSE`` or on
a per-scheme ``POSE_<SCHEME>`` channel; once a per-scheme channel is seen, ``POSE`` feeds no fusion
scheme's track (it carries copies then, which the analyzer leaves out too). The primary pose is the
one the firmware chose, as in ``analyze`` (:mod:`stridefix_analyzer.scoring.primary`): the ``POSE``
channel's latest once per-scheme channels are seen (POSE then carries the primary only); in a log
that carries every scheme on POSE, the latest of the scheme first in the analyzer's fallback order
(:func:`~stridefix_analyzer.scoring.primary.fallback_rank`; a live view cannot count messages still
to come).

Bad data is counted and skipped, never fatal: a message its type cannot decode (cut short, another
type's fingerprint, bad UTF-8) counts in ``bad_messages`` (:meth:`LiveState.fold`), and a NaN or
infinite value is held as ``None`` (JSON ``null``: the page shows "–"; a track point without a finite
position is left out), so the snapshot is always strict JSON (:func:`to_json`).
"""

from __future__ import annotations

import collections
import dataclasses
import json
import math
import struct
from typing import Any

from stridefix import pose_t

from stridefix_analyzer.io.channels import CHANNELS, POSE, POSE_CHANNELS
from stridefix_analyzer.schemes import UnknownSchemeError, scheme_colour, scheme_name
from stridefix_analyzer.scoring.fixsources import method_name, reason_name
from stridefix_analyzer.scoring.primary import fallback_rank

TRACK_EVERY_S = 0.5
TRACK_MAX = 4000
RECENT_FIXES = 12
#: the truth track's key among the schemes' in a client's ``sent`` record
TRUTH_KEY = -1
SCHEME_CONTROLLER = pose_t.SCHEME_CONTROLLER
#: what LCM's generated decode raises on bytes that are not a message of its type
DECODE_ERRORS = (ValueError, IndexError, UnicodeDecodeError, struct.error)


@dataclasses.dataclass
class _Scheme:
    name: str
    colour: str
    last: dict[str, Any] = dataclasses.field(default_factory=dict)
    track: list[tuple[float, float, int]] = dataclasses.field(default_factory=list)
    last_track_t_us: int | None = None
    every_us: float = TRACK_EVERY_S * 1e6
    epoch: int = 0  # grows when the track is thinned: a client holding its points starts again
    poses: int = 0

    def append(self, t_us: int, x_m: float | None, y_m: float | None, floor: int) -> None:
        """Keep a point every ``every_us`` of walk time; past TRACK_MAX points, every other one
        and twice the interval (a fixed cost for any walk length). No point without a position."""
        if x_m is None or y_m is None:
            return
        if self.last_track_t_us is not None and t_us - self.last_track_t_us < self.every_us:
            return
        self.track.append((round(x_m, 3), round(y_m, 3), floor))
        self.last_track_t_us = t_us
        if len(self.track) >= TRACK_MAX:
            self.track = self.track[::2]
            self.every_us *= 2
            self.epoch += 1


def _num(v: float) -> float | None:
    """``v`` as a float, ``None`` when it is NaN or infinite (JSON has neither)."""
    f = float(v)
    return f if math.isfinite(f) else None


def _pose_fields(m: Any) -> dict[str, Any]:
    return {
        "t_us": int(m.t_us),
        "x_m": _num(m.x_m),
        "y_m": _num(m.y_m),
        "floor": int(m.floor),
        "heading_rad": _num(m.heading_rad),
        "sigma_m": _num(m.sigma_m),
        "step_count": int(m.step_count),
    }


class LiveState:
    """The folded view (module docstring); ``walls`` are the site's [(x0, y0, x1, y1, floor)],
    ``ports`` its doors, stairs and elevators [{kind, x_m, y_m, radius_m, floor_lo, floor_hi}]."""

    def __init__(
        self,
        walls: list[tuple[float, float, float, float, int]] | None = None,
        source: str = "",
        ports: list[dict[str, Any]] | None = None,
    ) -> None:
        self.walls = walls or []
        self.ports = ports or []
        self.source = source
        self.version = 0
        self.bad_messages = 0  # undecodable messages, skipped
        self.messages: collections.Counter[str] = collections.Counter()
        self.schemes: dict[int, _Scheme] = {}
        self.primary: dict[str, Any] | None = None
        self.steps = 0
        self.fix_counts: dict[str, dict[str, dict[str, Any]]] = {}
        self.recent_fixes: collections.deque = collections.deque(maxlen=RECENT_FIXES)
        self.health: dict[str, Any] = {}
        self.context: dict[str, Any] | None = None
        self.truth = _Scheme("truth", "#000000")
        self.last_t_us: int | None = None
        self.ended = False
        self.per_scheme_channels = False  # POSE_<SCHEME> seen: POSE then carries the primary alone

    def _scheme(self, code: int) -> _Scheme:
        if code not in self.schemes:
            try:
                colour = scheme_colour(code)
            except UnknownSchemeError:
                colour = "#000000"
            self.schemes[code] = _Scheme(self._scheme_name(code), colour)
        return self.schemes[code]

    def fold(self, channel: str, data: bytes) -> bool:
        """Decode ``data`` with ``channel``'s type (the channel table) and fold it in; a message that
        does not decode is counted in ``bad_messages`` and skipped (False). A channel without a type
        is ignored (False)."""
        if channel not in CHANNELS:
            return False
        try:
            msg = CHANNELS[channel].msg_type.decode(data)
        except DECODE_ERRORS:
            self.bad_messages += 1
            self.version += 1
            return False
        self.add(channel, msg)
        return True

    def add(self, channel: str, msg: Any) -> None:
        """Fold one decoded message of ``channel`` into the view."""
        self.version += 1
        self.messages[channel] += 1
        t = getattr(msg, "t_us", None)
        if t is not None:
            self.last_t_us = int(t) if self.last_t_us is None else max(self.last_t_us, int(t))
        if channel in POSE_CHANNELS:
            self._pose(channel, msg)
        elif channel == "STEP":
            self.steps = max(self.steps, int(msg.index))  # step_t: the first step is 1
        elif channel == "FIX":
            self._fix(msg)
        elif channel == "HEALTH":
            self.health = {f: _plain(getattr(msg, f)) for f in msg.__slots__}
        elif channel == "CONTEXT":
            self.context = {f: _plain(getattr(msg, f)) for f in msg.__slots__}
        elif channel == "TRUTH":
            self.truth.append(int(msg.t_us), _num(msg.x_m), _num(msg.y_m), int(msg.floor))

    def _pose(self, channel: str, m: Any) -> None:
        code = int(m.scheme)
        p = _pose_fields(m)
        if channel != POSE and not self.per_scheme_channels:
            # the first per-scheme message: POSE carries the primary alone, and what it carried of
            # a fusion scheme was a copy (the analyzer leaves those out): that scheme starts afresh
            self.per_scheme_channels = True
            for c in [c for c in self.schemes if c != SCHEME_CONTROLLER]:
                del self.schemes[c]
        if channel != POSE or code == SCHEME_CONTROLLER or not self.per_scheme_channels:
            s = self._scheme(code)
            s.last, s.poses = p, s.poses + 1
            s.append(p["t_us"], p["x_m"], p["y_m"], p["floor"])
        if channel != POSE:
            return
        name = self._scheme_name(code)
        if self.per_scheme_channels or fallback_rank(name) <= fallback_rank(
            self.primary["scheme"] if self.primary else ""
        ):
            self.primary = {**p, "scheme": name}

    def _scheme_name(self, code: int) -> str:
        try:
            return scheme_name(code)
        except UnknownSchemeError:
            return f"scheme_{code}"

    def _fix(self, m: Any) -> None:
        scheme = self._scheme(int(m.scheme)).name
        method = method_name(int(m.method))
        c = self.fix_counts.setdefault(scheme, {}).setdefault(
            method, {"offered": 0, "accepted": 0, "rejected": 0, "rejected_by_reason": {}}
        )
        c["offered"] += 1
        if m.accepted:
            c["accepted"] += 1
        else:
            c["rejected"] += 1
            r = reason_name(int(m.reason))
            c["rejected_by_reason"][r] = c["rejected_by_reason"].get(r, 0) + 1
        self.recent_fixes.appendleft(
            {
                "t_us": int(m.t_us),
                "scheme": scheme,
                "method": method,
                "accepted": bool(m.accepted),
                "reason": reason_name(int(m.reason)),
                "test_ratio": _num(m.test_ratio),
                "alpha": _num(m.alpha),
            }
        )

    def snapshot(self, sent: dict[int, tuple[int, int]] | None = None) -> dict[str, Any]:
        """The JSON-ready document of the page (module docstring). ``sent`` (scheme code → (epoch,
        points) a client already holds) is updated in place and each track then carries only the
        points after those (``track_start``); a thinned track (new epoch) is sent whole."""
        sent = {} if sent is None else sent
        tracks = {}
        for c, s in [*self.schemes.items(), (TRUTH_KEY, self.truth)]:
            epoch, n = sent.get(c, (-1, 0))
            start = n if epoch == s.epoch else 0
            tracks[c] = (start, s.track[start:])
            sent[c] = (s.epoch, len(s.track))
        return {
            "version": self.version,
            "source": self.source,
            "ended": self.ended,
            "t_us": self.last_t_us,
            "messages": dict(self.messages),
            "bad_messages": self.bad_messages,
            "steps": self.steps,
            "primary": self.primary,
            "schemes": [
                {
                    "code": c,
                    "name": s.name,
                    "colour": s.colour,
                    "poses": s.poses,
                    "last": s.last,
                    "track_start": tracks[c][0],
                    "track": tracks[c][1],
                }
                for c, s in sorted(self.schemes.items())
            ],
            "fix_counts": self.fix_counts,
            "recent_fixes": list(self.recent_fixes),
            "health": self.health,
            "context": self.context,
            "truth": {"track_start": tracks[TRUTH_KEY][0], "track": tracks[TRUTH_KEY][1]},
            "walls": self.walls,
            "ports": self.ports,
        }


def to_json(doc: Any) -> str:
    """``doc`` (a snapshot) as strict JSON: any NaN or infinite float still in it becomes null."""
    try:
        return json.dumps(doc, allow_nan=False)
    except ValueError:  # a value folded without _num: still no NaN on the wire
        return json.dumps(_plain(doc), allow_nan=False)


def _plain(v: Any) -> Any:
    """``v`` JSON-ready: non-finite floats as None, sequences as lists, mappings with their keys,
    anything else as its text."""
    if isinstance(v, float):
        return _num(v)
    if isinstance(v, (bool, int, str)) or v is None:
        return v
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    return str(v)
