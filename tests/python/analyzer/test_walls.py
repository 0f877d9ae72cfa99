"""The site's floor plan against tracks: wall crossings counted, walls and ports in analyze's outputs
and drawn on the report's floor panels."""

from __future__ import annotations

import numpy as np
import pytest
from stridefix import pose_t, site_t
from stridefix_analyzer.io.site_v3 import fill_port_defaults
from stridefix_analyzer.io.sitefile import new_site, write_site
from stridefix_analyzer.scoring import plots, style
from stridefix_analyzer.scoring.analyze import run_analyze
from stridefix_analyzer.scoring.walls import crossings

# a 10 m corridor along x on floor 0 with a cross wall at x = 4.05 (y -2..2); floor 1 a wall at x = 7.05
WALLS = np.array([[4.05, -2.0, 4.05, 2.0, 0], [7.05, -2.0, 7.05, 2.0, 1], [0.0, 2.0, 10.0, 2.0, 0]])


def test_crossings_counts_segments_through_a_wall_of_their_floor():
    x = np.arange(0.0, 10.0, 0.1)
    assert crossings(x, np.zeros_like(x), np.zeros(len(x), int), WALLS) == 1  # x = 4.05 only
    assert crossings(x, np.zeros_like(x), np.ones(len(x), int), WALLS) == 1  # x = 7.05 only
    assert crossings(x, np.full_like(x, 3.0), np.zeros(len(x), int), WALLS) == 0  # beside the wall's end
    # back and forth through the wall: each pass is one
    xs = np.array([3.0, 5.0, 3.0, 5.0])
    assert crossings(xs, np.zeros(4), np.zeros(4, int), WALLS) == 3
    # a floor change between two samples is no crossing, whatever lies between them
    assert crossings([3.0, 5.0], [0.0, 0.0], [0, 1], WALLS) == 0
    # stepping onto the wall and on through it is one crossing, not two
    assert crossings([3.0, 4.05, 5.0], [0.0, 0.0, 0.0], [0, 0, 0], WALLS) == 1
    # NaN samples break the track; no walls, no crossings
    assert crossings([3.0, np.nan, 5.0], [0.0, 0.0, 0.0], [0, 0, 0], WALLS) == 0
    assert crossings(x, np.zeros_like(x), np.zeros(len(x), int), np.empty((0, 5))) == 0


@pytest.fixture
def corridor(msg, write_log, straight_walk, tmp_path):
    """The straight walk on floor 0 (x 0 … 9.9 m, y 0): adaptive 1 m to the side, pdr_only drifting
    off in y (through the side wall y = 2 at x = 0.5, then past the cross wall's end); a site with the
    walls above, a door on floor 0 and stairs joining floors 0 and 1."""
    t, x, y = straight_walk
    events = []
    for i in range(len(t)):
        events.append(("POSE", msg.pose(t[i], x[i], y[i] + 1.0)))
        events.append(("POSE", msg.pose(t[i], x[i], 1.0 + 0.2 * i, scheme=pose_t.SCHEME_PDR_ONLY)))
        events.append(("TRUTH", msg.truth(t[i], x[i], y[i])))
    site = new_site(
        lowest_floor=0,
        floor_height_m=[0.0, 3.5],
        wall_x0_m=WALLS[:, 0],
        wall_y0_m=WALLS[:, 1],
        wall_x1_m=WALLS[:, 2],
        wall_y1_m=WALLS[:, 3],
        wall_floor=WALLS[:, 4].astype(int),
        port_kind=[site_t.PORT_DOOR, site_t.PORT_STAIRS],
        port_x_m=[4.05, 9.0],
        port_y_m=[0.0, 1.0],
        port_radius_m=[0.6, 1.5],
        port_floor_lo=[0, 0],
        port_floor_hi=[0, 1],
    )
    fill_port_defaults(site)
    write_site(tmp_path / "s.sfsite", site)
    summary, _ = run_analyze(
        [str(write_log("w.lcmlog", events))], str(tmp_path / "an"), site=str(tmp_path / "s.sfsite")
    )
    return summary, dict(np.load(tmp_path / "an" / "analysis.npz"))


def test_analyze_counts_each_schemes_wall_crossings(corridor):
    summary, _ = corridor
    # truth and adaptive pass the cross wall at x = 4.05 (the door there is no gap in the wall list);
    # pdr_only climbs out of the corridor through y = 2 before it reaches x = 4.05
    assert summary["truth_wall_crossings"] == 1
    assert summary["per_scheme"]["adaptive"]["wall_crossings"] == 1
    assert summary["per_scheme"]["pdr_only"]["wall_crossings"] == 1


def test_trajectory_draws_ports_per_floor_with_a_legend(corridor):
    _, series = corridor
    assert list(series["site_port_kind"]) == [site_t.PORT_DOOR, site_t.PORT_STAIRS]
    fig = plots.plot_trajectory(series)
    (panel,) = [ax for ax in fig.axes if ax.get_visible()]  # the walk stays on floor 0
    markers = {ln.get_marker() for ln in panel.get_lines() if len(ln.get_xdata())}
    assert {style.PORT["door"]["marker"], style.PORT["stairs"]["marker"]} <= markers
    assert style.PORT["elevator"]["marker"] not in markers  # the site has none
    assert len(panel.patches) == 2  # each port's disc
    legend = {t.get_text() for t in fig.legends[0].get_texts()}
    assert {"door", "stairs"} <= legend and "elevator" not in legend
