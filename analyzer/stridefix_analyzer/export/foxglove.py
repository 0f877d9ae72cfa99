"""Foxglove's message types as JSON schemas, and StrideFix messages in them.

Foxglove recognises a channel's type by its schema *name* (``foxglove.PoseInFrame``, ...) and reads
JSON-encoded messages against the fields of its published schemas; the schemas here are written from
those field lists (timestamps as ``{sec, nsec}``, colours 0…1 RGBA), for the types an export uses:

* ``foxglove.PoseInFrame``: a pose in the ``map`` frame (z = the floor's height above the origin);
* ``foxglove.LocationFix``: a pose in latitude/longitude for the Map panel (needs the site's
  geo-reference), its horizontal covariance turned from the map frame into east-north;
* ``foxglove.SceneUpdate``: the floor plan, one entity per floor with the walls as a line list.

Any other LCM channel goes out as JSON with a schema named after its LCM type (``stridefix.fix_t``)
whose properties are the analyzer's columns of that type (:mod:`stridefix_analyzer.io.channels`); a
NaN, which JSON cannot hold, is ``null``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

#: the frame every StrideFix position is in
FRAME = "map"
LINE_LIST = 2  # foxglove.LinePrimitive type: each pair of points is one segment
COVARIANCE_KNOWN = 3  # foxglove.PositionCovarianceType

_NUMBER = {"type": "number"}
_TIME = {
    "type": "object",
    "title": "time",
    "properties": {
        "sec": {"type": "integer", "minimum": 0},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999},
    },
}
_DURATION = {
    "type": "object",
    "title": "duration",
    "properties": {
        "sec": {"type": "integer"},
        "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999},
    },
}


def _object(title: str, fields: Mapping[str, Any]) -> dict[str, Any]:
    return {"title": title, "type": "object", "properties": dict(fields), "required": list(fields)}


def _array(items: Any, n: int | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {"type": "array", "items": items}
    if n is not None:
        out.update(minItems=n, maxItems=n)
    return out


_VECTOR3 = _object("foxglove.Vector3", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER})
_POINT3 = _object("foxglove.Point3", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER})
_QUATERNION = _object("foxglove.Quaternion", {"x": _NUMBER, "y": _NUMBER, "z": _NUMBER, "w": _NUMBER})
_POSE = _object("foxglove.Pose", {"position": _VECTOR3, "orientation": _QUATERNION})
_COLOR = _object("foxglove.Color", {"r": _NUMBER, "g": _NUMBER, "b": _NUMBER, "a": _NUMBER})
_KEY_VALUE = _object("foxglove.KeyValuePair", {"key": {"type": "string"}, "value": {"type": "string"}})
_LINE = _object(
    "foxglove.LinePrimitive",
    {
        "type": {"type": "integer", "minimum": 0, "maximum": 2},
        "pose": _POSE,
        "thickness": _NUMBER,
        "scale_invariant": {"type": "boolean"},
        "points": _array(_POINT3),
        "color": _COLOR,
        "colors": _array(_COLOR),
        "indices": _array({"type": "integer", "minimum": 0}),
    },
)
_ANY_OBJECT = {"type": "object"}
_ENTITY = _object(
    "foxglove.SceneEntity",
    {
        "timestamp": _TIME,
        "frame_id": {"type": "string"},
        "id": {"type": "string"},
        "lifetime": _DURATION,
        "frame_locked": {"type": "boolean"},
        "metadata": _array(_KEY_VALUE),
        **{kind: _array(_ANY_OBJECT) for kind in ("arrows", "cubes", "spheres", "cylinders")},
        "lines": _array(_LINE),
        **{kind: _array(_ANY_OBJECT) for kind in ("triangles", "texts", "models")},
    },
)
_DELETION = _object(
    "foxglove.SceneEntityDeletion",
    {"timestamp": _TIME, "type": {"type": "integer", "minimum": 0, "maximum": 1}, "id": {"type": "string"}},
)

#: Foxglove schema name → its JSON schema
SCHEMAS: dict[str, dict[str, Any]] = {
    "foxglove.PoseInFrame": _object(
        "foxglove.PoseInFrame", {"timestamp": _TIME, "frame_id": {"type": "string"}, "pose": _POSE}
    ),
    "foxglove.LocationFix": _object(
        "foxglove.LocationFix",
        {
            "timestamp": _TIME,
            "frame_id": {"type": "string"},
            "latitude": _NUMBER,
            "longitude": _NUMBER,
            "altitude": _NUMBER,
            "position_covariance": _array(_NUMBER, 9),
            "position_covariance_type": {"type": "integer", "minimum": 0, "maximum": 3},
        },
    ),
    "foxglove.SceneUpdate": _object(
        "foxglove.SceneUpdate", {"deletions": _array(_DELETION), "entities": _array(_ENTITY)}
    ),
}

_JSON_TYPES = {bool: "boolean", str: "string", np.int64: "integer", np.float64: "number"}


def lcm_schema(type_name: str, columns: Mapping[str, type]) -> dict[str, Any]:
    """The JSON schema of an LCM type's messages: ``timestamp`` and one property per column."""
    props: dict[str, Any] = {"timestamp": _TIME}
    for name, dtype in columns.items():
        kind = _JSON_TYPES.get(dtype, "number")
        props[name] = {"type": [kind, "null"]} if kind == "number" else {"type": kind}
    return {"title": type_name, "type": "object", "properties": props}


