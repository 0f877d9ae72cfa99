"""End to end with a site: survey -> radio map -> site file -> walk -> stridefixd --site -> FIX and
POSE for every fusion scheme, scored at the reference points.

GIVEN the aadr2015 foyer surveyed (a recording of its own) and turned into a site file by
`stridefix radiomap build`, WHEN stridefixd replays a walk of the track with that site, THEN every
scheme judges every Wi-Fi scan (FIX audit records), every scheme publishes POSE from its first fix
on, and the fused schemes beat Wi-Fi alone at the reference points."""

from __future__ import annotations

import json
import subprocess
from collections import Counter
from pathlib import Path

import lcm
import numpy as np
import pytest
from stridefix import fix_t, pose_t, wifi_scan_t
from stridefix_analyzer.io.channels import POSE_CHANNELS, POSE_SCHEME_CHANNELS
from stridefix_analyzer.io.results import read_analyze_metrics
from stridefix_analyzer.schemes import FUSION_SCHEMES as SCHEMES  # the controller judges no fix

SCHEME_IDS = [s.id for s in SCHEMES]  # every fusion scheme of pose_t.lcm


def run_fw(stridefixd: Path, walk: Path, log: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(stridefixd), "--input", str(walk / "board.candump"), "--log", str(log), "-q", *extra],
        capture_output=True,
        text=True,
        timeout=300,
    )


def survey_site(stridefixd: Path, cli, out: Path, scenario: str, rotation_deg: float | None) -> Path:
    """A survey (seed 1000, never a scored walk) recorded through stridefixd and built into a site
    file; the map rotation is the survey's own (from its summary) unless given."""
    assert cli("sim", "--scenario", scenario, "--seed", "1000", "--out", str(out)).returncode == 0
    if rotation_deg is None:
        rotation_deg = json.loads((out / "sim_summary.json").read_text())["map_rotation_deg"]
    assert run_fw(stridefixd, out, out / "fw.lcmlog").returncode == 0
    site = out / "site.sfsite"
    proc = cli(
        "radiomap",
        "build",
        str(out / "fw.lcmlog"),
        str(out / "truth.lcmlog"),
        "--mode",
        "survey",
        "--out",
        str(site),
        "--map-rotation-deg",
        str(rotation_deg),
    )
    assert proc.returncode == 0, proc.stderr
    return site


@pytest.fixture(scope="module")
def site(stridefixd, cli, tmp_path_factory) -> Path:
    """The surveyed foyer as a site file (survey seed 1000, never a scored walk)."""
    out = tmp_path_factory.mktemp("survey")
    return survey_site(stridefixd, cli, out, "aadr2015_survey", rotation_deg=None)


@pytest.fixture(scope="module")
def walk(stridefixd, cli, site, tmp_path_factory) -> dict:
    out = tmp_path_factory.mktemp("walk")
    assert cli("sim", "--scenario", "aadr2015", "--seed", "1", "--out", str(out)).returncode == 0
    log = out / "fw.lcmlog"
    proc = run_fw(stridefixd, out, log, "--site", str(site))
    assert proc.returncode == 0, proc.stderr
    events = list(lcm.EventLog(str(log), "r"))
    return {"dir": out, "log": log, "events": events, "stderr": proc.stderr}


def test_every_scheme_judges_every_scan(walk):
    scans = [e for e in walk["events"] if e.channel == "WIFI"]
    fixes = [fix_t.decode(e.data) for e in walk["events"] if e.channel == "FIX"]
    assert len(scans) > 10
    assert len(fixes) == len(SCHEMES) * len(scans)
    per_scheme = Counter(f.scheme for f in fixes)
    assert sorted(per_scheme) == SCHEME_IDS and set(per_scheme.values()) == {len(scans)}
    for scheme in SCHEME_IDS:
        first = next(f for f in fixes if f.scheme == scheme)
        assert first.reason == fix_t.REASON_INITIALISED and first.accepted and first.alpha == 1.0
    for f in fixes:
        assert f.reason_text and 0.0 <= f.alpha <= 1.0
        assert (
            f.accepted
            == (f.reason in (fix_t.REASON_ACCEPTED, fix_t.REASON_INITIALISED, fix_t.REASON_RECOVERY))
            or f.reason == fix_t.REASON_SCHEME_IGNORES
        )


