"""Change indication (the PX4 EKF2 habit): fixed inputs -> stridefixd -> per-scheme state at 1 Hz.

Four cases, each a committed CSV beside this file:

- ``sil_tour.csv``   the default SIL tour (``stridefix sim``, default seed) on the office survey's site
- ``aadr2015.csv``   the aadr2015 walk (seed 1) on the foyer survey's site (seed 1000)
- ``msindoor.csv``   the longest msindoor site1/F2 walk on a map built from twelve other walks of the floor
- ``gsd.csv``        one gsd trial on a map built from the other three trials of the building

The harness only drives the public commands (``stridefix sim|import|radiomap build`` and
``stridefixd``, with a real data set's declared ``firmware_sets``) and reads the firmware's LCM log
with the generated bindings, so a refactor of the analyzer cannot change what it measures. Each row is one scheme at one whole second of board time:
the latest POSE at or before it (x, y, floor, heading, σ, step count) and the FIX verdicts of the
second that ended then (accepted, rejected, the last reason code). Values are printed at fixed
precision, so the files are byte-identical when behaviour is.

    python tests/change_indication/replay.py --out DIR [--case NAME ...] [--stridefixd PATH]

writes DIR/<case>.csv; ``make change-indication`` writes them here, and the pytest case
``tests/python/change_indication`` compares a fresh run with the committed files.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
DATA = REPO.parent / "shared" / "data"
MSINDOOR_FLOOR = DATA / "msindoor" / "site1" / "F2" / "path_data_files"
MSINDOOR_HELD = "5dda5a8b9191710006b573da"  # the floor's largest trace: the replayed walk
MSINDOOR_MAP_WALKS = 12  # the first walks by name (the held-out one excepted) build its map
GSD = DATA / "gsd"

HEADER = "t_s,scheme,x_m,y_m,floor,heading_rad,sigma_m,step_count,fixes_accepted,fixes_rejected,last_reason\n"


class ChangeIndicationError(RuntimeError):
    """A stage of the replay failed; the message names the command and its output."""


def _run(cmd: list[str]) -> None:
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if proc.returncode != 0:
        raise ChangeIndicationError(
            f"{' '.join(map(str, cmd))} exited {proc.returncode}:\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
        )


def _stridefix() -> str:
    return str(Path(sys.executable).with_name("stridefix"))


def state_csv(fw_log: Path) -> str:
    """The 1 Hz per-scheme state of a stridefixd log as CSV text."""
    import lcm
    import stridefix_channels
    from stridefix import fix_t, pose_t

    # every pose channel: POSE_<SCHEME> per fusion scheme and POSE (the primary: the controller's,
    # or a copy of one scheme's pose, equal to it, so it changes no row); an older log: POSE alone
    pose_channels = {"POSE", *stridefix_channels.POSE_SCHEME_CHANNELS.values()}
    poses: list[tuple[int, int, object]] = []
    fixes: list[tuple[int, int, bool, int]] = []
    for ev in lcm.EventLog(str(fw_log), "r"):
        if ev.channel in pose_channels:
            p = pose_t.decode(ev.data)
            poses.append((p.t_us, p.scheme, p))
        elif ev.channel == "FIX":
            f = fix_t.decode(ev.data)
            fixes.append((f.t_us, f.scheme, bool(f.accepted), f.reason))
    if not poses:
        raise ChangeIndicationError(f"{fw_log}: no POSE")
    poses.sort(key=lambda r: (r[0], r[1]))
    fixes.sort(key=lambda r: (r[0], r[1]))
    schemes = sorted({s for _, s, _ in poses} | {s for _, s, _, _ in fixes})
    t0_s = math.ceil(poses[0][0] / 1e6)
    t1_s = math.floor(max(poses[-1][0], fixes[-1][0] if fixes else 0) / 1e6)
    out = [HEADER]
    latest: dict[int, object] = {}
    counts = {s: [0, 0, -1] for s in schemes}
    ip = ifx = 0
    for t_s in range(t0_s, t1_s + 1):
        t_us = t_s * 1_000_000
        while ip < len(poses) and poses[ip][0] <= t_us:
            latest[poses[ip][1]] = poses[ip][2]
            ip += 1
        for c in counts.values():
            c[0] = c[1] = 0
        while ifx < len(fixes) and fixes[ifx][0] <= t_us:
            _, s, accepted, reason = fixes[ifx]
            counts[s][0 if accepted else 1] += 1
            counts[s][2] = reason
            ifx += 1
        for s in schemes:
            p = latest.get(s)
            a, r, last = counts[s]
            if p is None:
                out.append(f"{t_s},{s},,,,,,,{a},{r},{last}\n")
                continue
            out.append(
                f"{t_s},{s},{p.x_m:.3f},{p.y_m:.3f},{p.floor},{p.heading_rad:.4f},"
                f"{p.sigma_m:.3f},{p.step_count},{a},{r},{last}\n"
            )
    return "".join(out)


def _sim_case(work: Path, stridefixd: Path, survey: str, walk_args: list[str]) -> Path:
    import json

    sv = work / "survey"
    _run([_stridefix(), "sim", "--scenario", survey, "--seed", "1000", "--out", sv])
    _run([stridefixd, "--input", sv / "board.candump", "--log", sv / "fw.lcmlog", "-q"])
    rot = json.loads((sv / "sim_summary.json").read_text())["map_rotation_deg"]
    site = work / "site.sfsite"
    _run(
        [
            _stridefix(),
            "radiomap",
            "build",
            sv / "fw.lcmlog",
            sv / "truth.lcmlog",
            "--mode",
            "survey",
            "--map-rotation-deg",
            str(rot),
            "--out",
            site,
        ]
    )
    wk = work / "walk"
    _run([_stridefix(), "sim", *walk_args, "--out", wk])
    log = work / "run.lcmlog"
    _run([stridefixd, "--input", wk / "board.candump", "--log", log, "--site", site, "-q"])
    return log


def case_sil_tour(work: Path, stridefixd: Path) -> Path:
    return _sim_case(work, stridefixd, "office_survey", [])


def case_aadr2015(work: Path, stridefixd: Path) -> Path:
    return _sim_case(work, stridefixd, "aadr2015_survey", ["--scenario", "aadr2015", "--seed", "1"])


def _replay_on_map(work: Path, stridefixd: Path, fmt: str, held: Path, others: list[Path]) -> Path:
    """The held-out walk replayed on a map of the others, with the data set's own firmware overrides
    (``Dataset.firmware_sets``: what realbench replays with too)."""
    from stridefix_analyzer import datasets

    site = work / "site.sfsite"
    _run([_stridefix(), "radiomap", "build", *others, "--mode", "walk", "--min-count", "1", "--out", site])
    log = work / "run.lcmlog"
    sets = [a for kv in datasets.get(fmt).firmware_sets for a in ("--set", kv)]
    _run([stridefixd, "--replay", held, "--log", log, "--site", site, "-q", *sets])
    return log


def case_msindoor(work: Path, stridefixd: Path) -> Path:
    held = MSINDOOR_FLOOR / f"{MSINDOOR_HELD}.txt"
    others = [t for t in sorted(MSINDOOR_FLOOR.glob("*.txt")) if t != held][:MSINDOOR_MAP_WALKS]
    if not held.is_file() or len(others) < MSINDOOR_MAP_WALKS:
        raise ChangeIndicationError(
            f"{MSINDOOR_FLOOR}: needs {held.name} and {MSINDOOR_MAP_WALKS} more traces"
        )
    chosen = [held, *others]
    imp = work / "import"
    _run([_stridefix(), "import", "msindoor", *chosen, "--out", imp])
    logs = [imp / f"{t.stem}.lcmlog" for t in chosen]
    return _replay_on_map(work, stridefixd, "msindoor", logs[0], logs[1:])


def _first_posi(path: Path) -> str:
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            if line.startswith("POSI;"):
                p = line.split(";")
                return f"{p[3]},{p[4]}"
    raise ChangeIndicationError(f"{path}: no POSI record")


def case_gsd(work: Path, stridefixd: Path) -> Path:
    trials = sorted(GSD.glob("IPIN*.txt"))
    if len(trials) < 2:
        raise ChangeIndicationError(f"{GSD}: needs at least 2 trials")
    imp = work / "import"
    _run([_stridefix(), "import", "gsd", *trials, "--out", imp, f"--origin={_first_posi(trials[0])}"])
    logs = [imp / f"{t.stem}.lcmlog" for t in trials]
    held = logs[-1]  # the shortest-named last trial; the other three build the map
    return _replay_on_map(work, stridefixd, "gsd", held, logs[:-1])


CASES: dict[str, Callable[[Path, Path], Path]] = {
    "sil_tour": case_sil_tour,
    "aadr2015": case_aadr2015,
    "msindoor": case_msindoor,
    "gsd": case_gsd,
}
REAL_DATA_CASES = {"msindoor": MSINDOOR_FLOOR, "gsd": GSD}


def run_case(name: str, out_dir: Path, stridefixd: Path) -> Path:
    """Replays one case and writes out_dir/<name>.csv; returns its path."""
    with tempfile.TemporaryDirectory(prefix=f"sf-ci-{name}-") as tmp:
        log = CASES[name](Path(tmp), stridefixd)
        text = state_csv(log)
    out = out_dir / f"{name}.csv"
    out.write_text(text, encoding="ascii")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=HERE, help="folder for <case>.csv (default: here)")
    ap.add_argument("--case", action="append", choices=sorted(CASES), help="run only these (repeatable)")
    ap.add_argument(
        "--stridefixd",
        type=Path,
        default=Path(os.environ.get("STRIDEFIXD", REPO / "build" / "firmware" / "stridefixd")),
    )
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.case or list(CASES):
        if name in REAL_DATA_CASES and not REAL_DATA_CASES[name].is_dir():
            print(f"change-indication: {name}: {REAL_DATA_CASES[name]} not found, skipped", file=sys.stderr)
            continue
        path = run_case(name, args.out, args.stridefixd)
        print(f"change-indication: wrote {path} ({path.stat().st_size} bytes)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