def stamp(t_ns: int) -> dict[str, int]:
    """A Foxglove time from nanoseconds."""
    return {"sec": int(t_ns // 1_000_000_000), "nsec": int(t_ns % 1_000_000_000)}


def _plain(value: Any) -> Any:
    """A numpy scalar as a JSON value (NaN and ±inf as null)."""
    v = value.item() if isinstance(value, np.generic) else value
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def lcm_message(t_ns: int, row: Mapping[str, Any]) -> dict[str, Any]:
    """One LCM message (column → value) as JSON for :func:`lcm_schema`."""
    return {"timestamp": stamp(t_ns), **{k: _plain(v) for k, v in row.items()}}


def pose_in_frame(t_ns: int, x_m: float, y_m: float, z_m: float, heading_rad: float) -> dict[str, Any]:
    """A ``foxglove.PoseInFrame`` in the map frame: heading counter-clockwise from +x about +z."""
    half = 0.5 * float(heading_rad) if math.isfinite(heading_rad) else 0.0
    return {
        "timestamp": stamp(t_ns),
        "frame_id": FRAME,
        "pose": {
            "position": {"x": float(x_m), "y": float(y_m), "z": float(z_m)},
            "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(half), "w": math.cos(half)},
        },
    }


def location_fix(
    t_ns: int, lat_deg: float, lon_deg: float, alt_m: float, cov_en_m2: tuple[float, float, float]
) -> dict[str, Any]:
    """A ``foxglove.LocationFix``; ``cov_en_m2`` is the horizontal covariance (ee, en, nn) [m²]
    (the vertical part is left 0: the floor is not a measured height)."""
    ee, en, nn = (c if math.isfinite(c) else 0.0 for c in cov_en_m2)
    return {
        "timestamp": stamp(t_ns),
        "frame_id": FRAME,
        "latitude": float(lat_deg),
        "longitude": float(lon_deg),
        "altitude": float(alt_m),
        "position_covariance": [ee, en, 0.0, en, nn, 0.0, 0.0, 0.0, 0.0],
        "position_covariance_type": COVARIANCE_KNOWN,
    }


def floor_plan(
    t_ns: int, walls: Mapping[int, list[tuple[float, float, float, float]]], z_m: Mapping[int, float]
) -> dict[str, Any]:
    """A ``foxglove.SceneUpdate`` with one entity per floor (id ``floor N``) holding its walls
    (x0, y0, x1, y1) [m] as one line list at the floor's height ``z_m[floor]``."""
    entities = []
    for floor in sorted(walls):
        z = float(z_m[floor])
        points = []
        for x0, y0, x1, y1 in walls[floor]:
            points += [{"x": float(x0), "y": float(y0), "z": z}, {"x": float(x1), "y": float(y1), "z": z}]
        line = {
            "type": LINE_LIST,
            "pose": {
                "position": {"x": 0.0, "y": 0.0, "z": 0.0},
                "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
            },
            "thickness": 0.15,
            "scale_invariant": False,
            "points": points,
            "color": {"r": 0.35, "g": 0.35, "b": 0.4, "a": 1.0},
            "colors": [],
            "indices": [],
        }
        entities.append(
            {
                "timestamp": stamp(t_ns),
                "frame_id": FRAME,
                "id": f"floor {floor}",
                "lifetime": {"sec": 0, "nsec": 0},
                "frame_locked": False,
                "metadata": [{"key": "floor", "value": str(floor)}],
                "arrows": [],
                "cubes": [],
                "spheres": [],
                "cylinders": [],
                "lines": [line],
                "triangles": [],
                "texts": [],
                "models": [],
            }
        )
    return {"deletions": [], "entities": entities}