def test_adaptive_fix_records_carry_accuracy_factor_and_drift(walk):
    """FIX.accuracy_factor and FIX.drift: the adaptive law's two terms where it blended a fix
    (α = clamp(sum, 0, 1)), 0 everywhere else."""
    fixes = [fix_t.decode(e.data) for e in walk["events"] if e.channel == "FIX"]
    blended = [f for f in fixes if f.scheme == pose_t.SCHEME_ADAPTIVE and f.reason == fix_t.REASON_ACCEPTED]
    assert len(blended) > 5
    for f in blended:
        assert f.accuracy_factor > 0.0 and f.drift >= 0.0
        assert f.alpha == pytest.approx(min(max(f.accuracy_factor + f.drift, 0.0), 1.0), abs=1e-6)
    assert any(f.drift > 0.0 for f in blended)
    others = [
        f for f in fixes if not (f.scheme == pose_t.SCHEME_ADAPTIVE and f.reason == fix_t.REASON_ACCEPTED)
    ]
    assert all(f.accuracy_factor == 0.0 and f.drift == 0.0 for f in others)


def test_every_scheme_publishes_pose_after_its_first_fix(walk):
    first_scan_t = min(wifi_scan_t.decode(e.data).t_us for e in walk["events"] if e.channel == "WIFI")
    poses = [pose_t.decode(e.data) for e in walk["events"] if e.channel in POSE_CHANNELS]
    assert sorted({p.scheme for p in poses}) == SCHEME_IDS
    assert min(p.t_us for p in poses) >= first_scan_t  # nobody has a position before the first fix


def test_each_scheme_on_its_own_channel_and_the_primary_on_pose(walk):
    """Each fusion scheme's poses on POSE_<SCHEME> (its scheme field agreeing), and POSE the primary
    pose only: without a context map (this site has none) one per output, a copy of
    controller.init_scheme's pose (kalman), pdr_only's while kalman has none; the POSE record's payload
    is the one its scheme's channel got just before, at the same log time."""
    last: dict[str, tuple[int, bytes]] = {}
    primary: list[int] = []
    per_channel = Counter()
    for e in walk["events"]:
        if e.channel not in POSE_CHANNELS:
            continue
        per_channel[e.channel] += 1
        p = pose_t.decode(e.data)
        if e.channel == "POSE":
            assert p.scheme in (pose_t.SCHEME_KALMAN, pose_t.SCHEME_PDR_ONLY)
            assert last[POSE_SCHEME_CHANNELS[p.scheme]] == (e.timestamp, e.data)
            primary.append(p.scheme)
        else:
            assert e.channel == POSE_SCHEME_CHANNELS[p.scheme]
            last[e.channel] = (e.timestamp, e.data)
    assert sorted(per_channel) == sorted(POSE_CHANNELS)
    # one primary pose per output: as many as the scheme published most often
    assert per_channel["POSE"] == max(n for ch, n in per_channel.items() if ch != "POSE")
    assert primary.count(pose_t.SCHEME_KALMAN) > 0.9 * len(primary)


@pytest.mark.parametrize(
    ("args", "channels", "scheme"),
    [
        # one scheme: its own channel, and POSE its copy (the primary of a one-scheme replay)
        (["--fusion", "kalman"], {"POSE_KALMAN", "POSE"}, pose_t.SCHEME_KALMAN),
        # --channels picks pose channels one by one: the primary (kalman's copy here) without the rest
        (["--channels", "POSE"], {"POSE"}, pose_t.SCHEME_KALMAN),
        (["--channels", "POSE_PARTICLE"], {"POSE_PARTICLE"}, pose_t.SCHEME_PARTICLE),
    ],
    ids=["fusion-kalman", "channels-POSE", "channels-POSE_PARTICLE"],
)
def test_pose_channels_follow_fusion_and_channels(walk, stridefixd, site, tmp_path, args, channels, scheme):
    log = tmp_path / "one.lcmlog"
    assert run_fw(stridefixd, walk["dir"], log, "--site", str(site), *args).returncode == 0
    poses: dict[str, list[bytes]] = {}
    for e in lcm.EventLog(str(log), "r"):
        if e.channel in POSE_CHANNELS:
            poses.setdefault(e.channel, []).append(e.data)
    assert set(poses) == channels
    # the poses themselves are those of the full run: --fusion and --channels only pick what is written
    full = {ch: [e.data for e in walk["events"] if e.channel == ch] for ch in channels}
    for ch, payloads in poses.items():
        if ch != "POSE" or "--fusion" not in args:  # --fusion kalman: POSE copies kalman, not ekf
            assert payloads == full[ch]
        assert {pose_t.decode(d).scheme for d in payloads} <= {scheme, pose_t.SCHEME_PDR_ONLY}
        assert pose_t.decode(payloads[-1]).scheme == scheme
    if "POSE_KALMAN" in poses:
        assert poses["POSE"] == poses["POSE_KALMAN"]


