"""Readers for event recordings: IJRR text folders, rpg_e2vid text, EVREAL npy folders, HQF h5, npy
(AEDAT4 and Prophesee files: :mod:`evinr_lite.formats`).

Every reader returns :class:`~evinr_lite.events.Events` (or a :class:`Recording`: events plus
ground-truth frames plus metadata) in the package conventions: t float64 seconds relative to
``t_origin``, x column, y row, p in {-1, +1}, sensor_size (H, W).

Absolute clocks (IJRR: about 1.47e9 s written with 9 decimals) do not fit float64 at nanosecond
resolution (the spacing of float64 near 1.5e9 is 2.4e-7 s). The text readers therefore split each
timestamp into whole seconds and nanoseconds as integers and subtract a whole-second ``t_origin``
exactly, before any float is formed. Frames of the same recording are read on the same origin.

Use :func:`read_recording` (format detected from content and name) or the per-format readers.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np

from .events import LARGE_T, EventDataError, Events, relative_seconds
from .events import auto_origin as _auto_origin
from .frames import Frames

__all__ = [
    "Recording",
    "read_events_npy",
    "read_events_txt",
    "read_frames_ijrr",
    "read_ijrr_folder",
    "read_evreal_folder",
    "read_h5",
    "read_recording",
    "read_events",
    "detect_format",
    "SUPPORTED_FORMATS",
]

SUPPORTED_FORMATS = (
    "an IJRR folder (events.txt, images.txt, images/, calib.txt); "
    "an EVREAL folder (events_ts.npy, events_xy.npy, events_p.npy, images.npy, images_ts.npy, metadata.json); "
    "a data_fetch canonical .h5 file; an HQF-style .h5/.hdf5 file; "
    "a `t x y p` .txt file (optional `W H` header line); "
    "an [N, 4] .npy array; "
    "an AEDAT4 file (.aedat4, DV / DAVIS, with its frames); "
    "a Prophesee EVT2/EVT3 .raw or DAT .dat file"
)
NS = 10**9              # nanoseconds per second
CHUNK_BYTES = 1 << 20   # the text parser works on 1 MiB of whole lines at a time (cache-friendly)
EVENT_COLUMNS = "`t x y p` (time in seconds, x = column, y = row, polarity)"


@dataclass(frozen=True, eq=False)
class Recording:
    """Events with their ground-truth frames and metadata.

    Attributes:
        events: the event stream.
        frames: ground-truth frames on the same clock (same ``t_origin``) as the events, or None.
        meta: at least ``{"format": str, "path": str}``, plus what the file provides (e.g. ``calib``).
    """

    events: Events
    frames: Frames | None
    meta: dict

    def __repr__(self) -> str:
        return f"Recording({self.meta.get('format')!r}, {self.events!r}, frames={self.frames!r})"


# ---- small helpers ------------------------------------------------------------------------

def _existing(path, kind: str = "file") -> Path:
    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such {kind}: {path}; check the path")
    return path


def _origin_to_ns(t_origin) -> int:
    """Seconds (float or int) -> exact integer nanoseconds of that float value."""
    if not math.isfinite(t_origin):
        raise EventDataError(f"t_origin must be a finite number of seconds, got {t_origin!r}")
    return round(Fraction(t_origin) * NS)


def _build_events(source, t, x, y, p, sensor_size, *, polarity, t_origin=0.0, sort=False) -> Events:
    """Events.from_arrays with the file named in any error message."""
    try:
        return Events.from_arrays(t, x, y, p, sensor_size, polarity=polarity, sort=sort, t_origin=t_origin)
    except EventDataError as err:
        raise EventDataError(f"{source}: {err}") from None


def _size_hint(x, y) -> str:
    if len(x) == 0:
        return ""
    return (f"; the events span x (column) 0..{int(np.max(x))} and y (row) 0..{int(np.max(y))}, "
            f"so the smallest sensor that fits is ({int(np.max(y)) + 1}, {int(np.max(x)) + 1}), "
            "but use the camera's real size, e.g. (180, 240) for a DAVIS240C")


def _to_grey_uint8(img: np.ndarray, source) -> np.ndarray:
    """An image [H, W], [H, W, 1], [H, W, 3] or [H, W, 4] -> grey uint8 [H, W] (ITU-R 709 weights)."""
    img = np.asarray(img)
    if img.ndim == 3 and img.shape[-1] == 1:
        img = img[..., 0]
    if img.dtype == np.uint16:
        img = img / 257.0
    elif img.dtype.kind == "f":
        img = np.clip(img, 0.0, 1.0) * 255.0
    elif img.dtype != np.uint8:
        raise EventDataError(f"{source}: images must be 8- or 16-bit grey or RGB, got dtype {img.dtype}")
    if img.ndim == 3 and img.shape[-1] in (3, 4):
        img = img[..., :3].astype(np.float64) @ np.array([0.2125, 0.7154, 0.0721])
    if img.ndim != 2:
        raise EventDataError(f"{source}: expected a grey or RGB image, got shape {img.shape}")
    if img.dtype != np.uint8:
        img = np.clip(np.round(img), 0, 255).astype(np.uint8)
    return img


# ---- vectorised text parsing --------------------------------------------------------------
# A chunk of text (about 1 MiB of whole lines) is a uint8 array. Tokens are runs of non-whitespace
# bytes, found by comparing each byte with its neighbour; a column of tokens is given by two
# arrays of byte offsets (starts, ends). Integers and the two halves of a timestamp are parsed
# digit position by digit position over all tokens at once; anything else (exponents, nan) goes
# through numpy's float parser on a zero-padded char matrix [N, L].

_IS_WORD = np.ones(256, dtype=bool)
_IS_WORD[[9, 10, 13, 32]] = False  # tab, newline, carriage return, space


class _BadToken(Exception):
    """Token `row` of a column does not parse."""

    def __init__(self, row: int):
        self.row = row


def _tokenize(buf: np.ndarray):
    """Whitespace-separated tokens of whole lines of text.

    Args:
        buf: uint8 [B], the bytes of one or more whole lines.
    Returns:
        starts, ends: int64 [K], byte span [start, end) of each token.
        counts: int64 [n_lines], tokens on each line.
        newlines: int64, byte positions of the newlines in buf.
    """
    word = np.concatenate(([False], _IS_WORD[buf], [False]))
    starts = np.flatnonzero(word[1:] & ~word[:-1])
    ends = np.flatnonzero(word[:-1] & ~word[1:])
    newlines = np.flatnonzero(buf == 10)
    line_ends = newlines if len(buf) == 0 or buf[-1] == 10 else np.append(newlines, len(buf))
    counts = np.diff(np.searchsorted(starts, line_ends), prepend=0)
    return starts, ends, counts, newlines


def _char_matrix(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Byte spans [N] -> uint8 [N, L] of their characters, left-aligned and zero-padded."""
    lengths = ends - starts
    cols = np.arange(max(int(lengths.max()) if len(lengths) else 1, 1))
    chars = buf.take(starts[:, None] + cols, mode="clip")
    chars[cols >= lengths[:, None]] = 0
    return chars


