"""Gait: the three paces (cadence, stride), the person drawn from the seed, Weinberg's law between the
vertical acceleration and the step length, one step event per step, the inverted-pendulum phase."""

from __future__ import annotations

import numpy as np
import pytest
from stridefix_sim.gait import make_person
from stridefix_sim.pipeline import simulate
from stridefix_sim.scenario import builtin_scenario
from stridefix_sim.walker import ACT_WALK, MODE_WALK

PACES = ("slow", "normal", "fast")
# pace: (cadence range Hz, stride range m), the nominal values ± the person's scale
RANGES = {
    "slow": ((1.35, 1.65), (0.47, 0.63)),
    "normal": ((1.62, 1.98), (0.60, 0.80)),
    "fast": ((1.90, 2.30), (0.73, 0.97)),
}


@pytest.fixture(scope="module")
def pace_runs():
    """GIVEN each named pace scenario, the first 60 s (part of a lap of floor 0, one pause)."""
    return {p: simulate(builtin_scenario(f"pace_{p}").with_overrides(duration_s=60.0)) for p in PACES}


def interior_walking_steps(r):
    """Indices of steps on the flat, not the first or last of a bout (steady walking)."""
    w = r.walk
    t = w.step_t_s
    ok = (w.step_mode == MODE_WALK) & (t < w.t_s[-1] - 1.0)
    idx = np.clip(np.round(t * 100).astype(int), 0, len(w.t_s) - 1)
    ok &= w.speed_mps[np.clip(idx - 70, 0, None)] > 0.3  # moving 0.7 s before the step
    ok &= w.speed_mps[np.clip(idx + 70, None, len(w.t_s) - 1)] > 0.3  # and 0.7 s after
    return np.flatnonzero(ok)


@pytest.mark.parametrize("pace", PACES)
def test_each_pace_has_its_cadence_and_stride(pace_runs, pace):
    r = pace_runs[pace]
    w = r.walk
    k = interior_walking_steps(r)
    assert len(k) > 50
    cadence = 1.0 / np.median(np.diff(w.step_t_s)[k[:-1]])
    stride = np.median(w.step_len_m[k])
    (c_lo, c_hi), (l_lo, l_hi) = RANGES[pace]
    assert c_lo <= cadence <= c_hi
    assert l_lo <= stride <= l_hi
    assert r.summary()["pace"] == pace


def test_faster_pace_is_faster_longer_and_bouncier(pace_runs):
    med = {
        p: (
            np.median(r.walk.step_len_m[interior_walking_steps(r)]),
            np.median(r.walk.step_p2p_mps2[interior_walking_steps(r)]),
        )
        for p, r in pace_runs.items()
    }
    assert med["slow"][0] < med["normal"][0] < med["fast"][0]
    assert med["slow"][1] < med["normal"][1] < med["fast"][1]
    # Weinberg: amplitude ~ length^4, so the fast pace bounces several times more than the slow one
    assert med["fast"][1] / med["slow"][1] > 3.0


def test_person_comes_from_the_seed():
    def person(seed, pace):
        sc = builtin_scenario(f"pace_{pace}").with_overrides(seed=seed).data
        return make_person(sc, np.random.default_rng(np.random.SeedSequence(seed).spawn(5)[4]))

    a, b, c = person(1, "slow"), person(1, "fast"), person(2, "slow")
    assert (a.weinberg_k, a.stride_scale, a.cadence_scale) == (b.weinberg_k, b.stride_scale, b.cadence_scale)
    assert (a.weinberg_k, a.stride_scale) != (c.weinberg_k, c.stride_scale)
    ks = [person(s, "normal").weinberg_k for s in range(40)]
    assert 0.45 <= min(ks) < 0.48 and 0.52 < max(ks) <= 0.55


@pytest.mark.parametrize("pace", PACES)
def test_weinberg_law_relates_amplitude_and_step_length(pace_runs, pace):
    """The vertical acceleration measured per step, through the person's true K, gives the step length."""
    r = pace_runs[pace]
    w = r.walk
    K = r.summary()["weinberg_k"]
    k = interior_walking_steps(r)
    T = np.diff(w.step_t_s)
    az = w.accel_body_mps2[:, 2]
    measured = []
    for j in k[1:]:
        t_peak = w.step_t_s[j]
        m = (w.t_s >= t_peak - 0.58 * T[j - 1]) & (w.t_s <= t_peak + 0.05 * T[j])
        measured.append(az[m].max() - az[m].min())
    measured = np.asarray(measured)
    assert np.median(measured / w.step_p2p_mps2[k[1:]]) == pytest.approx(1.0, abs=0.07)
    est = K * measured**0.25
    assert np.median(est / w.step_len_m[k[1:]]) == pytest.approx(1.0, abs=0.03)
    # calibrating K on the walk recovers the true K
    k_fit = w.step_len_m[k[1:]].sum() / (measured**0.25).sum()
    assert k_fit == pytest.approx(K, rel=0.03)
    # step to step, the law holds within a few percent (amplitude noise ~8 % -> ~2 % in length)
    assert np.std(np.log(est / w.step_len_m[k[1:]])) < 0.06


@pytest.mark.parametrize("pace", PACES)
def test_step_count_equals_truth_and_detector(pace_runs, pace, step_detector):
    r = pace_runs[pace]
    truth_steps = r.steps
    assert truth_steps == int(np.sum(r.walk.step_t_s <= r.walk.t_s[-1] + 1e-9))
    peaks = step_detector(r.sensors.accel_mps2, threshold_mps2=0.3)
    assert abs(len(peaks) - truth_steps) <= 1


def test_default_tour_step_count_with_stairs(default_result, step_detector):
    r, _ = default_result
    peaks = step_detector(r.sensors.accel_mps2, threshold_mps2=0.3)
    assert r.steps > 400
    # the elevator's braking bump (+0.8 m/s², smooth) may add one peak to this naive detector
    assert abs(len(peaks) - r.steps) <= 2


@pytest.mark.parametrize("pace", PACES)
def test_inverted_pendulum_forward_speed_lowest_when_body_highest(pace_runs, pace):
    r = pace_runs[pace]
    w = r.walk
    m = (w.activity == ACT_WALK) & (np.abs(w.yaw_rate_radps) < 0.02) & (w.speed_mps > 0.3)
    ax = w.accel_body_mps2[m, 0]
    vz = w.vz_mps[m]
    assert np.corrcoef(ax, vz)[0, 1] < -0.5
    # the same from the board: accelerometer x (mounting 0 = body forward) against the vertical velocity
    ax_board = r.sensors.accel_mps2[m, 0]
    assert np.corrcoef(ax_board - ax_board.mean(), vz)[0, 1] < -0.5
    # speed and height within a step: speed minimum at the top
    bounce = (w.height_m - w.level_m)[m]
    assert (
        np.corrcoef(w.speed_mps[m] - np.convolve(w.speed_mps, np.ones(61) / 61, "same")[m], bounce)[0, 1]
        < -0.5
    )


def test_lateral_sway_at_half_the_step_rate(pace_runs):
    w = pace_runs["normal"].walk
    m = (w.activity == ACT_WALK) & (np.abs(w.yaw_rate_radps) < 0.02) & (w.speed_mps > 0.5)
    ay = w.accel_body_mps2[:, 1]
    seg = ay[np.flatnonzero(m)[:1024]]
    spec = np.abs(np.fft.rfft(seg - seg.mean()))
    f = np.fft.rfftfreq(len(seg), 0.01)
    cadence = pace_runs["normal"].walk.person.cadence_hz
    assert f[np.argmax(spec)] == pytest.approx(cadence / 2, rel=0.1)
