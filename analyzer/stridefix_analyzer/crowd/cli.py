"""``stridefix crowd``: the crowdsourced Wi-Fi model of Kannan (2024) on StrideFix logs.

``fit``        dissimilarity → distance model g(d) = max(X1, X2 + X3·d) from walks with ground truth:
               every scan pair on a floor (positions interpolated on the truth), exact streaming
               binning, bounded least squares on the bins → ``model.json`` + ``model_fit.png``.
``solve``      2-D positions of the points of a set of walks from anchors (a subset of the truth
               points) and range rows from PDR and/or the Wi-Fi model → ``solve.json``,
               ``positions.csv``, ``solve.png``; error at the non-anchor truth points.
``radiomap``   a site file built from the graph-solved positions (anchors every K-th truth point + the
               walk's steps, :mod:`.graph_run`) instead of the truth (the walk-mode builder of
               ``stridefix radiomap``); ``--truth-site`` also writes the truth-built one.

The model search over candidate forms (``stridefix-lab crowd models``) and the thesis's experiment
(``stridefix-lab crowd experiment``) are the lab's: :mod:`stridefix_lab.crowd`.

Logs: an argument ``a.lcmlog,b.lcmlog`` is one walk (e.g. ``stridefixd.lcmlog,truth.lcmlog`` of a SIL
run, or the firmware's replay log with the imported msindoor log); see :mod:`.walks`. This module
only declares the actions; the work: :mod:`.fit`, :mod:`.positions`, :mod:`.sites`
on top of :mod:`.model` (dissimilarity, binning, fit, filter), :mod:`.walks` (loading),
:mod:`.solve` (problem, solvers, errors), :mod:`.plots`.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from stridefix_common.exits import input_error_status

from stridefix_analyzer.crowd import model as cm
from stridefix_analyzer.crowd.fit import run_fit
from stridefix_analyzer.crowd.graph_solve import SOLVERS as GRAPH_SOLVERS
from stridefix_analyzer.crowd.positions import run_solve
from stridefix_analyzer.crowd.sites import run_radiomap
from stridefix_analyzer.crowd.solve import RANGES, SOLVERS
from stridefix_analyzer.crowd.walks import CrowdInputError, add_walk_arguments
from stridefix_analyzer.io.logread import LogReadError
from stridefix_analyzer.parallel import add_jobs_argument, add_scheduler_argument

# action -> its command (experiment returns its own exit status)
ACTIONS: dict[str, Callable[[argparse.Namespace], Any]] = {
    "fit": run_fit,
    "solve": run_solve,
    "radiomap": run_radiomap,
}


def _common(p, solve_opts: bool) -> None:
    add_walk_arguments(p)
    if not solve_opts:
        return
    p.add_argument(
        "--model",
        default=None,
        metavar="model.json",
        help="pair model from `crowd fit` or `stridefix-lab crowd models` (needed for --ranges wifi/both/hybrid; "
        "with graph it adds Wi-Fi loop closures)",
    )
    p.add_argument(
        "--anchors",
        default="every:4",
        metavar="every:K|every-other-waypoint",
        help="known truth points per walk (default every:4, the thesis)",
    )
    p.add_argument(
        "--ranges",
        choices=("graph",) + RANGES,
        default="graph",
        help="graph = the crowd graph: PDR steps with stride scale and heading bias per walk, "
        "anchors, and Wi-Fi loop closures when --model is given (default); the thesis's range "
        "problems: pdr; wifi; both = PDR + filtered Wi-Fi rows; hybrid = PDR rows filtered by Wi-Fi",
    )
    p.add_argument(
        "--pdr-span",
        type=int,
        default=1,
        help="PDR rows between points at most this far apart in a walk (1 = "
        "consecutive, 2 = thesis filtering, 0 = all pairs) (default 1)",
    )
    p.add_argument(
        "--pdr-metric",
        choices=("chord", "path"),
        default="chord",
        help="PDR distance: dead-reckoned chord, or Σ step lengths (default chord)",
    )
    p.add_argument(
        "--step-scale",
        type=float,
        default=1.0,
        help="multiply the firmware's step lengths (stride calibration) (default 1)",
    )
    p.add_argument(
        "--tau",
        type=float,
        default=cm.DEFAULT_TAU,
        help=f"reliability filter: keep g(d) ≤ tau·max (default {cm.DEFAULT_TAU})",
    )
    p.add_argument("--no-filter", action="store_true", help="no reliability filter")
    p.add_argument("--weight-m", type=float, default=1.0, help="weights 1/(m·b + c): m (default 1)")
    p.add_argument("--weight-c", type=float, default=2.0, help="c (default 2)")
    p.add_argument("--no-weights", action="store_true", help="all range rows weight 1")
    p.add_argument(
        "--solver",
        choices=SOLVERS,
        default="auto",
        help="native (stridefix_native, Ceres), scipy, or auto = native when importable (default)",
    )


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "crowd",
        help="crowdsourced Wi-Fi model (Kannan 2024): fit, solve, radio map",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="crowd_command", metavar="ACTION", required=True)
    f = sub.add_parser("fit", help="fit g(d) on walks with truth → model.json + plot")
    _common(f, False)
    f.add_argument("--out", required=True, metavar="DIR")
    f.add_argument(
        "--dissimilarity",
        choices=cm.MODES,
        default=cm.DEFAULT_MODE,
        help=f"common_sum (thesis Eq. 4) or common_scaled (× n/n*, n = union) (default {cm.DEFAULT_MODE})",
    )
    f.add_argument(
        "--bin-width-db",
        type=float,
        default=cm.DEFAULT_BIN_WIDTH_DB,
        help=f"dissimilarity bin of the streaming fit [dB] (default {cm.DEFAULT_BIN_WIDTH_DB:g})",
    )
    f.add_argument(
        "--min-common-aps",
        type=int,
        default=1,
        help="pairs sharing fewer APs are excluded (default 1, the thesis); the model "
        "file records it and solve uses it",
    )
    add_scheduler_argument(f, "serial")  # the pair blocks; the bins are bit-identical on every scheduler
    add_jobs_argument(f, "--scheduler processes or local: worker processes", dest="workers")
    f.add_argument(
        "--pair-fraction",
        type=float,
        default=1.0,
        help="fit on an unbiased random subsample of this fraction of the scan pairs (default 1 = all)",
    )
    f.add_argument(
        "--precision",
        choices=("float64", "float32"),
        default="float64",
        help="arithmetic of the pair blocks (float32: ~2x faster at fleet scale) (default float64)",
    )
    s = sub.add_parser("solve", help="positions of the walks' points from anchors + ranges")
    _common(s, True)
    s.add_argument("--out", required=True, metavar="DIR")
    r = sub.add_parser(
        "radiomap", help="site file from graph-solved positions (anchors + steps; + a truth-built one)"
    )
    _common(r, False)
    r.add_argument(
        "--anchors",
        default="every:4",
        metavar="every:K|every-other-waypoint",
        help="known truth points per walk (default every:4, the thesis)",
    )
    r.add_argument(
        "--solver",
        choices=GRAPH_SOLVERS,
        default="auto",
        help="graph solver: native (Ceres), scipy, or auto = native when importable (default)",
    )
    r.add_argument("--out", required=True, metavar="SITE.sfsite")
    r.add_argument(
        "--truth-site",
        default=None,
        metavar="SITE.sfsite",
        help="also write the site built from the truth at the same scans",
    )
    r.add_argument("--cell-size-m", type=float, default=2.0, help="walk-mode grid cell [m]")
    r.add_argument("--map-rotation-deg", type=float, default=0.0)
    return p


def run(args: argparse.Namespace) -> int:
    prog = f"stridefix crowd {args.crowd_command}"
    try:
        ACTIONS[args.crowd_command](args)
    except (LogReadError, CrowdInputError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    return 0
