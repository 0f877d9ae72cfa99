"""Scenario: everything that defines one simulated run, read from a TOML file (tomllib) or built in.

A scenario names the world, the walk (route, pace, pauses), the person, stairs and elevator, the sensor
imperfections (noise, biases and their drift, scale errors, board mounting rotation, magnetic
disturbances, weather), the radio model, the CAN link (frame loss, board time start; a board time start
near 2**32 makes the 32-bit time wrap during the walk), bus and board faults (``[faults]``, faults.py:
loss bursts, silence, duplicates, reordering, corruption, board resets, a stuck BOARD_TIME, a failed
IMU, implausible samples), the seed and the duration. Every key has a default (``DEFAULTS`` below, the built-in demo scenario: the two-floor tour —
a lap of floor 0, the stairs up, a lap of floor 1, the elevator down, a partial lap — at normal pace
with 3 pauses, about 5 minutes). A file only needs the keys it changes. An unknown key, a wrong type or
an out-of-range value raises :class:`ScenarioError` naming the file and the key.

Built-in named scenarios (``BUILTIN``, ``stridefix sim --scenario NAME``): ``default`` and
``pace_slow`` / ``pace_normal`` / ``pace_fast``: two laps of the floor-0 loop at one pace, two pauses;
``office_survey``: the survey of the office's calibration points (2 m along the corridors, both
floors, the elevator between them); ``aadr2015_slow`` / ``aadr2015`` / ``aadr2015_fast``: the 70 m
track with 14 reference points through the aadr2015 foyer (world ``aadr2015``) at one pace;
``aadr2015_survey``: the survey of the foyer's 67 calibration points; ``campus`` / ``campus_survey``:
world ``campus`` (indoor, a door with a landmark, 66 m outdoors with GNSS, another door, indoor) and its
survey; ``campus2`` / ``campus2_survey``: world ``campus2`` (outdoors → building A's door → stairs
up → elevator up, then down → outdoors → building B's door) and its survey. ``[ble]``, ``[gnss]``, ``[landmark]``: scenario_sources.py.

Survey mode (``[survey] enabled = true`` or ``stridefix sim --survey``): instead of ``walk.route`` the
person walks from calibration point to calibration point, and at each stands still, faces
``orientations`` headings (k·360°/n in the map frame, turning in place) and takes
``scans_per_orientation`` Wi-Fi scans in each; Wi-Fi scans happen only then (``walker.py``).
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .scenario_sources import SOURCE_DEFAULTS
from .scenario_values import ScenarioError, validate_values

# Built-in default scenario. Units are in the key names; comments give ranges.
DEFAULTS: dict[str, Any] = {
    "seed": 1,
    "duration_s": 0.0,  # 0: until the walk ends plus trailing_still_s
    "world": {
        "name": "default",
        "map_rotation_deg": 20.0,  # map frame = magnetic east-north frame turned CCW by this angle
    },
    "walk": {
        "route": "tour",  # "tour": two floors, stairs up, elevator down; "loop": laps of floor 0
        "laps": 2.0,  # route "loop" only: laps of the corridor loop (fractions allowed)
        "pace": "normal",  # "slow" 1.5 Hz / 0.55 m, "normal" 1.8 Hz / 0.70 m, "fast" 2.1 Hz / 0.85 m
        "start_still_s": 3.0,  # standing still before the first step
        "trailing_still_s": 3.0,  # standing still after the last step (when duration_s = 0)
        "cadence_hz": 0.0,  # > 0: mean step rate instead of pace x person
        "cadence_jitter": 0.03,  # step-to-step relative std of the step period
        "stride_m": 0.0,  # > 0: mean step length instead of pace x person
        "stride_jitter": 0.04,  # step-to-step relative std of the step length
        "speed_mps": 0.0,  # > 0: stride = speed_mps / cadence
        "turn_radius_m": 0.8,  # corner radius of the route in the corridor (centre line)
        "max_yaw_rate_dps": 120.0,  # corridor corners are widened so that speed/radius stays below this
        "bounce_jitter": 0.08,  # step-to-step log-normal std of the vertical amplitude (Weinberg)
        "pendulum_recovery": 0.65,  # inverted pendulum: fraction of potential energy returned as kinetic
        "sway_mps2": 0.6,  # lateral acceleration amplitude (half the step rate)
        "pause": [  # [[walk.pause]] at_m (distance walked), duration_s
            {"at_m": 40.0, "duration_s": 5.0},
            {"at_m": 200.0, "duration_s": 4.0},
            {"at_m": 320.0, "duration_s": 6.0},
        ],
    },
    "person": {  # 0 = drawn from the seed (own random stream)
        "weinberg_k": 0.0,  # step length = K (amax - amin)^(1/4); drawn 0.5 x stride_scale, 0.45..0.55
        "stride_scale": 0.0,  # x the pace's stride; drawn N(1, 0.06) within 0.88..1.12
        "cadence_scale": 0.0,  # x the pace's (and the stairs') cadence; drawn N(1, 0.04) within 0.92..1.08
    },
    "stairs": {
        "cadence_hz": 1.5,  # steps per second on a flight (x the person's cadence scale)
        "bounce_p2p_mps2": 3.5,  # vertical acceleration peak-to-peak per stair step
    },
    "elevator": {
        "speed_mps": 1.0,  # cruise speed
        "accel_mps2": 0.8,  # peak acceleration (sin² ramps, jerk-limited)
        "door_s": 4.0,  # standing in the cab before it moves (the turn happens here)
        "exit_s": 2.0,  # standing in the cab after it stops
    },
    "mounting": {  # board axes relative to the body (x forward, y left, z up), ZYX
        "roll_deg": 0.0,
        "pitch_deg": 0.0,
        "yaw_deg": 0.0,
    },
    "imu": {
        "accel_noise_mps2": 0.02,  # white noise std per sample
        "accel_bias_mps2": [0.03, -0.02, 0.05],
        "gyro_noise_dps": 0.05,
        "gyro_bias_dps": [0.10, -0.08, 0.05],  # initial bias
        "gyro_bias_rw_dps_per_sqrt_s": 0.002,  # bias random walk: std after t seconds = this x sqrt(t)
        "gyro_scale_error": [0.008, -0.006, 0.010],  # per board axis, fraction
    },
    "mag": {
        "field_ut": 48.0,  # total intensity of the (undisturbed) earth field
        "dip_deg": 60.0,  # inclination, positive = pointing down
        "noise_ut": 0.3,
        "hard_iron_ut": [0.8, -0.6, 0.5],
        "disturbance_scale": 1.0,  # x the world's magnetic disturbance zones (0 = none)
    },
    "baro": {
        "sea_level_pa": 101325.0,
        "sensor_height_m": 1.1,  # board height above the floor
        "noise_pa": 1.5,
        "drift_pa_per_sqrt_h": 20.0,  # weather: random walk, std after one hour [Pa]
        "temperature_degc": 22.5,  # board temperature at start; warms by 2 degC with 2 min time constant
        "temperature_noise_degc": 0.05,
    },
    "radio": {
        "path_loss_exponent": 2.5,
        "wall_loss_db": 5.0,  # per crossed wall
        "floor_loss_db": 15.0,  # per floor between the AP and the receiver
        "shadowing_db": 2.5,  # gaussian noise std per reading
        "floor_dbm": -95.0,  # detection floor: weaker APs are not reported
        "scan_interval_min_s": 2.0,
        "scan_interval_max_s": 4.0,
        "scan_duration_ms": 120,  # results are sent this long after the scan started
        "body_loss_db": 0.0,  # body shadowing: + this x (1 - cos(AP bearing - facing)) / 2 dB loss
    },
    "survey": {
        "enabled": False,  # true: survey the calibration points instead of walking walk.route
        "layout": "grid",  # "grid": spacing_m grid in the walkable area; "world": the world's own list
        "spacing_m": 2.0,  # grid spacing (and the longest move between neighbouring points)
        "margin_m": 0.5,  # calibration points keep this far from walls and block edges
        "floor": -1,  # -1: every floor of the world, else that floor only
        "orientations": 4,  # headings per point: k x 360/n deg (0, 90, 180, 270), map frame
        "scans_per_orientation": 3,
        "scan_interval_s": 1.0,  # between scan starts while facing one way
        "settle_s": 0.5,  # standing after a turn before the first scan
    },
    "can": {
        "loss_rate": 0.0,  # probability that a frame is lost between board and logger
        "board_time_start_ms": 1_000_000,
        "boot_id": 7,
        "latency_us": 300,  # board-to-host latency of the first frame of a burst
        "frame_time_us": 130,  # bus time per frame (8-byte classic frame at 1 Mbit/s)
    },
    "faults": {  # bus and board faults (faults.py), all off; their own random stream; times = walk time
        "burst_rate": 0.0,  # probability per frame that a loss burst starts there
        "burst_frames": 20,  # frames lost per burst, 1..10000
        "silence_at_s": [],  # starts of windows in which no frame arrives
        "silence_s": 5.0,  # length of each silence window
        "duplicate_rate": 0.0,  # probability that a frame arrives twice
        "reorder_rate": 0.0,  # probability that a frame arrives after the next reorder_frames frames
        "reorder_frames": 1,  # 1..100
        "corrupt_rate": 0.0,  # probability that a frame's payload has corrupt_bits bits flipped
        "corrupt_bits": 1,  # distinct random bits flipped per corrupted frame, 1..64
        "reset_at_s": [],  # board resets: new boot_id, BOARD_TIME first, board time and counters restart
        "reset_down_ms": 200,  # the board sends nothing for this long after a reset
        "reset_time_start_ms": 0,  # board time of the first frame after a reset, 0..2**32-1
        "implausible_at_s": [],  # one implausible IMU sample (implausible_signal) at each of these times
        "implausible_rate": 0.0,  # probability per frame of implausible_signal's message
        "implausible_signal": "accel_z",  # accel_x..z, gyro_x..z
        "implausible_mode": "bitflip",  # "bitflip": sign bit flipped (9.8 -> -147 m/s2); "full_scale"
        "board_time_stuck_at_s": [],  # from each: BOARD_TIME repeats the board time it had then
        "board_time_stuck_s": 60.0,  # for this long, 0..86400 (> 0)
        "imu_failed_at_s": [],  # from each: every IMU signal reads full scale (largest raw value)
        "imu_failed_s": 60.0,  # for this long, 0..86400 (> 0; past the walk's end: for good)
    },
    **SOURCE_DEFAULTS,  # [ble], [gnss], [landmark] (scenario_sources.py)
}


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: ``data`` has every key of DEFAULTS; ``source`` names where it came from."""

    data: dict
    source: str = "<built-in default>"

    def __getitem__(self, key: str) -> Any:
        return self.data[key]

    @property
    def seed(self) -> int:
        return int(self.data["seed"])

    def with_overrides(self, **dotted: Any) -> "Scenario":
        """Copy with keys replaced, e.g. ``with_overrides(seed=3, **{"can.loss_rate": 0.1})``; None = keep."""
        data = copy.deepcopy(self.data)
        for key, value in dotted.items():
            if value is None:
                continue
            node = data
            parts = key.split(".")
            for p in parts[:-1]:
                node = node[p]
            node[parts[-1]] = value
        validate_values(data, "<command line>")
        return Scenario(data=data, source=self.source)


