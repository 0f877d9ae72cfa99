"""TUM trajectory exports of a scored analysis, for cross-checks with evo and other tools.

Format (TUM RGB-D): one pose per line, ``timestamp x y z qx qy qz qw``, space-separated; timestamp
[s], position [m], unit quaternion (Hamilton, w last).

Files written into a folder by :func:`write_tum`:

- ``truth.tum``: the scored truth samples (those with a POSE at or before them, of the scheme);
- ``<scheme>.tum``: one line per truth sample: the POSE matched *causally* to it, exactly as
  :func:`stridefix_analyzer.metrics.match_causal` pairs them (latest POSE at or before the truth
  time), stamped with the truth time so that tools associating by timestamp pair the same samples.

Truth and estimate lines of a scheme share timestamps; ``truth_<scheme>.tum`` holds the truth of that
scheme's scored samples when schemes differ in which samples they score. z = the height of the floor
[m] (the estimate's floor for a scheme, the true floor for the truth; ``Metrics.heights``,
:mod:`stridefix_analyzer.scoring.floor_height`: a site's table or the log's uniform
``floor.height_m``), so evo sees a floor error as a height error; orientation = yaw only (``heading_rad``; identity when the heading is unknown). Numbers are written
with 17 significant digits so reading them back gives the same float64 values.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

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


class TumError(ValueError):
    """A TUM export cannot be written as asked (the message says why and what to give)."""


def format_tum(
    t_us: npt.ArrayLike,
    x_m: npt.ArrayLike,
    y_m: npt.ArrayLike,
    yaw_rad: npt.ArrayLike,
    z_m: npt.ArrayLike | None = None,
) -> str:
    """TUM lines of the given samples (timestamp = t_us / 1e6 [s]; z = 0 when ``z_m`` is None)."""
    q = yaw_quaternion(yaw_rad)
    n = len(q)
    z = np.zeros(n) if z_m is None else np.broadcast_to(np.asarray(z_m, float), (n,))
    lines = []
    for t, x, y, zz, qq in zip(
        np.asarray(t_us, np.int64).tolist(),
        np.asarray(x_m, float).tolist(),
        np.asarray(y_m, float).tolist(),
        z.tolist(),
        q.tolist(),
    ):
        lines.append(
            f"{t // 1_000_000}.{t % 1_000_000:06d} {x!r} {y!r} {zz!r} " + " ".join(repr(v) for v in qq)
        )
    return "\n".join(lines) + ("\n" if lines else "")


def write_tum(metrics: Metrics, out_dir: str | os.PathLike[str]) -> dict[str, str]:
    """Write ``truth.tum`` and one ``<scheme>.tum`` per scheme of ``metrics``; returns name → path.

    Only scored samples are written (a truth sample before the scheme's first POSE has no match).
    ``truth.tum`` holds the samples scored by every scheme when they are the same for all;
    otherwise ``truth_<scheme>.tum`` is written per scheme (and ``truth.tum`` for the primary).

    Raises :class:`TumError` when the floors' heights are unknown (``metrics.heights``) and the
    walk has more than one floor: z = 0 would hide every floor change and floor error from evo.
    """
    heights = metrics.heights if metrics.heights is not None and metrics.heights.known else None
    floors = {int(f) for f in metrics.truth["floor"]}
    for s in metrics.schemes.values():
        floors |= {int(f) for f in s.match["pose_floor"][s.match["scored"]]}
    if heights is None and len(floors) > 1:
        raise TumError(
            f"TUM z is the floor's height, unknown here (floors {sorted(floors)}; the logs have no CONFIG "
            "floor.height_m): give the site file (--site)"
        )

    def write(name: str, sc: np.ndarray, m: Any, who: str, heading: np.ndarray) -> None:
        """``name``.tum: the scored rows ``sc`` of ``m``'s ``who`` (pose or truth) columns."""
        z = heights.z_m(m[f"{who}_floor"][sc]) if heights is not None else None
        path = os.path.join(out_dir, f"{name}.tum")
        with open(path, "w", encoding="utf-8") as f:
            f.write(format_tum(m["t_us"][sc], m[f"{who}_x_m"][sc], m[f"{who}_y_m"][sc], heading, z))
        paths[name] = path

    os.makedirs(out_dir, exist_ok=True)
    paths: dict[str, str] = {}
    scored_sets = {code: s.match["scored"] for code, s in metrics.schemes.items()}
    same = len({m.tobytes() for m in scored_sets.values()}) <= 1
    for code, s in metrics.schemes.items():
        m = s.match
        sc = m["scored"]
        write(s.name, sc, m, "pose", np.asarray(s.pose["heading_rad"], float)[m["pose_row"][sc]])
        if not same or code == metrics.primary:
            truth_heading = np.asarray(metrics.truth["heading_rad"], float)[sc]  # NaN → identity
            write("truth" if code == metrics.primary else f"truth_{s.name}", sc, m, "truth", truth_heading)
    return paths
