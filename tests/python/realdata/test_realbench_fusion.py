"""`stridefix-lab realbench --format ...`: the fusion schemes on real walks, leave one walk out.

Synthetic checks of the fold machinery (sufficient-statistics maps, rotation and floor-height
learning), then a small real run (5 msindoor walks) checked for sanity, leakage, determinism, and
against evo's APE on the same trajectories.
"""

from __future__ import annotations

import math
import subprocess
import warnings

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from stridefix import truth_t, wifi_scan_t
from stridefix_analyzer import datasets, schemes
from stridefix_analyzer.io.logread import LogTruncatedWarning, read_logs
from stridefix_analyzer.io.sitefile import read_site
from stridefix_analyzer.radiomap import build as rm
from stridefix_analyzer.radiomap import heading
from stridefix_lab.realbench import cli as rbcli
from stridefix_lab.realbench import floors
from stridefix_lab.realbench import fold as rfold

SCHEMES = schemes.NAMES
MSINDOOR_SETS = datasets.get("msindoor").firmware_sets


# --- synthetic walks with WIFI + TRUTH -------------------------------------------------------------


def _truth(t_us, x, y, floor):
    m = truth_t()
    m.t_us, m.x_m, m.y_m, m.floor = int(t_us), float(x), float(y), int(floor)
    m.heading_rad, m.step_count, m.source = math.nan, -1, truth_t.SOURCE_WAYPOINT
    return m


def _scan(t_us, aps, complete=True):
    m = wifi_scan_t()
    m.t_us, m.scan_id, m.complete = int(t_us), 0, bool(complete)
    m.n_ap = len(aps)
    m.bssid = [int(b) for b, _ in aps]
    m.rssi_dbm = [float(r) for _, r in aps]
    m.freq_mhz = [2412] * len(aps)
    return m


def write_walk(path, seed: int, floor: int = 0, extra_ap: int | None = None):
    """A random walk of 8 waypoints over 40 × 30 m with a scan every 2 s (integer dBm, like real
    data) hearing 6 of 10 APs; one BSSID twice in a scan, one incomplete scan; ``extra_ap`` heard
    in every scan of this walk only."""
    rng = np.random.default_rng(seed)
    wp_t = np.arange(8) * 10.0
    wp = rng.uniform([0, 0], [40, 30], size=(8, 2))
    log = lcm.EventLog(str(path), "w", overwrite=True)
    events = [(t, "TRUTH", _truth(t * 1e6, x, y, floor)) for t, (x, y) in zip(wp_t, wp)]
    for k, t in enumerate(np.arange(1.0, 70.0, 2.0)):
        aps = [(0x100 + a, int(rng.integers(-90, -40))) for a in rng.choice(10, 6, replace=False)]
        if k == 3:
            aps.append((aps[0][0], aps[0][1] + 5))  # the same BSSID twice: strongest kept
        if extra_ap is not None:
            aps.append((extra_ap, -60))
        events.append((t, "WIFI", _scan(t * 1e6, aps, complete=k != 5)))
    for t, ch, m in sorted(events, key=lambda e: e[0]):
        log.write_event(int(t * 1e6), ch, m.encode())
    log.close()
    return str(path)


@pytest.fixture
def synthetic_walks(tmp_path):
    """GIVEN five synthetic walks (one on floor 1, the last with a unique AP 0xBEEF): recordings."""
    paths = [
        write_walk(
            tmp_path / f"w{i}.lcmlog", seed=i, floor=1 if i == 2 else 0, extra_ap=0xBEEF if i == 4 else None
        )
        for i in range(5)
    ]
    return [rm.load_recordings([p])[0] for p in paths]


def _site_arrays(site):
    return {
        k: np.asarray(getattr(site, k))
        for k in (
            "ap_bssid",
            "rp_x_m",
            "rp_y_m",
            "rp_floor",
            "rp_scans",
            "entry_ap",
            "entry_rp",
            "entry_mean_dbm",
            "entry_std_db",
            "entry_count",
            "floor_height_m",
        )
    }


