"""An ``.npy`` array [N, 4] of events (columns ``txyp`` by default), read a window at a time.

The array records neither the sensor size (``sensor_size=`` is needed) nor the time unit (integers
are taken as microseconds with a TimeUnitWarning, floats as seconds; ``time_unit=`` sets it). A
window (``t_start`` / ``t_end``, or :class:`NpySource`) is found by bisection on the time column
(one element read per step) and only its rows are read.
"""
from __future__ import annotations

from collections.abc import MutableMapping
from pathlib import Path

import numpy as np

from ...core.checks import require
from ...core.events import EventDataError, Events, check_time_span, resolve_time_unit
from ...core.recording import Recording
from ..source import RecordingSource
from .base import (Clock, FileFormat, bisect_seconds, build_events, check_reader_window, check_time_spread, existing,
                   load_npy, note_decimal_seconds, own_meta, probe_sorted, size_hint, to_seconds)

__all__ = ["read_events_npy", "read_npy", "NpySource", "FORMAT", "MAGIC"]

MAGIC = b"\x93NUMPY"


class _Rows:
    """Rows of an [N, 4] .npy file read with plain file reads at their offset (not through a memory map:
    the kernel's read-ahead would map megabytes around each element a bisection touches, and count
    them in the process's memory). ``table[lo:hi]`` -> array [hi - lo, 4]; ``column(i)`` -> a column
    whose elements ``column[k]`` are read one at a time. Fortran-ordered files use the memory map."""

    def __init__(self, path, mapped: np.memmap):
        self.path, self.shape, self.dtype = path, mapped.shape, mapped.dtype
        self.offset = int(mapped.offset)
        self.mapped = mapped if not mapped.flags.c_contiguous else None
        if self.mapped is None and path.stat().st_size < self.offset + mapped.size * mapped.dtype.itemsize:
            raise EventDataError(f"{path}: the .npy header claims {mapped.shape} but the file is shorter; it is "
                                 "damaged or incomplete")

    def __len__(self) -> int:
        return int(self.shape[0])

    def __getitem__(self, rows: slice) -> np.ndarray:
        lo, hi, _ = rows.indices(len(self))
        if self.mapped is not None:
            return np.array(self.mapped[lo:hi])
        with open(self.path, "rb") as f:
            f.seek(self.offset + lo * 4 * self.dtype.itemsize)
            block = np.fromfile(f, dtype=self.dtype, count=max(hi - lo, 0) * 4)
        return block.reshape(-1, 4)

    def column(self, index: int) -> "_Column":
        return _Column(self, index)


class _Column:
    """One column of a :class:`_Rows`, element by element (for bisection)."""

    def __init__(self, rows: _Rows, index: int):
        self.rows, self.index, self.shape = rows, index, (len(rows),)

    def __getitem__(self, k: int):
        return self.rows[int(k):int(k) + 1][0, self.index]


