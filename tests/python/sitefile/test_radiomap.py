"""radiomap build/show on synthetic logs with known RSSIs: a survey (exact means, stds, counts per
surveyed point) and a walk with sparse truth waypoints (scans interpolated into the right cells)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer import cli
from stridefix_analyzer.io import sitefile
from stridefix_analyzer.radiomap import build as radiomap

S = 1_000_000  # µs per s

# --- survey: 4 points × 3 scans -------------------------------------------------------------------
POINTS = [(0.0, 0.0, 0), (4.0, 0.0, 0), (0.0, 4.0, 1), (4.0, 4.0, 1)]
BASE_A = [-40.0, -50.0, -60.0, -70.0]  # AP 0xA: BASE + (0, −2, +2) in the 3 scans
AP_A, AP_B, AP_C, AP_D = 0xA, 0xB, 0xC, 0xD


def survey_events(msg):
    """Point k: truth at 10k s and 10k+5 s (standing), scans at 10k+1, +2, +3 s.

    AP A in every scan; AP B in scans 0 and 1 at −70 and −74; AP C once at point 0 (below min count);
    AP D at point 3 only, twice in scan 0 (−60, −50: the strongest counts) then −52, −54.
    """
    events = []
    for k, (x, y, f) in enumerate(POINTS):
        t0 = 10 * k * S
        events += [("TRUTH", msg.truth(t0, x, y, f)), ("TRUTH", msg.truth(t0 + 5 * S, x, y, f))]
        for j, delta in enumerate((0.0, -2.0, 2.0)):
            aps = [(AP_A, BASE_A[k] + delta)]
            if j < 2:
                aps.append((AP_B, -70.0 - 4.0 * j))
            if k == 0 and j == 0:
                aps.append((AP_C, -85.0))
            if k == 3:
                aps += [(AP_D, -60.0), (AP_D, -50.0)] if j == 0 else [(AP_D, -50.0 - 2.0 * j)]
            events.append(("WIFI", msg.scan(t0 + (j + 1) * S, aps, scan_id=3 * k + j)))
    return sorted(events, key=lambda e: e[1].t_us)


@pytest.fixture
def survey_log(write_log, msg):
    return write_log("survey.lcmlog", survey_events(msg))


def _entries(site):
    """{(bssid, rp): (mean, std, count)}"""
    return {
        (site.ap_bssid[a], r): (m, s, c)
        for a, r, m, s, c in zip(
            site.entry_ap, site.entry_rp, site.entry_mean_dbm, site.entry_std_db, site.entry_count
        )
    }


def test_survey_exact_statistics(survey_log, tmp_path, stridefix_main, capsys):
    out = tmp_path / "survey.sfsite"
    assert stridefix_main(["radiomap", "build", survey_log, "--out", out]) == 0
    text = capsys.readouterr().out
    assert "mode        survey" in text and "4 RPs, 3 APs, 9 entries (1 below min count 2" in text
    site = sitefile.read_site(out)
    assert site.n_rp == 4 and site.cell_size_m == 0.0
    assert [(x, y, f) for x, y, f in zip(site.rp_x_m, site.rp_y_m, site.rp_floor)] == POINTS
    assert list(site.rp_scans) == [3, 3, 3, 3]
    assert list(site.ap_bssid) == [AP_A, AP_B, AP_D]  # C heard once: dropped
    assert (site.lowest_floor, list(site.floor_height_m)) == (0, [0.0, 3.5])
    e = _entries(site)
    assert len(e) == 9
    spread = math.sqrt(8.0 / 3.0)  # population std of (0, −2, 2)
    for k in range(4):
        assert_allclose(e[(AP_A, k)], (BASE_A[k], spread, 3), rtol=1e-6)
        assert_allclose(e[(AP_B, k)], (-72.0, 2.0, 2), rtol=1e-6)
    assert_allclose(e[(AP_D, 3)], (-52.0, spread, 3), rtol=1e-6)  # −50 (strongest of two), −52, −54
    keys = list(zip(site.entry_ap, site.entry_rp))
    assert keys == sorted(keys)


def test_survey_min_count_one_keeps_single_hearings(survey_log, msg):
    site, summary = radiomap.build_site(radiomap.load_recordings([str(survey_log)]), min_count=1)
    assert summary["mode"] == "survey"
    assert_allclose(_entries(site)[(AP_C, 0)], (-85.0, 0.0, 1))


# --- walk: waypoints (0,0) → (10,0) → (10,10), one scan per second --------------------------------


def walk_position(t_s):
    return (t_s, 0.0) if t_s <= 10.0 else (10.0, t_s - 10.0)


def walk_rssi(x, y):
    return -40.0 - x - y


def walk_logs(write_log, msg, prefix=""):
    """Firmware-style log with WIFI only and a separate truth log with 3 waypoints (the simulator's
    layout). Scans at 0.5 … 19.5 s; plus one before the truth, one after it, one incomplete."""
    truth = [
        ("TRUTH", msg.truth(0, 0, 0)),
        ("TRUTH", msg.truth(10 * S, 10, 0)),
        ("TRUTH", msg.truth(20 * S, 10, 10)),
    ]
    scans = []
    for i in range(20):
        t = i + 0.5
        x, y = walk_position(t)
        aps = [(0x1, walk_rssi(x, y))] + ([(0x2, -80.0)] if x < 4 else [])
        scans.append(("WIFI", msg.scan(round(t * S), aps, scan_id=i)))
    scans += [
        ("WIFI", msg.scan(-1 * S, [(0x1, -1.0)], scan_id=100)),
        ("WIFI", msg.scan(25 * S, [(0x1, -1.0)], scan_id=101)),
        ("WIFI", msg.scan(round(5.25 * S), [(0x1, -1.0)], scan_id=102, complete=False)),
    ]
    scans.sort(key=lambda e: e[1].t_us)
    return (write_log(f"{prefix}fw.lcmlog", scans), write_log(f"{prefix}truth.lcmlog", truth))


def expected_cells(cell_m=2.0):
    """(floor, iy, ix) → list of scan positions, computed independently of the module."""
    cells = {}
    for i in range(20):
        x, y = walk_position(i + 0.5)
        cells.setdefault((0, math.floor(y / cell_m), math.floor(x / cell_m)), []).append((x, y))
    return dict(sorted(cells.items()))


def test_walk_scans_interpolated_into_cells(write_log, msg, tmp_path, stridefix_main, capsys):
    fw, truth = walk_logs(write_log, msg)
    out = tmp_path / "walk.sfsite"
    assert (
        stridefix_main(
            [
                "radiomap",
                "build",
                fw,
                truth,
                "--out",
                out,
                "--cell-size-m",
                "2",
                "--name",
                "corridor",
                "--map-rotation-deg",
                "-12.5",
            ]
        )
        == 0
    )
    text = capsys.readouterr().out
    assert "mode        walk" in text
    assert "skipped: incomplete 1, outside_truth 2" in text
    site = sitefile.read_site(out)
    cells = expected_cells()
    assert (site.name, site.map_rotation_deg, site.cell_size_m) == ("corridor", -12.5, 2.0)
    assert site.n_rp == len(cells) == 10
    for r, positions in enumerate(cells.values()):
        pos = np.asarray(positions)
        assert_allclose([site.rp_x_m[r], site.rp_y_m[r]], pos.mean(axis=0), rtol=1e-6)
        assert site.rp_scans[r] == len(positions)
    e = _entries(site)
    for r, positions in enumerate(cells.values()):
        rssi = [walk_rssi(x, y) for x, y in positions]
        assert_allclose(e[(0x1, r)], (np.mean(rssi), np.std(rssi), len(rssi)), rtol=1e-6)
    assert {r for b, r in e if b == 0x2} == {0, 1}  # heard only at x < 4 m


def test_recordings_with_commas_are_kept_apart(write_log, msg):
    a = walk_logs(write_log, msg, "a_")
    b = walk_logs(write_log, msg, "b_")
    recs = radiomap.load_recordings([f"{a[0]},{a[1]}", f"{b[0]},{b[1]}"])
    assert len(recs) == 2
    site, summary = radiomap.build_site(recs)
    assert summary["scans"]["used"] == 40
    assert list(site.rp_scans) == [2 * len(p) for p in expected_cells().values()]


def test_walk_skips_scans_between_floors(write_log, msg):
    events = [
        ("TRUTH", msg.truth(0, 0, 0, 0)),
        ("TRUTH", msg.truth(4 * S, 0, 0, 0)),
        ("TRUTH", msg.truth(10 * S, 0, 0, 1)),
        ("TRUTH", msg.truth(14 * S, 0, 0, 1)),
    ]
    events += [("WIFI", msg.scan(t * S, [(0x1, -50.0)], scan_id=t)) for t in (1, 2, 3, 6, 7, 11, 12, 13)]
    log = write_log("stairs.lcmlog", sorted(events, key=lambda e: e[1].t_us))
    site, summary = radiomap.build_site(
        radiomap.load_recordings([str(log)]), mode="walk", floor_heights_m=[0.0, 4.2]
    )
    assert summary["scans"]["skipped_floor_change"] == 2
    assert list(site.rp_floor) == [0, 1] and list(site.rp_scans) == [3, 3]
    assert list(site.floor_height_m) == [0.0, 4.2]


def test_survey_mode_forced_on_a_walk_fails(write_log, msg):
    fw, truth = walk_logs(write_log, msg)
    with pytest.raises(radiomap.RadioMapInputError, match="none of the 20 placed scan"):
        radiomap.build_site(radiomap.load_recordings([str(fw), str(truth)]), mode="survey")


def test_missing_truth_is_a_clear_error(write_log, msg, tmp_path, stridefix_main, capsys):
    fw, _ = walk_logs(write_log, msg)
    assert stridefix_main(["radiomap", "build", fw, "--out", tmp_path / "x.sfsite"]) == 2
    assert "no TRUTH messages" in capsys.readouterr().err
    assert (
        stridefix_main(["radiomap", "build", tmp_path / "nope.lcmlog", "--out", tmp_path / "x.sfsite"]) == 2
    )
    assert "nope.lcmlog" in capsys.readouterr().err


def test_show_summary_and_png(survey_log, tmp_path, stridefix_main, capsys):
    out = tmp_path / "s.sfsite"
    assert (
        stridefix_main(
            ["radiomap", "build", survey_log, "--out", out, "--lowest-floor", "-1", "--floor-height-m", "3"]
        )
        == 0
    )
    capsys.readouterr()
    png = tmp_path / "plots" / "rps.png"
    assert stridefix_main(["radiomap", "show", out, "--png", png]) == 0
    text = capsys.readouterr().out
    assert "4 RPs, 3 APs, 9 entries" in text and "floors      3 from -1" in text
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    bad = tmp_path / "bad.sfsite"
    bad.write_bytes(out.read_bytes()[:-1])
    assert stridefix_main(["radiomap", "show", bad]) == 2
    assert "length mismatch (truncated)" in capsys.readouterr().err


def test_registered_in_cli():
    assert cli.SUBCOMMANDS["radiomap"] == "stridefix_analyzer.radiomap.cli"
