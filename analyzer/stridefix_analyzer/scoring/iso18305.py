"""ISO/IEC 18305:2016 terms of one scheme's scored samples: accuracy, precision, floor detection.

ISO/IEC 18305 (test and evaluation of localization and tracking systems) reports, among its
performance metrics (its clause 8): the floor detection probability (8.2), means of the errors (8.4),
the covariance matrix of the error vector (8.5), variances of the error magnitudes (8.6) and RMS
values (8.7). In its words accuracy is the closeness of the estimates to the truth and precision the
closeness of the estimates to each other; here:

- **accuracy**: the mean horizontal error magnitude [m] (the headline, 8.4), the RMS of it (8.7), the
  CE50 / CE95 (median and 95th percentile, order statistics: no distribution assumed) and the bias,
  the mean error vector (estimate − truth, map x and y) and its length [m];
- **precision**: the spread of the error vector about its mean, the covariance matrix (8.5) and its
  scalar √trace [m] (the 2-D RMS about the bias: a constant offset costs accuracy, not precision), and
  the standard deviation of the error magnitude (8.6);
- **floor detection probability** (8.2): the share of scored samples on the true floor;
- **vertical and 3-D** (8.4, when floor heights are known, :mod:`.floor_height`): the height of the
  estimated floor against the true floor's, its mean magnitude, and the mean 3-D error magnitude.

Every number is over the samples :func:`~stridefix_analyzer.scoring.metrics.match_causal` scored (the
same as every other statistic of the scheme); NaN (``null`` in JSON) when there are none.
"""

from __future__ import annotations

import numpy as np

from stridefix_analyzer.io.logread import Table
from stridefix_analyzer.scoring.floor_height import FloorHeights


def _mean(x: np.ndarray) -> float:
    return float(np.mean(x)) if x.size else float("nan")


def terms(match: Table, heights: FloorHeights | None = None) -> dict:
    """The ISO/IEC 18305 terms (module docstring) of a :func:`match_causal` table's scored rows.

    Returns a JSON-ready dict: ``n``; ``accuracy`` (``mean_error_m``, ``rms_error_m``, ``ce50_m``,
    ``ce95_m``, ``bias_x_m``, ``bias_y_m``, ``bias_m``); ``precision`` (``cov_xx_m2``, ``cov_xy_m2``,
    ``cov_yy_m2``, ``spread_m``, ``error_std_m``); ``floor_detection_probability``; ``vertical``
    (``mean_error_m``, ``mean_3d_error_m``, ``heights``: the source) or None without floor heights.
    """
    sc = np.asarray(match["scored"], bool)
    dx = np.asarray(match["pose_x_m"], float)[sc] - np.asarray(match["truth_x_m"], float)[sc]
    dy = np.asarray(match["pose_y_m"], float)[sc] - np.asarray(match["truth_y_m"], float)[sc]
    ok = np.isfinite(dx) & np.isfinite(dy)
    dx, dy = dx[ok], dy[ok]
    e = np.hypot(dx, dy)
    n = int(e.size)
    nan = float("nan")
    if n:
        ce50, ce95 = (float(v) for v in np.percentile(e, (50, 95)))
        bx, by = float(dx.mean()), float(dy.mean())
        cxx, cyy = float(np.mean((dx - bx) ** 2)), float(np.mean((dy - by) ** 2))
        cxy = float(np.mean((dx - bx) * (dy - by)))
        spread, std = float(np.sqrt(cxx + cyy)), float(e.std())
    else:
        ce50 = ce95 = bx = by = cxx = cyy = cxy = spread = std = nan
    floor_est = np.asarray(match["pose_floor"], np.int64)[sc][ok]
    floor_true = np.asarray(match["truth_floor"], np.int64)[sc][ok]
    vertical = None
    if heights is not None and heights.known:
        dz = heights.z_m(floor_est) - heights.z_m(floor_true)
        vertical = {
            "mean_error_m": _mean(np.abs(dz)),
            "mean_3d_error_m": _mean(np.sqrt(e**2 + dz**2)),
            "heights": heights.source,
        }
    return {
        "n": n,
        "accuracy": {
            "mean_error_m": _mean(e),
            "rms_error_m": float(np.sqrt(np.mean(e**2))) if n else nan,
            "ce50_m": ce50,
            "ce95_m": ce95,
            "bias_x_m": bx,
            "bias_y_m": by,
            "bias_m": float(np.hypot(bx, by)),
        },
        "precision": {
            "cov_xx_m2": cxx,
            "cov_xy_m2": cxy,
            "cov_yy_m2": cyy,
            "spread_m": spread,
            "error_std_m": std,
        },
        "floor_detection_probability": _mean((floor_est == floor_true).astype(np.float64)),
        "vertical": vertical,
    }


def format_line(t: dict | None, scheme: str) -> str:
    """One console line of a scheme's terms (``stridefix analyze``)."""
    if not t or not t.get("n"):
        return f"ISO/IEC 18305 ({scheme}): no scored sample"
    a, p = t["accuracy"], t["precision"]
    v = t.get("vertical")
    vert = (
        f", vertical {v['mean_error_m']:.2f} m, 3-D {v['mean_3d_error_m']:.2f} m ({v['heights']})"
        if v
        else ""
    )
    return (
        f"ISO/IEC 18305 ({scheme}): accuracy {a['mean_error_m']:.2f} m mean (RMS {a['rms_error_m']:.2f}, "
        f"CE95 {a['ce95_m']:.2f}, bias {a['bias_m']:.2f} m), precision {p['spread_m']:.2f} m, "
        f"floor detection {100 * t['floor_detection_probability']:.1f} %{vert}"
    )
