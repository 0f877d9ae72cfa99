"""The pose channels: logs of today (each fusion scheme on POSE_<SCHEME>, the primary pose on POSE)
and logs from before the split (every scheme on POSE) read into the same POSE table and score alike.

A walk's poses are written both ways, with a controller (its pose, scheme 8, on POSE) and without
(POSE a copy of one scheme's pose, which the reader leaves out: its scheme's channel has it); both
readers (indexed and record by record) must give the old log's rows, and scoring the same numbers;
lcmindex and lcmdecode take a new log's pose channels together, vectorised.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import stridefix_channels
from numpy.testing import assert_array_equal
from stridefix import pose_t
from stridefix_analyzer.io.channels import CHANNELS, POSE_CHANNELS, POSE_SCHEME_CHANNELS, table_of
from stridefix_analyzer.io.lcmdecode import decode_columns
from stridefix_analyzer.io.lcmindex import index_file
from stridefix_analyzer.io.logread import read_logs, read_table
from stridefix_analyzer.scoring.metrics import run_metrics

EKF, PDR, CONTROLLER = pose_t.SCHEME_EKF, pose_t.SCHEME_PDR_ONLY, pose_t.SCHEME_CONTROLLER
#: the schemes of the synthetic walk: two fusion schemes and the controller following ekf
SCHEMES = (PDR, EKF)


def _outputs(msg, controller: bool):
    """Per output (10 of them, 1 s apart) the poses stridefixd writes: each scheme's, then the
    primary (the controller's, else a copy of ekf's); as (scheme, pose) in write order."""
    out = []
    for k in range(10):
        t = 1_000_000 * (k + 1)
        poses = {s: msg.pose(t, k + 0.25 * s, -k, step_count=k, scheme=s) for s in SCHEMES}
        out += [(s, poses[s]) for s in SCHEMES]
        out.append((CONTROLLER, msg.pose(t, k + 0.25 * EKF, -k, step_count=k, scheme=CONTROLLER)))
    return out if controller else [(s, p) for s, p in out if s != CONTROLLER]


def _old_log(write_log, msg, controller, truth):
    return write_log("old.lcmlog", [("POSE", p) for _, p in _outputs(msg, controller)] + truth)


def _new_log(write_log, msg, controller, truth):
    events = []
    for s, p in _outputs(msg, controller):
        events.append(("POSE" if s == CONTROLLER else POSE_SCHEME_CHANNELS[s], p))
        if not controller and s == EKF:  # stridefixd without a controller: the primary, ekf's copy
            events.append(("POSE", msg.pose(p.t_us, p.x_m, p.y_m, step_count=p.step_count, scheme=EKF)))
    return write_log("new.lcmlog", events + truth)


def _truth(msg):
    return [("TRUTH", msg.truth(500_000 * k, k / 2, -k / 2)) for k in range(2, 21)]


def test_channel_names_come_from_the_scheme_table():
    consts = {k[len("SCHEME_") :]: v for k, v in vars(pose_t).items() if k.startswith("SCHEME_")}
    assert POSE_SCHEME_CHANNELS == {v: f"POSE_{k}" for k, v in consts.items() if k != "CONTROLLER"}
    names = [c for c, _type, _writer in stridefix_channels.CHANNELS]
    assert set(POSE_CHANNELS) <= set(names) and names.count("POSE") == 1
    assert {table_of(c) for c in POSE_CHANNELS} == {"POSE"} and table_of("FIX") == "FIX"


@pytest.mark.parametrize("controller", [True, False], ids=["controller", "no-controller"])
@pytest.mark.parametrize("indexed", [True, False], ids=["indexed", "record-by-record"])
def test_new_log_reads_as_the_old_one(write_log, msg, controller, indexed):
    truth = _truth(msg)
    old = read_logs([_old_log(write_log, msg, controller, truth)], indexed=indexed)
    new = read_logs([_new_log(write_log, msg, controller, truth)], indexed=indexed)
    want, got = old.table("POSE"), new.table("POSE")
    assert len(want) == 10 * (len(SCHEMES) + controller)
    assert got.names == want.names
    for name in want.names:
        assert_array_equal(got[name], want[name], err_msg=name)
    # the channels are counted under their own names; the copies among them too
    assert new.messages["POSE_EKF"] == new.messages["POSE_PDR_ONLY"] == 10
    assert new.messages["POSE"] == 10 and old.messages["POSE"] == len(want)
    assert new.unknown_channels == {} and new.warnings == []
    # the primary: the new log says which scheme its POSE channel carried (the controller's pose,
    # else ekf's copy); the old one does not, and falls back to the controller, else equal counts
    # and pdr_only before ekf in the fallback order
    primary = CONTROLLER if controller else EKF
    assert new.pose_channel_scheme == primary and old.pose_channel_scheme is None
    m_old, m_new = run_metrics(old), run_metrics(new)
    assert (m_new.primary, m_new.primary_from) == (primary, "pose_channel")
    assert (m_old.primary, m_old.primary_from) == (CONTROLLER if controller else PDR, "fallback")
    # and scoring sees the same: the same schemes and, with the same primary, the same numbers
    m_old = run_metrics(old, scheme=primary)
    s_old, s_new = m_old.summary(), m_new.summary()
    assert s_old.pop("primary_from") == "requested" and s_new.pop("primary_from") == "pose_channel"
    # (as text: NaN, the heading error without truth headings, is not equal to itself)
    assert json.dumps(s_new, sort_keys=True) == json.dumps(s_old, sort_keys=True)
    series_old, series_new = m_old.series(), m_new.series()
    assert sorted(series_new) == sorted(series_old)
    for key, values in series_old.items():
        assert_array_equal(series_new[key], values, err_msg=key)


def test_old_log_keeps_every_pose(write_log, msg):
    """A log from before the split: all on POSE, nothing is a copy (no POSE_<SCHEME> channel)."""
    path = write_log("old.lcmlog", [("POSE", msg.pose(1_000, 1, 0, scheme=s)) for s in (PDR, EKF, EKF)])
    assert_array_equal(read_logs([path]).table("POSE")["scheme"], [PDR, EKF, EKF])


def test_a_copy_is_left_out_only_in_its_own_file(write_log, msg):
    """Copies are told by the file's own channels: a filtered new log (--channels FIX,POSE with one
    scheme) keeps its POSE rows, while merged with a full log of another run."""
    filtered = write_log("one.lcmlog", [("POSE", msg.pose(1_000, 1, 0, scheme=EKF))])
    full = write_log(
        "full.lcmlog",
        [("POSE_EKF", msg.pose(2_000, 2, 0, scheme=EKF)), ("POSE", msg.pose(2_000, 2, 0, scheme=EKF))],
    )
    for indexed in (True, False):
        pose = read_logs([filtered, full], indexed=indexed).table("POSE")
        assert_array_equal(pose["t_us"], [1_000, 2_000])


def test_decoding_one_pose_channel_decodes_them_all(write_log, msg):
    path = _new_log(write_log, msg, True, [])
    for channel in ("POSE", "POSE_EKF"):
        data = read_logs([path], decode=[channel])
        assert len(data.table("POSE")) == 30 and set(data.tables) == {"POSE"}
    assert len(read_table(path, "POSE_PDR_ONLY")) == 30  # the one POSE table


@pytest.mark.parametrize("controller", [True, False], ids=["controller", "no-controller"])
def test_index_and_vectorised_decode_of_the_pose_channels(write_log, msg, controller):
    """lcmindex finds each pose channel of a new log; lcmdecode decodes all their records at once
    (one type, one layout) into the columns the binding gives message by message, in log order."""
    path = _new_log(write_log, msg, controller, [])
    index = index_file(str(path))
    assert index is not None
    assert set(index.channels) == {"POSE", "POSE_PDR_ONLY", "POSE_EKF"}
    records = np.sort(np.concatenate([index.records_of(ch) for ch in index.channels]))
    assert len(records) == len(index) == 30
    spec = CHANNELS["POSE"]
    cols = decode_columns(
        spec.msg_type, spec.columns, index.data, index.payload_at[records], index.payload_len[records]
    )
    assert cols is not None  # the vectorised path, not the record-by-record fallback
    rows = [spec.row(pose_t.decode(index.payload(int(r)))) for r in records]
    for k, name in enumerate(spec.columns):
        assert_array_equal(cols[name], [row[k] for row in rows], err_msg=name)