def _parse_float(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Tokens given by byte spans [N] -> float64 [N] (numpy's parser); raises _BadToken."""
    chars = _char_matrix(buf, starts, ends)
    strings = chars.view(f"S{chars.shape[1]}").ravel()
    try:
        return strings.astype(np.float64)
    except ValueError:
        for row, s in enumerate(strings):  # error path only: find the first bad token
            try:
                float(s)
            except ValueError:
                raise _BadToken(row) from None
        raise


def _parse_digits(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray | None:
    """Tokens of decimal digits only -> int64 [N]; None if a token has another character.

    Empty spans give 0. One vectorised step per character position (Horner's scheme).
    """
    lengths = ends - starts
    width = int(lengths.max()) if len(lengths) else 0
    if width > 18:  # would overflow int64
        return None
    value = np.zeros(len(starts), dtype=np.int64)
    for k in range(width):
        inside = lengths > k
        digit = buf.take(starts + k, mode="clip").astype(np.int64) - 48
        if np.any(inside & ((digit < 0) | (digit > 9))):
            return None
        value = np.where(inside, value * 10 + digit, value)
    return value


def _parse_decimal(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray):
    """Exact parse of plain decimal tokens ``[-+]digits[.digits]`` as integers.

    Args:
        buf: uint8 text; starts, ends: int64 [N], byte spans of the tokens.
    Returns:
        (sign, whole, nanos), int64 [N] each: value = sign * (whole + nanos / 1e9), digits
        beyond nanoseconds dropped; or None when some token is not a plain decimal (exponent,
        nan, inf, no whole part, more than 18 whole digits).
    """
    first = buf[starts]
    sign = np.where(first == 45, -1, 1)               # '-'
    whole_start = starts + ((first == 45) | (first == 43))
    dots = np.flatnonzero(buf == 46)                  # '.'
    point = ends
    if len(dots):
        next_dot = dots[np.minimum(np.searchsorted(dots, whole_start), len(dots) - 1)]
        point = np.where((next_dot >= whole_start) & (next_dot < ends), next_dot, ends)
    frac_start = np.minimum(point + 1, ends)
    frac_end = np.minimum(frac_start + 9, ends)
    whole = _parse_digits(buf, whole_start, point)
    nanos = _parse_digits(buf, frac_start, frac_end)
    beyond_ns = _parse_digits(buf, frac_end, ends)  # only checked to be digits
    if whole is None or nanos is None or beyond_ns is None or np.any(point == whole_start):
        return None
    return sign, whole, nanos * 10 ** (9 - (frac_end - frac_start))


def _parse_number(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Tokens -> int64 [N] when all are plain integers, else float64 [N]; raises _BadToken."""
    first = buf[starts]
    signed = (first == 45) | (first == 43)
    value = _parse_digits(buf, starts + signed, ends)
    if value is None or np.any(ends - starts - signed < 1):
        return _parse_float(buf, starts, ends)
    return np.where(first == 45, -value, value)


def _parse_time(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, origin_ns: int) -> np.ndarray:
    """Timestamp tokens (seconds) -> float64 [N] seconds relative to ``origin_ns`` nanoseconds.

    With a non-zero origin the tokens are parsed as integers (whole seconds and nanoseconds) and
    the origin is subtracted exactly, so relative times keep nanosecond resolution. With origin 0
    (small timestamps) this is a plain float64 parse. Raises _BadToken.
    """
    parsed = _parse_decimal(buf, starts, ends) if origin_ns != 0 else None
    if parsed is None:  # small times, or exponents / nan / inf: plain float64 parse
        return _parse_float(buf, starts, ends) - origin_ns / NS
    sign, whole, nanos = parsed
    rel_ns = (sign * whole - origin_ns // NS) * NS + sign * nanos - origin_ns % NS
    return rel_ns / NS


def _first_time_origin(buf: np.ndarray, start: int, end: int) -> int:
    """The automatic origin (integer ns) from the first timestamp token: its whole seconds if large."""
    starts, ends = np.array([start]), np.array([end])
    parsed = _parse_decimal(buf, starts, ends)
    if parsed is not None:
        sign, whole, nanos = (int(a[0]) for a in parsed)
        value_ns = sign * (whole * NS + nanos)
        return (value_ns // NS) * NS if abs(value_ns) >= LARGE_T * NS else 0
    try:
        return int(_auto_origin(float(_parse_float(buf, starts, ends)[0]))) * NS
    except _BadToken:
        return 0  # reported with its line number by the caller


def _line_text(buf: np.ndarray, newlines: np.ndarray, line: int) -> str:
    """Line `line` (0-based) of buf, for error messages."""
    lo = int(newlines[line - 1]) + 1 if line > 0 else 0
    hi = int(newlines[line]) if line < len(newlines) else len(buf)
    text = bytes(buf[lo:hi]).decode("utf-8", "replace").strip()
    return text if len(text) <= 80 else text[:77] + "..."


def _chunks(data: bytes, size: int):
    """(start, end) byte ranges of about `size` bytes that end at a newline (or at the end)."""
    start = 0
    while start < len(data):
        end = len(data)
        if start + size < len(data):
            cut = data.rfind(b"\n", start, start + size)
            if cut < 0:  # one very long line
                cut = data.find(b"\n", start + size)
            end = cut + 1 if cut >= 0 else len(data)
        yield start, end
        start = end


@dataclass
class _EventText:
    """Raw columns of a `t x y p` text file."""

    t: np.ndarray                    # float64 [N], seconds relative to origin_ns
    x: np.ndarray                    # int64 [N], column
    y: np.ndarray                    # int64 [N], row
    p: np.ndarray                    # [N] as written: int8 when all in {-1, 0, 1}, else int64/float64
    header: tuple[int, int] | None   # (H, W) from a `W H` header line
    origin_ns: int                   # t_origin in integer nanoseconds


def _parse_event_text(path: Path, origin_ns: int | None) -> _EventText:
    """Parse `t x y p` lines (optionally after a `W H` header), chunk by chunk, all vectorised.

    Checks, naming the line: column count, numbers, finite and non-decreasing timestamps,
    whole-number coordinates. ``origin_ns`` None picks the origin from the first timestamp.
    """
    data = path.read_bytes()
    everything = np.frombuffer(data, dtype=np.uint8)
    parts, header, line_base, t_last = [], None, 0, -np.inf
    for lo, hi in _chunks(data, CHUNK_BYTES):
        buf = everything[lo:hi]
        starts, ends, counts, newlines = _tokenize(buf)

        def fail(line, problem):  # line: 0-based within this chunk
            raise EventDataError(f"{path}, line {line_base + line + 1}: {problem} "
                                 f"(line reads {_line_text(buf, newlines, line)!r})")

        def row_line(row):  # 0-based line (in this chunk) of event row `row`
            return int(np.searchsorted(newlines, starts[row, 0]))

        if lo == 0 and counts.any():  # an rpg_e2vid header `W H` may open the file
            first = int(np.flatnonzero(counts)[0])
            words = [bytes(buf[s:e]) for s, e in zip(starts[:2], ends[:2])]
            if counts[first] == 2 and all(w.isdigit() for w in words):
                header = (int(words[1]), int(words[0]))  # (H, W)
                counts[first], starts, ends = 0, starts[2:], ends[2:]
        bad = np.flatnonzero((counts != 0) & (counts != 4))
        if bad.size:
            i = int(bad[0])
            hint = " (a `W H` header is allowed only as the first line)" if counts[i] == 2 else ""
            fail(i, f"found {counts[i]} columns, expected 4: {EVENT_COLUMNS}{hint}")
        line_count = len(newlines)
        if len(starts) == 0:
            line_base += line_count
            continue
        starts, ends = starts.reshape(-1, 4), ends.reshape(-1, 4)

        if origin_ns is None:
            origin_ns = _first_time_origin(buf, starts[0, 0], ends[0, 0])
        try:
            t = _parse_time(buf, starts[:, 0], ends[:, 0], origin_ns)
        except _BadToken as err:
            fail(row_line(err.row), f"the timestamp is not a number; expected {EVENT_COLUMNS}")
        xyp = []
        for c, name in ((1, "x"), (2, "y"), (3, "p")):
            try:
                xyp.append(_parse_number(buf, starts[:, c], ends[:, c]))
            except _BadToken as err:
                fail(row_line(err.row), f"{name} is not a number; expected {EVENT_COLUMNS}")
        x, y, p = xyp

        nonfinite = np.flatnonzero(~np.isfinite(t))
        if nonfinite.size:
            fail(row_line(nonfinite[0]), "the timestamp is not finite; drop or repair that line")
        back = np.flatnonzero(np.diff(t, prepend=t_last) < 0)
        if back.size:
            fail(row_line(back[0]), "the timestamp is earlier than the one before: the events are not "
                 "sorted by time; sort the file (e.g. `sort -g -k1,1 events.txt`) or load the columns "
                 "with numpy and use Events.from_arrays(..., sort=True)")
        for name, v in (("x", x), ("y", y)):
            if v.dtype.kind == "f":
                not_whole = np.flatnonzero(~np.isfinite(v) | (v != np.round(v)))
                if not_whole.size:
                    fail(row_line(not_whole[0]), f"{name} must be a whole pixel index")
        if np.all(np.isin(p, (-1, 0, 1))):
            p = p.astype(np.int8)
        parts.append((t, x.astype(np.int64), y.astype(np.int64), p))
        t_last, line_base = t[-1], line_base + line_count

    if not parts:
        raise EventDataError(f"{path}: no events found; expected lines {EVENT_COLUMNS}")
    t, x, y, p = (np.concatenate(c) for c in zip(*parts))
    return _EventText(t, x, y, p, header, origin_ns)


def _sensor_from_header(path, header, sensor_size):
    """Reconcile a `W H` header (given as (H, W)) with a sensor_size argument."""
    if header is None or sensor_size is None:
        return sensor_size if header is None else header
    if tuple(int(v) for v in sensor_size) != header:
        H, W = header
        raise EventDataError(
            f"{path}: the header line `{W} {H}` (width first) means sensor_size (H, W) = {header}, "
            f"but sensor_size={tuple(sensor_size)} was passed; pass sensor_size={header} or leave it out"
        )
    return header


# ---- readers ------------------------------------------------------------------------------

def read_events_npy(path, sensor_size=None, *, columns="txyp", polarity="auto", time_unit="s",
                    sort=False) -> Events:
    """Events from an .npy array [N, 4].

    Args:
        path: .npy file holding an [N, 4] numeric array.
        sensor_size: (H, W); required (an .npy array does not record it).
        columns: order of the columns, a permutation of 'txyp' (e.g. 'xytp' for MVSEC).
        polarity: encoding of p, see :func:`~evinr_lite.events.normalize_polarity`.
        time_unit: unit of t: 's', 'ms', 'us' or 'ns'.
        sort: sort the events by time instead of raising on unsorted input.
    """
    path = _existing(path)
    try:
        a = np.load(path, allow_pickle=False)
    except ValueError as err:
        raise EventDataError(f"{path}: not a plain numeric .npy array ({err}); "
                             "save it with np.save(path, array)") from None
    if sorted(columns) != sorted("txyp"):
        raise EventDataError(f"columns must be a permutation of 'txyp' (e.g. 'txyp' or 'xytp'), got {columns!r}")
    if a.ndim != 2 or a.shape[1] != 4 or a.dtype.kind not in "iuf":
        raise EventDataError(
            f"{path}: expected a numeric array of shape [N, 4] with columns {' '.join(columns)} "
            f"(set columns= for another order), got shape {a.shape} and dtype {a.dtype}; for an EVREAL "
            "folder (events_ts.npy, events_xy.npy, ...) use read_evreal_folder"
        )
    col = {c: a[:, i] for i, c in enumerate(columns)}
    if sensor_size is None:
        raise EventDataError(
            f"{path}: an .npy array does not record the sensor size; pass sensor_size=(H, W) (rows, columns)"
            + _size_hint(col["x"], col["y"])
        )
    t, origin = relative_seconds(col["t"], time_unit)
    return _build_events(path, t, col["x"], col["y"], col["p"], sensor_size,
                         polarity=polarity, t_origin=origin, sort=sort)


def read_events_txt(path, sensor_size=None, *, polarity="auto", t_origin=None) -> Events:
    """Events from a text file of `t x y p` lines (IJRR events.txt, rpg_e2vid .txt).

    Args:
        path: text file; t in seconds, x column, y row, p polarity. An optional first line `W H`
            (two integers, width first: the rpg_e2vid header) gives the sensor size.
        sensor_size: (H, W); required unless the file has the header (then they must agree).
        polarity: encoding of p ('auto', '01', 'pm1').
        t_origin: seconds subtracted from every timestamp (exactly). None: the whole seconds of the
            first timestamp when it is >= 1e5 s (an absolute clock), else 0.
    """
    path = _existing(path)
    raw = _parse_event_text(path, None if t_origin is None else _origin_to_ns(t_origin))
    sensor_size = _sensor_from_header(path, raw.header, sensor_size)
    if sensor_size is None:
        raise EventDataError(
            f"{path}: the sensor size is unknown (no `W H` header line); pass sensor_size=(H, W) "
            f"(rows, columns){_size_hint(raw.x, raw.y)}"
        )
    return _build_events(path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                         polarity=polarity, t_origin=raw.origin_ns / NS)


def read_frames_ijrr(folder, t_origin=0.0) -> Frames:
    """Frames listed in ``folder/images.txt`` (`t images/frame_%08d.png` per line), in time order.

    Args:
        folder: the IJRR sequence folder.
        t_origin: seconds subtracted exactly from the timestamps (pass the events' ``t_origin``);
            None: automatic, as for the events.
    Returns:
        Frames with grey uint8 images [F, H, W] (RGB is converted to grey).
    """
    from skimage.io import imread

    folder = _existing(folder, "folder")
    listing = folder / "images.txt"
    if not listing.exists():
        raise EventDataError(f"{folder}: no images.txt, so no frames; expected lines `t images/frame_%08d.png`")
    buf = np.frombuffer(listing.read_bytes(), dtype=np.uint8)
    starts, ends, counts, newlines = _tokenize(buf)
    bad = np.flatnonzero((counts != 0) & (counts != 2))
    if bad.size:
        i = int(bad[0])
        raise EventDataError(
            f"{listing}, line {i + 1}: found {counts[i]} columns, expected 2: `t images/frame_%08d.png` "
            f"(file names without spaces; line reads {_line_text(buf, newlines, i)!r})"
        )
    if len(starts) == 0:
        raise EventDataError(f"{listing} lists no frames; expected lines `t images/frame_%08d.png`")
    starts, ends = starts.reshape(-1, 2), ends.reshape(-1, 2)
    origin_ns = (_first_time_origin(buf, starts[0, 0], ends[0, 0]) if t_origin is None
                 else _origin_to_ns(t_origin))
    try:
        t = _parse_time(buf, starts[:, 0], ends[:, 0], origin_ns)
    except _BadToken as err:
        i = int(np.searchsorted(newlines, starts[err.row, 0]))
        raise EventDataError(f"{listing}, line {i + 1}: the timestamp is not a number "
                             f"(line reads {_line_text(buf, newlines, i)!r})") from None
    images = []
    for s, e in zip(starts[:, 1], ends[:, 1]):
        image_path = folder / bytes(buf[s:e]).decode()
        if not image_path.exists():
            raise EventDataError(f"{listing} lists {image_path.name}, but {image_path} does not exist")
        images.append(_to_grey_uint8(imread(image_path), image_path))
    shapes = {im.shape for im in images}
    if len(shapes) > 1:
        raise EventDataError(f"{listing}: the frames have different sizes {sorted(shapes)}; all must share one (H, W)")
    try:
        return Frames(np.stack(images), t, origin_ns / NS).sorted()
    except EventDataError as err:
        raise EventDataError(f"{listing}: {err}") from None


def _read_calib(path: Path) -> dict | list:
    values = np.loadtxt(path, ndmin=1).ravel().tolist()
    names = ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3")
    return dict(zip(names, values)) if len(values) == len(names) else values


def read_ijrr_folder(folder, *, t_origin=None) -> Recording:
    """An IJRR / Event Camera Dataset sequence folder (the unzipped text release).

    Reads events.txt (p in {0, 1}), the frames of images.txt on the events' clock, and calib.txt
    (``meta["calib"] = {fx, fy, cx, cy, k1, k2, p1, p2, k3}``) when present. The sensor size is the
    frames' (H, W) (or a `W H` header of events.txt when there are no frames).

    Args:
        t_origin: seconds subtracted from all timestamps; None: whole seconds of the first event
            when the clock is absolute (>= 1e5 s), else 0.
    """
    folder = _existing(folder, "folder")
    events_path = folder / "events.txt"
    if not events_path.exists():
        raise EventDataError(f"{folder}: no events.txt; an IJRR folder holds events.txt, "
                             "images.txt, images/, calib.txt")
    raw = _parse_event_text(events_path, None if t_origin is None else _origin_to_ns(t_origin))
    frames = read_frames_ijrr(folder, t_origin=raw.origin_ns / NS) if (folder / "images.txt").exists() else None
    sensor_size = _sensor_from_header(events_path, raw.header, frames.size if frames is not None else None)
    if sensor_size is None:
        raise EventDataError(
            f"{folder}: no images.txt and no `W H` header in events.txt, so the sensor size is unknown; "
            f"read the events with read_events_txt(path, sensor_size=(H, W)){_size_hint(raw.x, raw.y)}"
        )
    events = _build_events(events_path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                           polarity="01", t_origin=raw.origin_ns / NS)
    meta = {"format": "ijrr", "path": str(folder)}
    if (folder / "calib.txt").exists():
        meta["calib"] = _read_calib(folder / "calib.txt")
    return Recording(events, frames, meta)


def read_evreal_folder(folder) -> Recording:
    """An EVREAL per-sequence folder of .npy files.

    Files: events_ts.npy [N] float64 s, events_xy.npy [N, 2] (x first), events_p.npy [N] in {0, 1},
    images.npy [F, H, W, 1] uint8, images_ts.npy [F], metadata.json {"sensor_resolution": [H, W]},
    image_event_indices.npy (optional, kept in ``meta``).
    """
    folder = _existing(folder, "folder")
    needed = ("events_ts.npy", "events_xy.npy", "events_p.npy", "metadata.json")
    missing = [name for name in needed if not (folder / name).exists()]
    if missing:
        raise EventDataError(f"{folder}: missing {', '.join(missing)}; an EVREAL folder holds {', '.join(needed)} "
                             "(and images.npy, images_ts.npy for frames)")
    metadata = json.loads((folder / "metadata.json").read_text())
    if "sensor_resolution" not in metadata:
        raise EventDataError(f"{folder / 'metadata.json'}: no 'sensor_resolution'; add \"sensor_resolution\": [H, W]")
    sensor_size = tuple(int(v) for v in metadata["sensor_resolution"])
    load = lambda name: np.load(folder / name, allow_pickle=False)  # noqa: E731
    ts, xy, p = load("events_ts.npy"), load("events_xy.npy"), load("events_p.npy")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise EventDataError(f"{folder / 'events_xy.npy'}: expected shape [N, 2] (x, y), got {xy.shape}")
    t, origin = relative_seconds(ts, "s")
    events = _build_events(folder, t, xy[:, 0], xy[:, 1], p, sensor_size, polarity="01", t_origin=origin)
    frames = None
    if (folder / "images.npy").exists():
        images, images_ts = load("images.npy"), load("images_ts.npy")
        try:
            frames = Frames(images, np.asarray(images_ts, np.float64) - origin, origin).sorted()
        except EventDataError as err:
            raise EventDataError(f"{folder / 'images.npy'}: {err}") from None
        if frames.size != sensor_size:
            raise EventDataError(f"{folder}: frames are {frames.size} but sensor_resolution is "
                                 f"{sensor_size} (both (H, W))")
    meta = {"format": "evreal", "path": str(folder), "metadata": metadata}
    if (folder / "image_event_indices.npy").exists():
        meta["image_event_indices"] = load("image_event_indices.npy")
    return Recording(events, frames, meta)


def _bisect_h5(ts, value: float, origin: float, lo: int, hi: int) -> int:
    """First index in [lo, hi) with ts[i] - origin >= value, reading single elements from disk."""
    while lo < hi:
        mid = (lo + hi) // 2
        if float(ts[mid]) - origin < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


def read_h5(path, *, t_start=None, t_end=None) -> Recording:
    """An HQF-style h5 file, optionally only the time window [t_start, t_end).

    Layout: events/xs, events/ys (int), events/ts (float64 s, sorted), events/ps (bool);
    images/image%09d (uint8) with attrs 'timestamp' (and 'event_idx'); root attr
    'sensor_resolution' (H, W).

    Args:
        t_start, t_end: seconds on the returned clock (file time minus ``t_origin``). The window
            is found by binary search on the ts dataset on disk and only that slice is read; frames
            are restricted to the same window. Frames come sorted by timestamp.
    """
    import h5py

    path = _existing(path)
    with h5py.File(path, "r") as f:
        names = ("events/xs", "events/ys", "events/ts", "events/ps")
        missing = [n for n in names if n not in f]
        if missing:
            raise EventDataError(f"{path}: missing datasets {missing}; expected the HQF layout {list(names)}")
        if "sensor_resolution" not in f.attrs:
            raise EventDataError(f"{path}: no root attribute 'sensor_resolution' (H, W); add it, e.g. "
                                 "h5py.File(path, 'r+').attrs['sensor_resolution'] = (H, W)")
        sensor_size = tuple(int(v) for v in f.attrs["sensor_resolution"])
        ts = f["events/ts"]
        n = ts.shape[0]
        if any(f[name].shape != (n,) for name in names):
            raise EventDataError(f"{path}: {names} must be 1-D with the same length, got "
                                 f"{[f[name].shape for name in names]}")
        origin = _auto_origin(float(ts[0])) if n else 0.0
        if t_start is not None and t_end is not None and t_end <= t_start:
            raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
        lo = 0 if t_start is None else _bisect_h5(ts, t_start, origin, 0, n)
        hi = n if t_end is None else _bisect_h5(ts, t_end, origin, lo, n)
        if hi <= lo:
            span = f"[{float(ts[0]) - origin:.6f}, {float(ts[n - 1]) - origin:.6f}] s" if n else "nothing"
            raise EventDataError(f"{path}: no events in the window [{t_start}, {t_end}) s; the events cover "
                                 f"{span} (relative to t_origin = {origin}); choose a window inside that range")
        t = ts[lo:hi].astype(np.float64) - origin
        x, y, p = (f[name][lo:hi] for name in ("events/xs", "events/ys", "events/ps"))
        events = _build_events(path, t, x, y, p, sensor_size, polarity="bool", t_origin=origin)

        frames, meta = None, {"format": "h5", "path": str(path), "attrs": dict(f.attrs), "event_slice": (lo, hi)}
        if "images" in f and len(f["images"]):
            group = f["images"]
            keys = np.array(sorted(group))
            stamps = np.array([float(group[k].attrs["timestamp"]) for k in keys]) - origin
            keep = np.ones(len(keys), dtype=bool)
            if t_start is not None:
                keep &= stamps >= t_start
            if t_end is not None:
                keep &= stamps < t_end
            order = np.argsort(stamps[keep], kind="stable")  # one HQF sequence has a frame out of order
            keys, stamps = keys[keep][order], stamps[keep][order]
            if len(keys):
                images = np.stack([_to_grey_uint8(group[k][()], f"{path}:images/{k}") for k in keys])
                frames = Frames(images, stamps, origin)
                if frames.size != sensor_size:
                    raise EventDataError(f"{path}: frames are {frames.size} but sensor_resolution is "
                                         f"{sensor_size} (both (H, W))")
                if all("event_idx" in group[k].attrs for k in keys):  # indices into the file's events
                    meta["frame_event_idx"] = np.array([int(group[k].attrs["event_idx"]) for k in keys])
    return Recording(events, frames, meta)


def _looks_like_event_text(path: Path) -> bool:
    """True when the first lines of a file are `t x y p` numbers (after an optional `W H` line)."""
    with open(path, "rb") as f:
        head = f.read(4096)
    try:
        lines = [line.split() for line in head.decode("ascii").splitlines()[:3] if line.strip()]
    except UnicodeDecodeError:
        return False
    if lines and len(lines[0]) == 2:
        lines = lines[1:]
    if not lines or len(lines[0]) != 4:
        return False
    try:
        [float(v) for v in lines[0]]
    except ValueError:
        return False
    return True


def detect_format(path) -> str:
    """The format of a recording, from its content first and its name second.

    Returns one of "ijrr", "evreal" (folders), "canonical", "h5", "aedat4", "prophesee_raw",
    "prophesee_dat", "txt", "npy". Raises EventDataError naming the supported formats otherwise.
    """
    from .formats import sniff_format

    path = Path(path)
    if not path.exists():
        raise EventDataError(f"no such file or folder: {path}; check the path")
    if path.is_dir():
        if (path / "events.txt").exists():
            return "ijrr"
        if (path / "events_ts.npy").exists():
            return "evreal"
        raise EventDataError(f"{path}: folder of unknown format (no events.txt or events_ts.npy); "
                             f"supported formats: {SUPPORTED_FORMATS}")
    suffix = path.suffix.lower()
    kind = sniff_format(path)
    if kind == "hdf5":
        from .canonical import is_canonical

        return "canonical" if is_canonical(path) else "h5"
    if kind in ("aedat4", "npy", "prophesee_raw", "prophesee_dat"):
        return kind
    if kind in ("aedat2", "aedat3"):
        raise EventDataError(f"{path}: an {kind.upper()} file; only AEDAT4 is read: convert it with iniVation's "
                             "DV software (Convert to AEDAT4) or export the events to a `t x y p` text file")
    if kind == "zip":
        raise EventDataError(f"{path}: a zip archive; unzip it first and pass the folder (IJRR / EVREAL) or "
                             "the file inside")
    if suffix == ".txt" or _looks_like_event_text(path):
        return "txt"
    raise EventDataError(f"{path}: unknown format {suffix or '(no extension)'!r} (and its content is none of "
                         f"the known ones); supported formats: {SUPPORTED_FORMATS}")


def read_recording(path, **kwargs) -> Recording:
    """Read any supported recording; the format is detected by :func:`detect_format`.

    IJRR folder -> :func:`read_ijrr_folder`; EVREAL folder -> :func:`read_evreal_folder`; HDF5 ->
    the canonical data_fetch format (:func:`evinr_lite.canonical.read_canonical`) or HQF-style
    :func:`read_h5`; AEDAT4 -> :func:`evinr_lite.formats.read_aedat4`; Prophesee .raw / .dat ->
    :func:`evinr_lite.formats.read_prophesee`; `t x y p` text -> :func:`read_events_txt`;
    .npy -> :func:`read_events_npy` (the last two without frames). ``kwargs`` go to that reader.
    ``meta["format"]`` names the format read.
    """
    path = Path(path)
    kind = detect_format(path)
    if kind == "ijrr":
        return read_ijrr_folder(path, **kwargs)
    if kind == "evreal":
        return read_evreal_folder(path, **kwargs)
    if kind == "canonical":
        from .canonical import read_canonical

        return read_canonical(path, **kwargs)
    if kind == "h5":
        return read_h5(path, **kwargs)
    if kind == "aedat4":
        from .formats import read_aedat4

        return read_aedat4(path, **kwargs)
    if kind in ("prophesee_raw", "prophesee_dat"):
        from .formats import read_prophesee

        return read_prophesee(path, **kwargs)
    if kind == "txt":
        return Recording(read_events_txt(path, **kwargs), None, {"format": "txt", "path": str(path)})
    return Recording(read_events_npy(path, **kwargs), None, {"format": "npy", "path": str(path)})


def read_events(path, **kwargs) -> Events:
    """Only the events of :func:`read_recording`."""
    return read_recording(path, **kwargs).events
