"""Property tests of the Python importers (hypothesis): whatever a trace or logfile holds, importing it
raises only the documented input errors.

GIVEN generated msindoor traces and GetSensorData logfiles (records of every type with absurd numbers:
times of 30 or 5000 digits, ``²`` as a digit, 1e308, ±inf, NaN, ``FloorName:F9999...``; random bytes;
the same text in UTF-8, UTF-16, Latin-1 or cut mid-character), WHEN the data set imports it (parse,
convert, write the LCM log: ``Dataset.import_walk``), THEN it either writes a log or raises a
:class:`~stridefix_analyzer.datasets.protocol.DatasetReadError` (NothingValidError, a header error),
never OverflowError, ValueError, TypeError, IndexError or another exception.

Regression: a huge time or floor number raised OverflowError (3 of 76 mutants of the real traces).
Examples per property: ``$STRIDEFIX_HYPOTHESIS_EXAMPLES`` (default 150, ``make fuzz`` runs more and
prints the count, ``--hypothesis-show-statistics``).
"""

from __future__ import annotations

import os
import tempfile
import warnings
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from stridefix_analyzer.datasets import gsd, msindoor
from stridefix_analyzer.datasets.protocol import DatasetReadError

EXAMPLES = int(os.environ.get("STRIDEFIX_HYPOTHESIS_EXAMPLES", "150"))
SETTINGS = settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    derandomize="STRIDEFIX_HYPOTHESIS_EXAMPLES" not in os.environ,  # make test: the same examples each run
    database=None,  # no .hypothesis/ folder: a failure prints its example
)

#: numbers as text: ordinary, absurd, not finite, not ASCII, not numbers
NUMBER = st.one_of(
    st.integers(-(10**6), 10**13).map(str),
    st.integers(-(10**40), 10**40).map(str),
    st.sampled_from(["9" * 30, "9" * 400, "1" + "0" * 5000, "²", "١٢٣", "+1", "1_000", "-0", "", " 7 "]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["1e308", "-1e308", "1e400", "nan", "inf", "-inf", "0x10", "1e-400"]),
    st.text(max_size=12),
)
MAC = st.one_of(st.just("aa:bb:cc:dd:ee:01"), st.text(max_size=20))
FLOOR_NAME = st.one_of(
    st.sampled_from(["F1", "B1", "G", "1F", "F0", "F32768", "B32769", "F" + "9" * 40, "F" + "9" * 5000]),
    st.text(max_size=10),
)
MS_TYPES = [
    "TYPE_ACCELEROMETER",
    "TYPE_GYROSCOPE",
    "TYPE_MAGNETIC_FIELD",
    "TYPE_WIFI",
    "TYPE_WAYPOINT",
    "TYPE_BEACON",
    "TYPE_ROTATION_VECTOR",
    "TYPE_X",
]
GSD_TAGS = ["ACCE", "GYRO", "MAGN", "PRES", "GNSS", "WIFI", "POSI", "BLE4", "AHRS", "XYZ"]
# record type -> fields after the tag, as the format has them (a strategy per field)
_GSD_FIELDS = {"ACCE": 6, "GYRO": 6, "MAGN": 6, "PRES": 4, "GNSS": 10, "WIFI": 6, "POSI": 6, "BLE4": 4}


@st.composite
def ms_line(draw: st.DrawFn) -> str:
    kind = draw(st.sampled_from(MS_TYPES))
    n = {"TYPE_WIFI": 5, "TYPE_WAYPOINT": 2, "TYPE_BEACON": 8}.get(kind, 4)
    n = draw(st.one_of(st.just(n), st.integers(0, 10)))
    fields = [draw(MAC if kind in ("TYPE_WIFI", "TYPE_BEACON") and i in (1, 6) else NUMBER) for i in range(n)]
    return "\t".join([draw(NUMBER), kind, *fields])


@st.composite
def ms_trace(draw: st.DrawFn) -> str:
    header = f"#\tSiteID:x\tFloorName:{draw(FLOOR_NAME)}"
    lines = draw(st.lists(st.one_of(ms_line(), st.text(max_size=40)), max_size=25))
    good = ["1000\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3"] if draw(st.booleans()) else []
    return "\n".join([header, *good, *lines]) + "\n"


