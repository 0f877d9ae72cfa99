"""TUM trajectory exports of a scored analysis, for cross-checks with evo and other tools.

Format (TUM RGB-D): one pose per line, ``timestamp x y z qx qy qz qw``, space-separated; timestamp
[s], position [m], unit quaternion (Hamilton, w last).

Files written into a folder by :func:`write_tum`:

- ``truth.tum``: the scored truth samples (those with a POSE at or before them, of the scheme);
- ``<scheme>.tum``: one line per truth sample: the POSE matched *causally* to it, exactly as
  :func:`stridefix_analyzer.metrics.match_causal` pairs them (latest POSE at or before the truth
  time), stamped with the truth time so that tools associating by timestamp pair the same samples.

Truth and estimate lines of a scheme share timestamps; ``truth_<scheme>.tum`` holds the truth of that
scheme's scored samples when schemes differ in which samples they score. z = 0 (the error is 2-D);
orientation = yaw only (``heading_rad``; identity when the heading is unknown). Numbers are written
with 17 significant digits so reading them back gives the same float64 values.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:  # only the annotation: io does not depend on scoring at run time
    from stridefix_analyzer.scoring.metrics import Metrics


def yaw_quaternion(yaw_rad: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """(n, 4) quaternions qx, qy, qz, qw of rotations by ``yaw_rad`` about +z; NaN yaw → identity."""
    yaw = np.asarray(yaw_rad, float).reshape(-1)
    yaw = np.where(np.isfinite(yaw), yaw, 0.0)
    q = np.zeros((len(yaw), 4))
    q[:, 2], q[:, 3] = np.sin(yaw / 2), np.cos(yaw / 2)
    return q


def format_tum(t_us: npt.ArrayLike, x_m: npt.ArrayLike, y_m: npt.ArrayLike, yaw_rad: npt.ArrayLike) -> str:
    """TUM lines of the given samples (timestamp = t_us / 1e6 [s])."""
    q = yaw_quaternion(yaw_rad)
    lines = []
    for t, x, y, qq in zip(
        np.asarray(t_us, np.int64).tolist(),
        np.asarray(x_m, float).tolist(),
        np.asarray(y_m, float).tolist(),
        q.tolist(),
    ):
        lines.append(f"{t // 1_000_000}.{t % 1_000_000:06d} {x!r} {y!r} 0.0 " + " ".join(repr(v) for v in qq))
    return "\n".join(lines) + ("\n" if lines else "")


def write_tum(metrics: Metrics, out_dir: str | os.PathLike[str]) -> dict[str, str]:
    """Write ``truth.tum`` and one ``<scheme>.tum`` per scheme of ``metrics``; returns name → path.

    Only scored samples are written (a truth sample before the scheme's first POSE has no match).
    ``truth.tum`` holds the samples scored by every scheme when they are the same for all;
    otherwise ``truth_<scheme>.tum`` is written per scheme (and ``truth.tum`` for the primary).
    """
    os.makedirs(out_dir, exist_ok=True)
    paths: dict[str, str] = {}
    scored_sets = {code: s.match["scored"] for code, s in metrics.schemes.items()}
    same = len({m.tobytes() for m in scored_sets.values()}) <= 1
    for code, s in metrics.schemes.items():
        m = s.match
        sc = m["scored"]
        pose_heading = np.asarray(s.pose["heading_rad"], float)[m["pose_row"][sc]]
        path = os.path.join(out_dir, f"{s.name}.tum")
        with open(path, "w", encoding="utf-8") as f:
            f.write(format_tum(m["t_us"][sc], m["pose_x_m"][sc], m["pose_y_m"][sc], pose_heading))
        paths[s.name] = path
        truth_heading = np.asarray(metrics.truth["heading_rad"], float)[sc]  # NaN → identity
        if not same or code == metrics.primary:
            name = "truth" if code == metrics.primary else f"truth_{s.name}"
            tpath = os.path.join(out_dir, f"{name}.tum")
            with open(tpath, "w", encoding="utf-8") as f:
                f.write(format_tum(m["t_us"][sc], m["truth_x_m"][sc], m["truth_y_m"][sc], truth_heading))
            paths[name] = tpath
    return paths
