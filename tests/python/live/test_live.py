"""stridefix live: the folded state against the analyzer's reading of the same log, the server over
HTTP, and the page in headless Chromium (DOM and a screenshot) against a replayed log."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import lcm
import numpy as np
import pytest
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.channels import CHANNELS
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.live.server import SUBSCRIBE, plan_of, walls_of
from stridefix_analyzer.live.state import LiveState
from stridefix_analyzer.scoring.fixsources import fix_source_counts


@pytest.fixture(scope="module")
def campus_walk(tmp_path_factory, stridefixd):
    """The campus (walls, Wi-Fi, BLE, GNSS, landmarks) surveyed into a site, then a 2-minute walk
    replayed with it: a log with every scheme's POSE and FIX records of every source."""
    from stridefix_lab.bench import fusion, sources

    out = tmp_path_factory.mktemp("live")
    fw = Firmware(stridefixd)
    site, _ = sources.build_site(fw, out / "survey")
    fusion.simulate_and_log("campus", 1, fw, out / "walk", site)
    log = out / "walk" / "stridefixd.lcmlog"
    data = read_logs([log], decode=("POSE", "STEP", "FIX", "HEALTH"))
    return {"site": site, "log": log, "data": data}


@pytest.fixture(scope="module")
def office_walk(tmp_path_factory, stridefixd, cli):
    """The demo's office: surveyed (seed 1000) into a site with its building.toml (two floors, 114
    walls, the stairs and the elevator), then the default walk replayed with it."""
    out = tmp_path_factory.mktemp("office")
    sv = out / "survey"
    assert cli("sim", "--scenario", "office_survey", "--seed", "1000", "--out", str(sv)).returncode == 0
    fw = Firmware(stridefixd)
    fw.run(input=sv / "board.candump", log=sv / "fw.lcmlog")
    rot = json.loads((sv / "sim_summary.json").read_text())["map_rotation_deg"]
    site = out / "site.sfsite"
    p = cli(
        "radiomap", "build", str(sv / "fw.lcmlog"), str(sv / "truth.lcmlog"), "--mode", "survey",
        "--map-rotation-deg", str(rot), "--building", str(sv / "building.toml"), "--out", str(site),
    )  # fmt: skip
    assert p.returncode == 0, p.stderr
    assert cli("sim", "--out", str(out / "walk")).returncode == 0
    log = out / "walk" / "stridefixd.lcmlog"
    fw.run(input=out / "walk" / "board.candump", log=log, site=site)
    data = read_logs([log], decode=("POSE", "STEP", "FIX", "HEALTH"))
    return {"site": site, "log": log, "data": data}


def _fold(log: Path, walls) -> LiveState:
    state = LiveState(walls)
    pattern = re.compile(f"^(?:{SUBSCRIBE})$")
    for event in lcm.EventLog(str(log), "r"):
        if pattern.match(event.channel):
            state.add(event.channel, CHANNELS[event.channel].msg_type.decode(event.data))
    return state


def _last_on_pose(log: Path) -> str:
    """The scheme of the last message on POSE itself (the primary pose, whichever scheme it copies)."""
    from stridefix import pose_t
    from stridefix_analyzer.schemes import scheme_name

    last = [e for e in lcm.EventLog(str(log), "r") if e.channel == "POSE"][-1]
    return scheme_name(pose_t.decode(last.data).scheme)


def _expected(data):
    pose, step = data.table("POSE"), data.table("STEP")
    last = {}
    for code in np.unique(pose["scheme"]):
        rows = pose.rows(pose["scheme"] == code)
        last[int(code)] = (float(rows["x_m"][-1]), float(rows["y_m"][-1]), int(rows["floor"][-1]), len(rows))
    return {"steps": len(step), "last": last, "fix": fix_source_counts(data.table("FIX"))}


def test_state_folds_what_the_analyzer_reads(campus_walk):
    """GIVEN the campus log folded message by message, THEN steps, every scheme's last pose and pose
    count, and the FIX verdicts per scheme and source equal the analyzer's reading of the same log."""
    exp = _expected(campus_walk["data"])
    doc = _fold(campus_walk["log"], walls_of(str(campus_walk["site"]))).snapshot()
    assert doc["steps"] == exp["steps"] > 100
    got = {
        s["code"]: (s["last"]["x_m"], s["last"]["y_m"], s["last"]["floor"], s["poses"])
        for s in doc["schemes"]
    }
    assert got == exp["last"]
    assert doc["fix_counts"] == exp["fix"]
    assert sum(c["offered"] for m in exp["fix"].values() for c in m.values()) > 100
    assert len(doc["walls"]) > 10
    assert doc["primary"]["scheme"] == _last_on_pose(campus_walk["log"])  # the firmware's primary pose
    # a client that holds every point gets none again; the tracks are thinned to a fixed size
    sent: dict = {}
    first = _fold(campus_walk["log"], []).snapshot(sent)
    assert all(s["track_start"] == 0 and 100 < len(s["track"]) < 400 for s in first["schemes"])


