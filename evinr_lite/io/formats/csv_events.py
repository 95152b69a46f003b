"""A .csv file of events: Metavision's `x,y,p,t` or any order that a header line names.

Two layouts are read, both parsed by :mod:`evinr_lite.io.text` (vectorised, exact on absolute clocks):

- Prophesee Metavision's ``metavision_file_to_csv``: lines `x,y,p,t` with t in integer microseconds,
  after an optional `%geometry:W,H` line that gives the sensor size;
- a header line that names the four columns in any order, e.g. `t,x,y,p` or
  `timestamp_us,x,y,polarity`. Names (any case): t, ts, time, timestamp; x; y; p, pol, polarity. A
  unit may follow the time's name (`t_us`, `time [ms]`, `timestamp(ns)`; s, ms, us, ns).

Without a names line the order is read off the first rows: `t,x,y,p` when the first column never
decreases and the last holds polarities, `x,y,p,t` (Metavision) when the last column never
decreases and the third holds polarities; anything else is refused with the fix (add a names line).
Lines that open the file with `%` or `#` are comments. Commas, semicolons, double quotes and white
space all separate values; in a file whose values are separated by semicolons, a comma is the decimal
mark (`0,0125;12;7;1`, as spreadsheets in many locales write). The polarity may be written `True` /
`False` (pandas' bool column). The whole file is read; a source over it slices the events in memory.
"""
from __future__ import annotations

import re
from collections.abc import MutableMapping
from pathlib import Path

import numpy as np

from ...core.checks import check_path_type, require
from ...core.events import MAX_SENSOR_SIDE, Events, EventDataError, check_time_span
from ...core.recording import Recording
from ..text import NS, TextLayout, origin_to_ns, parse_event_text, read_text_bytes
from .base import (FileFormat, build_events, own_meta, check_declared_size, check_time_spread, note_decimal_seconds,
                   size_hint)

__all__ = ["read_events_csv", "read_csv", "csv_layout", "FORMAT"]

ROLE_NAMES = {"t": ("t", "ts", "time", "timestamp", "timestamps"), "x": ("x",), "y": ("y",),
              "p": ("p", "pol", "polarity")}
UNITS = {"s": "s", "ms": "ms", "us": "us", "\u00b5s": "us", "ns": "ns"}
SNIFF_ROWS = 1000          # rows read to tell the order when no line names the columns
SNIFF_BYTES = 1 << 16      # at most this many bytes of them
_NAME = re.compile(r"^(?P<name>[a-z]+)(?:[\s_]*[\[(]?(?P<unit>s|ms|us|\u00b5s|ns)[\])]?)?$")
_GEOMETRY = re.compile(rb"^%\s*geometry\s*:\s*(\d+)\s*[,x ]\s*(\d+)\s*$", re.IGNORECASE)
SEPARATORS = b",;\""        # besides white space (a quote around a value, as csv.QUOTE_ALL writes, separates too)
_SEPARATORS = bytes.maketrans(SEPARATORS, b" " * len(SEPARATORS))
NAMED = "a first line naming the columns, e.g. `t,x,y,p` or `x,y,p,t` (t in seconds unless named `t_us`, `t_ms`...)"
SORT_HINT = "sort the rows by the time column"


def _layout(order_names: tuple, how: str) -> TextLayout:
    """The parser's layout for columns named ``order_names`` (the role of each column, in file order)."""
    written = ",".join(order_names)
    return TextLayout(order=tuple(order_names.index(r) for r in "txyp"),
                      columns=f"`{written}` ({how}; x = column, y = row, polarity)", sort_hint=SORT_HINT,
                      separators=SEPARATORS, size_line=False)


def _header(path: Path, data: bytes) -> tuple[list, tuple | None, list | None, str | None]:
    """(the header's byte spans [(start, end)], (H, W) from `%geometry:W,H` or None, the column roles
    in file order from a names line or None, the time unit that line names or None)."""
    spans, geometry, roles, unit, pos = [], None, None, None, 0
    while pos < len(data):
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        line = data[pos:end].strip()
        if line.startswith((b"%", b"#")):
            m = _GEOMETRY.match(line)
            if m:
                W, H = int(m.group(1)), int(m.group(2))
                if not (0 < W <= MAX_SENSOR_SIDE and 0 < H <= MAX_SENSOR_SIDE):
                    raise EventDataError(f"{path}: the line {line.decode(errors='replace')!r} gives a sensor of {H}x{W} "
                                         f"(H x W), which no event camera has (1 to {MAX_SENSOR_SIDE} pixels per side); "
                                         "repair it, or remove it and pass the sensor size")
                geometry = (H, W)
            spans.append((pos, end))
        elif line:
            if not _numbers(line):   # a line of names, not of values
                roles, unit = _names(path, line)
                spans.append((pos, end))
            break
        else:
            spans.append((pos, end))
        pos = end + 1
    return spans, geometry, roles, unit


