"""The ``aadr2015`` world: the foyer of Jäger, Süß and Becker's auto-adaptive dead-reckoning experiment
(8 access points, 67 calibration points on a 2 m grid, a ~70 m track with 14 reference points); the model
is described in ``world.py``'s module docstring and hil-sim/README.md."""

from __future__ import annotations

import numpy as np

from .world import AccessPoint, MagZone, World, _rect, aps_from_spec

# --- the aadr2015 foyer (Jäger, Süß, Becker: 8 APs, 67 calibration points, 70 m track, 14 reference points)
FOYER_W_M, FOYER_H_M = 20.0, 14.0
FOYER_CORE_M = (12.0, 6.0, 14.0, 12.0)  # concrete core (lift and service shaft)
FOYER_PILLARS_M = ((6.0, 10.0), (14.0, 4.0))  # 0.5 m concrete pillars (between grid lines)
CONCRETE_LOSS_DB = 15.0  # per concrete wall (core), cf. ITU-R P.2040 ~10-20 dB
PILLAR_LOSS_DB = 10.0
# the track: from the entrance (south doors) round the foyer, past the steel staircase and through the
# poor-coverage spot east of the core, back west; corners are filleted by the route (radius <= 1 m)
FOYER_TRACK_M = (
    (10.0, 1.0),
    (10.0, 4.0),
    (2.0, 4.0),
    (2.0, 8.5),
    (10.5, 8.5),
    (10.5, 13.0),
    (16.0, 13.0),
    (16.0, 4.5),
    (18.5, 4.5),
    (18.5, 1.5),
    (4.5, 1.5),
    (4.5, 6.3),
    (11.2, 6.3),
)
# 14 reference points on straight stretches of the track (>= 1.2 m from every corner), in walking order,
# about 5 m apart; (16, 11.8) is beside the steel staircase, (16, 7.1) in the poor-coverage spot
FOYER_REFERENCE_M = (
    (10.0, 2.8),
    (5.3, 4.0),
    (2.0, 6.1),
    (4.9, 8.5),
    (9.3, 8.5),
    (11.7, 13.0),
    (16.0, 11.8),
    (16.0, 7.1),
    (18.5, 3.3),
    (15.8, 1.5),
    (10.4, 1.5),
    (5.7, 1.5),
    (5.7, 6.3),
    (9.9, 6.3),
)


def _foyer_walls() -> tuple[np.ndarray, np.ndarray]:
    walls, loss = [], []

    def add(segments, db=np.nan):
        for seg in segments:
            walls.append(seg)
            loss.append(db)

    add(_rect(0.0, 0.0, FOYER_W_M, FOYER_H_M, [("bottom", 10.0, 2.4)]))  # facade, glass entrance doors
    add(_rect(*FOYER_CORE_M), CONCRETE_LOSS_DB)
    for x, y in FOYER_PILLARS_M:
        add(_rect(x - 0.25, y - 0.25, x + 0.25, y + 0.25), PILLAR_LOSS_DB)
    add([(0.0, 10.0, 4.0, 10.0), (4.0, 10.0, 4.0, 12.6)])  # cloakroom (drywall), door north-east
    return np.asarray(walls, float), np.asarray(loss, float)


def _foyer_aps() -> tuple[AccessPoint, ...]:
    # (x_m, y_m, channel, tx_power_dbm): on the facade and walls, one on the ceiling west of the core;
    # none in the north-east, so the spot east of the core hears most APs through the core only
    spec = [
        (1.0, 1.0, 1, 17.0),
        (7.0, 0.5, 36, 20.0),
        (0.5, 7.0, 6, 17.0),
        (6.0, 13.5, 11, 17.0),
        (10.0, 13.5, 44, 20.0),
        (10.0, 7.0, 6, 16.0),
        (17.0, 0.5, 1, 17.0),
        (19.5, 5.0, 149, 20.0),
    ]
    return aps_from_spec(spec, 0x00_1A_2B_30_00_00)


def aadr2015_world(map_rotation_deg: float = 20.0) -> World:
    walls, loss = _foyer_walls()
    blocked = [FOYER_CORE_M] + [(x - 0.25, y - 0.25, x + 0.25, y + 0.25) for x, y in FOYER_PILLARS_M]
    # the paper's 67 calibration points: the 2 m grid (1, 1) .. (19, 13) without the 3 inside the core
    cal = [
        (x, y, 0.0)
        for y in range(1, 14, 2)
        for x in range(1, 20, 2)
        if not (FOYER_CORE_M[0] < x < FOYER_CORE_M[2] and FOYER_CORE_M[1] < y < FOYER_CORE_M[3])
    ]
    return World(
        name="aadr2015",
        floor_w_m=FOYER_W_M,
        floor_h_m=FOYER_H_M,
        walls_m=walls,
        walls_loss_db=loss,
        aps=_foyer_aps(),
        loop_corners_m=np.array([[5.0, 2.5], [18.0, 2.5], [18.0, 12.8], [5.0, 12.8]]),
        start_xy_m=(8.0, 2.5),
        map_rotation_deg=map_rotation_deg,
        n_floors=1,
        mag_zones=(
            MagZone("steel staircase", 16.5, 12.2, 2.5, (0,), gain=1.5, azimuth_deg=45.0, dip_deg=-15.0),
        ),
        blocked_m=np.asarray(blocked, float),
        grid_origin_m=(1.0, 1.0),
        survey_points_m=np.asarray(cal, float),
        track_m=FOYER_TRACK_M,
        reference_points_m=np.asarray(FOYER_REFERENCE_M, float),
        poor_coverage_m=(14.5, 6.0, 18.0, 10.5),
        description="aadr2015 foyer, 20 m x 14 m, concrete core, 8 APs (Jäger, Süß, Becker)",
    )
