"""``stridefix-lab bench perf``: the estimator core's cost and the logger's speed against the unit's budgets.

Each figure says how it was measured:

* **instructions per call** (callgrind, repeatable on a noisy machine): the harness
  ``tests/perf/core_cost.c`` (``sf_core_cost``, built beside ``stridefixd``) drives one core call at a
  time; callgrind counts the instructions inside it (``--toggle-collect=FUNCTION``), divided by the
  calls the harness reports. Sensors: a 120 s walk at the board's rates (IMU 100 Hz, MAG 50 Hz, BARO
  20 Hz); "all core work per IMU sample" is the three calls' instructions over the IMU samples, and the
  attitude filter's share is ``sf_attitude_update_imu_finite`` (the estimator's call: its gates checked
  the sample) + ``sf_attitude_update_mag``. Wi-Fi: 50 fixes
  (``sf_fingerprint_match``) on synthetic maps of 100, 2 000 and 20 000 reference points of a building
  that grows with the map (one AP per 40 m², ~31–42 heard per scan; the harness's docstring), with the
  workspace stridefixd gives it (the candidate pre-selection, ``sf_fingerprint.h``) and, on the same
  scans, the full visit of every used AP's entries, each with its mean error; and against the APs
  heard: the ~2 000-RP map with scans hearing every AP above −70, −80, −85 or −88 dBm (~8–89 heard);
* **the ekf and particle schemes**: particle-cost's harness (``tests/perf/particle_cost.c``: 5 000
  walls, 1 000 particles, 400 PDR steps, a Wi-Fi-like fix every 4th) walks each scheme; callgrind counts
  inside ``sf_fusion_step_on_floor`` and ``sf_fusion_fix_on_floor``, per call;
* **state sizes**: ``sizeof`` printed by the harness (the radio map and the particle arrays are the
  caller's memory, not in them);
* **no heap in the core**: the ctest ``core_symbols`` check (``firmware/cmake/check_core_symbols.cmake``)
  on ``libsf_core.a``;
* **replay speed and peak RSS**: ``stridefix sim`` walks 1 hour (default scenario, no site), then
  ``stridefixd`` replays the candump file into an LCM log (decode, estimate, log); simulated seconds /
  the daemon's CPU seconds (user + system, every thread: "on one core", and not inflated by other
  processes on a loaded machine; the wall-clock ratio is reported beside it), and the daemon's peak
  RSS (its ``VmHWM``, polled); then
  ``stridefix analyze`` of that log and the truth, by wall clock.

The attitude peer is x-io Fusion (PyPI ``imufusion``, the C library compiled into its wheel): the same
samples (``sf_core_cost samples``) through ``FusionAhrsUpdate`` (gyro + accelerometer + magnetometer on
every IMU sample), counted by callgrind inside that function only; ours is ``sf_attitude_update_imu_finite`` +
``sf_attitude_update_mag`` per IMU sample (MAG at 50 Hz). The Python peers (:mod:`.perf_peers`,
``python_peers`` in the JSON, informative, no budget): the ``ahrs`` package's Madgwick and imufusion's
Python API on the same samples, wall time per sample and their yaw agreement, and our attitude's yaw
(``sf_core_cost yaw``) against Fusion's: RMS, max and mean of the wrapped difference after the
settle time (``python_peers.attitude.ours_vs_fusion_*``); scikit-learn's
``KNeighborsRegressor`` against ``sf_fingerprint_match`` on the harness's synthetic map, mean error and
queries/s. Writes ``perf.json``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from stridefix_analyzer import console
from stridefix_analyzer.firmware import REPO, Firmware

from stridefix_lab.bench import callgrind, particle_cost, perf_knn_real, perf_peers
from stridefix_lab.bench.registry import Bench
from stridefix_lab.bench.scale import add_floor_argument
from stridefix_lab.bench.soak import vm_hwm_kb
from stridefix_lab.stages import StageError, simulate, stridefix_exe

SENSOR_SECONDS = 120
WIFI_SIZES = (100, 2000, 20000)
WIFI_SCANS = 50
#: the scans' sensitivity [dBm] for the fix's cost against the APs heard, at ~2 000 RPs (-80: the map-size rows)
WIFI_HEARD_DBM = (-70.0, -80.0, -85.0, -88.0)
REPLAY_SECONDS = 3600

#: the unit's budgets: (key, figure, comparison, bound)
BUDGETS = (
    ("imu_all_ir", "all core work per IMU sample [instructions]", "<=", 1200),
    ("attitude_vs_fusion", "attitude filter / x-io Fusion's update, per IMU sample", "<=", 1.5),
    ("wifi_2000_ir", "Wi-Fi fix at ~2 000 RPs [instructions]", "<=", 150_000),
    ("wifi_scaling", "Wi-Fi fix at ~20 000 RPs / at ~2 000 RPs", "<=", 1.5),
    ("estimator_B", "sizeof(sf_estimator_t) without the radio map [B]", "<=", 16 * 1024),
    ("core_no_heap", "no heap, I/O or clock symbols in libsf_core.a", "==", True),
    ("replay_x_realtime", "end-to-end replay speed, CPU time [x real time]", ">=", 5000),
    ("peak_rss_kB", "stridefixd peak RSS during the replay [kB]", "<=", 8 * 1024),
    ("analyze_s", "stridefix analyze of the 1-hour walk [s]", "<=", 3.0),
)


def harness_path(stridefixd: Path) -> Path:
    """``sf_core_cost`` of the build tree that holds ``stridefixd`` (``build/firmware/stridefixd``)."""
    return stridefixd.resolve().parents[1] / "tests" / "perf" / "sf_core_cost"


def _harness_json(harness: Path, *args: str) -> dict[str, Any]:
    proc = subprocess.run([str(harness), *args], capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise StageError(f"perf: {harness} {' '.join(args)} failed ({proc.returncode}): {proc.stderr[-400:]}")
    return json.loads(proc.stdout)


def _callgrind(harness: Path, functions: tuple[str, ...], args: tuple[str, ...], out: Path) -> int:
    """Instructions inside ``functions`` (summed) over one run of the harness."""
    return callgrind.instructions([str(harness), *args], functions, out, "perf")


def measure_sensors(harness: Path, out: Path) -> dict[str, Any]:
    args = ("sensors", str(SENSOR_SECONDS))
    walk = _harness_json(harness, *args)
    ir = {
        name: _callgrind(harness, (fn,), args, out / f"perf.{name}.callgrind")
        for name, fn in (
            ("imu", "sf_estimator_imu"),
            ("mag", "sf_estimator_mag"),
            ("baro", "sf_estimator_baro"),
        )
    }
    att = _callgrind(
        harness,
        ("sf_attitude_update_imu_finite", "sf_attitude_update_mag"),
        args,
        out / "perf.attitude.callgrind",
    )
    return {
        "walk": walk,
        "ir_per_imu_call": ir["imu"] / walk["imu"],
        "ir_per_mag_call": ir["mag"] / walk["mag"],
        "ir_per_baro_call": ir["baro"] / walk["baro"],
        "ir_all_per_imu_sample": sum(ir.values()) / walk["imu"],
        "ir_attitude_per_imu_sample": att / walk["imu"],
    }


#: the peer: x-io Fusion's AHRS (PyPI imufusion, its compiled C library) on the harness's samples, one
#: FusionAhrsUpdate (gyro + accelerometer + magnetometer) per IMU sample; callgrind counts inside it only
_PEER = """
import sys
import imufusion
import numpy as np
d = np.loadtxt(sys.argv[1])
ahrs = imufusion.Ahrs()
ahrs.set_sample_period(0.01)
deg = 180.0 / np.pi
for row in d:
    ahrs.update(row[4:7] * deg, row[1:4] / 9.80665, row[7:10])
