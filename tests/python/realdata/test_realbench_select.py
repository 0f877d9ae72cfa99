"""realbench's per-fold matcher choice by cross-validation inside the training walks
(``stridefix_lab.realbench.select``, the rows of ``realbench.tuning``): the fix-error arithmetic, the user's override, and a real
run on 8 msindoor walks checked for the choice rule and for leakage of the held-out block."""

from __future__ import annotations

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import fix_t, pose_t
from stridefix_analyzer.io.results import read_realbench_results
from stridefix_analyzer.io.sitefile import read_site
from stridefix_lab.realbench import select as rs
from stridefix_lab.realbench import tuning

from .conftest import MSINDOOR


def _fix(t_us, x, y, scheme, accuracy=3.0):
    m = fix_t()
    m.t_us, m.method, m.scheme, m.x_m, m.y_m, m.accuracy_m = t_us, 1, scheme, x, y, accuracy
    m.reason_text = ""
    return m


def test_fix_errors_against_interpolated_truth(tmp_path):
    # truth: (0,0) at 0 s → (10,0) at 10 s. Fixes at 2 s (2 schemes repeat it), 5 s, 12 s (outside).
    path = tmp_path / "fw.lcmlog"
    log = lcm.EventLog(str(path), "w", overwrite=True)
    for m in (
        _fix(2_000_000, 2.0, 3.0, 1),
        _fix(2_000_000, 2.0, 3.0, 5),
        _fix(5_000_000, 9.0, 0.0, 1),
        _fix(12_000_000, 0.0, 0.0, 1),
    ):
        log.write_event(m.t_us, "FIX", m.encode())
    log.close()
    err = rs.fix_errors_m(path, [0, 10_000_000], [[0.0, 0.0], [10.0, 0.0]])
    # at 2 s the truth is (2, 0): error 3; at 5 s (5, 0): error 4; 12 s is outside the truth span
    assert_allclose(err, [3.0, 4.0])


def test_pose_errors_are_causal_at_the_waypoints(tmp_path):
    # poses: uninitialised at 0.5 s, (1,0) at 1 s, (4,4) at 3 s. Waypoints at 0.6 s (no pose yet),
    # 2 s (latest pose (1,0) against (1,2): 2 m) and 3 s ((4,4) against (1,0): 5 m).
    path = tmp_path / "fw.lcmlog"
    log = lcm.EventLog(str(path), "w", overwrite=True)
    for t, x, y, sigma in ((500_000, 0.0, 0.0, 1e6), (1_000_000, 1.0, 0.0, 2.0), (3_000_000, 4.0, 4.0, 2.0)):
        m = pose_t()
        m.t_us, m.x_m, m.y_m, m.sigma_m, m.scheme = t, x, y, sigma, pose_t.SCHEME_ADAPTIVE
        log.write_event(t, "POSE", m.encode())
    log.close()
    err = rs.pose_errors_m(path, [600_000, 2_000_000, 3_000_000], [[9, 9], [1.0, 2.0], [1.0, 0.0]])
    assert_allclose(err, [2.0, 5.0])


def test_a_user_setting_replaces_the_candidates():
    assert tuning.candidates("matcher", []) == tuning.MATCHER_VARIANTS
    assert tuning.candidates("matcher", ["fingerprint.average_scans=3"]) == {"given": []}
    assert tuning.candidates("matcher", ["fingerprint.powed_beta=3"]) == {"given": []}
    assert tuning.candidates("matcher", ["fusion.gate_sigma=4"]) == tuning.MATCHER_VARIANTS
    assert tuning.candidates("adaptive", ["fusion.acc_wifi_scale=0.3"]) == {"given": []}
    assert tuning.candidates("adaptive", []) == tuning.ADAPTIVE_VARIANTS
    assert tuning.candidates("heading", ["heading.learn_offset=1"]) == {"given": []}


def test_too_few_walks_keep_the_firmware_default():
    walks = [{"walk": str(i)} for i in range(rs.MIN_WALKS - 1)]
    choice, report = rs.select(
        walks, None, stridefixd="x", work_dir="unused", base_sets=[], candidates=tuning.MATCHER_VARIANTS
    )
    assert choice == [next(iter(tuning.MATCHER_VARIANTS))] * len(walks)
    assert report["chosen_by"].startswith("default")
    assert rs.n_tasks(rs.MIN_WALKS - 1, 2) == 0
    assert rs.n_tasks(8, 2) == 3 * 8 * 2


def test_no_block_is_scored_with_a_map_or_walk_of_its_own(tmp_path):
    """10 synthetic walks, 4 blocks (walk i in block i mod 4). Each walk's ``stats`` is a bit, so the
    removed statistics say exactly which walks a map left out. Fake replays report an error that
    favours "2 scans" only when block a is 1, so the choice must follow the block."""
    walks = [
        {"walk": f"w{i}", "stats": 1 << i, "import_log": "-", "waypoint_t_us": [], "waypoint_xy_m": []}
        for i in range(10)
    ]
    sites = {}

    def build_site(removed, others, name, path):
        sites[str(path)] = (removed, {w["walk"] for w in others})
        path.write_bytes(b"")

    replays = []

    def replay(task):
        replays.append(task)
        better = "2 scans, dBm" if task["a"] == 1 else "1 scan, dBm"
        return {**task, "errors": np.array([1.0 if task["name"] == better else 2.0]), "failure": None}

    choice, report = rs.select(
        walks,
        build_site,
        stridefixd="x",
        work_dir=tmp_path,
        base_sets=["k=v"],
        candidates=tuning.MATCHER_VARIANTS,
        replay=replay,
    )
    assert choice == ["2 scans, dBm" if i % 4 == 1 else "1 scan, dBm" for i in range(10)]
    assert len(replays) == rs.n_tasks(10, len(tuning.MATCHER_VARIANTS)) == 3 * 10 * 6
    for t in replays:
        removed, others = sites[t["site"]]
        a = t["a"]
        walk = int(t["walk"][1:])
        assert walk % 4 != a  # never a walk of the scored block
        left_out = {i for i in range(10) if removed >> i & 1}
        assert {i for i in range(10) if i % 4 == a} <= left_out  # the map never saw block a
        assert walk in left_out  # nor the replayed walk
        assert not {int(w[1:]) for w in others} & left_out
        assert t["sets"][0] == "k=v"  # the user's settings come first
    for b in report["blocks"].values():
        assert b["candidates"]["1 scan, dBm"]["fixes"] > 0


