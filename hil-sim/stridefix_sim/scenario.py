"""Scenario: everything that defines one simulated run, read from a TOML file (tomllib) or built in.

A scenario names the world, the walk (laps, pauses, cadence, stride), the sensor imperfections (noise,
biases, board mounting rotation), the radio model, the CAN link (frame loss, board time start), the seed
and the duration. Every key has a default (``DEFAULTS`` below, the built-in demo scenario: 2 laps of the
default office loop with 3 pauses, about 3.5 minutes). A file only needs the keys it changes. An unknown
key, a wrong type or an out-of-range value raises :class:`ScenarioError` naming the file and the key.
"""
from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

# Built-in default scenario. Units are in the key names; comments give ranges.
DEFAULTS: dict[str, Any] = {
    "seed": 1,
    "duration_s": 0.0,               # 0: until the walk ends plus trailing_still_s
    "world": {
        "name": "default",
        "map_rotation_deg": 20.0,    # map frame = magnetic east-north frame turned CCW by this angle
    },
    "walk": {
        "laps": 2.0,                 # laps of the corridor loop (fractions allowed)
        "start_still_s": 3.0,        # standing still before the first step
        "trailing_still_s": 3.0,     # standing still after the last step (when duration_s = 0)
        "cadence_hz": 1.8,           # mean step rate, 1.6..2.0 for normal walking
        "cadence_jitter": 0.03,      # step-to-step relative std of the step period
        "stride_m": 0.72,            # mean step length
        "stride_jitter": 0.04,       # step-to-step relative std of the step length
        "speed_mps": 0.0,            # > 0: overrides stride_m = speed_mps / cadence_hz
        "turn_radius_m": 0.8,        # corner radius of the route (centre line)
        "max_yaw_rate_dps": 120.0,   # corners are widened so that speed/radius stays below this
        "bounce_peak_mps2": 3.0,     # vertical acceleration peak per step (gravity removed)
        "bounce_jitter": 0.1,        # step-to-step relative std of that peak
        "surge": 0.12,               # forward speed oscillation within a step, fraction of the mean
        "sway_mps2": 0.4,            # lateral acceleration amplitude (half the step rate)
        "pause": [                   # [[walk.pause]] at_m (distance walked), duration_s
            {"at_m": 40.0, "duration_s": 5.0},
            {"at_m": 120.0, "duration_s": 4.0},
            {"at_m": 200.0, "duration_s": 6.0},
        ],
    },
    "mounting": {                    # board axes relative to the body (x forward, y left, z up), ZYX
        "roll_deg": 0.0,
        "pitch_deg": 0.0,
        "yaw_deg": 0.0,
    },
    "imu": {
        "accel_noise_mps2": 0.02,    # white noise std per sample
        "accel_bias_mps2": [0.03, -0.02, 0.05],
        "gyro_noise_dps": 0.05,
        "gyro_bias_dps": [0.10, -0.08, 0.05],
    },
    "mag": {
        "field_ut": 48.0,            # total intensity of the earth field
        "dip_deg": 60.0,             # inclination, positive = pointing down
        "noise_ut": 0.3,
        "hard_iron_ut": [0.0, 0.0, 0.0],
    },
    "baro": {
        "sea_level_pa": 101325.0,
        "sensor_height_m": 1.1,      # board height above the floor
        "noise_pa": 1.5,
        "temperature_degc": 22.5,    # board temperature at start; warms by 2 degC with 2 min time constant
        "temperature_noise_degc": 0.05,
    },
    "radio": {
        "path_loss_exponent": 2.5,
        "wall_loss_db": 5.0,         # per crossed wall
        "shadowing_db": 2.5,         # gaussian noise std per reading
        "floor_dbm": -95.0,          # detection floor: weaker APs are not reported
        "scan_interval_min_s": 2.0,
        "scan_interval_max_s": 4.0,
        "scan_duration_ms": 120,     # results are sent this long after the scan started
    },
    "can": {
        "loss_rate": 0.0,            # probability that a frame is lost between board and logger
        "board_time_start_ms": 1_000_000,
        "boot_id": 7,
        "latency_us": 300,           # board-to-host latency of the first frame of a burst
        "frame_time_us": 130,        # bus time per frame (8-byte classic frame at 1 Mbit/s)
    },
}