def _merge(defaults: dict, user: dict, source: str, prefix: str = "") -> dict:
    out = copy.deepcopy(defaults)
    for key, value in user.items():
        name = f"{prefix}{key}"
        if key not in defaults:
            raise ScenarioError(source, f"unknown key '{name}' (known here: {', '.join(defaults)})")
        dflt = defaults[key]
        if isinstance(dflt, dict):
            if not isinstance(value, dict):
                raise ScenarioError(source, f"key '{name}' must be a table")
            out[key] = _merge(dflt, value, source, prefix=f"{name}.")
        elif key == "pause":
            if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
                raise ScenarioError(source, f"key '{name}' must be an array of tables ([[walk.pause]])")
            pauses = []
            for i, p in enumerate(value):
                for k in p:
                    if k not in ("at_m", "duration_s"):
                        raise ScenarioError(
                            source, f"unknown key '{name}[{i}].{k}' (known: at_m, duration_s)"
                        )
                if set(p) != {"at_m", "duration_s"}:
                    raise ScenarioError(source, f"key '{name}[{i}]' needs both at_m and duration_s")
                for k in p:
                    if isinstance(p[k], bool) or not isinstance(p[k], (int, float)):
                        raise ScenarioError(source, f"key '{name}[{i}].{k}' must be a number")
                pauses.append({"at_m": float(p["at_m"]), "duration_s": float(p["duration_s"])})
            out[key] = pauses
        elif isinstance(dflt, list) and not dflt:  # an empty default: a list of any length (times)
            if not isinstance(value, list) or any(
                isinstance(v, bool) or not isinstance(v, (int, float)) for v in value
            ):
                raise ScenarioError(source, f"key '{name}' must be a list of numbers")
            out[key] = [float(v) for v in value]
        elif isinstance(dflt, list):
            if (
                not isinstance(value, list)
                or len(value) != len(dflt)
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)
            ):
                raise ScenarioError(source, f"key '{name}' must be a list of {len(dflt)} numbers")
            out[key] = [float(v) for v in value]
        elif isinstance(dflt, bool):
            if not isinstance(value, bool):
                raise ScenarioError(source, f"key '{name}' must be true or false")
            out[key] = value
        elif isinstance(dflt, str):  # (strings are checked against their choices in _validate_values)
            if not isinstance(value, str):
                raise ScenarioError(source, f"key '{name}' must be a string")
            out[key] = value
        elif isinstance(dflt, int) and not isinstance(dflt, bool):
            if isinstance(value, bool) or not isinstance(value, int):
                raise ScenarioError(source, f"key '{name}' must be an integer")
            out[key] = value
        else:  # float
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ScenarioError(source, f"key '{name}' must be a number")
            out[key] = float(value)
    return out


