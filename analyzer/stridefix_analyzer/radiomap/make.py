"""A site file from recorded walks and the building's own files: what ``stridefix radiomap build`` does.

:func:`make_site` reads the logs (:mod:`.recordings`; one task per argument on a scheduler, see
:mod:`stridefix_analyzer.parallel`), builds the radio map (:func:`~.build.build_site`), adds the
msindoor floor plan's walls (:mod:`.floorplan`), merges the building description (:mod:`.building`)
and its context map (:mod:`.contexts`), and writes the site. :class:`SiteOptions` holds every choice,
each with the CLI's default; the lab's benches call this function, never the command line.
Cost: O(scans × APs) for the map, O(walls × truth samples) for the floor plan's doors.
"""

from __future__ import annotations

import csv
import dataclasses
import os
from collections.abc import Sequence
from typing import Any

import numpy as np
from stridefix import site_t
from stridefix_common.geodesy import project

from stridefix_analyzer.io.logread import LogReadError
from stridefix_analyzer.io.sitefile import SiteFileError, set_counts, write_site
from stridefix_analyzer.parallel import SchedulerError, WorkerFiles, is_remote, task_runner
from stridefix_analyzer.radiomap.assemble import DEFAULT_FLOOR_HEIGHT_M, DEFAULT_MIN_COUNT, site_summary
from stridefix_analyzer.radiomap.build import build_site
from stridefix_analyzer.radiomap.building import BuildingError, merge_building, read_building
from stridefix_analyzer.radiomap.contexts import ContextMapError, build_context_map
from stridefix_analyzer.radiomap.floorplan import FloorPlanError
from stridefix_analyzer.radiomap.grid import DEFAULT_CELL_SIZE_M
from stridefix_analyzer.radiomap.placement import DEFAULT_SCAN_DURATION_MS, DEFAULT_STATIC_TOL_M
from stridefix_analyzer.radiomap.recordings import RadioMapInputError, arg_files, load_recordings

#: what :func:`make_site` raises on input it cannot build from (each message names the file)
INPUT_ERRORS: tuple[type[Exception], ...] = (
    LogReadError,
    RadioMapInputError,
    SiteFileError,
    BuildingError,
    FloorPlanError,
    ContextMapError,
    SchedulerError,
)


@dataclasses.dataclass
class SiteOptions:
    """How a site is built (the ``radiomap build`` options of the same names)."""

    mode: str = "auto"  # survey | walk | auto (build.MODES)
    cell_size_m: float = DEFAULT_CELL_SIZE_M
    name: str = ""  # "" = the output file's stem
    map_rotation_deg: float = 0.0
    floor_height_m: float = DEFAULT_FLOOR_HEIGHT_M
    floor_heights_m: list[float] | None = None
    lowest_floor: int | None = None
    min_count: int = DEFAULT_MIN_COUNT
    origin_deg: list[float] | None = None  # [lat, lon]
    scan_duration_ms: float = DEFAULT_SCAN_DURATION_MS
    static_tol_m: float = DEFAULT_STATIC_TOL_M
    building: str | None = None  # building.toml
    beacon_table: str | None = None  # BLE_Locations.csv
    floor_plan: str | None = None  # geojson_map.json
    floor_info: str | None = None
    plan_floor: int | None = None
    min_room_area_m2: float = 0.0
    #: beacons placed from the walks' BLE readings when no --beacon-table gives their positions
    learn_beacons: bool = True
    #: without a described building, a one-building context map so the multi-scheme controller runs
    context_map: bool = False


def read_beacon_table(path: str, origin: tuple[float, float]) -> dict[str, tuple[float, float, int]]:
    """A beacon table CSV (bleID, Lat, Lon, floor) → name → (x, y, floor) in the frame about origin."""
    try:
        with open(path, encoding="utf-8", newline="") as f:
            rows = list(csv.DictReader(f))
        out = {}
        i = 0
        for i, r in enumerate(rows):  # noqa: B007 - i names the row in the message
            x, y = project([float(r["Lat"])], [float(r["Lon"])], *origin)
            out[r["bleID"]] = (float(x[0]), float(y[0]), int(r["floor"]))
    except OSError as exc:
        raise RadioMapInputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except (KeyError, ValueError) as exc:
        raise RadioMapInputError(
            f"{path}: row {i + 2}: bad field {exc} (needs bleID,Lat,Lon,floor)"
        ) from None
    return out


def drop_beacons(site: site_t) -> int:
    """Remove every beacon of ``site`` (its path-loss model stays); returns how many there were."""
    n = int(site.n_beacons)
    for k in ("beacon_id", "beacon_x_m", "beacon_y_m", "beacon_floor", "beacon_rssi_1m_dbm"):
        setattr(site, k, [])
    set_counts(site)
    return n