@pytest.mark.parametrize("held", [0, 2, 4])
def test_fold_map_equals_the_map_built_from_the_other_walks(synthetic_walks, held):
    # GIVEN per-walk sufficient statistics and their total
    stats = [rm.WalkStats.from_recordings([r]) for r in synthetic_walks]
    total = rm.WalkStats.total(stats)
    # WHEN the fold's map is taken as total - held out walk
    fold, _ = (total - stats[held]).to_site(lowest_floor=0)
    # THEN it is the walk-mode map that build_site makes from scratch from the other walks
    ref, _ = rm.build_site(
        [r for i, r in enumerate(synthetic_walks) if i != held], mode="walk", lowest_floor=0
    )
    a, b = _site_arrays(fold), _site_arrays(ref)
    for k in ("ap_bssid", "rp_floor", "rp_scans", "entry_ap", "entry_rp", "entry_count", "floor_height_m"):
        assert_array_equal(a[k], b[k], err_msg=k)
    for k in ("rp_x_m", "rp_y_m", "entry_mean_dbm", "entry_std_db"):
        assert_allclose(a[k], b[k], rtol=0, atol=1e-5, err_msg=k)  # float32 in the site
    assert fold.n_entries > 50


def test_statistics_add_in_any_grouping(synthetic_walks):
    stats = [rm.WalkStats.from_recordings([r]) for r in synthetic_walks]
    one_by_one = stats[0] + stats[1] + stats[2] + stats[3] + stats[4]
    total = rm.WalkStats.total(stats)
    together = rm.WalkStats.from_recordings(synthetic_walks)
    for s in (one_by_one, together):
        assert_array_equal(s.entry_key, total.entry_key)
        assert_array_equal(s.entry_count, total.entry_count)
        assert_array_equal(s.entry_sum_dbm, total.entry_sum_dbm)
        assert_array_equal(s.cell_scans, total.cell_scans)
    assert total.scans["skipped_incomplete"] == 5


def test_held_out_walk_never_contributes_to_its_own_site(synthetic_walks):
    # GIVEN walk 4 is the only one hearing AP 0xBEEF
    stats = [rm.WalkStats.from_recordings([r]) for r in synthetic_walks]
    total = rm.WalkStats.total(stats)
    sites = [
        rfold.fold_site(
            total, stats[i], name=f"w{i}", rotation_deg=0.0, floor_heights_m=[0.0, 4.0], lowest_floor=0
        )[0]
        for i in range(5)
    ]
    # THEN its own fold's site does not know the AP, and every other fold's does
    assert 0xBEEF not in list(sites[4].ap_bssid)
    assert all(0xBEEF in list(sites[i].ap_bssid) for i in range(4))
    # and its scans are gone: the fold's statistics hold exactly the other walks' scans
    fold = total - stats[4]
    assert fold.scans["used"] == sum(s.scans["used"] for s in stats[:4])
    assert int(fold.cell_scans.sum()) == sum(int(s.cell_scans.sum()) for s in stats[:4])


def test_subtracting_a_walk_that_is_not_part_fails(synthetic_walks):
    stats = [rm.WalkStats.from_recordings([r]) for r in synthetic_walks]
    with pytest.raises(rm.RadioMapInputError, match="subtracted more"):
        _ = stats[0] - stats[1]


class _RecordingFirmware:
    """Stands in for stridefixd: records each replay's --set list and fails it (the fold stops there)."""

    def __init__(self):
        self.calls: list[list[str]] = []

    def run(self, **kw):
        self.calls.append(list(kw.get("sets") or []))
        return subprocess.CompletedProcess(["stridefixd"], 1, "", "stub")


