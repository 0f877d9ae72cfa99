"""The primary scheme: the one pose every report headlines, decided by the firmware, not here.

The firmware publishes its primary pose on the ``POSE`` channel (``sf_publish_primary_of``: the
multi-scheme controller's pose, or without an active controller a copy of the scheme
``output.scheme`` / ``controller.init_scheme`` names, pdr_only's while that has no position) and
each fusion scheme's on ``POSE_<SCHEME>``. So the primary of a log is the scheme of the last
message the POSE channel carried (:attr:`~stridefix_analyzer.io.logread.LogData.pose_channel_scheme`):
the one the firmware settled on, whatever it carried before its first fix or context. ``analyze``,
``report``, the live view and the demo all headline that scheme; ``--scheme`` overrides it.

A log from before the per-scheme channels carries every scheme on POSE and so does not say; for it
(and for synthetic logs written that way) :func:`fallback_primary` picks the controller when
present, else the scheme with most poses, ties in :data:`FALLBACK_ORDER`.
"""

from __future__ import annotations

import numpy as np

from stridefix_analyzer.schemes import scheme_name

#: tie-break of :func:`fallback_primary`, for logs that do not say which scheme POSE carried
FALLBACK_ORDER = ["controller", "adaptive", "kalman", "static", "overwrite", "wifi_only", "pdr_only"]

#: how the primary was chosen (metrics.json ``primary_from``)
REQUESTED, POSE_CHANNEL, FALLBACK = "requested", "pose_channel", "fallback"


class PrimaryError(ValueError):
    """The requested scheme has no pose in the log; the message lists those present."""


def fallback_rank(name: str) -> int:
    """A scheme's place in :data:`FALLBACK_ORDER` (lower first; an unlisted scheme after all)."""
    return FALLBACK_ORDER.index(name) if name in FALLBACK_ORDER else len(FALLBACK_ORDER)


def fallback_primary(codes: np.ndarray, counts: np.ndarray) -> int:
    """For a log that does not say: ``controller`` when present, else most poses, ties by
    :data:`FALLBACK_ORDER`, then by id."""
    names = [scheme_name(c) for c in codes]
    if "controller" in names:
        return int(codes[names.index("controller")])
    best = min(range(len(codes)), key=lambda i: (-counts[i], fallback_rank(names[i]), int(codes[i])))
    return int(codes[best])


def choose_scheme(
    schemes: np.ndarray, requested: int | None = None, pose_channel: int | None = None
) -> tuple[int, str]:
    """(primary scheme id, how it was chosen: :data:`REQUESTED`, :data:`POSE_CHANNEL` or :data:`FALLBACK`).

    Parameters
    ----------
    schemes : ndarray, shape (n_pose,)
        The POSE table's ``scheme`` column (every scheme's poses).
    requested : int, optional
        ``--scheme``: must have poses in the log (else :class:`PrimaryError`).
    pose_channel : int, optional
        The scheme the POSE channel carried last (``LogData.pose_channel_scheme``).
    """
    codes, counts = np.unique(schemes, return_counts=True)
    if requested is not None:
        if requested not in codes:
            raise PrimaryError(
                f"scheme {scheme_name(requested)} not in the POSE stream; present: "
                f"{[scheme_name(c) for c in codes]}"
            )
        return int(requested), REQUESTED
    if pose_channel is not None and pose_channel in codes:
        return int(pose_channel), POSE_CHANNEL
    return fallback_primary(codes, counts), FALLBACK
