"""Which poses are a track: the primary pose of a log with every scheme on POSE (written before the
per-scheme channels) is the controller's; a scheme's track is its rows of the POSE table."""

from __future__ import annotations

import lcm
import pytest
from stridefix import pose_t
from stridefix_analyzer.export.tracks import TrackError, read_channels, read_tracks


def _pose(t_us: int, scheme: int, x_m: float) -> bytes:
    m = pose_t()
    m.t_us, m.scheme, m.x_m, m.y_m, m.floor = t_us, scheme, x_m, 0.0, 0
    return m.encode()


def _log(path, rows):
    log = lcm.EventLog(str(path), "w", overwrite=True)
    for t_us, channel, payload in rows:
        log.write_event(t_us, channel, payload)
    log.close()
    return path


def test_every_scheme_on_pose_the_primary_is_the_controllers(tmp_path):
    # GIVEN an older log: pdr_only and the controller both on POSE, out of time order
    path = _log(
        tmp_path / "old.lcmlog",
        [
            (1, "POSE", _pose(2_000_000, pose_t.SCHEME_PDR_ONLY, 1.0)),
            (2, "POSE", _pose(2_000_000, pose_t.SCHEME_CONTROLLER, 2.0)),
            (3, "POSE", _pose(1_000_000, pose_t.SCHEME_CONTROLLER, 3.0)),
            (4, "POSE", _pose(1_000_000, pose_t.SCHEME_PDR_ONLY, 4.0)),
        ],
    )
    (primary,) = read_tracks([path])
    assert (primary.name, primary.channel) == ("primary", "POSE")
    assert primary.poses["x_m"].tolist() == [3.0, 2.0]  # the controller's, by time
    (pdr,) = read_tracks([path], "pdr_only")
    assert pdr.poses["x_m"].tolist() == [4.0, 1.0]
    assert [t.name for t in read_tracks([path], "all")] == ["pdr_only", "controller"]
    with pytest.raises(TrackError, match="no pose of scheme ekf; the log has pdr_only, controller"):
        read_tracks([path], "ekf")


def test_without_the_controller_the_primary_needs_a_scheme_name(tmp_path):
    path = _log(tmp_path / "old.lcmlog", [(1, "POSE", _pose(1_000, pose_t.SCHEME_KALMAN, 1.0))])
    with pytest.raises(TrackError, match="--scheme NAME"):
        read_tracks([path])


def test_channels_stay_apart_and_count_every_message(tmp_path):
    path = _log(
        tmp_path / "new.lcmlog",
        [
            (1, "POSE_KALMAN", _pose(1_000, pose_t.SCHEME_KALMAN, 1.0)),
            (2, "POSE", _pose(1_000, pose_t.SCHEME_KALMAN, 1.0)),  # the primary: a copy of kalman's
            (3, "POSE", b"\x00garbage"),
            (4, "NOT_OURS", b"x"),
        ],
    )
    read = read_channels([path], ["POSE", "POSE_KALMAN"])
    assert {ch: len(t) for ch, t in read.tables.items()} == {"POSE": 1, "POSE_KALMAN": 1}
    assert read.counts == {"POSE_KALMAN": 1, "POSE": 2, "NOT_OURS": 1}
    assert read.decode_errors == {"POSE": 1}
    (primary,) = read_tracks([path])
    assert len(primary) == 1 and primary.poses["scheme"].tolist() == [pose_t.SCHEME_KALMAN]
