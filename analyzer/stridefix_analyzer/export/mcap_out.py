"""An MCAP file of a walk for Foxglove: poses, steps, fixes and the site's floor plan.

Topics are the LCM channel names, one MCAP message per LCM message of the log (JSON encoding, the
``mcap`` package's JSON-schema profile, :mod:`.foxglove` for the schemas):

==================  ===================================  ==========================================
topic               schema                               what
==================  ===================================  ==========================================
POSE, POSE_<S>      foxglove.PoseInFrame                 each pose in the ``map`` frame, z = floor
                                                         height above the origin [m]
POSE…/location      foxglove.LocationFix                 the same poses in latitude/longitude (only
                                                         with the site's geo-reference)
GNSS                foxglove.LocationFix                 the raw GNSS fixes, σ² on the diagonal
STEP, FIX, CONTEXT  stridefix.<type> (JSON schema of     every column of the analyzer's table of
                    the LCM type's columns)              that channel
/floorplan          foxglove.SceneUpdate                 one message: per floor the site's walls
==================  ===================================  ==========================================

Message times are ``start`` + the message's board time ``t_us`` (log and publish time alike);
messages are written in time order. A metadata record ``stridefix`` names the logs and the site.
"""

from __future__ import annotations

import datetime
import json
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from stridefix_analyzer.export import foxglove
from stridefix_analyzer.export.extra import need
from stridefix_analyzer.export.georef import GeoRef
from stridefix_analyzer.export.tracks import EPOCH, NoPoseError, read_channels
from stridefix_analyzer.io.channels import CHANNELS, POSE_CHANNELS, table_of
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.scoring.floor_height import FloorHeights

#: the channels written besides the pose channels, as LCM-typed JSON
LCM_TOPICS = ("STEP", "FIX", "CONTEXT")
GNSS = "GNSS"
FLOOR_PLAN_TOPIC = "/floorplan"
LOCATION_SUFFIX = "/location"


def _ns(t_us: np.ndarray, start: datetime.datetime) -> np.ndarray:
    base = int((start - EPOCH) / datetime.timedelta(microseconds=1))
    return np.maximum(np.asarray(t_us, dtype=np.int64) + base, 0) * 1000


def _rows(table: Table) -> list[dict[str, Any]]:
    cols = {n: table[n].tolist() for n in table.names}
    return [dict(zip(cols, values)) for values in zip(*cols.values())]


def _walls(site: Any) -> dict[int, list[tuple[float, float, float, float]]]:
    out: dict[int, list[tuple[float, float, float, float]]] = {}
    for i in range(int(site.n_walls)):
        wall = (site.wall_x0_m[i], site.wall_y0_m[i], site.wall_x1_m[i], site.wall_y1_m[i])
        out.setdefault(int(site.wall_floor[i]), []).append(wall)
    return out


class _Out:
    """The messages to write, per topic, before they are sorted by time."""

    def __init__(self) -> None:
        self.schemas: dict[str, dict[str, Any]] = {}
        self.topics: dict[str, str] = {}  # topic -> schema name
        self.messages: list[tuple[int, str, bytes]] = []  # (log time [ns], topic, JSON)

    def add(self, topic: str, schema: str, body: dict[str, Any], t_ns: int) -> None:
        self.topics.setdefault(topic, schema)
        self.messages.append((int(t_ns), topic, json.dumps(body, allow_nan=False).encode()))


def _poses(
    out: _Out, channel: str, table: Table, t_ns: np.ndarray, floors: FloorHeights, geo: GeoRef | None
) -> None:
    z = geo.height_m(table["floor"]) if geo else np.nan_to_num(floors.z_m(table["floor"]))
    for i, t in enumerate(t_ns):
        body = foxglove.pose_in_frame(t, table["x_m"][i], table["y_m"][i], z[i], table["heading_rad"][i])
        out.add(channel, "foxglove.PoseInFrame", body, t)
    if geo is None:
        return
    lat, lon = geo.to_latlon(table["x_m"], table["y_m"])
    alt = geo.altitude_m(table["floor"])
    # the covariance turned from the map frame into east-north: R C Rᵀ, R the map → east-north rotation
    c, s = np.cos(np.radians(geo.rotation_deg)), np.sin(np.radians(geo.rotation_deg))
    xx, xy, yy = (np.asarray(table[k], dtype=np.float64) for k in ("cov_xx_m2", "cov_xy_m2", "cov_yy_m2"))
    ee = c * c * xx - 2 * c * s * xy + s * s * yy
    en = c * s * (xx - yy) + (c * c - s * s) * xy
    nn = s * s * xx + 2 * c * s * xy + c * c * yy
    for i, t in enumerate(t_ns):
        body = foxglove.location_fix(t, lat[i], lon[i], alt[i], (ee[i], en[i], nn[i]))
        out.add(channel + LOCATION_SUFFIX, "foxglove.LocationFix", body, t)


