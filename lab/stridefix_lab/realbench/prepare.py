"""Phase 1 of ``realbench fusion``, one walk: import (cached), replay without a site, and the walk's
*sufficient statistics* — everything a fold learns from it, in sums that add over walks.

From that replay and the walk's own log: the walk-mode radio-map sums
(:class:`~stridefix_analyzer.radiomap.build.WalkStats`), the Weinberg segment inputs of
:mod:`stridefix_analyzer.radiomap.strides`, the heading-offset sums of every heading candidate (:func:`stridefix_analyzer.radiomap.heading.rotation_stats`;
the walk is replayed once per candidate) and the barometric height of each truth floor. The walk's
raw sensors, read once more through the data set, give the textbook references their inputs
(:func:`.reference.track_of`).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from stridefix_analyzer.datasets.protocol import Dataset
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, read_logs, read_table
from stridefix_analyzer.radiomap.heading import rotation_stats

from stridefix_lab.realbench.floors import floor_heights_of_walk
from stridefix_lab.realbench.reference_sensors import track_of
from stridefix_lab.realbench.walks import cached_import, new_walk


@dataclasses.dataclass(frozen=True)
class PrepareJob:
    """What phase 1 needs for one walk (sent to a worker process)."""

    trace: Path
    dataset: Dataset
    work_dir: Path
    cache_dir: Path
    firmware: Firmware
    #: read options: max_wifi_age_s and the group's own (e.g. a common origin)
    read_options: Mapping[str, Any]
    reimport: bool
    cell_size_m: float
    #: the user's --set KEY=VALUE, then the heading candidates: name -> extra --set
    param_sets: Sequence[str]
    heading_candidates: Mapping[str, Sequence[str]]


def prepare(job: PrepareJob) -> dict[str, Any]:
    """Phase 1 of one walk.

    Returns
    -------
    dict
        The keys :func:`stridefix_analyzer.radiomap.strides.build_segments` reads (``walk``, ``import``, ``error``,
        ``waypoint_t_us``, ``waypoint_xy_m``, ``step_t_us``, ``step_range_mps2``,
        ``step_length_m``), plus ``stats`` (WalkStats), ``rotation`` (per heading candidate,
        :func:`stridefix_analyzer.radiomap.heading.rotation_stats`), ``floor_heights``, ``floors`` (truth floors),
        ``first_waypoint`` (t_us, x, y, floor), ``import_log``, ``fw_log`` (the site-less replay) and
        ``ble_placed`` (the BLE readings placed on the truth,
        :func:`~stridefix_analyzer.radiomap.beacons.place_readings`) and ``reference`` (the textbook
        references' :class:`.reference.Track`, None when the walk cannot be read again).
    """
    from stridefix_analyzer.radiomap.beacons import place_readings
    from stridefix_analyzer.radiomap.build import RadioMapInputError, WalkStats, load_recordings

    trace = job.trace
    walk = new_walk(trace)
    fw_dir = job.work_dir / "nosite"
    job.cache_dir.mkdir(parents=True, exist_ok=True)
    fw_dir.mkdir(parents=True, exist_ok=True)
    try:
        summary = cached_import(job.dataset, trace, job.cache_dir, job.read_options, job.reimport)
    except Exception as exc:  # any importer failure loses this walk only
        walk["error"] = f"import failed: {type(exc).__name__}: {exc}"
        return walk
    walk["import"] = summary
    walk["import_log"] = imp = summary["out"]
    walk["warnings"] += summary.get("warnings", [])[:5]
    first = next(iter(job.heading_candidates))
    headings = {}
    # every variant's STEP stream: the crowd-built map's dead reckoning (.crowdfolds chooses one)
    walk["fw_logs"] = fw_logs = {}
    for (
        name,
        sets,
    ) in job.heading_candidates.items():  # the first candidate's STEP stream also gives K and steps
        fw_log = fw_dir / f"{trace.stem}.{name}.lcmlog"
        fw_logs[name] = str(fw_log)
        proc = job.firmware.run(input=f"lcmlog:{imp}", log=fw_log, sets=[*job.param_sets, *sets], check=False)
        if proc.returncode != 0:
            walk["error"] = f"stridefixd exit {proc.returncode}: {proc.stderr.strip()[-300:]}"
            return walk
        if name != first:
            st = read_table(fw_log, "STEP")
            headings[name] = (st["t_us"], st["heading_rad"]) if st is not None else None
    fw_log = Path(fw_logs[first])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)
            fw = read_logs([fw_log], decode=("STEP",))
            raw = read_logs(
                [imp],
                decode=("TRUTH", "BARO", "IMU") if "imu_t_first_us" not in summary else ("TRUTH", "BARO"),
            )
        recs = load_recordings([imp])
    except (LogReadError, RadioMapInputError) as exc:
        walk["error"] = f"cannot read logs: {exc}"
        return walk
    truth, steps, baro = raw.table("TRUTH"), fw.table("STEP"), raw.table("BARO")
    if truth is None or not len(truth):
        walk["error"] = "no TRUTH in the imported log"
        return walk
    if "imu_t_first_us" not in summary:
        imu = raw.table("IMU")
        summary["imu_t_first_us"] = int(imu["t_us"][0]) if imu is not None and len(imu) else None
        summary["imu_t_last_us"] = int(imu["t_us"][-1]) if imu is not None and len(imu) else None
    summary.setdefault("waypoints", len(truth))
    walk["waypoint_t_us"] = truth["t_us"]
    walk["waypoint_xy_m"] = np.column_stack([truth["x_m"], truth["y_m"]])
    walk["waypoint_floor"] = truth["floor"].astype(np.int64)
    z = np.zeros(0)
    walk["step_t_us"] = steps["t_us"] if steps is not None else np.zeros(0, np.int64)
    walk["step_range_mps2"] = steps["accel_range_mps2"] if steps is not None else z
    walk["step_length_m"] = steps["length_m"] if steps is not None else z
    walk["step_heading_rad"] = steps["heading_rad"] if steps is not None else z
    walk["stats"] = WalkStats.from_recordings(recs, cell_size_m=job.cell_size_m)
    walk["ble_placed"] = place_readings(recs)
    wp_t, wp_xy = walk["waypoint_t_us"], walk["waypoint_xy_m"]
    walk["rotation"] = {first: rotation_stats(walk["step_t_us"], walk["step_heading_rad"], wp_t, wp_xy)}
    for name, th in headings.items():
        walk["rotation"][name] = rotation_stats(th[0] if th else [], th[1] if th else [], wp_t, wp_xy)
    walk["floor_heights"] = (
        floor_heights_of_walk(baro["t_us"], baro["pressure_pa"], truth["t_us"], truth["floor"])
        if baro is not None and len(baro)
        else {}
    )
    walk["floors"] = sorted({int(f) for f in truth["floor"]})
    try:
        walk["reference"] = track_of(job.dataset.read(trace, **job.read_options))
    except Exception as exc:  # the references lose this walk only; the schemes keep it
        walk["reference"] = None
        walk["warnings"].append(f"no reference track: {type(exc).__name__}: {exc}")
    walk["first_waypoint"] = (
        int(truth["t_us"][0]),
        float(truth["x_m"][0]),
        float(truth["y_m"][0]),
        int(truth["floor"][0]),
    )
    return walk
