"""ipin_eval and `stridefix score`: the IPIN organisers' scorer, checked against their own published output
(../shared/data/ipin2023/evaluation: skipped when absent) and against small hand-computed cases."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.scoring import ipin_eval
from stridefix_analyzer.scoring.ipin_eval import IpinFileError, IpinNothingValidError
from stridefix_analyzer.scoring.metrics import ipin_score, matlab_quantile

REPO = Path(__file__).resolve().parents[3]
EVALUATION = REPO.parent / "shared" / "data" / "ipin2023" / "evaluation"
OUTPUT = EVALUATION / "output_trials_zenodo.txt"

# the organisers' output_trials_zenodo.txt: EvAAL, MEAN, RMSE, MEDIAN, P95, FHR(%), MPExy, POINTS
PUBLISHED = {
    "S323ZENODOTS01": (5.75, 5.01, 6.47, 3.80, 16.34, 94.20, 4.14, 69),
    "S323ZENODOTS02": (6.35, 4.87, 6.62, 3.67, 13.11, 95.65, 4.22, 69),
    "S323ZENODOTZ01": (5.80, 4.72, 5.90, 4.03, 10.56, 97.10, 4.29, 69),
    "S323ZENODOTZ02": (4.35, 3.52, 5.21, 2.44, 8.83, 95.65, 2.87, 69),
}
KEYS = ("evaal_m", "mean_m", "rmse_m", "median_m", "p95_m", "floor_hit_rate_pct", "mean_planar_error_m")


def _evaluation() -> Path:
    if not OUTPUT.is_file():
        pytest.skip(
            f"IPIN evaluation data not found at {EVALUATION} (needs ../shared/data beside the repository)"
        )
    return EVALUATION


def _truth_of(ident: str) -> Path:
    """The ground truth of a sample file's trial (its last digit: ScoringTrial01 or 02)."""
    return _evaluation() / f"GT_IPIN2023_T3_ScoringTrial0{ident[-1]}.csv"


# --- Matlab's quantile -----------------------------------------------------------------------------


def test_matlab_quantile_of_hand_computed_arrays():
    # [1, 2, 3, 4]: the i-th value sits at (i - 0.5)/4 = 0.125, 0.375, 0.625, 0.875
    x = [4.0, 1.0, 3.0, 2.0]
    assert_allclose(matlab_quantile(x, 0.5), 2.5, rtol=1e-12)
    assert_allclose(matlab_quantile(x, 0.75), 3.5, rtol=1e-12)  # halfway 0.625 -> 0.875 (numpy: 3.25)
    assert_allclose(matlab_quantile(x, 0.25), 1.5, rtol=1e-12)
    assert_allclose(matlab_quantile(x, [0.1, 0.95, 0.0, 1.0]), [1.0, 4.0, 1.0, 4.0], rtol=1e-12)  # clamped
    # [0, 10, 30] at 1/6, 1/2, 5/6: 0.75 is 3/4 of the way from 10 to 30 -> 25 (numpy's linear: 20)
    assert_allclose(matlab_quantile([10.0, 0.0, 30.0], 0.75), 25.0, rtol=1e-12)
    assert_allclose(matlab_quantile([10.0, 0.0, 30.0], 0.95), 30.0, rtol=1e-12)
    assert_allclose(matlab_quantile([7.0], [0.0, 0.75, 1.0]), 7.0, rtol=1e-12)


def test_ipin_score_is_the_matlab_p75_of_error_plus_floor_penalty():
    # 2-D errors 1..4 m, the last one floor off: 1, 2, 3, 19 -> 3 + 0.5 x (19 - 3) = 11.0 m
    assert_allclose(ipin_score([1.0, 2.0, 3.0, 4.0], [0, 0, 0, -1]), 11.0, rtol=1e-12)


# --- the organisers' figures -----------------------------------------------------------------------


@pytest.mark.parametrize("ident", sorted(PUBLISHED))
def test_the_organisers_figures_of_the_four_sample_files(ident):
    evaluation = _evaluation()
    r = ipin_eval.score_file(ipin_eval.read_truth(_truth_of(ident)), evaluation / f"{ident}.est")
    published = PUBLISHED[ident]
    assert r["id"] == ident and r["points"] == published[-1] and r["unmatched"] == 0
    assert round(r["evaal_m"], 2) == published[0]
    for key, want in zip(KEYS, published):
        assert abs(r[key] - want) <= 0.005 + 1e-9, (key, r[key], want)


def test_the_table_and_ranking_are_the_organisers_layout():
    evaluation = _evaluation()
    results = [
        ipin_eval.score_file(ipin_eval.read_truth(_truth_of(i)), evaluation / f"{i}.est")
        for i in sorted(PUBLISHED)
    ]
    published = OUTPUT.read_text(encoding="utf-8").splitlines()
    table = ipin_eval.format_table(results).splitlines()
    start = published.index(table[0])
    assert published[start : start + len(table)] == table


