"""The GetSensorData (IPIN Track 3) importer: handmade excerpt with known content, and one real log."""

from __future__ import annotations

import json
import math
import warnings

import lcm
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix import baro_t, gnss_t, imu_t, truth_t, wifi_scan_t
from stridefix_analyzer.datasets import gsd, gsd_convert, gsd_parse
from stridefix_analyzer.datasets.lines import MalformedLineWarning
from stridefix_analyzer.io.logread import read_logs


def _import(path, tmp_path, **kw):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        summary = gsd.DATASET.import_walk(path, tmp_path / "out.lcmlog", **kw)
    return summary, [str(w.message) for w in caught if w.category is MalformedLineWarning]


def _events(tmp_path, channel, decoder):
    return [
        decoder.decode(e.data)
        for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r")
        if e.channel == channel
    ]


def test_handmade_counts_and_summary(gsd_log, tmp_path):
    s, _ = _import(gsd_log, tmp_path)
    assert s["messages"] == {"IMU": 3, "MAG": 2, "BARO": 2, "GNSS": 2, "WIFI": 2, "BLE": 0, "TRUTH": 3}
    assert s["events"] == 3 + 2 + 2 + 2 + 2 + 3
    assert s["skipped_lines"] == 3
    assert s["ignored_lines_by_type"] == {"AHRS": 1, "LIGH": 1}
    assert s["building_id"] == "100" and s["floors"] == [-1, 0]
    assert s["origin"] == {"lat_deg": 49.46, "lon_deg": 11.11, "source": "first POSI"}
    assert s["pressure_unit"] == "mbar"
    assert s["device"] == {"Model": "SM-TEST"}
    assert s["gnss_repeats_dropped"] == 1
    assert s["wifi_aps_written"] == 4
    assert s["wifi_aps_stale_dropped"] == 1 and s["wifi_aps_duplicate_dropped"] == 1
    assert s["clock_offset_s"] == pytest.approx(-4998.999, abs=1e-9)
    assert s["t_start_us"] == 1_001_000 and s["t_end_us"] == 9_000_000  # first ACCE .. last POSI
    assert s["duration_s"] == pytest.approx(7.999)
    json.dumps(s)  # JSON-ready


def test_handmade_malformed_lines_warn_with_file_and_line(gsd_log, tmp_path):
    s, warned = _import(gsd_log, tmp_path)
    assert [d["line"] for d in s["skipped"]] == [10, 14, 26]
    assert len(warned) == 3
    for line_no, text in zip([10, 14, 26], warned):
        assert f"{gsd_log}:{line_no}:" in text
    assert "ACCE with 5 fields, expected 7" in warned[0]
    assert "GYRO" in warned[1]
    assert "unknown record type" in warned[2]


def test_handmade_imu_timed_by_sensor_timestamps(gsd_log, tmp_path):
    _import(gsd_log, tmp_path)
    imu = read_logs([tmp_path / "out.lcmlog"]).table("IMU")
    # SensorTimestamp 5000.000/.020/.040 + offset -4998.999 (not the first ACCE's AppTimestamp 1.015)
    assert imu["t_us"].tolist() == [1_001_000, 1_021_000, 1_041_000]
    assert imu["seq"].tolist() == [0, 1, 2]
    assert_allclose(imu["accel_x_mps2"], [0.1, 0.3, 0.5], atol=1e-12)
    assert_allclose(imu["accel_z_mps2"], [9.8, 9.6, 9.4], atol=1e-12)
    # gyro x: 0 at 1.001 s, 0.3 at 1.031 s, 0.5 at 1.051 s -> 0, 0.2, 0.4 at the accel times
    assert_allclose(imu["gyro_x_radps"], [0.0, 0.2, 0.4], atol=1e-9)
    assert_allclose(imu["gyro_y_radps"], [-0.1, -0.1, -0.1], atol=1e-12)
    mag = read_logs([tmp_path / "out.lcmlog"]).table("MAG")
    assert mag["t_us"].tolist() == [1_011_000, 1_031_000]
    assert_allclose(mag["field_y_ut"], [20.0, 21.0])