class _Opened:
    """A checked [N, 4] .npy file: its rows, time column, clock and time unit."""

    def __init__(self, path, sensor_size, columns, time_unit):
        self.path = path = existing(path)
        if not isinstance(columns, str) or sorted(columns) != sorted("txyp"):
            raise EventDataError(f"columns must be a permutation of 'txyp' (e.g. 'txyp' or 'xytp'), got {columns!r}")
        a = load_npy(path, mmap=True)
        if a.dtype.names:   # a structured array (Metavision's EventCD buffers, tonic): one record per event
            names = list(a.dtype.names)
            raise EventDataError(
                f"{path}: a structured array with fields {names} (one record per event), not the [N, 4] array read "
                "here; save its fields as columns t, x, y, p, e.g. a = np.load(path); np.save('events.npy', "
                "np.stack([a['t'], a['x'], a['y'], a['p']], axis=1)) with your fields' names (an integer t is "
                "read as microseconds), and pass that with --sensor HxW")
        if a.ndim == 2 and a.shape[0] == 4 and a.shape[1] != 4 and a.dtype.kind in "iuf":
            raise EventDataError(
                f"{path}: the array has shape {a.shape}: 4 rows of {a.shape[1]} values, the events' columns stored "
                f"as rows (transposed); save it the other way round, np.save(path, np.load(path).T), so that it is "
                f"[N, 4] with columns {' '.join(columns)}")
        if a.ndim != 2 or a.shape[1] != 4 or a.dtype.kind not in "iuf":
            raise EventDataError(
                f"{path}: expected a numeric array of shape [N, 4] with columns {' '.join(columns)} "
                f"(set columns= for another order), got shape {a.shape} and dtype {a.dtype}; for an EVREAL "
                "folder (events_ts.npy, events_xy.npy, ...) use read_evreal_folder"
            )
        self.array, self.columns = _Rows(path, a), columns
        self.t = self.array.column(columns.index("t"))
        n = len(self.array)
        if sensor_size is None:
            head = self.array[:100_000]
            col = {c: head[:, i] for i, c in enumerate(columns)}
            raise EventDataError(
                f"{path}: an .npy array does not record the sensor size; pass sensor_size=(H, W) (rows, columns)"
                + size_hint(col["x"], col["y"]) + (" (from the first 100,000 events)" if n > 100_000 else "")
            )
        self.sensor_size = sensor_size
        self.unit = resolve_time_unit(a.dtype.kind, time_unit, path)
        if a.dtype.kind == "f" and a.dtype.itemsize < 8 and self.unit == "s":
            raise EventDataError(f"{path}: the array is {a.dtype}; float32/float16 timestamps lose microseconds (and "
                                 "whole seconds on absolute clocks): save it as float64, or with integer "
                                 "microseconds and time_unit='us'")
        if n and not np.isfinite(float(self.t[0])):
            raise EventDataError(f"{path}: the first timestamp is {float(self.t[0])} (non-finite); repair or drop it")
        self.clock = Clock(self.t[0] if n else 0, self.unit, a.dtype.kind in "iu")
        if n >= 2:   # every event at one instant: a damaged time column, refused before any window is read
            check_time_spread(float(self.clock.seconds(self.t[0])), float(self.clock.seconds(self.t[n - 1])), n, path)

    def note_units(self, time_unit, meta) -> None:
        """A note when decimal timestamps detected as seconds come too slowly for seconds."""
        n = len(self.array)
        if n > 1:
            first, last = self.clock.seconds(self.t[0]), self.clock.seconds(self.t[n - 1])
            note_decimal_seconds(float(first), float(last), n, time_unit, self.unit, self.path, meta)

    def rows(self, lo: int, hi: int, polarity: str) -> Events:
        block = self.array[lo:hi]   # only these rows are read from disk
        col = {c: block[:, i] for i, c in enumerate(self.columns)}
        t = self.clock.seconds(col["t"])
        check_time_span(t, self.path, self.unit)
        return build_events(self.path, t, col["x"], col["y"], col["p"], self.sensor_size, polarity=polarity,
                            t_origin=self.clock.origin)

    def window(self, t_start, t_end) -> tuple[int, int]:
        n = len(self.array)
        lo = 0 if t_start is None else bisect_seconds(self.t, self.clock, t_start, 0, n, self.path)
        hi = n if t_end is None else bisect_seconds(self.t, self.clock, t_end, lo, n, self.path)
        return lo, hi


# the .npy's own ways out of unsorted times: its reader sorts in memory, numpy sorts the file
NPY_SORT = (" (numpy: a = np.load(path); np.save(path, a[np.argsort(a[:, 0], kind='stable')]), with the time "
            "in column 0; or read it in Python with evinr_lite.io.read_events_npy(path, sort=True))")


