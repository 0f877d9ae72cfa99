"""lcmindex: an intact log's records located with numpy; anything else is left to the
record-by-record reader, so both readers always give the same LogData."""

import numpy as np
import pytest
from stridefix_analyzer.io.lcmindex import index_file
from stridefix_analyzer.io.logread import read_logs

SYNC = bytes.fromhex("EDA1DA01")


def test_index_finds_every_record_in_first_record_order(msg, write_log):
    events = [("CONFIG", msg.config({"a": "1"}))]
    events += [(("POSE", "TRUTH", "STEP")[i % 3], msg.pose(i, i, 0)) for i in range(30)]
    events += [("CAMERA", b"\x01\x02\x03")]
    path = write_log("a.lcmlog", events)
    index = index_file(str(path))
    assert index is not None and len(index) == 32
    assert index.counts() == {"CONFIG": 1, "POSE": 10, "TRUTH": 10, "STEP": 10, "CAMERA": 1}
    assert [index.payload(int(r)) for r in index.records_of("TRUTH")] == [
        m.encode() for ch, m in events if ch == "TRUTH"
    ]
    assert index.payload(31) == b"\x01\x02\x03"
    assert len(index.records_of("IMU")) == 0
    assert len(index.data) == path.stat().st_size


def test_a_sync_word_inside_a_payload_is_no_record(msg, write_log, assert_reads_alike):
    # a payload may hold the sync word by chance (float bytes): it breaks the chain, so the file is
    # read record by record, which knows where each record ends
    path = write_log("sync.lcmlog", [("POSE", msg.pose(1, 0, 0)), ("CAMERA", b"xx" + SYNC + b"\x00" * 40)])
    assert index_file(str(path)) is None
    d = assert_reads_alike([path])
    assert d.messages == {"POSE": 1, "CAMERA": 1} and d.warnings == []


@pytest.mark.parametrize(
    "damage",
    [
        lambda b: b[:-5],  # the last record cut short
        lambda b: b + b"\x00" * 9,  # junk after the last record
        lambda b: b[:60] + b"junk" + b[60:],  # junk inside a record
        lambda b: b"junk" + b,  # junk before the first record
        lambda b: b[:10],  # shorter than one header
    ],
)
def test_a_damaged_log_is_left_to_the_salvaging_reader(msg, write_log, tmp_path, damage, assert_reads_alike):
    clean = write_log("clean.lcmlog", [("POSE", msg.pose(i * 1000, i, 0)) for i in range(5)])
    path = tmp_path / "damaged.lcmlog"
    path.write_bytes(damage(clean.read_bytes()))
    assert index_file(str(path)) is None
    with pytest.warns(UserWarning):
        assert_reads_alike([path])


def test_channel_names_alike_in_their_first_8_bytes(msg, write_log, assert_reads_alike):
    # told apart only by bytes past the 8 the index compares at once: left to the record reader
    path = write_log(
        "long.lcmlog", [("CAMERA_LEFT", b"\x01"), ("CAMERA_LEFX", b"\x02"), ("POSE", msg.pose(1, 0, 0))]
    )
    assert index_file(str(path)) is None
    assert assert_reads_alike([path]).unknown_channels == {"CAMERA_LEFT": 1, "CAMERA_LEFX": 1}
    same = write_log("same.lcmlog", [("CAMERA_LEFT", b"\x01"), ("CAMERA_LEFT", b"\x02")])
    assert index_file(str(same)).counts() == {"CAMERA_LEFT": 2}


def test_decode_errors_keep_their_log_order_across_channels(msg, write_log, assert_reads_alike):
    # metrics.json lists decode_errors in the order they were met: the channels decoded message by
    # message are walked in log order, not channel by channel
    path = write_log(
        "errors.lcmlog",
        [
            ("STEP", msg.step(1, 1)),
            ("POSE", msg.pose(2, 0, 0)),
            ("POSE", msg.truth(3, 0, 0)),  # the first error
            ("STEP", b"\x00garbage"),
            ("WIFI", b"\x00garbage"),
            ("CONFIG", msg.config({"a": "1"})),
            ("CONFIG", msg.config({"a": "2"})),  # a conflict: a warning in log order
        ],
    )
    d = assert_reads_alike([path])
    assert list(d.decode_errors) == ["POSE", "STEP", "WIFI"]
    assert d.config == {"a": "2"} and len(d.tables["STEP"]) == 1


def test_several_files_merge_as_record_by_record(msg, write_log, assert_reads_alike):
    fw = write_log("fw.lcmlog", [("POSE", msg.pose(t, t, 0)) for t in (5, 1, 3)] + [("CAMERA", b"\x01")])
    sim = write_log(
        "sim.lcmlog", [("TRUTH", msg.truth(t, t, 0)) for t in (2, 4)] + [("POSE", msg.pose(2, 9, 0))]
    )
    d = assert_reads_alike([fw, sim])
    np.testing.assert_array_equal(d.table("POSE")["t_us"], [1, 2, 3, 5])
    assert [i["events"] for i in d.inputs] == [4, 3]
    assert_reads_alike([fw, sim], decode=("POSE",))


def test_an_empty_file_reads_as_before(tmp_path, assert_reads_alike):
    path = tmp_path / "empty.lcmlog"
    path.write_bytes(b"")
    assert index_file(str(path)) is None
    d = assert_reads_alike([path])
    assert d.inputs[0]["events"] == 0 and d.tables == {}


def test_indexed_read_is_the_default(msg, write_log):
    path = write_log("a.lcmlog", [("POSE", msg.pose(1, 0, 0))])
    assert len(read_logs([path]).table("POSE")) == 1