@st.composite
def gsd_line(draw: st.DrawFn) -> str:
    tag = draw(st.sampled_from(GSD_TAGS))
    n = _GSD_FIELDS.get(tag, 3)
    n = draw(st.one_of(st.just(n), st.integers(0, 12)))
    fields = []
    for i in range(n):
        if tag == "WIFI" and i == 3 or tag == "BLE4" and i == 2:
            fields.append(draw(MAC))
        elif tag == "BLE4" and i == 1:
            fields.append(draw(st.sampled_from(["iBeacon", "Eddystone", "x"])))
        else:
            fields.append(draw(NUMBER))
    return ";".join([tag, *fields])


@st.composite
def gsd_log(draw: st.DrawFn) -> str:
    unit = draw(st.sampled_from(["", "% 'PRES;AppTimestamp(s);SensorTimestamp(s);Pres(mbar);Accuracy'\n"]))
    lines = draw(st.lists(st.one_of(gsd_line(), st.text(max_size=40)), max_size=25))
    good = ["ACCE;1.0;2.0;0.1;0.2;9.8;3"] if draw(st.booleans()) else []
    return f"% GetSensorData\n{unit}" + "\n".join([*good, *lines]) + "\n"


def encoded(text: st.SearchStrategy[str]) -> st.SearchStrategy[bytes]:
    """``text`` in one of the encodings a user's file may have, or cut mid-character."""

    def encode(args: tuple[str, str, int]) -> bytes:
        s, codec, cut = args
        data = s.encode(codec, errors="replace")
        return data[: max(0, len(data) - cut)]

    codecs = st.sampled_from(["utf-8", "utf-16", "utf-16-be", "latin-1", "cp1252"])
    return st.tuples(text, codecs, st.sampled_from([0, 0, 0, 1])).map(encode)


def _import(dataset, data: bytes) -> None:
    """Import ``data`` as one file of ``dataset``; only DatasetReadError may escape."""
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # malformed-line warnings, numpy's float32 overflow
        path = Path(tmp) / "walk.txt"
        path.write_bytes(data)
        out = Path(tmp) / "walk.lcmlog"
        try:
            dataset.import_walk(path, out)
        except DatasetReadError as exc:
            assert str(path) in str(exc)  # the message names the file
            assert not out.exists()  # nothing written
        else:
            assert out.stat().st_size > 0


@SETTINGS
@given(encoded(ms_trace()))
def test_msindoor_import_raises_only_input_errors(data):
    _import(msindoor.DATASET, data)


@SETTINGS
@given(encoded(gsd_log()))
def test_gsd_import_raises_only_input_errors(data):
    _import(gsd.DATASET, data)


@SETTINGS
@given(st.binary(max_size=3000), st.sampled_from([msindoor.DATASET, gsd.DATASET]))
def test_random_bytes_raise_only_input_errors(data, dataset):
    _import(dataset, data)


def test_the_regressions_hypothesis_would_have_to_find():
    """The shapes that raised OverflowError / ValueError before, fixed and checked every run."""
    big = "9" * 400
    _import(msindoor.DATASET, f"#\tFloorName:F{big}\n1000\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n".encode())
    _import(msindoor.DATASET, f"#\tFloorName:F1\n{big}\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n".encode())
    _import(msindoor.DATASET, "#\tFloorName:F1\n²\tTYPE_ACCELEROMETER\t0.1\t0.2\t9.8\t3\n".encode())
    _import(
        msindoor.DATASET,
        f"#\tFloorName:F1\n1000\tTYPE_WIFI\tn\taa:bb:cc:dd:ee:01\t-50\t{big}\t900\n".encode(),
    )
    _import(
        gsd.DATASET, b"% x\nACCE;1e300;1e300;0.1;0.2;9.8;3\nPOSI;1.0;1;49.46;11.11;" + big.encode() + b";1\n"
    )
    _import(
        gsd.DATASET,
        b"% x\nACCE;1.0;2.0;0.1;0.2;9.8;3\nWIFI;1.0;1.0;n;aa:bb:cc:dd:ee:01;" + big.encode() + b";-5\n",
    )
