"""``stridefix-lab bench soak`` (``make soak``): an 8-hour SIL walk with faults through ``stridefixd``:
peak RSS at 1 h and at 8 h of input, and every event accounted for.

The walk (:func:`soak_scenario`) is laps of the floor-0 loop for ``hours`` with faults sprinkled in:
board resets, payload corruption, duplicates, loss bursts, a silence window and rare implausible
samples. ``stridefix sim --stdout`` streams the candump lines; this module forwards them into
``stridefixd --input -`` through a pipe, reading the daemon's ``VmHWM`` (peak RSS) from
``/proc/PID/status`` once the input has passed ``checkpoint_h`` of board traffic and again when all of
it has been written (not ``ru_maxrss`` of ``os.wait4``: a child forked from Python counts the
interpreter's pages from before its exec). Target: RSS at the end within 1 MB
of RSS at the checkpoint (:data:`RSS_GROWTH_MAX_KB`).

Accounting (:func:`account`), from the simulator's summary, the daemon's exit summary and the log:

* frames: every line the simulator wrote was read (sim ``frames_total`` = daemon frames read);
* per stream (IMU, MAG, BARO, WIFI, GNSS, STEP): the daemon's accepted count and the events of that
  channel in the log file; every accepted event is in the log or counted as dropped (sum of the
  shortfalls = the summary's dropped events), and the file holds exactly the events the summary says;
* beside them, what the simulator delivered (unique samples after bus loss; for STEP the truth's
  steps) and its fault record, so
  the frames the daemon did not turn into events can be read against the damage.

Writes ``OUT/soak.json`` and prints a table; a missed target (RSS growth, an unaccounted event) is a
``TARGET MISSED`` line (exit 1).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import time
from collections.abc import Sequence
from pathlib import Path
from typing import IO, Any

from stridefix_analyzer import console
from stridefix_analyzer.firmware import Firmware
from stridefix_analyzer.io.logread import read_logs

from stridefix_lab.bench.registry import Bench, BenchUsageError
from stridefix_lab.bench.reliability import scenario_toml
from stridefix_lab.bench.sil_pdr import BenchError
from stridefix_lab.stages import stridefix_exe

RSS_GROWTH_MAX_KB = 1024
SEED = 1
LAP_M = 126.0  # one lap of the default world's floor-0 loop (enough laps to walk all the time)
CHUNK_BYTES = 1 << 20
# daemon exit summary: "N frames (M ok): ..." and "a IMU, b MAG, c BARO, d WIFI, e GNSS; s steps; log
# PATH: E events, X MB, D dropped; W s"
_FRAMES_RE = re.compile(r"stridefixd: (\d+) frames \((\d+) ok\)")
_EVENTS_RE = re.compile(
    r"stridefixd: (\d+) IMU, (\d+) MAG, (\d+) BARO, (\d+) WIFI, (\d+) GNSS; (-?\d+) steps; log .*: "
    r"(\d+) events, ([\d.]+) MB, (\d+) dropped"
)
STREAMS = ("IMU", "MAG", "BARO", "WIFI", "GNSS", "STEP")


def soak_scenario(hours: float) -> dict[str, dict[str, Any]]:
    """Overrides of the default scenario: laps of the loop for ``hours`` with faults sprinkled in."""
    s = hours * 3600.0
    return {
        "walk": {"route": "loop", "laps": float(math.ceil(s * 1.4 / LAP_M) + 1)},
        "faults": {
            "reset_at_s": [round(s * f, 1) for f in (0.25, 0.55, 0.85)],
            "corrupt_rate": 1e-4,
            "duplicate_rate": 1e-3,
            "burst_rate": 1e-5,
            "burst_frames": 20,
            "silence_at_s": [round(s * 0.4, 1)],
            "silence_s": 5.0,
            "implausible_rate": 1e-5,
        },
    }


def vm_hwm_kb(pid: int) -> int | None:
    """Peak resident set size [kB] of a running process (``VmHWM``), None when unreadable."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def _last_host_s(chunk: bytes) -> float | None:
    """Host time [s] of the last whole candump line in ``chunk``."""
    end = chunk.rfind(b"\n")
    start = chunk.rfind(b"\n(", 0, end)
    line = chunk[start + 1 : end] if start >= 0 else chunk[:end]
    if not line.startswith(b"("):
        return None
    try:
        return float(line[1 : line.index(b")")])
    except ValueError:
        return None