def _value(token: bytes) -> float:
    """A value of a row for telling the columns apart: a number, or True / False as 1 / 0."""
    word = token.lower()
    return 1.0 if word == b"true" else 0.0 if word == b"false" else float(token)


def _decimal_comma(data: bytes, start: int) -> bool:
    """The first row after the header separates its values with semicolons and holds a comma: a spreadsheet's
    export in a locale whose decimal mark is the comma (`0,0125;12;7;1`)."""
    for line in bytes(data[start:start + SNIFF_BYTES]).split(b"\n", SNIFF_ROWS)[:SNIFF_ROWS]:
        line = line.strip()
        if line and not line.startswith((b"%", b"#")):
            return b";" in line and b"," in line
    return False


def _numbers(line: bytes) -> bool:
    """Every value of the line parses as a number (or is True / False)."""
    try:
        [_value(v) for v in line.translate(_SEPARATORS).split()]
    except ValueError:
        return False
    return True


def _roles(names: list) -> tuple[list | None, str | None]:
    """The role (t, x, y, p) of each of ``names`` (None when one names no role) and the time's unit (or None)."""
    roles, unit = [], None
    for n in names:
        m = _NAME.match(n)
        role = next((r for r, known in ROLE_NAMES.items() if m and m.group("name") in known), None)
        if role is None or (m.group("unit") and role != "t"):
            return None, None
        roles.append(role)
        unit = UNITS[m.group("unit")] if role == "t" and m.group("unit") else unit
    return roles, unit


def _names(path: Path, line: bytes) -> tuple[list, str | None]:
    """The role (t, x, y, p) of each named column and the unit the time's name gives (or None)."""
    text = line.decode("utf-8", errors="replace")
    separator = r"[,;\t]" if re.search(r"[,;\t]", text) else r"\s+"   # `t x y p` in a .csv: white space
    names = [n.strip().strip("'\"").lower() for n in re.split(separator, text.strip())]
    while names and not names[-1]:   # a trailing separator (as on every row of some exports)
        names.pop()
    roles, unit = _roles(names)
    if roles is None and len(names) == 5 and names[0] in ("", "unnamed: 0", "index") and \
            sorted(_roles(names[1:])[0] or ()) == ["p", "t", "x", "y"]:
        raise EventDataError(f"{path}: the first line names the columns {names}: the first, {names[0]!r}, is an "
                             "index column, as pandas writes by default, not a value of an event; write the file "
                             "again with df.to_csv(path, index=False), or drop that column")
    if roles is None or sorted(roles) != ["p", "t", "x", "y"]:
        raise EventDataError(f"{path}: the first line names the columns {names}, but an event file needs exactly "
                             "four: the time (t, ts, time or timestamp, optionally with a unit: t_us, time [ms]), "
                             "x (column), y (row) and the polarity (p, pol or polarity); rename them, e.g. `t,x,y,p`")
    return roles, unit


def _guess_order(path: Path, data: bytes, start: int) -> tuple:
    """The roles of the columns from the first :data:`SNIFF_ROWS` rows when no line names them."""
    rows, head = [], bytes(data[start:start + SNIFF_BYTES])   # a bounded slice: the file may be GBs
    for line in head.split(b"\n", SNIFF_ROWS)[:SNIFF_ROWS]:
        values = line.translate(_SEPARATORS).split()
        if not values:
            continue
        try:
            rows.append([_value(v) for v in values])
        except ValueError:
            break
        if len(values) != 4:
            break
    if not rows and not head.strip():
        raise EventDataError(f"{path}: no events found after the header; expected lines such as `t,x,y,p` or "
                             "Metavision's `x,y,p,t`")
    ok = len(rows) > 0 and all(len(r) == 4 for r in rows)
    if ok:
        a = np.asarray(rows)
        polarity = lambda c: bool(np.all(np.isin(a[:, c], (-1.0, 0.0, 1.0))))   # noqa: E731
        rising = lambda c: bool(np.all(np.diff(a[:, c]) >= 0))                  # noqa: E731
        fits = [order for order, t_col, p_col in ((("t", "x", "y", "p"), 0, 3), (("x", "y", "p", "t"), 3, 2))
                if rising(t_col) and polarity(p_col)]
        if len(fits) == 1:
            return fits[0]
    raise EventDataError(f"{path}: cannot tell which column is which: the first rows fit neither `t,x,y,p` (the first "
                         "column never decreasing, the last a polarity) nor Metavision's `x,y,p,t` exactly once "
                         f"(or the rows are not sorted by time, or a row is damaged); add {NAMED}")