def test_fusion_beats_wifi_alone_at_the_reference_points(walk, cli, tmp_path):
    proc = cli(
        "analyze",
        str(walk["log"]),
        str(walk["dir"] / "truth.lcmlog"),
        "--truth-source",
        "waypoint",
        "--out",
        str(tmp_path),
    )
    assert proc.returncode == 0, proc.stderr
    per = read_analyze_metrics(tmp_path / "metrics.json")["per_scheme"]
    n = {k: v["position_error_m"]["n"] for k, v in per.items()}
    assert n["kalman"] == 14  # the track's 14 reference points
    mean = {k: v["position_error_m"]["mean"] for k, v in per.items()}
    assert mean["wifi_only"] < 5.0
    assert mean["kalman"] < mean["wifi_only"]
    assert mean["adaptive"] < mean["wifi_only"]


def test_same_input_same_fix_and_pose_records(walk, stridefixd, site, tmp_path):
    log = tmp_path / "again.lcmlog"
    assert run_fw(stridefixd, walk["dir"], log, "--site", str(site)).returncode == 0

    def records(events):
        wanted = {"FIX", "STEP", *POSE_CHANNELS}
        return [(e.timestamp, e.channel, e.data) for e in events if e.channel in wanted]

    assert records(lcm.EventLog(str(log), "r")) == records(walk["events"])


