"""msindoor floor plans → walls (radiomap/floorplan.py): the GeoJSON mapping, simplification, doors
opened at crossings, the leave-one-out crossing fraction, and the real site1/F2 plan."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_analyzer.radiomap import floorplan as fp
from stridefix_common.geodesy import project

F2 = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "msindoor" / "site1" / "F2"
LON0, LAT0 = 120.0, 30.0


def _deg(x_m, y_m, w_deg=0.001, h_deg=0.0008, w_m=100.0, h_m=80.0):
    """Map metres on a 100 x 80 m floor → lon/lat of a box w_deg x h_deg from (LON0, LAT0)."""
    return [[LON0 + x / w_m * w_deg, LAT0 + y / h_m * h_deg] for x, y in zip(x_m, y_m)]


def _geojson(rooms=()):
    """A 100 x 80 m floor outline (with collinear midpoints on its bottom edge) and rooms (lists of
    (x, y) corners in metres)."""
    outline = _deg([0, 25, 50, 100, 100, 0, 0], [0, 0, 0, 0, 80, 80, 0])
    feats = [
        {
            "type": "Feature",
            "properties": {"type": "floor"},
            "geometry": {"type": "MultiPolygon", "coordinates": [[outline]]},
        }
    ]
    for r in rooms:
        xs, ys = zip(*(list(r) + [r[0]]))
        feats.append(
            {
                "type": "Feature",
                "properties": {},
                "geometry": {"type": "Polygon", "coordinates": [_deg(xs, ys)]},
            }
        )
    return {"type": "FeatureCollection", "features": feats}


def test_the_floor_box_maps_onto_the_extent_and_sets_the_geo_reference():
    plan = fp.read_geojson_plan(_geojson([[(10, 10), (20, 10), (20, 30), (10, 30)]]), 100.0, 80.0)
    assert_allclose(plan.to_map([LON0, LON0 + 0.001], [LAT0, LAT0 + 0.0008]), [[0, 0], [100, 80]], atol=1e-9)
    assert_allclose(plan.rooms[0][:4], [[10, 10], [20, 10], [20, 30], [10, 30]], atol=1e-6)
    assert_allclose(plan.room_area_m2, [200.0], rtol=1e-9)
    geo = fp.geo_reference(plan)
    assert geo["fields"]["has_geo"] and geo["fields"]["geo_rotation_deg"] == 0.0
    assert (geo["fields"]["origin_lat_deg"], geo["fields"]["origin_lon_deg"]) == (LAT0, LON0)
    # the scale is map metres per tangent-plane metre: 100 m over 0.001 deg of longitude at 30 deg N
    ex, ny = project([LAT0 + 0.0008], [LON0 + 0.001], LAT0, LON0)
    assert_allclose(geo["scale"], [100.0 / ex[0], 80.0 / ny[0]], rtol=1e-12)
    inside = fp.inside_outline(plan, [[50, 40], [-1, 40], [50, 81], [99.9, 0.1]])
    assert inside.tolist() == [True, False, False, True]


def test_walls_merge_collinear_runs_drop_short_edges_and_keep_a_shared_edge_once():
    # two rooms sharing the edge x = 20 (10..30), and a room with a 0.2 m notch edge
    rooms = [
        [(10, 10), (20, 10), (20, 30), (10, 30)],
        [(20, 10), (30, 10), (30, 30), (20, 30)],
        [(50, 50), (60, 50), (60, 60), (50.2, 60), (50.0, 60.0), (50, 55)],
    ]
    plan = fp.read_geojson_plan(_geojson(rooms), 100.0, 80.0)
    walls = fp.plan_walls(plan)
    # outline 4 (its midpoints merged) + room 1: 4 + room 2: 3 (shared edge once) + room 3: 4
    # (its collinear point (50, 55) merged, the 0.2 m edge dropped)
    assert len(walls) == 4 + 4 + 3 + 4
    lengths = np.hypot(walls[:, 2] - walls[:, 0], walls[:, 3] - walls[:, 1])
    assert lengths.min() >= fp.MIN_WALL_M
    assert np.sum(np.isclose(lengths, 100.0, atol=1e-6)) == 2  # the outline's long edges, one each
    assert len(fp.plan_walls(plan, min_room_area_m2=150.0)) == 4 + 4 + 3  # room 3 (~100 m²) left out
    assert len(fp.plan_walls(plan, min_room_area_m2=np.inf)) == 4


def test_a_crossing_opens_a_door_wide_gap_centred_on_it():
    wall = np.array([[0.0, 0.0, 10.0, 0.0]])
    # a truth segment crossing at x = 3, one at x = 0.5 (near the end), two 1 m apart at 7 and 8
    segs = np.array([[3, -1, 3, 1], [0.5, 1, 0.5, -1], [7, -1, 7, 2], [8, 1, 8, -1], [5, 1, 5, 2]], float)
    cw, cu, cs = fp.crossings(wall, segs)
    assert cw.tolist() == [0, 0, 0, 0] and sorted(cs.tolist()) == [0, 1, 2, 3]
    assert_allclose(np.sort(cu), [0.5, 3.0, 7.0, 8.0])
    opened, openings = fp.open_walls(wall, cw, cu, door_width_m=2.0)
    # gaps [0, 1.5], [2, 4], [6, 9] -> pieces [1.5, 2] and [4, 6] and [9, 10]
    assert openings == 3
    assert_allclose(
        opened[np.argsort(opened[:, 0])], [[1.5, 0, 2, 0], [4, 0, 6, 0], [9, 0, 10, 0]], atol=1e-12
    )
    # no crossing: the wall stays whole
    assert_allclose(fp.open_walls(wall, cw[:0], cu[:0])[0], wall)


def test_vectorised_crossings_equal_a_loop():
    rng = np.random.default_rng(3)
    walls = rng.uniform(0, 50, size=(300, 4))
    segs = rng.uniform(0, 50, size=(1300, 4))  # more than one block
    cw, cu, cs = fp.crossings(walls, segs)

    def cross(a, b):
        p, r, q, s = a[:2], a[2:] - a[:2], b[:2], b[2:] - b[:2]
        den = r[0] * s[1] - r[1] * s[0]
        t = ((q - p)[0] * s[1] - (q - p)[1] * s[0]) / den
        u = ((q - p)[0] * r[1] - (q - p)[1] * r[0]) / den
        return 0 <= t <= 1 and 0 <= u <= 1, t * np.hypot(*r)

    ref = {
        (i, j): cross(walls[i], segs[j])[1]
        for i in range(0, 300, 7)
        for j in range(1300)
        if cross(walls[i], segs[j])[0]
    }
    got = {(int(w), int(s)): float(u) for w, u, s in zip(cw, cu, cs) if w % 7 == 0}
    assert got.keys() == ref.keys() and len(ref) > 100
    assert_allclose([got[k] for k in ref], list(ref.values()), rtol=1e-9)


def test_held_out_crossing_counts_walls_only_the_scored_walk_crosses():
    # GIVEN a wall along y = 0; walks 0 and 1 cross it at x = 3, walk 2 at x = 8, each with one more
    # segment that crosses nothing
    walls = np.array([[0.0, 0.0, 10.0, 0.0]])
    walks = [
        np.array([[3, -1], [3, 1], [3, 2]]),
        np.array([[3.2, 1], [3.2, -1], [4, -2]]),
        np.array([[8, -1], [8, 1], [9, 2]]),
    ]
    survey = fp.DoorSurvey.of(walls, walks)
    # WHEN every walk is held out in turn
    h = survey.held_out_crossing()
    # THEN walks 0 and 1 pass through the door the other opened; walk 2 crosses a kept wall
    assert h["segments"] == 6 and h["crossing"] == 1
    assert_allclose(h["per_walk"], [0.0, 0.0, 0.5])
    # and a fold never opens the scored walk's own crossing
    w2, openings = survey.fold_walls(2)
    assert openings == 1 and len(fp.crossings(w2, [[8, -1, 8, 1]])[0]) == 1
    assert len(fp.crossings(survey.fold_walls(None)[0], [[8, -1, 8, 1]])[0]) == 0


def test_truth_segments_skip_floor_changes_and_zero_length():
    s = fp.truth_segments([[[0, 0], [1, 0], [1, 0], [2, 0]], [[5, 5], [6, 6]]], [[0, 0, 0, 1], [2, 2]])
    assert s["seg"].tolist() == [[0, 0, 1, 0], [5, 5, 6, 6]]
    assert s["walk"].tolist() == [0, 1] and s["floor"].tolist() == [0, 2]


@pytest.mark.parametrize(
    ("doc", "message"),
    [
        ({"type": "FeatureCollection"}, "features: missing"),
        ({"features": [{"geometry": {"coordinates": []}}]}, "feature 0: geometry.type: missing"),
        (
            {"features": [{"geometry": {"type": "Polygon", "coordinates": [[[1, 2], [3, "x"]]]}}]},
            "feature 0: coordinates",
        ),
        (
            {"features": [{"geometry": {"type": "Polygon", "coordinates": [[[1, 2], [3, 4], [5, 5]]]}}]},
            "no MultiPolygon",
        ),
    ],
)
def test_bad_plans_name_the_file_feature_and_field(doc, message):
    with pytest.raises(fp.FloorPlanError, match=message) as e:
        fp.read_geojson_plan(doc, 10.0, 10.0, "plan.json")
    assert str(e.value).startswith("plan.json: ")


def test_load_plan_names_a_missing_floor_info(tmp_path):
    (tmp_path / "geojson_map.json").write_text(json.dumps(_geojson()))
    with pytest.raises(fp.FloorPlanError, match="floor_info.json: cannot read"):
        fp.load_plan(str(tmp_path / "geojson_map.json"))
    (tmp_path / "floor_info.json").write_text(json.dumps({"map_info": {"width": 100.0}}))
    with pytest.raises(fp.FloorPlanError, match="map_info.width/height"):
        fp.load_plan(str(tmp_path / "geojson_map.json"))


def _waypoints(floor_dir: Path) -> list[np.ndarray]:
    walks = []
    for f in sorted((floor_dir / "path_data_files").glob("*.txt")):
        rows = [ln.split("\t") for ln in f.read_text(encoding="utf-8").splitlines()]
        walks.append(
            np.array([(float(r[2]), float(r[3])) for r in rows if len(r) > 3 and r[1] == "TYPE_WAYPOINT"])
        )
    return walks


def test_real_site1_f2_plan_holds_the_walks():
    if not F2.is_dir():
        pytest.skip(f"real msindoor data not found at {F2}")
    # GIVEN the real site1/F2 plan and its 102 walks' waypoints
    plan = fp.load_plan(str(F2 / "geojson_map.json"))
    walks = _waypoints(F2)
    xy = np.concatenate(walks)
    # THEN every waypoint is inside the floor outline (measured: 699 of 699)
    assert len(xy) > 600 and fp.inside_outline(plan, xy).mean() == 1.0
    # the frame is true metres to 0.5 % (measured x 0.9991, y 1.0042)
    assert_allclose(fp.geo_reference(plan)["scale"], [1.0, 1.0], atol=0.005)
    # WHEN the walls are made and opened leave one walk out
    t0 = time.perf_counter()
    fields, report = fp.site_plan(plan, walks, None, 1)
    cost_s = time.perf_counter() - t0
    # THEN (measured: 911 edges -> 747 walls, 64 openings -> 753 segments; held-out 5.0 %)
    assert report["edges_raw"] == 911 and 300 < report["walls_simplified"] < 3000
    assert report["openings"] > 20 and len(fields["wall_x0_m"]) == report["walls_opened"]
    assert report["held_out_crossing_fraction"] < 0.10
    assert set(fields["wall_floor"]) == {1}
    assert cost_s < 1.0
