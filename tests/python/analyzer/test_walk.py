"""A walk without ground truth: analyze describes it, report draws it, compare refuses it clearly; the
primary is the scheme the firmware put on POSE; ``-q`` keeps stdout empty.

The synthetic log is written as stridefixd writes one without a controller: each scheme on its own
POSE_<SCHEME> channel and POSE a copy of ekf's (the scheme controller.init_scheme names), so every
figure below is known in closed form."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import baro_t, fix_t, pose_t, step_t
from stridefix_analyzer.io.channels import POSE_SCHEME_CHANNELS
from stridefix_analyzer.io.results import read_analyze_metrics
from stridefix_analyzer.scoring.walk import CHI2_2DOF_95

EKF, PDR = pose_t.SCHEME_EKF, pose_t.SCHEME_PDR_ONLY
S = 1_000_000
GATE = 3.0
#: ekf's Wi-Fi fixes: test ratios (NIS = ratio · gate²), accepted when ≤ 1
RATIOS = [0.1, 0.2, 0.5, 0.8, 2.0]


def _fix(t_us, ratio, scheme=EKF, method=fix_t.METHOD_WIFI):
    m = fix_t()
    m.t_us, m.method, m.scheme, m.x_m, m.y_m, m.floor = int(t_us), method, scheme, 1.0, 2.0, 0
    m.accuracy_m, m.innovation_m, m.innovation_var_m2 = 3.0, [0.5, -0.5], 4.0
    m.test_ratio, m.accepted = ratio, ratio <= 1.0
    m.reason = fix_t.REASON_ACCEPTED if m.accepted else fix_t.REASON_GATE
    m.reason_text = "accepted" if m.accepted else "gate"
    return m


def _baro(t_us, pressure_pa):
    m = baro_t()
    m.t_us, m.seq, m.pressure_pa, m.temperature_degc = int(t_us), 0, pressure_pa, 20.0
    return m


def _step(msg, t_us, index, activity=step_t.ACTIVITY_WALKING, floor=0):
    m = msg.step(t_us, index, length_m=0.75)
    m.period_s, m.activity, m.floor = 0.5, activity, floor
    return m


@pytest.fixture
def field_log(msg, write_log):
    """20 s: 40 steps at 0.5 s (the last 4 on stairs up, to floor 1), ekf 10 poses 1 m apart with σ
    1..2 m and POSE carrying its copy, pdr_only 20 poses (more than ekf: the old preference would
    star it), ekf's five Wi-Fi fixes and one initialisation, pdr_only ignoring them, BARO falling
    by 36 Pa (about 3 m up), HEALTH growing."""
    events = [("CONFIG", msg.config({"fusion.gate_sigma": str(GATE)}))]
    for k in range(20):
        t = S + k * S
        events.append((POSE_SCHEME_CHANNELS[PDR], msg.pose(t, k * 0.5, 0, scheme=PDR, step_count=2 * k)))
        if k % 2 == 0:
            floor = 1 if k >= 18 else 0
            p = msg.pose(t, k * 0.5, 1, floor=floor, scheme=EKF, sigma_m=1.0 + k / 18, step_count=2 * k)
            events += [(POSE_SCHEME_CHANNELS[EKF], p), ("POSE", p)]
    events += [
        ("STEP", _step(msg, S + i * S // 2, i + 1, step_t.ACTIVITY_STAIRS_UP if i >= 36 else 2, i >= 38))
        for i in range(40)
    ]
    first = _fix(S, 0.0)
    first.reason, first.reason_text = fix_t.REASON_INITIALISED, "initialised"
    events.append(("FIX", first))
    events += [("FIX", _fix(2 * S + 3 * k * S, r)) for k, r in enumerate(RATIOS)]
    events += [("FIX", _fix(2 * S + 3 * k * S, 0.0, scheme=PDR)) for k in range(5)]
    for f in events[-5:]:
        f[1].reason, f[1].accepted = fix_t.REASON_SCHEME_IGNORES, False
    events += [("BARO", _baro(S + k * S // 10, 101_325.0 - 36.0 * k / 199)) for k in range(200)]
    events += [("HEALTH", msg.health(S + k * 5 * S, 100 * (k + 1))) for k in range(5)]
    return write_log("field.lcmlog", events)


def test_analyze_without_truth_writes_the_walk(field_log, tmp_path, cli_main, capsys):
    out = tmp_path / "an"
    assert cli_main(["analyze", str(field_log), "--out", str(out)]) == 0
    console = capsys.readouterr().out
    assert "walk without ground truth" in console and "*ekf" in console
    m = read_analyze_metrics(out / "metrics.json")
    assert m["truth"] is False and "position_error_m" not in m and "per_scheme" not in m
    # POSE carried ekf's copy: ekf is primary although pdr_only has twice its poses
    assert (m["primary_scheme"], m["primary_from"]) == ("ekf", "pose_channel")
    w = m["walk"]
    assert_allclose(w["duration_s"], 19.0)
    st = w["steps"]
    assert (st["count"], st["step_messages"]) == (40, 40)
    assert_allclose([st["walked_m"], st["cadence_spm"]], [30.0, 120.0])
    assert st["activity"] == {
        "walking": {"steps": 36, "seconds": 18.0},
        "stairs_up": {"steps": 4, "seconds": 2.0},
    }
    assert w["floors_visited"] == [0, 1] and w["floor_changes"] == 1
    # 36 Pa ≈ 3.0 m at sea level (international barometric formula), from the first second's median
    p0 = 101_325.0 - 36.0 * 5 / 199
    assert w["barometric_height_m"]["n"] == 200
    assert_allclose(w["barometric_height_m"]["final"], 44330 * (1 - ((101_325.0 - 36.0) / p0) ** (1 / 5.255)))
    assert w["barometric_height_m"]["max"] == w["barometric_height_m"]["final"]
    assert 2.9 < w["barometric_height_m"]["final"] < 3.0
    assert w["health"]["reports"] == 5 and w["health"]["grew"] == {"frames_total": 400, "frames_ok": 400}
    c = w["consistency"]
    assert c["gate_sigma"] == GATE and c["gate_sigma_from"] == "CONFIG fusion.gate_sigma"
    assert_allclose(c["chi2_95"], 5.991464547107979)
    ekf = w["per_scheme"]["ekf"]
    assert ekf["n_pose"] == 10 and ekf["floors_visited"] == [0, 1]
    assert_allclose(ekf["track_length_m"], 9.0)
    assert_allclose(
        [ekf["sigma_m"]["median"], ekf["sigma_m"]["final"], ekf["sigma_m"]["max"]], [1.5, 2.0, 2.0]
    )
    nis = np.array(RATIOS) * GATE**2  # the initialisation judges nothing
    fx = ekf["fixes"]
    assert (fx["offered"], fx["accepted"], fx["judged"]) == (6, 5, 5)
    assert_allclose(fx["nis_mean"], nis.mean())
    assert_allclose(fx["within_chi2_95_rate"], np.mean(nis <= CHI2_2DOF_95))  # 0.9, 1.8, 4.5 in
    assert_allclose(fx["accepted_nis_mean"], nis[:4].mean())
    assert ekf["fixes_by_method"]["wifi"]["judged"] == 5
    pdr = w["per_scheme"]["pdr_only"]
    assert pdr["fixes"]["judged"] == 0 and pdr["fixes"]["nis_mean"] is None
    assert m["fix_sources"]["ekf"]["wifi"]["rejected_by_reason"] == {"gate": 1}


def test_report_without_truth_draws_the_walk(field_log, tmp_path, cli_main):
    out = tmp_path / "an"
    assert cli_main(["analyze", str(field_log), "--out", str(out)]) == 0
    assert cli_main(["report", str(out)]) == 0
    page = (out / "report.html").read_text()
    for heading in (
        "The walk (no ground truth)",
        "Tracks on the floor plan",
        "Floors and barometric height",
        "Steps and activity",
        "Claimed σ and innovation consistency by scheme",
        "Every fix: verdict and innovation (ekf)",
        "HEALTH over time",
        "Fix sources",
    ):
        assert f"<h2>{heading}</h2>" in page, heading
    assert "Position error by scheme" not in page and "IPIN score" not in page
    assert re.findall(r"<img alt='([^']*)'", page) == [
        "tracks, one panel per floor",
        "floor and barometric height over time",
        "steps and activity over time",
        "claimed sigma over time",
        "innovation and NIS of every fix",
        "HEALTH counters over time",
    ]
    assert "6 FIX records of ekf" in page and "rejected (gate)" in page
    assert f"<td>{np.mean(np.array(RATIOS) * 9):.2f}</td>" in page  # ekf's mean NIS
    assert "ekf (the scheme the firmware published on POSE)" in page


def test_compare_of_walks_without_truth_says_why(field_log, tmp_path, cli_main, capsys):
    a, b = tmp_path / "a", tmp_path / "b"
    for d in (a, b):
        assert cli_main(["analyze", str(field_log), "--out", str(d)]) == 0
    capsys.readouterr()
    assert cli_main(["compare", str(a / "metrics.json"), str(b / "metrics.json")]) == 2
    err = capsys.readouterr().err
    assert "without truth" in err and "Traceback" not in err


def test_scheme_overrides_the_pose_channel(field_log, tmp_path, cli_main):
    out = tmp_path / "an"
    assert cli_main(["analyze", str(field_log), "--out", str(out), "--scheme", "pdr_only"]) == 0
    m = read_analyze_metrics(out / "metrics.json")
    assert (m["primary_scheme"], m["primary_from"]) == ("pdr_only", "requested")


def test_primary_with_truth_is_the_pose_channels(field_log, msg, write_log, tmp_path, cli_main):
    """The same log with TRUTH: scored as before, the primary still ekf (POSE's), and the walk beside."""
    truth = write_log("truth.lcmlog", [("TRUTH", msg.truth(S + k * S, k * 0.5, 0)) for k in range(20)])
    out = tmp_path / "an"
    assert cli_main(["analyze", str(field_log), str(truth), "--out", str(out)]) == 0
    m = read_analyze_metrics(out / "metrics.json")
    assert m["truth"] is True and (m["primary_scheme"], m["primary_from"]) == ("ekf", "pose_channel")
    assert m["position_error_m"] == m["per_scheme"]["ekf"]["position_error_m"]
    # ekf has a pose every 2 s: every other truth sample is scored against the pose 0.5 m behind
    assert_allclose(m["per_scheme"]["ekf"]["position_error_m"]["mean"], (1 + np.hypot(0.5, 1)) / 2)
    assert m["walk"]["per_scheme"]["ekf"]["fixes"]["judged"] == 5


@pytest.mark.parametrize("with_truth", [False, True], ids=["no-truth", "truth"])
def test_quiet_analyze_prints_nothing(field_log, msg, write_log, tmp_path, cli_main, capsys, with_truth):
    logs = [str(field_log)]
    if with_truth:
        logs.append(str(write_log("t.lcmlog", [("TRUTH", msg.truth(S + k * S, 0, 0)) for k in range(20)])))
    assert cli_main(["-q", "analyze", *logs, "--out", str(tmp_path / "q")]) == 0
    assert capsys.readouterr().out == ""
    doc = json.loads((tmp_path / "q" / "metrics.json").read_text())
    assert doc["truth"] is with_truth  # the files do not depend on -q


def test_no_pose_and_no_truth_is_nothing_valid(msg, write_log, tmp_path, cli_main, capsys):
    path = write_log("h.lcmlog", [("HEALTH", msg.health(S, 1))])
    assert cli_main(["analyze", str(path), "--out", str(tmp_path / "o")]) == 3
    assert "no TRUTH and no POSE" in capsys.readouterr().err
