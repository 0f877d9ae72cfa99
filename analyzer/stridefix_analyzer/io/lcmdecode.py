"""Decode all messages of one fixed-layout LCM type at once, with a numpy structured dtype.

The generated Python binding decodes one message per call (~5 µs for a POSE); a 1-hour walk has
36 k POSE and 36 k TRUTH. Most StrideFix types are a fixed sequence of primitives (scalars and
fixed-length arrays), at most one string among them, so every message of a given payload length
has the same byte layout and can be viewed as one record of a big-endian numpy dtype.

The layout comes from the binding itself, not from a second reading of the ``.lcm`` files: the
fields are ``__slots__`` in order (LCM encodes them in declaration order), and each primitive's
width is the widest value its ``encode()`` accepts (``struct`` refuses a value that does not fit:
127 fits int8, 2**15 − 1 int16 …; 1e300 fits a double, not a float). A layout is used only if it
decodes a probe message (every field set to a distinct value) exactly as the binding does.

:func:`decode_columns` returns ``None`` whenever its result could differ from decoding message by
message: a type with variable-length arrays, nested types or several strings, a payload with another
type hash (a decode error there), or one whose length or string length field does not match the
layout (the binding would read it differently or fail). The caller then decodes those messages one
by one, as before.
"""

from __future__ import annotations

import dataclasses
import functools
import struct
from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[Any]
_FINGERPRINT_BYTES = 8
_STRING_LENGTH_BYTES = 4  # uint32 byte count (with the NUL) before a string's bytes
#: signed integer codes, widest first, with the largest value each holds
_INT_TOPS = ((">i8", 2**63 - 1), (">i4", 2**31 - 1), (">i2", 2**15 - 1), ("i1", 2**7 - 1))


@dataclasses.dataclass(frozen=True)
class _Field:
    name: str  # the binding's slot
    code: str  # numpy dtype of one element, big-endian
    count: int | None  # None: a scalar; n: a fixed-length array
    kind: type  # bool, int or float: what the binding makes of it

    @property
    def size(self) -> int:
        return np.dtype(self.code).itemsize * (self.count or 1)


@dataclasses.dataclass(frozen=True)
class Layout:
    """One type's byte layout: the fields before the string (all of them without one), the string's
    slot and the fields after it."""

    fingerprint: bytes
    before: tuple[_Field, ...]
    string: str | None
    after: tuple[_Field, ...]

    def fixed_bytes(self) -> int:
        """Payload bytes besides the string's own (fingerprint, fields, the string's length field)."""
        fields = sum(f.size for f in (*self.before, *self.after))
        return _FINGERPRINT_BYTES + fields + (_STRING_LENGTH_BYTES if self.string else 0)


def _encodes(msg_type: Any, name: str, value: Any) -> bool:
    """Whether the binding encodes a message whose field ``name`` is ``value`` (the rest blank)."""
    msg = msg_type()
    setattr(msg, name, value)
    try:
        msg.encode()
    except (struct.error, OverflowError):
        return False
    return True


def _primitive(msg_type: Any, name: str, blank: Any) -> tuple[str, type] | None:
    """(numpy code, kind) of the primitive field ``name`` whose blank value is ``blank`` (one element
    of it for an array), or None for a type this module does not vectorise."""
    n = len(blank) if isinstance(blank, list) else None

    def fill(v: Any) -> Any:
        return [v] * n if n is not None else v

    value = blank[0] if n is not None else blank
    if isinstance(value, bool):
        return "i1", bool
    if isinstance(value, int):
        if not _encodes(msg_type, name, fill(-1)):
            return ("u1", int) if _encodes(msg_type, name, fill(255)) else None
        # the widest value that encodes tells the width (struct refuses one that does not fit)
        widths = [code for code, top in _INT_TOPS if _encodes(msg_type, name, fill(top))]
        return (widths[0], int) if widths else None
    if isinstance(value, float):
        return (">f8" if _encodes(msg_type, name, fill(1e300)) else ">f4"), float
    return None


@functools.cache
def layout_of(msg_type: Any) -> Layout | None:
    """The :class:`Layout` of a generated LCM type, or None when it has variable-length arrays,
    nested types or more than one string, or when the layout does not decode a probe message as the
    binding does."""
    blank = msg_type()
    before: list[_Field] = []
    after: list[_Field] = []
    string = None
    for name in msg_type.__slots__:
        value = getattr(blank, name)
        if isinstance(value, str):
            if string is not None:
                return None
            string = name
            continue
        if isinstance(value, list) and (not value or isinstance(value[0], list)):
            return None  # variable-length or multi-dimensional
        found = _primitive(msg_type, name, value)
        if found is None:
            return None
        code, kind = found
        (after if string else before).append(
            _Field(name, code, len(value) if isinstance(value, list) else None, kind)
        )
    layout = Layout(msg_type._get_packed_fingerprint(), tuple(before), string, tuple(after))
    return layout if _round_trips(msg_type, layout) else None


