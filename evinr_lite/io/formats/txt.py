"""A text file of `t x y p` lines (IJRR events.txt, rpg_e2vid .txt with an optional `W H` first line).

Parsed by :mod:`evinr_lite.io.text` (vectorised, exact on absolute clocks). The whole file is read;
a source over it slices the events in memory.
"""
from __future__ import annotations

from collections.abc import MutableMapping
from pathlib import Path

from ...core.checks import check_path_type, require
from ...core.events import Events, EventDataError, check_time_span
from ...core.recording import Recording
from ..text import NS, origin_to_ns, parse_event_text
from .base import (FileFormat, build_events, check_time_spread, note_decimal_seconds, own_meta, sensor_from_header,
                   size_hint)

__all__ = ["read_events_txt", "read_txt", "looks_like_event_text", "FORMAT"]


def read_events_txt(path, sensor_size=None, *, polarity="auto", t_origin=None, time_unit="auto",
                    meta: dict | None = None) -> Events:
    """Events from a text file of `t x y p` lines (IJRR events.txt, rpg_e2vid .txt).

    Args:
        path: text file; t in seconds, x column, y row, p polarity. An optional first line `W H`
            (two integers, width first: the rpg_e2vid header) gives the sensor size.
        sensor_size: (H, W); required unless the file has the header (then they must agree).
        polarity: encoding of p ('auto', '01', 'pm1').
        t_origin: seconds subtracted from every timestamp (exactly). None: the whole seconds of the
            first timestamp when it is >= 1e5 s (an absolute clock), else 0.
        time_unit: unit of t, 's', 'ms', 'us', 'ns'; 'auto': integer timestamps are microseconds
            (with a TimeUnitWarning), decimals seconds. Implausible spans are refused; decimals that
            come too slowly for seconds get a note (:func:`~.base.note_decimal_seconds`).
        meta: where notes go (``meta["read_notes"]``); they are also warnings (ReadNote).
    """
    path = Path(check_path_type(path, "path", "the event file"))
    require(meta, MutableMapping, "meta", none_ok=True)   # a number or text: the notes were dropped without a word
    raw = parse_event_text(path, None if t_origin is None else origin_to_ns(t_origin), time_unit=time_unit)
    check_time_spread(float(raw.t[0]), float(raw.t[-1]), len(raw.t), path)   # sorted by the parser
    check_time_span(raw.t, path, raw.time_unit)
    note_decimal_seconds(raw.t[0], raw.t[-1], len(raw.t), time_unit, raw.time_unit, path, meta)
    sensor_size = sensor_from_header(path, raw.header, sensor_size)
    if sensor_size is None:
        raise EventDataError(
            f"{path}: the sensor size is unknown (no `W H` header line); pass sensor_size=(H, W) "
            f"(rows, columns){size_hint(raw.x, raw.y)}"
        )
    return build_events(path, raw.t, raw.x, raw.y, raw.p, sensor_size,
                         polarity=polarity, t_origin=raw.origin_ns / NS)


def read_txt(path, **options) -> Recording:
    """:func:`read_events_txt` as a Recording (no frames)."""
    meta = own_meta("read_txt", "txt", path, options)
    return Recording(read_events_txt(path, meta=meta, **options), None, meta)


def looks_like_event_text(path: Path) -> bool:
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


def _sniff(path, head) -> bool:
    return head is not None and Path(path).suffix.lower() != ".txt" and looks_like_event_text(Path(path))


FORMAT = FileFormat(
    name="txt", description="a `t x y p` .txt file (optional `W H` header line)", reader=read_txt,
    suffixes=(".txt",), sniff=_sniff, by_suffix=True, needs_sensor_size=True, takes_sensor_size=True,
    options=("polarity", "t_origin", "time_unit"), priority=90)
