"""One simulated run: scenario → world → walker → sensors + radio → board emulator → output files.

Seeding: one ``numpy.random.SeedSequence(seed)`` spawns independent streams for the walker, the sensors,
the radio, the CAN link, the person (body: stride and cadence scales, Weinberg K) and the bus and board
faults (faults.py), so e.g. changing
the loss rate does not change the sensor noise, and changing the pace does not change the person. The
same scenario and seed give byte-identical outputs.

Outputs (``write_outputs``): ``board.candump`` (or ``board.log`` with ``candump_suffix=".log"``, the
same candump -L lines under the suffix python-can's ``can.LogReader`` reads them by; or a stream), ``truth.lcmlog`` (channel TRUTH, truth_t at
10 Hz, t_us = unwrapped board time in µs, also the event timestamp; x, y, the true floor, the true
heading = walking direction in the map frame, steps so far; source SIMULATION), ``sim_summary.json``
``init_truth.ini`` (the true start pose for the firmware), ``building.toml`` (the world's building
description, building.py) and, for a world with beacons, GNSS or landmarks, ``sources.json`` (what
they sent: ``Sources.as_dict``); a world with building outlines adds to the summary its contexts and
the walk's transitions with their truth times (transitions.py). On a route with reference points (the
``track``), one extra TRUTH with source WAYPOINT at the moment the walker passes each reference point
(time interpolated to the µs between walker samples; x, y = the surveyed point), in time order
with the 10 Hz messages (a SIMULATION message first when both fall on the same µs).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

import numpy as np

from .ble import Advertisements, simulate_ble
from .board import IMU_PERIOD_MS, BoardOutput, emulate_board
from .building import write_building
from .gait import make_person
from .gnss import Fixes, simulate_gnss
from .landmarks import LandmarkEvent, simulate_landmarks
from .radio import Scan, simulate_scans
from .scenario import Scenario
from .sensors import IMU_RATE_HZ, SensorData, simulate_sensors
from .transitions import contexts, transitions
from .walker import ACTIVITIES, Walk, simulate_walk
from .world import World
from .worlds import load_world

TRUTH_DECIMATION = 10  # 10 Hz truth from 100 Hz walker samples
TRUTH_CHANNEL = "TRUTH"
SOURCE_TABLES = ("ble", "gnss", "landmark")  # scenario tables of sources.py's models


@dataclass
class Sources:
    """What the board heard and read besides its sensors and Wi-Fi (empty where the world has none)."""

    ble: Advertisements
    gnss: Fixes
    landmarks: list[LandmarkEvent]

    def __bool__(self) -> bool:
        return bool(len(self.ble) or len(self.gnss) or self.landmarks)

    def as_dict(self, start_ms: int, world: World, landmark_latency_ms: int = 0) -> dict:
        """sources.json: the building's footprint (indoors) and doors, every landmark event (with the
        delay of its LANDMARK frame after the read) and GNSS fix (board time [ms] and walk time [s]),
        BLE counts."""
        g = self.gnss
        macs, counts = np.unique(self.ble.mac, return_counts=True)
        return {
            "board_time_start_ms": start_ms,
            "footprint_m": None if world.footprint_m is None else np.asarray(world.footprint_m).tolist(),
            "doors": [
                {"name": d.name, "x_m": d.x_m, "y_m": d.y_m, "floor": d.floor, "landmark_id": d.landmark_id}
                for d in world.doors
            ],
            "landmarks": [
                {
                    "t_s": e.t_ms / 1000.0,
                    "board_time_ms": (start_ms + e.t_ms) % 2**32,
                    "landmark_id": e.landmark_id,
                    "x_m": e.x_m,
                    "y_m": e.y_m,
                    "floor": e.floor,
                    "distance_m": round(e.distance_m, 4),
                    "latency_ms": landmark_latency_ms,
                }
                for e in self.landmarks
            ],
            "gnss": {
                "n": len(g),
                "columns": [
                    "t_s",
                    "lat_deg",
                    "lon_deg",
                    "alt_m",
                    "accuracy_m",
                    "x_m",
                    "y_m",
                    "truth_x_m",
                    "truth_y_m",
                    "mode",
                ],
                "rows": [
                    [
                        t / 1000.0,
                        la,
                        lo,
                        round(al, 3),
                        round(ac, 3),
                        round(x, 4),
                        round(y, 4),
                        round(tx, 4),
                        round(ty, 4),
                        int(m),
                    ]
                    for t, la, lo, al, ac, x, y, tx, ty, m in zip(
                        g.t_ms.tolist(),
                        g.lat_deg.tolist(),
                        g.lon_deg.tolist(),
                        g.alt_m.tolist(),
                        g.accuracy_m.tolist(),
                        g.x_m.tolist(),
                        g.y_m.tolist(),
                        g.truth_x_m.tolist(),
                        g.truth_y_m.tolist(),
                        g.mode.tolist(),
                    )
                ],
            },
            "ble": {
                "advertisements": len(self.ble),
                "per_beacon": {f"{int(m):012x}": int(c) for m, c in zip(macs, counts)},
            },
        }


@dataclass
class SimResult:
    scenario: Scenario
    world: World
    walk: Walk
    sensors: SensorData
    scans: list[Scan]
    board: BoardOutput
    duration_s: float
    sources: Sources | None = None

    @property
    def board_time_start_ms(self) -> int:
        return int(self.scenario["can"]["board_time_start_ms"])

    def truth_indices(self) -> np.ndarray:
        return np.arange(0, len(self.walk.t_s), TRUTH_DECIMATION)

    def steps_until(self, t_s: np.ndarray) -> np.ndarray:
        return np.searchsorted(self.walk.step_t_s, np.asarray(t_s) + 1e-9, side="right")

    @property
    def steps(self) -> int:
        return int(self.steps_until(self.walk.t_s[self.truth_indices()[-1]]))

    def init_pose(self) -> dict:
        w = self.walk
        return {
            "x_m": round(float(w.x_m[0]), 6),
            "y_m": round(float(w.y_m[0]), 6),
            "heading_rad": round(_wrap(float(w.heading_rad[0])), 9),
            "floor": int(w.floor[0]),
        }

    def activity_s(self) -> dict:
        """Seconds spent in each activity (IMU samples x period, up to the end of the run)."""
        counts = np.bincount(self.walk.activity[:-1], minlength=len(ACTIVITIES))
        return {name: round(float(c) * IMU_PERIOD_MS / 1000.0, 2) for name, c in zip(ACTIVITIES, counts)}

    def reference_passes(self) -> list[dict]:
        """When the walker passes each reference point of the route: index, x, y, floor, s_m, t_s, heading."""
        w = self.walk
        out = []
        for k, (s_ref, x, y) in enumerate(w.route.marks):
            i = int(np.searchsorted(w.s_m, s_ref - 1e-9, side="left"))
            if i >= len(w.s_m):
                continue  # the run ended before this point
            if i == 0:
                t = float(w.t_s[0])
            else:
                ds = float(w.s_m[i] - w.s_m[i - 1])
                f = (s_ref - float(w.s_m[i - 1])) / ds if ds > 0 else 1.0
                t = float(w.t_s[i - 1] + min(max(f, 0.0), 1.0) * (w.t_s[i] - w.t_s[i - 1]))
            out.append(
                {
                    "index": k,
                    "x_m": x,
                    "y_m": y,
                    "floor": int(w.floor[i]),
                    "s_m": round(float(s_ref), 6),
                    "t_s": round(t, 6),
                    "heading_rad": _wrap(float(w.heading_rad[i])),
                }
            )
        return out

    def survey_summary(self) -> dict:
        w, sv = self.walk, self.scenario["survey"]
        per_point = np.bincount([p[1] for p in w.scan_plan], minlength=len(w.stops)) if w.stops else []
        return {
            "n_points": len(w.stops),
            "scans_per_point": int(sv["orientations"] * sv["scans_per_orientation"]),
            "scans_per_orientation": int(sv["scans_per_orientation"]),
            "orientations": [
                round(360.0 * k / sv["orientations"], 6) for k in range(int(sv["orientations"]))
            ],
            "spacing_m": sv["spacing_m"],
            "survey_points": [
                {
                    "index": st["index"],
                    "x_m": st["x_m"],
                    "y_m": st["y_m"],
                    "floor": st["floor"],
                    "scans": int(per_point[st["index"]]),
                    "t_arrive_s": round(st["t_arrive"], 3),
                }
                for st in w.stops
            ],
        }

    def summary(self) -> dict:
        c = self.board.counts
        extra = {}
        if self.walk.stops:
            extra.update(self.survey_summary())
        if self.walk.route.marks:
            refs = self.reference_passes()
            extra["n_reference_points"] = len(refs)
            extra["reference_points"] = [
                {k: r[k] for k in ("index", "x_m", "y_m", "floor", "s_m", "t_s")} for r in refs
            ]
        scenario = self.scenario.data
        if not (self.world.beacons or self.world.doors or self.world.footprint_m is not None):
            # a world without these sources: its summary stays as it was before they existed
            scenario = {k: v for k, v in scenario.items() if k not in SOURCE_TABLES}
        elif self.sources is not None:
            extra["sources"] = {
                "ble_advertisements": len(self.sources.ble),
                "gnss_fixes": len(self.sources.gnss),
                "landmark_events": len(self.sources.landmarks),
            }
        if self.world.outlines:  # several buildings: the truth of contexts and transitions (transitions.py)
            extra["contexts"] = contexts(self.world)
            extra["transitions"] = transitions(self.world, self.walk, self.board_time_start_ms * 1000)
        if "faults" in c:  # the ground truth of what the faults damaged (faults.FaultRecord)
            extra["faults"] = c["faults"]
        else:  # faults off: the summary of a clean run stays as it was before faults existed
            scenario = {k: v for k, v in scenario.items() if k != "faults"}
        if self.world.name != "default":
            extra["world"] = {
                "name": self.world.name,
                "area_m2": self.world.area_m2,
                "n_aps": len(self.world.aps),
                "description": self.world.description,
            }
        return {
            "seed": self.scenario.seed,
            "scenario_source": self.scenario.source,
            "duration_s": round(self.duration_s, 3),
            "distance_m": round(float(self.walk.s_m[-1]), 3),
            "steps": self.steps,
            "imu_samples": c["imu_samples"],
            "mag_samples": c["mag_samples"],
            "baro_samples": c["baro_samples"],
            "wifi_scans": c["wifi_scans"],
            "wifi_ap_frames": c["wifi_ap_frames"],
            "frames_total": c["frames_total"],
            "frames_dropped": c["frames_dropped"],
            "frames_by_name": c["frames_by_name"],
            "dropped_by_name": c["dropped_by_name"],
            "truth_messages": len(self.truth_indices()),
            "board_time_start_ms": self.board_time_start_ms,
            "board_time_end_ms": (self.board_time_start_ms + (len(self.walk.t_s) - 1) * IMU_PERIOD_MS)
            % 2**32,
            "turn_radius_m": round(self.walk.route.radius_m, 6),
            "route": self.walk.route.name,
            "pace": self.walk.person.pace,
            "weinberg_k": round(self.walk.person.weinberg_k, 6),
            "person": self.walk.person.as_dict(),
            "map_rotation_deg": self.world.map_rotation_deg,
            "floors_visited": sorted({int(f) for f in np.unique(self.walk.floor)}),
            "floor_height_m": self.world.storey_m,
            "activity_s": self.activity_s(),
            "elevator_rides": len([r for r in self.walk.rides if r[0] <= self.duration_s]),
            "init": self.init_pose(),
            "scenario": scenario,
            **extra,
        }


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


def simulate(scenario: Scenario) -> SimResult:
    sc = scenario.data
    world = load_world(sc["world"]["name"], sc["world"]["map_rotation_deg"])
    ss = np.random.SeedSequence(scenario.seed)
    # (a sixth stream for the faults leaves the first five as they were: child i has spawn key (i,))
    # (children 6, 7 for BLE and GNSS leave the first six as they were)
    streams = [np.random.default_rng(s) for s in ss.spawn(8)]
    r_walk, r_sens, r_radio, r_can, r_person, r_faults, r_ble, r_gnss = streams
    duration = float(sc["duration_s"])
    duration = math.ceil(duration * 10 - 1e-9) / 10 if duration > 0 else None  # whole truth periods
    person = make_person(sc, r_person)
    walk = simulate_walk(sc, world, r_walk, rate_hz=IMU_RATE_HZ, duration_s=duration, person=person)
    duration_s = float(walk.t_s[-1])
    sensors = simulate_sensors(sc, world, walk, r_sens)
    scans = simulate_scans(sc, world, walk, r_radio)
    sources = Sources(
        simulate_ble(sc, world, walk, r_ble),
        simulate_gnss(sc, world, walk, r_gnss),
        simulate_landmarks(sc, world, walk),
    )
    board = emulate_board(sensors, scans, len(walk.t_s), sc, r_can, fault_rng=r_faults, sources=sources)
    return SimResult(
        scenario=scenario,
        world=world,
        walk=walk,
        sensors=sensors,
        scans=scans,
        board=board,
        duration_s=duration_s,
        sources=sources,
    )


def write_truth_log(result: SimResult, path: Path) -> int:
    import lcm
    from stridefix import truth_t

    w = result.walk
    idx = result.truth_indices()
    steps = result.steps_until(w.t_s[idx])
    start_us = result.board_time_start_ms * 1000
    msgs = []
    for i, n_steps in zip(idx.tolist(), steps.tolist()):
        msg = truth_t()
        msg.t_us = start_us + i * IMU_PERIOD_MS * 1000
        msg.x_m = float(w.x_m[i])
        msg.y_m = float(w.y_m[i])
        msg.floor = int(w.floor[i])
        msg.heading_rad = _wrap(float(w.heading_rad[i]))
        msg.step_count = int(n_steps)
        msg.source = truth_t.SOURCE_SIMULATION
        msgs.append(msg)
    t_end_us = start_us + int(idx[-1]) * IMU_PERIOD_MS * 1000 if len(idx) else start_us
    for ref in result.reference_passes():
        msg = truth_t()
        msg.t_us = start_us + int(round(ref["t_s"] * 1e6))
        if msg.t_us > t_end_us:
            continue
        msg.x_m, msg.y_m, msg.floor = ref["x_m"], ref["y_m"], ref["floor"]
        msg.heading_rad = ref["heading_rad"]
        msg.step_count = int(result.steps_until(np.array([ref["t_s"]]))[0])
        msg.source = truth_t.SOURCE_WAYPOINT
        msgs.append(msg)
    msgs.sort(key=lambda m: (m.t_us, m.source))  # stable: the 10 Hz stream keeps its order
    log = lcm.EventLog(str(path), "w", overwrite=True)
    try:
        for msg in msgs:
            log.write_event(msg.t_us, TRUTH_CHANNEL, msg.encode())
    finally:
        log.close()
    return len(msgs)


def write_init_ini(result: SimResult, path: Path) -> None:
    p = result.init_pose()
    path.write_text(
        "[init]\n"
        f"x_m = {p['x_m']:.3f}\n"
        f"y_m = {p['y_m']:.3f}\n"
        f"heading_rad = {p['heading_rad']:.6f}\n"
        f"floor = {p['floor']}\n",
        encoding="utf-8",
    )


#: The CAN log's name suffixes: candump -L lines either way; python-can's ``can.LogReader`` picks its
#: candump reader (``CanutilsLogReader``) from ``.log`` and refuses ``.candump``.
CANDUMP_SUFFIXES = (".candump", ".log")


def candump_path(out_dir: Path, suffix: str = CANDUMP_SUFFIXES[0]) -> Path:
    """Where :func:`write_outputs` writes the candump lines: ``out_dir/board<suffix>``."""
    if suffix not in CANDUMP_SUFFIXES:
        raise ValueError(f"candump suffix {suffix!r}: not one of {', '.join(CANDUMP_SUFFIXES)}")
    return out_dir / f"board{suffix}"


def write_outputs(
    result: SimResult,
    out_dir: Path,
    candump_stream: TextIO | None = None,
    candump_suffix: str = CANDUMP_SUFFIXES[0],
) -> dict:
    """Write the run's files into ``out_dir``; candump lines go to ``candump_stream`` when given, else
    to :func:`candump_path` (``board.candump``, or ``board.log`` with ``candump_suffix=".log"``)."""
    path = candump_path(out_dir, candump_suffix)
    out_dir.mkdir(parents=True, exist_ok=True)
    lines = result.board.lines or [""]  # (no frame: one empty line, as before)
    step = 100_000  # in pieces: an 8-hour walk's text would be another 400 MB at once
    if candump_stream is None:
        with open(path, "w", encoding="ascii") as f:
            for i in range(0, len(lines), step):
                f.write("\n".join(lines[i : i + step]) + "\n")
    else:
        for i in range(0, len(lines), step):
            candump_stream.write("\n".join(lines[i : i + step]) + "\n")
        candump_stream.flush()
    write_truth_log(result, out_dir / "truth.lcmlog")
    write_init_ini(result, out_dir / "init_truth.ini")
    write_building(result.world, out_dir / "building.toml", result.scenario["ble"])
    if result.sources:
        (out_dir / "sources.json").write_text(
            json.dumps(
                result.sources.as_dict(
                    result.board_time_start_ms, result.world, int(result.scenario["landmark"]["latency_ms"])
                ),
                indent=1,
            )
            + "\n",
            encoding="utf-8",
        )
    summary = result.summary()
    (out_dir / "sim_summary.json").write_text(
        json.dumps(summary, indent=2, sort_keys=True) + "\n", encoding="utf-8"
    )
    return summary