def csv_layout(path, data: bytes, time_unit: str = "auto") -> tuple[bytes | bytearray, TextLayout, tuple | None, str]:
    """(the file's bytes ready for the event-text parser: header and comment lines blanked, line numbers
    kept; the columns' layout (commas and semicolons separate values); (H, W) from `%geometry:W,H` or None; the time unit
    to read with), from the raw bytes ``data`` of the .csv file ``path``."""
    path = Path(path)
    spans, geometry, roles, unit = _header(path, data)
    if _decimal_comma(data, spans[-1][1] + 1 if spans else 0):   # `0,0125;12;7;1`: the comma is the decimal mark
        data = bytes(data).replace(b",", b".")                     # same length: byte offsets and line numbers kept
    if roles is not None:
        if unit is not None and time_unit not in ("auto", unit):
            raise EventDataError(f"{path}: the header names the time in {unit!r}, but time_unit={time_unit!r} was "
                                 f"passed; leave time_unit out (or rename the column)")
        how = f"t in {unit}" if unit else "t in seconds, or integers in microseconds"
        time_unit = unit or time_unit
    else:
        roles = list(_guess_order(path, data, spans[-1][1] + 1 if spans else 0))
        metavision = roles == ["x", "y", "p", "t"]
        how = "Metavision: t in integer microseconds" if metavision else "t in seconds, or integers in microseconds"
        if metavision and time_unit == "auto":
            time_unit = "us"
    if spans:                     # one copy, only when there is a header to blank
        data = bytearray(data)
        for lo, hi in spans:
            data[lo:hi] = b" " * (hi - lo)
    return data, _layout(tuple(roles), how), geometry, time_unit


def read_events_csv(path, sensor_size=None, *, polarity="auto", t_origin=None, time_unit="auto",
                    meta: dict | None = None) -> Events:
    """Events from a .csv file (Metavision's `x,y,p,t`, or columns named by a header line).

    Args:
        path: the .csv file (see the module's docstring for the layouts read).
        sensor_size: (H, W); required unless the file has a `%geometry:W,H` line (then they must agree).
        polarity: encoding of p ('auto', '01', 'pm1').
        t_origin: seconds subtracted from every timestamp (exactly). None: the whole seconds of the
            first timestamp when it is >= 1e5 s (an absolute clock), else 0.
        time_unit: unit of t, 's', 'ms', 'us', 'ns'; 'auto': the unit the header names, microseconds
            for Metavision's layout, else integers are microseconds (with a TimeUnitWarning) and
            decimals seconds.
        meta: where notes go (``meta["read_notes"]``).
    """
    path = Path(check_path_type(path, "path", "the event file"))
    require(meta, MutableMapping, "meta", none_ok=True)   # a number or text: the notes were dropped without a word
    data, layout, geometry, unit = csv_layout(path, read_text_bytes(path, "event file"), time_unit)
    raw = parse_event_text(path, None if t_origin is None else origin_to_ns(t_origin), time_unit=unit, data=data,
                           layout=layout)
    check_time_spread(float(raw.t[0]), float(raw.t[-1]), len(raw.t), path)
    check_time_span(raw.t, path, raw.time_unit)
    note_decimal_seconds(raw.t[0], raw.t[-1], len(raw.t), unit, raw.time_unit, path, meta)
    if geometry is not None:
        check_declared_size(path, geometry, sensor_size, "`%geometry:W,H` line")
        sensor_size = geometry
    if sensor_size is None:
        raise EventDataError(f"{path}: the sensor size is unknown (no `%geometry:W,H` line); pass sensor_size=(H, W) "
                             f"(rows, columns){size_hint(raw.x, raw.y)}")
    return build_events(path, raw.t, raw.x, raw.y, raw.p, sensor_size, polarity=polarity,
                        t_origin=raw.origin_ns / NS)


def read_csv(path, **options) -> Recording:
    """:func:`read_events_csv` as a Recording (no frames)."""
    meta = own_meta("read_csv", "csv", path, options)
    return Recording(read_events_csv(path, meta=meta, **options), None, meta)


def _sniff(path, head) -> bool:
    """Metavision's `%geometry:` first line (a .csv is also taken by its suffix)."""
    return head is not None and _GEOMETRY.match(head.split(b"\n", 1)[0].strip()) is not None


FORMAT = FileFormat(
    name="csv", description="a .csv of events (Metavision's `x,y,p,t` with an optional `%geometry:W,H` line, or "
                            "columns named by a header line such as `t,x,y,p`)", reader=read_csv,
    suffixes=(".csv",), sniff=_sniff, by_suffix=True, needs_sensor_size=True, takes_sensor_size=True,
    options=("polarity", "t_origin", "time_unit"), priority=91)
