"""The fold site's building content: walls, geo-reference and BLE beacons, each learnt from the fold's
training walks only (never the scored one).

Per group, once (:func:`group_content`): the data set's floor plan (msindoor: ``geojson_map.json`` of
the group's floor folder, :mod:`~stridefix_analyzer.radiomap.floorplan`) with every walk's crossings
of its walls (a :class:`~stridefix_analyzer.radiomap.floorplan.DoorSurvey`), the geo-reference
(msindoor: the GeoJSON mapping; gsd: the importer's common origin, the truth's own frame), the
beacon table (gsd: ``BLE_Locations.csv`` projected about that origin) and every walk's BLE readings
placed on its truth (from phase 1). Per fold (:meth:`GroupContent.fold_fields`): the walls opened at
the training walks' crossings, the geo fields, and the beacons and path-loss model
(:func:`~stridefix_analyzer.radiomap.beacons.placed_beacons`) of the training walks' readings.

Each part can be switched off (``--no-floor-plan``, ``--no-beacons``, ``--no-gnss``: no
geo-reference, so the firmware has no frame for GNSS fixes) to measure its effect. Without a beacon
table, beacons are placed from the walks only with ``--learn-beacons`` (:data:`LEARNT_ONLY_NOTE`).

Cost per fold: opening walls O(crossings); beacons one small least-squares fit per unknown beacon
(the fold's ``content_s`` records the time).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.datasets.protocol import Dataset, DatasetError
from stridefix_analyzer.radiomap.beacons import merge_placed, placed_beacons
from stridefix_analyzer.radiomap.floorplan import (
    DoorSurvey,
    FloorPlanError,
    geo_reference,
    inside_outline,
    plan_walls,
    read_geojson_plan,
    wall_fields,
)


@dataclasses.dataclass(frozen=True)
class ContentOptions:
    """Which building content the fold sites carry (all by default)."""

    floor_plan: bool = True
    beacons: bool = True
    gnss: bool = True
    #: beacons of a data set without a beacon table, placed from the walks alone (off by default: see
    #: LEARNT_ONLY_NOTE)
    learn_beacons: bool = False
    #: a context map (one building, a context per floor) with the scheme chosen on the training walks,
    #: so the multi-scheme controller runs (realbench/lsd.py); ``--no-controller`` leaves it out
    controller: bool = True


#: Why a data set without a beacon table gets no beacons by default. Placing a beacon needs the
#: walker's position at each reading, and between sparse waypoints that is an interpolation metres
#: off; on site1/F2 (2026-12-02, 102 walks) the learnt beacons' fixes raised kalman's mean error from
#: 4.21 to 4.89 m and ekf's from 4.19 to 5.56 m. A table (surveyed positions) anchors them.
LEARNT_ONLY_NOTE = "no beacon table: beacons placed from walks alone are left out (--learn-beacons uses them)"


@dataclasses.dataclass(frozen=True)
class GroupContent:
    """What a group's folds share (see the module docstring); sent to the fold workers."""

    survey: DoorSurvey | None
    plan_floor: int
    geo: Mapping[str, Any] | None
    table: Mapping[str, tuple[float, float, int]] | None
    placed: Sequence[Mapping[str, np.ndarray]]
    report: Mapping[str, Any]

    def fold_fields(self, held: int | Collection[int]) -> tuple[dict[str, Any], dict[str, Any]]:
        """site_t fields of the fold without walk ``held`` (index into the group's walks; several for
        an inner cross-validation's site) and the fold's record (walls, openings, beacons, seconds
        spent)."""
        t0 = time.perf_counter()
        fields: dict[str, Any] = {}
        rec: dict[str, Any] = {}
        if self.survey is not None:
            walls, openings = self.survey.fold_walls(held)
            fields.update(wall_fields(walls, self.plan_floor))
            rec.update(walls=len(walls), wall_openings=openings)
        if self.geo is not None:
            fields.update(self.geo)
        if self.placed:
            train = train_placed(self, held) or merge_placed([])
            ble = placed_beacons(train, dict(self.table) if self.table else None)
            fields.update(ble["fields"])
            rec.update(beacons=len(ble["fields"].get("beacon_id", [])), ble_model=ble["report"].get("model"))
        rec["content_s"] = time.perf_counter() - t0
        return fields, rec


def train_placed(content: GroupContent, held: int | Collection[int]) -> dict[str, np.ndarray] | None:
    """The placed BLE readings of the fold's training walks (all but walk(s) ``held``), or None."""
    out = {held} if isinstance(held, int) else set(held)
    train = [p for k, p in enumerate(content.placed) if k not in out]
    return merge_placed(train) if train else None  # type: ignore[arg-type]