def _start_live(url: str, site: Path | None = None) -> tuple[subprocess.Popen, str]:
    exe = Path(sys.executable).with_name("stridefix")
    cmd = [str(exe), "live", "--lcm-url", url, "--port", "0"] + (["--site", str(site)] if site else [])
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    m = re.search(r"(http://127\.0\.0\.1:\d+/)", line)
    assert m, line + proc.stderr.read()
    return proc, m.group(1)


def _state(base: str) -> dict:
    with urllib.request.urlopen(base + "state", timeout=10) as r:
        return json.load(r)


def test_server_serves_the_state_of_a_replayed_log(campus_walk):
    exp = _expected(campus_walk["data"])
    proc, base = _start_live(f"file://{campus_walk['log']}?speed=0", campus_walk["site"])
    try:
        deadline = time.time() + 60
        doc = _state(base)
        while not doc["ended"] and time.time() < deadline:
            time.sleep(0.2)
            doc = _state(base)
        assert doc["ended"] and doc["steps"] == exp["steps"] and doc["fix_counts"] == exp["fix"]
        with urllib.request.urlopen(base, timeout=10) as r:
            page = r.read().decode()
        assert '<canvas id="map"' in page and "http://" not in page and "https://" not in page
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def test_bad_lcm_url_exits_2(cli):
    p = cli("live", "--lcm-url", "nosuch://x", "--port", "0")
    assert p.returncode == 2 and "--lcm-url" in p.stderr


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (tools/deps.sh installs it)")
def test_page_in_headless_chromium(campus_walk, tmp_path):
    """GIVEN the log replayed at 20x through `stridefix live`, WHEN headless Chromium opens the page,
    THEN as the log ends the DOM shows the step count, every scheme, the FIX verdicts and HEALTH, the
    page's tracks are the server's, the map is drawn (walls and tracks), and no script error."""
    from playwright.sync_api import sync_playwright

    exp = _expected(campus_walk["data"])
    proc, base = _start_live(f"file://{campus_walk['log']}?speed=20", campus_walk["site"])
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            errors: list[str] = []
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(base)
            page.wait_for_function(
                "document.getElementById('status').textContent === 'log ended'", timeout=60000
            )
            page.wait_for_timeout(500)  # the last push after the end
            assert int(page.inner_text("#steps")) == exp["steps"]
            assert page.inner_text("#primary") == _last_on_pose(campus_walk["log"])
            names = page.eval_on_selector_all(
                "#schemes tr[data-scheme]", "rows => rows.map(r => r.dataset.scheme)"
            )
            assert len(names) == len(exp["last"])
            row = page.query_selector("#fix-table tr[data-scheme='adaptive'][data-method='wifi']")
            cells = [c.inner_text() for c in row.query_selector_all("td")]
            c = exp["fix"]["adaptive"]["wifi"]
            assert cells[2:5] == [str(c["offered"]), str(c["accepted"]), str(c["rejected"])]
            assert page.query_selector("#health-table tr[data-key='frames_total']") is not None
            srv = _state(base)
            for s in srv["schemes"]:
                assert page.evaluate(f"S.schemes[{s['code']}].track") == s["track"], s["name"]
            inked = page.evaluate(
                """() => { const c = document.getElementById('map'); const d = c.getContext('2d')
                   .getImageData(0, 0, c.width, c.height).data; let n = 0;
                   for (let i = 3; i < d.length; i += 4) if (d[i] > 0) n++; return n; }"""
            )
            assert inked > 5000  # walls and tracks drawn, not an empty canvas
            shot = tmp_path / "live.png"
            page.screenshot(path=str(shot), full_page=True)
            assert shot.read_bytes().startswith(b"\x89PNG") and shot.stat().st_size > 20_000
            assert errors == []
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=10)


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (tools/deps.sh installs it)")
@pytest.mark.parametrize(
    ("walk", "port_kinds", "n_floors"),
    [("campus_walk", {"door"}, 1), ("office_walk", {"stairs", "elevator"}, 2)],
)
def test_page_floor_plan_toggles_zoom_and_axes(request, walk, port_kinds, n_floors):
    """GIVEN the campus log replayed through `stridefix live --site`, WHEN headless Chromium shows
    each floor, unchecks a scheme, zooms and pans, THEN the map draws exactly the site's walls and
    ports of the floor shown, hides that scheme's track alone (the primary pose's stays on), and the
    scale bar and the axes' ticks follow the zoom (a nice 1-2-5 length, evenly spaced ticks)."""
    from playwright.sync_api import sync_playwright

    w = request.getfixturevalue(walk)
    walls, ports = plan_of(str(w["site"]))
    assert {p["kind"] for p in ports} == port_kinds
    proc, base = _start_live(f"file://{w['log']}?speed=0", w["site"])
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"], headless=True)
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            errors: list[str] = []
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.goto(base)
            page.wait_for_function(
                "document.getElementById('status').textContent === 'log ended'", timeout=60000
            )
            page.wait_for_timeout(500)
            drawn = lambda: page.evaluate("Object.assign({}, document.getElementById('map').dataset)")  # noqa: E731
            # the floor plan of every floor, one floor button at a time
            floors = sorted({wall[4] for wall in walls})
            assert len(floors) == n_floors
            for f in floors:
                page.click(f"#floors button[data-floor='{f}']")
                d = drawn()
                assert int(d["floor"]) == f
                assert int(d["walls"]) == sum(1 for wall in walls if wall[4] == f) > 0
                assert int(d["ports"]) == sum(1 for q in ports if q["floor_lo"] <= f <= q["floor_hi"])
            # a checkbox hides one scheme's track; the primary pose's cannot be hidden
            primary = page.inner_text("#primary")
            tracks = drawn()["tracks"].split(",")
            assert primary in tracks and len(tracks) == len(_expected(w["data"])["last"])
            other = next(t for t in tracks if t != primary)
            page.uncheck(f"#toggles input[data-scheme='{other}']")
            assert drawn()["tracks"].split(",") == [t for t in tracks if t != other]
            box = page.locator(f"#toggles input[data-scheme='{primary}']")
            assert box.is_checked() and box.is_disabled()
            page.check(f"#toggles input[data-scheme='{other}']")
            assert drawn()["tracks"].split(",") == tracks

            # zoom: the scale bar's label and the tick spacing follow; fit returns to the start
            def scale_and_step():
                d = drawn()
                xs = [float(v) for v in d["xticks"].split(",")]
                steps = np.diff(xs)
                assert len(xs) >= 3 and np.allclose(steps, steps[0])  # evenly spaced, in metres
                ys = np.diff([float(v) for v in d["yticks"].split(",")])
                assert np.allclose(ys, steps[0])  # the same step on y: equal scale
                m = float(d["scaleM"])
                assert page.inner_text("#scale-label") == f"{m:g} m"
                assert m / 10 ** np.floor(np.log10(m)) in (1, 2, 5)
                return m, steps[0]

            m0, step0 = scale_and_step()
            page.click("#zoom-in")
            page.click("#zoom-in")
            m1, step1 = scale_and_step()
            assert m1 < m0 and step1 < step0
            page.click("#zoom-fit")
            assert scale_and_step() == (m0, step0)
            box = page.locator("#map").bounding_box()
            page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
            page.mouse.wheel(0, 600)  # wheel down: zoom out
            page.wait_for_timeout(100)
            assert scale_and_step()[0] > m0
            # a drag pans: the ticks move, the scale does not
            page.click("#zoom-fit")
            x_before = drawn()["xticks"]
            page.mouse.move(box["x"] + 300, box["y"] + 300)
            page.mouse.down()
            page.mouse.move(box["x"] + 100, box["y"] + 300, steps=5)
            page.mouse.up()
            assert drawn()["xticks"] != x_before and scale_and_step()[0] == m0
            assert errors == []
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def _pose(t_us: int, x: float, scheme: int):
    from stridefix import pose_t

    m = pose_t()
    m.t_us, m.x_m, m.y_m, m.floor, m.scheme = t_us, x, 0.0, 0, scheme
    return m


