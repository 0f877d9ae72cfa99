"""The simulator's CAN log read by python-can and decoded by cantools (interoperability): ``stridefix sim
--candump-suffix .log`` writes board.log, which ``can.LogReader`` reads (it picks its candump -L
reader by the ``.log`` suffix and refuses ``.candump``); every frame decodes against
firmware/board.dbc to what the simulator sent, at the DBC's cycle times; stridefixd replays the same
file as it replays board.candump; ``--candump-suffix .log`` names the same lines board.log."""

from __future__ import annotations

import argparse
import collections
import re

import can
import numpy as np
import pytest
from numpy.testing import assert_allclose
from stridefix_common.exits import EXIT_OK
from stridefix_sim import cli as sim_cli

LINE_RE = re.compile(r"^\((\d+)\.(\d{6})\) can0 ([0-9A-F]{3})#([0-9A-F]*)$")


def read_messages(path) -> list[can.Message]:
    with can.LogReader(str(path)) as reader:
        return list(reader)


def test_python_can_reads_every_line_as_the_line_says(walk):
    msgs = read_messages(walk.log)
    lines = walk.log.read_text(encoding="ascii").splitlines()
    assert len(msgs) == len(lines) == walk.summary["frames_total"]
    for m, line in zip(msgs, lines):
        sec, usec, can_id, data = LINE_RE.match(line).groups()
        assert round(m.timestamp * 1e6) == int(sec) * 1_000_000 + int(usec)  # float s: exact to 1 µs
        assert (m.arbitration_id, bytes(m.data), m.channel) == (int(can_id, 16), bytes.fromhex(data), "can0")
        assert not (m.is_extended_id or m.is_remote_frame or m.is_fd or m.is_error_frame)


def test_python_can_refuses_the_candump_suffix(walk, tmp_path):
    candump = tmp_path / "board.candump"
    candump.write_bytes(walk.log.read_bytes())
    with pytest.raises(ValueError, match="candump"):
        can.LogReader(str(candump))


def test_counts_per_message_are_what_the_simulator_sent_at_the_dbc_cycle_times(walk, dbc):
    counts = collections.Counter(
        dbc.get_message_by_frame_id(m.arbitration_id).name for m in read_messages(walk.log)
    )
    assert dict(counts) == walk.summary["frames_by_name"]
    loss = walk.result.scenario["can"]["loss_rate"]
    for msg in dbc.messages:
        if msg.cycle_time is None:
            continue
        sent = walk.summary["duration_s"] * 1000 / msg.cycle_time  # e.g. IMU_ACCEL: 100 Hz x 20 s
        sigma = np.sqrt(sent * loss * (1 - loss))
        assert abs(counts[msg.name] - sent * (1 - loss)) <= 2 + 4 * sigma, (msg.name, counts[msg.name], sent)


def test_every_frame_decodes_within_its_signal_ranges(walk, dbc):
    for m in read_messages(walk.log):
        msg = dbc.get_message_by_frame_id(m.arbitration_id)
        values = dbc.decode_message(m.arbitration_id, m.data, decode_choices=False)
        for sig in msg.signals:
            assert sig.minimum <= values[sig.name] <= sig.maximum, (msg.name, sig.name, values[sig.name])
        if msg.name == "BOARD_STATUS":  # the value table: every sensor reported ok
            named = dbc.decode_message(m.arbitration_id, m.data)
            assert {str(named[f]) for f in ("imu_ok", "mag_ok", "baro_ok", "wifi_ok")} == {"ok"}


def decoded(walk, dbc, name: str) -> dict[str, np.ndarray]:
    """Every frame of message ``name`` in the log, decoded by cantools: signal -> values in log order."""
    frame_id = dbc.get_message_by_name(name).frame_id
    rows = [
        dbc.decode_message(frame_id, m.data) for m in read_messages(walk.log) if m.arbitration_id == frame_id
    ]
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def half_lsb(dbc, name: str, signal: str) -> float:
    return dbc.get_message_by_name(name).get_signal_by_name(signal).scale / 2 + 1e-9


def test_decoded_values_are_the_samples_the_simulator_sent(lossless_walk, dbc):
    # lossless: frame k of a stream is sample k; the board clips into the DBC range, then rounds
    s = lossless_walk.result.sensors

    def clipped(name, signal, values):
        sig = dbc.get_message_by_name(name).get_signal_by_name(signal)
        return np.clip(values, sig.minimum, sig.maximum)

    for name, prefix, truth in (
        ("IMU_ACCEL", "accel", s.accel_mps2),
        ("IMU_GYRO", "gyro", s.gyro_dps),
        ("MAG", "mag", s.mag_ut),
    ):
        d = decoded(lossless_walk, dbc, name)
        n = len(d["seq"])
        assert n == lossless_walk.summary["frames_by_name"][name]
        assert_allclose(d["seq"], np.arange(n) % 256)
        for axis, col in zip("xyz", truth[:n].T):
            sig = f"{prefix}_{axis}"
            assert_allclose(d[sig], clipped(name, sig, col), rtol=0, atol=half_lsb(dbc, name, sig))
    baro = decoded(lossless_walk, dbc, "BARO")
    n = len(baro["seq"])
    for sig, truth in (("pressure", s.pressure_pa), ("temperature", s.temperature_degc)):
        assert_allclose(baro[sig], clipped("BARO", sig, truth[:n]), rtol=0, atol=half_lsb(dbc, "BARO", sig))
    assert 90_000 < baro["pressure"].min() < baro["pressure"].max() < 110_000  # Pa, near sea level
    accel = decoded(lossless_walk, dbc, "IMU_ACCEL")
    g = np.linalg.norm(np.column_stack([accel[f"accel_{a}"] for a in "xyz"]), axis=1)
    assert 9.3 < g.mean() < 10.3  # m/s², gravity and the walk's mean-free accelerations
    t = decoded(lossless_walk, dbc, "BOARD_TIME")["time_ms"]
    assert set(np.diff(t)) == {dbc.get_message_by_name("BOARD_TIME").cycle_time}


def test_stridefixd_replays_the_log_file(lossless_walk, replay):
    h = replay(lossless_walk.log).health
    assert h.frames_total == lossless_walk.summary["frames_total"] == h.frames_ok
    assert h.imu_samples == lossless_walk.summary["imu_samples"]
    assert (h.bad_syntax, h.unknown_id, h.bad_length, h.decode_errors) == (0, 0, 0, 0)


def run_sim_cli(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="stridefix")
    sim_cli.add_parser(parser.add_subparsers(dest="command", required=True))
    return sim_cli.run(parser.parse_args(["sim", *argv]))


def test_sim_cli_candump_suffix_names_the_same_lines_board_log(tmp_path):
    args = ["--duration-s", "5", "--seed", "3"]
    assert run_sim_cli([*args, "--out", str(tmp_path / "a")]) == EXIT_OK
    assert run_sim_cli([*args, "--out", str(tmp_path / "b"), "--candump-suffix", ".log"]) == EXIT_OK
    assert not (tmp_path / "b" / "board.candump").exists()
    text = (tmp_path / "b" / "board.log").read_bytes()
    assert text == (tmp_path / "a" / "board.candump").read_bytes() and len(text) > 40_000
    with pytest.raises(SystemExit):  # argparse: not one of the choices
        run_sim_cli([*args, "--out", str(tmp_path / "c"), "--candump-suffix", ".txt"])
