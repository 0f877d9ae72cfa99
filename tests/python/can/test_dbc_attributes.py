"""firmware/board.dbc's attributes (what CAN tools read from it): a cycle time on every periodic message, equal to what
the simulator sends (the firmware's decoder seeds its IMU, MAG and BARO periods from the same
attribute: cantools generates BOARD_*_CYCLE_TIME_MS); event-driven messages marked as such; a value
table on every flag signal."""

from __future__ import annotations

import pytest
from stridefix_sim.board import IMU_PERIOD_MS
from stridefix_sim.sensors import BARO_DECIMATION, IMU_RATE_HZ, MAG_DECIMATION

# The simulator's periods [ms]: sensors.py's rates, board.py's 1 Hz BOARD_TIME and BOARD_STATUS.
SIM_PERIOD_MS = {
    "BOARD_TIME": 1000,
    "IMU_ACCEL": IMU_PERIOD_MS,
    "IMU_GYRO": IMU_PERIOD_MS,
    "MAG": 1000 // IMU_RATE_HZ * MAG_DECIMATION,
    "BARO": 1000 // IMU_RATE_HZ * BARO_DECIMATION,
    "BOARD_STATUS": 1000,
}
EVENT_MESSAGES = {
    "WIFI_SCAN_BEGIN",
    "WIFI_AP",
    "WIFI_SCAN_END",
    "BLE_ADV",
    "LANDMARK",
    "GNSS_POSITION",
    "GNSS_INFO",
}


def test_every_message_is_periodic_or_event_driven(dbc):
    assert {m.name for m in dbc.messages} == set(SIM_PERIOD_MS) | EVENT_MESSAGES


@pytest.mark.parametrize("name", sorted(SIM_PERIOD_MS))
def test_periodic_message_cycle_time_is_the_simulators_period(dbc, name):
    msg = dbc.get_message_by_name(name)
    assert msg.cycle_time == SIM_PERIOD_MS[name]
    assert msg.send_type == "Cyclic"


@pytest.mark.parametrize("name", sorted(EVENT_MESSAGES))
def test_event_message_has_no_cycle_time(dbc, name):
    msg = dbc.get_message_by_name(name)
    assert msg.cycle_time is None
    assert msg.send_type == "Event"


@pytest.mark.parametrize("flag", ["imu_ok", "mag_ok", "baro_ok", "wifi_ok"])
def test_status_flags_have_a_value_table(dbc, flag):
    msg = dbc.get_message_by_name("BOARD_STATUS")
    sig = msg.get_signal_by_name(flag)
    assert dict(sig.choices) == {0: "fault", 1: "ok"}
    data = dbc.encode_message("BOARD_STATUS", {s.name: 0 for s in msg.signals} | {flag: 1})
    assert str(dbc.decode_message("BOARD_STATUS", data)[flag]) == "ok"
    assert dbc.decode_message("BOARD_STATUS", data, decode_choices=False)[flag] == 1
