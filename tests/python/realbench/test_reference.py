"""The textbook references of ``realbench fusion`` (realbench.reference, realbench.reference_sensors):
the plain PDR on a synthetic straight walk, the EKF's χ² gate and reset on a constructed sequence, and a
real run whose results.json carries both reference rows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from stridefix_analyzer.datasets.rawwalk import RawWalk
from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.io.results import REALBENCH_RESULTS_KIND, read_realbench_results
from stridefix_analyzer.scoring.metrics import wrap_pi
from stridefix_lab.realbench import reference as ref
from stridefix_lab.realbench import reference_sensors as sensors

GSD = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "gsd"

STEP_HZ = 2.0  # cadence of the synthetic walk [steps/s]
STRIDE_M = 0.7  # true step length [m]
DURATION_S = 30.0
IMU_HZ = 100.0


def straight_walk(heading_deg: float) -> RawWalk:
    """A phone held flat, its +y axis along ``heading_deg`` (clockwise from +y = north), walked straight
    at STEP_HZ × STRIDE_M: |a| = g + 2 sin(2π·STEP_HZ·t) (one peak per step), no rotation, the earth's
    field (20 µT north, 44 µT down) in the device frame, constant pressure, truth every 5 s."""
    t = np.arange(0.0, DURATION_S, 1.0 / IMU_HZ)
    psi = math.radians(heading_deg)
    acc = np.zeros((len(t), 3))
    acc[:, 2] = sensors.G_MPS2 + 2.0 * np.sin(2 * math.pi * STEP_HZ * t)
    field = np.tile([-20.0 * math.sin(psi), 20.0 * math.cos(psi), -44.0], (len(t), 1))
    t_us = (t * 1e6).astype(np.int64)
    tt = np.arange(0.0, DURATION_S + 1e-9, 5.0)
    dist = STEP_HZ * STRIDE_M * tt
    empty_wifi = {
        "scan": np.zeros(0, np.int64),
        "t_us": np.zeros(0, np.int64),
        "bssid": np.zeros(0, np.int64),
    }
    return RawWalk(
        path=f"synthetic_{heading_deg:g}",
        imu=Table({"t_us": t_us, "accel_mps2": acc, "gyro_radps": np.zeros((len(t), 3))}),
        mag=Table({"t_us": t_us, "field_ut": field}),
        baro=Table({"t_us": t_us[::10], "pressure_pa": np.full(len(t_us[::10]), 101000.0)}),
        wifi=Table(
            {**empty_wifi, "rssi_dbm": np.zeros(0), "freq_mhz": np.zeros(0, np.int32), "age_ms": np.zeros(0)}
        ),
        truth=Table(
            {
                "t_us": (tt * 1e6).astype(np.int64),
                "x_m": dist * math.sin(psi),
                "y_m": dist * math.cos(psi),
                "floor": np.zeros(len(tt), np.int64),
            }
        ),
    )


def test_device_heading_is_the_magnetometer_heading_of_a_level_phone():
    walk = straight_walk(120.0)
    psi = sensors.device_heading(
        walk.imu["t_us"],
        walk.imu["accel_mps2"],
        walk.imu["gyro_radps"],
        walk.mag["t_us"],
        walk.mag["field_ut"],
    )
    assert np.degrees(np.abs(psi - math.radians(120.0))).max() < 0.5


def test_reference_pdr_recovers_distance_and_heading_of_a_straight_walk():
    """K learnt on a training walk (another heading) carries over: the held-out walk's distance within
    2 %, its direction within 2° (the truth-start offset from the magnetometer), every step found ± 1."""
    train, held = sensors.track_of(straight_walk(30.0)), sensors.track_of(straight_walk(-75.0))
    n_true = STEP_HZ * DURATION_S
    assert abs(len(held.step_t_us) - n_true) <= 1
    poses, info = ref.run_references(held, [train], [0.0], true_start=True)
    assert math.isfinite(info["K"])
    pdr = poses["true_start"][ref.REFERENCE_PDR]
    tr = held.truth
    # at the last truth time: the truth distance and direction walked from the start
    i = np.searchsorted(pdr["t_us"], tr["t_us"][-1], side="right") - 1
    dx, dy = pdr["x_m"][i] - tr["x_m"][0], pdr["y_m"][i] - tr["y_m"][0]
    true_d = math.hypot(tr["x_m"][-1] - tr["x_m"][0], tr["y_m"][-1] - tr["y_m"][0])
    assert math.hypot(dx, dy) == pytest.approx(true_d, rel=0.02)
    assert abs(math.degrees(float(wrap_pi(math.atan2(dx, dy) - math.radians(-75.0))))) < 2.0
    assert set(pdr["floor"].tolist()) == {0}  # constant pressure: no floor change


def _ekf(pos_sigma_m: float = 0.0) -> ref.Ekf:
    return ref.Ekf(ref.Start(0, 0.0, 0.0, 0), 0.0, pos_sigma_m, math.radians(5.0))


def test_ekf_gate_is_chi2_two_dof_99_percent():
    """Position σ = fix σ = 3 m per axis: S = 2σ²·I, so d² = |ν|²/18 against 9.21."""
    gate_m = math.sqrt(ref.GATE_CHI2 * 2) * ref.FIX_SIGMA_M
    inside, outside = gate_m * 0.999, gate_m * 1.001
    ekf = _ekf(ref.FIX_SIGMA_M)
    assert ekf.update(np.array([outside, 0.0])) == "rejected"
    assert ekf.x[:2].tolist() == [0.0, 0.0]
    ekf = _ekf(ref.FIX_SIGMA_M)
    assert ekf.update(np.array([inside, 0.0])) == "accepted"
    # equal prior and fix variances: half way
    assert ekf.x[0] == pytest.approx(inside / 2)


def test_ekf_resets_to_the_third_consecutive_rejected_fix():
    ekf = _ekf(1.0)
    far = np.array([40.0, -10.0])
    assert [ekf.update(far) for _ in range(2)] == ["rejected", "rejected"]
    assert ekf.x[:2].tolist() == [0.0, 0.0]
    assert ekf.update(far) == "reset"
    assert ekf.x[:2].tolist() == far.tolist()
    assert np.allclose(ekf.P[:2, :2], np.eye(2) * ref.FIX_SIGMA_M**2)
    assert ekf.update(far + 1.0) == "accepted"


def test_ekf_an_accepted_fix_restarts_the_rejection_count():
    ekf = _ekf(1.0)
    far, near = np.array([40.0, 0.0]), np.array([0.5, 0.0])
    out = [ekf.update(f) for f in (far, far, near, far, far)]
    assert out == ["rejected", "rejected", "accepted", "rejected", "rejected"]
    assert ekf.update(far) == "reset"


def test_ekf_prediction_follows_heading_plus_bias():
    ekf = ref.Ekf(ref.Start(0, 1.0, 2.0, 0), math.radians(90.0), 0.0, 0.1)
    ekf.predict(0.7, 0.0)  # device heading north + 90° bias: the walk goes east
    assert ekf.x[:2] == pytest.approx([1.7, 2.0])


@pytest.fixture(scope="module")
def gsd_results(tmp_path_factory, cli, stridefixd, lab) -> dict:
    """GIVEN `stridefix-lab realbench fusion --format gsd <gsd> --limit 3 --true-start` (3 real walks)."""
    if not GSD.is_dir() or not list(GSD.glob("*.txt")):
        pytest.skip(
            f"real GetSensorData logs not found at {GSD} (needs ../shared/data beside the repository)"
        )
    out = tmp_path_factory.mktemp("realbench_reference") / "results.json"
    proc = lab(
        "realbench", "fusion", "--format", "gsd", str(GSD), "--limit", "3", "--true-start",
        "--stridefixd", str(stridefixd), "--out", str(out), "--quiet",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    return dict(read_realbench_results(out))


def test_real_run_has_both_reference_rows_with_the_schemes_keys(gsd_results):
    assert gsd_results["kind"] == REALBENCH_RESULTS_KIND
    g = gsd_results["groups"][0]
    for key in ("summary", "summary_true_start"):
        refs = g[key]["references"]
        assert set(refs) == set(ref.NAMES)
        some_scheme = next(iter(g[key]["schemes"].values()))
        for row in refs.values():
            assert set(row) == set(some_scheme)
            assert row["n"] > 0 and math.isfinite(row["ipin_score"])
        assert isinstance(g[key]["loses_to_reference"], list)
        assert not set(refs) & set(g[key]["schemes"])  # references are not schemes
    for row in g["walk_rows"]:
        for tag in ("fixes", "true_start"):
            for name in ref.NAMES:
                r = row["references"][tag][name]
                assert set(r) == set(next(iter(row[tag].values())))
    # the truth-initialised references score the same truth samples as the schemes
    ts = g["summary_true_start"]
    assert {r["n"] for r in ts["references"].values()} == {ts["schemes"]["pdr_only"]["n"]}