def feed(src: IO[bytes], proc: subprocess.Popen[bytes], checkpoint_s: float) -> dict[str, Any]:
    """Forwards ``src`` into the daemon's stdin; VmHWM once ``checkpoint_s`` of input has gone in and
    when all of it has; then closes stdin. Returns the RSS figures and the bytes forwarded."""
    assert proc.stdin is not None
    first_s: float | None = None
    rss_checkpoint = None
    n_bytes = 0
    while chunk := src.read(CHUNK_BYTES):
        proc.stdin.write(chunk)
        n_bytes += len(chunk)
        t = _last_host_s(chunk)
        if first_s is None:
            first_s = float(chunk[1 : chunk.index(b")")])
        if rss_checkpoint is None and t is not None and t - first_s >= checkpoint_s:
            proc.stdin.flush()
            rss_checkpoint = vm_hwm_kb(proc.pid)
    proc.stdin.flush()
    rss_end = vm_hwm_kb(proc.pid)
    proc.stdin.close()
    return {"input_bytes": n_bytes, "vm_hwm_checkpoint_kb": rss_checkpoint, "vm_hwm_end_kb": rss_end}


def parse_daemon_summary(stderr: str) -> dict[str, int]:
    """The counts of stridefixd's exit summary (raises BenchError when it is missing)."""
    f, e = _FRAMES_RE.search(stderr), _EVENTS_RE.search(stderr)
    if not (f and e):
        raise BenchError(f"stridefixd printed no exit summary:\n{stderr[-1000:]}")
    imu, mag, baro, wifi, gnss, steps, events, _, dropped = e.groups()
    return {
        "frames": int(f[1]),
        "frames_ok": int(f[2]),
        "IMU": int(imu),
        "MAG": int(mag),
        "BARO": int(baro),
        "WIFI": int(wifi),
        "GNSS": int(gnss),
        "STEP": int(steps),
        "events": int(events),
        "dropped": int(dropped),
    }


def account(sim: dict[str, Any], daemon: dict[str, int], messages: dict[str, int]) -> dict[str, Any]:
    """The accounting of module doc: per stream and in total; ``accounted`` when every check holds."""
    delivered = {
        "IMU": sim["imu_samples"],
        "MAG": sim["mag_samples"],
        "BARO": sim["baro_samples"],
        "WIFI": sim["wifi_scans"],
        "GNSS": 0,
        "STEP": sim["steps"],  # the truth's steps (no frame carries a step)
    }
    streams = {
        s: {
            "sim_delivered": delivered[s],
            "daemon_accepted": daemon[s],
            "logged": messages.get(s, 0),
            "shortfall": daemon[s] - messages.get(s, 0),
        }
        for s in STREAMS
    }
    shortfall = sum(v["shortfall"] for v in streams.values())
    file_events = sum(messages.values())
    checks = {
        "every_line_read": sim["frames_total"] == daemon["frames"],
        "log_holds_the_summary_events": file_events == daemon["events"],
        "accepted_logged_or_counted_dropped": shortfall == daemon["dropped"]
        and all(v["shortfall"] >= 0 for v in streams.values()),
    }
    return {
        "frames_sent_by_sim": sim["frames_total"],
        "frames_read_by_daemon": daemon["frames"],
        "frames_ok": daemon["frames_ok"],
        "streams": streams,
        "log_file_events": file_events,
        "summary_events": daemon["events"],
        "summary_dropped": daemon["dropped"],
        "checks": checks,
        "accounted": all(checks.values()),
    }