def test_old_logs_all_on_pose_and_new_logs_with_copies():
    """An old log (every scheme on POSE) feeds every scheme from POSE; a new one (POSE_<SCHEME> plus
    a copy of one scheme on POSE) counts each pose once and takes the primary from POSE."""
    from stridefix import pose_t

    old = LiveState()
    for k in range(10):
        old.add("POSE", _pose(1_000_000 * k, k, pose_t.SCHEME_ADAPTIVE))
        old.add("POSE", _pose(1_000_000 * k, -k, pose_t.SCHEME_PDR_ONLY))
    doc = old.snapshot()
    assert [(s["name"], s["poses"]) for s in doc["schemes"]] == [("pdr_only", 10), ("adaptive", 10)]
    assert doc["primary"]["scheme"] == "adaptive" and doc["primary"]["x_m"] == 9
    new = LiveState()
    for k in range(10):
        new.add("POSE", _pose(1_000_000 * k, k, pose_t.SCHEME_EKF))  # the copy comes first here
        new.add("POSE_EKF", _pose(1_000_000 * k, k, pose_t.SCHEME_EKF))
        new.add("POSE_PDR_ONLY", _pose(1_000_000 * k, -k, pose_t.SCHEME_PDR_ONLY))
    doc = new.snapshot()
    assert sorted((s["name"], s["poses"]) for s in doc["schemes"]) == [("ekf", 10), ("pdr_only", 10)]
    assert doc["primary"]["scheme"] == "ekf" and doc["primary"]["x_m"] == 9
