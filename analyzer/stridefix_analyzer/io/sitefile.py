"""The site file: an LCM-encoded ``stridefix.site_t`` behind a small checked header.

Layout (all header integers little-endian)::

    offset  size  field
         0     8  magic            b"SFSITE\\0\\x01"
         8     4  format version   uint32, 3 (version 1 and 2 files are refused: rebuild them)
        12     4  payload length   uint32, bytes after the header (file size − 24)
        16     4  payload CRC-32   uint32, IEEE 802.3 (zlib.crc32) of the payload
        20     4  reserved         uint32, 0
        24     n  payload          site_t.encode() (starts with the LCM type hash)

The firmware's reader is ``firmware/board/sf_site.c``; both sides apply the same checks in the same
order and word their messages alike, so a file rejected by one is rejected by the other:

1. header: size ≥ 24, magic, version, reserved = 0, payload length = file size − 24, CRC-32;
2. payload: LCM type hash of ``site_t``, then a whole ``site_t`` with no trailing bytes;
3. fields (:func:`validate_site`): finite map rotation (and geo-reference in range when ``has_geo``;
   a positive semi-definite ``fix_floor_cov_m2``, a positive-definite ``fix_cov_per_acc2``, ``fix_bias_sigma_m`` ≥ 0, ``fix_bias_length_m`` > 0 and
   ``fix_white_share`` in 0 … 1 when ``has_fix_model``);
   ``n_floors`` ≥ 1 with finite, strictly increasing heights; BSSIDs in 0 … 2⁴⁸−1, strictly
   ascending; ``cell_size_m`` finite and ≥ 0; reference points with finite positions, a floor in
   ``lowest_floor`` … ``lowest_floor + n_floors − 1`` and ``rp_scans`` ≥ 1; entries with AP and RP
   indices in range, strictly sorted by (ap, rp), finite mean, finite std ≥ 0, and
   1 ≤ count ≤ ``rp_scans`` of their RP; then the version-2 content (:mod:`.site_v2`: geo altitude
   and rotation, walls, ports, beacons and the BLE path-loss model), then the version-3 content
   (:mod:`.site_v3`: outlines, port extras, links, contexts, constellations), then every numeric
   field within its physical range (:mod:`.site_ranges`: the table ``firmware/site_ranges.tsv`` both
   readers check). Every array's length must equal its count.

Errors: :class:`SiteFileError` (``path: what``), with ``kind`` one of :data:`ERROR_KINDS`.
Cost: one read of the file, O(n_ap + n_rp + n_entries) checks.
"""

from __future__ import annotations

import io
import os
import stat
import struct
import tempfile
import zlib
from typing import Any

import numpy as np
from stridefix import site_t

from stridefix_analyzer.io.site_ranges import validate_ranges
from stridefix_analyzer.io.site_v2 import (
    SiteV2ValidationError,
    check_len,
    finite,
    init_v2_fields,
    set_v2_counts,
    validate_geo,
    validate_plan,
)
from stridefix_analyzer.io.site_v3 import fill_port_defaults, init_v3_fields, set_v3_counts, validate_contexts

MAGIC = b"SFSITE\0\x01"
FORMAT_VERSION = 3
HEADER = struct.Struct("<8sIIII")
HEADER_SIZE = HEADER.size  # 24
#: Largest payload either reader accepts [bytes] (the firmware allocates the whole file).
MAX_PAYLOAD_BYTES = 256 << 20
BSSID_LIMIT = 1 << 48

#: What can be wrong with a site file (``SiteFileError.kind``).
ERROR_KINDS = ("io", "short", "magic", "version", "reserved", "length", "crc", "decode", "field")

assert HEADER_SIZE == 24


