"""`RecordingSource`: an open recording, read window by window (the streaming solver's input).

A source knows what is cheap to know about a recording (sensor size, first and last event time,
the event count where the format records it, the small APS / ground-truth frames) and hands out
the events of a time window on request, reading only that window from disk where the format
allows it (memory-mapped .npy, canonical and HQF h5, AEDAT4 and Prophesee packets). Every time is
in seconds on the recording's clock: the same clock as ``Events.t`` and ``Frames.t`` that
:func:`~evinr_lite.io.read_recording` returns (relative to ``t_origin``).

    source = open_recording("shared/data/ijrr_slider_depth_chunk")     # evinr_lite.io.open_recording
    t0, t1 = source.t_span
    for start in np.arange(t0, t1, 0.05):
        window = source.events(start, start + 0.05)     # Events with start <= t < start + 0.05

``as_source(obj)`` wraps a :class:`~evinr_lite.core.recording.Recording` or
:class:`~evinr_lite.core.events.Events` already in memory, so the API and tests stream the same way.
"""
from __future__ import annotations

import math
from pathlib import Path

from ..core.checks import host_array, is_real_number
from ..core.events import EventDataError, Events, InputError
from ..core.frames import Frames
from ..core.recording import Recording

__all__ = ["RecordingSource", "MemorySource", "as_source", "check_window"]


def check_window(t0, t1, what: str = "window") -> tuple[float, float]:
    """(t0, t1) as finite floats with t0 < t1, or an EventDataError naming the problem. Numbers only: a 0-d
    array or tensor holding one is that number; text ("0") and booleans are refused, not read as seconds."""
    if not (is_real_number(t0) and is_real_number(t1)):
        raise EventDataError(f"the {what} [t0, t1) must be two numbers of seconds, got {t0!r}, {t1!r}")
    t0, t1 = float(host_array(t0)), float(host_array(t1))
    if not (math.isfinite(t0) and math.isfinite(t1)):
        raise EventDataError(f"the {what} [{t0}, {t1}) must be finite seconds")
    if t1 <= t0:
        raise EventDataError(f"the {what} [{t0}, {t1}) is empty or reversed; t1 must exceed t0")
    return t0, t1


