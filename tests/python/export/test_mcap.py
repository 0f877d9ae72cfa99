"""`stridefix export --format mcap`: read back with mcap's own reader, every pose, step and fix of the
log is one message on the topic of its channel, in Foxglove's schemas, and the floor plan is there."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from mcap.reader import make_reader
from numpy.testing import assert_allclose
from stridefix_analyzer.io.logread import read_logs
from stridefix_analyzer.io.sitefile import read_site, write_site


@pytest.fixture(scope="module")
def mcap_file(cli, geo_walk, tmp_path_factory):
    out = tmp_path_factory.mktemp("mcap") / "walk.mcap"
    proc = cli("export", str(geo_walk["log"]), "--site", str(geo_walk["site"]), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    return out


def _read(path):
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        counts = summary.statistics.channel_message_counts
        topics = {
            ch.topic: (summary.schemas[ch.schema_id].name, counts.get(cid, 0))
            for cid, ch in summary.channels.items()
        }
        messages = {}
        for _schema, channel, message in reader.iter_messages(log_time_order=False):
            messages.setdefault(channel.topic, []).append((message.log_time, json.loads(message.data)))
    return topics, messages


def test_every_message_of_the_log_is_on_its_channels_topic(mcap_file, geo_walk):
    topics, _ = _read(mcap_file)
    logged = read_logs([geo_walk["log"]], decode=[]).messages
    wanted = [ch for ch in logged if ch.startswith("POSE") or ch in ("STEP", "FIX", "CONTEXT")]
    assert len(wanted) == 11  # POSE, 8 × POSE_<SCHEME>, STEP, FIX
    assert {ch: topics[ch][1] for ch in wanted} == {ch: logged[ch] for ch in wanted}
    # Foxglove's schema names (its panels pick a topic by them), the LCM type's name for the others
    assert {topics[ch][0] for ch in wanted if ch.startswith("POSE")} == {"foxglove.PoseInFrame"}
    assert {topics[ch + "/location"] for ch in wanted if ch.startswith("POSE")} == {
        ("foxglove.LocationFix", logged["POSE"])
    }
    assert topics["STEP"][0] == "stridefix.step_t" and topics["FIX"][0] == "stridefix.fix_t"
    assert topics["/floorplan"] == ("foxglove.SceneUpdate", 1)


def test_poses_and_the_floor_plan_are_in_the_map_frame(mcap_file, geo_walk, logged_poses):
    _, messages = _read(mcap_file)
    poses = logged_poses["POSE_KALMAN"]
    got = messages["POSE_KALMAN"]
    assert [t for t, _ in got] == [m.t_us * 1000 for m in poses]  # log time = board time [ns]
    assert_allclose([b["pose"]["position"]["x"] for _, b in got], [m.x_m for m in poses])
    assert_allclose([b["pose"]["position"]["z"] for _, b in got], [3.5 * m.floor for m in poses])
    # heading counter-clockwise from +x: the quaternion's yaw
    q = got[-1][1]["pose"]["orientation"]
    yaw = 2 * math.atan2(q["z"], q["w"])
    assert abs(math.remainder(yaw - poses[-1].heading_rad, math.tau)) < 1e-6
    site = read_site(geo_walk["site"])
    ((_, plan),) = messages["/floorplan"]
    assert sorted(e["id"] for e in plan["entities"]) == ["floor 0", "floor 1"]
    points = sum(len(line["points"]) for e in plan["entities"] for line in e["lines"])
    assert points == 2 * site.n_walls == 228
    # STEP carries every column of the analyzer's STEP table
    table = read_logs([geo_walk["log"]], decode=["STEP"]).table("STEP")
    steps = [b for _, b in messages["STEP"]]
    assert set(table.names) | {"timestamp"} == set(steps[0])
    assert [b["index"] for b in steps] == table["index"].tolist()
    assert_allclose([b["length_m"] for b in steps], table["length_m"])


def test_a_site_without_geo_reference_gives_map_frame_topics_only(cli, geo_walk, tmp_path):
    site = read_site(geo_walk["site"])
    site.has_geo = False
    write_site(tmp_path / "nogeo.sfsite", site)
    out = tmp_path / "walk.mcap"
    proc = cli("export", str(geo_walk["log"]), "--site", str(tmp_path / "nogeo.sfsite"), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    topics, _ = _read(out)
    assert not any(t.endswith("/location") for t in topics)
    assert topics["POSE"][0] == "foxglove.PoseInFrame"


def test_location_covariance_is_the_map_covariance_turned_into_east_north(mcap_file, logged_poses):
    # the ekf's covariance is not isotropic, so the 20° rotation shows: C_en = R C_map Rᵀ
    _, messages = _read(mcap_file)
    theta = np.radians(20.0)
    rot = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])  # map -> east-north
    poses, fixes = logged_poses["POSE_EKF"], [b for _, b in messages["POSE_EKF/location"]]
    assert len(fixes) == len(poses)
    checked = 0
    for m, fix in zip(poses[::200], fixes[::200]):
        c_map = np.array([[m.cov_xx_m2, m.cov_xy_m2], [m.cov_xy_m2, m.cov_yy_m2]], dtype=np.float64)
        c_en = rot @ c_map @ rot.T
        cov = np.array(fix["position_covariance"]).reshape(3, 3)
        assert_allclose(cov[:2, :2], c_en, rtol=1e-9, atol=1e-12)
        checked += abs(m.cov_xy_m2) > 1e-6 or abs(m.cov_xx_m2 - m.cov_yy_m2) > 1e-6
    assert checked > 0  # at least one anisotropic covariance was compared