def _pace_scenario(pace: str) -> dict:
    return {
        "walk": {
            "route": "loop",
            "laps": 2.0,
            "pace": pace,
            "pause": [{"at_m": 60.0, "duration_s": 4.0}, {"at_m": 170.0, "duration_s": 5.0}],
        }
    }


def _aadr2015_scenario(pace: str | None = None, survey: bool = False) -> dict:
    """The aadr2015 foyer: the track at one pace, or the survey of its 67 calibration points."""
    out = {"world": {"name": "aadr2015"}, "radio": {"body_loss_db": 3.0}}
    if survey:
        out["walk"] = {"pause": []}
        out["survey"] = {"enabled": True, "layout": "world"}
    else:
        out["walk"] = {"route": "track", "pace": pace, "pause": []}
    return out


# name -> TOML-like overrides of DEFAULTS
BUILTIN: dict[str, dict] = {
    "default": {},
    "pace_slow": _pace_scenario("slow"),
    "pace_normal": _pace_scenario("normal"),
    "pace_fast": _pace_scenario("fast"),
    "office_survey": {"walk": {"pause": []}, "survey": {"enabled": True}},
    "aadr2015_slow": _aadr2015_scenario("slow"),
    "aadr2015": _aadr2015_scenario("normal"),
    "aadr2015_fast": _aadr2015_scenario("fast"),
    "aadr2015_survey": _aadr2015_scenario(survey=True),
    # world campus: indoor -> west door (landmark) -> 66 m outdoors (GNSS) -> south door (landmark) -> indoor
    "campus": {"world": {"name": "campus"}, "walk": {"route": "track", "pause": []}},
    "campus_survey": {"world": {"name": "campus"}, "walk": {"pause": []}, "survey": {"enabled": True}},
    # world campus2: outdoors -> A (door, stairs 0->1, elevator 1->2, 2->0) -> outdoors -> B; its survey
    "campus2": {"world": {"name": "campus2"}, "walk": {"route": "legs", "pause": []}},
    "campus2_survey": {
        "world": {"name": "campus2"},
        "walk": {"pause": []},
        "survey": {"enabled": True, "layout": "world"},
    },
}


