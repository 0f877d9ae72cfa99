"""logread: decoding, merging, counting bad data, truncated and missing files."""

import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from stridefix import wifi_scan_t
from stridefix_analyzer.io.lcmfile import NotALogError, require_records
from stridefix_analyzer.io.logread import LogReadError, LogTruncatedWarning, read_logs, read_table


def test_columns_and_sorting(msg, write_log):
    # poses written out of time order come back sorted by t_us
    path = write_log(
        "a.lcmlog",
        [
            ("POSE", msg.pose(3_000, 3, 0, step_count=3)),
            ("POSE", msg.pose(1_000, 1, 0, step_count=1)),
            ("STEP", msg.step(1_000, 1, 0.7)),
            ("TRUTH", msg.truth(2_000, 2, 5, floor=1, step_count=2)),
        ],
    )
    d = read_logs([path])
    pose = d.table("POSE")
    assert pose.names == [
        "t_us",
        "x_m",
        "y_m",
        "floor",
        "heading_rad",
        "sigma_m",
        "cov_xx_m2",
        "cov_xy_m2",
        "cov_yy_m2",
        "heading_bias_rad",
        "stride_scale",
        "ess",
        "step_count",
        "scheme",
    ]
    assert_array_equal(pose["t_us"], [1_000, 3_000])
    assert_allclose(pose["x_m"], [1.0, 3.0])
    assert pose["t_us"].dtype == np.int64
    truth = d.table("TRUTH")
    assert truth["floor"][0] == 1 and truth["step_count"][0] == 2
    assert_allclose(d.table("STEP")["length_m"], [0.7], rtol=1e-6)  # float32 on the wire
    assert d.messages == {"POSE": 2, "STEP": 1, "TRUTH": 1}
    assert d.warnings == []


def test_merges_firmware_and_truth_logs(msg, write_log):
    fw = write_log("fw.lcmlog", [("POSE", msg.pose(t, t / 1e6, 0)) for t in (0, 2_000_000)])
    sim = write_log(
        "sim.lcmlog",
        [("TRUTH", msg.truth(t, t / 1e6, 0)) for t in (1_000_000,)] + [("POSE", msg.pose(1_000_000, 1, 0))],
    )
    d = read_logs([fw, sim])
    assert_array_equal(d.table("POSE")["t_us"], [0, 1_000_000, 2_000_000])
    assert len(d.table("TRUTH")) == 1
    assert [i["events"] for i in d.inputs] == [2, 2]


def test_unknown_channel_and_decode_error_are_counted(msg, write_log):
    path = write_log(
        "bad.lcmlog",
        [
            ("POSE", msg.pose(1, 0, 0)),
            ("POSE", msg.truth(2, 0, 0)),  # wrong type on POSE
            ("TRUTH", b"\x00garbage"),  # not a message at all
            ("CAMERA", b"\x01\x02"),
            ("CAMERA", b"\x01\x02"),
        ],
    )
    d = read_logs([path])
    assert len(d.table("POSE")) == 1
    assert d.table("TRUTH") is None
    assert d.decode_errors == {"POSE": 1, "TRUTH": 1}
    assert d.unknown_channels == {"CAMERA": 2}
    assert d.type_mismatches == {}  # one odd payload each: corruption, not a type version
    assert d.messages == {"POSE": 2, "TRUTH": 1, "CAMERA": 2}
    assert any("POSE" in w and "decode" in w for w in d.warnings)


def test_another_type_version_is_told_apart_from_corruption(msg, write_log):
    # regression: a stale stridefixd wrote FIX with an older fix_t; realbench read "no FIX" silently
    path = write_log(
        "stale.lcmlog", [("POSE", msg.truth(i, 0, 0)) for i in range(3)] + [("POSE", msg.pose(9, 0, 0))]
    )
    d = read_logs([path])
    assert d.decode_errors == {"POSE": 3} and d.type_mismatches == {"POSE": 3}
    assert any("another LCM type hash" in w and "POSE" in w for w in d.warnings)
    with pytest.raises(LogReadError, match="POSE.*another LCM type hash"):
        read_table(path, "POSE")


def test_truncated_log_reads_whole_records(msg, write_log, tmp_path):
    path = write_log("full.lcmlog", [("POSE", msg.pose(i * 1000, i, 0)) for i in range(10)])
    data = path.read_bytes()
    cut = tmp_path / "cut.lcmlog"
    cut.write_bytes(data[:-7])  # lose the tail of the last record
    with pytest.warns(LogTruncatedWarning, match="cut.lcmlog"):
        d = read_logs([cut])
    assert_array_equal(d.table("POSE")["t_us"], np.arange(9) * 1000)
    assert d.inputs[0]["truncated_bytes"] > 0
    assert any("truncated" in w for w in d.warnings)