def add_floor_plan(site: site_t, recordings: list[Any], opts: SiteOptions) -> dict[str, Any]:
    """Walls and geo-reference of ``opts.floor_plan`` written into ``site``; returns the plan report."""
    from stridefix_analyzer.radiomap.floorplan import load_plan, site_plan

    assert opts.floor_plan is not None
    plan = load_plan(opts.floor_plan, opts.floor_info)
    xy = [np.column_stack([r.truth["x_m"], r.truth["y_m"]]) for r in recordings]
    floors = [np.asarray(r.truth["floor"], np.int64) for r in recordings]
    seen = sorted({int(f) for fl in floors for f in fl})
    floor = opts.plan_floor
    if floor is None:
        if len(seen) != 1:
            raise RadioMapInputError(f"--floor-plan: the walks are on floors {seen}: give --plan-floor N")
        floor = seen[0]
    on = [fl == floor for fl in floors]
    fields, report = site_plan(
        plan,
        [p[m] for p, m in zip(xy, on)],
        [f[m] for f, m in zip(floors, on)],
        floor,
        min_room_area_m2=opts.min_room_area_m2,
    )
    for k, v in fields.items():
        setattr(site, k, v)
    set_counts(site)
    site.source = f"{site.source}; floor plan {os.path.basename(opts.floor_plan)}"
    return report


def make_site(
    logs: Sequence[str],
    out: str | os.PathLike[str],
    opts: SiteOptions | None = None,
    *,
    scheduler: str | None = None,
    workers: int = 2,
) -> tuple[site_t, dict[str, Any]]:
    """Build the site of ``logs`` (arguments as ``radiomap build``'s: ``a,b`` is one recording) and
    write it to ``out``; returns (site, summary). Raises one of :data:`INPUT_ERRORS` on bad input."""
    opts = opts or SiteOptions()
    out = os.fspath(out)
    if opts.origin_deg is not None and len(opts.origin_deg) != 2:
        raise RadioMapInputError("--origin-deg needs LAT,LON")
    table = None
    if opts.beacon_table:
        if opts.origin_deg is None:
            raise RadioMapInputError("--beacon-table needs --origin-deg LAT,LON (the frame's origin)")
        table = read_beacon_table(opts.beacon_table, (opts.origin_deg[0], opts.origin_deg[1]))
    logs = [os.fspath(a) for a in logs]
    if is_remote(scheduler):  # a remote worker's working folder is not ours
        logs = [",".join(os.path.abspath(f) for f in arg_files(a)) for a in logs]
    files = WorkerFiles(read=[f for a in logs for f in arg_files(a)])
    with task_runner(scheduler, workers, files) as runner:
        recordings = load_recordings(logs, runner)
    name = opts.name or os.path.splitext(os.path.basename(out))[0]
    site, summary = build_site(
        recordings,
        mode=opts.mode,
        cell_size_m=opts.cell_size_m,
        min_count=opts.min_count,
        name=name,
        map_rotation_deg=opts.map_rotation_deg,
        floor_height_m=opts.floor_height_m,
        floor_heights_m=opts.floor_heights_m,
        lowest_floor=opts.lowest_floor,
        origin_deg=(opts.origin_deg[0], opts.origin_deg[1]) if opts.origin_deg else None,
        scan_duration_ms=opts.scan_duration_ms,
        static_tol_m=opts.static_tol_m,
        beacon_table=table,
    )
    if table is None and not opts.learn_beacons and site.n_beacons:
        summary["ble"]["left_out"] = f"{drop_beacons(site)} beacons placed from the walks alone"
        summary["n_beacons"] = 0
    if opts.floor_plan:
        summary["floor_plan"] = add_floor_plan(site, recordings, opts)
    if opts.building:
        building = read_building(opts.building)
        summary["building"] = merge_building(site, building, os.path.basename(opts.building))
        if building.buildings:
            from stridefix_analyzer.radiomap.beacons import place_readings

            summary["context_map"] = build_context_map(site, building, place_readings(recordings))
    if opts.context_map and not site.n_contexts:
        from stridefix_analyzer.radiomap.beacons import place_readings
        from stridefix_analyzer.radiomap.contexts import (
            DEFAULT_SCHEME,
            MAPPED_SCHEME,
            context_map_summary,
            single_building_context_map,
        )

        # the rule of a described building's floor contexts: the map-aware scheme where there are walls
        scheme = MAPPED_SCHEME if site.n_walls else DEFAULT_SCHEME
        placed = place_readings(recordings) if site.n_beacons else None
        site = single_building_context_map(site, scheme=scheme, ble_placed=placed)
        summary["context_map"] = context_map_summary(site)
    # the plan line counts what the site file holds: the floor plan's and the description's too
    plan = site_summary(site)
    summary.update({k: plan[k] for k in ("n_walls", "n_ports", "n_beacons", "ble_model")})
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    summary["bytes"] = write_site(out, site)
    return site, summary
