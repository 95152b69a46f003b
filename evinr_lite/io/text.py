"""The vectorised parser of `t x y p` event text (IJRR events.txt, rpg_e2vid .txt) and IJRR images.txt.

Used by :func:`evinr_lite.io.readers.read_events_txt` (whole files) and by ``data_fetch``'s IJRR
converter (blocks of a multi-GB file inside a zip), so both check the same things with the same
messages: column count, numbers, finite timestamps, whole-number coordinates.

Absolute clocks (IJRR: about 1.47e9 s written with 9 decimals) do not fit float64 at nanosecond
resolution (the spacing of float64 near 1.5e9 is 2.4e-7 s). Timestamps are therefore split into
whole seconds and nanoseconds as integers, and a whole-second origin is subtracted exactly before
any float is formed.

Public functions: :func:`parse_event_block` (one block of whole lines), :func:`parse_event_text`
(a whole file, block by block), :func:`parse_frame_list` (images.txt), :func:`line_blocks`,
:func:`origin_to_ns`.
"""
from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..core.events import (LARGE_T, MAX_SENSOR_SIDE, TIME_UNITS, EventDataError, auto_origin, check_t_origin,
                           resolve_time_unit, wrap_hint)
from ..core.checks import ArgumentTypeError, check_path_type, whole_number
from ..core.guard import host_array

__all__ = ["EventBlock", "TextLayout", "TXT_LAYOUT", "parse_event_block", "parse_event_text", "blank_leading_comments",
           "parse_frame_list", "line_blocks", "origin_to_ns", "read_text_bytes", "NS", "NS_PER_UNIT", "CHUNK_BYTES", "EVENT_COLUMNS"]

NS = 10**9              # nanoseconds per second
NS_PER_UNIT = {"s": NS, "ms": 10**6, "us": 10**3, "ns": 1}   # nanoseconds per unit of a timestamp token
CHUNK_BYTES = 1 << 20   # the text parser works on 1 MiB of whole lines at a time (cache-friendly)
EVENT_COLUMNS = "`t x y p` (time in seconds, x = column, y = row, polarity)"
MAX_PIXEL = 1 << 31     # a coordinate at or beyond this is no pixel of any sensor (nor fits the int64 cast exactly)
MAX_CLOCK_S = 2.0**53   # seconds (285 million years): a timestamp beyond it is no clock, whatever its unit
FRAME_COLUMNS = "`t images/frame_%08d.png`"
_WORD = re.compile(r"^[A-Za-z_][\w\[\]()\u00b5.-]*$")   # a column's name, e.g. t, timestamp_us, time[ms]


@dataclass(frozen=True)
class TextLayout:
    """Where t, x, y and p sit on a line of event text, and how error messages name them.

    ``order``: the token index of t, x, y and p on each 4-token line ((0, 1, 2, 3): `t x y p`;
    Metavision's CSV `x,y,p,t` is (3, 0, 1, 2)). ``columns``: the columns as messages write them.
    ``sort_hint``: how to sort such a file, for the message about unsorted timestamps.
    ``separators``: bytes that separate values besides white space (a CSV's b",;").
    ``size_line``: an rpg_e2vid `W H` first line may open the file.
    """

    order: tuple = (0, 1, 2, 3)
    columns: str = EVENT_COLUMNS
    sort_hint: str = "sort the file (e.g. `sort -g -k1,1 events.txt`)"
    separators: bytes = b""
    size_line: bool = True


TXT_LAYOUT = TextLayout()   # `t x y p` (IJRR events.txt, rpg_e2vid)


def origin_to_ns(t_origin) -> int:
    """Seconds -> exact integer nanoseconds of that value (a float's exact binary value, a Fraction's or Decimal's
    exact value; a numpy scalar, 0-d array or tensor as its Python number)."""
    check_t_origin(t_origin)   # text or a list were Python's "must be real number", True was 1 s
    value = host_array(t_origin)   # a tensor as numpy
    if isinstance(value, (np.ndarray, np.generic)):   # Fraction() takes no np.float32 nor 0-d array: their .item()
        value = value.item()
    return round(Fraction(value) * NS)


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