def test_log_cut_inside_first_record_is_empty_not_an_error(msg, write_log, tmp_path):
    path = write_log("one.lcmlog", [("POSE", msg.pose(0, 0, 0))])
    cut = tmp_path / "stub.lcmlog"
    cut.write_bytes(path.read_bytes()[:10])
    with pytest.warns(LogTruncatedWarning):
        d = read_logs([cut])
    assert d.tables == {} and d.inputs[0]["events"] == 0


@pytest.mark.parametrize("keep", [0, 10, 40])
def test_a_command_input_without_one_whole_record_is_nothing_valid(msg, write_log, tmp_path, keep):
    """Regression: `analyze` or `radiomap build` of an empty log, or one cut inside its first record,
    exited 2 (a channel missing); such an input holds nothing valid: require_records raises
    NotALogError (exit 3) naming the file. The reader still takes it as empty (a replay that wrote
    nothing)."""
    path = write_log("one.lcmlog", [("POSE", msg.pose(0, 0, 0)), ("POSE", msg.pose(1, 0, 0))])
    cut = tmp_path / "stub.lcmlog"
    cut.write_bytes(path.read_bytes()[:keep])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LogTruncatedWarning)
        data = read_logs([path, cut])
    with pytest.raises(NotALogError, match=f"stub.lcmlog: nothing valid in the input.*\\({keep} bytes"):
        require_records(data.inputs)
    require_records(data.inputs[:1])  # the whole log passes


def test_missing_file_names_it(tmp_path):
    missing = tmp_path / "nowhere.lcmlog"
    with pytest.raises(LogReadError, match="nowhere.lcmlog"):
        read_logs([missing])


@pytest.mark.parametrize("content", [b"this is not an LCM log at all", b"\x00" * 64])
def test_not_a_log_names_it(tmp_path, content):
    path = tmp_path / "junk.bin"
    path.write_bytes(content)
    with pytest.raises(LogReadError, match="junk.bin"):
        read_logs([path])


def test_directory_is_rejected(tmp_path):
    with pytest.raises(LogReadError, match="not a regular file"):
        read_logs([tmp_path])


def test_health_config_and_wifi(msg, write_log):
    scan = wifi_scan_t()
    scan.t_us, scan.scan_id, scan.complete, scan.n_ap = 5, 7, True, 2
    scan.bssid, scan.rssi_dbm, scan.freq_mhz = [0xAABBCCDDEEFF, 1], [-60.0, -72.5], [2412, 5180]
    path = write_log(
        "h.lcmlog",
        [
            ("CONFIG", msg.config({"fusion.mode": "adaptive", "step.threshold": "1.2"})),
            ("HEALTH", msg.health(1_000, 10)),
            ("HEALTH", msg.health(2_000, 25)),
            ("WIFI", scan),
        ],
    )
    d = read_logs([path])
    assert d.health["frames_total"] == 25 and d.health["t_us"] == 2_000
    assert_allclose(d.health["loop_max_us"], 80.0)
    assert d.config == {"fusion.mode": "adaptive", "step.threshold": "1.2"}
    assert d.versions["version"] == "0.1.0-test"
    assert len(d.table("HEALTH")) == 2
    ap = d.table("WIFI_AP")
    assert_array_equal(ap["bssid"], [0xAABBCCDDEEFF, 1])
    assert_allclose(ap["rssi_dbm"], [-60.0, -72.5])
    assert_array_equal(ap["scan_row"], [0, 0])
    assert d.table("WIFI")["n_ap"][0] == 2


def test_decode_subset_only_counts_the_rest(msg, write_log):
    path = write_log("s.lcmlog", [("POSE", msg.pose(1, 0, 0)), ("STEP", msg.step(1, 1))])
    d = read_logs([path], decode=["POSE"])
    assert d.table("STEP") is None and d.messages["STEP"] == 1


def test_garbage_between_records_is_skipped_and_reported(write_log, tmp_path, msg):
    a = write_log("a.lcmlog", [("POSE", msg.pose(1, 1, 0))]).read_bytes()
    b = write_log("b.lcmlog", [("POSE", msg.pose(2, 2, 0))]).read_bytes()
    spliced = tmp_path / "spliced.lcmlog"
    spliced.write_bytes(a + b"\x55" * 13 + b)  # 13 junk bytes between two whole records
    with pytest.warns(LogTruncatedWarning, match="13 byte"):
        d = read_logs([spliced])
    assert_array_equal(d.table("POSE")["t_us"], [1, 2])
    assert d.inputs[0]["skipped_bytes"] == 13 and d.inputs[0]["truncated_bytes"] == 0