@pytest.mark.parametrize("damage", ["missing", "truncated", "crc"])
def test_bad_site_file_stops_startup(stridefixd, walk, site, tmp_path, damage):
    bad = tmp_path / "bad.sfsite"
    data = bytearray(site.read_bytes())
    if damage == "truncated":
        bad.write_bytes(bytes(data[: len(data) // 2]))
    elif damage == "crc":
        data[40] ^= 0xFF
        bad.write_bytes(bytes(data))
    proc = run_fw(stridefixd, walk["dir"], tmp_path / "x.lcmlog", "--site", str(bad))
    assert proc.returncode == 2
    assert "bad.sfsite" in proc.stderr
    if damage == "crc":
        assert "CRC" in proc.stderr


@pytest.fixture(scope="module")
def office_walk(stridefixd, cli, default_walk, tmp_path_factory) -> list:
    """The default office walk replayed with a site from a survey of the office (seed 1000)."""
    out = tmp_path_factory.mktemp("office_survey")
    site = survey_site(stridefixd, cli, out, "office_survey", rotation_deg=20.0)
    log = out / "walk.lcmlog"
    proc = run_fw(stridefixd, default_walk["dir"], log, "--site", str(site))
    assert proc.returncode == 0, proc.stderr
    return list(lcm.EventLog(str(log), "r"))


def test_stride_is_recalibrated_from_fixes(office_walk):
    """Weinberg's K (length / range^¼ of each level STEP) starts at the configured 0.47 and is moved by
    Kalman-accepted fixes over the corridors' straight stretches, within its bounds and by at most
    10 % a time. A stairs STEP is shorter than K · range^¼ (the going, L − 2R: sf_estimator.h)."""
    from stridefix import step_t

    steps = [step_t.decode(e.data) for e in office_walk if e.channel == "STEP"]
    stairs = (step_t.ACTIVITY_STAIRS_UP, step_t.ACTIVITY_STAIRS_DOWN)
    level = [s for s in steps if s.accel_range_mps2 > 0 and s.activity not in stairs]
    k = np.array([s.length_m / s.accel_range_mps2**0.25 for s in level])
    level_t_us = [lv.t_us for lv in level]
    n_stairs = 0
    for s in steps:
        if s.activity in stairs:
            i = max(
                int(np.searchsorted(level_t_us, s.t_us, side="right")) - 1, 0
            )  # K of the level step before
            assert s.length_m < k[i] * s.accel_range_mps2**0.25 + 1e-4
            n_stairs += 1
    assert n_stairs > 0  # the default walk climbs the staircase
    assert abs(k[0] - 0.47) < 1e-3
    changes = np.flatnonzero(np.abs(np.diff(k)) > 1e-4)
    assert len(changes) >= 2
    assert np.all(np.abs(np.diff(k)) <= 0.1 * k[:-1] + 1e-4)
    assert 0.25 <= k.min() and k.max() <= 0.80


def test_the_analyzer_decodes_every_channel_of_a_site_run(walk):
    # with a site the log also carries FIX: every channel known to io/channels.py, none undecodable
    from stridefix_analyzer.io.logread import read_logs

    data = read_logs([walk["log"]])
    assert data.unknown_channels == {} and data.decode_errors == {}
    assert len(data.table("FIX")) > 0 and len(data.table("POSE")) > 0


def test_fast_reader_reads_the_log_as_lcm_eventlog_does(walk, assert_reads_alike):
    # the numpy reader (lcmindex + lcmdecode) on a real stridefixd log with every scheme's FIX audit
    # records (reason texts of several lengths), POSE, WIFI and the simulator's truth: the same tables
    # as record by record, for all channels, for analyze's and for realbench's FIX-only read
    logs = [walk["log"], walk["dir"] / "truth.lcmlog"]
    data = assert_reads_alike(logs)
    assert len(data.tables["FIX"]) > 10 * len(SCHEMES) and len(set(data.tables["FIX"]["reason_text"])) > 1
    assert_reads_alike(logs, ("POSE", "TRUTH", "STEP", "FIX", "HEALTH", "CONFIG", "CONTEXT"))
    assert_reads_alike([walk["log"]], ("FIX",))


def test_the_walk_without_truth_headlines_the_pose_channels_scheme(walk, cli, tmp_path):
    """stridefixd's log alone (no TRUTH, as in the field): analyze describes the walk with finite
    numbers and headlines the scheme the POSE channel carried (controller.init_scheme's, kalman);
    with the truth log beside it the same scheme is primary; the report draws the walk."""
    carried = [pose_t.decode(e.data).scheme for e in walk["events"] if e.channel == "POSE"]
    pose_scheme = pose_t.SCHEME_KALMAN
    assert carried[-1] == pose_scheme
    proc = cli("analyze", str(walk["log"]), "--out", str(tmp_path / "walk"))
    assert proc.returncode == 0, proc.stderr
    m = read_analyze_metrics(tmp_path / "walk" / "metrics.json")
    assert m["truth"] is False and (m["primary_scheme"], m["primary_from"]) == ("kalman", "pose_channel")
    w = m["walk"]
    assert w["steps"]["count"] > 50 and 80 < w["steps"]["cadence_spm"] < 140
    assert w["duration_s"] > 30 and w["floors_visited"]
    kalman = w["per_scheme"]["kalman"]
    assert kalman["fixes"]["judged"] > 5 and 0.0 < kalman["fixes"]["nis_mean"] < 100.0
    assert 0.0 <= kalman["fixes"]["within_chi2_95_rate"] <= 1.0
    assert 0.0 < kalman["sigma_m"]["median"] < 50.0 and np.isfinite(kalman["track_length_m"])
    assert set(w["per_scheme"]) == set(m["fix_sources"])  # every scheme judged the fixes
    assert cli("report", str(tmp_path / "walk")).returncode == 0
    page = (tmp_path / "walk" / "report.html").read_text()
    for heading in ("The walk (no ground truth)", "Claimed σ and innovation consistency by scheme"):
        assert heading in page
    assert "Every fix: verdict and innovation (kalman)" in page
    proc = cli("analyze", str(walk["log"]), str(walk["dir"] / "truth.lcmlog"), "--out", str(tmp_path / "t"))
    assert proc.returncode == 0, proc.stderr
    assert read_analyze_metrics(tmp_path / "t" / "metrics.json")["primary_scheme"] == "kalman"