def test_score_command_prints_the_table_and_writes_json(cli_main, capsys, tmp_path):
    evaluation = _evaluation()
    out = tmp_path / "score.json"
    files = [str(evaluation / f"S323ZENODOT{team}01.est") for team in ("S", "Z")]
    assert cli_main(["score", "--truth", str(_truth_of("x1")), *files, "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "      S323ZENODOTS01:\t   5.75\t" in printed and "1 S323ZENODOTS \t       5.75 m" in printed
    doc = json.loads(out.read_text())
    assert [f["id"] for f in doc["files"]] == ["S323ZENODOTS01", "S323ZENODOTZ01"]
    assert doc["ranking"][0][0] == "S323ZENODOTS"


# --- the format, on small handmade files -------------------------------------------------------------

# two points at a site west of 10 deg E (so that a file written lat, lon has column 6 below 10 and is swapped)
LON, LAT = 2.1110, 41.4610
TRUTH_CSV = f"0010.000,{LON},{LAT},00,001\n0020.000,{LON},{LAT + 0.0001},01,002\n"


def _est(rows: list[tuple[float, float, float, float]], swap: bool = False) -> str:
    """An estimate file: two rows the scorer skips, then time, 3 unread columns, lon, lat, floor."""
    lines = ["0,0,0,0,0,0,0", "0,0,0,0,0,0,0"]
    for t, lon, lat, floor in rows:
        a, b = (lat, lon) if swap else (lon, lat)
        lines.append(f"{t:.3f},1.0,0.5,45.0,{a:.9f},{b:.9f},{floor:.1f}")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("swap", [False, True])
def test_match_is_latest_at_or_before_point_plus_slack_and_columns_swap(tmp_path, swap):
    truth_path = tmp_path / "gt.csv"
    truth_path.write_text(TRUTH_CSV)
    # point 1 (t 10 s) takes the estimate at 10.009 s (within the 0.01 s slack), not the one at 10.02 s;
    # point 2 (t 20 s) takes the estimate at 15 s: on the spot but one floor down -> 15 m
    rows = [(5.0, 2.2, 41.5, 0), (10.009, LON, LAT, 0), (10.02, 2.2, 41.5, 0), (15.0, LON, LAT + 0.0001, 0)]
    est = tmp_path / "t.est"
    est.write_text(_est(rows, swap))
    errors = ipin_eval.point_errors(*ipin_eval.read_truth(truth_path), ipin_eval.read_estimate(est))
    assert_allclose(errors.planar_m, [0.0, 0.0], atol=1e-6)
    assert_allclose(errors.error_m, [0.0, 15.0], atol=1e-6)
    assert list(errors.point) == [1, 2] and errors.unmatched == 0


def test_planar_distance_is_the_wgs84_local_plane():
    # 0.001 deg of latitude at 49.46 deg N: the WGS-84 meridian radius of curvature M gives 111.22 m
    lat0 = 49.46
    w = 1.0 - 6.69437999014e-3 * math.sin(math.radians(lat0)) ** 2
    m = 6378137.0 * (1.0 - 6.69437999014e-3) / w**1.5
    d = ipin_eval.planar_distance_m(
        np.array([lat0 + 0.001]), np.array([11.0]), np.array([lat0]), np.array([11.0])
    )
    assert_allclose(d, [m * math.radians(0.001)], rtol=1e-9)


def test_a_point_before_every_estimate_is_not_scored(tmp_path):
    truth_path = tmp_path / "gt.csv"
    truth_path.write_text(TRUTH_CSV)
    est = tmp_path / "late.est"
    est.write_text(_est([(12.0, LON, LAT + 0.0001, 1)]))
    r = ipin_eval.score_file(ipin_eval.read_truth(truth_path), est)
    assert r["points"] == 1 and r["unmatched"] == 1 and r["floor_hit_rate_pct"] == 100.0


def test_a_bad_estimate_names_file_line_and_field(tmp_path, cli_main, capsys):
    truth_path = tmp_path / "gt.csv"
    truth_path.write_text(TRUTH_CSV)
    est = tmp_path / "bad.est"
    est.write_text(_est([(10.0, LON, LAT, 0)]) + "11.0,1.0,0.5,45.0,2.1,north,0\n")
    with pytest.raises(IpinFileError) as caught:
        ipin_eval.read_estimate(est)
    assert str(caught.value) == f"{est}, line 4, column 6 (latitude): 'north' is not a finite number"
    assert (caught.value.line, caught.value.field) == (4, "column 6 (latitude)")
    assert cli_main(["score", "--truth", str(truth_path), str(est)]) == 2
    assert f"{est}, line 4, column 6 (latitude)" in capsys.readouterr().err


def test_short_lines_ranges_and_empty_files(tmp_path, cli_main):
    short = tmp_path / "short.est"
    short.write_text(_est([]) + "10.0,1.0,0.5,45.0,2.1\n")
    with pytest.raises(IpinFileError, match=r"short\.est, line 3: 5 comma-separated fields, 7 needed"):
        ipin_eval.read_estimate(short)
    far = tmp_path / "far.est"
    far.write_text(_est([(10.0, LON, LAT, 0), (11.0, LON, 95.0, 0), (12.0, LON, LAT, 0)]))
    with pytest.raises(IpinFileError, match=r"line 4, column 6 \(latitude\): 95 is outside ±90°"):
        ipin_eval.read_estimate(far)
    empty = tmp_path / "empty.est"
    empty.write_text(_est([]))
    with pytest.raises(IpinNothingValidError, match="no data row"):
        ipin_eval.read_estimate(empty)
    truth_path = tmp_path / "gt.csv"
    truth_path.write_text(TRUTH_CSV)
    assert cli_main(["score", "--truth", str(truth_path), str(empty)]) == 3
    junk = tmp_path / "junk.est"
    junk.write_bytes(b"\x00\xff\xfe" * 100)
    assert cli_main(["score", "--truth", str(truth_path), str(junk)]) == 3
    assert cli_main(["score", "--truth", str(truth_path), str(tmp_path)]) == 2  # a directory
    assert cli_main(["score", "--truth", str(tmp_path / "missing.csv"), str(empty)]) == 2