def apply_fields(site: Any, fields: Mapping[str, Any]) -> dict[str, int]:
    """Write ``fields`` into ``site``, drop walls and beacons on floors the site does not have, and
    set the counts; returns how many were dropped."""
    from stridefix_analyzer.io.sitefile import set_counts

    for name, value in fields.items():
        setattr(site, name, value)
    lo, hi = site.lowest_floor, site.lowest_floor + len(site.floor_height_m) - 1
    dropped = {}
    for prefix, cols in (
        ("wall", ("wall_x0_m", "wall_y0_m", "wall_x1_m", "wall_y1_m", "wall_floor")),
        ("beacon", ("beacon_id", "beacon_x_m", "beacon_y_m", "beacon_floor", "beacon_rssi_1m_dbm")),
    ):
        floors = list(getattr(site, f"{prefix}_floor"))
        keep = [i for i, f in enumerate(floors) if lo <= f <= hi]
        dropped[prefix] = len(floors) - len(keep)
        if dropped[prefix]:
            for c in cols:
                v = list(getattr(site, c))
                setattr(site, c, [v[i] for i in keep])
    set_counts(site)
    return dropped


def _geo_of_origin(summaries: Sequence[Mapping[str, Any] | None]) -> tuple[float, float] | None:
    """The importers' common origin (lat, lon) [deg] of the walks' truth frame, or None (none, or
    the walks disagree)."""
    origins = {
        (float(o["lat_deg"]), float(o["lon_deg"]))
        for s in summaries
        if s and isinstance(o := s.get("origin"), Mapping)
    }
    return origins.pop() if len(origins) == 1 else None


def group_content(
    dataset: Dataset,
    folder: Path | None,
    floor_dir: Path | None,
    walks: Sequence[Mapping[str, Any]],
    options: ContentOptions,
) -> GroupContent:
    """The group's shared content from its walks (phase-1 dicts: ``waypoint_xy_m``,
    ``waypoint_floor``, ``import``, ``ble_placed``). Raises nothing: a part that cannot be made is
    left out and the report says why."""
    report: dict[str, Any] = {}
    survey: DoorSurvey | None = None
    plan_floor = 0
    plan = None
    if floor_dir is not None:
        try:
            fp = dataset.floor_plan(floor_dir)
            if fp is not None and fp.geojson is not None:
                plan = read_geojson_plan(fp.geojson, fp.width_m, fp.height_m, str(floor_dir))
        except (DatasetError, FloorPlanError) as exc:
            report["floor_plan_error"] = str(exc)
    if plan is not None and options.floor_plan:
        floors = {int(f) for w in walks for f in w["waypoint_floor"]}
        if len(floors) == 1:
            plan_floor = floors.pop()
            t0 = time.perf_counter()
            walls = plan_walls(plan)
            survey = DoorSurvey.of(
                walls, [w["waypoint_xy_m"] for w in walks], [w["waypoint_floor"] for w in walks]
            )
            xy = np.concatenate([w["waypoint_xy_m"] for w in walks])
            held = survey.held_out_crossing()
            report["floor_plan"] = {
                "floor": plan_floor,
                "waypoints_inside_outline": float(inside_outline(plan, xy).mean()),
                "walls": len(walls),
                "walls_opened_all_walks": len(survey.fold_walls(None)[0]),
                "openings_all_walks": survey.fold_walls(None)[1],
                "truth_segments": len(survey.segments["seg"]),
                "held_out_crossing_fraction": held["fraction"],
                "survey_s": time.perf_counter() - t0,
            }
        else:
            report["floor_plan_error"] = f"walks on floors {sorted(floors)}: one plan per floor"
    frame = None  # the geo-reference of the truth's frame, which the beacon table needs too
    if plan is not None:
        g = geo_reference(plan)
        frame = g["fields"]
        report["geo"] = {"source": "floor plan GeoJSON", "scale": g["scale"]}
    elif (o := _geo_of_origin([w.get("import") for w in walks])) is not None:
        frame = {
            "has_geo": True,
            "origin_lat_deg": o[0],
            "origin_lon_deg": o[1],
            "origin_alt_m": 0.0,
            "geo_rotation_deg": 0.0,
        }
        report["geo"] = {"source": "importer origin", "origin_deg": list(o)}
    geo = frame if options.gnss else None
    if frame is not None and not options.gnss:
        report["geo"]["off"] = "--no-gnss"
    table = None
    if options.beacons and folder is not None and frame is not None:
        table = beacon_table(dataset, folder, (frame["origin_lat_deg"], frame["origin_lon_deg"]))
        if table:
            report["beacon_table"] = len(table)
    placed = [w["ble_placed"] for w in walks if "ble_placed" in w] if options.beacons else []
    if len(placed) != len(walks) or not any(len(p["rssi_dbm"]) for p in placed):
        placed = []
    if placed and not table and not options.learn_beacons:
        placed = []
        report["beacons"] = LEARNT_ONLY_NOTE
    return GroupContent(survey, plan_floor, geo, table, placed, report)


def beacon_table(
    dataset: Dataset, folder: Path, origin: tuple[float, float]
) -> dict[str, tuple[float, float, int]] | None:
    """The data set's beacon table in ``folder`` (name → x, y, floor) about ``origin``, or None."""
    from stridefix_common.geodesy import project

    try:
        t = dataset.beacons(folder)
    except DatasetError:
        return None
    if t is None or not len(t):
        return None
    x, y = project(t["lat_deg"], t["lon_deg"], *origin)
    return {
        str(n): (float(a), float(b), int(f))
        for n, a, b, f in zip(t["id"], x, y, t["floor"])
        if math.isfinite(a) and math.isfinite(b)
    }