class SiteFileError(Exception):
    """A site file cannot be read or is invalid. ``str()`` is ``"<path>: <what is wrong>"``.

    Attributes
    ----------
    path : str
        The file (or ``"<site>"`` when validating an in-memory site).
    kind : str
        One of :data:`ERROR_KINDS`.
    reason : str
        What is wrong, without the path.
    """

    def __init__(self, path: str, kind: str, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path, self.kind, self.reason = path, kind, reason


class SiteValidationError(ValueError):
    """A ``site_t`` breaks a field rule (message: what and where, e.g. ``entry 3: ...``)."""


# --- field validation ----------------------------------------------------------------------------


def _check_len(site: site_t, count_name: str, *arrays: str) -> int:
    return check_len(site, count_name, *arrays, error=SiteValidationError)


_ARRAYS = {
    "n_ap": ("ap_bssid",),
    "n_rp": ("rp_x_m", "rp_y_m", "rp_floor", "rp_scans"),
    "n_entries": ("entry_ap", "entry_rp", "entry_mean_dbm", "entry_std_db", "entry_count"),
}


def _arrays_pass(site: site_t, top_floor: int) -> bool:
    """Whether the AP, RP and entry rules of :func:`validate_site` (lengths included) hold for every
    element, checked at once with numpy (the per-element loops of a big map are seconds of Python).
    False (or anything numpy cannot hold) sends the loops over them, which name the first element
    that breaks a rule, in their order: the same outcome either way, only the check is faster."""
    counts = {c: getattr(site, c) for c in _ARRAYS}
    if any(n < 0 or any(len(getattr(site, f)) != n for f in _ARRAYS[c]) for c, n in counts.items()):
        return False
    n_ap, n_rp = counts["n_ap"], counts["n_rp"]
    try:
        with np.errstate(all="ignore"):
            bssid = np.asarray(site.ap_bssid, np.int64)
            ok = bool(np.all((bssid >= 0) & (bssid < BSSID_LIMIT)) and np.all(bssid[1:] > bssid[:-1]))
            x, y = np.asarray(site.rp_x_m, float), np.asarray(site.rp_y_m, float)
            floor, scans = np.asarray(site.rp_floor, np.int64), np.asarray(site.rp_scans, np.int64)
            ok = ok and bool(
                np.all(np.isfinite(x) & np.isfinite(y))
                and np.all((floor >= site.lowest_floor) & (floor <= top_floor))
                and np.all(scans >= 1)
            )
            ap, rp = np.asarray(site.entry_ap, np.int64), np.asarray(site.entry_rp, np.int64)
            mean, std = np.asarray(site.entry_mean_dbm, float), np.asarray(site.entry_std_db, float)
            count = np.asarray(site.entry_count, np.int64)
            if not (ok and np.all((ap >= 0) & (ap < n_ap) & (rp >= 0) & (rp < n_rp))):
                return False
            after = (ap[1:] > ap[:-1]) | ((ap[1:] == ap[:-1]) & (rp[1:] > rp[:-1]))
            return bool(
                np.all(after)
                and np.all(np.isfinite(mean))
                and np.all(np.isfinite(std) & (std >= 0.0))
                and np.all((count >= 1) & (count <= scans[rp]))
            )
    except (TypeError, ValueError, OverflowError):
        return False


def validate_site(site: site_t) -> None:
    """Check every field rule of the module docstring; raise on the first one broken.

    Raises
    ------
    SiteValidationError
        Naming the field and index, e.g. ``"entry 17: rp index 300 outside 0..99"``.
    """
    if not finite(site.map_rotation_deg):
        raise SiteValidationError(f"map_rotation_deg is {site.map_rotation_deg:g}, must be finite")
    if site.has_geo:
        if not (finite(site.origin_lat_deg) and -90.0 <= site.origin_lat_deg <= 90.0):
            raise SiteValidationError(f"origin_lat_deg = {site.origin_lat_deg:g} outside -90..90")
        if not (finite(site.origin_lon_deg) and -180.0 <= site.origin_lon_deg <= 180.0):
            raise SiteValidationError(f"origin_lon_deg = {site.origin_lon_deg:g} outside -180..180")
        try:
            validate_geo(site)
        except SiteV2ValidationError as exc:
            raise SiteValidationError(str(exc)) from None

    if site.has_fix_model:
        fxx, fxy, fyy = site.fix_floor_cov_m2
        if not (all(finite(v) for v in (fxx, fxy, fyy)) and fxx >= 0 and fyy >= 0 and fxx * fyy >= fxy * fxy):
            raise SiteValidationError(
                f"fix_floor_cov_m2 = [{fxx:g}, {fxy:g}, {fyy:g}] not positive semi-definite"
            )
        xx, xy, yy = site.fix_cov_per_acc2
        if not (all(finite(v) for v in (xx, xy, yy)) and xx > 0 and yy > 0 and xx * yy > xy * xy):
            raise SiteValidationError(f"fix_cov_per_acc2 = [{xx:g}, {xy:g}, {yy:g}] not positive definite")
        if not (finite(site.fix_bias_sigma_m) and site.fix_bias_sigma_m >= 0.0):
            raise SiteValidationError(
                f"fix_bias_sigma_m = {site.fix_bias_sigma_m:g}, must be finite and >= 0"
            )
        if not (finite(site.fix_bias_length_m) and site.fix_bias_length_m > 0.0):
            raise SiteValidationError(
                f"fix_bias_length_m = {site.fix_bias_length_m:g}, must be finite and > 0"
            )
        if not (finite(site.fix_white_share) and 0.0 <= site.fix_white_share <= 1.0):
            raise SiteValidationError(f"fix_white_share = {site.fix_white_share:g} outside 0..1")

    n_floors = _check_len(site, "n_floors", "floor_height_m")
    if n_floors < 1:
        raise SiteValidationError("n_floors = 0: a site has at least one floor")
    top_floor = site.lowest_floor + n_floors - 1
    if top_floor > 32767:
        raise SiteValidationError(f"floors {site.lowest_floor}..{top_floor} overflow int16")
    for i, h in enumerate(site.floor_height_m):
        if not finite(h):
            raise SiteValidationError(f"floor_height_m[{i}] is {h:g}, must be finite")
        if i > 0 and not h > site.floor_height_m[i - 1]:
            raise SiteValidationError(
                f"floor_height_m[{i}] = {h:g} not above floor_height_m[{i - 1}] = "
                f"{site.floor_height_m[i - 1]:g} (heights must increase)"
            )

    # every per-element rule below holds (checked at once): the loops have nothing to name
    fast = _arrays_pass(site, top_floor)
    n_ap = _check_len(site, "n_ap", "ap_bssid")
    for a, b in enumerate([] if fast else site.ap_bssid):
        if not 0 <= b < BSSID_LIMIT:
            raise SiteValidationError(f"ap {a}: BSSID {b} outside 0..2^48-1")
        if a > 0 and not b > site.ap_bssid[a - 1]:
            raise SiteValidationError(
                f"ap {a}: BSSID 0x{b:012x} not above ap {a - 1}'s 0x{site.ap_bssid[a - 1]:012x} "
                f"(BSSIDs must be strictly ascending)"
            )

    if not (finite(site.cell_size_m) and site.cell_size_m >= 0.0):
        raise SiteValidationError(f"cell_size_m = {site.cell_size_m:g}, must be finite and >= 0")

    n_rp = _check_len(site, "n_rp", "rp_x_m", "rp_y_m", "rp_floor", "rp_scans")
    for r in range(0 if fast else n_rp):
        x, y, f, s = site.rp_x_m[r], site.rp_y_m[r], site.rp_floor[r], site.rp_scans[r]
        if not (finite(x) and finite(y)):
            raise SiteValidationError(f"rp {r}: position ({x:g}, {y:g}) not finite")
        if not site.lowest_floor <= f <= top_floor:
            raise SiteValidationError(f"rp {r}: floor {f} outside {site.lowest_floor}..{top_floor}")
        if s < 1:
            raise SiteValidationError(f"rp {r}: rp_scans = {s}, must be >= 1")

    n_entries = _check_len(
        site, "n_entries", "entry_ap", "entry_rp", "entry_mean_dbm", "entry_std_db", "entry_count"
    )
    for i in range(0 if fast else n_entries):
        a, r = site.entry_ap[i], site.entry_rp[i]
        if not 0 <= a < n_ap:
            raise SiteValidationError(f"entry {i}: ap index {a} outside 0..{n_ap - 1}")
        if not 0 <= r < n_rp:
            raise SiteValidationError(f"entry {i}: rp index {r} outside 0..{n_rp - 1}")
        if i > 0 and not (a, r) > (site.entry_ap[i - 1], site.entry_rp[i - 1]):
            raise SiteValidationError(
                f"entry {i}: (ap {a}, rp {r}) not after entry {i - 1}'s (ap {site.entry_ap[i - 1]}, "
                f"rp {site.entry_rp[i - 1]}) (entries must be sorted by (ap, rp), no duplicates)"
            )
        mean, std, count = site.entry_mean_dbm[i], site.entry_std_db[i], site.entry_count[i]
        if not finite(mean):
            raise SiteValidationError(f"entry {i}: entry_mean_dbm is {mean:g}, must be finite")
        if not (finite(std) and std >= 0.0):
            raise SiteValidationError(f"entry {i}: entry_std_db = {std:g}, must be finite and >= 0")
        if not 1 <= count <= site.rp_scans[r]:
            raise SiteValidationError(
                f"entry {i}: count {count} outside 1..{site.rp_scans[r]} (rp_scans of rp {r})"
            )
    try:
        validate_plan(site, site.lowest_floor, top_floor)
        validate_contexts(site, site.lowest_floor, top_floor)
        validate_ranges(site)
    except SiteV2ValidationError as exc:
        raise SiteValidationError(str(exc)) from None


# --- file I/O ------------------------------------------------------------------------------------


def encode_site_file(site: site_t) -> bytes:
    """Header + payload bytes of ``site`` (validated first; raises SiteValidationError)."""
    fill_port_defaults(site)
    validate_site(site)
    payload: bytes = site.encode()
    if len(payload) > MAX_PAYLOAD_BYTES:
        raise SiteValidationError(
            f"encoded site is {len(payload)} bytes, more than the {MAX_PAYLOAD_BYTES} a reader accepts"
        )
    return HEADER.pack(MAGIC, FORMAT_VERSION, len(payload), zlib.crc32(payload), 0) + payload


def write_site(path: str | os.PathLike[str], site: site_t) -> int:
    """Validate ``site`` and write it to ``path`` atomically (temporary file + rename).

    Returns the file size [bytes]. Raises :class:`SiteFileError` (kind ``field``) when the site
    breaks a field rule, or ``OSError`` when the file cannot be written.
    """
    path = os.fspath(path)
    try:
        data = encode_site_file(site)
    except SiteValidationError as exc:
        raise SiteFileError(path, "field", f"not written: {exc}") from exc
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".sfsite-", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; a site file is an ordinary file
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return len(data)


def decode_site_file(data: bytes, path: str = "<site>") -> site_t:
    """Check the header, payload and fields of site-file bytes; return the site.

    Raises
    ------
    SiteFileError
        With ``kind`` naming the failed check and a message naming ``path`` and the values.
    """
    size = len(data)
    if size < HEADER_SIZE:
        raise SiteFileError(
            path, "short", f"file has only {size} bytes; a site file starts with a {HEADER_SIZE}-byte header"
        )
    magic, version, length, crc, reserved = HEADER.unpack_from(data)
    if magic != MAGIC:
        raise SiteFileError(
            path,
            "magic",
            f"bad magic {magic.hex(' ')}, expected {MAGIC.hex(' ')} (not a StrideFix site file)",
        )
    if version in (1, 2):
        raise SiteFileError(
            path,
            "version",
            f"format version {version}, this build reads {FORMAT_VERSION}: "
            f"rebuild it with `stridefix radiomap build`",
        )
    if version != FORMAT_VERSION:
        raise SiteFileError(
            path, "version", f"format version {version}, this reader supports {FORMAT_VERSION}"
        )
    if reserved != 0:
        raise SiteFileError(path, "reserved", f"reserved header field is 0x{reserved:08x}, must be 0")
    if length != size - HEADER_SIZE:
        what = "truncated" if length > size - HEADER_SIZE else "trailing bytes"
        raise SiteFileError(
            path,
            "length",
            f"length mismatch ({what}): header says {length} payload bytes, file has {size - HEADER_SIZE}",
        )
    if length > MAX_PAYLOAD_BYTES:
        raise SiteFileError(
            path, "length", f"payload of {length} bytes exceeds the limit of {MAX_PAYLOAD_BYTES}"
        )
    payload = data[HEADER_SIZE:]
    actual = zlib.crc32(payload)
    if actual != crc:
        raise SiteFileError(
            path, "crc", f"CRC-32 mismatch: header says 0x{crc:08x}, payload has 0x{actual:08x}"
        )
    expected_hash = site_t._get_packed_fingerprint()
    if payload[:8] != expected_hash:
        raise SiteFileError(
            path,
            "decode",
            f"payload is not a stridefix.site_t: LCM type hash "
            f"0x{payload[:8].hex()}, expected "
            f"0x{expected_hash.hex()} (written with another "
            f"version of site_t?)",
        )
    buf = io.BytesIO(payload)
    try:
        site = site_t.decode(buf)
    except Exception as exc:  # noqa: BLE001 - any decoder failure is a malformed payload
        raise SiteFileError(path, "decode", f"LCM decode of site_t failed: {exc!r}") from exc
    if buf.tell() != length:
        raise SiteFileError(
            path, "decode", f"payload has {length - buf.tell()} trailing bytes after the site_t"
        )
    try:
        validate_site(site)
    except SiteValidationError as exc:
        raise SiteFileError(path, "field", str(exc)) from exc
    return site


def read_site(path: str | os.PathLike[str]) -> site_t:
    """Read and fully check a site file (see the module docstring); return the ``site_t``.

    Raises
    ------
    SiteFileError
        The file is missing or unreadable (kind ``io``) or fails a check; the message names the
        file and what is wrong, e.g. ``"a.sfsite: CRC-32 mismatch: header says 0x…, payload has
        0x…"``.
    """
    path = os.fspath(path)
    if os.path.exists(path) and not (os.path.isfile(path) or stat.S_ISFIFO(os.stat(path).st_mode)):
        raise SiteFileError(path, "io", "cannot read site file: not a regular file (a directory or device)")
    try:
        with open(path, "rb") as f:
            data = f.read(HEADER_SIZE + MAX_PAYLOAD_BYTES + 1)
    except OSError as exc:
        raise SiteFileError(path, "io", f"cannot read site file: {exc.strerror or exc}") from exc
    return decode_site_file(data, path)


def new_site(**fields: Any) -> site_t:
    """A ``site_t`` with empty tables and one floor at 0 m, then ``fields`` applied; counts are
    set from the array lengths (``n_floors`` from ``floor_height_m``, and so on)."""
    s = site_t()
    s.name, s.source = "", ""
    s.map_rotation_deg, s.has_geo, s.origin_lat_deg, s.origin_lon_deg = 0.0, False, 0.0, 0.0
    s.lowest_floor, s.floor_height_m = 0, [0.0]
    s.ap_bssid, s.cell_size_m = [], 0.0
    s.rp_x_m, s.rp_y_m, s.rp_floor, s.rp_scans = [], [], [], []
    s.entry_ap, s.entry_rp, s.entry_mean_dbm, s.entry_std_db, s.entry_count = [], [], [], [], []
    s.has_fix_model, s.fix_floor_cov_m2, s.fix_cov_per_acc2 = False, [0.0, 0.0, 0.0], [1.0, 0.0, 1.0]
    s.fix_bias_sigma_m, s.fix_bias_length_m, s.fix_white_share = 0.0, 10.0, 1.0
    init_v2_fields(s)
    init_v3_fields(s)
    for name, value in fields.items():
        if not hasattr(s, name):
            raise AttributeError(f"site_t has no field {name!r}")
        if hasattr(value, "tolist"):
            value = value.tolist()  # numpy arrays and scalars → Python lists and numbers
        elif isinstance(value, tuple):
            value = list(value)
        setattr(s, name, value)
    return set_counts(s)


def set_counts(site: site_t) -> site_t:
    """Set every ``n_*`` count from its arrays' lengths (first array of each group); returns site."""
    site.n_floors = len(site.floor_height_m)
    site.n_ap = len(site.ap_bssid)
    site.n_rp = len(site.rp_x_m)
    site.n_entries = len(site.entry_ap)
    set_v2_counts(site)
    fill_port_defaults(site)
    set_v3_counts(site)
    return site