def read_events_npy(path, sensor_size=None, *, columns="txyp", polarity="auto", time_unit="auto",
                    sort=False, t_start: float | None = None, t_end: float | None = None,
                    meta: dict | None = None) -> Events:
    """Events from an .npy array [N, 4].

    Args:
        path: .npy file holding an [N, 4] numeric array.
        sensor_size: (H, W); required (an .npy array does not record it).
        columns: order of the columns, a permutation of 'txyp' (e.g. 'xytp' for MVSEC).
        polarity: encoding of p, see :func:`~evinr_lite.core.events.normalize_polarity`.
        time_unit: unit of t: 's', 'ms', 'us' or 'ns'; 'auto': an integer array is microseconds
            (with a TimeUnitWarning), a floating-point one seconds. Implausible spans are refused.
        sort: sort the events by time instead of raising on unsorted input (reads the whole file).
        t_start, t_end: seconds on the returned clock; only the rows with t_start <= t < t_end are
            read (found by bisection on the time column on disk; the times must be sorted).
        meta: where notes go (``meta["read_notes"]``); they are also warnings (ReadNote).
    """
    t_start, t_end = check_reader_window(t_start, t_end)   # 0-d, Fraction, Decimal: floats
    require(meta, MutableMapping, "meta", none_ok=True)   # a number or text: the notes were dropped without a word
    opened = _Opened(path, sensor_size, columns, time_unit)
    opened.note_units(time_unit, meta)
    if sort:
        block = opened.array[:]
        col = {c: block[:, i] for i, c in enumerate(columns)}
        t, origin, _ = to_seconds(opened.path, col["t"], time_unit)
        events = build_events(opened.path, t, col["x"], col["y"], col["p"], sensor_size, polarity=polarity,
                              t_origin=origin, sort=True)
        return events if t_start is None and t_end is None else events.slice_time(t_start, t_end)
    if t_start is None and t_end is None:
        return opened.rows(0, len(opened.array), polarity)
    probe_sorted(opened.t, opened.path, also=NPY_SORT)
    lo, hi = opened.window(t_start, t_end)
    if hi <= lo:
        n = len(opened.array)
        span = (f"[{float(opened.clock.seconds(opened.t[0])):.6f}, {float(opened.clock.seconds(opened.t[n - 1])):.6f}] s"
                if n else "nothing (no events)")
        raise EventDataError(f"{opened.path}: no events in the window [{t_start}, {t_end}) s; the events cover {span} "
                             f"(relative to t_origin = {opened.clock.origin}); choose a window inside that range")
    return opened.rows(lo, hi, polarity)


def read_npy(path, **options) -> Recording:
    """:func:`read_events_npy` as a Recording (no frames)."""
    meta = own_meta("read_npy", "npy", path, options)
    return Recording(read_events_npy(path, meta=meta, **options), None, meta)


class NpySource(RecordingSource):
    """Windows of an .npy array on disk: each window is found by bisection and only its rows are read."""

    def __init__(self, path, *, sensor_size=None, columns="txyp", polarity="auto", time_unit="auto"):
        self._opened = opened = _Opened(path, sensor_size, columns, time_unit)
        probe_sorted(opened.t, opened.path, also=NPY_SORT)
        self.meta = {"format": "npy", "path": str(opened.path)}
        opened.note_units(time_unit, self.meta)
        self._polarity = polarity
        n = len(opened.array)
        self.path, self.format = opened.path, "npy"
        self.sensor_size = tuple(int(v) for v in sensor_size)
        self.t_origin = opened.clock.origin
        self.n_events = n
        self.t_span = ((float(opened.clock.seconds(opened.t[0])), float(opened.clock.seconds(opened.t[n - 1])))
                       if n else (0.0, 0.0))
        check_time_span(np.array(self.t_span), opened.path, opened.unit)
        self.frames = None

    def _read_window(self, t0: float, t1: float) -> Events:
        lo, hi = self._opened.window(t0, t1)
        if hi <= lo:
            return Events.empty(self.sensor_size, self.t_origin)
        return self._opened.rows(lo, hi, self._polarity)


def _sniff(path, head) -> bool:
    return head is not None and head.startswith(MAGIC)


FORMAT = FileFormat(
    name="npy", description="an [N, 4] .npy array", reader=read_npy, suffixes=(".npy",), sniff=_sniff,
    needs_sensor_size=True, takes_sensor_size=True, windowed=True, open_source=NpySource,
    options=("columns", "polarity", "time_unit", "sort"))