def test_handmade_pressure_in_pa_and_gnss(gsd_log, tmp_path):
    _import(gsd_log, tmp_path)
    baro = _events(tmp_path, "BARO", baro_t)
    assert [m.t_us for m in baro] == [1_100_000, 1_300_000]
    assert [m.pressure_pa for m in baro] == pytest.approx([101325.0, 100000.0])  # mbar x 100
    assert all(math.isnan(m.temperature_degc) for m in baro)
    fixes = _events(tmp_path, "GNSS", gnss_t)
    assert [m.t_us for m in fixes] == [1_500_000, 2_500_000]
    assert [(m.lat_deg, m.lon_deg, m.alt_m) for m in fixes] == [
        (49.461269, 11.111049, 346.0),
        (49.461268, 11.111051, 347.5),
    ]
    assert [m.accuracy_m for m in fixes] == [9.0, 12.0]


def test_handmade_wifi_grouped_cached_dropped(gsd_log, tmp_path):
    _import(gsd_log, tmp_path)
    scans = _events(tmp_path, "WIFI", wifi_scan_t)
    assert [m.t_us for m in scans] == [2_000_000, 6_000_000]
    assert [m.scan_id for m in scans] == [0, 1]
    first, second = scans
    # 2.000 s + 2.004 s records: one scan; 20:23:..:45, last seen 2.5 s before it, is cached
    assert first.n_ap == 2
    assert dict(zip(first.bssid, zip(first.rssi_dbm, first.freq_mhz))) == {
        0x202300000001: (-60.0, 2437),
        0x202300000015: (-71.0, 5180),
    }
    # 20:23:..:01 twice: the fresher entry (-62 dBm, last seen 9 ms before) kept;
    # 20:23:..:82 has the SSID "we;got;semicolons" and a trailing ';'
    assert dict(zip(second.bssid, zip(second.rssi_dbm, second.freq_mhz))) == {
        0x202300000001: (-62.0, 2437),
        0x202300000082: (-64.0, 2462),
    }


@pytest.mark.parametrize("max_age_s, n_first_scan", [(2.0, 2), (3.0, 3), (0.015, 1)])
def test_wifi_age_limit_is_a_parameter(gsd_log, max_age_s, n_first_scan):
    with pytest.warns(MalformedLineWarning, match="3 in all"):
        log = gsd.DATASET.read(gsd_log, max_wifi_age_s=max_age_s, max_line_warnings=0)
    assert len(log.scan(0)["bssid"]) == n_first_scan


def test_handmade_posi_to_local_metres(gsd_log, tmp_path):
    _import(gsd_log, tmp_path)
    events = list(lcm.EventLog(str(tmp_path / "out.lcmlog"), "r"))
    assert [e.timestamp for e in events] == sorted(e.timestamp for e in events)
    truth = [truth_t.decode(e.data) for e in events if e.channel == "TRUTH"]
    assert [m.t_us for m in truth] == [3_000_000, 6_000_000, 9_000_000]  # time order
    assert [m.floor for m in truth] == [0, 0, -1]
    # Hand computation, origin φ0 = 49.46°, λ0 = 11.11° (the first POSI); WGS-84 a = 6378137 m,
    # e² = 0.00669437999014; sin²φ0 = 0.5775276, w = 1 − e²·sin²φ0 = 0.9961338;
    # N = a/√w = 6 390 502.4 m, M = a(1 − e²)/w^1.5 = 6 372 358.7 m; 0.0001° = 1.7453293e-6 rad.
    #   y = M·Δφ = 11.1219 m north   (a sphere of 6371 km would give 11.1195 m)
    #   x = N·cos φ0·Δλ = 6 390 502.4 · 0.6499788 · 1.7453293e-6 = 7.2496 m east (= 11.1·cos 49.46°)
    xy = [(m.x_m, m.y_m) for m in truth]
    assert_allclose(xy, [(0.0, 0.0), (0.0, 11.1219), (7.2496, 11.1219)], atol=1e-3)
    assert all(
        math.isnan(m.heading_rad) and m.step_count == -1 and m.source == truth_t.SOURCE_WAYPOINT
        for m in truth
    )
    for e in events:
        if e.channel == "IMU":
            assert imu_t.decode(e.data).t_us == e.timestamp


