"""``stridefix score``: the IPIN competition's score of estimate files, in the organisers' table.

Registers the sub-command and calls :mod:`stridefix_analyzer.scoring.ipin_eval`; nothing else.
"""

from __future__ import annotations

import argparse
import sys

from stridefix_common.exits import EXIT_FAILURE, EXIT_OK, input_error_status, worst

from stridefix_analyzer.io.jsonio import write_json
from stridefix_analyzer.scoring.ipin_eval import (
    MATCH_SLACK_S,
    SKIP_ROWS,
    SWAP_BELOW_DEG,
    IpinFileError,
    format_table,
    ranking,
    read_truth,
    score_file,
)
from stridefix_analyzer.scoring.metrics import IPIN_FLOOR_PENALTY_M


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Declare the ``score`` sub-command and its options."""
    p = subparsers.add_parser(
        "score",
        help="score IPIN competition estimate files against the organisers' ground truth",
        description="Score estimate files in the IPIN competition's format as the organisers' "
        "evaluation script does, and print their table: EvAAL score (the 75th percentile of the "
        f"error by Matlab's quantile), mean, RMSE, median and P95 of the error, floor hit rate [%], "
        "mean planar error and points, then the ranking (a team = the file name without its "
        "trailing trial number, ranked by its best file). The error at each ground-truth point = "
        "the horizontal distance (WGS-84, local) to the latest estimate at or before the point's "
        f"time + {MATCH_SLACK_S:g} s, + {IPIN_FLOOR_PENALTY_M:g} m x |floor difference|; a point "
        "before every estimate is not scored. Estimate format: comma-separated, the first "
        f"{SKIP_ROWS} rows skipped; column 1 time [s], columns 5 and 6 longitude and latitude [deg] "
        f"(swapped when the median of column 6 is below {SWAP_BELOW_DEG:g}), column 7 floor. "
        "Ground truth: time [s], longitude, latitude, floor, point number per line.",
    )
    p.add_argument(
        "--truth",
        required=True,
        metavar="GT.csv",
        help="the organisers' ground truth of the trial the estimate files are for",
    )
    p.add_argument("estimates", nargs="+", metavar="EST", help="estimate file(s) of that trial")
    p.add_argument(
        "--json",
        default=None,
        metavar="OUT",
        help="also write the figures (unrounded) and the ranking to the JSON file OUT",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Entry point of ``stridefix score``: the worst status over the estimate files."""
    try:
        truth = read_truth(args.truth)
    except IpinFileError as exc:
        print(f"stridefix score: error: {exc}", file=sys.stderr)
        return input_error_status(exc)
    results, statuses = [], []
    for path in args.estimates:
        try:
            results.append(score_file(truth, path))
        except IpinFileError as exc:
            print(f"stridefix score: error: {exc}", file=sys.stderr)
            statuses.append(input_error_status(exc))
            continue
        if not results[-1]["points"]:
            print(f"stridefix score: error: {path}: no ground-truth point has an estimate", file=sys.stderr)
            statuses.append(EXIT_FAILURE)
        else:
            statuses.append(EXIT_OK)
    if results:
        print(format_table(results))
    if args.json and results:
        doc = {"truth": args.truth, "files": results, "ranking": [list(r) for r in ranking(results)]}
        try:
            write_json(args.json, doc)
        except OSError as exc:
            print(f"stridefix score: error: cannot write {args.json}: {exc}", file=sys.stderr)
            statuses.append(EXIT_FAILURE)
    return worst(statuses)