def write_mcap(
    path: str | os.PathLike[str],
    logs: Sequence[str | os.PathLike[str]],
    site: Any,
    floors: FloorHeights,
    geo: GeoRef | None = None,
    start: datetime.datetime = EPOCH,
) -> dict[str, int]:
    """Write the MCAP of ``logs`` with ``site``'s floor plan (module docstring) to ``path``.

    ``floors`` gives the poses' z without a geo-reference; with ``geo`` the poses also go out as
    LocationFix. Returns topic → messages written.

    Raises
    ------
    LogReadError
        A log cannot be read.
    NoPoseError
        The logs hold none of the channels written (nothing is written then).
    MissingExtraError
        The ``mcap`` package is not installed.
    """
    writer_mod = need("mcap.writer", "--format mcap")
    read = read_channels(logs, [*POSE_CHANNELS, *LCM_TOPICS, GNSS])
    if not read.tables:
        names = ", ".join(os.fspath(p) for p in logs)
        raise NoPoseError(f"{names}: no pose, step, fix or GNSS message in the log: nothing to export")
    out = _Out()
    t_first: int | None = None
    for channel, table in read.tables.items():
        t_ns = _ns(table["t_us"], start)
        t_first = int(t_ns.min()) if t_first is None else min(t_first, int(t_ns.min()))
        if channel in POSE_CHANNELS:
            _poses(out, channel, table, t_ns, floors, geo)
        elif channel == GNSS:
            for t, row in zip(t_ns, _rows(table)):
                acc2 = float(row["accuracy_m"]) ** 2
                body = foxglove.location_fix(
                    t, row["lat_deg"], row["lon_deg"], row["alt_m"], (acc2, 0.0, acc2)
                )
                out.add(channel, "foxglove.LocationFix", body, t)
        else:
            spec = CHANNELS[table_of(channel)]
            name = f"stridefix.{type(spec.msg_type()).__name__}"
            out.schemas.setdefault(name, foxglove.lcm_schema(name, spec.columns))
            for t, row in zip(t_ns, _rows(table)):
                out.add(channel, name, foxglove.lcm_message(t, row), t)
    walls = _walls(site)
    if walls:
        t0 = t_first if t_first is not None else _ns(np.zeros(1, np.int64), start)[0]
        heights = {f: float(geo.height_m(f) if geo else np.nan_to_num(floors.z_m(f))) for f in walls}
        out.add(FLOOR_PLAN_TOPIC, "foxglove.SceneUpdate", foxglove.floor_plan(t0, walls, heights), t0)

    counts: dict[str, int] = {}
    with open(path, "wb") as f:
        writer = writer_mod.Writer(f)
        writer.start(profile="", library="stridefix export")
        schema_ids = {}
        for name in dict.fromkeys(out.topics.values()):
            schema = out.schemas.get(name) or foxglove.SCHEMAS[name]
            schema_ids[name] = writer.register_schema(
                name=name, encoding="jsonschema", data=json.dumps(schema).encode()
            )
        channel_ids = {
            topic: writer.register_channel(topic=topic, message_encoding="json", schema_id=schema_ids[name])
            for topic, name in out.topics.items()
        }
        for t_ns_one, topic, data in sorted(out.messages, key=lambda m: m[0]):
            counts[topic] = counts.get(topic, 0) + 1
            writer.add_message(
                channel_id=channel_ids[topic],
                log_time=t_ns_one,
                data=data,
                publish_time=t_ns_one,
                sequence=counts[topic],
            )
        writer.add_metadata(
            "stridefix",
            {"logs": ", ".join(os.fspath(p) for p in logs), "site": str(site.name), "frame": foxglove.FRAME},
        )
        writer.finish()
    return counts
