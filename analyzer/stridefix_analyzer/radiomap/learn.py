"""What a site learns from walks with known points by replaying them through ``stridefixd``: the
part of ``stridefix site`` that a radio map alone cannot give.

Every walk (an argument of ``stridefix site``: a raw-sensor log with TRUTH, e.g. an imported msindoor
trace whose waypoints are the known points) is replayed without a site once per heading candidate
(:data:`~stridefix_analyzer.firmware.HEADING_VARIANTS`). From the STEP messages against the known
points, pooled over every walk:

* the heading candidate whose step headings agree best with the truth directions, and the map
  rotation (STEP heading − truth direction over straight segments; :mod:`.heading`): the site's
  ``map_rotation_deg``;
* the Weinberg constant K = Σ true distance / Σ range^¼ over the segments between known points
  (:mod:`.strides`): ``stride.weinberg_k``.

These are the same sums the lab's realbench learns per fold from its training walks, here over all of
the given walks (nothing is held out: the walk a user looks at later is not among them). A survey
recorded standing still has no straight segments between its points: the rotation and the heading
candidate are then not learned (the caller keeps its own), K neither when no segment is long enough.
Cost: 2 replays per walk (each ~0.1 s per minute walked), O(steps + known points) per sum.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stridefix_analyzer.firmware import HEADING_VARIANTS, Firmware
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, read_logs
from stridefix_analyzer.parallel import TaskRunner
from stridefix_analyzer.radiomap.heading import choose_heading_variant, learn_rotation_deg, rotation_stats
from stridefix_analyzer.radiomap.strides import build_segments, stride_k


@dataclasses.dataclass(frozen=True)
class WalkJob:
    """One walk to replay: its files (the first is replayed; TRUTH and IMU are read from all)."""

    files: tuple[str, ...]
    firmware: Firmware
    sets: tuple[str, ...]
    work_dir: str


def replay_walk(job: WalkJob) -> dict[str, Any]:
    """The walk's STEP streams (one replay per heading candidate) against its known points: the keys
    :func:`~.strides.build_segments` reads and ``rotation`` per candidate; ``error`` says why not."""
    name = Path(job.files[0]).stem
    walk: dict[str, Any] = {"walk": name, "error": None, "import": None}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)
            raw = read_logs(list(job.files), decode=("TRUTH", "IMU"))
    except LogReadError as exc:
        walk["error"] = str(exc)
        return walk
    truth, imu = raw.table("TRUTH"), raw.table("IMU")
    if truth is None or len(truth) < 2 or imu is None or not len(imu):
        walk["error"] = f"{job.files[0]}: needs IMU and two or more TRUTH points to learn from"
        return walk
    wp_t, wp_xy = truth["t_us"], np.column_stack([truth["x_m"], truth["y_m"]])
    walk["rotation"] = {}
    for variant, extra in HEADING_VARIANTS.items():
        log = Path(job.work_dir) / f"{name}.{variant}.lcmlog"
        proc = job.firmware.run(
            input=f"lcmlog:{job.files[0]}", log=log, sets=[*job.sets, *extra], check=False
        )
        if proc.returncode != 0:
            walk["error"] = f"{job.files[0]}: stridefixd exit {proc.returncode}: {proc.stderr.strip()[-300:]}"
            return walk
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LogTruncatedWarning)
            steps = read_logs([log], decode=("STEP",)).table("STEP")
        t = steps["t_us"] if steps is not None else np.zeros(0, np.int64)
        h = steps["heading_rad"] if steps is not None else np.zeros(0)
        walk["rotation"][variant] = rotation_stats(t, h, wp_t, wp_xy)
        if variant == next(iter(HEADING_VARIANTS)):  # the firmware default's steps give K
            z = np.zeros(0)
            walk["step_t_us"] = t
            walk["step_range_mps2"] = steps["accel_range_mps2"] if steps is not None else z
            walk["step_length_m"] = steps["length_m"] if steps is not None else z
    walk["import"] = {
        "imu_t_first_us": int(imu["t_us"][0]),
        "imu_t_last_us": int(imu["t_us"][-1]),
        "waypoints": len(truth),
    }
    walk["waypoint_t_us"], walk["waypoint_xy_m"] = wp_t, wp_xy
    return walk


def learn_walks(
    files: Sequence[Sequence[str]],
    firmware: Firmware,
    sets: Sequence[str],
    work_dir: str | Path,
    runner: TaskRunner,
) -> dict[str, Any]:
    """Replay every walk (``files``: one tuple per walk) with ``sets`` and learn from all of them.

    Returns
    -------
    dict
        ``sets`` (the learned ``stridefixd --set`` lines: K, the heading candidate's), ``rotation_deg``
        (None when not learned), and the report: ``walks``, ``learned_from``, ``failed`` (walk: why),
        ``heading_variant``, ``heading_agreement`` (resultant length per candidate), ``weinberg_k``,
        ``segments`` (those K is learned from).
    """
    Path(work_dir).mkdir(parents=True, exist_ok=True)
    jobs = [WalkJob(tuple(f), firmware, tuple(sets), str(work_dir)) for f in files]
    walks: list[dict[str, Any]] = runner.map(replay_walk, jobs)
    ok = [w for w in walks if not w["error"]]
    report: dict[str, Any] = {
        "walks": len(walks),
        "learned_from": len(ok),
        "failed": {w["walk"]: w["error"] for w in walks if w["error"]},
    }
    learned: list[str] = []
    rotation = None
    if ok:
        variant, agreement = choose_heading_variant([w["rotation"] for w in ok])
        rot = learn_rotation_deg([w["rotation"][variant] for w in ok])
        report["heading_agreement"] = agreement
        if math.isfinite(rot):
            rotation = rot
            report["heading_variant"] = variant
            learned += HEADING_VARIANTS[variant]
        seg = build_segments(ok)
        used = seg["excluded"] == ""
        k = stride_k(seg, used) if used.any() else math.nan
        report["segments"] = int(used.sum())
        if math.isfinite(k) and k > 0:
            report["weinberg_k"] = k
            learned.append(f"stride.weinberg_k={k:.6f}")
    report["rotation_deg"] = rotation
    return {"sets": learned, "rotation_deg": rotation, "report": report}


def config_text(sets: Sequence[str], header: str) -> str:
    """``stridefixd --config`` INI of ``KEY=VALUE`` lines (``section.key``), later ones winning."""
    sections: dict[str, dict[str, str]] = {}
    for kv in sets:
        key, _, value = kv.partition("=")
        section, _, name = key.strip().partition(".")
        sections.setdefault(section, {})[name] = value.strip()
    lines = [f"# {line}" for line in header.splitlines()]
    for section, keys in sections.items():
        lines += ["", f"[{section}]", *(f"{k} = {v}" for k, v in keys.items())]
    return "\n".join(lines) + "\n"


def make_site_from_walks(
    logs: Sequence[str],
    out: str | Path,
    config_out: str | Path,
    opts: Any,
    firmware: Firmware,
    sets: Sequence[str] = (),
    *,
    learn: bool = True,
    scheduler: str | None = None,
    workers: int = 2,
) -> dict[str, Any]:
    """``stridefix site``: learn from the walks (:func:`learn_walks`, unless ``learn`` is false), build
    the site with the learned map rotation (:func:`~.make.make_site`, ``opts`` a
    :class:`~.make.SiteOptions`) and write ``config_out``: ``sets`` (the recordings' device settings)
    and the learned settings, for ``stridefixd --config``. Returns the summary (``learned`` added).
    Raises :data:`~.make.INPUT_ERRORS` or :class:`~stridefix_analyzer.firmware.FirmwareError`."""
    import os
    import tempfile

    from stridefix_analyzer.parallel import WorkerFiles, task_runner
    from stridefix_analyzer.radiomap.make import make_site
    from stridefix_analyzer.radiomap.recordings import arg_files

    firmware.check_sets(sets)
    learned: dict[str, Any] = {"sets": [], "rotation_deg": None, "report": {"walks": 0}}
    if learn:
        files = [tuple(os.path.abspath(f) for f in arg_files(a)) for a in logs]
        with tempfile.TemporaryDirectory(prefix="stridefix-site-") as work:
            shared = WorkerFiles(read=[f for fs in files for f in fs], write=[work], same=[firmware.path])
            with task_runner(scheduler, workers, shared) as runner:
                learned = learn_walks(files, firmware, sets, work, runner)
    if learned["rotation_deg"] is not None:
        opts = dataclasses.replace(opts, map_rotation_deg=learned["rotation_deg"])
    _, summary = make_site(logs, out, opts, scheduler=scheduler, workers=workers)
    all_sets = [*sets, *learned["sets"]]
    header = (
        f"stridefixd settings for {os.path.basename(os.fspath(out))}, written by stridefix site\n"
        f"from {len(logs)} walk(s): the recordings' device settings (--set), then what the walks taught"
    )
    Path(config_out).parent.mkdir(parents=True, exist_ok=True)
    Path(config_out).write_text(config_text(all_sets, header), encoding="utf-8")
    summary["learned"] = {**learned["report"], "sets": learned["sets"], "config": str(config_out)}
    return summary


def format_learned(report: dict[str, Any]) -> str:
    """The console lines of what :func:`learn_walks` learned."""
    if not report.get("walks"):
        return "learned     nothing (--no-learn)"
    rot = report.get("rotation_deg")
    k = report.get("weinberg_k")
    out = [
        f"learned     from {report['learned_from']} of {report['walks']} walk(s): map rotation "
        + (f"{rot:.1f} deg" if rot is not None else "not learned (no straight segment between known points)")
        + (f", heading {report['heading_variant']}" if report.get("heading_variant") else "")
        + (
            f", Weinberg K {k:.3f} ({report['segments']} segments)"
            if k is not None
            else ", Weinberg K not learned"
        )
    ]
    out += [f"  not learned from {w}: {why}" for w, why in sorted(report.get("failed", {}).items())]
    return "\n".join(out)