def run_soak(
    firmware: Firmware, out: Path, hours: float = 8.0, checkpoint_h: float = 1.0, sets: Sequence[str] = ()
) -> dict[str, Any]:
    """The soak (module doc); writes ``OUT/soak.json``."""
    firmware.check_executable()
    work = out / "soak"
    work.mkdir(parents=True, exist_ok=True)
    overrides = soak_scenario(hours)
    (work / "scenario.toml").write_text(scenario_toml(overrides, hours * 3600.0))
    console.say(f"bench soak: {hours:g} h walk: simulating, then streaming into stridefixd")
    log = work / "stridefixd.lcmlog"
    t0 = time.perf_counter()
    sim_cmd = [stridefix_exe(), "sim", "--scenario", str(work / "scenario.toml"), "--seed", str(SEED)]
    sim_cmd += ["--out", str(work), "--stdout"]
    cmd = firmware.command(input="-", log=log, sets=sets)
    with open(work / "sim.stderr", "w+b") as sim_err, open(work / "stridefixd.stderr", "w+b") as fw_err:
        sim = subprocess.Popen(sim_cmd, stdout=subprocess.PIPE, stderr=sim_err)
        daemon = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=fw_err)
        assert sim.stdout is not None
        try:
            rss = feed(sim.stdout, daemon, checkpoint_h * 3600.0)
        except BrokenPipeError:
            rss = {}
        sim_rc = sim.wait()
        daemon.wait()
        fw_err.seek(0)
        fw_text = fw_err.read().decode(errors="replace")
        sim_err.seek(0)
        sim_text = sim_err.read().decode(errors="replace")
    run_s = time.perf_counter() - t0
    if sim_rc != 0:
        raise BenchError(f"soak: stridefix sim exit {sim_rc}: {' '.join(sim_cmd)}\n{sim_text[-1000:]}")
    if daemon.returncode != 0 or not rss:
        raise BenchError(f"soak: stridefixd exit {daemon.returncode}: {' '.join(cmd)}\n{fw_text[-1000:]}")
    sim_summary = json.loads((work / "sim_summary.json").read_text())
    t1 = time.perf_counter()
    data = read_logs([str(log)], decode=("HEALTH",))
    read_s = time.perf_counter() - t1
    acc = account(sim_summary, parse_daemon_summary(fw_text), data.messages)
    hwm_1, hwm_end = rss["vm_hwm_checkpoint_kb"], rss["vm_hwm_end_kb"]
    growth = None if hwm_1 is None or hwm_end is None else hwm_end - hwm_1
    doc = {
        "bench": "soak",
        "hours": hours,
        "checkpoint_h": checkpoint_h,
        "seed": SEED,
        "scenario": overrides,
        "sim_faults": sim_summary.get("faults", {}),
        "rss": {
            **rss,
            "growth_kb": growth,
            "growth_max_kb": RSS_GROWTH_MAX_KB,
        },
        "accounting": acc,
        "last_health": data.health,
        "log_bytes": log.stat().st_size,
        "sim_plus_replay_s": run_s,
        "log_read_s": read_s,
        "targets_met": {
            "rss_flat": growth is not None and growth <= RSS_GROWTH_MAX_KB,
            "accounted": acc["accounted"],
        },
    }
    (out / "soak.json").write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def format_table(doc: dict[str, Any]) -> str:
    r, a = doc["rss"], doc["accounting"]
    lines = [
        f"soak: {doc['hours']:g} h walk, {a['frames_sent_by_sim']} frames sent, {a['frames_read_by_daemon']} read "
        f"({a['frames_ok']} ok); sim + replay {doc['sim_plus_replay_s']:.0f} s, log {doc['log_bytes'] / 1e6:.0f} MB",
        f"peak RSS (VmHWM): {r['vm_hwm_checkpoint_kb']} kB at {doc['checkpoint_h']:g} h of input, "
        f"{r['vm_hwm_end_kb']} kB at {doc['hours']:g} h (growth {r['growth_kb']} kB, target <= "
        f"{r['growth_max_kb']} kB)",
        f"{'stream':<7}{'sim':>10}{'accepted':>10}{'logged':>10}{'short':>7}",
    ]
    for name, s in a["streams"].items():
        sent = "-" if s["sim_delivered"] is None else str(s["sim_delivered"])
        lines.append(f"{name:<7}{sent:>10}{s['daemon_accepted']:>10}{s['logged']:>10}{s['shortfall']:>7}")
    lines.append(
        f"log file {a['log_file_events']} events, summary {a['summary_events']} events + "
        f"{a['summary_dropped']} dropped; checks: "
        + ", ".join(f"{k} {'ok' if v else 'FAILED'}" for k, v in a["checks"].items())
    )
    f = doc["sim_faults"]
    if f:
        lines.append(
            "faults (sim): "
            + ", ".join(
                f"{k} {f[k]}"
                for k in (
                    "resets",
                    "lost_burst",
                    "lost_silence",
                    "corrupted",
                    "duplicated",
                    "implausible",
                    "unsent_reset",
                )
            )
        )
    return "\n".join(lines)


def missed_targets(doc: dict[str, Any]) -> list[str]:
    lines = []
    r, a = doc["rss"], doc["accounting"]
    if not doc["targets_met"]["rss_flat"]:
        lines.append(
            f"soak: peak RSS grew {r['growth_kb']} kB from {doc['checkpoint_h']:g} h to {doc['hours']:g} h "
            f"(target <= {r['growth_max_kb']} kB)"
        )
    if not doc["targets_met"]["accounted"]:
        failed = [k for k, v in a["checks"].items() if not v]
        lines.append(f"soak: events not accounted for ({', '.join(failed)})")
    return lines


def _add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--hours", type=float, default=8.0, metavar="H", help="length of the walk [h] (default: 8)"
    )
    p.add_argument(
        "--checkpoint-h",
        type=float,
        default=1.0,
        metavar="H",
        help="read the first peak RSS after this much input [h] (default: 1)",
    )


def _run(args: argparse.Namespace, firmware: Firmware, seeds: list[int], out: Path) -> list[str]:
    del seeds  # one walk (SEED)
    if not 0 < args.checkpoint_h < args.hours:
        raise BenchUsageError(f"--checkpoint-h {args.checkpoint_h}: must be in 0..--hours ({args.hours})")
    doc = run_soak(firmware, out, hours=args.hours, checkpoint_h=args.checkpoint_h, sets=args.sets)
    print(format_table(doc))
    print(f"wrote {out / 'soak.json'}")
    return missed_targets(doc)


BENCH = Bench(
    "soak",
    "an 8-hour walk with faults: RSS and event accounting (make soak)",
    _run,
    add_arguments=_add_arguments,
)