@pytest.fixture(scope="module")
def realbench_eight(request, tmp_path_factory, cli, lab) -> dict:
    """GIVEN `stridefix-lab realbench --format msindoor site1/F2 --limit 8` (enough walks for a choice)."""
    floor = MSINDOOR / "site1" / "F2"
    if not floor.is_dir():
        pytest.skip(f"real msindoor data not found at {floor}")
    stridefixd = request.getfixturevalue("stridefixd")
    out = tmp_path_factory.mktemp("realbench_select")
    results = out / "results.json"
    proc = lab(
        "realbench",
        "--format",
        "msindoor",
        str(floor),
        "--limit",
        "8",
        "--no-report",
        "--stridefixd",
        str(stridefixd),
        "--out",
        str(results),
        "--quiet",
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return {"doc": read_realbench_results(results), "out": out}


def test_each_block_takes_the_candidate_with_the_lowest_pooled_error(realbench_eight):
    (g,) = realbench_eight["doc"]["groups"]
    sel = g["matcher_selection"]
    assert sel["chosen_by"].startswith("cross-validation") and not sel["failures"]
    assert set(sel["blocks"]) == {"0", "1", "2", "3"}
    for b in sel["blocks"].values():
        c = b["candidates"]
        assert set(c) == set(tuning.MATCHER_VARIANTS)
        for v in c.values():
            assert v["fixes"] > 20 and 0.5 < v["mean_m"] < 50.0  # real fixes, plausible errors
        assert b["chosen"] == min(c, key=lambda n: c[n]["mean_m"])
    # walk i (sorted by name) is in block i mod 4 and replays with that block's choice
    ad = g["adaptive_selection"]
    for b in ad["blocks"].values():
        c = b["candidates"]
        assert set(c) == set(tuning.ADAPTIVE_VARIANTS)
        assert b["chosen"] == min(c, key=lambda n: c[n]["mean_m"])
    for i, row in enumerate(g["walk_rows"]):
        assert row["fold"]["matcher_variant"] == sel["blocks"][str(i % 4)]["chosen"]
        assert row["fold"]["adaptive_variant"] == ad["blocks"][str(i % 4)]["chosen"]


def test_selection_maps_are_smaller_than_fold_maps(realbench_eight):
    """site_a_b leaves out two blocks (4 of 8 walks): fewer scans than a fold's map (7 of 8)."""
    (g,) = realbench_eight["doc"]["groups"]
    work = realbench_eight["out"] / "realbench_work" / "site1-F2"
    fold = read_site(work / g["walk_rows"][0]["walk"] / "site.sfsite")
    for a in range(4):
        for b in range(4):
            if a != b:
                site = read_site(work / "select" / f"site_{a}_{b}.sfsite")
                assert 0 < int(np.sum(site.rp_scans)) < int(np.sum(fold.rp_scans))


def test_a_replay_asked_for_twice_runs_once(monkeypatch):
    """The group's ReplayCache: tasks of any stage with the same (mode, walk, import log, site, --set
    list) share one replay (the adaptive stage's "table x 1" is the matcher's replay of block a's
    choice, the fix model's the adaptive stage's), each scored by its own stage, in task order."""
    ran = []

    def fake(job):
        ran.append((job["walk"], tuple(job["sets"])))
        n = len(job["sets"])
        return {
            "failure": None,
            "fix": np.array([[3.0 * n, 4.0 * n, 1.0, 0.0]]),
            "pose": np.array([float(n)]),
        }

    monkeypatch.setattr(rs, "replay_batch", lambda jobs: [fake(j) for j in jobs])
    runner = rs.TaskRunner(None, 1)
    base = {"mode": "one", "import_log": "x.lcmlog", "site": "s", "stridefixd": "fw", "a": 0, "name": "c"}
    cache = rs.ReplayCache()
    m = cache.run(
        [{**base, "walk": w, "stage": "matcher", "sets": s} for w in ("w0", "w1") for s in ([], ["k=1"])],
        runner,
        None,
    )
    assert [r["errors"].tolist() for r in m] == [[0.0], [5.0], [0.0], [5.0]]
    again = cache.run(
        [
            {**base, "walk": "w1", "stage": "adaptive", "sets": ["k=1"]},
            {**base, "walk": "w1", "stage": "fixmodel", "sets": ["k=1", "j=2"]},
        ],
        runner,
        None,
    )
    assert again[0]["errors"].tolist() == [1.0]
    assert again[1]["errors"].tolist() == [[6.0, 8.0, 1.0, 0.0]]
    assert ran == [("w0", ()), ("w0", ("k=1",)), ("w1", ()), ("w1", ("k=1",)), ("w1", ("k=1", "j=2"))]
    assert (cache.ran, cache.reused) == (5, 1)