class RecordingSource:
    """An open recording, read window by window.

    Attributes:
        path: the file or folder read (None for data in memory).
        format: the format's name, as ``detect_format`` gives it ("memory" for data in memory).
        sensor_size: (H, W).
        t_origin: seconds; absolute time of t = 0 (the events' and frames' ``t_origin``).
        t_span: (first, last) event time, seconds on the recording's clock; (0.0, 0.0) without events.
        n_events: the number of events, or None when the format cannot tell without a full scan.
        frames: the APS / ground-truth frames on the same clock (small; None when there are none).
        meta: what :func:`read_recording` puts in ``Recording.meta`` that is known without reading the events.

    Subclasses implement :meth:`_read_window` (and may override :meth:`load`). A source may hold a
    file open: use it as a context manager or call :meth:`close`.
    """

    path: Path | None = None
    format: str = ""
    sensor_size: tuple[int, int] = (0, 0)
    t_origin: float = 0.0
    t_span: tuple[float, float] = (0.0, 0.0)
    n_events: int | None = None
    frames: Frames | None = None
    meta: dict

    def events(self, t0: float, t1: float) -> Events:
        """Events with ``t0 <= t < t1`` (seconds, the recording's clock), sorted by time.

        A window with no events gives an empty :class:`Events` (streaming passes over gaps); a
        reversed or non-finite window is an EventDataError. Only this window is read from disk
        where the format allows it.
        """
        t0, t1 = check_window(t0, t1)
        return self._read_window(t0, t1)

    def _read_window(self, t0: float, t1: float) -> Events:
        raise NotImplementedError

    def load(self, t_start: float | None = None, t_end: float | None = None) -> Recording:
        """Everything in ``t_start <= t < t_end`` (None: open end) as :func:`read_recording` gives it:
        events and frames of the window, and the metadata. An empty window is an EventDataError."""
        lo = self.t_span[0] if t_start is None else t_start
        hi = math.nextafter(self.t_span[1], math.inf) if t_end is None else t_end
        events = self.events(lo, hi)
        if not len(events):
            raise EventDataError(self._empty_message(t_start, t_end))
        frames = self.frames
        if frames is not None and (t_start is not None or t_end is not None):
            frames = frames.slice_time(t_start, t_end)
            frames = frames if len(frames) else None
        return Recording(events, frames, dict(self.meta))

    def _empty_message(self, t_start, t_end) -> str:
        where = f"{self.path}: " if self.path is not None else ""
        span = (f"[{self.t_span[0]:.6f}, {self.t_span[1]:.6f}] s (relative to t_origin = {self.t_origin})"
                if self.n_events != 0 else "nothing (the recording has no events)")
        return (f"{where}no events in the window [{t_start}, {t_end}) s; the events cover {span}; "
                "choose a window inside that range")

    @property
    def duration(self) -> float:
        """Seconds from the first to the last event."""
        return float(self.t_span[1] - self.t_span[0])

    def close(self) -> None:
        """Release the file (nothing to do for sources that hold none open)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self) -> str:
        n = "?" if self.n_events is None else f"{self.n_events:,}"
        return (f"{type(self).__name__}({self.format!r}, path={str(self.path) if self.path else None!r}, "
                f"sensor_size={self.sensor_size}, t_span=({self.t_span[0]:.6f}, {self.t_span[1]:.6f}) s, "
                f"n_events={n}, frames={len(self.frames) if self.frames is not None else 0})")


class MemorySource(RecordingSource):
    """A recording held in memory (a :class:`Recording`, or :class:`Events` with optional frames);
    windows are slices by binary search (no copy of the events)."""

    def __init__(self, events: Events, frames: Frames | None = None, meta: dict | None = None,
                 path=None, format: str = "memory"):
        if not isinstance(events, Events):
            raise InputError(f"MemorySource needs Events, got {type(events).__name__}")
        if frames is not None and not isinstance(frames, Frames):
            raise InputError(f"frames must be Frames or None, got {type(frames).__name__}")
        self._events = events
        self.path = None if path is None else Path(path)
        self.format = format
        self.sensor_size = events.sensor_size
        self.t_origin = events.t_origin
        self.t_span = (float(events.t[0]), float(events.t[-1])) if len(events) else (0.0, 0.0)
        self.n_events = len(events)
        self.frames = frames
        self.meta = dict(meta or {"format": format, "path": None if path is None else str(path)})

    def _read_window(self, t0: float, t1: float) -> Events:
        return self._events.slice_time(t0, t1, allow_empty=True)

    def load(self, t_start=None, t_end=None) -> Recording:
        if t_start is None and t_end is None:
            return Recording(self._events, self.frames, dict(self.meta))
        return super().load(t_start, t_end)


def as_source(obj) -> RecordingSource:
    """A :class:`RecordingSource` over a Recording or Events already in memory (a source is returned
    as is). For files use :func:`open_recording`."""
    if isinstance(obj, RecordingSource):
        return obj
    if isinstance(obj, Recording):
        return MemorySource(obj.events, obj.frames, obj.meta, path=obj.meta.get("path"),
                            format=obj.meta.get("format", "memory"))
    if isinstance(obj, Events):
        return MemorySource(obj)
    if isinstance(obj, (str, Path)):
        raise InputError(f"as_source takes a Recording or Events in memory, got the path {obj!r}; "
                         "use evinr_lite.io.open_recording(path) for a file or folder")
    raise InputError(f"as_source takes a Recording or Events, got {type(obj).__name__}; read a file with "
                     "evinr_lite.io.open_recording(path), or build Events(t, x, y, p, sensor_size)")