def test_origin_option_shifts_the_frame(gsd_log, tmp_path):
    # origin 0.0001° south and west of the first POSI: every point moves by (+7.2496, +11.1219) m
    # (the radii at 49.4599° differ from those at 49.46° by < 1e-6 relative)
    s, _ = _import(gsd_log, tmp_path, origin=(49.4599, 11.1099))
    assert s["origin"] == {"lat_deg": 49.4599, "lon_deg": 11.1099, "source": "option"}
    truth = _events(tmp_path, "TRUTH", truth_t)
    assert_allclose(
        [(m.x_m, m.y_m) for m in truth], [(7.2496, 11.1219), (7.2496, 22.2438), (14.4991, 22.2438)], atol=2e-3
    )


def test_project_and_parse_origin():
    x, y = gsd_convert.project([49.46, 49.4601], [11.11, 11.11], 49.46, 11.11)
    assert_allclose(y, [0.0, 11.1219], atol=1e-4) and x.tolist() == [0.0, 0.0]
    assert gsd_convert.parse_origin("49.46, 11.11") == (49.46, 11.11)
    for bad in ("49.46", "91,0", "a,b"):
        with pytest.raises(ValueError):
            gsd_convert.parse_origin(bad)


@pytest.mark.parametrize("unit, pa", [("hPa", 101325.0), ("kPa", 1013250.0), ("Pa", 1013.25)])
def test_pressure_unit_from_header(tmp_path, unit, pa):
    path = tmp_path / "p.txt"
    path.write_text(
        f"% Pressure data: 'PRES;AppTimestamp(s);SensorTimestamp(s);Pres({unit});Acc'\n"
        "PRES;1.0;5.0;1013.25;3\n",
        encoding="utf-8",
    )
    assert gsd.DATASET.read(path).baro["pressure_pa"].tolist() == pytest.approx([pa])


def test_unknown_pressure_unit_raises_naming_file_and_line(tmp_path):
    path = tmp_path / "psi.txt"
    path.write_text(
        "% x\n% Pressure data: 'PRES;AppTimestamp(s);SensorTimestamp(s);Pres(psi);A'\n", encoding="utf-8"
    )
    with pytest.raises(gsd_parse.LogHeaderError, match=r"psi.txt: line 2: pressure unit 'psi'"):
        gsd.DATASET.read(path)


def test_import_walk_takes_the_protocol_options(gsd_log, tmp_path):
    # the options every data set reads (was the import_trace alias of msindoor's signature)
    with pytest.warns(MalformedLineWarning):
        s = gsd.DATASET.import_walk(gsd_log, tmp_path / "a.lcmlog", max_wifi_age_s=3.0)
    assert s["wifi_aps_written"] == 5 and s["max_wifi_age_s"] == 3.0


def test_missing_file_raises_naming_it(tmp_path):
    with pytest.raises(gsd_parse.LogReadError, match="nope.txt: no such file"):
        gsd.DATASET.read(tmp_path / "nope.txt")


