"""``stridefix-lab crowd``: the research half of the crowdsourced Wi-Fi model of Kannan (2024).

``models``     every candidate dissimilarity → distance model (feature × form × n* strata, the thesis's
               as the reference row) fitted on K−1 folds of walks and scored on the held-out one
               (R², RMSE, rank correlation); the best by held-out R² → ``models.json`` + ``models.png``
               (:mod:`.select_model`). ``stridefix crowd solve --model`` reads the file.
``experiment`` the thesis's table in SIL (``--sil``) or on msindoor walks (``--msindoor DIR``), see
               :mod:`.experiment`.

The product's crowd commands (``stridefix crowd fit|solve|radiomap``) build a user's map; these
choose and measure them. This module only declares the actions.
"""

from __future__ import annotations

import argparse
import sys

from stridefix_analyzer.crowd.walks import CrowdInputError, add_walk_arguments
from stridefix_analyzer.io.logread import LogReadError
from stridefix_common.exits import input_error_status

from stridefix_lab.crowd import experiment
from stridefix_lab.crowd.select_model import DEFAULT_FOLDS, run_models


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "crowd",
        help="crowdsourced Wi-Fi model (Kannan 2024): model search, the thesis's experiment",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="crowd_command", metavar="ACTION", required=True)
    mo = sub.add_parser("models", help="candidate models chosen by held-out fit → models.json + plot")
    add_walk_arguments(mo)
    mo.add_argument("--out", required=True, metavar="DIR")
    mo.add_argument(
        "--folds", type=int, default=DEFAULT_FOLDS, help=f"folds by walk (default {DEFAULT_FOLDS})"
    )
    mo.add_argument(
        "--candidates",
        nargs="+",
        default=None,
        metavar="FORM/FEATURE[@n*]",
        help="only these candidates (default all), e.g. thesis/common_sum isotonic/cosine@n*",
    )
    e = sub.add_parser("experiment", help="the thesis's table: --sil or --msindoor DIR")
    experiment.add_arguments(e)
    return p


def run(args: argparse.Namespace) -> int:
    prog = f"stridefix-lab crowd {args.crowd_command}"
    try:
        if args.crowd_command == "experiment":
            return experiment.run_experiment(args)
        run_models(args)
    except (LogReadError, CrowdInputError) as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    return 0