"""


def measure_attitude_peer(harness: Path, out: Path) -> dict[str, Any]:
    """Instructions per IMU sample of x-io Fusion's ``FusionAhrsUpdate`` on the sensors walk's samples."""
    samples = out / "perf.samples.txt"
    proc = subprocess.run(
        [str(harness), "samples", str(SENSOR_SECONDS)], capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        raise StageError(f"perf: {harness} samples failed ({proc.returncode}): {proc.stderr[-400:]}")
    samples.write_text(proc.stdout)
    n = proc.stdout.count("\n")
    # our attitude's yaw on the same walk, for perf_peers' heading agreement with Fusion
    yaw = subprocess.run(
        [str(harness), "yaw", str(SENSOR_SECONDS)], capture_output=True, text=True, check=False
    )
    if yaw.returncode != 0:
        raise StageError(f"perf: {harness} yaw failed ({yaw.returncode}): {yaw.stderr[-400:]}")
    (out / "perf.yaw.txt").write_text(yaw.stdout)
    script = out / "perf.fusion_peer.py"
    script.write_text(_PEER)
    ir = callgrind.instructions(
        [sys.executable, str(script), str(samples)],
        ["FusionAhrsUpdate"],
        out / "perf.fusion.callgrind",
        "perf",
    )
    if ir == 0:
        raise StageError(
            "perf: callgrind counted no instruction inside FusionAhrsUpdate (imufusion not run?)"
        )
    import imufusion  # noqa: PLC0415 - only to name the peer's version

    version = getattr(imufusion, "__version__", None)
    return {
        "peer": f"x-io Fusion FusionAhrsUpdate (imufusion {version or '1.3.3'} wheel), gyro + accel + mag per sample",
        "samples": n,
        "ir_per_sample": ir / n,
    }


def measure_wifi(harness: Path, out: Path) -> list[dict[str, Any]]:
    """Per map size: the fix as stridefixd runs it (with the pre-selection's workspace) and the full visit
    of every used AP's entries (``full``) on the same scans, instructions and mean error of each."""
    rows = []
    for n in WIFI_SIZES:
        args = ("wifi", str(n), str(WIFI_SCANS))
        built = _harness_json(harness, *args)
        ir = _callgrind(harness, ("sf_fingerprint_match",), args, out / f"perf.wifi{n}.callgrind")
        full = _harness_json(harness, *args, "full")
        ir_full = _callgrind(
            harness, ("sf_fingerprint_match",), (*args, "full"), out / f"perf.wifi{n}.full.callgrind"
        )
        rows.append(
            built
            | {
                "ir_per_fix": ir / built["scans"],
                "ir_per_fix_full_visit": ir_full / full["scans"],
                "mean_error_m_full_visit": full["mean_error_m"],
            }
        )
        console.say(
            f"bench perf: Wi-Fi fix at {built['n_rp']} RPs: {ir / built['scans']:,.0f} instructions "
            f"(full visit {ir_full / full['scans']:,.0f})"
        )
    return rows


def measure_wifi_heard(harness: Path, out: Path) -> list[dict[str, Any]]:
    """Per scan sensitivity (:data:`WIFI_HEARD_DBM`) on the ~2 000-RP map: instructions per fix against
    the APs a scan hears (``sf_core_cost wifiheard``, stridefixd's workspace and defaults)."""
    rows = []
    for heard_dbm in WIFI_HEARD_DBM:
        args = ("wifiheard", "2000", str(WIFI_SCANS), f"{heard_dbm:g}")
        built = _harness_json(harness, *args)
        ir = _callgrind(
            harness, ("sf_fingerprint_match",), args, out / f"perf.wifiheard{-heard_dbm:g}.callgrind"
        )
        rows.append(built | {"ir_per_fix": ir / built["scans"]})
    return rows


def measure_schemes(stridefixd: Path, out: Path) -> dict[str, Any]:
    """The ekf's and the particle scheme's instructions per PDR step and per Wi-Fi fix: particle-cost's
    harness (5 000 walls, 1 000 particles, a fix every 4th step) walks each scheme, callgrind counts
    inside sf_fusion_step_on_floor and sf_fusion_fix_on_floor."""
    harness = particle_cost.harness_path(stridefixd)
    steps, fixes = particle_cost.STEPS, particle_cost.FIXES
    rows: dict[str, Any] = {}
    for scheme in ("ekf", "particle"):
        args = (str(harness), str(steps), scheme)
        step_ir = callgrind.instructions(
            args, ["sf_fusion_step_on_floor"], out / f"perf.{scheme}.step.cg", "perf"
        )
        fix_ir = callgrind.instructions(
            args, ["sf_fusion_fix_on_floor"], out / f"perf.{scheme}.fix.cg", "perf"
        )
        rows[scheme] = {
            "steps": steps,
            "fixes": fixes,
            "ir_per_step": step_ir / steps,
            "ir_per_fix": fix_ir / fixes,
        }
    return rows


def check_no_heap(stridefixd: Path) -> dict[str, Any]:
    lib = stridefixd.resolve().parent / "libsf_core.a"
    script = REPO / "firmware" / "cmake" / "check_core_symbols.cmake"
    nm = shutil.which("nm") or "nm"
    proc = subprocess.run(
        ["cmake", f"-DNM={nm}", f"-DLIB={lib}", "-P", str(script)],
        capture_output=True,
        text=True,
        check=False,
    )
    return {
        "met": proc.returncode == 0,
        "message": (proc.stdout + proc.stderr).strip()[-400:],
        "library": str(lib),
    }


def measure_replay(firmware: Firmware, out: Path) -> dict[str, Any]:
    """The simulated walk replayed by stridefixd from its candump file; CPU and wall time, peak RSS."""
    work = out / "perf_replay"
    work.mkdir(parents=True, exist_ok=True)
    summary = simulate(None, None, work, "perf: sim", duration_s=float(REPLAY_SECONDS))
    log = work / "stridefixd.lcmlog"
    cmd = firmware.command(input=work / "board.candump", log=log)
    t0 = time.perf_counter()
    child = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    # peak RSS: the daemon's own VmHWM, polled (wait4's ru_maxrss would count the forked Python image
    # the child was before its exec); CPU time: wait4's rusage of the daemon (all its threads)
    hwm, status, usage = 0, 0, None
    while usage is None:
        pid, status, ru = os.wait4(child.pid, os.WNOHANG)
        if pid == child.pid:
            usage = ru
        else:
            hwm = max(hwm, vm_hwm_kb(child.pid) or 0)
            time.sleep(0.005)
    wall_s = time.perf_counter() - t0
    child.returncode = os.waitstatus_to_exitcode(status)
    cpu_s = usage.ru_utime + usage.ru_stime
    assert child.stderr is not None
    err = child.stderr.read()
    child.stderr.close()
    if child.returncode != 0:
        raise StageError(f"perf: {' '.join(cmd)} failed ({child.returncode}): {err.decode()[-400:]}")
    walked_s = float(summary.get("duration_s") or REPLAY_SECONDS)
    analyze = [
        stridefix_exe(),
        "analyze",
        str(log),
        str(work / "truth.lcmlog"),
        "--out",
        str(work / "analyze"),
    ]
    t1 = time.perf_counter()
    done = subprocess.run(analyze, capture_output=True, text=True, check=False)
    analyze_s = time.perf_counter() - t1
    if done.returncode != 0:
        raise StageError(f"perf: {' '.join(analyze)} failed ({done.returncode}): {done.stderr[-400:]}")
    return {
        "walk_s": walked_s,
        "wall_s": wall_s,
        "x_realtime": walked_s / wall_s,
        "cpu_s": cpu_s,
        "x_realtime_cpu": walked_s / cpu_s if cpu_s > 0 else math.inf,
        "speed_method": (
            "x_realtime: simulated seconds / wall seconds; x_realtime_cpu (the budget's figure, 'on one "
            "core'): simulated seconds / the daemon's user + system CPU seconds (wait4 rusage, every thread), "
            "which other processes on a loaded machine do not inflate"
        ),
        "peak_rss_kB": hwm,
        "peak_rss_method": "VmHWM of /proc/PID/status, polled every 5 ms",
        "log_bytes": log.stat().st_size,
        "command": " ".join(cmd),
        "analyze_s": analyze_s,
        "analyze_command": " ".join(analyze),
    }


def judge(values: dict[str, Any]) -> list[dict[str, Any]]:
    """Each budget of :data:`BUDGETS` with its measured value (``values[key]``) and verdict."""
    budgets = []
    for key, figure, op, bound in BUDGETS:
        v = values[key]
        met = {"<=": v <= bound, ">=": v >= bound, "==": v == bound}[op]
        budgets.append(
            {"key": key, "figure": figure, "value": v, "budget": f"{op} {bound}", "met": bool(met)}
        )
    return budgets


def run_perf(firmware: Firmware, out: Path, floor: Path | None = None) -> dict[str, Any]:
    """Every measurement (module docstring); writes ``OUT/perf.json``. ``floor``: the msindoor floor
    folder of the scikit-learn peer on a real map (:mod:`.perf_knn_real`; None or missing: not measured)."""
    harness = harness_path(firmware.path)
    if not harness.is_file():
        raise StageError(f"perf: {harness} not found (build it: make build)")
    out.mkdir(parents=True, exist_ok=True)
    console.say("bench perf: sensor calls under callgrind")
    sensors = measure_sensors(harness, out)
    console.say("bench perf: x-io Fusion on the same samples under callgrind")
    peer = measure_attitude_peer(harness, out)
    console.say("bench perf: Python peers (ahrs Madgwick, scikit-learn KNN) by wall clock")
    python_peers = {
        "attitude": perf_peers.measure_madgwick_peer(out / "perf.samples.txt", ours_yaw=out / "perf.yaw.txt"),
        "wifi": perf_peers.measure_knn_peer(harness, out),
    }
    not_measured = []
    if floor is not None and floor.is_dir():
        console.say(f"bench perf: scikit-learn KNN on the radio map of {floor}")
        python_peers["wifi_real"] = perf_knn_real.measure_knn_peer_real(
            perf_knn_real.site_match_path(firmware.path), floor, out
        )
    else:
        not_measured.append(f"scikit-learn's KNN on a real msindoor floor ({floor} not found)")
    wifi = measure_wifi(harness, out)
    wifi_heard = measure_wifi_heard(harness, out)
    console.say("bench perf: the ekf and particle schemes under callgrind")
    schemes = measure_schemes(firmware.path, out)
    sizes = _harness_json(harness, "sizes")
    heap = check_no_heap(firmware.path)
    console.say(f"bench perf: replaying a {REPLAY_SECONDS} s simulated walk")
    replay = measure_replay(firmware, out)
    by_n = {w["n_rp"]: w for w in wifi}
    mid = min(by_n, key=lambda n: abs(n - 2000))
    big = max(by_n)
    values = {
        "imu_all_ir": sensors["ir_all_per_imu_sample"],
        "attitude_vs_fusion": sensors["ir_attitude_per_imu_sample"] / peer["ir_per_sample"],
        "wifi_2000_ir": by_n[mid]["ir_per_fix"],
        "wifi_scaling": by_n[big]["ir_per_fix"] / by_n[mid]["ir_per_fix"],
        "estimator_B": sizes["sf_estimator_t"],
        "core_no_heap": heap["met"],
        "replay_x_realtime": replay["x_realtime_cpu"],
        "peak_rss_kB": replay["peak_rss_kB"],
        "analyze_s": replay["analyze_s"],
    }
    budgets = judge(values)
    doc = {
        "harness": str(harness),
        "sensors": sensors,
        "attitude_peer": peer,
        "python_peers": python_peers,
        "wifi": wifi,
        "wifi_heard": wifi_heard,
        "schemes": schemes,
        "sizes": sizes,
        "core_no_heap": heap,
        "replay": replay,
        "budgets": budgets,
        "not_measured": [
            *not_measured,
            "realbench <= 60 s per msindoor floor: a row of bench real-targets (the fusion results' run_s.total)",
        ],
    }
    (out / "perf.json").write_text(json.dumps(doc, indent=1))
    return doc


def format_table(doc: dict[str, Any]) -> str:
    s = doc["sensors"]
    lines = [
        f"perf: core calls under callgrind ({s['walk']['seconds']:.0f} s walk: {s['walk']['imu']} IMU, "
        f"{s['walk']['mag']} MAG, {s['walk']['baro']} BARO samples, {s['walk']['steps']} steps)",
        f"  per IMU call {s['ir_per_imu_call']:,.0f}, per MAG call {s['ir_per_mag_call']:,.0f}, per BARO call "
        f"{s['ir_per_baro_call']:,.0f}; attitude {s['ir_attitude_per_imu_sample']:,.0f} per IMU sample, "
        f"{doc['attitude_peer']['peer']}: {doc['attitude_peer']['ir_per_sample']:,.0f}",
        f"  {'Wi-Fi map':<22}{'RPs':>7}{'APs':>6}{'entries':>10}{'heard':>7}{'instr/fix':>11}{'err m':>7}"
        f"{'full visit':>12}{'err m':>7}",
    ]
    for w in doc["wifi"]:
        lines.append(
            f"  {'synthetic, 2 m grid':<22}{w['n_rp']:>7}{w['n_ap']:>6}{w['n_entries']:>10}{w['mean_heard']:>7.1f}"
            f"{w['ir_per_fix']:>11,.0f}{w['mean_error_m']:>7.2f}{w['ir_per_fix_full_visit']:>12,.0f}"
            f"{w['mean_error_m_full_visit']:>7.2f}"
        )
    lines += [
        f"  {'synthetic, APs heard':<22}{w['n_rp']:>7}{w['n_ap']:>6}{w['n_entries']:>10}{w['mean_heard']:>7.1f}"
        f"{w['ir_per_fix']:>11,.0f}{w['mean_error_m']:>7.2f}  (scans hear APs above {w['heard_dbm']:g} dBm; "
        f"{'pre-selection' if w['preselected'] else 'full visit: the pre-selection would not halve the visit'})"
        for w in doc.get("wifi_heard", [])
    ]
    if "python_peers" in doc:
        peers = doc["python_peers"]
        lines += perf_peers.format_rows(peers["attitude"], peers["wifi"])
        if "wifi_real" in peers:
            lines.append(
                perf_peers.format_knn_row(peers["wifi_real"], f"msindoor {peers['wifi_real']['floor']}")
            )
    for name, sc in doc["schemes"].items():
        lines.append(
            f"  {name} scheme (5,000 walls, fix every 4th step): {sc['ir_per_step']:,.0f} instructions per step, "
            f"{sc['ir_per_fix']:,.0f} per Wi-Fi fix"
        )
    r = doc["replay"]
    lines.append(
        f"  replay: {r['walk_s']:.0f} s walk in {r['wall_s']:.2f} s wall ({r['x_realtime']:,.0f}x real time), "
        f"{r['cpu_s']:.2f} s CPU ({r['x_realtime_cpu']:,.0f}x), "
        f"peak RSS {r['peak_rss_kB']:,} kB, log {r['log_bytes'] / 1e6:.1f} MB; analyze {r['analyze_s']:.1f} s"
    )
    lines.append(f"  {'budget':<55}{'value':>14}  {'target':<12}")
    for b in doc["budgets"]:
        v = b["value"]
        shown = (
            str(v)
            if isinstance(v, bool)
            else f"{v:,.2f}"
            if isinstance(v, float) and v < 100
            else f"{v:,.0f}"
        )
        lines.append(f"  {b['figure']:<55}{shown:>14}  {b['budget']:<12}{'MET' if b['met'] else 'MISSED'}")
    lines += [f"  not measured: {m}" for m in doc["not_measured"]]
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    return [
        f"perf: {b['figure']} = {b['value']} (budget {b['budget']})" for b in doc["budgets"] if not b["met"]
    ]


def _add_arguments(p: argparse.ArgumentParser) -> None:
    add_floor_argument(p, " of the scikit-learn peer on a real map")


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # fixed walks of the harness and one simulated walk; args.floor: the real-map peer
    doc = run_perf(firmware, out, Path(args.floor))
    print(format_table(doc))
    print(f"wrote {out / 'perf.json'}")
    return missed_targets(doc)


BENCH = Bench(
    "perf",
    "the core's instructions per IMU, MAG, BARO sample and per Wi-Fi fix against map size under "
    "callgrind, state sizes, no heap, replay speed and peak RSS against the unit's budgets",
    _run,
    add_arguments=_add_arguments,
    in_make_bench=True,
)