def _probe(msg_type: Any, layout: Layout) -> Any:
    """A message with every field set to a value of its own, exactly representable in its type."""
    msg = msg_type()
    for k, f in enumerate((*layout.before, *layout.after)):

        def value(i: int, f: _Field = f, k: int = k) -> Any:
            v = (k * 7 + i * 3) % 100 + 1  # fits int8 and float32 exactly
            signed = v if v % 2 or f.code == "u1" else -v
            return bool(v % 2) if f.kind is bool else f.kind(signed)

        setattr(msg, f.name, [value(i) for i in range(f.count)] if f.count else value(0))
    if layout.string:
        setattr(msg, layout.string, "probe")
    return msg


def _round_trips(msg_type: Any, layout: Layout) -> bool:
    """Whether ``layout`` decodes the probe message as the binding does."""
    try:
        encoded = _probe(msg_type, layout).encode()
    except (struct.error, OverflowError):
        return False
    payload = np.frombuffer(encoded, dtype=np.uint8)
    cols = _decode_group(layout, payload[None, :])
    if cols is None:
        return False
    decoded = msg_type.decode(encoded)
    for f in (*layout.before, *layout.after):
        want = getattr(decoded, f.name)
        got = cols[f.name][0]
        if list(np.atleast_1d(got)) != list(want if f.count else [want]):
            return False
    return not layout.string or cols[layout.string][0] == getattr(decoded, layout.string)


@functools.lru_cache(maxsize=1024)
def _dtype(layout: Layout, size: int) -> np.dtype | None:
    """The structured dtype of one ``size``-byte payload, or None when no string length fits
    (cached: building it cost more than decoding the few FIX records of a short replay)."""
    names, formats, offsets = ["_fp"], [f"V{_FINGERPRINT_BYTES}"], [0]
    at = _FINGERPRINT_BYTES

    def put(fields: tuple[_Field, ...]) -> None:
        nonlocal at
        for f in fields:
            names.append(f.name)
            formats.append(f"({f.count},){f.code}" if f.count else f.code)
            offsets.append(at)
            at += f.size

    put(layout.before)
    if layout.string:
        text = size - layout.fixed_bytes()  # the string's bytes, with its NUL
        if text < 1:
            return None
        names += ["_len", "_text"]
        formats += [">u4", f"V{text}"]
        offsets += [at, at + _STRING_LENGTH_BYTES]
        at += _STRING_LENGTH_BYTES + text
    put(layout.after)
    if at != size:
        return None
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": size})


def _decode_group(layout: Layout, rows: Array) -> dict[str, Array] | None:
    """Fields of equal-length payloads ``rows`` (k, size) uint8: each field's values as the binding
    gives them (bool, int64, float64 or str elements), or None where the binding would differ."""
    dtype = _dtype(layout, rows.shape[1])
    if dtype is None:
        return None
    rec = np.ascontiguousarray(rows).view(dtype).ravel()
    if np.any(rec["_fp"] != np.frombuffer(layout.fingerprint, dtype="V8")[0]):
        return None
    out: dict[str, Array] = {}
    for f in (*layout.before, *layout.after):
        raw = rec[f.name]
        out[f.name] = raw != 0 if f.kind is bool else raw.astype(np.int64 if f.kind is int else np.float64)
    if layout.string:
        text_bytes = dtype["_text"].itemsize
        if np.any(rec["_len"] != text_bytes):
            return None
        unique, inverse = np.unique(rec["_text"], return_inverse=True)
        # the binding drops the string's last byte (its NUL) and decodes the rest leniently
        texts = np.array([u.tobytes()[:-1].decode("utf-8", "replace") for u in unique], dtype=object)
        out[layout.string] = texts[inverse.ravel()]
    return out


def decode_columns(
    msg_type: Any,
    columns: Mapping[str, type],
    data: Array,
    payload_at: Array,
    payload_len: Array,
) -> dict[str, Array] | None:
    """Every payload of one channel decoded into its table columns, or None (module docstring).

    Parameters
    ----------
    msg_type : generated LCM class
        The channel's type.
    columns : mapping of str to dtype
        The channel's columns (:class:`stridefix_analyzer.io.channels.Channel`), in field order.
    data : ndarray of uint8
        The log's bytes.
    payload_at, payload_len : ndarray of int64, shape (n,)
        Byte offset and length of each payload, in log order.
    """
    layout = layout_of(msg_type)
    if layout is None or not len(payload_at):
        return None
    fields: dict[str, list[Array]] = {}
    order: list[Array] = []
    for size in np.unique(payload_len):
        rows = np.flatnonzero(payload_len == size)
        window = np.lib.stride_tricks.sliding_window_view(data, int(size))
        got = _decode_group(layout, window[payload_at[rows]])
        if got is None:
            return None
        order.append(rows)
        for name, values in got.items():
            fields.setdefault(name, []).append(values)
    back = np.argsort(np.concatenate(order), kind="stable")  # groups back into log order
    flat: list[Array] = []
    for name in (slot for slot in msg_type.__slots__ if slot in fields):  # declaration order
        values = np.concatenate(fields[name])[back]
        flat.extend(values.T if values.ndim == 2 else [values])
    if len(flat) != len(columns):
        return None
    return {
        name: np.asarray(values.tolist(), dtype=dtype) if dtype is str else values.astype(dtype, copy=False)
        for (name, dtype), values in zip(columns.items(), flat)
    }
