"""Scenario keys of the sources beyond Wi-Fi: BLE advertisements (``[ble]``, ble.py), GNSS fixes
(``[gnss]``, gnss.py) and NFC landmark events (``[landmark]``, landmarks.py). Each runs only where the
world has the thing (beacons, a geo-reference with a footprint and doors, landmark tags), so worlds
without them send exactly what they sent before. Merged into ``scenario.DEFAULTS``."""

from __future__ import annotations

from typing import Any

SOURCE_DEFAULTS: dict[str, Any] = {
    "ble": {
        "enabled": True,  # the board's radio reports the advertisements it hears (worlds with beacons)
        "path_loss_exponent": 2.2,  # log-distance exponent n (indoor 2.4 GHz, cf. radio.path_loss_exponent)
        "shadowing_db": 4.0,  # gaussian std per advertisement (BLE RSSI is noisier than Wi-Fi's)
        "floor_dbm": -100.0,  # receiver sensitivity: weaker advertisements are not heard
        "loss_rate": 0.3,  # probability that an advertisement above the floor is missed (scan window)
        "adv_jitter_ms": 10,  # the spec's advDelay: each interval is lengthened by U(0, this) ms
    },
    "gnss": {
        "enabled": True,  # the receiver reports fixes where it sees the sky (worlds with a geo-reference)
        "period_ms": 1000,  # one fix per second
        "sigma_m": 4.0,  # outdoors: stationary std of each horizontal error axis (first-order Gauss-Markov)
        "tau_s": 45.0,  # correlation time of the error
        "sigma_alt_m": 6.0,  # stationary std of the altitude error (same process, own state)
        "door_range_m": 4.0,  # indoors within this distance of a door to the outside: degraded fixes
        "door_sigma_factor": 3.0,  # the degraded fixes' error (and reported accuracy) x this
        "door_fix_prob": 0.5,  # probability of a fix per period near a door indoors
        "accuracy_jitter": 0.1,  # reported accuracy = sigma x exp(this x N(0, 1)) (an honest estimate)
        "latency_ms": 80,  # the fix's frames go out this long after the fix time
    },
    "landmark": {
        "enabled": True,  # an NFC tag at each door is read when the board passes within radius_m
        "radius_m": 0.5,
        "latency_ms": 50,  # the LANDMARK frame goes out this long after the read
    },
}


def validate_sources(d: dict, check) -> None:
    """Range checks of the source keys (``check(ok, key, what)`` raises ScenarioError)."""
    b, g, lm = d["ble"], d["gnss"], d["landmark"]
    check(1.0 <= b["path_loss_exponent"] <= 6.0, "ble.path_loss_exponent", "must be in 1..6")
    check(0 <= b["shadowing_db"] <= 20, "ble.shadowing_db", "must be in 0..20")
    check(-127 <= b["floor_dbm"] <= 0, "ble.floor_dbm", "must be in -127..0")
    check(0 <= b["loss_rate"] < 1, "ble.loss_rate", "must be in 0..1")
    check(0 <= b["adv_jitter_ms"] <= 100, "ble.adv_jitter_ms", "must be in 0..100")
    check(100 <= g["period_ms"] <= 60_000, "gnss.period_ms", "must be in 100..60000")
    check(0 < g["sigma_m"] <= 100, "gnss.sigma_m", "must be in 0..100 (> 0)")
    check(g["tau_s"] > 0, "gnss.tau_s", "must be > 0")
    check(g["sigma_alt_m"] >= 0, "gnss.sigma_alt_m", "must be >= 0")
    check(g["door_range_m"] >= 0, "gnss.door_range_m", "must be >= 0")
    check(g["door_sigma_factor"] >= 1, "gnss.door_sigma_factor", "must be >= 1")
    check(0 <= g["door_fix_prob"] <= 1, "gnss.door_fix_prob", "must be in 0..1")
    check(0 <= g["accuracy_jitter"] <= 1, "gnss.accuracy_jitter", "must be in 0..1")
    check(0 <= g["latency_ms"] < g["period_ms"], "gnss.latency_ms", "must be >= 0 and < gnss.period_ms")
    check(0 < lm["radius_m"] <= 5, "landmark.radius_m", "must be in 0..5 (> 0)")
    check(0 <= lm["latency_ms"] <= 1000, "landmark.latency_ms", "must be in 0..1000")