@pytest.mark.parametrize("junk", [b"\x00" * 5, b"\x00" * 4096, b"\xed\xa1"])
def test_junk_after_last_record_keeps_it(write_log, tmp_path, msg, junk):
    # LCM 1.5's reader drops the last whole record when non-record bytes follow it (e.g. the
    # zero-filled tail a power cut can leave); the analyzer must still return all three records.
    path = write_log("z.lcmlog", [("POSE", msg.pose(i, i, 0)) for i in range(3)])
    tail = tmp_path / "tail.lcmlog"
    tail.write_bytes(path.read_bytes() + junk)
    with pytest.warns(LogTruncatedWarning):
        d = read_logs([tail])
    assert_array_equal(d.table("POSE")["t_us"], [0, 1, 2])
    info = d.inputs[0]
    assert info["truncated_bytes"] + info["skipped_bytes"] == len(junk)


def test_several_corrupt_regions_lose_no_whole_record(write_log, tmp_path, msg):
    records = [write_log(f"r{i}.lcmlog", [("POSE", msg.pose(i, i, 0))]).read_bytes() for i in range(8)]
    junk = [b"", b"\x00" * 3, b"\xed\xa1\xda\x01garbage", b"", b"\xff" * 100, b"", b"\x01", b""]
    path = tmp_path / "patchy.lcmlog"
    path.write_bytes(b"".join(r + j for r, j in zip(records, junk)) + records[0][:20])
    with pytest.warns(LogTruncatedWarning):
        d = read_logs([path])
    assert_array_equal(d.table("POSE")["t_us"], np.arange(8))
    info = d.inputs[0]
    assert info["skipped_bytes"] == sum(map(len, junk[:-1])) and info["truncated_bytes"] == 20


def _fix(t_us, scheme, accepted):
    from stridefix import fix_t

    m = fix_t()
    m.t_us, m.method, m.scheme, m.x_m, m.y_m, m.floor = t_us, fix_t.METHOD_WIFI, scheme, 1.5, -2.0, 1
    m.accuracy_m, m.n_ap_used, m.innovation_m = 3.0, 7, [0.25, -0.5]
    m.innovation_var_m2, m.test_ratio, m.alpha, m.accepted = 4.0, 0.5, 0.75 if accepted else 0.0, accepted
    m.reason = fix_t.REASON_ACCEPTED if accepted else fix_t.REASON_GATE
    m.reason_text = "accepted" if accepted else "gate"
    return m


def test_fix_keeps_the_scheme_of_each_audit_record(write_log):
    # Regression: the FIX table dropped the audit record's `scheme`, so every scheme's verdicts on one
    # Wi-Fi fix were indistinguishable. Every scheme judges every fix: two records per scan here.
    from stridefix import pose_t

    path = write_log(
        "fix.lcmlog",
        [
            ("FIX", _fix(1_000, pose_t.SCHEME_KALMAN, True)),
            ("FIX", _fix(1_000, pose_t.SCHEME_WIFI_ONLY, False)),
        ],
    )
    fix = read_logs([path]).table("FIX")
    assert_array_equal(fix["scheme"], [pose_t.SCHEME_KALMAN, pose_t.SCHEME_WIFI_ONLY])
    assert fix["scheme"].dtype == np.int64
    assert_array_equal(fix["accepted"], [True, False])
    assert_allclose(fix["innovation_x_m"], [0.25, 0.25])
    assert_allclose(fix["innovation_y_m"], [-0.5, -0.5])
    assert list(fix["reason_text"]) == ["accepted", "gate"]


def test_fix_columns_are_the_fields_of_fix_t():
    # New fix_t fields (e.g. accuracy_factor, drift) must appear without an edit to the reader.
    from stridefix import fix_t
    from stridefix_analyzer.io.channels import CHANNELS

    expected = []
    for field in fix_t.__slots__:
        if field == "innovation_m":
            expected += ["innovation_x_m", "innovation_y_m"]
        else:
            expected.append(field)
    assert CHANNELS["FIX"].names == expected
    assert {"t_us", "method", "scheme", "x_m", "accepted", "reason", "reason_text"} <= set(expected)


def test_log_read_error_crosses_processes():
    """realbench's workers raise it; the pool pickles it back to the parent whole."""
    import pickle

    err = pickle.loads(pickle.dumps(LogReadError("walk.lcmlog", "not an LCM event log")))
    assert isinstance(err, LogReadError)
    assert (err.path, err.reason, str(err)) == (
        "walk.lcmlog",
        "not an LCM event log",
        "walk.lcmlog: not an LCM event log",
    )