@functools.lru_cache(maxsize=None)
def _word_table(separators: bytes) -> np.ndarray:
    """bool [256]: the bytes that belong to a token (not white space, not one of ``separators``)."""
    if not separators:
        return _IS_WORD
    table = _IS_WORD.copy()
    table[list(separators)] = False
    return table


def _tokenize(buf: np.ndarray, separators: bytes = b""):
    """Whitespace-separated tokens of whole lines of text.

    Args:
        buf: uint8 [B], the bytes of one or more whole lines.
        separators: bytes that also separate tokens (e.g. b",;" for CSV).
    Returns:
        starts, ends: int64 [K], byte span [start, end) of each token.
        counts: int64 [n_lines], tokens on each line.
        newlines: int64, byte positions of the newlines in buf.
    """
    word = np.concatenate(([False], _word_table(separators)[buf], [False]))
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
    if width > 19 or (width == 19 and np.any((lengths == 19) & (buf.take(starts, mode="clip") > 56))):
        return None  # would overflow int64 (19 digits fit when the first is at most 8)
    value = np.zeros(len(starts), dtype=np.int64)
    for k in range(width):
        inside = lengths > k
        digit = buf.take(starts + k, mode="clip").astype(np.int64) - 48
        if np.any(inside & ((digit < 0) | (digit > 9))):
            return None
        value = np.where(inside, value * 10 + digit, value)
    return value