class ScenarioError(ValueError):
    """A scenario file could not be read or holds an unknown key or a bad value."""

    def __init__(self, source: str, message: str):
        super().__init__(f"{source}: {message}")
        self.source = source


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
        _validate_values(data, "<command line>")
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
                        raise ScenarioError(source, f"unknown key '{name}[{i}].{k}' (known: at_m, duration_s)")
                if set(p) != {"at_m", "duration_s"}:
                    raise ScenarioError(source, f"key '{name}[{i}]' needs both at_m and duration_s")
                for k in p:
                    if isinstance(p[k], bool) or not isinstance(p[k], (int, float)):
                        raise ScenarioError(source, f"key '{name}[{i}].{k}' must be a number")
                pauses.append({"at_m": float(p["at_m"]), "duration_s": float(p["duration_s"])})
            out[key] = pauses
        elif isinstance(dflt, list):
            if (not isinstance(value, list) or len(value) != len(dflt)
                    or any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in value)):
                raise ScenarioError(source, f"key '{name}' must be a list of {len(dflt)} numbers")
            out[key] = [float(v) for v in value]
        elif isinstance(dflt, str):
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


def _validate_values(d: dict, source: str) -> None:
    def check(ok: bool, key: str, what: str) -> None:
        if not ok:
            raise ScenarioError(source, f"key '{key}' {what}")

    w, c, r = d["walk"], d["can"], d["radio"]
    check(d["world"]["name"] == "default", "world.name", "must be 'default' (the only built-in world)")
    check(d["duration_s"] >= 0, "duration_s", "must be >= 0")
    check(w["laps"] > 0, "walk.laps", "must be > 0")
    check(0.5 <= w["cadence_hz"] <= 3.0, "walk.cadence_hz", "must be in 0.5..3.0")
    check(0.2 <= w["stride_m"] <= 1.5, "walk.stride_m", "must be in 0.2..1.5")
    check(w["speed_mps"] == 0 or 0.2 <= w["speed_mps"] <= 3.0, "walk.speed_mps", "must be 0 or in 0.2..3.0")
    check(0 <= w["cadence_jitter"] <= 0.2, "walk.cadence_jitter", "must be in 0..0.2")
    check(0 <= w["stride_jitter"] <= 0.2, "walk.stride_jitter", "must be in 0..0.2")
    check(0.1 <= w["turn_radius_m"] <= 1.0, "walk.turn_radius_m", "must be in 0.1..1.0 (corridor half width)")
    check(w["max_yaw_rate_dps"] > 10, "walk.max_yaw_rate_dps", "must be > 10")
    check(0 <= w["surge"] < 0.5, "walk.surge", "must be in 0..0.5")
    check(0 <= w["bounce_jitter"] < 0.5, "walk.bounce_jitter", "must be in 0..0.5")
    check(w["start_still_s"] >= 0 and w["trailing_still_s"] >= 0, "walk.start_still_s", "must be >= 0")
    for i, p in enumerate(w["pause"]):
        check(p["at_m"] > 0 and p["duration_s"] >= 0, f"walk.pause[{i}]", "needs at_m > 0 and duration_s >= 0")
    check(0 <= c["loss_rate"] < 1, "can.loss_rate", "must be in 0..1")
    check(0 <= c["board_time_start_ms"] < 2**32, "can.board_time_start_ms", "must be in 0..2**32-1")
    check(0 <= c["boot_id"] <= 255, "can.boot_id", "must be in 0..255")
    check(0 < r["scan_interval_min_s"] <= r["scan_interval_max_s"], "radio.scan_interval_min_s",
          "must be > 0 and <= radio.scan_interval_max_s")
    check(0 <= r["scan_duration_ms"] < 1000 * r["scan_interval_min_s"], "radio.scan_duration_ms",
          "must be >= 0 and shorter than the scan interval")


def default_scenario() -> Scenario:
    return Scenario(data=copy.deepcopy(DEFAULTS))


def parse_scenario(text: str, source: str = "<string>") -> Scenario:
    try:
        user = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(source, f"bad TOML: {e}") from None
    data = _merge(DEFAULTS, user, source)
    _validate_values(data, source)
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