def test_many_malformed_lines_are_summed_up(tmp_path):
    path = tmp_path / "junk.txt"
    path.write_text("ACCE;1;2;x;y;z;3\n" * 50, encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        log = gsd.DATASET.read(path)
    assert len(log.skipped) == 50
    assert len(caught) == gsd_parse.MAX_LINE_WARNINGS + 1
    assert "30 more malformed line(s)" in str(caught[-1].message)


# --- CLI -----------------------------------------------------------------------------------------


def test_cli_output_file_and_dir(gsd_log, tmp_path, cli):
    one = tmp_path / "walk.lcmlog"
    proc = cli("import", "gsd", str(gsd_log), "-o", str(one), "--json", str(tmp_path / "s.json"))
    assert proc.returncode == 0, proc.stderr
    assert one.is_file()
    line = json.loads(proc.stdout.splitlines()[0])
    assert line["messages"]["TRUTH"] == 3 and line["building_id"] == "100"
    assert line["origin"]["source"] == "first POSI"
    assert "origin 49.460000000,11.110000000 (first POSI)" in proc.stderr
    assert f"{gsd_log}:10:" in proc.stderr
    assert json.loads((tmp_path / "s.json").read_text())[0]["origin"]["lat_deg"] == 49.46

    out = tmp_path / "logs"
    proc = cli(
        "import",
        "gsd",
        str(gsd_log),
        str(tmp_path / "missing.txt"),
        "--out",
        str(out),
        "--origin",
        "49.4599,11.1099",
    )
    assert proc.returncode == 2
    assert (out / "handmade_gsd.lcmlog").is_file()
    assert "missing.txt: no such file" in proc.stderr and "[1/2]" in proc.stderr
    assert json.loads(proc.stdout)["origin"]["source"] == "option"


def _parse(*argv):
    """`stridefix import ...` parsed in-process (the console script costs seconds per start)."""
    import argparse

    from stridefix_analyzer.datasets import cli as import_cli

    parser = argparse.ArgumentParser(prog="stridefix")
    import_cli.add_parser(parser.add_subparsers(dest="command"))
    return parser.parse_args(["import", *argv])


def test_cli_output_file_takes_one_input(gsd_log, handmade_trace, tmp_path, capsys):
    from stridefix_analyzer.datasets import cli as import_cli

    args = _parse("gsd", str(gsd_log), str(gsd_log), "-o", str(tmp_path / "x.lcmlog"))
    assert import_cli.run(args) == 2
    assert "single input" in capsys.readouterr().err
    assert not (tmp_path / "x.lcmlog").exists()
    args = _parse(
        "msindoor", str(handmade_trace), str(handmade_trace), "--output", str(tmp_path / "u.lcmlog")
    )
    assert import_cli.run(args) == 2
    assert "use --out DIR" in capsys.readouterr().err
    for bad in (
        ["gsd", str(gsd_log), "--origin", "north", "--out", str(tmp_path)],
        ["gsd", str(gsd_log)],  # no output given
        ["gsd", str(gsd_log), "-o", "a.lcmlog", "--out", str(tmp_path)],
    ):
        with pytest.raises(SystemExit) as exc:
            _parse(*bad)
        assert exc.value.code == 2
    assert _parse("gsd", str(gsd_log), "--origin", "49.46,11.11", "-o", "w.lcmlog").origin == (49.46, 11.11)


def test_cli_msindoor_output_file(handmade_trace, tmp_path, cli):
    proc = cli("import", "msindoor", str(handmade_trace), "-o", str(tmp_path / "t.lcmlog"))
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "t.lcmlog").is_file()
    assert "imported into " + str(tmp_path / "t.lcmlog") in proc.stderr


# --- one real logfile ----------------------------------------------------------------------------


def _count_type(path, kind: str) -> int:
    with open(path, encoding="utf-8", errors="replace") as f:
        return sum(1 for line in f if line.startswith(kind + ";"))


def test_real_log(real_gsd, tmp_path):
    s, warned = _import(real_gsd, tmp_path)
    assert warned == [] and s["skipped_lines"] == 0
    data = read_logs([tmp_path / "out.lcmlog"])
    imu = data.table("IMU")
    t = imu["t_us"]
    assert np.all(np.diff(t) > 0)
    assert len(imu) == _count_type(real_gsd, "ACCE")
    assert 48 <= 1e6 / np.median(np.diff(t)) <= 52  # the phone's 50 Hz accelerometer
    assert np.diff(t).max() < 50_000  # sensor timing: no gap of 50 ms
    truth = data.table("TRUTH")
    assert len(truth) == _count_type(real_gsd, "POSI") == s["waypoints"]
    assert np.all(np.diff(truth["t_us"]) > 0)
    assert set(truth["floor"].tolist()) == {0}
    assert truth["x_m"][0] == 0.0 and truth["y_m"][0] == 0.0  # origin = the first POSI
    assert np.hypot(truth["x_m"], truth["y_m"]).max() < 200  # one building
    assert t[0] < truth["t_us"][0] - 50e6  # the calibration minute is kept
    baro = data.table("BARO")
    assert 90_000 < np.median(baro["pressure_pa"]) < 105_000  # mbar -> Pa
    wifi = data.table("WIFI")
    assert len(wifi) >= 20 and np.all(wifi["n_ap"] > 0)
    assert np.all(np.diff(wifi["t_us"]) > 1e6)  # scans seconds apart
    assert len(data.table("GNSS")) > 100 and len(data.table("MAG")) > 0
    events = [e.timestamp for e in lcm.EventLog(str(tmp_path / "out.lcmlog"), "r")]
    assert events == sorted(events)
    acc = np.linalg.norm(np.column_stack([imu[f"accel_{a}_mps2"] for a in "xyz"]), axis=1)
    assert 9.0 < acc.mean() < 10.6
    assert s["building_id"] == "100"