def _parse_bool(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray | None:
    """Tokens that are all `True` / `False` (any case: pandas writes a bool column so) -> int64 [N] 1 / 0;
    None when some token is neither."""
    lengths = ends - starts
    if not len(starts) or int(lengths.max()) > 5:
        return None
    chars = _char_matrix(buf, starts, ends)
    words = np.char.lower(chars.view(f"S{chars.shape[1]}").ravel())
    true = words == b"true"
    if not np.all(true | (words == b"false")):
        return None
    return true.astype(np.int64)


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


def _unit_ns(buf, starts, ends, unit: str):
    """Exact integer nanoseconds of timestamp tokens in ``unit`` (plain decimals), or None."""
    parsed = _parse_decimal(buf, starts, ends)
    if parsed is None:
        return None
    sign, whole, nanos = parsed
    scale = NS_PER_UNIT[unit]
    if unit != "s" and np.any(whole > (2**62) // scale):
        return None
    return sign * (whole * scale + (nanos * scale) // NS)


def _parse_time(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, origin_ns: int,
                unit: str = "s") -> np.ndarray:
    """Timestamp tokens (in ``unit``, default seconds) -> float64 [N] seconds relative to ``origin_ns``.

    With a non-zero origin, or a unit other than seconds, the tokens are parsed as integers (whole
    units and nanoseconds of a unit) and the origin is subtracted exactly, so relative times keep
    nanosecond resolution. With origin 0 and seconds this is a plain float64 parse. Raises _BadToken.
    """
    if unit != "s":
        value_ns = _unit_ns(buf, starts, ends, unit)
        if value_ns is None:   # exponents / nan / inf / huge: float parse, then scaled
            return _parse_float(buf, starts, ends) * (NS_PER_UNIT[unit] / NS) - origin_ns / NS
        return (value_ns - origin_ns) / NS
    parsed = _parse_decimal(buf, starts, ends) if origin_ns != 0 else None
    if parsed is None:  # small times, or exponents / nan / inf: plain float64 parse
        return _parse_float(buf, starts, ends) - origin_ns / NS
    sign, whole, nanos = parsed
    rel_ns = (sign * whole - origin_ns // NS) * NS + sign * nanos - origin_ns % NS
    return rel_ns / NS


def _first_time_origin(buf: np.ndarray, start: int, end: int, unit: str = "s") -> int:
    """The automatic origin (integer ns) from the first timestamp token: its whole seconds if large."""
    starts, ends = np.array([start]), np.array([end])
    value = _unit_ns(buf, starts, ends, unit)
    if value is not None:
        value_ns = int(value[0])
        return (value_ns // NS) * NS if abs(value_ns) >= LARGE_T * NS else 0
    try:
        return int(auto_origin(float(_parse_float(buf, starts, ends)[0]) * NS_PER_UNIT[unit] / NS)) * NS
    except _BadToken:
        return 0  # reported with its line number by the caller


def _plain_integers(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> bool:
    """True when every token is a plain integer (optional sign, digits only)."""
    first = buf[starts]
    signed = (first == 45) | (first == 43)
    return bool(len(starts)) and not np.any(ends - starts - signed < 1) and \
        _parse_digits(buf, starts + signed, ends) is not None


_DASHES = ("\u2212", "\u2013", "\u2014", "\u2010", "\u2011", "\ufe63", "\uff0d")   # minus, en/em dash, hyphens
_POLARITY_WORDS = ("on", "off", "+", "-", "pos", "neg", "positive", "negative")
_SIZE_LINE = re.compile(r"^\d+\s*[x\u00d7,;:/]\s*\d+$", re.IGNORECASE)   # `640x480`, `640,480`: a mistyped `W H`
_QUOTED_THOUSANDS = re.compile(r'"\s*[+-]?\d{1,3}(,\d{3})+(\.\d*)?\s*"')   # "3,305": a spreadsheet's 1,000s


def _names_the_columns(words) -> bool:
    """Whether ``words`` name the four columns of an event file (a time, x, y and a polarity, units allowed:
    `t_us`, `time [s]`), as a names line does."""
    roots = {re.split(r"[_\[(]", w.lower(), maxsplit=1)[0] for w in words}
    return (len(words) == 4 and {"x", "y"} <= roots and bool(roots & {"t", "ts", "time", "timestamp", "timestamps"})
            and bool(roots & {"p", "pol", "polarity", "polarities"}))


def _token_hint(token: str, column: str, layout: TextLayout) -> str:
    """The fix for a value that does not parse, when its text shows the usual cause ('' when it does not):
    a Unicode minus or dash, a decimal comma or a trailing separator in a space-separated file, a polarity
    written as a word or a bare sign."""
    if any(d in token for d in _DASHES):
        return ("; it holds a Unicode minus sign or dash, not the ASCII '-' a number needs (a word processor or "
                "a copy from a web page puts it there): replace it with '-' (e.g. `sed 's/\u2212/-/g'`)")
    if column == "p" and token.strip().lower() in _POLARITY_WORDS:
        return ("; write the polarity as a number: 1 (or +1, or True) for ON / positive events, 0 (or -1, or "
                "False) for OFF / negative ones")
    if not layout.separators and re.fullmatch(r"[+-]?\d+,\d+", token):
        return ("; it has a decimal comma: write a decimal point (0.5), or name the file .csv with `;` between "
                "the values, a spreadsheet's layout, whose reader takes decimal commas")
    if not layout.separators and token[-1:] in ",;" and token[:-1]:
        return (f"; {token[-1]!r} follows the value, but a `t x y p` text file separates its values with spaces "
                "only: remove the separators, or name the file .csv")
    return ""


def _count_hint(text: str, first: bool, layout: TextLayout) -> str:
    """The fix for a line with the wrong number of values, when its text shows the usual cause ('' else)."""
    if first and layout.size_line and _SIZE_LINE.match(text):
        return ("; if it gives the sensor size, the `W H` line is the width and the height separated by a space "
                "(e.g. `640 480`)")
    if b'"' in layout.separators and _QUOTED_THOUSANDS.search(text):
        return ("; a quoted value holds commas as thousands separators (\"3,305\"): save the file again with the "
                "numbers written plainly (3305; in a spreadsheet, format the cells as numbers without the 1000 "
                "separator)")
    return ""


def _line_text(buf: np.ndarray, newlines: np.ndarray, line: int) -> str:
    """Line `line` (0-based) of buf, for error messages."""
    lo = int(newlines[line - 1]) + 1 if line > 0 else 0
    hi = int(newlines[line]) if line < len(newlines) else len(buf)
    text = bytes(buf[lo:hi]).decode("utf-8", "replace").strip()
    return text if len(text) <= 80 else text[:77] + "..."


def line_blocks(data: bytes, size: int = None):
    """(start, end) byte ranges of about ``size`` bytes (default :data:`CHUNK_BYTES`) that end at a
    newline (or at the end of ``data``): whole lines, so each range parses on its own."""
    size = CHUNK_BYTES if size is None else size
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
class EventBlock:
    """The columns of a block of `t x y p` lines."""

    t: np.ndarray                    # float64 [N], seconds relative to origin_ns
    x: np.ndarray                    # int64 [N], column
    y: np.ndarray                    # int64 [N], row
    p: np.ndarray                    # [N] as written: int8 when all in {-1, 0, 1}, else int64/float64
    header: tuple[int, int] | None   # (H, W) from a `W H` header line (first block only)
    origin_ns: int | None            # t_origin in integer nanoseconds (None: the block had no events)
    n_lines: int                     # lines in the block
    time_unit: str = "s"             # unit the timestamps were read in ('s', 'ms', 'us', 'ns')


def parse_event_block(buf, origin_ns: int | None, *, source, line_base: int = 0, first: bool = False,
                      t_last: float | None = None, time_unit: str = "s",
                      layout: TextLayout = TXT_LAYOUT) -> EventBlock:
    """Parse one block of whole `t x y p` lines, all vectorised.

    Args:
        buf: uint8 [B] (or bytes), whole lines.
        origin_ns: integer nanoseconds subtracted from every timestamp; None: picked from the first
            timestamp (its whole seconds when it is >= 1e5 s, an absolute clock; else 0).
        source: what to name in error messages (e.g. the file).
        line_base: lines before this block (for the line numbers in messages).
        first: the block opens the file, so an rpg_e2vid header `W H` may be its first line.
        t_last: the last timestamp of the previous block; when given, timestamps must not decrease.
        time_unit: unit of the timestamp tokens, 's', 'ms', 'us' or 'ns'; 'auto': plain integer
            tokens are microseconds (with a TimeUnitWarning), decimals seconds. The unit used is
            returned in ``EventBlock.time_unit`` (pass it to the next block).
        layout: where t, x, y, p sit on a line (:class:`TextLayout`; default `t x y p`).
    Raises:
        EventDataError naming ``source``, the line number and the line's text.
    """
    buf = np.frombuffer(buf, dtype=np.uint8) if isinstance(buf, (bytes, bytearray, memoryview)) else buf
    starts, ends, counts, newlines = _tokenize(buf, layout.separators)
    n_lines = len(newlines) + (0 if len(buf) == 0 or buf[-1] == 10 else 1)

    def fail(line, problem):  # line: 0-based within this block
        raise EventDataError(f"{source}, line {line_base + line + 1}: {problem} "
                             f"(line reads {_line_text(buf, newlines, line)!r})")

    def names_hint(line):  # a line of column names: say what it is and the ways out
        words = re.split(r"[\s,;]+", _line_text(buf, newlines, line).strip("\ufeff \t\"'"))
        if not all(_WORD.match(w) for w in words):
            return ""
        if not (first and line == int(np.flatnonzero(counts)[0])):   # after the events began: files joined
            if not _names_the_columns(words):   # a damaged line of words is not a names line
                return ""
            return ("; it names the columns again, as where two exports were joined into one file (`cat a.csv "
                    "b.csv`): delete that line, or read the files one by one and join them with Events.concatenate")
        if not layout.size_line:
            return ""
        return ("; it names the columns, but a `t x y p` text file holds only numbers: start that line with `#` "
                "(a comment), or name the file .csv, whose reader takes a first line naming the columns in any order")

    def row_line(row):  # 0-based line (in this block) of event row `row`
        return int(np.searchsorted(newlines, starts[row, 0]))

    def token_hint(row, c, column):  # the fix for token `row` of column `c` (t, x, y, p: 0..3) that did not parse
        text = bytes(buf[starts[row, c]:ends[row, c]]).decode("utf-8", "replace")
        return _token_hint(text, column, layout)

    header = None
    if first and counts.any():  # an rpg_e2vid header `W H` may open the file
        line = int(np.flatnonzero(counts)[0])
        words = [bytes(buf[s:e]) for s, e in zip(starts[:2], ends[:2])]
        if counts[line] == 2 and all(w.isdigit() for w in words):
            header = (int(words[1]), int(words[0]))  # (H, W)
            counts[line], starts, ends = 0, starts[2:], ends[2:]
    bad = np.flatnonzero((counts != 0) & (counts != 4))
    if bad.size:
        i = int(bad[0])
        opens = first and i == int(np.flatnonzero(counts)[0])
        hint = "" if counts[i] != 2 else (
            " (a `W H` first line gives the sensor size as two whole numbers: the width and the height, e.g. "
            "`640 480`)" if opens and layout.size_line else " (a `W H` header is allowed only as the first line)")
        fail(i, f"found {counts[i]} columns, expected 4: {layout.columns}{hint}{names_hint(i)}"
                f"{_count_hint(_line_text(buf, newlines, i), opens, layout)}")
    empty = np.zeros(0, dtype=np.int64)
    if time_unit != "auto" and not (isinstance(time_unit, str) and time_unit in TIME_UNITS):
        raise EventDataError(f"unknown time_unit={time_unit!r}; use one of {', '.join(TIME_UNITS)}")
    if len(starts) == 0:
        return EventBlock(np.zeros(0), empty, empty, empty.astype(np.int8), header, origin_ns, n_lines,
                          time_unit)
    order = list(layout.order)
    starts, ends = starts.reshape(-1, 4)[:, order], ends.reshape(-1, 4)[:, order]   # columns t, x, y, p
    if time_unit == "auto":
        time_unit = resolve_time_unit("i" if _plain_integers(buf, starts[:, 0], ends[:, 0]) else "f", None, source)

    if origin_ns is None:
        origin_ns = _first_time_origin(buf, starts[0, 0], ends[0, 0], time_unit)
    try:
        t = _parse_time(buf, starts[:, 0], ends[:, 0], origin_ns, time_unit)
    except _BadToken as err:
        fail(row_line(err.row), f"the timestamp is not a number; expected {layout.columns}"
             f"{names_hint(row_line(err.row)) or token_hint(err.row, 0, 't')}")
    xyp = []
    for c, name in ((1, "x"), (2, "y"), (3, "p")):
        try:
            xyp.append(_parse_number(buf, starts[:, c], ends[:, c]))
        except _BadToken as err:
            words = _parse_bool(buf, starts[:, c], ends[:, c]) if name == "p" else None
            if words is None:   # a polarity column of True / False (pandas' bool column) is 1 / 0
                fail(row_line(err.row), f"{name} is not a number; expected {layout.columns}"
                     f"{token_hint(err.row, c, name)}")
            xyp.append(words)
    x, y, p = xyp

    nonfinite = np.flatnonzero(~np.isfinite(t))
    if nonfinite.size:
        fail(row_line(nonfinite[0]), "the timestamp is not finite; drop or repair that line")
    far = np.flatnonzero(np.abs(t + origin_ns / NS) > MAX_CLOCK_S)   # absolute seconds
    if far.size:
        fail(row_line(far[0]), f"the timestamp is beyond any clock (over {MAX_CLOCK_S:.3g} s when read in "
             f"{time_unit!r}); the time column is damaged, or its unit is wrong (pass time_unit=)")
    if t_last is not None:
        back = np.flatnonzero(np.diff(t, prepend=t_last) < 0)
        if back.size:
            k = int(back[0])
            before, after = (t[k - 1] if k else t_last) + origin_ns / NS, t[k] + origin_ns / NS   # absolute seconds
            fail(row_line(k), "the timestamp is earlier than the one before: the events are not "
                 f"sorted by time; {layout.sort_hint} or load the columns "
                 "with numpy and use Events.from_arrays(..., sort=True)"
                 + wrap_hint(before, after, scales=(round(1 / TIME_UNITS[time_unit]),)))
    for name, v in (("x", x), ("y", y)):
        if v.dtype.kind == "f":
            not_whole = np.flatnonzero(~np.isfinite(v) | (v != np.round(v)))
            if not_whole.size:
                fail(row_line(not_whole[0]), f"{name} must be a whole pixel index")
            huge = np.flatnonzero(np.abs(v) >= MAX_PIXEL)   # too many digits for int64 parsing: read as floats
            if huge.size:
                fail(row_line(huge[0]), f"{name} = {v[huge[0]]:.6g} is no pixel index of any sensor (at most "
                     f"{MAX_SENSOR_SIDE} per side); the line is damaged: repair or drop it")
    if np.all(np.isin(p, (-1, 0, 1))):
        p = p.astype(np.int8)
    return EventBlock(t, x.astype(np.int64), y.astype(np.int64), p, header, origin_ns, n_lines, time_unit)


def read_text_bytes(path, what: str = "file") -> bytes:
    """The bytes of a text file, refusing (EventDataError naming the file) what is not one: a missing
    path, a folder, a FIFO / pipe / device (reading would block or never end), an empty file, an
    unreadable one, UTF-16/32 text, one whose end is zero bytes (a cut-off copy). A UTF-8 byte-order mark and
    DOS's end-of-file mark (a last Ctrl-Z) are dropped; a file whose lines end in CR alone (classic Mac OS,
    Excel for Mac's "CSV (Macintosh)") gets LF line ends (same length)."""
    import stat

    path = Path(path)
    try:
        st = path.stat()
    except FileNotFoundError:
        raise EventDataError(f"no such file: {path}; check the path") from None
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise EventDataError(f"{path} is a folder, not a {what}; pass the {what} (or the folder that holds it)")
    if not stat.S_ISREG(st.st_mode):
        raise EventDataError(f"{path} is not a regular file (a FIFO, pipe or device); save the data to a file first")
    try:
        data = path.read_bytes()
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror}); check its permissions") from None
    if not data.strip():
        raise EventDataError(f"{path} is empty; expected lines {EVENT_COLUMNS}" if what == "event file"
                             else f"{path} is empty")
    bom = 3 if data.startswith(b"\xef\xbb\xbf") else 0
    data = data[bom:]
    text = data.rstrip(b"\x00")
    if len(text) < len(data) and text.strip() and b"\x00" not in text:   # zero-filled tail: a cut-off copy
        lines = text.count(b"\n") + (not text.endswith(b"\n"))
        raise EventDataError(f"{path} ends in {len(data) - len(text):,} zero bytes (NUL) after line {lines:,}: the file "
                             "was not written completely (a copy or a recording cut off by a crash or a full disk "
                             "leaves its end zero-filled); copy it again, or keep the lines before the zeros "
                             f"(`truncate -s {bom + len(text)} {path}`) if they are all there is")
    if data.endswith(b"\x1a"):   # DOS's end-of-file mark (Ctrl-Z), as old Windows tools append it: not data
        data = data[:-1] + b" "
    if data.startswith((b"\xff\xfe", b"\xfe\xff")) or b"\x00" in data[:4096]:
        raise EventDataError(f"{path}: UTF-16/32 or binary content, not plain text; save it as plain UTF-8 (ASCII) "
                             f"text with lines {EVENT_COLUMNS}")
    if b"\n" not in data and b"\r" in data.rstrip(b"\r"):   # old Mac line ends (Excel for Mac's "CSV (Macintosh)")
        data = data.replace(b"\r", b"\n")                    # same length: byte offsets and line numbers kept
    return data


def blank_leading_comments(data: bytes) -> tuple[bytes | bytearray, list[int]]:
    """(``data`` with the comment lines (`#` or `%` first) before the first event blanked (same length: byte
    offsets and line numbers kept), as a tool or a hand writes a note or the columns' names on top; the
    1-based numbers of those lines)."""
    spans, lines, pos = [], [], 0
    while pos < min(len(data), CHUNK_BYTES):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        raw = data[pos:end]
        line = raw.strip()
        if b"\r" in raw.rstrip(b"\r"):   # old Mac line ends (CR only): no lines to tell apart here
            break
        if line.startswith((b"#", b"%")):
            spans.append((pos, end))
            lines.append(data.count(b"\n", 0, pos) + 1)
        elif line and not (len(line.split()) == 2 and all(w.isdigit() for w in line.split())):   # not `W H`
            break
        pos = end + 1
    if not spans:
        return data, lines
    data = bytearray(data)
    for lo, hi in spans:
        data[lo:hi] = b" " * (hi - lo)
    return data, lines


def _check_origin_ns(origin_ns):
    """The text parsers' ``origin_ns``: None (from the first timestamp) or whole nanoseconds (text was Python's "//"
    error, 1.5 or True taken as an origin)."""
    if origin_ns is None:
        return None
    try:
        return whole_number(origin_ns, "origin_ns")
    except EventDataError:
        raise EventDataError(f"origin_ns= must be whole nanoseconds (the clock's origin, an int) or None to take it "
                             f"from the first timestamp, got {origin_ns!r:.60}") from None


def _byte_buffer(data) -> bool:
    """Whether ``data`` holds bytes one by one (bytes, bytearray, memoryview, mmap, a 1-D uint8 array: what
    np.frombuffer reads as the file's bytes); text and arrays of wider numbers do not."""
    if isinstance(data, str):
        return False
    try:
        view = memoryview(data)
    except TypeError:
        return False
    return view.itemsize == 1 and view.ndim == 1


def parse_event_text(path, origin_ns: int | None = None, *, time_unit: str = "auto", data: bytes | bytearray | None = None,
                     layout: TextLayout = TXT_LAYOUT) -> EventBlock:
    """A whole `t x y p` text file (optionally after a `W H` header), block by block.

    Comment lines (`#` or `%` first) before the first event are skipped.
    Timestamps must be finite and non-decreasing. ``origin_ns`` None picks the origin from the
    first timestamp. ``time_unit``: see :func:`parse_event_block` ('auto': integers are
    microseconds, decimals seconds). ``data``: the file's bytes when the caller has read (and
    prepared) them already; ``layout``: the columns' order and separators, and whether a `W H` line
    may open the file (:class:`TextLayout`). Raises EventDataError naming the file and line.
    """
    check_path_type(path, "path", "the event text file")   # None or 5 was Python's "expected str, bytes or os.PathLike"
    origin_ns = _check_origin_ns(origin_ns)
    if data is not None and not _byte_buffer(data):   # text was np.frombuffer's error
        raise ArgumentTypeError(f"data= must be the file's bytes (bytes, bytearray, memoryview, mmap or a 1-D uint8 "
                                f"array; text: data.encode()) or None to read the file, got {type(data).__name__}"
                                + (f" of {data.dtype} {data.shape}" if isinstance(data, np.ndarray) else ""))
    if not isinstance(layout, TextLayout):   # None was "has no attribute 'size_line'"
        raise ArgumentTypeError(f"layout= must be a TextLayout (e.g. TXT_LAYOUT, the default), got "
                                f"{type(layout).__name__}")
    path = Path(path)
    comments = []
    if data is None:
        data, comments = blank_leading_comments(read_text_bytes(path, "event file"))
    everything = np.frombuffer(data, dtype=np.uint8)
    parts, header, line_base, t_last = [], None, 0, -np.inf
    for lo, hi in line_blocks(data, CHUNK_BYTES):
        block = parse_event_block(everything[lo:hi], origin_ns, source=path, line_base=line_base,
                                  first=layout.size_line and lo == 0, t_last=t_last, time_unit=time_unit, layout=layout)
        header = block.header if lo == 0 else header
        origin_ns = block.origin_ns
        line_base += block.n_lines
        if len(block.t):
            time_unit = block.time_unit
            parts.append((block.t, block.x, block.y, block.p))
            t_last = block.t[-1]
    if not parts:
        said = "" if not comments else (f" (line {comments[0]} is a comment)" if len(comments) == 1 else
                                        f" (lines {', '.join(map(str, comments))} are comments)")
        raise EventDataError(f"{path}: no events found{said}; expected lines {layout.columns}")
    t, x, y, p = (np.concatenate(c) for c in zip(*parts))
    return EventBlock(t, x, y, p, header, origin_ns, line_base, time_unit)


def parse_frame_list(buf, origin_ns: int | None, *, source, time_unit: str = "s") -> tuple[np.ndarray, list[str], int]:
    """IJRR images.txt (`t images/frame_%08d.png` per line) -> (t float64 [F] s, names, origin_ns).

    ``origin_ns`` None picks it from the first timestamp, as for the events. Raises EventDataError
    naming ``source`` and the line; a listing with no lines gives ([], [], origin_ns).
    """
    buf = np.frombuffer(buf, dtype=np.uint8) if isinstance(buf, (bytes, bytearray, memoryview)) else buf
    if not isinstance(buf, np.ndarray) or buf.dtype != np.uint8 or buf.ndim != 1:   # None, text: numpy's errors
        raise ArgumentTypeError(f"buf= must be the listing's bytes (bytes, or a uint8 array of them; text: "
                                f"text.encode()), got {type(buf).__name__}"
                                + (f" of {buf.dtype} {buf.shape}" if isinstance(buf, np.ndarray) else ""))
    origin_ns = _check_origin_ns(origin_ns)
    if not (isinstance(time_unit, str) and time_unit in TIME_UNITS):   # was a KeyError
        raise EventDataError(f"unknown time_unit={time_unit!r}; use one of {', '.join(TIME_UNITS)}")
    starts, ends, counts, newlines = _tokenize(buf)
    bad = np.flatnonzero((counts != 0) & (counts != 2))
    if bad.size:
        i = int(bad[0])
        raise EventDataError(f"{source}, line {i + 1}: found {counts[i]} columns, expected 2: {FRAME_COLUMNS} "
                             f"(file names without spaces; line reads {_line_text(buf, newlines, i)!r})")
    if len(starts) == 0:
        return np.zeros(0), [], origin_ns
    starts, ends = starts.reshape(-1, 2), ends.reshape(-1, 2)
    if origin_ns is None:
        origin_ns = _first_time_origin(buf, starts[0, 0], ends[0, 0], time_unit)
    try:
        t = _parse_time(buf, starts[:, 0], ends[:, 0], origin_ns, time_unit)
    except _BadToken as err:
        i = int(np.searchsorted(newlines, starts[err.row, 0]))
        raise EventDataError(f"{source}, line {i + 1}: the timestamp is not a number "
                             f"(line reads {_line_text(buf, newlines, i)!r})") from None
    if not np.all(np.isfinite(t)):
        i = int(np.searchsorted(newlines, starts[int(np.flatnonzero(~np.isfinite(t))[0]), 0]))
        raise EventDataError(f"{source}, line {i + 1}: the timestamp is not finite "
                             f"(line reads {_line_text(buf, newlines, i)!r})")
    names = [bytes(buf[s:e]).decode("utf-8", "replace") for s, e in zip(starts[:, 1], ends[:, 1])]
    return t, names, origin_ns
