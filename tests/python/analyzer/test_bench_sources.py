"""bench sources' own figures: wall crossings of a pose track against a building description, and the
targets' MET/MISSED (a missing particle scheme is a miss, not a pass)."""

from __future__ import annotations

import numpy as np
from stridefix_lab.bench.sources import GNSS_FRACTION_MIN, crossings, targets, walls_of
from stridefix_sim.building import write_building
from stridefix_sim.worlds import load_world


def test_crossings_count_wall_segments_not_door_gaps(tmp_path):
    write_building(load_world("campus", 20.0), tmp_path / "building.toml")
    walls = walls_of(tmp_path / "building.toml")
    # through the west door (gap y 9.2-10.8 at x = 0) and along the corridor: no crossing
    door = {"x_m": np.array([-3.0, 0.0, 5.0]), "y_m": np.array([10.0, 10.0, 10.0]), "floor": np.zeros(3, int)}
    assert crossings(door, walls) == 0
    # straight through the exterior wall at y = 5, then through the corridor's south wall: two segments cross
    wall = {"x_m": np.array([-3.0, 3.0, 3.0]), "y_m": np.array([5.0, 5.0, 10.0]), "floor": np.zeros(3, int)}
    assert crossings(wall, walls) == 2
    # a floor change between two rows is not a segment
    wall["floor"] = np.array([0, 1, 1])
    assert crossings(wall, walls) == 0


def test_targets_met_and_missed():
    row = {"gnss_within_2sigma_frac": GNSS_FRACTION_MIN + 0.01, "landmark_max_m": 0.4, "wall_crossings": 3}
    bad = {"gnss_within_2sigma_frac": 0.2, "landmark_max_m": float("nan"), "wall_crossings": 0}
    met = {t["figure"]: t["met"] for t in targets({"kalman": row, "ekf": bad, "pdr_only": bad})}
    assert (
        met["kalman: outdoor error <= 2 sigma (fraction)"]
        and met["kalman: distance to the landmark after its event (max)"]
    )
    assert not met["ekf: outdoor error <= 2 sigma (fraction)"]
    assert not met["ekf: distance to the landmark after its event (max)"]
    assert not any(k.startswith("pdr_only") for k in met)  # PDR alone uses no absolute source
    assert not met["particle: pose segments crossing a wall"]  # absent: missed
    assert {t["figure"]: t["met"] for t in targets({"particle": bad})}[
        "particle: pose segments crossing a wall"
    ]
