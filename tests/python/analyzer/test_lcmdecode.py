"""lcmdecode: a fixed-layout type's messages decoded at once, exactly as its binding decodes them one
by one; where they could differ, the caller is told to decode one by one."""

import numpy as np
import pytest
import stridefix
from stridefix import context_t, fix_t, pose_t
from stridefix_analyzer.io.channels import CHANNELS
from stridefix_analyzer.io.lcmdecode import decode_columns, layout_of


def _columns(channel, payloads):
    """decode_columns of ``payloads`` laid end to end with a gap byte between them."""
    data, at = b"", []
    for p in payloads:
        data += b"\xff"
        at.append(len(data))
        data += p
    spec = CHANNELS[channel]
    sizes = np.array([len(p) for p in payloads], dtype=np.int64)
    raw = np.frombuffer(data, dtype=np.uint8)
    return decode_columns(spec.msg_type, spec.columns, raw, np.array(at, dtype=np.int64), sizes)


def _one_by_one(channel, payloads):
    spec = CHANNELS[channel]
    rows = [spec.row(spec.msg_type.decode(p)) for p in payloads]
    return {
        name: np.asarray(col, dtype=dtype) for (name, dtype), col in zip(spec.columns.items(), zip(*rows))
    }


def _assert_same(got, want):
    assert got is not None and list(got) == list(want)
    for name in want:
        assert got[name].dtype == want[name].dtype, name
        assert got[name].tobytes() == want[name].tobytes(), name


def test_every_fixed_layout_channel_is_vectorised():
    vectorised = {ch for ch, spec in CHANNELS.items() if layout_of(spec.msg_type) is not None}
    # WIFI and BLE carry variable-length arrays; everything else is primitives and at most one string
    assert set(CHANNELS) - vectorised == {"WIFI", "BLE"}
    assert layout_of(stridefix.config_t) is None  # string arrays
    assert layout_of(pose_t).fixed_bytes() == len(pose_t().encode()) == 8 + 63


def test_layout_widths_are_the_binding_s():
    f = {x.name: x.code for x in layout_of(fix_t).before}
    assert (f["t_us"], f["method"], f["x_m"], f["floor"], f["accuracy_m"]) == (
        ">i8",
        "i1",
        ">f8",
        ">i2",
        ">f4",
    )
    assert layout_of(fix_t).string == "reason_text"


def _fix(t_us, text, accepted=True, innovation=(0.25, -0.5)):
    m = fix_t()
    m.t_us, m.method, m.scheme, m.x_m, m.y_m, m.floor = t_us, fix_t.METHOD_WIFI, 3, 1.0 / 3, -2.5, -1
    m.accuracy_m, m.n_ap_used, m.innovation_m = 4.1, 17, list(innovation)
    m.test_ratio, m.alpha, m.accepted, m.reason, m.reason_text = float("nan"), 0.3, accepted, 0, text
    return m.encode()


def test_fix_records_with_reason_texts_of_every_length():
    payloads = [
        _fix(i, text, i % 2 == 0) for i, text in enumerate(["accepted", "", "gate", "accepted", "é ü"])
    ]
    got = _columns("FIX", payloads)
    _assert_same(got, _one_by_one("FIX", payloads))
    assert list(got["reason_text"]) == ["accepted", "", "gate", "accepted", "é ü"]


def test_context_string_between_fields():
    def ctx(i, text):
        m = context_t()
        m.t_us, m.state, m.rule, m.rule_text, m.switched, m.recal_x_m, m.wifi_on = (
            i,
            2,
            5,
            text,
            True,
            1.5,
            True,
        )
        return m.encode()

    payloads = [ctx(i, t) for i, t in enumerate(["cls_unlimited", "door", "", "door"])]
    _assert_same(_columns("CONTEXT", payloads), _one_by_one("CONTEXT", payloads))


def test_a_non_utf8_string_decodes_leniently_as_the_binding_does():
    raw = bytearray(_fix(1, "abcd"))
    raw[-3] = 0xFF  # inside "abcd"
    payloads = [bytes(raw), _fix(2, "abcd")]
    got = _columns("FIX", payloads)
    _assert_same(got, _one_by_one("FIX", payloads))
    assert got["reason_text"][0] == "ab\ufffdd"


@pytest.mark.parametrize(
    "odd",
    [
        lambda p: p + b"\x00\x00",  # trailing bytes: the binding ignores them
        lambda p: p[:-1],  # short
        lambda p: b"\x00" * 8 + p[8:],  # another type hash
    ],
)
def test_a_payload_the_binding_reads_otherwise_is_left_to_it(odd):
    assert _columns("POSE", [pose_t().encode(), odd(pose_t().encode())]) is None


def test_a_string_length_field_that_disagrees_is_left_to_the_binding():
    raw = bytearray(_fix(1, "gate"))
    raw[-6] = 3  # the length field says 3 (with the NUL), the payload holds 5
    assert _columns("FIX", [bytes(raw)]) is None