def test_fold_on_a_multi_floor_site_replays_once(synthetic_walks, tmp_path):
    # GIVEN a fold whose site has two floors (walk 2 is on floor 1)
    stats = [rm.WalkStats.from_recordings([r]) for r in synthetic_walks]
    total = rm.WalkStats.total(stats)
    fw = _RecordingFirmware()
    job = rfold.FoldJob(
        index=0, walk="w0", group="g", dir=tmp_path / "w0", import_log="unused.lcmlog", firmware=fw,  # type: ignore[arg-type]
        K=0.45, rotation_deg=0.0, rotation_learned=False, floor_heights_m=[0.0, 4.0],
        floor_heights_source="test", lowest_floor=0, min_count=1, true_start=False, param_sets=[],
        variants={}, extra={}, first_waypoint=(0, 0.0, 0.0, 0), total=total, held=stats[0],
    )  # fmt: skip
    # WHEN the fold runs
    out = rfold.run_fold(job)
    # THEN the firmware replays the walk once, deciding its start floor itself (no first
    # pass feeding init.floor), and the fold record has no such field
    assert out["fold"]["n_floors"] == 2
    assert len(fw.calls) == 1 and not any(s.startswith("init.floor") for s in fw.calls[0])
    assert "init_floor_from_first_fix" not in out["fold"]
    assert out["error"].startswith("stridefixd exit 1")


# --- rotation and floor heights --------------------------------------------------------------------


def synthetic_rotation_walk(rot_deg: float, seed: int, noise_deg: float = 8.0):
    """Waypoints on a zig-zag, a step every 0.5 s whose heading is the segment direction + rot +
    noise; the first 3 s of each segment turn smoothly from the previous direction (a corner)."""
    rng = np.random.default_rng(seed)
    wp = np.cumsum(rng.uniform(-25, 25, size=(7, 2)), axis=0)
    wp_t = np.cumsum(np.r_[0.0, np.hypot(*np.diff(wp, axis=0).T) / 1.2])  # 1.2 m/s
    t_steps, head = [], []
    prev = None
    for k in range(len(wp) - 1):
        d = math.atan2(*(wp[k + 1] - wp[k])[::-1])
        for t in np.arange(wp_t[k] + 0.25, wp_t[k + 1], 0.5):
            h = d
            if prev is not None and t - wp_t[k] < 3.0:
                h = prev + (t - wp_t[k]) / 3.0 * math.remainder(d - prev, 2 * math.pi)
            t_steps.append(t)
            head.append(h + math.radians(rot_deg) + math.radians(noise_deg) * rng.standard_normal())
        prev = d
    return ((np.array(t_steps) * 1e6).astype(np.int64), np.array(head), (wp_t * 1e6).astype(np.int64), wp)


@pytest.mark.parametrize("rot_deg", [-31.0, 0.0, 97.5, 179.0])
def test_rotation_learning_recovers_a_known_rotation(rot_deg):
    stats = [heading.rotation_stats(*synthetic_rotation_walk(rot_deg, seed)) for seed in range(6)]
    assert all(s["n_segments"] >= 1 for s in stats)
    for held in (None, 0, 5):
        got = heading.learn_rotation_deg(stats, exclude=held)
        assert abs(math.remainder(got - rot_deg, 360.0)) < 2.0


def test_rotation_of_a_fold_ignores_the_held_out_walk():
    stats = [heading.rotation_stats(*synthetic_rotation_walk(10.0, s)) for s in range(3)]
    stats.append(heading.rotation_stats(*synthetic_rotation_walk(120.0, 9)))  # an outlier walk
    assert abs(heading.learn_rotation_deg(stats, exclude=3) - 10.0) < 2.0
    assert abs(heading.learn_rotation_deg(stats) - 10.0) > 5.0
    assert math.isnan(heading.learn_rotation_deg(stats[:1], exclude=0))


def test_floor_heights_from_barometer_and_default():
    # walk A: floors 0, -1, -2 at 0, -5, -9.5 m (+ weather offset 40 m); walk B: floors 0, -1
    a = {0: 40.0, -1: 35.0, -2: 30.5}
    b = {0: -7.0, -1: -12.0}
    h, src = floors.learn_floor_heights([a, b, {0: 3.0}], [-2, -1, 0])
    assert src == "barometer"
    assert_allclose(np.diff(h), [4.5, 5.0], atol=1e-9)
    h, src = floors.learn_floor_heights([b], [-2, -1, 0], storey_m=4.0)
    assert src == "barometer+default"
    assert_allclose(np.diff(h), [4.0, 5.0], atol=1e-9)
    h, src = floors.learn_floor_heights([{0: 1.0}], [-2, -1, 0], storey_m=4.0)
    assert src == "default"
    assert_allclose(h, [-8.0, -4.0, 0.0])