def default_scenario() -> Scenario:
    return Scenario(data=copy.deepcopy(DEFAULTS))


def builtin_scenario(name: str) -> Scenario:
    """A built-in named scenario (``BUILTIN``)."""
    if name not in BUILTIN:
        raise ScenarioError(name, f"unknown built-in scenario (known: {', '.join(BUILTIN)})")
    source = "<built-in default>" if name == "default" else f"<built-in {name}>"
    data = _merge(DEFAULTS, BUILTIN[name], source)
    validate_values(data, source)
    return Scenario(data=data, source=source)


def resolve_scenario(name_or_path: str | None) -> Scenario:
    """``None`` → the default; a built-in name → that scenario; anything else → a TOML file path."""
    if name_or_path is None:
        return default_scenario()
    if name_or_path in BUILTIN:
        return builtin_scenario(name_or_path)
    path = Path(name_or_path)
    if not path.exists() and path.suffix == "" and len(path.parts) == 1:
        raise ScenarioError(name_or_path, f"neither a built-in scenario ({', '.join(BUILTIN)}) nor a file")
    return load_scenario(path)


def parse_scenario(text: str, source: str = "<string>") -> Scenario:
    try:
        user = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(source, f"bad TOML: {e}") from None
    data = _merge(DEFAULTS, user, source)
    validate_values(data, source)
    return Scenario(data=data, source=source)


def load_scenario(path: str | Path) -> Scenario:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise ScenarioError(str(path), f"cannot read scenario file: {e.strerror or e}") from None
    except UnicodeDecodeError:
        raise ScenarioError(str(path), "not UTF-8 text") from None
    return parse_scenario(text, source=str(path))
