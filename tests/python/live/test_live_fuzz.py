"""The live view's message decoding fuzzed (hypothesis): whatever arrives on the channels it folds,
no exception escapes :meth:`LiveState.fold`, every message is either folded or counted bad, and the
snapshot (whole, and as a client's increments) is strict JSON.

Each example is a sequence of messages on the subscribed channels, each one of: random bytes; the
type's fingerprint and random bytes (so decoding reaches the fields); a message of random field
values (NaN, ±inf, huge and tiny floats, every integer of the field's width, any text) encoded
whole; or that encoding cut short. The field types are read from the ``.lcm`` files themselves.

``make fuzz`` runs :func:`test_fuzz_for_a_time_budget` for ``FUZZ_SECONDS``
(``STRIDEFIX_LIVE_FUZZ_SECONDS``) and prints how many examples and messages it ran.
"""

from __future__ import annotations

import json
import os
import re
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from stridefix_analyzer.io.channels import CHANNELS
from stridefix_analyzer.live.server import SUBSCRIBE
from stridefix_analyzer.live.state import LiveState, to_json

LCMTYPES = Path(__file__).resolve().parents[3] / "lcmtypes" / "stridefix"
FOLDED = SUBSCRIBE.split("|")
INT_BITS = {"int8_t": 8, "int16_t": 16, "int32_t": 32, "int64_t": 64}
FIELD = re.compile(r"^\s*(\w+)\s+(\w+)\s*(?:\[(\d+)\])?\s*;", re.M)


def _fields(msg_type) -> list[tuple[str, str, int | None]]:
    """(name, LCM type, fixed length or None) of each field of ``msg_type``, from its .lcm file."""
    text = re.sub(r"//[^\n]*", "", (LCMTYPES / f"{msg_type.__name__}.lcm").read_text())
    fields = [
        (n, t, int(k) if k else None) for t, n, k in FIELD.findall(text) if t not in ("const", "package")
    ]
    assert [f[0] for f in fields] == list(msg_type.__slots__), msg_type.__name__
    return fields


def _value(lcm_type: str) -> st.SearchStrategy:
    if lcm_type in INT_BITS:
        b = INT_BITS[lcm_type]
        return st.integers(-(2 ** (b - 1)), 2 ** (b - 1) - 1)
    if lcm_type in ("float", "double"):
        return st.floats(allow_nan=True, allow_infinity=True, width=32 if lcm_type == "float" else 64)
    if lcm_type == "boolean":
        return st.booleans()
    if lcm_type == "string":
        return st.text(st.characters(blacklist_categories=("Cs",)), max_size=40)  # LCM writes UTF-8
    raise AssertionError(f"no strategy for LCM type {lcm_type}")


def _encoded(msg_type) -> st.SearchStrategy:
    """A message of ``msg_type`` with random field values, encoded."""
    parts = {
        n: (st.lists(_value(t), min_size=k, max_size=k) if k else _value(t)) for n, t, k in _fields(msg_type)
    }

    def build(values: dict) -> bytes:
        m = msg_type()
        for n, v in values.items():
            setattr(m, n, v)
        return m.encode()

    return st.fixed_dictionaries(parts).map(build)


def _payload(channel: str) -> st.SearchStrategy:
    msg_type = CHANNELS[channel].msg_type
    fingerprint = msg_type._get_packed_fingerprint()
    whole = _encoded(msg_type)
    return st.one_of(
        st.binary(max_size=600),
        st.binary(max_size=600).map(lambda b: fingerprint + b),
        whole,
        st.tuples(whole, st.integers(0, 600)).map(lambda wb: wb[0][: wb[1]]),
    )


MESSAGES = st.lists(st.one_of([st.tuples(st.just(c), _payload(c)) for c in FOLDED]), min_size=1, max_size=30)


def _check(messages: list[tuple[str, bytes]]) -> None:
    """Fold ``messages``; every one is folded or counted bad, and every snapshot is strict JSON."""
    state = LiveState(source="fuzz")
    sent: dict = {}
    for k, (channel, data) in enumerate(messages):
        state.fold(channel, data)
        if k % 7 == 0:  # a client's increments along the way
            json.loads(to_json(state.snapshot(sent)), parse_constant=_refuse)
    doc = json.loads(to_json(state.snapshot()), parse_constant=_refuse)
    assert sum(doc["messages"].values()) + doc["bad_messages"] == len(messages)
    json.dumps(state.snapshot(sent), allow_nan=False)  # already null where NaN was: no fallback needed


def _refuse(constant: str):
    raise AssertionError(f"not strict JSON: {constant}")


@settings(max_examples=300, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(MESSAGES)
def test_fold_survives_any_message(messages):
    _check(messages)


def test_fuzz_for_a_time_budget():
    """The same property for STRIDEFIX_LIVE_FUZZ_SECONDS (make fuzz), new random examples each
    round; prints the examples and messages run."""
    seconds = float(os.environ.get("STRIDEFIX_LIVE_FUZZ_SECONDS", "0"))
    if seconds <= 0:
        pytest.skip("make fuzz runs this for FUZZ_SECONDS (STRIDEFIX_LIVE_FUZZ_SECONDS)")
    count = {"examples": 0, "messages": 0}

    @settings(
        max_examples=500,
        deadline=None,
        database=None,
        phases=[Phase.generate, Phase.shrink],
        suppress_health_check=list(HealthCheck),
    )
    @given(MESSAGES)
    def run(messages):
        count["examples"] += 1
        count["messages"] += len(messages)
        _check(messages)

    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        run()
    took = time.monotonic() - t0
    print(
        f"\nfuzz: live_decoder {count['examples']} examples, {count['messages']} messages in {took:.0f} s "
        f"({count['examples'] / took:.0f} examples/s)"
    )