def test_default_benchmark_is_fusion():
    assert rbcli.with_default_bench(["realbench", "--format", "gsd", "d"])[:2] == ["realbench", "fusion"]
    assert rbcli.with_default_bench(["realbench", "pdr-distance", "--floor", "x"])[1] == "pdr-distance"
    assert rbcli.with_default_bench(["realbench", "--help"])[1] == "--help"
    assert rbcli.with_default_bench(["analyze", "x"]) == ["analyze", "x"]


# --- a small real run ------------------------------------------------------------------------------


def test_end_to_end_on_five_real_walks(realbench_fusion_small):
    r = realbench_fusion_small
    assert r["proc"].returncode == 0, r["proc"].stderr[-2000:]
    assert "kalman" in r["proc"].stdout and "adaptive vs wifi_only" in r["proc"].stdout
    (g,) = r["doc"]["groups"]
    assert g["label"] == "site1/F2" and g["walks"] == 5 and not g["fold_errors"]
    # the data set's own firmware overrides are applied and recorded (its magnetometer is OS-calibrated)
    assert r["doc"]["params"]["firmware_sets"][: len(MSINDOOR_SETS)] == list(MSINDOOR_SETS)
    table = g["summary"]["schemes"]
    assert set(table) == set(SCHEMES)
    for name, s in table.items():
        assert s["n"] > 0, name
        for k in ("mean", "median", "p75", "p90", "max", "rmse", "ipin_score"):
            assert s[k] is not None and math.isfinite(s[k]), (name, k)
        assert 0.0 <= s["share_walks_mean_over_15m"] <= 1.0
    # measured 5.23 m mean / 5.75 m p75 on these five walks (2026-12-01); about 1.5x of that, so a
    # change that loses metres fails here (the change-indication CSVs catch any change at all)
    assert table["kalman"]["mean"] < 8.0 and table["kalman"]["p75"] < 9.0
    for row in g["walk_rows"]:
        fold = row["fold"]
        assert 0.25 < fold["K"] < 0.8 and math.isfinite(fold["rotation_deg"])
        assert fold["n_rp"] > 0 and fold["n_ap"] > 0
        assert set(row["fixes"]) == set(SCHEMES)
    assert r["results"].with_suffix(".html").stat().st_size > 10_000


def test_real_fold_sites_hold_no_ap_heard_only_by_the_held_out_walk(realbench_fusion_small):
    r = realbench_fusion_small
    assert r["proc"].returncode == 0
    (g,) = r["doc"]["groups"]
    cache = r["out"] / "cache" / "site1-F2"
    heard = {}
    for row in g["walk_rows"]:
        rec = rm.load_recordings([str(cache / f"{row['walk']}.lcmlog")])
        heard[row["walk"]] = set(rm.WalkStats.from_recordings(rec).entry_key[:, 3].tolist())
    for row in g["walk_rows"]:
        others = set().union(*(v for k, v in heard.items() if k != row["walk"]))
        own_only = heard[row["walk"]] - others
        site = read_site(f"{row['dir']}/site.sfsite")
        assert own_only, "each real walk hears some AP no other of the 5 hears"
        assert not own_only & set(site.ap_bssid), row["walk"]
        assert set(site.ap_bssid) <= others


