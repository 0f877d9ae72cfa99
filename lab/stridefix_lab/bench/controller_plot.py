"""The context timeline of one ``bench controller`` walk: the truth's context against the
controller's over time, with the truth's transitions marked (matplotlib, Agg; no figures computed
here: the inputs come from :mod:`.controller_score`)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)


def write_timeline(
    path: Path,
    truth_line: Sequence[tuple[int, int, str]],
    ctl_line: tuple[Sequence[int], Sequence[str]],
    transitions: Sequence[dict[str, Any]],
    title: str,
) -> None:
    """Write the PNG: ``truth_line`` runs (start µs, end µs, key), the controller's CONTEXT messages
    (t_us, key; ``""`` = none yet: drawn as INIT) held until the next, and each transition's crossing
    (a dotted line; red when it was not detected within the target)."""
    if not truth_line:
        return
    t0, t_end = truth_line[0][0], truth_line[-1][1]
    ct, ck = list(ctl_line[0]), [k or "none (INIT)" for k in ctl_line[1]]
    keys = sorted({k for _, _, k in truth_line} | set(ck), key=lambda k: (k == "none (INIT)", k))
    level = {k: i for i, k in enumerate(keys)}
    fig, ax = plt.subplots(figsize=(11, 0.6 * len(keys) + 2.0))
    for s, e, k in truth_line:
        ax.plot([(s - t0) / 1e6, (e - t0) / 1e6], [level[k]] * 2, color="black", linewidth=6, alpha=0.35)
    if ct:
        xs = [(t - t0) / 1e6 for t in ct] + [(t_end - t0) / 1e6]
        ys = [level[k] for k in ck]
        ax.step(xs, [*ys, ys[-1]], where="post", color="#e377c2", linewidth=1.8, label="controller")
    for tr in transitions:
        ax.axvline((tr["t_us"] - t0) / 1e6, color="green" if tr["within_target"] else "red", linestyle=":")
    ax.plot([], [], color="black", linewidth=6, alpha=0.35, label="truth")
    ax.set_yticks(range(len(keys)), keys)
    ax.set_xlabel("time since the walk's start [s]")
    ax.set_title(f"{title}: context over time (dotted: truth transitions, red = not detected in time)")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    ax.grid(axis="x", alpha=0.3)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
