"""The value rules of a scenario (scenario.py): every number finite, every key in its range.

:func:`validate_values` runs on every merged scenario — a file, a built-in one, and the command line's
overrides (``Scenario.with_overrides``, which bypass the file's type checks) — so a NaN, an infinity
or a value no walk, sensor or bus could have stops with :class:`ScenarioError` naming the key, and
``stridefix sim`` exits 2 with that one line, before anything is simulated: a NaN mounting angle gave
all-zero accelerometer frames, an infinite duration or pause never ended. First every number (list
elements and the pauses' ``at_m``/``duration_s`` included) must be finite, then the ranges:
:data:`RANGES` for the keys that only need one, then the keys whose rule involves another key or
the world.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from .faults import validate as validate_faults
from .scenario_sources import validate_sources

Check = Callable[[bool, str, str], None]


class ScenarioError(ValueError):
    """A scenario file could not be read or holds an unknown key or a bad value."""

    def __init__(self, source: str, message: str):
        super().__init__(f"{source}: {message}")
        self.source = source


#: (key, lowest, highest): the keys whose rule is a plain closed range (lists: every element).
#: Limits are physical or what the models hold (a week of walk, a board's operating temperature, the
#: barometric pressure of any inhabited place); the keys with a rule of their own are below.
RANGES: tuple[tuple[str, float, float], ...] = (
    ("seed", 0, 2**63 - 1),
    ("duration_s", 0, 604_800),
    ("world.map_rotation_deg", -360, 360),
    ("walk.laps", 0, 1000),
    ("walk.start_still_s", 0, 3600),
    ("walk.trailing_still_s", 0, 3600),
    ("walk.max_yaw_rate_dps", 0, 2000),
    ("mounting.roll_deg", -360, 360),
    ("mounting.pitch_deg", -360, 360),
    ("mounting.yaw_deg", -360, 360),
    ("imu.accel_noise_mps2", 0, 10),
    ("imu.accel_bias_mps2", -5, 5),
    ("imu.gyro_noise_dps", 0, 10),
    ("imu.gyro_bias_dps", -50, 50),
    ("imu.gyro_bias_rw_dps_per_sqrt_s", 0, 1),
    ("mag.field_ut", 0, 200),
    ("mag.dip_deg", -90, 90),
    ("mag.noise_ut", 0, 50),
    ("mag.hard_iron_ut", -500, 500),
    ("mag.disturbance_scale", 0, 100),
    ("baro.sea_level_pa", 50_000, 120_000),
    ("baro.sensor_height_m", 0, 3),
    ("baro.noise_pa", 0, 100),
    ("baro.drift_pa_per_sqrt_h", 0, 1000),
    ("baro.temperature_degc", -40, 85),
    ("baro.temperature_noise_degc", 0, 5),
    ("radio.path_loss_exponent", 1, 6),
    ("radio.wall_loss_db", 0, 50),
    ("radio.floor_loss_db", 0, 100),
    ("radio.shadowing_db", 0, 20),
    ("radio.floor_dbm", -127, 0),
    ("radio.scan_interval_max_s", 0, 3600),
    ("survey.scan_interval_s", 0, 60),
    ("can.latency_us", 0, 1_000_000),
    ("can.frame_time_us", 0, 100_000),
    ("gnss.tau_s", 0, 3600),
    ("gnss.sigma_alt_m", 0, 100),
    ("gnss.door_range_m", 0, 100),
    ("gnss.door_sigma_factor", 1, 100),
)


def _get(d: dict, key: str) -> Any:
    for part in key.split("."):
        d = d[part]
    return d


def _check_finite(d: dict, check: Check, prefix: str = "") -> None:
    """Every number of ``d`` (nested tables, lists, the pauses' fields) finite; names the first key."""
    for key, value in d.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            _check_finite(value, check, f"{name}.")
        elif key == "pause" and isinstance(value, list):
            for i, p in enumerate(value):
                for k, v in p.items():
                    check(math.isfinite(v), f"{name}[{i}].{k}", f"must be a finite number, not {v!r}")
        elif isinstance(value, list):
            bad = [v for v in value if not math.isfinite(v)]
            check(not bad, name, f"must hold finite numbers, not {bad[0]!r}" if bad else "")
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            check(math.isfinite(value), name, f"must be a finite number, not {value!r}")


def _check_ranges(d: dict, check: Check) -> None:
    for key, lo, hi in RANGES:
        value = _get(d, key)
        values = value if isinstance(value, list) else [value]
        check(all(lo <= v <= hi for v in values), key, f"must be in {lo}..{hi}, not {value!r}")
    for i, p in enumerate(d["walk"]["pause"]):
        check(0 < p["at_m"] <= 1e6, f"walk.pause[{i}].at_m", f"must be in 0..1e6 (> 0), not {p['at_m']!r}")
        check(
            0 <= p["duration_s"] <= 3600,
            f"walk.pause[{i}].duration_s",
            f"must be in 0..3600, not {p['duration_s']!r}",
        )


def validate_values(d: dict, source: str) -> None:
    """Every value of a merged scenario (every key of DEFAULTS present) finite and in its range;
    raises :class:`ScenarioError` naming ``source`` and the first key that is not."""

    def check(ok: bool, key: str, what: str) -> None:
        if not ok:
            raise ScenarioError(source, f"key '{key}' {what}")

    _check_finite(d, check)
    _check_ranges(d, check)

    from .worlds import WORLDS

    w, c, r, p, st, el = d["walk"], d["can"], d["radio"], d["person"], d["stairs"], d["elevator"]
    sv = d["survey"]
    check(d["world"]["name"] in WORLDS, "world.name", f"must be one of {', '.join(repr(k) for k in WORLDS)}")
    world = WORLDS[d["world"]["name"]]()
    check(d["duration_s"] >= 0, "duration_s", "must be >= 0")
    routes = ("tour", "loop", "track", "legs")
    check(w["route"] in routes, "walk.route", "must be 'tour', 'loop', 'track' or 'legs'")
    if not sv["enabled"]:
        check(
            w["route"] != "tour" or (world.stairs is not None and world.elevator is not None),
            "walk.route",
            f"'tour' needs stairs and an elevator (world {world.name!r} has none)",
        )
        check(
            w["route"] != "track" or world.track_m is not None,
            "walk.route",
            f"'track' needs a world with a track (world {world.name!r} has none)",
        )
        check(
            w["route"] != "legs" or bool(world.walk_legs),
            "walk.route",
            f"'legs': world {world.name!r} has none",
        )
    check(sv["layout"] in ("grid", "world"), "survey.layout", "must be 'grid' or 'world'")
    check(
        sv["layout"] != "world" or world.survey_points_m is not None,
        "survey.layout",
        f"'world' needs a world with its own calibration points (world {world.name!r} has none)",
    )
    check(0.5 <= sv["spacing_m"] <= 20.0, "survey.spacing_m", "must be in 0.5..20")
    check(0 <= sv["margin_m"] <= 2.0, "survey.margin_m", "must be in 0..2")
    check(-1 <= sv["floor"] < world.n_floors, "survey.floor", f"must be -1 (all) or 0..{world.n_floors - 1}")
    check(1 <= sv["orientations"] <= 8, "survey.orientations", "must be in 1..8")
    check(1 <= sv["scans_per_orientation"] <= 20, "survey.scans_per_orientation", "must be in 1..20")
    check(sv["settle_s"] >= 0, "survey.settle_s", "must be >= 0")
    check(
        sv["scan_interval_s"] * 1000 > r["scan_duration_ms"],
        "survey.scan_interval_s",
        "must be longer than radio.scan_duration_ms",
    )
    check(0 <= r["body_loss_db"] <= 30, "radio.body_loss_db", "must be in 0..30")
    check(w["pace"] in ("slow", "normal", "fast"), "walk.pace", "must be 'slow', 'normal' or 'fast'")
    check(w["laps"] > 0, "walk.laps", "must be > 0")
    check(
        w["cadence_hz"] == 0 or 0.5 <= w["cadence_hz"] <= 3.0, "walk.cadence_hz", "must be 0 or in 0.5..3.0"
    )
    check(w["stride_m"] == 0 or 0.2 <= w["stride_m"] <= 1.5, "walk.stride_m", "must be 0 or in 0.2..1.5")
    check(w["speed_mps"] == 0 or 0.2 <= w["speed_mps"] <= 3.0, "walk.speed_mps", "must be 0 or in 0.2..3.0")
    check(0 <= w["cadence_jitter"] <= 0.2, "walk.cadence_jitter", "must be in 0..0.2")
    check(0 <= w["stride_jitter"] <= 0.2, "walk.stride_jitter", "must be in 0..0.2")
    check(0.1 <= w["turn_radius_m"] <= 1.0, "walk.turn_radius_m", "must be in 0.1..1.0 (corridor half width)")
    check(w["max_yaw_rate_dps"] > 10, "walk.max_yaw_rate_dps", "must be > 10")
    check(0 <= w["pendulum_recovery"] <= 1.0, "walk.pendulum_recovery", "must be in 0..1")
    check(0 <= w["bounce_jitter"] < 0.5, "walk.bounce_jitter", "must be in 0..0.5")
    check(0 <= w["sway_mps2"] <= 3.0, "walk.sway_mps2", "must be in 0..3")
    check(
        p["weinberg_k"] == 0 or 0.2 <= p["weinberg_k"] <= 1.0, "person.weinberg_k", "must be 0 or in 0.2..1.0"
    )
    check(
        p["stride_scale"] == 0 or 0.5 <= p["stride_scale"] <= 1.5,
        "person.stride_scale",
        "must be 0 or in 0.5..1.5",
    )
    check(
        p["cadence_scale"] == 0 or 0.5 <= p["cadence_scale"] <= 1.5,
        "person.cadence_scale",
        "must be 0 or in 0.5..1.5",
    )
    check(0.5 <= st["cadence_hz"] <= 3.0, "stairs.cadence_hz", "must be in 0.5..3.0")
    check(0 <= st["bounce_p2p_mps2"] <= 20.0, "stairs.bounce_p2p_mps2", "must be in 0..20")
    check(0.2 <= el["speed_mps"] <= 5.0, "elevator.speed_mps", "must be in 0.2..5")
    check(0.1 <= el["accel_mps2"] <= 3.0, "elevator.accel_mps2", "must be in 0.1..3")
    check(el["door_s"] >= 0 and el["exit_s"] >= 0, "elevator.door_s", "must be >= 0 (and exit_s too)")
    check(d["imu"]["gyro_bias_rw_dps_per_sqrt_s"] >= 0, "imu.gyro_bias_rw_dps_per_sqrt_s", "must be >= 0")
    check(
        all(abs(v) < 0.2 for v in d["imu"]["gyro_scale_error"]), "imu.gyro_scale_error", "must be within ±0.2"
    )
    check(d["mag"]["disturbance_scale"] >= 0, "mag.disturbance_scale", "must be >= 0")
    check(d["baro"]["drift_pa_per_sqrt_h"] >= 0, "baro.drift_pa_per_sqrt_h", "must be >= 0")
    check(r["floor_loss_db"] >= 0, "radio.floor_loss_db", "must be >= 0")
    check(w["start_still_s"] >= 0 and w["trailing_still_s"] >= 0, "walk.start_still_s", "must be >= 0")
    for i, p in enumerate(w["pause"]):
        check(
            p["at_m"] > 0 and p["duration_s"] >= 0, f"walk.pause[{i}]", "needs at_m > 0 and duration_s >= 0"
        )
    check(0 <= c["loss_rate"] < 1, "can.loss_rate", "must be in 0..1")
    check(0 <= c["board_time_start_ms"] < 2**32, "can.board_time_start_ms", "must be in 0..2**32-1")
    check(0 <= c["boot_id"] <= 255, "can.boot_id", "must be in 0..255")
    validate_faults(d["faults"], check)
    validate_sources(d, check)
    check(
        0 < r["scan_interval_min_s"] <= r["scan_interval_max_s"],
        "radio.scan_interval_min_s",
        "must be > 0 and <= radio.scan_interval_max_s",
    )
    check(
        0 <= r["scan_duration_ms"] < 1000 * r["scan_interval_min_s"],
        "radio.scan_duration_ms",
        "must be >= 0 and shorter than the scan interval",
    )