def _pose_stream(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        pose = read_logs([path], decode=("POSE",)).table("POSE")
    return {k: pose[k] for k in pose.names}


def test_replay_with_a_site_is_deterministic(realbench_fusion_small, tmp_path):
    r = realbench_fusion_small
    row = r["doc"]["groups"][0]["walk_rows"][2]
    imp = r["out"] / "cache" / "site1-F2" / f"{row['walk']}.lcmlog"
    streams = []
    for i in range(2):
        log = tmp_path / f"run{i}.lcmlog"
        subprocess.run(
            [
                str(r["stridefixd"]),
                "--input",
                f"lcmlog:{imp}",
                "--site",
                f"{row['dir']}/site.sfsite",
                "--set",
                f"stride.weinberg_k={row['fold']['K']:.6f}",
                "--log",
                str(log),
                "-q",
            ],
            check=True,
            capture_output=True,
        )
        streams.append(_pose_stream(log))
    a, b = streams
    assert len(a["t_us"]) > 100 and set(np.unique(a["scheme"])) == {s.id for s in schemes.SCHEMES}
    for k in a:
        assert_array_equal(a[k], b[k], err_msg=k)


def test_mean_and_rmse_equal_evo_ape(realbench_fusion_small, tmp_path):
    """Issue: on the same trajectories, the mean and RMSE of position error equal what evo
    computes (APE, translation part, no alignment) from our TUM exports."""
    evo_metrics = pytest.importorskip("evo.core.metrics")
    from evo.tools import file_interface
    from stridefix_analyzer.io.tum import write_tum
    from stridefix_analyzer.scoring.analyze import run_analyze

    r = realbench_fusion_small
    checked = 0
    for row in r["doc"]["groups"][0]["walk_rows"][:3]:
        imp = r["out"] / "cache" / "site1-F2" / f"{row['walk']}.lcmlog"
        summary, metrics = run_analyze(
            [f"{row['dir']}/stridefixd.lcmlog", str(imp)],
            str(tmp_path / row["walk"]),
            truth_source="waypoint",
        )
        paths = write_tum(metrics, tmp_path / row["walk"] / "tum")
        for name, s in summary["per_scheme"].items():
            ours = s["position_error_m"]
            if ours["n"] < 2:
                continue
            ref = file_interface.read_tum_trajectory_file(
                paths["truth"] if "truth_" + name not in paths else paths["truth_" + name]
            )
            est = file_interface.read_tum_trajectory_file(paths[name])
            ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
            ape.process_data((ref, est))
            assert_allclose(
                ape.get_statistic(evo_metrics.StatisticsType.mean), ours["mean"], rtol=0, atol=1e-6
            )
            assert_allclose(
                ape.get_statistic(evo_metrics.StatisticsType.rmse), ours["rmse"], rtol=0, atol=1e-6
            )
            # and the per-walk numbers of results.json are these
            assert_allclose(row["fixes"][name]["mean"], ours["mean"], rtol=0, atol=1e-9)
            checked += 1
    assert checked >= 6


def test_inner_cv_replay_mode_scores_as_the_stage_replays_did(realbench_fusion_small, tmp_path):
    """The inner cross-validation replays once per (walk, site, --set list) as ``--fusion adaptive
    --channels FIX,POSE`` (realbench.select.MODES) and scores the matcher's Wi-Fi fix errors on those
    FIX rows, where it once replayed ``--fusion wifi_only`` with every channel, and with a one-particle
    cloud: --fusion only picks what is published, a FIX record's fix fields are the fix as offered,
    the same for every scheme, and neither the fixes nor the adaptive scheme read the particle cloud.
    GIVEN a real walk on its fold's site, WHEN replayed the three ways, THEN the fix residuals and the
    adaptive POSE errors are bit-identical and the filtered log holds FIX and POSE only."""
    from stridefix_analyzer.firmware import Firmware
    from stridefix_lab.realbench import select as rs

    r = realbench_fusion_small
    row = r["doc"]["groups"][0]["walk_rows"][1]
    imp = r["out"] / "cache" / "site1-F2" / f"{row['walk']}.lcmlog"
    truth = read_logs([imp], decode=("TRUTH",)).table("TRUTH")
    wp_t, wp_xy = truth["t_us"], np.column_stack([truth["x_m"], truth["y_m"]])
    fw, site = Firmware(r["stridefixd"]), f"{row['dir']}/site.sfsite"
    sets = [*MSINDOOR_SETS, "fingerprint.average_scans=2"]
    logs = {}
    for tag, fusion, channels in (
        ("wifi_only", "wifi_only", None),
        ("adaptive", "adaptive", None),
        ("mode", *rs.MODES["one"][:2]),
    ):
        logs[tag] = tmp_path / f"{tag}.lcmlog"
        extra = list(rs.MODES["one"][2]) if tag == "mode" else []
        fw.run(
            input=f"lcmlog:{imp}",
            site=site,
            fusion=fusion,
            log=logs[tag],
            sets=[*sets, *extra],
            channels=channels,
        )
    counts = read_logs([logs["mode"]], decode=()).messages
    assert set(counts) == {"FIX", "POSE"} and counts["FIX"] > 5
    fix = rs.fix_residuals_m(logs["wifi_only"], wp_t, wp_xy)
    assert len(fix) > 5
    assert_array_equal(rs.fix_residuals_m(logs["mode"], wp_t, wp_xy), fix)
    assert_array_equal(
        rs.pose_errors_m(logs["mode"], wp_t, wp_xy), rs.pose_errors_m(logs["adaptive"], wp_t, wp_xy)
    )
    job = {"mode": "one", "stridefixd": str(r["stridefixd"]), "import_log": str(imp), "site": site}
    got = rs.replay_products(
        {**job, "log": str(tmp_path / "p.lcmlog"), "sets": sets, "wp_t_us": wp_t, "wp_xy_m": wp_xy}
    )
    assert got["failure"] is None
    assert_array_equal(got["fix"], fix)
    assert_array_equal(rs.SCORES["matcher"](got), rs.fix_errors_m(logs["wifi_only"], wp_t, wp_xy))


def test_a_batch_replays_as_separate_processes_do(realbench_fusion_small, tmp_path):
    """`stridefixd --batch FILE` (the inner cross-validation's replays, realbench.select.replay_batch):
    GIVEN two real walks on one site, without a setting, again (the site's workspace kept prepared:
    reuse_prepared), with a setting the preparation depends on, and a replay that cannot run,
    WHEN run in one batch and each alone, THEN every channel but HEALTH (its loop timing is the
    host's) is the same, message for message, and the batch reports each exit status."""
    from stridefix_analyzer.firmware import Firmware
    from stridefix_analyzer.io.logread import KNOWN_CHANNELS

    r = realbench_fusion_small
    rows = r["doc"]["groups"][0]["walk_rows"]
    site = f"{rows[0]['dir']}/site.sfsite"
    imports = [r["out"] / "cache" / "site1-F2" / f"{row['walk']}.lcmlog" for row in rows[1:3]]
    runs = [
        {"input": f"lcmlog:{imp}", "site": site, "sets": [*MSINDOOR_SETS, *extra]}
        for imp in imports
        for extra in ([], [], ["fingerprint.powed_beta=2"])
    ]
    fw = Firmware(r["stridefixd"])
    batch = [{**kw, "log": tmp_path / f"batch{i}.lcmlog"} for i, kw in enumerate(runs)]
    missing = {"input": f"lcmlog:{tmp_path / 'missing.lcmlog'}", "log": tmp_path / "missing_out.lcmlog"}
    assert fw.run_batch([*batch, missing], tmp_path / "jobs.batch") == [0] * len(runs) + [2]
    channels = [c for c in KNOWN_CHANNELS if c != "HEALTH"]
    for i, kw in enumerate(runs):
        alone = tmp_path / f"alone{i}.lcmlog"
        fw.run(**kw, log=alone)
        a, b = (read_logs([p], decode=channels) for p in (batch[i]["log"], alone))
        assert a.messages == b.messages and a.config == b.config
        for c in channels:
            ta, tb = a.table(c), b.table(c)
            assert (ta is None) == (tb is None), c
            for k in ta.names if ta is not None else ():
                assert_array_equal(ta[k], tb[k], err_msg=f"{c}.{k}")
